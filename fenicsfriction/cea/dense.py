"""Dense quadratic eigenproblems: every eigenpair of :math:`(\\lambda^2 M + \\lambda C + K) w = 0`
by the QZ algorithm on a companion linearisation.

For small systems (a few hundred unknowns) and for the projected problems of modal CEA
(:mod:`~fenicsfriction.cea.projection`). The first companion form

.. math:: \\begin{bmatrix} 0 & I \\\\ -K & -C \\end{bmatrix} z
          = \\lambda \\begin{bmatrix} I & 0 \\\\ 0 & M \\end{bmatrix} z, \\qquad
          z = \\begin{bmatrix} w \\\\ \\lambda w \\end{bmatrix}

is solved by :func:`scipy.linalg.eig` (LAPACK's ``ggev``); infinite eigenvalues (a singular M)
are dropped. The eigenvector is read from the half of z that carries it best (w for |λ| <= 1,
λw / λ above), and every pair gets the relative residual of :mod:`fenicsfriction.stability`
(matrix ∞-norms, vector 2-norms). The cost is :math:`O((2n)^3)`: about a second at n = 400.
"""

from __future__ import annotations

from mpi4py import MPI

import numpy as np
import scipy.linalg

from fenicsfriction.cea.band import Band
from fenicsfriction.stability import Mode

__all__ = ["dense_modes", "quadratic_eig", "relative_residuals"]


def quadratic_eig(M: np.ndarray, C: np.ndarray, K: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Every finite eigenpair of the dense quadratic pencil.

    Args:
        M, C, K: real or complex n × n arrays.

    Returns:
        ``(values, vectors)``: the finite eigenvalues and, in the columns of ``vectors``
        (n × count), their eigenvectors of unit 2-norm.
    """
    n = K.shape[0]
    zero, eye = np.zeros((n, n)), np.eye(n)
    values, z = scipy.linalg.eig(np.block([[zero, eye], [-K, -C]]),
                                 np.block([[eye, zero], [zero, M]]))
    finite = np.isfinite(values)
    values, z = values[finite], z[:, finite]
    small = np.abs(values) <= 1
    vectors = np.where(small, z[:n], z[n:] / np.where(small, 1.0, values))
    vectors /= np.linalg.norm(vectors, axis=0)
    return values, vectors


def relative_residuals(M: np.ndarray, C: np.ndarray, K: np.ndarray, values: np.ndarray,
                       vectors: np.ndarray) -> np.ndarray:
    """:math:`\\|(\\lambda^2 M + \\lambda C + K) w\\| / ((|\\lambda|^2\\|M\\|_\\infty +
    |\\lambda|\\|C\\|_\\infty + \\|K\\|_\\infty)\\|w\\|)` of each pair (columns of ``vectors``)."""
    residual = (M @ vectors) * values**2 + (C @ vectors) * values + K @ vectors
    norms = [np.linalg.norm(A, np.inf) for A in (M, C, K)]
    modulus = np.abs(values)
    scale = (modulus**2 * norms[0] + modulus * norms[1] + norms[2]) \
        * np.linalg.norm(vectors, axis=0)
    return np.linalg.norm(residual, axis=0) / scale


def dense_modes(M: np.ndarray, C: np.ndarray, K: np.ndarray, band: Band | None = None,
                residual_tol: float = 1e-8, comm: MPI.Comm | None = None) -> list[Mode]:
    """The eigenpairs with Im λ >= 0 (and in ``band`` if given), sorted by frequency.

    Args:
        M, C, K: the dense matrices (every rank holds all of them).
        band: keep only the eigenvalues it contains (:meth:`Band.contains`).
        residual_tol: pairs with a larger relative residual are flagged inaccurate.
        comm: when given, each mode's ``vector`` holds only this rank's rows in PETSc's
            default row layout (as :attr:`Mode.vector` of a distributed solve); else all.

    Returns:
        The modes, by increasing Im λ then Re λ.
    """
    values, vectors = quadratic_eig(M, C, K)
    keep = values.imag >= 0
    if band is not None:
        keep &= np.array([band.contains(v) for v in values], dtype=bool)
    values, vectors = values[keep], vectors[:, keep]
    residuals = relative_residuals(M, C, K, values, vectors)
    rows = slice(None)
    if comm is not None:
        n = K.shape[0]
        # PETSc's default layout: the first n % size ranks hold one row more
        counts = [n // comm.size + (r < n % comm.size) for r in range(comm.size)]
        start = sum(counts[:comm.rank])
        rows = slice(start, start + counts[comm.rank])
    modes = [Mode(value=complex(v), residual=float(r), accurate=bool(r <= residual_tol),
                  vector=np.ascontiguousarray(vectors[rows, i]))
             for i, (v, r) in enumerate(zip(values, residuals, strict=True))]
    return sorted(modes, key=lambda m: (m.value.imag, m.value.real))
