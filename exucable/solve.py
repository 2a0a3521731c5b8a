"""Time integration of an assembled model: progress, recording, steady-state stop, failures.

Exudyn's implicit generalized-alpha solver (the paper used BDF, Sect. 2.6) with adaptive steps
and full Newton on the exact contact Jacobian. A post-step hook records the pulling force,
the trailing tension and the maximum tension at every output interval, draws the progress bar,
and (optionally) stops the run once the pulling force is steady.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import exudyn as exu

from .tension import detect_steady_state, tension_at, tension_profile

__all__ = ["History", "SolveOutcome", "simulate", "solver_settings", "steady_quantity", "expected_drift_N_per_s",
           "Progress"]


@dataclass
class History:
    """Time histories saved at the output interval."""

    time_s: list = field(default_factory=list)
    pull_force_N: list = field(default_factory=list)
    trailing_tension_N: list = field(default_factory=list)
    max_tension_N: list = field(default_factory=list)

    def arrays(self) -> dict[str, np.ndarray]:
        return {k: np.asarray(v, dtype=float) for k, v in self.__dict__.items()}


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


def solver_settings(solver_spec) -> exu.SimulationSettings:
    """Simulation settings from a scenario's ``[solver]`` table (see the README for why each)."""
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.endTime = solver_spec.end_time_s
    ti.initialStepSize = solver_spec.step_s
    ti.numberOfSteps = max(1, int(np.ceil(solver_spec.end_time_s / solver_spec.step_s)))
    ti.minimumStepSize = solver_spec.min_step_s
    ti.automaticStepSize = True
    ti.adaptiveStep = True
    # After a failed step Exudyn halves the step and doubles it again after `RecoverySteps` steps
    # that took at most `RecoveryIterations` Newton iterations. At 2 steps and any count (7), the
    # doubling failed again and again (a rejected attempt burns all its iterations: 45-59 % of
    # Examples 2 and 3's iterations, 31 % of Example 4's). 4 and 4, measured with
    # benchmarks/newton_trace.py: Newton iterations Ex. 2 398 -> 356, Ex. 3 821 -> 479,
    # Ex. 4 1947 -> 1818, Ex. 1 37 -> 37, results within 7e-5 relative.
    ti.adaptiveStepRecoverySteps = 4
    ti.adaptiveStepRecoveryIterations = 4
    ti.newton.useModifiedNewton = False          # full Newton on the exact Jacobian
    ti.newton.maxIterations = solver_spec.newton_max_iterations
    ti.newton.relativeTolerance = solver_spec.newton_tolerance
    ti.generalizedAlpha.spectralRadius = solver_spec.spectral_radius
    ti.verboseMode = 0
    return quiet_sparse(s)


def quiet_sparse(s: exu.SimulationSettings) -> exu.SimulationSettings:
    """Sparse linear solver, no solution file, sensors or statistics (both solve modes)."""
    s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    s.solution.file.write = False
    s.solution.sensors.active = False
    s.show.computationTime = False
    s.show.statistics = False
    return s


def steady_quantity(model) -> str:
    """The history column whose steadiness ends a run: the pulling force, or for a
    force-controlled pull (whose pulling force is given) the trailing tension."""
    return "trailing_tension_N" if model.applied_pull_force_N is not None else "pull_force_N"


def record_state(model, t: float, history: History) -> None:
    """Append the current pulling force, trailing tension and maximum tension to ``history``."""
    q, _ = model.coordinates()
    EA = model.axial_stiffness_N
    _, N = tension_profile(q, model.layout.element_length_m, EA, points_per_element=2)
    trail = model.trailing_reaction_N()
    if trail is None:
        trail = float(tension_at(q, model.layout.element_length_m, EA, [0.0])[0])
    history.time_s.append(float(t))
    history.pull_force_N.append(model.pull_force_N(t))
    history.trailing_tension_N.append(float(trail))
    history.max_tension_N.append(float(np.max(N)))


def expected_drift_N_per_s(model) -> float:
    """The drift the steady detector takes off the steady quantity [N/s]: the flexible reference's,
    as the cable leaves its conduit (pulling force of a velocity-controlled pull), else 0."""
    if steady_quantity(model) != "pull_force_N":
        return 0.0
    return float(getattr(model, "reference_drift_N_per_s", 0.0))


def simulate(model, progress: Progress | None = None, steady_stop: bool | None = None,
             snapshots=None) -> SolveOutcome:
    """Integrate ``model`` to the scenario's end time (or to a steady pulling force).

    ``snapshots`` (an :class:`exucable.snapshots.SnapshotRecorder`, optional) is fed the state at
    the end of every step.

    Never raises for a diverging run: the outcome has ``status == "failed"``, the simulated time
    where it happened, and the history recorded until then.
    """
    sp = model.scenario.solver
    steady_stop = sp.steady_stop if steady_stop is None else steady_stop
    history = History()
    out_dt = sp.output_interval_s
    next_out = [0.0]
    stopped_steady = [False]
    # nothing is recorded at t = 0: the rig's reaction (a Lagrange multiplier) exists only
    # once a step has been solved
    next_out[0] = out_dt

    def post_step(mbs, t):
        if snapshots is not None:
            snapshots.step(t, model.pull_force_N(t))
        if t >= next_out[0] - 1e-12 * max(1.0, t):
            record_state(model, t, history)
            next_out[0] = (np.floor(t / out_dt + 1e-9) + 1.0) * out_dt
            if progress is not None:
                progress.update(t, f"F = {history.pull_force_N[-1]:.4g} N")
            if steady_stop and t >= sp.steady_window_s:
                st = detect_steady_state(history.time_s, getattr(history, steady_quantity(model)),
                                         sp.steady_window_s, sp.steady_tolerance,
                                         expected_drift_N_per_s=expected_drift_N_per_s(model))
                if st.steady:
                    stopped_steady[0] = True
                    return False
        return True

    model.mbs.SetPostStepUserFunction(post_step)
    solver = exu.MainSolverImplicitSecondOrder()
    settings = solver_settings(sp)
    t0 = time.perf_counter()
    status, message = "ok", ""
    try:
        ok = solver.SolveSystem(model.mbs, settings)
        if not ok and not stopped_steady[0]:
            status, message = "failed", (solver.GetErrorString() or "the solver did not converge")
    except Exception as exc:  # Exudyn raises plain RuntimeError/ValueError on divergence
        status, message = "failed", f"{type(exc).__name__}: {exc}".strip()
    wall = time.perf_counter() - t0
    t_end = float(solver.it.currentTime)
    if stopped_steady[0] and status == "ok":
        status = "steady"
    if status != "failed" and (not history.time_s or history.time_s[-1] < t_end - 1e-12):
        record_state(model, t_end, history)
    if progress is not None:
        progress.update(t_end)
        progress.close()
    model.mbs.SetPostStepUserFunction(0)
    return SolveOutcome(history=history, status=status, message=message, end_time_s=t_end,
                        steps=int(solver.it.currentStepIndex), newton_iterations=int(solver.it.newtonStepsCount),
                        jacobian_updates=int(solver.it.newtonJacobiCount), wall_time_s=wall)
