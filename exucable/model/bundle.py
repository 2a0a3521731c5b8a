"""Several cables pulled together through one conduit (``cable.count`` 2-4), in steady sliding.

One ANCF cable per conductor, each with the scenario's cable data, laid along the conduit in the
arrangement's cross-section (:func:`arrangement_offsets`), its centroid on the path of the rope
with clearance of one cable's share (free spans across the duct included) and the arrangement turned,
station by station, toward the wall that path bears on (in a bend the tension presses the bundle onto
the bend's inner wall), and pre-tensioned to that rope's tension, except that a cable resting on the
others only starts at its back tension (:func:`start_tensions`). Each cable has its own wall contact (the cable-conduit kernel in its
steady-sliding form) and one more coupling carries the contact between the cables
(:class:`~exucable.contact.cable_pairs.CableContactKernel`).

The pulling eye: in a steady solve the rig holds the eye where the start put it, so each cable's
leading end is held at its place in the eye (its arrangement offset on the exit line); the pulling
force is the sum of those reactions along the exit tangent, and each reaction is that cable's share.
The back tension (``pull.back_tension``, the whole bundle's, as a calculator takes it) acts on the
trailing ends in equal parts T_b/n: identical cables fed off one reel set or one brake.

All cables have the same material length and trailing end place; through a bend the outer cable's
path is longer, so its leading end sits a little short of the inner one's inside the eye (by the
offset difference times the bend angle, millimetres to centimetres).

The dynamic mode's bundle is :mod:`exucable.model.bundle_rig` (the same cables, started from this
model's start or its solved state). Not covered yet, refused naming the key: a force-controlled
pull, the segmented wall, a dynamic bundle's snapshots.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import exudyn as exu

from ..errors import ModelError
from ..quasistatic import engineering as eng
from ..post.tension import tension_at
from .cable import CableHandles, CableProperties, add_cable, add_gravity
from .coupling import ContactCoupling
from .generic import add_user_force_object
from .layout import CableLayout, lay_cable, plan_cable_mesh, steady_lead_out_m
from .rig import Drive, add_drive, add_end_force

__all__ = ["BUNDLE_STARTS", "BundleModel", "arrangement_offsets", "bundle_offsets", "load_turn_rad", "start_tensions", "build_bundle_model", "statics_start", "check_bundle_supported",
           "bundle_arrangement", "bundle_report", "bundle_tension_profile", "straight_weight_correction",
           "bundle_sections", "bundle_cross_sections", "bundle_tension_along_conduit"]


#: Gap left at the start between the cables and to the wall, in cable radii [-] (see build_bundle_model).
START_GAP = 0.05

#: the bundle's starts (``build_bundle_model``'s ``start_path``; ``[solver] bundle_starts`` tries them in turn)
BUNDLE_STARTS = ("clearance", "statics_own", "statics", "axis")


def bundle_arrangement(scenario) -> str:
    """The arrangement of the scenario's cables (``cable.arrangement``, ``"auto"`` resolved)."""
    c = scenario.cable
    D, d = 2.0 * scenario.conduit.inner_radius_m, 2.0 * c.radius_m
    return eng.auto_arrangement(c.count, D, d) if c.arrangement == "auto" else c.arrangement


def bundle_offsets(scenario) -> np.ndarray:
    """The scenario's cable axes in the duct's cross-section at the start [m], shape (count, 2),
    (horizontal, up) from the duct's axis: ``cable.positions`` where given (checked to fit by the
    scenario), else :func:`arrangement_offsets` of :func:`bundle_arrangement`."""
    c = scenario.cable
    if c.positions_m is not None:
        return np.asarray(c.positions_m, dtype=float)
    return arrangement_offsets(c.count, bundle_arrangement(scenario), scenario.conduit.inner_radius_m, c.radius_m)


def arrangement_offsets(count: int, arrangement: str, inner_radius_m: float, cable_radius_m: float) -> np.ndarray:
    """Cable axes in the duct's cross-section as rigid circles at rest under gravity [m], shape (count, 2):
    (horizontal, up) from the duct's axis.

    With ρ = R - r and α = 2 asin(r/ρ) the angle between two touching cables on the wall, a cable on
    the wall at φ from the bottom sits at (ρ sin φ, -ρ cos φ): triangular 2 at ±α/2; triangular 3 two
    at ±α/2 and one on them; cradled 3 at 0, ±α; cradled 4 at ±α/2, ±3α/2; diamond one at 0, two at
    ±α and one on those two.
    """
    rho = inner_radius_m - cable_radius_m
    r = cable_radius_m
    if not rho > r:
        raise ModelError("conduit.inner_radius", f"a duct of inner radius {inner_radius_m:.4g} m holds no two cables "
                         f"of radius {r:.4g} m side by side; use a larger duct or cable.count = 1")
    alpha = 2.0 * math.asin(r / rho)

    def wall(phi):
        return [rho * math.sin(phi), -rho * math.cos(phi)]

    def on_top(p, q):
        # the circle resting on two touching-or-apart circles p, q symmetric about the vertical
        half = abs(p[0] - q[0]) / 2.0
        return [0.0, p[1] + math.sqrt(4.0 * r * r - half * half)]

    if arrangement == "triangular" and count == 2:
        pts = [wall(-alpha / 2), wall(alpha / 2)]
    elif arrangement == "triangular" and count == 3:
        a, b = wall(-alpha / 2), wall(alpha / 2)
        pts = [a, b, on_top(a, b)]
    elif arrangement == "cradled" and count == 3:
        pts = [wall(-alpha), wall(0.0), wall(alpha)]
    elif arrangement == "cradled" and count == 4:
        pts = [wall(-1.5 * alpha), wall(-alpha / 2), wall(alpha / 2), wall(1.5 * alpha)]
    elif arrangement == "diamond" and count == 4:
        a, b = wall(-alpha), wall(alpha)
        pts = [wall(0.0), a, b, on_top(a, b)]
    else:
        raise ModelError("cable.arrangement", f"{arrangement!r} is not an arrangement of {count} simulated cables; "
                         "use triangular (2, 3), cradled (3, 4) or diamond (4)")
    pts = np.asarray(pts, dtype=float)
    if np.any(np.hypot(pts[:, 0], pts[:, 1]) > rho * (1.0 + 1e-9)):
        raise ModelError("cable.arrangement", f"{arrangement!r}: the top cable does not fit the duct at D/d = "
                         f"{inner_radius_m / cable_radius_m:.3g}; use the other arrangement")
    gaps = np.hypot(*(pts[:, None, :] - pts[None, :, :]).transpose(2, 0, 1)) + np.eye(len(pts)) * 4.0 * r
    if gaps.min() < 2.0 * r * (1.0 - 1e-9):
        raise ModelError("cable.arrangement", f"{arrangement!r} does not stand at D/d = {inner_radius_m / cable_radius_m:.3g}: "
                         "its cables would overlap (the top one falls onto the bottom one); use \"cradled\"")
    return pts


def check_bundle_supported(scenario) -> None:
    """Refuse, naming the key, what the several-cables model does not cover yet."""
    sc = scenario
    if sc.solver.mode not in ("steady", "dynamic"):
        raise ModelError("solver.mode", f"cable.count = {sc.cable.count}: {sc.solver.mode!r} is not a solver mode; "
                         'set solver.mode = "steady" or "dynamic"')
    out = sc.output
    if sc.solver.mode == "dynamic" and (out.snapshots_s or out.snapshot_interval_s is not None):
        key = "output.snapshots" if out.snapshots_s else "output.snapshot_interval"
        raise ModelError(key, "several cables (cable.count > 1) write no snapshots yet; remove the key "
                              "(output.cross_sections draws the cables across the duct)")
    if sc.pull.force_N is not None:
        raise ModelError("pull.force", "several cables (cable.count > 1) are pulled by the rig's speed only; "
                         "remove pull.force")
    if not sc.solver.pretension:
        raise ModelError("solver.pretension", "several cables start from the rope solution; set it to true")
    if sc.contact.surface != "smooth":
        raise ModelError("contact.surface", 'several cables need the smooth wall; set contact.surface = "smooth"')
    if sc.contact.static_friction is not None and sc.solver.mode == "steady":
        raise ModelError("contact.static_friction", "several cables slide steadily: static friction does not act; "
                         'remove contact.static_friction (it acts in solver.mode = "dynamic")')


