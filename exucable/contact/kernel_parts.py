"""The parts both compiled contact kernels are made of: the dynamic kernel (:mod:`.fast`) and the
steady-sliding kernel (:mod:`.steady`) run the same steps on one work table per element.

Same equations as the numpy reference in :mod:`exucable.contact.numpy_kernel` (paper Eqs. 2-8, 14-23):

- :func:`positions`: P = S(ξ) q_e (Eq. 2) and, with other tables, the velocity (Eq. 8);
- :func:`nearest_segments`, :func:`refine_smooth`, :func:`closest_points`: the narrow phase, onto the
  segments and then onto the exact bends and helices (:func:`segment_sectors` tabulates their sectors);
- :func:`normals`: δ and n (Eqs. 14-15), δ blended over the onset layer s (:func:`~exucable.contact.law.onset_blend`); :func:`normal_force`, :func:`onset_ramp`, :func:`held_onset_ramp`,
  :func:`normal_force_with_ramp`: v_n, v_τ and the Hertz force with damping (Eqs. 16-18);
- :func:`friction`: μ(|v_τ|) and the force on the cable (Eqs. 19-23);
- :func:`add_generalized_force`: Q_e = Σ_k S_kᵀ F_k; :func:`point_jacobians`: ∂F/∂P and ∂F/∂v;
- the work table's rows (:data:`PX` ... :data:`ROWS`), the node-block pairs :data:`PAIRS`, the
  numba options :data:`JIT_OPTIONS` and :func:`exponent_mode_of`.

All compiled parts are inlined into the kernel that calls them (``inline="always"``), so a kernel's
machine code depends on this file too: :func:`exucable.contact.jitcache.forget_stale_machine_code`
compiles the kernels again when it changes.
"""

from __future__ import annotations

import math

import numpy as np

from .jitcache import njit

__all__ = ["FASTMATH", "JIT_OPTIONS", "PAIRS", "positions", "nearest_segments", "segment_sectors",
           "refine_smooth", "closest_points", "add_generalized_force", "normals", "normal_force",
           "onset_ramp", "held_onset_ramp", "normal_force_with_ramp", "friction", "point_jacobians",
           "exponent_mode_of", "PX", "PY", "PZ", "BEST", "RX", "RY", "RZ", "AX", "AY", "AZ", "NX",
           "NY", "NZ", "INVD", "DELTA", "TOUCH", "VX", "VY", "VZ", "VN", "G", "F", "WACT", "DDPOW",
           "TX", "TY", "TZ", "MU", "DMU", "SR", "HF", "FX", "MVX", "MTX", "KD", "WC", "FM", "C2", "GV",
           "MUS", "J0", "BEYOND", "RAMP", "DRAMP", "DPHI", "ROWS"]

# Reassociation lets LLVM vectorise the sums over check points; no-NaN/no-inf assumptions are left
# out on purpose (a point without candidate segments carries an infinite distance).
FASTMATH = {"nsz", "arcp", "contract", "reassoc"}

# (a, b) node-block pairs with a <= b, in the order of the columns of the pair table
PAIRS = np.array([(a, b) for a in range(4) for b in range(a, 4)], dtype=np.int64)


# cached on disk where numba can write (.jitcache adds cache=...: where, and what happens when it cannot)
JIT_OPTIONS = dict(fastmath=FASTMATH, nogil=True, error_model="numpy")

# Rows of the per-element work table, one column per check point. Each loop below reads and
# writes contiguous rows; LLVM vectorises a loop only while the number of runtime alias checks
# between its arrays stays small (measured: about s(s-1)/2 + s·l <= 128 for s written and l read
# rows), hence several short loops rather than one long one.
PX, PY, PZ, BEST = 0, 1, 2, 3  # position P, squared distance to the nearest segment
RX, RY, RZ = 4, 5, 6  # residual P - Pc
AX, AY, AZ = 7, 8, 9  # segment axis where the projection is inside the segment, else 0
NX, NY, NZ = 10, 11, 12  # contact normal n
INVD, DELTA, TOUCH = 13, 14, 15  # 1/d, penetration δ, 1 where δ > 0 else 0
VX, VY, VZ = 16, 17, 18  # velocity v
VN, G, F, WACT, DDPOW = 19, 20, 21, 22, 23  # v_n, |v_τ|², w f_n, w (0 if no force), dδ^e/dδ
TX, TY, TZ = 24, 25, 26  # sliding velocity v_τ
MU, DMU, SR, HF = 27, 28, 29, 30  # μ, dμ/d|v_τ|², √(|v_τ|² + ε²), μ w f_n / √(...)
FX = 31  # rows 31..33: force F on the cable [N]
MVX, MTX = 34, 37  # rows 34..36: M v, rows 37..39: M v_τ (M = ∂n/∂P)
KD, WC, FM, C2, GV, MUS = 40, 41, 42, 43, 44, 45  # scalar factors of the Jacobian
J0 = 46  # rows 46..63: ∂F/∂P (9, row-major) then ∂F/∂v (9)
BEYOND = 64  # 1 where the nearest segment is an open end's and the point lies past it
RAMP, DRAMP = 65, 66  # damping onset g(δ) and dg/dδ
DPHI = 67  # dφ_s/dδ of the blended penetration φ_s(δ) in row DELTA (1 without an onset layer)
ROWS = 68


