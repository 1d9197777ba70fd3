"""Every dolfinx-version difference the package depends on, in one place.

Written against dolfinx 0.5.2 (Debian 12). Differences are detected with
``hasattr``/``try`` rather than by parsing version strings, following scifem's
``compat.py``; a port to 0.9/0.10 should only touch this module. Renamed keyword
arguments (``scale``/``alpha``, ``diagonal``/``diag``) are passed positionally.
"""

from __future__ import annotations

import functools
import inspect
import logging
import math
import typing
import warnings

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem.petsc
import numpy as np
import ufl
from dolfinx import fem, geometry, mesh

__all__ = [
    "assemble_matrix_into",
    "cell_dofs",
    "colliding_cells",
    "create_box",
    "create_mesh_from_arrays",
    "create_simplex_mesh",
    "evaluate_expression",
    "create_rectangle",
    "dg0_vector_space",
    "element_degree",
    "interpolation_points",
    "jit_options",
    "key_partitioner",
    "lagrange_vector_space",
    "model_cell_centroids",
    "model_to_mesh",
    "nodal_quadrature",
    "petsc_vec",
    "read_msh",
    "scalar_function_space",
    "vector_function_space",
    "write_meshtags",
]


def vector_function_space(msh: mesh.Mesh, degree: int) -> fem.FunctionSpace:
    """Lagrange vector space of the given degree with ``gdim`` components."""
    if hasattr(fem, "functionspace"):  # dolfinx >= 0.8
        return fem.functionspace(msh, ("Lagrange", degree, (msh.geometry.dim,)))
    return fem.VectorFunctionSpace(msh, ("Lagrange", degree))


def scalar_function_space(msh: mesh.Mesh, family: str, degree: int) -> fem.FunctionSpace:
    """Scalar space (``family`` is e.g. ``"Lagrange"`` or ``"DG"``)."""
    if hasattr(fem, "functionspace"):
        return fem.functionspace(msh, (family, degree))
    return fem.FunctionSpace(msh, (family, degree))


def dg0_vector_space(msh: mesh.Mesh, components: int) -> fem.FunctionSpace:
    """Cellwise constant vectors with ``components`` entries (one value per cell and entry)."""
    if hasattr(fem, "functionspace"):
        return fem.functionspace(msh, ("DG", 0, (components,)))
    return fem.VectorFunctionSpace(msh, ("DG", 0), dim=components)


def lagrange_vector_space(msh: mesh.Mesh, degree: int, components: int) -> fem.FunctionSpace:
    """Lagrange vectors with ``components`` entries (any number, not only ``gdim``)."""
    if hasattr(fem, "functionspace"):
        return fem.functionspace(msh, ("Lagrange", degree, (components,)))
    return fem.VectorFunctionSpace(msh, ("Lagrange", degree), dim=components)


class _QuietArrayMetadata(logging.Filter):
    """UFL warns that it stringifies array-valued metadata for the form's signature; the
    nodal rule's points are a few exact small numbers, for which ``str`` is exact."""

    def filter(self, record: logging.LogRecord) -> bool:
        return "metadata value of type ndarray" not in record.getMessage()


_QUIET_ARRAY_METADATA = _QuietArrayMetadata()


