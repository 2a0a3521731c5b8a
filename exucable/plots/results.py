"""Figures of one run: pulling and trailing force against time (a steady-mode run: against the static
solve's steps), tension along the cable, sidewall pressure along the conduit."""

from __future__ import annotations

import textwrap

import numpy as np

from ..io import new_figure, save_figure

__all__ = ["plot_pull_force", "plot_tension_profile", "plot_pressure", "pull_force_figure", "tension_profile_figure",
           "pressure_figure", "pull_force_frame", "tension_profile_frame", "pressure_frame", "FRAMES",
           "framed_figure", "fit_frame", "thinned_scatter", "PNG_KWARGS"]

# A fixed layout: margins [in] around the axes, room for y tick labels of up to ~8 characters and the
# y label (left), the x tick labels and x label (bottom). Not ``bbox_inches="tight"``: that lays each
# figure out twice to find its extent (a quarter of its drawing time); only the title's width varies
# enough to need measuring, and measuring one line of text is cheap.
LEFT_IN, RIGHT_IN, BOTTOM_IN = 0.9, 0.3, 0.6
#: The resolution the figures are written at [dpi] (:func:`exucable.io.save_figure`'s default).
SAVE_DPI = 120
#: A title wider than the axes by more than this [in] is wrapped onto more lines instead of widening the figure.
TITLE_OVERHANG_IN = 2.0
#: The title's height in axes coordinates, given: without it matplotlib measures the x axis's tick
#: labels once more at every draw to lift the title clear of labels on top, which these axes never have.
TITLE_Y = 1.0
#: How the figures are encoded: zlib level 1 instead of Pillow's default 6 writes the same pixels in
#: about half the encoding time, for files ~5 % larger (``benchmarks/figure_cost.py``).
PNG_KWARGS = {"pil_kwargs": {"compress_level": 1}}
#: The axes sizes (width, height) [in] of the figures of one run.
PULL_FORCE_AXES_IN, TENSION_AXES_IN, PRESSURE_AXES_IN = (5.425, 4.0), (5.425, 3.08), (6.2, 3.08)
#: The pressure figure's bottom margin [in]: the x label, then the legend (two rows of 7 pt) 0.16
#: axes heights down.
PRESSURE_BOTTOM_IN = 0.16 * 3.08 + 0.45


def _text_width_in(text: str, size_pt: float) -> float:
    """Width [in] of one line of ``text`` in the default font at ``size_pt``, with a margin for hinting."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextToPath

    width_pt = TextToPath().get_text_width_height_descent(text, FontProperties(size=size_pt), ismath=False)[0]
    return 1.04 * width_pt / 72.0


def _wrap_title(title: str, size_pt: float, width_in: float) -> list[str]:
    """``title`` in as few lines as fit ``width_in`` [in], broken between words (a name without
    spaces or hyphens, within it, if it must)."""
    for breaking in (False, True):
        for chars in range(len(title), 10, -max(1, len(title) // 40)):
            lines = textwrap.wrap(title, chars, break_long_words=breaking) or [""]
            if max(_text_width_in(line, size_pt) for line in lines) <= width_in:
                return lines
    return textwrap.wrap(title, 10) or [""]


def fit_frame(fig, axes_in: tuple[float, float], title: str, title_pt: float, bottom_in: float = BOTTOM_IN) -> str:
    """Size ``fig`` so that its subplot area is ``axes_in`` (width, height) [in], with the fixed
    margins and room above for ``title`` (at ``title_pt`` points), centred on the axes as matplotlib
    places it. A title wider than the axes widens both side margins to hold it (as a tight bounding
    box would), up to :data:`TITLE_OVERHANG_IN`; a wider one is wrapped. The axes may exist already
    (positions are fractions of the figure, applied when it is drawn). Returns the title's text
    (lines joined), to be set with ``fontsize=title_pt``."""
    import matplotlib

    w_axes, h_axes = axes_in
    lines = _wrap_title(title, title_pt, w_axes + TITLE_OVERHANG_IN)
    half_extra = max(max(_text_width_in(line, title_pt) for line in lines) - w_axes, 0.0) / 2 + 0.1
    left, right = max(LEFT_IN, half_extra), max(RIGHT_IN, half_extra)
    pad_in = matplotlib.rcParams["axes.titlepad"] / 72.0
    top = 0.1 + pad_in + len(lines) * 1.25 * title_pt / 72.0
    w, h = left + w_axes + right, bottom_in + h_axes + top
    fig.set_size_inches(w, h)
    fig.subplots_adjust(left=left / w, right=1.0 - right / w, bottom=bottom_in / h, top=1.0 - top / h)
    return "\n".join(lines)


def framed_figure(axes_in: tuple[float, float], title: str, title_pt: float, bottom_in: float = BOTTOM_IN):
    """A new figure sized by :func:`fit_frame`; returns it and the title's text."""
    fig = new_figure()
    return fig, fit_frame(fig, axes_in, title, title_pt, bottom_in)


