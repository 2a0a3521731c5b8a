"""What one Newton iteration of a steady bundle costs, and where it goes.

    nice .venv/bin/python benchmarks/bundle_iteration.py [--count 3] [--settle 20] [--repeat 7]
        [--relax-steps 300] [--before TREE] [--quick]

The three cables of ``benchmarks/bundle_route.py``'s 100 m route (four bends, the scenario's mesh
rule) are solved steady for ``--settle`` s of CPU from their start, to a state representative of
the solve (the cables resting on one another along the whole route: the start has fewer contacts).
That state is saved, and at it, in a fresh process per tree (interleaved, ``--repeat`` times each):

- the cable-cable coupling's pass: the pair kernel with its Jacobian, assembled on the cables'
  coordinates (:meth:`~exucable.contact.cable_pairs.CableContactKernel.evaluate`), CPU [ms];
- the wall kernels' passes (one per cable) [ms];
- one Newton iteration of the steady solve: a one-iteration pseudo-time step from that state
  (:meth:`~exucable.solve.steady.SteadySolver.pseudo_step`, the kernels' cached pass forgotten first:
  the residual and Jacobian at the state, the linear solve, the residual at the new state) [ms] by
  the tree's static solver (``static``: ours for bundles since ``OwnBundleNewton``, Exudyn's before)
  and by Exudyn's (``exudyn step``), and the step's true residual after [N] (round-off apart, the
  same for both solvers and in both trees when the model's equations are); and the median of
  ``--repeat`` steps in a row at 16 times the spring (each from the last: the start's kernel pass is
  the last step's, as in the continuation: one kernel pass and one linear solve a step);
- a step of the dynamic relaxation (:func:`~exucable.solve.relax.relax_bundle`, ``--relax-steps``
  steps from that state, masses and restarts included) [ms], and the residual it reached [N] (the
  same trajectory in both trees when the residual's bits are);

``--before TREE`` also measures with the exucable package of the source tree TREE (``git archive
<commit> | tar -x -C TREE``; copy ``exucable/contact/__pycache__`` into it with the sources' time
stamps, ``touch -r``, or its kernels compile in its first run). Medians of CPU times measured in
one run on a shared machine: compare the rows with each other.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))


def _scenario(count: int, length_m: float):
    import bundle_route
    from exucable.scenario.specs import parse_scenario

    bends_m = 3 * 0.5 * np.pi * 5.0 + np.pi / 6 * 5.0
    straight = max(1.0, (length_m - bends_m) / 5.0)
    text = bundle_route.SCENARIO.format(count=count, arrangement="triangular", straight=f"{straight:.6g}")
    return parse_scenario(tomllib.loads(text), ROOT, default_name=f"bundle_iteration_{count}")


def settle(count: int, length_m: float, settle_s: float, path: str) -> None:
    """Solve for ``settle_s`` of CPU from the start and save the state reached (the best one)."""
    from exucable.model.bundle import build_bundle_model
    from exucable.solve.steady import SteadySettings, SteadySolver

    model = build_bundle_model(_scenario(count, length_m))
    solver = SteadySolver(model, SteadySettings(time_limit_s=settle_s))
    out = solver.solve()
    state = solver.best[1] if solver.best[1] is not None else solver.store.saved
    np.savez(path, ode2=state[0], ae=state[1])
    print(f"settled: {out.newton_iterations} Newton iterations, status {out.status}, best residual "
          f"{solver.best[0]:.3g} N", flush=True)


def measure(count: int, length_m: float, path: str, repeat: int, settle_s: float, element: str | None,
            relax_steps: int = 300) -> dict:
    """The figures of the module's notes, in this process: the passes at the saved state, then a
    steady solve from the start for ``settle_s`` of CPU (Newton iterations, CPU per iteration)."""
    from exucable.model.bundle import build_bundle_model
    from exucable.solve.steady import SteadySettings, SteadySolver

    sc = _scenario(count, length_m)
    if element is not None:
        sc = sc.replace(**{"solver.cable_element": element})
    model = build_bundle_model(sc)
    saved = np.load(path)
    q = model.layout.coordinates.reshape(-1) + np.asarray(saved["ode2"], dtype=float)[model.ode2_index]
    n = model.walls[0].n_coordinates

    def cpu(fn):
        fn()                                # warm (first call of a kernel, buffers)
        times = []
        for _ in range(repeat):
            t0 = time.process_time()
            fn()
            times.append(time.process_time() - t0)
        return 1e3 * statistics.median(times)

    res = model.between.evaluate(q, jacobian=True)
    pair_ms = cpu(lambda: model.between.evaluate(q, jacobian=True))
    zeros = np.zeros(n)
    wall_ms = cpu(lambda: [k.evaluate(q[i * n:(i + 1) * n], zeros, jacobian=True) for i, k in enumerate(model.walls)])
    # a fresh model for each part: a solver adds its pseudo-time spring to the model's system
    step = {which: _step_ms(build_bundle_model(sc), saved, repeat, which) for which in ("static", "exudyn")}
    relax_ms, relax_N = _relax_ms(build_bundle_model(sc), saved, relax_steps) if model.steady_force_supported \
        else (float("nan"),) * 2
    model = build_bundle_model(sc)
    solver = SteadySolver(model, SteadySettings(time_limit_s=settle_s))
    t0 = time.process_time()
    out = solver.solve()
    solve_s = time.process_time() - t0
    return {"contacts": res.n_in_contact, "pair_ms": pair_ms, "wall_ms": wall_ms, "solve_s": solve_s,
            "newton": out.newton_iterations, "newton_ms": 1e3 * solve_s / max(1, out.newton_iterations),
            "best_N": float(solver.best[0]), "status": out.status, "elements": int(model.mesh.elements),
            "check_points": int(model.mesh.check_points_per_element), "backend": step["static"][3],
            "step_ms": step["static"][0], "step_N": step["static"][1], "chain_ms": step["static"][2],
            "exudyn_step_ms": step["exudyn"][0], "exudyn_step_N": step["exudyn"][1],
            "exudyn_chain_ms": step["exudyn"][2], "relax_ms": relax_ms, "relax_N": relax_N,
            "element": "compiled" if getattr(model.wall_couplings[0], "cable_forces", None) is not None else "exudyn"}


def _at_saved(model, saved) -> None:
    import exudyn as exu

    sd = model.mbs.systemData
    for cfg in (exu.ConfigurationType.Initial, exu.ConfigurationType.Current):
        sd.SetODE2Coordinates(np.asarray(saved["ode2"], dtype=float), configuration=cfg)
        sd.SetAECoordinates(np.asarray(saved["ae"], dtype=float), configuration=cfg)


def _step_ms(model, saved, repeat: int, which: str) -> tuple[float, float, float, str]:
    """Median CPU [ms] of a one-iteration pseudo-time step from the saved state at the initial spring
    rate, the kernels' cached passes forgotten first (two kernel passes: at the start and the end);
    its true residual after [N]; the median CPU [ms] of ``repeat`` steps in a row at 16 times that
    rate, each from the last one's state (as the continuation's accepted steps: the start's pass is
    the last step's, one kernel pass a step); the solver's name."""
    from exucable.solve.newton_system import ExudynStatic
    from exucable.solve.steady import SteadySettings, SteadySolver, static_settings

    solver = SteadySolver(model, SteadySettings())       # (its spring's Assemble resets the coordinates)
    if which == "exudyn":
        solver.static = ExudynStatic(model.mbs, static_settings)
    _at_saved(model, saved)
    solver.store.save()
    times, residual = [], float("nan")
    for k in range(repeat + 1):
        model.coupling.forget_evaluation()
        solver.store.saved = solver.store.saved[:2] + (None,)
        t0 = time.process_time()
        ok, _, _ = solver.pseudo_step(solver.c0, solver.one_iteration_settings)
        if k:                                   # the first warms the buffers
            times.append(time.process_time() - t0)
        residual = solver.true_residual() if ok else float("nan")
    chain = []
    for k in range(repeat + 1):
        t0 = time.process_time()
        # a spring 16 times the first step's: steps that stay near the state, as a converging
        # continuation's do (at c0 they wander off to residuals of 1 kN, with more contacts)
        solver.pseudo_step(16.0 * solver.c0, solver.one_iteration_settings)
        if k:
            chain.append(time.process_time() - t0)
        solver.store.save()
    name = "exudyn" if isinstance(solver.static, ExudynStatic) else "exucable"
    return 1e3 * statistics.median(times), residual, 1e3 * statistics.median(chain), name


def _relax_ms(model, saved, steps: int) -> tuple[float, float]:
    """CPU per step [ms] of ``steps`` steps of the dynamic relaxation from the saved state at full
    load, and the smallest residual reached [N]."""
    from exucable.solve.relax import RelaxSettings, relax_bundle

    _at_saved(model, saved)
    model.coupling.forget_evaluation()
    out = relax_bundle(model, RelaxSettings(residual_N=1e-12, max_steps=steps, stall_steps=steps + 1))
    return 1e3 * out.cpu_s / max(1, out.steps), out.residual_N


def _child(tree: str | None, element: str | None, args, path: str) -> dict:
    env = dict(os.environ)
    if tree:
        env["PYTHONPATH"] = str(Path(tree).resolve())
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    cmd = [sys.executable, __file__, "--child", path, "--count", str(args.count), "--length", str(args.length),
           "--repeat", str(args.repeat), "--settle", str(args.settle), "--relax-steps", str(args.relax_steps)] \
        + (["--element", element] if element else [])
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=tempfile.gettempdir())
    if out.returncode:
        raise RuntimeError(out.stderr[-2000:])
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--count", type=int, default=3)
    p.add_argument("--length", type=float, default=100.0, help="route length [m] (approximately)")
    p.add_argument("--settle", type=float, default=20.0, help="CPU seconds of the steady solve to the state timed")
    p.add_argument("--repeat", type=int, default=7)
    p.add_argument("--relax-steps", type=int, default=300, help="steps of the dynamic relaxation timed")
    p.add_argument("--runs", type=int, default=2, help="fresh processes per tree, interleaved")
    p.add_argument("--before", metavar="TREE")
    p.add_argument("--quick", action="store_true", help="two cables, 12 m, 2 s of settling (a smoke run)")
    p.add_argument("--child", metavar="STATE", help=argparse.SUPPRESS)
    p.add_argument("--element", help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.child:
        print(json.dumps(measure(args.count, args.length, args.child, args.repeat, args.settle, args.element,
                                 args.relax_steps)))
        return 0
    if args.quick:
        args.count, args.length, args.settle, args.repeat, args.runs, args.relax_steps = 2, 12.0, 2.0, 2, 1, 20
    with tempfile.TemporaryDirectory() as tmp:
        path = str(Path(tmp) / "state.npz")
        settle(args.count, args.length, args.settle, path)
        trees = {"before": (args.before, None)} if args.before else {}
        trees.update({"this, exudyn element": (None, "exudyn"), "this": (None, None)})
        rows = {k: [] for k in trees}
        for _ in range(args.runs):
            for label, (tree, element) in trees.items():
                rows[label].append(_child(tree, element, args, path))
    first = next(iter(rows.values()))[0]
    print(f"# steady bundle: {args.count} cables, {args.length:g} m route, {first['elements']} elements each, "
          f"{first['check_points']} check points per element; the passes at the state the solve reached after "
          f"{args.settle:g} s CPU ({first['contacts']} cable-cable contacts), CPU medians of {args.repeat} [ms]; then "
          f"the solve from the start for {args.settle:g} s CPU; one row per process; load {os.getloadavg()[0]:.1f}")
    print("| tree | cable element | static solver | cable-cable pass (kernel + Jacobian) [ms] | wall passes [ms] | "
          "one-iteration step, cold [ms] | its residual [N] | steps in a row [ms] | Exudyn's step, cold [ms] | "
          "its residual [N] | Exudyn's steps in a row [ms] | relaxation step [ms] | "
          f"residual after {args.relax_steps} [N] | solve CPU [s] | Newton iterations | solve CPU per iteration [ms] | "
          "smallest residual [N] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for label, runs in rows.items():
        for r in runs:
            print(f"| {label} | {r['element']} | {r['backend']} | {r['pair_ms']:.2f} | {r['wall_ms']:.2f} | "
                  f"{r['step_ms']:.1f} | {r['step_N']:.6g} | {r['chain_ms']:.1f} | {r['exudyn_step_ms']:.1f} | "
                  f"{r['exudyn_step_N']:.6g} | {r['exudyn_chain_ms']:.1f} | {r['relax_ms']:.2f} | {r['relax_N']:.6g} | "
                  f"{r['solve_s']:.1f} | {r['newton']} | {r['newton_ms']:.1f} | {r['best_N']:.4g} |")
    figures = ("pair_ms", "wall_ms", "step_ms", "chain_ms", "exudyn_step_ms", "exudyn_chain_ms", "relax_ms",
               "newton_ms")
    med = {k: {f: statistics.median(r[f] for r in v) for f in figures} for k, v in rows.items()}
    base = "before" if args.before else "this, exudyn element"
    for label in rows:
        if label != base:
            print(f"{label} / {base} (medians): " + ", ".join(f"{f} {med[label][f] / med[base][f]:.2f}" for f in figures))
    this = med["this"]
    print(f"this tree, our step / Exudyn's step in the same process: cold {this['step_ms'] / this['exudyn_step_ms']:.2f}, "
          f"in a row {this['chain_ms'] / this['exudyn_chain_ms']:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
