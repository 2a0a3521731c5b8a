"""``exucable converge SCENARIO [--levels N] [--ratio R] [--out DIR]``: the scenario's result on
N ≥ 3 meshes, each refined by R in element length (and in check-point spacing: the check points
per element stay those of the first level), with the observed order and an extrapolated value
with its error estimate (:mod:`exucable.post.convergence`).

Writes ``DIR/level_K/`` (each a complete result directory), then ``DIR/converge.csv`` (one row
per level) and ``DIR/converge.json`` (the table, the extrapolation and how it was made), each
atomically. Exits 1 when a level's result is not trusted (its status names why) or failed.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from ..post.convergence import extrapolate
from ..io import write_csv, write_json
from ..output.outdir import check_out_dir, default_out_dir
from ..run import run_scenario
from ..scenario.specs import load_scenario
from ..post.trust import TRUSTED_STATUSES

__all__ = ["add_arguments", "main", "converge", "CONVERGE_COLUMNS"]

CONVERGE_COLUMNS = ("level", "refine", "elements", "element_length_m", "check_points_per_element", "value_N",
                    "uncertainty_N", "drift_N_per_s", "wall_time_s")


# levels of refinement: 8 at ratio 2 are 128x the first mesh's elements (the model's check-point
# bound, exucable.scenario.mesh.MAX_MODEL_CHECK_POINTS, refuses a level beyond memory)
MAX_LEVELS = 8


def converge(scenario, out_dir, levels: int = 3, ratio: float = 2.0, quiet: bool = True, progress=None,
             mode: str | None = None) -> dict:
    """Run ``scenario`` on ``levels`` meshes refined by ``ratio``; returns the report (also written).

    ``mode`` (``"dynamic"``/``"steady"``) overrides ``solver.mode`` at every level.

    The quantity is the run's steady quantity: the pulling force, or for a force-controlled pull
    the trailing tension [N]. ``progress(level, summary)`` is called after each level.
    """
    if not 3 <= levels <= MAX_LEVELS:
        raise ValueError(f"converge: 3 to {MAX_LEVELS} levels (an observed order needs three meshes; each level "
                         "multiplies the elements by the ratio)")
    sc = scenario if not isinstance(scenario, (str, Path)) else load_scenario(scenario)
    out = Path(out_dir)
    rows, statuses = [], []
    k0 = None
    for level in range(levels):
        refine = ratio**level
        res = run_scenario(sc, out / f"level_{level}", quiet=quiet, plots=False, refine=refine,
                           check_points_per_element=k0, mode=mode, error_bar=False)
        s = res.summary
        mesh = s["mesh"]
        k0 = mesh["check_points_per_element"] if k0 is None else k0
        q = s["steady_quantity"]
        rows.append({"level": level, "refine": refine, "elements": mesh["elements"],
                     "element_length_m": mesh["element_length_m"],
                     "check_points_per_element": mesh["check_points_per_element"],
                     "value_N": s[q] if s[q] is not None else float("nan"),
                     "uncertainty_N": s["pull_force_uncertainty_N"] if q == "pull_force_N" else s.get("pull_force_std_N"),
                     "drift_N_per_s": s["pull_force_drift_N_per_s"], "wall_time_s": s["wall_time_s"],
                     "status": s["status"],
                     "bends": [{k: b[k] for k in ("bend", "mean_pressure_vs_rope", "entry_point_load_N",
                                                  "exit_point_load_N")} for b in s.get("bends", [])]})
        statuses.append(s["status"])
        if progress is not None:
            progress(level, s)
    report = {"name": sc.name, "quantity": q, "ratio": ratio, "mode": mode or sc.solver.mode, "levels": rows,
              "trusted": all(st in TRUSTED_STATUSES for st in statuses)}
    # only trusted levels enter the extrapolation: a failed solve's last iterate is not a value of
    # the sequence (it would be extrapolated as if it were, and look like a converged answer)
    used = [r for r in rows if r["status"] in TRUSTED_STATUSES]
    left_out = [r for r in rows if r["status"] not in TRUSTED_STATUSES]
    report["levels_used"] = [r["level"] for r in used]
    values = [r["value_N"] for r in used]
    try:
        if left_out:
            why = "; ".join(f"level {r['level']} ({r['elements']} elements) is {r['status']}" for r in left_out)
            if len(used) < 3 or used != rows[:len(used)]:
                raise ValueError(f"no extrapolation: {why}, and the trusted levels are not three consecutive "
                                 "from the first (fix: fewer --levels, or the failed level's message)")
        ex = extrapolate(values, ratio, [r["uncertainty_N"] for r in used])
        if left_out:
            ex = type(ex)(ex.value, ex.error, ex.order, f"{ex.method} (over levels 0-{len(used) - 1}: {why})")
        report.update(extrapolated_N=ex.value, error_N=ex.error, observed_order=ex.order, method=ex.method,
                      finest_vs_extrapolated=(values[-1] / ex.value - 1.0) if ex.value else None,
                      default_vs_extrapolated=(values[0] / ex.value - 1.0) if ex.value else None)
    except ValueError as exc:
        report.update(extrapolated_N=None, error_N=None, observed_order=None, method=str(exc))
    write_csv(out / "converge.csv", CONVERGE_COLUMNS, {c: [r[c] if r[c] is not None else np.nan for r in rows]
                                                       for c in CONVERGE_COLUMNS})
    write_json(out / "converge.json", report)
    return report


def add_arguments(p) -> None:
    p.add_argument("scenario", help="scenario file (TOML), or a shipped scenario's name "
                                    "(`exucable scenarios` lists them)")
    p.add_argument("--levels", type=int, default=3, help="number of meshes, at least 3 (default 3)")
    p.add_argument("--ratio", type=float, default=2.0, help="refinement ratio of the element length (default 2)")
    p.add_argument("--out", "-o", default=None, help="result directory (default: out/<scenario name>-converge)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bars")
    p.add_argument("--mode", choices=("dynamic", "steady"), default=None,
                   help="solve every level dynamically or as one static solve of steady sliding "
                        "(overrides solver.mode)")


def _f(v, fmt=".6g"):
    return "n/a" if v is None or not np.isfinite(v) else format(v, fmt)


def main(args) -> int:
    sc = load_scenario(args.scenario)
    if args.levels < 3:
        print("exucable converge: error: --levels: at least 3 (an observed order needs three meshes)", file=sys.stderr)
        return 2
    if args.levels > MAX_LEVELS:
        print(f"exucable converge: error: --levels: at most {MAX_LEVELS} (each level refines the mesh by --ratio: "
              f"{MAX_LEVELS} levels at ratio 2 are already {2 ** (MAX_LEVELS - 1)}x the elements), got {args.levels}",
              file=sys.stderr)
        return 2
    if not 1.0 < args.ratio <= 10.0:
        print(f"exucable converge: error: --ratio: must be > 1 and <= 10 (each level multiplies the elements by it), "
              f"got {args.ratio}", file=sys.stderr)
        return 2
    out = check_out_dir(Path(args.out) if args.out else default_out_dir(sc.name, suffix="-converge"))
    from .compile import announce_compiling

    announce_compiling()

    def progress(level, s):
        m = s["mesh"]
        print(f"  level {level}: {m['elements']} elements × {m['check_points_per_element']} check points: "
              f"{s['steady_quantity']} {_f(s[s['steady_quantity']])} N, status {s['status']}, "
              f"wall {s['wall_time_s']:.1f} s", flush=True)

    print(f"{sc.name}: {args.levels} levels, element length refined by {args.ratio:g} per level", flush=True)
    rep = converge(sc, out, args.levels, args.ratio, quiet=args.quiet, progress=progress, mode=args.mode)
    print(f"\n{'level':>5} {'elements':>8} {'h [m]':>9} {'points/el':>9} {rep['quantity']:>22} {'± [N]':>9} {'status':>10}")
    for r in rep["levels"]:
        print(f"{r['level']:>5} {r['elements']:>8} {r['element_length_m']:>9.4g} {r['check_points_per_element']:>9} "
              f"{_f(r['value_N'], '.8g'):>22} {_f(r['uncertainty_N'], '.2g'):>9} {r['status']:>10}")
    for i, b in enumerate(rep["levels"][0]["bends"]):
        cells = [(r["bends"][i]["mean_pressure_vs_rope"], r["bends"][i]["entry_point_load_N"],
                  r["bends"][i]["exit_point_load_N"]) for r in rep["levels"]]
        print(f"bend {b['bend']}: windowed pressure in the body vs the rope's T/R "
              + " / ".join(f"{100 * c[0]:+.2f} %" for c in cells) + "; point loads entry "
              + " / ".join(f"{c[1]:.3g}" for c in cells) + " N, exit " + " / ".join(f"{c[2]:.3g}" for c in cells)
              + " N (levels 0 …)")
    print(f"extrapolated: {_f(rep['extrapolated_N'], '.8g')} ± {_f(rep['error_N'], '.2g')} N "
          f"(observed order {_f(rep['observed_order'], '.3g')}; {rep['method']})")
    if rep.get("default_vs_extrapolated") is not None:
        print(f"level 0 (the default mesh) differs from it by {100 * rep['default_vs_extrapolated']:+.3f} %")
    print(f"results in {out}/ (converge.csv, converge.json, level_K/)")
    if not rep["trusted"]:
        print("exucable converge: a level's result is not trusted (see its status above and its summary.json)",
              file=sys.stderr)
        return 1
    return 0
