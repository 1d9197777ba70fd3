"""Assembly of a :class:`~fenicsfriction.forms.Residual` into PETSc objects.

The SNES, TS and PEP drivers all go through these two functions, so UFL integrals and nodal
springs are always assembled together and Dirichlet rows are treated one way
(dolfinx 0.5 pattern of ``python/test/unit/nls/test_newton.py``).
"""

from __future__ import annotations

import contextlib
import typing

import numpy as np
from dolfinx import fem

import dolfinx.fem.petsc  # noqa: F401

from petsc4py import PETSc

from fenicsfriction import _compat

__all__ = ["RoundoffConvergence", "assemble_jacobian", "assemble_residual",
           "options_with_defaults"]


def assemble_residual(b: PETSc.Vec, L: fem.FormMetaClass, a: fem.FormMetaClass, bcs: list,
                      x: PETSc.Vec, springs: typing.Sequence = ()) -> None:
    """b = R(x) with Dirichlet rows set to (x - g) scaled by -1, springs included.

    ``x`` must already hold the state the coefficients of ``L`` see (ghosts updated).
    """
    with b.localForm() as b_local:
        b_local.set(0.0)
    dolfinx.fem.petsc.assemble_vector(b, L)
    if bcs:
        dolfinx.fem.petsc.apply_lifting(b, [a], [bcs], [x], -1.0)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    if springs:
        b_array, x_array = b.getArray(), x.getArray(readonly=True)
        for spring in springs:
            spring.add_to_residual(b_array, x_array)
    if bcs:
        dolfinx.fem.petsc.set_bc(b, bcs, x, -1.0)


def assemble_jacobian(A: PETSc.Mat, a: fem.FormMetaClass, bcs: list,
                      springs: typing.Sequence = (), diagonal: float = 1.0) -> None:
    """A = dR/du (bilinear form ``a``) plus nodal spring stiffnesses.

    Dirichlet rows and columns are zeroed with ``diagonal`` on the diagonal (1 for a
    stiffness, 0 for damping and mass so that constrained dofs give infinite eigenvalues).
    """
    _compat.assemble_matrix_into(A, a, bcs, diagonal)
    if springs:  # the Dirichlet diagonal was INSERTed; PETSc needs a flush before ADD
        A.assemblyBegin(PETSc.Mat.AssemblyType.FLUSH)
        A.assemblyEnd(PETSc.Mat.AssemblyType.FLUSH)
    for spring in springs:
        spring.add_to_matrix(A)
    A.assemble()


@contextlib.contextmanager
def options_with_defaults(prefix: str, defaults: dict):
    """Put ``defaults`` into the PETSc options database under ``prefix`` for the duration of
    the block (call ``setFromOptions`` inside it), then take them out again.

    Options already in the database (set by the user: command line, ``PETSC_OPTIONS`` or code)
    win and are left alone; the defaults never outlive the block, so a later solver with the
    same prefix gets its own defaults rather than these.
    """
    opts = PETSc.Options(prefix)
    added = [key for key in defaults if not opts.hasName(key)]
    for key in added:
        opts[key] = defaults[key]
    try:
        yield opts
    finally:
        for key in added:
            opts.delValue(key)


class RoundoffConvergence:
    r"""SNES convergence test: PETSc's atol/rtol tests on the residual norm, with atol raised at
    each iteration to ``safety`` times the residual's round-off floor
    :math:`\sqrt{n}\,\varepsilon_{mach}\,\lVert J\rVert_\infty \lVert x\rVert_\infty`
    (cancellation in :math:`J x`: large when a soft spring carries a large rigid displacement,
    or, in a time step, when the acceleration is differenced from displacements). ``max_it`` and
    line-search failures stay PETSc's; the step-length test (``snes_stol``) is not used: it
    accepts a step small against ‖x‖ (the rigid slide) while the penetration is still wrong.

    Install with ``snes.setConvergenceTest(test)`` after ``setFromOptions`` and call
    :meth:`jacobian_assembled` from the Jacobian callback. ``atol_used`` is the tolerance of
    the last test.
    """

    def __init__(self, snes: PETSc.SNES, safety: float = 1.0):
        self.safety = safety
        self.rtol, self.atol = snes.getTolerances()[:2]
        self.atol_used = self.atol
        self._jacobian_norm = 0.0
        self._f0 = np.inf

    def jacobian_assembled(self, A: PETSc.Mat) -> None:
        self._jacobian_norm = A.norm(PETSc.NormType.INFINITY)

    def floor(self, x: PETSc.Vec) -> float:
        """sqrt(n) ε_mach ‖J‖_∞ ‖x‖_∞ with the last assembled Jacobian J."""
        return float(np.sqrt(x.getSize()) * np.finfo(float).eps * self._jacobian_norm
                     * x.norm(PETSc.NormType.INFINITY))

    def __call__(self, snes, it, norms):
        fnorm = norms[2]
        if not np.isfinite(fnorm):
            return PETSc.SNES.ConvergedReason.DIVERGED_FNORM_NAN
        if it == 0:
            self._f0 = fnorm
        self.atol_used = max(self.atol, self.safety * self.floor(snes.getSolution()))
        if fnorm <= self.atol_used:
            return PETSc.SNES.ConvergedReason.CONVERGED_FNORM_ABS
        if it > 0 and fnorm <= self.rtol * self._f0:
            return PETSc.SNES.ConvergedReason.CONVERGED_FNORM_RELATIVE
        return PETSc.SNES.ConvergedReason.ITERATING
