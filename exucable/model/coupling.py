"""Thin glue between the contact kernel and Exudyn.

One ``ObjectGenericODE2`` spans all cable nodes and carries no mass, stiffness or damping of its
own; its ``forceUserFunction`` returns the kernel's generalized contact force Q (paper Eqs. 21-23
mapped by Sᵀ) and its ``jacobianUserFunction`` returns the exact derivative of the left-hand side,
``-(f_q ∂Q/∂q + f_v ∂Q/∂q̇)``, as sparse triplets. An exact Jacobian, including the
friction-normal-force coupling, is what lets Newton converge in a few iterations at large steps
(``../shared/notes/exudyn-findings.md``).

Exudyn passes coordinates *without* their reference values: absolute = reference + q.
"""

from __future__ import annotations

import time

import numpy as np
import exudyn as exu
from exudyn.itemInterface import ObjectGenericODE2

__all__ = ["ContactCoupling", "StartupDamper"]


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
    """

    def __init__(self, lumped_mass_kg, reference_velocity, rate_1_per_s, duration_s):
        n_nodes = len(lumped_mass_kg)
        self.mass = np.zeros((n_nodes, 6))
        self.mass[:, :3] = np.asarray(lumped_mass_kg, dtype=float)[:, None]
        self.mass = self.mass.reshape(-1)
        self.v_ref = np.asarray(reference_velocity, dtype=float).reshape(-1)
        self.rate = float(rate_1_per_s)
        self.duration = float(duration_s)

    def coefficient(self, t: float) -> float:
        """c(t) [1/s]."""
        if self.duration <= 0.0 or t >= self.duration:
            return 0.0
        tau = max(t, 0.0) / self.duration
        return self.rate * (1.0 - tau * tau * (3.0 - 2.0 * tau))

    def force(self, t, v):
        c = self.coefficient(t)
        if c == 0.0:
            return 0.0
        return -c * self.mass * (v - self.v_ref)

    def rate_jacobian_diagonal(self, t):
        """Diagonal of ∂Q/∂q̇ [kg/s]."""
        return -self.coefficient(t) * self.mass


class ContactCoupling:
    """Contact forces of ``kernel`` applied to the cable nodes ``nodes`` of ``mbs``.

    Attributes
    ----------
    kernel_time_s : float
        Wall time spent inside the kernel [s] (for the benchmarks' time shares).
    user_time_s : float
        Wall time spent inside the two user functions [s], kernel included.
    force_calls, jacobian_calls : int
        Number of user-function calls.
    kernel_evaluations, reused_evaluations : int
        Kernel passes made, and Jacobian calls served by the pass of the force call before.
    jacobian_with_force : bool
        Compute the Jacobian blocks already in the force call (default; False: only when asked,
        two kernel passes per Newton iteration, for the benchmarks' comparison).
    """

    def __init__(self, mbs, nodes, reference_coordinates, kernel, startup_damper=None, guide=None):
        from ..contact import block_sparsity

        self.kernel = kernel
        self.q_ref = np.ascontiguousarray(np.asarray(reference_coordinates, dtype=float).reshape(-1))
        self.n = self.q_ref.size
        if self.n != kernel.n_coordinates:
            raise ValueError("kernel and cable disagree on the number of coordinates")
        rows, cols = block_sparsity(kernel.n_elements)
        lin = rows.astype(np.int64) * self.n + cols
        unique, self._inverse = np.unique(lin, return_inverse=True)
        self._rows = (unique // self.n).astype(float)
        self._cols = (unique % self.n).astype(float)
        self._n_unique = unique.size
        self.damper = startup_damper
        if startup_damper is not None:
            # its Jacobian is diagonal: make sure the diagonal is in the sparsity pattern
            diag = np.arange(self.n, dtype=np.int64)
            lin_all = np.concatenate([lin, diag * self.n + diag])
            unique, inv = np.unique(lin_all, return_inverse=True)
            self._inverse = inv[:lin.size]
            self._diag_index = inv[lin.size:]
            self._rows = (unique // self.n).astype(float)
            self._cols = (unique % self.n).astype(float)
            self._n_unique = unique.size
        self.guide = guide
        if guide is not None:
            i0 = 6 * guide.node_index
            ii, jj = np.meshgrid(np.arange(i0, i0 + 3), np.arange(i0, i0 + 3), indexing="ij")
            pos = {int(v): k for k, v in enumerate((self._rows * self.n + self._cols).astype(np.int64))}
            self._guide_index = np.array([pos[int(a * self.n + b)] for a, b in zip(ii.ravel(), jj.ravel())])
        self.kernel_time_s = 0.0
        self.user_time_s = 0.0
        self.force_calls = 0
        self.jacobian_calls = 0
        self.kernel_evaluations = 0
        self.reused_evaluations = 0
        self.jacobian_with_force = True
        self._last = None
        empty = [exu.MatrixContainer() for _ in range(3)]
        for m in empty:
            m.Initialize(self.n, self.n, False)
        self.object = mbs.AddObject(ObjectGenericODE2(
            nodeNumbers=list(nodes),
            massMatrix=empty[0], stiffnessMatrix=empty[1], dampingMatrix=empty[2],
            forceUserFunction=self._force, jacobianUserFunction=self._jacobian,
            visualization={"show": False, "color": [-1.0, -1.0, -1.0, -1.0], "triangleMesh": [],
                           "showNodes": False, "graphicsDataUserFunction": 0},
        ))

    def absolute(self, q, q_t):
        """Absolute coordinates and rates from Exudyn's displacement coordinates."""
        return self.q_ref + np.asarray(q, dtype=float), np.asarray(q_t, dtype=float)

    def _evaluate(self, t, q, q_t, jacobian: bool):
        """The kernel's result at absolute (q, q_t), force and Jacobian blocks.

        Full Newton asks for the residual at a state and then, unless converged, for the Jacobian
        at the same state: one kernel pass computes both and the Jacobian call reuses it (only the
        last residual of a step computes blocks that go unused). The reuse is checked, not assumed:
        it needs the same t, q and q̇ bit for bit."""
        last = self._last
        if (last is not None and last[0] == t and np.array_equal(last[1], q)
                and np.array_equal(last[2], q_t)):
            self.reused_evaluations += 1
            return last[3]
        t0 = time.perf_counter()
        res = self.kernel.evaluate(q, q_t, jacobian=jacobian)
        self.kernel_time_s += time.perf_counter() - t0
        self.kernel_evaluations += 1
        # copies: Exudyn may hand over views of vectors it later overwrites
        self._last = (t, q.copy(), q_t.copy(), res) if jacobian else None
        return res

    def _force(self, mbs, t, item, q, q_t):
        t0 = time.perf_counter()
        qa, va = self.absolute(q, q_t)
        res = self._evaluate(t, qa, va, jacobian=self.jacobian_with_force)
        self.force_calls += 1
        Q = res.generalized_force
        if self.damper is not None:
            Q = Q + self.damper.force(t, va)
        if self.guide is not None:
            Q = Q + self.guide.force(np.asarray(q, dtype=float), va)
        self.user_time_s += time.perf_counter() - t0
        return Q

    def _jacobian(self, mbs, t, item, q, q_t, f_q, f_v):
        t0 = time.perf_counter()
        qa, va = self.absolute(q, q_t)
        res = self._evaluate(t, qa, va, jacobian=True)
        self.jacobian_calls += 1
        # LHS derivative: the contact force is on the right-hand side, hence the minus sign.
        blocks = -(f_q * res.jac_q_blocks + f_v * res.jac_qt_blocks)
        vals = np.bincount(self._inverse, weights=blocks.reshape(-1), minlength=self._n_unique)
        if self.damper is not None:
            vals[self._diag_index] -= f_v * self.damper.rate_jacobian_diagonal(t)
        if self.guide is not None:
            g = self.guide
            vals[self._guide_index] += (f_q * g.k + f_v * g.c) * g.P.ravel()
        nz = vals != 0.0  # Exudyn's sparse triplets must not contain zeros
        m = exu.MatrixContainer()
        if nz.any():
            trip = np.column_stack([self._rows[nz], self._cols[nz], vals[nz]])
            m.SetWithSparseMatrix(trip, self.n, self.n, False)
        else:
            m.Initialize(self.n, self.n, False)
        self.user_time_s += time.perf_counter() - t0
        return m
