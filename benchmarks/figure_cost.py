"""What a run's figures cost: ``exucable run`` with and without them, and where their time goes.

Part 1, whole processes: the fast Example 2 (``scenarios/fast/paper_ex2_bend90.toml``, dynamic mode,
the short run of the issue) and, with ``--steady``, the same in steady mode, run as ``exucable run
-q`` with ``--no-plots`` and with its figures, interleaved ``--repeat`` times after one warm-up run;
medians of wall time and of CPU time (user + system of the process and its children, less disturbed
by other jobs on a shared machine than wall time). The target is figures within +0.3 s of
``--no-plots`` in wall time, on a machine with a core free for the figures' helper process. "Beside
the rest" is the figures' CPU time that did not add to the wall time (CPU cost less wall cost): the
helper's import of matplotlib during the solve and its drawing in several processes at once.

Part 2 (skipped by ``--quick``): the figures' critical path, from CPU times, which a saturated machine
inflates less than wall times, per mode in a fresh child process: it runs the scenario with a helper
started before (:class:`exucable.output.figure_process.Figures`) and without figures; its extra CPU,
the helper's warm-up (beside the solve), the helper's own drawing after the results arrived and its
forks' (their total and the longest). On two free cores the figures add to the wall time about the
extra CPU plus the longer of the costliest drawing process and all the drawing CPU over two cores, once
the warm-up (about 0.6-0.75 s CPU, the frames included) ends before the solve does (a fresh process's
imports, build and solve after the fork: part 1's ``--no-plots`` CPU, less ~0.4 s of imports before
it).

Part 3, in this process (skipped by ``--quick``): the parts of the figures' cost, in CPU seconds: the
import of matplotlib's Figure and Agg canvas, then each figure drawn and written (first call, then the
median of ``--repeat`` warm calls, on a new figure and on a frame built ahead as the helper does), from
one solved result, and its PNG encoding at Pillow's default zlib level and at the figures' level 1;
then all figures drawn in one process and each in a process of its own at once
(:func:`exucable.output.figure_process.draw_in_parallel`, as the helper does), wall and CPU (all
processes) [s], medians of ``--repeat``.

``--before TREE`` runs parts 1 and 2 also with the exucable package of the source tree TREE (``git
archive <commit> | tar -x -C TREE``; copy ``exucable/contact/__pycache__`` into it with the sources'
time stamps, ``touch -r``, or its kernels compile in its first run), interleaved with the installed
one: a change's effect measured in one run.

    nice .venv/bin/python benchmarks/figure_cost.py               # ~1 min
    nice .venv/bin/python benchmarks/figure_cost.py --repeat 9 --steady [--before TREE]
    nice .venv/bin/python benchmarks/figure_cost.py --quick       # one repeat, no breakdown
"""

from __future__ import annotations

import argparse
import json
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


def timed(cmd, env=None) -> tuple[float, float]:
    """Whole-process wall time and CPU time (user + system, children included) [s] of ``cmd``."""
    c0, t0 = os.times(), time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True, env=env)
    dt, c1 = time.perf_counter() - t0, os.times()
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd))} exited {out.returncode}:\n{out.stderr[-2000:]}")
    return dt, (c1.children_user - c0.children_user) + (c1.children_system - c0.children_system)


def _env(tree: str | None) -> dict | None:
    """The environment of a child that imports the exucable package of source tree ``tree``
    instead of the installed one (None: the installed one)."""
    if tree is None:
        return None
    return dict(os.environ, PYTHONPATH=os.pathsep.join([str(Path(tree).resolve())]
                                                      + [p for p in [os.environ.get("PYTHONPATH")] if p]))