def _cross_section_frame(centreline, s_m):
    """Unit (horizontal, up) axes across the centreline at arc lengths ``s_m``, each shape (m, 3):
    up = e_z without its tangential part (a vertical tangent takes e_x's instead)."""
    from .layout import extended_tangent

    from ..post.bundle import frame_across

    return frame_across(extended_tangent(centreline, np.asarray(s_m, dtype=float)))


def load_turn_rad(centreline, s_m, tension_N, weight_per_length_N_per_m: float, blend_length_m: float) -> np.ndarray:
    """Angle φ(s) [rad] by which the arrangement is turned in the cross-section at arc lengths ``s_m``
    (a uniform grid) so that its "down" points along one cable's lateral load per length
    p = T κ n - w (e_z - (e_z·t) t) (the rope equation's sidewall load, as for one cable's start):
    φ = 0 under gravity alone, ±π/2 in a horizontal bend without gravity, measured from "down"
    toward the horizontal axis of :func:`_cross_section_frame`.

    Unloaded stations take their loaded neighbours' angle (interpolated; 0 where nothing is
    loaded); the angle is unwrapped along s and smoothed with a Gaussian of width
    ``blend_length_m``, so the bundle rolls round the duct into a bend rather than jumping.
    """
    s = np.asarray(s_m, dtype=float)
    t = np.atleast_2d(centreline.tangent(s))
    kn = np.atleast_2d(centreline.curvature_vector(s))
    ez = np.array([0.0, 0.0, 1.0])
    load = np.asarray(tension_N, dtype=float)[:, None] * kn - weight_per_length_N_per_m * (ez[None, :] - (t @ ez)[:, None] * t)
    return _turn_toward(centreline, s, load, None, blend_length_m)


def _turn_toward(centreline, s, vectors, loaded, blend_length_m: float) -> np.ndarray:
    """φ(s) [rad] of :func:`load_turn_rad` from vectors across the duct, shape (m, 3), at the
    uniform grid ``s``: their direction where ``loaded`` (None: where they are not ~0), the loaded
    neighbours' angle elsewhere, unwrapped and smoothed over ``blend_length_m``."""
    eh, ev = _cross_section_frame(centreline, s)
    ph, pv = np.einsum("ij,ij->i", vectors, eh), np.einsum("ij,ij->i", vectors, ev)
    size = np.hypot(ph, pv)
    if loaded is None:
        loaded = size > 1e-9 * max(float(size.max()), 1e-300)
    if not loaded.any():
        return np.zeros_like(s)
    phi = np.unwrap(np.arctan2(ph[loaded], -pv[loaded]))
    phi = np.interp(s, s[loaded], phi)
    ds = s[1] - s[0] if len(s) > 1 else 1.0
    sigma = blend_length_m / ds
    if sigma > 0.5:
        half = int(np.ceil(4 * sigma))
        k = np.exp(-0.5 * (np.arange(-half, half + 1) / sigma) ** 2)
        phi = np.convolve(np.pad(phi, half, mode="edge"), k / k.sum(), mode="valid")
    return phi


def start_tensions(centreline, share_rope, offsets_m, clearance_m: float, weight_per_length_N_per_m: float,
                   back_tension_N: float) -> list:
    """Each cable's start tension, s along the pull-oriented centreline [m] → T [N], one per cable.

    A cable of the arrangement that rests on the others only (``offsets_m`` inside the clearance
    ``clearance_m``: the triangle's top one) slides on them without friction (``contact.cable_friction``
    0, the default; with friction between the cables this is only a start) and touches no wall, so
    only its weight along the route changes its tension: T_free = T_b/n + w (z(s) - z(s_0)), at
    least 0 (z the centreline's height, s_0 the trailing end's place). The cables on the wall carry the
    rest of the bundle's rope, n·T_share(s) (``share_rope``: one cable's share with μ times the
    weight correction factor, back tension T_b/n), in equal parts. With every cable on the wall
    (cradled) each starts at T_share. Starting every cable at T_share instead left the top one of a
    triangle stretched by the bottom ones' strain (1.2 % against 0.07 % at the head of the 100 m
    route), which the solve must undo by sliding it along the whole route.
    """
    from .layout import extended_point

    s_r = np.asarray(share_rope.s_conduit_m, dtype=float)
    T_share = np.asarray(share_rope.tension_N, dtype=float)
    radius = np.hypot(offsets_m[:, 0], offsets_m[:, 1])
    on_wall = radius >= clearance_m * (1.0 - 1e-6)
    n = len(offsets_m)
    if on_wall.all() or not on_wall.any():
        return [lambda s: np.interp(s, s_r, T_share)] * n
    z = extended_point(centreline, s_r)[:, 2]
    T_free = np.maximum(back_tension_N + weight_per_length_N_per_m * (z - z[0]), 0.0)
    n_free = n - int(np.count_nonzero(on_wall))
    T_wall = np.maximum((n * T_share - n_free * T_free) / (n - n_free), 0.0)
    return [(lambda s, T=(T_wall if wall else T_free): np.interp(s, s_r, T)) for wall in on_wall]


def _smooth_rows(values, sigma: float) -> np.ndarray:
    """``values`` (m, k) on a uniform grid smoothed along it with a Gaussian of ``sigma`` grid steps
    (ends padded with their values)."""
    if not sigma > 0.5:
        return values
    half = int(np.ceil(4 * sigma))
    k = np.exp(-0.5 * (np.arange(-half, half + 1) / sigma) ** 2)
    k /= k.sum()
    pad = np.pad(values, ((half, half), (0, 0)), mode="edge")
    return np.stack([np.convolve(pad[:, j], k, mode="valid") for j in range(values.shape[1])], axis=1)


def _centroid_path(centreline, offsets_m, friction: float, weight_per_length_N_per_m: float,
                   back_tension_N: float, cable_length_m: float):
    """The path of the bundle's centroid at the start: the rope with clearance
    (:func:`~exucable.quasistatic.clearance.solve_rope_with_clearance`) of one cable's share (friction
    μ times the weight correction, back tension T_b/n, one cable's weight) whose clearance is the
    resting arrangement's centroid's distance from the duct's axis, or None (no clearance left, or a
    share that runs slack).

    With gravity a tensioned cable leaves the bottom in a free span, crossing the duct in a straight
    line toward a bend's inner wall, √(2TΔ/w) long (metres at kilonewtons); a start that hugs the
    bottom up to the bend and rolls there is centimetres off that, and its cross-section, held only
    by the tension in the span, must swing over. The share rope's tension on this path also has the
    path's lower friction where the spans cut the bends' corners.
    """
    from ..quasistatic.clearance import solve_rope_with_clearance

    mid_h, mid_v = np.asarray(offsets_m, dtype=float).mean(axis=0)
    clearance = -float(mid_v)
    # only for an arrangement resting with its centroid straight below the axis (any of
    # arrangement_offsets'): the path's offset is the direction the arrangement's "down" is turned to
    if not clearance > 1e6 * abs(float(mid_h)):
        return None
    try:
        return solve_rope_with_clearance(centreline, clearance, friction, weight_per_length_N_per_m, back_tension_N,
                                         cable_length_m=cable_length_m)
    except ModelError:
        return None


