"""Dynamic relaxation (exucable/solve/relax.py) against closed forms, and the bundle's residual
outside Exudyn against Exudyn's static residual."""

from __future__ import annotations

import numpy as np
import pytest

from exucable.errors import SolverError
from exucable.solve.relax import (RelaxSettings, block_gershgorin_masses, diagonal_gershgorin_masses,
                                  frame_gershgorin_masses, node_frames, relax)


def chain_problem(n=12, k=2.0e4, m=1.3, g=9.81):
    """n nodes hanging in a vertical chain of linear springs k [N/m] from a held top node (node 0),
    each node's weight m g: the spring above node i carries the weight of the n - i nodes from i down,
    so node i sinks u_i = Σ_{j=1..i} (n - j) m g / k below its unloaded place (a closed form)."""
    nb = n

    def force(q):
        z = q.reshape(n, 3)
        f = np.zeros((n, 3))
        stretch = z[1:] - z[:-1]                      # spring j joins nodes j-1, j
        f[1:] -= k * stretch
        f[:-1] += k * stretch
        f[:, 2] -= m * g
        return f.reshape(-1)

    rows, cols, blocks = [], [], []
    for j in range(1, n):
        for a, b, sign in ((j - 1, j - 1, 1), (j, j, 1), (j - 1, j, -1), (j, j - 1, -1)):
            rows.append(a), cols.append(b), blocks.append(sign * k * np.eye(3))
    free = np.ones(3 * n, dtype=bool)
    free[:3] = False
    exact = np.zeros((n, 3))
    exact[:, 2] = -np.concatenate([[0.0], np.cumsum([(n - j) * m * g / k for j in range(1, n)])])
    return force, (nb, rows, cols, blocks), free, exact.reshape(-1)


@pytest.mark.parametrize("kind", ["block", "diagonal"])
@pytest.mark.parametrize("damping", ["kinetic", "viscous"])
def test_a_hanging_spring_chain_relaxes_to_its_closed_form(kind, damping):
    force, K, free, exact = chain_problem()
    bound = block_gershgorin_masses if kind == "block" else diagonal_gershgorin_masses
    M = bound(*K, safety=1.2)
    out = relax(force, lambda q: M, np.zeros_like(exact), free,
                RelaxSettings(residual_N=1e-9, damping=damping, viscous_rate=0.2, time_limit_s=30.0))
    assert out.converged, out.message
    # the error is at most |f| / λ_min(K), λ_min ≈ k (π / 2n)² = 343 N/m here: 3e-12 m
    assert np.max(np.abs(out.q - exact)) < 1e-10
    assert np.allclose(out.q[:3], 0.0)          # the held node did not move
    assert out.steps > 0 and out.mass_updates >= 1


@pytest.mark.filterwarnings("ignore:overflow:RuntimeWarning")
def test_masses_too_light_are_made_heavier():
    """Masses a fifth of the bound: the central difference is unstable, the relaxation goes back to its
    best state with the masses doubled until it is not, and still reaches the closed form."""
    force, K, free, exact = chain_problem()
    M = block_gershgorin_masses(*K, safety=1.2)
    out = relax(force, lambda q: 0.2 * M, np.zeros_like(exact), free, RelaxSettings(residual_N=1e-9, time_limit_s=30.0))
    assert out.converged, out.message
    assert out.mass_scale >= 4.0
    assert np.max(np.abs(out.q - exact)) < 1e-10


def _full(M):
    nb = len(M)
    out = np.zeros((3 * nb, 3 * nb))
    for b in range(nb):
        out[3 * b:3 * b + 3, 3 * b:3 * b + 3] = M[b]
    return out


def test_the_masses_bound_the_stiffness():
    """Eq. (DR 3): every eigenvalue of M⁻¹K below 4/α, for blocks that are not symmetric on their own
    (a symmetric K with random off-diagonal blocks); the row sums taken in each block's own frame
    (random frames, with and without a floor across) bound it as well."""
    rng = np.random.default_rng(3)
    nb = 7
    A = rng.normal(size=(3 * nb, 3 * nb))
    K = A @ A.T
    rows, cols = np.divmod(np.arange(nb * nb), nb)
    blocks = K.reshape(nb, 3, nb, 3).transpose(0, 2, 1, 3).reshape(-1, 3, 3)
    frames = node_frames(rng.normal(size=(nb, 3)))
    assert np.allclose(np.einsum("bki,bkj->bij", frames, frames), np.eye(3)[None], atol=1e-14)
    bounds = [block_gershgorin_masses(nb, rows, cols, blocks, safety=1.0),
              diagonal_gershgorin_masses(nb, rows, cols, blocks, safety=1.0)]
    bounds += [frame_gershgorin_masses(nb, rows, cols, blocks, frames, safety=1.0, floor_across=floor)
               for floor in (None, rng.uniform(0.0, 5.0, nb))]
    for M in bounds:
        lam = np.linalg.eigvals(np.linalg.solve(_full(M), K)).real
        assert lam.max() <= 4.0 * (1 + 1e-12)


