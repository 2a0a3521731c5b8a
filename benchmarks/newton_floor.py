"""Where one steady Newton iteration's CPU time goes on a long route, and what its floor is.

For each route length (``benchmarks/long_routes.py``'s realistic routes: 30 mm cable, gravity,
μ 0.2, a 15° bend every ~350 m; the solved mesh of the default rules; Exudyn's ANCF cable element,
``solver.cable_element = "exudyn"``: the compiled one is ``benchmarks/cable_element.py``'s), in a process of its own,
two variants of the contact coupling's Jacobian handover, their calls interleaved (before, after,
before, ...) so that both see the same load:

- ``before``: the handover as it was (``-(f_q J_q + f_v J_q̇)``, ``np.bincount``, three boolean
  gathers and ``np.column_stack``), kept below in :func:`_triplets_before` to measure against;
- ``after``: :meth:`exucable.model.coupling.ContactCoupling.jacobian_triplets` (blocks scaled once,
  zeros dropped by one gather of 24-byte records; the same triplets bit for bit,
  ``tests/test_contact_model.py``).

Each part is called on its own through Exudyn's solver methods, CPU time per call, the median of
``--repeat`` calls per variant at slightly moved coordinates (so that no kernel pass is reused where a Newton
iteration would not reuse one):

- the residual (Exudyn's ANCF elements, our contact coupling's user function with its kernel pass,
  the pseudo-time spring's user function);
- the ODE2 Jacobian (the ANCF elements' by automatic differentiation inside Exudyn, our two user
  functions' sparse triplets, the pseudo-time spring's);
- one whole one-iteration static solve, with Exudyn's own timers (Jacobian, factorisation,
  residuals), which is what a steady pseudo-time step costs;
- the floor: the parts left when our Python glue costs nothing (Exudyn's elements, assembly and LU,
  the compiled contact kernel).

Also measured, on the one-iteration solve: Exudyn's
``parallel.numberOfThreads = 2`` (CPU and wall), and ``linearSolver.reuseAnalyzedPattern`` on a
four-iteration solve (the pattern analysis is kept only within one ``SolveSystem`` call).

    nice .venv/bin/python benchmarks/newton_floor.py                  # 1 and 10 km, ~5 min CPU
    nice .venv/bin/python benchmarks/newton_floor.py --lengths 1000   # one length
    nice .venv/bin/python benchmarks/newton_floor.py --quick          # smoke run: 200 m, 3 repeats

The machine is shared and noisy: compare the ratios of one run, not seconds across runs.
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


def _triplets_before(self, res, f_q, f_v, elastic_blocks=None):
    """The contact Jacobian's triplets as the coupling built them before (the baseline; the models
    here have Exudyn's cable elements, so no compiled element's blocks)."""
    import numpy as np

    assert elastic_blocks is None

    if not hasattr(self, "_before_rows"):
        self._before_rows = self._triplets[:, 0].copy()
        self._before_cols = self._triplets[:, 1].copy()
    blocks = -(f_q * res.jac_q_blocks + f_v * res.jac_qt_blocks)
    vals = np.bincount(self._inverse, weights=blocks.reshape(-1), minlength=self._n_unique)
    nz = vals != 0.0
    return np.column_stack([self._before_rows[nz], self._before_cols[nz], vals[nz]])


def measure(length_m: float, repeat: int) -> dict:
    """Every part's median CPU time per call [s] on the solved mesh of the route of ``length_m``,
    per variant (``{"before": ..., "after": ...}``, the variants' calls interleaved)."""
    import types

    import numpy as np
    import exudyn as exu

    import long_routes
    import exucable.model.coupling as coupling
    import exucable.solve.steady as steady
    from exucable.model.build import build_model
    from exucable.scenario.specs import parse_scenario

    after = coupling.ContactCoupling.jacobian_triplets
    variants = {"before": _triplets_before, "after": after}
    # the coupling's own timers then count this process's CPU time, not wall
    coupling.time = types.SimpleNamespace(perf_counter=time.process_time)
    # Exudyn's ANCF elements, whose floor this measures (the compiled element: benchmarks/cable_element.py)
    sc = parse_scenario(long_routes.route_data(length_m, "exudyn"), ROOT, default_name="route")
    first = build_model(sc)
    model = build_model(sc, refine=2.0, check_points_per_element=first.mesh.check_points_per_element,
                        references=first.start)
    mbs, c = model.mbs, model.coupling
    spring = steady.PseudoTimeSpring(model)
    spring.rate = steady.initial_spring_rate(model)
    sd = mbs.systemData
    q0 = np.array(sd.GetODE2Coordinates())
    n = q0.size
    rng = np.random.default_rng(0)

    def moved():
        sd.SetODE2Coordinates(q0 + 1e-12 * rng.random(n))

    def timed(f, count=repeat, before=moved):
        """Per variant: median CPU time of f [s], and the coupling's user-function and kernel CPU
        time per call; the variants' calls interleaved."""
        out = {v: [] for v in variants}
        for _ in range(count):
            for v, method in variants.items():
                coupling.ContactCoupling.jacobian_triplets = method
                before()
                t, u, k = time.process_time(), c.user_time_s, c.kernel_time_s
                f()
                out[v].append((time.process_time() - t, c.user_time_s - u, c.kernel_time_s - k))
        coupling.ContactCoupling.jacobian_triplets = after
        return {v: [float(x) for x in np.median(np.array(o), axis=0)] for v, o in out.items()}

    solver = exu.MainSolverStatic()
    solver.InitializeSolver(mbs, steady.static_settings())
    moved()
    solver.ComputeODE2RHS(mbs)            # warm-up: the kernel's first call loads it from numba's cache
    r = {"length_m": length_m, "elements": model.mesh.elements,
         "check_points": model.mesh.elements * model.mesh.check_points_per_element, "coordinates": n}
    r["residual"] = timed(lambda: solver.ComputeODE2RHS(mbs))
    # the Jacobian call right after a residual at the same state: its kernel pass is reused, as in Newton
    r["jacobian"] = timed(lambda: solver.ComputeJacobianODE2RHS(mbs, 1.0, 0.0, 0.0, 0),
                          before=lambda: (moved(), solver.ComputeODE2RHS(mbs)))
    qa, va = c.absolute(q0[:c.n] * 0.0, np.zeros(c.n))
    res = c.kernel.evaluate(qa, va, jacobian=True, held_onset=c.held_onset)
    r["kernel_with_jacobian"] = timed(lambda: c.kernel.evaluate(qa, va, jacobian=True, held_onset=c.held_onset))
    r["handover"] = timed(lambda: c.jacobian_triplets(res, 1.0, 0.0))
    ql = list(q0[:c.n])
    r["list_to_array"] = timed(lambda: np.asarray(ql, dtype=float))
    r["array_to_list"] = timed(lambda: q0[:c.n].tolist())
    zeros = [0.0] * spring.n
    r["spring_jacobian"] = timed(lambda: spring._jacobian(mbs, 0.0, 0, zeros, zeros, 1.0, 0.0))

    one = steady.static_settings(tolerance=1.0, max_iterations=1)
    r["one_iteration_solve"] = timed(lambda: exu.MainSolverStatic().SolveSystem(mbs, one))
    clocked = steady.static_settings(tolerance=1.0, max_iterations=1)
    clocked.show.computationTime = True   # Exudyn's timers (it prints them: discarded below)
    timers = []

    def with_timers():
        s = exu.MainSolverStatic()
        devnull, saved = os.open(os.devnull, os.O_WRONLY), os.dup(1)
        os.dup2(devnull, 1)
        try:
            s.SolveSystem(mbs, clocked)
        finally:
            os.dup2(saved, 1)
            os.close(devnull)
            os.close(saved)
        tm = s.timer
        timers.append([tm.totalJacobian, tm.factorization + tm.newtonIncrement, tm.ODE2RHS, tm.total])

    timed(with_timers)
    # (interleaved: the even calls were the baseline's)
    r["exudyn_timers"] = {v: [float(x) for x in np.median(np.array(timers[i::2]), axis=0)]
                          for i, v in enumerate(variants)}
    threads = steady.static_settings(tolerance=1.0, max_iterations=1)
    threads.parallel.numberOfThreads = 2

    def wall_and_cpu(settings):
        """Median CPU and wall time [s] of a static solve with ``settings``."""
        w = []
        for _ in range(repeat):
            moved()
            t0, c0 = time.perf_counter(), time.process_time()
            exu.MainSolverStatic().SolveSystem(mbs, settings)
            w.append((time.process_time() - c0, time.perf_counter() - t0))
        return [float(x) for x in np.median(np.array(w), axis=0)]

    r["threads_1"] = wall_and_cpu(one)
    r["threads_2"] = wall_and_cpu(threads)
    four = steady.static_settings(tolerance=1e-300, max_iterations=4, absolute_tolerance_N=1e-300)
    reuse = steady.static_settings(tolerance=1e-300, max_iterations=4, absolute_tolerance_N=1e-300)
    reuse.linearSolver.reuseAnalyzedPattern = True
    r["four_iterations"] = wall_and_cpu(four)
    r["four_iterations_reuse"] = wall_and_cpu(reuse)
    return r


def in_child(length_m: float, repeat: int) -> dict:
    cmd = [sys.executable, __file__, "--case", f"{length_m:g}", str(repeat)]
    done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def report(r: dict) -> None:
    ms = lambda x: f"{1e3 * x:8.1f}"
    print(f"\n## {r['length_m'] / 1000:g} km: {r['elements']} elements, {r['check_points']} check points, "
          f"{r['coordinates']} coordinates\n")
    print("| part (CPU per call, median) | before [ms] | after [ms] | after / before |")
    print("|---|---|---|---|")
    rows = [
        ("residual, whole", "residual", 0),
        ("  of it our contact user function (kernel pass included)", "residual", 1),
        ("ODE2 Jacobian, whole", "jacobian", 0),
        ("  of it our contact user function (kernel pass reused)", "jacobian", 1),
        ("  of it the contact Jacobian's triplets alone", "handover", 0),
        ("one whole one-iteration static solve", "one_iteration_solve", 0),
    ]
    for name, key, i in rows:
        x, y = r[key]["before"][i], r[key]["after"][i]
        print(f"| {name} | {ms(x)} | {ms(y)} | {y / x if x > 0 else float('nan'):5.2f} |")
    # Exudyn's timers are wall clock (and run slower with the timers on): their shares, not their seconds
    t = r["exudyn_timers"]["after"]
    print(f"\nExudyn's own timers of a one-iteration solve (wall-clock shares of its total, after): the Jacobian "
          f"{100 * t[0] / t[3]:.0f} %, factorisation + solve {100 * t[1] / t[3]:.0f} %, the two residuals "
          f"{100 * t[2] / t[3]:.0f} %")
    # the floor: what is left when our Python glue costs nothing
    a = {k: v["after"] for k, v in r.items() if isinstance(v, dict)}
    it, spring = a["one_iteration_solve"][0], a["spring_jacobian"][0]
    ours = 2 * a["residual"][1] + a["jacobian"][1]               # our user functions: two residuals, one Jacobian
    kernel = 2 * a["residual"][2] + a["jacobian"][2]             # their kernel passes (the Jacobian's is reused)
    glue = ours - kernel
    rest = it - ours - spring
    lists = 12 * a["array_to_list"][0]        # q and q̇ as lists: 2 objects x (2 residuals + 1 Jacobian) x 2
    print(f"floor of one iteration ({ms(it).strip()} ms CPU): Exudyn's own part (ANCF residuals, the ANCF Jacobian "
          f"by automatic differentiation, assembly, LU, handing coordinates to Python) ≈ {ms(rest).strip()} ms "
          f"({100 * rest / it:.0f} %), of it making the user functions' coordinate lists ≈ {ms(lists).strip()} ms "
          f"(12 lists; tolist as a proxy); two contact kernel passes with their Jacobian {ms(kernel).strip()} ms "
          f"({100 * kernel / it:.0f} %; one pass alone {ms(a['kernel_with_jacobian'][0]).strip()} ms); our Python "
          f"glue ≈ {ms(glue).strip()} ms ({100 * glue / it:.0f} %), of it turning the lists into arrays "
          f"{ms(6 * a['list_to_array'][0]).strip()} ms and the contact Jacobian's triplets "
          f"{ms(a['handover'][0]).strip()} ms; the pseudo-time spring's Jacobian {ms(spring).strip()} ms")
    (c1, w1), (c2, w2) = r["threads_1"], r["threads_2"]
    print(f"Exudyn numberOfThreads 1 → 2, one-iteration solve: CPU {ms(c1).strip()} → {ms(c2).strip()} ms "
          f"({c2 / c1:.2f}×), wall {ms(w1).strip()} → {ms(w2).strip()} ms ({w2 / w1:.2f}×) at load "
          f"{os.getloadavg()[0]:.1f}")
    (c4, _), (r4, _) = r["four_iterations"], r["four_iterations_reuse"]
    print(f"reuseAnalyzedPattern, a four-iteration static solve: CPU {ms(c4).strip()} → {ms(r4).strip()} ms "
          f"({r4 / c4:.2f}×); a steady pseudo-time step is one iteration, where it cannot act")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lengths", type=float, nargs="+", default=[1000.0, 10000.0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--quick", action="store_true", help="smoke run: a 200 m route, 3 repeats")
    ap.add_argument("--case", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.case:
        print(json.dumps(measure(float(args.case[0]), int(args.case[1]))))
        return
    lengths, repeat = ([200.0], 3) if args.quick else (args.lengths, args.repeat)
    print(f"# One steady Newton iteration's parts, before/after — {os.cpu_count()} cores, load "
          f"{os.getloadavg()[0]:.1f} at start")
    for L in lengths:
        report(in_child(L, repeat))


if __name__ == "__main__":
    main()
