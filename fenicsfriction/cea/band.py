"""The frequency band of a complex eigenvalue analysis and the part of the λ-plane it stands for.

Brake-squeal engineers ask for every mode whose frequency :math:`f = \\operatorname{Im}\\lambda
/ 2\\pi` lies in a band :math:`[f_{min}, f_{max}]` Hz. Real matrices have their complex
eigenvalues in conjugate pairs, so only Im λ >= 0 is kept. A band is a strip of the λ-plane,
unbounded in Re λ; it is closed by ``max_rate``, the largest decay or growth rate |Re λ| [1/s]
reported (by default a quarter of the band's top angular frequency: a damping ratio of about
0.24 at :math:`f_{max}`, far more than any structure's).
"""

from __future__ import annotations

import dataclasses
import math

from fenicsfriction.laws import check

__all__ = ["Band"]


@dataclasses.dataclass(frozen=True)
class Band:
    """Frequencies [f_min, f_max] in Hz, growth rates |Re λ| <= max_rate in 1/s.

    Attributes:
        fmin: lowest frequency [Hz], >= 0.
        fmax: highest frequency [Hz], > fmin.
        max_rate: largest |Re λ| [1/s] reported (default: :math:`2\\pi f_{max}/4`).
    """

    fmin: float
    fmax: float
    max_rate: float | None = None

    def __post_init__(self) -> None:
        check("fmin", self.fmin, math.isfinite(self.fmin) and self.fmin >= 0,
              "must be a finite number >= 0")
        check("fmax", self.fmax, math.isfinite(self.fmax) and self.fmax > self.fmin,
              f"must be a finite number > fmin = {self.fmin:g}")
        if self.max_rate is not None:
            check("max_rate", self.max_rate, math.isfinite(self.max_rate) and self.max_rate > 0,
                  "must be a finite number > 0")

    @property
    def omega(self) -> tuple[float, float]:
        """The angular frequencies (2π f_min, 2π f_max) [rad/s]."""
        return 2 * math.pi * self.fmin, 2 * math.pi * self.fmax

    @property
    def rate(self) -> float:
        """The largest |Re λ| reported [1/s]."""
        return self.omega[1] / 4 if self.max_rate is None else self.max_rate

    def contains(self, value: complex) -> bool:
        """Whether λ = ``value`` is reported: Im λ in [2π f_min, 2π f_max], |Re λ| <= rate."""
        low, high = self.omega
        return low <= value.imag <= high and abs(value.real) <= self.rate

    def covering_radius(self, shift: float) -> float:
        """Radius of the disc about the real ``shift`` that contains the band's rectangle and
        its mirror image: the farthest corner, :math:`\\sqrt{(r + |\\sigma|)^2 +
        \\omega_{max}^2}`."""
        return math.hypot(self.rate + abs(shift), self.omega[1])
