"""Three cables round a bend: what the calculators' formulas miss, D/d and the bending stiffness.

One horizontal 90° bend of 2 m radius between two 0.5 m straights, no gravity, wall friction μ 0.3,
frictionless between the cables, each cable entering with 100 N (16 elements of 0.26 m, 16 check
points each), in steady mode. Per case it prints, all measured in this one run:

- the most loaded cable's wall force over the bend's middle half per unit bend angle, over the
  calculators' sidewall pressure f_rad·T/R times R at the same place (T the bundle's tension there from
  the rigid-circle model, exucable/quasistatic/bundle_bend.py) and over the rigid-circle model's own value;
- the bundle's pull over the calculators' 3 T_0 e^{w_c μ θ} and over the rigid-circle model's total;
- the cables' pull shares.

    nice .venv/bin/python studies/bundle_bend_study.py [--ratios 2.6 2.8 3.0 3.3] [--stiffness 0.1 1 10]
        [--figure reference/bundle_bend.png]

The record and its reading: reference/README.md, "Three cables round a bend".
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import exucable as xc
from exucable.errors import ExucableError
from exucable.io import save_figure
from exucable.model.bundle import build_bundle_model, bundle_report
from exucable.quasistatic import engineering as eng
from exucable.quasistatic.bundle_bend import bundle_bend_split
from exucable.solve.steady import solve_steady

D_CABLE, RADIUS, T0, STRAIGHT, MU = 0.03, 2.0, 100.0, 0.5, 0.3
THETA = math.pi / 2


def scenario(arrangement, ratio, bending_stiffness):
    route = (xc.Route(inner_radius=ratio * D_CABLE / 2).straight(STRAIGHT).bend(90, radius=RADIUS, turn="left")
             .straight(STRAIGHT))
    return xc.Scenario(route=route,
                       cable=xc.Cable(radius=D_CABLE / 2, density=2000.0, youngs_modulus=2e8,
                                      bending_stiffness=bending_stiffness, count=3, arrangement=arrangement,
                                      elements=16),
                       contact=xc.Contact(friction=MU, check_points_per_element=16),
                       pull=xc.Pull(speed=0.1, back_tension=3 * T0),
                       solver=xc.Solver(mode="steady", end_time=1.0, steady_lead_out=0.0))


def middle_wall_force_per_angle(model):
    """Each cable's wall normal force over the bend's middle half per unit bend angle [N/rad]."""
    a, b = STRAIGHT + 0.25 * RADIUS * THETA, STRAIGHT + 0.75 * RADIUS * THETA
    out = []
    for q, k in zip(model.cable_coordinates(), model.walls):
        pts = k.points(q.reshape(-1), np.zeros(q.size))
        sel = (pts.s_conduit_m >= a) & (pts.s_conduit_m < b)
        out.append(float(np.sum(pts.normal_force_N[sel])) / ((b - a) / RADIUS))
    return np.array(out)


def one_case(arrangement, ratio, stiffness):
    D = ratio * D_CABLE
    try:
        wc = eng.weight_correction_factor(3, arrangement, D, D_CABLE)
        theta = np.linspace(THETA / 4, 3 * THETA / 4, 401)
        ref = bundle_bend_split(3, arrangement, D, D_CABLE, MU, T0, theta)
        model = build_bundle_model(scenario(arrangement, ratio, stiffness))
    except ExucableError as exc:       # an arrangement that does not stand or fit: say so, go on
        return {"arrangement": arrangement, "ratio": ratio, "EJ": stiffness, "status": f"refused: {exc}"}
    t0 = time.process_time()
    out = solve_steady(model)
    cpu = time.process_time() - t0
    row = {"arrangement": arrangement, "ratio": ratio, "EJ": stiffness, "status": out.status, "cpu": cpu}
    if out.status != "ok":
        return row
    N = middle_wall_force_per_angle(model)
    i = int(np.argmax(N))
    model_N = ref.wall_force_per_angle_N.mean(axis=1)
    # the calculators' sidewall pressure at the same places: f_rad times the bundle's tension there
    total = 3 * T0 * np.exp(wc * MU * theta)
    formula_N = eng.sidewall_pressure_factor(3, arrangement, wc) * float(np.mean(total))
    report = bundle_report(model)
    shares = np.array([c["pull_share_N"] for c in report["cables"]])
    end = bundle_bend_split(3, arrangement, D, D_CABLE, MU, T0, [THETA]).tension_N[:, 0]
    row.update(pressure_vs_formula=N[i] / formula_N, pressure_vs_model=N[i] / model_N[i],
               pull_vs_formula=shares.sum() / (3 * T0 * math.exp(wc * MU * THETA)), pull_vs_model=shares.sum() / end.sum(),
               shares=shares, model_shares=end)
    return row


def figure(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for arrangement, marker in (("cradled", "o"), ("triangular", "s")):
        for EJ in sorted({r["EJ"] for r in rows}):
            sel = [r for r in rows if r["arrangement"] == arrangement and r["EJ"] == EJ and r["status"] == "ok"]
            if not sel:
                continue
            x = [r["ratio"] for r in sel]
            label = f"{arrangement}, EJ {EJ:g} N m²"
            axes[0].plot(x, [r["pressure_vs_formula"] for r in sel], marker=marker, label=label)
            axes[1].plot(x, [r["pull_vs_formula"] for r in sel], marker=marker, label=label)
    axes[0].set_ylabel("most loaded cable's wall force / formula's [-]")
    axes[0].set_title("sidewall pressure, middle of a 90° bend (μ 0.3)")
    axes[1].set_ylabel("bundle's pull / 3 T₀ e^(w_c μ θ) [-]")
    axes[1].set_title("pull out of the bend")
    for ax in axes:
        ax.set_xlabel("D/d [-]")
        ax.axhline(1.0, color="k", lw=0.5)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)     # atomic: a reader never sees half a PNG


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--ratios", type=float, nargs="+", default=[2.6, 2.8, 3.0, 3.3])
    p.add_argument("--stiffness", type=float, nargs="+", default=[0.1, 1.0, 10.0])
    p.add_argument("--arrangements", nargs="+", default=["cradled", "triangular"])
    p.add_argument("--figure", help="write the figure here (PNG)")
    p.add_argument("--quick", action="store_true", help="one D/d, one EJ, cradled (a smoke run)")
    args = p.parse_args(argv)
    if args.quick:
        args.ratios, args.stiffness, args.arrangements = [3.3], [1.0], ["cradled"]
    print(f"{'arrangement':11} {'D/d':>5} {'EJ':>6} {'status':>7} {'p/formula':>10} {'p/model':>8} "
          f"{'F/formula':>10} {'F/model':>8} {'CPU [s]':>7}  shares [N] (model)")
    rows = []
    for arrangement in args.arrangements:
        for ratio in args.ratios:
            for EJ in args.stiffness:
                r = one_case(arrangement, ratio, EJ)
                rows.append(r)
                if r["status"] != "ok":
                    print(f"{arrangement:11} {ratio:5.2f} {EJ:6.3g} {r['status']}")
                    continue
                print(f"{arrangement:11} {ratio:5.2f} {EJ:6.3g} {r['status']:>7} {r['pressure_vs_formula']:10.4f} "
                      f"{r['pressure_vs_model']:8.4f} {r['pull_vs_formula']:10.4f} {r['pull_vs_model']:8.4f} "
                      f"{r['cpu']:7.1f}  " + " ".join(f"{s:.1f}" for s in r["shares"])
                      + " (" + " ".join(f"{s:.1f}" for s in r["model_shares"]) + ")", flush=True)
    if args.figure:
        figure(rows, args.figure)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
