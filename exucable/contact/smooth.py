"""The conduit's smooth wall: exact closest points on bends and helices.

The paper models the conduit as straight hollow cylinders (Sect. 2.3). Sliding through a bend
made of chords, every check point crosses a kink at each joint; its normal velocity jumps there
and the contact damping C·δ̇ (Eq. 18), one-sided because f_n ≥ 0, turns those jumps into a drag:
Example 2 at the paper's 100 segments and C = 1 kN s/m pulls 0.7 % too hard (see
``reference/README.md``). With ``surface = "smooth"`` the segments still do the broad phase and
pick the nearest piece of wall, and the closest point is then refined onto the exact centreline
of the bend or helix the segment belongs to, so the wall has no kinks.

Every curved piece is a helix (a bend has zero rise):
C(φ) = c + a (cos φ e1 + sin φ e2) + h φ k, φ ∈ [0, Φ]. The closest point solves
(P − C(φ))·C'(φ) = 0; for a bend in closed form, for a helix by Newton's method from the
segment's estimate. Beyond a piece's ends the wall continues along the end tangent, which is
exact where a bend meets a straight. For the Jacobian the kernel needs
Π = ∂(P − Pc)/∂P = I − T Tᵀ / (1 − r·κ) (T the unit tangent, κ the curvature vector at Pc,
r = P − Pc); it is passed on as the vector √β T with β = 1/(1 − r·κ), so that Π = I − (√β T)(√β T)ᵀ
like a straight segment's I − a aᵀ.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["SmoothWall", "refine_closest_points", "closest_point_angles", "angles_on_pieces", "NEWTON_ITERATIONS"]

# Newton steps for a helix: the chord's estimate is within ~1e-3 rad (the sagitta's angle), and
# the convergence is quadratic: 1e-6 after one step, 1e-12 after two. (Bends need none: closed form.)
NEWTON_ITERATIONS = 2

# piece table columns
_C, _E1, _E2, _K = 0, 3, 6, 9
_A, _H, _PHI, _CURVED = 12, 13, 14, 15
PIECE_COLUMNS = 16


class SmoothWall:
    """Per-segment lookup of the exact curved piece each segment approximates.

    Attributes
    ----------
    seg_piece : ndarray (n_seg,) int
        Piece index of every segment.
    pieces : ndarray (n_piece, 16)
        Centre c, e1, e2, axis k (3 each), coil radius a [m], rise h [m/rad], total angle Φ [rad],
        curved flag.
    seg_phi : ndarray (n_seg, 2)
        Helix angle φ at each segment's start and end [rad] (0 on straights).
    s_piece_start_m, piece_speed_m_per_rad : ndarray (n_piece,)
        Centreline arc length of each piece's start [m] and √(a² + h²) [m/rad].
    """

    def __init__(self, centreline, segments):
        pieces = centreline.pieces
        tab = np.zeros((len(pieces), PIECE_COLUMNS))
        speed = np.ones(len(pieces))
        s0 = np.array([p.s_start_m for p in pieces], dtype=float)
        for i, p in enumerate(pieces):
            if p.is_curved:
                tab[i, _C:_C + 3] = p.centre_m
                tab[i, _E1:_E1 + 3] = p.e1
                tab[i, _E2:_E2 + 3] = p.e2
                tab[i, _K:_K + 3] = p.axis
                tab[i, _A] = p.coil_radius_m
                tab[i, _H] = p.rise_m_per_rad
                tab[i, _PHI] = p.phi_rad
                tab[i, _CURVED] = 1.0
                speed[i] = math.hypot(p.coil_radius_m, p.rise_m_per_rad)
        sv = np.asarray(segments.s_vertex_m, dtype=float)
        mid = 0.5 * (sv[1:] + sv[:-1])
        seg_piece = np.asarray(centreline.piece_index(np.clip(mid, 0.0, centreline.length_m)), dtype=np.int64)
        phi = np.stack([(sv[:-1] - s0[seg_piece]) / speed[seg_piece],
                        (sv[1:] - s0[seg_piece]) / speed[seg_piece]], axis=1)
        phi[tab[seg_piece, _CURVED] == 0.0] = 0.0
        self.seg_piece = np.ascontiguousarray(seg_piece)
        self.pieces = np.ascontiguousarray(tab)
        self.seg_phi = np.ascontiguousarray(phi)
        self.s_piece_start_m = s0
        self.piece_speed_m_per_rad = speed


def _on_curved_pieces(seg, t, seg_length, wall: SmoothWall):
    """The points whose nearest segment (``seg``, -1: none) lies on a curved piece: their mask,
    indices, piece rows and the chord's estimate of their helix angle [rad] (from the clamped
    projection parameter ``t`` [m])."""
    ok = seg >= 0
    piece = np.where(ok, wall.seg_piece[np.maximum(seg, 0)], 0)
    mask = ok & (wall.pieces[piece, _CURVED] == 1.0)
    idx = np.nonzero(mask)[0]
    s = seg[idx]
    frac = t[idx] / seg_length[s]
    estimate = wall.seg_phi[s, 0] + frac * (wall.seg_phi[s, 1] - wall.seg_phi[s, 0])
    return mask, idx, wall.pieces[piece[idx]], estimate


def refine_closest_points(p, seg, t, seg_length, wall: SmoothWall):
    """Exact closest points on the curved pieces (numpy reference; see the module docstring).

    Parameters
    ----------
    p : ndarray (m, 3)
        Check point positions [m].
    seg : ndarray (m,) int
        Nearest segment of each point (points on straights or with ``seg < 0`` are not touched).
    t : ndarray (m,)
        Clamped projection parameter on that segment [m].
    seg_length : ndarray (n_seg,)
        Segment lengths [m].

    Returns
    -------
    mask : ndarray (m,) bool
        Points refined (on curved pieces).
    residual : ndarray (m, 3)
        P − Pc on the smooth wall [m] (rows outside ``mask`` undefined).
    axis_vec : ndarray (m, 3)
        √β T, so that ∂(P − Pc)/∂P = I − axis_vec axis_vecᵀ.
    phi : ndarray (m,)
        Helix angle of Pc [rad] (clamped to the piece).
    """
    m = p.shape[0]
    residual = np.zeros((m, 3))
    axis_vec = np.zeros((m, 3))
    phi_out = np.zeros(m)
    mask, idx, pc, phi = _on_curved_pieces(seg, t, seg_length, wall)
    if not idx.size:
        return mask, residual, axis_vec, phi_out
    c, e1, e2, k = pc[:, _C:_C + 3], pc[:, _E1:_E1 + 3], pc[:, _E2:_E2 + 3], pc[:, _K:_K + 3]
    a, h, Phi = pc[:, _A], pc[:, _H], pc[:, _PHI]
    x = p[idx] - c
    x1 = np.sum(x * e1, axis=1)
    x2 = np.sum(x * e2, axis=1)
    xk = np.sum(x * k, axis=1)
    for _ in range(NEWTON_ITERATIONS):
        cs, sn = np.cos(phi), np.sin(phi)
        # g = -(P - C)·C' and its derivative, in the (e1, e2, k) frame
        g = -(a * (-sn * x1 + cs * x2) + h * (xk - h * phi))
        dg = a * (cs * x1 + sn * x2) + h * h
        phi = phi - g / dg
    inside = (phi >= 0.0) & (phi <= Phi)
    phic = np.clip(phi, 0.0, Phi)
    cs, sn = np.cos(phic), np.sin(phic)
    w = np.hypot(a, h)
    C = c + a[:, None] * (cs[:, None] * e1 + sn[:, None] * e2) + (h * phic)[:, None] * k
    T = (a[:, None] * (-sn[:, None] * e1 + cs[:, None] * e2) + h[:, None] * k) / w[:, None]
    r = p[idx] - C
    # beyond the piece's ends: continue along the end tangent (Pc on the tangent line, Π = I - T Tᵀ)
    along = np.sum(r * T, axis=1)
    r = np.where(inside[:, None], r, r - along[:, None] * T)
    kappa = -(a / w**2)[:, None] * (cs[:, None] * e1 + sn[:, None] * e2)
    beta = np.where(inside, 1.0 / (1.0 - np.sum(r * kappa, axis=1)), 1.0)
    residual[idx] = r
    axis_vec[idx] = np.sqrt(beta)[:, None] * T
    phi_out[idx] = phic
    return mask, residual, axis_vec, phi_out


def closest_point_angles(p, residual, seg, t, seg_length, wall: SmoothWall):
    """Helix angle φ of each point's closest point Pc = P − (P − Pc) on its curved piece, from
    the residual a kernel already found (the profiles' arc length; no Newton iteration).

    Pc lies on the helix C(φ) = c + a (cos φ e1 + sin φ e2) + h φ k, so its angle is the polar
    angle of (Pc − c) in the (e1, e2) plane, unwrapped next to the chord's estimate (a helix may
    coil more than one turn) and clamped to the piece, [0, Φ]: beyond an end Pc is on the end
    tangent, whose polar angle runs past the end. The same φ as :func:`refine_closest_points`
    (there by Newton's method, to ~1e-12 rad), at a fraction of the cost.

    ``p``, ``seg``, ``t``, ``seg_length`` as for :func:`refine_closest_points`; ``residual``
    (m, 3) is P − Pc on the smooth wall [m]. Returns ``mask`` (points on curved pieces) and
    ``phi`` [rad] (0 outside ``mask``).
    """
    phi_out = np.zeros(p.shape[0])
    mask, idx, pc, estimate = _on_curved_pieces(seg, t, seg_length, wall)
    if not idx.size:
        return mask, phi_out
    # the piece's axes as contiguous (m, 3) arrays, the layout the compiled profiles pass
    # (exucable.contact.profiles): both take the same einsum path, so give the same bits
    phi_out[idx] = angles_on_pieces(p[idx] - residual[idx] - pc[:, _C:_C + 3], estimate,
                                    np.ascontiguousarray(pc[:, _E1:_E1 + 3]),
                                    np.ascontiguousarray(pc[:, _E2:_E2 + 3]), pc[:, _PHI])
    return mask, phi_out


def angles_on_pieces(relative_m, estimate_rad, e1, e2, phi_max_rad):
    """Helix angle φ [rad] of closest points Pc given relative to their pieces' centres,
    ``relative_m`` = Pc − c (m, 3) [m], next to the chord's estimates ``estimate_rad`` (m,):
    the polar angle in the plane of the pieces' axes ``e1``, ``e2`` (m, 3), unwrapped next to the
    estimate (a helix may coil more than one turn) and clamped to [0, ``phi_max_rad``] (m,) (see
    :func:`closest_point_angles`). NaN stays NaN."""
    polar = np.arctan2(np.einsum("ij,ij->i", relative_m, e2), np.einsum("ij,ij->i", relative_m, e1))
    phi = estimate_rad + ((polar - estimate_rad + np.pi) % (2.0 * np.pi) - np.pi)
    return np.clip(phi, 0.0, phi_max_rad)
