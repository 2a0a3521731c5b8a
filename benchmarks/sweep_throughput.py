"""Throughput of a steady-mode sweep at engineering scale: 500 cases on the local pool and on a Dask
cluster, in cases per minute per core.

The sweep: ``tests/data/sweep/tiny_bend.toml`` (a bend between two 0.5 m straights, 8 elements) in
steady mode, friction (10 values, 0.10-0.46) × back tension (10 values, 5-50 N) × the bend's angle
(5 route variants, 30-90°: the base's 8 elements follow a bend of up to about 100°) = 500 cases, each in its own process on the local pool (``forkserver``,
modules preloaded) and, if Dask's distributed scheduler is installed, on a ``LocalCluster`` of as many
single-threaded worker processes as the pool has workers. Figures are off (``--plots``: on), as an
engineering sweep would run; ``sweep.csv`` and ``sweep.png`` are written as always.

For each runner it prints the cases finished, the wall time, the cases per minute per core (wall),
each case's median wall, CPU (in its process: ``case.json``'s ``cpu_time_s``) and solver time, and the
CPU time of this process and the processes it waited for (the Dask workers, counted once the cluster
is closed; not the pool's case processes, which are the fork server's children), all measured in this
one run. Then it checks resumability: the same sweep run again into the same directory runs
no case.

    nice .venv/bin/python benchmarks/sweep_throughput.py                 # 500 cases, both runners
    nice .venv/bin/python benchmarks/sweep_throughput.py --out DIR       # keep DIR; a rerun resumes
    nice .venv/bin/python benchmarks/sweep_throughput.py --quick         # 4 cases (a smoke run)
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

from exucable.sweep import default_workers, parse_sweep, run_sweep
from exucable.sweep.store import case_dir, read_record

ROOT = Path(__file__).resolve().parents[1]
BASE = ROOT / "tests" / "data" / "sweep" / "tiny_bend.toml"


def make_sweep(frictions: int, back_tensions: int, angles: int):
    """The grid friction × back tension × bend angle of the tiny bend, in steady mode."""
    vary = {"contact.friction": [round(0.10 + 0.04 * i, 4) for i in range(frictions)],
            "pull.back_tension": [round(5.0 + 5.0 * i, 4) for i in range(back_tensions)],
            "conduit.path[1].bend": [round(30.0 + 15.0 * i, 4) for i in range(angles)]}
    return parse_sweep({"base": str(BASE), "name": "throughput", "set": {"solver.mode": "steady"}, "vary": vary},
                       ROOT, default_name="throughput")


def cpu_s() -> float:
    """CPU time [s] of this process and its waited-for children."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def timed(label: str, sweep, out: Path, workers: int, plots: bool, scheduler=None) -> dict:
    c0, t0 = cpu_s(), time.perf_counter()
    if scheduler == "dask":
        import distributed
        with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                                      dashboard_address=None) as cluster:
            t_up = time.perf_counter() - t0
            rows = run_sweep(sweep, out, scheduler=cluster.scheduler_address, plots=plots)
    else:
        t_up = 0.0
        rows = run_sweep(sweep, out, workers=workers, plots=plots)
    wall, cpu = time.perf_counter() - t0, cpu_s() - c0
    records = [read_record(case_dir(out, r["case"])) or {} for r in rows]

    def median(key):
        values = [r[key] for r in records if isinstance(r.get(key), (int, float))]
        return statistics.median(values) if values else float("nan")

    return {"label": label, "cases": len(rows), "ok": sum(r["status"] in ("ok", "steady") for r in rows),
            "wall_s": wall, "cpu_s": cpu, "startup_s": t_up, "case_cpu_s": median("cpu_time_s"),
            "case_wall_s": median("wall_time_s"), "solver_s": median("solver_wall_time_s")}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=None, help="pool workers and Dask workers (default: the cores)")
    ap.add_argument("--out", type=Path, default=None,
                    help="keep the sweeps in DIR/pool and DIR/dask (default: a temporary directory, removed); "
                         "run again with the same DIR to resume")
    ap.add_argument("--plots", action="store_true", help="write each case's figures too")
    ap.add_argument("--no-dask", action="store_true", help="the local pool only")
    ap.add_argument("--quick", action="store_true", help="smoke run: 4 cases (2 frictions × 2 back tensions)")
    args = ap.parse_args(argv)
    sweep = make_sweep(2, 2, 1) if args.quick else make_sweep(10, 10, 5)
    workers = args.workers or default_workers()
    n = len(sweep.cases)
    try:
        import distributed  # noqa: F401
        dask = not args.no_dask
    except ImportError:
        dask = False
    root = args.out or Path(tempfile.mkdtemp(prefix="exucable-sweep-throughput-"))
    print(f"# steady sweep of {n} cases ({BASE.relative_to(ROOT)}: friction × back tension × bend angle), "
          f"{workers} workers, figures {'on' if args.plots else 'off'}; {os.cpu_count()} cores, load average "
          f"{os.getloadavg()[0]:.1f}\n")
    results = []
    try:
        results.append(timed("local pool", sweep, root / "pool", workers, args.plots))
        if dask:
            results.append(timed("Dask LocalCluster", sweep, root / "dask", workers, args.plots, scheduler="dask"))
        again = timed("local pool, run again (resumed)", sweep, root / "pool", workers, args.plots)
    finally:
        if args.out is None:
            shutil.rmtree(root, ignore_errors=True)
    print("| runner | cases (ok) | wall [s] | cases/min/core (wall) | per case, median: wall / CPU / solver [s] "
          "| CPU of this process and the processes it waited for [s] |")
    print("|---|---|---|---|---|---|")
    for r in results + [again]:
        rate = 60.0 * r["cases"] / r["wall_s"] / workers
        up = f" (cluster start {r['startup_s']:.1f} s)" if r["startup_s"] else ""
        print(f"| {r['label']} | {r['cases']} ({r['ok']}) | {r['wall_s']:.1f}{up} | {rate:.1f} | "
              f"{r['case_wall_s']:.3f} / {r['case_cpu_s']:.3f} / {r['solver_s']:.3f} | {r['cpu_s']:.1f} |")
    print(f"\nresumed: the second run of the pool's sweep found every case finished and took {again['wall_s']:.1f} s; "
          f"load average after: {os.getloadavg()[0]:.1f}")
    return 0 if all(r["ok"] == r["cases"] for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
