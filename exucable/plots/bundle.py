"""Cross-sections of a bundle run: the duct's circle, each cable's circle where its axis crosses
a plane across the conduit, and marks where a cable touches the wall or another cable."""

from __future__ import annotations

import math

import numpy as np

from ..io import new_figure, save_figure

__all__ = ["plot_cross_sections"]


def plot_cross_sections(path, panels, inner_radius_m: float, cable_radius_m: float, title: str = "") -> None:
    """One panel per place along the route, looking along the pull.

    Parameters
    ----------
    path : path-like
        The PNG to write (atomically, :func:`exucable.io.save_figure`).
    panels : sequence of dict
        Each with ``s_conduit_m`` [m], ``label`` (str: the section and its arrangement),
        ``offsets_m`` (n_cables, 2: horizontal, up from the duct's axis [m]; NaN rows are left out),
        ``on_wall`` (per cable, bool), ``touching`` (1-based pairs) and ``wedged`` (bool).
    inner_radius_m, cable_radius_m : float
        R and r [m]; drawn in mm.
    """
    n = max(1, len(panels))
    cols = min(n, 4)
    rows = math.ceil(n / cols)
    fig = new_figure(figsize=(max(3.1 * cols, 5.0), 3.4 * rows + 0.7))
    axes = np.atleast_1d(fig.subplots(rows, cols)).reshape(-1)
    R, r = 1e3 * inner_radius_m, 1e3 * cable_radius_m
    colours = ["tab:blue", "tab:orange", "tab:green", "tab:purple"]
    from matplotlib.patches import Circle

    for ax, panel in zip(axes, panels):
        ax.add_patch(Circle((0, 0), R, fill=False, lw=1.5, color="0.2"))
        p = 1e3 * np.asarray(panel["offsets_m"], dtype=float)
        for k, (x, y) in enumerate(p):
            if not np.isfinite(x):
                continue
            ax.add_patch(Circle((x, y), r, color=colours[k % len(colours)], alpha=0.55, lw=1))
            ax.annotate(str(k + 1), (x, y), ha="center", va="center", fontsize=9)
            if panel["on_wall"][k]:
                u = np.array([x, y]) / max(math.hypot(x, y), 1e-12)
                ax.plot(*(R * u), "kx", ms=7, mew=2)
        for i, j in panel["touching"]:
            a, b = p[i - 1], p[j - 1]
            ax.plot(*(0.5 * (a + b)), "r+", ms=8, mew=2)
        ax.set_xlim(-1.1 * R, 1.1 * R)
        ax.set_ylim(-1.1 * R, 1.1 * R)
        ax.set_aspect("equal")
        ax.set_title(f"s = {panel['s_conduit_m']:.3g} m\n{panel['label']}" + ("  JAM" if panel["wedged"] else ""),
                     fontsize=9, color="red" if panel["wedged"] else "black")
        ax.set_xlabel("horizontal [mm]", fontsize=8)
        ax.set_ylabel("up [mm]", fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in axes[len(panels):]:
        ax.set_visible(False)
    fig.suptitle((title + ": " if title else "") + "cables across the duct, looking along the pull\n"
                 "(× touches the wall, + two cables touch)", fontsize=10)
    fig.tight_layout()
    save_figure(fig, path)
