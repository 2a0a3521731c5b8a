"""The quasi-static rope solver against every closed form of the rope equation.

Tolerance: the brief asks for 1e-6 relative. The solver integrates at rtol 1e-11 and reproduces the closed
forms to ~1e-12, so 1e-6 leaves six orders of margin for platform differences while still catching any
modelling error (a wrong sign or a missed piece changes the answer at the percent level).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from exucable.quasistatic import closed_forms as cf
from exucable.errors import ModelError
from exucable.geometry import Bend, Helix, Straight, centreline_from_path
from exucable.quasistatic.rope import RopeSolution, rope_pull_force_N, solve_rope, solve_rope_for_pull_force

RTOL = 1e-6  # see the module docstring
W = 1000.0 * math.pi * 2.5e-3**2 * 9.8  # the paper's cable: rho A g [N/m] (Sect. 3, Eq. 25)


def heading(elevation_deg: float, azimuth_deg: float = 0.0) -> list[float]:
    """Unit vector with the given elevation above the horizontal and azimuth from +x."""
    e, a = math.radians(elevation_deg), math.radians(azimuth_deg)
    return [math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)]


# ---------------------------------------------------------------- straight incline (paper Eq. 25)
@pytest.mark.parametrize("theta_deg", [30.0, 10.0, 0.0, -10.0])
def test_incline_matches_eq25_along_the_cable(theta_deg):
    mu, length = 0.3, 50.0
    route = centreline_from_path([0, 0, 0], heading(theta_deg), [Straight(length)])
    trailing = 1.0 if theta_deg < 0 else 0.0  # downhill (tan 10 deg < mu) starts with some back tension
    sol = solve_rope(route, mu, W, trailing_tension_N=trailing, n_output=51)
    theta = math.radians(theta_deg)
    expected = trailing + cf.incline_tension_N(sol.s_cable_m, W, mu, theta)
    np.testing.assert_allclose(sol.tension_N, expected, rtol=RTOL)
    np.testing.assert_allclose(sol.tension_at([3.3, 17.0]), trailing + cf.incline_tension_N([3.3, 17.0], W, mu, theta),
                               rtol=RTOL)
    assert sol.pull_force_N == pytest.approx(expected[-1], rel=RTOL)
    # On a straight the bearing pressure is the weight's normal component w cos(theta).
    np.testing.assert_allclose(sol.sidewall_pressure_N_per_m, W * math.cos(theta), rtol=RTOL)
    assert sol.max_tension_N == pytest.approx(max(expected[0], expected[-1]), rel=RTOL)
    assert not sol.slack


def test_example1_pull_force():
    route = centreline_from_path([0, 0, 0], heading(30.0), [Straight(50.0)])
    sol = solve_rope(route, 0.3, W)
    # NOTES.md / reference/paper_values.toml: 7.3102 N (rounded to 5 digits, hence 1e-5).
    assert sol.pull_force_N == pytest.approx(7.3102, rel=1e-5)
    assert sol.pull_force_N == pytest.approx(cf.incline_tension_N(50.0, W, 0.3, math.radians(30.0)), rel=RTOL)


def test_reverse_pull_on_incline_is_the_downhill_case():
    # Pulled out at s = 0 of an upward straight, the cable moves downhill: dT/dx = w (mu cos - sin).
    mu, theta = 0.5, math.radians(20.0)  # tan 20 deg = 0.36 < 0.5: stays taut
    route = centreline_from_path([0, 0, 0], heading(20.0), [Straight(10.0)])
    sol = solve_rope(route, mu, W, trailing_tension_N=0.2, direction="reverse")
    assert sol.pull_force_N == pytest.approx(0.2 + cf.incline_tension_N(10.0, W, mu, -theta), rel=RTOL)
    assert sol.s_conduit_m[0] == pytest.approx(10.0) and sol.s_conduit_m[-1] == pytest.approx(0.0, abs=1e-12)


def test_steep_downhill_runs_slack_and_recovers_in_a_sag_bend():
    # Downhill 30 deg with mu = 0.3 (tan 30 deg > mu): T falls linearly from 0.2 N to 0, then stays 0 (clamped).
    # The sag bend turns the cable up to horizontal; T stays 0 until the slope is below the friction angle
    # (|phi| < atan mu), then grows with the cable on the lower wall (sag closed form, sigma = -1), then a flat
    # straight adds mu w L.
    mu, trailing, radius, flat = 0.3, 0.2, 2.0, 3.0
    route = centreline_from_path([0, 0, 0], heading(-30.0), [Straight(10.0), Bend(30.0, radius, turn="up"),
                                                             Straight(flat)])
    sol = solve_rope(route, mu, W, trailing_tension_N=trailing, n_output=401)
    rate = W * (math.sin(math.radians(30.0)) - mu * math.cos(math.radians(30.0)))  # [N/m] decrease
    s_zero = trailing / rate
    assert sol.slack
    assert sol.tension_at(0.5 * s_zero) == pytest.approx(trailing - rate * 0.5 * s_zero, rel=RTOL)
    assert sol.tension_at([s_zero + 0.1, 9.9]) == pytest.approx([0.0, 0.0], abs=1e-12)
    assert np.all(sol.tension_N >= 0.0)
    phi_star = math.atan(mu)
    t_bend_exit = cf.sag_bend_out_N(0.0, mu, phi_star, W, radius, entry_elevation_rad=-phi_star)
    assert sol.pull_force_N == pytest.approx(t_bend_exit + mu * W * flat, rel=RTOL)
    assert sol.max_tension_N == pytest.approx(max(trailing, sol.pull_force_N), rel=RTOL)


def test_slack_to_the_end_gives_zero_pull():
    route = centreline_from_path([0, 0, 0], heading(-45.0), [Straight(5.0)])
    sol = solve_rope(route, 0.3, W, trailing_tension_N=0.0)
    assert sol.slack and sol.pull_force_N == 0.0 and np.all(sol.tension_N == 0.0)


def test_no_weight_no_back_tension_is_zero_but_not_slack():
    route = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(1.0), Bend(90.0, 0.5)])
    sol = solve_rope(route, 0.3, 0.0, 0.0)
    assert sol.pull_force_N == 0.0 and not sol.slack


# ---------------------------------------------------------------- bends
def test_example2_capstan_profile_and_pressure():
    mu, radius, back = 0.2, 0.5, 150.0
    route = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(1.0), Bend(90.0, radius, turn="up"), Straight(1.0)])
    sol = solve_rope(route, mu, 0.0, back, n_output=201)
    assert sol.pull_force_N == pytest.approx(cf.capstan_out_N(back, mu, math.pi / 2), rel=RTOL)
    # Inside the bend T grows as exp(mu * angle turned so far); flat on the straights (no weight).
    u = np.array([0.5, 1.2, 1.0 + radius * math.pi / 4, 2.7])
    angle = np.clip((u - 1.0) / radius, 0.0, math.pi / 2)
    np.testing.assert_allclose(sol.tension_at(u), back * np.exp(mu * angle), rtol=RTOL)
    # Bearing pressure T/R peaks at the bend's exit; 0 on the straights.
    assert sol.max_sidewall_pressure_N_per_m == pytest.approx(sol.pull_force_N / radius, rel=RTOL)
    assert sol.sidewall_pressure_N_per_m[10] == 0.0


@pytest.mark.parametrize("back", [0.0, 0.05, 1.0, 20.0])
def test_horizontal_bend_with_weight(back):
    mu, radius, l1, l2 = 0.3, 0.5, 2.0, 1.5
    route = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(l1), Bend(90.0, radius, turn="left"), Straight(l2)])
    sol = solve_rope(route, mu, W, back)
    t_in = back + mu * W * l1
    t_out = cf.horizontal_bend_out_N(t_in, mu, math.pi / 2, W, radius)
    assert sol.tension_at(l1) == pytest.approx(t_in, rel=RTOL)
    assert sol.pull_force_N == pytest.approx(t_out + mu * W * l2, rel=RTOL)


# (T_in [N], entry elevation [deg], bend angle [deg]); each chosen where the closed form is valid: the
# sag cases include the cable lying on the lower wall (sigma = -1, light cable) and lifted to the upper one.
SAG_CASES = [(1.0, 0.0, 90.0), (5.0, 0.0, 30.0), (0.0, 0.0, 30.0), (0.1, -40.0, 60.0), (0.3, 40.0, 160.0)]
HUMP_CASES = [(1.0, 0.0, 90.0), (0.3, 0.0, 60.0), (0.0, 40.0, 90.0), (5.0, -40.0, 30.0), (0.1, 60.0, 160.0)]


@pytest.mark.parametrize("t_in, elevation_deg, angle_deg", SAG_CASES)
def test_vertical_sag_bend(t_in, elevation_deg, angle_deg):
    mu, radius = 0.3, 2.0
    route = centreline_from_path([0, 0, 0], heading(elevation_deg, 30.0), [Bend(angle_deg, radius, turn="up")])
    sol = solve_rope(route, mu, W, t_in)
    expected = cf.sag_bend_out_N(t_in, mu, math.radians(angle_deg), W, radius, math.radians(elevation_deg))
    assert sol.pull_force_N == pytest.approx(expected, rel=RTOL)


@pytest.mark.parametrize("t_in, elevation_deg, angle_deg", HUMP_CASES)
def test_vertical_hump_bend(t_in, elevation_deg, angle_deg):
    mu, radius = 0.3, 2.0
    route = centreline_from_path([0, 0, 0], heading(elevation_deg, -70.0), [Bend(angle_deg, radius, turn="down")])
    sol = solve_rope(route, mu, W, t_in)
    expected = cf.hump_bend_out_N(t_in, mu, math.radians(angle_deg), W, radius, math.radians(elevation_deg))
    assert sol.pull_force_N == pytest.approx(expected, rel=RTOL)


def test_sag_bend_where_the_cable_changes_wall_is_continuous_and_between_the_bounds():
    # T_in = 0.3 N, R = 2 m: T/R < w at entry (lower wall), then the tension lifts it to the upper wall; no closed
    # form, but the result must lie between the frictionless rise and the capstan-amplified bound.
    mu, radius, angle = 0.3, 2.0, math.radians(60.0)
    with pytest.raises(ValueError):
        cf.sag_bend_out_N(0.3, mu, angle, W, radius)
    route = centreline_from_path([0, 0, 0], [1, 0, 0], [Bend(60.0, radius, turn="up")])
    sol = solve_rope(route, mu, W, 0.3)
    lift = W * radius * (1.0 - math.cos(angle))
    assert 0.3 + lift < sol.pull_force_N < (0.3 + lift + W * radius * angle) * math.exp(mu * angle)


# ---------------------------------------------------------------- helix (Example 3, Fig. 12)
def test_helix_capstan_with_exact_turning_angle():
    mu, back = 0.1, 10.0
    route = centreline_from_path([0, 0, 0], [1, 0, 0], [Helix(2.0, 1.0, 0.05)])
    beta = cf.helix_turning_angle_rad(2.0, 1.0, 0.05)
    assert beta < 4 * math.pi
    sol = solve_rope(route, mu, 0.0, back)
    assert sol.pull_force_N == pytest.approx(cf.capstan_out_N(back, mu, beta), rel=RTOL)
    # 4 pi instead of the exact beta would be off by mu * (4 pi - beta) = 4e-5: above RTOL, so the test can tell.
    assert abs(sol.pull_force_N / cf.capstan_out_N(back, mu, 4 * math.pi) - 1.0) > 10 * RTOL


def test_example3_force_controlled_inverse():
    route = centreline_from_path([0, 0, 0], [1, 0, 0], [Helix(2.0, 1.0, 0.05)])
    sol = solve_rope_for_pull_force(route, 0.1, 40.0)
    beta = cf.helix_turning_angle_rad(2.0, 1.0, 0.05)
    assert sol.trailing_tension_N == pytest.approx(cf.capstan_in_N(40.0, 0.1, beta), rel=RTOL)
    assert sol.pull_force_N == pytest.approx(40.0, rel=1e-10)  # brentq converged to rtol 1e-14


# ---------------------------------------------------------------- direction, short cable, inverse with weight
SPATIAL = [Straight(2.0), Bend(90.0, 0.5, turn="left"), Straight(1.0), Bend(45.0, 1.0, turn="up"), Straight(1.5),
           Bend(60.0, 0.8, turn=None, axis=(1, 1, 0)), Straight(0.7)]


def test_reverse_on_a_symmetric_route_equals_forward():
    # Straight - left bend - straight, symmetric about the bend's bisector: pulling from either end is the same.
    route = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(2.0), Bend(90.0, 1.0), Straight(2.0)])
    fwd = solve_rope(route, 0.3, W, 0.5)
    rev = solve_rope(route, 0.3, W, 0.5, direction="reverse")
    assert rev.pull_force_N == pytest.approx(fwd.pull_force_N, rel=RTOL)
    np.testing.assert_allclose(rev.tension_N, fwd.tension_N, rtol=RTOL)
    np.testing.assert_allclose(rev.s_conduit_m, route.length_m - fwd.s_conduit_m, atol=1e-12)


def test_reverse_equals_forward_on_the_reversed_route():
    route = centreline_from_path([0, 0, 0], [1, 0, 0], SPATIAL)
    rev = solve_rope(route, 0.25, W, 0.3, direction="reverse")
    fwd_of_reversed = solve_rope(route.reversed(), 0.25, W, 0.3)
    assert rev.pull_force_N == pytest.approx(fwd_of_reversed.pull_force_N, rel=RTOL)
    assert rev.pull_force_N != pytest.approx(solve_rope(route, 0.25, W, 0.3).pull_force_N, rel=1e-3)


def test_cable_shorter_than_the_conduit_lies_in_the_leading_part():
    mu, back, radius = 0.2, 150.0, 0.5
    route = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(2.0), Bend(90.0, radius), Straight(1.0)])
    length = 1.5  # trailing end 0.5 m into the bend: the cable turns through 1 rad
    fwd = solve_rope(route, mu, 0.0, back, cable_length_m=length)
    assert fwd.cable_length_m == pytest.approx(length)
    assert fwd.s_conduit_m[0] == pytest.approx(route.length_m - length)
    assert fwd.pull_force_N == pytest.approx(cf.capstan_out_N(back, mu, (length - 1.0) / radius), rel=RTOL)
    # Reverse: the cable lies in the first 1.5 m, all straight: only the horizontal straight's friction.
    rev = solve_rope(route, mu, W, back, direction="reverse", cable_length_m=length)
    assert rev.pull_force_N == pytest.approx(back + mu * W * length, rel=RTOL)


def test_split_route_composes():
    # Solving the whole route equals solving its last part with the tension reached at the split.
    route = centreline_from_path([0, 0, 0], [1, 0, 0], SPATIAL)
    whole = solve_rope(route, 0.25, W, 0.3)
    tail = 3.0
    split = whole.tension_at(route.length_m - tail)
    part = solve_rope(route, 0.25, W, split, cable_length_m=tail)
    assert part.pull_force_N == pytest.approx(whole.pull_force_N, rel=RTOL)


def test_force_controlled_inverse_with_weight_and_its_limits():
    route = centreline_from_path([0, 0, 0], [1, 0, 0], SPATIAL)
    forward = solve_rope(route, 0.25, W, 0.7)
    inverse = solve_rope_for_pull_force(route, 0.25, forward.pull_force_N, W)
    assert inverse.trailing_tension_N == pytest.approx(0.7, rel=RTOL)
    minimum = solve_rope(route, 0.25, W, 0.0).pull_force_N
    with pytest.raises(ModelError, match="below"):
        solve_rope_for_pull_force(route, 0.25, 0.5 * minimum, W)
    assert solve_rope_for_pull_force(route, 0.25, minimum, W).trailing_tension_N == pytest.approx(0.0, abs=1e-9)


def test_spatial_route_is_rotation_invariant():
    # The equation only sees e_z: rotating the route about z (start heading) must not change the tension.
    # (SPATIAL's last bend has a fixed world axis, so it does not rotate with the heading: use relative turns.)
    items = SPATIAL[:5] + [Bend(60.0, 0.8, turn="right"), Straight(0.7)]
    a = solve_rope(centreline_from_path([0, 0, 0], [1, 0, 0], items), 0.25, W, 0.3)
    b = solve_rope(centreline_from_path([5, -2, 1], heading(0.0, 137.0), items), 0.25, W, 0.3)
    assert b.pull_force_N == pytest.approx(a.pull_force_N, rel=RTOL)
    assert b.max_sidewall_pressure_N_per_m == pytest.approx(a.max_sidewall_pressure_N_per_m, rel=RTOL)


# ---------------------------------------------------------------- API and input checks
def test_solution_fields_and_errors():
    route = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(1.0), Bend(90.0, 0.5)])
    sol = solve_rope(route, 0.2, 0.0, 10.0, n_output=11)
    assert isinstance(sol, RopeSolution) and sol.tension_N.shape == (11,)
    assert sol.s_cable_m[0] == 0.0 and sol.s_cable_m[-1] == pytest.approx(route.length_m)
    assert sol.trailing_tension_N == 10.0 and sol.tension_N[0] == 10.0
    assert sol.tension_N[-1] == sol.pull_force_N
    assert sol.max_tension_N == pytest.approx(sol.pull_force_N, rel=1e-12)  # monotone: the maximum is at the end
    assert isinstance(sol.tension_at(0.3), float)
    with pytest.raises(ValueError):
        sol.tension_at(route.length_m + 0.1)
    for kwargs in ({"friction": -0.1}, {"weight_per_length_N_per_m": -1.0}, {"trailing_tension_N": -1.0},
                   {"direction": "sideways"}, {"cable_length_m": route.length_m + 1.0}, {"cable_length_m": 0.0}):
        args = {"friction": 0.2, **kwargs}
        with pytest.raises(ModelError):
            solve_rope(route, **args)


# ---------------------------------------------------------------- closed-form pieces against the ODE
@pytest.mark.parametrize("items, start_dir, w, back", [
    ([Straight(2.0), Bend(90.0, 0.5, turn="left"), Straight(3.0)], [1, 0, 0], W, 2.0),        # horizontal bend + weight
    ([Straight(10.0), Bend(90.0, 0.5, turn="left"), Straight(5.0)], heading(-8.0), W, 2.0),   # tilted bend (ODE)
    ([Straight(3.0), Bend(30.0, 1.0, turn="up"), Straight(4.0)], heading(-40.0), W, 0.1),     # T hits 0, slack, recovers
    ([Straight(1.0), Bend(90.0, 0.5, turn="left"), Helix(2.0, 1.0, 0.05)], [1, 0, 0], 0.0, 150.0),  # no weight
    (SPATIAL, [1, 0, 0], W, 5.0),
])
def test_closed_form_pieces_agree_with_the_ode(monkeypatch, items, start_dir, w, back):
    """Pieces solved in closed form (straights; bends and helices without weight; horizontal bends with
    weight) give the tension the DOP853 integration gives (rtol 1e-11) to 1e-9: the closed forms are the
    ODE's exact solutions, so only the integrator's own error remains."""
    import exucable.quasistatic.rope as rope

    route = centreline_from_path([0, 0, 0], start_dir, items)
    for direction in ("forward", "reverse"):
        exact = solve_rope(route, 0.3, w, back, direction=direction, n_output=201)
        with monkeypatch.context() as m:
            m.setattr(rope, "_closed_form", lambda *args: None)
            m.setattr(rope, "_chebyshev_piece", lambda *args: None)
            ode = solve_rope(route, 0.3, w, back, direction=direction, n_output=201)
        scale = max(ode.max_tension_N, 1e-12)
        np.testing.assert_allclose(exact.tension_N, ode.tension_N, rtol=1e-9, atol=1e-9 * scale)
        s = np.linspace(0.0, ode.cable_length_m, 57)
        np.testing.assert_allclose(exact.tension_at(s), ode.tension_at(s), rtol=1e-9, atol=1e-9 * scale)
        assert exact.pull_force_N == pytest.approx(ode.pull_force_N, rel=1e-9)
        assert exact.max_tension_N == pytest.approx(ode.max_tension_N, rel=1e-9)
        assert exact.max_sidewall_pressure_N_per_m == pytest.approx(ode.max_sidewall_pressure_N_per_m, rel=1e-9)
        assert exact.slack == ode.slack


# ---------------------------------------------------------------- Chebyshev collocation against the ODE
@pytest.mark.parametrize("items, start_dir, w, back", [
    ([Straight(10.0), Bend(90.0, 0.5, turn="left"), Straight(5.0)], heading(-8.0), W, 2.0),   # tilted bend
    ([Straight(2.0), Bend(60.0, 3.0, turn="up"), Straight(4.0)], [1, 0, 0], 50.0, 200.0),      # vertical bend
    ([Straight(2.0), Bend(60.0, 3.0, turn="down"), Straight(4.0)], heading(10.0), 50.0, 40.0),  # sag, low tension
    ([Straight(1.0), Helix(6.0, 0.5, 0.05)], [1, 0, 0], 30.0, 0.0),                            # 6 coils, from T = 0
    ([Straight(3.0), Bend(30.0, 1.0, turn="up"), Straight(4.0)], heading(-40.0), W, 0.1),      # slack: solve_ivp's
    (SPATIAL, [1, 0, 0], 30.0, 5.0),
])
def test_collocated_pieces_agree_with_dop853(monkeypatch, items, start_dir, w, back):
    """Curved pieces without a closed form (bends out of the horizontal with weight, helices with
    weight) are integrated by Chebyshev collocation, not solve_ivp: the tension profile, its dense
    output, the largest tension and the slack flag agree with DOP853 at rtol 1e-11 to 1e-9 of the
    largest tension (measured: ≤ 1.2e-10 on every shipped scenario's route and the 1-10 km benchmark routes,
    the pulling force ≤ 2.4e-12), in both directions."""
    import exucable.quasistatic.rope as rope

    route = centreline_from_path([0, 0, 0], start_dir, items)
    used = []
    original = rope._chebyshev_piece
    monkeypatch.setattr(rope, "_chebyshev_piece", lambda *args: used.append(original(*args)) or used[-1])
    for direction in ("forward", "reverse"):
        used.clear()
        got = solve_rope(route, 0.3, w, back, direction=direction, n_output=201)
        with monkeypatch.context() as m:
            m.setattr(rope, "_chebyshev_piece", lambda *args: None)
            ode = solve_rope(route, 0.3, w, back, direction=direction, n_output=201)
        assert used, "no piece went to the collocation"
        scale = max(ode.max_tension_N, 1e-12)
        np.testing.assert_allclose(got.tension_N, ode.tension_N, rtol=0.0, atol=1e-9 * scale)
        s = np.linspace(0.0, ode.cable_length_m, 301)
        np.testing.assert_allclose(got.tension_at(s), ode.tension_at(s), rtol=0.0, atol=1e-9 * scale)
        assert got.pull_force_N == pytest.approx(ode.pull_force_N, rel=1e-9, abs=1e-9 * scale)
        assert got.max_tension_N == pytest.approx(ode.max_tension_N, rel=1e-9)
        # the largest pressure is taken over sampled points, the output grid and each integrator's
        # own nodes (DOP853's steps, the Chebyshev points), so it may differ by the sampling: 7e-6
        # on the sag bend, where the pressure peaks inside a slack stretch's end
        assert got.max_sidewall_pressure_N_per_m == pytest.approx(ode.max_sidewall_pressure_N_per_m, rel=1e-5)
        assert got.slack == ode.slack


def test_collocation_hands_a_piece_where_the_tension_reaches_zero_to_solve_ivp():
    """Where the tension would reach zero inside a collocated piece (a down-bend from a small back
    tension) the collocation gives up (None) and solve_ivp's event finds where the slack begins."""
    import exucable.quasistatic.rope as rope

    route = centreline_from_path([0, 0, 0], heading(-10.0), [Straight(1.0), Bend(60.0, 3.0, turn="down")])
    piece = route.pieces[1]
    lo, hi = rope._inside(piece.s_start_m, piece.s_end_m)
    assert rope._chebyshev_piece(piece, lo, hi, 0.1, 50.0, lo, hi, 1.0) is None
    done = rope._chebyshev_piece(piece, lo, hi, 0.1, 50.0, lo, hi, 1e4)
    assert done is not None and done[0] > 1e4


