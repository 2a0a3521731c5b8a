"""The HTML page of ``exucable plan``: one self-contained file (inline PNG, no script, no network) that an
engineer can check and sign.

Sections: title block (project, engineer, revision, date, scenario file, versions), the verdict naming
every failing check and every limit not checked, the checks of both directions, the route, tension along
the route (both directions on one axis, route order), sidewall bearing pressure per bend (bends numbered
in route order), the section tables, the pull-in history (if computed), the inputs with their units and
the assumptions, and a sign-off block. Values are shown in the plan's unit system (SI or imperial) in
fixed-point engineering formats; the JSON and CSV files beside the page stay SI.

A print stylesheet keeps the page within A4 and Letter (182 mm of text width) and keeps headings with
what follows them; :func:`report_pdf` prints the same page to PDF with a headless Chromium when one is
installed.
"""

from __future__ import annotations

import base64
import html
import io
import math
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np
from exucable.errors import ExucableError
from exucable.io import atomic_write_text, new_figure
from exucable.post.bundle import LAID_AT_POSITIONS
from exucable.scenario.units import display_unit, from_si

__all__ = ["plan_report_html", "section_rows", "engine_note", "bundle_note", "simulated_arrangement_phrase", "check_in_units",
           "fmt_number", "direction_label", "report_pdf", "find_browser"]