def test_contact_stiffness_across_a_cable_leaves_its_tangent_light():
    """A node of a cable along t between two axial springs k_a, pressed by a contact of stiffness
    k_c ≫ k_a across it (normal n ⊥ t, the cable turned off the coordinate axes as in a bend): in
    the node's frame the tangent's mass is the axial springs' (α/4)·2k_a, as in a straight
    cable without the contact, and the contact's stiffness lands on the normals only; the row sums
    on the coordinates load k_c onto every axis it has a component on, the tangent too."""
    k_a, k_c = 1.0e5, 1.0e8
    t = np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0)
    n = np.array([-1.0, 1.0, 0.0]) / np.sqrt(2.0)
    K_node = 2.0 * k_a * np.outer(t, t) + k_c * np.outer(n, n)
    frames = node_frames(t[None])
    M = frame_gershgorin_masses(1, [0], [0], K_node[None], frames, safety=1.0)
    assert t @ M[0] @ t == pytest.approx(0.25 * 2.0 * k_a, rel=1e-12)
    assert n @ M[0] @ n == pytest.approx(0.25 * k_c, rel=1e-12)
    diag = diagonal_gershgorin_masses(1, [0], [0], K_node[None])
    assert t @ diag[0] @ t == pytest.approx(0.25 * k_c, rel=1e-12)   # the row sums: the contact on the tangent
    floor = frame_gershgorin_masses(1, [0], [0], np.zeros((1, 3, 3)), frames, floor_across=[8.0])[0]
    assert t @ floor @ t == pytest.approx(0.0, abs=1e-12) and n @ floor @ n == pytest.approx(2.0, rel=1e-12)


def test_a_chain_on_a_hertz_floor_relaxes_to_its_penetrations():
    """A straight horizontal chain of axial springs resting on a Hertz floor under its weight: each node
    sinks δ_i = (W_i / K_h)^(1/e), W_i its weight (half at the ends), from a start 1 mm above the floor,
    where the open contact has no stiffness: the masses carry the floor's stiffness at a reference
    penetration (as :func:`exucable.solve.relax.bundle_masses` does for the cables' contacts)."""
    n, k, K_h, e, w = 9, 5.0e4, 1.0e8, 1.5, 14.0
    W = np.full(n, w)
    W[[0, -1]] = w / 2

    def force(q):
        x = q.reshape(n, 3)
        f = np.zeros((n, 3))
        d = x[1:, 0] - x[:-1, 0]
        f[1:, 0] -= k * d
        f[:-1, 0] += k * d
        f[:, 2] -= W
        pen = np.maximum(-x[:, 2], 0.0)
        f[:, 2] += K_h * pen ** e
        return f.reshape(-1)

    def masses(q):
        pen = np.maximum(-q.reshape(n, 3)[:, 2], 2e-5)
        M = np.zeros((n, 3, 3))
        M[:, 0, 0] = 2 * 2 * k
        M[:, 1, 1] = 1.0
        M[:, 2, 2] = e * K_h * pen ** (e - 1)
        return 0.25 * 1.5 * M

    q0 = np.zeros(3 * n)
    q0[2::3] = 1e-3
    free = np.ones(3 * n, dtype=bool)
    out = relax(force, masses, q0, free, RelaxSettings(residual_N=1e-8, time_limit_s=30.0))
    assert out.converged, out.message
    assert np.allclose(-out.q[2::3], (W / K_h) ** (1 / e), rtol=1e-7, atol=0)


def test_it_leaves_an_unstable_balance():
    """f(x) = x - x³ (the potential -x²/2 + x⁴/4): x = 0 is a balance, unstable; started 1e-4 off it
    the relaxation falls into the well at x = 1, where Newton from the start would go back to 0."""
    def force(q):
        return q - q ** 3

    def masses(q):
        # |∂f/∂x| at the state, at least 20: steps short against the well's width (a unit step from
        # masses of the well's own stiffness 2 crosses it in a few steps and overshoots into the other)
        return (0.25 * 1.5 * np.diag(np.maximum(np.abs(1 - 3 * q ** 2), 20.0)))[None]

    out = relax(force, masses, np.array([1e-4, 1e-4, -1e-4]), np.ones(3, dtype=bool),
                RelaxSettings(residual_N=1e-10, time_limit_s=30.0))
    assert out.converged, out.message
    assert np.allclose(out.q, [1.0, 1.0, -1.0], atol=1e-9)


def test_bad_settings_are_refused_by_name():
    with pytest.raises(SolverError, match="RelaxSettings.damping"):
        RelaxSettings(damping="none")
    with pytest.raises(SolverError, match="RelaxSettings.mass_safety"):
        RelaxSettings(mass_safety=0.5)


def test_the_bundle_residual_is_the_static_solvers():
    """BundleModel.steady_force equals Exudyn's static residual on the free coordinates bit for bit,
    and the blocks of stiffness_blocks3 sum to minus Exudyn's Newton Jacobian there."""
    from conftest import exudyn_static_residual_jacobian, upbend_bundle_scenario
    from exucable.model.bundle import build_bundle_model
    from exucable.solve import steady as st

    model = build_bundle_model(upbend_bundle_scenario())
    solver = st.SteadySolver(model)           # its spring (rate 0) is part of Exudyn's system
    q, r, J = exudyn_static_residual_jacobian(model)
    idx = model.ode2_index
    free = np.setdiff1d(np.arange(idx.size), model.held_coordinates())
    f = model.steady_force(q)
    assert np.array_equal(f[free], r[free])
    rows, cols, blocks = model.stiffness_blocks3(q)
    K = np.zeros((idx.size, idx.size))
    for a, b, B in zip(rows, cols, blocks):
        K[3 * a:3 * a + 3, 3 * b:3 * b + 3] += B
    # Exudyn's static system Jacobian is ∂(residual)/∂q = ∂f/∂q = -K
    assert np.allclose(K[np.ix_(free, free)], -J[np.ix_(free, free)], rtol=0, atol=1e-9 * np.abs(J).max())
    assert solver.spring.rate == 0.0
