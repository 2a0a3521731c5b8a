"""What a run's figures cost: ``exucable run`` with and without them, and where their time goes.

Part 1, whole processes: the fast Example 2 (``scenarios/fast/paper_ex2_bend90.toml``, dynamic mode,
the short run of the issue) and, with ``--steady``, the same in steady mode, run as ``exucable run
-q`` with ``--no-plots`` and with its figures, interleaved ``--repeat`` times after one warm-up run;
medians of wall time and of CPU time (user + system of the process and its children, less disturbed
by other jobs on a shared machine than wall time). The target is figures within +0.3 s of
``--no-plots`` in wall time, on a machine with a core free for the figures' helper process. "Beside
the rest" is the figures' CPU time that did not add to the wall time (CPU cost less wall cost): the
helper's import of matplotlib during the solve and its drawing in two processes at once.

Part 2, in this process (skipped by ``--quick``): the parts of the figures' cost, in CPU seconds: the
import of matplotlib's Figure and Agg canvas, then each figure drawn and written (first call, then
the median of ``--repeat`` warm calls), from one solved result; then all figures drawn in one process
and in two at once (:func:`exucable.output.figure_process.draw_in_two`, as the helper does), wall and
CPU (both processes) [s], medians of ``--repeat``.

Part 3 (skipped by ``--quick``; run before part 2, whose import it would spoil): the figures' critical path, from CPU times, which a saturated
machine inflates less than wall times: this process runs the scenario with a helper started before
(:class:`exucable.output.figure_process.Figures`) and without figures; this process's extra CPU, the
helper's warm-up (beside the solve) and its drawing after the results arrived, and its fork's. On two
free cores the figures add to the wall time about this process's extra CPU plus the longer of the
two drawings, once the warm-up (about 0.6 s CPU) ends before the solve does (a fresh process's
imports, build and solve after the fork: part 1's ``--no-plots`` CPU, less ~0.4 s of imports before it).

    nice .venv/bin/python benchmarks/figure_cost.py               # ~1 min
    nice .venv/bin/python benchmarks/figure_cost.py --repeat 9 --steady
    nice .venv/bin/python benchmarks/figure_cost.py --quick       # one repeat, no breakdown
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "fast" / "paper_ex2_bend90.toml"
TARGET_S = 0.3


def timed(cmd) -> tuple[float, float]:
    """Whole-process wall time and CPU time (user + system, children included) [s] of ``cmd``."""
    c0, t0 = os.times(), time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True)
    dt, c1 = time.perf_counter() - t0, os.times()
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd))} exited {out.returncode}:\n{out.stderr[-2000:]}")
    return dt, (c1.children_user - c0.children_user) + (c1.children_system - c0.children_system)


def whole_process(repeat: int, modes: list[str]) -> None:
    exe = Path(sys.executable).with_name("exucable")
    with tempfile.TemporaryDirectory() as tmp:
        cases = {}
        for mode in modes:
            base = [str(exe), "run", str(SCENARIO), "-q", "--mode", mode]
            cases[(mode, "--no-plots")] = base + ["-o", f"{tmp}/{mode}-a", "--no-plots"]
            cases[(mode, "figures")] = base + ["-o", f"{tmp}/{mode}-b"]
        for cmd in cases.values() if repeat > 1 else ():   # warm the disk, numba's and matplotlib's font caches
            timed(cmd)
        load0 = os.getloadavg()[0]
        times = {k: [] for k in cases}
        for _ in range(repeat):
            for k, cmd in cases.items():
                times[k].append(timed(cmd))
        print(f"# exucable run with and without figures: {SCENARIO.relative_to(ROOT)}, load average "
              f"{load0:.1f} -> {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores, median of {repeat} interleaved runs\n")
        print("| mode | figures | wall, median [s] | CPU, median [s] | figures' cost, wall / CPU [s] | of it beside the rest, CPU [s] | all runs, wall [s] |")
        print("|---|---|---|---|---|---|---|")
        for mode in modes:
            base_w = statistics.median(w for w, _ in times[(mode, "--no-plots")])
            base_c = statistics.median(c for _, c in times[(mode, "--no-plots")])
            for what in ("--no-plots", "figures"):
                v = times[(mode, what)]
                w, c = statistics.median(x for x, _ in v), statistics.median(x for _, x in v)
                cost = beside = ""
                if what != "--no-plots":
                    cost, beside = f"{w - base_w:+.2f} / {c - base_c:+.2f}", f"{(c - base_c) - (w - base_w):.2f}"
                print(f"| {mode} | {what} | {w:.2f} | {c:.2f} | {cost} | {beside} | {', '.join(f'{x:.2f}' for x, _ in v)} |")
        print(f"\ntarget: figures within +{TARGET_S} s of --no-plots")


def breakdown(repeat: int) -> None:
    """CPU seconds of matplotlib's import and of each figure, in this process."""
    from exucable.run import run_scenario
    result = run_scenario(SCENARIO, None, plots=False)
    c0 = time.process_time()
    import matplotlib.backends.backend_agg  # noqa: F401
    import matplotlib.figure  # noqa: F401
    c_import = time.process_time() - c0
    from exucable.output.figure_process import draw_figures, draw_in_two
    from exucable.plots import results as plots
    figures = {"pull_force.png": plots.plot_pull_force, "tension_profile.png": plots.plot_tension_profile,
               "pressure.png": plots.plot_pressure}
    print("\n| part | CPU, first call [s] | CPU, warm median [s] | of it building the figure, no rendering [s] |"
          "\n|---|---|---|---|")
    print(f"| import matplotlib.figure + backend_agg | {c_import:.3f} | | |")
    save = plots.save_figure
    with tempfile.TemporaryDirectory() as tmp:
        total_first = total_warm = 0.0
        for name, draw in figures.items():
            cpu, built = [], []
            for _ in range(repeat + 1):
                c0 = time.process_time()
                draw(Path(tmp) / name, result)
                cpu.append(time.process_time() - c0)
            try:
                plots.save_figure = lambda fig, path, **kw: path       # the figure built, not rendered
                for _ in range(repeat):
                    c0 = time.process_time()
                    draw(Path(tmp) / name, result)
                    built.append(time.process_time() - c0)
            finally:
                plots.save_figure = save
            warm = statistics.median(cpu[1:])
            total_first, total_warm = total_first + cpu[0], total_warm + warm
            print(f"| {name} | {cpu[0]:.3f} | {warm:.3f} | {statistics.median(built):.3f} |")
        print(f"| all three figures | {total_first:.3f} | {total_warm:.3f} | |")
        large(result, repeat, Path(tmp))
        print("\n| all figures drawn | wall, median [s] | CPU, median [s] |\n|---|---|---|")
        for what, draw in (("in one process", draw_figures), ("in two processes at once", draw_in_two)):
            wall, cpu = [], []
            for _ in range(repeat):
                c0, t0 = os.times(), time.perf_counter()
                draw(Path(tmp), result)
                t1, c1 = time.perf_counter(), os.times()
                wall.append(t1 - t0)
                cpu.append(sum(c1[:4]) - sum(c0[:4]))       # this process and its waited-for children
            print(f"| {what} | {statistics.median(wall):.3f} | {statistics.median(cpu):.3f} |")


