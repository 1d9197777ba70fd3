r"""The 2m+1 d.o.f. slider on a rough moving surface: its parameters and its linear system.

A slider :math:`y_s` (mass :math:`m_s`, spring :math:`k_s`, dashpot :math:`c_s` to ground) carries
m contact subsystems, each with a tangential co-ordinate :math:`y_i` (spring :math:`k_{t,i}`,
dashpot :math:`c_{t,i}` to the slider) and a normal co-ordinate :math:`x_i` driven by the rough
surface :math:`x_{in,i} = h_i \sin(2\pi X_i/\lambda_i)` through :math:`k_{n,i}, c_{n,i}`
("Friction-induced sliding instability in a multi-degree-of-freedom system with oscillatory
normal forces" (2003), eqs. 1-12):

.. math::
    m_i \ddot x_i + c_{n,i}(\dot x_i - \dot x_{in,i}) + k_{n,i}(x_i - x_{in,i}) = 0,\qquad
    N_i = N_{o,i} + f_N m_i \ddot x_i,

    m_i \ddot y_i + c_{t,i}(\dot y_i - \dot y_s) + k_{t,i}(y_i - y_s) = F_{f,i},\qquad
    m_s \ddot y_s + c_s \dot y_s + k_s y_s = \sum_i c_{t,i}(\dot y_i - \dot y_s)
    + k_{t,i}(y_i - y_s),

with friction :math:`F_{f,i} = \mu_i(V_{rel,i}) N_i \operatorname{sgn} V_{rel,i}`,
:math:`V_{rel,i} = V_{ref,i} - \dot y_i` (the surface drags the contact along +y).
:math:`f_N` (``normal_force_factor``) is 1 in the dimensional model; it exists because the
paper's dimensionless eq. 55 can be read with a different factor (see
:func:`~fenicsfriction.studies.oscillators.slider.table2.table2_slider`).

**Linear analysis** (the m.d.o.f. slider paper (2003), §3-4). With :math:`X_i \approx V_{ref,i}
t` the normal motion decouples: its steady response is :math:`x_i = \operatorname{Im}(\hat X_i
e^{i\omega_i t})`, :math:`\hat X_i = h_i (k_{n,i} + i c_{n,i}\omega_i)/(k_{n,i} - m_i\omega_i^2 +
i c_{n,i}\omega_i)` (eqs. 17-19), :math:`\omega_i = 2\pi V_{ref,i}/\lambda_i`. Linearising μ
about :math:`V_{ref,i}` (:math:`S_i = \mu_i'(V_{ref,i})`, eq. 24), a perturbation q of the
tangential co-ordinates :math:`(y_s, y_1..y_m)` obeys the linear periodic system

.. math::  \hat M \ddot q + \big(\hat C + \operatorname{diag}(0, S_i N_i(t))\big)\dot q
           + \hat K q = 0,

whose damping is modulated by the normal force (the parametric term γ of eq. 26). Its two
stability analyses (:meth:`Slider.averaged`, :meth:`Slider.floquet`) are in
:mod:`~fenicsfriction.studies.oscillators.slider.stability`.
"""

from __future__ import annotations

import dataclasses
import math
import typing

import numpy as np
import scipy.linalg

from fenicsfriction import laws
from fenicsfriction.laws import check, check_positive

if typing.TYPE_CHECKING:
    from fenicsfriction.studies.oscillators.slider import stability

__all__ = ["Contact", "FrictionLaw", "ScaledFriction", "Slider"]


class FrictionLaw(typing.Protocol):
    """A friction coefficient μ(speed, pressure) with its derivative in the speed (the laws of
    :mod:`fenicsfriction.laws` and :class:`ScaledFriction`)."""

    def __call__(self, speed: typing.Any, pressure: typing.Any = None) -> typing.Any:
        """μ at ``speed`` (a float or an array)."""

    def derivative(self, speed: typing.Any) -> typing.Any:
        """dμ/dv at ``speed``."""


