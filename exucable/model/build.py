"""A cable pulled through a conduit, added to an Exudyn system: the plugin face of exucable.

Reads like the physical system: lay the cable in the conduit (:func:`initial_layout`, no
Exudyn), hang the loads on it, hook its leading end to the rig (or to the user's own drum or
vehicle), let the conduit's wall act on it. :func:`add_cable_in_conduit` does that in the user's
own ``mbs`` without assembling it; :func:`build_model` is the thin wrapper that makes its own
SystemContainer for ``exucable run``.
"""

from __future__ import annotations

import dataclasses

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import exudyn as exu
from exudyn.itemInterface import MarkerNodePosition, ObjectJointSpherical

from ..errors import ModelError, ScenarioError
from ..scenario.mesh import MeshPlan
from ..quasistatic.extent import reference_drift_N_per_s
from ..post.tension import CableLoads, check_point_forces_N, equilibrium_tension, tension_at
from .cable import CableHandles, CableProperties, add_cable, add_gravity
from .layout import CableLayout, InitialLayout, initial_layout
from .recorder import Recorder, earliest_steady_s
from .rig import (
    Drive,
    drive_force_vector_N,
    Guide,
    add_drive,
    add_end_force,
    add_guide,
    add_reel,
    add_tangential_drive,
    smooth_ramp,
)

if TYPE_CHECKING:  # names for the annotations only
    from ..contact import ContactKernel
    from ..geometry import Conduit
    from ..quasistatic.rope import RopeSolution
    from ..scenario.specs import Scenario
    from .coupling import ContactCoupling
    from .rig import TangentialDrive
    from .startup import StartupDamper

__all__ = ["CableInConduit", "Model", "JoinToMarker", "ReelOnto", "LoadScale", "add_cable_in_conduit", "build_model",
           "pull_oriented_conduit"]


@dataclass(frozen=True)
class JoinToMarker:
    """Join a cable end to a position marker of the user's own body (a vehicle, a winch carriage)
    with a spherical joint; place the body's marker at the end's start position
    (``InitialLayout.leading_position_m``)."""

    marker: int


@dataclass(frozen=True)
class ReelOnto:
    """Reel the leading end in along the exit tangent by ``radius_m`` × the user's coordinate
    marked by ``coordinate_marker`` (a drum's rotation angle [rad]); the drum then carries the
    cable's pull as a torque R·F."""

    coordinate_marker: int
    radius_m: float


_LEADING = ("rig", "force", "free")
_TRAILING = ("back_tension", "brake", "free")


