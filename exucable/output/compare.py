"""``exucable compare A B``: cross-check two sets of results, e.g. exucable against another solver.

A and B are result directories or single CSV files. Every quantity family of the results format
(``docs/results-format.md``) is compared when both sides have it:

=====================  ==========================  ==============  ==========================================
family                 file                        abscissa        values
=====================  ==========================  ==============  ==========================================
``history``            ``history.csv``             ``time_s``      pull_force_N, trailing_tension_N, max_tension_N
                                                                  (not of a steady-mode run: its rows are
                                                                  solve steps; its state's profiles compare)
``tension_profile``    ``tension_profile.csv``     ``x_m``         tension_N
``contact_profile``    ``contact_profile.csv``     ``s_conduit_m`` normal_force_per_length_N_per_m, penetration_m
``rope_profile``       ``rope_profile.csv``        ``s_conduit_m`` tension_N, sidewall_pressure_N_per_m
``snapshot_tension``   ``snapshot_tension.csv``    ``x_m``         tension_N, per snapshot time
``snapshot_contact``   ``snapshot_contact.csv``    ``x_mid_m``     normal_force_N, friction_force_N, their
                                                                   ``_per_length_N_per_m``, max_penetration_m
``snapshot_nodes``     ``snapshot_nodes.csv``      ``x_m``         pos_x_m, pos_y_m, pos_z_m
=====================  ==========================  ==============  ==========================================

A single CSV is recognised by its file name, else by its header. Column names written before the
one arc-length convention (``s_m`` in the three profiles) are still read, with a note, for one
release.

B is interpolated linearly onto A's abscissa over the range both cover; snapshot families are
compared time by time at the times both have (to 1e-9 s).

A steady result (a directory whose ``summary.json`` has ``"mode": "steady"``) is one state, not a
time history: its ``history.csv`` holds the solve's pseudo-time steps, so ``history`` is not
compared when either side is steady (a note says so); its state is the one snapshot at
``time_s = 0``, compared with the other side's state at time 0 when it has one, else with its last
snapshot (a dynamic run's latest state, the nearest to steady sliding; a note names both times).
The profiles are compared as always. For every quantity the maximum and RMS
differences are reported, absolute (in the column's unit) and relative to max |A|. A quantity
passes when ``max |B − A| <= atol + rtol · max |A|``; ``rtol`` and ``atol`` come from a tolerance
file (``--tolerances tol.toml``: a ``[default]`` table and tables named by column, or by
``family.column``, each with ``rtol`` and/or ``atol``), else from ``--rtol``/``--atol``
(defaults 1e-2 and 0); ``passed`` is false when any quantity fails. Input errors raise
:class:`~exucable.errors.ExucableError`.

Use :func:`compare_results` from Python; :mod:`exucable.commands.compare` is the command-line face.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ExucableError
from ..io import new_figure, save_figure

__all__ = ["compare_results", "is_steady_result", "write_overlay_plot", "write_overlay_plots", "format_report", "load_tolerances",
           "DEFAULT_RTOL", "FAMILIES", "unit_of"]

#: Default threshold on the relative maximum difference [-] (1 %: the paper's own agreement with its closed forms
#: is 0.39 %, and other multibody codes differ from exucable by their discretisation).
DEFAULT_RTOL = 1e-2


@dataclass(frozen=True)
class Family:
    """One quantity family: its file, abscissa, value columns and (snapshots) the time column."""

    file: str
    abscissa: str
    values: tuple
    group: str | None = None
    old: dict = field(default_factory=dict)      # old column name -> current one (read only)


# Snapshot families first: a single CSV is recognised by the first family its header fits.
FAMILIES = {
    "snapshot_tension": Family("snapshot_tension.csv", "x_m", ("tension_N",), "time_s"),
    "snapshot_contact": Family("snapshot_contact.csv", "x_mid_m",
                               ("normal_force_N", "friction_force_N", "normal_force_per_length_N_per_m",
                                "friction_force_per_length_N_per_m", "max_penetration_m"), "time_s"),
    "snapshot_nodes": Family("snapshot_nodes.csv", "x_m", ("pos_x_m", "pos_y_m", "pos_z_m"), "time_s"),
    "history": Family("history.csv", "time_s", ("pull_force_N", "trailing_tension_N", "max_tension_N")),
    "contact_profile": Family("contact_profile.csv", "s_conduit_m",
                              ("normal_force_per_length_N_per_m", "penetration_m"), old={"s_m": "s_conduit_m"}),
    "rope_profile": Family("rope_profile.csv", "s_conduit_m", ("tension_N", "sidewall_pressure_N_per_m"),
                           old={"s_m": "s_conduit_m"}),
    "tension_profile": Family("tension_profile.csv", "x_m", ("tension_N",), old={"s_m": "x_m"}),
}
_TIME_MATCH_S = 1e-9

_UNITS = (("_N_per_m", "N/m"), ("_m_per_s", "m/s"), ("_N", "N"), ("_m", "m"), ("_s", "s"))


def unit_of(column: str) -> str:
    """The unit a column's name ends with (``pull_force_N`` → N)."""
    return next((u for suffix, u in _UNITS if column.endswith(suffix)), "-")


