r"""Rigid rotation of a body about a fixed axis: its velocity field :math:`w = \omega\times(x - p)`.

A :class:`RigidRotation` gives the velocity of the material points of a body spinning rigidly
about an axis, as a UFL expression of the spatial coordinate (for the convective terms of
:mod:`fenicsfriction.forms` and for the slip velocity of friction on a rotating surface,
:math:`\dot u_T - (\omega\times r)_T`) or as NumPy values at points (to interpolate or to check).
In 2D the axis is :math:`e_z`, normal to the plane, and :math:`w = \omega\, e_z\times(x - p)`.

The angular velocity may be a ``fem.Constant``: a sweep in ω then changes its value without
compiling the forms again.
"""

from __future__ import annotations

import dataclasses
import numbers
import typing

import numpy as np
import ufl

from fenicsfriction.laws import check

__all__ = ["RigidRotation"]

#: An axis shorter than this [-] is refused: it has no direction to normalise.
MIN_AXIS_NORM = 1e-12


@dataclasses.dataclass(frozen=True)
class RigidRotation:
    r"""A rigid rotation at angular velocity ω about the axis through ``point`` along ``axis``.

    The velocity of the material point at x is :math:`w(x) = \omega\, a\times(x - p)`; in 2D
    (the mesh in the plane, a = :math:`e_z`) :math:`w = \omega\,(-(x_2 - p_2),\ x_1 - p_1)`,
    counter-clockwise for ω > 0.

    Attributes:
        omega: angular velocity ω [rad/s], a float or a scalar ``fem.Constant`` (changed in
            place, e.g. in a sweep, without recompiling).
        axis: direction a of the axis [-], nonzero; stored normalised. With a 2D mesh it must
            be ±e_z (its sign sets the sense of rotation). Default e_z.
        point: a point p on the axis [m], 2 or 3 coordinates (2 only for a 2D mesh; with a 2D
            mesh a third coordinate is ignored). Default the origin.
    """

    omega: typing.Any
    axis: tuple[float, ...] = (0.0, 0.0, 1.0)
    point: tuple[float, ...] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        if isinstance(self.omega, numbers.Real):
            check("omega", self.omega, bool(np.isfinite(float(self.omega))), "must be finite")
        else:
            check("omega", self.omega, getattr(self.omega, "ufl_shape", None) == (),
                  "must be a float or a scalar fem.Constant")
        axis = np.asarray(self.axis, dtype=float).ravel()
        check("axis", self.axis, axis.shape == (3,) and bool(np.all(np.isfinite(axis))),
              "must have 3 finite components")
        norm = float(np.linalg.norm(axis))
        check("axis", self.axis, norm > MIN_AXIS_NORM, "must be nonzero")
        point = np.asarray(self.point, dtype=float).ravel()
        check("point", self.point, point.shape in ((2,), (3,)) and bool(np.all(np.isfinite(point))),
              "must have 2 or 3 finite coordinates")
        object.__setattr__(self, "axis", tuple(float(c) for c in axis / norm))
        object.__setattr__(self, "point", tuple(float(c) for c in point))

    def _check_dimension(self, d: int) -> None:
        check("x", f"points of dimension {d}", d in (2, 3), "must be 2D or 3D points")
        if d == 2:
            check("axis", self.axis, self.axis[0] == 0.0 and self.axis[1] == 0.0,
                  "with a 2D mesh the axis is normal to the plane: (0, 0, ±1)")
        else:
            check("point", self.point, len(self.point) == 3, "a 3D mesh needs 3 coordinates")

    def _omega_value(self) -> float:
        return float(np.asarray(getattr(self.omega, "value", self.omega)))

    def velocity(self, x: typing.Any) -> typing.Any:
        r"""The velocity :math:`\omega\, a\times(x - p)` of the material point at ``x``.

        Args:
            x: a UFL ``SpatialCoordinate`` of the mesh (a vector of its geometric dimension,
                2 or 3), or NumPy points of shape (d, n), d = 2 or 3 (dolfinx's interpolation
                points have 3 rows: with a 2D axis pass ``x[:2]``).

        Returns:
            A UFL vector of dimension d, or an array of shape (d, n).
        """
        a = self.axis
        if isinstance(x, ufl.core.expr.Expr):
            check("x", x, len(x.ufl_shape) == 1, "must be a vector (a SpatialCoordinate)")
            d = x.ufl_shape[0]
            self._check_dimension(d)
            r = [x[i] - self.point[i] for i in range(d)]
            if d == 2:
                return self.omega * a[2] * ufl.as_vector((-r[1], r[0]))
            return self.omega * ufl.as_vector((a[1] * r[2] - a[2] * r[1],
                                               a[2] * r[0] - a[0] * r[2],
                                               a[0] * r[1] - a[1] * r[0]))
        points = np.asarray(x, dtype=float)
        check("x", points.shape, points.ndim == 2, "must be points of shape (d, n)")
        d = points.shape[0]
        self._check_dimension(d)
        r = points - np.asarray(self.point[:d])[:, None]
        omega = self._omega_value()
        if d == 2:
            return omega * a[2] * np.vstack((-r[1], r[0]))
        return omega * np.cross(np.asarray(a)[:, None], r, axis=0)
