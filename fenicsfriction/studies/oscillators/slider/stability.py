r"""Is steady sliding of the slider stable? Two analyses of its linear periodic system.

A perturbation q of the tangential co-ordinates obeys :math:`\hat M \ddot q + (\hat C +
\operatorname{diag}(0, S_i N_i(t)))\dot q + \hat K q = 0` (see
:mod:`~fenicsfriction.studies.oscillators.slider.model`), whose damping the normal force
modulates. Two independent tools act on it ("Friction-induced sliding instability in a
multi-degree-of-freedom system with oscillatory normal forces" (2003), §3-4):

* :func:`averaged` — the modal transformation (eqs. 27-29) and first-order averaging:
  Cases I, III and the non-resonant case are stable iff the modal damping :math:`\xi_{ii}>0`;
  Case II (:math:`\omega_k \approx \Omega_i \pm \Omega_j`, i = j the principal resonance) has
  the averaged eigenvalues :math:`(\lambda + \xi_{ii}/2 + i\sigma/2)(\lambda + \xi_{jj}/2 \mp
  i\sigma/2) = \Gamma_{ij}^2/16` (eq. 47 in a rotating frame), unstable iff
  :math:`|\Gamma_{ij}| > \Gamma_{crit}` of eq. 48;
* :func:`floquet` — the monodromy matrix over one forcing period, by integrating the
  variational equations with PETSc TS, and its Floquet multipliers (exact up to the
  integration tolerance).

:func:`stability_map` samples either over the forcing frequency and bisects the edges of the
unstable bands; :func:`stroboscopic_growth` measures the same growth rate on a time response.
"""

from __future__ import annotations

import dataclasses
import math
import time
import typing

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np

from fenicsfriction.laws import check
from fenicsfriction.numerics import bisect
from fenicsfriction.results import Record

if typing.TYPE_CHECKING:
    from fenicsfriction.studies.oscillators.slider.model import Slider

__all__ = ["AveragedStability", "FloquetStability", "StabilityMap", "averaged", "floquet",
           "stability_map", "stroboscopic_growth"]


