"""``exucable compare A B``: cross-check two sets of results (see :mod:`exucable.output.compare`)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from ..output.compare import (
    DEFAULT_RTOL,
    compare_results,
    format_report,
    load_tolerances,
    write_overlay_plot,
    write_overlay_plots,
)
from ..errors import ExucableError
from ..output.outdir import check_out_dir, check_out_file

__all__ = ["add_arguments", "main"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the ``compare`` subcommand's arguments to ``parser``."""
    parser.add_argument("a", help="reference results: a result directory or one results CSV")
    parser.add_argument("b", help="results to check, same kinds as A (interpolated onto A's abscissa)")
    parser.add_argument("--rtol", type=float, default=DEFAULT_RTOL,
                        help=f"relative tolerance on max |B-A|, relative to max |A| (default {DEFAULT_RTOL:g})")
    parser.add_argument("--atol", type=float, default=0.0,
                        help="absolute tolerance on max |B-A|, in each quantity's unit (default 0)")
    parser.add_argument("--tolerances", default=None,
                        help="TOML of per-quantity tolerances: [default], [pull_force_N], [snapshot_contact.normal_force_N], "
                             "... each with rtol and/or atol (overrides --rtol/--atol)")
    parser.add_argument("--allow-partial", action="store_true",
                        help="pass on what A and B both have; by default B must cover every file, column, "
                             "snapshot time and abscissa range of A")
    parser.add_argument("--out", default=None,
                        help="overlay figures: a directory (one PNG per quantity) or a .png path (all in one)")


def main(args: argparse.Namespace) -> int:
    """Run ``exucable compare``; print the table, write the figures if asked; 1 if beyond a tolerance."""
    for name in ("rtol", "atol"):
        value = getattr(args, name)
        if not (value >= 0.0 and math.isfinite(value)):
            raise ExucableError(f"--{name} must be a finite number >= 0, got {value!r}")
    tolerances = load_tolerances(args.tolerances) if args.tolerances else None
    if args.out:     # checked before comparing: a bad --out is refused in one line, up front
        out = Path(args.out)
        check_out_file(out) if out.suffix.lower() == ".png" else check_out_dir(out)
    result = compare_results(args.a, args.b, rtol=args.rtol, atol=args.atol, tolerances=tolerances,
                             allow_partial=args.allow_partial)
    print(format_report(result))
    if args.out:
        out = Path(args.out)
        if out.suffix.lower() == ".png":
            print(f"overlay plot: {write_overlay_plot(result, out)}")
        else:
            paths = write_overlay_plots(result, out)
            print(f"overlay plots: {len(paths)} in {out}/")
    return 0 if result["passed"] else 1
