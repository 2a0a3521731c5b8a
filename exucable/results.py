"""Results of one run and their files (the documented results format, see README).

Every file is written atomically (a temporary file in the same directory, then ``os.replace``),
so a crash or a kill never leaves a half-written file, and ``summary.json`` is written after the
data files: its presence marks complete results. The figures (optional) follow it.

Files
-----
``summary.json``          scalars (forces [N], times [s]), status, scenario echoed back, versions
``history.csv``           ``time_s,pull_force_N,trailing_tension_N,max_tension_N``
``tension_profile.csv``   ``x_m,tension_N`` at the final time (x: material coordinate from the trailing end)
``contact_profile.csv``   ``s_conduit_m,normal_force_per_length_N_per_m,penetration_m`` (along the
                          scenario's conduit from its start)
``rope_profile.csv``      ``s_conduit_m,tension_N,sidewall_pressure_N_per_m`` of the rope reference
``snapshot_*.csv``        the state at ``[output] snapshots`` times (see :mod:`exucable.snapshots`)
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

# The writers live in io.py (one atomic writer); re-exported here, where callers have found them.
from .io import atomic_write_bytes, atomic_write_text, read_csv, write_csv, write_json
from .plots.results import plot_pull_force, plot_tension_profile

__all__ = ["RunResult", "atomic_write_text", "atomic_write_bytes", "write_csv", "read_csv", "write_results",
           "read_summary", "HISTORY_COLUMNS", "PROFILE_COLUMNS", "CONTACT_COLUMNS", "ROPE_COLUMNS"]

HISTORY_COLUMNS = ("time_s", "pull_force_N", "trailing_tension_N", "max_tension_N")
# Arc lengths, one convention in every file: x_m = material coordinate along the cable from its
# trailing end; s_conduit_m = along the scenario's conduit from its start (whatever the pull direction)
PROFILE_COLUMNS = ("x_m", "tension_N")
CONTACT_COLUMNS = ("s_conduit_m", "normal_force_per_length_N_per_m", "penetration_m")
ROPE_COLUMNS = ("s_conduit_m", "tension_N", "sidewall_pressure_N_per_m")
# (the old name s_m is still read by ``compare`` for one release: exucable.compare.FAMILIES)


@dataclass
class RunResult:
    """Everything a run produced, ready to be written or post-processed."""

    summary: dict
    history: dict                     # HISTORY_COLUMNS -> arrays
    tension_profile: dict             # PROFILE_COLUMNS -> arrays
    contact_profile: dict | None = None
    rope_profile: dict | None = None
    extras: dict = field(default_factory=dict)
    snapshots: dict | None = None     # snapshot file name -> {column: array} (exucable.snapshots)


def write_results(out_dir, result: RunResult, plots: bool = True) -> list[Path]:
    """Write ``result`` into ``out_dir`` (created if needed): the CSV files, then ``summary.json``,
    then (unless ``plots`` is false) the figures. Returns the paths."""
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
    if result.snapshots:
        from .formats import SNAPSHOT_FILES
        for name, data in result.snapshots.items():
            write_csv(out / name, SNAPSHOT_FILES[name], data)
            written.append(out / name)
    write_json(out / "summary.json", result.summary)
    written.append(out / "summary.json")
    # the figures come after the numbers: they cost about half a second of matplotlib, and a
    # failure to draw must not hold back (or lose) a result already computed
    if plots:
        plot_pull_force(out / "pull_force.png", result)
        written.append(out / "pull_force.png")
        if result.tension_profile is not None:
            plot_tension_profile(out / "tension_profile.png", result)
            written.append(out / "tension_profile.png")
    return written


def read_summary(out_dir) -> dict:
    with open(Path(out_dir) / "summary.json") as f:
        return json.load(f)
