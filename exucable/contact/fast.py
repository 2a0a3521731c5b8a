"""Compiled (numba) contact kernel: the fast path of :class:`exucable.contact.ContactKernel`.

Same equations as the numpy reference in :mod:`exucable.contact.kernel` (paper Eqs. 2-8, 14-23).
One pass per element, each step a loop over the element's check points over contiguous arrays
(struct of arrays, rows of one work table) so that LLVM vectorises it:

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
from .smooth import NEWTON_ITERATIONS

__all__ = ["FastKernel"]

# Reassociation lets LLVM vectorise the sums over check points; no-NaN/no-inf assumptions are left
# out on purpose (a point without candidate segments carries an infinite distance).
_FASTMATH = {"nsz", "arcp", "contract", "reassoc"}

# (a, b) node-block pairs with a <= b, in the order of the columns of the pair table
_PAIRS = np.array([(a, b) for a in range(4) for b in range(a, 4)], dtype=np.int64)

# segment table columns: start point A (3), unit axis a (3), length, end point B (3)
_SEG_COLUMNS = 10


# cached on disk where numba can write (.jitcache adds cache=...: where, and what happens when it cannot)
_JIT = dict(fastmath=_FASTMATH, nogil=True, error_model="numpy")

# Rows of the per-element work table, one column per check point. Each loop below reads and
# writes contiguous rows; LLVM vectorises a loop only while the number of runtime alias checks
# between its arrays stays small (measured: about s(s-1)/2 + s·l <= 128 for s written and l read
# rows), hence several short loops rather than one long one.
_PX, _PY, _PZ, _BEST = 0, 1, 2, 3  # position P, squared distance to the nearest segment
_RX, _RY, _RZ = 4, 5, 6  # residual P - Pc
_AX, _AY, _AZ = 7, 8, 9  # segment axis where the projection is inside the segment, else 0
_NX, _NY, _NZ = 10, 11, 12  # contact normal n
_INVD, _DELTA, _TOUCH = 13, 14, 15  # 1/d, penetration δ, 1 where δ > 0 else 0
_VX, _VY, _VZ = 16, 17, 18  # velocity v
_VN, _G, _F, _WACT, _DDPOW = 19, 20, 21, 22, 23  # v_n, |v_τ|², w f_n, w (0 if no force), dδ^e/dδ
_TX, _TY, _TZ = 24, 25, 26  # sliding velocity v_τ
_MU, _DMU, _SR, _HF = 27, 28, 29, 30  # μ, dμ/d|v_τ|², √(|v_τ|² + ε²), μ w f_n / √(...)
_FX = 31  # rows 31..33: force F on the cable [N]
_MVX, _MTX = 34, 37  # rows 34..36: M v, rows 37..39: M v_τ (M = ∂n/∂P)
_KD, _WC, _FM, _C2, _GV, _MUS = 40, 41, 42, 43, 44, 45  # scalar factors of the Jacobian
_J0 = 46  # rows 46..63: ∂F/∂P (9, row-major) then ∂F/∂v (9)
_BEYOND = 64  # 1 where the nearest segment is an open end's and the point lies past it
_RAMP, _DRAMP = 65, 66  # damping onset g(δ) and dg/dδ
_ROWS = 67


@njit(inline="always", **_JIT)
def _positions(q, b, le, n1, n2, n3, n4, px, py, pz):
    """Check point positions P = S(ξ) q_e (Eq. 2) of the element whose coordinates start at q[b]."""
    r0 = q[b]
    r1 = q[b + 1]
    r2 = q[b + 2]
    s0 = le * q[b + 3]
    s1 = le * q[b + 4]
    s2 = le * q[b + 5]
    u0 = q[b + 6]
    u1 = q[b + 7]
    u2 = q[b + 8]
    t0 = le * q[b + 9]
    t1 = le * q[b + 10]
    t2 = le * q[b + 11]
    for k in range(n1.shape[0]):
        px[k] = n1[k] * r0 + n2[k] * s0 + n3[k] * u0 + n4[k] * t0
        py[k] = n1[k] * r1 + n2[k] * s1 + n3[k] * u1 + n4[k] * t1
        pz[k] = n1[k] * r2 + n2[k] * s2 + n3[k] * u2 + n4[k] * t2


@njit(inline="always", **_JIT)
def _nearest_segments(px, py, pz, seg, cand, c0, c1, best, sel, rx, ry, rz, ax_in, ay_in,
                      az_in, open_first, open_last, beyond):
    """Narrow phase of one element: nearest candidate segment of every check point.

    Projection parameter clamped to the segment (a point beyond a kink's outer side sees the
    vertex). Segment-major so that the inner loop over points vectorises; the strict ``<`` in
    increasing candidate order keeps the lower segment index on ties, as the numpy reference.
    A point beyond the conduit's open ends (before segment ``open_first``'s start or past
    segment ``open_last``'s end; -1 = closed) is outside the conduit: it gets d² = 0, no contact.
    That is decided after the search, on the nearest segment by true distance: a point far from
    the ends may well lie behind the first segment's start plane.
    """
    n_k = px.shape[0]
    for k in range(n_k):
        best[k] = np.inf
        sel[k] = -1
        rx[k] = 0.0
        ry[k] = 0.0
        rz[k] = 0.0
        ax_in[k] = 0.0
        ay_in[k] = 0.0
        az_in[k] = 0.0
        beyond[k] = 0.0
    for c in range(c0, c1):
        s = cand[c]
        sax = seg[s, 0]
        say = seg[s, 1]
        saz = seg[s, 2]
        ax = seg[s, 3]
        ay = seg[s, 4]
        az = seg[s, 5]
        ln = seg[s, 6]
        sbx = seg[s, 7]
        sby = seg[s, 8]
        sbz = seg[s, 9]
        end0 = s == open_first
        end1 = s == open_last
        for k in range(n_k):
            dx = px[k] - sax
            dy = py[k] - say
            dz = pz[k] - saz
            t = dx * ax + dy * ay + dz * az
            low = t <= 0.0
            high = t >= ln
            ex = dx - t * ax
            ey = dy - t * ay
            ez = dz - t * az
            ex = px[k] - sbx if high else ex  # clamped to the end vertex
            ey = py[k] - sby if high else ey
            ez = pz[k] - sbz if high else ez
            ex = dx if low else ex  # clamped to the start vertex
            ey = dy if low else ey
            ez = dz if low else ez
            d2 = ex * ex + ey * ey + ez * ez
            past = 1.0 if ((low & end0) | (high & end1)) else 0.0
            inside = 0.0 if (low | high) else 1.0
            if d2 < best[k]:  # strict: ties keep the lower segment index
                best[k] = d2
                sel[k] = s
                rx[k] = ex
                ry[k] = ey
                rz[k] = ez
                ax_in[k] = inside * ax
                ay_in[k] = inside * ay
                az_in[k] = inside * az
                beyond[k] = past
    for k in range(n_k):
        best[k] = 0.0 if beyond[k] != 0.0 else best[k]


# A bend point's direction must clear its segment's sector sides by this angle [rad] to skip the
# angle test: far above the rounding of that test's unwrapped atan2 (~1e-15 rad) and of the
# sectors' own ends (SmoothWall's segment angles vs the piece's Φ).
_SECTOR_MARGIN = 1e-9


def segment_sectors(seg_phi):
    """The smooth wall's segment angles [rad], shape (n_seg, 2), extended by the sector sides
    (cos, sin) of each segment's start and end angle: shape (n_seg, 6). A segment spanning π/2 or
    more gets zero sides, so that no point is ever found inside its sector (the exact test runs)."""
    phi = np.asarray(seg_phi, dtype=float)
    out = np.zeros((phi.shape[0], 6))
    out[:, :2] = phi
    narrow = np.abs(phi[:, 1] - phi[:, 0]) < 0.5 * math.pi
    out[narrow, 2] = np.cos(phi[narrow, 0])
    out[narrow, 3] = np.sin(phi[narrow, 0])
    out[narrow, 4] = np.cos(phi[narrow, 1])
    out[narrow, 5] = np.sin(phi[narrow, 1])
    return out


@njit(inline="always", **_JIT)
def _chord_angle(px, py, pz, seg, sg, seg_phi):
    """The chord's estimate of a point's helix angle [rad]: from its clamped projection parameter
    on segment ``sg``, linear between the segment's end angles."""
    dx = px - seg[sg, 0]
    dy = py - seg[sg, 1]
    dz = pz - seg[sg, 2]
    ln = seg[sg, 6]
    t = dx * seg[sg, 3] + dy * seg[sg, 4] + dz * seg[sg, 5]
    t = min(max(t, 0.0), ln)
    return seg_phi[sg, 0] + t / ln * (seg_phi[sg, 1] - seg_phi[sg, 0])


