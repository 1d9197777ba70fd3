r"""The 2m+1 d.o.f. slider on a rough moving surface (seed 004): model, averaging and Floquet.

A slider :math:`y_s` (mass :math:`m_s`, spring :math:`k_s`, dashpot :math:`c_s` to ground) carries
m contact subsystems, each with a tangential co-ordinate :math:`y_i` (spring :math:`k_{t,i}`,
dashpot :math:`c_{t,i}` to the slider) and a normal co-ordinate :math:`x_i` driven by the rough
surface :math:`x_{in,i} = h_i \sin(2\pi X_i/\lambda_i)` through :math:`k_{n,i}, c_{n,i}`
(seed 004 eqs. 1-12):

.. math::
    m_i \ddot x_i + c_{n,i}(\dot x_i - \dot x_{in,i}) + k_{n,i}(x_i - x_{in,i}) = 0,\qquad
    N_i = N_{o,i} + f_N m_i \ddot x_i,

    m_i \ddot y_i + c_{t,i}(\dot y_i - \dot y_s) + k_{t,i}(y_i - y_s) = F_{f,i},\qquad
    m_s \ddot y_s + c_s \dot y_s + k_s y_s = \sum_i c_{t,i}(\dot y_i - \dot y_s)
    + k_{t,i}(y_i - y_s),

with friction :math:`F_{f,i} = \mu_i(V_{rel,i}) N_i \operatorname{sgn} V_{rel,i}`,
:math:`V_{rel,i} = V_{ref,i} - \dot y_i` (the surface drags the contact along +y).
:math:`f_N` (``normal_force_factor``) is 1 in the dimensional model; it exists because seed
004's dimensionless eq. 55 can be read with a different factor (see :func:`table2_slider`).

**Linear analysis** (seed 004 §3-4). With :math:`X_i \approx V_{ref,i} t` the normal motion
decouples: its steady response is :math:`x_i = \operatorname{Im}(\hat X_i e^{i\omega_i t})`,
:math:`\hat X_i = h_i (k_{n,i} + i c_{n,i}\omega_i)/(k_{n,i} - m_i\omega_i^2 + i c_{n,i}\omega_i)`
(eqs. 17-19), :math:`\omega_i = 2\pi V_{ref,i}/\lambda_i`. Linearising μ about
:math:`V_{ref,i}` (:math:`S_i = \mu_i'(V_{ref,i})`, eq. 24), a perturbation q of the tangential
co-ordinates :math:`(y_s, y_1..y_m)` obeys the linear periodic system

.. math::  \hat M \ddot q + \big(\hat C + \operatorname{diag}(0, S_i N_i(t))\big)\dot q
           + \hat K q = 0,

whose damping is modulated by the normal force (the parametric term γ of eq. 26). Two
independent stability tools act on it:

* :meth:`Slider.averaged` — the modal transformation (eqs. 27-29) and first-order averaging:
  Cases I, III and the non-resonant case are stable iff the modal damping :math:`\xi_{ii}>0`;
  Case II (:math:`\omega_k \approx \Omega_i \pm \Omega_j`, i = j the principal resonance) has
  the averaged eigenvalues :math:`(\lambda + \xi_{ii}/2 + i\sigma/2)(\lambda + \xi_{jj}/2 \mp
  i\sigma/2) = \Gamma_{ij}^2/16` (eq. 47 in a rotating frame), unstable iff
  :math:`|\Gamma_{ij}| > \Gamma_{crit}` of eq. 48;
* :meth:`Slider.floquet` — the monodromy matrix over one forcing period, by integrating the
  variational equations with PETSc TS, and its Floquet multipliers (exact up to the
  integration tolerance).
"""

from __future__ import annotations

import dataclasses
import math
import time
import typing

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import scipy.linalg

from fenicsfriction import laws
from fenicsfriction.laws import check, check_positive

__all__ = ["AveragedStability", "Contact", "FloquetStability", "ScaledFriction", "Slider",
           "StabilityMap", "stability_map", "stroboscopic_growth", "table2_slider",
           "TABLE2_PAPER_BANDS", "TABLE2_READINGS"]


