"""``exucable validate``: the paper's examples against their references, one table.

Each check compares one exucable output with a reference value from ``reference/paper_values.toml``
(published inputs and closed forms, with sources) or with the independent rope solver, against a
stated tolerance: the issue's accuracy targets for the paper-fidelity scenarios, and looser ones
for the coarse ``--fast`` variants (their justification is in the table below and in
``reference/README.md``). Writes ``validation.csv``, ``validation.md`` and the figures that
correspond to the paper's (Figs. 7, 9, 11, 12, 14) into the output directory.
"""

from __future__ import annotations

import csv
import io
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..data import data_path
from ..io import atomic_write_text
from ..plots.validation import plot_validation_figures
from ..data.reference_values import load_reference

__all__ = ["text_table", "Check", "ModeDifference", "MODES", "ValidationRun", "validate", "format_table", "write_report", "TOLERANCES", "CASES"]

#: The validation cases, in the order they run.
CASES = ("ex1", "ex2", "ex3", "fig12", "ex4")
#: Case key -> the case's name in the checks (Fig. 12 keeps its key).
_CASE_NAMES = {"ex1": "Ex. 1", "ex2": "Ex. 2", "ex3": "Ex. 3", "ex4": "Ex. 4"}


@dataclass(frozen=True)
class Check:
    """One row of the validation table."""

    case: str
    quantity: str
    value: float
    reference: float
    tolerance: float          # relative
    paper_error: float | None = None
    scale: float | None = None  # error normalised by this instead of the reference (profiles)
    note: str = ""
    mode: str = "dynamic"     # solver.mode of the run that gave ``value``
    scatter: float | None = None  # relative steady scatter of the run (std/mean of its window)

    @property
    def rel_error(self) -> float:
        denom = self.scale if self.scale is not None else self.reference
        return abs(self.value - self.reference) / abs(denom) if denom else float("inf")

    @property
    def passed(self) -> bool:
        return bool(np.isfinite(self.value)) and self.rel_error <= self.tolerance


@dataclass(frozen=True)
class ModeDifference:
    """The same check in both modes: steady against dynamic.

    ``tolerance`` is the issue's bound (0.2 %) on |steady - dynamic| / |dynamic| when both describe
    the same state; ``scatter`` is the dynamic run's own steady scatter (std/mean) for scale.
    """

    case: str
    quantity: str
    dynamic: float
    steady: float
    scatter: float | None
    same_state: bool = False   # the steady value is of a solve in the dynamic run's extent
    tolerance: float = 2e-3

    @property
    def rel_difference(self) -> float:
        return (self.steady - self.dynamic) / abs(self.dynamic) if self.dynamic else float("inf")

    @property
    def agrees(self) -> bool:
        return bool(np.isfinite(self.rel_difference)) and abs(self.rel_difference) <= self.tolerance


# Tolerances: (paper fidelity, fast). Paper-fidelity targets are the issue's; fast ones are what
# the coarse meshes hold, measured by the mesh-convergence study in reference/README.md.
# Fast ones, measured (exucable validate --fast): Ex. 1 0.014 %; Ex. 2 0.06 %;
# Ex. 3 0.62 % with 40 elements (0.11 % with the paper's 80: the error falls ~h^2.5, mesh; the fast
# variant has 64 since its 40 ended not_steady);
# Fig. 12 0.26-0.37 % with 20 elements per coil; Ex. 4 0.8 % with 40 elements (from the steady start).
TOLERANCES = {
    "ex1_top": (5e-3, 1e-2),
    "ex1_profile": (1e-2, 2e-2),
    "ex2": (1e-3, 5e-3),
    "ex3": (1e-3, 1e-2),
    "fig12": (2e-3, 1e-2),
    "ex4": (1e-2, 2e-2),
}


MODES = ("dynamic", "steady")


