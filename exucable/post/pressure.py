"""Sidewall bearing pressure an engineer can use: windowed along the route, point loads at bend
ends, and a per-bend table beside the rope's.

The contact check points carry forces [N] at their places s along the conduit. Their force per
element share (``contact_profile.csv``) is a row of spikes when elements touch a bend near their
nodes, and its maximum grows under refinement where bending stiffness concentrates the load at a
bend's ends. Engineering quantities that converge are

* the **windowed pressure** p̄(s) = (sum of the normal forces of the check points within
  s ± w/2) / w [N/m], with a window w stated in the summary (``pressure_window_m``), by default
  half the tightest bend radius (at least a few elements of the mesh rule, so the spikes average
  out, and short enough to follow T/R along a bend); the rope's pressure (T/R and the weight)
  is windowed the same way for comparison;
* the **point load** at each bend end [N] with its place: the concentrated load of a stiff cable
  landing on a bend's wall after lifting off over about a bending length λ = √(EJ/T)
  (Iordanescu & Tamowski's PULLFLEX adds it to the rope). Beyond the bend-end gap (the free span,
  no load) the cable's load is modelled as a point load P at a place e plus the body's
  distributed pressure q(s) from e on — the beam-on-wall solution of :mod:`exucable.quasistatic.stiff_bend`.
  Over a capture window of length H ≈ 2λ + 3 L_e from the first loaded check point s_on (the
  mesh spreads the concentration over about three elements L_e), the check points' load and its
  first moment about the window's far end s_H fix P and e: M0 = P + ∫_e^{s_H} q ds,
  M1 = P |s_H − e| + ∫_e^{s_H} |s_H − s| q ds, with q the rope's pressure scaled by the cable's
  own tension at that place. Both moments converge under
  refinement where the raw peak does not (it grows as the elements shrink). Where no gap
  precedes the loaded zone (the lift-off is shorter than the check-point spacing, EJ → 0), P is
  the excess of the cable's load over that scaled pressure across ±w/2 of the bend's end.
  (The excess of the cable's load over the *rope's* across a window is no point load: it is
  zero at first order in λ/R, since P replaces the pressure of the lifted-off stretch.)

The *body* of a bend is the bend less w/2 + 3 λ at each end (λ = √(EJ/T), the bending length,
over which the end loads decay); its mean windowed pressure is the number to set against T/R.
Pure numpy; no Exudyn.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["BEND_COLUMNS", "PRESSURE_COLUMNS", "default_window_m", "windowed_load", "bend_table",
           "bend_end_point_load", "pressure_profile", "sorted_point_loads"]

BEND_COLUMNS = ("bend", "s_conduit_start_m", "s_conduit_end_m", "radius_m", "angle_deg", "tension_in_N", "tension_out_N",
                "rope_tension_in_N", "rope_tension_out_N", "mean_pressure_N_per_m", "peak_pressure_N_per_m",
                "rope_mean_pressure_N_per_m", "rope_peak_pressure_N_per_m", "mean_pressure_vs_rope",
                "entry_point_load_N", "entry_s_conduit_m", "exit_point_load_N", "exit_s_conduit_m",
                "point_loads_resolved")
PRESSURE_COLUMNS = ("s_conduit_m", "windowed_pressure_N_per_m", "rope_windowed_pressure_N_per_m")


def default_window_m(centreline) -> float:
    """w = half the tightest bend radius [m]; on a route without bends, a twentieth of its length."""
    radii = [p.radius_of_curvature_m for p in centreline.pieces if p.is_curved]
    return 0.5 * min(radii) if radii else centreline.length_m / 20.0


def sorted_point_loads(s_m, force_N) -> tuple[np.ndarray, np.ndarray]:
    """The points' places ``s_m`` in increasing order [m] and the running sums of their forces
    ``force_N`` in that order [N], a zero first: what :func:`windowed_load`, :func:`pressure_profile`
    and :func:`bend_table` sum over. A caller with both tables to make sorts once and passes the
    pair to each as ``sorted_loads`` (a steady state's 929k check points at 10 km, 10 ms a sort)."""
    s, f = np.asarray(s_m, dtype=float), np.asarray(force_N, dtype=float)
    # points in strictly increasing order (the run's check points come sorted) have one sorting
    # permutation, the identity; with ties argsort's own order of them decides the sums' rounding
    if not np.all(s[1:] > s[:-1]):
        order = np.argsort(s_m)
        s, f = s[order], f[order]
    c = np.empty(len(s) + 1)
    c[0] = 0.0
    np.cumsum(f, out=c[1:])
    return s, c


def _load_between(s_sorted, cum, a, b):
    """Sum of the point forces with a < s ≤ b [N] (arrays a, b)."""
    return cum[np.searchsorted(s_sorted, b, side="right")] - cum[np.searchsorted(s_sorted, a, side="right")]


def _rope_cumulative(rope_s_m, rope_pressure_N_per_m):
    order = np.argsort(rope_s_m)
    s = np.asarray(rope_s_m, dtype=float)[order]
    p = np.asarray(rope_pressure_N_per_m, dtype=float)[order]
    c = np.concatenate([[0.0], np.cumsum(0.5 * (p[1:] + p[:-1]) * np.diff(s))])
    return s, c


def _rope_between(s, c, a, b):
    return np.interp(b, s, c) - np.interp(a, s, c)


def windowed_load(s_m, force_N, window_m: float, at_m, sorted_loads=None) -> np.ndarray:
    """p̄(s) = (sum of point forces within s ± w/2) / w [N/m] at ``at_m``; ``sorted_loads``:
    :func:`sorted_point_loads` of ``s_m``, ``force_N``, if made."""
    s, c = sorted_point_loads(s_m, force_N) if sorted_loads is None else sorted_loads
    at = np.asarray(at_m, dtype=float)
    return _load_between(s, c, at - window_m / 2, at + window_m / 2) / window_m


def pressure_profile(s_m, force_N, rope_s_m, rope_pressure_N_per_m, window_m: float, length_m: float,
                     sorted_loads=None) -> dict:
    """Windowed pressure of the cable and of the rope on a grid of w/10 along [0, L] [N/m];
    ``sorted_loads``: :func:`sorted_point_loads` of ``s_m``, ``force_N``, if made."""
    grid = np.linspace(0.0, length_m, max(21, int(np.ceil(10 * length_m / window_m)) + 1))
    rs, rc = _rope_cumulative(rope_s_m, rope_pressure_N_per_m)
    lo, hi = np.clip(grid - window_m / 2, 0.0, length_m), np.clip(grid + window_m / 2, 0.0, length_m)
    return {"s_conduit_m": grid, "windowed_pressure_N_per_m": windowed_load(s_m, force_N, window_m, grid, sorted_loads),
            "rope_windowed_pressure_N_per_m": _rope_between(rs, rc, lo, hi) / window_m}


def _cumtrapz(y, x):
    return np.concatenate([[0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(x))])


def bend_end_point_load(s_m, force_N, s_end_m: float, inward: int, pressure_N_per_m, bending_length_m: float,
                        element_length_m: float, window_m: float, max_capture_m: float | None = None,
                        s_sorted: bool = False) -> tuple[float, float]:
    """The point load at one end of a bend and its place (module docstring): (P [N], e [m]).

    Parameters
    ----------
    s_m, force_N : ndarray
        Check points' places along the conduit [m], sorted, and their normal forces [N].
    s_end_m : float
        The bend's end [m].
    inward : {+1, -1}
        +1 when the bend lies at s > s_end_m (its start), −1 at its end.
    pressure_N_per_m : callable
        q(s), the body's distributed pressure [N/m] (vectorised).
    bending_length_m : float
        λ = √(EJ/T) at this end [m].
    element_length_m : float
        L_e [m]: the mesh spreads the concentration over about three elements.
    window_m : float
        w [m], for the fallback without a gap.
    max_capture_m : float, optional
        Upper bound of the capture window H, and how far inside the bend the landing is looked
        for (half the bend, so both ends stay apart).
    s_sorted : bool
        The caller has checked that ``s_m`` increases (:func:`bend_table`, once for all its bends'
        ends instead of once per end: a pass over every check point of the route).
    """
    s = np.asarray(s_m, dtype=float)
    F = np.asarray(force_N, dtype=float)
    H = 2.0 * bending_length_m + 3.0 * element_length_m
    if max_capture_m is not None:
        H = min(H, max_capture_m)
    # from the bend's body (half its length in) outwards: the cable may land well inside the bend
    # (a free span across the clearance under gravity)
    inside = max_capture_m if max_capture_m is not None else bending_length_m + H
    s, F = _near_end(s, F, s_end_m, max(H + bending_length_m + window_m / 2, inside + H, window_m / 2), s_sorted)
    u = inward * (s - s_end_m)                       # > 0 inside the bend
    near = np.flatnonzero((u >= -(H + bending_length_m + window_m / 2)) & (u <= inside))
    near = near[np.argsort(-u[near])]
    loaded = F[near] > 1e-12 * max(float(F[near].max()) if near.size else 0.0, 1e-300)
    # the first gap: three unloaded points in a row (a real gap, not one grazing point); the cable
    # lands at the last loaded point before it
    unloaded = ~loaded
    gaps = np.flatnonzero(unloaded[:-2] & unloaded[1:-1] & unloaded[2:])
    on = None
    if gaps.size:
        before = np.flatnonzero(loaded[:gaps[0]])
        on = int(near[before[-1]]) if before.size else None
    if on is None:                                    # no lift-off resolved: the excess over q across ±w/2
        a = window_m / 2
        sel = np.abs(s - s_end_m) <= a
        grid = np.linspace(s_end_m - a, s_end_m + a, 401)
        return float(F[sel].sum() - _cumtrapz(pressure_N_per_m(grid), grid)[-1]), float(s_end_m)
    u_on = u[on]
    sel = (u >= u_on - 1e-12) & (u <= u_on + H)
    beyond = u[u > u_on + H]
    # the window ends between its last check point and the next, where their shares meet
    u_end = 0.5 * (u[sel].max() + beyond.min()) if beyond.size else u[sel].max()
    H = u_end - u_on
    # moments about the window's far end z = u_end − u, where the window cuts through the body's
    # pressure (a cut there weighs z ≈ 0; the near end lies in the gap, where nothing is cut)
    z_pts = u_end - u[sel]
    M0 = float(F[sel].sum())
    M1 = float((F[sel] * z_pts).sum())
    z = np.linspace(0.0, H, 801)
    q = pressure_N_per_m(s_end_m + inward * (u_end - z))
    Q = _cumtrapz(q, z)                               # ∫_0^z q
    Q1 = _cumtrapz(q * z, z)                          # ∫_0^z z' q
    f = (M0 - Q) * z + Q1 - M1                        # zero at the place of P (M0 = P + Q, M1 = P z + Q1)
    k = np.flatnonzero((f[:-1] <= 0.0) & (f[1:] > 0.0))
    if not k.size:
        ze = H
    else:
        i = int(k[-1])
        ze = z[i] + (z[i + 1] - z[i]) * (-f[i]) / (f[i + 1] - f[i])
    P = M0 - float(np.interp(ze, z, Q))
    return P, float(s_end_m + inward * (u_end - ze))


def _near_end(s, F, s_end_m: float, reach_m: float, s_sorted: bool = False):
    """The sorted points ``s`` [m] (forces ``F``) within ``reach_m`` of ``s_end_m``, and one more
    on each side: all that :func:`bend_end_point_load` looks at (its selections lie within the
    reach; the first point past its window is at most the next one out), as contiguous slices, so
    that its sums run over the same numbers in the same order as over the whole route (Example 4:
    78 400 points on the route, a few thousand near an end). Unsorted input is returned whole;
    ``s_sorted``: the caller knows ``s`` increases."""
    if s.size < 2 or not (s_sorted or np.all(s[1:] >= s[:-1])):
        return s, F
    margin = reach_m * (1.0 + 1e-9) + 1e-9          # beyond the rounding of u = ±(s − s_end)
    i0 = max(int(np.searchsorted(s, s_end_m - margin, side="left")) - 1, 0)
    i1 = int(np.searchsorted(s, s_end_m + margin, side="right")) + 1
    return s[i0:i1], F[i0:i1]


@dataclass(frozen=True)
class _Piece:
    s0: float
    s1: float
    radius: float
    angle_deg: float


def bend_table(pieces, s_m, force_N, cable_s_m, cable_tension_N, rope_s_m, rope_tension_N,
               rope_pressure_N_per_m, window_m: float, bending_length_m: float,
               direction: str = "forward", bending_stiffness_N_m2: float | None = None,
               element_length_m: float = 0.0, sorted_loads=None) -> list[dict]:
    """One row per bend/helix of the route (columns :data:`BEND_COLUMNS`).

    Parameters
    ----------
    pieces : sequence
        The scenario's centreline pieces (``is_curved``, ``s_start_m``, ``s_end_m``,
        ``radius_of_curvature_m``, ``turning_angle_rad``).
    s_m, force_N : array_like
        Check points' places along the scenario's conduit [m] and normal forces [N].
    cable_s_m, cable_tension_N : array_like
        The cable's tension [N] at places along the conduit [m].
    rope_s_m, rope_tension_N, rope_pressure_N_per_m : array_like
        The rope reference along the conduit.
    window_m : float
        w [m].
    bending_length_m : float
        λ = √(EJ/T) [m].
    direction : str
        ``"forward"``: the cable enters a bend at its start; ``"reverse"``: at its end.
    bending_stiffness_N_m2 : float, optional
        EJ [N m²]: each end's bending length √(EJ/T) from the cable's tension there (default:
        ``bending_length_m`` at both).
    element_length_m : float
        L_e [m] (the point loads' capture window, :func:`bend_end_point_load`).
    sorted_loads : tuple, optional
        :func:`sorted_point_loads` of ``s_m``, ``force_N``, if made.
    """
    s_pts, cum = sorted_point_loads(s_m, force_N) if sorted_loads is None else sorted_loads
    f_pts = np.diff(cum)                             # the forces in the order of s_pts
    s_sorted = bool(s_pts.size < 2 or np.all(s_pts[1:] >= s_pts[:-1]))   # argsort's order: NaN would break it
    rs, rc = _rope_cumulative(rope_s_m, rope_pressure_N_per_m)
    ro = np.argsort(rope_s_m)
    rope_T = (np.asarray(rope_s_m, dtype=float)[ro], np.asarray(rope_tension_N, dtype=float)[ro])
    rope_p = np.asarray(rope_pressure_N_per_m, dtype=float)[ro]
    co = np.argsort(cable_s_m)
    cab_T = (np.asarray(cable_s_m, dtype=float)[co], np.asarray(cable_tension_N, dtype=float)[co])
    a = window_m / 2

    def body_pressure(x):
        """The rope's pressure scaled by the cable's own tension over the rope's there [N/m]; 0
        where the rope is slack (no load: its pressure is 0 and the scale undefined)."""
        t_rope = np.interp(x, *rope_T)
        scale = np.divide(np.interp(x, *cab_T), t_rope, out=np.zeros_like(t_rope), where=t_rope > 0.0)
        return np.interp(x, rope_T[0], rope_p) * scale

    rows = []
    bends = [_Piece(p.s_start_m, p.s_end_m, p.radius_of_curvature_m, float(np.degrees(p.turning_angle_rad)))
             for p in pieces if p.is_curved]
    for k, b in enumerate(bends, start=1):
        grid = np.linspace(b.s0 - a, b.s1 + a, 201)
        p_w = _load_between(s_pts, cum, grid - a, grid + a) / window_m     # windowed_load, sorted once
        r_w = _rope_between(rs, rc, grid - a, grid + a) / window_m
        margin = a + 3.0 * bending_length_m
        body = (grid >= b.s0 + margin) & (grid <= b.s1 - margin)
        mean = float(np.mean(p_w[body])) if body.any() else float("nan")
        rope_mean = float(np.mean(r_w[body])) if body.any() else float("nan")
        ends, lams = {}, []
        for name, s_end, inward in (("start", b.s0, 1), ("end", b.s1, -1)):
            T_here = float(np.interp(s_end, *cab_T))
            lam = bending_length_m if bending_stiffness_N_m2 is None else float(
                np.sqrt(bending_stiffness_N_m2 / max(T_here, 1e-12)))
            lams.append(lam)
            ends[name] = bend_end_point_load(s_pts, f_pts, s_end, inward, body_pressure, lam,
                                             element_length_m, window_m, max_capture_m=0.5 * (b.s1 - b.s0),
                                             s_sorted=s_sorted)
        t_start = (float(np.interp(b.s0, *cab_T)), float(np.interp(b.s1, *cab_T)))
        r_start = (float(np.interp(b.s0, *rope_T)), float(np.interp(b.s1, *rope_T)))
        entry, exit_ = ("start", "end") if direction == "forward" else ("end", "start")
        flip = (lambda x: x) if direction == "forward" else (lambda x: x[::-1])
        rows.append({
            "bend": k, "s_conduit_start_m": b.s0, "s_conduit_end_m": b.s1, "radius_m": b.radius, "angle_deg": b.angle_deg,
            "tension_in_N": flip(t_start)[0], "tension_out_N": flip(t_start)[1],
            "rope_tension_in_N": flip(r_start)[0], "rope_tension_out_N": flip(r_start)[1],
            "mean_pressure_N_per_m": mean, "peak_pressure_N_per_m": float(np.max(p_w)),
            "rope_mean_pressure_N_per_m": rope_mean, "rope_peak_pressure_N_per_m": float(np.max(r_w)),
            "mean_pressure_vs_rope": mean / rope_mean - 1.0 if rope_mean > 0 else float("nan"),
            "entry_point_load_N": ends[entry][0], "entry_s_conduit_m": ends[entry][1],
            "exit_point_load_N": ends[exit_][0], "exit_s_conduit_m": ends[exit_][1],
            # elements longer than 2λ cannot bend over the lift-off: the point loads are then the
            # mesh's, not converged (measured on route100_4bends, reference/README.md)
            "point_loads_resolved": bool(element_length_m <= 2.0 * min(lams)),
        })
    return rows
