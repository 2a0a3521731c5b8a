"""Independent quasi-static rope solution: a cable without bending stiffness sliding through a 3D conduit.

This is the project's reference against which the multibody model is checked (see
``reference/README.md``, "The rope equation behind the closed forms"). It uses numpy and scipy only; it knows nothing
of Exudyn or of the contact kernel.

A cable with unit tangent ``t``, curvature vector ``κn`` [1/m] and weight per length ``w = ρAg`` [N/m]
(acting along ``−e_z``), sliding steadily toward increasing arc length ``s``, satisfies

    dT/ds = μ · |T κn − w (e_z − (e_z·t) t)| + w (e_z·t),

the first term being Coulomb friction on the sidewall bearing pressure (paper Eq. 19 applied per unit length)
and the second the weight component along the cable. The bearing pressure is

    p(s) = |T κn − w (e_z − (e_z·t) t)|   [N/m].

On a straight incline this gives the paper's Eq. (25); without weight it gives the capstan law, Eq. (26).

The centreline only needs the interface of :mod:`exucable.geometry`'s ``Centreline``: ``length_m``,
``pieces`` (each with ``s_start_m``, ``length_m`` and ``tangent_and_curvature_fn()``), ``tangent(s)``,
``curvature_vector(s)`` and ``reversed()``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from exucable.errors import ModelError

# scipy.integrate and scipy.optimize are imported where needed: a route of straights and
# gravity-free or horizontal bends is integrated in closed form (_closed_form), the other curved
# pieces by Chebyshev collocation (_chebyshev_piece, numpy only), and importing them (with the
# scipy.sparse and scipy.special they pull in) is a quarter to a third of a second of an
# `exucable run` (the fixed cost, docs/performance.md). solve_ivp remains the fallback where the
# collocation does not reach its tolerance or the tension reaches zero inside a piece.

__all__ = ["RopeSolution", "solve_rope", "solve_rope_for_pull_force", "rope_pull_force_N", "sidewall_pressure_N_per_m"]

# solve_ivp tolerances. DOP853 at rtol 1e-11 reproduces the closed forms to ~1e-12 relative; the absolute
# tolerance only matters where T passes close to zero (slack onset) and is set far below any force of interest.
_RTOL = 1e-11
_ATOL_N = 1e-13
# Evaluation points inside a piece are kept this fraction of the piece length away from its ends, so that the
# centreline never answers with the curvature of the neighbouring piece (κ jumps at piece boundaries).
_EDGE_FRACTION = 1e-12
# Grid used to find where a slack stretch of cable becomes taut again (see _end_of_slack).
_SLACK_SCAN_POINTS = 257

_E_Z = np.array([0.0, 0.0, 1.0])


def _as_rows(v, n: int) -> np.ndarray:
    """Geometry answers (3,) for a scalar and (n, 3) for an array; always return (n, 3)."""
    return np.asarray(v, dtype=float).reshape(n, 3)


def _transverse_load(centreline, s_m: np.ndarray, tension_N: np.ndarray, w_N_per_m: float):
    """Return (T κn − w (e_z − (e_z·t) t), e_z·t) at arc lengths ``s_m`` [m] with tensions ``tension_N`` [N]."""
    s = np.atleast_1d(np.asarray(s_m, dtype=float))
    n = s.size
    t = _as_rows(centreline.tangent(s), n)
    kn = _as_rows(centreline.curvature_vector(s), n)
    tz = t[:, 2]
    gravity_perp = _E_Z[None, :] - tz[:, None] * t  # e_z − (e_z·t) t
    load = np.asarray(tension_N, dtype=float).reshape(-1, 1) * kn - w_N_per_m * gravity_perp
    return load, tz


def sidewall_pressure_N_per_m(centreline, s_m, tension_N, weight_per_length_N_per_m: float = 0.0) -> np.ndarray:
    """Sidewall bearing pressure p = |T κn − w (e_z − (e_z·t) t)| [N/m].

    Parameters
    ----------
    centreline : Centreline
        Conduit centreline (see module docstring for the interface used).
    s_m : array_like
        Conduit arc lengths [m].
    tension_N : array_like
        Cable tension at those arc lengths [N] (broadcast against ``s_m``).
    weight_per_length_N_per_m : float
        Weight per length w = ρAg [N/m], acting along −z.

    Returns
    -------
    ndarray
        Bearing pressure [N/m], same length as ``s_m``.
    """
    s = np.atleast_1d(np.asarray(s_m, dtype=float))
    tension = np.broadcast_to(np.asarray(tension_N, dtype=float), s.shape)
    load, _ = _transverse_load(centreline, s, tension, float(weight_per_length_N_per_m))
    return np.linalg.norm(load, axis=1)


@dataclass(frozen=True, eq=False)
class RopeSolution:
    """Quasi-static tension along a cable pulled through a conduit.

    Arrays are ordered from the trailing end (``s_cable_m = 0``) to the leading, pulled end.

    Attributes
    ----------
    s_conduit_m : ndarray
        Arc length along the *original* conduit centreline of each output point [m]; it increases along the
        cable for ``direction="forward"`` and decreases for ``"reverse"``.
    s_cable_m : ndarray
        Distance along the cable from its trailing end [m].
    tension_N : ndarray
        Cable tension T [N].
    sidewall_pressure_N_per_m : ndarray
        Sidewall bearing pressure p [N/m] (at a point where κ jumps, the value of one of the two sides).
    pull_force_N : float
        Tension at the leading (pulled) end [N].
    trailing_tension_N : float
        Tension at the trailing end (back tension) [N].
    max_tension_N : float
        Largest tension along the cable [N], over the output grid and the integrator's nodes.
    max_sidewall_pressure_N_per_m : float
        Largest bearing pressure [N/m], over the same points evaluated on both sides of every piece boundary.
    direction : str
        ``"forward"`` or ``"reverse"``.
    slack : bool
        True if the tension was clamped at zero somewhere (the cable runs slack there).
    """

    s_conduit_m: np.ndarray
    s_cable_m: np.ndarray
    tension_N: np.ndarray
    sidewall_pressure_N_per_m: np.ndarray
    pull_force_N: float
    trailing_tension_N: float
    max_tension_N: float
    max_sidewall_pressure_N_per_m: float
    direction: str = "forward"
    slack: bool = False
    # (s_lo, s_hi, T(s)) in cable coordinates; T from a closed form, solve_ivp's dense output or a constant 0 (slack).
    _branches: tuple = field(default=(), repr=False)

    @property
    def cable_length_m(self) -> float:
        """Length of the cable inside the conduit [m]."""
        return float(self.s_cable_m[-1])

    def tension_at(self, s_cable_m) -> np.ndarray | float:
        """Tension [N] at distances ``s_cable_m`` [m] from the trailing end, from the integrator's dense output.

        Accurate to about the integration tolerance (1e-11 relative), unlike interpolation of ``tension_N``.
        Raises ``ValueError`` outside ``[0, cable_length_m]``.
        """
        s = np.asarray(s_cable_m, dtype=float)
        flat = np.atleast_1d(s).ravel()
        length = self.cable_length_m
        tol = 1e-12 * max(length, 1.0)
        if np.any(flat < -tol) or np.any(flat > length + tol):
            raise ValueError(f"s_cable_m outside the cable [0, {length:g}] m")
        out = _evaluate_branches(self._branches, np.clip(flat, 0.0, length))
        return float(out[0]) if s.ndim == 0 else out.reshape(s.shape)


def _evaluate_branches(branches, s: np.ndarray) -> np.ndarray:
    """Tension [N] at cable coordinates ``s`` [m] (1-D) from (s_lo, s_hi, fn) branches covering them."""
    out = np.full(s.shape, np.nan)
    for s_lo, s_hi, fn in branches:
        mask = np.isnan(out) & (s >= s_lo) & (s <= s_hi)
        if np.any(mask):
            out[mask] = fn(s[mask])
    return out


def _piece_intervals(centreline, s_from: float, s_to: float) -> list[tuple[float, float, float, float, object]]:
    """Pieces clipped to [s_from, s_to] as (lo, hi, piece_lo, piece_hi) [m] and the piece, in order;
    empty ones dropped."""
    out = []
    for piece in sorted(centreline.pieces, key=lambda p: p.s_start_m):
        a = float(piece.s_start_m)
        b = a + float(piece.length_m)
        lo, hi = max(a, s_from), min(b, s_to)
        if hi - lo > 1e-14 * max(1.0, abs(s_to)):
            out.append((lo, hi, a, b, piece))
    return out


def _inside(piece_lo: float, piece_hi: float) -> tuple[float, float]:
    """Interval of a piece shrunk by a hair at both ends [m], so that evaluations there see this piece's curvature
    (the centreline answers with the later piece exactly at a boundary)."""
    edge = _EDGE_FRACTION * (piece_hi - piece_lo) + 4.0 * np.spacing(max(abs(piece_lo), abs(piece_hi)))
    return piece_lo + edge, piece_hi - edge


def _end_of_slack(g0: Callable[[float], float], s_lo: float, s_hi: float) -> float:
    """First arc length in (s_lo, s_hi] where the slack rate g0(s) = dT/ds|_{T=0} turns positive.

    Scans ``_SLACK_SCAN_POINTS`` points and refines with brentq; a taut excursion shorter than the scan
    spacing would be missed (irrelevant for the piecewise-constant-curvature routes used here).
    """
    grid = np.linspace(s_lo, s_hi, _SLACK_SCAN_POINTS)
    values = np.array([g0(x) for x in grid])
    idx = np.nonzero(values[1:] > 0.0)[0]
    if idx.size == 0:
        return s_hi
    i = idx[0] + 1  # values[i - 1] <= 0 < values[i]
    from scipy.optimize import brentq

    return float(brentq(g0, grid[i - 1], grid[i], xtol=1e-14 * max(1.0, abs(s_hi)), rtol=1e-15))


# A piece counts as straight, horizontal or of constant curvature if these hold to this relative tolerance
# at _SHAPE_PROBES points inside it (rounding of the geometry's own evaluation is ~1e-16).
_SHAPE_TOLERANCE = 1e-12
_SHAPE_PROBES = 5


def _closed_form(curve, s_min: float, s_max: float, mu: float, w: float):
    """The rope ODE's exact solution on one piece, where it has one; else None.

    Returns ``advance(s, T, s_to) -> (s_end, T_end, fn)``: the tension from ``T`` [N] at ``s`` on to
    ``s_to``, or to where it reaches zero first (``s_end``), ``fn`` the vectorised T(s) on [s, s_end].
    Three cases of dT/ds = μ|T κn − w g⊥| + w t_z (module docstring), exact where DOP853 is accurate to
    its tolerance (1e-11):

    - straight (κ = 0): the rate is the constant c = μ w |g⊥| + w t_z, T = T₀ + c (s − s₀) (paper Eq. 25);
    - no weight, |κ| constant (bend, helix): T = T₀ exp(μ|κ|(s − s₀)), the capstan law (paper Eq. 26);
    - a horizontal bend with weight (t and κn ⟂ e_z, |κ| constant): dT/ds = μ √(κ²T² + w²), so
      asinh(κT/w) grows linearly: T = (w/κ) sinh(μκ(s − s₀) + asinh(κT₀/w)).
    """
    probes = np.linspace(s_min, s_max, _SHAPE_PROBES)
    t = _as_rows(curve.tangent(probes), _SHAPE_PROBES)
    kn = _as_rows(curve.curvature_vector(probes), _SHAPE_PROBES)
    kappa = np.linalg.norm(kn, axis=1)
    if np.all(kappa == 0.0) and np.all(np.abs(t - t[0]) <= _SHAPE_TOLERANCE):
        load, tz = _transverse_load(curve, probes[:1], np.zeros(1), w)
        rate = mu * float(np.linalg.norm(load[0])) + w * float(tz[0])

        def advance(s, T, s_to):
            if rate < 0.0 and T < -rate * (s_to - s):     # downhill: T reaches zero inside (the ODE's event)
                s_end, T_end = s + T / -rate, 0.0
            else:
                s_end, T_end = s_to, max(T + rate * (s_to - s), 0.0)
            return s_end, T_end, lambda x: np.maximum(T + rate * (np.asarray(x, dtype=float) - s), 0.0)

        return advance
    k = float(kappa[0])
    if k == 0.0 or np.any(np.abs(kappa - k) > _SHAPE_TOLERANCE * k):
        return None
    if w == 0.0:
        def advance(s, T, s_to):
            return s_to, T * math.exp(mu * k * (s_to - s)), \
                lambda x: T * np.exp(mu * k * (np.asarray(x, dtype=float) - s))

        return advance
    if np.all(np.abs(t[:, 2]) <= _SHAPE_TOLERANCE) and np.all(np.abs(kn[:, 2]) <= _SHAPE_TOLERANCE * k):
        def advance(s, T, s_to):
            a = math.asinh(k * T / w)
            return s_to, (w / k) * math.sinh(mu * k * (s_to - s) + a), \
                lambda x: (w / k) * np.sinh(mu * k * (np.asarray(x, dtype=float) - s) + a)

        return advance
    return None


# Chebyshev collocation of the rope ODE on a curved piece without a closed form (a bend or helix
# with weight out of its plane). On such a piece t(s) and κn(s) are trigonometric in s and the rate
# is smooth in T wherever the load T κn − w g⊥ does not vanish, so the tension is analytic
# there and a polynomial of modest degree on a short interval reproduces it to rounding: the
# piece is cut into intervals turning the tangent by at most _CHEB_MAX_TURN_RAD, T is collocated
# at _CHEB_DEGREE + 1 Chebyshev points of each (Newton on T = T₀ + ∫ rate), and an interval whose
# last two Chebyshev coefficients exceed _CHEB_TOLERANCE of its tension is halved. Against DOP853
# at rtol 1e-11 the pulling force agrees to ≤ 2.4e-12 on the shipped routes (tests/test_rope.py).
_CHEB_DEGREE = 20
_CHEB_MAX_TURN_RAD = 0.5
_CHEB_TOLERANCE = 1e-14
_CHEB_MAX_HALVINGS = 6
_CHEB_NEWTON_ITERATIONS = 30
_CHEB_CACHE: dict = {}


def _chebyshev_matrices(n: int):
    """Chebyshev–Lobatto points x ∈ [−1, 1] (ascending), the map from values there to Chebyshev
    coefficients, and the matrix giving ∫₋₁^x of the interpolant at those points."""
    if n not in _CHEB_CACHE:
        cheb = np.polynomial.chebyshev
        x = -np.cos(np.pi * np.arange(n + 1) / n)
        to_coefficients = np.linalg.inv(cheb.chebvander(x, n))
        antiderivative = np.column_stack([cheb.chebint(np.eye(n + 1)[j], lbnd=-1.0) for j in range(n + 1)])
        _CHEB_CACHE[n] = (x, to_coefficients, cheb.chebvander(x, n + 1) @ antiderivative @ to_coefficients)
    return _CHEB_CACHE[n]


def _chebyshev_interval(piece, s_min, s_max, mu, w, a, b, T_a):
    """T on [a, b] from T(a) = ``T_a`` [N]: (node arc lengths, tensions, Chebyshev coefficients);
    None where Newton does not converge or the coefficients do not fall below the tolerance (a
    shorter interval may do), False where the tension does not stay positive (slack: solve_ivp's
    event finds where it ends)."""
    x, to_coefficients, integral = _chebyshev_matrices(_CHEB_DEGREE)
    half = 0.5 * (b - a)
    s = a + (x + 1.0) * half
    s[0], s[-1] = a, b
    u = np.clip(s, s_min, s_max) - piece.s_start_m     # as the ODE's rate: this piece's frame only
    t = _as_rows(piece.tangent(u), s.size)
    kn = _as_rows(piece.curvature_vector(u), s.size)
    tz = t[:, 2]
    g = w * tz[:, None] * t
    g[:, 2] -= w                                           # −w (e_z − (e_z·t) t)
    Q = half * integral
    T = np.full(s.size, float(T_a))
    for _ in range(_CHEB_NEWTON_ITERATIONS):
        load = T[:, None] * kn + g
        norm = np.sqrt(np.einsum("ij,ij->i", load, load))
        if not np.all(norm > 0.0):
            return None
        rate = mu * norm + w * tz
        d_rate = mu * np.einsum("ij,ij->i", load, kn) / norm
        residual = T - T_a - Q @ rate
        step = np.linalg.solve(np.eye(s.size) - Q * d_rate[None, :], -residual)
        T = T + step
        if np.max(np.abs(step)) <= 1e-15 * max(np.max(np.abs(T)), 1e-300):
            break
    else:
        return None
    if not np.all(T[1:] > 0.0):
        return False
    c = to_coefficients @ T
    if np.max(np.abs(c[-2:])) > _CHEB_TOLERANCE * np.max(np.abs(T)):
        return None
    return s, T, c


def _chebyshev_piece(piece, s_min, s_max, mu, w, s0, s1, T0):
    """The rope ODE from ``T0`` [N] at ``s0`` to ``s1`` [m] on one curved piece by Chebyshev
    collocation: (T(s1), [(s_lo, s_hi, fn, nodes), ...]), or None (the caller integrates the piece
    with solve_ivp: the tension approaches zero, or the load vanishes and the rate has a kink)."""
    turns = abs(piece.curvature_1_per_m) * (s1 - s0) / _CHEB_MAX_TURN_RAD
    edges = np.linspace(s0, s1, max(1, math.ceil(turns)) + 1)
    # intervals still to do, first last, each with the number of halvings that made it
    todo = [(a, b, 0) for a, b in zip(edges[-2::-1], edges[:0:-1])]
    out, T = [], float(T0)
    while todo:
        a, b, depth = todo.pop()
        found = _chebyshev_interval(piece, s_min, s_max, mu, w, a, b, T)
        if found is False:
            return None
        if found is None:
            if depth >= _CHEB_MAX_HALVINGS:
                return None
            middle = 0.5 * (a + b)
            todo += [(middle, b, depth + 1), (a, middle, depth + 1)]
            continue
        nodes, values, c = found
        out.append((a, b, _chebyshev_fn(c, a, b), nodes))
        T = float(values[-1])
    return T, out


def _chebyshev_fn(coefficients, a: float, b: float):
    """T(s) [N] of one collocation interval [a, b] [m], vectorised."""
    def fn(s):
        x = (2.0 * np.asarray(s, dtype=float) - (a + b)) / (b - a)
        return np.maximum(np.polynomial.chebyshev.chebval(x, coefficients), 0.0)

    return fn


class _OnePiece:
    """One piece of a centreline answering ``tangent`` and ``curvature_vector`` at centreline arc
    lengths inside it, as the centreline would (the same piece method at the same local arc
    length), without the centreline's range check and piece lookup."""

    def __init__(self, piece):
        self.piece = piece

    def tangent(self, s_m):
        return self.piece.tangent(np.asarray(s_m, dtype=float) - self.piece.s_start_m)

    def curvature_vector(self, s_m):
        return self.piece.curvature_vector(np.asarray(s_m, dtype=float) - self.piece.s_start_m)


