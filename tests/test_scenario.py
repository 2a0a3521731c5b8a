"""Scenario files: validation (every error names its key), defaults, round trip, CSV routes,
and the shipped scenario files."""

from __future__ import annotations

import copy
import dataclasses
import math
from pathlib import Path

import pytest

from exucable.errors import ScenarioError
from exucable.scenario.specs import Scenario, load_scenario, parse_scenario

SCENARIOS = Path(__file__).resolve().parent.parent / "scenarios"
SCENARIO_FILES = sorted(SCENARIOS.glob("*.toml")) + sorted((SCENARIOS / "fast").glob("*.toml"))


def base() -> dict:
    """A small valid scenario: straight 1 m, 90° bend R 0.5 m, straight 1 m."""
    return {
        "name": "t",
        "cable": {"radius": 0.0025, "density": 1000.0, "youngs_modulus": 1.0e9, "elements": 10},
        "conduit": {
            "inner_radius": 0.0035,
            "path": [
                {"straight": 1.0},
                {"bend": 90.0, "radius": 0.5, "turn": "left"},
                {"straight": 1.0},
            ],
        },
        "pull": {"speed": 0.1},
        "solver": {"end_time": 1.0, "step": 1.0e-2},
    }


def survey() -> dict:
    d = base()
    d["conduit"] = {"inner_radius": 0.0035, "points": [[0, 0, 0], [2, 0, 0], [2, 2, 0]], "bend_radius": 0.5}
    return d


_DELETE = object()


def with_(d: dict, path: tuple, value) -> dict:
    """Copy of ``d`` with the item at ``path`` (keys/indices) set to ``value`` (or deleted)."""
    d = copy.deepcopy(d)
    node = d
    for k in path[:-1]:
        node = node[k]
    if value is _DELETE:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return d


def parse(d: dict, base_dir: Path = Path(".")) -> Scenario:
    return parse_scenario(d, base_dir)


