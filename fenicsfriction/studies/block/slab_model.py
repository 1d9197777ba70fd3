r"""The block on an elastic slab as a finite element model: the one-body
:class:`~fenicsfriction.studies.block.model.BlockModel` with its mesh, interface and supports
replaced.

Both bodies live in one quadrilateral mesh (cell tags ``BLOCK`` and ``SLAB``); the block's
bottom (facet tag ``CONTACT``) is the slave surface of a two-body contact
(:func:`~fenicsfriction.contact.make_contact`: node-to-segment or mortar, the scene's
``formulation``) whose master is the slab's top (``SLAB_TOP``); the slab's bottom
(``SLAB_BOTTOM``) is clamped to the carrier. The residual is the block's (inertia, elasticity
and weight over the block's cells, the driver spring), the slab's inertia and elasticity over
its cells, and the contact as a coupling of the :class:`~fenicsfriction.forms.Residual`; the
solvers chain it through the pairing.

Everything the block model reads off a state refers to the block: the resultants of the
contact tractions on its bottom (integrated with the contact's nodal measure), its centre of
mass, its contact nodes' states and probe, all read through the contact's public attributes
(``penetration``, ``normal``, ``relative_velocity``, ``nodal_values``), whichever the
formulation. The energies are those of both bodies (the energy balance
of the dynamics needs the slab's strain and kinetic energy) and the interface powers are those
of the contact forces on both bodies.
"""

from __future__ import annotations

import functools
import typing

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem, mesh

from fenicsfriction import _compat, laws
from fenicsfriction.contact import make_contact
from fenicsfriction.forms import elasticity, inertia
from fenicsfriction.meshing import vertex_rows
from fenicsfriction.studies.block.data import CONTACT, LEFT, RIGHT, TOP
from fenicsfriction.studies.block.model import BlockModel
from fenicsfriction.studies.block.slab import (
    BLOCK,
    SLAB,
    SLAB_BOTTOM,
    SLAB_SIDES,
    SLAB_TOP,
    BlockOnSlab,
)

__all__ = ["SlabModel", "slab_arrays"]


