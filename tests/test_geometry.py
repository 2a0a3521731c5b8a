"""Conduit geometry from primitives, discretisation, reversal and the route figure.

Reference values are closed forms (arc R·θ, helix of radius a and rise c = p/2π per radian),
never our own output. Tolerances: evaluations are closed-form trigonometry of O(1) arguments, so
agreement to a few ulps of the largest coordinate is expected; 1e-12 (absolute, coordinates of
order 1–10 m) leaves room for ~100 ulps of rounding. Finite-difference checks have their own
truncation-error budget, stated where used.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from exucable.errors import GeometryError
from exucable.geometry import (
    Bend,
    Centreline,
    Conduit,
    Helix,
    Straight,
    centreline_from_path,
    discretise,
)
from exucable.plots.route import plot_route, route_table

# Rounding budget for closed-form evaluations of coordinates of order 1–10 m (see module docstring).
TOL = 1e-12

EX = np.array([1.0, 0.0, 0.0])
EY = np.array([0.0, 1.0, 0.0])
EZ = np.array([0.0, 0.0, 1.0])


def spatial_route() -> Centreline:
    """Three straights and three bends in different planes (like the paper's Example 4)."""
    return centreline_from_path([0, 0, 0], [1, 0, 0], [
        Straight(3.0), Bend(90, 0.5, "left"), Straight(2.0), Bend(90, 1.0, "up"), Straight(2.0),
        Bend(60, 0.8, turn=None, axis=(1.0, 0.0, 0.0)), Straight(1.5),
    ])


# --------------------------------------------------------------------------- helix
HELIX_CASES = [
    # turns, coil radius a [m], pitch p [m], turn
    (2.0, 1.0, 0.1, "left"),     # paper Example 3 (pitch is our choice)
    (1.25, 0.5, 0.3, "right"),
    (0.75, 2.0, -0.4, "left"),   # descending
    (3.0, 1.0, 1e-3, "right"),       # nearly flat coils
]


@pytest.mark.parametrize("turns, a, p, turn", HELIX_CASES)
def test_helix_closed_forms(turns, a, p, turn):
    c = p / (2 * math.pi)
    w = math.hypot(a, c)
    line = centreline_from_path([0, 0, 0], [1, 0, 0], [Helix(turns, a, p, turn)])
    phi = 2 * math.pi * turns
    sign = 1.0 if turn == "left" else -1.0
    assert line.length_m == pytest.approx(2 * math.pi * turns * w, rel=1e-14)
    # Exact turning angle per coil 2π·a/√(a² + c²) (NOTES.md, Example 3).
    assert line.turning_angle_rad == pytest.approx(phi * a / w, rel=1e-14)
    assert line.min_bend_radius_m == pytest.approx((a * a + c * c) / a, rel=1e-14)
    # Start heading +x, axis through (0, ±a, 0): x = a sin φ, y = ±a(1 − cos φ), z = p·turns.
    expected_end = np.array([a * math.sin(phi), sign * a * (1 - math.cos(phi)), p * turns])
    np.testing.assert_allclose(line.point(line.length_m), expected_end, atol=TOL)
    expected_t = np.array([a * math.cos(phi), sign * a * math.sin(phi), c]) / w
    np.testing.assert_allclose(line.tangent(line.length_m), expected_t, atol=TOL)
    s = np.linspace(0, line.length_m, 37)
    kappa = np.linalg.norm(line.curvature_vector(s), axis=1)
    np.testing.assert_allclose(kappa, a / (a * a + c * c), rtol=1e-13)
    # Unit tangents everywhere.
    np.testing.assert_allclose(np.linalg.norm(line.tangent(s), axis=1), 1.0, atol=TOL)


def test_helix_starts_tangent_to_horizontal_heading_part():
    heading = np.array([0.3, -0.4, 0.5])
    a, p = 0.7, 0.25
    line = centreline_from_path([1, 2, 3], heading, [Helix(1.5, a, p)])
    t0 = line.tangent(0.0)
    horizontal = np.array([0.3, -0.4, 0.0]) / 0.5
    np.testing.assert_allclose(t0[:2] / np.linalg.norm(t0[:2]), horizontal[:2], atol=TOL)
    # Its own slope: rise c per a of horizontal travel.
    assert t0[2] / np.linalg.norm(t0[:2]) == pytest.approx(p / (2 * math.pi) / a, rel=1e-13)
    np.testing.assert_allclose(line.point(0.0), [1, 2, 3], atol=TOL)
    # Entering with a different slope leaves a kink equal to the slope difference.
    jump = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(1.0), Helix(1, a, p)]).tangent_jumps_rad()
    assert jump[0] == pytest.approx(math.atan2(p / (2 * math.pi), a), rel=1e-12)


