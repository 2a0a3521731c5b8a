"""The rope with clearance: a cable without bending stiffness, free to move inside its conduit.

The centreline rope (:mod:`exucable.quasistatic.rope`) glues the cable to the conduit's centreline. A real cable
has a clearance ``c`` = conduit inner radius − cable radius [m] around it: it leaves a wall where
the loads let it, hangs in free spans (straight lines without gravity, catenaries with it) and
lands on another wall. This module solves that quasi-static problem for a perfectly flexible
cable in steady sliding, with numpy and scipy only (no Exudyn, no contact kernel): it is the
EJ → 0 limit of the multibody cable, which the centreline rope is only when c → 0 too.

Steady sliding is described in space (Eulerian): the cable's shape is fixed and its material runs
through it. The cable is a chain of N + 1 nodes at fixed conduit arc lengths ``s_i`` [m], each free
to move in its normal plane, ``x_i = C(s_i) + B_i d_i`` (``B_i`` two unit normals, ``d_i`` the
offset [m]); the wall is the tube ``|d_i| = c``. Segment ``j`` (nodes j, j + 1) has tension ``T_j``
[N] and unit direction ``t_j``. Node ``i`` is in equilibrium (the discrete form of the string
equation d(T t)/ds + f = 0, paper Sect. 2.6 with Eq. 19's Coulomb friction per unit length):

    T_i t_i − T_{i−1} t_{i−1} + W_i − ρ_i (d̂_i + μ τ_i) = 0,

with ``W_i`` the weight of half of each adjacent segment (−w ℓ e_z), ``ρ_i ≥ 0`` the wall's
reaction [N] along −d̂_i = −d_i/|d_i| (only where |d_i| = c), and ``−μ ρ_i τ_i`` Coulomb friction
against the sliding direction τ_i (the bisector of t_{i−1} and t_i). The trailing end carries the
back tension along the conduit's entry tangent; the rig pulls the leading end along the exit
tangent; both ends are free to move across the conduit.

Two sub-problems alternate until both hold (a fixed point, usually 3–10 passes):

1. *Shape* (the normal-plane components): with the tensions ``T_j`` and friction forces frozen,
   the offsets minimise the convex energy Σ T_j ℓ_j − Σ (W_i + F_i)·x_i + (k/2) Σ (|d_i| − c)₊²,
   whose stationarity is exactly the equilibrium above across the conduit; the wall is a stiff
   penalty ``k`` (penetration ~1e-7 of the clearance). Damped Newton with a sparse Hessian.
2. *Tensions* (along the conduit): with the shape frozen, march from the trailing end solving
   each node's 2 × 2 balance along the conduit tangent and along d̂_i for ``T_i`` and ``ρ_i``.

On a bend without gravity the cable wraps the inner wall and the capstan law T_out = T_in e^{μθ}
(paper Eq. 26) holds exactly; on a straight with gravity it lies on the floor, T grows by μwL
(paper Eq. 25 at θ = 0). Between, the free spans make the answer differ from the centreline rope.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import LinAlgError, get_lapack_funcs

from exucable.errors import ModelError

from .newton import armijo_step

__all__ = ["ClearanceRopeSolution", "solve_rope_with_clearance", "default_node_spacing_m", "graded_node_grid_m"]

_E_Z = np.array([0.0, 0.0, 1.0])
# Wall penalty k = _PENALTY · T_ref / h: the wall is this much stiffer than the chain's own lateral
# stiffness T/h, so the penetration (ρ/k ~ h²/(_PENALTY·R) on a bend) is a few 1e-7 of the clearance
# and the path it adds (penetration/R relative) is far below the 1e-4 this reference is used at.
_PENALTY = 1.0e4
_MAX_PASSES = 200
_MAX_NEWTON = 300
# A node placed on the wall sits this fraction of the clearance inside it (so it counts as touching).
_ON_WALL = 1e-7
# Chains of more segments than this start from the solution on a chain _COARSEN times coarser.
_COARSEN_ABOVE = 4000
_COARSEN = 4
# ... and so does the chain a caller asks for (not the coarser chains solved for it) above this many:
# Example 4's 970-segment chain spent 31 of its 47 Newton steps opening its free spans a node or two a
# step, which the 4× coarser chain does 4× faster and cheaper; more
# levels below 4000 segments cost more than they saved (100 m: 150 -> 210 ms, commscope: 190 -> 260 ms),
# and Example 2's 559 segments, which open no long spans, 18 -> 26 ms.
_COARSEN_REQUESTED_ABOVE = 800
# Nodes of the default chain beyond which its spacing grows past 2 cm (routes over 400 m), up to the
# bends' hundredth of a radius: the solve's cost is linear in the nodes, and what the answer needs is
# set by the bends (each node turns ≤ 0.01 rad) and the free spans (metres long at a long route's
# tensions). Measured (benchmarks/long_routes.py --clearance-spacing and the light cable below), the
# pulling force's change from the 2 cm chain: a 30 mm cable (1.5 kg/m) in a 60 mm duct, 15° bends of
# 10 m radius: 1 km at 5 cm -1.1e-6, at 10 cm -2.8e-6; 10 km at 10 cm 1.5e-5 (500 000 nodes 11.8 s
# CPU, 100 000 nodes 3.4 s); an 18 mm cable (0.21 kg/m), 8 mm clearance, μ 0.5, 100 N back tension,
# bends of 3 m radius: 1 km at 3 cm (the bends' rule) -1.7e-5, at 5 cm +1.1e-5, at 10 cm +8.7e-5; on
# 10 km of 20 m bends 2.5e-4 at 10 cm and 1.4e-3 at 20 cm, hence the bends' rule stays. Every change
# is within a fifth of the 1e-4 relative floor of a steady run's error bar, the finest this reference
# is compared at.
_MAX_NODES = 20_000
_SPACING_M = 0.02
# On routes over 400 m (where the spacing may grow past 2 cm) the chain is graded: the bends' spacing on
# the bends, growing by _GRADING per metre of distance from the nearest bend up to _FAR_SPACING_M.
# Away from the bends a chain on a straight wall is exact at any spacing (the friction of a node
# is μ w ℓ of its segments, as for the continuous rope); what needs nodes is where the cable
# leaves and regains the wall, the free spans next to the bends (metres long at these tensions).
# The effect on the pulling force is measured in tests/test_rope_clearance.py and at
# benchmarks/long_routes.py --clearance-spacing.
_GRADING = 0.05
_FAR_SPACING_M = 0.5


@dataclass(frozen=True, eq=False)
class ClearanceRopeSolution:
    """Steady sliding of a perfectly flexible cable in a conduit with clearance.

    Arrays are ordered from the trailing end to the leading (pulled) end.

    Attributes
    ----------
    s_conduit_m : ndarray, shape (N + 1,)
        Arc length of each node along the *original* conduit centreline [m].
    offset_m : ndarray, shape (N + 1, 3)
        Node position minus the centreline point at ``s_conduit_m`` [m] (|offset| ≤ clearance).
    position_m : ndarray, shape (N + 1, 3)
        Node positions [m].
    tension_N : ndarray, shape (N + 1,)
        Tension at each node [N]: the mean of its two segments' (the end values at the ends).
    contact_force_N : ndarray, shape (N + 1,)
        Wall reaction ρ_i at each node [N] (0 on free spans).
    sidewall_pressure_N_per_m : ndarray, shape (N + 1,)
        ρ_i per length of conduit the node stands for [N/m].
    in_contact : ndarray of bool
        Nodes on the wall.
    pull_force_N, trailing_tension_N : float
        Force at the leading end along the exit tangent, back tension at the trailing end [N].
    clearance_m : float
        Conduit inner radius minus cable radius [m].
    passes, newton_iterations : int
        Shape/tension passes of the fixed point and Newton iterations of the shape solves in all.
    residual_N : float
        Largest node force imbalance at the solution [N] (all three components).
    """

    s_conduit_m: np.ndarray
    offset_m: np.ndarray
    position_m: np.ndarray
    tension_N: np.ndarray
    contact_force_N: np.ndarray
    sidewall_pressure_N_per_m: np.ndarray
    in_contact: np.ndarray
    pull_force_N: float
    trailing_tension_N: float
    clearance_m: float
    passes: int
    newton_iterations: int
    residual_N: float

    @property
    def max_tension_N(self) -> float:
        """Largest tension along the cable [N]."""
        return float(max(np.max(self.tension_N), self.pull_force_N))

    def free_spans_m(self) -> list[tuple[float, float]]:
        """Conduit arc-length intervals (start, end) [m] where the cable touches no wall."""
        free = ~self.in_contact
        spans, start = [], None
        for i, f in enumerate(free):
            if f and start is None:
                start = i
            if (not f or i == len(free) - 1) and start is not None:
                end = i if f else i - 1
                if end > start:
                    spans.append((float(self.s_conduit_m[start]), float(self.s_conduit_m[end])))
                start = None
        return spans


def _row_norm(v) -> np.ndarray:
    """Length of each row of an (n, 2) or (n, 3) array: ``np.linalg.norm(v, axis=1)`` bit for bit
    (the same squares summed in the same order), without its generic reduction, which cost 5× as
    much on the chain's 10⁵ rows (the shape solve takes a dozen per Newton step)."""
    v = np.asarray(v, dtype=float)
    total = v[:, 0] * v[:, 0]
    for j in range(1, v.shape[1]):
        total = total + v[:, j] * v[:, j]
    return np.sqrt(total)