def _integrate(curve, mu_straight: float, w: float, s0: float, s1: float, trailing_N: float, dense: bool,
               mu_curved: float | None = None):
    """Integrate the rope ODE from s0 to s1 on ``curve``; return (T(s1) [N], branches, slack).

    ``mu_curved``: friction in curved pieces (default ``mu_straight``).

    branches (only if ``dense``): list of (s_lo, s_hi, piece_lo, piece_hi, fn, nodes) in curve coordinates,
    ``fn`` the vectorised tension T(s) [N] on [s_lo, s_hi], ``nodes`` the integrator's steps (for maxima).
    """
    branches = []
    slack_seen = False
    tension = float(trailing_N)
    for lo, hi, plo, phi, piece in _piece_intervals(curve, s0, s1):
        s_min, s_max = _inside(plo, phi)
        local = _OnePiece(piece)
        curved = bool(np.linalg.norm(_as_rows(local.curvature_vector(np.array([0.5 * (lo + hi)])), 1)[0]) > 0.0)
        mu = mu_curved if (curved and mu_curved is not None) else mu_straight

        def rate(s, y, s_min=s_min, s_max=s_max, mu_here=mu, frame=piece.tangent_and_curvature_fn(), s_piece=plo):
            # s is clamped into the piece so that RK stages at the piece's end use this piece's curvature.
            # The sidewall load T κn − w (e_z − (e_z·t) t) of _transverse_load in plain floats: DOP853
            # calls this ~100 times a piece, and numpy's overhead on 3-vectors was 90 % of its cost.
            sc = min(max(s, s_min), s_max)
            (tx, ty, tz), (kx, ky, kz) = frame(sc - s_piece)
            T = float(y[0])
            load = math.hypot(T * kx + w * tz * tx, T * ky + w * tz * ty, T * kz - w * (1.0 - tz * tz))
            return [mu_here * load + w * tz]

        def g0(s, rate=rate):
            return rate(s, [0.0])[0]

        def hits_zero(s, y):
            return y[0]

        hits_zero.terminal = True
        hits_zero.direction = -1.0
        exact = _closed_form(local, s_min, s_max, mu, w)

        s = lo
        for _ in range(10_000):  # guard: every pass advances s (a slack stretch or an ODE run)
            if s >= hi:
                break
            rate_at_zero = g0(s) if tension <= 0.0 else 1.0
            if rate_at_zero <= 0.0:
                # Steep downhill with no tension left: the rope ODE would drive T negative, which a cable cannot
                # carry. Clamp T = 0 (the cable runs slack) until the weight/friction balance turns positive.
                # (rate 0 exactly, e.g. no weight and no back tension, keeps T = 0 without being "slack".)
                slack_seen = slack_seen or rate_at_zero < 0.0
                s_next = _end_of_slack(g0, s, hi)
                if dense:
                    branches.append((s, s_next, plo, phi, _zero, np.array([s, s_next])))
                s, tension = s_next, 0.0
                if s >= hi:
                    break
            if exact is not None:
                s_end, tension, fn = exact(s, tension, hi)
                if dense:
                    branches.append((s, s_end, plo, phi, fn, np.array([s, s_end])))
                s = s_end
                continue
            if curved:
                collocated = _chebyshev_piece(piece, s_min, s_max, mu, w, s, hi, tension)
                if collocated is not None:
                    tension, parts = collocated
                    if dense:
                        branches.extend((a, b, plo, phi, fn, nodes) for a, b, fn, nodes in parts)
                    s = hi
                    continue
            from scipy.integrate import solve_ivp

            sol = solve_ivp(rate, (s, hi), [tension], method="DOP853", rtol=_RTOL, atol=_ATOL_N,
                            dense_output=dense, events=hits_zero)
            if sol.status < 0:
                raise ModelError("rope", f"rope ODE integration failed at s = {s:.6g} m: {sol.message}")
            if sol.status == 1:  # tension reached zero inside the piece; the next pass decides if it stays slack
                s_end = float(sol.t_events[0][0])
                tension = 0.0
            else:
                s_end = hi
                tension = max(float(sol.y[0, -1]), 0.0)
            if dense:
                branches.append((s, s_end, plo, phi, _dense_fn(sol.sol), sol.t))
            s = s_end
        else:  # pragma: no cover
            raise ModelError("rope", f"rope ODE made no progress near s = {s:.6g} m")
    return tension, branches, slack_seen


