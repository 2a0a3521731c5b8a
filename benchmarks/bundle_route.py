"""Whole-process wall and CPU time of a bundle run: three cables through a 100 m route with four bends, steady mode.

    nice .venv/bin/python benchmarks/bundle_route.py [--count 3] [--arrangement auto triangular]
        [--length 100] [--repeat 1] [--out DIR]

Writes the scenario (bends of 5 m radius: 90° left, 90° left, 30° up, 90° right, joined by equal
straights; cables of 30 mm diameter, 1.4 kg/m, in a 100 mm duct, D/d 3.33; μ 0.3, back tension 300 N)
and times ``exucable run SCENARIO --no-plots`` in a fresh process per repeat (scenario → build → solve
→ files; CPU time of the child process), next to the same route with one cable (``cable.count = 1``)
timed in the same run, and prints the ratio, the bundle's pull force, its weight correction factor
beside the calculators' and its status, for each arrangement given: by default ``auto`` (what a
scenario without ``cable.arrangement`` gets: the calculators' choice, cradled at this D/d) and
``triangular`` (the triangle's top cable falls off the other two in the bends at this D/d; the steady
solve follows it from the cross-section's statics start, which ``solver.bundle_starts`` tries after
the clearance start gives up: reference/README.md, "A start sequence"), each with the start that
answered. Mesh: the scenario's rule (printed); each run's error bar is printed with its parts (a
bundle's: the coarse-mesh solve only where the CPU budget left has room for it,
``exucable.solve.error_bar.bundle_error_bar``). Target (issue "Three
cables in one conduit"): ≤ 60 s whole process. The machine is shared: compare the rows of one run
with each other.
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

from exucable.io import atomic_write_text

SCENARIO = """name = "bundle_route_{count}"
[cable]
radius = 0.015
density = 2000.0
youngs_modulus = 2e8
count = {count}
arrangement = "{arrangement}"
[conduit]
inner_radius = 0.05
path = [{{straight = {straight}}}, {{bend = 90, radius = 5.0, turn = "left"}}, {{straight = {straight}}},
        {{bend = 90, radius = 5.0, turn = "left"}}, {{straight = {straight}}}, {{bend = 30, radius = 5.0, turn = "up"}},
        {{straight = {straight}}}, {{bend = 90, radius = 5.0, turn = "right"}}, {{straight = {straight}}}]