# (id, scenario dict, expected key, fragment expected in the message or None)
BAD = [
    # unknown keys anywhere
    ("top-unknown", with_(base(), ("colour",), "red"), "colour", "unknown key"),
    ("cable-unknown", with_(base(), ("cable", "raduis"), 1.0), "cable.raduis", "did you mean 'radius'"),
    ("contact-unknown", with_(base(), ("contact",), {"mu": 0.2}), "contact.mu", "unknown key"),
    ("path-item-unknown", with_(base(), ("conduit", "path", 0, "radius"), 1.0), "conduit.path[0].radius", "unknown"),
    ("solver-unknown", with_(base(), ("solver", "tol"), 1e-3), "solver.tol", "unknown"),
    # missing required keys and tables
    ("no-cable", with_(base(), ("cable",), _DELETE), "cable", "required"),
    ("no-radius", with_(base(), ("cable", "radius"), _DELETE), "cable.radius", "required"),
    ("elements-and-length", with_(base(), ("cable", "element_length"), 0.1), "cable.element_length", "not both"),
    ("element-length-zero", with_(with_(base(), ("cable", "elements"), _DELETE), ("cable", "element_length"), 0.0),
     "cable.element_length", "> 0"),
    ("elements-float-zero", with_(base(), ("cable", "elements"), 0.0), "cable.elements", "integer"),
    ("no-speed", with_(base(), ("pull", "speed"), _DELETE), "pull.speed", "required"),
    ("no-end-time", with_(with_(base(), ("solver", "mode"), "dynamic"), ("solver", "end_time"), _DELETE),
     "solver.end_time", "required in dynamic mode"),
    ("no-end-time-snapshots", with_(with_(base(), ("solver", "end_time"), _DELETE), ("output",), {"snapshots": [0.1]}),
     "solver.end_time", "snapshots need the time integration"),
    ("no-inner-radius", with_(base(), ("conduit", "inner_radius"), _DELETE), "conduit.inner_radius", "required"),
    # wrong types
    ("radius-bool", with_(base(), ("cable", "radius"), True), "cable.radius", "must be a number"),
    # a quantity may carry its unit ("2.5 mm"); a string that is no quantity is refused with the key
    ("radius-string", with_(base(), ("cable", "radius"), "thick"), "cable.radius", "cannot read 'thick' as a quantity"),
    ("radius-wrong-unit", with_(base(), ("cable", "radius"), "2.5 N"), "cable.radius", "is a force, but this key is a length"),
    ("elements-float", with_(base(), ("cable", "elements"), 10.0), "cable.elements", "integer"),
    ("gravity-not-table", with_(base(), ("gravity",), 9.8), "gravity", "table"),
    ("steady-stop-string", with_(base(), ("solver", "steady_stop"), "yes"), "solver.steady_stop", "true or false"),
    ("description-int", with_(base(), ("description",), 3), "description", "string"),
    ("start-short", with_(base(), ("conduit", "start"), [0.0, 0.0]), "conduit.start", "3 numbers"),
    ("start-string-item", with_(base(), ("conduit", "start"), ["a", 0, 0]), "conduit.start", "item 0"),
    ("heading-zero", with_(base(), ("conduit", "heading"), [0, 0, 0]), "conduit.heading", "nonzero"),
    ("path-item-not-table", with_(base(), ("conduit", "path", 0), 1.0), "conduit.path[0]", "table"),
    ("point-wrong-length", with_(survey(), ("conduit", "points", 1), [2, 0]), "conduit.points[1]", "3 numbers"),
    # non-finite
    ("E-nan", with_(base(), ("cable", "youngs_modulus"), math.nan), "cable.youngs_modulus", "finite"),
    ("E-inf", with_(base(), ("cable", "youngs_modulus"), math.inf), "cable.youngs_modulus", "finite"),
    # non-physical values
    ("radius-negative", with_(base(), ("cable", "radius"), -0.5), "cable.radius", "must be > 0 (m), got -0.5"),
    ("elements-zero", with_(base(), ("cable", "elements"), 0), "cable.elements", ">= 1"),
    ("damping-time-negative", with_(base(), ("cable", "damping_time"), -1.0), "cable.damping_time", ">= 0"),
    ("cable-longer-than-conduit", with_(base(), ("cable", "length"), 3.0), "cable.length", "centreline length"),
    ("inner-radius-below-cable", with_(base(), ("conduit", "inner_radius"), 0.002), "conduit.inner_radius", "0.0025"),
    ("inner-radius-equal-cable", with_(base(), ("conduit", "inner_radius"), 0.0025), "conduit.inner_radius",
     "cable radius"),
    ("bend-radius-negative", with_(base(), ("conduit", "path", 1, "radius"), -0.5), "conduit.path[1].radius",
     "must be > 0 (m), got -0.5"),
    ("bend-radius-below-conduit", with_(base(), ("conduit", "path", 1, "radius"), 0.003), "conduit.path[1].radius",
     "inner radius"),
    ("bend-angle-zero", with_(base(), ("conduit", "path", 1, "bend"), 0.0), "conduit.path[1].bend", "> 0"),
    ("straight-negative", with_(base(), ("conduit", "path", 0, "straight"), -1.0), "conduit.path[0].straight", "> 0"),
    ("turn-unknown", with_(base(), ("conduit", "path", 1, "turn"), "sideways"), "conduit.path[1].turn", '"left"'),
    ("turn-and-axis", with_(base(), ("conduit", "path", 1, "axis"), [0, 0, 1]), "conduit.path[1].axis", "not both"),
    ("neither-turn-nor-axis", with_(base(), ("conduit", "path", 1, "turn"), _DELETE), "conduit.path[1].turn",
     "required"),
    ("axis-parallel-heading", with_(with_(base(), ("conduit", "path", 1, "turn"), _DELETE),
                                    ("conduit", "path", 1, "axis"), [1, 0, 0]), "conduit.path[1].axis", "parallel"),
    ("helix-turn-up", with_(base(), ("conduit", "path"), [{"helix_turns": 1.0, "radius": 1.0, "pitch": 0.1,
                                                            "turn": "up"}]), "conduit.path[0].turn", '"right"'),
    ("helix-zero-turns", with_(base(), ("conduit", "path"), [{"helix_turns": 0, "radius": 1.0, "pitch": 0.1}]),
     "conduit.path[0].helix_turns", "> 0"),
    ("helix-zero-pitch-2-turns", with_(base(), ("conduit", "path"), [{"helix_turns": 2, "radius": 1.0, "pitch": 0}]),
     "conduit.path[0].pitch", "pitch"),
    ("path-item-two-kinds", with_(base(), ("conduit", "path", 0), {"straight": 1.0, "bend": 90.0}),
     "conduit.path[0]", "one kind"),
    ("path-item-no-kind", with_(base(), ("conduit", "path", 0), {"radius": 1.0}), "conduit.path[0]",
     "exactly one of straight, bend, helix_turns"),
    ("path-empty", with_(base(), ("conduit", "path"), []), "conduit.path", "non-empty"),
    ("path-and-points", with_(base(), ("conduit", "points"), [[0, 0, 0], [1, 0, 0]]), "conduit.points", "only one"),
    ("no-route", with_(base(), ("conduit", "path"), _DELETE), "conduit.path", "required"),
    ("bend-radius-with-path", with_(base(), ("conduit", "bend_radius"), 1.0), "conduit.bend_radius", "only used"),
    ("heading-with-points", with_(survey(), ("conduit", "heading"), [1, 0, 0]), "conduit.heading", "only used"),
    ("points-no-bend-radius", with_(survey(), ("conduit", "bend_radius"), _DELETE), "conduit.bend_radius",
     "required"),
    ("bend-radius-list-length", with_(survey(), ("conduit", "bend_radius"), [0.5, 0.5]), "conduit.bend_radius",
     "array of 1"),
    ("bend-radius-item-negative", with_(survey(), ("conduit", "bend_radius"), [-1.0]), "conduit.bend_radius[0]",
     "> 0"),
    ("fillet-does-not-fit", with_(survey(), ("conduit", "bend_radius"), 5.0), "conduit.points[1]", "fillet"),
    ("points-too-few", with_(survey(), ("conduit", "points"), [[0, 0, 0]]), "conduit.points", "at least 2"),
    ("csv-missing", with_(with_(survey(), ("conduit", "points"), _DELETE), ("conduit", "points_csv"),
                          "no_such_route.csv"), "conduit.points_csv", "not found"),
    ("max-angle-too-big", with_(base(), ("conduit", "max_segment_angle"), 50.0), "conduit.max_segment_angle",
     "<= 45"),
    ("max-angle-and-segments", with_(with_(base(), ("conduit", "max_segment_angle"), 1.0),
                                     ("conduit", "segments_per_bend"), 10), "conduit.segments_per_bend", "not both"),
    ("segments-per-bend-zero", with_(base(), ("conduit", "segments_per_bend"), 0), "conduit.segments_per_bend",
     ">= 1"),
    ("density-and-mass", with_(base(), ("cable", "mass_per_length"), 0.02), "cable.mass_per_length", "not both"),
    ("neither-density-nor-mass", with_(base(), ("cable", "density"), _DELETE), "cable.density", "mass_per_length"),
    ("friction-negative", with_(base(), ("contact",), {"friction": -0.1}), "contact.friction", ">= 0"),
    ("static-below-kinetic", with_(base(), ("contact",), {"friction": 0.3, "static_friction": 0.2}),
     "contact.static_friction", ">= the kinetic friction"),
    ("exponent-below-one", with_(base(), ("contact",), {"exponent": 0.5}), "contact.exponent", ">= 1"),
    ("stiffness-zero", with_(base(), ("contact",), {"stiffness": 0}), "contact.stiffness", "> 0"),
    ("check-points-zero", with_(base(), ("contact",), {"check_points_per_element": 0}),
     "contact.check_points_per_element", ">= 1"),
    ("check-point-rule", with_(base(), ("contact",), {"check_point_rule": "random"}), "contact.check_point_rule",
     '"gauss"'),
    ("broad-phase", with_(base(), ("contact",), {"broad_phase": "bvh"}), "contact.broad_phase", '"aabb"'),
    ("direction", with_(base(), ("pull", "direction"), "backward"), "pull.direction", '"reverse"'),
    ("speed-zero", with_(base(), ("pull", "speed"), 0.0), "pull.speed", "> 0 (m/s)"),
    ("back-tension-negative", with_(base(), ("pull", "back_tension"), -1.0), "pull.back_tension", ">= 0"),
    ("force-with-back-tension", with_(with_(base(), ("pull", "force"), 40.0), ("pull", "back_tension"), 10.0),
     "pull.force", "back_tension"),
    ("ramp-negative", with_(base(), ("pull", "ramp_time"), -0.1), "pull.ramp_time", ">= 0"),
    ("g-negative", with_(base(), ("gravity",), {"g": -9.8}), "gravity.g", ">= 0"),
    ("step-zero", with_(base(), ("solver", "step"), 0.0), "solver.step", "> 0"),
    ("min-step-above-step", with_(base(), ("solver", "min_step"), 0.1), "solver.min_step", "<= solver.step"),
    ("spectral-radius", with_(base(), ("solver", "spectral_radius"), 1.5), "solver.spectral_radius", "<= 1"),
    ("newton-zero", with_(base(), ("solver", "newton_max_iterations"), 0), "solver.newton_max_iterations", ">= 1"),
    ("name-empty", with_(base(), ("name",), " "), "name", "non-empty"),
]


