r"""The simplified disc brake: two elastic pads pressed on a rotating elastic disc.

The residual is the sum of the package's terms (:mod:`fenicsfriction.forms`): Hooke's law and
inertia in each body, the brake pressure :math:`p` on the pads' backs
(:math:`-\int_{\Gamma_p} (-p\,n)\cdot v`), and two node-to-segment contacts
(:class:`fenicsfriction.contact.NodeToSegment`), each pad's friction face (slave) against the
disc's face it lies on (master), with the package's interface law: normal compliance and
regularised Coulomb friction on the slip velocity

.. math:: w = \dot u_{pad} - \dot u_{disc} - \omega\, e_z\times x,

the last term the disc's rigid rotation (:class:`fenicsfriction.rotation.RigidRotation`). The
disc is Eulerian: its mesh does not turn and its material moves through it, an approximation
that keeps the disc's own inertia as that of a disc at rest (no gyroscopic or centrifugal
terms, which grow as ω and ω²). This is the usual complex eigenvalue analysis of brake squeal
(reviewed by Kinkaid, O'Reilly & Papadopoulos 2003, J. Sound Vib. 267, 105-166).

Supports: the disc is clamped on its hub; each pad is held in its plane (x and y) on its two
radial end faces, the abutments of the caliper, and free along the axis, where the pressure
and the contact balance it.

Steady sliding (:meth:`BrakeModel.solve_steady`) is :math:`R(u_0, 0, 0) = 0`; its stability the
quadratic eigenproblem :math:`(\lambda^2 M + \lambda C + \bar K)\phi = 0` of the same residual's
derivatives (:class:`fenicsfriction.stability.StabilitySolver`). Friction makes :math:`\bar K`
nonsymmetric (the follower friction force), which can merge two modes into a growing one
(mode coupling) once μ exceeds μ_crit; ``C`` holds the friction's viscous part
:math:`\mu p/|w|` across the sliding direction (small when the slip speed is much larger than ε).
"""

from __future__ import annotations

import dataclasses
import functools
import typing

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem

from fenicsfriction import _compat, cea, forms, laws
from fenicsfriction.contact import NodeToSegment, solve_with_search
from fenicsfriction.discs import DISC, DISC_BOTTOM, DISC_HUB, DISC_TOP
from fenicsfriction.laws import check
from fenicsfriction.rotation import RigidRotation
from fenicsfriction.stability import StabilitySolver
from fenicsfriction.steady import SteadySolver
from fenicsfriction.studies.brake.geometry import (
    PAD_IN,
    PAD_IN_ABUTMENT,
    PAD_IN_BACK,
    PAD_IN_FACE,
    PAD_OUT,
    PAD_OUT_ABUTMENT,
    PAD_OUT_BACK,
    PAD_OUT_FACE,
    BrakeMesh,
)

__all__ = ["CAST_IRON", "FRICTION_MATERIAL", "BrakeModel", "Solid", "default_law"]


@dataclasses.dataclass(frozen=True)
class Solid:
    """An isotropic linear elastic solid.

    Attributes:
        E: Young's modulus [Pa].
        nu: Poisson's ratio [-].
        rho: mass density [kg/m³].
    """

    E: float
    nu: float
    rho: float

    def __post_init__(self) -> None:
        laws.check_positive("E", self.E)
        laws.check_positive("rho", self.rho)
        check("nu", self.nu, -1 < self.nu < 0.5, "Poisson's ratio must be in (-1, 0.5)")


#: grey cast iron, the disc
CAST_IRON = Solid(E=125e9, nu=0.25, rho=7200.0)
#: an organic friction material, the pads (isotropic here)
FRICTION_MATERIAL = Solid(E=8e9, nu=0.25, rho=2500.0)


def default_law(mu: float = 0.0) -> laws.InterfaceLaw:
    """The pad-disc interface: linear normal compliance c_n = 1e13 Pa/m (a contact layer ten
    times stiffer than a 10 mm pad, E/t = 8e11 Pa/m), Coulomb friction μ regularised over
    ε = 1e-3 m/s (a ten-thousandth of the sliding speed at the default ω)."""
    return laws.InterfaceLaw(c_n=1e13, m_n=1.0, mu=mu, eps=1e-3)


