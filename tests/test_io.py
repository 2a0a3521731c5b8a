"""The one atomic writer (exucable.io): a batch of files flushed together, renamed in order, and
no result already written lost on an error."""

from __future__ import annotations

import os
import stat

import pytest

import exucable.io as eio
from exucable.io import AtomicBatch, atomic_write_text, write_csv


def test_a_batch_lands_every_file_in_the_order_added(tmp_path, monkeypatch):
    """Nothing is in place before the commit; then every file is, with its content, renamed in the
    order added (summary.json last marks complete results), each only after all are on disk."""
    events = []
    real_fsync, real_replace = os.fsync, os.replace
    monkeypatch.setattr(eio.os, "fsync", lambda fd: (events.append("fsync"), real_fsync(fd))[1])
    monkeypatch.setattr(eio.os, "replace", lambda a, b: (events.append(os.path.basename(b)), real_replace(a, b))[1])
    batch = AtomicBatch()
    write_csv(tmp_path / "a.csv", ["x_m"], {"x_m": [0.5, 1.0]}, batch=batch)
    batch.add_text(tmp_path / "sub" / "b.txt", "bee\n")
    batch.add(tmp_path / "summary.json", b"{}\n")
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == ["sub"]
    assert batch.commit() == [tmp_path / "a.csv", tmp_path / "sub" / "b.txt", tmp_path / "summary.json"]
    assert events == ["fsync"] * 3 + ["a.csv", "b.txt", "summary.json"]
    assert (tmp_path / "a.csv").read_text() == "x_m\n0.5\n1.0\n"
    assert (tmp_path / "sub" / "b.txt").read_text() == "bee\n"
    assert not list(tmp_path.rglob(".*.tmp"))


def test_an_error_keeps_the_files_added_before_it(tmp_path):
    """Leaving the batch by an error commits what was added before it (a run's CSVs stay when a
    later file fails), leaves no temporary file, and lets the error through."""
    with pytest.raises(KeyError):
        with AtomicBatch() as batch:
            write_csv(tmp_path / "history.csv", ["t_s"], {"t_s": [1.0]}, batch=batch)
            write_csv(tmp_path / "bends.csv", ["bend"], {}, batch=batch)     # no such column
    assert (tmp_path / "history.csv").read_text() == "t_s\n1.0\n"
    assert not (tmp_path / "bends.csv").exists()
    assert not list(tmp_path.glob(".*.tmp"))


def test_a_failed_flush_puts_nothing_in_place_and_leaves_no_temporary_file(tmp_path, monkeypatch):
    (tmp_path / "old.csv").write_text("old\n")

    def full(fd):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(eio.os, "fsync", full)
    batch = AtomicBatch()
    batch.add_text(tmp_path / "old.csv", "new\n")
    batch.add_text(tmp_path / "other.csv", "other\n")
    with pytest.raises(OSError, match="No space"):
        batch.commit()
    assert (tmp_path / "old.csv").read_text() == "old\n"        # the old file, never a torn one
    assert not (tmp_path / "other.csv").exists()
    assert not list(tmp_path.glob(".*.tmp"))


def test_columns_of_unequal_length_are_refused(tmp_path):
    """One value per row in every column: a shorter column (an empty one) is an error naming the
    lengths, not a file silently cut to the shortest column."""
    with pytest.raises(ValueError, match="unequal length"):
        write_csv(tmp_path / "history.csv", ["time_s", "max_penetration_m"], {"time_s": [1.0, 2.0], "max_penetration_m": []})
    assert not (tmp_path / "history.csv").exists()


@pytest.mark.skipif(not hasattr(os, "fchmod"), reason="POSIX permissions only")
@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002])
def test_files_get_the_users_umask_as_open_would_give_them(tmp_path, mask):
    """A result file on a shared drive is readable by whoever the user's umask lets read it: the mode
    open() would give (0666 & ~umask), not mkstemp's 0600."""
    old = os.umask(mask)
    try:
        atomic_write_text(tmp_path / "a.txt", "x")
        with AtomicBatch() as batch:
            batch.add_text(tmp_path / "b.txt", "y")
        with open(tmp_path / "c.txt", "w") as f:   # the reference: what the system gives a plain new file
            f.write("z")
    finally:
        os.umask(old)
    expected = stat.S_IMODE(os.stat(tmp_path / "c.txt").st_mode)
    assert expected == 0o666 & ~mask
    for name in ("a.txt", "b.txt"):
        assert stat.S_IMODE(os.stat(tmp_path / name).st_mode) == expected, name


def test_errors_survive_a_round_trip_through_pickle():
    """An error raised in a worker process reaches the parent as the same error (an error that
    cannot be unpickled hangs a multiprocessing pool)."""
    import pickle

    from exucable.errors import GeometryError, LogError, ModelError, OutputError, ScenarioError, SolverError

    for err in (ScenarioError("cable.radius", "must be > 0"), GeometryError("path[1]", "does not fit"),
                ModelError("cable.elements", "too coarse"), LogError("--tare", "no readings"),
                OutputError("/tmp/x", "not a directory"), SolverError("diverged", 0.25)):
        back = pickle.loads(pickle.dumps(err))
        assert type(back) is type(err) and str(back) == str(err)
        assert getattr(back, "key", None) == getattr(err, "key", None)
