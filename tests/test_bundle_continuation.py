"""The steady continuation's rules for several cables (exucable/solve/steady.py, module notes).

Where a bundle's loads' ramp stalls, its friction alone is ramped from the best state reached: with
gravity and the end forces ramped to zero the cables float in the duct (their equilibrium is
singular) and a ramp from λ = 0 stalled there. One cable keeps every rule it had (its whole load
ramp, from the start). Coarse models: 8 elements of 0.5 m.
"""

from __future__ import annotations

import numpy as np
import pytest

import exucable as xc
from exucable.model.build import build_model
from exucable.model.bundle import build_bundle_model
from exucable.solve.steady import SteadySolver

D_CABLE, MU = 0.03, 0.3


def duct(count):
    cable = dict(radius=D_CABLE / 2, density=2000.0, youngs_modulus=2e8, elements=8)
    if count > 1:
        cable.update(count=count, arrangement="triangular")
    return xc.Scenario(route=xc.Route(inner_radius=3.3 * D_CABLE / 2).straight(4.0), cable=xc.Cable(**cable),
                       contact=xc.Contact(friction=MU, check_points_per_element=8),
                       pull=xc.Pull(speed=0.1, back_tension=30.0 * count), gravity=xc.Gravity(g=9.81),
                       solver=xc.Solver(mode="steady", end_time=1.0, steady_lead_out=0.0))


def test_a_bundles_load_ramp_scales_its_friction_only():
    model = build_bundle_model(duct(3))
    solver = SteadySolver(model)
    solver.friction_only = True          # as ramp_loads(..., friction_only=True) sets it
    solver.at_scale(0.25)
    assert model.load_scale.gravity == 1.0 and model.load_scale.end_force == 1.0
    assert all(k.law.friction == pytest.approx(0.25 * MU, rel=1e-15) for k in model.walls)
    # the weight: each cable's compiled element at full gravity (solver.cable_element's default)
    assert all(c.cable_forces.gravity_scale == 1.0 for c in model.wall_couplings)


def test_one_cables_load_ramp_scales_every_load():
    model = build_model(duct(1))
    solver = SteadySolver(model)
    solver.at_scale(0.25)
    assert model.load_scale.gravity == 0.25 and model.load_scale.end_force == 0.25
    assert model.kernel.law.friction == pytest.approx(0.25 * MU, rel=1e-15)


def test_a_bundle_restarts_from_its_best_state_one_cable_from_the_start():
    bundle = SteadySolver(build_bundle_model(duct(3)))
    assert bundle.restart_state() is bundle.start          # nothing accepted yet
    best = (np.zeros(3), np.zeros(1), None)
    bundle.best = (1.0, best)
    assert bundle.restart_state() is best
    one = SteadySolver(build_model(duct(1)))
    one.best = (1.0, best)
    assert one.restart_state() is one.start



def _step_m(solver, c):
    """The largest nodal move [m] along and across the cables' tangents of a one-iteration step at
    spring rate ``c`` [1/s²] from the start, at the spring's axial share now."""
    ok, _, _ = solver.pseudo_step(c, solver.one_iteration_settings)
    assert ok
    model = solver.model
    q0 = solver.store.saved[0][model.ode2_index]
    dq = (np.array(model.mbs.systemData.GetODE2Coordinates())[model.ode2_index] - q0).reshape(-1, 6)[:, :3]
    slope = (model.layout.coordinates.reshape(-1) + q0).reshape(-1, 6)[:, 3:]
    t = slope / np.linalg.norm(slope, axis=1, keepdims=True)
    along = np.einsum("ki,ki->k", dq, t)
    return float(np.abs(along).max()), float(np.linalg.norm(dq - along[:, None] * t, axis=1).max())