# --------------------------------------------------------------------------- bends
BEND_CASES = [
    # kwargs of Bend, heading, expected normal n0 (direction toward the centre at the start)
    (dict(turn="left"), EX, EY),
    (dict(turn="right"), EX, -EY),
    (dict(turn="up"), EX, EZ),
    (dict(turn="down"), EX, -EZ),
    (dict(turn=None, axis=(0.0, 1.0, 0.0)), EX, -EZ),           # right-hand rule about +y: x → −z
    (dict(turn=None, axis=(1.0, 0.0, 2.0)), EX, EY),            # component along the heading removed
    (dict(turn="left"), np.array([0.0, 0.6, 0.8]), -EX),        # inclined heading, axis z projected
    (dict(turn="up"), np.array([0.6, 0.0, 0.8]), np.array([-0.8, 0.0, 0.6])),
]


@pytest.mark.parametrize("angle_deg", [30.0, 90.0, 179.0, 270.0])
@pytest.mark.parametrize("kwargs, heading, n0", BEND_CASES)
def test_bend_closed_forms(kwargs, heading, n0, angle_deg):
    R = 0.5
    th = math.radians(angle_deg)
    start = np.array([1.0, -2.0, 0.5])
    line = centreline_from_path(start, heading, [Bend(angle_deg, R, **kwargs)])
    t0 = heading / np.linalg.norm(heading)
    assert line.length_m == pytest.approx(R * th, rel=1e-14)
    assert line.turning_angle_rad == pytest.approx(th, rel=1e-14)
    assert line.min_bend_radius_m == R
    np.testing.assert_allclose(line.point(line.length_m),
                               start + R * math.sin(th) * t0 + R * (1 - math.cos(th)) * n0, atol=TOL)
    np.testing.assert_allclose(line.tangent(line.length_m), math.cos(th) * t0 + math.sin(th) * n0, atol=TOL)
    # The curvature vector points to the centre start + R·n0 and has magnitude 1/R.
    s = np.linspace(0, line.length_m, 11)
    centre = start + R * n0
    np.testing.assert_allclose(line.curvature_vector(s), (centre - line.point(s)) / R**2, atol=TOL)


def test_chain_straight_bend_straight():
    L1, R, L2 = 2.0, 0.5, 3.0
    line = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(L1), Bend(90, R, "left"), Straight(L2)])
    assert line.length_m == pytest.approx(L1 + R * math.pi / 2 + L2, rel=1e-15)
    np.testing.assert_allclose(line.point(line.length_m), [L1 + R, R + L2, 0.0], atol=TOL)
    np.testing.assert_allclose(line.tangent(line.length_m), EY, atol=TOL)
    assert line.curved_ranges_m() == [(pytest.approx(L1), pytest.approx(L1 + R * math.pi / 2))]
    # Curvature is zero on the straights.
    np.testing.assert_array_equal(line.curvature_vector(np.array([0.5, line.length_m - 0.5])), 0.0)
    assert line.piece_index(0.5) == 0
    np.testing.assert_array_equal(line.piece_index(np.array([0.0, L1 + 0.1, line.length_m])), [0, 1, 2])


