"""Small dense numerics shared by the finite element solvers and the reduced models.

NumPy/SciPy only (no dolfinx, no PETSc): the companion-form eigenvalues of a small quadratic
eigenproblem, the one bisection the package uses to locate a transition (a flutter onset
in μ, a band edge in forcing frequency) and the one log-log secant that finds the approach
carrying a given load (a power law through the last two solves).
"""

from __future__ import annotations

import math
import typing

import numpy as np
import scipy.linalg

__all__ = ["bisect", "dense_eigenvalues", "power_law_secant"]


def dense_eigenvalues(K: np.ndarray, C: np.ndarray, M: np.ndarray) -> np.ndarray:
    """Finite eigenvalues of (λ²M + λC + K) w = 0 from the companion linearisation
    [[0, I], [-K, -C]] z = λ [[I, 0], [0, M]] z (dense, scipy), sorted by |λ|."""
    n = K.shape[0]
    zero, eye = np.zeros((n, n)), np.eye(n)
    lam = scipy.linalg.eig(np.block([[zero, eye], [-K, -C]]),
                           np.block([[eye, zero], [zero, M]]), right=False)
    lam = lam[np.isfinite(lam)]
    return lam[np.argsort(np.abs(lam))]


def bisect(is_past: typing.Callable[[float], bool], before: float, after: float,
           tol: float) -> tuple[float, float]:
    """Shrink ``[before, after]`` around the point where ``is_past`` turns true.

    Args:
        is_past: the predicate; false at ``before``, true at ``after`` (not re-checked: the
            caller knows both ends, which are often expensive to evaluate).
        before, after: the bracket; ``after`` may lie below ``before``.
        tol: the final width |after - before|.

    Returns:
        The final bracket ``(before, after)``, still false at the first and true at the second.
    """
    if not tol > 0:
        raise ValueError(f"tol={tol!r} is invalid: must be > 0")
    while abs(after - before) > tol:
        middle = 0.5 * (before + after)
        if is_past(middle):
            after = middle
        else:
            before = middle
    return before, after


def power_law_secant(x0: float, y0: float, x1: float, y1: float, target: float,
                     min_slope: float = -math.inf) -> float:
    """The next ``log δ`` of a secant in log-log: the power law :math:`F = C\\,\\delta^k` through
    the last two solves (x = log δ, y = log F) solved for ``target`` = log F.

    Args:
        x0, y0, x1, y1: the logarithms of the last two approaches and their forces.
        target: the logarithm of the wanted force.
        min_slope: a lower bound of the exponent k (a safeguard where the force grows too
            slowly to trust the secant); k = 1 when the two approaches coincide.

    Returns:
        :math:`x_1 + (\\mathrm{target} - y_1)/\\max(k, k_{min})`,
        :math:`k = (y_1 - y_0)/(x_1 - x_0)`.
    """
    slope = (y1 - y0) / (x1 - x0) if x1 != x0 else 1.0
    return x1 + (target - y1) / max(slope, min_slope)