@pytest.mark.parametrize("data, key, fragment", [c[1:] for c in BAD], ids=[c[0] for c in BAD])
def test_bad_input_names_its_key(data, key, fragment):
    with pytest.raises(ScenarioError) as info:
        parse(data)
    assert info.value.key == key, str(info.value)
    if fragment is not None:
        assert fragment in info.value.message, str(info.value)
    # the printed form starts with the key, so the CLI shows it
    assert str(info.value).startswith(f"{key}: ")


def test_bad_cases_are_many_and_distinct():
    assert len(BAD) >= 30
    assert len({c[0] for c in BAD}) == len(BAD)


def test_base_cases_are_valid():
    # the table above mutates these; they must be valid themselves
    parse(base())
    parse(survey())


# ---------------------------------------------------------------------------------------- files


def test_toml_syntax_error_names_line_and_file(tmp_path):
    f = tmp_path / "broken.toml"
    f.write_text('name = "x"\n[cable]\nradius = = 1\n')
    with pytest.raises(ScenarioError) as info:
        load_scenario(f)
    assert info.value.key == ""
    assert "line 3" in info.value.message
    assert "broken.toml" in info.value.message


def test_missing_file(tmp_path):
    with pytest.raises(ScenarioError) as info:
        load_scenario(tmp_path / "nope.toml")
    assert "not found" in str(info.value) and "nope.toml" in str(info.value)