def test_tangent_continuity_and_derivatives():
    a, p = 1.0, 0.4
    slope = np.array([1.0, 0.0, p / (2 * math.pi) / a])  # enter the helix along its own slope: no kink
    line = centreline_from_path([0, 0, 0], slope, [
        Straight(1.0), Helix(1.5, a, p), Bend(40, 0.7, "up"), Bend(50, 0.6, turn=None, axis=(1, 2, 3)),
        Straight(0.5), Bend(120, 0.3, "right"), Straight(1.0)])
    # The end tangent of each piece is the start tangent of the next (to rounding).
    assert np.max(line.tangent_jumps_rad()) < 1e-12
    for left, right in zip(line.pieces[:-1], line.pieces[1:]):
        np.testing.assert_allclose(left.end_tangent, right.tangent(0.0), atol=1e-12)
        np.testing.assert_allclose(left.end_m, right.start_m, atol=TOL)
    # Tangent = dp/ds and curvature vector = dt/ds, by central differences away from the joints.
    # Truncation error ≈ h²κ³/6 with κ ≤ 3.4 1/m and h = 1e-4 m: ~7e-8; rounding ~1e-16·10/1e-4 = 1e-11.
    h = 1e-4
    s = np.concatenate([np.linspace(p_.s_start_m + 2 * h, p_.s_end_m - 2 * h, 5) for p_ in line.pieces])
    fd_t = (line.point(s + h) - line.point(s - h)) / (2 * h)
    np.testing.assert_allclose(fd_t, line.tangent(s), atol=1e-7)
    fd_k = (line.tangent(s + h) - line.tangent(s - h)) / (2 * h)
    np.testing.assert_allclose(fd_k, line.curvature_vector(s), atol=1e-6)  # κ⁴h²/6 ≈ 2e-7


def test_evaluation_shapes_and_range():
    line = spatial_route()
    assert line.point(1.0).shape == (3,)
    assert line.point(np.zeros((4, 2))).shape == (4, 2, 3)
    assert isinstance(line.piece_index(0.0), int)
    # Within 1e-9·L of the ends is clipped, beyond raises.
    np.testing.assert_allclose(line.point(line.length_m * (1 + 1e-12)), line.end_m, atol=TOL)
    with pytest.raises(ValueError):
        line.point(-1e-6)
    with pytest.raises(ValueError):
        line.tangent(np.array([0.0, line.length_m * 1.001]))
    s, pts = line.sample(50)
    assert s[0] == 0.0 and s[-1] == line.length_m and pts.shape == (50, 3)


