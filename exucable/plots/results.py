"""Figures of one run: pulling and trailing force against time, tension along the cable."""

from __future__ import annotations

import numpy as np

from ..io import new_figure, save_figure

__all__ = ["plot_pull_force", "plot_tension_profile", "plot_pressure"]


def plot_pull_force(path, result) -> None:
    """Pulling force and trailing tension [N] against time [s], with the steady window and the
    rope reference when there is one."""
    h, s = result.history, result.summary
    fig = new_figure(figsize=(7, 4))
    ax = fig.subplots()
    ax.plot(h["time_s"], h["pull_force_N"], label="pulling force (leading end)")
    ax.plot(h["time_s"], h["trailing_tension_N"], label="trailing-end tension")
    rope = s.get("rope_pull_force_N")
    if rope is not None:
        ax.axhline(rope, color="k", ls="--", lw=1, label=f"rope reference {rope:.4g} N")
    t0 = s.get("steady_from_s")
    if s.get("steady") and t0 is not None:
        ax.axvspan(t0, h["time_s"][-1], color="g", alpha=0.08, label="steady window")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("force [N]")
    pull = s.get("pull_force_N")
    status = "" if s.get("status") in ("ok", "steady") else f" (status {s.get('status')})"
    if s.get("status") == "failed":
        status = f" (FAILED at t = {s.get('failed_at_s', float('nan')):.4g} s)"
    ax.set_title(f"{s.get('name', '')}: pulling force "
                 f"{'n/a' if pull is None else format(pull, '.4g')} N{status}")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    save_figure(fig, path, bbox_inches="tight")


def plot_tension_profile(path, result) -> None:
    """Tension [N] along the cable (arc length from the trailing end [m]) at the final time,
    beside the rope reference."""
    p = result.tension_profile
    fig = new_figure(figsize=(7, 4))
    ax = fig.subplots()
    ax.plot(p["x_m"], p["tension_N"], ".-", ms=3, label="exucable (N from the equilibrium of its loads)")
    rp = result.rope_profile
    if rp is not None and "x_m" in result.extras:
        ax.plot(result.extras["x_m"], rp["tension_N"], "k--", lw=1, label="rope reference")
    ax.set_xlabel("x: material coordinate from the trailing end [m]")
    ax.set_ylabel("tension [N]")
    ax.set_title(f"{result.summary.get('name', '')}: tension along the cable")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    save_figure(fig, path, bbox_inches="tight")


def plot_pressure(path, result) -> None:
    """Sidewall bearing pressure [N/m] along the conduit: the check points' raw values (faint),
    the windowed pressure and the rope's, windowed alike; bends shaded, point loads marked [N]."""
    pp, s = result.pressure_profile, result.summary
    fig = new_figure(figsize=(8, 4))
    ax = fig.subplots()
    cp = result.contact_profile
    if cp is not None:
        ax.plot(cp["s_conduit_m"], cp["normal_force_per_length_N_per_m"], ",", color="0.6", alpha=0.5,
                label="check points (force / element share)")
    ax.plot(pp["s_conduit_m"], pp["windowed_pressure_N_per_m"], lw=1.8,
            label=f"exucable, windowed over {s.get('pressure_window_m', float('nan')):.3g} m")
    ax.plot(pp["s_conduit_m"], pp["rope_windowed_pressure_N_per_m"], "k--", lw=1, label="rope (T/R and weight), windowed")
    top = 1.6 * max(float(np.max(pp["windowed_pressure_N_per_m"])), float(np.max(pp["rope_windowed_pressure_N_per_m"])), 1e-9)
    for b in result.bends or []:
        ax.axvspan(b["s_conduit_start_m"], b["s_conduit_end_m"], color="b", alpha=0.05)
        for end in ("entry", "exit"):
            F = b[f"{end}_point_load_N"]
            if np.isfinite(F):
                ax.annotate(f"{F:+.3g} N", (b[f"{end}_s_conduit_m"], 0.72 * top), fontsize=7, ha="center", rotation=90)
    ax.set_ylim(0, top)
    ax.set_xlabel("s along the conduit [m]")
    ax.set_ylabel("sidewall bearing pressure [N/m]")
    ax.set_title(f"{s.get('name', '')}: sidewall pressure (bends shaded; point loads at bend ends)")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    save_figure(fig, path, bbox_inches="tight")
