"""The one field table (exucable.scenario.fields.FIELDS) drives the TOML parser, the checks of the
dataclasses built in Python, to_dict and the README key tables: walk it and check they agree."""

from __future__ import annotations

import copy
import dataclasses
from pathlib import Path

import pytest

from exucable.errors import ScenarioError
from exucable.scenario.specs import (
    CableSpec,
    ContactSpec,
    GravitySpec,
    PullSpec,
    Scenario,
    SolverSpec,
    default_elements,
    parse_scenario,
)
from exucable.scenario.fields import FIELDS, REQUIRED, SECTIONS, fields_of, markdown_table, readme_with_tables

README = Path(__file__).resolve().parent.parent / "scenarios" / "README.md"


def base() -> dict:
    return {
        "name": "t",
        "cable": {"radius": 0.0025, "density": 1000.0, "youngs_modulus": 1.0e9, "elements": 10},
        "conduit": {"inner_radius": 0.0035,
                    "path": [{"straight": 1.0}, {"bend": 90.0, "radius": 0.5, "turn": "left"}, {"straight": 1.0}]},
        "pull": {"speed": 0.1},
        "gravity": {"g": 9.8},
        "solver": {"end_time": 1.0, "step": 1.0e-2},
    }


def _table(d: dict, section: str) -> dict:
    return d if section == "" else d.setdefault(section, {})


def _bad_value(f):
    """A value that breaks the row's check."""
    if f.kind == "choice":
        return "nonsense"
    if f.kind == "bool":
        return "yes"
    if f.kind == "str":
        return 3
    if f.kind == "vector3":
        return [0.0, 0.0]
    if f.gt is not None:
        return f.gt
    if f.ge is not None:
        return f.ge - 1
    if f.lt is not None:
        return f.lt
    if f.le is not None:
        return f.le + 1
    return "not a number"


SCALAR = [f for f in FIELDS if f.kind != "custom"]


def test_readme_key_tables_are_the_field_table():
    text = README.read_text(encoding="utf-8")
    assert readme_with_tables(text) == text, (
        "scenarios/README.md key tables differ from exucable/scenario/fields.py: "
        "run `.venv/bin/python -m exucable.commands.key_tables`"
    )
    for section in SECTIONS:
        assert markdown_table(section) in text


@pytest.mark.parametrize("f", FIELDS, ids=[f.key for f in FIELDS])
def test_readme_row_names_key_unit_and_default(f):
    text = README.read_text(encoding="utf-8")
    rows = [r for r in text.splitlines() if r.startswith(f"| `{f.name}`")]
    assert rows, f"{f.key} has no README row"
    cells = [c.strip() for c in rows[0].strip("|").split("|")]
    assert cells[1] == f.readme_unit
    if f.default is REQUIRED and not f.default_doc:
        assert cells[2] == "required"


@pytest.mark.parametrize("f", SCALAR, ids=[f.key for f in SCALAR])
def test_parser_and_to_dict_agree_with_the_row(f):
    data = base()
    table = _table(data, f.section)
    table.pop(f.name, None)
    if f.key == "cable.density":  # one of density, mass_per_length is needed
        table["mass_per_length"] = 0.02
    if f.default is REQUIRED:
        with pytest.raises(ScenarioError) as info:
            parse_scenario(data, Path("."))
        assert info.value.key == f.key and "required" in info.value.message
        return
    sc = parse_scenario(data, Path("."))
    spec = sc if f.section == "" else getattr(sc, f.section)
    echo = sc.to_dict() if f.section == "" else sc.to_dict()[f.section]
    value = getattr(spec, f.attr)
    if f.key == "cable.mass_per_length":  # derived from density, which is echoed instead
        assert value == pytest.approx(1000.0 * sc.cable.area_m2) and f.name not in echo
    elif f.derived:
        assert value is not None and echo[f.name] == value
    elif f.default is None:
        assert value is None and f.name not in echo
    else:
        expect = tuple(f.default) if isinstance(f.default, tuple) else f.default
        assert value == expect
        assert echo[f.name] == (list(f.default) if isinstance(f.default, tuple) else f.default)
    # the given value reaches the attribute under the row's name, and round-trips
    assert parse_scenario(sc.to_dict(), Path(".")) == sc


def _python_base_spec(section):
    sc = parse_scenario(base(), Path("."))
    return sc if section == "" else getattr(sc, section)


