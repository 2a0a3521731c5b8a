"""Smooth conduit centreline: a chain of straight, circular-arc and helical pieces.

Pure numpy. Every piece is parametrised by its own arc length ``u`` [m] and evaluated in
closed form (no integration), vectorised over arrays of ``u``. A circular arc is a helix
of zero rise, so bends and helices share one formula:

    p(φ) = c + a (cos φ e1 + sin φ e2) + h φ k,      φ = u / √(a² + h²)

with ``k`` the (unit) axis, ``e1`` the unit vector from the axis to the start point,
``e2 = k × e1``, ``a`` the radius [m] and ``h`` the rise along ``k`` per radian [m/rad].
Curvature κ = a/(a² + h²) is constant on a piece (paper Sect. 2.3 builds the conduit from
straight and bending segments; the helix is its Example 3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

__all__ = ["Piece", "Centreline"]

#: Relative tolerance on arc length when checking the range of ``s`` and the chaining of pieces.
_S_RTOL = 1e-9


def _unit(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


@dataclass(frozen=True, eq=False)
class Piece:
    """One smooth piece of a centreline with constant curvature.

    Build with :meth:`straight`, :meth:`arc` or :meth:`helical` rather than directly.

    Attributes
    ----------
    kind : str
        ``"straight"``, ``"bend"`` (circular arc) or ``"helix"``.
    s_start_m : float
        Arc length of the piece's start along the whole centreline [m].
    length_m : float
        Arc length of the piece [m].
    start_m : ndarray, shape (3,)
        Start point [m].
    direction : ndarray, shape (3,)
        Unit tangent at the start (constant on a straight).
    centre_m, e1, e2, axis : ndarray, shape (3,) or None
        Helix frame of a curved piece (see the module docstring); ``None`` on a straight.
    coil_radius_m : float
        Radius ``a`` of a bend or a helix [m]; ``inf`` on a straight.
    rise_m_per_rad : float
        Rise ``h`` along ``axis`` per radian of rotation [m/rad]; 0 on a bend and a straight.
    """

    kind: str
    s_start_m: float
    length_m: float
    start_m: np.ndarray
    direction: np.ndarray
    centre_m: np.ndarray | None = None
    e1: np.ndarray | None = None
    e2: np.ndarray | None = None
    axis: np.ndarray | None = None
    coil_radius_m: float = math.inf
    rise_m_per_rad: float = 0.0

    # ---------------------------------------------------------------- constructors
    @classmethod
    def straight(cls, s_start_m: float, start_m, direction, length_m: float) -> "Piece":
        """A straight run of ``length_m`` [m] from ``start_m`` [m] along unit ``direction``."""
        return cls("straight", float(s_start_m), float(length_m),
                   np.array(start_m, dtype=float), _unit(direction))

    @classmethod
    def arc(cls, s_start_m: float, start_m, tangent, axis, radius_m: float, angle_rad: float) -> "Piece":
        """A circular arc of ``radius_m`` [m] turning by ``angle_rad`` about ``axis`` (right-hand rule).

        ``tangent`` and ``axis`` must be unit vectors and perpendicular; the tangent turns
        toward ``axis × tangent``, where the centre lies.
        """
        t0 = _unit(tangent)
        k = _unit(axis)
        n0 = np.cross(k, t0)  # unit: k ⟂ t0
        start = np.array(start_m, dtype=float)
        return cls("bend", float(s_start_m), float(radius_m * angle_rad), start, t0,
                   centre_m=start + radius_m * n0, e1=-n0, e2=t0, axis=k,
                   coil_radius_m=float(radius_m), rise_m_per_rad=0.0)

    @classmethod
    def helical(cls, s_start_m: float, centre_m, e1, axis, radius_m: float, rise_m_per_rad: float,
                phi_rad: float, kind: str = "helix") -> "Piece":
        """A helix about ``axis`` through ``centre_m`` starting at ``centre_m + radius_m·e1``.

        Parameters
        ----------
        centre_m : array_like, shape (3,)
            Point on the helix axis at the start's height [m].
        e1, axis : array_like, shape (3,)
            Orthonormal: unit vector from the axis to the start point, unit axis (rotation by the
            right-hand rule).
        radius_m : float
            Coil radius a [m].
        rise_m_per_rad : float
            Rise h along ``axis`` per radian [m/rad] (pitch / 2π).
        phi_rad : float
            Total rotation angle about the axis [rad] (2π per turn).
        """
        c = np.array(centre_m, dtype=float)
        e1 = _unit(e1)
        k = _unit(axis)
        e2 = np.cross(k, e1)
        w = math.hypot(radius_m, rise_m_per_rad)
        return cls(kind, float(s_start_m), float(phi_rad * w), c + radius_m * e1,
                   (radius_m * e2 + rise_m_per_rad * k) / w,
                   centre_m=c, e1=e1, e2=e2, axis=k,
                   coil_radius_m=float(radius_m), rise_m_per_rad=float(rise_m_per_rad))

    # ---------------------------------------------------------------- scalars
    @property
    def is_curved(self) -> bool:
        """True for bends and helices."""
        return self.kind != "straight"

    @property
    def s_end_m(self) -> float:
        """Arc length of the piece's end along the whole centreline [m]."""
        return self.s_start_m + self.length_m

    @property
    def radius_m(self) -> float:
        """Bend radius or helix coil radius [m]; ``inf`` on a straight."""
        return self.coil_radius_m

    @property
    def _speed(self) -> float:
        """√(a² + h²): arc length per radian of rotation [m/rad]."""
        return math.hypot(self.coil_radius_m, self.rise_m_per_rad)

    @property
    def curvature_1_per_m(self) -> float:
        """Curvature κ = a/(a² + h²) [1/m]; 0 on a straight."""
        if not self.is_curved:
            return 0.0
        return self.coil_radius_m / self._speed**2

    @property
    def radius_of_curvature_m(self) -> float:
        """1/κ = (a² + h²)/a [m]; ``inf`` on a straight."""
        if not self.is_curved:
            return math.inf
        return self._speed**2 / self.coil_radius_m

    @property
    def phi_rad(self) -> float:
        """Rotation about the piece's axis [rad] (bend angle, or 2π × turns); 0 on a straight."""
        return self.length_m / self._speed if self.is_curved else 0.0

    @property
    def turning_angle_rad(self) -> float:
        """Total turning ∫κ ds of the tangent [rad]: θ for a bend, 2π·n·a/√(a² + h²) for a helix."""
        if not self.is_curved:
            return 0.0
        return self.phi_rad * self.coil_radius_m / self._speed

    @property
    def pitch_m(self) -> float:
        """Rise along the axis per full turn, 2π·h [m]; 0 on bends and straights."""
        return 2.0 * math.pi * self.rise_m_per_rad

    @property
    def end_m(self) -> np.ndarray:
        """End point [m], shape (3,)."""
        return self.point(self.length_m)

    @property
    def end_tangent(self) -> np.ndarray:
        """Unit tangent at the end, shape (3,)."""
        return self.tangent(self.length_m)

    # ---------------------------------------------------------------- evaluation
    def point(self, u) -> np.ndarray:
        """Point at local arc length ``u`` [m]; shape (3,) for scalar ``u``, (n, 3) for shape (n,)."""
        u = np.asarray(u, dtype=float)
        if not self.is_curved:
            return self.start_m + u[..., None] * self.direction
        phi = u / self._speed
        c, s = np.cos(phi)[..., None], np.sin(phi)[..., None]
        return (self.centre_m + self.coil_radius_m * (c * self.e1 + s * self.e2)
                + (self.rise_m_per_rad * phi)[..., None] * self.axis)

    def tangent(self, u) -> np.ndarray:
        """Unit tangent at local arc length ``u`` [m]."""
        u = np.asarray(u, dtype=float)
        if not self.is_curved:
            return np.broadcast_to(self.direction, u.shape + (3,)).copy()
        w = self._speed
        phi = u / w
        c, s = np.cos(phi)[..., None], np.sin(phi)[..., None]
        return (self.coil_radius_m * (c * self.e2 - s * self.e1) + self.rise_m_per_rad * self.axis) / w

    def curvature_vector(self, u) -> np.ndarray:
        """Curvature vector κ·n at local arc length ``u`` [1/m]; points to the axis; zero on a straight."""
        u = np.asarray(u, dtype=float)
        if not self.is_curved:
            return np.zeros(u.shape + (3,))
        phi = u / self._speed
        c, s = np.cos(phi)[..., None], np.sin(phi)[..., None]
        return -self.curvature_1_per_m * (c * self.e1 + s * self.e2)

    def tangent_and_curvature_fn(self):
        """A function of one local arc length ``u`` [m] giving the unit tangent and the curvature
        vector κ·n [1/m] there, each a tuple of three plain floats.

        The formulas of :meth:`tangent` and :meth:`curvature_vector` in scalar arithmetic, with the
        piece's constants taken out of numpy once: for a caller that asks for one point at a time in
        a loop (the rope ODE's right-hand side, ~100 calls a piece), where numpy's per-call overhead
        on 3-vectors costs ~20× the arithmetic.
        """
        if not self.is_curved:
            t = tuple(float(x) for x in self.direction)
            zero = (0.0, 0.0, 0.0)
            return lambda u: (t, zero)
        w = self._speed
        a, h, k = self.coil_radius_m, self.rise_m_per_rad, self.curvature_1_per_m
        (e1x, e1y, e1z), (e2x, e2y, e2z) = self.e1.tolist(), self.e2.tolist()
        hx, hy, hz = (h * x for x in self.axis.tolist())
        cos, sin = math.cos, math.sin

        def at(u):
            phi = u / w
            c, s = cos(phi), sin(phi)
            return (((a * (c * e2x - s * e1x) + hx) / w, (a * (c * e2y - s * e1y) + hy) / w,
                     (a * (c * e2z - s * e1z) + hz) / w),
                    (-k * (c * e1x + s * e2x), -k * (c * e1y + s * e2y), -k * (c * e1z + s * e2z)))

        return at

    def reversed(self, s_start_m: float) -> "Piece":
        """The same piece traversed from its end, starting at centreline arc length ``s_start_m`` [m]."""
        if not self.is_curved:
            return Piece.straight(s_start_m, self.end_m, -self.direction, self.length_m)
        # Substituting φ = Φ − φ' into the helix formula gives a helix about −k with the same
        # rise h, starting at the old end (derivation in the module docstring's notation).
        phi = self.phi_rad
        e1_end = math.cos(phi) * self.e1 + math.sin(phi) * self.e2
        rev = Piece.helical(s_start_m, self.centre_m + self.rise_m_per_rad * phi * self.axis, e1_end,
                            -self.axis, self.coil_radius_m, self.rise_m_per_rad, phi, kind=self.kind)
        # Keep the length bit-identical (φ·w may round differently from the stored length).
        return replace(rev, length_m=self.length_m)


