"""The contact kernel coupled to Exudyn: gravity on a straight horizontal conduit (paper Eqs.
14-23 in a run), and check-point convergence."""

from __future__ import annotations

import numpy as np
import pytest
import exudyn as exu

from exucable.contact import ContactKernel, ContactLaw
from exucable.geometry import Bend, Conduit, Straight, centreline_from_path
from exucable.model.build import build_model
from exucable.solve.dynamic import simulate

from conftest import make_scenario

RHO_A = 1000.0 * np.pi * 0.0025**2
G = 9.8
W = RHO_A * G          # weight per length [N/m]


@pytest.fixture(scope="module")
def pulled_straight():
    """A 6 m cable pulled at 0.1 m/s through a straight horizontal conduit, gravity, μ = 0.3."""
    sc = make_scenario(conduit={"inner_radius": 0.0035, "path": [{"straight": 6.0}]},
                       cable=dict(radius=0.0025, density=1000.0, youngs_modulus=1.0e9, elements=24),
                       contact={"friction": 0.3, "check_points_per_element": 20},
                       gravity={"g": G}, solver={"end_time": 0.3, "step": 0.01})
    model = build_model(sc)
    out = simulate(model)
    assert out.status == "ok", out.message
    q, v = model.coordinates()
    pts = model.kernel.points(q.reshape(-1), v.reshape(-1))
    rig = np.array([model.mbs.GetObjectOutput(c, exu.OutputVariableType.Force)
                    for c in model.lead_drive.constraints])
    return model, out, pts, rig


def test_resting_cable_carries_its_weight_on_the_wall(pulled_straight):
    """Σ normal forces + the rig's vertical reaction = weight (1e-6: equilibrium to Newton's
    tolerance), and the penetration along the run is the one the Hertz law with the check-point
    weights predicts: K δ^e / h_ref = w, δ = (w h_ref / K)^(1/e) (1e-5 relative)."""
    model, out, pts, rig = pulled_straight
    L = model.layout.element_length_m.sum()
    # the rig's multiplier is minus its force on the node
    assert pts.normal_force_N.sum() - rig[2] == pytest.approx(W * L, rel=1e-6)
    mid = (pts.s_conduit_m > 1.0) & (pts.s_conduit_m < 4.5)   # away from the ends
    delta = (W * 1e-3 / 1.0e6) ** (1 / 1.5)
    np.testing.assert_allclose(pts.penetration_m[mid], delta, rtol=1e-4)
    # the force also carries the contact damping C·δ̇ of that residual motion (≤ 1e-3 here)
    np.testing.assert_allclose(pts.normal_force_per_length_N_per_m[mid], W, rtol=1e-3)


def test_pulling_force_through_straight_conduit_is_mu_w_L(pulled_straight):
    """Pulling force = μ·w·L within 0.5 % (the issue's bound): the rig holds the leading end and
    carries a few centimetres' worth of weight (0.3 % here); Coulomb's law on what rests on the
    wall, μ·(wL − R_v), holds to 1e-4 (friction regularised at 1 mm/s against 0.1 m/s sliding)."""
    model, out, pts, rig = pulled_straight
    L = model.layout.element_length_m.sum()
    pull = out.history.pull_force_N[-1]
    assert pull == pytest.approx(0.3 * W * L, rel=5e-3)
    assert pull == pytest.approx(0.3 * (W * L + rig[2]), rel=1e-4)


def _bend_cable(n_points):
    c = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(0.2), Bend(60, 0.5, "left"), Straight(0.2)])
    cond = Conduit.build(0.0035, c, segments_per_bend=30)
    # a cable drawn taut across the bend: straight chord from s = 0.1 to s = 0.8 pressed against
    # the inner wall only in the middle (partial contact, so the integrand has kinks)
    s = np.linspace(0.15, 0.55, 5)
    kn = c.curvature_vector(s)
    pos = c.point(s) + 0.0012 * np.where(np.linalg.norm(kn, axis=1, keepdims=True) > 0,
                                         kn / np.maximum(np.linalg.norm(kn, axis=1, keepdims=True), 1e-12), 0.0)
    t = c.tangent(s)
    q = np.hstack([pos, t]).reshape(-1)
    q_t = np.hstack([0.1 * t, np.zeros_like(t)]).reshape(-1)
    law = ContactLaw(stiffness=1e6, damping=0.0, exponent=1.5, friction=0.2)
    k = ContactKernel(cond.segments, np.diff(s), 0.0025, law, n_points, surface="smooth",
                      centreline=c)
    return k.evaluate(q, q_t).generalized_force


def test_contact_force_converges_as_check_points_are_added():
    """With each check point weighted by its share of the element, the generalized contact force
    is a quadrature of the distributed Hertz law and converges as points are added: the error
    against 1024 points falls at least like n^-1.5 (fitted slope of log error against log n; the
    integrand δ^1.5 has kinks where contact starts, which caps Gauss' rate near 2.5)."""
    ref = _bend_cable(1024)
    ns = np.array([8, 16, 32, 64, 128])
    err = np.array([np.abs(_bend_cable(n) - ref).max() for n in ns]) / np.abs(ref).max()
    slope = np.polyfit(np.log(ns), np.log(err), 1)[0]
    assert err[-1] < 1e-3
    assert slope < -1.5, (err, slope)


