"""Compiled (numba) contact kernel: the fast path of :class:`exucable.contact.ContactKernel`.

Same equations as the numpy reference in :mod:`exucable.contact.kernel` (paper Eqs. 2-8, 14-23).
One pass per element, each step a loop over the element's check points over contiguous arrays
(struct of arrays, rows of one work table) so that LLVM vectorises it; the steps are
:mod:`.kernel_parts`, shared with the steady-sliding kernel (:mod:`.steady`):

- positions P = S(ξ) q_e from the Hermite values tabulated once per check point;
- narrow phase: segment-major over the element's candidate segments only, keeping per point the
  nearest distance, segment and residual P - Pc;
- force law with branch-free masks (a point out of contact gets weight 0, which zeroes its force
  and derivatives), skipped for elements without contact;
- Q_e and the 12×12 blocks Σ_k (N_k N_kᵀ) ⊗ J_k as contiguous sums, with the ten distinct
  products N_a N_b tabulated once (unit element length, scaled by L afterwards);
- nothing is allocated inside the loops.

Compiled by numba with ``cache=True``: the first call in a fresh environment compiles (tens of
seconds; ``exucable compile`` does it ahead), later processes load the machine code from disk (where, and the choice: :mod:`.jitcache`).
A :class:`FastKernel` owns its work buffers: use one per thread.
"""

from __future__ import annotations

import math

import numpy as np

from .broadphase import SweepBroadPhase, candidates_all_segments
from .jitcache import njit
from .kernel_parts import (
    AX, AY, AZ, BEST, BEYOND, DELTA, F, G, HF, J0, JIT_OPTIONS, PAIRS, PX, PY, PZ, ROWS, RX, RY, RZ, VX, VY,
    VZ, add_generalized_force, closest_points, exponent_mode_of, friction, held_onset_ramp, normal_force,
    normal_force_with_ramp, normals, onset_ramp, point_jacobians, positions, nearest_segments,
    segment_sectors,
)
from .smooth import NEWTON_ITERATIONS

__all__ = ["FastKernel"]

# segment table columns: start point A (3), unit axis a (3), length, end point B (3)
_SEG_COLUMNS = 10


@njit(**JIT_OPTIONS)
def _search_kernel(q, length, n1, n2, n3, n4, seg, off, cand, tab, nearest, open_first, open_last):
    """Contact search only (no force law): nearest segment of every check point, -1 if none."""
    for e in range(length.shape[0]):
        positions(q, 6 * e, length[e], n1, n2, n3, n4, tab[PX], tab[PY], tab[PZ])
        nearest_segments(tab[PX], tab[PY], tab[PZ], seg, cand, off[e], off[e + 1],
                          tab[BEST], nearest[e], tab[RX], tab[RY], tab[RZ], tab[AX],
                          tab[AY], tab[AZ], open_first, open_last, tab[BEYOND])


