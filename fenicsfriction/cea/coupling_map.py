r"""The mode-coupling map of a finite element model: frequencies and growth rates of its modes
along the steady-sliding continuation in μ, the coalescence marked.

:class:`~fenicsfriction.stability.Loci` continues the steady state in μ, solves the quadratic
eigenproblem at each value and tracks each mode by MAC; :func:`coupling_map` keeps its records
as curves per mode (frequency f = Im λ / 2π in Hz, growth rate Re λ in 1/s), and, when a mode
grows within the values, bisects the onset between the last stable and the first unstable
value (:meth:`~fenicsfriction.stability.Loci.onset`), which names the two modes that coalesce.
:func:`plot_coupling_map` draws the map brake-squeal engineers read: the two branches merging in
frequency as their growth rates split.

**Modal projection** (:class:`ProjectedStability`): instead of the full quadratic eigenproblem
at each μ, its projection on the m lowest real modes of the symmetric frictionless problem,
:math:`\bar K(u_0; \mu = 0)` (the friction stiffness dropped with the friction switch of
:class:`~fenicsfriction.stability.StabilitySolver`, symmetrised in case the model leaves some
other asymmetry) and M at the first steady state. The basis
(:class:`~fenicsfriction.cea.projection.ModalBasis`) is computed once and reused along the
sweep, as modal CEA does; the projected eigenvalues converge to the full ones as modes are
added (Galerkin), and each carries its residual against the full matrices.
"""

from __future__ import annotations

import dataclasses
import math
import typing

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np

from fenicsfriction.cea.projection import ModalBasis, symmetric_part
from fenicsfriction.laws import check
from fenicsfriction.results import Record
from fenicsfriction.stability import Loci, Mode, Onset, StabilitySolver

__all__ = ["CouplingMap", "ProjectedStability", "coupling_map", "plot_coupling_map"]


class ProjectedStability:
    """The eigenvalues of a :class:`~fenicsfriction.stability.StabilitySolver` by projection on
    a fixed modal basis: an eigensolver for :class:`~fenicsfriction.stability.Loci`.

    Args:
        stability: the full solver; its matrices are assembled at each state and projected.
        modes: the number m of real modes in the basis.
        prefix: PETSc options prefix of the basis's EPS.
        options: EPS options (see :class:`~fenicsfriction.cea.projection.ModalBasis`).

    Attributes:
        basis: the :class:`~fenicsfriction.cea.projection.ModalBasis`, computed at the first
            :meth:`solve` (the first steady state) and kept.
    """

    def __init__(self, stability: StabilitySolver, modes: int, prefix: str = "cea_map_basis_",
                 options: dict | None = None):
        check("modes", modes, modes >= 1, "must be >= 1")
        self.stability, self.modes = stability, modes
        self.prefix, self.options = prefix, options
        self.comm: MPI.Comm = stability.comm
        self.basis: ModalBasis | None = None

    def _frictionless_stiffness(self) -> PETSc.Mat:
        """Symmetric part of K̄ at the current state, its friction part dropped when the
        residual says how (``Residual.friction``)."""
        solver = self.stability
        kept = solver.frictionless
        if solver.residual.friction is not None:
            solver.frictionless = {"K", "C"}
        try:
            solver.assemble()
        finally:
            solver.frictionless = kept
        return symmetric_part(solver.K)

    def solve(self, max_modulus: float) -> list[Mode]:
        """Every projected eigenvalue with |λ| <= ``max_modulus`` (Im λ >= 0), by |λ|."""
        solver = self.stability
        if self.basis is None:
            K_s = self._frictionless_stiffness()
            shift = -1e-6 * K_s.norm(PETSc.NormType.INFINITY) \
                / solver.M.norm(PETSc.NormType.INFINITY)
            self.basis = ModalBasis(K_s, solver.M, modes=self.modes, shift=shift,
                                    prefix=self.prefix, options=self.options)
            K_s.destroy()
        solver.assemble()
        modes = self.basis.solve(solver.M, solver.C, solver.K,
                                 residual_tol=solver.residual_tol)
        return sorted((m for m in modes if abs(m.value) <= max_modulus),
                      key=lambda m: abs(m.value))


