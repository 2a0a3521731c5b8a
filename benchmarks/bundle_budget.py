"""How the bundle's steady solve spends its CPU budget on the 100 m route of benchmarks/bundle_route.py.

Three cables (triangular) through the route's four bends, steady mode, one variant per fresh process
(``--variant`` runs one in this process): the dynamic relaxation capped at ``relax_steps`` steps
(0: off; :attr:`~exucable.solve.steady.SteadySettings.bundle_relax_steps`) and the onset layer's first
width ``first`` [m] (:class:`~exucable.solve.onset_continuation.OnsetSettings`), under the CPU limit
``--limit`` [s] (``solver.steady_time_limit``). Prints per variant: status, the solve's CPU [s], the
CPU of each phase (the one-iteration steps from the rope start, the relaxation with the steps from its
state, the load or friction ramps, the onset layers' descent) with the smallest true residual [N]
reached by that phase's end, the relaxation's steps and residual, the pull force [N] and the process's
whole CPU (build included, from getrusage). A variant ``N:first:friction`` goes from the relaxation
straight to the friction's ramp (a what-if: the continuation at full load and the loads' ramp
skipped). The machine is shared: compare CPU, not wall.

    nice .venv/bin/python benchmarks/bundle_budget.py [--limit 90] [--variants 300:5e-4,1000:5e-4]
    nice .venv/bin/python benchmarks/bundle_budget.py --quick      # smoke run: one variant, 3 s limit
"""

from __future__ import annotations

import argparse
import importlib.util
import resource
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PHASES = ("relax_one_iteration", "relax_dynamic", "relax", "ramp_loads")


def _route_scenario():
    spec = importlib.util.spec_from_file_location("bundle_route_onset", ROOT / "studies" / "bundle_route_onset.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.route_scenario()


def run_variant(relax_steps: int, first_m: float, limit_s: float, friction_first: bool = False) -> None:
    """One variant in this process: the table row's fields printed, one per line. ``friction_first``:
    after the relaxation, straight to the friction's ramp (the continuation at full load and the
    loads' ramp skipped; a what-if, not a library path)."""
    from exucable.model.bundle import build_bundle_model
    from exucable.solve import steady as st
    from exucable.solve.onset_continuation import OnsetSettings

    model = build_bundle_model(_route_scenario())
    settings = replace(st.SteadySettings(time_limit_s=limit_s), bundle_relax_steps=relax_steps)
    solver = st.SteadySolver(model, settings, onset=OnsetSettings(first_m=first_m))
    log, depth = [], [0]       # depth: phases running (the relaxation calls the one-iteration steps)

    def timed(name, method):
        def wrapper(*a, **k):
            depth[0] += 1
            c0 = time.process_time()
            try:
                return method(*a, **k)
            finally:
                depth[0] -= 1
                if depth[0] == 0:        # a phase's own calls (the relaxation's continuation) stay in it
                    log.append((name, time.process_time() - c0, solver.best[0]))
        return wrapper

    if friction_first:
        relax, ramp_loads, skipped = solver.relax, solver.ramp_loads, []

        def relax_skipping_full_load(lam, *a, **k):
            if not skipped and lam == 1.0:
                skipped.append(lam)
                return False, "the continuation at full load skipped"
            return relax(lam, *a, **k)

        def friction_ramp_only(first_message, friction_only=False):
            return ramp_loads(first_message, friction_only=True) if friction_only else ("failed", "skipped")

        solver.relax, solver.ramp_loads = relax_skipping_full_load, friction_ramp_only
    for name in PHASES:
        setattr(solver, name, timed(name, getattr(solver, name)))
    solver.onset.descend = timed("onset descent", solver.onset.descend)
    c0 = time.process_time()
    out = solver.solve()
    cpu = time.process_time() - c0
    print(f"  solve {cpu:.1f} s CPU, status {out.status}, {out.newton_iterations} Newton iterations")
    for name, dt, best in log:
        print(f"    {name:20s} {dt:7.1f} s CPU, smallest true residual so far {best if best is None else f'{best:.3g}'} N")
    r = solver.relaxation
    if r is not None:
        print(f"    relaxation: {r.steps} steps, {r.cpu_s:.1f} s CPU, residual {r.residual_N:.3g} N ({r.message})")
    layers = ", ".join(f"{1e6 * s.layer_m:.3g} µm: " + (f"{s.pull_force_N:.6g} N" if s.converged else "stalled")
                       for s in solver.onset.stages)
    print(f"    onset layers (pull force): {layers or 'none reached'}")
    print(f"    message: {out.message[:400]}")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--limit", type=float, default=90.0, help="the solve's CPU limit [s]")
    p.add_argument("--variants", default="300:5e-4,1000:5e-4,2000:5e-4,300:1e-3,300:2e-3",
                   help="comma-separated relax_steps:first_m pairs, each optionally :friction (friction_first)")
    p.add_argument("--variant", default=None, help=argparse.SUPPRESS)
    p.add_argument("--quick", action="store_true", help="smoke run: one variant (300:5e-4) under a 3 s limit")
    args = p.parse_args(argv)
    if args.quick:
        args.limit, args.variants = 3.0, "300:5e-4"
    if args.variant:
        steps, first, *rest = args.variant.split(":")
        run_variant(int(steps), float(first), args.limit, friction_first=rest == ["friction"])
        return 0
    for v in args.variants.split(","):
        steps, first, *rest = v.split(":")
        print(f"relaxation cap {steps} steps, first onset layer {1e3 * float(first):g} mm, limit {args.limit:g} s"
              + (", then the friction's ramp alone" if rest else "") + ":", flush=True)
        c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([sys.executable, __file__, "--limit", str(args.limit), "--variant", v], check=False)
        c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        print(f"  whole process {c1.ru_utime - c0.ru_utime + c1.ru_stime - c0.ru_stime:.1f} s CPU", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
