r"""A checked case file built into a finite element model: mesh, one space, the one residual.

:class:`CaseModel` turns a :class:`~fenicsfriction.case.schema.Case` into the sum of the
residual's terms (:mod:`fenicsfriction.forms`), body by body and boundary by boundary:

.. math::
    R = \sum_b \Big[\rho_b\langle\ddot u, v\rangle + a_b(u, v)
        + \alpha_b \rho_b\langle\dot u, v\rangle + \beta_b\, a_b(\dot u, v)\Big]_{\Omega_b}
        + \text{supports} - s\,\text{loads} + \text{contacts}

(Rayleigh damping :math:`C_b = \alpha_b M_b + \beta_b K_b` as two residual terms, :math:`s` the
global load factor ``load_scale``), the nodal springs and the body-to-body contacts as the
residual's ``springs`` and ``couplings``. Every value a continuation can step
(:data:`~fenicsfriction.case.schema.CONTINUABLE`) is one ``fem.Constant``
(:attr:`CaseModel.parameters`): changing it re-solves without compiling anything again.

Contact with a rigid plane foundation (point :math:`p`, unit normal :math:`n_f` pointing out of
the foundation, towards the body) uses the foundation's normal, not the body's facet normal:
the penetration is :math:`d = (u\cdot(-n_f) - g - (X - p)\cdot n_f)_+`, the law's gap plus the
geometric one, and the slip :math:`w = \dot u_T - U(X)` with the foundation's velocity
:math:`U` (a translation, or :math:`\omega\,a\times(X - p_a)` for a rotation about an axis
along :math:`n_f`). Body-to-body contact is the contact coupling of the case's
``formulation`` (:func:`fenicsfriction.contact.make_contact`: node-to-segment or mortar) with
the master body's velocity as ``transport`` (one pass, or two passes with weight 1/2 each, the
second with the roles swapped).
"""

from __future__ import annotations

import typing

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem, mesh

from fenicsfriction import _compat, laws
from fenicsfriction.case.schema import SIDES, Case, interface_law
from fenicsfriction.contact import make_contact
from fenicsfriction.forms import (
    NodalSpring,
    Residual,
    body_force,
    centrifugal_softening,
    centripetal_load,
    elastic_support,
    elasticity,
    friction,
    gyroscopic,
    inertia,
    normal_compliance,
    normal_damping,
    surface_traction,
    tangential_part,
)
from fenicsfriction.meshing import vertex_rows
from fenicsfriction.rotation import RigidRotation

__all__ = ["CaseModel", "generated_mesh"]


