r"""The interface law between two deformable bodies: segment-to-segment (mortar) contact.

The law of Martins & Oden (1986) acts on mortar-weighted gaps (Puso & Laursen 2004; Yang,
Laursen & Meng 2005; Popp, Gee & Wall 2009) instead of the gaps of single slave nodes
(:mod:`fenicsfriction.contact.node_to_segment`). On the slave surface :math:`\Gamma_s` a test
basis :math:`\psi_j`, one function per slave node — the P1 hats of the slave facets (degree 1),
or of each facet split into linear pieces at its midside nodes (degree 2: a 3-node segment into
two segments, a 6-node triangle into four triangles; Puso, Laursen & Solberg 2008), so that
every :math:`\psi_j` has a positive integral and :math:`\sum_j \psi_j = 1` — weighs the gap
between the slave points and the master points they face:

.. math::
    D_{jk} = \int_{\Gamma_s} \psi_j N^s_k \, dS, \qquad
    M_{jl} = \int_{\Gamma_s} \psi_j N^m_l(\xi(X)) \, dS, \qquad
    A_j = \int_{\Gamma_s} \psi_j \, dS = \sum_k D_{jk},

in the slave reference configuration (tractions per reference area: the package is
small-strain), :math:`N^s_k, N^m_l` the slave and master shape functions and :math:`\xi(X)` the
master facet coordinates of the point that the current slave point :math:`x_s(X)` faces along
the normal of the slave (sub)facet. The mortar relative position of slave node :math:`j` and
its penetration are

.. math::
    G_j = \frac{1}{A_j}\Big(\sum_k D_{jk} x_k - \sum_l M_{jl} x_l\Big), \qquad
    d_j = (n_j\cdot G_j)_+, \qquad g_j = -n_j\cdot G_j,

:math:`x = X + u`, :math:`n_j` the averaged normal of the slave facets at node :math:`j` (out
of the slave body). With :math:`D, M, n` computed at each search and held between searches,
:math:`G = B (X + u)` is linear in :math:`u`: ``B`` a sparse matrix from the dofs of all nodes
to those of the slave nodes. The slave velocity relative to the master is
:math:`w_j = (B \dot u)_j - U_T`, its approach rate :math:`\dot d_j = n_j\cdot w_j`, the
pressure :math:`p_j` and the friction traction :math:`t_{T,j}` those of the law, and the
force :math:`f_j = -p_j n_j + t_{T,j}` acts on :math:`G_j`. The virtual power is

.. math:: R_c(v) = -\sum_j A_j\, f_j\cdot (B v)_j = -\int_{\Gamma_s} f\cdot (B v)\, ds_h,

:math:`ds_h` a nodal rule on the slave facets whose weights are the :math:`A_j` (the
vertices' for degree 1; vertices and midpoints with the split hats' integrals for degree 2).
So the term is one UFL form ``G`` of the fields' mirrors :math:`B f` (Functions of ``V``) and
:math:`R_c = B^T G`, :math:`dR_c/du = B^T G_{,U} B` — node-to-segment's chain
(:class:`~fenicsfriction.contact.node_to_segment.ContactOperator`) with ``Q = B``.

Exactness: on each slave (sub)facet the integrals are summed over the pieces that one master
(sub)facet covers (segmentation: the master facet projected on the slave facet's line or
plane and clipped, Sutherland-Hodgman, the polygon fan-triangulated), with a Gauss rule exact
for the cubic integrands (3 points per segment, 6 per triangle). A uniform pressure is then
transmitted exactly across non-matching meshes (the contact patch test), and the slave and
master nodes receive the consistent loads of the traction.

Limits: the geometry (:math:`D, M, n`, the segmentation) is frozen between searches and not
linearised: the search is a fixed point on the contact geometry
(:func:`~fenicsfriction.contact.node_to_segment.solve_with_search` repeats the solve until it
holds), so Newton converges quadratically to the solution of the frozen geometry only. A slave
node that no master facet covers (farther than the search radius) has no force; its gap is the
distance to the nearest master facet's centroid.

Parallel: no rank gathers either surface; each holds the slave facets touching its owned
slave nodes and the master facets near them (:class:`MortarIntegrals`).
"""

from __future__ import annotations

import dataclasses
import functools
import time
import typing

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import scipy.sparse
import ufl
from dolfinx import fem, mesh
from scipy.spatial import cKDTree

from fenicsfriction import _compat, laws
from fenicsfriction.contact.node_to_segment import MirroredContact, discrete_gradient
from fenicsfriction.contact.pairing import EXCHANGES, FacetExchange, _Facets

__all__ = ["MortarIntegrals", "SegmentToSegment", "surface_facets"]

Value = typing.Any

#: a search changes the contact geometry when a gap moves by more than this, relative to the
#: largest penetration (or to the slave facets' size where nothing penetrates): the pressures
#: of a fixed point of the search are converged on the contact geometry to about this
#: fraction (each round of the fixed point divides the change by 10-100 on Hertz's cylinder)
GAP_TOLERANCE = 1e-5

#: master facets are candidates of a slave facet when their centroids are within this many
#: times the sum of the two facets' radii (in-plane overlap needs 1; the rest allows for a
#: normal separation of half the facets' size)
SEARCH_RADIUS = 1.5

#: the pieces of a split degree-2 facet: for each, its vertices among the facet's nodes
#: (vertices first, then the midside nodes m01 (2D); m01, m12, m20 (3D)), ordered as the
#: facet so that every piece has the facet's normal
_PIECES = {(2, 1): [[0, 1]], (2, 2): [[0, 2], [2, 1]],
           (3, 1): [[0, 1, 2]], (3, 2): [[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]]}

#: the barycentric coordinates of a facet's nodes
_NODES = {2: np.array([[1.0, 0.0], [0.0, 1.0], [0.5, 0.5]]),
          3: np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0],
                       [0.5, 0.5, 0.0], [0.0, 0.5, 0.5], [0.5, 0.0, 0.5]])}

# Gauss-Legendre, 3 points on [0, 1] (degree 5), and the 6-point rule of degree 4 on the
# triangle (Dunavant 1985, "High degree efficient symmetrical Gaussian quadrature rules for
# the triangle", Table I), barycentric, weights summing to 1
_GAUSS_SEGMENT = ((np.polynomial.legendre.leggauss(3)[0] + 1) / 2,
                  np.polynomial.legendre.leggauss(3)[1] / 2)
