"""The Python API without sharp edges, the shipped scenarios by name, and `exucable run` in the scenario's
display units."""

from __future__ import annotations

import argparse
import math

import pytest

import exucable as xc
from exucable.cli import main as cli_main
from exucable.data import data_path, resolve_scenario_path, shipped_scenarios
from exucable.errors import ScenarioError

LBF_N = 4.4482216152605          # NIST SP 811: 1 lbf in N
FT_M = 0.3048


def _cable(**over):
    keys = dict(radius=2.5e-3, density=1000.0, youngs_modulus=1e9)
    keys.update(over)
    return xc.Cable(**keys)


def test_values_are_read_as_in_a_file():
    assert _cable(radius="2.5 mm").radius_m == pytest.approx(2.5e-3, rel=1e-15)
    assert xc.Pull(speed="6 m/min", back_tension="0.15 kN").back_tension_N == pytest.approx(150.0)
    route = xc.Route(inner_radius="3.5 mm").straight("10 ft").bend(90, radius="0.5 m", turn="left")
    assert route.length_m == pytest.approx(10 * FT_M + 0.25 * math.pi, rel=1e-12)
    with pytest.raises(ScenarioError) as exc:
        _cable(radius="2.5 N")
    assert exc.value.key == "cable.radius" and "is a force" in str(exc.value)
    with pytest.raises(ScenarioError) as exc:
        _cable(radius=[2.5e-3])
    assert exc.value.key == "cable.radius" and "array" in str(exc.value)


def test_route_radius_is_checked_at_once_and_a_list_route_is_named():
    for bad in (-1.0, "3.5 N", "wide"):
        with pytest.raises(ScenarioError) as exc:
            xc.Route(inner_radius=bad)             # before any piece is added
        assert exc.value.key == "conduit.inner_radius"
    with pytest.raises(ScenarioError) as exc:
        xc.Route(inner_radius=0.0035).straight("1 lbf")
    assert exc.value.key == "conduit.path[0].straight"
    with pytest.raises(ScenarioError) as exc:
        xc.Scenario(route=[{"straight": 1.0}], cable=_cable(), pull=xc.Pull(speed=0.1),
                    solver=xc.Solver(end_time=0.1))
    assert exc.value.key == "route" and "exucable.Route" in str(exc.value)


def test_gravity_defaults_to_9_81_and_replace_names_the_dotted_key():
    assert xc.Gravity().g_m_per_s2 == 9.81
    sc = xc.load_scenario("fast/paper_ex2_bend90")
    with pytest.raises(ScenarioError) as exc:
        sc.replace(friction=0.3)
    assert exc.value.key == "friction" and "'contact.friction'" in str(exc.value)
    assert sc.replace(**{"contact.friction": 0.3}).contact.friction == 0.3


def test_shipped_scenarios_by_name_and_by_readme_path_from_anywhere(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)                   # not the repository: the README's relative paths do not exist
    expected = data_path("scenarios", "paper_ex2_bend90.toml")
    for arg in ("paper_ex2_bend90", "paper_ex2_bend90.toml", "scenarios/paper_ex2_bend90.toml"):
        assert resolve_scenario_path(arg) == expected, arg
    assert resolve_scenario_path("fast/paper_ex2_bend90") == data_path("scenarios", "fast", "paper_ex2_bend90.toml")
    assert resolve_scenario_path("scenarios/sweeps/ex2_friction.toml").is_file()
    names = shipped_scenarios()
    assert "industry/commscope_conquest_run_a_h" in names and not any(n.startswith("sweeps/") for n in names)
    assert cli_main(["scenarios"]) == 0
    printed = capsys.readouterr().out
    assert "fast/paper_ex2_bend90" in printed and "Paper Example 2" in printed
    assert cli_main(["route", "no_such_scenario", "-o", str(tmp_path / "r.png")]) == 2
    assert "exucable scenarios" in capsys.readouterr().err


