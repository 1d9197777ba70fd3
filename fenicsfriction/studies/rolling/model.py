r"""Kalker's complete theory of rolling contact by finite elements, and the Cattaneo-Mindlin shift.

Two quasi-identical elastic bodies (Kalker 1986, section 4): the normal problem is the
frictionless one, the tangential problem follows with the pressure :math:`p_n` given. Body 2's
tangential displacement is :math:`-u_\tau`, so the displacement difference is
:math:`\Delta u_\tau = 2u_\tau` of *one* elastic half-space, here a large clamped block
(:mod:`~fenicsfriction.studies.rolling.geometry`) loaded on its surface by the tangential
traction :math:`p_\tau` alone. Find u with

.. math::
    \int_\Omega \sigma(u):\varepsilon(v)\,dx - \int_{\Gamma_C} p_\tau(u)\cdot v_\tau\,ds = 0,
    \qquad p_\tau = -\mu\, p_n\, \phi_\varepsilon'(s)

for all v vanishing on the far faces, with the slip s (per unit rolling distance)

* steady rolling: :math:`s = w - \partial(\Delta u_\tau)/\partial x`, the rigid slip
  :math:`w = (\xi - \phi y,\ \eta + \phi x)` (2D: :math:`w = \xi`); rolling in +x, the
  material travels from the leading edge x = +a to −a, so that particles enter the contact
  unstrained and adhesion sits at the leading edge;
* the shift (no rolling; Cattaneo-Mindlin): per load increment
  :math:`s = \Delta u_\tau - \Delta u_\tau^{old} - \Delta\delta` with
  :math:`\Delta u_\tau = 2u_\tau`, the tractions of the increment committed before the next.

:math:`p_\tau` is the friction traction of the package's one interface law
(:class:`fenicsfriction.laws.InterfaceLaw`, its regularisations) with unit linear compliance read
on the pressure: :math:`c_n = 1`, :math:`m_n = m_T = 1`, :math:`d = p_n`;
ε → 0 by Kalker's sequential process (Kalker 1986, section 6,
:func:`fenicsfriction.steady.epsilon_sequence`). The residual is one UFL form
(:func:`fenicsfriction.forms.elasticity` and :func:`fenicsfriction.forms.surface_traction`)
solved by :class:`fenicsfriction.steady.SteadySolver`; a creep curve is a continuation, each
creepage starting from the last.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import pathlib
import time
import typing

from mpi4py import MPI

import numpy as np
import numpy.typing as npt
import ufl
from dolfinx import fem

from fenicsfriction import _compat, forms, laws
from fenicsfriction.assembly import assemble_owned
from fenicsfriction.io import FieldWriter
from fenicsfriction.laws import check, check_positive
from fenicsfriction.numerics import power_law_secant
from fenicsfriction.steady import SteadySolver, epsilon_sequence
from fenicsfriction.studies.rolling import closed_forms
from fenicsfriction.studies.rolling.geometry import CLAMPED, CONTACT, half_space
from fenicsfriction.studies.rolling.hertz import quasi_identical_modulus

__all__ = ["KINEMATICS", "PRESSURES", "RollingContact", "RollingModel", "RollingResult",
           "write_xdmf"]

#: the slip of :class:`RollingModel`: steady rolling or an incremental shift
KINEMATICS = ("rolling", "shift")
#: the normal pressure of :class:`RollingContact`
PRESSURES = ("hertz", "contact")
#: the default ε sequence, relative to the slip scale of each solve
#: (:meth:`RollingModel.slip_scale`): steps of sqrt(10) (by decades Newton needs 20-100
#: iterations for the ε after the first on Carter's problem, 5-10 by half-decades)
EPS_RELATIVE = tuple(10 ** (-k / 2) for k in range(-2, 5))
#: adhesion is where |s| < STICK_SLIP ε: with the smooth law, where the traction is below
#: 1/sqrt(1 + 1/9) = 95 % of the bound μ p_n (below 71 % at |s| < ε, which leaves a band of
#: stick out: on Carter's problem the stick zone's end is then 3h short at any h; at 3ε it is
#: within h, docs/rolling-fe.md)
STICK_SLIP = 3.0
#: Newton's options: the smooth law's stick-slip transition sharpens as ε falls
SOLVER_OPTIONS = {"snes_max_it": 100}


@dataclasses.dataclass
class RollingContact:
    """Two identical elastic bodies rolling (or shifted) over a Hertzian contact.

    Units are the user's (consistent). Modelling choices: the bodies are quasi-identical
    (the normal and tangential problems decouple); the half-space is a block of half-width
    and depth ``block_size`` × a, clamped on its far faces (in 2D the half-plane's
    displacement diverges logarithmically: the clamp biases the strain by about F/(E L)).

    Args:
        dim: 2 (plane strain, forces per unit length) or 3.
        a: the contact's semi-axis along the rolling direction x [length].
        b: the semi-axis across it [length] (3D; ``None``: a circle; ignored in 2D).
        G: shear modulus of both bodies [force/length²].
        nu: Poisson's ratio of both bodies.
        law: the interface law (:class:`~fenicsfriction.laws.InterfaceLaw`): its friction
            coefficient ``mu`` (or law μ(speed, pressure), read at the pressure p_n) and
            ``regularisation`` (``"smooth"``, Kalker 1986, eq. 40, or ``"c1"``,
            :data:`fenicsfriction.laws.REGULARISATIONS`; Newton stalls with ``"c1"`` on Carter's
            problem below ε ≈ 0.1 ξ, line search failures, docs/rolling-fe.md) make the
            tangential traction; its normal compliance c_n d^m_n [force/length^(2+m_n)] is
            that of ``pressure="contact"``. Its ε is not used: ``eps_sequence`` sets it.
            ``None``: μ = 0.3, the smooth regularisation, c_n = 1000 E*/a, m_n = 1 (a
            compliance stiff against the block's, whatever the units).
        p0: Hertz's peak pressure [force/length²]; or give ``Fn`` (neither: 0.01 G).
        Fn: the normal force [force] (2D: per unit length), instead of ``p0``.
        creepage: (ξ, η, φ): longitudinal and lateral creepage, spin [1/length] (2D: ξ only).
        eps_sequence: Kalker's sequence ε_k → 0 of the regularisation of the slip, relative to
            each solve's slip scale (:meth:`RollingModel.slip_scale`: the rigid slip's size, or
            μ p0/G if smaller) (``None``: :data:`EPS_RELATIVE`). Relative, because the
            linear theory's full adhesion (|ξ| ≪ μ p0/G) needs ε ≪ |ξ|.
        pressure: ``"hertz"`` (Hertz's p0 sqrt(1 - x²/a² - y²/b²)) or ``"contact"`` (2D: a
            frictionless normal-compliance contact of the block against a rigid parabola of
            radius 2R, R the cylinders' relative radius of Hertz's a and p0, with the law's
            normal compliance).
        cells_per_a: cells over the semi-axis a (the contact zone's cell size a / it).
        growth: size ratio of consecutive cells outside the contact zone.
        block_size: the block's half-width and depth over a.
        zone_margin: the uniform contact zone over the contact's semi-axes (>= 1; the
            ``"contact"`` pressure needs room for a contact that is not exactly Hertz's).
    """

    dim: int = 3
    a: float = 1.0
    b: float | None = None
    G: float = 1.0
    nu: float = 0.0
    law: laws.InterfaceLaw = None  # type: ignore[assignment]  # None: set by __post_init__
    p0: float | None = None
    Fn: float | None = None
    creepage: tuple[float, float, float] = (0.0, 0.0, 0.0)
    eps_sequence: tuple[float, ...] | None = None
    pressure: str = "hertz"
    cells_per_a: int = 8
    growth: float = 1.3
    block_size: float = 20.0
    zone_margin: float = 1.0

    def __post_init__(self) -> None:
        check("dim", self.dim, self.dim in (2, 3), "2 or 3")
        for name in ("a", "G", "growth", "block_size"):
            check_positive(name, getattr(self, name))
        # ν = 1/2 is refused: the displacement formulation locks for incompressible bodies
        check("nu", self.nu, -1 < self.nu < 0.5, "Poisson's ratio must be in (-1, 0.5)")
        if self.law is None:
            self.law = laws.InterfaceLaw(c_n=1e3 * self.E_star / self.a, m_n=1.0, mu=0.3,
                                         regularisation="smooth")
        check("law", self.law, isinstance(self.law, laws.InterfaceLaw) and self.law.has_friction,
              "must be a fenicsfriction.laws.InterfaceLaw with friction (mu > 0 or a law)")
        if self.dim == 3 and self.b is not None:
            check_positive("b", self.b)
        check("p0", self.p0, self.p0 is None or self.Fn is None, "give p0 or Fn, not both")
        if self.Fn is not None:
            check_positive("Fn", self.Fn)
        elif self.p0 is not None:
            check_positive("p0", self.p0)
        check("creepage", self.creepage, len(self.creepage) == 3
              and all(math.isfinite(c) for c in self.creepage), "three finite numbers (ξ, η, φ)")
        if self.eps_sequence is not None:
            check("eps_sequence", self.eps_sequence, len(self.eps_sequence) >= 1
                  and all(e > 0 for e in self.eps_sequence),
                  "a non-empty sequence of values > 0 (relative to the slip scale)")
        check("pressure", self.pressure, self.pressure in PRESSURES,
              f"one of {', '.join(PRESSURES)}")
        check("pressure", self.pressure, self.pressure == "hertz" or self.dim == 2,
              "'contact' is built in 2D only")
        check("cells_per_a", self.cells_per_a,
              isinstance(self.cells_per_a, int) and self.cells_per_a >= 1, "an integer >= 1")
        check("growth", self.growth, self.growth >= 1, "must be >= 1")
        check("block_size", self.block_size, self.block_size >= 2 * self.zone_margin,
              f"must be >= 2 zone_margin = {2 * self.zone_margin}")
        check("zone_margin", self.zone_margin, self.zone_margin >= 1, "must be >= 1")

    def with_law(self, **changes: typing.Any) -> typing.Self:
        """The scene with its law changed, e.g. ``scene.with_law(mu=0.5)``."""
        return dataclasses.replace(self, law=self.law.replace(**changes))

    @property
    def semi_axis_b(self) -> float | None:
        """b in 3D (a for a circle), ``None`` in 2D."""
        return None if self.dim == 2 else (self.a if self.b is None else self.b)

    @property
    def E_star(self) -> float:
        """The pair's contact modulus :math:`E^* = G/(1-\\nu)`."""
        return quasi_identical_modulus(self.G, self.nu)

    @property
    def peak_pressure(self) -> float:
        """Hertz's p0, from ``p0``, ``Fn`` or the default 0.01 G."""
        if self.Fn is not None:
            return self.Fn / closed_forms.ellipse_load(self.a, self.semi_axis_b, 1.0)
        return 0.01 * self.G if self.p0 is None else self.p0

    @property
    def normal_load(self) -> float:
        """Hertz's normal force (2D: per unit length)."""
        return closed_forms.ellipse_load(self.a, self.semi_axis_b, self.peak_pressure)

    @property
    def radius(self) -> float:
        """The relative radius R of Hertz's a and p0 in 2D (cylinders, Johnson 1985 ch. 4)."""
        return closed_forms.hertz_line_radius(self.a, self.peak_pressure, self.E_star)

    @property
    def creepage_scale(self) -> float:
        """μ p0 / G, the order of the creepage at which the contact saturates."""
        return self.law.coefficient(0.0, self.peak_pressure) * self.peak_pressure / self.G

    @property
    def eps_relative(self) -> tuple[float, ...]:
        """The ε sequence in use, relative to the slip scale."""
        return EPS_RELATIVE if self.eps_sequence is None else tuple(self.eps_sequence)

    def build(self, comm: MPI.Comm = MPI.COMM_WORLD, kinematics: str = "rolling"
              ) -> RollingModel:
        """The finite element model of the scene."""
        return RollingModel(self, comm, kinematics)


@dataclasses.dataclass
class RollingResult:
    """One solve: forces on body 1, adhesion and the surface's nodal values (all ranks).

    Attributes:
        Fx, Fy: tangential force on body 1 [force] (2D: per unit length; Fy = 0).
        Mz: spin moment about the contact's centre [force length] (2D: 0).
        Fn: normal force [force] (2D: per unit length).
        mu: friction coefficient.
        creepage: (ξ, η, φ) (rolling), ``None`` for the shift.
        shift: the accumulated tangential shift δ (x, y) (shift), ``None`` in rolling.
        adhesion_fraction: the share of the contact (2D: length, 3D: area; p_n > 0) where
            |s| < :data:`STICK_SLIP` ε, integrated with the residual's (nodal) rule.
        x: surface nodes over the contact zone, sorted by x then y, (n, dim).
        pressure, traction, slip: at those nodes, each a lumped L2 projection (nodal force
            over tributary length/area): p_n (n,), p_τ and s (n, dim - 1).
        eps: the last ε of the sequence.
        eps_records: one row per ε (:func:`fenicsfriction.steady.epsilon_sequence`): Newton
            iterations and the change of the solution from the previous ε.
        wall_time_s: the solve's wall time [s].
        newton_iterations: over the whole ε sequence.
    """

    Fx: float
    Fy: float
    Mz: float
    Fn: float
    mu: float
    creepage: tuple[float, ...] | None
    shift: tuple[float, ...] | None
    adhesion_fraction: float
    x: np.ndarray
    pressure: np.ndarray
    traction: np.ndarray
    slip: np.ndarray
    eps: float
    eps_records: list[dict]
    wall_time_s: float
    newton_iterations: int

    def stick(self) -> np.ndarray:
        """The nodes in adhesion: |s| < :data:`STICK_SLIP` ε where p_n > 0."""
        return (np.linalg.norm(self.slip, axis=1) < STICK_SLIP * self.eps) & (self.pressure > 0)


def rolling_slip(u: typing.Any, w: typing.Any, dim: int) -> typing.Any:
    """:math:`s = w - \\partial(2u_\\tau)/\\partial x` (a scalar in 2D)."""
    if dim == 2:
        return w - 2 * u[0].dx(0)
    return w - 2 * ufl.as_vector([u[0].dx(0), u[1].dx(0)])


def shift_slip(u: typing.Any, u_old: typing.Any, increment: typing.Any,
               dim: int) -> typing.Any:
    """:math:`s = 2(u_\\tau - u_\\tau^{old}) - \\Delta\\delta` (a scalar in 2D)."""
    if dim == 2:
        return 2 * (u[0] - u_old[0]) - increment[0]
    return 2 * ufl.as_vector([u[0] - u_old[0], u[1] - u_old[1]]) - increment


class RollingModel:
    """The mesh, the residual and its solver, built once; :meth:`solve` per creepage.

    Args:
        scene: the parameters.
        comm: the communicator.
        kinematics: ``"rolling"`` (steady rolling, :meth:`solve`, :meth:`creep_curve`) or
            ``"shift"`` (the incremental shift, :meth:`shift`).

    Attributes:
        msh, facet_tags, V, u: the mesh, its tags (``CONTACT`` is the contact zone), the
            displacement's space and the displacement.
        creepage: (ξ, η, φ) (``fem.Constant``); ``eps``, ``mu``: the law's constants.
        midpoint_x: rolling: x of each cell's midpoint (DG0), where the rigid slip and the
            spin moment's arm are read.
        increment, u_old: the shift's Δδ (``fem.Constant``) and the last increment's state.
        p_n: the normal pressure (UFL), ``slip`` and ``traction`` (UFL, dim - 1 components).
        residual, solver: the :class:`~fenicsfriction.forms.Residual` and its
            :class:`~fenicsfriction.steady.SteadySolver`.
    """

    CONTACT = CONTACT

    def __init__(self, scene: RollingContact, comm: MPI.Comm = MPI.COMM_WORLD,
                 kinematics: str = "rolling"):
        check("kinematics", kinematics, kinematics in KINEMATICS, f"one of {KINEMATICS}")
        self.scene, self.comm, self.kinematics = scene, comm, kinematics
        dim = self.dim = scene.dim
        zone = [scene.zone_margin * scene.a]
        if dim == 3:
            assert scene.semi_axis_b is not None
            zone.append(scene.zone_margin * scene.semi_axis_b)
        self.geometry = half_space(comm, dim, zone, scene.a / scene.cells_per_a,
                                   scene.block_size * scene.a, scene.growth)
        self.msh, self.facet_tags = self.geometry.mesh, self.geometry.facet_tags
        self.V = V = _compat.vector_function_space(self.msh, 1)
        self.u = fem.Function(V, name="displacement")
        self.u_old = fem.Function(V, name="previous_displacement")
        v = ufl.TestFunction(V)
        # the cells are boxes (affine maps), on which the Gauss rule of degree 2 integrates the
        # Q1 stiffness exactly; UFL's estimate for a hexahedral mesh's geometry is far higher
        # (9³ points per cell). The surface terms use the nodal rule: the law acts node by node
        self.dx = ufl.Measure("dx", domain=self.msh, metadata={"quadrature_degree": 2})
        self.ds = ufl.Measure("ds", domain=self.msh, subdomain_data=self.facet_tags,
                              metadata=_compat.nodal_quadrature(dim - 1, simplex=False))
        self.x = ufl.SpatialCoordinate(self.msh)
        self.creepage = fem.Constant(self.msh, np.asarray(scene.creepage, dtype=float))
        self.increment = fem.Constant(self.msh, np.zeros(dim - 1))
        self.eps = fem.Constant(self.msh, 1.0)
        self.mu = fem.Constant(self.msh, float(scene.law.mu))
        E = 2 * scene.G * (1 + scene.nu)
        self.E = E
        self.p_n = self._hertz_pressure() if scene.pressure == "hertz" else \
            self._contact_pressure()
        xi, eta, phi = self.creepage[0], self.creepage[1], self.creepage[2]
        if kinematics == "rolling":
            self.midpoint_x = _cell_midpoint_x(self.msh)
            # the rigid slip where the upwind difference is centred: the facet's midpoint in x
            # (at the node, the spin's φx would lag the difference by h/2: a lateral creepage
            # -φh/2, -1.3 h/a of the spin's Fy on the circle, docs/rolling-fe.md)
            w = xi if dim == 2 else ufl.as_vector([xi - phi * self.x[1],
                                                   eta + phi * self.midpoint_x])
            self.slip = rolling_slip(self.u, w, dim)
        else:
            self.slip = shift_slip(self.u, self.u_old, self.increment, dim)
        #: the scene's law read on the pressure (c_n = 1, m_n = m_T = 1, d = p_n: its bound is
        #: μ p_n, a friction coefficient law gets p_n), μ and ε the model's constants
        self.law = scene.law.replace(c_n=1.0, m_n=1.0, m_T=1.0, mu=self.mu, eps=self.eps)
        self.traction = self.law.friction_traction(self.p_n, self.slip)
        self.weight = self._upwind_weight() if kinematics == "rolling" else 1.0
        form = forms.elasticity(self.u, v, E, scene.nu, self.dx) \
            + forms.surface_traction(self.weight * self.contact_traction(), v, self.ds(CONTACT))
        zero = fem.Function(V)
        self.residual = forms.Residual(form, self.u, zero, zero, v, bcs=[self._clamp()])
        self.solver = SteadySolver(self.residual, prefix="rolling_", options=SOLVER_OPTIONS)
        self.shift_total: npt.NDArray[np.float64] = np.zeros(dim - 1)

    # --- the pieces of the residual ----------------------------------------------------------

    def _clamp(self) -> fem.DirichletBC:
        fdim = self.dim - 1
        dofs = fem.locate_dofs_topological(self.V, fdim, self.facet_tags.find(CLAMPED))
        return fem.dirichletbc(np.zeros(self.dim), dofs, self.V)

    def _hertz_pressure(self) -> typing.Any:
        s = self.scene
        r2 = (self.x[0] / s.a) ** 2
        if self.dim == 3:
            r2 = r2 + (self.x[1] / s.semi_axis_b) ** 2
        return s.peak_pressure * ufl.sqrt(ufl.max_value(1 - r2, 0.0))

    def _contact_pressure(self) -> typing.Any:
        """Frictionless normal compliance against a rigid parabola of radius 2R (the pair's
        Δu_n = 2u_n), pressed until the normal force is Hertz's; the pressure of that
        state, :func:`fenicsfriction.laws.normal_traction` of the penetration."""
        s = self.scene
        self.normal_displacement = u_n = fem.Function(self.V, name="normal_displacement")
        v = ufl.TestFunction(self.V)
        n = ufl.FacetNormal(self.msh)
        self.approach = fem.Constant(self.msh, 0.0)
        gap = self.x[0] ** 2 / (4 * s.radius) - self.approach / 2
        law = s.law.replace(g=gap)
        form = forms.elasticity(u_n, v, self.E, s.nu, self.dx) \
            + forms.normal_compliance(u_n, v, n, law, self.ds(CONTACT))
        zero = fem.Function(self.V)
        residual = forms.Residual(form, u_n, zero, zero, v, bcs=[self._clamp()])
        solver = SteadySolver(residual, prefix="rolling_normal_")
        pressure = law.normal_traction(laws.penetration(forms.normal_part(u_n, n), gap))
        load = _compat.form(pressure * self.ds(CONTACT))
        # the secant on log(force) against log(approach), from the rigid indentation's approach
        # a²/(2R): the force grows about linearly with it
        target, history = s.normal_load, []
        approach = s.a**2 / (2 * s.radius)
        for _ in range(30):
            self.approach.value = approach
            solver.solve()
            force = self.comm.allreduce(fem.assemble_scalar(load))
            if abs(force / target - 1) < 1e-8:
                break
            history.append((math.log(approach), math.log(force)))
            if len(history) == 1:
                approach *= target / force
                continue
            (x0, y0), (x1, y1) = history[-2:]
            approach = math.exp(power_law_secant(x0, y0, x1, y1, math.log(target)))
        else:
            raise RuntimeError(f"the normal force {force:.6g} did not reach {target:.6g}")
        self.normal_solver = solver
        return pressure

    def contact_traction(self) -> typing.Any:
        """The tangential traction on body 1 as a vector of the mesh's dimension."""
        t = self.traction
        return ufl.as_vector([t, 0.0] if self.dim == 2 else [t[0], t[1], 0.0])

    def _upwind_weight(self) -> typing.Any:
        """The upwind nodal rule: each surface facet's weight on its vertices at its
        downstream (lower x) edge, none on its upstream edge.

        On the tensor-product grid a Q1 field's ∂u/∂x at a facet's vertex is the difference
        along the facet's edge in x, so a node's slip is :math:`w(x_i + h/2) - 2(u_{i+1} -
        u_i)/h` (the rigid slip at the facet's midpoint, where the difference is centred): the
        node's and its upstream neighbour's, Kalker's discretisation of the convective
        derivative from the leading edge (Kalker 1990, chapter 2). The leading edge's node
        carries no traction (the material enters unstrained), which selects the solution of
        the rolling direction; the Galerkin (central) rule is blind to it, and at small
        creepage, where no slip zone is resolved, it returned an antisymmetric traction of
        nearly no net force (docs/rolling-fe.md)."""
        return ufl.conditional(ufl.gt(self.midpoint_x, self.x[0]), 2.0, 0.0)

    # --- observables ------------------------------------------------------------------------

    @functools.cached_property
    def _scalars(self) -> dict[str, typing.Any]:
        t, ds = self.contact_traction(), self.ds(CONTACT)
        in_contact = ufl.conditional(ufl.gt(self.p_n, 0.0), self.weight, 0.0)
        stick = ufl.conditional(ufl.lt(_magnitude(self.slip), STICK_SLIP * self.eps),
                                in_contact, 0.0)
        t = self.weight * t
        values = {"Fx": t[0] * ds, "Fn": self.weight * self.p_n * ds, "contact": in_contact * ds,
                  "stick": stick * ds}
        if self.dim == 3:
            # rolling: a node's traction is that of the slip at its facet's midpoint in x,
            # the moment's arm too (at the node, the arm is h/2 short: -0.55 h/a of the
            # spin's Mz on the circle, docs/rolling-fe.md)
            arm = self.midpoint_x if self.kinematics == "rolling" else self.x[0]
            values.update(Fy=t[1] * ds, Mz=(arm * t[1] - self.x[1] * t[0]) * ds)
        return {k: _compat.form(f) for k, f in values.items()}

    def _scalar(self, name: str) -> float:
        if name not in self._scalars:
            return 0.0
        return float(self.comm.allreduce(fem.assemble_scalar(self._scalars[name])))

    @functools.cached_property
    def _nodal(self) -> tuple[fem.FunctionSpace, typing.Any]:
        """P1 nodes of the contact zone and the form of (1, p_n, p_τ, s) · φ_i integrated."""
        t = self.dim - 1
        Q = _compat.lagrange_vector_space(self.msh, 1, 2 + 2 * t)
        slip = self.slip if t > 1 else ufl.as_vector([self.slip])
        traction = self.traction if t > 1 else ufl.as_vector([self.traction])
        values = self.weight * ufl.as_vector([1.0, self.p_n, *[traction[i] for i in range(t)],
                                              *[slip[i] for i in range(t)]])
        return Q, _compat.form(ufl.inner(values, ufl.TestFunction(Q)) * self.ds(CONTACT))

    def surface_values(self) -> dict[str, np.ndarray]:
        """The contact zone's nodes ``x`` and their lumped ``pressure``, ``traction`` and
        ``slip`` (integral against the node's hat function over the hat's integral), gathered
        on every rank and sorted by x, then y."""
        Q, form = self._nodal
        values = assemble_owned(form).reshape(-1, Q.dofmap.index_map_bs)
        owned = np.flatnonzero(values[:, 0] > 0)
        x = Q.tabulate_dof_coordinates()[owned, :self.dim]
        local = np.column_stack([x, values[owned, 1:] / values[owned, :1]])
        rows = np.vstack(self.comm.allgather(local))
        rows = rows[np.lexsort(rows[:, :self.dim].T[::-1])]
        t = self.dim - 1
        d = self.dim
        return {"x": rows[:, :d], "pressure": rows[:, d], "traction": rows[:, d + 1:d + 1 + t],
                "slip": rows[:, d + 1 + t:]}

    def result(self, records: list[dict], wall_time_s: float) -> RollingResult:
        """The observables of the current state."""
        contact = self._scalar("contact")
        nodal = self.surface_values()
        rolling = self.kinematics == "rolling"
        return RollingResult(
            Fx=self._scalar("Fx"), Fy=self._scalar("Fy"), Mz=self._scalar("Mz"),
            Fn=self._scalar("Fn"), mu=float(self.mu.value),
            creepage=tuple(float(c) for c in self.creepage.value) if rolling else None,
            shift=None if rolling else tuple(float(s) for s in self.shift_total),
            adhesion_fraction=self._scalar("stick") / contact if contact > 0 else 0.0,
            x=nodal["x"], pressure=nodal["pressure"], traction=nodal["traction"],
            slip=nodal["slip"], eps=float(self.eps.value), eps_records=records,
            wall_time_s=wall_time_s,
            newton_iterations=sum(r["newton_iterations"] for r in records))

    # --- solves -----------------------------------------------------------------------------

    def slip_scale(self) -> float:
        """The size of the rigid slip of the next solve, capped at the creepage of
        saturation's order μ p0/G (rolling: |ξ| + |η| + |φ| max(a, b); the shift: |Δδ| over a,
        times a): the unit of the ε sequence."""
        s = self.scene
        cap = s.creepage_scale
        if self.kinematics == "shift":
            size = float(np.linalg.norm(self.increment.value))
            return min(size, cap * s.a) if size > 0 else cap * s.a
        xi, eta, phi = (float(c) for c in self.creepage.value)
        size = abs(xi) + abs(eta) + abs(phi) * max(s.a, s.semi_axis_b or s.a)
        return min(size, cap) if size > 0 else cap

    def _sequence(self) -> list[dict]:
        scale = self.slip_scale()
        return epsilon_sequence(self.solver, self.eps,
                                [e * scale for e in self.scene.eps_relative])

    def solve(self, creepage: typing.Sequence[float] | None = None) -> RollingResult:
        """Steady rolling at ``creepage`` (ξ, η, φ) (default: the scene's), by the ε sequence
        from the current state."""
        check("kinematics", self.kinematics, self.kinematics == "rolling", "'rolling'")
        if creepage is not None:
            check("creepage", creepage, len(creepage) == 3, "three numbers (ξ, η, φ)")
            self.creepage.value = np.asarray(creepage, dtype=float)
        t0 = time.perf_counter()
        records = self._sequence()
        return self.result(records, time.perf_counter() - t0)

    def creep_curve(self, creepages: typing.Iterable[typing.Sequence[float]]
                    ) -> list[RollingResult]:
        """:meth:`solve` at each creepage in turn, each starting from the last."""
        return [self.solve(c) for c in creepages]

    def shift(self, total: typing.Sequence[float], increments: int
              ) -> list[RollingResult]:
        """Shift the bodies by ``total`` (δ_x, δ_y in 3D; δ_x in 2D) in equal increments, the
        ε sequence in each, the tractions committed after each; one result per increment."""
        check("kinematics", self.kinematics, self.kinematics == "shift", "'shift'")
        check("increments", increments, isinstance(increments, int) and increments >= 1,
              "an integer >= 1")
        step = np.asarray(total, dtype=float) / increments
        check("total", total, step.shape == (self.dim - 1,), f"{self.dim - 1} number(s)")
        results = []
        for _ in range(increments):
            t0 = time.perf_counter()
            self.u_old.x.array[:] = self.u.x.array
            self.increment.value = step
            self.shift_total = self.shift_total + step
            records = self._sequence()
            results.append(self.result(records, time.perf_counter() - t0))
        return results

    @property
    def dofs(self) -> int:
        """Number of displacement unknowns."""
        return self.V.dofmap.index_map.size_global * self.V.dofmap.index_map_bs


def _cell_midpoint_x(msh: typing.Any) -> fem.Function:
    """x of each cell's midpoint (DG0); on a surface facet, the facet's midpoint in x."""
    midpoint = fem.Function(_compat.scalar_function_space(msh, "DG", 0))
    midpoint.interpolate(lambda x: x[0])  # DG0: at the cell's midpoint
    return midpoint


def _magnitude(w: typing.Any) -> typing.Any:
    """|w| of a UFL scalar or vector."""
    return ufl.sqrt(ufl.inner(w, w)) if w.ufl_shape else abs(w)


def write_xdmf(path: str | pathlib.Path, model: RollingModel, t: float = 0.0) -> None:
    """Write the displacement and the surface traction (interpolated at the nodes, zero off
    the contact zone) of ``model``'s current state to an XDMF file (ParaView)."""
    with FieldWriter(path, model) as writer:
        writer.write(t)
