"""Broad phase of the contact search (paper Sect. 2.5): which segments can a cable element touch?

Each cable element is boxed by the axis-aligned bounding box (AABB) of its four Bézier control
points r_i, r_i + L r'_i/3, r_j - L r'_j/3, r_j (a cubic Hermite curve lies in their convex hull),
inflated by the cable radius r. Each conduit segment is boxed by ``Segments.aabb_min_m/max_m``
(inflated by the inner radius R). The candidate segments of an element are those whose box
overlaps its box (closed intervals on all three axes, the paper's three projection tests).

Why the result equals brute force: a check point P is inside its element's box. If P lies within
R of segment s, it is inside the box of s inflated by R, so the two boxes overlap and s is a
candidate. Hence, when every check point is within R of the polyline, its nearest segment (and
every segment tied with it) is a candidate and the narrow phase picks the same segment as a
search over all segments. A point farther than R from every segment has its cable centreline
outside the conduit wall: the cable has left the conduit, which is not modelled; such a point may
find no candidate and then feels no force.

Two ways to find overlapping pairs: :func:`candidates_all_pairs` (every element box against every
segment box, vectorised numpy, the reference) and :func:`candidates_sweep` (sort-and-sweep along
the axis of largest extent, then the other two axes tested per pair; O((n_el + n_seg) log + pairs)).
Both return the candidate lists in CSR form with each element's segments in increasing index
order, so that the narrow phase breaks distance ties towards the lower segment index either way.
"""

from __future__ import annotations

import numpy as np

from .jitcache import njit

__all__ = [
    "element_aabbs",
    "sweep_axis",
    "candidates_all_pairs",
    "candidates_sweep",
    "candidates_all_segments",
]

def _jit(func):
    """Compiled by numba (see .jitcache); runs as Python when numba is missing,
    so that the numpy reference never needs it."""
    return njit(nogil=True)(func)


def element_aabbs(q: np.ndarray, element_length_m: np.ndarray, cable_radius_m: float):
    """AABBs of the cable elements, inflated by the cable radius.

    Parameters
    ----------
    q : ndarray, shape (6 (n_el + 1),)
        Cable coordinates [x, y, z, x', y', z'] per node [m, -].
    element_length_m : ndarray, shape (n_el,)
        Reference length L_e of each element [m].
    cable_radius_m : float
        Cable radius r [m].

    Returns
    -------
    lo, hi : ndarray, shape (n_el, 3)
        Lower and upper box corners [m].
    """
    nodes = np.asarray(q, dtype=float).reshape(-1, 6)
    third = (np.asarray(element_length_m, dtype=float) / 3.0)[:, None]
    ri, si = nodes[:-1, :3], nodes[:-1, 3:]
    rj, sj = nodes[1:, :3], nodes[1:, 3:]
    control = np.stack([ri, ri + third * si, rj - third * sj, rj])  # Bézier control points
    return control.min(axis=0) - cable_radius_m, control.max(axis=0) + cable_radius_m


def sweep_axis(lo: np.ndarray, hi: np.ndarray) -> int:
    """Index of the axis along which the union of boxes ``lo``/``hi`` is longest (0, 1 or 2)."""
    extent = np.max(hi, axis=0) - np.min(lo, axis=0)
    return int(np.argmax(extent))


