"""Matrices of a complex eigenvalue analysis from files, as distributed PETSc matrices, and the
pencil they make along a parameter.

Three formats are read: MatrixMarket (``.mtx``, :func:`scipy.io.mmread`), MATLAB (``.mat``,
:func:`scipy.io.loadmat`: the variable named, or the only matrix in the file) and PETSc's binary
format (any other suffix, read by PETSc itself, already distributed). MatrixMarket and MATLAB
files are read whole on every rank (a shared file system is assumed), each rank keeping its
block of rows of the CSR matrix, PETSc's default row layout; the same layout for every matrix
of one size, so that they can be added. Every matrix must be square, real and finite; every
matrix of a pencil the same size.

A :class:`ParametricPencil` is the family :math:`M,\\ C(p) = C_0 + p C_1,\\ K(p) = K_0 + p K_1
+ p^2 K_2` of a parameter p (a friction coefficient, a pressure, a speed), any part but M and
K_0 optional.
"""

from __future__ import annotations

import dataclasses
import pathlib
import typing

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import scipy.io
import scipy.sparse

from fenicsfriction.laws import check

__all__ = ["ParametricPencil", "from_array", "read_matrix", "to_dense"]

#: suffixes read by SciPy; every other file is read as PETSc binary
SCIPY_SUFFIXES = (".mtx", ".mat")


def from_array(A: np.ndarray | scipy.sparse.spmatrix, comm: MPI.Comm = MPI.COMM_WORLD,
               name: str = "matrix") -> PETSc.Mat:
    """A distributed PETSc AIJ matrix from a dense or sparse array known on every rank.

    Args:
        A: the matrix (every rank holds all of it); square, real and finite.
        comm: the communicator of the result.
        name: how errors name the matrix (a flag, a file).

    Returns:
        The matrix with PETSc's default row layout, each rank its rows.
    """
    csr = scipy.sparse.csr_matrix(A)
    check(name, f"{csr.shape[0]}x{csr.shape[1]}", csr.shape[0] == csr.shape[1],
          "must be a square matrix")
    check(name, f"a matrix of {csr.dtype}", not np.iscomplexobj(csr.data),
          "must be real (the PETSc build uses real scalars)")
    csr = csr.astype(PETSc.ScalarType)
    check(name, "a matrix with NaN or infinite entries", bool(np.isfinite(csr.data).all()),
          "all entries must be finite")
    n = csr.shape[0]
    layout = PETSc.Vec().createMPI((PETSc.DECIDE, n), comm=comm)
    start, end = layout.getOwnershipRange()
    layout.destroy()
    rows = csr[start:end]
    rows.sort_indices()
    mat = PETSc.Mat().createAIJ(size=((end - start, n), (end - start, n)),
                                csr=(rows.indptr.astype(PETSc.IntType),
                                     rows.indices.astype(PETSc.IntType), rows.data), comm=comm)
    mat.assemble()
    return mat


def _scipy_matrix(path: pathlib.Path, name: str, variable: str | None
                  ) -> np.ndarray | scipy.sparse.spmatrix:
    """The matrix in a MatrixMarket or MATLAB file (every rank reads it)."""
    if path.suffix == ".mtx":
        return scipy.io.mmread(str(path))
    contents = {k: v for k, v in scipy.io.loadmat(str(path)).items() if not k.startswith("__")}
    matrices = sorted(k for k, v in contents.items()
                      if scipy.sparse.issparse(v) or getattr(v, "ndim", 0) == 2)
    if variable is not None:
        check(name, f"{path}:{variable}", variable in matrices,
              f"the file's matrices are {', '.join(matrices) or 'none'}")
        return contents[variable]
    check(name, str(path), len(matrices) == 1,
          f"holds {len(matrices)} matrices ({', '.join(matrices)}): name one as FILE:VARIABLE")
    return contents[matrices[0]]


