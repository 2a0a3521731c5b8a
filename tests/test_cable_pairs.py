"""Tests of the cable-cable contact kernel (exucable/contact/cable_pairs.py).

References independent of the kernel: the Hertz force between two parallel straight cables in
closed form, Coulomb's friction on a known sliding velocity, Newton's third law, and central
finite differences of the generalized force for the exact Jacobian. The compiled loop is checked
equal to the numpy definition, as for the cable-conduit kernel (tests/test_contact_kernel.py).
"""

from __future__ import annotations

import numpy as np
import pytest

from exucable.contact import ContactLaw
from exucable.contact.cable_pairs import CableContactKernel, _pair_contacts, pair_contacts_reference

R = 2.5e-3          # cable radius [m]
H_REF = 1e-3        # reference spacing [m]
LAW = ContactLaw(stiffness=1e6, damping=0.0, exponent=1.5, friction=0.3, regularisation_velocity_m_per_s=1e-3)


def straight_cable(n_el, Le, y, z, rng=None, wobble=0.0):
    """Nodal coordinates of a straight cable along x at (y, z), optionally perturbed [m, -]."""
    x = np.concatenate([[0.0], np.cumsum(np.full(n_el, Le))])
    q = np.zeros((n_el + 1, 6))
    q[:, 0], q[:, 1], q[:, 2], q[:, 3] = x, y, z, 1.0
    if rng is not None:
        q[:, 1:3] += wobble * rng.normal(size=(n_el + 1, 2))
        q[:, 4:6] += 0.02 * rng.normal(size=(n_el + 1, 2))
        q[:, 0] += 0.1 * wobble * rng.normal(size=n_el + 1)
    return q.reshape(-1)


def bundle_q(rng, n_el=4, Le=0.05, wobble=1e-4):
    """Three cables in a trefoil, pressed together by 0.1 mm, perturbed."""
    gap = 2 * R - 1e-4
    return np.concatenate([straight_cable(n_el, Le, 0.0, 0.0, rng, wobble),
                           straight_cable(n_el, Le, gap, 0.0, rng, wobble),
                           straight_cable(n_el, Le, gap / 2, gap * np.sqrt(3) / 2, rng, wobble)])


def kernel(backend, n_el=4, Le=0.05, n_k=5, law=LAW, speed=0.1, window=None):
    return CableContactKernel(3, np.full(n_el, Le), R, law, n_k, H_REF, speed, window=window, backend=backend)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_compiled_equals_numpy(seed):
    q = bundle_q(np.random.default_rng(seed))
    a, b = kernel("numpy").evaluate(q), kernel("numba").evaluate(q)
    assert a.n_in_contact == b.n_in_contact > 0
    scale = np.abs(a.generalized_force).max()
    # same formulas, same order of operations up to numpy's vs the loop's sums: round-off only
    np.testing.assert_allclose(b.generalized_force, a.generalized_force, rtol=0, atol=1e-11 * scale)
    jscale = abs(a.jacobian).max()
    assert abs(a.jacobian - b.jacobian).max() <= 1e-11 * jscale


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_jacobian_matches_central_differences(backend):
    """∂Q/∂q exact (positions, slopes and the steady-sliding velocity V ∂r/∂x), friction on."""
    q = bundle_q(np.random.default_rng(5))
    k = kernel(backend)
    J = k.evaluate(q).jacobian.toarray()
    assert np.abs(J - central_differences(k, q)).max() <= 1e-6 * np.abs(J).max()


def central_differences(k, q, h=1e-9):
    """∂Q/∂q of kernel ``k`` at ``q`` by central differences of step h [m]: truncation ~h² |Q'''|,
    round-off ~1e-16 |Q|/h; both < 1e-7 relative on these bundles."""
    fd = np.empty((q.size, q.size))
    for i in range(q.size):
        dq = np.zeros_like(q)
        dq[i] = h
        fd[:, i] = (k.evaluate(q + dq, False).generalized_force - k.evaluate(q - dq, False).generalized_force) / (2 * h)
    return fd


