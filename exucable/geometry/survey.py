"""Conduit route from survey points: a polyline whose interior vertices are filleted into arcs.

At an interior vertex P_i with incoming direction d_in, outgoing direction d_out and turning angle
θ = ∠(d_in, d_out), a circular arc of the given bend radius R replaces the corner. It touches the
two legs at the tangent points P_i − T d_in and P_i + T d_out, T = R·tan(θ/2). The fillets on a
leg must fit: T_i + T_{i+1} ≤ |P_{i+1} − P_i| (first and last legs: the single fillet's T). The
paper (Sect. 2.3) takes the conduit's points from the survey; the fillets make its bends smooth
so that the contact kernel's segments can be placed on a curve of known curvature.

Errors name the input relative to the conduit table: ``points[i]``, ``bend_radius``,
``bend_radius[j]``, ``points_csv line k``.
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Sequence

import numpy as np

from ..errors import GeometryError
from .centreline import Centreline, Piece

__all__ = ["centreline_from_survey", "read_survey_csv"]

#: Turning angles below this [rad] are treated as collinear: the vertex gets no arc.
COLLINEAR_RAD = 1e-9
#: Relative slack [-] on a leg's length when checking that fillets fit, and below which the straight
#: between two fillets is dropped (rounding in T = R·tan(θ/2) must not refuse an exact fit).
_FIT_RTOL = 1e-9


def _radii(bend_radius_m, n_points: int) -> np.ndarray:
    """Bend radius per point [m], shape (n,), NaN at the two ends (no fillet there)."""
    n_inner = max(n_points - 2, 0)
    out = np.full(n_points, np.nan)
    if np.ndim(bend_radius_m) == 0:
        r = bend_radius_m
        if isinstance(r, bool) or not _is_positive(r):
            raise GeometryError("bend_radius", f"bend radius must be a finite number > 0 [m], got {r!r}")
        out[1:-1] = float(r)
        return out
    values = list(bend_radius_m)
    if len(values) == n_inner:
        per_point = False
        interior = values
    elif len(values) == n_points:
        per_point = True  # as read_survey_csv returns them; the two ends are ignored
        interior = values[1:-1]
    else:
        raise GeometryError("bend_radius", f"expected one bend radius per interior vertex ({n_inner}) "
                                           f"or per point ({n_points}), got {len(values)}")
    for j, r in enumerate(interior):
        if isinstance(r, bool) or not _is_positive(r):
            idx = j + 1 if per_point else j
            raise GeometryError(f"bend_radius[{idx}]", f"bend radius must be a finite number > 0 [m], got {r!r}")
        out[1 + j] = float(r)
    return out


def _is_positive(x) -> bool:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return False
    return math.isfinite(v) and v > 0.0


def centreline_from_survey(points_m, bend_radius_m: float | Sequence[float]) -> Centreline:
    """Fillet a survey polyline into a smooth centreline of straights and circular arcs.

    Parameters
    ----------
    points_m : array_like, shape (n, 3)
        Polyline vertices [m], n ≥ 2, no two consecutive ones coincident.
    bend_radius_m : float or sequence of float
        Bend radius of the fillets [m]: one value for all interior vertices, one per interior
        vertex (length n − 2), or one per point (length n; the first and last are ignored, as
        :func:`read_survey_csv` returns them).

    Returns
    -------
    Centreline
        Starts at ``points_m[0]`` and ends at ``points_m[-1]``. A vertex with zero turning
        (collinear legs) gets no arc.

    Raises
    ------
    GeometryError
        ``points[i]`` for a bad or coincident point, a reversal, or a fillet that does not fit;
        ``bend_radius``/``bend_radius[j]`` for a bad radius.
    """
    try:
        p = np.asarray(points_m, dtype=float)
    except (TypeError, ValueError):
        raise GeometryError("points", "expected an (n, 3) array of numbers [m]") from None
    if p.ndim != 2 or p.shape[1] != 3:
        raise GeometryError("points", f"expected an (n, 3) array of points [m], got shape {p.shape}")
    n = p.shape[0]
    if n < 2:
        raise GeometryError("points", "a survey route needs at least two points")
    for i in range(n):
        if not np.all(np.isfinite(p[i])):
            raise GeometryError(f"points[{i}]", f"point must be three finite numbers, got {p[i].tolist()}")
    radius = _radii(bend_radius_m, n)

    legs = np.diff(p, axis=0)
    leg_len = np.linalg.norm(legs, axis=1)
    for i, length in enumerate(leg_len):
        if length <= 0.0:
            raise GeometryError(f"points[{i + 1}]", f"coincides with points[{i}]")
    d = legs / leg_len[:, None]

    # Turning angle and tangent length at every vertex (0 at the ends and at collinear vertices).
    theta = np.zeros(n)
    tan_len = np.zeros(n)
    for i in range(1, n - 1):
        d_in, d_out = d[i - 1], d[i]
        # atan2 of |sin| and cos stays accurate for small and for near-π angles (arccos does not).
        th = math.atan2(np.linalg.norm(np.cross(d_in, d_out)), float(np.dot(d_in, d_out)))
        if th >= math.pi - COLLINEAR_RAD:
            raise GeometryError(f"points[{i}]", "the route reverses on itself here (turning angle 180°)")
        if th < COLLINEAR_RAD:
            continue
        theta[i] = th
        tan_len[i] = radius[i] * math.tan(0.5 * th)

    # Fit check on every leg i (points[i] -> points[i + 1]).
    for i, length in enumerate(leg_len):
        need = tan_len[i] + tan_len[i + 1]
        if need > length * (1.0 + _FIT_RTOL):
            culprit = i if tan_len[i] >= tan_len[i + 1] else i + 1
            other = i + 1 if culprit == i else i
            msg = (f"the fillet of radius {radius[culprit]:.6g} m here needs a tangent length "
                   f"R·tan(θ/2) = {tan_len[culprit]:.6g} m")
            if tan_len[other] > 0.0:
                msg += f" and the one at points[{other}] {tan_len[other]:.6g} m"
            msg += (f" on the leg points[{i}]–points[{i + 1}], which is only {length:.6g} m long; "
                    "reduce the bend radius or move the points")
            raise GeometryError(f"points[{culprit}]", msg)

    pieces: list[Piece] = []
    s = 0.0
    for i in range(n - 1):
        # Straight part of leg i between the fillet at i (if any) and the one at i + 1.
        a = p[i] + tan_len[i] * d[i]
        remaining = leg_len[i] - tan_len[i] - tan_len[i + 1]
        if remaining > _FIT_RTOL * leg_len[i]:
            pieces.append(Piece.straight(s, a, d[i], remaining))
            s += remaining
        j = i + 1
        if j < n - 1 and theta[j] > 0.0:
            start = p[j] - tan_len[j] * d[j - 1]
            axis = np.cross(d[j - 1], d[j])
            arc = Piece.arc(s, start, d[j - 1], axis / np.linalg.norm(axis), radius[j], theta[j])
            pieces.append(arc)
            s += arc.length_m
    return Centreline(pieces)


def read_survey_csv(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray | None]:
    """Read survey points from a CSV file.

    The header is ``x,y,z`` or ``x,y,z,bend_radius`` (all in metres). Blank lines and lines
    starting with ``#`` are skipped. Bend radii on the first and last data rows are ignored
    (they may be empty) and returned as NaN.

    Parameters
    ----------
    path : str or os.PathLike
        CSV file.

    Returns
    -------
    points_m : ndarray, shape (n, 3)
        Survey points [m].
    bend_radius_m : ndarray, shape (n,) or None
        Bend radius at each point [m] (NaN at the ends), or ``None`` without that column.

    Raises
    ------
    GeometryError
        ``points_csv`` if the file cannot be read or has fewer than two points;
        ``points_csv line k`` (1-based line number in the file) for a malformed line.
    """
    try:
        with open(path, newline="", encoding="utf-8-sig") as f:
            lines = f.read().splitlines()
    except OSError as exc:
        raise GeometryError("points_csv", f"cannot read {os.fspath(path)!r}: {exc.strerror or exc}") from None

    rows = [(k + 1, line) for k, line in enumerate(lines) if line.strip() and not line.lstrip().startswith("#")]
    if not rows:
        raise GeometryError("points_csv", f"{os.fspath(path)!r} is empty")
    header_line, header_text = rows[0]
    header = [h.strip().lower() for h in next(csv.reader([header_text]))]
    if header == ["x", "y", "z"]:
        with_radius = False
    elif header == ["x", "y", "z", "bend_radius"]:
        with_radius = True
    else:
        raise GeometryError(f"points_csv line {header_line}",
                            f"header must be 'x,y,z' or 'x,y,z,bend_radius', got {header_text.strip()!r}")

    data = rows[1:]
    if len(data) < 2:
        raise GeometryError("points_csv", "a survey route needs at least two points")
    points = np.empty((len(data), 3))
    radii = np.full(len(data), np.nan) if with_radius else None
    ncol = len(header)
    for r, (line_no, text) in enumerate(data):
        key = f"points_csv line {line_no}"
        cells = [c.strip() for c in next(csv.reader([text]))]
        if len(cells) != ncol:
            raise GeometryError(key, f"expected {ncol} values ({','.join(header)}), got {len(cells)}")
        for c in range(3):
            points[r, c] = _parse_number(cells[c], key, header[c])
        if with_radius and 0 < r < len(data) - 1:
            value = _parse_number(cells[3], key, "bend_radius")
            if value <= 0.0:
                raise GeometryError(key, f"bend_radius must be > 0 [m], got {cells[3]!r}")
            radii[r] = value
    return points, radii


def _parse_number(text: str, key: str, column: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise GeometryError(key, f"{column} is not a number: {text!r}") from None
    if not math.isfinite(value):
        raise GeometryError(key, f"{column} must be finite, got {text!r}")
    return value