def whole_process(repeat: int, modes: list[str], before: str | None = None) -> None:
    exe = Path(sys.executable).with_name("exucable")
    trees = {"before": before, "after": None} if before else {"": None}
    with tempfile.TemporaryDirectory() as tmp:
        cases = {}
        for mode in modes:
            for label, tree in trees.items():
                base = [str(exe), "run", str(SCENARIO), "-q", "--mode", mode]
                cases[(mode, label, "--no-plots")] = (base + ["-o", f"{tmp}/{mode}{label}-a", "--no-plots"], _env(tree))
                cases[(mode, label, "figures")] = (base + ["-o", f"{tmp}/{mode}{label}-b"], _env(tree))
        for cmd, env in cases.values() if repeat > 1 else ():   # warm the disk, numba's and matplotlib's font caches
            timed(cmd, env)
        load0 = os.getloadavg()[0]
        times = {k: [] for k in cases}
        for _ in range(repeat):
            for k, (cmd, env) in cases.items():
                times[k].append(timed(cmd, env))
        print(f"# exucable run with and without figures: {SCENARIO.relative_to(ROOT)}, load average "
              f"{load0:.1f} -> {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores, median of {repeat} interleaved runs"
              + (f"; 'before': the exucable package of {before}" if before else "") + "\n")
        print("| mode | figures | wall, median [s] | CPU, median [s] | figures' cost, wall / CPU [s] | of it beside the rest, CPU [s] | all runs, wall [s] |")
        print("|---|---|---|---|---|---|---|")
        for mode in modes:
            for label in trees:
                base_w = statistics.median(w for w, _ in times[(mode, label, "--no-plots")])
                base_c = statistics.median(c for _, c in times[(mode, label, "--no-plots")])
                for what in ("--no-plots", "figures"):
                    v = times[(mode, label, what)]
                    w, c = statistics.median(x for x, _ in v), statistics.median(x for _, x in v)
                    cost = beside = ""
                    if what != "--no-plots":
                        cost, beside = f"{w - base_w:+.2f} / {c - base_c:+.2f}", f"{(c - base_c) - (w - base_w):.2f}"
                    print(f"| {mode}{' ' + label if label else ''} | {what} | {w:.2f} | {c:.2f} | {cost} | {beside} | "
                          f"{', '.join(f'{x:.2f}' for x, _ in v)} |")
        print(f"\ntarget: figures within +{TARGET_S} s of --no-plots")


def breakdown(repeat: int) -> None:
    """CPU seconds of matplotlib's import and of each figure, in this process: drawn on a new figure
    and on a frame built ahead (as the helper does), building alone, and the PNG encoding at
    Pillow's default level and at the level the figures use."""
    from exucable.run import run_scenario
    result = run_scenario(SCENARIO, None, plots=False)
    c0 = time.process_time()
    import matplotlib.backends.backend_agg  # noqa: F401
    import matplotlib.figure  # noqa: F401
    c_import = time.process_time() - c0
    from exucable.output.figure_process import FRAME_TICKS, build_frames, draw_figures, draw_in_parallel
    from exucable.plots import results as plots
    figures = {"pull_force.png": plots.plot_pull_force, "tension_profile.png": plots.plot_tension_profile,
               "pressure.png": plots.plot_pressure}
    print("\n| part | CPU, first call [s] | CPU, warm median [s] | on a frame built ahead [s] | of it building the "
          "figure, no rendering [s] | PNG encoding, Pillow's default / level 1, least [s] |\n|---|---|---|---|---|---|")
    print(f"| import matplotlib.figure + backend_agg | {c_import:.3f} | | | | |")
    save = plots.save_figure
    with tempfile.TemporaryDirectory() as tmp:
        totals = [0.0, 0.0, 0.0]
        for name, draw in figures.items():
            cpu, framed, built = [], [], []
            for _ in range(repeat + 1):
                c0 = time.process_time()
                draw(Path(tmp) / name, result)
                cpu.append(time.process_time() - c0)
            for _ in range(repeat):
                frame = plots.FRAMES[name](FRAME_TICKS)
                c0 = time.process_time()
                draw(Path(tmp) / name, result, frame)
                framed.append(time.process_time() - c0)
            try:
                plots.save_figure = lambda fig, path, **kw: path       # the figure built, not rendered
                for _ in range(repeat):
                    c0 = time.process_time()
                    draw(Path(tmp) / name, result)
                    built.append(time.process_time() - c0)
            finally:
                plots.save_figure = save
            encode = png_encoding(name, result, repeat)
            warm, on_frame = statistics.median(cpu[1:]), statistics.median(framed)
            for k, v in enumerate((cpu[0], warm, on_frame)):
                totals[k] += v
            print(f"| {name} | {cpu[0]:.3f} | {warm:.3f} | {on_frame:.3f} | {statistics.median(built):.3f} | "
                  f"{encode[0]:.4f} / {encode[1]:.4f} |")
        print(f"| all three figures | {totals[0]:.3f} | {totals[1]:.3f} | {totals[2]:.3f} | | |")
        large(result, repeat, Path(tmp))
        print("\n| all figures drawn | wall, median [s] | CPU, median [s] |\n|---|---|---|")
        for what, draw in (("in one process", draw_figures),
                           ("each in a process of its own, at once, on frames built ahead (as the helper)",
                            lambda out, res: draw_in_parallel(out, res, None, build_frames()))):
            wall, cpu = [], []
            for _ in range(repeat):
                c0, t0 = os.times(), time.perf_counter()
                draw(Path(tmp), result)
                t1, c1 = time.perf_counter(), os.times()
                wall.append(t1 - t0)
                cpu.append(sum(c1[:4]) - sum(c0[:4]))       # this process and its waited-for children
            print(f"| {what} | {statistics.median(wall):.3f} | {statistics.median(cpu):.3f} |")