@dataclass(frozen=True)
class _Table:
    """One CSV of one family: per group (snapshot time, or None) the sorted abscissa and value columns."""

    path: Path
    kind: str
    groups: dict          # group value (float or None) -> (x, {column: values})
    notes: tuple = ()

    @property
    def columns(self) -> set:
        return set(next(iter(self.groups.values()))[1])


def _fits(header, fam: Family) -> bool:
    need = [fam.abscissa] + ([fam.group] if fam.group else [])
    return all(c in header for c in need) and any(c in header for c in fam.values)


def _recognise(path: Path, header: list) -> tuple[str, list, tuple]:
    """(family, header with old names mapped, notes) of a CSV."""
    by_name = next((k for k, f in FAMILIES.items() if f.file == path.name), None)
    candidates = [by_name] if by_name else list(FAMILIES)
    for kind in candidates:
        fam = FAMILIES[kind]
        if _fits(header, fam):
            return kind, header, ()
        mapped = [fam.old.get(h, h) for h in header]
        if fam.old and _fits(mapped, fam):
            notes = tuple(f"{path.name}: read old column '{o}' as '{n}' (old names are read for one release)"
                          for o, n in fam.old.items() if o in header)
            return kind, mapped, notes
    if by_name:
        fam = FAMILIES[by_name]
        raise ExucableError(f"{path}: {by_name} file is missing its abscissa or value column(s); expected "
                            f"{fam.abscissa}{', ' + fam.group if fam.group else ''} and one of "
                            f"{','.join(fam.values)}, got {','.join(header)!r}")
    if "s_m" in header or "time_s" in header or "x_m" in header or "s_conduit_m" in header:
        raise ExucableError(f"{path}: header {','.join(header)!r}: missing its value column(s); expected one of "
                            + "; ".join(f"{f.abscissa} + {','.join(f.values)}" for f in FAMILIES.values()))
    raise ExucableError(f"{path}: header {','.join(header)!r} has no known abscissa: neither 'x_m', "
                        "'s_conduit_m' (or the old 's_m') nor 'time_s'")


