"""The multibody pull-in history (exucable.solve.pull_in): head tension against pulled length, one steady
state per head position, each solved from the last.

References: the capstan equation along a bend (paper Eq. 26: with the head θ into the bend the rig pulls
T2·e^(μθ)) and Eq. 25 on the incline (the head tension grows linearly with the pulled length), both closed
forms of a rope, where the fast examples' bending stiffness is negligible (bending length √(EJ/T) 1.2 cm
against the 0.5 m bend); the single steady run of the whole route for the last point. Coarse models
(the fast examples, 20 elements), a few seconds each.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from exucable.data import data_path
from exucable.errors import ScenarioError
from exucable.run import run_scenario
from exucable.scenario.specs import load_scenario
from exucable.solve.pull_in import pull_in_grid_m, steady_pull_in


def fast(name):
    return load_scenario(data_path("scenarios", "fast", f"{name}.toml"))


@pytest.fixture(scope="module")
def ex2():
    sc = fast("paper_ex2_bend90")
    return sc, steady_pull_in(sc, 8), steady_pull_in(sc, 8, warm_start=False)


def test_truncated_route_keeps_the_whole_conduit_before_the_head():
    conduit = fast("paper_ex2_bend90").build_conduit()
    cut = conduit.truncated(1.3)          # inside the bend
    c = cut.centreline
    assert c.length_m == pytest.approx(1.3, rel=1e-12)
    s = np.linspace(0.0, 1.3, 27)
    assert np.allclose(c.point(s), conduit.centreline.point(s), atol=1e-12)
    # the whole conduit's segment vertices up to the head, the last one on the centreline at the head
    seg, full = cut.segments, conduit.segments
    k = seg.count
    assert np.array_equal(seg.vertices_m[:k], full.vertices_m[:k])
    assert np.all(full.s_vertex_m[:k] < 1.3) and full.s_vertex_m[k] >= 1.3
    assert np.allclose(seg.vertices_m[-1], conduit.centreline.point(1.3), atol=1e-12)
    assert conduit.truncated(conduit.centreline.length_m) is conduit
    with pytest.raises(ValueError, match="truncated"):
        conduit.centreline.truncated(0.0)


def test_grid_has_the_piece_ends_and_no_near_duplicates():
    x = pull_in_grid_m(10.0, 5, [1.0, 4.0005, 6.0])
    assert x[0] == 0.0 and x[-1] == 10.0
    assert 1.0 in x and 6.0 in x and 4.0005 not in x      # 4.0005 lies within 1 % of a step of 4.0
    bend = pull_in_grid_m(10.0, 2, [4.0, 5.0], [(4.0, 5.0)])
    assert np.allclose(bend[(bend > 4.0) & (bend < 5.0)], [4.25, 4.5, 4.75])
    assert np.all(np.diff(x) > 0)


def test_history_along_a_bend_is_the_capstan(ex2):
    """Head θ into the bend: T2·e^(μθ) (T2 = 150 N, μ = 0.2, R = 0.5 m, 1 m straights, no gravity).
    Measured: at most 0.12 % off (head inside the bend, where the rig holds it past the cut; the whole
    pull's coarse-mesh error is -0.06 %); bound 0.2 %. Before the bend exactly the back tension."""
    sc, h, _ = ex2
    assert h.failed == 0 and h.status[0] == "exact"
    theta = np.clip((h.pulled_length_m - 1.0) / 0.5, 0.0, math.pi / 2)
    ref = 150.0 * np.exp(0.2 * theta)
    assert np.max(np.abs(h.pull_force_N / ref - 1.0)) < 2e-3
    before = h.pulled_length_m <= 1.0
    assert np.allclose(h.pull_force_N[before], 150.0, rtol=1e-6)
    # from the last state from the third point on (the first cable inside, 0.35 m, is all head region)
    assert h.warm_started[3:].all()


def test_warm_starts_reach_the_same_states_as_rope_starts(ex2):
    """The same equilibria from two starts: measured |warm/cold - 1| ≤ 3.6e-5 (the solves stop at a
    residual of 1e-6 of the largest tension, and a head held on the coarse mesh's bend has a soft
    lateral mode); bound 1e-4. Fewer Newton iterations from the last state."""
    _, warm, cold = ex2
    assert np.max(np.abs(warm.pull_force_N / cold.pull_force_N - 1.0)) < 1e-4
    assert warm.newton_iterations.sum() < cold.newton_iterations.sum()


def test_last_point_is_the_single_steady_run(ex2):
    """The last point is the whole route's model: from the rope start the very run (1e-9), from the
    last state within the solve's stop (measured 6.7e-6; bound 2e-5)."""
    sc, warm, cold = ex2
    F = run_scenario(sc, None, plots=False, mode="steady", quiet=True, error_bar=False).summary["pull_force_N"]
    assert cold.pull_force_N[-1] == pytest.approx(F, rel=1e-9)
    assert warm.pull_force_N[-1] == pytest.approx(F, rel=2e-5)


def test_history_up_an_incline_is_eq25():
    """Eq. 25: T(x) = w (sin 30° + μ cos 30°) x up the 30° incline with no back tension. Measured
    -0.004 %; bound 0.05 % (test_steady's bound for the whole pull)."""
    sc = fast("paper_ex1_incline")
    h = steady_pull_in(sc, 4)
    w = sc.cable.mass_per_length_kg_per_m * sc.gravity.g_m_per_s2
    ref = w * (0.5 + sc.contact.friction * math.cos(math.pi / 6)) * h.pulled_length_m
    assert h.failed == 0
    assert np.max(np.abs(h.pull_force_N[1:] / ref[1:] - 1.0)) < 5e-4


def test_reverse_pull_is_the_reversed_route():
    """The reverse pull of a symmetric bend has the forward pull's history."""
    sc = fast("paper_ex2_bend90")
    rev = steady_pull_in(dataclasses.replace(sc, pull=dataclasses.replace(sc.pull, direction="reverse")),
                         x_m=[1.3, 2.785])
    fwd = steady_pull_in(sc, x_m=[1.3, 2.785])
    assert rev.pull_force_N == pytest.approx(fwd.pull_force_N, rel=2e-4)


def test_bad_input_names_the_key():
    sc = fast("paper_ex2_bend90")
    with pytest.raises(ScenarioError, match="pull.force"):
        steady_pull_in(sc.replace(**{"pull.force": 200.0, "pull.back_tension": 0.0}), 4)
    with pytest.raises(ScenarioError, match="cable.length"):
        steady_pull_in(sc.replace(**{"cable.length": 2.0}), 4)
    with pytest.raises(ScenarioError, match="pull_in"):
        steady_pull_in(sc, x_m=[3.5])


def test_plan_with_the_steady_engine_writes_the_multibody_history(tmp_path):
    """``exucable plan --engine steady`` with ``pull.feed_from_reel``: the history is the multibody one, it
    ends at the direction's pull force (the same model, from another start) and stays within
    0.2 % of the rope beside it (the capstan, as above); the CSV carries both. The end: measured 2.9e-5
    after 60 solves each from the last (the fixture's 8: 6.7e-6); bound 1e-4, the floor of a steady run's
    own error bar (RESOLUTION_FLOOR · F, exucable/solve/error_bar.py)."""
    from exucable.commands.plan import write_plan
    from exucable.output.results import read_csv
    from exucable.plan.pull import plan_pull, plan_spec

    sc = fast("paper_ex2_bend90").replace(**{"pull.feed_from_reel": True})
    plan = plan_pull(sc, plan_spec(sc), engine="steady")
    for name in ("forward", "reverse"):
        d = plan["directions"][name]
        h = d["pull_in"]
        assert h["engine"] == "steady" and h["failed_points"] == 0
        assert h["pull_force_N"][-1] == pytest.approx(d["pull_force_N"], rel=1e-4)
        assert np.max(np.abs(np.array(h["pull_force_N"]) / np.array(h["rope_pull_force_N"]) - 1.0)) < 2e-3
    write_plan(tmp_path, plan, sc, "si")
    table = read_csv(tmp_path / "pull_in_forward.csv")
    assert list(table) == ["pulled_length_m", "pull_force_N", "rope_pull_force_N"]
    assert "multibody model" in (tmp_path / "report.html").read_text()
    # the rope engine's history stays the rope's
    assert plan_pull(sc, plan_spec(sc), engine="rope")["directions"]["forward"]["pull_in"]["engine"] == "rope"
