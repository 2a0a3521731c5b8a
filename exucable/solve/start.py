"""The dynamic run's start from a steady solve (``solver.start_from = "steady"``).

Its own module: it builds and solves a steady-mode model (:mod:`exucable.solve.steady`) for the
dynamic run (:mod:`exucable.solve.dynamic`), which neither of those should import.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

__all__ = ["SteadyStart", "steady_start", "BundleSteadyStart", "bundle_steady_start"]


@dataclass
class SteadyStart:
    """The dynamic run's start taken from a steady solve (``solver.start_from = "steady"``).

    Attributes
    ----------
    layout : exucable.model.layout.InitialLayout or None
        The start to build the dynamic model on; None when the steady solve failed (the run then
        starts from the rope, as with ``solver.start_from = "rope"``).
    pull_force_N : float
        The steady solve's pulling force [N] (nan when it failed).
    message : str
        The steady solve's message.
    wall_time_s : float
        Its wall time, model build included [s].
    """

    layout: object
    pull_force_N: float
    message: str
    wall_time_s: float


def steady_start(scenario, refine: float = 1.0, check_points_per_element: int | None = None) -> SteadyStart:
    """The steady sliding state at the dynamic run's own extent, as the dynamic run's start.

    The rope start (:func:`exucable.model.layout.initial_layout`) carries the rope's tension
    (EJ = 0) on the rope-with-clearance path. Where bending stiffness or gravity's free spans make
    the cable's steady tension differ from it (Gera's 2 ft bend: +9 %), the misfit
    rings in the cable's fundamental axial mode, which sliding Coulomb friction does not damp,
    and the cable's lateral shape in the clearance relaxes only as the material slides on, over a
    sliding distance of the order of the bend's boundary layer √(EJ/T) (Coulomb friction
    resists a lateral creep with μN·v_lat/V): seconds at a foot per second. The steady solve
    (:func:`exucable.solve.steady.solve_steady`, the same model without inertia, friction along
    the cable's tangent) gives that state directly; the dynamic run starts in it, laid out as
    steady mode lays it (on a route ending in a bend 10 bending lengths past it, so that the rig
    does not start inside the bend's boundary layer and pull out of it: ``solver.steady_lead_out``), sliding at the pull speed along its own shape
    (:func:`exucable.model.layout.sliding_layout`), and is then free to leave it: a state that
    is not the dynamics' steady state drifts away and the detector sees it.
    """
    import dataclasses

    from ..model.build import build_model
    from ..model.layout import initial_layout, sliding_layout
    from .steady import SteadySettings, solve_steady

    t0 = time.perf_counter()
    sc_steady = scenario.replace(**{"solver.mode": "steady"})
    model = build_model(sc_steady, refine=refine, check_points_per_element=check_points_per_element)
    out = solve_steady(model, settings=SteadySettings.from_solver(model.scenario.solver))
    if out.status == "failed":
        return SteadyStart(None, float("nan"), out.message, time.perf_counter() - t0)
    from .steady import steady_forces
    pull = steady_forces(model)[0]
    q, _ = model.coordinates()
    start = initial_layout(scenario, True, refine=refine, check_points_per_element=check_points_per_element)
    rope = start.cable
    if rope.n_elements != model.layout.n_elements:   # the same start rule: cannot happen; guard the indexing
        return SteadyStart(None, float("nan"), "the steady model's mesh differs from the dynamic one's",
                           time.perf_counter() - t0)
    cable = sliding_layout(rope.element_length_m, rope.node_x_m, rope.node_s_m, q[:, :3], q[:, 3:],
                           scenario.pull.speed_m_per_s)
    return SteadyStart(dataclasses.replace(start, cable=cable), float(pull), out.message, time.perf_counter() - t0)


@dataclass
class BundleSteadyStart:
    """A dynamic bundle run's start (``cable.count`` > 1): the steady bundle model and, with
    ``solver.start_from = "steady"``, its solved state.

    Attributes
    ----------
    model : exucable.model.bundle.BundleModel
        The steady bundle model of the scenario (mesh, arrangement, lead-out, rope references).
    layouts : list of CableLayout or None
        Each cable's solved shape sliding at the pull speed; None: start from the model's own start
        (the rope's, ``solver.start_from = "rope"``, or the steady solve failed).
    pull_force_N : float
        The steady solve's pulling force [N] (nan when not solved or failed).
    message : str
        The steady solve's message ("" when not solved).
    wall_time_s : float
        Its wall time, model build included [s].
    """

    model: object
    layouts: list | None
    pull_force_N: float
    message: str
    wall_time_s: float


def bundle_steady_start(scenario, refine: float = 1.0, solve: bool = True) -> BundleSteadyStart:
    """The steady bundle model of ``scenario`` (its start is the dynamic run's with
    ``solver.start_from = "rope"``) and, with ``solve``, its steady sliding state as the dynamic
    run's start: the same reasons as for one cable (:func:`steady_start`), and for a bundle the
    cables also start where they rest on one another and on the wall instead of falling the
    start's gap onto each other."""
    from ..model.bundle import build_bundle_model
    from ..model.bundle_rig import solved_bundle_layouts
    from .steady import SteadySettings, solve_steady

    t0 = time.perf_counter()
    model = build_bundle_model(scenario.replace(**{"solver.mode": "steady"}), refine=refine)
    if not solve:
        return BundleSteadyStart(model, None, float("nan"), "", time.perf_counter() - t0)
    out = solve_steady(model, settings=SteadySettings.from_solver(model.scenario.solver))
    if out.status == "failed":
        # the model's start (model.layout, data) is untouched by the solve: the run starts from it
        return BundleSteadyStart(model, None, float("nan"), out.message, time.perf_counter() - t0)
    return BundleSteadyStart(model, solved_bundle_layouts(model), float(np.sum(model.pull_shares_N())), out.message,
                             time.perf_counter() - t0)
