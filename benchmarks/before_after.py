"""Issue 15's solver changes, switched off and on, side by side in one run.

"before" is the code of another revision (default: main 04e3b65, as this session found it:
Newton tolerance 1e-7, contact damping onset 10 µm, the first step at the scenario's full step),
extracted with ``git archive`` into a temporary directory and run with this environment's
packages; "after" is this working tree. Each run is a whole ``exucable run --no-plots`` process
of a paper example at its fidelity (to a steady pulling force), alternating before/after
``--repeat`` times; medians and their ratio are printed, with the results and their difference.

    nice .venv/bin/python benchmarks/before_after.py                 # Examples 3 and 4, ~2 min
    nice .venv/bin/python benchmarks/before_after.py --repeat 3 --examples 2 3 4 --before-rev 04e3b65
"""

from __future__ import annotations

import argparse
import io
import json
import os
import statistics
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = {1: "paper_ex1_incline.toml", 2: "paper_ex2_bend90.toml", 3: "paper_ex3_helix.toml",
            4: "paper_ex4_spatial.toml"}


def extract(rev: str, directory: Path) -> Path:
    """The tree of git revision ``rev`` of this repository, written under ``directory``."""
    data = subprocess.run(["git", "-C", str(ROOT), "archive", rev], capture_output=True, check=True).stdout
    tree = directory / f"tree-{rev}"
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        tar.extractall(tree, filter="data")
    return tree


def run(tree: Path, scenario: Path, out: Path) -> dict:
    """One whole ``python -m exucable run`` process of the code in ``tree``."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    cmd = [sys.executable, "-m", "exucable", "run", str(scenario), "--out", str(out), "--quiet", "--no-plots"]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=tree)
    whole = time.perf_counter() - t0
    s_path = out / "summary.json"
    if not s_path.exists():
        raise RuntimeError(f"{tree.name} {scenario.name} failed:\n{p.stderr[-2000:]}")
    s = json.loads(s_path.read_text())
    if s["status"] not in ("ok", "steady"):
        raise RuntimeError(f"{tree.name} {scenario.name}: status {s['status']}\n{p.stderr[-2000:]}")
    key = s["steady_quantity"]
    return {"whole_s": whole, "solve_s": s["wall_time_s"], "steps": s["steps"], "newton": s["newton_iterations"],
            "kernel_s": s["kernel_time_s"], "result_N": s[key], "quantity": key}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--examples", type=int, nargs="+", default=[3, 4], choices=sorted(EXAMPLES))
    ap.add_argument("--before-rev", default="04e3b65", help="git revision of \"before\"")
    args = ap.parse_args(argv)
    print(f"# Before ({args.before_rev}) / after (this tree) — load average {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores, median of {args.repeat} alternating run(s)\n")
    print("| example | variant | whole process [s] | solve [s] | steps | Newton its | its/step | kernel [s] | result [N] |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        trees = {"before": extract(args.before_rev, Path(tmp)), "after": ROOT}
        for tree in trees.values():   # warm the numba caches and the disk
            run(tree, ROOT / "scenarios" / "fast" / EXAMPLES[2], Path(tmp) / f"warm-{tree.name}")
        for ex in args.examples:
            sc = ROOT / "scenarios" / EXAMPLES[ex]
            res = {"before": [], "after": []}
            for i in range(args.repeat):
                for v in ("before", "after"):
                    res[v].append(run(trees[v], sc, Path(tmp) / f"{ex}-{v}-{i}"))
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
