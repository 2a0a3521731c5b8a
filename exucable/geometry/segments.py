"""Straight hollow-cylinder segments of a conduit (paper Sect. 2.3).

Pure numpy; nothing here knows of Exudyn. The arrays are laid out for the contact
kernel: one row per segment, contiguous float64.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Segments"]


@dataclass(frozen=True, eq=False)
class Segments:
    """A polyline of straight hollow cylinders approximating a conduit centreline.

    Attributes
    ----------
    vertices_m : ndarray, shape (n + 1, 3)
        Polyline vertices [m]; segment ``i`` runs from ``vertices_m[i]`` to ``vertices_m[i + 1]``.
        Every vertex lies on the smooth centreline.
    s_vertex_m : ndarray, shape (n + 1,)
        Arc length of each vertex along the *smooth* centreline [m] (``s_vertex_m[0] == 0``).
    inner_radius_m : float
        Inner radius R of the conduit [m].
    """

    vertices_m: np.ndarray
    s_vertex_m: np.ndarray
    inner_radius_m: float

    def __post_init__(self):
        v = np.ascontiguousarray(self.vertices_m, dtype=float)
        s = np.ascontiguousarray(self.s_vertex_m, dtype=float)
        if v.ndim != 2 or v.shape[1] != 3 or v.shape[0] < 2:
            raise ValueError("vertices_m must have shape (n + 1, 3) with n >= 1")
        if s.shape != (v.shape[0],):
            raise ValueError("s_vertex_m must have one entry per vertex")
        lengths = np.linalg.norm(np.diff(v, axis=0), axis=1)
        if np.any(lengths <= 0.0):
            raise ValueError("zero-length segment in conduit polyline")
        object.__setattr__(self, "vertices_m", v)
        object.__setattr__(self, "s_vertex_m", s)
        object.__setattr__(self, "inner_radius_m", float(self.inner_radius_m))

    @property
    def count(self) -> int:
        """Number of segments."""
        return self.vertices_m.shape[0] - 1

    @property
    def start_m(self) -> np.ndarray:
        """Segment start points P_i [m], shape (n, 3)."""
        return self.vertices_m[:-1]

    @property
    def end_m(self) -> np.ndarray:
        """Segment end points P_j [m], shape (n, 3)."""
        return self.vertices_m[1:]

    @property
    def length_m(self) -> np.ndarray:
        """Segment lengths |P_j - P_i| [m], shape (n,)."""
        return np.linalg.norm(self.end_m - self.start_m, axis=1)

    @property
    def axis(self) -> np.ndarray:
        """Unit axis (P_j - P_i)/|P_j - P_i| of each segment, shape (n, 3)."""
        return (self.end_m - self.start_m) / self.length_m[:, None]

    @property
    def polyline_s_m(self) -> np.ndarray:
        """Cumulative length along the polyline at each vertex [m], shape (n + 1,)."""
        return np.concatenate([[0.0], np.cumsum(self.length_m)])

    @property
    def aabb_min_m(self) -> np.ndarray:
        """Lower corners of the segments' axis-aligned bounding boxes, inflated by the inner radius [m]."""
        return np.minimum(self.start_m, self.end_m) - self.inner_radius_m

    @property
    def aabb_max_m(self) -> np.ndarray:
        """Upper corners of the segments' axis-aligned bounding boxes, inflated by the inner radius [m]."""
        return np.maximum(self.start_m, self.end_m) + self.inner_radius_m

    def segment_aabbs(self) -> tuple[np.ndarray, np.ndarray]:
        """(lower, upper) corners of every segment's AABB inflated by the inner radius [m]."""
        return self.aabb_min_m, self.aabb_max_m
