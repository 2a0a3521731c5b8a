"""How many check points per element does a steady solve need? The mesh rule's count × 0.25, 0.5, 1, 2.

The mesh rule (exucable/scenario/mesh.py) spaces the contact check points at most λ/4 apart on the
rule's mesh, λ = √(EJ/T_max) the bending length over which a bend end's contact load decays, with
8–200 per element; steady mode solves on that mesh refined ``STEADY_REFINE`` (2) times with the same
count per element, so the solved spacing is at most λ/8. λ shrinks as the tension grows, so the count
grows with the route: 17 per element at 1 km, 72 at 10 km on the long routes of
``benchmarks/long_routes.py`` (30 mm cable, 1.5 kg/m, EA 14 MN, 60 mm duct, gravity, μ 0.2, a 15°
bend of 10 m radius every ~350 m). The contact kernel's two passes and the build's check-point
arrays scale with the count.

Each case is solved in steady mode on the solved mesh (the rule's refined by ``STEADY_REFINE``) with
the rule's count per element times 0.25, 0.5, 1 and 2 (at least 1), everything else unchanged, each
from the same rope start (no error bar's coarse solve, so only the count changes between the runs),
and prints per count: the check points, Newton iterations, the pulling force F [N], the largest
windowed sidewall pressure P [N/m] (``max_sidewall_pressure_N_per_m``), their change relative to the
run with the most check points, and the CPU time of the run [s] (the rule's own count's run also
builds the rule's unrefined mesh, where steady mode reads the count from). The criterion for a sparser rule:
F and P unchanged within a fifth of the error bar's relative floor
(``exucable.solve.error_bar.RESOLUTION_FLOOR`` = 1e-4, so 2e-5) on every case. A count that would
hold more than ``MAX_MODEL_CHECK_POINTS`` check points is refused (printed so, naming the limit);
the run with the most check points that solved is then the reference.

Cases: the long routes at 1 km and 5 km (``--lengths``; 10 km with ``--lengths 1000 5000 10000``),
and two industry routes in steady mode: CommScope ConQuest run A–H (three bends of 10 ft, μ 0.5)
and the Gera Tools worked example (a 90° bend of 2 ft radius after 200 ft, μ 0.3).

    nice .venv/bin/python studies/checkpoint_study.py [--lengths 1000 5000 10000] [--factors 0.25 0.5 1 2] [--record reference/checkpoint_study.json]
    nice .venv/bin/python studies/checkpoint_study.py --quick      # a 200 m route, counts × 0.5 and 1

The record and its reading: reference/README.md, "Check points per element".
"""

from __future__ import annotations

import argparse
import dataclasses
import gc
import importlib.util
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FACTORS = (0.25, 0.5, 1.0, 2.0)
INDUSTRY = ("industry/commscope_conquest_run_a_h", "industry/gera_wire_pulling_example")


