"""Thin glue between the contact kernel and Exudyn: the conduit wall's forces, nothing else.

One ``ObjectGenericODE2`` spans all cable nodes and carries no mass, stiffness or damping of its
own; its ``forceUserFunction`` returns the kernel's generalized contact force Q (paper Eqs. 21-23
mapped by Sᵀ) and its ``jacobianUserFunction`` returns the exact derivative of the left-hand side,
``-(f_q ∂Q/∂q + f_v ∂Q/∂q̇)``, as sparse triplets. An exact Jacobian, including the
friction-normal-force coupling, is what lets Newton converge in a few iterations at large steps
(``../shared/notes/exudyn-findings.md``).

Exudyn passes coordinates *without* their reference values: absolute = reference + q.
The start-up damper (:mod:`exucable.model.startup`) and the force-controlled pull's guide
(:func:`exucable.model.rig.add_guide`) are objects of their own.
"""

from __future__ import annotations

import time

import numpy as np
import exudyn as exu

from .generic import add_user_force_object

__all__ = ["ContactCoupling"]


class ContactCoupling:
    """Contact forces of ``kernel`` applied to the cable nodes ``nodes`` of ``mbs``.

    Attributes
    ----------
    kernel_time_s : float
        Wall time spent inside the kernel [s] (for the benchmarks' time shares).
    force_calls, jacobian_calls : int
        Number of user-function calls.
    """

    def __init__(self, mbs, nodes, reference_coordinates, kernel):
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
        self.kernel_time_s = 0.0
        self.force_calls = 0
        self.jacobian_calls = 0
        self.object = add_user_force_object(mbs, nodes, self.n, self._force, self._jacobian)

    def absolute(self, q, q_t):
        """Absolute coordinates and rates from Exudyn's displacement coordinates."""
        return self.q_ref + np.asarray(q, dtype=float), np.asarray(q_t, dtype=float)

    def _force(self, mbs, t, item, q, q_t):
        qa, va = self.absolute(q, q_t)
        t0 = time.perf_counter()
        res = self.kernel.evaluate(qa, va, jacobian=False)
        self.kernel_time_s += time.perf_counter() - t0
        self.force_calls += 1
        return res.generalized_force

    def _jacobian(self, mbs, t, item, q, q_t, f_q, f_v):
        qa, va = self.absolute(q, q_t)
        t0 = time.perf_counter()
        res = self.kernel.evaluate(qa, va, jacobian=True)
        self.kernel_time_s += time.perf_counter() - t0
        self.jacobian_calls += 1
        # LHS derivative: the contact force is on the right-hand side, hence the minus sign.
        blocks = -(f_q * res.jac_q_blocks + f_v * res.jac_qt_blocks)
        vals = np.bincount(self._inverse, weights=blocks.reshape(-1), minlength=self._n_unique)
        nz = vals != 0.0  # Exudyn's sparse triplets must not contain zeros
        m = exu.MatrixContainer()
        if nz.any():
            trip = np.column_stack([self._rows[nz], self._cols[nz], vals[nz]])
            m.SetWithSparseMatrix(trip, self.n, self.n, False)
        else:
            m.Initialize(self.n, self.n, False)
        return m
