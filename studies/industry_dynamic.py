"""The industry routes in dynamic mode: how steady the pulling force gets, and against steady mode.

For each route in ``scenarios/industry/`` named on the command line: the dynamic run with
``solver.end_time`` (default 3 s), ``solver.steady_stop`` and ``solver.start_from`` (default
``"steady"``; ``--start rope``: from the rope's state, as before the steady start), then steady mode laid out
as far as the dynamic run had pulled (``solver.steady_lead_out`` = its
``reference_pulled_out_m``), so both modes are compared in the same state. Prints one table row
per route: the dynamic status, when it became steady, the pulling force and its scatter
(standard deviation over the steady window, % of the mean), steady − dynamic (% of dynamic),
and the wall times (the dynamic one includes its steady start). Scatter and agreement target:
0.2 %. Read ``reference/README.md``, "Why the force wandered".

Run: ``nice .venv/bin/python studies/industry_dynamic.py [ROUTE ...] [--end-time 3] [--start steady|rope] [--window S]``
(default routes: commscope_conquest_500ft_bend90 commscope_conquest_run_a_h
gera_wire_pulling_example machinecalcs_two_bends); ``--quick``: the Gera example over 0.05 s on 210 elements (a smoke run).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from exucable.run import run_scenario
from exucable.scenario.specs import load_scenario

ROUTES = ["commscope_conquest_500ft_bend90", "commscope_conquest_run_a_h", "gera_wire_pulling_example",
          "machinecalcs_two_bends"]
HERE = Path(__file__).resolve().parent.parent / "scenarios" / "industry"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("routes", nargs="*", default=ROUTES)
    ap.add_argument("--end-time", type=float, default=3.0, help="solver.end_time [s]")
    ap.add_argument("--start", choices=("steady", "rope"), default="steady", help="solver.start_from")
    ap.add_argument("--window", type=float, default=None, help="solver.steady_window [s] (default: the scenario's)")
    ap.add_argument("--quick", action="store_true",
                    help="smoke run: the Gera worked example over 0.05 s on 210 elements (the coarsest the bend allows)")
    args = ap.parse_args(argv)
    coarse = {}
    if args.quick:
        args.routes, args.end_time = ["gera_wire_pulling_example"], 0.05
        coarse = {"cable.elements": 210}
    print("| route | dynamic | steady from [s] | pulling force [N] | scatter [%] | steady - dynamic [%] "
          "| wall dynamic / steady [s] |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.routes:
            sc = load_scenario(HERE / f"{name}.toml").replace(**{
                "solver.end_time": args.end_time, "solver.steady_stop": True, "solver.start_from": args.start, **coarse})
            if args.window is not None:
                sc = sc.replace(**{"solver.steady_window": args.window})
            t0 = time.perf_counter()
            dyn = run_scenario(sc, Path(tmp) / f"{name}_dyn", quiet=True, plots=False).summary
            wall_dyn = time.perf_counter() - t0
            force, sd = dyn["pull_force_N"], dyn["pull_force_std_N"]
            diff, wall_st = "-", float("nan")
            if dyn["reference_pulled_out_m"] is not None:
                t0 = time.perf_counter()
                st = run_scenario(sc.replace(**{"solver.mode": "steady",
                                                "solver.steady_lead_out": dyn["reference_pulled_out_m"]}),
                                  Path(tmp) / f"{name}_st", quiet=True, plots=False).summary
                wall_st = time.perf_counter() - t0
                diff = f"{100 * (st['pull_force_N'] / force - 1):+.3f} ({st['status']})"
            print(f"| {name} | {dyn['status']} | {dyn['steady_from_s']:.3f} | {force:.3f} | {100 * sd / force:.3f} "
                  f"| {diff} | {wall_dyn:.1f} / {wall_st:.1f} |", flush=True)


if __name__ == "__main__":
    main()
