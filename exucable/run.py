"""One scenario, start to finish: scenario → model → solve → post-processing → result files.

``run_scenario`` is the programmatic entry (sweeps call it in worker processes);
:mod:`exucable.commands.run` is its command-line face.
"""

from __future__ import annotations

import contextlib
import dataclasses
import time
from pathlib import Path

import numpy as np

from .errors import ModelError
from .output.versions import versions
from .output.export import conduit_s
from .output.figure_process import Figures
from .output.outdir import owned_out_dir
from .output.results import RunResult, write_results
from .output.summary import RunSummary
from .scenario.specs import Scenario, load_scenario
from .post.pressure import bend_table, default_window_m, pressure_profile, sorted_point_loads
from .post.tension import SteadyState, detect_steady_state, profile_stations_m
from .post.trust import AxisGauge, DYNAMIC_LIMIT, FRICTION_DEFICIT_LIMIT, PENETRATION_LIMIT, assess, not_steady_fix, pull_force_uncertainty

__all__ = ["run_scenario", "contact_profile", "one_blas_thread"]


def check_point_loads(model) -> dict | None:
    """Every check point at the current state, ordered by its place along the scenario's conduit:
    ``s_conduit_m`` [m], ``normal_force_N`` (weighted, what the wall pushes with) [N],
    ``normal_force_per_length_N_per_m`` (over the point's share of its element) [N/m],
    ``penetration_m`` [m]. None without contact."""
    if model.kernel is None:
        return None
    q, v = model.coordinates()
    pts = model.kernel.points(q.reshape(-1), v.reshape(-1))
    L = model.conduit.centreline.length_m
    s = np.asarray(pts.s_conduit_m, dtype=float)
    keep = np.isfinite(s) & (s >= 0.0) & (s <= L)
    s = conduit_s(model, s)   # along the scenario's own conduit, not the pull-oriented one
    kept = np.flatnonzero(keep)
    rows = kept[np.argsort(s[kept])]   # the kept points in order of s: one gather per column
    return {"s_conduit_m": s[rows],
            "normal_force_N": np.asarray(pts.normal_force_N, dtype=float)[rows],
            "normal_force_per_length_N_per_m": np.asarray(pts.normal_force_per_length_N_per_m, dtype=float)[rows],
            "penetration_m": np.maximum(np.nan_to_num(np.asarray(pts.penetration_m, dtype=float)[rows], nan=0.0), 0.0)}


def contact_profile(points: dict | None, max_rows: int = 5000) -> tuple[dict | None, float]:
    """The check points' line loads along the conduit from :func:`check_point_loads`.

    One row per check point in order of ``s_conduit_m`` along the scenario's conduit (normal force per unit
    length [N/m] = the point's force over its share of the element, penetration [m]); beyond
    ``max_rows`` points, consecutive points are averaged in equal groups (line load: mean,
    penetration: max). Also returns the largest per-point line load [N/m]: at a bend end it grows
    as the elements shrink and with the contact stiffness (a concentrated load spread over one
    point's share), so it is not the sidewall pressure an engineer sets against a cable's limit
    (that is the windowed pressure, :mod:`exucable.post.pressure`).
    """
    if points is None:
        return None, 0.0
    s, p, pen = points["s_conduit_m"], points["normal_force_per_length_N_per_m"], points["penetration_m"]
    peak = float(p.max()) if p.size else 0.0
    if s.size > max_rows:
        # the groups of np.array_split (contiguous, sizes differing by one), reduced at once
        size, extra = divmod(s.size, max_rows)
        counts = np.full(max_rows, size)
        counts[:extra] += 1
        starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        s = np.add.reduceat(s, starts) / counts
        p = np.add.reduceat(p, starts) / counts
        pen = np.maximum.reduceat(pen, starts)
    return {"s_conduit_m": s, "normal_force_per_length_N_per_m": p, "penetration_m": pen}, peak


def axis_gauge(model) -> AxisGauge:
    """The :class:`~exucable.post.trust.AxisGauge` of ``model``'s (pull-oriented) conduit."""
    return AxisGauge(model.conduit.centreline, model.conduit.inner_radius_m)


def cable_tension_along_conduit(model, gauge: AxisGauge | None = None,
                                profile_tension_N=None) -> tuple[np.ndarray, np.ndarray]:
    """The cable's tension at its nodes [N] (from its loads' equilibrium, :meth:`Model.tension_N`) and
    their places along the scenario's conduit [m]; ``gauge``: :func:`axis_gauge` of the model, if made;
    ``profile_tension_N``: the tension now at :func:`exucable.post.tension.profile_stations_m`'s
    stations (k per element from each node, and the leading end), if known: every k-th value is a
    node's (the same stations, the same numbers)."""
    q, _ = model.coordinates()
    Le = model.layout.element_length_m
    if profile_tension_N is not None:
        T = np.asarray(profile_tension_N, dtype=float)
        per_element, rest = divmod(len(T) - 1, len(Le))
        if rest or not per_element:
            raise ValueError(f"profile_tension_N: {len(T)} values are not k stations on each of {len(Le)} "
                             "elements and the leading end (exucable.post.tension.profile_stations_m)")
        T = T[::per_element]
    else:
        T = model.tension_N(np.concatenate([[0.0], np.cumsum(Le)]))
    _, s = (axis_gauge(model) if gauge is None else gauge)(q[:, :3])
    return conduit_s(model, s), T


def _pressure(model, points, rope, gauge: AxisGauge | None = None,
              profile_tension_N=None) -> tuple[dict, list, dict | None]:
    """Windowed pressure summary, per-bend rows and the pressure profile (see exucable.post.pressure);
    ``profile_tension_N``: as :func:`cable_tension_along_conduit` takes it."""
    if points is None or rope is None:
        return {}, [], None
    centre = model.scenario.build_conduit().centreline
    w = default_window_m(centre)
    rope_p = rope.sidewall_pressure_N_per_m
    rope_s = conduit_s(model, rope.s_conduit_m)     # the rope is solved on the pull-oriented conduit
    summed = sorted_point_loads(points["s_conduit_m"], points["normal_force_N"])   # for both tables
    prof = pressure_profile(points["s_conduit_m"], points["normal_force_N"], rope_s, rope_p, w, centre.length_m,
                            sorted_loads=summed)
    s_c, T_c = cable_tension_along_conduit(model, gauge, profile_tension_N)
    lam = model.mesh.bending_length_m if model.mesh is not None else 0.0
    bends = bend_table(centre.pieces, points["s_conduit_m"], points["normal_force_N"], s_c, T_c, rope_s,
                       rope.tension_N, rope_p, w, lam, model.scenario.pull.direction,
                       bending_stiffness_N_m2=model.scenario.cable.bending_stiffness_N_m2,
                       element_length_m=float(np.max(model.layout.element_length_m)), sorted_loads=summed)
    i = int(np.argmax(prof["windowed_pressure_N_per_m"]))
    info = {"pressure_window_m": w,
            "pressure_window_rule": "half the tightest bend radius (a twentieth of the route without bends)",
            # the calculators' SWBP: contact force within s ± w/2 over w, converged under refinement
            "max_sidewall_pressure_N_per_m": float(prof["windowed_pressure_N_per_m"][i]),
            "max_sidewall_pressure_s_conduit_m": float(prof["s_conduit_m"][i]),
            "rope_max_windowed_sidewall_pressure_N_per_m": float(np.max(prof["rope_windowed_pressure_N_per_m"]))}
    return info, bends, prof


