"""The static solves of the steady continuation: Exudyn's solver, or our Newton loop on the same model.

:class:`exucable.solve.steady.SteadySolver` runs many short static solves (pseudo-time steps of one
Newton iteration, or a few). It asks each through a small interface (:class:`StaticBackend`):
``solve(max_iterations, relative_tolerance, absolute_tolerance_N)`` → :class:`NewtonOutcome`;
``system_residual()``, the last residual's ODE2 part; the state lives in ``mbs.systemData``
either way, so the stored states, post-processing and the rig's reaction read it unchanged.

- :class:`ExudynStatic`: Exudyn's ``MainSolverStatic`` (one load step, plain Newton), the
  reference path; bundles, Exudyn's cable element and models with other items use it.
- :class:`OwnStaticNewton`: the same Newton iterations on our own assembled system, for a
  one-cable steady model whose cable is assembled by the contact coupling
  (``solver.cable_element = "compiled"``): the whole force and stiffness are ours already
  (:class:`exucable.model.coupling.ContactCoupling`: contact, elastic forces, weight), plus the
  pseudo-time spring, the end loads and a force-controlled pull's sheave. The Jacobian has the
  chain's fixed sparsity (each element couples its two nodes): the element blocks are written
  straight into LAPACK's band storage (node-major order, half bandwidth 11), the rig's held
  coordinates eliminated, and solved by ``dgbsv``; a CSR matrix of the same pattern with SuperLU
  is the cross-check (``linear_solver = "splu"``).

Exudyn's Newton (``CSolverBase::Newton`` with ``CSolverStatic``'s residual, Exudyn 1.13), which
:class:`OwnStaticNewton` reproduces so that the iterates agree to round-off: the multipliers start
at zero; the residual is ``[f(q) + C_qᵀλ ; C(q)]``, f the sum of the right-hand-side forces, and
its norm the Euclidean norm over every row, multipliers' rows and the held coordinates' included
(``weightTolerancePerCoordinate`` off); the initial residual is the start's (raised to twice the
absolute tolerance if below it, and to the first iterate's if that is larger:
``adaptInitialResidual``); a step converges when residual / initial ≤ the relative tolerance or
residual ≤ the absolute one; a non-finite iterate stops Newton.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import exudyn as exu
from scipy.linalg import lapack

__all__ = ["NewtonOutcome", "StaticBackend", "ExudynStatic", "OwnStaticNewton", "own_newton_unsupported",
           "OwnBundleNewton", "own_bundle_newton_unsupported", "static_backend", "HALF_BANDWIDTH"]

#: Half bandwidth of the node-major chain's Jacobian: a row of node k reaches nodes k ± 1 (6 each).
HALF_BANDWIDTH = 11


@dataclass
class NewtonOutcome:
    """What one static solve did.

    Attributes
    ----------
    converged : bool
    message : str
        Why not ("" when converged).
    residual_N : float
        Newton's last residual norm [N] (Exudyn's ``conv.residual``).
    newton_iterations, jacobian_updates : int
    """

    converged: bool
    message: str
    residual_N: float
    newton_iterations: int
    jacobian_updates: int


class StaticBackend:
    """The interface :class:`exucable.solve.steady.SteadySolver` solves through (see the module)."""

    name = ""

    def solve(self, max_iterations: int, relative_tolerance: float, absolute_tolerance_N: float) -> NewtonOutcome:
        """Newton from the system's current state; the state reached is left in ``mbs.systemData``."""
        raise NotImplementedError

    def system_residual(self) -> np.ndarray:
        """The last residual's ODE2 rows [N, N·m]: forces plus the multipliers' reactions."""
        raise NotImplementedError


class ExudynStatic(StaticBackend):
    """Exudyn's static solver (:func:`exucable.solve.steady.static_settings`' one load step)."""

    name = "exudyn"

    def __init__(self, mbs, settings_of):
        self.mbs = mbs
        self._settings_of = settings_of       # (tolerances) -> exu.SimulationSettings
        self._last = None

    def solve(self, max_iterations, relative_tolerance, absolute_tolerance_N, settings=None) -> NewtonOutcome:
        """As :meth:`StaticBackend.solve`; ``settings``: Exudyn's settings to use as they are instead."""
        solver = exu.MainSolverStatic()
        self._last = solver
        if settings is None:
            settings = self._settings_of(tolerance=relative_tolerance, max_iterations=max_iterations,
                                         absolute_tolerance_N=absolute_tolerance_N)
        try:
            ok = solver.SolveSystem(self.mbs, settings)
            message = "" if ok else (solver.GetErrorString() or "Newton did not converge")
        except Exception as exc:  # Exudyn raises plain RuntimeError/ValueError on divergence
            ok, message = False, f"{type(exc).__name__}: {exc}".strip()
        return NewtonOutcome(bool(ok), message, float(solver.conv.residual), int(solver.it.newtonStepsCount),
                             int(solver.it.newtonJacobiCount))

    def system_residual(self) -> np.ndarray:
        n = len(self.mbs.systemData.GetODE2Coordinates())
        return np.array(self._last.GetSystemResidual())[:n]


