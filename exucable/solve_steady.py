"""Steady sliding in one static solve (``[solver] mode = "steady"``).

At a constant low pull speed the cable reaches a state whose shape and tension no longer change
in space: its material flows along a fixed curve at the pull speed V. Inertia is then negligible
(ρA·V² is millinewtons), every check point slides along the cable's own tangent, and the pulling
force is the reaction of a static equilibrium. The model is the dynamic run's (same ANCF cable,
contact law, smooth wall, broad phase, gravity, back tension), built by
:func:`exucable.model.build.build_model` with

- the contact kernel :class:`exucable.contact.steady.SteadySlidingKernel` (friction against the
  tangent, v = V ∂r/∂x, exact Jacobian);
- the rig holding the leading end where the start put it (its reaction is the pulling force), or
  for a force-controlled pull the trailing end (its reaction is the trailing tension);

and solved from the pre-tensioned start (the rope solution) with Exudyn's static solver.

Why load steps: the start is near equilibrium, but a full Newton step from it overshoots into
the wall (Hertz contact is stiff, 1e5-1e6 N/m per node, and the free spans are soft), and the
iterates then bounce between contact states. Exudyn's static solver can add a mass-proportional
term to the Jacobian that fades out over the load steps (``stabilizerODE2term``, scaled by
1 - λ², λ the load step's factor): a damped Newton that turns into plain Newton at the last step.
Where that does not converge, the loads themselves are ramped (friction, gravity and end forces
scaled by λ, ``continuation``) with steps halved on failure.

Convergence: Newton's residual relative to its largest value in the step; see
``reference/README.md`` for the stall near 1e-5 and the tolerance chosen here.
"""

from __future__ import annotations

import time

import numpy as np
import exudyn as exu

from .solve import History, Progress, SolveOutcome
from .tension import tension_at, tension_profile

__all__ = ["solve_steady", "static_settings", "STATIC_TOLERANCE"]

#: Newton's relative residual tolerance of the static solve [-]. Newton stalls near 1e-5 on the
#: paper's examples (the Hertz law's infinite curvature at first touch, see reference/README.md);
#: 1e-4 moves the pulling force by < 1e-5 relative there (measured: tests/test_steady.py).
STATIC_TOLERANCE = 1e-4

#: Load steps over which the Jacobian stabiliser fades out in one static solve.
LOAD_STEPS = 10

#: Smallest continuation increment of the load scale before the solve is declared failed.
MIN_CONTINUATION_STEP = 1.0 / 64.0


def stabilizer(model) -> float:
    """Mass-proportional Jacobian term [1/s²] of the first load step: an element's axial
    stiffness EA/L_e per its mass ρA·L_e, E/(ρ L_e²) — of the order of the contact stiffness per
    node, so the first steps are short and the iterates do not jump through the wall."""
    L_e = float(np.min(model.layout.element_length_m))
    return model.axial_stiffness_N / (model.properties.mass_per_length_kg_per_m * L_e * L_e)


def static_settings(model, load_steps: int = LOAD_STEPS, tolerance: float = STATIC_TOLERANCE,
                    max_iterations: int = 25) -> exu.SimulationSettings:
    """Exudyn's static solver settings of one steady solve (loads are scaled by us, not by
    Exudyn's load factor; the load steps only fade the stabiliser)."""
    s = exu.SimulationSettings()
    ss = s.staticSolver
    ss.numberOfLoadSteps = int(load_steps)
    ss.loadStepDuration = 1.0
    ss.useLoadFactor = False
    ss.stabilizerODE2term = stabilizer(model)
    ss.adaptiveStep = True
    ss.minimumStepSize = 1e-4
    ss.verboseMode = 0
    ss.newton.useModifiedNewton = False
    ss.newton.relativeTolerance = tolerance
    ss.newton.absoluteTolerance = 1e-10
    ss.newton.maxIterations = int(max_iterations)
    s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    s.solution.file.write = False
    s.solution.sensors.active = False
    s.show.computationTime = False
    s.show.statistics = False
    return s


class _StateStore:
    """Copies of the system's coordinates (displacements and multipliers) to restart from."""

    def __init__(self, mbs):
        self.mbs = mbs
        self.saved = self.read()

    def read(self):
        sd = self.mbs.systemData
        return (np.array(sd.GetODE2Coordinates()), np.array(sd.GetAECoordinates()))

    def save(self):
        self.saved = self.read()

    def restore_as_initial(self):
        """Make the saved state the next solve's start."""
        sd = self.mbs.systemData
        q, lam = self.saved
        for cfg in (exu.ConfigurationType.Initial, exu.ConfigurationType.Current):
            sd.SetODE2Coordinates(list(q), configuration=cfg)
            sd.SetAECoordinates(list(lam), configuration=cfg)


