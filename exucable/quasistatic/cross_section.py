"""Rigid circles at rest in a round duct's cross-section under lateral loads (no Exudyn).

The several cables' start (:func:`exucable.model.bundle.build_bundle_model`, ``start_path =
"statics"``) lays each cable where the statics of its cross-section puts it: n equal rigid circles of
radius r in the duct's circle of radius R, each pressed by its own lateral load per length p_i (the
rope equation's T_i κ n minus the weight's part across the tangent), frictionless between each other
and on the wall. The rest is a local minimum of the potential

    Π(x) = −Σ_i p_i·x_i + (k/2) Σ_i ⟨|x_i| − ρ⟩² + (k/2) Σ_{i<j} ⟨2r − |x_i − x_j|⟩²     (1)

with ρ = R − r, ⟨a⟩ = max(a, 0) and a penalty k large against the loads (the contacts close to
within ~1e-4 r). Each station is solved by Newton's method on (1) from the previous station's rest
(:func:`rest_along`, a continuation along the route): every step is limited to a quarter radius per
circle and must lower Π, so no circle passes through another and the circles' order and contacts
carry over from station to station, as the cables' do.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

__all__ = ["rest_in_duct", "rest_along", "separate_circles"]

#: Penalty in units of the station's largest load over the cable radius [-]: overlaps ~1e-4 r.
PENALTY = 1e4
#: Largest move of one circle per Newton step, in cable radii [-].
STEP_CAP = 0.25


@lru_cache(maxsize=8)
def _pairs(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The pairs i < j of n circles (``np.triu_indices(n, 1)``), kept: the start's build evaluates
    Eq. (1) tens of thousands of times, and making them anew was a third of its cost."""
    I, J = np.triu_indices(n, 1)
    I.flags.writeable = False
    J.flags.writeable = False
    return I, J


_EYE2 = np.eye(2)
_EYE2.flags.writeable = False


def _energy_parts(x, p, rho, d, k, spring, target, hessian=True):
    """Π of Eq. (1) (plus the centroid spring's (s/2)|x̄ − target|²), its gradient (n, 2) and
    Hessian (2n, 2n) at positions ``x`` (n, 2), all in cable radii and loads scaled to order one."""
    n = len(x)
    E = -float(np.sum(p * x))
    g = -p.copy()
    size = np.hypot(x[:, 0], x[:, 1])
    wall = size > rho
    I, J = _pairs(n)
    v = x[I] - x[J]
    dist = np.hypot(v[:, 0], v[:, 1])
    pair = dist < d
    over = size[wall] - rho
    gap = d - dist[pair]
    E += 0.5 * k * (float(over @ over) + float(gap @ gap))
    uw = x[wall] / size[wall][:, None]
    g[wall] += (k * over)[:, None] * uw
    up = v[pair] / np.maximum(dist[pair], 1e-12)[:, None]
    fp = (k * gap)[:, None] * up
    np.add.at(g, I[pair], -fp)
    np.add.at(g, J[pair], fp)
    if spring > 0.0:
        c = x.mean(axis=0) - target
        E += 0.5 * spring * float(c @ c)
        g += spring * c / n
    if not hessian:
        return E, g, None
    H = np.zeros((n, n, 2, 2))
    eye = _EYE2
    uu = uw[:, :, None] * uw[:, None, :]
    w_idx = np.nonzero(wall)[0]
    H[w_idx, w_idx] += k * (uu + (over / size[wall])[:, None, None] * (eye - uu))
    uu = up[:, :, None] * up[:, None, :]
    B = k * (uu - (gap / np.maximum(dist[pair], 1e-12))[:, None, None] * (eye - uu))
    Ip, Jp = I[pair], J[pair]
    np.add.at(H, (Ip, Ip), B)
    np.add.at(H, (Jp, Jp), B)
    np.add.at(H, (Ip, Jp), -B)
    np.add.at(H, (Jp, Ip), -B)
    if spring > 0.0:
        H += spring / (n * n) * eye
    return E, g, H.transpose(0, 2, 1, 3).reshape(2 * n, 2 * n)


