"""Parameter sweeps (exucable.sweep): sweep files, validation, local pool vs Dask, kill and resume,
failures. The runs are small real cases (tests/data/sweep/tiny_bend.toml, about 2 s each).

Tables from two runs are compared for exact equality of every column except ``wall_time_s``:
the same scenario in a fresh process on the same machine is computed by the same code on the
same inputs, so its floats are bit-identical whatever process or scheduler ran it.
"""

from __future__ import annotations

import copy
import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from exucable import cli
from exucable.errors import ExucableError, ScenarioError
from exucable.sweep import load_sweep, parse_sweep, read_table, rows_from_disk, run_sweep
from exucable.scenario.dotted import format_key, parse_key, set_value, unset_value
from exucable.sweep.store import SweepLock

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data" / "sweep"
BASE = DATA / "tiny_bend.toml"
FRICTION4 = DATA / "friction4.toml"
FAILING = DATA / "failing.toml"
PHYSICS_COLUMNS = ("contact.friction", "case", "status", "pull_force_N", "rope_pull_force_N", "max_tension_N",
                   "max_sidewall_pressure_N_per_m", "message")


def _env(**extra) -> dict:
    """Environment for subprocesses and workers: the test runners importable."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(DATA), str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env.update(extra)
    return env


def _physics(rows):
    return [{k: r.get(k) for k in PHYSICS_COLUMNS} for r in rows]


def _final_case_dirs(out: Path) -> list[Path]:
    cases = out / "cases"
    return sorted(p for p in cases.iterdir() if p.is_dir() and not p.name.startswith(".")) if cases.is_dir() else []


# ------------------------------------------------------------------------------------------
# Dotted keys and sweep files (no runs)
# ------------------------------------------------------------------------------------------


def test_dotted_keys_round_trip_and_edit():
    toks = parse_key("conduit.path[1].helix_turns", "w")
    assert toks == ("conduit", "path", 1, "helix_turns")
    assert format_key(toks) == "conduit.path[1].helix_turns"
    data = {"conduit": {"path": [{"straight": 1.0}, {"helix_turns": 2.0}]}, "pull": {"force": 40.0}}
    set_value(data, toks, 5, "w")
    set_value(data, parse_key("gravity.g", "w"), 9.81, "w")   # a missing optional table is created
    unset_value(data, parse_key("pull.force", "w"), "w")
    assert data == {"conduit": {"path": [{"straight": 1.0}, {"helix_turns": 5}]}, "pull": {},
                    "gravity": {"g": 9.81}}
    with pytest.raises(ScenarioError) as e:
        set_value(data, parse_key("conduit.path[7].radius", "vary.x"), 1.0, "vary.x")
    assert e.value.key == "vary.x" and "index out of range" in e.value.message


def test_grid_cases_apply_values_in_order_and_hash_the_full_scenario():
    sw = parse_sweep({"base": str(BASE), "vary": {"contact.friction": [0.1, 0.3],
                                                  "pull.back_tension": [10.0, 20.0, 30.0]}}, DATA)
    assert sw.mode == "grid" and sw.keys == ("contact.friction", "pull.back_tension")
    assert [tuple(c.params.values()) for c in sw.cases] == [
        (0.1, 10.0), (0.1, 20.0), (0.1, 30.0), (0.3, 10.0), (0.3, 20.0), (0.3, 30.0)]
    for c in sw.cases:
        assert c.scenario.contact.friction == c.params["contact.friction"]
        assert c.scenario.pull.back_tension_N == c.params["pull.back_tension"]
        # the key is sha256 of the canonical JSON of the full scenario dict, first 16 hex digits
        canonical = json.dumps(c.scenario.to_dict(), sort_keys=True, separators=(",", ":"))
        assert c.case_id == hashlib.sha256(canonical.encode()).hexdigest()[:16]
    assert len(set(sw.case_ids())) == 6


def test_zip_unset_and_set_build_fig12_cases():
    """The fast Fig. 12 sweep: pull.force removed, back tension 10 N, coils with elements in step."""
    sw = load_sweep(ROOT / "scenarios" / "sweeps" / "fast" / "paper_fig12_coils.toml")
    assert sw.mode == "zip" and len(sw.cases) == 3
    for n, case in enumerate(sw.cases, start=1):
        sc = case.scenario
        assert sc.pull.force_N is None and sc.pull.back_tension_N == 10.0
        assert sc.conduit.path[1].turns == n and sc.cable.elements == 30 * n
    full = load_sweep(ROOT / "scenarios" / "sweeps" / "paper_fig12_coils.toml")
    assert [c.scenario.conduit.path[1].turns for c in full.cases] == [1, 2, 3, 4, 5]
    ex2 = load_sweep(ROOT / "scenarios" / "sweeps" / "ex2_friction.toml")
    assert [c.scenario.contact.friction for c in ex2.cases] == [0.1, 0.2, 0.3, 0.4]


@pytest.mark.parametrize("extra, key, fragment", [
    ({"vary": {"contact.friction": [0.1, 0.2, -0.3]}}, 'vary."contact.friction"[2]',
     "contact.friction: must be >= 0"),
    ({"vary": {"contact.frction": [0.1]}}, 'vary."contact.frction"[0]', "did you mean 'friction'"),
    ({"vary": {"conduit.path[1].radius": [0.5, 0.003]}}, 'vary."conduit.path[1].radius"[1]',
     "must be > the conduit inner radius"),
    ({"vary": {"conduit.path[9].radius": [0.5]}}, 'vary."conduit.path[9].radius"[0]', "index out of range"),
    ({"mode": "zip", "vary": {"contact.friction": [0.1, 0.2], "cable.elements": [8, 9, 10]}}, "vary",
     '"contact.friction": 2, "cable.elements": 3'),
    ({"vary": {"contact.friction": [0.1, 0.1]}}, "vary", "same scenario"),
    ({"set": {"pull.force": 10.0}, "vary": {"contact.friction": [0.1]}}, 'set."pull.force"',
     "cannot be combined with a nonzero pull.back_tension"),
    ({"unset": ["pull.forc"], "vary": {"contact.friction": [0.1]}}, "unset[0]", "not in the base scenario"),
    ({"mode": "cube", "vary": {"contact.friction": [0.1]}}, "mode", '"grid" or "zip"'),
    ({"output": "force", "vary": {"contact.friction": [0.1]}}, "output", "pull_force_N"),
    ({"vary": {}}, "vary", "required"),
])
def test_validation_errors_name_the_sweep_key(extra, key, fragment):
    data = {"base": str(BASE), **copy.deepcopy(extra)}
    with pytest.raises(ScenarioError) as e:
        parse_sweep(data, DATA)
    assert e.value.key == key
    assert fragment in e.value.message


def test_invalid_sweep_is_refused_before_anything_runs(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(f'base = "{BASE}"\n[vary]\n"contact.friction" = [0.1, -0.2]\n')
    out = tmp_path / "out"
    assert cli.main(["sweep", str(bad), "--out", str(out), "-q"]) == 2
    assert 'vary."contact.friction"[1]: contact.friction: must be >= 0' in capsys.readouterr().err
    assert not out.exists()


def test_missing_dask_is_a_clear_error(tmp_path, monkeypatch):
    sw = parse_sweep({"base": str(BASE), "vary": {"contact.friction": [0.1]}}, DATA)
    monkeypatch.setitem(sys.modules, "distributed", None)   # import distributed -> ImportError
    with pytest.raises(ExucableError, match=r"exucable\[dask\]"):
        run_sweep(sw, tmp_path / "out", scheduler="tcp://127.0.0.1:1")
    assert not (tmp_path / "out").exists()


def test_a_sweep_directory_is_locked_while_a_sweep_runs(tmp_path):
    sw = parse_sweep({"base": str(BASE), "vary": {"contact.friction": [0.1]}}, DATA)
    with SweepLock(tmp_path):
        with pytest.raises(ExucableError, match="another sweep is running"):
            run_sweep(sw, tmp_path, workers=1)


# ------------------------------------------------------------------------------------------
# Real runs
# ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def local_run(tmp_path_factory):
    """The 4-case friction sweep, uninterrupted, on the local pool with 2 workers."""
    out = tmp_path_factory.mktemp("local")
    rows = run_sweep(load_sweep(FRICTION4), out, workers=2, plots=False)
    return out, rows


def test_local_pool_writes_table_cases_and_plot(local_run):
    out, rows = local_run
    sw = load_sweep(FRICTION4)
    assert [r["case"] for r in rows] == sw.case_ids()
    assert all(r["status"] != "pending" for r in rows)
    table = read_table(out / "sweep.csv")
    assert list(table[0])[:3] == ["contact.friction", "case", "status"]
    assert _physics(table) == _physics(rows)
    assert [r["contact.friction"] for r in table] == [0.1, 0.15, 0.2, 0.25]
    for r in rows:
        d = out / "cases" / r["case"]
        rec = json.loads((d / "case.json").read_text())
        assert rec["params"] == {"contact.friction": r["contact.friction"]} and rec["status"] == r["status"]
        if r["status"] in ("ok", "steady"):
            assert json.loads((d / "summary.json").read_text())["status"] == r["status"]
    assert (out / "sweep.png").stat().st_size > 0
    # the table can be rebuilt from the directory alone
    assert _physics(rows_from_disk(out)) == _physics(rows)
    csv_text = (out / "sweep.csv").read_text()
    (out / "sweep.csv").unlink()
    assert cli.main(["sweep", str(FRICTION4), "--out", str(out), "--collect"]) == 0
    assert (out / "sweep.csv").read_text() == csv_text


def test_dry_run_lists_cases_and_writes_nothing(tmp_path, capsys):
    assert cli.main(["sweep", str(FRICTION4), "--out", str(tmp_path / "out"), "--dry-run"]) == 0
    text = capsys.readouterr().out
    assert "4 case(s)" in text and "4 to run" in text
    assert all(cid in text for cid in load_sweep(FRICTION4).case_ids())
    assert not (tmp_path / "out").exists()


def test_survey_csv_routes_travel_as_inline_points(tmp_path):
    """For Dask workers on other machines the CSV's points go inline; the route is the same."""
    from exucable.scenario.specs import parse_scenario
    from exucable.sweep.execute import _task

    (tmp_path / "route.csv").write_text("x,y,z,bend_radius\n0,0,0,\n2,0,0,0.5\n2,2,0,\n")
    base = tmp_path / "base.toml"
    base.write_text(BASE.read_text().replace(
        'segments_per_bend = 8\npath = [ { straight = 0.5 }, { bend = 90.0, radius = 0.5, turn = "left" }, '
        '{ straight = 0.5 } ]', 'segments_per_bend = 8\npoints_csv = "route.csv"'))
    sw = parse_sweep({"base": str(base), "vary": {"contact.friction": [0.1]}}, tmp_path)
    task = _task(sw, 0, sw.case_ids()[0], tmp_path / "cases", plots=False, portable=True)
    assert "points_csv" in task["scenario"]["conduit"] and "points_csv" not in task["portable_scenario"]["conduit"]
    moved = parse_scenario(task["portable_scenario"], Path("/nonexistent"))
    original = sw.cases[0].scenario
    assert moved.conduit.points_m == original.conduit.points_m
    assert moved.conduit.bend_radius_m == original.conduit.bend_radius_m
    a, b = moved.build_conduit().segments, original.build_conduit().segments
    assert (a.vertices_m == b.vertices_m).all()   # same inputs, same code: identical vertices


