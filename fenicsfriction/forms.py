r"""The regularised virtual-power residual of Problem 1ε as a sum of UFL terms.

.. math::
    R(u, \dot u, \ddot u; v) = \rho\langle\ddot u, v\rangle + a(u, v) + \langle P(u), v\rangle
        + \langle D(u, \dot u), v\rangle + \langle J_\varepsilon(u, \dot u), v\rangle
        - \langle f, v\rangle

Each term is a small pure function returning a UFL form; a scene adds up the ones it needs
(a frictionless scene has no friction term, a static one no inertia). Everything else is
*derived* from the one residual with :func:`ufl.derivative` and :func:`ufl.replace`:

* steady sliding (Problem 2): :math:`R(u_0, 0, 0; v)` and its Jacobian;
* stability (Problem 3): :math:`M = \partial R/\partial\ddot u`,
  :math:`C = \partial R/\partial\dot u`, :math:`\bar K = \partial R/\partial u` at
  :math:`(u_0, 0, 0)`.

A researcher can read or extend ``Residual.form`` before anything is compiled; see
``demos/demo_block_steady.py`` for a term added to the block and the problem re-solved.
"""

from __future__ import annotations

import dataclasses
import typing

import numpy as np
import ufl
from dolfinx import fem

from fenicsfriction import laws
from fenicsfriction.elasticity import lame

__all__ = [
    "NodalSpring",
    "Residual",
    "body_force",
    "centrifugal_softening",
    "centripetal_load",
    "convective_derivative",
    "elastic_support",
    "elasticity",
    "friction",
    "geometric_stiffness",
    "gyroscopic",
    "inertia",
    "normal_compliance",
    "normal_damping",
    "normal_part",
    "surface_traction",
    "tangential_part",
]

Value: typing.TypeAlias = typing.Any  # a float or a UFL expression (e.g. a fem.Constant)
Field = typing.Any  # a UFL vector expression: a Function, an Argument, a FacetNormal, ...


# --- kinematics on Γ_C ---------------------------------------------------------------------------

def normal_part(w: Field, n: Field) -> Field:
    """:math:`w_n = w \\cdot n`."""
    return ufl.dot(w, n)


def tangential_part(w: Field, n: Field) -> Field:
    """:math:`w_T = w - (w\\cdot n) n`."""
    return w - ufl.dot(w, n) * n


# --- bulk terms ----------------------------------------------------------------------------------

def inertia(rho: Value, u_ddot: Field, v: Field, dx: ufl.Measure) -> ufl.Form:
    """:math:`\\rho \\langle \\ddot u, v\\rangle`."""
    return rho * ufl.inner(u_ddot, v) * dx


def elasticity(u: Field, v: Field, E: Value, nu: Value, dx: ufl.Measure,
               plane_stress: bool = False) -> ufl.Form:
    """:math:`a_0(u, v) = \\int_\\Omega \\sigma(u):\\varepsilon(v)`, isotropic Hooke's law.

    In 2D the default is plane strain (the block of Martins & Oden 1986);
    ``plane_stress=True`` switches.
    """
    lmbda, mu = lame(E, nu, plane_stress)
    eps_u, eps_v = ufl.sym(ufl.grad(u)), ufl.sym(ufl.grad(v))
    sigma = 2 * mu * eps_u + lmbda * ufl.tr(eps_u) * ufl.Identity(len(u))
    return ufl.inner(sigma, eps_v) * dx


def elastic_support(u: Field, v: Field, K: Value, U_E: Field, ds: ufl.Measure) -> ufl.Form:
    """Distributed linear springs on :math:`\\Gamma_E`: :math:`\\int K (u - U^E)\\cdot v`."""
    return ufl.inner(K * (u - U_E), v) * ds


def body_force(b: Field, v: Field, dx: ufl.Measure) -> ufl.Form:
    """Load term :math:`-\\int_\\Omega b\\cdot v` (residual sign convention: R = internal - f)."""
    return -ufl.inner(b, v) * dx


def surface_traction(t: Field, v: Field, ds: ufl.Measure) -> ufl.Form:
    """Load term :math:`-\\int_{\\Gamma_F} t\\cdot v`."""
    return -ufl.inner(t, v) * ds


# --- interface terms on Γ_C (Martins & Oden 1986, eqs. 14-16) ----------------------------------
# Each takes the interface law (:class:`fenicsfriction.laws.InterfaceLaw`), whose values a model
# replaces by its ``fem.Constant`` (``law.replace(mu=..., c_n=...)``) to change them without
# recompiling.