def _zero(s):
    return np.zeros_like(np.asarray(s, dtype=float))


def _dense_fn(ode_solution):
    def fn(s):
        return np.maximum(ode_solution(np.asarray(s, dtype=float))[0], 0.0)

    return fn


def _validate(centreline, friction, w, direction, cable_length_m):
    mu = float(friction)
    if not np.isfinite(mu) or mu < 0.0:
        raise ModelError("friction", f"friction coefficient must be finite and >= 0, got {friction!r}")
    w = float(w)
    if not np.isfinite(w) or w < 0.0:
        raise ModelError("weight_per_length_N_per_m", f"weight per length must be finite and >= 0, got {w!r}")
    if direction not in ("forward", "reverse"):
        raise ModelError("direction", f"direction must be 'forward' or 'reverse', got {direction!r}")
    conduit_length = float(centreline.length_m)
    length = conduit_length if cable_length_m is None else float(cable_length_m)
    if not np.isfinite(length) or length <= 0.0:
        raise ModelError("cable_length_m", f"cable length must be > 0, got {cable_length_m!r}")
    if length > conduit_length * (1.0 + 1e-12):
        raise ModelError("cable_length_m", f"cable ({length:g} m) is longer than the conduit ({conduit_length:g} m)")
    return mu, w, min(length, conduit_length), conduit_length


