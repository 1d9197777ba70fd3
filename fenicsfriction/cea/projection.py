"""Modal complex eigenvalue analysis: the quadratic eigenproblem projected on the real modes of
the symmetric, frictionless problem (what brake codes call modal CEA, ANSYS's QRDAMP).

The basis Φ holds the m lowest modes of :math:`K_s \\phi = \\omega^2 M \\phi` (SLEPc EPS, GHEP,
shift-and-invert with a MUMPS LU, or with CG preconditioned by GAMG: ``inner``, chosen as the
stability solver's, :class:`~fenicsfriction.stability.ShiftInvert`, the multigrid taking K's
block size and the near-nullspace attached to K), :math:`K_s` the symmetric part of the
stiffness, normalised
:math:`\\Phi^T M \\Phi = I`. Each pencil of a parameter sweep is then projected,
:math:`\\Phi^T A \\Phi` (m × m, replicated on every rank), solved densely
(:mod:`~fenicsfriction.cea.dense`) and its eigenvectors lifted back, :math:`w = \\Phi q`; the
residual of each pair is measured against the full matrices, so a basis too small shows in the
residuals. The basis is computed once and reused at every point of a sweep: one sparse
factorisation in all instead of one per point. Its error is that of a Galerkin projection: the
eigenvalues converge as modes above the band are added (see the benchmark ``bench_cea``).
PETSc/SLEPc options live under the prefix (default ``cea_basis_``).
"""

from __future__ import annotations

import math

from petsc4py import PETSc
from slepc4py import SLEPc

import numpy as np

from fenicsfriction.cea.band import Band
from fenicsfriction.cea.dense import quadratic_eig
from fenicsfriction.laws import check
from fenicsfriction.petsc_options import options_with_defaults
from fenicsfriction.stability import (
    EigenSolveError,
    Mode,
    ShiftInvert,
    choose_inner,
    relative_residual,
)

__all__ = ["DEFAULT_OPTIONS", "ModalBasis", "symmetric_part"]

#: the EPS's defaults: Krylov-Schur, shift-and-invert with a MUMPS LU
DEFAULT_OPTIONS = {
    "eps_type": "krylovschur",
    "eps_tol": 1e-10,
    "st_type": "sinvert",
    "st_ksp_type": "preonly",
    "st_pc_type": "lu",
    "st_pc_factor_mat_solver_type": "mumps",
}