class BrakeModel:
    """The brake's residual, its steady sliding and its eigenproblem.

    Args:
        mesh: the brake's mesh (:func:`fenicsfriction.studies.brake.geometry.brake`).
        law: the interface law (its μ is the starting value of :attr:`mu`, a ``fem.Constant``
            that a sweep changes without compiling again); default :func:`default_law`.
        pressure: the pressure on the pads' backs [Pa].
        omega: the disc's angular velocity [rad/s], counter-clockwise about +z (default 100:
            11 m/s at the pads' mean radius). It enters through the friction's viscous part
            μp/|w| only, which damps the modes that slide the pads on the disc: on the 6 mm
            mesh with the free disc (docs/brake.md) the n = 3 doublet coupled from μ = 0.086 at
            100 rad/s, not up to 0.8 at 10.
        disc, pad: the solids (default grey cast iron and a friction material).

    Attributes:
        V, u: the displacement space and the displacement (the steady state after a solve).
        mu, pressure, omega: ``fem.Constant``.
        contacts: the two :class:`~fenicsfriction.contact.NodeToSegment` (inboard, outboard).
        residual: the one residual (:class:`~fenicsfriction.forms.Residual`).
    """

    def __init__(self, mesh: BrakeMesh, law: laws.InterfaceLaw | None = None,
                 pressure: float = 1e6, omega: float = 100.0, disc: Solid = CAST_IRON,
                 pad: Solid = FRICTION_MATERIAL):
        laws.check_positive("pressure", pressure)
        law = law or default_law()
        self.mesh = mesh
        msh, cell_tags, facet_tags = mesh.mesh, mesh.cell_tags, mesh.facet_tags
        self.comm: MPI.Comm = msh.comm
        self.V = V = _compat.vector_function_space(msh, 1)
        self.u = fem.Function(V, name="displacement")
        u_dot = fem.Function(V, name="velocity")
        u_ddot = fem.Function(V, name="acceleration")
        v = ufl.TestFunction(V)
        dx = ufl.Measure("dx", domain=msh, subdomain_data=cell_tags)
        ds = ufl.Measure("ds", domain=msh, subdomain_data=facet_tags)
        self.mu = fem.Constant(msh, float(law.mu))
        self.pressure = fem.Constant(msh, float(pressure))
        self.omega = fem.Constant(msh, float(omega))
        self.law = law.replace(mu=self.mu)
        form = forms.surface_traction(-self.pressure * ufl.FacetNormal(msh), v,
                                      ds(PAD_IN_BACK) + ds(PAD_OUT_BACK))
        for tag, solid in ((DISC, disc), (PAD_IN, pad), (PAD_OUT, pad)):
            form += forms.elasticity(self.u, v, solid.E, solid.nu, dx(tag))
            form += forms.inertia(solid.rho, u_ddot, v, dx(tag))
        transport = RigidRotation(self.omega).velocity(ufl.SpatialCoordinate(msh))
        self.contacts = [NodeToSegment(self.u, facet_tags, slave, master, self.law,
                                       velocity=u_dot, fields=[u_dot], transport=transport)
                         for slave, master in ((PAD_IN_FACE, DISC_BOTTOM),
                                               (PAD_OUT_FACE, DISC_TOP))]
        self.residual = forms.Residual(form, self.u, u_dot, u_ddot, v, bcs=self._bcs(),
                                       couplings=self.contacts)
        self.solids = {"disc": disc, "pad": pad}
        self._pressed = False

    def _bcs(self) -> list:
        V, facet_tags = self.V, self.mesh.facet_tags
        hub = facet_tags.indices[facet_tags.values == DISC_HUB]
        bcs = [fem.dirichletbc(np.zeros(3), fem.locate_dofs_topological(V, 2, hub), V)]
        for tag in (PAD_IN_ABUTMENT, PAD_OUT_ABUTMENT):
            ends = facet_tags.indices[facet_tags.values == tag]
            for axis in (0, 1):
                dofs = fem.locate_dofs_topological(V.sub(axis), 2, ends)
                bcs.append(fem.dirichletbc(0.0, dofs, V.sub(axis)))
        return bcs

    @property
    def dofs(self) -> int:
        """Number of displacement unknowns."""
        return self.V.dofmap.index_map.size_global * self.V.dofmap.index_map_bs

    @functools.cached_property
    def steady_solver(self) -> SteadySolver:
        """Newton on the steady residual, a MUMPS LU per iteration (prefix ``brake_``). Its
        absolute tolerance is 1e-10 of one pad's load: the default 1e-9 N is below the
        residual's round-off floor (about 3e-13 of the load: stiffness 1e11 N/m times
        displacements of 1e-6 m, summed over 1e4 rows)."""
        return SteadySolver(self.residual, prefix="brake_", linear_solver="lu",
                            options={"snes_atol": 1e-10 * self.load()})

    @functools.cached_property
    def stability(self) -> StabilitySolver:
        """The quadratic eigenproblem at the current state (prefix ``brake_pep_``)."""
        return StabilitySolver(self.residual, prefix="brake_pep_")

    def pencil(self) -> tuple[typing.Any, typing.Any, typing.Any]:
        """(M, C, K̄) assembled at the current state (PETSc matrices of :attr:`stability`,
        overwritten by the next call)."""
        self.stability.assemble()
        return self.stability.M, self.stability.C, self.stability.K

    def _press(self) -> None:
        """Move each pad rigidly onto the disc by the penetration that carries the pressure
        (p / c_n, linear compliance), so that Newton starts with every face node in contact
        (at zero penetration the pads would float along the axis: no stiffness holds them)."""
        depth = float(self.pressure.value) / float(self.law.c_n)
        cell_tags = self.mesh.cell_tags
        nodes = _compat.scalar_function_space(self.mesh.mesh, "Lagrange", 1)
        for tag, sign in ((PAD_IN, 1.0), (PAD_OUT, -1.0)):
            cells = cell_tags.indices[cell_tags.values == tag]
            dofs = _compat.cell_dofs(nodes, cells)
            self.u.x.array[dofs * 3 + 2] = sign * depth
        self.u.x.scatter_forward()
        self._pressed = True

    def solve_steady(self, mu: float | None = None) -> typing.Any:
        """Steady sliding at friction coefficient ``mu`` (default: the current one), Newton
        from the last state, the contact pairing searched again until it holds. Returns the
        solve's report (:class:`~fenicsfriction.steady.SolveReport`)."""
        if mu is not None:
            check("mu", mu, mu >= 0, "the friction coefficient must be >= 0")
            self.mu.value = mu
        if not self._pressed:
            self._press()
        return solve_with_search(self.steady_solver, self.contacts)

    @functools.cached_property
    def _force_operators(self) -> list:
        """Each contact's steady residual alone (no Jacobian), for its forces."""
        return [c.operator({}, rest=[self.residual.u_dot]) for c in self.contacts]

    def nodal_forces(self) -> list[np.ndarray]:
        """The contact force on each of this rank's owned pad nodes [N], one array (nodes × 3)
        per pad (inboard, outboard); zero rows off the friction faces."""
        import dolfinx.fem.petsc

        nodes = _compat.scalar_function_space(self.mesh.mesh, "Lagrange", 1)
        owned = self.V.dofmap.index_map.size_local
        cell_tags = self.mesh.cell_tags
        forces = []
        for operator, tag in zip(self._force_operators, (PAD_IN, PAD_OUT), strict=True):
            b = dolfinx.fem.petsc.create_vector(operator.F)
            b.set(0.0)
            operator.add_to_residual(b)
            pad = np.unique(_compat.cell_dofs(nodes, cell_tags.indices[cell_tags.values == tag]))
            forces.append(-b.getArray().reshape(-1, 3)[pad[pad < owned]].copy())
            b.destroy()
        return forces

    def pad_forces(self) -> np.ndarray:
        """The contact force on each pad [N], rows (inboard, outboard), columns x, y, z (all
        ranks)."""
        return self.comm.allreduce(np.array([f.sum(axis=0) for f in self.nodal_forces()]))

    @functools.cached_property
    def _body_masses(self) -> dict[str, typing.Any]:
        import dolfinx.fem.petsc

        dx = ufl.Measure("dx", domain=self.mesh.mesh, subdomain_data=self.mesh.cell_tags)
        w, v = ufl.TrialFunction(self.V), ufl.TestFunction(self.V)
        masses = {}
        for name, tag, solid in (("disc", DISC, self.solids["disc"]),
                                 ("pad-in", PAD_IN, self.solids["pad"]),
                                 ("pad-out", PAD_OUT, self.solids["pad"])):
            A = dolfinx.fem.petsc.assemble_matrix(
                _compat.form(solid.rho * ufl.inner(w, v) * dx(tag)))
            A.assemble()
            masses[name] = A
        return masses

    def kinetic_shares(self, vector: np.ndarray) -> dict[str, float]:
        r"""How a mode's kinetic energy splits between the bodies: :math:`\phi^H M_b \phi /
        \phi^H M \phi` for the disc and each pad (``vector``: this rank's owned entries, e.g.
        a :class:`~fenicsfriction.stability.Mode`'s), the same on every rank. A disc mode has
        nearly all of it in the disc."""
        masses = self._body_masses
        x, y = next(iter(masses.values())).createVecs()
        energy = {}
        for name, A in masses.items():
            total = 0.0
            for part in (vector.real, vector.imag):
                x.setArray(part)
                A.mult(x, y)
                total += x.dot(y)
            energy[name] = total
        x.destroy()
        y.destroy()
        whole = sum(energy.values())
        return {name: value / whole for name, value in energy.items()}

    def disc_alone(self, fmax: float, modes: int = 16, prefix: str = "brake_disc_"
                   ) -> list[float]:
        """The frequencies [Hz] of the disc alone up to ``fmax`` on this mesh: its stiffness
        and mass, the hub clamped and every pad node held (no contact, no friction). On an
        exact disc, and on a mesh with its rotational symmetry, the doublets of n nodal
        diameters are exact pairs: their split is the mesh's own asymmetry.

        Args:
            fmax: the band's top [Hz].
            modes: at most this many modes (:class:`~fenicsfriction.cea.ModalBasis`).
            prefix: the eigensolver's PETSc options prefix.
        """
        import dolfinx.fem.petsc

        dx = ufl.Measure("dx", domain=self.mesh.mesh, subdomain_data=self.mesh.cell_tags)
        w, v = ufl.TrialFunction(self.V), ufl.TestFunction(self.V)
        tags = self.mesh.cell_tags
        pads = np.isin(tags.values, (PAD_IN, PAD_OUT))
        facets = self.mesh.facet_tags
        held = np.unique(np.concatenate([
            _compat.cell_dofs(self.V, tags.indices[pads]),
            fem.locate_dofs_topological(self.V, 2, facets.indices[facets.values == DISC_HUB])]))
        bc = fem.dirichletbc(np.zeros(3), held, self.V)
        # over every cell (the held pads' rows become identity rows: their pattern must exist)
        disc, pad = self.solids["disc"], self.solids["pad"]
        stiffness = forms.elasticity(w, v, disc.E, disc.nu, dx(DISC)) + sum(
            forms.elasticity(w, v, pad.E, pad.nu, dx(tag)) for tag in (PAD_IN, PAD_OUT))
        mass = forms.inertia(disc.rho, w, v, dx(DISC)) + sum(
            forms.inertia(pad.rho, w, v, dx(tag)) for tag in (PAD_IN, PAD_OUT))
        K = dolfinx.fem.petsc.assemble_matrix(_compat.form(stiffness), [bc])
        M = dolfinx.fem.petsc.assemble_matrix(_compat.form(mass), [bc], 0.0)
        K.assemble()
        M.assemble()
        basis = cea.ModalBasis(K, M, modes=modes, max_frequency=fmax, prefix=prefix)
        return [float(f) for f in basis.frequencies]

    def load(self) -> float:
        """The pressure's resultant on one pad's back [N] (p times the meshed area)."""
        ds = ufl.Measure("ds", domain=self.mesh.mesh, subdomain_data=self.mesh.facet_tags)
        area = fem.assemble_scalar(_compat.form(self.pressure * ds(PAD_OUT_BACK)))
        return float(self.comm.allreduce(area))