def _grid(xs: np.ndarray, ys: np.ndarray, offset: int) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and quadrilaterals (dolfinx's tensor-product vertex order) of the grid
    ``xs`` × ``ys``; vertex numbers start at ``offset``."""
    X, Y = np.meshgrid(xs, ys, indexing="xy")
    x = np.column_stack([X.ravel(), Y.ravel()])
    nx = len(xs)
    index = np.arange(len(x)).reshape(len(ys), nx) + offset
    cells = np.column_stack([index[:-1, :-1].ravel(), index[:-1, 1:].ravel(),
                             index[1:, :-1].ravel(), index[1:, 1:].ravel()])
    return x, cells


def slab_arrays(scene: BlockOnSlab) -> tuple[np.ndarray, np.ndarray, int]:
    """(vertices, quadrilaterals, number of block cells) of both bodies: the block's cells
    first. See :mod:`fenicsfriction.studies.block.slab` for the layout."""
    s = scene
    nx, ny = 4 * s.refine, 3 * s.refine
    h = s.L / nx
    x_block = np.linspace(0.0, s.L, nx + 1)
    rows = vertex_rows(ny, s.degree, s.H, s.spring_height)
    overhang = (s.slab_length - s.L) / 2
    n_side = max(1, int(np.ceil(overhang / (2 * h))))
    left = np.linspace(-overhang, 0.0, n_side + 1)
    x_slab = np.concatenate([left[:-1], x_block, s.L - left[::-1][1:]])
    n_rows = max(1, int(round(s.slab_thickness / h)))
    y_slab = np.linspace(-s.slab_thickness, 0.0, n_rows + 1)
    xb, cb = _grid(x_block, rows, 0)
    xs, cs = _grid(x_slab, y_slab, len(xb))
    return np.vstack([xb, xs]), np.vstack([cb, cs]), len(cb)


class SlabModel(BlockModel):
    """A built block-on-slab scene: the block's model (see :class:`BlockModel`) on a slab.

    Attributes (besides the block's):
        cell_tags: ``BLOCK`` and ``SLAB`` cells.
        contact: the block-slab contact (:func:`~fenicsfriction.contact.make_contact`).
        ds_contact: the contact's nodal measure on the block's bottom.
    """

    CONTACT = CONTACT
    scene: BlockOnSlab
    #: the steady solves are repeated until the contact search holds: the block slides along
    #: the slab between continuation steps (μW/K_x, 2 cm per 0.05), and mortar contact holds
    #: its geometry within a solve (:meth:`fenicsfriction.steady.SteadySolver.solve_searched`)
    search_rounds = 10

    def __init__(self, scene: BlockOnSlab, comm: MPI.Comm, with_friction: bool | None):
        laws.check("g", scene.law.g, scene.law.g == 0,
                   "must be 0: the slab scene starts with the block on the slab")
        super().__init__(scene, comm, with_friction)

    def _mesh(self, comm: MPI.Comm) -> tuple[mesh.Mesh, mesh.MeshTags, mesh.MeshTags]:
        s = self.scene
        if comm.rank == 0:
            x, cells, _ = slab_arrays(s)
        else:
            x, cells = np.zeros((0, 2)), np.zeros((0, 4), dtype=np.int64)
        msh = _compat.create_mesh_from_arrays(comm, cells, x, "quadrilateral")
        tdim = msh.topology.dim
        cell_map = msh.topology.index_map(tdim)
        all_cells = np.arange(cell_map.size_local + cell_map.num_ghosts, dtype=np.int32)
        in_block = mesh.compute_midpoints(msh, tdim, all_cells)[:, 1] > 0
        cell_tags = mesh.meshtags(msh, tdim, all_cells,
                                  np.where(in_block, BLOCK, SLAB).astype(np.int32))
        msh.topology.create_connectivity(tdim - 1, tdim)
        facets = mesh.exterior_facet_indices(msh.topology)
        mid = mesh.compute_midpoints(msh, tdim - 1, facets)
        f_to_c = msh.topology.connectivity(tdim - 1, tdim)
        block_facet = np.array([in_block[f_to_c.links(f)[0]] for f in facets], dtype=bool)
        tol = 1e-10 * max(s.L, s.H)
        near = lambda a, b: np.isclose(a, b, rtol=0, atol=tol)  # noqa: E731
        values = np.full(len(facets), SLAB_SIDES, dtype=np.int32)
        values[~block_facet & near(mid[:, 1], 0.0)] = SLAB_TOP
        values[~block_facet & near(mid[:, 1], -s.slab_thickness)] = SLAB_BOTTOM
        for tag, where in ((LEFT, near(mid[:, 0], 0.0)), (RIGHT, near(mid[:, 0], s.L)),
                           (CONTACT, near(mid[:, 1], 0.0)), (TOP, near(mid[:, 1], s.H))):
            values[block_facet & where] = tag
        order = np.argsort(facets)
        return (msh, mesh.meshtags(msh, tdim - 1, facets[order].astype(np.int32),
                                   values[order]), cell_tags)

    def _block_measure(self) -> ufl.Measure:
        return ufl.Measure("dx", domain=self.msh, subdomain_data=self.cell_tags)(BLOCK)

    @property
    def dx_slab(self) -> ufl.Measure:
        """The volume measure of the slab."""
        return ufl.Measure("dx", domain=self.msh, subdomain_data=self.cell_tags)(SLAB)

    def _friction_factor(self) -> fem.Constant | None:
        """μ when the contact's friction bound is μ c_n; a factor of the friction coefficient
        law (see :meth:`_interface`); None with an elliptic slip rule (its bound μ_ref c_n
        has no factor of its own)."""
        if isinstance(self.scene.law.slip_rule, laws.EllipticSlipRule):
            return None
        return super()._friction_factor()

    def _interface(self, u: fem.Function, u_dot: fem.Function, u_ddot: fem.Function,
                   v: ufl.Argument) -> tuple[ufl.Form, list]:
        """The slab's inertia and elasticity, and the block-slab contact (a coupling whose
        forms are per unit breadth times B0, like the residual's)."""
        s = self.scene
        law = self.law if self.with_friction else \
            self.law.replace(mu=0.0, friction_coefficient=None, slip_rule=None)
        factor, coefficient = self.friction_factor, law.friction_coefficient
        if factor is not None and coefficient is not None:
            # the contact's friction linear in friction_factor, the stability's switch
            law = law.replace(friction_coefficient=lambda speed, pressure:
                              factor * coefficient(speed, pressure))
        self.rho_slab = fem.Constant(self.msh, np.float64(s.slab_density))
        slab = inertia(self.rho_slab, u_ddot, v, self.dx_slab) \
            + elasticity(u, v, s.slab_E, s.slab_nu, self.dx_slab)
        self.contact = make_contact(
            s.formulation, u, self.facet_tags, CONTACT, SLAB_TOP, law, velocity=u_dot,
            fields=[u_dot], transport=self.belt_velocity, weight=float(self.thickness.value))
        self.ds_contact = self.contact.ds
        return slab, [self.contact]

    def _supports(self) -> list[fem.DirichletBC]:
        """The slab's bottom clamped to the carrier."""
        V = self.V
        dofs = fem.locate_dofs_topological(V, self.msh.topology.dim - 1,
                                           self.facet_tags.find(SLAB_BOTTOM))
        return [fem.dirichletbc(np.zeros(2, dtype=np.float64), dofs, V)]

    def _contact_dofs(self) -> np.ndarray:
        """The y-dofs of the slave nodes this rank pairs (owned)."""
        return (self.contact.pairing.slave_nodes.astype(np.int64) * 2 + 1).astype(np.int32)

    def _slab_dofs(self) -> np.ndarray:
        """Local (unrolled) dofs of the slab's nodes."""
        assert self.cell_tags is not None
        nodes = _compat.cell_dofs(self.V, self.cell_tags.find(SLAB))
        return (nodes[:, None] * 2 + np.arange(2)).ravel()

    # --- the contact tractions (UFL, on the slave surface) ------------------------------------
    def penetration(self, n: typing.Any = None) -> typing.Any:
        """UFL penetration (-g)_+ of the slave point into the slab (``n`` is ignored: the
        normal is the master facet's)."""
        return self.contact.penetration

    def friction_traction(self, n: typing.Any = None) -> typing.Any:
        """UFL friction traction of the slab on the block (zero without friction)."""
        if self.contact.traction is None:
            return ufl.zero(2)
        return self.contact.traction

    def damping_pressure(self) -> typing.Any:
        """UFL normal damping pressure: the contact's normal traction less its elastic part."""
        return self.contact.pressure - self.pressure()

    def contact_traction(self) -> typing.Any:
        """UFL traction of the slab on the block (meaningful at the slave nodes only)."""
        return self.contact.pressure * self.contact.normal + self.friction_traction()

    def energy_forms(self) -> dict[str, ufl.Form]:
        """Kinetic and strain energies of the block and the slab together."""
        s = self.scene
        u, u_dot = self.residual.u, self.residual.u_dot
        block = super().energy_forms()
        return {"kinetic": block["kinetic"]
                + 0.5 * self.rho_slab * ufl.inner(u_dot, u_dot) * self.dx_slab,
                "strain": block["strain"]
                + 0.5 * elasticity(u, u, s.slab_E, s.slab_nu, self.dx_slab)}

    def interface_power_forms(self) -> dict[str, ufl.Form]:
        """Power of the friction and damping forces on both bodies:
        ∫ t · (u̇_s - u̇_m), u̇_s - u̇_m = w + U_T the velocity jump (the carrier's motion
        included)."""
        c = self.contact
        jump = c.relative_velocity + self.belt_velocity
        forms = {}
        if c.traction is not None:
            forms["friction"] = ufl.inner(c.traction, jump) * c.ds
        if self.scene.law.b_n > 0:
            forms["damping"] = self.damping_pressure() * ufl.inner(c.normal, jump) * c.ds
        return forms

    # --- nodal values ----------------------------------------------------------------------
    def nodal_contact(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(penetration, slip along the master facet, approach rate) at the slave nodes this
        rank pairs, after a contact search at the current state (collective)."""
        c = self.contact
        c.update()
        d, slip, rate = self._nodal_contact()[c.pairing.slave_nodes].T
        return d, slip, np.where(d > 0, rate, 0.0)

    @functools.cached_property
    def _nodal_contact(self) -> typing.Callable[[], np.ndarray]:
        """The contact's penetration, the relative velocity w (belt included) along the
        tangent t = (n_y, -n_x) of the contact normal n (out of the slab: +x on the flat slab)
        and the approach rate -w·n, at the slave nodes (compiled once)."""
        c = self.contact
        n, w = c.normal, c.relative_velocity
        t = ufl.as_vector([n[1], -n[0]])
        return c.nodal_values([c.penetration, ufl.dot(w, t), -ufl.dot(w, n)])

    # --- preparing a state -----------------------------------------------------------------
    def initial_guess(self) -> None:
        """The block's guess (uniform penetration under the mean pressure, the spring balancing
        μ W) on the block, the slab at rest."""
        super().initial_guess()
        self.residual.u.x.array[self._slab_dofs()] = 0.0

    def perturb_normal_velocity(self, value: float) -> None:
        """Add ``value`` [cm/s] to the normal (y) velocity of the block's nodes."""
        v = self.residual.u_dot.x.array
        block = np.setdiff1d(np.arange(1, len(v), 2), self._slab_dofs())
        v[block] += value
