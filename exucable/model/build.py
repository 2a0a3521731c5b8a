"""Assemble the Exudyn system of one scenario: cable + rig + loads + contact.

Reads like the physical system: lay the cable in the conduit, hang the loads on it, hook the
rig to its leading end, let the conduit's wall act on it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import exudyn as exu

from ..errors import ModelError
from ..rope import RopeSolution, solve_rope, solve_rope_for_pull_force
from ..references import reference_drift_N_per_s
from ..rope_clearance import solve_rope_with_clearance
from .cable import CableHandles, CableProperties, add_cable, add_gravity
from .layout import CableLayout, contact_offsets, lay_cable
from .rig import Drive, Guide, add_drive, add_end_force, add_tangential_drive, smooth_ramp

if TYPE_CHECKING:  # for the annotations only
    from ..contact import ContactKernel
    from ..geometry import Conduit
    from ..scenario import Scenario
    from .coupling import ContactCoupling

__all__ = ["LoadScale", "Model", "build_model", "pull_oriented_conduit"]


@dataclass(eq=False)
class Model:
    """An assembled Exudyn system of one scenario and the handles post-processing needs."""

    scenario: Scenario
    system_container: exu.SystemContainer
    mbs: exu.MainSystem
    conduit: Conduit                     # pull-oriented: the leading end is at its end
    cable: CableHandles
    layout: CableLayout
    properties: CableProperties
    lead_drive: Drive | None
    trail_drive: Drive | None
    applied_pull_force_N: float | None   # force-controlled pull
    back_tension_N: float
    rope: RopeSolution | None
    load_scale: LoadScale | None = None
    coupling: ContactCoupling | None = None
    kernel: ContactKernel | None = None
    ode2_index: np.ndarray = field(default=None)
    # how fast the flexible reference's pulling force moves as the cable leaves its conduit [N/s]
    reference_drift_N_per_s: float = 0.0

    @property
    def axial_stiffness_N(self) -> float:
        return self.properties.axial_stiffness_N

    def load_factor(self, t: float) -> float:
        """Ramp factor of loads and speed at time t [-]."""
        return smooth_ramp(t, self.scenario.pull.ramp_time_s)

    def coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """Current absolute nodal coordinates and their rates, each shape (n_el + 1, 6)."""
        sd = self.mbs.systemData
        q = np.asarray(sd.GetODE2Coordinates())[self.ode2_index]
        v = np.asarray(sd.GetODE2Coordinates_t())[self.ode2_index]
        return (self.layout.coordinates + q.reshape(-1, 6), v.reshape(-1, 6))

    def pull_force_N(self, t: float) -> float:
        """Force of the rig on the leading end along the pull [N]."""
        if self.lead_drive is not None:
            return self.lead_drive.force_N(self.mbs)
        return self.applied_pull_force_N * self.load_factor(t)

    def trailing_reaction_N(self) -> float | None:
        """Brake force at the trailing end of a force-controlled pull [N] (None otherwise)."""
        if self.trail_drive is None:
            return None
        return -self.trail_drive.force_N(self.mbs)


class LoadScale:
    """Scale factors [-] of the loads of a steady (static) solve, the continuation parameters of
    :func:`exucable.solve_steady.solve_steady`: gravity and the end forces (back tension or the
    applied pull). All 1 = the scenario's loads. The loads carry no user function (Exudyn would
    call it once per element and residual); :meth:`apply` rewrites their load vectors instead."""

    def __init__(self):
        self.gravity = 1.0
        self.end_force = 1.0
        self._gravity_loads: list[tuple[int, list]] = []
        self._end_loads: list[tuple[int, list]] = []

    def track(self, gravity_loads=(), end_loads=(), vectors=None) -> None:
        """Remember loads (indices) and their full-scale vectors [N or m/s²]."""
        for i in gravity_loads:
            self._gravity_loads.append((i, vectors[i]))
        for i in end_loads:
            self._end_loads.append((i, vectors[i]))

    def apply(self, mbs, gravity: float, end_force: float) -> None:
        """Set the factors and rewrite the loads' vectors."""
        self.gravity, self.end_force = float(gravity), float(end_force)
        for loads, f in ((self._gravity_loads, self.gravity), (self._end_loads, self.end_force)):
            for i, vec in loads:
                mbs.SetLoadParameter(i, "loadVector", [f * x for x in vec])


