"""Newton iterations and kernel passes of the steady solve, case by case, in one run.

For each case (the paper's examples and their coarse variants, Fig. 12's coils and the coarse
sweep's, the industry worked pulls, the 100 m study route, the 100 m and, with ``--long``, 1 km
benchmark routes of ``steady_scale.py``) it builds the steady model, solves it and prints the
Newton iterations, the pseudo-time steps tried (rejected ones included), the contact kernel's
passes, the solve's wall time, the pulling force and whether the exact-step continuation ran
(Newton iterations > steps tried: a one-iteration step takes exactly one).

``--set NAME=VALUE`` overrides a field of :class:`exucable.solve.steady.SteadySettings` (e.g.
``rate_fall=16``) to compare a rule across all cases (passed to every solve of this run); ``--tight`` also solves each case to 1/1000 of the stop
tolerance and prints how far the pulling force moves (how converged it is); ``--trace CASE``
prints, for each accepted pseudo-time step of one case, its residual and the check points whose
contact state (δ > 0) still differs from the converged one.

    nice .venv/bin/python benchmarks/steady_iterations.py [--only ex4,ex3] [--long] [--tight]
    nice .venv/bin/python benchmarks/steady_iterations.py --trace ex4
    nice .venv/bin/python benchmarks/steady_iterations.py --quick     # smoke run: ex2-coarse only
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

from exucable.model.build import build_model
from exucable.scenario.specs import load_scenario, parse_scenario
from exucable.sweep.spec import load_sweep
from exucable.solve.steady import SteadySettings, solve_steady

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"
PAPER = {"ex1": "paper_ex1_incline", "ex2": "paper_ex2_bend90", "ex3": "paper_ex3_helix", "ex4": "paper_ex4_spatial"}


def cases(long: bool = False) -> dict:
    """Case name -> a function returning its scenario (any mode; solved in steady mode)."""
    out = {}
    for key, stem in PAPER.items():
        out[key] = lambda stem=stem: load_scenario(SCENARIOS / f"{stem}.toml")
        out[f"{key}-coarse"] = lambda stem=stem: load_scenario(SCENARIOS / "fast" / f"{stem}.toml")
    for folder, tag in ((SCENARIOS / "sweeps", "fig12"), (SCENARIOS / "sweeps" / "fast", "fig12-coarse")):
        sweep = load_sweep(folder / "paper_fig12_coils.toml")
        for i, case in enumerate(sweep.cases):
            out[f"{tag}-{i + 1}"] = lambda scenario=case.scenario: scenario
    for path in sorted((SCENARIOS / "industry").glob("*.toml")):
        out[path.stem] = lambda path=path: load_scenario(path)
    out["route100-study"] = lambda: load_scenario(SCENARIOS / "studies" / "route100_4bends.toml")
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import steady_scale

    out["bench-100m"] = lambda: steady_scale.route_scenario(100.0)
    if long:
        out["bench-1km"] = lambda: steady_scale.route_scenario(1000.0)
    return out


def steady(scenario, name: str):
    """``scenario`` with ``solver.mode = "steady"``."""
    data = scenario.to_dict()
    return parse_scenario({**data, "solver": {**data["solver"], "mode": "steady"}}, SCENARIOS, default_name=name)


class _StateTrace:
    """A progress sink that keeps the cable's coordinates and the residual of every accepted step."""

    def __init__(self, model):
        self.model = model
        self.states, self.residuals = [], []

    def update(self, fraction, text=""):
        q = np.asarray(self.model.mbs.systemData.GetODE2Coordinates())[self.model.ode2_index]
        self.states.append(self.model.coupling.q_ref + q)
        self.residuals.append(text.split("residual ")[1].split(" N")[0] if "residual " in text else "?")

    def close(self):
        pass


