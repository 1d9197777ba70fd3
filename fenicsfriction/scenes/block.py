r"""The block on a moving belt of Martins & Oden (seed 000, Figs. 6-15; SPEC §4).

Units are the paper's: mass 10^3 kg, length cm, time s (so force 10^3 kg cm s^-2 and stress
10^3 kg cm^-1 s^-2). The defaults are eq. (36)-(37) with the driver spring of the FE dynamics
(Figs. 13-15).

Choices the paper leaves open, made here and changeable through the fields:

* **Plane strain with breadth B0.** B0 is the block's breadth out of the plane (the
  plane-strain thickness): every 2D integral is multiplied by B0, so forces are totals, the
  contact pressure is force / (L B0), and ``mass``/``weight`` are totals over that breadth.
  With ``dim=3`` the block is a box L × H × B0 (breadth along z, hexahedra) with free faces
  at z = 0 and z = B0, and the spring node is at mid-breadth. Nothing restrains translation
  along z or rotation about y (only the transverse friction damping c_T d^m_T / |U_T| acts on
  them), so the symmetry plane z = B0/2 is held in z: exact for the symmetric steady state,
  and it removes those two rigid modes from the eigenproblem.
* **Weight as a body force** ρ g = W / (L H B0), mass density ρ = M / (L H B0).
* **Driver spring through the centre of mass.** A horizontal nodal spring of total stiffness
  K_x on the node of the left face at height ``spring_height`` (default H/2, the height of
  the centre of mass): its line of action is horizontal at that height, which gives the
  tipping limit μ < L/(2 h_s) = L/H = 1.6 and a tangential mode ±i sqrt(K_x/M) that does
  not move with μ. Mesh rows are shifted so that a node lies at that height (no shift for
  H/2). The spring is anchored at zero displacement: its elongation is -u_x at the node.
* **Belt** along ``belt_direction`` × e_x at ``belt_speed``; friction drags the block that
  way and the spring holds it back.
* **Contact** on the bottom face y = 0 (outward normal -e_y), initial gap g (default 0).
  The contact integrals use a fixed quadrature rule so that the reported resultants are
  computed exactly as the residual integrates them.
* **Discrete tipping limit.** The normal resultant cannot lie further out than the outermost
  contact quadrature point, so steady sliding exists only up to
  μ_h = (L/2 - s_1)/h_s (s_1: that point's distance from the corner). Gauss points
  (default, ``contact_quadrature="gauss"``) give μ_h → L/(2 h_s) as the mesh is refined;
  Gauss-Lobatto points (``"gll"``) include the corners, so μ_h = L/(2 h_s) on any mesh.
"""

from __future__ import annotations

import dataclasses
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
    is_speed_law,
    normal_compliance,
    normal_damping,
    normal_part,
    surface_traction,
    tangential_part,
)
from fenicsfriction.laws import check

__all__ = ["BlockData", "BlockModel", "BlockOnBelt"]

CONTACT, TOP, LEFT, RIGHT = 1, 2, 3, 4


