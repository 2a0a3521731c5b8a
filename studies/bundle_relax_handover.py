"""The 100 m bundle route's dynamic relaxation, and from which of its states the one-iteration continuation converges.

Three cables (``--arrangement``) through benchmarks/bundle_route.py's route, steady mode, first onset
layer (0.5 mm), full load: the solve's one-iteration steps from the rope start, then the dynamic
relaxation (exucable/solve/relax.py, masses ``--masses``: ``diagonal`` the default, ``frame`` the
row sums in each node's frame) for ``--limit`` s CPU, its smallest residual every 500 steps, and
where its best state's residual sits (along, across the cables, on the slopes; per cable). The
relaxation's first states below ``--marks`` [N] are kept, and from each the solve's one-iteration
continuation (``SteadySolver.relax_one_iteration``) runs as in the solve: converged?, Newton
iterations, CPU. That measures Newton's basin against the relaxation's residual (the hand-over of
``SteadySettings.bundle_relax_handover``). ``--sections``: the cables across the duct every 5 m at
the start and at the relaxation's best state. ``--quick``: two cables through the 34 m route, 3 s.

    nice .venv/bin/python studies/bundle_relax_handover.py [--arrangement cradled] [--limit 40] [--masses diagonal]
"""

from __future__ import annotations

import argparse
import importlib.util
import tempfile
import time
from pathlib import Path

import numpy as np

from exucable.model.bundle import build_bundle_model, bundle_cross_sections
from exucable.scenario.specs import load_scenario
from exucable.solve import relax as rx
from exucable.solve import steady as st
from exucable.solve.onset_continuation import OnsetSettings

ROOT = Path(__file__).resolve().parents[1]


