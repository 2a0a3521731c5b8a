"""Cost of the steady (static) and dynamic solves against route length: 10 m, 100 m, 1 km.

Routes of a real cable (18 mm, 0.21 kg/m, E = 5e8 Pa, μ = 0.5, 8 mm radial clearance, gravity)
through straights of ~75 m with a bend every ~80 m, alternating horizontal and vertical (10-20°,
radius 3 m), built by :func:`route_scenario`; the default mesh is one element per metre (each
element turns ≤ 0.33 rad in a bend) with the default 20 check points per element.

Each length and mode (the dynamic mode only up to ``--dynamic-max`` metres: it integrates until
steady, hundreds of steps) runs in its own process, which first runs a 10 m route of the same
mode (loading the compiled kernels) and then the measured one, whole process (scenario → build
→ solve → result files). It prints wall time (and the build's and the solve's share), Newton
iterations, the process's peak memory (ru_maxrss) and its increase over the measured run, the
time and memory per element, the solve's and the contact kernel's time per Newton iteration and
element (flat if nothing is quadratic in the elements), the check points per element (the mesh
rule gives a tenser cable more) and the memory per check point, and the pulling force against the centreline rope and the rope
with clearance; then the exponent p of a least-squares fit wall ∝ L^p over the lengths solved
in steady mode, measured in this one run.

``--tolerance-check`` solves the longest route again in steady mode with the stop tolerance
divided by 100 and prints how far the pulling force moves (how converged it is); ``--mesh-check``
solves it with twice the elements.
Then, if ``--example4`` is given, steady Example 4 against dynamic Example 4 (``--repeat`` interleaved runs each, medians), whole process
(scenario → build → solve → result files), and their ratio, in this one run.

Run: ``nice .venv/bin/python benchmarks/steady_scale.py [--lengths 10 100 1000] [--dynamic-max 100]
[--tolerance-check] [--mesh-check] [--example4]``; ``--quick``: the 10 m route in both modes only (a smoke
run: no fit).
"""

from __future__ import annotations

import argparse
import json
import statistics
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from exucable.run import run_scenario
from exucable.scenario.specs import load_scenario, parse_scenario

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


def one_case(length_m: float, mode: str, elements_per_m: float = 1.0) -> dict:
    """One route in this process, after a 10 m warm-up of the same mode (the JSON a child prints)."""
    run_scenario(route_scenario(10.0, mode), None, plots=False)
    r = timed(route_scenario(length_m, mode, elements_per_m))
    s = r.pop("summary")
    keep = ("status", "message", "pull_force_N", "rope_pull_force_N", "rope_clearance_pull_force_N",
            "newton_iterations", "steps", "wall_time_s", "build_time_s", "kernel_time_s")
    return dict(r, length_m=length_m, mode=mode, elements=s["scenario"]["cable"]["elements"],
                check_points_per_element=s["mesh"]["check_points_per_element"], **{k: s[k] for k in keep})


def in_child(length_m: float, mode: str, elements_per_m: float = 1.0) -> dict:
    """:func:`one_case` in a fresh process, so that its peak memory is its own."""
    cmd = [sys.executable, __file__, "--case", f"{length_m:g}", mode, f"{elements_per_m:g}"]
    done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def _percent(value, ref) -> str:
    return f"{100 * (value / ref - 1):+.2f} %" if value is not None and ref else "-"


def report(r) -> str:
    F, n = r["pull_force_N"], r["elements"]
    per = max(r["newton_iterations"], 1) * n
    cp = r["check_points_per_element"]
    return (f"{r['length_m']:6.0f} m  {r['mode']:7s} {r['status']:6s} wall {r['wall_s']:7.2f} s "
            f"(build {r['build_time_s']:6.2f}, solve {r['wall_time_s']:6.2f})  Newton {r['newton_iterations']:5d}  "
            f"elements {n:5d}  {1e3 * r['wall_s'] / n:6.2f} ms/element  peak RSS {r['peak_rss_MB']:5.0f} MB "
            f"(+{r['rss_increase_MB']:4.0f} MB, {1024 * r['rss_increase_MB'] / n:5.1f} kB/element)  "
            f"F {'-' if F is None else f'{F:.2f}'} N  vs rope {_percent(F, r['rope_pull_force_N'])}, "
            f"vs rope with clearance {_percent(F, r['rope_clearance_pull_force_N'])}\n"
            f"{'':17s}per Newton iteration and element: solve {1e6 * r['wall_time_s'] / per:6.1f} µs, "
            f"of which contact kernel {1e6 * r['kernel_time_s'] / per:6.1f} µs; {cp} check points per element "
            f"(the mesh rule's, grows with the tension), {1024 * r['rss_increase_MB'] / (n * cp):5.2f} kB per check point")


def mesh_check(length_m: float, base: dict) -> str:
    """Pulling force of the steady solve on the route with twice the elements, against ``base``'s."""
    r = in_child(length_m, "steady", elements_per_m=2.0)
    F0, F1 = base["pull_force_N"], r["pull_force_N"]
    return (f"mesh check, {length_m:g} m steady: F = {F0:.4f} N with {base['elements']} elements, "
            f"{F1:.4f} N with {r['elements']} ({r['status']}, wall {r['wall_s']:.1f} s): change "
            f"{100 * (F1 / F0 - 1):+.4f} %")


