r"""The pin-on-disc study: steady sliding along μ, the eigenvalue loci, the flutter onset
μ_crit, the two coupling modes, and the two-mode (Hoffmann-type) model built from the same
finite element matrices (:mod:`~fenicsfriction.studies.squeal.two_mode`).

Everything is computed by the package's solvers on the one residual of
:class:`~fenicsfriction.studies.squeal.model.PinOnDiscModel`: :class:`~fenicsfriction.steady.
SteadySolver` (continuation in μ), :class:`~fenicsfriction.stability.StabilitySolver` and
:class:`~fenicsfriction.stability.Loci` (modes tracked by MAC, onset bisected).
"""

from __future__ import annotations

import dataclasses
import math
import typing

import numpy as np

from fenicsfriction.cea.projection import ModalBasis
from fenicsfriction.results import Record
from fenicsfriction.stability import Loci, Mode, StabilitySolver
from fenicsfriction.steady import SteadySolver, continuation
from fenicsfriction.studies.squeal.model import PinOnDiscModel
from fenicsfriction.studies.squeal.two_mode import TwoModeModel, modal_onset

__all__ = ["StabilityStudy", "TransientGrowth", "stability_study", "transient_growth"]


@dataclasses.dataclass
class StabilityStudy(Record):
    """What :func:`stability_study` measured.

    Attributes:
        dofs: the model's unknowns.
        axial_load: the pin's load [N].
        loci: one record per μ of the grid (``mu``, ``modes``: ``mode`` id, ``re``, ``im``,
            ``pin_share``; ``max_re``; ``contact_force`` [N], the disc's force on the pin).
        mu_crit: the flutter onset (bisected to ``tol``), ``interval`` its bracket.
        onset_value: the growing eigenvalue just past the onset [re, im] (1/s).
        coupling: the two modes that merge, named at the grid point before the onset: the two
            whose eigenvectors overlap most with the growing mode's in the mass inner product
            (``mode`` id, ``re``, ``im``, ``frequency_hz``, ``pin_share``, ``overlap``). (The
            frequencies alone can name the wrong pair: a mode of the disc or one damped by
            the friction may sit between the two that merge.) The two-mode model's real modes
            are those nearest to these two, one each.
        growing: the growing mode at the unstable end of the bracket (``mu``, ``re``, ``im``,
            ``pin_share``).
        two_mode: the two-mode model (:meth:`TwoModeModel.to_json`), its onset ``mu_c``.
        two_mode_linearity: max |B(μ₁/2) - B(μ₁)| / max |B(μ₁)|: how far the projected K̄
            is from linear in μ.
        basis_frequencies_hz: the real modes computed (μ = 0) [Hz].
        basis_onset: the onset of the pencil projected on all of them (damping included).
    """

    dofs: int
    axial_load: float
    loci: list[dict]
    mu_crit: float
    interval: list[float]
    onset_value: list[float]
    coupling: list[dict]
    growing: dict
    two_mode: dict
    two_mode_linearity: float
    basis_frequencies_hz: list[float]
    basis_onset: float


def _row(model: PinOnDiscModel, mode: Mode) -> dict[str, typing.Any]:
    return {"mode": mode.ident, "re": mode.value.real, "im": mode.value.imag,
            "frequency_hz": mode.value.imag / (2 * math.pi),
            "pin_share": model.pin_share(mode.vector)}


class _MassOverlap:
    """|a^H M w| / sqrt(a^H M a · w^H M w) of vectors ``a`` (owned entries, real or complex)
    with a fixed ``w``: 1 for the same mode, 0 for M-orthogonal ones."""

    def __init__(self, M: typing.Any, w: np.ndarray, comm: typing.Any):
        self.M, self.comm = M, comm
        self.x, self.y = M.createVecs()
        self.w = w
        self.Mw = self._apply(w)
        self.norm_w = self._norm(w, self.Mw)

    def _apply(self, a: np.ndarray) -> np.ndarray:
        out = []
        for part in (a.real, np.imag(a)):
            self.x.setArray(part)
            self.M.mult(self.x, self.y)
            out.append(self.y.getArray().copy())
        return out[0] + 1j * out[1]

    def _norm(self, a: np.ndarray, Ma: np.ndarray) -> float:
        return math.sqrt(abs(self.comm.allreduce(np.vdot(a, Ma))))

    def __call__(self, a: np.ndarray) -> float:
        Ma = self._apply(np.asarray(a, dtype=complex))
        inner = abs(self.comm.allreduce(np.vdot(a, self.Mw)))
        return inner / (self._norm(a, Ma) * self.norm_w)

    def destroy(self) -> None:
        self.x.destroy()
        self.y.destroy()


def overlap_with(M: typing.Any, vector: np.ndarray, comm: typing.Any,
                 basis: typing.Sequence[np.ndarray]) -> tuple[list[float], float]:
    """The mass overlaps of ``vector`` with each basis vector (this rank's rows), and the
    largest."""
    overlap = _MassOverlap(M, vector, comm)
    weights = [overlap(phi) for phi in basis]
    overlap.destroy()
    return weights, max(weights)


