"""The nearest of many fixed sample points along a curve, exactly, for batches of query points.

Used by :class:`exucable.post.trust.AxisGauge` (the cable axis's distance from the conduit's axis, at
every record) in place of ``scipy.spatial.cKDTree``, whose import alone (scipy.spatial with the
scipy.sparse and scipy.special it loads) was a tenth of a second of every ``exucable run``
(the fixed cost, docs/performance.md); numba is loaded by the contact kernel anyway.

The samples are cut into blocks of ~n^(1/3) consecutive samples, and the blocks into groups of
~n^(1/3) blocks. A block's samples lie within its radius ρ (the largest distance of a member from its
centre sample) of that centre, a group's within the largest |c_block − c_group| + ρ_block of its
blocks, so none of them is nearer to a query point p than |p − c| − ρ.
A query takes as its best so far the previous query's answer (the points of a cable come in order
along it) or, if nearer, the nearest group centre (itself a sample); it then opens only the groups,
and in them the blocks, whose bound does not exceed the best so far, and scans those blocks'
samples. The answer is the exact nearest sample (the first one among equally near samples, in the
order searched); only the work depends on the samples lying along a curve: consecutive samples
then make compact blocks and groups, and a query opens a few of them, O(n^(1/3)) per query instead
of O(n).
"""

from __future__ import annotations

import math

import numpy as np

from .jitcache import njit

__all__ = ["NearestSample"]


@njit(nogil=True)
def _nearest(points, samples, block_start, block_centre, block_radius, group_start, group_centre, group_radius,
             out):
    n_groups = group_centre.size
    group_distance = np.empty(n_groups)
    previous = -1
    for k in range(points.shape[0]):
        px, py, pz = points[k, 0], points[k, 1], points[k, 2]
        best, best_i = np.inf, -1
        if previous >= 0:
            dx, dy, dz = samples[previous, 0] - px, samples[previous, 1] - py, samples[previous, 2] - pz
            best, best_i = dx * dx + dy * dy + dz * dz, previous
        for g in range(n_groups):
            j = group_centre[g]
            dx, dy, dz = samples[j, 0] - px, samples[j, 1] - py, samples[j, 2] - pz
            d2 = dx * dx + dy * dy + dz * dz
            group_distance[g] = math.sqrt(d2)
            if d2 < best:
                best, best_i = d2, j
        for g in range(n_groups):
            if group_distance[g] - group_radius[g] > math.sqrt(best):
                continue                       # every member is farther than the best so far
            for b in range(group_start[g], group_start[g + 1]):
                j = block_centre[b]
                dx, dy, dz = samples[j, 0] - px, samples[j, 1] - py, samples[j, 2] - pz
                d2 = dx * dx + dy * dy + dz * dz
                if math.sqrt(d2) - block_radius[b] > math.sqrt(best):
                    continue
                for j in range(block_start[b], block_start[b + 1]):
                    dx, dy, dz = samples[j, 0] - px, samples[j, 1] - py, samples[j, 2] - pz
                    d2 = dx * dx + dy * dy + dz * dz
                    if d2 < best:
                        best, best_i = d2, j
        out[k] = best_i
        previous = best_i


class NearestSample:
    """Index of the nearest of ``samples_m`` (shape (n, 3) [m], best in order along a curve).

    ``NearestSample(samples)(points)`` returns, for points of shape (m, 3) [m], the index of each
    one's nearest sample (int array, shape (m,)).
    """

    def __init__(self, samples_m):
        c = np.ascontiguousarray(samples_m, dtype=float).reshape(-1, 3)
        n = len(c)
        if n == 0:
            raise ValueError("NearestSample needs at least one sample")
        size = _cube_root_up(n)                          # ~n^(1/3) samples a block
        starts = np.arange(0, n, size)
        centre, radius = _spans(c, starts)
        per_group = max(1, math.isqrt(len(starts) - 1) + 1)  # ~n^(1/3) blocks a group
        group_blocks = np.arange(0, len(starts), per_group)
        group_centre, _ = _spans(c, starts[group_blocks], radii=False)
        # a group's radius bounded through its blocks' (|c_b − c_g| + ρ_b ≥ any member's distance):
        # a bound is all the search needs, and it takes a distance per block, not per sample
        reach = np.linalg.norm(c[centre] - c[np.repeat(group_centre, np.diff(np.append(group_blocks, len(starts))))],
                               axis=1) + radius
        group_radius = np.maximum.reduceat(reach, group_blocks)
        self.samples_m = c
        self._start = np.append(starts, n).astype(np.int64)
        self._centre = centre.astype(np.int64)
        self._radius = radius
        self._group_start = np.append(group_blocks, len(starts)).astype(np.int64)
        self._group_centre = group_centre.astype(np.int64)
        self._group_radius = group_radius

    def __call__(self, points_m) -> np.ndarray:
        p = np.ascontiguousarray(points_m, dtype=float).reshape(-1, 3)
        out = np.empty(len(p), dtype=np.int64)
        _nearest(p, self.samples_m, self._start, self._centre, self._radius, self._group_start, self._group_centre,
                 self._group_radius, out)
        return out


def _cube_root_up(n: int) -> int:
    """The least k >= 1 with k³ >= n."""
    k = max(1, round(n ** (1.0 / 3.0)))
    while k ** 3 < n:
        k += 1
    while k > 1 and (k - 1) ** 3 >= n:
        k -= 1
    return k


def _spans(samples, starts, radii: bool = True):
    """Centre sample (the middle one) and radius (the largest distance of a member from it; None
    unless ``radii``) of each run of consecutive ``samples`` beginning at ``starts`` (the last run
    ends with the samples)."""
    n = len(samples)
    counts = np.diff(np.append(starts, n))
    centre = np.minimum(starts + counts // 2, n - 1)
    if not radii:
        return centre, None
    spread = np.linalg.norm(samples - samples[np.repeat(centre, counts)], axis=1)
    return centre, np.maximum.reduceat(spread, starts)
