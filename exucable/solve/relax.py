"""Dynamic relaxation: a static equilibrium f(q) = 0 found by a fictitious, damped explicit dynamics.

The steady solve's pseudo-time continuation (:mod:`exucable.solve.steady`) takes implicit steps, each
a Newton problem. Where several cables share a duct those steps stall (reference/README.md, "Three
cables through an up-bend: where the steady solve stalled"): a soft, sometimes unstable sideways mode of
a cable resting on others and grazing contacts that switch on and off keep each Newton update within
the contacts' micrometre scale. Dynamic relaxation (Day 1965; Underwood 1983, "Dynamic relaxation",
in *Computational Methods for Transient Analysis*, ch. 5; Barnes 1999, "Form finding and analysis of
tension structures by dynamic relaxation", Int J Space Struct 14:89-104) integrates instead

    M q̈ = f(q) − C q̇                                                                    (DR 1)

with the explicit central difference (leapfrog) at a unit step,

    v⁺ = v⁻ + M⁻¹ f(qₙ),   qₙ₊₁ = qₙ + v⁺,                                              (DR 2)

one evaluation of the residual f per step and no linear solve, until f is small. Like a physical
settle it leaves an unstable balance (a cable on another's crest falls into the valley) and it needs
no Newton convergence per step.

The fictitious masses: the central difference is stable at a unit step where every eigenvalue of
M⁻¹K is below 4 (K = −∂f/∂q). With M block diagonal, 3 × 3 blocks Mᵢ, the block Gershgorin bound

    Mᵢ = (α/4) Σⱼ ½ (|Kᵢⱼ| + |Kⱼᵢᵀ|),  |B| = (B Bᵀ)^½                                     (DR 3)

guarantees it for α ≥ 1 (xᵢᵀ B yⱼ ≤ ½ (xᵢᵀ |B| xᵢ + yⱼᵀ |Bᵀ| yⱼ), so xᵀ K x ≤ Σᵢ xᵢᵀ (4/α) Mᵢ xᵢ
for a symmetric K); :func:`block_gershgorin_masses`. Blocks rather than a scalar per coordinate
(Underwood's row sums, Eq. DR 3 on 1 × 1 blocks): a contact stiffens a node across the cable only, and
a scalar mass would load its stiffness onto the axial direction too, whose modes are then the slowest
of all (measured on the 100 m bundle route: the axial modes at eigenvalues of M⁻¹K near 2e-6 with
scalar masses). A contact that is open where the masses are taken has no stiffness in K; the caller
adds what it may reach (``masses`` of :func:`relax`). The masses are taken again every
``refresh_steps`` steps, keeping the momentum M v.

The damping: kinetic damping (Cundall 1976; Barnes 1999): the kinetic energy ½ vᵀ M v is tracked and
when it falls, its peak has passed; the velocities are zeroed there and the motion restarts from rest
at qₙ (the step that would go past the peak is not taken) with the half step v⁺ = ½ M⁻¹ f(qₙ).
Or viscous: C = c M, v⁺ = ((1 − c/2) v⁻ + M⁻¹ f)/(1 + c/2), with c near twice the smallest
frequency of M⁻¹K (critical damping of the slowest mode).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, fields

import numpy as np

from ..errors import SolverError

__all__ = ["check_settings", "RelaxSettings", "RelaxOutcome", "block_gershgorin_masses", "relax", "bundle_masses", "relax_bundle"]


def check_settings(settings, skip=()) -> None:
    """Refuse, naming the field, a settings dataclass's number that is not one: its ``int`` fields
    whole numbers >= 0, the others finite numbers > 0 (fields named in ``skip`` left out).

    Raises
    ------
    SolverError
    """
    name = type(settings).__name__
    for f in fields(settings):
        if f.name in skip:
            continue
        value = getattr(settings, f.name)
        if f.type == "int":
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
                raise SolverError(f"{name}.{f.name} = {value!r}: must be a whole number >= 0")
        elif isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)) \
                or not np.isfinite(value) or value <= 0:
            raise SolverError(f"{name}.{f.name} = {value!r}: must be a finite number > 0")


@dataclass(frozen=True)
class RelaxSettings:
    """How :func:`relax` steps and when it stops.

    Attributes
    ----------
    residual_N : float
        Stop once the free coordinates' residual norm |f| is at most this [N].
    mass_safety : float
        α of Eq. (DR 3) [-]: 1 is the bound itself; more is slower but tolerates the stiffness a
        contact gains between two mass updates.
    refresh_steps : int
        Steps between two mass updates (Eq. DR 3 at the current state) [-]; a kinetic-damping
        restart updates them too.
    damping : str
        ``"kinetic"`` or ``"viscous"`` (the module's notes).
    viscous_rate : float
        c of the viscous damping per unit step [-] (``damping = "viscous"``).
    max_steps : int
        Steps at most [-].
    stall_steps : int
        Steps without the smallest residual halving after which the relaxation stops [-].
    time_limit_s : float
        CPU time [s] at most.
    max_heavier : int
        Where the residual grows past any finite number (unstable: a contact closed stiffer than the
        masses covered), the relaxation goes back to the state of smallest residual and on from rest with
        masses twice as heavy, this many times at most before it stops [-]. Only the overflow counts: a
        residual growing 1e4-fold was a keystone falling into a cradle (tests/test_bundle_jam.py), no
        instability.
    """

    residual_N: float = 1e-2
    mass_safety: float = 1.2
    refresh_steps: int = 50
    damping: str = "kinetic"
    viscous_rate: float = 0.04
    max_steps: int = 100000
    stall_steps: int = 5000
    time_limit_s: float = 60.0
    max_heavier: int = 4

    def __post_init__(self):
        if self.damping not in ("kinetic", "viscous"):
            raise SolverError(f"RelaxSettings.damping = {self.damping!r}: must be 'kinetic' or 'viscous'")
        check_settings(self, skip=("damping",))
        if self.mass_safety < 1.0:
            raise SolverError(f"RelaxSettings.mass_safety = {self.mass_safety!r}: must be >= 1 (Eq. DR 3's bound)")


@dataclass
class RelaxOutcome:
    """What :func:`relax` reached.

    Attributes
    ----------
    q : ndarray
        The state of smallest residual met [the caller's units].
    residual_N : float
        Its free coordinates' residual norm [N].
    converged : bool
        ``residual_N`` is at most the settings' ``residual_N``.
    message : str
        Why it stopped.
    steps : int
        Steps taken (residual evaluations after the first) [-].
    restarts : int
        Kinetic-damping restarts [-].
    mass_updates : int
        Evaluations of the masses (stiffness passes) [-].
    mass_scale : float
        Factor on the masses at the end [-]: 2^k after k instabilities (``RelaxSettings.max_heavier``).
    cpu_s : float
        CPU time [s].
    trace : list of (int, float)
        (step, residual [N]) at every restart and every mass update: how it converged.
    """

    q: np.ndarray
    residual_N: float
    converged: bool
    message: str
    steps: int
    restarts: int
    mass_updates: int
    cpu_s: float
    mass_scale: float
    trace: list


def _abs_block(B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(B Bᵀ)^½ and (Bᵀ B)^½ of each 3 × 3 block of ``B`` (m, 3, 3), from its singular values:
    B = U S Vᵀ gives U S Uᵀ and V S Vᵀ."""
    U, S, Vt = np.linalg.svd(B)
    left = np.einsum("mij,mj,mkj->mik", U, S, U)
    right = np.einsum("mji,mj,mjk->mik", Vt, S, Vt)
    return left, right


def diagonal_gershgorin_masses(n_blocks: int, rows, cols, blocks, safety: float = 1.0) -> np.ndarray:
    """Underwood's masses, Eq. (DR 3) on 1 × 1 blocks: mₖ = (α/4) Σⱼ |Kₖⱼ| per coordinate, as
    diagonal 3 × 3 blocks (arguments as :func:`block_gershgorin_masses`)."""
    B = np.abs(np.asarray(blocks, dtype=float).reshape(-1, 3, 3)).sum(axis=2)
    m = np.zeros((n_blocks, 3))
    if len(B):
        np.add.at(m, np.asarray(rows, dtype=np.int64), B)
    M = np.zeros((n_blocks, 3, 3))
    M[:, np.arange(3), np.arange(3)] = (0.25 * safety) * m
    return M


def node_frames(slopes: np.ndarray) -> np.ndarray:
    """Orthonormal frames R = [t, n₁, n₂] (columns) of nodes with slope vectors ``slopes`` (m, 3):
    t the unit tangent, n₁ and n₂ across the cable."""
    t = slopes / np.linalg.norm(slopes, axis=1, keepdims=True)
    # n₁: the unit axis least aligned with t, made orthogonal to it
    e = np.eye(3)[np.argmin(np.abs(t), axis=1)]
    n1 = e - np.einsum("mi,mi->m", e, t)[:, None] * t
    n1 /= np.linalg.norm(n1, axis=1, keepdims=True)
    return np.stack([t, n1, np.cross(t, n1)], axis=2)


def frame_gershgorin_masses(n_blocks: int, rows, cols, blocks, frames: np.ndarray, safety: float = 1.0,
                            floor_across=None) -> np.ndarray:
    """Underwood's masses (Eq. DR 3 on 1 × 1 blocks) in each block's own frame Rᵢ (``frames``,
    (n_blocks, 3, 3), columns tangent and two normals): with K' = Rᵀ K R (R block diagonal,
    orthogonal) the row sums dᵢₖ = Σⱼₗ |K'ᵢⱼ,ₖₗ| bound K' as in Eq. (DR 3), and
    Mᵢ = (α/4) Rᵢ diag(dᵢ) Rᵢᵀ has M⁻¹K similar to diag(d)⁻¹K', so the same bound holds. In the
    cable's frame a contact's stiffness (across the cable) stays off the tangent, whose masses then
    carry the axial stiffness EA only: the axial modes are not slowed by the contacts. ``floor_across``
    (n_blocks,) is added on the two normals (what an open contact may add before the next update)
    [as the blocks' units]; other arguments as :func:`block_gershgorin_masses`."""
    B = np.asarray(blocks, dtype=float).reshape(-1, 3, 3)
    rows = np.asarray(rows, dtype=np.int64)
    cols = np.asarray(cols, dtype=np.int64)
    d = np.zeros((n_blocks, 3))
    if len(B):
        Bl = np.einsum("mki,mkl,mlj->mij", frames[rows], B, frames[cols])
        np.add.at(d, rows, np.abs(Bl).sum(axis=2))
    if floor_across is not None:
        d[:, 1:] += np.asarray(floor_across, dtype=float)[:, None]
    return (0.25 * safety) * np.einsum("bik,bk,bjk->bij", frames, d, frames)


def block_gershgorin_masses(n_blocks: int, rows, cols, blocks, safety: float = 1.0) -> np.ndarray:
    """Block masses of Eq. (DR 3) from the stiffness K = Σ blocks [N/m, or per the coordinates].

    Parameters
    ----------
    n_blocks : int
        Blocks of 3 coordinates [-].
    rows, cols : array_like of int, shape (m,)
        Each block's row and column block index; a pair may repeat (the blocks are summed as K's
        parts: each part's bound is added, which bounds their sum too).
    blocks : array_like, shape (m, 3, 3)
        The 3 × 3 blocks Kᵢⱼ.
    safety : float
        α [-].

    Returns
    -------
    ndarray, shape (n_blocks, 3, 3)
        Symmetric positive semi-definite Mᵢ.
    """
    B = np.asarray(blocks, dtype=float).reshape(-1, 3, 3)
    M = np.zeros((n_blocks, 3, 3))
    if len(B):
        left, right = _abs_block(B)
        np.add.at(M, np.asarray(rows, dtype=np.int64), 0.5 * left)
        np.add.at(M, np.asarray(cols, dtype=np.int64), 0.5 * right)
    return (0.25 * safety) * M


def _inverse(M: np.ndarray) -> np.ndarray:
    """Inverses of the mass blocks; a block without stiffness (all zero: nothing acts on it, or its
    coordinates are held) gets a zero inverse, so its coordinates do not move."""
    scale = np.maximum(np.abs(M).max(axis=(1, 2)), 1e-300)
    out = np.zeros_like(M)
    # each block scaled to unit size first: the blocks span many decades (slopes against positions)
    ok = np.linalg.cond(M / scale[:, None, None]) < 1e12
    out[ok] = np.linalg.inv(M[ok] / scale[ok, None, None]) / scale[ok, None, None]
    bad = np.flatnonzero(~ok)
    for i in bad:                   # a singular block (a direction without stiffness): its pseudo-inverse
        out[i] = np.linalg.pinv(M[i], rcond=1e-12)
    return out


def relax(force, masses, q0, free, settings: RelaxSettings = RelaxSettings()) -> RelaxOutcome:
    """Dynamic relaxation (the module's Eqs. DR 1-3) of the equilibrium ``force(q) = 0``.

    Parameters
    ----------
    force : callable
        ``force(q)`` → f, the resultant generalized force (right-hand side; equilibrium where it is 0)
        on every coordinate [N, or per the coordinates]; rows of held coordinates are ignored.
    masses : callable
        ``masses(q)`` → the block masses (n/3, 3, 3) at q (:func:`block_gershgorin_masses` of the
        stiffness −∂f/∂q there, with what a contact may add before the next update).
    q0 : array_like, shape (n,)
        The start, n a multiple of 3.
    free : array_like of bool, shape (n,)
        The coordinates that move; the others are held where ``q0`` has them.
    settings : RelaxSettings

    Returns
    -------
    RelaxOutcome
    """
    s = settings
    t0 = time.process_time()
    q = np.array(q0, dtype=float)
    n = q.size
    if n % 3:
        raise SolverError(f"relax: {n} coordinates are not blocks of 3")
    free = np.asarray(free, dtype=bool)
    fixed = ~free
    nb = n // 3

    def accelerate(Minv, f):
        a = np.einsum("bij,bj->bi", Minv, f.reshape(nb, 3)).reshape(-1)
        a[fixed] = 0.0
        return a

    def energy(M, v):
        vb = v.reshape(nb, 3)
        return 0.5 * float(np.einsum("bi,bij,bj->", vb, M, vb))

    f = np.asarray(force(q), dtype=float)
    r = float(np.linalg.norm(f[free]))
    mass_scale, heavier = 1.0, 0
    M = masses(q)
    Minv = _inverse(M)
    updates = 1
    v = np.zeros(n)
    ke_prev = 0.0
    restarts = steps = 0
    best_r, best_q, best_step = r, q.copy(), 0
    halved_r = r                   # the residual last halved to, and the step it was
    trace = [(0, r)]
    since_update = 0
    from_rest = True
    message = ""

    def restart():
        """The motion from rest at the current state, its masses taken there."""
        nonlocal v, M, Minv, ke_prev, from_rest, since_update, updates
        v = np.zeros(n)
        ke_prev, from_rest, since_update = 0.0, True, 0
        M = mass_scale * masses(q)
        Minv = _inverse(M)
        updates += 1
        trace.append((steps, r))
    while True:
        if r <= s.residual_N:
            message = f"residual {r:.3g} N after {steps} steps"
            break
        if not np.isfinite(r):
            # unstable: a contact closed stiffer than the masses cover (or a follower force's flutter);
            # back to the best state, from rest, with heavier masses
            if heavier >= s.max_heavier:
                message = (f"unstable after {steps} steps with the masses {mass_scale:g}x the bound's "
                           f"(smallest residual {best_r:.3g} N)")
                break
            heavier += 1
            mass_scale *= 2.0
            q = best_q.copy()
            f = np.asarray(force(q), dtype=float)
            r = float(np.linalg.norm(f[free]))
            restart()
            continue
        if steps >= s.max_steps:
            message = f"{s.max_steps} steps"
            break
        if steps - best_step >= s.stall_steps:
            message = f"the residual did not halve in {s.stall_steps} steps (smallest {best_r:.3g} N)"
            break
        if time.process_time() - t0 > s.time_limit_s:
            message = f"the CPU time limit of {s.time_limit_s:g} s (smallest residual {best_r:.3g} N)"
            break
        if since_update >= s.refresh_steps:
            M_new = mass_scale * masses(q)
            updates += 1
            # the momentum M v is kept across the update
            p = np.einsum("bij,bj->bi", M, v.reshape(nb, 3)).reshape(-1)
            M, Minv = M_new, _inverse(M_new)
            v = accelerate(Minv, p)
            ke_prev = energy(M, v)
            since_update = 0
            trace.append((steps, r))
        a = accelerate(Minv, f)
        if s.damping == "kinetic":
            v_new = 0.5 * a if from_rest else v + a
        else:
            c = s.viscous_rate
            v_new = ((1.0 - 0.5 * c) * v + a) / (1.0 + 0.5 * c)
        ke = energy(M, v_new)
        if s.damping == "kinetic" and ke < ke_prev and not from_rest:
            # the kinetic energy peaked: restart from rest at q (the step past the peak not taken)
            restarts += 1
            restart()
            continue
        from_rest = False
        ke_prev = ke
        v = v_new
        q = q + v
        f = np.asarray(force(q), dtype=float)
        r = float(np.linalg.norm(f[free]))
        steps += 1
        since_update += 1
        if r <= 0.5 * halved_r:
            halved_r, best_step = r, steps
        if r < best_r:
            best_r, best_q = r, q.copy()
    return RelaxOutcome(q=best_q, residual_N=best_r, converged=best_r <= s.residual_N, message=message, steps=steps,
                        restarts=restarts, mass_updates=updates, cpu_s=time.process_time() - t0, trace=trace,
                        mass_scale=mass_scale)


def bundle_masses(model, safety: float, reference_penetration_m: float, contacts_per_point: float = 2.0,
                  kind: str = "diagonal"):
    """``masses(q)`` for :func:`relax` on a steady bundle model (:class:`exucable.model.bundle.BundleModel`):
    Eq. (DR 3) on its stiffness (:meth:`~exucable.model.bundle.BundleModel.stiffness_blocks3`) plus, at
    every check point, ``contacts_per_point`` Hertz contacts closed to ``reference_penetration_m`` [m]
    acting across the cable (stiffness e K w δ^(e−1) on the plane normal to the node's tangent): a
    contact still open where the masses are taken has no stiffness in K, and a node falling freely
    onto it would go through in one step (measured: a first step of 12 mm onto another cable)."""
    between = model.between
    law = between.law
    n = model.ode2_index.size
    nb = n // 3
    k_point = contacts_per_point * law.exponent * law.stiffness * between.weight \
        * reference_penetration_m ** (law.exponent - 1.0)
    S = abs(between.S)
    # Σ_p |S_p|ᵀ k_p |S_p| row sums: each coordinate's share of the check points' springs
    floor = np.asarray(S.T @ (np.repeat(np.tile(k_point, model.n_cables), 3) * (S @ np.ones(n)))).reshape(nb, 3)[:, 0]
    q_ref = model.layout.coordinates.reshape(-1)

    def masses(q):
        rows, cols, blocks = model.stiffness_blocks3(q)
        if kind == "diagonal":
            M = diagonal_gershgorin_masses(nb, rows, cols, blocks, safety)
            M += (0.25 * safety) * floor[:, None, None] * np.eye(3)[None]
            return M
        if kind == "frame":
            slope = (q_ref + q).reshape(-1, 6)[:, 3:]
            return frame_gershgorin_masses(nb, rows, cols, blocks, np.repeat(node_frames(slope), 2, axis=0),
                                           safety, floor)
        M = block_gershgorin_masses(nb, rows, cols, blocks, safety)
        slope = (q_ref + q).reshape(-1, 6)[:, 3:]
        t = slope / np.linalg.norm(slope, axis=1, keepdims=True)
        P = np.eye(3)[None] - t[:, :, None] * t[:, None, :]           # across the cable, per node
        M += (0.25 * safety) * floor[:, None, None] * np.repeat(P, 2, axis=0)
        return M

    return masses


def relax_bundle(model, settings: RelaxSettings = RelaxSettings(), reference_penetration_m: float = 2e-5,
                 contacts_per_point: float = 2.0, masses: str = "diagonal") -> RelaxOutcome:
    """Dynamic relaxation of a steady bundle model from its current state (the system's ODE2
    coordinates) at its current load scale, the eye's coordinates held; the state of smallest
    residual is written into the system (initial and current configuration) as the next solve's
    start. See :func:`bundle_masses` for the masses' contact part."""
    import exudyn as exu

    sd = model.mbs.systemData
    index = model.ode2_index
    ode2 = np.array(sd.GetODE2Coordinates())
    free = np.ones(index.size, dtype=bool)
    free[model.held_coordinates()] = False
    out = relax(model.steady_force, bundle_masses(model, settings.mass_safety, reference_penetration_m,
                                                  contacts_per_point, masses), ode2[index], free, settings)
    ode2[index] = out.q
    for cfg in (exu.ConfigurationType.Initial, exu.ConfigurationType.Current):
        sd.SetODE2Coordinates(ode2, configuration=cfg)
    return out
