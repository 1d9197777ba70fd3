r"""Contacts as nodal springs on the top face of a finite elastic block (linear elasticity).

The block :math:`[-w/2, w/2]^2 \times [-d, 0]` is clamped at its bottom :math:`z = -d`, free
elsewhere. Contact :math:`i` is a spring of stiffness :math:`k` (all three components) between the
mesh node at :math:`\mathbf r_i` on the top face and an anchor displaced rigidly by
:math:`U_{0,i}`; it pulls the block with :math:`\mathbf f_i = k(U_{0,i} - \mathbf u_i)` and
extra point forces :math:`\mathbf p_i` may act on the same nodes:

.. math::

    \Big(K_{el} + k\sum_i P_i\Big)\,u = \sum_i P_i\,(k\,U_{0,i} + \mathbf p_i),

:math:`P_i` the projection on node :math:`i`'s three dofs. The block stands in for the half-space
of the Green tensor (Landau & Lifshitz 1986, *Theory of elasticity*, §8;
:mod:`fenicsfriction.studies.multicontact.interaction`): the same contact forces
:math:`F = (1 + KG)^{-1} K U_0` up to the mesh (the node's own compliance replaces the disc of
the Green tensor's self term) and the block's finite size. The break response
:math:`\delta F = B\,\delta K\,(U_0 - GF)` (Braun (slides), "Interaction between contacts") is
the second solve of :meth:`ElasticSubstrate.break_response`: the source
:math:`-k\,(U_0 - u)_{i^*}` as a point force at the breaking contact, the springs' anchors at
rest, :math:`\delta F_j = -k u_j` for :math:`j \ne i^*`.
"""

from __future__ import annotations

import dataclasses
import typing

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem.petsc
import numpy as np
import numpy.typing as npt
import ufl
from dolfinx import fem, mesh

from fenicsfriction import _compat, assembly, forms
from fenicsfriction.laws import check, check_positive
from fenicsfriction.petsc_options import options_with_defaults

__all__ = ["ElasticSubstrate", "SubstrateBlock"]

Array: typing.TypeAlias = npt.NDArray[np.float64]


