"""The steady bundle solve from its starts: the centroid on the rope-with-clearance path, the
arrangement about the duct's axis and the cross-section's statics (``build_bundle_model(...,
start_path=...)``), CPU time and Newton iterations of each solve measured in one run.

    nice .venv/bin/python benchmarks/bundle_start.py [--quick]
        [--route [--limit 55] [--arrangements triangular,cradled] [--starts clearance,statics,statics_own]]

``--route``: ``benchmarks/bundle_route.py``'s 100 m route (triangular and cradled) from the clearance
path and from the statics (``"statics"`` and ``"statics_own"``), each solve under a CPU limit (``--limit``, default 55 s, the route's
budget inside the 60 s whole-process target): status, build and solve CPU, the start's residual
in the first onset layer (0.5 mm) and the residual left, per cable and per 10 m of the route where
the largest remains.

Cases (three 30 mm cables in a 100 mm duct, D/d 3.33, μ 0.3, gravity; the coarse mesh of
``tests/test_bundle_gravity_bend.py``): a 90° left bend of 5 m radius between 3 m straights, triangular,
at back tensions of 300, 1000, 2000, 3000 and 4000 N (the bundle's); a 60° up-bend of 5 m radius
(3 m before, 2 m after), cradled, 200 N per cable (the tension lifts the bundle onto the upper wall).
Each solve has a CPU limit (``solver.steady_time_limit``) of 25 s (20 s up-bend): a failed case says
so at that cost. The machine is shared: compare the columns of one row.
"""

from __future__ import annotations

import argparse
import importlib.util
import time
from pathlib import Path

import numpy as np

import exucable as xc
from exucable.model.bundle import build_bundle_model
from exucable.solve.onset_continuation import OnsetSettings
from exucable.solve.steady import SteadySettings, solve_steady

ROOT = Path(__file__).resolve().parents[1]
STARTS = ("axis", "clearance", "statics")


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


def route(arrangement: str, limit_s: float):
    """``benchmarks/bundle_route.py``'s scenario with ``arrangement``, the solve's CPU limit ``limit_s``."""
    spec = importlib.util.spec_from_file_location("bundle_route_onset", ROOT / "studies" / "bundle_route_onset.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    sc = mod.route_scenario()
    return sc.replace(**{"cable.arrangement": arrangement, "solver.steady_time_limit": limit_s})


def residual_by_cable(model) -> np.ndarray:
    """The steady residual at the model's state [N] (the eye's held rows left out), per cable and node (n, nodes)."""
    q = np.concatenate([c.reshape(-1) for c in model.cable_coordinates()]) - model.layout.coordinates.reshape(-1)
    r = model.steady_force(q)
    r[model.held_coordinates()] = 0.0
    return np.linalg.norm(r.reshape(model.n_cables, -1, 6), axis=2)


def where(model, nodes_residual: np.ndarray, band_m: float = 10.0) -> str:
    """Per cable: its residual [N] and the band of ``band_m`` along the route holding most of it."""
    out = []
    for i, (lay, r) in enumerate(zip(model.layout.cables, nodes_residual)):
        band = np.floor(np.asarray(lay.node_s_m) / band_m)
        bands = np.unique(band)
        size = np.array([np.sqrt(np.sum(r[band == b] ** 2)) for b in bands])
        k = int(np.argmax(size))
        out.append(f"cable {i + 1}: {np.sqrt(np.sum(r ** 2)):.3g} N, most at {bands[k] * band_m:.0f}-"
                   f"{(bands[k] + 1) * band_m:.0f} m ({size[k]:.3g} N)")
    return "; ".join(out)


def route_row(arrangement: str, start: str, limit_s: float) -> None:
    sc = route(arrangement, limit_s)
    c0 = time.process_time()
    model = build_bundle_model(sc, start_path=start)
    c1 = time.process_time()
    model.kernel.set_onset_layer(OnsetSettings().first_m)
    r0 = float(np.sqrt(np.sum(residual_by_cable(model) ** 2)))
    model.kernel.set_onset_layer(0.0)
    out = solve_steady(model, settings=SteadySettings.from_solver(sc.solver))
    c2 = time.process_time()
    pull = f"{float(model.pull_shares_N().sum()):.3f}" if out.status == "ok" else "n/a"
    left = where(model, residual_by_cable(model)) if out.status != "ok" else "-"
    print(f"| {arrangement} | {start} | {out.status} | {c1 - c0:.2f} | {c2 - c1:.2f} | {r0:.4g} | {pull} | {left} |", flush=True)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="the bend at 300 N only (a smoke run)")
    p.add_argument("--route", action="store_true", help="the 100 m route from the clearance path and the statics (equal and own loads)")
    p.add_argument("--limit", type=float, default=55.0, help="the route's solve CPU limit [s]")
    p.add_argument("--arrangements", default="triangular,cradled", help="the route's arrangements, comma-separated")
    p.add_argument("--starts", default="clearance,statics,statics_own", help="the route's starts, comma-separated")
    args = p.parse_args(argv)
    if args.route:
        build_bundle_model(bend(300.0))      # the kernels' first call (numba's cache) outside the timings
        print("| arrangement | start | status | build CPU [s] | solve CPU [s] | start residual, 0.5 mm layer [N] "
              "| pull [N] | residual left: per cable, and the 10 m holding most |")
        print("| --- | --- | --- | --- | --- | --- | --- | --- |")
        for arrangement in args.arrangements.split(","):
            for start in args.starts.split(","):
                route_row(arrangement, start, args.limit)
        return 0
    cases = [(f"90° bend, triangular, T_b {b:g} N", bend(b)) for b in ((300.0,) if args.quick else
                                                                        (300.0, 1000.0, 2000.0, 3000.0, 4000.0))]
    if not args.quick:
        cases.append(("60° up-bend, cradled, 200 N per cable", up_bend(200.0)))
    build_bundle_model(cases[0][1])      # the kernels' first call (numba's cache) outside the timings
    print("| case | " + " | ".join(f"{start}: status, F [N], Newton its, CPU [s]" for start in STARTS)
          + " | CPU clearance / axis | CPU statics / clearance |")
    print("| --- " * (len(STARTS) + 3) + "|")
    for name, sc in cases:
        row = [one(sc, start) for start in STARTS]
        cells = [f"{r['status']}, {'n/a' if r['pull'] is None else format(r['pull'], '.2f')}, {r['its']}, {r['cpu']:.2f}"
                 for r in row]
        print(f"| {name} | {' | '.join(cells)} | {row[1]['cpu'] / row[0]['cpu']:.2f} | {row[2]['cpu'] / row[1]['cpu']:.2f} |",
              flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