@dataclasses.dataclass
class CouplingMap(Record):
    """Frequencies and growth rates of the tracked modes along μ, and the onset.

    Attributes:
        mu: the values of the continuation.
        modes: per tracked mode ``{"mode": id, "mu": [...], "frequency": [... Hz],
            "growth_rate": [... 1/s], "residual": [...]}`` (a mode may miss some values).
        onset: the bisected onset (:class:`~fenicsfriction.stability.Onset`: ``mu_crit``,
            ``interval``, the growing eigenvalue, the two ``colliding`` modes), or None when no
            mode grows within the values.
        projection: the number of modes of the modal basis, or None (full eigenproblem).
    """

    mu: list[float]
    modes: list[dict[str, typing.Any]]
    onset: Onset | None
    projection: int | None = None


def coupling_map(loci: Loci, values: typing.Sequence[float], tol: float = 1e-3) -> CouplingMap:
    """Follow the steady sliding over ``values`` (increasing), and bisect the onset to ``tol``
    if a mode grows.

    Args:
        loci: the loci of the model (its eigensolver full or :class:`ProjectedStability`).
        values: the μ of the continuation; the first must be stable for an onset to be found.
        tol: width of the onset's bisection interval.

    Returns:
        The map; the steady state is left at the onset's stable end, else at the last value.
    """
    check("values", list(values), len(values) >= 2 and bool(np.all(np.diff(values) > 0)),
          "at least two increasing values")
    steps: list[tuple[dict, list[Mode]]] = []
    loci.follow(values, on_step=lambda record, modes: steps.append((record, modes)))
    curves: dict[int, dict[str, list]] = {}
    for record, _ in steps:
        for m in record["modes"]:
            curve = curves.setdefault(m["mode"], {"mode": m["mode"], "mu": [], "frequency": [],
                                                  "growth_rate": [], "residual": []})
            curve["mu"].append(record["mu"])
            curve["frequency"].append(m["im"] / (2 * math.pi))
            curve["growth_rate"].append(m["re"])
            curve["residual"].append(m["residual"])
    onset = None
    unstable = [i for i, (_, modes) in enumerate(steps) if loci.unstable(modes)]
    if unstable and unstable[0] > 0:
        first = unstable[0]
        onset = loci.onset(values[first - 1], values[first], tol=tol,
                           reference=steps[first - 1][1])
    projection = loci.stability.modes if isinstance(loci.stability, ProjectedStability) \
        else None
    return CouplingMap(mu=[float(v) for v in values], modes=list(curves.values()), onset=onset,
                       projection=projection)


def plot_coupling_map(result: CouplingMap, path: typing.Any, comm: MPI.Comm = MPI.COMM_WORLD,
                      max_frequency: float | None = None) -> None:
    """Frequency and growth rate against μ, one curve per tracked mode; the two colliding modes
    in colour, the onset interval shaded (rank 0 draws).

    Args:
        result: the map.
        path: the PNG written.
        comm: the communicator (rank 0 draws).
        max_frequency: the modes above it [Hz] are left out (None: every mode).
    """
    if comm.rank != 0:
        return
    from fenicsfriction.plotting import saved_figure
    colliding = [] if result.onset is None else [c["mode"] for c in result.onset.colliding]
    with saved_figure(path, ncols=2, figsize=(10.0, 4.0)) as axes:
        for curve in result.modes:
            if max_frequency is not None and min(curve["frequency"]) > max_frequency:
                continue
            highlighted = curve["mode"] in colliding
            style = {"color": f"C{colliding.index(curve['mode'])}", "lw": 1.8,
                     "label": f"mode {curve['mode']}"} if highlighted else \
                {"color": "0.6", "lw": 0.8}
            for ax, key in zip(axes, ("frequency", "growth_rate"), strict=True):
                ax.plot(curve["mu"], curve[key], marker=".", **style)
        for ax, label in zip(axes, ("frequency [Hz]", "growth rate Re λ [1/s]"), strict=True):
            ax.set_xlabel("μ")
            ax.set_ylabel(label)
            if result.onset is not None:
                low, high = result.onset.interval
                ax.axvspan(low, high, color="C3", alpha=0.2, lw=0)
                ax.axvline(result.onset.mu_crit, color="C3", ls="--", lw=0.8)
        axes[1].axhline(0.0, color="k", lw=0.5)
        title = "full" if result.projection is None else f"{result.projection} modes"
        if result.onset is not None:
            title += f", μ_crit = {result.onset.mu_crit:.4f}"
        axes[0].set_title(title, fontsize=9)
        if colliding:
            axes[0].legend(fontsize=8)
