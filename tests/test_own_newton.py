"""Our own static Newton loop (``solver.static_solver = "exucable"``) against Exudyn's static solver.

The reference is Exudyn's ``MainSolverStatic`` on the same model: the same equations, Newton and
stop test (``exucable/solve/newton_system.py``'s notes), another linear solver (LAPACK's banded LU
with the rig's coordinates eliminated, against Eigen's SparseLU of the saddle-point system with
the multipliers). So the iterates agree to the round-off of two factorisations, not bit for bit.
Coarse models (the paper's fast examples, one industry route), a few seconds each.
"""

from __future__ import annotations

import numpy as np
import pytest

from exucable.data import data_path
from exucable.model.build import build_model
from exucable.run import run_scenario
from exucable.scenario.specs import load_scenario
from exucable.solve.newton_system import (ExudynStatic, OwnStaticNewton, own_newton_unsupported)
from exucable.solve.steady import SteadySolver, static_settings


def _scenario(path, **changes):
    sc = load_scenario(data_path("scenarios", *path.split("/")))
    return sc.replace(**{"solver.mode": "steady", **changes})


def _iterates(sc, backend: str, steps: int = 3):
    """Three pseudo-time steps of one Newton iteration each from the rope start (the spring
    anchored at the last state, its rate falling by 8 per step, as the continuation does): per
    step the converged flag, Newton's residual [N], the true residual [N], the absolute cable
    coordinates, the step's displacement and the rig's multipliers."""
    model = build_model(sc)
    solver = SteadySolver(model)
    if backend == "exudyn":
        solver.static = ExudynStatic(model.mbs, static_settings)
    assert type(solver.static).__name__ == {"exudyn": "ExudynStatic", "exucable": "OwnStaticNewton"}[backend]
    return one_iteration_steps(model, solver, steps)


def one_iteration_steps(model, solver, steps: int):
    """``steps`` one-iteration pseudo-time steps of ``solver`` from its stored state, each from the
    last (the rate falling by 8 per step): per step the tuple of :func:`_iterates`."""
    out = []
    rate = solver.c0
    for _ in range(steps):
        before = np.array(solver.store.saved[0])
        ok, _, residual = solver.pseudo_step(rate, solver.one_iteration_settings)
        sd = model.mbs.systemData
        q = np.array(sd.GetODE2Coordinates())
        out.append((ok, residual, solver.true_residual(), model.layout.coordinates.reshape(-1) + q[model.ode2_index],
                    q - before, np.array(sd.GetAECoordinates())))
        solver.store.save()
        rate /= 8.0
    return out


@pytest.mark.parametrize("path", ["fast/paper_ex2_bend90.toml", "fast/paper_ex1_incline.toml",
                                  "fast/paper_ex3_helix.toml"])
def test_one_iteration_is_exudyns(path):
    """From the same state, each one-iteration pseudo-time step reaches Exudyn's state: absolute
    coordinates within 1e-12 relative (measured ≤ 1e-16), the step itself within 1e-9 of its
    size (measured ≤ 1.3e-12 on Example 2, ≤ 1e-10 on Example 1, whose state is at equilibrium
    after the first step: the two LU factorisations' round-off, amplified by the stiff contact's
    condition number), the rig's multipliers and both residual norms within 1e-9
    (of the rig's force where the residual is at its round-off floor). Example 3 is a
    force-controlled pull: the sheave's stiffness and its damping at the start's rates, as
    Exudyn's static solver evaluates it (without the damping the sheave's node differed by 4e-9 m)."""
    sc = _scenario(path)
    a, b = _iterates(sc, "exudyn"), _iterates(sc, "exucable")
    for (ok_a, r_a, t_a, q_a, d_a, l_a), (ok_b, r_b, t_b, q_b, d_b, l_b) in zip(a, b):
        assert ok_a and ok_b
        assert np.linalg.norm(q_b - q_a) <= 1e-12 * np.linalg.norm(q_a)
        assert np.linalg.norm(d_b - d_a) <= 1e-9 * np.linalg.norm(d_a)
        assert np.linalg.norm(l_b - l_a) <= 1e-9 * np.linalg.norm(l_a)
        # a residual at the round-off floor (Example 1's steps end at 6e-9 N) is round-off itself:
        # compared against the rig's force instead
        scale = np.linalg.norm(l_a)
        assert abs(r_b - r_a) <= 1e-9 * max(r_a, scale) and abs(t_b - t_a) <= 1e-9 * max(t_a, scale)


