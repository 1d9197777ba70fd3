r"""The mollification of a field on the contact surface (Oden & Pires 1983; Kalker 1986, eq. 27).

Oden & Pires (1983) replace the normal pressure in the friction bound by its mollification

.. math:: \tilde p_n(x) = \int C(r)\, \omega_r(y)\, p_n(x + y)\, dy, \qquad
          \omega_r(y) = \exp\Big(\frac{r^2}{|y|^2 - r^2}\Big) \text{ for } |y| < r,\ 0 \text{ else},

a smooth average over the disc (2D: the segment) of radius r, C(r) normalising; r = 0 is the
local law. On a mesh the field is known at the nodes :math:`x_j` of the surface, each with its
tributary length/area :math:`w_j`, and the integral becomes the sparse linear operator

.. math:: \tilde p_i = \sum_j M_{ij} p_j, \qquad
          M_{ij} = \frac{\omega_r(x_j - x_i)\, w_j}{\sum_k \omega_r(x_k - x_i)\, w_k},

the row normalisation being the discrete C(r): the operator reproduces constants exactly,
also at the surface's edges (where the average is one-sided), and linear fields wherever the
nodes within r of :math:`x_i` are symmetric about it (the interior of a uniform mesh). A
radius below the node spacing leaves every node alone (M = I).

The surface is small against the body, so its nodes are gathered on every rank and the rows
of the owned nodes built against all of them.
"""

from __future__ import annotations

import typing

from mpi4py import MPI

import numpy as np
import scipy.sparse
import scipy.spatial

from fenicsfriction.laws import check, check_positive

__all__ = ["SurfaceMollifier", "mollifier_kernel"]


def mollifier_kernel(distance: np.ndarray, radius: float) -> np.ndarray:
    """:math:`\\omega_r = \\exp(r^2/(|y|^2 - r^2))` inside the ball |y| < r, 0 outside
    (Kalker 1986, eq. 27), unnormalised."""
    distance = np.asarray(distance, dtype=float)
    inside = distance < radius
    values = np.zeros_like(distance)
    values[inside] = np.exp(radius**2 / (distance[inside] ** 2 - radius**2))
    return values


class SurfaceMollifier:
    """The mollification operator M on the nodes of a surface (see the module docstring).

    Args:
        points: coordinates of the surface nodes this rank owns, (n, gdim).
        weights: their tributary lengths (2D) or areas (3D), > 0.
        radius: the mollification radius r >= 0 (0: the identity, the local law).
        comm: the communicator the nodes are distributed over.

    Attributes:
        matrix: the rows of the owned nodes, a SciPy CSR matrix (n_owned, n_surface) acting on
            the gathered values (rank by rank, in the order given).
    """

    def __init__(self, points: np.ndarray, weights: np.ndarray, radius: float,
                 comm: MPI.Comm = MPI.COMM_WORLD):
        check_positive("radius", radius, strict=False)
        points = np.asarray(points, dtype=float).reshape(len(weights), -1)
        weights = np.asarray(weights, dtype=float)
        check("weights", "...", bool(np.all(weights > 0)), "every tributary weight must be > 0")
        self.comm, self.radius = comm, float(radius)
        everywhere = np.vstack(comm.allgather(points))
        all_weights = np.concatenate(comm.allgather(weights))
        offset = sum(comm.allgather(len(points))[:comm.rank])
        if radius == 0:  # the kernel's support shrinks to the node itself: the local law
            rows = scipy.sparse.eye(len(points), len(everywhere), k=offset, format="csr")
        else:
            neighbours = scipy.spatial.cKDTree(everywhere).query_ball_point(points, radius)
            i = np.repeat(np.arange(len(points)), [len(n) for n in neighbours])
            j = np.concatenate([np.asarray(n, dtype=int) for n in neighbours]
                               + [np.zeros(0, dtype=int)])
            distance = np.linalg.norm(everywhere[j] - points[i], axis=1)
            values = mollifier_kernel(distance, radius) * all_weights[j]
            rows = scipy.sparse.csr_matrix((values, (i, j)),
                                           shape=(len(points), len(everywhere)))
            rows = scipy.sparse.diags(1.0 / np.asarray(rows.sum(axis=1)).ravel()) @ rows
        self.matrix = rows.tocsr()

    def __call__(self, values: np.ndarray | typing.Sequence[float]) -> np.ndarray:
        """The mollified values at the owned nodes, from the values at the owned nodes
        (collective)."""
        everywhere = np.concatenate(self.comm.allgather(np.asarray(values, dtype=float)))
        return self.matrix @ everywhere
