"""Time integration of an assembled model: progress, recording, steady-state stop, failures.

Exudyn's implicit generalized-alpha solver (the paper used BDF, Sect. 2.6) with adaptive steps
and full Newton on the exact contact Jacobian. A post-step hook records the pulling force,
the trailing tension and the maximum tension at every output interval, draws the progress bar,
and (optionally) stops the run once the pulling force is steady.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from typing import Literal

import numpy as np
import exudyn as exu

from ..model.recorder import History, Recorder, earliest_steady_s, expected_drift_N_per_s, steady_quantity
from ..model.settings import quiet_sparse, solver_settings

# the first step is solver.step / START_STEP_DIVISOR (see simulate)
START_STEP_DIVISOR = 128
# hold each check point's contact damping onset at the step's start value within a step
# (ContactLaw's notes; Newton iterations Ex. 4 381 -> 288). False: g(δ) of every iterate.
HOLD_ONSET = True

__all__ = ["History", "SolveOutcome", "simulate", "solver_settings", "steady_quantity", "expected_drift_N_per_s",
           "earliest_steady_s",
           "Progress"]


@dataclass
class SolveOutcome:
    """What the integration did."""

    history: History
    status: Literal["ok", "steady", "failed"]  # "steady": stopped early, once steady
    message: str
    end_time_s: float            # simulated time reached [s]
    steps: int
    newton_iterations: int
    jacobian_updates: int
    wall_time_s: float
    started_from: str = "rope"   # a steady solve's start that converged: "rope" or "coarse mesh"
    static_solver: str | None = None   # a steady solve's static solver: "exucable" or "exudyn"
    backtracks: int = 0          # a steady solve's force evaluations of shortened steps (no Newton iteration)
    onset_layer: dict | None = None    # several cables' steady solve: OnsetContinuation.summary()


class Progress:
    """A one-line progress bar on stderr, shown only when stderr is a terminal."""

    def __init__(self, total_s: float, label: str = "", enabled: bool = True, stream=None):
        self.stream = stream or sys.stderr
        self.enabled = enabled and hasattr(self.stream, "isatty") and self.stream.isatty()
        self.total = total_s
        self.label = label
        self._last = -1.0
        self._t0 = time.perf_counter()

    def update(self, t: float, extra: str = "") -> None:
        if not self.enabled:
            return
        now = time.perf_counter()
        if now - self._last < 0.2 and t < self.total:
            return
        self._last = now
        frac = min(max(t / self.total, 0.0), 1.0) if self.total > 0 else 1.0
        n = int(30 * frac)
        self.stream.write(f"\r{self.label} [{'#' * n}{'.' * (30 - n)}] t = {t:.3f}/{self.total:.3f} s "
                          f"{now - self._t0:6.1f} s wall {extra}   ")
        self.stream.flush()

    def close(self) -> None:
        if self.enabled:
            self.stream.write("\n")
            self.stream.flush()


def simulate(model, progress: Progress | None = None, steady_stop: bool | None = None,
             snapshots=None) -> SolveOutcome:
    """Integrate ``model`` to the scenario's end time (or to a steady pulling force).

    Records with the model's :class:`~exucable.model.recorder.Recorder`; a post-step function
    already set on ``model.mbs`` is called after it each step and set back afterwards.
    ``snapshots`` (an :class:`exucable.output.snapshots.SnapshotRecorder`, optional) is fed the state at
    the end of every step.

    Never raises for a diverging run: the outcome has ``status == "failed"``, the simulated time
    where it happened, and the history recorded until then.
    """
    sp = model.scenario.solver
    steady_stop = sp.steady_stop if steady_stop is None else steady_stop
    recorder = Recorder(model, sp.output_interval_s, steady_stop, sp.steady_window_s, sp.steady_tolerance,
                        progress=progress.update if progress is not None else None,
                        earliest_steady_s=earliest_steady_s(model))
    history = recorder.history
    mbs = model.mbs
    # Exudyn 1.13 returns {"function": f, "type": "Python"} for a set function, 0 for none
    previous = mbs.GetPostStepUserFunction()
    users = previous.get("function") if isinstance(previous, dict) else (previous or None)

    solver = exu.MainSolverImplicitSecondOrder()
    settings = solver_settings(sp)
    # Exudyn's generalized-alpha starts at its maximum step (its initialStepSize is for the
    # error-controlled integrators only) and halves it after each failed attempt; a failed attempt
    # burns all its Newton iterations. The pre-tensioned start needs steps of about step/128
    # (measured: Example 4 fails at 10 ... 0.16 ms, seven attempts, 84 iterations, before 78 µs
    # passes). So the first step is capped there and the cap is lifted after it: the usual step
    # control then doubles the step as Newton allows.
    ti = settings.timeIntegration
    max_steps = ti.numberOfSteps
    ti.numberOfSteps = max(max_steps, int(np.ceil(sp.end_time_s / (sp.step_s / START_STEP_DIVISOR))))
    lifted = [max_steps == ti.numberOfSteps]

    def post_step(mbs, t):
        if not lifted[0] and t > 0.0:
            solver.it.maxStepSize = sp.end_time_s / max_steps
            lifted[0] = True
        if HOLD_ONSET and model.coupling is not None:
            model.coupling.start_step(mbs, t)
        if snapshots is not None:
            snapshots.step(t, model.pull_force_N(t))
        go_on = recorder(mbs, t)
        if users is not None:
            go_on = (users(mbs, t) is not False) and go_on
        return go_on

    mbs.SetPostStepUserFunction(post_step)
    if HOLD_ONSET and model.coupling is not None:
        model.coupling.start_step(mbs, mbs.systemData.GetTime())
    t0 = time.perf_counter()
    status, message = "ok", ""
    try:
        ok = solver.SolveSystem(mbs, settings)
        if not ok and not recorder.stopped_steady:
            status, message = "failed", (solver.GetErrorString() or "the solver did not converge")
    except Exception as exc:  # Exudyn raises plain RuntimeError/ValueError on divergence
        status, message = "failed", f"{type(exc).__name__}: {exc}".strip()
    finally:
        mbs.SetPostStepUserFunction(users if users is not None else 0)
    wall = time.perf_counter() - t0
    t_end = float(solver.it.currentTime)
    if recorder.stopped_steady and status == "ok":
        status = "steady"
    if status != "failed" and (not history.time_s or history.time_s[-1] < t_end - 1e-12):
        recorder.record(t_end)
    if progress is not None:
        progress.update(t_end)
        progress.close()
    return SolveOutcome(history=history, status=status, message=message, end_time_s=t_end,
                        steps=int(solver.it.currentStepIndex), newton_iterations=int(solver.it.newtonStepsCount),
                        jacobian_updates=int(solver.it.newtonJacobiCount), wall_time_s=wall)
