"""Is a steady sliding state physical? Two checks on the whole cable's loads.

A steady solve ends where its residual is small; that alone does not make the state the steady
pull. Two conditions every steady sliding state of a cable in a conduit with Coulomb friction
satisfies, evaluated from the loads the post-processing already has (:class:`CableLoads`):

1. **Force balance.** The contact forces, the weight, nodal forces and the two ends' forces sum
   to zero: Σ F = 0.
2. **The friction cone of the whole cable.** Let E = R_lead + R_trail + W be the ends' forces plus
   the weight, so that the conduit's forces on the cable sum to −E = N + F_μ (normal and friction
   parts). With Coulomb friction |F_μ| ≤ μ_hi Σ|f_n| and |N| ≤ Σ|f_n|, so
   Σ|f_n| ≥ |E| / (1 + μ_hi). Every contact point slides at the pull speed V along the cable, so
   the friction dissipates μ_lo Σ|f_n| · V at least, and the power the ends and gravity put in,

       P / V = R_lead · t_lead + R_trail · t_trail + ρA g · (r_lead − r_trail)   [N],

   pays for it and for what else is stored or dissipated (the stretch carried out, contact
   damping; all ≥ 0 in a steady pull). Hence P/V ≥ μ_lo / (1 + μ_hi) · |E|. For a velocity-
   controlled pull P/V = F − T_back − (the weight's share of lifting the cable), the smallest
   pulling force the conduit's reactions allow.

A state that breaks (2) has conduit reactions without their Coulomb friction (check points that
slide across the cable instead of along it, a friction not developed); one that breaks (1) is not
an equilibrium, whatever residual the solver reported. Neither is the pull the solve was asked
for. Evaluated at the steady solve's end (:func:`exucable.solve.steady.solve_steady`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .tension import CableLoads

__all__ = ["SteadyBalance", "steady_balance", "BALANCE_TOLERANCE"]

#: Tolerance of both checks, relative to the largest force in them [-]: far above the solve's stop
#: residual (1e-6 of the largest tension) and the loads' quadrature, far below a wrong state's miss.
BALANCE_TOLERANCE = 1e-3


@dataclass(frozen=True)
class SteadyBalance:
    """The two checks of a steady state (see the module docstring).

    Attributes
    ----------
    unbalanced_N : float
        |Σ F| [N].
    power_N : float
        P / V [N]: the ends' and gravity's power per pull speed.
    friction_bound_N : float
        μ_lo / (1 + μ_hi) · |E| [N], the least P / V Coulomb friction allows.
    scale_N : float
        The largest force in the checks [N] (the tolerance's reference).
    message : str
        Empty when both hold, else what failed, where the numbers are, and the fix.
    """

    unbalanced_N: float
    power_N: float
    friction_bound_N: float
    scale_N: float
    message: str

    @property
    def ok(self) -> bool:
        return not self.message


def steady_balance(loads: CableLoads, nodes: np.ndarray, material_length_m: float, friction: float,
                   static_friction: float | None = None, tolerance: float = BALANCE_TOLERANCE) -> SteadyBalance:
    """Check a steady sliding state's loads (module docstring).

    Parameters
    ----------
    loads : CableLoads
        Every external force on the cable at the state (static: no acceleration).
    nodes : ndarray, shape (n_el + 1, 6)
        The cable's absolute nodal coordinates [m, -], trailing end first.
    material_length_m : float
        The cable's unstretched length [m] (the weight's line load is per material length).
    friction, static_friction : float
        μ (kinetic) and the Stribeck law's static μ (None: none) [-].
    tolerance : float
        Relative tolerance [-].
    """
    q = np.asarray(nodes, dtype=float).reshape(-1, 6)
    ends = np.zeros(3)
    for f in (loads.leading_force_N, loads.trailing_force_N):
        if f is not None:
            ends = ends + np.asarray(f, dtype=float)
    weight = np.asarray(loads.line_load_N_per_m, dtype=float) * float(material_length_m)
    contact = np.sum(loads.point_force_N, axis=0) if loads.point_force_N.size else np.zeros(3)
    total = contact + np.sum(loads.node_force_N, axis=0) + weight + ends
    E = ends + weight

    def unit(v):
        return v / max(float(np.linalg.norm(v)), 1e-300)

    t_lead, t_trail = unit(q[-1, 3:]), unit(q[0, 3:])
    power = float(np.dot(loads.line_load_N_per_m, q[-1, :3] - q[0, :3]))   # gravity's, per V
    if loads.leading_force_N is not None:
        power += float(np.dot(loads.leading_force_N, t_lead))
    if loads.trailing_force_N is not None:
        power += float(np.dot(loads.trailing_force_N, t_trail))
    mu_lo = float(friction)
    mu_hi = max(mu_lo, float(static_friction) if static_friction is not None else mu_lo)
    bound = mu_lo / (1.0 + mu_hi) * float(np.linalg.norm(E))
    scale = max(float(np.linalg.norm(E)), abs(power), float(np.linalg.norm(weight)),
                *(float(np.linalg.norm(f)) for f in (loads.leading_force_N, loads.trailing_force_N) if f is not None),
                1e-12)
    unbalanced = float(np.linalg.norm(total))
    msgs = []
    if unbalanced > tolerance * scale:
        msgs.append(f"its loads do not balance: |Σ F| = {unbalanced:.4g} N of {scale:.4g} N (more than "
                    f"{tolerance:g}): not an equilibrium")
    if power < bound - tolerance * scale:
        msgs.append(f"the pull's power is too small for the friction the conduit's reactions need: ends and "
                    f"gravity put in {power:.4g} N·V, Coulomb friction on reactions |N + F_μ| = "
                    f"{np.linalg.norm(E):.4g} N dissipates at least μ/(1 + μ)·|N + F_μ| = {bound:.4g} N·V "
                    f"(the conduit's reactions lack their friction)")
    return SteadyBalance(unbalanced, power, bound, scale, "; ".join(msgs))
