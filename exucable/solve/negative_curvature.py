"""Steps along directions of negative curvature: a bundle's cable rolled off a crest.

Where several cables share a duct, a cable may rest on an unstable balance: on the crest of the two
below it, not in their groove. There the stiffness K = −∂f/∂q of the steady residual f
(:meth:`exucable.model.bundle.BundleModel.steady_force`) has negative eigenvalues, and an implicit
pseudo-time step (c M + K) Δq = f either blows up along that mode (c below the eigenvalue's size) or
creeps (c above it). Trust-region methods for indefinite problems (Moré & Sorensen 1979; Conn, Gould &
Toint 2000, *Trust-Region Methods*, Sect. 6.6; Nocedal & Wright 2006, Sect. 4.3) take a step along the
direction of most negative curvature instead. Here the curvature is measured in the pseudo-time
spring's mass metric M (lumped nodal masses, times L_e² for slopes:
:class:`exucable.solve.steady.PseudoTimeSpring`), so that its eigenvalues are those the spring rate c
is compared with:

    K_s u = λ M u,   K_s = ½ (K + Kᵀ),  the eye's held coordinates removed,                   (NC 1)

the few lowest eigenpairs (λ < 0: the crest's modes) by shift-invert Lanczos
(``scipy.sparse.linalg.eigsh``), of the stiffness with the friction off: the steady sliding friction
is a follower force along each cable's tangent, its stiffness unsymmetric, and its symmetric part
alone is indefinite without any crest (measured on the 100 m three-cable route: eigenvalues down to
−7500 s⁻², and a step along them in the direction where the friction does positive work ran 30 mm
into the walls, |f| 25 N → 4.7e5 N). Without friction the forces are conservative (elastic,
contact, weight, constant end loads), the negative modes are the crest's (a cable on one convex
support: a contact force N over the radii's sum r₁ + r₂ gives −N/(r₁ + r₂), for a cable's weight
13.7 N/m on 30 mm about −330 s⁻² per unit mass), and the full unsymmetric K with friction has the
same negative eigenvalues there (measured: −204, −39, −35 s⁻² both). Along each mode u with λ < 0,
scaled to a largest nodal move of 1 m and signed both ways, the state moves to the line minimum of
the frictionless potential,

    q + α u,  α: the first length where f₀(q + α u)·u ≤ 0,  W = ∫₀^α f₀(q + t u)·u dt > 0,     (NC 2)

α doubling from ``first_move_m`` up to ``max_move_m`` (the sign of the larger work taken; no step
where neither does work). A rolling path is curved, a step straight: the modes are taken again at
the new state, up to ``rounds`` times. A line search on the true residual's norm instead took no
step on the 100 m route (moving off a crest first raises |f|).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import eigsh

from ..errors import SolverError
from .relax import check_settings

__all__ = ["CurvatureSettings", "CurvatureStep", "lowest_modes", "stiffness_matrix", "roll_off", "curvature_phase"]


@dataclass(frozen=True)
class CurvatureSettings:
    """How :func:`roll_off` finds and takes negative-curvature steps.

    Attributes
    ----------
    modes : int
        Lowest eigenpairs of Eq. (NC 1) computed per call [-].
    shift_per_s2 : float
        Magnitude of the (negative) shift σ = −shift of the shift-invert Lanczos [1/s²]: the modes
        nearest σ are found, so it should exceed the most negative eigenvalue's size.
    rounds : int
        Times the modes are taken again at the state the steps reached [-] (:func:`roll_off`).
    first_move_m : float
        Largest nodal move [m] of the line search's first trial length (the others twice the one before).
    max_move_m : float
        Largest nodal move [m] a step may make.
    """

    modes: int = 6
    shift_per_s2: float = 5000.0
    rounds: int = 8
    first_move_m: float = 1e-4
    max_move_m: float = 0.03

    def __post_init__(self):
        check_settings(self)
        for name in ("modes", "rounds"):
            if getattr(self, name) < 1:
                raise SolverError(f"CurvatureSettings.{name} = {getattr(self, name)!r}: must be at least 1")


@dataclass
class CurvatureStep:
    """One negative-curvature step (:func:`roll_off`).

    Attributes
    ----------
    eigenvalue_per_s2 : float
        λ of Eq. (NC 1) [1/s²] of the direction taken.
    move_m : float
        Largest nodal move of the step [m].
    residual_before_N, residual_after_N : float
        |f| on the free coordinates before and after, friction on [N].
    work_J : float
        The frictionless forces' work along the step [J] (Eq. NC 2).
    where_m : float
        Arc length along its cable [m] (from the trailing end) of the node that moved most.
    cable : int
        Index of that cable [-].
    """

    eigenvalue_per_s2: float
    move_m: float
    residual_before_N: float
    residual_after_N: float
    work_J: float
    where_m: float
    cable: int


def stiffness_matrix(model, q) -> sp.csr_matrix:
    """K = −∂f/∂q [N/m, per the coordinates] of the bundle's steady residual at ``q``, assembled
    from :meth:`~exucable.model.bundle.BundleModel.stiffness_blocks3` (n × n, the cables' coordinates)."""
    rows, cols, blocks = model.stiffness_blocks3(q)
    i3 = np.arange(3)
    r = (3 * rows[:, None, None] + i3[None, :, None] + 0 * i3[None, None, :]).reshape(-1)
    c = (3 * cols[:, None, None] + i3[None, None, :] + 0 * i3[None, :, None]).reshape(-1)
    n = model.ode2_index.size
    return sp.coo_matrix((np.asarray(blocks).reshape(-1), (r, c)), shape=(n, n)).tocsr()


def lowest_modes(model, q, mass, free, settings: CurvatureSettings = CurvatureSettings()):
    """The ``settings.modes`` eigenpairs of Eq. (NC 1) nearest σ = −``shift_per_s2``.

    Parameters
    ----------
    model : exucable.model.bundle.BundleModel
    q : ndarray, shape (n,)
        The cables' displacement coordinates [m, -].
    mass : ndarray, shape (n,)
        The metric's diagonal M [kg, kg·m²] per coordinate.
    free : ndarray of bool, shape (n,)
        The coordinates that move (the eye's held ones False).

    Returns
    -------
    eigenvalues : ndarray, shape (k,)
        λ [1/s²], ascending.
    vectors : ndarray, shape (n, k)
        The modes u (M-normalised on the free coordinates, zero on the held ones).
    """
    K = stiffness_matrix(model, q)
    Ks = (0.5 * (K + K.T)).tocsr()[free][:, free]
    w = 1.0 / np.sqrt(mass[free])
    A = sp.diags(w) @ Ks @ sp.diags(w)
    k = min(settings.modes, A.shape[0] - 2)
    lam, y = eigsh(A.tocsc(), k=k, sigma=-settings.shift_per_s2, which="LM")
    order = np.argsort(lam)
    vectors = np.zeros((q.size, k))
    vectors[free] = w[:, None] * y[:, order]
    return lam[order], vectors


def _line_minimum(force, q, d, settings: CurvatureSettings) -> tuple[float, float]:
    """Eq. (NC 2) along d from q: the length α [-] (d scaled to a largest nodal move of 1 m) at which
    the work of ``force`` along d stops growing, and that work [J]. α doubles from ``first_move_m``
    while f(q + α d)·d > 0, up to ``max_move_m``; the work is the trapezoid rule on those points."""
    a_prev, slope_prev, work, a = 0.0, float(force(q) @ d), 0.0, settings.first_move_m
    while a <= settings.max_move_m * (1.0 + 1e-12):
        slope = float(force(q + a * d) @ d)
        if not slope > 0.0:
            break
        work += 0.5 * (slope + slope_prev) * (a - a_prev)
        a_prev, slope_prev = a, slope
        a *= 2.0
    return a_prev, work


def _friction(model, scale: float) -> None:
    model.kernel.set_friction_scale(scale)
    # the couplings keep their last evaluation by coordinates: it was of the other friction scale
    model.coupling.forget_evaluation()


def roll_off(model, q, mass, free, friction_scale: float, settings: CurvatureSettings = CurvatureSettings()):
    """Negative-curvature steps from ``q``, friction off (module notes): for each mode of Eq. (NC 1)
    with λ < 0, most negative first, the line minimum of Eq. (NC 2) along it over both signs, taken in
    turn; the modes taken again at the new state, up to ``settings.rounds`` times or until none is
    negative.

    Parameters
    ----------
    model, q, mass, free
        As :func:`lowest_modes`.
    friction_scale : float
        The friction's scale [-] the solve is at, restored at the end, and at which the residual |f|
        of each step's report is evaluated.

    Returns
    -------
    q : ndarray
        The state after the steps.
    eigenvalues : list of ndarray
        The eigenvalues found [1/s²] at the start of each round.
    steps : list of CurvatureStep
    cpu_s : float
        CPU time [s].
    """
    t0 = time.process_time()
    free = np.asarray(free, dtype=bool)

    def force(x):
        f = np.asarray(model.steady_force(x), dtype=float)
        f[~free] = 0.0
        return f

    def residual(x) -> float:
        _friction(model, friction_scale)
        try:
            return float(np.linalg.norm(force(x)))
        finally:
            _friction(model, 0.0)

    q = np.array(q, dtype=float)
    steps: list = []
    found = []
    n1 = model.ode2_index.size // model.n_cables
    Le = np.asarray(model.layout.element_length_m, dtype=float)
    x_node = np.concatenate([[0.0], np.cumsum(Le)])
    _friction(model, 0.0)
    try:
        r = residual(q)
        for _ in range(settings.rounds):
            lam, U = lowest_modes(model, q, mass, free, settings)
            found.append(lam)
            if not np.any(lam < 0.0):
                break
            for j in np.flatnonzero(lam < 0.0):
                d = U[:, j] / np.max(np.abs(U[:, j].reshape(-1, 6)[:, :3]))
                best = max(((sign,) + _line_minimum(force, q, sign * d, settings) for sign in (1.0, -1.0)),
                           key=lambda t: t[2])
                sign, alpha, work = best
                if alpha == 0.0 or work <= 0.0:
                    continue
                step = sign * alpha * d
                moves = np.linalg.norm(step.reshape(-1, 6)[:, :3], axis=1)
                k = int(np.argmax(moves))
                cable, node = divmod(6 * k, n1)
                q = q + step
                r_new = residual(q)
                steps.append(CurvatureStep(float(lam[j]), float(moves[k]), r, r_new, work, float(x_node[node // 6]),
                                           cable))
                r = r_new
    finally:
        _friction(model, friction_scale)
    return q, found, steps, time.process_time() - t0


def curvature_phase(solver, rounds: int, settings: CurvatureSettings = CurvatureSettings()) -> tuple[bool, str]:
    """A steady bundle solve's phase (:class:`exucable.solve.steady.SteadySolver`, where the dynamic
    relaxation and the one-iteration continuation after it stalled): up to ``rounds`` times, the
    negative-curvature steps of :func:`roll_off` from the best state reached, then the one-iteration
    continuation from there: converged?, and what each round found."""
    model = solver.model
    free = np.ones(model.ode2_index.size, dtype=bool)
    free[model.held_coordinates()] = False
    mass = np.repeat(solver.spring.block_mass.reshape(-1), 3)
    notes = []
    for k in range(rounds):
        if solver.out_of_time() or solver.best[1] is None:
            break
        ode2 = np.array(solver.best[1][0])
        q, found, steps, cpu = roll_off(model, ode2[model.ode2_index], mass, free, 1.0, settings)
        negative = ", ".join(f"{x:.3g}" for x in found[0][found[0] < 0.0]) or "none"
        left = int(np.sum(found[-1] < 0.0))
        notes.append(f"round {k + 1}: eigenvalues < 0 [1/s²] {negative}; {len(steps)} steps taken in {len(found)} "
                     f"passes ({left} negative left, {cpu:.2g} s CPU) "
                     + (f"(|f| {steps[0].residual_before_N:.3g} → {steps[-1].residual_after_N:.3g} N)" if steps else ""))
        if not steps:
            break
        ode2[model.ode2_index] = q
        solver.store.saved = (ode2, solver.best[1][1], None)
        # the rolled state's residual is above the best (moving off a crest raises it): a bundle's
        # steps are held to twice the best, so the continuation from it starts a best of its own
        before = solver.best
        solver.best = (np.inf, None)
        ok, why = solver.relax_one_iteration(1.0)
        notes[-1] += f"; then {'converged' if ok else why}"
        if ok:
            return True, "negative-curvature steps: " + "; ".join(notes)
        if solver.best[0] >= before[0]:
            solver.best = before
            break                  # no better than before the steps: the next round would repeat them
    return False, "negative-curvature steps: " + ("; ".join(notes) or "not run")
