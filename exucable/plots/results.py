"""Figures of one run: pulling and trailing force against time, tension along the cable."""

from __future__ import annotations

from ..io import new_figure, save_figure

__all__ = ["plot_pull_force", "plot_tension_profile"]


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
    status = "" if s.get("status") != "failed" else f" (FAILED at t = {s.get('failed_at_s', float('nan')):.4g} s)"
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
    ax.plot(p["x_m"], p["tension_N"], ".-", ms=3, label="exucable (N = EA·ε)")
    rp = result.rope_profile
    if rp is not None and "x_m" in result.extras:
        ax.plot(result.extras["x_m"], rp["tension_N"], "k--", lw=1, label="rope reference")
    ax.set_xlabel("x: material coordinate from the trailing end [m]")
    ax.set_ylabel("tension [N]")
    ax.set_title(f"{result.summary.get('name', '')}: tension along the cable")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    save_figure(fig, path, bbox_inches="tight")