def test_closed_form_covers_straights_and_horizontal_or_weightless_bends_only():
    import exucable.quasistatic.rope as rope

    route = centreline_from_path([0, 0, 0], heading(10.0), [Straight(1.0), Bend(90.0, 0.5, turn="left"),
                                                          Bend(45.0, 1.0, turn="up"), Helix(2.0, 1.0, 0.05)])
    kinds = []
    for piece in route.pieces:
        lo, hi = rope._inside(piece.s_start_m, piece.s_start_m + piece.length_m)
        kinds.append((rope._closed_form(route, lo, hi, 0.3, W) is not None,
                      rope._closed_form(route, lo, hi, 0.3, 0.0) is not None))
    # the bend after a 10 deg incline is tilted: only without weight; the vertical bend and the helix likewise
    assert kinds == [(True, True), (False, True), (False, True), (False, True)]
    flat = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(1.0), Bend(90.0, 0.5, turn="right")])
    piece = flat.pieces[1]
    assert rope._closed_form(flat, *rope._inside(piece.s_start_m, piece.s_start_m + piece.length_m), 0.3, W)


@pytest.mark.parametrize("items, start_dir, back", [
    (SPATIAL, [1, 0, 0], 5.0),                                                                  # ODE pieces
    ([Straight(3.0), Bend(30.0, 1.0, turn="up"), Straight(4.0)], heading(-40.0), 0.1),            # slack stretch
])
def test_pull_force_alone_is_the_full_solutions_bit_for_bit(items, start_dir, back):
    """rope_pull_force_N (the steady lead-out rule's exit tension) is the same integration as
    solve_rope without the profile: the same float, in both directions and for a shorter cable;
    and it refuses a negative back tension like solve_rope."""
    route = centreline_from_path([0, 0, 0], start_dir, items)
    for direction in ("forward", "reverse"):
        for length in (None, 0.8 * route.length_m):
            full = solve_rope(route, 0.3, W, back, direction=direction, cable_length_m=length)
            assert rope_pull_force_N(route, 0.3, W, back, direction=direction, cable_length_m=length) == full.pull_force_N
    with pytest.raises(ModelError, match="trailing"):
        rope_pull_force_N(route, 0.3, W, -1.0)
