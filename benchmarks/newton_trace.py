"""Where a dynamic run's Newton iterations go, measured in one run.

Runs a scenario with Exudyn's ``timeIntegration.verboseMode = 2`` in a child process, parses the
per-iteration residuals that Exudyn prints, and reports per scenario:

- accepted steps and the Newton iterations they took (mean, median, max), rejected step attempts
  and the iterations spent in them, "System Jacobian seems to be singular" events;
- the residual contraction per iteration (residual_k / residual_(k-1)) of accepted steps, by
  iteration index: quadratic convergence shows as contractions falling fast (0.1, 1e-2, 1e-4),
  an inexact Jacobian as a constant contraction (linear convergence);
- optional overrides (``--set key=value`` with dotted scenario keys, or ``--exudyn key=value``
  with dotted ``SimulationSettings.timeIntegration`` attributes) to test one suspect at a time.

    .venv/bin/python benchmarks/newton_trace.py scenarios/paper_ex3_helix.toml
    .venv/bin/python benchmarks/newton_trace.py scenarios/paper_ex4_spatial.toml --end-time 0.1 \
        --exudyn newton.numericalDifferentiation.forODE2=True
    .venv/bin/python benchmarks/newton_trace.py --quick      # smoke run: the fast Example 2 over 0.05 s

The verbose mode and the overrides are Exudyn settings that ``simulate`` builds inside, and
``--solve`` names module settings of :mod:`exucable.solve.dynamic`: the child process swaps them in
for its one run and restores them after (nothing outside that child sees them).

Prints a Markdown summary (and ``--json`` the parsed steps).
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

_STEP = re.compile(r"^STEP(\d+), t = ([-0-9.e+]+), step size = ([-0-9.e+]+)")
_ITER = re.compile(r"NEWTON STEP (\d+): residual = ([-0-9.e+infa]+): relTol = ([-0-9.e+infa]+)")
_INITIAL = re.compile(r"Newton: initial residual = ([-0-9.e+infa]+)")

_CHILD = r"""
import sys, json, time
sys.path.insert(0, {root!r})
from exucable.scenario.specs import load_scenario, parse_scenario
from exucable.model.build import build_model
import exucable.solve.dynamic as solve
import tomllib
with open({path!r}, "rb") as f:
    data = tomllib.load(f)
for dotted, value in {overrides!r}.items():
    table, key = dotted.split(".", 1)
    data.setdefault(table, {{}})[key] = value
sc = parse_scenario(data, {parent!r}, default_name={stem!r})
base = solve.solver_settings
def settings(sp):
    s = base(sp)
    s.timeIntegration.verboseMode = 2
    for dotted, value in {exudyn!r}.items():
        obj = s.timeIntegration
        *head, last = dotted.split(".")
        for h in head:
            obj = getattr(obj, h)
        setattr(obj, last, value)
    return s
saved = dict(solver_settings=base, **{{name: getattr(solve, name) for name in {solve_attrs!r}}})
solve.solver_settings = settings
for name, value in {solve_attrs!r}.items():
    setattr(solve, name, value)
try:
    t0 = time.perf_counter()
    model = build_model(sc)
    out = solve.simulate(model)
finally:
    for name, value in saved.items():
        setattr(solve, name, value)
c = model.coupling
h = out.history
print("@@RESULT " + json.dumps(dict(status=out.status, steps=out.steps, newton=out.newton_iterations,
      end_time_s=out.end_time_s, wall_s=time.perf_counter() - t0,
      force_calls=c.force_calls, jacobian_calls=c.jacobian_calls, kernel_s=c.kernel_time_s,
      pull_force_N=h.pull_force_N[-1], trailing_N=h.trailing_tension_N[-1])), flush=True)
