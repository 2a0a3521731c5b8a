"""The planar beam-in-conduit model against its closed-form limits (exucable/quasistatic/beam.py).

Tolerances: the node spacing h = λ/10 resolves the bending length; the wall penalty lets the cable
in by ~1e-4 c and the trough that fixes a free straight's place without gravity (1e-5 T/ρ per
length) adds friction ~1e-5 of the pull, so the capstan holds to 1e-4; against stiff_bend (an exact
elastica) the discretisation of the edge load costs a few % of the ~0.3 % effect.
"""

import math

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
