"""Do neighbouring long routes take similar Newton counts? Families of steady runs, one parameter varied.

The routes are ``long_routes.py``'s (30 mm cable, 1.5 kg/m, EA 14 MN, 60 mm duct, gravity, μ 0.2,
500 N back tension, a 15° bend of radius 10 m every ~350 m turning left/up/right/down); each family
varies one thing in small steps about the 1 km route: its length (0.8-1.2 km in 50 m steps), with the
bends every 350 m, every 300 m, and turning in a seeded random order; the bend angle (10-20°); the
friction coefficient μ (0.15-0.25); the back tension (250-750 N); and, unless ``--no-10km``, the
length at 9.5 / 10 / 10.5 km. Each case is a whole steady run (``exucable.run.run_scenario``, no
files) in this process: the error bar's coarse solve (the rule's mesh, from the rope start) and the
solved mesh (twice finer, from the coarse state where the nested start applies, else from the rope
start and solved first).

Printed per case: Newton iterations of the solved mesh and of the error bar's coarse solve, their
pseudo-time steps tried and rejected (tried minus kept; a warm start given up counts its steps as
rejected), where the solved mesh started, each solve's CPU time and the pulling force; then per
family the largest ratio of Newton iterations between neighbours (solved mesh, coarse, both summed)
and, over every case, the largest neighbour ratio and the spread (largest / smallest count).

``--set NAME=VALUE`` overrides a field of :class:`exucable.solve.steady.SteadySettings` for every solve
(as in ``steady_iterations.py``); ``--only FAMILY,...`` runs some families.

    nice .venv/bin/python benchmarks/newton_spread.py [--no-10km] [--only length,angle] [--set reject_growth=4]
    nice .venv/bin/python benchmarks/newton_spread.py --quick     # smoke run: two 200 m routes
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
import long_routes  # noqa: E402  (the routes and the solve timer are long_routes.py's)

#: The turn order of the "seeded" family: a random draw, fixed by its seed.
TURN_SEED = 28


def seeded_turns(seed: int = TURN_SEED, count: int = 8) -> tuple:
    """``count`` turns drawn from left/right/up/down with numpy's generator seeded ``seed``."""
    return tuple(np.random.default_rng(seed).choice(["left", "right", "up", "down"], size=count))


def families(ten_km: bool = True, quick: bool = False) -> dict:
    """Family name -> list of (label, keyword arguments of :func:`long_routes.route_data`), neighbours adjacent."""
    lengths = [800.0 + 50.0 * i for i in range(9)]
    if quick:
        return {"length": [(f"{L:g} m", {"length_m": L}) for L in (200.0, 250.0)]}
    out = {
        "length": [(f"{L / 1000:g} km", {"length_m": L}) for L in lengths],
        "length, bends every 300 m": [(f"{L / 1000:g} km", {"length_m": L, "bend_spacing_m": 300.0}) for L in lengths],
        f"length, turns seeded {TURN_SEED}": [(f"{L / 1000:g} km", {"length_m": L, "turns": seeded_turns()})
                                              for L in lengths],
        "bend angle": [(f"{a:g}°", {"length_m": 1000.0, "bend_angle_deg": a}) for a in (10.0, 12.5, 15.0, 17.5, 20.0)],
        "friction": [(f"μ {mu:g}", {"length_m": 1000.0, "friction": mu}) for mu in (0.15, 0.175, 0.2, 0.225, 0.25)],
        "back tension": [(f"{T:g} N", {"length_m": 1000.0, "back_tension_N": T}) for T in (250.0, 375.0, 500.0, 625.0, 750.0)],
    }
    if ten_km:
        out["length at 10 km"] = [(f"{L / 1000:g} km", {"length_m": L}) for L in (9500.0, 10000.0, 10500.0)]
    return out


class Runner:
    """Whole steady runs in this process with their two solves timed (``long_routes._Timed``)."""

    def __init__(self, settings=None):
        import exucable.solve.steady as steady

        self.timed = long_routes._Timed()
        # run.py's solved mesh has a progress bar; the error bar's coarse solve has none
        self.timed.wrap(steady, "solve_steady", lambda i, kw: "solve" if "progress" in kw else "coarse")
        if settings is not None:
            # run.py and the error bar take their settings from the scenario: every solve gets these,
            # with the scenario's stop residual and time limit
            base = steady.SteadySettings.from_solver
            steady.SteadySettings.from_solver = classmethod(lambda cls, solver: dataclasses.replace(
                settings, **{k: getattr(base(solver), k) for k in ("steady_residual", "time_limit_s")}))

    def case(self, kwargs: dict) -> dict:
        """One run of ``long_routes.route_data(**kwargs)``: per solve its Newton iterations, steps tried and
        kept, CPU [s], and the pulling force [N]."""
        from exucable.run import run_scenario
        from exucable.scenario.specs import parse_scenario

        for d in (self.timed.wall, self.timed.cpu, self.timed.solves):
            d.clear()
        sc = parse_scenario(long_routes.route_data(**kwargs), ROOT, default_name="route")
        t0 = time.process_time()
        res = run_scenario(sc, None, plots=False)
        row = {"status": res.summary["status"], "F": res.summary["pull_force_N"], "cpu": time.process_time() - t0}
        for key in ("solve", "coarse"):
            out = self.timed.solves.get(key)
            row[key] = None if out is None else {
                "newton": out.newton_iterations, "steps": out.steps, "kept": len(out.history.pull_force_N),
                "cpu": self.timed.cpu[key], "from": out.started_from, "status": out.status}
        return row