def _prime_ticks(axes, ticks: int) -> None:
    """Create ``ticks`` major ticks on each axis of ``axes`` now, not while drawing. A tick is five
    artists (a fifth of a figure's drawing time goes into making them); matplotlib draws only as
    many as there are tick locations and makes more if needed, so the picture does not change."""
    if ticks > 0:
        for ax in np.atleast_1d(axes):
            ax.xaxis.get_major_ticks(ticks)
            ax.yaxis.get_major_ticks(ticks)


def pull_force_frame(ticks: int = 0):
    """The pulling-force figure before any data: a figure and its two axes (pulling force above,
    trailing tension below, sharing x), ``ticks`` major ticks made on each axis ahead. Sized when
    drawn (:func:`pull_force_figure`)."""
    fig = new_figure()
    axes = fig.subplots(2, 1, sharex=True, gridspec_kw=dict(height_ratios=(2.3, 1.0)))
    _prime_ticks(axes, ticks)
    return fig, tuple(axes)


def _one_axes_frame(ticks: int = 0):
    fig = new_figure()
    ax = fig.subplots()
    _prime_ticks(ax, ticks)
    return fig, ax


def tension_profile_frame(ticks: int = 0):
    """The tension figure before any data: a figure and its axes, ``ticks`` major ticks made on each
    axis ahead."""
    return _one_axes_frame(ticks)


def pressure_frame(ticks: int = 0):
    """The pressure figure before any data: a figure and its axes, ``ticks`` major ticks made on each
    axis ahead."""
    return _one_axes_frame(ticks)


#: Each figure's file name and the function making its frame, for a process that builds the frames
#: before the results exist (:mod:`exucable.output.figure_process`).
FRAMES = {"pull_force.png": pull_force_frame, "tension_profile.png": tension_profile_frame,
          "pressure.png": pressure_frame}


def _zoom(values: np.ndarray, centre: float, references, spread: float) -> tuple[float, float]:
    """A y-range around ``centre`` wide enough for the scatter ``spread`` and every reference, at
    least ±0.5 % of the centre: the pulling force's scatter and its gap to the rope stay visible
    instead of being flattened by the start-up's range."""
    half = max(4.0 * spread, 0.005 * abs(centre), 1e-9)
    for r in references:
        half = max(half, 1.25 * abs(r - centre))
    return centre - half, centre + half


