"""``exucable validate``: the paper's examples against their references, one table."""

from __future__ import annotations

import sys

from ..validate import CASES, MODES, format_table, validate

__all__ = ["add_arguments", "main"]


def add_arguments(p) -> None:
    p.add_argument("--fast", action="store_true", help="coarse variants (scenarios/fast), looser tolerances")
    p.add_argument("--out", "-o", default="validation", help="output directory (default: validation/)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress output")
    p.add_argument("--case", action="append", choices=list(CASES),
                   help="run only these cases (repeatable)")
    p.add_argument("--mode", action="append", choices=list(MODES),
                   help="run only these solver modes (repeatable; default: both, and their difference)")


def _say(line: str) -> None:
    print(line, flush=True)


def main(args) -> int:
    vr = validate(fast=args.fast, out_dir=args.out, quiet=args.quiet, cases=args.case,
                  progress=None if args.quiet else _say, modes=tuple(args.mode) if args.mode else MODES)
    print(format_table(vr))
    for case, msg in vr.failures:
        print(f"{case}: run failed: {msg}", file=sys.stderr)
    n_fail = sum(not c.passed for c in vr.checks)
    times = ", ".join(f"{m} {t:.1f} s" for m, t in vr.mode_wall_time_s.items())
    print(f"\n{len(vr.checks) - n_fail}/{len(vr.checks)} checks passed in {vr.wall_time_s:.1f} s ({times}); "
          f"table and figures in {args.out}/")
    diffs = vr.differences
    if diffs:
        print(f"steady and dynamic agree within 0.2 % on {sum(d.agrees for d in diffs)}/{len(diffs)} checks "
              f"(reference/README.md explains the others)")
    return 1 if n_fail or vr.failures else 0
