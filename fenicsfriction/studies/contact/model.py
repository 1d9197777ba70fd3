r"""Two elastic bodies pressed together: the finite element model of the contact scenes.

Both bodies live in one mesh (:class:`fenicsfriction.studies.contact.geometry.TwoBodyMesh`),
each with its own Hooke's law; the interface law acts between the slave surface (body 1) and the
master surface (body 2) through node-to-segment contact
(:class:`fenicsfriction.contact.NodeToSegment`, degree-1 elements) or mortar contact
(:class:`fenicsfriction.contact.mortar.SegmentToSegment`, degree 1 or 2), chosen by
``formulation`` (:func:`fenicsfriction.contact.make_contact`), optionally in two passes (each
surface slave in turn, each pass with weight 1/2).

Friction in a quasi-static scene follows Pop's incremental formulation: the slave
velocity of the regularised law is the increment :math:`(u - u_{old})/\Delta t` of a pseudo time
step (``dt``, 1 by default, so ε is a slip increment), and each load increment is one Newton
solve started from the last.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import typing

from mpi4py import MPI

import dolfinx.fem.petsc
import numpy as np
import ufl
from dolfinx import fem, mesh

from fenicsfriction import _compat, forms, laws
from fenicsfriction.assembly import assemble_owned
from fenicsfriction.contact import FORMULATIONS, make_contact, solve_with_search
from fenicsfriction.contact.node_to_segment import ENFORCEMENTS
from fenicsfriction.laws import check
from fenicsfriction.numerics import power_law_secant
from fenicsfriction.steady import SolveError, SteadySolver
from fenicsfriction.studies.contact.geometry import (
    BODY1,
    BODY2,
    FIXED,
    LOAD,
    MASTER,
    SLAVE,
    SYMMETRY_X,
    SYMMETRY_Y,
    TwoBodyMesh,
)

__all__ = ["Material", "SurfaceValues", "TwoBodyModel", "check_discretisation"]

log = logging.getLogger(__name__)


@dataclasses.dataclass(frozen=True)
class Material:
    """Isotropic linear elasticity: Young's modulus ``E`` [force/length²], Poisson's ``nu``."""

    E: float
    nu: float

    def __post_init__(self) -> None:
        check("E", self.E, self.E > 0, "Young's modulus must be > 0")
        check("nu", self.nu, -1 < self.nu < 0.5, "Poisson's ratio must be in (-1, 0.5)")


def check_discretisation(formulation: str, degree: int, enforcement: str = "compliance") -> None:
    """Raise ``ValueError`` naming the first of ``formulation`` (node-to-segment or mortar),
    ``degree`` (1 or 2; 2 with mortar only) and ``enforcement`` (perturbed-lagrangian with
    node-to-segment only) that does not fit the others."""
    check("formulation", formulation, formulation in FORMULATIONS,
          f"one of {', '.join(FORMULATIONS)}")
    check("degree", degree, degree in (1, 2), "1 or 2")
    check("degree", degree, degree == 1 or formulation == "mortar",
          "2 needs the mortar formulation (node-to-segment contact is for degree-1 "
          "elements)")
    check("enforcement", enforcement, enforcement in ENFORCEMENTS,
          f"one of {', '.join(ENFORCEMENTS)}")
    check("enforcement", enforcement,
          enforcement == "compliance" or formulation == "node-to-segment",
          "the perturbed Lagrangian is node-to-segment's (formulation='node-to-segment')")


@dataclasses.dataclass
class SurfaceValues:
    """Nodal values on the slave surface, gathered on every rank, sorted by x, then y, z.

    Attributes:
        x: reference coordinates of the slave nodes (n, dim).
        weight: each node's tributary length (2D) or area (3D): the weight of the contact's
            nodal rule.
        gap: the normal gap to the master surface (< 0: penetration).
        pressure: the contact pressure of the law at the node.
        traction: the tangential traction vector (zeros when frictionless), (n, dim).
        force: the contact force on the node from all passes (n, dim) per unit load weight:
            the pressure the node transmits (a uniform pressure p loads every node with p
            times its load weight). Where the load weight is zero (the vertices of 6-node
            triangles), per the surface's mean load weight instead.
        load_weight: the integral of the node's shape function over the slave surface, the
            force a unit pressure puts on the node (degree 1: ``weight``; degree 2 in 2D: 1/6
            and 2/3 of a facet's length at its vertices and midpoint, in 3D 0 and 1/3 of a
            triangle's area).
        projected_weight: the node's tributary length or area projected on the contact plane
            (:meth:`TwoBodyModel.contact_area`).
    """

    x: np.ndarray
    weight: np.ndarray
    gap: np.ndarray
    pressure: np.ndarray
    traction: np.ndarray
    force: np.ndarray
    load_weight: np.ndarray
    projected_weight: np.ndarray


class TwoBodyModel:
    """Body 1 (slave) on body 2 (master), a traction on body 1's :data:`LOAD` face.

    Args:
        geometry: the mesh and its tags.
        materials: body 1's and body 2's :class:`Material`.
        law: the interface law (:class:`~fenicsfriction.laws.InterfaceLaw`): c_n, m_n, μ (0:
            frictionless, no friction term), ε (regularisation of the slip increment [length
            per pseudo-time]), the regularisation and b_n (dynamic models).
        passes: 1 (body 1's surface is the slave) or 2 (each surface in turn).
        clamp: body 2's :data:`FIXED` face clamped (True) or on rollers (normal component
            fixed only: a patch test's free lateral expansion).
        density: both bodies' mass density [mass/length³]: a dynamic model (inertia, the
            friction on the slip rate u̇, normal damping ``b_n``, the LOAD face under the
            traction ``shear`` in every direction: no platen, inertia carries body 1); ``None``
            (default): quasi-static.
        formulation: the contact's discretisation, ``"node-to-segment"`` (default) or
            ``"mortar"`` (:data:`fenicsfriction.contact.FORMULATIONS`).
        degree: the Lagrange degree of the displacement, 1 or 2 (2: mortar only).
        enforcement, penalty_T: how node-to-segment contact enforces the law
            (``"compliance"`` or ``"perturbed-lagrangian"`` with the tangential penalty κ_T;
            :data:`fenicsfriction.contact.node_to_segment.ENFORCEMENTS`).
        fix_load_face: also fix the tangential displacement of the :data:`LOAD` face
            (removes the sliding mode of a frictionless body 1 in a full model); else the
            face carries the tangential traction ``shear``.
        energy_consistent: a dynamic model integrated by the energy-consistent midpoint rule
            (``DynamicsSolver(energy_consistent=True)``): the contacts' ``step_from`` is
            ``u_start``, the step's start.

    The normal load is applied through the approach: the :data:`LOAD` face is moved by
    ``approach`` towards body 2 (a rigid platen), and :meth:`solve_for_load` finds the approach
    whose contact force is the load asked for. Under a prescribed force instead, body 1 would
    float on its contact springs, whose stiffness vanishes where the contact zone is small,
    and Newton would creep along the contact's active set.

    Attributes:
        V, u, u_old: the displacement space, the displacement, the last increment's.
        approach: the normal displacement of the LOAD face towards body 2 (``fem.Constant``).
        shear: the tangential traction on the LOAD face (a vector ``fem.Constant``).
        contacts: the contact couplings (one per pass).
        residual, solver: the residual and its :class:`~fenicsfriction.steady.SteadySolver`.
        linear_solver: the solver's ``linear_solver`` (``"auto"``: the LU per iteration on
            small meshes, Krylov + AMG beyond the crossover); set before ``solver``'s first
            use.
    """

    def __init__(self, geometry: TwoBodyMesh, materials: tuple[Material, Material],
                 law: laws.InterfaceLaw, passes: int = 1, fix_load_face: bool = False,
                 clamp: bool = True, density: float | None = None,
                 formulation: str = "node-to-segment", degree: int = 1,
                 enforcement: str = "compliance", penalty_T: float | None = None,
                 energy_consistent: bool = False):
        check("passes", passes, passes in (1, 2), "1 or 2")
        check_discretisation(formulation, degree, enforcement)
        self.formulation, self.degree, self.enforcement = formulation, degree, enforcement
        self.linear_solver = "auto"
        self.geometry = geometry
        msh, cell_tags, facet_tags = geometry.mesh, geometry.cell_tags, geometry.facet_tags
        self.comm: MPI.Comm = msh.comm
        self.dim = dim = msh.geometry.dim
        self.V = V = _compat.vector_function_space(msh, degree)
        self.u = fem.Function(V, name="displacement")
        self.u_old = fem.Function(V, name="previous_displacement")
        u_dot, u_ddot = fem.Function(V, name="velocity"), fem.Function(V, name="acceleration")
        v = ufl.TestFunction(V)
        dx = ufl.Measure("dx", domain=msh, subdomain_data=cell_tags)
        ds = ufl.Measure("ds", domain=msh, subdomain_data=facet_tags)
        self.approach = fem.Constant(msh, 0.0)
        self.shear = fem.Constant(msh, np.zeros(dim))
        form = forms.surface_traction(self.shear, v, ds(LOAD))
        self.dx, self.ds = dx, ds
        self.materials = materials
        for tag, material in zip((BODY1, BODY2), materials, strict=True):
            form += forms.elasticity(self.u, v, material.E, material.nu, dx(tag))
        self.dynamic = density is not None
        if density is not None:
            check("density", density, density > 0, "the mass density must be > 0")
            form += forms.inertia(density, u_ddot, v, dx)
        self.density = density
        self.law = law
        self.mu = fem.Constant(msh, float(law.mu))
        self.eps = fem.Constant(msh, float(law.eps))
        self.dt = fem.Constant(msh, 1.0)
        options: dict = {}
        if self.dynamic:
            options.update(velocity=u_dot, fields=[u_dot])
            if energy_consistent:
                self.u_start = fem.Function(V, name="step_start")
                options.update(step_from=self.u_start)
        self.penalty_T = fem.Constant(msh, float(penalty_T if penalty_T is not None else 0.0))
        if law.has_friction:
            law = law.replace(mu=self.mu, eps=self.eps)
            if not self.dynamic:
                options.update({"velocity": (self.u - self.u_old) / self.dt,
                                "fields": [self.u_old]})
            if enforcement != "compliance":
                options.update({"enforcement": enforcement, "penalty_T": self.penalty_T,
                                "time_step": self.dt})
        pairs = [(SLAVE, MASTER), (MASTER, SLAVE)][:passes]
        self.contacts = [make_contact(formulation, self.u, facet_tags, slave, master, law,
                                      weight=1.0 / passes, **options)
                         for slave, master in pairs]
        self.residual = forms.Residual(form, self.u, u_dot, u_ddot, v,
                                       bcs=self._bcs(fix_load_face, clamp),
                                       couplings=self.contacts)
        cells = cell_tags.indices[cell_tags.values == BODY1]
        nodes = _compat.cell_dofs(V, cells)
        self._body1_rows = nodes[nodes < V.dofmap.index_map.size_local]
        self._body1_dofs = nodes * dim + dim - 1  # their normal components (local, ghosts too)

    @functools.cached_property
    def solver(self) -> SteadySolver:
        """Newton on the quasi-static residual (built at first use: a dynamic model, whose
        friction acts on u̇, is solved by the time integrators instead)."""
        return SteadySolver(self.residual, prefix="contact_", linear_solver=self.linear_solver)

    def _bcs(self, fix_load_face: bool, clamp: bool) -> list:
        V, facet_tags, fdim = self.V, self.geometry.facet_tags, self.dim - 1
        fixed = facet_tags.indices[facet_tags.values == FIXED]
        if clamp:
            bcs = [fem.dirichletbc(np.zeros(self.dim),
                                   fem.locate_dofs_topological(V, fdim, fixed), V)]
        else:
            bcs = [self._component_bc(self.dim - 1, fixed)]
        for axis, tag in ((0, SYMMETRY_X), (1, SYMMETRY_Y)):
            facets = facet_tags.indices[facet_tags.values == tag]
            if self.comm.allreduce(len(facets)) > 0:
                bcs.append(self._component_bc(axis, facets))
        load_face = facet_tags.indices[facet_tags.values == LOAD]
        self._platen = fem.Constant(self.geometry.mesh, 0.0)  # -approach
        if not self.dynamic:
            bcs.append(self._component_bc(self.dim - 1, load_face, self._platen))
        if fix_load_face:
            bcs += [self._component_bc(axis, load_face) for axis in range(self.dim - 1)]
        return bcs

    def _component_bc(self, axis: int, facets: np.ndarray,
                      value: typing.Any = 0.0) -> fem.DirichletBC:
        dofs = fem.locate_dofs_topological(self.V.sub(axis), self.dim - 1, facets)
        return fem.dirichletbc(value, dofs, self.V.sub(axis))

    def rollers(self, axes: typing.Sequence[int]) -> None:
        """Add rollers on the planes x_axis = 0 of both bodies (patch tests: no rigid motion
        in the plane, free lateral expansion)."""
        for axis in axes:
            facets = mesh.locate_entities_boundary(
                self.geometry.mesh, self.dim - 1, lambda x, a=axis: np.isclose(x[a], 0.0))
            self.residual.bcs.append(self._component_bc(axis, facets))

    def solve_at(self, approach: float) -> typing.Any:
        """Equilibrium with the LOAD face moved by ``approach`` towards body 2 (Newton from the
        current state, the pairing searched again until it holds); returns the report."""
        # a deeper approach starts from body 1 moved rigidly with its face: the contact zone
        # of a rigid indentation is wider than the elastic one, and Newton's active set shrinks
        # to it in a few iterations (growing it takes about one node per iteration); a
        # shallower one from the last state, whose zone also shrinks
        increase = approach - float(self.approach.value)
        if increase > 0:
            self.u.x.array[self._body1_dofs] -= increase
            self.u.x.scatter_forward()
        self._platen.value = -approach
        self.approach.value = approach
        return solve_with_search(self.solver, self.contacts)

    def commit(self) -> None:
        """Store the state as the last increment's: ``u_old`` and, under the perturbed
        Lagrangian, the contacts' tangential multipliers (call before each increment)."""
        if self.enforcement == "perturbed-lagrangian":
            for contact in self.contacts:
                contact.commit()
        self.u_old.x.array[:] = self.u.x.array

    def normal_force(self) -> float:
        """The contact force on body 1 along the approach (all passes, all ranks): the load."""
        return self.comm.allreduce(float(self._contact_force()[self._body1_rows, -1].sum()))

    def solve_for_load(self, load: float, guess: float, rtol: float = 1e-6,
                       max_solves: int = 30, max_cutbacks: int = 6) -> dict:
        """The approach whose contact force is ``load`` (total in 3D, per unit length in 2D).

        The force grows like a power of the approach (δ^{3/2} for Hertz in 3D, about δ in 2D),
        so the approach is found by secant steps on log force against log approach, from
        ``guess`` (any approach that makes contact). A solve that fails is cut back: the
        state and the approach return to the last converged ones (at first the start) and
        the step of the approach is halved, at most ``max_cutbacks`` times in all; the steps
        that follow are no longer than the last one halved (load stepping where the step is
        too long for Newton: each deeper approach starts from body 1 moved rigidly, whose
        overlap, the wider the deeper, Newton must shrink to the elastic contact zone by
        about one node per iteration; with two passes both surfaces' overlaps). Returns
        ``approach``, ``load`` (reached), ``newton_iterations`` (all solves, failed ones
        included), ``solves``, ``cutbacks``, and the last solve's ``residual_norm`` and
        ``atol`` (the bound it met: how far from equilibrium the state returned may be).

        Raises:
            SolveError: a solve still failed after ``max_cutbacks`` cut-backs (the state is
                the last converged one).
        """
        check("load", load, load > 0, "the load must be > 0")
        check("guess", guess, guess > 0, "the first approach must be > 0")
        history: list[tuple[float, float]] = []
        iterations, delta, cutbacks, force = 0, guess, 0, float("nan")
        converged = (float(self.approach.value), self.u.x.array.copy())
        longest = np.inf  # the longest step of the approach since the last cut-back
        for solves in range(1, max_solves + 1):
            delta = float(np.clip(delta, converged[0] - longest, converged[0] + longest))
            try:
                report = self.solve_at(delta)
            except SolveError as err:
                iterations += err.report.iterations
                last, state = converged
                self.approach.value, self._platen.value = last, -last
                self.u.x.array[:] = state
                self.u.x.scatter_forward()
                if cutbacks == max_cutbacks:
                    err.report.iterations = iterations
                    raise SolveError(f"solve_for_load: the approach {delta:.6g} failed after "
                                     f"{cutbacks} cut-backs (max_cutbacks): {err}",
                                     err.report) from err
                cutbacks += 1
                longest = abs(delta - last) / 2
                log.info("approach %.6g: Newton failed (%s); cut back to steps of %.6g", delta,
                         err.report.reason, longest)
                delta = (last + delta) / 2
                continue
            iterations += report.iterations
            converged = (delta, self.u.x.array.copy())
            force = self.normal_force()
            log.debug("approach %.6g: contact force %.6g (load %.6g), %d Newton iterations",
                      delta, force, load, report.iterations)
            if force > 0:
                history.append((np.log(delta), np.log(force)))
            if abs(force / load - 1) < rtol:
                return {"approach": delta, "load": force, "newton_iterations": iterations,
                        "solves": solves, "cutbacks": cutbacks,
                        "residual_norm": report.residual_norm, "atol": report.atol}
            if len(history) < 2:
                delta *= 2.0 if force <= 0 else (load / force) ** 0.7
                continue
            (x0, y0), (x1, y1) = history[-2], history[-1]
            delta = float(np.exp(power_law_secant(x0, y0, x1, y1, np.log(load), min_slope=0.3)))
        raise RuntimeError(f"solve_for_load: the contact force {force:.6g} did not reach the "
                           f"load {load:.6g} within {max_solves} solves (max_solves)")

    def surface_values(self) -> SurfaceValues:
        """Nodal values on the slave surface of the first pass (see :class:`SurfaceValues`),
        after one contact search at the current state: pass them to :meth:`contact_area` and
        :meth:`contact_edge` to measure that state without searching again."""
        contact = self.contacts[0]
        contact.update()
        weight = contact.nodal_weights
        values = self._surface_nodal()
        if contact.traction is None:
            values = np.column_stack([values, np.zeros((len(weight), self.dim))])
        force = self._contact_force()
        owned, order, _ = self._surface_order
        x = contact.nodal_space.tabulate_dof_coordinates()[owned, :self.dim]
        load = self._load_weight[owned]
        loaded = load > 1e-12 * self.comm.allreduce(float(load.max(initial=0.0)), op=MPI.MAX)
        mean = self.comm.allreduce(float(load[loaded].sum())) \
            / self.comm.allreduce(int(np.count_nonzero(loaded)))
        local = np.column_stack([x, weight[owned], values[owned],
                                 force[owned] / np.where(loaded, load, mean)[:, None],
                                 np.where(loaded, load, 0.0), self._projected_weight[owned]])
        rows = np.vstack(self.comm.allgather(local))[order]
        d = self.dim
        return SurfaceValues(x=rows[:, :d], weight=rows[:, d], gap=rows[:, d + 1],
                             pressure=rows[:, d + 2], traction=rows[:, d + 3:2 * d + 3],
                             force=rows[:, 2 * d + 3:3 * d + 3], load_weight=rows[:, 3 * d + 3],
                             projected_weight=rows[:, 3 * d + 4])

    @functools.cached_property
    def _surface_order(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The rows of :meth:`surface_values`: the owned slave nodes of the first pass (local
        indices, nodal weight > 0); the order that sorts their gathered list (over the ranks
        in turn) by x, then y (then z); and each local node's row in the sorted list (owned and
        ghost nodes; -1 off the slave surface)."""
        space = self.contacts[0].nodal_space
        index_map = space.dofmap.index_map
        owned = np.flatnonzero(self.contacts[0].nodal_weights > 0)
        x = np.vstack(self.comm.allgather(space.tabulate_dof_coordinates()[owned, :self.dim]))
        order = np.lexsort(x.T[::-1])
        numbers = np.concatenate(self.comm.allgather(
            index_map.local_to_global(owned.astype(np.int32)).astype(np.int64)))[order]
        local = np.arange(index_map.size_local + index_map.num_ghosts, dtype=np.int32)
        wanted = index_map.local_to_global(local).astype(np.int64)
        by_number = np.argsort(numbers)
        found = np.minimum(np.searchsorted(numbers, wanted, sorter=by_number),
                           max(len(numbers) - 1, 0))
        row = np.full(len(local), -1, dtype=np.int64)
        if len(numbers):
            hit = numbers[by_number[found]] == wanted
            row[hit] = by_number[found[hit]]
        return owned, order, row

    def contact_area(self, values: SurfaceValues | None = None) -> float:
        r"""The contact zone's area as the contact's nodal rule integrates it (2D: length),
        on the contact plane :math:`x_d = 0` (the master's surface, normal :math:`e_d`):

        .. math:: A_h = \sum_k \bar A_k\,[p_k > 0], \qquad
                  \bar A_k = \int_{\Gamma_s} N_k\, |n\cdot e_d|\, ds,

        :math:`p_k` the law's pressure at the slave node k of the first pass (the nodes the
        law acts at; one pass: those that carry load) and :math:`\bar A_k` the node's
        tributary area projected on the plane. The zone's boundary then runs about midway
        between the last nodes in contact and the first open ones, so its error is of either
        sign and averages out along a 3D zone's rim (where the gap's sign change, which hugs
        the last contact node, is biased inwards by about h/2). Summed over all the nodes (the
        same sum on every rank and on any number of ranks).

        Args:
            values: :meth:`surface_values` at the current state (``None``: evaluated here,
                with a contact search).
        """
        values = self.surface_values() if values is None else values
        return float(values.projected_weight[values.pressure > 0].sum())

    @functools.cached_property
    def _projected_weight(self) -> np.ndarray:
        """∫ N_k |n·e_d| over the slave surface of each owned node: its tributary area
        (length) projected on the contact plane."""
        q = ufl.TestFunction(self.contacts[0].nodal_space)
        n = ufl.FacetNormal(self.geometry.mesh)
        return assemble_owned(_compat.form(q * abs(n[self.dim - 1]) * self.ds(SLAVE)))

    @functools.cached_property
    def _load_weight(self) -> np.ndarray:
        """∫ N_k over the slave surface of each owned node (exact: P1 geometry)."""
        q = ufl.TestFunction(self.contacts[0].nodal_space)
        return assemble_owned(_compat.form(q * self.ds(SLAVE)))

    @functools.cached_property
    def _surface_nodal(self) -> typing.Callable[[], np.ndarray]:
        """Gap, pressure and (with friction) the traction's components at the slave nodes."""
        contact = self.contacts[0]
        traction = contact.traction
        return contact.nodal_values(
            [contact.gap, contact.pressure,
             *([] if traction is None else [traction[k] for k in range(self.dim)])])

    @functools.cached_property
    def _gap_nodal(self) -> typing.Callable[[], np.ndarray]:
        contact = self.contacts[0]
        return contact.nodal_values([contact.gap])

    def nodal_gap(self) -> np.ndarray:
        """The gap at each owned node of the first pass's slave surface (0 off it), for the
        contact's current pairing and mirrors (``update`` them first)."""
        return self._gap_nodal()[:, 0]

    def contact_edge(self, values: SurfaceValues | None = None) -> np.ndarray:
        """Points where the gap changes sign along the slave facets' edges (linear
        interpolation of the nodal gaps), one per edge of each facet (an edge inside the
        surface: twice), gathered on every rank (the same points on any number of ranks): the
        contact zone's boundary (its two ends in 2D, a ring in 3D), second-order accurate where
        the gap is smooth.

        Args:
            values: :meth:`surface_values` at the current state (``None``: evaluated here,
                with a contact search).
        """
        contact = self.contacts[0]
        values = self.surface_values() if values is None else values
        row = self._surface_order[2]
        # each local node's gap (owned and ghost; 0 off the slave surface)
        gap = np.where(row >= 0, values.gap[row], 0.0)
        edges = _surface_edges(contact.nodal_space, self.geometry.facet_tags, SLAVE)
        g = gap[edges]
        crossing = g[:, 0] * g[:, 1] < 0
        x = contact.nodal_space.tabulate_dof_coordinates()[:, :self.dim]
        a, b = edges[crossing, 0], edges[crossing, 1]
        t = (g[crossing, 0] / (g[crossing, 0] - g[crossing, 1]))[:, None]
        points = x[a] + t * (x[b] - x[a])
        return np.vstack(self.comm.allgather(points))

    @functools.cached_property
    def _force_operators(self) -> list:
        """The contacts' residuals alone (no Jacobian), for their forces."""
        return [contact.operator({}) for contact in self.contacts]

    def _contact_force(self) -> np.ndarray:
        """The contact force of every pass on each node (owned nodes, (n, dim))."""
        b = dolfinx.fem.petsc.create_vector(self._zero_residual)
        b.set(0.0)
        for operator in self._force_operators:
            operator.add_to_residual(b)
        force = -b.getArray().reshape(-1, self.dim).copy()
        b.destroy()
        return force

    @functools.cached_property
    def _zero_residual(self) -> typing.Any:
        """A compiled linear form on V, whose vectors have the residual's layout."""
        zero = fem.Constant(self.geometry.mesh, np.zeros(self.dim))
        return _compat.form(ufl.inner(zero, ufl.TestFunction(self.V)) * self.dx)

    @property
    def dofs(self) -> int:
        """Number of displacement unknowns."""
        index_map = self.V.dofmap.index_map
        return index_map.size_global * self.V.dofmap.index_map_bs


