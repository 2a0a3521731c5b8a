"""Fixed cost of ``exucable run``, measured in one run.

A trivial scenario (the fast Example 2 over one 1 ms step) is run as a whole process, with and
without figures, interleaved with ``python -c "import exudyn"`` (the floor: interpreter + Exudyn)
and with the numba floor (Exudyn, numba and numba's CPU target initialised, which any process
running a cached numba kernel pays), ``--repeat`` times each, after one warm-up that fills numba's
cache (``exucable compile``); medians of wall time and of CPU time (user + system, less disturbed by
the other jobs on a shared machine) are compared. Then one ``-X importtime`` run says which imports
the rest is made of.

    nice .venv/bin/python benchmarks/fixed_cost.py             # ~30 s
    nice .venv/bin/python benchmarks/fixed_cost.py --repeat 9
    nice .venv/bin/python benchmarks/fixed_cost.py --before /path/to/main-tree   # before/after
    nice .venv/bin/python benchmarks/fixed_cost.py --quick     # one repeat, no import table

Target: ``exucable run --no-plots`` within 1.0 s of ``import exudyn``.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FLOOR_CASE = "numba floor: import exudyn, numba + target init"
RUN_CASE = "exucable run --no-plots"
NUMBA_FLOOR = "import exudyn, numba; from numba.core.registry import cpu_target; cpu_target.target_context.refresh()"


def trivial_scenario(directory: Path) -> Path:
    """The fast Example 2 cut to one step of 1 ms."""
    text = (ROOT / "scenarios" / "fast" / "paper_ex2_bend90.toml").read_text()
    text = re.sub(r"(?m)^end_time = .*$", "end_time = 0.001", text)
    text = re.sub(r"(?m)^step = .*$", "step = 1.0e-3", text)
    text = re.sub(r'(?m)^name = .*$', 'name = "trivial"', text)
    path = directory / "trivial.toml"
    path.write_text(text)
    return path


def timed(cmd, out_dir: Path | None = None, env: dict | None = None) -> tuple[float, float]:
    """Whole-process wall time and CPU time [s] of ``cmd``. A run of 1 ms cannot be steady: ``exucable run``
    then exits 1 with status ``not_steady`` (the trust flags), which is accepted here, checked in
    ``out_dir/summary.json``; any other failure raises."""
    c0, t0 = os.times(), time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True, env=env)
    dt, c1 = time.perf_counter() - t0, os.times()
    if out.returncode != 0:
        summary = out_dir / "summary.json" if out_dir is not None else None
        status = json.loads(summary.read_text()).get("status") if summary and summary.exists() else None
        if status != "not_steady":
            raise RuntimeError(f"{' '.join(map(str, cmd))} failed (status {status}):\n{out.stderr[-2000:]}")
    return dt, (c1.children_user - c0.children_user) + (c1.children_system - c0.children_system)


def top_imports(cmd, n=8):
    """The slowest top-level imports (cumulative) of one ``-X importtime`` run."""
    out = subprocess.run([sys.executable, "-X", "importtime", *cmd], capture_output=True, text=True)
    rows = []
    for line in out.stderr.splitlines():
        m = re.match(r"import time:\s+(\d+) \|\s+(\d+) \|( *)(\S+)", line)
        if m and len(m.group(3)) <= 1:          # top level only
            rows.append((int(m.group(2)) / 1e6, m.group(4)))
    return sorted(rows, reverse=True)[:n]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--before", type=Path, default=None,
                    help="another exucable source tree (e.g. `git archive main` unpacked) to run interleaved "
                         "with this one, through PYTHONPATH; warm its numba cache first")
    ap.add_argument("--quick", action="store_true", help="one repeat and no import table (a smoke run)")
    args = ap.parse_args(argv)
    if args.quick:
        args.repeat = 1
    exe = Path(sys.executable).with_name("exucable")
    subprocess.run([str(exe), "compile", "--quiet"], check=False)
    env_default = dict(os.environ)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        sc = trivial_scenario(tmp)
        cases = {
            "python -c 'import exudyn'": [sys.executable, "-c", "import exudyn"],
            # what any run of a numba kernel pays before its first cached function: numba's import and
            # its CPU target's registries (numba.np.linalg, which imports scipy.linalg for BLAS, ...)
            FLOOR_CASE: [sys.executable, "-c", NUMBA_FLOOR],
            RUN_CASE: [str(exe), "run", str(sc), "-o", str(tmp / "a"), "-q", "--no-plots"],
            "exucable run (figures)": [str(exe), "run", str(sc), "-o", str(tmp / "b"), "-q"],
        }
        outs = {RUN_CASE: tmp / "a", "exucable run (figures)": tmp / "b"}
        envs = {RUN_CASE: env_default, "exucable run (figures)": env_default}
        if args.before is not None:
            before = f"exucable run --no-plots ({args.before.name})"
            cases[before] = [str(exe), "run", str(sc), "-o", str(tmp / "c"), "-q", "--no-plots"]
            outs[before] = tmp / "c"
            envs[before] = dict(os.environ, PYTHONPATH=str(args.before.resolve()))
            timed(cases[before], outs[before], envs[before])
        timed(cases[RUN_CASE], outs[RUN_CASE], envs[RUN_CASE])      # warm the disk and kernel caches
        times = {k: [] for k in cases}
        load0 = os.getloadavg()[0]
        for _ in range(args.repeat):
            for k, cmd in cases.items():
                times[k].append(timed(cmd, outs.get(k), envs.get(k)))
        med = {k: statistics.median(w for w, _ in v) for k, v in times.items()}
        cpu = {k: statistics.median(c for _, c in v) for k, v in times.items()}
        floor, cpu_floor = med["python -c 'import exudyn'"], cpu["python -c 'import exudyn'"]
        print(f"# Fixed cost of exucable run — load average {load0:.1f} -> {os.getloadavg()[0]:.1f} "
              f"on {os.cpu_count()} cores, median of {args.repeat} interleaved runs\n")
        print("| command | wall, median [s] | above import exudyn [s] | CPU, median [s] | CPU above import exudyn [s] "
              "| all runs, wall [s] |\n|---|---|---|---|---|---|")
        for k, v in times.items():
            print(f"| {k} | {med[k]:.3f} | {med[k] - floor:+.3f} | {cpu[k]:.2f} | {cpu[k] - cpu_floor:+.2f} | "
                  f"{', '.join(f'{w:.2f}' for w, _ in v)} |")
        print(f"\ntarget: exucable run --no-plots within 1.0 s of import exudyn: "
              f"{med[RUN_CASE] - floor:.2f} s wall, {cpu[RUN_CASE] - cpu_floor:.2f} s CPU; "
              f"the numba floor alone: {med[FLOOR_CASE] - floor:.2f} s wall, {cpu[FLOOR_CASE] - cpu_floor:.2f} s CPU")
        if args.quick:
            return 0
        print("\nslowest top-level imports of `exucable run --no-plots` (-X importtime, cumulative):\n")
        for seconds, name in top_imports(["-m", "exucable", *cases[RUN_CASE][1:]]):
            print(f"- {name}: {seconds:.3f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
