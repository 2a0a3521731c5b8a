"""The steady-sliding contact kernel: friction along the cable's own tangent, exact Jacobian.

References: central finite differences of the kernel's own force (the Jacobian must be its
derivative), the numpy reference vs the compiled path, and the defining property of steady
sliding (a check point's velocity is V ∂r/∂x, so the friction opposes the material's flow).
"""

from __future__ import annotations

import numpy as np
import pytest

from exucable.contact import ContactKernel, ContactLaw, assemble_blocks_dense
from exucable.contact.kernel_parts import PAIRS
from exucable.contact.steady import SteadySlidingKernel, bernstein, block_coefficients, hermite_unit_derivative
from exucable.contact.checkpoints import hermite_unit
from exucable.geometry import Bend, Conduit, Straight, centreline_from_path

R_CABLE, R_CONDUIT = 0.0025, 0.0035
GAP = R_CONDUIT - R_CABLE
LAW = ContactLaw(stiffness=1e6, damping=1e3, exponent=1.5, friction=0.3,
                 static_friction=0.4, stribeck_velocity_m_per_s=0.2)
SPEED = 0.1


def bend_conduit():
    c = centreline_from_path([0, 0, 0], [1, 0, 0],
                             [Straight(0.3), Bend(90, 0.5, "left"), Bend(45, 0.6, "up"), Straight(0.3)])
    return Conduit.build(R_CONDUIT, c, segments_per_bend=12)


def cable_in_bend(cond, rng):
    """Four elements pressed onto the inner wall of the bends, slopes slightly perturbed (so that
    the tangent, hence the friction direction, is not the centreline's)."""
    c = cond.centreline
    s = np.linspace(0.35, 0.95, 5)
    t = c.tangent(s)
    kn = c.curvature_vector(s)
    u = kn / np.linalg.norm(kn, axis=1, keepdims=True)
    pos = c.point(s) + (GAP + 3e-4) * u
    slope = (1.0 + 2e-3) * t + rng.normal(scale=2e-3, size=t.shape)
    return np.hstack([pos, slope]).reshape(-1), np.diff(s)


def kernels(cond, L, backend, n_k=7):
    return SteadySlidingKernel(cond.segments, L, R_CABLE, LAW, n_k, backend=backend, surface="smooth",
                               centreline=cond.centreline, speed_m_per_s=SPEED)


def test_hermite_derivative_is_the_derivative():
    xi = np.linspace(0.05, 0.95, 7)
    h = 1e-6
    fd = (hermite_unit(xi + h) - hermite_unit(xi - h)) / (2 * h)
    assert np.abs(hermite_unit_derivative(xi) - fd).max() < 1e-9


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_friction_direction_jacobian_matches_finite_differences(backend):
    """∂Q/∂q including the dependence of the sliding velocity V ∂r/∂x on the slopes, against
    central differences: step 1e-8, tolerance 1e-6 of max|J| (truncation (h/δ)² ≤ 1e-8 with
    δ ≈ 3e-4 m; rounding ~1e-8·|Q|/h·1e-16 negligible)."""
    cond = bend_conduit()
    q, L = cable_in_bend(cond, np.random.default_rng(3))
    k = kernels(cond, L, backend)
    zero = np.zeros_like(q)
    assert k.points(q, zero).in_contact.all()
    res = k.evaluate(q, zero, jacobian=True)
    assert not np.any(res.jac_qt_blocks)
    n = q.size
    fd = np.zeros((n, n))
    h = 1e-8
    for i in range(n):
        d = np.zeros(n)
        d[i] = h
        fd[:, i] = (k.evaluate(q + d, zero).generalized_force - k.evaluate(q - d, zero).generalized_force) / (2 * h)
    jq = assemble_blocks_dense(res.jac_q_blocks)
    assert np.abs(jq - fd).max() < 1e-6 * np.abs(jq).max()
    # the slope columns carry the friction-direction term: without it they would differ
    plain = ContactKernel(cond.segments, L, R_CABLE, LAW, 7, backend="numpy", surface="smooth",
                          centreline=cond.centreline)
    jq_fixed_v = assemble_blocks_dense(plain.evaluate(q, zero, jacobian=True).jac_q_blocks)
    assert np.abs(jq - jq_fixed_v).max() > 1e-3 * np.abs(jq).max()