def test_parallel_cables_hertz_force_per_length():
    """Two straight parallel cables pressed by δ: each carries (K/h_ref) δ^e per metre, opposite."""
    n_el, Le, delta = 6, 0.1, 2e-5
    q = np.concatenate([straight_cable(n_el, Le, 0.0, 0.0), straight_cable(n_el, Le, 2 * R - delta, 0.0)])
    for backend in ("numpy", "numba"):
        k = CableContactKernel(2, np.full(n_el, Le), R, LAW, 4, H_REF, 0.1, backend=backend)
        c = k.contacts(q)
        assert len(c["t"]) == n_el * 4        # every check point of cable 0 touches cable 1
        np.testing.assert_allclose(c["penetration_m"], delta, rtol=1e-9)
        Q = k.evaluate(q, False).generalized_force.reshape(2, n_el + 1, 6)
        per_m = LAW.stiffness / H_REF * delta ** LAW.exponent
        # the check points cover the length; the y-force on each cable's positions sums to ∓ per_m·L
        np.testing.assert_allclose(Q[0, :, 1].sum(), -per_m * n_el * Le, rtol=1e-9)
        np.testing.assert_allclose(Q[1, :, 1].sum(), per_m * n_el * Le, rtol=1e-9)
        assert np.abs(Q[:, :, [0, 2]]).max() < 1e-9 * per_m


