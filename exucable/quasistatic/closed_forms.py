"""Closed-form tensions of a rope (no bending stiffness) pulled through simple conduits.

Each function is an exact solution of the rope equation used by :mod:`exucable.quasistatic.rope`
(``reference/README.md``, "The rope equation behind the closed forms"),

    dT/ds = μ · |T κn − w (e_z − (e_z·t) t)| + w (e_z·t),

for one conduit shape, with the cable pulled toward increasing s. ``w = ρAg`` is the weight per length
[N/m] acting along −z. The straight incline is the paper's Eq. (25) and the weightless bend is its Eq. (26);
the weighted bends are the classical pulling formulas (Rifenburg 1953, Smith 1981, refs. [1, 2] of the paper)
re-derived here from the rope equation, with their validity range checked.

Bends in a vertical plane: with φ the elevation of the tangent, the transverse load is
``(T/R ∓ w cos φ) n`` (− for a sag bend, whose centre of curvature is above; + for a hump bend, whose centre
is below), so the equation is linear in T as long as that load keeps its sign, and is solved exactly.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "incline_tension_N",
    "capstan_out_N",
    "capstan_in_N",
    "helix_turning_angle_rad",
    "horizontal_bend_out_N",
    "sag_bend_out_N",
    "hump_bend_out_N",
]

# Points at which the vertical-bend validity (one-signed normal force, T >= 0) is checked.
_CHECK_POINTS = 2001


def incline_tension_N(x_m, w_N_per_m: float, mu: float, theta_rad: float):
    """Tension in a cable pulled up a straight incline, paper Eq. (25): T = w (μ cos θ + sin θ) x.

    Parameters
    ----------
    x_m : float or array_like
        Distance from the free (lower, trailing) end, measured along the conduit [m].
    w_N_per_m : float
        Weight per length w = ρAg [N/m].
    mu : float
        Friction coefficient [-].
    theta_rad : float
        Inclination above the horizontal [rad]; negative for a cable pulled downhill.

    Returns
    -------
    float or ndarray
        Tension [N]. Valid while it is >= 0: pulled downhill with tan|θ| > μ, the rope equation gives a
        negative value, i.e. the cable would run slack (the rope solver clamps at 0 there).
    """
    return w_N_per_m * (mu * math.cos(theta_rad) + math.sin(theta_rad)) * np.asarray(x_m, dtype=float)


def capstan_out_N(T_in_N: float, mu: float, beta_rad: float) -> float:
    """Capstan law, paper Eq. (26): T_out = T_in · e^(μβ) [N], no weight.

    Parameters
    ----------
    T_in_N : float
        Tension at the trailing side [N].
    mu : float
        Friction coefficient [-].
    beta_rad : float
        Total turning angle ∫κ ds of the conduit between the two ends [rad] (the paper's "helical angle";
        for a helix use :func:`helix_turning_angle_rad`, not 2π per coil).
    """
    return T_in_N * math.exp(mu * beta_rad)


def capstan_in_N(T_out_N: float, mu: float, beta_rad: float) -> float:
    """Inverse of :func:`capstan_out_N`: the trailing tension T_in = T_out · e^(−μβ) [N] for a given pull."""
    return T_out_N * math.exp(-mu * beta_rad)


def helix_turning_angle_rad(turns: float, radius_m: float, pitch_m: float) -> float:
    """Total turning angle ∫κ ds of a helix [rad]: turns · 2π · a / √(a² + (p/2π)²).

    A helix of radius a and pitch p has curvature κ = a/(a² + c²), c = p/2π, and arc length
    2π√(a² + c²) per coil, so each coil turns the tangent by 2π·a/√(a² + c²) < 2π
    (NOTES.md, Example 3). For p = 0 this is 2π per coil.

    Parameters
    ----------
    turns : float
        Number of coils [-].
    radius_m : float
        Coil radius a [m].
    pitch_m : float
        Rise per coil p [m].
    """
    c = pitch_m / (2.0 * math.pi)
    return turns * 2.0 * math.pi * radius_m / math.hypot(radius_m, c)


def horizontal_bend_out_N(T_in_N: float, mu: float, theta_rad: float, w_N_per_m: float, radius_m: float) -> float:
    """Tension after a bend of radius R in a horizontal plane, with weight (NOTES.md).

    The tension's pull toward the centre (T/R) and the weight (w) are perpendicular, so
    dT/dφ = μ √(T² + (wR)²), whose solution is

        T_out = T_in cosh(μθ) + sinh(μθ) √(T_in² + (wR)²).

    Parameters
    ----------
    T_in_N : float
        Tension entering the bend [N].
    mu : float
        Friction coefficient [-].
    theta_rad : float
        Bend angle [rad].
    w_N_per_m : float
        Weight per length [N/m].
    radius_m : float
        Bend radius of the centreline [m].
    """
    x = mu * theta_rad
    return T_in_N * math.cosh(x) + math.sinh(x) * math.hypot(T_in_N, w_N_per_m * radius_m)


def _vertical_bend(T_in_N, mu, theta_rad, w_N_per_m, radius_m, entry_elevation_rad, sag: bool) -> float:
    """Exact solution of the rope equation on a bend in a vertical plane (see the two public wrappers).

    With φ the tangent elevation and ψ ∈ [0, θ] the angle turned (ds = R dψ):
    sag  (φ = φ0 + ψ): dT/dψ = μσ(T − wR cos φ) + wR sin φ,
    hump (φ = φ0 − ψ): dT/dψ = μσ(T + wR cos φ) + wR sin φ,
    σ = ±1 the sign of the transverse load, assumed constant. Both are linear with a particular solution
    A cos φ + B sin φ; the homogeneous part is C e^(μσψ).
    """
    if theta_rad <= 0.0:
        raise ValueError(f"bend angle must be > 0, got {theta_rad!r} rad")
    if radius_m <= 0.0 or w_N_per_m < 0.0 or mu < 0.0 or T_in_N < 0.0:
        raise ValueError("need radius_m > 0, w_N_per_m >= 0, mu >= 0, T_in_N >= 0")
    wr = w_N_per_m * radius_m
    psi = np.linspace(0.0, theta_rad, _CHECK_POINTS)
    sign_gravity = -1.0 if sag else 1.0  # transverse load/(1/R) = T + sign_gravity · wR cos φ
    phi = entry_elevation_rad + psi if sag else entry_elevation_rad - psi
    phi0 = entry_elevation_rad
    tol = 1e-12 * max(T_in_N, wr, 1e-300)
    # σ is fixed by the sign of the transverse load at the entry (+1 if zero there); the solution is accepted if
    # that sign holds over the whole bend and the tension stays >= 0. Otherwise report which failed first.
    sigma = 1.0 if T_in_N + sign_gravity * wr * math.cos(phi0) >= 0.0 else -1.0
    if sag:
        a = wr * (mu * mu - 1.0) / (1.0 + mu * mu)
    else:
        a = wr * (1.0 - mu * mu) / (1.0 + mu * mu)
    b = -2.0 * mu * sigma * wr / (1.0 + mu * mu)
    c = T_in_N - a * math.cos(phi0) - b * math.sin(phi0)
    tension = c * np.exp(mu * sigma * psi) + a * np.cos(phi) + b * np.sin(phi)
    load = tension + sign_gravity * wr * np.cos(phi)
    bad_load = np.nonzero(sigma * load < -tol)[0]
    bad_tension = np.nonzero(tension < -tol)[0]
    first_load = bad_load[0] if bad_load.size else _CHECK_POINTS
    first_tension = bad_tension[0] if bad_tension.size else _CHECK_POINTS
    if first_tension < _CHECK_POINTS and first_tension <= first_load:
        raise ValueError(f"the tension would turn negative {math.degrees(psi[first_tension]):.4g} deg into the bend "
                         "(the cable runs slack); the closed form does not apply")
    if first_load < _CHECK_POINTS:
        raise ValueError(f"the normal force changes sign {math.degrees(psi[first_load]):.4g} deg into the bend (the "
                         "cable moves to the opposite wall); the closed form holds only while it keeps one sign")
    return float(tension[-1])


def sag_bend_out_N(T_in_N: float, mu: float, theta_rad: float, w_N_per_m: float, radius_m: float,
                   entry_elevation_rad: float = 0.0) -> float:
    """Tension after a sag bend (concave up: centre of curvature above) in a vertical plane.

    Covers a bend entered with tangent elevation φ0 (default 0: horizontally) that turns **up** by θ, e.g. the
    foot of a rising slope (φ0 = 0) or the bottom of a dip entered downhill (φ0 = −θ, leaving horizontally).
    With σ = sign(T − wR cos φ) constant (σ = +1: the tension lifts the cable against the upper, inner wall;
    σ = −1: the cable lies on the lower, outer wall):

        T(φ) = (T_in − A cos φ0 − B sin φ0) e^(μσ(φ − φ0)) + A cos φ + B sin φ,
        A = −wR (1 − μ²)/(1 + μ²),  B = −2μσ wR/(1 + μ²).

    For φ0 = 0 and σ = +1 this is T_out = T_in e^(μθ) + wR [(1 − μ²)(e^(μθ) − cos θ) − 2μ sin θ]/(1 + μ²);
    without friction it reduces to T_in + wR(1 − cos θ), the weight of the rise.

    Parameters
    ----------
    T_in_N : float
        Tension entering the bend [N] (>= 0).
    mu : float
        Friction coefficient [-].
    theta_rad : float
        Bend angle [rad] (> 0).
    w_N_per_m : float
        Weight per length [N/m].
    radius_m : float
        Bend radius of the centreline [m].
    entry_elevation_rad : float
        Elevation of the tangent entering the bend [rad].

    Returns
    -------
    float
        Tension leaving the bend [N].

    Raises
    ------
    ValueError
        If the normal force T/R − w cos φ changes sign inside the bend (a light cable starting on the lower wall is
        lifted to the upper one as its tension grows, or the reverse), or the tension would turn negative. The
        check samples 2001 points of the bend.
    """
    return _vertical_bend(T_in_N, mu, theta_rad, w_N_per_m, radius_m, entry_elevation_rad, sag=True)


def hump_bend_out_N(T_in_N: float, mu: float, theta_rad: float, w_N_per_m: float, radius_m: float,
                    entry_elevation_rad: float = 0.0) -> float:
    """Tension after a hump bend (concave down: centre of curvature below) in a vertical plane.

    Covers a bend entered with tangent elevation φ0 (default 0: horizontally, over a crest) that turns **down**
    by θ, e.g. the top of a descending slope (φ0 = 0) or the crest of a rise entered uphill (φ0 = +θ). The
    transverse load is (T/R + w cos φ) n: tension and weight both press the cable on the lower (inner) wall
    while |φ| < 90°, so the normal force keeps its sign there; it can only change sign if the bend runs past
    the vertical (cos φ < 0, e.g. entering steeply uphill and turning down by more than 90° + φ0). With
    σ = sign(T + wR cos φ):

        T(φ) = (T_in − A cos φ0 − B sin φ0) e^(μσ(φ0 − φ)) + A cos φ + B sin φ,
        A = wR (1 − μ²)/(1 + μ²),  B = −2μσ wR/(1 + μ²).

    Without friction it reduces to T_in − wR(1 − cos θ) for φ0 = 0, the weight of the descent.

    Parameters
    ----------
    T_in_N, mu, theta_rad, w_N_per_m, radius_m, entry_elevation_rad
        As in :func:`sag_bend_out_N`.

    Returns
    -------
    float
        Tension leaving the bend [N].

    Raises
    ------
    ValueError
        If the normal force T/R + w cos φ changes sign inside the bend, or the tension would turn negative
        (steep descent: the cable runs slack). The check samples 2001 points of the bend.
    """
    return _vertical_bend(T_in_N, mu, theta_rad, w_N_per_m, radius_m, entry_elevation_rad, sag=False)
