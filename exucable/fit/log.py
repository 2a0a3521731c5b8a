"""A tension recorder's log: read, put into SI, cleaned, and every cleaning step reported.

Format (``docs/pull-logs.md``): a CSV file with a header row; lines starting with ``#`` are comments, and
a comment whose first word is ``end`` (``# end of pull``) says the pull has ended. The columns hold the
pulled length (the head's distance into the conduit from its entrance) and the head tension, or the time
with a pull speed given apart. Each column's unit is stated in its name, as a suffix (``pulled_length_ft``,
``tension_kN``, ``pull_force_N``, ``time_s``) or in brackets (``Length [ft]``, ``Tension (lbf)``), or given
by a flag; a column without a unit is refused rather than guessed.

Cleaning, in this order, each reported in :attr:`PullLog.report`:

- *unreadable rows* (an empty or non-numeric cell in a used column) are dropped (``unreadable_rows``);
- *gaps*: steps in pulled length (or time) more than :data:`GAP_FACTOR` times the median step
  (``gaps``, each ``[from, to]``); the rows stay, nothing is interpolated;
- *tare*: a given offset, or ``"auto"``: the median reading before the winch first moved (the
  dynamometer's reading of a slack line), is subtracted from every reading (``tare_N``);
- *stops*: rows where the pulled length advanced by less than :data:`STOP_FRACTION` of the median step
  (the winch stood; the tension then relaxes or holds static friction, which a sliding model does not
  describe) are left out of the fit (``stops``);
- *spikes*: moving rows further than ``spike_threshold`` robust standard deviations (1.4826 × the median
  absolute deviation) from their running median over :data:`SPIKE_WINDOW` rows (a Hampel filter: a
  snatch of the line, a breakaway after a stop, a logger glitch), and than ``spike_threshold`` times the
  median step between readings, are left out of the fit (``spikes``).
"""

from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from exucable.errors import LogError
from exucable.scenario.units import UNITS, to_si

__all__ = ["PullLog", "read_pull_log", "parse_pull_log", "GAP_FACTOR", "STOP_FRACTION", "SPIKE_WINDOW",
           "TIME_UNITS"]

#: A step in pulled length (or time) this many times the median step is reported as a gap.
GAP_FACTOR = 5.0
#: A row whose pulled length advanced by less than this fraction of the median step is a stop.
STOP_FRACTION = 0.1
#: Rows in the running median of the spike filter (odd; spikes up to half as wide are caught).
SPIKE_WINDOW = 11
#: Time units of a time column, to seconds.
TIME_UNITS = {"s": 1.0, "sec": 1.0, "min": 60.0, "h": 3600.0}

_LENGTH_WORDS = ("pulled", "length", "distance", "footage", "payout", "position")
_FORCE_WORDS = ("tension", "force", "load")
_TIME_WORDS = ("time",)
_END = re.compile(r"^\s*#\s*end\b", re.IGNORECASE)
_BRACKET = re.compile(r"^(.*?)[\s_]*[\[(]\s*([^\])]+?)\s*[\])]\s*$")


@dataclass
class PullLog:
    """A log in SI, cleaned.

    Attributes
    ----------
    pulled_length_m : numpy.ndarray
        Head's distance into the conduit [m] of every readable row, in the file's order.
    pull_force_N : numpy.ndarray
        Head tension [N] of those rows, the tare subtracted.
    time_s : numpy.ndarray or None
        Time [s] of those rows when the log has a time column.
    used : numpy.ndarray of bool
        Rows the fit uses: moving, not a spike.
    stopped, spike : numpy.ndarray of bool
        Rows left out as stops, as spikes.
    tare_rows : numpy.ndarray of bool
        Rows read for ``tare="auto"`` (before the winch moved; none otherwise).
    ended : bool
        The log says the pull ended (an ``# end`` comment).
    report : dict
        What was read and cleaned (see the module's docstring), JSON-ready.
    """

    pulled_length_m: np.ndarray
    pull_force_N: np.ndarray
    time_s: np.ndarray | None
    used: np.ndarray
    stopped: np.ndarray
    spike: np.ndarray
    tare_rows: np.ndarray
    ended: bool
    report: dict = field(default_factory=dict)


