r"""The pin on the disc as a finite element model: steady sliding and its stability.

Two steel bodies in one mesh (:func:`~fenicsfriction.studies.squeal.geometry.pin_on_disc`).
The mesh is in the pin's frame (the pin's axis e_z, the disc's axis :math:`a_d`, tilted by
the pin's inclination). The disc is described in Eulerian fashion: it does not turn in the
mesh, its surface carries the rigid velocity :math:`U_T = \omega\, a_d \times x`, the
``transport`` of the
node-to-segment contact, so that the slip of the pin's face is
:math:`w = \dot u_s - (U_T + \dot u_m)`. (The convective terms of the disc's own deformation,
:math:`\omega\,\partial u/\partial\theta`, are left out: at the disc speeds of brake squeal
they shift the frequencies by :math:`\omega/\omega_{mode} \sim 10^{-3}`.)

The residual is the sum of the terms of :mod:`fenicsfriction.forms`:

.. math::
    R = \sum_{\text{bodies}} \big(\rho\langle\ddot u, v\rangle + a(u, v)\big)
        + \int_{\text{pin-top}} p\, e_z\cdot v
        + R_c(u, \dot u; v)

with the disc clamped on its hub, the pin held across its axis (u_x = u_y = 0) on the side of
its top part, in its holder (a rigid sleeve: its bending is clamped there, its axial motion
free), and pushed along its axis by the pressure :math:`p` on its top, and
:math:`R_c` the node-to-segment contact of the pin's face (slave) on the disc's top (master)
with the interface law (linear normal compliance, regularised Coulomb friction). Steady
sliding solves :math:`R(u_0, 0, 0) = 0` by continuation in μ; the stability of sliding is the
quadratic eigenproblem of the derivatives of the same R
(:class:`~fenicsfriction.stability.StabilitySolver`).
"""

from __future__ import annotations

import dataclasses
import functools
import typing

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem

from fenicsfriction import _compat, forms, laws
from fenicsfriction.contact import NodeToSegment
from fenicsfriction.discs import DISC, DISC_HUB, DISC_TOP
from fenicsfriction.studies.squeal.geometry import (
    PIN,
    PIN_FACE,
    PIN_HELD,
    PIN_TOP,
    PinOnDiscMesh,
)

__all__ = ["PinOnDisc", "PinOnDiscModel", "Steel"]


@dataclasses.dataclass(frozen=True)
class Steel:
    """An isotropic elastic material (SI units).

    Args:
        E: Young's modulus [Pa].
        nu: Poisson's ratio [-].
        rho: mass density [kg/m³].
    """

    E: float = 210e9
    nu: float = 0.3
    rho: float = 7850.0


@dataclasses.dataclass(frozen=True)
class PinOnDisc:
    """The loading and the interface of the pin-on-disc scene (SI units).

    Args:
        material: both bodies' material.
        law: the interface law: c_n [N/m³] (linear compliance, m_n = 1: a spring c_n per unit
            area of the pin's face), μ and ε [m/s] (ε ≪ ω R_p). The default c_n = 1e11 N/m³,
            a face stiffness c_n A = 5e6 N/m, is the compliance of a layer of friction
            material (E/t for E of a few GPa over some 10 mm). It is not stiffer for a reason:
            a flat face in full contact takes a share κ/(1 + κ), κ = c_n L / E, of the
            friction's bending moment μ N L/2 on the pin, and lifts off at one edge once that
            exceeds N r/4, that is for μ ≳ r/(2 L) (1 + κ)/κ. With c_n = 1e14 (κ = 24) the
            face lifts off from μ ≈ 0.04 and Newton stalls on the shrinking contact; with 1e11
            (κ = 0.024) the face stays in full contact up to μ ≈ 1.7.
        pressure: the axial pressure on the pin's top, p [Pa] (the normal load is p π r²).
        omega: the disc's angular velocity ω [rad/s], about +e_z.
    """

    material: Steel = Steel()
    law: laws.InterfaceLaw = laws.InterfaceLaw(c_n=1e11, m_n=1.0, eps=1e-3)
    pressure: float = 1e6
    omega: float = 10.0

    def __post_init__(self) -> None:
        laws.check_positive("pressure", self.pressure)
        laws.check("omega", self.omega, self.omega != 0, "the disc must turn (omega != 0)")