@dataclasses.dataclass(frozen=True)
class ScaledFriction:
    """A friction law read in another velocity unit: :math:`\\mu(v) = \\mu_0(v/U)`.

    The m.d.o.f. slider paper (2003) gives eq. 59 without the unit of its velocity; ``unit``
    U says how many units of the model's velocity make one unit of the law's.

    Attributes:
        law: μ_0, in its own velocity unit.
        unit: U > 0.
    """

    law: FrictionLaw
    unit: float

    def __post_init__(self) -> None:
        check("unit", self.unit, self.unit > 0 and math.isfinite(self.unit),
              "the velocity unit must be a positive number")

    def __call__(self, speed: typing.Any, pressure: typing.Any = None) -> typing.Any:
        """μ(v) = μ_0(v/U) (at any ``pressure``, passed on to μ_0)."""
        return self.law(np.asarray(speed, dtype=float) / self.unit, pressure)

    def derivative(self, speed: typing.Any) -> typing.Any:
        """dμ/dv = μ_0'(v/U) / U."""
        return self.law.derivative(np.asarray(speed, dtype=float) / self.unit) / self.unit


@dataclasses.dataclass(frozen=True)
class Contact:
    """One 2-d.o.f. contact subsystem (the m.d.o.f. slider paper (2003), Fig. 1); any
    consistent units.

    Attributes:
        mass: m_i, of both its tangential and normal motion.
        k_t, c_t: tangential spring and dashpot to the slider.
        k_n, c_n: normal spring and dashpot to the rough surface.
        normal_load: static normal force N_o,i > 0.
        roughness: asperity height h_i >= 0 (0: smooth surface, constant N).
        wavelength: λ_i > 0 of the sinusoidal surface.
        surface_speed: V_ref,i > 0, the speed of the surface under this contact.
        law: the interface law (:class:`~fenicsfriction.laws.InterfaceLaw`), of which this
            point contact uses the friction part: the coefficient μ(speed, N) (N, the contact's
            normal force, is its pressure) and the regularisation of
            :class:`~fenicsfriction.studies.oscillators.slider.motion.SliderMotion`'s ``eps``;
            its normal compliance is not used (the normal force comes from the contact's
            spring and dashpot). Default: eq. 59's
            :class:`~fenicsfriction.laws.PiecewiseLinearFriction`, the smooth regularisation.
        mu_static: static coefficient bounding stick; None: μ(0).
        normal_force_factor: f_N in N = N_o + f_N m ẍ (1: the dimensional model).
    """

    mass: float
    k_t: float
    c_t: float
    k_n: float
    c_n: float
    normal_load: float
    roughness: float
    wavelength: float
    surface_speed: float
    law: laws.InterfaceLaw = dataclasses.field(default_factory=lambda: laws.InterfaceLaw(
        friction_coefficient=laws.PiecewiseLinearFriction(), regularisation="smooth"))
    mu_static: float | None = None
    normal_force_factor: float = 1.0

    def __post_init__(self) -> None:
        for name in ("mass", "k_n", "normal_load", "wavelength", "surface_speed"):
            check_positive(name, getattr(self, name))
        for name in ("k_t", "c_t", "c_n", "roughness", "normal_force_factor"):
            check_positive(name, getattr(self, name), strict=False)
        if self.mu_static is not None:
            check_positive("mu_static", self.mu_static, strict=False)
        check("law", self.law, isinstance(self.law, laws.InterfaceLaw),
              "must be a fenicsfriction.laws.InterfaceLaw (it validates its own parameters)")

    @property
    def omega(self) -> float:
        """Forcing frequency ω_i = 2π V_ref,i / λ_i (eq. 16)."""
        return 2 * math.pi * self.surface_speed / self.wavelength

    @property
    def static_coefficient(self) -> float:
        """μ_s bounding stick: ``mu_static``, or μ(0) without one."""
        return self.mu(0.0) if self.mu_static is None else self.mu_static

    def mu(self, speed: typing.Any) -> float:
        """The law's coefficient μ(|V|, N_o) at the relative velocity V."""
        return float(self.law.coefficient(abs(speed), self.normal_load))

    def normal_amplitude(self) -> complex:
        """Complex amplitude X̂ of the steady normal response x = Im(X̂ e^{iωt}) (eqs. 17-19)."""
        w = self.omega
        return self.roughness * (self.k_n + 1j * self.c_n * w) \
            / (self.k_n - self.mass * w * w + 1j * self.c_n * w)

    def normal_fluctuation(self) -> complex:
        """Complex amplitude N̂ = −f_N m ω² X̂ of N − N_o = f_N m ẍ = Im(N̂ e^{iωt})."""
        return -self.normal_force_factor * self.mass * self.omega**2 * self.normal_amplitude()

    def normal_force(self, t: typing.Any) -> typing.Any:
        """N(t) = N_o + f_N m ẍ on the steady normal response (eq. 21); t a float or array."""
        return self.normal_load + np.imag(
            self.normal_fluctuation() * np.exp(1j * self.omega * np.asarray(t)))

    def fluctuation_amplitude(self) -> float:
        """|N − N_o| at its maximum: f_N m ω² |X̂| (M_i ω_i² of eq. 26)."""
        return abs(self.normal_fluctuation())

    def mu_star(self) -> float:
        """μ*_i = μ(V_ref,i), the coefficient of steady sliding (eq. 23)."""
        return self.mu(self.surface_speed)

    def slope(self) -> float:
        """S_i = dμ/dv at v = V_ref,i (eq. 24)."""
        return float(self.law.coefficient_slope(self.surface_speed, self.normal_load))


