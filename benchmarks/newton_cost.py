"""Where the time of a Newton iteration goes, and how far it is from the limit.

For each case (the paper's four examples at their fidelity, and a 100 m route), in its own process:

- steps, Newton iterations (rejected step attempts included) and iterations per step;
- per Newton iteration [ms]: the contact kernel; the Python glue of the two user functions
  (their time minus the kernel's); Exudyn's element forces, Jacobians and assembly (its
  ``ODE2RHS`` + ``totalJacobian`` timers minus the user functions); the linear solve
  (``factorization`` + ``newtonIncrement``); the rest (post-step hook, reactions, overhead);
- kernel passes per Newton iteration (1 + 1/iterations-per-step: the force call computes the
  Jacobian blocks too and the Jacobian call reuses them) and user-function calls;
- the limit: one kernel force + Jacobian evaluation (timed alone, median of 10 at the run's final
  state) × the Newton iterations the run needed, and the run's simulation time over that limit.

    nice .venv/bin/python benchmarks/newton_cost.py            # ~3 min on 2 idle cores
    nice .venv/bin/python benchmarks/newton_cost.py --ex23     # Ex. 2 and 3 only
    nice .venv/bin/python benchmarks/newton_cost.py --quick    # smoke run: the fast Example 2 only

Exudyn's timers need ``show.computationTime`` and the solver object, which ``simulate`` builds inside:
each case's process swaps ``solver_settings`` and Exudyn's solver class for the run and restores them
after (the case runs in a process of its own, so nothing else sees the swap).

The machine is shared and noisy: the table is one run; compare shares and ratios, not seconds.
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

# A 100 m route of the kind the tool is for: two long straights, a 90° bend, a 45° rise, gravity,
# check points at the paper's 1 mm reference spacing; simulated over a short window.
ROUTE_100M = {
    "name": "route-100m",
    "cable": {"radius": 0.0025, "density": 1000.0, "youngs_modulus": 1.0e9, "elements": 400},
    "conduit": {"inner_radius": 0.0035, "segments_per_bend": 80, "path": [
        {"straight": 30.0}, {"bend": 90.0, "radius": 1.0, "turn": "left"}, {"straight": 30.0},
        {"bend": 45.0, "radius": 1.0, "turn": "up"}, {"straight": 100.0 - 60.0 - np.pi / 2 - np.pi / 4}]},
    "contact": {"stiffness": 1.0e6, "damping": 1.0e3, "exponent": 1.5, "friction": 0.3,
                "check_points_per_element": 250},
    "pull": {"speed": 0.1, "direction": "forward", "back_tension": 20.0},
    "gravity": {"g": 9.8},
    "solver": {"end_time": 0.1, "step": 1.0e-2, "steady_stop": False},
}


def _case(args):
    """Run one case in this process; return its figures."""
    label, source, end_time = args
    import exudyn as exu
    import exucable.solve.dynamic as solve
    from exucable.scenario.specs import parse_scenario

    if isinstance(source, dict):
        data, parent = dict(source), ROOT / "scenarios"
    else:
        with open(source, "rb") as f:
            data = tomllib.load(f)
        parent = Path(source).parent
    if end_time is not None:
        data["solver"] = dict(data["solver"], end_time=end_time, steady_stop=False)
    sc = parse_scenario(data, parent, default_name=label)

    solvers = []

    class TimedSolver(exu.MainSolverImplicitSecondOrder):
        def SolveSystem(self, *a, **k):
            solvers.append(self)
            return super().SolveSystem(*a, **k)

    base = solve.solver_settings

    def settings(sp):
        s = base(sp)
        s.show.computationTime = True     # fills solver.timer (and prints it: discarded)
        return s

    from exucable.model.build import build_model

    model = build_model(sc)
    # load the compiled kernel before timing (the fixed cost is measured elsewhere); Exudyn's
    # timers start after its initial accelerations, whose user-function calls would otherwise
    # carry it
    c = model.coupling
    q0, v0 = model.coordinates()
    model.kernel.evaluate(q0.reshape(-1).copy(), v0.reshape(-1).copy(), jacobian=True)
    devnull = os.open(os.devnull, os.O_WRONLY)
    saved = os.dup(1)
    os.dup2(devnull, 1)          # Exudyn prints its timer statistics on stdout
    base_solver = exu.MainSolverImplicitSecondOrder
    solve.solver_settings, exu.MainSolverImplicitSecondOrder = settings, TimedSolver
    try:
        out = solve.simulate(model)
    finally:
        solve.solver_settings, exu.MainSolverImplicitSecondOrder = base, base_solver
        os.dup2(saved, 1)
        os.close(devnull)
    timer = solvers[-1].timer
    # the limit: one force + Jacobian pass of the kernel alone at the final state
    q, v = model.coordinates()
    qa, va = q.reshape(-1).copy(), v.reshape(-1).copy()
    ts = []
    for _ in range(10):
        t0 = time.perf_counter()
        model.kernel.evaluate(qa, va, jacobian=True)
        ts.append(time.perf_counter() - t0)
    return {
        "label": label, "status": out.status, "steps": out.steps, "newton": out.newton_iterations,
        "simulated_s": out.end_time_s, "wall_s": out.wall_time_s,
        "kernel_s": c.kernel_time_s, "user_s": c.user_time_s, "passes": c.kernel_evaluations,
        "calls": c.force_calls + c.jacobian_calls,
        "exudyn_rhs_jac_s": timer.ODE2RHS + timer.totalJacobian,
        "linear_s": timer.factorization + timer.newtonIncrement,
        "eval_s": float(np.median(ts)), "n_check_points": model.kernel.n_check_points * model.kernel.n_elements,
    }


def run_case(label, source, end_time=None):
    ctx = mp.get_context("forkserver")
    with ctx.Pool(1) as pool:      # its own process: nothing warm shared between cases
        return pool.apply(_case, ((label, source, end_time),))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ex23", action="store_true", help="Examples 2 and 3 only")
    ap.add_argument("--quick", action="store_true", help="smoke run: the fast (coarse) Example 2 only")
    args = ap.parse_args(argv)
    sc = ROOT / "scenarios"
    cases = [("Ex. 2 bend", sc / "paper_ex2_bend90.toml", None), ("Ex. 3 helix", sc / "paper_ex3_helix.toml", None)]
    if args.quick:
        cases = [("Ex. 2 bend, fast variant", sc / "fast" / "paper_ex2_bend90.toml", None)]
    elif not args.ex23:
        cases = [("Ex. 1 incline", sc / "paper_ex1_incline.toml", None)] + cases + [
            ("Ex. 4 spatial", sc / "paper_ex4_spatial.toml", None), ("100 m route (0.1 s)", ROUTE_100M, None)]
    print(f"# Cost per Newton iteration — {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at start\n")
    print("| case | check points | steps | Newton its | its/step | ms per its | kernel | Python glue | "
          "Exudyn elements+assembly | linear solve | rest | kernel passes/its | limit [s] | wall/limit |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for label, source, end in cases:
        r = run_case(label, source, end)
        n = max(r["newton"], 1)
        glue = r["user_s"] - r["kernel_s"]
        exudyn = r["exudyn_rhs_jac_s"] - r["user_s"]
        rest = r["wall_s"] - r["user_s"] - exudyn - r["linear_s"]
        limit = r["eval_s"] * n

        def ms(x):
            return f"{1e3 * x / n:.2f} ({100 * x / r['wall_s']:.0f} %)"

        print(f"| {label} | {r['n_check_points']} | {r['steps']} | {r['newton']} | {r['newton'] / max(r['steps'], 1):.2f} | "
              f"{1e3 * r['wall_s'] / n:.2f} | {ms(r['kernel_s'])} | {ms(glue)} | {ms(exudyn)} | {ms(r['linear_s'])} | "
              f"{ms(rest)} | {r['passes'] / n:.2f} | {limit:.2f} | {r['wall_s'] / limit:.2f} |", flush=True)
    print(f"\nlimit = one kernel force+Jacobian pass timed alone × the run's Newton iterations; "
          f"load average {os.getloadavg()[0]:.1f} at the end")
    return 0


if __name__ == "__main__":
    sys.exit(main())