_A, _B = 0.445948490915965, 0.091576213509771
_GAUSS_TRIANGLE = (np.array([[_A, _A, 1 - 2 * _A], [_A, 1 - 2 * _A, _A], [1 - 2 * _A, _A, _A],
                             [_B, _B, 1 - 2 * _B], [_B, 1 - 2 * _B, _B], [1 - 2 * _B, _B, _B]]),
                   np.array([0.223381589678011] * 3 + [0.109951743655322] * 3))


def shape_functions(lam: np.ndarray, degree: int) -> np.ndarray:
    """The Lagrange shape functions of a facet (nodes as in :data:`_NODES`) at barycentric
    coordinates ``lam[..., a]``."""
    if degree == 1:
        return lam
    vertices = lam * (2 * lam - 1)
    if lam.shape[-1] == 2:
        return np.concatenate([vertices, 4 * lam[..., :1] * lam[..., 1:]], axis=-1)
    edges = 4 * lam * np.roll(lam, -1, axis=-1)  # λ0λ1, λ1λ2, λ2λ0
    return np.concatenate([vertices, edges], axis=-1)


def _normal(x: np.ndarray) -> np.ndarray:
    """Unnormalised normal of the flat facets through ``x[..., a, :]`` (kinematics'
    convention), of length the facet's length (2D) or twice its area (3D)."""
    t = x[..., 1, :] - x[..., 0, :]
    if x.shape[-2] == 2:
        return np.stack([-t[..., 1], t[..., 0]], axis=-1)
    return np.cross(t, x[..., 2, :] - x[..., 0, :])


def surface_facets(V: fem.FunctionSpace, facet_tags: mesh.MeshTags, tag: int) -> np.ndarray:
    """The local node indices of the facets tagged ``tag``, one row per facet: the vertices,
    ordered so that the facet normal (:func:`fenicsfriction.contact.kinematics.project`'s
    convention) points out of the body, then for degree 2 the midside nodes (m01 in 2D; m01,
    m12, m20 in 3D)."""
    msh = V.mesh
    tdim = msh.topology.dim
    degree = _compat.element_degree(V)
    msh.topology.create_connectivity(tdim - 1, tdim)
    msh.topology.create_connectivity(tdim, tdim - 1)
    f_to_c = msh.topology.connectivity(tdim - 1, tdim)
    c_to_f = msh.topology.connectivity(tdim, tdim - 1)
    layout = V.dofmap.dof_layout
    x = V.tabulate_dof_coordinates()[:, :msh.geometry.dim]
    facets = facet_tags.indices[facet_tags.values == tag]
    count = tdim if degree == 1 else len(_NODES[tdim])
    rows = np.empty((len(facets), count), dtype=np.int32)
    flip = [1, 0, 2] if tdim == 2 else [0, 2, 1, 5, 4, 3]
    for i, facet in enumerate(facets):
        cell = f_to_c.links(facet)[0]
        local = int(np.flatnonzero(c_to_f.links(cell) == facet)[0])
        cell_nodes = V.dofmap.cell_dofs(cell)
        nodes = cell_nodes[layout.entity_closure_dofs(tdim - 1, local)]  # vertices first
        if degree == 2:  # the midside nodes in the order of _NODES
            middle = nodes[tdim:]
            targets = _NODES[tdim][tdim:] @ x[nodes[:tdim]]
            distance = np.linalg.norm(x[middle][None, :, :] - targets[:, None, :], axis=-1)
            nodes = np.concatenate([nodes[:tdim], middle[np.argmin(distance, axis=1)]])
        inside = x[cell_nodes].mean(axis=0)
        vertices = x[nodes[:tdim]]
        if np.dot(_normal(vertices), vertices.mean(axis=0) - inside) < 0:
            nodes = nodes[flip[:len(nodes)]]
        rows[i] = nodes
    return rows


@dataclasses.dataclass
class _Pieces:
    """The linear pieces of a surface's facets (the facets themselves for degree 1)."""

    facet: np.ndarray  # (p,) the facet of each piece
    nodes: np.ndarray  # (p, nv) global node indices of the piece's vertices
    split: np.ndarray  # (pieces per facet, nv) the pieces' vertices among the facet's nodes
    parent: np.ndarray  # (pieces per facet, nv, nv) their barycentric coordinates in it

    @classmethod
    def split_facets(cls, nodes: np.ndarray, dim: int, degree: int) -> _Pieces:
        split = np.array(_PIECES[dim, degree])
        facet = np.repeat(np.arange(len(nodes)), len(split))
        return cls(facet, nodes[:, split].reshape(-1, dim), split, _NODES[dim][split])

    def in_facet(self, lam: np.ndarray, pieces: np.ndarray) -> np.ndarray:
        """The facet's barycentric coordinates of points with coordinates ``lam[q]`` in the
        pieces ``pieces[q]``."""
        kind = pieces % len(self.split)
        out = np.empty_like(lam)
        for k, parent in enumerate(self.parent):
            chosen = kind == k
            out[chosen] = lam[chosen] @ parent
        return out

    def coordinates(self, x: np.ndarray) -> np.ndarray:
        """The pieces' vertices' coordinates, ``x`` those of the facets' nodes (f, nen, dim):
        the pieces are flat through them."""
        return x[:, self.split].reshape(-1, self.split.shape[1], x.shape[-1])