#: Stations of the statics start per blend length (the cable's bending length or one element) [-].
STATIONS_PER_BLEND = 10


@dataclass
class StaticsStart:
    """The cables' places across the duct from the cross-section's statics (:func:`statics_start`).

    Attributes
    ----------
    s_m : ndarray (m,)
        Stations along the pull-oriented centreline [m].
    offsets : ndarray (m, n_cables, 2)
        Each cable's axis (horizontal, up) from the duct's axis [m].
    forward : ndarray (m, n_cables, 2)
        The continuation from the trailing end alone [m].
    join_s_m : float or None
        Where the continuation back from the eye's arrangement meets the forward one and takes over
        [m]; None where they never meet (the forward one kept, blended into the eye's in the last element).
    newton_steps : int
        Newton steps of the two continuations together.
    """

    s_m: np.ndarray
    offsets: np.ndarray
    forward: np.ndarray
    join_s_m: float | None
    newton_steps: int

    def offsets_m(self, s_m, cable: int) -> np.ndarray:
        """Cable ``cable``'s axis (horizontal, up) from the duct's axis at ``s_m`` [m], shape (m, 2)."""
        s = np.asarray(s_m, dtype=float)
        return np.stack([np.interp(s, self.s_m, self.offsets[:, cable, j]) for j in range(2)], axis=1)


def statics_start(centreline, tension_fns, weight_per_length_N_per_m: float, inner_radius_m: float,
                  laid_radius_m: float, laid_offsets_m, s_grid_m, turn_rad, blend_length_m: float,
                  own_tensions: bool = False) -> StaticsStart:
    """The cables across the duct along the route from the statics of each cross-section
    (:mod:`exucable.quasistatic.cross_section`), continued station by station so that the cables'
    order and contacts carry over.

    Cable i's lateral load per length is the rope equation's p = T κ n − w (e_z − (e_z·t) t) with T
    the cables' mean start tension (``tension_fns``: :func:`start_tensions`), smoothed along s with a
    Gaussian of ``blend_length_m`` as the cable's bending stiffness spreads a bend's end: equal loads,
    so the arrangement moves as a whole where the load turns (a triangle lifting in an up-bend until
    its top cable meets the upper wall, the two others sliding up beside it). ``own_tensions``: each
    cable's own start tension instead, so a cable resting on the others presses with its lower one;
    at an up-bend's entry the top cable of a triangle then drops between the two others as they lift
    (the frictionless rigid circles' answer under those loads), a turn over the cables cannot make
    within the few elements the smoothing gives it (overlaps of millimetres between the nodes;
    ``benchmarks/bundle_start.py`` measures both). The circles are the laid ones (``laid_radius_m``,
    :data:`START_GAP` larger than the cables), stations :data:`STATIONS_PER_BLEND` per blend length.

    Two continuations: forward from the trailing end (``laid_offsets_m`` turned by ``turn_rad`` at
    the first station), and back from the eye's arrangement (``laid_offsets_m`` turned by the last
    station's ``turn_rad``, as the eye holds the cables) until the two agree within 2 % of a radius at
    every cable; the back one is used from there to the eye. Rigid circles snap across the duct
    where their loads turn (a triangle lifting in an up-bend within one station); a cable takes a
    bending length at least and the mesh an element or two, so the rests are smoothed over
    ``blend_length_m`` and then pushed apart where the smoothing made two overlap
    (:func:`~exucable.quasistatic.cross_section.separate_circles`).
    """
    from ..quasistatic.cross_section import rest_along, separate_circles

    s_grid = np.asarray(s_grid_m, dtype=float)
    L = float(s_grid[-1])
    m = max(int(math.ceil(STATIONS_PER_BLEND * (L - s_grid[0]) / max(blend_length_m, 1e-9))), 2) + 1
    s = np.linspace(s_grid[0], L, m)
    t = np.atleast_2d(centreline.tangent(s))
    kn = np.atleast_2d(centreline.curvature_vector(s))
    ez = np.array([0.0, 0.0, 1.0])
    across = ez[None, :] - (t @ ez)[:, None] * t
    eh, ev = _cross_section_frame(centreline, s)
    sigma = blend_length_m / (s[1] - s[0])
    loads = []
    T_own = [np.asarray(fn(s), dtype=float) for fn in tension_fns]
    T_mean = np.mean(T_own, axis=0)
    for T in T_own:
        p = _smooth_rows((T if own_tensions else T_mean)[:, None] * kn - weight_per_length_N_per_m * across, sigma)
        loads.append(np.stack([np.einsum("ij,ij->i", p, eh), np.einsum("ij,ij->i", p, ev)], axis=1))
    loads = np.stack(loads, axis=1)                                     # (m, n, 2)
    turn = np.interp(s, s_grid, turn_rad)
    laid = np.asarray(laid_offsets_m, dtype=float)

    def turned(phi):
        c, sn = math.cos(phi), math.sin(phi)
        return np.stack([laid[:, 0] * c - laid[:, 1] * sn, laid[:, 0] * sn + laid[:, 1] * c], axis=1)

    fwd, steps_f = rest_along(loads, inner_radius_m, laid_radius_m, turned(turn[0]))
    back, steps_b = rest_along(loads[::-1], inner_radius_m, laid_radius_m, turned(turn[-1]),
                               stop_near=fwd[::-1], tolerance_m=0.02 * laid_radius_m)
    out = fwd.copy()
    join = None
    if len(back) < m:             # met: from the meeting station on, the back continuation
        k = m - len(back)
        out[k:] = back[::-1]
        join = float(s[k])
    out = _smooth_rows(out.reshape(m, -1), sigma).reshape(out.shape)
    for i in range(m):
        out[i] = separate_circles(out[i], inner_radius_m, laid_radius_m)
    return StaticsStart(s_m=s, offsets=out, forward=fwd, join_s_m=join, newton_steps=steps_f + steps_b)


@dataclass
class BundleLayout:
    """The cables' start together: ``coordinates`` (n_cables·(n_el + 1), 6) cable after cable,
    ``element_length_m`` of one cable (all alike)."""

    element_length_m: np.ndarray
    cables: list
    n_cables: int

    @property
    def coordinates(self) -> np.ndarray:
        return np.concatenate([c.coordinates for c in self.cables], axis=0)


class _GravityScales:
    """The cables' compiled elastic forces (:class:`~exucable.contact.ancf_cable.AncfCableForces`)
    as the one whose weight :class:`~exucable.model.build.LoadScale` scales: setting
    ``gravity_scale`` sets every cable's."""

    def __init__(self):
        self.parts = []

    @property
    def gravity_scale(self) -> float:
        return self.parts[0].gravity_scale if self.parts else 1.0

    @gravity_scale.setter
    def gravity_scale(self, value: float) -> None:
        for p in self.parts:
            p.gravity_scale = value


class _Walls:
    """The cables' wall kernels and their cable-cable kernel as one, for the steady solve."""

    def __init__(self, walls, between):
        self.walls = walls
        self.between = between
        self.n = walls[0].n_coordinates

    @property
    def n_check_points(self) -> int:
        return self.walls[0].n_check_points

    def set_friction_scale(self, scale: float) -> None:
        for k in self.walls:
            k.set_friction_scale(scale)
        self.between.set_friction_scale(scale)

    def set_onset_layer(self, layer_m: float) -> None:
        """Every contact's onset layer s [m] (:mod:`exucable.solve.onset_continuation`)."""
        for k in self.walls:
            k.set_onset_layer(layer_m)
        self.between.set_onset_layer(layer_m)

    def point_segments(self, q) -> np.ndarray:
        q = np.asarray(q, dtype=float).reshape(-1)
        return np.concatenate([k.point_segments(q[i * self.n:(i + 1) * self.n]) for i, k in enumerate(self.walls)])


