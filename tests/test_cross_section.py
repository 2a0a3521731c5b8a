"""Rigid circles at rest in a round duct (exucable/quasistatic/cross_section.py) against closed forms.

References: the triangle resting under gravity (:func:`exucable.model.bundle.arrangement_offsets`,
its own closed form), and what the frictionless statics of equal circles under a uniform load
gives by symmetry: the same arrangement turned with the load (circles in a circle have no
preferred direction), and under a load reversed the order-preserving cradle on the opposite wall:
the middle circle at ρ = R − r from the axis along the load, the two others on the wall at
α = 2 asin(r/ρ) either side of it (touching it, the cradle of ``arrangement_offsets``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from exucable.model.bundle import arrangement_offsets
from exucable.quasistatic.cross_section import rest_along, rest_in_duct

R, r = 0.05, 0.015
RHO = R - r
W = 13.9          # a cable's weight per length [N/m]
# the penalty closes contacts to within ~1e-4 r per load carried: a micrometre here
TOL_M = 2e-6


def _turned(x, phi):
    c, s = math.cos(phi), math.sin(phi)
    return np.stack([x[:, 0] * c - x[:, 1] * s, x[:, 0] * s + x[:, 1] * c], axis=1)


def _assert_admissible(x, tol=TOL_M):
    """Every circle inside the duct, no two overlapping (beyond the penalty's micrometres)."""
    assert np.max(np.hypot(x[:, 0], x[:, 1])) <= RHO + tol
    for i in range(len(x)):
        for j in range(i + 1, len(x)):
            assert np.hypot(*(x[i] - x[j])) >= 2 * r - tol


def test_the_triangle_under_gravity_rests_as_arrangement_offsets_lays_it():
    tri = arrangement_offsets(3, "triangular", R, r)
    start = tri + np.array([[1e-3, 2e-3], [-1e-3, 1e-3], [0.0, 3e-3]])      # lifted a little off its rest
    x, steps = rest_in_duct(np.array([[0.0, -W]] * 3), R, r, start)
    assert steps > 0
    np.testing.assert_allclose(x, tri, atol=TOL_M)


def test_under_an_upward_load_the_triangle_lifts_into_the_cradle_on_the_upper_wall_in_its_order():
    """The top circle (index 2) hits the upper wall first and stays in the middle; the bottom two
    come up beside it, each touching it: (∓ρ sin α, ρ cos α) and (0, ρ)."""
    tri = arrangement_offsets(3, "triangular", R, r)
    x, _ = rest_in_duct(np.array([[0.0, 20.0]] * 3), R, r, tri)
    a = 2.0 * math.asin(r / RHO)
    expected = np.array([[-RHO * math.sin(a), RHO * math.cos(a)], [RHO * math.sin(a), RHO * math.cos(a)], [0.0, RHO]])
    np.testing.assert_allclose(x, expected, atol=TOL_M)
    _assert_admissible(x)


@pytest.mark.parametrize("phi", [-math.pi / 2, math.pi / 2, -math.pi / 3])
def test_a_load_turned_slowly_turns_the_triangle_with_it(phi):
    """The load turned from down to φ in 30 stations (a bend's entry): the triangle ends turned by φ,
    the same circle inward (a horizontal load: the triangle on the side wall)."""
    tri = arrangement_offsets(3, "triangular", R, r)
    ang = np.linspace(0.0, phi, 31)
    loads = np.stack([np.tile([W * math.sin(a), -W * math.cos(a)], (3, 1)) for a in ang])
    X, steps = rest_along(loads, R, r, tri)
    assert steps > 0
    np.testing.assert_allclose(X[-1], _turned(tri, phi), atol=TOL_M)
    for x in X:
        _assert_admissible(x)


def test_the_cradle_under_gravity_stays_and_no_load_moves_nothing():
    cradle = arrangement_offsets(3, "cradled", R, r)
    x, _ = rest_in_duct(np.array([[0.0, -W]] * 3), R, r, cradle)
    np.testing.assert_allclose(x, cradle, atol=TOL_M)
    x, steps = rest_in_duct(np.zeros((3, 2)), R, r, cradle)
    assert steps == 0 and np.array_equal(x, cradle)


def test_the_continuation_stops_where_it_meets_another():
    tri = arrangement_offsets(3, "triangular", R, r)
    loads = np.tile([0.0, -W], (5, 3, 1))
    far = np.tile(tri + 0.01, (5, 1, 1))
    near = np.tile(tri, (5, 1, 1))
    X, _ = rest_along(loads, R, r, tri, stop_near=far, tolerance_m=1e-4)
    assert len(X) == 5
    X, _ = rest_along(loads, R, r, tri, stop_near=near, tolerance_m=1e-4)
    assert len(X) == 1
