"""Survey routes: polyline vertices filleted into circular arcs, and the CSV reader.

Reference values are closed forms: tangent length T = R·tan(θ/2), route length
Σ legs − Σ 2T + Σ Rθ. Tolerances: coordinates of order 1–10 m evaluated in closed form agree to
a few ulps; 1e-12 m absolute leaves room for ~100 ulps of rounding.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from exucable.errors import GeometryError
from exucable.geometry import centreline_from_survey, read_survey_csv

TOL = 1e-12  # rounding budget for O(1–10 m) closed-form coordinates (see module docstring)

SPATIAL_POINTS = np.array([
    [0.0, 0.0, 0.0],
    [4.0, 0.0, 0.0],
    [5.0, 3.0, 0.5],
    [5.0, 3.0, 4.0],
    [1.0, 6.0, 5.0],
])


def _turning_angle(d_in, d_out):
    return math.atan2(np.linalg.norm(np.cross(d_in, d_out)), np.dot(d_in, d_out))


@pytest.mark.parametrize("L1, L2, R, corner_deg", [
    (3.0, 2.0, 0.5, 90.0),     # L-shape
    (5.0, 4.0, 1.0, 135.0),    # obtuse corner: turning 45°
    (2.0, 2.0, 0.2, 30.0),     # sharp corner: turning 150°
])
def test_l_shape_length(L1, L2, R, corner_deg):
    theta = math.pi - math.radians(corner_deg)  # turning angle at the vertex
    d_out = np.array([math.cos(theta), math.sin(theta), 0.0])
    pts = np.array([[0.0, 0.0, 0.0], [L1, 0.0, 0.0], [L1, 0.0, 0.0] + L2 * d_out])
    line = centreline_from_survey(pts, R)
    T = R * math.tan(theta / 2)
    assert line.length_m == pytest.approx(L1 + L2 - 2 * T + R * theta, rel=1e-14)
    assert line.turning_angle_rad == pytest.approx(theta, rel=1e-13)
    assert [p.kind for p in line.pieces] == ["straight", "bend", "straight"]
    np.testing.assert_allclose(line.point(0.0), pts[0], atol=TOL)
    np.testing.assert_allclose(line.point(line.length_m), pts[-1], atol=TOL)
    # The arc's centre is on the bisector at distance R/cos(θ/2) from the vertex.
    arc = line.pieces[1]
    centre = arc.centre_m
    assert np.linalg.norm(centre - pts[1]) == pytest.approx(R / math.cos(theta / 2), rel=1e-13)


@pytest.mark.parametrize("radius", [0.4, [0.3, 0.5, 0.2], [math.nan, 0.3, 0.5, 0.2, math.nan]])
def test_fillet_tangency_spatial(radius):
    line = centreline_from_survey(SPATIAL_POINTS, radius)
    r = np.asarray(radius, dtype=float)
    radii = np.full(3, r) if r.ndim == 0 else (r[1:-1] if r.size == 5 else r)  # one per interior vertex
    arcs = [p for p in line.pieces if p.kind == "bend"]
    assert len(arcs) == 3
    legs = np.diff(SPATIAL_POINTS, axis=0)
    d = legs / np.linalg.norm(legs, axis=1)[:, None]
    expected_length = np.sum(np.linalg.norm(legs, axis=1))
    for j, arc in enumerate(arcs):
        vertex = SPATIAL_POINTS[j + 1]
        d_in, d_out = d[j], d[j + 1]
        theta = _turning_angle(d_in, d_out)
        T = radii[j] * math.tan(theta / 2)
        assert arc.radius_m == pytest.approx(radii[j], rel=1e-15)
        assert arc.turning_angle_rad == pytest.approx(theta, rel=1e-13)
        # Tangent at the arc's ends equals the legs' directions ...
        np.testing.assert_allclose(arc.tangent(0.0), d_in, atol=TOL)
        np.testing.assert_allclose(arc.end_tangent, d_out, atol=TOL)
        # ... and its ends lie on the legs, T from the vertex.
        np.testing.assert_allclose(arc.start_m, vertex - T * d_in, atol=TOL)
        np.testing.assert_allclose(arc.end_m, vertex + T * d_out, atol=TOL)
        expected_length += radii[j] * theta - 2 * T
    assert line.length_m == pytest.approx(expected_length, rel=1e-14)
    assert np.max(line.tangent_jumps_rad()) < 1e-12
    np.testing.assert_allclose(line.point(line.length_m), SPATIAL_POINTS[-1], atol=TOL)


def test_collinear_vertex_gets_no_arc():
    pts = [[0, 0, 0], [1, 1, 1], [2.5, 2.5, 2.5], [2.5, 4.5, 2.5]]
    line = centreline_from_survey(pts, 0.5)
    assert [p.kind for p in line.pieces] == ["straight", "straight", "bend", "straight"]
    assert line.pieces[0].length_m == pytest.approx(math.sqrt(3), rel=1e-15)


def test_exact_fit_leaves_no_straight_between_fillets():
    # Two 90° corners 1 m apart with R = 0.5: T = 0.5 each, T + T = leg, so the arcs meet.
    pts = [[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0]]
    line = centreline_from_survey(pts, 0.5)
    assert [p.kind for p in line.pieces] == ["straight", "bend", "bend", "straight"]
    assert line.length_m == pytest.approx(1.5 + math.pi / 2 + 1.5, rel=1e-14)
    np.testing.assert_allclose(line.pieces[1].end_m, line.pieces[2].start_m, atol=TOL)


@pytest.mark.parametrize("points, radius, key", [
    # last leg: T = R = 1.1 > 1 m
    ([[0, 0, 0], [3, 0, 0], [3, 1, 0]], 1.1, "points[1]"),
    # first leg: T = R = 1.1 > 1 m
    ([[0, 0, 0], [1, 0, 0], [1, 3, 0]], 1.1, "points[1]"),
    # inner leg points[2]–points[3] of 1 m: T2 = 0.4, T3 = 0.7 → 1.1 > 1; points[3] has the larger T
    ([[0, 0, 0], [2, 0, 0], [2, 2, 0], [3, 2, 0], [3, 5, 0], [5, 5, 0]], [0.5, 0.4, 0.7, 0.1], "points[3]"),
    ([[0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 0, 0]], 0.1, "points[2]"),           # coincident points
    ([[0, 0, 0], [1, 0, 0], [0, 0, 0]], 0.1, "points[1]"),                      # reversal
    ([[0, 0, 0], [1, 0, math.nan], [2, 0, 0]], 0.1, "points[1]"),
    ([[0, 0, 0]], 0.1, "points"),
    ([[0, 0], [1, 0]], 0.1, "points"),
    ([[0, 0, 0], [1, 0, 0], [1, 1, 0]], 0.0, "bend_radius"),
    ([[0, 0, 0], [1, 0, 0], [1, 1, 0], [2, 1, 0]], [0.1, -0.1], "bend_radius[1]"),
    ([[0, 0, 0], [1, 0, 0], [1, 1, 0], [2, 1, 0]], [None, 0.1, math.nan, None], "bend_radius[2]"),
    ([[0, 0, 0], [1, 0, 0], [1, 1, 0], [2, 1, 0]], [0.1, 0.1, 0.1], "bend_radius"),
])
def test_survey_errors_name_the_input(points, radius, key):
    with pytest.raises(GeometryError) as info:
        centreline_from_survey(points, radius)
    assert info.value.key == key


def test_misfit_message_names_both_fillets_and_the_leg():
    with pytest.raises(GeometryError) as info:
        centreline_from_survey([[0, 0, 0], [2, 0, 0], [2, 2, 0], [3, 2, 0], [3, 5, 0], [5, 5, 0]],
                               [0.5, 0.4, 0.7, 0.1])
    assert "points[2]" in info.value.message and "points[2]–points[3]" in info.value.message


def test_survey_reversed():
    line = centreline_from_survey(SPATIAL_POINTS, 0.4)
    rev = line.reversed()
    s = np.linspace(0, line.length_m, 101)
    np.testing.assert_allclose(rev.point(s), line.point(line.length_m - s), atol=1e-11)
    np.testing.assert_allclose(rev.point(0.0), SPATIAL_POINTS[-1], atol=TOL)


# --------------------------------------------------------------------------- CSV
def test_csv_without_radius(tmp_path):
    f = tmp_path / "route.csv"
    f.write_text("x,y,z\n0,0,0\n\n# a comment\n4, 0, 0\n5,3,0.5\n")
    points, radii = read_survey_csv(f)
    np.testing.assert_array_equal(points, [[0, 0, 0], [4, 0, 0], [5, 3, 0.5]])
    assert radii is None


def test_csv_with_radius_builds_the_same_route(tmp_path):
    f = tmp_path / "route.csv"
    rows = ["x,y,z,bend_radius"]
    radius = [None, 0.3, 0.5, 0.2, None]
    for p, r in zip(SPATIAL_POINTS, radius):
        rows.append(",".join(f"{v:.17g}" for v in p) + "," + ("" if r is None else f"{r}"))
    rows[1] = rows[1] + "9.9"  # a value on the first row is ignored
    f.write_text("\n".join(rows) + "\n")
    points, radii = read_survey_csv(f)
    np.testing.assert_array_equal(points, SPATIAL_POINTS)
    assert np.isnan(radii[0]) and np.isnan(radii[-1])
    np.testing.assert_array_equal(radii[1:-1], [0.3, 0.5, 0.2])
    from_csv = centreline_from_survey(points, radii)
    direct = centreline_from_survey(SPATIAL_POINTS, [0.3, 0.5, 0.2])
    assert from_csv.length_m == direct.length_m


@pytest.mark.parametrize("text, key", [
    ("x,y,z\n0,0,0\n1,0,0\n2,0,0\n3,0,0\n4,0,0\n5,zero,0\n", "points_csv line 7"),
    ("x,y,z,bend_radius\n0,0,0,\n1,0,0,0.1\n2,1,0,abc\n3,1,0,\n", "points_csv line 4"),
    ("x,y,z,bend_radius\n0,0,0,\n1,0,0,\n2,1,0,\n", "points_csv line 3"),          # empty interior
    ("x,y,z,bend_radius\n0,0,0,\n1,0,0,-0.5\n2,1,0,\n", "points_csv line 3"),
    ("x,y,z\n0,0,0\n1,0\n", "points_csv line 3"),
    ("x,y,z\n0,0,0\n1,0,inf\n", "points_csv line 3"),
    ("# header below\nx,y,radius\n0,0,0\n1,0,0\n", "points_csv line 2"),
    ("x,y,z\n0,0,0\n", "points_csv"),
    ("", "points_csv"),
])
def test_csv_malformed_line_named(tmp_path, text, key):
    f = tmp_path / "bad.csv"
    f.write_text(text)
    with pytest.raises(GeometryError) as info:
        read_survey_csv(f)
    assert info.value.key == key


def test_csv_missing_file(tmp_path):
    with pytest.raises(GeometryError) as info:
        read_survey_csv(tmp_path / "absent.csv")
    assert info.value.key == "points_csv"
