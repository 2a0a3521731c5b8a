"""Steady sliding in one static solve (``[solver] mode = "steady"``).

At a constant low pull speed the cable reaches a state whose shape and tension no longer change
in space: its material flows along a fixed curve at the pull speed V. Inertia is then negligible
(ρA·V² is millinewtons), every check point slides along the cable's own tangent, and the pulling
force is the reaction of a static equilibrium. The model is the dynamic run's (same ANCF cable,
contact law, smooth wall, broad phase, gravity, back tension), built by
:func:`exucable.model.build.build_model` with

- the contact kernel :class:`exucable.contact.steady.SteadySlidingKernel` (friction against the
  tangent, v = V ∂r/∂x, exact Jacobian);
- the rig holding the leading end where the start put it (its reaction is the pulling force), or
  for a force-controlled pull the trailing end (its reaction is the trailing tension);

and solved from the pre-tensioned start (the rope solution) with Exudyn's static solver.

Why pseudo-time steps: the start is near equilibrium, but a full Newton step from it overshoots
into the wall (Hertz contact is stiff, 1e5-1e6 N/m per node, the free spans are soft), and the
iterates then bounce between contact states. Where the cable continues a bend's inner wall along
a straight it grazes that wall with δ → 0 over a long stretch, the Hertz stiffness ∝ δ^(1/2)
vanishes there, and plain Newton 2-cycles (a check point in contact is pushed out, out of contact
it falls back in): the "stall near 1e-5" of the first probe. So the solve is pseudo-transient
continuation (Kelley & Keyes 1998): each static solve adds a spring c·m_k·(q_k - q̄_k) to every
coordinate, anchored at the previous solve's state q̄ (m_k the lumped nodal mass, times L_e² for
slopes), which makes every Newton problem well posed; c starts at an element's axial stiffness
per mass and falls by 4 after each converged solve (rises by 4 after a failed one). The spring's force at convergence is exactly the
residual of the unregularised equilibrium, so the solve stops once its norm is below
``STATIC_TOLERANCE`` times the rope solution's largest tension. Far from it a step's Newton
problem is solved only to ``INEXACT_NEWTON_TOLERANCE`` (each step need only make progress: inexact
continuation, 59 → 36 Newton iterations on Example 4); within ``EXACT_WITHIN`` tolerances of the
stop, and always for the step that stops, to ``NEWTON_TOLERANCE``, so that the spring's force is the
whole residual there.

First, though, the same continuation is tried with one Newton iteration per pseudo-time step,
steered by the true residual (:func:`solve_steady`'s ``relax_one_iteration``): after each step the
unregularised residual is the static solver's residual at the new state minus the spring's force
there, so no step need be solved exactly to know how far the state is from equilibrium. A step
whose residual grows more than ``REJECT_GROWTH``-fold is undone and retried with c × 4; an accepted
step divides c by ``RATE_FALL`` (by ``RATE_FALL_AFTER_REJECT`` right after a rejection), so the
steps become plain Newton steps near the solution. The solve stops once that residual is below the
tolerance: Example 4 in 17 Newton iterations instead of 36, its pulling force 1e-9 (not 7e-7) from
the one at 1/1000 of the stop tolerance (reference/README.md, "Speed"). Where it does not converge within its budget, the
exact-step continuation above runs from the start.
Where that does not converge either, the loads themselves are ramped (friction, gravity and end forces
scaled by λ) with the increment halved on failure.
"""

from __future__ import annotations

import time

import numpy as np
import exudyn as exu

from .dynamic import History, Progress, SolveOutcome, quiet_sparse
from ..post.tension import TensionStations, profile_stations_m

__all__ = ["solve_steady", "static_settings", "STATIC_TOLERANCE"]

#: Residual of the steady equilibrium at which the solve stops, relative to the largest tension of
#: the rope solution [-]: the spring force c·m·(q - q̄) left at the last pseudo-time step.
STATIC_TOLERANCE = 1e-6

