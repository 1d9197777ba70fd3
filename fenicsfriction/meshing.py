"""gmsh models read into distributed dolfinx meshes: the session on rank 0, shared by the scenes
that build their meshes with gmsh (two-body contact, rolling contact); and the annulus of exact
circles (a ring, a disc with a hole) built from arrays, for rotating bodies.

The builder owns the gmsh session: it initialises gmsh without the user's configuration files
and finalises it; where gmsh has ``isInitialized`` (not 4.8) and reports a session open
already, it uses it and removes only its own model.
"""

from __future__ import annotations

import itertools
import typing

from mpi4py import MPI

import numpy as np

from fenicsfriction import _compat
from fenicsfriction.laws import check

__all__ = ["annulus", "gmsh_mesh", "vertex_rows"]

_model_numbers = itertools.count()


def gmsh_mesh(comm: MPI.Comm, name: str, gdim: int,
              construct: typing.Callable[[typing.Any], None], msh_file: str | None = None,
              partition_key: typing.Callable[[np.ndarray], np.ndarray] | None = None
              ) -> tuple[typing.Any, typing.Any, typing.Any]:
    """Run ``construct(gmsh)`` (geometry, physical groups, size control) on rank 0, mesh it,
    write ``msh_file`` if given, and read the model into a mesh distributed over ``comm``.

    An error on rank 0 is broadcast, so that every rank raises instead of waiting.

    Args:
        comm: the communicator of the mesh; gmsh runs on its rank 0.
        name: the geometry's name (in the gmsh model's name and in error messages).
        gdim: the geometric (and topological) dimension, 2 or 3.
        construct: ``construct(gmsh)`` builds the geometry, its physical groups and its mesh
            size control in the current gmsh model.
        msh_file: where to write the ``.msh`` file, or None.
        partition_key: ``None``: dolfinx's graph partitioner; else a function of the cells'
            centroids (cells, 3) giving one number per cell: the cells sorted by it are cut
            into equal runs, one per rank (:func:`fenicsfriction._compat.key_partitioner`).

    Returns:
        ``(mesh, cell_tags, facet_tags)``, the tags from the physical groups.
    """
    root = 0
    model = None
    owns_session = True
    error = None
    session: typing.Any = None  # the gmsh module, once there is something to close (rank 0)
    keys = np.zeros(0)
    if comm.rank == root:
        try:
            import gmsh
            owns_session = not getattr(gmsh, "isInitialized", lambda: False)()
            if owns_session:  # without the user's gmshrc: the same mesh everywhere
                gmsh.initialize(readConfigFiles=False)
                session = gmsh
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.model.add(f"fenicsfriction-{name}-{next(_model_numbers)}")
            session = gmsh  # to be closed (finalised, or our model removed)
            construct(gmsh)
            gmsh.model.mesh.generate(gdim)
            if msh_file is not None:
                gmsh.write(str(msh_file))
            model = gmsh.model
            if partition_key is not None:
                keys = partition_key(_compat.model_cell_centroids(model, gdim))
        except Exception as e:  # broadcast below: the other ranks must not wait for the mesh
            error = f"building the {name} mesh with gmsh failed: {type(e).__name__}: {e}"
    try:
        error = comm.bcast(error, root=root)
        if error is not None:
            raise RuntimeError(error)
        partitioner = None if partition_key is None else _compat.key_partitioner(keys)
        msh, cell_tags, facet_tags = _compat.model_to_mesh(model, comm, root, gdim,
                                                           partitioner)
    finally:
        if session is not None:
            if owns_session:
                session.finalize()
            else:
                session.model.remove()
    return msh, cell_tags, facet_tags


def vertex_rows(n_rows: int, degree: int, H: float, target: float) -> np.ndarray:
    """Heights of the n_rows+1 vertex rows of a grid on [0, H]: uniform, except shifted so
    that a row of nodes of the degree-``degree`` Lagrange space lies at height ``target`` (a
    nodal spring's node): the row of cells holding it slides, or else the nearest vertex row
    moves there."""
    rows = np.linspace(0.0, H, n_rows + 1)
    nodes = np.linspace(0.0, H, degree * n_rows + 1)
    k = int(np.argmin(np.abs(nodes - target)))
    if np.isclose(nodes[k], target, rtol=0, atol=1e-12 * H):
        return rows
    spacing = H / n_rows
    j, fraction = divmod(k, degree)
    if fraction:  # a row inside cell row j: slide that cell row so the node row hits target
        low = target - fraction / degree * spacing
        if 0 < j < n_rows - 1 and low > 0 and low + spacing < H:
            return np.concatenate([np.linspace(0.0, low, j + 1),
                                   np.linspace(low + spacing, H, n_rows - j)])
    j = min(max(int(round(target / spacing)), 1), n_rows - 1)  # move the nearest vertex row
    return np.concatenate([np.linspace(0.0, target, j + 1)[:-1],
                           np.linspace(target, H, n_rows - j + 1)])


def annulus(comm: MPI.Comm, r_in: float, r_out: float, n_radial: int, n_around: int
            ) -> typing.Any:
    """The annulus r_in <= r <= r_out centred at the origin: nine-node quadrilaterals on the
    (r, θ) grid, periodic in θ, their nodes on the exact circles and rays (degree-2 geometry).

    The mesh is ``n_around``-fold symmetric, so the doublets of a body of revolution stay
    degenerate (n < n_around / 2 nodal diameters) and a rotation's w·n vanishes on the
    boundary to the accuracy of the degree-2 circle. The arrays are built on rank 0 and
    partitioned by dolfinx.

    Args:
        comm: the communicator of the mesh.
        r_in, r_out: inner and outer radii [m], 0 < r_in < r_out.
        n_radial: elements through the thickness.
        n_around: elements around, >= 3.

    Returns:
        The dolfinx mesh (gdim 2).
    """
    check("r_in", r_in, 0 < r_in < r_out, "need 0 < r_in < r_out")
    check("n_radial", n_radial, n_radial >= 1, "must be >= 1")
    check("n_around", n_around, n_around >= 3, "must be >= 3")
    if comm.rank == 0:
        n_r, n_t = 2 * n_radial + 1, 2 * n_around
        r, t = np.meshgrid(np.linspace(r_in, r_out, n_r), np.arange(n_t) * np.pi / n_around,
                           indexing="ij")
        x = np.column_stack([(r * np.cos(t)).ravel(), (r * np.sin(t)).ravel()])
        i, j = (a.ravel() for a in np.meshgrid(np.arange(0, 2 * n_radial, 2),
                                               np.arange(0, n_t, 2), indexing="ij"))

        def node(di: int, dj: int) -> np.ndarray:
            return (i + di) * n_t + (j + dj) % n_t

        # dolfinx's order: vertices (0,0) (1,0) (0,1) (1,1), the midpoints of the reference
        # edges (0,1) (0,2) (1,3) (2,3), the centre; ξ radial, η along θ (counter-clockwise)
        cells = np.column_stack([node(0, 0), node(2, 0), node(0, 2), node(2, 2), node(1, 0),
                                 node(0, 1), node(2, 1), node(1, 2), node(1, 1)])
    else:
        x, cells = np.zeros((0, 2)), np.zeros((0, 9), dtype=np.int64)
    return _compat.create_mesh_from_arrays(comm, cells, x, "quadrilateral", degree=2)