@dataclass
class ValidationRun:
    checks: list = field(default_factory=list)
    runs: dict = field(default_factory=dict)       # case -> RunResult (dynamic mode if it ran)
    sweep_rows: list = field(default_factory=list)
    wall_time_s: float = 0.0
    failures: list = field(default_factory=list)   # (case, message)
    steady_runs: dict = field(default_factory=dict)  # case -> RunResult of the steady mode
    steady_sweep_rows: list = field(default_factory=list)
    mode_wall_time_s: dict = field(default_factory=dict)  # mode -> wall time of its runs [s]
    #: the steady solve's checks in the dynamic run's state (its cable pulled out as far,
    #: ``solver.steady_lead_out`` = the dynamic run's ``reference_pulled_out_m``): what
    #: :attr:`differences` compares; not validation checks themselves
    same_state_checks: list = field(default_factory=list)

    @property
    def differences(self) -> list:
        """:class:`ModeDifference` of every check that ran in both modes, in the same state.

        The steady solve lays its cable out past the exit by its own rule (10 bending lengths past
        the last bend); a dynamic run that stops once steady has pulled it only a few centimetres.
        On a route ending in a bend those are different states (the end's bending boundary layer,
        reference/README.md), so the steady value compared is that of a second steady solve with
        the dynamic run's extent where there is one, else the steady check's own.
        """
        dyn = {(c.case, c.quantity): c for c in self.checks if c.mode == "dynamic"}
        same = {(c.case, c.quantity): c for c in self.same_state_checks}
        out = []
        for c in self.checks:
            d = dyn.get((c.case, c.quantity))
            if c.mode == "steady" and d is not None:
                s = same.get((c.case, c.quantity), c)
                out.append(ModeDifference(c.case, c.quantity, d.value, s.value, d.scatter,
                                          same_state=s is not c))
        return out


def _shipped(*parts: str, fast: bool) -> tuple[Path, str]:
    """A shipped scenario file (its coarse variant in ``fast/`` beside it) and its name for messages."""
    *dirs, name = parts
    parts = (*dirs, "fast", name) if fast else parts
    return data_path("scenarios", *parts), "/".join(("scenarios",) + parts)


def _run_case(case, name, fast, out_dir, quiet, vr: ValidationRun, progress, mode: str = "dynamic",
              lead_out_m: float | None = None):
    from ..run import run_scenario
    from ..scenario.specs import load_scenario
    path, shown = _shipped(f"{name}.toml", fast=fast)
    if progress is not None:
        state = f", {lead_out_m:.4g} m pulled out as in the dynamic run" if lead_out_m is not None else ""
        progress(f"validate: running {case} ({shown}, {mode}{state})")
    scenario = path
    if lead_out_m is not None:
        scenario = load_scenario(path).replace(**{"solver.steady_lead_out": lead_out_m})
    res = run_scenario(scenario, Path(out_dir) / name, quiet=quiet, plots=True, mode=mode)
    if lead_out_m is None:
        (vr.runs if mode == "dynamic" else vr.steady_runs)[case] = res
    if res.summary["status"] == "failed":
        state = ", in the dynamic run's state" if lead_out_m is not None else ""
        vr.failures.append((f"{case} ({mode}{state})", res.summary["message"]))
    return res


def _tol(key, fast):
    return TOLERANCES[key][1 if fast else 0]


def _scatter(res, what="pull_force_N") -> float | None:
    """Relative steady scatter std/mean of a dynamic run's pulling force (None for a steady solve)."""
    s = res.summary
    if s.get("mode") == "steady" or not s.get(what):
        return None
    std = s.get("pull_force_std_N") if what == "pull_force_N" else None
    return None if std is None else abs(std / s[what])


