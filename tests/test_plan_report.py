"""The plan report an engineer signs: every check made or listed as not made, the failing check named,
bends named alike everywhere, engineering number formats, title block, print layout, fill; a screenshot
and a PDF where a headless Chromium is installed (skipped otherwise)."""

from __future__ import annotations

import json
import re
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest

from exucable.cli import main as cli_main
from exucable.errors import ScenarioError
from exucable.plan.pull import CHECKS, parse_plan_scenario, plan_pull
from exucable.plan.report import find_browser, fmt_number, plan_report_html
from exucable.quasistatic.engineering import conduit_fill_percent

ROOT = Path(__file__).resolve().parents[1]
COMMSCOPE = ROOT / "scenarios" / "industry" / "commscope_conquest_run_a_h.toml"


def _data(limits=None, **over):
    """A level route A–D: 100 m straight, a 90° bend R 2 m, 50 m straight; one cable."""
    data = {
        "name": "t",
        "cable": {"radius": 0.01, "mass_per_length": 2.0, "youngs_modulus": 1e9},
        "conduit": {"inner_radius": 0.05, "path": [{"straight": 100.0}, {"bend": 90.0, "radius": 2.0, "turn": "left"},
                                                   {"straight": 50.0}]},
        "contact": {"friction": 0.3},
        "pull": {"speed": 0.1, "back_tension": 100.0},
        "gravity": {"g": 9.80665},
        "solver": {"end_time": 0.1},
    }
    if limits:
        data["limits"] = limits
    for k, v in over.items():
        table, _, name = k.partition("__")
        data.setdefault(table, {})[name] = v
    return data


def _plan(limits=None, **over):
    scenario, spec = parse_plan_scenario(_data(limits, **over), ROOT)
    return plan_pull(scenario, spec, engine="rope"), spec.units      # the calculators' method: instant


class _Page(HTMLParser):
    """Ids, tables, images and the visible text of a page."""

    def __init__(self):
        super().__init__()
        self.ids, self.text, self.imgs, self.tables, self._skip = set(), [], [], {}, 0
        self._table = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "img":
            self.imgs.append(a.get("src", ""))
        if tag == "table":
            self._table = a.get("id")
            self.tables[self._table] = []
        if tag in ("style", "title"):
            self._skip += 1
        if tag == "tr" and self._table is not None:
            self.tables[self._table].append([])

    def handle_endtag(self, tag):
        if tag in ("style", "title"):
            self._skip -= 1
        if tag == "table":
            self._table = None

    def handle_data(self, data):
        if self._skip:
            return
        self.text.append(data)
        if self._table is not None and self.tables[self._table] and data.strip():
            # a cell's text (one chunk per cell: cells hold no markup but a span)
            self.tables[self._table][-1].append(data.strip())


def _page(plan, units="si", meta=None) -> _Page:
    page = _Page()
    page.feed(plan_report_html(plan, "t", None, units, meta=meta))
    return page


def test_engineering_number_formats():
    assert fmt_number(13530.4) == "13\u202f530" and fmt_number(340.0) == "340"
    assert fmt_number(2.743e-05, scale=66.66) == "0.00"          # a zero tension beside 66.66 lbf
    assert fmt_number(-4.358e-09, scale=1.0) == "0.000"          # never "-0.000"
    assert fmt_number(66.664) == "66.66" and fmt_number(0.715) == "0.715" and fmt_number(float("nan")) == "n/a"
    assert fmt_number(None) == "–"


def test_every_check_is_made_or_listed_as_not_made_and_the_verdict_says_so():
    plan, units = _plan({"max_tension": 20e3})
    page = _page(plan, units)
    verdict = " ".join(page.text)
    assert "PASS" in verdict and "Not checked (no limit given)" in verdict
    for name in ("forward", "reverse"):
        rows = page.tables[f"checks-{name}"][1:]
        assert {r[0] for r in rows} == set(CHECKS), name          # all eight, made or not
        made = [r for r in rows if r[1] == "pass"]
        assert [r[0] for r in made] == ["max_tension"]
        unchecked = {r[0] for r in rows if r[1] == "not checked"}
        assert unchecked == {"conductor_tension", "grip_tension", "max_sidewall_pressure", "min_bend_radius",
                             "min_clearance", "max_fill"}
    # no limits at all: nothing passes, and the verdict does not say "pass"
    plan, units = _plan()
    text = " ".join(_page(plan, units).text)
    assert "Limits not checked" in text and "PASS" not in text