#: Newton's relative tolerance inside one pseudo-time step (its problem is well posed).
NEWTON_TOLERANCE = 1e-8

#: Newton's relative tolerance inside a pseudo-time step still far from the steady state: each
#: step only has to make progress toward it (inexact pseudo-transient continuation, Kelley & Keyes
#: 1998 Sect. 4); the step that stops the solve is converged to NEWTON_TOLERANCE.
INEXACT_NEWTON_TOLERANCE = 0.1

#: Residual, in stop tolerances, below which the pseudo-time steps are solved exactly [-].
EXACT_WITHIN = 1000.0

#: Newton's absolute tolerance in an exact pseudo-time step, as a share of the stop tolerance [-];
#: the Newton residual left over counts toward the stop test (spring force + leftover ≤ tolerance).
#: Why not tighter: the residual has a round-off floor that grows with the mesh. Measured on Gera's
#: route: 2e-5 N at 2032 elements, while the former absolute tolerance 1e-3 × the stop
#: tolerance was 6e-7 N and the relative one 1e-8 × the initial residual 6.5e-6 N; every exact step
#: then failed (12 iterations stuck at 2e-5 N), the spring rate rose a million-fold without helping,
#: and the solve was reported as "continuation stalled at load scale 0". At 0.1 the floor is 30×
#: below the Newton tolerance there, and the stop test stays honest (residual ≤ 1.1 × tolerance).
EXACT_NEWTON_SHARE = 0.1

#: Weight of the pseudo-time spring along the cable's axis relative to across it (see
#: :class:`PseudoTimeSpring`).
AXIAL_SHARE = 1.0

#: Factor on the axial share after each converged pseudo-time step: the axial mode is linear (EA)
#: and, on a long cable, so soft (1 km: ~1 s⁻² per unit mass) that a spring falling like the
#: lateral one would hold it for hundreds of steps.
AXIAL_RELEASE = 0.25

#: Pseudo-time steps (failed attempts included) without the residual halving before the solve at
#: one load scale is declared failed. A budget on progress, not on the count: from a start far from
#: the steady state (1 km from the centreline rope's start, the cable 6 % too tense and pressed where
#: it should hang free) the residual falls steadily but slowly, 900 N to 8 N in the first 80 steps
#: (a count budget of 80 declared it failed), and converges after 51 converged steps.
MAX_PSEUDO_STEPS = 80

#: Pseudo-time steps at one load scale in all before the solve there is declared failed.
MAX_PSEUDO_STEPS_TOTAL = 400

#: Growth of the true residual [-] over the last accepted step's above which a one-iteration
#: pseudo-time step is undone and retried with a 4× stiffer spring (a trust-region test).
REJECT_GROWTH = 2.0

#: Factor by which the spring rate falls after an accepted one-iteration step, and right after a
#: rejected one [-]. Measured on the paper's examples and industry scenarios (Newton iterations,
#: one-iteration steps vs the exact-step continuation): Ex4 17 vs 36, Gera 60 vs 102, fast Ex2 29 vs
#: 55, Ex3 27 vs 19, route100 43 vs 25; a fall by 4 after a rejection too gave 34 on Ex3 and 60 on
#: fast Ex2, a fall by 4 throughout fell back to the exact steps on Ex4 (60).
RATE_FALL = 8.0
RATE_FALL_AFTER_REJECT = 2.0

#: Pseudo-time steps (accepted and rejected) the one-iteration continuation may take before the
#: exact-step continuation takes over [-].
MAX_ONE_ITERATION_STEPS = 80

#: Pseudo-time steps (accepted and rejected) without the true residual halving after which the
#: one-iteration continuation gives up for the exact-step one [-]. Gera's route at 4× the mesh
#: wandered at 10-200 N for 48 accepted steps (80 steps, then the exact steps from the start:
#: 210 Newton iterations against their 130 alone); 10 sent Ex. 3 and the coarse Ex. 2-4 to the
#: exact steps too, 20 none of the paper's examples.
MAX_ONE_ITERATION_STALL = 20

