"""`exucable plan --engine steady` with three cables whose asked arrangement is not the calculators'
rule's for the duct (exucable/plan/pull.py ``_bundle_fallback``): the triangle asked at D/d ≥ 2.5
that reaches no steady state is reported with where it broke and simulated as cradled, labelled so in
the JSON, the section CSVs and the report, the formula's triangular values beside;
``arrangement_as_given`` keeps it failed with the reason; a cradled request runs once per direction.

The triangle's failure is made real and cheap: its run gets no CPU budget (the budget's own failure,
:func:`exucable.run._budgeted`), the cradle's run the plan's. Coarse straight duct (8 elements of 0.5 m,
D/d 3.3), as tests/test_bundle_report.py.
"""

from __future__ import annotations

import csv
import importlib
import json
import math

import pytest

import exucable as xc
from exucable.plan.pull import arrangement_left, plan_pull, plan_spec
from exucable.quasistatic import engineering as eng

R_CABLE = 0.015


def straight_duct(arrangement: str, ratio: float):
    return xc.Scenario(route=xc.Route(inner_radius=ratio * R_CABLE).straight(4.0),
                       cable=xc.Cable(radius=R_CABLE, density=2000.0, youngs_modulus=2e8, count=3,
                                      arrangement=arrangement, elements=8),
                       contact=xc.Contact(friction=0.3, check_points_per_element=8),
                       pull=xc.Pull(speed=0.1, back_tension=30.0), gravity=xc.Gravity(g=9.81),
                       solver=xc.Solver(mode="steady", end_time=1.0, steady_lead_out=0.0))


@pytest.fixture
def runs(monkeypatch):
    """Every run the plan makes, by arrangement; a triangle's run gets no CPU budget."""
    run = importlib.import_module("exucable.run")
    real, made = run.run_scenario, []

    def counted(sc, *args, **kwargs):
        made.append(sc.cable.arrangement)
        if sc.cable.arrangement == "triangular":
            kwargs["cpu_budget_s"] = 0.0
        return real(sc, *args, **kwargs)

    monkeypatch.setattr(run, "run_scenario", counted)
    return made


def test_a_triangle_that_does_not_hold_is_simulated_cradled_and_labelled(runs, tmp_path):
    from exucable.commands.plan import write_plan

    sc = straight_duct("triangular", 3.3)
    lines = []
    plan = plan_pull(sc, plan_spec(sc), engine="steady", notify=lines.append)
    cradled = plan_pull(straight_duct("cradled", 3.3), plan_spec(straight_duct("cradled", 3.3)), engine="steady")
    assert runs == ["triangular", "cradled"] * 2 + ["cradled"] * 2
    # the formula's values stay the triangle's: T_out = T_in + w_c μ W L on the level straight
    wc = eng.weight_correction_factor(3, "triangular", 3.3 * 2 * R_CABLE, 2 * R_CABLE)
    assert plan["arrangement"] == "triangular" and plan["weight_correction_factor"] == pytest.approx(wc, rel=1e-12)
    assert len(lines) == 2 and all("simulating as cradled" in line for line in lines)
    for name in ("forward", "reverse"):
        d = plan["directions"][name]
        fb = d["arrangement_fallback"]
        assert d["status"] == "ok" and d["simulated_arrangement"] == "cradled"
        assert fb["asked"] == "triangular" and fb["simulated"] == fb["rule"] == "cradled"
        assert fb["attempt_status"] == "failed" and "CPU budget" in fb["attempt_message"]
        assert "D/d 3.3" in fb["reason"] and "gives 3 free cables cradled" in fb["reason"]
        # the triangle's run stopped after its first step (the cables not yet settled into contact): the
        # reason names the stretches of its last state that were not the triangle, by the route's points
        assert fb["left"] and all(st["pieces"] == ["straight A–B"] and 0.0 < st["s_start_m"] <= st["s_end_m"] < 4.0
                                  for st in fb["left"])
        assert "in its last state the cables had left the triangle at " in fb["reason"]
        assert f"(straight A–B: {fb['left'][0]['arrangement']})" in fb["reason"]
        assert d["message"].startswith("simulated as cradled (the triangle did not hold: its steady solve found no "
                                        "steady state in ")
        assert d["rope_pull_force_N"] == pytest.approx(30.0 + wc * 0.3 * 3 * 2000.0 * 0.03**2 / 4 * 3.141592653589793
                                                       * 9.81 * 4.0, rel=1e-9)
        # the simulated number is the cradle's, as a cradled request gives it
        assert d["pull_force_N"] == pytest.approx(cradled["directions"][name]["pull_force_N"], rel=1e-12)
        (row,) = d["sections"]
        assert (row["formula_arrangement"], row["simulated_arrangement"], row["arrangement_found"]) == \
            ("triangular", "cradled", "cradled")
        # the check names what was simulated; the solve's details stay on the direction's status line
        (check,) = [c for c in d["checks"] if c["name"] == "multibody_run"]
        head = d["message"].split("; ")[0]
        assert check["passed"] and check["where"].startswith("status ok: simulated as cradled (the triangle did not")
        assert len(check["where"]) < len(d["message"]) and check["where"].endswith(")") and head in check["where"]
    write_plan(tmp_path, plan, sc, "si")
    with open(tmp_path / "sections_forward.csv", newline="") as fh:
        (row,) = list(csv.DictReader(fh))
    assert (row["formula_arrangement"], row["simulated_arrangement"], row["arrangement_found"]) == \
        ("triangular", "cradled", "cradled")
    saved = json.loads((tmp_path / "plan.json").read_text())
    assert saved["directions"]["reverse"]["arrangement_fallback"]["simulated"] == "cradled"
    page = (tmp_path / "report.html").read_text()
    assert "Simulated as cradled (the triangle did not hold:" in page
    assert "triangular (given: triangular); simulated as cradled" in page
    assert "multibody model of 3 cables in one duct" in page and "multibody model of one cable" not in page


