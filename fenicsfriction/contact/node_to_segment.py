r"""The interface law between two deformable bodies: node-to-segment contact elements.

Pop puts the law of Martins & Oden (1986) — normal compliance, normal damping,
regularised friction — between a slave node :math:`s` and its closest point on the master
surface, in contact elements of one slave node and the two (2D) or three (3D) nodes of the
master facet. With the projection of :mod:`fenicsfriction.contact.kinematics`
(:math:`N_a(\xi)`, :math:`n`, :math:`g`), the penetration is :math:`d = (-g)_+` and the
relative velocity :math:`w = \dot u_s - (U_T + \sum_a N_a \dot u_a)` (``transport`` :math:`U_T`:
a rigid velocity of the master body, e.g. a belt's); the force on the slave node is

.. math:: f = \big(c_n d^{m_n} + b_n d^{l_n} \dot d\big)\, n + t_T(d, w_T), \qquad
          \dot d = -w\cdot n,

:math:`t_T` the regularised friction traction of :func:`fenicsfriction.laws.friction_traction`
on the tangential part :math:`w_T`, and :math:`-f` goes to the master nodes with the weights
:math:`N_a(\xi)`. Its virtual power is

.. math:: R_c(v) = -\int_{\Gamma_s} f\cdot\Big(v_s - \sum_a N_a(\xi)\, v_a\Big)\, ds_h,

:math:`ds_h` the nodal (trapezoidal) rule on the slave facets, so that each slave node carries
its tributary length/area. The master nodes' displacements (velocities, ...) enter as fields
of a space ``W`` at the slave nodes, :math:`U = Q u`, ``Q`` the pairing of
:mod:`fenicsfriction.contact.pairing`. So the term is two UFL forms, ``F`` (test functions of
``V``) and ``G`` (of ``W``), and the residual and Jacobian are

.. math:: R = F + Q^T G, \qquad
          \frac{dR}{du} = F_{,u} + F_{,U} Q + Q^T G_{,u} + Q^T G_{,U} Q,

every block an :func:`ufl.derivative` (the closest point's motion along the facet included),
chained through ``Q`` with PETSc's sparse products. The pairing is searched again at every
residual evaluation (finite sliding); ``frozen=True`` keeps it (for derivative tests).
"""

from __future__ import annotations

import copy
import functools
import time
import typing

from petsc4py import PETSc

import dolfinx.fem.petsc
import numpy as np
import ufl
from dolfinx import fem, mesh

from fenicsfriction import _compat, laws
from fenicsfriction.assembly import assemble_into, assemble_owned
from fenicsfriction.contact.kinematics import Projection, project
from fenicsfriction.contact.pairing import Pairing, facet_nodes

__all__ = ["ENFORCEMENTS", "ContactOperator", "MirroredContact", "NodalValues", "NodeToSegment",
           "discrete_gradient", "solve_with_search"]

#: how the law is enforced at the slave nodes: ``"compliance"`` (normal compliance, friction
#: regularised on the slip rate: Martins & Oden 1986) and ``"perturbed-lagrangian"`` (Pop,
#: eq. 27: normal and tangential penalties κ_N = c_n, κ_T with their multipliers eliminated
#: node by node)
ENFORCEMENTS = ("compliance", "perturbed-lagrangian")

Value = typing.Any