def test_block_coefficients_reproduce_the_shape_products():
    """The compiled Jacobian sums Σ_k N_a N_b J_k and Σ_k N_a N'_b J_k through seven Bernstein
    moments: the coefficients must give the products themselves (polynomials of degree ≤ 6, so
    exactly up to round-off: 1e-14 against products of order 1)."""
    xi = np.random.default_rng(1).uniform(0.0, 1.0, 50)
    nh, dnh = hermite_unit(xi), hermite_unit_derivative(xi)
    direct = np.stack([nh[:, a] * nh[:, b] for a, b in PAIRS]
                      + [nh[:, a] * dnh[:, b] for a in range(4) for b in range(4)], axis=1)
    assert np.abs(bernstein(xi) @ block_coefficients().T - direct).max() < 1e-14
    assert np.allclose(bernstein(xi).sum(axis=1), 1.0, rtol=0, atol=1e-15)


@pytest.mark.parametrize("n_k", [7, 64])
def test_numba_equals_numpy(n_k):
    """Same force and Jacobian blocks (the numpy reference sums the products directly, the
    compiled path through Bernstein moments)."""
    cond = bend_conduit()
    q, L = cable_in_bend(cond, np.random.default_rng(4))
    zero = np.zeros_like(q)
    a = kernels(cond, L, "numpy", n_k).evaluate(q, zero, jacobian=True)
    b = kernels(cond, L, "numba", n_k).evaluate(q, zero, jacobian=True)
    assert np.allclose(a.generalized_force, b.generalized_force, rtol=1e-10, atol=1e-9)
    assert np.abs(a.jac_q_blocks - b.jac_q_blocks).max() < 1e-9 * np.abs(a.jac_q_blocks).max()


def test_numba_points_equal_numpy():
    """The compiled per-point state (post-processing and the steady solve's outside-the-conduit
    check) is the numpy reference's: v = V ∂r/∂x, its normal and friction forces, the segment and
    the arc length; with a second cable half out of contact (moved to the axis) as well."""
    cond = bend_conduit()
    q, L = cable_in_bend(cond, np.random.default_rng(6))
    q_free = q.reshape(-1, 6).copy()
    q_free[2:, :3] = cond.centreline.point(np.linspace(0.35, 0.95, 5))[2:]
    for coords in (q, q_free.reshape(-1)):
        a = kernels(cond, L, "numpy").points(coords, np.zeros_like(coords))
        b = kernels(cond, L, "numba").points(coords, np.ones_like(coords))   # q_t is ignored
        assert np.array_equal(a.segment, b.segment)
        assert np.array_equal(a.in_contact, b.in_contact)
        for name in ("position_m", "velocity_m_per_s", "s_conduit_m", "penetration_m", "normal_force_N",
                     "sliding_velocity_m_per_s", "friction_force_N"):
            x, y = getattr(a, name), getattr(b, name)
            assert np.allclose(x, y, rtol=1e-10, atol=1e-12 * max(1.0, np.nanmax(np.abs(x)))), name
    assert 0 < np.count_nonzero(a.in_contact) < a.in_contact.size


def test_friction_opposes_the_flow_toward_the_leading_end():
    """Check-point velocities are V ∂r/∂x (nodes numbered from the trailing end), so the friction
    force on the cable points back along the cable: its total, dotted with the local tangent, is
    -μ Σ f_n, fully developed: steady sliding uses the regularisation 1e-6 V, factor 1 - 5e-13
    (the dynamic law's 1e-3 m/s would give 1 - 5e-5 at 0.1 m/s and 0.71 at 1 mm/s); Stribeck at
    0.1 m/s adds (μ_s - μ_k) e^-0.25."""
    cond = bend_conduit()
    q, L = cable_in_bend(cond, np.random.default_rng(5))
    k = kernels(cond, L, "numpy")
    st = k.points(q, np.zeros_like(q))
    t = st.velocity_m_per_s / np.linalg.norm(st.velocity_m_per_s, axis=1, keepdims=True)
    assert np.allclose(np.linalg.norm(st.velocity_m_per_s, axis=1), SPEED, rtol=1e-2)  # |r'| = 1 ± 0.5 % on this crude shape
    # the velocity is along the cable: compare with the chord direction of each element
    nodes = q.reshape(-1, 6)[:, :3]
    chord = np.repeat(np.diff(nodes, axis=0), 7, axis=0)
    chord /= np.linalg.norm(chord, axis=1, keepdims=True)
    assert np.all(np.sum(t * chord, axis=1) > 0.98)  # an element turns 17 deg here
    mu = LAW.friction + (LAW.static_friction - LAW.friction) * np.exp(-(st.sliding_velocity_m_per_s / 0.2) ** 2)
    assert np.allclose(st.friction_force_N, mu * st.normal_force_N, rtol=1e-9)
