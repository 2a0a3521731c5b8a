"""Conduit route from primitives: straight runs, circular bends and vertical-axis helices.

The primitives are chained from a start point and heading; each starts where the previous one
ended, with its end tangent as the new heading. Pure numpy.

Errors name the item relative to the conduit table, with the scenario file's field names:
``path[i].straight`` (length), ``path[i].bend`` (angle), ``path[i].radius``, ``path[i].turn``,
``path[i].axis``, ``path[i].helix`` (turns), ``path[i].pitch``; ``start``, ``heading``, ``path``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError
from .centreline import Centreline, Piece

__all__ = ["Straight", "Bend", "Helix", "centreline_from_path"]

_EZ = np.array([0.0, 0.0, 1.0])

#: Below this norm (of a unit vector's remainder) a direction is taken as undefined.
_DEGENERATE = 1e-9


@dataclass(frozen=True)
class Straight:
    """A straight run.

    Attributes
    ----------
    length_m : float
        Length [m], > 0.
    """

    length_m: float


@dataclass(frozen=True)
class Bend:
    """A circular bend.

    Attributes
    ----------
    angle_deg : float
        Turning angle [deg], 0 < angle < 360.
    radius_m : float
        Bend radius of the centreline [m], > 0.
    turn : str or None
        ``"left"``/``"right"``: about +z/−z (right-hand rule); ``"up"``/``"down"``: in the vertical
        plane containing the current heading, toward +z/−z. Default: ``"left"`` unless ``axis``
        is given.
    axis : tuple of 3 float or None
        Rotation axis (right-hand rule). Its component along the current heading is removed; the
        bend is refused if little remains. Give at most one of ``turn`` and ``axis``
        (``Bend(90, 0.5, axis=(1, 0, 0))``).
    """

    angle_deg: float
    radius_m: float
    turn: str | None = None
    axis: tuple[float, float, float] | None = None


@dataclass(frozen=True)
class Helix:
    """A helix about a vertical axis, entered tangentially to the heading's horizontal part.

    Attributes
    ----------
    turns : float
        Number of coils, > 0.
    radius_m : float
        Coil radius a [m], > 0.
    pitch_m : float
        Rise in z per turn [m]; negative descends. Zero only for at most one turn (coils would
        coincide).
    turn : str
        ``"left"`` (counter-clockwise seen from above) or ``"right"``.

    Notes
    -----
    The helix's horizontal tangent at its start is the normalised horizontal projection of the
    current heading; its own slope is ``atan(p / (2π a))``. If the heading's slope differs, the
    route has a kink there (see :meth:`Centreline.tangent_jumps_rad`). A vertical heading is refused.
    """

    turns: float
    radius_m: float
    pitch_m: float
    turn: str = "left"


def _finite(x) -> bool:
    try:
        return math.isfinite(float(x))
    except (TypeError, ValueError):
        return False


def _vector3(value, key: str) -> np.ndarray:
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise GeometryError(key, f"expected three numbers, got {value!r}") from None
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise GeometryError(key, f"expected three finite numbers, got {value!r}")
    return v


def _positive(value, key: str, what: str) -> float:
    if isinstance(value, bool) or not _finite(value) or float(value) <= 0.0:
        raise GeometryError(key, f"{what} must be a finite number > 0, got {value!r}")
    return float(value)


def _perpendicular_axis(axis: np.ndarray, heading: np.ndarray, key: str, what: str) -> np.ndarray:
    """Unit part of ``axis`` perpendicular to the unit ``heading``; refuse if (nearly) parallel."""
    a = axis / np.linalg.norm(axis)
    perp = a - np.dot(a, heading) * heading
    n = np.linalg.norm(perp)
    if n < _DEGENERATE:
        raise GeometryError(key, f"{what} is parallel to the current heading {np.round(heading, 12).tolist()}; "
                                 "the bend plane is undefined")
    return perp / n


def _bend_axis(item: Bend, heading: np.ndarray, key: str) -> np.ndarray:
    if item.turn is not None and item.axis is not None:
        raise GeometryError(key + ".axis", "give either turn (left/right/up/down) or axis, not both")
    if item.axis is not None:
        axis = _vector3(item.axis, key + ".axis")
        if np.linalg.norm(axis) == 0.0:
            raise GeometryError(key + ".axis", "axis must not be the zero vector")
        return _perpendicular_axis(axis, heading, key + ".axis", "axis")
    turn = "left" if item.turn is None else item.turn
    if turn in ("left", "right"):
        return _perpendicular_axis(_EZ if turn == "left" else -_EZ, heading, key + ".turn",
                                   f"the {turn} turn's axis (±z)")
    if turn in ("up", "down"):
        # The bend lies in the vertical plane containing the heading; "up" turns toward +z, so the
        # axis is heading × n_up with n_up the unit part of +z perpendicular to the heading.
        up = _EZ - np.dot(_EZ, heading) * heading
        n = np.linalg.norm(up)
        if n < _DEGENERATE:
            raise GeometryError(key + ".turn", f"'{turn}' is undefined for a vertical heading; give axis")
        normal = up / n if turn == "up" else -up / n
        return np.cross(heading, normal)
    raise GeometryError(key + ".turn", f"unknown turn {turn!r}; expected left, right, up or down")


def _bend_piece(item: Bend, s: float, start: np.ndarray, heading: np.ndarray, key: str) -> Piece:
    if isinstance(item.angle_deg, bool) or not _finite(item.angle_deg) or not 0.0 < float(item.angle_deg) < 360.0:
        raise GeometryError(key + ".bend", f"bend angle must be in (0, 360) deg, got {item.angle_deg!r}")
    radius = _positive(item.radius_m, key + ".radius", "bend radius")
    axis = _bend_axis(item, heading, key)
    return Piece.arc(s, start, heading, axis, radius, math.radians(float(item.angle_deg)))


def _helix_piece(item: Helix, s: float, start: np.ndarray, heading: np.ndarray, key: str) -> Piece:
    turns = _positive(item.turns, key + ".helix", "number of turns")
    radius = _positive(item.radius_m, key + ".radius", "helix radius")
    if isinstance(item.pitch_m, bool) or not _finite(item.pitch_m):
        raise GeometryError(key + ".pitch", f"pitch must be a finite number, got {item.pitch_m!r}")
    pitch = float(item.pitch_m)
    if pitch == 0.0 and turns > 1.0:
        raise GeometryError(key + ".pitch", "a helix of more than one turn needs a non-zero pitch")
    if item.turn not in ("left", "right"):
        raise GeometryError(key + ".turn", f"unknown helix turn {item.turn!r}; expected left or right")
    horizontal = np.array([heading[0], heading[1], 0.0])
    n = np.linalg.norm(horizontal)
    if n < _DEGENERATE:
        raise GeometryError(key, "a helix cannot start from a vertical heading")
    e2 = horizontal / n
    # A right-hand helix about k = −z rises along +z when its rise along k is −p/2π.
    k = _EZ if item.turn == "left" else -_EZ
    rise = pitch / (2.0 * math.pi) * (1.0 if item.turn == "left" else -1.0)
    e1 = np.cross(e2, k)  # so that k × e1 = e2: the horizontal tangent at the start
    return Piece.helical(s, start - radius * e1, e1, k, radius, rise, 2.0 * math.pi * turns)


def centreline_from_path(start_m, heading, items: Sequence[Straight | Bend | Helix]) -> Centreline:
    """Chain primitives into a smooth centreline.

    Parameters
    ----------
    start_m : array_like, shape (3,)
        Start point [m].
    heading : array_like, shape (3,)
        Initial direction (any non-zero length).
    items : sequence of Straight, Bend, Helix
        The route, in order from the start.

    Returns
    -------
    Centreline

    Raises
    ------
    GeometryError
        Non-physical input; ``key`` names the item, e.g. ``"path[2].radius"``.
    """
    start = _vector3(start_m, "start")
    h = _vector3(heading, "heading")
    norm = np.linalg.norm(h)
    if norm == 0.0:
        raise GeometryError("heading", "heading must not be the zero vector")
    h = h / norm
    items = list(items)
    if not items:
        raise GeometryError("path", "the path needs at least one item")
    pieces: list[Piece] = []
    s = 0.0
    point = start
    for i, item in enumerate(items):
        key = f"path[{i}]"
        if isinstance(item, Straight):
            length = _positive(item.length_m, key + ".straight", "straight length")
            piece = Piece.straight(s, point, h, length)
        elif isinstance(item, Bend):
            piece = _bend_piece(item, s, point, h, key)
        elif isinstance(item, Helix):
            piece = _helix_piece(item, s, point, h, key)
        else:
            raise GeometryError(key, f"expected Straight, Bend or Helix, got {type(item).__name__}")
        pieces.append(piece)
        s += piece.length_m
        point = piece.end_m
        t = piece.end_tangent
        h = t / np.linalg.norm(t)
    return Centreline(pieces)