def own_newton_unsupported(model, spring=None) -> str:
    """Why :class:`OwnStaticNewton` cannot solve ``model`` ("" when it can): it needs one cable
    whose forces the contact coupling assembles, the rig as coordinate constraints, point forces
    as the only loads, the force-controlled pull's sheave (a constant stiffness) and, when given,
    the pseudo-time ``spring``'s object, and no other item."""
    if getattr(model, "n_cables", 1) > 1:
        return "several cables"
    if getattr(model, "cable_forces", None) is None or getattr(model, "coupling", None) is None:
        return "the cable is Exudyn's element (solver.cable_element = \"exudyn\") or there is no contact"
    mbs = model.mbs
    sd = mbs.systemData
    if len(sd.GetODE2Coordinates()) != model.ode2_index.size:
        return "coordinates other than the cable's"
    drives = [d for d in (model.lead_drive, model.trail_drive) if d is not None]
    held = set()
    for d in drives:
        if not hasattr(d, "constraints"):
            return "a velocity-level drive"
        held.update(int(c) for c in d.constraints)
    guide = getattr(model, "guide", None)
    known = {int(model.coupling.object)} | ({int(guide.object)} if guide is not None else set()) \
        | ({int(spring.object)} if spring is not None else set())
    for i in range(sd.NumberOfObjects()):
        kind = mbs.GetObject(i)["objectType"]
        if kind == "ConnectorCoordinate":
            o = mbs.GetObject(i)
            if (i not in held or float(o["factor1"]) != 1.0 or o["velocityLevel"] or float(o["offset"]) != 0.0
                    or mbs.GetMarker(o["markerNumbers"][1])["markerType"] != "NodeCoordinate"):
                return f"object {i} (a coordinate constraint that is not the rig's)"
        elif kind != "GenericODE2":
            return f"object {i} ({kind})"
        elif i not in known:
            return f"object {i} (a generic object that is not the contact's, the sheave's or the spring's)"
    for i in range(sd.NumberOfLoads()):
        load = mbs.GetLoad(i)
        if load["loadType"] != "ForceVector" or load.get("loadVectorUserFunction", 0) not in (0, None):
            return f"load {i} ({load['loadType']})"
        if mbs.GetMarker(load["markerNumber"])["markerType"] != "NodePosition":
            return f"load {i} (not on a node's position)"
    return ""