def png_encoding(name: str, result, repeat: int) -> tuple[float, float]:
    """CPU seconds of encoding figure ``name``'s pixels as PNG the way matplotlib does (Pillow, from
    the RGBA buffer), at Pillow's default zlib level and at the figures'
    (:data:`exucable.plots.results.PNG_KWARGS`): the least of ``4 * repeat`` interleaved encodings
    each (a few ms: the least is the encoding's own cost, the rest is other jobs' noise)."""
    import io

    import numpy as np
    from PIL import Image
    from exucable.plots import results as plots

    draw = {"pull_force.png": plots.pull_force_figure, "tension_profile.png": plots.tension_profile_figure,
            "pressure.png": plots.pressure_figure}[name]
    fig = draw(result)
    fig.set_dpi(plots.SAVE_DPI)
    fig.canvas.draw()
    rgba = np.asarray(fig.canvas.buffer_rgba())
    levels = ({}, plots.PNG_KWARGS["pil_kwargs"])
    cpu = [[], []]
    for _ in range(4 * repeat):
        for k, kwargs in enumerate(levels):
            c0 = time.process_time()
            Image.fromarray(rgba).save(io.BytesIO(), format="png", **kwargs)
            cpu[k].append(time.process_time() - c0)
    return min(cpu[0]), min(cpu[1])


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


def critical_path(repeat: int, mode: str) -> dict:
    """CPU seconds of the parts on the figures' critical path (medians of ``repeat``): this process's
    extra CPU with figures (sending the results, writing beside the helper), the helper's warm-up
    and its own drawing after the results arrived, the drawing of the processes it forked (their
    total and the longest); and the estimate of the figures' wall cost on two free cores: the extra
    CPU plus the longer of the costliest drawing process and all the drawing CPU over two cores."""
    from exucable.output.figure_process import Figures
    from exucable.run import run_scenario
    keys = ("main", "warm_up_s", "draw_s", "forks_draw_s", "longest_fork_draw_s", "estimate")
    rows = {k: [] for k in keys}
    with tempfile.TemporaryDirectory() as tmp:
        run_scenario(SCENARIO, Path(tmp) / "warm", plots=False, mode=mode)   # this process's first run loads the kernels
        for k in range(repeat):
            c0 = time.process_time()
            run_scenario(SCENARIO, Path(tmp) / f"none{k}", plots=False, mode=mode)
            none = time.process_time() - c0
            with Figures(helper=True) as figures:
                _wait_idle(figures._proc.pid)
                c0 = time.process_time()
                run_scenario(SCENARIO, Path(tmp) / f"fig{k}", plots=figures, mode=mode)
                main = time.process_time() - c0 - none
            cpu = dict(figures.helper_cpu_s)
            if "second_process_draw_s" in cpu:          # a tree whose helper forked one process
                cpu["forks_draw_s"] = cpu["longest_fork_draw_s"] = cpu.pop("second_process_draw_s")
            rows["main"].append(main)
            for key in keys[1:-1]:
                rows[key].append(cpu.get(key, 0.0))
            longest = max(cpu["draw_s"], cpu.get("longest_fork_draw_s", 0.0))
            total = cpu["draw_s"] + cpu.get("forks_draw_s", 0.0)
            rows["estimate"].append(max(main, 0.0) + max(longest, total / 2))
    return {k: statistics.median(v) for k, v in rows.items()}


