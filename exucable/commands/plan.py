"""``exucable plan SCENARIO``: both pull directions, section tables, limit checks, one report.

Prints per direction the section table and the checks, and the recommended direction; writes
``DIR/plan.json`` (SI; fields in README "exucable plan"), ``sections_forward.csv``,
``sections_reverse.csv``, ``checks.csv``, ``pull_in_<direction>.csv`` (with ``pull.feed_from_reel``),
``route.png`` and ``report.html`` (with ``--pdf`` also ``report.pdf``, printed by a headless Chromium), each
atomically, ``plan.json`` last. Exit status 0 when every check passes in the recommended direction, 1 when a
check fails in both directions, 2 on bad input.
"""

from __future__ import annotations

import csv
import datetime
import io
import sys
from pathlib import Path

from exucable.plan.pull import ENGINES, load_plan_scenario, plan_pull
from exucable.io import atomic_write_bytes, atomic_write_text, write_csv, write_json
from exucable.output.outdir import check_out_dir, name_as_path_part
from exucable.scenario.units import SYSTEMS

__all__ = ["add_arguments", "main", "write_plan"]

SECTION_COLUMNS = ("index", "kind", "plane", "slope_deg", "angle_deg", "radius_m", "length_m", "tension_in_N",
                   "tension_out_N", "sidewall_pressure_N_per_m", "max_tension_so_far_N")
#: Extra section columns of a multibody plan (``--engine steady|dynamic``): the rope's values beside,
#: the bend body's mean windowed pressure and the point loads at the bend ends [N] with their places.
MULTIBODY_SECTION_COLUMNS = ("rope_tension_in_N", "rope_tension_out_N", "rope_sidewall_pressure_N_per_m",
                             "rope_windowed_sidewall_pressure_N_per_m", "mean_sidewall_pressure_N_per_m",
                             "entry_point_load_N", "entry_s_conduit_m", "exit_point_load_N", "exit_s_conduit_m")
#: Extra section columns of a simulated bundle's plan (several cables, ``--engine steady``): the
#: arrangement the calculators' formula assumed, the one simulated (the rule's where the asked one did
#: not hold, see ``exucable.plan.pull.arrangement_left``) and the one found in the section's simulated state.
BUNDLE_SECTION_COLUMNS = ("formula_arrangement", "simulated_arrangement", "arrangement_found")
CHECK_COLUMNS = ("direction", "name", "passed", "value", "limit", "margin", "where", "quantity")


def add_arguments(p) -> None:
    p.add_argument("scenario", help="scenario file (TOML) or a shipped scenario's name, with optional [limits], "
                                    "cable.count, cable.arrangement")
    p.add_argument("--out", default=None, help="output directory (default: plan_<scenario name>)")
    p.add_argument("--engine", choices=ENGINES, default="auto",
                   help="auto (default): steady for one cable, rope for cable.count > 1; steady (one static solve "
                        "per direction, seconds) or dynamic (a dynamic run per direction, with progress; needs "
                        "solver.end_time): the multibody model of the cable (or of cable.count cables in one duct), the rope's values beside; rope "
                        "(instant, any cable.count)")
    p.add_argument("--arrangement-as-given", action="store_true",
                   help="several cables, --engine steady: simulate cable.arrangement only, even where the "
                        "calculators' rule gives another for the duct's D/d (three free cables are cradled at "
                        "D/d >= 2.5); without it a direction whose asked arrangement does not reach a steady "
                        "state is simulated in the rule's arrangement and labelled so")
    p.add_argument("--units", choices=SYSTEMS, default=None,
                   help="units of the printed tables and the report (default: the scenario's display.units); "
                        "the file's bare numbers are always read in its own display.units")
    p.add_argument("--project", default=None, help="project name for the report's title block")
    p.add_argument("--engineer", default=None, help="engineer's name for the report's title block")
    p.add_argument("--revision", default=None, help="revision of the plan for the report's title block")
    p.add_argument("--pdf", action="store_true",
                   help="also write report.pdf, the page printed by a headless Chromium (A4; Letter with imperial "
                        "units); needs chromium or chrome on PATH")


def _text_csv(columns, rows) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns)
    for r in rows:
        w.writerow(["" if r.get(c) is None else r.get(c) for c in columns])
    return buf.getvalue()