@njit(inline="always", **JIT_OPTIONS)
def positions(q, b, le, n1, n2, n3, n4, px, py, pz):
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


@njit(inline="always", **JIT_OPTIONS)
def nearest_segments(px, py, pz, seg, cand, c0, c1, best, sel, rx, ry, rz, ax_in, ay_in,
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


@njit(inline="always", **JIT_OPTIONS)
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


@njit(inline="always", **JIT_OPTIONS)
def refine_smooth(px, py, pz, seg, sel, best, rx, ry, rz, ax_in, ay_in, az_in, seg_piece, pieces,
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


@njit(inline="always", **JIT_OPTIONS)
def closest_points(tab, seg, cand, c0, c1, sel, open_first, open_last, smooth, seg_piece, pieces,
                    seg_phi, n_newton):
    """Closest point Pc of every check point of the element: nearest candidate segment, then on
    the smooth wall refined onto the exact bend or helix (rows BEST, RX..., AX..., BEYOND)."""
    nearest_segments(tab[PX], tab[PY], tab[PZ], seg, cand, c0, c1, tab[BEST], sel,
                      tab[RX], tab[RY], tab[RZ], tab[AX], tab[AY], tab[AZ],
                      open_first, open_last, tab[BEYOND])
    if smooth:
        refine_smooth(tab[PX], tab[PY], tab[PZ], seg, sel, tab[BEST], tab[RX], tab[RY],
                       tab[RZ], tab[AX], tab[AY], tab[AZ], seg_piece, pieces, seg_phi, n_newton)


@njit(inline="always", **JIT_OPTIONS)
def add_generalized_force(tab, n1, n2, n3, n4, le, b, force):
    """Q_e += Σ_k S(ξ_k)ᵀ F_k for the element whose coordinates start at force[b] (slope rows
    carry the factor L)."""
    n_k = n1.shape[0]
    fxr = tab[FX]
    fyr = tab[FX + 1]
    fzr = tab[FX + 2]
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

@njit(fastmath=FASTMATH | {"nnan"}, nogil=True, error_model="numpy")
def _max_finite(x, n):
    """Largest finite entry of x[:n], -1 if none (x >= 0 or inf, never NaN: lets it vectorise)."""
    m = -1.0
    for k in range(n):
        m = max(m, x[k] if x[k] < np.inf else -1.0)
    return m


@njit(inline="always", **JIT_OPTIONS)
def normals(tab, n_k, gap, max_d2, layer):
    """δ (Eq. 14) and n (Eq. 15) of every point; returns (points with δ > -s, running max d²).

    Row DELTA holds the penetration the law acts on: max(δ, 0) for an onset layer s = 0, else the
    blend φ_s(δ) of :func:`exucable.contact.law.onset_blend` (0 where the point does not touch),
    row DPHI its derivative dφ_s/dδ. The layer needs s < gap."""
    best = tab[BEST]
    rx = tab[RX]
    ry = tab[RY]
    rz = tab[RZ]
    nx = tab[NX]
    ny = tab[NY]
    nz = tab[NZ]
    invd = tab[INVD]
    delta = tab[DELTA]
    touch = tab[TOUCH]
    gap2 = gap * gap
    dphi = tab[DPHI]
    if layer > 0.0:
        lo = gap - layer
        lo2 = lo * lo
        quarter = 0.25 / layer
        for k in range(n_k):
            d2 = best[k]
            hit = d2 > lo2  # δ > -s without a square root
            d = math.sqrt(d2 if hit else gap2)  # out of contact any finite d keeps n finite
            inv_d = 1.0 / d
            nx[k] = rx[k] * inv_d
            ny[k] = ry[k] * inv_d
            nz[k] = rz[k] * inv_d
            invd[k] = inv_d
            x = d - gap
            y = min(max(x + layer, 0.0), 2.0 * layer)
            blend = x < layer
            on = 1.0 if hit else 0.0
            delta[k] = on * (y * y * quarter if blend else x)
            dphi[k] = on * (2.0 * y * quarter if blend else 1.0)
            touch[k] = on
    else:
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
            dphi[k] = 1.0
            touch[k] = 1.0 if hit else 0.0
    n_touch = 0.0
    for k in range(n_k):
        n_touch += touch[k]
    return int(n_touch), max(max_d2, _max_finite(best, n_k))


@njit(inline="always", **JIT_OPTIONS)
def normal_force(tab, omega, n_k, weight_scale, stiffness, damping, exponent, exponent_mode,
                  inv_onset):
    """v_n, v_τ (Eqs. 16-17) and the weighted normal force w·max(0, K δ^e + C g(δ) δ̇) (Eq. 18)."""
    onset_ramp(tab, n_k, inv_onset)
    normal_force_with_ramp(tab, omega, n_k, weight_scale, stiffness, damping, exponent, exponent_mode)


@njit(inline="always", **JIT_OPTIONS)
def onset_ramp(tab, n_k, inv_onset):
    """Damping onset g(φ) = min(φ/δ_d, 1) and dg/dδ of every point ((1, 0) for δ_d = 0); φ is row
    DELTA, the blended penetration (δ without an onset layer), dφ/dδ row DPHI."""
    delta = tab[DELTA]
    dphi = tab[DPHI]
    rr = tab[RAMP]
    drr = tab[DRAMP]
    if inv_onset > 0.0:
        for k in range(n_k):
            x = delta[k] * inv_onset
            below = x < 1.0
            rr[k] = x if below else 1.0
            drr[k] = inv_onset * dphi[k] if below else 0.0
    else:
        for k in range(n_k):
            rr[k] = 1.0
            drr[k] = 0.0


@njit(inline="always", **JIT_OPTIONS)
def held_onset_ramp(tab, n_k, ramp):
    """Damping onset held at given values g [-] (the step's start, see ContactCoupling): dg/dδ = 0."""
    rr = tab[RAMP]
    drr = tab[DRAMP]
    for k in range(n_k):
        rr[k] = ramp[k]
        drr[k] = 0.0


@njit(inline="always", **JIT_OPTIONS)
def normal_force_with_ramp(tab, omega, n_k, weight_scale, stiffness, damping, exponent, exponent_mode):
    """:func:`normal_force` with the onset rows RAMP, DRAMP already filled."""
    nx = tab[NX]
    ny = tab[NY]
    nz = tab[NZ]
    vx = tab[VX]
    vy = tab[VY]
    vz = tab[VZ]
    delta = tab[DELTA]
    touch = tab[TOUCH]
    vnr = tab[VN]
    txr = tab[TX]
    tyr = tab[TY]
    tzr = tab[TZ]
    gr = tab[G]
    fr = tab[F]
    wr = tab[WACT]
    ddr = tab[DDPOW]
    dphi = tab[DPHI]
    # φ^e into the force row and its derivative dφ^e/dδ = e φ^(e-1) dφ/dδ, one loop per case (a
    # branch on the exponent inside the loop would stop vectorisation); φ = δ without an onset layer
    if exponent_mode == 1:  # e = 1.5, the project's value: no pow
        for k in range(n_k):
            sq = math.sqrt(delta[k])
            fr[k] = delta[k] * sq
            ddr[k] = 1.5 * sq * dphi[k]
    elif exponent_mode == 2:  # e = 1
        for k in range(n_k):
            fr[k] = delta[k]
            ddr[k] = dphi[k]
    else:
        for k in range(n_k):
            fr[k] = delta[k] ** exponent
            ddr[k] = exponent * delta[k] ** (exponent - 1.0) * dphi[k]
    rr = tab[RAMP]
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


@njit(inline="always", **JIT_OPTIONS)
def friction(tab, n_k, mu_k, dmu, inv_vs2, eps2):
    """μ(|v_τ|) and the force F = -f n - μ f v_τ/√(|v_τ|² + ε²) (Eqs. 19-23)."""
    gr = tab[G]
    mur = tab[MU]
    dmur = tab[DMU]
    if dmu != 0.0:  # Stribeck: μ = μ_k + (μ_s - μ_k) exp(-|v_τ|²/v_s²)
        for k in range(n_k):
            decay = math.exp(-gr[k] * inv_vs2)
            mur[k] = mu_k + dmu * decay
            dmur[k] = -dmu * inv_vs2 * decay
    else:
        for k in range(n_k):
            mur[k] = mu_k
            dmur[k] = 0.0
    fr = tab[F]
    nx = tab[NX]
    ny = tab[NY]
    nz = tab[NZ]
    tx = tab[TX]
    ty = tab[TY]
    tz = tab[TZ]
    srr = tab[SR]
    hfr = tab[HF]
    fxr = tab[FX]
    fyr = tab[FX + 1]
    fzr = tab[FX + 2]
    for k in range(n_k):
        sr = math.sqrt(gr[k] + eps2)
        hf = mur[k] * fr[k] / sr  # friction force per unit of v_τ
        srr[k] = sr
        hfr[k] = hf
        fxr[k] = -fr[k] * nx[k] - hf * tx[k]
        fyr[k] = -fr[k] * ny[k] - hf * ty[k]
        fzr[k] = -fr[k] * nz[k] - hf * tz[k]


@njit(inline="always", **JIT_OPTIONS)
def point_jacobians(tab, n_k, stiffness, damping):
    """∂F/∂P and ∂F/∂v of every check point of the element (rows J0 ... J0 + 17).

    Every coupling: the normal force through δ and δ̇ = n·v (n depends on P), friction through
    f_n, through v_τ (which depends on n) and through μ(|v_τ|). With M = ∂n/∂P = (Π - n nᵀ)/d
    (Π = I - a aᵀ inside the segment, I at a vertex) and h = μ f/s, s = √(|v_τ|² + ε²):

        ∂F/∂P = -u (k_d n + w C Mv)ᵀ - (f - h v_n) M - c₂ v_τ (M v_τ)ᵀ + h n (Mv)ᵀ
        ∂F/∂v = -w C u nᵀ - g_v v_τ v_τᵀ - h (I - n nᵀ)

    where u = n + (μ/s) v_τ, k_d = w K e δ^(e-1), c₂ = -2 v_n c_g, g_v = 2 c_g and
    c_g = f (μ'/s - μ/(2 s³)) is ∂h/∂|v_τ|² at fixed f. Zero where w = 0.
    """
    ax = tab[AX]
    ay = tab[AY]
    az = tab[AZ]
    nx = tab[NX]
    ny = tab[NY]
    nz = tab[NZ]
    invd = tab[INVD]
    vx = tab[VX]
    vy = tab[VY]
    vz = tab[VZ]
    tx = tab[TX]
    ty = tab[TY]
    tz = tab[TZ]
    mvx = tab[MVX]
    mvy = tab[MVX + 1]
    mvz = tab[MVX + 2]
    mtx = tab[MTX]
    mty = tab[MTX + 1]
    mtz = tab[MTX + 2]
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
    wr = tab[WACT]
    ddr = tab[DDPOW]
    fr = tab[F]
    mur = tab[MU]
    dmur = tab[DMU]
    srr = tab[SR]
    hfr = tab[HF]
    vnr = tab[VN]
    kdr = tab[KD]
    wcr = tab[WC]
    fmr = tab[FM]
    c2r = tab[C2]
    gvr = tab[GV]
    musr = tab[MUS]
    rr = tab[RAMP]
    drr = tab[DRAMP]
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


@njit(inline="always", **JIT_OPTIONS)
def _jacobian_rows(tab, n_k, i):
    """Row i of ∂F/∂P and of ∂F/∂v (see :func:`point_jacobians`)."""
    e0 = 1.0 if i == 0 else 0.0  # row i of the identity
    e1 = 1.0 if i == 1 else 0.0
    e2 = 1.0 if i == 2 else 0.0
    ni = tab[NX + i]
    ti = tab[TX + i]
    ai = tab[AX + i]
    nx = tab[NX]
    ny = tab[NY]
    nz = tab[NZ]
    ax = tab[AX]
    ay = tab[AY]
    az = tab[AZ]
    invd = tab[INVD]
    mvx = tab[MVX]
    mvy = tab[MVX + 1]
    mvz = tab[MVX + 2]
    mtx = tab[MTX]
    mty = tab[MTX + 1]
    mtz = tab[MTX + 2]
    kdr = tab[KD]
    wcr = tab[WC]
    fmr = tab[FM]
    c2r = tab[C2]
    musr = tab[MUS]
    hfr = tab[HF]
    o0 = tab[J0 + 3 * i]
    o1 = tab[J0 + 3 * i + 1]
    o2 = tab[J0 + 3 * i + 2]
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
    tx = tab[TX]
    ty = tab[TY]
    tz = tab[TZ]
    gvr = tab[GV]
    p0 = tab[J0 + 9 + 3 * i]
    p1 = tab[J0 + 9 + 3 * i + 1]
    p2 = tab[J0 + 9 + 3 * i + 2]
    for k in range(n_k):  # ∂F/∂v, row i
        n_i = ni[k]
        t_i = ti[k]
        wu = wcr[k] * (n_i + musr[k] * t_i)
        gt = gvr[k] * t_i
        hf = hfr[k]
        p0[k] = -wu * nx[k] - gt * tx[k] - hf * (e0 - n_i * nx[k])
        p1[k] = -wu * ny[k] - gt * ty[k] - hf * (e1 - n_i * ny[k])
        p2[k] = -wu * nz[k] - gt * tz[k] - hf * (e2 - n_i * nz[k])


def exponent_mode_of(exponent: float) -> int:
    """1 for e = 1.5 (square root instead of pow), 2 for e = 1, 0 otherwise."""
    if exponent == 1.5:
        return 1
    if exponent == 1.0:
        return 2
    return 0