@njit(inline="always", **_JIT)
def _refine_smooth(px, py, pz, seg, sel, best, rx, ry, rz, ax_in, ay_in, az_in, seg_piece, pieces,
                   seg_phi, n_newton):
    """Closest points on the exact bends/helices (see :mod:`exucable.contact.smooth`).

    Overwrites the residual, the squared distance and the Jacobian axis √β·T of every point whose
    nearest segment lies on a curved piece. Points beyond an open end (d² = 0) are left alone.
    ``seg_phi`` is :func:`segment_sectors`' table: a point on a bend whose direction lies inside its
    nearest segment's angular sector is inside the bend, and needs no angle (no atan2).
    """
    for k in range(px.shape[0]):
        sg = sel[k]
        if sg < 0 or best[k] == 0.0:
            continue
        pi = seg_piece[sg]
        if pieces[pi, 15] == 0.0:
            continue
        xx = px[k] - pieces[pi, 0]
        xy = py[k] - pieces[pi, 1]
        xz = pz[k] - pieces[pi, 2]
        x1 = xx * pieces[pi, 3] + xy * pieces[pi, 4] + xz * pieces[pi, 5]
        x2 = xx * pieces[pi, 6] + xy * pieces[pi, 7] + xz * pieces[pi, 8]
        xk = xx * pieces[pi, 9] + xy * pieces[pi, 10] + xz * pieces[pi, 11]
        a = pieces[pi, 12]
        h = pieces[pi, 13]
        big_phi = pieces[pi, 14]
        rho = 0.0
        in_sector = False
        if h == 0.0:
            # a bend: strictly inside the segment's sector (by _SECTOR_MARGIN rad) is inside
            # [0, Φ] for the angle test below too, whatever its rounding
            rho = math.sqrt(x1 * x1 + x2 * x2)
            margin = _SECTOR_MARGIN * rho
            in_sector = ((seg_phi[sg, 2] * x2 - seg_phi[sg, 3] * x1 > margin)
                         & (seg_phi[sg, 5] * x1 - seg_phi[sg, 4] * x2 > margin))
        if in_sector:
            inside = True
            cs = x1 / rho
            sn = x2 / rho
            phic = 0.0  # unused on a bend (h = 0)
        elif h == 0.0:
            # a bend: the closest point is in the direction of P's projection, no iteration;
            # the angle (for the range test only) unwrapped next to the chord's estimate
            phi = _chord_angle(px[k], py[k], pz[k], seg, sg, seg_phi)
            ang = math.atan2(x2, x1)
            phi = phi + ((ang - phi + math.pi) % (2.0 * math.pi) - math.pi)
            inside = 0.0 <= phi <= big_phi
            if inside:
                cs = x1 / rho
                sn = x2 / rho
                phic = phi
            else:
                phic = min(max(phi, 0.0), big_phi)
                cs = math.cos(phic)
                sn = math.sin(phic)
        else:
            phi = _chord_angle(px[k], py[k], pz[k], seg, sg, seg_phi)
            # Newton on the helix angle; the steps are tiny (the chord's estimate is close), so
            # cos/sin are carried along by rotating with the series of the step (error < 1e-14
            # for |Δφ| < 1e-2) instead of being recomputed: 2 trigonometric calls per point
            cs = math.cos(phi)
            sn = math.sin(phi)
            for _ in range(n_newton):
                g = -(a * (-sn * x1 + cs * x2) + h * (xk - h * phi))
                dg = a * (cs * x1 + sn * x2) + h * h
                dphi = -g / dg
                phi = phi + dphi
                if abs(dphi) < 1e-2:
                    d2 = dphi * dphi
                    c_d = 1.0 - d2 * (0.5 - d2 / 24.0)
                    s_d = dphi * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0))
                    cs, sn = cs * c_d - sn * s_d, sn * c_d + cs * s_d
                else:
                    cs = math.cos(phi)
                    sn = math.sin(phi)
            inside = 0.0 <= phi <= big_phi
            phic = min(max(phi, 0.0), big_phi)
            if not inside:
                cs = math.cos(phic)
                sn = math.sin(phic)
        w = math.sqrt(a * a + h * h)
        r1 = x1 - a * cs
        r2 = x2 - a * sn
        r3 = xk - h * phic
        t1 = -a * sn / w
        t2 = a * cs / w
        t3 = h / w
        beta = 1.0
        if inside:
            # κ = -(a/w²)(cos φ e1 + sin φ e2);  β = 1/(1 - r·κ)
            beta = 1.0 / (1.0 + a / (w * w) * (r1 * cs + r2 * sn))
        else:
            along = r1 * t1 + r2 * t2 + r3 * t3
            r1 -= along * t1
            r2 -= along * t2
            r3 -= along * t3
        sb = math.sqrt(beta)
        e1x = pieces[pi, 3]
        e1y = pieces[pi, 4]
        e1z = pieces[pi, 5]
        e2x = pieces[pi, 6]
        e2y = pieces[pi, 7]
        e2z = pieces[pi, 8]
        kx = pieces[pi, 9]
        ky = pieces[pi, 10]
        kz = pieces[pi, 11]
        rx[k] = r1 * e1x + r2 * e2x + r3 * kx
        ry[k] = r1 * e1y + r2 * e2y + r3 * ky
        rz[k] = r1 * e1z + r2 * e2z + r3 * kz
        best[k] = r1 * r1 + r2 * r2 + r3 * r3
        ax_in[k] = sb * (t1 * e1x + t2 * e2x + t3 * kx)
        ay_in[k] = sb * (t1 * e1y + t2 * e2y + t3 * ky)
        az_in[k] = sb * (t1 * e1z + t2 * e2z + t3 * kz)


