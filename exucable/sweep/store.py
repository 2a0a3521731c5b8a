"""A sweep's directory on disk: case directories installed atomically, their records, the table.

Layout of ``DIR``::

    DIR/sweep.json              the sweep: keys, mode, output, every case's hash and parameters
    DIR/sweep.csv               one row per case (rewritten atomically every few seconds while
                                running and when the sweep ends)
    DIR/sweep.png               output against the first varied key
    DIR/cases/<hash>/           one finished case: run_scenario's files + case.json
    DIR/cases/.<hash>.tmp-<pid> a case being run by process <pid> (never read; removed by a later
                                run once that process is gone)

A case directory appears under its final name only by one ``os.rename`` of a complete temporary
directory, so a kill at any moment leaves either the whole case or nothing. ``case.json`` is the
small record a table row is made from (varied parameters, status, message, key outputs, the full
scenario), so ``sweep.csv`` can be rebuilt from the directory alone (:func:`rows_from_disk`).
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import re
import shutil
from pathlib import Path

from ..errors import ExucableError
from ..io import atomic_write_text, pid_alive, remove_stale_temporaries

__all__ = [
    "CASES_DIR", "CASE_JSON", "MANIFEST", "TABLE", "FINISHED", "RESULT_COLUMNS", "RECORD_OUTPUTS",
    "case_dir", "temp_dir", "read_record", "read_verified_record", "files_intact", "is_finished",
    "write_record", "install_case", "remove_stale",
    "write_manifest", "read_manifest", "make_row", "rows_from_disk", "extra_columns", "table_columns", "write_table",
    "read_table", "SweepLock",
]

CASES_DIR = "cases"
CASE_JSON = "case.json"
MANIFEST = "sweep.json"
TABLE = "sweep.csv"
LOCK = ".sweep.lock"

# A case is finished (never re-run) when its record has one of these statuses: trusted, or
# completed but flagged as untrustworthy (exucable.post.trust; re-running would give the same answer).
FINISHED = ("ok", "steady", "outside_conduit", "penetration", "dynamic", "friction_underdeveloped", "not_steady")

# sweep.csv columns after the varied keys, in order; "message" is kept last (free text).
RESULT_COLUMNS = ("case", "status", "pull_force_N", "rope_pull_force_N", "max_tension_N",
                  "max_sidewall_pressure_N_per_m", "wall_time_s", "message")

# summary.json values copied into case.json
RECORD_OUTPUTS = ("pull_force_N", "pull_force_std_N", "rope_pull_force_N", "trailing_tension_N",
                  "rope_trailing_tension_N", "max_tension_N", "max_sidewall_pressure_N_per_m",
                  "rope_max_sidewall_pressure_N_per_m", "steady", "simulated_time_s", "steps")


def case_dir(out_dir, case_id: str) -> Path:
    """``DIR/cases/<hash>``: where a finished case lives."""
    return Path(out_dir) / CASES_DIR / case_id


def temp_dir(cases_dir, case_id: str, tag) -> Path:
    """``DIR/cases/.<hash>.tmp-<tag>``: where a case is run before it is installed."""
    return Path(cases_dir) / f".{case_id}.tmp-{tag}"


def read_record(path) -> dict | None:
    """The ``case.json`` of a case directory, or None if there is none (or it cannot be read)."""
    try:
        with open(Path(path) / CASE_JSON) as f:
            rec = json.load(f)
    except (OSError, ValueError):
        return None
    return rec if isinstance(rec, dict) else None


def files_intact(path, record: dict) -> bool:
    """Whether a case directory still holds what its record says it finished with.

    Every file the record lists under ``files`` (relative path → bytes) must be there with that
    size, and a ``summary.json`` must parse as a JSON object with the record's status. Records
    written before ``files`` existed are checked on ``summary.json`` alone, when it is there.
    """
    path = Path(path)
    listed = record.get("files")
    if isinstance(listed, dict):
        for rel, size in listed.items():
            try:
                if (path / rel).stat().st_size != size:
                    return False
            except OSError:
                return False
    summary = path / "summary.json"
    if not summary.exists():
        return not (isinstance(listed, dict) and "summary.json" in listed)
    try:
        data = json.loads(summary.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(data, dict) and data.get("status", record.get("status")) == record.get("status")


def read_verified_record(path) -> dict | None:
    """:func:`read_record`, but None for a finished case whose files are damaged or gone
    (:func:`files_intact`): such a case is run again, not skipped."""
    rec = read_record(path)
    if is_finished(rec) and not files_intact(path, rec):
        return None
    return rec


def is_finished(record: dict | None) -> bool:
    """True if ``record`` is a successfully finished case (status ok or steady)."""
    return record is not None and record.get("status") in FINISHED


def _finite_or_none(v):
    """JSON has no NaN/inf: a non-finite float is recorded as null."""
    if isinstance(v, float):
        return v if math.isfinite(v) else None
    return v


def write_record(path, record: dict) -> None:
    """Write ``case.json`` into a case directory (atomically)."""
    safe = {k: _finite_or_none(v) for k, v in record.items()}
    atomic_write_text(Path(path) / CASE_JSON, json.dumps(safe, indent=2, allow_nan=False) + "\n")


def _fsync_dir(path: Path) -> None:
    """Make a rename durable (POSIX); a no-op where directories cannot be opened."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def install_case(tmp: Path, final: Path) -> dict:
    """Move a complete temporary case directory to its final name, atomically.

    A finished case already at ``final`` is never replaced (nothing twice: a task that ran
    twice, e.g. after a lost Dask worker, keeps the first result); a failed or damaged one is
    replaced by renaming it aside first. Returns the record now at ``final``.
    """
    tmp, final = Path(tmp), Path(final)
    existing = read_verified_record(final)
    if is_finished(existing):
        shutil.rmtree(tmp, ignore_errors=True)
        return existing
    if final.exists():
        # A failed (or record-less) case being redone: rename() cannot replace a non-empty
        # directory, so move it aside; a kill between the two renames leaves the case missing,
        # which a later run redoes.
        aside = final.with_name(f".{final.name}.old-{os.getpid()}")
        shutil.rmtree(aside, ignore_errors=True)
        os.rename(final, aside)
        os.rename(tmp, final)
        shutil.rmtree(aside, ignore_errors=True)
    else:
        os.rename(tmp, final)
    _fsync_dir(final.parent)
    rec = read_record(final)
    if rec is None:
        raise ExucableError(f"case directory {final} has no {CASE_JSON} after installation")
    return rec