def large(result, repeat: int, tmp: Path) -> None:
    """Each figure's CPU seconds with a 10 km steady run's point counts (the solved result's curves
    interpolated onto them: 900 000 check points, 26 000 profile stations, 100 000 pressure points)."""
    import dataclasses

    import numpy as np
    from exucable.output.figure_process import draw_figures

    def stretch(table, key, n):
        x = np.asarray(table[key], dtype=float)
        xs = np.linspace(x[0], x[-1], n)
        return {k: np.interp(xs, x, np.asarray(v, dtype=float)) for k, v in table.items()}

    big = dataclasses.replace(
        result, contact_profile=stretch(result.contact_profile, "s_conduit_m", 900_000),
        tension_profile=stretch(result.tension_profile, "x_m", 26_000),
        pressure_profile=stretch(result.pressure_profile, "s_conduit_m", 100_000),
        rope_profile=stretch(result.rope_profile, "s_conduit_m", 26_000) if result.rope_profile is not None else None,
        extras={**result.extras, "x_m": stretch({"x_m": result.extras["x_m"]}, "x_m", 26_000)["x_m"]}
        if "x_m" in result.extras else result.extras)
    print("\n| figure at a 10 km run's point counts | CPU, warm median [s] |\n|---|---|")
    for name in ("pull_force.png", "tension_profile.png", "pressure.png"):
        cpu = []
        for _ in range(repeat):
            c0 = time.process_time()
            draw_figures(tmp, big, [name])
            cpu.append(time.process_time() - c0)
        print(f"| {name} | {statistics.median(cpu):.3f} |")


def critical_path(repeat: int) -> None:
    """CPU seconds of the parts on the figures' critical path: this process's extra CPU with figures
    (sending the results, writing beside the helper), the helper's warm-up and drawing, its fork's."""
    from exucable.output.figure_process import Figures
    from exucable.run import run_scenario
    rows = {k: [] for k in ("main", "warm_up_s", "draw_s", "second_process_draw_s", "estimate")}
    with tempfile.TemporaryDirectory() as tmp:
        run_scenario(SCENARIO, Path(tmp) / "warm", plots=False)       # this process's first run loads the kernels
        for k in range(repeat):
            c0 = time.process_time()
            run_scenario(SCENARIO, Path(tmp) / f"none{k}", plots=False)
            none = time.process_time() - c0
            with Figures(helper=True) as figures:
                c0 = time.process_time()
                run_scenario(SCENARIO, Path(tmp) / f"fig{k}", plots=figures)
                main = time.process_time() - c0 - none
            cpu = figures.helper_cpu_s
            rows["main"].append(main)
            for key in ("warm_up_s", "draw_s", "second_process_draw_s"):
                rows[key].append(cpu.get(key, float("nan")))
            rows["estimate"].append(max(main, 0.0) + max(cpu["draw_s"], cpu.get("second_process_draw_s", 0.0)))
    med = {k: statistics.median(v) for k, v in rows.items()}
    print(f"\n| figures' critical path (in-process run, median of {repeat}) | CPU [s] |\n|---|---|")
    print(f"| this process's extra CPU with figures (sending, writing beside the helper) | {med['main']:+.3f} |")
    print(f"| helper: matplotlib's import and warm-up, beside the solve | {med['warm_up_s']:.3f} |")
    print(f"| helper: drawing its figures after the results arrived | {med['draw_s']:.3f} |")
    print(f"| helper's fork: drawing its share (the pulling force's figure) at the same time | {med['second_process_draw_s']:.3f} |")
    print(f"| figures' wall cost on two free cores, estimated: extra CPU + the longer drawing | {med['estimate']:.3f} |")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="interleaved rounds (default 5)")
    ap.add_argument("--steady", action="store_true", help="also in steady mode")
    ap.add_argument("--quick", action="store_true", help="smoke run: one round, no breakdown")
    args = ap.parse_args(argv)
    if args.quick:
        args.repeat = 1
    whole_process(args.repeat, ["dynamic", "steady"] if args.steady else ["dynamic"])
    if not args.quick:
        critical_path(args.repeat)          # first: its helper imports matplotlib afresh
        breakdown(args.repeat)
    return 0


if __name__ == "__main__":
    sys.exit(main())