def test_friction_opposes_relative_sliding_with_coulomb_magnitude():
    """Cable 0 slides along x at 0.1 m/s past cable 1 at rest: friction μ f_n against it, on
    cable 1 the reaction; the point kernel is given the velocities directly."""
    n_pts = 5
    X = np.zeros((2 * n_pts, 3))
    X[:n_pts, 0] = X[n_pts:, 0] = np.linspace(0.0, 0.04, n_pts)
    X[n_pts:, 1] = 2 * R - 1e-5
    U = np.zeros_like(X)
    U[:n_pts, 0] = 0.1
    weight = np.full(n_pts, 10.0)
    ref = pair_contacts_reference(X, U, 2, n_pts, 2, 2 * R, weight, LAW)
    f_n = 10.0 * LAW.stiffness * 1e-5 ** 1.5
    eps = LAW.regularisation_velocity_m_per_s
    mu_eff = LAW.friction * 0.1 / np.sqrt(0.1 ** 2 + eps ** 2)
    np.testing.assert_allclose(ref["force"][:, 0], -mu_eff * f_n, rtol=1e-12)     # on the sliding point
    np.testing.assert_allclose(ref["force"][:, 1], -f_n, rtol=1e-12)               # pushed away from cable 1
    total = ref["force"].reshape(-1, 3, 3).sum(axis=1)                              # P, B0, B1 together
    assert np.abs(total).max() < 1e-12 * f_n                                        # action = reaction
    m = 2 * n_pts
    out = (np.zeros((m, 3), np.int64), np.zeros(m), np.zeros(m), np.zeros((m, 9)), np.zeros((m, 9, 9)),
           np.zeros((m, 9, 9)), np.zeros(m, np.bool_))
    count = _pair_contacts(X, U, 2, n_pts, 2, 2 * R, weight, LAW.stiffness, LAW.exponent, LAW.friction, eps ** 2,
                           LAW.damping, LAW.damping_onset_m, True, *out, LAW.onset_layer_m)
    assert count == len(ref["t"])
    np.testing.assert_allclose(out[3][:count], ref["force"], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(out[4][:count], ref["jac_x"], rtol=1e-10, atol=1e-9)
    np.testing.assert_allclose(out[5][:count], ref["jac_u"], rtol=1e-10, atol=1e-12)


def test_forces_balance_between_cables():
    """Newton's third law over the whole bundle: the contact forces on all positions sum to zero."""
    q = bundle_q(np.random.default_rng(9))
    Q = kernel("numba").evaluate(q, False).generalized_force.reshape(-1, 6)
    assert np.abs(Q[:, :3].sum(axis=0)).max() < 1e-10 * np.abs(Q[:, :3]).max()


def test_windowed_search_equals_the_full_search():
    """The broad phase (segments within the window of the same index) finds the contacts a search
    over every segment finds, when the cables lie side by side."""
    q = bundle_q(np.random.default_rng(3), n_el=10, Le=0.02)
    near = kernel("numba", n_el=10, Le=0.02).contacts(q)
    full = kernel("numba", n_el=10, Le=0.02, window=10 * 5).contacts(q)
    np.testing.assert_array_equal(near["index"], full["index"])
    np.testing.assert_allclose(near["force"], full["force"], rtol=0, atol=0)
    assert not near["edge"].any()


@pytest.mark.parametrize("window", [None, 40, 400])
def test_blocked_search_equals_the_numpy_scan_on_a_long_bent_bundle(window):
    """The compiled search skips blocks of segments by their bounding balls: on a long trefoil bent
    into an arc (so that blocks near and far from each point differ), with windows from the default
    to the whole cable, it finds the same segments as the numpy scan over every segment of the
    window, and the same forces (round-off only)."""
    n_el, Le, bend_R = 40, 0.02, 0.3
    q = bundle_q(np.random.default_rng(11), n_el=n_el, Le=Le, wobble=2e-4).reshape(-1, 6)
    x, y = q[:, 0].copy(), q[:, 1].copy()
    q[:, 0], q[:, 1] = (bend_R + y) * np.sin(x / bend_R), bend_R - (bend_R + y) * np.cos(x / bend_R)
    q = q.reshape(-1)
    a = kernel("numpy", n_el=n_el, Le=Le, n_k=12, window=window).contacts(q, jacobian=True)
    b = kernel("numba", n_el=n_el, Le=Le, n_k=12, window=window).contacts(q, jacobian=True)
    assert len(a["t"]) > 100
    np.testing.assert_array_equal(b["index"], a["index"])
    np.testing.assert_array_equal(b["edge"], a["edge"])
    np.testing.assert_allclose(b["force"], a["force"], rtol=0, atol=1e-11 * np.abs(a["force"]).max())
    np.testing.assert_allclose(b["jac_x"], a["jac_x"], rtol=0, atol=1e-11 * np.abs(a["jac_x"]).max())


@pytest.mark.parametrize("seed", [0, 4])
def test_compiled_assembly_equals_the_sparse_products_with_rates(seed):
    """A dynamic evaluation (the points' velocities from nodal rates): the compiled assembly of
    Sᵀ J S into node blocks gives the numpy path's sparse products, ∂Q/∂q and ∂Q/∂q̇, to round-off."""
    rng = np.random.default_rng(seed)
    q = bundle_q(rng)
    q_t = 0.1 * rng.normal(size=q.size)
    law = ContactLaw(stiffness=1e6, damping=50.0, exponent=1.5, friction=0.3, regularisation_velocity_m_per_s=1e-3,
                     damping_onset_m=2e-5)
    a = kernel("numpy", law=law).evaluate(q, q_t=q_t)
    b = kernel("numba", law=law).evaluate(q, q_t=q_t)
    assert a.n_in_contact == b.n_in_contact > 0
    np.testing.assert_allclose(b.generalized_force, a.generalized_force, rtol=0,
                               atol=1e-11 * np.abs(a.generalized_force).max())
    for x, y in ((a.jacobian, b.jacobian), (a.jacobian_t, b.jacobian_t)):
        assert abs(x - y).max() <= 1e-11 * abs(x).max()


@pytest.mark.parametrize("window", [None, 400])
def test_compiled_assembly_on_a_long_bent_bundle(window):
    """The node-block assembly on the long trefoil bent into an arc, with the default window and one
    spanning the whole cable (the blocks' node offsets widest): the numpy path's Jacobian, to round-off."""
    n_el, Le, bend_R = 40, 0.02, 0.3
    q = bundle_q(np.random.default_rng(11), n_el=n_el, Le=Le, wobble=2e-4).reshape(-1, 6)
    x, y = q[:, 0].copy(), q[:, 1].copy()
    q[:, 0], q[:, 1] = (bend_R + y) * np.sin(x / bend_R), bend_R - (bend_R + y) * np.cos(x / bend_R)
    q = q.reshape(-1)
    a = kernel("numpy", n_el=n_el, Le=Le, n_k=12, window=window).evaluate(q)
    b = kernel("numba", n_el=n_el, Le=Le, n_k=12, window=window).evaluate(q)
    assert a.n_in_contact > 100
    assert abs(a.jacobian - b.jacobian).max() <= 1e-11 * abs(a.jacobian).max()


def test_without_cable_friction_the_rates_sweep_is_left_out_bit_for_bit():
    """Without friction and damping between the cables ∂Q/∂u is zero entry by entry, and the steady
    Jacobian's assembly leaves its sweep out: the same matrix, bit for bit, as with the sweep (and
    the numpy path's sparse products to round-off); S q and Sᵀ f compiled are the sparse products' bits."""
    from dataclasses import replace

    n_el, Le, bend_R = 40, 0.02, 0.3
    q = bundle_q(np.random.default_rng(11), n_el=n_el, Le=Le, wobble=2e-4).reshape(-1, 6)
    x, y = q[:, 0].copy(), q[:, 1].copy()
    q[:, 0], q[:, 1] = (bend_R + y) * np.sin(x / bend_R), bend_R - (bend_R + y) * np.cos(x / bend_R)
    q = q.reshape(-1)
    law = replace(LAW, friction=0.0)
    k = kernel("numba", n_el=n_el, Le=Le, n_k=12, law=law)
    res = k.evaluate(q)
    c = k.contacts(q, jacobian=True)
    assert len(c["t"]) > 100 and not np.any(c["jac_u"])
    full = k._assemble([(c["jac_x"], k._coef, 1.0), (c["jac_u"], k._coef_d, k.speed_m_per_s)], c["index"])
    assert (res.jacobian != full).nnz == 0
    a = kernel("numpy", n_el=n_el, Le=Le, n_k=12, law=law).evaluate(q)
    assert abs(a.jacobian - res.jacobian).max() <= 1e-11 * abs(a.jacobian).max()
    X, U = k.points(q)
    np.testing.assert_array_equal(X.reshape(-1), k.S @ q)
    np.testing.assert_array_equal(U.reshape(-1), k.speed_m_per_s * (k.dS @ q))
    np.testing.assert_array_equal(res.generalized_force, k.St @ (np.bincount(
        (3 * c["index"][:, :, None] + np.arange(3)).reshape(-1), weights=c["force"].reshape(-1), minlength=X.size)))


@pytest.mark.parametrize("window", [None, 400])
def test_search_from_the_guess_to_the_layer_edge_equals_the_numpy_scan(window):
    """The compiled search starts from the last point's segment and its neighbours (kept, not
    evaluated again) and reaches no farther than the onset layer's edge (gap + s): on the bent
    trefoil with its third cable lifted off the other two along the cable (points in contact, in the
    layer and beyond it, so that both bounds bite), with a layer, it finds the numpy scan's segments
    over the whole window and the same forces and Jacobian (round-off only)."""
    n_el, Le, bend_R, layer = 40, 0.02, 0.3, 3e-4
    q = bundle_q(np.random.default_rng(5), n_el=n_el, Le=Le, wobble=1e-4).reshape(3, -1, 6)
    q[2, :, 2] += np.linspace(-2e-4, 1.5e-3, n_el + 1)      # from pressed in to 1.5 mm off
    q = q.reshape(-1, 6)
    x, y = q[:, 0].copy(), q[:, 1].copy()
    q[:, 0], q[:, 1] = (bend_R + y) * np.sin(x / bend_R), bend_R - (bend_R + y) * np.cos(x / bend_R)
    q = q.reshape(-1)
    ka, kb = (kernel(b, n_el=n_el, Le=Le, n_k=12, window=window) for b in ("numpy", "numba"))
    for k in (ka, kb):
        k.set_onset_layer(layer)
    a, b = ka.contacts(q, jacobian=True), kb.contacts(q, jacobian=True)
    inside = a["penetration_m"] > 0.0
    assert inside.sum() > 100 and (~inside).sum() > 20          # contacts in the layer too
    assert len(a["t"]) < 3 * 40 * 12                              # and points beyond it
    np.testing.assert_array_equal(b["index"], a["index"])
    np.testing.assert_array_equal(b["edge"], a["edge"])
    np.testing.assert_allclose(b["t"], a["t"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(b["penetration_m"], a["penetration_m"], rtol=0, atol=1e-15)
    np.testing.assert_allclose(b["force"], a["force"], rtol=0, atol=1e-11 * np.abs(a["force"]).max())
    np.testing.assert_allclose(b["jac_x"], a["jac_x"], rtol=0, atol=1e-11 * np.abs(a["jac_x"]).max())
