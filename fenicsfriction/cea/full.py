"""Every eigenvalue of :math:`(\\lambda^2 M + \\lambda C + K) w = 0` in a frequency band, on the
full matrices: SLEPc PEP (TOAR, shift-and-invert: MUMPS or Krylov + AMG), or dense QZ for small
systems.

A real-scalar PETSc build cannot take the complex target :math:`i\\omega` at the band's centre:
the shift σ is real. The band's rectangle (:class:`~fenicsfriction.cea.band.Band`, and its
mirror image) lies in the disc :math:`|\\lambda - \\sigma| \\le \\rho` through its farthest
corner; the eigenvalues nearest σ are computed, the number requested doubling until one beyond
ρ has converged, as :meth:`fenicsfriction.stability.StabilitySolver.solve` covers its disc. Then
a SLEPc region (an interval ``[-r, r] × [-ω_max, ω_max]``, symmetric about the real axis as real
arithmetic needs) and ``Im λ >= ω_min`` pick the band's eigenvalues. **Cost**: every eigenvalue
of the disc is computed, also those below the band — a band high in frequency costs as much as
the band from 0 to its top. Modes with :math:`|\\operatorname{Re}\\lambda| > r` (``max_rate``)
are not reported.

Below ``dense_below`` unknowns (or when SLEPc's subspace would not fit in the problem) the
matrices are gathered on every rank and solved by QZ (:mod:`~fenicsfriction.cea.dense`).
PETSc/SLEPc options live under the prefix (default ``cea_``); ``-cea_pep_*``, ``-cea_st_*``
override :data:`DEFAULT_OPTIONS`. The inner solves of shift-and-invert are chosen as the
stability solver's (``inner``; :class:`~fenicsfriction.stability.ShiftInvert`): by AMG, the
multigrid takes K's block size and the near-nullspace attached to K (``K.setNearNullSpace``,
e.g. :func:`fenicsfriction.amg.rigid_body_modes`); matrices read from files have neither, and
"auto" then keeps the LU unless their block size is 3.
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc
from slepc4py import SLEPc

from fenicsfriction import stability
from fenicsfriction.cea.band import Band
from fenicsfriction.cea.dense import dense_modes
from fenicsfriction.cea.matrices import to_dense
from fenicsfriction.laws import check
from fenicsfriction.petsc_options import options_with_defaults
from fenicsfriction.stability import (
    EigenSolveError,
    Mode,
    ShiftInvert,
    choose_inner,
    relative_residual,
)

__all__ = ["DEFAULT_OPTIONS", "BandSolver"]

#: the PEP's defaults: TOAR, shift-and-invert with a MUMPS LU (as the stability solver's)
DEFAULT_OPTIONS = dict(stability.DEFAULT_OPTIONS)

#: the default size up to which the dense QZ solve is used
DENSE_BELOW = 400


class BandSolver:
    """All eigenpairs of a quadratic pencil in a frequency band.

    Args:
        comm: the communicator of the matrices.
        prefix: PETSc options prefix of the PEP (and its ST/KSP/PC).
        options: defaults over :data:`DEFAULT_OPTIONS` (user options in the database win).
        residual_tol: eigenpairs with a larger relative residual are flagged inaccurate.
        dense_below: systems of at most this many unknowns are solved densely.
        max_nev: the most eigenvalues the PEP is asked for; reaching it without covering the
            band raises :class:`~fenicsfriction.stability.EigenSolveError`.
        inner: the inner solves of shift-and-invert, ``"direct"``, ``"amg"`` or ``"auto"``
            (chosen at each solve from the matrices' size and block size, see
            :func:`~fenicsfriction.stability.choose_inner`); options in the database win.

    Attributes:
        pep: the SLEPc PEP, exposed for inspection or further configuration.
        last_method: ``"dense"`` or ``"pep"``, the path of the last solve.
        last_nev: the number of eigenvalues the PEP was last asked for (0 after a dense solve).
        shift_invert: the inner solves; ``shift_invert.path`` the last PEP's, ``"direct"`` or
            ``"amg"``.
    """

    def __init__(self, comm: MPI.Comm, prefix: str = "cea_", options: dict | None = None,
                 residual_tol: float = 1e-8, dense_below: int = DENSE_BELOW,
                 max_nev: int = 2000, inner: str = "auto"):
        check("residual_tol", residual_tol, residual_tol > 0, "must be > 0")
        check("dense_below", dense_below, dense_below >= 0, "must be >= 0")
        choose_inner(inner, 0, 1)  # checks the value
        self.comm, self.residual_tol = comm, residual_tol
        self.dense_below, self.max_nev, self.inner = dense_below, max_nev, inner
        self.pep = SLEPc.PEP().create(comm)
        self.pep.setOptionsPrefix(prefix)
        self.pep.setProblemType(SLEPc.PEP.ProblemType.GENERAL)
        self.pep.setWhichEigenpairs(SLEPc.PEP.Which.TARGET_MAGNITUDE)
        self.shift_invert = ShiftInvert(self.pep.getST())
        self._prefix, self._options = prefix, options or {}
        self._path = "direct" if inner == "auto" else inner
        with options_with_defaults(prefix, self._defaults) as opts:
            self.pep.setFromOptions()
            self._ncv = opts.getInt("pep_ncv", PETSc.DECIDE)
            self.shift_invert.configure(opts, self.pep.getTolerances()[0])
        self.last_method, self.last_nev = "", 0

    def _configure(self, path: str) -> None:
        """The inner solves of the path ``path`` ("auto" resolved at a solve), set anew only
        when it differs from the last (the ST alone: the PEP's options stay)."""
        if path == self._path:
            return
        self._path = path
        with options_with_defaults(self._prefix, self._defaults) as opts:
            self.pep.getST().setFromOptions()
            self.shift_invert.configure(opts, self.pep.getTolerances()[0])

    @property
    def _defaults(self) -> dict:
        return {**DEFAULT_OPTIONS, **ShiftInvert.options(self._path), **self._options}

    def solve(self, M: PETSc.Mat, C: PETSc.Mat, K: PETSc.Mat, band: Band,
              nev: int = 16, shift: float | None = None) -> list[Mode]:
        """The eigenpairs in ``band`` (Im λ >= 0), sorted by frequency.

        Args:
            M, C, K: the distributed PETSc matrices of one size.
            band: the frequencies and largest |Re λ| wanted.
            nev: eigenvalues requested at first; doubled until the band is covered.
            shift: real shift σ (default ``band.rate``: positive, which favours growing modes
                and adds σC + σ²M to the factorised matrix, keeping it regular where K is
                singular).

        Returns:
            The modes, their ``vector`` this rank's owned entries, by increasing Im λ.
        """
        n = K.getSize()[0]
        if n <= self.dense_below or n < 2 * nev:
            self.last_method, self.last_nev = "dense", 0
            return dense_modes(to_dense(M), to_dense(C), to_dense(K), band,
                               self.residual_tol, self.comm)
        self.last_method = "pep"
        shift = band.rate if shift is None else shift
        radius = band.covering_radius(shift)
        self._configure(choose_inner(self.inner, n, K.getBlockSize()))
        self.pep.setOperators([K, C, M])
        # new values: factorise again, or a new multigrid
        self.shift_invert.update(shift, (K, C, M), K.getNearNullSpace())
        self.pep.setTarget(shift)
        while True:
            ncv = PETSc.DECIDE if self._ncv == PETSc.DECIDE else min(max(self._ncv, 2 * nev), n)
            self.pep.setDimensions(nev=min(nev, n), ncv=ncv, mpd=PETSc.DECIDE)
            with options_with_defaults(self._prefix, self._defaults):  # the multigrid's
                self.pep.solve()
            count = self.pep.getConverged()
            reach = max((abs(self.pep.getEigenpair(i) - shift) for i in range(count)),
                        default=0.0)
            covered = reach > radius
            if covered or count >= n or nev >= min(n, self.max_nev):
                break
            nev *= 2
        self.last_nev = nev
        if not covered and count < n:
            raise EigenSolveError(
                f"PEP found {count} eigenvalues, none beyond |λ - {shift:g}| = {radius:g}, with "
                f"{nev} requested (max_nev={self.max_nev}); reason "
                f"{self.pep.getConvergedReason()}")
        return self._band_modes(M, C, K, band, count)

    def _band_modes(self, M: PETSc.Mat, C: PETSc.Mat, K: PETSc.Mat, band: Band,
                    count: int) -> list[Mode]:
        region = SLEPc.RG().create(self.comm)
        region.setType(SLEPc.RG.Type.INTERVAL)
        rate, (low, high) = band.rate, band.omega
        region.setIntervalEndpoints(-rate, rate, -high, high)
        norms = tuple(A.norm(PETSc.NormType.INFINITY) for A in (K, C, M))
        xr, xi = K.createVecs()
        modes = []
        for i in range(count):
            lam = complex(self.pep.getEigenpair(i, xr, xi))
            if lam.imag < low or region.checkInside([lam])[0] < 0:
                continue
            res = relative_residual((K, C, M), norms, lam, xr, xi)
            modes.append(Mode(value=lam, residual=res, accurate=res <= self.residual_tol,
                              vector=xr.getArray() + 1j * xi.getArray()))
        for obj in (xr, xi, region):
            obj.destroy()
        return sorted(modes, key=lambda m: (m.value.imag, m.value.real))
