r"""The block on a moving belt as a finite element model: mesh, facet tags, the residual.

The scene's parameters and modelling choices are in :mod:`fenicsfriction.studies.block.data`;
what is read off a state (resultants, energies, probes) in
:mod:`fenicsfriction.studies.block.observables`, which :class:`BlockModel`'s methods call.
"""

from __future__ import annotations

import typing

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem, mesh

from fenicsfriction import _compat, laws
from fenicsfriction.forms import (
    NodalSpring,
    Residual,
    body_force,
    elasticity,
    friction,
    inertia,
    normal_compliance,
    normal_damping,
    normal_part,
    surface_traction,
    tangential_part,
)
from fenicsfriction.laws import check
from fenicsfriction.meshing import vertex_rows
from fenicsfriction.studies.block import observables
from fenicsfriction.studies.block.data import CONTACT, LEFT, QUADRATURE, RIGHT, TOP, BlockOnBelt

if typing.TYPE_CHECKING:
    from fenicsfriction.steady import SteadySolver

__all__ = ["BlockModel"]


class _FixedParameter(fem.Constant):
    """A ``fem.Constant`` the residual does not contain: setting any other value than the one
    it was built with raises ``ValueError`` naming it (instead of being silently ignored)."""

    def __init__(self, domain: mesh.Mesh, value: float, name: str, reason: str):
        super().__init__(domain, np.float64(value))
        self._name, self._reason = name, reason

    @property
    def value(self) -> typing.Any:
        """The value (read-only in effect: see the class docstring)."""
        return self._cpp_object.value

    @value.setter
    def value(self, v: typing.Any) -> None:
        if np.any(np.asarray(v) != self._cpp_object.value):
            raise ValueError(f"{self._name}={v!r} is invalid: {self._reason}")


