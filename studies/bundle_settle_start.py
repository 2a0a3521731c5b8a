"""A short dynamic pull as the steady bundle solve's start: does it help, and is the answer the same?

    nice .venv/bin/python studies/bundle_settle_start.py [--settle 0.1 0.3 1.0] [--limit 60] [--route100]
    nice .venv/bin/python studies/bundle_settle_start.py --quick

Three cables (triangular, 30 mm, D/d 3.3) through a 30° up-bend of 5 m radius (3 m before, 2 m
after), μ 0.3, 600 N back tension, gravity, the mesh rule (``--route100``: the 100 m route of
``benchmarks/bundle_route.py`` instead). Per row, in this process, CPU seconds:

- ``rope``: the steady solve from its own start (the rope with clearance's path), within ``--limit``;
- ``settle T``: the dynamic bundle (:mod:`exucable.model.bundle_rig`) pulled for T s from the same
  start, then the steady solve started from the settled state: each steady node at material X takes the
  dynamic cable's curve at X shifted by the eye's travel (the material slides along a fixed curve in
  the steady state; shift so that the leading node lands where the steady rig holds it, the trailing
  stretch beyond the dynamic cable's end continued along its end slope), every phase of the steady
  solve then running from that state instead of the rope start.

The steady answer must not depend on the start: the pull forces of converged rows are printed to
compare (the steady bundle state is not unique in general: cables may rest in other places).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def up_bend(count: int = 3, route_m: tuple = (3.0, 2.0)):
    import exucable as xc

    route = xc.Route(inner_radius=3.3 * 0.015).straight(route_m[0]).bend(30, radius=5.0, turn="up").straight(route_m[1])
    return xc.Scenario(route=route, cable=xc.Cable(radius=0.015, density=2000.0, youngs_modulus=2e8, count=count,
                                                   arrangement="triangular"),
                       contact=xc.Contact(friction=0.3), pull=xc.Pull(speed=0.1, back_tension=200.0 * count),
                       gravity=xc.Gravity(g=9.81), solver=xc.Solver(mode="steady", end_time=1.0))


def settled_state(steady_model, dynamic_model) -> np.ndarray:
    """The system's ODE2 coordinates of ``steady_model`` with each cable on the dynamic run's current
    curve, shifted along it by the eye's travel (see the module's notes)."""
    from exucable.solve.start import hermite_state

    ode2 = np.array(steady_model.mbs.systemData.GetODE2Coordinates())
    rows = []
    for lay, q in zip(steady_model.layout.cables, np.split(dynamic_model.coordinates()[0], dynamic_model.n_cables)):
        X = lay.node_x_m
        slope = q[-1, 3:]
        x = X + float(np.dot(lay.position_m[-1] - q[-1, :3], slope) / np.dot(slope, slope))
        qq = hermite_state(q, X, np.clip(x, X[0], X[-1]))
        for beyond, end in ((x > X[-1], -1), (x < X[0], 0)):
            if beyond.any():
                qq[beyond, :3] = q[end, :3] + (x[beyond] - X[end])[:, None] * q[end, 3:]
                qq[beyond, 3:] = q[end, 3:]
        rows.append(qq)
    ode2[steady_model.ode2_index] = (np.concatenate(rows) - steady_model.layout.coordinates).reshape(-1)
    return ode2


def steady_from(model, limit_s: float, ode2=None):
    """The steady solve of ``model`` from its start or from ``ode2``: (outcome, CPU s)."""
    from exudyn import ConfigurationType
    from exucable.solve.steady import SteadySettings, SteadySolver

    t0 = time.process_time()
    solver = SteadySolver(model, SteadySettings(time_limit_s=limit_s))
    if ode2 is not None:
        # after the solver's spring is assembled (Assemble resets the state to the nodes' own)
        for cfg in (ConfigurationType.Initial, ConfigurationType.Current):
            model.mbs.systemData.SetODE2Coordinates(list(ode2), configuration=cfg)
        solver.store.save()
        solver.start = solver.store.saved
    out = solver.solve()
    return out, time.process_time() - t0


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--settle", type=float, nargs="+", default=[0.1, 0.3, 1.0], help="dynamic pull times [s]")
    p.add_argument("--limit", type=float, default=60.0, help="the steady solves' CPU limit [s]")
    p.add_argument("--route100", action="store_true", help="the 100 m route of benchmarks/bundle_route.py")
    p.add_argument("--quick", action="store_true", help="two cables, 2 m + 1 m straights, one settle of 0.05 s")
    args = p.parse_args(argv)
    from exucable.model.bundle import build_bundle_model
    from exucable.model.bundle_rig import build_bundle_dynamic_model
    from exucable.solve.dynamic import simulate

    if args.quick:
        sc, args.settle, args.limit = up_bend(2, (2.0, 1.0)), [0.05], 10.0
    elif args.route100:
        sys.path.insert(0, str(ROOT / "benchmarks"))
        import bundle_iteration
        sc = bundle_iteration._scenario(3, 100.0)
    else:
        sc = up_bend()
    rows = []
    model = build_bundle_model(sc)
    out, cpu = steady_from(model, args.limit)
    rows.append(("rope", 0.0, out, cpu, float(np.sum(model.pull_shares_N()))))
    for T in args.settle:
        t0 = time.process_time()
        model = build_bundle_model(sc)
        dyn = build_bundle_dynamic_model(sc.replace(**{"solver.mode": "dynamic", "solver.end_time": T}), start=model)
        simulate(dyn, steady_stop=False)
        cpu_dyn = time.process_time() - t0
        out, cpu = steady_from(model, args.limit, settled_state(model, dyn))
        rows.append((f"settle {T:g} s", cpu_dyn, out, cpu, float(np.sum(model.pull_shares_N()))))
    print(f"# {sc.cable.count} cables, {sc.name or 'up-bend'}: {model.mesh.elements} elements each, "
          f"{model.mesh.check_points_per_element} check points per element; steady CPU limit {args.limit:g} s")
    print("| start | dynamic pull CPU [s] | steady status | Newton iterations | steady CPU [s] | total CPU [s] | pull force [N] |")
    print("|---|---|---|---|---|---|---|")
    for name, cpu_dyn, out, cpu, pull in rows:
        print(f"| {name} | {cpu_dyn:.1f} | {out.status} | {out.newton_iterations} | {cpu:.1f} | {cpu_dyn + cpu:.1f} | "
              + (f"{pull:.6g}" if out.status == "ok" else "n/a") + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
