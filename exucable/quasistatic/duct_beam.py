"""A stiff cable in a circular duct, linearised about the centreline: the gravity terms of the
bending-stiffness estimate. Pure numpy/scipy; no Exudyn, no contact kernel.

Why a model of its own. The in-plane stiff-bend model (:mod:`exucable.quasistatic.stiff_bend`) predicts what
bending stiffness EJ changes at a bend without gravity. With gravity the cable lies on the floor of
the straights; on a horizontal bend the rope (EJ → 0) rides up the floor's trough to the bend's
inner wall, but a stiff cable cannot follow: it crosses from the floor to the contact on the inner
wall in a free span over both the lateral and the vertical clearance, and its straight lies on the
trough's far side, where the floor pushes it back against the bend's pressure. On a down-bend its
weight holds it on a floor that curves away beneath it. Neither has a closed form; this model
solves them with the same few assumptions as the rope's and nothing of exucable's beam or contact.

The model. The cable's axis is ``r(x) = C(x) + y(x) e_y + z(x) e_z``: ``C`` the conduit's
centreline at arc length ``x``, ``e_y`` its horizontal normal (to the left of the pull), ``e_z`` its
upward normal, ``d = (y, z)`` the offset, ``|d| ≤ c`` the wall. For offsets and slopes small
(``c κ₀ ≪ 1``, ``|d′| ≪ 1``; here c/R ≤ 0.03 and |d′| ≲ 0.3 at a tight bend's ends) the cable's
curvature vector is ``κ₀ e_b + d″`` (``κ₀`` the centreline's curvature, ``e_b`` towards its centre) and
its length ``∫ (1 − κ₀ e_b·d + |d′|²/2) dx``. With the tension ``T(x)`` frozen, the offsets minimise
the convex energy

    Π(d) = ∫ [ EJ/2 |κ₀ e_b + d″|² + T (|d′|²/2 − κ₀ e_b·d) − w_n·d + k/2 (|d| − c)₊² ] dx,

whose Euler–Lagrange equation is the beam under tension on the wall,
``EJ (κ₀ e_b + d″)″ − (T d′)′ − T κ₀ e_b = w_n + f`` (``w_n`` the weight's normal part, ``f`` the wall's
reaction; with EJ = 0 the string of paper Sect. 2.6). The wall is a stiff penalty ``k``. Then the
tension is marched from the trailing end: ``dT/dx = μ |f| + w dH/dx`` (Coulomb friction against the
sliding, along x; ``H`` the centreline's height: the weight lifted or lowered in steady sliding).
Shape and tension alternate to a fixed point, as in :mod:`exucable.quasistatic.clearance`. Central
differences on nodes ``h`` apart; the answer converges in h (a point load lands on a node).

Its closed-form limits (``tests/test_duct_beam.py``): the capstan ``T_in e^{μθ}`` on a bend without
gravity at EJ = 0 (paper Eq. 26), ``T_in + μ w L`` on a level straight (Eq. 25), no change of the
tension without friction, and the stiff bend's point load ``√(EJ T)/ρ`` at ``λ = √(EJ/T)`` into a bend
(:func:`exucable.quasistatic.stiff_bend.stiff_bend` at first order). Being linearised, it gets the in-plane
stiff bend's own second-order change (``−(1 + μ²) EJ/(2ρ²)(1/T_in − 1/T_out)``) only roughly: use
it for what gravity *changes* (:func:`gravity_change_of_stiffness`), which is first order in the
offsets it solves for.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.linalg import solveh_banded

from .newton import armijo_step

__all__ = ["DuctBeamSolution", "duct_route", "solve_duct_beam", "gravity_change_of_stiffness"]

# Wall penalty k = _PENALTY · T_ref / (h c): a bend's load T/R then sinks the cable ~h/(R _PENALTY)·c,
# a point load P ~ √(EJ T)/ρ on one node ~ P/(T _PENALTY)·c: a few 1e-5 of the clearance.
_PENALTY = 1.0e4
_MAX_PASSES = 200
_MAX_NEWTON = 200


@dataclass(frozen=True)
class DuctRoute:
    """A planar route sampled at nodes: what the model needs of the conduit.

    Attributes
    ----------
    x_m : ndarray, shape (n + 1,)
        Node arc lengths along the centreline [m], ``h`` apart.
    curvature_1_per_m : ndarray, shape (n + 1, 2)
        ``κ₀ e_b`` in (e_y, e_z) [1/m] (the fraction of each node's cell inside a bend).
    up_component : ndarray, shape (n + 1,)
        World-up's component along e_z (cos of the centreline's inclination β).
    height_m : ndarray, shape (n + 1,)
        Centreline height H above the start [m].
    """

    x_m: np.ndarray
    curvature_1_per_m: np.ndarray
    up_component: np.ndarray
    height_m: np.ndarray

    @property
    def spacing_m(self) -> float:
        return float(self.x_m[1] - self.x_m[0])


def duct_route(path, node_spacing_m: float) -> DuctRoute:
    """Sample a planar path (the scenario's ``conduit.path`` form) at nodes about ``node_spacing_m`` apart.

    Parameters
    ----------
    path : sequence of dict
        ``{"straight": L [m]}`` or ``{"bend": angle [deg], "radius": R [m], "turn": "left" | "right" |
        "up" | "down"}``. Horizontal turns need a level route (no up/down turn in the same path).
    node_spacing_m : float
        Wanted node spacing h [m]; the route's length is split into equal cells.
    """
    turns = {p.get("turn") for p in path if "bend" in p}
    if turns & {"left", "right"} and turns & {"up", "down"}:
        raise ValueError("path: the linearised duct model takes a level route (left/right turns) or a vertical "
                         "one (up/down turns), not both")
    lengths = [p["straight"] if "straight" in p else math.radians(p["bend"]) * p["radius"] for p in path]
    total = float(sum(lengths))
    n = max(int(math.ceil(total / node_spacing_m)), 8)
    x = np.linspace(0.0, total, n + 1)
    h = total / n
    kappa = np.zeros((n + 1, 2))
    incline = np.zeros(n + 1)           # inclination β at the node [rad]
    start, beta0 = 0.0, 0.0
    cells_lo, cells_hi = np.maximum(x - h / 2, 0.0), np.minimum(x + h / 2, total)
    for p, length in zip(path, lengths):
        end = start + length
        inside = np.clip(np.minimum(cells_hi, end) - np.maximum(cells_lo, start), 0.0, None) / (cells_hi - cells_lo)
        u = np.clip(x - start, 0.0, length)
        if "bend" in p:
            turn = p.get("turn", "left")
            sign = {"left": (1.0, 0.0), "right": (-1.0, 0.0), "up": (0.0, 1.0), "down": (0.0, -1.0)}[turn]
            kappa += np.outer(inside, sign) / p["radius"]
            on = (x >= start) & (x <= end) if p is path[-1] else (x >= start) & (x < end)
            if turn in ("up", "down"):
                incline[on] = beta0 + sign[1] * u[on] / p["radius"]
                beta0 += sign[1] * math.radians(p["bend"])
        else:
            on = (x >= start) & (x <= end)
            incline[on] = beta0
        start = end
    height = np.concatenate([[0.0], np.cumsum(0.5 * (np.sin(incline[1:]) + np.sin(incline[:-1])) * h)])
    return DuctRoute(x_m=x, curvature_1_per_m=kappa, up_component=np.cos(incline), height_m=height)


@dataclass(frozen=True, eq=False)
class DuctBeamSolution:
    """Steady sliding of the linearised stiff cable (:func:`solve_duct_beam`).

    Attributes
    ----------
    x_m : ndarray
        Node arc lengths along the centreline [m].
    offset_m : ndarray, shape (n + 1, 2)
        (y, z) offsets from the centreline [m] (e_y left of the pull, e_z up).
    tension_N : ndarray
        Tension at the nodes [N].
    wall_force_N : ndarray
        Wall reaction on each node [N] (its cell's; 0 off the wall).
    pull_force_N : float
        Tension at the leading end [N].
    passes : int
        Shape/tension passes of the fixed point.
    """

    x_m: np.ndarray
    offset_m: np.ndarray
    tension_N: np.ndarray
    wall_force_N: np.ndarray
    pull_force_N: float
    passes: int


def _difference_operators(n: int, h: float):
    """First differences (n × n+1) and second differences at interior nodes (n−1 × n+1)."""
    d1 = sp.diags([-np.ones(n), np.ones(n)], [0, 1], shape=(n, n + 1)) / h
    d2 = sp.diags([np.ones(n - 1), -2.0 * np.ones(n - 1), np.ones(n - 1)], [0, 1, 2], shape=(n - 1, n + 1)) / h**2
    return d1.tocsr(), d2.tocsr()


def _upper_bands(quad) -> np.ndarray:
    """The symmetric pentadiagonal ``quad`` (one per component) as the upper bands of the interleaved
    (y₀, z₀, y₁, z₁, …) system, ``solveh_banded``'s layout (half-bandwidth 4)."""
    m = quad.shape[0]
    ab = np.zeros((5, 2 * m))
    for k in range(3):
        diag = quad.diagonal(k)
        for a in range(2):
            ab[4 - 2 * k, 2 * k + a::2] = diag
    return ab


def solve_duct_beam(path, clearance_m: float, friction: float, weight_N_per_m: float, back_tension_N: float,
                    bending_stiffness_N_m2: float, node_spacing_m: float = 0.005, head_offset_m=None,
                    rtol: float = 1e-9) -> DuctBeamSolution:
    """Steady pull of the linearised stiff cable through a planar route (module docstring).

    Parameters
    ----------
    path : sequence of dict
        The route (:func:`duct_route`); pulled from its start to its end.
    clearance_m : float
        c = conduit inner radius − cable radius [m] (> 0).
    friction : float
        Coulomb μ.
    weight_N_per_m : float
        w [N/m], acting straight down (0: no gravity).
    back_tension_N : float
        T at the trailing end [N] (> 0).
    bending_stiffness_N_m2 : float
        EJ [N m²] (≥ 0; 0 is the rope with clearance, linearised).
    node_spacing_m : float
        h [m]; resolve λ = √(EJ/T) with several nodes.
    head_offset_m : (float, float), optional
        Hold the leading end at this (y, z) offset (as exucable's rig holds the head where the rope
        with clearance put it); default free, as the trailing end.
    rtol : float
        Relative change of the pulling force at which the fixed point stops.
    """
    if back_tension_N <= 0.0:
        raise ValueError(f"back_tension_N must be > 0, got {back_tension_N}")
    if clearance_m <= 0.0:
        raise ValueError(f"clearance_m must be > 0, got {clearance_m}")
    route = duct_route(path, node_spacing_m)
    x, h = route.x_m, route.spacing_m
    n = len(x) - 1
    cell = np.full(n + 1, h)
    cell[[0, -1]] = h / 2
    kappa = route.curvature_1_per_m
    weight = np.zeros((n + 1, 2))
    weight[:, 1] = -weight_N_per_m * route.up_component          # w_n along e_z
    d1, d2 = _difference_operators(n, h)
    ej, c = bending_stiffness_N_m2, clearance_m
    k_wall = _PENALTY * back_tension_N / (h * c)
    bend_term = ej * h * (d2.T @ kappa[1:-1])                      # ∂/∂d of EJ/2 ∫|κ₀ e_b|² cross term
    stiff_bending = (ej * h) * (d2.T @ d2)
    head = None if head_offset_m is None else np.asarray(head_offset_m, dtype=float)
    k_head = 1e3 * k_wall * h

    tension = np.full(n + 1, float(back_tension_N))
    d = np.zeros((n + 1, 2))
    pull, passes = None, 0
    reg = 1e-11 * back_tension_N / h                               # the free chain's translation
    for passes in range(1, _MAX_PASSES + 1):
        seg_t = 0.5 * (tension[1:] + tension[:-1])
        quad = (stiff_bending + d1.T @ sp.diags(seg_t * h) @ d1 + reg * sp.eye(n + 1)).tocsr()  # y and z alike
        lin = -(tension * cell)[:, None] * kappa - weight * cell[:, None] + bend_term
        bands = _upper_bands(quad)

        def energy(dd):
            r = np.linalg.norm(dd, axis=1)
            e = 0.5 * np.sum(dd * (quad @ dd)) + np.sum(lin * dd) + 0.5 * np.sum(k_wall * cell * np.clip(r - c, 0.0, None) ** 2)
            if head is not None:
                e += 0.5 * k_head * np.sum((dd[-1] - head) ** 2)
            return e

        for _ in range(_MAX_NEWTON):
            r = np.linalg.norm(d, axis=1)
            over = np.clip(r - c, 0.0, None)
            scale = k_wall * cell * over / np.maximum(r, 1e-300)
            grad = quad @ d + lin + scale[:, None] * d
            # wall Hessian per node k (uuᵀ + (r − c)/r (I − uuᵀ)), u = d/r: convex
            u = d / np.maximum(r, 1e-300)[:, None]
            touching = (over > 0.0) * k_wall * cell
            frac = over / np.maximum(r, 1e-300)
            hyy = touching * (u[:, 0] ** 2 + frac * (1.0 - u[:, 0] ** 2))
            hzz = touching * (u[:, 1] ** 2 + frac * (1.0 - u[:, 1] ** 2))
            hyz = touching * (1.0 - frac) * u[:, 0] * u[:, 1]
            if head is not None:
                grad[-1] += k_head * (d[-1] - head)
                hyy[-1] += k_head
                hzz[-1] += k_head
            ab = bands.copy()
            ab[4, 0::2] += hyy
            ab[4, 1::2] += hzz
            ab[3, 1::2] += hyz
            step = -solveh_banded(ab, grad.ravel()).reshape(-1, 2)
            if np.max(np.abs(step)) <= 1e-9 * c:      # converged: this last (full) step makes the residual ~0
                d = d + step
                break
            slope = float(np.sum(grad * step))
            t = armijo_step(lambda a: energy(d + a * step), energy(d), slope, min_step=1e-6)
            d = d + t * step
        r = np.linalg.norm(d, axis=1)
        wall = k_wall * cell * np.clip(r - c, 0.0, None)
        # march from the trailing end: each node's friction as the cable passes it, the weight lifted
        seg = back_tension_N + np.cumsum(friction * wall[:-1]) + weight_N_per_m * (route.height_m[1:] - route.height_m[0])
        new_pull = float(back_tension_N + friction * np.sum(wall) + weight_N_per_m * (route.height_m[-1] - route.height_m[0]))
        tension = np.concatenate([[back_tension_N], 0.5 * (seg[1:] + seg[:-1]), [new_pull]])
        if pull is not None and abs(new_pull - pull) <= rtol * new_pull:
            pull = new_pull
            break
        pull = new_pull
    else:
        raise RuntimeError(f"duct beam: the shape/tension fixed point did not settle in {_MAX_PASSES} passes")
    return DuctBeamSolution(x_m=x, offset_m=d, tension_N=tension, wall_force_N=wall, pull_force_N=pull,
                            passes=passes)


def gravity_change_of_stiffness(path, clearance_m: float, friction: float, weight_N_per_m: float,
                                back_tension_N: float, bending_stiffness_N_m2: float,
                                node_spacing_m: float = 0.005) -> float:
    """What gravity changes in the stiff cable's pull against the rope with clearance [relative].

    ``(F_EJ/F_0)|_w − (F_EJ/F_0)|_{w=0}`` of the linearised model (F_0 its EJ = 0 rope with
    clearance, F_EJ the stiff cable with its head held where that rope's head lies): the term to
    add to the in-plane stiff bend (:func:`exucable.quasistatic.stiff_bend.stiff_bend`) on a route with
    gravity. Four solves.
    """
    ratio = []
    for w in (weight_N_per_m, 0.0):
        rope = solve_duct_beam(path, clearance_m, friction, w, back_tension_N, 0.0, node_spacing_m)
        stiff = solve_duct_beam(path, clearance_m, friction, w, back_tension_N, bending_stiffness_N_m2,
                                node_spacing_m, head_offset_m=rope.offset_m[-1])
        ratio.append(stiff.pull_force_N / rope.pull_force_N)
    return ratio[0] - ratio[1]