def test_dask_cluster_gives_the_same_table(local_run, tmp_path):
    distributed = pytest.importorskip("distributed")
    out_local, rows_local = local_run
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        rows = run_sweep(load_sweep(FRICTION4), tmp_path, scheduler=cluster.scheduler_address, plots=False)
    assert _physics(rows) == _physics(rows_local)
    assert _physics(read_table(tmp_path / "sweep.csv")) == _physics(read_table(out_local / "sweep.csv"))
    # the worker's files were shipped back and installed here
    for r in rows:
        assert (tmp_path / "cases" / r["case"] / "case.json").is_file()


def test_killed_sweep_resumes_without_rerunning_finished_cases(local_run, tmp_path):
    _, rows_local = local_run
    out = tmp_path / "out"
    log = tmp_path / "runs.log"
    cmd = [sys.executable, "-m", "exucable", "sweep", str(FRICTION4), "--out", str(out), "--workers", "2",
           "--no-plots", "-q", "--runner", "sweep_runners:counting_runner"]
    env = _env(EXUCABLE_TEST_RUN_LOG=str(log))
    proc = subprocess.Popen(cmd, env=env, cwd=tmp_path, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    try:
        while len(_final_case_dirs(out)) < 2:
            assert proc.poll() is None, proc.stderr.read().decode()
            assert time.monotonic() < deadline, "no case finished within 120 s"
            time.sleep(0.02)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)   # the sweep and its workers, at once
        proc.wait()
    finished = {p.name: p for p in _final_case_dirs(out)}
    assert 2 <= len(finished) < 4, f"the kill must come before the end of the sweep: {sorted(finished)}"
    before = {cid: ((p / "case.json").stat().st_ino, (p / "case.json").stat().st_mtime_ns,
                    (p / "case.json").read_bytes()) for cid, p in finished.items()}

    res = subprocess.run(cmd, env=env, cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert res.returncode in (0, 1), res.stdout + res.stderr
    for cid, (ino, mtime, content) in before.items():
        st = (out / "cases" / cid / "case.json").stat()
        assert (st.st_ino, st.st_mtime_ns) == (ino, mtime)
        assert (out / "cases" / cid / "case.json").read_bytes() == content
    runs = log.read_text().split()
    for cid in finished:
        assert runs.count(cid) == 1, f"finished case {cid} was run again"
    assert set(runs) == {r["case"] for r in rows_local}
    table = read_table(out / "sweep.csv")
    assert _physics(table) == _physics(rows_local), (res.stdout, runs)
    assert not [p for p in (out / "cases").iterdir() if p.name.startswith(".")], "temporary dirs left"


def test_failing_cases_are_recorded_and_the_rest_complete(tmp_path):
    sw = load_sweep(FAILING)
    rows = run_sweep(sw, tmp_path, workers=2, plots=False)
    ok, diverged, refused = rows
    assert ok["status"] in ("ok", "steady") and ok["message"] == ""
    assert diverged["status"] == "failed" and "minimum step size" in diverged["message"]
    assert refused["status"] == "failed" and refused["message"].startswith("ModelError: cable.elements")
    table = read_table(tmp_path / "sweep.csv")
    assert [r["status"] for r in table] == [r["status"] for r in rows]
    assert table[2]["message"] == refused["message"]

    mtimes = {r["case"]: (tmp_path / "cases" / r["case"] / "case.json").stat().st_mtime_ns for r in rows}
    run_sweep(sw, tmp_path, workers=2, plots=False)                 # failed ones stay failed
    assert all((tmp_path / "cases" / c / "case.json").stat().st_mtime_ns == m for c, m in mtimes.items())
    again = run_sweep(sw, tmp_path, workers=2, plots=False, retry_failed=True)
    assert [r["status"] for r in again] == [r["status"] for r in rows]
    changed = {c for c, m in mtimes.items() if (tmp_path / "cases" / c / "case.json").stat().st_mtime_ns != m}
    assert changed == {diverged["case"], refused["case"]}


def test_dead_worker_is_rerun_then_recorded(tmp_path):
    """A case whose process is killed once (mu = 0.2) is rerun and finishes; one whose process
    dies every time (mu = 0.3) is recorded as failed with the signal; the others complete and
    the sweep does not hang. Stand-in runner: the kill is the point here."""
    sys.path.insert(0, str(DATA))   # workers get the parent's sys.path
    try:
        import sweep_runners
        sw = parse_sweep({"base": str(BASE), "vary": {"contact.friction": [0.1, 0.2, 0.3, 0.4]}}, DATA)
        rows = run_sweep(sw, tmp_path / "out", workers=2, runner=sweep_runners.dying_runner)
    finally:
        sys.path.remove(str(DATA))
    status = {r["contact.friction"]: r["status"] for r in rows}
    assert status == {0.1: "ok", 0.2: "ok", 0.3: "failed", 0.4: "ok"}
    dead = next(r for r in rows if r["contact.friction"] == 0.3)
    assert "process died 2 times" in dead["message"] and "SIGKILL" in dead["message"]
    assert (tmp_path / "out" / "died-once").exists()