def _trailing_tension(value) -> float:
    trailing = float(value)
    if not np.isfinite(trailing) or trailing < 0.0:
        raise ModelError("trailing_tension_N", f"trailing tension must be finite and >= 0, got {value!r}")
    return trailing


def solve_rope(centreline, friction: float, weight_per_length_N_per_m: float = 0.0, trailing_tension_N: float = 0.0,
               direction: str = "forward", cable_length_m: float | None = None, n_output: int = 801,
               bend_friction: float | None = None) -> RopeSolution:
    """Tension along a rope pulled steadily through a conduit, given the trailing (back) tension.

    Integrates ``dT/ds = μ|T κn − w(e_z − (e_z·t)t)| + w(e_z·t)`` piece by piece (restarting at every piece
    boundary, where κ jumps) in closed form where it has one (straights; bends without weight or
    horizontal ones, see ``_closed_form``), on the other curved pieces by Chebyshev collocation
    (``_chebyshev_piece``, to ~1e-14), elsewhere with scipy's DOP853 at rtol 1e-11.

    If the ODE would drive the tension negative (a downhill stretch steeper than the friction angle,
    tan θ > μ), the tension is clamped at 0: the cable runs slack there, and the tension rises again from 0
    where the slope flattens. ``RopeSolution.slack`` reports it.

    Parameters
    ----------
    centreline : Centreline
        Conduit centreline (``exucable.geometry``).
    friction : float
        Coulomb friction coefficient μ between cable and conduit [-].
    weight_per_length_N_per_m : float
        Weight per length w = ρAg [N/m], acting along −z.
    trailing_tension_N : float
        Back tension at the trailing end [N] (>= 0).
    direction : {"forward", "reverse"}
        "forward": the cable is pulled out at the conduit's end (s = L), moving toward increasing s.
        "reverse": pulled out at s = 0 (solved on ``centreline.reversed()``).
    cable_length_m : float, optional
        Length of cable in the conduit [m]; default the conduit length. A shorter cable lies in the leading
        part of the conduit (forward: from s = L − cable_length to L).
    n_output : int
        Number of points of the output profile (uniform in cable length).
    bend_friction : float, optional
        Friction coefficient in curved pieces (bends, helices) [-], default ``friction``. Lets a pull
        plan apply a calculation convention that corrects friction differently on straights and in bends
        (``cable.weight_correction_in_bends``).

    Returns
    -------
    RopeSolution
    """
    if bend_friction is not None:
        bend_mu = float(bend_friction)
        if not np.isfinite(bend_mu) or bend_mu < 0.0:
            raise ModelError("bend_friction", f"bend friction coefficient must be finite and >= 0, got {bend_friction!r}")
    else:
        bend_mu = None
    mu, w, length, conduit_length = _validate(centreline, friction, weight_per_length_N_per_m, direction,
                                              cable_length_m)
    trailing = _trailing_tension(trailing_tension_N)
    if int(n_output) < 2:
        raise ModelError("n_output", "n_output must be >= 2")
    curve = centreline if direction == "forward" else centreline.reversed()
    s0 = conduit_length - length  # trailing end, in the coordinates of `curve`
    pull, raw_branches, slack = _integrate(curve, mu, w, s0, conduit_length, trailing, dense=True, mu_curved=bend_mu)

    # Branches in cable coordinates (s_cable = s_curve − s0).
    # The first and last branch are widened to exactly [0, length] so that rounding of s0 leaves no gap.
    branches = [[b[0] - s0, b[1] - s0, _shifted(b[4], s0, b[0], b[1])] for b in raw_branches]
    branches[0][0], branches[-1][1] = 0.0, length
    branches = tuple(tuple(b) for b in branches)
    s_cable = np.linspace(0.0, length, int(n_output))
    s_curve = s_cable + s0
    s_curve[-1] = conduit_length  # exact end despite rounding
    tension = _evaluate_branches(branches, s_cable)
    tension[0] = trailing
    tension[-1] = pull
    pressure = sidewall_pressure_N_per_m(curve, s_curve, tension, w)

    # Maxima over the output grid plus the integrator's nodes, each evaluated inside its own piece.
    # (one pressure evaluation for all branches: each point lies inside its own piece, so the
    # centreline answers for it as it would alone)
    pts, tens = [], []
    for s_lo, s_hi, plo, phi, fn, nodes in raw_branches:
        p = np.clip(np.concatenate([nodes, [s_lo, s_hi], s_curve[(s_curve >= s_lo) & (s_curve <= s_hi)]]),
                    *_inside(plo, phi))
        pts.append(p)
        tens.append(fn(p))
    pts, tens = np.concatenate(pts), np.concatenate(tens)
    max_t = max(float(np.max(tension)), float(np.max(tens)))
    max_p = max(float(np.max(pressure)), float(np.max(sidewall_pressure_N_per_m(curve, pts, tens, w))))

    s_conduit = s_curve if direction == "forward" else conduit_length - s_curve
    return RopeSolution(
        s_conduit_m=s_conduit,
        s_cable_m=s_cable,
        tension_N=tension,
        sidewall_pressure_N_per_m=pressure,
        pull_force_N=float(pull),
        trailing_tension_N=trailing,
        max_tension_N=max_t,
        max_sidewall_pressure_N_per_m=max_p,
        direction=direction,
        slack=bool(slack),
        _branches=branches,
    )


