"""The linearised stiff cable in a duct (exucable.quasistatic.duct_beam) against its closed-form limits.

The capstan (EJ = 0, no gravity, paper Eq. 26), a level straight's μwL (Eq. 25), the stiff bend's
point load √(EJ T)/ρ at λ = √(EJ/T) into the bend (exucable.quasistatic.stiff_bend at first order), the
rope with clearance (exucable.quasistatic.clearance, an independent solver of the EJ → 0 problem), the
up-bend's free-span term μ EJ/(ρ X₀) (exucable.quasistatic.stiff_bend.free_span_stiffness_N) and
convergence in h. Short routes, coarse enough for seconds each.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from exucable.quasistatic.duct_beam import duct_route, gravity_change_of_stiffness, solve_duct_beam

TIGHT = [{"straight": 0.6}, {"bend": 90.0, "radius": 0.5, "turn": "left"}, {"straight": 0.6}]


def test_rope_limit_is_the_capstan():
    s = solve_duct_beam(TIGHT, 0.015, 0.5, 0.0, 100.0, 0.0, 0.005)
    # the penalty sinks the cable ~1e-5 c into the wall; the cell-averaged curvature at the bend's
    # ends is second order in h
    assert s.pull_force_N == pytest.approx(100.0 * math.exp(0.5 * math.pi / 2), rel=2e-5)


def test_level_straight_with_weight_is_mu_w_L():
    s = solve_duct_beam([{"straight": 3.0}], 0.01, 0.4, 9.81, 200.0, 5.0, 0.01)
    assert s.pull_force_N == pytest.approx(200.0 + 0.4 * 9.81 * 3.0, rel=1e-7)   # Newton's tolerance
    assert np.allclose(s.offset_m[:, 1], -0.01, atol=1e-6)        # on the floor


def test_no_friction_keeps_the_tension_through_a_vertical_bend():
    """μ = 0: the pull is the back tension plus the weight lifted, w·ΔH (steady sliding's energy)."""
    path = [{"straight": 1.0}, {"bend": 60.0, "radius": 2.0, "turn": "up"}, {"straight": 1.0}]
    s = solve_duct_beam(path, 0.01, 0.0, 9.81, 200.0, 2.0, 0.01)
    rise = 2.0 * (1 - math.cos(math.pi / 3)) + math.sin(math.pi / 3)
    assert duct_route(path, 0.01).height_m[-1] == pytest.approx(rise, rel=1e-4)
    assert s.pull_force_N == pytest.approx(200.0 + 9.81 * rise, rel=1e-4)


def test_stiff_bend_point_load_and_place():
    """No gravity: the cable lands λ into the bend with √(EJ T)/ρ (stiff_bend, first order in λ/ρ)."""
    t_in, ej, radius = 100.0, 1.0, 0.5
    lam = math.sqrt(ej / t_in)
    s = solve_duct_beam(TIGHT, 0.015, 0.0, 0.0, t_in, ej, 0.0025)
    entry = (s.x_m > 0.6 - lam) & (s.x_m < 0.6 + 2.5 * lam)
    peak = np.argmax(np.where(entry, s.wall_force_N, 0.0))
    assert s.x_m[peak] - 0.6 == pytest.approx(lam, abs=0.1 * lam)
    # the load beyond the body's pressure T/R from the peak on, over the window
    window = entry & (s.x_m >= s.x_m[peak] - 4 * 0.0025)
    point = s.wall_force_N[window].sum() - t_in / radius * (0.6 + 2.5 * lam - s.x_m[peak])
    assert point == pytest.approx(math.sqrt(ej * t_in) / radius, rel=0.1)


def test_rope_limit_matches_the_rope_with_clearance():
    """EJ = 0 with gravity: the cable rides up the floor's trough to the bend's inner wall, as the
    independent rope-with-clearance solver has it (both converge as h²; 0.02 % apart at h 5 mm)."""
    from exucable.geometry.path import Bend, Straight, centreline_from_path
    from exucable.quasistatic.clearance import solve_rope_with_clearance
    w = 0.21 * 9.81
    s = solve_duct_beam(TIGHT, 0.015, 0.5, w, 100.0, 0.0, 0.005)
    centreline = centreline_from_path((0, 0, 0), (1, 0, 0), [Straight(0.6), Bend(90.0, 0.5, "left"), Straight(0.6)])
    ref = solve_rope_with_clearance(centreline, 0.015, 0.5, w, 100.0)
    assert s.pull_force_N == pytest.approx(ref.pull_force_N, rel=3e-4)


def test_converges_with_the_node_spacing():
    """First order in h (a point load lands on a node), 1e-5 apart at h = 5 mm."""
    w = 0.21 * 9.81
    f = [solve_duct_beam(TIGHT, 0.015, 0.5, w, 100.0, 1.0, h).pull_force_N for h in (0.02, 0.01, 0.005)]
    assert abs(f[2] - f[1]) < 0.6 * abs(f[1] - f[0])
    assert abs(f[2] - f[1]) < 1e-5 * f[2]


def test_gravity_change_vanishes_with_the_bending_stiffness():
    w = 0.21 * 9.81
    small = gravity_change_of_stiffness(TIGHT, 0.015, 0.5, w, 100.0, 1e-4, 0.01)
    large = gravity_change_of_stiffness(TIGHT, 0.015, 0.5, w, 100.0, 1.0, 0.01)
    assert abs(small) < 0.05 * abs(large)


def test_mixed_route_is_refused():
    with pytest.raises(ValueError, match="level route"):
        duct_route([{"bend": 90.0, "radius": 1.0, "turn": "left"}, {"bend": 30.0, "radius": 1.0, "turn": "up"}], 0.01)


def test_up_bend_free_spans_match_their_closed_form():
    """Up-bend with gravity: the cable crosses from the straights' floors to the bend's upper wall in
    free spans; bending stiffness keeps more weight on the floor, ΔF = μ EJ/(ρ X₀) per span
    (first order in λ/X₀ ≈ 0.3 here), the entry's grown by e^{μθ}."""
    from exucable.quasistatic.stiff_bend import free_span_stiffness_N
    path = [{"straight": 2.5}, {"bend": 60.0, "radius": 5.0, "turn": "up"}, {"straight": 2.0}]
    mu, w, ej, c, t_back, theta = 0.3, 9.81, 25.0, 0.01, 200.0, math.pi / 3
    h = 0.02
    model = gravity_change_of_stiffness(path, c, mu, w, t_back, ej, h)
    rope = solve_duct_beam(path, c, mu, w, t_back, 0.0, h)
    t_in = t_back + mu * w * 2.5
    t_out = float(np.interp(2.5 + 5.0 * theta, rope.x_m, rope.tension_N))
    rho = 5.0 - c
    closed = (free_span_stiffness_N(ej, mu, rho, c, w, t_in) * math.exp(mu * theta)
              + free_span_stiffness_N(ej, mu, rho, c, w * math.cos(theta), t_out)) / rope.pull_force_N
    assert model == pytest.approx(closed, rel=0.15)
