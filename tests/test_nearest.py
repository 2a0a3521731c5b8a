"""The exact nearest-sample search of the trust gauge (exucable.contact.nearest) against scipy's
cKDTree, which it replaces in a run (issue 15, fixed cost). Exact: the same index wherever the
nearest sample is unique (ties have measure zero for these random points), so the test asks for
equality, and for equal distances as a guard against a tie."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from exucable.contact.nearest import NearestSample
from exucable.geometry import Bend, Helix, Straight, centreline_from_path


def _check(samples, points):
    got = NearestSample(samples)(points)
    d_ref, ref = cKDTree(samples).query(points)
    d_got = np.linalg.norm(points - samples[got], axis=1)
    np.testing.assert_array_equal(d_got, d_ref)
    assert np.mean(got == ref) == 1.0


@pytest.mark.parametrize("n", [1, 2, 7, 100, 5674])
def test_nearest_sample_on_a_conduit_axis_equals_cKDTree(n):
    route = centreline_from_path([0, 0, 0], [1, 0, 0], [Straight(2.0), Bend(90.0, 0.5, turn="left"),
                                                       Helix(2.0, 1.0, 0.05), Straight(1.0)])
    s = np.linspace(0.0, route.length_m, n)
    samples = np.asarray(route.point(s), dtype=float).reshape(n, 3)
    rng = np.random.default_rng(n)
    near = samples[rng.integers(0, n, 400)] + rng.normal(scale=3e-3, size=(400, 3))  # a cable in the conduit
    far = rng.uniform(-5.0, 5.0, size=(200, 3))                                    # a cable thrown out
    _check(samples, np.concatenate([near, far]))


def test_nearest_sample_in_a_random_cloud_equals_cKDTree():
    rng = np.random.default_rng(3)
    _check(rng.normal(size=(3000, 3)), rng.normal(size=(500, 3)) * 2.0)


def test_nearest_sample_needs_a_sample():
    with pytest.raises(ValueError, match="at least one sample"):
        NearestSample(np.zeros((0, 3)))
