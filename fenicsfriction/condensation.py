r"""The linear bulk condensed onto the nonlinear interface: a direct solver for Newton's
systems that factorises once per continuation instead of once per iteration, for interfaces
small against the body (2D; :mod:`fenicsfriction.reused_lu` for large ones).

In every scene of the package the body is linear elastic and the nonlinearity lives on the
contact surface Γ_C (normal compliance, friction). Split the dofs into the few on the facets of
the nonlinear integrals, Γ, and the rest, I. Then only the Γ × Γ block of the Jacobian changes
with the state:

.. math::
    J(u) = \begin{pmatrix} K_{II} & K_{I\Gamma} \\ K_{\Gamma I} & J_{\Gamma\Gamma}(u)
    \end{pmatrix},

whether an integral's Jacobian is constant being decided symbolically: ``u`` does not enter it
(:func:`interface_split`). The Schur complement of the bulk,
:math:`C = K_{\Gamma I} K_{II}^{-1} K_{I\Gamma}` (|Γ| × |Γ|, dense), is formed once, and each
Newton system is the bulk's solve with :math:`J_{\Gamma\Gamma}(u) - C` on the interface:

.. math::
    y = K_{II}^{-1} r_I,\quad
    (J_{\Gamma\Gamma} - C)\,\delta_\Gamma = r_\Gamma - K_{\Gamma I} y,\quad
    \delta_I = y - K_{II}^{-1} K_{I\Gamma} \delta_\Gamma.

MUMPS forms C itself (its Schur complement option, :mod:`fenicsfriction.mumps_schur`): the
Jacobian is factorised once with Γ eliminated last, which leaves
:math:`J_{\Gamma\Gamma}(u_0) - C` as a by-product. In serial that factor then solves every Newton
system in one forward and one backward sweep, its dense Schur block replaced by
:math:`J_{\Gamma\Gamma}(u) - C` and re-factorised by PETSc at each iteration; in parallel (PETSc
solves with a Schur factor in serial only) C comes from a factorisation with Γ centralised on
rank 0, and the sweeps above use a separate factorisation of :math:`K_{II}`. With another LU
package C is formed by one solve per interface dof.

This is static condensation of the elastic body onto its contact surface, the finite element
counterpart of the influence numbers of boundary-element contact solvers (Kalker 1990). Unlike
the Sherman-Morrison-Woodbury update of a factorised full Jacobian, it involves no
cancellation, so it stays exact to round-off with stiff contact.

:class:`InterfaceCondensation` is a PETSc preconditioner (``PCPYTHON``) inside flexible GMRES:
while the split holds it is the exact inverse and GMRES stops after one iteration; if the bulk
changed after the factorisation (a parameter of a bulk integral was changed), GMRES still
converges to the true Newton step, with more iterations, and the solver factorises anew. So
correctness never rests on the split.
"""

from __future__ import annotations

import time

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import scipy.linalg
import ufl
from dolfinx import fem, mesh

from fenicsfriction import mumps_schur
from fenicsfriction.assembly import split_constant
from fenicsfriction.reused_lu import factorise_and_keep, lu_solver

__all__ = ["InterfaceCondensation", "condensation_for", "interface_split"]

#: columns of K_IΓ solved for at once when C is formed (multiple right-hand sides)
BLOCK_COLUMNS = 64

#: a Krylov count above this makes the condensation factorise the bulk anew (exact, it takes 1)
REFACTORISE_AFTER_ITERATIONS = 5


def interface_split(jacobian: ufl.Form, u: fem.Function
                    ) -> tuple[ufl.Form, list[ufl.classes.Integral]] | None:
    """``(K0 form, nonlinear integrals)`` of a Jacobian, or ``None`` if it does not split.

    K0 holds the integrals ``u`` does not enter (:func:`fenicsfriction.assembly.split_constant`).
    The split is usable when every other integral is an exterior-facet integral over tagged
    facets (or all exterior facets), so that B(u) lives on their dofs only.
    """
    constant, varying = split_constant(jacobian, [u])
    if constant is None or not varying:
        return None
    if any(i.integral_type() != "exterior_facet" for i in varying):
        return None
    return constant, varying


def _interface_dofs(V: fem.FunctionSpace, integrals: list) -> np.ndarray:
    """Global indices (unrolled, owned by this rank) of the dofs on the integrals' facets."""
    msh = V.mesh
    fdim = msh.topology.dim - 1
    facets = []
    for integral in integrals:
        tags, tag = integral.subdomain_data(), integral.subdomain_id()
        if tags is None or tag in ("everywhere", "otherwise"):
            msh.topology.create_connectivity(fdim, fdim + 1)
            facets.append(mesh.exterior_facet_indices(msh.topology))
        else:
            facets.append(tags.indices[tags.values == tag])
    blocks = fem.locate_dofs_topological(V, fdim, np.unique(np.concatenate(facets)))
    index_map, bs = V.dofmap.index_map, V.dofmap.index_map_bs
    blocks = blocks[blocks < index_map.size_local]
    global_blocks = index_map.local_to_global(blocks.astype(np.int32))
    return np.sort((global_blocks[:, None] * bs + np.arange(bs)).ravel()).astype(PETSc.IntType)


