"""Where results go: names are never paths, a run owns its output directory (checked before the
solve, locked, an earlier run's files removed, no summary vouching for files a failed write left
out), and temporary files of writers killed mid-write are cleaned, those of live ones kept."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

import importlib
from exucable import cli
from exucable.errors import OutputError
from exucable.io import AtomicBatch, remove_stale_temporaries
from exucable.output.outdir import check_out_dir, name_as_path_part, owned_out_dir
from exucable.output.results import RunResult, write_results

xrun = importlib.import_module("exucable.run")   # the module (the package exports a function run)
ROOT = Path(__file__).resolve().parents[1]
TINY = ROOT / "tests" / "data" / "sweep" / "tiny_bend.toml"


def _scenario_file(tmp_path, name: str) -> Path:
    """tiny_bend.toml under another name (the name is what becomes a path)."""
    text = TINY.read_text().replace('name = "tiny-bend"', f"name = {json.dumps(name)}")
    path = tmp_path / "sc.toml"
    path.write_text(text)
    return path


def _dead_pid() -> int:
    """The pid of a process that has ended (reaped)."""
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


# ------------------------------------------------------------------------------------------
# Names are never paths
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name, part", [
    ("paper-ex2-bend90", "paper-ex2-bend90"),
    ("../../etc/evil", "etc_evil"),
    ("/tmp/abs", "tmp_abs"),
    ("..", "scenario"),
    ("-rf", "rf"),
    ("a b:c\\d", "a_b_c_d"),
    (".hidden", "hidden"),
    ("Kabel-Zug ä", "Kabel-Zug_ä"),
])
def test_a_name_becomes_one_safe_path_component(name, part):
    got = name_as_path_part(name)
    assert got == part
    assert os.sep not in got and got not in (".", "..") and not got.startswith((".", "-"))


def test_long_names_are_cut():
    assert len(name_as_path_part("x" * 1000)) <= 96


@pytest.mark.parametrize("name", ["../escaped", "/tmp/exucable-escaped-abs", "../../x/../y"])
def test_route_and_plan_write_inside_the_working_directory_whatever_the_name(tmp_path, monkeypatch, name, capsys):
    work = tmp_path / "work"
    work.mkdir()
    sc = _scenario_file(tmp_path, name)
    monkeypatch.chdir(work)
    assert cli.main(["route", str(sc)]) == 0
    assert cli.main(["plan", str(sc)]) == 0
    made = sorted(p.name for p in work.iterdir())
    part = name_as_path_part(name)
    assert made == sorted([f"{part}_route.png", f"plan_{part}"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sc.toml", "work"]   # nothing outside
    assert not Path("/tmp/exucable-escaped-abs_route.png").exists()


def test_run_and_sweep_default_directories_are_made_from_safe_names():
    from exucable.output.outdir import default_out_dir

    assert default_out_dir("../../evil") == Path("out") / "evil"
    assert default_out_dir("/abs/name", suffix="-converge") == Path("out") / "abs_name-converge"


# ------------------------------------------------------------------------------------------
# A run owns its output directory
# ------------------------------------------------------------------------------------------


def _no_solve(*args, **kwargs):
    raise AssertionError("the solve must not start with an unusable output directory")


@pytest.mark.parametrize("make", ["file", "under_a_file"])
def test_a_bad_out_is_refused_before_the_solve(tmp_path, monkeypatch, capsys, make):
    (tmp_path / "f").write_text("x")
    out = tmp_path / "f" if make == "file" else tmp_path / "f" / "sub"
    monkeypatch.setattr(xrun, "_solve", _no_solve)
    with pytest.raises(OutputError, match="f"):
        xrun.run_scenario(TINY, out)
    assert cli.main(["run", str(TINY), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("exucable run: error: ") and "Traceback" not in err[0]
    assert cli.main(["export", str(TINY), str(out)]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_an_unwritable_out_is_refused_before_the_solve(monkeypatch):
    """/proc refuses new entries even to root (a chmod'ed directory would not stop root)."""
    monkeypatch.setattr(xrun, "_solve", _no_solve)
    if not Path("/proc/self").exists():
        pytest.skip("no /proc here")
    with pytest.raises(OutputError, match="cannot"):
        xrun.run_scenario(TINY, "/proc/exucable-results")


def test_compare_out_is_checked_before_comparing(tmp_path, capsys):
    a = tmp_path / "a.csv"
    a.write_text("x_m,tension_N\n0,1\n1,2\n2,3\n")
    (tmp_path / "f").write_text("x")
    assert cli.main(["compare", str(a), str(a), "--out", str(tmp_path / "f" / "figs")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "exucable compare: error:" in err[0]


def test_a_second_process_writing_into_the_same_out_is_refused(tmp_path, monkeypatch):
    """The lock holds across processes: a run started while another owns the directory stops
    before its solve with one line (exit 2)."""
    out = tmp_path / "out"
    holder = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(f"""
            import sys, time
            from exucable.output.outdir import owned_out_dir
            with owned_out_dir({str(out)!r}):
                print("held", flush=True)
                time.sleep(60)
            """)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        monkeypatch.setattr(xrun, "_solve", _no_solve)
        with pytest.raises(OutputError, match="another exucable run is writing"):
            xrun.run_scenario(TINY, out)
    finally:
        holder.kill()
        holder.wait(timeout=10)
    with owned_out_dir(out) as got:             # released when its process died
        assert got == out
        with pytest.raises(OutputError, match="another exucable run"):
            with owned_out_dir(out):
                pass


def _result(bends: bool, snapshots: bool) -> RunResult:
    """A small hand-made result (the writer is under test, not the physics)."""
    t = np.array([0.0, 0.1, 0.2])
    bend_rows = None
    if bends:
        from exucable.post.pressure import BEND_COLUMNS
        bend_rows = [{c: 1.0 for c in BEND_COLUMNS}]
    snaps = None
    if snapshots:
        from exucable.output.formats import SNAPSHOT_FILES
        cols = SNAPSHOT_FILES["snapshot_times.csv"]
        snaps = {"snapshot_times.csv": {c: [0.1] for c in cols}}
    return RunResult(summary={"status": "ok", "pull_force_N": 1.0},
                     history={"time_s": t, "pull_force_N": t + 1.0, "trailing_tension_N": t,
                              "max_tension_N": t + 1.0},
                     tension_profile={"x_m": t, "tension_N": t}, bends=bend_rows, snapshots=snaps)


def test_a_second_run_leaves_none_of_the_first_runs_files(tmp_path):
    out = tmp_path / "out"
    write_results(out, _result(bends=True, snapshots=True), plots=False)
    (out / "pull_force.png").write_bytes(b"old figure")       # the first run's figure
    (out / "notes.txt").write_text("mine")                    # not a result file: left alone
    assert (out / "bends.csv").exists() and (out / "snapshot_times.csv").exists()
    write_results(out, _result(bends=False, snapshots=False), plots=False)
    assert sorted(p.name for p in out.iterdir()) == ["history.csv", "notes.txt", "summary.json",
                                                      "tension_profile.csv"]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["files"] == {n: (out / n).stat().st_size for n in ("history.csv", "tension_profile.csv")}


def test_a_failed_write_leaves_no_summary_vouching_for_it(tmp_path, monkeypatch):
    """Disk full on the third file: the error is one OutputError naming the directory, and neither
    the earlier run's summary.json nor a new one is left."""
    out = tmp_path / "out"
    write_results(out, _result(bends=True, snapshots=False), plots=False)
    assert (out / "summary.json").exists()
    real_add = AtomicBatch.add

    def full(self, path, data):
        if Path(path).name == "bends.csv":
            raise OSError(28, "No space left on device", str(path))
        return real_add(self, path, data)

    monkeypatch.setattr(AtomicBatch, "add", full)
    with pytest.raises(OutputError, match="No space left on device.*no summary.json"):
        write_results(out, _result(bends=True, snapshots=False), plots=False)
    assert not (out / "summary.json").exists()
    assert not (out / "bends.csv").exists()                   # the old one went with its summary
    assert not list(out.glob(".*.tmp"))


def test_a_real_run_into_the_same_out_twice_and_through_the_api(tmp_path):
    """The whole path once, on a tiny real case: files of the run's own, summary listing them."""
    import exucable as xc

    out = tmp_path / "out"
    (out).mkdir()
    (out / "bends.csv").write_text("stale\n")
    (out / "snapshot_nodes.csv").write_text("stale\n")
    res = xc.run(TINY, out_dir=out)
    files = json.loads((out / "summary.json").read_text())["files"]
    assert "snapshot_nodes.csv" not in files and not (out / "snapshot_nodes.csv").exists()
    assert (out / "bends.csv").read_text() != "stale\n"
    assert all((out / n).stat().st_size == size for n, size in files.items())
    assert res.status in ("ok", "steady")


# ------------------------------------------------------------------------------------------
# Temporary files of writers killed mid-write
# ------------------------------------------------------------------------------------------


def test_temporaries_of_dead_writers_are_removed_and_live_ones_kept(tmp_path):
    old = time.time() - 3600
    dead, live = _dead_pid(), os.getpid()
    names = {"dead_old": f".history.csv.{dead}.abcd1234.tmp", "dead_new": f".bends.csv.{dead}.efgh5678.tmp",
             "live_old": f".summary.json.{live}.ijkl9012.tmp", "other": ".notmine.tmp", "data": "history.csv"}
    for key, name in names.items():
        (tmp_path / name).write_text(key)
        if key != "dead_new":
            os.utime(tmp_path / name, (old, old))
    removed = remove_stale_temporaries(tmp_path)
    assert [p.name for p in removed] == [names["dead_old"]]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(n for k, n in names.items() if k != "dead_old")


def test_a_writer_killed_mid_write_leaves_a_temporary_that_the_next_writer_cleans(tmp_path):
    """kill -9 between writing and renaming (the writer sleeps there): its temporary stays, then
    the next run into the directory removes it once it is older than the grace period."""
    out = tmp_path / "out"
    code = textwrap.dedent(f"""
        import time
        from exucable.io import AtomicBatch
        b = AtomicBatch()
        b.add({str(out / "history.csv")!r}, b"time_s\\n0.0\\n")
        print("written", flush=True)
        time.sleep(60)
        """)
    writer = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        assert writer.stdout.readline().strip() == "written"
    finally:
        writer.send_signal(signal.SIGKILL)
        writer.wait(timeout=10)
    (left,) = out.glob(".history.csv.*.tmp")
    assert str(writer.pid) in left.name
    old = time.time() - 3600
    os.utime(left, (old, old))
    with owned_out_dir(out):
        pass
    assert not left.exists()


def test_check_out_dir_creates_and_returns_the_directory(tmp_path):
    d = check_out_dir(tmp_path / "a" / "b")
    assert d.is_dir() and list(d.iterdir()) == []          # the write check leaves nothing