def write_plan(out_dir, plan: dict, scenario, units: str, meta: dict | None = None, pdf: bool = False) -> list[Path]:
    """Write the plan's files into ``out_dir`` (each atomically, ``plan.json`` last); return their paths.

    ``meta`` fills the report's title block (``project``, ``engineer``, ``revision``, ``date``,
    ``scenario_file``); ``pdf`` also prints the page to ``report.pdf``
    (:func:`exucable.plan.report.report_pdf`).
    """
    from exucable.plots.route import plot_route
    from exucable.plan.report import plan_report_html, report_pdf
    from exucable.scenario.units import UNITS, display_unit

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    # plan.json marks a complete plan: an earlier one goes first, and a pull-in table this plan
    # does not write again with it
    for stale in ("plan.json", "pull_in_forward.csv", "pull_in_reverse.csv"):
        (out / stale).unlink(missing_ok=True)
    written = []
    for name in ("forward", "reverse"):
        d = plan["directions"][name]
        path = out / f"sections_{name}.csv"
        columns = SECTION_COLUMNS + (MULTIBODY_SECTION_COLUMNS if plan["engine"] != "rope" else ()) + (
            BUNDLE_SECTION_COLUMNS if "bundle" in d else ())
        atomic_write_text(path, _text_csv(columns, d["sections"]))
        written.append(path)
        if "pull_in" in d:
            path = out / f"pull_in_{name}.csv"
            columns = ("pulled_length_m", "pull_force_N") + (("rope_pull_force_N",) if "rope_pull_force_N" in d["pull_in"]
                                                             else ())
            write_csv(path, columns, d["pull_in"])
            written.append(path)
    rows = [dict(c, direction=n) for n in ("forward", "reverse") for c in plan["directions"][n]["checks"]]
    atomic_write_text(out / "checks.csv", _text_csv(CHECK_COLUMNS, rows))
    written.append(out / "checks.csv")
    length_unit = display_unit("length", units)
    route_png = plot_route(scenario.build_conduit(), out / "route.png", title=scenario.name, length_unit=length_unit,
                           metres_per_unit=UNITS[length_unit][1], point_names=plan["point_names"])
    written.append(route_png)
    page = plan_report_html(plan, scenario.name, route_png.read_bytes(), units, meta=meta)
    atomic_write_text(out / "report.html", page)
    written.append(out / "report.html")
    if pdf:
        atomic_write_bytes(out / "report.pdf", report_pdf(page, paper="Letter" if units == "imperial" else "A4"))
        written.append(out / "report.pdf")
    write_json(out / "plan.json", plan, indent=1)
    written.append(out / "plan.json")
    return written


def _print_table(header, rows) -> None:
    from exucable.plan.report import fmt_number

    scales = [max([abs(r[i]) for r in rows if isinstance(r[i], float) and abs(r[i]) < float("inf")], default=None)
              for i in range(len(header))]
    cells = [[str(v) if isinstance(v, int) else fmt_number(v, scales[i]) for i, v in enumerate(r)] for r in rows]
    widths = [max(len(h), *(len(c[i]) for c in cells)) for i, h in enumerate(header)]
    print("  " + "  ".join(h.rjust(w) for h, w in zip(header, widths)))
    for c in cells:
        print("  " + "  ".join(v.rjust(w) for v, w in zip(c, widths)))


def _print_bundle(b: dict, units: str) -> None:
    """A simulated bundle's values beside the calculators' (``--engine steady``, several cables)."""
    from exucable.plan.report import fmt_number
    from exucable.post.bundle import laid_phrase
    from exucable.scenario.units import display_unit, from_si

    p = display_unit("force_per_length", units)
    if b["weight_correction_factor"] is None:
        return      # the solve failed: the status above says so, the sections are the calculators'
    print(f"  simulated {b['count']} cables, {laid_phrase(b)}: weight correction factor "
          f"{fmt_number(b['weight_correction_factor'])} (the calculators' for {b['arrangement']} "
          f"{fmt_number(b['formula_weight_correction_factor'])})"
          + (f"; JAM at s = {b['jam_s_conduit_m']:.4g} m" if b.get("jam") else ""))
    for row in b.get("sections") or []:
        print(f"  {row['kind']} {row['section']}: {row['arrangement']}")
    for row in b.get("bends") or []:
        print(f"  bend {row['bend']}: SWBP on cable {row['most_loaded_cable']} "
              f"{fmt_number(from_si(row['peak_pressure_N_per_m'], 'force_per_length', units))} {p}, the calculators' "
              f"formula on the simulated tension {fmt_number(from_si(row['formula_pressure_N_per_m'], 'force_per_length', units))} {p}")


