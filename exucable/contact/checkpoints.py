"""Check points along a cable element and the ANCF cable shape functions at them (paper Eqs. 2-6).

A check point sits at a fixed element coordinate ξ = x/L_e in [0, 1]. Element ``e`` of the 3D ANCF
cable (Exudyn's ``NodePointSlope1`` nodes) has the 12 coordinates q_e = [r_i, r'_i, r_j, r'_j]
(positions [m] and slopes dr/dx [-]), and a point of it is

    r(ξ) = N1 r_i + N2 r'_i + N3 r_j + N4 r'_j = S(ξ) q_e,   S = [N1 I, N2 I, N3 I, N4 I]

with the cubic Hermite functions N1 = 1 - 3ξ² + 2ξ³, N2 = L(ξ - 2ξ² + ξ³), N3 = 3ξ² - 2ξ³,
N4 = L(-ξ² + ξ³) (the paper's Eqs. 4-6 in Exudyn's ordering).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

__all__ = ["check_points", "gauss_legendre", "hermite_unit", "hermite", "RULES"]

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
    if rule not in RULES:
        raise ValueError(f"check point rule must be one of {RULES}, got {rule!r}")
    xi, weights = _rule(n, rule)
    return xi.copy(), weights.copy()


@lru_cache(maxsize=8)
def _rule(n: int, rule: str) -> tuple[np.ndarray, np.ndarray]:
    """:func:`check_points`' table, kept per (n, rule): at the paper's 800 points the Gauss rule
    costs 15 ms, a twentieth of a steady Example 4 run, and every run, sweep point and validation
    case of a process asks for the same few rules."""
    if rule == "gauss":
        x, w = gauss_legendre(n)
        return 0.5 * (x + 1.0), 0.5 * w
    return (np.arange(n) + 0.5) / n, np.full(n, 1.0 / n)


def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes on [-1, 1], ascending, and their weights (summing to 2), ``n >= 1``.

    Golub-Welsch as in scipy's ``roots_legendre`` (to rounding, ~1e-15): the nodes are the
    eigenvalues of the symmetric tridiagonal Jacobi matrix of the Legendre recurrence, off-diagonal
    k/√(4k² − 1) (O(n²); numpy's ``leggauss`` takes a dense eigensolve, O(n³), 0.2-0.7 s at the
    paper's 800 points per element), polished by one Newton step on P_n; the weights are
    2 / ((1 − x²) P_n'(x)²) (Abramowitz & Stegun 25.4.29). Here rather than ``scipy.special``,
    whose import is a tenth of a second of ``exucable run``'s fixed cost (docs/performance.md); scipy.linalg is
    loaded anyway (numba's BLAS).
    """
    from scipy.linalg import eigvalsh_tridiagonal

    k = np.arange(1.0, n)
    x = eigvalsh_tridiagonal(np.zeros(n), k / np.sqrt(4.0 * k * k - 1.0))

    def legendre_and_derivative(x):
        p_prev, p = np.ones_like(x), x.copy()
        for j in range(2, n + 1):               # Bonnet: j P_j = (2j − 1) x P_{j−1} − (j − 1) P_{j−2}
            p_prev, p = p, ((2 * j - 1) * x * p - (j - 1) * p_prev) / j
        if n == 1:
            p_prev, p = np.ones_like(x), x
        return p, n * (p_prev - x * p) / (1.0 - x * x)

    p, dp = legendre_and_derivative(x)
    x = x - p / dp
    _, dp = legendre_and_derivative(x)
    w = 2.0 / ((1.0 - x * x) * dp * dp)
    x, w = 0.5 * (x - x[::-1]), 0.5 * (w + w[::-1])    # exactly symmetric, like scipy's
    return x, w * (2.0 / w.sum())


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
