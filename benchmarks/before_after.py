"""Issue 15's solver changes, switched off and on, side by side in one run.

"before" is the solve as this session found it (main 04e3b65): Newton tolerance 1e-7, contact
damping onset 10 µm, and the first step at the scenario's full step (Exudyn then halves it after
each failed attempt). "after" is the current default: tolerance 1e-5, onset 100 µm, first step
capped at step/128. Each run is a whole ``exucable run --no-plots`` process of a paper example at
its fidelity (to a steady pulling force), alternating before/after ``--repeat`` times; medians and
their ratio are printed, with the results and their difference. The "before" settings are given
as scenario keys in a copy of the scenario, and the start by patching ``START_STEP_DIVISOR``.

    nice .venv/bin/python benchmarks/before_after.py                 # Examples 3 and 4, ~2 min
    nice .venv/bin/python benchmarks/before_after.py --repeat 3 --examples 2 3 4
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = {1: "paper_ex1_incline.toml", 2: "paper_ex2_bend90.toml", 3: "paper_ex3_helix.toml",
            4: "paper_ex4_spatial.toml"}

# `exucable run` with the start as it was: the first step at the full solver.step
_BEFORE = r"""
import sys
import exucable.solve as solve
solve.START_STEP_DIVISOR = 1
from exucable.cli import main
sys.exit(main(sys.argv[1:]))
"""

#: scenario keys of "before" (main 04e3b65 defaults), written into a copy of the scenario
BEFORE_KEYS = {"contact": {"damping_onset": "1.0e-5"}, "solver": {"newton_tolerance": "1.0e-7"}}


def before_scenario(scenario: Path, directory: Path) -> Path:
    """A copy of ``scenario`` with the keys of :data:`BEFORE_KEYS` set at the top of their tables."""
    text = scenario.read_text()
    for table, keys in BEFORE_KEYS.items():
        lines = "".join(f"{k} = {v}\n" for k, v in keys.items())
        text, n = re.subn(rf"(?m)^\[{table}\]\s*\n", lambda m: m.group(0) + lines, text, count=1)
        if n == 0:
            text += f"\n[{table}]\n{lines}"
    path = directory / f"before-{scenario.name}"
    path.write_text(text)
    return path


def run(variant: str, scenario: Path, out: Path) -> dict:
    if variant == "before":
        scenario = before_scenario(scenario, out.parent)
    args = ["run", str(scenario), "--out", str(out), "--quiet", "--no-plots"]
    cmd = ([sys.executable, "-c", _BEFORE, *args] if variant == "before"
           else [str(Path(sys.executable).with_name("exucable")), *args])
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    whole = time.perf_counter() - t0
    s_path = out / "summary.json"
    if not s_path.exists():
        raise RuntimeError(f"{variant} {scenario.name} failed:\n{p.stderr[-2000:]}")
    s = json.loads(s_path.read_text())
    if s["status"] not in ("ok", "steady"):
        raise RuntimeError(f"{variant} {scenario.name}: status {s['status']}\n{p.stderr[-2000:]}")
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