def test_load_sets_default_name_and_source(tmp_path):
    text = """
[cable]
radius = 0.0025
mass_per_length = 0.02
youngs_modulus = 1e9
elements = 4
[conduit]
inner_radius = 0.0035
path = [{ straight = 2 }]
[pull]
speed = 0.1
[solver]
end_time = 1
step = 1e-2
"""
    f = tmp_path / "my_route.toml"
    f.write_text(text)
    s = load_scenario(f)
    assert s.name == "my_route"
    assert s.source_path == f.resolve()
    # ints accepted for floats, stored as floats
    assert isinstance(s.conduit.path[0].length_m, float) and s.conduit.path[0].length_m == 2.0
    assert isinstance(s.solver.end_time_s, float)


# ------------------------------------------------------------------------------------- defaults


def test_defaults_filled():
    s = parse(base())
    assert s.description == ""
    assert s.gravity is None
    assert s.cable.length_m is None
    assert s.cable.damping_time_s == 1.0e-3
    assert s.conduit.start_m == (0.0, 0.0, 0.0)
    assert s.conduit.heading == (1.0, 0.0, 0.0)
    assert s.conduit.max_segment_angle_deg == 1.0 and s.conduit.segments_per_bend is None
    c = s.contact
    assert (c.stiffness, c.damping, c.exponent, c.friction) == (1.0e6, 1.0e3, 1.5, 0.0)
    assert c.static_friction is None
    assert c.stribeck_velocity_m_per_s == 0.01
    assert c.friction_regularisation_velocity_m_per_s == pytest.approx(0.01 * s.pull.speed_m_per_s, rel=1e-15)
    assert c.check_points_per_element is None and c.check_point_rule == "gauss"   # None: the mesh rule
    assert c.reference_spacing_m == 1.0e-3 and c.broad_phase == "aabb"
    p = s.pull
    assert (p.direction, p.back_tension_N, p.force_N, p.ramp_time_s) == ("forward", 0.0, None, 0.0)
    v = s.solver
    assert v.min_step_s == 1.0e-8
    assert v.spectral_radius == 0.5 and v.newton_max_iterations == 8 and v.newton_tolerance == 1e-5
    assert v.output_interval_s == max(1.0e-2, 1.0 / 1000)
    assert v.steady_stop is False and v.steady_window_s == 0.2 and v.steady_tolerance == 1.0e-3
    assert v.pretension is True
    # the echo carries every default under its TOML name
    d = s.to_dict()
    assert "check_points_per_element" not in d["contact"]      # the mesh rule chooses (exucable.scenario.mesh)
    assert d["solver"]["output_interval"] == 1.0e-2
    assert d["conduit"]["max_segment_angle"] == 1.0
    assert d["cable"]["damping_time"] == 1.0e-3
    assert "gravity" not in d and "force" not in d["pull"] and "length" not in d["cable"]


