"""Contact law between a cable check point and the conduit wall (paper Sect. 2.4, Eqs. 18-20).

Pure numpy; nothing here knows of Exudyn or of the geometry. The functions work on arrays of
any shape, one entry per check point, and are the reference the compiled kernel is tested
against.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..scenario.fields import default_of

import numpy as np

__all__ = ["ContactLaw", "normal_force_magnitude", "friction_coefficient", "damping_ramp", "damping_onset",
           "onset_blend"]


@dataclass(frozen=True)
class ContactLaw:
    """Hertz normal force with damping (Eq. 18) and regularised Coulomb friction (Eqs. 19-20).

    Parameters
    ----------
    stiffness : float
        Normal contact stiffness K_n [N/m^e] of one check point of weight 1 (the kernel scales it
        by the check point's share of the element length, see :class:`ContactKernel`).
    damping : float
        Normal contact damping C_n [N·s/m], acting on the penetration rate δ̇ (Eq. 18).
    exponent : float
        Hertz exponent e [-] of f_n = K_n δ^e + C_n δ̇; at least 1 so that ∂f_n/∂δ stays finite
        at first touch (the paper's value is lost; the project uses 1.5).
    friction : float
        Kinetic (sliding) friction coefficient μ_k [-] (Eq. 19).
    static_friction : float or None
        Static friction coefficient μ_s >= μ_k [-]. ``None`` (default): μ = μ_k at every speed.
    stribeck_velocity_m_per_s : float
        Stribeck velocity v_s [m/s]: μ(v) = μ_k + (μ_s - μ_k)·exp(-(v/v_s)²). Unused when
        ``static_friction`` is None.
    regularisation_velocity_m_per_s : float
        Friction regularisation velocity ε [m/s]: the friction direction is v_τ/√(|v_τ|² + ε²)
        instead of v_τ/|v_τ| (Eq. 20), so the force is smooth through zero sliding speed.
    damping_onset_m : float
        Penetration δ_d [m] over which the damping term grows from 0 to C_n δ̇:
        f_n = K_n δ^e + C_n g δ̇ with g = min(δ/δ_d, 1) (default: the scenario's
        ``contact.damping_onset``). 0 is the paper's Eq. 18, whose damping force jumps to C_n δ̇
        at first touch.
    onset_layer_m : float
        Thickness s [m] of a smooth contact onset (docs/theory.md, "A smooth contact onset"): the
        law acts on the blended penetration φ_s(δ) of :func:`onset_blend` instead of max(δ, 0),
        so that contact begins at δ = -s with zero force and slope and is the Hertz law itself
        from δ = s on. 0 (default) is the law above, bit for bit; the several cables' steady solve
        continues s toward 0 (:mod:`exucable.solve.onset_continuation`).

    Notes
    -----
    In a dynamic run the onset g of each check point is held, within a time step, at its value
    in the step's start state, g = g(δ(t_n)); δ and δ̇ are the step's own. The product g(δ)·δ̇
    is what made Newton converge linearly: an iterate that overshoots a point into the wall by x
    meets a damping force ∝ x·ẋ ∝ x², and Newton on a quadratic halves the overshoot per
    iteration (measured on Example 4: penetration errors 30, 15, 7, 3.5 ... µm in successive
    iterates). With g held the force is linear in δ̇ and the Jacobian has no ∂g/∂δ term. It
    differs from the law at the step's end only through g(δ(t_n)) - g(δ(t_{n+1})), a first-order
    lag of a regularisation (the paper's law has no onset at all), and moves the paper examples'
    pulling forces by less than 1e-5 relative (docs/performance.md). The steady mode has δ̇ = 0
    and does not need it.
    """

    # defaults: the validated scenario defaults (scenarios/README.md)
    stiffness: float = default_of("contact.stiffness")
    damping: float = default_of("contact.damping")
    exponent: float = default_of("contact.exponent")
    friction: float = default_of("contact.friction")
    static_friction: float | None = default_of("contact.static_friction")
    stribeck_velocity_m_per_s: float = default_of("contact.stribeck_velocity")
    # 1 % of the paper's 0.1 m/s; a scenario sets 1 % of its own pull speed (scenarios/README.md)
    regularisation_velocity_m_per_s: float = 1.0e-3
    damping_onset_m: float = default_of("contact.damping_onset")
    onset_layer_m: float = 0.0

    def __post_init__(self):
        # The kernel is below the scenario layer, which reports bad user input with its own
        # keys; here a bad value is a programming error, hence ValueError.
        checks = [
            ("stiffness", self.stiffness >= 0.0, "must be >= 0"),
            ("damping", self.damping >= 0.0, "must be >= 0"),
            ("exponent", self.exponent >= 1.0, "must be >= 1 (finite stiffness at first touch)"),
            ("friction", self.friction >= 0.0, "must be >= 0"),
            ("stribeck_velocity_m_per_s", self.stribeck_velocity_m_per_s > 0.0, "must be > 0"),
            ("regularisation_velocity_m_per_s", self.regularisation_velocity_m_per_s > 0.0,
             "must be > 0"),
            ("damping_onset_m", self.damping_onset_m >= 0.0, "must be >= 0"),
            ("onset_layer_m", self.onset_layer_m >= 0.0, "must be >= 0 (0: contact starts at δ = 0)"),
        ]
        for name, ok, message in checks:
            value = getattr(self, name)
            if not (ok and math.isfinite(value)):
                raise ValueError(f"ContactLaw.{name} = {value!r}: {message}")
        if self.static_friction is not None and not (
            math.isfinite(self.static_friction) and self.static_friction >= self.friction
        ):
            raise ValueError(
                f"ContactLaw.static_friction = {self.static_friction!r}: must be >= friction "
                f"({self.friction}) or None"
            )

    @property
    def static_excess(self) -> float:
        """μ_s - μ_k [-]; 0 when there is no static friction."""
        return 0.0 if self.static_friction is None else self.static_friction - self.friction


def onset_blend(penetration_m, layer_m: float):
    """Blended penetration φ_s(δ) [m] and dφ_s/dδ [-] of a smooth contact onset of thickness s.

    φ_s(δ) = 0 for δ <= -s, (δ + s)²/(4s) for -s < δ < s, δ for δ >= s (docs/theory.md, "A smooth
    contact onset"): C¹, so the Hertz force K φ_s^e is C¹ in δ (C² at δ = -s for e = 1.5, where
    it grows as (δ + s)³), and its stiffness at the contact surface δ = 0 is K e (s/4)^(e-1)/2
    instead of 0. For s = 0: (max(δ, 0), 1), the law without the layer.

    Parameters
    ----------
    penetration_m : array_like
        Penetration δ [m] (negative: a gap).
    layer_m : float
        s >= 0 [m].

    Returns
    -------
    phi : ndarray
        φ_s(δ) [m].
    dphi : ndarray
        dφ_s/dδ [-].
    """
    d = np.asarray(penetration_m, dtype=float)
    if layer_m <= 0.0:
        return np.maximum(d, 0.0), np.ones_like(d)
    s = float(layer_m)
    x = np.clip(d + s, 0.0, 2.0 * s)
    blend = d < s
    return np.where(blend, x * x / (4.0 * s), d), np.where(blend, x / (2.0 * s), 1.0)


def normal_force_magnitude(law: ContactLaw, penetration_m, penetration_rate_m_per_s):
    """Unweighted normal force max(0, K_n φ^e + C_n g(φ) δ̇) [N] (Eq. 18, never pulling), φ the
    penetration blended over the law's onset layer (:func:`onset_blend`; δ itself for s = 0).

    Parameters
    ----------
    law : ContactLaw
    penetration_m : array_like
        Penetration δ [m]; entries <= -s give zero force.
    penetration_rate_m_per_s : array_like
        Penetration rate δ̇ = n·v [m/s].

    Returns
    -------
    ndarray
        f_n [N], same shape as the inputs.
    """
    delta = np.asarray(penetration_m, dtype=float)
    rate = np.asarray(penetration_rate_m_per_s, dtype=float)
    touching = delta > -law.onset_layer_m
    d = np.where(touching, onset_blend(delta, law.onset_layer_m)[0], 0.0)
    raw = law.stiffness * d ** law.exponent + law.damping * damping_ramp(law, d)[0] * rate
    return np.where(touching & (raw > 0.0), raw, 0.0)


def damping_ramp(law: ContactLaw, penetration_m):
    """(g, dg/dδ) of the damping onset g(δ) = min(δ/δ_d, 1); (1, 0) for the paper's law (δ_d = 0)."""
    d = np.asarray(penetration_m, dtype=float)
    if law.damping_onset_m <= 0.0:
        return np.ones_like(d), np.zeros_like(d)
    ramp = d < law.damping_onset_m
    return np.where(ramp, d / law.damping_onset_m, 1.0), np.where(ramp, 1.0 / law.damping_onset_m, 0.0)


def damping_onset(law: ContactLaw, penetration_m):
    """Damping onset g(δ) [-] of penetrations δ [m]: min(δ/δ_d, 1) for δ > 0, 0 for δ <= 0
    (out of contact); 1 everywhere for the paper's law (δ_d = 0), whose damping is not ramped."""
    d = np.asarray(penetration_m, dtype=float)
    if law.damping_onset_m <= 0.0:
        return np.ones_like(d)
    return np.where(d > 0.0, damping_ramp(law, np.maximum(d, 0.0))[0], 0.0)


def friction_coefficient(law: ContactLaw, sliding_speed_squared):
    """Friction coefficient μ(|v_τ|) [-] with the optional Stribeck decay.

    Parameters
    ----------
    law : ContactLaw
    sliding_speed_squared : array_like
        |v_τ|² [m²/s²]; the square is the argument so that μ is smooth at zero speed.

    Returns
    -------
    mu : ndarray
        μ_k + (μ_s - μ_k)·exp(-|v_τ|²/v_s²).
    dmu_dg : ndarray
        dμ/d(|v_τ|²) [s²/m²], used by the Jacobian.
    """
    g = np.asarray(sliding_speed_squared, dtype=float)
    excess = law.static_excess
    if excess == 0.0:
        return np.full_like(g, law.friction), np.zeros_like(g)
    inv_vs2 = 1.0 / law.stribeck_velocity_m_per_s**2
    decay = np.exp(-g * inv_vs2)
    return law.friction + excess * decay, -excess * inv_vs2 * decay