@njit(**JIT_OPTIONS)
def _points_kernel(q, qt, length, n1, n2, n3, n4, r1, r2, r3, r4, steady_speed, omega, seg, off,
                   cand, gap, stiffness, damping, exponent, exponent_mode, mu_k, dmu, inv_vs2, eps2,
                   inv_href, tab, sel, open_first, open_last, smooth, seg_piece, pieces, seg_phi,
                   n_newton, inv_onset, layer, out_seg, out_p, out_v, out_res, out_f, out_g, out_hf):
    """Per check point state for post-processing, by the same steps as :func:`_contact_kernel`:
    nearest segment (-1 without candidates), P, v, residual P - Pc (NaN without candidates),
    weighted normal force w f_n, |v_τ|² and μ w f_n/√(|v_τ|² + ε²).

    The velocity is ``positions(qt)`` with the tables r1..r4: the dynamic kernel's v = S(ξ) q̇
    (Eq. 8) with r = n and ``steady_speed`` 0; steady sliding's v = V ∂r/∂x with r = dN/dξ,
    qt = q and ``steady_speed`` = V [m/s] (as :func:`exucable.contact.steady._steady_kernel`)."""
    n_k = n1.shape[0]
    for e in range(length.shape[0]):
        c0 = off[e]
        c1 = off[e + 1]
        le = length[e]
        b = 6 * e
        r0 = e * n_k
        positions(q, b, le, n1, n2, n3, n4, tab[PX], tab[PY], tab[PZ])  # Eq. 2
        positions(qt, b, le, r1, r2, r3, r4, tab[VX], tab[VY], tab[VZ])  # Eq. 8
        if steady_speed != 0.0:
            # r = dN/dξ: positions gave L ∂r/∂x
            vs = steady_speed / le
            for k in range(n_k):
                tab[VX, k] *= vs
                tab[VY, k] *= vs
                tab[VZ, k] *= vs
        for k in range(n_k):
            out_p[r0 + k, 0] = tab[PX, k]
            out_p[r0 + k, 1] = tab[PY, k]
            out_p[r0 + k, 2] = tab[PZ, k]
            out_v[r0 + k, 0] = tab[VX, k]
            out_v[r0 + k, 1] = tab[VY, k]
            out_v[r0 + k, 2] = tab[VZ, k]
        if c0 == c1:
            for k in range(n_k):
                out_seg[r0 + k] = -1
                out_res[r0 + k, 0] = np.nan
                out_res[r0 + k, 1] = np.nan
                out_res[r0 + k, 2] = np.nan
                out_f[r0 + k] = 0.0
                out_g[r0 + k] = 0.0
                out_hf[r0 + k] = 0.0
            continue
        closest_points(tab, seg, cand, c0, c1, sel, open_first, open_last, smooth, seg_piece, pieces,
                        seg_phi, n_newton)
        normals(tab, n_k, gap, -1.0, layer)
        normal_force(tab, omega, n_k, le * inv_href, stiffness, damping, exponent,
                      exponent_mode, inv_onset)
        friction(tab, n_k, mu_k, dmu, inv_vs2, eps2)
        for k in range(n_k):
            out_seg[r0 + k] = sel[k]
            inside = 0.0 if tab[BEYOND, k] != 0.0 else 1.0  # beyond an open end: Pc = P, as numpy
            out_res[r0 + k, 0] = inside * tab[RX, k]
            out_res[r0 + k, 1] = inside * tab[RY, k]
            out_res[r0 + k, 2] = inside * tab[RZ, k]
            out_f[r0 + k] = tab[F, k]
            out_g[r0 + k] = tab[G, k]
            out_hf[r0 + k] = tab[HF, k]


@njit(**JIT_OPTIONS)
def _contact_kernel(q, qt, length, n1, n2, n3, n4, pair_t, pair_ab, omega, seg, off, cand,
                    gap, stiffness, damping, exponent, exponent_mode, mu_k, dmu, inv_vs2, eps2,
                    inv_href, jacobian, force, jq, jqt, tab, sel, acc, open_first, open_last,
                    smooth, seg_piece, pieces, seg_phi, n_newton, inv_onset, held_ramp, hold, delta_out, layer):
    """Generalized contact force and its 12×12 Jacobian blocks; returns (n_in_contact, max δ).

    ``delta_out[e, k]`` receives every point's penetration δ [m] (0 out of contact; the blended
    φ_s(δ) with an onset ``layer`` s > 0 [m], :func:`.kernel_parts.normals`). With ``hold``
    the damping onset is ``held_ramp[e, k]`` instead of g(δ) (see :class:`FastKernel`)."""
    n_k = n1.shape[0]
    n_contact = 0
    max_d2 = -1.0
    for e in range(length.shape[0]):
        c0 = off[e]
        c1 = off[e + 1]
        d_out = delta_out[e]
        if c0 == c1:
            d_out[:] = 0.0
            continue
        le = length[e]
        b = 6 * e
        positions(q, b, le, n1, n2, n3, n4, tab[PX], tab[PY], tab[PZ])  # Eq. 2
        closest_points(tab, seg, cand, c0, c1, sel, open_first, open_last, smooth, seg_piece, pieces,
                        seg_phi, n_newton)
        n_touch, max_d2 = normals(tab, n_k, gap, max_d2, layer)
        d_out[:] = tab[DELTA, :n_k]
        if n_touch == 0:
            continue
        n_contact += n_touch
        positions(qt, b, le, n1, n2, n3, n4, tab[VX], tab[VY], tab[VZ])  # Eq. 8
        if hold:
            held_onset_ramp(tab, n_k, held_ramp[e])
        else:
            onset_ramp(tab, n_k, inv_onset)
        normal_force_with_ramp(tab, omega, n_k, le * inv_href, stiffness, damping, exponent,
                                exponent_mode)
        friction(tab, n_k, mu_k, dmu, inv_vs2, eps2)
        add_generalized_force(tab, n1, n2, n3, n4, le, b, force)
        if not jacobian:
            continue
        point_jacobians(tab, n_k, stiffness, damping)
        _accumulate_blocks(tab, pair_t, pair_ab, le, acc, jq[e], jqt[e])
    max_pen = math.sqrt(max_d2) - gap if max_d2 >= 0.0 else -np.inf
    return n_contact, max_pen


