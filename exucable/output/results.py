"""Results of one run and their files (the documented results format, docs/results-format.md).

Every file is written atomically (a temporary file in the same directory, then ``os.replace``),
so a crash or a kill never leaves a half-written file, and ``summary.json`` is written after the
data files: its presence marks complete results. The figures (optional) are drawn while the data files
are written (by a helper process, :mod:`exucable.output.figure_process`) or after them.

Files
-----
``summary.json``          scalars (forces [N], times [s]), status, scenario echoed back, versions
``history.csv``           ``time_s,pull_force_N,trailing_tension_N,max_tension_N`` and, with contact,
                          ``max_penetration_m,max_axis_offset_m,max_axis_offset_s_conduit_m``
``tension_profile.csv``   ``x_m,tension_N`` at the final time (x: material coordinate from the trailing end)
``cable_tensions.csv``    several cables: ``x_m,cable_1_tension_N,...`` (``tension_profile.csv`` then holds their sum)
``contact_profile.csv``   ``s_conduit_m,normal_force_per_length_N_per_m,penetration_m`` (along the
                          scenario's conduit from its start)
``rope_profile.csv``      ``s_conduit_m,tension_N,sidewall_pressure_N_per_m`` of the rope reference
``snapshot_*.csv``        the state at ``[output] snapshots`` times (see :mod:`exucable.output.snapshots`)
``bends.csv``             one row per bend: tensions in/out, windowed pressure mean/peak, point loads
                          (columns ``exucable.post.pressure.BEND_COLUMNS``)
``pressure_profile.csv``  ``s_conduit_m,windowed_pressure_N_per_m,rope_windowed_pressure_N_per_m``
``cross_sections.png``    several cables: the cables across the duct at places along the route
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field
from pathlib import Path

# The writers live in io.py (one atomic writer); re-exported here, where callers have found them.
from ..errors import OutputError
from ..io import AtomicBatch, atomic_write_bytes, atomic_write_text, csv_text, read_csv, write_csv, write_json
from .figure_process import Figures, draw_figures
from .numbers_text import csv_rows
from ..post.pressure import BEND_COLUMNS, PRESSURE_COLUMNS
from .summary import RunSummary

__all__ = ["RunResult", "atomic_write_text", "atomic_write_bytes", "write_csv", "read_csv", "write_results",
           "read_summary", "result_file_names", "draw_figures", "DATA_FILES", "FIGURE_FILES", "HISTORY_COLUMNS", "PROFILE_COLUMNS", "CONTACT_COLUMNS", "ROPE_COLUMNS"]

HISTORY_COLUMNS = ("time_s", "pull_force_N", "trailing_tension_N", "max_tension_N", "max_penetration_m",
                   "max_axis_offset_m", "max_axis_offset_s_conduit_m")
# Arc lengths, one convention in every file: x_m = material coordinate along the cable from its
# trailing end; s_conduit_m = along the scenario's conduit from its start (whatever the pull direction)
PROFILE_COLUMNS = ("x_m", "tension_N")
CONTACT_COLUMNS = ("s_conduit_m", "normal_force_per_length_N_per_m", "penetration_m")
ROPE_COLUMNS = ("s_conduit_m", "tension_N", "sidewall_pressure_N_per_m")
# (the old name s_m is still read by ``compare`` for one release: exucable.output.compare.FAMILIES)


@dataclass
class RunResult:
    """Everything a run produced, ready to be written or post-processed."""

    summary: RunSummary               # summary.json (a plain dict of its keys is written as it is)
    history: dict                     # HISTORY_COLUMNS -> arrays
    tension_profile: dict             # PROFILE_COLUMNS -> arrays
    contact_profile: dict | None = None
    rope_profile: dict | None = None
    extras: dict = field(default_factory=dict)
    bends: list | None = None                # BEND_COLUMNS rows (exucable.post.pressure)
    pressure_profile: dict | None = None      # PRESSURE_COLUMNS -> arrays
    snapshots: dict | None = None     # snapshot file name -> {column: array} (exucable.output.snapshots)
    cable_tensions: dict | None = None  # several cables: x_m and cable_<k>_tension_N -> arrays
    cross_sections: dict | None = None  # several cables: plot_cross_sections' panels, inner_radius_m, cable_radius_m
    model: object | None = field(default=None, repr=False, compare=False)  # the solved model, not written


#: Every file a run may write into its directory, figures included (``snapshot_*.csv``:
#: :data:`exucable.output.formats.SNAPSHOT_FILES`). A new run removes those of an earlier run that it
#: does not write again, so no file of another run is left beside its ``summary.json``.
DATA_FILES = ("history.csv", "tension_profile.csv", "contact_profile.csv", "rope_profile.csv", "bends.csv",
              "pressure_profile.csv", "cable_tensions.csv")
FIGURE_FILES = ("pull_force.png", "tension_profile.png", "pressure.png", "cross_sections.png")
SUMMARY_FILE = "summary.json"


def result_file_names() -> tuple[str, ...]:
    """The names of every file :func:`write_results` may write (summary, data, snapshots, figures)."""
    from .formats import SNAPSHOT_FILES
    return (SUMMARY_FILE, *DATA_FILES, *SNAPSHOT_FILES, *FIGURE_FILES)


def write_results(out_dir, result: RunResult, plots: bool | Figures = True) -> list[Path]:
    """Write ``result`` into ``out_dir`` (created if needed): the CSV files, then ``summary.json``,
    and (unless ``plots`` is false) the figures. Returns the paths.

    ``plots`` may be a :class:`~exucable.output.figure_process.Figures` started before the solve: its
    helper process then draws the figures while the data files are written here. True draws them
    here, after the data files.

    The directory's ``summary.json`` vouches only for files of its own run: an earlier run's
    ``summary.json`` is removed first, then every result file of that run (:func:`result_file_names`;
    other files are left alone), and the new one is written last among the data files, listing them
    under ``files`` (name → bytes). A write that fails (a full disk) therefore leaves no summary, and
    the error says so. Raises :class:`~exucable.errors.OutputError` on a failed write.
    """
    out = Path(out_dir)
    data_error = []
    written = []

    def write_data() -> None:
        try:
            written.extend(_write_data(out, result))
        except OSError as exc:
            data_error.append(exc)

    try:
        out.mkdir(parents=True, exist_ok=True)
        for name in result_file_names():
            try:
                (out / name).unlink()
            except FileNotFoundError:
                pass
    except OSError as exc:
        data_error.append(exc)
    figures = []
    if plots and not data_error:
        try:
            figures = (plots if isinstance(plots, Figures) else Figures(helper=False)).write(
                out, result, while_drawing=write_data)
        except OSError as exc:
            if not data_error:
                raise OutputError(out, f"the results and {SUMMARY_FILE} are written, but a figure is not "
                                       f"({_reason(exc)})") from None
    elif not data_error:
        write_data()
    if data_error:
        raise OutputError(out, f"writing the results failed ({_reason(data_error[0])}); no {SUMMARY_FILE} was "
                               "left to vouch for an incomplete set: free space or choose another directory and "
                               "run again") from None
    return written + figures


def _reason(exc: OSError) -> str:
    what = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
    return f"{what}{exc.strerror or exc}"


def _write_data(out: Path, result: RunResult) -> list[Path]:
    """The CSV files and ``summary.json`` (last, listing them)."""
    written = []
    contents = {}
    # one batch: the files are flushed to disk together and renamed in this order, summary.json
    # last; an error on the way still puts the files before it in place (io.AtomicBatch)
    with AtomicBatch() as batch:
        def add_csv(name, columns, data):
            # the numbers through the compiled formatter on large tables: repr's characters, ~5x faster
            encoded = csv_text(columns, data, rows=csv_rows).encode("utf-8")
            contents[name] = len(encoded)
            written.append(batch.add(out / name, encoded))

        add_csv("history.csv", [c for c in HISTORY_COLUMNS if c in result.history], result.history)
        if result.tension_profile is not None:
            add_csv("tension_profile.csv", PROFILE_COLUMNS, result.tension_profile)
        if result.cable_tensions is not None:
            add_csv("cable_tensions.csv", list(result.cable_tensions), result.cable_tensions)
        if result.contact_profile is not None:
            add_csv("contact_profile.csv", CONTACT_COLUMNS, result.contact_profile)
        if result.rope_profile is not None:
            add_csv("rope_profile.csv", ROPE_COLUMNS, result.rope_profile)
        if result.bends:
            add_csv("bends.csv", BEND_COLUMNS, {c: [row[c] for row in result.bends] for c in BEND_COLUMNS})
        if result.pressure_profile is not None:
            add_csv("pressure_profile.csv", PRESSURE_COLUMNS, result.pressure_profile)
        if result.snapshots:
            from .formats import SNAPSHOT_FILES
            for name, data in result.snapshots.items():
                add_csv(name, SNAPSHOT_FILES[name], data)
        summary = result.summary
        if isinstance(summary, RunSummary):
            result.summary = dataclasses.replace(summary, files=dict(contents))
        else:
            summary["files"] = dict(contents)
        written.append(write_json(out / SUMMARY_FILE, dict(result.summary), batch=batch))
    return written


def read_summary(out_dir) -> dict:
    with open(Path(out_dir) / "summary.json") as f:
        return json.load(f)
