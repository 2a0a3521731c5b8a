"""The nearest of many fixed sample points along a curve, exactly, for batches of query points.

Used by :class:`exucable.post.trust.AxisGauge` (the cable axis's distance from the conduit's axis, at
every record) in place of ``scipy.spatial.cKDTree``, whose import alone (scipy.spatial with the
scipy.sparse and scipy.special it loads) was a tenth of a second of every ``exucable run``
(the fixed cost, docs/performance.md); numba is loaded by the contact kernel anyway.

The samples are cut into blocks of √n consecutive samples. A block's samples lie within its radius
ρ_b (the largest distance of a member from the block's centre sample) of that centre, so none of
them is nearer to a query point p than |p − c_b| − ρ_b. A query first takes the nearest block centre
(itself a sample) as its best, then searches only the blocks whose bound does not exceed the best so
far. The answer is the exact nearest sample (the first one among equally near samples, in the order
searched); only the work depends on the samples lying along a curve: consecutive samples then make
compact blocks and a query opens a few of them, O(√n) per query instead of O(n).
"""

from __future__ import annotations

import math

import numpy as np

from .jitcache import njit

__all__ = ["NearestSample"]


@njit(nogil=True)
def _nearest(points, samples, block_start, block_centre, block_radius, out):
    n_blocks = block_centre.size
    centre_distance = np.empty(n_blocks)
    for k in range(points.shape[0]):
        px, py, pz = points[k, 0], points[k, 1], points[k, 2]
        best, best_i = np.inf, -1
        for b in range(n_blocks):
            j = block_centre[b]
            dx, dy, dz = samples[j, 0] - px, samples[j, 1] - py, samples[j, 2] - pz
            d2 = dx * dx + dy * dy + dz * dz
            centre_distance[b] = math.sqrt(d2)
            if d2 < best:
                best, best_i = d2, j
        for b in range(n_blocks):
            if centre_distance[b] - block_radius[b] > math.sqrt(best):
                continue                       # every member is farther than the best so far
            for j in range(block_start[b], block_start[b + 1]):
                dx, dy, dz = samples[j, 0] - px, samples[j, 1] - py, samples[j, 2] - pz
                d2 = dx * dx + dy * dy + dz * dz
                if d2 < best:
                    best, best_i = d2, j
        out[k] = best_i


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
        size = max(1, math.isqrt(n - 1) + 1)            # ⌈√n⌉ samples a block
        starts = np.arange(0, n, size)
        centre = np.minimum(starts + size // 2, n - 1)
        counts = np.diff(np.append(starts, n))
        spread = np.linalg.norm(c - c[np.repeat(centre, counts)], axis=1)
        self.samples_m = c
        self._start = np.append(starts, n).astype(np.int64)
        self._centre = centre.astype(np.int64)
        self._radius = np.maximum.reduceat(spread, starts)

    def __call__(self, points_m) -> np.ndarray:
        p = np.ascontiguousarray(points_m, dtype=float).reshape(-1, 3)
        out = np.empty(len(p), dtype=np.int64)
        _nearest(p, self.samples_m, self._start, self._centre, self._radius, out)
        return out