#: Smallest continuation increment of the load scale before the solve is declared failed.
MIN_CONTINUATION_STEP = 1.0 / 16.0


def initial_spring_rate(model) -> float:
    """c0 [1/s²]: an element's axial stiffness EA/L_e per its mass ρA·L_e, E/(ρ L_e²) — of the
    order of the contact stiffness per node, so the first steps are short."""
    L_e = float(np.min(model.layout.element_length_m))
    return model.axial_stiffness_N / (model.properties.mass_per_length_kg_per_m * L_e * L_e)


def static_settings(tolerance: float = NEWTON_TOLERANCE, max_iterations: int = 12,
                    absolute_tolerance_N: float = 1e-10) -> exu.SimulationSettings:
    """Exudyn's static solver settings of one pseudo-time step: one load step, plain Newton.

    ``max_iterations = 1`` with ``tolerance = 1`` makes one Newton iteration (the solver's first
    residual holds the end reactions unbalanced, its multipliers start at zero, so any sane
    iterate is below it); a wilder iterate is reported as not converged."""
    s = exu.SimulationSettings()
    ss = s.staticSolver
    ss.numberOfLoadSteps = 1
    ss.loadStepDuration = 1.0
    ss.useLoadFactor = False
    ss.stabilizerODE2term = 0.0
    ss.adaptiveStep = False
    ss.verboseMode = 0
    ss.newton.useModifiedNewton = False
    ss.newton.relativeTolerance = tolerance
    ss.newton.absoluteTolerance = absolute_tolerance_N
    ss.newton.maxIterations = int(max_iterations)
    return quiet_sparse(s)