def steady_forces(model) -> tuple[float, float, float]:
    """Pulling force, trailing tension and maximum tension [N] of the current static state.

    The static solver's Lagrange multipliers carry the opposite sign of the dynamic solver's
    (checked: the leading end's reaction then equals its tension EA·ε, tests/test_steady.py).
    """
    q, _ = model.coordinates()
    EA = model.axial_stiffness_N
    _, N = tension_profile(q, model.layout.element_length_m, EA, points_per_element=2)
    if model.lead_drive is not None:
        pull = -model.lead_drive.force_N(model.mbs)
    else:
        pull = model.applied_pull_force_N * model.load_scale.end_force
    if model.trail_drive is not None:
        trail = model.trail_drive.force_N(model.mbs)
    else:
        trail = float(tension_at(q, model.layout.element_length_m, EA, [0.0])[0])
    return float(pull), float(trail), float(np.max(N))


def _set_scale(model, lam: float) -> None:
    model.load_scale.gravity = lam
    model.load_scale.end_force = lam
    model.kernel.set_friction_scale(lam)


def solve_steady(model, progress: Progress | None = None) -> SolveOutcome:
    """Solve ``model`` (built with ``solver.mode = "steady"``) for its steady sliding state.

    First one static solve at the full loads; if it fails, continuation from the start in the
    load scale λ (friction, gravity, end forces), doubling the increment after a success and
    halving it after a failure. The history has one row per converged load step, its
    ``time_s`` column holding the continuation parameter (stage - 1 + load step factor) [-].

    Never raises for a diverging solve: the outcome has ``status == "failed"`` and the message.
    """
    mbs = model.mbs
    history = History()
    store = _StateStore(mbs)
    stage = [0]
    counters = {"newton": 0, "jacobian": 0, "steps": 0}
    t_wall = time.perf_counter()

    def post_step(mbs_, t):
        if t <= 0.0:       # Exudyn's call for the start state: not a solved load step
            return True
        pull, trail, tmax = steady_forces(model)
        history.time_s.append(stage[0] + float(t))
        history.pull_force_N.append(pull)
        history.trailing_tension_N.append(trail)
        history.max_tension_N.append(tmax)
        if progress is not None:
            progress.update(stage[0] + float(t), f"F = {pull:.4g} N")
        return True

    mbs.SetPostStepUserFunction(post_step)

    def attempt(lam: float) -> tuple[bool, str]:
        _set_scale(model, lam)
        solver = exu.MainSolverStatic()
        n_rows = len(history.time_s)
        try:
            ok = solver.SolveSystem(mbs, static_settings(model))
            message = "" if ok else (solver.GetErrorString() or "Newton did not converge")
        except Exception as exc:  # Exudyn raises plain RuntimeError/ValueError on divergence
            ok, message = False, f"{type(exc).__name__}: {exc}".strip()
        counters["newton"] += int(solver.it.newtonStepsCount)
        counters["jacobian"] += int(solver.it.newtonJacobiCount)
        counters["steps"] += int(solver.it.currentStepIndex)
        if not ok:
            del history.time_s[n_rows:], history.pull_force_N[n_rows:]
            del history.trailing_tension_N[n_rows:], history.max_tension_N[n_rows:]
        return ok, message

    status, message = "ok", ""
    ok, first_message = attempt(1.0)
    if ok:
        message = "direct static solve"
    else:
        # continuation from the start in the load scale
        store.restore_as_initial()
        lam, step = 0.0, 0.25
        while lam < 1.0:
            target = min(1.0, lam + step)
            stage[0] += 1
            ok, msg = attempt(target)
            if ok:
                lam = target
                store.save()
                store.restore_as_initial()
                step = min(2.0 * step, 1.0)
            else:
                store.restore_as_initial()
                step *= 0.5
                if step < MIN_CONTINUATION_STEP:
                    status = "failed"
                    message = (f"no steady state found: continuation stalled at load scale {lam:.4g} "
                               f"(direct solve: {first_message}; last: {msg})")
                    break
        if status == "ok":
            message = f"continuation in {stage[0]} stages (direct solve failed: {first_message})"
    mbs.SetPostStepUserFunction(0)
    wall = time.perf_counter() - t_wall
    if progress is not None:
        progress.close()
    return SolveOutcome(history=history, status=status, message=message, end_time_s=0.0,
                        steps=counters["steps"], newton_iterations=counters["newton"],
                        jacobian_updates=counters["jacobian"], wall_time_s=wall)