# Screen: a readable column. Print: 182 mm of text (A4 210 mm and Letter 216 mm, less 14 mm margins), no
# heading left at a page foot, no figure, check table or title block split across pages.
_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:2em auto;max-width:1000px;color:#222}
h1{font-size:1.5em;margin-bottom:.2em} h2{font-size:1.2em;border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.4em}
table{border-collapse:collapse;margin:.4em 0 .8em 0;font-size:.9em} th,td{border:1px solid #ccc;padding:.2em .5em;text-align:right}
td{white-space:nowrap} td.w{white-space:normal}
th{background:#f3f3f3} td.l,th.l{text-align:left} .pass{color:#11751b;font-weight:600} .fail{color:#b00020;font-weight:600}
.unchecked{color:#8a5a00;font-weight:600}
.verdict{font-size:1.05em;padding:.6em 1em;border-radius:6px;border:1px solid #999}
.ok{background:#e6f4ea} .bad{background:#fde7e9} img{max-width:100%} .note{color:#555;font-size:.88em}
table.meta td{text-align:left;white-space:normal} table.meta th{text-align:left;width:11em} .sign td{height:2.2em;min-width:12em}
figure{margin:.4em 0} figcaption{font-size:.85em;color:#555}
@page{margin:14mm}
@media print{
 body{max-width:182mm;margin:0;font-size:9pt}
 h1{font-size:14pt} h2{font-size:11pt;margin-top:.8em;break-after:avoid;page-break-after:avoid}
 table{font-size:8pt;break-inside:avoid;page-break-inside:avoid} tr{break-inside:avoid}
 figure,.block,.verdict,table.meta{break-inside:avoid;page-break-inside:avoid}
 img{max-width:182mm;max-height:110mm}
 .verdict{border:1.5px solid #000}
}
"""

_THIN = "\u202f"  # narrow no-break space: the SI brochure's thousands separator


def fmt_number(value, scale: float | None = None) -> str:
    """A number in a fixed-point engineering format: four significant digits of ``scale`` (default: of
    the value itself), thousands grouped by a narrow space, never an exponent; values below the last
    shown digit print as 0 (never "-0"). None prints "–", NaN "n/a".

    ``scale`` is the largest magnitude of the column or quantity the value belongs to, so that a column
    shares its decimals and a tension of 3e-5 lbf beside 66.66 lbf reads 0.00. A lone value (no
    ``scale``) drops trailing zeros (0.715, not 0.7150), which would claim digits it was not given with.
    """
    if value is None:
        return "–"
    if isinstance(value, str):
        return value
    v = float(value)
    if not math.isfinite(v):
        return "n/a"
    ref = abs(v) if scale is None else max(abs(float(scale)), abs(v))
    decimals = 3 if ref == 0.0 else min(6, max(0, 3 - math.floor(math.log10(ref))))
    text = f"{v:,.{decimals}f}".replace(",", _THIN)
    if scale is None and "." in text:
        text = text.rstrip("0").rstrip(".")
    if float(text.replace(_THIN, "")) == 0.0:
        text = text.lstrip("-")
    return text


def _png(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _figure(b64: str, alt: str, caption: str, fig_id: str) -> str:
    return (f'<figure id="{fig_id}"><img alt="{html.escape(alt)}" src="data:image/png;base64,{b64}">'
            f"<figcaption>{caption}</figcaption></figure>")


def direction_label(plan: dict, name: str) -> str:
    """``"forward (A→H)"``: the direction with the route's points it runs between."""
    names = plan.get("point_names")
    if not names:
        return name
    a, b = (names[0], names[-1]) if name == "forward" else (names[-1], names[0])
    return f"{name} ({a}→{b})"


def check_in_units(check: dict, units: str) -> tuple[float | None, float | None, str]:
    """(value, limit, unit) of a check in display units."""
    q = check.get("quantity")
    if q is None:
        return check["value"], check["limit"], ""
    if q == "percent":
        return check["value"], check["limit"], "%"
    dim, small = ("length", True) if q == "small_length" else (q, False)
    conv = (lambda v: None if v is None else from_si(v, dim, units, small))
    return conv(check["value"]), conv(check["limit"]), display_unit(dim, units, small)


def section_rows(direction: dict, units: str) -> tuple[list[str], list[list]]:
    """Header and rows of a direction's section table in display units (shared by the CLI and the page).

    Sections in pull order; each named by the route's points it runs between (``"B–C"``) and, for
    bends, by its number in route order (the same in both directions).
    """
    f, p, ln = display_unit("force", units), display_unit("force_per_length", units), display_unit("length", units)
    header = ["#", "section", "bend", "plane / slope", f"length [{ln}]", f"radius [{ln}]", f"T in [{f}]",
              f"T out [{f}]", f"SWBP [{p}]", f"max T so far [{f}]"]
    # a multibody plan keeps the rope's values beside each section's
    beside = bool(direction["sections"]) and "rope_tension_out_N" in direction["sections"][0]
    if beside:
        header += [f"rope T out [{f}]", f"rope SWBP [{p}]", f"end point loads in/out [{f}]"]
    rows = []
    for r in direction["sections"]:
        if r["kind"] == "straight":
            where = f"slope {fmt_number(r['slope_deg'], 10.0)}°"
            radius = None
        else:
            where = f"{r['plane']}, {fmt_number(r['angle_deg'], 100.0)}°"
            radius = from_si(r["radius_m"], "length", units)
        swbp = None if r["sidewall_pressure_N_per_m"] is None else from_si(r["sidewall_pressure_N_per_m"],
                                                                          "force_per_length", units)
        row = [r.get("route_index", r["index"]), f"{r['kind']} {r.get('name', '')}".strip(),
               None if r.get("bend_number") is None else r["bend_number"], where,
               from_si(r["length_m"], "length", units), radius,
               from_si(r["tension_in_N"], "force", units), from_si(r["tension_out_N"], "force", units),
               swbp, from_si(r["max_tension_so_far_N"], "force", units)]
        if beside:
            rope_p = r["rope_sidewall_pressure_N_per_m"]
            # on the scale of the section's tension, as the tension columns beside (a load of 0.03 lbf
            # beside 36 lbf reads 0.03, not -0.03095)
            t_scale = abs(from_si(r["tension_out_N"], "force", units))
            loads = (None if "entry_point_load_N" not in r else
                     f"{fmt_number(from_si(r['entry_point_load_N'], 'force', units), t_scale)} / "
                     f"{fmt_number(from_si(r['exit_point_load_N'], 'force', units), t_scale)}")
            row += [from_si(r["rope_tension_out_N"], "force", units),
                    None if rope_p is None else from_si(rope_p, "force_per_length", units), loads]
        rows.append(row)
    return header, rows


def _column_scales(rows) -> list[float | None]:
    """Largest magnitude of each numeric column (tensions share one scale: T in, T out, max T)."""
    scales = []
    for i in range(len(rows[0]) if rows else 0):
        numbers = [abs(float(r[i])) for r in rows if isinstance(r[i], (float, np.floating))
                   and math.isfinite(float(r[i]))]
        scales.append(max(numbers) if numbers else None)
    return scales


def _table(header, rows, left=(1, 2), table_id: str | None = None, raw=(), wrap=()) -> str:
    scales = _column_scales(rows)
    attr = f" id='{table_id}'" if table_id else ""
    out = [f"<table{attr}><tr>" + "".join(f'<th class="{"l" if i in left else ""}">{html.escape(str(h))}</th>'
                                          for i, h in enumerate(header)) + "</tr>"]
    for row in rows:
        cells = []
        for i, v in enumerate(row):
            if i in raw:
                text = v            # trusted markup made here
            elif isinstance(v, (int, np.integer)) and not isinstance(v, bool):
                text = str(v)
            else:
                text = html.escape(fmt_number(v, scales[i]))
            css = ("l" if i in left else "") + (" w" if i in wrap else "")
            cells.append(f'<td class="{css.strip()}">{text}</td>')
        out.append("<tr>" + "".join(cells) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


def _route_x(plan: dict, name: str, s_pull) -> np.ndarray:
    """Distance along the route from its first point of a position given from the pull's tail."""
    s_pull = np.asarray(s_pull, dtype=float)
    return s_pull if name == "forward" else plan["inputs"]["route_length_m"] - s_pull


def _bend_spans(plan: dict) -> list[tuple[int, float, float, str]]:
    """(bend number, start, end along the route [m], name) of every bend, route order."""
    spans = []
    for r in plan["directions"]["forward"]["sections"]:
        if r.get("bend_number"):
            spans.append((r["bend_number"], r["s_start_m"], r["s_start_m"] + r["length_m"], r["name"]))
    return spans


def _tension_figure(plan: dict, units: str) -> str:
    fig = new_figure(figsize=(7.2, 3.4), dpi=110)
    ax = fig.add_subplot(111)
    f, ln = display_unit("force", units), display_unit("length", units)
    L = from_si(plan["inputs"]["route_length_m"], "length", units)
    for name, style in (("forward", "-"), ("reverse", "--")):
        d = plan["directions"][name]
        prof = d["profile"]
        x = from_si(_route_x(plan, name, prof["s_m"]), "length", units)
        t = from_si(np.asarray(prof["tension_N"]), "force", units)
        line, = ax.plot(x, t, style, lw=1.6, label=f"{direction_label(plan, name)} pull: "
                                                   f"{fmt_number(from_si(d['pull_force_N'], 'force', units))} {f}")
        rope = d.get("rope_profile")
        if rope is not None:
            ax.plot(from_si(_route_x(plan, name, rope["s_m"]), "length", units),
                    from_si(np.asarray(rope["tension_N"]), "force", units), ":", color=line.get_color(), lw=1.0,
                    label=f"{name}, rope [{f}]")
    for number, a, b, _ in _bend_spans(plan):
        ax.axvspan(from_si(a, "length", units), from_si(b, "length", units), color="0.5", alpha=0.12, lw=0)
    ax.set_xlim(0.0, L)
    ax.set_ylim(bottom=0.0)
    names = plan.get("point_names") or []
    if names:
        top = ax.twiny()
        top.set_xlim(ax.get_xlim())
        top.set_xticks(from_si(np.asarray(plan["point_s_m"]), "length", units), names, fontsize=8)
        top.tick_params(length=3, pad=1)
    ax.set_xlabel(f"distance along the route from {names[0] if names else 'its start'} [{ln}] (bends shaded)")
    ax.set_ylabel(f"tension [{f}]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    return _png(fig)


def _swbp_figure(plan: dict, units: str, limit_N_per_m) -> str | None:
    spans = _bend_spans(plan)
    if not spans:
        return None
    p = display_unit("force_per_length", units)
    fig = new_figure(figsize=(7.2, 2.9), dpi=110)
    ax = fig.add_subplot(111)
    width = 0.38
    numbers = [s[0] for s in spans]
    for k, name in enumerate(("forward", "reverse")):
        by_bend = {r["bend_number"]: r["sidewall_pressure_N_per_m"] for r in plan["directions"][name]["sections"]
                   if r.get("bend_number")}
        y = [from_si(by_bend[n], "force_per_length", units) for n in numbers]
        ax.bar(np.arange(len(numbers)) + (k - 0.5) * width, y, width, label=f"{direction_label(plan, name)} [{p}]")
    ax.set_xticks(range(len(numbers)), [f"bend {n}\n{name}" for n, _, _, name in spans], fontsize=8)
    if limit_N_per_m is not None:
        lim = from_si(limit_N_per_m, "force_per_length", units)
        ax.axhline(lim, color="tab:red", lw=1.5, label=f"limit {fmt_number(lim)} {p}")
    ax.set_ylabel(f"SWBP [{p}]")
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.tight_layout()
    return _png(fig)


def simulated_arrangement_phrase(plan: dict) -> str:
    """"; simulated as cradled forward and reverse" where a simulated bundle's arrangement differs from
    the plan's (the calculators'), else ""."""
    simulated = {n: plan["directions"][n].get("simulated_arrangement") for n in ("forward", "reverse")}
    other = {n: a for n, a in simulated.items() if a is not None and a != plan["arrangement"]}
    if not other:
        return ""
    # cables laid at their positions are a lay, not an arrangement's name: no "as" before it
    return "; " + "; ".join(f"simulated {'' if a == LAID_AT_POSITIONS else 'as '}{a} {direction_label(plan, n)}"
                            for n, a in other.items())


def bundle_note(direction: dict, plan: dict) -> str | None:
    """One sentence on what a simulated bundle's direction simulated, beside the formula's arrangement:
    "Simulated as cradled (the triangle did not hold: …); …" (None: not a simulated bundle)."""
    if "bundle" not in direction:
        return None
    fb = direction.get("arrangement_fallback")
    formula = (f"the calculators' formula values (rope columns) are for {plan['arrangement']}, weight correction "
               f"factor {fmt_number(plan['weight_correction_factor'])}")
    if fb is None:
        return f"Simulated {plan['count']} cables, {direction.get('simulated_arrangement')}; {formula}."
    if fb["simulated"] is None:
        return (f"Not simulated: the {fb['asked']} arrangement was asked as given and did not hold ({fb['reason']}); "
                f"the sections are the calculators' ({plan['arrangement']}).")
    word = "triangle" if fb["asked"] == "triangular" else f"{fb['asked']} arrangement"
    if direction["status"] == "failed":
        return (f"Not simulated: the {word} did not hold ({fb['reason']}), and the rule's {fb['simulated']} did not "
                f"solve either; the sections are the calculators' ({plan['arrangement']}).")
    return f"Simulated as {fb['simulated']} (the {word} did not hold: {fb['reason']}); {formula}."


def _input_rows(plan: dict, units: str) -> list[list]:
    """Rows (input, value in ``units``, SI) of the plan's inputs and limits, named in words."""
    inp = plan["inputs"]
    length_small = ("length", True)

    def q(value, dim, small=False):
        if value is None:
            return "–", "–"
        shown = f"{fmt_number(from_si(value, dim, units, small))} {display_unit(dim, units, small)}"
        si = f"{fmt_number(value)} {display_unit(dim, 'si', small)}"
        return shown, si

    rows = [["cable outer diameter d", *q(inp["cable_diameter_m"], *length_small)],
            ["duct inner diameter D", *q(inp["duct_inner_diameter_m"], *length_small)],
            ["cables in the duct", str(inp.get("count", plan["count"])), ""],
            ["arrangement", f"{plan['arrangement']} (given: {inp.get('arrangement', plan['arrangement'])})"
             + simulated_arrangement_phrase(plan), ""],
            *([["cables laid at (horizontal, up) from the duct's axis (cable.positions)",
                 "; ".join(f"({', '.join(q(x, *length_small)[0] for x in pair)})" for pair in inp["positions_m"]),
                 "; ".join(f"({', '.join(q(x, *length_small)[1] for x in pair)})" for pair in inp["positions_m"])]]
              if inp.get("positions_m") else []),
            ["weight per length, one cable", *q(inp["weight_per_length_one_cable_N_per_m"], "force_per_length")],
            ["friction coefficient μ", fmt_number(inp["friction"]), ""],
            ["back tension at the tail", *q(inp["back_tension_N"], "force")],
            ["route length", *q(inp["route_length_m"], "length")]]
    if "youngs_modulus_Pa" in inp:
        E = inp["youngs_modulus_Pa"]
        shown_E = f"{fmt_number(E / 1e9)} GPa" if E >= 1e8 else f"{fmt_number(E / 1e6)} MPa"
        rows.append(["Young's modulus E (EA of the multibody model)", shown_E, f"{fmt_number(E)} Pa"])
        ej = "given (cable.bending_stiffness)" if inp.get("bending_stiffness_given") else "E·π·r⁴/4 of a solid rod"
        rows.append([f"bending stiffness EJ ({ej})", f"{fmt_number(inp['bending_stiffness_N_m2'])} N·m²", ""])
    limit_dims = {"max_tension": ("force", False), "grip_limit": ("force", False),
                  "max_sidewall_pressure": ("force_per_length", False), "min_clearance": length_small,
                  "conductor_area": ("area", False)}
    for key, value in inp["limits"].items():
        if key in limit_dims and isinstance(value, (int, float)):
            shown, si = q(value, *limit_dims[key])
        elif key == "max_fill":
            shown, si = f"{fmt_number(value)} %", ""
        else:
            shown, si = html.escape(str(value)), ""
        rows.append([f"limit: {key.replace('_', ' ')}", shown, si])
    return rows


_ENGINE_NOTE = {
    "rope": "quasi-static rope (exucable.quasistatic.rope): a perfectly flexible cable (EJ = 0) on the duct's "
            "centreline, as the installation calculators; E and EJ are not used",
    "steady": "multibody model of one cable, steady sliding in one static solve per direction; the rope's values "
              "beside; SWBP: peak windowed pressure in each bend",
    "dynamic": "multibody model of one cable, a dynamic run per direction (tensions of its last state, pull force "
               "averaged over its steady window); the rope's values beside; SWBP: peak windowed pressure in each bend",
}


def engine_note(plan: dict) -> str:
    """What the plan's engine simulated, in words: the note of ``_ENGINE_NOTE``, with "one cable" made
    the bundle's cables where ``cable.count`` > 1 (each cable its own ANCF cable, the cable–cable
    contact between them; the calculators' weight-corrected rope beside)."""
    note = _ENGINE_NOTE[plan["engine"]]
    count = int(plan.get("count") or plan.get("inputs", {}).get("count") or 1)
    if count > 1 and plan["engine"] != "rope":
        note = note.replace("multibody model of one cable", f"multibody model of {count} cables in one duct "
                            "(one ANCF cable each, cable–cable contact)").replace(
            "the rope's values beside", "the calculators' formula values beside")
    return note


def _check_phrase(c: dict, units: str) -> str:
    value, limit, unit = check_in_units(c, units)
    if value is None or limit is None:
        return f"{c['name']} ({c['where']})"
    return f"{c['name']} {fmt_number(value)} {unit} against {fmt_number(limit)} {unit} at {c['where']}"


def _verdict(plan: dict, units: str) -> tuple[str, str]:
    """(css class, HTML) of the verdict: what passes, what fails and what was not checked."""
    f = display_unit("force", units)
    rec = plan["recommended_direction"]
    d = plan["directions"][rec]
    pull = f"{fmt_number(from_si(d['pull_force_N'], 'force', units))} {f}"
    not_checked = [c["name"] for c in plan["not_checked"] if c["why"].startswith("not checked")]
    checked = [c["name"] for c in plan["checks"]]
    if plan["passed"]:
        head = (f"<b>PASS</b>: every given limit is met pulling <b id='recommended'>{direction_label(plan, rec)}</b> "
                f"(pull force {pull}), recommended as the passing direction with the lower maximum tension.")
        limits_given = plan.get("limits_checked", bool(checked))
        if not limits_given:
            head = (f"<b>Limits not checked</b> (no [limits] given); the lower maximum tension is pulling "
                    f"<b id='recommended'>{direction_label(plan, rec)}</b> (pull force {pull}).")
        fails = [f"{direction_label(plan, n)} fails: " + "; ".join(_check_phrase(c, units) for c in
                                                                     plan["directions"][n]["checks"] if not c["passed"])
                 for n in ("forward", "reverse") if not plan["directions"][n]["passed"]]
        body = head + "".join(f"<br>{html.escape(x)}" for x in fails)
        css = "ok" if limits_given else "bad"
    else:
        fails = [f"{direction_label(plan, n)} fails: " + "; ".join(_check_phrase(c, units) for c in
                                                                     plan["directions"][n]["checks"] if not c["passed"])
                 for n in ("forward", "reverse")]
        body = ("<b>FAIL</b>: no direction meets every given limit; do not pull as planned. "
                + "".join(f"<br>{html.escape(x)}" for x in fails)
                + f"<br>Lower maximum tension: <b id='recommended'>{direction_label(plan, rec)}</b> (pull force {pull}).")
        css = "bad"
    if checked:
        body += f"<br>Checked: {html.escape(', '.join(checked))}."
    if not_checked:
        body += (f"<br><span class='unchecked'>Not checked (no limit given): {html.escape(', '.join(not_checked))}"
                 "</span>.")
    return css, body


def _meta_rows(plan: dict, meta: dict) -> list[tuple[str, str]]:
    inp, v = plan["inputs"], plan.get("versions", {})
    blank = "________________"
    rows = [("Project", meta.get("project") or blank), ("Engineer", meta.get("engineer") or blank),
            ("Revision", meta.get("revision") or blank), ("Date", meta.get("date") or blank),
            ("Scenario", f"{inp['scenario']}" + (f": {inp['description']}" if inp.get("description") else "")),
            ("Scenario file", meta.get("scenario_file") or inp.get("scenario_file") or "–"),
            ("Engine", f"{plan['engine']}: {engine_note(plan)}"),
            ("Software", f"exucable {v.get('exucable', '?')} (Exudyn {v.get('exudyn', '?')}, numpy "
                         f"{v.get('numpy', '?')}, Python {v.get('python', '?')})")]
    return rows


def _checks_table(plan: dict, name: str, units: str) -> str:
    rows = []
    for c in plan["directions"][name]["checks"]:
        value, limit, unit = check_in_units(c, units)
        result = "<span class='pass'>pass</span>" if c["passed"] else "<span class='fail'>FAIL</span>"
        rows.append([c["name"], result, value, limit, unit,
                     None if c["margin"] is None else f"{100 * c['margin']:.1f} %", c["where"]])
    for c in plan["directions"][name].get("not_checked", []):
        rows.append([c["name"], "<span class='unchecked'>not checked</span>" if c["why"].startswith("not checked")
                     else "n/a", None, None, "", None, c["why"]])
    return _table(["check", "result", "value", "limit", "unit", "margin", "where / why"], rows,
                  left=(0, 1, 4, 6), table_id=f"checks-{name}", raw=(1,), wrap=(6,))


def plan_report_html(plan: dict, title: str, route_png: bytes | None = None, units: str = "si",
                     meta: dict | None = None) -> str:
    """The report page as one HTML string.

    Parameters
    ----------
    plan : dict
        What :func:`exucable.plan.pull.plan_pull` returned.
    title : str
        Scenario name.
    route_png : bytes, optional
        The route's picture (``exucable.plots.route.plot_route``, in the report's units), inlined.
    units : {"si", "imperial"}
        Display units of the tables and figures.
    meta : dict, optional
        Title block: ``project``, ``engineer``, ``revision``, ``date`` (strings), ``scenario_file``; the
        missing ones print as blanks to fill in by hand.
    """
    meta = meta or {}
    f = display_unit("force", units)
    css, verdict = _verdict(plan, units)
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>Pull plan: {html.escape(title)}"
             f"</title><style>{_CSS}</style></head><body>",
             f"<h1>Cable pull plan: {html.escape(title)}</h1>",
             "<table class='meta' id='title-block'>" + "".join(
                 f"<tr><th>{html.escape(k)}</th><td>{html.escape(str(v))}</td></tr>" for k, v in _meta_rows(plan, meta))
             + "</table>",
             f"<div class='verdict {css}' id='verdict'>{verdict}</div>",
             f"<p class='note'>{plan['count']} cable(s), arrangement {html.escape(plan['arrangement'])}"
             f"{html.escape(simulated_arrangement_phrase(plan))}, weight "
             f"correction factor {fmt_number(plan['weight_correction_factor'])}, jam ratio "
             f"{fmt_number(plan['jam_ratio'])} (risk: {html.escape(plan['jam_risk'])}), clearance "
             f"{fmt_number(from_si(plan['clearance_m'], 'length', units, small=True))} "
             f"{display_unit('length', units, small=True)}, conduit fill {fmt_number(plan['fill_percent'], 10.0)} % "
             "(NEC Chapter 9 Table 1 allows 53 % for one cable, 31 % for two, 40 % for more; checked only against "
             "limits.max_fill).</p>"]
    for name in ("forward", "reverse"):
        parts += [f"<div class='block'><h2>Checks, {html.escape(direction_label(plan, name))} pull</h2>",
                  _checks_table(plan, name, units), "</div>"]
    # each heading travels with what it heads (div.block: no page break inside when printed)
    if route_png:
        parts += ["<div class='block'><h2>Route</h2>", _figure(base64.b64encode(route_png).decode("ascii"), "route",
                                                               "The route with its points named as in the tables.",
                                                               "route"), "</div>"]
    parts += ["<div class='block'><h2>Tension along the route</h2>",
              _figure(_tension_figure(plan, units), "tension along the route",
                      "Both directions on one axis: the distance along the route from its first point; bends "
                      "shaded, points named on top.", "tension"), "</div>"]
    sw = _swbp_figure(plan, units, next((c["limit"] for c in plan["checks"]
                                         if c["name"] == "max_sidewall_pressure"), None))
    if sw:
        parts += ["<div class='block'><h2>Sidewall bearing pressure per bend</h2>",
                  _figure(sw, "sidewall bearing pressure per bend",
                          "Bends numbered in route order, the same bend side by side in both directions.", "swbp"),
                  "</div>"]
    for name in ("forward", "reverse"):
        d = plan["directions"][name]
        header, rows = section_rows(d, units)
        loads = ("<p class='note'>End point loads: the concentrated force where the stiff cable lands on the bend's "
                 "wall at each end, beyond the bend's distributed pressure (exucable/post/pressure.py). A negative "
                 "value: near that end the cable bears on the wall less than the distributed pressure would put "
                 "there (it lifts off); there is no concentrated load.</p>" if len(header) > 10 else "")
        parts += [f"<div class='block'><h2>Sections, {html.escape(direction_label(plan, name))} pull</h2>",
                  f"<p>Pull force {fmt_number(from_si(d['pull_force_N'], 'force', units))} {f}; max tension "
                  f"{fmt_number(from_si(d['max_tension_N'], 'force', units))} {f}; "
                  f"{'every given limit is met' if d['passed'] else 'a check fails'}"
                  f"{'; the cable runs slack somewhere (a downhill stretch steeper than the friction angle)' if d['slack'] else ''}"
                  ". Sections in pull order, numbered and named in route order.</p>",
                  "" if bundle_note(d, plan) is None else
                  f"<p class='note' id='simulated-{name}'>{html.escape(bundle_note(d, plan))}</p>",
                  f"<div id='sections-{name}'>" + _table(header, rows, left=(1, 3), table_id=f"sections-table-{name}")
                  + "</div>" + loads + "</div>"]
    if plan["directions"]["forward"].get("pull_in", {}).get("engine") == "steady":
        failed = sum(plan["directions"][n]["pull_in"]["failed_points"] for n in ("forward", "reverse"))
        parts += ["<h2 id='pull-in'>Pull-in history</h2><p>Tension at the rig while the cable's head advances from "
                  "the entrance (multibody model, pulling line taken frictionless): one steady state per head "
                  "position, the cable filling the route up to its head, each solved from the last; the rope's "
                  "tension at the same head positions beside"
                  f"{'' if not failed else f'; {failed} head positions whose solve failed are left out'}. Tables: "
                  "<code>pull_in_forward.csv</code>, <code>pull_in_reverse.csv</code>.</p>"]
    elif "pull_in" in plan["directions"]["forward"]:
        # The quasi-static rope integrates from the tail: with the head at x the rig pulls T(x) of the full
        # pull, so the history is the tension curve above read as "force at the rig vs pulled length".
        parts += ["<h2 id='pull-in'>Pull-in history</h2><p>Tension at the rig while the cable's head advances from "
                  "the entrance (rope, quasi-static, pulling line taken frictionless): with the head at a distance x "
                  "the rig pulls the rope's tension at x of the figure <i>Tension along the route</i>, read as force "
                  "against pulled length"
                  f"{'' if plan['engine'] == 'rope' else ' (from the rope with every engine)'}. Tables: "
                  "<code>pull_in_forward.csv</code>, <code>pull_in_reverse.csv</code>.</p>"]
    assumptions = ["The rope (every engine's reference) is perfectly flexible, EJ = 0, and lies on the duct's "
                   "centreline."]
    if plan["count"] > 1:
        assumptions.append(f"{plan['count']} cables: the rope carries the weight of all of them and the friction μ "
                           "times the weight correction factor; the SWBP is that of the most loaded cable "
                           "(reference/engineering.toml).")
    if plan["engine"] != "rope":
        assumptions.append("The multibody model uses E and EJ above; a cable's real EJ may differ from E·π·r⁴/4 by "
                           "an order of magnitude (stranded or layered cables): give cable.bending_stiffness from "
                           "the data sheet.")
    parts += ["<div class='block'><h2>Inputs and assumptions</h2>",
              _table(["input", f"value ({units})", "SI"], _input_rows(plan, units), left=(0, 1, 2), table_id="inputs",
                     wrap=(0, 1, 2)),
              "<ul class='note'>" + "".join(f"<li>{html.escape(a)}</li>" for a in assumptions) + "</ul></div>",
              "<div class='block'><h2>Sign-off</h2><table class='sign' id='sign-off'><tr><th class='l'>role</th>"
              "<th class='l'>name</th><th class='l'>signature</th><th class='l'>date</th></tr>"
              + "".join(f"<tr><td class='l'>{r}</td><td></td><td></td><td></td></tr>"
                        for r in ("prepared", "checked", "approved")) + "</table></div>",
              "<p class='note'>Generated by exucable plan. SI values in plan.json and the CSV files beside this "
              "page.</p>",
              "</body></html>"]
    return "\n".join(parts)


_BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable", "chrome")


def find_browser() -> str | None:
    """Path of a Chromium-family browser that can run headless (``$EXUCABLE_BROWSER`` first), or None."""
    own = os.environ.get("EXUCABLE_BROWSER")
    if own:
        return shutil.which(own) or (own if Path(own).is_file() else None)
    for name in _BROWSERS:
        path = shutil.which(name)
        if path:
            return path
    return None


def report_pdf(page_html: str, paper: str = "A4", timeout_s: float = 120.0) -> bytes:
    """The report page printed to PDF by a headless Chromium (the browser's own print, so the PDF is the
    page as a browser shows and prints it; no Python PDF library renders this HTML and CSS as faithfully).

    Parameters
    ----------
    page_html : str
        What :func:`plan_report_html` returned.
    paper : {"A4", "Letter"}
        Paper size.
    timeout_s : float
        Longest the browser may take [s].

    Returns
    -------
    bytes
        The PDF.

    Raises
    ------
    ExucableError
        No browser found (naming how to install one), or the browser failed.
    """
    browser = find_browser()
    if browser is None:
        raise ExucableError("--pdf: needs Chromium or Chrome on PATH (Debian/Ubuntu: apt-get install chromium; "
                            "or set EXUCABLE_BROWSER), or print report.html from a browser")
    page = page_html.replace("@page{margin:14mm}", f"@page{{size:{paper};margin:14mm}}")
    with tempfile.TemporaryDirectory(prefix="exucable-pdf-") as tmp:
        src, out = Path(tmp) / "report.html", Path(tmp) / "report.pdf"
        atomic_write_text(src, page)              # a scratch copy for the browser, deleted with the folder
        cmd = [browser, "--headless", "--disable-gpu", "--no-sandbox", f"--user-data-dir={tmp}/profile",
               "--no-pdf-header-footer", f"--print-to-pdf={out}", src.as_uri()]
        try:
            done = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s)
        except subprocess.TimeoutExpired:
            raise ExucableError(f"--pdf: {browser} did not finish within {timeout_s:.0f} s") from None
        if not out.is_file() or out.stat().st_size == 0:
            tail = (done.stderr or done.stdout).strip().splitlines()[-1:] or ["no output"]
            raise ExucableError(f"--pdf: {browser} made no PDF (exit {done.returncode}: {tail[0]})")
        return out.read_bytes()
