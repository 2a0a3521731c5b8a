"""Flexible-cable references for the cable's current extent.

A velocity-controlled pull moves the cable out of its conduit at the pull speed v: after a time t
the length inside is ``L_cable − v t`` (the tail has moved in by v t) and a straight length v t
runs from the conduit's exit to the rig along the exit tangent. Gravity acts on both changes, so
on a route with weight the pulling force drifts by (μ w e^{μθ} for the tail's friction) + (w t_z for
the head's weight along the exit line) times v, and "the" rope answer depends on the time. The
references here are evaluated for the extent the cable has at a given time, so that a run's
steady window is compared with the reference of that same window:

    F_ref(t) = F_rope(cable inside: L_cable − v t) + w (e_z · t_exit) v t,

the second term the weight of the length beyond the exit pulled along the exit line (its sag
between the conduit's mouth and the rig is ignored: O(w (vt)²/T) sideways). Both the centreline
rope (:mod:`exucable.quasistatic.rope`) and the rope with clearance (:mod:`exucable.quasistatic.clearance`) are given.
Exudyn-free.
"""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from .rope import rope_pull_force_N
from .clearance import solve_rope_with_clearance

__all__ = ["pull_force_references_N", "reference_drift_N_per_s"]


def pull_force_references_N(scenario, conduit, pulled_out_m: float = 0.0, with_clearance: bool = True,
                            clearance_solution=None, rope_solution=None) -> dict:
    """Pulling force of both flexible references once ``pulled_out_m`` of cable has left the conduit.

    Parameters
    ----------
    scenario : Scenario
        A velocity-controlled pull (``pull.force_N`` None).
    conduit : Conduit
        The scenario's conduit oriented so that the leading end is at its end.
    pulled_out_m : float
        Length of cable pulled out past the conduit's exit since the start [m], v·t.
    with_clearance : bool
        Also solve the rope with clearance (the costlier of the two).
    clearance_solution : ClearanceRopeSolution, optional
        The rope with clearance already solved for this conduit and extent (the start's, at
        ``pulled_out_m`` 0): used instead of solving it again.
    rope_solution : RopeSolution, optional
        Likewise the centreline rope already solved for this conduit and extent (the start's).

    Returns
    -------
    dict
        ``rope_pull_force_N`` (centreline rope) and ``rope_clearance_pull_force_N`` (rope with
        clearance; None without clearance or if that cable runs slack) [N], and ``pulled_out_m``.
    """
    sc = scenario
    if sc.pull.force_N is not None:
        raise ModelError("pull.force", "the extent references are for velocity-controlled pulls")
    centre = conduit.centreline
    g = sc.gravity.g_m_per_s2 if sc.gravity is not None else 0.0
    w = sc.cable.mass_per_length_kg_per_m * g
    out = float(max(pulled_out_m, 0.0))
    inside = sc.cable_length_m - out
    if inside <= 0.0:
        raise ModelError("solver.end_time", f"the cable has left its conduit ({out:.4g} m pulled out of "
                         f"{sc.cable_length_m:.4g} m)")
    head = w * float(np.asarray(centre.tangent(centre.length_m))[2]) * out
    mu, back = sc.contact.friction, sc.pull.back_tension_N
    # only the force is needed: without a solution at hand, the rope's force alone (no profile)
    rope = (rope_solution.pull_force_N if rope_solution is not None
            else rope_pull_force_N(centre, mu, w, back, cable_length_m=inside)) + head
    clearance = conduit.inner_radius_m - sc.cable.radius_m
    clear = None
    if clearance > 0.0 and with_clearance and clearance_solution is not None:
        clear = clearance_solution.pull_force_N + head
    elif clearance > 0.0 and with_clearance:
        try:
            clear = solve_rope_with_clearance(centre, clearance, mu, w, back, cable_length_m=inside).pull_force_N + head
        except ModelError:
            clear = None
    return {"rope_pull_force_N": rope, "rope_clearance_pull_force_N": clear, "pulled_out_m": out}


def reference_drift_N_per_s(scenario, conduit, duration_s: float) -> float:
    """Rate at which the centreline rope's pulling force changes as the cable leaves its conduit [N/s].

    The secant over ``duration_s`` [s] at the pull speed (exact while the tail stays on one straight
    and the head on the exit line: the drift is then linear, (μ w_⊥ e^{μθ} ± w_∥) v at the tail plus
    w (e_z·t_exit) v at the head). 0 for force-controlled pulls, without gravity, or when the cable
    would leave the conduit within ``duration_s``.
    """
    sc = scenario
    if sc.pull.force_N is not None or sc.gravity is None or sc.gravity.g_m_per_s2 == 0.0 or duration_s <= 0.0:
        return 0.0
    out = sc.pull.speed_m_per_s * duration_s
    if out >= sc.cable_length_m:
        return 0.0
    f0 = pull_force_references_N(sc, conduit, 0.0, with_clearance=False)["rope_pull_force_N"]
    f1 = pull_force_references_N(sc, conduit, out, with_clearance=False)["rope_pull_force_N"]
    return (f1 - f0) / duration_s
