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

__all__ = ["plot_route", "route_table"]

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


def _piece_label(number: int, piece) -> str:
    angle = f"{math.degrees(piece.turning_angle_rad):.0f}°"
    if piece.kind == "helix":
        turns = piece.phi_rad / (2.0 * math.pi)
        return f"B{number} helix {turns:.3g} turns {angle} a{piece.radius_m:.3g} m p{abs(piece.pitch_m):.3g} m"
    return f"B{number} {angle} R{piece.radius_m:.3g} m"


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


def plot_route(conduit, path, title: str | None = None) -> Path:
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
    out = Path(path)
    c = conduit.centreline
    fig = new_figure(figsize=(10.0, 7.0), dpi=110)
    ax = fig.add_axes((0.0, 0.02, 0.68, 0.90), projection="3d")
    extent = float(np.ptp(np.concatenate([_piece_polyline(p) for p in c.pieces]), axis=0).max())

    all_points = []
    number = 0
    for piece in c.pieces:
        xyz = _piece_polyline(piece)
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
            at = piece.point(u_label) + 0.07 * extent * outward
            ax.text(at[0], at[1], at[2], _piece_label(number, piece), fontsize=8, color="0.1",
                    ha="center", va="center", bbox=_LABEL_BOX)
    points = np.concatenate(all_points)

    start, end = c.start_m, c.end_m
    ax.scatter(*start, color="tab:green", s=45, marker="o", depthshade=False, zorder=5)
    ax.scatter(*end, color="tab:red", s=45, marker="s", depthshade=False, zorder=5)
    ax.text(*start, "  start", color="tab:green", fontsize=9, fontweight="bold")
    ax.text(*end, "  end", color="tab:red", fontsize=9, fontweight="bold")

    _equal_box(ax, points)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.tick_params(labelsize=8)
    side = np.diff(np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()]), axis=1).ravel()
    if side[2] < 0.3 * side.max():
        ax.zaxis.set_major_locator(MaxNLocator(nbins=2))  # a flat route's thin box: few, legible ticks
    fig.suptitle(title or "Conduit route", fontsize=12)

    rows = route_table(conduit) + [("inner radius [m]", f"{conduit.inner_radius_m:.4g}")]
    text = "\n".join(f"{label}: {value}" for label, value in rows)
    fig.text(0.69, 0.80, text, fontsize=8.5, va="top", family="monospace",
             bbox=dict(boxstyle="round", facecolor="0.96", edgecolor="0.7"))
    handles = [Line2D([], [], color=_STRAIGHT_COLOUR, lw=1.8, label="straight"),
               Line2D([], [], color=_CURVED_COLOUR, lw=2.2, marker="o", mfc="k", mec="k", ms=3,
                      label="bend / helix (dots: ends)")]
    fig.legend(handles=handles, loc="upper left", bbox_to_anchor=(0.685, 0.56), fontsize=8.5, frameon=False)

    save_figure(fig, out, dpi=None)
    return out

