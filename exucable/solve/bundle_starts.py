"""Several cables' steady solve from a sequence of starts (``[solver] bundle_starts``).

Which start a bundle's steady solve can get from is not known before it is tried: the clearance
start (:func:`exucable.model.bundle.build_bundle_model`'s ``start_path = "clearance"``) solves the
up-bend study's 12 cases and the 100 m cradle, while on the 100 m triangle its dynamic relaxation
stalls at 29.4 N, 1.7e4 stop tolerances, and only the cross-section's statics start
(``"statics_own"``) solves it. And the start chooses among the steady states where there are
several (the up-bend with cable friction: 468.1 N from the clearance start, 484.9 N from the
statics start), so a solve that converges must keep the start it converged from.

So the starts are tried in turn (:func:`solve_bundle_starts`): each but the last gives up where its
dynamic relaxation stalls (:class:`~exucable.solve.steady.SteadySolver`'s ``fallback``: no halving
in ``SteadySettings.bundle_start_stall_steps`` steps or more, no exact-step continuation or load ramp
after it), and the next is built and solved in the CPU time left of ``time_limit_s``, which
holds for the whole sequence. A solve that converges from the first start is the single-start
solve, step for step.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

from .dynamic import Progress, SolveOutcome
from .onset_continuation import OnsetSettings
from .steady import SteadySettings, SteadySolver

__all__ = ["StartAttempt", "BundleStartsOutcome", "solve_bundle_starts"]


@dataclass
class StartAttempt:
    """One start tried: its name (``start_path``), status (``"ok"`` or ``"failed"``), CPU time [s]
    (its build included, but for the first start's), Newton iterations [-] and message."""

    start: str
    status: str
    cpu_s: float
    newton_iterations: int
    message: str


@dataclass
class BundleStartsOutcome:
    """The sequence's result: the model and outcome of the start that gave the answer (the last one
    tried), that start's name and every attempt in order."""

    model: object
    outcome: SolveOutcome
    start: str
    attempts: list


def solve_bundle_starts(scenario, model, refine: float = 1.0, settings: SteadySettings | None = None,
                        progress: Progress | None = None, on_start=None) -> BundleStartsOutcome:
    """Solve a bundle's steady state from ``settings.bundle_starts`` in turn (the module's notes).

    Parameters
    ----------
    scenario : exucable.scenario.Scenario
        The bundle's scenario (``cable.count`` > 1, steady mode).
    model : exucable.model.bundle.BundleModel
        The bundle built from the first start (``build_bundle_model(scenario, refine,
        start_path=settings.bundle_starts[0])``); the later starts' models are built here.
    refine : float
        ``build_bundle_model``'s ``refine`` for the later starts [-].
    settings : SteadySettings
        The solve's settings; ``time_limit_s`` [s] is the CPU time of the whole sequence, the
        builds after the first included.
    progress : Progress, optional
        Told each solve's progress.
    on_start : callable, optional
        Called as ``on_start(start, model)`` before each start's solve, so that a caller whose own
        budget stops the sequence by an exception (the plan's CPU budget) still holds the state
        that was being solved, not the first start's.

    Returns
    -------
    BundleStartsOutcome
        The outcome's ``steps`` and ``newton_iterations`` count every attempt's; its message says
        which start gave the answer and why the ones before it gave up.
    """
    from ..model.bundle import build_bundle_model

    settings = SteadySettings() if settings is None else settings
    starts = settings.bundle_starts
    t0 = time.process_time()
    attempts: list[StartAttempt] = []
    steps = iterations = 0
    for k, start in enumerate(starts):
        t_start = time.process_time()
        last = k == len(starts) - 1
        if k:
            model = build_bundle_model(scenario, refine=refine, start_path=start)
        if on_start is not None:
            on_start(start, model)
        left = settings.time_limit_s - (time.process_time() - t0)
        solver = SteadySolver(model, replace(settings, time_limit_s=max(left, 1e-3)), progress,
                              onset=OnsetSettings(), fallback=not last)
        out = solver.solve()
        steps += out.steps
        iterations += out.newton_iterations
        attempts.append(StartAttempt(start, out.status, time.process_time() - t_start, out.newton_iterations,
                                     out.message))
        if out.status != "failed" or solver.timed_out or time.process_time() - t0 >= settings.time_limit_s:
            break
    if len(attempts) > 1:
        before = "; ".join(f'"{a.start}" gave up after {a.cpu_s:.3g} s CPU: {a.message}' for a in attempts[:-1])
        out = replace(out, message=f'from the start "{start}" ({before}): {out.message}')
    out = replace(out, steps=steps, newton_iterations=iterations)
    return BundleStartsOutcome(model=model, outcome=out, start=start, attempts=attempts)
