r"""Closed forms of the rolling and shift scenes (two identical elastic bodies).

Notation: :math:`G, \nu` the bodies' shear modulus and Poisson ratio, :math:`E^*` the contact
modulus of the pair, :math:`1/E^* = 2(1-\nu^2)/E`, i.e. :math:`E^* = G/(1-\nu)`
(:func:`fenicsfriction.studies.rolling.hertz.quasi_identical_modulus`); R the relative
radius of curvature :math:`1/R = 1/R_1 + 1/R_2` (two cylinders of radius :math:`R_1`:
:math:`R = R_1/2`); a (b) the contact's semi-axis along (across) the rolling direction x.

* Carter's rolling cylinders (Carter 1926, "On the action of a locomotive driving wheel";
  Johnson 1985, *Contact Mechanics*, section 8.3), derived here for the conventions of the
  package: rolling in +x, leading edge at x = +a, slip
  :math:`s = \xi - \partial\Delta u_x/\partial x`.
  The traction on body 1 is :math:`q = -\mathrm{sgn}(\xi)\mu p_0 [\sqrt{1 - x^2/a^2} -
  (c/a)\sqrt{1 - (x - a + c)^2/c^2}]`: the second term alone is the stick zone's,
  :math:`a - 2c \le x \le a`. The half-plane's surface gradient under a tangential traction q
  (Johnson 1985, chapter 2), doubled for the pair, is :math:`\partial\Delta u_x/\partial x =
  -(2/(\pi E^*)) \int q(s)/(x - s) ds`, and with :math:`\int \sqrt{a^2 - s^2}/(x - s) ds = \pi x`
  (|x| < a) it is constant over the stick zone,
  :math:`\mathrm{sgn}(\xi)\, 2\mu p_0 (a - c)/(a E^*)`;
  stick (s = 0) there and Hertz's :math:`p_0 = a E^*/(2R)` give
  :math:`|\xi| = (\mu a/R)(1 - c/a)` and the force :math:`F_x = -\mathrm{sgn}(\xi)\mu P
  (1 - c^2/a^2)`, :math:`P = \pi a p_0/2`. Small creepage: :math:`F_x = -(\pi/2) a E^* \xi`.
* Cattaneo-Mindlin's shifted spheres (Cattaneo 1938; Mindlin 1949; Johnson 1985, section
  7.2): under a monotonically rising tangential force Q the stick disc has the radius
  :math:`c = a(1 - Q/(\mu P))^{1/3}` and the traction :math:`\mu p_0 [\sqrt{1 - r^2/a^2} -
  (c/a)\sqrt{1 - r^2/c^2}]` along Q, exact for ν = 0 (for ν ≠ 0 it neglects the traction
  perpendicular to Q that the stick condition needs).

Kalker's creepage coefficients of the linear theory (:math:`F_x = -G ab C_{11}\xi`, ...) are
in :mod:`fenicsfriction.studies.rolling.kalker`.
"""

from __future__ import annotations

import math

import numpy as np

from fenicsfriction.elasticity import hertz_pressure
from fenicsfriction.laws import check, check_positive

__all__ = ["carter_force", "carter_stick_half_width", "carter_traction", "ellipse_load",
           "hertz_line_radius", "mindlin_stick_radius", "mindlin_traction"]

def hertz_line_radius(a: float, p0: float, E_star: float) -> float:
    """The relative radius R of the cylinders whose Hertz contact has half-width a and peak
    pressure p0: :math:`p_0 = a E^*/(2R)` (Johnson 1985, chapter 4)."""
    for name, value in (("a", a), ("p0", p0), ("E_star", E_star)):
        check_positive(name, value)
    return a * E_star / (2 * p0)


def ellipse_load(a: float, b: float | None, p0: float) -> float:
    """The total force of Hertz's pressure: :math:`2\\pi a b p_0/3` on an ellipse,
    :math:`\\pi a p_0/2` per unit length on a strip (``b=None``)."""
    return math.pi * a * p0 / 2 if b is None else 2 * math.pi * a * b * p0 / 3


def carter_stick_half_width(creepage: float, mu: float, a: float, R: float) -> float:
    """The stick zone's half-width :math:`c = a - |\\xi| R/\\mu` (0 once it has vanished:
    full slip from :math:`|\\xi| = \\mu a/R`)."""
    check_positive("mu", mu)
    return max(a - abs(creepage) * R / mu, 0.0)


def carter_force(creepage: float, mu: float, a: float, p0: float, R: float) -> float:
    """Carter's longitudinal force per unit length on body 1,
    :math:`-\\mathrm{sgn}(\\xi)\\mu P (1 - c^2/a^2)`."""
    c = carter_stick_half_width(creepage, mu, a, R)
    return -float(np.sign(creepage)) * mu * ellipse_load(a, None, p0) * (1 - (c / a) ** 2)


def carter_traction(x: np.ndarray, creepage: float, mu: float, a: float, p0: float,
                    R: float) -> np.ndarray:
    """Carter's traction on body 1 at x (0 outside the contact)."""
    c = carter_stick_half_width(creepage, mu, a, R)
    q = hertz_pressure(x, a, p0)
    if c > 0:
        q = q - (c / a) * hertz_pressure(np.asarray(x) - (a - c), c, p0)
    return -float(np.sign(creepage)) * mu * q


def mindlin_stick_radius(a: float, q_ratio: float) -> float:
    """Cattaneo-Mindlin's stick radius :math:`c = a(1 - Q/(\\mu P))^{1/3}`."""
    check("q_ratio", q_ratio, 0 <= q_ratio <= 1, "Q/(mu P) must be in [0, 1]")
    return a * (1 - q_ratio) ** (1 / 3)


def mindlin_traction(r: np.ndarray, a: float, p0: float, mu: float,
                     q_ratio: float) -> np.ndarray:
    """Cattaneo-Mindlin's traction along Q at the distance r from the centre."""
    c = mindlin_stick_radius(a, q_ratio)
    q = mu * hertz_pressure(r, a, p0)
    if c > 0:
        q = q - mu * (c / a) * hertz_pressure(r, c, p0)
    return q

