"""What a bundle run reports (exucable/post/bundle.py, exucable/model/bundle.py's bundle_sections):
the cables' places across the duct, the arrangement, the jam, the figure.

References: rigid-circle geometry built by hand (three cables wedged in a line across the duct for
2.4 < D/d ≤ 3, the middle one off the line by √(d² − ρ²), ρ = (D − d)/2), the calculators'
arrangements from :func:`exucable.model.bundle.arrangement_offsets` (tested against touching
circles in tests/test_bundle.py), a cable laid exactly on a concentric arc. Coarse straight ducts
(8 elements of 0.5 m) for the solved states.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import exucable as xc
from exucable.geometry.centreline import Centreline, Piece
from exucable.model.bundle import arrangement_offsets
from exucable.post.bundle import classify_cross_section, cross_section_offsets
from exucable.quasistatic import engineering as eng

D_CABLE = 0.03
R_CABLE = D_CABLE / 2


def rotate(p, angle_deg):
    a = math.radians(angle_deg)
    m = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    return np.asarray(p) @ m.T


@pytest.mark.parametrize("count, arrangement, ratio, expected", [
    (3, "triangular", 2.4, "triangular"), (3, "triangular", 3.3, "triangular"), (3, "cradled", 2.8, "cradled"),
    (3, "cradled", 3.3, "cradled"), (2, "triangular", 3.0, "side_by_side"), (4, "cradled", 3.5, "cradled"),
    (4, "diamond", 2.6, "diamond")])
def test_the_laid_arrangements_are_recognised(count, arrangement, ratio, expected):
    """The rigid circles at rest of each arrangement are classified as that arrangement, none wedged."""
    R = ratio * R_CABLE
    c = classify_cross_section(arrangement_offsets(count, arrangement, R, R_CABLE), R, R_CABLE)
    assert c["arrangement"] == expected
    assert not c["wedged"]


@pytest.mark.parametrize("ratio", [2.5, 2.8, 2.9, 3.0])
@pytest.mark.parametrize("turn", [0.0, 37.0, 90.0])
def test_three_in_a_line_across_the_duct_is_a_jam(ratio, turn):
    """Outer cables on opposite walls, the middle one touching both and held off the wall: wedged,
    whichever way the line lies across the duct (in a bend it lies across the bend's plane)."""
    R = ratio * R_CABLE
    rho = R - R_CABLE
    y = math.sqrt(max(D_CABLE**2 - rho**2, 0.0))
    p = rotate([[-rho, 0.0], [0.0, -y], [rho, 0.0]], turn)
    c = classify_cross_section(p, R, R_CABLE)
    assert c["arrangement"] == "side_by_side" and c["wedged"]
    assert c["on_wall"] == [True, False, True]
    assert c["touching"] == [[1, 2], [2, 3]]


def test_a_line_with_room_to_spare_and_a_loose_cable_are_not_jams():
    """D/d = 3.3: three in a line cannot touch both walls and each other (gaps): apart, no jam.
    A top cable resting on two bottom ones pushed apart: triangular, no jam."""
    R = 3.3 * R_CABLE
    rho = R - R_CABLE
    c = classify_cross_section([[-rho, 0.0], [-rho + D_CABLE, 0.0], [rho, 0.0]], R, R_CABLE)
    assert c["arrangement"] == "apart" and not c["wedged"]
    a, b = [-0.9 * rho * math.sin(0.6), -rho * math.cos(0.6)], [0.9 * rho * math.sin(0.6), -rho * math.cos(0.6)]
    a[1] = b[1] = -math.sqrt(rho**2 - a[0] ** 2)          # both on the wall
    top = [0.0, a[1] + math.sqrt(D_CABLE**2 - a[0] ** 2)]
    c = classify_cross_section([a, top, b], R, R_CABLE)
    assert c["arrangement"] == "triangular" and not c["wedged"]
    # a chain hanging from a cable on the top of the wall, 60° either side of the vertical: loose
    h, v = D_CABLE * math.sin(math.radians(60)), D_CABLE * math.cos(math.radians(60))
    c = classify_cross_section([[-h, rho - v], [0.0, rho], [h, rho - v]], R, R_CABLE)
    assert c["arrangement"] == "loose" and not c["wedged"]
    assert c["on_wall"] == [False, True, False] and c["touching"] == [[1, 2], [2, 3]]


def test_the_jam_range_is_the_calculators():
    """NEC Chapter 9 Table 1 Informational Note 2: 2.8 ≤ D/d ≤ 3.2, three cables only."""
    assert eng.JAM_RANGE_D_OVER_d == (2.8, 3.2)
    assert eng.in_jam_range(3, 0.09, 0.03) and not eng.in_jam_range(3, 0.1, 0.03)
    assert not eng.in_jam_range(4, 0.09, 0.03)


def _cable_on(points, tangents, spacing):
    """ANCF coordinates (n, 6) of a cable through ``points`` with unit slopes ``tangents``."""
    return np.hstack([points, tangents]), np.full(len(points) - 1, spacing)


def test_cross_section_offsets_on_a_straight_and_a_bend():
    """A cable laid 12 mm left of and 5 mm below the axis of a straight, and on the arc 20 mm
    inside a 2 m bend (the chord between nodes sags 0.8 mm: the Hermite shape must not), is found
    there: exactly on the straight, to 2e-6 m in the bend (a cubic through 0.2 rad of arc with
    its end tangents departs from the arc by 1.4e-6 m)."""
    straight = Centreline([Piece.straight(0.0, [0, 0, 0], [1, 0, 0], 4.0)])
    x = np.linspace(-0.2, 4.2, 12)
    q, Le = _cable_on(np.column_stack([x, np.full_like(x, 0.012), np.full_like(x, -0.005)]),
                      np.tile([1.0, 0.0, 0.0], (x.size, 1)), x[1] - x[0])
    offs = cross_section_offsets([q], Le, straight, [0.5, 2.0, 3.9])
    np.testing.assert_allclose(offs[:, 0, :], [[-0.012, -0.005]] * 3, atol=1e-9)   # horizontal points right
    R_bend, inside = 2.0, 0.02
    bend = Centreline([Piece.arc(0.0, [0, 0, 0], [1, 0, 0], [0, 0, 1], R_bend, math.pi / 2)])
    th = np.linspace(-0.1, math.pi / 2 + 0.1, 18)     # elements of 0.2 rad: chord sag R θ²/8 = 0.8 mm
    rad = R_bend - inside
    pts = np.column_stack([rad * np.sin(th), R_bend - rad * np.cos(th), np.zeros_like(th)])
    tan = np.column_stack([np.cos(th), np.sin(th), np.zeros_like(th)])
    q, Le = _cable_on(pts, tan, rad * (th[1] - th[0]))
    offs = cross_section_offsets([q], Le, bend, np.linspace(0.1, R_bend * math.pi / 2 - 0.1, 5))
    # a left turn: the bend's centre is to the left of the pull (horizontal points right), up is up
    np.testing.assert_allclose(offs[:, 0, 0], -inside, atol=2e-6)
    np.testing.assert_allclose(offs[:, 0, 1], 0.0, atol=1e-9)


def test_a_place_the_cable_does_not_reach_is_nan():
    straight = Centreline([Piece.straight(0.0, [0, 0, 0], [1, 0, 0], 4.0)])
    x = np.linspace(1.0, 2.0, 3)
    q, Le = _cable_on(np.column_stack([x, 0 * x, 0 * x]), np.tile([1.0, 0.0, 0.0], (3, 1)), 0.5)
    assert np.isnan(cross_section_offsets([q], Le, straight, [3.0])).all()


def straight_duct(arrangement, ratio, **output):
    return xc.Scenario(route=xc.Route(inner_radius=ratio * R_CABLE).straight(4.0),
                       cable=xc.Cable(radius=R_CABLE, density=2000.0, youngs_modulus=2e8, count=3,
                                      arrangement=arrangement, elements=8),
                       contact=xc.Contact(friction=0.3, check_points_per_element=8),
                       pull=xc.Pull(speed=0.1, back_tension=30.0), gravity=xc.Gravity(g=9.81),
                       solver=xc.Solver(mode="steady", end_time=1.0, steady_lead_out=0.0),
                       output=xc.Output(**output))


@pytest.mark.parametrize("arrangement, ratio", [("triangular", 2.4), ("cradled", 3.3)])
def test_a_solved_straight_reports_its_arrangement_and_no_jam(tmp_path, arrangement, ratio):
    """Three cables in a horizontal straight under gravity stay as laid: every station of the
    straight is classified so, no jam (an explicit false, not a missing key), the figure is written."""
    res = xc.run(straight_duct(arrangement, ratio, cross_sections=[1.0, 3.0]), out_dir=tmp_path)
    assert res.status == "ok"
    b = json.loads((tmp_path / "summary.json").read_text())["bundle"]
    (row,) = b["sections"]
    assert row["kind"] == "straight" and row["arrangement"] == arrangement
    assert row["arrangements_seen"] == {arrangement: 9}
    assert b["jam"] is False and row["jam"] is False and b["jam_s_conduit_m"] is None
    assert b["duct_over_cable_diameter"] == pytest.approx(ratio)
    assert [x["s_conduit_m"] for x in b["cross_sections"]] == [1.0, 3.0]
    for x in b["cross_sections"]:
        # the cables sit where the rigid circles at rest do, to the Hertz penetration (~µm)
        np.testing.assert_allclose(x["offsets_m"], arrangement_offsets(3, arrangement, ratio * R_CABLE, R_CABLE),
                                   atol=1e-4)
    assert b["bends"] == []
    assert (tmp_path / "cross_sections.png").stat().st_size > 0


def test_plan_simulates_a_bundle_with_the_calculators_values_beside():
    """`plan --engine steady` with three cables: each direction's tensions are the simulated bundle's
    (the straight's tension out is the bundle's pull force), the calculators' (the rope with w_c)
    beside; `auto` stays the rope for bundles and says why; the dynamic engine is refused naming
    cable.count."""
    from exucable.errors import ScenarioError
    from exucable.plan.pull import plan_pull, plan_spec, resolve_engine

    sc = straight_duct("cradled", 3.3)
    plan = plan_pull(sc, plan_spec(sc), engine="steady")
    assert plan["engine"] == "steady" and plan["count"] == 3
    for name in ("forward", "reverse"):
        d = plan["directions"][name]
        assert d["status"] == "ok"
        (row,) = d["sections"]
        # each cable's tension from its loads' equilibrium meets its end forces: T_b/n at the trailing
        # ends; at the eye t·F of its reaction F, the pull share e·F along the exit line e. The two differ
        # by the eye's lateral hold times the end's tilt |t − e| (measured 1.2e-5 relative), hence 1e-4
        assert row["tension_in_N"] == pytest.approx(30.0, rel=1e-9)
        assert row["tension_out_N"] == pytest.approx(d["pull_force_N"], rel=1e-4)
        assert row["rope_tension_out_N"] == pytest.approx(d["rope_pull_force_N"], rel=1e-12)
        b = d["bundle"]
        assert b["formula_weight_correction_factor"] == plan["weight_correction_factor"]
        assert b["sections"][0]["arrangement"] == "cradled" and b["jam"] is False
        # the run's error bar carried over (exucable.solve.error_bar.bundle_error_bar), with its method
        assert 0.0 < d["pull_force_uncertainty_N"] < 0.05 * d["pull_force_N"]
        assert "coarser" in d["pull_force_uncertainty_method"] or "mesh part not measured" in d["pull_force_uncertainty_method"]
    engine, rule = resolve_engine("auto", 3)
    assert engine == "rope" and "bends" in rule
    with pytest.raises(ScenarioError) as err:
        plan_pull(sc, plan_spec(sc), engine="dynamic")
    assert err.value.key == "cable.count"


def test_a_bend_reports_its_arrangement_and_the_pressure_beside_the_formula():
    """Three cables (cradled at the start) through a 30° bend of 1 m radius without gravity: the
    steady state is found; the bend's row names its most loaded cable and the calculators' SWBP
    f_rad·T_out/R on the simulated exit tension; along every cable the pull minus the back tension
    is the wall's friction μ ΣN (frictionless between the cables; what bending stiffness adds through
    the shear at the bend's ends is measured -0.27 %, tolerance 1 %)."""
    route = xc.Route(inner_radius=2.9 * R_CABLE).straight(1.0).bend(30, radius=1.0, turn="left").straight(1.0)
    sc = xc.Scenario(route=route, cable=xc.Cable(radius=R_CABLE, density=2000.0, youngs_modulus=2e8, count=3,
                                                 arrangement="cradled", elements=12),
                     contact=xc.Contact(friction=0.3, check_points_per_element=8), pull=xc.Pull(speed=0.1, back_tension=100.0),
                     solver=xc.Solver(mode="steady", steady_lead_out=0.0))
    res = xc.run(sc)
    assert res.status == "ok", res.summary["message"]
    b = res.summary["bundle"]
    (bend,) = b["bends"]
    x = 1.0 / (2.9 - 1.0)
    factor = eng.sidewall_pressure_factor(3, "cradled", 1 + 4 / 3 * x * x)
    assert b["formula_sidewall_pressure_factor"] == pytest.approx(factor, rel=1e-12)
    assert bend["formula_pressure_N_per_m"] == pytest.approx(factor * bend["tension_out_N"] / 1.0, rel=1e-12)
    assert bend["most_loaded_cable"] in (1, 2, 3) and bend["peak_pressure_N_per_m"] > 0
    assert [r["kind"] for r in b["sections"]] == ["straight", "bend", "straight"]
    assert b["jam"] is False
    F, wall = res.pull_force_N, sum(c["wall_normal_force_N"] for c in b["cables"])
    assert F - 100.0 == pytest.approx(0.3 * wall, rel=1e-2)


def test_a_plan_whose_bundle_does_not_solve_in_its_budget_fails_cleanly(monkeypatch):
    """A bundle's steady solve given no CPU time at all: each direction's status is failed with the
    budget named in its message, the calculators' sections are kept beside, and the plan's
    multibody_run check fails (no number passes on an unsolved bundle)."""
    import exucable.plan.pull as pull

    monkeypatch.setattr(pull, "BUNDLE_CPU_BUDGET_S", 0.0)
    sc = straight_duct("cradled", 3.3)
    plan = pull.plan_pull(sc, pull.plan_spec(sc), engine="steady")
    for d in plan["directions"].values():
        assert d["status"] == "failed" and "CPU budget" in d["message"] and "--engine rope" in d["message"]
        assert d["sections"][0]["tension_out_N"] == d["rope_pull_force_N"]
        assert d["bundle"]["weight_correction_factor"] is None      # no simulated number from an unsolved state
        assert d["pull_force_uncertainty_N"] is None and "failed" in d["pull_force_uncertainty_method"]
        (check,) = [c for c in d["checks"] if c["name"] == "multibody_run"]
        assert not check["passed"]
    assert not plan["passed"]