def symmetric_part(K: PETSc.Mat) -> PETSc.Mat:
    """:math:`(K + K^T)/2`, a new matrix (with K's near-nullspace, for a multigrid)."""
    Ks = K.transpose(PETSc.Mat())
    Ks.axpy(1.0, K, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    Ks.scale(0.5)
    near_nullspace = K.getNearNullSpace()
    if near_nullspace is not None and near_nullspace.handle:
        Ks.setNearNullSpace(near_nullspace)
    return Ks


class ModalBasis:
    """The real modes of :math:`(K_s, M)`: a number of them, or all below a frequency.

    Args:
        K: the symmetric stiffness :math:`K_s` (:func:`symmetric_part` of an unsymmetric one).
        M: the mass matrix (symmetric, positive semi-definite).
        modes: how many modes (the lowest).
        max_frequency: or every mode below this frequency [Hz] (``modes`` is then the first
            request, doubled until one mode above it has converged).
        shift: target σ of shift-and-invert [rad²/s²]; K - σM is factorised, so a negative
            σ keeps it regular when K_s is singular (free bodies).
        prefix: PETSc options prefix of the EPS (and its ST/KSP/PC).
        options: defaults over :data:`DEFAULT_OPTIONS` (user options in the database win).
        inner: the inner solves of shift-and-invert, ``"direct"``, ``"amg"`` (CG + GAMG on
            K - σM, positive definite for σ below the lowest mode) or ``"auto"``
            (:func:`~fenicsfriction.stability.choose_inner`).

    Attributes:
        eps: the SLEPc EPS used.
        shift_invert: its inner solves; ``shift_invert.path`` is ``"direct"`` or ``"amg"``.
        omega2: the eigenvalues ω² [rad²/s²] of the modes, increasing.
        phi: this rank's rows of Φ (n_local × m), M-orthonormal columns.
    """

    def __init__(self, K: PETSc.Mat, M: PETSc.Mat, modes: int | None = None,
                 max_frequency: float | None = None, shift: float = 0.0,
                 prefix: str = "cea_basis_", options: dict | None = None,
                 inner: str = "auto"):
        check("modes", modes, modes is not None or max_frequency is not None,
              "give a number of modes or a max_frequency")
        if modes is not None:
            check("modes", modes, modes >= 1, "must be >= 1")
        if max_frequency is not None:
            check("max_frequency", max_frequency, max_frequency > 0, "must be > 0")
        self.comm = K.getComm().tompi4py()
        n = K.getSize()[0]
        self.eps = SLEPc.EPS().create(self.comm)
        self.eps.setOptionsPrefix(prefix)
        self.eps.setOperators(K, M)
        self.eps.setProblemType(SLEPc.EPS.ProblemType.GHEP)
        self.eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
        self.eps.setTarget(shift)
        path = choose_inner(inner, n, K.getBlockSize())
        self.shift_invert = ShiftInvert(self.eps.getST())
        defaults = {**DEFAULT_OPTIONS, **ShiftInvert.options(path, symmetric=True),
                    **(options or {})}
        with options_with_defaults(prefix, defaults) as opts:
            self.eps.setFromOptions()
            self.shift_invert.configure(opts, self.eps.getTolerances()[0])
        self.shift_invert.update(-shift, (K, M), K.getNearNullSpace())
        request = min(modes or 16, n)
        limit = math.inf if max_frequency is None else (2 * math.pi * max_frequency) ** 2
        while True:
            # ncv and mpd given each time: slepc4py >= 3.20 keeps the previous ones otherwise
            self.eps.setDimensions(nev=request, ncv=PETSc.DECIDE, mpd=PETSc.DECIDE)
            with options_with_defaults(prefix, defaults):  # the multigrid's level options
                self.eps.solve()
            count = self.eps.getConverged()
            values = sorted(self.eps.getEigenvalue(i).real for i in range(count))
            enough = count >= request if max_frequency is None else \
                bool(values) and values[-1] > limit
            if enough or request >= n:
                break
            request = min(2 * request, n)
        if not enough and count < min(request, n):
            raise EigenSolveError(f"EPS found {count} of {request} modes; reason "
                                  f"{self.eps.getConvergedReason()}")
        order = sorted(range(count), key=lambda i: self.eps.getEigenvalue(i).real)
        if max_frequency is None:
            order = order[:modes]
        else:
            order = [i for i in order if self.eps.getEigenvalue(i).real <= limit]
        self.omega2 = np.array([self.eps.getEigenvalue(i).real for i in order])
        x, mx = M.createVecs()
        columns = []
        for i in order:
            self.eps.getEigenvector(i, x)
            M.mult(x, mx)
            x.scale(1.0 / math.sqrt(x.dot(mx)))
            columns.append(x.getArray().copy())
        local = x.getLocalSize()
        x.destroy()
        mx.destroy()
        self.phi = np.column_stack(columns) if columns else np.zeros((local, 0))

    @property
    def size(self) -> int:
        """The number of modes m."""
        return self.phi.shape[1]

    @property
    def frequencies(self) -> np.ndarray:
        """The modes' frequencies [Hz]."""
        return np.sqrt(np.maximum(self.omega2, 0.0)) / (2 * math.pi)

    def truncated(self, modes: int) -> ModalBasis:
        """The basis of the first ``modes`` modes (no new solve; shares the EPS)."""
        check("modes", modes, 1 <= modes <= self.size, f"must be in [1, {self.size}]")
        basis = object.__new__(ModalBasis)
        basis.comm, basis.eps = self.comm, self.eps
        basis.omega2, basis.phi = self.omega2[:modes], self.phi[:, :modes]
        return basis

    def project(self, A: PETSc.Mat) -> np.ndarray:
        """:math:`\\Phi^T A \\Phi`, dense m × m, the same on every rank (A Φ in one sparse ×
        dense product, then this rank's rows of Φᵀ (AΦ), summed over the ranks)."""
        rows, n = A.getLocalSize()[0], A.getSize()[0]
        phi = PETSc.Mat().createDense(size=((rows, n), (PETSc.DECIDE, self.size)),
                                      array=np.asfortranarray(self.phi), comm=A.getComm())
        product = A.matMult(phi)
        local = self.phi.T @ product.getDenseArray()
        for obj in (product, phi):
            obj.destroy()
        return self.comm.allreduce(local)

    def solve(self, M: PETSc.Mat, C: PETSc.Mat, K: PETSc.Mat, band: Band | None = None,
              residual_tol: float = 1e-8) -> list[Mode]:
        """The projected quadratic eigenproblem's pairs (Im λ >= 0, in ``band`` if given).

        Args:
            M, C, K: the full distributed matrices (K unsymmetric in general).
            band: keep only the eigenvalues it contains.
            residual_tol: pairs whose residual against the full matrices is larger are flagged
                inaccurate.

        Returns:
            The modes, their ``vector`` this rank's owned entries of Φq, by increasing Im λ.
        """
        values, q = quadratic_eig(self.project(M), self.project(C), self.project(K))
        keep = [i for i, v in enumerate(values)
                if v.imag >= 0 and (band is None or band.contains(v))]
        norms = tuple(A.norm(PETSc.NormType.INFINITY) for A in (K, C, M))
        xr, xi = K.createVecs()
        modes = []
        for i in keep:
            w = self.phi @ q[:, i]
            xr.setArray(w.real)
            xi.setArray(w.imag)
            lam = complex(values[i])
            res = relative_residual((K, C, M), norms, lam, xr, xi)
            modes.append(Mode(value=lam, residual=res, accurate=res <= residual_tol, vector=w))
        xr.destroy()
        xi.destroy()
        return sorted(modes, key=lambda m: (m.value.imag, m.value.real))