@dataclasses.dataclass(frozen=True)
class ScaledFriction:
    """A friction law read in another velocity unit: :math:`\\mu(v) = \\mu_0(v/U)`.

    Seed 004 gives eq. 59 without the unit of its velocity; ``unit`` U says how many units of
    the model's velocity make one unit of the law's.
    """

    law: typing.Any
    unit: float

    def __post_init__(self):
        check("unit", self.unit, self.unit > 0 and math.isfinite(self.unit),
              "the velocity unit must be a positive number")

    def __call__(self, speed):
        return self.law(np.asarray(speed, dtype=float) / self.unit)

    def derivative(self, speed):
        return self.law.derivative(np.asarray(speed, dtype=float) / self.unit) / self.unit


@dataclasses.dataclass(frozen=True)
class Contact:
    """One 2-d.o.f. contact subsystem (seed 004 Fig. 1); any consistent units.

    Attributes:
        mass: m_i, of both its tangential and normal motion.
        k_t, c_t: tangential spring and dashpot to the slider.
        k_n, c_n: normal spring and dashpot to the rough surface.
        normal_load: static normal force N_o,i > 0.
        roughness: asperity height h_i >= 0 (0: smooth surface, constant N).
        wavelength: λ_i > 0 of the sinusoidal surface.
        surface_speed: V_ref,i > 0, the speed of the surface under this contact.
        friction: μ(v) with ``__call__`` and ``derivative`` (:mod:`fenicsfriction.laws`).
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
    friction: typing.Any = dataclasses.field(default_factory=laws.PiecewiseLinearFriction)
    mu_static: float | None = None
    normal_force_factor: float = 1.0

    def __post_init__(self):
        for name in ("mass", "k_n", "normal_load", "wavelength", "surface_speed"):
            check_positive(name, getattr(self, name))
        for name in ("k_t", "c_t", "c_n", "roughness", "normal_force_factor"):
            check_positive(name, getattr(self, name), strict=False)
        if self.mu_static is not None:
            check_positive("mu_static", self.mu_static, strict=False)

    @property
    def omega(self) -> float:
        """Forcing frequency ω_i = 2π V_ref,i / λ_i (eq. 16)."""
        return 2 * math.pi * self.surface_speed / self.wavelength

    @property
    def static_coefficient(self) -> float:
        return float(self.friction(0.0)) if self.mu_static is None else self.mu_static

    def normal_amplitude(self) -> complex:
        """Complex amplitude X̂ of the steady normal response x = Im(X̂ e^{iωt}) (eqs. 17-19)."""
        w = self.omega
        return self.roughness * (self.k_n + 1j * self.c_n * w) \
            / (self.k_n - self.mass * w * w + 1j * self.c_n * w)

    def normal_fluctuation(self) -> complex:
        """Complex amplitude N̂ = −f_N m ω² X̂ of N − N_o = f_N m ẍ = Im(N̂ e^{iωt})."""
        return -self.normal_force_factor * self.mass * self.omega**2 * self.normal_amplitude()

    def normal_force(self, t):
        """N(t) = N_o + f_N m ẍ on the steady normal response (eq. 21)."""
        return self.normal_load + np.imag(
            self.normal_fluctuation() * np.exp(1j * self.omega * np.asarray(t)))

    def fluctuation_amplitude(self) -> float:
        """|N − N_o| at its maximum: f_N m ω² |X̂| (M_i ω_i² of eq. 26)."""
        return abs(self.normal_fluctuation())

    def mu_star(self) -> float:
        """μ*_i = μ(V_ref,i), the coefficient of steady sliding (eq. 23)."""
        return float(self.friction(self.surface_speed))

    def slope(self) -> float:
        """S_i = dμ/dv at v = V_ref,i (eq. 24)."""
        return float(self.friction.derivative(self.surface_speed))


@dataclasses.dataclass(frozen=True)
class AveragedStability:
    """First-order averaging at one surface speed (seed 004 §4).

    Attributes:
        growth: the largest real part of the averaged eigenvalues (< 0: stable).
        case: the governing case (Table 1): ``"II: Ω2-Ω1 ≈ ω1"`` when a Case II resonance
            sets the growth; else ``"I: Ω1 ≈ ω1"``, ``"III: Ω2 ≈ ω1+ω1"`` or
            ``"non-resonant"``, whose growth is -min ξ_ii/2 (stable iff every ξ_ii > 0).
        modal_damping: ξ_ii (1/time) of each mode.
        gamma: the modal parametric amplitudes Γ_ij of the governing contact.
        gamma_crit: Γ_crit (eq. 48) of the governing Case II resonance (None for others).
    """

    growth: float
    case: str
    modal_damping: np.ndarray
    gamma: np.ndarray
    gamma_crit: float | None


@dataclasses.dataclass(frozen=True)
class FloquetStability:
    """Floquet multipliers ρ of the linear periodic system over one period T.

    ``growth`` = max ln|ρ| / T, the exact counterpart of :attr:`AveragedStability.growth`.
    """

    multipliers: np.ndarray
    period: float
    growth: float
    monodromy: np.ndarray
    steps: int


class Slider:
    """The slider with its m contact subsystems (seed 004 §2).

    Args:
        mass, stiffness, damping: m_s > 0, k_s >= 0, c_s >= 0 of the slider.
        contacts: one or more :class:`Contact`.
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
        return len(self.contacts)

    def tangential_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """M̂, Ĉ, K̂ of the tangential co-ordinates (y_s, y_1..y_m) (eqs. 9-10), fresh copies."""
        return tuple(A.copy() for A in self._tangential_system)

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
        normal = [np.diag([getattr(c, a) for c in self.contacts]) for a in ("mass", "c_n", "k_n")]
        return tuple(scipy.linalg.block_diag(tangential, nn)
                     for tangential, nn in zip((Mt, Ct, Kt), normal, strict=True))

    def natural_frequencies(self) -> tuple[np.ndarray, np.ndarray]:
        """Ω (ascending) and the mass-normalised modes R̂ of the undamped tangential system."""
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
        """Complex amplitudes Ŷ of the tangential co-ordinates' forced oscillation about steady
        sliding, q − q̄ = Im(Ŷ e^{iωt}), driven by β_i = μ*_i × the normal-force fluctuation
        (eqs. 25-26) with the mean damping Ĉ + diag(S_i N_o,i); the parametric term γ_i is a
        higher-order correction. |ω Ŷ_i| against V_ref,i says whether the linear analysis'
        assumption of continuous sliding (V_rel > 0) holds on the forced motion itself."""
        omega = self._common_omega("the forced response")
        M, _, K = self.tangential_matrices()
        C = self._friction_damping([c.normal_load for c in self.contacts])
        force = np.r_[0.0, [c.mu_star() * c.normal_fluctuation() for c in self.contacts]]
        return np.linalg.solve(K - omega**2 * M + 1j * omega * C, force)

    def _common_omega(self, what: str) -> float:
        """The forcing frequency all contacts share; an error naming ``what`` needs it."""
        omegas = [c.omega for c in self.contacts]
        check("contacts", omegas, np.allclose(omegas, omegas[0], rtol=1e-12),
              f"{what} needs one forcing frequency for all contacts")
        return omegas[0]

    def periodic_damping(self, t: float) -> np.ndarray:
        """Ĉ + diag(0, S_i N_i(t)): the damping of the linear periodic system."""
        return self._friction_damping([c.normal_force(t) for c in self.contacts])

    def _friction_damping(self, normal_forces) -> np.ndarray:
        """Ĉ + diag(0, S_i N_i): linearised friction adds S_i N_i to each contact's damping."""
        C = self._tangential_system[1].copy()
        C[1:, 1:] += np.diag(self.slopes * np.asarray(normal_forces, dtype=float))
        return C

    # --- first-order averaging -------------------------------------------------------------

    def averaged(self) -> AveragedStability:
        """First-order averaging of the linear periodic system (seed 004 §4, Table 1).

        Every Case II resonance ω_k ≈ Ω_i ± Ω_j (i <= j, each contact k) contributes the
        eigenvalues of its averaged 2 × 2 complex system with the detuning
        σ = ω_k − (Ω_i ± Ω_j); the other cases contribute −ξ_ii/2. The largest real part wins.
        """
        Omega, R = self.natural_frequencies()
        C = self._friction_damping([c.normal_load for c in self.contacts])
        xi = np.diag(R.T @ C @ R)
        growth, case, gamma_crit = -float(xi.min()) / 2, self._damping_case(Omega), None
        gammas = []
        for k, contact in enumerate(self.contacts, start=1):
            gamma = -self.slopes[k - 1] * contact.fluctuation_amplitude()   # γ_k of eq. 26
            G = gamma * np.outer(R[k], R[k])
            gammas.append(G)
            for i in range(len(Omega)):
                for j in range(i, len(Omega)):
                    for sign in ((1, -1) if j > i else (1,)):
                        rate, crit = _case2(xi[i], xi[j], G[i, j],
                                            contact.omega - (Omega[j] + sign * Omega[i]))
                        if rate > growth + 0.01 * abs(growth):
                            label = f"Ω{j + 1}{'+-'[sign < 0]}Ω{i + 1}"
                            growth, case, gamma_crit = rate, f"II: {label} ≈ ω{k}", crit
        return AveragedStability(growth, case, xi, gammas[0], gamma_crit)

    def _damping_case(self, Omega: np.ndarray, window: float = 0.02) -> str:
        """The resonance, if any, within ``window`` (relative) whose criterion is ξ_ii > 0."""
        w = [c.omega for c in self.contacts]
        for i, Om in enumerate(Omega, start=1):
            for k, wk in enumerate(w, start=1):
                if abs(wk - Om) < window * Om:
                    return f"I: Ω{i} ≈ ω{k}"
                for j, wj in enumerate(w[k - 1:], start=k):
                    for sign, text in ((1, "+"), (-1, "-")):
                        if abs(wk + sign * wj - Om) < window * Om:
                            return f"III: Ω{i} ≈ ω{k}{text}ω{j}"
        return "non-resonant"

    # --- Floquet ----------------------------------------------------------------------------

    def floquet(self, rtol: float = 1e-10, atol: float = 1e-12,
                prefix: str = "floquet_") -> FloquetStability:
        """Monodromy matrix of the linear periodic system over one forcing period.

        Integrates Φ' = A(t) Φ, Φ(0) = I, with A = [[0, I], [−M̂⁻¹K̂, −M̂⁻¹Ĉ(t)]], by PETSc TS
        (adaptive Dormand–Prince ``rk``/``5dp``; options under ``prefix``). All contacts must
        share one forcing frequency (one period).
        """
        omega = self._common_omega("Floquet analysis")
        M, _, K = self.tangential_matrices()
        n = M.shape[0]
        Minv = np.diag(1.0 / np.diag(M))
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = -Minv @ K
        period = 2 * math.pi / omega

        def rhs(ts, t, y, f):
            A[n:, n:] = -Minv @ self.periodic_damping(t)
            f.array[:] = (A @ y.array_r.reshape(2 * n, 2 * n)).ravel()

        phi, steps = _integrate_ode(rhs, np.eye(2 * n).ravel(), period, rtol, atol, prefix)
        phi = phi.reshape(2 * n, 2 * n)
        rho = np.linalg.eigvals(phi)
        rho = rho[np.argsort(-np.abs(rho))]
        return FloquetStability(rho, period, float(np.log(np.abs(rho[0])) / period), phi, steps)


