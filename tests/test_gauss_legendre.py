"""Gauss-Legendre check points (exucable.contact.checkpoints.gauss_legendre), which replaced
scipy.special.roots_legendre in a run (issue 15, fixed cost).

Checked against closed forms: an n-point rule integrates x^k exactly for k <= 2n - 1, so
Σ w x^k = 2/(k + 1) for even k and 0 for odd k. The tolerance 1e-13 is rounding in a sum of n
terms of size ≤ 1 (a wrong node or weight breaks the identities at the 1e-3 level or worse), and
for n = 800 (Example 4's paper fidelity) the moments up to x^40 are checked (higher ones are tiny
and dominated by the end nodes). Against scipy's roots_legendre: nodes to 2e-16, weights to 1e-8
relative (scipy's own weights err by 3e-9 at n = 800 against a 40-digit mpmath solution, ours by 2e-12).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import roots_legendre

from exucable.contact.checkpoints import check_points, gauss_legendre


@pytest.mark.parametrize("n", [1, 2, 3, 8, 30, 200, 800])
def test_gauss_legendre_integrates_polynomials_exactly(n):
    x, w = gauss_legendre(n)
    assert np.all(np.diff(x) > 0.0) and np.all(w > 0.0)
    for k in range(min(2 * n, 41)):
        exact = 2.0 / (k + 1) if k % 2 == 0 else 0.0
        assert np.sum(w * x**k) == pytest.approx(exact, abs=1e-13)


@pytest.mark.parametrize("n", [1, 5, 30, 200, 800])
def test_gauss_legendre_equals_scipy(n):
    x, w = gauss_legendre(n)
    xr, wr = roots_legendre(n)
    np.testing.assert_allclose(x, xr, rtol=0.0, atol=2.3e-16)
    np.testing.assert_allclose(w, wr, rtol=1e-8)


def test_gauss_check_points_on_the_unit_element():
    xi, w = check_points(4, "gauss")
    xr, wr = roots_legendre(4)
    np.testing.assert_allclose(xi, 0.5 * (xr + 1.0), atol=1e-15)
    np.testing.assert_allclose(w, 0.5 * wr, rtol=1e-14)
    assert w.sum() == pytest.approx(1.0, abs=1e-15)
