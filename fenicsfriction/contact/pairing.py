"""Contact search: each slave node paired with its closest master facet, in parallel.

The master surface is gathered on every rank (its facets' global node indices and reference
coordinates once, their nodes' displacements at each search), so a slave node and its master
facet may live on different ranks; each rank then pairs its own slave nodes with a k-d tree of
the master facets' centroids (SciPy), checking the exact point-to-facet distance of the nearest
few. The pairing is the sparse 0/1 operator ``Q`` that carries the displacements of the master
nodes of each slave node's facet to the slave node (rows: the node's ``dim * nodes_per_facet``
components in the space ``W``; columns: the master dofs of ``V``), a PETSc matrix whose
columns may belong to any rank.

Cost per search: an all-gather of the master facets' displacements (O(master facets)), one
k-d tree build (O(m log m)) and O(s log m) queries for s slave nodes, against the O(n)
assembly of the bulk.
"""

from __future__ import annotations

import dataclasses
import functools
import time

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
from dolfinx import fem, mesh
from scipy.spatial import cKDTree

__all__ = ["Pairing", "facet_nodes", "point_facet_distance", "surface_coordinates"]

#: how many master facets (by centroid distance) are checked exactly for each slave node
CANDIDATES = 12

#: a slave node keeps its facet while its projection's shape functions are all >= -this
KEEP_TOLERANCE = 1e-2


def facet_nodes(V: fem.FunctionSpace, facet_tags: mesh.MeshTags, tag: int,
                outward: bool = True) -> np.ndarray:
    """The local node indices of the vertices of the facets tagged ``tag``, one row per facet.

    With ``outward`` the nodes of each row are ordered so that the normal of
    :func:`fenicsfriction.contact.kinematics.project` points out of the body the facet bounds.
    ``V`` must be a degree-1 Lagrange space.
    """
    msh = V.mesh
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    msh.topology.create_connectivity(tdim, tdim - 1)
    f_to_c = msh.topology.connectivity(tdim - 1, tdim)
    c_to_f = msh.topology.connectivity(tdim, tdim - 1)
    layout = V.dofmap.dof_layout
    x = V.tabulate_dof_coordinates()[:, :tdim]
    facets = facet_tags.indices[facet_tags.values == tag]
    rows = np.empty((len(facets), tdim), dtype=np.int32)
    for i, facet in enumerate(facets):
        cell = f_to_c.links(facet)[0]
        local = int(np.flatnonzero(c_to_f.links(cell) == facet)[0])
        cell_nodes = V.dofmap.cell_dofs(cell)
        nodes = cell_nodes[layout.entity_closure_dofs(tdim - 1, local)]
        if outward:
            inside = x[cell_nodes].mean(axis=0)
            if np.dot(_normal(x[nodes]), x[nodes].mean(axis=0) - inside) < 0:
                nodes = nodes[[0, 2, 1]] if tdim == 3 else nodes[::-1]
        rows[i] = nodes
    return rows


def _normal(x: np.ndarray) -> np.ndarray:
    """Unnormalised normal of the facet(s) through ``x[..., a, :]`` (kinematics' convention)."""
    t = x[..., 1, :] - x[..., 0, :]
    if x.shape[-2] == 2:
        return np.stack([-t[..., 1], t[..., 0]], axis=-1)
    return np.cross(t, x[..., 2, :] - x[..., 0, :])


def _closest_by_geometry(distance: np.ndarray, centroids: np.ndarray) -> np.ndarray:
    """The column of the smallest distance in each row; among facets as close to round-off
    (a node over an edge or a vertex), the one whose reference centroid comes first in
    (x, y, z) order, so that the choice does not depend on how the mesh is partitioned."""
    best = np.argmin(distance, axis=1)
    rows = np.arange(len(distance))
    tied = distance <= distance[rows, best][:, None] * (1 + 1e-9) + 1e-14
    for row in np.flatnonzero(tied.sum(axis=1) > 1):
        columns = np.flatnonzero(tied[row])
        order = np.lexsort(centroids[row, columns].T[::-1])
        best[row] = columns[order[0]]
    return best


