"""`exucable run` end to end: result files, failures reported with their time, bad input refused."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from exucable.errors import ModelError, ScenarioError
from exucable.model.build import build_model
from exucable.output.results import read_csv
from exucable.run import run_scenario

from conftest import ROOT, make_scenario


def test_run_writes_the_documented_results(tmp_path):
    res = run_scenario(ROOT / "scenarios/fast/paper_ex1_incline.toml", tmp_path, quiet=True)
    s = json.loads((tmp_path / "summary.json").read_text())
    for key in ("pull_force_N", "pull_force_std_N", "trailing_tension_N", "max_tension_N", "steady_from_s",
                "steps", "newton_iterations_per_step", "wall_time_s", "rope_pull_force_N", "max_sidewall_pressure_N_per_m", "scenario",
                "versions"):
        assert key in s, key
    assert s["versions"]["exudyn"].startswith("1.13")
    assert s["scenario"]["contact"]["friction"] == 0.3          # echoed with defaults filled in
    assert list(read_csv(tmp_path / "history.csv")) == ["time_s", "pull_force_N", "trailing_tension_N",
                                                         "max_tension_N", "max_penetration_m", "max_axis_offset_m",
                                                         "max_axis_offset_s_conduit_m"]
    assert list(read_csv(tmp_path / "tension_profile.csv")) == ["x_m", "tension_N"]
    contact = read_csv(tmp_path / "contact_profile.csv")
    assert list(contact) == ["s_conduit_m", "normal_force_per_length_N_per_m", "penetration_m"]
    # the sidewall pressure of a cable resting on an incline is w·cos θ (1e-3: binning at the ends)
    w = 1000 * np.pi * 0.0025**2 * 9.8
    mid = (contact["s_conduit_m"] > 10) & (contact["s_conduit_m"] < 40)
    np.testing.assert_allclose(contact["normal_force_per_length_N_per_m"][mid], w * np.cos(np.pi / 6), rtol=1e-3)
    # one sidewall-pressure name: the windowed pressure's maximum; the single point's peak named apart
    pressure = read_csv(tmp_path / "pressure_profile.csv")
    assert s["max_sidewall_pressure_N_per_m"] == pytest.approx(np.max(pressure["windowed_pressure_N_per_m"]), rel=1e-12)
    assert s["max_check_point_line_load_N_per_m"] == pytest.approx(np.max(contact["normal_force_per_length_N_per_m"]),
                                                                    rel=1e-12)     # < 5000 points: one row each
    assert "max_windowed_sidewall_pressure_N_per_m" not in s
    for png in ("pull_force.png", "tension_profile.png"):
        assert (tmp_path / png).stat().st_size > 5000
    assert not list(tmp_path.glob(".*.tmp"))                   # atomic writes leave no temp files
    assert res.summary["status"] in ("ok", "steady")
    assert s["newton_iterations_per_step"] == pytest.approx(s["newton_iterations"] / s["steps"])


def test_solver_failure_is_reported_with_its_time_and_keeps_results(tmp_path):
    """One Newton iteration and no room to cut the step: the solve fails; the run still writes
    what it has, says where it failed, and the CLI exits non-zero with that message."""
    sc = make_scenario(pull={"speed": 0.1, "back_tension": 150.0},
                       conduit={"inner_radius": 0.0035, "path": [{"straight": 0.5}, {"bend": 90, "radius": 0.5, "turn": "left"}]},
                       solver={"end_time": 0.2, "step": 0.01, "min_step": 0.01, "newton_max_iterations": 1})
    res = run_scenario(sc, tmp_path, quiet=True)
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["status"] == "failed" and s["message"]
    assert 0.0 <= s["failed_at_s"] < 0.2
    assert (tmp_path / "history.csv").exists() and (tmp_path / "tension_profile.csv").exists()
    assert res.summary["status"] == "failed"


@pytest.mark.parametrize("tables, key", [
    ({"cable": dict(radius=0.0025, density=1000.0, youngs_modulus=1e9, elements=10, length=5.0)}, "cable.length"),
    ({"pull": {"speed": 0.0}}, "pull.speed"),
    ({"solver": {"end_time": 0.2, "step": -0.01}}, "solver.step"),
    ({"conduit": {"inner_radius": 0.002, "path": [{"straight": 1.0}]}}, "conduit.inner_radius"),
])
def test_bad_model_input_is_refused_naming_the_key(tables, key):
    with pytest.raises(ScenarioError) as e:
        make_scenario(**tables)
    assert e.value.key == key


def test_elements_too_long_for_the_tightest_bend_are_refused():
    sc = make_scenario(cable=dict(radius=0.0025, density=1000.0, youngs_modulus=1e9, elements=2),
                       conduit={"inner_radius": 0.0035, "path": [{"straight": 0.5}, {"bend": 90, "radius": 0.3, "turn": "left"}]})
    with pytest.raises(ModelError) as e:
        build_model(sc)
    assert e.value.key == "cable.elements" and "at least" in str(e.value)


def test_cli_reports_user_errors_without_traceback(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text((ROOT / "scenarios/fast/paper_ex2_bend90.toml").read_text().replace("radius = 0.5", "radius = -0.5"))
    p = subprocess.run([sys.executable, "-m", "exucable", "run", str(bad), "--out", str(tmp_path / "o")],
                       capture_output=True, text=True)
    assert p.returncode == 2
    assert "conduit.path[1].radius" in p.stderr and "Traceback" not in p.stderr


def test_cli_lists_every_subcommand():
    p = subprocess.run([sys.executable, "-m", "exucable", "--help"], capture_output=True, text=True)
    assert p.returncode == 0
    for cmd in ("route", "run", "validate", "sweep", "compare"):
        assert cmd in p.stdout


def test_cli_imports_only_the_chosen_subcommand():
    """`exucable run` does not pay for the other commands' imports (fixed cost, issue 15), and
    their help still works."""
    code = ("import sys\nfrom exucable.cli import build_parser, _command_in\n"
            "build_parser(only=_command_in(['run', 'x.toml']))\n"
            "print(sorted(m for m in ('exucable.commands.sweep', 'exucable.commands.validate', "
            "'exucable.commands.compare', 'exucable.sweep', 'exucable.validation.paper', "
            "'matplotlib') if m in sys.modules))")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == "[]"
    p = subprocess.run([sys.executable, "-m", "exucable", "sweep", "--help"], capture_output=True, text=True)
    assert p.returncode == 0 and "--workers" in p.stdout


@pytest.mark.parametrize("name", ["paper_ex1_incline", "paper_ex2_bend90", "paper_ex3_helix", "paper_ex4_spatial"])
def test_route_draws_each_paper_scenario(name, tmp_path):
    png = tmp_path / f"{name}.png"
    p = subprocess.run([sys.executable, "-m", "exucable", "route", str(ROOT / "scenarios" / f"{name}.toml"),
                        "-o", str(png)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert png.stat().st_size > 10000
    for row in ("length", "turning", "segments", "bend radius"):
        assert row in p.stdout.lower(), p.stdout


def test_contact_profile_groups_are_those_of_array_split():
    """Beyond max_rows the profile averages consecutive points in np.array_split's groups (the
    definition, evaluated group by group here): mean pressure and position, largest penetration."""
    from exucable.run import contact_profile

    rng = np.random.default_rng(7)
    n, rows = 10007, 300
    pts = {"s_conduit_m": np.sort(rng.uniform(0, 50, n)), "normal_force_per_length_N_per_m": rng.uniform(0, 9, n),
           "penetration_m": rng.uniform(0, 1e-4, n)}
    prof, peak = contact_profile(pts, max_rows=rows)
    groups = np.array_split(np.arange(n), rows)
    assert peak == pts["normal_force_per_length_N_per_m"].max()
    for key, reduce in (("s_conduit_m", np.mean), ("normal_force_per_length_N_per_m", np.mean), ("penetration_m", np.max)):
        want = np.array([reduce(pts[key][g]) for g in groups])
        assert np.allclose(prof[key], want, rtol=1e-14, atol=0.0), key


@pytest.mark.parametrize("name", ["paper_ex3_helix", "paper_ex4_spatial"])
def test_the_shipped_fast_examples_3_and_4_end_steady(name, tmp_path):
    """`exucable run scenarios/fast/...` as shipped exits 0: steady within its end time (Ex. 3 with
    64 elements, Ex. 4 started in the steady state; the files say why), within the
    fast validation's tolerances of their references (exucable.validation.paper.TOLERANCES)."""
    p = subprocess.run([sys.executable, "-m", "exucable", "run", str(ROOT / "scenarios" / "fast" / f"{name}.toml"),
                        "--out", str(tmp_path / "out"), "--no-plots", "-q"], capture_output=True, text=True,
                       timeout=600)
    assert p.returncode == 0, p.stdout + p.stderr
    s = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert s["status"] == "steady" and s["steady"]
    if name == "paper_ex3_helix":
        assert abs(s["trailing_tension_N"] / s["rope_trailing_tension_N"] - 1) < 1e-2
    else:
        assert abs(s["pull_force_N"] / s["rope_pull_force_N"] - 1) < 2e-2


def test_a_rope_start_that_cannot_be_solved_names_the_scenario_key():
    """The rope solver's own argument names (pull_force_N, ...) are not keys a user can set: a
    prescribed pull too small to move the cable is refused naming pull.force."""
    bend = {"inner_radius": 0.0035, "path": [{"straight": 1.0}, {"bend": 90.0, "radius": 0.5, "turn": "left"},
                                             {"straight": 1.0}]}
    sc = make_scenario(cable={"radius": 0.0025, "density": 1000.0, "youngs_modulus": 1e9, "elements": 40},
                       conduit=bend, pull={"speed": 0.1, "force": 0.01}, contact={"friction": 0.3},
                       gravity={"g": 9.8})
    with pytest.raises(ModelError, match=r"^pull\.force: pull force 0.01 N is below"):
        build_model(sc)