def pull_oriented_conduit(scenario):
    """The scenario's conduit, reversed when the pull direction is ``reverse``, so that the
    leading end is always at the end of the returned conduit's centreline."""
    conduit = scenario.build_conduit()
    return conduit.reversed() if scenario.pull.direction == "reverse" else conduit


def _rope_start(scenario, centreline, w_N_per_m: float) -> RopeSolution:
    common = dict(friction=scenario.contact.friction, weight_per_length_N_per_m=w_N_per_m,
                  cable_length_m=scenario.cable_length_m)
    if scenario.pull.force_N is not None:
        return solve_rope_for_pull_force(centreline, pull_force_N=scenario.pull.force_N, **common)
    return solve_rope(centreline, trailing_tension_N=scenario.pull.back_tension_N, **common)


def _clearance_rope_start(scenario, centreline, w_N_per_m: float, clearance_m: float):
    """The rope with clearance for the start of a velocity-controlled pull, or None (force-controlled,
    no clearance, or a cable that runs slack somewhere)."""
    if scenario.pull.force_N is not None or clearance_m <= 0.0:
        return None
    try:
        return solve_rope_with_clearance(centreline, clearance_m, scenario.contact.friction, w_N_per_m,
                                         scenario.pull.back_tension_N, cable_length_m=scenario.cable_length_m)
    except ModelError:
        return None


def check_resolution(scenario, conduit) -> None:
    """Refuse meshes too coarse for the conduit: along the tightest bend (curvature κ) each
    element may turn at most 0.5 rad. A cubic element spanning an arc of angle φ departs from it
    by about Rφ⁴/100 (0.3 mm at R = 0.5 m, φ = 0.5 rad: a third of the paper's 1 mm clearance), and
    the coarse Example 3 (0.31 rad per element) is already 0.3-0.6 % off its capstan value."""
    kappa = 1.0 / conduit.centreline.min_bend_radius_m
    L_e = scenario.cable_length_m / scenario.cable.elements
    if kappa > 0 and L_e * kappa > 0.5:
        n_needed = int(np.ceil(scenario.cable_length_m * kappa / 0.5))
        raise ModelError(
            "cable.elements",
            f"elements of {L_e:.4g} m cannot follow the tightest bend (radius {1/kappa:.4g} m): "
            f"each element would turn {np.degrees(L_e * kappa):.1f} deg (at most 28.6 deg = 0.5 rad allowed); "
            f"use at least {n_needed} elements")