class MortarIntegrals:
    """The mortar integrals of one slave surface against a master surface, and ``B``.

    No rank holds either surface whole. Each rank holds the slave facets that touch its owned
    slave nodes (its own, and those that the ranks holding their cells send it, point to
    point) and the master facets near them, obtained at each search from the ranks holding
    them as node-to-segment's search does (:class:`~fenicsfriction.contact.pairing.
    FacetExchange`, the points being the centroids of the slave pieces): a master facet is
    held when its centroid is within the radius of a slave piece's box, and each piece's
    radius must reach beyond every master piece it could be segmented with and beyond the
    master piece nearest to each of its nodes. Each rank integrates the slave pieces that
    touch its owned slave nodes and builds their rows of ``B``; its arrays are as long as
    its own nodes and the surfaces' nodes it holds.

    Args:
        V: the displacement space (Lagrange vectors of degree 1 or 2).
        slave, master: the surfaces' facets (:func:`surface_facets`, local node indices).
        exchange: ``"neighbours"`` (default) or ``"all"``: the whole master surface
            all-gathered on every rank (the reference the tests compare with).

    Attributes:
        Q: ``B`` (rows: the owned slave nodes' dofs; columns: all dofs of V), a PETSc matrix
            (``None`` before :meth:`search`); named as node-to-segment's pairing operator.
        D, M: the mortar integrals of the owned slave nodes (SciPy CSR, rows: owned local
            nodes of V, columns: global node indices).
        area: :math:`A_j` of the owned nodes (0 off the slave surface or where uncovered).
        normal: a Function of V, each slave node's averaged normal (out of the slave body).
        reference: a Function of V, :math:`B X` (plus, at uncovered slave nodes, their gap
            to the nearest master facet along :math:`-n`).
        slave_nodes: the owned slave nodes (local indices).
        slave_local, master_local: this rank's facets of either surface (local node indices).
        held: how many master facets this rank held at the last search.
        searches, changes: how many searches ran, how many changed B's sparsity pattern.
        time_s: seconds in ``"search"`` (exchanges, normals, segmentation, integrals, the
            change test: until every rank is done), of which ``"exchange"`` obtaining the
            facets, and ``"build"`` (B as a PETSc matrix, the reference gaps, normals and
            coverage as Functions), summed over calls.
    """

    def __init__(self, V: fem.FunctionSpace, slave: np.ndarray, master: np.ndarray,
                 exchange: str = "neighbours"):
        laws.check("exchange", exchange, exchange in EXCHANGES, f"one of {', '.join(EXCHANGES)}")
        self.V = V
        self.exchange = exchange
        self.comm: MPI.Comm = V.mesh.comm
        self.dim = dim = V.mesh.geometry.dim
        self.degree = _compat.element_degree(V)
        self.x_nodes = V.tabulate_dof_coordinates()[:, :dim]
        index_map = V.dofmap.index_map
        self.owned_range = np.array(index_map.local_range, dtype=np.int64)
        self.size_local, self.size_global = index_map.size_local, index_map.size_global
        self.slave_local, self.master_local = slave, master
        self._slave_global = self._global(slave)
        self._master_global = self._global(master)
        on_slave = np.unique(slave)
        self.slave_nodes = on_slave[on_slave < self.size_local].astype(np.int32)
        # the slave facets each rank sends to the owners of their nodes, and whence it receives
        owner = np.full(len(self.x_nodes), self.comm.rank, dtype=np.int64)
        owner[self.size_local:] = np.asarray(index_map.owners, dtype=np.int64)
        self._sends = {int(q): np.flatnonzero((owner[slave] == q).any(axis=1))
                       for q in np.unique(owner[slave]) if q != self.comm.rank}
        counts = self.comm.alltoall([q in self._sends for q in range(self.comm.size)])
        self._sources = [q for q, sends in enumerate(counts) if sends]
        self._mine_facets = np.flatnonzero((owner[slave] == self.comm.rank).any(axis=1))
        reference = self._slave_facets(None)
        self.slave_pieces = _Pieces.split_facets(reference.global_nodes, dim, self.degree)
        self.mine = np.flatnonzero(self._owned(self.slave_pieces.nodes).any(axis=1))
        centres = self.slave_pieces.coordinates(reference.reference)[self.mine].mean(axis=1)
        self._exchange = FacetExchange(self.comm, centres, master.shape[1])
        self._tributary = self._tributaries(reference)
        self._facet_size = self._mean_size(reference)
        self.Q: PETSc.Mat | None = None
        self.D = self.M = scipy.sparse.csr_matrix((self.size_local, self.size_global))
        self.area = np.zeros(self.size_local)
        self.normal = fem.Function(V, name="slave_normal")
        self.coverage = fem.Function(_compat.scalar_function_space(V.mesh, "Lagrange",
                                                                   self.degree),
                                     name="mortar_coverage")
        self.reference = fem.Function(V, name="mortar_reference")
        self.held = 0
        self._master_radius = 0.0
        self.searches = 0
        self.changes = 0
        self.time_s = {"search": 0.0, "build": 0.0, "exchange": 0.0}
        self._B: scipy.sparse.csr_matrix | None = None
        self._gap: np.ndarray | None = None
        self._searched_at: np.ndarray | None = None

    def _global(self, local: np.ndarray) -> np.ndarray:
        index_map = self.V.dofmap.index_map
        return index_map.local_to_global(local.ravel()).reshape(local.shape).astype(np.int64)

    def _owned(self, nodes: np.ndarray) -> np.ndarray:
        return (nodes >= self.owned_range[0]) & (nodes < self.owned_range[1])

    def _facets(self, local: np.ndarray, global_nodes: np.ndarray,
                u: fem.Function | None) -> _Facets:
        reference = self.x_nodes[local]
        if u is None:
            return _Facets(global_nodes, reference, reference)
        return _Facets(global_nodes, reference,
                       reference + u.x.array.reshape(-1, self.dim)[local])

    def _slave_facets(self, u: fem.Function | None) -> _Facets:
        """The slave facets that touch this rank's owned nodes, at displacement ``u`` (None:
        the reference): its own, and those the ranks holding them send (point to point)."""
        nen = self.slave_local.shape[1]
        facets = self._facets(self.slave_local, self._slave_global, u)
        requests = [self.comm.isend(facets.take(rows), dest=q, tag=7027)
                    for q, rows in self._sends.items()]
        pieces = [facets.take(self._mine_facets)]
        pieces += [self.comm.recv(source=q, tag=7027) for q in self._sources]
        MPI.Request.waitall(requests)
        return _Facets.join(pieces, nen, self.dim)

    def _master_facets(self, u: fem.Function, slave_x: np.ndarray) -> _Facets:
        """The master facets near this rank's slave pieces ``slave_x`` (current), or all of
        them (``exchange="all"``)."""
        local = self._facets(self.master_local, self._master_global, u)
        nen = self.master_local.shape[1]
        pieces = _Pieces.split_facets(self._master_global, self.dim, self.degree)
        x = pieces.coordinates(local.current)
        centre = local.current.mean(axis=1)
        # the farthest a master piece's vertex is from its centroid (the segmentation's ball
        # depends on it), and a piece's centroid from its facet's centroid (the one the
        # exchange measures): over all ranks
        m_radius = float(np.linalg.norm(x - x.mean(axis=1)[:, None], axis=-1).max(initial=0.0))
        spread = float(np.linalg.norm(local.current - centre[:, None], axis=-1).max(initial=0.0))
        self._master_radius = m_radius = self.comm.allreduce(m_radius, op=MPI.MAX)
        spread = self.comm.allreduce(spread, op=MPI.MAX)
        if self.exchange == "all":
            return _Facets.join(self.comm.allgather(local), nen, self.dim)
        s_x = slave_x[self.mine]
        s_centre = s_x.mean(axis=1)
        s_radius = np.linalg.norm(s_x - s_centre[:, None], axis=-1).max(axis=1, initial=0.0)
        segment = SEARCH_RADIUS * (s_radius + m_radius) + spread

        def need(held: _Facets) -> tuple[np.ndarray, None]:
            # the segmentation's ball, and the ball of the master pieces that may be the
            # nearest to a node of the piece (the nearest held is at most that far)
            if not len(held.global_nodes):
                return np.full(len(s_centre), np.inf), None
            m = _Pieces.split_facets(held.global_nodes, self.dim, self.degree)
            tree = cKDTree(m.coordinates(held.current).mean(axis=1))
            nearest = tree.query(s_centre)[0] if len(s_centre) else np.zeros(0)
            return np.maximum(segment, 2 * s_radius + nearest + spread), None

        if self.searches == 1:
            self._exchange.radius[:] = self.comm.allreduce(
                float(segment.max(initial=0.0)), op=MPI.MAX) * 1.1 or 1.0
        spent = self._exchange.seconds
        held, _ = self._exchange.hold(local, s_centre, need)
        self.time_s["exchange"] += self._exchange.seconds - spent
        return held

    def search(self, u: fem.Function) -> bool:
        """Normals, segmentation and mortar integrals at displacement ``u``, and ``B``.

        Returns True if the contact geometry changed: B's sparsity pattern, or a gap at
        ``u`` by more than :data:`GAP_TOLERANCE` (relative) from the last search's. At the
        state of the last search nothing is done (False).
        """
        state = u.x.array[:self.size_local * self.dim]
        if self._searched_at is not None and self.comm.allreduce(
                bool(np.array_equal(state, self._searched_at)), op=MPI.LAND):
            return False  # the state of the last search (a new solve starting from it)
        self._searched_at = state.copy()
        t0 = time.perf_counter()
        self.searches += 1
        te = time.perf_counter()
        slave = self._slave_facets(u)
        self.time_s["exchange"] += time.perf_counter() - te
        slave_x = self.slave_pieces.coordinates(slave.current)
        slave_X = self.slave_pieces.coordinates(slave.reference)
        master = self._master_facets(u, slave_x)
        self.held = len(master.global_nodes)
        self.master_pieces = _Pieces.split_facets(master.global_nodes, self.dim, self.degree)
        master_x = self.master_pieces.coordinates(master.current)
        # the columns: the surfaces' nodes this rank holds, in global order
        columns = np.unique(np.concatenate([slave.global_nodes.ravel(),
                                            master.global_nodes.ravel()]))
        normals = self._nodal_normals(slave_x)
        D, M, nearest = self._integrals(slave_x, slave_X, master_x, slave, master, columns,
                                        u)
        area = np.asarray(D.sum(axis=1)).ravel()
        self.area = area
        covered = area > 0
        offset = np.where(covered, 0.0, nearest)[:, None] * normals
        scale = np.where(covered, 1.0 / np.where(covered, area, 1.0), 0.0)
        B = (scipy.sparse.diags(scale) @ (D - M)).tocsr()
        B.sort_indices()
        B.eliminate_zeros()
        # the relative positions at u with the new geometry, uncovered nodes at their distance
        G = (B @ _rows(columns, slave, master, "current")) - offset
        gap = -np.einsum("jk,jk->j", normals, G)[self.slave_nodes]
        B_reference = B @ _rows(columns, slave, master, "reference")
        B, self.D, self.M = (_to_global(A, columns, self.size_global) for A in (B, D, M))
        pattern_changed = self._B is None or not (
            np.array_equal(self._B.indptr, B.indptr) and np.array_equal(self._B.indices,
                                                                        B.indices))
        moved = 0.0
        if self._gap is not None:
            moved = float(np.abs(gap - self._gap).max(initial=0.0))
        reach = self.comm.allreduce(float(np.maximum(-gap, 0.0).max(initial=0.0)), op=MPI.MAX)
        size = self._facet_size
        changed = pattern_changed or moved > GAP_TOLERANCE * (reach if reach > 0 else size)
        changed = bool(self.comm.allreduce(changed, op=MPI.LOR))
        pattern_changed = bool(self.comm.allreduce(pattern_changed, op=MPI.LOR))
        t1 = time.perf_counter()  # the ranks' searches done (the collectives wait for all)
        self.time_s["search"] += t1 - t0
        self._B, self._gap = B, gap
        self._set(self.normal, normals)
        fraction = self.coverage.x.array
        fraction[:] = 0.0
        fraction[self.slave_nodes] = (self.area / self._tributary)[self.slave_nodes]
        self.coverage.x.scatter_forward()
        self._set(self.reference, B_reference - offset)
        if pattern_changed:
            self.changes += 1
        self._build(B)
        self.time_s["build"] += time.perf_counter() - t1
        return changed

    def _set(self, f: fem.Function, owned: np.ndarray) -> None:
        """A Function of V: ``owned`` (size_local, dim) on the owned nodes, ghosts updated."""
        f.x.array[:] = 0.0
        f.x.array.reshape(-1, self.dim)[:self.size_local] = owned
        f.x.scatter_forward()

    def _tributaries(self, slave: _Facets) -> np.ndarray:
        """Each owned node's integral of its test function :math:`\\psi_j` over the whole
        slave surface (reference): a third (half in 2D) of its pieces' sizes."""
        X = self.slave_pieces.coordinates(slave.reference)
        share = np.linalg.norm(_normal(X), axis=-1) / (2.0 if self.dim == 3 else 1.0) / self.dim
        total = np.zeros(self.size_local)
        nodes = self.slave_pieces.nodes
        for a in range(nodes.shape[1]):
            owned = self._owned(nodes[:, a])
            np.add.at(total, nodes[owned, a] - self.owned_range[0], share[owned])
        return np.where(total > 0, total, 1.0)

    def _mean_size(self, slave: _Facets) -> float:
        """The mean length of a slave piece's first side over the whole surface: each facet
        counted by the rank that owns its smallest node."""
        X = self.slave_pieces.coordinates(slave.reference)
        counted = np.repeat(self._owned(slave.global_nodes.min(axis=1, initial=-1)),
                            len(self.slave_pieces.split))
        total = self.comm.allreduce(float(np.linalg.norm(X[counted, 1] - X[counted, 0],
                                                         axis=-1).sum()))
        count = self.comm.allreduce(int(np.count_nonzero(counted)))
        return total / count if count else 1.0

    def _nodal_normals(self, slave_x: np.ndarray) -> np.ndarray:
        """The owned nodes' unit normals: the sum of their slave pieces' area vectors."""
        normals = np.zeros((self.size_local, self.dim))
        pieces = self.slave_pieces.nodes
        area = _normal(slave_x)
        for a in range(pieces.shape[1]):
            owned = self._owned(pieces[:, a])
            np.add.at(normals, pieces[owned, a] - self.owned_range[0], area[owned])
        size = np.linalg.norm(normals, axis=1)
        return normals / np.where(size > 0, size, 1.0)[:, None]

    def _integrals(self, slave_x: np.ndarray, slave_X: np.ndarray, master_x: np.ndarray,
                   slave: _Facets, master: _Facets, columns: np.ndarray, u: fem.Function
                   ) -> tuple[scipy.sparse.csr_matrix, scipy.sparse.csr_matrix, np.ndarray]:
        """D, M of the owned slave nodes (columns: the surfaces' nodes held, ``columns``
        their global indices), and each owned node's distance to the nearest master piece's
        centroid (the gap of an uncovered node)."""
        d = self.dim
        mine = self.mine
        s_x, s_X = slave_x[mine], slave_X[mine]
        s_normal, m_normal = _normal(s_x), _normal(master_x)
        s_centre, m_centre = s_x.mean(axis=1), master_x.mean(axis=1)
        s_radius = np.linalg.norm(s_x - s_centre[:, None], axis=-1).max(axis=1)
        m_radius = np.linalg.norm(master_x - m_centre[:, None], axis=-1).max(axis=1)
        tree = cKDTree(m_centre)
        nearest = np.zeros(self.size_local)
        if len(self.slave_nodes):
            x_nodes = (self.x_nodes[self.slave_nodes]
                       + u.x.array.reshape(-1, self.dim)[self.slave_nodes])
            nearest[self.slave_nodes] = tree.query(x_nodes)[0]
        shape = (self.size_local, len(columns))
        if not len(mine):
            empty = scipy.sparse.csr_matrix(shape)
            return empty, empty, nearest
        radius = SEARCH_RADIUS * (s_radius + self._master_radius)
        found = tree.query_ball_point(s_centre, r=radius)
        counts = np.fromiter((len(f) for f in found), dtype=np.int64, count=len(found))
        s_index = np.repeat(np.arange(len(mine)), counts)
        m_index = (np.concatenate([np.asarray(f, dtype=np.int64) for f in found])
                   if counts.sum() else np.zeros(0, dtype=np.int64))
        # facing each other, and close enough across the slave normal to overlap
        unit = s_normal[s_index] / np.linalg.norm(s_normal[s_index], axis=-1, keepdims=True)
        offset = m_centre[m_index] - s_centre[s_index]
        across = offset - np.einsum("pk,pk->p", offset, unit)[:, None] * unit
        keep = ((np.einsum("pk,pk->p", unit, m_normal[m_index]) < 0)
                & (np.linalg.norm(across, axis=-1) <= s_radius[s_index] + m_radius[m_index]))
        s_index, m_index = s_index[keep], m_index[keep]
        segment = _segments_2d if d == 2 else _segments_3d
        mu, nu, weight, pair = segment(s_x[s_index], master_x[m_index])
        # reference measure: the piece's reference size over its current one
        ratio = (np.linalg.norm(_normal(s_X), axis=-1) / np.linalg.norm(s_normal, axis=-1))
        order = np.argsort(pair, kind="stable")  # the points of each pair together
        mu, nu, weight, pair = mu[order], nu[order], weight[order], pair[order]
        starts = np.flatnonzero(np.diff(pair, prepend=-1))
        pair = pair[starts]
        weight = weight * ratio[s_index][pair].repeat(np.diff(np.append(starts, len(order))))
        sp, mp = self.slave_pieces, self.master_pieces
        s_piece, m_piece = mine[s_index[pair]], m_index[pair]
        points = np.repeat(np.arange(len(pair)), np.diff(np.append(starts, len(order))))
        N_s = shape_functions(sp.in_facet(mu, s_piece[points]), self.degree)
        N_m = shape_functions(mp.in_facet(nu, m_piece[points]), self.degree)
        rows = sp.nodes[s_piece]  # (pairs, nv)
        owned = self._owned(rows)
        rows_local = rows - self.owned_range[0]
        weighted = weight[:, None] * mu
        matrices = []
        for N, facets, nodes in ((N_s, sp.facet[s_piece], slave.global_nodes),
                                 (N_m, mp.facet[m_piece], master.global_nodes)):
            held = np.searchsorted(columns, nodes[facets])  # (pairs, nen)
            values = np.add.reduceat(weighted[:, :, None] * N[:, None, :], starts, axis=0)
            keep = np.broadcast_to(owned[:, :, None], values.shape)
            r = np.broadcast_to(rows_local[:, :, None], values.shape)[keep]
            c = np.broadcast_to(held[:, None, :], values.shape)[keep]
            matrices.append(scipy.sparse.csr_matrix((values[keep], (r, c)), shape=shape))
        return matrices[0], matrices[1], nearest

    def _build(self, B: scipy.sparse.csr_matrix) -> None:
        """B on the dofs (each node's block of ``dim`` components) as a PETSc matrix."""
        d = self.dim
        B_dofs = scipy.sparse.kron(B, scipy.sparse.identity(d), format="csr")
        B_dofs.sort_indices()
        if self.Q is not None:
            self.Q.destroy()
        sizes = (self.size_local * d, self.size_global * d)
        self.Q = PETSc.Mat().createAIJ(
            (sizes, sizes), csr=(B_dofs.indptr.astype(PETSc.IntType),
                                 B_dofs.indices.astype(PETSc.IntType), B_dofs.data),
            comm=self.comm)


