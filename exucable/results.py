"""Results of one run and their files (the documented results format, see README).

Every file is written atomically (a temporary file in the same directory, then ``os.replace``),
so a crash or a kill never leaves a half-written file, and ``summary.json`` is written last:
its presence marks a complete result directory.

Files
-----
``summary.json``          scalars (forces [N], times [s]), status, scenario echoed back, versions
``history.csv``           ``time_s,pull_force_N,trailing_tension_N,max_tension_N``
``tension_profile.csv``   ``s_m,tension_N`` at the final time (s from the trailing end)
``contact_profile.csv``   ``s_m,normal_force_per_length_N_per_m,penetration_m`` (s along the conduit)
``rope_profile.csv``      ``s_m,tension_N,sidewall_pressure_N_per_m`` of the rope reference
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["RunResult", "atomic_write_text", "atomic_write_bytes", "write_csv", "read_csv", "write_results",
           "read_summary", "HISTORY_COLUMNS", "PROFILE_COLUMNS", "CONTACT_COLUMNS", "ROPE_COLUMNS"]

HISTORY_COLUMNS = ("time_s", "pull_force_N", "trailing_tension_N", "max_tension_N")
PROFILE_COLUMNS = ("s_m", "tension_N")
CONTACT_COLUMNS = ("s_m", "normal_force_per_length_N_per_m", "penetration_m")
ROPE_COLUMNS = ("s_m", "tension_N", "sidewall_pressure_N_per_m")


def atomic_write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (temp file in the same directory + ``os.replace``)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def atomic_write_text(path, text: str) -> None:
    atomic_write_bytes(path, text.encode("utf-8"))


def write_csv(path, columns, data: dict) -> None:
    """Write equal-length columns ``data[c]`` for ``c in columns`` as CSV with a header, atomically."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns)
    arrays = [np.asarray(data[c], dtype=float) for c in columns]
    for row in zip(*arrays):
        w.writerow([repr(float(v)) for v in row])
    atomic_write_text(path, buf.getvalue())


def read_csv(path) -> dict[str, np.ndarray]:
    """Read a results CSV into a dict of float arrays keyed by header."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        raise ValueError(f"{path}: empty file")
    header = [h.strip() for h in rows[0]]
    body = np.array([[float(x) for x in r] for r in rows[1:] if r], dtype=float).reshape(-1, len(header))
    return {h: body[:, i] for i, h in enumerate(header)}


def _json_safe(obj):
    if isinstance(obj, dict):
        return {str(k): _json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_safe(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        v = float(obj)
        return v if math.isfinite(v) else None
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, np.ndarray):
        return _json_safe(obj.tolist())
    if isinstance(obj, Path):
        return str(obj)
    return obj


@dataclass
class RunResult:
    """Everything a run produced, ready to be written or post-processed."""

    summary: dict
    history: dict                     # HISTORY_COLUMNS -> arrays
    tension_profile: dict             # PROFILE_COLUMNS -> arrays
    contact_profile: dict | None = None
    rope_profile: dict | None = None
    extras: dict = field(default_factory=dict)
    model: object | None = field(default=None, repr=False, compare=False)  # the solved model, not written


def write_results(out_dir, result: RunResult, plots: bool = True) -> list[Path]:
    """Write ``result`` into ``out_dir`` (created if needed); ``summary.json`` last. Returns the paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    write_csv(out / "history.csv", HISTORY_COLUMNS, result.history)
    written.append(out / "history.csv")
    if result.tension_profile is not None:
        write_csv(out / "tension_profile.csv", PROFILE_COLUMNS, result.tension_profile)
        written.append(out / "tension_profile.csv")
    if result.contact_profile is not None:
        write_csv(out / "contact_profile.csv", CONTACT_COLUMNS, result.contact_profile)
        written.append(out / "contact_profile.csv")
    if result.rope_profile is not None:
        write_csv(out / "rope_profile.csv", ROPE_COLUMNS, result.rope_profile)
        written.append(out / "rope_profile.csv")
    if plots:
        from .plots.results import plot_pull_force, plot_tension_profile
        plot_pull_force(out / "pull_force.png", result)
        written.append(out / "pull_force.png")
        if result.tension_profile is not None:
            plot_tension_profile(out / "tension_profile.png", result)
            written.append(out / "tension_profile.png")
    atomic_write_text(out / "summary.json", json.dumps(_json_safe(result.summary), indent=2) + "\n")
    written.append(out / "summary.json")
    return written


def read_summary(out_dir) -> dict:
    with open(Path(out_dir) / "summary.json") as f:
        return json.load(f)
