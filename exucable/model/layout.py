"""Initial placement of the cable in its conduit (pure numpy; no Exudyn).

Where the run starts decides what it costs: a cable laid on the centreline, unloaded, first
slams onto the wall and sheds axial waves (thousands of tiny steps); a cable laid where it will
slide anyway, already carrying its tension, starts in near-equilibrium and the solver takes
large steps at once (``../shared/notes/exudyn-findings.md``: 116 s -> 0.6 s on Example 2).

So the start is built from the quasi-static rope solution:

* the cable is **pre-stretched**: a material element of length ``L_e`` spans ``(1 + T/EA) L_e``
  of its path, so that N = EA·ε (paper Eq. 24) equals the rope tension T from the first step;
* it is **offset toward the wall** it will bear on, by the clearance ``R - r`` plus the
  penetration that the Hertz law needs to carry the sidewall load (paper Eqs. 14, 18); the
  offset field is smoothed along the route so that the cable is not kinked where contact starts
  (and straight runs without load stay off the wall: contact sitting exactly at the clearance
  chatters);
* it already **moves** at the pulling speed along its path (positions and slope rates).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["CableLayout", "InitialLayout", "initial_layout", "lay_cable", "sliding_layout", "steady_lead_out_m", "contact_offsets", "extended_point", "extended_tangent"]


@dataclass(frozen=True, eq=False)
class CableLayout:
    """Nodal start state of an ANCF cable, nodes numbered from the trailing end.

    Attributes
    ----------
    element_length_m : ndarray (n_el,)
        Unstretched (material) element lengths [m].
    node_x_m : ndarray (n_el + 1,)
        Material coordinate of each node, from the trailing end [m].
    node_s_m : ndarray (n_el + 1,)
        Arc length of each node along the (pull-oriented) centreline [m]; beyond the conduit's
        length the path continues straight along the exit tangent.
    position_m, slope : ndarray (n_el + 1, 3)
        Node positions [m] and slopes dr/dx [-] (|slope| = 1 + ε).
    velocity_m_per_s, slope_rate_1_per_s : ndarray (n_el + 1, 3)
        Initial time derivatives of position [m/s] and slope [1/s].
    """

    element_length_m: np.ndarray
    node_x_m: np.ndarray
    node_s_m: np.ndarray
    position_m: np.ndarray
    slope: np.ndarray
    velocity_m_per_s: np.ndarray
    slope_rate_1_per_s: np.ndarray

    @property
    def n_elements(self) -> int:
        return len(self.element_length_m)

    @property
    def coordinates(self) -> np.ndarray:
        """Nodal coordinates ``[x, y, z, x', y', z']`` per node, shape (n_el + 1, 6)."""
        return np.hstack([self.position_m, self.slope])

    @property
    def velocities(self) -> np.ndarray:
        """Nodal coordinate rates, shape (n_el + 1, 6)."""
        return np.hstack([self.velocity_m_per_s, self.slope_rate_1_per_s])


#: The rope solver's argument names (its errors' keys) → the scenario keys they come from.
ROPE_ARGUMENT_KEYS = {"pull_force_N": "pull.force", "trailing_tension_N": "pull.back_tension",
                      "friction": "contact.friction", "cable_length_m": "cable.length",
                      "weight_per_length_N_per_m": "cable.density"}


def extended_point(centreline, s_m: np.ndarray) -> np.ndarray:
    """Centreline point at ``s_m`` [m], continued straight along the end tangents outside [0, L]."""
    s = np.atleast_1d(np.asarray(s_m, dtype=float))
    L = centreline.length_m
    inside = np.clip(s, 0.0, L)
    p = np.atleast_2d(centreline.point(inside))      # a new array, changed in place below
    lo, hi = s < 0.0, s > L
    if lo.any():
        p[lo] += (s[lo] - 0.0)[:, None] * np.atleast_2d(centreline.tangent(0.0))
    if hi.any():
        p[hi] += (s[hi] - L)[:, None] * np.atleast_2d(centreline.tangent(L))
    return p


def extended_tangent(centreline, s_m: np.ndarray) -> np.ndarray:
    """Unit tangent at ``s_m``, constant beyond the conduit's ends."""
    s = np.clip(np.atleast_1d(np.asarray(s_m, dtype=float)), 0.0, centreline.length_m)
    return np.atleast_2d(centreline.tangent(s))


def contact_offsets(
    centreline,
    s_m: np.ndarray,
    tension_N: np.ndarray,
    weight_per_length_N_per_m: float,
    clearance_m: float,
    line_stiffness_N_per_m_e_per_m: float,
    exponent: float,
    blend_length_m: float,
    path_offset_m: np.ndarray | None = None,
    path_pressure_N_per_m: np.ndarray | None = None,
) -> np.ndarray:
    """Offset of the cable axis from the conduit axis at rest on its bearing wall.

    The cable presses on the wall along the lateral load per length
    ``p = T κ n - w (e_z - (e_z·t) t)`` (the rope equation's sidewall load); its axis sits at the
    clearance plus the penetration ``δ = (|p| / k)^(1/e)`` that the distributed Hertz law
    ``k δ^e`` (``k = K_n / h_ref``) needs to carry it. Unloaded stretches keep zero offset. The
    field is smoothed with a Gaussian of width ``blend_length_m`` along s.

    Parameters
    ----------
    s_m : ndarray (m,)
        Uniform grid of arc lengths inside [0, L] [m].
    tension_N : ndarray (m,)
        Rope tension on the grid [N].
    weight_per_length_N_per_m : float
        w = ρAg [N/m] (0 without gravity).
    clearance_m : float
        R - r [m].
    line_stiffness_N_per_m_e_per_m : float
        Contact stiffness per unit cable length, K_n / h_ref [N/m^e per m].
    exponent : float
        Hertz exponent e [-].
    blend_length_m : float
        Smoothing length [m].
    path_offset_m, path_pressure_N_per_m : ndarray (m, 3) and (m,), optional
        The path and wall pressure of the rope with clearance on the grid
        (:mod:`exucable.quasistatic.clearance`); when given, the cable starts on that path (free spans
        included) instead of on the wall the centreline rope's load points to.

    Returns
    -------
    ndarray (m, 3)
        Offset vectors [m].
    """
    s = np.asarray(s_m, dtype=float)
    if path_offset_m is not None:
        p = np.asarray(path_pressure_N_per_m, dtype=float)
        load = np.asarray(path_offset_m, dtype=float)   # only its direction is used where loaded
        off = load.copy()
    else:
        t = np.atleast_2d(centreline.tangent(s))
        kn = np.atleast_2d(centreline.curvature_vector(s))
        ez = np.array([0.0, 0.0, 1.0])
        w_perp = weight_per_length_N_per_m * (ez[None, :] - (t @ ez)[:, None] * t)
        load = np.asarray(tension_N, dtype=float)[:, None] * kn - w_perp
        p = np.linalg.norm(load, axis=1)
        off = np.zeros_like(load)
    scale = max(p.max(), 1e-300)
    loaded = p > 1e-9 * scale
    if loaded.any():
        delta = (p[loaded] / line_stiffness_N_per_m_e_per_m) ** (1.0 / exponent)
        bearing = load[loaded]
        size = np.maximum(np.sqrt(_dot3(bearing.T, bearing.T)), 1e-300)   # the rows' lengths
        off[loaded] = bearing / size[:, None] * (clearance_m + delta)[:, None]
    ds = s[1] - s[0] if len(s) > 1 else 1.0
    sigma = blend_length_m / ds
    if sigma > 0.5 and loaded.any():
        half = int(np.ceil(4 * sigma))
        k = np.exp(-0.5 * (np.arange(-half, half + 1) / sigma) ** 2)
        k /= k.sum()
        # 'edge' padding: at the conduit's ends the wall the cable rests on continues.
        pad = np.pad(off, ((half, half), (0, 0)), mode="edge")
        off = np.stack([np.convolve(pad[:, j], k, mode="valid") for j in range(3)], axis=1)
        # smoothing may only lift the cable off the wall, never push it further in than the load needs
        mag = np.sqrt(_dot3(off.T, off.T))
        cap = np.where(loaded, clearance_m + (p / line_stiffness_N_per_m_e_per_m) ** (1.0 / exponent), clearance_m)
        too = mag > cap
        off[too] *= (cap[too] / mag[too])[:, None]
    return off


def lay_cable(
    centreline,
    cable_length_m: float,
    n_elements: int,
    axial_stiffness_N: float,
    speed_m_per_s: float = 0.0,
    tension_N: Callable[[np.ndarray], np.ndarray] | None = None,
    offset_m: Callable[[np.ndarray], np.ndarray] | None = None,
    points_per_element: int = 40,
    clearance_m: float | None = None,
    fit_points_per_element: int = 8,
    correction_iterations: int = 8,
    lead_out_m: float = 0.0,
) -> CableLayout:
    """Lay a cable of ``n_elements`` equal material elements into the leading part of a conduit.

    The trailing end sits at ``s = L - cable_length_m + lead_out_m``; the pre-stretch (1 + T/EA)
    (and ``lead_out_m``) carry the leading end past the conduit's exit, along the exit tangent
    (where the rig holds it).

    Parameters
    ----------
    centreline
        Pull-oriented centreline (``point``, ``tangent``, ``length_m``); the leading end is at its end.
    cable_length_m : float
        Unstretched cable length [m], ≤ the centreline length.
    n_elements : int
        Number of ANCF cable elements.
    axial_stiffness_N : float
        EA [N].
    speed_m_per_s : float
        Initial sliding speed along the path [m/s].
    tension_N : callable, optional
        T(s) [N] on the conduit's arc length (vectorised); None = unstressed.
    offset_m : callable, optional
        Offset vector field o(s) [m] (vectorised, shape (m, 3)); None = on the centreline.
    points_per_element : int
        Resolution of the fine grid that integrates the stretched path.
    clearance_m : float, optional
        R − r [m]; when given, the fitted cable is pulled back wherever it strays further from the
        axis than its target offset (at most ``correction_iterations`` refits).
    fit_points_per_element : int
        Gauss points per element of the least-squares fit.
    lead_out_m : float
        Unstretched-path length [m] of cable laid beyond the exit along the exit tangent, as if
        pulled out that far (see :func:`steady_lead_out_m`); T and the offset there are the exit's.
    """
    L = float(centreline.length_m)
    s0 = L - float(cable_length_m) + float(lead_out_m)
    # Fine grid along s, long enough to hold the stretched cable (strain < 50 % is asserted below).
    ds = cable_length_m / (n_elements * points_per_element)
    s_full = np.arange(s0, s0 + 1.5 * cable_length_m + ds, ds)
    x_nodes = np.linspace(0.0, cable_length_m, n_elements + 1)
    # First on the grid's leading part, as far as the largest strain stretches the cable (with a
    # margin: the offset path is shorter than the axis on the inside of bends), then up to 1.15
    # cable lengths (enough below ~14 % strain): every value used below is then the full grid's,
    # bit for bit (the same points; the integral is a running sum; only the last point's one-sided
    # slope differs, and it is not used when the cable ends before it); else the whole grid.
    part = s_full[:int(np.searchsorted(s_full, s0 + 1.15 * cable_length_m)) + 1]
    T_part = np.zeros_like(part) if tension_N is None else np.asarray(tension_N(np.clip(part, 0.0, L)), dtype=float)
    first = 1.0 + 1.5 * max(float(np.max(T_part)), 0.0) / axial_stiffness_N + 0.01
    for extent in ((first,) if first < 1.15 else ()) + (1.15, 1.5):
        s = s_full if extent == 1.5 else s_full[:int(np.searchsorted(s_full, s0 + extent * cable_length_m)) + 1]
        if len(s) <= len(part):
            T = T_part[:len(s)]
        else:
            T = np.zeros_like(s) if tension_N is None else np.asarray(tension_N(np.clip(s, 0.0, L)), dtype=float)
        o = np.zeros((len(s), 3)) if offset_m is None else np.asarray(offset_m(np.clip(s, 0.0, L)), dtype=float)
        P = extended_point(centreline, s)
        P += o
        dP = np.gradient(P, s, axis=0, edge_order=2)
        speed_geom = np.sqrt(_dot3(dP.T, dP.T))             # dσ/ds of the offset path, |dP/ds|
        stretch = 1.0 + T / axial_stiffness_N                # dσ/dx
        if np.any(stretch <= 0.5) or np.any(stretch > 1.5):
            from ..errors import ModelError
            raise ModelError("cable.youngs_modulus",
                             f"the rope's tension (up to {float(np.max(np.abs(T))):.4g} N) would stretch the cable by "
                             f"more than 50 % (EA = {axial_stiffness_N:.4g} N): the cable is far too soft for its loads; "
                             "check cable.youngs_modulus (Pa), cable.radius and the loads")
        dx_ds = speed_geom / stretch
        x = np.concatenate([[0.0], np.cumsum(0.5 * (dx_ds[1:] + dx_ds[:-1]) * np.diff(s))])
        if len(s) >= 3 and x[-2] > cable_length_m:
            break
    if x[-1] < cable_length_m:
        raise ValueError("internal: fine grid too short for the stretched cable")
    s_nodes = np.interp(x_nodes, x, s)
    Le = np.diff(x_nodes)
    # Least-squares fit of the cubic elements to the path (not interpolation at the nodes): an
    # element spanning a bend's end cannot follow the jump of curvature, and nodes put exactly on
    # the path make it bulge into the wall by up to ~L²κ/8 (0.6 mm against a 1 mm clearance on
    # Example 4's coarse mesh). Then correct: where a fitted point leaves the offset it should
    # have, move its target back by the excess and refit.
    k = fit_points_per_element
    xi_s, _ = np.polynomial.legendre.leggauss(k)
    xi_s = 0.5 * (xi_s + 1.0)
    xs = (x_nodes[:-1, None] + xi_s[None, :] * Le[:, None]).ravel()
    xs = np.concatenate([[0.0], xs, [cable_length_m]])
    # the rows: the trailing node, k Gauss points in each element in turn, the leading node; each
    # Gauss point lies inside its element (ξ in (0, 1)), so a row's element is known without a search
    e_of = np.concatenate([[0], np.repeat(np.arange(n_elements), k), [n_elements - 1]])
    xi_of = (xs - x_nodes[e_of]) / Le[e_of]
    _, vals = _hermite_rows(e_of, xi_of, Le)
    # From here on the rows are taken Gauss point by Gauss point (the first point of every element,
    # then the second, ...; the end nodes first and last) and each coordinate direction is one
    # contiguous row of a (3, m) array: the fit's sums over an element's points become additions of
    # whole arrays (:func:`_fit_rhs`). Row-wise operations give the same numbers in any row order.
    order = _point_major(n_elements, k)
    xs, vals_t = xs[order], vals[order].T.copy()          # vals_t (4, m): each basis function's values
    ss = np.interp(xs, x, s)
    target = np.stack([np.interp(ss, s, P[:, j]) for j in range(3)])
    C = np.ascontiguousarray(extended_point(centreline, ss).T)
    t_c = np.ascontiguousarray(extended_tangent(centreline, ss).T)
    rel = target - C
    lat = rel - _dot3(rel, t_c) * t_c
    want = np.sqrt(_dot3(lat, lat))
    inside = (ss > 0.0) & (ss < L)
    # scipy.linalg (loaded anyway: numba's BLAS) rather than scipy.sparse, whose import is part of
    # `exucable run`'s fixed cost (docs/performance.md)
    from scipy.linalg import cho_solve_banded, cholesky_banded

    factor = cholesky_banded(_normal_matrix_banded(vals_t, n_elements, k), check_finite=False)   # factored once
    for _ in range(correction_iterations + 1):
        rhs = _fit_rhs(vals_t, target, n_elements, k)                              # Bᵀ target
        coef = cho_solve_banded((factor, False), rhs.T, check_finite=False)   # (2(n+1), 3): r_k, r'_k rows
        rel = _fit_values(vals_t, coef, n_elements, k) - C                          # B coef − C
        lat = rel - _dot3(rel, t_c) * t_c
        d = np.sqrt(_dot3(lat, lat))
        excess = np.where(inside & (d > want), d - want, 0.0)
        if excess.max() < 1e-7 * max(1.0, want.max()) or clearance_m is None:
            break
        target = target - (excess / np.maximum(d, 1e-300)) * lat
    return sliding_layout(np.diff(x_nodes), x_nodes, s_nodes, coef[0::2], coef[1::2], speed_m_per_s)


def sliding_layout(element_length_m, node_x_m, node_s_m, position_m, slope, speed_m_per_s: float) -> CableLayout:
    """A :class:`CableLayout` whose shape is fixed in space while the material slides along it at
    speed V [m/s] (the steady pull's flow): velocity V·r'/|r'|, slope rate d(r')/dt = V·r''/|r'|
    (r'' of the cubic Hermite shape, averaged over the elements meeting at a node)."""
    Le = np.asarray(element_length_m, dtype=float)
    pos, slope = np.asarray(position_m, dtype=float), np.asarray(slope, dtype=float)
    coef = np.empty((2 * len(pos), 3))
    coef[0::2], coef[1::2] = pos, slope
    r2 = _second_derivative_at_nodes(coef, Le)
    mag = np.linalg.norm(slope, axis=1)[:, None]
    return CableLayout(
        element_length_m=Le,
        node_x_m=np.asarray(node_x_m, dtype=float),
        node_s_m=np.asarray(node_s_m, dtype=float),
        position_m=pos,
        slope=slope,
        velocity_m_per_s=speed_m_per_s * slope / mag,
        slope_rate_1_per_s=speed_m_per_s * r2 / mag,
    )


def _hermite_rows(e, xi, Le):
    """The Hermite basis (paper Eqs. 4-6) on the unknowns [r_0, r'_0, r_1, r'_1, ...] (one coordinate
    direction) at element ``e`` and coordinate ``xi``: each row's four columns and values, shape (m, 4).

    Four entries a row, so the fit's normal matrix is banded (bandwidth 3) and a 1 km cable's start
    (thousands of elements) costs milliseconds, not the seconds-to-minutes of a dense O(n³) solve."""
    L = Le[e]
    cols = 2 * e[:, None] + np.arange(4)[None, :]
    vals = np.stack([1 - 3 * xi**2 + 2 * xi**3, L * (xi - 2 * xi**2 + xi**3),
                     3 * xi**2 - 2 * xi**3, L * (-xi**2 + xi**3)], axis=1)
    return cols, vals


def _dot3(a, b):
    """Row-wise dot product of two (3, m) arrays, summed x + y then z, as ``np.sum(a * b, axis=1)``
    sums the rows of (m, 3) arrays (so that the fit's numbers are those of the row-per-point form)."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _point_major(n_elements: int, k: int):
    """The fit's rows (the trailing node, ``k`` points in each element in turn, the leading node)
    reordered point by point: the trailing node, every element's first point, every element's
    second, ..., the leading node."""
    mid = 1 + np.arange(n_elements)[None, :] * k + np.arange(k)[:, None]
    return np.concatenate([[0], mid.ravel(), [n_elements * k + 1]])


def _element_sums(w, n_elements: int, k: int, carry_from: slice, carry_to: slice):
    """Sums over each element of the fit's row terms ``w`` (..., slots, m) (rows in the order of
    :func:`_point_major`), shape (..., slots, n): every sum taken in the original row order from
    zero, as ``np.bincount`` adds the terms into their entries (the same sums, bit for bit), but in
    whole arrays instead of one scattered addition per term.

    A slot stands for one entry per element; the entry of slot ``carry_to`` of element e is the one
    of slot ``carry_from`` of element e − 1 (a node's shared by the two elements), so its sum goes
    on from there. The trailing node's row adds to element 0 before its points, the leading node's
    to element n − 1 after them."""
    mid = w[..., 1:-1].reshape(w.shape[:-1] + (k, n_elements))
    out = np.zeros(w.shape[:-1] + (n_elements,))
    out[..., 0] += w[..., 0]
    own = slice(0, carry_to.start) if carry_to.start > 0 else slice(carry_to.stop, None)   # carry_to: first or last
    for r in range(k):
        out[..., own, :] += mid[..., own, r, :]
    out[..., carry_to, 1:] = out[..., carry_from, :-1]
    for r in range(k):
        out[..., carry_to, :] += mid[..., carry_to, r, :]
    out[..., -1] += w[..., -1]
    return out


def _fit_rhs(vals_t, target, n_elements: int, k: int):
    """Bᵀ target, shape (3, 2(n + 1)), for the fit's rows in the order of :func:`_point_major`
    (``vals_t`` (4, m): the Hermite values of :func:`_hermite_rows`, transposed; ``target`` (3, m)),
    bit for bit ``np.bincount`` over the rows' columns (:func:`_element_sums`): element e's
    columns 2, 3 are node e + 1's unknowns, its columns 0, 1 node e's."""
    sums = _element_sums(vals_t[None, :, :] * target[:, None, :], n_elements, k, slice(2, 4), slice(0, 2))
    # unknowns 2e + i at [:, i, e]; the leading node's, 2n + i, at [:, 2 + i, n − 1]
    return np.concatenate([sums[:, :2].transpose(0, 2, 1).reshape(3, 2 * n_elements), sums[:, 2:, -1]], axis=1)


def _fit_values(vals_t, coef, n_elements: int, k: int):
    """B coef, shape (3, m), for the fit's rows in the order of :func:`_point_major` (``coef``
    (2(n + 1), 3)): each row's four terms summed from zero in column order, as ``np.einsum("mk,mkj->mj",
    vals, coef[cols])`` sums them, with element e's coefficients (rows 2e … 2e + 3 of ``coef``)
    taken once per element instead of gathered per row."""
    c = coef.T                                                 # (3, 2(n + 1))
    out = np.zeros((3, vals_t.shape[1]))
    for j in range(4):   # the end rows: the trailing node's element is the first, the leading node's the last
        out[:, 0] += vals_t[j, 0] * c[:, j]
        out[:, -1] += vals_t[j, -1] * c[:, 2 * n_elements - 2 + j]
    mid = out[:, 1:-1].reshape(3, k, n_elements)
    v = vals_t[:, 1:-1].reshape(4, k, n_elements)
    for j in range(4):
        mid += v[j][None] * np.ascontiguousarray(c[:, j:j + 2 * n_elements:2])[:, None, :]
    return out


#: Column pairs (a, b), a ≤ b, of a row's four Hermite values whose products enter BᵀB: those across
#: an element's two nodes, those of its leading node (carried into the next element's trailing node,
#: the same entries), those of its trailing node (see :func:`_element_sums`).
_PAIRS = ((0, 2), (0, 3), (1, 2), (1, 3), (2, 2), (2, 3), (3, 3), (0, 0), (0, 1), (1, 1))


def _normal_matrix_banded(vals_t, n_elements: int, k: int):
    """BᵀB of the rows of :func:`_hermite_rows` (``vals_t`` (4, m), rows in the order of
    :func:`_point_major`) in LAPACK's upper banded storage (row 3 + i − j holds entry (i, j), i ≤ j),
    as ``scipy.linalg.cholesky_banded`` takes it; each entry's products summed in the original row
    order, as ``np.add.at`` sums them (bit for bit, :func:`_element_sums`)."""
    a, b = np.array(_PAIRS).T
    sums = _element_sums(vals_t[a] * vals_t[b], n_elements, k, slice(4, 7), slice(7, 10))
    ab = np.zeros((4, 2 * (n_elements + 1)))
    e2 = 2 * np.arange(n_elements)
    for p, (i, j) in enumerate(_PAIRS):
        if 4 <= p < 7:      # the leading node's entries: final in the last element only
            ab[3 + i - j, 2 * (n_elements - 1) + j] = sums[p, -1]
        else:
            ab[3 + i - j, e2 + j] = sums[p]
    return ab


def _second_derivative_at_nodes(coef, Le):
    """∂²r/∂x² at the nodes, averaged over the elements meeting there; coef rows r_k, r'_k."""
    r, d = coef[0::2], coef[1::2]
    L = Le[:, None]
    # element e at ξ = 0 and ξ = 1
    left = (-6 * r[:-1] - 4 * L * d[:-1] + 6 * r[1:] - 2 * L * d[1:]) / L**2
    right = (6 * r[:-1] + 2 * L * d[:-1] - 6 * r[1:] + 4 * L * d[1:]) / L**2
    out = np.zeros_like(r)
    cnt = np.zeros((len(r), 1))
    out[:-1] += left
    cnt[:-1] += 1
    out[1:] += right
    cnt[1:] += 1
    return out / cnt