def point_facet_distance(p: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Distance of points ``p[..., :]`` to the closed segments/triangles ``x[..., a, :]``."""
    if x.shape[-2] == 2:
        return _point_segment_distance(p, x[..., 0, :], x[..., 1, :])
    x1, x2, x3 = x[..., 0, :], x[..., 1, :], x[..., 2, :]
    shape = surface_coordinates(p, x)
    inside = np.all(shape >= 0, axis=-1)
    plane = np.linalg.norm(p - np.einsum("...a,...ak->...k", shape, x), axis=-1)
    edges = np.minimum(np.minimum(_point_segment_distance(p, x1, x2),
                                  _point_segment_distance(p, x2, x3)),
                       _point_segment_distance(p, x3, x1))
    return np.where(inside, plane, edges)


def surface_coordinates(p: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The shape functions N_a(ξ) of the projections of points ``p[..., :]`` on the lines or
    planes of the facets ``x[..., a, :]`` (all in [0, 1] when the projection is on the facet)."""
    x1 = x[..., 0, :]
    r, t = p - x1, x[..., 1:, :] - x1[..., None, :]
    metric = np.einsum("...ak,...bk->...ab", t, t)
    xi = np.linalg.solve(metric, np.einsum("...ak,...k->...a", t, r)[..., None])[..., 0]
    return np.concatenate([1 - xi.sum(axis=-1, keepdims=True), xi], axis=-1)


def _point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    t = b - a
    s = np.clip(((p - a) * t).sum(-1) / (t * t).sum(-1), 0.0, 1.0)
    return np.linalg.norm(p - a - s[..., None] * t, axis=-1)


@dataclasses.dataclass
class _MasterSurface:
    """The master facets of all ranks: global node indices and coordinates, per facet."""

    global_nodes: np.ndarray  # (m, nen) int64
    reference: np.ndarray  # (m, nen, dim)
    current: np.ndarray  # (m, nen, dim)


class Pairing:
    """Slave nodes of one surface paired with the facets of another, and the operator Q.

    Args:
        V: the displacement space (degree-1 Lagrange vectors) of the mesh holding both bodies.
        W: vectors of ``dim * nodes_per_facet`` components on the same mesh and nodes, where
            the master facet's nodal quantities are stored at each slave node.
        slave_nodes: the local indices of the slave nodes this rank pairs (owned ones).
        master_facets: (facets, nodes per facet) local node indices of this rank's master
            facets, ordered outward (:func:`facet_nodes`).

    Attributes:
        Q: the pairing operator, a PETSc matrix W x V (``None`` before :meth:`search`).
        facet: for each slave node, the index of its master facet in the gathered surface.
        reference: a Function of W: the reference coordinates of each slave node's master
            nodes (the current ones are these plus ``Q u``).
        searches, changes: how many searches ran, how many changed the pairing.
        time_s: seconds spent in ``"search"`` (gather, k-d tree, distances) and ``"build"``
            (the operator Q), summed over calls.
    """

    def __init__(self, V: fem.FunctionSpace, W: fem.FunctionSpace, slave_nodes: np.ndarray,
                 master_facets: np.ndarray):
        self.V, self.W = V, W
        self.comm: MPI.Comm = V.mesh.comm
        self.dim = V.mesh.geometry.dim
        self.nodes_per_facet = master_facets.shape[1] if master_facets.ndim == 2 else self.dim
        self.slave_nodes = np.asarray(slave_nodes, dtype=np.int32)
        self.master_facets = master_facets.reshape(-1, self.nodes_per_facet)
        self.x_nodes = V.tabulate_dof_coordinates()[:, :self.dim]
        self.Q: PETSc.Mat | None = None
        self.facet = np.full(len(self.slave_nodes), -1, dtype=np.int64)
        self.reference = fem.Function(W, name="master_reference")
        self.searches = 0
        self.changes = 0
        self.time_s = {"search": 0.0, "build": 0.0}
        self._surface: _MasterSurface | None = None

    @functools.cached_property
    def _fixed(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """What of the master surface never changes, gathered from every rank once: the
        facets' global node indices and reference coordinates, and which rows of the gathered
        pieces to keep (a facet on a process boundary may be listed by two ranks)."""
        d, nen = self.dim, self.nodes_per_facet
        nodes = self.master_facets
        global_nodes = self.V.dofmap.index_map.local_to_global(nodes.ravel()).reshape(nodes.shape)
        pieces = self.comm.allgather((global_nodes.astype(np.int64), self.x_nodes[nodes]))
        g = np.concatenate([p[0] for p in pieces]).reshape(-1, nen)
        ref = np.concatenate([p[1] for p in pieces]).reshape(-1, nen, d)
        _, first = np.unique(np.sort(g, axis=1), axis=0, return_index=True)
        first = np.sort(first)
        return g[first], ref[first], first

    def gather(self, u: fem.Function) -> _MasterSurface:
        """The master surface of every rank at displacement ``u``: an all-gather of the
        facets' nodal displacements, in the same order at every search."""
        global_nodes, reference, first = self._fixed
        displacement = u.x.array.reshape(-1, self.dim)[self.master_facets]
        pieces = self.comm.allgather(displacement)
        moved = np.concatenate(pieces).reshape(-1, self.nodes_per_facet, self.dim)[first]
        return _MasterSurface(global_nodes, reference, reference + moved)

    def search(self, u: fem.Function) -> bool:
        """Pair every slave node with its closest master facet at displacement ``u``.

        Returns True if the pairing changed (``Q`` and ``reference`` are then rebuilt).
        """
        t0 = time.perf_counter()
        surface = self.gather(u)
        self.searches += 1
        d = self.dim
        x_slave = self.x_nodes[self.slave_nodes] + u.x.array.reshape(-1, d)[self.slave_nodes]
        facet = np.zeros(len(self.slave_nodes), dtype=np.int64)
        m = len(surface.global_nodes)
        if m == 0:
            raise RuntimeError("contact search: the master surface has no facets on any rank")
        if len(x_slave):
            k = min(CANDIDATES, m)
            _, candidates = cKDTree(surface.current.mean(axis=1)).query(x_slave, k=k)
            candidates = candidates.reshape(len(x_slave), k)
            distance = point_facet_distance(x_slave[:, None, :], surface.current[candidates])
            best = _closest_by_geometry(distance, surface.reference[candidates].mean(axis=2))
            facet = candidates[np.arange(len(x_slave)), best]
            if self.Q is not None:
                facet = self._keep_ties(facet, x_slave, surface)
        changed = self.Q is None or not np.array_equal(facet, self.facet)
        self._surface = surface
        changed = bool(self.comm.allreduce(changed, op=MPI.LOR))
        self.facet = facet
        t1 = time.perf_counter()
        self.time_s["search"] += t1 - t0
        if changed:
            self.changes += 1
            self._build(surface)
            self.time_s["build"] += time.perf_counter() - t1
        return changed

    def _keep_ties(self, facet: np.ndarray, x_slave: np.ndarray,
                   surface: _MasterSurface) -> np.ndarray:
        """Keep a slave node's facet while its projection stays on it (surface coordinates in
        the facet, to :data:`KEEP_TOLERANCE`): a node over a master edge or vertex is about as
        close to every facet there, and switching between them at each residual evaluation
        would stall Newton on the kink of the master surface. (The gathered surface keeps its
        order, so the last search's facet indices still name the same facets.)"""
        shape = surface_coordinates(x_slave, surface.current[self.facet])
        return np.where(np.all(shape >= -KEEP_TOLERANCE, axis=1), self.facet, facet)

    def _build(self, surface: _MasterSurface) -> None:
        """Q and the master reference coordinates for the current ``facet``."""
        d, nen = self.dim, self.nodes_per_facet
        bs_w = d * nen
        reference = self.reference.x.array.reshape(-1, bs_w)
        reference[:] = 0.0
        reference[self.slave_nodes] = surface.reference[self.facet].reshape(-1, bs_w)
        self.reference.x.scatter_forward()
        w_map, v_map = self.W.dofmap.index_map, self.V.dofmap.index_map
        # one entry per row of a slave node's components, none elsewhere: CSR of the local rows
        rows = (self.slave_nodes.astype(np.int64)[:, None] * bs_w + np.arange(bs_w)).ravel()
        cols = (surface.global_nodes[self.facet][:, :, None] * d + np.arange(d)).ravel()
        order = np.argsort(rows)
        counts = np.zeros(w_map.size_local * bs_w, dtype=np.int32)
        counts[rows] = 1
        indptr = np.concatenate([[0], np.cumsum(counts)]).astype(PETSc.IntType)
        if self.Q is not None:
            self.Q.destroy()
        Q = PETSc.Mat().createAIJ(
            ((w_map.size_local * bs_w, w_map.size_global * bs_w),
             (v_map.size_local * d, v_map.size_global * d)),
            csr=(indptr, cols[order].astype(PETSc.IntType), np.ones(len(rows))),
            comm=self.comm)
        self.Q = Q