def default_node_spacing_m(centreline, clearance_m: float) -> float:
    """Node spacing [m] that resolves the route's bends and the free spans across the clearance.

    A hundredth of the tightest bend radius (each node turns 0.01 rad; the discrete capstan's
    error is O((μ·0.01)³) per node) and at most 2 cm (free spans across 10 mm clearances are
    metres long), or on routes over 400 m at most a ``_MAX_NODES``-th of the route (20 000 nodes);
    at least 400 nodes over the route. The measured effect of the cap is at ``_MAX_NODES``. On
    routes over 400 m it is the spacing on the bends of the graded default chain
    (:func:`graded_node_grid_m`).
    """
    L = centreline.length_m
    h = min(0.01 * centreline.min_bend_radius_m, max(_SPACING_M, L / _MAX_NODES), L / 400.0)
    return float(h)


def graded_node_grid_m(centreline, s_from_m: float, s_to_m: float, clearance_m: float,
                       scale: float = 1.0) -> np.ndarray:
    """Node arc lengths [m] of the default chain on ``[s_from_m, s_to_m]`` of ``centreline``.

    The spacing is :func:`default_node_spacing_m` (times ``scale``, for the coarser chains of the
    nested solve). On routes over 400 m (``_MAX_NODES`` × 2 cm), it holds on the curved pieces only and grows away from them by ``_GRADING`` per metre of distance to
    the nearest one, up to ``_FAR_SPACING_M`` (times ``scale``); the nodes are where the integral
    of 1/spacing passes whole numbers, so neighbouring segments differ by ≤ ``_GRADING``.
    """
    length = s_to_m - s_from_m
    h_bend = scale * default_node_spacing_m(centreline, clearance_m)
    n_uniform = max(int(np.ceil(length / h_bend)), 4)
    curved = [(a, b) for a, b in centreline.curved_ranges_m() if b > s_from_m and a < s_to_m]
    h_far = max(scale * _FAR_SPACING_M, h_bend)
    if centreline.length_m <= _MAX_NODES * _SPACING_M or not curved or h_far <= h_bend:
        return np.linspace(s_from_m, s_to_m, n_uniform + 1)
    # the spacing on a sample grid fine enough to integrate it (half the bends' spacing); the distance
    # to the nearest curved piece from the one before and the one after each sample (pieces in order)
    x = np.linspace(s_from_m, s_to_m, int(np.ceil(2.0 * length / h_bend)) + 1)
    starts, ends = np.array(curved).T
    after = np.searchsorted(starts, x, side="right")        # the first curved piece starting past x
    before_dist = np.where(after > 0, np.maximum(x - ends[np.maximum(after - 1, 0)], 0.0), np.inf)
    after_dist = np.where(after < len(starts), starts[np.minimum(after, len(starts) - 1)] - x, np.inf)
    h = np.minimum(h_bend + _GRADING * np.minimum(before_dist, after_dist), h_far)
    inv = 1.0 / h
    count = np.concatenate([[0.0], np.cumsum(0.5 * (inv[1:] + inv[:-1]) * np.diff(x))])
    n_seg = max(int(np.ceil(count[-1] - 1e-9)), 4)
    grid = np.interp(np.linspace(0.0, count[-1], n_seg + 1), count, x)
    grid[0], grid[-1] = s_from_m, s_to_m
    return grid


