"""``exucable fit SCENARIO LOG``: the friction coefficient from a tension recorder's log, with its 95 %
interval, and for a partial log the rest of the pull forecast against the scenario's ``[limits]``.

Writes into ``--out DIR`` (default ``fit_<log name>``), each atomically, ``fit.json`` last:
``fit_curve.csv`` (the model and its bands over the route), ``fit_residuals.csv``, ``forecast.csv`` (a
partial log), ``fit_band.png`` and ``fit_residuals.png``. ``--watch`` re-reads a growing log and refits at
each change until the log says the pull ended, the head reaches the end, the log stays unchanged for
``--timeout`` seconds, or Ctrl-C. Exit status 0; 1 when one coefficient does not explain the log or a limit
is expected to be exceeded at the fitted friction; 2 on bad input.
"""

from __future__ import annotations

from pathlib import Path

from exucable.errors import LogError
from exucable.fit.friction import FIT_ENGINES, RESAMPLERS, RopeFamily, fit_friction, fit_friction_steady, resolve_fit_engine
from exucable.fit.log import read_pull_log
from exucable.io import AtomicBatch, write_csv, write_json
from exucable.plan.pull import load_plan_scenario
from exucable.scenario.units import SYSTEMS, UNITS, display_unit, to_si

__all__ = ["add_arguments", "main", "write_fit"]


def add_arguments(p) -> None:
    p.add_argument("scenario", help="scenario file (TOML) of the pull: route, cable, back tension, gravity, [limits]")
    p.add_argument("log", help="the recorder's CSV log: pulled length (or time) and head tension (docs/pull-logs.md)")
    p.add_argument("--out", default=None, help="output directory (default: fit_<log name>)")
    p.add_argument("--length-column", default=None, help="name or 1-based number of the pulled-length column")
    p.add_argument("--force-column", default=None, help="name or 1-based number of the head-tension column")
    p.add_argument("--time-column", default=None, help="name or 1-based number of the time column")
    p.add_argument("--length-unit", default=None, help="unit of the length column if its name does not say (m, ft)")
    p.add_argument("--force-unit", default=None, help="unit of the tension column if its name does not say (N, kN, lbf)")
    p.add_argument("--time-unit", default=None, help="unit of the time column if its name does not say (s, min, h)")
    p.add_argument("--speed", default=None,
                   help="pull speed for a log without pulled length: m/s, or a quantity such as '60 ft/min'")
    p.add_argument("--tare", default=None,
                   help="offset subtracted from every reading: a number in the log's force unit, '20 lbf', or "
                        "'auto' (the median reading before the winch moved)")
    p.add_argument("--spike-threshold", type=float, default=6.0,
                   help="readings this many robust standard deviations off their running median are spikes (default 6)")
    p.add_argument("--direction", choices=("forward", "reverse"), default=None,
                   help="the pull's direction along the route (default: the scenario's pull.direction)")
    p.add_argument("--engine", choices=FIT_ENGINES, default="auto",
                   help="the pull-in history fitted: rope (instant; auto's choice) or steady (the multibody model's, "
                        "a few histories of one steady solve per head position, seconds to minutes; the friction the "
                        "multibody plan needs; not with --separate or several cables)")
    p.add_argument("--mu-max", type=float, default=1.0, help="largest friction coefficient looked at (default 1)")
    p.add_argument("--bootstrap", type=int, default=999, help="bootstrap resamples for the interval (default 999)")
    p.add_argument("--interval", choices=tuple(RESAMPLERS), default="block",
                   help="how residuals are resampled: circular blocks (default) or an AR sieve")
    p.add_argument("--separate", action="store_true",
                   help="also fit one friction for straights and one for bends, with a check that the log can tell "
                        "them apart")
    p.add_argument("--seed", type=int, default=0, help="seed of the resampling (default 0)")
    p.add_argument("--units", choices=SYSTEMS, default=None,
                   help="units of the printed values and figures (default: the scenario's display.units)")
    p.add_argument("--no-plots", action="store_true", help="skip the figures")
    p.add_argument("--watch", action="store_true",
                   help="re-read the growing log and refit at each change (Ctrl-C, '# end' in the log, the head at "
                        "the route's end or --timeout stops it)")
    p.add_argument("--poll", type=float, default=2.0, help="--watch: seconds between looks at the log (default 2)")
    p.add_argument("--timeout", type=float, default=600.0,
                   help="--watch: stop when the log has not changed for this many seconds (default 600)")


def _read_kwargs(args) -> dict:
    speed = None
    if args.speed is not None:
        try:
            speed = float(args.speed)
        except ValueError:
            speed = to_si("--speed", args.speed, "speed")
    return dict(length_column=args.length_column, force_column=args.force_column, time_column=args.time_column,
                length_unit=args.length_unit, force_unit=args.force_unit, time_unit=args.time_unit,
                speed_m_per_s=speed, tare=args.tare, spike_threshold=args.spike_threshold)