@dataclasses.dataclass(frozen=True)
class AveragedStability(Record):
    """First-order averaging at one surface speed (the m.d.o.f. slider paper (2003), §4).

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
class FloquetStability(Record):
    """Floquet multipliers ρ of the linear periodic system over one period T.

    Attributes:
        multipliers: ρ, by decreasing modulus.
        period: T = 2π/ω.
        growth: max ln|ρ| / T, the exact counterpart of :attr:`AveragedStability.growth`.
        monodromy: the monodromy matrix Φ(T).
        steps: accepted TS steps over the period.
    """

    multipliers: np.ndarray
    period: float
    growth: float
    monodromy: np.ndarray
    steps: int


@dataclasses.dataclass(frozen=True)
class StabilityMap(Record):
    """Growth rate of perturbations of steady sliding against the forcing frequency.

    Attributes:
        omega: the forcing frequencies sampled.
        growth: method name ("averaging", "floquet") -> growth rate at each ω (< 0: stable).
        bands: method name -> list of (ω_lo, ω_hi) unstable intervals, edges refined by
            bisection to ``tol``.
        seconds: method name -> wall time of the sampling (without the edge refinement).
    """

    omega: np.ndarray
    growth: dict[str, np.ndarray]
    bands: dict[str, list[tuple[float, float]]]
    seconds: dict[str, float]


# --- first-order averaging ---------------------------------------------------------------------


def averaged(slider: Slider) -> AveragedStability:
    """First-order averaging of the linear periodic system (the m.d.o.f. slider paper (2003),
    §4, Table 1).

    Every Case II resonance ω_k ≈ Ω_i ± Ω_j (i <= j, each contact k) contributes the
    eigenvalues of its averaged 2 × 2 complex system with the detuning
    σ = ω_k − (Ω_i ± Ω_j); the other cases contribute −ξ_ii/2. The largest real part wins.

    Args:
        slider: the :class:`~fenicsfriction.studies.oscillators.slider.model.Slider`.

    Returns:
        The :class:`AveragedStability`.
    """
    Omega, R = slider.natural_frequencies()
    C = slider.friction_damping([c.normal_load for c in slider.contacts])
    xi = np.diag(R.T @ C @ R)
    growth, case = -float(xi.min()) / 2, _damping_case(slider, Omega)
    gamma_crit: float | None = None
    gammas = []
    for k, contact in enumerate(slider.contacts, start=1):
        gamma = -slider.slopes[k - 1] * contact.fluctuation_amplitude()   # γ_k of eq. 26
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


def _damping_case(slider: Slider, Omega: np.ndarray, window: float = 0.02) -> str:
    """The resonance, if any, within ``window`` (relative) whose criterion is ξ_ii > 0."""
    w = [c.omega for c in slider.contacts]
    for i, Om in enumerate(Omega, start=1):
        for k, wk in enumerate(w, start=1):
            if abs(wk - Om) < window * Om:
                return f"I: Ω{i} ≈ ω{k}"
            for j, wj in enumerate(w[k - 1:], start=k):
                for sign, text in ((1, "+"), (-1, "-")):
                    if abs(wk + sign * wj - Om) < window * Om:
                        return f"III: Ω{i} ≈ ω{k}{text}ω{j}"
    return "non-resonant"


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


# --- Floquet -----------------------------------------------------------------------------------


def floquet(slider: Slider, rtol: float = 1e-10, atol: float = 1e-12,
            prefix: str = "floquet_") -> FloquetStability:
    """Monodromy matrix of the linear periodic system over one forcing period.

    Integrates Φ' = A(t) Φ, Φ(0) = I, with A = [[0, I], [−M̂⁻¹K̂, −M̂⁻¹Ĉ(t)]], by PETSc TS
    (adaptive Dormand–Prince ``rk``/``5dp``). All contacts must share one forcing frequency
    (one period).

    Args:
        slider: the :class:`~fenicsfriction.studies.oscillators.slider.model.Slider`.
        rtol, atol: error-control tolerances of the Runge-Kutta steps.
        prefix: PETSc options prefix of the TS.

    Returns:
        The :class:`FloquetStability`.

    Raises:
        RuntimeError: the TS failed.
    """
    omega = slider.forcing_frequency("Floquet analysis")
    M, _, K = slider.tangential_matrices()
    n = M.shape[0]
    Minv = np.diag(1.0 / np.diag(M))
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -Minv @ K
    period = 2 * math.pi / omega

    def rhs(ts: PETSc.TS, t: float, y: PETSc.Vec, f: PETSc.Vec) -> None:
        A[n:, n:] = -Minv @ slider.periodic_damping(t)
        f.array[:] = (A @ y.array_r.reshape(2 * n, 2 * n)).ravel()

    phi, steps = _integrate_ode(rhs, np.eye(2 * n).ravel(), period, rtol, atol, prefix)
    phi = phi.reshape(2 * n, 2 * n)
    rho = np.linalg.eigvals(phi)
    rho = rho[np.argsort(-np.abs(rho))]
    return FloquetStability(rho, period, float(np.log(np.abs(rho[0])) / period), phi, steps)


def _integrate_ode(rhs: typing.Callable[[PETSc.TS, float, PETSc.Vec, PETSc.Vec], None],
                   y0: np.ndarray, t_end: float, rtol: float, atol: float,
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


# --- over the forcing frequency ------------------------------------------------------------------


def stability_map(make_slider: typing.Callable[[float], Slider],
                  omegas: typing.Sequence[float] | np.ndarray,
                  methods: typing.Sequence[str] = ("averaging", "floquet"),
                  tol: float = 1e-4) -> StabilityMap:
    """Sample the growth rate of each method over ``omegas`` and locate its unstable bands.

    Args:
        make_slider: ω_o -> the slider forced at ω_o (e.g. ``table2_slider``).
        omegas: increasing forcing frequencies; a band is seen if it contains a sample.
        methods: any of "averaging" (:func:`averaged`), "floquet" (:func:`floquet`).
        tol: the band edges are bisected to this width in ω.

    Returns:
        The :class:`StabilityMap`.

    Raises:
        ValueError: fewer than two or non-increasing ``omegas``, an unknown method.
    """
    samples = np.asarray(omegas, dtype=float)
    check("omegas", samples.size, samples.size >= 2 and bool(np.all(np.diff(samples) > 0)),
          "needs two or more increasing frequencies")
    rate: dict[str, typing.Callable[[float], float]] = {
        "averaging": lambda w: make_slider(w).averaged().growth,
        "floquet": lambda w: make_slider(w).floquet().growth}
    for method in methods:
        check("methods", method, method in rate, f"must be among {sorted(rate)}")
    growth, bands, seconds = {}, {}, {}
    for method in methods:
        start = time.perf_counter()
        g = np.array([rate[method](w) for w in samples])
        seconds[method] = time.perf_counter() - start
        growth[method] = g
        edges = [_sign_change(rate[method], samples[i], samples[i + 1], g[i], tol)
                 for i in np.flatnonzero(np.sign(g[:-1]) != np.sign(g[1:]))]
        if g[0] > 0:
            edges.insert(0, samples[0])
        if g[-1] > 0:
            edges.append(samples[-1])
        bands[method] = [(float(a), float(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]
    return StabilityMap(samples, growth, bands, seconds)


def _sign_change(f: typing.Callable[[float], float], a: float, b: float, f_a: float,
                 tol: float) -> float:
    """Where f changes sign in [a, b] (f(a) = ``f_a`` known), bisected to ``tol``."""
    before, after = bisect(lambda x: bool(np.sign(f(x)) != np.sign(f_a)), a, b, tol)
    return (before + after) / 2


def stroboscopic_growth(t: np.ndarray, y: np.ndarray, period: float,
                        t_from: float = 0.0) -> tuple[np.ndarray, np.ndarray, float]:
    """Growth rate of a time response away from its periodic solution.

    From the samples at the multiples of ``period``: d_k = |y(kT) − y((k−1)T)| grows like
    ``|ρ|^k`` for the largest Floquet multiplier ρ, whatever the (unknown) periodic solution.

    Args:
        t: recorded times (with the multiples of ``period`` among them, e.g. ``sample_dt``
            = period).
        y: the states at those times, one row each.
        period: the forcing period T.
        t_from: the fit uses the stroboscopic times from here on.

    Returns:
        (t_k, d_k, rate): the stroboscopic times and differences, and the least-squares slope
        of log d_k over t_k >= ``t_from``.

    Raises:
        ValueError: fewer than two forcing periods sampled after ``t_from``.
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
