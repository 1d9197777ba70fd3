"""Contact search: each slave node paired with its closest master facet, in parallel.

Each rank pairs its own slave nodes with a k-d tree of the centroids of the master facets it
holds (SciPy), checking the exact point-to-facet distance of the nearest few
(:data:`CANDIDATES`). A rank holds only the master facets near its slave nodes, not the whole
master surface: its slave nodes are split once into at most :data:`BOXES` groups (coordinate
bisection), and at each search every rank all-gathers the groups' bounding boxes at the current
configuration with each group's search radius, and the bounding box of its own master facets'
centroids (O(ranks) numbers). Two ranks whose boxes come within a radius of each other are
neighbours: each sends the other (point to point) the master facets whose centroids lie within
the radius of one of the other's boxes -- their global node indices, reference and current
coordinates. A slave node's candidates are exact when its radius covers them: the search
checks that every node's :data:`CANDIDATES`-th nearest centroid is closer than its group's
radius, and repeats the exchange with larger radii where it is not (each group's radius is
then kept for the next search, so one exchange is the rule). The candidates are the nearest
:data:`CANDIDATES` centroids, extended to all centroids as close as the last one, and among
them the closest facet wins, ties going to the facet whose reference centroid comes first in
(x, y, z) order: the choice depends on the geometry only, not on which facets a rank holds, so
the pairing is the same on any number of ranks and with the whole surface gathered
(``exchange="all"``, the reference the tests compare with).

The pairing is the sparse 0/1 operator ``Q`` that carries the displacements of the master
nodes of each slave node's facet to the slave node (rows: the node's ``dim * nodes_per_facet``
components in the space ``W``; columns: the master dofs of ``V``), a PETSc matrix whose
columns may belong to any rank.

Cost per search: the boxes' all-gather (O(ranks)), the neighbours' facets near each rank's
slave nodes, one k-d tree build over them (O(m log m)) and O(s log m) queries for s slave
nodes, against the O(n) assembly of the bulk.
"""

from __future__ import annotations

import dataclasses
import time
import typing

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
from dolfinx import fem, mesh
from scipy.spatial import cKDTree

from fenicsfriction import _compat, laws

__all__ = ["EXCHANGES", "FacetExchange", "Pairing", "facet_nodes", "point_facet_distance",
           "surface_coordinates"]

#: how many master facets (by centroid distance) are checked exactly for each slave node
CANDIDATES = 12

#: at most this many groups of slave nodes per rank, each with its bounding box
BOXES = 64

#: the ways a rank obtains the master facets: from its neighbours, near its slave nodes, or
#: all of them from every rank (the reference)
EXCHANGES = ("neighbours", "all")

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
class _Facets:
    """Master facets held by one rank: global node indices and coordinates, per facet."""

    global_nodes: np.ndarray  # (m, nen) int64
    reference: np.ndarray  # (m, nen, dim)
    current: np.ndarray  # (m, nen, dim)

    @classmethod
    def join(cls, pieces: list[_Facets], nen: int, dim: int) -> _Facets:
        """The pieces in order, each facet once (the first copy: a facet on a process boundary
        may come from two ranks)."""
        g = np.concatenate([p.global_nodes for p in pieces]).reshape(-1, nen).astype(np.int64)
        ref = np.concatenate([p.reference for p in pieces]).reshape(-1, nen, dim)
        cur = np.concatenate([p.current for p in pieces]).reshape(-1, nen, dim)
        _, first = np.unique(np.sort(g, axis=1), axis=0, return_index=True)
        first = np.sort(first)
        return cls(g[first], ref[first], cur[first])

    def take(self, rows: np.ndarray) -> _Facets:
        return _Facets(self.global_nodes[rows], self.reference[rows], self.current[rows])


def _canonical(nodes: np.ndarray) -> np.ndarray:
    """Each triangle's nodes rotated (keeping their cyclic order, hence the normal) so that the
    smallest global index comes first: two ranks' copies of a facet then agree to the bit.
    Segments are left as they are (their order is their orientation)."""
    if nodes.shape[1] != 3 or not len(nodes):
        return np.arange(nodes.size).reshape(nodes.shape) % nodes.shape[1]
    shift = np.argmin(nodes, axis=1)
    return (shift[:, None] + np.arange(3)) % 3


