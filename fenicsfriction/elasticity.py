r"""Closed forms of linear elasticity that more than one family of studies checks against
(NumPy only: the mesh-free models import it too).

Lamé's parameters from Young's modulus and Poisson's ratio (:func:`lame`; numbers or UFL
values: the finite element forms take them too). Two elastic bodies of moduli :math:`E_i` and
Poisson ratios :math:`\nu_i` pressed together act as one body of effective modulus :math:`E^*`
against a rigid one (plane strain in 2D; Johnson 1985, *Contact Mechanics*, section 4.2), and
Hertz's pressure is an ellipsoid over the contact.
"""

from __future__ import annotations

import math
import typing

import numpy as np
import numpy.typing as npt

from fenicsfriction.laws import check, check_positive

__all__ = ["check_poisson_ratio", "effective_modulus", "hertz_pressure", "lame"]

Value = typing.Any  # a number or a UFL expression


def lame(E: Value, nu: Value, plane_stress: bool = False) -> tuple[Value, Value]:
    """Lamé's parameters :math:`(\\lambda, \\mu)`, :math:`\\mu = E/(2(1+\\nu))`,
    :math:`\\lambda = E\\nu/((1+\\nu)(1-2\\nu))`; with ``plane_stress`` the 2D plane-stress
    :math:`\\lambda^* = 2\\mu\\lambda/(\\lambda + 2\\mu)` (numbers or UFL values)."""
    mu = E / (2 * (1 + nu))
    lmbda = E * nu / ((1 + nu) * (1 - 2 * nu))
    if plane_stress:
        lmbda = 2 * mu * lmbda / (lmbda + 2 * mu)
    return lmbda, mu


def check_poisson_ratio(name: str, nu: float) -> None:
    """:func:`~fenicsfriction.laws.check` that ``nu`` is a Poisson ratio, in (-1, 0.5]."""
    check(name, nu, isinstance(nu, (int, float)) and math.isfinite(nu) and -1.0 < nu <= 0.5,
          "Poisson's ratio must be in (-1, 0.5]")


def effective_modulus(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """:math:`E^*`, :math:`1/E^* = (1-\\nu_1^2)/E_1 + (1-\\nu_2^2)/E_2` [force/length²] (Johnson
    1985, section 4.2; plane strain in 2D)."""
    check_positive("E1", E1)
    check_positive("E2", E2)
    check_poisson_ratio("nu1", nu1)
    check_poisson_ratio("nu2", nu2)
    return 1.0 / ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2)


def hertz_pressure(r: npt.ArrayLike, a: float, p0: float) -> np.ndarray:
    """Hertz's pressure :math:`p(r) = p_0\\sqrt{1 - r^2/a^2}` at the distance r from the centre
    of a contact of half-width (radius) a, 0 outside it."""
    return p0 * np.sqrt(np.clip(1 - (np.asarray(r) / a) ** 2, 0.0, None))
