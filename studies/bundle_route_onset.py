"""The 100 m bundle route of benchmarks/bundle_route.py through the smooth contact onset: where it stalls.

Three cables (triangular) through the route's four bends, steady mode, the bundle's
:class:`~exucable.solve.steady.SteadySolver` with the onset layer's first thickness ``--first`` [m]
(exucable/solve/onset_continuation.py) and a CPU limit ``--limit`` [s]: status, CPU, Newton iterations,
the message and the layers solved. ``--smoothness``: instead, the one-iteration steps at full load in
the first layer alone, and at the best state they reach, the remainder of the contact forces'
linearisation Q(q + d) - Q(q) - J d for random d of size h (1 nm, 10 nm, 100 nm) in the cable-cable
and each wall kernel: it falls as h² where the forces are smooth there, stays where a contact
switches. ``--audit``: at the best state those steps reach, whether Newton's matrix and the residual
agree: the residual evaluated twice (after another state), Exudyn's whole static Jacobian (spring
rate 0: elastic forces, weight, end loads, the eye's constraints, walls, cable pairs) against central
differences of its residual along random directions, part by part, and one step at a spring rate
5e5 c0 with the axial share released as after 23 accepted steps and restored to 1: the true residual
and the largest nodal move along and across the tangents. ``--quick``: the audit on two cables
through the 34 m route (a smoke run).

    nice .venv/bin/python studies/bundle_route_onset.py [--first 5e-4] [--limit 60] [--smoothness] [--audit]
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


def route_scenario(count: int = 3, length_m: float = 100.0):
    """benchmarks/bundle_route.py's scenario: ``count`` cables (triangular), about ``length_m`` [m]."""
    spec = importlib.util.spec_from_file_location("bundle_route", ROOT / "benchmarks" / "bundle_route.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    bends_m = 3 * 0.5 * 3.14159265 * 5.0 + 3.14159265 / 6 * 5.0
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / f"bundle_route_{count}.toml"
        path.write_text(bench.SCENARIO.format(count=count, arrangement="triangular",
                                              straight=f"{max(1.0, (length_m - bends_m) / 5.0):.6g}"))
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


def audit(model, solver) -> None:
    """The checks of ``--audit`` (module notes), printed as a table."""
    import exudyn as exu

    solver.onset.begin(model)
    solver.store.saved = solver.start
    ok, why = solver.relax_one_iteration(1.0)
    q0, lam0 = (np.array(x) for x in solver.best[1][:2])
    print(f"one-iteration steps at full load, first layer: converged {ok}; best residual {solver.best[0]:.4g} N "
          f"after {solver.newton_iterations} Newton iterations\n")
    print("| check | result |\n| --- | --- |")
    mbs, sd = model.mbs, model.mbs.systemData
    solver.spring.rate = 0.0
    settings = st.static_settings()
    settings.linearSolver.solverType = exu.LinearSolverType.EXUdense
    for cfg in (exu.ConfigurationType.Initial, exu.ConfigurationType.Current):
        sd.SetODE2Coordinates(q0, configuration=cfg)
        sd.SetAECoordinates(lam0, configuration=cfg)
    static = exu.MainSolverStatic()
    static.InitializeSolver(mbs, settings)

    def residual(q, lam):
        sd.SetODE2Coordinates(q)
        sd.SetAECoordinates(lam)
        static.ComputeNewtonResidual(mbs, settings)
        return np.array(static.GetSystemResidual())

    r0 = residual(q0, lam0)
    residual(q0 + 1e-4, lam0 + 1.0)
    n2 = q0.size
    print(f"| residual at the best state [N], ODE2 rows | {np.linalg.norm(r0[:n2]):.4g} |")
    print(f"| the same state again, after another: largest difference [N] | {np.abs(residual(q0, lam0) - r0).max():.3g} |")
    static.ComputeNewtonJacobian(mbs, settings)
    J = np.array(static.GetSystemJacobian())
    rng = np.random.default_rng(0)
    index = model.ode2_index.reshape(model.n_cables, -1, 6)
    parts = {"every coordinate": np.arange(n2)}
    for c in range(model.n_cables):
        parts[f"cable {c + 1} positions"] = index[c, :, :3].ravel()
        parts[f"cable {c + 1} slopes"] = index[c, :, 3:].ravel()
    for name, cols in parts.items():
        rest = []
        for h in (1e-6, 1e-7, 1e-8):
            d = np.zeros(n2)
            d[cols] = rng.normal(size=cols.size) * h
            fd = (residual(q0 + d, lam0) - residual(q0 - d, lam0)) / 2.0
            rest.append(f"{np.linalg.norm(J[:, :n2] @ d - fd) / np.linalg.norm(fd):.1e}")
        print(f"| Jacobian - central differences, relative, h = 1e-6, 1e-7, 1e-8 m: {name} | {', '.join(rest)} |")
    dl = rng.normal(size=lam0.size)
    fd = (residual(q0, lam0 + dl) - residual(q0, lam0 - dl)) / 2.0
    print(f"| the same, the eye's multipliers | {np.linalg.norm(J[:, n2:] @ dl - fd) / np.linalg.norm(fd):.1e} |")
    qa = (model.layout.coordinates.reshape(-1) + q0[model.ode2_index]).reshape(-1, 6)
    t = qa[:, 3:] / np.linalg.norm(qa[:, 3:], axis=1, keepdims=True)
    s = solver.settings
    for share in (s.axial_share * s.axial_release ** 23, s.axial_share):
        solver.store.saved = (q0, lam0, None)
        solver.spring.axial_share = share
        solver.pseudo_step(5e5 * solver.c0, solver.one_iteration_settings)
        dq = (np.array(sd.GetODE2Coordinates()) - q0)[model.ode2_index].reshape(-1, 6)[:, :3]
        along = np.einsum("ki,ki->k", dq, t)
        across = np.linalg.norm(dq - along[:, None] * t, axis=1)
        print(f"| a step at rate 5e5 c0, axial share {share:.2g}: true residual [N]; largest move along, "
              f"across the tangents [m] | {solver.true_residual():.4g}; {np.abs(along).max():.3g}, {across.max():.3g} |")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--first", type=float, default=OnsetSettings().first_m, help="the first onset layer [m]")
    p.add_argument("--limit", type=float, default=60.0, help="the solve's CPU limit [s]")
    p.add_argument("--smoothness", action="store_true")
    p.add_argument("--audit", action="store_true")
    p.add_argument("--quick", action="store_true", help="the audit on two cables through the 34 m route (a smoke run)")
    args = p.parse_args(argv)
    model = build_bundle_model(route_scenario(2, 12.0) if args.quick else route_scenario())
    solver = st.SteadySolver(model, st.SteadySettings(time_limit_s=args.limit), onset=OnsetSettings(first_m=args.first))
    if args.smoothness:
        smoothness(model, solver)
        return 0
    if args.audit or args.quick:
        audit(model, solver)
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