def read_matrix(path: str | pathlib.Path, comm: MPI.Comm = MPI.COMM_WORLD,
                name: str | None = None) -> PETSc.Mat:
    """A matrix file as a distributed PETSc AIJ matrix.

    Args:
        path: a ``.mtx`` (MatrixMarket) or ``.mat`` (MATLAB) file, or any other name for PETSc
            binary. A MATLAB file holding several matrices needs the variable:
            ``file.mat:K``.
        comm: the communicator of the result.
        name: how errors name the matrix (default: the path), e.g. the flag ``--K``.

    Raises:
        ValueError: one line, ``name='path' is invalid: ...``, when the file is missing,
            unreadable, not square, complex or not finite.
    """
    text = str(path)
    variable = None
    if ".mat:" in text:
        text, variable = text.rsplit(":", 1)
    file = pathlib.Path(text)
    name = name or text
    check(name, str(path), file.is_file(), "no such file")
    if file.suffix in SCIPY_SUFFIXES:
        try:
            array = _scipy_matrix(file, name, variable)
        except (OSError, ValueError, TypeError) as err:
            if str(err).startswith(f"{name}="):
                raise
            raise ValueError(f"{name}={str(path)!r} is invalid: cannot be read as "
                             f"{file.suffix} ({err})") from None
        return from_array(array, comm, name)
    viewer = PETSc.Viewer().createBinary(text, "r", comm=comm)
    mat = PETSc.Mat().create(comm)
    mat.setType(PETSc.Mat.Type.AIJ)
    try:
        mat.load(viewer)
    except PETSc.Error:
        raise ValueError(f"{name}={str(path)!r} is invalid: not a PETSc binary matrix "
                         f"(suffixes .mtx and .mat are read by SciPy)") from None
    finally:
        viewer.destroy()
    rows, cols = mat.getSize()
    check(name, f"{rows}x{cols}", rows == cols, "must be a square matrix")
    _, _, values = mat.getValuesCSR()
    finite = comm.allreduce(bool(np.isfinite(values).all()), op=MPI.LAND)
    check(name, "a matrix with NaN or infinite entries", finite, "all entries must be finite")
    return mat


def to_dense(A: PETSc.Mat) -> np.ndarray:
    """The whole matrix as a dense array on every rank (for small and projected problems)."""
    n = A.getSize()[0]
    start, end = A.getOwnershipRange()
    indptr, indices, values = A.getValuesCSR()
    local = scipy.sparse.csr_matrix((values, indices, indptr), shape=(end - start, n)).toarray()
    return np.vstack(A.getComm().tompi4py().allgather(local))


def _sum(terms: list[tuple[float, PETSc.Mat]]) -> PETSc.Mat:
    """Σ coefficient · matrix, a new matrix (sparsity patterns may differ)."""
    (first, A), *rest = terms
    total = A.copy()
    total.scale(first)
    for coefficient, B in rest:
        total.axpy(coefficient, B, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    return total


@dataclasses.dataclass
class ParametricPencil:
    """The pencil :math:`\\lambda^2 M + \\lambda C(p) + K(p)`, :math:`C(p) = C_0 + p C_1`,
    :math:`K(p) = K_0 + p K_1 + p^2 K_2` (distributed PETSc matrices of one size and layout).

    Attributes:
        M: the mass matrix.
        K0: the stiffness at p = 0.
        C0, C1, K1, K2: the other parts, None where absent (C = 0 when C0 and C1 are).
    """

    M: PETSc.Mat
    K0: PETSc.Mat
    C0: PETSc.Mat | None = None
    C1: PETSc.Mat | None = None
    K1: PETSc.Mat | None = None
    K2: PETSc.Mat | None = None

    def __post_init__(self) -> None:
        size = self.M.getSize()
        for name, A in self.parts().items():
            check(name, "x".join(map(str, A.getSize())), A.getSize() == size,
                  f"must have the size of M, {size[0]}x{size[1]}")

    def parts(self) -> dict[str, PETSc.Mat]:
        """The matrices given, by name (``M``, ``C0``, ``C1``, ``K0``, ``K1``, ``K2``)."""
        names = ("M", "C0", "C1", "K0", "K1", "K2")
        return {n: getattr(self, n) for n in names if getattr(self, n) is not None}

    @classmethod
    def read(cls, paths: typing.Mapping[str, str | pathlib.Path],
             comm: MPI.Comm = MPI.COMM_WORLD, flags: dict[str, str] | None = None
             ) -> ParametricPencil:
        """The pencil from files (:func:`read_matrix`), ``paths`` keyed by part name (``M``,
        ``K0``, ...); ``flags[name]`` names a part in errors (default: the part's name)."""
        flags = flags or {}
        return cls(**{name: read_matrix(path, comm, flags.get(name, name))
                      for name, path in paths.items()})

    @property
    def size(self) -> int:
        """The number of unknowns."""
        return int(self.M.getSize()[0])

    @property
    def comm(self) -> MPI.Comm:
        """The matrices' communicator."""
        return self.M.getComm().tompi4py()

    def at(self, p: float) -> tuple[PETSc.Mat, PETSc.Mat, PETSc.Mat]:
        """New matrices ``(M, C(p), K(p))``; M is the pencil's own, C and K are new."""
        stiffness = [(1.0, self.K0)] + [(c, A) for c, A in ((p, self.K1), (p * p, self.K2))
                                        if A is not None]
        damping = [(c, A) for c, A in ((1.0, self.C0), (p, self.C1)) if A is not None]
        C = _sum(damping) if damping else self.M.duplicate(copy=False)
        if not damping:
            C.zeroEntries()
            C.assemble()
        return self.M, C, _sum(stiffness)
