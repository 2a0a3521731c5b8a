"""`exucable plan`: outputs and their fields, the HTML page, exit status, several cables, units, pull-in
history, and refusals that name the key."""

from __future__ import annotations

import json
import math
import tomllib
from html.parser import HTMLParser
from pathlib import Path

import pytest

from exucable.cli import main as cli_main
from exucable.errors import ExucableError, ScenarioError
from exucable.plan.pull import parse_plan_scenario, plan_pull

ROOT = Path(__file__).resolve().parents[1]
G = 9.80665


def _data(**over):
    """A small SI planning scenario: 100 m straight, a 90° horizontal bend R 2 m, 50 m straight."""
    data = {
        "name": "t",
        "cable": {"radius": 0.01, "mass_per_length": 2.0, "youngs_modulus": 1e9, "elements": 10},
        "conduit": {"inner_radius": 0.05, "path": [{"straight": 100.0}, {"bend": 90.0, "radius": 2.0, "turn": "left"},
                                                   {"straight": 50.0}]},
        "contact": {"friction": 0.3},
        "pull": {"speed": 0.1, "back_tension": 100.0},
        "gravity": {"g": G},
        "solver": {"end_time": 0.1, "step": 0.01},
    }
    for k, v in over.items():
        table, _, name = k.partition("__")
        if name:
            data.setdefault(table, {})[name] = v
        else:
            data[table] = v
    return data


def _plan(**over):
    scenario, spec = parse_plan_scenario(_data(**over), ROOT)
    return plan_pull(scenario, spec, engine="rope")


def test_single_cable_matches_the_closed_form_section_by_section():
    plan = _plan()
    w, mu = 2.0 * G, 0.3
    rows = plan["directions"]["forward"]["sections"]
    t1 = 100.0 + mu * w * 100.0
    assert rows[0]["tension_out_N"] == pytest.approx(t1, rel=1e-9)
    # Bend with weight: between the capstan without weight and with |T/R| + w (bounds of sqrt((T/R)^2 + w^2)).
    cap = t1 * math.exp(mu * math.pi / 2)
    assert cap < rows[1]["tension_out_N"] < cap * 1.01
    assert rows[1]["sidewall_pressure_N_per_m"] == pytest.approx(math.hypot(rows[1]["tension_out_N"] / 2.0, w), rel=1e-6)
    assert rows[2]["tension_out_N"] == pytest.approx(rows[1]["tension_out_N"] + mu * w * 50.0, rel=1e-9)
    assert rows[0]["plane"] is None and rows[1]["plane"] == "horizontal" and rows[0]["slope_deg"] == 0.0
    # Reverse: the bend comes after 50 m; the recommended direction is the lower maximum tension.
    fwd, rev = (plan["directions"][d]["max_tension_N"] for d in ("forward", "reverse"))
    assert plan["recommended_direction"] == ("forward" if fwd < rev else "reverse")


def test_three_cables_use_weight_correction_and_bundle_weight():
    plan = _plan(cable__count=3, cable__arrangement="cradled")
    D, d = 0.1, 0.02
    wc = 1 + 4 / 3 * (d / (D - d)) ** 2
    assert plan["arrangement"] == "cradled" and plan["weight_correction_factor"] == pytest.approx(wc)
    first = plan["directions"]["forward"]["sections"][0]
    assert first["tension_out_N"] == pytest.approx(100.0 + wc * 0.3 * 3 * 2.0 * G * 100.0, rel=1e-9)
    assert plan["jam_ratio"] == pytest.approx(1.05 * 5.0)
    assert _plan(cable__count=3)["arrangement"] == "cradled"  # auto: D/d = 5 >= 2.5


@pytest.mark.parametrize("in_bends", [True, False])
def test_weight_correction_in_bends_or_on_straights_only(in_bends):
    """Without gravity the rope is the capstan law: the bend's factor is e^(w_c mu theta) by default (IEEE 1185)
    and e^(mu theta) with cable.weight_correction_in_bends = false (SEC TES-P-104.05's worked example)."""
    plan = _plan(cable__count=3, cable__arrangement="cradled", cable__weight_correction_in_bends=in_bends,
                 gravity={"g": 0.0})
    wc, mu = plan["weight_correction_factor"], 0.3
    assert wc > 1.05 and plan["weight_correction_in_bends"] is in_bends
    bend = plan["directions"]["forward"]["sections"][1]
    factor = math.exp((wc if in_bends else 1.0) * mu * math.pi / 2)
    assert bend["tension_out_N"] == pytest.approx(bend["tension_in_N"] * factor, rel=1e-9)


