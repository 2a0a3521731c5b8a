"""Does one ObjectGenericODE2 spanning all cable nodes make Exudyn's assembly grow faster than the
elements? (issue 15, part 4: 0.07 → 0.16 ms per element per Newton iteration from 100 to 400
elements on the 100 m route), measured in one run.

A straight ANCF cable of n elements with, as the contact coupling, mass-free ``ObjectGenericODE2``
user objects whose force function returns a constant vector and whose Jacobian function returns
sparse triplets with the coupling's block pattern (12×12 per element): either none, one object over
all nodes (as ``exucable.model.coupling``), or one per block of ``--block`` elements. No contact
kernel: what is timed is Exudyn (residual and Jacobian assembly via the solver's own
``ComputeNewtonResidual`` / ``ComputeNewtonJacobian``) plus the unavoidable Python calls.

    nice .venv/bin/python benchmarks/generic_split.py
    nice .venv/bin/python benchmarks/generic_split.py --elements 100 400 1600 --block 50

Prints ms per residual and per Jacobian, and per element, for each layout and size (median of
``--repeat`` timings of 20 evaluations each).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import exudyn as exu  # noqa: E402
from exudyn.itemInterface import NodePointSlope1, ObjectANCFCable  # noqa: E402

from exucable.contact import block_sparsity  # noqa: E402
from exucable.model.generic import add_user_force_object  # noqa: E402
from exucable.solve.dynamic import quiet_sparse  # noqa: E402


class _Block:
    """User functions of one mass-free GenericODE2 over ``n_el`` consecutive elements."""

    def __init__(self, n_el: int, seed: int):
        rows, cols = block_sparsity(n_el)
        self.n = 6 * (n_el + 1)
        rng = np.random.default_rng(seed)
        lin = rows.astype(np.int64) * self.n + cols
        unique, self.inverse = np.unique(lin, return_inverse=True)
        self.rows = (unique // self.n).astype(float)
        self.cols = (unique % self.n).astype(float)
        self.n_unique = unique.size
        self.blocks = rng.standard_normal(rows.size)
        self.force_vector = np.zeros(self.n)

    def force(self, mbs, t, item, q, q_t):
        return self.force_vector

    def jacobian(self, mbs, t, item, q, q_t, f_q, f_v):
        # the same work per call as ContactCoupling._jacobian: sum duplicates, drop zeros, triplets
        vals = np.bincount(self.inverse, weights=f_q * self.blocks, minlength=self.n_unique)
        nz = vals != 0.0
        m = exu.MatrixContainer()
        m.SetWithSparseMatrix(np.column_stack([self.rows[nz], self.cols[nz], vals[nz]]), self.n, self.n, False)
        return m


def build(n_el: int, block: int | None):
    """A straight cable of ``n_el`` elements; ``block``: None (no user object), 0 (one over all
    nodes) or the number of elements per user object."""
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    L = 0.25
    nodes = [mbs.AddNode(NodePointSlope1(referenceCoordinates=[i * L, 0, 0, 1, 0, 0])) for i in range(n_el + 1)]
    for i in range(n_el):
        mbs.AddObject(ObjectANCFCable(nodeNumbers=[nodes[i], nodes[i + 1]], length=L, massPerLength=0.02,
                                      axialStiffness=2e4, bendingStiffness=3e-3, useReducedOrderIntegration=2,
                                      visualization={"show": False, "radius": 0.0, "color": [-1.0] * 4}))
    keep = []
    if block is not None:
        size = n_el if block == 0 else block
        for b0 in range(0, n_el, size):
            b1 = min(n_el, b0 + size)
            user = _Block(b1 - b0, seed=b0)
            keep.append(user)
            add_user_force_object(mbs, nodes[b0:b1 + 1], user.n, user.force, user.jacobian)
    mbs.Assemble()
    return sc, mbs, keep


def time_case(n_el: int, block, repeat: int) -> tuple[float, float]:
    """Median ms per residual and per Jacobian."""
    sc, mbs, keep = build(n_el, block)
    s = exu.SimulationSettings()
    s.timeIntegration.numberOfSteps = 1
    s.timeIntegration.endTime = 1e-3
    s.timeIntegration.verboseMode = 0
    quiet_sparse(s)
    solver = exu.MainSolverImplicitSecondOrder()
    solver.InitializeSolver(mbs, s)
    res, jac = [], []
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(20):
            solver.ComputeNewtonResidual(mbs, s)
        res.append((time.perf_counter() - t0) / 20)
        t0 = time.perf_counter()
        for _ in range(20):
            solver.ComputeNewtonJacobian(mbs, s)
        jac.append((time.perf_counter() - t0) / 20)
    solver.FinalizeSolver(mbs, s)
    return 1e3 * statistics.median(res), 1e3 * statistics.median(jac)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--elements", type=int, nargs="+", default=[100, 200, 400, 800])
    ap.add_argument("--block", type=int, default=50, help="elements per user object when split")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    print(f"# Exudyn assembly with GenericODE2 user objects — load average {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores\n")
    print("| elements | layout | residual [ms] | Jacobian [ms] | Jacobian per element [ms] |")
    print("|---|---|---|---|---|")
    layouts = {"cable only": None, "one object over all nodes": 0, f"one object per {args.block} elements": args.block}
    for n in args.elements:
        for name, block in layouts.items():
            r, j = time_case(n, block, args.repeat)
            print(f"| {n} | {name} | {r:.3f} | {j:.3f} | {j / n:.4f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