def stability_study(model: PinOnDiscModel, mus: typing.Sequence[float],
                    max_frequency: float = 5000.0, growth_tol: float = 1e-4,
                    tol: float = 1e-3, basis_size: int = 12,
                    prefix: str = "pin_on_disc_") -> StabilityStudy:
    """Steady sliding, loci and onset along ``mus`` (increasing from 0), and the two-mode model.

    Args:
        model: the built scene.
        mus: the grid of friction coefficients (the first one 0).
        max_frequency: every eigenvalue with |λ| <= 2π max_frequency is computed [Hz].
        growth_tol: a mode grows when Re λ > growth_tol |λ| (1e-4: the disc's modes take
            Re λ up to 3e-5 |λ| from the friction's geometric terms; a flutter pair's Re λ
            grows like sqrt(μ - μ_crit), which puts the threshold within 1e-5 of μ_crit).
        tol: the width of the onset's final bracket.
        basis_size: real modes computed for the two-mode model (the pair is picked among them).
        prefix: PETSc options prefix of the solvers.

    Returns:
        The study's record. ``model``'s state is left at the last μ of the grid.

    Raises:
        RuntimeError: no mode grows on the grid.
    """
    steady = SteadySolver(model.residual, prefix=f"{prefix}steady_", linear_solver="lu")
    model.initial_guess()
    continuation(steady, model.mu, [mus[0]])
    stability = StabilitySolver(model.residual, prefix=f"{prefix}pep_")
    stability.assemble()
    K0, M = stability.K.copy(), stability.M.copy()
    modal = ModalBasis(K0, M, modes=basis_size, prefix=f"{prefix}eps_")
    omega2, basis = modal.omega2, list(modal.phi.T)
    loci = Loci(steady, stability, model.mu, 2 * math.pi * max_frequency, growth_tol)
    seen: list[list[Mode]] = []

    def on_step(record: dict, modes: list[Mode]) -> None:
        record["modes"] = [{**m, "pin_share": model.pin_share(mode.vector)}
                           for m, mode in zip(record["modes"], modes, strict=True)]
        record["contact_force"] = model.contact_force().tolist()
        seen.append(modes)

    records = loci.follow(mus, on_step=on_step)
    first = next((i for i, modes in enumerate(seen) if loci.unstable(modes)), None)
    if first is None or first == 0:
        raise RuntimeError(f"no onset on the grid {list(mus)}: need stable sliding at the "
                           "first μ and a growing mode at a later one")
    mu1 = float(mus[first])
    onset = loci.onset(float(mus[first - 1]), mu1, tol=tol, reference=seen[first - 1])
    # the mode that grows first, just past the onset (the first unstable grid point may have
    # another), and the two that merge into it: at the grid point before the onset, those
    # nearest to it (nearer the onset, at the exceptional point, they are one)
    continuation(steady, model.mu, [onset.interval[1]])
    just_past = stability.solve(2 * math.pi * max_frequency)
    growing = max(loci.unstable(just_past), key=lambda m: m.value.real)
    growing_row = {"mu": onset.interval[1], **_row(model, growing)}
    overlap = _MassOverlap(M, growing.vector, model.comm)
    before = sorted(seen[first - 1], key=lambda m: overlap(m.vector))[-2:]
    coupling = [{**_row(model, m), "overlap": overlap(m.vector)}
                for m in sorted(before, key=lambda m: m.value.imag)]
    overlap.destroy()
    # and the real modes they come from: for each, the basis mode nearest to it
    pair: list[int] = []
    for mode in sorted(before, key=lambda m: -overlap_with(M, m.vector, model.comm, basis)[1]):
        weights = overlap_with(M, mode.vector, model.comm, basis)[0]
        pair.append(next(int(i) for i in np.argsort(weights)[::-1] if int(i) not in pair))
    pair.sort()
    projected = {}
    for value in (mu1 / 2, mu1):
        continuation(steady, model.mu, [value])
        stability.assemble()
        projected[value] = (modal.project(stability.K), modal.project(stability.C))
    both = np.ix_(pair, pair)
    k0 = np.diag(omega2[pair])
    K1, C1 = projected[mu1]
    two_mode = TwoModeModel.build(k0, K1[both], C1[both], mu1, pair)
    half = (projected[mu1 / 2][0][both] - k0) / (mu1 / 2)
    linearity = float(np.abs(half - two_mode.B).max() / np.abs(two_mode.B).max())
    # the same projection on the whole basis: what the other modes change
    all_modes = modal_onset(np.diag(omega2), (K1 - np.diag(omega2)) / mu1, C1 / mu1,
                            upper=1.5 * mu1)
    continuation(steady, model.mu, [mus[-1]])
    modal.eps.destroy()
    for mat in (K0, M):
        mat.destroy()
    return StabilityStudy(dofs=model.dofs, axial_load=model.axial_load, loci=records,
                          mu_crit=onset.mu_crit, interval=onset.interval,
                          onset_value=onset.value, coupling=coupling, growing=growing_row,
                          two_mode=two_mode.to_json(), two_mode_linearity=linearity,
                          basis_frequencies_hz=(np.sqrt(omega2) / (2 * math.pi)).tolist(),
                          basis_onset=all_modes)




