"""``exucable validate``: the paper's examples (default), the published industry pulls and three cables
in one duct (``--suite bundle``) against their references, one table each."""

from __future__ import annotations

import sys
from pathlib import Path

from ..validation.paper import CASES, MODES, format_table, validate

__all__ = ["add_arguments", "main", "SUITES"]

SUITES = ("paper", "industry", "bundle", "all")


def add_arguments(p) -> None:
    p.add_argument("--suite", choices=SUITES, default="paper",
                   help="paper: the paper's examples (default); industry: the published worked pulls of "
                        "scenarios/industry (minutes per route); bundle: three cables in one duct against "
                        "the rigid-circle closed forms (minutes); all: the three")
    p.add_argument("--fast", action="store_true",
                   help="paper: coarse variants (scenarios/fast), looser tolerances; industry: the default mesh "
                        "only (no refined run, no mesh check); bundle: the unit tests' coarse meshes, fewer D/d")
    p.add_argument("--out", "-o", default="validation",
                   help="output directory (default: validation/; the industry and bundle suites write into "
                        "industry/ and bundle/ there)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress output")
    p.add_argument("--case", action="append", choices=list(CASES),
                   help="paper suite: run only these cases (repeatable)")
    p.add_argument("--example", action="append", metavar="NAME",
                   help="industry suite: run only the examples whose scenario file name contains NAME (repeatable)")
    p.add_argument("--levels", type=int, default=3,
                   help="industry suite: mesh levels, the default mesh then each refined by 2 (default 3: "
                        "Richardson extrapolation; 2: the refined value)")
    p.add_argument("--mode", action="append", choices=list(MODES),
                   help="run only these solver modes (repeatable; default: paper both, and their difference; "
                        "industry steady only, as the dynamic runs take minutes to tens of minutes per route)")


def _say(line: str) -> None:
    print(line, flush=True)


def _paper(args) -> int:
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
        agree = sum(d.agrees for d in diffs)
        same = sum(d.same_state for d in diffs)
        print(f"steady and dynamic agree within 0.2 % on {agree}/{len(diffs)} checks ({same} compared in the "
              f"same state: the steady cable laid out as far as the dynamic run had pulled it)"
              + ("" if agree == len(diffs) else "; reference/README.md explains the others"))
    return 1 if n_fail or vr.failures else 0


def _industry(args) -> int:
    from ..validation.industry import format_industry_table, load_industry_examples, validate_industry
    if args.levels < 1:
        print(f"exucable validate: error: --levels: at least 1 (3 for an extrapolation), got {args.levels}",
              file=sys.stderr)
        return 2
    examples = load_industry_examples()
    if args.example:
        examples = [e for e in examples if any(n in e["scenario"] for n in args.example)]
        if not examples:
            print(f"exucable validate: error: --example: no industry example matches {args.example}; the scenario "
                  f"files are {sorted({e['scenario'] for e in load_industry_examples()})}", file=sys.stderr)
            return 2
    out = Path(args.out) / "industry"
    iv = validate_industry(fast=args.fast, out_dir=out, quiet=args.quiet, modes=tuple(args.mode or ("steady",)),
                           examples=examples, progress=None if args.quiet else _say, levels=args.levels)
    print(format_industry_table(iv))
    for n in iv.skipped:
        print(f"industry: skipped {n}")
    for f in iv.failures:
        print(f"industry: FAIL {f}", file=sys.stderr)
    n_pass = sum(r.passed for r in iv.rows)
    times = ", ".join(f"{m} {t:.1f} s" for m, t in iv.mode_wall_time_s.items())
    print(f"\nindustry: {n_pass}/{len(iv.rows)} example rows passed every check in {iv.wall_time_s:.1f} s ({times}); "
          f"table and figure in {out}/")
    return 1 if iv.failures else 0


def _bundle(args) -> int:
    from ..validation.bundle import format_bundle_table, validate_bundle
    out = Path(args.out) / "bundle"
    bv = validate_bundle(fast=args.fast, out_dir=out, progress=None if args.quiet else _say)
    print(format_bundle_table(bv))
    for f in bv.failures:
        print(f"bundle: FAIL {f}", file=sys.stderr)
    n_pass = sum(c.passed for c in bv.checks)
    print(f"\nbundle: {n_pass}/{len(bv.checks)} checks passed in {bv.cpu_time_s:.1f} s CPU ({bv.wall_time_s:.1f} s "
          f"wall); table in {out}/")
    return 1 if bv.failures else 0


def main(args) -> int:
    from .compile import announce_compiling

    announce_compiling()
    status = 0
    if args.suite in ("paper", "all"):
        status = max(status, _paper(args))
    if args.suite in ("industry", "all"):
        status = max(status, _industry(args))
    if args.suite in ("bundle", "all"):
        status = max(status, _bundle(args))
    return status