def _split_unit(name: str) -> tuple[str, str | None]:
    """A column name's stem and its unit (``"Tension [kN]"`` → ``("Tension", "kN")``), or no unit."""
    m = _BRACKET.match(name)
    if m:
        return m.group(1).strip(), m.group(2).strip()
    stem, sep, suffix = name.rpartition("_")
    if sep and stem and (_unit_factor(suffix, "length") or _unit_factor(suffix, "force")
                         or suffix.lower() in TIME_UNITS):
        return stem, suffix
    return name, None


def _unit_factor(unit: str, dimension: str) -> float | None:
    """SI factor of ``unit`` if it is a unit of ``dimension`` (case-insensitive: loggers write KN, LBF)."""
    if dimension == "time":
        return TIME_UNITS.get(unit.lower())
    for name, (dim, factor) in UNITS.items():
        if dim == dimension and name.lower() == unit.lower():
            return factor
    return None


def _allowed(dimension: str) -> str:
    if dimension == "time":
        return ", ".join(TIME_UNITS)
    return ", ".join(u for u, (d, _) in UNITS.items() if d == dimension)


def _pick(header: list[str], chosen, words, role: str, flag: str) -> int | None:
    """Index of the column playing ``role``: the one ``chosen`` (a name or a 1-based number), else the
    one whose name contains one of ``words``."""
    if chosen is not None:
        text = str(chosen).strip()
        if text.isdigit():
            i = int(text) - 1
            if not 0 <= i < len(header):
                raise LogError(flag, f"column number {text} is outside 1..{len(header)} of the header {header}")
            return i
        names = [h.strip().lower() for h in header]
        stems = [_split_unit(h)[0].strip().lower() for h in header]
        for seq in (names, stems):
            if text.lower() in seq:
                return seq.index(text.lower())
        raise LogError(flag, f"no column named {text!r}; the header has {header}")
    found = [i for i, h in enumerate(header)
             if any(w in _split_unit(h)[0].lower() for w in words)
             and not (role == "force" and any(w in h.lower() for w in _LENGTH_WORDS))]
    if role == "time":
        found = [i for i in found] + [i for i, h in enumerate(header) if _split_unit(h)[0].strip().lower() == "t"]
    if len(found) > 1:
        raise LogError(flag, f"several columns could be the {role} ({[header[i] for i in found]}); "
                             f"choose one with {flag} NAME or {flag} NUMBER")
    return found[0] if found else None


def _column_factor(name: str, unit_flag: str | None, dimension: str, flag: str) -> tuple[float, str]:
    unit = unit_flag or _split_unit(name)[1]
    if unit is None:
        raise LogError(f"column {name!r}", f"its unit is not stated; name it like '{name}_"
                                           f"{'m' if dimension == 'length' else 'N' if dimension == 'force' else 's'}' "
                                           f"or give {flag} (one of {_allowed(dimension)})")
    factor = _unit_factor(unit, dimension)
    if factor is None:
        key = flag if unit_flag else f"column {name!r}"
        raise LogError(key, f"unit {unit!r} is not a {dimension} unit; use one of {_allowed(dimension)}")
    return factor, unit


def _tare_value(tare, force_factor: float) -> float | str:
    if tare is None:
        return 0.0
    if isinstance(tare, str) and tare.strip().lower() == "auto":
        return "auto"
    if isinstance(tare, str):
        try:
            return float(tare) * force_factor          # a bare number: the log's force unit
        except ValueError:
            return to_si("--tare", tare, "force")      # "50 lbf"
    return float(tare) * force_factor


def _rows(text: str, complete_only: bool) -> tuple[list[list[str]], bool]:
    """Data lines (header first) and whether an end marker was seen. A last line without its newline is
    still being written when ``complete_only`` (a growing log) and is left for the next read."""
    lines = text.splitlines(keepends=True)
    if complete_only and lines and not lines[-1].endswith(("\n", "\r")):
        lines = lines[:-1]
    ended = any(_END.match(ln) for ln in lines)
    data = [ln for ln in lines if ln.strip() and not ln.lstrip().startswith("#")]
    return [r for r in csv.reader(io.StringIO("".join(data)))], ended


