"""Block Gauss–Seidel by cable (exucable/solve/block_sweeps.py): what it converges to, how fast against
the linear theory, and its settings' checks. Coarse straight ducts of tests/test_bundle_continuation.py
(8 elements of 0.5 m, D/d 3.3, μ 0.3, gravity)."""

from __future__ import annotations

import numpy as np
import pytest

from exucable.errors import SolverError
from exucable.model.bundle import build_bundle_model
from exucable.solve.block_sweeps import BlockSweepSettings, block_sweeps, node_block_masses, sweep_order
from exucable.solve.steady import PseudoTimeSpring, SteadySettings, SteadySolver
from exucable.solve.onset_continuation import OnsetSettings

from test_bundle_continuation import duct


def cradle():
    return build_bundle_model(duct(3).replace(**{"cable.arrangement": "cradled"}))


def gauss_seidel_radius(model, q) -> float:
    """Spectral radius of the linear block Gauss–Seidel iteration −(D + L)⁻¹ U on the bundle's
    stiffness K = −∂f/∂q at ``q`` (free coordinates; blocks by cable, in the sweep's order): the
    rate at which the sweeps' error falls per sweep near the solution."""
    rows, cols, blocks = model.stiffness_blocks3(q)
    n = model.ode2_index.size
    K = np.zeros((n, n))
    for r, c, b in zip(rows, cols, blocks):
        K[3 * r:3 * r + 3, 3 * c:3 * c + 3] += b
    free = np.ones(n, dtype=bool)
    free[model.held_coordinates()] = False
    rank = np.empty(model.n_cables, dtype=int)
    rank[sweep_order(model, "bottom_first")] = np.arange(model.n_cables)
    turn = rank[np.repeat(np.arange(model.n_cables), n // model.n_cables)][free]
    Kf = K[free][:, free]
    lower = turn[:, None] >= turn[None, :]
    G = -np.linalg.solve(np.where(lower, Kf, 0.0), np.where(lower, 0.0, Kf))
    return float(np.max(np.abs(np.linalg.eigvals(G))))


def test_the_sweeps_bring_a_straight_cradle_to_the_coupled_solves_state():
    # every cable on the wall: each cable's block is stiff across the duct, the sweeps contract by
    # ~0.23 per sweep until the collective mode (below) is what is left
    model = cradle()
    solver = SteadySolver(model)
    q0 = solver.start[0][model.ode2_index]
    out = block_sweeps(model, q0, solver.c0, BlockSweepSettings(residual_N=solver.tolerance_N, max_sweeps=40,
                                                                stall_sweeps=40))
    assert out.converged, out.message
    assert out.residual_N <= solver.tolerance_N
    trace = [row["residual_N"] for row in out.trace]
    assert trace[0] > 1e4 * trace[-1]
    # the same state as the coupled steady solve's (another path: the onset layer's continuation from
    # the rope start), within what the stop tolerance allows (|Δq| ≤ |f| / λ_min(K))
    other = cradle()
    reference = SteadySolver(other, SteadySettings(), onset=OnsetSettings()).solve()
    assert reference.status == "ok", reference.message
    q_ref = np.array(other.mbs.systemData.GetODE2Coordinates())[other.ode2_index]
    assert np.max(np.abs(out.q - q_ref)) < 2e-5


@pytest.mark.parametrize("count, arrangement", [(2, "triangular"), (3, "triangular")])
def test_a_triangle_stalls_at_the_linear_gauss_seidel_rate(count, arrangement):
    # two cables side by side on the wall can roll round the duct together, resisted by their weight
    # alone, while each one alone is held by the other's contact: the block Gauss–Seidel iteration's
    # spectral radius is then 1 − O(k_weight / k_contact), and the sweeps' residual falls by that
    # per sweep (measured 0.991-0.995 against a radius of 0.9996-0.9997: the slowest mode not yet alone)
    model = build_bundle_model(duct(count).replace(**{"cable.arrangement": arrangement}))
    solver = SteadySolver(model)
    out = block_sweeps(model, solver.start[0][model.ode2_index], solver.c0,
                       BlockSweepSettings(residual_N=1e-9, max_sweeps=20, stall_sweeps=40))
    assert not out.converged and out.sweeps == 20
    trace = [row["residual_N"] for row in out.trace]
    assert trace[-1] < 0.1 * trace[0]            # the cables' own misfit is gone ...
    rate = trace[-1] / trace[-2]
    rho = gauss_seidel_radius(model, out.q)
    assert 0.98 < rate < 1.0 and rate < rho < 1.0   # ... what is left falls at the linear rate


@pytest.mark.parametrize("count", [2, 3])
def test_a_coarse_correction_on_the_cross_sections_rigid_motion_lets_the_triangle_converge(count):
    # the slow mode above is the cross-section moving rigidly; a Galerkin step on those motions after
    # each sweep (Eq. GS 3) removes it, and the sweeps reach the stop tolerance (2: 13 sweeps, 3: 30)
    model = build_bundle_model(duct(count))
    solver = SteadySolver(model)
    out = block_sweeps(model, solver.start[0][model.ode2_index], solver.c0,
                       BlockSweepSettings(residual_N=solver.tolerance_N, max_sweeps=40, stall_sweeps=40, coarse_steps=6))
    assert out.converged, out.message
    assert out.sweeps <= 35
    coarse = [b for row in out.trace for b in row["blocks"] if b[0] == -1]
    assert coarse and all(after <= before for _, before, after, _ in coarse)   # never raises the residual


def test_the_masses_are_the_pseudo_time_springs():
    model = cradle()
    spring = PseudoTimeSpring(model)
    assert np.array_equal(node_block_masses(model), spring.block_mass)
    Le = model.layout.element_length_m
    rho_a = model.properties.mass_per_length_kg_per_m
    assert node_block_masses(model)[1, 0] == pytest.approx(rho_a * Le[0])      # an inner node: ρA L_e
    assert node_block_masses(model)[0, 1] == pytest.approx(0.5 * rho_a * Le[0] ** 3)


def test_bottom_cables_sweep_first():
    model = build_bundle_model(duct(3))         # triangular: cables 1, 2 on the wall, 3 on them
    assert sweep_order(model, "bottom_first") == [0, 1, 2]
    assert sweep_order(model, "index") == [0, 1, 2]
    cradled = cradle()                           # the middle one lowest
    assert sweep_order(cradled, "bottom_first")[0] == 1


def test_the_solve_with_sweeps_first_reaches_the_same_pull():
    a, b = cradle(), cradle()
    plain = SteadySolver(a, SteadySettings(), onset=OnsetSettings()).solve()
    swept_solver = SteadySolver(b, SteadySettings(bundle_block_sweeps=4), onset=OnsetSettings())
    swept = swept_solver.solve()
    assert plain.status == swept.status == "ok", swept.message
    assert swept_solver.sweeps is not None and swept_solver.sweeps.sweeps >= 1
    assert "block sweeps by cable" in swept.message
    assert b.steady_forces()[0] == pytest.approx(a.steady_forces()[0], rel=1e-6)


@pytest.mark.parametrize("field, value", [("relaxation", 1.5), ("relaxation", 0.0), ("max_sweeps", -1),
                                          ("order", "top"), ("later_axial_share", 2.0),
                                          ("coarse_steps", -2)])
def test_bad_settings_are_refused_naming_the_field(field, value):
    with pytest.raises(SolverError, match=f"BlockSweepSettings.{field}"):
        BlockSweepSettings(**{field: value})


def test_a_wrong_state_size_is_refused():
    model = cradle()
    with pytest.raises(SolverError, match="coordinates given"):
        block_sweeps(model, np.zeros(6), 1.0)
