"""Whether a run's answer can be trusted, and how precisely it is known.

Pure numpy/scipy on what a run recorded (no Exudyn):

* :func:`cable_axis_offset` — how far the cable's axis is from the conduit's axis, and where;
* :func:`pull_force_uncertainty` — the steady pulling force's mean over whole oscillation periods,
  its uncertainty (scatter of per-period means, plus the drift across the window) and drift rate;
* :func:`assess` — the flags that make a result untrustworthy, each naming the
  cause, where [m along the conduit] and when [s].

Thresholds (stated in the summary and in scenarios/README.md, "Trust"):

``PENETRATION_LIMIT`` — penetration δ beyond this fraction of min(clearance, cable radius): the
contact is too soft for the route (the cable no longer rides on the wall but in it, and the
friction acts on a different path).
Outside — the cable's axis farther from the conduit's axis than the inner radius R_in: at least half
the cable is outside its conduit.
``DYNAMIC_LIMIT`` — ρA·v² / pulling force (the rope's, when there is one) above this: the quasi-static capstan relation on which the
pull rests shifts by about ρA·v²(e^{μθ}−1) (the centrifugal load ρA·v²·κ offsets T·κ on the wall).
``FRICTION_DEFICIT_LIMIT`` — dynamic mode: the regularised friction μ v/√(v² + ε²) at the pull speed
V falls short of μ by more than this fraction (ε = ``contact.friction_regularisation_velocity``):
the friction is not fully developed and the pulling force comes out low (the unsafe side).
A scenario without any load (no gravity, back tension or prescribed force) has a quasi-static
pulling force of 0 N: ρA·v² has nothing to be compared with, and the zero answer stands.
Not steady — no window of ``solver.steady_window`` in which drift and scatter stay within
``solver.steady_tolerance``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["AxisGauge", "cable_sample_points", "PullForceEstimate", "pull_force_uncertainty", "assess", "not_steady_fix",
           "PENETRATION_LIMIT", "DYNAMIC_LIMIT", "FRICTION_DEFICIT_LIMIT", "TRUSTED_STATUSES", "friction_factor"]

# beyond ¼ of the clearance a stiff cable in a tight duct is > 5 % low (studies/wall_compliance_study.py);
# inside it the steady error bar's wall part states the shortfall (exucable.solve.error_bar)
PENETRATION_LIMIT = 0.25
DYNAMIC_LIMIT = 0.01
# 1e-4 of μ: the capstan force's error μθ·deficit stays below 0.05 % up to μθ = 5 (a long route)
FRICTION_DEFICIT_LIMIT = 1.0e-4
TRUSTED_STATUSES = ("ok", "steady")
# order of precedence: the run's status names the first that applies. A pull fast enough for
# inertia to matter is named before what it causes (a whipping cable pressed into or out of the wall).
_SEVERITY = ("failed", "dynamic", "friction_underdeveloped", "outside_conduit", "penetration", "not_steady")


def friction_factor(speed_m_per_s: float, regularisation_velocity_m_per_s: float) -> float:
    """V/√(V² + ε²) [-]: the share of μ the regularised friction law develops at sliding speed V."""
    v, eps = float(speed_m_per_s), float(regularisation_velocity_m_per_s)
    return v / math.hypot(v, eps) if v > 0.0 else 0.0


def cable_sample_points(coordinates, element_length_m) -> np.ndarray:
    """Nodes and element midpoints of an ANCF cable, shape (2 n_el + 1, 3) [m].

    The midpoint of the cubic Hermite element is (r_i + r_j)/2 + L (r'_i − r'_j)/8 (paper Eq. 5)."""
    q = np.asarray(coordinates, dtype=float).reshape(-1, 6)
    L = np.asarray(element_length_m, dtype=float)[:, None]
    mid = 0.5 * (q[:-1, :3] + q[1:, :3]) + L * (q[:-1, 3:] - q[1:, 3:]) / 8.0
    out = np.empty((2 * len(mid) + 1, 3))
    out[0::2] = q[:, :3]
    out[1::2] = mid
    return out


class AxisGauge:
    """Distance of points from a conduit's axis [m] and their arc length along it [m].

    The centreline is sampled at a spacing of half the inner radius (at most 200 000 samples);
    each point is projected onto the tangent line at its nearest sample, which is exact on
    straights and errs by O(h²/R) on bends. Beyond the ends, the distance is from the axis
    extended along the end tangents (where the pulled or fed cable is).
    """

    def __init__(self, centreline, inner_radius_m: float):
        L = centreline.length_m
        n = int(min(200_000, max(2, math.ceil(L / (0.5 * inner_radius_m)) + 1)))
        self.s = np.linspace(0.0, L, n)
        self.c = np.asarray(centreline.point(self.s), dtype=float).reshape(n, 3)
        self.t = np.asarray(centreline.tangent(self.s), dtype=float).reshape(n, 3)
        from ..contact.nearest import NearestSample  # numba: loaded when a run has a contact kernel

        self.nearest = NearestSample(self.c)
        self.length_m = L

    def __call__(self, points_m) -> tuple[np.ndarray, np.ndarray]:
        p = np.asarray(points_m, dtype=float).reshape(-1, 3)
        i = self.nearest(p)
        rel = p - self.c[i]
        along = np.einsum("ij,ij->i", rel, self.t[i])
        d = np.linalg.norm(rel - along[:, None] * self.t[i], axis=1)
        s = self.s[i] + along
        # beyond an end the cable runs along the end's tangent (the pulling line, the feed), which
        # may pass closer to the axis extended there than to any sample (a helix's next coil)
        for k, sign in ((0, -1.0), (-1, 1.0)):
            rel_k = p - self.c[k]
            along_k = rel_k @ self.t[k]
            d_k = np.linalg.norm(rel_k - along_k[:, None] * self.t[k], axis=1)
            better = (sign * along_k > 0.0) & (d_k < d)
            d = np.where(better, d_k, d)
            s = np.where(better, self.s[k] + along_k, s)
        return d, s


@dataclass(frozen=True)
class PullForceEstimate:
    """The steady pulling force and how well the run knows it.

    Attributes
    ----------
    mean_N : float
        Mean over whole oscillation periods in the window (the whole window if fewer than 2).
    uncertainty_N : float
        √(u_scatter² + u_drift²): u_scatter the standard error of the per-period means about
        their trend (the standard deviation of the force when fewer than 3 periods), u_drift half
        the change of the drift line across the window.
    drift_N_per_s : float
        Slope of the least-squares line through the per-period means (through the samples when
        fewer than 3 periods) [N/s].
    periods : int
        Whole oscillation periods found (crossings of the trend line upwards).
    period_s : float
        Mean period [s] (NaN without 2 crossings).
    window_s : tuple
        (start, end) of the window used [s].
    method : str
        How it was computed, in words.
    """

    mean_N: float
    uncertainty_N: float
    drift_N_per_s: float
    periods: int
    period_s: float
    window_s: tuple
    method: str


def pull_force_uncertainty(time_s, force_N, from_s: float) -> PullForceEstimate:
    """Estimate the pulling force over the window ``[from_s, end]`` (see :class:`PullForceEstimate`)."""
    t = np.asarray(time_s, dtype=float)
    f = np.asarray(force_N, dtype=float)
    m = t >= from_s - 1e-12
    t, f = t[m], f[m]
    if t.size < 3 or t[-1] <= t[0]:
        val = float(f.mean()) if f.size else float("nan")
        return PullForceEstimate(val, float("nan"), float("nan"), 0, float("nan"),
                                 (float(t[0]) if t.size else float("nan"), float(t[-1]) if t.size else float("nan")),
                                 "too few samples for an uncertainty")
    slope, icpt = np.polyfit(t - t[0], f, 1)
    resid = f - (icpt + slope * (t - t[0]))
    up = np.flatnonzero((resid[:-1] < 0.0) & (resid[1:] >= 0.0)) + 1
    u_drift = 0.5 * abs(slope) * (t[-1] - t[0])
    if up.size >= 3:
        means = np.array([f[a:b].mean() for a, b in zip(up[:-1], up[1:])])
        n = means.size
        if n >= 3:   # a line through an oscillation's partial periods tilts; one through period means does not
            centres = np.array([t[a:b].mean() for a, b in zip(up[:-1], up[1:])])
            slope = float(np.polyfit(centres - centres[0], means, 1)[0])
            u_drift = 0.5 * abs(slope) * (t[-1] - t[0])
            means = means - slope * (centres - centres.mean())   # scatter about the trend
        mean = float(f[up[0]:up[-1]].mean())
        u_scatter = float(means.std(ddof=1) / math.sqrt(n)) if n >= 3 else float(np.std(f))
        how = (f"mean over {n} whole periods (upward crossings of the trend line); scatter: "
               + ("standard error of the per-period means" if n >= 3 else "standard deviation (fewer than 3 periods)"))
        period = float((t[up[-1]] - t[up[0]]) / n)
    else:
        n, mean, u_scatter, period = 0, float(f.mean()), float(np.std(f)), float("nan")
        how = "mean over the window (no whole oscillation period found); scatter: standard deviation"
    u = math.hypot(u_scatter, u_drift)
    how += "; plus half the least-squares drift across the window, combined in quadrature"
    return PullForceEstimate(mean, u, float(slope), int(n), period, (float(t[0]), float(t[-1])), how)


def not_steady_fix(*, force_controlled: bool, start_from: str, exit_span_damping_1_per_s: float,
                   pretension: bool) -> str:
    """What to try when a dynamic run ends ``not_steady``, most effective first.

    A velocity-controlled pull from the rope start rings in the cable's all but undamped axial
    mode and, on a stiff cable, pulls its rig out of the last bend's boundary layer; the span past
    the exit swings undamped (reference/README.md, "Why the force wandered"). Steady mode gives
    the steady force without any of that; a longer run only waits.
    """
    tries = []
    if pretension:
        tries.append('solver.mode = "steady" for the steady force in one solve')
    if not force_controlled:
        if start_from != "steady" and pretension:
            tries.append('solver.start_from = "steady" to start the dynamic run in the steady state')
        if exit_span_damping_1_per_s == 0.0:
            tries.append("solver.exit_span_damping = 10 to damp the span past the exit")
    tries.append("raise solver.end_time")
    return "try " + "; or ".join(tries)


def assess(*, failed: bool, steady: bool, max_penetration_m: float, max_penetration_time_s: float,
           max_penetration_s_conduit_m: float, max_axis_offset_m: float, max_axis_offset_time_s: float,
           max_axis_offset_s_conduit_m: float, clearance_m: float, cable_radius_m: float, inner_radius_m: float,
           mass_per_length_kg_per_m: float, speed_m_per_s: float, pull_force_N: float,
           steady_window_s: float, steady_tolerance: float, end_time_s: float,
           base_status: str, loaded: bool = True, friction: float = 0.0,
           regularisation_velocity_m_per_s: float | None = None,
           not_steady_fix: str = "raise solver.end_time") -> tuple[str, list[dict]]:
    """The run's status and its flags (see the module docstring).

    ``loaded`` False (no gravity, back tension or prescribed force) skips the inertia check: the
    quasi-static pulling force is 0 N. ``regularisation_velocity_m_per_s`` ε (dynamic mode; None in
    steady mode, whose friction is fully developed) with ``friction`` μ > 0 checks the friction law's
    development at the pull speed.

    Returns
    -------
    status : str
        ``base_status`` ("ok"/"steady"/"failed") when nothing is flagged, else the first flag
        found of ``"failed"``, ``"dynamic"``, ``"friction_underdeveloped"``, ``"outside_conduit"``,
        ``"penetration"``, ``"not_steady"``.
    flags : list of dict
        Each with ``flag``, ``message``, and where known ``time_s`` and ``s_conduit_m`` (along the
        scenario's conduit).
    """
    flags = []
    if max_axis_offset_m > inner_radius_m:
        flags.append({"flag": "outside_conduit", "time_s": max_axis_offset_time_s, "s_conduit_m": max_axis_offset_s_conduit_m,
                      "value_m": max_axis_offset_m,
                      "message": f"the cable's axis is {1e3 * max_axis_offset_m:.3g} mm from the conduit's axis "
                                 f"(inner radius {1e3 * inner_radius_m:.3g} mm), "
                                 f"{1e3 * (max_axis_offset_m - inner_radius_m):.3g} mm beyond the wall, at "
                                 f"s = {max_axis_offset_s_conduit_m:.4g} m, t = {max_axis_offset_time_s:.4g} s: the contact "
                                 f"is far too soft (raise contact.stiffness)"})
    limit = PENETRATION_LIMIT * min(clearance_m, cable_radius_m)
    if max_penetration_m > limit:
        flags.append({"flag": "penetration", "time_s": max_penetration_time_s, "s_conduit_m": max_penetration_s_conduit_m,
                      "value_m": max_penetration_m, "limit_m": limit,
                      "message": f"penetration {1e3 * max_penetration_m:.3g} mm > {PENETRATION_LIMIT:g} × "
                                 f"min(clearance, cable radius) = {1e3 * limit:.3g} mm at s = {max_penetration_s_conduit_m:.4g} m, "
                                 f"t = {max_penetration_time_s:.4g} s (raise contact.stiffness)"})
    ratio = mass_per_length_kg_per_m * speed_m_per_s**2 / max(abs(pull_force_N), 1e-12) \
        if np.isfinite(pull_force_N) and loaded else float("nan")
    if np.isfinite(ratio) and ratio > DYNAMIC_LIMIT:
        flags.append({"flag": "dynamic", "value": ratio, "limit": DYNAMIC_LIMIT,
                      "message": f"ρA·v² = {mass_per_length_kg_per_m * speed_m_per_s**2:.4g} N is "
                                 f"{100 * ratio:.3g} % of the pulling force (> {100 * DYNAMIC_LIMIT:g} %): inertia "
                                 f"changes the wall loads; the quasi-static answer and its rope reference do not apply "
                                 f"(lower pull.speed)"})
    if regularisation_velocity_m_per_s is not None and friction > 0.0:
        factor = friction_factor(speed_m_per_s, regularisation_velocity_m_per_s)
        if 1.0 - factor > FRICTION_DEFICIT_LIMIT:
            # V/√(V² + ε²) ≥ 1 - limit  ⇔  ε ≤ V √((1 - limit)^-2 - 1)
            eps_max = speed_m_per_s * math.sqrt((1.0 - FRICTION_DEFICIT_LIMIT) ** -2 - 1.0)
            flags.append({"flag": "friction_underdeveloped", "value": 1.0 - factor, "limit": FRICTION_DEFICIT_LIMIT,
                          "message": f"at pull.speed {speed_m_per_s:.3g} m/s the regularised friction develops only "
                                     f"{100 * factor:.4g} % of μ (contact.friction_regularisation_velocity "
                                     f"{regularisation_velocity_m_per_s:.3g} m/s): the pulling force comes out low; "
                                     f"set contact.friction_regularisation_velocity <= {eps_max:.2g} m/s "
                                     f"(or use solver.mode = \"steady\")"})
    if not steady and not failed:
        flags.append({"flag": "not_steady", "time_s": end_time_s,
                      "message": f"no final window of {steady_window_s:g} s (solver.steady_window) in which drift and "
                                 f"scatter stay within {steady_tolerance:g} (solver.steady_tolerance) by "
                                 f"t = {end_time_s:.4g} s ({not_steady_fix})"})
    if failed:
        return "failed", flags
    names = [f["flag"] for f in flags]
    for name in _SEVERITY:
        if name in names:
            return name, flags
    return base_status, flags