_OWNED = re.compile(r"^\.[0-9a-f]+\.(?:tmp|old)-(\d+)(?:-parent)?$")


def remove_stale(cases_dir) -> int:
    """Remove the temporary and set-aside case directories of processes that are gone; returns
    how many. A directory whose process is alive (a case still running, e.g. one of a sweep killed
    a moment ago) is left to it: deleting it would lose that case's files under its feet."""
    cases_dir = Path(cases_dir)
    n = 0
    if not cases_dir.is_dir():
        return 0
    remove_stale_temporaries(cases_dir)
    for p in cases_dir.iterdir():
        m = _OWNED.match(p.name)
        if m is None or pid_alive(int(m.group(1))):
            continue
        shutil.rmtree(p, ignore_errors=True)
        n += 1
    return n


def write_manifest(out_dir, sweep) -> None:
    """``sweep.json``: what is needed to rebuild the table from the directory alone."""
    data = {
        "name": sweep.name,
        "description": sweep.description,
        "source": str(sweep.source_path) if sweep.source_path else None,
        "base": str(sweep.base_path),
        "mode": sweep.mode,
        "output": sweep.output,
        "keys": list(sweep.keys),
        "unset": list(sweep.unset),
        "set": sweep.set,
        "cases": [{"index": i, "case": c.case_id, "params": c.params} for i, c in enumerate(sweep.cases)],
    }
    atomic_write_text(Path(out_dir) / MANIFEST, json.dumps(data, indent=2) + "\n")