def _with_final_contact(model, h: dict, gauge: AxisGauge | None = None, tension_N=None) -> dict:
    """``h`` with the contact columns (``max_penetration_m``, ``max_axis_offset_m`` and its place) of
    the model's current state in its last row, NaN before it: a steady solve's history records the
    forces of its pseudo-time steps only, and its last row is the converged state. ``gauge``,
    ``tension_N``: the model's :func:`axis_gauge` and its tension profile now, if the caller has them."""
    from .model.recorder import History, record_state

    last = History()
    record_state(model, float(h["time_s"][-1]), last, axis_gauge(model) if gauge is None else gauge,
                 tension_N=tension_N)
    rows = len(h["time_s"])
    columns = {}
    for key in ("max_penetration_m", "max_axis_offset_m", "max_axis_offset_s_conduit_m"):
        column = np.full(rows, np.nan)
        column[-1] = getattr(last, key)[0]
        columns[key] = column
    return {**h, **columns}


def _solver_counts(out) -> dict:
    """The summary's counts of a time integration or steady solve ``out`` (a SolveOutcome)."""
    return {"simulated_time_s": out.end_time_s, "steps": out.steps, "newton_iterations": out.newton_iterations,
            # all iterations, those of rejected step attempts included, per accepted step
            "newton_iterations_per_step": out.newton_iterations / out.steps if out.steps else None,
            "jacobian_updates": out.jacobian_updates, "wall_time_s": out.wall_time_s}


def _assess(model, out, st, h, pull_force_N):
    """Status and flags of a finished run (see :mod:`exucable.post.trust`)."""
    sc = model.scenario
    c = sc.cable
    pen = np.nan_to_num(h.get("max_penetration_m", np.zeros(0)), nan=-np.inf)
    off = np.nan_to_num(h.get("max_axis_offset_m", np.zeros(0)), nan=-np.inf)
    t = h["time_s"]
    ip = int(np.argmax(pen)) if pen.size else None
    io = int(np.argmax(off)) if off.size else None
    R_in = model.conduit.inner_radius_m
    clearance = R_in - c.radius_m
    # the kernel's check points give the penetration; points far outside have no candidate segment,
    # so the cable axis's offset beyond the clearance bounds it from below
    pen_max = max(float(pen[ip]) if ip is not None else -np.inf, float(off[io]) - clearance if io is not None else -np.inf)
    ip_use = io if (io is not None and (ip is None or float(off[io]) - clearance >= float(pen[ip]))) else ip
    return assess(
        failed=out.status == "failed", steady=bool(st.steady),
        max_penetration_m=pen_max, max_penetration_time_s=float(t[ip_use]) if ip_use is not None else float("nan"),
        max_penetration_s_conduit_m=float(h["max_axis_offset_s_conduit_m"][ip_use]) if ip_use is not None else float("nan"),
        max_axis_offset_m=float(off[io]) if io is not None else -np.inf,
        max_axis_offset_time_s=float(t[io]) if io is not None else float("nan"),
        max_axis_offset_s_conduit_m=float(h["max_axis_offset_s_conduit_m"][io]) if io is not None else float("nan"),
        clearance_m=clearance, cable_radius_m=c.radius_m, inner_radius_m=R_in,
        mass_per_length_kg_per_m=c.mass_per_length_kg_per_m, speed_m_per_s=sc.pull.speed_m_per_s,
        # the quasi-static expectation (the rope's) is the scale ρA·v² is measured against; a run
        # thrown about by inertia can report any pulling force, even a negative one
        pull_force_N=(model.rope.pull_force_N if model.rope is not None
                      else pull_force_N if pull_force_N is not None else float("nan")),
        steady_window_s=sc.solver.steady_window_s, steady_tolerance=sc.solver.steady_tolerance,
        end_time_s=out.end_time_s, base_status=out.status, loaded=is_loaded(sc), friction=sc.contact.friction,
        regularisation_velocity_m_per_s=(sc.contact.friction_regularisation_velocity_m_per_s
                                         if sc.solver.mode == "dynamic" else None),
        not_steady_fix=not_steady_fix(force_controlled=sc.pull.force_N is not None, start_from=sc.solver.start_from,
                                      exit_span_damping_1_per_s=sc.solver.exit_span_damping_1_per_s,
                                      pretension=sc.solver.pretension))


def is_loaded(sc) -> bool:
    """Whether anything loads the cable: gravity, a back tension or a prescribed pulling force.
    Without, the quasi-static pulling force is 0 N (a valid answer)."""
    g = sc.gravity.g_m_per_s2 if sc.gravity is not None else 0.0
    return g > 0.0 or sc.pull.back_tension_N > 0.0 or sc.pull.force_N is not None