def rope_pull_force_N(centreline, friction: float, weight_per_length_N_per_m: float = 0.0,
                      trailing_tension_N: float = 0.0, direction: str = "forward",
                      cable_length_m: float | None = None) -> float:
    """The pulling force [N] of :func:`solve_rope` alone, bit for bit: the same integration without
    its dense output, tension profile and maxima (for a caller that needs only the force, such as
    :func:`exucable.model.layout.steady_lead_out_m`'s rule). Parameters as in :func:`solve_rope`."""
    mu, w, length, conduit_length = _validate(centreline, friction, weight_per_length_N_per_m, direction,
                                              cable_length_m)
    trailing = _trailing_tension(trailing_tension_N)
    curve = centreline if direction == "forward" else centreline.reversed()
    return float(_integrate(curve, mu, w, conduit_length - length, conduit_length, trailing, dense=False)[0])


def _shifted(fn, offset, lo, hi):
    """fn in cable coordinates: s_curve = s_cable + offset, kept inside the branch's own range [lo, hi]."""
    def shifted(s):
        return fn(np.clip(np.asarray(s, dtype=float) + offset, lo, hi))

    return shifted


def solve_rope_for_pull_force(centreline, friction: float, pull_force_N: float,
                              weight_per_length_N_per_m: float = 0.0, direction: str = "forward",
                              cable_length_m: float | None = None) -> RopeSolution:
    """Force-controlled pull: the trailing tension for which the leading end carries ``pull_force_N``.

    The map trailing tension → pull force is continuous and non-decreasing (strictly increasing unless the
    cable runs slack), so the trailing tension is found with brentq on it. If the cable runs slack for every
    trailing tension up to the root, the smallest trailing tension (0) is returned.

    Parameters
    ----------
    centreline, friction, weight_per_length_N_per_m, direction, cable_length_m
        As in :func:`solve_rope`.
    pull_force_N : float
        Tension applied at the leading end [N].

    Returns
    -------
    RopeSolution
        The full solution for the trailing tension found.

    Raises
    ------
    ModelError
        If ``pull_force_N`` is below the force needed to pull the cable with zero back tension.
    """
    mu, w, length, conduit_length = _validate(centreline, friction, weight_per_length_N_per_m, direction,
                                              cable_length_m)
    target = float(pull_force_N)
    if not np.isfinite(target) or target < 0.0:
        raise ModelError("pull_force_N", f"pull force must be finite and >= 0, got {pull_force_N!r}")
    curve = centreline if direction == "forward" else centreline.reversed()
    s0 = conduit_length - length

    def pull_of(trailing):
        return _integrate(curve, mu, w, s0, conduit_length, trailing, dense=False)[0]

    minimum = pull_of(0.0)
    if target < minimum * (1.0 - 1e-12):
        raise ModelError("pull_force_N", f"pull force {target:.6g} N is below {minimum:.6g} N, the force needed to "
                                          "pull this cable with zero back tension")
    if target <= minimum:
        trailing = 0.0
    else:
        hi = max(target, 1e-9)
        f_hi = pull_of(hi)
        for _ in range(200):
            if f_hi >= target:
                break
            hi *= 2.0
            f_hi = pull_of(hi)
        else:  # pragma: no cover - the pull force grows at least linearly in the back tension
            raise ModelError("pull_force_N", "could not bracket the trailing tension")
        from scipy.optimize import brentq

        trailing = float(brentq(lambda x: pull_of(x) - target, 0.0, hi, xtol=1e-15 * max(1.0, hi), rtol=1e-14))
    return solve_rope(centreline, mu, w, trailing, direction, length)