def test_vertical_bends_are_named():
    plan = _plan(conduit__path=[{"straight": 10.0}, {"bend": 30.0, "radius": 5.0, "turn": "up"}, {"straight": 10.0},
                                {"bend": 30.0, "radius": 5.0, "turn": "down"}, {"straight": 10.0}])
    rows = plan["directions"]["forward"]["sections"]
    assert [r["plane"] for r in rows if r["kind"] == "bend"] == ["vertical up", "vertical down"]
    assert rows[2]["slope_deg"] == pytest.approx(30.0)
    rev = plan["directions"]["reverse"]["sections"]
    assert rev[2]["slope_deg"] == pytest.approx(-30.0)


def test_imperial_numbers_equal_si_quantities():
    si = _plan(limits={"max_tension": "20 kN"})
    imp_data = _data(limits={"max_tension": "20 kN"})
    imp_data["display"] = {"units": "imperial"}
    imp_data["cable"].update(radius=0.01 / 0.0254, mass_per_length=2.0 / (0.45359237 / 0.3048))
    imp_data["conduit"]["inner_radius"] = 0.05 / 0.0254
    for item in imp_data["conduit"]["path"]:
        for k in ("straight", "radius"):
            if k in item:
                item[k] /= 0.3048
    imp_data["pull"]["back_tension"] = 100.0 / 4.4482216152605
    imp_data["pull"]["speed"] = 0.1 / 0.3048
    scenario, spec = parse_plan_scenario(imp_data, ROOT)
    imp = plan_pull(scenario, spec, engine="rope")
    assert imp["directions"]["forward"]["pull_force_N"] == pytest.approx(si["directions"]["forward"]["pull_force_N"],
                                                                         rel=1e-9)
    assert imp["checks"][0]["limit"] == pytest.approx(20e3)


def test_pull_in_history_ends_at_the_full_pull():
    plan = _plan(pull__feed_from_reel=True)
    for name in ("forward", "reverse"):
        h = plan["directions"][name]["pull_in"]
        assert h["pulled_length_m"][-1] == pytest.approx(100.0 + math.pi + 50.0)
        assert h["pull_force_N"][-1] == pytest.approx(plan["directions"][name]["pull_force_N"], rel=1e-9)
        # Head 50 m in, on the first straight (forward): back tension plus friction on 50 m.
    h = plan["directions"]["forward"]["pull_in"]
    i = min(range(len(h["pulled_length_m"])), key=lambda k: abs(h["pulled_length_m"][k] - 50.0))
    assert h["pull_force_N"][i] == pytest.approx(100.0 + 0.3 * 2.0 * G * h["pulled_length_m"][i], rel=1e-9)
    assert all(b >= a for a, b in zip(h["pull_force_N"], h["pull_force_N"][1:]))


@pytest.mark.parametrize("over, key", [
    ({"cable__count": -1}, "cable.count"),
    ({"cable__count": 5}, "cable.count"),
    ({"cable__arrangement": "hexagonal"}, "cable.arrangement"),
    ({"cable__count": 2, "cable__arrangement": "cradled"}, "cable.arrangement"),
    ({"cable__count": 4, "conduit__inner_radius": 0.02}, "conduit.inner_radius"),
    ({"limits": {"max_sidewall_pressure": "500 lb"}}, "limits.max_sidewall_pressure"),
    ({"limits": {"max_tension": "3 m"}}, "limits.max_tension"),
    ({"limits": {"max_tenson": 3.0}}, "limits.max_tenson"),
    ({"limits": {"conductor_material": "copper"}}, "limits.conductor_area"),
    ({"pull__feed_from_reel": "yes"}, "pull.feed_from_reel"),
    ({"display": {"units": "furlongs"}}, "display.units"),
])
def test_bad_inputs_are_refused_with_the_key(over, key):
    with pytest.raises(ScenarioError) as exc:
        parse_plan_scenario(_data(**over), ROOT)
    assert exc.value.key == key


def test_the_dynamic_engine_refuses_several_cables_naming_the_key():
    # --engine steady simulates a bundle (tests/test_bundle_report.py)
    scenario, spec = parse_plan_scenario(_data(cable__count=3), ROOT)
    with pytest.raises(ScenarioError, match="--engine rope") as exc:
        plan_pull(scenario, spec, engine="dynamic")
    assert exc.value.key == "cable.count"


def test_an_unknown_engine_is_refused():
    scenario, spec = parse_plan_scenario(_data(), ROOT)
    with pytest.raises(ExucableError, match="--engine"):
        plan_pull(scenario, spec, engine="fem")


class _Page(HTMLParser):
    def __init__(self):
        super().__init__()
        self.ids, self.imgs, self.tables, self.external = set(), [], 0, []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "img":
            self.imgs.append(a.get("src", ""))
        if tag == "table":
            self.tables += 1
        for k in ("src", "href"):
            if k in a and a[k] and not a[k].startswith(("data:", "#")):
                self.external.append(a[k])


