"""exucable against a naive Exudyn implementation of the same problem, in one run.

The naive implementation is what a first Exudyn model of paper Example 2 looks like
(``../shared/notes/exudyn-findings.md``, first row of its table): the 90° bend (R 0.5 m between
two 1 m straights, μ 0.2, back tension 150 N, pulled at 0.1 m/s), 40 ANCF elements, 10 check
points per element, the paper's straight segments (100) searched brute force, the paper's contact
law (damping C = 1e3 N·s/m from first touch), all in one ``ObjectGenericODE2`` whose force is the
numpy reference kernel and whose Jacobian is its exact sparse one; the cable starts on the
centreline at rest, loads and speed ramped over 0.05 s; Exudyn's default solver settings
(modified Newton, dense linear solver, adaptive step) with steps ≤ 1e-3 s, 0.25 s simulated.

exucable is ``exucable run scenarios/paper_ex2_bend90.toml`` (the paper's fidelity, 40 × 200),
whole process, as a user runs it. Both are timed here, in this run, each in its own process:

- whole process: wall time of the command, interpreter start to exit;
- simulation alone: ``wall_time_s`` (Exudyn's ``SolveSystem``) of each.

    nice .venv/bin/python benchmarks/naive_baseline.py            # ~2 min (the baseline: ~100 s)
    nice .venv/bin/python benchmarks/naive_baseline.py --repeat 5
    nice .venv/bin/python benchmarks/naive_baseline.py --quick   # smoke run: baseline over 0.5 ms, fast Example 2, once

Targets: whole process ≥ 50×, simulation alone ≥ 150×.
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
EXAMPLE_2 = ROOT / "scenarios" / "paper_ex2_bend90.toml"
EXAMPLE_2_FAST = ROOT / "scenarios" / "fast" / "paper_ex2_bend90.toml"

# the naive model's departures from the scenario file, as dotted scenario keys
NAIVE_OVERRIDES = {
    "cable.elements": 40,
    "contact.check_points_per_element": 10,
    "contact.surface": "segments",          # the paper's straight segments
    "contact.broad_phase": "none",          # every segment for every check point
    "contact.damping_onset": 0.0,           # the paper's Eq. 18: C·δ̇ from first touch
    "solver.pretension": False,             # on the centreline, unloaded, at rest ...
    "pull.ramp_time": 0.05,                 # ... loads and speed ramped over 0.05 s
    "solver.startup_time": 0.0,
    "solver.end_time": 0.25,
    "solver.step": 1.0e-3,
    "solver.steady_stop": False,
}

_NAIVE_CHILD = r"""
import functools, json, sys, time, tomllib
sys.path.insert(0, {root!r})
import numpy as np
import exudyn as exu
import exucable.contact as contact
from exucable.scenario.specs import parse_scenario
from exucable.model.build import build_model
from exucable.model.recorder import History, record_state

# the numpy reference kernel (force and exact sparse Jacobian), not the compiled one
contact.ContactKernel = functools.partial(contact.ContactKernel, backend="numpy")
with open({path!r}, "rb") as f:
    data = tomllib.load(f)
for dotted, value in {overrides!r}.items():
    table, key = dotted.split(".", 1)
    data.setdefault(table, {{}})[key] = value
sc = parse_scenario(data, {parent!r}, default_name="naive-ex2")
model = build_model(sc)
s = exu.SimulationSettings()              # Exudyn's defaults: modified Newton, dense solver
ti = s.timeIntegration
ti.endTime = sc.solver.end_time_s
ti.numberOfSteps = max(1, int(round(sc.solver.end_time_s / sc.solver.step_s)))   # steps <= 1e-3 s
ti.adaptiveStep = True
ti.verboseMode = 0
s.solution.file.write = False
s.solution.sensors.active = False
s.show.computationTime = False
s.show.statistics = False
solver = exu.MainSolverImplicitSecondOrder()
t0 = time.perf_counter()
ok = solver.SolveSystem(model.mbs, s)
wall = time.perf_counter() - t0
h = History()
record_state(model, float(solver.it.currentTime), h)
print("@@RESULT " + json.dumps(dict(ok=bool(ok), wall_time_s=wall, steps=int(solver.it.currentStepIndex),
      newton_iterations=int(solver.it.newtonStepsCount), end_time_s=float(solver.it.currentTime),
      pull_force_N=h.pull_force_N[-1])), flush=True)
