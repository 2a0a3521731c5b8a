"""A bundle's steady solve on our own Newton loop (``OwnBundleNewton``) against Exudyn's static solver.

The reference is Exudyn's ``MainSolverStatic`` on the same bundle model: the same equations (the
walls' couplings, the cable-cable coupling, the end loads, the pseudo-time spring; the eye's
constraints), Newton and stop test, another linear solver (LAPACK's banded LU of the interleaved
order with the eye's coordinates eliminated, against Eigen's SparseLU of the saddle-point system).
So the iterates agree to the round-off of two factorisations of a stiff contact system, not bit for
bit. The small cases of ``studies/bundle_upbend_study.py`` (a 30° bend between two 3 m straights,
three cables, 10 elements each), a few seconds each.
"""

from __future__ import annotations

import numpy as np
import pytest

import exucable as xc
from exucable.model.bundle import build_bundle_model
from exucable.solve.newton_system import (ExudynStatic, OwnBundleNewton, own_bundle_newton_unsupported,
                                          own_newton_unsupported)
from exucable.solve.steady import SteadySettings, SteadySolver, solve_steady, static_settings
from test_own_newton import one_iteration_steps


def scenario(turn: str = "down", arrangement: str = "triangular", time_limit_s: float = 30.0, **solver):
    route = xc.Route(inner_radius=0.05).straight(3.0).bend(30, radius=5.0, turn=turn).straight(3.0)
    return xc.Scenario(route=route,
                       cable=xc.Cable(radius=0.015, density=2000.0, youngs_modulus=2e8, count=3,
                                      arrangement=arrangement),
                       contact=xc.Contact(friction=0.3, check_points_per_element=8),
                       pull=xc.Pull(speed=0.1, back_tension=300.0), gravity=xc.Gravity(g=9.81),
                       solver=xc.Solver(mode="steady", steady_lead_out=0.0, steady_time_limit=time_limit_s,
                                        **solver))


def _iterates(sc, backend: str, steps: int = 4, linear_solver: str = "banded"):
    """Pseudo-time steps of one Newton iteration each from the start (the spring anchored at the
    last state, its rate falling by 8 per step): per step the converged flag, Newton's residual [N],
    the true residual [N], the absolute coordinates, the step's displacement and the eye's multipliers."""
    model = build_bundle_model(sc)
    solver = SteadySolver(model)
    if backend == "exudyn":
        solver.static = ExudynStatic(model.mbs, static_settings)
    elif linear_solver != "banded":
        solver.static = OwnBundleNewton(model, solver.spring, linear_solver=linear_solver)
    assert type(solver.static).__name__ == {"exudyn": "ExudynStatic", "exucable": "OwnBundleNewton"}[backend]
    return one_iteration_steps(model, solver, steps)


@pytest.mark.parametrize("turn", ["up", "down"])
def test_one_iteration_is_exudyns(turn):
    """From the same states, each one-iteration step is Exudyn's: the step within 1e-7 of its size
    (measured ≤ 4e-9 on the 100 m route's settled state, the contacts' stiffness amplifying the two
    LU factorisations' round-off), the eye's multipliers and both residual norms within 1e-7."""
    sc = scenario(turn)
    a, b = _iterates(sc, "exudyn"), _iterates(sc, "exucable")
    for (ok_a, r_a, t_a, _, d_a, l_a), (ok_b, r_b, t_b, _, d_b, l_b) in zip(a, b):
        assert ok_a and ok_b
        assert np.linalg.norm(d_b - d_a) <= 1e-7 * np.linalg.norm(d_a)
        assert np.linalg.norm(l_b - l_a) <= 1e-7 * np.linalg.norm(l_a)
        assert abs(r_b - r_a) <= 1e-7 * r_a and abs(t_b - t_a) <= 1e-7 * t_a


def test_banded_and_sparse_lu_take_the_same_steps():
    """LAPACK's banded LU on the interleaved order and SuperLU solve the same eliminated system."""
    a = _iterates(scenario("up"), "exucable", steps=2)
    b = _iterates(scenario("up"), "exucable", steps=2, linear_solver="splu")
    for (_, _, _, _, d_a, l_a), (_, _, _, _, d_b, l_b) in zip(a, b):
        assert np.linalg.norm(d_b - d_a) <= 1e-9 * np.linalg.norm(d_a)
        assert np.linalg.norm(l_b - l_a) <= 1e-9 * np.linalg.norm(l_a)


@pytest.mark.parametrize("turn, arrangement", [("down", "triangular"), ("up", "cradled")])
def test_whole_steady_solves_equal_exudyns(turn, arrangement):
    """Whole steady solves through the onset layer's continuation: the same status, pulling force
    within 1e-8 relative of Exudyn's static solver's and the same Newton count (one-iteration steps
    accept or reject on the true residual: round-off could only flip a step at its threshold)."""
    pulls, counts = {}, {}
    for choice in ("exudyn", "exucable"):
        sc = scenario(turn, arrangement, static_solver=choice)
        model = build_bundle_model(sc)
        out = solve_steady(model, settings=SteadySettings.from_solver(sc.solver))
        assert out.status == "ok", out.message
        pulls[choice], counts[choice] = float(np.sum(model.pull_shares_N())), out.newton_iterations
    assert abs(pulls["exucable"] / pulls["exudyn"] - 1) < 1e-8, pulls
    assert counts["exucable"] == counts["exudyn"], counts


def test_bundles_ours_cannot_solve_keep_exudyns_solver():
    """Exudyn's cable element in a bundle: Exudyn's static solver, saying why; the one-cable check
    still refuses a bundle, and a bundle is ours by default."""
    model = build_bundle_model(scenario(cable_element="exudyn"))
    assert "Exudyn's elements" in own_bundle_newton_unsupported(model)
    solver = SteadySolver(model)
    assert isinstance(solver.static, ExudynStatic) and "cable_element" in solver.static_note
    with pytest.raises(ValueError, match="cannot solve this bundle"):
        OwnBundleNewton(model, solver.spring)
    ours = build_bundle_model(scenario())
    assert own_newton_unsupported(ours) == "several cables" and own_bundle_newton_unsupported(ours) == ""
    assert isinstance(SteadySolver(ours).static, OwnBundleNewton)
