"""Several ropes pulled together round one bend: the tension split and the wall forces (no Exudyn).

The independent model the simulated bundle is checked against in a bend (tests/test_bundle_bends.py).
Assumptions: a horizontal circular bend without gravity, the cables perfectly flexible (EJ = 0) rigid
circles of diameter d in the duct's circular cross-section (inner diameter D), frictionless between
each other and across the cross-section (the wall's Coulomb friction μ acts along the cables only, as
they slide steadily), each cable's axis a circle round the bend's axis.

Statics of one sector dθ of the bend (per unit bend angle, so the cables' different radii drop out):
cable i carries the load T_i dθ toward the bend's axis (its tension's turn, the rope equation's T κ),
the wall presses it with N_i dθ (normal to the duct's wall, through the duct's axis) and its tension
grows by dT_i = μ N_i dθ. With ρ = (D - d)/2, x = d/(D - d) = sin(α/2) (α the angle at the duct's
axis between two touching cables on the wall), the load direction "down":

* **cradled 3** (middle cable m at the bottom, sides s at ±α): a side cable's balance along and
  across its wall normal gives N_s = T_s and the contact force 2 x T_s from the middle; the middle's
  wall force is then N_m = T_m + 4 x² T_s. So T_s = T_0 e^{μθ}, and T_m' = μ T_m + 4 μ x² T_0 e^{μθ}
  integrates to T_m = T_0 e^{μθ} (1 + 4 x² μ θ). With equal tensions T (μ = 0) the middle's share of
  the bundle's 3T is N_m = (3 w_c - 2)·T with w_c = 1 + (4/3)x², the calculators' cradled sidewall
  pressure (3 w_c - 2)·(3T)/(3R) per unit length of the bend's centreline (radius R).
* **triangular 3** (bottom cables b at ±α/2 touching, top cable t on them): the top has no wall
  contact, N_t = 0, so T_t = T_0; its load splits over the two bottoms along the equilateral
  triangle's sides, and a bottom's balance along the vertical gives N_b cos(α/2) = T_b + T_t/2, i.e.
  N_b = (T_b + T_0/2)/√(1 - x²). So T_b + T_0/2 = (3/2) T_0 e^{a θ}, a = μ/√(1 - x²): the bundle's
  total 3 T_0 e^{aθ} is the calculators' T_0 e^{w_c μ θ} with w_c = 1/√(1 - x²), and each bottom
  cable's wall force with equal tensions is w_c·(3T)/2, their w_c T/2R.
* **triangular 2** (side by side at ±α/2): N = T/√(1 - x²) each, T = T_0 e^{aθ}.

Valid while the bottom cables of the triangle stay pressed together: their contact force
G = N_b x - (T_t/2)/√3 ≥ 0 (a wedge that spreads them no longer stands on the wall as laid; refused).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError

__all__ = ["BendSplit", "bundle_bend_split"]


@dataclass
class BendSplit:
    """Tensions and wall forces of each cable round a bend (:func:`bundle_bend_split`).

    Attributes
    ----------
    theta_rad : ndarray (m,)
        Bend angles from the bend's entry [rad].
    tension_N : ndarray (n_cables, m)
        Each cable's tension [N], in the order of :func:`exucable.model.bundle.arrangement_offsets`.
    wall_force_per_angle_N : ndarray (n_cables, m)
        Each cable's wall normal force per unit bend angle [N/rad]; divided by the bend's centreline
        radius it is the sidewall pressure per unit length of the centreline [N/m].
    """

    theta_rad: np.ndarray
    tension_N: np.ndarray
    wall_force_per_angle_N: np.ndarray


def bundle_bend_split(count: int, arrangement: str, duct_inner_diameter_m: float, cable_diameter_m: float,
                      friction: float, entry_tension_N: float, theta_rad) -> BendSplit:
    """Each cable's tension and wall force round a horizontal bend without gravity, every cable
    entering with ``entry_tension_N`` [N] (see the module's derivation).

    Raises
    ------
    ModelError
        An arrangement this model does not cover, or a triangle that would not stand
        (``cable.arrangement``).
    """
    D, d = float(duct_inner_diameter_m), float(cable_diameter_m)
    if not D > 2.0 * d:
        raise ModelError("conduit.inner_radius", f"D/d = {D / d:.3g}: two cables do not fit side by side")
    x = d / (D - d)
    c = math.sqrt(1.0 - x * x)
    th = np.atleast_1d(np.asarray(theta_rad, dtype=float))
    mu, T0 = float(friction), float(entry_tension_N)
    if arrangement == "cradled" and count == 3:
        Ts = T0 * np.exp(mu * th)
        Tm = Ts * (1.0 + 4.0 * x * x * mu * th)
        T = np.stack([Ts, Tm, Ts])
        N = np.stack([Ts, Tm + 4.0 * x * x * Ts, Ts])
    elif arrangement == "triangular" and count in (2, 3):
        a = mu / c
        if count == 2:
            Tb = T0 * np.exp(a * th)
            T = np.stack([Tb, Tb])
            N = T / c
        else:
            Tb = 1.5 * T0 * np.exp(a * th) - 0.5 * T0
            Tt = np.full_like(th, T0)
            T = np.stack([Tb, Tb, Tt])
            Nb = (Tb + 0.5 * Tt) / c
            N = np.stack([Nb, Nb, np.zeros_like(th)])
            G = Nb * x - 0.5 * Tt / math.sqrt(3.0)
            if np.any(G < 0.0):
                raise ModelError("cable.arrangement", f"at D/d = {D / d:.3g} the top cable spreads the bottom ones "
                                 "apart in the bend: the triangle as laid does not stand; use \"cradled\"")
    else:
        raise ModelError("cable.arrangement", f"the bend model covers cradled 3, triangular 2 and 3 cables, "
                         f"not {arrangement} {count}")
    return BendSplit(theta_rad=th, tension_N=T, wall_force_per_angle_N=N)