"""


def run_naive(end_time_s: float | None = None) -> dict:
    """The naive model in a child process (``end_time_s`` [s] overrides its simulated time)."""
    overrides = dict(NAIVE_OVERRIDES, **({} if end_time_s is None else {"solver.end_time": end_time_s}))
    code = _NAIVE_CHILD.format(root=str(ROOT), path=str(EXAMPLE_2), overrides=overrides,
                               parent=str(EXAMPLE_2.parent))
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    whole = time.perf_counter() - t0
    line = [ln for ln in out.stdout.splitlines() if ln.startswith("@@RESULT ")]
    if out.returncode != 0 or not line:
        raise RuntimeError(f"naive baseline failed:\n{out.stderr[-3000:]}")
    r = json.loads(line[0][9:])
    r["whole_process_s"] = whole
    return r


def run_exucable(out_dir: Path, scenario: Path = EXAMPLE_2) -> dict:
    exe = Path(sys.executable).with_name("exucable")
    t0 = time.perf_counter()
    out = subprocess.run([str(exe), "run", str(scenario), "--out", str(out_dir), "--quiet", "--no-plots"],
                         capture_output=True, text=True)
    whole = time.perf_counter() - t0
    if out.returncode != 0:
        raise RuntimeError(f"exucable run failed:\n{out.stderr[-3000:]}")
    s = json.loads((out_dir / "summary.json").read_text())
    return {"whole_process_s": whole, "wall_time_s": s["wall_time_s"], "steps": s["steps"],
            "newton_iterations": s["newton_iterations"], "end_time_s": s["simulated_time_s"],
            "pull_force_N": s["pull_force_N"]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=3, help="exucable runs (median taken) [3]")
    ap.add_argument("--quick", action="store_true",
                    help="smoke run: the baseline over 0.5 ms, the fast Example 2, one exucable run before and after "
                         "(the ratios then compare unequal runs: they only show that the code path works)")
    args = ap.parse_args(argv)
    if args.quick:
        args.repeat = 1
    scenario = EXAMPLE_2_FAST if args.quick else EXAMPLE_2
    load = os.getloadavg()[0]
    print(f"# exucable vs the naive Exudyn baseline (paper Example 2{', smoke run' if args.quick else ''}), "
          f"load average {load:.1f} on {os.cpu_count()} cores\n", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        ours = [run_exucable(Path(tmp) / f"run{i}", scenario) for i in range(args.repeat)]
        naive = run_naive(5e-4 if args.quick else None)
        ours += [run_exucable(Path(tmp) / f"run{i}", scenario) for i in range(args.repeat, 2 * args.repeat)]
    whole = statistics.median(r["whole_process_s"] for r in ours)
    sim = statistics.median(r["wall_time_s"] for r in ours)
    o = ours[0]
    print("| | whole process [s] | simulation [s] | simulated [s] | steps | Newton its | pulling force [N] |")
    print("|---|---|---|---|---|---|---|")
    print(f"| naive Exudyn (40 × 10, numpy kernel) | {naive['whole_process_s']:.1f} | {naive['wall_time_s']:.1f} | "
          f"{naive['end_time_s']:.3g} | {naive['steps']} | {naive['newton_iterations']} | {naive['pull_force_N']:.2f} |")
    mesh = "fast variant" if args.quick else "40 × 200"
    print(f"| exucable run ({mesh}), median of {len(ours)} | {whole:.2f} | {sim:.2f} | {o['end_time_s']:.3g} | "
          f"{o['steps']} | {o['newton_iterations']} | {o['pull_force_N']:.2f} |")
    wholes = ", ".join(f"{r['whole_process_s']:.2f}" for r in ours)
    sims = ", ".join(f"{r['wall_time_s']:.2f}" for r in ours)
    print(f"\nexucable runs: whole process {wholes} s; simulation {sims} s (before and after the baseline)")
    if args.quick:
        print("\nsmoke run: the two rows simulate different times; the ratios below only show the code path works")
    print(f"\nratio, whole process: {naive['whole_process_s'] / whole:.0f}x (target >= 50x)")
    print(f"ratio, simulation alone: {naive['wall_time_s'] / sim:.0f}x (target >= 150x)")
    print(f"capstan reference T1 = 205.37 N; load average now {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