def main(args) -> int:
    from exucable.plan.report import check_in_units, direction_label, fmt_number, section_rows
    from exucable.scenario.units import display_unit, from_si

    if args.pdf:
        from exucable.plan.report import find_browser, report_pdf

        if find_browser() is None:           # say so before anything runs or is written
            report_pdf("")
    scenario, spec = load_plan_scenario(args.scenario, units=args.units)
    # checked before planning: a multibody engine's solves are not lost to a bad --out
    out = check_out_dir(Path(args.out) if args.out else Path(f"plan_{name_as_path_part(scenario.name)}"))
    if args.engine != "rope":
        from .compile import announce_compiling

        announce_compiling()
    plan = plan_pull(scenario, spec, engine=args.engine, progress=True,
                     arrangement_as_given=args.arrangement_as_given,
                     notify=lambda line: print(f"{scenario.name}: {line}", file=sys.stderr, flush=True))
    units = spec.units
    f = display_unit("force", units)
    def force(v):
        return f"{fmt_number(from_si(v, 'force', units))} {f}"

    print(f"{scenario.name}: engine {plan['engine']} ({plan['engine_rule']})")
    print(f"{scenario.name}: {plan['count']} cable(s), {plan['arrangement']}, weight correction "
          f"{fmt_number(plan['weight_correction_factor'])}, jam ratio {fmt_number(plan['jam_ratio'])} ({plan['jam_risk']}), "
          f"clearance {fmt_number(from_si(plan['clearance_m'], 'length', units, small=True))} "
          f"{display_unit('length', units, small=True)}, fill {fmt_number(plan['fill_percent'], 10.0)} %")
    for name in ("forward", "reverse"):
        d = plan["directions"][name]
        print(f"\n{direction_label(plan, name)} pull: pull force {force(d['pull_force_N'])}, "
              f"max tension {force(d['max_tension_N'])}")
        if "rope_pull_force_N" in d:
            u = d.get("pull_force_uncertainty_N")
            if u is not None:
                # a bundle's bar without its coarse solve (no CPU time left for it) is the solve's parts only: say so
                partial = (d.get("pull_force_uncertainty_method") or "").startswith("solve parts only")
                print(f"  pull force uncertainty ± {from_si(u, 'force', units):.2g} {f}"
                      + (" (solve parts only, mesh part not measured)" if partial else ""))
            # a bundle's rope is the calculators' formula (the weight correction of the plan's arrangement)
            rope = (f"the calculators' formula ({plan['arrangement']}, weight correction "
                    f"{fmt_number(plan['weight_correction_factor'])})" if "bundle" in d else "rope")
            print(f"  {plan['engine']} engine, {d['elements']} elements: status {d['status']}"
                  f"{'; ' + d['message'] if d['message'] else ''}; {rope}: pull force "
                  f"{force(d['rope_pull_force_N'])}, max tension {force(d['rope_max_tension_N'])}")
        _print_table(*section_rows(d, units))
        if "bundle" in d:
            _print_bundle(d["bundle"], units)
        if d["slack"]:
            print("  note: the cable runs slack somewhere (a downhill stretch steeper than the friction angle): "
                  "tension 0 there")
        if not plan["limits_checked"]:
            print("  limits: not checked (the scenario has no [limits])")
        for c in d["checks"]:
            value, limit, unit = check_in_units(c, units)
            margin = "" if c["margin"] is None else f", margin {100 * c['margin']:.1f} %"
            limit = "" if limit is None else f", limit {fmt_number(limit)} {unit}".rstrip()
            value = "" if value is None else f"value {fmt_number(value)} {unit}".rstrip()
            print(f"  check {c['name']}: {'pass' if c['passed'] else 'FAIL'} ({value}"
                  f"{limit}{margin}{'; ' if value else ''}{c['where']})")
        unchecked = [c["name"] for c in d["not_checked"] if c["why"].startswith("not checked")]
        if unchecked:
            print(f"  not checked (no limit given): {', '.join(unchecked)}")
    meta = {"project": args.project, "engineer": args.engineer, "revision": args.revision,
            "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
            "scenario_file": str(scenario.source_path or args.scenario)}
    written = write_plan(out, plan, scenario, units, meta=meta, pdf=args.pdf)
    rec = direction_label(plan, plan["recommended_direction"])
    if plan["passed"]:
        checked = [c["name"] for c in plan["checks"]]
        print(f"\nrecommended direction: {rec}" + ("" if plan["limits_checked"] else " (limits not checked: no [limits] given)"))
    else:
        failing = sorted({c["name"] for n in ("forward", "reverse") for c in plan["directions"][n]["checks"]
                          if not c["passed"]})
        print(f"\nFAIL: no direction meets every given limit (failing: {', '.join(failing)}); "
              f"lower maximum tension: {rec}")
    print(f"written: {', '.join(str(p) for p in written)}")
    return 0 if plan["passed"] else 1
