r"""A mass under gravity on a compliant foundation: the smallest model with the interface's normal
law, one d.o.f., whose periods are known in closed form (linear foundation, also with flight)
or by an energy quadrature (power law); the verification scene of
:class:`~fenicsfriction.timestepping.ReducedDynamics`."""

from __future__ import annotations

import dataclasses
import typing

import numpy as np

from fenicsfriction import laws
from fenicsfriction.laws import check

__all__ = ["BouncingMass"]

ArrayLike: typing.TypeAlias = typing.Any  # an array of floats, or a float for one d.o.f.


@dataclasses.dataclass
class BouncingMass:
    r"""A mass under gravity on a compliant foundation, one d.o.f.: the vertical displacement
    y (upward; y = 0: the foundation's unloaded surface).

    The foundation presses with the normal law of :mod:`fenicsfriction.laws` over an area A:

    .. math::
        m\ddot y + W - A\left(c_n d^{m_n} + b_n d^{l_n}(-\dot y)\right) = 0,
        \qquad d = (-y)_+,

    so that the mass flies ballistically (ÿ = -W/m) once d = 0.

    Args:
        mass: m [10^3 kg], > 0.
        weight: W = m g [10^3 kg cm s^-2], > 0.
        area: contact area A [cm^2], > 0.
        law: the interface law (:class:`~fenicsfriction.laws.InterfaceLaw`): its normal
            compliance c_n d^{m_n} [10^3 kg cm^(-1-m_n) s^-2] and damping b_n d^{l_n} (-ẏ).

    Defaults: the block of Martins & Oden 1986 (M = 0.45, W = 450, c_n = 1e10, m_n = 2.5, A = L B0).
    """

    mass: float = 0.45
    weight: float = 450.0
    area: float = 48.8 * 30.5
    law: laws.InterfaceLaw = dataclasses.field(default_factory=laws.InterfaceLaw)

    def __post_init__(self):
        check("law", self.law, isinstance(self.law, laws.InterfaceLaw),
              "must be a fenicsfriction.laws.InterfaceLaw")
        for name in ("mass", "weight", "area"):
            value = getattr(self, name)
            check(name, value, isinstance(value, (int, float)) and np.isfinite(value)
                  and value > 0, "must be a finite number > 0")

    @property
    def gravity(self) -> float:
        """g = W / m [cm s^-2]."""
        return self.weight / self.mass

    def equilibrium(self) -> float:
        """Rest position y0 = -d0 with d0 = (W / (c_n A))^(1/m_n)."""
        return -(self.weight / (self.law.c_n * self.area)) ** (1.0 / self.law.m_n)

    def foundation_force(self, q: ArrayLike, q_dot: ArrayLike) -> np.ndarray:
        """Upward force of the foundation A (c_n d^{m_n} + b_n d^{l_n} (-ẏ))."""
        y, y_dot = np.asarray(q, float), np.asarray(q_dot, float)
        d = laws.penetration(-y)
        return self.area * self.law.normal_traction(d, -y_dot)

    def residual(self, q: ArrayLike, q_dot: ArrayLike, q_ddot: ArrayLike) -> np.ndarray:
        """R = m ÿ + W - foundation force."""
        return self.mass * np.asarray(q_ddot, float) + self.weight \
            - self.foundation_force(q, q_dot)

    def linearisation(self, q: ArrayLike, q_dot: ArrayLike | None = None
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(M, C, K) = (∂R/∂ÿ, ∂R/∂ẏ, ∂R/∂y) as 1 × 1 arrays; out of contact (y >= 0)
        C = K = 0 (d^0 would read 1 at d = 0 for a linear law)."""
        y = float(np.asarray(q, float).ravel()[0])
        y_dot = 0.0 if q_dot is None else float(np.asarray(q_dot, float).ravel()[0])
        if y >= 0:
            return np.array([[self.mass]]), np.zeros((1, 1)), np.zeros((1, 1))
        d = -y
        stiffness, damping = self.law.normal_traction_derivatives(d, -y_dot)
        return (np.array([[self.mass]]), np.array([[self.area * damping]]),
                np.array([[self.area * stiffness]]))

    def energy(self, q: ArrayLike, q_dot: ArrayLike) -> np.ndarray:
        """Kinetic + foundation c_n A d^{m_n+1}/(m_n+1) + gravity W y (conserved if b_n = 0)."""
        y, y_dot = np.asarray(q, float), np.asarray(q_dot, float)
        d = laws.penetration(-y)
        return 0.5 * self.mass * y_dot**2 \
            + self.law.c_n * self.area * d ** (self.law.m_n + 1) / (self.law.m_n + 1) \
            + self.weight * y