@pytest.mark.parametrize("f", SCALAR, ids=[f.key for f in SCALAR])
def test_bad_value_same_error_from_toml_and_python(f):
    bad = _bad_value(f)
    data = base()
    _table(data, f.section)[f.name] = bad
    if f.key == "cable.mass_per_length":
        del data["cable"]["density"]
    if f.key == "conduit.segments_per_bend":
        del data["conduit"]  # not with max_segment_angle: a route without the default's rival
        data["conduit"] = {"inner_radius": 0.0035, "segments_per_bend": bad, "path": [{"straight": 1.0}]}
    with pytest.raises(ScenarioError) as from_toml:
        parse_scenario(data, Path("."))
    assert from_toml.value.key == f.key, str(from_toml.value)

    spec = _python_base_spec(f.section)
    changes = {f.attr: bad}
    if f.key == "conduit.segments_per_bend":
        changes["max_segment_angle_deg"] = None
    with pytest.raises(ScenarioError) as from_python:
        dataclasses.replace(spec, **changes)
    assert str(from_python.value) == str(from_toml.value)
    if f.section:
        with pytest.raises(ScenarioError) as from_replace:
            spec.replace(**{f.name: bad})
        assert from_replace.value.key == f.key


def test_issue_example_message():
    msg = "pull.speed: must be > 0 (m/s), got -0.1"
    for build in (lambda: PullSpec(speed_m_per_s=-0.1), lambda: PullSpec.from_keys(speed=-0.1)):
        with pytest.raises(ScenarioError) as info:
            build()
        assert str(info.value) == msg
    with pytest.raises(ScenarioError, match="pull.speed: required key is missing"):
        PullSpec()


def test_unknown_python_key_suggests_the_right_one():
    with pytest.raises(ScenarioError) as info:
        ContactSpec.from_keys(frictoin=0.2)
    assert info.value.key == "contact.frictoin" and "did you mean 'friction'" in info.value.message


def test_cross_field_rules_hold_in_python():
    with pytest.raises(ScenarioError, match="contact.static_friction"):
        ContactSpec(friction=0.3, static_friction=0.2)
    with pytest.raises(ScenarioError, match="pull.force"):
        PullSpec(speed_m_per_s=0.1, force_N=40.0, back_tension_N=10.0)
    with pytest.raises(ScenarioError, match="solver.min_step"):
        SolverSpec(end_time_s=1.0, step_s=1e-3, min_step_s=1e-2)
    with pytest.raises(ScenarioError, match="cable.density"):
        CableSpec(radius_m=0.0025, youngs_modulus_Pa=1e9)


def test_scenario_replace_dotted_keys_validates_and_rederives():
    sc = parse_scenario(base(), Path("."))
    sc2 = sc.replace(**{"contact.friction": 0.3, "conduit.path[1].radius": 0.8})
    assert sc2.contact.friction == 0.3 and sc2.conduit.path[1].radius_m == 0.8
    assert sc.contact.friction == 0.0  # frozen: the original is unchanged
    with pytest.raises(ScenarioError) as info:
        sc.replace(**{"conduit.path[1].radius": -0.5})
    assert str(info.value) == "conduit.path[1].radius: must be > 0 (m), got -0.5"
    # derived defaults follow the new values
    longer = sc.replace(**{"solver.end_time": 20.0})
    assert longer.solver.output_interval_s == 20.0 / 1000
    # a given value stays given
    assert sc.replace(**{"solver.end_time": 20.0, "solver.output_interval": 0.5}).solver.output_interval_s == 0.5
    assert sc.replace(gravity=None).gravity is None
    assert sc.with_(gravity=GravitySpec(g_m_per_s2=1.0)).gravity.g_m_per_s2 == 1.0


def test_default_elements_rule():
    data = base()
    del data["cable"]["elements"]
    sc = parse_scenario(data, Path("."))
    L = sc.cable_length_m
    centre = sc.build_conduit().centreline
    c = sc.conduit.inner_radius_m - sc.cable.radius_m
    # the mesh rule (exucable.scenario.mesh): chord sagitta ≤ 2 clearances, ≤ 0.2 rad per element
    R = centre.min_bend_radius_m
    h = min((16 * R * c) ** 0.5, 0.2 * R, L / 10)
    assert sc.cable.elements == default_elements(centre, c, L) == -(-int(L / h * 1e9) // int(1e9))
    assert "elements" in sc.cable.derived_keys
    assert default_elements(centre, c, L, element_length_m=L / 7) == 7
    with_length = dict(data, cable=dict(data["cable"], element_length=L / 12))
    assert parse_scenario(with_length, Path(".")).cable.elements == 12
    # a longer cable gets more elements when replaced
    data["conduit"]["path"][0]["straight"] = 3.0
    assert sc.replace(**{"conduit.path[0].straight": 3.0}).cable.elements > sc.cable.elements


def test_every_dataclass_attribute_has_a_row():
    for cls, section in ((CableSpec, "cable"), (ContactSpec, "contact"), (PullSpec, "pull"),
                         (GravitySpec, "gravity"), (SolverSpec, "solver")):
        attrs = {fl.name for fl in dataclasses.fields(cls)}
        assert attrs == {f.attr for f in fields_of(section)}, section
    assert {"name", "description"} <= {fl.name for fl in dataclasses.fields(Scenario)}