def rest_in_duct(loads_N_per_m, duct_radius_m: float, cable_radius_m: float, start_m, centroid_m=None,
                 centroid_stiffness: float = 0.0, tolerance: float = 1e-6, max_steps: int = 400) -> tuple[np.ndarray, int]:
    """The rest of n frictionless rigid circles in the duct reached from ``start_m``: a local minimum of Eq. (1).

    Parameters
    ----------
    loads_N_per_m : array (n, 2)
        Each circle's lateral load per length [N/m] in the cross-section's (horizontal, up) axes.
    duct_radius_m, cable_radius_m : float
        R and r [m].
    start_m : array (n, 2)
        The circles' centres to start from [m] (the previous station's rest).
    centroid_m : array (2,), optional
        A place the circles' centroid is drawn to [m] by a spring of ``centroid_stiffness`` times the
        largest load over r (0: none): a cable's free span across the duct, held by its tension.
    tolerance : float
        Stop when the largest gradient entry is below this fraction of the largest load.

    Returns
    -------
    (centres [m] (n, 2), Newton steps taken)

    Newton's method with the Hessian's eigenvalues taken by magnitude and at least 1e-3 (a circle no
    contact holds moves along its load, a quarter radius per step), each step halved until Π falls.
    Loads of zero leave the circles where they are.
    """
    r = float(cable_radius_m)
    rho = float(duct_radius_m) / r - 1.0
    p = np.asarray(loads_N_per_m, dtype=float)
    scale = float(np.max(np.hypot(p[:, 0], p[:, 1])))
    x = np.array(start_m, dtype=float) / r
    if not scale > 0.0:
        return x * r, 0
    target = np.zeros(2) if centroid_m is None else np.asarray(centroid_m, dtype=float) / r
    spring = float(centroid_stiffness) if centroid_m is not None else 0.0
    x, steps = _descend(x, p / scale, rho, PENALTY * len(p), spring, target, tolerance, max_steps)
    return x * r, steps


def _descend(x, p, rho, k, spring, target, tolerance, max_steps):
    """Newton's steps on Π from ``x`` (radii), the Hessian's eigenvalues taken by magnitude and at
    least 1e-3, each step at most :data:`STEP_CAP` per circle and halved until Π falls: (x, steps)."""
    for step in range(max_steps):
        E, g, H = _energy_parts(x, p, rho, 2.0, k, spring, target)
        if np.max(np.abs(g)) < tolerance:
            return x, step
        w, V = np.linalg.eigh(H)
        dx = -(V @ ((V.T @ g.reshape(-1)) / np.maximum(np.abs(w), 1e-3 * k / (PENALTY * len(x))))).reshape(-1, 2)
        move = float(np.max(np.hypot(dx[:, 0], dx[:, 1])))
        if move > STEP_CAP:
            dx *= STEP_CAP / move
        for _ in range(40):
            E1 = _energy_parts(x + dx, p, rho, 2.0, k, spring, target, hessian=False)[0]
            if E1 <= E:
                break
            dx *= 0.5
        else:
            return x, step          # no descent left at round-off: a minimum
        x = x + dx
    return x, max_steps


def rest_along(loads_N_per_m, duct_radius_m: float, cable_radius_m: float, start_m, centroids_m=None,
               centroid_stiffness=0.0, stop_near=None, tolerance_m: float = 0.0) -> tuple[np.ndarray, int]:
    """Rests of :func:`rest_in_duct` at successive stations, each from the one before.

    Parameters
    ----------
    loads_N_per_m : array (m, n, 2)
        The circles' loads per station [N/m].
    start_m : array (n, 2)
        The circles' centres before the first station [m].
    centroids_m : array (m, 2), optional; centroid_stiffness : float or array (m,)
        Per station, as :func:`rest_in_duct`'s.
    stop_near : array (m, n, 2), optional
        Another continuation's rests [m]: stop at the first station where every circle is within
        ``tolerance_m`` of its place there (the two have met).

    Returns
    -------
    (rests [m] (m', n, 2), Newton steps): m' = m, or the meeting station's index + 1.
    Stations whose loads all vanish keep the previous rest.
    """
    P = np.asarray(loads_N_per_m, dtype=float)
    m = len(P)
    k = np.broadcast_to(np.asarray(centroid_stiffness, dtype=float), (m,))
    out = np.empty_like(P)
    x = np.array(start_m, dtype=float)
    steps = 0
    for i in range(m):
        x, taken = rest_in_duct(P[i], duct_radius_m, cable_radius_m, x,
                                None if centroids_m is None else centroids_m[i], float(k[i]))
        out[i] = x
        steps += taken
        if stop_near is not None and np.all(np.hypot(*(x - stop_near[i]).T) <= tolerance_m):
            return out[:i + 1], steps
    return out, steps


def separate_circles(centres_m, duct_radius_m: float, cable_radius_m: float) -> np.ndarray:
    """``centres_m`` (n, 2) [m] moved by descent on Eq. (1)'s penalty terms alone (steps of at most a
    quarter radius, so no circle is pushed through another) until no circle overlaps another or the
    wall by more than ~1e-6 r; admissible centres come back unchanged."""
    r = float(cable_radius_m)
    rho = float(duct_radius_m) / r - 1.0
    x = np.array(centres_m, dtype=float) / r
    x, _ = _descend(x, np.zeros_like(x), rho, 1.0, 0.0, None, 1e-6, 400)
    return x * r