def normal_compliance(u: Field, v: Field, n: Field, law: laws.InterfaceLaw,
                      ds: ufl.Measure) -> ufl.Form:
    """:math:`\\langle P(u), v\\rangle = \\int_{\\Gamma_C} c_n (u_n - g)_+^{m_n} v_n`."""
    d = laws.penetration(normal_part(u, n), law.g)
    return law.pressure(d) * normal_part(v, n) * ds


def normal_damping(u: Field, u_dot: Field, v: Field, n: Field, law: laws.InterfaceLaw,
                   ds: ufl.Measure) -> ufl.Form:
    """:math:`\\langle D(u,\\dot u), v\\rangle = \\int_{\\Gamma_C} b_n d^{l_n} \\dot u_n v_n`."""
    d = laws.penetration(normal_part(u, n), law.g)
    return law.damping_pressure(d, normal_part(u_dot, n)) * normal_part(v, n) * ds


def friction(u: Field, u_dot: Field, v: Field, n: Field, law: laws.InterfaceLaw, U_T: Field,
             ds: ufl.Measure) -> ufl.Form:
    """Regularised friction power :math:`\\langle J_\\varepsilon(u,\\dot u), v\\rangle`.

    .. math:: \\int_{\\Gamma_C} c_T\\, d^{m_T}\\, \\phi_\\varepsilon'(\\dot u_T - U_T)\\cdot v_T

    that is :math:`-\\int t_T \\cdot v_T` with the law's traction
    (:meth:`fenicsfriction.laws.InterfaceLaw.friction_traction`): constant μ, a friction
    coefficient law μ(speed, pressure) (its slopes then enter every derivative) and the law's
    slip rule (e.g. orthotropic friction with :class:`~fenicsfriction.laws.EllipticSlipRule`).
    """
    d = laws.penetration(normal_part(u, n), law.g)
    w = tangential_part(u_dot, n) - U_T
    return -ufl.inner(law.friction_traction(d, w), tangential_part(v, n)) * ds


# --- a body spinning rigidly, described at fixed points in space (Eulerian) --------------------
# The mesh does not rotate: material flows through it with the rigid velocity w = ω a × (x - p)
# (:meth:`fenicsfriction.rotation.RigidRotation.velocity`) and u(x, t) is the displacement of
# the material point passing through x. Its acceleration is
#     ü + 2 (w·∇)u̇ + (w·∇)(w·∇)u + (w·∇)w
# exactly (the terms are linear in u). The three terms below are its virtual power beyond
# :func:`inertia`, with the convective ones integrated by parts; this is exact when ρ is uniform,
# div w = 0 (any rigid rotation) and w·n = 0 on the whole boundary: a body of revolution about
# the axis of rotation (a disc, a ring, a drum), supports and contact included, since a
# surface term on a part of the boundary does not change w·n.

def convective_derivative(w: Field, u: Field) -> Field:
    """:math:`(w\\cdot\\nabla)u = (\\nabla u)\\,w`, the rate of change of u seen by a material
    point moving with velocity w through fixed space."""
    return ufl.dot(ufl.grad(u), w)


def gyroscopic(rho: Value, w: Field, u_dot: Field, v: Field, dx: ufl.Measure) -> ufl.Form:
    """Gyroscopic (Coriolis) term of the Eulerian description, in skew form.

    .. math::
        \\rho\\langle(\\nabla\\dot u)\\,w, v\\rangle
        - \\rho\\langle\\dot u, (\\nabla v)\\,w\\rangle

    It equals :math:`2\\rho\\langle(w\\cdot\\nabla)\\dot u, v\\rangle` when ρ is uniform,
    div w = 0 and w·n = 0 on the boundary (a body of revolution spinning about its axis of
    symmetry); otherwise the integration by parts drops
    :math:`\\int_{\\partial\\Omega}\\rho\\,(w\\cdot n)\\,\\dot u\\cdot v` and
    :math:`\\int_\\Omega \\mathrm{div}(\\rho w)\\,\\dot u\\cdot v`. In this form the discrete
    matrix :math:`G = \\partial R/\\partial\\dot u` is skew, :math:`G = -G^T`, on any mesh and
    with any element: it does no work, as the Coriolis force does not.

    Args:
        rho: mass density [kg/m³].
        w: the rigid velocity field [m/s] (``RigidRotation.velocity(SpatialCoordinate)``).
        u_dot: the displacement's time derivative at a fixed point in space [m/s].
        v: the test function.
        dx: the body's volume measure.
    """
    return rho * (ufl.inner(convective_derivative(w, u_dot), v)
                  - ufl.inner(u_dot, convective_derivative(w, v))) * dx