class PseudoTimeSpring:
    """The pseudo-transient term c·m_k·P_k (q_k - q̄_k) on the cable coordinates, as an
    ``ObjectGenericODE2`` with a force and a sparse Jacobian user function.

    m_k: lumped nodal mass [kg] for positions, times L_e² [kg·m²] for slopes.
    P_k = I - (1 - AXIAL_SHARE) t tᵀ weights the spring along the cable's tangent t at node k
    (at the anchor). Measured: releasing the axial direction entirely (share 0) lets a long
    cable's first Newton step slide it by the start's strain misfit (decimetres on 300 m) and
    the step fails; the isotropic spring (share 1) solves 300 m in 21 pseudo-time steps.
    """

    def __init__(self, model):
        from exudyn.itemInterface import ObjectGenericODE2

        Le = np.asarray(model.layout.element_length_m, dtype=float)
        rho_a = model.properties.mass_per_length_kg_per_m
        m_node = rho_a * (np.concatenate([Le, [0.0]]) + np.concatenate([[0.0], Le])) / 2
        L_node = np.maximum(np.concatenate([Le, [0.0]]), np.concatenate([[0.0], Le]))
        # several cables meshed alike (exucable.model.bundle): their nodes one cable after another
        cables = getattr(model.layout, "n_cables", 1)
        m_node, L_node = np.tile(m_node, cables), np.tile(L_node, cables)
        self._q_ref = np.asarray(model.layout.coordinates, dtype=float).reshape(-1)
        self.n_nodes = len(m_node)
        self.n = 6 * self.n_nodes
        # per 3-block (positions, slopes of each node): its mass
        self.block_mass = np.empty((self.n_nodes, 2))
        self.block_mass[:, 0] = m_node
        self.block_mass[:, 1] = m_node * L_node**2
        self.rate = 0.0                       # c [1/s²]
        self.axial_share = AXIAL_SHARE        # weight along the tangent [-]
        self.anchor = np.zeros(self.n)        # q̄ (displacement coordinates)
        self._proj = np.broadcast_to(np.eye(3), (self.n_nodes, 3, 3)).copy()
        base = 6 * np.arange(self.n_nodes)[:, None, None, None] + 3 * np.arange(2)[None, :, None, None]
        i3 = np.arange(3)
        self._rows = (base + i3[None, None, :, None] + 0 * i3[None, None, None, :]).reshape(-1).astype(float)
        self._cols = (base + i3[None, None, None, :] + 0 * i3[None, None, :, None]).reshape(-1).astype(float)
        empty = [exu.MatrixContainer() for _ in range(3)]
        for m in empty:
            m.Initialize(self.n, self.n, False)
        mbs = model.mbs
        self.object = mbs.AddObject(ObjectGenericODE2(
            nodeNumbers=_spring_nodes(model), massMatrix=empty[0], stiffnessMatrix=empty[1],
            dampingMatrix=empty[2], forceUserFunction=self._force, jacobianUserFunction=self._jacobian,
            visualization={"show": False, "color": [-1.0, -1.0, -1.0, -1.0], "triangleMesh": [],
                           "showNodes": False, "graphicsDataUserFunction": 0}))
        mbs.Assemble()

    def anchor_at(self, q_disp) -> None:
        """Anchor the spring at displacement coordinates ``q_disp`` (tangents taken there)."""
        self.anchor = np.asarray(q_disp, dtype=float).copy()
        slope = (self._q_ref + self.anchor).reshape(-1, 6)[:, 3:]
        t = slope / np.linalg.norm(slope, axis=1, keepdims=True)
        self._proj = np.eye(3)[None] - (1.0 - self.axial_share) * t[:, :, None] * t[:, None, :]

    def force(self, q) -> np.ndarray:
        """Generalized force -c·m·P (q - q̄) [N, N·m]."""
        d = (np.asarray(q, dtype=float) - self.anchor).reshape(self.n_nodes, 2, 3)
        f = np.einsum("kij,kbj->kbi", self._proj, d) * self.block_mass[:, :, None]
        return -self.rate * f.reshape(-1)

    def _force(self, mbs, t, item, q, q_t):
        return self.force(q)

    def _jacobian(self, mbs, t, item, q, q_t, f_q, f_v):
        m = exu.MatrixContainer()
        vals = (f_q * self.rate * self.block_mass[:, :, None, None] * self._proj[:, None, :, :]).reshape(-1)
        nz = vals != 0.0  # Exudyn's sparse triplets must not contain zeros
        if not nz.any():
            m.Initialize(self.n, self.n, False)
            return m
        m.SetWithSparseMatrix(np.column_stack([self._rows[nz], self._cols[nz], vals[nz]]), self.n, self.n, False)
        return m


def _spring_nodes(model) -> list:
    """The nodes the pseudo-time spring acts on: the cable's, or every cable's of a bundle."""
    cables = getattr(model, "cables", None)
    if cables is not None:
        return [n for c in cables for n in c.nodes]
    return list(model.cable.nodes)


class _StateStore:
    """Copies of the system's coordinates (displacements and multipliers) to restart from, with
    the contact kernel's evaluation there.

    A rejected or failed pseudo-time step restarts from the saved state, whose contact forces and
    Jacobian the kernel computed when the step that reached it ended; handing that evaluation back
    to the coupling spares the restart a kernel pass (the coupling reuses it only at the same
    coordinates bit for bit). Measured (one-iteration steps): Ex. 3 37 -> 27 kernel
    passes, Fig. 12 4 coils 47 -> 33, the 1 km benchmark route 94 -> 66; the iterates are unchanged.
    """

    def __init__(self, mbs, coupling=None):
        self.mbs = mbs
        self.coupling = coupling
        self.saved = self.read()

    def read(self):
        sd = self.mbs.systemData
        kept = self.coupling.last_evaluation() if self.coupling is not None else None
        return (np.array(sd.GetODE2Coordinates()), np.array(sd.GetAECoordinates()), kept)

    def save(self):
        self.saved = self.read()

    def restore_as_initial(self):
        """Make the saved state the next solve's start."""
        sd = self.mbs.systemData
        q, lam, kept = self.saved
        for cfg in (exu.ConfigurationType.Initial, exu.ConfigurationType.Current):
            sd.SetODE2Coordinates(list(q), configuration=cfg)
            sd.SetAECoordinates(list(lam), configuration=cfg)
        if self.coupling is not None:
            self.coupling.offer_evaluation(kept)


