"""Extrapolation (exucable.post.convergence) on problems of known order, and honest refusals."""

from __future__ import annotations

import numpy as np
import pytest

from exucable.post.convergence import extrapolate


def _trapezoid_sin(n):
    x = np.linspace(0.0, np.pi, n + 1)
    y = np.sin(x)
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)))


def test_richardson_on_the_trapezoid_rule_recovers_order_two_and_the_integral():
    """∫₀^π sin = 2 exactly; the trapezoid rule's error is O(h²)."""
    values = [_trapezoid_sin(n) for n in (8, 16, 32)]
    ex = extrapolate(values, 2.0)
    assert ex.order == pytest.approx(2.0, abs=0.01)
    assert ex.method.startswith("richardson")
    assert abs(ex.value - 2.0) < 1e-5                  # finest alone is 1.6e-3 off
    assert abs(ex.value - 2.0) <= ex.error             # the estimate covers the true error
    # GCI-style: 1.25 × the finest level's own error (conservative for the extrapolated value)
    assert ex.error == pytest.approx(1.25 * abs(values[-1] - 2.0), rel=0.01)


def test_known_power_law_with_offset():
    h = np.array([0.4, 0.2, 0.1, 0.05])
    f = 205.37 + 3.0 * h**2.5
    ex = extrapolate(f, 2.0)
    assert ex.order == pytest.approx(2.5, rel=1e-9) and ex.value == pytest.approx(205.37, rel=1e-12)


def test_non_monotone_sequence_is_not_extrapolated():
    ex = extrapolate([100.0, 101.0, 100.5], 2.0)
    assert ex.method.startswith("non-monotone") and ex.value == 100.5 and ex.error == pytest.approx(0.5)


def test_differences_within_the_values_uncertainty_count_as_converged():
    ex = extrapolate([100.0, 100.01, 100.015], 2.0, uncertainties=[0.02, 0.02, 0.02])
    assert ex.method.startswith("converged") and ex.error >= 0.02


def test_implausible_order_is_refused():
    ex = extrapolate([100.0, 110.0, 119.0], 2.0)          # p = 0.15: barely converging
    assert ex.method.startswith("implausible") and ex.error == pytest.approx(19.0)


def test_bad_input():
    with pytest.raises(ValueError):
        extrapolate([1.0, 2.0], 2.0)
    with pytest.raises(ValueError):
        extrapolate([1.0, 2.0, 3.0], 1.0)
