"""A steady bundle with the compiled ANCF cable element (``solver.cable_element = "compiled"``,
exucable/contact/ancf_cable.py in each cable's wall coupling) against Exudyn's ``ObjectANCFCable``.

Reference: Exudyn's own element and its mass-proportional weight, in the same model otherwise. The
compiled element is tested equal to Exudyn's element (tests/test_ancf_compiled.py); here the
handover of several cables' blocks and weights (one coupling per cable, the load scale setting
every cable's weight) is checked by solving, on coarse meshes (8 elements of 0.5 m, 8 check points
each): the same Newton iterations and pull shares to 1e-9 on a straight. Both models leave out the
cable's Kelvin-Voigt damping in steady mode (Exudyn's element applied it to the start's sliding rates:
7e-6 of the pull shares).
"""

from __future__ import annotations

import numpy as np
import pytest

import exucable as xc
from exucable.model.bundle import build_bundle_model
from exucable.solve.steady import SteadySettings, solve_steady

D_CABLE = 0.03


def bundle(route, ratio=3.0, **solver):
    cable = xc.Cable(radius=D_CABLE / 2, density=2000.0, youngs_modulus=2e8, count=3, arrangement="triangular",
                     elements=8)
    return xc.Scenario(route=route(xc.Route(inner_radius=ratio * D_CABLE / 2)), cable=cable,
                       contact=xc.Contact(friction=0.3, check_points_per_element=8),
                       pull=xc.Pull(speed=0.1, back_tension=30.0), gravity=xc.Gravity(g=9.81),
                       solver=xc.Solver(mode="steady", end_time=1.0, steady_lead_out=0.0, **solver))


def solved(route, element):
    model = build_bundle_model(bundle(route, cable_element=element))
    assert (len(model.cables[0].elements) == 0) == (element == "compiled")
    # the same continuation for both: the dynamic relaxation needs the compiled element's residual
    return solve_steady(model, settings=SteadySettings(bundle_relax_steps=0)), model


def test_compiled_element_solves_a_straight_bundle_as_exudyns():
    """The same Newton iterations (the same iterates to round-off) and pull shares."""
    (a, ma), (b, mb) = (solved(lambda r: r.straight(4.0), e) for e in ("exudyn", "compiled"))
    assert a.status == b.status == "ok", (a.message, b.message)
    assert b.newton_iterations == a.newton_iterations
    np.testing.assert_allclose(mb.pull_shares_N(), ma.pull_shares_N(), rtol=1e-9)
    assert np.abs(ma.coordinates()[0] - mb.coordinates()[0]).max() < 1e-9


def test_compiled_element_solves_an_up_bend_bundle_as_exudyns():
    """Through an up-bend the continuation takes hundreds of iterations and round-off changes its
    path (366 against 377 iterations measured): the same pull shares within 1e-6 relative, the
    level of the stop residual (1e-6 of the largest tension)."""
    route = lambda r: r.straight(1.5).bend(30, radius=2.0, turn="up").straight(1.0)      # noqa: E731
    (a, ma), (b, mb) = (solved(route, e) for e in ("exudyn", "compiled"))
    assert a.status == b.status == "ok", (a.message, b.message)
    np.testing.assert_allclose(mb.pull_shares_N(), ma.pull_shares_N(), rtol=1e-6)


def test_the_load_scale_sets_every_cables_weight():
    """The continuation's gravity scale reaches each cable's compiled weight, not only the first's."""
    model = build_bundle_model(bundle(lambda r: r.straight(4.0)))
    model.load_scale.apply(model.mbs, gravity=0.25, end_force=1.0)
    forces = [c.cable_forces for c in model.wall_couplings]
    assert len(forces) == 3 and all(f.gravity_scale == 0.25 for f in forces)
    assert all(np.allclose(f.weight(), 0.25 * f.weight_N) for f in forces)
