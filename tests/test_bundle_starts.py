"""Several cables' steady solve from a sequence of starts (``[solver] bundle_starts``,
exucable/solve/bundle_starts.py): the first start that solves gives the answer, exactly as a solve
from that start alone; a start that another follows gives up where its dynamic relaxation stalls and
the next one solves in the time left; one start given is the only one tried; a name that is no start
is refused naming the key. The 30° up-bend of tests/test_bundle_upbend.py (10 elements, 1-2 s a solve)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import exucable as xc
from exucable.errors import ScenarioError, SolverError
from exucable.model.bundle import BUNDLE_STARTS, build_bundle_model
from exucable.scenario.fields import FIELDS
from exucable.solve.bundle_starts import solve_bundle_starts
from exucable.solve.steady import SteadySettings, solve_steady


def scenario(starts=None):
    route = xc.Route(inner_radius=0.05).straight(3.0).bend(30, radius=5.0, turn="up").straight(3.0)
    extra = {} if starts is None else {"bundle_starts": starts}
    return xc.Scenario(route=route,
                       cable=xc.Cable(radius=0.015, density=2000.0, youngs_modulus=2e8, count=3,
                                      arrangement="triangular"),
                       contact=xc.Contact(friction=0.3, check_points_per_element=8),
                       pull=xc.Pull(speed=0.1, back_tension=300.0), gravity=xc.Gravity(g=9.81),
                       solver=xc.Solver(mode="steady", steady_lead_out=0.0, steady_time_limit=30.0, **extra))


def alone(sc, start: str) -> float:
    """The pull [N] of a solve from ``start`` alone (``build_bundle_model`` + ``solve_steady``)."""
    model = build_bundle_model(sc, start_path=start)
    settings = replace(SteadySettings.from_solver(sc.solver), bundle_starts=(start,))
    out = solve_steady(model, settings=settings)
    assert out.status == "ok", out.message
    return float(np.sum(model.pull_shares_N()))


def test_the_key_names_the_model_starts():
    field = next(f for f in FIELDS if f.key == "solver.bundle_starts")
    assert set(field.choices) == set(BUNDLE_STARTS)
    assert tuple(field.default) == SteadySettings().bundle_starts == ("clearance", "statics_own")


@pytest.mark.parametrize("starts, where", [(["rope"], "solver.bundle_starts[0]"), (["clearance", ""], "solver.bundle_starts[1]"),
                                           ([], "solver.bundle_starts"), ("clearance", "solver.bundle_starts")])
def test_a_start_that_is_none_is_refused_naming_the_key(starts, where):
    with pytest.raises(ScenarioError) as err:
        scenario(starts)
    assert where in str(err.value)
    with pytest.raises(SolverError, match="bundle_starts"):
        SteadySettings(bundle_starts=("clearance", "rope"))


def test_the_first_start_that_solves_gives_its_own_answer():
    sc = scenario()
    res = xc.run(sc)
    assert res.status == "ok", res.message
    b = res.summary.bundle
    assert b["start"] == "clearance"
    assert [a["start"] for a in b["starts_tried"]] == ["clearance"]
    # the sequence's first solve is the single start's, step for step
    assert res.pull_force_N == pytest.approx(alone(sc, "clearance"), rel=1e-12)


def test_a_start_given_up_hands_over_to_the_next():
    sc = scenario()
    model = build_bundle_model(sc)
    # a stall rule that stops the first start's relaxation at once: the up-bend needs it
    settings = replace(SteadySettings.from_solver(sc.solver), bundle_start_stall_steps=1, bundle_start_stall_work=1.0)
    seen = []
    out = solve_bundle_starts(sc, model, settings=settings, on_start=lambda name, m: seen.append((name, m)))
    assert out.start == "statics_own"
    # the caller is told each start's model before its solve: the first is the one it built, the
    # last the one the answer is in (what a budget that stops the sequence must report)
    assert [name for name, _ in seen] == ["clearance", "statics_own"]
    assert seen[0][1] is model and seen[-1][1] is out.model
    assert [(a.start, a.status) for a in out.attempts] == [("clearance", "failed"), ("statics_own", "ok")]
    assert "given up for the next start" in out.attempts[0].message
    assert out.outcome.status == "ok" and out.outcome.message.startswith('from the start "statics_own" ("clearance" gave up')
    assert out.outcome.newton_iterations == sum(a.newton_iterations for a in out.attempts)
    # the later start's solve is its own, the clearance attempt leaves nothing behind in it
    assert float(np.sum(out.model.pull_shares_N())) == pytest.approx(alone(sc, "statics_own"), rel=1e-12)


def test_one_start_given_is_the_only_one_tried():
    res = xc.run(scenario(["statics_own"]))
    assert res.status == "ok", res.message
    assert res.summary.bundle["start"] == "statics_own"
    assert [a["start"] for a in res.summary.bundle["starts_tried"]] == ["statics_own"]


def test_the_dynamic_runs_steady_start_takes_the_same_sequence():
    """A dynamic bundle run's steady start (``solver.start_from = "steady"``) is the state a steady
    run of the same scenario reports: from the first start that solves, here the one start given."""
    from exucable.solve.start import bundle_steady_start

    sc = scenario(["statics_own"])
    first = bundle_steady_start(sc)
    assert first.layouts is not None, first.message
    assert first.pull_force_N == pytest.approx(alone(sc, "statics_own"), rel=1e-12)
