"""`exucable export` and snapshots: the discrete problem rebuilt from the files alone, snapshot
times and equilibrium, and the worked cross-check of examples/crosscheck_reader.py."""

from __future__ import annotations

import csv
import importlib.util
import json

import jsonschema
import numpy as np
import pytest

from exucable.errors import ScenarioError
from exucable.output.export import export_problem
from exucable.output.formats import EXPORT_FILES, SNAPSHOT_FILES, schema_of
from exucable.model.build import build_model
from exucable.output.results import read_csv
from exucable.run import run_scenario
from exucable.scenario.specs import load_scenario, parse_scenario

from conftest import ROOT

_spec = importlib.util.spec_from_file_location("crosscheck_reader", ROOT / "examples" / "crosscheck_reader.py")
reader = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(reader)

EX2 = ROOT / "scenarios/fast/paper_ex2_bend90.toml"
SNAPSHOTS_S = [0.1234567, 0.25, 0.3]


def _rows(path):
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            yield {k: (int(v) if v.lstrip("-").isdigit() else float(v)) for k, v in row.items()}


def _validate_dir(directory, names):
    for name in names:
        schema = schema_of(name)
        jsonschema.Draft202012Validator.check_schema(schema)
        validator = jsonschema.Draft202012Validator(schema)
        if name.endswith(".json"):
            validator.validate(json.loads((directory / name).read_text()))
            continue
        n = 0
        for row in _rows(directory / name):
            validator.validate(row)
            n += 1
        assert n > 0, name


@pytest.fixture(scope="module")
def ex2_run(tmp_path_factory):
    """Fast Example 2 with snapshots, run and exported into one directory (as a user would)."""
    out = tmp_path_factory.mktemp("ex2")
    data = load_scenario(EX2).to_dict()
    data["output"] = {"snapshots": SNAPSHOTS_S}
    sc = parse_scenario(data, ROOT)
    res = run_scenario(sc, out, quiet=True, plots=False)
    export_problem(sc, out)
    return out, res


def test_export_files_follow_their_schemas(ex2_run):
    out, _ = ex2_run
    _validate_dir(out, list(EXPORT_FILES) + list(SNAPSHOT_FILES))
    p = json.loads((out / "problem.json").read_text())
    assert p["cable"]["axial_stiffness_N"] == pytest.approx(1e9 * np.pi * 0.0025**2, rel=1e-12)
    assert p["versions"]["exudyn"].startswith("1.13")


def test_schema_rejects_a_missing_column():
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate({"node": 0}, schema_of("nodes_initial.csv"))


@pytest.mark.parametrize("name, rtol", [
    # measured 3e-12 and 3e-11; Example 3, 8.5e-10: at its worst point the penetration agrees to
    # 4e-18 m, the rest is the damping term C·δ̇ with δ̇ = n·v, the small normal part of the 0.1 m/s
    # sliding speed, where n's round-off ε|P|/(R − r) ≈ 4e-13 is multiplied by C|v| = 100 N·s/m·m/s
    ("paper_ex2_bend90", 1e-9), ("paper_ex4_spatial", 1e-9), ("paper_ex3_helix", 1e-9),
    # Example 1's cable rests on a straight under its weight alone: δ ≈ 0.3 µm at coordinates up to
    # 50 m, so the round-off of P − Pc (ε·50 m ≈ 1e-14 m) is 3e-8 of δ; no two codes agree closer
    ("paper_ex1_incline", 1e-6),
    ("paper_ex2_bend90:reverse", 1e-9),
])
def test_rebuilt_initial_state_gives_exucables_contact_forces(tmp_path, name, rtol):
    name, _, direction = name.partition(":")
    sc = load_scenario(ROOT / f"scenarios/fast/{name}.toml")
    if direction:
        sc = sc.replace(**{"pull.direction": direction})
    export_problem(sc, tmp_path)
    _validate_dir(tmp_path, EXPORT_FILES)
    ex = reader.load_export(tmp_path)
    q, v = reader.node_state(ex["nodes_initial"])
    mine = reader.contact_forces(ex, q, v)["generalized_force"]
    model = build_model(sc)
    theirs = model.kernel.evaluate(model.layout.coordinates.reshape(-1), model.layout.velocities.reshape(-1))
    Q = theirs.generalized_force
    assert np.max(np.abs(Q)) > 0.1                       # the start is in contact
    assert np.max(np.abs(mine - Q)) <= rtol * np.max(np.abs(Q))