@dataclass(eq=False, repr=False)
class CableInConduit:
    """Handles of a cable in a conduit inside an Exudyn system (see :func:`add_cable_in_conduit`).

    Attributes
    ----------
    scenario : exucable.scenario.specs.Scenario
    mbs : exudyn.MainSystem
    conduit : exucable.geometry.Conduit
        Pull-oriented: the leading end is at the end of its centreline.
    cable : CableHandles
        Node and element indices; ``cable.nodes[0]`` is the trailing end.
    layout : CableLayout
        The start state (reference coordinates of the nodes).
    start : InitialLayout
    properties : CableProperties
    leading_marker, trailing_marker : int
        ``MarkerNodePosition`` of the two end nodes (to join, load or sense them).
    lead_drive, trail_drive : Drive or None
        The rig (or reel) at the leading end and the brake of a force-controlled pull.
    applied_pull_force_N : float or None
        The prescribed pulling force of a force-controlled pull [N].
    back_tension_N : float
        Tension applied at the trailing end [N].
    rope : exucable.quasistatic.rope.RopeSolution
        The quasi-static reference the start is pre-tensioned to.
    coupling, kernel
        The contact coupling (an ObjectGenericODE2 over the cable nodes) and its kernel.
    startup_damper : StartupDamper or None
    exit_span_damper : ExitSpanDamper or None
        The damper on the span past the exit (``solver.exit_span_damping``).
    guide : Guide or None
        The force-controlled pull's sheave.
    recorder : Recorder
        Call ``recorder(mbs, t)`` from your post-step function; ``recorder.history`` holds the
        pulling force, trailing and maximum tension at ``solver.output_interval``.
    """

    scenario: Scenario
    mbs: exu.MainSystem
    conduit: Conduit
    cable: CableHandles
    layout: CableLayout
    start: InitialLayout
    properties: CableProperties
    leading_marker: int
    trailing_marker: int
    lead_drive: Drive | None = None
    trail_drive: Drive | TangentialDrive | None = None
    applied_pull_force_N: float | None = None
    back_tension_N: float = 0.0
    rope: RopeSolution | None = None
    mesh: MeshPlan | None = None
    load_scale: LoadScale | None = None
    coupling: ContactCoupling | None = None
    kernel: ContactKernel | None = None
    startup_damper: StartupDamper | None = None
    exit_span_damper: object = None   # ExitSpanDamper (solver.exit_span_damping) or None
    guide: Guide | None = None
    recorder: Recorder | None = None
    # how fast the flexible reference's pulling force moves as the cable leaves its conduit [N/s]
    reference_drift_N_per_s: float = 0.0
    # what holds each end ("rig", "force", "reel", "joined"; "back_tension", "brake", "joined"),
    # the Exudyn loads on each end's node and the cable's weight loads (for the tension's equilibrium)
    leading_end: str = "rig"
    trailing_end: str = "back_tension"
    end_loads: dict = field(default_factory=lambda: {"leading": [], "trailing": []})
    gravity_loads: tuple = ()
    # the cable's elastic forces and weight when exucable assembles them (steady mode,
    # solver.cable_element = "compiled"; exucable.contact.ancf_cable.AncfCableForces), else None
    cable_forces: object = None
    _ode2_index: np.ndarray | None = field(default=None)
    # a steady state's loads and the system state they were computed at (see :meth:`loads`)
    _loads_memo: tuple | None = field(default=None)
    # a steady state's check-point forces and the coordinates and contact law they were computed at
    _points_memo: tuple | None = field(default=None)

    def __repr__(self) -> str:
        return (f"{type(self).__name__}({self.scenario.name!r}: {self.cable.n_elements} cable elements, "
                f"{'with' if self.coupling is not None else 'without'} contact)")

    @property
    def nodes(self) -> tuple[int, ...]:
        """Cable node indices, trailing end first."""
        return self.cable.nodes

    @property
    def axial_stiffness_N(self) -> float:
        return self.properties.axial_stiffness_N

    @property
    def ode2_index(self) -> np.ndarray:
        """Indices of the cable's coordinates in the system's ODE2 vector (after ``Assemble``)."""
        if self._ode2_index is None:
            # one call into Exudyn per node (each costs microseconds; 10 km has 26 000 nodes)
            first = np.array([self.mbs.GetNodeODE2Index(n) for n in self.cable.nodes], dtype=np.int64)
            self._ode2_index = (first[:, None] + np.arange(6, dtype=np.int64)[None, :]).reshape(-1)
        return self._ode2_index

    def recommended_settings(self) -> exu.SimulationSettings:
        """Exudyn simulation settings from the scenario's ``[solver]`` table, to start from:
        generalized-α with adaptive steps, full Newton on the exact contact Jacobian, the end time
        and step of ``solver`` (see scenarios/README.md for why each)."""
        from .settings import solver_settings
        return solver_settings(self.scenario.solver)

    def load_factor(self, t: float) -> float:
        """Ramp factor of loads and speed at time t [-]."""
        return smooth_ramp(t, self.scenario.pull.ramp_time_s)

    def coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """Current absolute nodal coordinates and their rates, each shape (n_el + 1, 6)."""
        sd = self.mbs.systemData
        q = np.asarray(sd.GetODE2Coordinates())[self.ode2_index]
        v = np.asarray(sd.GetODE2Coordinates_t())[self.ode2_index]
        return (self.layout.coordinates + q.reshape(-1, 6), v.reshape(-1, 6))

    def leading_tension_N(self) -> float:
        """Axial force N = EA·ε at the leading end now [N] (paper Eq. 24)."""
        q, _ = self.coordinates()
        Le = self.layout.element_length_m
        return float(tension_at(q, Le, self.axial_stiffness_N, [float(np.sum(Le))])[0])

    def pull_force_N(self, t: float) -> float:
        """Force of the rig on the leading end along the pull [N]: the drive's (or reel's)
        reaction, the prescribed force, or else the cable's tension at its leading end."""
        if self.lead_drive is not None:
            return self.lead_drive.force_N(self.mbs)
        if self.applied_pull_force_N is not None:
            return self.applied_pull_force_N * self.load_factor(t)
        return self.leading_tension_N()

    def loads(self, state: tuple | None = None) -> CableLoads:
        """Every external force on the cable (see :func:`exucable.post.tension.equilibrium_tension`):
        the contact forces at the check points, the weight, the inertia of a dynamic state, the
        dampers' and the guide's nodal forces, and each end's force (the rig's or brake's
        reaction, back tension or applied pull; None for an end joined to the user's own model).

        ``state``: ``(t, q, v, a, reactions)`` — time [s], absolute coordinates, rates and
        accelerations, each (n_el + 1, 6), and the drives' reactions (:meth:`drive_reactions_N`,
        interpolated by the caller) — instead of the system's current state (a snapshot between
        two steps). The contact forces are the kernel's at that state; at the current state of a
        dynamic run they are those the solver applied, with the damping onset held at the step's
        start value (:class:`exucable.contact.law.ContactLaw`), so that the loads balance.
        """
        mbs = self.mbs
        sd = mbs.systemData
        static = self.scenario.solver.mode == "steady"
        key = None
        if state is None and static:
            # a steady state's loads are asked for several times (its tension profile, the balance
            # check, the pressure table): computed once per state (coordinates, the rig's reaction in
            # the algebraic ones, the loads' scale); the check points' forces are most of a post-processing
            key = (float(sd.GetTime()), np.asarray(sd.GetODE2Coordinates()).tobytes(),
                   np.asarray(sd.GetODE2Coordinates_t()).tobytes(), np.asarray(sd.GetAECoordinates()).tobytes(),
                   self.load_scale.gravity if self.load_scale is not None else None,
                   self.load_scale.end_force if self.load_scale is not None else None)
            if self._loads_memo is not None and self._loads_memo[0] == key:
                return self._loads_memo[1]
        loads = self._loads(state, static)
        if key is not None:
            self._loads_memo = (key, loads)
        return loads

    def _loads(self, state, static: bool) -> CableLoads:
        """The loads of :meth:`loads`, computed."""
        mbs = self.mbs
        sd = mbs.systemData
        if state is None:
            q, v = self.coordinates()
            t = float(sd.GetTime())
            acc = None if static else np.asarray(sd.GetODE2Coordinates_tt())[self.ode2_index].reshape(-1, 6)
        else:
            t, q, v, acc, reactions = state
            q, v = np.asarray(q, dtype=float).reshape(-1, 6), np.asarray(v, dtype=float).reshape(-1, 6)
            acc = None if static or acc is None else np.asarray(acc, dtype=float).reshape(-1, 6)
        Le = np.asarray(self.layout.element_length_m, dtype=float)
        x_nodes = np.concatenate([[0.0], np.cumsum(Le)])
        if self.kernel is not None:
            # the steady kernel's forces depend on q and its law alone (v = V r'): kept per state, so
            # the snapshot's loads (rates V r') and the current state's (rates nan) are one pass
            key = (q.tobytes(), getattr(self.kernel, "law", None)) if static else None
            if key is not None and self._points_memo is not None and self._points_memo[0] == key:
                point_x, point_f = self._points_memo[1]
            else:
                # a steady state's rates may be nan (unknown): its kernel takes them from q anyway
                pts = self.kernel.points(q.reshape(-1), np.nan_to_num(v).reshape(-1))
                point_x = x_nodes[pts.element] + pts.xi * Le[pts.element]
                f_n, f_t = pts.normal_force_N, pts.friction_force_N
                solved = getattr(self.coupling, "solved_onset", None)
                if state is None and not static and solved is not None:
                    f_n, f_t = _with_held_onset(self.kernel, pts, solved)
                point_f = check_point_forces_N(pts.normal, f_n, f_t, pts.velocity_m_per_s)
                if key is not None:
                    self._points_memo = (key, (point_x, point_f))
        else:
            point_x, point_f = np.zeros(0), np.zeros((0, 3))
        g = np.asarray(mbs.GetLoadValues(self.gravity_loads[0]), dtype=float) if self.gravity_loads else np.zeros(3)
        if self.cable_forces is not None:
            g = self.cable_forces.gravity_m_per_s2 * self.cable_forces.gravity_scale
        if state is not None and self.gravity_loads and self.scenario.pull.ramp_time_s > 0.0 and not static:
            g = np.asarray(self.load_scale.vector(self.gravity_loads[0]), dtype=float) * self.load_factor(t)
        q_rel = (q - self.layout.coordinates).reshape(-1)
        nodal = np.zeros((len(q), 6))
        if self.startup_damper is not None:
            nodal += np.asarray(self.startup_damper.force(t, v.reshape(-1)), dtype=float).reshape(-1, 6)
        if self.exit_span_damper is not None:
            nodal += np.asarray(self.exit_span_damper.force(t, q_rel, v.reshape(-1)), dtype=float).reshape(-1, 6)
        if self.guide is not None:
            P = self._guide_projection()
            k = self.guide.node_index
            nodal[k, :3] += -self.guide.k * P @ q_rel.reshape(-1, 6)[k, :3] - self.guide.c * P @ v[k, :3]

        def end_force(end: str, kind: str, drive):
            if kind == "joined":
                return None
            if drive is not None and state is not None:
                return reactions[end]
            f = np.zeros(3)
            for i in self.end_loads[end]:
                if state is None:
                    f += np.asarray(mbs.GetLoadValues(i), dtype=float)
                else:   # the load at the snapshot's time: its vector times the ramp
                    f += np.asarray(self.load_scale.vector(i), dtype=float) * (
                        self.load_factor(t) if self.scenario.pull.ramp_time_s > 0.0 and not static else 1.0)
            if drive is not None:
                f += drive_force_vector_N(mbs, drive, static)
            return f

        return CableLoads(point_x_m=point_x, point_force_N=point_f, node_force_N=nodal[:, :3],
                          line_load_N_per_m=self.properties.mass_per_length_kg_per_m * g,
                          mass_per_length_kg_per_m=self.properties.mass_per_length_kg_per_m, acceleration=acc,
                          trailing_force_N=end_force("trailing", self.trailing_end, self.trail_drive),
                          leading_force_N=end_force("leading", self.leading_end, self.lead_drive))

    def drive_reactions_N(self) -> dict:
        """The force [N] of each end's drive (the rig or reel, the brake) on the cable now, as a
        vector: ``{"leading": ..., "trailing": ...}``, None at an end without a drive."""
        static = self.scenario.solver.mode == "steady"
        return {end: None if d is None else drive_force_vector_N(self.mbs, d, static)
                for end, d in (("leading", self.lead_drive), ("trailing", self.trail_drive))}

    def _guide_projection(self) -> np.ndarray:
        """I − d dᵀ of the guide's direction d (the exit tangent)."""
        d = np.asarray(self.start.exit_tangent, dtype=float)
        d = d / np.linalg.norm(d)
        return np.eye(3) - np.outer(d, d)

    def tension_N(self, x_m) -> np.ndarray:
        """The cable's tension [N] at material stations ``x_m`` [m] from the trailing end, now: from
        the equilibrium of its loads (:func:`exucable.post.tension.equilibrium_tension`, the
        paper's Eq. 24 without the element's strain error), or EA·ε where neither end's force is
        known (both ends joined to the user's own model)."""
        q, _ = self.coordinates()
        Le = self.layout.element_length_m
        loads = self.loads()
        if loads.trailing_force_N is None and loads.leading_force_N is None:
            return tension_at(q, Le, self.axial_stiffness_N, x_m)
        return equilibrium_tension(q, Le, loads, x_m)

    def trailing_reaction_N(self) -> float | None:
        """Brake force at the trailing end of a force-controlled pull [N] (None otherwise)."""
        if self.trail_drive is None:
            return None
        return -self.trail_drive.force_N(self.mbs)