def nodal_quadrature(facet_dim: int, simplex: bool = True, degree: int = 1) -> dict:
    """Integral metadata of the nodal (trapezoidal) rule on facets: the facet's vertices with
    equal weights. FFCx's ``"vertex"`` rule is for cell integrals only, so the points are given
    as a ``"custom"`` rule on the reference facet (an interval or a triangle; with
    ``simplex=False`` in 3D, the unit square of a hexahedron's facet).

    ``degree=2`` (simplices): the nodes of the quadratic facet, vertices and edge midpoints,
    each weighted by the integral of its P1 hat on the facet split at the midpoints (an
    interval into two, a triangle into four): 1/4, 1/4, 1/2 of the length; 1/12 of the area
    per vertex, 1/4 per midpoint. Every weight is positive (the quadratic vertex functions
    integrate to zero on a triangle), and the rule integrates each node's quadratic basis
    function to that weight, its value at the other nodes being 0."""
    # UFL 2022 logs the notice, UFL 2024 warns it; neither call adds a filter twice
    logging.getLogger("UFL").addFilter(_QUIET_ARRAY_METADATA)
    warnings.filterwarnings("ignore", message=".*metadata value of type ndarray")
    if degree == 2 and simplex:
        vertices = np.vstack([np.zeros(facet_dim), np.eye(facet_dim)])
        pairs = [(0, 1)] if facet_dim == 1 else [(0, 1), (1, 2), (2, 0)]
        middles = np.array([(vertices[a] + vertices[b]) / 2 for a, b in pairs])
        volume = 1.0 / math.factorial(facet_dim)
        shares = (0.25, 0.5) if facet_dim == 1 else (1 / 12, 0.25)
        return {"quadrature_rule": "custom", "quadrature_degree": 2,
                "quadrature_points": np.vstack([vertices, middles]),
                "quadrature_weights": np.concatenate([np.full(len(vertices), shares[0]),
                                                      np.full(len(middles), shares[1])]) * volume}
    if simplex or facet_dim == 1:
        points = np.vstack([np.zeros(facet_dim), np.eye(facet_dim)])
        volume = 1.0 / math.factorial(facet_dim)
    else:
        points = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
        volume = 1.0
    weights = np.full(len(points), volume / len(points))
    return {"quadrature_rule": "custom", "quadrature_degree": 1,
            "quadrature_points": points, "quadrature_weights": weights}


def cell_dofs(V: fem.FunctionSpace, cells: np.ndarray) -> np.ndarray:
    """The (block) dofs of ``V`` on ``cells``: ``locate_dofs_topological`` on cells, which from
    0.7 needs the cell-to-cell connectivity made first."""
    tdim = V.mesh.topology.dim
    V.mesh.topology.create_connectivity(tdim, tdim)
    return fem.locate_dofs_topological(V, tdim, cells)


def element_degree(V: fem.FunctionSpace) -> int:
    """The polynomial degree of a space's element (a method of the UFL element up to 0.6, a
    property of the Basix UFL element from 0.7)."""
    degree = V.ufl_element().degree
    return int(degree() if callable(degree) else degree)


def petsc_vec(u: fem.Function) -> PETSc.Vec:
    """The PETSc vector that shares memory with a Function's dof array."""
    x = u.x
    return x.petsc_vec if hasattr(x, "petsc_vec") else u.vector


def create_rectangle(comm: MPI.Comm, corner0: typing.Sequence[float],
                     corner1: typing.Sequence[float], n: typing.Sequence[int]) -> mesh.Mesh:
    """Quadrilateral mesh of a rectangle (``dtype`` was inserted before ``cell_type`` in 0.8)."""
    points = [np.asarray(corner0, dtype=float), np.asarray(corner1, dtype=float)]
    return mesh.create_rectangle(comm=comm, points=points, n=list(n),
                                 cell_type=mesh.CellType.quadrilateral)


def create_box(comm: MPI.Comm, corner0: typing.Sequence[float], corner1: typing.Sequence[float],
               n: typing.Sequence[int]) -> mesh.Mesh:
    """Hexahedral mesh of a box (keywords: ``dtype`` was inserted before ``cell_type`` in 0.8)."""
    points = [np.asarray(corner0, dtype=float), np.asarray(corner1, dtype=float)]
    return mesh.create_box(comm=comm, points=points, n=list(n),
                           cell_type=mesh.CellType.hexahedron)


def create_simplex_mesh(comm: MPI.Comm, cells: np.ndarray, x: np.ndarray) -> mesh.Mesh:
    """A mesh of triangles (2D) or tetrahedra (3D) from arrays (given on any ranks, e.g. all on
    rank 0 and empty elsewhere), partitioned by dolfinx. The coordinate element is a UFL
    ``VectorElement`` up to 0.6 and a Basix element from 0.7."""
    gdim = x.shape[1]
    cell = "triangle" if gdim == 2 else "tetrahedron"
    try:
        import basix.ufl
        element = basix.ufl.element("Lagrange", cell, 1, shape=(gdim,))
    except (ImportError, AttributeError):
        element = ufl.VectorElement("Lagrange", cell, 1)
    return mesh.create_mesh(comm, cells.astype(np.int64), x, ufl.Mesh(element))