def test_a_bundles_rejections_take_back_the_axial_release():
    # the 100 m route's stall: steps accepted and rejected in turn, each accepted one releasing the
    # spring's axial share by 4; with a rejection only quadrupling the rate the share fell to
    # 0.25^23 = 1.4e-14 and a retried step stayed 28 mm long along the cables with the spring a
    # million times stiffer (7 nm across). stiffen() takes one release back per rejection.
    solver = SteadySolver(build_bundle_model(duct(3)))
    s = solver.settings
    c = solver.c0
    for _ in range(23):
        c /= s.rate_fall_after_reject                 # accepted after a rejection (relax_one_iteration)
        solver.spring.axial_share *= s.axial_release
        c = solver.stiffen(c)                         # the next one rejected
    assert solver.spring.axial_share == s.axial_share
    c = 1e3 * solver.c0
    along, across = _step_m(solver, c)
    solver.spring.axial_share = s.axial_share * s.axial_release ** 23
    along_released, _ = _step_m(solver, c)
    assert along_released > 1e-4                     # the start's axial misfit, nothing holding it
    assert along < 1e-3 * along_released and across < 1e-6


def test_one_cables_rejection_only_stiffens_the_rate():
    solver = SteadySolver(build_model(duct(1)))
    solver.spring.axial_share = 1e-6
    assert solver.stiffen(2.0) == 8.0 and solver.spring.axial_share == 1e-6


def test_the_relaxation_hands_over_early_then_lower(monkeypatch):
    """SteadySolver.relax_dynamic's ladder: the relaxation hands its state to the one-iteration
    continuation at bundle_relax_handover stop tolerances; where that fails, it goes on from its
    state to a residual bundle_relax_handover_fall times smaller, down to bundle_relax_within;
    every phase after starts from the last relaxed state."""
    import exucable.solve.relax as rx

    solver = SteadySolver(build_bundle_model(duct(3)))
    s, tol = solver.settings, solver.tolerance_N
    targets, relaxed = [], []
    real = rx.relax_bundle

    def recorded(model, settings, *a, **k):
        targets.append(settings.residual_N)
        out = real(model, settings, *a, **k)
        relaxed.append(out.q.copy())
        return out

    monkeypatch.setattr(rx, "relax_bundle", recorded)
    answers = iter([(False, "stalled"), (False, "stalled"), (True, "")])
    monkeypatch.setattr(solver, "relax_one_iteration", lambda lam: next(answers))
    ok, note = solver.relax_dynamic("the one-iteration steps from the start failed")
    assert ok, note
    assert targets == pytest.approx([s.bundle_relax_handover * tol, s.bundle_relax_handover * tol / s.bundle_relax_handover_fall,
                                     s.bundle_relax_within * tol], rel=1e-12)
    assert solver.relaxation.residual_N <= s.bundle_relax_within * tol
    assert np.array_equal(solver.start[0][solver.model.ode2_index], relaxed[-1])
    assert solver.relaxation.steps >= 1


def test_a_handover_residual_that_does_not_fall_is_refused():
    from exucable.errors import SolverError
    from exucable.solve.steady import SteadySettings

    with pytest.raises(SolverError, match="bundle_relax_handover_fall"):
        SteadySettings(bundle_relax_handover_fall=1.0)


def test_relaxation_masses_other_than_diagonal_or_frame_are_refused():
    from exucable.errors import SolverError
    from exucable.solve.steady import SteadySettings

    assert SteadySettings(bundle_relax_masses="frame").bundle_relax_masses == "frame"
    with pytest.raises(SolverError, match="bundle_relax_masses"):
        SteadySettings(bundle_relax_masses="block")


def test_the_relaxation_takes_the_settings_masses(monkeypatch):
    """SteadySettings.bundle_relax_masses reaches relax_bundle's ``masses`` (the default "diagonal")."""
    import exucable.solve.relax as rx
    from exucable.solve.steady import SteadySettings

    kinds = []
    real = rx.relax_bundle

    def recorded(model, settings, *a, **k):
        kinds.append(k.get("masses"))
        return real(model, settings, *a, **k)

    monkeypatch.setattr(rx, "relax_bundle", recorded)
    for kind in ("diagonal", "frame"):
        solver = SteadySolver(build_bundle_model(duct(3)), SteadySettings(bundle_relax_masses=kind))
        monkeypatch.setattr(solver, "relax_one_iteration", lambda lam: (True, ""))
        assert solver.relax_dynamic("the one-iteration steps from the start failed")[0]
    assert kinds == ["diagonal", "frame"]