def _long_routes():
    """benchmarks/long_routes.py as a module: its routes are the ones the rule's cost was measured on."""
    spec = importlib.util.spec_from_file_location("long_routes", ROOT / "benchmarks" / "long_routes.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def scenarios(lengths, quick: bool):
    """(case name, validated steady-mode Scenario) of each case."""
    from exucable.scenario.specs import load_scenario, parse_scenario

    routes = _long_routes()
    out = []
    for L in lengths:
        sc = parse_scenario(routes.route_data(float(L)), ROOT, default_name="route")
        out.append((f"long route {L / 1000:g} km", sc))
    if not quick:
        for name in INDUSTRY:
            sc = load_scenario(ROOT / "scenarios" / f"{name}.toml")
            sc = dataclasses.replace(sc, solver=dataclasses.replace(sc.solver, mode="steady"))
            out.append((name.split("/")[-1], sc))
    return out


def solve(sc, k: int | None) -> dict:
    """One steady solve with ``k`` check points per element on the solved mesh (None: the rule's,
    which steady mode takes from the rule's unrefined mesh, built for it); the numbers only."""
    from exucable.errors import ExucableError
    from exucable.run import run_scenario

    c0 = time.process_time()
    try:
        res = run_scenario(sc, None, plots=False, check_points_per_element=k, error_bar=False)
    except ExucableError as exc:
        return {"check_points_per_element": k, "status": "refused", "message": str(exc).splitlines()[0],
                "cpu_s": time.process_time() - c0}
    s = res.summary
    k = s["mesh"]["check_points_per_element"]
    row = {"check_points_per_element": k, "status": s.get("status"),
           "elements": s["mesh"]["elements"], "check_points": s["mesh"]["elements"] * k,
           "newton_iterations": s.get("newton_iterations"),
           "pull_force_N": s.get("pull_force_N"),
           "max_sidewall_pressure_N_per_m": s.get("max_sidewall_pressure_N_per_m"),
           "cpu_s": time.process_time() - c0}
    del res
    gc.collect()
    return row


def study(lengths, factors, quick: bool) -> dict:
    from exucable.solve.error_bar import RESOLUTION_FLOOR

    cases = []
    for name, sc in scenarios(lengths, quick):
        # the rule's own count first (it says what the count is), then the others from it
        first = solve(sc, None)
        k_rule = first["check_points_per_element"]
        if k_rule is None:
            cases.append({"case": name, "rule_check_points_per_element": None, "elements": None,
                          "reference_factor": None, "runs": [dict(first, factor=1.0)]})
            continue
        runs = []
        for f in factors:
            row = first if f == 1.0 else solve(sc, max(1, int(round(f * k_rule))))
            row["factor"] = f
            runs.append(row)
            print(f"# {name}: x{f:g} ({row['check_points_per_element']} per element): {row['status']}, {row['cpu_s']:.1f} s CPU", file=sys.stderr, flush=True)
        ok = [r for r in runs if r["status"] not in ("refused", "failed")]
        ref = max(ok, key=lambda r: r["check_points_per_element"]) if ok else None
        for r in runs:
            for key in ("pull_force_N", "max_sidewall_pressure_N_per_m"):
                if ref is not None and r in ok and ref[key]:
                    r[f"{key}_change"] = r[key] / ref[key] - 1.0
        cases.append({"case": name, "rule_check_points_per_element": k_rule, "elements": first.get("elements"),
                      "reference_factor": ref["factor"] if ref else None, "runs": runs})
    return {"tolerance_relative": RESOLUTION_FLOOR / 5, "factors": list(factors), "cases": cases}


def print_record(record) -> None:
    tol = record["tolerance_relative"]
    print(f"# check points per element: the rule's count x factor; changes relative to the run with the most "
          f"check points; tolerance {tol:.0e} (a fifth of the error bar's floor)\n")
    print("| case | rule's count | factor | per element | check points | Newton its | F [N] | F change | "
          "P max [N/m] | P change | within tolerance | CPU [s] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")

    def rel(x):
        return "" if x is None else f"{x:+.1e}"

    for c in record["cases"]:
        for r in c["runs"]:
            if r["status"] == "refused" or r.get("pull_force_N") is None:
                print(f"| {c['case']} | {c['rule_check_points_per_element']} | {r['factor']:g} | "
                      f"{r['check_points_per_element']} | {r['status']}: {r.get('message', '')[:90]} | | | | | | | |")
                continue
            dF, dP = r.get("pull_force_N_change"), r.get("max_sidewall_pressure_N_per_m_change")
            within = "" if dF is None or dP is None else ("yes" if max(abs(dF), abs(dP)) <= tol else "no")
            print(f"| {c['case']} | {c['rule_check_points_per_element']} | {r['factor']:g} | "
                  f"{r['check_points_per_element']} | {r['check_points']} | {r['newton_iterations']} | "
                  f"{r['pull_force_N']:.6f} | {rel(dF)} | {r['max_sidewall_pressure_N_per_m']:.5f} | {rel(dP)} | "
                  f"{within} | {r['cpu_s']:.1f} |")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--lengths", type=float, nargs="+", default=[1000.0, 5000.0], help="long routes' lengths [m]")
    p.add_argument("--factors", type=float, nargs="+", default=list(FACTORS),
                   help="multiples of the rule's count to solve (default 0.25 0.5 1 2)")
    p.add_argument("--record", help="write the record here (JSON)")
    p.add_argument("--from-json", help="print a stored record instead of running")
    p.add_argument("--quick", action="store_true", help="smoke run: a 200 m route, the rule's count x 0.5 and 1")
    args = p.parse_args(argv)
    if args.from_json:
        record = json.loads(Path(args.from_json).read_text())
    else:
        lengths, factors = ([200.0], (0.5, 1.0)) if args.quick else (args.lengths, sorted(set(args.factors) | {1.0}))
        record = study(lengths, factors, args.quick)
        if args.record:
            from exucable.io import atomic_write_text
            atomic_write_text(Path(args.record), json.dumps(record, indent=1) + "\n")
    print_record(record)
    return 0


if __name__ == "__main__":
    sys.exit(main())