class MirroredContact:
    r"""What node-to-segment and mortar contact share: a contact whose forms read the fields'
    mirrors :math:`Q f` (Functions kept up to date by :meth:`update`), its residual
    :math:`F + Q^T G` and Jacobian chained by :class:`ContactOperator`.

    A subclass sets ``u``, ``V``, ``W``, ``mirrors``, ``pairing`` (with ``search(u)`` and
    ``Q``), ``ds`` (the nodal rule on the slave surface), ``nodal_space``, ``F`` (or None),
    ``G``, ``m_n``, ``frozen``, ``searched`` and ``search_pending``, and gives
    :meth:`frequency_bound`.
    """

    u: fem.Function
    V: fem.FunctionSpace
    mirrors: dict[fem.Function, fem.Function]
    pairing: typing.Any
    ds: typing.Any
    F: typing.Any
    G: typing.Any
    frozen: bool
    searched: bool
    search_pending: bool
    search_every_residual: bool
    W: fem.FunctionSpace  # where the mirrors live
    m_n: typing.Any
    nodal_space: fem.FunctionSpace  # scalar Lagrange functions of one value per node

    def frequency_bound(self, lumped_mass: PETSc.Vec) -> float:
        """An upper bound of the contact springs' frequency² on the lumped mass (a
        subclass's)."""
        raise NotImplementedError

    def _check_mirrored(self, velocity: typing.Any, fields: typing.Sequence[fem.Function]
                        ) -> None:
        """Refuse a velocity that depends on a Function without a mirror (not u or a field)."""
        unmirrored = set(ufl.algorithms.extract_coefficients(velocity)) - {self.u, *fields}
        laws.check("fields", [f.name for f in fields], not unmirrored,
                   "every Function the velocity depends on besides u (missing: "
                   f"{', '.join(sorted(f.name for f in unmirrored))})")

    @functools.cached_property
    def nodal_weights(self) -> np.ndarray:
        """Each owned node's weight in the nodal rule on the slave surface, 0 off it: the
        integral of the node's basis function (its tributary length or area for
        node-to-segment; :math:`A_j = \\int \\psi_j` for mortar)."""
        return assemble_owned(_compat.form(ufl.TestFunction(self.nodal_space) * self.ds))

    def nodal_values(self, expressions: typing.Sequence[typing.Any]) -> NodalValues:
        """The values of UFL scalars at the slave nodes (compiled once, evaluated on call)."""
        return NodalValues(self, expressions)

    def friction_bound(self) -> typing.Any:
        """The law's friction bound :math:`c_T d^{m_T}` at the slave nodes (UFL), ``None``
        without friction or with the perturbed Lagrangian (its bound is not the law's
        labelled one)."""
        bounds = [b for form in (self.F, self.G) if form is not None
                  for b in laws.friction_bounds(form)]
        return bounds[0] if bounds else None

    def with_friction_bound(self, bound: typing.Any) -> typing.Self:
        """A copy of this contact whose forms ``F``, ``G`` have ``bound`` (UFL) in place of
        the friction bound; it shares the pairing and the mirrors with this one."""
        twin = copy.copy(self)
        twin.F, twin.G = (None if form is None
                          else laws.substitute_friction_bound(form, lambda _: bound)
                          for form in (self.F, self.G))
        return twin

    def search(self) -> bool:
        """Pair the surfaces at the current ``u``; True if the pairing changed."""
        return self.pairing.search(self.u)

    def update(self, search: bool = True) -> None:
        """Pair the surfaces at the current ``u`` (unless frozen) and refresh the mirrors."""
        if search and not (self.frozen and self.searched):
            self.search()
            self.searched = True
            self.search_pending = False
        Q = self.pairing.Q
        assert Q is not None, "search before the first use"
        for f, mirror in self.mirrors.items():
            Q.mult(_compat.petsc_vec(f), _compat.petsc_vec(mirror))
            mirror.x.scatter_forward()

    def operator(self, derivatives: dict[fem.Function, Value],
                 rest: typing.Sequence[fem.Function] = (),
                 jit_cache_dir: str | None = None) -> ContactOperator:
        """The compiled residual and Jacobian of this contact.

        Args:
            derivatives: the fields to differentiate with and each one's weight (``{u: 1}``
                for a stiffness, ``{u: 1, u_dot: shift}`` for a time step's Jacobian).
            rest: fields set to zero, with their mirrors, after differentiating (``u_dot`` in
                steady sliding and in the linearisation about it).
        """
        zero = ufl.zero(*self.u.ufl_shape)
        at_rest = {}
        for f in rest:
            at_rest[f] = zero
            if f in self.mirrors:
                at_rest[self.mirrors[f]] = ufl.zero(*self.mirrors[f].ufl_shape)
        return ContactOperator(self, derivatives, at_rest, jit_cache_dir)