def _read_csv(path: Path) -> _Table:
    """Read one results CSV; its family is recognised by its name or header. '#' lines are skipped."""
    try:
        # utf-8-sig: a byte-order mark (as spreadsheet programs write one) is read past
        with open(path, newline="", encoding="utf-8-sig") as fh:
            rows = [r for r in csv.reader(fh) if r and not r[0].lstrip().startswith("#")]
    except OSError as exc:
        raise ExucableError(f"{path}: cannot read ({exc.strerror})") from None
    except (UnicodeDecodeError, csv.Error):
        raise ExucableError(f"{path}: not a text CSV file (binary content or another encoding than UTF-8); "
                            "give a results CSV") from None
    if not rows:
        raise ExucableError(f"{path}: empty file, expected a header line")
    header = [h.strip() for h in rows[0]]
    kind, header, notes = _recognise(path, header)
    fam = FAMILIES[kind]
    present = [c for c in fam.values if c in header]
    if len(rows) < 3:
        raise ExucableError(f"{path}: needs at least two data rows, found {len(rows) - 1}")
    wanted = [fam.abscissa] + ([fam.group] if fam.group else []) + present
    index = {name: header.index(name) for name in wanted}
    data = np.empty((len(rows) - 1, len(wanted)))
    for i, row in enumerate(rows[1:]):
        for j, name in enumerate(wanted):
            try:
                data[i, j] = float(row[index[name]])
            except (IndexError, ValueError):
                raise ExucableError(f"{path}: data row {i + 1}, column {name!r}: not a number "
                                    f"({row[index[name]] if index[name] < len(row) else 'missing'!r})") from None
    if not np.all(np.isfinite(data)):
        raise ExucableError(f"{path}: contains non-finite values (nan or inf)")
    first = 1 + (1 if fam.group else 0)
    groups = {}
    keys = np.unique(data[:, 1]) if fam.group else [None]
    for key in keys:
        sub = data if key is None else data[data[:, 1] == key]
        sub = sub[np.argsort(sub[:, 0], kind="stable")]
        groups[None if key is None else float(key)] = (sub[:, 0], {n: sub[:, first + j] for j, n in enumerate(present)})
    return _Table(path, kind, groups, notes)


def is_steady_result(source) -> bool:
    """True when ``source`` is a result directory of a steady solve (its ``summary.json`` says
    ``"mode": "steady"``)."""
    summary = Path(source) / "summary.json"
    if not summary.is_file():
        return False
    try:
        return json.loads(summary.read_text()).get("mode") == "steady"
    except (OSError, ValueError, AttributeError):
        return False


def _load(source) -> dict:
    """Tables of a result directory or a single CSV, keyed by family.

    A steady-mode run's ``history.csv`` counts static solve steps, not time: it is left out (the run's
    state, its profiles, is what compares with a dynamic run's final state), with a note saying so.
    """
    path = Path(source)
    if path.is_dir():
        # a steady result's history.csv is its pseudo-time steps (possibly one row): not read
        skip = {"history"} if is_steady_result(path) else set()
        tables = {kind: _read_csv(path / fam.file) for kind, fam in FAMILIES.items()
                  if kind not in skip and (path / fam.file).is_file()}
        if not tables:
            raise ExucableError(f"{path}: result directory has none of "
                                + ", ".join(f.file for f in FAMILIES.values()))
        return tables
    if not path.exists():
        raise ExucableError(f"{path}: no such file or directory")
    table = _read_csv(path)
    return {table.kind: table}


def _differences(x_a, a, x_b, b):
    """(abscissa, B − A) over the common range, B interpolated onto A's abscissa; None without overlap."""
    lo, hi = max(x_a[0], x_b[0]), min(x_a[-1], x_b[-1])
    mask = (x_a >= lo) & (x_a <= hi)
    if hi <= lo or np.count_nonzero(mask) < 2:
        return None
    return x_a[mask], np.interp(x_a[mask], x_b, b) - a[mask], a[mask]


def load_tolerances(path) -> dict:
    """A tolerance TOML: ``{name: {"rtol": r, "atol": a}}`` with ``default`` and column or family.column names."""
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
        data = tomllib.loads(raw.decode("utf-8-sig"))       # a byte-order mark is read past
    except OSError as exc:
        raise ExucableError(f"{path}: cannot read ({exc.strerror})") from None
    except UnicodeDecodeError:
        raise ExucableError(f"{path}: not a UTF-8 text file; give a TOML file of tolerances") from None
    except tomllib.TOMLDecodeError as exc:
        raise ExucableError(f"{path}: not valid TOML ({exc})") from None
    out = {}

    def walk(prefix, table):
        for key, value in table.items():
            name = f"{prefix}.{key}" if prefix else key
            if isinstance(value, dict):
                walk(name, value)
                continue
            if key not in ("rtol", "atol"):
                raise ExucableError(f"{path}: {name}: unknown key; a tolerance table holds rtol and/or atol")
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not (math.isfinite(value) and value >= 0):
                raise ExucableError(f"{path}: {name}: must be a finite number >= 0, got {value!r}")
            out.setdefault(prefix, {})[key] = float(value)

    walk("", data)
    return out