def _surface_edges(V: fem.FunctionSpace, facet_tags: mesh.MeshTags, tag: int) -> np.ndarray:
    """Pairs of nodes of ``V`` (local indices) joined by an edge of the linear sub-facets of
    the owned facets tagged ``tag`` (each facet on one rank): the facets' edges (degree 1), or
    the edges of the segments (2D) and four triangles (3D) that the midside nodes cut each
    facet into (degree 2, straight facets: a midside node is the midpoint of its two
    vertices)."""
    msh = V.mesh
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    msh.topology.create_connectivity(tdim, tdim - 1)
    f_to_c = msh.topology.connectivity(tdim - 1, tdim)
    c_to_f = msh.topology.connectivity(tdim, tdim - 1)
    layout = V.dofmap.dof_layout
    x = V.tabulate_dof_coordinates()
    edges = []
    owned = msh.topology.index_map(tdim - 1).size_local
    tagged = facet_tags.indices[facet_tags.values == tag]
    for facet in tagged[tagged < owned]:
        cell = f_to_c.links(facet)[0]
        local = int(np.flatnonzero(c_to_f.links(cell) == facet)[0])
        nodes = V.dofmap.cell_dofs(cell)[layout.entity_closure_dofs(tdim - 1, local)]
        pairs = [(a, b) for i, a in enumerate(nodes) for b in nodes[i + 1:]]
        if len(nodes) == tdim:  # degree 1: every pair is an edge
            edges += pairs
            continue
        size = max(float(np.linalg.norm(x[a] - x[b])) for a, b in pairs)
        midside = {m: (a, b) for m in nodes for a, b in pairs
                   if np.linalg.norm(x[m] - (x[a] + x[b]) / 2) < 1e-10 * size}
        edges += [(a, m) for m, (a, _) in midside.items()]
        edges += [(m, b) for m, (_, b) in midside.items()]
        middle = list(midside)
        edges += [(m, n) for i, m in enumerate(middle) for n in middle[i + 1:]]
    return np.array(edges, dtype=np.int32).reshape(-1, 2)
