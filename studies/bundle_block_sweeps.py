"""Block Gauss–Seidel by cable (exucable/solve/block_sweeps.py) on the 100 m bundle route: where it stalls.

Three cables through benchmarks/bundle_route.py's four bends, steady mode, first onset layer
``--layer`` [m] (the coupled solve's first, exucable/solve/onset_continuation.py), full load, from the
rope start: one row per sweep (coupled residual, each cable's, CPU, each cable's block steps), then
where the residual of the best state lies (each cable's, per 10 m of material from the trailing end,
and its largest nodes). ``--handoff``: then the coupled steady solve (every phase, the onset layer's
continuation included) from the swept state (``SteadySettings.bundle_block_sweeps``, the solver's own path), within ``--limit``
[s] CPU. ``--quick``: two cables through the 34 m route, two sweeps (a smoke run).

    nice .venv/bin/python studies/bundle_block_sweeps.py [--arrangement triangular] [--sweeps 8]
        [--relaxation 1] [--order bottom_first] [--block-iterations 20] [--block-reduction 1e-3]
        [--handoff] [--relax-steps N] [--limit 60]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from exucable.model.bundle import build_bundle_model
from exucable.solve import steady as st
from exucable.solve.block_sweeps import BlockSweepSettings, block_sweeps
from exucable.solve.onset_continuation import OnsetSettings

from bundle_route_onset import route_scenario


def where(model, q, width_m: float = 10.0) -> None:
    """Each cable's residual at ``q``: its norm per ``width_m`` of material from the trailing end,
    and its five largest nodes (node: |f| positions [N], slopes [N m])."""
    f = model.steady_force(q)
    f[model.held_coordinates()] = 0.0
    fr = f.reshape(model.n_cables, -1, 6)
    x = np.concatenate([[0.0], np.cumsum(model.layout.element_length_m)])
    edges = np.arange(0.0, x[-1] + width_m, width_m)
    print(f"\nwhere the residual is (per {width_m:g} m of cable from the trailing end, then the largest nodes):")
    print("| cable | |f| [N] | " + " | ".join(f"{a:.0f}-{b:.0f} m" for a, b in zip(edges[:-1], edges[1:])) + " | largest nodes |")
    print("| --- " * (len(edges) + 2) + "|")
    for i in range(model.n_cables):
        parts = [np.linalg.norm(fr[i][(x >= a) & (x < b)]) for a, b in zip(edges[:-1], edges[1:])]
        pos = np.linalg.norm(fr[i, :, :3], axis=1)
        top = sorted(np.argsort(pos)[::-1][:5])
        print(f"| {i + 1} | {np.linalg.norm(fr[i]):.3g} | " + " | ".join(f"{p:.2g}" for p in parts) + " | "
              + ", ".join(f"{k} ({x[k]:.0f} m): {pos[k]:.3g}/{np.linalg.norm(fr[i, k, 3:]):.2g}" for k in top) + " |")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--arrangement", default="triangular")
    p.add_argument("--layer", type=float, default=OnsetSettings().first_m, help="the onset layer of the sweeps [m]")
    p.add_argument("--sweeps", type=int, default=8)
    p.add_argument("--relaxation", type=float, default=1.0)
    p.add_argument("--order", default="bottom_first")
    p.add_argument("--block-iterations", type=int, default=20)
    p.add_argument("--block-reduction", type=float, default=BlockSweepSettings().block_reduction)
    p.add_argument("--handoff", action="store_true")
    p.add_argument("--relax-steps", type=int, default=st.SteadySettings().bundle_relax_steps,
                   help="the coupled solve's dynamic relaxation steps (0: off) after --handoff")
    p.add_argument("--limit", type=float, default=60.0, help="CPU limit of sweeps and coupled solve [s]")
    p.add_argument("--quick", action="store_true", help="two cables through the 34 m route, two sweeps")
    args = p.parse_args(argv)
    sc = route_scenario(2, 12.0) if args.quick else route_scenario()
    if args.quick:
        args.sweeps = 2
    if args.arrangement != "triangular":
        sc = sc.replace(**{"cable.arrangement": args.arrangement})
    model = build_bundle_model(sc)
    solver = st.SteadySolver(model, st.SteadySettings(time_limit_s=args.limit, bundle_relax_steps=args.relax_steps),
                             onset=OnsetSettings(first_m=args.layer))
    model.kernel.set_onset_layer(args.layer)
    q0 = solver.start[0][model.ode2_index]
    settings = BlockSweepSettings(residual_N=st.SteadySettings().bundle_relax_within * solver.tolerance_N,
                                  max_sweeps=args.sweeps, relaxation=args.relaxation, order=args.order,
                                  block_iterations=args.block_iterations, time_limit_s=args.limit,
                                  block_reduction=args.block_reduction, stall_sweeps=args.sweeps)
    out = block_sweeps(model, q0, solver.c0, settings)
    print(f"{sc.name}, {model.n_cables} cables {model.arrangement}, layer {1e6 * args.layer:g} µm, ω {args.relaxation:g}, "
          f"order {args.order}, {args.block_iterations} block steps at most: {out.message}; {out.sweeps} sweeps, "
          f"{out.block_steps} block steps, {out.cpu_s:.2f} s CPU")
    print("| sweep | coupled residual [N] | per cable [N] | per cable: residual before → after its solve [N] (steps) |")
    print("| --- | --- | --- | --- |")
    for row in out.trace:
        blocks = ", ".join(f"{i + 1}: {a:.3g} → {b:.3g} ({k})" for i, a, b, k in row["blocks"])
        print(f"| {row['sweep']} | {row['residual_N']:.4g} | " + ", ".join(f"{x:.3g}" for x in row["cable_residual_N"])
              + f" | {blocks} |")
    where(model, out.q)
    if args.handoff:
        # the solver's own path: SteadySettings.bundle_block_sweeps, then every phase from the swept state
        cpu1 = time.process_time()
        model = build_bundle_model(sc)
        solver = st.SteadySolver(model, st.SteadySettings(time_limit_s=args.limit, bundle_relax_steps=args.relax_steps,
                                                          bundle_block_sweeps=args.sweeps),
                                 onset=OnsetSettings(first_m=args.layer))
        result = solver.solve()
        b = solver.sweeps
        print(f"\nthe steady solve with {args.sweeps} block sweeps first (SteadySettings.bundle_block_sweeps; the "
              f"sweeps' own settings the defaults): {result.status}, {time.process_time() - cpu1:.2f} s CPU (build and "
              f"solve), sweeps {b.sweeps if b else 0} ({b.cpu_s if b else 0:.2f} s, {b.residual_N if b else float('nan'):.4g} N), "
              f"{result.newton_iterations} Newton iterations: {result.message}")
        if result.status == "ok":
            print(f"pull {model.steady_forces()[0]:.6f} N")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