@njit(inline="always", **_JIT)
def _closest_points(tab, seg, cand, c0, c1, sel, open_first, open_last, smooth, seg_piece, pieces,
                    seg_phi, n_newton):
    """Closest point Pc of every check point of the element: nearest candidate segment, then on
    the smooth wall refined onto the exact bend or helix (rows _BEST, _RX..., _AX..., _BEYOND)."""
    _nearest_segments(tab[_PX], tab[_PY], tab[_PZ], seg, cand, c0, c1, tab[_BEST], sel,
                      tab[_RX], tab[_RY], tab[_RZ], tab[_AX], tab[_AY], tab[_AZ],
                      open_first, open_last, tab[_BEYOND])
    if smooth:
        _refine_smooth(tab[_PX], tab[_PY], tab[_PZ], seg, sel, tab[_BEST], tab[_RX], tab[_RY],
                       tab[_RZ], tab[_AX], tab[_AY], tab[_AZ], seg_piece, pieces, seg_phi, n_newton)


@njit(inline="always", **_JIT)
def _add_generalized_force(tab, n1, n2, n3, n4, le, b, force):
    """Q_e += Σ_k S(ξ_k)ᵀ F_k for the element whose coordinates start at force[b] (slope rows
    carry the factor L)."""
    n_k = n1.shape[0]
    fxr = tab[_FX]
    fyr = tab[_FX + 1]
    fzr = tab[_FX + 2]
    for a in range(4):
        na = n1 if a == 0 else (n2 if a == 1 else (n3 if a == 2 else n4))
        scale = le if (a == 1 or a == 3) else 1.0
        sx = 0.0
        sy = 0.0
        sz = 0.0
        for k in range(n_k):
            sx += na[k] * fxr[k]
            sy += na[k] * fyr[k]
            sz += na[k] * fzr[k]
        force[b + 3 * a] += scale * sx
        force[b + 3 * a + 1] += scale * sy
        force[b + 3 * a + 2] += scale * sz