class NodeToSegment(MirroredContact):
    r"""Slave nodes of one tagged surface against the facets of another, same residual.

    A :class:`~fenicsfriction.coupling.Coupling`: what the solvers ask of ``Residual.couplings``.

    Args:
        u: the displacement (degree-1 Lagrange vectors on the mesh holding both bodies).
        facet_tags: the mesh's facet tags.
        slave, master: the tags of the slave and master surfaces.
        law: the interface law (:class:`fenicsfriction.laws.InterfaceLaw`, its values numbers
            or ``fem.Constant`` through ``law.replace``); a law without friction
            (``law.has_friction`` false: μ = 0, no coefficient law) has no friction term.
        velocity: the slave velocity, a UFL vector of Functions of ``V`` (``u_dot`` in
            dynamics, ``(u - u_old) / dt`` in a quasi-static increment); ``None``: no velocity
            (frictionless statics).
        fields: the Functions of ``V`` that ``velocity`` depends on, besides ``u``; each gets
            a mirror in ``W`` (its values at the master nodes), replacing it on the master side.
        transport: the master body's rigid velocity :math:`U_T` (a vector; default zero).
        weight: the factor of the term (1/2 for each pass of two-pass contact).
        frozen: keep the pairing of the first search (derivative tests).
        enforcement: one of :data:`ENFORCEMENTS`. The perturbed Lagrangian's multipliers
            are nodal and enter their own equations quadratically, so they are eliminated at
            each slave node: λ_N = κ_N (-g)_+ (linear compliance, ``c_n`` = κ_N, m_n = 1) and
            λ_T = κ_T times the slip increment from the last committed λ_T (:meth:`commit`),
            returned to μλ_N in slide. The law's ε is then unused.
        penalty_T: the tangential penalty κ_T [force/length³] (perturbed Lagrangian).
        time_step: the increment's duration, slip increment = velocity × time_step
            (perturbed Lagrangian; 1 with a quasi-static velocity (u - u_old)/1).
        step_from: the displacement u_n at the start of a time step of the midpoint rule
            (:class:`~fenicsfriction.dynamics.DynamicsSolver` with ``energy_consistent``),
            ``u`` then holding the step's midpoint (u_n + u_{n+1})/2: the elastic pressure
            becomes the discrete gradient of the compliance's potential between the two ends
            (:meth:`_discrete_gradient`), so that the step's normal force does exactly the
            work φ(d_{n+1}) − φ(d_n); ``None`` (default): the pressure at ``u``.
        search: when the pairing is searched again: ``"solve"`` (default) once at the start
            of each Newton solve or time step (:func:`solve_with_search` repeats a solve until
            its converged state keeps its pairing), ``"residual"`` at every residual
            evaluation (the pairing then moves within Newton's iterations, which can stall
            them where many slave nodes cross master facet edges).
        exchange: how each rank obtains the master facets its search needs:
            ``"neighbours"`` (default; those near its slave nodes) or ``"all"`` (the whole
            master surface gathered; :class:`~fenicsfriction.contact.pairing.Pairing`).

    Attributes:
        V, W: the displacement space and the space of master quantities at slave nodes.
        pairing: the :class:`~fenicsfriction.contact.pairing.Pairing`.
        mirrors: the W Function of each V field (``mirrors[u]`` is ``Q u``).
        F, G: the slave- and master-side forms of the contact's virtual power.
        projection: the UFL projection (shape functions, normal, gap).
        normal, gap, penetration: the projection's normal (out of the master body), its gap
            and the penetration :math:`d = (-g)_+` (UFL, at the slave nodes).
        pressure, traction: the normal pressure and tangential traction (UFL) at slave nodes.
        potential, dissipation: the energy stored in the compliance
            :math:`\int c_n d^{m_n+1}/(m_n+1)` and the power dissipated by friction and normal
            damping (UFL forms, nodal rule; the latter zero without a velocity).
        relative_velocity: :math:`w`, the slave velocity less the master's at the closest point
            (UFL; None without ``velocity``).
    """

    def __init__(self, u: fem.Function, facet_tags: mesh.MeshTags, slave: int, master: int,
                 law: laws.InterfaceLaw, velocity: typing.Any = None,
                 fields: typing.Sequence[fem.Function] = (), transport: typing.Any = None,
                 weight: float = 1.0, frozen: bool = False, search: str = "solve",
                 enforcement: str = "compliance", penalty_T: Value | None = None,
                 time_step: Value = 1.0, step_from: fem.Function | None = None,
                 exchange: str = "neighbours"):
        V = u.function_space
        msh = V.mesh
        dim = msh.geometry.dim
        laws.check("V", _compat.element_degree(V), _compat.element_degree(V) == 1,
                   "node-to-segment contact needs a degree-1 Lagrange displacement space")
        for name, tag in (("slave", slave), ("master", master)):
            count = msh.comm.allreduce(int(np.count_nonzero(facet_tags.values == tag)))
            laws.check(name, tag, count > 0, "a facet tag present in facet_tags")
        laws.check("search", search, search in ("solve", "residual"), "'solve' or 'residual'")
        laws.check("enforcement", enforcement, enforcement in ENFORCEMENTS,
                   f"one of {', '.join(ENFORCEMENTS)}")
        if enforcement == "perturbed-lagrangian":
            laws.check("m_n", law.m_n, law.m_n == 1, "the perturbed Lagrangian's normal "
                       "penalty is linear: m_n = 1 (c_n is the penalty eps_N)")
            laws.check("penalty_T", penalty_T, penalty_T is not None,
                       "the tangential penalty (> 0)")
        self.enforcement = enforcement
        #: the tangential multiplier of the last committed increment (perturbed Lagrangian)
        self.traction_old = fem.Function(V, name="tangential_multiplier")
        self.u, self.V = u, V
        self.dim = dim
        self.frozen = frozen
        self.search_every_residual = search == "residual"
        self.law, self.c_n, self.m_n, self.weight = law, law.c_n, law.m_n, weight
        self.search_pending = True
        self.W = _compat.lagrange_vector_space(msh, 1, dim * dim)
        slave_nodes = np.unique(facet_nodes(V, facet_tags, slave, outward=False))
        owned = slave_nodes[slave_nodes < V.dofmap.index_map.size_local]
        self.pairing = Pairing(V, self.W, owned, facet_nodes(V, facet_tags, master),
                               exchange=exchange)
        self.mirrors: dict[fem.Function, fem.Function] = {
            f: fem.Function(self.W, name=f"master_{f.name}")
            for f in (u, *fields, *([] if step_from is None else [step_from]))}
        self.step_from = step_from
        self.ds = ufl.Measure("ds", domain=msh, subdomain_data=facet_tags,
                              subdomain_id=slave, metadata=_compat.nodal_quadrature(dim - 1))
        self.searched = False

        X = ufl.SpatialCoordinate(msh)
        x_master = [self._node(self.pairing.reference, a) + self._node(self.mirrors[u], a)
                    for a in range(dim)]
        self.projection: Projection = project(X + u, x_master)
        n = self.normal = self.projection.normal
        self.gap = self.projection.gap
        d = self.penetration = laws.penetration(-self.projection.gap)
        w = None
        if velocity is not None:
            self._check_mirrored(velocity, fields)
            w = velocity - self._master_value(velocity, fields)
            if transport is not None:
                w = w - ufl.as_vector(transport)
        self.relative_velocity = w
        approach = -ufl.dot(w, n) if w is not None else 0.0
        self.pressure = law.normal_traction(d, approach)
        elastic = law.pressure(d)
        if step_from is not None:  # the step's elastic pressure: φ's discrete gradient
            elastic = self._discrete_gradient(X)
            self.pressure = self.pressure - law.pressure(d) + elastic
        force = self.pressure * n
        self.traction = None
        if law.has_friction:
            laws.check("velocity", velocity, w is not None,
                       "friction (mu != 0) needs the slave velocity")
            w_T = w - ufl.dot(w, n) * n
            if enforcement == "compliance":
                self.traction = law.friction_traction(d, w_T)
            else:
                self.traction = self._stick_penalty(d, w_T * time_step, n, penalty_T)
            force = force + self.traction
        v, omega = ufl.TestFunction(V), ufl.TestFunction(self.W)
        master_test = self.projection.interpolate([self._node(omega, a) for a in range(dim)])
        self.F = -weight * ufl.inner(force, v) * self.ds
        self.G = weight * ufl.inner(force, master_test) * self.ds
        # energy bookkeeping: the compliance's stored energy and the power the interface
        # dissipates (friction, normal damping), both >= 0
        self.potential = weight * law.c_n * d ** (law.m_n + 1) / (law.m_n + 1) * self.ds
        dissipated = 0.0 * d
        if w is not None:
            damping = self.pressure - elastic
            dissipated = damping * approach
            if self.traction is not None:
                dissipated = dissipated - ufl.dot(self.traction, w)
        self.dissipation = weight * dissipated * self.ds

    def _discrete_gradient(self, X: typing.Any) -> typing.Any:
        r"""The elastic pressure of a midpoint step from :math:`u_n` (``step_from``) to
        :math:`u_{n+1} = 2u - u_n`: the discrete gradient of the potential
        :math:`\phi(d) = c_n d^{m_n+1}/(m_n+1)` (Gonzalez 1996, "Time integration and
        discrete Hamiltonian systems"; for contact, Laursen & Chawla 1997 and Armero &
        Petőcz 1998),

        .. math:: p = \frac{\phi(d(g_{n+1})) - \phi(d(g_n))}{g_n - g_{n+1}}
                  \quad (\phi'(d(g_{n+1/2}))\ \text{when}\ g_{n+1} = g_n),

        a quotient in the gap (:math:`d = (-g)_+`), both ends' gaps projected on the same
        master facet (the step's pairing). Along the midpoint normal, whose
        :math:`n\cdot(\Delta u_s - \sum_a N_a(\xi)\, \Delta u_a)` is the gradient of the
        gap at the midpoint applied to the step, its work is
        :math:`\phi(d_{n+1}) - \phi(d_n)` up to the change of that gradient across the step
        (none where the master facet translates). A midpoint pressure misses it wherever a
        node enters or leaves contact within the step (φ' is not smooth at d = 0)."""
        assert self.step_from is not None
        u, start = self.u, self.step_from
        approaches = []  # -g at both ends: d = (-g)_+
        for field, mirror in ((start, self.mirrors[start]),
                              (2 * u - start, 2 * self.mirrors[u] - self.mirrors[start])):
            x_master = [self._node(self.pairing.reference, a) + self._node(mirror, a)
                        for a in range(self.dim)]
            approaches.append(-project(X + field, x_master).gap)
        return discrete_gradient(self.law, *approaches)

    @functools.cached_property
    def nodal_space(self) -> fem.FunctionSpace:
        """Scalar degree-1 Lagrange functions on the mesh: one value per node."""
        return _compat.scalar_function_space(self.V.mesh, "Lagrange", 1)

    # --- the friction bound, for the Panagiotopoulos process (FrictionBoundCoupling) --------
    @property
    def configuration(self) -> list[fem.Function]:
        """u, its master mirror and the paired master nodes' reference coordinates: what the
        gap, the normal and the friction bound at each slave node are made of."""
        return [self.u, self.mirrors[self.u], self.pairing.reference]

    def frequency_bound(self, lumped_mass: PETSc.Vec) -> float:
        """An upper bound of the contact springs' frequency² on the lumped mass, for linear
        compliance (m_n = 1, the stiffness c_n per unit length/area whatever the
        penetration): every slave node in contact, its spring k_i = c_n A_i between masses no
        lighter than the lightest node of either surface, ω² <= 2 max k_i / min m."""
        laws.check("m_n", self.m_n, self.m_n == 1,
                   "a penetration-independent bound exists for m_n = 1 only")
        slave = self.pairing.slave_nodes
        stiffness = float(self.weight * float(self.c_n)
                          * self.nodal_weights[slave].max(initial=0.0))
        d = self.dim
        masses = lumped_mass.array_r.reshape(-1, d)
        surfaces = np.concatenate([slave, self.pairing.master_facets.ravel()])
        surfaces = surfaces[surfaces < len(masses)]
        lightest = float(masses[surfaces].min(initial=np.inf))
        comm = self.V.mesh.comm
        from mpi4py import MPI
        return 2 * comm.allreduce(stiffness, op=MPI.MAX) / comm.allreduce(lightest, op=MPI.MIN)

    def _stick_penalty(self, d: typing.Any, slip: typing.Any, n: typing.Any,
                       penalty_T: Value) -> typing.Any:
        """The tangential multiplier of the perturbed Lagrangian (Pop, eq. 27), eliminated
        node by node: a stick spring of stiffness κ_T on the slip increment from the last
        committed multiplier, returned to the Coulomb bound c_T d^{m_T} when it would exceed
        it (slide)."""
        old = self.traction_old - ufl.dot(self.traction_old, n) * n
        trial = old - penalty_T * slip
        size = ufl.sqrt(ufl.dot(trial, trial))
        bound = self.law.friction_bound(d)
        return ufl.conditional(ufl.le(size, bound), trial, bound * trial / size)

    def commit(self) -> None:
        """Store the tangential multipliers of the current state as the last increment's
        (perturbed Lagrangian; call after each converged increment)."""
        if self.enforcement != "perturbed-lagrangian" or self.traction is None:
            return
        self.update(search=False)
        nodal = self._committed_traction()
        slave = self.nodal_weights > 0
        self.traction_old.x.array.reshape(-1, self.dim)[:len(slave)][slave] = nodal[slave]
        self.traction_old.x.scatter_forward()

    @functools.cached_property
    def _committed_traction(self) -> NodalValues:
        assert self.traction is not None
        return self.nodal_values([self.traction[k] for k in range(self.dim)])

    def _node(self, packed: typing.Any, a: int) -> typing.Any:
        """The vector of master node ``a`` in a packed W quantity."""
        d = self.dim
        return ufl.as_vector([packed[a * d + k] for k in range(d)])

    def _master_value(self, expr: typing.Any, fields: typing.Sequence[fem.Function]) -> typing.Any:
        """``expr`` (a UFL vector of V fields) at the closest point of the master facet."""
        nodal = [ufl.replace(expr, {f: self._node(self.mirrors[f], a)
                                    for f in (self.u, *fields)})
                 for a in range(self.dim)]
        return self.projection.interpolate(nodal)