def colliding_cells(msh: mesh.Mesh, points: np.ndarray) -> typing.Any:
    """The local cells containing each point (``points``: shape (n, 3)), as an AdjacencyList
    (``links(i)``: the cells of point i, empty if it is off this rank's part of the mesh), for
    ``Function.eval``. ``BoundingBoxTree`` and ``compute_collisions`` became ``bb_tree`` and
    ``compute_collisions_points`` in 0.7."""
    tdim = msh.topology.dim
    if hasattr(geometry, "bb_tree"):
        candidates = geometry.compute_collisions_points(geometry.bb_tree(msh, tdim), points)
    else:
        candidates = geometry.compute_collisions(geometry.BoundingBoxTree(msh, tdim), points)
    return geometry.compute_colliding_cells(msh, candidates, points)


def interpolation_points(V: fem.FunctionSpace) -> np.ndarray:
    """Reference interpolation points of a space's element (method in 0.5, property later)."""
    pts = V.element.interpolation_points
    return pts() if callable(pts) else pts


def evaluate_expression(expr: fem.Expression, msh: mesh.Mesh, cells: np.ndarray) -> np.ndarray:
    """An Expression's values on ``cells`` (0.9's ``eval`` takes the mesh first)."""
    import inspect
    if "mesh" in inspect.signature(expr.eval).parameters:
        return expr.eval(msh, cells)
    return expr.eval(cells)


def jit_options(cache_dir: str | None = None) -> dict:
    """Keyword arguments for ``fem.form``: the option dict was renamed in 0.7."""
    options: dict = {"cffi_extra_compile_args": ["-O2"]}
    if cache_dir is not None:
        options["cache_dir"] = cache_dir
    import inspect
    if "jit_options" in inspect.signature(fem.form).parameters:
        return {"jit_options": options}
    return {"jit_params": options}


def assemble_matrix_into(A: PETSc.Mat, a: fem.FormMetaClass, bcs: list,
                         diagonal: float = 1.0, zero: bool = True) -> None:
    """Assemble ``a`` into ``A`` (Dirichlet rows: ``diagonal`` on the diagonal), leaving A
    *unfinalised*: the caller adds its own entries (nodal springs), then ``A.assemble()``.
    ``zero=False`` adds to what A holds (the Dirichlet diagonal is still set, not added).
    ``diagonal`` became ``diag`` in 0.8, so it is passed positionally.
    """
    if zero:
        A.zeroEntries()
    dolfinx.fem.petsc.assemble_matrix(A, a, bcs, diagonal)


def _gmsh_reader() -> typing.Any:
    import importlib
    try:
        return importlib.import_module("dolfinx.io.gmsh")  # dolfinx >= 0.10
    except ImportError:
        return importlib.import_module("dolfinx.io.gmshio")


def model_cell_centroids(model: typing.Any, gdim: int) -> np.ndarray:
    """The centroids (cells, 3) of a gmsh model's cells of dimension ``gdim``, in the order
    :func:`model_to_mesh` hands them to the partitioner (its physical groups' elements, read
    by the reader's own ``extract_topology_and_markers``). On the rank that holds the model."""
    reader = _gmsh_reader()
    x = reader.extract_geometry(model)
    for kind, data in reader.extract_topology_and_markers(model).items():
        if model.mesh.getElementProperties(kind)[1] == gdim:
            return x[np.asarray(data["topology"], dtype=np.int64)].mean(axis=1)
    return np.zeros((0, 3))


