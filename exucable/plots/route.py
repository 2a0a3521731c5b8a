"""Route figure: the conduit centreline in 3D with its bends marked, and a summary table.

Drawn on matplotlib's Agg canvas directly (no pyplot state), so it is safe in worker processes
and without a display.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from ..io import new_figure, save_figure

__all__ = ["plot_route", "route_figure", "route_table"]

_STRAIGHT_COLOUR = "tab:blue"
_CURVED_COLOUR = "tab:orange"
#: Background of the text labels, so that they stay legible where they cross a line.
_LABEL_BOX = dict(facecolor="white", alpha=0.75, edgecolor="none", pad=0.8)
#: Smallest box side relative to the largest [-], so that a flat route still shows its third axis.
_MIN_BOX_FRACTION = 0.08


def route_table(conduit) -> list[tuple[str, str]]:
    """Rows (label, value) summarising a conduit, for printing.

    Parameters
    ----------
    conduit : exucable.geometry.Conduit

    Returns
    -------
    list of (str, str)
        Total length [m], total turning angle [deg], number of segments, min bend radius [m]
        (radius of curvature; "none" if the route is straight), number of bends (bends and helices).
    """
    s = conduit.summary()
    rmin = s["min_bend_radius_m"]
    return [
        ("total length [m]", f"{s['length_m']:.4f}"),
        ("total turning angle [deg]", f"{s['turning_angle_deg']:.2f}"),
        ("number of segments", f"{s['segments']:d}"),
        ("min bend radius [m]", "none" if math.isinf(rmin) else f"{rmin:.4g}"),
        ("number of bends", f"{s['bends']:d}"),
    ]


def _piece_label(number: int, piece, unit: str = "m", per_unit: float = 1.0) -> str:
    angle = f"{math.degrees(piece.turning_angle_rad):.0f}°"
    if piece.kind == "helix":
        turns = piece.phi_rad / (2.0 * math.pi)
        return (f"B{number} helix {turns:.3g} turns {angle} a{piece.radius_m / per_unit:.3g} {unit} "
                f"p{abs(piece.pitch_m) / per_unit:.3g} {unit}")
    return f"B{number} {angle} R{piece.radius_m / per_unit:.3g} {unit}"


def _piece_polyline(piece) -> np.ndarray:
    if not piece.is_curved:
        return piece.point(np.array([0.0, piece.length_m]))
    # About 3° per plotted chord: smooth at figure scale, cheap for many coils.
    n = max(8, math.ceil(math.degrees(piece.phi_rad) / 3.0)) + 1
    return piece.point(np.linspace(0.0, piece.length_m, n))


def _equal_box(ax, points: np.ndarray) -> None:
    lo, hi = points.min(axis=0), points.max(axis=0)
    span = hi - lo
    biggest = max(float(span.max()), 1e-9)
    side = np.maximum(span, _MIN_BOX_FRACTION * biggest) + 0.06 * biggest  # room for markers/labels
    mid = 0.5 * (lo + hi)
    ax.set_xlim(mid[0] - side[0] / 2, mid[0] + side[0] / 2)
    ax.set_ylim(mid[1] - side[1] / 2, mid[1] + side[1] / 2)
    ax.set_zlim(mid[2] - side[2] / 2, mid[2] + side[2] / 2)
    # Box sides proportional to the axis ranges: one metre has the same length on every axis.
    # zoom < 1 keeps the tick labels of a tall or wide box inside the axes.
    ax.set_box_aspect(tuple(side), zoom=0.88)


def _is_flat(points: np.ndarray) -> bool:
    """All points at one height (within 1e-6 of the route's extent): drawn as a plan view."""
    span = np.ptp(points, axis=0)
    return float(span[2]) <= 1e-6 * max(float(span.max()), 1e-12)


def _unit2(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)[:2]
    n = float(np.hypot(*v))
    return v / n if n > 0 else np.zeros(2)


def _name_offsets(pieces) -> list[np.ndarray]:
    """Unit directions (plan view) in which each point's name sits off the route: behind the start,
    beyond the end, and at a bend's ends back along the route and towards the bend's centre, so that
    the two ends of a short bend are named on either side and the bend's label (outside) stays clear."""
    out = [-_unit2(pieces[0].tangent(0.0))]
    for k in range(1, len(pieces)):
        before, after = pieces[k - 1], pieces[k]
        if after.is_curved:
            inward = _unit2(after.curvature_vector(0.0))
            out.append(_unit2(-_unit2(after.tangent(0.0)) + inward))
        elif before.is_curved:
            inward = _unit2(before.curvature_vector(before.length_m))
            out.append(_unit2(_unit2(before.tangent(before.length_m)) + inward))
        else:
            t = _unit2(after.tangent(0.0))
            out.append(np.array([-t[1], t[0]]))
    out.append(_unit2(pieces[-1].tangent(pieces[-1].length_m)))
    return out


def _plan_view(conduit, title, unit: str, per_unit: float, point_names) -> "object":
    """A level route seen from above, in ``unit``: straights blue, bends orange and numbered in route
    order ("bend 1"), the route's points marked and named; every label set off the route so that none
    covers a line, a point or another label."""
    c = conduit.centreline
    fig = new_figure(figsize=(7.2, 4.6), dpi=110)
    ax = fig.add_subplot(111)
    polylines = [_piece_polyline(p) / per_unit for p in c.pieces]
    pts = np.concatenate(polylines)
    extent = float(np.ptp(pts[:, :2], axis=0).max())
    gap = 0.045 * extent
    labels = []                                   # label anchors, to keep them inside the axes
    number = 0
    for piece, xyz in zip(c.pieces, polylines):
        ax.plot(xyz[:, 0], xyz[:, 1], color=_CURVED_COLOUR if piece.is_curved else _STRAIGHT_COLOUR,
                lw=2.6 if piece.is_curved else 1.8, solid_capstyle="butt")
        if piece.is_curved:
            number += 1
            u = 0.5 * piece.length_m
            outward = -_unit2(piece.curvature_vector(u))
            on = piece.point(u)[:2] / per_unit
            at = on + 1.6 * gap * outward
            labels.append(at)
            ax.annotate(f"bend {number}\n{math.degrees(piece.turning_angle_rad):.0f}°, R {piece.radius_m / per_unit:.3g} {unit}",
                        on, xytext=at, fontsize=7.5, color="0.1", bbox=_LABEL_BOX,
                        # the label grows away from the bend on the side it sits
                        ha="left" if outward[0] > 0.3 else "right" if outward[0] < -0.3 else "center",
                        va="bottom" if outward[1] > 0.3 else "top" if outward[1] < -0.3 else "center",
                        arrowprops=dict(arrowstyle="-", color="0.5", lw=0.6))
    ends = np.array([p.point(0.0) for p in c.pieces] + [c.end_m])[:, :2] / per_unit
    ax.plot(ends[:, 0], ends[:, 1], "o", color="k", ms=3.5)
    for name, xy, away in zip(point_names or [], ends, _name_offsets(c.pieces)):
        at = xy + gap * away
        labels.append(at)
        ax.text(at[0], at[1], name, fontsize=9, fontweight="bold", ha="center", va="center")
    if labels:
        lab = np.array(labels)
        ax.plot(lab[:, 0], lab[:, 1], alpha=0.0)        # the labels take part in the axes' limits
    ax.set_aspect("equal", adjustable="datalim")
    ax.margins(0.1)
    ax.set_xlabel(f"x [{unit}]")
    ax.set_ylabel(f"y [{unit}]")
    ax.grid(alpha=0.3)
    ax.set_title((title or "Conduit route") + f" (plan view, level at z = {pts[0, 2]:.4g} {unit})", fontsize=10)
    fig.tight_layout()
    return fig


def route_figure(conduit, title: str | None = None, length_unit: str = "m", metres_per_unit: float = 1.0,
                 point_names=None):
    """The route's figure (a :class:`matplotlib.figure.Figure`) in ``length_unit``.

    A level route is drawn in plan view with its points named (``point_names``, route order: the start
    and each piece's end); any other route in 3D as :func:`plot_route` draws it.
    """
    c = conduit.centreline
    pts = np.concatenate([_piece_polyline(p) for p in c.pieces])
    if _is_flat(pts):
        return _plan_view(conduit, title, length_unit, metres_per_unit, point_names)
    return _figure_3d(conduit, title, length_unit, metres_per_unit, point_names)


def plot_route(conduit, path, title: str | None = None, length_unit: str = "m", metres_per_unit: float = 1.0,
               point_names=None) -> Path:
    """Draw the conduit's centreline and write it as a PNG (atomically); returns the path.

    ``length_unit`` and ``metres_per_unit`` set the axes' unit (default metres); ``point_names`` names
    the route's points (a level route is then drawn in plan view: :func:`route_figure`).
    """
    out = Path(path)
    if point_names is not None or length_unit != "m":
        save_figure(route_figure(conduit, title, length_unit, metres_per_unit, point_names), out, dpi=None)
    else:
        save_figure(_figure_3d(conduit, title), out, dpi=None)
    return out


def _figure_3d(conduit, title: str | None = None, unit: str = "m", per_unit: float = 1.0, point_names=None):
    """Draw the conduit's centreline in 3D and write it as a PNG.

    Straights are drawn in blue, bends and helices in orange with a dot at each start and end and a
    label such as ``B1 90° R0.5 m``; the start and end of the route are marked. The route table
    (:func:`route_table`) is printed beside the axes. The file is written atomically.

    Parameters
    ----------
    conduit : exucable.geometry.Conduit
    path : str or os.PathLike
        Output PNG file; its directory must exist.
    title : str, optional
        Figure title (default "Conduit route").

    Returns
    -------
    pathlib.Path
        The file written.
    """
    c = conduit.centreline
    fig = new_figure(figsize=(10.0, 7.0), dpi=110)
    ax = fig.add_axes((0.0, 0.02, 0.68, 0.90), projection="3d")
    extent = float(np.ptp(np.concatenate([_piece_polyline(p) for p in c.pieces]), axis=0).max()) / per_unit

    all_points = []
    number = 0
    for piece in c.pieces:
        xyz = _piece_polyline(piece) / per_unit
        all_points.append(xyz)
        colour = _CURVED_COLOUR if piece.is_curved else _STRAIGHT_COLOUR
        ax.plot(xyz[:, 0], xyz[:, 1], xyz[:, 2], color=colour, lw=2.2 if piece.is_curved else 1.8)
        if piece.is_curved:
            number += 1
            ends = xyz[[0, -1]]
            ax.scatter(ends[:, 0], ends[:, 1], ends[:, 2], color="k", s=10, depthshade=False)
            # Label a bend at its middle; a helix half a turn in (its middle may sit above the start).
            turns = piece.phi_rad / (2.0 * math.pi)
            u_label = 0.5 * piece.length_m * (min(1.0, 1.0 / turns) if piece.kind == "helix" else 1.0)
            # Set the label off the curve, away from its centre of curvature, so it hides no line.
            outward = -piece.curvature_vector(u_label) / piece.curvature_1_per_m
            # further out with named points, whose names sit at the bend's ends
            at = piece.point(u_label) / per_unit + (0.1 if point_names else 0.07) * extent * outward
            label = _piece_label(number, piece, unit, per_unit)
            if point_names:                 # the tables' name of the bend: "bend 2", not "B2"
                label = "bend " + label[1:].replace(" ", ": ", 1)
            ax.text(at[0], at[1], at[2], label, fontsize=8, color="0.1",
                    ha="center", va="center", bbox=_LABEL_BOX)
    points = np.concatenate(all_points)

    start, end = np.asarray(c.start_m) / per_unit, np.asarray(c.end_m) / per_unit
    ax.scatter(*start, color="tab:green", s=45, marker="o", depthshade=False, zorder=5)
    ax.scatter(*end, color="tab:red", s=45, marker="s", depthshade=False, zorder=5)
    if not point_names:                 # named points say where the route starts and ends themselves
        ax.text(*start, "  start", color="tab:green", fontsize=9, fontweight="bold")
        ax.text(*end, "  end", color="tab:red", fontsize=9, fontweight="bold")

    _equal_box(ax, points)
    if point_names:
        ends = np.array([p.point(np.array([0.0]))[0] for p in c.pieces] + [c.end_m]) / per_unit
        for name, xyz in zip(point_names, ends):
            ax.text(xyz[0], xyz[1], xyz[2], f" {name}", fontsize=9, fontweight="bold", color="0.1")
    ax.set_xlabel(f"x [{unit}]")
    ax.set_ylabel(f"y [{unit}]")
    ax.set_zlabel(f"z [{unit}]")
    ax.tick_params(labelsize=8)
    side = np.diff(np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()]), axis=1).ravel()
    if side[2] < 0.3 * side.max():
        ax.zaxis.set_major_locator(MaxNLocator(nbins=2))  # a flat route's thin box: few, legible ticks
    fig.suptitle(title or "Conduit route", fontsize=12)

    rows = route_table(conduit) + [("inner radius [m]", f"{conduit.inner_radius_m:.4g}")]
    if per_unit != 1.0:
        rows = [("total length", f"{c.length_m / per_unit:.4g} {unit}")] + rows[1:]
    text = "\n".join(f"{label}: {value}" for label, value in rows)
    fig.text(0.69, 0.80, text, fontsize=8.5, va="top", family="monospace",
             bbox=dict(boxstyle="round", facecolor="0.96", edgecolor="0.7"))
    handles = [Line2D([], [], color=_STRAIGHT_COLOUR, lw=1.8, label="straight"),
               Line2D([], [], color=_CURVED_COLOUR, lw=2.2, marker="o", mfc="k", mec="k", ms=3,
                      label="bend / helix (dots: ends)")]
    fig.legend(handles=handles, loc="upper left", bbox_to_anchor=(0.685, 0.56), fontsize=8.5, frameon=False)

    return fig