# --------------------------------------------------------------------------- errors
ERROR_CASES = [
    # start, heading, items, expected key
    ([0, 0, 0], [0, 0, 0], [Straight(1)], "heading"),
    ([0, 0, 0], [1, math.nan, 0], [Straight(1)], "heading"),
    ([0, math.inf, 0], [1, 0, 0], [Straight(1)], "start"),
    ([0, 0, 0], [1, 0, 0], [], "path"),
    ([0, 0, 0], [1, 0, 0], [Straight(0.0)], "path[0].straight"),
    ([0, 0, 0], [1, 0, 0], [Straight(1), Straight(-2)], "path[1].straight"),
    ([0, 0, 0], [1, 0, 0], [Straight(1), Straight(2), Bend(90, 0.0)], "path[2].radius"),
    ([0, 0, 0], [1, 0, 0], [Bend(90, math.nan)], "path[0].radius"),
    ([0, 0, 0], [1, 0, 0], [Bend(0.0, 1.0)], "path[0].bend"),
    ([0, 0, 0], [1, 0, 0], [Bend(360.0, 1.0)], "path[0].bend"),
    ([0, 0, 0], [1, 0, 0], [Bend(90, 1.0, "sideways")], "path[0].turn"),
    ([0, 0, 0], [1, 0, 0], [Bend(90, 1.0, turn="left", axis=(0, 0, 1))], "path[0].axis"),
    ([0, 0, 0], [1, 0, 0], [Bend(90, 1.0, "left", axis=(0, 0, 1))], "path[0].axis"),
    ([0, 0, 0], [1, 0, 0], [Bend(90, 1.0, None, axis=(2, 0, 0))], "path[0].axis"),
    ([0, 0, 0], [1, 0, 0], [Bend(90, 1.0, None, axis=(0, 0, 0))], "path[0].axis"),
    ([0, 0, 0], [0, 0, 1], [Bend(90, 1.0, "left")], "path[0].turn"),
    ([0, 0, 0], [0, 0, -1], [Bend(90, 1.0, "up")], "path[0].turn"),
    ([0, 0, 0], [1, 0, 0], [Helix(0.0, 1.0, 0.1)], "path[0].helix"),
    ([0, 0, 0], [1, 0, 0], [Helix(-1.0, 1.0, 0.1)], "path[0].helix"),
    ([0, 0, 0], [1, 0, 0], [Helix(2.0, 0.0, 0.1)], "path[0].radius"),
    ([0, 0, 0], [1, 0, 0], [Helix(2.0, 1.0, math.nan)], "path[0].pitch"),
    ([0, 0, 0], [1, 0, 0], [Helix(2.0, 1.0, 0.0)], "path[0].pitch"),
    ([0, 0, 0], [1, 0, 0], [Helix(2.0, 1.0, 0.1, "up")], "path[0].turn"),
    ([0, 0, 0], [0, 0, 1], [Straight(1), Helix(2.0, 1.0, 0.1)], "path[1]"),
    ([0, 0, 0], [1, 0, 0], [Straight(1), "bend"], "path[1]"),
]


@pytest.mark.parametrize("start, heading, items, key", ERROR_CASES)
def test_non_physical_input_names_the_item(start, heading, items, key):
    with pytest.raises(GeometryError) as info:
        centreline_from_path(start, heading, items)
    assert info.value.key == key


# --------------------------------------------------------------------------- discretisation
def _distance_to_piece(piece, x, u_guess, half_width):
    """Distance from point x to a piece, minimised over local arc length near u_guess."""
    from scipy.optimize import minimize_scalar

    lo, hi = max(0.0, u_guess - half_width), min(piece.length_m, u_guess + half_width)
    res = minimize_scalar(lambda u: float(np.sum((piece.point(u) - x) ** 2)), bounds=(lo, hi),
                          method="bounded", options={"xatol": 1e-12})
    return math.sqrt(res.fun)


@pytest.mark.parametrize("item, dmax_deg", [
    (Bend(90, 0.5, "left"), 0.9),     # 100 chords exactly (not 101 from rounding)
    (Bend(90, 0.5, "left"), 7.0),     # ceil(12.86) = 13
    (Bend(200, 2.0, "up"), 10.0),
    (Helix(2, 1.0, 0.6), 3.6),
    (Helix(1.3, 0.4, 1.5, "right"), 12.0),
])
def test_chord_error_and_segment_count(item, dmax_deg):
    line = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(1.0), item, Straight(1.0)])
    piece = line.pieces[1]
    seg = discretise(line, 0.0035, max_segment_angle_deg=dmax_deg)
    k = math.ceil(round(math.degrees(piece.turning_angle_rad) / dmax_deg, 9))
    assert seg.count == k + 2
    rho = piece.radius_of_curvature_m
    dtheta = piece.turning_angle_rad / k
    bound = rho * (1 - math.cos(dtheta / 2))
    mids = 0.5 * (seg.start_m[1:-1] + seg.end_m[1:-1])
    u_mid = 0.5 * (seg.s_vertex_m[1:-2] + seg.s_vertex_m[2:-1]) - piece.s_start_m
    err = np.array([_distance_to_piece(piece, m, u, piece.length_m / k) for m, u in zip(mids, u_mid)])
    # Bounded minimisation converges to ~1e-12 m in u; the sagitta is quadratic there, so the
    # distance is accurate to far better than 1e-9·ρ.
    assert np.all(err <= bound * (1 + 1e-6) + 1e-12)
    if piece.kind == "bend":
        np.testing.assert_allclose(err, bound, rtol=1e-6)