@dataclasses.dataclass
class TransientGrowth(Record):
    """The growth of the flutter mode in time (see :func:`transient_growth`).

    Attributes:
        mu: the friction coefficient.
        eigenvalue: the growing eigenvalue of the PEP [re, im] (1/s).
        fitted: the fitted [a, ω] of the normal force's oscillation (1/s).
        amplification: the envelope's growth over the run, e^{a t_end}.
        max_relative_force: max |N(t) - N_0| / N_0 (the linear regime: small).
        time, normal_force: the series [s], [N].
        steps, wall_time_s: the time steps taken and their cost.
    """

    mu: float
    eigenvalue: list[float]
    fitted: list[float]
    amplification: float
    max_relative_force: float
    time: list[float]
    normal_force: list[float]
    steps: int
    wall_time_s: float


def transient_growth(model: PinOnDiscModel, mode: Mode, amplitude: float, periods: float,
                     steps_per_period: int = 40, prefix: str = "pin_on_disc_ts_"
                     ) -> TransientGrowth:
    r"""Steady sliding perturbed by a growing mode, integrated in time (generalized-α).

    The model holds a steady state :math:`u_0` at its μ and ``mode`` is an eigenpair
    :math:`(\lambda, w)` of its linearisation there. The run starts from
    :math:`u = u_0 + \mathrm{Re}\,w`, :math:`\dot u = \mathrm{Re}\,\lambda w` (w scaled to a
    largest displacement ``amplitude``), the initial state of the linear solution
    :math:`\mathrm{Re}\,(w e^{\lambda t})` alone; the disc's normal force on the pin, N(t),
    must then oscillate as :math:`N_0 + A e^{at}\cos(\omega t + \varphi)` with
    :math:`a + i\omega = \lambda`, as long as the motion stays small (linear regime). The fit
    of that form gives ``fitted``.

    Args:
        model: the model, at a steady state.
        mode: the growing eigenpair at that state.
        amplitude: the largest nodal displacement of the perturbation [m].
        periods: the run's length in periods 2π/Im λ.
        steps_per_period: time steps per period (the scheme's relative error on a is about
            (ω Δt)²/4: 0.6 % for 40).
        prefix: PETSc options prefix of the TS.
    """
    import scipy.optimize

    from fenicsfriction.dynamics import DynamicsSolver

    lam = mode.value
    residual = model.residual
    comm = model.comm
    w = mode.vector
    scale = amplitude / comm.allreduce(float(np.abs(w).max(initial=0.0)), op=_max())
    owned = len(w)
    u0 = residual.u.x.array.copy()
    normal0 = model.contact_force()[2]
    residual.u.x.array[:owned] += scale * w.real
    residual.u_dot.x.array[:] = 0.0
    residual.u_dot.x.array[:owned] = scale * (lam * w).real
    residual.u_ddot.x.array[:] = 0.0
    for f in (residual.u, residual.u_dot):
        f.x.scatter_forward()
    period = 2 * math.pi / lam.imag
    dynamics = DynamicsSolver(residual, prefix=prefix, atol=1e-10 * model.axial_load,
                              options={"snes_rtol": 1e-12})
    records = dynamics.run(periods * period, period / steps_per_period,
                           observe=lambda t: {"normal_force": model.contact_force()[2]})
    t = np.array([r["time"] for r in records])
    n = np.array([r["normal_force"] for r in records]) - normal0

    def oscillation(t: np.ndarray, a: float, omega: float, c: float, s: float,
                    c0: float) -> np.ndarray:
        return np.exp(a * t) * (c * np.cos(omega * t) + s * np.sin(omega * t)) + c0

    guess = [lam.real, lam.imag, n[0], 0.0, 0.0]
    (a, omega, *_), _ = scipy.optimize.curve_fit(oscillation, t, n, p0=guess, maxfev=20000)
    # back to the steady state
    residual.u.x.array[:] = u0
    residual.u_dot.x.array[:] = 0.0
    residual.u_ddot.x.array[:] = 0.0
    return TransientGrowth(mu=float(model.mu.value), eigenvalue=[lam.real, lam.imag],
                           fitted=[float(a), float(omega)],
                           amplification=float(math.exp(a * t[-1])),
                           max_relative_force=float(np.abs(n).max() / abs(normal0)),
                           time=[float(x) for x in t],
                           normal_force=[float(x) for x in n + normal0],
                           steps=len(records) - 1,
                           wall_time_s=float(sum(r["wall_time_s"] for r in records)))


def _max() -> typing.Any:
    from mpi4py import MPI
    return MPI.MAX