class CableContactCoupling:
    """Contact between the cables (:class:`~exucable.contact.cable_pairs.CableContactKernel`) as one
    mass-free ``ObjectGenericODE2`` over every cable's nodes, exact sparse Jacobian."""

    def __init__(self, mbs, nodes, reference_coordinates, kernel):
        self.kernel = kernel
        self.q_ref = np.ascontiguousarray(np.asarray(reference_coordinates, dtype=float).reshape(-1))
        self.n = self.q_ref.size
        self._last = None
        self.evaluations = 0
        self.object = add_user_force_object(mbs, nodes, self.n, self._force, self._jacobian)

    def _evaluate(self, q):
        qa = self.q_ref + np.asarray(q, dtype=float)
        last = self._last
        if last is not None and np.array_equal(last[0], qa):
            return last[1]
        res = self.kernel.evaluate(qa, jacobian=True)
        self.evaluations += 1
        self._last = (qa.copy(), res)
        return res

    def last_evaluation(self):
        return self._last

    def offer_evaluation(self, evaluation) -> None:
        if evaluation is not None:
            self._last = evaluation

    def forget_evaluation(self) -> None:
        self._last = None

    def _force(self, mbs, t, item, q, q_t):
        return self._evaluate(q).generalized_force

    def _jacobian(self, mbs, t, item, q, q_t, f_q, f_v):
        # LHS derivative: the contact force is on the right-hand side, hence the minus sign
        J = (-f_q * self._evaluate(q).jacobian).tocoo()
        keep = J.data != 0.0   # Exudyn's sparse triplets must not contain zeros
        m = exu.MatrixContainer()
        if keep.any():
            m.SetWithSparseMatrix(np.column_stack([J.row[keep].astype(float), J.col[keep].astype(float), J.data[keep]]),
                                  self.n, self.n, False)
        else:
            m.Initialize(self.n, self.n, False)
        return m


class _Couplings:
    """The wall couplings and the cable-cable coupling as one, for the steady solve's state store."""

    def __init__(self, parts):
        self.parts = parts

    def last_evaluation(self):
        return tuple(p.last_evaluation() for p in self.parts)

    def offer_evaluation(self, evaluation) -> None:
        if evaluation is not None:
            for p, e in zip(self.parts, evaluation):
                p.offer_evaluation(e)

    def forget_evaluation(self) -> None:
        for p in self.parts:
            p.forget_evaluation()