def _tolerance(tolerances: dict, kind: str, column: str, rtol: float, atol: float) -> tuple[float, float]:
    t = {"rtol": rtol, "atol": atol}
    for name in ("default", column, f"{kind}.{column}"):
        t.update(tolerances.get(name, {}))
    return t["rtol"], t["atol"]


def _rows(table: _Table) -> int:
    return sum(x.size for x, _ in table.groups.values())


def _reaches(xa, xb) -> str | None:
    """Why abscissa ``xb`` does not span ``xa``'s range (None when it does). One median step of A
    is allowed at each end: another solver's output times or stations need not fall on A's."""
    step = float(np.median(np.diff(xa))) if xa.size > 1 else 0.0
    if xb[0] <= xa[0] + step and xb[-1] >= xa[-1] - step:
        return None
    return f"B spans {xb[0]:.6g}..{xb[-1]:.6g}, A {xa[0]:.6g}..{xa[-1]:.6g}"


def _coverage(kind: str, ta: _Table, tb: _Table | None, b_is_dir: bool, steady: bool = False) -> dict:
    """How far B covers A's table of one family: rows, range and times of each, and what B lacks
    (``missing``; empty when B covers A). With a steady side (``steady``) a state is one state: A's
    latest snapshot is covered by B's latest, and a time history is not asked of the steady side."""
    fam = FAMILIES[kind]
    xa = np.concatenate([x for x, _ in ta.groups.values()])
    entry = {"kind": kind, "file": fam.file, "abscissa": fam.abscissa, "rows_a": _rows(ta),
             "range_a": (float(xa.min()), float(xa.max())), "rows_b": 0, "range_b": None, "missing": [],
             "checked": True}
    if steady and kind == "history":
        entry["checked"] = False      # a steady solve has no time history to cover or be covered by
        if tb is None:
            entry["missing"].append(f"{fam.file}: not compared (steady result)")
        return entry
    if steady and fam.group is not None and tb is not None and tb.groups:
        t_a, t_b = max(ta.groups), max(tb.groups)
        ta = dataclasses.replace(ta, groups={t_a: ta.groups[t_a]})
        tb = dataclasses.replace(tb, groups={t_a: tb.groups[t_b]})
    if tb is None:
        # a directory B answers for every file of A; a single CSV only for its own family
        entry["missing"].append(f"{fam.file} not in B")
        entry["checked"] = b_is_dir
        return entry
    xb = np.concatenate([x for x, _ in tb.groups.values()])
    entry.update(rows_b=_rows(tb), range_b=(float(xb.min()), float(xb.max())))
    entry["missing"] += [f"column {c} not in B" for c in fam.values if c in ta.columns and c not in tb.columns]
    times_b = np.array(sorted(k for k in tb.groups if k is not None))
    for t, (x, _) in ta.groups.items():
        if t is not None and not (times_b.size and np.min(np.abs(times_b - t)) <= _TIME_MATCH_S):
            entry["missing"].append(f"snapshot t = {t:.12g} s not in B")
            continue
        key = None if t is None else float(times_b[int(np.argmin(np.abs(times_b - t)))])
        why = _reaches(x, tb.groups[key][0])
        if why is not None:
            entry["missing"].append(f"{fam.abscissa}: {why}" + ("" if t is None else f" at t = {t:.12g} s"))
    return entry


