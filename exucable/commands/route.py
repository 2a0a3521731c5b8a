"""``exucable route``: a scenario's conduit as a 3D picture and a table."""

from __future__ import annotations

from pathlib import Path

from ..output.outdir import check_out_file, name_as_path_part
from ..plots.route import plot_route, route_table
from ..scenario.specs import load_scenario

__all__ = ["add_arguments", "main"]


def add_arguments(p) -> None:
    p.add_argument("scenario", help="scenario file (TOML), or a shipped scenario's name "
                                    "(`exucable scenarios` lists them)")
    p.add_argument("-o", "--out", default=None, help="PNG to write (default: <scenario name>_route.png)")


def main(args) -> int:
    sc = load_scenario(args.scenario)
    conduit = sc.build_conduit()
    out = check_out_file(Path(args.out) if args.out else Path(f"{name_as_path_part(sc.name)}_route.png"))
    plot_route(conduit, out, title=sc.name)
    rows = route_table(conduit)
    width = max(len(k) for k, _ in rows)
    print(f"{sc.name}")
    for k, v in rows:
        print(f"  {k:<{width}}  {v}")
    print(f"  route drawn to {out}")
    return 0