def run_scenario(scenario: Scenario | str | Path, out_dir=None, quiet: bool = True, plots: bool | Figures = True,
                 steady_stop: bool | None = None, refine: float = 1.0,
                 check_points_per_element: int | None = None, mode: str | None = None,
                 error_bar: bool = True, cpu_budget_s: float | None = None) -> RunResult:
    """Run one scenario and (if ``out_dir`` is given) write its result files.

    A solver failure does not raise: the result has ``summary["status"] == "failed"`` with the
    message and the simulated time where it happened, and everything recorded until then is
    written. Invalid input raises :class:`~exucable.errors.ExucableError` before anything runs,
    and so does an ``out_dir`` that cannot be written or that another run is writing into
    (:class:`~exucable.errors.OutputError`; :func:`exucable.output.outdir.owned_out_dir`): the
    directory is this run's from before the solve until its files are written.
    ``refine`` divides the mesh's element length and ``check_points_per_element`` overrides the
    scenario's (``exucable converge``); ``mode`` (``"dynamic"`` or ``"steady"``) overrides
    ``solver.mode``. ``error_bar``: a steady solve states its uncertainty from a second solve on a
    coarser mesh (:mod:`exucable.solve.error_bar`); False skips that solve (its uncertainty is then
    None), as ``exucable converge`` does, whose levels are the error bar. ``cpu_budget_s`` (several
    cables only): the steady solve gives up once it has used this much CPU time [s], checked after
    each accepted pseudo-time step (status ``failed``, saying so). ``plots`` may be a
    :class:`~exucable.output.figure_process.Figures` the caller started before anything loaded Exudyn
    (``exucable run`` does, first thing), so that its helper process draws the figures.
    """
    sc = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    if mode is not None and mode != sc.solver.mode:
        sc = dataclasses.replace(sc, solver=dataclasses.replace(sc.solver, mode=mode))

    def checked_solver():
        # the checks before the run may import Exudyn: after the figures' helper is forked
        if sc.cable.count != 1:
            def solve(*args):
                return _solve_bundle(*args, cpu_budget_s=cpu_budget_s)
        else:
            _refuse_pulling_the_cable_out(sc)
            solve = _solve
        _refuse_snapshot_times_in_steady_mode(sc)
        return solve

    if out_dir is None:
        with one_blas_thread():
            return checked_solver()(sc, quiet, steady_stop, refine, check_points_per_element, error_bar)
    # the figures' helper process is forked before anything loads Exudyn (or was, by the caller), to
    # import matplotlib beside the solve; refused input stops it at once, before anything is written
    started = plots if isinstance(plots, Figures) else Figures() if plots else contextlib.nullcontext(False)
    with started as figures:
        solve = checked_solver()
        with owned_out_dir(out_dir) as out, one_blas_thread():
            result = solve(sc, quiet, steady_stop, refine, check_points_per_element, error_bar)
            write_results(out, result, plots=figures)
    return result


def one_blas_thread():
    """A context in which numpy's and scipy's BLAS run on one thread; the former limits come back on exit.

    Why: a run's linear algebra is vectors and thin bands (the banded LU's half bandwidth is 11), far
    below the size where BLAS threads pay; OpenBLAS still splits every product of more than ~10 000
    entries over its threads, whose start-up and spin-wait cost more than they save. Measured
    (``benchmarks/long_routes.py --lengths 10000 --no-figures``, one BLAS thread against OpenBLAS's
    default two, one run each on a quiet machine): the 10 km run 10.83 → 8.96 s CPU, 11.34 → 8.99 s
    wall; its rope references 1.20 → 0.51 s. The limit is process-wide while the run lasts: another
    thread of the caller's doing linear algebra meanwhile runs on one BLAS thread too.
    """
    from threadpoolctl import threadpool_limits   # at call time: importing exucable changes nothing

    return threadpool_limits(limits=1, user_api="blas")