def validate(fast: bool = False, out_dir="validation", quiet: bool = True, cases=None,
             progress: Callable[[str], None] | None = None, modes=MODES) -> ValidationRun:
    """Run the validation set in each solver mode, write its table and figures into ``out_dir``;
    returns the checks (see :class:`Check`) and, where both modes ran, their differences
    (:attr:`ValidationRun.differences`).

    Parameters
    ----------
    fast : bool
        The coarse variants (``scenarios/fast``) with their looser tolerances.
    out_dir : str or os.PathLike
        Where ``validation.csv``, ``validation.md``, the figures and each run's results go
        (dynamic runs in ``out_dir/<scenario>``, steady ones in ``out_dir/steady/<scenario>``).
    quiet : bool
        No progress bar in the runs.
    cases : iterable of str, optional
        A subset of :data:`CASES` (default: all).
    progress : callable, optional
        Called with one line of text as each case starts.
    modes : iterable of {"dynamic", "steady"}
        The solver modes to run (default both).
    """
    ref = load_reference()
    vr = ValidationRun()
    t0 = time.perf_counter()
    wanted = set(cases or CASES)
    out = Path(out_dir)
    for mode in modes:
        tm = time.perf_counter()
        _mode_checks(ref, vr, wanted, fast, out if mode == "dynamic" else out / "steady", quiet, progress, mode)
        vr.mode_wall_time_s[mode] = time.perf_counter() - tm
    if "dynamic" in modes and "steady" in modes:
        tm = time.perf_counter()
        _mode_checks(ref, vr, wanted, fast, out / "steady_same_state", quiet, progress, "steady",
                     lead_out=_dynamic_extents(vr, out))
        vr.mode_wall_time_s["steady in the dynamic state"] = time.perf_counter() - tm
    vr.wall_time_s = time.perf_counter() - t0
    write_report(vr, out, fast)
    return vr


def _dynamic_extents(vr: ValidationRun, out: Path) -> dict:
    """How far each dynamic run had pulled its cable out (``reference_pulled_out_m`` [m], at its
    steady window's mean time), by case; Fig. 12's by number of coils under ``"fig12"``. Cases
    without one (a force-controlled pull, a failed run) are left out: no same-state solve."""
    import json

    extents = {}
    for case, res in vr.runs.items():
        x = res.summary.get("reference_pulled_out_m")
        if x is not None and res.summary.get("status") != "failed":
            extents[case] = float(x)
    coils = {}
    for row in vr.sweep_rows:
        key = next((k for k in row if k.endswith("helix_turns")), None)
        summary = out / "fig12" / "cases" / str(row.get("case", "")) / "summary.json"
        if key is None or not summary.exists():
            continue
        x = json.loads(summary.read_text()).get("reference_pulled_out_m")
        if x is not None and row.get("status") in ("ok", "steady"):
            coils[float(row[key])] = float(x)
    if coils:
        extents["fig12"] = coils
    return extents