def _solve_band(ab, b):
    """``scipy.linalg.solve_banded((3, 3), ab, b)``: LAPACK's ``gbsv`` on the band (7, n) laid into its
    LU storage (10, n) directly in Fortran order, so that neither scipy nor f2py copies it once more
    (the same call, bit for bit; a third less time per Newton step on 10⁴ nodes)."""
    gbsv, = get_lapack_funcs(("gbsv",), (ab, b))
    lu = np.zeros((10, ab.shape[1]), order="F")
    lu[3:] = ab
    _, _, x, info = gbsv(3, 3, lu, b, overwrite_ab=True)
    if info > 0:
        raise LinAlgError("singular matrix")
    if info < 0:
        raise ValueError(f"illegal value in {-info}-th argument of internal gbsv")
    return x


def _frames(tangents: np.ndarray) -> np.ndarray:
    """Two unit normals per node, transported along the nodes without twist: shape (n, 3, 2).

    The first normal is carried from node to node by projecting it onto the next normal plane,
    n_i ∝ (I − a_i a_iᵀ) n_{i−1}, so n_i ∝ P_i ⋯ P_1 n_0: the prefix products of the projections
    are formed in log₂(n) vectorised doubling passes (Hillis–Steele scan), each rescaled (only the
    direction counts), instead of a Python loop over the nodes (50 000 on a 1 km route).
    """
    n = len(tangents)
    a0 = tangents[0]
    first = np.cross(_E_Z, a0)
    if np.linalg.norm(first) < 1e-8:
        first = np.cross([1.0, 0.0, 0.0], a0)
    n0 = first / np.linalg.norm(first)
    prefix = np.eye(3)[None] - tangents[:, :, None] * tangents[:, None, :]
    shift = 1
    while shift < n:
        prefix[shift:] = prefix[shift:] @ prefix[:-shift]   # the right side is read before the write
        prefix /= np.linalg.norm(prefix, axis=(1, 2))[:, None, None]
        shift *= 2
    n1 = prefix @ n0
    n1 /= _row_norm(n1)[:, None]
    out = np.empty((n, 3, 2))
    out[:, :, 0] = n1
    out[:, :, 1] = np.cross(tangents, n1)
    return out


