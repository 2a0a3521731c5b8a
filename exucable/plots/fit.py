"""Figures of a friction fit: the log beside the prediction band, and the residuals."""

from __future__ import annotations

import numpy as np

from ..io import new_figure, save_figure

__all__ = ["plot_fit_band", "plot_fit_residuals"]


def plot_fit_band(path, fit, title: str = "", force_factor: float = 1.0, force_unit: str = "N",
                  length_factor: float = 1.0, length_unit: str = "m", left_out=None) -> None:
    """Head tension against pulled length: the log's used and left-out readings, the model at the fitted
    friction, the band of its 95 % interval and the band where 95 % of readings should fall; for a
    partial log the forecast to the end; ``left_out``: (pulled length [m], reading [N]) of the readings
    left out as stops and spikes. Values are divided by ``force_factor`` / ``length_factor`` (SI per
    display unit) for display."""
    c = fit.curve
    X = np.asarray(c["pulled_length_m"]) / length_factor
    fig = new_figure(figsize=(8, 4.5))
    ax = fig.subplots()
    ax.fill_between(X, np.asarray(c["reading_low_N"]) / force_factor, np.asarray(c["reading_high_N"]) / force_factor,
                    color="tab:blue", alpha=0.12, lw=0, label="95 % of readings (friction band + scatter)")
    ax.fill_between(X, np.asarray(c["low_N"]) / force_factor, np.asarray(c["high_N"]) / force_factor,
                    color="tab:blue", alpha=0.35, lw=0,
                    label=f"friction {fit.friction_interval[0]:.3f}–{fit.friction_interval[1]:.3f} (95 %)")
    ax.plot(X, np.asarray(c["pull_force_N"]) / force_factor, color="tab:blue", lw=1.5,
            label=f"rope, fitted friction {fit.friction:.3f}")
    ax.plot(np.asarray(fit.pulled_length_m) / length_factor, np.asarray(fit.pull_force_N) / force_factor, ".",
            ms=2.5, color="k", label="log (used)")
    if left_out is not None and len(left_out[0]):
        ax.plot(np.asarray(left_out[0]) / length_factor, np.asarray(left_out[1]) / force_factor, "x", ms=3,
                color="tab:gray", label="left out (stops, spikes)")
    if fit.forecast is not None:
        f = fit.forecast
        fx = np.asarray(f["pulled_length_m"]) / length_factor
        ax.plot(fx, np.asarray(f["pull_force_N"]) / force_factor, color="tab:red", lw=2, label="forecast")
        ax.axvline(fx[0], color="tab:red", ls=":", lw=1)
    top = float(np.max(c["reading_high_N"])) / force_factor
    for lim in fit.expected.get("limits", []):
        if lim["name"] == "max_sidewall_pressure":
            continue
        value = lim["limit"] / force_factor
        if value <= 1.5 * top:      # a far-off limit would squash the log into the bottom of the figure
            ax.axhline(value, color="tab:orange", ls="--", lw=1, label=f"limit {lim['name']}")
        else:
            ax.plot([], [], " ", label=f"limit {lim['name']} {value:.4g} {force_unit} (off scale)")
    ax.set_xlabel(f"pulled length [{length_unit}]")
    ax.set_ylabel(f"head tension [{force_unit}]")
    verdict = "" if fit.one_coefficient.get("explains", True) else " — one coefficient does NOT explain the log"
    ax.set_title(f"{title}{': ' if title else ''}friction {fit.friction:.3f} "
                 f"[{fit.friction_interval[0]:.3f}, {fit.friction_interval[1]:.3f}]{verdict}", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", fontsize=7)
    save_figure(fig, path, bbox_inches="tight")


def plot_fit_residuals(path, fit, force_factor: float = 1.0, force_unit: str = "N", length_factor: float = 1.0,
                       length_unit: str = "m") -> None:
    """Residuals (reading − model at the fitted friction) against pulled length, with the split of the
    one-coefficient test and the halves' friction."""
    fig = new_figure(figsize=(8, 3.2))
    ax = fig.subplots()
    x = np.asarray(fit.pulled_length_m) / length_factor
    ax.plot(x, np.asarray(fit.residual_N) / force_factor, ".", ms=2.5, color="k")
    ax.axhline(0.0, color="tab:blue", lw=1)
    one = fit.one_coefficient
    if one.get("p_value") is not None:
        ax.axvline(one["split_pulled_length_m"] / length_factor, color="tab:gray", ls=":", lw=1)
        ax.set_title(f"residuals; halves' friction {one['first_half_friction']:.3f} | {one['second_half_friction']:.3f} "
                     f"(p = {one['p_value']:.3g}{', differ' if not one['explains'] else ''})", fontsize=10)
    ax.set_xlabel(f"pulled length [{length_unit}]")
    ax.set_ylabel(f"reading − model [{force_unit}]")
    ax.grid(alpha=0.3)
    save_figure(fig, path, bbox_inches="tight")
