r"""Rigid rotation (:mod:`fenicsfriction.rotation`): the velocity field ω a × (x − p), as UFL and
as NumPy, checked against the cross product written out, and its validation.
"""

from mpi4py import MPI

import numpy as np
import pytest
import ufl
from dolfinx import fem

from fenicsfriction import _compat
from fenicsfriction.rotation import RigidRotation

COMM = MPI.COMM_WORLD


def test_velocity_is_omega_cross_r_in_3d():
    axis = np.array([1.0, 2.0, 2.0])  # normalised by the constructor
    p = np.array([0.3, -0.1, 0.2])
    rot = RigidRotation(omega=2.5, axis=tuple(axis), point=tuple(p))
    x = np.random.default_rng(0).normal(size=(3, 7))
    expected = 2.5 * np.cross(axis / 3.0, (x - p[:, None]).T).T
    assert np.allclose(rot.velocity(x), expected, rtol=0, atol=1e-14)
    # w is normal to the axis and to r: no velocity along the axis
    assert np.allclose(np.asarray(rot.axis) @ rot.velocity(x), 0.0, atol=1e-14)


def test_velocity_in_2d_is_counter_clockwise_and_flips_with_the_axis():
    x = np.array([[1.0, 0.0], [0.0, 2.0]])  # points (1, 0) and (0, 2)
    rot = RigidRotation(omega=3.0, point=(0.0, 0.0))
    assert np.allclose(rot.velocity(x), [[0.0, -6.0], [3.0, 0.0]])
    assert np.allclose(RigidRotation(3.0, axis=(0, 0, -1)).velocity(x), -rot.velocity(x))


def test_ufl_velocity_equals_numpy_velocity():
    """The NumPy field interpolated into P1 (exact: w is linear in x) equals the UFL field, and
    ω a Constant changed in place changes the compiled form's value."""
    msh = _compat.create_rectangle(COMM, (-1.0, -1.0), (1.0, 1.0), (4, 4))
    omega = fem.Constant(msh, 2.0)
    rot = RigidRotation(omega=omega, point=(0.2, -0.3))
    x = ufl.SpatialCoordinate(msh)
    w = rot.velocity(x)
    # ω² ∫ |x - p|² over [-1, 1]²: ∫ (x² + y²) = 8/3, area 4
    p = np.array([0.2, -0.3])
    exact = 8.0 / 3.0 + 4.0 * p @ p
    speed2 = fem.form(ufl.inner(w, w) * ufl.dx)
    assert COMM.allreduce(fem.assemble_scalar(speed2)) == pytest.approx(4.0 * exact, rel=1e-12)
    omega.value = -1.0
    assert COMM.allreduce(fem.assemble_scalar(speed2)) == pytest.approx(exact, rel=1e-12)
    w_h = fem.Function(_compat.vector_function_space(msh, 1))
    w_h.interpolate(lambda y: rot.velocity(y[:2]))
    error = fem.form(ufl.inner(w_h - w, w_h - w) * ufl.dx)
    assert COMM.allreduce(fem.assemble_scalar(error)) < 1e-28


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"omega": 1.0, "axis": (0.0, 0.0, 0.0)}, "nonzero"),
    ({"omega": 1.0, "axis": (1.0, 0.0)}, "3 finite components"),
    ({"omega": float("nan")}, "finite"),
    ({"omega": 1.0, "point": (0.0,)}, "2 or 3"),
])
def test_invalid_rotations_are_refused(kwargs, message):
    with pytest.raises(ValueError, match=message):
        RigidRotation(**kwargs)


def test_a_tilted_axis_is_refused_on_a_2d_mesh():
    rot = RigidRotation(1.0, axis=(1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="normal to the plane"):
        rot.velocity(np.zeros((2, 3)))
