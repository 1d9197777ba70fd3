"""The contact patch test of two-body contact, without the scenes: two stacked blocks with
non-matching meshes (tests/two_blocks.py), a uniform pressure p on the upper block's top,
rollers on the planes x = 0 (and y = 0) and under the lower block, linear compliance c_n.

Its exact solution is linear in each block (uniaxial stress σ_zz = -p), so every Lagrange
space holds it. In 3D the strains are ε_zz = -p/E and ε_xx = ε_yy = ν p/E; in plane strain
(2D) ε_zz = -(1 - ν²) p/E and ε_xx = ν (1 + ν) p/E. The lower block (z in [-H, 0]) has
u_z = ε_zz₂ (z + H), the upper one (z in [0, H]) is moreover moved down by the penetration
p/c_n: u_z = ε_zz₂ H - p/c_n + ε_zz₁ z; u_x = ε_xx x in each (the two materials expand equally:
no block overhangs the other). A contact discretisation passes when the
finite element solution is it.
"""

from __future__ import annotations

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem, mesh
from two_blocks import FIXED, LOAD, MASTER, SLAVE, UPPER, stacked_blocks

from fenicsfriction import _compat, forms
from fenicsfriction.contact import make_contact, solve_with_search
from fenicsfriction.laws import InterfaceLaw
from fenicsfriction.steady import SteadySolver

PRESSURE, C_N = 0.01, 10.0
#: (E, ν) of the upper and the lower block in 2D and 3D: different stiffnesses, the same
#: lateral strain (ν(1 + ν)/E in plane strain, ν/E in 3D), so that neither block overhangs
#: the other (an overhang carries no pressure: the exact solution would not be linear)
MATERIALS = {2: ((1.0, 0.2), (1.625, 0.3)), 3: ((1.0, 0.2), (1.5, 0.3))}


def exact(x: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """The exact displacement at points ``x`` (n, dim), ``upper`` those of the upper block."""
    dim = x.shape[1]
    z = x[:, -1]
    strains = []
    for E, nu in MATERIALS[dim]:
        if dim == 2:
            strains.append((nu * (1 + nu) * PRESSURE / E, -(1 - nu**2) * PRESSURE / E))
        else:
            strains.append((nu * PRESSURE / E, -PRESSURE / E))
    (lateral1, normal1), (lateral2, normal2) = strains
    u = np.zeros_like(x)
    u[:, :-1] = np.where(upper, lateral1, lateral2)[:, None] * x[:, :-1]
    u[:, -1] = np.where(upper, normal2 - PRESSURE / C_N + normal1 * z, normal2 * (z + 1.0))
    assert dim in (2, 3)
    return u


class PatchTest:
    """The two blocks in contact through ``formulation`` ("mortar" or "node-to-segment"),
    ``passes`` 1 or 2, displacements of Lagrange ``degree``."""

    def __init__(self, dim: int, degree: int = 1, formulation: str = "mortar",
                 passes: int = 1, n_upper: int | None = None, n_lower: int | None = None,
                 comm: MPI.Comm = MPI.COMM_WORLD):
        n_upper = n_upper or (5 if dim == 2 else 3)
        n_lower = n_lower or (7 if dim == 2 else 4)
        msh, cell_tags, facet_tags = stacked_blocks(comm, dim, n_upper, n_lower)
        self.dim = dim
        self.V = V = _compat.vector_function_space(msh, degree)
        self.u = u = fem.Function(V, name="u")
        v = ufl.TestFunction(V)
        dx = ufl.Measure("dx", domain=msh, subdomain_data=cell_tags)
        ds = ufl.Measure("ds", domain=msh, subdomain_data=facet_tags)
        load = np.zeros(dim)
        load[-1] = -PRESSURE
        form = forms.surface_traction(fem.Constant(msh, load), v, ds(LOAD))
        for tag, (E, nu) in zip((UPPER, 2), MATERIALS[dim], strict=True):
            form += forms.elasticity(u, v, E, nu, dx(tag))
        law = InterfaceLaw(c_n=C_N, m_n=1.0)
        pairs = [(SLAVE, MASTER), (MASTER, SLAVE)][:passes]
        self.contacts = [make_contact(formulation, u, facet_tags, slave, master, law,
                                      weight=1.0 / passes) for slave, master in pairs]
        fdim = dim - 1
        bcs = []
        for axis in range(dim - 1):
            facets = mesh.locate_entities_boundary(msh, fdim,
                                                   lambda x, a=axis: np.isclose(x[a], 0.0))
            dofs = fem.locate_dofs_topological(V.sub(axis), fdim, facets)
            bcs.append(fem.dirichletbc(0.0, dofs, V.sub(axis)))
        bottom = facet_tags.indices[facet_tags.values == FIXED]
        bcs.append(fem.dirichletbc(0.0, fem.locate_dofs_topological(V.sub(dim - 1), fdim,
                                                                    bottom), V.sub(dim - 1)))
        zero = fem.Function(V)
        self.residual = forms.Residual(form, u, zero, zero, v, bcs=bcs, couplings=self.contacts)
        self.x = V.tabulate_dof_coordinates()[:, :dim]
        cells = cell_tags.indices[cell_tags.values == UPPER]
        self.upper = np.zeros(len(self.x), dtype=bool)
        self.upper[_compat.cell_dofs(_compat.scalar_function_space(msh, "Lagrange", degree),
                                     cells)] = True
        self.exact = exact(self.x, self.upper)

    def solve(self) -> float:
        """Solve from the exact solution moved by twice the penetration (every slave node in
        contact from the start) and return max |u - u_exact| / max |u_exact|."""
        u = self.u
        start = self.exact.copy()
        start[self.upper, -1] -= PRESSURE / C_N
        u.x.array[:] = start.ravel()
        u.x.scatter_forward()
        solver = SteadySolver(self.residual, prefix=f"patch{id(self)}_", linear_solver="lu",
                              options={"snes_rtol": 1e-14, "snes_atol": 1e-13})
        solve_with_search(solver, self.contacts)
        error = np.abs(u.x.array - self.exact.ravel()).max()
        comm = self.V.mesh.comm
        return comm.allreduce(float(error), op=MPI.MAX) / np.abs(self.exact).max()

    def pressures(self) -> np.ndarray:
        """The contact pressure at the owned slave nodes of each pass."""
        out = []
        for contact in self.contacts:
            values = contact.nodal_values([contact.pressure])()[:, 0]
            out.append(values[contact.nodal_weights > 0])
        return np.concatenate(out)