def _grid(axes: list[np.ndarray], offset: int) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and cells (dolfinx's tensor-product vertex order) of the grid ``axes``."""
    dim = len(axes)
    points = np.meshgrid(*axes, indexing="ij")
    x = np.column_stack([p.ravel(order="F") for p in points])
    shape = tuple(len(a) for a in axes)
    index = np.arange(len(x)).reshape(shape, order="F") + offset
    if dim == 2:
        corners = [index[:-1, :-1], index[1:, :-1], index[:-1, 1:], index[1:, 1:]]
    else:
        corners = [index[i:i + shape[0] - 1 if i == 0 else None,
                         j:j + shape[1] - 1 if j == 0 else None,
                         k:k + shape[2] - 1 if k == 0 else None]
                   for k in (0, 1) for j in (0, 1) for i in (0, 1)]
    return x, np.column_stack([c.ravel(order="F") for c in corners])


def _axes(body: dict, degree: int) -> list[np.ndarray]:
    """A generated body's vertex coordinates along each axis, uniform ones shifted so that a
    node of the degree-``degree`` space lies at every ``nodes_at`` coordinate."""
    axes = [np.asarray(a, dtype=float) for a in body["axes"]]
    for point in body["nodes_at"]:
        for i, target in enumerate(point):
            a = axes[i]
            if np.allclose(np.diff(a), a[1] - a[0], rtol=1e-12, atol=0):  # uniform
                axes[i] = a[0] + vertex_rows(len(a) - 1, degree, a[-1] - a[0], target - a[0])
    return axes


def generated_mesh(case: Case, comm: MPI.Comm) -> tuple[mesh.Mesh, mesh.MeshTags, mesh.MeshTags,
                                                        dict[str, int], dict[str, int]]:
    """The generated bodies in one mesh (no node shared between bodies).

    Returns:
        (mesh, cell tags, facet tags, body name -> cell tag, "BODY.SIDE" -> facet tag); body
        ``i`` (from 0, in the case's order) has cell tag ``i + 1`` and its sides facet tags
        ``10 (i + 1) + k``, k = 1..6 in the order xmin, xmax, ymin, ymax, zmin, zmax.
    """
    dim, degree = case.model["dim"], case.model["degree"]
    bodies = list(case.bodies.items())
    boxes = [_axes(b, degree) for _, b in bodies]
    if comm.rank == 0:
        xs, cells, offset = [], [], 0
        for axes in boxes:
            x, c = _grid(axes, offset)
            xs.append(x)
            cells.append(c)
            offset += len(x)
        x, c = np.vstack(xs), np.vstack(cells)
    else:
        x, c = np.zeros((0, dim)), np.zeros((0, 2**dim), dtype=np.int64)
    msh = _compat.create_mesh_from_arrays(comm, c, x, "quadrilateral" if dim == 2
                                          else "hexahedron")
    tdim = msh.topology.dim
    cell_map = msh.topology.index_map(tdim)
    all_cells = np.arange(cell_map.size_local + cell_map.num_ghosts, dtype=np.int32)
    mid = mesh.compute_midpoints(msh, tdim, all_cells)[:, :dim]
    body_of = np.zeros(len(all_cells), dtype=np.int32)
    for i, axes in enumerate(boxes):
        inside = np.all([(mid[:, k] > a[0]) & (mid[:, k] < a[-1])
                         for k, a in enumerate(axes)], axis=0)
        body_of[inside] = i + 1
    cell_tags = mesh.meshtags(msh, tdim, all_cells, body_of)
    msh.topology.create_connectivity(tdim - 1, tdim)
    facets = mesh.exterior_facet_indices(msh.topology).astype(np.int32)
    fmid = mesh.compute_midpoints(msh, tdim - 1, facets)[:, :dim]
    f_to_c = msh.topology.connectivity(tdim - 1, tdim)
    values = np.zeros(len(facets), dtype=np.int32)
    for j, f in enumerate(facets):
        i = body_of[f_to_c.links(f)[0]] - 1
        axes = boxes[i]
        scale = max(a[-1] - a[0] for a in axes)
        for k, (axis, end) in enumerate(SIDES.values()):
            if axis < dim and np.isclose(fmid[j, axis], axes[axis][-end], rtol=0,
                                         atol=1e-10 * scale):
                values[j] = 10 * (i + 1) + k + 1
    keep = values > 0
    facet_tags = mesh.meshtags(msh, tdim - 1, facets[keep], values[keep])
    names = {name: i + 1 for i, (name, _) in enumerate(bodies)}
    sides = {f"{name}.{side}": 10 * (i + 1) + k + 1 for i, (name, _) in enumerate(bodies)
             for k, side in enumerate(SIDES)}
    return msh, cell_tags, facet_tags, names, sides


class CaseModel:
    """A built case: mesh, space, the one residual and what is read off a state.

    Attributes:
        case: the checked case it was built from.
        msh, V: the mesh and the vector Lagrange space of every body.
        cell_tags, facet_tags: the mesh's tags.
        body_tags: body name -> its cell tag (see :attr:`body_dofs`).
        residual: the one residual (:class:`~fenicsfriction.forms.Residual`).
        law: the interface law with its continuable values as ``fem.Constant``.
        parameters: name -> ``fem.Constant`` of every continuable value the model has
            (:data:`~fenicsfriction.case.schema.CONTINUABLE`).
        contacts: name -> the contact's resultant forms (:meth:`contact_forces`).
        body_contacts: the body-to-body contacts' passes (contact couplings,
            :func:`fenicsfriction.contact.make_contact`).
        springs: the nodal springs (supports of type "spring").
    """

    def __init__(self, case: Case, comm: MPI.Comm = MPI.COMM_WORLD):
        self.case = case
        model, dim = case.model, case.model["dim"]
        self.dim = dim
        if case.mesh is None:
            msh, self.cell_tags, self.facet_tags, self.body_tags, self._surface_tags = \
                generated_mesh(case, comm)
        else:
            msh, self.cell_tags, self.facet_tags = _compat.read_msh(
                str(case.mesh["file"]), comm, 0, dim)
            self.body_tags = {name: self._group(b["group"], dim)
                              for name, b in case.bodies.items()}
            self._surface_tags = {}
        self.msh = msh
        self.V = V = _compat.vector_function_space(msh, model["degree"])
        self.thickness = model["thickness"]

        def constant(value: float) -> fem.Constant:
            return fem.Constant(msh, np.float64(value))

        parameter = case.parameter
        values = case.steady["values"] if case.steady else [case.parameter_value()]
        self.parameters: dict[str, fem.Constant] = {
            name: constant(case.law[name]) for name in ("mu", "c_n", "b_n", "g", "eps")}
        self.parameters["load_scale"] = constant(model["load_scale"])
        law = interface_law(case.law)
        self.with_friction = law.has_friction or (parameter == "mu" and max(values) > 0)
        self.with_damping = law.b_n > 0 or (parameter == "b_n" and max(values) > 0)
        self.law = law.replace(**{k: self.parameters[k] for k in ("mu", "c_n", "b_n", "g", "eps")})
        self.motion: typing.Any = None
        if case.motion is not None and case.motion["type"] == "translation":
            velocity = np.asarray(case.motion["velocity"])
            self.parameters["speed"] = constant(float(np.linalg.norm(velocity)))
            self.motion = self.parameters["speed"] * ufl.as_vector(
                velocity / np.linalg.norm(velocity))
        elif case.motion is not None:
            self.parameters["omega"] = constant(case.motion["omega"])
            self.rotation = RigidRotation(self.parameters["omega"], tuple(case.motion["axis"]),
                                          tuple(case.motion["point"]))
        self.X = ufl.SpatialCoordinate(msh)

        u, u_dot, u_ddot = fem.Function(V, name="displacement"), fem.Function(V), fem.Function(V)
        v = ufl.TestFunction(V)
        self.dx = ufl.Measure("dx", domain=msh, subdomain_data=self.cell_tags)
        self.ds = ufl.Measure("ds", domain=msh, subdomain_data=self.facet_tags)
        self.n = ufl.FacetNormal(msh)
        plane_stress = model["plane"] == "stress"
        terms = []
        for name, body in case.bodies.items():
            dxb = self.dx(self.body_tags[name])
            # a constant, not a float: FFCx 0.5 fails on a bilinear form whose only
            # coefficient is a literal (the mass matrix)
            E, nu, rho = body["E"], body["nu"], constant(body["rho"])
            terms.append(inertia(rho, u_ddot, v, dxb)
                         + elasticity(u, v, E, nu, dxb, plane_stress))
            if body["rayleigh_alpha"] > 0:
                terms.append(inertia(body["rayleigh_alpha"] * rho, u_dot, v, dxb))
            if body["rayleigh_beta"] > 0:
                terms.append(body["rayleigh_beta"] * elasticity(u_dot, v, E, nu, dxb,
                                                                 plane_stress))
            if body["rotating"]:  # Eulerian: the mesh stays, the material turns through it
                w = self.rotation.velocity(self.X)
                terms.append(gyroscopic(rho, w, u_dot, v, dxb)
                             + centrifugal_softening(rho, w, u, v, dxb)
                             + centripetal_load(rho, w, v, dxb))
        bcs, self.springs = self._supports(terms, u, v)
        self._loads(terms, v)
        self.contacts: dict[str, dict[str, typing.Any]] = {}
        self.body_contacts: list[typing.Any] = []
        for contact in case.contacts:
            if contact["kind"] == "foundation":
                terms.append(self._foundation(contact, u, u_dot, v))
            else:
                self._bodies_contact(contact, u, u_dot)
        form = sum(terms[1:], terms[0])
        # the friction terms are linear in μ when μ is the law's constant coefficient: the
        # stability solver's friction switch sets it to 0 to drop their part of K̄ and C
        linear_in_mu = self.with_friction and law.friction_coefficient is None and not \
            isinstance(law.slip_rule, laws.EllipticSlipRule)
        self.residual = Residual(form=constant(self.thickness) * form, u=u, u_dot=u_dot,
                                 u_ddot=u_ddot, v=v, bcs=bcs, springs=self.springs,
                                 couplings=list(self.body_contacts),
                                 friction=self.parameters["mu"] if linear_in_mu else None)

    # --- tags -------------------------------------------------------------------------------
    def _group(self, group: typing.Any, dim: int) -> int:
        """The tag of a physical group given by name or number."""
        if isinstance(group, int):
            return group
        return self.case.physical_names[(dim, group)]

    def surface_tag(self, surface: typing.Any) -> int:
        """The facet tag of a surface: "BODY.SIDE" of a generated body, or a physical group."""
        if self.case.mesh is None:
            return self._surface_tags[surface]
        return self._group(surface, self.dim - 1)

    def body_dofs(self, name: str) -> np.ndarray:
        """The local (unrolled, ghosts included) dofs of body ``name``'s nodes."""
        nodes = _compat.cell_dofs(self.V, self.cell_tags.find(self.body_tags[name]))
        bs = self.V.dofmap.index_map_bs
        return (nodes[:, None] * bs + np.arange(bs)).ravel()

    def body_cells(self) -> dict[str, np.ndarray]:
        """Each body's cells on this rank (local indices), by name: the bodies of
        :class:`fenicsfriction.cea.contributions.FreeInterfaceModes`."""
        return {name: self.cell_tags.find(tag) for name, tag in self.body_tags.items()}

    @property
    def interface_tags(self) -> list[int]:
        """The facet tags of the contacts with rigid foundations: their integrals are the
        interface, left out of a body's own stiffness."""
        return [self.surface_tag(c["surface"]) for c in self.case.contacts
                if c["kind"] == "foundation"]

    def _surface_bodies(self, tag: int) -> list[str]:
        """The bodies whose cells touch the facets tagged ``tag`` (on every rank)."""
        tdim = self.msh.topology.dim
        self.msh.topology.create_connectivity(tdim - 1, tdim)
        f_to_c = self.msh.topology.connectivity(tdim - 1, tdim)
        cells = [f_to_c.links(f)[0] for f in self.facet_tags.find(tag)]
        owned = set(self.cell_tags.values[np.isin(self.cell_tags.indices, cells)].tolist())
        found = set().union(*self.msh.comm.allgather(owned))
        return [name for name, t in self.body_tags.items() if t in found]

    # --- supports and loads -----------------------------------------------------------------
    def _supports(self, terms: list, u: fem.Function, v: ufl.Argument
                  ) -> tuple[list[fem.DirichletBC], list[NodalSpring]]:
        V, fdim = self.V, self.dim - 1
        bcs, springs = [], []
        for support in self.case.supports:
            kind = support["type"]
            if kind == "spring":
                springs.append(NodalSpring.at_point(V, support["point"], support["component"],
                                                    support["stiffness"], support["anchor"]))
                continue
            tag = self.surface_tag(support["on"])
            facets = self.facet_tags.find(tag)
            if kind == "clamped":
                dofs = fem.locate_dofs_topological(V, fdim, facets)
                bcs.append(fem.dirichletbc(np.zeros(self.dim, dtype=np.float64), dofs, V))
            elif kind == "displacement":
                for axis, value in support["values"].items():
                    i = "xyz".index(axis)
                    dofs = fem.locate_dofs_topological(V.sub(i), fdim, facets)
                    bcs.append(fem.dirichletbc(np.float64(value), dofs, V.sub(i)))
            else:
                terms.append(elastic_support(u, v, support["stiffness"],
                                             ufl.zero(self.dim), self.ds(tag)))
        return bcs, springs

    def _loads(self, terms: list, v: ufl.Argument) -> None:
        s = self.parameters["load_scale"]
        for load in self.case.loads:
            kind, value = load["type"], load["value"]
            if kind == "pressure":
                terms.append(surface_traction(-s * value * self.n, v,
                                              self.ds(self.surface_tag(load["on"]))))
            elif kind == "traction":
                terms.append(surface_traction(s * ufl.as_vector(value), v,
                                              self.ds(self.surface_tag(load["on"]))))
            else:
                for name in load["bodies"]:
                    scale = self.case.bodies[name]["rho"] if kind == "gravity" else 1.0
                    terms.append(body_force(s * scale * ufl.as_vector(value), v,
                                            self.dx(self.body_tags[name])))

    def _load_resultants(self) -> list[np.ndarray]:
        """Each applied load's resultant force (times the thickness in 2D) at the current load
        factor."""
        s = float(self.parameters["load_scale"].value)
        one = fem.Constant(self.msh, np.float64(1.0))
        resultants = []
        for load in self.case.loads:
            value = np.asarray(load["value"])
            total = np.zeros(self.dim)
            if load["type"] == "pressure":
                ds = self.ds(self.surface_tag(load["on"]))
                total += [-value * self._scalar(self.n[i] * ds) for i in range(self.dim)]
            elif load["type"] == "traction":
                total += value * self._scalar(one * self.ds(self.surface_tag(load["on"])))
            else:
                for name in load["bodies"]:
                    rho = self.case.bodies[name]["rho"] if load["type"] == "gravity" else 1.0
                    total += rho * value * self._scalar(one * self.dx(self.body_tags[name]))
            resultants.append(s * self.thickness * total)
        return resultants

    def load_resultant(self) -> np.ndarray:
        """The total applied load (forces, times the thickness in 2D) at the current load
        factor, for the initial guess."""
        return sum(self._load_resultants(), np.zeros(self.dim))

    def load_magnitude(self) -> float:
        """The sum of the loads' resultant magnitudes: the force scale of the residual's
        tolerances (the resultant itself vanishes where loads balance, e.g. two brake pads
        pressed from both sides)."""
        return float(sum(np.linalg.norm(r) for r in self._load_resultants()))

    # --- contacts -----------------------------------------------------------------------------
    def foundation_velocity(self, x: typing.Any) -> typing.Any:
        """The foundation's (or master body's) velocity at the points ``x`` (UFL)."""
        if self.case.motion is None:
            return ufl.zero(self.dim)
        if self.case.motion["type"] == "translation":
            return self.motion
        return self.rotation.velocity(x)

    def _foundation(self, contact: dict, u: fem.Function, u_dot: fem.Function,
                    v: ufl.Argument) -> ufl.Form:
        """Normal compliance, normal damping and friction against a rigid plane."""
        n_f = np.asarray(contact["normal"]) / np.linalg.norm(contact["normal"])
        n = fem.Constant(self.msh, -n_f)  # a literal vector makes FFCx 0.5 fail on C
        tag = self.surface_tag(contact["surface"])
        rule = contact["quadrature_rule"]
        metadata: dict[str, typing.Any] = {}
        if rule == "nodal":
            simplex = self.msh.topology.cell_type in (mesh.CellType.triangle,
                                                       mesh.CellType.tetrahedron)
            metadata = _compat.nodal_quadrature(self.dim - 1, simplex=simplex)
        else:
            if contact["quadrature_degree"] is not None:
                metadata["quadrature_degree"] = contact["quadrature_degree"]
            if rule == "GLL":
                metadata["quadrature_rule"] = "GLL"
        ds = self.ds(tag, metadata=metadata)
        geometric = ufl.dot(self.X - ufl.as_vector(contact["point"]), ufl.as_vector(n_f))
        law = self.law.replace(g=self.law.g + geometric)
        terms = normal_compliance(u, v, n, law, ds)
        if self.with_damping:
            terms += normal_damping(u, u_dot, v, n, law, ds)
        U = self.foundation_velocity(self.X) if contact["moving"] else ufl.zero(self.dim)
        d = laws.penetration(ufl.dot(u, n), law.g)
        traction = None
        if self.with_friction:
            terms += friction(u, u_dot, v, n, law, U, ds)
            traction = law.friction_traction(d, tangential_part(u_dot, n) - U)
        self.contacts[contact["name"]] = {
            "pressure": law.normal_traction(d, ufl.dot(u_dot, n)), "traction": traction,
            "ds": ds, "weight": self.thickness, "normal": -n_f,
            "bodies": self._surface_bodies(tag)}
        return terms

    def _bodies_contact(self, contact: dict, u: fem.Function, u_dot: fem.Function) -> None:
        """Contact between two bodies (the case's ``formulation``), the master body moving
        with the case's motion."""
        slave, master = (self.surface_tag(contact[k]) for k in ("slave", "master"))
        passes = contact["passes"]
        law = self.law if self.with_friction else self.law.replace(
            mu=0.0, friction_coefficient=None, slip_rule=None)
        weight = self.thickness / passes
        moving = contact["moving"]
        for k, (s, m) in enumerate(((slave, master), (master, slave))[:passes]):
            # the second pass's slave is the moving body: its relative velocity gains +U
            transport = None
            if moving:
                transport = (1 - 2 * k) * self.foundation_velocity(self.X)
            pair = make_contact(contact["formulation"], u, self.facet_tags, slave=s, master=m,
                                law=law, velocity=u_dot, fields=[u_dot], transport=transport,
                                weight=weight)
            self.body_contacts.append(pair)
            if k == 0:
                self.contacts[contact["name"]] = {
                    "pressure": pair.pressure, "traction": pair.traction, "ds": pair.ds,
                    "weight": self.thickness, "normal": None, "pair": pair,
                    "bodies": self._surface_bodies(slave)}

    def _scalar(self, form: typing.Any) -> float:
        """An assembled scalar form, summed over the ranks."""
        return self.msh.comm.allreduce(fem.assemble_scalar(_compat.form(form)))

    # --- a state ------------------------------------------------------------------------------
    def initial_guess(self) -> None:
        """Every body pressed into its foundation (or master) by a uniform penetration: the
        contact's ``initial_penetration``, else the one of the mean pressure the loads exert
        on the contact surface; then the Dirichlet values."""
        u = self.residual.u
        u.x.array[:] = 0.0
        for contact in self.case.contacts:
            entry = self.contacts[contact["name"]]
            if entry["normal"] is not None:
                normal = np.asarray(entry["normal"], dtype=float)  # outward, into the foundation
            else:  # the slave surface's mean outward normal
                normal = np.array([self._scalar(self.n[i] * entry["ds"])
                                   for i in range(self.dim)])
                normal /= max(np.linalg.norm(normal), 1e-300)
            d0 = contact["initial_penetration"]
            if d0 is None:
                one = fem.Constant(self.msh, np.float64(1.0))
                area = self.thickness * self._scalar(one * entry["ds"])
                pressure = max(float(self.load_resultant() @ normal), 0.0) / area
                d0 = self.case.law["g"] + laws.InterfaceLaw(
                    c_n=self.case.law["c_n"], m_n=self.case.law["m_n"]).uniform_penetration(
                    pressure)
            shift = d0 * normal
            for name in entry["bodies"]:
                dofs = self.body_dofs(name)
                u.x.array[dofs] = np.tile(shift, len(dofs) // self.dim)
        for bc in self.residual.bcs:
            _compat_set_bc(u, bc)
        u.x.scatter_forward()

    def contact_forces(self) -> dict[str, dict[str, typing.Any]]:
        """Each contact's resultants at the current state (every rank): the normal force
        ``normal_force`` = ∫ p, the friction force vector ``friction_force`` = ∫ t, and for a
        rotating foundation the friction torque about its axis ``friction_torque`` =
        ∫ ((X + u - p_a) × t) · a (times the thickness in 2D)."""
        out: dict[str, dict[str, typing.Any]] = {}
        for name, entry in self.contacts.items():
            if "pair" in entry:
                entry["pair"].update(search=False)
            ds, scale = entry["ds"], entry["weight"]
            row: dict[str, typing.Any] = {
                "normal_force": scale * self._scalar(entry["pressure"] * ds)}
            t = entry["traction"]
            force = np.zeros(self.dim) if t is None else np.array(
                [scale * self._scalar(t[i] * ds) for i in range(self.dim)])
            row["friction_force"] = force.tolist()
            if self.case.motion is not None and self.case.motion["type"] == "rotation" \
                    and self.dim == 3 and t is not None:
                a = np.asarray(self.rotation.axis)
                r = self.X + self.residual.u - ufl.as_vector(self.rotation.point)
                row["friction_torque"] = scale * self._scalar(ufl.dot(ufl.cross(r, t),
                                                                 ufl.as_vector(a)) * ds)
            out[name] = row
        return out


def _compat_set_bc(u: fem.Function, bc: fem.DirichletBC) -> None:
    """The Dirichlet values into ``u`` (local array, ghosts included)."""
    import dolfinx.fem.petsc
    dolfinx.fem.petsc.set_bc(_compat.petsc_vec(u), [bc])
