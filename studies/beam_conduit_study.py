"""Three-point bending predicted: the beam-in-conduit model's change of the pulling force against its own
EJ → 0 limit, for the industry routes and the bending-stiffness study's `tight` bend.

`exucable.quasistatic.beam.stiff_route_difference` — an independent steady beam in the conduit (a node chain
with unilateral round walls, the weight, Coulomb friction; not Exudyn, not ANCF) — at two node spacings
(λ/10 and λ/20), beside nothing of exucable's own: reference/README.md sets these predictions beside the
measured exucable − rope with clearance (`exucable validate --suite industry`, `bending_stiffness_study.py`).

    nice .venv/bin/python studies/beam_conduit_study.py                 # minutes per route on a loaded machine
    nice .venv/bin/python studies/beam_conduit_study.py --ej-scale 0.1  # a cable 10x less stiff
    nice .venv/bin/python studies/beam_conduit_study.py --only gera --levels 1
    nice .venv/bin/python studies/beam_conduit_study.py --quick   # smoke run: the tight bend, EJ 4, λ/10 only

Prints a Markdown table (and writes ``--json``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from exucable.quasistatic.beam import route_pieces, stiff_route_difference  # noqa: E402
from exucable.io import atomic_write_text  # noqa: E402

INDUSTRY = [("commscope_conquest_run_a_h", "forward"), ("commscope_conquest_run_a_h", "reverse"),
            ("commscope_conquest_500ft_bend90", "forward"), ("gera_wire_pulling_example", "forward"),
            ("machinecalcs_two_bends", "forward")]
# the bending-stiffness study's `tight` case: 90° bend, R 0.5 m, 2 m straights, c 15 mm, μ 0.5, 100 N, 0.21 kg/m
TIGHT = [(False, 2.25), (False, 4.0), (True, 1.0), (True, 2.25)]


def industry_case(name, direction, ej_scale):
    from exucable.scenario.specs import load_scenario
    sc = load_scenario(ROOT / "scenarios" / "industry" / f"{name}.toml")
    conduit = sc.build_conduit()
    if direction == "reverse":
        conduit = conduit.reversed()
    c = sc.conduit.inner_radius_m - sc.cable.radius_m
    return dict(label=f"{name}-{direction}", pieces=route_pieces(conduit.centreline), clearance_m=c,
                friction=sc.contact.friction, weight_N_per_m=sc.cable.mass_per_length_kg_per_m * sc.gravity.g_m_per_s2,
                bending_stiffness_N_m2=ej_scale * sc.cable.bending_stiffness_N_m2,
                back_tension_N=max(sc.pull.back_tension_N, 1e-3))


def tight_case(gravity, ej, ej_scale):
    r = 0.5
    return dict(label=f"tight{'-gravity' if gravity else ''} EJ {ej:g}", pieces=[(2.0, 0.0), (r * math.pi / 2, 1 / r), (2.0, 0.0)],
                clearance_m=0.015, friction=0.5, weight_N_per_m=0.21 * 9.80665 if gravity else 0.0,
                bending_stiffness_N_m2=ej_scale * ej, back_tension_N=100.0)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ej-scale", type=float, default=1.0, help="multiply every EJ (sensitivity; default 1)")
    ap.add_argument("--levels", type=int, default=2, help="node spacings λ/10, λ/20, ... (default 2)")
    ap.add_argument("--only", action="append", help="cases whose label contains this (repeatable)")
    ap.add_argument("--json", type=Path, help="write the rows here")
    ap.add_argument("--quick", action="store_true",
                    help="smoke run: the tight bend without gravity at EJ 4 N m², node spacing λ/10 only")
    args = ap.parse_args(argv)
    if args.quick:
        args.only, args.levels = ["tight EJ 4"], 1
    cases = [industry_case(n, d, args.ej_scale) for n, d in INDUSTRY] + [tight_case(g, e, args.ej_scale) for g, e in TIGHT]
    if args.only:
        cases = [c for c in cases if any(o in c["label"] for o in args.only)]
    print(f"| case | EJ [N m²] | model: stiff vs its EJ → 0 limit (nodes/λ = {', '.join(str(10 * 2 ** k) for k in range(args.levels))}) "
          "| flexible limit [N] | max outer offset / c | wall [s] |")
    print("|---|---|---|---|---|---|")
    rows = []
    for case in cases:
        label = case.pop("label")
        t0 = time.perf_counter()
        results = [stiff_route_difference(**case, nodes_per_bending_length=10.0 * 2 ** k) for k in range(args.levels)]
        wall = time.perf_counter() - t0
        outer = max(w["max_outer_offset_over_c"] for w in results[-1]["windows"])
        diffs = [r["difference"] for r in results]
        print(f"| {label} | {case['bending_stiffness_N_m2']:.4g} | " + " / ".join(f"{100 * d:+.3f} %" for d in diffs)
              + f" | {results[-1]['flexible_N']:.2f} | {outer:.2f} | {wall:.0f} |", flush=True)
        rows.append(dict(case=label, bending_stiffness_N_m2=case["bending_stiffness_N_m2"], differences=diffs,
                         flexible_N=results[-1]["flexible_N"], stiff_N=results[-1]["stiff_N"],
                         max_outer_offset_over_c=outer, wall_s=wall))
    if args.json:
        atomic_write_text(args.json, json.dumps(dict(ej_scale=args.ej_scale, rows=rows), indent=1) + "\n")


if __name__ == "__main__":
    main()