def parse_pull_log(text: str, *, length_column=None, force_column=None, time_column=None,
                   length_unit: str | None = None, force_unit: str | None = None, time_unit: str | None = None,
                   speed_m_per_s: float | None = None, tare=None, spike_threshold: float = 6.0,
                   complete_only: bool = False, source: str = "log") -> PullLog:
    """Read a log's text; see :func:`read_pull_log` for the parameters."""
    rows, ended = _rows(text, complete_only)
    if not rows:
        raise LogError(source, "no header row: the first line that is not a '#' comment must name the columns")
    header = [h.strip() for h in rows[0]]
    body = rows[1:]
    li = _pick(header, length_column, _LENGTH_WORDS, "length", "--length-column")
    fi = _pick(header, force_column, _FORCE_WORDS, "force", "--force-column")
    ti = _pick(header, time_column, _TIME_WORDS, "time", "--time-column")
    if fi is None:
        raise LogError("--force-column", f"no column looks like the head tension (a name with "
                                         f"{'/'.join(_FORCE_WORDS)}) in {header}; choose it with --force-column")
    if li is None and ti is None:
        raise LogError("--length-column", f"no pulled-length or time column in {header}; choose one with "
                                          "--length-column (or --time-column with --speed)")
    if li is None and speed_m_per_s is None:
        raise LogError("--speed", f"the log has time ({header[ti]!r}) but no pulled length: give the pull speed, "
                                  "e.g. --speed 0.3 or --speed '60 ft/min'")
    if speed_m_per_s is not None and not (np.isfinite(speed_m_per_s) and speed_m_per_s > 0):
        raise LogError("--speed", f"must be > 0 (m/s), got {speed_m_per_s}")
    if not (np.isfinite(spike_threshold) and spike_threshold > 0):
        raise LogError("--spike-threshold", f"must be > 0 (robust standard deviations), got {spike_threshold}")
    f_factor, f_unit = _column_factor(header[fi], force_unit, "force", "--force-unit")
    used_cols = [fi]
    l_factor = l_unit = t_factor = t_unit = None
    if li is not None:
        l_factor, l_unit = _column_factor(header[li], length_unit, "length", "--length-unit")
        used_cols.append(li)
    if ti is not None:
        t_factor, t_unit = _column_factor(header[ti], time_unit, "time", "--time-unit")
        used_cols.append(ti)

    values, unreadable = [], []
    for n, r in enumerate(body, start=2):
        try:
            if len(r) < len(header):
                raise ValueError
            vals = [float(r[c]) for c in used_cols]
            if not all(np.isfinite(vals)):
                raise ValueError
        except ValueError:
            unreadable.append(n)
            continue
        values.append(vals)
    if len(values) < 3:
        raise LogError(source, f"only {len(values)} readable data rows; a fit needs more")
    arr = np.asarray(values, dtype=float)
    force = arr[:, 0] * f_factor
    time = arr[:, used_cols.index(ti)] * t_factor if ti is not None else None
    if li is not None:
        length = arr[:, used_cols.index(li)] * l_factor
    else:
        length = float(speed_m_per_s) * (time - time[0])

    # stops: the length did not advance (measured against the median forward step)
    steps = np.diff(length)
    forward = steps[steps > 0]
    if forward.size == 0:
        raise LogError(source, "the pulled length never increases: is the length column the right one?")
    h = float(np.median(forward))
    moving = np.empty(length.size, dtype=bool)
    moving[1:] = steps > STOP_FRACTION * h
    moving[0] = moving[1] if length.size > 1 else False
    # the head's position only counts where it is beyond all earlier positions (a pay-back is not a pull)
    moving &= length >= np.maximum.accumulate(length) - 1e-12
    stopped = ~moving
    if li is None:
        stopped[:] = False                           # length from time: stops cannot be seen
        moving[:] = True

    # tare: subtract a fixed offset, or the median reading before the winch first moved
    tare_si = _tare_value(tare, f_factor)
    tare_rows = np.zeros(length.size, dtype=bool)
    if tare_si == "auto":
        first = int(np.argmax(moving)) if moving.any() else 0
        if first < 3:
            raise LogError("--tare", "auto needs at least 3 rows before the winch moved (pulled length unchanged "
                                     f"at the start), found {first}; give --tare VALUE in the log's force unit")
        tare_si = float(np.median(force[:first]))
        tare_rows[:first] = True
    force = force - tare_si

    spike = np.zeros(length.size, dtype=bool)
    idx = np.flatnonzero(moving)
    if idx.size >= SPIKE_WINDOW:
        from scipy.ndimage import median_filter

        y = force[idx]
        r = y - median_filter(y, size=SPIKE_WINDOW, mode="nearest")
        scale = 1.4826 * float(np.median(np.abs(r - np.median(r))))
        # floors for nearly noiseless logs, where the running median lags a steep rise by a step or two:
        # a spike must also stand out by the threshold in typical steps between readings
        step = float(np.median(np.abs(np.diff(y))))
        limit = max(spike_threshold * scale, spike_threshold * step, 1e-3 * float(np.max(np.abs(y))))
        spike[idx[np.abs(r) > limit]] = True
    used = moving & ~spike

    axis, axis_steps = (length, steps) if li is not None else (time, np.diff(time))
    pos = axis_steps[axis_steps > 0]
    gaps = []
    if pos.size:
        big = np.flatnonzero(axis_steps > GAP_FACTOR * float(np.median(pos)))
        gaps = [[float(length[i]), float(length[i + 1])] for i in big]
    stops = []
    runs = np.flatnonzero(np.diff(np.concatenate([[0], stopped.astype(int), [0]])))
    for a, b in zip(runs[::2], runs[1::2]):
        stop = {"pulled_length_m": float(length[a]), "rows": int(b - a)}
        if time is not None:
            stop["duration_s"] = float(time[min(b, time.size - 1)] - time[a])
        stops.append(stop)
    report = {
        "source": source,
        "columns": {"pulled_length": None if li is None else header[li], "pull_force": header[fi],
                    "time": None if ti is None else header[ti]},
        "units": {"pulled_length": l_unit if li is not None else f"speed {speed_m_per_s} m/s x time",
                  "pull_force": f_unit, "time": t_unit},
        "rows": len(body),
        "readable_rows": int(length.size),
        "rows_used": int(used.sum()),
        "unreadable_rows": unreadable,
        "gaps_m": gaps,
        "tare_N": float(tare_si),
        "stops": stops,
        "stopped_rows": int(stopped.sum()),
        "spikes": [{"pulled_length_m": float(length[i]), "pull_force_N": float(force[i])}
                   for i in np.flatnonzero(spike)],
        "ended": bool(ended),
        "stops_detectable": li is not None,
    }
    return PullLog(pulled_length_m=length, pull_force_N=force, time_s=time, used=used, stopped=stopped,
                   spike=spike, tare_rows=tare_rows, ended=bool(ended), report=report)