def _solve(sc: Scenario, quiet: bool, steady_stop, refine: float, check_points_per_element,
           error_bar: bool = True) -> RunResult:
    """Build and solve a validated scenario and post-process it (no files)."""
    from .model.build import build_model
    from .solve.dynamic import Progress, earliest_steady_s, expected_drift_N_per_s, simulate, steady_quantity  # Exudyn: only when a run is asked for

    t_start = time.perf_counter()
    from .solve.start import steady_start
    first = None
    if sc.solver.start_from == "steady" and sc.solver.mode == "dynamic" and sc.pull.force_N is None and sc.solver.pretension:
        first = steady_start(sc, refine=refine, check_points_per_element=check_points_per_element)
    coarse = None
    solve_refine, points = refine, check_points_per_element
    if _steady_on_the_rule(sc):
        # steady mode solves on the rule's mesh refined STEADY_REFINE times, elements and check-point
        # spacing alike; the rule's own mesh is the error bar's coarse solve (exucable.solve.error_bar)
        from .scenario.mesh import STEADY_REFINE
        if error_bar or points is None:     # without the bar, only for the rule's check points per element
            coarse = build_model(sc, refine=refine, check_points_per_element=points)
            points = coarse.mesh.check_points_per_element
        solve_refine = refine * STEADY_REFINE
    # the coarse build's rope references are the scenario's, whatever the mesh: not solved twice
    model = build_model(sc, refine=solve_refine, check_points_per_element=points,
                        start=first.layout if first is not None else None,
                        references=coarse.start if coarse is not None else None)
    build_s = time.perf_counter() - t_start
    sp = sc.solver
    recorder = None
    bar = None
    if sp.mode == "steady":
        from .output.snapshots import SnapshotRecorder
        from .solve.start import nested_start, resolves_bend_ends
        from .solve.steady import SteadySettings, solve_steady
        settings = SteadySettings.from_solver(sp)
        coarse_out, warm = None, None
        if error_bar and coarse is not None and resolves_bend_ends(coarse.mesh):
            # nested iteration: the error bar's coarse solve first, from the rope start; the solved
            # mesh then starts from its state, subdivided exactly (the rope start if that fails).
            # Otherwise the solved mesh first: the coarse solve's kernel buffers are not held
            # through the larger solve (10 km: +45 MB peak)
            coarse_out = solve_steady(coarse, settings=settings)
            if coarse.coupling is not None:
                coarse.coupling.forget_evaluation()   # its last kernel pass: not needed, and large on long routes
            if coarse_out.status != "failed":
                warm = nested_start(model, coarse)
        out = solve_steady(model, progress=Progress(1.0, label=sc.name, enabled=not quiet),
                           settings=settings, warm_start=warm)
        h = out.history.arrays()
        # the steady state is the result: written as the one snapshot, so that a cross-check
        # needs the files only
        recorder = SnapshotRecorder(model, [])
        recorder.record_steady_state(float(h["pull_force_N"][-1]) if len(h["time_s"]) else float("nan"))
        # one static state, the start's extent of cable in the conduit (laid out past the exit by
        # the steady lead-out, model.layout.steady_lead_out_m): the result is the last (converged)
        # pseudo-time step's; no time history, no scatter
        drift = 0.0
        st = SteadyState(out.status != "failed", 0.0, 0.0, 0.0, 0.0)
        i0 = max(len(h["time_s"]) - 1, 0)
        refs = extent_references(sc, model, model.start.lead_out_m)
        pf = None
        if error_bar and out.status != "failed" and len(h["time_s"]):
            from .solve.error_bar import steady_error_bar
            quantity = steady_quantity(model)
            bar = steady_error_bar(sc, model, float(h[quantity][-1]), quantity, coarse=coarse, refine=solve_refine,
                                   coarse_outcome=coarse_out)
    else:
        progress = Progress(sp.end_time_s, label=sc.name, enabled=not quiet)
        snapshot_times = sc.output.times_s(sp.end_time_s)
        if snapshot_times:
            from .output.snapshots import SnapshotRecorder
            recorder = SnapshotRecorder(model, snapshot_times)
        out = simulate(model, progress=progress, steady_stop=steady_stop, snapshots=recorder)
        h = out.history.arrays()
        drift = expected_drift_N_per_s(model)
        st = detect_steady_state(h["time_s"], h[steady_quantity(model)], sp.steady_window_s, sp.steady_tolerance,
                                 expected_drift_N_per_s=drift, earliest_s=earliest_steady_s(model))
        i0 = int(np.searchsorted(h["time_s"], st.from_s)) if np.isfinite(st.from_s) else 0
        refs = window_references(sc, model, h["time_s"][i0:])
        # the uncertainty is of the mean about the drift the references explain (the cable's changing
        # extent, evaluated at the window's mean time): remove that drift first
        pf = pull_force_uncertainty(h["time_s"], h["pull_force_N"] - drift * h["time_s"],
                                    st.from_s if np.isfinite(st.from_s) else 0.0) if len(h["time_s"]) else None
    # the cable's tension from the equilibrium of its loads (exucable.post.tension.equilibrium_tension):
    # EA·ε of the elements oscillates next to the concentrated loads at bend ends
    x = profile_stations_m(model.layout.element_length_m)
    N = model.tension_N(x)
    if sp.mode == "steady" and len(h["time_s"]):
        # the result's row is the converged state's; the pseudo-time steps before it are not in
        # equilibrium and keep EA·ε's maximum (the recovery's contact pass each step would cost more)
        h["max_tension_N"][-1] = float(np.max(N))
    points = check_point_loads(model)
    cprof, peak_line_load = contact_profile(points)
    rope = model.rope
    # one gauge of the conduit's axis for the pressure table and the final contact check (built
    # from up to 200 000 centreline samples)
    gauge = axis_gauge(model) if model.kernel is not None else None
    pressure_info, bends, pressure_prof = _pressure(model, points, rope, gauge, profile_tension_N=N)
    has_history = bool(len(h["time_s"]))
    pull_force_N = float(np.mean(h["pull_force_N"][i0:])) if has_history else None
    warnings = list(model.mesh.warnings) if model.mesh is not None else []
    if sp.mode == "steady":
        bar, wall_warning = _with_wall_part(model, bar, h, refs, points)
        warnings += wall_warning
        uncertainty = _steady_uncertainty(sc, bar, out)
    else:
        uncertainty = {"pull_force_uncertainty_N": pf.uncertainty_N if pf else None,
                       "pull_force_uncertainty_method": (pf.method if pf else "no history: none")}
    start = None
    if first is not None:
        start = {"kind": "steady" if first.layout is not None else "rope",
                 "steady_pull_force_N": first.pull_force_N if first.layout is not None else None,
                 "lead_out_m": getattr(model.start, "lead_out_m", 0.0),
                 "steady_solve_message": first.message, "steady_solve_wall_time_s": first.wall_time_s}
        if first.layout is None:
            warnings.append(f"solver.start_from = \"steady\": the steady solve failed ({first.message}); "
                            "started from the rope instead")
    # a steady solve's pseudo-time steps record forces only: the trust checks of the wall (penetration,
    # the axis beyond the wall) read the converged state's contact, or they would never run
    trusted_h = (_with_final_contact(model, h, gauge, tension_N=N)
                 if sp.mode == "steady" and out.status != "failed" and has_history else h)
    status, flags = _assess(model, out, st, trusted_h, pull_force_N)
    if not is_loaded(sc):
        warnings.append("no load acts on the cable (no gravity, pull.back_tension 0, no pull.force): its "
                        "rope reference is 0 N; what the run reports is the bending stiffness's share and "
                        f"inertia's, of the order of ρA·v² = {sc.cable.mass_per_length_kg_per_m * sc.pull.speed_m_per_s**2:.3g} N")
    message = out.message
    if flags and not message:
        message = "; ".join(f["message"] for f in flags)
    summary = RunSummary(
        name=sc.name,
        mode=sp.mode,
        mode_rule=sp.mode_rule,
        cable_element="compiled" if getattr(model, "cable_forces", None) is not None else "exudyn",
        static_solver=getattr(out, "static_solver", None),
        status=status,
        message=message,
        pull_force_N=pull_force_N,
        # scatter about the drift the cable's changing extent explains (none without gravity)
        pull_force_std_N=float(np.std(h["pull_force_N"][i0:] - drift * h["time_s"][i0:])) if has_history else None,
        reference_drift_N_per_s=drift,
        **uncertainty,
        pull_force_drift_N_per_s=pf.drift_N_per_s + drift if pf else None,
        pull_force_unexplained_drift_N_per_s=pf.drift_N_per_s if pf else None,
        pull_force_uncertainty=({"mean_over_periods_N": pf.mean_N + drift * 0.5 * (pf.window_s[0] + pf.window_s[1]),
                                 "periods": pf.periods, "period_s": pf.period_s,
                                 "window_s": list(pf.window_s),
                                 "method": pf.method + (f"; after removing the references' expected drift "
                                                        f"{drift:.4g} N/s" if drift else "")} if pf
                                else bar.to_dict() if bar is not None else None),
        steady_quantity=steady_quantity(model),
        steady_drift_N=st.drift_N,
        trailing_tension_N=float(np.mean(h["trailing_tension_N"][i0:])) if has_history else None,
        max_tension_N=float(np.max(h["max_tension_N"][i0:])) if has_history else None,
        steady=st.steady,
        steady_from_s=st.from_s,
        **_solver_counts(out),
        build_time_s=build_s,
        kernel_time_s=model.coupling.kernel_time_s if model.coupling is not None else 0.0,
        # one check point's normal force over its share of the element: depends on the mesh and
        # the contact stiffness at a bend end; kept for cross-checks, not for a cable's limit
        max_check_point_line_load_N_per_m=peak_line_load if points is not None else None,
        rope_pull_force_N=refs.get("rope_pull_force_N", rope.pull_force_N if rope is not None else None),
        rope_trailing_tension_N=rope.trailing_tension_N if rope is not None else None,
        rope_max_sidewall_pressure_N_per_m=rope.max_sidewall_pressure_N_per_m if rope is not None else None,
        rope_clearance_pull_force_N=refs.get("rope_clearance_pull_force_N"),
        reference_pulled_out_m=refs.get("pulled_out_m"),
        **pressure_info,     # without contact or rope: none, and max_sidewall_pressure_N_per_m is None
        bends=bends,
        mesh=(dict(model.mesh.to_dict(), steady_refine=solve_refine / refine) if model.mesh is not None else None),
        warnings=warnings,
        scenario=sc.to_dict(),
        versions=versions(),
        start=start,
        failed_at_s=out.end_time_s if out.status == "failed" else None,
        flags=flags,
        trust_limits={"penetration_fraction_of_min_clearance_radius": PENETRATION_LIMIT,
                      "dynamic_rhoAv2_over_pull_force": DYNAMIC_LIMIT,
                      "friction_deficit_fraction_of_mu": FRICTION_DEFICIT_LIMIT,
                      "outside": "cable axis farther from the conduit axis than its inner radius"},
        snapshots_s=recorder.recorded_s if recorder is not None else None,
        snapshots_not_reached_s=list(recorder.pending) if recorder is not None else None,
    )
    rope_profile = None
    extras = {}
    if rope is not None:
        # the rope is solved on the pull-oriented conduit, trailing end first; written along the
        # scenario's conduit in increasing s_conduit_m, as the contact profile
        order = slice(None, None, -1) if sc.pull.direction == "reverse" else slice(None)
        rope_profile = {"s_conduit_m": conduit_s(model, rope.s_conduit_m)[order],
                        "tension_N": rope.tension_N[order],
                        "sidewall_pressure_N_per_m": rope.sidewall_pressure_N_per_m[order]}
        extras["x_m"] = rope.s_cable_m[order]
    result = RunResult(summary=summary, history=h, tension_profile={"x_m": x, "tension_N": N},
                       contact_profile=cprof, rope_profile=rope_profile, extras=extras,
                       snapshots=recorder.tables() if recorder is not None else None,
                       bends=bends, pressure_profile=pressure_prof, model=model)
    return result


