"""The steady bundle solve from its two starts: the centroid on the rope-with-clearance path against the
arrangement about the duct's axis (``build_bundle_model(..., start_path=...)``), CPU time and Newton
iterations of each solve measured in one run.

    nice .venv/bin/python benchmarks/bundle_start.py [--quick]

Cases (three 30 mm cables in a 100 mm duct, D/d 3.33, μ 0.3, gravity; the coarse mesh of
``tests/test_bundle_gravity_bend.py``): a 90° left bend of 5 m radius between 3 m straights, triangular,
at back tensions of 300, 1000, 2000, 3000 and 4000 N (the bundle's); a 60° up-bend of 5 m radius
(3 m before, 2 m after), cradled, 200 N per cable (the tension lifts the bundle onto the upper wall).
Each solve has a CPU limit (``solver.steady_time_limit``) of 25 s (20 s up-bend): a failed case says
so at that cost. The machine is shared: compare the two columns of one row.
"""

from __future__ import annotations

import argparse
import time

import exucable as xc
from exucable.model.bundle import build_bundle_model
from exucable.solve.steady import SteadySettings, solve_steady


def bend(back_tension_N: float):
    route = xc.Route(inner_radius=0.05).straight(3.0).bend(90, radius=5.0, turn="left").straight(3.0)
    return xc.Scenario(route=route,
                       cable=xc.Cable(radius=0.015, density=2000.0, youngs_modulus=2e8, count=3, arrangement="triangular"),
                       contact=xc.Contact(friction=0.3, check_points_per_element=8),
                       pull=xc.Pull(speed=0.1, back_tension=back_tension_N), gravity=xc.Gravity(g=9.81),
                       solver=xc.Solver(mode="steady", steady_lead_out=0.0, steady_time_limit=25.0))


def up_bend(per_cable_N: float):
    route = xc.Route(inner_radius=3.3 * 0.015).straight(3.0).bend(60, radius=5.0, turn="up").straight(2.0)
    return xc.Scenario(route=route,
                       cable=xc.Cable(radius=0.015, density=2000.0, youngs_modulus=2e8, bending_stiffness=1.0,
                                      count=3, arrangement="cradled", elements=21),
                       contact=xc.Contact(friction=0.3, check_points_per_element=8),
                       pull=xc.Pull(speed=0.1, back_tension=3 * per_cable_N), gravity=xc.Gravity(g=9.81),
                       solver=xc.Solver(mode="steady", steady_lead_out=0.0, steady_time_limit=20.0))


def one(sc, start_path: str) -> dict:
    """Build (not timed) and solve from ``start_path``: status, pull [N], Newton iterations, solve CPU [s]."""
    model = build_bundle_model(sc, start_path=start_path)
    c0 = time.process_time()
    out = solve_steady(model, settings=SteadySettings.from_solver(sc.solver))
    cpu = time.process_time() - c0
    pull = float(model.pull_shares_N().sum()) if out.status != "failed" else None
    return {"status": out.status, "pull": pull, "its": out.newton_iterations, "cpu": cpu}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="the bend at 300 N only (a smoke run)")
    args = p.parse_args(argv)
    cases = [(f"90° bend, triangular, T_b {b:g} N", bend(b)) for b in ((300.0,) if args.quick else
                                                                        (300.0, 1000.0, 2000.0, 3000.0, 4000.0))]
    if not args.quick:
        cases.append(("60° up-bend, cradled, 200 N per cable", up_bend(200.0)))
    build_bundle_model(cases[0][1])      # the kernels' first call (numba's cache) outside the timings
    print("| case | axis: status, F [N], Newton its, CPU [s] | clearance path: status, F [N], Newton its, CPU [s] "
          "| CPU clearance / axis |")
    print("| --- | --- | --- | --- |")
    for name, sc in cases:
        row = [one(sc, start) for start in ("axis", "clearance")]
        cells = [f"{r['status']}, {'n/a' if r['pull'] is None else format(r['pull'], '.2f')}, {r['its']}, {r['cpu']:.2f}"
                 for r in row]
        print(f"| {name} | {cells[0]} | {cells[1]} | {row[1]['cpu'] / row[0]['cpu']:.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