class InterfaceCondensation:
    """PETSc ``PCPYTHON`` context: J⁻¹ by condensation onto Γ (see the module's docstring).

    Args:
        interface: global indices of the Γ dofs this rank owns (sorted).
        comm: the communicator.
        prefix: options prefix of K_II's factorisation (``<prefix>condensed_``; MUMPS LU).

    Attributes:
        size: |Γ|, the number of interface dofs.
        setup_time_s: time spent factorising and forming C.
        factorisations: how many times the bulk was factorised.
        option_defaults: option defaults under ``prefix`` (the solver's ``options``), in
            place when the factorisations read the options database.
        whole: serial with MUMPS: J itself is factorised with Γ last, MUMPS's Schur complement
            gives C, and each Newton system is one solve with that factor (its Schur
            complement replaced by J_ΓΓ(u) − C); otherwise K_II is factorised and C formed by
            MUMPS's Schur complement of J centralised on rank 0 (or, with another LU package,
            by one solve per interface dof).
        stale: set to factorise anew at the next set-up (the solver does it when the bulk
            changed, :meth:`krylov_count` when the Krylov count says it no longer matches).
        refactorise_after: that Krylov count (the condensation is exact: it takes 1).
    """

    def __init__(self, interface: np.ndarray, comm: MPI.Comm, prefix: str = ""):
        self.comm = comm
        self.interface = interface
        counts = comm.allgather(len(interface))
        self.size = sum(counts)
        self._offsets = np.concatenate([[0], np.cumsum(counts)])
        self.prefix = prefix
        self.ksp: PETSc.KSP = None
        self.factorisations = 0
        self.setup_time_s = 0.0
        self.stale = False
        self._lu: tuple | None = None
        self.whole = False
        self.option_defaults: dict = {}
        self.refactorise_after = REFACTORISE_AFTER_ITERATIONS

    def _index_sets(self, J: PETSc.Mat) -> None:
        lo, hi = J.getOwnershipRange()
        owned = np.arange(lo, hi, dtype=PETSc.IntType)
        self.is_gamma = PETSc.IS().createGeneral(self.interface, comm=self.comm)
        self.is_inner = PETSc.IS().createGeneral(
            np.setdiff1d(owned, self.interface, assume_unique=True).astype(PETSc.IntType),
            comm=self.comm)

    # --- the one-off part: the factorisation and C ---------------------------------------------
    def _factorise(self, J: PETSc.Mat) -> None:
        t0 = time.perf_counter()
        if self.ksp is None:
            self._index_sets(J)
            self.ksp = lu_solver(self.comm, self.prefix, "condensed_", self.option_defaults)
            pc = self.ksp.getPC()
            self._mumps_schur = (mumps_schur.available()
                                 and pc.getFactorSolverType() == "mumps")
            self.whole = self._mumps_schur and self.comm.size == 1
            if self.whole:
                self.ksp.setOperators(J)
                pc.setFactorSetUpSolverType()  # the factor exists before the factorisation
                mumps_schur.set_schur_indices(pc.getFactorMatrix(), self.is_gamma)
        pc = self.ksp.getPC()
        if self.whole:
            factorise_and_keep(self.ksp, J)  # Γ last; kept while J changes under it
            with mumps_schur.schur_complement(pc.getFactorMatrix()) as S:
                self.C = self._gather_gamma(J) - S
        else:
            self.K_II = J.createSubMatrix(self.is_inner, self.is_inner)
            self.K_IG = J.createSubMatrix(self.is_inner, self.is_gamma)
            self.K_GI = J.createSubMatrix(self.is_gamma, self.is_inner)
            self.ksp.setOperators(self.K_II)
            self.ksp.setUp()
            self.C = self._centralised_schur(J) if self._mumps_schur else self._bulk_schur(J)
        self.factorisations += 1
        self.setup_time_s += time.perf_counter() - t0

    def _centralised_schur(self, J: PETSc.Mat) -> np.ndarray:
        """C from MUMPS's Schur complement of J with Γ on rank 0 (a second, parallel
        factorisation, dropped afterwards: PETSc solves with a Schur factor in serial only),
        broadcast to every rank."""
        ksp = lu_solver(self.comm, self.prefix, "condensed_", self.option_defaults)
        ksp.setOperators(J)
        pc = ksp.getPC()
        pc.setFactorSetUpSolverType()
        everything = self.comm.gather(self.interface)  # Γ on rank 0, in global order
        on_root = PETSc.IS().createGeneral(
            np.concatenate(everything).astype(PETSc.IntType) if everything is not None
            else np.empty(0, dtype=PETSc.IntType), comm=self.comm)
        mumps_schur.set_schur_indices(pc.getFactorMatrix(), on_root)
        ksp.setUp()
        with mumps_schur.schur_complement(pc.getFactorMatrix()) as S:
            schur = self.comm.bcast(S.copy() if self.comm.rank == 0 else None, root=0)
        ksp.destroy()
        on_root.destroy()
        return self._gather_gamma(J) - schur

    def _bulk_schur(self, J: PETSc.Mat) -> np.ndarray:
        """C = K_ΓI K_II⁻¹ K_IΓ, replicated on every rank, BLOCK_COLUMNS columns at a time: the
        fallback where MUMPS's Schur complement cannot be had (another LU package)."""
        n = self.size
        C = np.empty((n, n))
        factor = self.ksp.getPC().getFactorMatrix()
        positions = np.arange(self._offsets[self.comm.rank], self._offsets[self.comm.rank + 1])
        local_inner = self.is_inner.getLocalSize()
        for start in range(0, n, BLOCK_COLUMNS):
            width = min(BLOCK_COLUMNS, n - start)
            inside = (positions >= start) & (positions < start + width)
            columns = PETSc.IS().createGeneral(self.interface[inside], comm=self.comm)
            sparse = J.createSubMatrix(self.is_inner, columns)
            rhs = sparse.convert("dense")
            solution = np.zeros((local_inner, width), order="F")
            sol = PETSc.Mat().createDense(((local_inner, None), (None, width)), array=solution,
                                          comm=self.comm)
            sol.assemble()
            factor.matSolve(rhs, sol)
            product = self.K_GI.matMult(sol)
            C[:, start:start + width] = np.vstack(
                self.comm.allgather(product.getDenseArray().copy()))
            for obj in (columns, sparse, rhs, sol, product):
                obj.destroy()
        return C

    def _gather_gamma(self, J: PETSc.Mat) -> np.ndarray:
        """J[Γ, Γ] as a dense array on every rank."""
        sub = J.createSubMatrix(self.is_gamma, self.is_gamma)
        dense = sub.convert("dense")
        rows = dense.getDenseArray().copy()
        sub.destroy()
        dense.destroy()
        return np.vstack(self.comm.allgather(rows))

    def krylov_count(self, iterations: int) -> None:
        """Told the Krylov count of the last Newton iteration: a high one means the bulk no
        longer matches its factorisation, so factorise anew."""
        if iterations > self.refactorise_after:
            self.stale = True

    # --- PCPYTHON interface -------------------------------------------------------------------
    def setUp(self, pc: PETSc.PC) -> None:  # petsc4py's name
        J = pc.getOperators()[0]
        if self.ksp is None or self.stale:
            self._factorise(J)
            self.stale = False
        if self.whole:  # the factor's own Schur complement becomes J_ΓΓ(u) - C
            with mumps_schur.schur_complement(self.ksp.getPC().getFactorMatrix()) as S:
                S[:] = self._gather_gamma(J) - self.C
        else:
            self._lu = scipy.linalg.lu_factor(self._gather_gamma(J) - self.C)

    def apply(self, pc: PETSc.PC, r: PETSc.Vec, z: PETSc.Vec) -> None:
        if self.whole:  # MUMPS condenses r onto Γ, PETSc solves with S, MUMPS expands
            self.ksp.solve(r, z)
            return
        assert self._lu is not None, "setUp comes first"
        r_I, r_G = r.getSubVector(self.is_inner), r.getSubVector(self.is_gamma)
        y = r_I.duplicate()
        self.ksp.solve(r_I, y)
        rhs = r_G.duplicate()
        self.K_GI.mult(y, rhs)
        rhs.aypx(-1.0, r_G)  # r_Γ - K_ΓI y
        mine = slice(self._offsets[self.comm.rank], self._offsets[self.comm.rank + 1])
        delta = scipy.linalg.lu_solve(
            self._lu, np.concatenate(self.comm.allgather(rhs.getArray(readonly=True))))[mine]
        r.restoreSubVector(self.is_inner, r_I)
        r.restoreSubVector(self.is_gamma, r_G)
        z_I, z_G = z.getSubVector(self.is_inner), z.getSubVector(self.is_gamma)
        z_G.getArray()[:] = delta
        correction = y.duplicate()
        self.K_IG.mult(z_G, correction)
        self.ksp.solve(correction, z_I)
        z_I.aypx(-1.0, y)  # y - K_II⁻¹ K_IΓ δ_Γ
        z.restoreSubVector(self.is_inner, z_I)
        z.restoreSubVector(self.is_gamma, z_G)
        for v in (y, rhs, correction):
            v.destroy()


def condensation_for(split: tuple[ufl.Form, list], V: fem.FunctionSpace, prefix: str = "",
                     max_interface: int = 6000) -> InterfaceCondensation | None:
    """The condensation of a Jacobian split by :func:`interface_split`, or ``None`` where Γ has
    more than ``max_interface`` dofs, beyond which the dense ``|Γ|²`` work outweighs a sparse
    factorisation."""
    interface = _interface_dofs(V, split[1])
    comm = V.mesh.comm
    if comm.allreduce(len(interface)) > max_interface:
        return None
    return InterfaceCondensation(interface, comm, prefix)