def test_output_interval_default_follows_end_time():
    s = parse(with_(base(), ("solver", "end_time"), 100.0))
    assert s.solver.output_interval_s == 100.0 / 1000


def test_default_name_used_when_absent():
    s = parse_scenario(with_(base(), ("name",), _DELETE), Path("."), default_name="stem")
    assert s.name == "stem"


# ------------------------------------------------------------------------- cable properties


def test_density_gives_derived_properties():
    s = parse(base())
    c = s.cable
    # NOTES.md values for r = 2.5 mm, rho = 1000, E = 1e9, quoted to 5 significant digits -> rel 1e-4
    assert c.area_m2 == pytest.approx(1.9635e-5, rel=1e-4)
    assert c.mass_per_length_kg_per_m == pytest.approx(0.019635, rel=1e-4)
    assert c.axial_stiffness_N == pytest.approx(19635.0, rel=1e-4)
    assert c.bending_stiffness_N_m2 == pytest.approx(0.03068, rel=1e-3)  # quoted to 4 digits
    assert c.density_kg_per_m3 == 1000.0
    # damping = tau * stiffness, exactly by definition
    assert c.axial_damping_N_s == c.damping_time_s * c.axial_stiffness_N
    assert c.bending_damping_N_m2_s == c.damping_time_s * c.bending_stiffness_N_m2


def test_mass_per_length_instead_of_density():
    d = with_(with_(base(), ("cable", "density"), _DELETE), ("cable", "mass_per_length"), 0.05)
    s = parse(d)
    assert s.cable.density_kg_per_m3 is None
    assert s.cable.mass_per_length_kg_per_m == 0.05
    echo = s.to_dict()["cable"]
    assert echo["mass_per_length"] == 0.05 and "density" not in echo


def test_cable_length_defaults_to_conduit_and_may_be_shorter():
    s = parse(base())
    # 1 + pi/2 * 0.5 + 1: the centreline is exact arcs, round-off only
    assert s.cable_length_m == pytest.approx(2.0 + math.pi / 4, rel=1e-12)
    s2 = parse(with_(base(), ("cable", "length"), 2.0))
    assert s2.cable_length_m == 2.0


# --------------------------------------------------------------------------------- round trip


