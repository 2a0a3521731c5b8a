"""Tension post-processing (paper Sect. 2.6, Eq. 24) and the steady-state detector.

Pure numpy on nodal coordinates, so the same code serves live recording during a run and
post-processing of saved states. Two readings of the axial force: N = EA·ε of the ANCF cable's axial
strain ε = |r'(x)| − 1 (paper Eq. 11; r' = ∂r/∂x along the unstretched, material coordinate x; a test
checks it against Exudyn's own ``ForceLocal`` output), and :func:`equilibrium_tension`, the one the
results report, from the balance of the cable's loads (EA·ε spikes next to the point loads at bend ends).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

__all__ = ["axial_strain", "tension_at", "tension_profile", "profile_stations_m", "TensionStations", "SteadyState",
           "CableLoads", "equilibrium_tension", "load_imbalance_N", "check_point_forces_N", "hermite_integral_weights",
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


def hermite_integral_weights(xi: np.ndarray, length_m: np.ndarray) -> np.ndarray:
    """Weights of [r_i, r'_i, r_j, r'_j] in ∫₀^{ξL} r dx, the integral of the position from the
    element's start to element coordinate ξ ∈ [0, 1] (antiderivatives of N1…N4 of
    :func:`hermite_derivative_weights`, times L). Shape (m, 4) [m, m²]."""
    xi = np.asarray(xi, dtype=float)
    L = np.asarray(length_m, dtype=float)
    return np.stack([L * (xi - xi**3 + 0.5 * xi**4), L * L * (0.5 * xi**2 - 2.0 / 3.0 * xi**3 + 0.25 * xi**4),
                     L * (xi**3 - 0.5 * xi**4), L * L * (-xi**3 / 3.0 + 0.25 * xi**4)], axis=-1)


@dataclass(frozen=True)
class CableLoads:
    """Every external force on a cable at one state, for :func:`equilibrium_tension`.

    Attributes
    ----------
    point_x_m : ndarray (p,)
        Material coordinates of concentrated loads (the contact check points) [m].
    point_force_N : ndarray (p, 3)
        Their forces on the cable [N] (contact normal force and friction).
    node_force_N : ndarray (n_el + 1, 3)
        Forces on the nodes' positions [N] (dampers, a guide), zeros when none.
    line_load_N_per_m : ndarray (3,)
        A uniform load per unit of material length [N/m] (the weight ρA·g).
    mass_per_length_kg_per_m : float
        ρA [kg/m], for the inertia −ρA·r̈ of ``acceleration``.
    acceleration : ndarray (n_el + 1, 6) or None
        Nodal accelerations [m/s², 1/s²] (None: a static state).
    trailing_force_N, leading_force_N : ndarray (3,) or None
        The force on the cable's trailing (x = 0) and leading (x = L) end [N] (back tension, the
        rig's reaction); None where the end's force is not known.
    """

    point_x_m: np.ndarray
    point_force_N: np.ndarray
    node_force_N: np.ndarray
    line_load_N_per_m: np.ndarray
    mass_per_length_kg_per_m: float
    acceleration: np.ndarray | None
    trailing_force_N: np.ndarray | None
    leading_force_N: np.ndarray | None

    @cached_property
    def point_forces_summed(self) -> tuple[np.ndarray, np.ndarray]:
        """The concentrated loads' places in increasing order [m], shape (p,), and the running sums
        of their forces in that order [N], shape (p + 1, 3), a zero row first: the check points' part
        of G(x) (:func:`equilibrium_tension`), sorted and summed once for every station asked (the
        tension profile, the nodes' tension and the snapshot read one steady state's loads)."""
        x, f = self.point_x_m, self.point_force_N
        if not np.all(x[1:] >= x[:-1]):          # the check points come element by element, in order
            order = np.argsort(x, kind="stable")
            x, f = x[order], f[order]
        summed = np.empty((len(x) + 1, 3))
        summed[0] = 0.0
        np.cumsum(f, axis=0, out=summed[1:])
        return x, summed


def _loads_up_to(loads: CableLoads, element_length_m, x_m) -> np.ndarray:
    """G(x): the resultant [N] of every load on the material [0, x] but the ends' forces, shape (m, 3)."""
    Le = np.asarray(element_length_m, dtype=float)
    x_nodes = np.concatenate([[0.0], np.cumsum(Le)])
    x = np.asarray(x_m, dtype=float)
    # concentrated loads at x_p <= x, summed in order of x_p
    point_x, cum = loads.point_forces_summed
    G = cum[np.searchsorted(point_x, x, side="right")]
    node_cum = np.vstack([np.zeros((1, 3)), np.cumsum(loads.node_force_N, axis=0)])
    G = G + node_cum[np.searchsorted(x_nodes, x, side="right")]
    G = G + np.clip(x, 0.0, x_nodes[-1])[:, None] * np.asarray(loads.line_load_N_per_m, dtype=float)[None, :]
    if loads.acceleration is not None:
        # −ρA ∫₀ˣ r̈ dx: whole elements before x, then the part of x's own element (cubic Hermite, exact)
        a = np.asarray(loads.acceleration, dtype=float)
        whole = hermite_integral_weights(np.ones(len(Le)), Le)
        per_element = (whole[:, 0, None] * a[:-1, :3] + whole[:, 1, None] * a[:-1, 3:]
                       + whole[:, 2, None] * a[1:, :3] + whole[:, 3, None] * a[1:, 3:])
        before = np.vstack([np.zeros((1, 3)), np.cumsum(per_element, axis=0)])
        e, xi = _locate(x, Le)
        w = hermite_integral_weights(xi, Le[e])
        part = (w[:, 0, None] * a[e, :3] + w[:, 1, None] * a[e, 3:] + w[:, 2, None] * a[e + 1, :3]
                + w[:, 3, None] * a[e + 1, 3:])
        G = G - loads.mass_per_length_kg_per_m * (before[e] + part)
    return G