def test_segments_vertices_on_curve_and_arc_lengths():
    line = spatial_route()
    for options in (dict(max_segment_angle_deg=2.5), dict(segments_per_bend=80)):
        seg = discretise(line, 0.0035, **options)
        np.testing.assert_allclose(seg.vertices_m, line.point(seg.s_vertex_m), atol=TOL)
        assert np.all(np.diff(seg.s_vertex_m) > 0)
        assert seg.s_vertex_m[0] == 0.0 and seg.s_vertex_m[-1] == line.length_m
        assert seg.inner_radius_m == 0.0035
    # 4 straights + 3 bends × 80 chords; consecutive straights stay separate segments.
    assert discretise(line, 0.0035, segments_per_bend=80).count == 4 + 3 * 80
    two = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(1.0), Straight(2.0)])
    seg = discretise(two, 0.01, segments_per_bend=5)
    np.testing.assert_allclose(seg.s_vertex_m, [0.0, 1.0, 3.0], atol=0)


@pytest.mark.parametrize("kwargs, key", [
    (dict(), "max_segment_angle"),
    (dict(max_segment_angle_deg=1.0, segments_per_bend=10), "max_segment_angle"),
    (dict(max_segment_angle_deg=0.0), "max_segment_angle"),
    (dict(max_segment_angle_deg=math.nan), "max_segment_angle"),
    (dict(segments_per_bend=0), "segments_per_bend"),
    (dict(segments_per_bend=2.5), "segments_per_bend"),
])
def test_discretise_options_refused(kwargs, key):
    with pytest.raises(GeometryError) as info:
        discretise(spatial_route(), 0.0035, **kwargs)
    assert info.value.key == key


@pytest.mark.parametrize("radius", [0.0, -1.0, math.nan])
def test_inner_radius_refused(radius):
    with pytest.raises(GeometryError) as info:
        Conduit.build(radius, spatial_route(), segments_per_bend=4)
    assert info.value.key == "inner_radius"


# --------------------------------------------------------------------------- reversal
def test_reversed_route_is_the_same_curve():
    line = centreline_from_path([0.3, -1, 2], [1, 1, 0], [
        Straight(1.0), Helix(1.5, 0.8, 0.3), Bend(70, 0.4, "down"), Straight(0.7),
        Bend(45, 1.2, turn=None, axis=(0.2, 1, 0.5))])
    rev = line.reversed()
    L = line.length_m
    assert rev.length_m == pytest.approx(L, rel=1e-15)
    assert rev.turning_angle_rad == pytest.approx(line.turning_angle_rad, rel=1e-14)
    assert rev.min_bend_radius_m == pytest.approx(line.min_bend_radius_m, rel=1e-14)
    s = np.linspace(0, L, 201)
    np.testing.assert_allclose(rev.point(s), line.point(L - s), atol=1e-11)
    np.testing.assert_allclose(rev.tangent(s), -line.tangent(L - s), atol=1e-11)
    # The curvature vector κn does not depend on the direction of travel.
    np.testing.assert_allclose(rev.curvature_vector(s), line.curvature_vector(L - s), atol=1e-11)
    assert [p.kind for p in rev.pieces] == [p.kind for p in reversed(line.pieces)]
    assert rev.reversed().point(1.234) == pytest.approx(line.point(1.234), abs=1e-11)