def key_partitioner(keys: np.ndarray) -> typing.Callable:
    """A cell partitioner for dolfinx's mesh creation that sorts the cells by ``keys`` (one
    number per input cell on this rank, e.g. a coordinate of its centroid) and gives each rank
    an equal run of them: a coordinate cut, not a graph cut. Ghost cells, where the mesh has
    them (0.5.2's gmsh reader asks for shared facets), are the facet neighbours owned
    elsewhere. The input cells must all be on one rank (as :func:`model_to_mesh` reads them).

    dolfinx wraps it with ``create_cell_partitioner``: 0.5.2 takes the graph partitioner alone
    (the ghost mode comes from ``create_mesh``), 0.6-0.9 also the ghost mode (none, the gmsh
    reader's default there).
    """
    keys = np.asarray(keys, dtype=float)

    def partition(comm: typing.Any, nparts: int, graph: typing.Any, ghosting: bool) -> typing.Any:
        n = graph.num_nodes
        if comm.allreduce(int(n > 0)) > 1:
            raise RuntimeError("key_partitioner: the cells must all be on one rank")
        if n and len(keys) != n:
            raise RuntimeError(f"key_partitioner: {len(keys)} keys for {n} cells")
        owner = np.zeros(n, dtype=np.int32)
        owner[np.argsort(keys[:n], kind="stable")] = np.arange(n, dtype=np.int64) * nparts // n
        if not ghosting:
            return _adjacency_list(owner, np.arange(n + 1, dtype=np.int32))
        offsets, links = np.asarray(graph.offsets), np.asarray(graph.array)
        first = comm.exscan(n) or 0
        rows = np.repeat(np.arange(n), np.diff(offsets))
        other = owner[links - first]
        pairs = np.unique(np.stack([rows, other])[:, other != owner[rows]], axis=1)
        counts = np.bincount(pairs[0], minlength=n) + 1
        data = np.empty(counts.sum(), dtype=np.int32)
        starts = np.concatenate([[0], np.cumsum(counts)])
        data[starts[:-1]] = owner
        slot = starts[pairs[0]] + 1 + (np.arange(pairs.shape[1]) - np.searchsorted(pairs[0],
                                                                                  pairs[0]))
        data[slot] = pairs[1]
        return _adjacency_list(data, starts.astype(np.int32))

    cpp = dolfinx.cpp.mesh
    try:  # 0.6-0.9: the graph partitioner and the ghost mode
        return cpp.create_cell_partitioner(partition, mesh.GhostMode.none)
    except TypeError:  # 0.5.2: the graph partitioner alone
        return cpp.create_cell_partitioner(partition)


def _adjacency_list(data: np.ndarray, offsets: np.ndarray) -> typing.Any:
    import dolfinx.graph
    make = getattr(dolfinx.graph, "adjacencylist", None) or dolfinx.graph.create_adjacencylist
    return make(np.ascontiguousarray(data, dtype=np.int32),
                np.ascontiguousarray(offsets, dtype=np.int32))


def model_to_mesh(model: typing.Any, comm: MPI.Comm, rank: int, gdim: int,
                  partitioner: typing.Callable | None = None
                  ) -> tuple[mesh.Mesh, mesh.MeshTagsMetaClass, mesh.MeshTagsMetaClass]:
    """A gmsh model (built on ``rank`` only) as a distributed mesh with its cell and facet tags.

    Only the physical groups of the two highest dimensions are read. The reader is
    ``dolfinx.io.gmshio.model_to_mesh`` up to 0.9 (a tuple) and ``dolfinx.io.gmsh.model_to_mesh``
    from 0.10 (a ``MeshData`` with ``mesh``, ``cell_tags``, ``facet_tags``). Imported here, not at
    the top, so that the package works where gmsh is not installed. ``partitioner``: a cell
    partitioner (:func:`key_partitioner`) instead of dolfinx's graph partitioner; 0.5.2's
    reader has no argument for it and is lent it for the call.
    """
    reader = _gmsh_reader()
    if partitioner is None:
        data = reader.model_to_mesh(model, comm, rank, gdim=gdim)
    elif "partitioner" in inspect.signature(reader.model_to_mesh).parameters:  # >= 0.6
        data = reader.model_to_mesh(model, comm, rank, gdim=gdim, partitioner=partitioner)
    else:  # 0.5.2's reader calls create_mesh with its default partitioner: lend it ours
        create = reader.create_mesh
        reader.create_mesh = functools.partial(create, partitioner=partitioner)
        try:
            data = reader.model_to_mesh(model, comm, rank, gdim=gdim)
        finally:
            reader.create_mesh = create
    if hasattr(data, "mesh"):
        return data.mesh, data.cell_tags, data.facet_tags
    msh, cell_tags, facet_tags = data
    return msh, cell_tags, facet_tags


