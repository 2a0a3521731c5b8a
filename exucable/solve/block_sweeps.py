"""Several cables' steady state by nonlinear block Gauss–Seidel: one cable at a time, the others frozen.

The bundle's coupled Newton stalls on collective modes (a cable resting on two others, a soft
sideways mode at an up-bend; reference/README.md, "Three cables through an up-bend"), while one
cable's steady solve in a conduit is robust. So sweep over the cables and solve each one's steady
equilibrium with the others held where they are,

    f_i(q_i; q_j≠i) = 0,   i = 1 … n in turn,                                              (GS 1)

f_i the rows of cable i of the bundle's residual (:meth:`exucable.model.bundle.BundleModel.steady_force`:
its wall contact with friction, elastic forces, weight, end loads, and the other cables' contact on
it, those cables frozen as obstacles), the eye's rows held (:meth:`~exucable.model.bundle.BundleModel.held_coordinates`).
Each cable's problem is solved by the steady solve's pseudo-transient continuation on its own
coordinates (Kelley & Keyes 1998; the spring of :class:`exucable.solve.steady.PseudoTimeSpring`):

    (K_ii + c M P) Δq_i = f_i,   q_i ← q_i + ω Δq_i,                                       (GS 2)

K_ii = −∂f_i/∂q_i (the cable's wall and elastic stiffness, :meth:`~exucable.model.coupling.ContactCoupling.stiffness_values`,
plus the diagonal block of the pair kernel's Jacobian: the contact with the others' coordinates
fixed), M the lumped nodal masses (:func:`node_block_masses`), P = I − (1 − a) t tᵀ the spring's
axial share a along the node's tangent t, c its rate, ω the under-relaxation. A step whose block
residual grows more than twofold over the block's best is undone and retried with 4c (the axial
share × 4, at most 1); an accepted one divides c by 8 and a by 4, as the one-iteration steps of the
coupled solve do. After each sweep the coupled residual |f| is taken on every free coordinate; the
sweeps stop when it is below ``residual_N`` or stops halving.

A coarse correction (two-level, as in additive Schwarz methods) may follow each sweep: Galerkin
pseudo-time Newton steps on the subspace P of the bundle's cross-section moving rigidly, node index by
node index (every cable's node k translated across the mean tangent and turned about it, positions
and slopes alike; :func:`_coarse_basis`),

    (Pᵀ (K + c M P_a) P) δ = Pᵀ f,   q ← q + P δ,                                         (GS 3)

K the whole bundle's stiffness, kept only where it lowers the coupled residual.

What this can and cannot do: the block solve removes each cable's own misfit (its axial strain, its
wall contact, its weight) at the cost of one cable's Newton system; the coupling between the cables
is only relaxed sweep by sweep. A collective mode (two cables side by side on the wall pushing each
other along it) has a Gauss–Seidel rate near 1 − K_soft/K_contact, i.e. no progress, and a cable on
frozen obstacles may sit on an unstable balance (K_ii indefinite). The coarse correction removes
the first in a straight duct (``tests/test_block_sweeps.py``), not on the 100 m route: measured in
reference/README.md, "Block Gauss–Seidel by cable: where it stalls".
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import splu

from ..errors import SolverError
from .relax import check_settings

__all__ = ["BlockSweepSettings", "BlockSweepOutcome", "node_block_masses", "sweep_order", "block_sweeps"]


@dataclass(frozen=True)
class BlockSweepSettings:
    """How :func:`block_sweeps` sweeps and when it stops.

    Attributes
    ----------
    residual_N : float
        Stop once the coupled residual |f| on the free coordinates is at most this [N].
    max_sweeps : int
        Sweeps over all cables at most [-].
    block_iterations : int
        Pseudo-time Newton steps (accepted and rejected) per cable and sweep at most [-].
    block_reduction : float
        A cable's solve in a sweep stops once its residual is this share of what it was at the
        sweep's turn (or below ``residual_N``/√n) [-]: a sweep need not solve a cable against
        obstacles that move next.
    relaxation : float
        ω of Eq. (GS 2) [-], in (0, 1]: the share of each Newton update taken.
    first_rate : float
        The spring rate of a cable's first step in the first sweep, in units of c0 (the element's
        axial stiffness per mass, :func:`exucable.solve.steady.initial_spring_rate`) [-].
    later_rate : float
        The same in the later sweeps [-] (the state is then near each cable's equilibrium).
    later_axial_share : float
        The spring's axial share a at the first step of a cable in the later sweeps [-] (1 in the first).
    stall_sweeps : int
        Sweeps without the coupled residual halving after which the sweeps stop [-].
    time_limit_s : float
        CPU time [s] at most.
    order : str
        ``"bottom_first"``: the cables in the order of their start height in the arrangement
        (lowest first: those on the wall, then those resting on them); ``"index"``: as numbered.
    coarse_steps : int
        After each sweep, pseudo-time Newton steps of the coarse correction (Eq. GS 3: the bundle's
        cross-section moved rigidly, node index by node index) at most [-]; 0: none.
    """

    residual_N: float = 1e-2
    max_sweeps: int = 8
    block_iterations: int = 20
    block_reduction: float = 1e-3
    relaxation: float = 1.0
    first_rate: float = 1.0
    later_rate: float = 1.0 / 64.0
    later_axial_share: float = 0.01
    stall_sweeps: int = 3
    time_limit_s: float = 60.0
    order: str = "bottom_first"
    coarse_steps: int = 0

    def __post_init__(self):
        if self.order not in ("bottom_first", "index"):
            raise SolverError(f"BlockSweepSettings.order = {self.order!r}: must be 'bottom_first' or 'index'")
        check_settings(self, skip=("order",))
        if self.relaxation > 1.0:
            raise SolverError(f"BlockSweepSettings.relaxation = {self.relaxation!r}: must be in (0, 1]")
        if self.later_axial_share > 1.0:
            raise SolverError(f"BlockSweepSettings.later_axial_share = {self.later_axial_share!r}: must be in (0, 1]")


@dataclass
class BlockSweepOutcome:
    """What :func:`block_sweeps` reached.

    Attributes
    ----------
    q : ndarray
        The state of smallest coupled residual met (the cables' displacement coordinates) [m, -].
    residual_N : float
        Its coupled residual norm on the free coordinates [N].
    cable_residual_N : ndarray (n_cables,)
        Each cable's share of it [N].
    converged : bool
        ``residual_N`` is at most the settings' ``residual_N``.
    message : str
        Why the sweeps stopped.
    sweeps : int
        Sweeps made [-].
    block_steps : int
        Pseudo-time Newton steps over all cables, rejected ones included (each one force and
        Jacobian evaluation of the bundle's residual), the coarse correction's included [-].
    cpu_s : float
        CPU time [s].
    trace : list of dict
        Per sweep: ``sweep``, ``residual_N`` (coupled, after it), ``cable_residual_N`` (list), and per
        cable ``blocks`` as (cable, residual before [N], after [N], steps); cable −1: the coarse
        correction, with the coupled residual before and after.
    """

    q: np.ndarray
    residual_N: float
    cable_residual_N: np.ndarray
    converged: bool
    message: str
    sweeps: int
    block_steps: int
    cpu_s: float
    trace: list = field(default_factory=list)


def node_block_masses(model) -> np.ndarray:
    """Lumped masses of each node's two 3-blocks (positions [kg], slopes [kg·m²]) of every cable,
    shape (n_nodes, 2): m_k = ρA (L_{k−1} + L_k)/2 and m_k L_k² with L_k the longer adjoining
    element (the pseudo-time spring's weights, :class:`exucable.solve.steady.PseudoTimeSpring`).
    Several cables meshed alike (:mod:`exucable.model.bundle`): their nodes one cable after another."""
    Le = np.asarray(model.layout.element_length_m, dtype=float)
    rho_a = model.properties.mass_per_length_kg_per_m
    m_node = rho_a * (np.concatenate([Le, [0.0]]) + np.concatenate([[0.0], Le])) / 2
    L_node = np.maximum(np.concatenate([Le, [0.0]]), np.concatenate([[0.0], Le]))
    cables = getattr(model.layout, "n_cables", 1)
    m_node, L_node = np.tile(m_node, cables), np.tile(L_node, cables)
    return np.stack([m_node, m_node * L_node**2], axis=1)


def sweep_order(model, order: str) -> list[int]:
    """The cables' order in a sweep (:attr:`BlockSweepSettings.order`): by the arrangement's start
    height (``model.offsets_m``' second column, lowest first; ties by index), or by index."""
    n = model.n_cables
    if order == "index":
        return list(range(n))
    return [int(i) for i in np.lexsort((np.arange(n), np.round(np.asarray(model.offsets_m)[:, 1], 12)))]


class _CableBlocks:
    """The bundle's residual and each cable's diagonal stiffness block at a state (Eqs. GS 1-2)."""

    def __init__(self, model):
        self.model = model
        self.n1 = model.walls[0].n_coordinates
        self.n = model.ode2_index.size
        self.free = np.ones(self.n, dtype=bool)
        self.free[model.held_coordinates()] = False
        self.q_ref = model.layout.coordinates.reshape(-1)
        mass = node_block_masses(model)                     # (nodes, 2)
        self.mass3 = np.repeat(mass.reshape(-1), 3).reshape(-1, 3)     # per 3-block, per coordinate
        self.evaluations = 0

    def rows(self, i: int) -> slice:
        return slice(i * self.n1, (i + 1) * self.n1)

    def force(self, q, jacobian: bool = False):
        """The bundle's residual f(q) [N, N·m] and, with ``jacobian``, the pair kernel's result there."""
        m = self.model
        between = m.between.evaluate(self.q_ref + q, jacobian=jacobian)
        self.evaluations += 1
        return m.steady_force(q, between=between), between

    def residuals(self, f) -> np.ndarray:
        """Each cable's residual norm on its free rows [N]."""
        return np.array([np.linalg.norm(f[self.rows(i)][self.free[self.rows(i)]]) for i in range(self.model.n_cables)])

    def stiffness(self, q, i: int, between) -> sparse.csr_matrix:
        """K_ii = −∂f_i/∂q_i of cable ``i`` at ``q``: its wall coupling's (contact, elastic forces)
        and the pair kernel's diagonal block (the others frozen)."""
        sl = self.rows(i)
        coupling = self.model.wall_couplings[i]
        indptr, indices = coupling.chain_pattern_csr()
        K = sparse.csr_matrix((coupling.stiffness_values(q[sl], 1.0).copy(), indices, indptr), shape=(self.n1, self.n1))
        return K - between.jacobian[sl, sl]

    def spring(self, q, i: int, share: float) -> sparse.bsr_matrix:
        """M P of Eq. (GS 2) on cable ``i``'s coordinates: per node block m (I − (1 − a) t tᵀ)."""
        qa = (self.q_ref + q)[self.rows(i)].reshape(-1, 6)
        t = qa[:, 3:] / np.linalg.norm(qa[:, 3:], axis=1, keepdims=True)
        P = np.eye(3)[None] - (1.0 - share) * t[:, :, None] * t[:, None, :]
        nodes = len(qa)
        blocks = np.repeat(P, 2, axis=0) * self.mass3[2 * i * nodes:2 * (i + 1) * nodes][:, :, None]
        k = np.arange(2 * nodes)
        return sparse.bsr_matrix((blocks, k, np.arange(2 * nodes + 1)), shape=(self.n1, self.n1))


def _solve_cable(blocks: _CableBlocks, q, f, between, i: int, c: float, share: float, target_N: float,
                 settings: BlockSweepSettings, deadline: float):
    """Cable ``i``'s pseudo-time continuation (Eq. GS 2) from ``q`` (residual ``f``, pair result
    ``between`` there) until its residual is at most ``target_N`` [N]: the state, its residual and
    pair result, and the steps made."""
    sl = blocks.rows(i)
    fr = blocks.free[sl]
    r = best = float(np.linalg.norm(f[sl][fr]))
    steps = 0
    K = blocks.stiffness(q, i, between)
    while r > target_N and steps < settings.block_iterations and time.process_time() < deadline:
        steps += 1
        A = (K + c * blocks.spring(q, i, share)).tocsc()[fr][:, fr]
        try:
            d = splu(A.tocsc()).solve(f[sl][fr])
        except RuntimeError:          # a singular block at this rate: a stiffer spring
            c, share = 4.0 * c, min(1.0, 4.0 * share)
            continue
        q_new = q.copy()
        q_new[np.arange(sl.start, sl.stop)[fr]] += settings.relaxation * d
        f_new, between_new = blocks.force(q_new, jacobian=True)
        r_new = float(np.linalg.norm(f_new[sl][fr]))
        if not np.isfinite(r_new) or r_new > 2.0 * best:
            c, share = 4.0 * c, min(1.0, 4.0 * share)
            continue
        q, f, between, r = q_new, f_new, between_new, r_new
        best = min(best, r)
        K = blocks.stiffness(q, i, between)
        c, share = c / 8.0, share / 4.0
    return q, f, between, steps


def _coarse_basis(blocks: _CableBlocks, q) -> sparse.csr_matrix:
    """P of Eq. (GS 3): per node index k, six coarse unknowns moving every cable's node k alike, the
    positions by (a₁ e₁ + a₂ e₂ + θ t × r_c) and the slopes by (b₁ e₁ + b₂ e₂ + φ t × r_c), t the
    cables' mean tangent there, e₁, e₂ across it, r_c the cable's position from the cables' centroid
    [m]; the eye's held rows left out."""
    m = blocks.model
    nc = m.n_cables
    qa = (blocks.q_ref + q).reshape(nc, -1, 6)
    nodes = qa.shape[1]
    t = qa[:, :, 3:].mean(axis=0)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    helper = np.where(np.abs(t[:, 2:3]) < 0.9, np.array([[0.0, 0.0, 1.0]]), np.array([[1.0, 0.0, 0.0]]))
    e1 = np.cross(t, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(t, e1)
    r = qa[:, :, :3] - qa[:, :, :3].mean(axis=0)[None]
    spin = np.cross(t[None], r)                                        # (nc, nodes, 3)
    cols3 = np.stack([e1, e2], axis=2)                                  # (nodes, 3, 2)
    rows, cols, vals = [], [], []
    for c in range(nc):
        for part in (0, 1):                                             # positions, slopes
            row = c * blocks.n1 + 6 * np.arange(nodes)[:, None] + 3 * part + np.arange(3)[None, :]   # (nodes, 3)
            B = np.concatenate([cols3, spin[c][:, :, None]], axis=2)    # (nodes, 3, 3)
            col = 6 * np.arange(nodes)[:, None] + 3 * part + np.arange(3)[None, :]
            rows.append(np.broadcast_to(row[:, :, None], B.shape).reshape(-1))
            cols.append(np.broadcast_to(col[:, None, :], B.shape).reshape(-1))
            vals.append(B.reshape(-1))
    rows, cols, vals = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    keep = blocks.free[rows]
    return sparse.csr_matrix((vals[keep], (rows[keep], cols[keep])), shape=(blocks.n, 6 * nodes))


def _coupled_stiffness(blocks: _CableBlocks, q) -> sparse.csr_matrix:
    """The bundle's whole stiffness K = −∂f/∂q at ``q`` (:meth:`~exucable.model.bundle.BundleModel.stiffness_blocks3`)."""
    rows, cols, B = blocks.model.stiffness_blocks3(q)
    i3 = np.arange(3)
    r = np.broadcast_to((3 * rows)[:, None, None] + i3[None, :, None], B.shape).reshape(-1)
    c = np.broadcast_to((3 * cols)[:, None, None] + i3[None, None, :], B.shape).reshape(-1)
    return sparse.coo_matrix((B.reshape(-1), (r, c)), shape=(blocks.n, blocks.n)).tocsr()


def _coarse_correction(blocks: _CableBlocks, q, f, c: float, share: float, settings: BlockSweepSettings, deadline: float):
    """Pseudo-time Newton steps on the coarse space (Eq. GS 3),
    (Pᵀ (K + c M P_a) P) δ = Pᵀ f, q ← q + P δ, accepted where it lowers the coupled residual: the state, its residual and pair result, the rate reached and the steps made."""
    r = float(np.linalg.norm(f[blocks.free]))
    between = None
    steps = 0
    while steps < settings.coarse_steps and time.process_time() < deadline:
        steps += 1
        P = _coarse_basis(blocks, q)
        spring = sparse.block_diag([blocks.spring(q, i, share) for i in range(blocks.model.n_cables)], format="csr")
        A = (P.T @ ((_coupled_stiffness(blocks, q) + c * spring) @ P)).toarray()
        g = P.T @ f
        try:
            d = np.linalg.solve(A + 1e-12 * np.abs(np.diag(A)).max() * np.eye(len(A)), g)
        except np.linalg.LinAlgError:
            c, share = 4.0 * c, min(1.0, 4.0 * share)
            continue
        q_new = q + P @ d
        f_new, between_new = blocks.force(q_new, jacobian=True)
        r_new = float(np.linalg.norm(f_new[blocks.free]))
        # only a step that lowers the coupled residual: the sweep before was a descent already,
        # and on the 100 m route steps within twice the best undid it (73.7 → 131 N)
        if not np.isfinite(r_new) or r_new >= r:
            c, share = 4.0 * c, min(1.0, 4.0 * share)
            continue
        q, f, between, r = q_new, f_new, between_new, r_new
        c, share = c / 8.0, share / 4.0
    if between is None:
        f, between = blocks.force(q, jacobian=True)
    return q, f, between, c, share, steps


def block_sweeps(model, q0, c0: float, settings: BlockSweepSettings = BlockSweepSettings()) -> BlockSweepOutcome:
    """Nonlinear block Gauss–Seidel by cable (the module's Eqs. GS 1-2) on a steady bundle model
    (:class:`exucable.model.bundle.BundleModel`, compiled cable element) at its current load scale
    and contact law, from the cables' displacement coordinates ``q0`` (:attr:`~exucable.model.bundle.BundleModel.ode2_index`'s
    order), the eye's coordinates held.

    Parameters
    ----------
    model : BundleModel
    q0 : array_like
        The start [m, -].
    c0 : float
        The spring rate unit [1/s²] (:func:`exucable.solve.steady.initial_spring_rate`).
    settings : BlockSweepSettings

    Returns
    -------
    BlockSweepOutcome
        The state of smallest coupled residual, not written into the model.
    """
    s = settings
    t0 = time.process_time()
    deadline = t0 + s.time_limit_s
    blocks = _CableBlocks(model)
    q = np.array(q0, dtype=float)
    if q.size != blocks.n:
        raise SolverError(f"block_sweeps: {q.size} coordinates given, the bundle has {blocks.n}")
    order = sweep_order(model, s.order)
    f, between = blocks.force(q, jacobian=True)
    per = blocks.residuals(f)
    r = best = halved = float(np.linalg.norm(f[blocks.free]))
    best_q, best_per = q.copy(), per
    trace = [{"sweep": 0, "residual_N": r, "cable_residual_N": per.tolist(), "blocks": []}]
    steps = sweeps = since_halved = 0
    n = model.n_cables
    message = ""
    coarse_c, coarse_share = s.later_rate * c0, s.later_axial_share
    while True:
        if r <= s.residual_N:
            message = f"coupled residual {r:.3g} N after {sweeps} sweeps"
            break
        if sweeps >= s.max_sweeps:
            message = f"{s.max_sweeps} sweeps (smallest coupled residual {best:.3g} N)"
            break
        if since_halved >= s.stall_sweeps:
            message = f"the coupled residual did not halve in {s.stall_sweeps} sweeps (smallest {best:.3g} N)"
            break
        if time.process_time() >= deadline:
            message = f"the CPU time limit of {s.time_limit_s:g} s (smallest coupled residual {best:.3g} N)"
            break
        rate, share = (s.first_rate, 1.0) if sweeps == 0 else (s.later_rate, s.later_axial_share)
        done = []
        for i in order:
            before = float(blocks.residuals(f)[i])
            target = max(s.block_reduction * before, s.residual_N / np.sqrt(n))
            q, f, between, k = _solve_cable(blocks, q, f, between, i, rate * c0, share, target, s, deadline)
            steps += k
            done.append((i, before, float(blocks.residuals(f)[i]), k))
        if s.coarse_steps:
            before = float(np.linalg.norm(f[blocks.free]))
            q, f, between, coarse_c, coarse_share, k = _coarse_correction(blocks, q, f, coarse_c, coarse_share, s, deadline)
            steps += k
            done.append((-1, before, float(np.linalg.norm(f[blocks.free])), k))
        sweeps += 1
        per = blocks.residuals(f)
        r = float(np.linalg.norm(f[blocks.free]))
        trace.append({"sweep": sweeps, "residual_N": r, "cable_residual_N": per.tolist(), "blocks": done})
        if r < best:
            best, best_q, best_per = r, q.copy(), per
        since_halved += 1
        if r <= 0.5 * halved:
            halved, since_halved = r, 0
    return BlockSweepOutcome(q=best_q, residual_N=best, cable_residual_N=np.asarray(best_per), converged=best <= s.residual_N,
                             message=message, sweeps=sweeps, block_steps=steps, cpu_s=time.process_time() - t0,
                             trace=trace)
