"""The friction coefficient fitted to a tension log, its 95 % interval, and the rest of the pull forecast.

Model. With the head x metres into the conduit, the rope reference (:func:`exucable.plan.pull.pull_in_rope`,
plan's conventions for several cables) gives the head tension T(x; μ): the pull-in history that
``exucable plan`` writes to ``pull_in_<direction>.csv``. T is smooth in μ, so it is solved on a grid of μ
(:data:`GRID_STEP`) and interpolated between by a cubic spline in μ, which is linear in the grid's
histories: T(x; μ) = Σ_k φ_k(μ) H_k(x) with φ_k the spline's cardinal functions. The sum of squares
SSE(μ) = |y|² − 2 φ(μ)·(H y) + φ(μ)ᵀ (H Hᵀ) φ(μ) then costs a few grid-sized products per μ, and is
minimised for every bootstrap resample at once on a fine μ grid, refined by a parabola through the
three points around the minimum (SSE is locally quadratic in μ).

Interval. A log's residuals are correlated in time (the dynamometer's drift, the tension's slow waves),
so resampling them one by one would make the interval too narrow. The residuals are resampled in blocks
(the circular block bootstrap, Politis & Romano 1992) whose length is chosen from their autocorrelation
by Politis & White (2004, with Patton, Politis & White 2009's correction); each resample y* = T(x; μ̂) + r*
is refitted, and the 2.5 and 97.5 percentiles of the refitted μ* are the 95 % interval.

One coefficient? The used rows are split at their median pulled length and μ fitted to each half alone;
the difference of the halves' μ is compared with its distribution over the same resamples, which were
made with one μ. A difference beyond it (p < :data:`ONE_COEFFICIENT_P`) means one coefficient does not
explain the log (the friction changed along the route or in time, or the tare is wrong).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline

from exucable.errors import LogError, ScenarioError
from exucable.fit.log import PullLog
from exucable.plan.pull import PlanSpec, plan_spec, pull_in_rope
from exucable.quasistatic import engineering as eng
from exucable.scenario.specs import Scenario

__all__ = ["FrictionFit", "RopeFamily", "SteadyFamily", "fit_friction_steady", "FIT_ENGINES", "resolve_fit_engine", "STEADY_NODE_FACTORS", "fit_friction", "SEPARABLE_CORRELATION", "SEPARABLE_HALF_WIDTH", "block_length", "GRID_STEP", "FINE_BELOW", "ONE_COEFFICIENT_P", "CONFIDENCE"]

#: Step of the μ grid on which the rope is solved [-], a fifth of it below :data:`FINE_BELOW`; between, a
#: cubic spline in μ (error of the interpolated history against a direct solve: tests/test_fit.py).
GRID_STEP = 0.025
FINE_BELOW = 0.1
#: Below this p-value the halves' coefficients differ by more than the log's noise explains.
ONE_COEFFICIENT_P = 0.01
#: Confidence of the reported intervals.
CONFIDENCE = 0.95
_FINE = 501  # points of the fine μ grid over [0, mu_max]; a parabola refines between them


def block_length(residuals: np.ndarray) -> int:
    """Block length for the circular block bootstrap (Politis & White 2004; Patton et al. 2009).

    The flat-top lag-window estimate b = (2 G² / D)^(1/3) n^(1/3), G = Σ λ(k/M)|k|R(k),
    D = (4/3) (Σ λ(k/M) R(k))², M = 2 m̂ with m̂ the first lag after which K_n autocorrelations stay
    below 2·sqrt(log10(n)/n). Clipped to [1, n/3].
    """
    r = np.asarray(residuals, dtype=float) - float(np.mean(residuals))
    n = r.size
    if n < 8:
        return 1
    var = float(r @ r) / n
    if var == 0.0:
        return 1
    max_lag = min(n - 1, int(math.ceil(math.sqrt(n))) + max(5, int(math.ceil(math.sqrt(math.log10(n))))))
    max_lag = max(max_lag, min(n - 1, 10))
    acov = np.array([float(r[:n - k] @ r[k:]) / n for k in range(max_lag + 1)])
    rho = acov / acov[0]
    kn = max(5, int(math.ceil(math.sqrt(math.log10(n)))))
    bound = 2.0 * math.sqrt(math.log10(n) / n)
    m_hat = max_lag
    for m in range(1, max_lag - kn + 1):
        if np.all(np.abs(rho[m + 1:m + 1 + kn]) < bound):
            m_hat = m
            break
    # a slowly wandering residual (drift) keeps its autocorrelation above the bound out to the longest
    # lag looked at: then every lag counts
    M = min(2 * m_hat, max_lag)
    k = np.arange(-M, M + 1)
    t = np.abs(k) / max(M, 1)
    lam = np.where(t <= 0.5, 1.0, np.where(t <= 1.0, 2.0 * (1.0 - t), 0.0))
    R = acov[np.abs(k)]
    g = float(np.sum(lam * np.abs(k) * R))
    s0 = float(np.sum(lam * R))
    if s0 <= 0.0:
        return 1
    d = 4.0 / 3.0 * s0 ** 2
    b = (2.0 * g * g / d) ** (1.0 / 3.0) * n ** (1.0 / 3.0)
    return int(min(max(1, math.ceil(b)), max(1, n // 3)))


def _circular_blocks(r: np.ndarray, count: int, rng) -> tuple[np.ndarray, int]:
    """``count`` circular block resamples (count × n) of the series ``r``, and the block length."""
    n = r.size
    b = block_length(r)
    blocks = int(math.ceil(n / b))
    starts = rng.integers(0, n, size=(count, blocks))
    idx = (starts[:, :, None] + np.arange(b)[None, None, :]) % n
    return r[idx.reshape(count, blocks * b)[:, :n]], b


def _ar_sieve(r: np.ndarray, count: int, rng) -> tuple[np.ndarray, int]:
    """``count`` AR-sieve resamples (count × n) of the series ``r`` (Bühlmann 1997) and the AR order.

    An AR(p) is fitted by Yule–Walker (Levinson–Durbin), p ≤ 10 log10(n) chosen by AIC; series are
    regenerated from its resampled, centred innovations after a burn-in of n steps, so that a slow drift
    is reproduced over the whole log, not only within blocks.
    """
    n = r.size
    x = r - r.mean()
    p_max = int(min(10 * math.log10(max(n, 10)), n // 4))
    acov = np.array([float(x[:n - k] @ x[k:]) / n for k in range(p_max + 1)])
    if acov[0] == 0.0:
        return np.zeros((count, n)), 0
    # Levinson–Durbin: coefficients and innovation variance of every order
    best = (n * math.log(acov[0]), 0, np.zeros(0))
    a = np.zeros(0)
    v = acov[0]
    for k in range(1, p_max + 1):
        kappa = (acov[k] - float(a @ acov[1:k][::-1])) / v
        a = np.concatenate([a - kappa * a[::-1], [kappa]])
        v *= (1.0 - kappa * kappa)
        if v <= 0:
            break
        aic = n * math.log(v) + 2 * k
        if aic < best[0]:
            best = (aic, k, a.copy())
    _, p, a = best
    if p == 0:
        return x[rng.integers(0, n, size=(count, n))], 0
    e = x[p:] - np.array([a @ x[t - p:t][::-1] for t in range(p, n)])
    e = e - e.mean()
    burn = n
    draws = e[rng.integers(0, e.size, size=(count, n + burn))]
    out = np.zeros((count, n + burn + p))
    for t in range(n + burn):
        out[:, t + p] = out[:, t:t + p][:, ::-1] @ a + draws[:, t]
    return out[:, p + burn:], p


RESAMPLERS = {"block": _circular_blocks, "ar": _ar_sieve}


class RopeFamily:
    """The rope's full pulls on the μ grid [0, mu_max] for one scenario and direction: solved once, reused
    for every log read from the same pull (``--watch``) and every synthetic log of a test.

    Parameters
    ----------
    scenario : Scenario
    spec : PlanSpec, optional
        Several cables per duct (default: from the scenario).
    direction : {"forward", "reverse"}, optional
        Default ``pull.direction``.
    mu_max : float
        Largest μ [-] on the grid.
    """

    def __init__(self, scenario: Scenario, spec: PlanSpec | None = None, direction: str | None = None,
                 mu_max: float = 1.0):
        if not (np.isfinite(mu_max) and mu_max > 0):
            raise LogError("--mu-max", f"must be > 0, got {mu_max}")
        if scenario.pull.force_N is not None:
            raise ScenarioError("pull.force", "a pull-in history starts from the reel's back tension; give "
                                              "pull.back_tension instead of a prescribed pull.force")
        self.scenario = scenario
        self.spec = spec or plan_spec(scenario)
        self.direction = direction or scenario.pull.direction
        self.mu_max = float(mu_max)
        # finer below FINE_BELOW: there the wall's load turns from the weight to T/R as μ grows, a bend
        # within a step of μ
        fine = np.arange(0.0, min(FINE_BELOW, mu_max), GRID_STEP / 5)
        coarse = np.arange(fine[-1] + GRID_STEP / 5, mu_max + 0.5 * GRID_STEP, GRID_STEP)
        nodes = np.concatenate([fine, coarse[coarse <= mu_max + 1e-12]])
        self.nodes = nodes if nodes[-1] >= mu_max - 1e-12 else np.append(nodes, mu_max)
        self.ropes = [pull_in_rope(scenario, self.spec, self.direction, friction=float(mu)) for mu in self.nodes]
        self.route_length_m = float(self.ropes[0].cable_length_m)
        d = 2.0 * scenario.cable.radius_m
        D = 2.0 * scenario.conduit.inner_radius_m
        spec = self.spec
        arrangement = eng.auto_arrangement(spec.count, D, d) if spec.arrangement == "auto" else spec.arrangement
        self.sidewall_pressure_factor = eng.sidewall_pressure_factor(
            spec.count, arrangement, eng.weight_correction_factor(spec.count, arrangement, D, d))

    engine = "rope"

    def histories(self, x_m: np.ndarray) -> np.ndarray:
        """Head tension [N] at head positions ``x_m`` [m] (clipped to the route), one row per grid μ."""
        return np.asarray([r.tension_at(np.clip(x_m, 0.0, r.cable_length_m)) for r in self.ropes])

    def max_tensions_N(self) -> list:
        """The largest tension of the pull [N] at each grid μ."""
        return [r.max_tension_N for r in self.ropes]


class SteadyFamily(RopeFamily):
    """The multibody model's pull-in histories on the μ grid, from a few steady histories.

    The multibody history (:func:`exucable.solve.pull_in.steady_pull_in`) costs seconds to minutes per μ,
    the rope's milliseconds. Their ratio T_mb(x; μ) / T_rope(x; μ) is smooth in μ and x (both grow by the
    same capstan exponentials; the ratio carries what the rope misses: the stiffness at bends, free spans),
    so the multibody history is solved at a few μ (``mu_nodes``) and its ratio to the rope interpolated:
    in x linearly between the history's head positions (which include every piece end), in μ by the
    polynomial through the nodes (quadratic for three), held at the end nodes' values outside them.
    Then T(x; μ_k) = T_rope(x; μ_k) · ratio(x; μ_k) on the rope family's grid, and the fit proceeds as
    with the rope (:func:`fit_friction`). How well the interpolation in μ holds:
    ``tests/test_fit_steady.py`` (against a history solved directly between the nodes).

    Parameters
    ----------
    scenario, spec, direction, mu_max
        As :class:`RopeFamily`; one cable (``cable.count = 1``).
    mu_nodes : sequence of float
        The μ [-] at which the multibody history is solved (one to four; the fit should fall between
        the outer ones: :attr:`mu_span`).
    points : int
        Uniform head positions of each history (:func:`exucable.solve.pull_in.pull_in_grid_m`).
    solved : dict, optional
        Histories solved before, by μ (:attr:`solved`), not solved again.
    """

    engine = "steady"

    def __init__(self, scenario: Scenario, spec: PlanSpec | None = None, direction: str | None = None,
                 mu_max: float = 1.0, *, mu_nodes, points: int | None = None, solved: dict | None = None):
        from exucable.solve.pull_in import DEFAULT_POINTS, steady_pull_in  # builds Exudyn models

        super().__init__(scenario, spec, direction, mu_max)
        if self.spec.count != 1:
            raise ScenarioError("cable.count", f"--engine steady simulates one cable, got {self.spec.count}; fit "
                                               "several cables per duct with --engine rope")
        mu = np.unique(np.asarray(mu_nodes, dtype=float))
        if not (1 <= mu.size <= 4) or mu[0] <= 0.0 or mu[-1] > self.mu_max:
            raise LogError("--engine", f"the multibody histories need 1 to 4 friction values in (0, {self.mu_max}], "
                                       f"got {list(mu)}")
        self.steady_mu = mu
        self.steady = []
        self._ratio = []
        for m in mu:
            h = (solved or {}).get(float(m))
            if h is None:
                sc = scenario.replace(**{"contact.friction": float(m), "pull.direction": self.direction})
                h = steady_pull_in(sc, DEFAULT_POINTS if points is None else points)
            ok = np.isfinite(h.pull_force_N)
            if np.count_nonzero(ok) < 2:
                raise LogError("--engine", f"the multibody pull-in history at friction {m:.4g} failed: "
                                           f"{h.messages[-1]}; fit with --engine rope")
            rope = pull_in_rope(scenario, self.spec, self.direction, friction=float(m))
            x = h.pulled_length_m[ok]
            T_rope = np.asarray(rope.tension_at(np.clip(x, 0.0, rope.cable_length_m)), dtype=float)
            # where the rope carries nothing (no back tension, the head at the entrance) the two agree: 1
            ratio = np.divide(h.pull_force_N[ok], T_rope, out=np.ones_like(T_rope), where=T_rope > 1e-9)
            self.steady.append(h)
            self._ratio.append((x, ratio))

    @property
    def solved(self) -> dict:
        """The multibody histories by μ."""
        return {float(m): h for m, h in zip(self.steady_mu, self.steady)}

    @property
    def mu_span(self) -> tuple[float, float]:
        """The smallest and largest μ [-] with a multibody history: between them the ratio is interpolated."""
        return float(self.steady_mu[0]), float(self.steady_mu[-1])

    @property
    def cpu_time_s(self) -> float:
        """Process CPU time [s] of the multibody histories."""
        return float(sum(h.cpu_time_s for h in self.steady))

    def ratio(self, x_m: np.ndarray) -> np.ndarray:
        """T_mb / T_rope [-] at head positions ``x_m`` [m], one row per grid μ."""
        R = np.array([np.interp(x_m, x, r) for x, r in self._ratio])           # (J, n)
        mu = np.clip(self.nodes, *self.mu_span)
        # Lagrange basis of the nodes at every grid μ: (K, J)
        nodes = self.steady_mu
        w = np.ones((mu.size, nodes.size))
        for j in range(nodes.size):
            for m in range(nodes.size):
                if m != j:
                    w[:, j] *= (mu - nodes[m]) / (nodes[j] - nodes[m])
        return w @ R

    def histories(self, x_m: np.ndarray) -> np.ndarray:
        x = np.clip(np.asarray(x_m, dtype=float), 0.0, self.route_length_m)
        return super().histories(x) * self.ratio(x)

    def max_tensions_N(self) -> list:
        # the cable's largest tension is at its head: the history's largest value
        x = np.linspace(0.0, self.route_length_m, 241)
        return list(np.max(self.histories(x), axis=1))


class _Histories:
    """T(x; μ) on the μ grid at the points x, interpolated in μ (cardinal cubic spline)."""

    def __init__(self, mu_nodes: np.ndarray, H: np.ndarray):
        self.mu_nodes = mu_nodes
        self.H = H                                   # (K, n)
        self.mu_fine = np.linspace(mu_nodes[0], mu_nodes[-1], _FINE)
        self.phi = CubicSpline(mu_nodes, np.eye(mu_nodes.size), axis=0)(self.mu_fine)   # (F, K)
        self.quad = np.sum((self.phi @ (H @ H.T)) * self.phi, axis=1)   # |T(μ)|² on the fine grid

    def at(self, mu) -> np.ndarray:
        return CubicSpline(self.mu_nodes, self.H, axis=0)(mu)

    def fit(self, Y: np.ndarray, rows: np.ndarray | None = None) -> np.ndarray:
        """Least-squares μ for each row of Y (B × n) over the columns ``rows`` (all by default)."""
        H = self.H if rows is None else self.H[:, rows]
        Yr = Y if rows is None else Y[:, rows]
        G = H @ Yr.T                                 # (K, B)
        quad = self.quad if rows is None else np.sum((self.phi @ (H @ H.T)) * self.phi, axis=1)
        sse = quad[:, None] - 2.0 * (self.phi @ G)   # (F, B), without the constant |y|²
        j = np.argmin(sse, axis=0)
        jj = np.clip(j, 1, self.mu_fine.size - 2)
        cols = np.arange(sse.shape[1])
        a, b, c = sse[jj - 1, cols], sse[jj, cols], sse[jj + 1, cols]
        den = a - 2.0 * b + c
        h = self.mu_fine[1] - self.mu_fine[0]
        shift = np.where(den > 0, 0.5 * (a - c) / np.where(den > 0, den, 1.0), 0.0)
        mu = self.mu_fine[jj] + np.clip(shift, -1.0, 1.0) * h
        return np.where((j == 0) | (j == self.mu_fine.size - 1), self.mu_fine[j], mu)


@dataclass
class FrictionFit:
    """A fitted friction coefficient, its interval, the fit's diagnostics and the forecast (SI).

    Attributes
    ----------
    friction : float
        Least-squares μ [-].
    friction_interval : tuple of float
        95 % interval [low, high] of μ (circular block bootstrap of the residuals).
    one_coefficient : dict
        ``explains`` (bool), ``p_value``, the halves' ``split_pulled_length_m``, ``first_half_friction`` and
        ``second_half_friction`` with their intervals.
    residual_std_N, resampling, bootstrap_samples, engine, direction
        The fit's residual scatter [N], how the residuals were resampled (``method`` with
        ``block_length_rows`` or ``ar_order``) and how often, the engine and the pull direction.
    pulled_length_m, pull_force_N, fitted_N, residual_N : numpy.ndarray
        The used rows: pulled length [m], reading [N], the model at μ̂ [N], reading − model [N].
    curve : dict
        On a grid over the whole route: ``pulled_length_m``, ``pull_force_N`` (at μ̂), ``low_N``/``high_N``
        (the band of the friction interval) and ``reading_low_N``/``reading_high_N`` (that band widened by
        the readings' scatter: where 95 % of readings should fall).
    forecast : dict or None
        For a partial log: the rest of the pull from the last used reading (``pulled_length_m``,
        ``pull_force_N``, ``low_N``, ``high_N``).
    expected : dict
        At μ̂ with the interval: pull force at the end, maximum tension, maximum sidewall pressure
        (each ``*_N`` / ``*_N_per_m`` with ``*_interval_*``), and per given limit, where it would be reached.
    log : dict
        The log's cleaning report (:attr:`exucable.fit.log.PullLog.report`) and rows beyond the route.
    warnings : list of str
    steady : dict or None
        With the multibody engine (:func:`fit_friction_steady`): the ``mu_nodes`` of its histories, the rope
        fit of the same log (``rope_friction``, ``rope_friction_interval``), ``history_points`` and
        ``history_cpu_time_s``.
    straights_and_bends : dict or None
        With ``separate``: ``friction_straights``, ``friction_bends`` with ``*_interval``, their
        ``correlation``, ``bends_minus_straights_interval``, ``separable`` (the log tells them apart: correlation
        within ±:data:`SEPARABLE_CORRELATION`, each half-width within :data:`SEPARABLE_HALF_WIDTH` of its
        value), ``differ`` (separable and the difference's interval excludes 0), ``reason`` when not separable.
    """

    friction: float
    friction_interval: tuple
    one_coefficient: dict
    residual_std_N: float
    resampling: dict
    bootstrap_samples: int
    engine: str
    direction: str
    partial: bool
    pulled_length_m: np.ndarray
    pull_force_N: np.ndarray
    fitted_N: np.ndarray
    residual_N: np.ndarray
    curve: dict
    forecast: dict | None
    expected: dict
    log: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    straights_and_bends: dict | None = None
    steady: dict | None = None

    def to_json(self) -> dict:
        """The content of ``fit.json``."""
        out = {
            "friction": self.friction,
            "friction_interval": list(self.friction_interval),
            "confidence": CONFIDENCE,
            "engine": self.engine,
            "direction": self.direction,
            "partial": self.partial,
            "one_coefficient": self.one_coefficient,
            "residual_std_N": self.residual_std_N,
            "resampling": self.resampling,
            "bootstrap_samples": self.bootstrap_samples,
            "rows_fitted": int(self.pulled_length_m.size),
            "expected": self.expected,
            "log": self.log,
            "warnings": self.warnings,
        }
        if self.straights_and_bends is not None:
            out["straights_and_bends"] = self.straights_and_bends
        if self.steady is not None:
            out["steady"] = self.steady
        if self.partial:
            out["forecast_pull_force_N"] = self.expected["pull_force_N"]
            out["forecast_pull_force_interval_N"] = self.expected["pull_force_interval_N"]
            out["forecast_from_pulled_length_m"] = float(self.forecast["pulled_length_m"][0])
        return out


def _limit_reached(x: np.ndarray, values: np.ndarray, limit: float) -> float | None:
    """First head position [m] where ``values`` reaches ``limit`` (linear between grid points), or None."""
    over = np.flatnonzero(values >= limit)
    if over.size == 0:
        return None
    i = int(over[0])
    if i == 0:
        return float(x[0])
    x0, x1, v0, v1 = x[i - 1], x[i], values[i - 1], values[i]
    return float(x0 + (limit - v0) / (v1 - v0) * (x1 - x0)) if v1 != v0 else float(x1)


#: Straights and bends are told apart when their estimates' correlation is at most this in magnitude ...
SEPARABLE_CORRELATION = 0.95
#: ... and each 95 % interval's half-width is at most this fraction of its estimate.
SEPARABLE_HALF_WIDTH = 0.5


def _straights_and_bends(family: RopeFamily, x: np.ndarray, y: np.ndarray, mu_hat: float, series: np.ndarray,
                         in_use: np.ndarray, r_series_of, method: str, bootstrap: int, seed: int) -> dict:
    """μ on straights and μ in bends (bends and helices) fitted apart, with the check that the log can
    tell them apart.

    Least squares on the rope directly (scipy's ``least_squares``, from μ̂ for both); the interval from the
    same resampling as the one-coefficient fit, refitted in the model linearised at the optimum
    (θ* = θ̂ + (JᵀJ)⁻¹Jᵀr*: the rope is smooth in μ and the intervals are narrow against its curvature).
    """
    from scipy.optimize import least_squares

    sc, spec, direction = family.scenario, family.spec, family.direction

    def model(theta):
        rope = pull_in_rope(sc, spec, direction, friction=float(theta[0]), bend_friction=float(theta[1]))
        return np.asarray(rope.tension_at(np.clip(x, 0.0, rope.cable_length_m)))

    out = {"separable": False}
    res = least_squares(lambda th: model(th) - y, x0=[mu_hat, mu_hat], bounds=([0.0, 0.0], [family.mu_max] * 2),
                        diff_step=1e-4, x_scale=0.1)
    theta = res.x
    J = res.jac
    fitted = model(theta)
    JtJ = J.T @ J
    out.update(friction_straights=float(theta[0]), friction_bends=float(theta[1]),
               residual_std_N=float(np.std(y - fitted)))
    if np.linalg.cond(JtJ) > 1e12:
        out["reason"] = "the log does not reach a bend, or has no straight: one of the two does not act on it"
        return out
    R, _ = RESAMPLERS[method](r_series_of(fitted), int(bootstrap), np.random.default_rng(seed))
    tare_shift = np.median(R[:, ~in_use], axis=1) if (~in_use).any() else np.zeros(R.shape[0])
    Rstar = R[:, in_use] - tare_shift[:, None]
    star = theta[None, :] + np.linalg.solve(JtJ, J.T @ Rstar.T).T        # (B, 2)
    alpha = 1.0 - CONFIDENCE
    q = [alpha / 2, 1 - alpha / 2]
    iv = np.quantile(star, q, axis=0)                                     # (2, 2)
    corr = float(np.corrcoef(star.T)[0, 1])
    diff_iv = np.quantile(star[:, 1] - star[:, 0], q)
    half = 0.5 * (iv[1] - iv[0])
    separable = bool(abs(corr) <= SEPARABLE_CORRELATION and np.all(half <= SEPARABLE_HALF_WIDTH * np.maximum(theta, 1e-12)))
    out.update(friction_straights_interval=[float(v) for v in iv[:, 0]],
               friction_bends_interval=[float(v) for v in iv[:, 1]],
               correlation=corr, bends_minus_straights_interval=[float(v) for v in diff_iv],
               separable=separable,
               differ=bool(separable and (diff_iv[0] > 0 or diff_iv[1] < 0)))
    if not separable:
        out["reason"] = (f"the estimates are correlated {corr:+.2f}, or an interval is wider than "
                         f"±{SEPARABLE_HALF_WIDTH:.0%} of its value: the log cannot tell straights from bends")
    return out


def fit_friction(scenario: Scenario, log: PullLog, *, spec: PlanSpec | None = None, direction: str | None = None,
                 mu_max: float = 1.0, bootstrap: int = 999, seed: int = 0, route_points: int = 241,
                 family: RopeFamily | None = None, method: str = "block", separate: bool = False) -> FrictionFit:
    """Fit the friction coefficient to a log against the rope's pull-in history; forecast the rest.

    Parameters
    ----------
    scenario : Scenario
        Route, cable, back tension, gravity and ``[limits]``; its ``contact.friction`` is not used.
    log : PullLog
        From :func:`exucable.fit.log.read_pull_log`.
    spec : PlanSpec, optional
        Several cables per duct (default: from the scenario).
    direction : {"forward", "reverse"}, optional
        The pull's direction (default ``pull.direction``).
    mu_max : float
        Largest μ [-] looked at.
    bootstrap : int
        Block-bootstrap resamples.
    seed : int
        Seed of the resampling (the result is reproducible).
    route_points : int
        Head positions on the grid of the curve, band and forecast.
    family : RopeFamily, optional
        The rope solved on the μ grid for this scenario (built from the arguments above if not given).
    method : {"block", "ar"}
        How the residuals are resampled: circular blocks (Politis & White's length) or an AR sieve.
    separate : bool
        Also fit μ on straights and μ in bends apart (:attr:`FrictionFit.straights_and_bends`).

    Returns
    -------
    FrictionFit

    Raises
    ------
    LogError
        Too few usable rows on the route, or a best μ at ``mu_max``.
    """
    if int(bootstrap) < 99:
        raise LogError("--bootstrap", f"needs at least 99 resamples for a 95 % interval, got {bootstrap}")
    family = family or RopeFamily(scenario, spec, direction, mu_max)
    if separate and family.engine != "rope":
        raise LogError("--separate", "fits straights and bends apart on the rope only; use --engine rope with it")
    spec, direction, mu_max, nodes = family.spec, family.direction, family.mu_max, family.nodes
    L = family.route_length_m
    if method not in RESAMPLERS:
        raise LogError("--interval", f"must be one of {', '.join(RESAMPLERS)}, got {method!r}")
    on_route_all = (log.pulled_length_m >= 0.0) & (log.pulled_length_m <= L * (1.0 + 1e-9))
    off_route = log.used & ~on_route_all
    use = log.used & on_route_all
    x, y = log.pulled_length_m[use], log.pull_force_N[use]
    warnings = []
    if off_route.any():
        warnings.append(f"{int(off_route.sum())} rows with a pulled length outside the route [0, {L:.6g}] m "
                        "were left out (is the length column's unit right?)")
    if x.size < 10:
        raise LogError(log.report.get("source", "log"), f"only {x.size} usable rows on the route (moving, no "
                                                        "spike, pulled length within the route); a fit needs 10")
    xr = np.linspace(0.0, L, int(route_points))
    x_last = float(np.max(x))
    partial = bool(not log.ended and x_last < L - max(1e-6 * L, 0.5 * (xr[1] - xr[0])))
    H, Hr = family.histories(x), family.histories(xr)
    f = family.sidewall_pressure_factor
    tmax = family.max_tensions_N()
    pmax = [r.max_sidewall_pressure_N_per_m * f for r in family.ropes]
    prof = [np.interp(xr, r.s_cable_m, r.sidewall_pressure_N_per_m * f) for r in family.ropes]
    model = _Histories(nodes, H)
    route = _Histories(nodes, Hr)
    mu_hat = float(model.fit(y[None, :])[0])
    if mu_hat >= mu_max - 1e-12:
        raise LogError("--mu-max", f"the best friction is at the bound {mu_max}; raise --mu-max, or check the "
                                   "log's force unit and tare and the scenario's route and back tension")
    fitted = model.at(mu_hat)
    resid = y - fitted
    # the resampled series: the readings before the winch moved (auto tare: model 0) and the used rows, in
    # the log's order, so that the tare's own error and the drift between it and the pull are resampled too
    series = np.flatnonzero(log.tare_rows | use)
    in_use = use[series]
    r_series = log.pull_force_N[series].copy()
    r_series[in_use] -= fitted
    rng = np.random.default_rng(seed)
    R, b = RESAMPLERS[method](r_series - r_series.mean(), int(bootstrap), rng)
    tare_shift = np.median(R[:, ~in_use], axis=1) if (~in_use).any() else np.zeros(R.shape[0])
    Ystar = fitted[None, :] + R[:, in_use] - tare_shift[:, None]
    mu_star = model.fit(Ystar)
    alpha = 1.0 - CONFIDENCE
    lo, hi = (float(v) for v in np.quantile(mu_star, [alpha / 2, 1 - alpha / 2]))

    # one coefficient? fit each half alone, against the halves' difference under one μ
    split = float(np.median(x))
    first, second = np.flatnonzero(x <= split), np.flatnonzero(x > split)
    one = {"explains": True, "p_value": None, "split_pulled_length_m": split}
    if first.size >= 5 and second.size >= 5:
        mu_a = float(model.fit(y[None, :], first)[0])
        mu_b = float(model.fit(y[None, :], second)[0])
        a_star, b_star = model.fit(Ystar, first), model.fit(Ystar, second)
        diff_star = b_star - a_star
        diff = mu_b - mu_a
        p = (1 + int(np.sum(np.abs(diff_star - np.median(diff_star)) >= abs(diff)))) / (diff_star.size + 1)
        one.update(explains=bool(p >= ONE_COEFFICIENT_P), p_value=float(p),
                   first_half_friction=mu_a, second_half_friction=mu_b,
                   first_half_friction_interval=[float(v) for v in np.quantile(a_star - np.median(a_star) + mu_a,
                                                                                 [alpha / 2, 1 - alpha / 2])],
                   second_half_friction_interval=[float(v) for v in np.quantile(b_star - np.median(b_star) + mu_b,
                                                                                  [alpha / 2, 1 - alpha / 2])])
        if not one["explains"]:
            warnings.append(f"one friction coefficient does not explain the log: the first half (pulled length "
                            f"<= {split:.4g} m) fits {mu_a:.3f}, the second {mu_b:.3f} (p = {p:.3g}); the friction "
                            "changed along the route or in time, or the tare is wrong")
    else:
        warnings.append("too few rows in a half of the log to test whether one coefficient explains it")
    if lo <= 1e-12:
        warnings.append("the interval reaches μ = 0: the log cannot tell this friction from none")
    span = getattr(family, "mu_span", None)
    if span is not None and not (span[0] <= lo and hi <= span[1]):
        warnings.append(f"the interval [{lo:.4g}, {hi:.4g}] reaches beyond the friction values with a multibody "
                        f"history ({span[0]:.4g}-{span[1]:.4g}): there the model is extrapolated")
    separate_fit = None
    if separate:
        def r_series_of(model_values):
            r = log.pull_force_N[series].copy()
            r[in_use] -= model_values
            return r - r.mean()

        separate_fit = _straights_and_bends(family, x, y, mu_hat, series, in_use, r_series_of, method,
                                            bootstrap, seed)

    # the route's curve and band; the readings' band adds their scatter (resampled residuals' quantiles)
    curve_hat = route.at(mu_hat)
    curves = route.at(np.clip(mu_star, 0.0, mu_max))           # (B, P)
    band_lo, band_hi = np.quantile(curves, [alpha / 2, 1 - alpha / 2], axis=0)
    r_lo, r_hi = np.quantile(resid - resid.mean(), [alpha / 2, 1 - alpha / 2])
    curve = {"pulled_length_m": xr, "pull_force_N": curve_hat, "low_N": band_lo, "high_N": band_hi,
             "reading_low_N": band_lo + r_lo, "reading_high_N": band_hi + r_hi}
    forecast = None
    if partial:
        keep = xr >= x_last
        fx = np.concatenate([[x_last], xr[keep]])
        forecast = {"pulled_length_m": fx,
                    "pull_force_N": np.interp(fx, xr, curve_hat),
                    "low_N": np.interp(fx, xr, band_lo), "high_N": np.interp(fx, xr, band_hi)}

    def at_mu(values, mu):
        return CubicSpline(nodes, np.asarray(values), axis=0)(mu)

    def with_interval(values):
        v = np.asarray(at_mu(values, np.clip(mu_star, 0, mu_max)))
        return float(at_mu(values, mu_hat)), [float(q) for q in np.quantile(v, [alpha / 2, 1 - alpha / 2], axis=0)]

    pull, pull_iv = with_interval([h[-1] for h in Hr])
    tm, tm_iv = with_interval(tmax)
    pm, pm_iv = with_interval(pmax)
    expected = {"pull_force_N": pull, "pull_force_interval_N": pull_iv,
                "max_tension_N": tm, "max_tension_interval_N": tm_iv,
                "max_sidewall_pressure_N_per_m": pm, "max_sidewall_pressure_interval_N_per_m": pm_iv,
                "limits": []}
    lim = spec.limits
    tension_limits = [(n, v) for n, v in (("max_tension", lim.max_tension_N), ("grip_tension", lim.grip_limit_N),
                                          ("conductor_tension", lim.conductor_tension_N)) if v is not None]
    prof_hat = at_mu(np.asarray(prof), mu_hat)
    prof_hi = at_mu(np.asarray(prof), hi)
    for name, value in tension_limits:
        expected["limits"].append({
            "name": name, "limit": value, "expected": tm, "upper": tm_iv[1], "passed": bool(tm <= value),
            "passed_at_upper": bool(tm_iv[1] <= value),
            "reached_at_pulled_length_m": _limit_reached(xr, curve_hat, value),
            "reached_at_upper_at_pulled_length_m": _limit_reached(xr, band_hi, value)})
    if lim.max_sidewall_pressure_N_per_m is not None:
        v = lim.max_sidewall_pressure_N_per_m
        expected["limits"].append({
            "name": "max_sidewall_pressure", "limit": v, "expected": pm, "upper": pm_iv[1], "passed": bool(pm <= v),
            "passed_at_upper": bool(pm_iv[1] <= v),
            "reached_at_pulled_length_m": _limit_reached(xr, prof_hat, v),
            "reached_at_upper_at_pulled_length_m": _limit_reached(xr, prof_hi, v)})

    return FrictionFit(friction=mu_hat, friction_interval=(lo, hi), one_coefficient=one,
                       residual_std_N=float(np.std(resid)), resampling={"method": method, ("block_length_rows" if method == "block" else "ar_order"): b}, bootstrap_samples=int(bootstrap),
                       engine=family.engine, direction=direction, partial=partial, pulled_length_m=x, pull_force_N=y,
                       fitted_N=fitted, residual_N=resid, curve=curve, forecast=forecast, expected=expected,
                       log=dict(log.report, rows_outside_route=int(off_route.sum())), warnings=warnings,
                       straights_and_bends=separate_fit)


#: The engines ``exucable fit`` fits against.
FIT_ENGINES = ("auto", "rope", "steady")


def resolve_fit_engine(engine: str, count: int = 1) -> tuple[str, str]:
    """The engine ``"auto"`` stands for, and why: the rope. A fit is made on site and refitted at every
    change of a growing log (``--watch``), where the rope's histories cost milliseconds and the multibody
    ones seconds to minutes (three histories of one steady solve per head position); where the cable's
    stiffness or free spans matter, the two fits differ (``studies/fit_engines.py``) and
    ``--engine steady`` gives the friction the multibody model needs."""
    if engine not in FIT_ENGINES:
        raise LogError("--engine", f"must be one of {', '.join(FIT_ENGINES)}, got {engine!r}")
    if engine == "steady" and count != 1:
        raise ScenarioError("cable.count", f"--engine steady simulates one cable, got {count}; fit several cables "
                                           "per duct with --engine rope")
    if engine != "auto":
        return engine, "given (--engine)"
    return "rope", "auto: the rope, instant (--engine steady for the multibody model's history)"


#: The multibody histories of :func:`fit_friction_steady` at these multiples of the rope's fitted μ [-].
STEADY_NODE_FACTORS = (0.8, 1.0, 1.25)


def fit_friction_steady(scenario: Scenario, log: PullLog, *, spec: PlanSpec | None = None,
                        direction: str | None = None, mu_max: float = 1.0, rope_family: RopeFamily | None = None,
                        points: int | None = None, **kwargs) -> tuple[FrictionFit, SteadyFamily]:
    """Fit the friction coefficient against the multibody model's pull-in history.

    The rope fit of the same log (:func:`fit_friction`) places the multibody histories: at
    :data:`STEADY_NODE_FACTORS` times its μ (:class:`SteadyFamily`). Where the multibody fit's interval
    reaches beyond those, a history is added at the interval's end (once each side), so that the fit's
    interval lies between solved histories. ``kwargs``: as :func:`fit_friction` (not ``separate``).

    Returns
    -------
    (FrictionFit, SteadyFamily)
        The fit (``engine = "steady"``; ``rope_friction`` and ``rope_friction_interval`` in its
        :attr:`FrictionFit.steady`) and the family, to refit a growing log (``--watch``) without solving again.
    """
    rope_family = rope_family or RopeFamily(scenario, spec, direction, mu_max)
    rope = fit_friction(scenario, log, family=rope_family, **kwargs)
    mu_max = rope_family.mu_max
    nodes = sorted({min(mu_max, max(1e-3, f * rope.friction)) for f in STEADY_NODE_FACTORS})
    family = SteadyFamily(scenario, rope_family.spec, rope_family.direction, mu_max, mu_nodes=nodes, points=points)
    fit = fit_friction(scenario, log, family=family, **kwargs)
    lo, hi = fit.friction_interval
    extra = []
    if lo < family.mu_span[0]:
        extra.append(max(1e-3, lo - 0.05 * (hi - lo)))
    if hi > family.mu_span[1]:
        extra.append(min(mu_max, hi + 0.05 * (hi - lo)))
    if extra:
        # at most four histories (a cubic in μ): the new ends, and of the others those nearest the fit
        kept = sorted(nodes, key=lambda m: abs(m - fit.friction))[:4 - len(extra)]
        family = SteadyFamily(scenario, rope_family.spec, rope_family.direction, mu_max,
                              mu_nodes=sorted(set(kept) | set(extra)), points=points, solved=family.solved)
        fit = fit_friction(scenario, log, family=family, **kwargs)
    fit.steady = {"mu_nodes": [float(m) for m in family.steady_mu], "rope_friction": rope.friction,
                  "rope_friction_interval": list(rope.friction_interval),
                  "history_points": int(family.steady[0].pulled_length_m.size),
                  "history_cpu_time_s": family.cpu_time_s}
    return fit, family
