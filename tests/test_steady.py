"""Steady sliding in one static solve (solver.mode = "steady"): against closed forms, the dynamic
run, and its own reaction; continuation; bad input.

References: the capstan equation on one bend (paper Eq. 26, reference/paper_values.toml), Eq. 25
on the incline, a short dynamic run of the same small spatial route, and the leading end's
tension EA·ε. Coarse models (seconds each); the paper-fidelity comparison is `exucable validate`.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from exucable.errors import ExucableError
from exucable.data.reference_values import load_reference
from exucable.run import run_scenario
from exucable.output.results import read_csv
from exucable.scenario.specs import load_scenario
from exucable.data import data_path

from conftest import make_scenario


def fast(name):
    return load_scenario(data_path("scenarios", "fast", f"{name}.toml"))


def test_steady_bend_matches_capstan(tmp_path):
    """Example 2 (coarse): T1 = T2 e^(μπ/2) = 205.37 N. Measured -0.08 % (the coarse mesh's
    error; the dynamic run of the same mesh is +0.06 %); bound 0.15 %."""
    r = run_scenario(fast("paper_ex2_bend90"), tmp_path, plots=False, mode="steady")
    s = r.summary
    T1 = load_reference()["example2"]["pull_force_N"]
    assert s["status"] == "ok" and s["mode"] == "steady"
    assert abs(s["pull_force_N"] / T1 - 1) < 1.5e-3
    assert abs(s["trailing_tension_N"] - 150.0) < 1e-3
    # the same result files as a dynamic run, summary.json last with the mode
    for f in ("summary.json", "history.csv", "tension_profile.csv", "contact_profile.csv", "rope_profile.csv"):
        assert (tmp_path / f).is_file(), f
    assert json.loads((tmp_path / "summary.json").read_text())["mode"] == "steady"
    # one history row per converged pseudo-time step (numbered 1, 2, ...), the last one the result
    h = r.history
    assert len(h["time_s"]) >= 1 and np.array_equal(h["time_s"], np.arange(1, len(h["time_s"]) + 1))
    assert h["pull_force_N"][-1] == pytest.approx(s["pull_force_N"])
    # and so does the file (its contact columns, which pseudo-time steps do not record, left out:
    # an empty column once cut every row of it)
    written = read_csv(tmp_path / "history.csv")
    assert list(written) == ["time_s", "pull_force_N", "trailing_tension_N", "max_tension_N"]
    assert np.array_equal(written["pull_force_N"], h["pull_force_N"])


def test_steady_incline_matches_eq25():
    """Example 1 (coarse): T(50 m) = w(sin 30° + μ cos 30°)·50 m (Eq. 25); measured 0.005 %,
    bound 0.05 %; and the profile T(x) within 0.05 % of T(50 m) everywhere."""
    r = run_scenario(fast("paper_ex1_incline"), None, plots=False, mode="steady")
    ref = load_reference()["example1"]
    assert r.summary["status"] == "ok"
    assert abs(r.summary["pull_force_N"] / ref["pull_force_N"] - 1) < 5e-4
    x = np.asarray(r.tension_profile["x_m"])
    N = np.asarray(r.tension_profile["tension_N"])
    assert np.max(np.abs(N - ref["tension_slope_N_per_m"] * x)) < 5e-4 * ref["pull_force_N"]


SMALL_SPATIAL = dict(
    cable={"radius": 0.0025, "density": 1000.0, "youngs_modulus": 1.0e9, "elements": 24},
    conduit={"inner_radius": 0.0035, "segments_per_bend": 24,
             "path": [{"straight": 0.6}, {"bend": 90.0, "radius": 0.5, "turn": "left"},
                      {"bend": 45.0, "radius": 0.5, "turn": "up"}, {"straight": 0.6}]},
    contact={"friction": 0.3, "check_points_per_element": 20},
    pull={"speed": 0.1, "back_tension": 20.0},
    gravity={"g": 9.8},
    solver={"end_time": 1.0, "step": 0.01, "steady_stop": True},
)


def test_steady_agrees_with_a_short_dynamic_run_on_a_small_spatial_route():
    """A 90° horizontal then 45° vertical bend with gravity, 24 elements: the dynamic run stops
    once steady (0.2 s window, 0.1 %) after ~0.33 s; measured difference 0.015 % with a dynamic
    scatter of 0.03 %; bound 0.1 % (half the issue's 0.2 % on the paper's examples)."""
    sc = make_scenario(**SMALL_SPATIAL)
    st = run_scenario(sc, None, plots=False, mode="steady").summary
    dy = run_scenario(sc, None, plots=False, mode="dynamic").summary
    assert st["status"] == "ok" and dy["steady"]
    assert abs(st["pull_force_N"] / dy["pull_force_N"] - 1) < 1e-3


def test_pulling_force_is_the_leading_end_tension():
    """The rig's reaction (a Lagrange multiplier, whose sign the static solver flips) is the
    tension EA·ε at the leading end (within 0.1 %: the end element's axial force, Eq. 24)."""
    r = run_scenario(make_scenario(**SMALL_SPATIAL), None, plots=False, mode="steady")
    N_lead = float(np.asarray(r.tension_profile["tension_N"])[-1])
    assert r.summary["pull_force_N"] > 0
    assert abs(r.summary["pull_force_N"] / N_lead - 1) < 1e-3


def test_force_controlled_pull_holds_the_trailing_end():
    """Example 3 (the paper's 80 elements, coarse check points): the pull is given (40 N), the
    trailing tension is the result; capstan with the exact helix angle 11.3848 N, measured
    +0.064 % (2026-11-29; 160 elements +0.073 %), bound 0.2 %. The fast variant's former 40
    elements (0.33 m, 12 bending lengths) were not: -0.24 % with the rig 10 bending lengths out,
    +0.22 % at 5 (an element straddles the exit either way)."""
    r = run_scenario(fast("paper_ex3_helix").replace(**{"cable.elements": 80}), None, plots=False,
                     mode="steady")
    s = r.summary
    assert s["status"] == "ok" and s["pull_force_N"] == pytest.approx(40.0)
    T2 = load_reference()["example3"]["back_tension_N"]
    assert abs(s["trailing_tension_N"] / T2 - 1) < 2e-3


def test_a_route_that_needs_continuation():
    """Where the pseudo-time steps at the full loads fail, the loads are ramped (friction,
    gravity, end forces) from the start. Forced here by allowing the full-load attempt from the
    start only 2 pseudo-time steps (Example 2 needs 9), with one Newton iteration each and then
    with exact steps: both fail, the load continuation (default budget per stage) converges, and
    to the same pulling force (within 1e-5)."""
    from dataclasses import replace

    import exucable.solve.steady as ss
    from exucable.model.build import build_model

    sc = fast("paper_ex2_bend90")
    sc = replace(sc, solver=replace(sc.solver, mode="steady"))
    direct = ss.solve_steady(build_model(sc))
    assert direct.status == "ok" and "continuation" not in direct.message

    stages = []
    short = replace(ss.SteadySettings(), max_one_iteration_steps=2, max_pseudo_steps_total=2)

    class Budgeted(ss.SteadySolver):
        def at_scale(self, lam):
            # the first two stages are the full-load attempts from the start (one-iteration
            # steps, then exact ones): 2 steps each; then the default budget
            self.settings = short if len(stages) < 2 else ss.SteadySettings()
            stages.append(lam)
            super().at_scale(lam)

    out = Budgeted(build_model(sc), short).solve()
    assert out.status == "ok", out.message
    assert "continuation in the load scale" in out.message
    assert stages[:2] == [1.0, 1.0] and len(stages) >= 4 and stages[-1] == 1.0
    assert abs(out.history.pull_force_N[-1] / direct.history.pull_force_N[-1] - 1) < 1e-5


def test_pseudo_time_budget_is_on_progress_not_on_the_count():
    """A solve that keeps making progress is not cut off: Example 2 (coarse) takes 13 pseudo-time
    steps (11 converged), its residual halving at least every 4, so a budget of 5 steps *without
    halving* lets it finish at the full loads (a budget of 5 steps in all would have sent it to the
    load continuation), to the pulling force of the default budget. (The exact-step continuation:
    the one-iteration steps tried before it are switched off.)"""
    from dataclasses import replace

    import exucable.solve.steady as ss
    from exucable.model.build import build_model

    exact_steps = ss.SteadySettings(max_one_iteration_steps=0)
    sc = fast("paper_ex2_bend90")
    sc = replace(sc, solver=replace(sc.solver, mode="steady"))
    default = ss.solve_steady(build_model(sc), settings=exact_steps)
    out = ss.solve_steady(build_model(sc), settings=replace(exact_steps, max_pseudo_steps=5))
    assert out.status == "ok" and "continuation" not in out.message, out.message
    assert out.steps > 5
    assert out.history.pull_force_N[-1] == pytest.approx(default.history.pull_force_N[-1], rel=1e-12)


def test_one_iteration_steps_reach_the_exact_step_answer():
    """The one-iteration pseudo-time steps stop on the true residual (the solver's residual minus
    the spring force), not on the spring force of an inexact step: on Example 2 (coarse) they
    stop at the default tolerance without falling back to the exact steps (one Newton iteration
    per step), and their pulling force is that of the exact-step continuation converged to 1/1000
    of the stop tolerance within 1e-8, closer than the exact-step continuation at the default
    tolerance (measured: 4e-10 and 4.5e-8 relative; 29 against 55 Newton iterations)."""
    from dataclasses import replace

    import exucable.solve.steady as ss
    from exucable.model.build import build_model

    sc = fast("paper_ex2_bend90")
    sc = replace(sc, solver=replace(sc.solver, mode="steady"))
    one = ss.solve_steady(build_model(sc))
    assert one.status == "ok" and one.newton_iterations == one.steps, one.message
    default = ss.SteadySettings()
    tight = ss.solve_steady(build_model(sc), settings=replace(
        default, max_one_iteration_steps=0, steady_residual=default.steady_residual / 1000.0))
    assert tight.status == "ok"
    F_one, F_tight = one.history.pull_force_N[-1], tight.history.pull_force_N[-1]
    assert abs(F_one / F_tight - 1) < 1e-8


def test_a_rejected_step_restarts_from_the_saved_kernel_pass(monkeypatch):
    """A rejected pseudo-time step restarts from the saved state with the kernel pass made when
    the state was reached: Example 2 (coarse), its spiking steps rejected at once
    (``max_backtracks = 0``), rejects some of its one-iteration steps and makes one kernel pass per
    Newton iteration plus the start's (36 passes before), with the same iterates bit for bit as
    without the reuse."""
    from dataclasses import replace

    import exucable.solve.steady as ss
    from exucable.model.build import build_model
    from exucable.model.coupling import ContactCoupling

    sc = fast("paper_ex2_bend90")
    sc = replace(sc, solver=replace(sc.solver, mode="steady"))
    settings = replace(ss.SteadySettings(), max_backtracks=0)
    model = build_model(sc)
    out = ss.solve_steady(model, settings=settings)
    assert out.status == "ok" and out.steps > len(out.history.pull_force_N)   # some steps were rejected
    assert model.coupling.kernel_evaluations == out.newton_iterations + 1
    monkeypatch.setattr(ContactCoupling, "offer_evaluation", lambda self, evaluation: None)
    again = build_model(sc)
    without = ss.solve_steady(again, settings=settings)
    assert again.coupling.kernel_evaluations > model.coupling.kernel_evaluations
    assert without.history.pull_force_N == out.history.pull_force_N
    assert without.newton_iterations == out.newton_iterations


def test_a_spiking_step_is_shortened_before_it_is_rejected():
    """A one-iteration step whose residual grows more than ``reject_growth``-fold is first halved
    along itself (``SteadySolver.shorten_step``): Example 4 (coarse) keeps shortened steps, each
    length one kernel pass and no Newton iteration (passes = Newton iterations + shortened lengths
    + the start's), converges in fewer Newton iterations than when it rejects them at once
    (measured 19 against 33), and its pulling force is the one of a solve to 1/1000 of the stop
    residual within 1e-9 (measured 5e-11)."""
    from dataclasses import replace

    import exucable.solve.steady as ss
    from exucable.model.build import build_model

    sc = fast("paper_ex4_spatial")
    sc = replace(sc, solver=replace(sc.solver, mode="steady"))
    default = ss.SteadySettings()
    runs = {}
    for tag, settings in (("shortened", default), ("rejected", replace(default, max_backtracks=0)),
                          ("tight", replace(default, steady_residual=default.steady_residual / 1000.0))):
        model = build_model(sc)
        runs[tag] = (ss.solve_steady(model, settings=settings), model.coupling.kernel_evaluations)
    (out, passes), (rejected, _), (tight, _) = runs["shortened"], runs["rejected"], runs["tight"]
    assert out.status == rejected.status == tight.status == "ok"
    assert out.backtracks > 0 and rejected.backtracks == 0
    assert passes == out.newton_iterations + out.backtracks + 1
    assert out.newton_iterations < rejected.newton_iterations
    assert abs(out.history.pull_force_N[-1] / tight.history.pull_force_N[-1] - 1) < 1e-9


def test_exact_steps_stop_above_the_round_off_floor():
    """What stalled the fine industry meshes (Gera 2032, MachineCalcs 4064 elements): the residual has a
    round-off floor that grows with the mesh (2e-5 N at Gera's 2032 elements), the exact pseudo-time
    steps' Newton tolerance was below it (1e-3 × the stop tolerance, and 1e-8 of the initial residual),
    every exact step failed and the solve was reported as "continuation stalled at load scale 0".

    Reproduced on Example 2 (coarse, 20 elements, floor measured 1.8e-10 N): the relative Newton
    tolerance made unreachable (1e-30) and the stop tolerance tightened to 5e-10 × 205 N = 1.0e-7 N.
    With the former share (1e-3: Newton to 1e-10 N, below the floor) the solve stalls and says where,
    why and which keys to change; with the default ``exact_newton_share`` (1e-8 N) it converges to the default solve's
    pulling force (within 1e-6). (The exact-step continuation: the one-iteration steps tried before
    it are switched off.)"""
    from dataclasses import replace

    import exucable.solve.steady as ss
    from exucable.model.build import build_model

    sc = fast("paper_ex2_bend90")
    sc = replace(sc, solver=replace(sc.solver, mode="steady"))
    exact_steps = ss.SteadySettings(max_one_iteration_steps=0)
    default = ss.solve_steady(build_model(sc), settings=exact_steps)
    assert default.status == "ok", default.message
    # one continuation stage is enough to show it
    floor = replace(exact_steps, newton_tolerance=1e-30, min_continuation_step=0.5, steady_residual=5e-10)
    out = ss.solve_steady(build_model(sc), settings=floor)
    assert out.status == "ok", out.message
    assert out.history.pull_force_N[-1] == pytest.approx(default.history.pull_force_N[-1], rel=1e-6)

    stalled = ss.solve_steady(build_model(sc), settings=replace(floor, exact_newton_share=1e-3))
    assert stalled.status == "failed"
    for part in ("continuation stalled at load scale", "round-off floor", "Newton residual stayed at",
                 "`cable.element_length`", '`solver.mode = "dynamic"`'):
        assert part in stalled.message, (part, stalled.message)


def test_steady_mode_refuses_a_start_without_pretension():
    with pytest.raises(ExucableError, match="solver.pretension"):
        make_scenario(solver={"end_time": 0.2, "step": 0.01, "mode": "steady", "pretension": False})


def test_unknown_mode_names_the_key():
    with pytest.raises(ExucableError, match="solver.mode"):
        make_scenario(solver={"end_time": 0.2, "step": 0.01, "mode": "quasi"})


def _one_coil(elements):
    """Fig. 12's one coil (velocity pull, back tension 10 N) with coarse check points."""
    sc = load_scenario(data_path("scenarios", "paper_ex3_helix.toml")).replace(**{
        "pull.force": None, "pull.back_tension": 10.0, "conduit.path[1].helix_turns": 1,
        "conduit.segments_per_bend": 100, "cable.elements": elements})
    return run_scenario(sc, None, plots=False, mode="steady", check_points_per_element=20)


def test_steady_helix_converges_under_refinement():
    """The defect this guards: with the rig pinning the leading end flush with the helix's top,
    inside the bending boundary layer √(EJ/T) = 4 cm, the steady error grew as the mesh resolved
    that layer (40/80/160 elements: +0.23/+0.64/+0.72 % against the capstan 18.7442 N). With the
    rig 10 bending lengths out (measured -0.041/-0.049 %, 2026-11-29) both meshes are within
    0.1 % and within 0.02 % of each other."""
    from exucable.quasistatic.closed_forms import capstan_out_N, helix_turning_angle_rad

    T1 = capstan_out_N(10.0, 0.1, helix_turning_angle_rad(1.0, 1.0, 0.05))
    coarse, fine = (_one_coil(n).summary for n in (40, 80))
    for s in (coarse, fine):
        assert s["status"] == "ok"
        assert abs(s["pull_force_N"] / T1 - 1) < 1e-3
    assert abs(fine["pull_force_N"] / coarse["pull_force_N"] - 1) < 2e-4


def test_steady_lead_out_clears_the_last_bend():
    """The rig sits 10 bending lengths past the last bend's end: all of it laid beyond the exit
    after a helix, nothing after a straight that long (Example 2's 1 m exit straight)."""
    from exucable.model.layout import LEAD_OUT_BENDING_LENGTHS, steady_lead_out_m

    helix = load_scenario(data_path("scenarios", "paper_ex3_helix.toml")).build_conduit().centreline
    bend = load_scenario(data_path("scenarios", "paper_ex2_bend90.toml")).build_conduit().centreline
    lam = np.sqrt(0.0307 / 18.74)
    assert steady_lead_out_m(helix, 0.0307, 18.74) == pytest.approx(LEAD_OUT_BENDING_LENGTHS * lam)
    assert steady_lead_out_m(bend, 0.0307, 18.74) == 0.0
    assert steady_lead_out_m(helix, 0.0, 18.74) == 0.0


def test_steady_lead_out_given_is_used_and_bounded():
    """``solver.steady_lead_out`` (what `exucable validate` sets to the dynamic run's extent) lays
    the leading end that far past the exit, and one as long as the cable is refused by its key."""
    from exucable.errors import ModelError
    from exucable.model.layout import initial_layout

    sc = load_scenario(data_path("scenarios", "fast", "paper_ex2_bend90.toml")).replace(
        **{"solver.mode": "steady", "solver.steady_lead_out": 0.05})
    assert initial_layout(sc).lead_out_m == pytest.approx(0.05)
    with pytest.raises(ModelError, match=r"solver\.steady_lead_out"):
        initial_layout(sc.replace(**{"solver.steady_lead_out": sc.cable_length_m}))


def test_steady_settings_are_frozen_and_checked():
    """The solver's rules are a frozen value (a variant is ``dataclasses.replace``), and a
    nonsensical one is refused naming its field."""
    import dataclasses

    from exucable.errors import SolverError
    from exucable.solve.steady import SteadySettings

    s = SteadySettings()
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.rate_fall = 16.0
    assert dataclasses.replace(s, rate_fall=16.0).rate_fall == 16.0 and s.rate_fall == 8.0
    for bad in ({"rate_fall": -1.0}, {"steady_residual": float("nan")}, {"max_pseudo_steps": 2.5},
                {"max_one_iteration_steps": -1}):
        (name, value), = bad.items()
        with pytest.raises(SolverError, match=f"SteadySettings.{name} = "):
            SteadySettings(**bad)
    assert SteadySettings(max_one_iteration_steps=0).max_one_iteration_steps == 0   # 0 skips that phase


def test_the_steady_residual_key_maps_to_the_settings():
    """``[solver] steady_residual`` becomes :attr:`SteadySettings.steady_residual`; the solver
    object and the ``solve_steady(tolerance=...)`` entry point give the same iterates (Example 2,
    coarse, at a looser stop), and a solver solves once."""
    from dataclasses import replace

    from exucable.errors import SolverError
    from exucable.model.build import build_model
    from exucable.solve.steady import SteadySettings, SteadySolver, solve_steady

    sc = fast("paper_ex2_bend90")
    sc = replace(sc, solver=replace(sc.solver, mode="steady", steady_residual=1e-5))
    settings = SteadySettings.from_solver(sc.solver)
    assert settings == SteadySettings(steady_residual=1e-5)
    solver = SteadySolver(build_model(sc), settings)
    out = solver.solve()
    assert out.status == "ok", out.message
    again = solve_steady(build_model(sc), tolerance=1e-5)
    assert again.history.pull_force_N == out.history.pull_force_N
    assert again.newton_iterations == out.newton_iterations and again.steps == out.steps
    with pytest.raises(SolverError, match="runs once"):
        solver.solve()
