"""``exucable plan SCENARIO``: both pull directions, section tables, limit checks, one report.

Prints per direction the section table and the checks, and the recommended direction; writes
``DIR/plan.json`` (SI; fields in README "exucable plan"), ``sections_forward.csv``,
``sections_reverse.csv``, ``checks.csv``, ``pull_in_<direction>.csv`` (with ``pull.feed_from_reel``),
``route.png`` and ``report.html``, each atomically, ``plan.json`` last. Exit status 0 when every check
passes in the recommended direction, 1 when a check fails in both directions, 2 on bad input.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

from exucable.plan.pull import ENGINES, load_plan_scenario, plan_pull
from exucable.io import atomic_write_text, write_csv, write_json
from exucable.scenario.units import SYSTEMS

__all__ = ["add_arguments", "main", "write_plan"]

SECTION_COLUMNS = ("index", "kind", "plane", "slope_deg", "angle_deg", "radius_m", "length_m", "tension_in_N",
                   "tension_out_N", "sidewall_pressure_N_per_m", "max_tension_so_far_N")
#: Extra section columns of a multibody plan (``--engine steady|dynamic``): the rope's values beside,
#: the bend body's mean windowed pressure and the point loads at the bend ends [N] with their places.
MULTIBODY_SECTION_COLUMNS = ("rope_tension_in_N", "rope_tension_out_N", "rope_sidewall_pressure_N_per_m",
                             "rope_windowed_sidewall_pressure_N_per_m", "mean_sidewall_pressure_N_per_m",
                             "entry_point_load_N", "entry_s_conduit_m", "exit_point_load_N", "exit_s_conduit_m")
CHECK_COLUMNS = ("direction", "name", "passed", "value", "limit", "margin", "where", "quantity")


def add_arguments(p) -> None:
    p.add_argument("scenario", help="scenario file (TOML), with optional [limits], cable.count, cable.arrangement")
    p.add_argument("--out", default=None, help="output directory (default: plan_<scenario name>)")
    p.add_argument("--engine", choices=ENGINES, default="auto",
                   help="auto (default): steady for one cable, rope for cable.count > 1; steady (one static solve "
                        "per direction, seconds) or dynamic (a dynamic run per direction, with progress; needs "
                        "solver.end_time): the multibody model of one cable, the rope's values beside; rope "
                        "(instant, any cable.count)")
    p.add_argument("--units", choices=SYSTEMS, default=None,
                   help="units of the printed tables and the report (default: the scenario's display.units); "
                        "the file's bare numbers are always read in its own display.units")


def _text_csv(columns, rows) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns)
    for r in rows:
        w.writerow(["" if r.get(c) is None else r.get(c) for c in columns])
    return buf.getvalue()


def write_plan(out_dir, plan: dict, scenario, units: str) -> list[Path]:
    """Write the plan's files into ``out_dir`` (each atomically, ``plan.json`` last); return their paths."""
    from exucable.plots.route import plot_route
    from exucable.plan.report import plan_report_html

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name in ("forward", "reverse"):
        d = plan["directions"][name]
        path = out / f"sections_{name}.csv"
        columns = SECTION_COLUMNS + (MULTIBODY_SECTION_COLUMNS if plan["engine"] != "rope" else ())
        atomic_write_text(path, _text_csv(columns, d["sections"]))
        written.append(path)
        if "pull_in" in d:
            path = out / f"pull_in_{name}.csv"
            write_csv(path, ("pulled_length_m", "pull_force_N"), d["pull_in"])
            written.append(path)
    rows = [dict(c, direction=n) for n in ("forward", "reverse") for c in plan["directions"][n]["checks"]]
    atomic_write_text(out / "checks.csv", _text_csv(CHECK_COLUMNS, rows))
    written.append(out / "checks.csv")
    route_png = plot_route(scenario.build_conduit(), out / "route.png", title=scenario.name)
    written.append(route_png)
    page = plan_report_html(plan, scenario.name, route_png.read_bytes(), units)
    atomic_write_text(out / "report.html", page)
    written.append(out / "report.html")
    write_json(out / "plan.json", plan, indent=1)
    written.append(out / "plan.json")
    return written


def _print_table(header, rows) -> None:
    def cell(v):
        if v is None:
            return "–"
        return f"{v:.4g}" if isinstance(v, float) else str(v)

    cells = [[cell(v) for v in r] for r in rows]
    widths = [max(len(h), *(len(c[i]) for c in cells)) for i, h in enumerate(header)]
    print("  " + "  ".join(h.rjust(w) for h, w in zip(header, widths)))
    for c in cells:
        print("  " + "  ".join(v.rjust(w) for v, w in zip(c, widths)))


def main(args) -> int:
    from exucable.plan.report import check_in_units, section_rows
    from exucable.scenario.units import display_unit, from_si

    scenario, spec = load_plan_scenario(args.scenario, units=args.units)
    plan = plan_pull(scenario, spec, engine=args.engine, progress=True)
    units = spec.units
    f = display_unit("force", units)
    print(f"{scenario.name}: engine {plan['engine']} ({plan['engine_rule']})")
    print(f"{scenario.name}: {plan['count']} cable(s), {plan['arrangement']}, weight correction "
          f"{plan['weight_correction_factor']:.4g}, jam ratio {plan['jam_ratio']:.3g} ({plan['jam_risk']}), "
          f"clearance {from_si(plan['clearance_m'], 'length', units, small=True):.3g} {display_unit('length', units, small=True)}")
    for name in ("forward", "reverse"):
        d = plan["directions"][name]
        print(f"\n{name} pull: pull force {from_si(d['pull_force_N'], 'force', units):.4g} {f}, "
              f"max tension {from_si(d['max_tension_N'], 'force', units):.4g} {f}")
        if "rope_pull_force_N" in d:
            u = d.get("pull_force_uncertainty_N")
            if u is not None:
                print(f"  pull force uncertainty ± {from_si(u, 'force', units):.2g} {f}")
            print(f"  {plan['engine']} engine, {d['elements']} elements: status {d['status']}"
                  f"{'; ' + d['message'] if d['message'] else ''}; rope: pull force "
                  f"{from_si(d['rope_pull_force_N'], 'force', units):.4g} {f}, max tension "
                  f"{from_si(d['rope_max_tension_N'], 'force', units):.4g} {f}")
        _print_table(*section_rows(d, units))
        if d["slack"]:
            print("  note: the cable runs slack somewhere (a downhill stretch steeper than the friction angle): "
                  "tension 0 there")
        for c in d["checks"]:
            value, limit, unit = check_in_units(c, units)
            margin = "" if c["margin"] is None else f", margin {100 * c['margin']:.1f} %"
            limit = "" if limit is None else f", limit {limit:.4g} {unit}"
            value = "" if value is None else f"value {value:.4g} {unit}"
            print(f"  check {c['name']}: {'pass' if c['passed'] else 'FAIL'} ({value}"
                  f"{limit}{margin}{'; ' if value else ''}{c['where']})")
    out = Path(args.out) if args.out else Path(f"plan_{scenario.name}")
    write_plan(out, plan, scenario, units)
    print(f"\nrecommended direction: {plan['recommended_direction']}"
          f"{'' if plan['passed'] else ' (a check fails in both directions)'}")
    print(f"written: {out}/plan.json, sections_*.csv, checks.csv, report.html")
    return 0 if plan["passed"] else 1
