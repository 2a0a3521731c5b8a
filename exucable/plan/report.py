"""The HTML page of ``exucable plan``: one self-contained file (inline PNG, no script, no network).

Sections: verdict and recommended direction, the route's picture, tension along the route in both
directions, SWBP per bend against its limit, the section tables, the checks, the pull-in history (if
computed) and the inputs. Values are shown in the plan's unit system (SI or imperial); the JSON and CSV
files beside the page stay SI.
"""

from __future__ import annotations

import base64
import html
import io

import numpy as np
from exucable.io import new_figure
from exucable.scenario.units import display_unit, from_si

__all__ = ["plan_report_html", "section_rows", "check_in_units"]

_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:2em auto;max-width:1100px;color:#222}
h1{font-size:1.6em;margin-bottom:.2em} h2{font-size:1.25em;border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:1.6em}
table{border-collapse:collapse;margin:.5em 0 1em 0;font-size:.92em} th,td{border:1px solid #ccc;padding:.25em .6em;text-align:right}
th{background:#f3f3f3} td.l,th.l{text-align:left} .pass{color:#11751b;font-weight:600} .fail{color:#b00020;font-weight:600}
.verdict{font-size:1.15em;padding:.6em 1em;border-radius:6px;display:inline-block}
.ok{background:#e6f4ea} .bad{background:#fde7e9} img{max-width:100%} .note{color:#555;font-size:.9em}
"""


def _png(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _img(b64: str, alt: str) -> str:
    return f'<img alt="{html.escape(alt)}" src="data:image/png;base64,{b64}">'


def _fmt(v, nd=4) -> str:
    if v is None:
        return "–"
    if isinstance(v, str):
        return html.escape(v)
    return f"{v:.{nd}g}"


def check_in_units(check: dict, units: str) -> tuple[float | None, float | None, str]:
    """(value, limit, unit) of a check in display units."""
    q = check.get("quantity")
    if q is None:
        return check["value"], check["limit"], ""
    dim, small = ("length", True) if q == "small_length" else (q, False)
    conv = (lambda v: None if v is None else from_si(v, dim, units, small))
    return conv(check["value"]), conv(check["limit"]), display_unit(dim, units, small)


def section_rows(direction: dict, units: str) -> tuple[list[str], list[list]]:
    """Header and rows of a direction's section table in display units (shared by the CLI and the page)."""
    f, fl, p, ln = (display_unit("force", units), display_unit("length", units),
                    display_unit("force_per_length", units), display_unit("length", units))
    header = ["#", "section", "plane / slope", f"length [{ln}]", f"radius [{ln}]", f"T in [{f}]", f"T out [{f}]",
              f"SWBP [{p}]", f"max T so far [{f}]"]
    # a multibody plan keeps the rope's values beside each section's
    beside = bool(direction["sections"]) and "rope_tension_out_N" in direction["sections"][0]
    if beside:
        header += [f"rope T out [{f}]", f"rope SWBP [{p}]", f"end point loads in/out [{f}]"]
    rows = []
    for r in direction["sections"]:
        if r["kind"] == "straight":
            where = f"slope {r['slope_deg']:+.3g}°"
            radius = None
        else:
            where = f"{r['plane']}, {r['angle_deg']:.4g}°"
            radius = from_si(r["radius_m"], "length", units)
        swbp = None if r["sidewall_pressure_N_per_m"] is None else from_si(r["sidewall_pressure_N_per_m"],
                                                                          "force_per_length", units)
        row = [r["index"], r["kind"], where, from_si(r["length_m"], "length", units), radius,
               from_si(r["tension_in_N"], "force", units), from_si(r["tension_out_N"], "force", units),
               swbp, from_si(r["max_tension_so_far_N"], "force", units)]
        if beside:
            rope_p = r["rope_sidewall_pressure_N_per_m"]
            loads = (None if "entry_point_load_N" not in r else
                     f"{from_si(r['entry_point_load_N'], 'force', units):.3g} / "
                     f"{from_si(r['exit_point_load_N'], 'force', units):.3g}")
            row += [from_si(r["rope_tension_out_N"], "force", units),
                    None if rope_p is None else from_si(rope_p, "force_per_length", units), loads]
        rows.append(row)
    del fl
    return header, rows


def _table(header, rows, left=(1, 2)) -> str:
    out = ["<table><tr>" + "".join(f'<th class="{"l" if i in left else ""}">{html.escape(str(h))}</th>'
                                   for i, h in enumerate(header)) + "</tr>"]
    for row in rows:
        out.append("<tr>" + "".join(f'<td class="{"l" if i in left else ""}">{_fmt(v)}</td>'
                                    for i, v in enumerate(row)) + "</tr>")
    out.append("</table>")
    return "\n".join(out)


def _tension_figure(plan: dict, units: str) -> str:
    fig = new_figure(figsize=(9.0, 4.0), dpi=100)
    ax = fig.add_subplot(111)
    for name, style in (("forward", "-"), ("reverse", "--")):
        prof = plan["directions"][name]["profile"]
        s = from_si(np.asarray(prof["s_m"]), "length", units)
        t = from_si(np.asarray(prof["tension_N"]), "force", units)
        line, = ax.plot(s, t, style, label=f"{name} (pull force {from_si(plan['directions'][name]['pull_force_N'], 'force', units):.4g})")
        rope = plan["directions"][name].get("rope_profile")
        if rope is not None:
            ax.plot(from_si(np.asarray(rope["s_m"]), "length", units), from_si(np.asarray(rope["tension_N"]), "force", units),
                    ":", color=line.get_color(), lw=1.0, label=f"{name}, rope")
    ax.set_xlabel(f"distance from the cable's tail along the route [{display_unit('length', units)}]")
    ax.set_ylabel(f"tension [{display_unit('force', units)}]")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    return _png(fig)


def _swbp_figure(plan: dict, units: str, limit_N_per_m) -> str | None:
    fig = new_figure(figsize=(9.0, 3.6), dpi=100)
    ax = fig.add_subplot(111)
    any_bend = False
    width = 0.38
    for k, name in enumerate(("forward", "reverse")):
        rows = [r for r in plan["directions"][name]["sections"] if r["sidewall_pressure_N_per_m"] is not None]
        if not rows:
            continue
        any_bend = True
        x = np.arange(len(rows)) + (k - 0.5) * width
        y = [from_si(r["sidewall_pressure_N_per_m"], "force_per_length", units) for r in rows]
        ax.bar(x, y, width, label=f"{name} (bends in pull order)")
    if not any_bend:
        return None
    n = max(sum(r["sidewall_pressure_N_per_m"] is not None for r in plan["directions"][d]["sections"])
            for d in ("forward", "reverse"))
    ax.set_xticks(range(n), [f"B{i + 1}" for i in range(n)])
    if limit_N_per_m is not None:
        ax.axhline(from_si(limit_N_per_m, "force_per_length", units), color="tab:red", lw=1.5, label="limit")
    ax.set_xlabel("bend, in pull order")
    ax.set_ylabel(f"SWBP [{display_unit('force_per_length', units)}]")
    ax.grid(alpha=0.3, axis="y")
    ax.legend()
    fig.tight_layout()
    return _png(fig)


# inputs and limits shown in both unit systems: key -> (dimension, cross-section length?)
_INPUT_DIMENSIONS = {
    "cable_diameter_m": ("length", True), "duct_inner_diameter_m": ("length", True),
    "weight_per_length_one_cable_N_per_m": ("force_per_length", False), "back_tension_N": ("force", False),
    "route_length_m": ("length", False), "max_tension": ("force", False), "grip_limit": ("force", False),
    "max_sidewall_pressure": ("force_per_length", False), "min_clearance": ("length", True),
}


def _input_rows(plan: dict, units: str) -> list[list]:
    """Rows (name, SI value with unit, value in ``units``) of the plan's inputs, limits included."""
    items = [(k, v) for k, v in plan["inputs"].items() if k != "limits"]
    items += [(f"limits.{k}", v) for k, v in plan["inputs"]["limits"].items()]
    rows = []
    for name, value in items:
        dim = _INPUT_DIMENSIONS.get(name.removeprefix("limits."))
        if dim is None or not isinstance(value, (int, float)):
            rows.append([name, str(value), str(value)])
            continue
        si = f"{value:.6g} {display_unit(dim[0], 'si', dim[1])}"
        shown = f"{from_si(value, dim[0], units, dim[1]):.6g} {display_unit(dim[0], units, dim[1])}"
        rows.append([name, si, shown])
    return rows


_ENGINE_NOTE = {
    "rope": "quasi-static rope, exucable.quasistatic.rope",
    "steady": "multibody model of the cable, steady sliding in one static solve per direction; the rope's "
              "values beside; SWBP: peak windowed pressure in each bend",
    "dynamic": "multibody model of the cable, dynamic run per direction (tensions of its last state, pull force "
               "averaged over its steady window); the rope's values beside; SWBP: peak windowed pressure in each bend",
}


def _verdict(plan: dict) -> str:
    """The report's one-line verdict; "not checked" where no limit was given."""
    if not plan["passed"]:
        return "A check fails in both directions"
    return "All checks pass" if plan.get("limits_checked", True) else "Limits not checked (no [limits] given)"


def plan_report_html(plan: dict, title: str, route_png: bytes | None = None, units: str = "si") -> str:
    """The report page as one HTML string.

    Parameters
    ----------
    plan : dict
        What :func:`exucable.plan.pull.plan_pull` returned.
    title : str
        Scenario name.
    route_png : bytes, optional
        The route's picture (``exucable.plots.route.plot_route``), inlined.
    units : {"si", "imperial"}
        Display units of the tables and figures.
    """
    f = display_unit("force", units)
    rec = plan["recommended_direction"]
    passed = plan["passed"]
    parts = [f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>exucable plan: {html.escape(title)}</title>"
             f"<style>{_CSS}</style></head><body>",
             f"<h1>Pull plan: {html.escape(title)}</h1>",
             f"<p class='verdict {'ok' if passed else 'bad'}' id='verdict'>"
             f"{_verdict(plan)} — recommended direction: "
             f"<b id='recommended'>{rec}</b>, pull force {from_si(plan['directions'][rec]['pull_force_N'], 'force', units):.4g} {f}</p>",
             f"<p class='note'>Engine: {plan['engine']} ({_ENGINE_NOTE[plan['engine']]}). {plan['count']} cable(s), "
             f"arrangement {plan['arrangement']}, weight correction factor {plan['weight_correction_factor']:.4g}, "
             f"jam ratio {plan['jam_ratio']:.3g} (risk: {plan['jam_risk']}), clearance "
             f"{from_si(plan['clearance_m'], 'length', units, small=True):.3g} {display_unit('length', units, small=True)}.</p>"]
    if route_png:
        parts += ["<h2>Route</h2>", _img(base64.b64encode(route_png).decode("ascii"), "route")]
    parts += ["<h2>Tension along the route</h2>", _img(_tension_figure(plan, units), "tension along the route")]
    sw = _swbp_figure(plan, units, None if not plan["checks"] else next(
        (c["limit"] for c in plan["checks"] if c["name"] == "max_sidewall_pressure"), None))
    if sw:
        parts += ["<h2>Sidewall bearing pressure per bend</h2>", _img(sw, "sidewall bearing pressure per bend")]
    for name in ("forward", "reverse"):
        d = plan["directions"][name]
        header, rows = section_rows(d, units)
        parts += [f"<h2>Sections, {name} pull</h2>",
                  f"<p>Pull force {from_si(d['pull_force_N'], 'force', units):.4g} {f}; max tension "
                  f"{from_si(d['max_tension_N'], 'force', units):.4g} {f}; "
                  f"{'all checks pass' if d['passed'] else 'a check fails'}"
                  f"{'; the cable runs slack somewhere (a downhill stretch steeper than the friction angle)' if d['slack'] else ''}.</p>",
                  f"<div id='sections-{name}'>" + _table(header, rows) + "</div>"]
    for name in ("forward", "reverse"):
        checks = plan["directions"][name]["checks"]
        parts.append(f"<h2>Checks, {name} pull</h2>")
        if not plan.get("limits_checked", True):
            parts.append("<p>Limits not checked: none given ([limits] in the scenario).</p>")
        if not checks:
            continue
        rows = []
        for c in checks:
            value, limit, unit = check_in_units(c, units)
            rows.append([c["name"], "<pass>" if c["passed"] else "<fail>", value, limit, unit,
                         None if c["margin"] is None else f"{100 * c['margin']:.1f} %", c["where"]])
        t = _table(["check", "result", "value", "limit", "unit", "margin", "where"], rows, left=(0, 1, 4, 6))
        t = t.replace("&lt;pass&gt;", "<span class='pass'>pass</span>").replace("&lt;fail&gt;", "<span class='fail'>FAIL</span>")
        parts.append(f"<div id='checks-{name}'>{t}</div>")
    if "pull_in" in plan["directions"]["forward"]:
        # The quasi-static rope integrates from the tail: with the head at x the rig pulls T(x) of the full
        # pull, so the history is the tension curve above read as "force at the rig vs pulled length".
        parts += ["<h2 id='pull-in'>Pull-in history</h2><p>Tension at the rig while the cable's head advances from "
                  "the entrance (rope, quasi-static, pulling line taken frictionless): with the head at a distance x "
                  "the rig pulls the rope's tension at x of the figure <i>Tension along the route</i>, read as force "
                  "against pulled length"
                  f"{'' if plan['engine'] == 'rope' else ' (from the rope with every engine)'}. Tables: "
                  "<code>pull_in_forward.csv</code>, <code>pull_in_reverse.csv</code>.</p>"]
    parts += ["<h2>Inputs</h2>", _table(["input", "SI", f"{units}"], _input_rows(plan, units), left=(0,)),
              "<p class='note'>Generated by exucable plan. SI values in plan.json and the CSV files beside this page.</p>",
              "</body></html>"]
    return "\n".join(parts)
