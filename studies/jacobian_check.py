"""Is the Newton Jacobian exact? A finite-difference check of the whole Exudyn residual.

Runs a scenario with Exudyn's own solver and, at chosen Newton iterations, compares the system
Jacobian that Exudyn assembled (mass term, ANCF elements, contact coupling, start-up damper,
constraints, with the solver's own factors) against central differences of the solver's own
residual along the solver's own update direction: a unit Newton increment Δ moves
q by Δ, q̇ by γ'Δ and q̈ by β'Δ (Arnold & Brüls 2007, as in Exudyn's ``ComputeNewtonUpdate``), so
column j of the exact Jacobian is (r(x + εΔ_j) − r(x − εΔ_j)) / 2ε.

Prints per checked iteration: the relative error of the Jacobian, where it sits (rows of
positions, slopes, constraints), and the **predicted contraction** ρ(I − J⁻¹ J_fd): the factor by
which an exact Newton step would fall short. ρ ≈ 0.2 would explain a linear convergence with
contraction 0.2; ρ ≪ 0.1 says the Jacobian is exact and the slowness comes from elsewhere
(non-smoothness: check points entering and leaving contact between iterations). Run it with a
tiny ``--eps`` (1e-12: the derivative) and a larger one (1e-8: how far the residual stays linear).

    nice .venv/bin/python studies/jacobian_check.py scenarios/paper_ex4_spatial.toml \
        --from-time 0.0022 --checks 2 --eps 1e-12
    nice .venv/bin/python studies/jacobian_check.py --quick   # smoke run: the fast Example 2, one check
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import exudyn as exu  # noqa: E402

from exucable.model.build import build_model  # noqa: E402
from exucable.scenario.specs import load_scenario  # noqa: E402
import exucable.solve.dynamic as solve  # noqa: E402


def residual(solver, mbs, settings) -> np.ndarray:
    solver.ComputeNewtonResidual(mbs, settings)
    return np.array(solver.GetSystemResidual())


def fd_jacobian(solver, mbs, settings, eps: float) -> np.ndarray:
    """Central differences of the solver's residual along its own update directions (ODE2 columns
    and the Lagrange multipliers' columns)."""
    sd = mbs.systemData
    cur = exu.ConfigurationType.Current
    q0 = np.array(sd.GetODE2Coordinates(cur))
    v0 = np.array(sd.GetODE2Coordinates_t(cur))
    a0 = np.array(sd.GetODE2Coordinates_tt(cur))
    lam0 = np.array(sd.GetAECoordinates(cur))
    h = solver.it.currentStepSize
    beta, gamma = solver.newmarkBeta, solver.newmarkGamma
    beta_p = (1.0 - solver.alphaM) / (h * h * beta * (1.0 - solver.alphaF))
    gamma_p = gamma / (h * beta)
    scal_ae = 1.0 / (beta * h * h)
    n2, nae = q0.size, lam0.size
    r0 = np.array(solver.GetSystemResidual())
    J = np.zeros((r0.size, n2 + nae))

    def at(dq, dlam):
        sd.SetODE2Coordinates(q0 + dq, cur)
        sd.SetODE2Coordinates_t(v0 + gamma_p * dq, cur)
        sd.SetODE2Coordinates_tt(a0 + beta_p * dq, cur)
        sd.SetAECoordinates(lam0 + scal_ae * dlam, cur)
        return residual(solver, mbs, settings)

    zq, zl = np.zeros(n2), np.zeros(nae)
    for j in range(n2):
        e = zq.copy()
        e[j] = eps
        J[:, j] = (at(e, zl) - at(-e, zl)) / (2 * eps)
    for j in range(nae):
        e = zl.copy()
        e[j] = eps
        J[:, n2 + j] = (at(zq, e) - at(zq, -e)) / (2 * eps)
    at(zq, zl)                       # back to the solver's state
    # (the solver computes the residual anew right after this hook)
    return J


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenario", nargs="?", help="scenario file (required unless --quick)")
    ap.add_argument("--from-time", type=float, default=0.0022, help="check iterations of steps after this time [s]")
    ap.add_argument("--checks", type=int, default=3, help="number of Newton iterations to check")
    ap.add_argument("--eps", type=float, default=1e-8, help="finite-difference step along Δ [m, -]")
    ap.add_argument("--exudyn", action="append", default=[], metavar="KEY=VALUE",
                    help="dotted attribute of SimulationSettings.timeIntegration")
    ap.add_argument("--save", default=None, help="save J, J_fd and r to SAVE_k.npz")
    ap.add_argument("--quick", action="store_true",
                    help="smoke run: scenarios/fast/paper_ex2_bend90.toml, one check after 1 ms")
    args = ap.parse_args(argv)
    if args.quick:
        args.scenario = args.scenario or str(ROOT / "scenarios" / "fast" / "paper_ex2_bend90.toml")
        args.from_time, args.checks = 0.001, 1
    if not args.scenario:
        ap.error("scenario: give a scenario file (or --quick)")
    sc = load_scenario(args.scenario)
    model = build_model(sc)
    mbs = model.mbs
    settings = solve.solver_settings(sc.solver)
    for kv in args.exudyn:
        key, value = kv.split("=", 1)
        obj = settings.timeIntegration
        *head, last = key.split(".")
        for h in head:
            obj = getattr(obj, h)
        setattr(obj, last, {"True": True, "False": False}.get(value, type(getattr(obj, last))(value)))
    settings.timeIntegration.endTime = args.from_time + 0.05
    settings.timeIntegration.verboseMode = 0
    solver = exu.MainSolverImplicitSecondOrder()
    done = []

    def check(mbs_, t, newton_it, discontinuous_it):
        # called before the residual of Newton iteration `newton_it`: the state is the iterate
        if t < args.from_time or newton_it < 1 or len(done) >= args.checks:
            return
        r = residual(solver, mbs, settings)
        solver.ComputeNewtonJacobian(mbs, settings)   # Exudyn's Jacobian at this iterate
        J = np.array(solver.GetSystemJacobian())
        t0 = time.perf_counter()
        Jfd = fd_jacobian(solver, mbs, settings, args.eps)
        n = Jfd.shape[1]
        J = J[:Jfd.shape[0], :n]
        err = J - Jfd
        rel = np.linalg.norm(err) / np.linalg.norm(Jfd)
        n2 = solver.GetODE2size()
        pos = np.zeros(n2, bool)
        pos[np.arange(n2) % 6 < 3] = True
        parts = {"position rows": np.r_[pos, np.zeros(n - n2, bool)],
                 "slope rows": np.r_[~pos, np.zeros(n - n2, bool)],
                 "constraint rows": np.r_[np.zeros(n2, bool), np.ones(n - n2, bool)]}
        where = ", ".join(f"{k} {np.linalg.norm(err[m]) / np.linalg.norm(Jfd):.1e}" for k, m in parts.items())
        rho = np.max(np.abs(np.linalg.eigvals(np.eye(n) - np.linalg.solve(J, Jfd))))
        # the step an exact Newton would take from here, against Exudyn's
        step_exudyn = np.linalg.solve(J, r)
        step_fd = np.linalg.solve(Jfd, r)
        dstep = np.linalg.norm(step_exudyn - step_fd) / np.linalg.norm(step_fd)
        print(f"t = {t:.6f} s, h = {solver.it.currentStepSize:.3g} s, before residual {newton_it}, "
              f"|r| = {np.linalg.norm(r):.3e}: |J - J_fd|/|J_fd| = {rel:.2e} ({where}); "
              f"rho(I - J^-1 J_fd) = {rho:.3g}; |dx - dx_fd|/|dx_fd| = {dstep:.2e}  "
              f"[{time.perf_counter() - t0:.0f} s]", flush=True)
        done.append((t, rel, rho))
        if args.save:
            sd = mbs.systemData
            cur = exu.ConfigurationType.Current
            np.savez(f"{args.save}_{len(done)}.npz", J=J, Jfd=Jfd, r=r, t=t, h=solver.it.currentStepSize,
                     q=np.array(sd.GetODE2Coordinates(cur)), v=np.array(sd.GetODE2Coordinates_t(cur)))

    mbs.SetPreNewtonResidualUserFunction(check)
    print(f"# {Path(args.scenario).name}: Exudyn's Jacobian against central differences (eps {args.eps:g}), "
          f"{args.checks} Newton iterations after t = {args.from_time} s\n", flush=True)

    def stop_when_done(mbs_, t):
        return len(done) < args.checks

    mbs.SetPostStepUserFunction(stop_when_done)
    solver.SolveSystem(mbs, settings)
    return 0


if __name__ == "__main__":
    sys.exit(main())
