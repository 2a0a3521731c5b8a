"""Check points along a cable element and the ANCF cable shape functions at them (paper Eqs. 2-6).

A check point sits at a fixed element coordinate ξ = x/L_e in [0, 1]. Element ``e`` of the 3D ANCF
cable (Exudyn's ``NodePointSlope1`` nodes) has the 12 coordinates q_e = [r_i, r'_i, r_j, r'_j]
(positions [m] and slopes dr/dx [-]), and a point of it is

    r(ξ) = N1 r_i + N2 r'_i + N3 r_j + N4 r'_j = S(ξ) q_e,   S = [N1 I, N2 I, N3 I, N4 I]

with the cubic Hermite functions N1 = 1 - 3ξ² + 2ξ³, N2 = L(ξ - 2ξ² + ξ³), N3 = 3ξ² - 2ξ³,
N4 = L(-ξ² + ξ³) (the paper's Eqs. 4-6 in Exudyn's ordering).
"""

from __future__ import annotations

import numpy as np

__all__ = ["check_points", "hermite_unit", "hermite", "RULES"]

RULES = ("gauss", "uniform")


def check_points(n: int, rule: str = "gauss") -> tuple[np.ndarray, np.ndarray]:
    """Element coordinates and weights of ``n`` check points per element.

    Parameters
    ----------
    n : int
        Number of check points per element (>= 1).
    rule : {"gauss", "uniform"}
        ``"gauss"``: Gauss-Legendre points on [0, 1]; ``"uniform"``: midpoints (k + 1/2)/n with
        equal weights 1/n.

    Returns
    -------
    xi : ndarray, shape (n,)
        Element coordinates ξ_k in (0, 1) [-], increasing.
    weights : ndarray, shape (n,)
        Quadrature weights ω_k [-], summing to 1 (the share of the element length each point
        stands for).
    """
    n = int(n)
    if n < 1:
        raise ValueError(f"check points per element must be >= 1, got {n}")
    if rule == "gauss":
        # scipy's Golub-Welsch on the banded Jacobi matrix, O(n²): numpy's leggauss takes a dense
        # eigensolve, O(n³), 0.2-0.7 s at the paper's 800 points per element (Example 4)
        from scipy.special import roots_legendre

        x, w = roots_legendre(n)
        return 0.5 * (x + 1.0), 0.5 * w
    if rule == "uniform":
        return (np.arange(n) + 0.5) / n, np.full(n, 1.0 / n)
    raise ValueError(f"check point rule must be one of {RULES}, got {rule!r}")


def hermite_unit(xi) -> np.ndarray:
    """Hermite shape values for a unit-length element, shape (..., 4) [-].

    Columns 1 and 3 (the slope functions) are to be multiplied by the element length L [m];
    keeping them unit-length lets one table serve elements of any length.
    """
    x = np.asarray(xi, dtype=float)
    x2 = x * x
    x3 = x2 * x
    return np.stack([1.0 - 3.0 * x2 + 2.0 * x3, x - 2.0 * x2 + x3, 3.0 * x2 - 2.0 * x3, x3 - x2],
                    axis=-1)


def hermite(xi, length_m: float) -> np.ndarray:
    """Hermite values [N1, N2, N3, N4] of an element of length ``length_m`` [m], shape (..., 4)."""
    n = hermite_unit(xi)
    n[..., 1] *= length_m
    n[..., 3] *= length_m
    return n