def test_a_failure_in_both_directions_names_the_failing_check_and_recommends_nothing():
    plan, units = _plan({"max_tension": 500.0, "max_sidewall_pressure": 1e6})
    assert not plan["passed"]
    page = _page(plan, units)
    text = " ".join(page.text)
    assert "FAIL" in text and "no direction meets every given limit" in text and "recommended" not in text.lower()
    assert text.count("fails: max_tension") == 2
    # the failing value and limit are printed with their unit
    assert re.search(r"max_tension [\d\u202f.]+ N against 500 N at ", text)


def test_bends_and_sections_are_named_alike_in_both_directions():
    plan, units = _plan(display__point_names=["Manhole 1", "B", "C", "Vault 2"])
    fwd, rev = plan["directions"]["forward"]["sections"], plan["directions"]["reverse"]["sections"]
    assert [r["name"] for r in fwd] == ["Manhole 1–B", "B–C", "C–Vault 2"]
    assert [r["name"] for r in rev] == ["Vault 2–C", "C–B", "B–Manhole 1"]
    assert [r["bend_number"] for r in fwd] == [None, 1, None] and [r["bend_number"] for r in rev] == [None, 1, None]
    assert [r["route_index"] for r in rev] == [3, 2, 1]
    page = _page(plan, units)
    assert [r[1] for r in page.tables["sections-table-reverse"][1:]] == ["straight Vault 2–C", "bend C–B",
                                                                       "straight B–Manhole 1"]
    assert [r[0] for r in page.tables["sections-table-reverse"][1:]] == ["3", "2", "1"]   # route order numbers
    assert "reverse (Vault 2→Manhole 1)" in " ".join(page.text)
    # default names A, B, C, D
    assert _plan()[0]["point_names"] == ["A", "B", "C", "D"]


def test_point_names_of_the_wrong_count_name_the_key():
    with pytest.raises(ScenarioError) as exc:
        _plan(display__point_names=["A", "B"])
    assert exc.value.key == "display.point_names" and "4 points" in str(exc.value)
    with pytest.raises(ScenarioError) as exc:
        _plan(display__point_names=["A", "", "C", "D"])
    assert exc.value.key == "display.point_names[1]"


def test_fill_is_the_cross_section_ratio_and_is_checked_against_its_limit():
    # closed form: three 1 in cables in a 3 in duct fill 3 (1/3)^2 = 33.3 %
    assert conduit_fill_percent(3, 3.0, 1.0) == pytest.approx(100.0 / 3.0)
    plan, _ = _plan({"max_fill": 3.0})                      # one 20 mm cable in a 100 mm duct: 4 %
    check = next(c for c in plan["checks"] if c["name"] == "max_fill")
    assert check["value"] == pytest.approx(4.0) and not check["passed"]
    assert plan["fill_percent"] == pytest.approx(4.0)


def test_title_block_inputs_with_units_and_assumptions(tmp_path):
    meta = {"project": "Feeder 7", "engineer": "A. Engineer", "revision": "B", "date": "2026-12-01 20:00 UTC",
            "scenario_file": "/x/route.toml"}
    plan, units = _plan({"max_tension": 20e3})
    page = _page(plan, units, meta)
    block = dict(page.tables["title-block"])
    assert block["Project"] == "Feeder 7" and block["Engineer"] == "A. Engineer" and block["Revision"] == "B"
    assert block["Date"] == meta["date"] and block["Scenario file"] == "/x/route.toml"
    assert block["Software"].startswith(f"exucable {plan['versions']['exucable']}")
    inputs = {r[0]: r[1:] for r in page.tables["inputs"][1:]}
    assert inputs["cable outer diameter d"][0] == "0.02 m"          # never a raw key or a bare number
    assert inputs["cables in the duct"] == ["1"]
    assert any(k.startswith("bending stiffness EJ (E·π·r⁴/4") for k in inputs)
    assert "sign-off" in page.ids
    # no scientific notation anywhere in the visible text
    visible = " ".join(page.text)
    assert not re.search(r"\d[eE][-+]?\d", visible), re.findall(r"\S*\d[eE][-+]?\d\S*", visible)


