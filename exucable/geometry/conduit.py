"""A conduit: inner radius + smooth centreline + its straight-segment approximation.

Paper Sect. 2.3 models the conduit as "the assembly of multiple straight segments", each a hollow
cylinder of the conduit's inner radius between two points on its axis. Here every straight piece of
the centreline becomes one segment and every bend or helix is cut into k chords of equal arc length,
all vertices on the smooth curve. For a piece of radius of curvature ρ turned by Δθ per chord the
distance from a chord's midpoint to the curve is at most ρ(1 − cos(Δθ/2)) (equal on a bend).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError
from .centreline import Centreline
from .segments import Segments

__all__ = ["discretise", "Conduit"]

#: Relative slack on θ/Δθ_max before rounding up, so that e.g. 90°/0.9° gives 100 chords, not 101.
_CEIL_RTOL = 1e-9


def _segment_counts(centreline: Centreline, max_segment_angle_deg, segments_per_bend) -> list[int]:
    if (max_segment_angle_deg is None) == (segments_per_bend is None):
        raise GeometryError("max_segment_angle", "give exactly one of max_segment_angle and segments_per_bend")
    if max_segment_angle_deg is not None:
        try:
            dmax = float(max_segment_angle_deg)
        except (TypeError, ValueError):
            dmax = math.nan
        if isinstance(max_segment_angle_deg, bool) or not math.isfinite(dmax) or not 0.0 < dmax < 180.0:
            raise GeometryError("max_segment_angle",
                                f"must be a number in (0, 180) deg, got {max_segment_angle_deg!r}")
        dmax_rad = math.radians(dmax)
        return [max(1, math.ceil(p.turning_angle_rad / dmax_rad * (1.0 - _CEIL_RTOL))) if p.is_curved else 1
                for p in centreline.pieces]
    k = segments_per_bend
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
        raise GeometryError("segments_per_bend", f"must be an integer >= 1, got {k!r}")
    return [int(k) if p.is_curved else 1 for p in centreline.pieces]


def discretise(centreline: Centreline, inner_radius_m: float, max_segment_angle_deg: float | None = None,
               segments_per_bend: int | None = None) -> Segments:
    """Approximate a centreline by straight hollow-cylinder segments (paper Sect. 2.3).

    Parameters
    ----------
    centreline : Centreline
        Smooth route.
    inner_radius_m : float
        Conduit inner radius R [m], > 0.
    max_segment_angle_deg : float, optional
        Largest turning angle of the curve per chord [deg]: a curved piece of turning angle θ gets
        k = ceil(θ / max_segment_angle) chords.
    segments_per_bend : int, optional
        Fixed number k of chords per curved piece. Give exactly one of the two options.

    Returns
    -------
    Segments
        Each straight piece is one segment (consecutive straights stay separate); each curved piece
        is k chords of equal arc length. ``s_vertex_m`` is the arc length of the smooth curve at each
        vertex, ending at exactly ``centreline.length_m``.
    """
    radius = _check_inner_radius(inner_radius_m)
    counts = _segment_counts(centreline, max_segment_angle_deg, segments_per_bend)
    vertices = []
    s_vertex = []
    for piece, k in zip(centreline.pieces, counts):
        u = piece.length_m * np.arange(k) / k  # the piece's own start, not the previous piece's end
        vertices.append(piece.point(u))
        s_vertex.append(piece.s_start_m + u)
    last = centreline.pieces[-1]
    vertices.append(last.end_m[None, :])
    s_vertex.append(np.array([centreline.length_m]))
    return Segments(np.concatenate(vertices), np.concatenate(s_vertex), radius)


def _check_inner_radius(inner_radius_m) -> float:
    try:
        r = float(inner_radius_m)
    except (TypeError, ValueError):
        r = math.nan
    if isinstance(inner_radius_m, bool) or not math.isfinite(r) or r <= 0.0:
        raise GeometryError("inner_radius", f"inner radius must be a finite number > 0 [m], got {inner_radius_m!r}")
    return r


@dataclass(frozen=True, eq=False)
class Conduit:
    """A rigid conduit: inner radius, smooth centreline and its straight segments.

    Attributes
    ----------
    inner_radius_m : float
        Inner radius R [m].
    centreline : Centreline
        Smooth route of the conduit's axis.
    segments : Segments
        Straight hollow cylinders for the contact kernel (vertices on the centreline).
    """

    inner_radius_m: float
    centreline: Centreline
    segments: Segments

    @classmethod
    def build(cls, inner_radius_m: float, centreline: Centreline, max_segment_angle_deg: float | None = None,
              segments_per_bend: int | None = None) -> "Conduit":
        """Discretise ``centreline`` (see :func:`discretise`) and bundle the result."""
        segments = discretise(centreline, inner_radius_m, max_segment_angle_deg, segments_per_bend)
        return cls(segments.inner_radius_m, centreline, segments)

    def summary(self) -> dict:
        """Key figures: ``length_m`` [m], ``turning_angle_deg`` [deg], ``segments`` (count),
        ``min_bend_radius_m`` [m] (``inf`` if straight), ``bends`` (number of bends and helices)."""
        c = self.centreline
        return {
            "length_m": c.length_m,
            "turning_angle_deg": math.degrees(c.turning_angle_rad),
            "segments": self.segments.count,
            "min_bend_radius_m": c.min_bend_radius_m,
            "bends": sum(1 for p in c.pieces if p.is_curved),
        }

    def truncated(self, length_m: float) -> "Conduit":
        """The conduit's first ``length_m`` [m] (the cable's pull-in, head at ``length_m``): the same
        segments up to there, the last one ending on the centreline at ``length_m``, so that the
        wall the cable meets before its head is the whole conduit's."""
        c = self.centreline.truncated(length_m)
        if c is self.centreline:
            return self
        seg = self.segments
        x = c.length_m
        keep = int(np.searchsorted(seg.s_vertex_m, x, side="left"))       # vertices with s < x
        # a vertex within a hair of x would leave a zero-length last segment: drop it
        if keep > 1 and x - seg.s_vertex_m[keep - 1] <= 1e-9 * x:
            keep -= 1
        vertices = np.vstack([seg.vertices_m[:keep], c.point(x)[None, :]])
        s = np.concatenate([seg.s_vertex_m[:keep], [x]])
        return Conduit(self.inner_radius_m, c, Segments(vertices, s, seg.inner_radius_m))

    def reversed(self) -> "Conduit":
        """The same conduit entered from its other end (for pulling in the opposite direction).

        The segments are the original ones in reverse order, with s' = L − s.
        """
        c = self.centreline.reversed()
        seg = self.segments
        s = c.length_m - seg.s_vertex_m[::-1]
        s[0], s[-1] = 0.0, c.length_m  # exact ends despite rounding of L − s
        return Conduit(self.inner_radius_m, c, Segments(seg.vertices_m[::-1].copy(), s, seg.inner_radius_m))