ROUND_TRIP = {
    "base": base(),
    "survey": survey(),
    "survey-radius-list": with_(with_(survey(), ("conduit", "points"), [[0, 0, 0], [2, 0, 0], [2, 2, 0], [4, 2, 1]]),
                                ("conduit", "bend_radius"), [0.5, 0.7]),
    "axis-bend-helix-everything": {
        "name": "full",
        "description": "all keys given",
        "cable": {"radius": 0.003, "mass_per_length": 0.03, "youngs_modulus": 2e9, "elements": 7, "length": 5.0,
                  "damping_time": 0.0},
        "conduit": {"inner_radius": 0.005, "start": [1, 2, 3], "heading": [0, 1, 0], "segments_per_bend": 12,
                    "path": [{"straight": 1.5}, {"bend": 30, "radius": 0.8, "axis": [0, 0, -1]},
                             {"bend": 20, "radius": 0.9, "turn": "down"},
                             {"helix_turns": 1.5, "radius": 0.6, "pitch": -0.2, "turn": "right"}]},
        "contact": {"stiffness": 2e6, "damping": 50, "exponent": 1.0, "friction": 0.25, "static_friction": 0.3,
                    "stribeck_velocity": 0.02, "friction_regularisation_velocity": 2e-3,
                    "check_points_per_element": 9, "check_point_rule": "uniform", "reference_spacing": 2e-3,
                    "broad_phase": "none"},
        "pull": {"speed": 0.2, "direction": "reverse", "force": 12.0, "ramp_time": 0.05},
        "gravity": {"g": 9.81},
        "solver": {"end_time": 2, "step": 1e-3, "min_step": 1e-7, "spectral_radius": 0.8,
                   "newton_max_iterations": 12, "output_interval": 0.05, "steady_stop": True,
                   "steady_window": 0.3, "steady_tolerance": 1e-4, "pretension": False},
    },
}


def _plain(value) -> bool:
    """Only TOML-writable Python types."""
    if isinstance(value, dict):
        return all(isinstance(k, str) and _plain(v) for k, v in value.items())
    if isinstance(value, list):
        return all(_plain(v) for v in value)
    return isinstance(value, (str, bool, int, float))


@pytest.mark.parametrize("data", list(ROUND_TRIP.values()), ids=list(ROUND_TRIP))
def test_round_trip(data):
    s = parse(data)
    d = s.to_dict()
    assert _plain(d)
    again = parse(d)
    assert again == s
    assert again.to_dict() == d


def test_full_scenario_values_reach_the_dataclasses():
    s = parse(ROUND_TRIP["axis-bend-helix-everything"])
    assert s.conduit.start_m == (1.0, 2.0, 3.0)
    assert s.conduit.path[1].axis == (0.0, 0.0, -1.0) and s.conduit.path[1].turn is None
    assert s.conduit.path[3].pitch_m == -0.2 and s.conduit.path[3].turn == "right"
    assert s.contact.static_friction == 0.3
    assert s.pull.force_N == 12.0 and s.pull.direction == "reverse"
    assert s.gravity.g_m_per_s2 == 9.81
    assert s.solver.pretension is False and s.solver.steady_stop is True


def test_scenario_is_frozen_and_conduit_cached():
    s = parse(base())
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.name = "other"
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.cable.radius_m = 1.0
    assert s.build_conduit() is s.build_conduit()
    # the cache takes no part in equality or hashing
    assert parse(base()) == s and hash(parse(base())) == hash(s)


# ---------------------------------------------------------------------------------- CSV route


def _csv_scenario(tmp_path: Path, csv_text: str, extra: dict | None = None) -> Path:
    sub = tmp_path / "routes"
    sub.mkdir(exist_ok=True)
    (sub / "route.csv").write_text(csv_text)
    conduit = {"inner_radius": 0.0035, "points_csv": "route.csv", **(extra or {})}
    lines = ['name = "csv"', "[cable]", "radius = 0.0025", "density = 1000.0", "youngs_modulus = 1e9",
             "elements = 10", "[conduit]"]
    for k, v in conduit.items():
        lines.append(f"{k} = {v!r}" if not isinstance(v, str) else f'{k} = "{v}"')
    lines += ["[pull]", "speed = 0.1", "[solver]", "end_time = 1.0", "step = 0.01"]
    f = sub / "scn.toml"
    f.write_text("\n".join(lines) + "\n")
    return f


def test_csv_route_with_bend_radius_column(tmp_path):
    f = _csv_scenario(tmp_path, "x,y,z,bend_radius\n0,0,0,\n2,0,0,0.5\n2,2,0,\n")
    s = load_scenario(f)
    assert s.conduit.points_m == ((0.0, 0.0, 0.0), (2.0, 0.0, 0.0), (2.0, 2.0, 0.0))
    assert s.conduit.bend_radius_m == (0.5,)
    assert s.conduit.points_csv == str((f.parent / "route.csv").resolve())
    # two straights of 2 - R*tan(45°) = 1.5 m and a quarter circle of R = 0.5 m (exact arcs)
    assert s.cable_length_m == pytest.approx(3.0 + math.pi / 4, rel=1e-12)
    # round trip from another directory: the CSV path is absolute in the echo
    assert parse_scenario(s.to_dict(), tmp_path) == s


