r"""The Hertzian contact ellipse (Hertz 1882; Johnson 1985, *Contact mechanics*, §4.2).

Two bodies whose undeformed gap near the first point of contact is
:math:`h = A x^2 + B y^2` (:math:`x` the rolling direction; :math:`A, B > 0` the relative
curvatures, half the sums of the bodies' principal curvatures in the x-z and y-z planes,
the principal axes of both bodies aligned), of combined modulus :math:`E^*`
(:func:`fenicsfriction.elasticity.effective_modulus`; :math:`E^* = G/(1-\nu)` for
quasi-identical bodies), pressed together by :math:`F_n`, touch on an ellipse under the
pressure :math:`p = p_0\sqrt{1 - x^2/a^2 - y^2/b^2}`, :math:`p_0 = 3F_n/(2\pi ab)`. Its long
semi-axis :math:`l` lies along the smaller curvature :math:`A_l`, the short one is
:math:`s = l\sqrt{1-e^2}`, and with the complete elliptic integrals :math:`K(e), E(e)`
(Johnson 1985, §4.2):

.. math::

    A_l = \frac{p_0 s}{E^* e^2 l^2} (K - E), \qquad
    A_s = \frac{p_0 s}{E^* e^2 l^2} \Big(\frac{l^2}{s^2} E - K\Big), \qquad
    \delta = \frac{p_0 s}{E^*} K .

The ratio :math:`A_s/A_l = (E/(1-e^2) - K)/(K - E)` fixes :math:`e` (found with
:func:`scipy.optimize.brentq`), then :math:`l^3 = 3F_n (K - E)/(2\pi E^* e^2 A_l)`. Both
contain :math:`K - E \approx \pi e^2/4`, which cancels catastrophically in floating point for
nearly circular contacts, so they are evaluated with Carlson's symmetric integrals
(:math:`K = R_F(0, 1-m, 1)`, :math:`K - E = \tfrac{m}{3} R_D(0, 1-m, 1)`, :math:`m = e^2`;
Carlson 1995, "Numerical computation of real or complex elliptic integrals", Numer.
Algorithms 10): :math:`A_s/A_l = (3R_F - R_D)/((1-m) R_D)` and
:math:`l^3 = F_n R_D / (2\pi E^* A_l)`, exact down to the circle.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import numpy.typing as npt
import scipy.optimize
import scipy.special

from fenicsfriction.elasticity import check_poisson_ratio
from fenicsfriction.laws import check, check_positive

__all__ = ["HertzEllipse", "hertz_from_curvatures", "hertz_from_radii",
           "quasi_identical_modulus"]


@dataclasses.dataclass(frozen=True)
class HertzEllipse:
    """A Hertzian contact: its ellipse, peak pressure and approach.

    Attributes:
        a: semi-axis along the rolling direction x [length].
        b: lateral semi-axis (y) [length].
        Fn: normal load [force].
        p0: peak pressure 3 Fn / (2 pi a b) [force/length²].
        approach: approach of distant points of the two bodies [length]; None when the
            ellipse was given directly (:meth:`from_axes`), which fixes no elastic constants.
    """

    a: float
    b: float
    Fn: float
    p0: float
    approach: float | None = None

    @classmethod
    def from_axes(cls, a: float, b: float, Fn: float) -> HertzEllipse:
        """The ellipsoidal pressure on a given ellipse: p0 = 3 Fn / (2 pi a b).

        Args:
            a: semi-axis along x [length], > 0.
            b: semi-axis along y [length], > 0.
            Fn: normal load [force], > 0.
        """
        for name, value in (("a", a), ("b", b), ("Fn", Fn)):
            check_positive(name, value)
        return cls(a=float(a), b=float(b), Fn=float(Fn), p0=1.5 * Fn / (math.pi * a * b))

    def pressure(self, x: npt.ArrayLike, y: npt.ArrayLike) -> np.ndarray:
        """The Hertz pressure p0 sqrt(1 - x²/a² - y²/b²) at (x, y), zero outside the ellipse."""
        r2 = np.asarray(x) ** 2 / self.a**2 + np.asarray(y) ** 2 / self.b**2
        return self.p0 * np.sqrt(np.clip(1.0 - r2, 0.0, None))


def quasi_identical_modulus(G: float, nu: float) -> float:
    """E* = G / (1 - nu) of two bodies of the same shear modulus G and Poisson's ratio nu."""
    check_positive("G", G)
    check_poisson_ratio("nu", nu)
    return G / (1.0 - nu)