@dataclass(eq=False, repr=False)
class BundleModel:
    """Several cables in one conduit in an assembled Exudyn system (:func:`build_bundle_model`).

    Attributes
    ----------
    scenario, mbs, system_container, conduit
        As for :class:`~exucable.model.build.Model` (the conduit pull-oriented).
    arrangement : str
        The arrangement laid (``cable.arrangement``, ``auto`` resolved).
    offsets_m : ndarray (n_cables, 2)
        Each cable's axis at the start, (horizontal, up) from the duct axis [m].
    cables : list of CableHandles
    layout : BundleLayout
    properties : CableProperties
    walls : list of ContactKernel
        Each cable's wall kernel (steady sliding).
    between : CableContactKernel
    lead_drives : list of Drive
        The pulling eye's hold on each leading end.
    rope : RopeSolution
        One cable's share: friction μ times the calculators' weight correction, back tension T_b/n
        (the start's tension and the solve's scale).
    rope_alone : RopeSolution
        One cable alone in the conduit with back tension T_b/n: the weight correction's denominator.
    back_tension_N : float
        The bundle's back tension [N] (each trailing end carries 1/n of it).
    """

    scenario: object
    mbs: exu.MainSystem
    system_container: exu.SystemContainer
    conduit: object
    arrangement: str
    offsets_m: np.ndarray
    cables: list
    layout: BundleLayout
    properties: CableProperties
    walls: list
    between: object
    wall_couplings: list
    between_coupling: CableContactCoupling
    lead_drives: list
    rope: object
    rope_alone: object
    back_tension_N: float
    load_scale: object
    mesh: object
    lead_out_m: float
    exit_tangent: np.ndarray
    entry_tangent: np.ndarray | None = None
    lead_drive: Drive | None = None
    trail_drive: Drive | None = None
    applied_pull_force_N: float | None = None
    _ode2_index: np.ndarray | None = field(default=None)
    _loads: list | None = field(default=None)

    def __repr__(self) -> str:
        return (f"BundleModel({self.scenario.name!r}: {len(self.cables)} cables {self.arrangement}, "
                f"{self.cables[0].n_elements} elements each)")

    @property
    def n_cables(self) -> int:
        return len(self.cables)

    @property
    def axial_stiffness_N(self) -> float:
        return self.properties.axial_stiffness_N

    @property
    def kernel(self) -> _Walls:
        return _Walls(self.walls, self.between)

    @property
    def coupling(self) -> _Couplings:
        return _Couplings(self.wall_couplings + [self.between_coupling])

    @property
    def ode2_index(self) -> np.ndarray:
        """The cables' coordinates in the system's ODE2 vector, cable after cable."""
        if self._ode2_index is None:
            self._ode2_index = np.concatenate([
                np.arange(self.mbs.GetNodeODE2Index(n), self.mbs.GetNodeODE2Index(n) + 6)
                for c in self.cables for n in c.nodes])
        return self._ode2_index

    def coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """Absolute nodal coordinates and rates of all cables, each (n_cables·(n_el + 1), 6)."""
        sd = self.mbs.systemData
        q = np.asarray(sd.GetODE2Coordinates())[self.ode2_index]
        v = np.asarray(sd.GetODE2Coordinates_t())[self.ode2_index]
        return self.layout.coordinates + q.reshape(-1, 6), v.reshape(-1, 6)

    def cable_coordinates(self) -> list[np.ndarray]:
        """Each cable's absolute nodal coordinates (n_el + 1, 6)."""
        q, _ = self.coordinates()
        return np.split(q, self.n_cables)

    def pull_shares_N(self) -> np.ndarray:
        """Each cable's pull at the eye [N]: its leading end's reaction along the exit tangent
        (the static solver's multipliers carry the opposite sign of the dynamic one's)."""
        return np.array([-d.force_N(self.mbs) for d in self.lead_drives])

    def cable_loads(self) -> list:
        """Each cable's external loads at the current (static) state, :class:`~exucable.post.tension.CableLoads`:
        the wall's contact forces at its check points, the other cables' (the pair kernel's forces
        on its check points, :meth:`~exucable.contact.cable_pairs.CableContactKernel.point_forces_N`),
        its weight, the back tension's share T_b/n at the trailing end and its leading end's
        reaction in the eye (all three components: the eye holds the end on the exit line)."""
        from ..post.tension import CableLoads, check_point_forces_N
        from .rig import drive_force_vector_N

        Le = self.layout.element_length_m
        x_nodes = np.concatenate([[0.0], np.cumsum(Le)])
        qs = self.cable_coordinates()
        x_between, f_between = self.between.point_forces_N(np.concatenate([q.reshape(-1) for q in qs]))
        sc = self.scenario
        g = (sc.gravity.g_m_per_s2 if sc.gravity is not None else 0.0) * self.load_scale.gravity
        rho_a = self.properties.mass_per_length_kg_per_m
        t_entry = self.exit_tangent if self.entry_tangent is None else self.entry_tangent
        trailing = -(self.back_tension_N / self.n_cables) * self.load_scale.end_force * np.asarray(t_entry, dtype=float)
        out = []
        for i, (q, wall, drive) in enumerate(zip(qs, self.walls, self.lead_drives)):
            pts = wall.points(q.reshape(-1), np.zeros(q.size))
            f_wall = check_point_forces_N(pts.normal, pts.normal_force_N, pts.friction_force_N, pts.velocity_m_per_s)
            out.append(CableLoads(
                point_x_m=np.concatenate([x_nodes[pts.element] + pts.xi * Le[pts.element], x_between]),
                point_force_N=np.concatenate([f_wall, f_between[i]]), node_force_N=np.zeros((len(q), 3)),
                line_load_N_per_m=rho_a * np.array([0.0, 0.0, -g]), mass_per_length_kg_per_m=rho_a,
                acceleration=None, trailing_force_N=trailing.copy(),
                leading_force_N=drive_force_vector_N(self.mbs, drive, static=True)))
        return out

    def tension_N(self, x_m) -> np.ndarray:
        """Each cable's tension [N] at material stations ``x_m`` [m] from the trailing ends, shape
        (n_cables, m): from the equilibrium of its loads (:meth:`cable_loads`,
        :func:`~exucable.post.tension.equilibrium_tension`; the paper's Eq. 24 without the ANCF
        element's strain error next to concentrated contact loads)."""
        from ..post.tension import equilibrium_tension

        Le = self.layout.element_length_m
        return np.stack([equilibrium_tension(q, Le, loads, x_m)
                         for q, loads in zip(self.cable_coordinates(), self.cable_loads())])

    def steady_forces(self, stations=None) -> tuple[float, float, float]:
        """Pulling force (the eye's), trailing tension (the bundle's) and largest cable tension [N]."""
        Le = self.layout.element_length_m
        x = np.concatenate([[0.0], np.cumsum(Le)])
        tmax = max(float(np.max(tension_at(q, Le, self.axial_stiffness_N, x))) for q in self.cable_coordinates())
        return float(np.sum(self.pull_shares_N())), self.back_tension_N * self.load_scale.end_force, tmax

    # ---- the steady equilibrium's residual and stiffness on the cables' coordinates, outside Exudyn
    # (the dynamic relaxation's, exucable.solve.relax): the same forces the static solve balances

    def held_coordinates(self) -> np.ndarray:
        """Indices, among the cables' coordinates (:attr:`ode2_index`'s order), of the coordinates the
        eye holds: each leading node's position."""
        n1 = 6 * (self.cables[0].n_elements + 1)
        return (n1 * np.arange(self.n_cables)[:, None] + (n1 - 6) + np.arange(3)[None, :]).reshape(-1)

    def steady_force(self, q, between=None) -> np.ndarray:
        """The resultant generalized force [N, N·m] on the cables' displacement coordinates ``q``
        (:attr:`ode2_index`'s order) of the steady model at its current load scale: wall contact with
        the steady sliding friction, the cables' elastic forces and weight, the contact between the
        cables and the end loads; the eye's reactions left out (its rows are not balanced). Equal to
        the static solver's residual on the free coordinates, bit for bit (``tests/test_relax.py``).
        ``between``: the pair kernel's result at ``q`` when the caller has it (with its Jacobian,
        :mod:`exucable.solve.block_sweeps`), else evaluated here.
        Needs the compiled cable element (``solver.cable_element = "compiled"``)."""
        q = np.asarray(q, dtype=float)
        self._need_compiled()
        n1 = self.walls[0].n_coordinates
        f = np.empty(q.size)
        for i, coupling in enumerate(self.wall_couplings):
            f[i * n1:(i + 1) * n1] = coupling.force(q[i * n1:(i + 1) * n1], 1.0, jacobian=False)
        if between is None:
            between = self.between.evaluate(self.between_coupling.q_ref + q, jacobian=False)
        f += between.generalized_force
        for i, rows in self._load_rows():
            f[rows] += np.asarray(self.mbs.GetLoadParameter(i, "loadVector"), dtype=float)
        return f

    def stiffness_blocks3(self, q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The stiffness K = −∂f/∂q of :meth:`steady_force` at ``q`` as 3 × 3 blocks (a node's
        positions, a node's slopes): row and column block indices (coordinate // 3) and the blocks,
        shape (m, 3, 3); a pair may repeat (the walls' element blocks, the pairs' node blocks), K is their sum."""
        q = np.asarray(q, dtype=float)
        self._need_compiled()
        n1 = self.walls[0].n_coordinates
        n_el = self.cables[0].n_elements
        a = np.arange(4)
        rows, cols, blocks = [], [], []
        for i, coupling in enumerate(self.wall_couplings):
            B = coupling.stiffness_blocks(q[i * n1:(i + 1) * n1], 1.0)          # (n_el, 12, 12)
            first = i * n1 // 3 + 2 * np.arange(n_el)
            rows.append(np.repeat(first[:, None] + a[None, :], 4, axis=1).reshape(-1))
            cols.append(np.tile(first[:, None] + a[None, :], (1, 4)).reshape(-1))
            blocks.append(B.reshape(n_el, 4, 3, 4, 3).transpose(0, 1, 3, 2, 4).reshape(-1, 3, 3))
        J = self.between.evaluate(self.between_coupling.q_ref + q, jacobian=True).jacobian.tobsr(blocksize=(3, 3))
        rows.append(np.repeat(np.arange(J.shape[0] // 3), np.diff(J.indptr)))
        cols.append(J.indices)
        blocks.append(-J.data)
        return np.concatenate(rows), np.concatenate(cols), np.concatenate(blocks)

    @property
    def steady_force_supported(self) -> bool:
        """Whether :meth:`steady_force` can assemble the residual: the cables' elastic forces are the
        compiled element's (``solver.cable_element = "compiled"``), not Exudyn's objects."""
        return self.wall_couplings[0].cable_forces is not None

    def _need_compiled(self) -> None:
        if not self.steady_force_supported:
            raise ModelError("solver.cable_element", 'the bundle\'s residual outside Exudyn needs the compiled '
                             'cable element; set solver.cable_element = "compiled"')

    def _load_rows(self) -> list:
        """(Exudyn load index, its node's three rows among the cables' coordinates) of every load: the
        end loads, point forces on node positions (their vectors are read at each call: the load scale)."""
        if self._loads is None:
            where = np.full(len(self.mbs.systemData.GetODE2Coordinates()), -1, dtype=np.int64)
            where[self.ode2_index] = np.arange(self.ode2_index.size)
            self._loads = []
            for i in range(self.mbs.systemData.NumberOfLoads()):
                node = self.mbs.GetMarker(self.mbs.GetLoad(i)["markerNumber"])["nodeNumber"]
                self._loads.append((i, where[self.mbs.GetNodeODE2Index(node) + np.arange(3)]))
        return self._loads


def build_bundle_model(scenario, refine: float = 1.0, start_path: str = "clearance") -> BundleModel:
    """Build and assemble the Exudyn system of ``scenario``'s bundle (``cable.count`` > 1, steady mode).

    ``start_path``: ``"clearance"`` lays the bundle's centroid on the rope with clearance's path
    (:func:`_centroid_path`; where that rope has no solution, as ``"axis"``); ``"axis"`` lays the
    arrangement about the duct's axis, turned toward the centreline rope's lateral load
    (:func:`load_turn_rad`), the start before the path was used, kept to compare the two;
    ``"statics"`` lays each cable where the statics of its cross-section puts it, continued along
    the route so that the cables keep their order (:func:`statics_start`; no free spans: the
    cables rest on the wall or each other at every station), except in the last element, blended
    into the circles the eye holds as the other starts lay them there (equal loads on the cables;
    ``"statics_own"``: each cable's load from its own start tension). Measured against
    ``"clearance"`` in ``benchmarks/bundle_start.py`` (``reference/README.md``, "A start from the
    cross-section's statics"): not the default.

    Raises
    ------
    ModelError
        A case the model does not cover (:func:`check_bundle_supported`), an arrangement that does
        not fit, a cable longer than the conduit.
    """
    from ..contact import ContactKernel, ContactLaw
    from ..contact.cable_pairs import CableContactKernel
    from ..contact.steady import SteadySlidingKernel
    from ..quasistatic.rope import solve_rope
    from .build import LoadScale

    sc = scenario
    check_bundle_supported(sc)
    n = sc.cable.count
    c = sc.cable
    arrangement = bundle_arrangement(sc)
    offsets = bundle_offsets(sc)
    conduit = sc.build_conduit()
    if sc.pull.direction == "reverse":
        conduit = conduit.reversed()
    centre = conduit.centreline
    L_cable = sc.cable_length_m
    if L_cable > centre.length_m * (1 + 1e-12):
        raise ModelError("cable.length", f"cable of {L_cable:.6g} m is longer than the conduit "
                         f"({centre.length_m:.6g} m); shorten it or extend the route")
    g = sc.gravity.g_m_per_s2 if sc.gravity is not None else 0.0
    w = c.mass_per_length_kg_per_m * g
    D, d = 2.0 * sc.conduit.inner_radius_m, 2.0 * c.radius_m
    wcf = eng.weight_correction_factor(n, arrangement, D, d)
    back = sc.pull.back_tension_N / n

    def share_rope(length_m, factor):
        return solve_rope(centre, friction=sc.contact.friction * factor, weight_per_length_N_per_m=w,
                          trailing_tension_N=back, cable_length_m=length_m)

    lead_out = (float(sc.solver.steady_lead_out_m) if sc.solver.steady_lead_out_m is not None else
                steady_lead_out_m(centre, c.bending_stiffness_N_m2, share_rope(L_cable, wcf).pull_force_N))
    if lead_out >= L_cable:
        raise ModelError("solver.steady_lead_out", f"{lead_out:.4g} m laid out past the exit leaves none of the "
                         f"{L_cable:.4g} m cable in the conduit; give less than the cable's length")
    rope = share_rope(L_cable - lead_out, wcf)
    rope_alone = share_rope(L_cable - lead_out, 1.0)
    mesh = plan_cable_mesh(sc, conduit, rope, refine)
    n_el = mesh.elements

    s_grid = np.linspace(0.0, centre.length_m, max(2001, 20 * n_el + 1))
    # Rolled over a few elements (a faster roll the cubic elements cannot follow: measured 1 mm into
    # the wall and 2 mm into each other at 1 m elements and a 0.5 m roll)
    T_ref = max(float(np.max(rope.tension_N)), 1e-6)
    blend = max(L_cable / n_el, math.sqrt(c.bending_stiffness_N_m2 / T_ref))
    if start_path not in BUNDLE_STARTS:
        raise ModelError("start_path", f"{start_path!r} is not a bundle start; use one of "
                                       + ", ".join(f'"{x}"' for x in BUNDLE_STARTS))
    path = _centroid_path(centre, offsets, sc.contact.friction * wcf, w, back, L_cable - lead_out) \
        if start_path != "axis" else None
    start_rope = rope if path is None else path
    tension_fns = start_tensions(centre, start_rope, offsets, sc.conduit.inner_radius_m - c.radius_m, w, back)
    if path is None:
        # the arrangement turned, station by station, to the lateral load the share rope puts on a
        # cable (its rigid-circle rest under that load): in a bend the tension presses the bundle to
        # the bend's inner wall, and a start left resting on the bottom there is far from any equilibrium
        turn = load_turn_rad(centre, s_grid, np.interp(s_grid, rope.s_conduit_m, rope.tension_N), w, blend)
        centroid_fn = None
    else:
        # the bundle's centroid on the path of the rope with clearance, the arrangement turned toward
        # the wall that path bears on: free spans cross the duct where they do (see _centroid_path)
        P = np.stack([np.interp(s_grid, path.s_conduit_m, path.offset_m[:, j]) for j in range(3)], axis=1)
        # smoothed as the roll is, and the roll taken from its direction wherever it is near the wall,
        # so that the arrangement turns with the path (a roll lagging the path's turn onto a bend's
        # wall put the cables into the wall and into one another)
        P = _smooth_rows(P, blend / (s_grid[1] - s_grid[0]))
        near = np.linalg.norm(P, axis=1) > 0.5 * path.clearance_m
        turn = _turn_toward(centre, s_grid, P, near if near.any() else None, 0.0)

        def centroid_fn(s):
            return np.stack([np.interp(s, s_grid, P[:, j]) for j in range(3)], axis=1)
    # laid as circles START_GAP·r larger: the cables start that far off the wall and apart, so what
    # the fit and the roll leave over is a gap the first steps close, not an overlap they must undo
    # (cable.positions are laid where the user put them: they have no larger circles to take)
    laid, laid_r = offsets, c.radius_m
    if c.positions_m is None:
        try:
            laid = arrangement_offsets(n, arrangement, sc.conduit.inner_radius_m, (1.0 + START_GAP) * c.radius_m)
            laid_r = (1.0 + START_GAP) * c.radius_m
        except ModelError:
            pass

    # ...except in the last element before the exit and beyond: the eye holds the leading ends where
    # they are laid, and there they are the rigid circles (a gap held open at the eye is not the pull's)
    L_e = L_cable / n_el
    layouts = []
    mid0, mid1 = offsets.mean(axis=0), laid.mean(axis=0)
    statics = None
    if start_path in ("statics", "statics_own"):
        statics = statics_start(centre, tension_fns, w, sc.conduit.inner_radius_m, laid_r, laid, s_grid, turn, blend,
                                own_tensions=start_path == "statics_own")
    laid_radius = float(np.max(np.hypot(laid[:, 0], laid[:, 1])))   # the laid circles' distance to the wall
    for (h0, v0), (h1, v1), cable_tension_fn in zip(offsets, laid, tension_fns):
        def offset_fn(s, h0=h0, v0=v0, h1=h1, v1=v1, i=len(layouts)):
            eh, ev = _cross_section_frame(centre, s)
            f = np.clip((centre.length_m - np.asarray(s, dtype=float)) / L_e, 0.0, 1.0)[:, None]
            if statics is not None:
                # the cross-section's statics, blended in the last element into the circles the eye
                # holds (the rigid arrangement turned as the other starts turn it there)
                phi = np.interp(s, s_grid, turn)[:, None]
                x = statics.offsets_m(s, i)
                h = f * x[:, :1] + (1.0 - f) * (h0 * np.cos(phi) - v0 * np.sin(phi))
                v = f * x[:, 1:] + (1.0 - f) * (h0 * np.sin(phi) + v0 * np.cos(phi))
                return h * eh + v * ev
            h, v = h0 + f * (h1 - h0), v0 + f * (v1 - v0)
            phi = np.interp(s, s_grid, turn)[:, None]
            o = (h * np.cos(phi) - v * np.sin(phi)) * eh + (h * np.sin(phi) + v * np.cos(phi)) * ev
            if centroid_fn is not None:
                # the centroid moved onto the path (scaled as the laid circles are), except at the eye,
                # which holds the ends where the circles rest (the blend's f: 0 there)
                mh, mv = mid0[0] + f * (mid1[0] - mid0[0]), mid0[1] + f * (mid1[1] - mid0[1])
                k = mv / float(mid0[1])
                mid = (mh * np.cos(phi) - mv * np.sin(phi)) * eh + (mh * np.sin(phi) + mv * np.cos(phi)) * ev
                o = o + f * (k * centroid_fn(s) - mid)
                # where the turn (smoothed) lags the path's direction, a cable would stand out of the
                # duct: held at its laid distance from the axis instead
                cap = np.hypot(h0 + f[:, 0] * (h1 - h0), v0 + f[:, 0] * (v1 - v0))
                cap = np.maximum(cap, laid_radius)
                size = np.linalg.norm(o, axis=1)
                over = size > cap
                o[over] *= (cap[over] / size[over])[:, None]
            return o
        layouts.append(lay_cable(centre, L_cable, n_el, c.axial_stiffness_N, sc.pull.speed_m_per_s, cable_tension_fn,
                                 offset_fn, lead_out_m=lead_out))
    Le = layouts[0].element_length_m
    layout = BundleLayout(element_length_m=Le, cables=layouts, n_cables=n)

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    # no Kelvin-Voigt damping, as for one steady cable (exucable.model.build): it acts on the nodal
    # rates, which a static solve never updates, so Exudyn's element added the start's sliding rates'
    # damping force to the equilibrium (pull shares 7e-6 to 1.5e-5 off on coarse cases)
    props = CableProperties(
        mass_per_length_kg_per_m=c.mass_per_length_kg_per_m, axial_stiffness_N=c.axial_stiffness_N,
        bending_stiffness_N_m2=c.bending_stiffness_N_m2, axial_damping_N_s=0.0,
        bending_damping_N_m2_s=0.0, integration=c.integration)
    t_exit = np.asarray(centre.tangent(centre.length_m), dtype=float)
    t_entry = np.asarray(centre.tangent(centre.length_m - L_cable + lead_out), dtype=float)
    load_scale = LoadScale()
    ct = sc.contact
    wall_law = ContactLaw(stiffness=ct.stiffness, damping=ct.damping, exponent=ct.exponent, friction=ct.friction,
                          regularisation_velocity_m_per_s=ct.friction_regularisation_velocity_m_per_s,
                          damping_onset_m=ct.damping_onset_m)
    # the cables' elastic forces and weight assembled by exucable in each wall coupling's user
    # function (solver.cable_element, as for one cable), or by Exudyn's ANCF elements and loads
    compiled = sc.solver.cable_element == "compiled"
    if compiled:
        from ..contact.ancf_cable import AncfCableForces
        load_scale.cable_forces = _GravityScales()
    cables, walls, couplings, drives = [], [], [], []
    for lay in layouts:
        cable = add_cable(mbs, lay.coordinates, Le, props, lay.velocities, draw_radius_m=c.radius_m,
                          with_elements=not compiled)
        cables.append(cable)
        forces = None
        if compiled:
            forces = AncfCableForces(Le, props.axial_stiffness_N, props.bending_stiffness_N_m2, props.integration,
                                     props.mass_per_length_kg_per_m, [0.0, 0.0, -g])
            load_scale.cable_forces.parts.append(forces)
        elif g > 0:
            vec = [0.0, 0.0, -g]
            loads = add_gravity(mbs, cable, vec)
            load_scale.track(gravity_loads=loads, vectors={i: vec for i in loads})
        if back > 0:
            vec = list(-back * t_entry)
            i = add_end_force(mbs, cable.nodes[0], vec)
            load_scale.track(end_loads=[i], vectors={i: vec})
        drives.append(add_drive(mbs, cable.nodes[-1], t_exit, 0.0))
        kernel = SteadySlidingKernel(conduit.segments, Le, c.radius_m, wall_law, mesh.check_points_per_element,
                                     rule=ct.check_point_rule, reference_spacing_m=ct.reference_spacing_m,
                                     broad_phase=ct.broad_phase, surface=ct.surface, centreline=centre,
                                     speed_m_per_s=sc.pull.speed_m_per_s)
        walls.append(kernel)
        couplings.append(ContactCoupling(mbs, cable.nodes, lay.coordinates, kernel, cable_forces=forces))
    between_law = ContactLaw(stiffness=ct.stiffness, damping=0.0, exponent=ct.exponent, friction=ct.cable_friction,
                             regularisation_velocity_m_per_s=ct.friction_regularisation_velocity_m_per_s)
    # the broad phase's window: one element either side, plus how far apart the cables' nodes of
    # one index start along the route (the outer cable's longer path through bends)
    s_nodes = np.stack([lay.node_s_m for lay in layouts])
    drift = float(np.max(s_nodes.max(axis=0) - s_nodes.min(axis=0)))
    k = mesh.check_points_per_element
    window = k * (2 + int(math.ceil(drift / float(np.min(Le))))) + 2
    between = CableContactKernel(n, Le, c.radius_m, between_law, k, ct.reference_spacing_m,
                                 sc.pull.speed_m_per_s, window=window)
    all_nodes = [nd for cable in cables for nd in cable.nodes]
    between_coupling = CableContactCoupling(mbs, all_nodes, layout.coordinates, between)
    mbs.Assemble()
    return BundleModel(
        scenario=sc, mbs=mbs, system_container=SC, conduit=conduit, arrangement=arrangement, offsets_m=offsets,
        cables=cables, layout=layout, properties=props, walls=walls, between=between, wall_couplings=couplings,
        between_coupling=between_coupling, lead_drives=drives, rope=rope, rope_alone=rope_alone,
        back_tension_N=sc.pull.back_tension_N, load_scale=load_scale, mesh=mesh, lead_out_m=lead_out,
        exit_tangent=t_exit, entry_tangent=t_entry)


def straight_weight_correction(model: BundleModel, s_from_m: float, s_to_m: float) -> float | None:
    """The bundle's weight correction factor emerging on a straight between ``s_from_m`` and
    ``s_to_m`` of the pull-oriented conduit [-], or None where the cables' weight gives no friction.

    On a straight of slope sin θ = t_z (t along the pull) the cables' tensions rise by
    ΣΔT = n w (sin θ + w_c μ cos θ) Δs, so w_c = (ΣΔT/n - w sin θ Δs)/(μ w cos θ Δs): the bundle's
    friction over what the same cables would have alone. Measured between two stations inside
    the straight, away from the cables' ends and the bends' bending boundary layers; each cable's
    station is its material point laid there at the start (the steady state moves it by its strain),
    its tension from the equilibrium of its loads (:meth:`BundleModel.tension_N`).
    """
    sc = model.scenario
    g = sc.gravity.g_m_per_s2 if sc.gravity is not None else 0.0
    w = sc.cable.mass_per_length_kg_per_m * g
    mu = sc.contact.friction
    centre = model.conduit.centreline
    t = np.asarray(centre.tangent(0.5 * (s_from_m + s_to_m)), dtype=float).reshape(3)
    cos_t = math.sqrt(max(0.0, 1.0 - t[2] ** 2))
    ds = s_to_m - s_from_m
    if not (mu * w * cos_t * ds > 0.0):
        return None
    at = _bundle_tension_at(model)
    T = at([s_from_m, s_to_m])
    rise = float(T[1] - T[0])
    n = model.n_cables
    return (rise / n - w * t[2] * ds) / (mu * w * cos_t * ds)


def bundle_report(model: BundleModel) -> dict:
    """What a bundle's steady state says, in SI units (``summary.json``'s bundle keys).

    ``pull_force_N`` (the eye's), ``trailing_tension_N`` (the bundle's back tension), ``max_tension_N``;
    ``weight_correction_factor``: (F - T_b)/(n (F_1 - T_b/n)) with F_1 the rope pull force of one
    cable alone with back tension T_b/n in the same extent (the bundle's friction over the cables'
    alone, the whole route, ends included); ``formula_weight_correction_factor`` (the calculators');
    ``straights``: per straight of at least four cable diameters inside the cable's extent, its
    factor from the tension rise over its middle half (:func:`straight_weight_correction`);
    ``cables``: per cable its pull share (N and fraction), trailing tension, largest tension, wall
    normal force and contact force from the other cables (sums over its check points [N]), its start
    offset in the duct.
    """
    sc = model.scenario
    n = model.n_cables
    shares = model.pull_shares_N()
    F = float(np.sum(shares))
    Tb = model.back_tension_N
    alone = model.rope_alone.pull_force_N - Tb / n
    D, d = 2.0 * sc.conduit.inner_radius_m, 2.0 * sc.cable.radius_m
    Le = model.layout.element_length_m
    qs = model.cable_coordinates()
    q_all = np.concatenate([q.reshape(-1) for q in qs])
    between = model.between.contacts(q_all)
    n_points = model.between.n_points
    owner = between["index"] // n_points
    push = np.linalg.norm(between["force"].reshape(-1, 3, 3), axis=2)      # |force| on P, B0, B1
    from_others = np.zeros(n)
    for col in range(3):
        np.add.at(from_others, owner[:, col], push[:, col])
    from ..post.tension import profile_stations_m

    tensions = model.tension_N(profile_stations_m(Le))
    cables = []
    for i, (q, k, T) in enumerate(zip(qs, model.walls, tensions)):
        pts = k.points(q.reshape(-1), np.zeros(q.size))
        cables.append({
            "cable": i + 1,
            "pull_share_N": float(shares[i]),
            "pull_share": float(shares[i] / F) if F != 0.0 else None,
            "trailing_tension_N": Tb / n,
            "max_tension_N": float(np.max(T)),
            "wall_normal_force_N": float(np.sum(pts.normal_force_N)),
            "cable_contact_force_N": float(from_others[i]),
            "start_offset_horizontal_m": float(model.offsets_m[i, 0]),
            "start_offset_up_m": float(model.offsets_m[i, 1]),
        })
    centre = model.conduit.centreline
    lay0 = model.layout.cables[0]
    s_lo, s_hi = float(np.min(lay0.node_s_m)), min(float(np.max(lay0.node_s_m)), centre.length_m)
    straights = []
    for piece in centre.pieces:
        if piece.is_curved:
            continue
        a, b = max(piece.s_start_m, s_lo), min(piece.s_start_m + piece.length_m, s_hi)
        if b - a < 4.0 * d:
            continue
        s0, s1 = piece.s_start_m, piece.s_start_m + piece.length_m
        if sc.pull.direction == "reverse":      # along the scenario's conduit, as every file
            s0, s1 = centre.length_m - s1, centre.length_m - s0
        straights.append({"s_conduit_start_m": s0, "s_conduit_end_m": s1,
                          "weight_correction_factor": straight_weight_correction(model, a + 0.25 * (b - a),
                                                                                 a + 0.75 * (b - a))})
    return {
        "count": n,
        "arrangement": model.arrangement,
        "positions_given": sc.cable.positions_m is not None,
        "pull_force_N": F,
        "trailing_tension_N": Tb,
        "max_tension_N": max(c["max_tension_N"] for c in cables),
        "weight_correction_factor": (F - Tb) / (n * alone) if alone > 0.0 else None,
        "formula_weight_correction_factor": eng.weight_correction_factor(n, model.arrangement, D, d),
        "rope_pull_force_one_cable_N": model.rope_alone.pull_force_N,
        "contacts_at_window_edge": int(np.count_nonzero(between["edge"])),
        "straights": straights,
        "cables": cables,
        "lead_out_m": model.lead_out_m,
    }


def bundle_tension_profile(model: BundleModel, points_per_element: int = 4) -> dict:
    """``x_m`` (material coordinate from the trailing ends) and each cable's ``cable_<k>_tension_N`` [N],
    from the equilibrium of its loads (:meth:`BundleModel.tension_N`)."""
    from ..post.tension import profile_stations_m

    x = profile_stations_m(model.layout.element_length_m, points_per_element)
    out = {"x_m": x}
    for i, T in enumerate(model.tension_N(x)):
        out[f"cable_{i + 1}_tension_N"] = T
    return out


def _extent_m(model) -> tuple[float, float]:
    """The stretch of the pull-oriented centreline every cable covers [m]."""
    s_nodes = [lay.node_s_m for lay in model.layout.cables]
    L = model.conduit.centreline.length_m
    return max(0.0, max(float(np.min(s)) for s in s_nodes)), min(L, min(float(np.max(s)) for s in s_nodes))


def _bundle_tension_at(model):
    """s along the pull-oriented centreline [m] → the cables' tensions summed there [N] (each
    cable's material point laid at s, as :func:`straight_weight_correction`; each tension from the
    equilibrium of the cable's loads, :meth:`BundleModel.tension_N`)."""
    from ..post.tension import equilibrium_tension

    Le = model.layout.element_length_m
    qs = model.cable_coordinates()
    loads = model.cable_loads()

    def at(s_m):
        s = np.atleast_1d(np.asarray(s_m, dtype=float))
        return sum(equilibrium_tension(q, Le, load, np.interp(s, lay.node_s_m, lay.node_x_m))
                   for lay, q, load in zip(model.layout.cables, qs, loads))
    return at


def bundle_sections(model) -> dict:
    """The arrangement found in each straight and bend, the jam, and the sidewall pressure per bend on
    the most loaded cable beside the calculators' (:mod:`exucable.post.bundle`): ``sections``,
    ``bends``, ``jam``, ``jam_s_conduit_m``, ``duct_over_cable_diameter``, ``in_jam_range``,
    ``formula_sidewall_pressure_factor``."""
    from ..post.bundle import arrangement_sections, bend_pressures
    from ..post.pressure import default_window_m

    sc = model.scenario
    centre = model.conduit.centreline
    reverse = sc.pull.direction == "reverse"
    R, r = sc.conduit.inner_radius_m, sc.cable.radius_m
    qs = model.cable_coordinates()
    sections = arrangement_sections(centre.pieces, qs, model.layout.element_length_m, centre, R, r,
                                    _extent_m(model), reverse=reverse)
    s_pts, f_pts = [], []
    for q, k in zip(qs, model.walls):
        pts = k.points(q.reshape(-1), np.zeros(q.size))
        s = np.asarray(pts.s_conduit_m, dtype=float)
        keep = np.isfinite(s)
        s_pts.append(s[keep])
        f_pts.append(np.asarray(pts.normal_force_N, dtype=float)[keep])
    n = model.n_cables
    factor = eng.sidewall_pressure_factor(n, model.arrangement, eng.weight_correction_factor(n, model.arrangement, 2 * R, 2 * r))
    at = _bundle_tension_at(model)
    bends = bend_pressures(centre.pieces, s_pts, f_pts, lambda x: float(at(x)[0]), default_window_m(centre), factor,
                           sc.cable.bending_stiffness_N_m2, reverse=reverse)
    jams = [row for row in sections if row["jam"]]
    return {"sections": sections, "bends": bends, "jam": bool(jams),
            "jam_s_conduit_m": jams[0]["jam_s_conduit_m"] if jams else None,
            "duct_over_cable_diameter": R / r, "in_jam_range": eng.in_jam_range(n, 2 * R, 2 * r),
            "formula_sidewall_pressure_factor": factor}


def bundle_cross_sections(model, s_conduit_m) -> np.ndarray:
    """Each cable's axis in the planes across the scenario's conduit at ``s_conduit_m`` [m]:
    (horizontal, up) from the duct's axis looking along the pull [m], shape (m, n_cables, 2)."""
    from ..post.bundle import cross_section_offsets

    centre = model.conduit.centreline
    s = np.asarray(s_conduit_m, dtype=float)
    if model.scenario.pull.direction == "reverse":
        s = centre.length_m - s
    return cross_section_offsets(model.cable_coordinates(), model.layout.element_length_m, centre, s)


def bundle_tension_along_conduit(model) -> tuple[np.ndarray, np.ndarray]:
    """The bundle's tension (the cables' summed) [N] at the first cable's node places along the
    scenario's conduit [m], as :func:`exucable.run.cable_tension_along_conduit` for one cable."""
    s = np.clip(np.asarray(model.layout.cables[0].node_s_m, dtype=float), 0.0, model.conduit.centreline.length_m)
    T = _bundle_tension_at(model)(s)
    if model.scenario.pull.direction == "reverse":
        s = model.conduit.centreline.length_m - s
    return s, T
