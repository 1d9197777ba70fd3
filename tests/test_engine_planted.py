"""The engine's small pieces against closed forms and dense references: the tests that kill the
planted bugs (tests/planted_bugs.toml) no end-to-end test noticed.

* A nodal spring's force -K (u - U) with an anchor U other than 0 (every scene anchors at 0).
* The secant predictor of continuation (Keller 1977) is exact on a path linear in the
  parameter.
* The normal and tangential parts of a vector on a facet, w_n = w.n and w_T = w - w_n n, for
  a normal off the axes (every scene's contact normal is a coordinate axis, where a wrong sign
  in w_T changes only the normal component, which friction's tangential traction ignores).
* An eigenpair's relative residual is the backward error of the module docstring of
  :mod:`fenicsfriction.stability`, written out here with NumPy's complex arithmetic.
* The modal assurance criterion |a^H b|^2 / ((a^H a)(b^H b)) of complex vectors (Allemang &
  Brown 1982): 1 for a complex multiple, 0 for orthogonal vectors.
* Central differences on a body held by uniform distributed springs, k u per unit volume: the
  consistent matrices are K = (k/rho) M_c, and Q1 mass entries are all positive with the row
  sums of the lumped mass, so the largest eigenvalue of M_L^{-1} K is k/rho (the rigid
  translation), and the stable step is 2 sqrt(rho/k). A dashpot c per unit volume gives the
  stick-band bound 2 m_i/(kappa c_i) = 2 rho/(kappa c). The rigid translation is then one
  undamped oscillator x'' = -omega^2 x, whose central-difference solution from x_0 = 1,
  v_0 = 0 is exactly cos(n theta), cos theta = 1 - (omega dt)^2 / 2: x_{n+1} - 2 x_n + x_{n-1} =
  -(omega dt)^2 x_n has the roots e^{+-i theta}, and the half step v_{1/2} = (dt/2) a_0 starts it
  at x_1 = cos theta (central differences and their stable step: Hughes 1987, chapter 9).
"""

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest
import ufl
from dolfinx import fem

from fenicsfriction import _compat, forms
from fenicsfriction.dynamics import CentralDifference
from fenicsfriction.stability import mac, relative_residual
from fenicsfriction.steady import SteadySolver, continuation

COMM = MPI.COMM_WORLD


def _matrix(values: np.ndarray) -> PETSc.Mat:
    A = PETSc.Mat().createDense(values.shape, array=values.copy(), comm=MPI.COMM_SELF)
    A.assemble()
    return A


def test_relative_residual_is_the_backward_error_written_out_in_complex_arithmetic():
    """(lambda^2 M + lambda C + K) w over (|lambda|^2 ||M|| + |lambda| ||C|| + ||K||) ||w||,
    norms of infinity for the matrices, 2 for the vector: agreement to round-off (1e-12)."""
    rng = np.random.default_rng(27)
    n = 6
    K, C, M = (rng.normal(size=(n, n)) for _ in range(3))
    lam = complex(0.7, 1.3)
    w = rng.normal(size=n) + 1j * rng.normal(size=n)
    expected = (np.linalg.norm((lam**2 * M + lam * C + K) @ w)
                / ((abs(lam) ** 2 * np.abs(M).sum(axis=1).max()
                    + abs(lam) * np.abs(C).sum(axis=1).max()
                    + np.abs(K).sum(axis=1).max()) * np.linalg.norm(w)))
    matrices = tuple(_matrix(A) for A in (K, C, M))
    norms = tuple(A.norm(PETSc.NormType.INFINITY) for A in matrices)
    xr, xi = (PETSc.Vec().createWithArray(part.copy(), comm=MPI.COMM_SELF)
              for part in (w.real, w.imag))
    assert relative_residual(matrices, norms, lam, xr, xi) == pytest.approx(expected, rel=1e-12)
    for obj in (*matrices, xr, xi):
        obj.destroy()


def test_mac_is_one_for_a_complex_multiple_and_zero_for_orthogonal_complex_vectors():
    """Each rank holds a piece of the vectors (a = (1, i) on every rank), chosen so that
    a^T b, without the conjugate, would give the opposite answers (0 and 1)."""
    a = np.array([1.0, 1.0j])
    orthogonal = np.array([1.0j, 1.0])  # a^H b = i - i = 0, but a^T b = 2i
    assert mac(a, (2.0 - 3.0j) * a, COMM) == pytest.approx(1.0, rel=1e-14)
    assert mac(a, orthogonal, COMM) == pytest.approx(0.0, abs=1e-14)
    rng = np.random.default_rng(COMM.rank)
    x, y = (rng.normal(size=5) + 1j * rng.normal(size=5) for _ in range(2))
    xs, ys = np.concatenate(COMM.allgather(x)), np.concatenate(COMM.allgather(y))
    expected = abs(np.sum(np.conj(xs) * ys)) ** 2 / (np.sum(abs(xs) ** 2) * np.sum(abs(ys) ** 2))
    assert mac(x, y, COMM) == pytest.approx(expected, rel=1e-12)


def test_normal_and_tangential_parts_of_a_vector_on_an_oblique_facet():
    """w = (1, 2), n = (0.6, 0.8): w_n = 2.2, w_T = (1 - 1.32, 2 - 1.76) = (-0.32, 0.24), which
    is orthogonal to n; integrated over the unit square (exact: constants)."""
    msh = _compat.create_rectangle(COMM, [0.0, 0.0], [1.0, 1.0], [2, 2])
    dx = ufl.dx(domain=msh)
    w, n = ufl.as_vector([1.0, 2.0]), ufl.as_vector([0.6, 0.8])

    def integral(expression) -> float:
        return COMM.allreduce(fem.assemble_scalar(_compat.form(expression * dx)))

    assert integral(forms.normal_part(w, n)) == pytest.approx(2.2, rel=1e-14)
    w_T = forms.tangential_part(w, n)
    assert integral(w_T[0]) == pytest.approx(-0.32, rel=1e-13)
    assert integral(w_T[1]) == pytest.approx(0.24, rel=1e-13)


