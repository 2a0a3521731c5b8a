"""``exucable compare A B``: cross-check two sets of results (see :mod:`exucable.compare`)."""

from __future__ import annotations

import argparse
import math

from ..compare import DEFAULT_RTOL, compare_results, format_report, write_overlay_plot
from ..errors import ExucableError

__all__ = ["add_arguments", "main"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the ``compare`` subcommand's arguments to ``parser``."""
    parser.add_argument("a", help="reference results: a result directory or a tension_profile/history CSV")
    parser.add_argument("b", help="results to check, same kinds as A (interpolated onto A's abscissa)")
    parser.add_argument("--rtol", type=float, default=DEFAULT_RTOL,
                        help=f"largest allowed relative max difference, relative to max |A| (default {DEFAULT_RTOL:g})")
    parser.add_argument("--out", default=None, help="write an overlay plot (PNG) to this path")


def main(args: argparse.Namespace) -> int:
    """Run ``exucable compare``; print the table, write the plot if asked; 1 if A and B differ beyond rtol."""
    if not (args.rtol >= 0.0 and math.isfinite(args.rtol)):
        raise ExucableError(f"--rtol must be a finite number >= 0, got {args.rtol!r}")
    result = compare_results(args.a, args.b, rtol=args.rtol)
    print(format_report(result))
    if args.out:
        print(f"overlay plot: {write_overlay_plot(result, args.out)}")
    return 0 if result["passed"] else 1