def centrifugal_softening(rho: Value, w: Field, u: Field, v: Field, dx: ufl.Measure) -> ufl.Form:
    """Convective term :math:`\\rho\\langle(w\\cdot\\nabla)(w\\cdot\\nabla)u, v\\rangle`,
    integrated by parts:

    .. math:: -\\rho\\langle(\\nabla u)\\,w, (\\nabla v)\\,w\\rangle

    Its matrix :math:`-K_c` is symmetric negative semi-definite and needs only first
    derivatives (valid with P1 elements). The integration by parts is exact under the
    conditions of :func:`gyroscopic`; otherwise it drops
    :math:`\\int_{\\partial\\Omega}\\rho\\,(w\\cdot n)\\,((w\\cdot\\nabla)u)\\cdot v` and
    :math:`\\int_\\Omega \\mathrm{div}(\\rho w)\\,((w\\cdot\\nabla)u)\\cdot v`. It is the
    Eulerian form of the centrifugal softening :math:`\\rho\\,\\omega\\times(\\omega\\times u)`
    of the co-rotating frame; the stiffening by the centrifugal prestress is not in it (it
    comes from the geometric stiffness of the stress :func:`centripetal_load` causes).
    """
    return -rho * ufl.inner(convective_derivative(w, u), convective_derivative(w, v)) * dx


def centripetal_load(rho: Value, w: Field, v: Field, dx: ufl.Measure) -> ufl.Form:
    """The rigid motion's own acceleration :math:`\\rho\\langle(w\\cdot\\nabla)w, v\\rangle`.

    For a rigid rotation :math:`(w\\cdot\\nabla)w = \\omega\\times(\\omega\\times r)
    = -\\omega^2 r_\\perp` (:math:`r_\\perp` the distance vector from the axis): in the residual
    (internal minus external) it is the centrifugal body force
    :math:`\\rho\\,\\omega^2 r_\\perp` as a load, a steady term independent of u whose static
    response is the centrifugal prestress. No integration by parts: valid for any body.
    """
    return rho * ufl.inner(convective_derivative(w, w), v) * dx



def geometric_stiffness(sigma0: Field, u: Field, v: Field, dx: ufl.Measure) -> ufl.Form:
    """Stiffness of a prestress :math:`\\sigma_0`:
    :math:`\\int_\\Omega \\sigma_0 : (\\nabla u)^T\\nabla v = \\langle(\\nabla u)\\sigma_0,
    \\nabla v\\rangle`.

    The linearisation of the Green-Lagrange strain's quadratic part about a stressed state
    (small strain, σ0 symmetric). For a spinning body, σ0 = σ(u_c) with u_c the static
    response to :func:`centripetal_load`: the centrifugal stiffening that, added to
    :func:`centrifugal_softening`, makes a free body's rigid rotation neutral again.
    """
    return ufl.inner(ufl.dot(ufl.grad(u), sigma0), ufl.grad(v)) * dx

# --- nodal springs (point loads are not UFL integrals in dolfinx 0.5) ----------------------------

