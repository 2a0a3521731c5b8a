"""References for the cable's extent at a given time, and the steady detector that follows them.

A velocity-controlled pull moves the cable out of its conduit: on a straight incline of angle θ,
with the cable filling the conduit at t = 0, after pulling out x = v t the closed form (paper Eq. 25)
is F = T_b + w (μ cos θ + sin θ)(L − x) + w sin θ · x (the part beyond the exit hangs on the exit
line). Exact to the rope solver's 1e-11, so 1e-9 relative.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from exucable.quasistatic.extent import pull_force_references_N, reference_drift_N_per_s
from exucable.scenario.specs import parse_scenario
from exucable.post.tension import detect_steady_state

W_KG_PER_M, G, MU, TB, L = 1.0, 9.81, 0.3, 50.0, 20.0


def incline(theta_deg: float):
    t = math.radians(theta_deg)
    data = {
        "cable": {"radius": 0.009, "mass_per_length": W_KG_PER_M, "youngs_modulus": 5e8, "elements": 20},
        "conduit": {"inner_radius": 0.019, "heading": [math.cos(t), 0.0, math.sin(t)], "path": [{"straight": L}]},
        "contact": {"friction": MU},
        "pull": {"speed": 0.2, "back_tension": TB},
        "gravity": {"g": G},
        "solver": {"end_time": 2.0, "step": 1e-2},
    }
    sc = parse_scenario(data, ".")
    return sc, sc.build_conduit()


@pytest.mark.parametrize("theta_deg", [0.0, 15.0, -10.0])
def test_references_follow_the_cable_out_of_an_incline(theta_deg):
    sc, conduit = incline(theta_deg)
    t = math.radians(theta_deg)
    w = W_KG_PER_M * G
    for x in (0.0, 0.7):
        refs = pull_force_references_N(sc, conduit, x)
        expected = TB + w * (MU * math.cos(t) + math.sin(t)) * (L - x) + w * math.sin(t) * x
        assert refs["rope_pull_force_N"] == pytest.approx(expected, rel=1e-9)
        # on a straight the cable lies on the floor: the rope with clearance is the same
        assert refs["rope_clearance_pull_force_N"] == pytest.approx(expected, rel=1e-9)
    # the drift: the tail's friction and lift leave, the head's weight pulls along the exit line
    assert reference_drift_N_per_s(sc, conduit, 2.0) == pytest.approx(-w * MU * math.cos(t) * 0.2, rel=1e-9)


def test_steady_detector_follows_an_expected_drift():
    t = np.linspace(0.01, 1.0, 100)
    wobble = 0.01 * np.sin(40.0 * t)
    force = 300.0 - 2.5 * t + wobble           # drifting by 0.8 %/s: never steady at 0.1 % per 0.2 s
    assert not detect_steady_state(t, force, 0.2, 1e-3).steady
    st = detect_steady_state(t, force, 0.2, 1e-3, expected_drift_N_per_s=-2.5)
    assert st.steady and st.from_s == pytest.approx(0.01)
    assert st.mean_N == pytest.approx(np.mean(force), rel=1e-12)   # the force's own mean, at the mean time
    assert st.std_N == pytest.approx(np.std(wobble), rel=1e-9)


def test_a_pull_starts_on_the_rope_with_clearance():
    # The up-bend of the issue: the cable starts where the rope with clearance hangs, off the floor over
    # its free span before the bend (the old start pressed it on the floor there, and it rang as the span
    # formed), with that rope's tension.
    from exucable.model.build import build_model
    from exucable.quasistatic.clearance import solve_rope_with_clearance

    data = {
        "cable": {"radius": 0.009, "mass_per_length": 1.0, "youngs_modulus": 5e8, "bending_stiffness": 0.079,
                  "elements": 60},
        "conduit": {"inner_radius": 0.019, "path": [{"straight": 5.0}, {"bend": 60.0, "radius": 5.0, "turn": "up"},
                                                    {"straight": 3.0}]},
        "contact": {"friction": 0.3},
        "pull": {"speed": 0.2, "back_tension": 200.0},
        "gravity": {"g": 9.81},
        "solver": {"mode": "dynamic", "end_time": 0.5, "step": 1e-2},
    }
    sc = parse_scenario(data, ".")
    model = build_model(sc)
    centre = model.conduit.centreline
    free = solve_rope_with_clearance(centre, 0.01, 0.3, 9.81, 200.0)
    lay = model.layout
    z_rope = np.interp(lay.node_s_m, free.s_conduit_m, free.position_m[:, 2])
    span = (lay.node_s_m > 4.4) & (lay.node_s_m < 4.9)      # inside the free span (4.2 … 5.2 m)
    assert np.any(span)
    # off the floor (z = −0.01 m there) and within 0.5 mm of the rope with clearance's height
    assert np.all(lay.position_m[span, 2] > -0.009)
    np.testing.assert_allclose(lay.position_m[span, 2], z_rope[span], atol=5e-4)


def test_a_second_mesh_reuses_the_rope_references():
    """The rope, the rope with clearance and the lead-out depend on the scenario, not on the mesh:
    the solved mesh's layout takes them from the coarse one's (steady mode builds both) and is then
    the same, bit for bit, as a layout that solved them again."""
    from exucable.model.layout import initial_layout

    data = {
        "cable": {"radius": 0.009, "mass_per_length": W_KG_PER_M, "youngs_modulus": 5e8},
        "conduit": {"inner_radius": 0.019, "path": [{"straight": 6.0}, {"bend": 30.0, "radius": 2.0, "turn": "up"},
                                                    {"straight": 6.0}]},
        "contact": {"friction": MU},
        "pull": {"speed": 0.2, "back_tension": TB},
        "gravity": {"g": G},
        "solver": {"mode": "steady", "end_time": 1.0},
    }
    sc = parse_scenario(data, ".")
    coarse = initial_layout(sc)
    assert coarse.rope_clearance is not None
    k = coarse.mesh.check_points_per_element
    reused = initial_layout(sc, refine=2.0, check_points_per_element=k, references=coarse)
    solved = initial_layout(sc, refine=2.0, check_points_per_element=k)
    assert reused.rope is coarse.rope and reused.rope_clearance is coarse.rope_clearance
    assert reused.lead_out_m == solved.lead_out_m
    assert reused.mesh.elements == solved.mesh.elements > coarse.mesh.elements
    np.testing.assert_array_equal(reused.cable.coordinates, solved.cable.coordinates)
    np.testing.assert_array_equal(reused.rope.tension_N, solved.rope.tension_N)
    np.testing.assert_array_equal(reused.rope_clearance.offset_m, solved.rope_clearance.offset_m)
