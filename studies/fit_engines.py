"""How far a rope fit's friction is from the multibody model's, on the industry routes.

The multibody steady engine has no pull-in history yet (head tension against pulled length). Its nearest
stand-in: the tension along the cable in the full pull's steady state, T_mb(s), read as the history
(for the rope the two are the same thing: with the head at x the cable fills [0, x] and its head tension
is the full pull's T(x); for a stiff cable in a clearance the head's own boundary layer makes them differ
near the head, so this is an estimate). T_mb at the scenario's μ is fitted by the rope engine
(``exucable.fit``: the same grid, spline and least squares as ``exucable fit``), noise-free; the printed
μ_rope − μ says how far a rope fit of a log that followed the multibody model would be off.

Run: ``nice .venv/bin/python studies/fit_engines.py [ROUTE ...]`` (default: the four one-cable routes).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from exucable.fit.friction import RopeFamily, fit_friction
from exucable.fit.log import parse_pull_log
from exucable.io import csv_text
from exucable.plan.pull import plan_pull, plan_spec
from exucable.scenario.specs import load_scenario

ROUTES = ["commscope_conquest_500ft_bend90", "commscope_conquest_run_a_h", "gera_wire_pulling_example",
          "machinecalcs_two_bends"]
HERE = Path(__file__).resolve().parent.parent / "scenarios" / "industry"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("routes", nargs="*", default=ROUTES)
    ap.add_argument("--quick", action="store_true", help="the first route only (a smoke run)")
    args = ap.parse_args()
    if args.quick:      # the smoke run: the first route only
        args.routes = args.routes[:1]
    print(f"{'route':34s} {'dir':8s} {'mu':>6s} {'mu_rope':>8s} {'diff %':>7s} {'pull mb/rope-1 %':>17s} {'rows':>5s} "
          f"{'wall s':>7s}")
    for name in args.routes:
        scenario = load_scenario(HERE / f"{name}.toml")
        spec = plan_spec(scenario)
        t0 = time.perf_counter()
        plan = plan_pull(scenario, spec, engine="steady")
        wall = time.perf_counter() - t0
        mu = scenario.contact.friction
        for direction in ("forward", "reverse"):
            d = plan["directions"][direction]
            s = np.asarray(d["profile"]["s_m"], dtype=float)
            T = np.asarray(d["profile"]["tension_N"], dtype=float)
            keep = np.concatenate([[True], np.diff(s) > 0])        # one reading per place
            text = csv_text(("pulled_length_m", "tension_N"), {"pulled_length_m": s[keep], "tension_N": T[keep]})
            log = parse_pull_log(text + "# end\n")
            family = RopeFamily(scenario, spec, direction)
            fit = fit_friction(scenario, log, family=family, bootstrap=99)
            print(f"{name:34s} {direction:8s} {mu:6.3f} {fit.friction:8.4f} {100 * (fit.friction / mu - 1):+7.2f} "
                  f"{100 * (d['pull_force_N'] / d['rope_pull_force_N'] - 1):+17.2f} {fit.pulled_length_m.size:5d} "
                  f"{wall:7.1f}  status {d['status']}", flush=True)


if __name__ == "__main__":
    main()