def test_run_takes_a_mode_and_a_steady_result_is_a_state(monkeypatch, tmp_path):
    sc = xc.load_scenario("fast/paper_ex2_bend90")
    with pytest.raises(ScenarioError):
        xc.run(sc, mode="sideways")
    captured = {}
    import exucable.plots.results as figures

    def keep(fig, path, **kwargs):                # the figures as drawn, not as pixels
        captured[path.name] = fig
        return path

    monkeypatch.setattr(figures, "save_figure", keep)
    res = xc.run(sc, mode="steady", out_dir=tmp_path)
    assert res.summary["mode"] == "steady" and res.status in ("ok", "steady")
    assert res.summary["pull_force_uncertainty_N"] is None and math.isnan(res.pull_force_uncertainty_N)
    text = repr(res)
    assert "\n" not in text and len(text) < 300 and "mode='steady'" in text
    axes = captured["pull_force.png"].axes
    assert all("time [s]" not in ax.get_xlabel() for ax in axes)
    assert "static solve step" in axes[-1].get_xlabel()
    # the pulling force's own axis shows its gap to the rope (capstan 205.37 N for this example): the
    # range is a few per cent of the force, not trailing tension (150 N) to pull force
    lo, hi = axes[0].get_ylim()
    assert lo > 190.0 and hi < 220.0
    # the bend's two point-load labels clear of each other and of the legend
    fig = captured["pressure.png"]
    renderer = fig.canvas.get_renderer()
    fig.draw(renderer)
    ax = fig.axes[0]
    boxes = [t.get_window_extent(renderer) for t in ax.texts] + [ax.get_legend().get_window_extent(renderer)]
    assert len(boxes) == 3
    assert not any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1:])


def test_run_prints_in_the_scenarios_display_units(monkeypatch, capsys, tmp_path):
    import exucable.commands.run as run_command

    from dataclasses import replace

    from exucable.scenario.specs import DisplaySpec

    # the same SI scenario, shown in imperial units (replace() would re-read its bare numbers as imperial)
    sc = replace(xc.load_scenario("fast/paper_ex2_bend90"), display=DisplaySpec(units="imperial"))
    monkeypatch.setattr(run_command, "load_scenario", lambda _: sc)
    args = argparse.Namespace(scenario="x", out=str(tmp_path / "o"), quiet=True, no_plots=True, mode="steady",
                              steady_stop=None)
    assert run_command.main(args) == 0
    printed = capsys.readouterr().out
    first = printed.splitlines()[0]
    assert "lbf" in first and " N " not in first
    summary = __import__("json").loads((tmp_path / "o" / "summary.json").read_text())
    shown = float(first.split("pulling force ")[1].split(" lbf")[0])
    assert shown == pytest.approx(summary["pull_force_N"] / LBF_N, rel=1e-5)   # printed to 6 digits


def test_compare_across_modes_compares_states_not_histories(tmp_path):
    """A dynamic and a steady run of one scenario: the steady run's solve steps are not set against
    the dynamic run's time; their states' profiles are compared (and drawn)."""
    from exucable.output.compare import compare_results, write_overlay_plots

    sc = xc.load_scenario("fast/paper_ex2_bend90")
    xc.run(sc, out_dir=tmp_path / "dynamic")
    xc.run(sc, out_dir=tmp_path / "steady", mode="steady")
    result = compare_results(tmp_path / "dynamic", tmp_path / "steady")
    kinds = {c["kind"] for c in result["comparisons"]}
    assert "history" not in kinds and "tension_profile" in kinds
    assert any(k == "history" and "steady result" in why for k, _, why in result["skipped"])
    tension = next(c for c in result["comparisons"] if c["kind"] == "tension_profile")
    # both are the steady sliding state of one cable: the rope's 205 N over 150 N spans 55 N, and the
    # two states differ by well under that (the dynamic run has pulled the cable 4 cm further)
    assert tension["max_abs"] < 20.0
    assert len(write_overlay_plots(result, tmp_path / "figures")) == len(result["comparisons"])