def compare_results(a, b, rtol: float = DEFAULT_RTOL, atol: float = 0.0, tolerances: dict | None = None,
                    allow_partial: bool = False) -> dict:
    """Compare two result directories or CSV files.

    Parameters
    ----------
    a, b : str or Path
        Result directory or CSV file; A is the reference whose abscissa is used.
    rtol, atol : float
        Default relative [-] and absolute [column's unit] tolerances: a quantity passes when
        max |B − A| <= atol + rtol · max |A|.
    tolerances : dict, optional
        Per-quantity tolerances from :func:`load_tolerances` (override ``rtol``/``atol``).
    allow_partial : bool
        Pass on the overlap alone. By default B must cover A: every file of A (when B is a
        directory), every value column and snapshot time of A, and A's abscissa range (to one of A's
        median steps at each end); otherwise ``passed`` is false whatever the differences.

    Returns
    -------
    dict
        ``{"a", "b", "passed", "comparisons": [...], "skipped": [...], "notes": [...]}``; each
        comparison has ``kind`` (family), ``abscissa``, ``column``, ``unit``, ``range`` (the overlap,
        over all snapshot times), ``n_points``, ``times`` (snapshot times compared, or None),
        ``max_abs``, ``rms_abs`` [unit], ``scale`` (max |A|), ``max_rel``, ``rms_rel``, ``rtol``,
        ``atol``, ``worst_at`` (abscissa, and time for snapshots, of the largest difference) and
        ``passed``; ``skipped`` lists (family, column, reason); ``coverage`` has one entry per file
        of A: ``kind``, ``file``, ``rows_a``, ``rows_b``, ``range_a``, ``range_b``, ``missing`` (what B
        lacks; empty when it covers A) and ``checked`` (whether it counts toward ``covered``);
        ``covered`` is true when B covers A.

    Raises
    ------
    ExucableError
        Missing or malformed inputs, nothing in common, or no overlap.
    """
    tables_a, tables_b = _load(a), _load(b)
    tolerances = tolerances or {}
    comparisons, skipped = [], []
    notes = [n for t in (*tables_a.values(), *tables_b.values()) for n in t.notes]
    steady = {side: is_steady_result(src) for side, src in (("A", a), ("B", b))}
    kinds = [k for k in FAMILIES if k in tables_a and k in tables_b]
    if any(steady.values()):
        # a steady solve's history rows are pseudo-time steps: nothing to align in time
        if "history" in kinds:
            kinds.remove("history")
        which = " and ".join(side for side, st in steady.items() if st)
        skipped.append(("history", "*", f"{which}: steady result, its history.csv holds pseudo-time steps "
                                        "(time_s = step number), not a time history"))
    if not kinds:
        raise ExucableError(f"nothing to compare: {a} has {', '.join(tables_a)} and {b} has {', '.join(tables_b)}")
    for kind in kinds:
        fam = FAMILIES[kind]
        ta, tb = tables_a[kind], tables_b[kind]
        pairs = []
        if fam.group is None:
            pairs = [(None, ta.groups[None], tb.groups[None])]
        else:
            times_b = np.array(sorted(tb.groups))
            for t in sorted(ta.groups):
                j = int(np.argmin(np.abs(times_b - t)))
                if abs(times_b[j] - t) <= _TIME_MATCH_S:
                    pairs.append((t, ta.groups[t], tb.groups[float(times_b[j])]))
                elif not any(steady.values()):
                    skipped.append((kind, "*", f"snapshot t = {t:.12g} s only in A"))
            if not pairs and any(steady.values()):
                # a steady state against the other side's latest state
                t_a, t_b = max(ta.groups), float(times_b[-1])
                pairs.append((t_a, ta.groups[t_a], tb.groups[t_b]))
                note = f"{kind}: steady state compared with the latest state (A t = {t_a:.12g} s, B t = {t_b:.12g} s)"
                if note not in notes:
                    notes.append(note)
            if not pairs:
                raise ExucableError(f"{kind}: A and B have no snapshot time in common")
        for column in fam.values:
            if column not in ta.columns or column not in tb.columns:
                if column in ta.columns or column in tb.columns:
                    skipped.append((kind, column, f"only in {'A' if column in ta.columns else 'B'}"))
                continue
            xs, diffs, refs, times = [], [], [], []
            for t, (xa, ca), (xb, cb) in pairs:
                d = _differences(xa, ca[column], xb, cb[column])
                if d is None:
                    raise ExucableError(f"{kind}: the {fam.abscissa} ranges do not overlap "
                                        f"(A {xa[0]:g}..{xa[-1]:g}, B {xb[0]:g}..{xb[-1]:g})"
                                        + ("" if t is None else f" at t = {t:.12g} s"))
                xs.append(d[0])
                diffs.append(d[1])
                refs.append(d[2])
                times.append(np.full(d[0].size, np.nan if t is None else t))
            x, diff, ref, tt = (np.concatenate(v) for v in (xs, diffs, refs, times))
            k = int(np.argmax(np.abs(diff)))
            max_abs = float(np.abs(diff[k]))
            rms_abs = float(np.sqrt(np.mean(diff**2)))
            scale = float(np.max(np.abs(ref)))
            if scale > 0.0:
                max_rel, rms_rel = max_abs / scale, rms_abs / scale
            else:   # A is identically zero: relative difference is 0 if B is too, infinite otherwise
                max_rel = rms_rel = 0.0 if max_abs == 0.0 else math.inf
            r, at = _tolerance(tolerances, kind, column, rtol, atol)
            comparisons.append({
                "kind": kind, "abscissa": fam.abscissa, "column": column, "unit": unit_of(column),
                "range": (float(x.min()), float(x.max())), "n_points": int(x.size),
                "times": None if fam.group is None else [p[0] for p in pairs],
                "times_b": None if fam.group is None else [_group_time(tb, p[2]) for p in pairs],
                "max_abs": max_abs, "rms_abs": rms_abs, "scale": scale, "max_rel": max_rel, "rms_rel": rms_rel,
                "rtol": r, "atol": at, "worst_at": (float(x[k]), None if fam.group is None else float(tt[k])),
                "passed": bool(max_abs <= at + r * scale),
            })
    b_is_dir = Path(b).is_dir()
    coverage = [_coverage(k, tables_a[k], tables_b.get(k), b_is_dir, any(steady.values()))
                for k in FAMILIES if k in tables_a]
    covered = all(not c["missing"] for c in coverage if c["checked"])
    return {"a": str(a), "b": str(b), "comparisons": comparisons, "skipped": skipped, "notes": notes,
            "coverage": coverage, "covered": covered, "allow_partial": bool(allow_partial),
            "passed": all(c["passed"] for c in comparisons) and (covered or bool(allow_partial))}


