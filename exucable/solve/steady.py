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

and solved from the pre-tensioned start (the rope solution) by static solves: Exudyn's Newton method
on our own assembled system where the model allows it, else Exudyn's static solver
(``[solver] static_solver``, :mod:`exucable.solve.newton_system`; the same iterates to round-off,
but that ours also shortens a step whose residual spikes before rejecting it, which Exudyn's cannot:
``SteadySettings.max_backtracks``).

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
``steady_residual`` (:class:`SteadySettings`) times the rope solution's largest tension. Far from
it a step's Newton problem is solved only to ``inexact_newton_tolerance`` (each step need only make
progress: inexact continuation, 59 → 36 Newton iterations on Example 4); within ``exact_within`` tolerances of the
stop, and always for the step that stops, to ``newton_tolerance``, so that the spring's force is the
whole residual there.

First, though, the same continuation is tried with one Newton iteration per pseudo-time step,
steered by the true residual (:meth:`SteadySolver.relax_one_iteration`): after each step the
unregularised residual is the static solver's residual at the new state minus the spring's force
there, so no step need be solved exactly to know how far the state is from equilibrium. A step
whose residual grows more than ``reject_growth``-fold is first shortened, halved up to
``max_backtracks`` times along itself (a line search: one force evaluation each, no Newton
iteration), and kept at the first length within that growth; if none is, it is undone and retried
with c × 4. An accepted step divides c by ``rate_fall`` (by ``rate_fall_after_reject`` right after a
rejection), so the steps become plain Newton steps near the solution. Why shorten first: where
the cable leaves a wall it grazed (a bend's end), the check points just off the wall add no
stiffness, and a nearly plain Newton step pushed the cable there millimetres into the wall (the
residual 5-550× the step's start, on ~1 km routes at spring rates of 500-8000 s⁻²); retrying with
a stiffer spring everywhere held the whole cable's soft axial mode for tens of steps for a
spike at a few nodes, and the Newton count swung with whether a route's bend ends happened to
spike (neighbouring routes 13 against 45 Newton iterations; ``benchmarks/newton_spread.py``).
The shortened step keeps the step's direction; the spring then falls as after a rejection. The
solve stops once that residual is below the
tolerance: Example 4 in 17 Newton iterations instead of 36, its pulling force 1e-9 (not 7e-7) from
the one at 1/1000 of the stop tolerance (reference/README.md, "Speed"). Where it does not converge within its budget, the
exact-step continuation above runs from the start.
Where that does not converge either, the loads themselves are ramped (friction, gravity and end forces
scaled by λ) with the increment halved on failure (:meth:`SteadySolver.ramp_loads`).

Several cables (:mod:`exucable.model.bundle`) follow two more rules. A one-iteration step is held
to the smallest residual reached, not the last (steps that each stayed within 2x of the one before
drifted 496 -> 22 000 N). Where the loads' ramp stalls, the friction alone is ramped,
gravity and the end forces kept, from the best state reached (:meth:`SteadySolver.restart_state`):
with gravity and the end forces ramped to zero the cables float in the duct, their equilibrium is
singular, and the ramp stalled at load scale 0 (one 90° bend at 4000 N back tension: with friction
alone from the best state it converged at λ = 0.5). The loads' ramp from the start stays first:
a keystone laid in a straight drops into a cradle that way, and not from the best state.
And where the one-iteration steps from the start fail, a bundle is first relaxed by a fictitious
explicit dynamics on the same residual (:mod:`exucable.solve.relax`, :meth:`SteadySolver.relax_dynamic`)
until the one-iteration continuation from its state converges (handed over at ``bundle_relax_handover``
stop tolerances, then at residuals 10× smaller down to ``bundle_relax_within``: Newton's basin is wider
than the relaxation's last digits cost), and every phase after runs from the relaxed state: the
implicit steps stalled at newtons where the cables must rearrange across the duct (three cables in an
up-bend: the triangle turns over onto the upper wall), and the relaxation, like a physical settle, moves
off the unstable balances on the way (reference/README.md, the up-bend study: 12 of 12 cases solve, 5
failed at the 60 s limit before). Where the relaxation from one start stalls, the next start of
``bundle_starts`` is built and solved instead (:mod:`exucable.solve.bundle_starts`; the solver's
``fallback``).

A solve may instead start warm, from a state near its steady state (``warm_start``: the coarse mesh's
solved state subdivided, :func:`exucable.solve.start.nested_start`). The phases above assume the rope
start, far from equilibrium: their first pseudo-time steps are short (c0, an isotropic spring) because
the start's lateral and axial misfits are large. From a warm start those steps would only creep, so
the warm solve skips them: it runs the one-iteration continuation from the rate and axial share it
would have reached after ``warm_start_skipped_steps`` accepted steps, with its own smaller budget
(``max_warm_start_steps``), and no load ramp (the loads are already carried). If that does not
converge, the solve starts again from the rope start with every phase, so that the answer does not
depend on the start (``tests/test_nested_start.py``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np
import exudyn as exu

from ..errors import SolverError
from .dynamic import History, Progress, SolveOutcome, quiet_sparse
from ..post.tension import TensionStations, profile_stations_m
from .steady_advice import TIME_LIMIT_KEY, failure_advice
from .newton_system import ExudynStatic, static_backend
from .relax import check_settings
from .block_sweeps import node_block_masses
from .onset_continuation import OnsetContinuation, OnsetSettings
from .negative_curvature import curvature_phase

__all__ = ["SteadySettings", "SteadySolver", "solve_steady", "static_settings"]


@dataclass(frozen=True)
class SteadySettings:
    """How the steady solve iterates and when it stops (:class:`SteadySolver`).

    Frozen: a variant is ``dataclasses.replace(SteadySettings(), rate_fall=16.0)``, never a
    changed module constant, so that one solve's rules cannot leak into another's. Only
    ``steady_residual`` and ``time_limit_s`` are scenario keys (``[solver] steady_residual``,
    ``steady_time_limit``; :meth:`from_solver`); the
    others are the solver's tuning, measured on the paper's examples and the industry scenarios
    (``benchmarks/steady_iterations.py --set NAME=VALUE`` compares a change across them).

    Attributes
    ----------
    steady_residual : float
        Residual of the steady equilibrium at which the solve stops, relative to the largest
        tension of the rope solution [-]: the spring force c·m·(q - q̄) left at the last
        pseudo-time step. Why 1e-6: the pulling force then moves by less than 1e-7 relative
        against a solve to 1/1000 of it (``benchmarks/steady_iterations.py --tight``).
    newton_tolerance : float
        Newton's relative tolerance inside one exact pseudo-time step [-] (its problem is well posed).
    inexact_newton_tolerance : float
        Newton's relative tolerance inside a pseudo-time step still far from the steady state [-]:
        each step only has to make progress toward it (inexact pseudo-transient continuation,
        Kelley & Keyes 1998 Sect. 4); the step that stops the solve is converged to
        ``newton_tolerance``. Why 0.1: 59 → 36 Newton iterations on Example 4.
    exact_within : float
        Residual, in stop tolerances, below which the pseudo-time steps are solved exactly [-].
    exact_newton_share : float
        Newton's absolute tolerance in an exact pseudo-time step, as a share of the stop
        tolerance [-]; the Newton residual left over counts toward the stop test (spring force +
        leftover ≤ tolerance). Why not tighter: the residual has a round-off floor that grows with
        the mesh (2e-5 N at Gera's 2032 elements, above a share of 1e-3 there: every exact step
        failed and the solve stalled at load scale 0). At 0.1 the floor is 30× below the Newton
        tolerance there, and the stop test stays honest (residual ≤ 1.1 × tolerance);
        ``tests/test_steady.py::test_exact_steps_stop_above_the_round_off_floor``.
    axial_share : float
        Weight of the pseudo-time spring along the cable's axis relative to across it at the first
        step of a continuation [-] (see :class:`PseudoTimeSpring`: 0 lets a long cable's first step
        slide it by the start's strain misfit and fail, 1 solves 300 m in 21 pseudo-time steps).
    axial_release : float
        Factor on the axial share after each converged pseudo-time step [-]: the axial mode is
        linear (EA) and, on a long cable, so soft (1 km: ~1 s⁻² per unit mass) that a spring
        falling like the lateral one would hold it for hundreds of steps.
    max_pseudo_steps : int
        Exact-step continuation: pseudo-time steps (failed attempts included) without the residual
        halving before the solve at one load scale is declared failed. A budget on progress, not on
        the count: 1 km from the centreline rope's start the residual falls from 900 N to 8 N in the
        first 80 steps (a count budget of 80 declared it failed), then converges after 51 more.
    max_pseudo_steps_total : int
        Exact-step continuation: pseudo-time steps at one load scale in all before the solve there
        is declared failed.
    reject_growth : float
        Growth of the true residual over the last accepted step's [-] above which a one-iteration
        pseudo-time step is undone and retried with a 4× stiffer spring (a trust-region test).
    rate_fall, rate_fall_after_reject : float
        Factor by which the spring rate falls after an accepted one-iteration step, and right after
        a rejected one [-]. Measured (Newton iterations, one-iteration steps vs the exact-step
        continuation): Ex4 17 vs 36, Gera 60 vs 102, coarse Ex2 29 vs 55, Ex3 27 vs 19, route100 43
        vs 25; a fall by 4 after a rejection too gave 34 on Ex3 and 60 on coarse Ex2, a fall by 4
        throughout fell back to the exact steps on Ex4 (60).
    max_one_iteration_steps : int
        Pseudo-time steps (accepted and rejected) the one-iteration continuation may take before the
        exact-step continuation takes over [-]; 0 skips it.
    max_one_iteration_stall : int
        Pseudo-time steps (accepted and rejected) without the true residual halving after which the
        one-iteration continuation gives up for the exact-step one [-]. Gera's route at 4× the mesh
        wandered at 10-200 N for 48 accepted steps (210 Newton iterations in all against 130 for the
        exact steps alone); 10 sent Ex. 3 and the coarse Ex. 2-4 to the exact steps too, 20 none of
        the paper's examples.
    min_continuation_step : float
        Smallest increment of the load scale λ [-] in the load continuation before the solve is
        declared failed.
    time_limit_s : float
        CPU time [s] the solve may take before it stops as failed (``[solver] steady_time_limit``).
        CPU, not wall: a loaded machine must not turn a converging solve into a failed one.
    warm_start_skipped_steps : int
        A warm start (:class:`SteadySolver`'s ``warm_start``) begins the one-iteration continuation
        at the spring rate c0 / ``rate_fall``^k and the axial share ``axial_share`` ·
        ``axial_release``^k, k this many [-]: the first steps' short springs are for the rope
        start's misfit, which a warm start does not have. Measured (the nested start on
        ``benchmarks/long_routes.py``'s 1, 2, 5 km routes, Newton iterations): k = 2: 10, 9, 10;
        3: 7, 8, 9; 4: 13, 8, 26; 5: -, 10, 29 (k = 0 at 1 km: 12; from the rope start 19, 26, 24):
        a softer first spring lets the first Newton step overshoot.
    max_warm_start_steps : int
        Pseudo-time steps (accepted and rejected) a warm start may take, the stall rule
        (``max_one_iteration_stall``) included, before the solve starts again from the rope start [-]
        (a warm start that converges took at most 10 on the long routes).
    bundle_relax_steps : int
        Several cables: steps of the dynamic relaxation (:mod:`exucable.solve.relax`) at most, run
        where the one-iteration continuation from the start fails [-]; 0 skips it (the module's notes).
    bundle_relax_within : float
        Residual, in stop tolerances, below which the dynamic relaxation does not go [-]: its last
        hand-over to the one-iteration continuation (:meth:`SteadySolver.relax_dynamic`).
    bundle_relax_handover : float
        Residual, in stop tolerances, of the dynamic relaxation's first hand-over to the
        one-iteration continuation [-]. Measured (the 100 m three-cable route, cradled, stop
        tolerance 2.2e-3 N): that continuation converged from relaxed states at 2.96 and 7.9 N,
        not from 23.6 N (``studies/bundle_relax_handover.py``).
    bundle_relax_handover_fall : float
        Factor by which the hand-over residual falls after a hand-over whose continuation failed [-].
    bundle_relax_masses : str
        The dynamic relaxation's masses (:func:`exucable.solve.relax.bundle_masses` ``kind``):
        ``"diagonal"`` (the default) or ``"frame"`` (row sums in each node's frame); measured with the
        bundle's starts in ``studies/bundle_start_masses.py`` (reference/README.md, "Starts ×
        masses on the triangle's route").
    bundle_block_sweeps : int
        Several cables: sweeps of block Gauss–Seidel by cable (:mod:`exucable.solve.block_sweeps`) at
        most, run from the rope start at full load in the onset layer's first width before any other
        phase, whose start the swept state then is [-]; 0 (the default) skips it. Why off: on the 100 m
        route the sweeps stall at a coupled residual of ~170 N (the coupled steps' best is 62 N) and
        the solve from their state fails as from the rope start (reference/README.md, "Block
        Gauss–Seidel by cable").
    bundle_block_coarse_steps : int
        The block sweeps' coarse correction: steps after each sweep at most
        (:attr:`exucable.solve.block_sweeps.BlockSweepSettings.coarse_steps`) [-]; 0 (the default): none.
    bundle_curvature_rounds : int
        Several cables: rounds of negative-curvature steps (:mod:`exucable.solve.negative_curvature`),
        each followed by the one-iteration continuation, where the dynamic relaxation's hand-over
        stalled [-]; 0 (the default) skips them. Off: on the 100 m three-cable route the steps left no
        negative mode, but the continuation after them put the top cable back on its crest and
        stalled higher (28.2 N against 18.2 N; reference/README.md, "Negative curvature on the 100 m
        route").
    bundle_starts : tuple of str
        Several cables: the starts tried in turn (``build_bundle_model``'s ``start_path``,
        ``[solver] bundle_starts``; :func:`exucable.solve.bundle_starts.solve_bundle_starts`), each
        but the last given up where its dynamic relaxation stalls (``bundle_start_stall_steps``), the
        next built and solved in the CPU time left. Why ``("clearance", "statics_own")``: the
        clearance start solves the up-bend study's 12 cases and the 100 m cradle (their answers
        unchanged), the cross-section's statics the 100 m triangle, where the clearance start's
        relaxation stalls at 29.4 N (reference/README.md, "A start sequence").
    bundle_start_stall_steps, bundle_start_stall_work : int, float
        A start that another follows gives up where its dynamic relaxation has not halved its
        residual in max(``bundle_start_stall_steps``, ``bundle_start_stall_work`` / the bundle's
        coordinates) steps [-] (at most the relaxation's own 5000), counted in steps, not seconds,
        so that which start answers does not depend on the machine. Measured (the longest stretch
        without a halving in relaxations that went on to solve, reference/README.md, "A start
        sequence"): the up-bend study's cases 867-2017 steps (198 coordinates: 2e6 / 198 = 10 100,
        the relaxation's own rule applies), the 100 m cradle 655 (1818 coordinates), the industry
        three-cable plan's cradle 823 (3546); the 100 m triangle's clearance start last halved at
        step 1084 and never again in 5000. 1100 steps: it gives up at step 2184.
    max_backtracks : int
        Halvings of a one-iteration step whose residual grew more than ``reject_growth``-fold before
        it is rejected [-] (the module's notes; each costs one force evaluation, no Newton
        iteration); 0 rejects at once. Only where the static solver can evaluate a state without a
        Newton iteration (our own, :mod:`exucable.solve.newton_system`); Exudyn's rejects at once.
        Measured (``benchmarks/newton_spread.py``'s 42 routes about 1 km, the error bar's coarse
        solves: Newton iterations in all, the largest ratio between neighbouring routes): 6: 864,
        1.23 (13-25 each); 4-12: 864-866, 1.23; 3: 884, 1.62; 0: 1590, 3.46 (13-53 each).
    """

    steady_residual: float = 1e-6
    newton_tolerance: float = 1e-8
    inexact_newton_tolerance: float = 0.1
    exact_within: float = 1000.0
    exact_newton_share: float = 0.1
    axial_share: float = 1.0
    axial_release: float = 0.25
    max_pseudo_steps: int = 80
    max_pseudo_steps_total: int = 400
    reject_growth: float = 2.0
    rate_fall: float = 8.0
    rate_fall_after_reject: float = 2.0
    max_one_iteration_steps: int = 80
    max_one_iteration_stall: int = 20
    min_continuation_step: float = 1.0 / 16.0
    time_limit_s: float = 60.0
    warm_start_skipped_steps: int = 3
    max_warm_start_steps: int = 20
    bundle_relax_steps: int = 100000
    bundle_relax_within: float = 30.0
    bundle_relax_handover: float = 3000.0
    bundle_relax_handover_fall: float = 10.0
    bundle_relax_masses: str = "diagonal"
    bundle_curvature_rounds: int = 0
    max_backtracks: int = 6
    bundle_block_sweeps: int = 0
    bundle_block_coarse_steps: int = 0
    bundle_starts: tuple = ("clearance", "statics_own")
    bundle_start_stall_steps: int = 1100
    bundle_start_stall_work: float = 2.0e6

    def __post_init__(self):
        from ..model.bundle import BUNDLE_STARTS

        check_settings(self, skip=("bundle_relax_masses", "bundle_starts"))
        starts = self.bundle_starts
        if isinstance(starts, str) or not isinstance(starts, (tuple, list)) or not starts \
                or any(x not in BUNDLE_STARTS for x in starts):
            allowed = ", ".join(f'"{x}"' for x in BUNDLE_STARTS)
            raise SolverError(f"SteadySettings.bundle_starts = {starts!r}: give one or more of {allowed}")
        object.__setattr__(self, "bundle_starts", tuple(starts))
        if self.bundle_relax_masses not in ("diagonal", "frame"):
            raise SolverError(f"SteadySettings.bundle_relax_masses = {self.bundle_relax_masses!r}: "
                              f"use \"diagonal\" or \"frame\"")
        if self.bundle_relax_handover_fall <= 1.0:
            raise SolverError(f"SteadySettings.bundle_relax_handover_fall = {self.bundle_relax_handover_fall!r}: "
                              f"must be > 1 (the hand-over residual must fall)")

    @classmethod
    def from_solver(cls, solver) -> "SteadySettings":
        """The settings of a scenario's ``[solver]`` table (:class:`exucable.scenario.specs.SolverSpec`):
        its ``steady_residual``, ``steady_time_limit_s`` and ``bundle_starts``, the defaults otherwise."""
        return cls(steady_residual=float(solver.steady_residual), time_limit_s=float(solver.steady_time_limit_s),
                   bundle_starts=tuple(solver.bundle_starts))


def initial_spring_rate(model) -> float:
    """c0 [1/s²]: an element's axial stiffness EA/L_e per its mass ρA·L_e, E/(ρ L_e²) — of the
    order of the contact stiffness per node, so the first steps are short."""
    L_e = float(np.min(model.layout.element_length_m))
    return model.axial_stiffness_N / (model.properties.mass_per_length_kg_per_m * L_e * L_e)


def static_settings(tolerance: float = SteadySettings.newton_tolerance, max_iterations: int = 12,
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
    P_k = I - (1 - s) t tᵀ weights the spring along the cable's tangent t at node k
    (at the anchor) by the axial share s [-] (:attr:`SteadySettings.axial_share`). Measured: releasing the axial direction entirely (share 0) lets a long
    cable's first Newton step slide it by the start's strain misfit (decimetres on 300 m) and
    the step fails; the isotropic spring (share 1) solves 300 m in 21 pseudo-time steps.
    """

    def __init__(self, model, axial_share: float = SteadySettings.axial_share):
        from exudyn.itemInterface import ObjectGenericODE2

        self._q_ref = np.asarray(model.layout.coordinates, dtype=float).reshape(-1)
        # per 3-block (positions, slopes of each node): its mass
        self.block_mass = node_block_masses(model)
        self.n_nodes = len(self.block_mass)
        self.n = 6 * self.n_nodes
        self.rate = 0.0                       # c [1/s²]
        self.axial_share = axial_share        # weight along the tangent [-]
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

    def block_values(self, f_q: float = 1.0) -> np.ndarray:
        """The stiffness c·m_k·P_k of the spring's 3 × 3 blocks times ``f_q``, per node, positions
        then slopes, row-major (the left-hand-side derivative of :meth:`force`)."""
        return (f_q * self.rate * self.block_mass[:, :, None, None] * self._proj[:, None, :, :]).reshape(-1)

    def _jacobian(self, mbs, t, item, q, q_t, f_q, f_v):
        m = exu.MatrixContainer()
        vals = self.block_values(f_q)
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

    def restore_as_initial(self, backend=None):
        """Make the saved state the next solve's start: handed to ``backend`` where it takes one
        (``start_from``: our Newton loop reads nothing else of Exudyn's state before it writes its
        own; four vector writes into Exudyn cost ~30 ms a step at 10 km), else written into
        Exudyn's initial and current configurations."""
        q, lam, kept = self.saved
        take = getattr(backend, "start_from", None)
        if take is not None:
            take(q)
        else:
            sd = self.mbs.systemData
            for cfg in (exu.ConfigurationType.Initial, exu.ConfigurationType.Current):
                sd.SetODE2Coordinates(q, configuration=cfg)
                sd.SetAECoordinates(lam, configuration=cfg)
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


def _static_choice(model) -> str:
    """``[solver] static_solver`` of the model's scenario ("exucable" when it has none)."""
    solver = getattr(getattr(model, "scenario", None), "solver", None)
    return getattr(solver, "static_solver", "exucable")


def _set_scale(model, lam: float, loads: bool = True) -> None:
    model.load_scale.apply(model.mbs, gravity=lam if loads else 1.0, end_force=lam if loads else 1.0)
    model.kernel.set_friction_scale(lam)
    if model.coupling is not None:
        # a pass at the same coordinates was of the former friction scale
        model.coupling.forget_evaluation()


class SteadySolver:
    """The steady sliding state of ``model`` (built with ``solver.mode = "steady"``) by
    pseudo-transient continuation (the module's notes); :meth:`solve` runs it, once.

    The phases are methods: :meth:`relax_one_iteration` (one Newton iteration per pseudo-time step,
    steered by the true residual), :meth:`relax` (inexact, then exact pseudo-time steps) and
    :meth:`ramp_loads` (continuation in the load scale); they share the state in attributes (the stored state to
    restart from, the spring, the counters, the history).

    Parameters
    ----------
    model : exucable.model.build.Model
        A steady-mode model, at its pre-tensioned start. Constructing the solver adds the
        pseudo-time spring to its system.
    settings : SteadySettings
        The stop tolerance and the continuation's rules.
    progress : Progress, optional
        Told the residual reached after every accepted pseudo-time step, closed at the end.
    warm_start : tuple of numpy.ndarray, optional
        The system's ODE2 and algebraic coordinates of a state near the steady state to start from
        (:func:`exucable.solve.start.nested_start`); the model's own start (the rope's) is the
        fallback. See the module's notes.
    onset : OnsetSettings, optional
        Several cables: the contact onset layer's continuation (:mod:`exucable.solve.onset_continuation`).
    fallback : bool
        Several cables: another start follows this one
        (:func:`exucable.solve.bundle_starts.solve_bundle_starts`). The dynamic relaxation then stops
        where its residual has not halved in ``bundle_start_stall_steps`` (or more) steps, and
        where it fails the solve fails at once (no exact-step continuation, no load ramp): the
        next start gets the time left.
    """

    def __init__(self, model, settings: SteadySettings = SteadySettings(), progress: Progress | None = None,
                 warm_start: tuple | None = None, onset: OnsetSettings | None = None, fallback: bool = False):
        self.model = model
        #: another start follows (exucable.solve.bundle_starts): give up where the relaxation stalls
        self.fallback = fallback
        self.warm_start = warm_start
        self.settings = settings
        self.progress = progress
        self.mbs = model.mbs
        self.history = History()
        self.spring = PseudoTimeSpring(model, axial_share=settings.axial_share)
        self.store = _StateStore(self.mbs, model.coupling)
        self.start = self.store.saved
        self.newton_iterations = 0
        self.jacobian_updates = 0
        self.backtracks = 0       # force evaluations of shortened one-iteration steps (shorten_step)
        self.steps = 0            # pseudo-time steps tried (rejected and failed ones included)
        self.accepted = 0         # pseudo-time steps kept (the history's rows)
        scale_N = max(float(np.max(np.abs(model.rope.tension_N))) if model.rope is not None else 0.0,
                      model.back_tension_N, 1.0)
        #: the stop tolerance [N]
        self.tolerance_N = float(settings.steady_residual) * scale_N
        self.exact_settings = static_settings(tolerance=settings.newton_tolerance,
                                              absolute_tolerance_N=settings.exact_newton_share * self.tolerance_N)
        self.inexact_settings = static_settings(tolerance=settings.inexact_newton_tolerance,
                                                absolute_tolerance_N=1e-3 * self.tolerance_N)
        self.c0 = initial_spring_rate(model)
        self.stations = force_stations(model)
        self.one_iteration_settings = static_settings(tolerance=1.0, max_iterations=1,
                                                      absolute_tolerance_N=1e-3 * self.tolerance_N)
        #: who solves each static problem (``[solver] static_solver``; exucable.solve.newton_system)
        self.static, self.static_note = static_backend(model, self.spring, static_settings, _static_choice(model))
        self._solved = False
        self._cpu_start = time.process_time()
        if hasattr(self.static, "deadline_cpu_s"):
            # our Newton loop reads the clock between its iterations too: an exact step is up to 12
            self.static.deadline_cpu_s = self._cpu_start + settings.time_limit_s
        self.timed_out = False           # stopped at settings.time_limit_s
        self._trace_lam, self._trace = 0.0, []   # the load scale of the last accepted steps, their residuals [N]
        #: several cables (exucable.model.bundle): the continuation's bundle rules apply (module notes)
        self.bundle = getattr(model, "n_cables", 1) > 1
        self.best = (np.inf, None)       # the smallest true residual [N] of an accepted step and its state
        self.friction_only = False       # the load ramp scales the friction only (a bundle's first ramp)
        self.relaxation = None           # a bundle's dynamic relaxation (exucable.solve.relax.RelaxOutcome), if run
        self.sweeps = None               # a bundle's block sweeps (exucable.solve.block_sweeps.BlockSweepOutcome), if run
        self.curvature_note = ""         # what a bundle's negative-curvature steps found (bundle_curvature_rounds)
        #: several cables: solved through a smooth contact onset first (exucable.solve.onset_continuation)
        self.onset = OnsetContinuation(onset) if onset is not None and self.bundle else None

    def out_of_time(self) -> bool:
        """Whether the solve has used up its CPU time (:attr:`SteadySettings.time_limit_s`)."""
        self.timed_out = self.timed_out or time.process_time() - self._cpu_start > self.settings.time_limit_s
        return self.timed_out

    def advice(self, lam: float) -> str:
        """Where the solve got to and what to change (:func:`failure_advice`): the residual is the
        smallest at the last load scale tried; it counts as still converging unless five accepted
        steps there failed to halve it (fewer steps tell nothing yet)."""
        r = self._trace
        falling = len(r) < 6 or r[-1] <= 0.5 * r[-6]
        return failure_advice(self.model, load_scale=lam, residual_N=min(r) if r else float("nan"),
                              tolerance_N=self.tolerance_N, timed_out=self.timed_out, still_converging=falling,
                              time_limit_s=self.settings.time_limit_s,
                              residual_load_scale=self._trace_lam if r else None)

    def one_solve(self, exact: bool | exu.SimulationSettings) -> tuple[bool, str, float]:
        """One static solve with the exact, inexact or given settings: converged?, message, and
        Newton's last residual norm [N]."""
        if isinstance(exact, exu.SimulationSettings):
            chosen = exact
        else:
            chosen = self.exact_settings if exact else self.inexact_settings
        newton = chosen.staticSolver.newton
        extra = {"settings": chosen} if isinstance(self.static, ExudynStatic) else {}
        out = self.static.solve(int(newton.maxIterations), float(newton.relativeTolerance),
                                float(newton.absoluteTolerance), **extra)
        self.newton_iterations += out.newton_iterations
        self.jacobian_updates += out.jacobian_updates
        return out.converged, out.message, out.residual_N

    def pseudo_step(self, c: float, exact: bool | exu.SimulationSettings) -> tuple[bool, str, float]:
        """One pseudo-time step at spring rate ``c`` [1/s²] from the stored state (see :meth:`one_solve`)."""
        self.store.restore_as_initial(self.static)
        self.spring.anchor_at(_cable_part(self.model, self.store.saved[0]))
        self.spring.rate = c
        self.steps += 1
        return self.one_solve(exact)

    def record(self, lam: float, residual: float) -> None:
        """One history row (and the progress bar) for an accepted pseudo-time step."""
        self.accepted += 1
        if lam != self._trace_lam:
            self._trace_lam, self._trace = lam, []
        self._trace.append(residual)
        pull, trail, tmax = steady_forces(self.model, self.stations)
        self.history.time_s.append(float(self.accepted))
        self.history.pull_force_N.append(pull)
        self.history.trailing_tension_N.append(trail)
        self.history.max_tension_N.append(tmax)
        if self.progress is not None:
            self.progress.update(min(1.0, self.tolerance_N / max(residual, 1e-300)),
                                 f"λ = {lam:.3g}, residual {residual:.2e} N, F = {pull:.5g} N")

    def true_residual(self) -> float:
        """Norm [N] of the unregularised equilibrium residual at the current state: the last
        solve's residual there (Exudyn evaluates it after its last update) minus the spring's force."""
        own = getattr(self.static, "equilibrium_residual_N", None)
        if own is not None:
            return own()
        sd = self.mbs.systemData
        q_all = np.array(sd.GetODE2Coordinates())
        r = self.static.system_residual()[:q_all.size]
        r[self.model.ode2_index] -= self.spring.force(_cable_part(self.model, q_all))
        return float(np.linalg.norm(r))

    def at_scale(self, lam: float) -> None:
        """Loads and friction at scale ``lam`` [-] (a bundle's friction only, :meth:`ramp_loads`);
        the stored state's kernel pass was of another."""
        _set_scale(self.model, lam, loads=not self.friction_only)
        self.store.saved = self.store.saved[:2] + (None,)

    def relax_one_iteration(self, lam: float, skip: int = 0, max_steps: int | None = None) -> tuple[bool, str]:
        """Pseudo-time steps of one Newton iteration each at load scale ``lam`` [-] from the stored
        state, accepted while the true residual does not grow more than ``reject_growth``-fold,
        until it is below the tolerance: converged?, and why not.

        ``skip``: begin at the spring rate and axial share reached after that many accepted steps
        (a warm start); ``max_steps``: the budget of steps instead of ``max_one_iteration_steps``."""
        self.at_scale(lam)
        s = self.settings
        c = self.c0 / s.rate_fall ** skip
        self.spring.axial_share = s.axial_share * s.axial_release ** skip
        previous, after_reject, message = np.inf, False, ""
        best, stalled = np.inf, 0
        budget = s.max_one_iteration_steps if max_steps is None else max_steps
        for tried in range(1, budget + 1):
            if self.out_of_time():
                return False, f"stopped at `{TIME_LIMIT_KEY}`"
            if stalled >= s.max_one_iteration_stall:
                return False, (f"one-iteration pseudo-time steps: the residual did not halve in "
                               f"{s.max_one_iteration_stall} steps (smallest {best:.3g} N)")
            stalled += 1
            ok, message, _ = self.pseudo_step(c, self.one_iteration_settings)
            residual = self.true_residual() if ok else np.inf
            # a bundle's steps are held to the best residual, not the last: drifting up by 2x per
            # step went 496 -> 22 000 N on the 100 m route
            limit = s.reject_growth * (min(previous, self.best[0]) if self.bundle else previous)
            if ok and residual > limit:
                residual = self.shorten_step(residual, limit)
                # a shortened step kept: the spring falls as after a rejection (by 8 instead, 10 km's
                # coarse solve took 54 Newton iterations instead of 23: the next steps diverged)
                after_reject = True
            if residual > limit or not ok:
                c = self.stiffen(c)
                after_reject = True
                if c > 1e6 * self.c0:
                    return False, (f"one-iteration pseudo-time steps: a step rejected up to a spring rate of "
                                   f"1e6 c0 after {tried} steps ("
                                   f"{f'smallest {best:.3g} N' if np.isfinite(best) else 'none accepted'})"
                                   f"{f'; last: {message}' if message else ''}")
                continue
            self.store.save()
            self.record(lam, residual)
            if residual <= self.tolerance_N:
                return True, ""
            if residual < self.best[0]:
                self.best = (residual, self.store.saved)
            if residual <= 0.5 * best:
                best, stalled = residual, 0
            c /= s.rate_fall_after_reject if after_reject else s.rate_fall
            after_reject = False
            self.spring.axial_share *= s.axial_release
            previous = residual
        return False, (f"one-iteration pseudo-time steps: no equilibrium after {budget} "
                       f"steps{f' ({message})' if message else ''}")

    def stiffen(self, c: float) -> float:
        """The spring rate [1/s²] after a rejected or failed pseudo-time step at rate ``c``: 4c, and
        for several cables the axial share raised back by 1/``axial_release`` (at most to
        ``axial_share``), so that the retried step is shorter along the cables too.

        Why: each accepted step multiplies the axial share by ``axial_release``, so after tens of
        them the spring holds nothing along the cables (0.25²³ = 1.4e-14 on the 100 m three-cable
        route), and 4c alone left the steps 28 mm long along the tangent with the spring a million
        times stiffer (across it, 7 nm), and every retried step was rejected: in a bend of radius R
        an axial step u moves the nodes off their curve by up to u²/2R (78 µm at 28 mm and 5 m),
        several times the contacts' loaded penetration (reference/README.md, "The 100 m route: the
        spring released along the cables"; ``tests/test_bundle_continuation.py``). One cable's steps
        keep 4c alone (its rejected steps are shortened first, :meth:`shorten_step`)."""
        if self.bundle:
            s = self.settings
            self.spring.axial_share = min(s.axial_share, self.spring.axial_share / s.axial_release)
        return 4.0 * c

    def relax_dynamic(self, why: str) -> tuple[bool, str]:
        """Several cables, where the one-iteration continuation from the start failed (``why``):
        dynamic relaxation (:func:`exucable.solve.relax.relax_bundle`) from the start at full load,
        handed to the one-iteration continuation at ``bundle_relax_handover`` stop tolerances; where
        that continuation fails, the relaxation goes on from its state to a residual
        ``bundle_relax_handover_fall`` times smaller, and so on down to ``bundle_relax_within`` stop
        tolerances. The last relaxed state is the start of every phase after: converged?, and why not.

        Why a ladder: Newton's basin is wider than the relaxation's last digits cost. On the 100 m
        three-cable route (cradled) the one-iteration continuation converges from relaxed states at
        2.96 and 7.9 N (20 and 79 Newton iterations, 1.1 and 4.2 s CPU), where the relaxation had
        taken ~3000 steps (30 s) to reach 3 N and was at 1.15 N after 40 s, far from 30 stop
        tolerances (0.066 N); a failed attempt costs at most ``max_one_iteration_steps`` Newton
        iterations (``studies/bundle_relax_handover.py``; reference/README.md, "The relaxation
        handed over early, and the layers' descent from c0")."""
        from .relax import RelaxSettings, relax_bundle

        s = self.settings
        self.at_scale(1.0)
        self.store.saved = self.start
        floor = s.bundle_relax_within * self.tolerance_N
        target = max(s.bundle_relax_handover * self.tolerance_N, floor)
        steps = restarts = 0
        cpu = 0.0
        notes = []
        while True:
            self.store.saved = self.start
            self.store.restore_as_initial()
            left = s.time_limit_s - (time.process_time() - self._cpu_start)
            stall = RelaxSettings.stall_steps
            if self.fallback:
                stall = min(stall, max(s.bundle_start_stall_steps,
                                       int(s.bundle_start_stall_work / self.model.ode2_index.size)))
            out = relax_bundle(self.model, RelaxSettings(residual_N=target, max_steps=max(s.bundle_relax_steps - steps, 1),
                                                         time_limit_s=max(left, 1e-3), stall_steps=stall),
                               masses=s.bundle_relax_masses)
            steps, restarts, cpu = steps + out.steps, restarts + out.restarts, cpu + out.cpu_s
            self.relaxation = replace(out, steps=steps, restarts=restarts, cpu_s=cpu)
            self.store.save()
            self.start = self.store.saved
            note = (f"{why}; then dynamic relaxation: {steps} steps, {restarts} restarts, residual "
                    f"{out.residual_N:.3g} N ({out.message})")
            if self.out_of_time() or (self.fallback and not out.converged):
                # a start that another follows gives up where its relaxation stalled
                return False, note
            ok, message = self.relax_one_iteration(1.0)
            if ok:
                return True, note
            notes.append(f"from {out.residual_N:.3g} N: {message}")
            if not out.converged or target <= floor or steps >= s.bundle_relax_steps or self.timed_out:
                return False, f"{note}; the continuation " + "; ".join(notes)
            target = max(target / s.bundle_relax_handover_fall, floor)

    def sweep_cables(self) -> None:
        """Several cables: block Gauss–Seidel by cable (:func:`exucable.solve.block_sweeps.block_sweeps`)
        from the start at full load, at most ``bundle_block_sweeps`` sweeps, to ``bundle_relax_within``
        stop tolerances; its best state becomes the start of every phase after (:attr:`sweeps` holds
        the outcome)."""
        from .block_sweeps import BlockSweepSettings, block_sweeps

        s = self.settings
        self.at_scale(1.0)
        self.store.saved = self.start
        self.store.restore_as_initial()
        left = s.time_limit_s - (time.process_time() - self._cpu_start)
        model = self.model
        out = block_sweeps(model, self.start[0][model.ode2_index], self.c0,
                           BlockSweepSettings(residual_N=s.bundle_relax_within * self.tolerance_N,
                                              max_sweeps=s.bundle_block_sweeps, time_limit_s=max(left, 1e-3),
                                              coarse_steps=s.bundle_block_coarse_steps))
        self.sweeps = out
        sd = self.mbs.systemData
        ode2 = np.array(self.start[0])
        ode2[model.ode2_index] = out.q
        for cfg in (exu.ConfigurationType.Initial, exu.ConfigurationType.Current):
            sd.SetODE2Coordinates(ode2, configuration=cfg)
        self.store.save()
        self.start = self.store.saved

    def shorten_step(self, residual_N: float, limit_N: float) -> float:
        """Go back along the one-iteration step just made (its true residual ``residual_N`` above
        ``limit_N`` [N]), halving its length up to ``max_backtracks`` times, until the true residual
        is within ``limit_N``: the residual [N] at the state left there (still above ``limit_N`` when
        no length was within it: the step is then rejected). Each length costs one force evaluation
        (:attr:`backtracks`), no Newton iteration; a static solver that cannot evaluate a state on
        its own (Exudyn's) leaves the step as it is."""
        evaluate = getattr(self.static, "evaluate_at", None)
        if evaluate is None:
            return residual_N
        q_end = np.array(self.mbs.systemData.GetODE2Coordinates())
        q_start = self.store.saved[0]
        alpha, residual = 1.0, residual_N
        for _ in range(self.settings.max_backtracks):
            alpha *= 0.5
            evaluate(q_start + alpha * (q_end - q_start))
            self.backtracks += 1
            residual = self.true_residual()
            if residual <= limit_N:
                break
        return residual

    def relax(self, lam: float) -> tuple[bool, str]:
        """Pseudo-time steps (inexact far from the steady state, exact near it) at load scale
        ``lam`` [-] from the stored state until the equilibrium residual is below the tolerance:
        converged?, and why not."""
        self.at_scale(lam)
        s = self.settings
        c = self.c0
        self.spring.axial_share = s.axial_share
        message = ""
        best, stalled = np.inf, 0
        stuck = _FailedSteps()
        exact = s.inexact_newton_tolerance <= s.newton_tolerance   # only the stopping step need be exact
        for _ in range(s.max_pseudo_steps_total):
            if self.out_of_time():
                return False, f"stopped at `{TIME_LIMIT_KEY}`"
            if stalled >= s.max_pseudo_steps:
                return False, (f"no equilibrium at load scale {lam:.3g}: the residual did not halve in "
                               f"{s.max_pseudo_steps} pseudo-time steps (smallest {best:.3g} N, stop at "
                               f"{self.tolerance_N:.3g} N)")
            stalled += 1
            ok, message, leftover = self.pseudo_step(c, exact)
            if not ok:
                stuck.record(exact, leftover)
                c = self.stiffen(c)
                if c > 1e6 * self.c0:
                    return False, stuck.why(message, lam, best, self.tolerance_N, self.exact_settings)
                continue
            q_now = _cable_part(self.model, np.array(self.mbs.systemData.GetODE2Coordinates()))
            # the equilibrium residual is at most the spring's force plus what Newton left over
            residual = float(np.linalg.norm(self.spring.force(q_now))) + (leftover if exact else 0.0)
            self.store.save()
            self.record(lam, residual)
            if residual <= self.tolerance_N:
                if exact:
                    return True, ""
                # an inexact step's spring force is not yet the whole residual: confirm with a
                # step at the same rate whose Newton problem is solved to newton_tolerance
                exact = True
                continue
            if residual <= 0.5 * best:
                best, stalled = residual, 0
            # near the steady state the steps are exact: the one that stops must be, and an exact
            # solve from a loosely converged state near grazing contact may fail (2-cycle)
            exact = exact or residual <= s.exact_within * self.tolerance_N
            c /= 4.0
            self.spring.axial_share *= s.axial_release
        return False, (f"no equilibrium at load scale {lam:.3g} after {s.max_pseudo_steps_total} pseudo-time "
                       f"steps (smallest residual {best:.3g} N, stop at {self.tolerance_N:.3g} N)")

    def ramp_loads(self, first_message: str, friction_only: bool = False) -> tuple[str, str]:
        """Continuation in the load scale λ (friction, gravity, end forces) from the start, each
        stage solved by :meth:`relax`, the increment doubled after a success and halved after a
        failure: status ("ok" or "failed") and message.

        ``friction_only`` (a bundle's first ramp): the friction alone is ramped, gravity and the end
        forces kept, from the best state reached (:meth:`restart_state`): without gravity and end
        forces several cables in a duct float, their equilibrium is singular, and a ramp from
        λ = 0 stalled there (one 90° bend at 4000 N back tension)."""
        self.friction_only = friction_only
        self.store.saved = self.restart_state() if friction_only else self.start
        lam, step, stages = 0.0, 0.5, 0
        if self.timed_out:
            return "failed", (f"no steady state found: stopped at `{TIME_LIMIT_KEY}` = {self.settings.time_limit_s:g} s "
                              f"CPU (at full load: {first_message}); {self.advice(lam)}")
        while lam < 1.0:
            target = min(1.0, lam + step)
            before = self.store.saved
            ok, msg = self.relax(target)
            stages += 1
            if ok:
                lam = target
                step = min(2.0 * step, 1.0)
            else:
                self.store.saved = before
                step *= 0.5
                if step < self.settings.min_continuation_step or self.timed_out:
                    return "failed", (f"no steady state found: continuation stalled at load scale {lam:.4g} "
                                      f"(at full load: {first_message}; last: {msg}); {self.advice(lam)}")
        return "ok", (f"continuation in the load scale, {stages} stages, {self.accepted} pseudo-time steps "
                      f"(at full load from the start: {first_message})")

    def solve(self) -> SolveOutcome:
        """Solve for the steady sliding state: one-iteration steps at the full loads from the start,
        then (if they do not converge) the exact-step continuation, then the load ramp.

        The history has one row per accepted pseudo-time step; its ``time_s`` column holds the
        step's number [-] (not a time: a static solve has none). Never raises for a diverging
        solve: the outcome has ``status == "failed"`` and the message.
        """
        if self._solved:
            raise SolverError("SteadySolver.solve() runs once: build a new SteadySolver for another solve")
        self._solved = True
        t_wall = time.perf_counter()
        model = self.model
        status, message = "ok", ""
        outside_at_start = _outside_points(model)
        if self.onset is not None:
            self.onset.begin(model)
        ok, warm_note, started_from, gave_up = False, "", "rope", False
        if self.warm_start is not None:
            ok, why = self.relax_warm()
            if ok:
                started_from = "coarse mesh"
            else:
                warm_note = f" (from the coarse mesh's state: {why}; again from the rope start)"
                self.forget_history()
        if not ok:
            if (self.bundle and self.settings.bundle_block_sweeps and not self.timed_out
                    and model.steady_force_supported):
                self.sweep_cables()
            self.store.saved = self.start
            ok, first_message = self.relax_one_iteration(1.0)
            if (not ok and self.bundle and self.settings.bundle_relax_steps and not self.timed_out
                    and model.steady_force_supported):
                ok, first_message = self.relax_dynamic(first_message)
                if not ok and self.settings.bundle_curvature_rounds and not self.timed_out:
                    ok, self.curvature_note = curvature_phase(self, self.settings.bundle_curvature_rounds)
            gave_up = not ok and self.fallback and self.relaxation is not None
            if not ok and not self.timed_out and not gave_up:
                self.store.saved = self.start
                ok, first_message = self.relax(1.0)
                if not ok and self.relaxation is not None:
                    r = self.relaxation
                    first_message += (f" (from the state of a dynamic relaxation: {r.steps} steps, {r.cpu_s:.3g} s "
                                      f"CPU, residual {r.residual_N:.3g} N: {r.message})")
                if not ok and self.curvature_note:
                    first_message += f" (before it, {self.curvature_note})"
            first_message += warm_note
            if self.sweeps is not None:
                b = self.sweeps
                first_message = (f"from the state of {b.sweeps} block sweeps by cable ({b.cpu_s:.3g} s CPU, "
                                 f"residual {b.residual_N:.3g} N: {b.message}): {first_message}")
        if ok:
            message = (f"{self.accepted} pseudo-time steps from the coarse mesh's state" if started_from != "rope"
                       else f"{self.accepted} pseudo-time steps{warm_note}")
            if self.sweeps is not None:
                message += f" ({first_message.split('): ')[0]})"
            if self.relaxation is not None:
                r = self.relaxation
                message += (f" (after the one-iteration steps from the rope start failed, from the state of a "
                            f"dynamic relaxation: {r.steps} steps, {r.cpu_s:.3g} s CPU, residual {r.residual_N:.3g} N)")
        elif gave_up:
            # another start follows: the slower phases are left to the last one (SteadySolver's fallback)
            status, message = "failed", f"given up for the next start: {first_message}"
        else:
            status, message = self.ramp_loads(first_message)
            if status != "ok" and self.bundle and not self.timed_out:
                # the loads' ramp stalled: the friction's alone, from the best state reached
                status, message = self.ramp_loads(first_message, friction_only=True)
        if status == "ok" and self.onset is not None:
            status, message = self.onset.descend(self, message)
        self.store.restore_as_initial()
        self.spring.rate = 0.0
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
        if self.progress is not None:
            self.progress.close()
        return SolveOutcome(history=self.history, status=status, message=message, end_time_s=0.0,
                            steps=self.steps, newton_iterations=self.newton_iterations,
                            jacobian_updates=self.jacobian_updates, wall_time_s=wall, started_from=started_from,
                            static_solver=self.static.name, backtracks=self.backtracks,
                            onset_layer=self.onset.summary() if self.onset is not None else None)

    def restart_state(self):
        """The state the friction's ramp starts from: for a bundle the accepted state of smallest
        true residual so far (a bundle's start is far from its equilibrium across the duct, and the
        steps' progress from it is worth keeping), else the start."""
        if self.bundle and self.best[1] is not None:
            return self.best[1]
        return self.start

    def relax_warm(self) -> tuple[bool, str]:
        """The one-iteration continuation at the full loads from :attr:`warm_start`, its first
        ``warm_start_skipped_steps`` skipped, within ``max_warm_start_steps``: converged?, and why not."""
        s = self.settings
        ode2, ae = self.warm_start
        self.store.saved = (np.asarray(ode2, dtype=float), np.asarray(ae, dtype=float), None)
        return self.relax_one_iteration(1.0, skip=s.warm_start_skipped_steps, max_steps=s.max_warm_start_steps)

    def forget_history(self) -> None:
        """Drop the accepted steps' rows (a warm start given up): the history is of the start that
        converged; the counts of steps and Newton iterations keep every attempt."""
        self.history = History()
        self.accepted = 0
        self._trace_lam, self._trace = 0.0, []


def solve_steady(model, progress: Progress | None = None, tolerance: float | None = None,
                 settings: SteadySettings | None = None, warm_start: tuple | None = None) -> SolveOutcome:
    """Solve ``model`` (built with ``solver.mode = "steady"``) for its steady sliding state:
    ``SteadySolver(model, settings, progress).solve()``.

    ``tolerance`` [-]: the stop residual relative to the rope solution's largest tension
    (:attr:`SteadySettings.steady_residual`, the scenario's ``[solver] steady_residual``; a tighter
    one shows how converged the pulling force is, ``benchmarks/steady_scale.py --tolerance-check``);
    given, it replaces that of ``settings`` (default :class:`SteadySettings`). ``warm_start``: a
    state near the steady state to start from, the rope start the fallback (:class:`SteadySolver`).
    Several cables are solved through a smooth contact onset continued to the law without it
    (:mod:`exucable.solve.onset_continuation`, :class:`OnsetSettings`' defaults), from the model's own
    start only: ``settings.bundle_starts`` in turn is :func:`exucable.solve.bundle_starts.solve_bundle_starts`.
    """
    settings = SteadySettings() if settings is None else settings
    if tolerance is not None:
        settings = replace(settings, steady_residual=float(tolerance))
    onset = OnsetSettings() if getattr(model, "n_cables", 1) > 1 else None
    return SteadySolver(model, settings, progress, warm_start=warm_start, onset=onset).solve()


#: What to change when a steady solve ends in a state that is not the steady pull.
BALANCE_FIX = ('fix: the rule\'s mesh (omit `cable.element_length`/`cable.elements`) or the dynamic run '
               '(`solver.mode = "dynamic"` with `solver.start_from = "steady"`)')


def _check_balance(model, message: str) -> tuple[str, str]:
    """``("failed", why)`` when the solved state is not a steady pull (:mod:`exucable.post.balance`),
    else ``("ok", message)``: a residual below the stop tolerance alone does not prove it."""
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
