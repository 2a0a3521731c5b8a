"""The steady bundle's start (exucable/model/bundle.py, ``start_path``): the bundle's centroid on the
path of the rope with clearance, the arrangement turned with it.

The case: the 90° bend of tests/test_bundle_gravity_bend.py (three 30 mm cables, triangular, in a
100 mm duct, 5 m radius between 3 m straights, μ 0.3, gravity) at 1000 N back tension, where the
free spans before the bend are ~1.5 m long (√(2TΔ/w), T the share's tension, Δ the centroid's
clearance, w one cable's weight) and the old start, hugging the duct's bottom up to the bend and
rolling there, took twice the Newton iterations (``benchmarks/bundle_start.py``).

References: geometry (every cable inside the duct and clear of the others, by the rigid circles'
radii) and, for the solved pull, the calculators' bundle on the path of the rope with clearance
(``exucable.quasistatic.clearance``, no Exudyn) bracketed between one cable's clearance and the
triangle's, widened by 0.5 % for the bending stiffness at the bend's ends and the rolls, as in
tests/test_bundle_gravity_bend.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import exucable as xc
from exucable.model.bundle import build_bundle_model
from exucable.quasistatic import engineering as eng
from exucable.quasistatic.clearance import solve_rope_with_clearance
from exucable.solve.steady import solve_steady

R_CABLE, R_DUCT, DENSITY, MU, G = 0.015, 0.05, 2000.0, 0.3, 9.81
BACK_TENSION_N = 1000.0


def scenario(route=None, back_tension_N=BACK_TENSION_N):
    route = route or xc.Route(inner_radius=R_DUCT).straight(3.0).bend(90, radius=5.0, turn="left").straight(3.0)
    return xc.Scenario(route=route,
                       cable=xc.Cable(radius=R_CABLE, density=DENSITY, youngs_modulus=2e8, count=3,
                                      arrangement="triangular"),
                       contact=xc.Contact(friction=MU, check_points_per_element=8),
                       pull=xc.Pull(speed=0.1, back_tension=back_tension_N), gravity=xc.Gravity(g=G),
                       solver=xc.Solver(mode="steady", steady_lead_out=0.0))


@pytest.fixture(scope="module")
def models():
    return {start: build_bundle_model(scenario(), start_path=start) for start in ("clearance", "axis")}


def _offsets(model):
    """Each cable's node offsets from the duct's axis at the node's place [m], shape (n, nodes, 3),
    inside the conduit only (the leading node may lie beyond the exit)."""
    centre = model.conduit.centreline
    out = []
    for lay in model.layout.cables:
        s = lay.node_s_m
        inside = (s >= 0.0) & (s <= centre.length_m)
        out.append(lay.coordinates[inside, :3] - np.asarray(centre.point(s[inside])))
    return np.stack(out)


def test_the_start_lies_inside_the_duct_and_the_cables_clear_of_each_other(models):
    """At every node each cable's axis is at most R − r from the duct's axis and at least 2r from the
    other cables' nodes of the same index (the rigid circles; 1 µm for round-off): the start the
    solve relaxes has no penetration to undo."""
    off = _offsets(models["clearance"])
    assert np.max(np.linalg.norm(off, axis=2)) <= R_DUCT - R_CABLE + 1e-6
    for i in range(3):
        for j in range(i + 1, 3):
            assert np.min(np.linalg.norm(off[i] - off[j], axis=1)) >= 2 * R_CABLE - 1e-6


def calculators_pull_N(centre, clearance_m: float) -> float:
    """Each cable's share one rope with μ·w_c and back tension T_b/3 on the path of the rope with
    clearance ``clearance_m`` [m], times three [N]."""
    w = DENSITY * math.pi * R_CABLE ** 2 * G
    wc = eng.weight_correction_factor(3, "triangular", 2 * R_DUCT, 2 * R_CABLE)
    rope = solve_rope_with_clearance(centre, clearance_m, MU * wc, w, BACK_TENSION_N / 3, cable_length_m=centre.length_m)
    return 3.0 * rope.pull_force_N


def test_from_the_path_the_bend_solves_to_the_calculators_bracket(models):
    """The solve from the path ends ``ok`` with the pull between the calculators' bundle on one
    cable's clearance path and on the triangle's, ±0.5 % (the module's note)."""
    model = models["clearance"]
    out = solve_steady(model)
    assert out.status == "ok", out.message
    F = float(np.sum(model.pull_shares_N()))
    centre = model.conduit.centreline
    lo, hi = sorted((calculators_pull_N(centre, R_DUCT - R_CABLE),
                     calculators_pull_N(centre, R_DUCT - R_CABLE * (1.0 + 2.0 / math.sqrt(3.0)))))
    assert lo * (1 - 5e-3) <= F <= hi * (1 + 5e-3)


def test_the_statics_start_lies_inside_the_duct_and_the_cables_clear_of_each_other():
    """``start_path = "statics"`` on the bend and on the up-bend of ``studies/bundle_upbend_study.py``
    (30°, 5 m radius, 300 N back tension), where its cables cross the duct: in 200 planes across the
    duct every cable's axis is at most R − r from the duct's axis and at least 2r from the others'
    (20 µm: the cubic elements between the nodes laid on the statics' rests)."""
    from exucable.model.bundle import bundle_cross_sections

    up = xc.Route(inner_radius=R_DUCT).straight(3.0).bend(30, radius=5.0, turn="up").straight(3.0)
    for sc in (scenario(), scenario(up, 300.0)):
        model = build_bundle_model(sc, start_path="statics")
        L = model.conduit.centreline.length_m
        x = bundle_cross_sections(model, np.linspace(0.05, L - 0.05, 200))          # (200, 3, 2)
        assert np.max(np.hypot(x[..., 0], x[..., 1])) <= R_DUCT - R_CABLE + 2e-5
        for i in range(3):
            for j in range(i + 1, 3):
                assert np.min(np.hypot(*(x[:, i] - x[:, j]).T)) >= 2 * R_CABLE - 2e-5


def test_an_unknown_start_is_refused_naming_the_choices():
    with pytest.raises(xc.ModelError, match="statics"):
        build_bundle_model(scenario(), start_path="rolled")