def _refuse_snapshot_times_in_steady_mode(sc) -> None:
    """A steady solve has no time to take snapshots at: it always writes its state as the one
    snapshot (time 0). Refuse the times rather than ignore them."""
    out = sc.output
    if sc.solver.mode != "steady" or not (out.snapshots_s or out.snapshot_interval_s is not None):
        return
    key = "output.snapshots" if out.snapshots_s else "output.snapshot_interval"
    raise ModelError(key, 'solver.mode = "steady" has no time: it always writes its steady state as the one '
                          "snapshot (snapshot_*.csv, time_s = 0); remove the key or use the dynamic mode")


class _OverBudget(Exception):
    """The steady solve of a bundle used up its CPU budget."""


def _budgeted(progress, budget_s: float | None):
    """``progress`` whose update (after each accepted pseudo-time step, between Exudyn's solves)
    raises :class:`_OverBudget` once the process has used ``budget_s`` of CPU time since now."""
    if budget_s is None:
        return progress
    t0, update = time.process_time(), progress.update

    def checked(t, extra=""):
        update(t, extra)
        progress.last_step = extra
        if time.process_time() - t0 > budget_s:
            raise _OverBudget
    progress.update = checked
    progress.last_step = ""
    return progress


def _solve_bundle(sc, quiet: bool, steady_stop, refine: float, check_points_per_element,
                  error_bar: bool = True, cpu_budget_s: float | None = None) -> RunResult:
    """Several cables in one conduit (``cable.count`` > 1): one steady solve of the bundle
    (:mod:`exucable.model.bundle`), its report in ``summary.json`` and each cable's tension in
    ``cable_tensions.csv``; ``tension_profile.csv`` holds the bundle's, the sum over the cables
    (no files here: :func:`run_scenario` writes them)."""
    from .model.bundle import build_bundle_model, bundle_report, bundle_tension_profile, check_bundle_supported
    from .solve.dynamic import Progress
    from .solve.bundle_starts import solve_bundle_starts
    from .solve.steady import SteadySettings

    if check_points_per_element is not None:
        raise ModelError("contact.check_points_per_element", "several cables take the scenario's check points; "
                         "set the key in the scenario instead")
    check_bundle_supported(sc)
    if sc.solver.mode == "dynamic":
        return _solve_bundle_dynamic(sc, quiet, steady_stop, refine)
    settings = SteadySettings.from_solver(sc.solver)
    t_start = time.perf_counter()
    model = build_bundle_model(sc, refine=refine, start_path=settings.bundle_starts[0])
    build_s = time.perf_counter() - t_start
    t_cpu = time.process_time()
    progress = _budgeted(Progress(1.0, label=sc.name, enabled=not quiet), cpu_budget_s)
    start, attempts = settings.bundle_starts[0], []
    current = {"start": start, "model": model}

    def on_start(name, start_model):
        current.update(start=name, model=start_model)

    try:
        # the starts in turn, each but the last given up where its relaxation stalls (solve.bundle_starts)
        solved = solve_bundle_starts(sc, model, refine=refine, settings=settings, progress=progress,
                                     on_start=on_start)
        model, out, start, attempts = solved.model, solved.outcome, solved.start, solved.attempts
    except _OverBudget:
        # the budget may stop a later start: report the state that was being solved
        model, start = current["model"], current["start"]
        from .model.recorder import History
        from .solve.dynamic import SolveOutcome

        bends = sum(1 for p in model.conduit.centreline.pieces if p.is_curved)
        why = (f"{bends} bend(s): several cables through bends do not yet solve reliably in steady mode" if bends
               else "a route without bends")
        out = SolveOutcome(history=History(), status="failed", end_time_s=0.0, steps=0, newton_iterations=0,
                           jacobian_updates=0, wall_time_s=float("nan"),
                           message=f"no steady state within the CPU budget of {cpu_budget_s:g} s (used "
                                   f"{time.process_time() - t_cpu:.3g} s, last step: {progress.last_step}; {why}); "
                                   "fix: --engine rope (the calculators' weight correction), or a shorter route")
    h = out.history.arrays()
    report = bundle_report(model)
    cables = bundle_tension_profile(model)
    if out.status != "failed" and len(h["time_s"]):
        # the result's row is the converged state's: its largest tension is the profile's (from the
        # cables' loads' equilibrium); the steps before it, not in equilibrium, keep EA·ε's
        h["max_tension_N"][-1] = report["max_tension_N"]
    total = np.sum([cables[k] for k in cables if k != "x_m"], axis=0)
    flags = []
    panels = _bundle_panels(sc, model, report, flags, out.status != "failed")
    status = out.status if out.status == "failed" or not flags else flags[0]["flag"]
    message = out.message if not flags else "; ".join([out.message] + [f["message"] for f in flags])
    summary = RunSummary(
        name=sc.name,
        mode="steady",
        status=status,
        message=message,
        flags=flags,
        pull_force_N=report["pull_force_N"],
        trailing_tension_N=report["trailing_tension_N"],
        max_tension_N=report["max_tension_N"],
        bundle={k: v for k, v in report.items() if k not in ("pull_force_N", "trailing_tension_N", "max_tension_N")}
        | {"onset_layer": out.onset_layer, "start": start,
           "starts_tried": [{"start": a.start, "status": a.status, "cpu_s": a.cpu_s,
                             "newton_iterations": a.newton_iterations} for a in attempts]},
        steps=out.steps,
        newton_iterations=out.newton_iterations,
        wall_time_s=out.wall_time_s,
        build_time_s=build_s,
        cable_element="compiled" if getattr(model.wall_couplings[0], "cable_forces", None) is not None else "exudyn",
        mesh=model.mesh.to_dict() if model.mesh is not None else None,
        warnings=(list(model.mesh.warnings) if model.mesh is not None else []) + _jam_band_warning(sc, model),
        scenario=sc.to_dict(),
        versions=versions(),
    )
    result = RunResult(summary=summary, history=h, tension_profile={"x_m": cables["x_m"], "tension_N": total},
                       cable_tensions=cables, model=model,
                       cross_sections={"panels": panels, "inner_radius_m": sc.conduit.inner_radius_m,
                                       "cable_radius_m": sc.cable.radius_m} if panels else None)
    return result