def _groups(x: np.ndarray, count: int) -> np.ndarray:
    """The group of each point: recursive coordinate bisection (at the median of the longest
    side) into at most ``count`` groups of nearly equal size."""
    group = np.zeros(len(x), dtype=np.int64)
    todo: list[np.ndarray] = [np.arange(len(x))]
    parts: list[np.ndarray] = []
    while todo:
        rows = todo.pop()
        if len(todo) + len(parts) + 2 > count or len(rows) < 2:
            parts.append(rows)
            continue
        axis = int(np.argmax(np.ptp(x[rows], axis=0)))
        order = rows[np.argsort(x[rows, axis], kind="stable")]
        half = len(order) // 2
        todo += [order[:half], order[half:]]
    for g, rows in enumerate(parts):
        group[rows] = g
    return group


def _box_distance(points: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """The distance of each point to the box [lower, upper] (0 inside)."""
    return np.linalg.norm(np.maximum(np.maximum(lower - points, points - upper), 0.0), axis=-1)


def _near_boxes(tree: cKDTree | None, points: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """Whether each point is within the radius of any of ``boxes`` (b, 3, dim): lower corner,
    upper corner and the radius (in every column). ``tree``: a k-d tree of ``points``, whose
    balls around the boxes' centres pick the points to check exactly."""
    near = np.zeros(len(points), dtype=bool)
    if tree is None or not len(boxes):
        return near
    centre = (boxes[:, 0] + boxes[:, 1]) / 2
    reach = np.linalg.norm(boxes[:, 1] - boxes[:, 0], axis=1) / 2 + boxes[:, 2, 0]
    for (lower, upper, radius), ball in zip(boxes, tree.query_ball_point(centre, reach * 1.01),
                                            strict=True):
        rows = np.asarray(ball, dtype=np.int64)
        near[rows[_box_distance(points[rows], lower, upper) <= radius[0]]] = True
    return near


def _boxes_meet(a: np.ndarray, boxes: np.ndarray) -> bool:
    """Whether box ``a`` (2, dim) comes within the radius of any of ``boxes`` (b, 3, dim)."""
    if not len(boxes):
        return False
    gap = np.maximum(np.maximum(boxes[:, 0] - a[1], a[0] - boxes[:, 1]), 0.0)
    return bool(np.any(np.linalg.norm(gap, axis=1) <= boxes[:, 2, 0]))


class FacetExchange:
    """How a rank obtains the facets of a surface near its own points from the other ranks,
    without a global gather (the pairing's and the mortar search's exchange).

    The points are split once into at most :data:`BOXES` groups (coordinate bisection of
    ``points``, their reference positions). At each :meth:`hold` every rank all-gathers its
    groups' bounding boxes with each group's radius and the bounding box of its own facets'
    centroids (O(ranks) numbers); two ranks whose boxes come within a radius are neighbours
    and send each other, point to point, the facets whose centroids lie within a radius of one
    of the other's boxes. The caller states for each point the distance its search needs; where
    a group's radius falls short, its radius is set to 1.1 times the need and the exchange
    repeats (the radii are kept for the next call).

    Attributes:
        radius: each group's radius (set the first one before the first :meth:`hold`).
        rounds: how many exchanges the last :meth:`hold` needed.
        seconds: the time spent exchanging (boxes, sends, receives), summed over calls.
    """

    def __init__(self, comm: MPI.Comm, points: np.ndarray, nodes_per_facet: int):
        self.comm = comm
        self.dim = points.shape[1]
        self.nodes_per_facet = nodes_per_facet
        self.group = _groups(points, BOXES)
        self.radius = np.zeros(int(self.group.max(initial=-1)) + 1)
        self.rounds = 0
        self.seconds = 0.0

    def hold(self, local: _Facets, x: np.ndarray,
             need: typing.Callable[[_Facets], tuple[np.ndarray, typing.Any]]
             ) -> tuple[_Facets, typing.Any]:
        """The facets near the points ``x`` (the current positions of ``points``), from all
        ranks' ``local`` facets: repeated until every point's need (the first item of
        ``need(held)``: a distance, inf where the facets held cannot tell) is within its
        group's radius, or the whole surface is held. Returns the facets held and the second
        item of ``need(held)``."""
        self.rounds = 0
        while True:
            self.rounds += 1
            t0 = time.perf_counter()
            held, complete = self._neighbour_facets(local, x)
            self.seconds += time.perf_counter() - t0
            reach, result = need(held)
            ok = complete or bool(np.all(reach * (1 + 1e-9) < self.radius[self.group]))
            if self.comm.allreduce(ok, op=MPI.LAND):
                return held, result
            # each group's radius: beyond its farthest need among the facets held now (that
            # among all facets is no farther), or four times larger if too few were held
            for g in range(len(self.radius)):
                far = reach[self.group == g].max(initial=0.0)
                self.radius[g] = 4 * self.radius[g] if not np.isfinite(far) else max(
                    self.radius[g], 1.1 * far)

    def _boxes(self, x: np.ndarray) -> np.ndarray:
        """The groups' bounding boxes at ``x`` with their radii (g, 3, dim): lower and upper
        corners, the radius repeated (empty groups: none)."""
        boxes = []
        for g, radius in enumerate(self.radius):
            y = x[self.group == g]
            if len(y):
                boxes.append([y.min(axis=0), y.max(axis=0), np.full(self.dim, radius)])
        return np.array(boxes, dtype=float).reshape(-1, 3, self.dim)

    def _neighbour_facets(self, local: _Facets, x: np.ndarray) -> tuple[_Facets, bool]:
        """The master facets of every rank whose centroids lie within the radius of one of
        this rank's boxes, and whether those hold the whole master surface (the candidates are
        then complete whatever the radii)."""
        centroid = local.current.mean(axis=1)
        mine = np.array([centroid.min(axis=0), centroid.max(axis=0)]) if len(centroid) else \
            np.full((2, self.dim), np.nan)
        boxes = self._boxes(x)
        everyone = self.comm.allgather((mine, boxes))
        masters = np.array([m for m, _ in everyone])
        present = np.all(np.isfinite(masters[:, 0]), axis=1)
        whole = (np.array([np.nanmin(masters[present, 0], axis=0),
                           np.nanmax(masters[present, 1], axis=0)])
                 if present.any() else np.zeros((2, self.dim)))
        # the farthest corner of the whole surface's box within some box's radius
        corners = np.array([[whole[i, k] for k, i in enumerate(bits)]
                            for bits in np.ndindex(*(2,) * self.dim)])
        complete = bool(any(np.all(_box_distance(corners, b[0], b[1]) <= b[2, 0])
                            for b in boxes))
        rank = self.comm.rank
        tree = cKDTree(centroid) if len(centroid) else None
        requests = []
        for q, (_, their_boxes) in enumerate(everyone):
            if q != rank and present[rank] and _boxes_meet(mine, their_boxes):
                rows = np.flatnonzero(_near_boxes(tree, centroid, their_boxes))
                requests.append(self.comm.isend(local.take(rows), dest=q, tag=7026))
        pieces: list[_Facets] = []
        for q, (theirs, _) in enumerate(everyone):
            if q == rank:
                pieces.append(local.take(np.flatnonzero(_near_boxes(tree, centroid, boxes))))
            elif present[q] and _boxes_meet(theirs, boxes):
                pieces.append(self.comm.recv(source=q, tag=7026))
        MPI.Request.waitall(requests)
        return _Facets.join(pieces, self.nodes_per_facet, self.dim), complete


class Pairing:
    """Slave nodes of one surface paired with the facets of another, and the operator Q.

    Args:
        V: the displacement space (degree-1 Lagrange vectors) of the mesh holding both bodies.
        W: vectors of ``dim * nodes_per_facet`` components on the same mesh and nodes, where
            the master facet's nodal quantities are stored at each slave node.
        slave_nodes: the local indices of the slave nodes this rank pairs (owned ones).
        master_facets: (facets, nodes per facet) local node indices of this rank's master
            facets, ordered outward (:func:`facet_nodes`).
        exchange: ``"neighbours"`` (default): each rank receives from its neighbours the master
            facets near its slave nodes; ``"all"``: the whole master surface is all-gathered
            on every rank (the reference: same pairing, memory O(master facets) per rank).

    Attributes:
        Q: the pairing operator, a PETSc matrix W x V (``None`` before :meth:`search`).
        facet_global_nodes: for each slave node, the global node indices of its master facet
            (-1 before :meth:`search`).
        reference: a Function of W: the reference coordinates of each slave node's master
            nodes (the current ones are these plus ``Q u``).
        held: how many master facets this rank held at the last search.
        rounds: how many exchanges the last search needed (1 unless a radius grew).
        searches, changes: how many searches ran, how many changed the pairing.
        time_s: seconds spent in ``"search"`` (exchange, k-d tree, distances) and ``"build"``
            (the operator Q), summed over calls; ``"exchange"`` is the part of ``"search"``
            spent obtaining the master facets (boxes, sends, receives).
    """

    def __init__(self, V: fem.FunctionSpace, W: fem.FunctionSpace, slave_nodes: np.ndarray,
                 master_facets: np.ndarray, exchange: str = "neighbours"):
        laws.check("exchange", exchange, exchange in EXCHANGES, f"one of {', '.join(EXCHANGES)}")
        self.V, self.W = V, W
        self.exchange = exchange
        self.comm: MPI.Comm = V.mesh.comm
        self.dim = V.mesh.geometry.dim
        self.nodes_per_facet = master_facets.shape[1] if master_facets.ndim == 2 else self.dim
        self.slave_nodes = np.asarray(slave_nodes, dtype=np.int32)
        nodes = master_facets.reshape(-1, self.nodes_per_facet)
        global_nodes = V.dofmap.index_map.local_to_global(nodes.ravel()).reshape(nodes.shape)
        rotate = _canonical(global_nodes)
        rows = np.arange(len(nodes))[:, None]
        self.master_facets = nodes[rows, rotate]
        self._master_global = global_nodes[rows, rotate].astype(np.int64)
        self.x_nodes = V.tabulate_dof_coordinates()[:, :self.dim]
        self.Q: PETSc.Mat | None = None
        self.facet_global_nodes = np.full((len(self.slave_nodes), self.nodes_per_facet), -1,
                                          dtype=np.int64)
        self._facet_reference = np.zeros((len(self.slave_nodes), self.nodes_per_facet,
                                          self.dim))
        self.reference = fem.Function(W, name="master_reference")
        self.held = 0
        self.rounds = 0
        self.searches = 0
        self.changes = 0
        self.time_s = {"search": 0.0, "build": 0.0, "exchange": 0.0}
        self._exchange = FacetExchange(self.comm, self.x_nodes[self.slave_nodes],
                                       self.nodes_per_facet)

    # --- the master facets a rank holds ----------------------------------------------------

    def _local_facets(self, u: fem.Function) -> _Facets:
        reference = self.x_nodes[self.master_facets]
        displacement = u.x.array.reshape(-1, self.dim)[self.master_facets]
        return _Facets(self._master_global, reference, reference + displacement)

    def gather(self, u: fem.Function) -> _Facets:
        """The whole master surface at displacement ``u``, on every rank (an all-gather)."""
        pieces = self.comm.allgather(self._local_facets(u))
        return _Facets.join(pieces, self.nodes_per_facet, self.dim)

    # --- the search ------------------------------------------------------------------------

    def search(self, u: fem.Function) -> bool:
        """Pair every slave node with its closest master facet at displacement ``u``.

        Returns True if the pairing changed (``Q`` and ``reference`` are then rebuilt).
        """
        t0 = time.perf_counter()
        self.searches += 1
        d = self.dim
        x_slave = self.x_nodes[self.slave_nodes] + u.x.array.reshape(-1, d)[self.slave_nodes]
        local = self._local_facets(u)
        count = self.comm.allreduce(len(local.global_nodes))
        if count == 0:
            raise RuntimeError("contact search: the master surface has no facets on any rank")
        if self.searches == 1:
            self._exchange.radius[:] = self._first_radius()
        if self.exchange == "all":
            te = time.perf_counter()
            held = self.gather(u)
            self.time_s["exchange"] += time.perf_counter() - te
            candidates = _candidates(held, x_slave)[0]
            self.rounds = 1
        else:
            spent = self._exchange.seconds
            held, candidates = self._exchange.hold(
                local, x_slave, lambda held: _candidates(held, x_slave)[::-1])
            self.time_s["exchange"] += self._exchange.seconds - spent
            self.rounds = self._exchange.rounds
        self.held = len(held.global_nodes)
        nodes, reference = self._closest(held, x_slave, candidates)
        if self.Q is not None:
            nodes, reference = self._keep_ties(u, x_slave, nodes, reference)
        changed = self.Q is None or not np.array_equal(nodes, self.facet_global_nodes)
        changed = bool(self.comm.allreduce(changed, op=MPI.LOR))
        self.facet_global_nodes, self._facet_reference = nodes, reference
        t1 = time.perf_counter()
        self.time_s["search"] += t1 - t0
        if changed:
            self.changes += 1
            self._build()
            self.time_s["build"] += time.perf_counter() - t1
        return changed

    def _first_radius(self) -> float:
        """The radius of the first exchange: the largest master facet's size (all ranks)."""
        x = self.x_nodes[self.master_facets]
        size = float(np.ptp(x, axis=1).max(initial=0.0)) if len(x) else 0.0
        return self.comm.allreduce(size, op=MPI.MAX) or 1.0

    def _closest(self, held: _Facets, x_slave: np.ndarray, candidates: list[np.ndarray]
                 ) -> tuple[np.ndarray, np.ndarray]:
        """Each slave node's closest candidate facet: its global nodes and reference
        coordinates."""
        facet = np.zeros(len(x_slave), dtype=np.int64)
        for rows in _same_length(candidates):
            c = np.array([candidates[i] for i in rows]).reshape(len(rows), -1)
            distance = point_facet_distance(x_slave[rows, None, :], held.current[c])
            best = _closest_by_geometry(distance, held.reference[c].mean(axis=2))
            facet[rows] = c[np.arange(len(rows)), best]
        return held.global_nodes[facet], held.reference[facet]

    def facet_coordinates(self, u: fem.Function) -> np.ndarray:
        """The current coordinates (s, nodes per facet, dim) of each slave node's master facet
        at displacement ``u``: their reference ones plus ``Q u`` (no master facet needs to be
        held). Needs a search first."""
        if self.Q is None:
            raise RuntimeError("Pairing.facet_coordinates: no search has run yet")
        moved = self.Q.createVecLeft()
        self.Q.mult(_compat.petsc_vec(u), moved)
        shape = self._facet_reference.shape
        x = self._facet_reference + moved.array.reshape(-1, *shape[1:])[self.slave_nodes]
        moved.destroy()
        return x

    def _keep_ties(self, u: fem.Function, x_slave: np.ndarray, nodes: np.ndarray,
                   reference: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Keep a slave node's facet while its projection stays on it (surface coordinates in
        the facet, to :data:`KEEP_TOLERANCE`): a node over a master edge or vertex is about as
        close to every facet there, and switching between them at each residual evaluation
        would stall Newton on the kink of the master surface."""
        last = self.facet_coordinates(u)
        keep = np.all(surface_coordinates(x_slave, last) >= -KEEP_TOLERANCE, axis=1)
        return (np.where(keep[:, None], self.facet_global_nodes, nodes),
                np.where(keep[:, None, None], self._facet_reference, reference))

    def _build(self) -> None:
        """Q and the master reference coordinates for the current pairing."""
        d, nen = self.dim, self.nodes_per_facet
        bs_w = d * nen
        reference = self.reference.x.array.reshape(-1, bs_w)
        reference[:] = 0.0
        reference[self.slave_nodes] = self._facet_reference.reshape(-1, bs_w)
        self.reference.x.scatter_forward()
        w_map, v_map = self.W.dofmap.index_map, self.V.dofmap.index_map
        # one entry per row of a slave node's components, none elsewhere: CSR of the local rows
        rows = (self.slave_nodes.astype(np.int64)[:, None] * bs_w + np.arange(bs_w)).ravel()
        cols = (self.facet_global_nodes[:, :, None] * d + np.arange(d)).ravel()
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


def _candidates(held: _Facets, x: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
    """Each point's candidate facets among those held: the :data:`CANDIDATES` nearest
    centroids, and every other centroid as close as the last of them (so that the set does
    not depend on the k-d tree's order among equal distances); and that last distance (inf
    when fewer facets are held than the candidates need: more must be fetched, unless these
    are all)."""
    m = len(held.global_nodes)
    if not len(x):
        return [], np.zeros(0)
    if m == 0:
        return [np.zeros(0, dtype=np.int64)] * len(x), np.full(len(x), np.inf)
    tree = cKDTree(held.current.mean(axis=1))
    k = min(CANDIDATES, m)
    distance, index = tree.query(x, k=min(k + 1, m))
    distance, index = distance.reshape(len(x), -1), index.reshape(len(x), -1)
    reach = distance[:, k - 1].copy()
    rows: list[np.ndarray] = list(index[:, :k])
    if m > k:
        tied = np.flatnonzero(distance[:, k] <= reach * (1 + 1e-12))
        for i in tied:
            ball = np.asarray(tree.query_ball_point(x[i], r=reach[i] * (1 + 1e-12)))
            rows[i] = np.sort(ball).astype(np.int64)
    else:
        reach[:] = np.inf  # all held facets are candidates: complete only if they are all
    return rows, reach


def _same_length(rows: list[np.ndarray]) -> list[np.ndarray]:
    """The indices of ``rows`` grouped by their lengths (one group when none is tied)."""
    lengths = np.fromiter((len(r) for r in rows), dtype=np.int64, count=len(rows))
    return [np.flatnonzero(lengths == n) for n in np.unique(lengths)]
