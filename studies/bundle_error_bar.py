"""A bundle's steady error bar (:func:`exucable.solve.error_bar.bundle_error_bar`) on the up-bend study's cases.

Per case of ``studies/bundle_upbend_study.py`` (three cables, 30° bend of R 5 m up, down or left between
3 m straights, triangular or cradled, cable friction 0 or 0.3) it runs the scenario as ``exucable run``
does (:func:`exucable.run.run_scenario`, steady) and prints the pull F, the bar u and its parts (mesh,
solve, onset layer), the coarse mesh's pull and the CPU time of the whole run, of the fine solve (the
answering start's, the budget rule's yardstick) and of the coarse one.
Then, on one case, the check against finer meshes: F on the mesh refined 2 and 4 times (each with its
own bar), and whether |F_h − F_finest| is within the bar of F_h.

    nice .venv/bin/python studies/bundle_error_bar.py [--limit 60] [--quick] [--check down,triangular,0]

``--quick``: two cases (down-bend, triangular and cradled, frictionless between the cables) and the
check on the down-bend's triangle at refine 1 and 2 only.
"""

from __future__ import annotations

import argparse
import time

from bundle_upbend_study import CASES, scenario

from exucable.run import run_scenario


def run(sc, refine=1.0):
    c = time.process_time()
    s = run_scenario(sc, refine=refine).summary
    total = time.process_time() - c
    parts = s.get("pull_force_uncertainty") or {}
    return s, parts, total


def fmt(x, spec=".4g"):
    return "" if x is None else format(x, spec)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--limit", type=float, default=60.0, help="each solve's CPU budget [s] (solver.steady_time_limit)")
    p.add_argument("--quick", action="store_true", help="two cases, the check at refine 1 and 2")
    p.add_argument("--check", default="down,triangular,0", help="the case checked against finer meshes")
    args = p.parse_args(argv)
    cases = [("down", "triangular", 0.0), ("down", "cradled", 0.0)] if args.quick else CASES
    print("| bend | arrangement | cable friction | status | F [N] | u [N] (u/F) | mesh [N] | solve [N] | layer [N] "
          "| coarse F [N] | CPU whole run [s] | fine solve CPU [s] | coarse CPU [s] | coarse / fine |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for bend, arr, cf in cases:
        s, b, cpu = run(scenario(bend, arr, cf, args.limit))
        u, F = s["pull_force_uncertainty_N"], s["pull_force_N"]
        fine = s["bundle"]["starts_tried"][-1]["cpu_s"]      # the answering start's solve (the rule's yardstick)
        coarse = b.get("cpu_time_s")
        print(f"| {bend} | {arr} | {cf:g} | {s['status']} | {fmt(F, '.6g')} | {fmt(u)} "
              f"({fmt(u / F if u is not None and F else None, '.2g')}) | {fmt(b.get('mesh_N'))} | {fmt(b.get('solve_N'), '.2g')} "
              f"| {fmt(b.get('layer_N'), '.2g')} | {fmt(b.get('coarse_value_N'), '.6g')} | {cpu:.3g} | {fine:.3g} "
              f"| {fmt(coarse, '.3g')} | {fmt(coarse / fine if coarse is not None and fine else None, '.2g')} |")
    bend, arr, cf = args.check.split(",")
    refines = (1.0, 2.0) if args.quick else (1.0, 2.0, 4.0)
    rows = [(r, *run(scenario(bend, arr, float(cf), args.limit), refine=r)) for r in refines]
    ref = rows[-1][1]["pull_force_N"]
    print(f"\nthe {bend} bend, {arr}, cable friction {cf}: against the finest mesh (refine {refines[-1]:g}, F_ref = {ref:.6g} N)")
    print("| refine | elements per cable | status | F_h [N] | u [N] | abs(F_h - F_ref) [N] | within the bar | CPU whole run [s] |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for r, s, b, cpu in rows[:-1]:
        err, u = abs(s["pull_force_N"] - ref), s["pull_force_uncertainty_N"]
        print(f"| {r:g} | {s['mesh']['elements']} | {s['status']} | {s['pull_force_N']:.6g} | {fmt(u)} | {err:.3g} | "
              f"{'yes' if u is not None and err <= u else 'NO'} | {cpu:.3g} |")
    r, s, b, cpu = rows[-1]
    print(f"| {r:g} | {s['mesh']['elements']} | {s['status']} | {s['pull_force_N']:.6g} | {fmt(s['pull_force_uncertainty_N'])} "
          f"| (the reference) | | {cpu:.3g} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
