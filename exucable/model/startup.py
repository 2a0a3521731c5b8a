"""The start-up damper: its own Exudyn object that settles the pre-tensioned start, then fades.

Kept apart from the contact coupling (:mod:`exucable.model.coupling`) so that each object does
one thing, and a user who builds the cable into their own system can leave it out or replace it.
"""

from __future__ import annotations

import numpy as np
import exudyn as exu

from .generic import add_user_force_object

__all__ = ["ExitSpanDamper", "StartupDamper", "add_exit_span_damper", "add_startup_damper"]


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


class ExitSpanDamper:
    """A light viscous damper on the cable past the conduit's exit, toward the steady flow.

    Past the exit the cable hangs under gravity from the conduit's mouth to the rig, which moves
    away along the exit tangent; nothing but the material damping (ζ < 1 %) damps that span, and
    its swing (Gera: period 0.8 s, ±0.36 % of the pulling force) outlasts any run
    (reference/README.md, "Why the force wandered"). Force on each node past the exit:
    -c·w_k·m_k·(v_k − V·r'_k/|r'_k|), m_k the lumped mass, r'_k the current slope, V the rig's
    speed: zero on a cable that slides steadily along its own path. w_k ramps from 0 at the exit
    to 1 one element past it (C¹), so nodes enter the damper smoothly. ``solver.exit_span_damping``
    sets c [1/s]; 0 (the default) switches it off.
    """

    def __init__(self, lumped_mass_kg, reference_coordinates, rate_1_per_s: float, speed_m_per_s: float,
                 exit_point_m, exit_tangent, ramp_length_m: float, ramp_time_s: float = 0.0):
        self.mk = np.asarray(lumped_mass_kg, dtype=float)
        self.q_ref = np.asarray(reference_coordinates, dtype=float).reshape(-1)
        self.rate = float(rate_1_per_s)
        self.speed = float(speed_m_per_s)
        self.exit_point = np.asarray(exit_point_m, dtype=float)
        self.exit_tangent = np.asarray(exit_tangent, dtype=float)
        self.ramp_length = float(ramp_length_m)
        self.ramp_time = float(ramp_time_s)
        self.object: int | None = None

    def _parts(self, t, q):
        from .rig import smooth_ramp
        x = (self.q_ref + np.asarray(q, dtype=float)).reshape(-1, 6)
        d = (x[:, :3] - self.exit_point) @ self.exit_tangent
        tau = np.clip(d / self.ramp_length, 0.0, 1.0)
        w = tau * tau * (3.0 - 2.0 * tau)
        slope = x[:, 3:]
        mag = np.linalg.norm(slope, axis=1)[:, None]
        return self.rate * w * self.mk, self.speed * smooth_ramp(t, self.ramp_time), slope, mag

    def force(self, t, q, v) -> np.ndarray:
        """Generalized force [N] on the cable coordinates."""
        c, speed, slope, mag = self._parts(t, q)
        out = np.zeros((len(c), 6))
        out[:, :3] = -c[:, None] * (np.asarray(v, dtype=float).reshape(-1, 6)[:, :3] - speed * slope / mag)
        return out.reshape(-1)

    def _force(self, mbs, t, item, q, q_t):
        return self.force(t, q, q_t)

    def _jacobian(self, mbs, t, item, q, q_t, f_q, f_v):
        # ∂Q/∂q̇ (diagonal) and ∂Q/∂r' of the flow reference; the weight's slow change with position is left out
        c, speed, slope, mag = self._parts(t, q)
        n = 6 * len(c)
        on = np.flatnonzero(c)
        rows, cols, vals = [], [], []
        for k in on:
            for i in range(3):
                rows.append(6 * k + i), cols.append(6 * k + i), vals.append(f_v * c[k])
            u = slope[k] / mag[k]
            block = -f_q * c[k] * speed / mag[k, 0] * (np.eye(3) - np.outer(u, u))
            for i in range(3):
                for j in range(3):
                    if block[i, j] != 0.0:
                        rows.append(6 * k + i), cols.append(6 * k + 3 + j), vals.append(block[i, j])
        m = exu.MatrixContainer()
        if vals:
            m.SetWithSparseMatrix(np.column_stack([rows, cols, vals]).astype(float), n, n, False)
        else:
            m.Initialize(n, n, False)
        return m


def add_exit_span_damper(mbs, nodes, damper: ExitSpanDamper) -> int:
    """Add ``damper`` to ``mbs`` as one mass-free ``ObjectGenericODE2`` on the cable ``nodes``;
    returns the Exudyn object index (also stored as ``damper.object``)."""
    if len(damper.mk) != len(nodes):
        raise ValueError("the damper and the cable disagree on the number of nodes")
    damper.object = add_user_force_object(mbs, nodes, 6 * len(nodes), damper._force, damper._jacobian)
    return damper.object