class OwnStaticNewton(StaticBackend):
    """Exudyn's static Newton iterations (the module's notes) on our own assembled system.

    Parameters
    ----------
    model : exucable.model.build.Model
        A one-cable steady model with the compiled cable (:func:`own_newton_unsupported` is "").
    spring : exucable.solve.steady.PseudoTimeSpring
        The pseudo-time spring (its force and its 3 × 3 nodal blocks c·m·P).
    time_s : float
        The time handed to the coupling (Exudyn's static solver evaluates at its load step's end, 1).
    linear_solver : {"banded", "splu"}
        LAPACK's banded LU (``dgbsv``) or SuperLU (``scipy.sparse.linalg.splu``); both solve the
        same system (``benchmarks/long_routes.py --compare-static-solver`` measures them).
    checked : bool
        The caller found :func:`own_newton_unsupported` to be "" already (its walk over the
        system's items is not repeated).

    Attributes
    ----------
    time_parts_s : dict
        CPU time [s] per part: ``"forces"`` (kernel, cable, spring: the residual), ``"assembly"``
        (values into the banded matrix), ``"factorisation"`` (factor and solve), ``"glue"`` (the rest).
    deadline_cpu_s : float
        Process CPU time (``time.process_time()``) [s] after which :meth:`solve` takes no further
        iteration and says that it stopped (inf, the default: never). The steady solve sets it to
        the end of its budget: an exact pseudo-time step is up to 12 iterations (~1.5 s on the
        100 m three-cable route), and a solve that read its clock only between steps overran its
        limit by seconds.
    """

    name = "exucable"
    deadline_cpu_s = float("inf")

    def __init__(self, model, spring, time_s: float = 1.0, linear_solver: str = "banded", checked: bool = False):
        why = "" if checked else own_newton_unsupported(model, spring)
        if why:
            raise ValueError(f"our static Newton cannot solve this model: {why}")
        if linear_solver not in ("banded", "splu"):
            raise ValueError(f"linear_solver must be 'banded' or 'splu', got {linear_solver!r}")
        self.model, self.mbs, self.spring = model, model.mbs, spring
        self.coupling = model.coupling
        self.time_s = float(time_s)
        self.linear_solver = linear_solver
        self.index = np.asarray(model.ode2_index, dtype=np.int64)   # cable coordinate k -> system row
        n = self.n = self.index.size
        indptr, indices = self.coupling.chain_pattern_csr()
        self.indptr, self.indices = indptr, indices
        rows = np.repeat(np.arange(n), np.diff(indptr))
        # where each (row, column) entry sits in the pattern: the row's start plus the column's offset
        # from the row's first column (the row's columns are contiguous)
        first_col = indices[indptr[:-1]]

        def entry(r, c):
            return indptr[r] + (c - first_col[r])

        # the spring's 3 × 3 blocks per node and per positions/slopes (PseudoTimeSpring's order)
        k = np.arange(spring.n_nodes)[:, None, None, None]
        b = np.arange(2)[None, :, None, None]
        i3 = np.arange(3)
        sr = (6 * k + 3 * b + i3[None, None, :, None]) + 0 * i3[None, None, None, :]
        sc = (6 * k + 3 * b + i3[None, None, None, :]) + 0 * i3[None, None, :, None]
        self._spring_entries = entry(sr.reshape(-1), sc.reshape(-1))
        # the rig's held coordinates (cable order) and their constraints' multipliers (AE order)
        sd = self.mbs.systemData
        where = np.empty(n, dtype=np.int64)
        where[self.index] = np.arange(n)
        self.held, self.ae = _held_rows(self.mbs, [d for d in (model.lead_drive, model.trail_drive) if d is not None],
                                        where)
        self.n_ae = len(sd.GetAECoordinates())
        is_held = np.zeros(n, dtype=bool)
        is_held[self.held] = True
        self._is_held = is_held
        # entries in a held row or column: the eliminated system has the identity there
        self._off = is_held[rows] | is_held[indices]
        self._held_diagonal = entry(self.held, self.held)
        # the end loads: constant point forces on node positions, read at each solve (load scale)
        self._loads = []
        for i in range(sd.NumberOfLoads()):
            node = self.mbs.GetMarker(self.mbs.GetLoad(i)["markerNumber"])["nodeNumber"]
            self._loads.append((i, where[self.mbs.GetNodeODE2Index(node) + np.arange(3)]))
        self._rows = rows
        # the force-controlled pull's sheave: a constant stiffness K on its node, force -K q
        self._guide = None
        if model.guide is not None:
            node = self.mbs.GetObject(model.guide.object)["nodeNumbers"][0]
            grows = where[self.mbs.GetNodeODE2Index(node) + np.arange(6)]
            trip = np.asarray(self.mbs.GetObjectParameter(model.guide.object, "stiffnessMatrix")
                              .GetPythonObject()["triplets"], dtype=float).reshape(-1, 3)
            K, D = np.zeros((6, 6)), np.zeros((6, 6))
            np.add.at(K, (trip[:, 0].astype(int), trip[:, 1].astype(int)), trip[:, 2])
            trip = np.asarray(self.mbs.GetObjectParameter(model.guide.object, "dampingMatrix")
                              .GetPythonObject()["triplets"], dtype=float).reshape(-1, 3)
            np.add.at(D, (trip[:, 0].astype(int), trip[:, 1].astype(int)), trip[:, 2])
            gi, gj = np.repeat(grows, 6), np.tile(grows, 6)
            self._guide = (grows, K, entry(gi, gj), gj * (3 * HALF_BANDWIDTH + 1) + 2 * HALF_BANDWIDTH + gi - gj, D)
        # dgbsv's band storage, Fortran order (LAPACK's own: no copy on the call): entry (i, j) at
        # row kl + ku + i - j of column j, so at memory position 34 j + 22 + i - j; the top kl rows
        # take the LU's fill-in
        kl = HALF_BANDWIDTH
        self._kl, self._ld = kl, 3 * kl + 1
        self._band = np.zeros((self._ld, n), order="F")
        memory = self._band.T.reshape(-1)                       # a view of the same memory
        assert np.shares_memory(memory, self._band)
        top, stride = 2 * kl, memory.strides[0]
        # element e's 12 × 12 block (a, b) sits at 204 e + 22 + a + 33 b: a strided view, one per
        # parity (consecutive elements share a node, every second one does not)
        n_el = (n // 6) - 1
        self._element_view = np.lib.stride_tricks.as_strided(
            memory[top:], shape=(n_el, 12, 12), strides=(6 * self._ld * stride, stride, (self._ld - 1) * stride))
        # the spring's 3 × 3 blocks of node k, positions (c = 0) and slopes (c = 1): 204 k + 102 c + 22 + i + 33 j
        self._spring_view = np.lib.stride_tricks.as_strided(
            memory[top:], shape=(spring.n_nodes, 2, 3, 3),
            strides=(6 * self._ld * stride, 3 * self._ld * stride, stride, (self._ld - 1) * stride))
        self._memory = memory
        # the held coordinates' rows and columns in the band (entries beyond the matrix's edge dropped)
        off = np.arange(-kl, kl + 1)
        self._held_row, self._held_col = [], []
        for h in self.held:
            j = h + off
            j = j[(j >= 0) & (j < n)]
            self._held_row.append((j, j * self._ld + top + h - j))     # (columns, positions) of row h
            self._held_col.append((j, h * self._ld + top + j - h))     # (rows, positions) of column h
        self._held_diagonal_band = self.held * self._ld + top
        self._residual = np.zeros(n)
        self._last_spring = np.zeros(n)
        self.time_parts_s = {"forces": 0.0, "assembly": 0.0, "factorisation": 0.0, "glue": 0.0}
        self._start = None          # the next solve's start, handed over (:meth:`start_from`)

    # ---- the system's parts
    def _load_vector(self) -> np.ndarray:
        f = np.zeros(self.n)
        for i, rows in self._loads:
            f[rows] += np.asarray(self.mbs.GetLoadParameter(i, "loadVector"), dtype=float)
        return f

    def _constant_forces(self) -> np.ndarray:
        """The forces that do not depend on the iterate, cable order [N]: the end loads, and the
        sheave's damping -D q̇ at the nodes' initial rates (Exudyn's static solver evaluates it there,
        a static solve never updates them: kept so that the iterates match)."""
        loads = self._load_vector()
        if self._guide is not None:
            rows, D = self._guide[0], self._guide[4]
            rates = np.asarray(self.mbs.systemData.GetODE2Coordinates_t(
                configuration=exu.ConfigurationType.Initial))[self.index]
            loads[rows] -= D @ rates[rows]
        return loads

    def _forces(self, q, lam, loads) -> np.ndarray:
        """ODE2 residual rows in cable order: f(q) + C_qᵀλ (f: coupling, spring, end loads)."""
        t0 = time.process_time()
        spring = self.spring.force(q)
        r = self.coupling.force(q, self.time_s) + spring + loads
        r[self.held] += lam
        if self._guide is not None:
            rows, K = self._guide[:2]
            r[rows] -= K @ q[rows]
        self._last_spring = spring
        self.time_parts_s["forces"] += time.process_time() - t0
        return r

    def _newton_step(self, q, r, dq_held):
        """Solve the bordered system [[-K, E], [Eᵀ, 0]] [Δq; Δλ] = [r; C] at ``q`` with the held
        coordinates eliminated: K_ff Δq_f = -(r_f + K_fh Δq_h), Δq_h = C, Δλ = r_h + K_h· Δq
        (K = -∂f/∂q, the left-hand-side stiffness). Returns (Δq, Δλ); raises
        numpy.linalg.LinAlgError for a singular matrix."""
        if self.linear_solver == "banded":
            return self._banded_step(q, r, dq_held)
        return self._sparse_step(q, r, dq_held)

    def _banded_step(self, q, r, dq_held):
        t0 = time.process_time()
        blocks = self.coupling.stiffness_blocks(q, self.time_s)
        spring = self.spring.block_values().reshape(self.spring.n_nodes, 2, 3, 3)
        t1 = time.process_time()
        band, view = self._band, self._element_view
        band.fill(0.0)
        view[0::2] = blocks[0::2]
        view[1::2] += blocks[1::2]
        self._spring_view[...] += spring
        memory = self._memory
        if self._guide is not None:
            memory[self._guide[3]] += self._guide[1].reshape(-1)
        rhs = -r
        rows_k = []
        for (cols, row_pos), (rows, col_pos), dqh in zip(self._held_row, self._held_col, dq_held):
            rows_k.append((cols, memory[row_pos].copy()))
            if dqh != 0.0:
                rhs[rows] -= memory[col_pos] * dqh
        for (_, row_pos), (_, col_pos) in zip(self._held_row, self._held_col):
            memory[row_pos] = 0.0
            memory[col_pos] = 0.0
        memory[self._held_diagonal_band] = 1.0
        rhs[self.held] = dq_held
        t2 = time.process_time()
        _, _, dq, info = lapack.dgbsv(self._kl, self._kl, band, rhs, overwrite_ab=True, overwrite_b=True)
        if info != 0:
            raise np.linalg.LinAlgError(f"the system matrix is singular (LAPACK dgbsv info {info})")
        t3 = time.process_time()
        dlam = r[self.held] + np.array([k @ dq[cols] for cols, k in rows_k])
        self._count_time(t0, t1, t2, t3)
        return dq, dlam

    def _count_time(self, t0: float, t1: float, t2: float, t3: float) -> None:
        """Add one step's CPU times [s] to :attr:`time_parts_s`: forces t0–t1, assembly t1–t2,
        factorisation t2–t3, the glue after it until now."""
        parts = self.time_parts_s
        parts["forces"] += t1 - t0
        parts["assembly"] += t2 - t1
        parts["factorisation"] += t3 - t2
        parts["glue"] += time.process_time() - t3

    def _sparse_step(self, q, r, dq_held):
        """:meth:`_newton_step` on the CSR matrix of the chain's pattern, by SuperLU."""
        from scipy.sparse import csc_matrix
        from scipy.sparse.linalg import splu

        t0 = time.process_time()
        values = np.array(self.coupling.stiffness_values(q, self.time_s))
        values[self._spring_entries] += self.spring.block_values()
        if self._guide is not None:
            values[self._guide[2]] += self._guide[1].reshape(-1)
        t1 = time.process_time()
        rhs = -r
        rhs[self.held] = 0.0
        if np.any(dq_held):
            full = np.zeros(self.n)
            full[self.held] = dq_held
            rhs -= np.bincount(self._rows, weights=values * full[self.indices], minlength=self.n)
        rhs[self.held] = dq_held
        reduced = np.where(self._off, 0.0, values)
        reduced[self._held_diagonal] = 1.0
        t2 = time.process_time()
        # the CSR arrays read as CSC are the transpose: solve with it transposed
        try:
            dq = splu(csc_matrix((reduced, self.indices, self.indptr), shape=(self.n, self.n))).solve(rhs, trans="T")
        except RuntimeError as exc:
            raise np.linalg.LinAlgError(f"the system matrix is singular ({exc})") from exc
        t3 = time.process_time()
        dlam = r[self.held] + np.array([values[self.indptr[i]:self.indptr[i + 1]]
                                        @ dq[self.indices[self.indptr[i]:self.indptr[i + 1]]] for i in self.held])
        self._count_time(t0, t1, t2, t3)
        return dq, dlam

    # ---- the interface
    def start_from(self, q_sys) -> None:
        """Start the next :meth:`solve` from the system's ODE2 coordinates ``q_sys`` instead of
        Exudyn's initial configuration (the multipliers start at zero either way), so that a
        restart need not write them into Exudyn first; the solve writes its result as ever."""
        self._start = q_sys

    def solve(self, max_iterations, relative_tolerance, absolute_tolerance_N) -> NewtonOutcome:
        sd = self.mbs.systemData
        t0 = time.process_time()
        # Exudyn's solver starts from the initial configuration (it copies it to the current one),
        # or the start handed over; a copy, since the result is written into it
        start, self._start = self._start, None
        q_sys = np.array(sd.GetODE2Coordinates(configuration=exu.ConfigurationType.Initial) if start is None
                         else start, dtype=float)
        q = q_sys[self.index]
        lam = np.zeros(len(self.held))              # Exudyn starts Newton with zero multipliers
        loads = self._constant_forces()
        # the rig holds its coordinates at the start's position (a steady model's drive does not move)
        offset = np.zeros(len(self.held))
        self.time_parts_s["glue"] += time.process_time() - t0
        iterations = factorisations = 0
        converged, message = False, ""
        try:
            r = self._forces(q, lam, loads)
            c = q[self.held] - offset
            residual = initial = float(np.sqrt(_squared_norm(r) + c @ c))
            if initial <= absolute_tolerance_N:
                initial = 2.0 * absolute_tolerance_N     # at least one step
            while not converged and iterations < max_iterations:
                if iterations and time.process_time() > self.deadline_cpu_s:
                    message = f"Newton stopped at the CPU time limit after {iterations} iterations (residual {residual:.3g} N)"
                    break
                iterations += 1
                try:
                    dq, dlam = self._newton_step(q, r, c)
                except np.linalg.LinAlgError as exc:
                    message = f"Newton: {exc}"
                    break
                factorisations += 1
                q = q - dq
                lam = lam - dlam
                r = self._forces(q, lam, loads)
                c = q[self.held] - offset
                residual = float(np.sqrt(_squared_norm(r) + c @ c))
                if residual > initial and iterations <= 1:   # Exudyn's adaptInitialResidual
                    initial = residual
                if residual / initial <= relative_tolerance or residual <= absolute_tolerance_N:
                    converged = True
                elif not (np.all(np.isfinite(q)) and np.all(np.isfinite(lam))):
                    message = "Newton: the iterate is not finite (diverged)"
                    break
        except (ArithmeticError, ValueError) as exc:   # a degenerate state in the kernels
            message = f"{type(exc).__name__}: {exc}".strip()
            residual = float("inf")
            r = np.full(self.n, np.nan)
        if not converged and not message:
            message = f"Newton did not converge in {max_iterations} iterations (residual {residual:.3g} N)"
        t1 = time.process_time()
        q_sys[self.index] = q
        lam_sys = np.zeros(self.n_ae)
        lam_sys[self.ae] = lam
        sd.SetODE2Coordinates(q_sys)
        sd.SetAECoordinates(lam_sys)
        if np.all(np.isfinite(r)):
            self._residual = np.empty(self.n)
            self._residual[self.index] = r
        else:
            self._residual = np.full(self.n, np.nan)
        self.time_parts_s["glue"] += time.process_time() - t1
        return NewtonOutcome(converged, message, residual, iterations, factorisations)

    def system_residual(self) -> np.ndarray:
        return self._residual.copy()

    def evaluate_at(self, q_sys) -> None:
        """Make the system's ODE2 coordinates ``q_sys`` the state reached, without a Newton
        iteration: its residual becomes the last one (:meth:`equilibrium_residual_N`), the rig's
        multipliers those that balance its held rows (the reaction there is whatever holds them).
        ``q_sys`` must hold the rig's coordinates where a solve leaves them (as any point between
        two states a solve reached does). One force evaluation: what a shortened step costs
        (``SteadySolver.relax_one_iteration``)."""
        q_sys = np.array(q_sys, dtype=float)
        r = self._forces(q_sys[self.index], np.zeros(len(self.held)), self._constant_forces())
        lam_sys = np.zeros(self.n_ae)
        lam_sys[self.ae] = -r[self.held]
        r[self.held] = 0.0
        sd = self.mbs.systemData
        sd.SetODE2Coordinates(q_sys)
        sd.SetAECoordinates(lam_sys)
        self._residual = np.empty(self.n)
        self._residual[self.index] = r

    def equilibrium_residual_N(self) -> float:
        """Norm [N] of the last residual less the pseudo-time spring's force: the unregularised
        equilibrium's residual at the state reached (what ``SteadySolver.true_residual`` computes
        from :meth:`system_residual`, without reading the state back from Exudyn)."""
        if not np.all(np.isfinite(self._residual)):
            return float("nan")
        r = self._residual[self.index] - self._last_spring
        return float(np.sqrt(_squared_norm(r)))


def _held_rows(mbs, drives, where) -> tuple[np.ndarray, np.ndarray]:
    """The coordinates the rig's ``drives`` hold (their constraints' coordinates, as indices into the
    cables' coordinates through ``where``: system ODE2 index → cable order) and their constraints'
    multipliers (indices into the AE coordinates)."""
    sd = mbs.systemData
    held, ae = [], []
    for drive in drives:
        for c in drive.constraints:
            marker = mbs.GetMarker(mbs.GetObject(c)["markerNumbers"][1])
            held.append(where[mbs.GetNodeODE2Index(marker["nodeNumber"]) + int(marker["coordinate"])])
            ae.append(int(np.asarray(sd.GetObjectLTGAE(c))[0]))
    return np.asarray(held, dtype=np.int64), np.asarray(ae, dtype=np.int64)


def _squared_norm(r: np.ndarray) -> float:
    """r·r without BLAS: OpenBLAS splits a dot product of over 10 000 entries across its threads,
    whose start-up cost 7.7 ms of CPU per 77 000-entry residual on this loaded 2-core machine
    against 0.05 ms here (and made the last bits depend on the thread count)."""
    return float(np.einsum("i,i->", r, r))


def own_bundle_newton_unsupported(model, spring=None) -> str:
    """Why :class:`OwnBundleNewton` cannot solve ``model`` ("" when it can): it needs a steady
    bundle (:class:`exucable.model.bundle.BundleModel`) whose cables' forces are the compiled
    element's (``BundleModel.steady_force`` assembles the whole residual), the eye as coordinate
    constraints on the leading nodes, point forces on node positions as the only loads, and no
    item but the contacts', the spring's and the eye's."""
    if getattr(model, "n_cables", 1) < 2 or not hasattr(model, "steady_force"):
        return "not a bundle"
    if not model.steady_force_supported:
        return "the cables are Exudyn's elements (solver.cable_element = \"exudyn\")"
    mbs = model.mbs
    sd = mbs.systemData
    if len(sd.GetODE2Coordinates()) != model.ode2_index.size:
        return "coordinates other than the cables'"
    held = {int(c) for d in model.lead_drives for c in getattr(d, "constraints", ())}
    if len(held) != model.held_coordinates().size or model.trail_drive is not None:
        return "a rig other than the eye's coordinate constraints"
    known = {int(c.object) for c in model.wall_couplings} | {int(model.between_coupling.object)} \
        | ({int(spring.object)} if spring is not None else set())
    for i in range(sd.NumberOfObjects()):
        kind = mbs.GetObject(i)["objectType"]
        if kind == "ConnectorCoordinate" and i in held:
            continue
        if kind != "GenericODE2" or i not in known:
            return f"object {i} ({kind})"
    for i in range(sd.NumberOfLoads()):
        load = mbs.GetLoad(i)
        if load["loadType"] != "ForceVector" or load.get("loadVectorUserFunction", 0) not in (0, None) \
                or mbs.GetMarker(load["markerNumber"])["markerType"] != "NodePosition":
            return f"load {i} ({load['loadType']})"
    return ""


class OwnBundleNewton(OwnStaticNewton):
    """Exudyn's static Newton iterations (the module's notes) on a steady bundle's own assembled
    system: :class:`OwnStaticNewton`'s loop, with the residual of
    :meth:`exucable.model.bundle.BundleModel.steady_force`'s parts (each cable's wall coupling, the
    cable-cable coupling, the end loads) plus the pseudo-time spring, and the stiffness of its parts
    (the walls' element blocks, the pair kernel's exact Jacobian, the spring's blocks).

    The cables' coordinates are ordered node by node along the route, the cables interleaved
    (coordinate d of node k of cable c at 6 (k n_cables + c) + d): the elements couple the
    neighbouring stations and the pairs the stations beside one another, so the matrix is banded;
    its half bandwidths are read off each iteration's pattern (a pair contact reaches a few nodes
    along the other cable). ``linear_solver``: ``"banded"`` (LAPACK ``dgbsv`` on that order; SuperLU
    where the band would be over a quarter of the matrix) or ``"splu"`` (SuperLU, its own column
    order). Measured on the 100 m three-cable route (half bandwidths 53): dgbsv 1.8 ms with the band's
    assembly, SuperLU 3.9 ms (COLAMD) or 2.5 ms (the natural order) plus 1.0 ms for its CSC matrix
    (``benchmarks/bundle_iteration.py``). The couplings' evaluations are their cached ones
    (force and Jacobian in one kernel pass at a state, as Exudyn's user functions get them), so a
    Jacobian at a state whose residual was evaluated costs no kernel pass.

    A shortened step's evaluation (:meth:`OwnStaticNewton.evaluate_at`, the line search of
    ``SteadySolver.shorten_step``) is off unless ``line_search``: with it the continuation takes
    other steps than Exudyn's solver would (the up-bend's two steady states: the path picks one).
    """

    name = "exucable"

    #: kl (kl + ku + 1) above which the banded LU (work ∝ n kl (kl + ku)) gives way to SuperLU:
    #: 2.5 times the work of the route's band at kl = ku = 53 (1.8 ms), about SuperLU's 4.5 ms there
    BAND_WORK_LIMIT = 14000

    def __init__(self, model, spring, time_s: float = 1.0, linear_solver: str = "banded", checked: bool = False,
                 line_search: bool = False):
        why = "" if checked else own_bundle_newton_unsupported(model, spring)
        if why:
            raise ValueError(f"our static Newton cannot solve this bundle: {why}")
        if linear_solver not in ("banded", "splu"):
            raise ValueError(f"linear_solver must be 'banded' or 'splu', got {linear_solver!r}")
        if not line_search:
            self.evaluate_at = None          # SteadySolver.shorten_step reads None as "cannot"
        self.model, self.mbs, self.spring = model, model.mbs, spring
        self.time_s = float(time_s)
        self.linear_solver = linear_solver
        self.index = np.asarray(model.ode2_index, dtype=np.int64)
        n = self.n = self.index.size
        n_c = model.n_cables
        n1 = self.n1 = n // n_c
        n_el = n1 // 6 - 1
        # the interleaved order: cable coordinate k (cable c = k // n1, node, d) -> its place
        c, rest = np.divmod(np.arange(n), n1)
        node, d = np.divmod(rest, 6)
        self.order = 6 * (node * n_c + c) + d
        # the walls' element blocks (12 x 12 on the element's two nodes) and the spring's 3 x 3 blocks
        loc = 6 * np.arange(n_el)[:, None] + np.arange(12)[None, :]                    # (n_el, 12)
        first = n1 * np.arange(n_c)[:, None, None, None]
        wr = (first + loc[None, :, :, None] + 0 * loc[None, :, None, :]).reshape(-1)
        wc = (first + loc[None, :, None, :] + 0 * loc[None, :, :, None]).reshape(-1)
        self._fixed_rows = np.concatenate([wr, spring._rows.astype(np.int64)])
        self._fixed_cols = np.concatenate([wc, spring._cols.astype(np.int64)])
        self._fixed_prow, self._fixed_pcol = self.order[self._fixed_rows], self.order[self._fixed_cols]
        off = self._fixed_prow - self._fixed_pcol
        self._fixed_kl, self._fixed_ku = int(off.max()), int(-off.min())
        # the eye's held coordinates (cable order) and their constraints' multipliers (AE order)
        sd = self.mbs.systemData
        where = np.empty(n, dtype=np.int64)
        where[self.index] = np.arange(n)
        self.held, self.ae = _held_rows(self.mbs, model.lead_drives, where)
        self.n_ae = len(sd.GetAECoordinates())
        self._is_held = np.zeros(n, dtype=bool)
        self._is_held[self.held] = True
        self._loads = list(model._load_rows())
        self._guide = None
        self._residual = np.zeros(n)
        self._last_spring = np.zeros(n)
        self.time_parts_s = {"forces": 0.0, "assembly": 0.0, "factorisation": 0.0, "glue": 0.0}
        self._start = None

    def _forces(self, q, lam, loads) -> np.ndarray:
        """ODE2 residual rows in cable order: f(q) + C_qᵀλ (f: the walls' couplings, the pairs',
        the spring, the end loads)."""
        t0 = time.process_time()
        model, n1 = self.model, self.n1
        r = self.model.between_coupling._evaluate(q).generalized_force.copy()
        for i, coupling in enumerate(model.wall_couplings):
            r[i * n1:(i + 1) * n1] += coupling.force(q[i * n1:(i + 1) * n1], self.time_s, jacobian=True)
        spring = self.spring.force(q)
        r += spring
        r += loads
        r[self.held] += lam
        self._last_spring = spring
        self.time_parts_s["forces"] += time.process_time() - t0
        return r

    def stiffness_triplets(self, q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """K = -∂f/∂q of :meth:`_forces` at ``q`` as (rows, columns, values) in cable order, a
        pair repeating where parts overlap (K is their sum)."""
        model, n1 = self.model, self.n1
        walls = [coupling.stiffness_blocks(q[i * n1:(i + 1) * n1], self.time_s).reshape(-1)
                 for i, coupling in enumerate(model.wall_couplings)]
        J = model.between_coupling._evaluate(q).jacobian
        rows = np.concatenate([self._fixed_rows, np.repeat(np.arange(self.n), np.diff(J.indptr))])
        cols = np.concatenate([self._fixed_cols, J.indices])
        vals = np.concatenate(walls + [self.spring.block_values(), -J.data])
        return rows, cols, vals

    def _newton_step(self, q, r, dq_held):
        """As :meth:`OwnStaticNewton._newton_step`, in the interleaved order (the class notes)."""
        t0 = time.process_time()
        rows, cols, vals = self.stiffness_triplets(q)
        n_fixed = self._fixed_prow.size
        pr = np.concatenate([self._fixed_prow, self.order[rows[n_fixed:]]])
        pc = np.concatenate([self._fixed_pcol, self.order[cols[n_fixed:]]])
        t1 = time.process_time()
        rhs = -r
        rhs[self.held] = 0.0
        b = np.empty(self.n)
        b[self.order] = rhs
        ph = self.order[self.held]
        if self.linear_solver == "banded":
            off = pr[n_fixed:] - pc[n_fixed:]
            kl = max(self._fixed_kl, int(off.max()) if off.size else 0)
            ku = max(self._fixed_ku, int(-off.min()) if off.size else 0)
            if kl * (kl + ku + 1) <= self.BAND_WORK_LIMIT:
                return self._band_step(pr, pc, vals, b, r, ph, dq_held, kl, ku, (t0, t1))
            # cables slid far apart along the route (a diverging iterate): SuperLU's own order is cheaper
        # SuperLU on the triplets, the held rows and columns dropped and the identity put there
        held_r, held_c = self._is_held[rows], self._is_held[cols]
        if np.any(dq_held):
            full = np.zeros(self.n)
            full[self.held] = dq_held
            b[self.order] -= np.bincount(rows, weights=np.where(held_r, 0.0, vals * full[cols]), minlength=self.n)
        b[ph] = dq_held
        keep = ~(held_r | held_c)
        t2 = time.process_time()
        x = self._splu_solve(np.concatenate([pr[keep], ph]), np.concatenate([pc[keep], ph]),
                             np.concatenate([vals[keep], np.ones(ph.size)]), b)
        t3 = time.process_time()
        dq = x[self.order]
        in_held_row = np.flatnonzero(held_r)
        h_of = np.full(self.n, -1, dtype=np.int64)
        h_of[self.held] = np.arange(self.held.size)
        dlam = r[self.held] + np.bincount(h_of[rows[in_held_row]], weights=vals[in_held_row] * dq[cols[in_held_row]],
                                          minlength=self.held.size)
        self._count_time(t0, t1, t2, t3)
        return dq, dlam

    def _band_step(self, pr, pc, vals, b, r, ph, dq_held, kl, ku, times):
        """:meth:`_newton_step` by LAPACK's banded LU (``dgbsv``): the triplets (interleaved order,
        duplicates summed) into the band, the held rows and columns read and replaced by the identity."""
        n = self.n
        ld = 2 * kl + ku + 1
        top = kl + ku
        # LAPACK's band storage, Fortran order: entry (i, j) at row kl + ku + i - j of column j
        memory = np.bincount(pc * ld + top + pr - pc, weights=vals, minlength=ld * n)
        band = memory.reshape(n, ld).T
        rows_k = []
        for h, dqh in zip(ph, dq_held):
            j = np.arange(max(0, h - kl), min(n, h + ku + 1))          # row h's columns in the band
            row_pos = j * ld + top + h - j
            i = np.arange(max(0, h - ku), min(n, h + kl + 1))          # column h's rows in the band
            col_pos = h * ld + top + i - h
            rows_k.append((j, memory[row_pos].copy(), row_pos, col_pos))
            if dqh != 0.0:
                b[i] -= memory[col_pos] * dqh
        for _, _, row_pos, col_pos in rows_k:
            memory[row_pos] = 0.0
            memory[col_pos] = 0.0
        memory[ph * ld + top] = 1.0
        b[ph] = dq_held
        t2 = time.process_time()
        _, _, x, info = lapack.dgbsv(kl, ku, band, b, overwrite_ab=True, overwrite_b=True)
        if info != 0:
            raise np.linalg.LinAlgError(f"the system matrix is singular (LAPACK dgbsv info {info})")
        t3 = time.process_time()
        dlam = r[self.held] + np.array([k @ x[j] for j, k, _, _ in rows_k])
        self._count_time(times[0], times[1], t2, t3)
        return x[self.order], dlam

    def _splu_solve(self, rows, cols, vals, b) -> np.ndarray:
        """Solve the matrix of triplets (duplicates summed) by SuperLU."""
        from scipy.sparse import csc_matrix
        from scipy.sparse.linalg import splu

        try:
            return splu(csc_matrix((vals, (rows, cols)), shape=(self.n, self.n))).solve(b)
        except RuntimeError as exc:
            raise np.linalg.LinAlgError(f"the system matrix is singular ({exc})") from exc


def static_backend(model, spring, settings_of, choice: str):
    """The backend for ``[solver] static_solver`` = ``choice``: ours where the model allows it
    (:func:`own_newton_unsupported`; a bundle's :func:`own_bundle_newton_unsupported`), else
    Exudyn's; and why Exudyn's when ours was asked for."""
    if choice == "exucable":
        if getattr(model, "n_cables", 1) > 1:
            why = own_bundle_newton_unsupported(model, spring)
            if not why:
                return OwnBundleNewton(model, spring, checked=True), ""
            return ExudynStatic(model.mbs, settings_of), why
        why = own_newton_unsupported(model, spring)
        if not why:
            return OwnStaticNewton(model, spring, checked=True), ""
        return ExudynStatic(model.mbs, settings_of), why
    return ExudynStatic(model.mbs, settings_of), ""
