"""Tension post-processing (paper Sect. 2.6, Eq. 24: N = EA·ε) and the steady-state detector.

Pure numpy on nodal coordinates, so the same code serves live recording during a run and
post-processing of saved states; a test checks it against Exudyn's own ``ForceLocal`` output.
The strain is the ANCF cable's axial strain ε = |r'(x)| − 1 (paper Eq. 11), r' = ∂r/∂x along the
unstretched (material) coordinate x.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["axial_strain", "tension_at", "tension_profile", "profile_stations_m", "TensionStations", "SteadyState",
           "detect_steady_state", "hermite_derivative_weights"]


def hermite_derivative_weights(xi: np.ndarray, length_m: np.ndarray) -> np.ndarray:
    """Weights of [r_i, r'_i, r_j, r'_j] in ∂r/∂x at element coordinate ξ ∈ [0, 1].

    Returns shape (m, 4): derivatives of N1 = 1 − 3ξ² + 2ξ³, N2 = L(ξ − 2ξ² + ξ³),
    N3 = 3ξ² − 2ξ³, N4 = L(−ξ² + ξ³) with respect to x = ξL (paper Eqs. 5-6).
    """
    xi = np.asarray(xi, dtype=float)
    L = np.asarray(length_m, dtype=float)
    return np.stack([(-6 * xi + 6 * xi**2) / L, 1 - 4 * xi + 3 * xi**2,
                     (6 * xi - 6 * xi**2) / L, -2 * xi + 3 * xi**2], axis=-1)


def _locate(x_m, element_length_m):
    x_nodes = np.concatenate([[0.0], np.cumsum(element_length_m)])
    x = np.clip(np.asarray(x_m, dtype=float), 0.0, x_nodes[-1])
    e = np.clip(np.searchsorted(x_nodes, x, side="right") - 1, 0, len(element_length_m) - 1)
    xi = (x - x_nodes[e]) / element_length_m[e]
    return e, xi


class TensionStations:
    """Fixed material stations ``x_m`` [m] on a cable of element lengths ``element_length_m`` [m]:
    the elements and Hermite derivative weights found once, then the strain or tension of any
    state (the steady solve's history asks at every pseudo-time step)."""

    def __init__(self, element_length_m, x_m):
        Le = np.asarray(element_length_m, dtype=float)
        self.element, xi = _locate(x_m, Le)
        self.weights = hermite_derivative_weights(xi, Le[self.element])

    def strain(self, coordinates) -> np.ndarray:
        """ε = |∂r/∂x| − 1 [-] at the stations (see :func:`axial_strain`)."""
        q = np.asarray(coordinates, dtype=float).reshape(-1, 6)
        e, w = self.element, self.weights
        d = (w[:, 0, None] * q[e, :3] + w[:, 1, None] * q[e, 3:] + w[:, 2, None] * q[e + 1, :3]
             + w[:, 3, None] * q[e + 1, 3:])
        return np.linalg.norm(d, axis=1) - 1.0

    def tension(self, coordinates, axial_stiffness_N) -> np.ndarray:
        """N = EA·ε [N] at the stations (paper Eq. 24)."""
        return axial_stiffness_N * self.strain(coordinates)


def axial_strain(coordinates, element_length_m, x_m) -> np.ndarray:
    """Axial strain ε = |∂r/∂x| − 1 [-] at material stations ``x_m`` [m] from the trailing end.

    Parameters
    ----------
    coordinates : array_like (n_el + 1, 6)
        Absolute nodal coordinates ``[x, y, z, x', y', z']``.
    element_length_m : array_like (n_el,)
        Unstretched element lengths [m].
    x_m : array_like (m,)
        Stations along the cable [m]; an element's end node belongs to the next element.
    """
    return TensionStations(element_length_m, x_m).strain(coordinates)


def tension_at(coordinates, element_length_m, axial_stiffness_N, x_m) -> np.ndarray:
    """Axial force N = EA·ε [N] (paper Eq. 24) at stations ``x_m`` [m] from the trailing end."""
    return axial_stiffness_N * axial_strain(coordinates, element_length_m, x_m)


def profile_stations_m(element_length_m, points_per_element: int = 4) -> np.ndarray:
    """:func:`tension_profile`'s stations [m]: ``points_per_element`` + 1 per element including
    both ends."""
    Le = np.asarray(element_length_m, dtype=float)
    x_nodes = np.concatenate([[0.0], np.cumsum(Le)])
    xi = np.linspace(0.0, 1.0, points_per_element + 1)[:-1]
    x = (x_nodes[:-1, None] + xi[None, :] * Le[:, None]).ravel()
    return np.concatenate([x, [x_nodes[-1]]])


def tension_profile(coordinates, element_length_m, axial_stiffness_N, points_per_element: int = 4):
    """Tension along the whole cable: (x_m, tension_N) at ``points_per_element`` + 1 stations per
    element including both ends (the end node of each element evaluated from its left element)."""
    x = profile_stations_m(element_length_m, points_per_element)
    return x, tension_at(coordinates, element_length_m, axial_stiffness_N, x)


@dataclass(frozen=True)
class SteadyState:
    """A steady window of a force history.

    Attributes
    ----------
    steady : bool
        Whether a window satisfying both bounds was found.
    from_s : float
        Start of the steady window [s] (the last ``min_window_s`` when not steady).
    mean_N, std_N : float
        Mean and standard deviation of the force in the window [N].
    drift_N : float
        Change of the least-squares line across the window [N].
    """

    steady: bool
    from_s: float
    mean_N: float
    std_N: float
    drift_N: float


def _window_stats(t, f):
    mean = float(np.mean(f))
    std = float(np.std(f))
    if len(t) > 1 and t[-1] > t[0]:
        slope = np.polyfit(t - t[0], f, 1)[0]
        drift = float(slope * (t[-1] - t[0]))
    else:
        drift = 0.0
    return mean, std, drift


def detect_steady_state(time_s, force_N, min_window_s: float, rel_tolerance: float = 1e-3,
                        abs_tolerance_N: float = 1e-6, expected_drift_N_per_s: float = 0.0,
                        earliest_s: float = 0.0) -> SteadyState:
    """Find the longest final window in which the force is steady.

    A window [t0, t_end] is steady when it is at least ``min_window_s`` long and both the drift
    of a least-squares line across it and the standard deviation are below
    ``rel_tolerance·|mean| + abs_tolerance_N``. The earliest such t0 (scanned on the saved times)
    is returned, so the mean uses as much of the steady sliding as there is.

    ``expected_drift_N_per_s`` [N/s] is a drift the physics predicts (the cable leaving its conduit
    under gravity, :mod:`exucable.quasistatic.extent`): it is taken off the force before the tests, so a
    force that follows its moving reference is steady; the mean reported is of the force itself,
    and belongs to the window's mean time.

    ``earliest_s`` [s]: no window starts before it (the start-up damper's fade,
    ``solver.startup_time``: a start-up transient that happens to stay within the tolerance must
    not enter the mean).
    """
    t = np.asarray(time_s, dtype=float)
    f = np.asarray(force_N, dtype=float)
    if expected_drift_N_per_s and len(t):
        f = f - expected_drift_N_per_s * (t - t[-1])   # the force referred to the last time...
    if len(t) == 0:
        return SteadyState(False, float("nan"), float("nan"), float("nan"), float("nan"))
    t_end = t[-1]

    def ok(i0):
        mean, std, drift = _window_stats(t[i0:], f[i0:])
        if expected_drift_N_per_s:   # ...and the mean back to the window's own mean time
            mean += expected_drift_N_per_s * (float(np.mean(t[i0:])) - t[-1])
        bound = rel_tolerance * abs(mean) + abs_tolerance_N
        return abs(drift) <= bound and std <= bound, (mean, std, drift)

    last = int(np.searchsorted(t, t_end - min_window_s, side="right")) - 1
    last = max(last, 0)
    first = int(np.searchsorted(t, earliest_s * (1 - 1e-12), side="left"))  # earliest window start
    good, stats = ok(last)
    if t_end - t[last] < min_window_s * (1 - 1e-9) or not good or last < first:
        return SteadyState(False, float(t[last]), *stats)
    # extend the window backwards while it stays steady (coarse-to-fine scan over saved times)
    lo = last
    step = max(1, (last - first) // 64)
    while step >= 1:
        while lo - step >= first:
            g, st = ok(lo - step)
            if not g:
                break
            lo -= step
            stats = st
        step //= 2
    return SteadyState(True, float(t[lo]), *stats)
