"""exucable.solve.negative_curvature: the lowest modes of a bundle's stiffness, and steps along them."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from conftest import upbend_bundle_scenario
from exucable.errors import SolverError


def _bundle():
    from exucable.model.bundle import build_bundle_model
    from exucable.solve import steady as st

    model = build_bundle_model(upbend_bundle_scenario())
    solver = st.SteadySolver(model)
    return model, solver


def test_the_lowest_modes_are_those_of_the_dense_problem_on_exudyns_jacobian():
    """Eq. (NC 1)'s lowest eigenvalues by shift-invert Lanczos on the assembled blocks equal those of
    the dense generalized problem on minus Exudyn's own Newton Jacobian (symmetric part, eye's rows held)."""
    from conftest import exudyn_static_residual_jacobian
    from exucable.solve import negative_curvature as nc

    model, solver = _bundle()
    q, _, J = exudyn_static_residual_jacobian(model)
    K = -J
    idx = model.ode2_index
    free = np.ones(idx.size, dtype=bool)
    free[model.held_coordinates()] = False
    mass = np.repeat(solver.spring.block_mass.reshape(-1), 3)
    Kf = 0.5 * (K + K.T)[np.ix_(free, free)]
    want = scipy.linalg.eigh(Kf, np.diag(mass[free]), eigvals_only=True)
    cs = nc.CurvatureSettings(modes=4, shift_per_s2=max(1.0, -2.0 * want[0]))
    lam, U = nc.lowest_modes(model, q, mass, free, cs)
    assert np.allclose(lam, want[:4], rtol=1e-6, atol=1e-6 * np.abs(want).max())
    assert np.all(U[~free] == 0.0)
    # M-orthonormal on the free coordinates
    G = U[free].T @ (mass[free, None] * U[free])
    assert np.allclose(G, np.eye(4), atol=1e-8)


def test_roll_off_steps_downhill_and_restores_the_friction():
    """Each step does positive frictionless work along a negative mode; the held coordinates stay;
    the friction is back at its scale afterwards (the residual at the start bit for bit)."""
    from exucable.solve import negative_curvature as nc

    model, solver = _bundle()
    q = np.array(model.mbs.systemData.GetODE2Coordinates())[model.ode2_index]
    free = np.ones(q.size, dtype=bool)
    free[model.held_coordinates()] = False
    mass = np.repeat(solver.spring.block_mass.reshape(-1), 3)
    f0 = model.steady_force(q)
    q1, lam, steps, _ = nc.roll_off(model, q, mass, free, 1.0)
    for s in steps:
        assert s.eigenvalue_per_s2 < 0.0 and s.work_J > 0.0 and s.move_m > 0.0
    assert np.array_equal(q1[~free], q[~free])
    # the friction is back at its scale: the residual at the start is as before, bit for bit
    assert np.array_equal(model.steady_force(q), f0)


def test_bad_settings_are_refused_by_name():
    from exucable.solve.negative_curvature import CurvatureSettings

    with pytest.raises(SolverError, match="max_move_m"):
        CurvatureSettings(max_move_m=-1.0)
    with pytest.raises(SolverError, match="CurvatureSettings.modes"):
        CurvatureSettings(modes=0)