@dataclasses.dataclass
class NodalSpring:
    """A linear spring on one displacement component of one node: force -K (u_i - U).

    It is the one contribution to the residual that is not a UFL integral (dolfinx has no
    point measure); being linear, its Jacobian is exactly K on the node's diagonal entry and it
    contributes to :math:`\\bar K` only. On each rank ``local_dof`` is the dof's local index
    (unrolled, block size included) or ``-1`` where the rank does not own the dof.
    """

    stiffness: float
    anchor: float
    local_dof: int
    global_dof: int
    position: np.ndarray

    @classmethod
    def at_point(cls, V: fem.FunctionSpace, point: typing.Sequence[float], component: int,
                 stiffness: float, anchor: float = 0.0, tol: float = 1e-10) -> NodalSpring:
        """Attach to the node of ``V`` at ``point`` (it must be a node of the mesh)."""
        laws.check("stiffness", stiffness, stiffness > 0, "the spring stiffness must be > 0")
        Vc, to_parent = V.sub(component).collapse()
        position = np.asarray(point, dtype=float)
        dofs = fem.locate_dofs_geometrical(
            (V.sub(component), Vc),
            lambda x: np.linalg.norm(x[:len(position)] - position[:, None], axis=0) < tol)[0]
        bs, index_map = V.dofmap.index_map_bs, V.dofmap.index_map
        owned = dofs[dofs < index_map.size_local * bs]
        comm = V.mesh.comm
        count = comm.allreduce(len(owned))
        laws.check("point", position.tolist(), count == 1,
                   f"the spring must sit on exactly one node of the mesh (found {count})")
        local = int(owned[0]) if len(owned) else -1
        g = -1
        if local >= 0:
            g = int(index_map.local_to_global(np.array([local // bs], dtype=np.int32))[0] * bs
                    + local % bs)
        g = comm.allreduce(g, op=__import__("mpi4py").MPI.MAX)
        return cls(stiffness=float(stiffness), anchor=float(anchor), local_dof=local,
                   global_dof=g, position=position)

    def add_to_residual(self, b_local: np.ndarray, x_local: np.ndarray) -> None:
        """``b += K (x_i - U)`` on the owning rank (arrays are local, owned part first)."""
        if self.local_dof >= 0:
            b_local[self.local_dof] += self.stiffness * (x_local[self.local_dof] - self.anchor)

    def add_to_matrix(self, A: typing.Any) -> None:
        """``A[i, i] += K`` (call between assembly and ``A.assemble()``)."""
        if self.local_dof >= 0:
            from petsc4py import PETSc
            A.setValue(self.global_dof, self.global_dof, self.stiffness, addv=PETSc.InsertMode.ADD)

    def force(self, u: fem.Function) -> float:
        """Force exerted by the spring on the body, -K (u_i - U), on every rank."""
        value = 0.0
        if self.local_dof >= 0:
            value = -self.stiffness * (u.x.array[self.local_dof] - self.anchor)
        return u.function_space.mesh.comm.allreduce(value)


# --- the residual and what is derived from it ----------------------------------------------------

@dataclasses.dataclass
class Residual:
    """The one residual R(u, u̇, ü; v) of Problem 1ε and everything derived from it.

    Attributes:
        form: the full dynamic residual (UFL), linear in the test function ``v``.
        u, u_dot, u_ddot: the fields R depends on (Functions of one space V).
        v: the test function of ``form``.
        bcs: Dirichlet conditions on V (homogeneous; may be empty).
        springs: nodal springs added to R outside UFL (see :class:`NodalSpring`).
        couplings: terms between two points of the mesh that no integral of ``form`` holds,
            e.g. two-body contact (:class:`fenicsfriction.contact.NodeToSegment`): UFL forms
            of their own, chained into R and its derivatives by the solvers.
        friction: the ``fem.Constant`` that every friction term of ``form`` and of
            ``couplings`` is linear in, 0 meaning no friction (a model's constant μ); None
            when no such constant exists. The stability solver assembles K̄ and C with it set
            to 0 to drop their friction parts (``friction_stiffness``/``friction_damping`` of
            :class:`fenicsfriction.stability.StabilitySolver`).
    """

    form: ufl.Form
    u: fem.Function
    u_dot: fem.Function
    u_ddot: fem.Function
    v: ufl.Argument
    bcs: list = dataclasses.field(default_factory=list)
    springs: list = dataclasses.field(default_factory=list)
    couplings: list = dataclasses.field(default_factory=list)
    friction: fem.Constant | None = None

    @property
    def V(self) -> fem.FunctionSpace:
        return self.u.function_space

    def at_rest(self, form: ufl.Form) -> ufl.Form:
        """``form`` with u̇ = ü = 0 substituted (UFL drops the terms that vanish)."""
        zero = ufl.zero(*self.u.ufl_shape)
        return ufl.replace(form, {self.u_dot: zero, self.u_ddot: zero})

    def steady(self) -> ufl.Form:
        """Problem 2: the steady-sliding residual R(u0, 0, 0; v)."""
        return self.at_rest(self.form)

    def derivative(self, form: ufl.Form, field: fem.Function) -> ufl.Form:
        """Gateaux derivative of ``form`` with respect to ``field`` (trial function of V)."""
        return ufl.derivative(form, field, ufl.TrialFunction(self.V))

    def steady_jacobian(self) -> ufl.Form:
        """Jacobian of the steady residual with respect to u."""
        return self.derivative(self.steady(), self.u)

    def linearisation(self) -> tuple[ufl.Form, ufl.Form, ufl.Form]:
        """(M, C, K̄) = (∂R/∂ü, ∂R/∂u̇, ∂R/∂u) at (u, 0, 0); empty forms are returned as-is."""
        return tuple(self.at_rest(self.derivative(self.form, f))
                     for f in (self.u_ddot, self.u_dot, self.u))