def route_scenario(arrangement: str, count: int = 3, length_m: float = 100.0):
    """benchmarks/bundle_route.py's scenario with ``count`` cables laid ``arrangement``, about ``length_m`` [m]."""
    spec = importlib.util.spec_from_file_location("bundle_route", ROOT / "benchmarks" / "bundle_route.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    bends_m = 3 * 0.5 * np.pi * 5.0 + np.pi / 6 * 5.0
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "route.toml"
        path.write_text(bench.SCENARIO.format(count=count, arrangement=arrangement,
                                              straight=f"{max(1.0, (length_m - bends_m) / 5.0):.6g}"))
        return load_scenario(path)


def solver_at_first_layer(scenario):
    """A bundle model and its steady solver at the first onset layer, full load, at the rope start."""
    model = build_bundle_model(scenario)
    solver = st.SteadySolver(model, st.SteadySettings(), onset=OnsetSettings())
    solver.onset.begin(model)
    solver.at_scale(1.0)
    solver.store.saved = solver.start
    return model, solver


def sections(model, q_start, q) -> None:
    """Each cable's axis across the duct [mm] (horizontal, up, looking along the pull) every 5 m
    along the conduit: at the cables' displacement coordinates ``q_start`` (the start) and ``q``."""
    sd = model.mbs.systemData
    s = np.arange(5.0, model.conduit.centreline.length_m, 5.0)
    ode2 = np.array(sd.GetODE2Coordinates())
    found = []
    for x in (q_start, q):
        ode2[model.ode2_index] = x
        sd.SetODE2Coordinates(ode2)
        found.append(bundle_cross_sections(model, s))
    start, relaxed = found
    print("\ncables across the duct [mm], (horizontal, up) looking along the pull, cable 1, 2, ...:")
    for x, a, b in zip(s, start, relaxed):
        print(f"  s = {x:5.1f} m: start " + " ".join(f"({1e3 * h:+4.0f}, {1e3 * v:+4.0f})" for h, v in a)
              + "   relaxed " + " ".join(f"({1e3 * h:+4.0f}, {1e3 * v:+4.0f})" for h, v in b))


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--arrangement", default="cradled")
    p.add_argument("--limit", type=float, default=40.0, help="the relaxation's CPU limit [s]")
    p.add_argument("--masses", default="diagonal", choices=("diagonal", "frame", "block"))
    p.add_argument("--marks", default="30,10,3,1", help="residuals [N] whose first relaxed states are kept")
    p.add_argument("--sections", action="store_true",
                   help="the cables across the duct every 5 m, at the start and at the relaxation's best state")
    p.add_argument("--quick", action="store_true", help="two cables (triangular) through the 34 m route, 3 s (a smoke run)")
    args = p.parse_args(argv)
    sc = route_scenario("triangular", 2, 12.0) if args.quick else route_scenario(args.arrangement)
    if args.quick:
        args.limit = 3.0
    model, solver = solver_at_first_layer(sc)
    c0 = time.process_time()
    ok, why = solver.relax_one_iteration(1.0)
    print(f"{model}: one-iteration steps from the rope start: {time.process_time() - c0:.1f} s CPU, {why or 'converged'}")
    free = np.ones(model.ode2_index.size, dtype=bool)
    free[model.held_coordinates()] = False
    marks = sorted((float(x) for x in args.marks.split(",")), reverse=True)
    kept, residuals = {}, []

    def force(q):
        f = model.steady_force(q)
        r = float(np.linalg.norm(f[free]))
        residuals.append(r)
        for m in marks:
            if r < m and m not in kept:
                kept[m] = q.copy()
        return f

    settings = rx.RelaxSettings(residual_N=30 * solver.tolerance_N, time_limit_s=args.limit)
    q0 = np.array(solver.start[0])[model.ode2_index]
    out = rx.relax(force, rx.bundle_masses(model, settings.mass_safety, 2e-5, kind=args.masses), q0, free, settings)
    print(f"\nrelaxation ({args.masses} masses): {out.steps} steps, {out.restarts} restarts, {out.mass_updates} mass "
          f"updates, {out.cpu_s:.1f} s CPU, smallest residual {out.residual_N:.4g} N ({out.message})")
    best = np.minimum.accumulate(residuals)
    print("smallest residual by step [N]: " + ", ".join(f"{k}: {best[k]:.3g}" for k in range(500, len(best), 500)))
    f = model.steady_force(out.q)
    f[~free] = 0.0
    nodes = f.reshape(-1, 6)
    qa = (model.layout.coordinates.reshape(-1) + out.q).reshape(-1, 6)
    t = qa[:, 3:] / np.linalg.norm(qa[:, 3:], axis=1, keepdims=True)
    along = np.einsum("ki,ki->k", nodes[:, :3], t)
    print(f"its residual: along the cables {np.linalg.norm(along):.3g} N, across {np.linalg.norm(nodes[:, :3] - along[:, None] * t):.3g} N, "
          f"slopes {np.linalg.norm(nodes[:, 3:]):.3g} N; per cable: "
          + ", ".join(f"{np.linalg.norm(part):.3g}" for part in np.split(f, model.n_cables)) + " N")
    if args.sections:
        sections(model, q0, out.q)
    print("\n| relaxed state below [N] | its residual [N] | one-iteration continuation | Newton its | CPU [s] | last (converged) or smallest residual [N] |")
    print("| --- | --- | --- | --- | --- | --- |")
    for m in marks:
        if m not in kept:
            print(f"| {m:g} | not reached | | | | |")
            continue
        model, solver = solver_at_first_layer(sc)
        ode2 = np.array(solver.start[0])
        ode2[model.ode2_index] = kept[m]
        solver.store.saved = (ode2, np.array(solver.start[1]), None)
        c0 = time.process_time()
        ok, why = solver.relax_one_iteration(1.0)
        print(f"| {m:g} | {np.linalg.norm(model.steady_force(kept[m])[free]):.3g} | {'converged' if ok else 'failed'} "
              f"| {solver.newton_iterations} | {time.process_time() - c0:.2f} | {(solver._trace[-1] if ok else solver.best[0]):.3g} |",
              flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