def thinned_scatter(x, y, y_range: tuple[float, float], size_px: tuple[float, float], most: int = 20_000):
    """The points of a scatter drawn as single pixels, at most one per half pixel of an axes
    ``size_px`` (width, height) [px] whose y-axis spans ``y_range`` (the x-axis spans at least the
    points). Up to ``most`` points are kept as they are; beyond, most fall on pixels already drawn (a
    10 km run has ~10^6 check points for ~750 pixel columns), and drawing them again costs time and
    changes only how dark the overlaps are. Points outside ``y_range`` keep one each side."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if x.size <= most:
        return x, y
    ok = np.isfinite(x) & np.isfinite(y)
    x, y = x[ok], y[ok]
    if x.size == 0:
        return x, y
    nx, ny = 2 * int(np.ceil(size_px[0])), 2 * int(np.ceil(size_px[1]))
    ix = np.floor((x - x.min()) / max(float(x.max() - x.min()), 1e-300) * nx).astype(np.int64)
    iy = np.floor((y - y_range[0]) / max(y_range[1] - y_range[0], 1e-300) * ny)
    iy = np.clip(iy, -1, ny).astype(np.int64) + 1
    # one point per occupied cell: each cell keeps the index written into it last (a linear pass,
    # no sort of 10^6 keys)
    cell = np.full((nx + 1) * (ny + 2), -1, dtype=np.int64)
    cell[ix * (ny + 2) + iy] = np.arange(x.size)
    kept = cell[cell >= 0]
    return x[kept], y[kept]


def plot_pull_force(path, result, frame=None) -> None:
    """:func:`pull_force_figure` written to ``path`` (atomically, :func:`exucable.io.save_figure`)."""
    save_figure(pull_force_figure(result, frame), path, dpi=SAVE_DPI, **PNG_KWARGS)


def pull_force_figure(result, frame=None):
    """Pulling force [N] on a scale that shows its scatter and its gap to the rope references (top),
    trailing tension [N] below it. A dynamic run is drawn against time [s] with its steady window; a
    steady-mode run is one static state, drawn against the static solve's steps (no time axis), its
    converged force marked. ``frame``: a :func:`pull_force_frame` to draw on (default: a new one).
    Returns the figure."""
    h, s = result.history, result.summary
    steady_mode = s.get("mode") == "steady"
    x = np.asarray(h["time_s"], dtype=float)
    pull_h = np.asarray(h["pull_force_N"], dtype=float)
    pull = s.get("pull_force_N")
    status = "" if s.get("status") in ("ok", "steady") else f" (status {s.get('status')})"
    if s.get("status") == "failed":
        status = f" (FAILED at t = {s.get('failed_at_s', float('nan')):.4g} s)"
    what = "steady sliding state, pulling force" if steady_mode else "pulling force"
    fig, (ax, low) = frame or pull_force_frame()
    title = fit_frame(fig, PULL_FORCE_AXES_IN, f"{s.get('name', '')}: {what} "
                      f"{'n/a' if pull is None else format(pull, '.5g')} N{status}", 10)
    ax.plot(x, pull_h, ".-" if steady_mode else "-", ms=3, lw=1.2, label="pulling force (leading end)")
    refs = []
    for key, style, what in (("rope_pull_force_N", "--", "rope reference"),
                             ("rope_clearance_pull_force_N", ":", "rope free in its clearance")):
        value = s.get(key)
        if value is not None:
            refs.append(value)
            ax.axhline(value, color="k", ls=style, lw=1, label=f"{what} {value:.5g} N")
    t0 = s.get("steady_from_s")
    spread = 0.0
    if not steady_mode and s.get("steady") and t0 is not None:
        ax.axvspan(t0, x[-1], color="g", alpha=0.08, label="steady window")
        window = pull_h[x >= t0]
        spread = float(np.std(window)) if window.size else 0.0
    u = s.get("pull_force_uncertainty_N")
    if pull is not None and np.isfinite(pull):
        band = f" ± {u:.2g} N" if u is not None else ""
        ax.axhline(pull, color="tab:blue", lw=0.8, alpha=0.7,
                   label=f"{'steady state' if steady_mode else 'mean over the window'} {pull:.5g} N{band}")
        if u is not None and not steady_mode and t0 is not None:
            ax.fill_between([t0, x[-1]], pull - u, pull + u, color="tab:blue", alpha=0.15, lw=0)
        ax.set_ylim(*_zoom(pull_h, pull, refs, max(spread, u or 0.0)))
    trail = np.asarray(h["trailing_tension_N"], dtype=float)
    low.plot(x, trail, color="tab:orange", lw=1.2, label="trailing-end tension")
    finite = trail[np.isfinite(trail)]
    if finite.size:
        # a prescribed back tension is flat: show it as such, not its round-off magnified by an offset axis
        low.set_ylim(*_zoom(finite, float(np.median(finite)), [float(finite.min()), float(finite.max())], 0.0))
    low.ticklabel_format(axis="y", useOffset=False, style="plain")
    low.set_ylabel("force [N]")
    low.legend(loc="best", fontsize=7)
    low.grid(alpha=0.3)
    low.set_xlabel("static solve step (one steady state: no time axis)" if steady_mode else "time [s]")
    ax.ticklabel_format(axis="y", useOffset=False, style="plain")
    ax.set_ylabel("pulling force [N]")
    ax.set_title(title, fontsize=10, y=TITLE_Y)
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=7)
    return fig


def plot_tension_profile(path, result, frame=None) -> None:
    """:func:`tension_profile_figure` written to ``path`` (atomically)."""
    save_figure(tension_profile_figure(result, frame), path, dpi=SAVE_DPI, **PNG_KWARGS)


def tension_profile_figure(result, frame=None):
    """Tension [N] along the cable (arc length from the trailing end [m]) at the final time,
    beside the rope reference. ``frame``: a :func:`tension_profile_frame` to draw on (default: a new
    one). Returns the figure."""
    p = result.tension_profile
    fig, ax = frame or tension_profile_frame()
    cables = getattr(result, "cable_tensions", None)
    what = "tension along the cable" if cables is None else "tension along the cables"
    title = fit_frame(fig, TENSION_AXES_IN, f"{result.summary.get('name', '')}: {what}", 12)
    if cables is None:
        ax.plot(p["x_m"], p["tension_N"], ".-", ms=3, label="exucable (N from the equilibrium of its loads)")
    else:
        # several cables: the bundle's (their sum, the pull at the eye) and each cable's share beside it
        names = [k for k in cables if k != "x_m"]
        ax.plot(p["x_m"], p["tension_N"], ".-", ms=3,
                label=f"bundle: sum of the {len(names)} cables (N from the equilibrium of their loads)")
        for k in names:
            ax.plot(cables["x_m"], cables[k], "-", lw=1, alpha=0.8,
                    label=k.replace("_tension_N", "").replace("_", " "))
    rp = result.rope_profile
    if rp is not None and "x_m" in result.extras:
        ax.plot(result.extras["x_m"], rp["tension_N"], "k--", lw=1, label="rope reference")
    ax.set_xlabel("x: material coordinate from the trailing end [m]")
    ax.set_ylabel("tension [N]")
    ax.set_title(title, fontsize=12, y=TITLE_Y)
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8 if cables is None else 7)
    return fig


def plot_pressure(path, result, frame=None) -> None:
    """:func:`pressure_figure` written to ``path`` (atomically)."""
    save_figure(pressure_figure(result, frame), path, dpi=SAVE_DPI, **PNG_KWARGS)


def pressure_figure(result, frame=None):
    """Sidewall bearing pressure [N/m] along the conduit: the check points' raw values (faint),
    the windowed pressure and the rope's, windowed alike; bends shaded, point loads marked [N].
    ``frame``: a :func:`pressure_frame` to draw on (default: a new one). Returns the figure."""
    pp, s = result.pressure_profile, result.summary
    fig, ax = frame or pressure_frame()
    title = fit_frame(fig, PRESSURE_AXES_IN, f"{s.get('name', '')}: sidewall pressure (bends shaded; point loads "
                      "at bend ends)", 12, bottom_in=PRESSURE_BOTTOM_IN)
    top = 1.6 * max(float(np.max(pp["windowed_pressure_N_per_m"])), float(np.max(pp["rope_windowed_pressure_N_per_m"])), 1e-9)
    cp = result.contact_profile
    if cp is not None:
        size_px = (PRESSURE_AXES_IN[0] * SAVE_DPI, PRESSURE_AXES_IN[1] * SAVE_DPI)
        ax.plot(*thinned_scatter(cp["s_conduit_m"], cp["normal_force_per_length_N_per_m"], (0.0, top), size_px),
                ",", color="0.6", alpha=0.5, label="check points (force / element share)")
    ax.plot(pp["s_conduit_m"], pp["windowed_pressure_N_per_m"], lw=1.8,
            label=f"exucable, windowed over {s.get('pressure_window_m', float('nan')):.3g} m")
    ax.plot(pp["s_conduit_m"], pp["rope_windowed_pressure_N_per_m"], "k--", lw=1, label="rope (T/R and weight), windowed")
    loads = []
    for b in result.bends or []:
        ax.axvspan(b["s_conduit_start_m"], b["s_conduit_end_m"], color="b", alpha=0.05)
        for end in ("entry", "exit"):
            F = b[f"{end}_point_load_N"]
            if np.isfinite(F):
                loads.append((b[f"{end}_s_conduit_m"], F))
    # labels alternate between two heights, so that a bend's entry and exit labels (and a short bend's
    # neighbours) do not overprint each other; the legend goes below the axes, clear of them
    for k, (where, F) in enumerate(sorted(loads)):
        ax.annotate(f"{F:+.3g} N", (where, (0.62 if k % 2 == 0 else 0.84) * top), fontsize=7, ha="center",
                    va="center", rotation=90, bbox=dict(facecolor="white", alpha=0.8, edgecolor="none", pad=0.5))
    ax.set_ylim(0, top)
    ax.set_xlabel("s along the conduit [m]")
    ax.set_ylabel("sidewall bearing pressure [N/m]")
    ax.set_title(title, fontsize=12, y=TITLE_Y)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, fontsize=7, frameon=False)
    return fig
