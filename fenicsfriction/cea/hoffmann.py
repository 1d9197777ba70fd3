"""The two-degree-of-freedom model of mode-coupling instability of Hoffmann, Fischer, Allgaier &
Gaul (2002), "A minimal model for studying properties of the mode-coupling type instability in
friction induced oscillations", and its flutter onsets in closed form (NumPy only).

A point mass m, displacements :math:`x_1` (along the belt) and :math:`x_2` (normal to it), is
held by two springs :math:`k_1, k_2` whose axes make the angles :math:`\\alpha_1, \\alpha_2`
with the belt, and pressed on the belt through a contact spring :math:`k_3`. A spring k along
the unit vector :math:`e = (\\cos\\alpha, \\sin\\alpha)` adds :math:`k e e^T` to the stiffness,
so

.. math:: k_{11} = \\sum_i k_i\\cos^2\\alpha_i,\\quad
          k_{12} = k_{21} = \\sum_i k_i\\sin\\alpha_i\\cos\\alpha_i,\\quad
          k_{22} = \\sum_i k_i\\sin^2\\alpha_i.

The variation of the normal force, :math:`k_3 x_2`, changes the friction force by
:math:`\\mu k_3 x_2` along the belt's motion (the constant preload is the steady state's). With
damping C:

.. math:: m\\ddot x + C\\dot x + \\begin{bmatrix} k_{11} & k_{12} - \\mu k_3 \\\\
          k_{21} & k_{22} + k_3\\end{bmatrix} x = 0,

:math:`K(\\mu) = K_0 + \\mu K_1`, :math:`K_1 = -k_3 e_1 e_2^T`: friction makes K unsymmetric.

**Without damping** the eigenfrequencies solve :math:`\\det(K - \\omega^2 m I) = 0`,

.. math:: m^2\\omega^4 - m\\omega^2 (k_{11} + k_{22}') + \\det K(\\mu) = 0,\\qquad
          k_{22}' = k_{22} + k_3;

the two frequencies merge where the discriminant vanishes,
:math:`(k_{11} - k_{22}')^2 + 4 k_{21}(k_{12} - \\mu k_3) = 0`:

.. math:: \\mu_c = \\frac{(k_{11} - k_{22}')^2 + 4 k_{12}k_{21}}{4 k_{21} k_3},\\qquad
          \\omega_c^2 = \\frac{k_{11} + k_{22}'}{2m},

and past :math:`\\mu_c` the pair is :math:`\\lambda = \\pm a + i\\omega` (flutter).

**With damping** the characteristic polynomial
:math:`\\det(\\lambda^2 M + \\lambda C + K(\\mu)) = a_4\\lambda^4 + a_3\\lambda^3 + a_2\\lambda^2
+ a_1\\lambda + a_0` has coefficients polynomial in μ (of degree one for a diagonal C, two for
a full one); by Routh–Hurwitz it is stable where :math:`a_i > 0`,
:math:`\\Delta_2 = a_3 a_2 - a_4 a_1 > 0` and :math:`\\Delta_3 = a_1\\Delta_2 - a_3^2 a_0 > 0`. The
onset is the first real root in μ > 0 of these polynomials past which stability is lost; on
:math:`\\Delta_3 = 0` the roots :math:`\\pm i\\omega_c` have :math:`\\omega_c^2 = a_1/a_3`.
Damping does not tend to the undamped onset as it vanishes unless it is distributed like the
modes' (Hoffmann & Gaul 2003 call this the destabilisation paradox): unequal damping of the two
coordinates lowers :math:`\\mu_c`, equal damping raises it.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from numpy.polynomial import Polynomial

from fenicsfriction.laws import check, check_positive

__all__ = ["HoffmannModel"]


@dataclasses.dataclass(frozen=True)
class HoffmannModel:
    """The minimal model of Hoffmann et al. (2002), in any consistent units.

    The default values are ours, not the paper's: round numbers for which the undamped onset is
    :math:`\\mu_c = 1`, :math:`\\omega_c = \\sqrt 2` (k11 = 3/2, k12 = 1/2, k22' = 5/2).

    Attributes:
        m: the mass.
        k1, k2: the two oblique springs' stiffnesses.
        k3: the contact spring's stiffness.
        alpha1, alpha2: the springs' angles to the belt [rad].
        c1, c2: viscous dampers along x1 and x2 (C = diag(c1, c2)).
    """

    m: float = 1.0
    k1: float = 2.0
    k2: float = 1.0
    k3: float = 1.0
    alpha1: float = math.pi / 4
    alpha2: float = 3 * math.pi / 4
    c1: float = 0.0
    c2: float = 0.0

    def __post_init__(self) -> None:
        for name in ("m", "k1", "k2", "k3"):
            check_positive(name, getattr(self, name))
        for name in ("c1", "c2"):
            check_positive(name, getattr(self, name), strict=False)
        check("k12", self.k12, self.k12 * self.k3 > 0,
              "the angles must couple x1 and x2 so that friction destabilises (k12 > 0)")

    @property
    def k11(self) -> float:
        """:math:`\\sum k_i \\cos^2\\alpha_i`."""
        return self.k1 * math.cos(self.alpha1) ** 2 + self.k2 * math.cos(self.alpha2) ** 2

    @property
    def k12(self) -> float:
        """:math:`\\sum k_i \\sin\\alpha_i\\cos\\alpha_i` (= k21)."""
        return (self.k1 * math.sin(self.alpha1) * math.cos(self.alpha1)
                + self.k2 * math.sin(self.alpha2) * math.cos(self.alpha2))

    @property
    def k22(self) -> float:
        """:math:`\\sum k_i \\sin^2\\alpha_i + k_3` (the contact spring included)."""
        return (self.k1 * math.sin(self.alpha1) ** 2 + self.k2 * math.sin(self.alpha2) ** 2
                + self.k3)

    def matrices(self) -> dict[str, np.ndarray]:
        """The pencil's parts ``M``, ``C0``, ``K0``, ``K1`` (K(μ) = K0 + μ K1)."""
        return {"M": self.m * np.eye(2), "C0": np.diag([self.c1, self.c2]),
                "K0": np.array([[self.k11, self.k12], [self.k12, self.k22]]),
                "K1": np.array([[0.0, -self.k3], [0.0, 0.0]])}

    def undamped_onset(self) -> tuple[float, float]:
        """``(mu_c, omega_c)``: where the two frequencies of the undamped model merge."""
        mu = ((self.k11 - self.k22) ** 2 + 4 * self.k12**2) / (4 * self.k12 * self.k3)
        return mu, math.sqrt((self.k11 + self.k22) / (2 * self.m))

    def characteristic(self) -> list[Polynomial]:
        """:math:`[a_0, ..., a_4]`, the coefficients of det(λ²M + λC + K(μ)) in λ, each a
        polynomial in μ."""
        parts = self.matrices()
        M, C, K0, K1 = (parts[k] for k in ("M", "C0", "K0", "K1"))

        def entry(i: int, j: int) -> list[Polynomial]:  # coefficients of λ^0, λ^1, λ^2
            return [Polynomial([K0[i, j], K1[i, j]]), Polynomial([C[i, j]]),
                    Polynomial([M[i, j]])]

        def product(a: list[Polynomial], b: list[Polynomial]) -> list[Polynomial]:
            out = [Polynomial([0.0])] * (len(a) + len(b) - 1)
            for i, x in enumerate(a):
                for j, y in enumerate(b):
                    out[i + j] = out[i + j] + x * y
            return out

        first, second = product(entry(0, 0), entry(1, 1)), product(entry(0, 1), entry(1, 0))
        return [x - y for x, y in zip(first, second, strict=True)]

    def hurwitz(self) -> dict[str, Polynomial]:
        """The Routh–Hurwitz quantities, polynomials in μ, all > 0 where the model is stable:
        ``a0`` … ``a3``, ``delta2`` and ``delta3`` (``a4`` = m² > 0)."""
        a0, a1, a2, a3, a4 = self.characteristic()
        delta2 = a3 * a2 - a4 * a1
        return {"a0": a0, "a1": a1, "a2": a2, "a3": a3, "delta2": delta2,
                "delta3": a1 * delta2 - a3 * a3 * a0}

    def is_stable(self, mu: float) -> bool:
        """Every Routh–Hurwitz quantity > 0 at μ (the damped model)."""
        return all(q(mu) > 0 for q in self.hurwitz().values())

    def damped_onset(self) -> tuple[float, float]:
        """``(mu_c, omega_c)``: the smallest μ > 0 past which the damped model is unstable,
        the first real root of a Routh–Hurwitz quantity, and the frequency of the roots ±iω_c
        there (0 when a0 vanishes first: divergence)."""
        check("c1 + c2", self.c1 + self.c2, self.c1 + self.c2 > 0,
              "the damped onset needs damping (use undamped_onset)")
        check("mu = 0", 0.0, self.is_stable(0.0), "the model must be stable without friction")
        quantities = self.hurwitz()
        roots = sorted({float(r.real) for q in quantities.values() if q.degree() > 0
                        for r in map(complex, q.roots())
                        if abs(r.imag) <= 1e-12 * max(1.0, abs(r)) and r.real > 0})
        for root in roots:
            if not self.is_stable(root * (1 + 1e-9) + 1e-15):
                a = self.characteristic()
                if abs(quantities["a0"](root)) <= abs(quantities["delta3"](root)):
                    return root, 0.0
                return root, math.sqrt(a[1](root) / a[3](root))
        raise ValueError("the damped model is stable for every μ > 0")
