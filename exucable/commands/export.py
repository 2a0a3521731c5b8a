"""``exucable export SCENARIO DIR``: write a scenario's exact discrete problem (see ``docs/results-format.md``)."""

from __future__ import annotations

from pathlib import Path

__all__ = ["add_arguments", "main"]


def add_arguments(p) -> None:
    p.add_argument("scenario", help="scenario file (TOML), or a shipped scenario's name "
                                    "(`exucable scenarios` lists them)")
    p.add_argument("out", help="directory to write problem.json and the CSV tables into")
    p.add_argument("--mode", choices=("dynamic", "steady"), default=None,
                   help="override solver.mode: the problem of that mode (as exucable run --mode)")


def main(args) -> int:
    from ..output.export import export_problem

    written = export_problem(args.scenario, Path(args.out), mode=args.mode)   # checks the directory before building
    print(f"exported {len(written)} files to {args.out}/: " + ", ".join(p.name for p in written))
    return 0