@njit(inline="always", **JIT_OPTIONS)
def _accumulate_blocks(tab, pair_t, pair_ab, le, acc, bq, bqt):
    """Element blocks Σ_k (N_k N_kᵀ) ⊗ J_k from the ten distinct products N_a N_b."""
    n_k = pair_t.shape[1]
    p0 = pair_t[0]
    p1 = pair_t[1]
    p2 = pair_t[2]
    p3 = pair_t[3]
    p4 = pair_t[4]
    p5 = pair_t[5]
    p6 = pair_t[6]
    p7 = pair_t[7]
    p8 = pair_t[8]
    p9 = pair_t[9]
    for col in range(18):
        jc = tab[J0 + col]
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        s3 = 0.0
        s4 = 0.0
        s5 = 0.0
        s6 = 0.0
        s7 = 0.0
        s8 = 0.0
        s9 = 0.0
        for k in range(n_k):  # each J column read once for the ten products
            jv = jc[k]
            s0 += p0[k] * jv
            s1 += p1[k] * jv
            s2 += p2[k] * jv
            s3 += p3[k] * jv
            s4 += p4[k] * jv
            s5 += p5[k] * jv
            s6 += p6[k] * jv
            s7 += p7[k] * jv
            s8 += p8[k] * jv
            s9 += p9[k] * jv
        acc[0, col] = s0
        acc[1, col] = s1
        acc[2, col] = s2
        acc[3, col] = s3
        acc[4, col] = s4
        acc[5, col] = s5
        acc[6, col] = s6
        acc[7, col] = s7
        acc[8, col] = s8
        acc[9, col] = s9
    for p in range(10):
        a = pair_ab[p, 0]
        bb = pair_ab[p, 1]
        scale = 1.0
        if a == 1 or a == 3:  # slope shape functions carry a factor L
            scale *= le
        if bb == 1 or bb == 3:
            scale *= le
        for i in range(3):
            for j in range(3):
                vq = scale * acc[p, 3 * i + j]
                vt = scale * acc[p, 9 + 3 * i + j]
                bq[3 * a + i, 3 * bb + j] = vq
                bqt[3 * a + i, 3 * bb + j] = vt
                if a != bb:  # (N Nᵀ) is symmetric: block (b, a) has the same 3×3
                    bq[3 * bb + i, 3 * a + j] = vq
                    bqt[3 * bb + i, 3 * a + j] = vt



