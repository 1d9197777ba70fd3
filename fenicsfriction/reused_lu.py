r"""Newton's linear systems by Krylov iterations preconditioned with a factorisation that is kept
across Newton iterations and continuation steps, and renewed only when the Krylov count says it
no longer fits.

Along a continuation the Jacobian changes only where the problem is nonlinear: on the contact
interface of the block, whose normal-compliance and friction stiffnesses are small against the
elastic bulk's on any mesh fine enough to matter (c_n m_n d^{m_n-1} ≈ 10⁴ per unit area at the
block's contact pressure, against E/h ≳ 10⁶). Preconditioned by the LU of an earlier Jacobian
J₀, flexible GMRES sees J J₀⁻¹ = I + (J − J₀) J₀⁻¹, a small perturbation of the identity, and
converges in a few iterations, each one triangular solve. Where a sparse factorisation costs
a hundred solves or more (the 3D block at 1.4e5 dofs: 27 s against 0.2-0.4 s), that beats both
a factorisation per iteration and condensing the bulk onto a large interface
(:mod:`fenicsfriction.condensation`, whose dense Schur complement then rivals the sparse
factor).

Nothing rests on the factorisation being current: GMRES converges to the true Newton step
(right preconditioning: the test is on the true residual) and a count above
``refactorise_after`` makes the next Newton iteration factorise anew. This is the
"Jacobian lagging" of PETSc's SNES (``-snes_lag_preconditioner``) with a renewal rule, which
petsc4py 3.18 cannot express through SNES itself.
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc

from fenicsfriction.petsc_options import options_with_defaults

__all__ = ["ReusedFactorisation", "factorise_and_keep", "lu_solver"]

#: the default Krylov count above which the next Newton iteration factorises anew
REFACTORISE_AFTER = 12


def lu_solver(comm: MPI.Comm, prefix: str, inner: str,
              defaults: dict | None = None) -> PETSc.KSP:
    """A ``preonly`` KSP with a MUMPS LU under ``prefix + inner``, the options database read
    with ``defaults`` (keys under ``prefix``, e.g. the solver's ``options``) in place."""
    ksp = PETSc.KSP().create(comm)
    ksp.setOptionsPrefix(prefix + inner)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("lu")
    pc.setFactorSolverType("mumps")
    with options_with_defaults(prefix, defaults or {}):
        ksp.setFromOptions()
    return ksp


def factorise_and_keep(ksp: PETSc.KSP, A: PETSc.Mat) -> None:
    """Factorise ``A`` now and keep that factorisation while ``A`` changes under it (KSPSetUp
    does nothing unless handed the operators anew; the PC's reuse flag holds the factors across
    later solves)."""
    pc = ksp.getPC()
    pc.setReusePreconditioner(False)
    ksp.setOperators(A)
    ksp.setUp()
    pc.setReusePreconditioner(True)


class ReusedFactorisation:
    """PETSc ``PCPYTHON`` context: the sparse LU (MUMPS) of the Jacobian of some earlier Newton
    iteration, applied as the preconditioner of the current one.

    Args:
        comm: the communicator.
        prefix: options prefix of the factorisation (``<prefix>reused_``: e.g.
            ``-steady_reused_mat_mumps_icntl_35 2`` for MUMPS's block low-rank LU, an
            approximation GMRES then corrects).
        refactorise_after: Krylov count of a Newton iteration above which the next one
            factorises anew.

    Attributes:
        factorisations: how many times the Jacobian was factorised.
        option_defaults: option defaults under ``prefix`` (the solver's ``options``), in
            place when the factorisation reads the options database.
        stale: set to factorise anew at the next set-up (the solver sets it from the Krylov
            count).
        ksp: the inner ``preonly`` KSP holding the factorisation.
    """

    def __init__(self, comm: MPI.Comm, prefix: str = "",
                 refactorise_after: int = REFACTORISE_AFTER):
        self.comm = comm
        self.prefix = prefix
        self.refactorise_after = refactorise_after
        self.ksp: PETSc.KSP = None
        self.factorisations = 0
        self.stale = False
        self.option_defaults: dict = {}

    def setUp(self, pc: PETSc.PC) -> None:  # petsc4py's name
        J = pc.getOperators()[0]
        if self.ksp is None:
            self.ksp = lu_solver(self.comm, self.prefix, "reused_", self.option_defaults)
        elif not self.stale:
            return
        factorise_and_keep(self.ksp, J)
        self.factorisations += 1
        self.stale = False

    def apply(self, pc: PETSc.PC, r: PETSc.Vec, z: PETSc.Vec) -> None:
        self.ksp.solve(r, z)

    def krylov_count(self, iterations: int) -> None:
        """Told the Krylov count of the last Newton iteration: factorise anew if it was high."""
        if iterations > self.refactorise_after:
            self.stale = True