def _mode_checks(ref, vr, wanted, fast, out, quiet, progress, mode, lead_out: dict | None = None):
    """The checks of ``wanted`` cases in one solver mode. With ``lead_out`` (case -> metres pulled
    out, :func:`_dynamic_extents`) the steady solves are laid out as far as the dynamic runs had
    pulled, only the cases that have one run, and their checks go to ``vr.same_state_checks``."""
    target = vr.checks if lead_out is None else vr.same_state_checks
    if lead_out is not None:
        wanted = {c for c in wanted if _CASE_NAMES.get(c, c) in lead_out}

    def check(case, quantity, value, reference, tol, res, **kw):
        target.append(Check(case, quantity, value, reference, tol, mode=mode,
                            scatter=_scatter(res), **kw))

    def _run(case, name, *args):
        return _run_case(case, name, *args, lead_out_m=None if lead_out is None else lead_out[case])

    if "ex1" in wanted:
        r = _run("Ex. 1", "paper_ex1_incline", fast, out, quiet, vr, progress, mode)
        T50 = ref["example1"]["pull_force_N"]
        slope = ref["example1"]["tension_slope_N_per_m"]
        check("Ex. 1", "pulling force at the top end [N]", r.summary["pull_force_N"], T50,
              _tol("ex1_top", fast), r, note="Eq. 25")
        x = np.asarray(r.tension_profile["x_m"])
        N = np.asarray(r.tension_profile["tension_N"])
        worst = float(np.max(np.abs(N - slope * x)))
        check("Ex. 1", "max |T(x) - Eq. 25| along the cable / T(50 m)", T50 + worst, T50,
              _tol("ex1_profile", fast), r, scale=T50, note="Fig. 7")
    if "ex2" in wanted:
        r = _run("Ex. 2", "paper_ex2_bend90", fast, out, quiet, vr, progress, mode)
        T1 = ref["example2"]["pull_force_N"]
        paper = abs(ref["example2"].get("pull_force_reported_N", float("nan")) / T1 - 1)
        check("Ex. 2", "pulling force T1 [N]", r.summary["pull_force_N"], T1,
              _tol("ex2", fast), r, paper_error=paper, note="Eq. 26, capstan")
    if "ex3" in wanted:
        r = _run("Ex. 3", "paper_ex3_helix", fast, out, quiet, vr, progress, mode)
        T2 = ref["example3"]["back_tension_N"]
        check("Ex. 3", "trailing tension T2 [N]", r.summary["trailing_tension_N"], T2,
              _tol("ex3", fast), r, paper_error=ref["example3"].get("relative_error_reported"),
              note="Eq. 26 with the exact helix angle")
    if "fig12" in wanted:
        _fig12(ref, fast, out, quiet, vr, progress, mode, target=target,
               lead_out=None if lead_out is None else lead_out["fig12"])
    if "ex4" in wanted:
        r = _run("Ex. 4", "paper_ex4_spatial", fast, out, quiet, vr, progress, mode)
        check("Ex. 4", "pulling force vs rope solver [N]", r.summary["pull_force_N"],
              r.summary["rope_pull_force_N"], _tol("ex4", fast), r,
              note="independent rope solution (paper: RecurDyn)")


def _fig12(ref, fast, out, quiet, vr, progress, mode="dynamic", target=None, lead_out: dict | None = None):
    from ..scenario.specs import read_toml
    from ..sweep import run_sweep
    from ..sweep.spec import parse_sweep
    path, shown = _shipped("sweeps", "paper_fig12_coils.toml", fast=fast)
    if progress is not None:
        progress(f"validate: running Fig. 12 ({shown}, {mode})")
    data = read_toml(path, "sweep")
    data.setdefault("set", {})["solver.mode"] = mode
    if lead_out is not None:   # each case laid out as far as its dynamic run had pulled (zip mode)
        turns_key = next(k for k in data["vary"] if k.endswith("helix_turns"))
        turns = [float(n) for n in data["vary"][turns_key]]
        keep = [i for i, n in enumerate(turns) if n in lead_out]
        data["vary"] = {k: [v[i] for i in keep] for k, v in data["vary"].items()}
        data["vary"]["solver.steady_lead_out"] = [lead_out[turns[i]] for i in keep]
        if not keep:
            return
    sweep = parse_sweep(data, Path(path).parent, default_name=Path(path).stem)
    object.__setattr__(sweep, "source_path", Path(path).resolve())
    rows = run_sweep(sweep, out / "fig12", quiet=quiet)
    if lead_out is None:
        if mode == "dynamic":
            vr.sweep_rows = rows
        else:
            vr.steady_sweep_rows = rows
    target = vr.checks if target is None else target
    expected = dict(zip(ref["fig12"]["coils"], ref["fig12"]["pull_force_N"]))
    key = next(k for k in rows[0] if k.endswith("helix_turns"))
    for row in rows:
        n = float(row[key])
        value = float(row["pull_force_N"]) if row.get("status") in ("ok", "steady") else float("nan")
        if row.get("status") not in ("ok", "steady"):
            state = ", in the dynamic run's state" if lead_out is not None else ""
            vr.failures.append((f"Fig. 12 n = {n:g} ({mode}{state})", row.get("message", "")))
        std = row.get("pull_force_std_N")
        scatter = (abs(float(std) / value) if mode == "dynamic" and std not in (None, "") and np.isfinite(value)
                   and value else None)
        target.append(Check("Fig. 12", f"pulling force, {n:g} coils [N]", value, expected[int(round(n))],
                               _tol("fig12", fast), note="10 e^(0.1 beta(n))", mode=mode, scatter=scatter))