class Centreline:
    """A smooth conduit centreline: pieces chained end to start, parametrised by arc length s [m].

    Parameters
    ----------
    pieces : sequence of Piece
        Contiguous pieces; ``pieces[i].s_start_m`` must equal the sum of the previous lengths.

    Notes
    -----
    Evaluation methods take ``s_m`` in [0, L] (a scalar or an array); values outside by more than
    1e-9·L raise ``ValueError``, values within that tolerance are clipped. At a boundary between
    two pieces the later piece is used.
    """

    def __init__(self, pieces):
        pieces = tuple(pieces)
        if not pieces:
            raise ValueError("a centreline needs at least one piece")
        s = 0.0
        for i, p in enumerate(pieces):
            if not isinstance(p, Piece):
                raise TypeError(f"pieces[{i}] is not a Piece")
            if not (p.length_m > 0.0 and math.isfinite(p.length_m)):
                raise ValueError(f"pieces[{i}] has non-positive length {p.length_m!r}")
            if abs(p.s_start_m - s) > _S_RTOL * max(s, p.length_m):
                raise ValueError(f"pieces[{i}].s_start_m = {p.s_start_m} but the previous pieces end at {s}")
            s += p.length_m
        self.pieces: tuple[Piece, ...] = pieces
        self._s_start = np.array([p.s_start_m for p in pieces])
        self.length_m: float = float(pieces[-1].s_end_m)

    def __repr__(self) -> str:
        kinds = ", ".join(p.kind for p in self.pieces)
        return f"Centreline(length_m={self.length_m:.6g}, pieces=[{kinds}])"

    # ---------------------------------------------------------------- scalars
    @property
    def turning_angle_rad(self) -> float:
        """Total turning angle ∫κ ds over the centreline [rad] (exact, closed form per piece)."""
        return float(sum(p.turning_angle_rad for p in self.pieces))

    @property
    def min_bend_radius_m(self) -> float:
        """Smallest radius of curvature 1/κ over the curved pieces [m]; ``inf`` if all are straight."""
        return float(min((p.radius_of_curvature_m for p in self.pieces), default=math.inf))

    @property
    def start_m(self) -> np.ndarray:
        """Start point [m], shape (3,)."""
        return self.pieces[0].start_m.copy()

    @property
    def end_m(self) -> np.ndarray:
        """End point [m], shape (3,)."""
        return self.pieces[-1].end_m

    def tangent_jumps_rad(self) -> np.ndarray:
        """Angle between the end tangent of each piece and the start tangent of the next [rad].

        Shape (len(pieces) − 1,). Zero (to rounding) on routes built from compatible pieces; a
        helix entered from a heading whose slope differs from the helix's own slope leaves a kink,
        which ∫κ ds (and so :attr:`turning_angle_rad`) does not count.
        """
        out = []
        for a, b in zip(self.pieces[:-1], self.pieces[1:]):
            ta, tb = a.end_tangent, b.direction
            out.append(math.atan2(np.linalg.norm(np.cross(ta, tb)), float(np.dot(ta, tb))))
        return np.array(out)

    # ---------------------------------------------------------------- evaluation
    def _check_s(self, s_m) -> np.ndarray:
        s = np.asarray(s_m, dtype=float)
        tol = _S_RTOL * self.length_m
        if s.size == 1:
            x = s.item()
            if not (math.isfinite(x) and -tol <= x <= self.length_m + tol):
                raise ValueError(f"arc length outside [0, {self.length_m:.9g}] m")
            return np.full(s.shape, min(max(x, 0.0), self.length_m))
        if np.any(~np.isfinite(s)) or np.any(s < -tol) or np.any(s > self.length_m + tol):
            raise ValueError(f"arc length outside [0, {self.length_m:.9g}] m")
        return np.clip(s, 0.0, self.length_m)

    def piece_index(self, s_m):
        """Index of the piece containing arc length ``s_m`` [m]: int for a scalar, ndarray for an array."""
        s = self._check_s(s_m)
        idx = np.clip(np.searchsorted(self._s_start, s, side="right") - 1, 0, len(self.pieces) - 1)
        return int(idx) if idx.ndim == 0 else idx

    def _evaluate(self, s_m, method: str) -> np.ndarray:
        s = self._check_s(s_m)
        if s.size == 1:
            # one point (the rope ODE's right-hand side, ~1000 calls a solve): its piece directly,
            # without the grouping below
            idx = min(max(int(np.searchsorted(self._s_start, s.item(), side="right")) - 1, 0), len(self.pieces) - 1)
            piece = self.pieces[idx]
            u = s.reshape(1) - piece.s_start_m
            return getattr(piece, method)(u).reshape(s.shape + (3,))
        flat = s.reshape(-1)
        idx = np.clip(np.searchsorted(self._s_start, flat, side="right") - 1, 0, len(self.pieces) - 1)
        out = np.empty((flat.size, 3))
        # each piece's points as one slice of the points grouped by piece (ascending arc lengths are
        # grouped already): one pass over the points, not one boolean mask per piece (a 10 km route's
        # 60 pieces × 10⁵ points)
        ascending = bool(np.all(idx[1:] >= idx[:-1]))
        order = None if ascending else np.argsort(idx, kind="stable")
        bounds = np.searchsorted(idx if ascending else idx[order], np.arange(len(self.pieces) + 1))
        for i in np.flatnonzero(np.diff(bounds)):
            sel = slice(bounds[i], bounds[i + 1]) if ascending else order[bounds[i]:bounds[i + 1]]
            piece = self.pieces[i]
            out[sel] = getattr(piece, method)(flat[sel] - piece.s_start_m)
        return out.reshape(s.shape + (3,))

    def point(self, s_m) -> np.ndarray:
        """Point at arc length ``s_m`` [m]: shape (3,) for a scalar, (..., 3) for an array."""
        return self._evaluate(s_m, "point")

    def tangent(self, s_m) -> np.ndarray:
        """Unit tangent at arc length ``s_m`` [m]."""
        return self._evaluate(s_m, "tangent")

    def curvature_vector(self, s_m) -> np.ndarray:
        """Curvature vector κ·n at arc length ``s_m`` [1/m]; zero on straights."""
        return self._evaluate(s_m, "curvature_vector")

    # ---------------------------------------------------------------- derived routes
    def reversed(self) -> "Centreline":
        """The same route traversed from the other end: point'(s) = point(L − s), tangent flipped."""
        pieces = []
        s = 0.0  # accumulate afresh so that s_start is exactly the sum of the previous lengths
        for p in reversed(self.pieces):
            pieces.append(p.reversed(s))
            s += p.length_m
        return Centreline(pieces)

    def truncated(self, length_m: float) -> "Centreline":
        """The route's first ``length_m`` [m], ``0 < length_m <= L``: the pieces before it, and the
        piece it ends in cut there (the same curve, a shorter arc)."""
        x = float(length_m)
        if not (0.0 < x <= self.length_m * (1.0 + _S_RTOL)):
            raise ValueError(f"truncated: length must be in (0, {self.length_m:.9g}] m, got {length_m!r}")
        if x >= self.length_m:
            return self
        k = self.piece_index(x)
        pieces = list(self.pieces[:k])
        if x > self.pieces[k].s_start_m:
            pieces.append(replace(self.pieces[k], length_m=x - self.pieces[k].s_start_m))
        return Centreline(pieces)

    def curved_ranges_m(self) -> list[tuple[float, float]]:
        """Arc-length intervals (start, end) [m] of the bends and helices, in order."""
        return [(p.s_start_m, p.s_end_m) for p in self.pieces if p.is_curved]

    def sample(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """``n`` ≥ 2 equally spaced arc lengths [m] and the points there [m], shapes (n,) and (n, 3)."""
        if n < 2:
            raise ValueError("sample needs n >= 2")
        s = np.linspace(0.0, self.length_m, int(n))
        return s, self.point(s)