def _group_time(table: _Table, group) -> float:
    """The snapshot time [s] of one of ``table``'s groups."""
    return next(float(t) for t, g in table.groups.items() if g is group)


def format_report(result: dict) -> str:
    """Plain-text table of a :func:`compare_results` result."""
    lines = [f"A: {result['a']}", f"B: {result['b']} (interpolated onto A)", *result.get("notes", []),
             f"{'quantity':<42} {'range':>21} {'max |B-A|':>12} {'rms':>10} {'max rel':>9} {'rms rel':>9} "
             f"{'rtol':>7} {'atol':>8}  verdict"]
    for c in result["comparisons"]:
        unit = "s" if c["abscissa"] == "time_s" else "m"
        rng = f"{c['range'][0]:.4g}..{c['range'][1]:.4g} {unit}"
        name = f"{c['kind']}.{c['column']}" + (f" ({len(c['times'])} t)" if c["times"] else "")
        verdict = "ok" if c["passed"] else "BEYOND"
        lines.append(f"{name:<42} {rng:>21} {c['max_abs']:>9.4g} {c['unit']:<2} {c['rms_abs']:>10.4g} "
                     f"{c['max_rel']:>9.2e} {c['rms_rel']:>9.2e} {c['rtol']:>7.1e} {c['atol']:>8.2g}  {verdict}")
    for kind, column, reason in result["skipped"]:
        lines.append(f"{kind + '.' + column:<42} skipped ({reason})")
    coverage = result.get("coverage", [])
    if coverage:
        lines.append("coverage of A by B:")
    for c in coverage:
        unit = "s" if c["abscissa"] == "time_s" else "m"
        rng_b = "-" if c["range_b"] is None else f"{c['range_b'][0]:.4g}..{c['range_b'][1]:.4g} {unit}"
        state = "covered" if not c["missing"] else ("; ".join(c["missing"]) + ("" if c["checked"] else
                                                                               " (B is one file: not checked)"))
        lines.append(f"  {c['file']:<22} rows A {c['rows_a']:>6}, B {c['rows_b']:>6}; range A "
                     f"{c['range_a'][0]:.4g}..{c['range_a'][1]:.4g} {unit}, B {rng_b}: {state}")
    differ = not all(c["passed"] for c in result["comparisons"])
    uncovered = not result.get("covered", True)
    if not differ and not uncovered:
        lines.append("agree within tolerances, B covering A")
    elif not differ and result.get("allow_partial"):
        lines.append("agree within tolerances over what both have (--allow-partial: B does not cover A)")
    else:
        if differ:
            lines.append("DIFFER: max |B-A| > atol + rtol·max|A| for a quantity marked BEYOND")
        if uncovered:
            lines.append("INCOMPLETE: B does not cover A (see coverage); --allow-partial compares the overlap alone")
    return "\n".join(lines)