class FastKernel:
    """Numba evaluation of the contact force and Jacobian for a fixed conduit and cable mesh.

    Built by :class:`exucable.contact.ContactKernel`; see there for the parameters' meaning.

    Parameters
    ----------
    seg_start_m, seg_end_m, seg_axis, seg_length_m : ndarray
        Segment start/end points [m], unit axes and lengths [m].
    seg_lo_m, seg_hi_m : ndarray, shape (n_seg, 3)
        Segment boxes inflated by the inner radius [m].
    element_length_m : ndarray, shape (n_el,)
    nh_unit : ndarray, shape (n_k, 4)
        Hermite values of a unit-length element at the check points.
    omega : ndarray, shape (n_k,)
        Check point weights.
    law : ContactLaw
    gap_m : float
        Clearance R - r [m].
    cable_radius_m : float
    reference_spacing_m : float
    broad_phase : {"aabb", "none"}
    """

    def __init__(self, seg_start_m, seg_end_m, seg_axis, seg_length_m, seg_lo_m, seg_hi_m,
                 element_length_m, nh_unit, omega, law, gap_m, cable_radius_m,
                 reference_spacing_m, broad_phase, open_ends=True, wall=None):
        n_s = seg_start_m.shape[0]
        self.open_first = 0 if open_ends else -1
        self.open_last = n_s - 1 if open_ends else -1
        self.smooth = wall is not None
        if wall is not None:
            self.seg_piece, self.pieces = wall.seg_piece, wall.pieces
            self.seg_phi = segment_sectors(wall.seg_phi)
        else:
            self.seg_piece = np.zeros(n_s, dtype=np.int64)
            self.pieces = np.zeros((1, 16))
            self.seg_phi = np.zeros((n_s, 6))
        self.seg = np.empty((n_s, _SEG_COLUMNS))
        self.seg[:, 0:3] = seg_start_m
        self.seg[:, 3:6] = seg_axis
        self.seg[:, 6] = seg_length_m
        self.seg[:, 7:10] = seg_end_m
        self.length = np.ascontiguousarray(element_length_m, dtype=float)
        self.nh = np.ascontiguousarray(nh_unit, dtype=float)
        self.omega = np.ascontiguousarray(omega, dtype=float)
        # N_a N_b of a unit-length element, one row per (a, b) of PAIRS
        self.pair_t = np.ascontiguousarray((self.nh[:, PAIRS[:, 0]] * self.nh[:, PAIRS[:, 1]]).T)
        self.gap = float(gap_m)
        self.law = law
        self.inv_href = 1.0 / float(reference_spacing_m)
        self.n_el = self.length.shape[0]
        self.n_coordinates = 6 * (self.n_el + 1)
        self.broad_phase = broad_phase
        if broad_phase == "aabb":
            self.sweep = SweepBroadPhase(seg_lo_m, seg_hi_m, self.length, cable_radius_m)
        else:
            self.all_off, self.all_cand = candidates_all_segments(self.n_el, n_s)
        n_k = self.nh.shape[0]
        self._n = [np.ascontiguousarray(self.nh[:, i]) for i in range(4)]
        self._sel = np.empty(n_k, dtype=np.int64)
        self._tab = np.empty((ROWS, n_k))
        self._acc = np.empty((10, 18))
        self._empty_blocks = np.empty((0, 12, 12))
        self._no_onset = np.empty((self.n_el, n_k))

    def candidates(self, q):
        """CSR candidate segment lists (offsets, indices) for coordinates ``q``."""
        if self.broad_phase == "aabb":
            return self.sweep.candidates(q)
        return self.all_off, self.all_cand

    def nearest_segments(self, q):
        """Contact search only: nearest segment per check point, shape (n_el, n_k) (-1: none)."""
        q = np.ascontiguousarray(q, dtype=float)
        off, cand = self.candidates(q)
        nearest = np.empty((self.n_el, self.nh.shape[0]), dtype=np.int64)
        n1, n2, n3, n4 = self._n
        _search_kernel(q, self.length, n1, n2, n3, n4, self.seg, off, cand, self._tab, nearest,
                       self.open_first, self.open_last)
        return nearest

    def evaluate(self, q, q_t, jacobian, held_onset=None):
        """Return (Q, ∂Q/∂q blocks or None, ∂Q/∂q̇ blocks or None, n_in_contact, max δ [m],
        δ [m] per point (n_el, n_k), 0 out of contact); ``held_onset``: the damping onset g per
        point, shape (n_el, n_k), instead of g(δ) (see ContactKernel.evaluate)."""
        q = np.ascontiguousarray(q, dtype=float)
        q_t = np.ascontiguousarray(q_t, dtype=float)
        off, cand = self.candidates(q)
        force = np.zeros(self.n_coordinates)
        if jacobian:
            jq = np.zeros((self.n_el, 12, 12))
            jqt = np.zeros((self.n_el, 12, 12))
        else:
            jq = jqt = self._empty_blocks
        n1, n2, n3, n4 = self._n
        penetration = np.empty((self.n_el, self.nh.shape[0]))
        hold = held_onset is not None
        onset = np.ascontiguousarray(held_onset, dtype=float) if hold else self._no_onset
        n_contact, max_pen = _contact_kernel(
            q, q_t, self.length, n1, n2, n3, n4, self.pair_t, PAIRS, self.omega, self.seg, off,
            cand, self.gap, *self._law_arguments(),
            self.inv_href, bool(jacobian), force, jq, jqt, self._tab, self._sel, self._acc,
            self.open_first, self.open_last, self.smooth, self.seg_piece, self.pieces, self.seg_phi,
            NEWTON_ITERATIONS, self._inverse_onset(), onset, hold, penetration, float(self.law.onset_layer_m))
        if not jacobian:
            jq = jqt = None
        return force, jq, jqt, int(n_contact), float(max_pen), penetration

    def _law_arguments(self):
        """The law's numbers as both kernels take them: K, C, e, e's mode, μ_k, μ_s - μ_k, 1/v_s², ε²."""
        law = self.law
        return (float(law.stiffness), float(law.damping), float(law.exponent), exponent_mode_of(law.exponent),
                float(law.friction), float(law.static_excess), 1.0 / law.stribeck_velocity_m_per_s**2,
                law.regularisation_velocity_m_per_s**2)

    def _inverse_onset(self):
        """1/δ_d of the damping onset [1/m], 0 for the paper's step."""
        onset = self.law.damping_onset_m
        return 1.0 / onset if onset > 0.0 else 0.0

    def point_state(self, q, q_t):
        """Per check point (element-major): nearest segment (-1: none), P [m], v [m/s], residual
        P - Pc [m] (NaN without a segment), weighted normal force w·f_n [N], sliding speed |v_τ|
        [m/s] and friction force [N] (both 0 where there is no force)."""
        return self.point_state_with_rates(q, q_t, self._n, 0.0)

    def point_state_with_rates(self, q, rate_source, rate_tables, steady_speed_m_per_s):
        """:meth:`point_state` with the velocity v = ``positions(rate_source, rate_tables)``,
        times V/L_e if ``steady_speed_m_per_s`` V is not 0 (steady sliding: v = V ∂r/∂x with the
        tables dN/dξ and ``rate_source`` = q; see :mod:`exucable.contact.steady`)."""
        q = np.ascontiguousarray(q, dtype=float)
        q_t = np.ascontiguousarray(rate_source, dtype=float)
        off, cand = self.candidates(q)
        m = self.n_el * self.nh.shape[0]
        segment = np.empty(m, dtype=np.int64)
        p, v, res = np.empty((m, 3)), np.empty((m, 3)), np.empty((m, 3))
        f, g, hf = np.empty(m), np.empty(m), np.empty(m)
        n1, n2, n3, n4 = self._n
        r1, r2, r3, r4 = rate_tables
        _points_kernel(q, q_t, self.length, n1, n2, n3, n4, r1, r2, r3, r4, float(steady_speed_m_per_s),
                       self.omega, self.seg, off, cand, self.gap,
                       *self._law_arguments(), self.inv_href, self._tab, self._sel, self.open_first,
                       self.open_last, self.smooth, self.seg_piece, self.pieces, self.seg_phi,
                       NEWTON_ITERATIONS, self._inverse_onset(), float(self.law.onset_layer_m),
                       segment, p, v, res, f, g, hf)
        acting = f > 0.0
        slip = np.where(acting, np.sqrt(g), 0.0)
        return {"segment": segment, "position_m": p, "velocity_m_per_s": v, "residual_m": res,
                "normal_force_N": np.where(acting, f, 0.0), "sliding_velocity_m_per_s": slip,
                "friction_force_N": np.where(acting, hf * slip, 0.0)}