class BlockModel:
    """A built block scene: mesh, function space, the residual and post-processing.

    Attributes:
        scene: the parameters it was built from.
        msh, V: mesh and vector Lagrange space.
        residual: the one residual (see :mod:`fenicsfriction.forms`).
        mu, eps, thickness: ``fem.Constant`` — change ``mu.value`` / ``eps.value`` and re-solve
            (μ only when the friction term is there with a constant μ; otherwise a new value
            raises ``ValueError``).
        law: the scene's interface law holding the model's ``fem.Constant`` (μ, c_n, g, ε):
            the one law of the residual's terms and of the tractions read off a state.
        ds_contact: measure on Γ_C with the fixed quadrature degree used everywhere.
        spring: the driver's :class:`~fenicsfriction.forms.NodalSpring`.
        friction_factor: the ``fem.Constant`` the friction terms are linear in
            (:attr:`fenicsfriction.forms.Residual.friction`): ``mu`` when the friction bound is
            μ c_n, else a factor of value 1 multiplying the friction term (a friction
            coefficient law, an elliptic slip rule), which the stability solver alone sets to
            0 while it assembles the parts it drops; None without friction.
    """

    CONTACT = CONTACT
    #: the steady solver's ``search_rounds`` for this model's contact couplings (none here)
    search_rounds = 1

    def __init__(self, scene: BlockOnBelt, comm: MPI.Comm, with_friction: bool | None):
        """Mesh the block, tag its faces and assemble the residual's UFL terms.

        Args:
            scene: the parameters.
            comm: communicator the mesh is distributed over.
            with_friction: include the friction term (None: when the law has friction).
        """
        self.scene = s = scene
        law = s.law
        if with_friction is None:
            with_friction = law.has_friction
        self.with_friction = with_friction
        msh, self.facet_tags, self.cell_tags = self._mesh(comm)
        self.msh = msh
        self.V = V = _compat.vector_function_space(msh, s.degree)
        tol = 1e-10 * max(s.L, s.H)
        ds = ufl.Measure("ds", domain=msh, subdomain_data=self.facet_tags)
        self.dx = self._block_measure()
        self.ds_contact = ds(CONTACT, metadata=(
            _compat.nodal_quadrature(msh.topology.dim - 1) if s.contact_quadrature == "nodal"
            else QUADRATURE[s.contact_quadrature](s.degree)[1]))

        def constant(value: float) -> fem.Constant:
            return fem.Constant(msh, np.float64(value))

        # 2D integrals are per unit breadth: times B0 makes every force a total
        thickness = s.B0 if s.dim == 2 else 1.0
        self.eps, self.thickness = constant(law.eps), constant(thickness)
        if not with_friction:
            self.mu = _FixedParameter(msh, law.mu, "mu", "the model was built without friction "
                                      "(with_friction=False, or mu = 0 and no friction law): "
                                      "build it with_friction=True to step mu")
        elif law.friction_coefficient is not None:
            self.mu = _FixedParameter(msh, law.mu, "mu", "the friction coefficient is the "
                                      f"velocity-dependent (or pressure-dependent) law "
                                      f"{law.friction_coefficient!r}, not mu")
        else:
            self.mu = constant(law.mu)
        e_x, e_y = np.eye(s.dim)[0], np.eye(s.dim)[1]
        self.c_n = constant(law.c_n)
        # exponents stay Python floats: UFL differentiates d**Constant very slowly
        self.m_n, self.m_T = float(law.m_n), float(law.m_T)
        self.gap = constant(law.g)
        self.law = law.replace(c_n=self.c_n, m_n=self.m_n, mu=self.mu, m_T=self.m_T,
                               g=self.gap, eps=self.eps)
        self.belt_velocity = fem.Constant(msh, s.belt_direction * s.belt_speed * e_x)
        volume = s.L * s.H * s.B0
        self.rho = constant(s.mass / volume)
        self.gravity = fem.Constant(msh, -s.weight / volume * e_y)
        self.top_traction = fem.Constant(msh, -s.top_pressure * e_y)
        self.normal = ufl.FacetNormal(msh)
        self.friction_factor = self._friction_factor()

        u, u_dot, u_ddot = fem.Function(V, name="displacement"), fem.Function(V), fem.Function(V)
        v = ufl.TestFunction(V)
        terms = inertia(self.rho, u_ddot, v, self.dx) \
            + elasticity(u, v, *self._moduli(), self.dx) \
            + body_force(self.gravity, v, self.dx)
        if s.top_pressure > 0:
            terms += surface_traction(self.top_traction, v, ds(TOP))
        interface, couplings = self._interface(u, u_dot, u_ddot, v)
        if interface is not None:
            terms += interface
        self.spring = NodalSpring.at_point(V, (0.0, s.spring_height, s.B0 / 2)[:s.dim], 0, s.K_x)
        bcs = []
        if s.dim == 3:
            Vz, _ = V.sub(2).collapse()
            mid = fem.locate_dofs_geometrical(
                (V.sub(2), Vz), lambda x: np.isclose(x[2], s.B0 / 2, atol=tol))
            zero = fem.Function(Vz)
            bcs.append(fem.dirichletbc(zero, mid, V.sub(2)))
        bcs += self._supports()
        self.residual = Residual(form=self.thickness * terms, u=u, u_dot=u_dot, u_ddot=u_ddot,
                                 v=v, bcs=bcs, springs=[self.spring], couplings=couplings,
                                 friction=self.friction_factor)
        self._functionals: dict = {}
        self._contact_y = self._contact_dofs()

    # --- what a scene on another foundation overrides (see scenes.block_on_slab) ------------
    def _mesh(self, comm: MPI.Comm) -> tuple[mesh.Mesh, mesh.MeshTags, mesh.MeshTags | None]:
        """(mesh, facet tags, cell tags or None): the block alone, its faces tagged CONTACT
        (y = 0), TOP, LEFT and RIGHT; vertex rows shifted so a node is at the spring height."""
        s = self.scene
        nx, ny = 4 * s.refine, 3 * s.refine
        if s.dim == 2:
            msh = _compat.create_rectangle(comm, (0.0, 0.0), (s.L, s.H), (nx, ny))
        else:
            msh = _compat.create_box(comm, (0.0, 0.0, 0.0), (s.L, s.H, s.B0),
                                     (nx, ny, s.nz * s.refine))
        rows = vertex_rows(ny, s.degree, s.H, s.spring_height)
        msh.geometry.x[:, 1] = np.interp(msh.geometry.x[:, 1], np.linspace(0, s.H, ny + 1), rows)
        fdim = msh.topology.dim - 1
        tol = 1e-10 * max(s.L, s.H)
        marked = [(CONTACT, lambda x: np.isclose(x[1], 0.0, atol=tol)),
                  (TOP, lambda x: np.isclose(x[1], s.H, atol=tol)),
                  (LEFT, lambda x: np.isclose(x[0], 0.0, atol=tol)),
                  (RIGHT, lambda x: np.isclose(x[0], s.L, atol=tol))]
        facets, values = [], []
        for tag, where in marked:
            f = mesh.locate_entities_boundary(msh, fdim, where)
            facets.append(f)
            values.append(np.full(len(f), tag, dtype=np.int32))
        indices, tags = np.concatenate(facets), np.concatenate(values)
        order = np.argsort(indices)
        return msh, mesh.meshtags(msh, fdim, indices[order], tags[order]), None

    def _moduli(self) -> tuple[typing.Any, typing.Any]:
        """Young's modulus and Poisson's ratio of the block: the scene's E and ν (a layered
        block returns cell-wise fields)."""
        return self.scene.E, self.scene.nu

    def _block_measure(self) -> ufl.Measure:
        """The volume measure of the block (the whole mesh here)."""
        return ufl.Measure("dx", domain=self.msh)

    def _friction_factor(self) -> fem.Constant | None:
        """The constant the friction terms are linear in (see ``friction_factor``)."""
        if not self.with_friction:
            return None
        law = self.scene.law
        if law.friction_coefficient is None \
                and not isinstance(law.slip_rule, laws.EllipticSlipRule):
            return self.mu
        return fem.Constant(self.msh, np.float64(1.0))

    def _interface(self, u: fem.Function, u_dot: fem.Function, u_ddot: fem.Function,
                   v: ufl.Argument) -> tuple[ufl.Form | None, list]:
        """(UFL terms per unit breadth, couplings) of the contact and of any other body: here
        normal compliance, normal damping and friction against the rigid belt on Γ_C."""
        law, n, ds_c = self.law, self.normal, self.ds_contact
        terms = normal_compliance(u, v, n, law, ds_c)
        if law.b_n > 0:
            terms += normal_damping(u, u_dot, v, n, law, ds_c)
        if self.with_friction:
            term = friction(u, u_dot, v, n, law, self.belt_velocity, ds_c)
            terms += term if self.friction_factor is self.mu else self.friction_factor * term
        return terms, []

    def _supports(self) -> list[fem.DirichletBC]:
        """Dirichlet conditions besides the 3D mid-plane's (none: the belt holds the block
        through the contact only)."""
        return []

    def _contact_dofs(self) -> np.ndarray:
        """The owned y-dofs of the contact nodes, where :meth:`nodal_contact` is evaluated."""
        V, fdim = self.V, self.msh.topology.dim - 1
        dofs = fem.locate_dofs_topological(V.sub(1), fdim, self.facet_tags.find(CONTACT))
        return dofs[dofs < V.dofmap.index_map.size_local * self.scene.dim]

    def nodal_contact(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(penetration d, tangential slip u̇_x - U_T, approach rate ḋ where d > 0) at the
        contact nodes this rank owns (the y-dofs ``_contact_y``). Collective in scenes whose
        contact is searched (call it on every rank)."""
        s = self.scene
        u, v = self.residual.u.x.array, self.residual.u_dot.x.array
        y = self._contact_y
        d = np.maximum(-u[y] - s.law.g, 0.0)
        slip = v[y - 1] - s.belt_direction * s.belt_speed
        return d, slip, np.where(d > 0, -v[y], 0.0)

    def damping_pressure(self) -> typing.Any:
        """UFL normal damping pressure b_n d^{l_n} ḋ on Γ_C (zero at rest)."""
        return self.law.damping_pressure(self.penetration(),
                                         normal_part(self.residual.u_dot, self.normal))

    def energy_forms(self) -> dict[str, ufl.Form]:
        """Kinetic and strain energies per unit breadth (UFL) of every body of the model."""
        u, u_dot = self.residual.u, self.residual.u_dot
        return {"kinetic": 0.5 * self.rho * ufl.inner(u_dot, u_dot) * self.dx,
                "strain": 0.5 * elasticity(u, u, *self._moduli(), self.dx)}

    def interface_power_forms(self) -> dict[str, ufl.Form]:
        """Power per unit breadth (UFL) of the friction and normal-damping tractions on the
        bodies: the residual's own terms with the velocity as test function, sign reversed."""
        R, n, law = self.residual, self.normal, self.law
        forms = {}
        if self.with_friction:
            forms["friction"] = -friction(R.u, R.u_dot, R.u_dot, n, law, self.belt_velocity,
                                          self.ds_contact)
        if law.b_n > 0:
            forms["damping"] = -normal_damping(R.u, R.u_dot, R.u_dot, n, law, self.ds_contact)
        return forms

    # --- the tractions on Γ_C (UFL), those of the residual -----------------------------------
    def penetration(self, n: typing.Any = None) -> typing.Any:
        """UFL penetration d = (u_n - g)_+ (``n``: normal to use, default the facet normal)."""
        n = self.normal if n is None else n
        return laws.penetration(normal_part(self.residual.u, n), self.gap)

    def pressure(self, n: typing.Any = None) -> typing.Any:
        """UFL normal contact pressure c_n d^{m_n} (elastic part)."""
        return self.law.pressure(self.penetration(n))

    def friction_traction(self, n: typing.Any = None) -> typing.Any:
        """UFL friction traction on the body at the current velocity ``u_dot`` (zero in steady
        sliding), a vector tangent to Γ_C: the law's
        (:meth:`fenicsfriction.laws.InterfaceLaw.friction_traction`)."""
        if not self.with_friction:
            return ufl.zero(self.scene.dim)
        n = self.normal if n is None else n
        w = tangential_part(self.residual.u_dot, n) - self.belt_velocity
        return self.law.friction_traction(self.penetration(n), w)

    def contact_traction(self) -> typing.Any:
        """UFL traction of the foundation on the body, valid in cells (for output fields).

        Uses the contact face's constant normal -e_y instead of the facet normal so it can be
        interpolated; it is meaningful only on Γ_C.
        """
        n = ufl.as_vector(-np.eye(self.scene.dim)[1])
        return -self.pressure(n) * n + self.friction_traction(n)

    def band_damping(self) -> ufl.Form | None:
        """Linear form of the nodal dashpots of sticking nodes (per tangential dof), for the
        explicit scheme's stable step; None without friction.

        Inside the regularisation band the friction term of the residual is a tangential
        damping
        :math:`\\partial J_\\varepsilon/\\partial \\dot u = c_T d^{m_T} \\phi_\\varepsilon''(0) I`
        on :math:`\\Gamma_C`; the form is that operator applied to the unit tangential field
        (its row sums): :math:`\\int c_T(0) d^{m_T} \\phi_\\varepsilon''(0) v_T` with the law's
        :math:`\\phi_\\varepsilon''` (:data:`fenicsfriction.laws.REGULARISATIONS`), 1/ε for both
        regularisations. (``ufl.derivative`` of the term itself is 0/0 at zero slip, where
        :math:`|w|` is not differentiable.)
        """
        if not self.with_friction:
            return None
        v = self.residual.v
        tangential = sum(v[i] for i in range(self.scene.dim) if i != 1)
        return self.thickness * self.law.friction_bound(self.penetration()) \
            * self.law.stick_curvature() * tangential * self.ds_contact

    # --- preparing a state -----------------------------------------------------------------------
    @property
    def force_scale(self) -> float:
        """Total load pressing the block down [force]: the scale of the residual's entries."""
        return self.scene.contact_pressure * self.scene.L * self.scene.B0

    def solver_options(self) -> dict[str, float]:
        """SNES tolerances scaled to this scene: residual entries are nodal forces, 1e-10 of the
        load. The solver raises it to the round-off floor where needed (see SteadySolver)."""
        return {"snes_atol": 1e-10 * self.force_scale}

    def initial_guess(self) -> None:
        """Uniform penetration under the mean pressure and the spring balancing μ W."""
        s = self.scene
        d0 = s.law.uniform_penetration(s.contact_pressure)
        ux = s.belt_direction * float(self.mu.value) * s.contact_pressure * s.L * s.B0 / s.K_x
        value = np.array([ux, -(d0 + s.law.g), 0.0][:s.dim])
        self.residual.u.interpolate(lambda x: np.tile(value[:, None], (1, x.shape[1])))

    def slide_to(self, mu: float, solver: SteadySolver, step: float = 0.05
                 ) -> list[dict[str, typing.Any]]:
        """Steady sliding at ``mu`` by continuation: μ ramps from 0 (a first solve from the
        current ``u``) up to ``mu`` in equal increments <= ``step``.

        Args:
            mu: the friction coefficient to reach, >= 0.
            solver: the steady solver of this model's residual.
            step: the largest increment of μ.

        Returns:
            The continuation's rows (:func:`fenicsfriction.steady.continuation`).
        """
        from fenicsfriction.steady import continuation
        check("mu", mu, bool(np.isfinite(mu)) and mu >= 0, "must be a finite number >= 0")
        check("step", step, step > 0, "must be > 0")
        return continuation(solver, self.mu, np.linspace(0.0, mu, 1 + int(np.ceil(mu / step))))

    def perturb_normal_velocity(self, value: float) -> None:
        """Add ``value`` [cm/s] to the normal (y) component of u̇ at every node."""
        self.residual.u_dot.x.array[1::self.V.dofmap.index_map_bs] += value

    # --- observables (see fenicsfriction.studies.block.observables) -------------------------------
    def quantities(self) -> observables.BlockQuantities:
        """Resultants and penetration extremes of the current state."""
        return observables.quantities(self)

    def energies(self) -> observables.Energies:
        """Kinetic, strain, interface, spring and load-potential energies of the state."""
        return observables.energies(self)

    def powers(self) -> observables.Powers:
        """Power of the friction and normal-damping tractions on the body."""
        return observables.powers(self)

    def contact_states(self) -> observables.ContactStates:
        """Counts of open, sticking and slipping contact nodes."""
        return observables.contact_states(self)

    def centre_of_mass(self) -> observables.CentreOfMass:
        """Displacement and velocity of the centre of mass, mean rotation."""
        return observables.centre_of_mass(self)

    def probe(self, x: float) -> observables.ProbeValues:
        """Values at the contact node nearest to abscissa ``x`` (same on every rank)."""
        return observables.probe(self, x)

    def dynamics_observer(self, probe_x: float | None = None
                          ) -> typing.Callable[[float], dict[str, typing.Any]]:
        """``observe(t) -> dict`` for the time integrators (one flat table row per step)."""
        return observables.dynamics_observer(self, probe_x)