[contact]
friction = 0.3
[pull]
speed = 0.1
back_tension = 300.0
[gravity]
g = 9.81
[solver]
mode = "steady"
end_time = 1.0
"""


def _num(value, fmt: str, unit: str = "") -> str:
    """A summary number formatted, or "n/a" where the run gave none (a failed solve's None)."""
    return "n/a" if value is None else f"{value:{fmt}}{unit}"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--count", type=int, default=3)
    p.add_argument("--arrangement", nargs="+", default=["auto", "triangular"],
                   help="the bundle's arrangements, one run each (auto: the calculators' choice)")
    p.add_argument("--length", type=float, default=100.0, help="route length [m] (approximately)")
    p.add_argument("--repeat", type=int, default=1)
    p.add_argument("--out", default="out/bundle-benchmark")
    p.add_argument("--quick", action="store_true", help="two cables on the shortest route, 1 m straights, 34 m (a smoke run)")
    args = p.parse_args(argv)
    if args.quick:      # the smoke run: two cables on the shortest route (the straights' floor of 1 m)
        args.count, args.length, args.repeat, args.arrangement = 2, 12.0, 1, ["triangular"]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    bends_m = 3 * 0.5 * 3.14159265 * 5.0 + 3.14159265 / 6 * 5.0
    straight = max(1.0, (args.length - bends_m) / 5.0)
    exe = Path(sys.executable).with_name("exucable")
    runs = [("single", 1, "single")] + [(a, args.count, a) for a in args.arrangement]
    rows = {}
    for name, count, arrangement in runs:
        path = out / f"bundle_route_{count}_{name}.toml"
        atomic_write_text(path, SCENARIO.format(count=count, arrangement=arrangement, straight=f"{straight:.6g}"))
        rows[name] = {"times": [], "cpu": [], "path": path}
    for _ in range(args.repeat):
        for name, row in rows.items():        # interleaved: one cable, then each bundle
            t0 = time.perf_counter()
            c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            proc = subprocess.run([str(exe), "run", str(row["path"]), "--out", str(out / f"run_{name}"), "--no-plots",
                                   "--quiet"], capture_output=True, text=True)
            row["times"].append(time.perf_counter() - t0)
            c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            row["cpu"].append(c1.ru_utime - c0.ru_utime + c1.ru_stime - c0.ru_stime)
            row["exit"] = proc.returncode
            row["summary"] = json.loads((out / f"run_{name}" / "summary.json").read_text())
    one = rows["single"]
    t1, c1 = statistics.median(one["times"]), statistics.median(one["cpu"])
    s1 = one["summary"]
    print(f"route {5 * straight + bends_m:.0f} m (straights {straight:.4g} m, 4 bends), whole process, "
          f"median of {args.repeat}:")
    print(f"  1 cable : {t1:7.2f} s wall, {c1:7.2f} s CPU, status {s1['status']}, pull {_num(s1['pull_force_N'], '.6g')} N, "
          f"{s1['mesh']['elements']} elements, {s1['newton_iterations']} Newton iterations")
    for name in args.arrangement:
        _print_bundle(args.count, name, rows[name], t1, c1)
    return 0


def _print_bundle(count: int, name: str, row: dict, t1: float, c1: float) -> None:
    """The lines of one bundle run: time against the one cable's, status, and (solved) its factor and shares."""
    tn, cn = statistics.median(row["times"]), statistics.median(row["cpu"])
    sn = row["summary"]
    b = sn.get("bundle") or {}
    laid = b.get("arrangement", name)
    tried = ", ".join(f"{a['start']} {a['status']} {a['cpu_s']:.3g} s" for a in b.get("starts_tried") or [])
    print(f"  {count} cables, arrangement {name}{f' ({laid})' if laid != name else ''}: {tn:7.2f} s wall, {cn:7.2f} s CPU, "
          f"status {sn['status']}, pull {_num(sn['pull_force_N'], '.6g')} N, starts tried: {tried or 'n/a'}, "
          f"{sn['mesh']['elements']} elements each ({sn['mesh']['element_length_m']:.3g} m, {sn['mesh']['check_points_per_element']} check points), {sn['newton_iterations']} Newton iterations"
          + (f" ({sn['message']})" if sn["status"] == "ok" else ""))
    print(f"    ratio bundle / one cable: {tn / t1:.2f}x wall, {cn / c1:.2f}x CPU; target ≤ 60 s whole process: "
          f"{'met' if tn <= 60.0 and sn['status'] == 'ok' else 'NOT met'} (wall), "
          f"{'met' if cn <= 60.0 and sn['status'] == 'ok' else 'NOT met'} (CPU)")
    if sn["status"] != "ok":     # a failed run's state is not the steady pull: no factor or shares from it
        print(f"    NOT a steady pull (no weight correction or pull shares): status {sn['status']}: {sn['message']}")
        return
    print(f"    weight correction factor {_num(b.get('weight_correction_factor'), '.5g')} (calculators' "
          f"{_num(b.get('formula_weight_correction_factor'), '.5g')}); per straight: "
          + ", ".join(_num(st.get("weight_correction_factor"), ".4g") for st in b.get("straights") or []))
    u = sn.get("pull_force_uncertainty") or {}
    coarse = (f"coarse {_num(u.get('coarse_value_N'), '.6g')} N on {u.get('coarse_elements')} elements, "
              f"{_num(u.get('cpu_time_s'), '.3g')} s CPU" if u.get("coarse_value_N") is not None
              else "no coarse solve")
    mesh = f"mesh {_num(u.get('mesh_N'), '.3g')} N" if u.get("mesh_N") is not None else "mesh not measured"
    print(f"    error bar ± {_num(sn.get('pull_force_uncertainty_N'), '.3g')} N ({mesh}, "
          f"solve {_num(u.get('solve_N'), '.2g')} N, onset layer {_num(u.get('layer_N'), '.2g')} N; {coarse}): "
          f"{(sn.get('pull_force_uncertainty_method') or '')[:200]}")
    print("    pull shares: " + ", ".join(_num(None if c.get("pull_share") is None else 100 * c["pull_share"], ".1f", " %")
                                         for c in b.get("cables") or []))

if __name__ == "__main__":
    raise SystemExit(main())
