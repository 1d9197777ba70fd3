"""Segment-to-segment (mortar) contact: the contact patch test, the mortar integrals, the
Jacobian, parallel agreement and the inputs it refuses.

The patch test's exact solution is linear in each block (tests/mortar_patch.py); the finite
element solution reproduces it to round-off when the contact transmits a uniform pressure
exactly. Its tolerance, 1e-8, leaves room for the LU's round-off (condition number of the
stiffness, about 1e4 here, times 1e-16) and for Newton's stopping test.
"""

from __future__ import annotations

from mpi4py import MPI

import dolfinx.fem.petsc
import numpy as np
import pytest
from dolfinx import fem
from mortar_patch import PRESSURE, PatchTest
from two_blocks import MASTER, SLAVE, stacked_blocks

from fenicsfriction import _compat
from fenicsfriction.contact import make_contact
from fenicsfriction.contact.mortar import SegmentToSegment
from fenicsfriction.laws import InterfaceLaw

PATCH_TOLERANCE = 1e-8


@pytest.mark.parametrize("passes", [1, 2])
@pytest.mark.parametrize("degree", [1, 2])
@pytest.mark.parametrize("dim", [2, 3])
def test_mortar_contact_passes_the_patch_test(dim, degree, passes):
    """Non-matching meshes (5 against 7 elements across in 2D, 3 against 4 in 3D): the
    displacement is the exact linear solution and the pressure at every slave node is the
    pressure applied."""
    patch = PatchTest(dim, degree, passes=passes)
    assert patch.solve() < PATCH_TOLERANCE
    pressures = patch.pressures()
    assert np.abs(pressures / PRESSURE - 1).max(initial=0.0) < PATCH_TOLERANCE


@pytest.mark.parametrize("dim", [2, 3])
def test_node_to_segment_fails_the_same_patch_test(dim):
    """The same meshes through node-to-segment contact, one pass and two: the displacement
    and each pass's pressure deviate by percents (two passes pass only as the penalty
    stiffens: Taylor & Papadopoulos 1991), so the patch test above can fail."""
    for passes in (1, 2):
        patch = PatchTest(dim, 1, formulation="node-to-segment", passes=passes)
        error = patch.solve()
        deviation = np.abs(patch.pressures() / PRESSURE - 1).max(initial=0.0)
        deviation = MPI.COMM_WORLD.allreduce(float(deviation), op=MPI.MAX)
        assert error > 1e3 * PATCH_TOLERANCE, (passes, error)
        assert deviation > 1e-2, (passes, deviation)


def _contact(dim: int, degree: int, n_upper: int, n_lower: int, comm=MPI.COMM_WORLD,
             overlap: float = 0.0, **options) -> tuple[SegmentToSegment, fem.Function]:
    msh, _, facet_tags = stacked_blocks(comm, dim, n_upper, n_lower, overlap=overlap)
    V = _compat.vector_function_space(msh, degree)
    u = fem.Function(V, name="u")
    contact = SegmentToSegment(u, facet_tags, SLAVE, MASTER, InterfaceLaw(c_n=1.0, m_n=1.0),
                               **options)
    return contact, u


@pytest.mark.parametrize("degree", [1, 2])
@pytest.mark.parametrize("dim", [2, 3])
def test_mortar_integrals_are_a_partition_of_unity(dim, degree):
    """Surfaces that cover each other: Σ_k D_jk = Σ_l M_jl = A_j (the shape functions of
    each side sum to one), every A_j > 0, the A_j are the nodal rule's weights, and they sum
    to the interface's area (1)."""
    contact, _ = _contact(dim, degree, 3, 4)
    contact.update()
    integrals = contact.pairing
    slave = integrals.slave_nodes
    area = integrals.area[slave]
    assert np.all(area > 0)
    assert np.allclose(np.asarray(integrals.D.sum(axis=1)).ravel()[slave], area,
                       rtol=1e-13, atol=0)
    assert np.allclose(np.asarray(integrals.M.sum(axis=1)).ravel()[slave], area,
                       rtol=1e-12, atol=0)
    assert np.allclose(contact.nodal_weights[slave], area, rtol=1e-12, atol=0)
    total = MPI.COMM_WORLD.allreduce(float(area.sum()))
    assert total == pytest.approx(1.0, rel=1e-13)


