"""The steady solve's nested start: the coarse mesh solved first, the solved mesh started from its
state subdivided (exucable.solve.start.nested_start), the rope start as the fallback.

References: a cubic polynomial curve, which the ANCF cable's Hermite interpolation must reproduce
exactly (paper Sect. 2.2); and the same fine model solved from the rope start (the answer must not
depend on the start: within the stop tolerance, steady_residual × the rope's largest tension).
A 200 m route of the long-route benchmark's cable on the mesh rule: a few seconds.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from exucable.model.build import build_model
from exucable.run import run_scenario
from exucable.scenario.specs import parse_scenario
from exucable.solve.error_bar import combine
from exucable.solve.start import hermite_state, nested_start
from exucable.solve.steady import SteadySettings, solve_steady, steady_forces

from conftest import ROOT


def test_hermite_state_reproduces_a_cubic_curve_exactly():
    """r(X) = a + bX + cX² + dX³ has nodal values r, r' on any mesh; the Hermite interpolation gives
    r and r' everywhere (round-off: 1e-12 of the coefficients), so splitting an element is exact."""
    rng = np.random.default_rng(3)
    a, b, c, d = rng.normal(size=(4, 3))
    r = lambda x: a + np.outer(x, b) + np.outer(x**2, c) + np.outer(x**3, d)
    dr = lambda x: b + np.outer(2 * x, c) + np.outer(3 * x**2, d)
    X = np.sort(np.concatenate([[0.0, 2.0], rng.uniform(0.0, 2.0, 5)]))
    q = np.hstack([r(X), dr(X)])
    x = rng.uniform(0.0, 2.0, 50)
    got = hermite_state(q, X, x)
    assert np.allclose(got[:, :3], r(x), rtol=0, atol=1e-12)
    assert np.allclose(got[:, 3:], dr(x), rtol=0, atol=1e-12)
    # any state (not only a cubic): the subdivided mesh carries the coarse mesh's curve
    q = rng.normal(size=(len(X), 6))
    X_fine = np.sort(np.concatenate([X, 0.5 * (X[1:] + X[:-1])]))
    fine = hermite_state(q, X, X_fine)
    assert np.allclose(fine[::2], q, rtol=0, atol=1e-12)
    assert np.allclose(hermite_state(fine, X_fine, x), hermite_state(q, X, x), rtol=0, atol=1e-12)


def _route():
    """200 m of the long-route benchmark's cable (30 mm, 1.5 kg/m, EA 14 MN) in a 60 mm duct, two
    15° bends, gravity, μ 0.2, steady mode on the mesh rule."""
    area = math.pi * 0.015**2
    bend = {"bend": 15.0, "radius": 10.0}
    return parse_scenario({
        "name": "nested",
        "cable": {"radius": 0.015, "mass_per_length": 1.5, "youngs_modulus": 14e6 / area},
        "conduit": {"inner_radius": 0.030, "path": [{"straight": 65.0}, dict(bend, turn="left"), {"straight": 65.0},
                                                     dict(bend, turn="up"), {"straight": 65.0}]},
        "contact": {"friction": 0.2},
        "pull": {"speed": 0.1, "back_tension": 500.0},
        "gravity": {"g": 9.81},
        "solver": {"mode": "steady", "end_time": 1.0},
    }, ROOT, default_name="nested")


@pytest.fixture(scope="module")
def solved():
    """The coarse (rule's) mesh solved from the rope start, and a builder of the solved (2×) mesh."""
    sc = _route()
    coarse = build_model(sc)
    settings = SteadySettings.from_solver(sc.solver)
    out = solve_steady(coarse, settings=settings)
    assert out.status == "ok", out.message
    k = coarse.mesh.check_points_per_element
    return sc, coarse, settings, lambda: build_model(sc, refine=2.0, check_points_per_element=k,
                                                     references=coarse.start)


