"""One scenario, start to finish: scenario → model → solve → post-processing → result files.

``run_scenario`` is the programmatic entry (sweeps call it in worker processes);
``exucable run`` is its command-line face.
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

from .versions import versions
from .errors import ExucableError
from .results import RunResult, write_results
from .scenario import Scenario, load_scenario
from .solve import Progress, simulate, steady_quantity
from .tension import SteadyState, detect_steady_state, tension_profile

__all__ = ["run_scenario", "contact_profile", "add_arguments", "main"]


def contact_profile(model, max_rows: int = 5000) -> tuple[dict | None, float]:
    """Sidewall bearing pressure along the conduit at the current state.

    One row per check point in contact order of ``s`` along the scenario's conduit (normal force
    per unit length [N/m] = the point's force over its share of the element, penetration [m]);
    beyond ``max_rows`` points, consecutive points are averaged in equal groups (pressure: mean,
    penetration: max). Also returns the largest per-point pressure [N/m].
    """
    if model.kernel is None:
        return None, 0.0
    q, v = model.coordinates()
    pts = model.kernel.points(q.reshape(-1), v.reshape(-1))
    L = model.conduit.centreline.length_m
    s = np.asarray(pts.s_conduit_m, dtype=float)
    keep = np.isfinite(s) & (s >= 0.0) & (s <= L)
    if model.scenario.pull.direction == "reverse":
        s = L - s   # report along the scenario's own conduit
    order = np.argsort(s[keep])
    s = s[keep][order]
    p = np.asarray(pts.normal_force_per_length_N_per_m, dtype=float)[keep][order]
    pen = np.maximum(np.nan_to_num(np.asarray(pts.penetration_m, dtype=float)[keep][order], nan=0.0), 0.0)
    peak = float(p.max()) if p.size else 0.0
    if s.size > max_rows:
        groups = np.array_split(np.arange(s.size), max_rows)
        s = np.array([s[g].mean() for g in groups])
        p = np.array([p[g].mean() for g in groups])
        pen = np.array([pen[g].max() for g in groups])
    return {"s_m": s, "normal_force_per_length_N_per_m": p, "penetration_m": pen}, peak


def run_scenario(scenario: Scenario | str | Path, out_dir=None, quiet: bool = True, plots: bool = True,
                 steady_stop: bool | None = None, mode: str | None = None) -> RunResult:
    """Run one scenario and (if ``out_dir`` is given) write its result files.

    A solver failure does not raise: the result has ``summary["status"] == "failed"`` with the
    message and the simulated time where it happened, and everything recorded until then is
    written. Invalid input raises :class:`~exucable.errors.ExucableError` before anything runs.
    """
    from .model.build import build_model

    sc = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    if mode is not None and mode != sc.solver.mode:
        sc = dataclasses.replace(sc, solver=dataclasses.replace(sc.solver, mode=mode))
    t_start = time.perf_counter()
    model = build_model(sc)
    build_s = time.perf_counter() - t_start
    sp = sc.solver
    if sp.mode == "steady":
        from .solve_steady import solve_steady
        out = solve_steady(model, progress=Progress(1.0, label=sc.name, enabled=not quiet))
        h = out.history.arrays()
        # one static state: the result is the last (converged) load step's
        st = SteadyState(out.status != "failed", 0.0, 0.0, 0.0, 0.0)
        i0 = max(len(h["time_s"]) - 1, 0)
    else:
        progress = Progress(sc.solver.end_time_s, label=sc.name, enabled=not quiet)
        out = simulate(model, progress=progress, steady_stop=steady_stop)
        h = out.history.arrays()
        st = detect_steady_state(h["time_s"], h[steady_quantity(model)], sp.steady_window_s, sp.steady_tolerance)
        i0 = int(np.searchsorted(h["time_s"], st.from_s)) if np.isfinite(st.from_s) else 0
    q, _ = model.coordinates()
    x, N = tension_profile(q, model.layout.element_length_m, model.axial_stiffness_N)
    cprof, peak_pressure = contact_profile(model)
    rope = model.rope
    summary = {
        "name": sc.name,
        "mode": sp.mode,
        "status": out.status,
        "message": out.message,
        "pull_force_N": float(np.mean(h["pull_force_N"][i0:])) if len(h["time_s"]) else None,
        "pull_force_std_N": float(np.std(h["pull_force_N"][i0:])) if len(h["time_s"]) else None,
        "steady_quantity": steady_quantity(model),
        "steady_drift_N": st.drift_N,
        "trailing_tension_N": float(np.mean(h["trailing_tension_N"][i0:])) if len(h["time_s"]) else None,
        "max_tension_N": float(np.max(h["max_tension_N"][i0:])) if len(h["time_s"]) else None,
        "steady": st.steady,
        "steady_from_s": st.from_s,
        "simulated_time_s": out.end_time_s,
        "steps": out.steps,
        "newton_iterations": out.newton_iterations,
        "jacobian_updates": out.jacobian_updates,
        "wall_time_s": out.wall_time_s,
        "build_time_s": build_s,
        "kernel_time_s": model.coupling.kernel_time_s if model.coupling is not None else 0.0,
        "max_sidewall_pressure_N_per_m": peak_pressure,
        "rope_pull_force_N": rope.pull_force_N if rope is not None else None,
        "rope_trailing_tension_N": rope.trailing_tension_N if rope is not None else None,
        "rope_max_sidewall_pressure_N_per_m": rope.max_sidewall_pressure_N_per_m if rope is not None else None,
        "scenario": sc.to_dict(),
        "versions": versions(),
    }
    if out.status == "failed":
        summary["failed_at_s"] = out.end_time_s
    rope_profile = None
    extras = {}
    if rope is not None:
        rope_profile = {"s_m": rope.s_conduit_m, "tension_N": rope.tension_N,
                        "sidewall_pressure_N_per_m": rope.sidewall_pressure_N_per_m}
        extras["s_cable_m"] = rope.s_cable_m
    result = RunResult(summary=summary, history=h, tension_profile={"s_m": x, "tension_N": N},
                       contact_profile=cprof, rope_profile=rope_profile, extras=extras)
    if out_dir is not None:
        write_results(out_dir, result, plots=plots)
    return result


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


def _f(value, fmt=".6g") -> str:
    return "n/a" if value is None or not np.isfinite(value) else format(value, fmt)


def main(args) -> int:
    sc = load_scenario(args.scenario)
    out_dir = Path(args.out) if args.out else Path("out") / sc.name
    res = run_scenario(sc, out_dir, quiet=args.quiet, plots=not args.no_plots, steady_stop=args.steady_stop,
                       mode=args.mode)
    s = res.summary
    rope = s.get("rope_pull_force_N")
    print(f"{sc.name}: status {s['status']}, pulling force {_f(s['pull_force_N'])} N "
          f"(± {_f(s['pull_force_std_N'], '.2g')}), trailing tension {_f(s['trailing_tension_N'])} N, "
          f"max tension {_f(s['max_tension_N'])} N")
    if s["steady_quantity"] == "trailing_tension_N":     # force-controlled: T2 is the result
        ref, got, what = s.get("rope_trailing_tension_N"), s["trailing_tension_N"], "trailing tension"
    else:
        ref, got, what = rope, s["pull_force_N"], "pulling force"
    if ref is not None and got is not None and np.isfinite(got):
        print(f"  rope reference: {what} {ref:.6g} N ({100 * (got / ref - 1):+.3f} %)")
    if s["mode"] == "steady":
        print(f"  steady sliding, one static solve ({s['message']}): {s['steps']} load steps, "
              f"{s['newton_iterations']} Newton iterations, wall {s['wall_time_s']:.2f} s")
    else:
        print(f"  steady from {_f(s['steady_from_s'], '.4g')} s: {s['steady']}; {s['steps']} steps, "
              f"{s['newton_iterations']} Newton iterations, wall {s['wall_time_s']:.2f} s")
    print(f"  results in {out_dir}/")
    if s["status"] == "failed":
        print(f"  FAILED: {s['message']} (at t = {_f(s.get('failed_at_s'))} s); "
              f"the results recorded until then are in {out_dir}/", file=sys.stderr)
        return 1
    return 0
