"""The pull-in history of the multibody model: head tension against pulled length, steady state by state.

With the cable's head x metres into the conduit, the cable fills the route's first x metres, the reel's
back tension at its tail, the pulling line (taken as free of friction, as the rope's history takes it)
holding its head. At a steady pull speed that cable slides in the steady state of the route cut at x
(:meth:`exucable.scenario.specs.Scenario.pulled_in`), so the history is a sequence of steady solves
(:func:`exucable.solve.steady.solve_steady`, the public entry point, with ``exucable run``'s settings),
one per head position, the cable lengthened from a short lead to the whole route.

What changes from one head position to the next is only the cable's far end: the wall it meets before
its old head is the whole conduit's (the cut conduit keeps the whole conduit's segments), and its tail
carries the same back tension. So each solve starts from the last converged state, extended
(:func:`_extended_start`): the new cable's nodes take the last state's shape at the same place along the
route, up to a few bending lengths before the old head, and beyond that the rope start of the new length
(as a single steady solve starts), shifted along the cable to join it. A start that does not converge
is solved again from the rope start alone.

The mesh is the single run's (:func:`exucable.model.layout.initial_layout` of the whole route, the same
``refine``): the same element length at every head position, so the last point is the full run's
model and its pull force the full run's (``tests/test_pull_in.py``).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field

import numpy as np

__all__ = ["SteadyPullIn", "steady_pull_in", "pull_in_grid_m", "DEFAULT_POINTS"]

#: Head positions of a history (besides x = 0, where the head tension is the back tension).
DEFAULT_POINTS = 50

#: Bending lengths √(EJ/T) before the last cut up to which the last state starts the next solve
#: (the lead-out rule's LEAD_OUT_BENDING_LENGTHS: the head's boundary layer has decayed there).
HEAD_MARGIN_BENDING_LENGTHS = 10.0


@dataclass
class SteadyPullIn:
    """A multibody pull-in history (SI).

    Attributes
    ----------
    pulled_length_m : numpy.ndarray
        Head positions x [m] along the route in pull direction, from 0 (no cable in the conduit) to L.
    pull_force_N : numpy.ndarray
        Head tension [N] (the rig's reaction on the head; at x = 0 the back tension); nan where the
        solve failed.
    status : list of str
        ``"ok"`` or ``"failed"`` per point (``"exact"`` at x = 0).
    messages : list of str
    newton_iterations : numpy.ndarray
        Newton iterations of each point's solve (warm start and, where it failed, the rope start).
    warm_started : numpy.ndarray of bool
        The point converged from the last state (False: from the rope start).
    elements : numpy.ndarray of int
        Cable elements at each point.
    wall_time_s, cpu_time_s : float
        The whole history's wall and process CPU time [s].
    """

    pulled_length_m: np.ndarray
    pull_force_N: np.ndarray
    status: list = field(default_factory=list)
    messages: list = field(default_factory=list)
    newton_iterations: np.ndarray | None = None
    warm_started: np.ndarray | None = None
    elements: np.ndarray | None = None
    wall_time_s: float = 0.0
    cpu_time_s: float = 0.0

    @property
    def failed(self) -> int:
        """Points whose steady solve failed."""
        return sum(s == "failed" for s in self.status)


#: Head positions inside every bend or helix at least (besides its ends): the head tension grows there
#: by e^(μθ), which a straight line between its ends misses by up to μ²θ²/8 of it.
BEND_POINTS = 3


def pull_in_grid_m(length_m: float, points: int, boundaries_m=(), curved_m=()) -> np.ndarray:
    """Head positions [m]: 0, ``points`` uniform positions up to ``length_m`` (the first at
    ``length_m / points``), the route's piece boundaries ``boundaries_m`` (bend ends, where the
    history's slope changes) and :data:`BEND_POINTS` evenly inside each curved range ``curved_m``
    ((start, end) pairs), sorted, one each."""
    if int(points) < 1:
        raise ValueError(f"points must be >= 1, got {points!r}")
    L = float(length_m)
    inside = [np.linspace(a, b, BEND_POINTS + 2)[1:-1] for a, b in curved_m]
    x = np.concatenate([[0.0], np.linspace(L / points, L, int(points)), np.asarray(boundaries_m, float)] + inside)
    x = np.unique(np.clip(x, 0.0, L))
    # a boundary within a hundredth of a step of a uniform position adds nothing but a solve
    keep = np.concatenate([[True], np.diff(x) > 0.01 * L / points])
    return x[keep]


def _full_mesh(scenario, refine: float):
    """Element length [m] and check points per element of the single steady run's mesh."""
    from ..model.layout import initial_layout
    from ..scenario.mesh import STEADY_REFINE

    on_rule = "elements" in scenario.cable.derived_keys and scenario.cable.element_length_m is None
    coarse = initial_layout(scenario, refine=refine).mesh
    points = coarse.check_points_per_element
    if on_rule:
        # exucable run's steady solve: the rule's mesh refined STEADY_REFINE times, its check points
        # per element kept (the spacing refined alike)
        fine = initial_layout(scenario, refine=refine * STEADY_REFINE, check_points_per_element=points).mesh
        return scenario.cable_length_m / fine.elements, fine.check_points_per_element
    return scenario.cable_length_m / coarse.elements, points


def _extended_start(start, last_model, last_length_m: float, speed_m_per_s: float):
    """The start of the next head position: ``start`` (the rope start of the longer cable) with its
    nodes up to shortly before the last cable's head replaced by the last converged state there.

    Nodes are matched by place: each tail sits at its own lead-out into the conduit
    (:func:`exucable.model.layout.steady_lead_out_m`, 0 unless the route is cut in or just after a
    bend), so the new node at material distance X from its tail is the last state's node at
    X + (lead-out now - lead-out then) (the strain's part of that shift, T/EA times a metre, is
    negligible). The last state is used only up to :data:`HEAD_MARGIN_BENDING_LENGTHS` bending
    lengths (plus two elements) before its cut: nearer its head it bends out of the route toward
    the rig (its lead-out runs straight on), which the longer cable does not. Between matched nodes
    the shape is the last state's cubic (Hermite) interpolation; beyond them the rope start is kept,
    shifted along the cable by the displacement at the nearest matched node so that its material stays
    continuous (its lateral place stays the rope start's).
    """
    from ..model.layout import sliding_layout

    q_last, _ = last_model.coordinates()
    lay = start.cable
    X_new = lay.node_x_m
    old = last_model.layout
    Le_last, X_last = old.element_length_m, old.node_x_m
    props = last_model.properties
    head_N = max(float(np.max(np.abs(last_model.rope.tension_N))), 1e-9)
    margin = (HEAD_MARGIN_BENDING_LENGTHS * math.sqrt(props.bending_stiffness_N_m2 / head_N)
              + 2.0 * float(np.max(Le_last)))
    s_keep = last_length_m - margin
    if s_keep <= old.node_s_m[0]:
        return None
    X_keep = float(np.interp(s_keep, old.node_s_m, X_last))
    X_match = X_new + (start.lead_out_m - last_model.start.lead_out_m)
    inside = (X_match >= 0.0) & (X_match <= X_keep)
    if np.count_nonzero(inside) < 2:
        return None
    pos, slope = lay.position_m.copy(), lay.slope.copy()
    Xm = X_match[inside]
    e = np.clip(np.searchsorted(X_last, Xm, side="right") - 1, 0, len(Le_last) - 1)
    h = Le_last[e][:, None]
    x = ((Xm - X_last[e]) / Le_last[e])[:, None]
    x2, x3 = x * x, x * x * x
    r0, r1 = q_last[e, :3], q_last[e + 1, :3]
    d0, d1 = q_last[e, 3:], q_last[e + 1, 3:]
    pos[inside] = ((2 * x3 - 3 * x2 + 1) * r0 + (x3 - 2 * x2 + x) * h * d0
                   + (-2 * x3 + 3 * x2) * r1 + (x3 - x2) * h * d1)
    slope[inside] = ((6 * x2 - 6 * x) / h * r0 + (3 * x2 - 4 * x + 1) * d0
                     + (-6 * x2 + 6 * x) / h * r1 + (3 * x2 - 2 * x) * d1)
    idx = np.flatnonzero(inside)
    first, last = int(idx[0]), int(idx[-1])
    before, after = np.arange(len(X_new)) < first, np.arange(len(X_new)) > last
    # along the cable only: the rope start's lateral place is where the cable rests (the rig holds the
    # head where the start puts it, and a head held off its resting place presses on the wall)
    tangent = lay.slope / np.linalg.norm(lay.slope, axis=1, keepdims=True)
    for part, k in ((before, first), (after, last)):
        along = float(np.dot(pos[k] - lay.position_m[k], tangent[k]))
        pos[part] += along * tangent[part]
    cable = sliding_layout(lay.element_length_m, lay.node_x_m, lay.node_s_m, pos, slope, speed_m_per_s)
    return dataclasses.replace(start, cable=cable)


def steady_pull_in(scenario, points: int = DEFAULT_POINTS, *, x_m=None, refine: float = 1.0,
                   warm_start: bool = True, settings=None, progress=None) -> SteadyPullIn:
    """The multibody pull-in history of ``scenario`` in its ``pull.direction``.

    Parameters
    ----------
    scenario : exucable.scenario.specs.Scenario
        Solved in steady mode (``solver.mode`` is set to ``"steady"``); velocity-controlled
        (``pull.back_tension``), without ``cable.length``.
    points : int
        Uniform head positions (:func:`pull_in_grid_m`; the route's piece boundaries and
        :data:`BEND_POINTS` inside each bend are added).
    x_m : array_like, optional
        The head positions [m] instead (ascending, in (0, L]; 0 is added).
    refine : float
        Divides the mesh rule's element length (as ``exucable run`` and ``converge``).
    warm_start : bool
        Start each solve from the last converged state, extended (:func:`_extended_start`); False:
        from the rope start, as a single steady run does.
    settings : exucable.solve.steady.SteadySettings, optional
        The steady solves' settings (default: the scenario's, :meth:`SteadySettings.from_solver`, as
        ``exucable run``).
    progress : callable, optional
        Called ``progress(i, n, x_m, pull_force_N)`` after each point.

    Returns
    -------
    SteadyPullIn

    Raises
    ------
    exucable.errors.ScenarioError
        A prescribed ``pull.force`` or a given ``cable.length``.
    """
    from ..errors import ExucableError, ScenarioError
    from ..model.build import build_model
    from ..model.layout import initial_layout
    from .steady import SteadySettings, solve_steady, steady_forces

    if scenario.pull.force_N is not None:
        raise ScenarioError("pull.force", "a pull-in history starts from the reel's back tension; give "
                                          "pull.back_tension instead of a prescribed pull.force")
    sc = scenario if scenario.solver.mode == "steady" else scenario.replace(**{"solver.mode": "steady"})
    conduit = sc.build_conduit()
    curve = conduit.centreline if sc.pull.direction == "forward" else conduit.centreline.reversed()
    L = curve.length_m
    if x_m is None:
        grid = pull_in_grid_m(L, points, [p.s_end_m for p in curve.pieces[:-1]], curve.curved_ranges_m())
    else:
        grid = np.unique(np.concatenate([[0.0], np.asarray(x_m, dtype=float)]))
        if grid[0] < 0.0 or grid[-1] > L * (1.0 + 1e-9):
            raise ScenarioError("pull_in", f"head positions must lie in [0, {L:.6g}] m")
    element_m, check_points = _full_mesh(sc, refine)
    settings = SteadySettings.from_solver(sc.solver) if settings is None else settings
    t_wall, t_cpu = time.perf_counter(), time.process_time()
    n = grid.size
    force = np.full(n, np.nan)
    force[0] = sc.pull.back_tension_N
    status, messages = ["exact"], ["no cable in the conduit: the head tension is the back tension"]
    newton = np.zeros(n, dtype=int)
    warm = np.zeros(n, dtype=bool)
    elements = np.zeros(n, dtype=int)
    last, last_x = None, 0.0
    for i in range(1, n):
        x = float(grid[i])
        n_el = max(2, int(math.ceil(x / element_m * (1.0 - 1e-9))))
        sc_x = sc.pulled_in(x, n_el)
        elements[i] = n_el
        try:
            start = initial_layout(sc_x, check_points_per_element=check_points)
        except ExucableError as exc:
            # a cable this short cannot be laid as a steady solve needs (its lead-out past the cut longer
            # than itself): the point has no multibody state; the history goes on from the last one
            status.append("failed")
            messages.append(f"head at {x:.4g} m: {exc}")
            continue
        tries = []
        if warm_start and last is not None:
            extended = _extended_start(start, last, last_x, sc.pull.speed_m_per_s)
            if extended is not None:
                tries.append((extended, True))
        tries.append((start, False))
        outcome, model = None, None
        for lay, is_warm in tries:
            model = build_model(sc_x, check_points_per_element=check_points, start=lay)
            outcome = solve_steady(model, settings=settings)
            newton[i] += outcome.newton_iterations
            if outcome.status != "failed":
                warm[i] = is_warm
                break
        status.append(outcome.status)
        messages.append(outcome.message)
        if outcome.status != "failed":
            force[i] = steady_forces(model)[0]
            last, last_x = model, x
        if progress is not None:
            progress(i, n - 1, x, force[i])
    return SteadyPullIn(pulled_length_m=grid, pull_force_N=force, status=status, messages=messages,
                        newton_iterations=newton, warm_started=warm, elements=elements,
                        wall_time_s=time.perf_counter() - t_wall, cpu_time_s=time.process_time() - t_cpu)