def _fmt(v, digits=6):
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return f"{v:.{digits}g}"


def table_rows(vr: ValidationRun):
    header = ["case", "quantity", "mode", "exucable", "reference", "rel. error", "tolerance", "paper's error", "pass"]
    rows = []
    for c in vr.checks:
        rows.append([c.case, c.quantity, c.mode, _fmt(c.value), _fmt(c.reference), f"{100 * c.rel_error:.3f} %",
                     f"{100 * c.tolerance:.2f} %",
                     "-" if c.paper_error is None or not math.isfinite(c.paper_error) else f"{100 * c.paper_error:.2f} %",
                     "PASS" if c.passed else "FAIL"])
    return header, rows


def difference_rows(vr: ValidationRun):
    header = ["case", "quantity", "dynamic", "steady", "steady state", "steady - dynamic", "dynamic scatter",
              "bound", "agree"]
    rows = []
    for d in vr.differences:
        rows.append([d.case, d.quantity, _fmt(d.dynamic), _fmt(d.steady),
                     "dynamic's extent" if d.same_state else "own lead-out", f"{100 * d.rel_difference:+.3f} %",
                     "-" if d.scatter is None else f"{100 * d.scatter:.3f} %", f"{100 * d.tolerance:.2f} %",
                     "yes" if d.agrees else "NO"])
    return header, rows


def text_table(header, rows) -> str:
    widths = [max(len(str(x)) for x in col) for col in zip(header, *rows)]
    line = "  ".join(h.ljust(w) for h, w in zip(header, widths))
    out = [line, "-" * len(line)]
    out += ["  ".join(str(x).ljust(w) for x, w in zip(r, widths)) for r in rows]
    return "\n".join(out)


def format_table(vr: ValidationRun) -> str:
    text = text_table(*table_rows(vr))
    if vr.differences:
        text += "\n\nSteady against dynamic (see reference/README.md where they differ):\n"
        text += text_table(*difference_rows(vr))
    return text


def write_report(vr: ValidationRun, out: Path, fast: bool) -> None:
    header, rows = table_rows(vr)
    out.mkdir(parents=True, exist_ok=True)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["case", "quantity", "mode", "exucable", "reference", "rel_error", "tolerance", "paper_error",
                "passed", "scatter"])
    for c in vr.checks:
        w.writerow([c.case, c.quantity, c.mode, repr(float(c.value)), repr(float(c.reference)), repr(c.rel_error),
                    c.tolerance, "" if c.paper_error is None else c.paper_error, c.passed,
                    "" if c.scatter is None else c.scatter])
    atomic_write_text(out / "validation.csv", buf.getvalue())
    md = [f"# exucable validation ({'fast variants' if fast else 'paper fidelity'})", "",
          "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    md += ["| " + " | ".join(str(x) for x in r) + " |" for r in rows]
    if vr.differences:
        dh, dr = difference_rows(vr)
        md += ["", "## Steady against dynamic", "", "| " + " | ".join(dh) + " |", "|" + "---|" * len(dh)]
        md += ["| " + " | ".join(str(x) for x in r) + " |" for r in dr]
    times = ", ".join(f"{m} {t:.1f} s" for m, t in vr.mode_wall_time_s.items())
    md += ["", f"Wall time {vr.wall_time_s:.1f} s ({times})."]
    for case, msg in vr.failures:
        md.append(f"- {case}: run failed: {msg}")
    atomic_write_text(out / "validation.md", "\n".join(md) + "\n")
    plot_validation_figures(vr, out, load_reference())
