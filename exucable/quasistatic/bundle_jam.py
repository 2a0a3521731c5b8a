"""The jam of three cables as rigid circles in a round duct: the keystone wedge and when friction holds it.

The independent model the bundle jam study reads its simulations against (studies/bundle_jam_study.py).
Assumptions: three equal rigid circles of diameter d in the duct's circular cross-section (inner
diameter D, ρ = (D − d)/2 the largest axis offset), each pressed by the same lateral load p per
unit length (the bend's T κ, the weight, or both) toward "down", statics of the cross-section only,
friction (where it acts) at the wall only: friction between the cables would hold a keystone in a
wider band.

The jam (Anixter: "the wedging of three cables lying side by side in a conduit") is the **keystone**:
the outer cables a and b on the wall at ±ψ from the bottom, spread apart (not touching), and the
middle cable m above them, off the wall, held by a and b alone. With a = (−ρ sin ψ, −ρ cos ψ) and
h = √(d² − ρ² sin² ψ) the height of m over the line a–b, the balance of m gives the contact force
G = p d / (2h), and the balance of a, with the wall's normal force N (toward the duct's axis) and a
friction force F along the wall (toward larger ψ, i.e. against a sliding down the wall):

    N = p (ρ sin²ψ + 3 h cos ψ) / (2h),    F = p sin ψ (3h − ρ cos ψ) / (2h).

* Without friction in the cross-section (F = 0) the keystone needs ρ cos ψ = 3h, i.e.
  ρ²(1 + 8 sin²ψ) = 9 d², impossible for ρ < d (D/d < 3): three sliding, frictionless circles
  never wedge there; the outer ones slide down the wall until they touch and the middle one rests
  on them (the triangle). For D/d a little above 3 that balance exists (the outer cables a little
  below the horizontal) but is unstable: spread a hair more, the middle one drops between them.
* With a friction coefficient μ on the wall acting in the cross-section (cables that do not slide
  along the duct: static friction) a keystone stands where |F| ≤ μ N. Taking "across the duct" as
  the classifier does (the outer cables at least :data:`exucable.post.bundle.ACROSS_DEG` = 150°
  apart seen from the duct's axis, 2ψ ≥ 150°), the least friction that holds one
  (:func:`keystone_friction_needed`) falls from 0.77 at D/d = 2.9 to 0.28 at 2.99 and to 0 above 3 (the unstable balance),
  while its contact force G/p = d/(2h) grows without bound toward D/d = 3 (5.0 at 2.99 across): the
  jam's force multiplication. The widest duct with such a keystone has ρ sin 75° = d, D/d = 3.07.
  So a keystone across can stand for D/d from where μ suffices up to 3.07
  (:func:`wedge_band_d_over_D`: 2.967-3.07 for μ 0.5). A bend's oval cross-section (the
  calculators' 5 %, :func:`exucable.quasistatic.engineering.jam_ratio`) stretches or shrinks the
  diameter across the bundle by that factor, so the nominal band widens to 2.83-3.22: NFPA 70's
  2.8-3.2.

The dynamic model with the pull standing still (``pull.stop_time``) and a static friction
(``contact.static_friction``) on the wall reproduces this band: a keystone laid at
:func:`least_friction_keystone`'s angle stands where μ_s exceeds the friction it needs and drops into
the triangle where it does not (tests/test_bundle_jam.py, studies/bundle_jam_study.py).

Why the steady sliding model cannot show the keystone: a sliding cable's Coulomb friction acts
along its slip, along the duct, so its part in the cross-section is μN times the slope of the cable's
path across the duct (zero in a settled bundle): in steady sliding F = 0, the first case above.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError

__all__ = ["BEND_OVALITY", "Keystone", "keystone", "keystone_friction_needed", "least_friction_keystone",
           "frictionless_keystone_psi_rad", "wedge_band_d_over_D"]

#: Relative stretch of a bend's diameter across the bundle, either way [-]: the 5 % of the
#: calculators' jam ratio 1.05·D/d (Cableizer JR_p, :func:`exucable.quasistatic.engineering.jam_ratio`).
BEND_OVALITY = 0.05


@dataclass(frozen=True)
class Keystone:
    """Forces of the keystone wedge per unit lateral load p on each cable (:func:`keystone`).

    Attributes
    ----------
    psi_rad : ndarray
        The outer cables' angle on the wall from the load's direction [rad].
    contact_force_per_load : ndarray
        G/p, the a–m (and b–m) contact force over p [-].
    wall_force_per_load : ndarray
        N/p, the wall's normal force on a (and b) over p [-].
    wall_friction_per_load : ndarray
        F/p, the friction along the wall a (and b) needs to stay [-] (> 0: against sliding down).
    positions_m : ndarray (m, 3, 2)
        a, m, b as (horizontal, up) from the duct's axis, "down" the load's direction [m].
    """

    psi_rad: np.ndarray
    contact_force_per_load: np.ndarray
    wall_force_per_load: np.ndarray
    wall_friction_per_load: np.ndarray
    positions_m: np.ndarray


def _rho(duct_inner_diameter_m: float, cable_diameter_m: float) -> float:
    D, d = float(duct_inner_diameter_m), float(cable_diameter_m)
    if not (D > 2.0 * d and d > 0.0):
        raise ModelError("conduit.inner_radius", f"D/d = {D / d:.3g}: two cables do not fit side by side; "
                         "the keystone needs D/d > 2")
    return 0.5 * (D - d)


def keystone(duct_inner_diameter_m: float, cable_diameter_m: float, psi_rad) -> Keystone:
    """The keystone's forces at the outer cables' angles ``psi_rad`` [rad] (module docstring).

    Raises
    ------
    ModelError
        D/d ≤ 2, or an angle where the outer cables overlap (ρ sin ψ < d/2), cannot both touch the
        middle one (ρ sin ψ > d) or push it through the wall (``conduit.inner_radius``).
    """
    rho = _rho(duct_inner_diameter_m, cable_diameter_m)
    d = float(cable_diameter_m)
    psi = np.atleast_1d(np.asarray(psi_rad, dtype=float))
    half = rho * np.sin(psi)
    if np.any(half < 0.5 * d * (1 - 1e-12)) or np.any(half > d):
        raise ModelError("conduit.inner_radius", "keystone angle outside the spread range "
                         f"asin(d/2ρ) ≤ ψ ≤ asin(d/ρ) at D/d = {duct_inner_diameter_m / d:.4g}")
    h = np.sqrt(np.maximum(d * d - half * half, 0.0))
    y_m = -rho * np.cos(psi) + h
    if np.any(np.abs(y_m) > rho * (1 + 1e-12)):
        raise ModelError("conduit.inner_radius", "the middle cable of this keystone would stand in the wall")
    with np.errstate(divide="ignore"):
        G = d / (2.0 * h)
        N = (rho * np.sin(psi) ** 2 + 3.0 * h * np.cos(psi)) / (2.0 * h)
        F = np.sin(psi) * (3.0 * h - rho * np.cos(psi)) / (2.0 * h)
    pos = np.stack([np.stack([-half, -rho * np.cos(psi)], axis=-1), np.stack([np.zeros_like(psi), y_m], axis=-1),
                    np.stack([half, -rho * np.cos(psi)], axis=-1)], axis=1)
    return Keystone(psi_rad=psi, contact_force_per_load=G, wall_force_per_load=N, wall_friction_per_load=F,
                    positions_m=pos)


def least_friction_keystone(duct_inner_diameter_m: float, cable_diameter_m: float,
                            across_deg: float = 150.0) -> tuple[float, float]:
    """The keystone across the duct that needs the least wall friction: (its outer cables' angle ψ
    [rad], that friction F/N [-]), the minimum of :func:`keystone_friction_needed`; (nan, inf) where
    none fits. Where friction ≥ that holds a keystone, laid at this ψ it stands."""
    rho = _rho(duct_inner_diameter_m, cable_diameter_m)
    d = float(cable_diameter_m)
    lo = max(math.radians(0.5 * across_deg), math.asin(min(1.0, 0.5 * d / rho)))
    hi = math.pi - lo
    psi = np.linspace(lo, hi, int(round(math.degrees(hi - lo) / 0.01)) + 1)
    half = rho * np.sin(psi)
    h = np.sqrt(np.maximum(d * d - half * half, 0.0))
    fits = (half <= d) & (h > 0.0) & (np.abs(-rho * np.cos(psi) + h) <= rho)
    if not fits.any():
        return float("nan"), math.inf
    k = keystone(duct_inner_diameter_m, cable_diameter_m, psi[fits])
    need = np.abs(k.wall_friction_per_load) / k.wall_force_per_load
    i = int(np.argmin(need))
    return float(psi[fits][i]), float(need[i])


def keystone_friction_needed(duct_inner_diameter_m: float, cable_diameter_m: float,
                             across_deg: float = 150.0) -> float:
    """The least wall friction coefficient F/N [-] at which a keystone *across the duct* stands: the
    minimum over the outer cables' angles ψ with 2ψ within ``across_deg`` [deg] of 360 − ``across_deg``
    (seen from the duct's axis they are at least that far apart, as
    :data:`exucable.post.bundle.ACROSS_DEG` classifies a wedge), found on a grid of 0.01°.

    ``inf`` where no such keystone fits (D/d above 1 + 2/sin(``across_deg``/2), 3.07 at 150°). Spread less, the keystone is the triangle pushed apart: it needs less friction (≈ 0.4) but
    multiplies no force (G/p → 1/√3)."""
    return least_friction_keystone(duct_inner_diameter_m, cable_diameter_m, across_deg)[1]


def frictionless_keystone_psi_rad(duct_inner_diameter_m: float, cable_diameter_m: float) -> float | None:
    """The outer cables' angle ψ [rad] at which a keystone balances without friction,
    sin²ψ = (9d²/ρ² − 1)/8 (ρ cos ψ = 3h, module docstring); None where there is none (D/d < 3,
    or the middle cable would stand in the wall). The balance is unstable (spread a little more,
    the middle cable drops between the outer ones; a little less, they slide down under it)."""
    rho = _rho(duct_inner_diameter_m, cable_diameter_m)
    d = float(cable_diameter_m)
    s2 = (9.0 * d * d / (rho * rho) - 1.0) / 8.0
    if not 0.0 < s2 <= 1.0 or rho <= d:
        return None
    return math.asin(math.sqrt(s2))


def wedge_band_d_over_D(friction: float, ovality: float = 0.0, across_deg: float = 150.0) -> tuple:
    """The D/d band [-] in which a keystone across the duct (:func:`keystone_friction_needed`) can
    stand on a wall of friction ``friction`` [-] acting in the cross-section: from the D/d where the
    friction needed falls to μ up to 1 + 2/sin(``across_deg``/2) (the widest duct where the outer
    cables touch the middle one that far apart), the lower end divided and the upper multiplied by
    (1 + ``ovality``), the bend's relative stretch of the diameter across the bundle either way [-]
    (module docstring)."""
    from scipy.optimize import brentq

    mu = float(friction)
    if not (mu > 0.0 and ovality >= 0.0):
        raise ModelError("contact.friction", f"friction must be > 0 and ovality ≥ 0, got {mu}, {ovality}")
    need = lambda r: keystone_friction_needed(r, 1.0, across_deg) - mu      # noqa: E731
    a, b = 1.0 + math.sqrt(2.0), 3.0
    lo = a if need(a) <= 0.0 else brentq(need, a, b, xtol=1e-6)
    hi = 1.0 + 2.0 / math.sin(math.radians(0.5 * across_deg))
    return lo / (1.0 + ovality), hi * (1.0 + ovality)
