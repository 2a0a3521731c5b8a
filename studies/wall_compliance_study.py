"""The wall's compliance: how far the finite (Hertz) contact stiffness lowers the pulling force below the
rigid-wall limit, against the penetration over the clearance.

The Hertz wall lets the cable sink δ into it. Where a stiff cable is forced round a bend with little
room to cut it, the wall forces at the bend ends grow as the clearance c shrinks, and a compliant wall
gives the cable room c + δ: the pull comes out low. Each case is solved in steady mode at several
``contact.stiffness`` K and set beside two rigid-wall references:

* *stiffness extrapolation*: the two stiffest runs, linear in their measured deepest penetration δ
  (the error is linear in δ for small δ/c): F_∞ = F_b + (F_b − F_a)·δ_b/(δ_a − δ_b);
* *beam model* (``--beam``; the stiff cable only): the independent rigid-wall beam-in-conduit model
  :func:`exucable.quasistatic.beam.stiff_route_difference` (a node chain, not ANCF, not Exudyn) at
  40/80/160 nodes per bending length, extrapolated (Aitken's Δ², i.e. Richardson with the observed order).

The law tested: a compliant wall acts as a rigid one with the clearance c + δ, and the bend-end share
of the pull, F − F_rope (F_rope the rope with clearance), scales as c^(-1/2) (a cable of bending
stiffness EJ bent to the radius R over the length l ~ √(R c) that the clearance leaves needs wall
forces ~ EJ/(R l)); so (F_∞ − F)/(F_∞ − F_rope) = 1 − (1 + δ/c)^(-1/2), the rigid-wall shortfall is
estimated as |F − F_rope|·(√(1 + δ/c) − 1), and the steady error bar's wall part is that times
``WALL_FACTOR`` (``exucable.solve.error_bar.wall_compliance_N``), from the shortfall / estimate ratios here.

    nice .venv/bin/python studies/wall_compliance_study.py --beam \\
        --record reference/wall_compliance_study.json --figure reference/wall_compliance.png
    nice .venv/bin/python studies/wall_compliance_study.py --from-json reference/wall_compliance_study.json
    nice .venv/bin/python studies/wall_compliance_study.py --quick      # smoke run: c 0.5 mm, two stiffnesses
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from exucable.io import atomic_write_text, save_figure  # noqa: E402

# the stiff cable of the tight-clearance case: r 29.5 mm, E 5 GPa (EJ 2974 N m²), 1.5 kg/m, 30 m straights
# either side of a 30° bend of R 10 m, μ 0.2, 500 N back tension, gravity
TIGHT = """name = "tight-c{c_mm:g}mm-K{k:g}"
[cable]
radius = 0.0295
mass_per_length = 1.5
youngs_modulus = 5e9
[conduit]
inner_radius = {rin!r}
path = [{{straight = 30}}, {{bend = 30, radius = 10.0, turn = "left"}}, {{straight = 30}}]
[contact]
friction = 0.2
stiffness = {k!r}
[pull]
speed = 1.0
back_tension = 500.0
[gravity]
g = 9.81
[solver]
mode = "steady"
"""
TIGHT_EJ_N_m2 = 5e9 * math.pi * 0.0295 ** 4 / 4.0
TIGHT_PIECES = [(30.0, 0.0), (10.0 * math.pi / 6.0, 0.1), (30.0, 0.0)]
# the paper's Example 2 (fast variant, steady mode): a flexible cable, 1 mm clearance, the paper's K 1e6
EX2 = ROOT / "scenarios" / "fast" / "paper_ex2_bend90.toml"


def law_share(x):
    """(F_∞ − F)/(F_∞ − F_rope) of the law at δ/c = x [-]."""
    return 1.0 - 1.0 / np.sqrt(1.0 + np.asarray(x, dtype=float))


def solve(sc):
    from exucable.run import run_scenario
    t0 = time.process_time()
    res = run_scenario(sc, None, plots=False, error_bar=False)
    s = res.summary
    pen = float(np.max(res.contact_profile["penetration_m"]))
    rope = s["rope_clearance_pull_force_N"] if s["rope_clearance_pull_force_N"] is not None else s["rope_pull_force_N"]
    return {"status": s["status"], "pull_force_N": s["pull_force_N"], "rope_N": rope, "max_penetration_m": pen,
            "newton_iterations": s["newton_iterations"], "cpu_s": time.process_time() - t0}


def beam_reference(clearance_m, levels=(40.0, 80.0, 160.0)):
    from exucable.quasistatic.beam import stiff_route_difference
    F = [stiff_route_difference(TIGHT_PIECES, clearance_m, 0.2, 1.5 * 9.81, TIGHT_EJ_N_m2, 500.0,
                                nodes_per_bending_length=n)["stiff_N"] for n in levels]
    if len(F) < 3:
        return {"nodes_per_bending_length": list(levels), "pull_force_N": F, "limit_N": F[-1]}
    d1, d2 = F[1] - F[0], F[2] - F[1]
    # Aitken's Δ²: the limit of a sequence converging geometrically (observed ratio d1/d2)
    limit = F[2] - d2 * d2 / (d2 - d1) if d1 * d2 > 0 and abs(d2) < abs(d1) else F[2]
    return {"nodes_per_bending_length": list(levels), "pull_force_N": F, "limit_N": limit,
            "observed_ratio": d1 / d2 if d2 else float("nan")}


def case_runs(label, clearance_m, scenarios, beam=None):
    runs = []
    for k, sc in scenarios:
        r = solve(sc)
        r["stiffness"] = k
        runs.append(r)
        print(f"  done: {label} K {k:g}: {r['pull_force_N']:.2f} N, δ/c {r['max_penetration_m'] / clearance_m:.4f}, "
              f"{r['status']}, {r['cpu_s']:.1f} s CPU", flush=True)
    a, b = runs[-2], runs[-1]
    da, db = a["max_penetration_m"], b["max_penetration_m"]
    extrapolated = b["pull_force_N"] + (b["pull_force_N"] - a["pull_force_N"]) * db / (da - db)
    rate = math.log(da / db) / math.log(b["stiffness"] / a["stiffness"])
    out = {"case": label, "clearance_m": clearance_m, "runs": runs, "stiffness_extrapolated_N": extrapolated,
           "penetration_exponent": rate}
    if beam is not None:
        out["beam"] = beam
    return out


def print_record(record):
    """The runs against the rigid-wall limit of the same model (stiffness extrapolation) and the beam model's."""
    from exucable.solve.error_bar import WALL_FACTOR, wall_compliance_N

    print("| case | c [mm] | K [N/m^1.5] | δ/c [-] | F [N] | vs K → ∞ [%] | law [%] | vs beam [%] "
          "| shortfall / law's estimate | u_wall [N] | covers K → ∞ | status |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for case in record["cases"]:
        F_inf, c = case["stiffness_extrapolated_N"], case["clearance_m"]
        beam = case["beam"]["limit_N"] if "beam" in case else None
        for r in case["runs"]:
            x = r["max_penetration_m"] / c
            F, rope = r["pull_force_N"], r["rope_N"]
            law = -(F_inf - rope) * law_share(x) / F_inf
            u = wall_compliance_N(F, rope, r["max_penetration_m"], c)
            vs_beam = f"{100 * (F / beam - 1):+.3f}" if beam else "-"
            print(f"| {case['case']} | {1e3 * c:g} | {r['stiffness']:.0e} | {x:.4f} | {F:.2f} | {100 * (F / F_inf - 1):+.3f} "
                  f"| {100 * float(law):+.3f} | {vs_beam} | {(F_inf - F) / (u / WALL_FACTOR):.2f} | {u:.2f} "
                  f"| {'yes' if F + u >= F_inf else 'NO'} | {r['status']} |")
    print()
    print("| case | rope with clearance [N] | K → ∞ (two stiffest, linear in δ) [N] | beam model, 40/80/160 nodes per λ → limit [N] "
          "| K → ∞ vs beam [%] | δ ∝ K^-p, p |")
    print("|---|---|---|---|---|---|")
    for case in record["cases"]:
        b = case.get("beam")
        beam = (" / ".join(f"{f:.1f}" for f in b["pull_force_N"]) + f" → {b['limit_N']:.1f}") if b else "-"
        diff = f"{100 * (case['stiffness_extrapolated_N'] / b['limit_N'] - 1):+.3f}" if b else "-"
        print(f"| {case['case']} | {case['runs'][-1]['rope_N']:.2f} | {case['stiffness_extrapolated_N']:.2f} | {beam} | {diff} "
              f"| {case['penetration_exponent']:.3f} |")


def figure(record, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11.5, 4.4))
    xs = [r["max_penetration_m"] / case["clearance_m"] for case in record["cases"] for r in case["runs"]]
    grid = np.logspace(math.log10(max(min(xs), 1e-4)), math.log10(max(xs) * 1.2), 100)
    for i, case in enumerate(record["cases"]):
        F_inf, c = case["stiffness_extrapolated_N"], case["clearance_m"]
        x = np.array([r["max_penetration_m"] / c for r in case["runs"]])
        F = np.array([r["pull_force_N"] for r in case["runs"]])
        rope = case["runs"][-1]["rope_N"]
        marker, color = "os^vD<>"[i % 7], f"C{i}"
        axes[0].semilogx(x, 100 * (F / F_inf - 1.0), marker=marker, ls="", color=color, label=case["case"])
        axes[0].semilogx(grid, -100 * (F_inf - rope) / F_inf * law_share(grid), ls="-", lw=0.8, color=color)
        if "beam" in case:
            axes[0].semilogx([grid[0]], [100 * (case["beam"]["limit_N"] / F_inf - 1.0)], marker=marker, mfc="none",
                             ls="", color=color, ms=9)
            axes[1].semilogx(x, (F_inf - F) / (F_inf - rope), marker=marker, ls="", color=color, label=case["case"])
    axes[1].semilogx(grid, law_share(grid), "k-", lw=1, label="law 1 − (1 + δ/c)^(-1/2)")
    axes[1].semilogx(grid, 0.5 * grid, "k:", lw=1, label="first order δ/(2c)")
    axes[1].set_ylim(-0.02, 0.3)
    axes[0].set_xlabel("deepest penetration / clearance δ/c [-]")
    axes[0].set_ylabel("F / F(K → ∞) − 1 [%]")
    axes[0].set_title("pull against the rigid wall (lines: the law; open: beam model)", fontsize=10)
    axes[1].set_xlabel("deepest penetration / clearance δ/c [-]")
    axes[1].set_ylabel("(F(K → ∞) − F) / (F(K → ∞) − F_rope) [-]")
    axes[1].set_title("stiff cable: share of the bend-end force lost to the compliance", fontsize=10)
    for ax in axes:
        ax.axvline(0.25, color="0.5", lw=0.8, ls="--")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)     # atomic: a reader never sees half a PNG


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--clearances-mm", type=float, nargs="+", default=[0.25, 0.5, 1.0, 2.0])
    p.add_argument("--stiffness", type=float, nargs="+", default=[1e6, 1e7, 1e8, 1e9])
    p.add_argument("--ex2-stiffness", type=float, nargs="*", default=[1e5, 1e6, 1e7, 1e8],
                   help="contact.stiffness of the paper's Example 2 runs (none: skip)")
    p.add_argument("--beam", action="store_true", help="the rigid-wall beam model beside each stiff-cable clearance")
    p.add_argument("--record", help="write the record here (JSON)")
    p.add_argument("--figure", help="write the figure here (PNG)")
    p.add_argument("--from-json", help="print (and draw) a stored record instead of running")
    p.add_argument("--quick", action="store_true", help="smoke run: c 0.5 mm at K 1e7 and 1e8, no Example 2")
    args = p.parse_args(argv)
    if args.from_json:
        record = json.loads(Path(args.from_json).read_text())
    else:
        if args.quick:
            args.clearances_mm, args.stiffness, args.ex2_stiffness, args.beam = [0.5], [1e7, 1e8], [], False
        import tomllib
        from exucable.scenario.specs import load_scenario, parse_scenario
        cases = []
        for c_mm in args.clearances_mm:
            c = 1e-3 * c_mm
            scs = [(k, parse_scenario(tomllib.loads(TIGHT.format(c_mm=c_mm, k=k, rin=0.0295 + c)), ROOT)) for k in args.stiffness]
            beam = beam_reference(c) if args.beam else None
            cases.append(case_runs(f"stiff cable, c {c_mm:g} mm", c, scs, beam))
        if args.ex2_stiffness:
            base = load_scenario(EX2).replace(**{"solver.mode": "steady"})
            c = base.conduit.inner_radius_m - base.cable.radius_m
            scs = [(k, base.replace(**{"contact.stiffness": k})) for k in args.ex2_stiffness]
            cases.append(case_runs("paper Ex2", c, scs))
        record = {"cases": cases}
        if args.record:
            atomic_write_text(Path(args.record), json.dumps(record, indent=1) + "\n")
    print_record(record)
    if args.figure:
        figure(record, args.figure)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