def test_csv_route_scenario_radius_overrides_column(tmp_path):
    f = _csv_scenario(tmp_path, "x,y,z,bend_radius\n0,0,0,\n2,0,0,0.5\n2,2,0,\n", {"bend_radius": 1.0})
    assert load_scenario(f).conduit.bend_radius_m == 1.0


def test_csv_route_needs_a_radius(tmp_path):
    f = _csv_scenario(tmp_path, "x,y,z\n0,0,0\n2,0,0\n2,2,0\n")
    with pytest.raises(ScenarioError) as info:
        load_scenario(f)
    assert info.value.key == "conduit.bend_radius" and "CSV" in info.value.message
    f = _csv_scenario(tmp_path, "x,y,z\n0,0,0\n2,0,0\n2,2,0\n", {"bend_radius": 0.5})
    assert load_scenario(f).conduit.bend_radius_m == 0.5


def test_csv_malformed_line_names_points_csv(tmp_path):
    f = _csv_scenario(tmp_path, "x,y,z\n0,0,0\n2,zero,0\n2,2,0\n", {"bend_radius": 0.5})
    with pytest.raises(ScenarioError) as info:
        load_scenario(f)
    assert info.value.key == "conduit.points_csv" and "line 3" in info.value.message


def test_csv_fillet_error_points_at_the_csv(tmp_path):
    f = _csv_scenario(tmp_path, "x,y,z\n0,0,0\n2,0,0\n2,2,0\n", {"bend_radius": 5.0})
    with pytest.raises(ScenarioError) as info:
        load_scenario(f)
    assert info.value.key == "conduit.points_csv" and "points[1]" in info.value.message


# ------------------------------------------------------------------------- shipped scenarios


def test_shipped_scenarios_exist():
    names = {p.name for p in SCENARIO_FILES if p.parent == SCENARIOS}
    fast = {p.name for p in SCENARIO_FILES if p.parent.name == "fast"}
    expected = {"paper_ex1_incline.toml", "paper_ex2_bend90.toml", "paper_ex3_helix.toml", "paper_ex4_spatial.toml"}
    assert expected <= names and expected <= fast


@pytest.mark.parametrize("path", SCENARIO_FILES, ids=[str(p.relative_to(SCENARIOS)) for p in SCENARIO_FILES])
def test_shipped_scenario_loads_and_round_trips(path):
    s = load_scenario(path)
    assert s.cable_length_m > 0
    assert s.build_conduit().segments.count >= 1
    assert parse_scenario(s.to_dict(), path.parent) == s
    # common paper parameters (Sect. 3)
    assert (s.cable.radius_m, s.conduit.inner_radius_m) == (0.0025, 0.0035)
    assert (s.cable.density_kg_per_m3, s.cable.youngs_modulus_Pa) == (1000.0, 1.0e9)
    assert (s.contact.stiffness, s.contact.damping, s.contact.exponent) == (1.0e6, 1.0e3, 1.5)
    assert s.pull.speed_m_per_s == 0.1


@pytest.mark.parametrize("stem", ["paper_ex1_incline", "paper_ex2_bend90", "paper_ex3_helix", "paper_ex4_spatial"])
def test_fast_variant_has_same_geometry_and_physics(stem):
    full = load_scenario(SCENARIOS / f"{stem}.toml")
    fast = load_scenario(SCENARIOS / "fast" / f"{stem}.toml")
    assert fast.conduit.path == full.conduit.path
    assert (fast.conduit.start_m, fast.conduit.heading) == (full.conduit.start_m, full.conduit.heading)
    assert fast.pull == full.pull and fast.gravity == full.gravity
    assert fast.cable_length_m == full.cable_length_m
    assert (fast.contact.friction, fast.contact.stiffness) == (full.contact.friction, full.contact.stiffness)
    assert fast.cable.elements < full.cable.elements
    assert 20 <= fast.contact.check_points_per_element <= 50
    assert fast.solver.steady_stop and fast.solver.end_time_s < full.solver.end_time_s
    assert fast.name != full.name


