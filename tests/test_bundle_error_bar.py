"""A bundle's steady error bar (exucable.solve.error_bar.bundle_error_bar): its parts add up, it is
stated (labelled) when the coarse solve is skipped, and it covers the error against a finer mesh."""

import math
import sys
from pathlib import Path

import pytest

from exucable.run import run_scenario
from exucable.solve.error_bar import (BUNDLE_ASSUMED_ORDER, BUNDLE_COARSE_COST, RESOLUTION_FLOOR, coarse_solve_skipped,
                                      onset_layer_part_N)

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "studies"))
from bundle_upbend_study import scenario  # noqa: E402  (the up-bend study's cases: 12 m, 10 elements)


@pytest.fixture(scope="module")
def down_bend():
    return run_scenario(scenario("down", "triangular", 0.0, 60.0)).summary


def test_parts_add_up_and_the_coarse_solve_is_the_answering_start(down_bend):
    s = down_bend
    b = s["pull_force_uncertainty"]
    assert s["status"] == "ok"
    assert b["mesh_N"] is not None and b["coarse_elements"] == s["mesh"]["elements"] // 2
    assert s["pull_force_uncertainty_N"] == pytest.approx(b["mesh_N"] + b["solve_N"] + b["layer_N"], rel=1e-12)
    # mesh = |F - F_coarse| / (2^p - 1) + floor |F|
    F = s["pull_force_N"]
    assert b["mesh_N"] == pytest.approx(abs(F - b["coarse_value_N"]) / (2.0**BUNDLE_ASSUMED_ORDER - 1.0)
                                        + RESOLUTION_FLOOR * abs(F), rel=1e-12)
    assert b["solve_N"] > 0.0 and b["layer_N"] >= 0.0 and b["cpu_time_s"] > 0.0
    assert f'from the start "{s["bundle"]["start"]}"' in s["pull_force_uncertainty_method"]
    assert "several" in s["pull_force_uncertainty_method"]


def test_a_bar_without_the_coarse_solve_is_the_solve_parts_and_says_so(down_bend):
    s = run_scenario(scenario("down", "triangular", 0.0, 60.0), error_bar=False).summary
    b = s["pull_force_uncertainty"]
    assert s["pull_force_N"] == pytest.approx(down_bend["pull_force_N"], rel=1e-12)     # the same solve
    assert b["mesh_N"] is None and b["coarse_value_N"] is None
    assert s["pull_force_uncertainty_N"] == pytest.approx(b["solve_N"] + b["layer_N"], rel=1e-12)
    assert s["pull_force_uncertainty_method"].startswith("solve parts only, mesh part not measured (not asked for")
    assert b["layer_N"] == down_bend["pull_force_uncertainty"]["layer_N"]


def test_a_coarse_solve_out_of_time_leaves_the_solve_parts_and_says_why():
    from exucable.solve.error_bar import bundle_error_bar
    from exucable.solve.steady import SteadySettings

    sc = scenario("down", "triangular", 0.0, 60.0)
    r = run_scenario(sc)
    s = r.summary
    bar = bundle_error_bar(sc, r.model, s["pull_force_N"], s["bundle"]["onset_layer"],
                           SteadySettings.from_solver(sc.solver), s["bundle"]["start"], cpu_left_s=1e-3,
                           weight_correction=s["bundle"]["weight_correction_factor"])
    assert bar.mesh_N is None and bar.coarse_elements == s["mesh"]["elements"] // 2
    assert bar.uncertainty_N == pytest.approx(s["pull_force_uncertainty"]["solve_N"] + s["pull_force_uncertainty"]["layer_N"])
    assert bar.method.startswith("solve parts only, mesh part not measured (second bundle steady solve")
    assert "failed" in bar.method or "no CPU time left" in bar.method


def test_without_a_cpu_limit_the_coarse_solve_has_the_fine_solves(down_bend):
    # the default limit: the solver's settings refuse an unlimited time, so it is the fine solve's own
    from exucable.solve.error_bar import bundle_error_bar
    from exucable.solve.steady import SteadySettings

    sc = scenario("down", "triangular", 0.0, 60.0)
    r = run_scenario(sc, error_bar=False)
    s = r.summary
    bar = bundle_error_bar(sc, r.model, s["pull_force_N"], s["bundle"]["onset_layer"],
                           SteadySettings.from_solver(sc.solver), s["bundle"]["start"],
                           weight_correction=s["bundle"]["weight_correction_factor"])
    assert bar.mesh_N is not None
    assert bar.coarse_value_N == pytest.approx(down_bend["pull_force_uncertainty"]["coarse_value_N"], rel=1e-9)
    assert bar.uncertainty_N == pytest.approx(down_bend["pull_force_uncertainty_N"], rel=1e-9)


@pytest.mark.parametrize("left_s, fine_s, skipped", [(10.0, 40.0, True), (39.0, 40.0, True), (45.0, 40.0, False), (5.0, 4.0, False)])
def test_the_coarse_solve_waits_for_its_budget(left_s, fine_s, skipped):
    why = coarse_solve_skipped(True, left_s, fine_s)
    assert (why is not None) == skipped
    if skipped:
        assert "solver.steady_time_limit" in why and f"{BUNDLE_COARSE_COST * fine_s:.3g} s" in why


def test_the_onset_layer_part_is_the_richardson_step():
    stage = lambda s, f: {"layer_m": s, "converged": True, "pull_force_N": f}   # noqa: E731
    at_zero = {"layer_m": 0.0, "layer_error_N": 0.0,
               "stages": [stage(4e-6, 100.4), stage(2e-6, 100.2), stage(0.0, 100.05)]}
    assert onset_layer_part_N(at_zero) == pytest.approx(0.05)      # F0 = 2·100.2 − 100.4 = 100.0
    assert onset_layer_part_N({"layer_m": 2e-6, "layer_error_N": 0.2, "stages": []}) == 0.2
    assert math.isinf(onset_layer_part_N({"layer_m": 5e-4, "layer_error_N": None, "stages": []}))
    assert onset_layer_part_N(None) == 0.0


@pytest.mark.slow
@pytest.mark.parametrize("bend, arrangement, cable_friction", [("down", "triangular", 0.0), ("down", "cradled", 0.0),
                                                               ("left", "cradled", 0.0), ("up", "triangular", 0.0),
                                                               ("left", "triangular", 0.3)])
def test_the_bar_covers_the_error_against_a_mesh_four_times_finer(bend, arrangement, cable_friction):
    # studies/bundle_error_bar.py: the reference is the same case on the mesh refined 4 times
    sc = scenario(bend, arrangement, cable_friction, 60.0)
    ref = run_scenario(sc, refine=4.0, error_bar=False).summary["pull_force_N"]
    for refine in (1.0, 2.0):
        s = run_scenario(sc, refine=refine).summary
        assert s["status"] == "ok"
        assert abs(s["pull_force_N"] - ref) <= s["pull_force_uncertainty_N"], refine
