"""What several cables in one duct do in its cross-section: where each cable's axis crosses a
plane across the conduit, the arrangement that makes (triangular, cradled, side by side), the jam,
and the sidewall pressure per bend on the most loaded cable beside the calculators' formula.

Pure numpy on arrays (no Exudyn, no model objects): the cables' nodal coordinates, their element
lengths, the (pull-oriented) centreline.

Cross-section positions are (horizontal, up) offsets [m] from the duct's axis: ``up`` is the
vertical e_z without its part along the tangent (e_x for a vertical tangent), ``horizontal`` =
tangent × up (to the right, looking along the pull; the frame the cables are laid in). Where a cable crosses the plane through the centreline
point c(s) normal to the tangent t(s) is found on its cubic Hermite (ANCF) shape sampled densely,
so the chord's sag between nodes (L_e²/8R, millimetres in a 5 m bend with 0.5 m elements) does
not enter the positions.

Arrangements (rigid-circle geometry of three cables, radius r, duct inner radius R, ρ_w = R − r
the largest axis offset): a cable is *on the wall* if its axis is within ``tolerance``·r of ρ_w,
two cables *touch* if their axes are within 2r + ``tolerance``·r. For three cables

* ``triangular``: each cable touches both others, or one rides off the wall on two that do not
  touch each other and are not across the duct;
* ``cradled``: a chain a–m–b (m touches both) with all three on the wall;
* ``side_by_side``: a chain a–m–b across the duct, a and b on the wall on nearly opposite sides
  (their axes at least :data:`ACROSS_DEG` apart seen from the duct's axis) and m off the wall,
  held only by a and b: a keystone, the **jam** (Anixter, "7 tips for pulling cable": "Jamming is
  the wedging of three cables lying side by side in a conduit"). Rigid circles can do this only for
  about 2.4 ≤ D/d ≤ 3 (m must fit between a and b, and a–m–b must reach across), the range the
  calculators warn of (:data:`exucable.quasistatic.engineering.JAM_RANGE_D_OVER_d`);
* ``loose``: a chain in none of those formations (the middle one on the wall, an outer one off it);
* ``apart``: a cable touching no other.

Two cables: ``side_by_side`` (both on the wall, touching), ``stacked`` (touching, one off the
wall), ``apart``. Four: ``cradled`` (all on the wall), ``diamond`` (touching, not all on the
wall), ``apart``.
"""

from __future__ import annotations

import math

import numpy as np

from .pressure import windowed_load

__all__ = ["ACROSS_DEG", "CONTACT_TOLERANCE", "cross_section_frame", "frame_across", "cable_points", "cross_section_offsets",
           "classify_cross_section", "arrangement_sections", "bend_pressures", "jam_band_warning", "LAID_AT_POSITIONS",
           "laid_phrase"]

#: Gap, as a fraction of the cable radius, below which two surfaces count as touching [-]. Contact
#: acts at check points, not in every plane, and the kernel sees the other cable as the polyline of
#: its check points, whose chord sags spacing²/8R from the cable in a bend (a few per cent of r on
#: coarse meshes); the Hertz penetrations are ~1e-4 r.
CONTACT_TOLERANCE = 0.05
#: Angle between the outer cables of a chain, seen from the duct's axis, from which they are across
#: the duct (on nearly opposite sides) [deg]; the cradle of three at D/d = 3 spans 120°, a wedged
#: line 180° less the chain's sag.
ACROSS_DEG = 150.0
#: What a bundle laid at ``cable.positions`` is called where an arrangement's name would stand.
LAID_AT_POSITIONS = "laid at cable.positions"


def laid_phrase(bundle: dict) -> str:
    """How a bundle's cables were laid, from its summary (``summary["bundle"]``): the arrangement's
    name, or :data:`LAID_AT_POSITIONS` where ``positions_given``."""
    return LAID_AT_POSITIONS if bundle.get("positions_given") else bundle["arrangement"]