def test_snapshots_land_on_the_requested_times(ex2_run):
    out, res = ex2_run
    times = read_csv(out / "snapshot_times.csv")
    assert np.max(np.abs(times["time_s"] - SNAPSHOTS_S)) <= 1e-12
    assert np.all(times["step_start_s"] <= times["time_s"]) and np.all(times["time_s"] <= times["step_end_s"])
    for name in ("snapshot_nodes.csv", "snapshot_tension.csv", "snapshot_contact.csv"):
        t = read_csv(out / name)["time_s"]
        assert set(t) == set(times["time_s"]), name
    assert res.summary["snapshots_s"] == SNAPSHOTS_S and res.summary["snapshots_not_reached_s"] == []


def test_snapshot_tension_integrates_to_the_pulling_force(ex2_run):
    """At each snapshot of steady sliding: the tension at the leading end is the rig's pulling
    force, and back tension + the friction along the cable (no gravity here) add up to it, both
    within the run's own scatter of the pulling force (3 σ over its steady window)."""
    out, res = ex2_run
    s = res.summary
    tol = 3.0 * s["pull_force_std_N"]
    assert 0.0 < tol < 0.01 * s["pull_force_N"]
    times = read_csv(out / "snapshot_times.csv")
    T = read_csv(out / "snapshot_tension.csv")
    C = read_csv(out / "snapshot_contact.csv")
    checked = 0
    for t, F in zip(times["time_s"], times["pull_force_N"]):
        if t < s["steady_from_s"]:
            continue
        m = T["time_s"] == t
        e, xi, N = T["element"][m], T["xi"][m], T["tension_N"][m]
        lead = N[(e == e.max()) & (xi == 1.0)][0]
        trail = N[(e == 0) & (xi == 0.0)][0]
        friction = C["friction_force_N"][C["time_s"] == t].sum()
        assert abs(lead - F) <= tol
        assert abs(trail - 150.0) <= tol
        assert abs(trail + friction - F) <= tol
        checked += 1
    assert checked >= 2


def test_a_run_compared_with_itself_agrees_in_every_family(ex2_run):
    from exucable.output.compare import FAMILIES, compare_results

    out, _ = ex2_run
    result = compare_results(out, out, rtol=0.0)
    assert result["passed"] and result["notes"] == [] and result["skipped"] == []
    assert {c["kind"] for c in result["comparisons"]} == set(FAMILIES)
    assert all(c["max_abs"] == 0.0 for c in result["comparisons"])


def test_independent_reader_reproduces_the_snapshot_contact_forces(ex2_run):
    out, _ = ex2_run
    res = reader.first_snapshot_check(out)
    assert res["time_s"] == SNAPSHOTS_S[0]
    assert res["normal_force_N"] <= 1e-9 and res["friction_force_N"] <= 1e-9


def test_snapshot_times_are_checked(scenario_factory):
    with pytest.raises(ScenarioError, match=r"output\.snapshots\[1\]"):
        scenario_factory(output={"snapshots": [0.1, 5.0]})
    with pytest.raises(ScenarioError, match=r"output\.snapshot_interval"):
        scenario_factory(output={"snapshot_interval": 0.0})
    sc = scenario_factory(output={"snapshots": [0.05], "snapshot_interval": 0.1})
    assert sc.output.times_s(sc.solver.end_time_s) == pytest.approx((0.05, 0.1, 0.2))


def test_hermite_in_time_is_exact_for_a_cubic_and_at_step_ends():
    from exucable.output.snapshots import hermite_in_time

    def q(t):
        return np.array([1.0 - 2.0 * t + 3.0 * t**2 - 0.5 * t**3, 4.0 * t**3])

    def v(t):
        return np.array([-2.0 + 6.0 * t - 1.5 * t**2, 12.0 * t**2])

    t0, t1 = 0.3, 0.7
    for t in (0.3, 0.41, 0.5, 0.7):
        qi, vi = hermite_in_time(t, t0, q(t0), v(t0), t1, q(t1), v(t1))
        assert np.allclose(qi, q(t), rtol=0, atol=1e-14) and np.allclose(vi, v(t), rtol=0, atol=1e-13)
    q1, v1 = hermite_in_time(t1, t0, q(t0), v(t0), t1, q(t1), v(t1))
    assert np.array_equal(q1, q(t1)) and np.array_equal(v1, v(t1))


def test_export_command_writes_every_file_and_refuses_bad_input(tmp_path, capsys):
    from exucable.cli import main

    assert main(["export", str(EX2), str(tmp_path / "e")]) == 0
    assert sorted(p.name for p in (tmp_path / "e").iterdir()) == sorted(EXPORT_FILES)
    bad = tmp_path / "bad.toml"
    bad.write_text(EX2.read_text() + "\n[output]\nsnapshots = [-1.0]\n")
    assert main(["export", str(bad), str(tmp_path / "f")]) == 2
    assert "output.snapshots[0]" in capsys.readouterr().err
    assert not (tmp_path / "f").exists()