class Slider:
    """The slider with its m contact subsystems (the m.d.o.f. slider paper (2003), §2).

    Args:
        mass: m_s > 0 of the slider.
        stiffness: k_s >= 0 of its spring to ground.
        damping: c_s >= 0 of its dashpot to ground.
        contacts: one or more :class:`Contact`.

    Attributes:
        slopes: S_i = μ_i'(V_ref,i) of each contact (eq. 24).
    """

    def __init__(self, mass: float, stiffness: float, damping: float,
                 contacts: typing.Sequence[Contact]):
        check_positive("mass", mass)
        check_positive("stiffness", stiffness, strict=False)
        check_positive("damping", damping, strict=False)
        contacts = tuple(contacts)
        check("contacts", contacts, len(contacts) > 0 and all(
            isinstance(c, Contact) for c in contacts), "must be one or more Contact")
        self.mass, self.stiffness, self.damping = float(mass), float(stiffness), float(damping)
        self.contacts = contacts
        self._tangential_system = self._assemble_tangential()
        self.slopes = np.array([c.slope() for c in contacts])  # S_i (eq. 24)

    @property
    def m(self) -> int:
        """The number of contacts."""
        return len(self.contacts)

    def tangential_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """M̂, Ĉ, K̂ of the tangential co-ordinates (y_s, y_1..y_m) (eqs. 9-10), fresh copies."""
        M, C, K = self._tangential_system
        return M.copy(), C.copy(), K.copy()

    def _assemble_tangential(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        n = self.m + 1
        M, C, K = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
        M[0, 0], C[0, 0], K[0, 0] = self.mass, self.damping, self.stiffness
        for i, c in enumerate(self.contacts, start=1):
            M[i, i] = c.mass
            for A, value in ((C, c.c_t), (K, c.k_t)):
                A[[0, i], [0, i]] += value
                A[0, i] -= value
                A[i, 0] -= value
        return M, C, K

    def matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """M, C, K of all 2m+1 co-ordinates (y_s, y_1..y_m, x_1..x_m) (eqs. 7-10)."""
        Mt, Ct, Kt = self.tangential_matrices()
        Mn, Cn, Kn = (np.diag([getattr(c, a) for c in self.contacts])
                      for a in ("mass", "c_n", "k_n"))
        return (scipy.linalg.block_diag(Mt, Mn), scipy.linalg.block_diag(Ct, Cn),
                scipy.linalg.block_diag(Kt, Kn))

    def natural_frequencies(self) -> tuple[np.ndarray, np.ndarray]:
        """Ω (ascending) and the mass-normalised modes R̂ of the undamped tangential system.

        Raises:
            ValueError: k_s = 0 (a free slider has a zero natural frequency).
        """
        M, _, K = self.tangential_matrices()
        w2, R = scipy.linalg.eigh(K, M)
        check("stiffness", self.stiffness, w2[0] > 0,
              "must be > 0: a free slider has a zero natural frequency")
        return np.sqrt(w2), R

    def steady_sliding(self) -> np.ndarray:
        """Mean tangential position: K̂ q = (0, μ(V_ref,i) N_o,i) (eq. 13)."""
        _, _, K = self.tangential_matrices()
        rhs = np.r_[0.0, [c.mu_star() * c.normal_load for c in self.contacts]]
        return np.linalg.solve(K, rhs)

    def forced_response(self) -> np.ndarray:
        """The tangential co-ordinates' forced oscillation about steady sliding.

        Complex amplitudes Ŷ with q − q̄ = Im(Ŷ e^{iωt}), driven by β_i = μ*_i × the
        normal-force fluctuation (eqs. 25-26) with the mean damping Ĉ + diag(S_i N_o,i); the
        parametric term γ_i is a higher-order correction. |ω Ŷ_i| against V_ref,i says
        whether the linear analysis' assumption of continuous sliding (V_rel > 0) holds on the
        forced motion itself.
        """
        omega = self.forcing_frequency("the forced response")
        M, _, K = self.tangential_matrices()
        C = self.friction_damping([c.normal_load for c in self.contacts])
        force = np.r_[0.0, [c.mu_star() * c.normal_fluctuation() for c in self.contacts]]
        return np.linalg.solve(K - omega**2 * M + 1j * omega * C, force)

    def forcing_frequency(self, what: str) -> float:
        """The forcing frequency all contacts share.

        Args:
            what: the analysis that needs one frequency (named in the error).

        Raises:
            ValueError: the contacts are forced at different frequencies.
        """
        omegas = [c.omega for c in self.contacts]
        check("contacts", omegas, bool(np.allclose(omegas, omegas[0], rtol=1e-12)),
              f"{what} needs one forcing frequency for all contacts")
        return omegas[0]

    def periodic_damping(self, t: float) -> np.ndarray:
        """Ĉ + diag(0, S_i N_i(t)): the damping of the linear periodic system at time t."""
        return self.friction_damping([c.normal_force(t) for c in self.contacts])

    def friction_damping(self, normal_forces: typing.Sequence[float]) -> np.ndarray:
        """Ĉ + diag(0, S_i N_i): linearised friction adds S_i N_i to each contact's damping."""
        C = self._tangential_system[1].copy()
        C[1:, 1:] += np.diag(self.slopes * np.asarray(normal_forces, dtype=float))
        return C

    def averaged(self) -> stability.AveragedStability:
        """First-order averaging
        (:func:`~fenicsfriction.studies.oscillators.slider.stability.averaged`)."""
        from fenicsfriction.studies.oscillators.slider import (
            stability,  # MPI/PETSc: only when asked
        )

        return stability.averaged(self)

    def floquet(self, rtol: float = 1e-10, atol: float = 1e-12,
                prefix: str = "floquet_") -> stability.FloquetStability:
        """Floquet multipliers over one forcing period
        (:func:`~fenicsfriction.studies.oscillators.slider.stability.floquet`)."""
        from fenicsfriction.studies.oscillators.slider import stability

        return stability.floquet(self, rtol=rtol, atol=atol, prefix=prefix)