def force_stations(model) -> tuple[TensionStations, TensionStations]:
    """:func:`steady_forces`' stations: two per element along the cable, and the trailing end."""
    Le = model.layout.element_length_m
    return TensionStations(Le, profile_stations_m(Le, 2)), TensionStations(Le, [0.0])


def steady_forces(model, stations: tuple[TensionStations, TensionStations] | None = None
                  ) -> tuple[float, float, float]:
    """Pulling force, trailing tension and maximum tension [N] of the current static state.

    The static solver's Lagrange multipliers carry the opposite sign of the dynamic solver's
    (checked: the leading end's reaction then equals its tension EA·ε, tests/test_steady.py).
    ``stations``: :func:`force_stations` of the model, when asked at many states. A model of
    several cables (:class:`exucable.model.bundle.BundleModel`) reports its own.
    """
    own = getattr(model, "steady_forces", None)
    if own is not None:
        return own(stations)
    q, _ = model.coordinates()
    EA = model.axial_stiffness_N
    along, trailing = force_stations(model) if stations is None else stations
    N = along.tension(q, EA)
    if model.lead_drive is not None:
        pull = -model.lead_drive.force_N(model.mbs)
    else:
        pull = model.applied_pull_force_N * model.load_scale.end_force
    if model.trail_drive is not None:
        trail = model.trail_drive.force_N(model.mbs)
    else:
        trail = float(trailing.tension(q, EA)[0])
    return float(pull), float(trail), float(np.max(N))


def _outside_points(model) -> int:
    """Check points with no conduit segment within R of them (outside the conduit, or beyond
    its open ends where the rig holds the cable)."""
    q, _ = model.coordinates()
    return int(np.count_nonzero(model.kernel.point_segments(q.reshape(-1)) < 0))


#: What to change when the steady solve stalls (scenario keys), appended to its message.
STALL_FIX = ('fix: a coarser mesh (larger `cable.element_length`, or fewer `contact.check_points_per_element`) '
             'or the dynamic run (`solver.mode = "dynamic"` with a `solver.end_time`)')


class _FailedSteps:
    """The failed pseudo-time steps at one load scale, for the message of a solve that stalls there."""

    def __init__(self):
        self.exact = 0
        self.inexact = 0
        self.floor_N = np.inf      # smallest Newton residual a failed exact step ended at [N]

    def record(self, exact: bool, leftover_N: float) -> None:
        if exact:
            self.exact += 1
            self.floor_N = min(self.floor_N, leftover_N)
        else:
            self.inexact += 1

    def why(self, message: str, lam: float, best_N: float, tolerance_N: float, settings) -> str:
        """Where (load scale, residual reached) and why (Newton's last residual against its tolerance)."""
        newton_tol = settings.staticSolver.newton.absoluteTolerance
        text = (f"at load scale {lam:.3g} the residual reached {best_N:.3g} N (stop at {tolerance_N:.3g} N), then "
                f"{self.exact + self.inexact} pseudo-time steps failed with the spring stiffened a million-fold")
        if self.exact and np.isfinite(self.floor_N):
            text += (f"; the exact steps' Newton residual stayed at ≥ {self.floor_N:.3g} N against its tolerance "
                     f"{newton_tol:.3g} N")
            if self.floor_N <= tolerance_N:
                text += " (a round-off floor: the mesh is too fine for the stop tolerance)"
        return f"{text}: {message}"


def _set_scale(model, lam: float) -> None:
    model.load_scale.apply(model.mbs, gravity=lam, end_force=lam)
    model.kernel.set_friction_scale(lam)
    if model.coupling is not None:
        # a pass at the same coordinates was of the former friction scale
        model.coupling.forget_evaluation()