def _case2(xi_i: float, xi_j: float, gamma: float, sigma: float) -> tuple[float, float]:
    """Largest real part of the averaged Case II eigenvalues and Γ_crit (eqs. 47-48).

    In a frame rotating with the detuning, the complex amplitudes obey
    (λ + ξ_i/2 + iσ/2)(λ + ξ_j/2 − iσ/2) = Γ²/16 (sum and difference resonances alike, and
    the principal resonance i = j).
    """
    b = (xi_i + xi_j) / 2
    c = (xi_i / 2 + 0.5j * sigma) * (xi_j / 2 - 0.5j * sigma) - gamma * gamma / 16
    growth = float(np.max(np.roots([1.0, b, c]).real))
    s = xi_i + xi_j
    crit = 2 * math.sqrt(max(xi_i * xi_j, 0.0)) / s * math.sqrt(s * s + 4 * sigma * sigma) \
        if s > 0 else 0.0
    return growth, crit


def _integrate_ode(rhs, y0: np.ndarray, t_end: float, rtol: float, atol: float,
                   prefix: str) -> tuple[np.ndarray, int]:
    """y' = f(t, y) from 0 to t_end with PETSc TS (explicit adaptive RK), sequentially."""
    y = PETSc.Vec().createSeq(y0.size, comm=MPI.COMM_SELF)
    y.array[:] = y0
    ts = PETSc.TS().create(comm=MPI.COMM_SELF)
    ts.setOptionsPrefix(prefix)
    ts.setType(PETSc.TS.Type.RK)
    ts.setRKType("5dp")
    ts.setRHSFunction(rhs, y.duplicate())
    ts.setTolerances(rtol=rtol, atol=atol)
    ts.setTimeStep(t_end / 100)
    ts.setMaxTime(t_end)
    ts.setExactFinalTime(PETSc.TS.ExactFinalTime.MATCHSTEP)
    ts.setMaxSteps(10**7)
    ts.setFromOptions()
    ts.solve(y)
    reason = ts.getConvergedReason()
    if reason < 0:
        raise RuntimeError(f"TS ({prefix}) failed at t={ts.getTime():g} of {t_end:g}: "
                           f"converged reason {reason}")
    out, steps = y.array_r.copy(), ts.getStepNumber()
    ts.destroy()
    y.destroy()
    return out, steps