class _Chain:
    """Geometry and equations of the node chain (see the module docstring)."""

    def __init__(self, centre_pts, tangents, frames, clearance, w, mu, k):
        self.C = centre_pts
        self.a = tangents
        self.B = frames
        self.c = clearance
        self.w = w
        self.mu = mu
        self.k = k
        self.n = len(centre_pts)
        self.BlBr = np.matmul(frames[:-1].transpose(0, 2, 1), frames[1:])   # B_jᵀ B_{j+1}, shape (n − 1, 2, 2)

    def positions(self, d):
        return self.C + np.einsum("ijk,ik->ij", self.B, d)

    def segments(self, x):
        dx = np.diff(x, axis=0)
        ell = _row_norm(dx)
        return dx / ell[:, None], ell

    def energy(self, d, T, G):
        x = self.positions(d)
        _, ell = self.segments(x)
        r = _row_norm(d)
        pen = np.maximum(r - self.c, 0.0)
        return float(T @ ell - np.sum(G * x) + 0.5 * self.k * pen @ pen)

    def gradient_hessian(self, d, T, G):
        """Gradient [N] of the shape energy in the offsets, shape (2n,), and its Hessian [N/m] in
        LAPACK band storage, shape (7, 2n): node i's offsets couple only with nodes i ± 1, so the
        Hessian is a band of half-width 3 (:func:`_solve_band`)."""
        n = self.n
        x = self.positions(d)
        t, ell = self.segments(x)
        fx = np.zeros((n, 3))            # ∂E/∂x_i
        fx[:-1] -= T[:, None] * t
        fx[1:] += T[:, None] * t
        fx -= G
        g = np.einsum("ijk,ij->ik", self.B, fx)
        r = _row_norm(d)
        over = r > self.c
        dhat = np.divide(d, r[:, None], out=np.zeros_like(d), where=over[:, None])   # masked: no row gathers
        g += self.k * np.maximum(r - self.c, 0.0)[:, None] * dhat
        # tension stiffness of each segment, K = T/ℓ (I − t tᵀ), mapped to the offsets: the frames are
        # orthonormal, so B_lᵀ K B_l = T/ℓ (I − u_l u_lᵀ) with u = Bᵀ t, and B_lᵀ K B_r = T/ℓ (B_lᵀ B_r − u_l u_rᵀ)
        # (written out per 2 × 2 entry (p, q), with the same floating-point operations as the
        # matrix form: the (n, 2, 2) broadcasts cost twice as much at ~1000 nodes)
        stiff = T / ell
        ul = np.einsum("jki,jk->ji", self.B[:-1], t)
        ur = np.einsum("jki,jk->ji", self.B[1:], t)
        ratio = np.divide(self.c, r, out=np.zeros(n), where=over)
        # band storage: entry (row, col) at ab[3 + row − col, col]; node i's columns are 2i + q
        ab = np.zeros((7, 2 * n))
        for p in range(2):
            for q in range(2):
                eye = 1.0 if p == q else 0.0
                diag = np.zeros(n)
                diag[:-1] += stiff * (eye - ul[:, p] * ul[:, q])
                diag[1:] += stiff * (eye - ur[:, p] * ur[:, q])
                # wall penalty k (|d| − c)₊²/2: Hessian k[(1 − c/r) I + (c/r) d̂ d̂ᵀ] outside the wall
                wall = self.k * ((1.0 - ratio) * eye + ratio * dhat[:, p] * dhat[:, q])
                diag = np.where(over, diag + wall, diag)
                Hlr = -stiff * (self.BlBr[:, p, q] - ul[:, p] * ur[:, q])
                ab[3 + p - q, q::2] = diag
                ab[1 + p - q, 2 + q::2] = Hlr              # (2i + p, 2(i + 1) + q)
                ab[5 + q - p, p:2 * n - 2:2] = Hlr         # its transpose
        return g.ravel(), ab

    def solve_shape(self, d, T, G, tol_m):
        """Damped Newton on the convex shape energy; returns (d, iterations)."""
        E = self.energy(d, T, G)
        for it in range(1, _MAX_NEWTON + 1):
            g, ab = self.gradient_hessian(d, T, G)
            # a tiny Levenberg term: free straights without gravity may shift sideways at no cost
            ab[3] += 1e-12 * float(ab[3].max())
            step = -_solve_band(ab, g).reshape(-1, 2)
            slope = float(g @ step.ravel())
            if -slope <= 1e-13 * abs(E):   # the energy cannot resolve a smaller decrease
                return d, it
            # Nodes on the wall move along it (a step along its tangent, then back onto the circle of
            # their present radius): a straight step would cut into the round wall, where the stiff
            # penalty would cut the step to a sliver (observed: 100 Newton steps of 1e-5 m).
            r = _row_norm(d)
            wall = r > self.c
            er = np.divide(d, r[:, None], out=np.zeros_like(d), where=wall[:, None])
            ephi = np.stack([-er[:, 1], er[:, 0]], axis=1)
            dr = np.sum(step * er, axis=1)
            dt = np.sum(step * ephi, axis=1)
            tried = {}

            def energy_at(alpha):
                d_new = d + alpha * step
                if np.any(wall):
                    ang = alpha * dt[wall] / r[wall]
                    rad = r[wall] + alpha * dr[wall]
                    d_new[wall] = rad[:, None] * (np.cos(ang)[:, None] * er[wall] + np.sin(ang)[:, None] * ephi[wall])
                # A free node the step carries through the wall stops just on it (the linear model did not
                # see the wall; taken unclipped, the penalty would cut the step to a sliver for all nodes).
                r_new = _row_norm(d_new)
                hit = ~wall & (r_new > self.c)
                d_new[hit] *= (self.c * (1.0 + _ON_WALL) / r_new[hit])[:, None]
                tried[alpha] = d_new, self.energy(d_new, T, G)
                return tried[alpha][1]

            alpha = armijo_step(energy_at, E, slope, min_step=1e-10)
            d_new, E_new = tried[alpha]
            moved = alpha * float(np.max(np.abs(step)))
            d, E = d_new, E_new
            if moved < tol_m:
                return d, it
        raise ModelError("rope_clearance", f"shape solve did not converge in {_MAX_NEWTON} Newton iterations")

    def march(self, d, trailing_N, T_guess):
        """Tensions and wall reactions from the trailing end, shape frozen (2 × 2 balance per node).

        Node i's balance along the conduit tangent a_i (and, on the wall, along d̂_i) is affine in
        the tension T_{i−1} that the cable brings in, so T_i = p_i T_{i−1} + q_i and ρ_i = α_i T_{i−1}
        + β_i, with (p_i, q_i) those of a free node or of a node on the wall; a node bears on the
        wall where it touches it and ρ_i > 0. The recurrence is solved with cumulative products and
        sums; which nodes bear is taken from ``T_guess`` (the previous pass's segment tensions) and
        corrected until it agrees with the tensions it gives (each round settles at least the first
        node that disagreed; a few rounds in practice), which is the sequential march's answer.
        """
        n, mu = self.n, self.mu
        x = self.positions(d)
        t, ell = self.segments(x)
        r = _row_norm(d)
        contact = r > self.c
        dhat = np.zeros_like(x)
        dhat[contact] = np.einsum("ijk,ik->ij", self.B[contact], d[contact] / r[contact, None])
        half = np.zeros(n)
        half[:-1] += 0.5 * ell
        half[1:] += 0.5 * ell
        W = -self.w * half[:, None] * _E_Z[None, :]
        tau = np.empty((n, 3))
        tau[0], tau[-1] = t[0], t[-1]
        bis = t[:-1] + t[1:]
        tau[1:-1] = bis / _row_norm(bis)[:, None]
        a, e = self.a, dhat
        into = np.concatenate([a[:1], t])          # direction of the force the cable brings into node i
        out = np.concatenate([t, a[-1:]])          # the leading end is pulled along the exit tangent

        def dot(u, v):
            return np.einsum("ij,ij->i", u, v)

        ia, ie, wa, we = dot(into, a), dot(into, e), dot(W, a), dot(W, e)
        oa = dot(out, a)
        # free node: T_i oa = T_{i−1} ia − wa
        p_free, q_free = ia / oa, -wa / oa
        # on the wall: [[oa, −μ τ·a], [oe, −(1 + μ τ·e)]] [T_i, ρ_i] = [T_{i−1} ia − wa, T_{i−1} ie − we]
        m12, m21, m22 = -mu * dot(tau, a), dot(out, e), -(1.0 + mu * dot(tau, e))
        det = oa * m22 - m12 * m21
        p_wall, q_wall = (m22 * ia - m12 * ie) / det, (m12 * we - m22 * wa) / det
        p_rho, q_rho = (oa * ie - m21 * ia) / det, (m21 * wa - oa * we) / det

        T_in = np.concatenate([[trailing_N], T_guess])     # T_{i−1} of each node
        bears = contact & (p_rho * T_in + q_rho > 0.0)
        for _ in range(n):
            p = np.where(bears, p_wall, p_free)
            q = np.where(bears, q_wall, q_free)
            growth = np.cumprod(p)
            T_all = growth * (trailing_N + np.cumsum(q / growth))
            T_in = np.concatenate([[trailing_N], T_all[:-1]])
            now = contact & (p_rho * T_in + q_rho > 0.0)
            if np.array_equal(now, bears):
                break
            bears = now
        rho = np.where(bears, p_rho * T_in + q_rho, 0.0)
        F = -mu * rho[:, None] * tau
        return T_all[:-1], rho, W, F, float(T_all[-1])

    def residual(self, d, T, rho, W, F, trailing_N, pull_N):
        """Largest |node force imbalance| [N] with the wall reactions along −d̂."""
        x = self.positions(d)
        t, _ = self.segments(x)
        r = _row_norm(d)
        dhat = np.zeros_like(x)
        on = r > 0
        dhat[on] = np.einsum("ijk,ik->ij", self.B[on], d[on] / r[on, None])
        res = W + F - rho[:, None] * dhat
        res[:-1] += T[:, None] * t
        res[1:] -= T[:, None] * t
        res[0] -= trailing_N * self.a[0]
        res[-1] += pull_N * self.a[-1]
        return float(np.max(_row_norm(res)))