def test_the_triangle_as_given_fails_with_the_reason(runs):
    sc = straight_duct("triangular", 3.3)
    lines = []
    plan = plan_pull(sc, plan_spec(sc), engine="steady", arrangement_as_given=True, notify=lines.append)
    assert runs == ["triangular", "triangular"] and lines == []
    for d in plan["directions"].values():
        assert d["status"] == "failed" and d["simulated_arrangement"] == "triangular"
        assert d["arrangement_fallback"]["simulated"] is None
        assert d["message"].startswith("the triangle did not hold (its steady solve found no steady state in ")
        assert "without --arrangement-as-given to simulate it as cradled" in d["message"]
        assert d["sections"][0]["arrangement_found"] is None
        (check,) = [c for c in d["checks"] if c["name"] == "multibody_run"]
        assert not check["passed"]
    assert not plan["passed"]


def test_a_cradled_request_and_a_triangle_inside_its_range_are_untouched(runs):
    """Cradled at D/d 3.3 (the rule's own): one run per direction, no fallback. A triangle at D/d 2.4
    (the rule's own too) that fails stays failed: there is no other arrangement to fall back on."""
    sc = straight_duct("cradled", 3.3)
    plan = plan_pull(sc, plan_spec(sc), engine="steady")
    assert runs == ["cradled", "cradled"]
    for d in plan["directions"].values():
        assert d["status"] == "ok" and d["arrangement_fallback"] is None and d["simulated_arrangement"] == "cradled"
        assert "simulated as" not in d["message"]
    runs.clear()
    sc = straight_duct("triangular", 2.4)
    plan = plan_pull(sc, plan_spec(sc), engine="steady")
    assert runs == ["triangular", "triangular"]
    assert all(d["status"] == "failed" and d["arrangement_fallback"] is None for d in plan["directions"].values())


def test_where_the_cables_are_not_in_the_asked_arrangement():
    """A solved cradle read against the triangle: one stretch over the whole straight, cradled, named
    by the route's points; read against the cradle: none."""
    res = xc.run(straight_duct("cradled", 3.3))
    assert res.status == "ok"
    (stretch,) = arrangement_left(res.model, "triangular", ["A", "B"])
    assert stretch["arrangement"] == "cradled" and stretch["pieces"] == ["straight A–B"]
    # stations every 0.5 m at the middles of the 8 intervals of the 4 m straight
    assert (stretch["s_start_m"], stretch["s_end_m"]) == pytest.approx((0.25, 3.75))
    assert arrangement_left(res.model, "cradled", ["A", "B"]) == []


def test_cables_laid_at_positions_are_not_replaced_by_the_rule(runs):
    # cable.positions is the user's lay: a triangle laid there that fails stays failed (as
    # --arrangement-as-given keeps an arrangement), and a lay that solves is labelled as positions
    rho = 3.3 * R_CABLE - R_CABLE
    a = [-R_CABLE, -(rho**2 - R_CABLE**2) ** 0.5]
    b = [R_CABLE, a[1]]
    top = [0.0, a[1] + (4.0 * R_CABLE**2 - R_CABLE**2) ** 0.5]
    sc = straight_duct("triangular", 3.3).replace(**{"cable.positions": [a, b, top]})
    plan = plan_pull(sc, plan_spec(sc), engine="steady")
    assert runs == ["triangular"] * 2
    assert all(plan["directions"][n]["status"] == "failed" and plan["directions"][n]["arrangement_fallback"] is None
               for n in ("forward", "reverse"))
    runs.clear()
    cradled = straight_duct("cradled", 3.3)
    alpha = 2.0 * math.asin(R_CABLE / rho)      # two touching cables on the wall, seen from the axis
    sc = cradled.replace(**{"cable.positions": [[rho * math.sin(k * alpha), -rho * math.cos(k * alpha)]
                                                for k in (-1, 0, 1)]})
    plan = plan_pull(sc, plan_spec(sc), engine="steady")
    assert runs == ["cradled"] * 2
    assert plan["directions"]["forward"]["status"] == "ok"
    assert plan["directions"]["forward"]["simulated_arrangement"] == "laid at cable.positions"
    # the report's inputs list the places; its engine text says the lay, not "simulated as"
    from exucable.plan.report import plan_report_html

    assert plan["inputs"]["positions_m"] == [list(p) for p in sc.cable.positions_m]
    page = plan_report_html(plan, "t")
    assert "cables laid at (horizontal, up) from the duct&#x27;s axis (cable.positions)" in page
    assert "simulated laid at cable.positions forward" in page and "simulated as laid" not in page
