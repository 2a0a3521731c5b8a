"""``exucable run``: simulate one scenario and write its results."""

from __future__ import annotations

import contextlib
import sys
from pathlib import Path

import numpy as np

from ..output.figure_process import Figures
from ..output.outdir import default_out_dir
from ..run import run_scenario
from .compile import announce_compiling
from ..scenario.specs import load_scenario
from ..post.trust import TRUSTED_STATUSES

__all__ = ["add_arguments", "main"]


def add_arguments(p) -> None:
    p.add_argument("scenario", help="scenario file (TOML), or a shipped scenario's name "
                                    "(`exucable scenarios` lists them)")
    p.add_argument("--out", "-o", default=None, help="result directory, this run's alone: an earlier run's result files in it are replaced "
                        "(default: out/<scenario name>, the name made safe as a directory name)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG figures")
    p.add_argument("--mode", choices=("dynamic", "steady"), default=None,
                   help="dynamic time integration or one static solve of steady sliding "
                        "(overrides solver.mode)")
    p.add_argument("--steady-stop", dest="steady_stop", action="store_true", default=None,
                   help="stop once the pulling force is steady (overrides solver.steady_stop)")
    p.add_argument("--no-steady-stop", dest="steady_stop", action="store_false",
                   help="run to solver.end_time whatever the pulling force does")


def _f(value, fmt=".6g") -> str:
    return "n/a" if value is None or not np.isfinite(value) else format(value, fmt)


def _versus(got: float, ref: float) -> str:
    """``got`` against ``ref`` in per cent, or in newtons where the reference is zero (no load: a
    relative difference does not exist)."""
    if ref != 0.0 and np.isfinite(ref):
        return f"{100 * (got / ref - 1):+.3f} %"
    return f"{got - ref:+.3g} N"


def main(args) -> int:
    from ..scenario.units import display_unit, from_si

    sc = load_scenario(args.scenario)
    out_dir = Path(args.out) if args.out else default_out_dir(sc.name)
    # the figures' helper is forked now, before anything loads Exudyn or numba: it imports matplotlib
    # on the other core while this process imports, builds and solves
    with contextlib.nullcontext(False) if args.no_plots else Figures() as figures:
        announce_compiling()
        res = run_scenario(sc, out_dir, quiet=args.quiet, plots=figures, steady_stop=args.steady_stop,
                           mode=args.mode)
    s = res.summary
    if "bundle" in s:
        return _print_bundle(s, out_dir)
    # the printout in the scenario's display units (the files stay SI)
    system = sc.display.units
    N = display_unit("force", system)
    per_s = f"{N}/s"

    def force(key):
        v = s.get(key)
        return None if v is None else from_si(v, "force", system)

    rope = force("rope_pull_force_N")
    if s.get("mode") == "steady":
        # no scatter, no drift: the error bar is the mesh's and the solve's (summary: pull_force_uncertainty)
        spread = f"± {_f(force('pull_force_uncertainty_N'), '.2g')} {N}: mesh and solve tolerance"
        wall = (s.get("pull_force_uncertainty") or {}).get("wall_N")
        if wall and s.get("pull_force_uncertainty_N") and wall > 0.1 * s["pull_force_uncertainty_N"]:
            # the part that says how much higher the pull is against a rigid wall, named when it counts
            spread = spread.replace(": mesh and", ": mesh,") + f" and the wall's compliance {_f(from_si(wall, 'force', system), '.2g')} {N}"
    else:
        spread = (f"± {_f(force('pull_force_uncertainty_N'), '.2g')} {N}, sd {_f(force('pull_force_std_N'), '.2g')} "
                  f"{N}, drift {_f(force('pull_force_drift_N_per_s'), '.2g')} {per_s}")
    print(f"{sc.name}: status {s['status']}, pulling force {_f(force('pull_force_N'))} {N} ({spread}), trailing "
          f"tension {_f(force('trailing_tension_N'))} {N}, max tension {_f(force('max_tension_N'))} {N}")
    if s["steady_quantity"] == "trailing_tension_N":     # force-controlled: T2 is the result
        ref, got, what = force("rope_trailing_tension_N"), force("trailing_tension_N"), "trailing tension"
    else:
        ref, got, what = rope, force("pull_force_N"), "pulling force"
    if ref is not None and got is not None and np.isfinite(got):
        print(f"  rope reference: {what} {ref:.6g} {N} ({_versus(got, ref)})")
    ref_c = force("rope_clearance_pull_force_N")
    if what == "pulling force" and ref_c is not None and got is not None and np.isfinite(got):
        print(f"  rope with clearance: pulling force {ref_c:.6g} {N} ({_versus(got, ref_c)})")
    if s.get("mode") == "steady":
        print(f"  steady mode ({s['mode_rule']}): {s['message']}: {s['steps']} solves, "
              f"{s['newton_iterations']} Newton iterations, wall {s['wall_time_s']:.2f} s")
    else:
        print(f"  steady from {_f(s['steady_from_s'], '.4g')} s: {s['steady']}; {s['steps']} steps, "
              f"{s['newton_iterations']} Newton iterations, wall {s['wall_time_s']:.2f} s")
    print(f"  results in {out_dir}/" + (f" (SI: N, m; printed here in {system} units)" if system != "si" else ""))
    m = s.get("mesh") or {}
    if m:
        ln = display_unit("length", system)
        refined = f", refined {m['steady_refine']:g}x for steady mode" if m.get("steady_refine", 1.0) != 1.0 else ""
        print(f"  mesh: {m['elements']} elements of {from_si(m['element_length_m'], 'length', system):.4g} {ln} "
              f"({m['source']}; rule {from_si(m['rule_element_length_m'], 'length', system):.4g} {ln}{refined}), "
              f"{m['check_points_per_element']} check points per element")
    for w in s.get("warnings", []):
        print(f"  warning: {w}", file=sys.stderr)
    if s["status"] == "failed":
        print(f"  FAILED: {s['message']} (at t = {_f(s.get('failed_at_s'))} s); "
              f"the results recorded until then are in {out_dir}/", file=sys.stderr)
        return 1
    if s["status"] not in TRUSTED_STATUSES:
        for f in s["flags"]:
            print(f"  NOT TRUSTED ({f['flag']}): {f['message']}", file=sys.stderr)
        print(f"  status {s['status']}: do not use this result; what was computed is in {out_dir}/", file=sys.stderr)
        return 1
    return 0


