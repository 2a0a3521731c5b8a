"""The default path's answer and its error bar against the mesh-converged value, and its wall time.

Each scenario is run as a user runs it, with no solver keys of its own (its ``[solver]`` table is
dropped, so ``solver.mode = "auto"`` picks steady mode and the mesh rule the mesh): the pulling force
F with its stated uncertainty u (``pull_force_uncertainty_N``, a second solve on the rule's mesh;
``exucable.solve.error_bar``). The converged value F∞ is Richardson's over the steady pulling force
(``exucable converge --mode steady``, elements and check-point spacing both refined by 2 per level)
from the rule's mesh (``--levels 3``: 1, 2 and 4 times the rule's elements; the default solves on
the second, whose value the converge level must repeat) or with ``--finer`` from the default's
(2, 4 and 8 times: Gera's route fails at 8x, 4064 elements, and is then left out of F∞), with its
own error estimate; only trusted levels enter it. A row passes when every level is trusted,
|F − F∞| ≤ u and u ≤ 0.3 % of F.

The whole process (``python -m exucable run FILE --out DIR``: import, scenario, both solves,
post-processing, result files and figures) is timed in a subprocess, the median of ``--repeat``:
wall time, and the child's CPU time (user + system), which a loaded machine does not stretch.

    nice .venv/bin/python benchmarks/steady_error_bar.py                      # every case (minutes)
    nice .venv/bin/python benchmarks/steady_error_bar.py --only downbend --levels 4
    nice .venv/bin/python benchmarks/steady_error_bar.py --no-converge        # wall times and u only

Prints a Markdown table (``--json FILE`` keeps the rows).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

CASES = [
    "studies/downbend60_gravity.toml", "studies/upbend60_gravity.toml", "studies/hbend90_r3.toml",
    "studies/sbend_horizontal.toml", "studies/sroute_3d.toml", "studies/route100_c2mm.toml",
    "studies/route100_4bends.toml",
    "industry/commscope_conquest_500ft_bend90.toml", "industry/commscope_conquest_run_a_h.toml",
    "industry/gera_wire_pulling_example.toml", "industry/machinecalcs_two_bends.toml",
]


def user_scenario(path: Path, tmp: Path) -> Path:
    """The scenario as a user without solver keys has it: its [solver] table and mesh overrides
    (``cable.elements``, ``cable.element_length``, ``contact.check_points_per_element``) dropped."""
    keep, in_solver = [], False
    for line in path.read_text().splitlines():
        head = line.strip()
        if head.startswith("["):
            in_solver = head == "[solver]"
        if in_solver or head.split("=")[0].strip() in ("elements", "element_length", "check_points_per_element"):
            continue
        keep.append(line)
    out = tmp / path.name
    out.write_text("\n".join(keep) + "\n")
    return out


def whole_process_s(path: Path, out: Path, repeat: int) -> tuple[float, list[float], float]:
    """Median wall time [s] of ``exucable run`` in a subprocess, each run's, and the median CPU time
    (user + system of the child) [s], which the machine's other jobs do not stretch."""
    times, cpus = [], []
    for _ in range(repeat):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "exucable", "run", str(path), "--out", str(out), "--quiet"],
                              capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(ROOT)))
        times.append(time.perf_counter() - t0)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
        if proc.returncode not in (0, 1):
            raise RuntimeError(f"{path.name}: exucable run exited {proc.returncode}: {proc.stderr.strip()}")
    return statistics.median(times), times, statistics.median(cpus)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", action="append", help="cases whose file name contains this (repeatable)")
    ap.add_argument("--levels", type=int, default=3, help="converge levels finer than the default (>= 3)")
    ap.add_argument("--repeat", type=int, default=1, help="whole-process runs per case (median)")
    ap.add_argument("--no-converge", action="store_true", help="skip the converged values")
    ap.add_argument("--finer", action="store_true", help="converge levels from the default's mesh, not the rule's")
    ap.add_argument("--json", type=Path, help="write the rows here")
    ap.add_argument("--quick", action="store_true", help="one study route, no converged value (a smoke run)")
    args = ap.parse_args(argv)
    if args.quick:
        args.only, args.no_converge = ["hbend90"], True
    from exucable.commands.converge import converge
    from exucable.scenario.specs import load_scenario

    cases = [c for c in CASES if not args.only or any(o in c for o in args.only)]
    print(f"load average at start: {os.getloadavg()[0]:.1f}")
    print("| case | elements (coarse) | F [N] | u [N] (u/F) | F∞ [N] ± err (order) | F − F∞ | |F − F∞|/u | "
          "within u | levels [N] (status) | whole process wall / CPU [s] | status |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    with tempfile.TemporaryDirectory() as tmpdir:
        tmp = Path(tmpdir)
        for case in cases:
            path = user_scenario(ROOT / "scenarios" / case, tmp)
            wall, walls, cpu = whole_process_s(path, tmp / "run", args.repeat)
            s = json.loads((tmp / "run" / "summary.json").read_text())
            F, u = s["pull_force_N"], s["pull_force_uncertainty_N"]
            row = {"case": case, "mode": s["mode"], "status": s["status"], "pull_force_N": F,
                   "uncertainty_N": u, "elements": s["mesh"]["elements"],
                   "coarse_elements": (s.get("pull_force_uncertainty") or {}).get("coarse_elements"),
                   "whole_process_s": wall, "whole_process_runs_s": walls, "whole_process_cpu_s": cpu}
            conv = ""
            if not args.no_converge:
                sc = load_scenario(path)
                if not args.finer and row["coarse_elements"]:
                    # from the rule's mesh: the default's solve is converge's level 1 (same elements and
                    # check points per element)
                    sc = sc.replace(**{"cable.elements": int(row["coarse_elements"]),
                                       "contact.check_points_per_element": int(s["mesh"]["check_points_per_element"])})
                # from the default's mesh: converge on the rule adds steady mode's refinement, so its
                # levels start at the default's mesh
                rep = converge(sc, tmp / "conv", levels=args.levels, ratio=2.0, mode="steady")
                ext, err = rep.get("extrapolated_N"), rep.get("error_N")
                levels = " / ".join(f"{r['value_N']:.6g} ({r['elements']}{'' if r['status'] in ('ok', 'steady') else ', ' + r['status']})"
                                    for r in rep["levels"])
                row.update(converged_N=ext, converged_error_N=err, observed_order=rep.get("observed_order"),
                           levels_N=[r["value_N"] for r in rep["levels"]], levels_status=[r["status"] for r in rep["levels"]],
                           levels_elements=[r["elements"] for r in rep["levels"]], converge_method=rep.get("method"),
                           levels_trusted=rep["trusted"])
                if ext is not None and u:
                    row["within"] = abs(F - ext) <= u
                    row["error_in_u"] = abs(F - ext) / u
                    conv = (f"{ext:.6g} ± {err:.2g} ({rep.get('observed_order') or float('nan'):.2g}) | "
                            f"{F - ext:+.3g} ({100 * (F / ext - 1):+.3f} %) | {row['error_in_u']:.2f} | "
                            f"{'yes' if row['within'] else 'NO'} | {levels}")
                else:
                    conv = f"– ({rep.get('method')}) | – | – | – | {levels}"
            else:
                conv = "– | – | – | – | –"
            rows.append(row)
            u_text = f"{u:.3g} ({100 * u / F:.3f} %)" if u is not None else "none"
            print(f"| {Path(case).stem} | {row['elements']} ({row['coarse_elements']}) | {F:.6g} | "
                  f"{u_text} | {conv} | {wall:.2f} / {cpu:.2f} | {s['status']} ({s['mode']}) |", flush=True)
    print(f"load average at end: {os.getloadavg()[0]:.1f}")
    if args.json:
        from exucable.io import atomic_write_text
        atomic_write_text(args.json, json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
