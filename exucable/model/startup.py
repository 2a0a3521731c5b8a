"""The start-up damper: its own Exudyn object that settles the pre-tensioned start, then fades.

Kept apart from the contact coupling (:mod:`exucable.model.coupling`) so that each object does
one thing, and a user who builds the cable into their own system can leave it out or replace it.
"""

from __future__ import annotations

import numpy as np
import exudyn as exu

from .generic import add_user_force_object

__all__ = ["StartupDamper", "add_startup_damper"]


class StartupDamper:
    """A viscous damper that settles the start and then fades away.

    The pre-tensioned start is close to, not at, equilibrium: where an element spans the end of
    a bend it cannot follow the jump of curvature, and the misfit sets the cable's free spans
    ringing as taut strings (ω ≈ (π/ℓ)√(T/ρA), tens of rad/s, all but undamped by the cable's
    material damping). Each slap on the wall then clips the contact damping (f_n ≥ 0) and Newton
    needs tiny steps: Example 4 took 1300 steps per 0.03 s. This damper pulls the nodes' velocities
    toward the start's sliding field with force -c(t)·m_k·(v_k - v_k,ref) (m_k the node's lumped
    mass) and fades out smoothly, c(t) = c0·(1 - smoothstep(t/T)). Along the cable v ≈ v_ref, so
    the pulling force is not biased; after T it is gone. Results are read after it
    (``solver.startup_time``).

    Parameters
    ----------
    lumped_mass_kg : array_like, shape (n_nodes,)
        Lumped mass of each cable node [kg].
    reference_velocity : array_like, shape (n_nodes, 6) or (6 n_nodes,)
        The start's nodal velocities and slope rates [m/s, 1/s].
    rate_1_per_s : float
        c0 [1/s].
    duration_s : float
        T [s]; 0 switches the damper off.
    """

    def __init__(self, lumped_mass_kg, reference_velocity, rate_1_per_s: float, duration_s: float):
        n_nodes = len(lumped_mass_kg)
        mass = np.zeros((n_nodes, 6))
        mass[:, :3] = np.asarray(lumped_mass_kg, dtype=float)[:, None]
        self.mass = mass.reshape(-1)
        self.v_ref = np.asarray(reference_velocity, dtype=float).reshape(-1)
        self.rate = float(rate_1_per_s)
        self.duration = float(duration_s)
        self.object: int | None = None

    def coefficient(self, t: float) -> float:
        """c(t) [1/s]."""
        if self.duration <= 0.0 or t >= self.duration:
            return 0.0
        tau = max(t, 0.0) / self.duration
        return self.rate * (1.0 - tau * tau * (3.0 - 2.0 * tau))

    def force(self, t: float, v) -> np.ndarray:
        """Generalized force on the cable coordinates [N] at time t [s], velocities ``v``."""
        c = self.coefficient(t)
        if c == 0.0:
            return np.zeros_like(self.mass)
        return -c * self.mass * (np.asarray(v, dtype=float) - self.v_ref)

    def rate_jacobian_diagonal(self, t: float) -> np.ndarray:
        """Diagonal of ∂Q/∂q̇ [kg/s]."""
        return -self.coefficient(t) * self.mass

    # -- Exudyn face
    def _force(self, mbs, t, item, q, q_t):
        return self.force(t, q_t)

    def _jacobian(self, mbs, t, item, q, q_t, f_q, f_v):
        diag = -f_v * self.rate_jacobian_diagonal(t)  # LHS derivative: the force is on the RHS
        nz = np.flatnonzero(diag)                      # Exudyn's sparse triplets must not hold zeros
        m = exu.MatrixContainer()
        n = self.mass.size
        if nz.size:
            m.SetWithSparseMatrix(np.column_stack([nz, nz, diag[nz]]).astype(float), n, n, False)
        else:
            m.Initialize(n, n, False)
        return m


def add_startup_damper(mbs, nodes, damper: StartupDamper) -> int:
    """Add ``damper`` to ``mbs`` as one mass-free ``ObjectGenericODE2`` on the cable ``nodes``.

    Returns
    -------
    int
        The Exudyn object index (also stored as ``damper.object``).
    """
    n = damper.mass.size
    if n != 6 * len(nodes):
        raise ValueError("the damper and the cable disagree on the number of nodes")
    damper.object = add_user_force_object(mbs, nodes, n, damper._force, damper._jacobian)
    return damper.object
