"""A friction sweep in Python: one Scenario, friction varied, pulling force against the capstan law.

``xc.vary`` runs the cases one after another and returns (parameters, Result) pairs; for many
cases in parallel with results on disk, use ``exucable sweep`` with a sweep file.
The figure is drawn on a matplotlib ``Figure`` of its own (no pyplot, the backend is untouched).
"""

import math
import sys

import numpy as np
from matplotlib.figure import Figure

import exucable as xc


def main(frictions=(0.0, 0.1, 0.2, 0.3, 0.4), end_time=0.5, out="friction_sweep.png"):
    route = xc.Route(inner_radius=3.5e-3).straight(1.0).bend(90, radius=0.5, turn="left").straight(1.0)
    base = xc.Scenario(route=route, cable=xc.Cable(radius=2.5e-3, density=1000.0, youngs_modulus=1e9),
                       pull=xc.Pull(speed=0.1, back_tension=150.0), solver=xc.Solver(end_time=end_time))
    runs = xc.vary(base, {"contact.friction": list(frictions)})
    mu = np.array([p["contact.friction"] for p, _ in runs])
    force = np.array([r.pull_force_N for _, r in runs])
    error = np.array([r.pull_force_uncertainty_N for _, r in runs])
    capstan = 150.0 * np.exp(mu * math.pi / 2)

    fig = Figure(figsize=(5, 3.5), layout="constrained")
    ax = fig.add_subplot()
    grid = np.linspace(0.0, max(frictions), 100)
    ax.plot(grid, 150.0 * np.exp(grid * math.pi / 2), "k-", lw=1, label="capstan T2·exp(μθ)")
    ax.errorbar(mu, force, yerr=error, fmt="o", label="exucable")
    ax.set_xlabel("friction coefficient μ [-]")
    ax.set_ylabel("pulling force [N]")
    ax.legend()
    fig.savefig(out, dpi=120)
    for m, f, c in zip(mu, force, capstan):
        print(f"mu = {m:.2f}: {f:8.3f} N, capstan {c:8.3f} N ({100 * (f / c - 1):+.3f} %)")
    print(f"figure: {out}")
    return mu, force, capstan


if __name__ == "__main__":
    main(out=sys.argv[1] if len(sys.argv) > 1 else "friction_sweep.png")