def test_paper_example_parameters():
    ex1 = load_scenario(SCENARIOS / "paper_ex1_incline.toml")
    # 30° incline: heading elevation atan2(z, x)
    hx, _, hz = ex1.conduit.heading
    assert math.degrees(math.atan2(hz, hx)) == pytest.approx(30.0, abs=1e-12)
    assert ex1.cable_length_m == 50.0 and ex1.build_conduit().centreline.length_m == pytest.approx(50.0, rel=1e-12)
    assert (ex1.cable.elements, ex1.contact.check_points_per_element, ex1.contact.friction) == (40, 400, 0.3)
    assert ex1.gravity.g_m_per_s2 == 9.8

    ex2 = load_scenario(SCENARIOS / "paper_ex2_bend90.toml")
    assert ex2.gravity is None and ex2.pull.back_tension_N == 150.0 and ex2.contact.friction == 0.2
    assert (ex2.cable.elements, ex2.conduit.segments_per_bend, ex2.contact.check_points_per_element) == (40, 100, 200)
    # turning angle beta = pi/2 (Eq. 26)
    assert ex2.build_conduit().centreline.turning_angle_rad == pytest.approx(math.pi / 2, rel=1e-12)

    ex3 = load_scenario(SCENARIOS / "paper_ex3_helix.toml")
    assert ex3.gravity is None and ex3.pull.force_N == 40.0 and ex3.contact.friction == 0.1
    assert (ex3.cable.elements, ex3.contact.check_points_per_element) == (80, 500)
    assert ex3.build_conduit().segments.count == 200 + 1          # the helix's 200 + the lead-in
    # lead-in 0.5 m + helix: 2 coils of sqrt((2 pi a)^2 + p^2), a = 1 m, p = 0.05 m
    assert ex3.cable_length_m == pytest.approx(0.5 + 2 * math.hypot(2 * math.pi, 0.05), rel=1e-12)
    # the lead-in is tangent-continuous with the helix
    assert ex3.build_conduit().centreline.tangent_jumps_rad().max() < 1e-9

    ex4 = load_scenario(SCENARIOS / "paper_ex4_spatial.toml")
    kinds = [type(p).__name__ for p in ex4.conduit.path]
    assert kinds.count("Straight") == 3 and kinds.count("Bend") == 3
    assert (ex4.cable.elements, ex4.conduit.segments_per_bend, ex4.contact.check_points_per_element) == (100, 80, 800)
    assert ex4.gravity.g_m_per_s2 == 9.8 and ex4.pull.back_tension_N == 20.0 and ex4.contact.friction == 0.3
    # 90° + 45° + 90° of turning
    assert math.degrees(ex4.build_conduit().centreline.turning_angle_rad) == pytest.approx(225.0, rel=1e-12)


def test_quantities_with_units_and_imperial_numbers_are_read_as_si():
    data = base()
    data["cable"]["radius"] = "2.5 mm"
    data["conduit"]["path"][0]["straight"] = "100 cm"
    sc = parse_scenario(data, Path("."))
    assert sc.cable.radius_m == pytest.approx(2.5e-3) and sc.conduit.path[0].length_m == pytest.approx(1.0)
    imperial = base()
    imperial["display"] = {"units": "imperial"}
    imperial["cable"]["radius"] = 0.1           # in
    imperial["conduit"]["inner_radius"] = 0.15  # in
    imperial["conduit"]["path"][0]["straight"] = 10.0  # ft
    imperial["pull"]["speed"] = 1.0             # ft/s
    sc = parse_scenario(imperial, Path("."))
    assert sc.cable.radius_m == pytest.approx(0.00254) and sc.conduit.path[0].length_m == pytest.approx(3.048)
    assert sc.pull.speed_m_per_s == pytest.approx(0.3048)
    # the echo reads back to the same scenario (quantities as exact SI strings)
    assert parse_scenario(sc.to_dict(), Path(".")) == sc
