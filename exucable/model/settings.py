"""Exudyn simulation settings for a scenario's ``[solver]`` table (both solve modes use them).

Lives with the model so that :meth:`~exucable.model.build.CableModel.recommended_settings` needs
nothing from ``solve/``; the solvers import it from here.
"""

from __future__ import annotations

import numpy as np
import exudyn as exu

__all__ = ["solver_settings", "quiet_sparse"]


def solver_settings(solver_spec) -> exu.SimulationSettings:
    """Simulation settings from a scenario's ``[solver]`` table (docs/theory.md and scenarios/README.md say why each)."""
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.endTime = solver_spec.end_time_s
    ti.initialStepSize = solver_spec.step_s
    ti.numberOfSteps = max(1, int(np.ceil(solver_spec.end_time_s / solver_spec.step_s)))
    ti.minimumStepSize = solver_spec.min_step_s
    ti.automaticStepSize = True
    ti.adaptiveStep = True
    # After a failed step Exudyn halves the step and doubles it again after `RecoverySteps` steps
    # that took at most `RecoveryIterations` Newton iterations. With fewer, the doubling failed again
    # and again and the rejected attempts burnt a third to a half of all iterations; 4 and 4 cut them
    # at the same results (benchmarks/newton_trace.py; decision record 0002).
    ti.adaptiveStepRecoverySteps = 4
    ti.adaptiveStepRecoveryIterations = 4
    ti.newton.useModifiedNewton = False          # full Newton on the exact Jacobian
    ti.newton.maxIterations = solver_spec.newton_max_iterations
    ti.newton.relativeTolerance = solver_spec.newton_tolerance
    ti.generalizedAlpha.spectralRadius = solver_spec.spectral_radius
    ti.verboseMode = 0
    return quiet_sparse(s)


def quiet_sparse(s: exu.SimulationSettings) -> exu.SimulationSettings:
    """Sparse linear solver, no solution file, sensors or statistics (both solve modes); no
    loads' Jacobian in a static solve."""
    s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    # The loads (each element's weight, the end forces) do not depend on the coordinates, so their
    # Jacobian is zero; the static solver's default differentiates every element's weight
    # numerically each Newton iteration (8-10 % of one at 1 km). The time integration's default
    # already skips it.
    s.staticSolver.computeLoadsJacobian = False
    s.solution.file.write = False
    s.solution.sensors.active = False
    s.show.computationTime = False
    s.show.statistics = False
    return s