@njit(**_JIT)
def _search_kernel(q, length, n1, n2, n3, n4, seg, off, cand, tab, nearest, open_first, open_last):
    """Contact search only (no force law): nearest segment of every check point, -1 if none."""
    for e in range(length.shape[0]):
        _positions(q, 6 * e, length[e], n1, n2, n3, n4, tab[_PX], tab[_PY], tab[_PZ])
        _nearest_segments(tab[_PX], tab[_PY], tab[_PZ], seg, cand, off[e], off[e + 1],
                          tab[_BEST], nearest[e], tab[_RX], tab[_RY], tab[_RZ], tab[_AX],
                          tab[_AY], tab[_AZ], open_first, open_last, tab[_BEYOND])


@njit(**_JIT)
def _points_kernel(q, qt, length, n1, n2, n3, n4, r1, r2, r3, r4, steady_speed, omega, seg, off,
                   cand, gap, stiffness, damping, exponent, exponent_mode, mu_k, dmu, inv_vs2, eps2,
                   inv_href, tab, sel, open_first, open_last, smooth, seg_piece, pieces, seg_phi,
                   n_newton, inv_onset, out_seg, out_p, out_v, out_res, out_f, out_g, out_hf):
    """Per check point state for post-processing, by the same steps as :func:`_contact_kernel`:
    nearest segment (-1 without candidates), P, v, residual P - Pc (NaN without candidates),
    weighted normal force w f_n, |v_τ|² and μ w f_n/√(|v_τ|² + ε²).

    The velocity is ``_positions(qt)`` with the tables r1..r4: the dynamic kernel's v = S(ξ) q̇
    (Eq. 8) with r = n and ``steady_speed`` 0; steady sliding's v = V ∂r/∂x with r = dN/dξ,
    qt = q and ``steady_speed`` = V [m/s] (as :func:`exucable.contact.steady._steady_kernel`)."""
    n_k = n1.shape[0]
    for e in range(length.shape[0]):
        c0 = off[e]
        c1 = off[e + 1]
        le = length[e]
        b = 6 * e
        r0 = e * n_k
        _positions(q, b, le, n1, n2, n3, n4, tab[_PX], tab[_PY], tab[_PZ])  # Eq. 2
        _positions(qt, b, le, r1, r2, r3, r4, tab[_VX], tab[_VY], tab[_VZ])  # Eq. 8
        if steady_speed != 0.0:
            # r = dN/dξ: _positions gave L ∂r/∂x
            vs = steady_speed / le
            for k in range(n_k):
                tab[_VX, k] *= vs
                tab[_VY, k] *= vs
                tab[_VZ, k] *= vs
        for k in range(n_k):
            out_p[r0 + k, 0] = tab[_PX, k]
            out_p[r0 + k, 1] = tab[_PY, k]
            out_p[r0 + k, 2] = tab[_PZ, k]
            out_v[r0 + k, 0] = tab[_VX, k]
            out_v[r0 + k, 1] = tab[_VY, k]
            out_v[r0 + k, 2] = tab[_VZ, k]
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
        _closest_points(tab, seg, cand, c0, c1, sel, open_first, open_last, smooth, seg_piece, pieces,
                        seg_phi, n_newton)
        _normals(tab, n_k, gap, -1.0)
        _normal_force(tab, omega, n_k, le * inv_href, stiffness, damping, exponent,
                      exponent_mode, inv_onset)
        _friction(tab, n_k, mu_k, dmu, inv_vs2, eps2)
        for k in range(n_k):
            out_seg[r0 + k] = sel[k]
            inside = 0.0 if tab[_BEYOND, k] != 0.0 else 1.0  # beyond an open end: Pc = P, as numpy
            out_res[r0 + k, 0] = inside * tab[_RX, k]
            out_res[r0 + k, 1] = inside * tab[_RY, k]
            out_res[r0 + k, 2] = inside * tab[_RZ, k]
            out_f[r0 + k] = tab[_F, k]
            out_g[r0 + k] = tab[_G, k]
            out_hf[r0 + k] = tab[_HF, k]


