r"""The closed forms the two-body scenes are checked against (Johnson 1985, *Contact
Mechanics*, chapters 4 and 7; Hertz 1882; Cattaneo 1938, Mindlin 1949).

Two elastic bodies of moduli :math:`E_i`, Poisson ratios :math:`\nu_i` act as one of effective
modulus :math:`1/E^* = (1-\nu_1^2)/E_1 + (1-\nu_2^2)/E_2` against a rigid flat
(:mod:`fenicsfriction.elasticity`, with Hertz's pressure profile).
"""

from __future__ import annotations

import math

import numpy as np

from fenicsfriction import elasticity
from fenicsfriction.elasticity import hertz_pressure
from fenicsfriction.laws import check

__all__ = ["cattaneo_stick_half_width", "cattaneo_traction", "dundurs_beta", "effective_modulus",
           "fit_hertz_pressure", "hertz_line_contact", "hertz_load", "hertz_point_contact",
           "hertz_pressure"]


def effective_modulus(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """:func:`fenicsfriction.elasticity.effective_modulus` of two bodies the finite element
    scenes can model: compressible (ν < 0.5; the displacement formulation locks at 0.5)."""
    for name, value in (("nu1", nu1), ("nu2", nu2)):
        check(name, value, value < 0.5, "Poisson's ratio must be in (-1, 0.5)")
    return elasticity.effective_modulus(E1, nu1, E2, nu2)


def dundurs_beta(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """The second Dundurs constant (plane strain; Johnson 1985, chapter 5):

    .. math:: \\beta = \\frac{(1-2\\nu_1)/G_1 - (1-2\\nu_2)/G_2}
                       {2\\,[(1-\\nu_1)/G_1 + (1-\\nu_2)/G_2]},

    :math:`G_i = E_i / (2(1+\\nu_i))`. The normal and tangential contact problems of two
    half-spaces uncouple when β = 0 (quasi-identical bodies: De Pater 1962; Kalker 1986, §4).
    """
    effective_modulus(E1, nu1, E2, nu2)  # validates the four, naming each
    G1, G2 = E1 / (2 * (1 + nu1)), E2 / (2 * (1 + nu2))
    return ((1 - 2 * nu1) / G1 - (1 - 2 * nu2) / G2) / (2 * ((1 - nu1) / G1 + (1 - nu2) / G2))


def hertz_line_contact(load: float, radius: float, E_star: float) -> tuple[float, float]:
    """Cylinder on a flat, plane strain (Johnson 1985, chapter 4): the half-width
    :math:`a = \\sqrt{4 P R / (\\pi E^*)}` and peak pressure :math:`p_0 = 2 P / (\\pi a)` under
    the load ``load`` = P per unit length."""
    check("load", load, load > 0, "the load must be > 0")
    check("radius", radius, radius > 0, "the radius must be > 0")
    a = math.sqrt(4 * load * radius / (math.pi * E_star))
    return a, 2 * load / (math.pi * a)


def hertz_point_contact(load: float, radius: float, E_star: float) -> tuple[float, float]:
    """Sphere on a flat (Johnson 1985, chapter 4): contact radius
    :math:`a = (3 F R / (4 E^*))^{1/3}` and peak pressure :math:`p_0 = 3 F / (2 \\pi a^2)`
    under the total force ``load`` = F."""
    check("load", load, load > 0, "the load must be > 0")
    check("radius", radius, radius > 0, "the radius must be > 0")
    a = (3 * load * radius / (4 * E_star)) ** (1 / 3)
    return a, 3 * load / (2 * math.pi * a**2)


def hertz_load(half_width: float, radius: float, E_star: float, dim: int = 2) -> float:
    """The load that makes Hertz's contact half-width (2D: P per unit length) or radius (3D:
    the total F) equal ``half_width``: the inverse of :func:`hertz_line_contact` and
    :func:`hertz_point_contact`."""
    check("dim", dim, dim in (2, 3), "2 or 3")
    a = half_width
    return (a**2 * math.pi * E_star / (4 * radius) if dim == 2
            else 4 * E_star * a**3 / (3 * radius))


def fit_hertz_pressure(r: np.ndarray, pressure: np.ndarray) -> tuple[float, float]:
    """The half-width (radius) a and peak p_0 of the Hertz profile that fits nodal pressures.

    :math:`p^2 = p_0^2 - (p_0/a)^2 r^2` is linear in :math:`r^2`: a least-squares line through
    the points of ``pressure > 0`` gives both. Unlike the nodes where contact ends, which
    place the edge only to within one element, the fit uses every contact node, so its error
    is that of the pressures, not of where the nodes happen to fall.
    """
    r, pressure = np.asarray(r, dtype=float), np.asarray(pressure, dtype=float)
    contact = pressure > 0
    check("pressure", int(contact.sum()), contact.sum() >= 2, "at least two contact nodes")
    slope, intercept = np.polyfit(r[contact] ** 2, pressure[contact] ** 2, 1)
    check("pressure", slope, slope < 0 < intercept, "a profile falling from its peak")
    return float(math.sqrt(-intercept / slope)), float(math.sqrt(intercept))


def cattaneo_stick_half_width(a: float, q_ratio: float) -> float:
    """Stick half-width :math:`c = a\\sqrt{1 - Q/(\\mu P)}` under a tangential force Q rising
    monotonically to ``q_ratio`` = Q/(μP) < 1 (Johnson 1985, chapter 7)."""
    check("q_ratio", q_ratio, 0 <= q_ratio < 1, "Q/(mu P) must be in [0, 1)")
    return a * math.sqrt(1 - q_ratio)


def cattaneo_traction(x: np.ndarray, a: float, p0: float, mu: float,
                      q_ratio: float) -> np.ndarray:
    """Tangential traction of the cylinders (Johnson 1985, chapter 7): μ p(x) in the slip
    zones c ≤ |x| ≤ a, minus :math:`\\mu p_0 (c/a)\\sqrt{1 - x^2/c^2}` in the stick zone."""
    c = cattaneo_stick_half_width(a, q_ratio)
    q = mu * hertz_pressure(x, a, p0)
    if c > 0:
        q = q - mu * p0 * (c / a) * np.sqrt(np.clip(1 - (np.asarray(x) / c) ** 2, 0.0, None))
    return q
