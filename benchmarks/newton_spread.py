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
rejected), the force evaluations of shortened steps (the line search of
:meth:`exucable.solve.steady.SteadySolver.shorten_step`, no Newton iteration), where the solved mesh
started, each solve's CPU time and the pulling force; then per
family the largest ratio of Newton iterations between neighbours (solved mesh, coarse, both summed)
and, over every case, the largest neighbour ratio and the spread (largest / smallest count).

``--set NAME=VALUE`` overrides a field of :class:`exucable.solve.steady.SteadySettings` for every solve
(as in ``steady_iterations.py``); ``--against NAME=VALUE`` runs each case a second time right after
with that field changed too (B against A: the two solves' CPU ratio, interleaved in one run, and the
pulling force's change); ``--only FAMILY,...`` runs some families.

    nice .venv/bin/python benchmarks/newton_spread.py [--no-10km] [--only length,angle] [--set reject_growth=4]
    nice .venv/bin/python benchmarks/newton_spread.py --against max_backtracks=0   # the line search's effect
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
    """Whole steady runs in this process with their two solves timed (``long_routes._Timed``);
    :attr:`settings` (None: the defaults) are every solve's steady settings, with the scenario's stop
    residual and time limit."""

    def __init__(self):
        import exucable.solve.steady as steady

        self.settings = None
        self.timed = long_routes._Timed()
        # run.py's solved mesh has a progress bar; the error bar's coarse solve has none
        self.timed.wrap(steady, "solve_steady", lambda i, kw: "solve" if "progress" in kw else "coarse")
        # run.py and the error bar take their settings from the scenario
        base = steady.SteadySettings.from_solver
        steady.SteadySettings.from_solver = classmethod(lambda cls, solver: base(solver) if self.settings is None else
                                                        dataclasses.replace(self.settings, **{
                                                            k: getattr(base(solver), k)
                                                            for k in ("steady_residual", "time_limit_s")}))

    def case(self, kwargs: dict, settings=None) -> dict:
        """One run of ``long_routes.route_data(**kwargs)`` with ``settings``: per solve its Newton
        iterations, steps tried and kept, shortened steps' force evaluations, CPU [s], where it started;
        the whole run's CPU [s] and the pulling force [N]."""
        from exucable.run import run_scenario
        from exucable.scenario.specs import parse_scenario

        self.settings = settings
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
                "backtracks": out.backtracks, "cpu": self.timed.cpu[key], "from": out.started_from}
        return row


def neighbour_ratio(counts) -> float:
    """The largest ratio max/min of two adjacent counts [-] (nan for fewer than two)."""
    c = np.asarray(counts, dtype=float)
    if c.size < 2:
        return float("nan")
    return float(np.max(np.maximum(c[1:], c[:-1]) / np.maximum(np.minimum(c[1:], c[:-1]), 1.0)))


def _settings(ap, items) -> tuple:
    """``NAME=VALUE`` items -> (SteadySettings with them, their text)."""
    from exucable.solve.steady import SteadySettings

    kinds = {f.name: f.type for f in dataclasses.fields(SteadySettings)}
    overrides = {}
    for item in items:
        key, _, value = item.partition("=")
        key = key.strip().lower()
        if key not in kinds:
            ap.error(f"{item}: SteadySettings has no field {key!r}; fields: {', '.join(kinds)}")
        overrides[key] = int(float(value)) if kinds[key] == "int" else float(value)
    text = ", ".join(f"{k} = {v:g}" for k, v in overrides.items()) or "the defaults"
    return dataclasses.replace(SteadySettings(), **overrides), text


def _cells(s) -> str:
    if s is None:
        return "- | - | - | - |"
    return f"{s['newton']} | {s['steps']} / {s['steps'] - s['kept']} | {s['backtracks']} | {s['cpu']:.2f} |"


def _row(family, label, tag, r) -> str:
    fine = r["solve"]
    return (f"| {family} | {label} | {tag} | {r['status']} | {_cells(fine)} {fine['from'] if fine else '-'} | "
            f"{_cells(r['coarse'])} {r['cpu']:.2f} | {r['F']:.6f} |")


