"""The planar beam-in-conduit model against its closed-form limits (exucable/quasistatic/beam.py).

Tolerances: the node spacing h = λ/10 resolves the bending length; the wall penalty lets the cable
in by ~1e-4 c and the trough that fixes a free straight's place without gravity (1e-5 T/ρ per
length) adds friction ~1e-5 of the pull, so the capstan holds to 1e-4; against stiff_bend (an exact
elastica) the discretisation of the edge load costs a few % of the ~0.3 % effect.
"""

import math

import numpy as np
import pytest

from exucable.quasistatic.beam import BeamConduitError, solve_planar_beam, stiff_route_difference
from exucable.quasistatic.stiff_bend import stiff_bend

R, C, MU, T = 0.5, 0.015, 0.5, 100.0
ROUTE = [(0.6, 0.0), (R * math.pi / 2, 1.0 / R), (0.6, 0.0)]


def test_flexible_limit_is_the_capstan():
    """λ = h (EJ → 0): the cable wraps the inner wall, T_out = T_in e^{μθ} (paper Eq. 26)."""
    h = 0.01
    sol = solve_planar_beam(ROUTE, C, MU, 0.0, T * h * h, T, h, trough_weight_N_per_m=1e-5 * T / R)
    assert sol.pull_force_N == pytest.approx(T * math.exp(MU * math.pi / 2), rel=1e-4)


def test_floor_friction_on_a_straight():
    """With gravity, a straight with no bend: T grows by μ w L (the rope's straight)."""
    w = 2.0
    sol = solve_planar_beam([(3.0, 0.0)], C, MU, w, 0.25, T, 0.02)
    assert sol.pull_force_N == pytest.approx(T + MU * w * 3.0, rel=1e-6)


def test_small_bending_length_matches_the_stiff_bend_elastica():
    """λ/R = 0.1, lift-off 0.09 × 2c: the span stays inside the conduit, so stiff_bend's exact
    elastica (held exit) holds; its change against the capstan is −0.30 %."""
    ej = 0.25
    got = stiff_route_difference(ROUTE, C, MU, 0.0, ej, T)["difference"]
    held = stiff_bend(T, MU, math.pi / 2, R - C, ej, exit_held_m=0.6 - 0.0).vs_rope
    assert got == pytest.approx(held, rel=0.1)
    assert got < 0.0


def test_invalid_input_names_the_field():
    with pytest.raises(ValueError, match="bending_stiffness_N_m2"):
        solve_planar_beam(ROUTE, C, MU, 0.0, 0.0, T, 0.01)
    assert issubclass(BeamConduitError, RuntimeError)


def test_flexible_limit_in_3d_is_the_rope_with_clearance():
    """With gravity on a horizontal bend the 3D chain at λ = h is the rope with clearance (an independent
    solver: a string, its free spans lifting off the floor near the bend's ends): 2e-4 (h = 1 cm; 2e-5 at
    5 mm), while the free spans themselves move the pull by ~1 % from the capstan with μ w L."""
    from exucable.geometry import Bend, Straight, centreline_from_path
    from exucable.quasistatic.clearance import solve_rope_with_clearance
    from exucable.quasistatic.beam import route_pieces

    w, h = 0.21 * 9.80665, 0.01
    centre = centreline_from_path([0.0, 0.0, 0.0], (1.0, 0.0, 0.0), [Straight(1.0), Bend(90.0, R), Straight(1.0)])
    pieces = route_pieces(centre)
    assert pieces == [(1.0, 0.0), pytest.approx((R * math.pi / 2, 1.0 / R)), (1.0, 0.0)]
    rope = solve_rope_with_clearance(centre, C, MU, w, T, node_spacing_m=0.005).pull_force_N
    beam = solve_planar_beam(pieces, C, MU, w, T * h * h, T, h, three_d=True).pull_force_N
    assert beam == pytest.approx(rope, rel=2e-4)


