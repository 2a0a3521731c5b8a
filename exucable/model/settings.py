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