def _csr_from_mask(mask: np.ndarray):
    counts = mask.sum(axis=1)
    offsets = np.zeros(mask.shape[0] + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    # np.nonzero walks row-major: per element, segment indices come out increasing
    indices = np.nonzero(mask)[1].astype(np.int64)
    return offsets, indices


def candidates_all_pairs(elo, ehi, slo, shi):
    """Candidate segments of every element by testing every pair of boxes (reference).

    Parameters
    ----------
    elo, ehi : ndarray, shape (n_el, 3)
        Element boxes [m].
    slo, shi : ndarray, shape (n_seg, 3)
        Segment boxes [m].

    Returns
    -------
    offsets : ndarray of int64, shape (n_el + 1,)
    indices : ndarray of int64, shape (offsets[-1],)
        Element ``e``'s candidates are ``indices[offsets[e]:offsets[e + 1]]``, increasing.
    """
    overlap = np.all(
        (elo[:, None, :] <= shi[None, :, :]) & (slo[None, :, :] <= ehi[:, None, :]), axis=2
    )
    return _csr_from_mask(overlap)


def candidates_all_segments(n_elements: int, n_segments: int):
    """Brute force (``broad_phase="none"``): every segment is a candidate of every element (CSR)."""
    offsets = np.arange(n_elements + 1, dtype=np.int64) * n_segments
    indices = np.tile(np.arange(n_segments, dtype=np.int64), n_elements)
    return offsets, indices


@_jit
def _sweep_pairs(elo, ehi, slo, shi, e_order, s_order, axis, pair_e, pair_s, active_e, active_s):
    """Sort-and-sweep along ``axis`` over presorted element and segment boxes.

    Walks the interval starts in increasing order; each new interval is tested against the
    still-open intervals of the other kind (those whose end is not before its start), then on
    the two remaining axes. Returns the number of overlapping pairs; only the first
    ``len(pair_e)`` are stored (the caller retries with more room when the count is larger).
    """
    n_e = e_order.shape[0]
    n_s = s_order.shape[0]
    cap = pair_e.shape[0]
    b1 = (axis + 1) % 3
    b2 = (axis + 2) % 3
    i = 0
    j = 0
    na_e = 0
    na_s = 0
    n_pairs = 0
    while i < n_e or j < n_s:
        take_element = j >= n_s or (i < n_e and elo[e_order[i], axis] <= slo[s_order[j], axis])
        if take_element:
            e = e_order[i]
            i += 1
            x = elo[e, axis]
            m = 0
            for u in range(na_s):  # drop segments that ended before this start: they are done
                s = active_s[u]
                if shi[s, axis] >= x:
                    active_s[m] = s
                    m += 1
            na_s = m
            for u in range(na_s):
                s = active_s[u]
                if (elo[e, b1] <= shi[s, b1] and slo[s, b1] <= ehi[e, b1]
                        and elo[e, b2] <= shi[s, b2] and slo[s, b2] <= ehi[e, b2]):
                    if n_pairs < cap:
                        pair_e[n_pairs] = e
                        pair_s[n_pairs] = s
                    n_pairs += 1
            active_e[na_e] = e
            na_e += 1
        else:
            s = s_order[j]
            j += 1
            x = slo[s, axis]
            m = 0
            for u in range(na_e):
                e = active_e[u]
                if ehi[e, axis] >= x:
                    active_e[m] = e
                    m += 1
            na_e = m
            for u in range(na_e):
                e = active_e[u]
                if (elo[e, b1] <= shi[s, b1] and slo[s, b1] <= ehi[e, b1]
                        and elo[e, b2] <= shi[s, b2] and slo[s, b2] <= ehi[e, b2]):
                    if n_pairs < cap:
                        pair_e[n_pairs] = e
                        pair_s[n_pairs] = s
                    n_pairs += 1
            active_s[na_s] = s
            na_s += 1
    return n_pairs


@_jit
def _pairs_to_csr(n_pairs, pair_e, pair_s, n_e, n_s, offsets, indices, seg_count, tmp):
    """Two stable counting sorts (by segment, then by element): CSR with increasing segments."""
    for s in range(n_s + 1):
        seg_count[s] = 0
    for p in range(n_pairs):
        seg_count[pair_s[p] + 1] += 1
    for s in range(n_s):
        seg_count[s + 1] += seg_count[s]
    for p in range(n_pairs):  # tmp = pair ids ordered by segment
        s = pair_s[p]
        tmp[seg_count[s]] = p
        seg_count[s] += 1
    for e in range(n_e + 1):
        offsets[e] = 0
    for p in range(n_pairs):
        offsets[pair_e[p] + 1] += 1
    for e in range(n_e):
        offsets[e + 1] += offsets[e]
    # fill per element in segment order; offsets[e] is used as a cursor, then shifted back
    for u in range(n_pairs):
        p = tmp[u]
        e = pair_e[p]
        indices[offsets[e]] = pair_s[p]
        offsets[e] += 1
    for e in range(n_e, 0, -1):
        offsets[e] = offsets[e - 1]
    offsets[0] = 0


@_jit
def _element_boxes(q, element_length_m, cable_radius_m, lo, hi):
    """Compiled :func:`element_aabbs` writing into ``lo``/``hi`` (no allocation)."""
    for e in range(element_length_m.shape[0]):
        third = element_length_m[e] / 3.0
        b = 6 * e
        for i in range(3):
            c0 = q[b + i]
            c3 = q[b + 6 + i]
            c1 = c0 + third * q[b + 3 + i]
            c2 = c3 - third * q[b + 9 + i]
            lo[e, i] = min(min(c0, c1), min(c2, c3)) - cable_radius_m
            hi[e, i] = max(max(c0, c1), max(c2, c3)) + cable_radius_m


class SweepBroadPhase:
    """Sort-and-sweep broad phase for a fixed conduit (compiled; buffers kept between calls).

    Parameters
    ----------
    seg_lo, seg_hi : ndarray, shape (n_seg, 3)
        Segment boxes inflated by the conduit's inner radius [m].
    element_length_m : ndarray, shape (n_el,)
        Element reference lengths [m].
    cable_radius_m : float
        Cable radius r [m], inflation of the element boxes.
    axis : int or None
        Sweep axis; default: the axis of largest extent of the segment boxes (the cable lies
        inside the conduit, so this is also the cable's longest extent).
    """

    def __init__(self, seg_lo, seg_hi, element_length_m, cable_radius_m, axis=None):
        self.seg_lo = np.ascontiguousarray(seg_lo, dtype=float)
        self.seg_hi = np.ascontiguousarray(seg_hi, dtype=float)
        self.length = np.ascontiguousarray(element_length_m, dtype=float)
        self.radius = float(cable_radius_m)
        self.axis = sweep_axis(self.seg_lo, self.seg_hi) if axis is None else int(axis)
        n_e, n_s = self.length.shape[0], self.seg_lo.shape[0]
        self.s_order = np.argsort(self.seg_lo[:, self.axis], kind="stable").astype(np.int64)
        self.elo = np.empty((n_e, 3))
        self.ehi = np.empty((n_e, 3))
        self.active_e = np.empty(n_e, dtype=np.int64)
        self.active_s = np.empty(n_s, dtype=np.int64)
        self.offsets = np.zeros(n_e + 1, dtype=np.int64)
        self.seg_count = np.empty(n_s + 1, dtype=np.int64)
        self._grow(8 * n_e + n_s)

    def _grow(self, capacity):
        self.pair_e = np.empty(capacity, dtype=np.int64)
        self.pair_s = np.empty(capacity, dtype=np.int64)
        self.tmp = np.empty(capacity, dtype=np.int64)
        self.indices = np.empty(capacity, dtype=np.int64)

    def boxes(self, q):
        """Element boxes (lo, hi) [m] for coordinates ``q`` (internal buffers, overwritten)."""
        _element_boxes(np.ascontiguousarray(q, dtype=float), self.length, self.radius,
                       self.elo, self.ehi)
        return self.elo, self.ehi

    def candidates(self, q):
        """CSR candidate lists (offsets, indices) for coordinates ``q``.

        The arrays are internal buffers, valid until the next call.
        """
        elo, ehi = self.boxes(q)
        return self.candidates_from_boxes(elo, ehi)

    def candidates_from_boxes(self, elo, ehi):
        """CSR candidate lists for given element boxes (internal buffers, valid until next call)."""
        e_order = np.argsort(elo[:, self.axis], kind="stable").astype(np.int64)
        while True:
            n_pairs = _sweep_pairs(elo, ehi, self.seg_lo, self.seg_hi, e_order, self.s_order,
                                   self.axis, self.pair_e, self.pair_s, self.active_e,
                                   self.active_s)
            if n_pairs <= self.pair_e.shape[0]:
                break
            self._grow(2 * n_pairs)
        _pairs_to_csr(n_pairs, self.pair_e, self.pair_s, elo.shape[0], self.seg_lo.shape[0],
                      self.offsets, self.indices, self.seg_count, self.tmp)
        return self.offsets, self.indices[:n_pairs]


def candidates_sweep(elo, ehi, slo, shi, axis=None):
    """Candidate segments of every element by sort-and-sweep (= :func:`candidates_all_pairs`).

    Parameters and returns as :func:`candidates_all_pairs`; ``axis`` is the sweep axis
    (default: largest extent of the segment boxes). Returns fresh arrays.
    """
    elo = np.ascontiguousarray(elo, dtype=float)
    ehi = np.ascontiguousarray(ehi, dtype=float)
    sweep = SweepBroadPhase(slo, shi, np.ones(elo.shape[0]), 0.0, axis=axis)
    offsets, indices = sweep.candidates_from_boxes(elo, ehi)
    return offsets.copy(), indices.copy()
