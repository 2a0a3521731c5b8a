"""Ahead-of-time against JIT contact kernels (issue 15, fixed cost), measured in one run.

Runs ``exucable run --no-plots`` of the given scenarios (default: paper Example 4, dynamic and
steady) as whole processes, alternately with the ahead-of-time kernels (``exucable compile``, built
first if missing) and with the JIT kernels forced (``EXUCABLE_KERNELS=jit``), ``--repeat`` times
each; prints the medians of wall and CPU time (user + system, less disturbed by the other jobs on a
shared machine), their ratio AOT/JIT, and whether the two paths wrote the same pulling force, Newton
iterations and force history (they should, bit for bit). Then one contact-kernel evaluation with
Jacobians at Example 4's size (``benchmarks/contact_kernel.py``'s case: 100 elements × 800 check
points), alternately through the AOT and the JIT kernels in this process: median and minimum of
batches of five, and their ratio — the kernels' own speed, without the processes' start-up.

    nice .venv/bin/python benchmarks/kernels_aot_jit.py --repeat 3
    nice .venv/bin/python benchmarks/kernels_aot_jit.py scenarios/fast/paper_ex2_bend90.toml:dynamic
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ["scenarios/paper_ex4_spatial.toml:dynamic", "scenarios/paper_ex4_spatial.toml:steady"]


def run(exe: Path, scenario: str, mode: str, out: Path, kernels: str) -> dict:
    """One whole process; its wall and CPU time [s] and what it wrote."""
    env = {k: v for k, v in os.environ.items() if k != "EXUCABLE_KERNELS"}
    if kernels == "jit":
        env["EXUCABLE_KERNELS"] = "jit"
    cmd = [str(exe), "run", str(ROOT / scenario), "--mode", mode, "-o", str(out), "-q", "--no-plots"]
    c0, t0 = os.times(), time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, env=env)
    wall, c1 = time.perf_counter() - t0, os.times()
    summary = json.loads((out / "summary.json").read_text()) if (out / "summary.json").exists() else {}
    if done.returncode != 0 and summary.get("status") not in ("not_steady",):
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{done.stderr[-2000:]}")
    history = out / "history.csv"
    return {"wall": wall, "cpu": (c1.children_user - c0.children_user) + (c1.children_system - c0.children_system),
            "force": summary.get("pull_force_N"), "newton": summary.get("newton_iterations"),
            "history": hashlib.sha256(history.read_bytes()).hexdigest() if history.exists() else None}


def _set_kernels(kernels: str) -> None:
    """Route this process's next kernel calls to the AOT ("aot") or the JIT ("jit") kernels."""
    from exucable.contact import aot

    if kernels == "jit":
        os.environ["EXUCABLE_KERNELS"] = "jit"
    else:
        os.environ.pop("EXUCABLE_KERNELS", None)
    aot.reset()


def per_evaluation(batches: int) -> str:
    """One evaluation (force + Jacobians) at Example 4's size through each path, interleaved."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import numpy as np

    import contact_kernel as case
    from exucable.contact import ContactKernel, ContactLaw, aot

    verts, s_verts, at, total = case.route()
    q, q_t, length = case.cable_state(at, total, np.random.default_rng(4))
    law = ContactLaw(stiffness=1e6, damping=1e3, exponent=1.5, friction=0.3, damping_onset_m=0.0)
    kernel = ContactKernel(case.Segments(verts, s_verts, case.R_CONDUIT), length, case.R_CABLE, law,
                           case.CHECK_POINTS, n_elements=case.N_ELEMENTS, backend="numba")
    times = {"aot": [], "jit": []}
    saved = os.environ.get("EXUCABLE_KERNELS")
    try:
        for _ in range(batches):
            for kernels in times:
                _set_kernels(kernels)
                kernel.evaluate(q, q_t, jacobian=True)      # looks the module up again: not timed
                t0 = time.perf_counter()
                for _ in range(5):
                    kernel.evaluate(q, q_t, jacobian=True)
                times[kernels].append((time.perf_counter() - t0) / 5)
    finally:
        _set_kernels("jit" if saved == "jit" else "aot")
    med = {k: statistics.median(v) for k, v in times.items()}
    return (f"contact kernel + Jacobians at Example 4's size ({case.N_ELEMENTS} x {case.CHECK_POINTS} points), "
            f"median of {batches} batches of 5: AOT {1e3 * med['aot']:.3f} ms (min {1e3 * min(times['aot']):.3f}), "
            f"JIT {1e3 * med['jit']:.3f} ms (min {1e3 * min(times['jit']):.3f}); AOT/JIT {med['aot'] / med['jit']:.3f}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("cases", nargs="*", default=DEFAULT, help="scenario:mode pairs (default: Example 4 both modes)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--batches", type=int, default=30, help="interleaved batches of the per-evaluation timing")
    args = ap.parse_args(argv)
    exe = Path(sys.executable).with_name("exucable")
    subprocess.run([str(exe), "compile", "--quiet"], check=False)
    check = subprocess.run([str(exe), "compile", "--check"], capture_output=True, text=True,
                           env={k: v for k, v in os.environ.items() if k != "EXUCABLE_KERNELS"})
    print(f"ahead-of-time kernels: {check.stdout.strip()}")
    load0 = os.getloadavg()[0]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for case in args.cases:
            scenario, _, mode = case.partition(":")
            mode = mode or "dynamic"
            results = {"aot": [], "jit": []}
            for i in range(args.repeat):
                for kernels in ("aot", "jit"):
                    results[kernels].append(run(exe, scenario, mode, Path(tmp) / f"{kernels}{i}", kernels))
            rows.append((f"{scenario} {mode}", results))
    print(f"\n# AOT vs JIT kernels, whole process — load average {load0:.1f} -> {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores, median of {args.repeat} interleaved runs\n")
    print("| case | AOT wall [s] | JIT wall [s] | AOT/JIT wall | AOT CPU [s] | JIT CPU [s] | AOT/JIT CPU "
          "| same force, Newton iterations, history |\n|---|---|---|---|---|---|---|---|")
    for name, results in rows:
        med = {k: (statistics.median(r["wall"] for r in v), statistics.median(r["cpu"] for r in v))
               for k, v in results.items()}
        outcomes = {(r["force"], r["newton"], r["history"]) for v in results.values() for r in v}
        print(f"| {name} | {med['aot'][0]:.2f} | {med['jit'][0]:.2f} | {med['aot'][0] / med['jit'][0]:.2f} | "
              f"{med['aot'][1]:.2f} | {med['jit'][1]:.2f} | {med['aot'][1] / med['jit'][1]:.2f} | "
              f"{'yes' if len(outcomes) == 1 else 'NO: ' + repr(outcomes)} |")
    print("\n" + per_evaluation(args.batches))
    return 0


if __name__ == "__main__":
    sys.exit(main())