def discrete_gradient(law: laws.InterfaceLaw, start: typing.Any, end: typing.Any) -> typing.Any:
    r"""The elastic pressure of a step whose approach :math:`a = -g` (penetration
    :math:`d = a_+`) goes from ``start`` to ``end``: the discrete gradient (Gonzalez 1996) of
    the compliance's potential :math:`\phi(d) = c_n d^{m_n+1}/(m_n+1)`,

    .. math:: p = \frac{\phi(a_{n+1}^+) - \phi(a_n^+)}{a_{n+1} - a_n}
              \quad (c_n ((a_n + a_{n+1})/2)_+^{m_n}\ \text{when}\ a_{n+1} = a_n),

    whose work on the approach's change is exactly the potential's (UFL)."""
    potential = lambda a: law.c_n * laws.penetration(a) ** (law.m_n + 1) / (law.m_n + 1)  # noqa: E731
    jump = end - start
    # below the round-off of the approaches the quotient is 0/0: its limit instead
    moved = ufl.gt(abs(jump), 1e-12 * ufl.max_value(ufl.max_value(abs(start), abs(end)),
                                                    1e-300))
    return ufl.conditional(moved, (potential(end) - potential(start))
                           / ufl.conditional(moved, jump, 1.0),
                           law.pressure(laws.penetration(0.5 * (start + end))))


