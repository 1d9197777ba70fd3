r"""Problem 3, stability of steady sliding: :math:`(\lambda^2 M + \lambda C + \bar K) w = 0`.

The operators are the Gateaux derivatives of the one residual at the steady state
:math:`(u_0, 0, 0)` (:meth:`Residual.linearisation`); :math:`\bar K` is not symmetric: friction
couples normal displacement into tangential force (Martins & Oden 1986, eq. 31). Re λ > 0 means the
steady sliding is dynamically unstable.

SLEPc PEP (TOAR) with shift-and-invert about a real shift σ > 0 computes the eigenvalues
nearest σ; the number requested grows until every eigenvalue with
:math:`|\lambda| \le \omega_{max}` has been found, so all modes whose frequency and growth rate
lie in that disc — those that can go unstable in the band of interest — are caught. In the real
PETSc build, complex eigenvalues come in conjugate pairs; only Im λ >= 0 is kept. Each
eigenpair carries its relative residual

.. math:: \frac{\|(\lambda^2 M + \lambda C + \bar K) w\|}
               {(|\lambda|^2\|M\|_\infty + |\lambda|\|C\|_\infty + \|\bar K\|_\infty)\|w\|}

and is flagged when that exceeds ``residual_tol``. Dirichlet dofs have 1 on the diagonal of
:math:`\bar K` and 0 in M and C, so their eigenvalues are infinite and never near the shift.
PETSc/SLEPc options live under the prefix (default ``stability_``).

**The inner solves** of shift-and-invert, with :math:`P(\sigma) = \sigma^2 M + \sigma C + \bar K`
(the matrix SLEPc's spectral transformation assembles), are chosen by ``inner``:
``"direct"`` factorises it (MUMPS LU, then one triangular solve per Krylov step of TOAR);
``"amg"`` solves it by GMRES preconditioned by PETSc's GAMG, built on a copy of
:math:`P(\sigma)` that carries the block size and the rigid-body near-nullspace
(:func:`fenicsfriction.amg.rigid_body_modes`); ``"auto"`` takes AMG for 3D problems of more
than :data:`AMG_ABOVE_3D` unknowns, where the LU's fill (memory ~ n^{4/3}) stops fitting, and
the LU otherwise: where both fit, the LU is an order of magnitude cheaper, since TOAR needs
~50 inner solves each to 1e-12 (docs/benchmarks.md, "Eigenvalues at scale"). TOAR's Krylov
basis is only as accurate as the inner solves, so their relative tolerance is tied to the
eigen tolerance, ``st_ksp_rtol`` = :data:`INNER_RTOL_FACTOR` × ``pep_tol``, and every
returned pair's residual is measured against the full operators. The residual is a backward
error: it flags the pairs an inner solve too loose has spoiled where the eigenvalue is well
conditioned (the flutter pair of the block at 1e-4), but a badly conditioned one (the block's
soft-spring mode: 40 % off at 1e-4 with a residual of 1e-9) can pass it, so the inner
tolerance, not the check, is the safeguard and should not be loosened.
Any option set in the PETSc database (``-stability_st_pc_type hypre``, ``-stability_st_ksp_rtol
...``) overrides these choices.

**The friction switch** of complex eigenvalue analysis: ``friction_stiffness=False`` drops the
friction part of :math:`\bar K` (the derivative of the friction force with respect to the
displacement, which couples normal displacement into tangential force and alone makes
:math:`\bar K` unsymmetric), ``friction_damping=False`` the friction part of C (the derivative
with respect to the velocity, negative where μ falls with the slip speed). Both are assembled
at the same steady state with the friction constant of the residual
(:attr:`fenicsfriction.forms.Residual.friction`, e.g. the constant μ) set to zero: the friction
terms are linear in it, so the result is exactly the operator less its friction part, for the
integrals and for node-to-segment couplings alike. An instability that survives without the
friction stiffness is not mode coupling; one that disappears without the friction damping is
negative damping (the distinction of Abaqus's and ANSYS's complex eigenvalue analyses);
beware that a small non-proportional damping can itself destabilise a coupling pair below its
coalescence (Hoffmann & Gaul 2003), so the onset with the damping may lie below both.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import typing

from mpi4py import MPI
from petsc4py import PETSc
from slepc4py import SLEPc

import dolfinx.fem.petsc
import numpy as np
import scipy.optimize

from fenicsfriction import _compat
from fenicsfriction.amg import amg_options, rigid_body_modes, uses_amg
from fenicsfriction.assembly import (
    BulkWatcher,
    CoupledMatrix,
    assemble_jacobian,
    split_constant,
)
from fenicsfriction.coupling import CouplingOperator
from fenicsfriction.forms import Residual
from fenicsfriction.laws import check
from fenicsfriction.numerics import bisect
from fenicsfriction.petsc_options import options_with_defaults
from fenicsfriction.results import Record

__all__ = ["AMG_ABOVE_3D", "AMG_OPTIONS", "INNER_RTOL_FACTOR", "EigenSolveError", "Eigensolver",
           "Loci", "Mode", "Onset", "ShiftInvert", "StabilitySolver", "choose_inner", "mac",
           "relative_residual", "track", "unstable_intervals"]

DEFAULT_OPTIONS = {
    "pep_type": "toar",
    "pep_tol": 1e-10,
    "pep_max_it": 1000,
    "pep_scale": "scalar",
    "st_type": "sinvert",
    "st_ksp_type": "preonly",
    "st_pc_type": "lu",
    "st_pc_factor_mat_solver_type": "mumps",
}

#: the spectral transformation's inner solve by Krylov + AMG (over :data:`DEFAULT_OPTIONS`):
#: the steady solvers' AMG path (:func:`fenicsfriction.amg.amg_options`: GMRES, as P(σ) is not
#: symmetric with friction, preconditioned by GAMG with Chebyshev/Jacobi smoothing) under the
#: ST's prefix, with room for the tighter inner tolerance. GAMG's level options are read when
#: it is set up, at the solve: the solvers keep these defaults in the database through it.
#: (SOR smoothing took 0.55x the CPU time on the 3D block at 5,967 unknowns but met a singular
#: diagonal block at 42,075.)
AMG_OPTIONS = {f"st_{key}": value for key, value in amg_options(3).items()
               if key not in ("ksp_rtol", "ksp_max_it")} | {"st_ksp_max_it": 5000}

#: the inner solves' relative tolerance is this times the eigen tolerance (``pep_tol``,
#: ``eps_tol``) unless ``st_ksp_rtol`` is set
INNER_RTOL_FACTOR = 1e-2

#: ``inner="auto"`` solves 3D problems above this many unknowns by AMG (2D always by LU): on
#: the 3D block the LU path took 13-18x less CPU time where both ran (6e3-4e4 unknowns), and
#: its stage's peak memory, 4.4 GiB at 135,975, reaches 24 GiB near 4.9e5 if it grows like
#: n^(4/3) (docs/benchmarks.md, "Eigenvalues at scale"): AMG only where the LU may not fit
AMG_ABOVE_3D = 400_000

def choose_inner(inner: str, size: int, block_size: int) -> str:
    """``"direct"`` or ``"amg"``: ``inner`` itself, or for ``"auto"`` AMG on 3D problems
    (``block_size`` 3) of more than :data:`AMG_ABOVE_3D` unknowns (``size``)."""
    check("inner", inner, inner in ("auto", "direct", "amg"), "must be auto, direct or amg")
    if inner != "auto":
        return inner
    return "amg" if block_size == 3 and size > AMG_ABOVE_3D else "direct"


class ShiftInvert:
    """The inner solves of a SLEPc spectral transformation with shift-and-invert (module
    docstring, "The inner solves"): the options of the chosen path and, for a multigrid
    preconditioner, the matrix it is built from with its block size and near-nullspace.

    Args:
        st: the ST of a PEP or EPS (its options prefix set).

    Attributes:
        preconditioner: the matrix the multigrid was last built from (None without one).
    """

    def __init__(self, st: SLEPc.ST):
        self.st = st
        self.preconditioner: PETSc.Mat | None = None

    @staticmethod
    def options(inner: str, symmetric: bool = False) -> dict:
        """The options of a path (``"direct"`` or ``"amg"``) over :data:`DEFAULT_OPTIONS`; CG
        for a symmetric positive definite shifted matrix."""
        if inner != "amg":
            return {}
        if not symmetric:
            return AMG_OPTIONS
        return {**{f"st_{key}": value for key, value in amg_options(3, symmetric=True).items()
                   if key not in ("ksp_rtol", "ksp_max_it")}, "st_ksp_max_it": 5000}

    def configure(self, opts: PETSc.Options, eigen_tol: float) -> None:
        """After ``setFromOptions``: the inner relative tolerance :data:`INNER_RTOL_FACTOR` ×
        ``eigen_tol`` unless ``st_ksp_rtol`` is set in ``opts`` (the solver's prefix)."""
        if self.multigrid and not opts.hasName("st_ksp_rtol"):
            self.st.getKSP().setTolerances(rtol=INNER_RTOL_FACTOR * eigen_tol)

    @property
    def multigrid(self) -> bool:
        """Whether the inner preconditioner is a multigrid (else a factorisation or other)."""
        return uses_amg(self.st.getKSP())

    @property
    def path(self) -> str:
        """``"amg"`` (a multigrid preconditioner) or ``"direct"``."""
        return "amg" if self.multigrid else "direct"

    def update(self, shift: float, operators: typing.Sequence[PETSc.Mat],
               near_nullspace: PETSc.NullSpace | None) -> None:
        """Before a solve with new values: a new factorisation, or for a multigrid the matrix
        :math:`\\sum_k s^k A_k` of ``operators`` (lowest degree first; s = ``shift``) with
        the first one's block size and ``near_nullspace``, as the preconditioning matrix
        (SLEPc assembles its own copy as the operator, without them)."""
        pc = self.st.getKSP().getPC()
        pc.reset()
        if not self.multigrid:
            return
        if self.preconditioner is not None:
            self.preconditioner.destroy()
        P = operators[0].copy()
        for k, A in enumerate(operators[1:], start=1):
            P.axpy(shift**k, A, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        if near_nullspace is not None:
            P.setNearNullSpace(near_nullspace)
        self.preconditioner = P
        self.st.setPreconditionerMat(P)

    def destroy(self) -> None:
        """Free the preconditioning matrix (collective)."""
        if self.preconditioner is not None:
            self.preconditioner.destroy()
            self.preconditioner = None


class EigenSolveError(RuntimeError):
    """The PEP could not cover the requested disc (not enough eigenpairs converged)."""


@dataclasses.dataclass
class Mode:
    """One eigenpair with Im λ >= 0.

    Attributes:
        value: the eigenvalue λ [1/s]; Re λ > 0 is a growing mode, Im λ its angular frequency.
        residual: relative residual of the pair (see module docstring).
        accurate: ``residual <= residual_tol`` of the solver.
        vector: this rank's owned entries of the complex eigenvector.
        ident: identifier of the physical mode along a continuation (set by :func:`track`).
    """

    value: complex
    residual: float
    accurate: bool
    vector: np.ndarray = dataclasses.field(repr=False)
    ident: int = -1


def mac(a: np.ndarray, b: np.ndarray, comm: MPI.Comm) -> float:
    """Modal assurance criterion ``|a^H b|² / ((a^H a)(b^H b))`` of distributed complex vectors."""
    ab, aa, bb = comm.allreduce(np.array([np.vdot(a, b), np.vdot(a, a), np.vdot(b, b)]))
    return float(abs(ab) ** 2 / (aa.real * bb.real))


def relative_residual(operators: tuple[PETSc.Mat, PETSc.Mat, PETSc.Mat],
                      norms: tuple[float, float, float], lam: complex, xr: PETSc.Vec,
                      xi: PETSc.Vec) -> float:
    """Relative residual of the eigenpair (λ, xr + i xi) of (λ²M + λC + K) w = 0 (module
    docstring), in real arithmetic.

    Args:
        operators: the PETSc matrices ``(K, C, M)``.
        norms: their infinity norms ``(‖K‖∞, ‖C‖∞, ‖M‖∞)``.
        lam: the eigenvalue.
        xr, xi: the real and imaginary parts of the eigenvector.
    """
    K, C, M = operators
    a, b = lam.real, lam.imag
    r_re, r_im, tmp = xr.duplicate(), xr.duplicate(), xr.duplicate()
    # (λ² M + λ C + K)(xr + i xi) with λ = a + ib, split into real and imaginary parts
    K.mult(xr, r_re)
    K.mult(xi, r_im)
    C.mult(xr, tmp)
    r_re.axpy(a, tmp)
    r_im.axpy(b, tmp)
    C.mult(xi, tmp)
    r_re.axpy(-b, tmp)
    r_im.axpy(a, tmp)
    M.mult(xr, tmp)
    r_re.axpy(a * a - b * b, tmp)
    r_im.axpy(2 * a * b, tmp)
    M.mult(xi, tmp)
    r_re.axpy(-2 * a * b, tmp)
    r_im.axpy(a * a - b * b, tmp)
    nK, nC, nM = norms
    modulus = abs(lam)
    scale = (modulus**2 * nM + modulus * nC + nK) * np.hypot(xr.norm(), xi.norm())
    value = np.hypot(r_re.norm(), r_im.norm()) / scale
    for v in (r_re, r_im, tmp):
        v.destroy()
    return float(value)


class StabilitySolver:
    """Quadratic eigenproblem of the linearisation of a :class:`Residual` at its current state.

    Args:
        residual: the residual; its ``u`` must hold a converged steady state.
        prefix: PETSc options prefix of the PEP (and its ST/KSP/PC).
        options: defaults over :data:`DEFAULT_OPTIONS` (user options in the database win).
        residual_tol: eigenpairs with a larger relative residual are flagged inaccurate.
        friction_stiffness: keep the friction part of K̄ (see the module docstring).
        friction_damping: keep the friction part of C.
        inner: the inner solves of shift-and-invert, ``"direct"``, ``"amg"`` or ``"auto"``
            (module docstring, "The inner solves"); options in the database override it.

    Raises:
        ValueError: a friction part is dropped but the residual has no friction constant
            (``Residual.friction`` is None).

    Attributes:
        pep: the SLEPc PEP, exposed for inspection or further configuration.
        K, C, M: the assembled PETSc matrices (after :meth:`assemble`).
        frictionless: the names ("K", "C") of the operators assembled without their friction
            part.
        shift_invert: the inner solves (:class:`ShiftInvert`); ``shift_invert.path`` is the
            one in use, ``"direct"`` or ``"amg"``.
    """

    def __init__(self, residual: Residual, prefix: str = "stability_",
                 options: dict | None = None, residual_tol: float = 1e-8,
                 friction_stiffness: bool = True, friction_damping: bool = True,
                 inner: str = "auto"):
        check("residual_tol", residual_tol, residual_tol > 0, "must be > 0")
        dropped = [name for name, kept in (("friction_stiffness", friction_stiffness),
                                           ("friction_damping", friction_damping)) if not kept]
        if dropped and residual.friction is None:
            raise ValueError(f"{dropped[0]}=False needs a friction constant the friction is "
                             "linear in (Residual.friction), and this residual has none")
        self.residual = residual
        self.residual_tol = residual_tol
        self.frictionless = {name for name, kept in (("K", friction_stiffness),
                                                     ("C", friction_damping)) if not kept}
        self.comm = residual.V.mesh.comm
        M, C, K = residual.linearisation()
        operators = (("K", K), ("C", C), ("M", M))
        self._forms = {name: None if form.empty() else _compat.form(form)
                       for name, form in operators}
        if self._forms["K"] is None or self._forms["M"] is None:
            raise ValueError("the residual has no stiffness or no inertia: nothing to oscillate")
        self.K = dolfinx.fem.petsc.create_matrix(self._forms["K"])
        self.M = dolfinx.fem.petsc.create_matrix(self._forms["M"])
        self.C = (dolfinx.fem.petsc.create_matrix(self._forms["C"]) if self._forms["C"]
                  else self.M.duplicate())
        # contact couplings: their K̄ and C parts (derivatives in u and u̇ about u̇ = 0) are
        # added to matrices of the pencil apart from the ones dolfinx assembles into
        u, u_dot = residual.u, residual.u_dot
        self._couplings: dict[str, list[CouplingOperator]] = {
            "K": [c.operator({u: 1.0}, rest=[u_dot]) for c in residual.couplings],
            "C": [c.operator({u_dot: 1.0}, rest=[u_dot]) for c in residual.couplings]}
        self._coupled = {name: CoupledMatrix(getattr(self, name))
                         for name in ("K", "C") if residual.couplings}
        for name, coupled in self._coupled.items():
            setattr(self, name, coupled.A)
        # an operator the state enters nowhere (the mass; C without friction) is assembled
        # again only when one of its inputs (e.g. the density) has changed
        state = (u, u_dot, residual.u_ddot)
        self._watchers = {name: BulkWatcher([form], functools.partial(self._assemble, name))
                          for name, form in operators
                          if not form.empty() and not split_constant(form, state)[1]}
        self.pep = SLEPc.PEP().create(self.comm)
        self.pep.setOptionsPrefix(prefix)
        self.pep.setOperators([self.K, self.C, self.M])
        self.pep.setProblemType(SLEPc.PEP.ProblemType.GENERAL)
        self.pep.setWhichEigenpairs(SLEPc.PEP.Which.TARGET_MAGNITUDE)
        path = choose_inner(inner, self.K.getSize()[0], residual.V.dofmap.index_map_bs)
        self.shift_invert = ShiftInvert(self.pep.getST())
        self._prefix = prefix
        self._defaults = {**DEFAULT_OPTIONS, **ShiftInvert.options(path), **(options or {})}
        with options_with_defaults(prefix, self._defaults) as opts:
            self.pep.setFromOptions()
            self.shift_invert.configure(opts, self.pep.getTolerances()[0])
            # the subspace sizes set by the user, else PETSc's choice for each nev: given at
            # every setDimensions, as slepc4py >= 3.20 keeps the previous ncv when none is
            self._subspace = {key: opts.getInt(f"pep_{key}", PETSc.DECIDE)
                              for key in ("ncv", "mpd")}
        self._norms = (1.0, 1.0, 1.0)
        if self.shift_invert.multigrid:
            self.K.setNearNullSpace(rigid_body_modes(residual.V))

    def _assemble(self, name: str) -> None:
        """Assemble the integrals of K̄ (nodal springs included), C or M (``name``)."""
        coupled = self._coupled.get(name)
        integrals = getattr(self, name) if coupled is None else coupled.base
        if self._forms[name] is not None:
            stiffness = name == "K"
            assemble_jacobian(integrals, self._forms[name], self.residual.bcs,
                              self.residual.springs if stiffness else (),
                              1.0 if stiffness else 0.0)
        else:
            integrals.zeroEntries()
            integrals.assemble()

    @contextlib.contextmanager
    def _friction_for(self, name: str) -> typing.Iterator[None]:
        """The residual's friction constant set to 0 while ``name`` is assembled, if that
        operator's friction part is dropped."""
        constant = self.residual.friction
        if name not in self.frictionless or constant is None:
            yield
            return
        saved = np.array(constant.value, copy=True)
        constant.value = 0.0
        try:
            yield
        finally:
            constant.value = saved

    def assemble(self) -> None:
        """Assemble K̄ (nodal springs included), C and M at the residual's current state
        (without the friction parts dropped, see the module docstring)."""
        bcs = self.residual.bcs
        for name in ("M", "K", "C"):
            with self._friction_for(name):
                watcher = self._watchers.get(name)
                if watcher is None:
                    self._assemble(name)
                else:
                    watcher.refresh()
                coupled = self._coupled.get(name)
                if coupled is not None and coupled.assemble(self._couplings[name], bcs):
                    # the spectral transformation's factorisation is set up anew
                    self.pep.setOperators([self.K, self.C, self.M])
                    self.pep.getST().getKSP().getPC().reset()
        self._norms = tuple(A.norm(PETSc.NormType.INFINITY) for A in (self.K, self.C, self.M))

    def _relative_residual(self, lam: complex, xr: PETSc.Vec, xi: PETSc.Vec) -> float:
        return relative_residual((self.K, self.C, self.M), self._norms, lam, xr, xi)

    def solve(self, max_modulus: float, nev: int = 8, max_nev: int = 400,
              shift: float | None = None) -> list[Mode]:
        """Every eigenvalue with |λ| <= ``max_modulus`` (Im λ >= 0), sorted by |λ|.

        Args:
            max_modulus: radius of the disc searched [1/s]: the highest angular frequency (or
                growth rate) of interest.
            nev: eigenvalues requested at first; doubled until the disc is covered.
            max_nev: upper bound on the request; reaching it raises :class:`EigenSolveError`.
            shift: real shift σ of shift-and-invert (default ``max_modulus / 4``). The
                eigenvalues nearest σ are computed until the disc |λ - σ| <= max_modulus + σ,
                which contains |λ| <= max_modulus, is covered. σ > 0 favours growing modes and
                adds σ²M to the factorised matrix, which keeps it well conditioned when soft
                springs carry rigid-body motions (σ = 0 would factorise K̄ itself).
        """
        check("max_modulus", max_modulus, max_modulus > 0, "must be > 0")
        shift = max_modulus / 4 if shift is None else shift
        radius = max_modulus + abs(shift)
        self.assemble()
        self.pep.setOperators([self.K, self.C, self.M])  # values changed: set up again
        self.shift_invert.update(shift, (self.K, self.C, self.M), self.K.getNearNullSpace())
        self.pep.setTarget(shift)
        n = self.K.getSize()[0]
        while True:
            ncv, mpd = self._subspace["ncv"], self._subspace["mpd"]
            if ncv != PETSc.DECIDE:  # the user's subspace, large enough for a doubled nev
                ncv = min(max(ncv, 2 * nev), n)
            self.pep.setDimensions(nev=min(nev, n), ncv=ncv, mpd=mpd)
            with options_with_defaults(self._prefix, self._defaults):  # the multigrid's
                self.pep.solve()
            count = self.pep.getConverged()
            values = [self.pep.getEigenpair(i) for i in range(count)]
            covered = count > 0 and max(abs(v - shift) for v in values) > radius
            if covered or count >= n or nev >= min(n, max_nev):
                break
            nev *= 2
        if not covered and count < n:
            raise EigenSolveError(
                f"PEP found {count} eigenvalues, none beyond |λ - {shift:g}| = {radius:g}, with "
                f"{nev} requested (max_nev={max_nev}); reason {self.pep.getConvergedReason()}")
        xr, xi = self.K.createVecs()
        modes = []
        for i in range(count):
            lam = complex(self.pep.getEigenpair(i, xr, xi))
            if lam.imag < 0 or abs(lam) > max_modulus:
                continue
            res = self._relative_residual(lam, xr, xi)
            modes.append(Mode(value=lam, residual=res, accurate=res <= self.residual_tol,
                              vector=xr.getArray() + 1j * xi.getArray()))
        xr.destroy()
        xi.destroy()
        return sorted(modes, key=lambda m: abs(m.value))


def track(previous: list[Mode], current: list[Mode], comm: MPI.Comm,
          next_ident: int) -> int:
    """Give each mode of ``current`` the ``ident`` of the ``previous`` mode it continues.

    Pairs are matched by the Hungarian algorithm on 1 - MAC (eigenvectors), ties broken by
    eigenvalue distance; a mode matched with MAC < 0.5 or with no partner is new and gets a
    fresh ident. Returns the next unused ident.
    """
    if previous:
        scale = max(abs(m.value) for m in previous + current)
        cost = np.array([[1.0 - mac(p.vector, c.vector, comm) + abs(p.value - c.value) / scale
                          for c in current] for p in previous])
        rows, cols = scipy.optimize.linear_sum_assignment(cost)
        for r, c in zip(rows, cols, strict=True):
            if mac(previous[r].vector, current[c].vector, comm) >= 0.5:
                current[c].ident = previous[r].ident
    for mode in current:
        if mode.ident < 0:
            mode.ident = next_ident
            next_ident += 1
    return next_ident


class Eigensolver(typing.Protocol):
    """What :class:`Loci` asks of its eigensolver: :class:`StabilitySolver`, or one that
    projects it on a modal basis (:class:`fenicsfriction.cea.coupling_map.ProjectedStability`).
    """

    comm: MPI.Comm

    def solve(self, max_modulus: float) -> list[Mode]:
        """Every eigenvalue with |λ| <= ``max_modulus`` (Im λ >= 0), sorted by |λ|."""


@dataclasses.dataclass
class Onset(Record):
    """Where a mode starts to grow along a continuation (see :meth:`Loci.onset`).

    Attributes:
        mu_crit: midpoint of the final bisection interval.
        interval: the final interval [stable, unstable].
        value: the growing eigenvalue [re, im] just past the onset.
        colliding: the two modes nearest to it in frequency at the stable end, each with its
            ``mode`` id and eigenvalue ``re``, ``im``.
    """

    mu_crit: float
    interval: list[float]
    value: list[float]
    colliding: list[dict[str, typing.Any]]


def is_unstable(mode: Mode, growth_tol: float) -> bool:
    """Re λ > growth_tol |λ|: a growing mode (undamped stable modes have Re λ ~ round-off)."""
    return mode.value.real > growth_tol * abs(mode.value)


def _records(value: float, modes: list[Mode]) -> dict:
    return {"mu": float(value),
            "modes": [{"mode": m.ident, "re": m.value.real, "im": m.value.imag,
                       "residual": m.residual, "accurate": m.accurate} for m in modes],
            "max_re": max((m.value.real for m in modes), default=float("nan"))}


class Loci:
    """Eigenvalue loci along a continuation in a parameter (μ), one curve per physical mode.

    Args:
        steady: steady solver of the problem (its ``u`` is moved along the continuation).
        stability: quadratic eigensolver of the same residual (a :class:`StabilitySolver`
            or any :class:`Eigensolver`).
        parameter: the ``fem.Constant`` continued.
        max_modulus: every eigenvalue with |λ| <= max_modulus is computed at each step.
        growth_tol: a mode is unstable when Re λ > growth_tol |λ|.
        max_halvings: how many times a failing step of the steady state (to the next value,
            or a bisection's jump) may be halved.
    """

    def __init__(self, steady: typing.Any, stability: Eigensolver, parameter: typing.Any,
                 max_modulus: float,
                 growth_tol: float = 1e-6, max_halvings: int = 8):
        check("growth_tol", growth_tol, growth_tol > 0, "must be > 0")
        check("max_halvings", max_halvings, max_halvings >= 0, "must be >= 0")
        self.steady, self.stability, self.parameter = steady, stability, parameter
        self.max_halvings = max_halvings
        self.max_modulus, self.growth_tol = max_modulus, growth_tol
        self.comm = stability.comm
        self._next = 0
        self._previous: list[Mode] = []

    def _solve_at(self, value: float) -> list[Mode]:
        from fenicsfriction.steady import continuation
        continuation(self.steady, self.parameter, [value], max_halvings=self.max_halvings)
        return self.stability.solve(self.max_modulus)

    def follow(self, values: typing.Iterable[float],
               on_step: typing.Callable[[dict, list[Mode]], None] | None = None
               ) -> list[dict]:
        """Steady state and eigenvalues at each value; modes tracked by MAC from step to step.

        Returns one record per value: ``mu``, ``modes`` (``mode`` id, ``re``, ``im``,
        ``residual``, ``accurate``) and ``max_re``. ``on_step(record, modes)`` sees each step.
        A further call goes on from the last step of the previous one (same mode ids).
        """
        records = []
        for value in values:
            modes = self._solve_at(value)
            self._next = track(self._previous, modes, self.comm, self._next)
            record = _records(value, modes)
            records.append(record)
            if on_step is not None:
                on_step(record, modes)
            self._previous = modes
        return records

    def unstable(self, modes: list[Mode]) -> list[Mode]:
        return [m for m in modes if is_unstable(m, self.growth_tol)]

    def onset(self, stable: float, unstable: float, tol: float = 1e-4,
              reference: list[Mode] | None = None) -> Onset:
        """Bisect [stable, unstable] for the parameter where a mode starts to grow.

        Args:
            stable, unstable: parameter values with no growing mode / with one.
            tol: width of the final interval.
            reference: the tracked modes at ``stable`` (from :meth:`follow`), used to name the
                colliding modes; at the onset itself their eigenvectors coalesce (an
                exceptional point), so they are named where they are still apart.

        Returns:
            ``mu_crit`` (midpoint of the final interval), ``interval``, the growing eigenvalue
            ``value`` just past the onset, and ``colliding``: the two modes of ``reference``
            whose frequencies are nearest to it (``mode`` id and eigenvalue ``re``, ``im``).
            The steady state is left at the stable end.
        """
        if reference is None:
            reference = self._solve_at(stable)
        if self.unstable(reference) or not self.unstable(self._solve_at(unstable)):
            raise ValueError(f"onset: need no growing mode at {stable} and one at {unstable}")
        stable, unstable = bisect(lambda value: bool(self.unstable(self._solve_at(value))),
                                  stable, unstable, tol)
        grow = max(self.unstable(self._solve_at(unstable)), key=lambda m: m.value.real)
        self._solve_at(stable)
        nearest = sorted(reference, key=lambda m: abs(m.value.imag - grow.value.imag))[:2]
        return Onset(mu_crit=0.5 * (stable + unstable), interval=[stable, unstable],
                     value=[grow.value.real, grow.value.imag],
                     colliding=[{"mode": m.ident, "re": m.value.real, "im": m.value.imag}
                                for m in nearest])


def unstable_intervals(records: list[dict], growth_tol: float = 1e-6) -> dict[int, list]:
    """Grid μ-intervals [first, last] in which each tracked mode is unstable."""
    spans: dict[int, list] = {}
    for record in records:
        for m in record["modes"]:
            growing = m["re"] > growth_tol * abs(complex(m["re"], m["im"]))
            runs = spans.setdefault(m["mode"], [])
            if growing:
                if runs and runs[-1][2]:
                    runs[-1][1] = record["mu"]
                else:
                    runs.append([record["mu"], record["mu"], True])
            elif runs:
                runs[-1][2] = False
    return {k: [r[:2] for r in v] for k, v in spans.items() if v}
