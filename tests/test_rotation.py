r"""Rigid rotation (:mod:`fenicsfriction.rotation`): the velocity field ω a × (x − p), as UFL and
as NumPy, checked against the cross product written out, and its validation; friction on a
rotating surface (the slip velocity u̇_T − (ω × r)_T), against the closed-form torque of a pad
on a spinning plane; the derivatives of a residual with the Eulerian terms of a spinning ring
pressed on a fixed pad (Taylor tests).
"""

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem.petsc
import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh

from fenicsfriction import _compat, forms
from fenicsfriction.laws import InterfaceLaw, StribeckFriction
from fenicsfriction.meshing import annulus
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


def test_ufl_velocity_equals_numpy_velocity_about_a_tilted_axis_in_3d():
    """The 3D UFL cross product, written out, against NumPy's, on a box (P1 interpolation of a
    linear field is exact)."""
    msh = _compat.create_box(COMM, (0.0, 0.0, 0.0), (1.0, 2.0, 1.0), (2, 2, 2))
    rot = RigidRotation(omega=-3.0, axis=(1.0, -2.0, 0.5), point=(0.1, 0.4, -0.3))
    w = rot.velocity(ufl.SpatialCoordinate(msh))
    w_h = fem.Function(_compat.vector_function_space(msh, 1))
    w_h.interpolate(rot.velocity)
    error = fem.form(ufl.inner(w_h - w, w_h - w) * ufl.dx)
    norm = fem.form(ufl.inner(w, w) * ufl.dx)
    assert COMM.allreduce(fem.assemble_scalar(error)) < 1e-28 * COMM.allreduce(
        fem.assemble_scalar(norm))


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


# --- friction on a rotating surface ---------------------------------------------------------------

def boundary_tags(msh, where, tag: int = 1):
    """Facet tags: ``tag`` on the boundary facets where ``where(x)`` holds."""
    fdim = msh.topology.dim - 1
    msh.topology.create_connectivity(fdim, msh.topology.dim)
    facets = np.sort(mesh.locate_entities_boundary(msh, fdim, where)).astype(np.int32)
    return mesh.meshtags(msh, fdim, facets, np.full(len(facets), tag, dtype=np.int32))


def gauss_legendre_2d(f, x0: float, x1: float, y0: float, y1: float, n: int = 64) -> float:
    """∫∫ f(x, y) over a rectangle, n × n Gauss-Legendre points (f analytic there)."""
    t, weights = np.polynomial.legendre.leggauss(n)
    x = 0.5 * (x1 + x0) + 0.5 * (x1 - x0) * t
    y = 0.5 * (y1 + y0) + 0.5 * (y1 - y0) * t
    X, Y = np.meshgrid(x, y, indexing="ij")
    return float(weights @ f(X, Y) @ weights) * 0.25 * (x1 - x0) * (y1 - y0)


