"""PETSc plumbing without a mesh: option defaults under a prefix and a Newton stopping test.

Used by every PETSc driver of the package, the finite element solvers and the reduced models
alike, so it imports petsc4py only (no dolfinx).
"""

from __future__ import annotations

import contextlib
import typing

from petsc4py import PETSc

import numpy as np

__all__ = ["EVENTS_LOCATED_TO_RESOLUTION", "RoundoffConvergence", "callback_error",
           "options_inserted", "options_with_defaults"]


@contextlib.contextmanager
def options_with_defaults(prefix: str, defaults: dict) -> typing.Iterator[PETSc.Options]:
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


@contextlib.contextmanager
def options_inserted(text: str) -> typing.Iterator[None]:
    """Insert ``text`` (``-name value`` pairs, as on a command line) into the PETSc options
    database for the duration of the block, then put the database back as it was: the
    options added are removed and those overridden get their old values again.

    The command line's PETSc options belong to its one run; without this a second run in
    the same process (a notebook, a test) would inherit, say, the first's ``snes_max_it``.
    """
    opts = PETSc.Options()
    before = opts.getAll()
    opts.insertString(text)
    try:
        yield
    finally:
        for key, value in opts.getAll().items():
            if key not in before:
                opts.delValue(key)
            elif before[key] != value:
                opts.setValue(key, before[key])


def callback_error(error: PETSc.Error) -> BaseException:
    """What ended a solve, as a callback (monitor, right-hand side, event) raised it.

    petsc4py 3.18 re-raises an exception from a callback as it is; petsc4py 3.22 raises a
    ``PETSc.Error`` with code -1 whose ``__cause__`` is the original. Returned: that original
    (a Python exception, to re-raise, or a ``PETSc.Error`` with its real code), or ``error``
    itself when PETSc failed on its own.
    """
    cause = error.__cause__
    return error if cause is None else cause


#: PETSc 3.22's event location (rewritten after 3.18) locates an event to the time resolution
#: itself; 3.18's retries until |g| <= tol and stalls there, which the hybrid driver detects
#: and resumes with a relaxed tolerance
EVENTS_LOCATED_TO_RESOLUTION = PETSc.Sys.getVersion() >= (3, 22)


class RoundoffConvergence:
    r"""SNES convergence test: PETSc's atol/rtol tests on the residual norm, with atol raised at
    each iteration to ``safety`` times the residual's round-off floor
    :math:`\sqrt{n}\,\lVert\,|J|\,|x|\,\rVert_\infty` times the machine precision
    (cancellation in :math:`J x`: large when a soft spring carries a large rigid displacement,
    or, in a time step, when the acceleration is differenced from displacements). The bound is
    taken row by row (:math:`|J|` the matrix of the entries' moduli), not as
    :math:`\lVert J\rVert_\infty \lVert x\rVert_\infty`, which it equals when the stiffest
    rows also move most (one body) but which is far too large when a stiff body that hardly
    moves shares the system with a soft one that slides (a block on a stiff slab: the slab's
    rows times the block's rigid slide accepted Newton's first iterate at 1e-5 of the load;
    matrices that are not AIJ fall back to it). ``max_it`` and
    line-search failures stay PETSc's; the step-length test (``snes_stol``) is not used: it
    accepts a step small against ‖x‖ (the rigid slide) while the penetration is still wrong.

    Install with ``snes.setConvergenceTest(test)`` after ``setFromOptions`` and call
    :meth:`jacobian_assembled` from the Jacobian callback. ``atol_used`` is the tolerance of
    the last test. ``force_iteration`` (from ``-<prefix>snes_force_iteration``, which PETSc
    leaves to the convergence test) makes every solve take at least one iteration, e.g. to
    polish a state accepted at its round-off floor.
    """

    def __init__(self, snes: PETSc.SNES, safety: float = 1.0):
        self.safety = safety
        self.rtol, self.atol = snes.getTolerances()[:2]
        self.force_iteration = PETSc.Options(snes.getOptionsPrefix()).getBool(
            "snes_force_iteration", False)
        self.atol_used = self.atol
        self._jacobian_norm = 0.0
        self._moduli: PETSc.Mat | None = None
        self._f0 = np.inf

    def jacobian_assembled(self, A: PETSc.Mat) -> None:
        self._jacobian_norm = A.norm(PETSc.NormType.INFINITY)
        if self._moduli is not None:
            self._moduli.destroy()
            self._moduli = None
        if A.getType() in ("seqaij", "mpiaij"):
            indptr, indices, values = A.getValuesCSR()
            moduli = A.duplicate(copy=False)
            moduli.setValuesCSR(indptr, indices, np.abs(values))
            moduli.assemble()
            self._moduli = moduli

    def floor(self, x: PETSc.Vec) -> float:
        """sqrt(n) ‖|J| |x|‖_∞ times the machine precision, with the last assembled Jacobian J
        (AIJ matrices; else sqrt(n) ‖J‖_∞ ‖x‖_∞)."""
        scale = np.sqrt(x.getSize()) * np.finfo(float).eps
        if self._moduli is None:
            return float(scale * self._jacobian_norm * x.norm(PETSc.NormType.INFINITY))
        x_abs, y = x.copy(), x.duplicate()
        x_abs.abs()
        self._moduli.mult(x_abs, y)
        value = y.norm(PETSc.NormType.INFINITY)
        x_abs.destroy()
        y.destroy()
        return float(scale * value)

    def __call__(self, snes: PETSc.SNES, it: int, norms: tuple) -> int:
        fnorm = norms[2]
        if not np.isfinite(fnorm):
            return PETSc.SNES.ConvergedReason.DIVERGED_FNORM_NAN
        if it == 0:
            self._f0 = fnorm
            if self.force_iteration:
                return PETSc.SNES.ConvergedReason.ITERATING
        self.atol_used = max(self.atol, self.safety * self.floor(snes.getSolution()))
        if fnorm <= self.atol_used:
            return PETSc.SNES.ConvergedReason.CONVERGED_FNORM_ABS
        if it > 0 and fnorm <= self.rtol * self._f0:
            return PETSc.SNES.ConvergedReason.CONVERGED_FNORM_RELATIVE
        return PETSc.SNES.ConvergedReason.ITERATING
