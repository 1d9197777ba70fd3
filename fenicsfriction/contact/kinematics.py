r"""Node-to-segment kinematics as UFL expressions of the current nodal positions.

A slave point :math:`x_s` is paired with a master facet, a segment (2D, nodes
:math:`x_1, x_2`) or a triangle (3D, :math:`x_1, x_2, x_3`), whose nodes are ordered so that
the facet normal points out of the master body (Pop, eq. 28):

.. math::
    n = \frac{(x_2 - x_1)^\perp}{|x_2 - x_1|}\ (2D), \qquad
    n = \frac{(x_2 - x_1)\times(x_3 - x_1)}{|(x_2 - x_1)\times(x_3 - x_1)|}\ (3D).

The closest point :math:`x_m = \sum_a N_a(\xi) x_a` has the surface coordinates of the
projection (Pop, eq. 29), :math:`\xi = A^{-1} [\tau_\alpha\cdot(x_s - x_1)]` with the
tangents :math:`\tau_\alpha = x_{\alpha+1} - x_1` and the metric
:math:`A_{\alpha\beta} = \tau_\alpha\cdot\tau_\beta`; the normal gap is
:math:`g = (x_s - x_1)\cdot n`, positive while the slave point is outside the master body.

Every quantity is a closed-form UFL expression of :math:`x_s` and the :math:`x_a`, so its
derivatives, including the motion of the closest point along the facet as the bodies slide,
come from :func:`ufl.derivative` like every other term of the residual.
"""

from __future__ import annotations

import dataclasses
import typing

import ufl

__all__ = ["Projection", "project"]

Vector = typing.Any  # a UFL vector expression


@dataclasses.dataclass
class Projection:
    """A slave point projected on its master facet.

    Attributes:
        shape: :math:`N_a(\\xi)`, one UFL scalar per master node.
        normal: the facet's unit normal, out of the master body.
        gap: :math:`(x_s - x_1)\\cdot n`.
    """

    shape: list
    normal: Vector
    gap: typing.Any

    def interpolate(self, nodal: list[Vector]) -> Vector:
        """:math:`\\sum_a N_a(\\xi) q_a` of nodal vectors (master displacement, velocity)."""
        terms = [N * q for N, q in zip(self.shape, nodal, strict=True)]
        return sum(terms[1:], terms[0])


def project(x_s: Vector, x_nodes: list[Vector]) -> Projection:
    """Project the slave point ``x_s`` on the facet through ``x_nodes`` (2 in 2D, 3 in 3D)."""
    x1 = x_nodes[0]
    tangents = [x - x1 for x in x_nodes[1:]]
    r = x_s - x1
    if len(x_nodes) == 2:
        (t,) = tangents
        length2 = ufl.dot(t, t)
        xi = ufl.dot(r, t) / length2
        shape = [1 - xi, xi]
        normal = ufl.as_vector((-t[1], t[0])) / ufl.sqrt(length2)
    elif len(x_nodes) == 3:
        t1, t2 = tangents
        a11, a12, a22 = ufl.dot(t1, t1), ufl.dot(t1, t2), ufl.dot(t2, t2)
        det = a11 * a22 - a12 * a12
        r1, r2 = ufl.dot(r, t1), ufl.dot(r, t2)
        xi1, xi2 = (a22 * r1 - a12 * r2) / det, (a11 * r2 - a12 * r1) / det
        shape = [1 - xi1 - xi2, xi1, xi2]
        c = ufl.cross(t1, t2)
        normal = c / ufl.sqrt(ufl.dot(c, c))
    else:
        raise ValueError(f"x_nodes: a master facet has 2 (2D) or 3 (3D) nodes, got {len(x_nodes)}")
    return Projection(shape=shape, normal=normal, gap=ufl.dot(r, normal))
