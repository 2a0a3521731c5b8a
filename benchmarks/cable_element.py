"""One steady Newton iteration with Exudyn's ANCF cable element and with the compiled one, side by side.

For each route length (``benchmarks/long_routes.py``'s realistic routes: 30 mm cable, gravity, μ 0.2,
a 15° bend every ~350 m; the solved mesh of the default rules), in a process of its own, the same
model built twice: ``[solver] cable_element = "exudyn"`` (``ObjectANCFCable`` objects, whose
Jacobian Exudyn takes by automatic differentiation over positions and velocities) and
``"compiled"`` (exucable's compiled element inside the contact's user function,
``exucable/contact/ancf_cable.py``). Their calls interleaved (exudyn, compiled, exudyn, ...) so that
both see the same load, CPU time per call, the median of ``--repeat`` calls at slightly moved
coordinates:

- the ODE2 residual, the ODE2 Jacobian (after a residual at the same state, as in Newton);
- one whole one-iteration static solve (what a steady pseudo-time step costs), with the share of
  Exudyn's own timers (Jacobian, factorisation, residuals);
- and, as a check that both models are the same equations, the largest difference of their residuals
  at the start state relative to its largest entry.

``--runs``: whole steady runs (``run_scenario``, no files) with either element, one after the other
in this process, on the paper's examples (fast variants), two industry routes and the 1 km long
route: the pulling forces, their relative difference, Newton iterations and the run's CPU time.

    nice .venv/bin/python benchmarks/cable_element.py                  # 1 and 10 km, a few minutes CPU
    nice .venv/bin/python benchmarks/cable_element.py --lengths 1000   # one length
    nice .venv/bin/python benchmarks/cable_element.py --runs           # the pulling force either way
    nice .venv/bin/python benchmarks/cable_element.py --quick          # smoke run: 200 m, 3 repeats

Whole runs (build, both solves, post) with either element: ``benchmarks/long_routes.py
--compare-elements``. The machine is shared and noisy: compare the ratios of one run, not seconds
across runs.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

ELEMENTS = ("exudyn", "compiled")


def measure(length_m: float, repeat: int) -> dict:
    """Median CPU time per call [s] of each part, per element, the elements' calls interleaved."""
    import numpy as np
    import exudyn as exu

    import long_routes
    import exucable.solve.steady as steady
    from exucable.model.build import build_model
    from exucable.scenario.specs import parse_scenario

    models = {}
    for element in ELEMENTS:
        sc = parse_scenario(long_routes.route_data(length_m, element), ROOT, default_name="route")
        first = build_model(sc)
        models[element] = build_model(sc, refine=2.0, check_points_per_element=first.mesh.check_points_per_element,
                                      references=first.start)
    rng = np.random.default_rng(0)
    state = {}
    for element, model in models.items():
        spring = steady.PseudoTimeSpring(model)
        spring.rate = steady.initial_spring_rate(model)
        solver = exu.MainSolverStatic()
        solver.InitializeSolver(model.mbs, steady.static_settings())
        q0 = np.array(model.mbs.systemData.GetODE2Coordinates())
        state[element] = (model, solver, q0)
    n = state["exudyn"][2].size
    moves = [1e-12 * rng.random(n) for _ in range(repeat)]

    def moved(element, k):
        model, _, q0 = state[element]
        model.mbs.systemData.SetODE2Coordinates(q0 + moves[k])

    # the same equations: residuals at the start state (the kernels' first calls load them from numba's cache)
    rhs = {}
    for element, (model, solver, q0) in state.items():
        model.mbs.systemData.SetODE2Coordinates(q0)
        solver.ComputeODE2RHS(model.mbs)
        rhs[element] = np.array(solver.GetSystemResidual())[:n]
    diff = float(np.max(np.abs(rhs["compiled"] - rhs["exudyn"])) / np.max(np.abs(rhs["exudyn"])))

    def timed(f, before=moved):
        out = {e: [] for e in ELEMENTS}
        for k in range(repeat):
            for e in ELEMENTS:
                before(e, k)
                t = time.process_time()
                f(e)
                out[e].append(time.process_time() - t)
        return {e: float(np.median(v)) for e, v in out.items()}

    r = {"length_m": length_m, "elements": state["exudyn"][0].mesh.elements, "coordinates": n,
         "residual_difference": diff}
    r["residual"] = timed(lambda e: state[e][1].ComputeODE2RHS(state[e][0].mbs))
    r["jacobian"] = timed(lambda e: state[e][1].ComputeJacobianODE2RHS(state[e][0].mbs, 1.0, 0.0, 0.0, 0),
                          before=lambda e, k: (moved(e, k), state[e][1].ComputeODE2RHS(state[e][0].mbs)))
    one = steady.static_settings(tolerance=1.0, max_iterations=1)
    r["one_iteration_solve"] = timed(lambda e: exu.MainSolverStatic().SolveSystem(state[e][0].mbs, one))
    clocked = steady.static_settings(tolerance=1.0, max_iterations=1)
    clocked.show.computationTime = True   # Exudyn's timers (it prints them: discarded below)
    timers = {e: [] for e in ELEMENTS}

    def with_timers(e):
        s = exu.MainSolverStatic()
        devnull, saved = os.open(os.devnull, os.O_WRONLY), os.dup(1)
        os.dup2(devnull, 1)
        try:
            s.SolveSystem(state[e][0].mbs, clocked)
        finally:
            os.dup2(saved, 1)
            os.close(devnull)
            os.close(saved)
        tm = s.timer
        timers[e].append([tm.totalJacobian, tm.factorization + tm.newtonIncrement, tm.ODE2RHS, tm.total])

    timed(with_timers)
    r["exudyn_timers"] = {e: [float(x) for x in np.median(np.array(v), axis=0)] for e, v in timers.items()}
    return r