def test_conduit_build_summary_and_reversed():
    conduit = Conduit.build(0.0035, spatial_route(), max_segment_angle_deg=1.5)
    summary = conduit.summary()
    L = 3.0 + 0.5 * math.pi / 2 + 2.0 + math.pi / 2 + 2.0 + 0.8 * math.pi / 3 + 1.5
    assert summary["length_m"] == pytest.approx(L, rel=1e-14)
    assert summary["turning_angle_deg"] == pytest.approx(240.0, rel=1e-13)
    assert summary["segments"] == 4 + 60 + 60 + 40
    assert summary["min_bend_radius_m"] == 0.5
    assert summary["bends"] == 3
    rev = conduit.reversed()
    np.testing.assert_array_equal(rev.segments.vertices_m, conduit.segments.vertices_m[::-1])
    np.testing.assert_allclose(rev.segments.s_vertex_m, L - conduit.segments.s_vertex_m[::-1], atol=1e-12)
    np.testing.assert_allclose(rev.segments.vertices_m, rev.centreline.point(rev.segments.s_vertex_m), atol=1e-11)
    assert rev.summary()["segments"] == summary["segments"]
    straight = Conduit.build(0.01, centreline_from_path([0, 0, 0], [0, 0, 1], [Straight(5)]), segments_per_bend=3)
    assert straight.summary()["min_bend_radius_m"] == math.inf and straight.summary()["bends"] == 0


# --------------------------------------------------------------------------- figure
def test_route_table_rows():
    rows = dict(route_table(Conduit.build(0.0035, spatial_route(), segments_per_bend=80)))
    assert rows["total turning angle [deg]"] == "240.00"
    assert rows["number of segments"] == str(4 + 240)
    assert rows["number of bends"] == "3"
    assert rows["min bend radius [m]"] == "0.5"
    assert len(rows) == 5


@pytest.mark.parametrize("line", [
    spatial_route(),
    centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(1), Helix(2, 1.0, 0.2), Straight(1)]),
    centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(4)]),
], ids=["spatial", "helix", "straight"])
def test_plot_route_writes_png(tmp_path, line):
    out = tmp_path / "route.png"
    written = plot_route(Conduit.build(0.0035, line, segments_per_bend=20), out, title="test")
    assert written == out
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
    assert [p.name for p in tmp_path.iterdir()] == ["route.png"]  # no temp file left behind


def test_one_point_evaluation_equals_the_array_path():
    """A single arc length (the rope ODE's right-hand side) takes a shortcut to its piece: the same
    values, bit for bit, as the same point evaluated within an array, at piece boundaries too, and
    the same refusal outside [0, L]."""
    from exucable.geometry import Bend, Straight, centreline_from_path

    c = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(2.0), Bend(90, 1.5, "left"), Bend(30, 2.0, "up"),
                                                     Straight(1.0)])
    s_all = np.concatenate([np.linspace(0.0, c.length_m, 37), [2.0, 2.0 + 1.5 * np.pi / 2]])
    for method in ("point", "tangent", "curvature_vector"):
        f = getattr(c, method)
        many = f(s_all)
        for s, row in zip(s_all, many):
            assert np.array_equal(f(float(s)), row) and np.array_equal(f(np.array([s]))[0], row)
            assert f(float(s)).shape == (3,) and f(np.array([s])).shape == (1, 3)
    with pytest.raises(ValueError, match="arc length outside"):
        c.point(c.length_m + 1.0)
    with pytest.raises(ValueError, match="arc length outside"):
        c.tangent(float("nan"))


def test_scalar_tangent_and_curvature_equal_the_array_methods():
    """The plain-float evaluator (the rope ODE's right-hand side) gives each piece's tangent and
    curvature vector to a few ulps (TOL) on straights, bends in three planes, a helix and the
    reversed route (whose pieces are helices about −k)."""
    c = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(2.0), Bend(90, 1.5, "left"), Bend(30, 2.0, "up"),
                                                     Bend(60, 0.7, "right"), Helix(2.0, 0.4, 0.3), Straight(1.0)])
    for route in (c, c.reversed()):
        for piece in route.pieces:
            at = piece.tangent_and_curvature_fn()
            for u in np.linspace(0.0, piece.length_m, 7):
                t, kn = at(float(u))
                assert all(isinstance(x, float) for x in t + kn)
                np.testing.assert_allclose(t, piece.tangent(u), rtol=0, atol=TOL)
                np.testing.assert_allclose(kn, piece.curvature_vector(u), rtol=0, atol=TOL)
