r"""The mode-coupling map of a finite element model: frequencies and growth rates of its modes
along the steady-sliding continuation in μ, the coalescence marked.

:func:`coupling_map` continues the steady state of a
:class:`~fenicsfriction.stability.Loci` over the μ values, solves its quadratic eigenproblem at
each and runs the matrix-level sweep on it (:class:`~fenicsfriction.cea.sweep.Sweep`: modes
tracked by MAC, frequency f = Im λ / 2π in Hz and growth rate Re λ in 1/s); each interval where
a mode starts to grow is bisected, which names the two modes that coalesce
(:class:`~fenicsfriction.cea.sweep.Coalescence`). :meth:`CouplingMap.plot` draws the map
brake-squeal engineers read (:func:`fenicsfriction.cea.figures.plot_coupling_map`): the two
branches merging in frequency as their growth rates split.

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
import typing

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np

from fenicsfriction.cea.projection import ModalBasis, symmetric_part
from fenicsfriction.cea.sweep import Coalescence, Sweep
from fenicsfriction.laws import check
from fenicsfriction.results import Record
from fenicsfriction.stability import Loci, Mode, StabilitySolver

__all__ = ["CouplingMap", "ProjectedStability", "coupling_map"]


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
    """The sweep along μ of a finite element model and where its modes couple.

    Attributes:
        records: one per μ (:attr:`Sweep.records <fenicsfriction.cea.sweep.Sweep.records>`):
            ``p`` (μ), ``modes`` (``mode`` id, ``re``, ``im``, ``frequency`` [Hz],
            ``residual``, ``accurate``), ``max_re``.
        coalescences: each onset of growth, bisected, with the pair that coalesces.
        projection: the number of modes of the modal basis, or None (full eigenproblem).
    """

    records: list[dict[str, typing.Any]]
    coalescences: list[Coalescence]
    projection: int | None = None

    def plot(self, path: typing.Any, comm: MPI.Comm = MPI.COMM_WORLD,
             max_frequency: float | None = None) -> None:
        """The mode-coupling map as a PNG (:func:`fenicsfriction.cea.figures.plot_coupling_map`,
        drawn on rank 0), the modes that start above ``max_frequency`` [Hz] left out."""
        if comm.rank != 0:
            return
        from fenicsfriction.cea.figures import plot_coupling_map
        records = self.records
        if max_frequency is not None:
            kept = {m["mode"] for m in records[0]["modes"] if m["frequency"] <= max_frequency}
            records = [{**r, "modes": [m for m in r["modes"] if m["mode"] in kept]}
                       for r in records]
        plot_coupling_map(records, path, self.coalescences, param_name="μ")


def coupling_map(loci: Loci, values: typing.Sequence[float], tol: float = 1e-3) -> CouplingMap:
    """Sweep the steady sliding of ``loci`` over ``values`` and bisect each onset to ``tol``.

    Args:
        loci: the model's steady solver, eigensolver (full or :class:`ProjectedStability`),
            continued parameter, disc |λ| <= ``max_modulus`` and growth tolerance.
        values: the μ of the sweep, increasing from the steady state's.
        tol: width of each onset's bisection interval.

    Returns:
        The map; the steady state is left where it was last solved: at the unstable end of
        the last onset's bisection, else at the last value.
    """
    from fenicsfriction.steady import continuation
    check("values", list(values), len(values) >= 2 and bool(np.all(np.diff(values) > 0)),
          "at least two increasing values")

    def solve_at(value: float) -> list[Mode]:
        continuation(loci.steady, loci.parameter, [value])
        return loci.stability.solve(loci.max_modulus)

    sweep = Sweep(solve_at, loci.comm, loci.growth_tol)
    sweep.follow(values)
    events = [sweep.refine(event, tol) for event in sweep.coalescences()]
    projection = loci.stability.modes if isinstance(loci.stability, ProjectedStability) \
        else None
    return CouplingMap(records=sweep.records, coalescences=events, projection=projection)
