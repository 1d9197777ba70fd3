"""Checks of the mortar room that its planted bugs asked for (tests/planted_bugs.toml): the
contact's frequency bound at a weight other than 1 (each pass of two-pass contact has 1/2).

The bound must hold the largest ω² of the contact's own stiffness, the assembled Jacobian of
its residual, whatever the weight; both are linear in the weight, so their ratio does not
depend on it.
"""

from __future__ import annotations

from mpi4py import MPI

import dolfinx.fem.petsc
import numpy as np
import pytest
from dolfinx import fem
from two_blocks import MASTER, SLAVE, stacked_blocks

from fenicsfriction import _compat
from fenicsfriction.contact.mortar import SegmentToSegment
from fenicsfriction.laws import InterfaceLaw

pytestmark = pytest.mark.sequential


def _largest_and_bound(weight: float, degree: int) -> tuple[float, float]:
    """The largest ω² of the contact stiffness on a varying lumped mass, and the bound."""
    msh, _, facet_tags = stacked_blocks(MPI.COMM_SELF, 2, 3, 4, overlap=0.01)
    V = _compat.vector_function_space(msh, degree)
    u = fem.Function(V, name="u")
    contact = SegmentToSegment(u, facet_tags, SLAVE, MASTER, InterfaceLaw(c_n=3.0, m_n=1.0),
                               weight=weight)
    operator = contact.operator({u: 1.0})
    b = dolfinx.fem.petsc.create_vector(operator.G)
    operator.add_to_residual(b)  # searches
    dense = operator.matrix().convert("dense").getDenseArray()
    x = V.tabulate_dof_coordinates()[:, :2]
    mass = b.duplicate()
    mass.array[:] = np.repeat(1.0 + 0.5 * np.sin(7 * x[:, 0] + 3 * x[:, 1]), 2)
    scale = 1 / np.sqrt(mass.array)
    largest = float(np.linalg.eigvalsh(scale[:, None] * dense * scale[None, :]).max())
    return largest, contact.frequency_bound(mass)


@pytest.mark.parametrize("degree", [1])
def test_frequency_bound_scales_with_the_contacts_weight(degree):
    """Weights 1 and 1/2 (c_n = 3, not 1): the stiffness halves, and so must the bound
    (degree 1: the weight enters the bound the same way for degree 2)."""
    full_largest, full_bound = _largest_and_bound(1.0, degree)
    half_largest, half_bound = _largest_and_bound(0.5, degree)
    assert half_largest == pytest.approx(0.5 * full_largest, rel=1e-12)
    assert half_largest <= half_bound * (1 + 1e-12)
    assert half_bound / half_largest == pytest.approx(full_bound / full_largest, rel=1e-12)


@pytest.mark.parametrize(("dim", "degree"), [(2, 2), (3, 1), (3, 2)])
def test_mortar_integrals_reproduce_linear_fields_across_non_matching_meshes(dim, degree):
    """Surfaces that coincide (3 against 4 elements across, no overlap): every field linear
    in x is interpolated exactly by either side's shape functions, so Σ_k D_jk f_k =
    Σ_l M_jl f_l = ∫ ψ_j f for f = each coordinate, and the mortar relative position
    B X = (D X − M X)/A vanishes at every slave node, in the plane as well as across it. The
    contact patch test sees only its normal component on a flat interface, where any
    weighting of the master's nodes gives the same height."""
    msh, _, facet_tags = stacked_blocks(MPI.COMM_SELF, dim, 3, 4)
    V = _compat.vector_function_space(msh, degree)
    u = fem.Function(V, name="u")
    contact = SegmentToSegment(u, facet_tags, SLAVE, MASTER, InterfaceLaw(c_n=1.0, m_n=1.0))
    contact.update()
    pairing = contact.pairing
    X = V.tabulate_dof_coordinates()[:, :dim]
    slave = pairing.slave_nodes
    DX, MX = pairing.D @ X, pairing.M @ X
    assert np.abs(DX[slave] - MX[slave]).max() < 1e-14
    relative = pairing.reference.x.array.reshape(-1, dim)[slave]
    assert np.abs(relative).max() < 1e-13
    # and the check is not empty: the slave nodes' weighted coordinates are not zero
    assert np.abs(DX[slave, 0]).max() > 1e-3