@dataclasses.dataclass(frozen=True)
class SubstrateBlock:
    """The block under the contacts.

    Attributes:
        width: side w of the square top face (m), centred on the origin.
        depth: thickness d (m); the bottom is clamped.
        E: Young's modulus (Pa).
        nu: Poisson's ratio.
        cells_per_side: hexahedra along x and y (the spacing of the top-face nodes is
            ``width / cells_per_side``: contacts must sit on these nodes).
        cells_deep: hexahedra along z.
        degree: Lagrange degree of the displacement.
        grading: exponent p >= 1 of the mesh grading towards the centre of the top face: a
            uniform coordinate ξ ∈ [-1, 1] maps to ``sign(ξ) |ξ|^p`` across the face and
            ζ ∈ [0, 1] to ``-depth ζ^p`` downwards, so the cells near the contacts are small
            while the block stays deep and wide (the half-space of the Green tensor).
    """

    width: float
    depth: float
    E: float
    nu: float
    cells_per_side: int
    cells_deep: int
    degree: int = 1
    grading: float = 1.0

    def __post_init__(self) -> None:
        check_positive("width", self.width)
        check_positive("depth", self.depth)
        check_positive("E", self.E)
        check("nu", self.nu, -1 < self.nu < 0.5, "Poisson's ratio must be in (-1, 0.5)")
        for name in ("cells_per_side", "cells_deep", "degree"):
            value = getattr(self, name)
            check(name, value, isinstance(value, int) and value >= 1, "must be an integer >= 1")
        check("grading", self.grading, self.grading >= 1, "the grading exponent must be >= 1")

    @property
    def surface_nodes(self) -> npt.NDArray[np.float64]:
        """x (and y) coordinates of the top face's vertices (m): contacts sit on these."""
        uniform = np.linspace(-1.0, 1.0, self.cells_per_side + 1, dtype=np.float64)
        return self.graded(uniform) * self.width / 2

    def graded(self, xi: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """The grading map ``sign(ξ) |ξ|^p`` of uniform box coordinates in [-1, 1]."""
        return np.sign(xi) * np.abs(xi) ** self.grading


class ElasticSubstrate:
    """The block with contact springs, its stiffness matrix factorised once.

    Args:
        comm: MPI communicator.
        block: geometry, material and mesh.
        positions: ``(N, 2)`` contact points on the top face (mesh vertices).
        stiffness: contact stiffness k (N/m).
        options_prefix: PETSc options prefix of the linear solver (LU, MUMPS by default).

    Attributes:
        mesh, V: the mesh and the displacement space.
        u: the last displacement solved for.
        ksp: the PETSc solver.
    """

    def __init__(self, comm: MPI.Comm, block: SubstrateBlock, positions: npt.ArrayLike,
                 stiffness: float, options_prefix: str = "substrate_"):
        check_positive("stiffness", stiffness)
        self.block, self.stiffness = block, float(stiffness)
        self.positions = np.asarray(positions, dtype=float)
        check("positions", self.positions.shape,
              self.positions.ndim == 2 and self.positions.shape[1] == 2,
              "must be an (N, 2) array of points on the top face")
        self.mesh = _compat.create_box(
            comm, [-1.0, -1.0, -1.0], [1.0, 1.0, 0.0],
            [block.cells_per_side, block.cells_per_side, block.cells_deep])
        x = self.mesh.geometry.x
        x[:, :2] = block.graded(x[:, :2]) * block.width / 2
        x[:, 2] = block.graded(x[:, 2]) * block.depth
        self.V = _compat.vector_function_space(self.mesh, block.degree)
        self.u = fem.Function(self.V)
        self._local, self._global = self._contact_dofs()

        bottom = mesh.locate_entities_boundary(
            self.mesh, self.mesh.topology.dim - 1, lambda x: np.isclose(x[2], -block.depth))
        clamp = fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType),
                                fem.locate_dofs_topological(self.V, self.mesh.topology.dim - 1,
                                                            bottom), self.V)
        a = _compat.form(forms.elasticity(ufl.TrialFunction(self.V), ufl.TestFunction(self.V),
                                          block.E, block.nu, ufl.dx))
        self.A = dolfinx.fem.petsc.create_matrix(a)
        springs = [forms.NodalSpring(stiffness=self.stiffness, anchor=0.0, local_dof=int(local),
                                     global_dof=int(glob), position=position)
                   for local_dofs, global_dofs, position in zip(self._local, self._global,
                                                                self.positions, strict=True)
                   for local, glob in zip(local_dofs, global_dofs, strict=True)]
        assembly.assemble_jacobian(self.A, a, [clamp], springs)
        self.b = self.A.createVecRight()
        self.ksp = PETSc.KSP().create(comm)
        self.ksp.setOptionsPrefix(options_prefix)
        self.ksp.setOperators(self.A)
        defaults = {"ksp_type": "preonly", "pc_type": "lu",
                    "pc_factor_mat_solver_type": "mumps"}
        with options_with_defaults(options_prefix, defaults):
            self.ksp.setFromOptions()

    def _contact_dofs(self) -> tuple[npt.NDArray[np.int32], npt.NDArray[np.int64]]:
        """Local and global dof indices ``(N, 3)`` of the contact nodes (-1 where not owned)."""
        index_map, bs = self.V.dofmap.index_map, self.V.dofmap.index_map_bs
        nodes = self.V.tabulate_dof_coordinates()[:index_map.size_local]
        tol = 1e-8 * self.block.width
        local = np.full((len(self.positions), 3), -1, dtype=np.int32)
        glob = np.full((len(self.positions), 3), -1, dtype=np.int64)
        top = np.flatnonzero(np.abs(nodes[:, 2]) < tol)
        for i, p in enumerate(self.positions):
            hit = top[np.linalg.norm(nodes[top, :2] - p, axis=1) < tol]
            if len(hit):
                block_global = index_map.local_to_global(hit[:1].astype(np.int32))[0]
                local[i] = bs * hit[0] + np.arange(3)
                glob[i] = bs * block_global + np.arange(3)
        found = self.mesh.comm.allreduce((local[:, 0] >= 0).astype(int), op=MPI.SUM)
        missing = np.flatnonzero(found != 1)
        check("positions", self.positions[missing].tolist() if len(missing) else None,
              len(missing) == 0, "every contact must sit on a vertex of the top face "
              "(SubstrateBlock.surface_nodes)")
        return local, glob

    def _gather(self, local_values: Array) -> Array:
        values = np.where(self._local >= 0, local_values, 0.0)
        return self.mesh.comm.allreduce(values, op=MPI.SUM)

    def displacements(self, anchors: npt.ArrayLike, point_forces: npt.ArrayLike = 0.0) -> Array:
        """Solve for the block's displacement; return it at the contacts, ``(N, 3)``, every rank.

        Args:
            anchors: the anchors' displacement U₀, ``(3,)`` or ``(N, 3)`` (m).
            point_forces: extra forces on the contact nodes, ``(3,)`` or ``(N, 3)`` (N).
        """
        n = len(self.positions)
        load = (self.stiffness * np.broadcast_to(np.asarray(anchors, dtype=float), (n, 3))
                + np.broadcast_to(np.asarray(point_forces, dtype=float), (n, 3)))
        self.b.zeroEntries()
        owned = self._local >= 0
        self.b.array[self._local[owned]] = load[owned]
        self.ksp.solve(self.b, _compat.petsc_vec(self.u))
        self.u.x.scatter_forward()
        return self._gather(self.u.x.array[np.maximum(self._local, 0)])

    def forces(self, U0: npt.ArrayLike) -> Array:
        """The contacts' forces on the block, :math:`k(U_0 - u)`, ``(N, 3)`` (N)."""
        n = len(self.positions)
        anchors = np.broadcast_to(np.asarray(U0, dtype=float), (n, 3))
        return self.stiffness * (anchors - self.displacements(anchors))

    def break_response(self, U0: npt.ArrayLike, broken: int) -> Array:
        """:math:`\\delta F = B\\,\\delta K\\,(U_0 - GF)` when ``broken`` breaks, ``(N, 3)``.

        First order in :math:`\\delta K = -k`, as the Green-tensor
        :func:`~fenicsfriction.studies.multicontact.interaction.break_response`.
        """
        n = len(self.positions)
        check("broken", broken, isinstance(broken, (int, np.integer)) and 0 <= broken < n,
              f"must be a contact index in [0, {n})")
        source = np.zeros((n, 3))
        source[broken] = -self.forces(U0)[broken]
        response = -self.stiffness * self.displacements(0.0, source)
        response[broken] += source[broken]
        return response
