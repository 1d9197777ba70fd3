"""The dolfinx version layer (fenicsfriction._compat): what the suite does not reach otherwise."""

from mpi4py import MPI

import numpy as np
from dolfinx import fem, mesh

from fenicsfriction import _compat


def test_colliding_cells_let_a_function_be_evaluated_at_points():
    """Every point of the unit square is found in a cell of some rank, and a degree-1 function
    evaluated there gives the affine function it interpolates (exact up to round-off)."""
    comm = MPI.COMM_WORLD
    msh = mesh.create_unit_square(comm, 4, 4)
    u = fem.Function(_compat.scalar_function_space(msh, "Lagrange", 1))
    u.interpolate(lambda x: 1.0 + x[0] + 2.0 * x[1])
    points = np.array([[0.1, 0.2, 0.0], [0.5, 0.5, 0.0], [0.9, 0.05, 0.0], [1.0, 1.0, 0.0]])
    colliding = _compat.colliding_cells(msh, points)
    found = [i for i in range(len(points)) if len(colliding.links(i))]
    cells = np.array([colliding.links(i)[0] for i in found], dtype=np.int32)
    values = u.eval(points[found], cells).ravel() if found else np.empty(0)
    np.testing.assert_allclose(values, 1.0 + points[found, 0] + 2.0 * points[found, 1],
                               rtol=1e-14)
    assert set().union(*comm.allgather(set(found))) == set(range(len(points)))
    # a point off the mesh is in no cell
    assert len(_compat.colliding_cells(msh, np.array([[1.5, 0.5, 0.0]])).links(0)) == 0