def _wait_idle(pid: int, settle_s: float = 0.3, timeout_s: float = 60.0) -> None:
    """Wait until process ``pid`` has used no CPU for ``settle_s`` [s]: the helper's warm-up is over
    and it waits for the results, as in a fresh run, whose imports, build and solve outlast it (here
    the model's code is loaded already, and the results would come before the helper is ready).
    Without ``/proc``, a fixed 3 s."""
    stat = Path(f"/proc/{pid}/stat")
    if not stat.exists():
        time.sleep(3.0)
        return
    last, end = None, time.monotonic() + timeout_s
    while time.monotonic() < end:
        fields = stat.read_text().rsplit(")", 1)[1].split()
        cpu = int(fields[11]) + int(fields[12])           # utime + stime, in clock ticks
        if cpu == last:
            return
        last = cpu
        time.sleep(settle_s)


CRITICAL_ROWS = (("main", "this process's extra CPU with figures (sending, writing beside the helper)"),
                 ("warm_up_s", "helper: matplotlib's import, warm-up and the figures' frames, beside the solve"),
                 ("draw_s", "helper: drawing its own figures after the results arrived"),
                 ("forks_draw_s", "the helper's forks: drawing the other figures at the same time, total"),
                 ("longest_fork_draw_s", "the helper's forks: the longest one"),
                 ("estimate", "figures' wall cost on two free cores, estimated: extra CPU + max(longest drawing, all drawing / 2)"))


def critical_paths(repeat: int, modes: list[str], before: str | None) -> None:
    """:func:`critical_path` of each mode in a fresh child process (its helper imports matplotlib
    afresh), for the tree ``before`` too, interleaved."""
    trees = {"before": before, "after": None} if before else {"": None}
    got = {}
    for mode in modes:
        for label, tree in trees.items():
            done = subprocess.run([sys.executable, __file__, "--critical-path", mode, "--repeat", str(repeat)],
                                  capture_output=True, text=True, env=_env(tree))
            if done.returncode != 0:
                raise RuntimeError(f"critical path ({mode} {label}) failed:\n{done.stderr[-2000:]}")
            got[(mode, label)] = json.loads(done.stdout.strip().splitlines()[-1])
    cols = list(got)
    print(f"\n| figures' critical path (in-process runs, CPU [s], median of {repeat}) | "
          + " | ".join(f"{m}{' ' + lab if lab else ''}" for m, lab in cols) + " |")
    print("|---|" + "---|" * len(cols))
    for key, what in CRITICAL_ROWS:
        print(f"| {what} | " + " | ".join(f"{got[c][key]:.3f}" for c in cols) + " |")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="interleaved rounds (default 5)")
    ap.add_argument("--steady", action="store_true", help="also in steady mode")
    ap.add_argument("--before", metavar="TREE", help="also with the exucable package of source tree TREE, interleaved")
    ap.add_argument("--critical-path", metavar="MODE", help=argparse.SUPPRESS)   # a child of critical_paths
    ap.add_argument("--quick", action="store_true", help="smoke run: one round, no breakdown")
    ap.add_argument("--no-whole", action="store_true", help="skip part 1 (the whole processes)")
    args = ap.parse_args(argv)
    if args.critical_path:
        print(json.dumps(critical_path(args.repeat, args.critical_path)))
        return 0
    if args.quick:
        args.repeat = 1
    modes = ["dynamic", "steady"] if args.steady else ["dynamic"]
    if not args.no_whole:
        whole_process(args.repeat, modes, args.before)
    if not args.quick:
        critical_paths(args.repeat, modes, args.before)
        breakdown(args.repeat)
    return 0


if __name__ == "__main__":
    sys.exit(main())