def _bundle_panels(sc, model, report: dict, flags: list, solved: bool) -> list | None:
    """Adds the arrangement found along the route, the jam and the drawn cross-sections to a bundle's
    ``report`` (:func:`exucable.model.bundle.bundle_sections`) and their flags (``jam``,
    ``window_edge``) to ``flags``; returns the panels to draw (None when not ``solved``: a failed
    solve has no state to classify, and the keys say so, jam unknown, not a silent false)."""
    from .model.bundle import bundle_cross_sections, bundle_sections
    from .post.bundle import classify_cross_section

    panels = None
    report.update(sections=[], bends=[], jam=None, jam_s_conduit_m=None, cross_sections=[])
    if solved:
        places = _bundle_places(sc, report, bundle_sections(model))
        offsets = bundle_cross_sections(model, [p["s_conduit_m"] for p in places])
        panels = []
        for p, offs in zip(places, offsets):
            if np.isnan(offs).any():
                continue        # outside some cable's extent
            c = classify_cross_section(offs, sc.conduit.inner_radius_m, sc.cable.radius_m)
            panels.append(dict(p, offsets_m=offs.tolist(), label=f"{p['label']}: {c['arrangement']}", **c))
        report["cross_sections"] = [{k: v for k, v in p.items() if k != "label"} for p in panels]
        if report["jam"]:
            flags.append(_jam_flag(sc, report))
    if report["contacts_at_window_edge"]:
        flags.append({"flag": "window_edge", "s_conduit_m": None, "time_s": None,
                      "message": f"{report['contacts_at_window_edge']} cable-cable contacts at the broad phase's window "
                                 "edge: the cables slid apart along the route further than it covers"})
    return panels