class PinOnDiscModel:
    """A built pin-on-disc scene: the residual, its fields and what is read off them.

    Args:
        geometry: the mesh (:func:`~fenicsfriction.studies.squeal.geometry.pin_on_disc`).
        scene: the loading and interface.

    Attributes:
        V, residual: the displacement space (P1 vectors) and the one residual.
        mu, eps: the law's friction coefficient and regularisation (``fem.Constant``).
        contact: the pin-face / disc-top :class:`~fenicsfriction.contact.NodeToSegment`.
        transport: the disc's surface velocity ω e_z × x (UFL).
    """

    def __init__(self, geometry: PinOnDiscMesh, scene: PinOnDisc = PinOnDisc()):
        self.geometry, self.scene = geometry, scene
        msh = geometry.mesh
        self.comm: MPI.Comm = msh.comm
        self.V = V = _compat.vector_function_space(msh, 1)
        u = fem.Function(V, name="displacement")
        u_dot, u_ddot = fem.Function(V, name="velocity"), fem.Function(V, name="acceleration")
        v = ufl.TestFunction(V)
        dx = ufl.Measure("dx", domain=msh, subdomain_data=geometry.cell_tags)
        ds = ufl.Measure("ds", domain=msh, subdomain_data=geometry.facet_tags)
        m = scene.material
        self.rho = fem.Constant(msh, m.rho)
        form = forms.inertia(self.rho, u_ddot, v, dx) \
            + sum(forms.elasticity(u, v, m.E, m.nu, dx(tag)) for tag in (DISC, PIN))
        self.pressure = fem.Constant(msh, scene.pressure)
        form += forms.surface_traction(-self.pressure * ufl.as_vector((0.0, 0.0, 1.0)), v,
                                       ds(PIN_TOP))
        self.mu = fem.Constant(msh, float(scene.law.mu))
        self.eps = fem.Constant(msh, float(scene.law.eps))
        self.omega = fem.Constant(msh, scene.omega)
        x = ufl.SpatialCoordinate(msh)
        self.transport = self.omega * ufl.cross(ufl.as_vector(geometry.pin.disc_axis), x)
        law = scene.law.replace(mu=self.mu, eps=self.eps)
        self.contact = NodeToSegment(u, geometry.facet_tags, slave=PIN_FACE, master=DISC_TOP,
                                     law=law, velocity=u_dot, fields=[u_dot],
                                     transport=self.transport)
        tags = geometry.facet_tags
        hub = fem.locate_dofs_topological(V, 2, tags.find(DISC_HUB))
        bcs = [fem.dirichletbc(np.zeros(3), hub, V)]
        for axis in (0, 1):  # the holder: the pin's sleeve held across the pin's axis e_z
            held = fem.locate_dofs_topological(V.sub(axis), 2, tags.find(PIN_HELD))
            bcs.append(fem.dirichletbc(0.0, held, V.sub(axis)))
        self.residual = forms.Residual(form, u, u_dot, u_ddot, v, bcs=bcs,
                                       couplings=[self.contact])
        self._pin_dofs = _compat.cell_dofs(V, geometry.cell_tags.find(PIN))

    @property
    def msh(self) -> typing.Any:
        """The mesh (both bodies)."""
        return self.geometry.mesh

    @property
    def dofs(self) -> int:
        """The number of displacement unknowns."""
        return self.V.dofmap.index_map.size_global * self.V.dofmap.index_map_bs

    @functools.cached_property
    def _top_area(self) -> float:
        ds = ufl.Measure("ds", domain=self.geometry.mesh, subdomain_data=self.geometry.facet_tags)
        one = fem.Constant(self.geometry.mesh, 1.0)
        return self.comm.allreduce(fem.assemble_scalar(_compat.form(one * ds(PIN_TOP))))

    @property
    def axial_load(self) -> float:
        """The axial load on the pin, p times its top's area in the mesh [N] (the mesh's
        polygonal circle is 1-4 % smaller than π r²)."""
        return float(self.pressure.value) * self._top_area

    def pin_share(self, vector: np.ndarray) -> float:
        """The share of the pin in a mode's kinetic energy, w^H M_pin w / w^H M w (a complex
        eigenvector's owned entries; on every rank): 1 for a mode of the pin alone, 0 for
        one of the disc."""
        M = self._masses
        w = np.asarray(vector)
        parts = [float(np.real(np.vdot(w, mass @ w))) for mass in M]
        pin, total = (self.comm.allreduce(x) for x in parts)
        return pin / total

    @functools.cached_property
    def _masses(self) -> tuple:
        """The owned rows of the pin's and the whole mass matrices (SciPy CSR, local
        columns of the owned block: enough for the kinetic energies of owned entries, the
        mass coupling across ranks dropped — a relative error of order (interface
        nodes / nodes) that does not matter for a share)."""
        import scipy.sparse
        from dolfinx.fem.petsc import assemble_matrix
        dx = ufl.Measure("dx", domain=self.geometry.mesh, subdomain_data=self.geometry.cell_tags)
        u, v = ufl.TrialFunction(self.V), ufl.TestFunction(self.V)
        out = []
        for measure in (dx(PIN), dx):
            A = assemble_matrix(_compat.form(self.rho * ufl.inner(u, v) * measure))
            A.assemble()
            rows, cols = A.getOwnershipRange(), A.getOwnershipRangeColumn()
            ai, aj, av = A.getValuesCSR()
            n, m = rows[1] - rows[0], cols[1] - cols[0]
            row = np.repeat(np.arange(n), np.diff(ai))
            keep = (aj >= cols[0]) & (aj < cols[1])
            out.append(scipy.sparse.csr_matrix((av[keep], (row[keep], aj[keep] - cols[0])),
                                               shape=(n, m)))
            A.destroy()
        return tuple(out)

    def initial_guess(self) -> None:
        """The pin moved rigidly into the disc by the compliance's approach under the load
        (a Newton start inside the contact, where the compliance has its stiffness), the disc
        at rest."""
        u = self.residual.u
        u.x.array[:] = 0.0
        approach = self.scene.law.uniform_penetration(self.axial_load
                                                      / self.geometry.pin.face_area)
        u.x.array.reshape(-1, 3)[self._pin_dofs, 2] = -approach
        u.x.scatter_forward()

    @functools.cached_property
    def _resultant_forms(self) -> list:
        """The contact force on the pin: the normal (along e_z) and tangential resultants."""
        c = self.contact
        traction = c.pressure * c.projection.normal
        if c.traction is not None:
            traction = traction + c.traction
        return [_compat.form(traction[k] * c.ds) for k in range(3)]

    def contact_force(self) -> np.ndarray:
        """The resultant of the disc's tractions on the pin's face [N] (on every rank)."""
        self.contact.update()
        local = np.array([fem.assemble_scalar(f) for f in self._resultant_forms])
        return self.comm.allreduce(local)