def read_pull_log(path, **kwargs) -> PullLog:
    """Read a tension recorder's log (CSV) into SI, cleaned.

    Parameters
    ----------
    path : path-like
        The CSV file (format in the module's docstring).
    length_column, force_column, time_column : str or int, optional
        The column's name or 1-based number; default: the one column whose name says it
        (``length``/``pulled``/``distance``/``footage``; ``tension``/``force``/``load``; ``time``).
    length_unit, force_unit, time_unit : str, optional
        The column's unit when its name does not state it, or to override it (``m``, ``ft``, ``N``,
        ``kN``, ``lbf``, ``s``, ``min``).
    speed_m_per_s : float, optional
        Pull speed [m/s] for a log with time but no pulled length (length = speed × time elapsed).
    tare : float, str or None
        Offset subtracted from every reading: a number in the log's force unit, a quantity string
        (``"20 lbf"``), or ``"auto"`` (the median reading before the winch moved).
    spike_threshold : float
        Robust standard deviations from the running median beyond which a reading is a spike.
    complete_only : bool
        Leave out a last line that has no newline yet (a log being written).

    Returns
    -------
    PullLog

    Raises
    ------
    LogError
        The file cannot be read, a column is missing, ambiguous or has no unit, or too few rows.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise LogError(str(path), f"cannot read the log: {exc.strerror or exc}") from None
    return parse_pull_log(text, source=str(path), **kwargs)