def test_span_pressing_the_opposite_wall_costs_friction():
    """λ/R = 0.4 (EJ 4 N m², lift-off 1.37 × 2c): stiff_bend's single-contact elastica is invalid; the
    cable touches the exit straight's outer wall (three-point bending) and the pull lies well above
    that model's −3.5 % (the opposite wall's friction), still below the capstan."""
    got = stiff_route_difference([(1.0, 0.0), (R * math.pi / 2, 1.0 / R), (1.0, 0.0)], C, MU, 0.0, 4.0, T)
    assert got["windows"][0]["max_outer_offset_over_c"] == pytest.approx(1.0, abs=1e-3)
    single = stiff_bend(T, MU, math.pi / 2, R - C, 4.0)
    assert not single.fits(C)
    assert single.vs_rope + 0.01 < got["difference"] < 0.0


def test_vertical_route_without_friction_lifts_the_weight():
    """μ = 0 on an up- and a down-bend (the weight in the bend plane): the pull is T_b + w ΔH, ΔH the
    rise of the cable's axis (steady sliding's energy balance: no work but the weight's; paper
    Eq. 25 with μ = 0). Both ends lie on the floor, the head held there, so ΔH is the centreline's
    R(1 − cos θ) + L sin θ plus c(1 − cos θ) from the floor's tilt. The chain lumps the weight per
    centreline length, so on the bend's wall (at R ∓ c) it lifts w c (1 − cos θ) too much or too
    little: 2e-5 of the pull at c = 1 mm, hence 5e-5."""
    from exucable.quasistatic.beam import path_pieces
    c, w, radius, theta, t_back = 0.001, 9.81, 2.0, math.pi / 3, 200.0
    for turn, sign in (("up", 1.0), ("down", -1.0)):
        pieces, vertical = path_pieces([{"straight": 1.0}, {"bend": 60.0, "radius": radius, "turn": turn},
                                        {"straight": 1.0}])
        assert vertical
        sol = solve_planar_beam(pieces, c, 0.0, w, 2.0, t_back, 0.01, vertical=True, head_offset_m=-c)
        rise = sign * (radius * (1.0 - math.cos(theta)) + math.sin(theta)) + c * (1.0 - math.cos(theta))
        assert sol.pull_force_N == pytest.approx(t_back + w * rise, rel=5e-5)


def test_up_bend_free_spans_match_their_closed_form():
    """Up-bend with gravity: the cable crosses from the straights' floors to the bend's upper wall in
    free spans; bending stiffness keeps more weight on the floor, ΔF = μ EJ/(ρ X₀) per span
    (reference/README.md, "Gravity on vertical bends"; stiff_bend.free_span_stiffness_N), the entry's
    grown by e^{μθ}. What gravity changes (gravity_change_of_stiffness) against that closed form:
    first order in λ/X₀ ≈ 0.3 here, hence 15 %."""
    from exucable.quasistatic.beam import gravity_change_of_stiffness, path_pieces
    from exucable.quasistatic.stiff_bend import free_span_stiffness_N
    path = [{"straight": 2.5}, {"bend": 60.0, "radius": 5.0, "turn": "up"}, {"straight": 2.0}]
    mu, w, ej, c, t_back, theta, h = 0.3, 9.81, 25.0, 0.01, 200.0, math.pi / 3, 0.02
    model = gravity_change_of_stiffness(path, c, mu, w, ej, t_back, h)
    pieces, _ = path_pieces(path)
    flex = solve_planar_beam(pieces, c, mu, w, t_back * h * h, t_back, h, vertical=True)
    t_in = t_back + mu * w * 2.5
    mid = 0.5 * (flex.station_m[1:] + flex.station_m[:-1])
    t_out = float(np.interp(2.5 + 5.0 * theta, mid, flex.tension_N))
    rho = 5.0 - c
    closed = (free_span_stiffness_N(ej, mu, rho, c, w, t_in) * math.exp(mu * theta)
              + free_span_stiffness_N(ej, mu, rho, c, w * math.cos(theta), t_out)) / flex.pull_force_N
    assert model == pytest.approx(closed, rel=0.15)


def test_mixed_route_and_vertical_3d_are_refused():
    from exucable.quasistatic.beam import path_pieces
    with pytest.raises(ValueError, match="horizontal route"):
        path_pieces([{"bend": 90.0, "radius": 1.0, "turn": "left"}, {"bend": 30.0, "radius": 1.0, "turn": "up"}])
    with pytest.raises(ValueError, match="three_d=False"):
        solve_planar_beam(ROUTE, C, MU, 1.0, 0.1, T, 0.01, three_d=True, vertical=True)