@pytest.mark.parametrize("degree", [1, 2])
@pytest.mark.parametrize("dim", [2, 3])
def test_sliding_leaves_the_integrals_on_the_overlap(dim, degree):
    """The upper block slid by s = 0.37 along x (not a multiple of either mesh's size): the
    integrals cover the overlap only, Σ A_j = 1 - s (its length or area), each row of D and M
    still sums to A_j, the covered fraction of each node is in [0, 1], and the new pattern of
    B is counted as a change."""
    contact, u = _contact(dim, degree, 3, 4)
    contact.update()
    changes = contact.pairing.changes
    x = u.function_space.tabulate_dof_coordinates()[:, :dim]
    slide = 0.37
    upper = u.x.array.reshape(-1, dim)
    upper[x[:, -1] > 1e-12, 0] = slide  # the upper block's nodes, above z = 0 ...
    slave = contact.pairing.slave_nodes
    upper[slave, 0] = slide  # ... and its contact face
    u.x.scatter_forward()
    assert contact.search()
    integrals = contact.pairing
    assert integrals.changes == changes + 1
    area = integrals.area[slave]
    total = MPI.COMM_WORLD.allreduce(float(area.sum()))
    assert total == pytest.approx(1.0 - slide, rel=1e-12)
    for matrix in (integrals.D, integrals.M):
        assert np.allclose(np.asarray(matrix.sum(axis=1)).ravel()[slave], area,
                           rtol=1e-12, atol=1e-15)
    fraction = integrals.coverage.x.array[slave]
    assert np.all((fraction >= 0) & (fraction <= 1 + 1e-12))


@pytest.mark.parametrize("formulation", ["mortar", "node-to-segment"])
def test_gap_and_normal_mean_the_same_in_both_formulations(formulation):
    """The upper block moved 0.01 into the lower one (flat interface z = 0): at every slave
    node the gap is -0.01, the penetration 0.01 and the normal +z, out of the master body."""
    msh, _, facet_tags = stacked_blocks(MPI.COMM_WORLD, 3, 2, 3, overlap=0.01)
    u = fem.Function(_compat.vector_function_space(msh, 1))
    contact = make_contact(formulation, u, facet_tags, SLAVE, MASTER,
                           InterfaceLaw(c_n=1.0, m_n=1.0))
    contact.update()
    values = contact.nodal_values([contact.gap, contact.penetration, *contact.normal])()
    slave = contact.nodal_weights > 0
    assert np.allclose(values[slave], [-0.01, 0.01, 0.0, 0.0, 1.0], rtol=0, atol=1e-14)


