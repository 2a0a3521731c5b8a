"""Cost of the steady (static) and dynamic solves against route length: 10 m, 100 m, 1 km.

Routes of a real cable (18 mm, 0.21 kg/m, E = 5e8 Pa, μ = 0.5, 8 mm radial clearance, gravity)
through straights of ~75 m with a bend every ~80 m, alternating horizontal and vertical (10-20°,
radius 3 m), built by :func:`route_scenario`; the default mesh is one element per metre (each
element turns ≤ 0.33 rad in a bend) with the default 20 check points per element.

For each length and mode (the dynamic mode only up to ``--dynamic-max`` metres: it integrates
until steady, hundreds of steps) it prints wall time (build + solve), Newton iterations, peak
memory of the process (the increase of ru_maxrss over the run, so measure the lengths in
increasing order) and the pulling force against the rope solution; then the exponent p of a
least-squares fit wall ∝ L^p over the lengths solved in steady mode, measured in this one run.

Then, if ``--example4`` is given, steady Example 4 against dynamic Example 4, whole process
(scenario → build → solve → result files), and their ratio, in this one run.

Run: ``nice .venv/bin/python benchmarks/steady_scale.py [--lengths 10 100 1000] [--example4]``.
"""

from __future__ import annotations

import argparse
import resource
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from exucable.run import run_scenario
from exucable.scenario import load_scenario, parse_scenario

ROOT = Path(__file__).resolve().parents[1]

CABLE = {"radius": 0.009, "mass_per_length": 0.21, "youngs_modulus": 5.0e8}
CLEARANCE_M = 0.008
BEND_RADIUS_M = 3.0
BEND_SPACING_M = 80.0


def route_path(length_m: float) -> list[dict]:
    """Straights and bends adding up to ``length_m``: a bend every ~80 m (one in the middle of a
    route shorter than that), alternating left/up/right/down, 10°-20° (a route's total turning
    stays that of real duct runs: 1 km has 12 bends, 165°; the capstan factor e^(μθ) is 4.2)."""
    turns = ["left", "up", "right", "down"]
    angles = [20.0, 10.0, 15.0, 10.0]
    n_bends = max(1, int(round(length_m / BEND_SPACING_M)))
    arcs = [np.radians(angles[i % 4]) * BEND_RADIUS_M for i in range(n_bends)]
    straight = (length_m - sum(arcs)) / (n_bends + 1)
    if straight <= 0:
        raise ValueError(f"route of {length_m} m too short for {n_bends} bends")
    path = [{"straight": straight}]
    for i in range(n_bends):
        path.append({"bend": angles[i % 4], "radius": BEND_RADIUS_M, "turn": turns[i % 4]})
        path.append({"straight": straight})
    return path


def route_scenario(length_m: float, mode: str = "steady", elements_per_m: float = 1.0, **solver):
    """The benchmark scenario of a route of ``length_m`` [m] in ``mode``."""
    data = {
        "name": f"route-{length_m:g}m-{mode}",
        "cable": dict(CABLE, elements=max(4, int(round(length_m * elements_per_m)))),
        "conduit": {"inner_radius": CABLE["radius"] + CLEARANCE_M, "path": route_path(length_m)},
        "contact": {"friction": 0.5},
        "pull": {"speed": 0.1, "back_tension": 100.0},
        "gravity": {"g": 9.81},
        "solver": dict({"end_time": 20.0, "step": 0.01, "steady_stop": True, "mode": mode}, **solver),
    }
    return parse_scenario(data, ROOT, default_name="route")


def timed(scenario) -> dict:
    """Whole process (build, solve, result files) of one scenario, with its peak memory."""
    out = Path(tempfile.mkdtemp(prefix="exucable-steady-scale-"))
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    try:
        t0 = time.perf_counter()
        s = run_scenario(scenario, out, plots=False).summary
        wall = time.perf_counter() - t0
    finally:
        shutil.rmtree(out, ignore_errors=True)
    rss1 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return {"wall_s": wall, "summary": s, "peak_rss_MB": rss1 / 1024.0, "rss_increase_MB": (rss1 - rss0) / 1024.0}


def report(length, mode, r) -> str:
    s = r["summary"]
    F, rope = s["pull_force_N"], s["rope_pull_force_N"]
    dev = f"{100 * (F / rope - 1):+.2f} %" if F is not None and rope else "-"
    return (f"{length:8.0f} m  {mode:8s} {s['status']:7s} wall {r['wall_s']:8.2f} s  "
            f"(solve {s['wall_time_s']:7.2f} s)  Newton {s['newton_iterations']:6d}  "
            f"elements {s['scenario']['cable']['elements']:5d}  peak RSS {r['peak_rss_MB']:7.0f} MB "
            f"(+{r['rss_increase_MB']:.0f})  F {F if F is None else round(F, 2)} N  rope {rope:.2f} N ({dev})")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lengths", type=float, nargs="+", default=[10.0, 100.0, 1000.0])
    ap.add_argument("--dynamic-max", type=float, default=10.0,
                    help="largest route [m] also run in dynamic mode (default 10)")
    ap.add_argument("--example4", action="store_true", help="also steady vs dynamic Example 4")
    args = ap.parse_args()
    # warm-up: compile/load the kernels outside the timings
    run_scenario(route_scenario(10.0), None, plots=False)
    walls = []
    for L in sorted(args.lengths):
        for mode in ("steady", "dynamic"):
            if mode == "dynamic" and L > args.dynamic_max:
                continue
            r = timed(route_scenario(L, mode))
            print(report(L, mode, r), flush=True)
            if mode == "steady" and r["summary"]["status"] != "failed":
                walls.append((L, r["wall_s"]))
    if len(walls) >= 2:
        L, w = np.array(walls).T
        p = np.polyfit(np.log(L), np.log(w), 1)[0]
        print(f"steady: wall ∝ L^{p:.2f} over {', '.join(f'{x:g}' for x in L)} m (least squares on log-log)")
        if len(walls) >= 3:
            p_hi = np.log(w[-1] / w[-2]) / np.log(L[-1] / L[-2])
            print(f"        between the two longest routes: exponent {p_hi:.2f}")
    if args.example4:
        sc = load_scenario(ROOT / "scenarios" / "paper_ex4_spatial.toml")
        rd = timed(sc)
        rs = timed(parse_scenario({**sc.to_dict(), "solver": {**sc.solver.to_dict(), "mode": "steady"}},
                                  ROOT, default_name="ex4"))
        print(report(0, "dynamic", rd).replace("       0 m", "Example 4"))
        print(report(0, "steady", rs).replace("       0 m", "Example 4"))
        print(f"Example 4, whole process: dynamic {rd['wall_s']:.2f} s / steady {rs['wall_s']:.2f} s = "
              f"{rd['wall_s'] / rs['wall_s']:.1f}x; pulling force steady - dynamic "
              f"{100 * (rs['summary']['pull_force_N'] / rd['summary']['pull_force_N'] - 1):+.3f} %")


if __name__ == "__main__":
    main()
