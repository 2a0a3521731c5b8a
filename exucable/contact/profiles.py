"""Per-check-point profiles for the compiled backend: penetration, normal, conduit arc length.

:meth:`exucable.contact.ContactKernel.points` derives, from each check point's position P, its
nearest segment and residual P − Pc (the backend's point state), the penetration
δ = |P − Pc| − (R − r) (paper Eq. 14), the normal n = (P − Pc)/|P − Pc| (Eq. 15) and the
centreline arc length of Pc. The numpy form (``ContactKernel._profiles_numpy`` with
:func:`exucable.contact.smooth.closest_point_angles`) is the definition. Here the same arithmetic
runs as one compiled loop over the points, except the polar angle of Pc on a bend or helix, which
goes through the numpy form's own :func:`~exucable.contact.smooth.angles_on_pieces` (its
``arctan2`` and ``einsum`` may round differently from a compiled ``atan2`` and dot product, by an
ulp). Everything else is elementwise arithmetic in the numpy form's order, without fast-math, so
both give the same bits (``tests/test_contact_smooth.py``). On Example 4's 80 000 check points
the numpy form spends ~15 ms gathering segment and piece rows for every point; this, 2-3 ms.
"""

from __future__ import annotations

import math

import numpy as np
from .jitcache import njit
from .smooth import angles_on_pieces

__all__ = ["point_profiles"]


# no fast-math: the numpy form's bits (the deferred njit caches on disk where it can)
_JIT = dict(nogil=True, error_model="numpy")

# piece table columns (exucable.contact.smooth)
_C, _E1, _E2, _PHI, _CURVED = 0, 3, 6, 14, 15


@njit(**_JIT)
def _profiles(p, seg, residual, gap, seg_start, seg_axis, seg_length, s_vertex, smooth, seg_piece,
              pieces, seg_phi, penetration, normal, s_conduit, curved, piece, estimate, relative, e1, e2,
              phi_max):
    """Fill δ, n and the segments' arc length of every point; list the points on curved pieces
    (``curved``, their ``piece``, the chord's ``estimate`` of φ, Pc − c in ``relative``, the
    piece's axes ``e1``, ``e2`` and angle ``phi_max``) for the angles. Returns how many."""
    n_curved = 0
    for i in range(seg.shape[0]):
        r0, r1, r2 = residual[i, 0], residual[i, 1], residual[i, 2]
        d = math.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
        penetration[i] = d - gap                                   # Eq. 14 (NaN without a segment)
        if d > 0.0:                                                # Eq. 15
            normal[i, 0] = r0 / d
            normal[i, 1] = r1 / d
            normal[i, 2] = r2 / d
        else:
            normal[i, 0] = np.nan
            normal[i, 1] = np.nan
            normal[i, 2] = np.nan
        s = seg[i]
        if s < 0:
            s_conduit[i] = np.nan
            continue
        # the clamped projection on the segment, then linear between its vertices' arc lengths
        length = seg_length[s]
        t = ((p[i, 0] - seg_start[s, 0]) * seg_axis[s, 0] + (p[i, 1] - seg_start[s, 1]) * seg_axis[s, 1]
             + (p[i, 2] - seg_start[s, 2]) * seg_axis[s, 2])
        t = min(max(t, 0.0), length)
        frac = t / length
        s_conduit[i] = s_vertex[s] + frac * (s_vertex[s + 1] - s_vertex[s])
        # on the smooth wall a point on a bend or helix takes the exact arc length of Pc; beyond
        # an open end the residual is zero and the segment's value stays
        if not smooth or (r0 == 0.0 and r1 == 0.0 and r2 == 0.0):
            continue
        k = seg_piece[s]
        if pieces[k, _CURVED] != 1.0:
            continue
        curved[n_curved] = i
        piece[n_curved] = k
        estimate[n_curved] = seg_phi[s, 0] + frac * (seg_phi[s, 1] - seg_phi[s, 0])
        relative[n_curved, 0] = p[i, 0] - r0 - pieces[k, _C]
        relative[n_curved, 1] = p[i, 1] - r1 - pieces[k, _C + 1]
        relative[n_curved, 2] = p[i, 2] - r2 - pieces[k, _C + 2]
        for j in range(3):
            e1[n_curved, j] = pieces[k, _E1 + j]
            e2[n_curved, j] = pieces[k, _E2 + j]
        phi_max[n_curved] = pieces[k, _PHI]
        n_curved += 1
    return n_curved


def point_profiles(p, seg, residual, gap_m: float, segments, wall=None):
    """Penetration δ [m], normal n [-] and conduit arc length of Pc [m] of every check point.

    Parameters
    ----------
    p : ndarray (m, 3)
        Check point positions P [m].
    seg : ndarray (m,) int
        Nearest segment (-1: none).
    residual : ndarray (m, 3)
        P − Pc [m] (NaN without a segment; zero beyond an open end).
    gap_m : float
        R − r [m].
    segments : Segments
        The conduit polyline (start, unit axis, length, vertex arc lengths).
    wall : SmoothWall, optional
        The smooth wall: points on its bends and helices take the exact arc length of Pc.

    Returns
    -------
    penetration_m, normal, s_conduit_m : ndarray (m,), (m, 3), (m,)
        As :class:`exucable.contact.CheckPointState` (NaN where undefined).
    """
    m = seg.shape[0]
    penetration, normal, s_conduit = np.empty(m), np.empty((m, 3)), np.empty(m)
    smooth = wall is not None
    n_list = m if smooth else 0
    curved, piece = np.empty(n_list, dtype=np.int64), np.empty(n_list, dtype=np.int64)
    estimate, relative = np.empty(n_list), np.empty((n_list, 3))
    e1, e2, phi_max = np.empty((n_list, 3)), np.empty((n_list, 3)), np.empty(n_list)
    tables = ((wall.seg_piece, wall.pieces, wall.seg_phi) if smooth
              else (np.zeros(1, dtype=np.int64), np.zeros((1, 16)), np.zeros((1, 2))))
    n_curved = _profiles(np.ascontiguousarray(p, dtype=float), np.ascontiguousarray(seg, dtype=np.int64),
                         np.ascontiguousarray(residual, dtype=float), float(gap_m),
                         np.ascontiguousarray(segments.start_m, dtype=float),
                         np.ascontiguousarray(segments.axis, dtype=float),
                         np.ascontiguousarray(segments.length_m, dtype=float),
                         np.ascontiguousarray(segments.s_vertex_m, dtype=float), smooth, *tables,
                         penetration, normal, s_conduit, curved, piece, estimate, relative, e1, e2, phi_max)
    if n_curved:
        k = piece[:n_curved]
        phi = angles_on_pieces(relative[:n_curved], estimate[:n_curved], e1[:n_curved], e2[:n_curved],
                               phi_max[:n_curved])
        ok = np.isfinite(phi)
        s_conduit[curved[:n_curved][ok]] = wall.s_piece_start_m[k[ok]] + phi[ok] * wall.piece_speed_m_per_rad[k[ok]]
    return penetration, normal, s_conduit