def _gauss(degree: int) -> tuple[np.ndarray, dict]:
    """Gauss points on [0, 1] of the contact rule and its UFL metadata."""
    q = 2 * degree + 4
    x = (np.polynomial.legendre.leggauss(q // 2 + 1)[0] + 1) / 2
    return x, {"quadrature_degree": q}


def _gll(degree: int) -> tuple[np.ndarray, dict]:
    """Gauss-Lobatto points (corners included) and metadata; FFCx uses (q+3)/2 points."""
    q = 2 * degree + 5
    return np.array([0.0, 1.0]), {"quadrature_degree": q, "quadrature_rule": "GLL"}


QUADRATURE = {"gauss": _gauss, "gll": _gll}


@dataclasses.dataclass
class BlockData:
    """The block, its interface and its driver: what the FE and the rigid models share.

    Args:
        L: length of the block along the belt [cm].
        H: height of the block [cm].
        B0: breadth out of the plane, the plane-strain thickness [cm].
        mass: total mass M [10^3 kg].
        weight: total weight W, applied as a body force [10^3 kg cm s^-2].
        c_n, m_n: normal compliance c_n [10^3 kg cm^(-1-m_n) s^-2] and exponent [-].
        mu: friction coefficient μ = c_T / c_n [-].
        m_T: friction exponent [-] (None: m_n, Coulomb).
        b_n, l_n: normal damping [10^3 kg cm^(-2-l_n) s^-1] and exponent [-] (None: m_n).
        g: initial gap [cm].
        eps: regularisation of |u̇_T - U_T| [cm/s].
        regularisation: "c1" or "smooth".
        belt_speed: |U_T| [cm/s], > 0.
        belt_direction: +1 (belt moves along +x) or -1.
        K_x: total stiffness of the driver spring [10^3 kg s^-2].
        spring_height: height of the spring's line of action [cm] (None: H/2).
    """

    L: float = 48.8
    H: float = 30.5
    B0: float = 30.5
    mass: float = 0.45
    weight: float = 450.0
    c_n: float = 1e10
    m_n: float = 2.5
    mu: float = 0.0
    m_T: float | None = None
    b_n: float = 0.0
    l_n: float | None = None
    g: float = 0.0
    eps: float = 1e-3
    regularisation: str = "c1"
    belt_speed: float = 0.287
    belt_direction: int = 1
    K_x: float = 11.1
    spring_height: float | None = None

    def __post_init__(self):
        if self.spring_height is None:
            self.spring_height = self.H / 2
        self.validate()

    def validate(self) -> None:
        """Raise ``ValueError`` naming the first parameter out of its range."""
        for name in ("L", "H", "B0", "mass", "K_x", "belt_speed"):
            value = getattr(self, name)
            check(name, value, np.isfinite(value) and value > 0, "must be a finite number > 0")
        check("weight", self.weight, self.weight >= 0, "must be >= 0")
        check("belt_direction", self.belt_direction, self.belt_direction in (1, -1),
              "must be +1 or -1")
        check("spring_height", self.spring_height, 0 <= self.spring_height <= self.H,
              f"must lie in [0, H] = [0, {self.H}]")
        laws.InterfaceLaw(**self._law_parameters())  # validates the interface parameters

    def _law_parameters(self) -> dict:
        names = ("c_n", "m_n", "mu", "m_T", "b_n", "l_n", "g", "eps", "regularisation")
        return {name: getattr(self, name) for name in names}

    @property
    def law(self) -> laws.InterfaceLaw:
        """The interface law of the scene (validated)."""
        return laws.InterfaceLaw(**self._law_parameters())

    @property
    def tipping_limit(self) -> float:
        """μ at which the normal resultant reaches the front corner: L / (2 h_s)."""
        return self.L / (2 * self.spring_height) if self.spring_height > 0 else np.inf


@dataclasses.dataclass
class BlockOnBelt(BlockData):
    """The block-on-belt scene: :class:`BlockData` and the finite element model's own data.

    Args:
        E: Young's modulus [10^3 kg cm^-1 s^-2].
        nu: Poisson's ratio [-].
        top_pressure: uniform pressure on the top face [10^3 kg cm^-1 s^-2] (0 in the paper).
        friction_coefficient: velocity-dependent μ(|v|) replacing ``mu`` (see laws).
        refine: mesh refinement factor; the mesh has 4·refine × 3·refine cells.
        degree: polynomial degree of the Lagrange quadrilaterals (2: nine-node Q2).
        contact_quadrature: "gauss" or "gll" (Gauss-Lobatto, includes the corners) on Γ_C.
        dim: 2 (plane strain, the paper's model) or 3 (a box, 4r × 3r × nz·r hexahedra).
        nz: cells across the breadth per refinement in 3D (even, so a node row is at B0/2).
        Other parameters: see :class:`BlockData`.
    """

    E: float = 1.4e6
    nu: float = 0.25
    top_pressure: float = 0.0
    friction_coefficient: laws.FrictionCoefficient | None = None
    refine: int = 1
    degree: int = 2
    contact_quadrature: str = "gauss"
    dim: int = 2
    nz: int = 2

    def validate(self) -> None:
        super().validate()
        check("E", self.E, np.isfinite(self.E) and self.E > 0, "must be a finite number > 0")
        check("nu", self.nu, -1 < self.nu < 0.5, "Poisson's ratio must lie in (-1, 0.5)")
        check("top_pressure", self.top_pressure, self.top_pressure >= 0, "must be >= 0")
        check("weight", self.weight, self.weight + self.top_pressure > 0,
              "weight and top_pressure cannot both be 0: nothing presses the block on the belt")
        check("refine", self.refine, isinstance(self.refine, int) and self.refine >= 1,
              "must be an integer >= 1")
        check("degree", self.degree, self.degree in (1, 2, 3), "must be 1, 2 or 3")
        check("dim", self.dim, self.dim in (2, 3), "must be 2 or 3")
        check("nz", self.nz, isinstance(self.nz, int) and self.nz >= 2 and self.nz % 2 == 0,
              "must be an even integer >= 2")
        check("contact_quadrature", self.contact_quadrature,
              self.contact_quadrature in QUADRATURE, f"must be one of {sorted(QUADRATURE)}")

    def _law_parameters(self) -> dict:
        return {**super()._law_parameters(), "friction_coefficient": self.friction_coefficient}

    @property
    def contact_pressure(self) -> float:
        """Mean contact pressure (W + p_top L B0) / (L B0) at equilibrium."""
        return self.weight / (self.L * self.B0) + self.top_pressure

    @property
    def discrete_tipping_limit(self) -> float:
        """μ at which the resultant reaches the outermost contact quadrature point."""
        if self.spring_height == 0:
            return np.inf
        points = QUADRATURE[self.contact_quadrature](self.degree)[0]
        s_1 = points.min() * self.L / (4 * self.refine)
        return (self.L / 2 - s_1) / self.spring_height

    def build(self, comm: MPI.Comm = MPI.COMM_WORLD,
              with_friction: bool | None = None) -> BlockModel:
        """Mesh, spaces, the residual and its parameters as ``fem.Constant``.

        Args:
            comm: communicator the mesh is distributed over.
            with_friction: include the friction term; default only when μ > 0 or a
                velocity-dependent law is given (a frictionless scene assembles no friction).
        """
        return BlockModel(self, comm, with_friction)


def _vertex_rows(n_rows: int, degree: int, H: float, target: float) -> np.ndarray:
    """Heights of the n_rows+1 vertex rows: uniform, except shifted so that a row of nodes of
    the degree-``degree`` Lagrange space lies at height ``target`` (the spring's node)."""
    rows = np.linspace(0.0, H, n_rows + 1)
    nodes = np.linspace(0.0, H, degree * n_rows + 1)
    k = int(np.argmin(np.abs(nodes - target)))
    if np.isclose(nodes[k], target, rtol=0, atol=1e-12 * H):
        return rows
    spacing = H / n_rows
    j, fraction = divmod(k, degree)
    if fraction:  # a row inside cell row j: slide that cell row so the node row hits target
        low = target - fraction / degree * spacing
        if 0 < j < n_rows - 1 and low > 0 and low + spacing < H:
            return np.concatenate([np.linspace(0.0, low, j + 1),
                                   np.linspace(low + spacing, H, n_rows - j)])
    j = min(max(int(round(target / spacing)), 1), n_rows - 1)  # move the nearest vertex row
    return np.concatenate([np.linspace(0.0, target, j + 1)[:-1],
                           np.linspace(target, H, n_rows - j + 1)])


class BlockModel:
    """A built block scene: mesh, function space, the residual and post-processing.

    Attributes:
        scene: the parameters it was built from.
        msh, V: mesh and vector Lagrange space.
        residual: the one residual (see :mod:`fenicsfriction.forms`).
        mu, eps, thickness: ``fem.Constant`` — change ``mu.value`` / ``eps.value`` and re-solve.
        ds_contact: measure on Γ_C with the fixed quadrature degree used everywhere.
        spring: the driver's :class:`~fenicsfriction.forms.NodalSpring`.
    """

    CONTACT = CONTACT

    def __init__(self, scene: BlockOnBelt, comm: MPI.Comm, with_friction: bool | None):
        self.scene = s = scene
        law = s.law
        if with_friction is None:
            with_friction = s.mu > 0 or s.friction_coefficient is not None
        self.with_friction = with_friction
        nx, ny = 4 * s.refine, 3 * s.refine
        if s.dim == 2:
            msh = _compat.create_rectangle(comm, (0.0, 0.0), (s.L, s.H), (nx, ny))
        else:
            msh = _compat.create_box(comm, (0.0, 0.0, 0.0), (s.L, s.H, s.B0),
                                     (nx, ny, s.nz * s.refine))
        self.msh = msh
        rows = _vertex_rows(ny, s.degree, s.H, s.spring_height)
        msh.geometry.x[:, 1] = np.interp(msh.geometry.x[:, 1], np.linspace(0, s.H, ny + 1), rows)
        self.V = V = _compat.vector_function_space(msh, s.degree)

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
        facets, values = np.concatenate(facets), np.concatenate(values)
        order = np.argsort(facets)
        self.facet_tags = mesh.meshtags(msh, fdim, facets[order], values[order])
        ds = ufl.Measure("ds", domain=msh, subdomain_data=self.facet_tags)
        self.ds_contact = ds(CONTACT, metadata=QUADRATURE[s.contact_quadrature](s.degree)[1])
        self.dx = ufl.Measure("dx", domain=msh)

        def constant(value):
            return fem.Constant(msh, np.float64(value))

        # 2D integrals are per unit breadth: times B0 makes every force a total
        thickness = s.B0 if s.dim == 2 else 1.0
        self.mu, self.eps, self.thickness = constant(s.mu), constant(s.eps), constant(thickness)
        e_x, e_y = np.eye(s.dim)[0], np.eye(s.dim)[1]
        self.c_n = constant(law.c_n)
        # exponents stay Python floats: UFL differentiates d**Constant very slowly
        self.m_n, self.m_T = float(law.m_n), float(law.m_T)
        self.gap = constant(law.g)
        self.belt_velocity = fem.Constant(msh, s.belt_direction * s.belt_speed * e_x)
        volume = s.L * s.H * s.B0
        self.rho = constant(s.mass / volume)
        self.gravity = fem.Constant(msh, -s.weight / volume * e_y)
        self.top_traction = fem.Constant(msh, -s.top_pressure * e_y)
        self.normal = ufl.FacetNormal(msh)

        u, u_dot, u_ddot = fem.Function(V, name="displacement"), fem.Function(V), fem.Function(V)
        v = ufl.TestFunction(V)
        n, ds_c = self.normal, self.ds_contact
        terms = inertia(self.rho, u_ddot, v, self.dx) \
            + elasticity(u, v, s.E, s.nu, self.dx) \
            + body_force(self.gravity, v, self.dx) \
            + normal_compliance(u, v, n, self.c_n, self.m_n, self.gap, ds_c)
        if s.top_pressure > 0:
            terms += surface_traction(self.top_traction, v, ds(TOP))
        if law.b_n > 0:
            terms += normal_damping(u, u_dot, v, n, law.b_n, law.l_n, self.gap, ds_c)
        if with_friction:
            terms += friction(u, u_dot, v, n, self.friction_c_T, self.m_T, self.gap,
                              self.belt_velocity, self.eps, ds_c, law.regularisation)
        self.spring = NodalSpring.at_point(V, (0.0, s.spring_height, s.B0 / 2)[:s.dim], 0, s.K_x)
        bcs = []
        if s.dim == 3:
            Vz, _ = V.sub(2).collapse()
            mid = fem.locate_dofs_geometrical(
                (V.sub(2), Vz), lambda x: np.isclose(x[2], s.B0 / 2, atol=tol))
            zero = fem.Function(Vz)
            bcs.append(fem.dirichletbc(zero, mid, V.sub(2)))
        self.residual = Residual(form=self.thickness * terms, u=u, u_dot=u_dot, u_ddot=u_ddot,
                                 v=v, bcs=bcs, springs=[self.spring])
        self._functionals: dict = {}
        contact_dofs = fem.locate_dofs_topological(
            V.sub(1), fdim, self.facet_tags.find(CONTACT))
        self._contact_y = contact_dofs[contact_dofs < V.dofmap.index_map.size_local * s.dim]

    @property
    def friction_c_T(self):
        """c_T as used by the friction term: μ c_n, or c_n μ(|v|) for a velocity law."""
        law = self.scene.friction_coefficient
        if law is None:
            return self.mu * self.c_n
        return lambda speed: self.c_n * law(speed)

    # --- quantities on Γ_C -----------------------------------------------------------------------
    def penetration(self, n=None):
        """UFL penetration d = (u_n - g)_+ (``n``: normal to use, default the facet normal)."""
        n = self.normal if n is None else n
        return laws.penetration(normal_part(self.residual.u, n), self.gap)

    def pressure(self, n=None):
        """UFL normal contact pressure c_n d^{m_n} (elastic part)."""
        return laws.normal_pressure(self.penetration(n), self.c_n, self.m_n)

    def friction_traction(self, n=None):
        """UFL friction traction on the body at the current velocity ``u_dot`` (zero in steady
        sliding), a vector tangent to Γ_C."""
        if not self.with_friction:
            return ufl.zero(self.scene.dim)
        n = self.normal if n is None else n
        w = tangential_part(self.residual.u_dot, n) - self.belt_velocity
        c_T = self.friction_c_T
        if is_speed_law(c_T):
            c_T = c_T(ufl.sqrt(ufl.inner(w, w)))
        direction = laws.REGULARISATIONS[self.scene.regularisation][1](w, self.eps)
        return -laws.friction_bound(self.penetration(n), c_T, self.m_T) * direction

    def contact_traction(self):
        """UFL traction of the foundation on the body, valid in cells (for output fields).

        Uses the contact face's constant normal -e_y instead of the facet normal so it can be
        interpolated; it is meaningful only on Γ_C (see :meth:`contact_dofs`).
        """
        n = ufl.as_vector(-np.eye(self.scene.dim)[1])
        return -self.pressure(n) * n + self.friction_traction(n)

    def _integral(self, key: str, integrand: typing.Callable) -> float:
        """∫_Γc integrand() ds (times the thickness), compiled at the first call only."""
        if key not in self._functionals:
            self._functionals[key] = _compat.form(self.thickness * integrand() * self.ds_contact)
        value = fem.assemble_scalar(self._functionals[key])
        return self.msh.comm.allreduce(value, op=MPI.SUM)

    def energies(self) -> dict:
        """Kinetic, strain, interface, spring and load-potential energies of the current state.

        The load potential is -∫ b·u (weight) - ∫ t·u (top pressure); without friction and
        damping their sum ``total`` is conserved by the dynamics.
        """
        s, R = self.scene, self.residual
        u, u_dot = R.u, R.u_dot
        if "energy" not in self._functionals:
            d = self.penetration()
            ds = ufl.Measure("ds", domain=self.msh, subdomain_data=self.facet_tags)
            forms = {"kinetic": 0.5 * self.rho * ufl.inner(u_dot, u_dot) * self.dx,
                     "strain": 0.5 * elasticity(u, u, s.E, s.nu, self.dx),
                     "interface": self.c_n * d ** (self.m_n + 1) / (self.m_n + 1)
                     * self.ds_contact,
                     "load": -ufl.inner(self.gravity, u) * self.dx
                     - ufl.inner(self.top_traction, u) * ds(TOP)}
            self._functionals["energy"] = {k: _compat.form(self.thickness * f)
                                           for k, f in forms.items()}
        comm = self.msh.comm
        values = {k: comm.allreduce(fem.assemble_scalar(f), op=MPI.SUM)
                  for k, f in self._functionals["energy"].items()}
        force = self.spring.force(u)
        values["spring"] = 0.5 * force**2 / self.spring.stiffness
        values["total"] = sum(values.values())
        return values

    def powers(self) -> dict:
        """Power of the interface forces on the body at the current state [force × cm/s].

        ``friction``: ∫ t_T · u̇ of the regularised friction traction (the moving belt can put
        energy in); ``damping``: -∫ b_n d^{l_n} u̇_n² (normal damping, <= 0).
        """
        if "power" not in self._functionals:
            R, n, law = self.residual, self.normal, self.scene.law
            forms = {"friction": -friction(R.u, R.u_dot, R.u_dot, n, self.friction_c_T,
                                           self.m_T, self.gap, self.belt_velocity, self.eps,
                                           self.ds_contact, law.regularisation)
                     if self.with_friction else None,
                     "damping": -normal_damping(R.u, R.u_dot, R.u_dot, n, law.b_n, law.l_n,
                                                self.gap, self.ds_contact)
                     if law.b_n > 0 else None}
            self._functionals["power"] = {k: _compat.form(self.thickness * f)
                                          for k, f in forms.items() if f is not None}
        comm = self.msh.comm
        values = {"friction": 0.0, "damping": 0.0}
        values.update({k: comm.allreduce(fem.assemble_scalar(f), op=MPI.SUM)
                       for k, f in self._functionals["power"].items()})
        return values

    def contact_states(self) -> dict:
        """Counts of contact nodes that are open (d = 0), sticking (|u̇_T - U_T| < ε, the
        regularisation band) or slipping, over the whole mesh."""
        y = self._contact_y
        d = np.maximum(-self.residual.u.x.array[y] - self.scene.g, 0.0)
        slip = np.abs(self.residual.u_dot.x.array[y - 1] - self.scene.belt_direction
                      * self.scene.belt_speed)
        closed = d > 0
        stick = closed & (slip < float(self.eps.value))
        counts = np.array([np.sum(~closed), np.sum(stick), np.sum(closed & ~stick)])
        n_open, n_stick, n_slip = self.msh.comm.allreduce(counts, op=MPI.SUM)
        return {"n_open": int(n_open), "n_stick": int(n_stick), "n_slip": int(n_slip)}

    def band_damping(self) -> ufl.Form | None:
        """Linear form of the nodal dashpots of sticking nodes, ∫ c_T d^{m_T}/ε v_T ds (per
        tangential dof), for the explicit scheme's stable step; None without friction."""
        if not self.with_friction:
            return None
        c_T = self.friction_c_T
        if is_speed_law(c_T):
            c_T = c_T(0.0)
        v = self.residual.v
        tangential = sum(v[i] for i in range(self.scene.dim) if i != 1)
        return self.thickness * laws.friction_bound(self.penetration(), c_T, self.m_T) \
            / self.eps * tangential * self.ds_contact

    def dynamics_observer(self, probe_x: float | None = None) -> typing.Callable:
        """An ``observe(t)`` for the time integrators: one flat record of the state per step.

        Resultants (:meth:`quantities`), centre-of-mass motion (``u_yG``, ``v_yG``, ``theta``),
        the spring elongation, contact-state counts, the probe node (:meth:`probe`, prefix
        ``probe_``; default: mid-base, the paper's node 29) and the energy balance: ``energy_error``
        = E(t) − E(0) − W(t), with E the kinetic + strain + interface + spring + load-potential
        energies and W the work of the friction and damping stresses (trapezoidal rule over
        the observed steps): zero for the exact solution, its drift measures the time error.
        """
        x = self.scene.L / 2 if probe_x is None else probe_x
        energy0 = self.energies()["total"]
        last: dict = {}

        def observe(t: float) -> dict:
            q, powers, energies = self.quantities(), self.powers(), self.energies()
            centre, probe = self.centre_of_mass(), self.probe(x)
            power = powers["friction"] + powers["damping"]
            work = last.get("work", 0.0)
            if last:
                work += 0.5 * (power + last["power"]) * (t - last["time"])
            last.update(time=t, power=power, work=work)
            return {**{key: q[key] for key in ("normal_force", "normal_force_elastic",
                                               "friction_force", "spring_force",
                                               "centre_of_pressure", "min_penetration",
                                               "max_penetration")},
                    "spring_elongation": -q["spring_force"] / self.scene.K_x,
                    "u_yG": float(centre["u_G"][1]), "v_yG": float(centre["v_G"][1]),
                    "v_xG": float(centre["v_G"][0]), "theta": centre["theta"],
                    **self.contact_states(),
                    **{f"probe_{k}": v for k, v in probe.items()},
                    "kinetic_energy": energies["kinetic"], "friction_power": powers["friction"],
                    "damping_power": powers["damping"],
                    "energy_error": energies["total"] - energy0 - work}

        return observe

    @property
    def force_scale(self) -> float:
        """Total load pressing the block down [force]: the scale of the residual's entries."""
        return self.scene.contact_pressure * self.scene.L * self.scene.B0

    def solver_options(self) -> dict:
        """SNES tolerances scaled to this scene: residual entries are nodal forces, 1e-10 of the
        load. The solver raises it to the round-off floor where needed (see SteadySolver)."""
        return {"snes_atol": 1e-10 * self.force_scale}

    def initial_guess(self) -> None:
        """Uniform penetration under the mean pressure and the spring balancing μ W."""
        s = self.scene
        d0 = s.law.uniform_penetration(s.contact_pressure)
        ux = s.belt_direction * float(self.mu.value) * s.contact_pressure * s.L * s.B0 / s.K_x
        value = np.array([ux, -(d0 + s.g), 0.0][:s.dim])
        self.residual.u.interpolate(lambda x: np.tile(value[:, None], (1, x.shape[1])))

    def centre_of_mass(self) -> dict:
        """Displacement ``u_G`` and velocity ``v_G`` of the centre of mass (uniform density:
        the mean over the body), and the mean rotation ``theta`` = ∫ ½ curl u / area [rad]."""
        if "centre" not in self._functionals:
            R, dx = self.residual, self.dx
            forms = [f * dx for f in (*R.u, *R.u_dot)]
            curl = 0.5 * (R.u[1].dx(0) - R.u[0].dx(1))
            self._functionals["centre"] = [_compat.form(f) for f in (*forms, curl * dx,
                                                                      fem.Constant(self.msh, 1.0)
                                                                      * dx)]
        comm = self.msh.comm
        values = np.array([comm.allreduce(fem.assemble_scalar(f), op=MPI.SUM)
                           for f in self._functionals["centre"]])
        mean = values[:-1] / values[-1]
        dim = self.scene.dim
        return {"u_G": mean[:dim], "v_G": mean[dim:2 * dim], "theta": float(mean[-1])}

    def probe(self, x: float) -> dict:
        """Nodal values at the contact node nearest to abscissa ``x`` (same on every rank).

        ``x`` [cm] of the node; ``u_y``, ``v_x``, ``v_y``: its displacement and velocity;
        ``slip`` = v_x - U_T; ``pressure``: c_n d^{m_n} + b_n d^{l_n} ḋ; ``friction``: the
        x-traction of the belt on the body, -c_T d^{m_T} φ'_ε(slip) (Coulomb law only).
        """
        if "probe" not in self._functionals or self._functionals["probe"][0] != x:
            coords = self.V.tabulate_dof_coordinates()
            y = self._contact_y
            nodes = y // self.scene.dim
            distance = np.abs(coords[nodes, 0] - x) if y.size else np.array([np.inf])
            best = int(np.argmin(distance))
            comm = self.msh.comm
            _, owner = comm.allreduce((float(distance[best]), comm.rank), op=MPI.MINLOC)
            self._functionals["probe"] = (x, owner, int(y[best]) if y.size else -1,
                                          float(coords[nodes[best], 0]) if y.size else 0.0)
        _, owner, dof, node_x = self._functionals["probe"]
        s, law, comm = self.scene, self.scene.law, self.msh.comm
        values = None
        if comm.rank == owner:
            u, v = self.residual.u.x.array, self.residual.u_dot.x.array
            d = max(-u[dof] - s.g, 0.0)
            slip = v[dof - 1] - s.belt_direction * s.belt_speed
            rate = -v[dof] if d > 0 else 0.0
            pressure = laws.normal_pressure(d, law.c_n, law.m_n) \
                + laws.normal_damping_pressure(d, rate, law.b_n, law.l_n)
            direction = laws.REGULARISATIONS[s.regularisation][1](
                np.array([slip]), float(self.eps.value))[0]
            c_T = float(self.mu.value) * law.c_n if self.with_friction else 0.0
            values = {"x": node_x, "u_y": float(u[dof]), "v_x": float(v[dof - 1]),
                      "v_y": float(v[dof]), "slip": float(slip), "pressure": float(pressure),
                      "friction": float(-laws.friction_bound(d, c_T, law.m_T) * direction)}
        return comm.bcast(values, root=owner)

    def quantities(self) -> dict:
        """Resultants and penetration extremes of the current state (same on every rank).

        ``normal_force`` [force]: total normal contact force on the body (upwards > 0),
        normal damping included; ``normal_force_elastic``: its elastic part c_n d^{m_n}, which
        bounds the friction force (|F| <= μ N_elastic) and locates ``centre_of_pressure``;
        ``friction_force`` and ``spring_force`` [force]: x-components of the forces on the
        body; ``centre_of_pressure`` [cm]: x of the normal resultant minus L/2;
        ``min_penetration``/``max_penetration`` [cm] over the contact nodes.
        """
        elastic = self._integral("normal", self.pressure)
        normal = elastic
        if self.scene.law.b_n > 0:  # the damping part of the normal stress (zero at rest)
            law, n = self.scene.law, self.normal
            normal += self._integral("damping", lambda: laws.normal_damping_pressure(
                self.penetration(), normal_part(self.residual.u_dot, n), law.b_n, law.l_n))
        moment = self._integral("moment", lambda: (ufl.SpatialCoordinate(self.msh)[0]
                                                   - self.scene.L / 2) * self.pressure())
        friction_force = self._integral("friction", lambda: self.friction_traction()[0]) \
            if self.with_friction else 0.0
        uy = self.residual.u.x.array[self._contact_y]
        d = np.maximum(-uy - self.scene.g, 0.0)
        comm = self.msh.comm
        return {"mu": float(self.mu.value),
                "normal_force": normal, "normal_force_elastic": elastic,
                "friction_force": friction_force,
                "spring_force": self.spring.force(self.residual.u),
                "centre_of_pressure": moment / elastic if elastic > 0 else float("nan"),
                "min_penetration": comm.allreduce(d.min() if d.size else np.inf, op=MPI.MIN),
                "max_penetration": comm.allreduce(d.max() if d.size else -np.inf, op=MPI.MAX)}