def _solve_bundle_dynamic(sc, quiet: bool, steady_stop, refine: float) -> RunResult:
    """Several cables in the dynamic mode (:mod:`exucable.model.bundle_rig`): the bundle integrated in
    time until the eye's pull is steady, as one cable's run (:func:`_solve`): ``history.csv`` with
    the bundle's row, the pulling force the steady window's mean with its uncertainty, the trust
    checks; ``summary.json``'s ``bundle`` report as in steady mode, each cable's share the window's
    mean and the weight correction against one cable alone at the window's extent."""
    from .model.bundle import bundle_report, bundle_tension_profile
    from .model.bundle_rig import build_bundle_dynamic_model
    from .quasistatic.extent import pull_force_references_N
    from .solve.dynamic import Progress, earliest_steady_s, expected_drift_N_per_s, simulate
    from .solve.start import bundle_steady_start

    _refuse_pulling_the_cable_out(sc)
    sp = sc.solver
    t_start = time.perf_counter()
    first = bundle_steady_start(sc, refine=refine, solve=sp.start_from == "steady")
    model = build_bundle_dynamic_model(sc, refine=refine, start=first.model, layouts=first.layouts)
    build_s = time.perf_counter() - t_start
    out = simulate(model, progress=Progress(sp.end_time_s, label=sc.name, enabled=not quiet), steady_stop=steady_stop)
    h = out.history.arrays()
    drift = expected_drift_N_per_s(model)
    st = detect_steady_state(h["time_s"], h["pull_force_N"], sp.steady_window_s, sp.steady_tolerance,
                             expected_drift_N_per_s=drift, earliest_s=earliest_steady_s(model))
    from_s = st.from_s if np.isfinite(st.from_s) else 0.0
    i0 = int(np.searchsorted(h["time_s"], from_s)) if len(h["time_s"]) else 0
    has_history = bool(len(h["time_s"]))
    pf = pull_force_uncertainty(h["time_s"], h["pull_force_N"] - drift * h["time_s"], from_s) if has_history else None
    pull_force_N = float(np.mean(h["pull_force_N"][i0:])) if has_history else None
    status, flags = _assess(model, out, st, h, pull_force_N)

    n, Tb = sc.cable.count, sc.pull.back_tension_N
    report = bundle_report(model)          # the last state's, then the window's means below
    shares = model.mean_shares_N(from_s)
    if shares is not None:
        F = float(np.sum(shares))
        for row, share in zip(report["cables"], shares):
            row["pull_share_N"], row["pull_share"] = float(share), (float(share / F) if F != 0.0 else None)
    # one cable alone with T_b/n over the cables' extent at the window's mean time (the cables have
    # been pulled on by then), as one cable's references (window_references)
    t_mean = float(np.mean(h["time_s"][i0:])) if has_history else 0.0
    alone = pull_force_references_N(sc.replace(**{"pull.back_tension": Tb / n}), model.conduit,
                                    model.lead_out_m + model.pulled_m(t_mean), with_clearance=False)
    F1 = alone["rope_pull_force_N"]
    report["rope_pull_force_one_cable_N"] = F1
    report["weight_correction_factor"] = ((pull_force_N - Tb) / (n * (F1 - Tb / n))
                                          if pull_force_N is not None and F1 - Tb / n > 0.0 else None)
    cables = bundle_tension_profile(model)
    total = np.sum([cables[k] for k in cables if k != "x_m"], axis=0)
    panels = _bundle_panels(sc, model, report, flags, out.status != "failed")
    bundle_flags = [f for f in flags if f["flag"] in ("jam", "window_edge")]
    if any(f["flag"] == "jam" for f in flags) and status in ("ok", "steady", "not_steady"):
        # wedged cables outrank a pull force that has not settled: a stopped pull's never does
        status = "jam"
    elif bundle_flags and status in ("ok", "steady"):
        status = bundle_flags[0]["flag"]
    message = out.message
    if flags and not message:
        message = "; ".join(f["message"] for f in sorted(flags, key=lambda f: f["flag"] != status))
    warnings = list(model.mesh.warnings) if model.mesh is not None else []
    start = None
    if sp.start_from == "steady":
        start = {"kind": "steady" if first.layouts is not None else "rope",
                 "steady_pull_force_N": first.pull_force_N if first.layouts is not None else None,
                 "lead_out_m": model.lead_out_m,
                 "steady_solve_message": first.message, "steady_solve_wall_time_s": first.wall_time_s}
        if first.layouts is None:
            warnings.append(f"solver.start_from = \"steady\": the steady solve failed ({first.message}); "
                            "started from the rope instead")
    summary = RunSummary(
        name=sc.name,
        mode="dynamic",
        status=status,
        message=message,
        flags=flags,
        pull_force_N=pull_force_N,
        pull_force_std_N=float(np.std(h["pull_force_N"][i0:] - drift * h["time_s"][i0:])) if has_history else None,
        reference_drift_N_per_s=drift,
        pull_force_uncertainty_N=pf.uncertainty_N if pf else None,
        pull_force_uncertainty_method=pf.method if pf else "no history: none",
        pull_force_drift_N_per_s=pf.drift_N_per_s + drift if pf else None,
        pull_force_unexplained_drift_N_per_s=pf.drift_N_per_s if pf else None,
        pull_force_uncertainty=({"mean_over_periods_N": pf.mean_N + drift * 0.5 * (pf.window_s[0] + pf.window_s[1]),
                                 "periods": pf.periods, "period_s": pf.period_s, "window_s": list(pf.window_s),
                                 "method": pf.method} if pf else None),
        steady_quantity="pull_force_N",
        steady_drift_N=st.drift_N,
        trailing_tension_N=float(np.mean(h["trailing_tension_N"][i0:])) if has_history else None,
        max_tension_N=float(np.max(h["max_tension_N"][i0:])) if has_history else None,
        bundle={k: v for k, v in report.items() if k not in ("pull_force_N", "trailing_tension_N", "max_tension_N")},
        steady=st.steady,
        steady_from_s=st.from_s,
        **_solver_counts(out),
        build_time_s=build_s,
        kernel_time_s=model.coupling.kernel_time_s + model.between_coupling.kernel_time_s,
        mesh=model.mesh.to_dict() if model.mesh is not None else None,
        warnings=warnings,
        scenario=sc.to_dict(),
        versions=versions(),
        start=start,
        failed_at_s=out.end_time_s if out.status == "failed" else None,
        trust_limits={"penetration_fraction_of_min_clearance_radius": PENETRATION_LIMIT,
                      "dynamic_rhoAv2_over_pull_force": DYNAMIC_LIMIT,
                      "friction_deficit_fraction_of_mu": FRICTION_DEFICIT_LIMIT,
                      "outside": "cable axis farther from the conduit axis than its inner radius"},
    )
    return RunResult(summary=summary, history=h, tension_profile={"x_m": cables["x_m"], "tension_N": total},
                     cable_tensions=cables, model=model,
                     cross_sections={"panels": panels, "inner_radius_m": sc.conduit.inner_radius_m,
                                     "cable_radius_m": sc.cable.radius_m} if panels else None)


def _bundle_places(sc, report: dict, found: dict) -> list[dict]:
    """Adds the arrangement keys of :func:`exucable.model.bundle.bundle_sections` to ``report`` and
    returns the places to draw across the duct (``output.cross_sections``, or the middle of each
    section inside the cables' extent, at most eight evenly chosen), each ``s_conduit_m`` and ``label``."""
    report.update(found)
    rows = found["sections"]
    if sc.output.cross_sections_m:
        def label(x):
            row = next((r for r in rows if r["s_conduit_start_m"] <= x <= r["s_conduit_end_m"]), None)
            return f"{row['kind']} {row['section']}" if row else "outside the cables"
        return [{"s_conduit_m": x, "label": label(x)} for x in sc.output.cross_sections_m]
    from .scenario.specs import MAX_CROSS_SECTIONS

    pick = rows if len(rows) <= MAX_CROSS_SECTIONS else [rows[i] for i in np.linspace(0, len(rows) - 1, MAX_CROSS_SECTIONS).round().astype(int)]
    return [{"s_conduit_m": 0.5 * (r["s_conduit_start_m"] + r["s_conduit_end_m"]), "label": f"{r['kind']} {r['section']}"}
            for r in pick]


def _jam_band_warning(sc, model) -> list[str]:
    """The summary's warning when three cables could wedge (:func:`exucable.post.bundle.jam_band_warning`)."""
    from .post.bundle import jam_band_warning

    mu = sc.contact.static_friction if sc.contact.static_friction is not None else sc.contact.friction
    bends = any(p.is_curved for p in model.conduit.centreline.pieces)
    text = jam_band_warning(sc.cable.count, sc.conduit.inner_radius_m / sc.cable.radius_m, mu, bends)
    return [text] if text else []


def _jam_flag(sc, report: dict) -> dict:
    """The summary's flag for three cables wedged across the duct: where, and what to change."""
    from .quasistatic.engineering import JAM_RANGE_D_OVER_d

    lo, hi = JAM_RANGE_D_OVER_d
    ratio = report["duct_over_cable_diameter"]
    where = next(r for r in report["sections"] if r["jam"])
    inside = "inside" if report["in_jam_range"] else "outside"
    return {"flag": "jam", "s_conduit_m": report["jam_s_conduit_m"], "time_s": None,
            "message": f"jam: three cables wedged side by side across the duct at s = {report['jam_s_conduit_m']:.4g} m "
                       f"({where['kind']} {where['section']}), D/d = {ratio:.3g} ({inside} the calculators' jam range "
                       f"{lo:g}-{hi:g}); fix: a duct with D/d outside {lo:g}-{hi:g} (conduit.inner_radius), or the "
                       "cables pulled as a bound trefoil"
                       + (", or no stop there (pull.stop_time: the pull stands still, and static friction across the "
                          "duct holds the wedge)" if sc.pull.stop_time_s is not None else "")}


