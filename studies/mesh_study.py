"""Does the default mesh (exucable.scenario.mesh's rule) give the pulling force within 0.2 % of the refined
answer?

For each route, ``exucable converge`` runs the scenario on the rule's mesh and on meshes refined by
``--ratio`` (element length and check-point spacing), extrapolates (observed order, Richardson)
and reports the default mesh's difference from the extrapolated value, with each level's wall
time. Routes: Example 2 of the paper on the rule's mesh, Example 4 on the rule's mesh, and
an 18 mm fibre cable on a single 90° bend and on a ~100 m route of four bends with gravity
(studies/mesh_study/*.toml).

    nice .venv/bin/python studies/mesh_study.py [--only NAME ...] [--ratio 2] [--out out/mesh_study]
    nice .venv/bin/python studies/mesh_study.py --quick   # smoke run: Example 2, steady mode, ratio 1.5, temporary folder

Prints one table (Markdown) and writes it to OUT/mesh_study.md; each case's converge.csv and
converge.json are in OUT/NAME/. CPU-heavy: run with nice, one case at a time.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from exucable.commands.converge import converge  # noqa: E402
from exucable.io import atomic_write_text  # noqa: E402
from exucable.scenario.specs import load_scenario  # noqa: E402

CASES = {
    "paper_ex2": ROOT / "scenarios" / "paper_ex2_bend90.toml",
    "paper_ex4": ROOT / "scenarios" / "paper_ex4_spatial.toml",
    "fibre_bend90": ROOT / "studies" / "mesh_study" / "fibre_bend90.toml",
    "route100_gravity": ROOT / "studies" / "mesh_study" / "route100_gravity.toml",
}


def rule_mesh(sc):
    """The scenario with its mesh overrides removed: the rule chooses."""
    from exucable.scenario.specs import parse_scenario
    d = sc.to_dict()
    d["cable"].pop("elements", None)
    d["cable"].pop("element_length", None)
    d["contact"].pop("check_points_per_element", None)
    return parse_scenario(d, sc.source_path.parent if sc.source_path else ROOT, default_name=sc.name)


def _number(value, spec: str) -> str:
    """``value`` formatted, or "n/a" where the report has none (a steady solve has no scatter)."""
    return "n/a" if value is None else format(value, spec)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--only", nargs="*", default=None, choices=sorted(CASES))
    p.add_argument("--ratio", type=float, default=2.0)
    p.add_argument("--levels", type=int, default=3)
    p.add_argument("--out", default=str(ROOT / "out" / "mesh_study"))
    p.add_argument("--mode", choices=("dynamic", "steady"), default=None,
                   help="solver.mode at every level (default: each scenario's)")
    p.add_argument("--quick", action="store_true",
                   help="smoke run: paper_ex2 in steady mode, 3 levels refined by 1.5, into a temporary folder")
    a = p.parse_args(argv)
    if a.quick:
        a.only, a.mode, a.ratio = ["paper_ex2"], "steady", 1.5
        with tempfile.TemporaryDirectory() as tmp:
            a.out = tmp
            return study(a)
    return study(a)


def study(a) -> int:
    """Converge each case of ``a.only`` (all by default); print and write the table."""
    out = Path(a.out)
    lines = ["| route | default mesh | default [N] | ± [N] | extrapolated [N] | error [N] | default vs extrapolated "
             "| order | method | wall per level [s] |", "|---|---|---|---|---|---|---|---|---|---|"]
    for name in a.only or CASES:
        sc = rule_mesh(load_scenario(CASES[name]))
        t0 = time.perf_counter()

        def progress(level, s):
            print(f"  {name} level {level}: {s['mesh']['elements']} el × {s['mesh']['check_points_per_element']} "
                  f"points, {s[s['steady_quantity']]:.6g} N, status {s['status']}, wall {s['wall_time_s']:.1f} s",
                  flush=True)

        rep = converge(sc, out / name, levels=a.levels, ratio=a.ratio, progress=progress, mode=a.mode)
        lv = rep["levels"]
        d = rep.get("default_vs_extrapolated")
        lines.append(
            f"| {name} | {lv[0]['elements']} × {lv[0]['check_points_per_element']} | {lv[0]['value_N']:.6g} | "
            f"{_number(lv[0]['uncertainty_N'], '.2g')} | {_number(rep['extrapolated_N'], '.6g')} | "
            f"{_number(rep['error_N'], '.2g')} | "
            f"{'n/a' if d is None else format(100 * d, '+.3f') + ' %'} | "
            f"{rep['observed_order'] if rep['observed_order'] is None else format(rep['observed_order'], '.2g')} | "
            f"{rep['method'].split(':')[0]} | {' / '.join(format(r['wall_time_s'], '.0f') for r in lv)} |")
        print(lines[-1], f"({time.perf_counter() - t0:.0f} s)", flush=True)
    text = "\n".join(lines) + "\n"
    atomic_write_text(out / "mesh_study.md", text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