def _with_held_onset(kernel, pts, onset) -> tuple[np.ndarray, np.ndarray]:
    """The check points' weighted normal and friction forces [N] with the damping onset g held at
    ``onset`` (per point) instead of g(δ) of the state: f = w·max(0, Kδ^e + C·g·δ̇), the friction
    scaled with f (it is μ·f times a function of the slip). A point that the held onset brings into
    force from none gets no friction (its slip direction was not evaluated; a point leaving the
    wall that fast carries a vanishing force)."""
    law = kernel.law
    delta = np.nan_to_num(np.asarray(pts.penetration_m, dtype=float), nan=-1.0)
    n = np.nan_to_num(np.asarray(pts.normal, dtype=float))
    rate = np.sum(n * np.asarray(pts.velocity_m_per_s, dtype=float), axis=1)
    w = (kernel.element_length_m[:, None] * kernel.omega[None, :]).reshape(-1) / kernel.reference_spacing_m
    touch = delta > 0.0
    raw = np.where(touch, law.stiffness * np.maximum(delta, 0.0) ** law.exponent
                   + law.damping * np.asarray(onset, dtype=float).reshape(-1) * rate, 0.0)
    f_held = w * np.maximum(raw, 0.0)
    f_now = np.asarray(pts.normal_force_N, dtype=float)
    scale = np.divide(f_held, f_now, out=np.zeros_like(f_held), where=f_now > 0.0)
    return f_held, np.asarray(pts.friction_force_N, dtype=float) * scale