def write_fit(out_dir, fit, title: str = "", units: str = "si", plots: bool = True, log=None) -> list[Path]:
    """Write the fit's files into ``out_dir`` (each atomically, ``fit.json`` last); return their paths.
    ``log`` (the :class:`~exucable.fit.log.PullLog`) adds its left-out readings to the figure."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    c = fit.curve
    with AtomicBatch() as batch:
        paths = [write_csv(out / "fit_curve.csv", ("pulled_length_m", "pull_force_N", "low_N", "high_N",
                                                    "reading_low_N", "reading_high_N"), c, batch),
                 write_csv(out / "fit_residuals.csv", ("pulled_length_m", "pull_force_N", "fitted_N", "residual_N"),
                           {"pulled_length_m": fit.pulled_length_m, "pull_force_N": fit.pull_force_N,
                            "fitted_N": fit.fitted_N, "residual_N": fit.residual_N}, batch)]
        if fit.forecast is not None:
            paths.append(write_csv(out / "forecast.csv", ("pulled_length_m", "pull_force_N", "low_N", "high_N"),
                                   fit.forecast, batch))
    if plots:
        from exucable.plots.fit import plot_fit_band, plot_fit_residuals

        f_unit, l_unit = display_unit("force", units), display_unit("length", units)
        scale = dict(force_factor=UNITS[f_unit][1], force_unit=f_unit, length_factor=UNITS[l_unit][1],
                     length_unit=l_unit)
        left = None
        if log is not None:
            out_rows = (log.stopped | log.spike) & ~log.tare_rows
            left = (log.pulled_length_m[out_rows], log.pull_force_N[out_rows])
        plot_fit_band(out / "fit_band.png", fit, title=title, left_out=left, **scale)
        plot_fit_residuals(out / "fit_residuals.png", fit, **scale)
        paths += [out / "fit_band.png", out / "fit_residuals.png"]
    paths.append(write_json(out / "fit.json", fit.to_json(), indent=1))
    return paths


def _q(value_si, dimension, units, fmt=".4g") -> str:
    unit = display_unit(dimension, units)
    return f"{value_si / UNITS[unit][1]:{fmt}} {unit}"


def _print_fit(fit, units: str) -> None:
    rep = fit.log
    lo, hi = fit.friction_interval
    print(f"friction {fit.friction:.4f}, 95 % interval [{lo:.4f}, {hi:.4f}] ({fit.engine} engine, {fit.direction} pull, "
          f"{fit.pulled_length_m.size} rows fitted, residual scatter {_q(fit.residual_std_N, 'force', units, '.3g')}, "
          f"{fit.resampling['method']} bootstrap x{fit.bootstrap_samples})")
    print(f"log: {rep['rows']} rows, {rep['readable_rows']} readable, {rep['rows_used']} used; "
          f"tare {_q(rep['tare_N'], 'force', units, '.4g')}; {len(rep['stops'])} stop(s) ({rep['stopped_rows']} rows), "
          f"{len(rep['spikes'])} spike(s), {len(rep['gaps_m'])} gap(s), {len(rep['unreadable_rows'])} unreadable row(s)"
          f"{'' if rep['stops_detectable'] else ' (time-only log: stops cannot be seen)'}")
    one = fit.one_coefficient
    if one.get("p_value") is not None:
        verdict = "explains the log" if one["explains"] else "does NOT explain the log"
        print(f"one coefficient {verdict}: halves (split at {_q(one['split_pulled_length_m'], 'length', units)}) "
              f"{one['first_half_friction']:.4f} and {one['second_half_friction']:.4f}, p = {one['p_value']:.3g}")
    st = fit.steady
    if st is not None and st.get("rope_friction") is not None:
        a, b = st["rope_friction_interval"]
        print(f"multibody histories at friction {', '.join(f'{m:.4g}' for m in st['mu_nodes'])} "
              f"({st['history_points']} head positions each, {st['history_cpu_time_s']:.3g} s CPU); the rope fit "
              f"of the same log: {st['rope_friction']:.4f} [{a:.4f}, {b:.4f}]")
    sb = fit.straights_and_bends
    if sb is not None:
        if "friction_straights_interval" in sb:
            (a, b), (c, d) = sb["friction_straights_interval"], sb["friction_bends_interval"]
            print(f"straights {sb['friction_straights']:.4f} [{a:.4f}, {b:.4f}], bends {sb['friction_bends']:.4f} "
                  f"[{c:.4f}, {d:.4f}], correlation {sb['correlation']:+.2f}: "
                  + ("told apart, " + ("they differ" if sb["differ"] else "no difference shown") if sb["separable"]
                     else sb["reason"]))
        else:
            print(f"straights and bends: {sb['reason']}")
    e = fit.expected
    word = "forecast" if fit.partial else "at the fitted friction"
    if fit.partial:
        print(f"forecast from {_q(fit.forecast['pulled_length_m'][0], 'length', units)} to the end:")
    print(f"  {word}: pull force {_q(e['pull_force_N'], 'force', units)} "
          f"[{_q(e['pull_force_interval_N'][0], 'force', units)}, {_q(e['pull_force_interval_N'][1], 'force', units)}], "
          f"max tension {_q(e['max_tension_N'], 'force', units)} (up to {_q(e['max_tension_interval_N'][1], 'force', units)}), "
          f"max sidewall pressure {_q(e['max_sidewall_pressure_N_per_m'], 'force_per_length', units)} "
          f"(up to {_q(e['max_sidewall_pressure_interval_N_per_m'][1], 'force_per_length', units)})")
    for lim in e["limits"]:
        dim = "force_per_length" if lim["name"] == "max_sidewall_pressure" else "force"
        where = lim["reached_at_pulled_length_m"]
        where_hi = lim["reached_at_upper_at_pulled_length_m"]
        state = ("FAIL" if not lim["passed"] else "at risk" if not lim["passed_at_upper"] else "pass")
        extra = f", reached at {_q(where, 'length', units)} pulled" if where is not None else \
            f", at the interval's upper end reached at {_q(where_hi, 'length', units)} pulled" if where_hi is not None else ""
        print(f"  limit {lim['name']} {_q(lim['limit'], dim, units)}: {state}{extra}")
    for w in fit.warnings:
        print(f"  warning: {w}")


def _status(fit) -> int:
    ok = fit.one_coefficient.get("explains", True) and all(lim["passed"] for lim in fit.expected["limits"])
    return 0 if ok else 1


def main(args) -> int:
    scenario, spec = load_plan_scenario(args.scenario, units=args.units)
    if args.direction is not None:
        direction = args.direction
    else:
        direction = scenario.pull.direction
    engine, rule = resolve_fit_engine(args.engine, spec.count)
    if engine == "steady" and args.separate:
        raise LogError("--separate", "fits straights and bends apart on the rope only; use --engine rope with it")
    family = RopeFamily(scenario, spec, direction, args.mu_max)
    read_kwargs = _read_kwargs(args)
    out = Path(args.out) if args.out else Path(f"fit_{Path(args.log).stem}")
    title = f"{scenario.name} / {Path(args.log).name}"
    print(f"engine: {engine} ({rule})", flush=True)
    steady = {}

    def fit_once(log):
        kwargs = dict(bootstrap=args.bootstrap, seed=args.seed, method=args.interval)
        if engine == "rope":
            return fit_friction(scenario, log, family=family, separate=args.separate, **kwargs)
        if "family" not in steady:
            # the multibody histories are solved once, around the first log's rope fit, and reused
            print("solving the multibody pull-in histories (one steady solve per head position)...", flush=True)
            fit, steady["family"] = fit_friction_steady(scenario, log, rope_family=family, **kwargs)
            steady["info"] = fit.steady
            return fit
        fit = fit_friction(scenario, log, family=steady["family"], **kwargs)
        fit.steady = dict(steady["info"], rope_friction=None, rope_friction_interval=None)
        return fit

    if not args.watch:
        log = read_pull_log(args.log, **read_kwargs)
        fit = fit_once(log)
        _print_fit(fit, spec.units)
        write_fit(out, fit, title, spec.units, plots=not args.no_plots, log=log)
        print(f"written: {out}/fit.json, fit_curve.csv, fit_residuals.csv"
              f"{', forecast.csv' if fit.partial else ''}{'' if args.no_plots else ', fit_band.png, fit_residuals.png'}")
        return _status(fit)

    from exucable.fit.watch import watch_log

    last = None
    try:
        for update in watch_log(args.log, fit_once, poll_s=args.poll, timeout_s=args.timeout,
                                route_length_m=family.route_length_m, **read_kwargs):
            if update.error is not None:
                print(f"waiting: {update.error}", flush=True)
            if update.fit is not None:
                last = update.fit
                print(f"\n[{update.log.report['readable_rows']} rows, head at "
                      f"{_q(float(update.log.pulled_length_m.max()), 'length', spec.units)}]", flush=True)
                _print_fit(last, spec.units)
                write_fit(out, last, title, spec.units, plots=not args.no_plots, log=update.log)
            if update.stop == "ended":
                print("the pull has ended: watch stopped", flush=True)
            elif update.stop == "timeout":
                print(f"the log has not changed for {args.timeout:g} s: watch stopped", flush=True)
    except KeyboardInterrupt:
        print("\nwatch stopped (Ctrl-C)", flush=True)
    if last is None:
        raise LogError(str(args.log), "no fit was made: the log never had enough usable rows")
    print(f"written: {out}/fit.json (last fit)")
    return _status(last)
