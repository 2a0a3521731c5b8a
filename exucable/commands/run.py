"""``exucable run``: simulate one scenario and write its results."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from ..run import run_scenario
from ..scenario.specs import load_scenario
from ..post.trust import TRUSTED_STATUSES

__all__ = ["add_arguments", "main"]


def add_arguments(p) -> None:
    p.add_argument("scenario", help="scenario file (TOML)")
    p.add_argument("--out", "-o", default=None, help="result directory (default: out/<scenario name>)")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress bar")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG figures")
    p.add_argument("--mode", choices=("dynamic", "steady"), default=None,
                   help="dynamic time integration or one static solve of steady sliding "
                        "(overrides solver.mode)")
    p.add_argument("--steady-stop", dest="steady_stop", action="store_true", default=None,
                   help="stop once the pulling force is steady (overrides solver.steady_stop)")
    p.add_argument("--no-steady-stop", dest="steady_stop", action="store_false",
                   help="run to solver.end_time whatever the pulling force does")


def _used_jit_kernels_without_need() -> bool:
    """Whether this process ran numba's JIT kernels only because no ahead-of-time module is built
    (not when ``EXUCABLE_KERNELS=jit`` asked for them)."""
    if "numba" not in sys.modules:
        return False
    from ..contact import aot

    state = aot.status()
    return not state["valid"] and not state["forced_jit"]


def _f(value, fmt=".6g") -> str:
    return "n/a" if value is None or not np.isfinite(value) else format(value, fmt)


def main(args) -> int:
    sc = load_scenario(args.scenario)
    out_dir = Path(args.out) if args.out else Path("out") / sc.name
    res = run_scenario(sc, out_dir, quiet=args.quiet, plots=not args.no_plots, steady_stop=args.steady_stop,
                       mode=args.mode)
    s = res.summary
    rope = s.get("rope_pull_force_N")
    if s.get("mode") == "steady":
        # no scatter, no drift: the error bar is the mesh's and the solve's (summary: pull_force_uncertainty)
        spread = "mesh and solve tolerance"
    else:
        spread = f"sd {_f(s['pull_force_std_N'], '.2g')} N, drift {_f(s['pull_force_drift_N_per_s'], '.2g')} N/s"
    print(f"{sc.name}: status {s['status']}, pulling force {_f(s['pull_force_N'])} N "
          f"(± {_f(s['pull_force_uncertainty_N'], '.2g')} N: {spread}), trailing tension {_f(s['trailing_tension_N'])} N, "
          f"max tension {_f(s['max_tension_N'])} N")
    if s["steady_quantity"] == "trailing_tension_N":     # force-controlled: T2 is the result
        ref, got, what = s.get("rope_trailing_tension_N"), s["trailing_tension_N"], "trailing tension"
    else:
        ref, got, what = rope, s["pull_force_N"], "pulling force"
    if ref is not None and got is not None and np.isfinite(got):
        print(f"  rope reference: {what} {ref:.6g} N ({100 * (got / ref - 1):+.3f} %)")
    ref_c = s.get("rope_clearance_pull_force_N")
    if what == "pulling force" and ref_c is not None and got is not None and np.isfinite(got):
        print(f"  rope with clearance: pulling force {ref_c:.6g} N ({100 * (got / ref_c - 1):+.3f} %)")
    if s.get("mode") == "steady":
        print(f"  steady mode ({s['mode_rule']}): {s['message']}: {s['steps']} solves, "
              f"{s['newton_iterations']} Newton iterations, wall {s['wall_time_s']:.2f} s")
    else:
        print(f"  steady from {_f(s['steady_from_s'], '.4g')} s: {s['steady']}; {s['steps']} steps, "
              f"{s['newton_iterations']} Newton iterations, wall {s['wall_time_s']:.2f} s")
    print(f"  results in {out_dir}/")
    if not args.quiet and _used_jit_kernels_without_need():
        print("  note: this run compiled or loaded numba's JIT kernels (~0.7 s of start-up a process); "
              "`exucable compile` builds ahead-of-time kernels that later runs load instead")
    m = s.get("mesh") or {}
    if m:
        refined = f", refined {m['steady_refine']:g}x for steady mode" if m.get("steady_refine", 1.0) != 1.0 else ""
        print(f"  mesh: {m['elements']} elements of {m['element_length_m']:.4g} m ({m['source']}; rule "
              f"{m['rule_element_length_m']:.4g} m{refined}), {m['check_points_per_element']} check points per element")
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