def _carlson(m: float) -> tuple[float, float]:
    """R_F(0, 1-m, 1) = K(m) and R_D(0, 1-m, 1) = 3 (K - E)/m."""
    return float(scipy.special.elliprf(0.0, 1.0 - m, 1.0)), \
        float(scipy.special.elliprd(0.0, 1.0 - m, 1.0))


def _parameter(ratio: float) -> float:
    """m = e² of the ellipse whose curvatures have the ratio A_s/A_l = ``ratio`` >= 1."""
    def residual(m: float) -> float:
        rf, rd = _carlson(m)
        return (3.0 * rf - rd) / ((1.0 - m) * rd) - ratio

    if residual(0.0) >= 0.0:  # ratio == 1: a circle
        return 0.0
    # the ratio grows monotonically from 1 (m = 0) to infinity (m -> 1)
    return float(scipy.optimize.brentq(residual, 0.0, 1.0 - 1e-15, xtol=1e-16, rtol=1e-15))


def hertz_from_curvatures(A: float, B: float, Fn: float, E_star: float) -> HertzEllipse:
    """The Hertz ellipse of the gap h = A x² + B y² under the load ``Fn``.

    Args:
        A: relative curvature in the x-z plane (rolling direction) [1/length], > 0.
        B: relative curvature in the y-z plane [1/length], > 0.
        Fn: normal load [force], > 0.
        E_star: effective modulus [force/length²]
            (:func:`fenicsfriction.elasticity.effective_modulus`,
            :func:`quasi_identical_modulus`), > 0.
    """
    for name, value in (("A", A), ("B", B), ("Fn", Fn), ("E_star", E_star)):
        check_positive(name, value)
    small, large = min(A, B), max(A, B)
    m = _parameter(large / small)
    rf, rd = _carlson(m)
    long_axis = (Fn * rd / (2.0 * math.pi * E_star * small)) ** (1.0 / 3.0)
    short_axis = long_axis * math.sqrt(1.0 - m)
    a, b = (long_axis, short_axis) if A <= B else (short_axis, long_axis)
    p0 = 1.5 * Fn / (math.pi * a * b)
    return HertzEllipse(a=a, b=b, Fn=float(Fn), p0=p0, approach=p0 * short_axis * rf / E_star)


def hertz_from_radii(R1x: float, R1y: float, R2x: float, R2y: float, Fn: float,
                     E_star: float) -> HertzEllipse:
    """The Hertz ellipse of two bodies whose principal radii of curvature lie along x and y.

    A radius is positive for a convex surface, negative for a concave one and ``math.inf`` for
    a flat one; A = (1/R1x + 1/R2x)/2 and B = (1/R1y + 1/R2y)/2 must both be positive.

    Args:
        R1x: body 1's radius in the x-z plane [length].
        R1y: body 1's radius in the y-z plane [length].
        R2x: body 2's radius in the x-z plane [length].
        R2y: body 2's radius in the y-z plane [length].
        Fn: normal load [force], > 0.
        E_star: effective modulus [force/length²], > 0.
    """
    for name, value in (("R1x", R1x), ("R1y", R1y), ("R2x", R2x), ("R2y", R2y)):
        check(name, value, isinstance(value, (int, float)) and value != 0.0
              and not math.isnan(value), "a radius is a nonzero number (inf for a flat body)")
    A = 0.5 * (1.0 / R1x + 1.0 / R2x)
    B = 0.5 * (1.0 / R1y + 1.0 / R2y)
    for name, value in (("(1/R1x + 1/R2x)/2", A), ("(1/R1y + 1/R2y)/2", B)):
        check(name, value, value > 0.0, "the relative curvature must be positive (the "
              "concave body must be the flatter one)")
    return hertz_from_curvatures(A, B, Fn, E_star)