def solve_rope_with_clearance(centreline, clearance_m: float, friction: float,
                              weight_per_length_N_per_m: float = 0.0, trailing_tension_N: float = 0.0,
                              direction: str = "forward", cable_length_m: float | None = None,
                              node_spacing_m: float | None = None, rtol: float = 1e-10,
                              _coarsen_above: int | None = None, _grid_scale: float = 1.0) -> ClearanceRopeSolution:
    """Steady pull of a perfectly flexible cable through a conduit with clearance (module docstring).

    Parameters
    ----------
    centreline : Centreline
        Conduit centreline (``exucable.geometry``).
    clearance_m : float
        Conduit inner radius − cable radius [m] (> 0; at 0 the centreline rope is the answer).
    friction : float
        Coulomb friction coefficient μ [-].
    weight_per_length_N_per_m : float
        Weight per length w = ρAg [N/m], acting along −z.
    trailing_tension_N : float
        Back tension at the trailing end, along the conduit's tangent there [N].
    direction : {"forward", "reverse"}
        Pulled out at s = L ("forward") or at s = 0 ("reverse").
    cable_length_m : float, optional
        Length of conduit the cable occupies, from the leading end [m]; default the whole conduit.
    node_spacing_m : float, optional
        Uniform spacing of the chain's nodes along the conduit [m]; default the chain of
        :func:`graded_node_grid_m` (:func:`default_node_spacing_m` on routes of 400 m or less, graded
        away from the bends on longer ones). The answer converges as the spacing squared.
    rtol : float
        Relative change of the tensions (and of the shape, in units of the clearance) at which the
        fixed point stops.
    _coarsen_above : int, optional
        Internal: a chain of more segments starts from the solution on a coarser chain (default
        ``_COARSEN_REQUESTED_ABOVE``; the coarser chains' own solves use ``_COARSEN_ABOVE``).
    _grid_scale : float, optional
        Internal: the default grid's spacings times this (the coarser chains of the nested solve).

    Returns
    -------
    ClearanceRopeSolution

    Raises
    ------
    ModelError
        Bad arguments, a cable that runs slack (tension ≤ 0: not modelled here), or no convergence.
    """
    mu, w, c = float(friction), float(weight_per_length_N_per_m), float(clearance_m)
    for key, v in (("friction", mu), ("weight_per_length_N_per_m", w), ("trailing_tension_N", trailing_tension_N)):
        if not np.isfinite(v) or v < 0:
            raise ModelError(key, f"must be finite and >= 0, got {v!r}")
    if not np.isfinite(c) or c <= 0:
        raise ModelError("clearance_m", f"must be > 0 (use exucable.quasistatic.rope for no clearance), got {clearance_m!r}")
    if direction not in ("forward", "reverse"):
        raise ModelError("direction", f"must be 'forward' or 'reverse', got {direction!r}")
    curve = centreline if direction == "forward" else centreline.reversed()
    L = float(curve.length_m)
    length = L if cable_length_m is None else float(cable_length_m)
    if not (0 < length <= L * (1 + 1e-12)):
        raise ModelError("cable_length_m", f"must be in (0, {L:g}] m, got {cable_length_m!r}")
    if node_spacing_m is None:
        s = graded_node_grid_m(curve, max(L - length, 0.0), L, c, scale=_grid_scale)
    else:
        h = float(node_spacing_m)
        if not np.isfinite(h) or h <= 0:
            raise ModelError("node_spacing_m", f"must be > 0, got {node_spacing_m!r}")
        s = np.linspace(max(L - length, 0.0), L, max(int(np.ceil(length / h)), 4) + 1)
    n_seg = len(s) - 1
    centre = np.asarray(curve.point(s), dtype=float)
    a = np.asarray(curve.tangent(s), dtype=float)
    frames = _frames(a)
    seg = np.diff(s)
    uniform = bool(np.ptp(seg) <= 1e-9 * seg[0])
    if uniform:
        # a uniform chain's spacing, weights and coarser chain exactly as they always were
        hs = length / n_seg
        seg = np.full(n_seg, hs)
        weight_length = np.full(n_seg + 1, hs)
    else:
        hs = float(np.min(seg))       # the finest segment: it sets the wall's stiffness
    share = np.zeros(n_seg + 1)       # the length of conduit each node stands for [m]
    share[:-1] += 0.5 * seg
    share[1:] += 0.5 * seg
    if not uniform:
        weight_length = share

    # start: capstan growth over the bends plus friction and lift of the weight (a rough upper guess)
    kappa = np.linalg.norm(np.asarray(curve.curvature_vector(s), dtype=float), axis=1)
    Tb = float(trailing_tension_N)
    T_nodes = Tb * np.exp(mu * np.concatenate([[0.0], np.cumsum(0.5 * (kappa[1:] + kappa[:-1]) * seg)]))
    T_nodes = T_nodes + w * (mu + 1.0) * (s - s[0])
    T = 0.5 * (T_nodes[1:] + T_nodes[:-1])
    T_ref = max(float(np.max(T)), w * length, 1e-9)
    k_wall = _PENALTY * T_ref / hs
    chain = _Chain(centre, a, frames, c, w, mu, k_wall)
    # start each node on the wall the centreline rope's load presses it against (T κn − w e_z, across)
    load = T_nodes[:, None] * np.asarray(curve.curvature_vector(s), dtype=float) - w * _E_Z[None, :]
    d = np.einsum("ijk,ij->ik", frames, load)
    size = _row_norm(d)
    pressed = size > 1e-12 * T_ref
    d[pressed] *= (c * (1.0 + _ON_WALL) / size[pressed])[:, None]
    d[~pressed] = 0.0
    G = np.zeros((n_seg + 1, 3))
    G[:, 2] = -w * weight_length
    newton = 0
    ramp = True
    if n_seg > (_COARSEN_REQUESTED_ABOVE if _coarsen_above is None else _coarsen_above):
        # Nested iteration: the same problem on a chain _COARSEN times coarser places the free spans and
        # the tensions to within a few of these nodes, from where few Newton steps finish (a free span's
        # end moves about one node per step; on 1 km, 50 000 nodes, the fine chain needed ~110 steps).
        coarse = solve_rope_with_clearance(centreline, clearance_m, friction, weight_per_length_N_per_m,
                                           trailing_tension_N, direction, cable_length_m,
                                           _COARSEN * hs if uniform else None, rtol,
                                           _coarsen_above=_COARSEN_ABOVE, _grid_scale=_COARSEN * _grid_scale)
        s_c = coarse.s_conduit_m if direction == "forward" else L - coarse.s_conduit_m
        order = np.argsort(s_c)
        off = np.stack([np.interp(s, s_c[order], coarse.offset_m[order, j]) for j in range(3)], axis=1)
        d = np.einsum("ijk,ij->ik", frames, off)
        on_wall = np.interp(s, s_c[order], coarse.in_contact[order].astype(float)) >= 0.5
        size = _row_norm(d)
        d[on_wall] *= (c * (1.0 + _ON_WALL) / np.maximum(size[on_wall], 1e-300))[:, None]
        T_node = np.interp(s, s_c[order], coarse.tension_N[order])
        T = 0.5 * (T_node[1:] + T_node[:-1])
        newton, ramp = coarse.newton_iterations, False
    for passes in range(1, _MAX_PASSES + 1):
        if np.min(T) <= 0.0:
            raise ModelError("rope_clearance", "the cable runs slack (tension <= 0); the rope with clearance "
                             "models taut cables only")
        # The first pass stiffens the wall from soft to full in decades: a soft wall lets Newton move the
        # ends of the free spans by many nodes per step (at full stiffness they move ~1 node per step).
        d_new = d
        for k in (k_wall * np.logspace(-4, 0, 5) if passes == 1 and ramp else [k_wall]):
            chain.k = k
            d_new, it = chain.solve_shape(d_new, T, G, max(1e-3 * rtol, 1e-10) * c)
            newton += it
        T_new, rho, W, F, pull = chain.march(d_new, Tb, T)
        change = max(float(np.max(np.abs(T_new - T))) / T_ref, float(np.max(np.abs(d_new - d))) / c)
        d, T, G = d_new, T_new, W + F
        if change < rtol:
            break
    else:
        raise ModelError("rope_clearance", f"no fixed point in {_MAX_PASSES} passes (last change {change:.3g})")

    x = chain.positions(d)
    offset = x - centre
    r = _row_norm(d)
    node_T = np.concatenate([[Tb], 0.5 * (T[1:] + T[:-1]), [pull]])
    s_out = s if direction == "forward" else L - s
    return ClearanceRopeSolution(
        s_conduit_m=s_out, offset_m=offset, position_m=x, tension_N=node_T, contact_force_N=rho,
        sidewall_pressure_N_per_m=rho / share, in_contact=rho > 0.0, pull_force_N=pull,
        trailing_tension_N=Tb, clearance_m=c, passes=passes, newton_iterations=newton,
        residual_N=chain.residual(d, T, rho, W, F, Tb, pull))
