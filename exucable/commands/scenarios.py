"""``exucable scenarios``: the scenarios shipped with exucable, by the names every command takes."""

from __future__ import annotations

__all__ = ["add_arguments", "main"]


def add_arguments(p) -> None:
    p.add_argument("--paths", action="store_true", help="also print each file's path")


def main(args) -> int:
    from ..data import shipped_scenarios
    from ..scenario.specs import read_toml

    shipped = shipped_scenarios()
    width = max(len(n) for n in shipped)
    print("Shipped scenarios (give the name to any command, e.g. `exucable run fast/paper_ex2_bend90`):")
    for name, path in shipped.items():
        description = read_toml(path).get("description", "")
        print(f"  {name.ljust(width)}  {description}")
        if args.paths:
            print(f"  {''.ljust(width)}  {path}")
    return 0