def read_msh(path: str, comm: MPI.Comm, rank: int,
             gdim: int) -> tuple[mesh.Mesh, mesh.MeshTagsMetaClass, mesh.MeshTagsMetaClass]:
    """A gmsh ``.msh`` file (read on ``rank``) as a distributed mesh with its cell and facet
    tags. dolfinx 0.10's ``dolfinx.io.gmsh.read_from_msh``; before it, the file merged into a
    gmsh model on ``rank`` and :func:`model_to_mesh` (0.5.2's ``gmshio.read_from_msh`` returns
    an undefined name on the reading rank)."""
    import importlib
    try:
        data = importlib.import_module("dolfinx.io.gmsh").read_from_msh(path, comm, rank,
                                                                         gdim=gdim)
        return data.mesh, data.cell_tags, data.facet_tags
    except ImportError:
        pass
    model, error = None, None
    if comm.rank == rank:
        import gmsh
        gmsh.initialize(readConfigFiles=False)
        gmsh.option.setNumber("General.Terminal", 0)
        try:
            gmsh.model.add("fenicsfriction-msh")
            gmsh.merge(str(path))
            model = gmsh.model
        except Exception as e:  # broadcast: the other ranks must not wait for the mesh
            error = f"reading {path} with gmsh failed: {e}"
    try:
        error = comm.bcast(error, root=rank)
        if error is not None:
            raise RuntimeError(error)
        return model_to_mesh(model, comm, rank, gdim)
    finally:
        if comm.rank == rank:
            gmsh.finalize()


def form(expr: ufl.Form, cache_dir: str | None = None) -> fem.FormMetaClass:
    """Compile a UFL form with the package's JIT options (``cache_dir``: where FFCx caches)."""
    return fem.form(expr, **jit_options(cache_dir))


def create_mesh_from_arrays(comm: MPI.Comm, cells: np.ndarray, x: np.ndarray,
                            cell_type: str, degree: int = 1) -> mesh.Mesh:
    """A mesh of cells of ``cell_type`` ("triangle", "quadrilateral", "tetrahedron",
    "hexahedron") and geometric ``degree`` from arrays (given on any ranks, e.g. all on rank 0
    and empty elsewhere), partitioned by dolfinx. Nodes are in dolfinx's order: quadrilateral
    and hexahedron vertices in tensor-product order (a quadrilateral's 0, 1, 2, 3 at (0,0),
    (1,0), (0,1), (1,1)), not counter-clockwise; then, for degree 2, the edge midpoints in the
    order of the reference cell's edges and the interior node. The coordinate element is a UFL
    ``VectorElement`` up to 0.6 and a Basix element from 0.7."""
    gdim = x.shape[1]
    try:
        import basix.ufl
        element = basix.ufl.element("Lagrange", cell_type, degree, shape=(gdim,))
    except (ImportError, AttributeError):
        element = ufl.VectorElement("Lagrange", cell_type, degree)
    return mesh.create_mesh(comm, cells.astype(np.int64), x, ufl.Mesh(element))


def write_meshtags(xdmf: typing.Any, tags: mesh.MeshTags, msh: mesh.Mesh) -> None:
    """``XDMFFile.write_meshtags``: dolfinx 0.5 takes the tags alone, 0.7+ also the geometry."""
    try:
        xdmf.write_meshtags(tags, msh.geometry)
    except TypeError:
        xdmf.write_meshtags(tags)