class LoadScale:
    """Scale factors [-] of the loads of a steady (static) solve, the continuation parameters of
    :func:`exucable.solve.steady.solve_steady`: gravity and the end forces (back tension or the
    applied pull). All 1 = the scenario's loads. The loads carry no user function (Exudyn would
    call it once per element and residual); :meth:`apply` rewrites their load vectors instead."""

    def __init__(self):
        self.gravity = 1.0
        self.end_force = 1.0
        self._gravity_loads: list[tuple[int, list]] = []
        self._end_loads: list[tuple[int, list]] = []
        self.cable_forces = None     # AncfCableForces whose weight scales with gravity, if any

    def track(self, gravity_loads=(), end_loads=(), vectors=None) -> None:
        """Remember loads (indices) and their full-scale vectors [N or m/s²]."""
        for i in gravity_loads:
            self._gravity_loads.append((i, vectors[i]))
        for i in end_loads:
            self._end_loads.append((i, vectors[i]))

    def vector(self, load: int) -> list:
        """The unscaled vector of a tracked load (Exudyn load index ``load``)."""
        return dict(self._gravity_loads + self._end_loads)[load]

    def apply(self, mbs, gravity: float, end_force: float) -> None:
        """Set the factors and rewrite the loads' vectors."""
        self.gravity, self.end_force = float(gravity), float(end_force)
        if self.cable_forces is not None:
            self.cable_forces.gravity_scale = self.gravity
        for loads, f in ((self._gravity_loads, self.gravity), (self._end_loads, self.end_force)):
            for i, vec in loads:
                mbs.SetLoadParameter(i, "loadVector", [f * x for x in vec])