def test_one_kernel_pass_per_newton_iteration():
    """The Jacobian call reuses the kernel pass of the force call at the same state: half the
    passes, and a bit-identical run (issue 15: contact cost per Newton iteration)."""
    def run(with_force):
        sc = make_scenario(conduit={"inner_radius": 0.0035, "path": [{"straight": 1.0},
                                                                     {"bend": 90.0, "radius": 0.5, "turn": "left"}]},
                           cable=dict(radius=0.0025, density=1000.0, youngs_modulus=1.0e9, elements=8),
                           contact={"friction": 0.2, "check_points_per_element": 10},
                           pull={"speed": 0.1, "back_tension": 50.0},
                           solver={"end_time": 0.03, "step": 0.01})
        model = build_model(sc)
        model.coupling.jacobian_with_force = with_force
        out = simulate(model)
        return out, model.coupling

    (a, ca), (b, cb) = run(False), run(True)
    assert a.status == b.status == "ok"
    assert a.history.pull_force_N == b.history.pull_force_N       # bit for bit
    assert cb.jacobian_calls > 0 and cb.reused_evaluations == cb.jacobian_calls
    assert ca.kernel_evaluations == ca.force_calls + ca.jacobian_calls + ca.onset_evaluations
    assert cb.kernel_evaluations == cb.force_calls + cb.onset_evaluations
    # the held damping onset is read off the converged state's own pass: one pass more, at t = 0
    assert ca.onset_evaluations == cb.onset_evaluations == 1


def _reference_triplets(coupling, res, f_q, f_v):
    """The contact Jacobian's triplets by the plain formula: -(f_q ∂Q/∂q + f_v ∂Q/∂q̇) per element
    block, summed with scipy where blocks share a node, zeros dropped, sorted by (row, column)."""
    import scipy.sparse as sp
    from exucable.contact import block_sparsity

    blocks = -(f_q * res.jac_q_blocks + f_v * res.jac_qt_blocks)
    rows, cols = block_sparsity(res.jac_q_blocks.shape[0])
    m = sp.coo_matrix((blocks.reshape(-1), (rows, cols)), shape=(coupling.n, coupling.n)).tocsr()
    m.sum_duplicates()
    m.eliminate_zeros()
    m = m.tocoo()
    order = np.lexsort((m.col, m.row))
    return np.column_stack([m.row[order], m.col[order], m.data[order]]).astype(float)


@pytest.mark.parametrize("mode", ["dynamic", "steady"])
def test_contact_jacobian_triplets_are_the_plain_formula_bit_for_bit(mode):
    """The triplets handed to Exudyn (summed in place, zeros dropped by a record gather, the
    q̇-term skipped when it is zero) equal the plain formula's to the last bit, at Newton's
    factors of both solvers (f_v = 0 in a static solve; an f_q that is no power of two)."""
    sc = make_scenario(conduit={"inner_radius": 0.0035, "path": [{"straight": 1.0},
                                                                 {"bend": 90.0, "radius": 0.5, "turn": "up"}]},
                       cable=dict(radius=0.0025, density=1000.0, youngs_modulus=1.0e9, elements=8),
                       contact={"friction": 0.2, "check_points_per_element": 10},
                       pull={"speed": 0.1, "back_tension": 50.0}, gravity={"g": G},
                       solver={"mode": mode, "end_time": 0.03, "step": 0.01})
    model = build_model(sc)
    c = model.coupling
    q, v = model.coordinates()
    rng = np.random.default_rng(1)
    # a state pressed into the wall along part of the cable (some blocks zero, some not)
    qa = q.reshape(-1) + 2e-4 * rng.standard_normal(c.n)
    va = v.reshape(-1) + 1e-6 * rng.standard_normal(c.n)
    res = c.kernel.evaluate(qa, va, jacobian=True, held_onset=c.held_onset)
    assert res.n_in_contact > 0
    free = (res.jac_q_blocks == 0.0).all(axis=(1, 2))
    assert free.any() and not free.all()      # some zeros to drop, some values to keep
    for f_q, f_v in [(1.0, 0.0), (0.7, 0.0), (1.0, 37.3), (0.3, 1.1e3)]:
        got = c.jacobian_triplets(res, f_q, f_v).copy()
        np.testing.assert_array_equal(got, _reference_triplets(c, res, f_q, f_v))


@pytest.mark.parametrize("n_elements", [1, 2, 5, 64])
def test_the_couplings_sparsity_pattern_is_numpys_unique_of_the_element_blocks(n_elements):
    from exucable.contact import block_sparsity
    from exucable.model.coupling import _chain_pattern

    rows, cols = block_sparsity(n_elements)
    n = 6 * (n_elements + 1)
    unique, inverse = np.unique(rows.astype(np.int64) * n + cols, return_inverse=True)
    got_rows, got_cols, got_inverse = _chain_pattern(n_elements)
    np.testing.assert_array_equal(got_rows, unique // n)
    np.testing.assert_array_equal(got_cols, unique % n)
    np.testing.assert_array_equal(got_inverse, inverse.reshape(-1))
