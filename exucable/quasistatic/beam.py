"""A stiff cable in its conduit, touching either wall: three-point bending.
numpy and scipy only; no Exudyn.

:mod:`exucable.quasistatic.stiff_bend` lands the free span of a stiff cable on the bend's inner wall and
assumes the span's straight then fits in the conduit, i.e. its offset λ²/(2ρ) from the rope's line
(λ = √(EJ/T)) stays within the 2c across it. Beyond that the span also presses the straight's
opposite wall — the three-point bending of Iordanescu & Tamowski's PULLFLEX (IEEE Trans. Power
Delivery 11(2), 1996) — with friction of its own; and with gravity the span's straight, pushed
towards the outer wall, climbs the round conduit's floor, which pushes back. This module solves
both without assuming where the cable touches: an independent steady beam-in-conduit model,
discretised differently from exucable's ANCF elements.

**Model.** Steady sliding seen in space (as :mod:`exucable.quasistatic.clearance`): the cable's shape is
fixed and its material runs through it. Nodes ``i`` sit at fixed centreline arc lengths σ_i (spacing
h) of a horizontal route (straights and arcs of signed curvature κ₀). Segment j has tension T_j and
unit direction t_j; bending costs EJ φ_i²/(2h) at node i (φ_i its turning angle; a discrete
elastica of curvature φ_i/h). Two variants:

- *3D* (default with gravity, ``three_d``): node i moves in its normal plane, offset d_i (along the
  bend plane's normal n and up) inside the round conduit |d| ≤ c (a stiff penalty, smoothed over
  1e-4 c so Newton does not chatter); its weight w h is a body force, so the cable rests on the
  floor, climbs the wall where the bend pulls it, lifts off in free spans (the rope with
  clearance's) and bridges the floor with its stiffness. Bending energy (EJ/h) Σ (1 − t_{i−1}·t_i).
- *planar* (without gravity): node i moves along n only, walls at d = ±c; a weight, if given, acts
  as the trough's potential w (c − √(c² − d²)) and presses the floor with √(f² + w²) (kept for
  comparison: it overstates the gravity part, not bridging the floor).
- *planar, vertical route* (``vertical``): the route lies in a vertical plane, so the weight w h is
  a body force in the bend plane and the walls at ±c are the floor and the roof: the cable lies on
  the straights' floor, crosses to an up-bend's roof in free spans, rests on a down-bend's floor.

Coulomb friction μ |contact| acts against the sliding direction (the bisector of t_{i−1} and t_i;
Eq. 19 of Yang et al. 2013). Two sub-problems alternate until the pulling force settles (as in
:mod:`exucable.quasistatic.clearance`): (1) the *shape*: with tensions and friction frozen, the offsets
minimise Σ T_j ℓ_j + bending + wall and weight potentials − friction · x — damped Newton on the
normal-plane balance, its banded Jacobian by finite differences in colours, an energy line search;
(2) the *tensions*: march from the trailing end solving each node's balance along the sliding
direction for the next segment's tension (bending and wall forces included).

The trailing end is free (back tension along the entry straight); the leading end either free
too (a long exit straight) or pinned where exucable's steady rig holds it (its rope-with-clearance
position, 10 bending lengths past the last bend: :func:`exucable.model.layout.steady_lead_out_m`).
Stiff cables are reached by continuation in EJ from λ ≈ h (where the rope's path, on the inner
wall of each bend and the floor, is a good start).

Limits (``tests/test_beam_conduit.py``): λ = h gives the capstan on a bend without gravity (1e-4)
and, in 3D with gravity, the rope with clearance (:mod:`exucable.quasistatic.clearance`, 2e-4); small λ/ρ
with the span inside the conduit gives :func:`exucable.quasistatic.stiff_bend.stiff_bend` (within 10 % of its
−0.24 %); μ = 0 on a vertical route gives T_b + w ΔH; an up-bend's free spans give
:func:`exucable.quasistatic.stiff_bend.free_span_stiffness_N` (:func:`gravity_change_of_stiffness`). What it leaves out: torsion, the cable's extension, and dynamics; the prediction used is
the *ratio* of the stiff cable's pull to the model's own λ = h limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import solve_banded

from .newton import armijo_step, banded_jacobian

__all__ = ["PlanarBeamSolution", "solve_planar_beam", "stiff_route_difference", "route_pieces", "path_pieces",
           "gravity_change_of_stiffness"]

# Wall penalty per node = _PENALTY · T_ref / h: node loads of a bend end (~√(EJ T)/ρ) penetrate
# ~1e-4 of the clearance.
_PENALTY = 1.0e3
# The trough's lateral force w d/√(c² − d²) is continued linearly beyond this fraction of c (so
# it stays finite at the wall, where the penalty takes over).
_TROUGH_LINEAR_FROM = 0.98
_TOL_PULL = 1e-9
# In 3D the cable lifts off and lands on the floor node by node, and the penalty's kinks stall Newton
# near round-off: a residual of 1e-6 of the tension (~1e-4 N here, against node weights of ~0.02 N)
# moves the pull by ~1e-7, far below the 1e-4 the model is read at.
_SHAPE_TOL_3D = 1e-6
_TOL_PULL_3D = 1e-7
_SHAPE_STALL_3D = 1e-4
_SMOOTH_3D = 1e-4


class BeamConduitError(RuntimeError):
    """The beam-in-conduit model did not converge (names the stage and the stiffness)."""


def _centreline(pieces, h):
    """Nodes of a planar route of (length_m, curvature_1_per_m) pieces: stations σ [m], points
    C [m], unit tangents and left normals, node curvature (of the piece starting there)."""
    ends = np.concatenate([[0.0], np.cumsum([length for length, _ in pieces])])
    sig = np.linspace(0.0, ends[-1], max(4, int(round(ends[-1] / h))) + 1)
    points = np.zeros((sig.size, 2))
    theta = np.zeros(sig.size)
    start, heading = np.zeros(2), 0.0
    for (length, k), a, b in zip(pieces, ends[:-1], ends[1:]):
        m = (sig >= a - 1e-12) & (sig <= b + 1e-12)
        u = sig[m] - a
        if k == 0.0:
            points[m] = start + np.outer(u, [math.cos(heading), math.sin(heading)])
            start = start + length * np.array([math.cos(heading), math.sin(heading)])
        else:
            points[m, 0] = start[0] + (np.sin(heading + k * u) - math.sin(heading)) / k
            points[m, 1] = start[1] - (np.cos(heading + k * u) - math.cos(heading)) / k
            start = start + np.array([math.sin(heading + k * length) - math.sin(heading),
                                      -(math.cos(heading + k * length) - math.cos(heading))]) / k
        theta[m] = heading + k * u
        heading += k * length
    tangent = np.stack([np.cos(theta), np.sin(theta)], 1)
    normal = np.stack([-np.sin(theta), np.cos(theta)], 1)
    kappa = np.array([pieces[min(np.searchsorted(ends, s, side="right") - 1, len(pieces) - 1)][1] for s in sig])
    return sig, points, tangent, normal, kappa


@dataclass
class PlanarBeamSolution:
    """Steady state of :func:`solve_planar_beam`.

    Attributes
    ----------
    pull_force_N : float
        Tension at the leading end [N].
    station_m, offset_m : numpy.ndarray
        Node stations along the centreline and the cable axis' offset along the left normal [m].
    tension_N : numpy.ndarray
        Segment tensions [N].
    contact_N : numpy.ndarray
        Contact force per node (lateral wall/trough force with the weight) [N].
    passes : int
        Shape/tension passes to convergence.
    """

    pull_force_N: float
    station_m: np.ndarray
    offset_m: np.ndarray
    tension_N: np.ndarray
    contact_N: np.ndarray
    passes: int


class _Chain:
    space_dim = 2          # node positions' dimension (the frozen friction forces' shape)
    dofs = 1               # unknowns per node: the offset along n
    pull_tol = _TOL_PULL
    shape_tol = 1e-8       # lateral residual / T_ref at which the shape is converged
    stall_move = 1e-12     # a step below this fraction of c is a stall
    residual_name = "lateral"

    def __init__(self, pieces, clearance_m, friction, weight_N_per_m, bending_stiffness_N_m2, back_tension_N,
                 spacing_m, head_offset_m=None, trough_weight_N_per_m=None, tension_scale_N=None, vertical=False):
        self.sig, self.C, self.e, self.n, self.kap = _centreline(pieces, spacing_m)
        self.N = self.sig.size
        self.h = float(np.diff(self.sig).mean())
        self.c, self.mu, self.w, self.EJ = clearance_m, friction, weight_N_per_m, bending_stiffness_N_m2
        self.Tb = back_tension_N
        self.Tref = tension_scale_N or back_tension_N
        # a vertical route: the weight acts in the bend plane (world-up is the start's left normal,
        # +y), through the walls at ±c; no trough across the plane and no floor load out of it
        self.vertical = vertical
        self.w_plane = weight_N_per_m if vertical else 0.0
        self.w_out = 0.0 if vertical else weight_N_per_m
        default_trough = 0.0 if vertical else weight_N_per_m
        self.wt = default_trough if trough_weight_N_per_m is None else trough_weight_N_per_m
        self.head = head_offset_m
        self.K = _PENALTY * self.Tref / self.h
        self.hbar = np.full(self.N, self.h)
        self.hbar[[0, -1]] = self.h / 2
        c, d1 = self.c, self.c * _TROUGH_LINEAR_FROM
        self.d1, self.f1 = d1, self.wt * d1 / math.sqrt(c * c - d1 * d1)
        self.k1 = self.wt * c * c / (c * c - d1 * d1) ** 1.5
        self.e1 = self.wt * (c - math.sqrt(c * c - d1 * d1))

    def wall_force(self, d):
        """Lateral node force along n [N]: trough (weight) and wall penalty."""
        a = np.abs(d)
        trough = np.where(a <= self.d1, self.wt * a / np.sqrt(self.c ** 2 - np.minimum(a, self.d1) ** 2),
                          self.f1 + self.k1 * (a - self.d1))
        return -np.sign(d) * (trough * self.hbar + self.K * np.maximum(a - self.c, 0.0))

    def wall_energy(self, d):
        a = np.abs(d)
        inside = self.wt * (self.c - np.sqrt(self.c ** 2 - np.minimum(a, self.d1) ** 2))
        outside = self.e1 + self.f1 * (a - self.d1) + 0.5 * self.k1 * (a - self.d1) ** 2
        return float(np.sum(np.where(a <= self.d1, inside, outside) * self.hbar)
                     + 0.5 * self.K * np.sum(np.maximum(a - self.c, 0.0) ** 2))

    def geometry(self, d):
        x = self.C + d[:, None] * self.n
        v = np.diff(x, axis=0)
        length = np.hypot(v[:, 0], v[:, 1])
        beta = np.unwrap(np.arctan2(v[:, 1], v[:, 0]))
        return x, v, length, beta, np.diff(beta)

    def energy(self, d, T, G):
        x, _, length, _, phi = self.geometry(d)
        return float(T @ length + self.EJ / (2 * self.h) * phi @ phi + self.wall_energy(d) - np.sum(G * x)
                     + self.w_plane * float(self.hbar @ x[:, 1]))

    def forces(self, d, T):
        """Tension, bending and wall forces on the nodes (2D) [N], segment directions and lengths."""
        x, v, length, beta, phi = self.geometry(d)
        t = v / length[:, None]
        tension = np.zeros_like(x)
        tension[:-1] += T[:, None] * t
        tension[1:] -= T[:, None] * t
        dE_dbeta = np.zeros(beta.size)
        dE_dbeta[:-1] -= self.EJ / self.h * phi
        dE_dbeta[1:] += self.EJ / self.h * phi
        perp = np.stack([-v[:, 1], v[:, 0]], 1) / (length ** 2)[:, None]
        bending = np.zeros_like(x)
        bending[1:] -= dE_dbeta[:, None] * perp
        bending[:-1] += dE_dbeta[:, None] * perp
        wall = self.wall_force(d)[:, None] * self.n
        wall[:, 1] -= self.w_plane * self.hbar      # the in-plane weight (vertical route), with the wall's force
        return tension, bending, wall, t

    def lateral_residual(self, d, T, G):
        tension, bending, wall, _ = self.forces(d, T)
        return np.einsum("ij,ij->i", tension + bending + wall + G, self.n)

    def offsets(self, flat):
        """The flat vector of unknowns as offsets: (N,) in the plane, (N, 2) in 3D."""
        return flat if self.dofs == 1 else flat.reshape(-1, self.dofs)

    def solve_shape(self, d, T, G, maxit=300):
        """Damped Newton on the offsets (the head's pinned): the lateral balance's banded Jacobian by
        finite differences (:func:`.newton.banded_jacobian`), an energy line search."""
        free = np.ones(d.shape, bool)
        if self.head is not None:
            free[-1] = False
            d[-1] = self.head
        idx = np.flatnonzero(free)
        half_band = 3 * self.dofs - 1          # a node couples with the nodes ±2 (bending)
        flat = d.reshape(-1)

        def residual(x):
            return self.lateral_residual(self.offsets(x), T, G).reshape(-1)[idx]

        def moved(x, step, alpha):
            trial = x.copy()
            trial[idx] += alpha * step
            return trial

        for it in range(maxit):
            r = residual(flat)
            nr = float(np.max(np.abs(r)))
            if nr < self.shape_tol * self.Tref:
                return self.offsets(flat), it
            ab = banded_jacobian(residual, flat, idx, half_band, 1e-7 * self.c, r)
            step = solve_banded((half_band, half_band), ab, -r)
            E0 = self.energy(self.offsets(flat), T, G)
            slope = -float(r @ step)
            if slope > 0.0:      # not a descent direction: fall back to a scaled gradient step
                step = r / np.max(np.abs(ab[half_band]))
                slope = -float(r @ step)
            lam = armijo_step(lambda a: self.energy(self.offsets(moved(flat, step, a)), T, G), E0, slope,
                              slack=1e-12 * abs(E0))
            trial = moved(flat, step, lam)
            if (lam < 1e-9 or np.max(np.abs(trial - flat)) < self.stall_move * self.c) and nr < _SHAPE_STALL_3D * self.Tref:
                return self.offsets(flat), it   # stalled on the penalty's kink, at a residual far below what matters
            flat = trial
        if nr < _SHAPE_STALL_3D * self.Tref:
            return self.offsets(flat), maxit
        raise BeamConduitError(f"shape Newton did not converge in {maxit} iterations at EJ = {self.EJ:.4g} N m^2 "
                               f"({self.residual_name} residual {nr:.3g} N)")

    def march(self, d, T):
        """Tensions from the trailing end, and the frozen friction forces."""
        _, bending, wall, t = self.forces(d, T)
        contact = np.hypot(self.wall_force(d), self.w_out * self.hbar)
        new_T = np.empty_like(T)
        friction_force = np.zeros((self.N, 2))
        prev_T, prev_t = self.Tb, self.e[0]
        for i in range(self.N - 1):
            tau = prev_t + t[i]
            tau /= math.hypot(tau[0], tau[1])
            friction_force[i] = -self.mu * contact[i] * tau
            new_T[i] = (prev_T * (prev_t @ tau) - (bending[i] + wall[i]) @ tau + self.mu * contact[i]) / (t[i] @ tau)
            prev_T, prev_t = new_T[i], t[i]
        friction_force[-1] = -self.mu * contact[-1] * t[-1]
        # the head node's own share of an in-plane weight (a vertical route) is lifted by the pull too
        head_weight = self.w_plane * self.hbar[-1] * t[-1, 1]
        return new_T, friction_force, prev_T + self.mu * contact[-1] + head_weight, contact

    def solve(self, d, soften=False, max_passes=200):
        T = np.full(self.N - 1, self.Tb)
        G = np.zeros((self.N, self.space_dim))
        if soften:       # from a rough start: a soft wall first
            K = self.K
            for f in (1e-3, 1e-2, 1e-1):
                self.K = K * f
                d, _ = self.solve_shape(d, T, G)
            self.K = K
        old = None
        for p in range(max_passes):
            d, _ = self.solve_shape(d, T, G)
            T, G, pull, contact = self.march(d, T)
            if old is not None and abs(pull - old) < self.pull_tol * pull:
                return PlanarBeamSolution(pull, self.sig, d, T, contact, p + 1)
            old = pull
        raise BeamConduitError(f"shape/tension passes did not converge in {max_passes} at EJ = {self.EJ:.4g} N m^2")


def solve_planar_beam(pieces, clearance_m: float, friction: float, weight_N_per_m: float,
                      bending_stiffness_N_m2: float, back_tension_N: float, spacing_m: float,
                      head_offset_m: float | None = None, trough_weight_N_per_m: float | None = None,
                      start_bending_stiffness_N_m2: float | None = None, three_d: bool = False,
                      vertical: bool = False) -> PlanarBeamSolution:
    """Steady pull of a beam through a planar route, by continuation in EJ.

    Parameters
    ----------
    pieces : list of (float, float)
        The route in pull order: (length [m], signed curvature [1/m], > 0 turning left) of the axis'
        reference line (the conduit's centreline).
    clearance_m : float
        c: the axis moves within ±c of the centreline [m].
    friction : float
        μ.
    weight_N_per_m : float
        w, the weight per length [N/m]: pressing the floor of a horizontal route, in the bend plane
        of a ``vertical`` one; 0 without gravity.
    bending_stiffness_N_m2 : float
        EJ [N m²] (> 0).
    back_tension_N : float
        Tension at the trailing end [N] (> 0).
    spacing_m : float
        Node spacing h [m]; resolve the bending length √(EJ/T) with ~10 nodes.
    head_offset_m : float or (float, float), optional
        Pin the leading end at this offset [m] (a rig; with ``three_d`` along n and up); default free.
    trough_weight_N_per_m : float, optional
        The weight that centres the cable in the trough (default ``weight_N_per_m``); a small value
        without gravity fixes the otherwise free lateral position of a straight far from a bend.
    start_bending_stiffness_N_m2 : float, optional
        Where the continuation starts (default T h², λ = h).
    three_d : bool
        Nodes move in their whole normal plane inside the round conduit, under their weight (free
        spans over the floor, the trough bridged by the stiffness); default: in the bend plane only,
        the weight as the trough's potential and floor friction.
    vertical : bool
        The route lies in a vertical plane, turning left = up (world-up is the start's left normal):
        the weight acts in the bend plane on the planar chain (its walls at ±c are the conduit's
        floor and roof; no trough). Not with ``three_d``.

    Returns
    -------
    PlanarBeamSolution
    """
    if bending_stiffness_N_m2 <= 0.0 or back_tension_N <= 0.0 or clearance_m <= 0.0:
        raise ValueError("bending_stiffness_N_m2, back_tension_N and clearance_m must be > 0")
    if vertical and three_d:
        raise ValueError("vertical: the in-plane weight of a vertical route is for the planar chain; "
                         "set three_d=False (the 3D chain's weight is out of the route's plane)")
    args = (pieces, clearance_m, friction, weight_N_per_m)
    kw = dict(head_offset_m=head_offset_m, trough_weight_N_per_m=trough_weight_N_per_m, tension_scale_N=back_tension_N,
              vertical=vertical)
    ej = start_bending_stiffness_N_m2 or min(bending_stiffness_N_m2, back_tension_N * spacing_m ** 2)
    cls = _Chain3D if three_d else _Chain
    chain = cls(*args, ej, back_tension_N, spacing_m, **kw)
    d = np.clip(chain.kap * 1e12, -clearance_m, clearance_m)   # the rope's: on each bend's inner wall
    if vertical and weight_N_per_m > 0.0:                      # ... and on the straights' floor
        d = np.where(chain.kap != 0.0, d, -clearance_m)
    if three_d:                                                # ... and on the floor
        d = np.stack([d, -np.sqrt(np.maximum(clearance_m ** 2 - d * d, 0.0))], 1)
    sol = chain.solve(d, soften=True)
    factor = 2.0
    while ej < bending_stiffness_N_m2:
        nxt = min(bending_stiffness_N_m2, ej * factor)
        try:
            sol = cls(*args, nxt, back_tension_N, spacing_m, **kw).solve(sol.offset_m.copy())
        except BeamConduitError:
            factor = math.sqrt(factor)
            if factor < 1.0 + 1e-3:
                raise
            continue
        ej = nxt
    return sol


def route_pieces(centreline) -> list[tuple[float, float]]:
    """A horizontal route's pieces as (length [m], signed curvature [1/m], > 0 turning left)."""
    out = []
    for p in centreline.pieces:
        if not p.is_curved:
            out.append((float(p.length_m), 0.0))
            continue
        a = centreline.tangent(p.s_start_m + 1e-6 * p.length_m)
        b = centreline.tangent(p.s_end_m - 1e-6 * p.length_m)
        sign = 1.0 if np.cross(a, b)[2] >= 0.0 else -1.0
        out.append((float(p.length_m), sign / float(p.radius_of_curvature_m)))
    return out


def path_pieces(path) -> tuple[list[tuple[float, float]], bool]:
    """A planar path in the scenario's ``conduit.path`` form as pieces, and whether it is vertical.

    Parameters
    ----------
    path : sequence of dict
        ``{"straight": L [m]}`` or ``{"bend": angle [deg], "radius": R [m], "turn": "left" | "right" |
        "up" | "down"}``: left/right turns only (a horizontal route) or up/down only (a vertical one).

    Returns
    -------
    pieces : list of (float, float)
        (length [m], signed curvature [1/m], > 0 turning left or up).
    vertical : bool
        The path turns up or down (:func:`solve_planar_beam`'s ``vertical``).
    """
    turns = {p.get("turn", "left") for p in path if "bend" in p}
    if turns & {"left", "right"} and turns & {"up", "down"}:
        raise ValueError("path: the planar beam takes a horizontal route (left/right turns) or a vertical one "
                         "(up/down turns), not both; split the route or use exucable's 3D model")
    sign = {"left": 1.0, "up": 1.0, "right": -1.0, "down": -1.0}
    pieces = [(float(p["straight"]), 0.0) if "straight" in p
              else (math.radians(p["bend"]) * p["radius"], sign[p.get("turn", "left")] / p["radius"]) for p in path]
    return pieces, bool(turns & {"up", "down"})


def gravity_change_of_stiffness(path, clearance_m: float, friction: float, weight_N_per_m: float,
                                bending_stiffness_N_m2: float, back_tension_N: float, spacing_m: float) -> float:
    """What gravity changes in the stiff cable's pull against the flexible one [relative].

    ``(F_EJ/F_0)|_w − (F_EJ/F_0)|_{w=0}`` on the whole route in one window (F_0 the chain at λ = h,
    F_EJ the stiff chain with its head held where F_0's head lies, as exucable's steady rig holds it):
    the term to add to the in-plane stiff bend (:func:`exucable.quasistatic.stiff_bend.stiff_bend`) on a
    route with gravity. A horizontal route with gravity uses the 3D chain (the cable crosses the
    floor's trough), a vertical one the planar chain with the weight in its plane (free spans on an
    up-bend, the cable held on a down-bend's floor). Four continuation solves.

    Parameters
    ----------
    path : sequence of dict
        The route (:func:`path_pieces`), pulled from its start to its end.
    clearance_m, friction, weight_N_per_m, bending_stiffness_N_m2, back_tension_N, spacing_m : float
        c [m], μ, w [N/m] (> 0), EJ [N m²], T at the trailing end [N], node spacing h [m] (resolve
        λ = √(EJ/T) with several nodes).
    """
    if weight_N_per_m <= 0.0:
        raise ValueError(f"weight_N_per_m must be > 0 (the gravity term), got {weight_N_per_m}")
    pieces, vertical = path_pieces(path)
    h = spacing_m
    ratio = []
    for w in (weight_N_per_m, 0.0):
        # without gravity a faint trough fixes a free straight's place (stiff_route_difference's)
        trough = None if w > 0.0 else 1e-5 * back_tension_N * max(abs(k) for _, k in pieces)
        kw = dict(trough_weight_N_per_m=trough, three_d=w > 0.0 and not vertical, vertical=vertical and w > 0.0)
        flex = solve_planar_beam(pieces, clearance_m, friction, w, min(bending_stiffness_N_m2, back_tension_N * h * h),
                                 back_tension_N, h, **kw)
        stiff = solve_planar_beam(pieces, clearance_m, friction, w, bending_stiffness_N_m2, back_tension_N, h,
                                  head_offset_m=flex.offset_m[-1].copy(), **kw)
        ratio.append(stiff.pull_force_N / flex.pull_force_N)
    return ratio[0] - ratio[1]


def stiff_route_difference(pieces, clearance_m, friction, weight_N_per_m, bending_stiffness_N_m2,
                           back_tension_N, lead_out_bending_lengths=10.0, nodes_per_bending_length=10.0,
                           pad_decay_lengths=3.0, max_pad_m=6.0, three_d=None, progress=None) -> dict:
    """Bending stiffness' change of the pulling force on a route, from the planar beam-in-conduit model:
    (T_EJ − T_flexible) / T_flexible, the model's own EJ → 0 limit as reference.

    Bends are grouped into windows (bends closer than two pads); each window is solved with straight
    pads before and after it (``pad_decay_lengths`` trough decay lengths √(T c / w), at least 10
    bending lengths, at most ``max_pad_m`` and what the route has), the far parts of the straights
    adding μ w L in both chains (the rope's straight). ``three_d`` (default: with gravity) lets the
    nodes move in the whole normal plane (:func:`solve_planar_beam`). A route ending in a bend gets a lead-out of
    ``lead_out_bending_lengths`` where the stiff cable is pinned at the flexible cable's offset (as
    exucable's steady rig, :func:`exucable.model.layout.steady_lead_out_m`).

    Returns
    -------
    dict
        ``stiff_N``, ``flexible_N`` (pulling force of each chain), ``difference`` (relative),
        ``windows`` (per window: stations, both pulls, max |offset|/c on the straights' outer side).
    """
    say = progress or (lambda line: None)
    mu, w, c, ej = friction, weight_N_per_m, clearance_m, bending_stiffness_N_m2
    three_d = w > 0.0 if three_d is None else three_d
    n = len(pieces)
    windows, i = [], 0
    while i < n:
        if pieces[i][1] == 0.0:
            i += 1
            continue
        j = i
        while True:   # a window: this bend and the bends that follow it closer than two pads
            if j + 1 < n and pieces[j + 1][1] != 0.0:
                j += 1
            elif j + 2 < n and pieces[j + 2][1] != 0.0 and pieces[j + 1][0] < 2.0 * max_pad_m:
                j += 2
            else:
                break
        windows.append((i, j))
        i = j + 1
    used = [0.0] * n      # straight length already inside a window [m]
    t_stiff = t_flex = back_tension_N
    out_windows = []
    for wi, (i, j) in enumerate(windows):
        lam_in = math.sqrt(ej / t_flex)
        pad = min(max_pad_m, max(pad_decay_lengths * math.sqrt(t_flex * c / w), 10.0 * lam_in)) if w > 0 else max_pad_m
        window = []
        if i > 0 and pieces[i - 1][1] == 0.0:
            avail = pieces[i - 1][0] - used[i - 1]
            pad_before = min(pad, avail)
            t_stiff += mu * w * (avail - pad_before)      # the straight's far part: the rope's μ w L
            t_flex += mu * w * (avail - pad_before)
            used[i - 1] = pieces[i - 1][0]
            window.append((pad_before, 0.0))
        window += list(pieces[i:j + 1])
        turn = sum(abs(k) * length for length, k in pieces[i:j + 1])
        lam_out = math.sqrt(ej / (t_flex * math.exp(mu * turn)))
        if j + 1 < n:
            lead = min(pad, pieces[j + 1][0])
            used[j + 1] = lead
        else:
            lead = lead_out_bending_lengths * lam_out
        window.append((lead, 0.0))
        h = min(lam_out, lam_in) / nodes_per_bending_length
        trough_w = w if w > 0 else 1e-5 * t_flex * max(abs(k) for _, k in window)
        say(f"beam in conduit: window {wi + 1}/{len(windows)} (pieces {i + 1}-{j + 1}), "
            f"{sum(length for length, _ in window) / h:.0f} nodes")
        flex = solve_planar_beam(window, c, mu, w, min(ej, t_flex * h * h), t_flex, h, trough_weight_N_per_m=trough_w,
                                 three_d=three_d)
        # the leading end: pinned where the flexible cable is (exucable's rig) at the route's end or
        # without gravity (nothing else centres it); free on a straight with gravity
        head = flex.offset_m[-1].copy() if j + 1 >= n or w == 0.0 else None
        stiff = solve_planar_beam(window, c, mu, w, ej, t_stiff, h, head_offset_m=head, trough_weight_N_per_m=trough_w,
                                  three_d=three_d)
        lateral = stiff.offset_m[:, 0] if three_d else stiff.offset_m
        outer = -math.copysign(1.0, sum(k for _, k in pieces[i:j + 1])) * lateral
        out_windows.append({"pieces": (i + 1, j + 1), "flexible_in_N": t_flex, "stiff_in_N": t_stiff,
                            "flexible_out_N": flex.pull_force_N, "stiff_out_N": stiff.pull_force_N,
                            "nodes": int(stiff.station_m.size), "max_outer_offset_over_c": float(np.max(outer) / c)})
        t_flex, t_stiff = flex.pull_force_N, stiff.pull_force_N
    for k, (length, kappa) in enumerate(pieces):      # straights' parts outside every window
        if kappa == 0.0 and used[k] < length and k > (windows[-1][1] if windows else -1):
            t_flex += mu * w * (length - used[k])
            t_stiff += mu * w * (length - used[k])
    return {"stiff_N": t_stiff, "flexible_N": t_flex, "difference": t_stiff / t_flex - 1.0, "windows": out_windows}


class _Chain3D(_Chain):
    """The same chain with the third dimension: each node moves in its normal plane (the bend plane's
    normal n and the vertical), the wall is the round conduit |d| = c (a stiff penalty), the weight a
    body force; the cable may lift off the floor in free spans (the rope with clearance's) and bridge
    the trough with its stiffness. Bending energy (EJ/h) Σ (1 − t_{i−1}·t_i) (= EJ φ²/(2h) at small φ).
    Offsets are (N, 2) arrays: along n and up."""

    space_dim = 3
    dofs = 2
    pull_tol = _TOL_PULL_3D
    shape_tol = _SHAPE_TOL_3D
    stall_move = 1e-9
    residual_name = "normal-plane"

    def pos(self, d):
        x = np.zeros((self.N, 3))
        x[:, :2] = self.C + d[:, :1] * self.n
        x[:, 2] = d[:, 1]
        return x

    def _normal_frames(self):
        n3 = np.zeros((self.N, 3))
        n3[:, :2] = self.n
        up = np.zeros((self.N, 3))
        up[:, 2] = 1.0
        return n3, up

    def wall_force(self, d):
        """Wall force on each node in its normal plane, (N, 2) [N] (a penalty on |d| − c)."""
        r = np.hypot(d[:, 0], d[:, 1])
        p = np.maximum(r - self.c, 0.0)
        delta = _SMOOTH_3D * self.c       # the penalty's force is smoothed (C¹) over this depth, for Newton
        force = self.K * np.where(p < delta, p * p / (2.0 * delta), p - delta / 2.0)
        return -(force / np.maximum(r, 1e-300))[:, None] * d

    def wall_energy(self, d):
        r = np.hypot(d[:, 0], d[:, 1])
        p = np.maximum(r - self.c, 0.0)
        delta = _SMOOTH_3D * self.c
        return self.K * float(np.sum(np.where(p < delta, p ** 3 / (6.0 * delta),
                                              p * p / 2.0 - delta * p / 2.0 + delta * delta / 6.0)))

    def geometry3(self, d):
        x = self.pos(d)
        v = np.diff(x, axis=0)
        length = np.linalg.norm(v, axis=1)
        return x, v, length, v / length[:, None]

    def energy(self, d, T, G):
        x, _, length, t = self.geometry3(d)
        cosines = np.einsum("ij,ij->i", t[:-1], t[1:])
        return float(T @ length + self.EJ / self.h * np.sum(1.0 - cosines) + self.wall_energy(d)
                     + self.w * float(self.hbar @ d[:, 1]) - np.sum(G * x))

    def forces(self, d, T):
        x, v, length, t = self.geometry3(d)
        tension = np.zeros_like(x)
        tension[:-1] += T[:, None] * t
        tension[1:] -= T[:, None] * t
        cosines = np.einsum("ij,ij->i", t[:-1], t[1:])[:, None]
        a = self.EJ / self.h
        dE_dv = np.zeros_like(v)
        dE_dv[:-1] -= a * (t[1:] - cosines * t[:-1]) / length[:-1, None]
        dE_dv[1:] -= a * (t[:-1] - cosines * t[1:]) / length[1:, None]
        bending = np.zeros_like(x)
        bending[1:] -= dE_dv
        bending[:-1] += dE_dv
        n3, up = self._normal_frames()
        wf = self.wall_force(d)
        wall = wf[:, :1] * n3 + wf[:, 1:] * up
        wall[:, 2] -= self.w * self.hbar      # the weight, with the wall's force
        return tension, bending, wall, t

    def lateral_residual(self, d, T, G):
        tension, bending, wall, _ = self.forces(d, T)
        total = tension + bending + wall + G
        n3, up = self._normal_frames()
        return np.stack([np.einsum("ij,ij->i", total, n3), total[:, 2]], 1)

    def march(self, d, T):
        _, bending, wall, t = self.forces(d, T)
        contact = np.hypot(*self.wall_force(d).T)
        new_T = np.empty_like(T)
        friction_force = np.zeros((self.N, 3))
        prev_T, prev_t = self.Tb, np.array([self.e[0, 0], self.e[0, 1], 0.0])
        for i in range(self.N - 1):
            tau = prev_t + t[i]
            tau /= np.linalg.norm(tau)
            friction_force[i] = -self.mu * contact[i] * tau
            new_T[i] = (prev_T * (prev_t @ tau) - (bending[i] + wall[i]) @ tau + self.mu * contact[i]) / (t[i] @ tau)
            prev_T, prev_t = new_T[i], t[i]
        friction_force[-1] = -self.mu * contact[-1] * t[-1]
        return new_T, friction_force, prev_T + self.mu * contact[-1], contact