def _print_bundle(s: dict, out_dir: Path) -> int:
    """The report of a run of several cables (``cable.count`` > 1); exit status as for one cable."""
    b = s["bundle"]
    wcf = b["weight_correction_factor"]
    u = s.get("pull_force_uncertainty_N")
    if s["mode"] == "steady" and u is not None:
        parts = s.get("pull_force_uncertainty") or {}
        # the mesh part only where the budget left had room for the coarse solve: say when it is missing
        spread = (f" (± {_f(u, '.2g')} N: mesh and solve tolerance)" if parts.get("mesh_N") is not None
                  else f" (± {_f(u, '.2g')} N: solve tolerance only, mesh part not measured)")
    else:
        spread = ""
    from ..post.bundle import laid_phrase

    laid = laid_phrase(b) + (f" (formulas: {b['arrangement']})" if b.get("positions_given") else "")
    print(f"{s['name']}: status {s['status']}, {b['count']} cables {laid}, pulling force "
          f"{_f(s['pull_force_N'])} N{spread}, back tension {_f(s['trailing_tension_N'])} N, max tension {_f(s['max_tension_N'])} N")
    print(f"  weight correction factor {_f(wcf, '.5g')} (the calculators' {b['formula_weight_correction_factor']:.5g})")
    for st in b["straights"]:
        print(f"  straight {st['s_conduit_start_m']:.4g}-{st['s_conduit_end_m']:.4g} m: weight correction "
              f"{_f(st['weight_correction_factor'], '.5g')}")
    for row in b.get("sections", []):
        seen = ", ".join(f"{k} {v}" for k, v in row["arrangements_seen"].items())
        jam = f"  JAM at s = {row['jam_s_conduit_m']:.4g} m" if row["jam"] else ""
        print(f"  {row['kind']} {row['section']} ({row['s_conduit_start_m']:.4g}-{row['s_conduit_end_m']:.4g} m): "
              f"{row['arrangement']} (stations: {seen}){jam}")
    for row in b.get("bends", []):
        print(f"  bend {row['bend']}: sidewall pressure on cable {row['most_loaded_cable']} {_f(row['peak_pressure_N_per_m'], '.4g')} "
              f"N/m (the calculators' {row['formula_pressure_N_per_m']:.4g} N/m at T_out {row['tension_out_N']:.4g} N)")
    for c in b["cables"]:
        share = None if c["pull_share"] is None else 100.0 * c["pull_share"]
        print(f"  cable {c['cable']}: pull {_f(c['pull_share_N'])} N ({_f(share, '.3g')} %), "
              f"wall {_f(c['wall_normal_force_N'], '.4g')} N, other cables {_f(c['cable_contact_force_N'], '.4g')} N")
    if s["mode"] == "dynamic":
        u = s.get("pull_force_uncertainty_N")
        print(f"  time integration to t = {_f(s['simulated_time_s'], '.4g')} s, "
              f"{'steady from ' + _f(s['steady_from_s'], '.4g') + ' s' if s['steady'] else 'not steady'}, "
              f"pulling force uncertainty {_f(u, '.3g')} N: {s['steps']} steps, "
              f"{s['newton_iterations']} Newton iterations, wall {s['wall_time_s']:.2f} s")
    else:
        print(f"  steady sliding, one static solve ({s['message']}): {s['steps']} solves, "
              f"{s['newton_iterations']} Newton iterations, wall {s['wall_time_s']:.2f} s")
    print(f"  results in {out_dir}/")
    for w in s.get("warnings", []):
        print(f"  warning: {w}", file=sys.stderr)
    if s["status"] == "failed":
        print(f"  FAILED: {s['message']}", file=sys.stderr)
        return 1
    if s["status"] not in TRUSTED_STATUSES:
        for f in s["flags"]:
            print(f"  NOT TRUSTED ({f['flag']}): {f['message']}", file=sys.stderr)
        return 1
    return 0