def _steady_on_the_rule(sc) -> bool:
    """A steady solve on the mesh rule's mesh (no ``cable.elements`` or ``cable.element_length`` given)."""
    return (sc.solver.mode == "steady" and "elements" in sc.cable.derived_keys
            and sc.cable.element_length_m is None)


def _with_wall_part(model, bar, h, refs, points) -> tuple:
    """The steady error bar with the wall's compliance added (:func:`exucable.solve.error_bar.with_wall_compliance`:
    the rigid wall's pull is higher by up to u_wall), and a warning naming ``contact.stiffness`` when
    that part exceeds ``WALL_WARNING`` of the force; ``(bar, [])`` without a bar, contact or rope."""
    from .solve.dynamic import steady_quantity
    from .solve.error_bar import WALL_WARNING, with_wall_compliance

    if bar is None or bar.uncertainty_N is None or points is None or model.rope is None or not len(h["time_s"]):
        return bar, []
    quantity = steady_quantity(model)
    value = float(h[quantity][-1])
    if quantity == "trailing_tension_N":
        rope_N = model.rope.trailing_tension_N
    else:
        rope_N = refs.get("rope_clearance_pull_force_N") or refs.get("rope_pull_force_N", model.rope.pull_force_N)
    sc = model.scenario
    clearance = model.conduit.inner_radius_m - sc.cable.radius_m
    deepest = float(np.max(points["penetration_m"])) if len(points["penetration_m"]) else 0.0
    bar = with_wall_compliance(bar, value, rope_N, deepest, clearance)
    if not bar.wall_N > WALL_WARNING * abs(value):
        return bar, []
    name = quantity.removesuffix("_N").replace("_", " ")
    return bar, [f"the wall's compliance: the cable sinks {1e3 * deepest:.3g} mm into the wall "
                 f"({100 * deepest / clearance:.3g} % of the clearance {1e3 * clearance:.3g} mm); against a rigid wall "
                 f"the {name} may be up to {bar.wall_N:.3g} N ({100 * bar.wall_N / abs(value):.2g} %) higher, in its "
                 f"uncertainty (raise contact.stiffness: the penetration falls about as its -1/2 power)"]


def _steady_uncertainty(sc, bar, out) -> dict:
    """The summary's uncertainty keys of a steady solve from its error bar (None: none made)."""
    if bar is None:
        why = "the steady solve failed" if out.status == "failed" else "not asked for (error_bar=False)"
        return {"pull_force_uncertainty_N": None, "pull_force_uncertainty_method": f"none: {why}"}
    if sc.pull.force_N is not None:
        # the pulling force is given; what the solve finds is the trailing tension
        return {"pull_force_uncertainty_N": 0.0, "pull_force_uncertainty_method": "prescribed (pull.force)",
                "trailing_tension_uncertainty_N": bar.uncertainty_N,
                "trailing_tension_uncertainty_method": bar.method}
    return {"pull_force_uncertainty_N": bar.uncertainty_N, "pull_force_uncertainty_method": bar.method}


def _refuse_pulling_the_cable_out(sc) -> None:
    """Refuse a velocity-controlled dynamic pull whose drive would pull the whole cable out of its
    conduit before ``solver.end_time``: nothing inside is left to pull, and the references at the
    cable's extent do not exist. Refused before the run, so no result is lost afterwards."""
    from .model.rig import pulled_distance_m

    sp = sc.solver
    if sp.mode != "dynamic" or sc.pull.force_N is not None:
        return
    v, ramp, length = sc.pull.speed_m_per_s, sc.pull.ramp_time_s, sc.cable_length_m

    def ramped_displacement(t, v, ramp):
        return pulled_distance_m(t, v, ramp, sc.pull.stop_time_s, sc.pull.hold_time_s)

    pulled_m = ramped_displacement(sp.end_time_s, v, ramp)
    if pulled_m < length:
        return
    # the time the drive has pulled the whole cable out (the ramp is monotone: invert it on a bracket)
    from scipy.optimize import brentq
    t_out = brentq(lambda t: ramped_displacement(t, v, ramp) - length, 0.0, sp.end_time_s)
    raise ModelError("solver.end_time",
                     f"at {v:g} m/s the drive pulls {pulled_m:.4g} m by {sp.end_time_s:g} s, but the cable is "
                     f"{length:.4g} m long: it has left its conduit at {t_out:.3g} s. Set solver.end_time "
                     f"well below {t_out:.3g} s, lower pull.speed, or lengthen the cable")


def window_references(scenario, model, window_time_s) -> dict:
    """Both flexible references (:mod:`exucable.quasistatic.extent`) for the cable's extent at the mean
    time of the averaging window ``window_time_s`` [s] of a velocity-controlled pull; ``{}`` for a
    force-controlled one (its references are the model's centreline rope)."""
    from .model.rig import pulled_distance_m

    sc = scenario
    if sc.pull.force_N is not None or len(window_time_s) == 0:
        return {}
    t_mean = float(np.mean(window_time_s))
    lead_out = getattr(model.start, "lead_out_m", 0.0)   # a steady start's lead-out (solver.start_from)
    p = sc.pull
    return extent_references(sc, model, lead_out + pulled_distance_m(t_mean, p.speed_m_per_s, p.ramp_time_s,
                                                                     p.stop_time_s, p.hold_time_s))


def extent_references(scenario, model, pulled_out_m: float) -> dict:
    """Both flexible references for the cable pulled ``pulled_out_m`` [m] out of its start;
    ``{}`` for a force-controlled pull."""
    from .quasistatic.extent import pull_force_references_N

    if scenario.pull.force_N is not None:
        return {}
    # at the start's extent (nothing pulled out, or a steady start's lead-out) the start's own ropes
    # (centreline and with clearance) are those references (same conduit, cable inside, loads):
    # not solved twice
    start = model.start
    at_start = pulled_out_m == getattr(start, "lead_out_m", 0.0)
    return pull_force_references_N(scenario, model.conduit, pulled_out_m,
                                   clearance_solution=getattr(start, "rope_clearance", None) if at_start else None,
                                   rope_solution=getattr(start, "rope", None) if at_start else None)
