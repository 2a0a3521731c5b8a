"""The 100 m bundle route of benchmarks/bundle_route.py through the smooth contact onset: where it stalls.

Three cables (triangular) through the route's four bends, steady mode, the bundle's
:class:`~exucable.solve.steady.SteadySolver` with the onset layer's first thickness ``--first`` [m]
(exucable/solve/onset_continuation.py) and a CPU limit ``--limit`` [s]: status, CPU, Newton iterations,
the message and the layers solved. ``--smoothness``: instead, the one-iteration steps at full load in
the first layer alone, and at the best state they reach, the remainder of the contact forces'
linearisation Q(q + d) - Q(q) - J d for random d of size h (1 nm, 10 nm, 100 nm) in the cable-cable
and each wall kernel: it falls as h² where the forces are smooth there, stays where a contact
switches.

    nice .venv/bin/python studies/bundle_route_onset.py [--first 5e-4] [--limit 60] [--smoothness]
"""

from __future__ import annotations

import argparse
import importlib.util
import tempfile
import time
from pathlib import Path

import numpy as np

from exucable.contact import assemble_blocks_dense
from exucable.model.bundle import build_bundle_model
from exucable.scenario.specs import load_scenario
from exucable.solve import steady as st
from exucable.solve.onset_continuation import OnsetSettings

ROOT = Path(__file__).resolve().parents[1]


def route_scenario():
    """benchmarks/bundle_route.py's three-cable scenario, 100 m."""
    spec = importlib.util.spec_from_file_location("bundle_route", ROOT / "benchmarks" / "bundle_route.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    bends_m = 3 * 0.5 * 3.14159265 * 5.0 + 3.14159265 / 6 * 5.0
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "bundle_route_3.toml"
        path.write_text(bench.SCENARIO.format(count=3, arrangement="triangular",
                                              straight=f"{max(1.0, (100.0 - bends_m) / 5.0):.6g}"))
        return load_scenario(path)


def smoothness(model, solver) -> None:
    solver.onset.begin(model)
    solver.store.saved = solver.start
    ok, why = solver.relax_one_iteration(1.0)
    print(f"one-iteration steps at full load, first layer: converged {ok} ({why}); best residual {solver.best[0]:.4g} N")
    q_all = solver.best[1][0]
    qa = model.layout.coordinates.reshape(-1) + q_all[model.ode2_index]
    n = model.walls[0].n_coordinates
    rng = np.random.default_rng(0)
    for h in (1e-9, 1e-8, 1e-7):
        d = rng.normal(size=qa.size) * h
        a, b = model.between.evaluate(qa), model.between.evaluate(qa + d)
        rest = [np.abs(b.generalized_force - a.generalized_force - a.jacobian @ d).max()]
        for i, w in enumerate(model.walls):
            part = slice(i * n, (i + 1) * n)
            wa = w.evaluate(qa[part], np.zeros(n), jacobian=True)
            wb = w.evaluate(qa[part] + d[part], np.zeros(n))
            rest.append(np.abs(wb.generalized_force - wa.generalized_force
                               - assemble_blocks_dense(wa.jac_q_blocks) @ d[part]).max())
        print(f"  h {h:g} m: remainder [N] cable-cable {rest[0]:.3g}, walls " + ", ".join(f"{x:.3g}" for x in rest[1:]))


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--first", type=float, default=OnsetSettings().first_m, help="the first onset layer [m]")
    p.add_argument("--limit", type=float, default=60.0, help="the solve's CPU limit [s]")
    p.add_argument("--smoothness", action="store_true")
    args = p.parse_args(argv)
    model = build_bundle_model(route_scenario())
    solver = st.SteadySolver(model, st.SteadySettings(time_limit_s=args.limit), onset=OnsetSettings(first_m=args.first))
    if args.smoothness:
        smoothness(model, solver)
        return 0
    c0 = time.process_time()
    out = solver.solve()
    print(f"first layer {1e6 * args.first:g} µm: {out.status}, {time.process_time() - c0:.2f} s CPU, "
          f"{out.newton_iterations} Newton iterations: {out.message}")
    for s in solver.onset.stages:
        print(f"  {1e6 * s.layer_m:.3g} µm: " + (f"{s.pull_force_N:.6g} N" if s.converged else "stalled")
              + f" ({s.newton_iterations} iterations, {s.cpu_s:.2f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
