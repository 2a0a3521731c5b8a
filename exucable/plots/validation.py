"""The validation figures, one per figure of the paper they reproduce."""

from __future__ import annotations

import numpy as np

from ..io import new_figure, save_figure
from ..data.reference_values import load_reference

__all__ = ["plot_validation_figures"]


def _ends_against_time(ax, res, title):
    h = res.history
    ax.plot(h["time_s"], h["pull_force_N"], label="T1 (leading end)")
    ax.plot(h["time_s"], h["trailing_tension_N"], label="T2 (trailing end)")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("tension [N]")
    ax.set_title(title)
    ax.grid(alpha=0.3)


def plot_validation_figures(vr, out, ref: dict | None = None) -> list:
    """Write fig07 … fig14 PNGs for the cases present in ``vr``; returns their paths.

    Parameters
    ----------
    vr : exucable.validation.paper.ValidationRun
        Its ``runs`` (case → result) and ``sweep_rows`` (Fig. 12).
    out : pathlib.Path
        Directory to write into.
    ref : dict, optional
        Reference values as :func:`exucable.data.reference_values.load_reference` returns them (read if not given).
    """
    ref = load_reference() if ref is None else ref
    written = []
    r = vr.runs.get("Ex. 1")
    if r is not None:
        fig = new_figure(figsize=(7, 4))
        ax = fig.subplots()
        x = np.asarray(r.tension_profile["x_m"])
        ax.plot(x, r.tension_profile["tension_N"], ".", ms=3, label="exucable")
        xs = np.linspace(0, x.max(), 50)
        ax.plot(xs, ref["example1"]["tension_slope_N_per_m"] * xs, "k-", lw=1, label="Eq. 25")
        ax.set_xlabel("x from the lower (free) end [m]")
        ax.set_ylabel("tension [N]")
        ax.set_title("Fig. 7: tension along the 30° incline (Example 1)")
        ax.grid(alpha=0.3)
        ax.legend()
        save_figure(fig, out / "fig07_ex1_tension_along_incline.png", bbox_inches="tight")
        written.append(out / "fig07_ex1_tension_along_incline.png")
    for case, name, title, refline in (
            ("Ex. 2", "fig09_ex2_end_tensions.png", "Fig. 9: end tensions, 90° bend (Example 2)",
             ("T1 capstan", ref["example2"]["pull_force_N"])),
            ("Ex. 3", "fig11_ex3_end_tensions.png", "Fig. 11: end tensions, helix (Example 3)",
             ("T2 capstan", ref["example3"]["back_tension_N"]))):
        r = vr.runs.get(case)
        if r is None:
            continue
        fig = new_figure(figsize=(7, 4))
        ax = fig.subplots()
        _ends_against_time(ax, r, title)
        ax.axhline(refline[1], color="k", ls="--", lw=1, label=f"{refline[0]} {refline[1]:.5g} N")
        ax.legend(fontsize=8)
        save_figure(fig, out / name, bbox_inches="tight")
        written.append(out / name)
    if vr.sweep_rows:
        key = next(k for k in vr.sweep_rows[0] if k.endswith("helix_turns"))
        n = np.array([float(row[key]) for row in vr.sweep_rows])
        F = np.array([float(row["pull_force_N"]) if row.get("status") in ("ok", "steady") else np.nan
                      for row in vr.sweep_rows])
        order = np.argsort(n)
        fig = new_figure(figsize=(7, 4))
        ax = fig.subplots()
        nn = np.linspace(0.5, n.max() + 0.5, 100)
        coils = np.asarray(ref["fig12"]["coils"], dtype=float)
        law = np.asarray(ref["fig12"]["pull_force_N"], dtype=float)
        # the law 10 e^(0.1 β(n)), β linear in n: interpolate its logarithm
        rate = np.polyfit(coils, np.log(law), 1)
        ax.semilogy(nn, np.exp(np.polyval(rate, nn)), "k-", lw=1, label="10·e^(0.1·β(n))")
        ax.semilogy(n[order], F[order], "o", label="exucable")
        ax.set_xlabel("number of coils")
        ax.set_ylabel("pulling force T1 [N]")
        ax.set_title("Fig. 12: pulling force against coils (T2 = 10 N, μ = 0.1)")
        ax.grid(alpha=0.3, which="both")
        ax.legend()
        save_figure(fig, out / "fig12_coils.png", bbox_inches="tight")
        written.append(out / "fig12_coils.png")
    r = vr.runs.get("Ex. 4")
    if r is not None:
        fig = new_figure(figsize=(7, 4))
        ax = fig.subplots()
        h = r.history
        ax.plot(h["time_s"], h["pull_force_N"], label="exucable")
        rope = r.summary.get("rope_pull_force_N")
        if rope is not None:
            ax.axhline(rope, color="k", ls="--", lw=1, label=f"rope solution {rope:.5g} N")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("pulling force [N]")
        ax.set_title("Fig. 14: pulling force, spatial conduit (Example 4)")
        ax.grid(alpha=0.3)
        ax.legend()
        save_figure(fig, out / "fig14_ex4_pull_force.png", bbox_inches="tight")
        written.append(out / "fig14_ex4_pull_force.png")
    return written


def plot_industry(iv, path):
    """Bars per industry example and mode, relative to the published value: the centreline rope, the
    rope with clearance and exucable (with the published rounding bound as a band)."""
    fig = new_figure(figsize=(9.0, 4.5), layout="constrained")
    ax = fig.subplots()
    rows = iv.rows
    x = np.arange(len(rows))
    bound = np.array([100 * r.published_bound_N / r.published_N for r in rows])
    ax.bar(x, 2 * bound, bottom=-bound, width=0.9, color="0.9", label="published ± its rounding bound")
    series = [("centreline rope", [r.rope_N for r in rows]),
              ("rope with clearance", [r.run_rope_clearance_N for r in rows]),
              ("exucable (default mesh)", [r.value_N for r in rows])]
    for k, (label, vals) in enumerate(series):
        rel = [100 * (v / r.published_N - 1) if v is not None else np.nan for v, r in zip(vals, rows)]
        ax.bar(x + (k - 1) * 0.25, rel, width=0.25, label=label)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xticks(x, [f"{r.example.replace('_', ' ')}\n({r.mode})" for r in rows], fontsize=7, rotation=12,
                  ha="right")
    ax.set_ylabel("pulling force vs published [%]")
    ax.set_title("Industry worked pulls (exucable validate --suite industry)")
    ax.legend(fontsize=7)
    return save_figure(fig, path)
