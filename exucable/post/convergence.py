"""Mesh convergence of a scalar result: observed order, Richardson extrapolation, error estimate.

Pure numpy. Given values f_1, f_2, f_3 … on meshes refined by a constant
ratio r (element length h_k = h_1 / r^(k−1)), the last three give the observed order

    p = ln((f_{n−2} − f_{n−1}) / (f_{n−1} − f_n)) / ln r,

and when the differences keep their sign (a monotone sequence) and p is plausible
(``MIN_ORDER`` ≤ p ≤ ``MAX_ORDER``), Richardson's extrapolation

    f_∞ = f_n + (f_n − f_{n−1}) / (r^p − 1)

with the error estimate |f_∞ − f_n| times the safety factor ``SAFETY`` = 1.25 (Roache's grid
convergence index for three meshes). A non-monotone (oscillating) or implausible sequence is not
extrapolated: the answer is the finest value with the error bound max |f_k − f_n| over the last
three levels, and the method says so. Each value's own uncertainty (its time scatter) is added in
quadrature to the error: an extrapolation cannot know the result better than its inputs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Extrapolation", "extrapolate", "MIN_ORDER", "MAX_ORDER", "SAFETY"]

MIN_ORDER = 0.5
MAX_ORDER = 8.0
SAFETY = 1.25


@dataclass(frozen=True)
class Extrapolation:
    """The mesh-converged estimate of a result.

    Attributes
    ----------
    value : float
        Extrapolated (or finest) value.
    error : float
        Error estimate of ``value`` (same unit), including the inputs' own uncertainty.
    order : float
        Observed order p (NaN when not computable).
    method : str
        ``"richardson"``, ``"converged"`` (the last differences are within the inputs'
        uncertainty), ``"non-monotone"`` or ``"implausible order"``, with words.
    """

    value: float
    error: float
    order: float
    method: str


def extrapolate(values, ratio: float, uncertainties=None) -> Extrapolation:
    """Extrapolate a sequence of results on meshes refined by ``ratio`` (> 1), coarsest first.

    Parameters
    ----------
    values : sequence of float
        At least three results f_1 … f_n.
    ratio : float
        Refinement ratio r = h_k / h_{k+1}.
    uncertainties : sequence of float, optional
        Each value's own uncertainty (e.g. ``pull_force_uncertainty_N``); NaN/None count as 0.
    """
    f = np.asarray(values, dtype=float)
    if f.size < 3 or not np.all(np.isfinite(f)):
        raise ValueError("extrapolate: need at least three finite values")
    if not ratio > 1.0:
        raise ValueError(f"extrapolate: the refinement ratio must be > 1, got {ratio}")
    u = np.zeros_like(f) if uncertainties is None else np.nan_to_num(
        np.asarray([np.nan if x is None else x for x in uncertainties], dtype=float), nan=0.0)
    f1, f2, f3 = f[-3:]
    u_in = float(np.max(u[-3:]))
    d1, d2 = f2 - f1, f3 - f2
    spread = float(np.max(np.abs(f[-3:] - f3)))
    if abs(d1) <= 2 * u_in and abs(d2) <= 2 * u_in:
        return Extrapolation(float(f3), math.hypot(spread, u_in), float("nan"),
                             "converged: the last differences are within twice the values' own uncertainty; "
                             "finest value, error = largest difference and that uncertainty")
    if d1 == 0.0 or d2 == 0.0 or np.sign(d1) != np.sign(d2):
        return Extrapolation(float(f3), math.hypot(spread, u_in), float("nan"),
                             "non-monotone: no extrapolation; finest value, error = largest difference of the last "
                             "three levels from it")
    p = math.log(d1 / d2) / math.log(ratio)
    if not (MIN_ORDER <= p <= MAX_ORDER):
        return Extrapolation(float(f3), math.hypot(spread, u_in), p,
                             f"implausible order {p:.2g} (outside [{MIN_ORDER}, {MAX_ORDER}]): no extrapolation; "
                             "finest value, error = largest difference of the last three levels from it")
    ext = f3 + d2 / (ratio**p - 1.0)
    return Extrapolation(float(ext), math.hypot(SAFETY * abs(ext - f3), u_in), p,
                         f"richardson: observed order {p:.3g} from the last three levels; error = "
                         f"{SAFETY} × |extrapolated − finest| (grid convergence index) and the values' own uncertainty")
