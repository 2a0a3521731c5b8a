"""Speed of the paper's examples at full fidelity, measured in one run.

For each example: wall time, simulated time, steps, Newton iterations per step, Jacobian
updates, the time shares of the contact kernel / Exudyn / Python, and peak memory (each example in
its own process, so the peak is its own). Then the same Example 4 with ``broad_phase = "none"``
over a shorter time, and the brute-force / broad-phase ratio of the time per Newton iteration
(both measured here, in this run). Then the growth of cost with elements and check points on
Example 2, with the fitted exponent (expected ≈ 1: linear).

    .venv/bin/python benchmarks/run_examples.py            # everything (~10 min on 2 cores)
    .venv/bin/python benchmarks/run_examples.py --quick    # smoke run: fast Ex. 2 and 4, two sizes, short runs

Prints a Markdown table per part; machine noise is real (shared machines): compare ratios
measured within one run, not absolute seconds across runs.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import os
import platform
import resource
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def _one(args):
    """Run one scenario (dict overrides applied) in this process; return its figures."""
    path, overrides, steady_stop, end_time = args
    import tomllib
    from exucable.scenario.specs import parse_scenario
    from exucable.model.build import build_model
    from exucable.solve.dynamic import simulate

    with open(path, "rb") as f:
        data = tomllib.load(f)
    for dotted, value in overrides.items():
        table, key = dotted.split(".")
        data.setdefault(table, {})[key] = value
    if end_time is not None:
        data["solver"]["end_time"] = end_time
    sc = parse_scenario(data, Path(path).parent, default_name=Path(path).stem)
    t0 = time.perf_counter()
    model = build_model(sc)
    build = time.perf_counter() - t0
    out = simulate(model, steady_stop=steady_stop)
    c = model.coupling
    kernel = c.kernel_time_s if c is not None else 0.0
    peak_mib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return {
        "status": out.status, "wall_s": out.wall_time_s + build, "build_s": build,
        "simulated_s": out.end_time_s, "steps": out.steps, "newton": out.newton_iterations,
        "jacobians": out.jacobian_updates, "kernel_s": kernel,
        "user_calls": (c.force_calls + c.jacobian_calls) if c is not None else 0,
        "pull_force_N": out.history.pull_force_N[-1] if out.history.pull_force_N else float("nan"),
        "trailing_N": out.history.trailing_tension_N[-1] if out.history.trailing_tension_N else float("nan"),
        "peak_MiB": peak_mib,
    }


def run(path, overrides=None, steady_stop=True, end_time=None):
    ctx = mp.get_context("forkserver")
    with ctx.Pool(1) as pool:   # its own process: its own peak memory, no warm caches shared
        return pool.apply(_one, ((str(path), overrides or {}, steady_stop, end_time),))


def python_overhead_s(n_calls):
    """Cost of the Python user-function round trips alone, measured: calls of a trivial
    ObjectGenericODE2 force function per second on this machine."""
    import exudyn as exu
    from exudyn.itemInterface import NodePointSlope1, ObjectGenericODE2
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    nodes = [mbs.AddNode(NodePointSlope1(referenceCoordinates=[i, 0, 0, 1, 0, 0])) for i in range(41)]
    n = 6 * 41
    zero = np.zeros(n)
    M = exu.MatrixContainer()
    M.SetWithDenseMatrix(np.eye(n), useDenseMatrix=False)
    mbs.AddObject(ObjectGenericODE2(nodeNumbers=nodes, massMatrix=M,
                                    forceUserFunction=lambda mbs, t, i, q, v: zero))
    mbs.Assemble()
    s = exu.SimulationSettings()
    s.timeIntegration.endTime = 1.0
    s.timeIntegration.numberOfSteps = 2000
    s.show.computationTime = False
    s.solution.file.write = False
    t0 = time.perf_counter()
    mbs.SolveDynamic(s)
    per_step = (time.perf_counter() - t0) / 2000
    return per_step * n_calls / 2.0   # ~2 force calls per step there


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true",
                    help="smoke run: the fast Examples 2 and 4, two sizes per growth table, 0.01 s runs")
    args = ap.parse_args()
    fidelity = "their fast variants (smoke run)" if args.quick else "paper fidelity"
    print(f"# exucable examples at {fidelity} — {platform.processor() or platform.machine()}, "
          f"{os.cpu_count()} cores, Python {platform.python_version()}\n")
    examples = [("Ex. 1 incline", "paper_ex1_incline.toml"), ("Ex. 2 bend 90°", "paper_ex2_bend90.toml"),
                ("Ex. 3 helix", "paper_ex3_helix.toml"), ("Ex. 4 spatial", "paper_ex4_spatial.toml")]
    folder = ROOT / "scenarios"
    if args.quick:   # the coarse variants of the two examples the later parts use
        folder = folder / "fast"
        examples = [examples[1], examples[3]]
    print("| example | status | wall [s] | simulated [s] | steps | Newton/step | Jacobians | kernel | Exudyn+Python | peak [MiB] | result [N] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    results = {}
    for name, f in examples:
        r = run(folder / f)
        results[name] = r
        solve = r["wall_s"] - r["build_s"]
        share_k = r["kernel_s"] / solve if solve > 0 else 0.0
        result = r["trailing_N"] if "helix" in name else r["pull_force_N"]
        print(f"| {name} | {r['status']} | {r['wall_s']:.1f} | {r['simulated_s']:.3f} | {r['steps']} | "
              f"{r['newton'] / max(r['steps'], 1):.1f} | {r['jacobians']} | {100 * share_k:.0f} % | "
              f"{100 * (1 - share_k):.0f} % | {r['peak_MiB']:.0f} | {result:.5g} |", flush=True)
    overhead = python_overhead_s(results["Ex. 4 spatial"]["user_calls"])
    print(f"\nPython round trips of Ex. 4's {results['Ex. 4 spatial']['user_calls']} user-function calls "
          f"(measured with a trivial force function): ~{overhead:.2f} s")

    # broad phase against brute force on Example 4, same shortened duration
    T = 0.01 if args.quick else 0.05
    print(f"\n## Broad phase, Example 4 over {T} s (steady stop off)\n")
    a = run(folder / "paper_ex4_spatial.toml", {}, steady_stop=False, end_time=T)
    b = run(folder / "paper_ex4_spatial.toml", {"contact.broad_phase": "none"}, steady_stop=False, end_time=T)
    ka, kb = a["kernel_s"] / max(a["user_calls"], 1), b["kernel_s"] / max(b["user_calls"], 1)
    print("| broad phase | wall [s] | steps | kernel ms/call |\n|---|---|---|---|")
    print(f"| aabb | {a['wall_s']:.1f} | {a['steps']} | {1e3 * ka:.2f} |")
    print(f"| none | {b['wall_s']:.1f} | {b['steps']} | {1e3 * kb:.2f} |")
    print(f"\nbrute force / broad phase: wall {b['wall_s'] / a['wall_s']:.1f}x, kernel per call {kb / ka:.1f}x")

    # growth with elements and check points (Example 2, fixed short duration)
    T = 0.01 if args.quick else 0.1
    print(f"\n## Cost growth, Example 2 over {T} s\n")
    for label, key, values, base in (
            ("elements", "cable.elements", [20, 40] if args.quick else [25, 50, 100, 200],
             {"contact.check_points_per_element": 20 if args.quick else 100}),
            ("check points per element", "contact.check_points_per_element",
             [20, 40] if args.quick else [50, 100, 200, 400, 800], {"cable.elements": 20 if args.quick else 40})):
        rows = []
        for v in values:
            ov = dict(base)
            ov[key] = v
            r = run(folder / "paper_ex2_bend90.toml", ov, steady_stop=False, end_time=T)
            rows.append((v, r))
        print(f"| {label} | wall [s] | Newton its | ms per Newton iteration | kernel ms/call |\n|---|---|---|---|---|")
        per = []
        for v, r in rows:
            p = (r["wall_s"] - r["build_s"]) / max(r["newton"], 1)
            per.append(p)
            print(f"| {v} | {r['wall_s']:.2f} | {r['newton']} | {1e3 * p:.2f} | "
                  f"{1e3 * r['kernel_s'] / max(r['user_calls'], 1):.3f} |")
        slope = np.polyfit(np.log([v for v, _ in rows]), np.log(per), 1)[0]
        print(f"\ncost per Newton iteration grows like {label}^{slope:.2f} (linear = 1; below 1 "
              f"while fixed costs dominate)\n", flush=True)
    print(json.dumps({k: {kk: vv for kk, vv in v.items()} for k, v in results.items()}, indent=1)
          if "--json" in sys.argv else "")


if __name__ == "__main__":
    main()