def solve_steady(model, progress: Progress | None = None, tolerance: float = STATIC_TOLERANCE) -> SolveOutcome:
    """Solve ``model`` (built with ``solver.mode = "steady"``) for its steady sliding state.

    ``tolerance`` [-] is the equilibrium residual at which it stops, relative to the rope
    solution's largest tension (default :data:`STATIC_TOLERANCE`; a tighter one shows how
    converged the pulling force is, ``benchmarks/steady_scale.py --tolerance-check``).

    Pseudo-transient continuation from the pre-tensioned start at the full loads, first with one
    Newton iteration per pseudo-time step steered by the true residual, then (if that does not
    converge) with the inexact/exact steps; if that fails too,
    continuation in the load scale λ (friction, gravity, end forces) from the start, each stage
    solved the same way, the increment doubled after a success and halved after a failure. The
    history has one row per converged pseudo-time step; its ``time_s`` column holds the step's
    number [-] (not a time: a static solve has none).

    Never raises for a diverging solve: the outcome has ``status == "failed"`` and the message.
    """
    mbs = model.mbs
    history = History()
    spring = PseudoTimeSpring(model)
    store = _StateStore(mbs, model.coupling)
    start = store.saved
    counters = {"newton": 0, "jacobian": 0, "steps": 0}
    scale_N = max(float(np.max(np.abs(model.rope.tension_N))) if model.rope is not None else 0.0,
                  model.back_tension_N, 1.0)
    tolerance_N = float(tolerance) * scale_N
    settings = static_settings(tolerance=NEWTON_TOLERANCE, absolute_tolerance_N=EXACT_NEWTON_SHARE * tolerance_N)
    inexact = static_settings(tolerance=INEXACT_NEWTON_TOLERANCE, absolute_tolerance_N=1e-3 * tolerance_N)
    c0 = initial_spring_rate(model)
    t_wall = time.perf_counter()
    total = [0]

    stations = force_stations(model)
    one_iteration = static_settings(tolerance=1.0, max_iterations=1, absolute_tolerance_N=1e-3 * tolerance_N)
    last_solver = [None]

    def one_solve(exact: bool | exu.SimulationSettings) -> tuple[bool, str, float]:
        """One static solve with the exact, inexact or given settings: converged?, message, and
        Newton's last residual norm [N]."""
        solver = exu.MainSolverStatic()
        last_solver[0] = solver
        chosen = exact if isinstance(exact, exu.SimulationSettings) else (settings if exact else inexact)
        try:
            ok = solver.SolveSystem(mbs, chosen)
            message = "" if ok else (solver.GetErrorString() or "Newton did not converge")
        except Exception as exc:  # Exudyn raises plain RuntimeError/ValueError on divergence
            ok, message = False, f"{type(exc).__name__}: {exc}".strip()
        counters["newton"] += int(solver.it.newtonStepsCount)
        counters["jacobian"] += int(solver.it.newtonJacobiCount)
        return ok, message, float(solver.conv.residual)

    def pseudo_step(c: float, exact: bool | exu.SimulationSettings) -> tuple[bool, str, float]:
        """One pseudo-time step at spring rate ``c`` [1/s²] from the stored state (see one_solve)."""
        store.restore_as_initial()
        spring.anchor_at(_cable_part(model, store.saved[0]))
        spring.rate = c
        counters["steps"] += 1
        return one_solve(exact)

    def record(lam: float, residual: float) -> None:
        """One history row (and the progress bar) for an accepted pseudo-time step."""
        total[0] += 1
        pull, trail, tmax = steady_forces(model, stations)
        history.time_s.append(float(total[0]))
        history.pull_force_N.append(pull)
        history.trailing_tension_N.append(trail)
        history.max_tension_N.append(tmax)
        if progress is not None:
            progress.update(min(1.0, tolerance_N / max(residual, 1e-300)),
                            f"λ = {lam:.3g}, residual {residual:.2e} N, F = {pull:.5g} N")

    def true_residual() -> float:
        """Norm [N] of the unregularised equilibrium residual at the current state: the last
        solve's residual there (Exudyn evaluates it after its last update) minus the spring's force."""
        sd = mbs.systemData
        q_all = np.array(sd.GetODE2Coordinates())
        r = np.array(last_solver[0].GetSystemResidual())[:q_all.size]
        r[model.ode2_index] -= spring.force(_cable_part(model, q_all))
        return float(np.linalg.norm(r))

    def at_scale(lam: float) -> None:
        """Loads and friction at scale ``lam`` [-]; the stored state's kernel pass was of another."""
        _set_scale(model, lam)
        store.saved = store.saved[:2] + (None,)

    def relax_one_iteration(lam: float) -> tuple[bool, str]:
        """Pseudo-time steps of one Newton iteration each at load scale ``lam`` from the stored
        state, accepted while the true residual does not grow more than REJECT_GROWTH-fold, until
        it is below the tolerance."""
        at_scale(lam)
        c = c0
        spring.axial_share = AXIAL_SHARE
        previous, after_reject, message = np.inf, False, ""
        best, stalled = np.inf, 0
        for _ in range(MAX_ONE_ITERATION_STEPS):
            if stalled >= MAX_ONE_ITERATION_STALL:
                return False, (f"one-iteration pseudo-time steps: the residual did not halve in "
                               f"{MAX_ONE_ITERATION_STALL} steps (smallest {best:.3g} N)")
            stalled += 1
            ok, message, _ = pseudo_step(c, one_iteration)
            residual = true_residual() if ok else np.inf
            if residual > REJECT_GROWTH * previous or not ok:
                c *= 4.0
                after_reject = True
                if c > 1e6 * c0:
                    break
                continue
            store.save()
            record(lam, residual)
            if residual <= tolerance_N:
                return True, ""
            if residual <= 0.5 * best:
                best, stalled = residual, 0
            c /= RATE_FALL_AFTER_REJECT if after_reject else RATE_FALL
            after_reject = False
            spring.axial_share *= AXIAL_RELEASE
            previous = residual
        return False, (f"one-iteration pseudo-time steps: no equilibrium after {MAX_ONE_ITERATION_STEPS} "
                       f"steps{f' ({message})' if message else ''}")

    def relax(lam: float) -> tuple[bool, str]:
        """Pseudo-time steps at load scale ``lam`` from the stored state until the equilibrium
        residual is below the tolerance."""
        at_scale(lam)
        c = c0
        spring.axial_share = AXIAL_SHARE
        message = ""
        best, stalled = np.inf, 0
        stuck = _FailedSteps()
        exact = INEXACT_NEWTON_TOLERANCE <= NEWTON_TOLERANCE   # only the stopping step need be exact
        for _ in range(MAX_PSEUDO_STEPS_TOTAL):
            if stalled >= MAX_PSEUDO_STEPS:
                return False, (f"no equilibrium at load scale {lam:.3g}: the residual did not halve in "
                               f"{MAX_PSEUDO_STEPS} pseudo-time steps (smallest {best:.3g} N, stop at "
                               f"{tolerance_N:.3g} N)")
            stalled += 1
            ok, message, leftover = pseudo_step(c, exact)
            if not ok:
                stuck.record(exact, leftover)
                c *= 4.0
                if c > 1e6 * c0:
                    return False, stuck.why(message, lam, best, tolerance_N, settings)
                continue
            q_now = _cable_part(model, np.array(mbs.systemData.GetODE2Coordinates()))
            # the equilibrium residual is at most the spring's force plus what Newton left over
            residual = float(np.linalg.norm(spring.force(q_now))) + (leftover if exact else 0.0)
            store.save()
            record(lam, residual)
            if residual <= tolerance_N:
                if exact:
                    return True, ""
                # an inexact step's spring force is not yet the whole residual: confirm with a
                # step at the same rate whose Newton problem is solved to NEWTON_TOLERANCE
                exact = True
                continue
            if residual <= 0.5 * best:
                best, stalled = residual, 0
            # near the steady state the steps are exact: the one that stops must be, and an exact
            # solve from a loosely converged state near grazing contact may fail (2-cycle)
            exact = exact or residual <= EXACT_WITHIN * tolerance_N
            c /= 4.0
            spring.axial_share *= AXIAL_RELEASE
        return False, (f"no equilibrium at load scale {lam:.3g} after {MAX_PSEUDO_STEPS_TOTAL} pseudo-time steps "
                       f"(smallest residual {best:.3g} N, stop at {tolerance_N:.3g} N)")

    status, message = "ok", ""
    outside_at_start = _outside_points(model)
    ok, first_message = relax_one_iteration(1.0)
    if not ok:
        store.saved = start
        ok, first_message = relax(1.0)
    if ok:
        message = f"{total[0]} pseudo-time steps"
    else:
        store.saved = start
        lam, step, stages = 0.0, 0.5, 0
        while lam < 1.0:
            target = min(1.0, lam + step)
            before = store.saved
            ok, msg = relax(target)
            stages += 1
            if ok:
                lam = target
                step = min(2.0 * step, 1.0)
            else:
                store.saved = before
                step *= 0.5
                if step < MIN_CONTINUATION_STEP:
                    status = "failed"
                    message = (f"no steady state found: continuation stalled at load scale {lam:.4g} "
                               f"(at full load: {first_message}; last: {msg}); {STALL_FIX}")
                    break
        if status == "ok":
            message = (f"continuation in the load scale, {stages} stages, {total[0]} pseudo-time steps "
                       f"(at full load from the start: {first_message})")
    store.restore_as_initial()
    spring.rate = 0.0
    if status == "ok":
        # an equilibrium with the cable pulled out of the conduit (straight across its walls) is
        # a solution of the same equations, but not the steady pull
        outside = _outside_points(model) - outside_at_start
        if outside > model.kernel.n_check_points:
            status = "failed"
            message = (f"the static solve found an equilibrium with {outside} more check points outside "
                       f"the conduit than at the start: the cable left the conduit (start too far from "
                       f"the steady state?)")
    if status == "ok":
        status, message = _check_balance(model, message)
    wall = time.perf_counter() - t_wall
    if progress is not None:
        progress.close()
    return SolveOutcome(history=history, status=status, message=message, end_time_s=0.0,
                        steps=counters["steps"], newton_iterations=counters["newton"],
                        jacobian_updates=counters["jacobian"], wall_time_s=wall)