def trace(name: str, scenario, settings: SteadySettings) -> None:
    """Per accepted step: residual, check points in contact, and those whose state differs from the last."""
    model = build_model(steady(scenario, name))
    sink = _StateTrace(model)
    out = solve_steady(model, progress=sink, settings=settings)
    kernel = model.kernel
    zero = np.zeros_like(sink.states[-1])
    final = kernel.points(sink.states[-1], zero).penetration_m > 0.0
    print(f"{name}: {out.status}, {out.newton_iterations} Newton iterations, {out.message}; "
          f"{final.size} check points, {int(final.sum())} in contact at the end")
    print("step  residual [N]  in contact  differing from the end")
    for i, q in enumerate(sink.states):
        touch = kernel.points(q, zero).penetration_m > 0.0
        print(f"{i + 1:4d}  {sink.residuals[i]:>12s}  {int(touch.sum()):10d}  {int(np.count_nonzero(touch != final)):10d}")


def solve(name: str, scenario, settings: SteadySettings) -> dict:
    model = build_model(steady(scenario, name))
    t0 = time.perf_counter()
    out = solve_steady(model, settings=settings)
    wall = time.perf_counter() - t0
    F = out.history.pull_force_N[-1] if out.history.pull_force_N else float("nan")
    return {"status": out.status, "newton": out.newton_iterations, "steps": out.steps,
            "accepted": len(out.history.pull_force_N), "passes": model.coupling.kernel_evaluations,
            "wall_s": wall, "F": F, "message": out.message}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", help="comma-separated case names")
    ap.add_argument("--long", action="store_true", help="include the 1 km benchmark route")
    ap.add_argument("--tight", action="store_true", help="also solve to 1/1000 of the stop tolerance")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="override a field of exucable.solve.steady.SteadySettings")
    ap.add_argument("--trace", metavar="CASE", help="per-step residual and contact state of one case")
    ap.add_argument("--quick", action="store_true", help="smoke run: the case ex2-coarse only")
    args = ap.parse_args(argv)
    if args.quick and not args.only:
        args.only = "ex2-coarse"
    kinds = {f.name: f.type for f in dataclasses.fields(SteadySettings)}
    overrides = {}
    for item in args.set:
        key, _, value = item.partition("=")
        key = key.strip().lower()
        if key not in kinds:
            ap.error(f"--set {item}: SteadySettings has no field {key!r}; fields: {', '.join(kinds)}")
        overrides[key] = int(float(value)) if kinds[key] == "int" else float(value)
    return run(ap, args, dataclasses.replace(SteadySettings(), **overrides))


def run(ap, args, settings: SteadySettings) -> int:
    """The table (or the trace) of the cases ``args`` names."""
    table = cases(long=args.long or (args.only is not None and "bench-1km" in args.only))
    if args.trace:
        if args.trace not in table:
            ap.error(f"--trace: no case {args.trace!r}; cases: {', '.join(table)}")
        trace(args.trace, table[args.trace](), settings)
        return 0
    wanted = args.only.split(",") if args.only else list(table)
    unknown = [w for w in wanted if w not in table]
    if unknown:
        ap.error(f"--only: no case {', '.join(unknown)}; cases: {', '.join(table)}")
    tight = dataclasses.replace(settings, steady_residual=settings.steady_residual / 1000.0)
    # compile the kernels before the first timed solve
    solve("warm-up", table["ex1-coarse"](), settings)
    print(f"{'case':34s} {'status':6s} {'Newton':>6s} {'steps':>5s} {'kept':>4s} {'passes':>6s} {'solve [s]':>9s} "
          f"{'pulling force [N]':>18s}" + ("  vs tol/1000" if args.tight else "") + "  exact steps")
    totals = np.zeros(3)
    for name in wanted:
        r = solve(name, table[name](), settings)
        totals += (r["newton"], r["passes"], r["wall_s"])
        line = (f"{name:34s} {r['status']:6s} {r['newton']:6d} {r['steps']:5d} {r['accepted']:4d} {r['passes']:6d} "
                f"{r['wall_s']:9.2f} {r['F']:18.10g}")
        if args.tight:
            t = solve(name, table[name](), tight)
            line += f"  {r['F'] / t['F'] - 1:+.1e}" if t["status"] == "ok" else f"  ({t['status']})"
        line += "  yes" if r["newton"] > r["steps"] else "  no"
        print(line, flush=True)
    print(f"{'total':34s} {'':6s} {int(totals[0]):6d} {'':5s} {'':4s} {int(totals[1]):6d} {totals[2]:9.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
