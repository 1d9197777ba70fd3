"""The contact search without a global gather, and the partition that shares the contact.

Each rank holds only the master facets near its own slave nodes (bounding boxes exchanged
with neighbours, :class:`~fenicsfriction.contact.pairing.Pairing`); the pairing must be the
one found with the whole master surface gathered on every rank, bit for bit, since the
candidates and the tie-breaking depend on the geometry only. Under ``mpirun -n 2`` the mesh
is cut across the contact plane (``partition="contact"``), so that both ranks pair slave
nodes and neither holds the whole master surface.
"""

from __future__ import annotations

from mpi4py import MPI

import dolfinx.fem.petsc
import numpy as np
import pytest
from dolfinx import fem

from fenicsfriction import _compat
from fenicsfriction.contact import NodeToSegment
from fenicsfriction.contact.mortar import MortarIntegrals, SegmentToSegment
from fenicsfriction.contact.pairing import CANDIDATES, Pairing, _candidates, _Facets, facet_nodes
from fenicsfriction.laws import InterfaceLaw
from fenicsfriction.studies.contact import geometry
from fenicsfriction.studies.contact.validation import Hertz, pressure_on_axis

#: a coarse quarter sphere on a block (about 3,300 unknowns): seconds to solve
H_CONTACT = 0.08


def _hertz_mesh(comm: MPI.Comm, partition: str = "contact") -> geometry.TwoBodyMesh:
    return geometry.hertz_3d(comm, h_contact=H_CONTACT, h_far=0.8, partition=partition)


def _sheared(V: fem.FunctionSpace, slide: float) -> fem.Function:
    """A smooth displacement, the same on any partition (a function of position), with the
    sphere (z > 0) pressed 0.02 into the block (twice Hertz's approach at a = R/10) and slid by
    ``slide`` along x."""
    u = fem.Function(V)
    x = V.tabulate_dof_coordinates()
    k = np.array([[1.0, 2.0, 3.0], [2.0, -1.0, 1.0], [0.5, 1.0, -2.0]])
    values = 0.01 * np.sin(x @ k.T)
    values[:, 0] += slide * (x[:, 2] > 0)
    values[:, 2] -= 0.02 * (x[:, 2] > 0)
    u.x.array[:] = values.ravel()
    u.x.scatter_forward()
    return u


def _contacts(u: fem.Function, mesh: geometry.TwoBodyMesh) -> list[NodeToSegment]:
    law = InterfaceLaw(c_n=100.0, m_n=2.0)
    return [NodeToSegment(u, mesh.facet_tags, geometry.SLAVE, geometry.MASTER, law,
                          exchange=exchange) for exchange in ("neighbours", "all")]


def _local_csr(Q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return Q.getValuesCSR()


def test_pairing_and_contact_forces_equal_the_gathered_search():
    """Two searches (the second after the sphere slid by a tenth of its contact radius, so that
    slave nodes change facets and the kept-facet rule acts): the same master facet for every
    slave node, the same operator Q and the same contact residual as with the whole master
    surface on every rank, to the bit (the same arithmetic on the same numbers)."""
    mesh = _hertz_mesh(MPI.COMM_WORLD)
    V = _compat.vector_function_space(mesh.mesh, 1)
    u = _sheared(V, 0.0)
    near, gathered = _contacts(u, mesh)
    for slide in (0.0, 0.01):
        u.x.array[:] = _sheared(V, slide).x.array
        residuals = []
        for contact in (near, gathered):
            contact.search_pending = True
            contact.frozen = False
            contact.update()
            b = dolfinx.fem.petsc.create_vector(contact.operator({u: 1.0}).F)
            b.set(0.0)
            contact.operator({u: 1.0}).add_to_residual(b)
            residuals.append(b.getArray().copy())
        a, b = near.pairing, gathered.pairing
        assert np.array_equal(a.facet_global_nodes, b.facet_global_nodes)
        assert np.array_equal(a.reference.x.array, b.reference.x.array)
        for x, y in zip(_local_csr(a.Q), _local_csr(b.Q), strict=True):
            assert np.array_equal(x, y)
        assert MPI.COMM_WORLD.allreduce(float(np.abs(residuals[0]).max(initial=0.0)),
                                        op=MPI.MAX) > 1e-6
        assert np.array_equal(residuals[0], residuals[1])
    assert a.changes >= 2  # the slide changed the pairing


def test_no_rank_holds_the_whole_master_surface():
    """The facets a rank holds after the search, against the whole surface's (what the
    gathered search holds): fewer on every rank, and more than the candidates a node needs."""
    mesh = _hertz_mesh(MPI.COMM_WORLD)
    V = _compat.vector_function_space(mesh.mesh, 1)
    u = _sheared(V, 0.0)
    near, gathered = _contacts(u, mesh)
    for contact in (near, gathered):
        contact.update()
    whole = gathered.pairing.held
    assert whole == MPI.COMM_WORLD.allreduce(len(near.pairing.master_facets)) or \
        MPI.COMM_WORLD.size > 1  # serially the whole surface is this rank's own
    held = MPI.COMM_WORLD.allgather(near.pairing.held)
    assert all(CANDIDATES <= h < whole for h in held), (held, whole)


def test_candidates_do_not_depend_on_which_facets_are_held():
    """Facets whose centroids are equally far from the query point (a ring of 16 around it,
    more than the 12 candidates): the candidates are all of the ring, whatever extra facets
    farther away are held and in whatever order."""
    angles = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    ring = np.stack([np.cos(angles), np.sin(angles), np.zeros(16)], axis=1)
    far = 3 * ring[:5] + [0.0, 0.0, 0.1]
    corners = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.0, 0.01, 0.0]]) \
        - [0.01 / 3, 0.01 / 3, 0.0]
    centres = np.vstack([ring, far])
    x = centres[:, None, :] + corners
    nodes = np.arange(3 * len(centres)).reshape(-1, 3)
    point = np.zeros((1, 3))
    for order in (np.arange(len(centres)), np.arange(len(centres))[::-1]):
        held = _Facets(nodes[order], x[order], x[order])
        rows, reach = _candidates(held, point)
        assert sorted(nodes[order][rows[0], 0]) == sorted(nodes[:16, 0])
        assert reach[0] == pytest.approx(1.0)
    only_ring = _Facets(nodes[:16], x[:16], x[:16])
    assert len(_candidates(only_ring, point)[0][0]) == 16