def _toml(path: Path, limits: str) -> Path:
    path.write_text(f"""
name = "cli"
[cable]
radius = 0.01
mass_per_length = 2.0
youngs_modulus = 1e9
elements = 10
count = 3
[conduit]
inner_radius = 0.05
path = [{{ straight = 100.0 }}, {{ bend = 90.0, radius = 2.0, turn = "left" }}, {{ straight = 50.0 }}]
[contact]
friction = 0.3
[pull]
speed = 0.1
back_tension = 100.0
feed_from_reel = true
[gravity]
g = 9.80665
[solver]
end_time = 0.1
step = 0.01
[limits]
{limits}
""")
    return path


def test_cli_writes_plan_json_csv_and_a_self_contained_page(tmp_path, capsys):
    sc = _toml(tmp_path / "s.toml", 'max_tension = "20 kN"\nmax_sidewall_pressure = "10 kN/m"\n'
                                     'min_bend_radius_multiple = 12\nconductor_material = "copper"\n'
                                     'conductor_area = "95 mm2"\nconductors = 3\n')
    out = tmp_path / "out"
    assert cli_main(["plan", str(sc), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "recommended direction" in printed and "T out [N]" in printed
    plan = json.loads((out / "plan.json").read_text())
    for k in ("engine", "directions", "recommended_direction", "weight_correction_factor", "jam_ratio", "clearance_m",
              "checks"):
        assert k in plan
    for name in ("forward", "reverse"):
        d = plan["directions"][name]
        for k in ("pull_force_N", "max_tension_N", "max_sidewall_pressure_N_per_m", "sections"):
            assert k in d
        for row in d["sections"]:
            assert set(("kind", "length_m", "tension_in_N", "tension_out_N", "sidewall_pressure_N_per_m")) <= set(row)
            assert (row["sidewall_pressure_N_per_m"] is None) == (row["kind"] == "straight")
        assert (out / f"sections_{name}.csv").read_text().startswith("index,kind,plane")
        assert (out / f"pull_in_{name}.csv").exists()
    names = {c["name"] for c in plan["checks"]}
    assert names == {"max_tension", "conductor_tension", "max_sidewall_pressure", "min_bend_radius", "jam_ratio"}
    for c in plan["checks"]:
        assert set(c) >= {"name", "passed", "value", "limit", "margin", "where"}
    # Conductor limit: 3 x 95 mm2 copper at 50 N/mm2.
    assert next(c for c in plan["checks"] if c["name"] == "conductor_tension")["limit"] == pytest.approx(14250.0)
    page = _Page()
    page.feed((out / "report.html").read_text())
    assert {"verdict", "recommended", "sections-forward", "sections-reverse", "checks-forward", "pull-in"} <= page.ids
    assert len(page.imgs) == 3 and all(src.startswith("data:image/png;base64,") for src in page.imgs)
    assert page.external == [] and page.tables >= 4


def test_cli_exits_nonzero_when_a_check_fails_in_both_directions(tmp_path, capsys):
    sc = _toml(tmp_path / "s.toml", 'max_tension = "1 kN"\n')
    assert cli_main(["plan", str(sc), "--out", str(tmp_path / "o")]) == 1
    assert "FAIL" in capsys.readouterr().out
    assert json.loads((tmp_path / "o" / "plan.json").read_text())["passed"] is False


def test_cli_names_the_key_of_a_bad_limit(tmp_path, capsys):
    sc = _toml(tmp_path / "s.toml", 'max_sidewall_pressure = "500 lb"\n')
    assert cli_main(["plan", str(sc), "--out", str(tmp_path / "o")]) == 2
    assert "limits.max_sidewall_pressure" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_imperial_file_reads_the_manuals_numbers():
    from exucable.plan.pull import load_plan_scenario

    scenario, spec = load_plan_scenario(ROOT / "scenarios" / "industry" / "commscope_conquest_run_a_h.toml")
    plan = plan_pull(scenario, spec, engine="rope")
    lbf, ft = 4.4482216152605, 0.3048
    assert spec.units == "imperial"
    assert plan["inputs"]["weight_per_length_one_cable_N_per_m"] / (lbf / ft) == pytest.approx(0.144, rel=1e-12)
    assert scenario.limits.max_tension_N / lbf == pytest.approx(340.0, rel=1e-12)
    assert plan["directions"]["forward"]["sections"][0]["length_m"] / ft == pytest.approx(100.0, rel=1e-12)


def test_3d_bends_and_helices_are_named_and_get_a_pressure():
    plan = _plan(conduit__path=[{"straight": 5.0}, {"bend": 60.0, "radius": 3.0, "axis": [0.0, 1.0, 1.0]},
                                {"straight": 5.0}, {"helix_turns": 1.0, "radius": 2.0, "pitch": 0.5}])
    rows = plan["directions"]["forward"]["sections"]
    assert [r["kind"] for r in rows] == ["straight", "bend", "straight", "helix"]
    assert rows[1]["plane"] == "3D" and rows[3]["plane"] == "helix"
    assert all(r["sidewall_pressure_N_per_m"] > 0 for r in rows if r["kind"] != "straight")


def test_a_prescribed_pull_force_is_refused_and_slack_is_reported():
    scenario, spec = parse_plan_scenario(_data(pull={"speed": 0.1, "force": 500.0}), ROOT)
    with pytest.raises(ScenarioError) as exc:
        plan_pull(scenario, spec, engine="rope")
    assert exc.value.key == "pull.force"
    # 30 deg down a straight with mu 0.3 < tan 30 deg: the reverse pull runs slack (tension 0, not negative).
    plan = _plan(conduit__heading=[math.cos(math.radians(30)), 0.0, math.sin(math.radians(30))],
                 conduit__path=[{"straight": 20.0}], pull__back_tension=0.0)
    assert plan["directions"]["reverse"]["slack"] and plan["directions"]["reverse"]["pull_force_N"] == 0.0
    assert not plan["directions"]["forward"]["slack"]


def test_readme_links_an_industry_report_and_shows_its_picture():
    """Issue #16 "Done when": the HTML report of one industry route is linked from the README, with a picture."""
    readme = (ROOT / "README.md").read_text()
    assert "(docs/plan_example/report.html)" in readme and "![plan report](docs/plan_example/preview.png)" in readme
    example = ROOT / "docs" / "plan_example"
    assert (example / "preview.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    page = _Page()
    page.feed((example / "report.html").read_text())
    assert page.external == [] and page.imgs and all(src.startswith("data:image/png;base64,") for src in page.imgs)
    assert {"sections-forward", "sections-reverse", "checks-forward", "recommended"} <= page.ids
    plan = json.loads((example / "plan.json").read_text())
    scenario = ROOT / "scenarios" / "industry" / "commscope_conquest_run_a_h.toml"
    assert plan["inputs"]["scenario"] == parse_plan_scenario(tomllib.loads(scenario.read_text()), ROOT)[0].name



def test_without_limits_the_plan_says_not_checked(tmp_path, capsys):
    """No [limits]: nothing to pass or fail, and the plan says so instead of 'all checks pass'."""
    plan = _plan()
    assert plan["limits_checked"] is False and plan["passed"] is True
    assert _plan(limits={"max_tension": 1e6})["limits_checked"] is True
    path = _toml(tmp_path / "s.toml", "")
    path.write_text(path.read_text().replace("[limits]", ""))
    assert cli_main(["plan", str(path), "--out", str(tmp_path / "out")]) == 0
    printed = capsys.readouterr().out
    assert "limits: not checked" in printed and "limits not checked: no [limits]" in printed
    assert "Limits not checked" in (tmp_path / "out" / "report.html").read_text()


@pytest.mark.filterwarnings("ignore:overflow:RuntimeWarning", "ignore:invalid value:RuntimeWarning")
def test_an_infinite_tension_fails_with_or_without_limits():
    """A tension past what a float holds is infinite, and that fails a check of its own instead of
    passing unchecked. The scenario's ranges now refuse the inputs that made one (a back tension of
    1.79e308 N grown by friction), so the check is exercised on a direction whose tension overflowed."""
    from exucable.errors import ScenarioError
    from types import SimpleNamespace

    import exucable.plan.pull as pull

    with pytest.raises(ScenarioError, match=r"^pull\.back_tension"):
        _plan(pull__back_tension=1.79e308)
    scenario, spec = parse_plan_scenario(_data(), ROOT)
    plan = plan_pull(scenario, spec, engine="rope")
    for name in ("forward", "reverse"):
        d = dict(plan["directions"][name], max_tension_N=math.inf)
        check = next(c for c in pull._checks(d, spec, scenario, plan["clearance_m"], SimpleNamespace(risk="not applicable"))
                     if c["name"] == "finite_tension")
        assert check["passed"] is False


def test_a_rope_that_cannot_be_solved_names_the_scenario_key(monkeypatch):
    """The rope solver's own argument names are not keys a user can set: they are translated."""
    import exucable.plan.pull as pull
    from exucable.errors import ModelError

    def refuse(*args, **kwargs):
        raise ModelError("weight_per_length_N_per_m", "weight per length must be finite and >= 0, got nan")

    monkeypatch.setattr(pull, "solve_rope", refuse)
    with pytest.raises(ModelError, match=r"^cable\.mass_per_length: weight per length"):
        _plan()
