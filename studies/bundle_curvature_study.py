"""Negative curvature of the bundle's stiffness on the 100 m route, and steps along it.

The 100 m route of benchmarks/bundle_route.py (three cables, triangular): the solve's first phases
(one-iteration steps at full load in the first onset layer, then the dynamic relaxation for
``--relax`` s CPU), and at the relaxed state the lowest eigenpairs of the frictionless stiffness's
symmetric part in the pseudo-time spring's mass metric (exucable/solve/negative_curvature.py, Eq. NC 1)
with, for each negative one, the cable and place (from the trailing end) where its mode is largest;
then :func:`~exucable.solve.negative_curvature.roll_off`'s steps (Eq. NC 2), and the one-iteration
continuation's smallest residual in 40 steps from the relaxed state, from the rolled one, and from the
relaxed state moved by ``--moves`` [m] along every mode below −15 s⁻² (signed by the forces' work). ``--quick``: two cables, 34 m, 2 s
of relaxation (a smoke run).

    nice .venv/bin/python studies/bundle_curvature_study.py [--relax 15] [--moves 0,0.002,0.01] [--scenario FILE]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from exucable.model.bundle import build_bundle_model
from exucable.scenario.specs import load_scenario
from exucable.solve import steady as st
from exucable.solve import negative_curvature as nc
from exucable.solve.onset_continuation import OnsetSettings
from exucable.solve.relax import RelaxSettings, relax_bundle

from bundle_route_onset import route_scenario


def _solver(scenario):
    model = build_bundle_model(scenario)
    solver = st.SteadySolver(model, st.SteadySettings(time_limit_s=1e9), onset=OnsetSettings())
    solver.onset.begin(model)
    return model, solver


def _set_state(model, solver, q) -> None:
    import exudyn as exu

    sd = model.mbs.systemData
    ode2 = np.array(sd.GetODE2Coordinates())
    ode2[model.ode2_index] = q
    for cfg in (exu.ConfigurationType.Initial, exu.ConfigurationType.Current):
        sd.SetODE2Coordinates(ode2, configuration=cfg)
    solver.store.save()


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--relax", type=float, default=15.0, help="CPU time of the dynamic relaxation [s]")
    p.add_argument("--moves", default="0,0.002,0.01", help="nodal moves along the negative modes [m]")
    p.add_argument("--scenario", help="a bundle scenario file instead of the 100 m route (steady mode)")
    p.add_argument("--quick", action="store_true")
    a = p.parse_args(argv)
    count, length = (2, 12.0) if a.quick else (3, 100.0)
    if a.quick:
        a.relax, a.moves = 2.0, "0,0.002"
    scenario = route_scenario(count, length) if a.scenario is None else \
        load_scenario(a.scenario).replace(**{"solver.mode": "steady", "solver.cable_element": "compiled"})
    model, solver = _solver(scenario)
    t0 = time.process_time()
    solver.store.saved = solver.start
    ok, why = solver.relax_one_iteration(1.0)
    print(f"one-iteration steps from the start: {'converged' if ok else why} ({time.process_time() - t0:.1f} s CPU)")
    solver.store.restore_as_initial()
    out = relax_bundle(model, RelaxSettings(residual_N=30 * solver.tolerance_N, time_limit_s=a.relax))
    q0 = out.q
    print(f"dynamic relaxation: {out.steps} steps, residual {out.residual_N:.4g} N ({out.message})")
    free = np.ones(q0.size, dtype=bool)
    free[model.held_coordinates()] = False
    mass = np.repeat(solver.spring.block_mass.reshape(-1), 3)
    n1 = q0.size // model.n_cables
    x_node = np.concatenate([[0.0], np.cumsum(model.layout.element_length_m)])
    nc._friction(model, 0.0)
    t = time.process_time()
    lam, U = nc.lowest_modes(model, q0, mass, free, nc.CurvatureSettings(modes=10))
    cpu = time.process_time() - t
    nc._friction(model, 1.0)
    print(f"lowest eigenvalues of Eq. NC 1 (frictionless), {cpu:.2f} s CPU:")
    print("| eigenvalue [1/s²] | mode largest on cable | at s [m] from the trailing end |")
    for j in range(len(lam)):
        k = int(np.argmax(np.linalg.norm(U[:, j].reshape(-1, 6)[:, :3], axis=1)))
        cable, node = divmod(6 * k, n1)
        print(f"| {lam[j]:.4g} | {cable + 1} | {x_node[node // 6]:.0f} |")
    q1, found, steps, cpu = nc.roll_off(model, q0, mass, free, 1.0)
    print(f"roll_off (Eq. NC 2, friction off): {len(steps)} steps in {len(found)} passes, {cpu:.2f} s CPU; "
          f"negative eigenvalues per pass: {[int(np.sum(x < 0.0)) for x in found]}, lowest "
          f"{[round(float(x[0]), 1) for x in found]} 1/s²"
          + "".join(f"\n  λ {s.eigenvalue_per_s2:.4g}: cable {s.cable + 1} at {s.where_m:.0f} m, move {1e3 * s.move_m:.3g} mm, "
                    f"work {s.work_J:.3g} J, |f| {s.residual_before_N:.4g} → {s.residual_after_N:.4g} N" for s in steps))
    for move in [None] + [float(x) for x in a.moves.split(",")]:
        m2, s2 = _solver(scenario)
        q = (q1 if move is None else q0).copy()
        f = m2.steady_force(q)
        f[~free] = 0.0
        for j in np.flatnonzero(lam < -15.0) if move else []:
            u = U[:, j]
            q = q + (1.0 if f @ u >= 0.0 else -1.0) * move / np.abs(u.reshape(-1, 6)[:, :3]).max() * u
        r = np.linalg.norm(np.where(free, m2.steady_force(q), 0.0))
        _set_state(m2, s2, q)
        t = time.process_time()
        ok, why = s2.relax_one_iteration(1.0, max_steps=40)
        where = "rolled (roll_off)" if move is None else f"moved {1e3 * move:g} mm along the modes below -15 1/s²"
        print(f"{where}: |f| {r:.4g} N; one-iteration steps: "
              f"{'converged' if ok else 'not converged'}, smallest {s2.best[0]:.4g} N, "
              f"{time.process_time() - t:.1f} s CPU")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