@pytest.mark.parametrize("name", ["paper_ex2_bend90", "paper_ex3_helix"])
def test_exact_steps_and_the_load_ramp_are_exudyns(name):
    """The other phases of the continuation (exact pseudo-time steps of several Newton iterations,
    then the load ramp, which rescales the end loads, gravity and friction) through either solver:
    the same Newton counts and forces within 1e-9 (measured ≤ 1.1e-13 relative)."""
    from dataclasses import replace

    from exucable.solve.steady import SteadySettings, steady_forces

    sc = _scenario(f"fast/{name}.toml")
    out = {}
    for backend in ("exudyn", "exucable"):
        model = build_model(sc)
        solver = SteadySolver(model, replace(SteadySettings(), max_one_iteration_steps=0))
        if backend == "exudyn":
            solver.static = ExudynStatic(model.mbs, static_settings)
        ok, _ = solver.relax(1.0)
        exact = solver.newton_iterations
        status, _ = solver.ramp_loads("(a test: the ramp from the start)")
        solver.store.restore_as_initial()
        out[backend] = (ok, exact, status, solver.newton_iterations, np.array(steady_forces(model)))
    a, b = out["exudyn"], out["exucable"]
    assert a[:4] == b[:4] and a[0] and a[2] == "ok"
    assert np.all(np.abs(b[4] - a[4]) <= 1e-9 * np.abs(a[4]))


def test_a_handed_over_start_is_the_written_one_bit_for_bit():
    """A pseudo-time step whose start is handed to our Newton loop (``start_from``, what
    ``pseudo_step`` does) reaches the same state, multipliers and residual bit for bit as one whose
    start is first written into Exudyn's initial and current configurations; the stored state is
    not changed by the solve that starts from it."""
    sc = _scenario("fast/paper_ex2_bend90.toml")
    out = []
    for handed in (True, False):
        model = build_model(sc)
        solver = SteadySolver(model)
        assert isinstance(solver.static, OwnStaticNewton)
        saved = np.array(solver.store.saved[0])
        for rate in (solver.c0, solver.c0 / 8.0):
            solver.store.restore_as_initial(solver.static if handed else None)
            solver.spring.anchor_at(solver.store.saved[0][model.ode2_index])
            solver.spring.rate = rate
            ok, _, residual = solver.one_solve(solver.one_iteration_settings)
            assert ok
        assert np.array_equal(solver.store.saved[0], saved)
        sd = model.mbs.systemData
        out.append((np.array(sd.GetODE2Coordinates()), np.array(sd.GetAECoordinates()), residual))
    (q_a, l_a, r_a), (q_b, l_b, r_b) = out
    assert np.array_equal(q_a, q_b) and np.array_equal(l_a, l_b) and r_a == r_b


def test_banded_and_sparse_lu_take_the_same_step():
    """LAPACK's banded LU and SuperLU solve the same eliminated system: the same Newton step to
    1e-10 of its size (measured ~1e-13)."""
    sc = _scenario("fast/paper_ex2_bend90.toml")
    steps = {}
    for linear in ("banded", "splu"):
        model = build_model(sc)
        solver = SteadySolver(model)
        solver.static = OwnStaticNewton(model, solver.spring, linear_solver=linear)
        solver.pseudo_step(solver.c0, solver.one_iteration_settings)
        steps[linear] = np.array(model.mbs.systemData.GetODE2Coordinates()) - solver.store.saved[0]
    assert np.linalg.norm(steps["splu"] - steps["banded"]) <= 1e-10 * np.linalg.norm(steps["banded"])


@pytest.mark.parametrize("path", ["fast/paper_ex1_incline.toml", "fast/paper_ex2_bend90.toml",
                                  "fast/paper_ex3_helix.toml", "industry/commscope_conquest_run_a_h.toml"])
def test_whole_steady_runs_equal_exudyns(path, monkeypatch):
    """Whole steady runs (continuation, nested start, error bar): the pulling force (Example 3,
    force-controlled: the trailing tension) within 1e-9 relative of Exudyn's static solver's
    (measured 5e-13, 3e-15, 9e-16, 2e-14) with the same Newton count, where ours too rejects a
    spiking step at once (``max_backtracks = 0``: Exudyn's solver cannot shorten a step); with the
    shortened steps, the same force within the stop residual (1e-6 of the largest tension; measured
    ≤ 1.7e-9); the summary says which solver ran."""
    from dataclasses import replace

    from exucable.solve.steady import SteadySettings

    sc = _scenario(path)
    key = "trailing_tension_N" if sc.pull.force_N is not None else "pull_force_N"
    shortened = run_scenario(sc, None, plots=False).summary
    base = SteadySettings.from_solver
    monkeypatch.setattr(SteadySettings, "from_solver",
                        classmethod(lambda cls, solver: replace(base(solver), max_backtracks=0)))
    a = run_scenario(sc.replace(**{"solver.static_solver": "exudyn"}), None, plots=False).summary
    b = run_scenario(sc, None, plots=False).summary
    assert a["status"] == b["status"] == shortened["status"] == "ok"
    assert (a["static_solver"], b["static_solver"]) == ("exudyn", "exucable")
    assert abs(b[key] / a[key] - 1) < 1e-9
    assert b["newton_iterations"] == a["newton_iterations"]
    assert abs(shortened[key] / a[key] - 1) < 1e-6


