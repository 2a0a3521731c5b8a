"""Sweeps after damage: a finished case whose files were damaged or deleted is run again, a killed
sweep leaves no case process computing on, and a re-run never deletes a live process's temporary
case directory. Stand-in runners (tests/data/sweep/sweep_runners.py): the bookkeeping is the point."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from exucable.io import pid_alive
from exucable.sweep import parse_sweep, run_sweep
from exucable.sweep.store import files_intact, read_record, remove_stale

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data" / "sweep"
BASE = DATA / "tiny_bend.toml"


@pytest.fixture
def runners():
    sys.path.insert(0, str(DATA))   # the workers get the parent's sys.path
    try:
        import sweep_runners
        yield sweep_runners
    finally:
        sys.path.remove(str(DATA))


def test_a_finished_case_with_damaged_files_is_run_again(tmp_path, runners):
    sw = parse_sweep({"base": str(BASE), "vary": {"contact.friction": [0.1, 0.2, 0.3]}}, DATA)
    out = tmp_path / "out"
    rows = run_sweep(sw, out, workers=2, runner=runners.quick_runner, plots=False)
    assert [r["status"] for r in rows] == ["ok"] * 3
    ids = sw.case_ids()
    dirs = [out / "cases" / c for c in ids]
    assert all(files_intact(d, read_record(d)) for d in dirs)
    assert read_record(dirs[0])["files"] == {"history.csv": (dirs[0] / "history.csv").stat().st_size,
                                             "summary.json": (dirs[0] / "summary.json").stat().st_size}
    (dirs[0] / "summary.json").write_text("{ corrupted")
    (dirs[1] / "summary.json").unlink()
    untouched = (dirs[2] / "case.json").stat().st_ino
    assert not files_intact(dirs[0], read_record(dirs[0])) and not files_intact(dirs[1], read_record(dirs[1]))
    rows = run_sweep(sw, out, workers=2, runner=runners.quick_runner, plots=False)
    assert [r["status"] for r in rows] == ["ok"] * 3
    for d in dirs[:2]:
        assert json.loads((d / "summary.json").read_text())["status"] == "ok"
        assert files_intact(d, read_record(d))
    assert (dirs[2] / "case.json").stat().st_ino == untouched           # intact: not run again


def test_temporary_case_dirs_of_live_processes_are_kept(tmp_path):
    cases = tmp_path / "cases"
    cases.mkdir()
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    live, gone = cases / f".0123456789abcdef.tmp-{os.getpid()}", cases / f".0123456789abcdef.tmp-{dead.pid}"
    aside = cases / f".fedcba9876543210.old-{dead.pid}"
    parent = cases / f".fedcba9876543210.tmp-{dead.pid}-parent"
    for d in (live, gone, aside, parent):
        d.mkdir()
    assert remove_stale(cases) == 3
    assert sorted(p.name for p in cases.iterdir()) == [live.name]


def test_a_killed_sweep_leaves_no_case_process_running(tmp_path):
    """SIGKILL to the sweep process alone (not its group): its case process, mid-case, dies
    within seconds instead of computing on as an orphan."""
    out = tmp_path / "out"
    sweep = tmp_path / "one.toml"
    sweep.write_text(f'base = {json.dumps(str(BASE))}\n[vary]\n"contact.friction" = [0.1]\n')
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(DATA), str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    cmd = [sys.executable, "-m", "exucable", "sweep", str(sweep), "--out", str(out), "--workers", "1",
           "--no-plots", "-q", "--runner", "sweep_runners:sleeping_runner"]
    proc = subprocess.Popen(cmd, env=env, cwd=tmp_path, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    case_pid = None
    try:
        deadline = time.monotonic() + 60
        while case_pid is None:
            assert proc.poll() is None, proc.stderr.read().decode()
            assert time.monotonic() < deadline, "the case did not start within 60 s"
            tmp = [p for p in (out / "cases").glob(".*.tmp-*")] if (out / "cases").is_dir() else []
            if tmp:
                case_pid = int(tmp[0].name.rsplit("-", 1)[1])
            time.sleep(0.05)
        assert pid_alive(case_pid)
        proc.send_signal(signal.SIGKILL)           # the sweep only
        proc.wait(timeout=10)
        deadline = time.monotonic() + 15
        while pid_alive(case_pid) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not pid_alive(case_pid), "the case process outlived its sweep"
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait(timeout=10)


def test_the_table_is_not_rewritten_after_every_case(tmp_path, runners, monkeypatch):
    """A sweep of n cases must not rewrite sweep.csv n times (O(n²) in all): while running it is
    refreshed at most every TABLE_REFRESH_S, and it is complete when the sweep ends."""
    import exucable.sweep.execute as execute
    writes = []
    real = execute.write_table

    def counting(path, rows, columns):
        writes.append(len(rows))
        real(path, rows, columns)

    monkeypatch.setattr(execute, "write_table", counting)
    monkeypatch.setattr(execute, "TABLE_REFRESH_S", 3600.0)     # no refresh can fall due in this test
    frictions = [round(0.01 * k, 2) for k in range(1, 41)]
    sw = parse_sweep({"base": str(BASE), "vary": {"contact.friction": frictions}}, DATA)
    rows = run_sweep(sw, tmp_path / "out", workers=2, runner=runners.quick_runner, plots=False)
    assert [r["status"] for r in rows] == ["ok"] * 40
    assert len(writes) == 2                      # the empty table when it starts, the whole one at its end
    with open(tmp_path / "out" / "sweep.csv") as f:
        assert sum(1 for _ in f) == 41           # a header and every case