def _derivative(form: ufl.Form, pairs: list[tuple[fem.Function, Value]],
                space: fem.FunctionSpace, at_rest: dict) -> ufl.Form | None:
    """Σ weight · ∂form/∂field (trial functions of ``space``) at ``at_rest``, or None if it
    vanishes. A field that ``at_rest`` sets to zero is differentiated first (u̇ for C);
    the others after the substitution, which commutes with them and which UFL handles better
    before differentiation (replacing inside an expanded derivative can leave a sum whose
    terms disagree on their arguments)."""
    trial = ufl.TrialFunction(space)
    rested = _substitute(form, at_rest)
    terms = []
    for f, weight in pairs:
        if f in at_rest:
            derivative = ufl.algorithms.expand_derivatives(ufl.derivative(form, f, trial))
            terms.append(weight * _substitute(derivative, at_rest))
        elif f in rested.coefficients():
            terms.append(weight * ufl.derivative(rested, f, trial))
    if not terms:
        return None
    total = ufl.algorithms.expand_derivatives(sum(terms[1:], terms[0]))
    return None if total.empty() else total


def _substitute(form: ufl.Form, mapping: dict) -> ufl.Form:
    return ufl.replace(form, mapping) if mapping else form


class ContactOperator:
    """A :class:`NodeToSegment`'s residual ``F + Q^T G`` and Jacobian, compiled.

    It is called by :func:`fenicsfriction.assembly.assemble_residual` (``couplings=``) and
    :class:`~fenicsfriction.assembly.CoupledMatrix`: the residual searches the pairing at the
    current state when a search is due, the Jacobian chains the four blocks through ``Q``.
    """

    def __init__(self, contact: MirroredContact, derivatives: dict[fem.Function, Value],
                 at_rest: dict, jit_cache_dir: str | None = None):
        self.contact = contact
        compile_ = lambda form: None if form is None else _compat.form(form, jit_cache_dir)  # noqa: E731
        F, G = contact.F, contact.G
        # a mortar contact has no slave-side form F: all of it acts through Q (= B)
        self.F = None if F is None else compile_(_substitute(F, at_rest))
        self.G = compile_(_substitute(G, at_rest))
        own = list(derivatives.items())
        mirrored = [(contact.mirrors[f], w) for f, w in derivatives.items()
                    if f in contact.mirrors]
        V, W = contact.V, contact.W
        self.blocks = {key: compile_(None if form is None
                                     else _derivative(form, pairs, space, at_rest))
                       for key, form, pairs, space in (
                           ("VV", F, own, V), ("VW", F, mirrored, W),
                           ("WV", G, own, V), ("WW", G, mirrored, W))}
        self.b_F = None if self.F is None else dolfinx.fem.petsc.create_vector(self.F)
        self.b_G = dolfinx.fem.petsc.create_vector(self.G)
        self.matrices = {key: dolfinx.fem.petsc.create_matrix(a)
                         for key, a in self.blocks.items() if a is not None}
        #: seconds spent assembling the residual (``"residual"``: search excluded) and the
        #: chained Jacobian (``"jacobian"``: blocks, products, addition), summed over calls
        self.time_s = {"residual": 0.0, "jacobian": 0.0}

    def create_vector(self) -> PETSc.Vec:
        """A vector of the displacement space's layout, for :meth:`add_to_residual`."""
        return dolfinx.fem.petsc.create_vector(self.F if self.F is not None else self.G)

    def add_to_residual(self, b: PETSc.Vec) -> None:
        """``b += F + Q^T G`` at the current state (the pairing searched first if due)."""
        contact = self.contact
        contact.update(search=contact.search_pending or contact.search_every_residual
                       or not contact.searched)
        t0 = time.perf_counter()
        if self.b_F is not None:
            b.axpy(1.0, assemble_into(self.b_F, self.F))
        assemble_into(self.b_G, self.G)
        Q = self.contact.pairing.Q
        assert Q is not None
        Q.multTransposeAdd(self.b_G, b, b)
        self.time_s["residual"] += time.perf_counter() - t0

    def matrix(self, bcs: typing.Sequence[fem.DirichletBC] = ()) -> PETSc.Mat:
        """The chained Jacobian of the contact (rows and columns of ``bcs`` zeroed)."""
        self.contact.update(search=not self.contact.searched)
        Q = self.contact.pairing.Q
        assert Q is not None
        for key, A in self.matrices.items():
            A.zeroEntries()
            dolfinx.fem.petsc.assemble_matrix(A, self.blocks[key])
            A.assemble()
        m = self.matrices
        parts = []
        if "VV" in m:
            parts.append(m["VV"])
        if "VW" in m:
            parts.append(m["VW"].matMult(Q))
        if "WV" in m:
            parts.append(Q.transposeMatMult(m["WV"]))
        if "WW" in m:
            parts.append(m["WW"].PtAP(Q))
        if not parts:
            return None
        J = parts[0].copy()
        for part in parts[1:]:
            J.axpy(1.0, part, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        rows = _constrained_rows(self.contact.V, bcs)
        J.zeroRowsColumns(rows, diag=0.0)
        for part in parts[1:]:
            part.destroy()
        return J

    @property
    def pattern(self) -> int:
        """Identifies this Jacobian's nonzero pattern: it changes with the pairing only."""
        return self.contact.pairing.changes

    def add_to_matrix(self, A: PETSc.Mat, bcs: typing.Sequence[fem.DirichletBC] = (),
                      structure: typing.Any = None) -> None:
        """``A += dR_c/du``. With ``DIFFERENT_NONZERO_PATTERN`` (the default) A's pattern
        grows to the contact's couplings, so A must not be a matrix dolfinx assembles into
        (see :class:`fenicsfriction.assembly.CoupledMatrix`); ``SUBSET_NONZERO_PATTERN`` once
        it has."""
        t0 = time.perf_counter()
        J = self.matrix(bcs)
        if J is not None:
            A.axpy(1.0, J, structure=structure or PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            J.destroy()
        self.time_s["jacobian"] += time.perf_counter() - t0


class NodalValues:
    """UFL scalars at the slave nodes of a :class:`NodeToSegment`: each one's integral against
    the nodes' hat functions with the nodal rule, over the node's tributary weight — the exact
    nodal value, the rule's points being the nodes. The forms are compiled once.

    Calling it returns an array (owned nodes, expressions), zero off the slave surface.
    """

    def __init__(self, contact: MirroredContact, expressions: typing.Sequence[typing.Any]):
        self.contact = contact
        q = ufl.TestFunction(contact.nodal_space)
        self.forms = [_compat.form(e * q * contact.ds) for e in expressions]

    def __call__(self) -> np.ndarray:
        weights = self.contact.nodal_weights
        values = np.zeros((len(weights), len(self.forms)))
        slave = weights > 0
        for k, form in enumerate(self.forms):
            values[slave, k] = assemble_owned(form)[slave] / weights[slave]
        return values


def _constrained_rows(V: fem.FunctionSpace, bcs: typing.Sequence[fem.DirichletBC]) -> np.ndarray:
    """Global indices of the owned dofs of ``V`` constrained by ``bcs``."""
    bs = V.dofmap.index_map_bs
    index_map = V.dofmap.index_map
    rows = [np.zeros(0, dtype=np.int64)]
    for bc in bcs:
        dofs, first_ghost = bc.dof_indices()
        owned = dofs[:first_ghost]
        rows.append(index_map.local_to_global(owned // bs).astype(np.int64) * bs + owned % bs)
    return np.unique(np.concatenate(rows)).astype(PETSc.IntType)


def solve_with_search(solver: typing.Any, contacts: typing.Sequence[typing.Any],
                      max_rounds: int = 10) -> typing.Any:
    """Newton solves with the pairing searched between them, until a converged state keeps
    the pairing it was solved with (a fixed point of the contact search).

    Args:
        solver: a solver whose ``solve()`` returns a report and searches the pairing at its
            first residual (``SteadySolver``).
        contacts: the couplings of its residual (:class:`NodeToSegment`,
            :class:`~fenicsfriction.contact.mortar.SegmentToSegment`: their ``search()``).
        max_rounds: how many solves may be tried.

    Returns:
        The last solve's report, with ``iterations`` summed over the rounds and ``rounds``
        added.

    Raises:
        RuntimeError: the pairing still changed after ``max_rounds`` solves.
    """
    iterations = 0
    for rounds in range(1, max_rounds + 1):
        report = solver.solve()
        iterations += report.iterations
        changed = [contact.search() for contact in contacts]
        if not any(changed):
            report.iterations = iterations
            report.rounds = rounds
            return report
    raise RuntimeError(f"contact search: the pairing still changed after {max_rounds} "
                       "Newton solves (max_rounds); the state of the last solve is kept")


if typing.TYPE_CHECKING:  # mypy checks that the node-to-segment contact is a Coupling
    from fenicsfriction.coupling import Coupling, FrictionBoundCoupling

    def _node_to_segment_is_a_coupling(contact: NodeToSegment) -> Coupling:
        return contact

    def _node_to_segment_has_a_friction_bound(contact: NodeToSegment) -> FrictionBoundCoupling:
        return contact
