"""Wall time of each industry route (``scenarios/industry/``, ``reference/industry_values.toml``) in each
solver mode, on the default mesh and (``--refined``) the refined one, as ``exucable validate --suite industry``
runs them.

    nice .venv/bin/python benchmarks/industry_suite.py [--mode steady] [--mode dynamic] [--refined]
        [--example NAME] [--out DIR] [--json FILE]
    nice .venv/bin/python benchmarks/industry_suite.py --quick   # one route, steady, default mesh, into a temporary folder

Prints one row per route, mode and mesh level: elements, wall time of the solve and of the whole run
(model build, references and output included), the pulling force and the run's status. The machine is
shared: compare the rows of one run with each other, not with another day's.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

from exucable.io import write_json
from exucable.validation.industry import load_industry_examples, validate_industry


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--mode", action="append", choices=("steady", "dynamic"), help="default: steady")
    p.add_argument("--refined", action="store_true", help="also the mesh refined by 2 (the suite's mesh check)")
    p.add_argument("--example", action="append", metavar="NAME", help="only scenario files containing NAME")
    p.add_argument("--out", default="out/industry-benchmark")
    p.add_argument("--json", default=None, help="also write the rows here")
    p.add_argument("--quick", action="store_true",
                   help="the Gera worked example only, steady mode, default mesh, results in a temporary folder")
    args = p.parse_args(argv)
    examples = load_industry_examples()
    if args.quick:
        args.example, args.mode, args.refined = ["gera"], ["steady"], False
    if args.example:
        examples = [e for e in examples if any(n in e["scenario"] for n in args.example)]
    if args.quick:
        with tempfile.TemporaryDirectory() as tmp:
            args.out = tmp
            return run(args, examples)
    return run(args, examples)


def run(args, examples) -> int:
    """Time each of ``examples`` in each of ``args.mode``; print a row per mesh level."""
    rows = []
    print(f"{'example':<42} {'mode':<8} {'level':>5} {'elements':>8} {'solve [s]':>10} {'run [s]':>8} "
          f"{'pull force [N]':>15} status", flush=True)
    for mode in args.mode or ["steady"]:
        for ex in examples:
            t0 = time.perf_counter()
            iv = validate_industry(fast=not args.refined, out_dir=Path(args.out) / f"{Path(ex['scenario']).stem}-"
                                   f"{ex['direction']}", modes=(mode,), examples=[ex])
            total = time.perf_counter() - t0
            if not iv.rows:
                print(f"{ex['scenario']} ({ex['direction']}): skipped: {'; '.join(iv.skipped)}", flush=True)
                continue
            (r,) = iv.rows
            for level, (n, wall, value, status) in enumerate(zip(r.elements, r.wall_time_s, r.values_N, r.statuses)):
                rows.append({"example": r.example, "mode": mode, "level": level, "elements": n, "solve_wall_s": wall,
                             "suite_wall_s": total, "pull_force_N": value, "status": status})
                print(f"{r.example:<42} {mode:<8} {level:>5} {n:>8} {wall:>10.1f} {total:>8.1f} {value:>15.6g} "
                      f"{status}", flush=True)
    if args.json:
        write_json(args.json, {"rows": rows, "argv": sys.argv[1:]})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