def test_the_fine_solve_from_the_coarse_state_gets_the_rope_starts_answer(solved):
    """Warm and cold starts of the solved mesh converge to one pulling force, within the stop
    tolerance (measured: 2.1e-5 N against 1.4e-3 N here, 7 Newton iterations against 98; 4.9e-7 N
    against 5.6e-3 N at 1 km), the warm one in fewer Newton iterations; the fine cable starts on the
    coarse curve with its leading node where the fine rig holds it."""
    sc, coarse, settings, fine = solved
    cold_model = fine()
    cold = solve_steady(cold_model, settings=settings)
    F_cold = steady_forces(cold_model)[0]
    warm_model = fine()
    start = nested_start(warm_model, coarse)
    assert start is not None
    lead = warm_model.ode2_index.reshape(-1, 6)[-1, :3]
    assert np.max(np.abs(start[0][lead])) < 1e-6      # the rig's constraint holds at the start
    warm = solve_steady(warm_model, settings=settings, warm_start=start)
    F_warm = steady_forces(warm_model)[0]
    tolerance_N = settings.steady_residual * warm_model.rope.max_tension_N
    assert cold.status == warm.status == "ok"
    assert cold.started_from == "rope" and warm.started_from == "coarse mesh"
    assert "from the coarse mesh's state" in warm.message
    assert abs(F_warm - F_cold) <= tolerance_N, (F_warm, F_cold, tolerance_N)
    assert warm.newton_iterations < cold.newton_iterations


def test_a_warm_start_that_fails_falls_back_to_the_rope_start(solved):
    """A start far off (the coarse state pushed 5 cm sideways, out through the duct's wall) with a
    budget of two steps: the solve says so, starts again from the rope and gets its answer."""
    sc, coarse, settings, fine = solved
    model = fine()
    ode2, ae = nested_start(model, coarse)
    off = ode2.copy()
    idx = model.ode2_index.reshape(-1, 6)
    off[idx[:-1, 1]] += 0.05        # every node but the rig's, across the route's first straight
    tight = SteadySettings(max_warm_start_steps=2, steady_residual=settings.steady_residual)
    out = solve_steady(model, settings=tight, warm_start=(off, ae))
    assert out.status == "ok" and out.started_from == "rope"
    assert "again from the rope start" in out.message
    cold_model = fine()
    solve_steady(cold_model, settings=settings)
    tolerance_N = settings.steady_residual * model.rope.max_tension_N
    assert abs(steady_forces(model)[0] - steady_forces(cold_model)[0]) <= tolerance_N


def test_a_steady_run_solves_the_coarse_mesh_first(solved):
    """``run_scenario`` on the mesh rule: the error bar's coarse value is the coarse solve's, and the
    solved mesh started from it; without the error bar the solved mesh starts from the rope."""
    sc, coarse, settings, fine = solved
    r = run_scenario(sc, None, plots=False)
    s = r.summary
    assert s["status"] == "ok"
    assert "from the coarse mesh's state" in s["message"]
    assert s["pull_force_uncertainty_N"] is not None
    n, m = s["mesh"]["elements"], coarse.mesh.elements
    assert n == 2 * m
    # the bar is Richardson's estimate against the coarse solve's value (the fixture's: the same
    # model solved alike, deterministic), with the stop residual's term and the wall's part
    solve_N = settings.steady_residual * coarse.rope.max_tension_N
    expected = (combine(s["pull_force_N"], float(steady_forces(coarse)[0]), n, m, solve_N)[1]
                + s["pull_force_uncertainty"]["wall_N"])
    assert s["pull_force_uncertainty_N"] == pytest.approx(expected, rel=1e-6)
    plain = run_scenario(sc, None, plots=False, error_bar=False)
    assert "from the coarse mesh's state" not in plain.summary["message"]
    tolerance_N = settings.steady_residual * coarse.rope.max_tension_N
    assert abs(plain.summary["pull_force_N"] - s["pull_force_N"]) <= tolerance_N


def test_the_nested_start_needs_coarse_elements_that_resolve_the_bend_ends():
    """Coarse elements longer than NESTED_MAX_BENDING_LENGTHS bending lengths start the solved mesh
    from the rope (10 km of the long-route benchmark: 17.9, where the coarse state was 4 mm off at the
    bends and the fine solve slower from it)."""
    from types import SimpleNamespace

    from exucable.solve.start import NESTED_MAX_BENDING_LENGTHS, resolves_bend_ends

    lam = 0.09
    assert resolves_bend_ends(SimpleNamespace(element_length_m=10.1 * lam, bending_length_m=lam))
    assert not resolves_bend_ends(SimpleNamespace(element_length_m=17.9 * lam, bending_length_m=lam))
    assert 10.1 < NESTED_MAX_BENDING_LENGTHS < 17.9
