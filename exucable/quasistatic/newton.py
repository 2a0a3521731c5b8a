"""Damped Newton for the quasi-static models' shape problems: an energy-decreasing step size and a
banded Jacobian by finite differences in colours. numpy and scipy only.

Each model (:mod:`.clearance`, :mod:`.beam`) finds its cable's offsets by minimising
an energy whose gradient is a force residual; the steps differ (along the wall, through a band), the
safeguard is the same: halve the step until the energy falls by the Armijo fraction of
what the linear model promises (Nocedal & Wright, *Numerical Optimization*, 2nd ed., Alg. 3.1).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["armijo_step", "banded_jacobian"]

ARMIJO_FRACTION = 1e-4


def armijo_step(energy_at: Callable[[float], float], energy_0: float, slope: float,
                min_step: float = 1e-9, slack: float = 0.0) -> float:
    """The largest of 1, ½, ¼, … (down to ``min_step``) at which the energy falls enough.

    Parameters
    ----------
    energy_at : callable
        Energy [J] after a step of the given fraction of the Newton step.
    energy_0 : float
        Energy at the start [J].
    slope : float
        Directional derivative of the energy along the full step [J] (negative for a descent step).
    min_step : float
        Smallest fraction tried; returned as it is when even that does not decrease the energy.
    slack : float
        Round-off allowance [J] added to the acceptance bound.

    Returns
    -------
    float
        The accepted fraction of the step.
    """
    alpha = 1.0
    while True:
        if energy_at(alpha) <= energy_0 + ARMIJO_FRACTION * alpha * slope + slack or alpha < min_step:
            return alpha
        alpha *= 0.5


def banded_jacobian(residual: Callable[[np.ndarray], np.ndarray], x: np.ndarray, free: np.ndarray,
                    half_band: int, eps: float, r0: np.ndarray | None = None) -> np.ndarray:
    """Jacobian of ``residual`` in ``x[free]`` by forward differences, in LAPACK band storage.

    A residual whose component i depends only on the unknowns within ``half_band`` of i is
    differenced in 2·half_band + 1 colours: every unknown of one colour is perturbed at once.

    Parameters
    ----------
    residual : callable
        ``x`` (the full flat vector) → residual of the free unknowns, shape ``(m,)``.
    x : ndarray
        Flat vector of all unknowns at the linearisation point.
    free : ndarray of int
        Indices of the free unknowns in ``x`` (``m`` of them).
    half_band : int
        Half band width of the Jacobian.
    eps : float
        Perturbation of one unknown (in ``x``'s unit).
    r0 : ndarray, optional
        ``residual(x)`` if already known.

    Returns
    -------
    ndarray, shape (2·half_band + 1, m)
        For ``scipy.linalg.solve_banded((half_band, half_band), ab, b)``.
    """
    r0 = residual(x) if r0 is None else r0
    m = free.size
    width = 2 * half_band + 1
    ab = np.zeros((width, m))
    for colour in range(width):
        cols = np.arange(colour, m, width)
        trial = x.copy()
        trial[free[cols]] += eps
        dr = (residual(trial) - r0) / eps
        for off in range(-half_band, half_band + 1):
            rows = cols + off
            ok = (rows >= 0) & (rows < m)
            ab[half_band + off, cols[ok]] = dr[rows[ok]]
    return ab