def _rows(columns: np.ndarray, slave: _Facets, master: _Facets, which: str) -> np.ndarray:
    """The nodal coordinates (``"current"`` or ``"reference"``) of the surfaces' nodes held,
    one row per entry of ``columns`` (their global indices, sorted)."""
    x = np.zeros((len(columns), slave.reference.shape[-1]))
    for facets in (slave, master):
        x[np.searchsorted(columns, facets.global_nodes.ravel())] = \
            getattr(facets, which).reshape(-1, x.shape[1])
    return x


def _to_global(A: scipy.sparse.csr_matrix, columns: np.ndarray, size: int
               ) -> scipy.sparse.csr_matrix:
    """``A`` with its columns (indices into ``columns``) renumbered to ``columns``' global
    indices, of which there are ``size`` (sorted ``columns`` keep each row sorted)."""
    return scipy.sparse.csr_matrix((A.data, columns[A.indices], A.indptr),
                                   shape=(A.shape[0], size))


def _segments_2d(slave: np.ndarray, master: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Gauss points of the part of each slave segment that its master segment covers
    (projected on the slave segment's line): the slave and master barycentric coordinates,
    the weights (current length) and the pair of each point."""
    a, t = slave[:, 0], slave[:, 1] - slave[:, 0]
    length2 = np.einsum("pk,pk->p", t, t)
    s = np.einsum("pak,pk->pa", master - a[:, None], t) / length2[:, None]  # (p, 2)
    lo = np.maximum(s.min(axis=1), 0.0)
    hi = np.minimum(s.max(axis=1), 1.0)
    span = s[:, 1] - s[:, 0]
    keep = np.flatnonzero((hi > lo) & (np.abs(span) > 0))
    points, weights = _GAUSS_SEGMENT
    lo, hi = lo[keep], hi[keep]
    q = lo[:, None] + (hi - lo)[:, None] * points  # (p, 3) slave coordinate
    eta = (q - s[keep, :1]) / span[keep, None]
    w = (hi - lo)[:, None] * weights * np.sqrt(length2[keep])[:, None]
    mu = np.stack([1 - q, q], axis=-1).reshape(-1, 2)
    nu = np.stack([1 - eta, eta], axis=-1).reshape(-1, 2)
    return mu, nu, w.ravel(), np.repeat(keep, len(points))


def _segments_3d(slave: np.ndarray, master: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Gauss points of the part of each slave triangle that its master triangle covers,
    projected on the slave triangle's plane (Sutherland-Hodgman clipping, fan
    triangulation): the slave and master barycentric coordinates, the weights (current
    area) and the pair of each point."""
    origin = slave[:, 0]
    e1 = slave[:, 1] - origin
    e1 /= np.linalg.norm(e1, axis=-1, keepdims=True)
    n = _normal(slave)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    e2 = np.cross(n, e1)

    def plane(x: np.ndarray) -> np.ndarray:
        r = x - origin[:, None]
        return np.stack([np.einsum("pak,pk->pa", r, e1), np.einsum("pak,pk->pa", r, e2)], -1)

    s2, m2 = plane(slave), plane(master)  # (p, 3, 2); the slave triangle counter-clockwise
    # only the pairs whose bounding boxes overlap in the plane are clipped
    overlap = np.all((m2.max(axis=1) >= s2.min(axis=1)) & (m2.min(axis=1) <= s2.max(axis=1)),
                     axis=1)
    candidates = np.flatnonzero(overlap)
    s2, m2 = s2[candidates], m2[candidates]
    polygon, count = _clip(m2, s2)
    points, weights = _GAUSS_TRIANGLE
    mu_all, nu_all, w_all, pair_all = [], [], [], []
    for i in range(1, polygon.shape[1] - 1):
        pieces = np.flatnonzero(count >= i + 2)
        if not len(pieces):
            break
        tri = polygon[pieces][:, [0, i, i + 1]]  # (k, 3, 2)
        area = 0.5 * np.abs(_cross2(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]))
        y = np.einsum("qa,kab->kqb", points, tri)  # (k, q, 2)
        mu_all.append(_barycentric(y, s2[pieces]).reshape(-1, 3))
        nu_all.append(_barycentric(y, m2[pieces]).reshape(-1, 3))
        w_all.append((area[:, None] * weights).ravel())
        pair_all.append(np.repeat(pieces, len(weights)))
    if not mu_all:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0, dtype=np.int64)
    return (np.concatenate(mu_all), np.concatenate(nu_all), np.concatenate(w_all),
            candidates[np.concatenate(pair_all)])