@dataclass(eq=False, repr=False)
class Model(CableInConduit):
    """A cable in a conduit in its own assembled SystemContainer (:func:`build_model`)."""

    system_container: exu.SystemContainer | None = None


def pull_oriented_conduit(scenario):
    """The scenario's conduit, reversed when the pull direction is ``reverse``, so that the
    leading end is always at the end of the returned conduit's centreline."""
    conduit = scenario.build_conduit()
    return conduit.reversed() if scenario.pull.direction == "reverse" else conduit


def _scenario_from(scenario, parts: dict):
    from ..scenario.specs import Scenario, SolverSpec
    if scenario is not None:
        if parts:
            raise TypeError(f"give a scenario or its parts, not both (got {sorted(parts)})")
        return scenario
    parts = dict(parts)
    # The user's own settings decide the run; the solver spec only sets the start-up damper,
    # the recorder's interval and recommended_settings().
    parts.setdefault("solver", SolverSpec(end_time_s=1.0))
    return Scenario(**parts)


def add_cable_in_conduit(mbs, scenario=None, *, leading: str | JoinToMarker | ReelOnto | None = None,
                         trailing: str | JoinToMarker | None = None, with_contact: bool = True,
                         start: InitialLayout | None = None, cable_element: str = "exudyn",
                         **parts) -> CableInConduit:
    """Add a cable pulled through a conduit to the user's own Exudyn system, without assembling it.

    Adds the ANCF cable (paper Sect. 2.2) pre-tensioned in the conduit (:func:`initial_layout`),
    its weight, the end loads, the contact coupling with the conduit wall (Sects. 2.4-2.5) and the
    start-up damper. Nothing of the user's is changed: no post-step function is set (call the
    returned ``recorder`` from yours) and ``mbs.Assemble()`` is left to the caller.

    Parameters
    ----------
    mbs : exudyn.MainSystem
    scenario : exucable.scenario.specs.Scenario, optional
        Or its parts as keywords: ``route=``, ``cable=``, ``contact=``, ``pull=``, ``gravity=``,
        ``solver=`` (as for :class:`exucable.Scenario`; ``solver`` defaults to ``Solver(end_time=1)``).
    leading : {"rig", "force", "free"}, JoinToMarker or ReelOnto, optional
        The leading end: the built-in velocity rig at ``pull.speed`` (default), the prescribed
        ``pull.force`` with its sheave (default when ``pull.force`` is given), free, joined to a
        user's marker, or reeled onto a user's drum coordinate.
    trailing : {"back_tension", "brake", "free"} or JoinToMarker, optional
        The trailing end: ``pull.back_tension`` along the entry tangent (default), the pay-out
        brake at ``pull.speed`` (default for a force-controlled pull), free, or joined to a marker.
    with_contact : bool
        False: no conduit wall (a free cable, for tests).
    start : InitialLayout, optional
        A start state computed before (default: ``initial_layout(scenario, with_contact)``).
    cable_element : {"exudyn", "compiled"}
        Exudyn's ``ObjectANCFCable`` objects (default: the user's system gets Exudyn's elements), or,
        for a steady-mode scenario with contact, exucable's compiled copy in the contact's user
        function (what :func:`build_model` does with ``solver.cable_element``).

    Returns
    -------
    CableInConduit
        Handles: nodes, end markers, drives, coupling and kernel, recorder, recommended_settings().

    Raises
    ------
    ModelError
        Mesh too coarse for the tightest bend, or a cable longer than its conduit.
    """
    sc = _scenario_from(scenario, parts)
    force_pull = sc.pull.force_N is not None
    leading = ("force" if force_pull else "rig") if leading is None else leading
    trailing = ("brake" if force_pull else "back_tension") if trailing is None else trailing
    if isinstance(leading, str) and leading not in _LEADING:
        raise ValueError(f"leading must be one of {_LEADING}, JoinToMarker(...) or ReelOnto(...), got {leading!r}")
    if isinstance(trailing, str) and trailing not in _TRAILING:
        raise ValueError(f"trailing must be one of {_TRAILING} or JoinToMarker(...), got {trailing!r}")
    if leading == "force" and not force_pull:
        raise ScenarioError("pull.force", 'required with leading="force": the pulling force to apply (N)')

    start = initial_layout(sc, with_contact) if start is None else start
    conduit = start.conduit
    centre = conduit.centreline
    L_cable = sc.cable_length_m
    if L_cable > centre.length_m * (1 + 1e-12):
        raise ModelError("cable.length", f"cable of {L_cable:.6g} m is longer than the conduit "
                         f"({centre.length_m:.6g} m); shorten it or extend the route")
    c = sc.cable
    layout = start.cable
    if sc.pull.stop_time_s == 0.0 and sc.solver.mode != "steady":
        # a pull standing still from the start: the cable starts at rest, not sliding
        layout = dataclasses.replace(layout, velocity_m_per_s=np.zeros_like(layout.velocity_m_per_s),
                                     slope_rate_1_per_s=np.zeros_like(layout.slope_rate_1_per_s))
    # Steady mode drops the cable's Kelvin–Voigt damping: it acts on the nodal rates, which a static
    # solve never updates (they would stay the start's), and it exists to damp vibrations; in steady
    # flow its axial force would be τ·V·∂N/∂x (τ·V = 1e-4 m at 1 ms, 0.1 m/s), negligible.
    internal_damping = sc.solver.mode != "steady"
    props = CableProperties(
        mass_per_length_kg_per_m=c.mass_per_length_kg_per_m,
        axial_stiffness_N=c.axial_stiffness_N,
        bending_stiffness_N_m2=c.bending_stiffness_N_m2,
        axial_damping_N_s=c.axial_damping_N_s if internal_damping else 0.0,
        bending_damping_N_m2_s=c.bending_damping_N_m2_s if internal_damping else 0.0,
        integration=c.integration,
    )
    # steady mode may assemble the cable's elastic forces itself, in the contact's user function
    compiled = sc.solver.mode == "steady" and cable_element == "compiled" and with_contact
    cable = add_cable(mbs, layout.coordinates, layout.element_length_m, props, layout.velocities,
                      draw_radius_m=c.radius_m, with_elements=not compiled)
    lead_node, trail_node = cable.nodes[-1], cable.nodes[0]
    h = CableInConduit(
        scenario=sc, mbs=mbs, conduit=conduit, cable=cable, layout=layout, start=start, properties=props,
        leading_marker=mbs.AddMarker(MarkerNodePosition(nodeNumber=lead_node)),
        trailing_marker=mbs.AddMarker(MarkerNodePosition(nodeNumber=trail_node)),
        back_tension_N=sc.pull.back_tension_N, rope=start.rope, mesh=start.mesh, load_scale=LoadScale())

    # steady mode: a static solve of the steady sliding state; the rig holds the leading end
    # (or, for a force-controlled pull, the trailing end) where the start put it, and the loads'
    # scale is the continuation parameter of exucable.solve.steady, not time
    steady = sc.solver.mode == "steady"
    if steady and not sc.solver.pretension:
        raise ModelError("solver.pretension", 'solver.mode = "steady" starts from the rope solution near the '
                         "steady state; set it to true (or use the dynamic mode)")
    ramp_time = sc.pull.ramp_time_s
    factor = None if (steady or ramp_time <= 0) else (lambda t: smooth_ramp(t, ramp_time))
    g = sc.gravity.g_m_per_s2 if sc.gravity is not None else 0.0
    if g > 0 and not compiled:
        gravity_vector = [0.0, 0.0, -g]
        loads = add_gravity(mbs, cable, gravity_vector, factor)
        h.load_scale.track(gravity_loads=loads, vectors={i: gravity_vector for i in loads})
        h.gravity_loads = tuple(loads)
    speed = sc.pull.speed_m_per_s
    rig_speed = 0.0 if steady else speed
    t_exit, t_entry = start.exit_tangent, start.entry_tangent

    def end_force(node, vec):
        vec = list(vec)
        i = add_end_force(mbs, node, vec, factor)
        h.load_scale.track(end_loads=[i], vectors={i: vec})
        h.end_loads["leading" if node == lead_node else "trailing"].append(i)

    h.leading_end = leading if isinstance(leading, str) else "reel" if isinstance(leading, ReelOnto) else "joined"
    h.trailing_end = trailing if isinstance(trailing, str) else "joined"

    if leading == "rig":
        h.lead_drive = add_drive(mbs, lead_node, t_exit, rig_speed, ramp_time, sc.pull.stop_time_s, sc.pull.hold_time_s)
    elif leading == "force":
        h.applied_pull_force_N = sc.pull.force_N
        end_force(lead_node, sc.pull.force_N * t_exit)
    elif isinstance(leading, JoinToMarker):
        mbs.AddObject(ObjectJointSpherical(markerNumbers=[leading.marker, h.leading_marker],
                                           visualization={"show": False, "jointRadius": 0.0, "color": [-1.0, -1.0, -1.0, -1.0]}))
    elif isinstance(leading, ReelOnto):
        h.lead_drive = add_reel(mbs, lead_node, t_exit, leading.coordinate_marker, leading.radius_m)

    if trailing == "back_tension":
        if sc.pull.back_tension_N > 0:
            end_force(trail_node, -sc.pull.back_tension_N * t_entry)
    elif trailing == "brake":
        if steady:
            h.trail_drive = add_drive(mbs, trail_node, t_entry, 0.0)
        elif ramp_time > 0.0:
            h.trail_drive = add_drive(mbs, trail_node, t_entry, speed, ramp_time)
        else:
            h.trail_drive = add_tangential_drive(mbs, trail_node, t_entry, speed)
    elif isinstance(trailing, JoinToMarker):
        mbs.AddObject(ObjectJointSpherical(markerNumbers=[trailing.marker, h.trailing_marker],
                                           visualization={"show": False, "jointRadius": 0.0, "color": [-1.0, -1.0, -1.0, -1.0]}))

    if with_contact:
        from ..contact import ContactKernel, ContactLaw
        from .coupling import ContactCoupling
        from .startup import StartupDamper, add_startup_damper
        ct = sc.contact
        law = ContactLaw(stiffness=ct.stiffness, damping=ct.damping, exponent=ct.exponent, friction=ct.friction,
                         static_friction=ct.static_friction, stribeck_velocity_m_per_s=ct.stribeck_velocity_m_per_s,
                         regularisation_velocity_m_per_s=ct.friction_regularisation_velocity_m_per_s,
                         damping_onset_m=ct.damping_onset_m)
        kernel_type, extra = ContactKernel, {}
        if steady:
            from ..contact.steady import SteadySlidingKernel
            kernel_type, extra = SteadySlidingKernel, {"speed_m_per_s": speed}
        h.kernel = kernel_type(conduit.segments, layout.element_length_m, c.radius_m, law,
                               start.mesh.check_points_per_element, rule=ct.check_point_rule,
                               reference_spacing_m=ct.reference_spacing_m, broad_phase=ct.broad_phase,
                               surface=ct.surface, centreline=centre, **extra)
        if compiled:
            from ..contact.ancf_cable import AncfCableForces
            h.cable_forces = AncfCableForces(layout.element_length_m, props.axial_stiffness_N,
                                             props.bending_stiffness_N_m2, props.integration,
                                             props.mass_per_length_kg_per_m, [0.0, 0.0, -g])
            h.load_scale.cable_forces = h.cable_forces
        h.coupling = ContactCoupling(mbs, cable.nodes, layout.coordinates, h.kernel, cable_forces=h.cable_forces)
        sp = sc.solver
        Le = layout.element_length_m
        lumped = c.mass_per_length_kg_per_m * (np.concatenate([Le, [0.0]]) + np.concatenate([[0.0], Le])) / 2  # [kg]
        if sp.pretension and sp.startup_time_s > 0.0 and not steady:
            h.startup_damper = StartupDamper(lumped, layout.velocities, sp.startup_damping_1_per_s, sp.startup_time_s)
            add_startup_damper(mbs, cable.nodes, h.startup_damper)
        if sp.exit_span_damping_1_per_s > 0.0 and leading == "rig" and not steady:
            from .startup import ExitSpanDamper, add_exit_span_damper
            h.exit_span_damper = ExitSpanDamper(lumped, layout.coordinates, sp.exit_span_damping_1_per_s, speed,
                                                np.asarray(centre.point(centre.length_m), dtype=float).reshape(3),
                                                t_exit, float(np.mean(Le)), ramp_time)
            add_exit_span_damper(mbs, cable.nodes, h.exit_span_damper)
        if leading == "force":
            # the sheave of a force-controlled pull: lateral stiffness of the contact law's order at
            # its working point (1e6 N/m), damped near-critically for the end node's mass
            h.guide = add_guide(mbs, lead_node, t_exit, 1.0e6,
                                2.0 * np.sqrt(1.0e6 * c.mass_per_length_kg_per_m * L_cable / layout.n_elements),
                                node_index=len(cable.nodes) - 1)
    # the reference's drift is along a time history, which a steady solve does not have
    h.reference_drift_N_per_s = 0.0 if steady else reference_drift_N_per_s(sc, conduit, sc.solver.end_time_s)
    sp = sc.solver
    h.recorder = Recorder(h, sp.output_interval_s, sp.steady_stop, sp.steady_window_s, sp.steady_tolerance,
                          earliest_steady_s=earliest_steady_s(h))
    return h