def _figure(rows: int):
    fig = new_figure(figsize=(7.0, 3.6 * rows), layout="constrained")
    axes = fig.subplots(2 * rows, 1, squeeze=False, height_ratios=[3, 1] * rows)[:, 0]
    return fig, axes


def _draw(c, ta, tb, top, bottom) -> None:
    """A and B (solid, dashed; one pair per snapshot time) above, B − A below."""
    col = c["column"]
    times = c["times"] or [None]
    times_b = c.get("times_b") or times
    for i, (t, t_b) in enumerate(zip(times, times_b)):
        xa, ca = ta.groups[t]
        tb_key = None if t_b is None else min(tb.groups, key=lambda k: abs(k - t_b))
        xb, cb = tb.groups[tb_key]
        suffix = "" if t is None else f" t={t:.4g} s"
        line, = top.plot(xa, ca[col], lw=1.6, label=f"A{suffix}" if i < 6 else None)
        top.plot(xb, cb[col], "--", lw=1.2, color=line.get_color(), label=f"B{suffix}" if i < 6 else None)
        d = _differences(xa, ca[col], xb, cb[col])
        bottom.plot(d[0], d[1], lw=1.0, color=line.get_color())
    top.set_ylabel(f"{col} [{c['unit']}]")
    top.set_title(f"{c['kind']}.{col}: max |B−A| {c['max_abs']:.3g} {c['unit']} (rel {c['max_rel']:.3g})",
                  fontsize="medium")
    top.legend(fontsize="small")
    bottom.axhline(0.0, color="0.5", lw=0.6)
    bottom.set_ylabel(f"B − A [{c['unit']}]")
    bottom.set_xlabel(f"{c['abscissa']}")


def write_overlay_plot(result: dict, out) -> Path:
    """Every compared quantity in one figure (A, B, and B − A below), written atomically to ``out``."""
    tables_a, tables_b = _load(result["a"]), _load(result["b"])
    comps = result["comparisons"]
    fig, axes = _figure(len(comps))
    for i, c in enumerate(comps):
        _draw(c, tables_a[c["kind"]], tables_b[c["kind"]], axes[2 * i], axes[2 * i + 1])
    return save_figure(fig, out, dpi=120)


def write_overlay_plots(result: dict, out_dir) -> list[Path]:
    """One overlay figure per compared quantity, ``out_dir/compare_<family>_<column>.png``."""
    tables_a, tables_b = _load(result["a"]), _load(result["b"])
    written = []
    for c in result["comparisons"]:
        fig, axes = _figure(1)
        _draw(c, tables_a[c["kind"]], tables_b[c["kind"]], axes[0], axes[1])
        written.append(save_figure(fig, Path(out_dir) / f"compare_{c['kind']}_{c['column']}.png", dpi=120))
    return written
