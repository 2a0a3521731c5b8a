"""What the multibody pull-in history costs: 50 head positions on a 100 m route, each solve from the last state.

Target: 50 points on a 100 m route in ≤ 30 s on the shared 2-core machine. Prints, measured in one run,
the process CPU time of the history (warm starts: each steady solve from the last state, extended) and of
the same history solved from the rope start at every point, their ratio, the per-point cost and Newton
iterations, and the largest difference between the two histories (the same equilibria, reached from two
starts) and between the last point and a single steady run of the whole route.

Run: ``nice .venv/bin/python benchmarks/pull_in_history.py [--points 50] [--scenario FILE] [--no-cold]``;
``--quick``: fast Example 2 (2.8 m, 20 elements), 8 points.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from exucable.data import data_path
from exucable.run import run_scenario
from exucable.scenario.specs import load_scenario
from exucable.solve.pull_in import steady_pull_in

ROOT = Path(__file__).resolve().parent.parent


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default=str(ROOT / "scenarios" / "studies" / "route100_4bends.toml"))
    ap.add_argument("--points", type=int, default=50)
    ap.add_argument("--no-cold", action="store_true", help="skip the history from the rope start at every point")
    ap.add_argument("--quick", action="store_true", help="fast Example 2, 8 points (a smoke run)")
    args = ap.parse_args()
    if args.quick:
        args.scenario, args.points = data_path("scenarios", "fast", "paper_ex2_bend90.toml"), 8
    scenario = load_scenario(args.scenario)
    length = scenario.build_conduit().centreline.length_m
    print(f"scenario {scenario.name}: {length:.4g} m, {args.points} uniform head positions plus the piece ends")
    # the first solve of a process loads numba's kernels and Exudyn's code: paid before either history
    steady_pull_in(scenario, x_m=[length / args.points])
    warm = steady_pull_in(scenario, args.points)
    n = warm.pulled_length_m.size - 1
    rows = [("warm (from the last state)", warm)]
    if not args.no_cold:
        rows.append(("cold (from the rope start)", steady_pull_in(scenario, args.points, warm_start=False)))
    t0 = time.process_time()
    full = run_scenario(scenario, None, plots=False, mode="steady", quiet=True, error_bar=False)
    full_cpu = time.process_time() - t0
    print(f"\n| history | points | CPU [s] | CPU per point [s] | Newton its per point | warm-started | failed |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for label, h in rows:
        print(f"| {label} | {n} | {h.cpu_time_s:.2f} | {h.cpu_time_s / n:.3f} | {np.mean(h.newton_iterations[1:]):.1f} "
              f"| {int(np.sum(h.warm_started))} | {h.failed} |")
    if len(rows) == 2:
        cold = rows[1][1]
        rel = np.abs(warm.pull_force_N / cold.pull_force_N - 1.0)
        print(f"\nCPU ratio warm / cold: {warm.cpu_time_s / cold.cpu_time_s:.2f}; largest |warm/cold - 1| of the head "
              f"tension: {np.nanmax(rel):.2e}")
    F = full.summary["pull_force_N"]
    print(f"last point {warm.pull_force_N[-1]:.6g} N against the single steady run's {F:.6g} N "
          f"(|ratio - 1| = {abs(warm.pull_force_N[-1] / F - 1):.2e}; that run alone: {full_cpu:.2f} s CPU, "
          f"{full.summary['mesh']['elements']} elements)")


if __name__ == "__main__":
    main()