def _cross2(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _barycentric(y: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Barycentric coordinates of points ``y[k, q]`` in the triangles ``tri[k]`` (2D)."""
    a, b, c = tri[:, None, 0], tri[:, None, 1], tri[:, None, 2]
    total = _cross2(b - a, c - a)
    l1 = _cross2(y - a, c - a) / total
    l2 = _cross2(b - a, y - a) / total
    return np.stack([1 - l1 - l2, l1, l2], axis=-1)


def _clip(subject: np.ndarray, clip: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sutherland-Hodgman: the polygons ``subject`` (p, 3, 2) clipped by the counter-clockwise
    triangles ``clip`` (p, 3, 2), for all p at once; returns the vertices (p, k, 2) and how
    many of each row are used."""
    p = len(subject)
    count = np.full(p, subject.shape[1])
    rows = np.arange(p)[:, None]
    for e in range(3):
        a, b = clip[:, e][:, None], clip[:, (e + 1) % 3][:, None]
        k = subject.shape[1]
        index = np.arange(k)[None, :]
        valid = index < count[:, None]
        following = subject[rows, (index + 1) % np.maximum(count, 1)[:, None]]
        side = _cross2(b - a, subject - a)
        side_next = _cross2(b - a, following - a)
        inside, inside_next = side >= 0, side_next >= 0
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(inside != inside_next, side / (side - side_next), 0.0)
        crossing = subject + t[..., None] * (following - subject)
        candidates = np.stack([subject, crossing], axis=2).reshape(p, 2 * k, 2)
        used = np.stack([valid & inside, valid & (inside != inside_next)], axis=2).reshape(p, -1)
        count = used.sum(axis=1)
        subject = np.zeros((p, max(int(count.max(initial=0)), 1), 2))
        r, c = np.nonzero(used)  # the used candidates, in order, to the front of each row
        subject[r, (np.cumsum(used, axis=1) - 1)[r, c]] = candidates[r, c]
    return subject, count


class SegmentToSegment(MirroredContact):
    r"""The interface law between a slave and a master surface, integrated segment to
    segment (mortar): see the module's docstring for the formulation and its limits.

    A :class:`~fenicsfriction.coupling.Coupling`, with the arguments and the attributes of
    :class:`~fenicsfriction.contact.node_to_segment.NodeToSegment` (``make_contact`` builds
    either).

    Args:
        u: the displacement (Lagrange vectors of degree 1 or 2 on a mesh of degree-1
            geometry holding both bodies).
        facet_tags, slave, master: the mesh's facet tags and the two surfaces' tags.
        law: the interface law (:class:`fenicsfriction.laws.InterfaceLaw`, any of its normal
            and friction laws).
        velocity, fields: the slave velocity (a UFL vector of Functions of V, linear in them)
            and the Functions it depends on besides ``u``; each gets a mirror :math:`B f`.
        transport: the master body's rigid velocity :math:`U_T` (default zero).
        weight: the factor of the term (1/2 for each pass of two-pass contact).
        frozen: keep the geometry of the first search (derivative tests).
        search: ``"solve"`` (default: the geometry searched at the start of each Newton solve
            or time step) or ``"residual"`` (at every residual evaluation).
        step_from: the displacement u_n at the start of a midpoint step, ``u`` the step's
            midpoint (:class:`~fenicsfriction.dynamics.DynamicsSolver` with
            ``energy_consistent``): the elastic pressure becomes the discrete gradient of the
            potential between the approaches :math:`-g_j` of the two ends
            (:func:`~fenicsfriction.contact.node_to_segment.discrete_gradient`). ``G`` being
            affine in u between searches, its work over the step is exactly the potential's
            change. ``None`` (default): the pressure at ``u``.
        exchange: how each rank obtains the master facets near its slave facets:
            ``"neighbours"`` (default) or ``"all"`` (:class:`MortarIntegrals`).
        enforcement, formulation, penalty_T, time_step: node-to-segment's choice of the
            perturbed Lagrangian (``formulation`` its former name) is refused here: only
            ``"compliance"`` and no ``penalty_T``; ``time_step`` is accepted and unused, as
            by node-to-segment's compliance law.

    Attributes:
        V, W: the displacement space (both: the mirrors are Functions of V).
        pairing: the :class:`MortarIntegrals` (``Q`` is B).
        mirrors: the Function :math:`B f` of each field f.
        F, G: ``None`` and the form of the contact's virtual power on the mirrors' test
            functions (:math:`R_c = B^T G`).
        ds: the nodal measure on the slave facets, :math:`\int q\, ds = \sum_j A_j q_j`.
        normal, gap, penetration: the contact normal :math:`-n_j`, out of the master body
            (node-to-segment's orientation: ``pressure * normal + traction`` is the force on
            the slave side with either formulation; :math:`n_j` is the Function
            ``pairing.normal``), :math:`g_j = -n_j\cdot G_j` and :math:`d_j` (UFL, nodal).
        pressure, traction: the pressure and the friction traction (UFL, nodal; the traction
            None without friction).
        relative_velocity: :math:`w` (UFL; None without ``velocity``).
        potential, dissipation: the compliance's stored energy and the power dissipated by
            friction and normal damping (UFL forms, nodal rule).
    """

    def __init__(self, u: fem.Function, facet_tags: mesh.MeshTags, slave: int, master: int,
                 law: laws.InterfaceLaw, velocity: typing.Any = None,
                 fields: typing.Sequence[fem.Function] = (), transport: typing.Any = None,
                 weight: float = 1.0, frozen: bool = False, search: str = "solve",
                 enforcement: str = "compliance", formulation: str | None = None,
                 penalty_T: Value | None = None, time_step: Value = 1.0,
                 step_from: fem.Function | None = None, exchange: str = "neighbours"):
        V = u.function_space
        msh = V.mesh
        dim = msh.geometry.dim
        degree = _compat.element_degree(V)
        laws.check("V", degree, degree in (1, 2),
                   "mortar contact needs a Lagrange displacement space of degree 1 or 2")
        # the facets must be straight segments (2D: of triangles or quadrilaterals) or
        # triangles (3D: of tetrahedra; a hexahedron's quadrilateral facet is not one)
        simplex_facets = msh.topology.cell_type != mesh.CellType.hexahedron
        laws.check("mesh", msh.topology.cell_type.name,
                   simplex_facets and msh.geometry.cmap.degree == 1,
                   "mortar contact needs a mesh of straight (degree-1) triangles or "
                   "quadrilaterals (2D) or tetrahedra (3D)")
        if formulation is not None:
            enforcement = formulation
        laws.check("enforcement", enforcement, enforcement == "compliance",
                   "'compliance' (the perturbed Lagrangian is node-to-segment's only)")
        laws.check("penalty_T", penalty_T, penalty_T is None,
                   "None (node-to-segment's perturbed Lagrangian only)")
        for name, tag in (("slave", slave), ("master", master)):
            count = msh.comm.allreduce(int(np.count_nonzero(facet_tags.values == tag)))
            laws.check(name, tag, count > 0, "a facet tag present in facet_tags")
        laws.check("search", search, search in ("solve", "residual"), "'solve' or 'residual'")
        self.u, self.V, self.W = u, V, V
        self.dim, self.degree = dim, degree
        self.frozen = frozen
        self.search_every_residual = search == "residual"
        self.law, self.c_n, self.m_n, self.weight = law, law.c_n, law.m_n, weight
        self.search_pending = True
        self.searched = False
        self.pairing = MortarIntegrals(V, surface_facets(V, facet_tags, slave),
                                       surface_facets(V, facet_tags, master), exchange)
        self.mirrors: dict[fem.Function, fem.Function] = {
            f: fem.Function(V, name=f"mortar_{f.name}")
            for f in (u, *fields, *([] if step_from is None else [step_from]))}
        self.step_from = step_from
        self.ds = ufl.Measure("ds", domain=msh, subdomain_data=facet_tags, subdomain_id=slave,
                              metadata=_compat.nodal_quadrature(dim - 1, degree=degree))
        # the contact normal out of the master body, -n_j, as node-to-segment's: the force on
        # the slave side is p n + t_T with either formulation
        n = self.normal = -self.pairing.normal
        G = self.pairing.reference + self.mirrors[u]
        self.gap = ufl.dot(n, G)
        d = self.penetration = laws.penetration(-self.gap)
        w = None
        if velocity is not None:
            self._check_mirrored(velocity, fields)
            w = ufl.replace(velocity, {f: self.mirrors[f] for f in (u, *fields)})
            if transport is not None:
                w = w - ufl.as_vector(transport)
        self.relative_velocity = w
        laws.check("velocity", velocity, w is not None or not law.has_friction,
                   "friction (mu != 0) needs the slave velocity")
        force = self._force(d, n, w)
        self.F = None
        # the traction acts on the covered part of each test function's support only
        covered = self.pairing.coverage
        self.G = -weight * covered * ufl.inner(force, ufl.TestFunction(V)) * self.ds
        self.potential = (weight * covered * law.c_n * d ** (law.m_n + 1) / (law.m_n + 1)
                          * self.ds)
        dissipated = 0.0 * d
        if w is not None:
            dissipated = (self.pressure - self._elastic) * -ufl.dot(w, n)
            if self.traction is not None:
                dissipated = dissipated - ufl.dot(self.traction, w)
        self.dissipation = weight * covered * dissipated * self.ds

    def _force(self, d: typing.Any, n: typing.Any, w: typing.Any) -> typing.Any:
        """The force on the slave side at penetration ``d``, contact normal ``n`` (out of
        the master body) and relative velocity ``w`` (None: none): :math:`p n + t_T`, the
        approach rate :math:`\\dot d = -w\\cdot n`; sets ``pressure`` and ``traction``."""
        approach = -ufl.dot(w, n) if w is not None else 0.0
        self.pressure = self.law.normal_traction(d, approach)
        self._elastic = self.law.pressure(d)
        if self.step_from is not None:  # the step's elastic pressure: φ's discrete gradient
            start = self.mirrors[self.step_from]
            G = self.pairing.reference
            self._elastic = discrete_gradient(  # of the approaches -g = -n·G at both ends
                self.law, -ufl.dot(n, G + start),
                -ufl.dot(n, G + 2 * self.mirrors[self.u] - start))
            self.pressure = self.pressure - self.law.pressure(d) + self._elastic
        force = self.pressure * n
        self.traction = None
        if self.law.has_friction:
            w_T = w - ufl.dot(w, n) * n
            self.traction = self.law.friction_traction(d, w_T)
            force = force + self.traction
        return force

    @functools.cached_property
    def nodal_space(self) -> fem.FunctionSpace:
        """Scalar Lagrange functions of V's degree: one value per node."""
        return _compat.scalar_function_space(self.V.mesh, "Lagrange", self.degree)

    def frequency_bound(self, lumped_mass: PETSc.Vec) -> float:
        """An upper bound of the contact springs' frequency² on the lumped mass, for linear
        compliance (m_n = 1) and the current B: every slave node in contact, the stiffness
        :math:`B^T C B` with :math:`C = \\mathrm{diag}(w c_n A_j)` has
        :math:`\\lambda_{max} \\le \\|C^{1/2}B\\|_1 \\|C^{1/2}B\\|_\\infty`, over the lightest
        node of either surface."""
        laws.check("m_n", self.m_n, self.m_n == 1,
                   "a penetration-independent bound exists for m_n = 1 only")
        if self.pairing.Q is None:
            self.update()
        Q = self.pairing.Q
        assert Q is not None
        scaled = Q.copy()
        rows = scaled.createVecLeft()
        stiffness = self.weight * float(self.c_n) * np.repeat(self.nodal_weights, self.dim)
        rows.array[:] = np.sqrt(stiffness)
        scaled.diagonalScale(L=rows)
        bound = scaled.norm(PETSc.NormType.NORM_1) * scaled.norm(PETSc.NormType.NORM_INFINITY)
        scaled.destroy()
        masses = lumped_mass.array_r.reshape(-1, self.dim)
        surfaces = np.unique(np.concatenate([self.pairing.slave_local.ravel(),
                                             self.pairing.master_local.ravel()]))
        surfaces = surfaces[surfaces < len(masses)]
        lightest = self.V.mesh.comm.allreduce(float(masses[surfaces].min(initial=np.inf)),
                                              op=MPI.MIN)
        return float(bound) / lightest

    def commit(self) -> None:
        """Nothing to store between increments (the compliance law has no history)."""

    @property
    def configuration(self) -> list[fem.Function]:
        """What the mortar gaps, normals and friction bound are made of: u, its mirror
        :math:`B u`, the reference :math:`B X`, the slave nodes' normal and covered fraction
        (:class:`~fenicsfriction.coupling.FrictionBoundCoupling`)."""
        return [self.u, self.mirrors[self.u], self.pairing.reference, self.pairing.normal,
                self.pairing.coverage]



if typing.TYPE_CHECKING:  # mypy checks that the mortar contact is a Coupling
    from fenicsfriction.coupling import Coupling

    def _segment_to_segment_is_a_coupling(contact: SegmentToSegment) -> Coupling:
        return contact

    from fenicsfriction.coupling import FrictionBoundCoupling

    def _segment_to_segment_has_a_friction_bound(contact: SegmentToSegment
                                                 ) -> FrictionBoundCoupling:
        return contact