def build_model(scenario, with_contact: bool = True) -> Model:
    """Build the Exudyn system of ``scenario`` (a :class:`exucable.scenario.Scenario`).

    The start follows :mod:`exucable.model.layout`: pre-stretched to the rope tension, on its
    bearing wall, moving at the pull speed (unless ``solver.pretension`` is false: then on the
    centreline, unloaded, at rest, with loads and speed ramped over ``pull.ramp_time``).
    """
    sc = scenario
    conduit = pull_oriented_conduit(sc)
    centre = conduit.centreline
    L_cable = sc.cable_length_m
    if L_cable > centre.length_m * (1 + 1e-12):
        raise ModelError("cable.length", f"cable of {L_cable:.6g} m is longer than the conduit "
                         f"({centre.length_m:.6g} m); shorten it or extend the route")
    check_resolution(sc, conduit)
    c = sc.cable
    g = sc.gravity.g_m_per_s2 if sc.gravity is not None else 0.0
    w = c.mass_per_length_kg_per_m * g
    props = CableProperties(
        mass_per_length_kg_per_m=c.mass_per_length_kg_per_m,
        axial_stiffness_N=c.axial_stiffness_N,
        bending_stiffness_N_m2=c.bending_stiffness_N_m2,
        axial_damping_N_s=c.axial_damping_N_s,
        bending_damping_N_m2_s=c.bending_damping_N_m2_s,
        integration=c.integration,
    )
    clearance = conduit.inner_radius_m - c.radius_m
    speed = sc.pull.speed_m_per_s
    rope = _rope_start(sc, centre, w)
    if sc.solver.pretension:
        s_grid = np.linspace(0.0, centre.length_m, max(2001, 20 * sc.cable.elements + 1))
        T_grid = np.interp(s_grid, rope.s_conduit_m, rope.tension_N)
        L_e = L_cable / c.elements
        # blend over the length on which a tensioned beam leaves the wall, √(EJ/T), but at least
        # half an element so the nodes can follow it
        T_ref = max(float(np.max(rope.tension_N)), 1e-6)
        blend = max(0.5 * L_e, np.sqrt(c.bending_stiffness_N_m2 / T_ref))
        free = _clearance_rope_start(sc, centre, w, clearance) if with_contact else None
        path = {}
        if free is not None:
            # Start on the path of the rope with clearance: with gravity the cable leaves the wall in
            # free spans across the clearance, and a start pressed onto the wall the centreline rope's
            # load points to rang for a second as those spans formed (issue 10, item 3).
            T_grid = np.interp(s_grid, free.s_conduit_m, free.tension_N)
            path = {"path_offset_m": np.stack([np.interp(s_grid, free.s_conduit_m, free.offset_m[:, j])
                                               for j in range(3)], axis=1),
                    "path_pressure_N_per_m": np.interp(s_grid, free.s_conduit_m, free.sidewall_pressure_N_per_m)}
        off = contact_offsets(centre, s_grid, T_grid, w, clearance,
                              sc.contact.stiffness / sc.contact.reference_spacing_m,
                              sc.contact.exponent, blend, **path) if with_contact else np.zeros((len(s_grid), 3))

        def tension_fn(s):
            return np.interp(s, s_grid, T_grid)

        def offset_fn(s):
            return np.stack([np.interp(s, s_grid, off[:, j]) for j in range(3)], axis=1)

        layout = lay_cable(centre, L_cable, c.elements, c.axial_stiffness_N, speed, tension_fn, offset_fn,
                           clearance_m=clearance if with_contact else None)
    else:
        layout = lay_cable(centre, L_cable, c.elements, c.axial_stiffness_N, 0.0)

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    cable = add_cable(mbs, layout.coordinates, layout.element_length_m, props, layout.velocities,
                      draw_radius_m=c.radius_m)
    # steady mode: a static solve of the steady sliding state; the rig holds the leading end
    # (or, for a force-controlled pull, the trailing end) where the start put it, and the loads'
    # scale is the continuation parameter of exucable.solve_steady, not time
    steady = sc.solver.mode == "steady"
    if steady and not sc.solver.pretension:
        raise ModelError("solver.pretension", 'solver.mode = "steady" starts from the rope solution near the '
                         "steady state; set it to true (or use the dynamic mode)")
    ramp_time = sc.pull.ramp_time_s
    load_scale = LoadScale()
    factor = None if (steady or ramp_time <= 0) else (lambda t: smooth_ramp(t, ramp_time))
    if g > 0:
        gravity_vector = [0.0, 0.0, -g]
        loads = add_gravity(mbs, cable, gravity_vector, factor)
        load_scale.track(gravity_loads=loads, vectors={i: gravity_vector for i in loads})
    rig_speed = 0.0 if steady else speed
    t_exit = np.asarray(centre.tangent(centre.length_m), dtype=float)
    s_trail = centre.length_m - L_cable
    t_entry = np.asarray(centre.tangent(s_trail), dtype=float)
    lead_drive = trail_drive = None
    applied = None
    if sc.pull.force_N is None:
        lead_drive = add_drive(mbs, cable.nodes[-1], t_exit, rig_speed, ramp_time)
        if sc.pull.back_tension_N > 0:
            vec = list(-sc.pull.back_tension_N * t_entry)
            i = add_end_force(mbs, cable.nodes[0], vec, factor)
            load_scale.track(end_loads=[i], vectors={i: vec})
    else:
        applied = sc.pull.force_N
        vec = list(applied * t_exit)
        i = add_end_force(mbs, cable.nodes[-1], vec, factor)
        load_scale.track(end_loads=[i], vectors={i: vec})
        if steady:
            trail_drive = add_drive(mbs, cable.nodes[0], t_entry, 0.0)
        elif ramp_time > 0.0:
            trail_drive = add_drive(mbs, cable.nodes[0], t_entry, speed, ramp_time)
        else:
            trail_drive = add_tangential_drive(mbs, cable.nodes[0], t_entry, speed)

    model = Model(scenario=sc, system_container=SC, mbs=mbs, conduit=conduit, cable=cable, layout=layout,
                  properties=props, lead_drive=lead_drive, trail_drive=trail_drive,
                  applied_pull_force_N=applied, back_tension_N=sc.pull.back_tension_N, rope=rope,
                  load_scale=load_scale,
                  reference_drift_N_per_s=reference_drift_N_per_s(sc, conduit, sc.solver.end_time_s))
    if with_contact:
        from ..contact import ContactKernel, ContactLaw
        from .coupling import ContactCoupling, StartupDamper
        ct = sc.contact
        law = ContactLaw(stiffness=ct.stiffness, damping=ct.damping, exponent=ct.exponent, friction=ct.friction,
                         static_friction=ct.static_friction, stribeck_velocity_m_per_s=ct.stribeck_velocity_m_per_s,
                         regularisation_velocity_m_per_s=ct.friction_regularisation_velocity_m_per_s,
                         damping_onset_m=ct.damping_onset_m)
        kernel_type, extra = ContactKernel, {}
        if steady:
            from ..contact.steady import SteadySlidingKernel
            kernel_type, extra = SteadySlidingKernel, {"speed_m_per_s": speed}
        kernel = kernel_type(conduit.segments, layout.element_length_m, c.radius_m, law,
                             ct.check_points_per_element, rule=ct.check_point_rule,
                             reference_spacing_m=ct.reference_spacing_m, broad_phase=ct.broad_phase,
                             surface=ct.surface, centreline=centre, **extra)
        model.kernel = kernel
        damper = None
        sp = sc.solver
        if sp.pretension and sp.startup_time_s > 0.0 and not steady:
            Le = layout.element_length_m
            lumped = c.mass_per_length_kg_per_m * (np.concatenate([Le, [0.0]]) + np.concatenate([[0.0], Le])) / 2
            damper = StartupDamper(lumped, layout.velocities, sp.startup_damping_1_per_s, sp.startup_time_s)
        guide = None
        if applied is not None:
            # the sheave of a force-controlled pull: lateral stiffness of the contact law's order at
            # its working point (1e6 N/m), damped near-critically for the end node's mass
            guide = Guide(len(cable.nodes) - 1, t_exit, 1.0e6, 2.0 * np.sqrt(1.0e6 * c.mass_per_length_kg_per_m * L_cable / c.elements))
        model.coupling = ContactCoupling(mbs, cable.nodes, layout.coordinates, kernel, damper, guide)
    mbs.Assemble()
    model.ode2_index = np.concatenate([
        np.arange(mbs.GetNodeODE2Index(n), mbs.GetNodeODE2Index(n) + 6) for n in cable.nodes])
    return model