"""


def _value(text: str):
    for conv in (int, float):
        try:
            return conv(text)
        except ValueError:
            pass
    return {"True": True, "False": False}.get(text, text)


def trace(path, overrides=None, exudyn=None, end_time=None, steady_stop=None, solve_attrs=None):
    """Run ``path`` in a child process with Exudyn's verbose Newton output; return (result, attempts).

    Each attempt is a dict with ``t`` [s], ``h`` [s], ``residuals`` (initial first), ``accepted``,
    ``singular``.
    """
    path = Path(path).resolve()
    ov = dict(overrides or {})
    if end_time is not None:
        ov["solver.end_time"] = end_time
    if steady_stop is not None:
        ov["solver.steady_stop"] = steady_stop
    code = _CHILD.format(root=str(ROOT), path=str(path), overrides=ov, parent=str(path.parent),
                         stem=path.stem, exudyn=dict(exudyn or {}),
                         solve_attrs=dict(solve_attrs or {}))
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True, bufsize=1 << 16)
    attempts, cur, result = [], None, None
    for line in proc.stdout:
        m = _STEP.match(line)
        if m:
            cur = {"t": float(m.group(2)), "h": float(m.group(3)), "residuals": [], "accepted": False,
                   "singular": False}
            attempts.append(cur)
            continue
        if cur is None:
            continue
        if (m := _INITIAL.search(line)):
            cur["residuals"].append(float(m.group(1)))
        elif (m := _ITER.search(line)):
            cur["residuals"].append(float(m.group(2)))
        elif "converged after" in line:
            cur["accepted"] = True
        elif "singular" in line:
            cur["singular"] = True
        elif line.startswith("@@RESULT "):
            result = json.loads(line[9:])
    proc.wait()
    if result is None:
        raise RuntimeError(f"{path}: the child process ended without a result (exit {proc.returncode})")
    return result, attempts


def summarize(result, attempts) -> dict:
    """Counts and contraction statistics of a :func:`trace`."""
    acc = [a for a in attempts if a["accepted"]]
    rej = [a for a in attempts if not a["accepted"]]
    its_acc = np.array([len(a["residuals"]) - 1 for a in acc]) if acc else np.zeros(1)
    its_rej = sum(len(a["residuals"]) - 1 for a in rej)
    contractions = {}
    for a in acc:
        r = np.asarray(a["residuals"])
        for k in range(1, len(r)):
            if r[k - 1] > 0:
                contractions.setdefault(k, []).append(r[k] / r[k - 1])
    return {
        "accepted": len(acc), "rejected": len(rej), "singular": sum(a["singular"] for a in attempts),
        "iterations_accepted": int(its_acc.sum()), "iterations_rejected": int(its_rej),
        "per_accepted_step_mean": float(its_acc.mean()), "per_accepted_step_median": float(np.median(its_acc)),
        "per_accepted_step_max": int(its_acc.max()),
        "contraction_median_by_iteration": {k: float(np.median(v)) for k, v in sorted(contractions.items())
                                            if len(v) >= 3},
        "result": result,
    }


def print_summary(label, s) -> None:
    r = s["result"]
    total = s["iterations_accepted"] + s["iterations_rejected"]
    print(f"### {label}\n")
    print(f"status {r['status']}, simulated {r['end_time_s']:.4g} s, wall {r['wall_s']:.2f} s (verbose output included), "
          f"pulling force {r['pull_force_N']:.6g} N, trailing {r['trailing_N']:.6g} N\n")
    print("| accepted steps | rejected attempts | singular | Newton its (all) | per step (all) | "
          "in accepted: mean / median / max | spent in rejected | force calls | Jacobian calls |")
    print("|---|---|---|---|---|---|---|---|---|")
    print(f"| {s['accepted']} | {s['rejected']} | {s['singular']} | {total} | {total / max(s['accepted'], 1):.2f} | "
          f"{s['per_accepted_step_mean']:.2f} / {s['per_accepted_step_median']:.0f} / {s['per_accepted_step_max']} | "
          f"{s['iterations_rejected']} ({100 * s['iterations_rejected'] / max(total, 1):.0f} %) | "
          f"{r['force_calls']} | {r['jacobian_calls']} |")
    c = s["contraction_median_by_iteration"]
    print("\nmedian residual contraction in accepted steps, by iteration: "
          + ", ".join(f"{k}: {v:.2g}" for k, v in c.items()) + "\n", flush=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenario", nargs="*", help="scenario files (required unless --quick)")
    ap.add_argument("--end-time", type=float, default=None, help="override solver.end_time [s]")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="dotted scenario key")
    ap.add_argument("--exudyn", action="append", default=[], metavar="KEY=VALUE",
                    help="dotted attribute of SimulationSettings.timeIntegration")
    ap.add_argument("--solve", action="append", default=[], metavar="NAME=VALUE",
                    help="module setting of exucable.solve.dynamic (e.g. PREDICTOR=zero)")
    ap.add_argument("--json", default=None, help="write the parsed attempts here")
    ap.add_argument("--quick", action="store_true",
                    help="smoke run: scenarios/fast/paper_ex2_bend90.toml over 0.05 s (unless given)")
    args = ap.parse_args(argv)
    if args.quick:
        args.scenario = args.scenario or [str(ROOT / "scenarios" / "fast" / "paper_ex2_bend90.toml")]
        args.end_time = 0.05 if args.end_time is None else args.end_time
    if not args.scenario:
        ap.error("scenario: give at least one scenario file (or --quick)")
    ov = {k: _value(v) for k, v in (s.split("=", 1) for s in args.set)}
    ex = {k: _value(v) for k, v in (s.split("=", 1) for s in args.exudyn)}
    sv = {k: _value(v) for k, v in (s.split("=", 1) for s in args.solve)}
    dump = {}
    for path in args.scenario:
        result, attempts = trace(path, ov, ex, args.end_time, solve_attrs=sv)
        s = summarize(result, attempts)
        label = f"{Path(path).parent.name}/{Path(path).name} {' '.join(args.set + args.exudyn + args.solve)}".strip()
        print_summary(label, s)
        dump[label] = {"summary": s, "attempts": attempts}
    if args.json:
        Path(args.json).write_text(json.dumps(dump))
    return 0


if __name__ == "__main__":
    sys.exit(main())