def tolerance_check(length_m: float) -> str:
    """Pulling force of the steady solve at the default stop tolerance and at 1/100 of it."""
    from exucable.model.build import build_model
    from exucable.solve.steady import SteadySettings, solve_steady, steady_forces

    forces = []
    default = SteadySettings().steady_residual
    for tol in (default, default / 100.0):
        model = build_model(route_scenario(length_m))
        out = solve_steady(model, tolerance=tol)
        if out.status != "ok":
            return f"tolerance check at {length_m:g} m: {tol:g} failed ({out.message})"
        forces.append((tol, steady_forces(model)[0], out.steps, out.newton_iterations))
    (t0, f0, s0, n0), (t1, f1, s1, n1) = forces
    return (f"tolerance check, {length_m:g} m steady: F = {f0:.6f} N at {t0:g} ({s0} pseudo-time steps, {n0} Newton), "
            f"{f1:.6f} N at {t1:g} ({s1} steps, {n1} Newton): change {100 * (f1 / f0 - 1):+.2e} %")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lengths", type=float, nargs="+", default=[10.0, 100.0, 1000.0])
    ap.add_argument("--dynamic-max", type=float, default=100.0,
                    help="largest route [m] also run in dynamic mode (default 100)")
    ap.add_argument("--tolerance-check", action="store_true",
                    help="solve the longest route again at 1/100 of the stop tolerance")
    ap.add_argument("--example4", action="store_true", help="also steady vs dynamic Example 4")
    ap.add_argument("--repeat", type=int, default=5,
                    help="interleaved runs of each mode for --example4 (medians; default 5)")
    ap.add_argument("--mesh-check", action="store_true",
                    help="solve the longest route again in steady mode with twice the elements")
    ap.add_argument("--case", nargs=3, metavar=("LENGTH_M", "MODE", "ELEMENTS_PER_M"), help=argparse.SUPPRESS)
    ap.add_argument("--quick", action="store_true", help="smoke run: the 10 m route in both modes only")
    args = ap.parse_args(argv)
    if args.quick:
        args.lengths, args.dynamic_max = [10.0], 10.0
    if args.case:
        print(json.dumps(one_case(float(args.case[0]), args.case[1], float(args.case[2]))))
        return
    walls, steady_runs = [], {}
    for L in sorted(args.lengths):
        for mode in ("steady", "dynamic"):
            if mode == "dynamic" and L > args.dynamic_max:
                continue
            r = in_child(L, mode)
            print(report(r), flush=True)
            if mode == "steady" and r["status"] != "failed":
                walls.append((L, r["wall_s"]))
                steady_runs[L] = r
    if len(walls) >= 2:
        L, w = np.array(walls).T
        p = np.polyfit(np.log(L), np.log(w), 1)[0]
        print(f"steady: wall ∝ L^{p:.2f} over {', '.join(f'{x:g}' for x in L)} m (least squares on log-log)")
        if len(walls) >= 3:
            p_hi = np.log(w[-1] / w[-2]) / np.log(L[-1] / L[-2])
            print(f"        between the two longest routes: exponent {p_hi:.2f}")
    if args.tolerance_check:
        print(tolerance_check(max(args.lengths)), flush=True)
    if args.mesh_check and max(args.lengths) in steady_runs:
        print(mesh_check(max(args.lengths), steady_runs[max(args.lengths)]), flush=True)
    if args.example4:
        print(example4(args.repeat), flush=True)


def example4(repeat: int) -> str:
    """Steady against dynamic Example 4, whole process each (scenario -> build -> solve -> files),
    ``repeat`` times interleaved (dynamic, steady, dynamic, ...) in this one process; the ratio of
    the medians. The first pair also pays each mode's one-time compiled-kernel load."""
    sc = load_scenario(ROOT / "scenarios" / "paper_ex4_spatial.toml")
    st = parse_scenario({**sc.to_dict(), "solver": {**sc.solver.to_dict(), "mode": "steady"}}, ROOT, default_name="ex4")
    walls = {"dynamic": [], "steady": []}
    lines = []
    for i in range(repeat):
        for name, scenario in (("dynamic", sc), ("steady", st)):
            r = timed(scenario)
            walls[name].append(r["wall_s"])
            s = r["summary"]
            walls.setdefault(name + "_F", s["pull_force_N"])
            lines.append(f"Example 4 {name:7s} run {i + 1}: {s['status']:6s} wall {r['wall_s']:7.2f} s  "
                         f"Newton {s['newton_iterations']:6d}  F {s['pull_force_N']:.6f} N")
    med_d, med_s = statistics.median(walls["dynamic"]), statistics.median(walls["steady"])
    ratios = ", ".join(f"{d / s:.1f}x" for d, s in zip(walls["dynamic"], walls["steady"]))
    lines.append(f"Example 4, whole process, median of {repeat}: dynamic {med_d:.2f} s / steady {med_s:.2f} s = "
                 f"{med_d / med_s:.1f}x (pairwise {ratios}); pulling force steady - dynamic "
                 f"{100 * (walls['steady_F'] / walls['dynamic_F'] - 1):+.3f} %")
    return "\n".join(lines)

if __name__ == "__main__":
    main()
