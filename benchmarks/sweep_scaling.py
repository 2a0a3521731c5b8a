"""Throughput of ``exucable sweep`` on the local process pool: cases per minute with 1 and 2 workers.

A sweep of small real cases (``tests/data/sweep/tiny_bend.toml``: a 90° bend, 8 ANCF elements,
friction varied) is run, each time into a fresh directory, with

- the cases one after another in this process (``run_scenario``, no pool; after the first case
  every import and compiled function is warm);
- the pool with 1 worker and with 2 workers (``forkserver``, modules preloaded);
- the pool with 2 workers on the ``spawn`` context (every case imports numpy/scipy/Exudyn itself).

Prints the best wall time of ``--repeat`` interleaved rounds, cases per minute and the 2-worker /
1-worker throughput ratio, all measured in this one run. The machine's load average is printed too: on a shared machine the ratio can only
be as good as the idle cores.

Run: ``.venv/bin/python benchmarks/sweep_scaling.py [--cases 4] [--repeat 2]`` (about a minute);
``--quick``: 2 cases, one round (a smoke run).
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time
from pathlib import Path

from exucable.run import run_scenario
from exucable.sweep import parse_sweep, run_sweep, worker_context

ROOT = Path(__file__).resolve().parents[1]
BASE = ROOT / "tests" / "data" / "sweep" / "tiny_bend.toml"


def make_sweep(n: int):
    """``n`` cases: contact.friction = 0.10, 0.11, ... (distinct scenarios, similar cost)."""
    frictions = [round(0.10 + 0.01 * i, 4) for i in range(n)]
    return parse_sweep({"base": str(BASE), "name": "scaling", "vary": {"contact.friction": frictions}},
                       ROOT, default_name="scaling")


def timed_pool(sweep, workers: int, method: str) -> tuple[float, int]:
    out = Path(tempfile.mkdtemp(prefix=f"exucable-bench-{method}-{workers}-"))
    try:
        t0 = time.perf_counter()
        rows = run_sweep(sweep, out, workers=workers, plots=False, mp_context=worker_context(method))
        wall = time.perf_counter() - t0
    finally:
        shutil.rmtree(out, ignore_errors=True)
    return wall, sum(r["status"] in ("ok", "steady") for r in rows)


def timed_inline(sweep) -> tuple[float, int]:
    """The cases one after another in this process, writing the same files as a sweep."""
    out = Path(tempfile.mkdtemp(prefix="exucable-bench-inline-"))
    try:
        t0 = time.perf_counter()
        ok = 0
        for i, case in enumerate(sweep.cases):
            summary = run_scenario(case.scenario, out / str(i), plots=False).summary
            ok += summary["status"] in ("ok", "steady")
        wall = time.perf_counter() - t0
    finally:
        shutil.rmtree(out, ignore_errors=True)
    return wall, ok


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=4, help="cases in the sweep (default 4)")
    ap.add_argument("--repeat", type=int, default=2,
                    help="rounds; each configuration's best round is reported (default 2)")
    ap.add_argument("--quick", action="store_true", help="smoke run: 2 cases, one round")
    args = ap.parse_args(argv)
    if args.quick:
        args.cases, args.repeat = 2, 1
    sweep = make_sweep(args.cases)
    n = len(sweep.cases)
    print(f"sweep of {n} cases on {BASE.relative_to(ROOT)}; cores available: {len(os.sched_getaffinity(0))}; "
          f"load average before: {os.getloadavg()[0]:.2f}")
    runs = {
        "in-process, sequential": lambda: timed_inline(sweep),
        "pool forkserver, 1 worker": lambda: timed_pool(sweep, 1, "forkserver"),
        "pool forkserver, 2 workers": lambda: timed_pool(sweep, 2, "forkserver"),
        "pool spawn, 2 workers": lambda: timed_pool(sweep, 2, "spawn"),
    }
    walls: dict[str, list[float]] = {k: [] for k in runs}
    ok: dict[str, int] = {}
    # rounds interleave the configurations, so that a burst of load from other processes on a
    # shared machine hits one round of each rather than every round of one
    for _ in range(args.repeat):
        for label, fn in runs.items():
            wall, ok[label] = fn()
            walls[label].append(wall)
    best = {k: min(v) for k, v in walls.items()}
    print(f"{'configuration':30s} {'best wall [s]':>13s} {'cases/min':>10s} {'ok':>4s}   all rounds [s]")
    for label in runs:
        print(f"{label:30s} {best[label]:13.2f} {60.0 * n / best[label]:10.1f} {ok[label]:4d}   "
              + " ".join(f"{w:.2f}" for w in walls[label]))
    w1, w2 = best["pool forkserver, 1 worker"], best["pool forkserver, 2 workers"]
    print(f"throughput ratio 2 workers / 1 worker: {w1 / w2:.2f} (ideal 2.00)")
    print(f"pool overhead, 1 worker vs in-process: {100.0 * (w1 / best['in-process, sequential'] - 1):+.1f} % "
          f"({(w1 - best['in-process, sequential']) / n:.2f} s per case)")
    print(f"spawn / forkserver wall time, 2 workers: {best['pool spawn, 2 workers'] / w2:.2f}")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
