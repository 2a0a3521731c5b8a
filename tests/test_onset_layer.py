"""The smooth contact onset (ContactLaw.onset_layer_m, exucable/contact/law.py: onset_blend) and its
continuation toward the law without it (exucable/solve/onset_continuation.py).

References independent of the kernels: the blend's closed form and its one-sided derivatives at
the layer's ends, the Hertz force of a point at a known distance in the layer (K ((δ + s)²/4s)^e),
central finite differences of the generalized force for the exact Jacobians, the numpy definitions
for the compiled kernels (wall: dynamic and steady sliding; cable-cable), and Richardson's step on
a function linear in s. s = 0 is the law without a layer: the kernels' own tests
(tests/test_contact_kernel.py, tests/test_cable_pairs.py, tests/test_contact_smooth.py) hold it.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from exucable.contact import ContactKernel, ContactLaw, assemble_blocks_dense
from exucable.contact.cable_pairs import CableContactKernel
from exucable.contact.law import onset_blend
from exucable.contact.steady import SteadySlidingKernel
from exucable.solve.onset_continuation import OnsetSettings, extrapolate_to_zero

from test_cable_pairs import R as R_PAIR, central_differences, kernel as pair_kernel, straight_cable
from test_contact_smooth import GAP, R_CABLE, cable_on_offset_curve, conduit, fd_jacobians, towards_centre

LAYER = 3e-4
LAW = ContactLaw(stiffness=1e6, damping=1e3, exponent=1.5, friction=0.2, damping_onset_m=2e-4,
                 onset_layer_m=LAYER)


def test_blend_is_continuous_with_its_slope_and_zero_layer_is_max():
    s = LAYER
    d = np.array([-2 * s, -s, -0.5 * s, 0.0, 0.5 * s, s, 2 * s])
    phi, dphi = onset_blend(d, s)
    np.testing.assert_allclose(phi, [0, 0, s / 16, s / 4, 9 * s / 16, s, 2 * s], rtol=1e-15, atol=0)
    np.testing.assert_allclose(dphi, [0, 0, 0.25, 0.5, 0.75, 1, 1], rtol=1e-15, atol=0)
    # C¹ at both ends of the layer: one-sided values and slopes meet
    for end in (-s, s):
        h = 1e-9 * s
        lo, hi = onset_blend(np.array([end - h, end + h]), s)
        assert abs(lo[1] - lo[0]) <= 2.1 * h and abs(hi[1] - hi[0]) <= 1e-8
    # the slope is the derivative (central differences)
    x = np.linspace(-1.5 * s, 1.5 * s, 31)
    h = 1e-7 * s
    fd = (onset_blend(x + h, s)[0] - onset_blend(x - h, s)[0]) / (2 * h)
    np.testing.assert_allclose(onset_blend(x, s)[1], fd, atol=1e-6)
    phi0, dphi0 = onset_blend(d, 0.0)
    assert np.array_equal(phi0, np.maximum(d, 0.0)) and np.all(dphi0 == 1.0)


def _wall_case(kind="bend", steady=False):
    """A cable 6 elements long along a bend, its axis from 0.8 s inside to 1.5 s beyond the
    contact surface (points in the layer, across it and in contact)."""
    cond = conduit(kind)
    s_nodes = np.linspace(0.35, 1.05, 7)      # inside the bend (0.3 to 1.085 m)
    rng = np.random.default_rng(3)
    q, q_t = cable_on_offset_curve(cond, s_nodes, towards_centre(cond), GAP, rng=rng, noise=0.02)
    q = q.reshape(-1, 6)
    kn = cond.centreline.curvature_vector(s_nodes)
    q[:, :3] += np.linspace(-0.8, 1.5, 7)[:, None] * LAYER * kn / np.linalg.norm(kn, axis=1, keepdims=True)
    L = np.diff(s_nodes)
    cls = (lambda *a, **k: SteadySlidingKernel(*a, speed_m_per_s=0.1, **k)) if steady else ContactKernel
    ks = {b: cls(cond.segments, L, R_CABLE, LAW, 6, backend=b, surface="smooth", centreline=cond.centreline)
          for b in ("numpy", "numba")}
    return q.reshape(-1), q_t, ks


@pytest.mark.parametrize("steady", [False, True])
def test_wall_kernels_with_a_layer_agree_and_their_jacobians_are_exact(steady):
    q, q_t, ks = _wall_case(steady=steady)
    a, b = (ks[x].evaluate(q, q_t, jacobian=True) for x in ("numpy", "numba"))
    pen = ks["numpy"].points(q, q_t).penetration_m
    assert a.n_in_contact == b.n_in_contact > 0
    # the case has points in the layer's lower half, in its upper half and beyond it
    assert np.any((pen > -LAYER) & (pen < -LAYER / 2)) and np.any((pen > 0) & (pen < LAYER)) and np.any(pen > LAYER)
    assert np.abs(a.generalized_force - b.generalized_force).max() <= 1e-11 * np.abs(a.generalized_force).max()
    assert np.abs(a.jac_q_blocks - b.jac_q_blocks).max() <= 1e-10 * np.abs(a.jac_q_blocks).max()
    if b.penetration_m is not None:         # the compiled steady kernel reports none
        # the closest points' round-off, as in tests/test_contact_smooth.py, on the scale of s
        np.testing.assert_allclose(b.penetration_m, a.penetration_m, rtol=1e-12, atol=1e-12 * LAYER)
    jq_fd, jqt_fd = fd_jacobians(ks["numpy"], q, q_t)
    assert np.abs(assemble_blocks_dense(a.jac_q_blocks) - jq_fd).max() < 1e-6 * np.abs(jq_fd).max()
    if not steady:
        assert np.abs(assemble_blocks_dense(a.jac_qt_blocks) - jqt_fd).max() < 1e-6 * np.abs(jqt_fd).max()


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_a_point_in_the_layer_carries_the_blended_hertz_force(backend):
    """Two parallel straight cables with their surfaces s/2 apart (δ = -s/2): each check point
    carries w K ((δ + s)²/4s)^e = w K (s/16)^1.5; pulled apart by more than s, none."""
    n_el, Le, s = 6, 0.1, 2e-5
    law = ContactLaw(stiffness=1e6, damping=0.0, exponent=1.5, friction=0.0, onset_layer_m=s)
    k = CableContactKernel(2, np.full(n_el, Le), R_PAIR, law, 4, 1e-3, 0.1, backend=backend)
    q = np.concatenate([straight_cable(n_el, Le, 0.0, 0.0), straight_cable(n_el, Le, 2 * R_PAIR + s / 2, 0.0)])
    c = k.contacts(q)
    w = Le / 4 / 1e-3
    np.testing.assert_allclose(c["force"][:, 1], -w * 1e6 * (s / 16) ** 1.5, rtol=1e-9)
    far = np.concatenate([straight_cable(n_el, Le, 0.0, 0.0), straight_cable(n_el, Le, 2 * R_PAIR + 1.01 * s, 0.0)])
    assert len(k.contacts(far)["t"]) == 0


def _pair_layer_case(seed):
    """The trefoil of tests/test_cable_pairs.py with the cables 0.1 mm apart instead of pressed,
    perturbed: contacts in a 0.2 mm layer and pressed."""
    rng = np.random.default_rng(seed)
    gap = 2 * R_PAIR + 1e-4
    return np.concatenate([straight_cable(4, 0.05, 0.0, 0.0, rng, 1e-4),
                           straight_cable(4, 0.05, gap, 0.0, rng, 1e-4),
                           straight_cable(4, 0.05, gap / 2, gap * np.sqrt(3) / 2, rng, 1e-4)])


@pytest.mark.parametrize("damping", [0.0, 50.0])
def test_cable_pair_kernels_with_a_layer_agree_and_their_jacobians_are_exact(damping):
    law = ContactLaw(stiffness=1e6, damping=damping, exponent=1.5, friction=0.3,
                     regularisation_velocity_m_per_s=1e-3, damping_onset_m=5e-5, onset_layer_m=2e-4)
    q = _pair_layer_case(7)
    ka, kb = pair_kernel("numpy", law=law), pair_kernel("numba", law=law)
    a, b = ka.evaluate(q), kb.evaluate(q)
    pen = ka.contacts(q)["penetration_m"]
    assert a.n_in_contact == b.n_in_contact == len(pen)
    assert np.any(pen < -1e-4) and np.any((pen < 0) & (pen > -1e-4)) and np.any(pen > 0)   # in the layer and beyond
    scale = np.abs(a.generalized_force).max()
    np.testing.assert_allclose(b.generalized_force, a.generalized_force, rtol=0, atol=1e-11 * scale)
    assert abs(a.jacobian - b.jacobian).max() <= 1e-11 * abs(a.jacobian).max()
    J = b.jacobian.toarray()
    assert np.abs(J - central_differences(kb, q)).max() <= 1e-6 * np.abs(J).max()


def test_the_layer_is_set_and_refused_on_the_kernels():
    """set_onset_layer survives a friction scale; a layer as thick as the clearance is refused."""
    q, q_t, ks = _wall_case(steady=True)
    k = ks["numba"]
    base = replace(LAW, onset_layer_m=0.0)
    k2 = SteadySlidingKernel(k.segments, k.element_length_m, R_CABLE, base, 6, backend="numba", surface="smooth",
                             centreline=conduit("bend").centreline, speed_m_per_s=0.1)
    k2.set_onset_layer(LAYER)
    k2.set_friction_scale(0.5)
    assert k2.law.onset_layer_m == LAYER
    np.testing.assert_array_equal(k2.evaluate(q, q_t).generalized_force,
                                  SteadySlidingKernel(k.segments, k.element_length_m, R_CABLE,
                                                      replace(LAW, friction=0.5 * LAW.friction), 6, backend="numba",
                                                      surface="smooth", centreline=conduit("bend").centreline,
                                                      speed_m_per_s=0.1).evaluate(q, q_t).generalized_force)
    with pytest.raises(ValueError, match="onset layer"):
        k2.set_onset_layer(GAP)
    with pytest.raises(ValueError, match="onset_layer_m"):
        ContactLaw(onset_layer_m=-1e-6)


def test_richardson_step_recovers_a_linear_dependence_and_the_layers_halve():
    s = [4e-4, 2e-4, 1e-4]
    f = [500.0 + 2e4 * x for x in s]
    f0, err = extrapolate_to_zero(s, f)
    assert f0 == pytest.approx(500.0, rel=1e-14) and err == pytest.approx(2.0, rel=1e-12)
    assert extrapolate_to_zero(s + [0.0], f + [499.9]) == (499.9, 0.0)
    layers = OnsetSettings(first_m=4e-4, floor_m=1e-4).layers_m()
    assert layers == [4e-4, 2e-4, 1e-4, 0.0]
    from exucable.solve.error_bar import RESOLUTION_FLOOR
    assert OnsetSettings().tolerance == RESOLUTION_FLOOR


class _FakeSolver:
    """The parts of SteadySolver the continuation drives: a model whose pull is F(s) = 500 N + 1e5 N/m · s
    (linear: Richardson's step is exact), whose solves converge at layers in ``converges(s)``."""

    class _Model:
        def __init__(self):
            self.layer, self.coupling = None, None
            self.kernel = self

        def set_onset_layer(self, s):
            self.layer = s

        def steady_forces(self):
            return 500.0 + 1e5 * self.layer, 0.0, 0.0

    class _Store:
        saved = ("state",)

    def __init__(self, converges):
        from exucable.solve.steady import SteadySettings

        self.model, self.store, self.settings = self._Model(), self._Store(), SteadySettings()
        self.converges, self.timed_out, self.newton_iterations, self._trace = converges, False, 0, [1e-5]
        self.tried = []

    def relax_one_iteration(self, lam, skip=0):
        self.tried.append(self.model.layer)
        self.newton_iterations += 10
        return self.converges(self.model.layer), "stalled"

    def relax(self, lam):
        return self.converges(self.model.layer), "stalled"

    def at_scale(self, lam):
        pass


def _descend(converges, **settings):
    from exucable.solve.onset_continuation import OnsetContinuation

    solver = _FakeSolver(converges)
    onset = OnsetContinuation(OnsetSettings(**settings))
    onset.begin(solver.model)
    status, message = onset.descend(solver, "first layer solved")
    return onset, solver, status, message


def test_the_continuation_reaches_the_law_without_a_layer():
    onset, solver, status, _ = _descend(lambda s: True, first_m=4e-4, floor_m=1e-4)
    assert status == "ok" and onset.layer_m == 0.0 and solver.model.layer == 0.0
    assert [st.layer_m for st in onset.stages] == [4e-4, 2e-4, 1e-4, 0.0]
    assert onset.stages[-1].pull_force_N == 500.0 and onset.layer_error_N == 0.0


def test_a_stalled_layer_is_retried_nearer_and_a_finite_layer_stands_within_the_floor():
    """The layer 50 µm stalls, s = 0 never converges: 200 → 100 → (50 stalls) → 70.7 (the factor's
    square root) → 35.4 (the factor back to 2) ... → 0.4 µm (the floor) → (0 stalls). The answer at the
    last layer solved is kept only where its distance to the extrapolation, here exactly
    1e5 N/m · s, is within 1e-4 of it."""
    onset, solver, status, message = _descend(lambda s: s not in (0.0, 5e-5), first_m=2e-4, floor_m=4e-7)
    assert solver.tried[:4] == [1e-4, 5e-5, pytest.approx(1e-4 / 2 ** 0.5), pytest.approx(0.5e-4 / 2 ** 0.5)]
    assert solver.tried[-2:] == [pytest.approx(4e-7), 0.0]
    assert onset.layer_m == pytest.approx(4e-7) and solver.model.layer == onset.layer_m      # back at the floor
    assert onset.extrapolated_N == pytest.approx(500.0, rel=1e-12)
    assert onset.layer_error_N == pytest.approx(1e5 * 4e-7, rel=1e-6)        # 0.04 N < 1e-4 · 500 N
    assert status == "ok" and "the answer at the onset layer 0.4 µm" in message
    # a floor where the layer's error is larger than 1e-4 of the answer: failed, saying so
    onset, _, status, message = _descend(lambda s: s > 0.0, first_m=2e-4, floor_m=1e-4)
    assert status == "failed" and onset.layer_error_N == pytest.approx(10.0) and "100 µm" in message