@dataclass(frozen=True, eq=False)
class InitialLayout:
    """Where and how a scenario's cable starts (Exudyn-free): see :func:`initial_layout`.

    Attributes
    ----------
    conduit : exucable.geometry.Conduit
        The conduit oriented so that the leading (pulled) end is at the end of its centreline.
    rope : exucable.quasistatic.rope.RopeSolution
        The quasi-static rope solution the start is pre-tensioned to (also the reference).
    cable : CableLayout
        Nodal coordinates and rates, nodes numbered from the trailing end.
    weight_per_length_N_per_m : float
        ρA·g [N/m].
    exit_tangent, entry_tangent : ndarray (3,)
        Unit tangents of the centreline at the leading end and at the trailing end's start position.
    mesh : exucable.scenario.mesh.MeshPlan or None
        The cable mesh (elements, check points per element) by the rule of :mod:`exucable.scenario.mesh`
        or the scenario's override, with its warnings.
    lead_out_m : float
        Cable laid beyond the exit along the exit tangent at the start [m] (steady mode,
        :func:`steady_lead_out_m`; 0 otherwise): the start is the cable pulled out that far.
    rope_clearance : exucable.quasistatic.clearance.ClearanceRopeSolution or None
        The rope with clearance whose path the start follows, for the cable inside the conduit at
        the start (None where it is not used: a force-controlled pull, no clearance, no
        pretension, or a cable that runs slack).
    """

    conduit: object
    rope: object
    cable: CableLayout
    weight_per_length_N_per_m: float
    exit_tangent: np.ndarray
    entry_tangent: np.ndarray
    mesh: object = None
    lead_out_m: float = 0.0
    rope_clearance: object = None

    @property
    def leading_position_m(self) -> np.ndarray:
        """Start position of the leading end [m] (where a user's body joins it)."""
        return self.cable.position_m[-1].copy()

    @property
    def trailing_position_m(self) -> np.ndarray:
        """Start position of the trailing end [m]."""
        return self.cable.position_m[0].copy()


