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
inflates less than wall times, per mode, from fresh processes that run the command as ``exucable run``
does (``--no-plots`` and with figures, interleaved; a process that has loaded the model's code would
fork its helper with hundreds of MB to copy on write, which the command's helper, forked first thing,
has not): the main process's own extra CPU with figures, its extra minor page faults and the bytes it
sends to the helper; the helper's warm-up (beside the solve), the frames of the drawing processes it
forks ahead, the helper's own drawing after the results arrived and its drawing processes' (their
total and the longest); all figure processes' CPU. On two free cores the figures add to the wall time
about the main process's extra CPU plus the longer of the costliest drawing process and all the
drawing CPU over two cores, once the warm-up ends before the solve does; on a busy machine, about all
the figure processes' CPU stretched by the load.

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
                           ("each in a process of its own, at once, on frames built ahead (forked once the results are there)",
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


def fresh_run(mode: str, out: str, plots: bool) -> dict:
    """``exucable run -q`` of the fast Example 2 in this process, a fresh one (a child of
    :func:`critical_paths`: nothing but the standard library loaded before it, as in the command,
    so that the figures' helper is forked as there), then its parts: this process's own CPU time
    [s] and minor page faults, its children's CPU time [s], the bytes sent to the helper and the
    helper's CPU times (:attr:`exucable.output.figure_process.Figures.helper_cpu_s`)."""
    import dataclasses
    import pickle
    import resource

    from exucable import cli
    from exucable.output import figure_process

    got = {}
    write = figure_process.Figures.write

    def noting(self, out_dir, result, while_drawing=None):
        paths = write(self, out_dir, result, while_drawing)
        got["result"], got["cpu"] = result, dict(self.helper_cpu_s)
        return paths

    figure_process.Figures.write = noting
    cli.main(["run", str(SCENARIO), "-q", "--mode", mode, "-o", out] + ([] if plots else ["--no-plots"]))
    me, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    sent = (len(pickle.dumps((out, dataclasses.replace(got["result"], model=None)))) if "result" in got else 0)
    return {"self_cpu_s": me.ru_utime + me.ru_stime, "minor_faults": me.ru_minflt,
            "children_cpu_s": children.ru_utime + children.ru_stime, "sent_bytes": sent, "helper": got.get("cpu", {})}


CRITICAL_ROWS = (("main", "the main process's extra CPU with figures (its own CPU, fresh `exucable run` with figures less without)"),
                 ("faults", "  of it, its extra minor page faults (copies on write after the fork) [count]"),
                 ("sent_bytes", "  the results sent to the helper, pickled [bytes]"),
                 ("warm_up_s", "helper: matplotlib's import, warm-up and frames, beside the solve"),
                 ("forks_warm_up_s", "drawing processes forked ahead: their frames, beside the solve (total)"),
                 ("draw_s", "helper: drawing its own figure after the results arrived"),
                 ("forks_draw_s", "its drawing processes: drawing the other figures at the same time, total"),
                 ("longest_fork_draw_s", "its drawing processes: the longest one"),
                 ("children", "all figure processes' CPU (helper and drawing processes)"),
                 ("estimate", "figures' wall cost on two free cores, estimated: extra CPU + max(longest drawing, all drawing / 2)"))


def critical_paths(repeat: int, modes: list[str], before: str | None) -> None:
    """The figures' critical path from CPU times, per mode (and tree, with ``before``), from fresh
    processes that run the command as ``exucable run`` does (:func:`fresh_run`), ``--no-plots`` and
    with figures, interleaved ``repeat`` times after one warm-up round; medians. The main process's
    extra CPU is the difference of the two medians of its own CPU time (its children's excluded)."""
    trees = {"before": before, "after": None} if before else {"": None}
    cases = [(mode, label, plots) for mode in modes for label in trees for plots in (False, True)]
    runs = {c: [] for c in cases}
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(repeat + 1):
            for mode, label, plots in cases:
                done = subprocess.run([sys.executable, __file__, "--fresh-run", mode, f"{tmp}/{mode}{label}{plots}"]
                                      + ([] if plots else ["--no-plots"]), capture_output=True, text=True,
                                      env=_env(trees[label]))
                if done.returncode != 0:
                    raise RuntimeError(f"fresh run ({mode} {label}) failed:\n{done.stderr[-2000:]}")
                if k:           # the first round warms the disk, numba's and matplotlib's caches
                    runs[(mode, label, plots)].append(json.loads(done.stdout.strip().splitlines()[-1]))
    med = statistics.median
    got = {}
    for mode in modes:
        for label in trees:
            none, fig = runs[(mode, label, False)], runs[(mode, label, True)]
            h = [r["helper"] for r in fig]
            row = {"main": med(r["self_cpu_s"] for r in fig) - med(r["self_cpu_s"] for r in none),
                   "faults": med(r["minor_faults"] for r in fig) - med(r["minor_faults"] for r in none),
                   "sent_bytes": med(r["sent_bytes"] for r in fig),
                   "children": med(r["children_cpu_s"] for r in fig)}
            for key in ("warm_up_s", "forks_warm_up_s", "draw_s", "forks_draw_s", "longest_fork_draw_s"):
                row[key] = med(x.get(key, 0.0) for x in h)
            row["estimate"] = max(row["main"], 0.0) + med(
                max(max(x["draw_s"], x.get("longest_fork_draw_s", 0.0)), (x["draw_s"] + x.get("forks_draw_s", 0.0)) / 2)
                for x in h)
            got[(mode, label)] = row
    print(f"\n| figures' critical path (fresh processes, CPU [s], median of {repeat}; load average "
          f"{os.getloadavg()[0]:.1f}) | " + " | ".join(f"{m}{' ' + lab if lab else ''}" for m, lab in got) + " |")
    print("|---|" + "---|" * len(got))
    for key, what in CRITICAL_ROWS:
        fmt = "{:.0f}" if key in ("faults", "sent_bytes") else "{:.3f}"
        print(f"| {what} | " + " | ".join(fmt.format(got[c][key]) for c in got) + " |")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="interleaved rounds (default 5)")
    ap.add_argument("--steady", action="store_true", help="also in steady mode")
    ap.add_argument("--before", metavar="TREE", help="also with the exucable package of source tree TREE, interleaved")
    ap.add_argument("--fresh-run", nargs=2, metavar=("MODE", "OUT"), help=argparse.SUPPRESS)   # a child of critical_paths
    ap.add_argument("--no-plots", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--quick", action="store_true", help="smoke run: one round, no breakdown")
    ap.add_argument("--no-whole", action="store_true", help="skip part 1 (the whole processes)")
    args = ap.parse_args(argv)
    if args.fresh_run:
        print(json.dumps(fresh_run(*args.fresh_run, plots=not args.no_plots)), flush=True)
        os._exit(0)             # as the command ends (exucable.cli.end_process)
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
