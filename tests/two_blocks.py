"""Two stacked blocks touching on y = 0 (2D) or z = 0 (3D), with non-matching meshes, built
from arrays on rank 0 (no mesh generator): the fixture of the node-to-segment tests.

Tags follow the package's two-body scenes: cells 1 (upper, slave body) and 2 (lower, master);
facets 10 (upper body's bottom: slave), 20 (lower body's top: master), 11 (upper top: load),
21 (lower bottom: fixed).
"""

from __future__ import annotations

import itertools

from mpi4py import MPI

import numpy as np
from dolfinx import mesh

from fenicsfriction import _compat

SLAVE, MASTER, LOAD, FIXED = 10, 20, 11, 21
UPPER, LOWER = 1, 2


def _grid(n: int, dim: int, z0: float, height: float, width: float):
    """Simplices of a structured block [0, width]^(dim-1) x [z0, z0 + height]."""
    axes = [np.linspace(0.0, width, n + 1)] * (dim - 1) + [np.linspace(z0, z0 + height, n + 1)]
    x = np.array(list(itertools.product(*axes)))
    index = np.arange((n + 1) ** dim).reshape((n + 1,) * dim)
    cells = []
    for corner in itertools.product(range(n), repeat=dim):
        box = [index[tuple(c + o for c, o in zip(corner, offset, strict=True))]
               for offset in itertools.product((0, 1), repeat=dim)]
        if dim == 2:
            cells += [[box[0], box[1], box[3]], [box[0], box[3], box[2]]]
        else:  # the six tetrahedra of a cube around its diagonal 0-7
            for path in itertools.permutations(range(3)):
                vertex, nodes = 0, [box[0]]
                for axis in path:
                    vertex += 1 << (2 - axis)
                    nodes.append(box[vertex])
                cells.append(nodes)
    return x, np.array(cells)


def stacked_blocks(comm: MPI.Comm, dim: int = 2, n_upper: int = 5, n_lower: int = 7,
                   width: float = 1.0, height: float = 1.0, overlap: float = 0.0):
    """(mesh, cell_tags, facet_tags) of the two blocks; ``overlap`` moves the upper one down."""
    if comm.rank == 0:
        x1, c1 = _grid(n_upper, dim, -overlap, height, width)
        x2, c2 = _grid(n_lower, dim, -height, height, width)
        x = np.vstack([x1, x2])
        cells = np.vstack([c1, c2 + len(x1)])
    else:
        x, cells = np.zeros((0, dim)), np.zeros((0, dim + 1), dtype=np.int64)
    msh = _compat.create_simplex_mesh(comm, cells, x)
    tdim = msh.topology.dim
    cell_map = msh.topology.index_map(tdim)
    midpoints = mesh.compute_midpoints(msh, tdim, np.arange(
        cell_map.size_local + cell_map.num_ghosts, dtype=np.int32))
    upper = midpoints[:, dim - 1] > -overlap
    cell_tags = mesh.meshtags(msh, tdim, np.arange(len(upper), dtype=np.int32),
                              np.where(upper, UPPER, LOWER).astype(np.int32))
    msh.topology.create_connectivity(tdim - 1, tdim)
    facets = mesh.exterior_facet_indices(msh.topology)
    f_mid = mesh.compute_midpoints(msh, tdim - 1, facets)
    f_to_c = msh.topology.connectivity(tdim - 1, tdim)
    in_upper = np.array([upper[f_to_c.links(f)[0]] for f in facets], dtype=bool)
    z = f_mid[:, dim - 1]
    tol = 1e-10
    values = np.zeros(len(facets), dtype=np.int32)
    values[in_upper & np.isclose(z, -overlap, atol=tol)] = SLAVE
    values[in_upper & np.isclose(z, height - overlap, atol=tol)] = LOAD
    values[~in_upper & np.isclose(z, 0.0, atol=tol)] = MASTER
    values[~in_upper & np.isclose(z, -height, atol=tol)] = FIXED
    keep = values > 0
    facet_tags = mesh.meshtags(msh, tdim - 1, facets[keep].astype(np.int32), values[keep])
    return msh, cell_tags, facet_tags