@pytest.mark.parametrize("regularisation", ["c1", "smooth"])
def test_pad_on_a_spinning_plane_feels_the_closed_form_torque(regularisation):
    """A rigid square pad (side 2a, centred at radius R) pressed with uniform pressure p on a
    plane spinning at Ω about the z axis: the disc drags the pad along e_θ, so the friction
    torque about the axis is μ p ∫ r dA and the force μ p ∫ e_θ dA (F_x = 0 by symmetry,
    F_y = μ p ∫ x/r dA). They are read from the friction term (−∫ t·v) with the rigid test
    fields v = e_z × x, e_x, e_y, at u̇ = 0 with the slip velocity −(ω × r)_T.

    Reference: 64² Gauss points on the square (analytic integrand: round-off). With "c1" the
    traction is exactly μ p ŵ when |w| > ε (here |w| ≥ Ω(R − a) = 40 ε): only the FE
    quadrature of r on the 4 × 4 facets is left (measured 1e-12). With "smooth" the traction
    is μ p w/sqrt(|w|² + ε²): short by at most ε²/(2Ω²(R − a)²) = 3.1e-4 (relative)."""
    R, a, Omega, eps = 0.1, 0.02, 50.0, 0.1
    msh = _compat.create_box(COMM, (R - a, -a, 0.0), (R + a, a, 0.01), (4, 4, 1))
    ds = ufl.ds(domain=msh, subdomain_data=boundary_tags(msh, lambda x: np.isclose(x[2], 0.0)),
                subdomain_id=1, metadata={"quadrature_degree": 10})
    V = _compat.vector_function_space(msh, 1)
    u, u_dot = fem.Function(V), fem.Function(V)
    delta = 1e-5
    u.interpolate(lambda x: np.vstack([0 * x[0], 0 * x[0], -delta + 0 * x[0]]))  # pressed down
    law = InterfaceLaw(c_n=1e18, m_n=2.0, mu=0.4, eps=eps, regularisation=regularisation)
    p = 1e18 * delta**2
    x = ufl.SpatialCoordinate(msh)
    n = ufl.FacetNormal(msh)
    disc = RigidRotation(omega=Omega, axis=(0.0, 0.0, 1.0))
    U_T = forms.tangential_part(disc.velocity(x), n)

    def power(v):
        form = forms.friction(u, u_dot, v, n, law, U_T, ds)
        return COMM.allreduce(dolfinx.fem.assemble_scalar(_compat.form(form)))

    torque = -power(ufl.as_vector((-x[1], x[0], 0.0)))
    force = [-power(ufl.as_vector(e)) for e in ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0))]
    exact_torque = 0.4 * p * gauss_legendre_2d(np.hypot, R - a, R + a, -a, a)
    exact_force_y = 0.4 * p * gauss_legendre_2d(lambda X, Y: X / np.hypot(X, Y),
                                                R - a, R + a, -a, a)
    if regularisation == "c1":
        assert torque == pytest.approx(exact_torque, rel=1e-10)
        assert force[1] == pytest.approx(exact_force_y, rel=1e-10)
    else:
        bound = eps**2 / (2 * (Omega * (R - a)) ** 2)
        assert 0 < 1 - torque / exact_torque < bound
        assert 0 < 1 - force[1] / exact_force_y < bound
    assert abs(force[0]) < 1e-10 * force[1]


# --- the derivatives of a residual with the Eulerian terms ----------------------------------------

def spinning_ring_on_a_pad():
    """A ring (R = 0.15 m, h = 0.1 R, steel) spinning at Ω = 100 rad/s in the space-fixed
    frame, pressed into a pad fixed in space on its outer surface (|θ| < 20°), with friction
    on the material slip velocity u̇ + (w·∇)u + w relative to the pad; at a state u0 of radial
    expansion δ = 1e-3 m (into the pad) plus a random perturbation. Returns the residual and
    u0 as a PETSc vector."""
    R, h, rho = 0.15, 0.015, 7850.0
    msh = annulus(COMM, R - h / 2, R + h / 2, 1, 32)
    outer = R + h / 2
    tags = boundary_tags(msh, lambda x: (np.hypot(x[0], x[1]) > R)
                         & (x[0] > outer * np.cos(np.radians(20)) - 1e-9))
    ds = ufl.ds(domain=msh, subdomain_data=tags, subdomain_id=1)
    dx = ufl.dx(msh)
    V = _compat.vector_function_space(msh, 2)
    u, u_dot, u_ddot = fem.Function(V), fem.Function(V), fem.Function(V)
    v = ufl.TestFunction(V)
    n = ufl.FacetNormal(msh)
    w = RigidRotation(omega=fem.Constant(msh, 100.0)).velocity(ufl.SpatialCoordinate(msh))
    # μ falling with the slip speed (Stribeck, v_s ~ ΩR): in 2D, Coulomb's constant μ makes
    # the friction independent of u̇ while sliding (one tangent: the direction is a sign)
    delta = 1e-3  # a soft contact, p = 1 MPa at δ: the friction's convective part is visible
    law = InterfaceLaw(c_n=1e6 / delta**2.5, m_n=2.5, eps=1e-3,
                       friction_coefficient=StribeckFriction(mu_s=0.6, mu_k=0.3, v_s=10.0))
    material_slip = u_dot + forms.convective_derivative(w, u)
    form = (forms.inertia(rho, u_ddot, v, dx) + forms.elasticity(u, v, 210e9, 0.3, dx, True)
            + forms.gyroscopic(rho, w, u_dot, v, dx)
            + forms.centrifugal_softening(rho, w, u, v, dx)
            + forms.centripetal_load(rho, w, v, dx)
            + forms.normal_compliance(u, v, n, law, ds)
            + forms.friction(u, material_slip, v, n, law, -forms.tangential_part(w, n), ds))
    residual = forms.Residual(form=form, u=u, u_dot=u_dot, u_ddot=u_ddot, v=v)
    u.interpolate(lambda x: delta * x[:2] / outer)
    rng = np.random.default_rng(seed=COMM.rank)
    u.x.array[:] += rng.uniform(-delta / 10, delta / 10, u.x.array.size)
    u.x.scatter_forward()
    return residual, delta