def _summary(tag: str, rows: dict) -> None:
    """The largest neighbour ratios per family and over all, of the runs ``rows[family]``."""
    print(f"\n{tag}:")
    print("| family | largest neighbour ratio: solved mesh | coarse | both | Newton range, solved mesh | coarse |")
    print("|---|---|---|---|---|---|")
    worst, every = 0.0, []
    for family, runs in rows.items():
        c = np.array([[r["solve"]["newton"] if r["solve"] else 0, r["coarse"]["newton"] if r["coarse"] else 0]
                      for r in runs])
        ratios = (neighbour_ratio(c[:, 0]), neighbour_ratio(c[:, 1]), neighbour_ratio(c.sum(axis=1)))
        worst = max(worst, *ratios)
        print(f"| {family} | {ratios[0]:.2f} | {ratios[1]:.2f} | {ratios[2]:.2f} | {c[:, 0].min()}-{c[:, 0].max()} "
              f"| {c[:, 1].min()}-{c[:, 1].max()} |")
        if family != "length at 10 km":
            every.extend(c.tolist())
    if every:
        c = np.array(every)
        spread = lambda x: f"{x.max()} / {x.min()} = {x.max() / max(x.min(), 1):.2f}"
        print(f"largest neighbour ratio over every family {worst:.2f}; spread (largest / smallest) of the cases "
              f"about 1 km: solved mesh {spread(c[:, 0])}, coarse {spread(c[:, 1])}, both {spread(c.sum(axis=1))}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smoke run: a 200 m and a 250 m route")
    ap.add_argument("--no-10km", dest="ten_km", action="store_false", help="skip the 9.5 / 10 / 10.5 km family")
    ap.add_argument("--only", help="comma-separated family names (or their first word)")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="override a field of exucable.solve.steady.SteadySettings")
    ap.add_argument("--against", action="append", default=[], metavar="NAME=VALUE",
                    help="also run each case with these SteadySettings fields (the --set ones too), right after")
    args = ap.parse_args(argv)
    settings, text = _settings(ap, args.set)
    against, against_text = _settings(ap, args.set + args.against) if args.against else (None, "")
    table = families(ten_km=args.ten_km, quick=args.quick)
    if args.only:
        wanted = [w.strip() for w in args.only.split(",")]
        table = {k: v for k, v in table.items() if k in wanted or k.split()[0].rstrip(",") in wanted}
        if not table:
            ap.error(f"--only {args.only}: no such family; families: {', '.join(families())}")
    runner = Runner()
    runner.case({"length_m": 200.0}, settings)     # warm-up: numba's kernels loaded before the first timed run
    print(f"A: steady settings {text}" + (f"; B: {against_text}" if against else ""))
    print("| family | case | run | status | Newton, solved mesh | steps tried / rejected | shortened-step force "
          "evaluations | solve CPU [s] | from | Newton, coarse | steps tried / rejected | shortened-step force "
          "evaluations | coarse CPU [s] | run CPU [s] | pulling force [N] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    rows = {"A": {}, "B": {}}
    for family, cases in table.items():
        for label, kwargs in cases:
            for tag, chosen in (("A", settings), ("B", against)):
                if chosen is None:
                    continue
                r = runner.case(kwargs, chosen)
                rows[tag].setdefault(family, []).append(r)
                print(_row(family, label, tag, r), flush=True)
                if tag == "B":
                    a = rows["A"][family][-1]
                    print(f"|   | B against A | | | CPU of the two solves B / A "
                          f"{sum(r[k]['cpu'] for k in ('solve', 'coarse') if r[k]) / max(sum(a[k]['cpu'] for k in ('solve', 'coarse') if a[k]), 1e-9):.2f}"
                          f", pulling force B / A - 1 {r['F'] / a['F'] - 1:+.1e} |", flush=True)
    _summary(f"A ({text})", rows["A"])
    if against:
        _summary(f"B ({against_text})", rows["B"])
        cpu = {t: sum(r[k]["cpu"] for runs in rows[t].values() for r in runs for k in ("solve", "coarse") if r[k])
               for t in rows}
        moved = max(abs(b["F"] / a["F"] - 1) for f in rows["A"] for a, b in zip(rows["A"][f], rows["B"][f]))
        print(f"\nCPU of the two solves over every case: B / A = {cpu['B']:.2f} / {cpu['A']:.2f} s = "
              f"{cpu['B'] / max(cpu['A'], 1e-9):.2f} (interleaved in this run); the largest relative change of a "
              f"pulling force {moved:.1e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