@njit(**_JIT)
def _contact_kernel(q, qt, length, n1, n2, n3, n4, pair_t, pair_ab, omega, seg, off, cand,
                    gap, stiffness, damping, exponent, exponent_mode, mu_k, dmu, inv_vs2, eps2,
                    inv_href, jacobian, force, jq, jqt, tab, sel, acc, open_first, open_last,
                    smooth, seg_piece, pieces, seg_phi, n_newton, inv_onset, held_ramp, hold, delta_out):
    """Generalized contact force and its 12×12 Jacobian blocks; returns (n_in_contact, max δ).

    ``delta_out[e, k]`` receives every point's penetration δ [m] (0 out of contact). With ``hold``
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
        _positions(q, b, le, n1, n2, n3, n4, tab[_PX], tab[_PY], tab[_PZ])  # Eq. 2
        _closest_points(tab, seg, cand, c0, c1, sel, open_first, open_last, smooth, seg_piece, pieces,
                        seg_phi, n_newton)
        n_touch, max_d2 = _normals(tab, n_k, gap, max_d2)
        d_out[:] = tab[_DELTA, :n_k]
        if n_touch == 0:
            continue
        n_contact += n_touch
        _positions(qt, b, le, n1, n2, n3, n4, tab[_VX], tab[_VY], tab[_VZ])  # Eq. 8
        if hold:
            _held_ramp(tab, n_k, held_ramp[e])
        else:
            _onset_ramp(tab, n_k, inv_onset)
        _normal_force_with_ramp(tab, omega, n_k, le * inv_href, stiffness, damping, exponent,
                                exponent_mode)
        _friction(tab, n_k, mu_k, dmu, inv_vs2, eps2)
        _add_generalized_force(tab, n1, n2, n3, n4, le, b, force)
        if not jacobian:
            continue
        _point_jacobians(tab, n_k, stiffness, damping)
        _accumulate_blocks(tab, pair_t, pair_ab, le, acc, jq[e], jqt[e])
    max_pen = math.sqrt(max_d2) - gap if max_d2 >= 0.0 else -np.inf
    return n_contact, max_pen


@njit(fastmath=_FASTMATH | {"nnan"}, nogil=True, error_model="numpy")
def _max_finite(x, n):
    """Largest finite entry of x[:n], -1 if none (x >= 0 or inf, never NaN: lets it vectorise)."""
    m = -1.0
    for k in range(n):
        m = max(m, x[k] if x[k] < np.inf else -1.0)
    return m


@njit(inline="always", **_JIT)
def _normals(tab, n_k, gap, max_d2):
    """δ (Eq. 14) and n (Eq. 15) of every point; returns (points with δ > 0, running max d²)."""
    best = tab[_BEST]
    rx = tab[_RX]
    ry = tab[_RY]
    rz = tab[_RZ]
    nx = tab[_NX]
    ny = tab[_NY]
    nz = tab[_NZ]
    invd = tab[_INVD]
    delta = tab[_DELTA]
    touch = tab[_TOUCH]
    gap2 = gap * gap
    for k in range(n_k):
        d2 = best[k]
        hit = d2 > gap2  # δ > 0 without a square root (no candidate segment: d² = inf)
        d = math.sqrt(d2 if hit else gap2)  # out of contact any finite d keeps n finite
        inv_d = 1.0 / d
        nx[k] = rx[k] * inv_d  # outward from the axis
        ny[k] = ry[k] * inv_d
        nz[k] = rz[k] * inv_d
        invd[k] = inv_d
        delta[k] = max(d - gap, 0.0)  # guards the square root against rounding
        touch[k] = 1.0 if hit else 0.0
    n_touch = 0.0
    for k in range(n_k):
        n_touch += touch[k]
    return int(n_touch), max(max_d2, _max_finite(best, n_k))


@njit(inline="always", **_JIT)
def _normal_force(tab, omega, n_k, weight_scale, stiffness, damping, exponent, exponent_mode,
                  inv_onset):
    """v_n, v_τ (Eqs. 16-17) and the weighted normal force w·max(0, K δ^e + C g(δ) δ̇) (Eq. 18)."""
    _onset_ramp(tab, n_k, inv_onset)
    _normal_force_with_ramp(tab, omega, n_k, weight_scale, stiffness, damping, exponent, exponent_mode)


@njit(inline="always", **_JIT)
def _onset_ramp(tab, n_k, inv_onset):
    """Damping onset g(δ) = min(δ/δ_d, 1) and dg/dδ of every point ((1, 0) for δ_d = 0)."""
    delta = tab[_DELTA]
    rr = tab[_RAMP]
    drr = tab[_DRAMP]
    if inv_onset > 0.0:
        for k in range(n_k):
            x = delta[k] * inv_onset
            below = x < 1.0
            rr[k] = x if below else 1.0
            drr[k] = inv_onset if below else 0.0
    else:
        for k in range(n_k):
            rr[k] = 1.0
            drr[k] = 0.0


@njit(inline="always", **_JIT)
def _held_ramp(tab, n_k, ramp):
    """Damping onset held at given values g [-] (the step's start, see ContactCoupling): dg/dδ = 0."""
    rr = tab[_RAMP]
    drr = tab[_DRAMP]
    for k in range(n_k):
        rr[k] = ramp[k]
        drr[k] = 0.0


@njit(inline="always", **_JIT)
def _normal_force_with_ramp(tab, omega, n_k, weight_scale, stiffness, damping, exponent, exponent_mode):
    """:func:`_normal_force` with the onset rows _RAMP, _DRAMP already filled."""
    nx = tab[_NX]
    ny = tab[_NY]
    nz = tab[_NZ]
    vx = tab[_VX]
    vy = tab[_VY]
    vz = tab[_VZ]
    delta = tab[_DELTA]
    touch = tab[_TOUCH]
    vnr = tab[_VN]
    txr = tab[_TX]
    tyr = tab[_TY]
    tzr = tab[_TZ]
    gr = tab[_G]
    fr = tab[_F]
    wr = tab[_WACT]
    ddr = tab[_DDPOW]
    # δ^e into the force row and its derivative, one loop per case (a branch on the exponent
    # inside the loop would stop vectorisation)
    if exponent_mode == 1:  # e = 1.5, the project's value: no pow
        for k in range(n_k):
            sq = math.sqrt(delta[k])
            fr[k] = delta[k] * sq
            ddr[k] = 1.5 * sq
    elif exponent_mode == 2:  # e = 1
        for k in range(n_k):
            fr[k] = delta[k]
            ddr[k] = 1.0
    else:
        for k in range(n_k):
            fr[k] = delta[k] ** exponent
            ddr[k] = exponent * delta[k] ** (exponent - 1.0)
    rr = tab[_RAMP]
    for k in range(n_k):
        vn = nx[k] * vx[k] + ny[k] * vy[k] + nz[k] * vz[k]  # Eq. 16, = δ̇
        raw = stiffness * fr[k] + damping * rr[k] * vn  # Eq. 18 (with the damping onset)
        # weight w = L ω / h_ref; 0 out of contact or where the force would pull
        w_act = weight_scale * omega[k] * touch[k] if raw > 0.0 else 0.0
        tx = vx[k] - vn * nx[k]  # Eq. 17
        ty = vy[k] - vn * ny[k]
        tz = vz[k] - vn * nz[k]
        vnr[k] = vn
        txr[k] = tx
        tyr[k] = ty
        tzr[k] = tz
        gr[k] = tx * tx + ty * ty + tz * tz
        fr[k] = w_act * raw
        wr[k] = w_act


@njit(inline="always", **_JIT)
def _friction(tab, n_k, mu_k, dmu, inv_vs2, eps2):
    """μ(|v_τ|) and the force F = -f n - μ f v_τ/√(|v_τ|² + ε²) (Eqs. 19-23)."""
    gr = tab[_G]
    mur = tab[_MU]
    dmur = tab[_DMU]
    if dmu != 0.0:  # Stribeck: μ = μ_k + (μ_s - μ_k) exp(-|v_τ|²/v_s²)
        for k in range(n_k):
            decay = math.exp(-gr[k] * inv_vs2)
            mur[k] = mu_k + dmu * decay
            dmur[k] = -dmu * inv_vs2 * decay
    else:
        for k in range(n_k):
            mur[k] = mu_k
            dmur[k] = 0.0
    fr = tab[_F]
    nx = tab[_NX]
    ny = tab[_NY]
    nz = tab[_NZ]
    tx = tab[_TX]
    ty = tab[_TY]
    tz = tab[_TZ]
    srr = tab[_SR]
    hfr = tab[_HF]
    fxr = tab[_FX]
    fyr = tab[_FX + 1]
    fzr = tab[_FX + 2]
    for k in range(n_k):
        sr = math.sqrt(gr[k] + eps2)
        hf = mur[k] * fr[k] / sr  # friction force per unit of v_τ
        srr[k] = sr
        hfr[k] = hf
        fxr[k] = -fr[k] * nx[k] - hf * tx[k]
        fyr[k] = -fr[k] * ny[k] - hf * ty[k]
        fzr[k] = -fr[k] * nz[k] - hf * tz[k]


@njit(inline="always", **_JIT)
def _point_jacobians(tab, n_k, stiffness, damping):
    """∂F/∂P and ∂F/∂v of every check point of the element (rows _J0 ... _J0 + 17).

    Every coupling: the normal force through δ and δ̇ = n·v (n depends on P), friction through
    f_n, through v_τ (which depends on n) and through μ(|v_τ|). With M = ∂n/∂P = (Π - n nᵀ)/d
    (Π = I - a aᵀ inside the segment, I at a vertex) and h = μ f/s, s = √(|v_τ|² + ε²):

        ∂F/∂P = -u (k_d n + w C Mv)ᵀ - (f - h v_n) M - c₂ v_τ (M v_τ)ᵀ + h n (Mv)ᵀ
        ∂F/∂v = -w C u nᵀ - g_v v_τ v_τᵀ - h (I - n nᵀ)

    where u = n + (μ/s) v_τ, k_d = w K e δ^(e-1), c₂ = -2 v_n c_g, g_v = 2 c_g and
    c_g = f (μ'/s - μ/(2 s³)) is ∂h/∂|v_τ|² at fixed f. Zero where w = 0.
    """
    ax = tab[_AX]
    ay = tab[_AY]
    az = tab[_AZ]
    nx = tab[_NX]
    ny = tab[_NY]
    nz = tab[_NZ]
    invd = tab[_INVD]
    vx = tab[_VX]
    vy = tab[_VY]
    vz = tab[_VZ]
    tx = tab[_TX]
    ty = tab[_TY]
    tz = tab[_TZ]
    mvx = tab[_MVX]
    mvy = tab[_MVX + 1]
    mvz = tab[_MVX + 2]
    mtx = tab[_MTX]
    mty = tab[_MTX + 1]
    mtz = tab[_MTX + 2]
    for k in range(n_k):  # M v and M v_τ
        a0 = ax[k]
        a1 = ay[k]
        a2 = az[k]
        n0 = nx[k]
        n1_ = ny[k]
        n2_ = nz[k]
        inv_d = invd[k]
        m00 = (1.0 - a0 * a0 - n0 * n0) * inv_d
        m11 = (1.0 - a1 * a1 - n1_ * n1_) * inv_d
        m22 = (1.0 - a2 * a2 - n2_ * n2_) * inv_d
        m01 = (-a0 * a1 - n0 * n1_) * inv_d
        m02 = (-a0 * a2 - n0 * n2_) * inv_d
        m12 = (-a1 * a2 - n1_ * n2_) * inv_d
        mvx[k] = m00 * vx[k] + m01 * vy[k] + m02 * vz[k]
        mvy[k] = m01 * vx[k] + m11 * vy[k] + m12 * vz[k]
        mvz[k] = m02 * vx[k] + m12 * vy[k] + m22 * vz[k]
        mtx[k] = m00 * tx[k] + m01 * ty[k] + m02 * tz[k]
        mty[k] = m01 * tx[k] + m11 * ty[k] + m12 * tz[k]
        mtz[k] = m02 * tx[k] + m12 * ty[k] + m22 * tz[k]
    wr = tab[_WACT]
    ddr = tab[_DDPOW]
    fr = tab[_F]
    mur = tab[_MU]
    dmur = tab[_DMU]
    srr = tab[_SR]
    hfr = tab[_HF]
    vnr = tab[_VN]
    kdr = tab[_KD]
    wcr = tab[_WC]
    fmr = tab[_FM]
    c2r = tab[_C2]
    gvr = tab[_GV]
    musr = tab[_MUS]
    rr = tab[_RAMP]
    drr = tab[_DRAMP]
    for k in range(n_k):  # scalar factors
        sr = srr[k]
        cg = fr[k] * (dmur[k] / sr - 0.5 * mur[k] / (sr * sr * sr))
        kdr[k] = wr[k] * (stiffness * ddr[k] + damping * drr[k] * vnr[k])
        wcr[k] = wr[k] * damping * rr[k]
        fmr[k] = fr[k] - hfr[k] * vnr[k]
        c2r[k] = -2.0 * vnr[k] * cg
        gvr[k] = 2.0 * cg
        musr[k] = mur[k] / sr
    # three calls with literal rows so that each inlined copy has constant row indices
    _jacobian_rows(tab, n_k, 0)
    _jacobian_rows(tab, n_k, 1)
    _jacobian_rows(tab, n_k, 2)


@njit(inline="always", **_JIT)
def _jacobian_rows(tab, n_k, i):
    """Row i of ∂F/∂P and of ∂F/∂v (see :func:`_point_jacobians`)."""
    e0 = 1.0 if i == 0 else 0.0  # row i of the identity
    e1 = 1.0 if i == 1 else 0.0
    e2 = 1.0 if i == 2 else 0.0
    ni = tab[_NX + i]
    ti = tab[_TX + i]
    ai = tab[_AX + i]
    nx = tab[_NX]
    ny = tab[_NY]
    nz = tab[_NZ]
    ax = tab[_AX]
    ay = tab[_AY]
    az = tab[_AZ]
    invd = tab[_INVD]
    mvx = tab[_MVX]
    mvy = tab[_MVX + 1]
    mvz = tab[_MVX + 2]
    mtx = tab[_MTX]
    mty = tab[_MTX + 1]
    mtz = tab[_MTX + 2]
    kdr = tab[_KD]
    wcr = tab[_WC]
    fmr = tab[_FM]
    c2r = tab[_C2]
    musr = tab[_MUS]
    hfr = tab[_HF]
    o0 = tab[_J0 + 3 * i]
    o1 = tab[_J0 + 3 * i + 1]
    o2 = tab[_J0 + 3 * i + 2]
    for k in range(n_k):  # ∂F/∂P, row i
        n_i = ni[k]
        t_i = ti[k]
        u_i = n_i + musr[k] * t_i
        kd = kdr[k]
        wc = wcr[k]
        fmd = fmr[k] * invd[k]
        ct = c2r[k] * t_i
        hn = hfr[k] * n_i
        aa = ai[k]
        o0[k] = (-u_i * (kd * nx[k] + wc * mvx[k]) - fmd * (e0 - aa * ax[k] - n_i * nx[k])
                 - ct * mtx[k] + hn * mvx[k])
        o1[k] = (-u_i * (kd * ny[k] + wc * mvy[k]) - fmd * (e1 - aa * ay[k] - n_i * ny[k])
                 - ct * mty[k] + hn * mvy[k])
        o2[k] = (-u_i * (kd * nz[k] + wc * mvz[k]) - fmd * (e2 - aa * az[k] - n_i * nz[k])
                 - ct * mtz[k] + hn * mvz[k])
    tx = tab[_TX]
    ty = tab[_TY]
    tz = tab[_TZ]
    gvr = tab[_GV]
    p0 = tab[_J0 + 9 + 3 * i]
    p1 = tab[_J0 + 9 + 3 * i + 1]
    p2 = tab[_J0 + 9 + 3 * i + 2]
    for k in range(n_k):  # ∂F/∂v, row i
        n_i = ni[k]
        t_i = ti[k]
        wu = wcr[k] * (n_i + musr[k] * t_i)
        gt = gvr[k] * t_i
        hf = hfr[k]
        p0[k] = -wu * nx[k] - gt * tx[k] - hf * (e0 - n_i * nx[k])
        p1[k] = -wu * ny[k] - gt * ty[k] - hf * (e1 - n_i * ny[k])
        p2[k] = -wu * nz[k] - gt * tz[k] - hf * (e2 - n_i * nz[k])


@njit(inline="always", **_JIT)
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
        jc = tab[_J0 + col]
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


def _exponent_mode(exponent: float) -> int:
    """1 for e = 1.5 (square root instead of pow), 2 for e = 1, 0 otherwise."""
    if exponent == 1.5:
        return 1
    if exponent == 1.0:
        return 2
    return 0


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
        # N_a N_b of a unit-length element, one row per (a, b) of _PAIRS
        self.pair_t = np.ascontiguousarray((self.nh[:, _PAIRS[:, 0]] * self.nh[:, _PAIRS[:, 1]]).T)
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
        self._tab = np.empty((_ROWS, n_k))
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
            q, q_t, self.length, n1, n2, n3, n4, self.pair_t, _PAIRS, self.omega, self.seg, off,
            cand, self.gap, *self._law_arguments(),
            self.inv_href, bool(jacobian), force, jq, jqt, self._tab, self._sel, self._acc,
            self.open_first, self.open_last, self.smooth, self.seg_piece, self.pieces, self.seg_phi,
            NEWTON_ITERATIONS, self._inverse_onset(), onset, hold, penetration)
        if not jacobian:
            jq = jqt = None
        return force, jq, jqt, int(n_contact), float(max_pen), penetration

    def _law_arguments(self):
        """The law's numbers as both kernels take them: K, C, e, e's mode, μ_k, μ_s - μ_k, 1/v_s², ε²."""
        law = self.law
        return (float(law.stiffness), float(law.damping), float(law.exponent), _exponent_mode(law.exponent),
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
        """:meth:`point_state` with the velocity v = ``_positions(rate_source, rate_tables)``,
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
                       NEWTON_ITERATIONS, self._inverse_onset(), segment, p, v, res, f, g, hf)
        acting = f > 0.0
        slip = np.where(acting, np.sqrt(g), 0.0)
        return {"segment": segment, "position_m": p, "velocity_m_per_s": v, "residual_m": res,
                "normal_force_N": np.where(acting, f, 0.0), "sliding_velocity_m_per_s": slip,
                "friction_force_N": np.where(acting, hf * slip, 0.0)}
