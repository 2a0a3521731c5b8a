"""``exucable export SCENARIO DIR``: write a scenario's exact discrete problem (see ``docs/results-format.md``)."""

from __future__ import annotations

from pathlib import Path

__all__ = ["add_arguments", "main"]


def add_arguments(p) -> None:
    p.add_argument("scenario", help="scenario file (TOML), or a shipped scenario's name "
                                    "(`exucable scenarios` lists them)")
    p.add_argument("out", help="directory to write problem.json and the CSV tables into")


def main(args) -> int:
    from ..output.export import export_problem

    written = export_problem(args.scenario, Path(args.out))
    print(f"exported {len(written)} files to {args.out}/: " + ", ".join(p.name for p in written))
    return 0