@pytest.mark.mpi(min_size=2)
def test_contact_partition_gives_every_rank_slave_nodes():
    """dolfinx's graph partitioner puts the sphere (every slave node) on one rank; the contact
    partition cuts both bodies by the angle about z: each rank pairs about half of the slave
    nodes and holds master facets."""
    comm = MPI.COMM_WORLD
    counts = {}
    for partition in ("graph", "contact"):
        mesh = _hertz_mesh(comm, partition)
        V = _compat.vector_function_space(mesh.mesh, 1)
        slave = np.unique(facet_nodes(V, mesh.facet_tags, geometry.SLAVE, outward=False))
        owned = np.count_nonzero(slave < V.dofmap.index_map.size_local)
        counts[partition] = comm.allgather(int(owned))
        masters = comm.allgather(int(np.count_nonzero(mesh.facet_tags.values
                                                      == geometry.MASTER)))
        if partition == "contact":
            assert min(masters) > 0
    total = sum(counts["contact"])
    assert total == sum(counts["graph"])
    # equal runs of cells by angle: the slave surface splits in about equal parts
    assert min(counts["contact"]) > 0.35 * total / comm.size, counts


def test_hertz_pressures_agree_on_one_and_two_ranks():
    """The quarter sphere pressed to Hertz's a = R/10 on this communicator (the contact
    partition) and on each rank alone: the nodal pressures agree to 1e-8 of the peak (Newton
    converges quadratically, its last step leaves round-off; the search is the same), and so
    do the recovered contact area (summed over the nodes) and the pressure on the axis
    (projected from the gathered nodal values), and the points where the gap changes sign
    (interpolated along the facets' edges from each rank's owned and ghost nodes)."""
    scene = Hertz(dim=3)
    delta = (scene.radius / 10) ** 2 / scene.radius
    pressures, recovered, edges = [], [], []
    for comm in (MPI.COMM_WORLD, MPI.COMM_SELF):
        model = scene.model(_hertz_mesh(comm), fix_load_face=False)
        model.solve_at(delta)
        values = model.surface_values()
        # by coordinates rounded off (a partition's coordinates may differ by 1e-17)
        order = np.lexsort(np.round(values.x, 12).T[::-1])
        pressures.append((values.x[order], values.pressure[order]))
        area = model.contact_area(values)
        edge = model.contact_edge(values)
        edges.append(edge[np.lexsort(np.round(edge, 9).T[::-1])])
        r = np.linalg.norm(values.x[:, :2], axis=1)
        # the whole zone: this coarse mesh has few nodes near the axis
        recovered.append((area, pressure_on_axis(r, values.pressure, values.load_weight,
                                                 np.sqrt(4 * area / np.pi), disc=1.0)))
    (x1, p1), (x2, p2) = pressures
    assert np.allclose(x1, x2, rtol=0, atol=1e-12)  # the same nodes
    assert p1.max() > 0
    assert np.abs(p1 - p2).max() <= 1e-8 * p1.max()
    (area1, axis1), (area2, axis2) = recovered
    assert area1 > 0
    assert area1 == pytest.approx(area2, rel=1e-12)  # the same nodes in contact
    assert axis1 == pytest.approx(axis2, rel=1e-8)
    assert len(edges[0]) > 0 and edges[0].shape == edges[1].shape
    assert np.allclose(edges[0], edges[1], rtol=0, atol=1e-6 * scene.radius)


