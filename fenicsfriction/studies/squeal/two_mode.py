r"""The pin on the disc reduced to its two coupling modes: a Hoffmann-type model built from the
finite element model's own modes.

The real modes of the symmetric, frictionless problem, :math:`\bar K(0)\,\phi = \omega^2 M\phi`
(:class:`fenicsfriction.cea.projection.ModalBasis`, :math:`\phi^T M \phi = 1`), are a basis
in which the pencil of steady sliding at μ is

.. math:: \big(\lambda^2 I + \lambda\,\Phi^T C(\mu)\Phi + \Phi^T\bar K(\mu)\Phi\big)\,q = 0,
          \qquad \Phi^T\bar K(\mu)\Phi \approx \mathrm{diag}(\omega_1^2, \omega_2^2)
          + \mu B .

Kept to the two modes that carry the flutter mode of the full model (the largest
:math:`|\phi_i^T M w|`), it is the two-degree-of-freedom model of Hoffmann, Fischer, Allgaier
& Gaul (2002), whose undamped frequencies merge where the discriminant of
:math:`\det(K - \omega^2 I) = 0` vanishes:

.. math:: \big(k_{11}(\mu) - k_{22}(\mu)\big)^2 + 4 k_{12}(\mu) k_{21}(\mu) = 0,
          \qquad k_{ij}(\mu) = \omega_i^2\delta_{ij} + \mu B_{ij},

a quadratic in μ whose smallest positive root is the two-mode onset :math:`\mu_c`
(:func:`coalescence`), at :math:`\omega_c^2 = (k_{11} + k_{22})/2`. B is the difference
quotient of the projected :math:`\bar K` between μ = 0 and a μ₁ (it is linear in μ up to the
steady state's change with μ, measured by :meth:`TwoModeModel.linearity`).

What it leaves out, and so how it differs from the full model's onset: the other modes (those
between and around the pair, whose veering with them the projection drops), the damping of the
regularised friction (:math:`C(\mu)`, a viscous term :math:`\mu p/|w|` across the slip), and
the change of the steady state with μ.
"""

from __future__ import annotations

import dataclasses
import math
import typing

import numpy as np

from fenicsfriction.laws import check
from fenicsfriction.numerics import bisect, dense_eigenvalues

__all__ = ["TwoModeModel", "coalescence", "modal_onset"]

def coalescence(K0: np.ndarray, B: np.ndarray) -> tuple[float, float]:
    """``(mu_c, omega_c)``: where the two undamped frequencies of
    :math:`\\det(K_0 + \\mu B - \\omega^2 I) = 0` merge (the smallest μ > 0 that zeroes the
    discriminant :math:`(k_{11} - k_{22})^2 + 4 k_{12}k_{21}`; ``nan`` if none)."""
    d0, d1 = K0[0, 0] - K0[1, 1], B[0, 0] - B[1, 1]
    # (d0 + μ d1)² + 4 (K0_12 + μ B_12)(K0_21 + μ B_21), coefficients of μ², μ, 1
    a = d1**2 + 4 * B[0, 1] * B[1, 0]
    b = 2 * d0 * d1 + 4 * (K0[0, 1] * B[1, 0] + B[0, 1] * K0[1, 0])
    c = d0**2 + 4 * K0[0, 1] * K0[1, 0]
    roots = np.roots([a, b, c])
    real = sorted(r.real for r in roots if abs(r.imag) <= 1e-12 * abs(r) and r.real > 0)
    if not real:
        return math.nan, math.nan
    mu = real[0]
    K = K0 + mu * B
    return float(mu), math.sqrt((K[0, 0] + K[1, 1]) / 2)


def modal_onset(K0: np.ndarray, B: np.ndarray, C1: np.ndarray, upper: float,
                tol: float = 1e-6, points: int = 200) -> float:
    r"""The first μ in (0, ``upper``] where the projected pencil
    :math:`\lambda^2 I + \lambda\mu C_1 + K_0 + \mu B` has an eigenvalue with Re λ > 0
    (any number of modes; the friction's damping μ C₁ is linear in μ): a scan of ``points``
    values, then bisection to ``tol``. ``nan`` if none."""
    def grows(mu: float) -> bool:
        values = dense_eigenvalues(K0 + mu * B, mu * C1, np.eye(len(K0)))
        return bool(values.real.max() > 1e-9 * np.abs(values).max())

    grid = np.linspace(0.0, upper, points + 1)[1:]
    first = next((k for k, mu in enumerate(grid) if grows(mu)), None)
    if first is None:
        return math.nan
    low, high = bisect(grows, 0.0 if first == 0 else grid[first - 1], grid[first], tol)
    return 0.5 * (low + high)


@dataclasses.dataclass
class TwoModeModel:
    """The pencil projected on two real modes: ``M`` (I), ``C`` and ``K`` at μ₁, and
    ``K0`` + μ ``B`` with ``B = (K - K0)/μ₁``.

    Attributes:
        frequencies: the two modes' frequencies at μ = 0 [Hz].
        indices: their places among the real modes computed (0: the lowest).
        mu1: the μ at which ``K`` and ``C`` were projected.
        K0, K, C, B: 2 × 2 arrays.
    """

    frequencies: list[float]
    indices: list[int]
    mu1: float
    K0: np.ndarray
    K: np.ndarray
    C: np.ndarray
    B: np.ndarray

    @classmethod
    def build(cls, K0: np.ndarray, K1: np.ndarray, C1: np.ndarray, mu1: float,
              indices: list[int]) -> TwoModeModel:
        check("mu1", mu1, mu1 > 0, "must be > 0")
        omega2 = np.diag(K0)
        return cls(frequencies=[float(math.sqrt(w) / (2 * math.pi)) for w in omega2],
                   indices=indices, mu1=mu1, K0=K0, K=K1, C=C1, B=(K1 - K0) / mu1)

    def onset(self) -> tuple[float, float]:
        """The undamped two-mode onset ``(mu_c, omega_c)`` (:func:`coalescence`)."""
        return coalescence(self.K0, self.B)

    def damped_onset(self, upper: float, tol: float = 1e-6) -> float:
        """The onset of the damped 2 × 2 pencil (the friction's viscous term included): see
        :func:`modal_onset`."""
        return modal_onset(self.K0, self.B, self.C / self.mu1, upper, tol)

    def eigenvalues(self, mu: float, damped: bool = True) -> np.ndarray:
        """The two eigenvalues with Im λ >= 0 of the 2 × 2 pencil at μ (K0 + μB, and the
        damping μ/μ₁ C when ``damped``: the friction's viscous term is linear in μ)."""
        C = (mu / self.mu1) * self.C if damped else np.zeros((2, 2))
        values = dense_eigenvalues(self.K0 + mu * self.B, C, np.eye(2))
        return np.sort_complex(values[values.imag >= 0])

    def to_json(self) -> dict[str, typing.Any]:
        mu_c, omega_c = self.onset()
        return {"frequencies_hz": self.frequencies, "indices": self.indices, "mu1": self.mu1,
                "K0": self.K0.tolist(), "B": self.B.tolist(), "C": self.C.tolist(),
                "mu_c": mu_c, "f_c_hz": omega_c / (2 * math.pi),
                "mu_c_damped": self.damped_onset(1.5 * mu_c) if math.isfinite(mu_c) else math.nan}