def neighbour_ratio(counts) -> float:
    """The largest ratio max/min of two adjacent counts [-] (nan for fewer than two)."""
    c = np.asarray(counts, dtype=float)
    if c.size < 2:
        return float("nan")
    return float(np.max(np.maximum(c[1:], c[:-1]) / np.maximum(np.minimum(c[1:], c[:-1]), 1.0)))


def _solve_cells(s) -> str:
    if s is None:
        return "- | - | - |"
    return f"{s['newton']} | {s['steps']} / {s['steps'] - s['kept']} | {s['cpu']:.2f} |"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smoke run: a 200 m and a 250 m route")
    ap.add_argument("--no-10km", dest="ten_km", action="store_false", help="skip the 9.5 / 10 / 10.5 km family")
    ap.add_argument("--only", help="comma-separated family names (or their first word)")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="override a field of exucable.solve.steady.SteadySettings")
    args = ap.parse_args(argv)
    from exucable.solve.steady import SteadySettings

    kinds = {f.name: f.type for f in dataclasses.fields(SteadySettings)}
    overrides = {}
    for item in args.set:
        key, _, value = item.partition("=")
        key = key.strip().lower()
        if key not in kinds:
            ap.error(f"--set {item}: SteadySettings has no field {key!r}; fields: {', '.join(kinds)}")
        overrides[key] = int(float(value)) if kinds[key] == "int" else float(value)
    table = families(ten_km=args.ten_km, quick=args.quick)
    if args.only:
        wanted = [w.strip() for w in args.only.split(",")]
        table = {k: v for k, v in table.items() if k in wanted or k.split()[0].rstrip(",") in wanted}
        if not table:
            ap.error(f"--only {args.only}: no such family; families: {', '.join(families())}")
    runner = Runner(dataclasses.replace(SteadySettings(), **overrides) if overrides else None)
    runner.case({"length_m": 200.0})          # warm-up: numba's kernels loaded before the first timed run
    print(f"steady settings: {', '.join(f'{k} = {v:g}' for k, v in overrides.items()) or 'the defaults'}")
    print("| family | case | status | Newton, solved mesh | steps tried / rejected | solve CPU [s] | from "
          "| Newton, coarse | steps tried / rejected | coarse CPU [s] | run CPU [s] | pulling force [N] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    summary, all_counts = [], []
    for family, cases in table.items():
        counts = []
        for label, kwargs in cases:
            r = runner.case(kwargs)
            fine, coarse = r["solve"], r["coarse"]
            n = (fine["newton"] if fine else 0, coarse["newton"] if coarse else 0)
            counts.append(n)
            print(f"| {family} | {label} | {r['status']} | {_solve_cells(fine)} {fine['from'] if fine else '-'} | "
                  f"{_solve_cells(coarse)} {r['cpu']:.2f} | {r['F']:.6f} |", flush=True)
        c = np.array(counts)
        summary.append((family, neighbour_ratio(c[:, 0]), neighbour_ratio(c[:, 1]), neighbour_ratio(c.sum(axis=1)),
                        c.min(axis=0), c.max(axis=0)))
        if family != "length at 10 km":
            all_counts.extend(counts)
    print()
    print("| family | largest neighbour ratio: solved mesh | coarse | both | Newton range, solved mesh | coarse |")
    print("|---|---|---|---|---|---|")
    for family, rf, rc, rb, lo, hi in summary:
        print(f"| {family} | {rf:.2f} | {rc:.2f} | {rb:.2f} | {lo[0]}-{hi[0]} | {lo[1]}-{hi[1]} |")
    if all_counts:
        c = np.array(all_counts)
        worst = max(max(s[1], s[2], s[3]) for s in summary)
        print(f"over every family: largest neighbour ratio {worst:.2f}; spread (largest / smallest) of the "
              f"~1 km cases: solved mesh {c[:, 0].max()} / {c[:, 0].min()} = {c[:, 0].max() / max(c[:, 0].min(), 1):.2f}, "
              f"coarse {c[:, 1].max()} / {c[:, 1].min()} = {c[:, 1].max() / max(c[:, 1].min(), 1):.2f}, both "
              f"{c.sum(axis=1).max()} / {c.sum(axis=1).min()} = {c.sum(axis=1).max() / max(c.sum(axis=1).min(), 1):.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