def build_model(scenario, with_contact: bool = True, refine: float = 1.0,
                check_points_per_element: int | None = None, start: InitialLayout | None = None,
                references: InitialLayout | None = None) -> Model:
    """Build and assemble the Exudyn system of ``scenario`` in a SystemContainer of its own.

    A thin wrapper of :func:`add_cable_in_conduit` with the scenario's rig and loads. The mesh is
    :func:`exucable.model.layout.plan_cable_mesh`'s: the rule of :mod:`exucable.scenario.mesh` or the
    scenario's override, with the element length divided by ``refine`` and the check points per
    element overridden by ``check_points_per_element`` (``exucable converge``). ``start`` replaces
    the start state (:func:`exucable.solve.start.steady_start`: the steady solve's state).
    ``references``: another model's start of the same scenario, whose rope solutions are reused
    (see :func:`exucable.model.layout.initial_layout`).
    """
    if start is None:
        start = initial_layout(scenario, with_contact, refine=refine, check_points_per_element=check_points_per_element,
                               references=references)
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    h = add_cable_in_conduit(mbs, scenario, with_contact=with_contact, start=start,
                             cable_element=scenario.solver.cable_element)
    model = Model(**{f: getattr(h, f) for f in h.__dataclass_fields__}, system_container=SC)
    model.recorder.cable = model
    mbs.Assemble()
    return model