RUN_CASES = ("fast/paper_ex1_incline", "fast/paper_ex2_bend90", "fast/paper_ex3_helix", "fast/paper_ex4_spatial",
             "industry/commscope_conquest_run_a_h", "industry/gera_wire_pulling_example", "long route 1 km")


def runs(cases=RUN_CASES) -> None:
    """Whole steady runs with either element: the pulling force and its relative difference."""
    import long_routes
    from exucable.data import data_path
    from exucable.run import run_scenario
    from exucable.scenario.specs import load_scenario, parse_scenario

    print("| case (status) | elements | F exudyn [N] | F compiled [N] | compiled / exudyn − 1 | Newton, the solve, "
          "exudyn / compiled | run CPU exudyn / compiled [s] |")
    print("|---|---|---|---|---|---|---|")
    for case in cases:
        out = {}
        for element in ELEMENTS:
            if case.startswith("long route"):
                sc = parse_scenario(long_routes.route_data(1000.0, element), ROOT, default_name="route")
            else:
                sc = load_scenario(data_path("scenarios", *f"{case}.toml".split("/")))
                sc = sc.replace(**{"solver.mode": "steady", "solver.cable_element": element})
            t = time.process_time()
            s = run_scenario(sc, None, plots=False).summary
            out[element] = (s["pull_force_N"], s["newton_iterations"], time.process_time() - t, s["status"],
                            s["mesh"]["elements"])
        (fa, na, ca, sa, ne), (fb, nb, cb, sb, _) = out["exudyn"], out["compiled"]
        rel = fb / fa - 1.0 if fa and fb else float("nan")
        print(f"| {case} ({sa}/{sb}) | {ne} | {fa:.10g} | {fb:.10g} | {rel:+.1e} | {na} / {nb} | "
              f"{ca:.2f} / {cb:.2f} |", flush=True)


def in_child(length_m: float, repeat: int) -> dict:
    cmd = [sys.executable, __file__, "--case", f"{length_m:g}", str(repeat)]
    done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def report(r: dict) -> None:
    ms = lambda x: f"{1e3 * x:8.1f}"
    print(f"\n## {r['length_m'] / 1000:g} km: {r['elements']} elements, {r['coordinates']} coordinates; "
          f"residuals at the start differ by {r['residual_difference']:.1e} of the largest\n")
    print("| part (CPU per call, median) | exudyn [ms] | compiled [ms] | compiled / exudyn |")
    print("|---|---|---|---|")
    for name, key in (("residual", "residual"), ("ODE2 Jacobian", "jacobian"),
                      ("one whole one-iteration static solve", "one_iteration_solve")):
        x, y = r[key]["exudyn"], r[key]["compiled"]
        print(f"| {name} | {ms(x)} | {ms(y)} | {y / x if x > 0 else float('nan'):5.2f} |")
    for e in ELEMENTS:
        t = r["exudyn_timers"][e]
        print(f"\nExudyn's timers of a one-iteration solve, {e} (wall-clock shares of its total): the Jacobian "
              f"{100 * t[0] / t[3]:.0f} %, factorisation + solve {100 * t[1] / t[3]:.0f} %, the residuals "
              f"{100 * t[2] / t[3]:.0f} %")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lengths", type=float, nargs="+", default=[1000.0, 10000.0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--quick", action="store_true", help="smoke run: a 200 m route, 3 repeats")
    ap.add_argument("--runs", action="store_true", help="whole steady runs with either element (see the notes)")
    ap.add_argument("--case", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.runs:
        runs(RUN_CASES[1:2] if args.quick else RUN_CASES)
        return
    if args.case:
        print(json.dumps(measure(float(args.case[0]), int(args.case[1]))))
        return
    lengths, repeat = ([200.0], 3) if args.quick else (args.lengths, args.repeat)
    print(f"# One steady Newton iteration, Exudyn's ANCF cable vs the compiled one — {os.cpu_count()} cores, "
          f"load {os.getloadavg()[0]:.1f} at start")
    for L in lengths:
        report(in_child(L, repeat))


if __name__ == "__main__":
    main()
