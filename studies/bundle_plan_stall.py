"""The industry three-cable plan's steady solve: where its dynamic relaxation stalls.

scenarios/industry/sec_tes_p_104_05_three_cables.toml (triangular, D/d 3.7, μ 0.5, no back tension),
steady mode, the first onset layer (exucable/solve/onset_continuation.py), full load, from the rope
start: the dynamic relaxation (exucable/solve/relax.py, ``--masses``) in chunks of ``--chunks`` steps;
after each chunk the residual, the top cable's (cable 3's) height in the duct every 5 m and each
cable's residual split along its tangent (summed per 10 m from the trailing end: a tension gradient
where no load acts along the cable) and across it. ``--reverse``: pulled F→A; ``--back-tension``
[N]: the bundle's, instead of 0; ``--arrangement``. ``--quick``: one chunk of 50 steps (a smoke run).

    nice .venv/bin/python studies/bundle_plan_stall.py [--reverse] [--masses diagonal|frame]
        [--chunks 1000,1000,2000,2000] [--back-tension 0] [--arrangement triangular]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from exucable.model.bundle import build_bundle_model, bundle_cross_sections
from exucable.scenario.specs import load_scenario
from exucable.solve import steady as st
from exucable.solve.onset_continuation import OnsetSettings
from exucable.solve.relax import RelaxSettings, relax_bundle

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios/industry/sec_tes_p_104_05_three_cables.toml"


def split(model, q):
    """Each cable's residual at ``q`` [N]: along its tangent per node (signed), and across it per node."""
    f = model.steady_force(q)
    f[model.held_coordinates()] = 0.0
    fr = f.reshape(model.n_cables, -1, 6)
    slope = (model.layout.coordinates.reshape(-1) + q).reshape(model.n_cables, -1, 6)[:, :, 3:]
    t = slope / np.linalg.norm(slope, axis=2, keepdims=True)
    along = np.einsum("cki,cki->ck", fr[:, :, :3], t)
    across = np.linalg.norm(fr[:, :, :3] - along[:, :, None] * t, axis=2)
    return float(np.linalg.norm(f)), along, across


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--reverse", action="store_true")
    p.add_argument("--masses", default="diagonal", choices=("diagonal", "frame", "block"))
    p.add_argument("--chunks", default="1000,1000,2000,2000", help="relaxation steps per chunk, comma-separated")
    p.add_argument("--back-tension", type=float, default=0.0, help="the bundle's back tension [N]")
    p.add_argument("--arrangement", default="triangular")
    p.add_argument("--quick", action="store_true", help="one chunk of 50 steps")
    args = p.parse_args(argv)
    sc = load_scenario(str(SCENARIO)).replace(**{"solver.mode": "steady", "pull.back_tension": args.back_tension,
                                                 "cable.arrangement": args.arrangement})
    if args.reverse:
        sc = sc.replace(**{"pull.direction": "reverse"})
    chunks = [50] if args.quick else [int(c) for c in args.chunks.split(",")]
    model = build_bundle_model(sc)
    solver = st.SteadySolver(model, st.SteadySettings(), onset=OnsetSettings())
    solver.onset.begin(model)
    solver.at_scale(1.0)
    solver.store.saved = solver.start
    solver.store.restore_as_initial()
    L = model.conduit.centreline.length_m
    where = np.arange(2.5, L, 5.0)
    x = np.concatenate([[0.0], np.cumsum(model.layout.element_length_m)])
    bins = np.arange(0.0, x[-1], 10.0)
    print(f"{sc.name} ({'reverse' if args.reverse else 'forward'}), {model.arrangement}, back tension "
          f"{args.back_tension:g} N, {len(model.layout.element_length_m)} elements per cable, masses {args.masses}")
    print("| steps | CPU [s] | residual [N] | cable 3's height in the duct every 5 m from "
          f"{where[0]:g} m [mm] |\n| --- | --- | --- | --- |")
    steps, rows = 0, []
    for chunk in chunks:
        out = relax_bundle(model, RelaxSettings(residual_N=1e-3, max_steps=chunk, time_limit_s=600.0,
                                                stall_steps=10 ** 6), masses=args.masses)
        steps += out.steps
        q = np.array(model.mbs.systemData.GetODE2Coordinates())[model.ode2_index]
        height = bundle_cross_sections(model, where)[:, 2, 1] * 1e3
        norm, along, across = split(model, q)
        rows.append((steps, along, across))
        print(f"| {steps} | {out.cpu_s:.1f} | {norm:.3g} | " + " ".join(f"{h:+.0f}" for h in height) + " |")
    steps, along, across = rows[-1]
    print(f"\nafter {steps} steps, each cable's residual: along the tangent, summed per 10 m of cable from the "
          "trailing end [N]; across it, the norm per 10 m [N]")
    print("| cable | along, total norm [N] | along per 10 m | across per 10 m |\n| --- | --- | --- | --- |")
    for i in range(model.n_cables):
        a = " ".join(f"{along[i][(x >= b) & (x < b + 10.0)].sum():+.2g}" for b in bins)
        c = " ".join(f"{np.linalg.norm(across[i][(x >= b) & (x < b + 10.0)]):.2g}" for b in bins)
        print(f"| {i + 1} | {np.linalg.norm(along[i]):.3g} | {a} | {c} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