def _mortar_contacts(u: fem.Function, mesh: geometry.TwoBodyMesh) -> list[SegmentToSegment]:
    law = InterfaceLaw(c_n=100.0, m_n=2.0)
    return [SegmentToSegment(u, mesh.facet_tags, geometry.SLAVE, geometry.MASTER, law,
                             exchange=exchange) for exchange in ("neighbours", "all")]


def _residual(contact, u: fem.Function) -> np.ndarray:
    operator = contact.operator({u: 1.0})
    b = dolfinx.fem.petsc.create_vector(operator.G)
    b.set(0.0)
    operator.add_to_residual(b)
    return b.getArray().copy()


def test_mortar_integrals_equal_the_gathered_search():
    """Mortar (segment-to-segment) on the quarter sphere, two searches (the second after a
    slide by a tenth of the contact radius): with the master facets near each rank's slave
    pieces only, B, the reference gaps, the normals, the covered fractions and the contact
    residual are those with the whole master surface gathered, to round-off (the same
    integrals summed in another order: 1e-12 of the largest entry), and no rank holds the
    whole master surface."""
    comm = MPI.COMM_WORLD
    mesh = _hertz_mesh(comm)
    V = _compat.vector_function_space(mesh.mesh, 1)
    u = _sheared(V, 0.0)
    near, gathered = _mortar_contacts(u, mesh)
    for slide in (0.0, 0.01):
        u.x.array[:] = _sheared(V, slide).x.array
        residuals = []
        for contact in (near, gathered):
            contact.search_pending = True
            contact.update()
            residuals.append(_residual(contact, u))
        a, b = near.pairing, gathered.pairing
        assert a.Q is not None and b.Q is not None
        (ia, ja, va), (ib, jb, vb) = a.Q.getValuesCSR(), b.Q.getValuesCSR()
        assert np.array_equal(ia, ib) and np.array_equal(ja, jb)
        assert np.allclose(va, vb, rtol=0, atol=1e-12 * np.abs(vb).max(initial=1.0))
        for f in ("reference", "normal", "coverage"):
            x, y = getattr(a, f).x.array, getattr(b, f).x.array
            assert np.allclose(x, y, rtol=0, atol=1e-12), f
        peak = comm.allreduce(float(np.abs(residuals[1]).max(initial=0.0)), op=MPI.MAX)
        assert peak > 1e-6
        assert np.allclose(residuals[0], residuals[1], rtol=0, atol=1e-12 * peak)
    whole = gathered.pairing.held
    held = comm.allgather(near.pairing.held)
    assert all(0 < h < whole for h in held), (held, whole)


@pytest.mark.mpi(min_size=2)
def test_mortar_hertz_pressures_agree_on_one_and_two_ranks():
    """The quarter sphere pressed to Hertz's a = R/10 with mortar contact on this communicator
    (the contact partition: each rank holds part of both surfaces) and on each rank alone: the
    nodal pressures agree to 1e-8 of the peak (Newton's last step leaves round-off)."""
    scene = Hertz(dim=3, formulation="mortar")
    delta = (scene.radius / 10) ** 2 / scene.radius
    pressures = []
    for comm in (MPI.COMM_WORLD, MPI.COMM_SELF):
        model = scene.model(_hertz_mesh(comm), fix_load_face=False)
        model.solve_at(delta)
        values = model.surface_values()
        order = np.lexsort(np.round(values.x, 12).T[::-1])
        pressures.append((values.x[order], values.pressure[order]))
    (x1, p1), (x2, p2) = pressures
    assert np.allclose(x1, x2, rtol=0, atol=1e-12)
    assert p1.max() > 0
    assert np.abs(p1 - p2).max() <= 1e-8 * p1.max()


def test_bad_exchange_and_partition_are_named():
    mesh = _hertz_mesh(MPI.COMM_SELF, "graph")
    V = _compat.vector_function_space(mesh.mesh, 1)
    W = _compat.lagrange_vector_space(mesh.mesh, 1, 9)
    master = facet_nodes(V, mesh.facet_tags, geometry.MASTER)
    with pytest.raises(ValueError, match="exchange"):
        Pairing(V, W, np.zeros(0, dtype=np.int32), master, exchange="everyone")
    with pytest.raises(ValueError, match="exchange"):
        MortarIntegrals(V, master, master, exchange="everyone")
    with pytest.raises(ValueError, match="partition"):
        geometry.hertz_3d(MPI.COMM_SELF, h_contact=H_CONTACT, partition="metis")