#: What to change when a steady solve ends in a state that is not the steady pull.
BALANCE_FIX = ('fix: the rule\'s mesh (omit `cable.element_length`/`cable.elements`) or the dynamic run '
               '(`solver.mode = "dynamic"` with `solver.start_from = "steady"`)')


def _check_balance(model, message: str) -> tuple[str, str]:
    """``("failed", why)`` when the solved state is not a steady pull (:mod:`exucable.post.balance`),
    else ``("ok", message)``. A residual below the tolerance does not prove it: a state whose
    weight the rig holds up across its line is an equilibrium too."""
    loads_of = getattr(model, "loads", None)
    if loads_of is None:          # several cables (exucable.model.bundle): not checked yet
        return "ok", message
    from ..post.balance import steady_balance

    c = model.scenario.contact
    q, _ = model.coordinates()
    check = steady_balance(loads_of(), q, float(np.sum(model.layout.element_length_m)), c.friction,
                           c.static_friction)
    if check.ok:
        return "ok", message
    return "failed", f"the steady solve ended in a state that is not the steady pull: {check.message}; {BALANCE_FIX}"


def _cable_part(model, q_all) -> np.ndarray:
    """The cable's displacement coordinates out of the system's ODE2 vector."""
    return np.asarray(q_all, dtype=float)[model.ode2_index]
