"""Block Gauss–Seidel by cable (exucable/solve/block_sweeps.py) on the 100 m bundle route: where it stalls.

Three cables through benchmarks/bundle_route.py's four bends (``--scenario``: another bundle
scenario, ``--reverse`` pulled the other way), steady mode, first onset layer ``--layer`` [m] (the
coupled solve's first, exucable/solve/onset_continuation.py), full load, from the rope start
(``--from-coupled``: from the best state of the coupled one-iteration steps): one row per sweep
(coupled residual, each cable's, each cable's block solve), then where the residual of the best state
lies (each cable's, per 10 m of material from the trailing end, and its largest nodes).
``--analyse``: there, each cable's block stiffness per mass (the others frozen) and the linear
Gauss–Seidel iteration's spectral radius with its slowest modes. ``--handoff``: then the steady solve
with the sweeps first (``SteadySettings.bundle_block_sweeps``, the solver's own path) within
``--limit`` [s] CPU. ``--quick``: two cables through the 34 m route, two sweeps (a smoke run).

    nice .venv/bin/python studies/bundle_block_sweeps.py [--arrangement triangular] [--sweeps 8]
        [--relaxation 1] [--order bottom_first] [--block-iterations 20] [--block-reduction 1e-3]
        [--from-coupled] [--analyse] [--scenario FILE [--reverse]] [--handoff] [--relax-steps N] [--limit 60]
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


def analyse(model, q, c_unit: float) -> None:
    """At ``q``: each cable's block K_ii per mass (the others frozen), its three smallest eigenvalues
    [1/s²] and the nodes their modes move most; and the linear block Gauss–Seidel iteration
    −(D + L)⁻¹ U of the whole stiffness (the sweep's order): its spectral radius (the sweeps' rate
    near the solution) and where its slowest mode is (each cable's share, the nodes it moves most)."""
    from exucable.solve.block_sweeps import node_block_masses, sweep_order

    rows, cols, blocks = model.stiffness_blocks3(q)
    n = model.ode2_index.size
    K = np.zeros((n, n))
    np.add.at(K.reshape(n // 3, 3, n // 3, 3).transpose(0, 2, 1, 3), (rows, cols), blocks)
    free = np.ones(n, dtype=bool)
    free[model.held_coordinates()] = False
    m = np.repeat(node_block_masses(model).reshape(-1), 3)
    n1 = n // model.n_cables
    x = np.concatenate([[0.0], np.cumsum(model.layout.element_length_m)])

    def nodes_of(v):
        size = np.linalg.norm(v.reshape(-1, 6)[:, :3], axis=1)
        return ", ".join(f"{x[k % len(x)]:.0f} m" for k in np.argsort(size)[::-1][:3])

    print("\n| cable | smallest eigenvalues of M⁻¹K_ii, the others frozen [1/s²] (where the mode is) |\n| --- | --- |")
    for i in range(model.n_cables):
        sl = slice(i * n1, (i + 1) * n1)
        fr = free[sl]
        w_m = 1.0 / np.sqrt(m[sl][fr])
        A = K[sl, sl][fr][:, fr] * w_m[:, None] * w_m[None, :]
        w, V = np.linalg.eig(A)
        order = np.argsort(w.real)[:3]
        out = []
        for k in order:
            v = np.zeros(n1)
            v[fr] = V[:, k].real * w_m
            out.append(f"{w[k].real:.3g} ({nodes_of(v)})")
        print(f"| {i + 1} | " + "; ".join(out) + " |")
    rank = np.empty(model.n_cables, dtype=int)
    rank[sweep_order(model, "bottom_first")] = np.arange(model.n_cables)
    turn = rank[np.repeat(np.arange(model.n_cables), n1)][free]
    Kf = K[free][:, free]
    lower = turn[:, None] >= turn[None, :]
    G = -np.linalg.solve(np.where(lower, Kf, 0.0), np.where(lower, 0.0, Kf))
    w, V = np.linalg.eig(G)
    print("\n| linear Gauss–Seidel mode | |eigenvalue| | share per cable | where it moves most |\n| --- | --- | --- | --- |")
    for k in np.argsort(np.abs(w))[::-1][:3]:
        v = np.zeros(n)
        v[free] = np.abs(V[:, k])
        share = [np.linalg.norm(v[i * n1:(i + 1) * n1]) for i in range(model.n_cables)]
        share = np.array(share) / max(np.linalg.norm(share), 1e-300)
        worst = int(np.argmax(share))
        print(f"| {k} | {abs(w[k]):.5f} | " + ", ".join(f"{a:.2f}" for a in share) + f" | cable {worst + 1}: "
              f"{nodes_of(v[worst * n1:(worst + 1) * n1])} |")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--arrangement", default="triangular")
    p.add_argument("--layer", type=float, default=OnsetSettings().first_m, help="the onset layer of the sweeps [m]")
    p.add_argument("--sweeps", type=int, default=8)
    p.add_argument("--relaxation", type=float, default=1.0)
    p.add_argument("--order", default="bottom_first")
    p.add_argument("--block-iterations", type=int, default=20)
    p.add_argument("--block-reduction", type=float, default=BlockSweepSettings().block_reduction)
    p.add_argument("--coarse-steps", type=int, default=0, help="coarse-correction steps after each sweep (Eq. GS 3)")
    p.add_argument("--handoff", action="store_true")
    p.add_argument("--from-coupled", action="store_true",
                   help="sweep from the best state of the coupled one-iteration steps, not the rope start")
    p.add_argument("--analyse", action="store_true", help="the blocks' and the sweeps' linear spectra at the best state")
    p.add_argument("--scenario", help="a bundle scenario file instead of the 100 m route")
    p.add_argument("--reverse", action="store_true", help="the scenario pulled the other way")
    p.add_argument("--relax-steps", type=int, default=st.SteadySettings().bundle_relax_steps,
                   help="the coupled solve's dynamic relaxation steps (0: off) after --handoff")
    p.add_argument("--limit", type=float, default=60.0, help="CPU limit of sweeps and coupled solve [s]")
    p.add_argument("--quick", action="store_true", help="two cables through the 34 m route, two sweeps")
    args = p.parse_args(argv)
    if args.scenario:
        from exucable.scenario.specs import load_scenario

        sc = load_scenario(args.scenario)
        if sc.solver.mode != "steady":
            sc = sc.replace(**{"solver.mode": "steady"})
        if args.reverse:
            sc = sc.replace(**{"pull.direction": "reverse"})
    else:
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
    if args.from_coupled:
        solver.onset.begin(model)
        solver.store.saved = solver.start
        c = time.process_time()
        ok, why = solver.relax_one_iteration(1.0)
        print(f"the coupled one-iteration steps first: {time.process_time() - c:.2f} s CPU, best {solver.best[0]:.4g} N "
              f"({why or 'converged'})")
        if solver.best[1] is not None:
            q0 = solver.best[1][0][model.ode2_index]
    settings = BlockSweepSettings(residual_N=st.SteadySettings().bundle_relax_within * solver.tolerance_N,
                                  max_sweeps=args.sweeps, relaxation=args.relaxation, order=args.order,
                                  block_iterations=args.block_iterations, time_limit_s=args.limit,
                                  block_reduction=args.block_reduction, stall_sweeps=args.sweeps,
                                  coarse_steps=args.coarse_steps)
    out = block_sweeps(model, q0, solver.c0, settings)
    print(f"{sc.name}, {model.n_cables} cables {model.arrangement}, layer {1e6 * args.layer:g} µm, ω {args.relaxation:g}, "
          f"order {args.order}, {args.block_iterations} block steps at most: {out.message}; {out.sweeps} sweeps, "
          f"{out.block_steps} block steps, {out.cpu_s:.2f} s CPU")
    print("| sweep | coupled residual [N] | per cable [N] | per cable: residual before → after its solve [N] (steps) |")
    print("| --- | --- | --- | --- |")
    for row in out.trace:
        blocks = ", ".join(f"{i + 1 if i >= 0 else 'coarse'}: {a:.3g} → {b:.3g} ({k})" for i, a, b, k in row["blocks"])
        print(f"| {row['sweep']} | {row['residual_N']:.4g} | " + ", ".join(f"{x:.3g}" for x in row["cable_residual_N"])
              + f" | {blocks} |")
    where(model, out.q)
    if args.analyse or args.quick:
        analyse(model, out.q, solver.c0)
    if args.handoff:
        # the solver's own path: SteadySettings.bundle_block_sweeps, then every phase from the swept state
        cpu1 = time.process_time()
        model = build_bundle_model(sc)
        solver = st.SteadySolver(model, st.SteadySettings(time_limit_s=args.limit, bundle_relax_steps=args.relax_steps,
                                                          bundle_block_sweeps=args.sweeps,
                                                          bundle_block_coarse_steps=args.coarse_steps),
                                 onset=OnsetSettings(first_m=args.layer))
        result = solver.solve()
        b = solver.sweeps
        print(f"\nthe steady solve with {args.sweeps} block sweeps first (SteadySettings.bundle_block_sweeps, "
              f"{args.coarse_steps} coarse steps after each; the sweeps' other settings the defaults): {result.status}, {time.process_time() - cpu1:.2f} s CPU (build and "
              f"solve), sweeps {b.sweeps if b else 0} ({b.cpu_s if b else 0:.2f} s, {b.residual_N if b else float('nan'):.4g} N), "
              f"{result.newton_iterations} Newton iterations: {result.message}")
        if result.status == "ok":
            print(f"pull {model.steady_forces()[0]:.6f} N")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
