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

A steady model with ``[solver] cable_element = "compiled"`` has no ``ObjectANCFCable`` objects: the
same user functions then add the cable's elastic forces and weight
(:class:`exucable.contact.ancf_cable.AncfCableForces`, ``cable_forces``) and their stiffness blocks,
which share the contact blocks' sparsity (element blocks of 12 × 12), so one handover carries both.
"""

from __future__ import annotations

import time

import numpy as np
import exudyn as exu

from .generic import add_user_force_object

__all__ = ["ContactCoupling"]


def _chain_pattern(n_elements: int, with_inverse: bool = True):
    """The distinct (row, column) pairs of a chain's element blocks in row-major order, and the
    index of each block entry among them, in the order of :func:`exucable.contact.block_sparsity`:
    what ``np.unique(rows·n + cols, return_inverse=True)`` of its rows and columns gives, without
    sorting (or forming) 144 entries per element. Element e's 12 × 12 block spans nodes e and e + 1
    (coordinates 6e … 6e + 11), so the row of node k's coordinates holds the columns of nodes
    max(k − 1, 0) … min(k + 1, n_nodes − 1), contiguous; entry (a, b) of element e's block is row
    6e + a, column 6e + b. ``with_inverse=False``: the pairs only (the inverse None)."""
    n_nodes = n_elements + 1
    node = np.arange(n_nodes)
    first = np.maximum(node - 1, 0)                      # first column node of each row node
    width = 6 * (np.minimum(node + 1, n_nodes - 1) - first + 1)
    row_width = np.repeat(width, 6)                      # per row (6 per node)
    row_start = np.concatenate([[0], np.cumsum(row_width)])
    col_start = np.repeat(6 * first, 6)
    # an entry's index: its row's start + (its column − the row's first column)
    shift = row_start[:-1] - col_start                   # per row
    inverse = None
    if with_inverse:
        element_row = 6 * np.arange(n_elements)[:, None] + np.arange(12)[None, :]
        inverse = ((shift[element_row] + 6 * np.arange(n_elements)[:, None])[:, :, None]
                   + np.arange(12)[None, None, :]).reshape(-1)
    unique_rows = np.repeat(np.arange(6 * n_nodes), row_width)
    unique_cols = np.arange(row_start[-1]) - np.repeat(shift, row_width)
    return unique_rows, unique_cols, inverse


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
    onset_evaluations : int
        Kernel passes made by :meth:`start_step` (its state was not the last pass's).
    held_onset : ndarray or None
        The damping onset g [-] per check point, held within the current step.
    solved_onset : ndarray or None
        The onset the last accepted step was solved with (the one before :attr:`held_onset`).
    jacobian_with_force : bool
        Compute the Jacobian blocks already in the force call (default; False: only when asked,
        two kernel passes per Newton iteration, for the benchmarks' comparison).
    cable_forces : AncfCableForces or None
        The cable's elastic forces and weight, added to the contact's (None: Exudyn's elements
        carry them).
    cable_time_s : float
        Wall time spent in ``cable_forces`` [s].
    """

    def __init__(self, mbs, nodes, reference_coordinates, kernel, cable_forces=None):
        self.kernel = kernel
        self.cable_forces = cable_forces
        self.cable_time_s = 0.0
        if cable_forces is not None and cable_forces.n_elements != kernel.n_elements:
            raise ValueError("kernel and cable forces disagree on the number of elements")
        self.q_ref = np.ascontiguousarray(np.asarray(reference_coordinates, dtype=float).reshape(-1))
        self.n = self.q_ref.size
        if self.n != kernel.n_coordinates:
            raise ValueError("kernel and cable disagree on the number of coordinates")
        unique_rows, unique_cols, _ = _chain_pattern(kernel.n_elements, with_inverse=False)
        self._n_unique = unique_rows.size
        self._csr = (np.concatenate([[0], np.cumsum(np.bincount(unique_rows, minlength=self.n))]).astype(np.int64),
                     unique_cols.astype(np.int64))
        self._handover = None    # the triplets for Exudyn's solver: made when first asked for (see _triplets)
        self.kernel_time_s = 0.0
        self.user_time_s = 0.0
        self.force_calls = 0
        self.jacobian_calls = 0
        self.kernel_evaluations = 0
        self.reused_evaluations = 0
        self.jacobian_with_force = True
        self._last = None
        self.object = add_user_force_object(mbs, nodes, self.n, self._force, self._jacobian)
        self._ltg = None
        # the damping onset g per check point, held within a step at its value in the step's
        # start state (ContactLaw's notes); None before the first start_step
        self.held_onset = None
        self.solved_onset = None
        self.onset_evaluations = 0

    def start_step(self, mbs, t):
        """Hold every check point's damping onset g(δ) at its value in the current state: call it
        once a step is accepted (and before the first), with t [s] the current time.

        The state's penetrations are the last kernel pass's when that pass was at this state (it
        is: Exudyn's last residual of a converged step is evaluated there), else one pass more.
        """
        if self._ltg is None:
            self._ltg = np.asarray(mbs.systemData.GetObjectLTGODE2(self.object), dtype=np.int64)
        sd = mbs.systemData
        qa, va = self.absolute(np.asarray(sd.GetODE2Coordinates())[self._ltg],
                               np.asarray(sd.GetODE2Coordinates_t())[self._ltg])
        last = self._last
        if last is not None and last[0] == t and np.array_equal(last[1], qa) and np.array_equal(last[2], va):
            res = last[3]
        else:
            res = self._evaluate(t, qa, va, jacobian=False)
            self.onset_evaluations += 1
        # the onset the state just accepted was solved with (its loads' balance needs it)
        self.solved_onset = self.held_onset
        self.held_onset = self.kernel.damping_onset(res.penetration_m)
        self._last = None  # evaluated with the onset held before

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
        if (last is not None and (last[3].jac_q_blocks is not None or not jacobian) and last[0] == t
                and np.array_equal(last[1], q) and np.array_equal(last[2], q_t)):
            self.reused_evaluations += 1
            return last[3]
        t0 = time.perf_counter()
        res = self.kernel.evaluate(q, q_t, jacobian=jacobian, held_onset=self.held_onset)
        t1 = time.perf_counter()
        self.kernel_time_s += t1 - t0
        self.kernel_evaluations += 1
        elastic = None
        if self.cable_forces is not None:
            elastic = self.cable_forces.evaluate(q, jacobian=jacobian)
            self.cable_time_s += time.perf_counter() - t1
        # copies: Exudyn may hand over views of vectors it later overwrites
        self._last = (t, q.copy(), q_t.copy(), res, elastic)
        return res

    def _elastic(self):
        """The cable forces of the last pass (``(rhs, blocks)``; None without ``cable_forces``)."""
        return self._last[4] if self._last is not None and len(self._last) > 4 else None

    def last_evaluation(self):
        """The last kernel pass (time, coordinates, rates, result), to :meth:`offer_evaluation`
        back when the solve restarts from that state (None before the first pass)."""
        return self._last

    def offer_evaluation(self, evaluation) -> None:
        """Make ``evaluation`` (from :meth:`last_evaluation`) the pass the next user-function
        call may reuse; it is reused only at the same t, q and q̇ bit for bit (see _evaluate)."""
        if evaluation is not None:
            self._last = evaluation

    def forget_evaluation(self) -> None:
        """Reuse no former kernel pass: the kernel's law changed (its friction scale)."""
        self._last = None

    def _handover_arrays(self):
        """The triplets (row, column, value) handed to Exudyn, rows and columns filled once, each row
        also one 24-byte record (so that dropping the zero values is one gather of records), and each
        block entry's index among them: made on first use, since only a Jacobian handed to Exudyn (or
        the SuperLU step's values) needs them, not our banded Newton step (10 km: 33 MB of triplets)."""
        if self._handover is None:
            unique_rows, unique_cols, inverse = _chain_pattern(self.kernel.n_elements)
            triplets = np.zeros((unique_rows.size, 3))
            triplets[:, 0] = unique_rows
            triplets[:, 1] = unique_cols
            self._handover = (triplets, triplets.view(np.dtype((np.void, 24))).reshape(-1), inverse)
        return self._handover

    @property
    def _triplets(self):
        return self._handover_arrays()[0]

    @property
    def _records(self):
        return self._handover_arrays()[1]

    @property
    def _inverse(self):
        return self._handover_arrays()[2]

    def chain_pattern_csr(self) -> tuple[np.ndarray, np.ndarray]:
        """The Jacobian's fixed sparsity as CSR ``(indptr, indices)`` over the cable's coordinates
        (node-major; each row's columns sorted): the order of :meth:`stiffness_values`."""
        return self._csr

    def force(self, q, t: float = 0.0, jacobian: bool | None = None) -> np.ndarray:
        """The generalized force [N, N·m] on the cable's displacement coordinates ``q`` at rest
        (q̇ = 0): contact, and the cable's elastic forces and weight when assembled here; the same
        vector the force user function hands Exudyn (a static solve's right-hand side).
        ``jacobian``: compute the Jacobian blocks in the same pass (None: as
        :attr:`jacobian_with_force`; False for a caller that needs the force alone, such as the
        dynamic relaxation, :mod:`exucable.solve.relax`)."""
        q = np.asarray(q, dtype=float)
        return self._total(t, q, np.zeros_like(q), self.jacobian_with_force if jacobian is None else jacobian)

    def stiffness_values(self, q, t: float = 0.0) -> np.ndarray:
        """The left-hand-side derivative ``-∂Q/∂q`` at ``q`` (at rest), as the values of
        :meth:`chain_pattern_csr` (zeros kept, so the pattern never changes). Reuses the kernel pass
        of :meth:`force` at the same ``q`` and ``t``; the array returned is reused by the next call."""
        qa, va = self.absolute(q, np.zeros(self.n))
        res = self._evaluate(t, qa, va, jacobian=True)
        self.jacobian_calls += 1
        elastic = self._elastic()
        return self._lhs_values(res, 1.0, 0.0, None if elastic is None else elastic[1])

    def stiffness_blocks(self, q, t: float = 0.0) -> np.ndarray:
        """The left-hand-side derivative ``-∂Q/∂q`` at ``q`` (at rest) per element, (n_el, 12, 12):
        element e's block over the coordinates of nodes e and e + 1 (the values
        :meth:`stiffness_values` sums where two elements share a node). Reuses the kernel pass of
        :meth:`force` at the same ``q`` and ``t``."""
        qa, va = self.absolute(q, np.zeros(self.n))
        res = self._evaluate(t, qa, va, jacobian=True)
        self.jacobian_calls += 1
        elastic = self._elastic()
        # (-1)·∂Q/∂q + the cable's stiffness: the same sum as jacobian_triplets' blocks at f_q = 1
        return -res.jac_q_blocks if elastic is None else elastic[1] - res.jac_q_blocks

    def _force(self, mbs, t, item, q, q_t):
        return self._total(t, q, q_t, self.jacobian_with_force)

    def _total(self, t, q, q_t, jacobian: bool) -> np.ndarray:
        """The force user function's vector at displacement coordinates q and rates q_t."""
        t0 = time.perf_counter()
        qa, va = self.absolute(q, q_t)
        res = self._evaluate(t, qa, va, jacobian=jacobian)
        self.force_calls += 1
        elastic = self._elastic()
        out = res.generalized_force
        if elastic is not None:
            out = out + elastic[0]
            weight = self.cable_forces.weight()     # at the loads' scale now, never a cached one
            if weight is not None:
                out += weight
        self.user_time_s += time.perf_counter() - t0
        return out

    def _jacobian(self, mbs, t, item, q, q_t, f_q, f_v):
        t0 = time.perf_counter()
        qa, va = self.absolute(q, q_t)
        res = self._evaluate(t, qa, va, jacobian=True)
        self.jacobian_calls += 1
        m = exu.MatrixContainer()
        elastic = self._elastic()
        trip = self.jacobian_triplets(res, f_q, f_v, None if elastic is None else elastic[1])
        if trip.shape[0]:
            m.SetWithSparseMatrix(trip, self.n, self.n, False)
        else:
            m.Initialize(self.n, self.n, False)
        self.user_time_s += time.perf_counter() - t0
        return m

    def jacobian_triplets(self, res, f_q: float, f_v: float, elastic_blocks=None) -> np.ndarray:
        """Sparse triplets (row, column, value) of the LHS derivative ``-(f_q ∂Q/∂q + f_v ∂Q/∂q̇)``
        of the kernel result ``res``, the element blocks summed where they share a node, zero
        values left out (Exudyn leaves an element's zero entries out of the system matrix too, so
        the sparsity pattern, and with it the LU's ordering, is the one Exudyn's elements make).

        Without a velocity term (``f_v = 0``, or the steady kernel's zero q̇-blocks) the blocks
        are ``(-f_q) ∂Q/∂q``: the same values bit for bit as the general formula (a product's
        rounding does not depend on its sign; the only difference, a zero's sign, is dropped).
        ``elastic_blocks`` (n_el, 12, 12): the cable's stiffness ∂Q_e/∂q, a left-hand-side term,
        added as ``f_q`` times it. The array returned is reused by the next call.
        """
        vals = self._lhs_values(res, f_q, f_v, elastic_blocks)
        nz = vals != 0.0
        if nz.all():
            return self._triplets
        return self._records[nz].view(float).reshape(-1, 3)

    def _lhs_values(self, res, f_q: float, f_v: float, elastic_blocks=None) -> np.ndarray:
        """:meth:`jacobian_triplets`' values in the chain pattern, zeros kept (a view of the
        triplets' value column)."""
        jq, jv = res.jac_q_blocks, res.jac_qt_blocks
        if f_v == 0.0 or jv is None or not jv.any():
            blocks = (-f_q) * jq
        else:
            # LHS derivative: the contact force is on the right-hand side, hence the minus sign.
            blocks = -(f_q * jq + f_v * jv)
        if elastic_blocks is not None:
            blocks = blocks + f_q * elastic_blocks
        self._triplets[:, 2] = np.bincount(self._inverse, weights=blocks.reshape(-1), minlength=self._n_unique)
        return self._triplets[:, 2]