def read_manifest(out_dir) -> dict:
    """Read ``sweep.json``."""
    path = Path(out_dir) / MANIFEST
    try:
        with open(path) as f:
            return json.load(f)
    except FileNotFoundError:
        raise ExucableError(f"{path}: not found; is {out_dir} a sweep directory?") from None


def make_row(keys, params: dict, case_id: str, record: dict | None, extra=()) -> dict:
    """One ``sweep.csv`` row: the varied values, the case hash, and its record's outputs.

    A case without a record is ``pending``.
    """
    row = {k: params.get(k) for k in keys}
    row["case"] = case_id
    rec = record or {}
    row["status"] = rec.get("status", "pending")
    for c in RESULT_COLUMNS[2:-1] + tuple(extra):
        row[c] = rec.get(c)
    row["message"] = rec.get("message", "") or ""
    return row


def rows_from_disk(out_dir) -> list[dict]:
    """Rebuild the table rows of a sweep directory from ``sweep.json`` and the cases' ``case.json``."""
    man = read_manifest(out_dir)
    keys = man["keys"]
    extra = extra_columns(man.get("output", "pull_force_N"))
    return [make_row(keys, c["params"], c["case"], read_verified_record(case_dir(out_dir, c["case"])), extra)
            for c in man["cases"]]


def extra_columns(output: str) -> tuple[str, ...]:
    from .spec import OUTPUTS
    cols = [c for c in (output, OUTPUTS.get(output)) if c and c not in RESULT_COLUMNS]
    return tuple(cols)


def table_columns(keys, output: str = "pull_force_N") -> list[str]:
    """Column order of ``sweep.csv``: varied keys, result columns (message last)."""
    return list(keys) + list(RESULT_COLUMNS[:-1]) + list(extra_columns(output)) + ["message"]


def _cell(v) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ""
    if isinstance(v, (int, str)):
        return str(v)
    return json.dumps(v)


def write_table(path, rows: list[dict], columns) -> None:
    """Write ``sweep.csv`` atomically: floats as ``repr`` (exact round trip), None as empty."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns)
    for r in rows:
        w.writerow([_cell(r.get(c)) for c in columns])
    atomic_write_text(path, buf.getvalue())


_TEXT_COLUMNS = ("case", "status", "message")


def read_table(path) -> list[dict]:
    """Read ``sweep.csv``: result columns as float (None when empty), parameters parsed as JSON
    where they are (numbers, booleans, arrays), else kept as text."""
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        result_cols = set(RESULT_COLUMNS) | {"trailing_tension_N", "rope_trailing_tension_N",
                                             "rope_max_sidewall_pressure_N_per_m"}
        rows = []
        for raw in reader:
            row = {}
            for k, v in raw.items():
                if k in _TEXT_COLUMNS:
                    row[k] = v
                elif k in result_cols:
                    row[k] = float(v) if v != "" else None
                else:
                    try:
                        row[k] = json.loads(v)
                    except ValueError:
                        row[k] = v
            rows.append(row)
    return rows


class SweepLock:
    """An exclusive lock on a sweep directory for one ``run_sweep`` (``DIR/.sweep.lock``, flock).

    The lock dies with its process, so a killed sweep never leaves the directory locked. Where
    ``fcntl`` does not exist (Windows) the lock is a no-op.
    """

    def __init__(self, out_dir):
        self.path = Path(out_dir) / LOCK
        self._f = None

    def __enter__(self):
        try:
            import fcntl
        except ImportError:  # pragma: no cover - not POSIX
            return self
        self.path.parent.mkdir(parents=True, exist_ok=True)
        f = open(self.path, "a+")
        try:
            fcntl.flock(f.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            f.seek(0)
            holder = f.read().strip()
            f.close()
            raise ExucableError(
                f"another sweep is running in {self.path.parent}" + (f" ({holder})" if holder else "")
                + "; wait for it or use another --out") from None
        f.seek(0)
        f.truncate()
        f.write(f"pid {os.getpid()}\n")
        f.flush()
        self._f = f
        return self

    def __exit__(self, *exc):
        if self._f is not None:
            self._f.close()   # closing releases the flock
            self._f = None
        return False