def test_a_state_evaluated_without_newton_is_the_solves_own():
    """``evaluate_at`` (a shortened step's state, no Newton iteration) at the state a solve reached
    gives that solve's residual and rig multipliers: at a state converged to 1e-10 N, the same
    true residual within 1e-9 of the rig's force and the multipliers within 1e-9 relative."""
    model = build_model(_scenario("fast/paper_ex2_bend90.toml"))
    solver = SteadySolver(model)
    solver.pseudo_step(solver.c0 / 64.0, static_settings(tolerance=1e-14, max_iterations=30))
    sd = model.mbs.systemData
    q, lam, r = np.array(sd.GetODE2Coordinates()), np.array(sd.GetAECoordinates()), solver.true_residual()
    solver.static.evaluate_at(q)
    assert np.array_equal(np.array(sd.GetODE2Coordinates()), q)
    scale = np.linalg.norm(lam)
    assert np.linalg.norm(np.array(sd.GetAECoordinates()) - lam) <= 1e-9 * scale
    assert abs(solver.true_residual() - r) <= 1e-9 * scale


def test_models_ours_cannot_solve_keep_exudyns_solver():
    """Exudyn's cable element, several cables and an item our system does not know are not ours
    to solve: the steady solve uses Exudyn's static solver and says why."""
    from types import SimpleNamespace

    from exudyn.itemInterface import ObjectGenericODE2

    exu_element = build_model(_scenario("fast/paper_ex2_bend90.toml", **{"solver.cable_element": "exudyn"}))
    assert "exudyn" in own_newton_unsupported(exu_element)
    solver = SteadySolver(exu_element)
    assert isinstance(solver.static, ExudynStatic) and "exudyn" in solver.static_note
    assert own_newton_unsupported(SimpleNamespace(n_cables=3)) == "several cables"
    model = build_model(_scenario("fast/paper_ex2_bend90.toml"))
    assert own_newton_unsupported(model) == ""
    # a user's own generic object on a cable node: its forces would be missing from our system
    model.mbs.AddObject(ObjectGenericODE2(nodeNumbers=[model.cable.nodes[0]]))
    model.mbs.Assemble()
    assert "generic object" in own_newton_unsupported(model)
    assert isinstance(SteadySolver(model).static, ExudynStatic)
    with pytest.raises(ValueError, match="cannot solve this model"):
        OwnStaticNewton(exu_element, solver.spring)


def test_the_scenario_key_is_checked():
    from exucable.errors import ExucableError

    with pytest.raises(ExucableError, match="solver.static_solver"):
        _scenario("fast/paper_ex2_bend90.toml", **{"solver.static_solver": "eigen"})
    assert _scenario("fast/paper_ex2_bend90.toml").solver.static_solver == "exucable"


def test_the_true_residual_is_the_residual_less_the_spring():
    """Our backend's shortcut for the true residual equals the generic formula on its system
    residual (ODE2 rows less the spring's force at the state reached) to round-off."""
    model = build_model(_scenario("fast/paper_ex2_bend90.toml"))
    solver = SteadySolver(model)
    solver.pseudo_step(solver.c0, solver.one_iteration_settings)
    q = np.array(model.mbs.systemData.GetODE2Coordinates())
    r = solver.static.system_residual()
    r[model.ode2_index] -= solver.spring.force(q[model.ode2_index])
    assert abs(solver.true_residual() - np.linalg.norm(r)) <= 1e-12 * np.linalg.norm(r)


def test_a_failing_force_pass_is_a_failed_solve_not_an_exception(monkeypatch):
    """A degenerate state in the kernels (numba raises ZeroDivisionError at |r'| = 0) ends the
    static solve as not converged, with the cause in its message and a residual that no step
    accepts (as Exudyn's solver reports a failed solve)."""
    model = build_model(_scenario("fast/paper_ex2_bend90.toml"))
    solver = SteadySolver(model)
    calls = []

    def degenerate(q, t=0.0):
        calls.append(1)
        raise ZeroDivisionError("division by zero")

    monkeypatch.setattr(model.coupling, "force", degenerate)
    ok, message, residual = solver.pseudo_step(solver.c0, solver.one_iteration_settings)
    assert not ok and "ZeroDivisionError" in message and residual == np.inf and calls
    assert np.isnan(solver.static.equilibrium_residual_N())


@pytest.mark.slow
def test_the_benchmarks_comparison_runs():
    """``benchmarks/long_routes.py --compare-static-solver`` in its smoke mode (four child runs and
    the interleaved iteration; ~15 s CPU, hence slow): it prints both ways and the per-part line."""
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    done = subprocess.run([sys.executable, str(root / "benchmarks" / "long_routes.py"), "--quick", "--no-figures",
                           "--compare-static-solver"], capture_output=True, text=True, check=False, cwd=root)
    assert done.returncode == 0, done.stderr[-2000:]
    for fragment in ("CPU exucable/exudyn", "ours, banded LU", "ratio to Exudyn's", "factorisation"):
        assert fragment in done.stdout