def _reference_integrals(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """D and M of one slave segment [0, 1] (nodes 0, 1 and, for degree 2, 1/2) against two
    master segments [0, 1/2], [1/2, 1] (nodes 0, 1/2, 1 and the quarter points), by
    Gauss quadrature of the shape functions written out here, rows and columns ordered by x."""
    def hats(nodes, x):  # piecewise linear hats on sorted nodes
        return np.array([np.interp(x, nodes, np.eye(len(nodes))[i]) for i in range(len(nodes))])

    def quadratic(a, b, x):  # the P2 functions of the segment [a, b], zero outside it
        s = (x - a) / (b - a)
        inside = (s >= 0) & (s <= 1)
        return np.array([(1 - s) * (1 - 2 * s), 4 * s * (1 - s), s * (2 * s - 1)]) * inside

    points, weights = np.polynomial.legendre.leggauss(6)
    x = np.concatenate([(points + 1) / 8 + k / 4 for k in range(4)])  # exact on each quarter
    w = np.tile(weights / 8, 4)
    if degree == 1:
        psi = hats([0.0, 1.0], x)
        N_s = psi
        N_m = hats([0.0, 0.5, 1.0], x)
    else:
        psi = hats([0.0, 0.5, 1.0], x)  # the split hats
        N_s = quadratic(0.0, 1.0, x)
        left, right = quadratic(0.0, 0.5, x), quadratic(0.5, 1.0, x)
        N_m = np.array([left[0], left[1], left[2] + right[0], right[1], right[2]])
    return (psi * w) @ N_s.T, (psi * w) @ N_m.T


@pytest.mark.parametrize("degree", [1, 2])
def test_mortar_integrals_of_one_segment_on_two(degree):
    """D and M entry by entry on the smallest non-matching interface (degree 1: the closed
    forms D = [[1/3, 1/6], [1/6, 1/3]], M = [[5/24, 1/4, 1/24], [1/24, 1/4, 5/24]])."""
    contact, _ = _contact(2, degree, 1, 2, comm=MPI.COMM_SELF)
    contact.update()
    integrals = contact.pairing
    x = contact.V.tabulate_dof_coordinates()[:, 0]
    slave = np.unique(integrals.slave_local)
    master = np.unique(integrals.master_local)
    slave, master = slave[np.argsort(x[slave])], master[np.argsort(x[master])]
    D = integrals.D.toarray()[np.ix_(slave, slave)]
    M = integrals.M.toarray()[np.ix_(slave, master)]
    D_ref, M_ref = _reference_integrals(degree)
    if degree == 1:
        assert np.allclose(D_ref, [[1 / 3, 1 / 6], [1 / 6, 1 / 3]], rtol=1e-14)
        assert np.allclose(M_ref, [[5 / 24, 1 / 4, 1 / 24], [1 / 24, 1 / 4, 5 / 24]],
                           rtol=1e-14)
    assert np.allclose(D, D_ref, rtol=0, atol=1e-14)
    assert np.allclose(M, M_ref, rtol=0, atol=1e-14)


def _smooth(V: fem.FunctionSpace, scale: float, phase: float) -> np.ndarray:
    """A smooth field of V, the same on any partition (a function of position)."""
    dim = V.mesh.geometry.dim
    x = V.tabulate_dof_coordinates()[:, :dim]
    k = np.array([[1.3, -0.7, 0.4], [0.5, 1.1, -0.9], [0.8, 0.3, 1.7]])[:dim, :dim]
    return (scale * np.sin(x @ k.T + phase)).ravel()


def _contact_residual(operator, u: fem.Function, values: np.ndarray):
    u.x.array[:] = values
    u.x.scatter_forward()
    b = dolfinx.fem.petsc.create_vector(operator.G)
    b.set(0.0)
    operator.add_to_residual(b)
    return b


@pytest.mark.parametrize(("dim", "degree"), [(2, 1), (2, 2), (3, 1), (3, 2)])
def test_mortar_jacobian_passes_the_taylor_test(dim, degree):
    """Frozen geometry, friction on the velocity (u - u_old)/0.1, a smooth state with the
    blocks overlapping: the remainder |R(u + h du) - R(u) - h J du| falls like h²."""
    msh, _, facet_tags = stacked_blocks(MPI.COMM_WORLD, dim, 3, 4, overlap=0.02)
    V = _compat.vector_function_space(msh, degree)
    u, u_old = fem.Function(V, name="u"), fem.Function(V, name="u_old")
    u.x.array[:] = _smooth(V, 0.01, 0.2)
    u_old.x.array[:] = _smooth(V, 0.005, 1.1)
    for f in (u, u_old):
        f.x.scatter_forward()
    law = InterfaceLaw(c_n=100.0, m_n=2.0, mu=0.5, eps=1e-2)
    contact = make_contact("mortar", u, facet_tags, SLAVE, MASTER, law,
                           velocity=(u - u_old) / 0.1, fields=[u_old], frozen=True)
    operator = contact.operator({u: 1.0})
    x0 = u.x.array.copy()
    b0 = _contact_residual(operator, u, x0)
    J = operator.matrix()
    du = fem.Function(V)
    du.x.array[:] = _smooth(V, 1.0, 0.7)
    du.x.scatter_forward()
    Jdu = b0.duplicate()
    J.mult(_compat.petsc_vec(du), Jdu)
    remainders = []
    for h in (2e-4, 1e-4, 5e-5):
        b = _contact_residual(operator, u, x0 + h * du.x.array)
        b.axpy(-1.0, b0)
        assert b.norm() > 0
        b.axpy(-h, Jdu)
        remainders.append(b.norm())
    rates = np.log2(np.array(remainders[:-1]) / remainders[1:])
    # a missing or wrong block would leave rate 1
    assert rates.min() > 1.9, rates


def test_refused_inputs_name_what_is_allowed():
    msh, _, facet_tags = stacked_blocks(MPI.COMM_WORLD, 2, 1, 2)
    law = InterfaceLaw(c_n=1.0, m_n=1.0)
    cubic = fem.Function(_compat.vector_function_space(msh, 3))
    with pytest.raises(ValueError, match="degree 1 or 2"):
        SegmentToSegment(cubic, facet_tags, SLAVE, MASTER, law)
    cubes = _compat.create_box(MPI.COMM_WORLD, [0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2, 2, 2])
    with pytest.raises(ValueError, match="mesh='hexahedron'.*tetrahedra"):
        SegmentToSegment(fem.Function(_compat.vector_function_space(cubes, 1)), facet_tags,
                         SLAVE, MASTER, law)
    u = fem.Function(_compat.vector_function_space(msh, 1))
    for options in ({"enforcement": "perturbed-lagrangian"},
                    {"formulation": "perturbed-lagrangian"}):
        with pytest.raises(ValueError, match="perturbed Lagrangian is node-to-segment's only"):
            SegmentToSegment(u, facet_tags, SLAVE, MASTER, law, **options)
    with pytest.raises(ValueError, match="^penalty_T=1.0 is invalid"):
        SegmentToSegment(u, facet_tags, SLAVE, MASTER, law, penalty_T=1.0)
    with pytest.raises(ValueError, match="^slave=99 is invalid"):
        SegmentToSegment(u, facet_tags, 99, MASTER, law)
    with pytest.raises(ValueError, match="^velocity=None is invalid"):
        SegmentToSegment(u, facet_tags, SLAVE, MASTER, law.replace(mu=0.3, eps=1e-3))


def _surface_state(comm: MPI.Comm, dim: int, degree: int) -> np.ndarray:
    """(x, gap, contact force) rows of the owned slave nodes at a smooth overlapping state,
    gathered and sorted by position."""
    contact, u = _contact(dim, degree, 3, 4, comm=comm, overlap=0.01)
    u.x.array[:] = _smooth(u.function_space, 0.005, 0.3)
    u.x.scatter_forward()
    operator = contact.operator({u: 1.0})
    b = dolfinx.fem.petsc.create_vector(operator.G)
    b.set(0.0)
    operator.add_to_residual(b)
    gap = contact.nodal_values([contact.gap])()[:, 0]
    slave = contact.pairing.slave_nodes
    x = contact.V.tabulate_dof_coordinates()[slave, :dim]
    force = b.array_r.reshape(-1, dim)[slave]
    rows = np.vstack(comm.allgather(np.column_stack([x, gap[slave], force])))
    return rows[np.lexsort(rows[:, :dim].T[::-1])]


@pytest.mark.mpi(min_size=2)
@pytest.mark.parametrize(("dim", "degree"), [(2, 2), (3, 1)])
def test_mortar_contact_on_two_ranks_matches_one(dim, degree):
    """The gaps and the slave nodes' contact forces at a smooth state, on COMM_WORLD (both
    surfaces split over the ranks) and on each rank alone: the same to round-off."""
    here = _surface_state(MPI.COMM_WORLD, dim, degree)
    alone = _surface_state(MPI.COMM_SELF, dim, degree)
    assert here.shape == alone.shape
    assert np.allclose(here, alone, rtol=0, atol=1e-13)


@pytest.mark.parametrize("degree", [1, 2])
def test_frequency_bound_holds_the_contact_springs_largest_frequency(degree):
    """Every slave node in contact (the blocks overlapping), linear compliance: the largest
    ω² of the contact's stiffness B^T C B (its Jacobian, assembled) on a lumped mass is below
    the bound, and the bound is within a small factor of it (a norm bound, not a guess)."""
    contact, u = _contact(2, degree, 3, 4, comm=MPI.COMM_SELF, overlap=0.01)
    operator = contact.operator({u: 1.0})
    b = dolfinx.fem.petsc.create_vector(operator.G)
    operator.add_to_residual(b)  # searches
    K = operator.matrix()
    V = contact.V
    x = V.tabulate_dof_coordinates()[:, :2]
    mass = b.duplicate()
    mass.array[:] = np.repeat(1.0 + 0.5 * np.sin(7 * x[:, 0] + 3 * x[:, 1]), 2)
    dense = K.convert("dense").getDenseArray()
    scale = 1 / np.sqrt(mass.array)
    largest = np.linalg.eigvalsh(scale[:, None] * dense * scale[None, :]).max()
    bound = contact.frequency_bound(mass)
    assert largest > 0
    assert largest <= bound * (1 + 1e-12)
    # ||C^1/2 B||_1 ||C^1/2 B||_inf / min(m) over-estimates the largest ω² where the nodes'
    # weights and masses vary (by 2.0 and 2.4 here)
    assert bound < 4 * largest, (bound, largest)