#: Length of straight cable between the last bend's end and the rig in a steady solve, in bending
#: lengths √(EJ/T) of the cable at the exit [-] (see :func:`steady_lead_out_m`). Measured on
#: Fig. 12's one coil (80 elements, 1.5 m lead-in), steady minus capstan at 1 / 2.5 /
#: 5 / 10 / 20 bending lengths: +0.09 / +0.00 / -0.034 / -0.050 / -0.052 %: settled from 10 on.
LEAD_OUT_BENDING_LENGTHS = 10.0


def steady_lead_out_m(centreline, bending_stiffness_N_m2: float, exit_tension_N: float) -> float:
    """Cable to lay beyond the exit for a steady solve [m], so that the rig sits at least
    ``LEAD_OUT_BENDING_LENGTHS`` bending lengths λ = √(EJ/T) past the end of the last bend.

    Why: the steady solve holds the leading end where the start put it, free to turn (a pinned
    end: no bending moment). Laid flush with the exit of a route that ends in a bend (a helix's
    top, Example 4's last bend), that end sits a few millimetres past the bend, inside the
    bending boundary layer λ (4 cm on Fig. 12's coil): the cable must unbend from 1/R to zero
    curvature within it, presses on the wall at the bend's end, and its extra friction raised the
    pulling force by +0.7 % once the mesh resolved λ (the error grew under refinement).
    A real rig sits far out on the exit line, where the moment has decayed as e^(-x/λ); the
    dynamic run reaches that state as it pulls the end out. Routes ending on a straight at least
    that long need no lead-out (0).

    Parameters
    ----------
    centreline : Centreline
        Pull-oriented centreline (the leading end at its end).
    bending_stiffness_N_m2 : float
        EJ [N·m²].
    exit_tension_N : float
        Tension at the exit [N] (the rope's pulling force).
    """
    if bending_stiffness_N_m2 <= 0.0 or exit_tension_N <= 0.0:
        return 0.0
    if not any(piece.is_curved for piece in centreline.pieces):
        return 0.0      # no bend, no boundary layer to leave (a straight route, or a pull-in's first metres)
    straight = 0.0
    for piece in reversed(centreline.pieces):
        if piece.is_curved:
            break
        straight += piece.length_m
    need = LEAD_OUT_BENDING_LENGTHS * float(np.sqrt(bending_stiffness_N_m2 / exit_tension_N))
    return max(0.0, need - straight)