def load_imbalance_N(loads: CableLoads, element_length_m) -> np.ndarray | None:
    """The sum [N] of every force on the cable, inertia included (0 in equilibrium; None when an
    end's force is unknown): what a solve's tolerance and the dynamic run's step leave."""
    if loads.trailing_force_N is None or loads.leading_force_N is None:
        return None
    total = _loads_up_to(loads, element_length_m, [float(np.sum(element_length_m))])[0]
    return total + np.asarray(loads.trailing_force_N) + np.asarray(loads.leading_force_N)


def equilibrium_tension(coordinates, element_length_m, loads: CableLoads, x_m) -> np.ndarray:
    """Axial force N(x) [N] from the equilibrium of the cable's external loads: N = t(x)·F(x).

    The paper's Eq. 24 reads N = EA·ε off the ANCF cable's strain. Next to a concentrated contact
    load (a stiff cable landing on a bend's end) that strain oscillates along the element: the
    cubic Hermite element (paper Eqs. 5-6) cannot bend and keep |r'| smooth at once, and Exudyn's
    reduced (Lobatto) quadrature ties ε down at three points per element only, so EA·ε between
    and even at them carries the element's error (CommScope A–H, steady: −99…416 N at a pull of
    291 N; read at the Lobatto points alone it stays within 0…290.4 N but is up to 6.5 N off the
    loads' balance, 11.4 N at half the elements). The internal force F(x) of the cut at x instead
    follows exactly from the loads on either side: from the trailing end F = −F_trail − G(x),
    from the leading end F = F_lead + G(L) − G(x), G(x) the resultant of the loads on [0, x]
    (contact forces at the check points, weight, inertia −ρA·r̈, nodal dampers). Its tangential
    part t·F, t = r'/|r'|, is the tension; it jumps only where a check point's friction acts (and
    where a stiff cable lands on the wall at an angle, the normal force having a part along it),
    and converges to the continuum's axial force as the mesh is refined (reference/README.md,
    "The tension profile"). With both ends' forces known the two are
    blended linearly in x, so that N meets both ends' forces exactly (their difference is the
    solve's residual, :func:`load_imbalance_N`); with one, that one is used.

    Parameters
    ----------
    coordinates : array_like (n_el + 1, 6)
        Absolute nodal coordinates [m, -].
    element_length_m : array_like (n_el,)
        Unstretched element lengths [m].
    loads : CableLoads
        The loads at this state; at least one end's force must be known.
    x_m : array_like (m,)
        Stations along the cable from the trailing end [m].
    """
    if loads.trailing_force_N is None and loads.leading_force_N is None:
        raise ValueError("equilibrium_tension needs the force on at least one end of the cable")
    Le = np.asarray(element_length_m, dtype=float)
    length = float(np.sum(Le))
    x = np.clip(np.asarray(x_m, dtype=float), 0.0, length)
    G = _loads_up_to(loads, Le, np.append(x, length))     # the stations', then all the loads'
    G, total = G[:-1], G[-1]
    if loads.leading_force_N is not None:
        from_lead = np.asarray(loads.leading_force_N, dtype=float)[None, :] + total[None, :] - G
    if loads.trailing_force_N is not None:
        from_trail = -np.asarray(loads.trailing_force_N, dtype=float)[None, :] - G
    if loads.leading_force_N is None:
        F = from_trail
    elif loads.trailing_force_N is None:
        F = from_lead
    else:
        w = (x / length)[:, None]
        F = (1.0 - w) * from_trail + w * from_lead
    q = np.asarray(coordinates, dtype=float).reshape(-1, 6)
    e, xi = _locate(x, Le)
    wd = hermite_derivative_weights(xi, Le[e])
    d = wd[:, 0, None] * q[e, :3] + wd[:, 1, None] * q[e, 3:] + wd[:, 2, None] * q[e + 1, :3] + wd[:, 3, None] * q[e + 1, 3:]
    t = d / np.linalg.norm(d, axis=1)[:, None]
    return np.sum(t * F, axis=1)


def check_point_forces_N(normal, normal_force_N, friction_force_N, velocity_m_per_s) -> np.ndarray:
    """Each check point's force on the cable [N], shape (n, 3), from the kernel's per-point state
    (:meth:`exucable.contact.ContactKernel.points`): −w·f_n·n minus the friction along the sliding
    direction v_τ/|v_τ|, v_τ = v − (v·n)n (paper Eqs. 17-23). Σ_k S(ξ_k)ᵀ F_k is the kernel's
    generalized force; points out of contact (no force, NaN normal) give 0."""
    n = np.nan_to_num(np.asarray(normal, dtype=float))
    v = np.asarray(velocity_m_per_s, dtype=float)
    tau = v - np.sum(v * n, axis=1)[:, None] * n
    slip = np.linalg.norm(tau, axis=1)
    along = np.divide(tau, slip[:, None], out=np.zeros_like(tau), where=slip[:, None] > 0.0)
    return (-np.asarray(normal_force_N, dtype=float)[:, None] * n
            - np.asarray(friction_force_N, dtype=float)[:, None] * along)
