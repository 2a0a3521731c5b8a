"""Issue 15's solver changes, switched off and on, side by side in one run.

"before" is the solve as released: Exudyn doubles the step after any 2 steps
(``adaptiveStepRecoverySteps = 2``, ``adaptiveStepRecoveryIterations = 7``) and each Newton
iteration makes two kernel passes (force, then force + Jacobian). "after" is the current default:
doubling after 4 steps of at most 4 iterations, one kernel pass per iteration. Each run is a whole
``exucable run --no-plots`` process of a paper example at its fidelity (to a steady pulling force),
alternating before/after ``--repeat`` times; medians and their ratio are printed, with the results
and their difference.

    nice .venv/bin/python benchmarks/before_after.py                 # Examples 3 and 4, ~3 min
    nice .venv/bin/python benchmarks/before_after.py --repeat 3 --examples 2 3 4
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = {1: "paper_ex1_incline.toml", 2: "paper_ex2_bend90.toml", 3: "paper_ex3_helix.toml",
            4: "paper_ex4_spatial.toml"}

# `exucable run` with the released solver settings patched back in
_BEFORE = r"""
import sys
import exucable.solve as solve
import exucable.model.coupling as coupling
base = solve.solver_settings
def released(sp):
    s = base(sp)
    s.timeIntegration.adaptiveStepRecoverySteps = 2
    s.timeIntegration.adaptiveStepRecoveryIterations = 7
    return s
solve.solver_settings = released
init = coupling.ContactCoupling.__init__
def two_passes(self, *a, **k):
    init(self, *a, **k)
    self.jacobian_with_force = False
coupling.ContactCoupling.__init__ = two_passes
from exucable.cli import main
sys.exit(main(sys.argv[1:]))
"""


def run(variant: str, scenario: Path, out: Path) -> dict:
    args = ["run", str(scenario), "--out", str(out), "--quiet", "--no-plots"]
    cmd = ([sys.executable, "-c", _BEFORE, *args] if variant == "before"
           else [str(Path(sys.executable).with_name("exucable")), *args])
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    whole = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"{variant} {scenario.name} failed:\n{p.stderr[-2000:]}")
    s = json.loads((out / "summary.json").read_text())
    key = s["steady_quantity"]
    return {"whole_s": whole, "solve_s": s["wall_time_s"], "steps": s["steps"], "newton": s["newton_iterations"],
            "kernel_s": s["kernel_time_s"], "result_N": s[key], "quantity": key}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--examples", type=int, nargs="+", default=[3, 4], choices=sorted(EXAMPLES))
    args = ap.parse_args(argv)
    print(f"# Before/after issue 15's solver changes — load average {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores, median of {args.repeat} alternating run(s)\n")
    print("| example | variant | whole process [s] | solve [s] | steps | Newton its | its/step | kernel [s] | result [N] |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for ex in args.examples:
            sc = ROOT / "scenarios" / EXAMPLES[ex]
            res = {"before": [], "after": []}
            for i in range(args.repeat):
                for v in ("before", "after"):
                    res[v].append(run(v, sc, Path(tmp) / f"{ex}-{v}-{i}"))
            med = {}
            for v, rs in res.items():
                med[v] = {k: statistics.median(r[k] for r in rs) for k in ("whole_s", "solve_s", "kernel_s")}
                r = rs[0]
                print(f"| Ex. {ex} | {v} | {med[v]['whole_s']:.2f} | {med[v]['solve_s']:.2f} | {r['steps']} | "
                      f"{r['newton']} | {r['newton'] / r['steps']:.2f} | {med[v]['kernel_s']:.2f} | "
                      f"{r['quantity']} {r['result_N']:.6g} |", flush=True)
            b, a = res["before"][0], res["after"][0]
            print(f"| Ex. {ex} | before/after | {med['before']['whole_s'] / med['after']['whole_s']:.2f}x | "
                  f"{med['before']['solve_s'] / med['after']['solve_s']:.2f}x | | "
                  f"{b['newton'] / a['newton']:.2f}x | | | {100 * (a['result_N'] / b['result_N'] - 1):+.4f} % |",
                  flush=True)
    print(f"\nload average at the end {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