def _clearance_rope_start(scenario, centreline, w_N_per_m: float, clearance_m: float, cable_length_m: float):
    """The rope with clearance for the start of a velocity-controlled pull, or None (force-controlled,
    no clearance, or a cable that runs slack somewhere)."""
    from ..errors import ModelError
    from ..quasistatic.clearance import solve_rope_with_clearance

    if scenario.pull.force_N is not None or clearance_m <= 0.0:
        return None
    try:
        return solve_rope_with_clearance(centreline, clearance_m, scenario.contact.friction, w_N_per_m,
                                         scenario.pull.back_tension_N, cable_length_m=cable_length_m)
    except ModelError:
        return None


def plan_cable_mesh(scenario, conduit, rope, refine: float = 1.0, check_points_per_element: int | None = None):
    """The scenario's cable mesh by the rule of :mod:`exucable.scenario.mesh` (or its override, checked).

    ``refine`` divides the element length (``exucable converge``); ``check_points_per_element``
    overrides the scenario's ``contact.check_points_per_element``."""
    from ..scenario.mesh import plan_mesh

    c = scenario.cable
    k = check_points_per_element if check_points_per_element is not None else scenario.contact.check_points_per_element
    return plan_mesh(conduit.centreline, conduit.inner_radius_m - c.radius_m, scenario.cable_length_m,
                     c.bending_stiffness_N_m2, float(np.max(rope.tension_N)) if rope is not None else 0.0,
                     elements=None if "elements" in c.derived_keys else c.elements,
                     element_length_m=c.element_length_m,
                     check_points_per_element=k, refine=refine)