def cross_section_frame(centreline, s_m) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Tangent, horizontal and up unit vectors across the centreline at ``s_m``, each (m, 3)."""
    s = np.atleast_1d(np.asarray(s_m, dtype=float))
    t = np.asarray(centreline.tangent(s), dtype=float).reshape(-1, 3)
    return (t, *frame_across(t))


def frame_across(t) -> tuple[np.ndarray, np.ndarray]:
    """Unit (horizontal, up) axes across unit tangents ``t`` (m, 3): up = e_z without its tangential
    part (a vertical tangent takes e_x's instead), horizontal = t × up."""
    up = np.array([0.0, 0.0, 1.0])[None, :] - t[:, 2:3] * t
    norm = np.linalg.norm(up, axis=1)
    vertical = norm < 1e-6
    if np.any(vertical):
        alt = np.array([1.0, 0.0, 0.0])[None, :] - t[:, 0:1] * t
        up[vertical] = alt[vertical]
        norm = np.linalg.norm(up, axis=1)
    up /= norm[:, None]
    return np.cross(t, up), up


def cable_points(coordinates, element_length_m, per_element: int = 32) -> np.ndarray:
    """Points on one cable's cubic Hermite (ANCF) axis [m], ``per_element`` per element plus the
    last node, shape (n_el·per_element + 1, 3), from its nodal coordinates (n_el + 1, 6)."""
    q = np.asarray(coordinates, dtype=float).reshape(-1, 6)
    Le = np.asarray(element_length_m, dtype=float).reshape(-1)
    xi = np.arange(per_element) / per_element
    S1, S2 = 1 - 3 * xi**2 + 2 * xi**3, xi - 2 * xi**2 + xi**3
    S3, S4 = 3 * xi**2 - 2 * xi**3, -xi**2 + xi**3
    r0, d0, r1, d1 = q[:-1, None, :3], q[:-1, None, 3:], q[1:, None, :3], q[1:, None, 3:]
    L = Le[:, None, None]
    pts = (S1[None, :, None] * r0 + S2[None, :, None] * L * d0 + S3[None, :, None] * r1
           + S4[None, :, None] * L * d1)
    return np.concatenate([pts.reshape(-1, 3), q[-1:, :3]], axis=0)


def cross_section_offsets(cables, element_length_m, centreline, s_m, per_element: int = 32) -> np.ndarray:
    """Where each cable's axis crosses the planes across the centreline at ``s_m`` [m]:
    (horizontal, up) offsets from the duct's axis [m], shape (len(s_m), n_cables, 2); NaN where a
    cable does not reach the plane. Of several crossings (a coil's turns) the one nearest the
    centreline point is taken."""
    s = np.atleast_1d(np.asarray(s_m, dtype=float))
    c = np.asarray(centreline.point(s), dtype=float).reshape(-1, 3)
    t, h, up = cross_section_frame(centreline, s)
    out = np.full((s.size, len(cables), 2), np.nan)
    for k, q in enumerate(cables):
        P = cable_points(q, element_length_m, per_element)
        for i in range(s.size):
            f = (P - c[i]) @ t[i]
            j = np.nonzero((f[:-1] <= 0.0) & (f[1:] > 0.0) | (f[:-1] > 0.0) & (f[1:] <= 0.0))[0]
            if j.size == 0:
                continue
            a = f[j] / (f[j] - f[j + 1])
            x = P[j] + a[:, None] * (P[j + 1] - P[j]) - c[i]
            best = int(np.argmin(np.linalg.norm(x, axis=1)))
            out[i, k] = (x[best] @ h[i], x[best] @ up[i])
    return out


def classify_cross_section(offsets_m, inner_radius_m: float, cable_radius_m: float,
                           tolerance: float = CONTACT_TOLERANCE) -> dict:
    """The arrangement of the cables in one cross-section (module docstring).

    Parameters
    ----------
    offsets_m : array_like (n_cables, 2)
        Each cable's axis, (horizontal, up) from the duct's axis [m].
    inner_radius_m, cable_radius_m : float
        R and r [m].
    tolerance : float
        Gap as a fraction of r that still counts as contact [-].

    Returns
    -------
    dict
        ``arrangement`` (str), ``wedged`` (bool: three cables side by side across the duct, the
        middle one held off the wall by the outer two), ``on_wall`` (list of bool, per cable),
        ``touching`` (list of [i, j] pairs, 1-based cable numbers).
    """
    p = np.asarray(offsets_m, dtype=float).reshape(-1, 2)
    n = len(p)
    r = cable_radius_m
    rho_w = inner_radius_m - r
    on_wall = np.hypot(p[:, 0], p[:, 1]) >= rho_w - tolerance * r
    dist = np.hypot(*(p[:, None, :] - p[None, :, :]).transpose(2, 0, 1))
    touch = (dist <= 2.0 * r + tolerance * r) & ~np.eye(n, dtype=bool)
    pairs = [[i + 1, j + 1] for i in range(n) for j in range(i + 1, n) if touch[i, j]]
    label, wedged = "apart", False
    if n == 2:
        if touch[0, 1]:
            label = "side_by_side" if on_wall.all() else "stacked"
    elif n == 3:
        degree = touch.sum(axis=1)
        if degree.min() == 2:
            label = "triangular"
        elif sorted(degree) == [1, 1, 2]:
            m = int(np.argmax(degree))
            a, b = [i for i in range(3) if i != m]
            cos_ab = float(p[a] @ p[b]) / max(float(np.linalg.norm(p[a]) * np.linalg.norm(p[b])), 1e-300)
            spread = math.degrees(math.acos(min(1.0, max(-1.0, cos_ab))))
            if on_wall.all():
                label = "cradled"
            elif on_wall[a] and on_wall[b] and spread >= ACROSS_DEG:
                label, wedged = "side_by_side", True
            elif not on_wall[m]:
                label = "triangular"
            else:
                label = "loose"
    elif n == 4:
        # connected through contacts: every cable reaches every other
        reach = touch | np.eye(n, dtype=bool)
        for _ in range(n):
            reach = reach | (reach.astype(int) @ reach.astype(int) > 0)
        if reach.all():
            label = "cradled" if on_wall.all() else "diamond"
    return {"arrangement": label, "wedged": bool(wedged), "on_wall": [bool(x) for x in on_wall], "touching": pairs}


def arrangement_sections(pieces, cables, element_length_m, centreline, inner_radius_m: float,
                         cable_radius_m: float, s_range_m, stations_per_section: int = 9,
                         reverse: bool = False) -> list[dict]:
    """The arrangement found along each straight and bend inside the cables' extent.

    Each piece of the (pull-oriented) centreline within ``s_range_m`` = (from, to) [m] is sampled
    at ``stations_per_section`` planes spread over its part inside that range (its ends excluded);
    ``reverse``: the pull runs against the scenario's conduit (rows and places are the scenario's).

    Returns
    -------
    list of dict
        Per piece: ``section`` (1-based, scenario order), ``kind`` ("straight", "bend", "helix"),
        ``s_conduit_start_m``, ``s_conduit_end_m``, ``arrangement`` (the most frequent over its
        stations), ``arrangements_seen`` (each label with its count of stations),
        ``jam`` (any station wedged), ``jam_s_conduit_m`` (the first such, along the pull; None).
    """
    lo, hi = s_range_m
    L = pieces[-1].s_end_m
    to_conduit = (lambda x: L - x) if reverse else (lambda x: x)
    rows = []
    for k, piece in enumerate(pieces):
        a, b = max(piece.s_start_m, lo), min(piece.s_end_m, hi)
        if b - a <= 0.0:
            continue
        s = a + (b - a) * (np.arange(stations_per_section) + 0.5) / stations_per_section
        offs = cross_section_offsets(cables, element_length_m, centreline, s)
        labels, jam_at = [], None
        for i in range(s.size):
            if np.isnan(offs[i]).any():
                continue
            c = classify_cross_section(offs[i], inner_radius_m, cable_radius_m)
            labels.append(c["arrangement"])
            if c["wedged"] and jam_at is None:
                jam_at = float(to_conduit(s[i]))
        if not labels:
            continue
        seen = {lab: labels.count(lab) for lab in sorted(set(labels))}
        kind = "straight" if not piece.is_curved else ("helix" if getattr(piece, "pitch_m", 0.0) else "bend")
        s0, s1 = sorted((float(to_conduit(piece.s_start_m)), float(to_conduit(piece.s_end_m))))
        rows.append({"section": len(pieces) - k if reverse else k + 1, "kind": kind, "s_conduit_start_m": s0, "s_conduit_end_m": s1,
                     "arrangement": max(seen, key=seen.get), "arrangements_seen": seen,
                     "jam": jam_at is not None, "jam_s_conduit_m": jam_at})
    return sorted(rows, key=lambda row: row["section"])


def bend_pressures(pieces, cable_points_s_m, cable_points_force_N, cable_tension_out_N, window_m: float,
                   sidewall_factor: float, bending_stiffness_N_m2: float = 0.0, reverse: bool = False) -> list[dict]:
    """Sidewall pressure per bend on the most loaded cable beside the calculators' formula.

    Parameters
    ----------
    pieces : sequence
        The pull-oriented centreline's pieces.
    cable_points_s_m, cable_points_force_N : sequence of arrays
        Per cable: its check points' places along the pull-oriented centreline [m] and wall normal
        forces [N].
    cable_tension_out_N : callable
        s [m] → the bundle's tension there (the sum over the cables) [N].
    window_m : float
        The pressure window w [m] (:func:`exucable.post.pressure.default_window_m`).
    sidewall_factor : float
        The calculators' factor on T/R for the most loaded cable
        (:func:`exucable.quasistatic.engineering.sidewall_pressure_factor`).
    bending_stiffness_N_m2 : float
        EJ of one cable [N m²]: the bend body leaves out w/2 + 3√(EJ/T) at each end.
    reverse : bool
        The pull runs against the scenario's conduit (rows and places are the scenario's).

    Returns
    -------
    list of dict
        Per bend (scenario order): ``bend``, ``s_conduit_start_m``, ``s_conduit_end_m``, ``radius_m``,
        ``angle_deg``, ``tension_out_N`` (the bundle's, at the bend's exit along the pull),
        ``most_loaded_cable`` (1-based), ``peak_pressure_N_per_m`` and ``mean_pressure_N_per_m``
        (that cable's windowed pressure: its peak over the bend, its mean over the bend's body;
        NaN if the body is empty), ``formula_pressure_N_per_m`` (factor × T_out/R, the
        calculators' on the simulated T_out), ``peak_vs_formula`` (peak / formula − 1).
    """
    bends = [(i, p) for i, p in enumerate(pieces) if p.is_curved]
    L = pieces[-1].s_end_m
    to_conduit = (lambda x: L - x) if reverse else (lambda x: x)
    rows = []
    for k, (i, p) in enumerate(bends):
        s0, s1, R = p.s_start_m, p.s_end_m, p.radius_of_curvature_m
        T_out = float(cable_tension_out_N(s1))
        grid = np.linspace(s0, s1, 201)
        lam = math.sqrt(bending_stiffness_N_m2 / max(T_out, 1e-12)) if bending_stiffness_N_m2 > 0 else 0.0
        margin = 0.5 * window_m + 3.0 * lam
        body = (grid >= s0 + margin) & (grid <= s1 - margin)
        best = None
        for c, (s_pts, f_pts) in enumerate(zip(cable_points_s_m, cable_points_force_N)):
            pw = windowed_load(s_pts, f_pts, window_m, grid)
            peak = float(np.max(pw))
            if best is None or peak > best[1]:
                best = (c, peak, float(np.mean(pw[body])) if body.any() else float("nan"))
        formula = sidewall_factor * T_out / R
        a, b = sorted((float(to_conduit(s0)), float(to_conduit(s1))))
        rows.append({"bend": k + 1, "s_conduit_start_m": a, "s_conduit_end_m": b, "radius_m": R,
                     "angle_deg": math.degrees(p.turning_angle_rad), "tension_out_N": T_out,
                     "most_loaded_cable": best[0] + 1, "peak_pressure_N_per_m": best[1],
                     "mean_pressure_N_per_m": best[2], "formula_pressure_N_per_m": formula,
                     "peak_vs_formula": best[1] / formula - 1.0 if formula > 0 else float("nan")})
    if reverse:       # the bends in the scenario's order
        rows = rows[::-1]
        for k, row in enumerate(rows):
            row["bend"] = k + 1
    return rows


def jam_band_warning(count: int, duct_over_cable_diameter: float, friction: float, bends: bool) -> str | None:
    """One sentence when ``count`` = 3 cables at this D/d [-] could wedge: a keystone across the duct
    stands on a wall of friction ``friction`` [-] (the static one where given) in the band of
    :func:`exucable.quasistatic.bundle_jam.wedge_band_d_over_D`, widened by a bend's ovality where
    the route ``bends``; None outside it. The steady sliding state never shows the keystone (its
    friction acts along the slip, :mod:`exucable.quasistatic.bundle_jam`), so a run there says so
    rather than a silent "ok"."""
    from ..quasistatic.bundle_jam import BEND_OVALITY, wedge_band_d_over_D

    if count != 3 or not friction > 0.0:
        return None
    lo, hi = wedge_band_d_over_D(friction, BEND_OVALITY if bends else 0.0)
    r = float(duct_over_cable_diameter)
    if not lo <= r <= hi:
        return None
    return (f"D/d = {r:.3g}: three cables that stop here can wedge side by side across the duct (a keystone stands "
            f"on a wall of friction {friction:g} for D/d {lo:.3g}-{hi:.3g}{', bends 5 % oval' if bends else ''}); the "
            "steady sliding state cannot show it (sliding friction acts along the slip); fix: keep the pull moving, "
            "a duct outside that band (conduit.inner_radius), or the cables bound as a trefoil")