def test_imperial_report_shows_feet_and_pounds_and_print_layout(tmp_path):
    out = tmp_path / "plan"
    assert cli_main(["plan", str(COMMSCOPE), "--out", str(out), "--project", "P", "--engineer", "E",
                     "--revision", "0"]) == 0
    html_text = (out / "report.html").read_text()
    page = _Page()
    page.feed(html_text)
    assert {"title-block", "verdict", "recommended", "checks-forward", "checks-reverse", "sections-forward",
            "sections-reverse", "route", "tension", "swbp", "inputs", "sign-off"} <= page.ids
    assert all(src.startswith("data:image/png;base64,") for src in page.imgs) and len(page.imgs) == 3
    text = " ".join(page.text)
    assert "forward (A→H)" in text and "reverse (H→A)" in text
    assert page.tables["sections-table-forward"][0][4:8] == ["length [ft]", "radius [ft]", "T in [lbf]",
                                                              "T out [lbf]"]
    inputs = {r[0]: r[1:] for r in page.tables["inputs"][1:]}
    assert inputs["cable outer diameter d"][0] == "0.715 in" and inputs["route length"][0].endswith(" ft")
    assert "@media print" in html_text and "break-after:avoid" in html_text and "max-width:182mm" in html_text
    plan = json.loads((out / "plan.json").read_text())
    assert plan["versions"]["exucable"] and plan["point_names"] == list("ABCDEFGH")


def _chromium_or_skip() -> str:
    browser = find_browser()
    if browser is None:
        pytest.skip("no headless Chromium/Chrome on PATH (Debian: apt-get install chromium)")
    return browser


def test_screenshot_and_pdf_of_the_report(tmp_path):
    """Where a headless browser is installed: the page renders (a non-blank screenshot as wide as the
    print column) and prints to a PDF of a few Letter pages."""
    browser = _chromium_or_skip()
    out = tmp_path / "plan"
    assert cli_main(["plan", str(COMMSCOPE), "--out", str(out), "--pdf"]) == 0
    pdf = (out / "report.pdf").read_bytes()
    assert pdf.startswith(b"%PDF")
    pages = len(re.findall(rb"/Type\s*/Page[^s]", pdf))
    assert 1 <= pages <= 6, pages
    shot = tmp_path / "shot.png"
    subprocess.run([browser, "--headless", "--disable-gpu", "--no-sandbox", f"--user-data-dir={tmp_path}/profile",
                    "--hide-scrollbars", "--window-size=1000,1400", f"--screenshot={shot}",
                    (out / "report.html").as_uri()], capture_output=True, timeout=120)
    from matplotlib.image import imread

    img = imread(shot)
    assert img.shape[0] >= 1000 and img.shape[1] == 1000
    assert float(img[..., :3].std()) > 0.05                  # not a blank page


def test_route_plan_view_labels_do_not_collide():
    """A level route in plan view, in feet: every point name and bend label inside the figure and clear
    of every other label (bounding boxes as drawn)."""
    from exucable.plan.pull import load_plan_scenario
    from exucable.plots.route import route_figure

    scenario, _ = load_plan_scenario(COMMSCOPE)
    fig = route_figure(scenario.build_conduit(), "t", "ft", 0.3048, list("ABCDEFGH"))
    ax = fig.axes[0]
    assert ax.name != "3d" and ax.get_xlabel() == "x [ft]"
    renderer = fig.canvas.get_renderer()
    fig.draw(renderer)
    boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in ax.texts]
    assert sorted(name for name, _ in boxes if len(name) == 1) == list("ABCDEFGH")
    assert sum(name.startswith("bend ") for name, _ in boxes) == 3
    frame = fig.bbox
    for i, (a, box_a) in enumerate(boxes):
        assert frame.x0 <= box_a.x0 and box_a.x1 <= frame.x1 and frame.y0 <= box_a.y0 and box_a.y1 <= frame.y1, a
        for b, box_b in boxes[i + 1:]:
            assert not box_a.overlaps(box_b), (a, b)


def test_pdf_without_a_browser_is_a_one_line_error_naming_the_fix(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("EXUCABLE_BROWSER", str(tmp_path / "no-such-browser"))
    assert find_browser() is None
    assert cli_main(["plan", str(COMMSCOPE), "--out", str(tmp_path / "plan"), "--pdf"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--pdf" in err and "apt-get install chromium" in err
    assert not (tmp_path / "plan").exists()                  # refused before anything was written