def initial_layout(scenario, with_contact: bool = True, refine: float = 1.0,
                   check_points_per_element: int | None = None,
                   references: InitialLayout | None = None) -> InitialLayout:
    """The start state of ``scenario``'s cable, without Exudyn.

    Pre-stretched to the rope solution's tension, on its bearing wall, sliding at the pull speed
    (paper Sect. 2.1's pull, started near its quasi-static state, which makes runs ~100× cheaper
    than starting at rest); with ``solver.pretension = false`` on the centreline, unloaded, at rest.

    Parameters
    ----------
    scenario : exucable.scenario.specs.Scenario
    with_contact : bool
        False: on the centreline even when pre-tensioned (no wall to bear on).
    refine : float
        Divides the mesh rule's element length (``exucable converge``).
    check_points_per_element : int, optional
        Overrides ``contact.check_points_per_element``.
    references : InitialLayout, optional
        A layout of the same scenario with the same ``with_contact`` (another mesh): its rope, rope
        with clearance and lead-out are taken instead of solved again. They depend on the scenario
        alone, not on the mesh, and on a long route they cost more than the rest of the build.

    Returns
    -------
    InitialLayout
    """
    from ..errors import ModelError
    from ..quasistatic.rope import rope_pull_force_N, solve_rope, solve_rope_for_pull_force

    sc = scenario
    conduit = sc.build_conduit()
    if sc.pull.direction == "reverse":
        conduit = conduit.reversed()
    centre = conduit.centreline
    c = sc.cable
    L_cable = sc.cable_length_m
    g = sc.gravity.g_m_per_s2 if sc.gravity is not None else 0.0
    w = c.mass_per_length_kg_per_m * g
    common = dict(friction=sc.contact.friction, weight_per_length_N_per_m=w)

    def rope_for(length_m):
        try:
            if sc.pull.force_N is not None:
                return solve_rope_for_pull_force(centre, pull_force_N=sc.pull.force_N, **common,
                                                 cable_length_m=length_m)
            return solve_rope(centre, trailing_tension_N=sc.pull.back_tension_N, **common, cable_length_m=length_m)
        except ModelError as exc:
            # the rope solver names its own arguments; the user knows the scenario's keys
            key = ROPE_ARGUMENT_KEYS.get(exc.key, exc.key)
            raise ModelError(key, exc.message) from None

    full = None          # the rope of the whole cable inside, where the lead-out rule needed it
    lead_out = 0.0 if references is None else references.lead_out_m
    if references is None and sc.solver.pretension and (sc.solver.mode == "steady" or (sc.solver.start_from == "steady" and sc.pull.force_N is None)):
        if sc.solver.steady_lead_out_m is not None:
            lead_out = float(sc.solver.steady_lead_out_m)
        else:
            # the rule needs the whole cable's exit tension only: its force alone (no profile) for a
            # velocity-controlled pull, whose rope is then solved once, for the cable as laid
            if sc.pull.force_N is None:
                exit_N = rope_pull_force_N(centre, trailing_tension_N=sc.pull.back_tension_N, **common,
                                           cable_length_m=L_cable)
            else:
                full = rope_for(L_cable)
                exit_N = full.pull_force_N
            lead_out = steady_lead_out_m(centre, c.bending_stiffness_N_m2, exit_N)
        if lead_out >= L_cable:
            raise ModelError("solver.steady_lead_out", f"{lead_out:.4g} m laid out past the exit leaves none of the "
                             f"{L_cable:.4g} m cable in the conduit; give less than the cable's length")
    # the reference of the cable as laid: less inside by the lead-out
    if references is not None:
        rope = references.rope
    else:
        rope = full if full is not None and lead_out == 0.0 else rope_for(L_cable - lead_out)
    clearance = conduit.inner_radius_m - c.radius_m
    mesh = plan_cable_mesh(sc, conduit, rope, refine, check_points_per_element)
    n_el = mesh.elements
    if sc.solver.pretension:
        s_grid = np.linspace(0.0, centre.length_m, max(2001, 20 * n_el + 1))
        L_e = L_cable / n_el
        # blend over the length on which a tensioned beam leaves the wall, √(EJ/T), but at least
        # half an element so the nodes can follow it
        T_ref = max(float(np.max(rope.tension_N)), 1e-6)
        blend = max(0.5 * L_e, np.sqrt(c.bending_stiffness_N_m2 / T_ref))
        if not with_contact:
            free = None
        elif references is not None:
            free = references.rope_clearance
        else:
            free = _clearance_rope_start(sc, centre, w, clearance, L_cable - lead_out)
        path = {}
        if free is None:
            T_grid = np.interp(s_grid, rope.s_conduit_m, rope.tension_N)
        else:
            # Start on the path of the rope with clearance: with gravity the cable leaves the wall in
            # free spans across the clearance, and a start pressed onto the wall the centreline rope's
            # load points to rang for a second as those spans formed.
            T_grid = np.interp(s_grid, free.s_conduit_m, free.tension_N)
            path = {"path_offset_m": np.stack([np.interp(s_grid, free.s_conduit_m, free.offset_m[:, j])
                                               for j in range(3)], axis=1),
                    "path_pressure_N_per_m": np.interp(s_grid, free.s_conduit_m, free.sidewall_pressure_N_per_m)}
        off = contact_offsets(centre, s_grid, T_grid, w, clearance,
                              sc.contact.stiffness / sc.contact.reference_spacing_m,
                              sc.contact.exponent, blend, **path) if with_contact else np.zeros((len(s_grid), 3))

        def tension_fn(s):
            return np.interp(s, s_grid, T_grid)

        off_columns = [np.ascontiguousarray(off[:, j]) for j in range(3)]   # np.interp copies strided ones per call

        def offset_fn(s):
            return np.stack([np.interp(s, s_grid, column) for column in off_columns], axis=1)

        cable = lay_cable(centre, L_cable, n_el, c.axial_stiffness_N, sc.pull.speed_m_per_s, tension_fn,
                          offset_fn, clearance_m=clearance if with_contact else None, lead_out_m=lead_out)
    else:
        cable = lay_cable(centre, L_cable, n_el, c.axial_stiffness_N, 0.0)
        free = None
    t_exit = np.asarray(centre.tangent(centre.length_m), dtype=float)
    t_entry = np.asarray(centre.tangent(centre.length_m - L_cable + lead_out), dtype=float)
    return InitialLayout(conduit=conduit, rope=rope, cable=cable, weight_per_length_N_per_m=w,
                         exit_tangent=t_exit, entry_tangent=t_entry, mesh=mesh, lead_out_m=lead_out,
                         rope_clearance=free)