@dataclasses.dataclass(frozen=True)
class StabilityMap:
    """Growth rate of perturbations of steady sliding against the forcing frequency.

    Attributes:
        omega: the forcing frequencies sampled.
        growth: method name ("averaging", "floquet") -> growth rate at each ω (< 0: stable).
        bands: method name -> list of (ω_lo, ω_hi) unstable intervals, edges refined by
            bisection to ``tol``.
        seconds: method name -> wall time of the sampling (without the edge refinement).
    """

    omega: np.ndarray
    growth: dict
    bands: dict
    seconds: dict


def stability_map(make_slider: typing.Callable[[float], Slider], omegas: typing.Sequence[float],
                  methods: typing.Sequence[str] = ("averaging", "floquet"),
                  tol: float = 1e-4) -> StabilityMap:
    """Sample the growth rate of each method over ``omegas`` and locate its unstable bands.

    Args:
        make_slider: ω_o -> the slider forced at ω_o (e.g. ``table2_slider``).
        omegas: increasing forcing frequencies; a band is seen if it contains a sample.
        methods: any of "averaging" (:meth:`Slider.averaged`), "floquet"
            (:meth:`Slider.floquet`).
        tol: the band edges are bisected to this width in ω.
    """
    omegas = np.asarray(omegas, dtype=float)
    check("omegas", omegas.size, omegas.size >= 2 and np.all(np.diff(omegas) > 0),
          "needs two or more increasing frequencies")
    rate = {"averaging": lambda w: make_slider(w).averaged().growth,
            "floquet": lambda w: make_slider(w).floquet().growth}
    for method in methods:
        check("methods", method, method in rate, f"must be among {sorted(rate)}")
    growth, bands, seconds = {}, {}, {}
    for method in methods:
        start = time.perf_counter()
        g = np.array([rate[method](w) for w in omegas])
        seconds[method] = time.perf_counter() - start
        growth[method] = g
        edges = [_bisect(rate[method], omegas[i], omegas[i + 1], tol)
                 for i in np.flatnonzero(np.sign(g[:-1]) != np.sign(g[1:]))]
        if g[0] > 0:
            edges.insert(0, omegas[0])
        if g[-1] > 0:
            edges.append(omegas[-1])
        bands[method] = [(float(a), float(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]
    return StabilityMap(omegas, growth, bands, seconds)


def stroboscopic_growth(t: np.ndarray, y: np.ndarray, period: float,
                        t_from: float = 0.0) -> tuple[np.ndarray, np.ndarray, float]:
    """Growth rate of a time response away from its periodic solution, from the samples at
    the multiples of ``period``: d_k = |y(kT) − y((k−1)T)| grows like |ρ|^k for the largest
    Floquet multiplier ρ, whatever the (unknown) periodic solution.

    Returns:
        (t_k, d_k, rate): the stroboscopic times and differences, and the least-squares slope
        of log d_k over t_k >= ``t_from``.
    """
    on = np.isclose(t / period, np.round(t / period), rtol=0.0, atol=1e-9)
    tk, yk = np.asarray(t)[on], np.asarray(y)[on]
    _, first = np.unique(np.round(tk / period), return_index=True)  # events repeat times
    tk, yk = tk[first], yk[first]
    d = np.linalg.norm(np.diff(yk, axis=0), axis=1)
    tk = tk[1:]
    fit = (tk >= t_from) & (d > 0)
    check("t", float(tk[-1]) if tk.size else 0.0, fit.sum() >= 2,
          "needs two or more forcing periods sampled after t_from")
    return tk, d, float(np.polyfit(tk[fit], np.log(d[fit]), 1)[0])


def _bisect(f, a: float, b: float, tol: float) -> float:
    fa = f(a)
    while b - a > tol:
        c = (a + b) / 2
        fc = f(c)
        a, b, fa = (c, b, fc) if np.sign(fc) == np.sign(fa) else (a, c, fa)
    return (a + b) / 2


# --- seed 004's numerical example (Table 2) ---------------------------------------------------

#: The unstable bands seed 004 reports (§5) near Ω2 − Ω1, Ω2 + Ω1 and 2 Ω2.
TABLE2_PAPER_BANDS = ((30.74, 30.83), (32.72, 32.83), (62.70, 64.45))

#: Readings of seed 004's dimensionless model that the paper leaves open, by name:
#: (normal_force_factor f_N, velocity unit U of eq. 59, end of eq. 59's sloping branch in its
#: own units). See :func:`table2_slider`.
TABLE2_READINGS: dict[str, tuple[float, float, float]] = {
    "paper": (100.0, 10.0, 20.0),
    "eq59-unmodified": (100.0, 12.0, 15.0),
    "slider-mass": (1.0, 10.0, 20.0),
    "dimensional": (1.0, 1.0, 15.0),
}


def table2_slider(omega: float, reading: str = "paper") -> Slider:
    r"""Seed 004's 3-d.o.f. example (Table 2, eqs. 53-59), dimensionless, at forcing ω_o.

    Units: slider mass, slider stiffness and asperity height are 1 (time in 1/ω_1 with
    ω_1² = k_s/m_s). Table 2: m̄_1 = 0.01, k̄_1 = 10, c̄_1 = 1, ζ_1 = 0.015, k̄_n = 0.1,
    ζ_n = 0.1, ω_n = √10, N̂_o = 0.05, λ̂ = 16.67. So m_s = k_s = 1, c_s = ζ_1, the contact has
    m = 0.01, k_t = 10, c_t = c̄_1 ζ_1, k_n = k̄_n = m ω_n² (consistent), c_n = m ζ_n, h = 1,
    λ = λ̂, and the surface speed V̂_ref = ω_o λ̂ / 2π (eq. 53). This gives Ω1 = 0.9950,
    Ω2 = 31.7807 (eq. 60) in every reading.

    What the paper leaves open, and the readings offered (``TABLE2_READINGS``):

    * the factor of the normal-force fluctuation: eq. 55 writes N̂ = N̂_o − M̄ ω_o² cos(…),
      i.e. the fluctuation of the *contact*-mass normalisation (f_N = 1/m̄_1 = 100), while the
      slider-mass normalisation of eq. 57 gives m̄_1 x'' (f_N = 1);
    * the velocity unit U of eq. 59 (the slope 0.03 per U): with U = 1 the operating speeds
      V̂_ref = 2.65 ω_o ≈ 82 … 171 lie on the flat branch (S = 0, no instability at all);
    * whether N may reach zero: in all readings the fluctuation exceeds N̂_o = 0.05; the
      linear analysis (eq. 21), like the paper, keeps the signed N.

    ``"paper"`` (f_N = 100, U = 10, S = −0.003) is the reading that puts the three unstable
    bands where the paper does; it needs eq. 59's sloping branch continued to 20 law units
    (μ_k = 0.15 instead of 0.3) so that the 2Ω2 band's speeds (up to 17.1 law units) are on
    it, as the paper's analysis and its Figs. 10-13 require. ``"eq59-unmodified"`` keeps eq.
    59 as printed with the smallest unit (U = 12) that keeps every studied speed on its slope;
    ``"slider-mass"`` takes f_N = 1 with the paper's slope; ``"dimensional"`` is the consistent
    dimensional reading (f_N = 1, U = 1: every speed on the flat branch).
    """
    check("reading", reading, reading in TABLE2_READINGS,
          f"must be one of {sorted(TABLE2_READINGS)}")
    check("omega", omega, math.isfinite(omega) and omega > 0, "must be a positive frequency")
    factor, unit, v_c = TABLE2_READINGS[reading]
    law = ScaledFriction(laws.PiecewiseLinearFriction(mu_s=0.75, slope=0.03, v_c=v_c), unit)
    m, zeta_1, zeta_n, lam = 0.01, 0.015, 0.1, 16.67
    contact = Contact(mass=m, k_t=10.0, c_t=1.0 * zeta_1, k_n=m * 10.0, c_n=m * zeta_n,
                      normal_load=0.05, roughness=1.0, wavelength=lam,
                      surface_speed=omega * lam / (2 * math.pi), friction=law,
                      normal_force_factor=factor)
    return Slider(mass=1.0, stiffness=1.0, damping=zeta_1, contacts=[contact])


# --- the nonlinear motion: true stick by events, or a regularised law -------------------------

_NORMAL_FORCE_MODELS = ("signed", "absolute", "clipped")


class SliderMotion:
    r"""The slider's nonlinear equations of motion as a :class:`~.events.HybridSystem`.

    State :math:`y = (q, \dot q)` with :math:`q = (y_s, y_1..y_m, x_1..x_m)` (eq. 8). The mode is
    a tuple with one entry per contact: +1 / −1 slipping with :math:`V_{rel} \gtrless 0`, 0
    sticking (:math:`\dot y_i = V_{ref,i}`, eq. 5). Events (each >= 0 while the mode holds,
    scaled by :math:`V_{ref,i}` and :math:`\mu_s \max|N_i|`): slipping, :math:`\pm V_{rel,i}`;
    sticking, :math:`\mu_s |N_i| - |F_{req,i}|` with the
    force that keeps the contact on the surface,
    :math:`F_{req,i} = c_{t,i}(V_{ref,i} - \dot y_s) + k_{t,i}(y_i - y_s)`. At an event a
    contact whose required force is within the static bound sticks, else it slips in the
    direction of that force.

    Args:
        slider: the :class:`Slider`.
        normal_force: how N enters friction — ``"signed"`` (eq. 21, the paper's linear
            model: N may change sign), ``"absolute"`` (eq. 3: |N|), ``"clipped"`` (max(N, 0):
            the contact opens when N would pull).
        coupled: the surface input reads :math:`X_i = V_{ref,i} t - y_i` (the contact's own
            motion shifts the roughness under it, seed 004 §2) instead of eq. 14's
            :math:`X_i = V_{ref,i} t`.
        eps: None: true stick by events; > 0: no stick, the regularised law
            :math:`F = \mu(V) N\,V/\sqrt{V^2+\varepsilon^2}` (one mode, no events).
        linearised: friction linearised about steady sliding (eq. 25),
            :math:`F_i = (\mu^*_i - S_i \dot y_i) N_i(t)` with the signed N, no stick, no
            events: the linear periodic system of :meth:`Slider.averaged` and
            :meth:`Slider.floquet`, forcing included, integrated in time.
    """

    def __init__(self, slider: Slider, normal_force: str = "signed", coupled: bool = False,
                 eps: float | None = None, linearised: bool = False):
        check("normal_force", normal_force, normal_force in _NORMAL_FORCE_MODELS,
              f"must be one of {_NORMAL_FORCE_MODELS}")
        check("eps", eps, eps is None or (math.isfinite(eps) and eps > 0),
              "must be None (events) or a number > 0 (regularised law)")
        check("linearised", linearised, not linearised or (
            eps is None and normal_force == "signed" and not coupled),
            "the linearised friction of eq. 25 takes the signed N, no eps and no coupling")
        self.slider, self.normal_force, self.coupled, self.eps = slider, normal_force, coupled, eps
        self.linearised = linearised
        m = slider.m
        self.size = 2 * (2 * m + 1)
        self._M, self._C, self._K = slider.matrices()
        self._Minv = 1.0 / np.diag(self._M)
        get = lambda name: np.array([getattr(c, name) for c in slider.contacts])  # noqa: E731
        self._mass, self._k_t, self._c_t = get("mass"), get("k_t"), get("c_t")
        self._k_n, self._c_n, self._N0 = get("k_n"), get("c_n"), get("normal_load")
        self._h, self._lam, self._V = get("roughness"), get("wavelength"), get("surface_speed")
        self._f = get("normal_force_factor")
        self._mu_s = np.array([c.static_coefficient for c in slider.contacts])
        self._mu_star = np.array([c.mu_star() for c in slider.contacts])
        self._force_scale = np.maximum(self._mu_s, 1e-3) * np.array(
            [c.normal_load + c.fluctuation_amplitude() for c in slider.contacts])
        self._tangential = slice(1, m + 1)
        self._normal = slice(m + 1, 2 * m + 1)

    # the pieces every mode needs
    def _contact_state(self, t: float, y: np.ndarray):
        n = self.size // 2
        q, v = y[:n], y[n:]
        ys, yi, xi = q[0], q[self._tangential], q[self._normal]
        vs, vi, vxi = v[0], v[self._tangential], v[self._normal]
        X = self._V * t - (yi if self.coupled else 0.0)
        X_dot = self._V - (vi if self.coupled else 0.0)
        phase = 2 * np.pi * X / self._lam
        x_in = self._h * np.sin(phase)
        x_in_dot = self._h * 2 * np.pi / self._lam * np.cos(phase) * X_dot
        normal_spring = self._c_n * (vxi - x_in_dot) + self._k_n * (xi - x_in)
        N = self._N0 - self._f * normal_spring        # N_o + f_N m ẍ, m ẍ = −(spring + dashpot)
        if self.normal_force == "absolute":
            N = np.abs(N)
        elif self.normal_force == "clipped":
            N = np.maximum(N, 0.0)
        V_rel = self._V - vi
        F_req = self._c_t * (self._V - vs) + self._k_t * (yi - ys)
        return q, v, N, V_rel, F_req, normal_spring

    def friction(self, t: float, y: np.ndarray, mode) -> np.ndarray:
        """Friction force on each contact (+ along the surface's motion); the reaction F_req
        for a sticking contact."""
        return self._friction(self._contact_state(t, y), mode)

    def _friction(self, state: tuple, mode) -> np.ndarray:
        _, _, N, V_rel, F_req, _ = state
        if self.linearised:  # μ(V_rel) ≈ μ* + S (V_rel − V_ref) = μ* − S ẏ_i
            return (self._mu_star - self.slider.slopes * (self._V - V_rel)) * N
        mu = np.array([c.friction(V) for c, V in zip(self.slider.contacts, V_rel, strict=True)])
        if self.eps is not None:
            return mu * N * V_rel / np.sqrt(V_rel * V_rel + self.eps * self.eps)
        sign = np.array(mode, dtype=float)
        return np.where(sign == 0, F_req, mu * N * sign)

    def contact_forces(self, t: float, y: np.ndarray, mode) -> tuple[np.ndarray, np.ndarray]:
        """(N, F): normal and friction force of each contact, from one contact-state
        evaluation."""
        state = self._contact_state(t, y)
        return state[2], self._friction(state, mode)

    def rhs(self, t: float, y: np.ndarray, mode) -> np.ndarray:
        n = self.size // 2
        state = self._contact_state(t, y)
        q, v, normal_spring = state[0], state[1], state[5]
        force = -self._C @ v - self._K @ q
        force[self._normal] = -normal_spring            # the normal d.o.f. see the surface
        force[self._tangential] += self._friction(state, mode)
        a = force * self._Minv
        if self.eps is None:
            stick = np.flatnonzero(np.array(mode) == 0)
            a[1 + stick] = 0.0                           # eq. 5: ÿ_i = 0 while sticking
        out = np.empty_like(y)
        out[:n], out[n:] = v, a
        if self.eps is None:
            out[1 + stick] = self._V[stick]
        return out

    def events(self, t: float, y: np.ndarray, mode) -> np.ndarray:
        if self.eps is not None or self.linearised:
            return np.zeros(0)
        _, _, N, V_rel, F_req, _ = self._contact_state(t, y)
        sign = np.array(mode, dtype=float)
        # scaled to O(1) (by V_ref and μ_s max|N|) so that one absolute event tolerance fits all
        return np.where(sign == 0, (self._mu_s * np.abs(N) - np.abs(F_req)) / self._force_scale,
                        sign * V_rel / self._V)

    def switch(self, t: float, y: np.ndarray, mode, fired: list[int]):
        _, _, N, _, F_req, _ = self._contact_state(t, y)
        y, mode = y.copy(), list(mode)
        n = self.size // 2
        for i in fired:
            y[n + 1 + i] = self._V[i]                    # V_rel = 0 at either kind of event
            holds = abs(F_req[i]) < self._mu_s[i] * abs(N[i]) and mode[i] != 0
            mode[i] = 0 if holds else (1 if F_req[i] > 0 else -1)
        return y, tuple(mode)

    def initial_state(self, perturbation: typing.Sequence[float] = ()) -> np.ndarray:
        """Steady sliding: the mean tangential position (eq. 13) at rest, the normal d.o.f. on
        their steady response (eq. 17); ``perturbation`` is added to (ẏ_s, ẏ_1, …)."""
        m = self.slider.m
        y = np.zeros(self.size)
        y[:m + 1] = self.slider.steady_sliding()
        for i, c in enumerate(self.slider.contacts):
            X = c.normal_amplitude()
            y[m + 1 + i] = X.imag
            y[self.size // 2 + m + 1 + i] = (1j * c.omega * X).imag
        p = np.asarray(perturbation, dtype=float)
        y[self.size // 2: self.size // 2 + p.size] += p
        return y

    def slip_mode(self) -> tuple:
        return (1,) * self.slider.m