def remainders(residual, field, operator, direction, steps):
    """‖R(field + h δ) − R(field) − h A δ‖ and ‖R(field + h δ) − R(field)‖ for each h."""
    L = _compat.form(residual.form)
    A = dolfinx.fem.petsc.assemble_matrix(_compat.form(operator))
    A.assemble()
    x = _compat.petsc_vec(field)
    base = dolfinx.fem.petsc.assemble_vector(L)
    base.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    A_delta = base.duplicate()
    A.mult(direction, A_delta)
    x0 = x.copy()
    out, increments = [], []
    for h in steps:
        x0.copy(x)
        x.axpy(h, direction)
        field.x.scatter_forward()
        b = dolfinx.fem.petsc.assemble_vector(L)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        b.axpy(-1.0, base)
        increments.append(b.norm())
        b.axpy(-h, A_delta)
        out.append(b.norm())
        b.destroy()
    x0.copy(x)
    field.x.scatter_forward()
    for obj in (A, base, A_delta, x0):
        obj.destroy()
    return np.array(out), np.array(increments)


@pytest.mark.parametrize("operator", ["K", "C"])
def test_linearisation_with_the_eulerian_terms_passes_the_taylor_test(operator):
    """‖R(u0 + h δu, 0, 0) − R(u0, 0, 0) − h K̄ δu‖ = O(h²), and the same in u̇ with C, for
    K̄, C of :meth:`Residual.linearisation` on the spinning ring on a pad: the convective terms
    (linear: exact), the compliance d^2.5 and the friction on the material slip velocity
    u̇ + (w·∇)u + w (nonlinear through d and, by the Stribeck μ, through the slip speed,
    convective part included)."""
    residual, delta = spinning_ring_on_a_pad()
    M, C, K = residual.linearisation()
    rng = np.random.default_rng(seed=100 + COMM.rank)
    field = residual.u if operator == "K" else residual.u_dot
    direction = _compat.petsc_vec(field).duplicate()
    # |δu| ≤ δ/4 keeps the pad closed along the path; |δu̇| ≤ 3 m/s, a fifth of ΩR
    scale = delta / 4 if operator == "K" else 3.0
    direction.setArray(rng.uniform(-scale, scale, direction.getLocalSize()))
    steps = 0.5 ** np.arange(10)
    rest, increments = remainders(residual, field, K if operator == "K" else C, direction,
                                  steps)
    orders = np.log2(rest[:-1] / rest[1:])
    # measured 2.00 ± 0.02 (K̄ and C). A missing term leaves O(h): the friction's convective
    # part (w·∇)u dropped from K̄ (checked) gives 2.0 down to h = 1/32, then 1.8, 1.4, 1.1, 1.0
    assert np.all(np.abs(orders - 2) < 0.1), orders
    assert rest[-1] < 1e-3 * increments[-1]