def test_a_nodal_spring_pulls_towards_its_anchor():
    """K = 5 at (1, 1) along x, anchored at U = 0.3, the node at x = 0.1: the residual gains
    K (u - U) = -1 on that dof alone, and the spring's force on the body is -K (u - U) = +1."""
    msh = _compat.create_rectangle(COMM, [0.0, 0.0], [1.0, 1.0], [2, 2])
    V = _compat.vector_function_space(msh, 1)
    spring = forms.NodalSpring.at_point(V, [1.0, 1.0], 0, stiffness=5.0, anchor=0.3)
    u = fem.Function(V)
    u.x.array[:] = 0.1
    b = np.zeros_like(u.x.array)
    spring.add_to_residual(b, u.x.array)
    assert COMM.allreduce(b.sum()) == pytest.approx(-1.0, rel=1e-14)
    assert COMM.allreduce(np.count_nonzero(b)) == 1
    assert spring.force(u) == pytest.approx(1.0, rel=1e-14)


def test_the_secant_predictor_is_exact_where_the_state_is_linear_in_the_parameter():
    """A clamped linear elastic square under a body force p (0, -1): u(p) = p u(1), so from the
    third value on the secant extrapolation u_c + (u_c - u_p)(p - c)/(c - p_prev) is the
    solution itself and Newton stops at its first residual (0 iterations); the first two solves
    (from 0 and from the last state) take one iteration each, the problem being linear."""
    msh = _compat.create_rectangle(COMM, [0.0, 0.0], [1.0, 1.0], [4, 4])
    V = _compat.vector_function_space(msh, 1)
    u, zero = fem.Function(V), fem.Function(V)
    v = ufl.TestFunction(V)
    dx = ufl.dx(domain=msh)
    load = fem.Constant(msh, 0.0)
    form = (forms.elasticity(u, v, 1.0, 0.3, dx)
            + forms.body_force(load * ufl.as_vector([0.0, -1.0]), v, dx))
    clamped = fem.locate_dofs_geometrical(V, lambda x: np.isclose(x[0], 0.0))
    bc = fem.dirichletbc(np.zeros(2), clamped, V)
    residual = forms.Residual(form=form, u=u, u_dot=zero, u_ddot=zero, v=v, bcs=[bc])
    solver = SteadySolver(residual, prefix="planted_secant_", options={"snes_atol": 1e-11})
    records = continuation(solver, load, [1.0, 2.0, 3.0, 4.5], predictor="secant")
    assert [r["newton_iterations"] for r in records] == [1, 0, 0, 0]
    assert records[-1]["residual_norm"] < 1e-11


RHO, K_SPRING, DAMPING = 2.0, 8.0, 6.0  # omega^2 = k/rho = 4


def _springs_on_a_square() -> forms.Residual:
    """A unit square (4 x 4 Q1) of density rho held by springs k u in every point."""
    msh = _compat.create_rectangle(COMM, [0.0, 0.0], [1.0, 1.0], [4, 4])
    V = _compat.vector_function_space(msh, 1)
    u, u_dot, u_ddot = fem.Function(V), fem.Function(V), fem.Function(V)
    v = ufl.TestFunction(V)
    dx = ufl.dx(domain=msh)
    form = (forms.inertia(RHO, u_ddot, v, dx)
            + forms.elastic_support(u, v, K_SPRING, ufl.as_vector([0.0, 0.0]), dx))
    return forms.Residual(form=form, u=u, u_dot=u_dot, u_ddot=u_ddot, v=v)


def test_explicit_stable_steps_are_two_over_omega_max_and_two_m_over_kappa_c():
    """2/omega_max = 2 sqrt(rho/k) = 1 (SLEPc's tolerance 1e-6 on omega^2); the band's
    2 rho/(kappa c) = 1/3 at kappa = 2 (a ratio of assembled row sums: round-off)."""
    residual = _springs_on_a_square()
    band = DAMPING * residual.v[0] * ufl.dx(domain=residual.V.mesh)
    explicit = CentralDifference(residual, band_damping=band, band_margin=2.0)
    assert explicit.stable_dt_elastic == pytest.approx(2.0 * np.sqrt(RHO / K_SPRING), rel=1e-5)
    assert explicit.stable_dt_band == pytest.approx(2.0 * RHO / (2.0 * DAMPING), rel=1e-12)
    assert explicit.stable_dt == explicit.stable_dt_band


def test_central_differences_follow_the_discrete_cosine_of_the_rigid_translation():
    """From u = (1, 0), u' = 0 every node moves as x_n = cos(n theta), cos theta =
    1 - (omega dt)^2/2, exactly (to round-off, 1e-12), at dt = 0.25 < 0.9 x 2/omega."""
    residual = _springs_on_a_square()
    residual.u.x.array[0::2] = 1.0
    explicit = CentralDifference(residual)
    dt = 0.25
    records = explicit.run(5.0, dt, observe=lambda t: {
        "x": residual.u.x.array[0::2].copy(), "y": residual.u.x.array[1::2].copy()})
    theta = np.arccos(1.0 - (np.sqrt(K_SPRING / RHO) * dt) ** 2 / 2)
    assert len(records) == 21
    for n, record in enumerate(records):
        assert record["time"] == pytest.approx(n * dt, rel=1e-12)
        assert np.abs(record["x"] - np.cos(n * theta)).max() < 1e-12
        assert np.abs(record["y"]).max() == 0.0
