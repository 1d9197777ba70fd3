"""MUMPS's Schur complement (ICNTL(19)) through the three PETSc calls petsc4py does not wrap:
``MatFactorSetSchurIS``, ``MatFactorGetSchurComplement`` and
``MatFactorRestoreSchurComplement``, called with ctypes in the PETSc library petsc4py itself
runs on (found through petsc4py's own extension module, so the versions always match).

With the Schur indices set before the factorisation, MUMPS eliminates every other unknown and
leaves the dense Schur complement S = A_ΓΓ − A_ΓI A_II⁻¹ A_IΓ as a by-product of one
factorisation, instead of one solve per interface unknown. A solve with the factor (serial
only, PETSc's restriction) then condenses the right-hand side onto Γ, solves with whatever dense
matrix S holds (factorised by PETSc when the view is restored as unfactored) and expands: one
forward and one backward sweep for the whole system.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import typing

from petsc4py import PETSc

import numpy as np

__all__ = ["available", "schur_complement", "set_schur_indices"]

_UNFACTORED = 0  # MAT_FACTOR_SCHUR_UNFACTORED


@functools.cache
def _library() -> ctypes.CDLL | None:
    """The PETSc library petsc4py's extension module links (its symbols resolve through it)."""
    try:
        library = ctypes.CDLL(PETSc.__file__)
        for name in ("MatFactorSetSchurIS", "MatFactorGetSchurComplement",
                     "MatFactorRestoreSchurComplement", "MatDenseGetArray",
                     "MatDenseRestoreArray", "MatGetLocalSize"):
            getattr(library, name)
    except (OSError, AttributeError):
        return None
    return library


def available() -> bool:
    """Whether the PETSc calls could be found (else callers form the complement by solves)."""
    return _library() is not None


def _call(name: str, *args: typing.Any) -> None:
    library = _library()
    assert library is not None, "check available() first"
    code = getattr(library, name)(*args)
    if code:
        raise PETSc.Error(code)


def set_schur_indices(factor: PETSc.Mat, indices: PETSc.IS) -> None:
    """Ask the factor for the Schur complement on ``indices`` (global numbering); call before
    the factorisation. In parallel PETSc requires every index on rank 0 (a centralised S)."""
    _call("MatFactorSetSchurIS", ctypes.c_void_p(factor.handle), ctypes.c_void_p(indices.handle))


@contextlib.contextmanager
def schur_complement(factor: PETSc.Mat) -> typing.Iterator[np.ndarray]:
    """A writable view (|Γ| × |Γ|, on the rank that holds it; empty elsewhere) of the Schur
    complement the factor holds. On exit it is handed back as unfactored, so that the next
    solve with the factor factorises whatever the view then holds."""
    schur, status = ctypes.c_void_p(), ctypes.c_int()
    _call("MatFactorGetSchurComplement", ctypes.c_void_p(factor.handle), ctypes.byref(schur),
          ctypes.byref(status))
    integer = ctypes.c_int64 if np.dtype(PETSc.IntType).itemsize == 8 else ctypes.c_int32
    rows, columns = integer(), integer()
    _call("MatGetLocalSize", schur, ctypes.byref(rows), ctypes.byref(columns))
    n = rows.value
    data = ctypes.POINTER(ctypes.c_double)()
    _call("MatDenseGetArray", schur, ctypes.byref(data))
    try:
        view = (np.ctypeslib.as_array(data, shape=(n * n,)).reshape((n, n), order="F")
                if n else np.empty((0, 0)))
        yield view
    finally:
        _call("MatDenseRestoreArray", schur, ctypes.byref(data))
        _call("MatFactorRestoreSchurComplement", ctypes.c_void_p(factor.handle),
              ctypes.byref(schur), ctypes.c_int(_UNFACTORED))
