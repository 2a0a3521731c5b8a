"""Fixed cost of ``exucable run`` (issue 15, part 3), measured in one run.

A trivial scenario (the fast Example 2 over one 1 ms step) is run as a whole process, with and
without figures, interleaved with ``python -c "import exudyn"`` (the floor: interpreter + Exudyn),
``--repeat`` times each; medians are compared. Then one ``-X importtime`` run says which imports
the rest is made of.

    nice .venv/bin/python benchmarks/fixed_cost.py             # ~30 s
    nice .venv/bin/python benchmarks/fixed_cost.py --repeat 9

Target: ``exucable run --no-plots`` within 0.6 s of ``import exudyn``.
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


def trivial_scenario(directory: Path) -> Path:
    """The fast Example 2 cut to one step of 1 ms."""
    text = (ROOT / "scenarios" / "fast" / "paper_ex2_bend90.toml").read_text()
    text = re.sub(r"(?m)^end_time = .*$", "end_time = 0.001", text)
    text = re.sub(r"(?m)^step = .*$", "step = 1.0e-3", text)
    text = re.sub(r'(?m)^name = .*$', 'name = "trivial"', text)
    path = directory / "trivial.toml"
    path.write_text(text)
    return path


def timed(cmd, out_dir: Path | None = None) -> float:
    """Whole-process wall time [s] of ``cmd``. A run of 1 ms cannot be steady: ``exucable run``
    then exits 1 with status ``not_steady`` (the trust flags), which is accepted here, checked in
    ``out_dir/summary.json``; any other failure raises."""
    t0 = time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if out.returncode != 0:
        summary = out_dir / "summary.json" if out_dir is not None else None
        status = json.loads(summary.read_text()).get("status") if summary and summary.exists() else None
        if status != "not_steady":
            raise RuntimeError(f"{' '.join(map(str, cmd))} failed (status {status}):\n{out.stderr[-2000:]}")
    return dt


def top_imports(cmd, n=8):
    """The slowest top-level imports (cumulative) of one ``-X importtime`` run."""
    out = subprocess.run([sys.executable, "-X", "importtime", *cmd], capture_output=True, text=True)
    rows = []
    for line in out.stderr.splitlines():
        m = re.match(r"import time:\s+(\d+) \|\s+(\d+) \|( *)(\S+)", line)
        if m and len(m.group(3)) <= 1:          # top level only
            rows.append((int(m.group(2)) / 1e6, m.group(4)))
    return sorted(rows, reverse=True)[:n]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    exe = Path(sys.executable).with_name("exucable")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        sc = trivial_scenario(tmp)
        cases = {
            "python -c 'import exudyn'": [sys.executable, "-c", "import exudyn"],
            "exucable run --no-plots": [str(exe), "run", str(sc), "-o", str(tmp / "a"), "-q", "--no-plots"],
            "exucable run (figures)": [str(exe), "run", str(sc), "-o", str(tmp / "b"), "-q"],
        }
        outs = {"exucable run --no-plots": tmp / "a", "exucable run (figures)": tmp / "b"}
        timed(cases["exucable run --no-plots"], outs["exucable run --no-plots"])  # warm the disk and kernel caches
        times = {k: [] for k in cases}
        load0 = os.getloadavg()[0]
        for _ in range(args.repeat):
            for k, cmd in cases.items():
                times[k].append(timed(cmd, outs.get(k)))
        med = {k: statistics.median(v) for k, v in times.items()}
        floor = med["python -c 'import exudyn'"]
        print(f"# Fixed cost of exucable run — load average {load0:.1f} -> {os.getloadavg()[0]:.1f} "
              f"on {os.cpu_count()} cores, median of {args.repeat} interleaved runs\n")
        print("| command | median [s] | above import exudyn [s] | all runs [s] |\n|---|---|---|---|")
        for k, v in times.items():
            print(f"| {k} | {med[k]:.3f} | {med[k] - floor:+.3f} | {', '.join(f'{x:.2f}' for x in v)} |")
        print(f"\ntarget: exucable run --no-plots within 0.6 s of import exudyn: "
              f"{med['exucable run --no-plots'] - floor:.2f} s")
        print("\nslowest top-level imports of `exucable run --no-plots` (-X importtime, cumulative):\n")
        for seconds, name in top_imports(["-m", "exucable", *cases["exucable run --no-plots"][1:]]):
            print(f"- {name}: {seconds:.3f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
