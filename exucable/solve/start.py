"""Starts of a solve taken from another solve's state.

- The dynamic run's start from a steady solve (``solver.start_from = "steady"``,
  :func:`steady_start`; several cables: :func:`bundle_steady_start`). Its own module: it builds and
  solves a steady-mode model (:mod:`exucable.solve.steady`) for the dynamic run
  (:mod:`exucable.solve.dynamic`), which neither of those should import.
- The steady solve's start on a fine mesh from the coarse mesh's solved state (nested iteration,
  :func:`nested_start`): an ANCF cable element's centreline is a cubic Hermite curve of its material
  coordinate, so a fine mesh whose nodes lie on the coarse one's elements (each coarse element split
  in two: the solved mesh of steady mode against the error bar's coarse mesh) carries that curve
  exactly, nodal positions and slopes (the slope's length is 1 + the axial strain).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

__all__ = ["SteadyStart", "steady_start", "BundleSteadyStart", "bundle_steady_start", "hermite_state",
           "nested_start", "resolves_bend_ends", "NESTED_MAX_BENDING_LENGTHS"]

#: The nested start is taken only where the coarse mesh's elements are at most this many bending
#: lengths √(EJ/T) long [-]. Longer elements do not resolve the bend ends' boundary layer, and the
#: coarse state lies millimetres off the fine one there (10 km of benchmarks/long_routes.py: 4 mm
#: at the bends, 23 mm along the cable at its tail, the pulling force 5e-4 apart). Measured on the
#: long routes (coarse elements of 4.1, 5.8, 10.1, 17.9 bending lengths at 1, 2, 5, 10 km): the
#: fine solve took 7, 8, 9 Newton iterations from the coarse state against 19, 26, 24 from the rope
#: start, but at 10 km 28 or more (or gave up) against 21. A bound between the last two, nearer
#: the one that worked.
NESTED_MAX_BENDING_LENGTHS = 12.0


def hermite_state(q, node_x_m, x_m) -> np.ndarray:
    """Positions and slopes of an ANCF cable state at material coordinates ``x_m`` [m].

    Parameters
    ----------
    q : array_like, shape (n_el + 1, 6)
        Absolute nodal coordinates ``[x, y, z, x', y', z']`` [m, -] (slopes ∂r/∂X along the
        reference length X).
    node_x_m : array_like, shape (n_el + 1,)
        The nodes' material coordinates X [m], ascending.
    x_m : array_like, shape (m,)
        Where to evaluate [m], within ``[node_x_m[0], node_x_m[-1]]``.

    Returns
    -------
    numpy.ndarray, shape (m, 6)
        ``[r, ∂r/∂X]`` from the element's cubic Hermite shape functions (the ANCF cable's own
        interpolation, paper Sect. 2.2): exact, not an approximation, at any point of the curve.
    """
    q = np.asarray(q, dtype=float)
    X = np.asarray(node_x_m, dtype=float)
    x = np.asarray(x_m, dtype=float)
    e = np.clip(np.searchsorted(X, x, side="right") - 1, 0, len(X) - 2)
    h = (X[e + 1] - X[e])[:, None]
    t = ((x - X[e])[:, None]) / h
    t2, t3 = t * t, t * t * t
    r0, r1, d0, d1 = q[e, :3], q[e + 1, :3], q[e, 3:], q[e + 1, 3:]
    r = (2 * t3 - 3 * t2 + 1) * r0 + (t3 - 2 * t2 + t) * h * d0 + (-2 * t3 + 3 * t2) * r1 + (t3 - t2) * h * d1
    d = ((6 * t2 - 6 * t) / h * r0 + (3 * t2 - 4 * t + 1) * d0 + (-6 * t2 + 6 * t) / h * r1
         + (3 * t2 - 2 * t) * d1)
    return np.hstack([r, d])


def resolves_bend_ends(mesh) -> bool:
    """Whether a coarse mesh plan (:class:`exucable.scenario.mesh.MeshPlan`) is fine enough for the
    nested start: elements at most :data:`NESTED_MAX_BENDING_LENGTHS` bending lengths long."""
    return mesh is None or mesh.element_length_m <= NESTED_MAX_BENDING_LENGTHS * mesh.bending_length_m


def nested_start(fine, coarse) -> tuple[np.ndarray, np.ndarray] | None:
    """The start of ``fine``'s steady solve from ``coarse``'s solved state: the system's ODE2 and
    algebraic coordinates (:class:`exucable.solve.steady.SteadySolver`'s ``warm_start``).

    Both models are steady-mode models of the same scenario laid out alike (``fine`` built with
    ``coarse``'s references: the same rope path, lead-out and ends). The fine nodes take the coarse
    elements' cubic curve at their material coordinates (:func:`hermite_state`: the same curve
    exactly, each coarse element split in two), shifted along the cable so that the leading node
    lands where the fine mesh's rig holds it; the rig's multipliers are the coarse solve's (the same
    constraints, the same pulling force). None when the two cannot be matched (other extents) or
    the coarse elements are too long for the bends' boundary layers
    (:data:`NESTED_MAX_BENDING_LENGTHS`): the fine solve then starts from the rope.
    """
    if not resolves_bend_ends(coarse.mesh):
        return None
    lay_f, lay_c = fine.layout, coarse.layout
    X_f, X_c = lay_f.node_x_m, lay_c.node_x_m
    span = max(abs(X_c[-1] - X_c[0]), 1e-300)
    if abs(X_f[0] - X_c[0]) > 1e-9 * span or abs(X_f[-1] - X_c[-1]) > 1e-9 * span:
        return None
    q_c, _ = coarse.coordinates()
    # the rig holds each mesh's leading node where its own start put it, and the two rope starts
    # place it apart along the exit by the strain's integral on each mesh (sub-millimetre): the
    # fine cable takes the coarse curve shifted along itself by that much (the steady state's
    # material slides along a fixed curve), continued straight along the end slopes beyond its ends
    lead_f, lead_c = lay_f.position_m[-1], lay_c.position_m[-1]
    slope = q_c[-1, 3:]
    shift_m = float(np.dot(lead_f - lead_c, slope) / np.dot(slope, slope))
    x = X_f + shift_m
    q_f = hermite_state(q_c, X_c, np.clip(x, X_c[0], X_c[-1]))
    for beyond, end in ((x > X_c[-1], -1), (x < X_c[0], 0)):
        if beyond.any():
            q_f[beyond, :3] = q_c[end, :3] + (x[beyond] - X_c[end])[:, None] * q_c[end, 3:]
            q_f[beyond, 3:] = q_c[end, 3:]
    sd_f, sd_c = fine.mbs.systemData, coarse.mbs.systemData
    ode2 = np.array(sd_f.GetODE2Coordinates())
    ode2[fine.ode2_index] = (q_f - lay_f.coordinates).reshape(-1)
    ae_c = np.array(sd_c.GetAECoordinates())
    ae = np.array(sd_f.GetAECoordinates())
    if ae.size != ae_c.size:
        return None
    return ode2, ae_c.copy()


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
    from .bundle_starts import solve_bundle_starts
    from .steady import SteadySettings

    t0 = time.perf_counter()
    # steady sliding has no static friction and no stop: the start leaves them out
    steady = scenario.replace(**{"solver.mode": "steady", "contact.static_friction": None,
                                 "pull.stop_time": None, "pull.hold_time": None})
    settings = SteadySettings.from_solver(steady.solver)
    model = build_bundle_model(steady, refine=refine, start_path=settings.bundle_starts[0])
    if not solve:
        return BundleSteadyStart(model, None, float("nan"), "", time.perf_counter() - t0)
    # the steady mode's own sequence of starts (solve.bundle_starts), so that the dynamic run starts
    # from the state a steady run of the same scenario reports
    solved = solve_bundle_starts(steady, model, refine=refine, settings=settings)
    out = solved.outcome
    if out.status == "failed":
        # the model's start (model.layout, data) is untouched by the solve: the run starts from it
        return BundleSteadyStart(model, None, float("nan"), out.message, time.perf_counter() - t0)
    model = solved.model
    return BundleSteadyStart(model, solved_bundle_layouts(model), float(np.sum(model.pull_shares_N())), out.message,
                             time.perf_counter() - t0)
