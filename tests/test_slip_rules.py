"""Slip rules (Frederiksson 1976; Michałowski & Mróz 1978; Kalker 1986, §7): the elliptic
slip surface against its closed forms, the isotropic case against the Coulomb law as it was
before slip rules, the UFL derivative by a Taylor test, and a 3D block on an oblique belt.

Closed forms for the elliptic surface (p_1/μ_x)² + (p_2/μ_y)² = p_n², slip at the angle θ_s
from t1, friction resistance p = -t at θ_p:

* associated (normality): p = p_n A² w / |A w|, tan θ_p = (μ_y/μ_x)² tan θ_s;
* non-associated: p = μ(θ_s) p_n w/|w|, 1/μ(θ)² = cos²θ/μ_x² + sin²θ/μ_y²;
* in both, |p| = μ(θ_p) p_n (p is on the ellipse, μ(θ) is its polar radius).
"""

from __future__ import annotations

import typing

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem.petsc
import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh

from fenicsfriction import _compat, forms, laws
from fenicsfriction.steady import SteadySolver

MU_X, MU_Y = 0.2, 0.5
EPS = 1e-3


def _polar_radius(theta: np.ndarray) -> np.ndarray:
    """μ(θ) of the ellipse with semi-axes (μ_x, μ_y), written out."""
    return 1.0 / np.sqrt(np.cos(theta) ** 2 / MU_X**2 + np.sin(theta) ** 2 / MU_Y**2)


def _angles(count: int) -> np.ndarray:
    # all four quadrants, away from the axes where tan is 0 or infinite
    return np.linspace(0.0, 2 * np.pi, count, endpoint=False) + 0.1


# --- pointwise (NumPy) ---------------------------------------------------------------------------

def test_associated_traction_is_on_the_ellipse_at_the_closed_form_angle_and_normal_to_it():
    theta_s = _angles(64)
    speed = 1.0  # outside the band |A w| < μ_ref ε: the traction is on the slip surface
    w = speed * np.stack([np.cos(theta_s), np.sin(theta_s)], axis=-1)
    p_n = 3.0
    rule = laws.EllipticSlipRule(MU_X, MU_Y)
    p = -rule.traction(rule.mu_ref * p_n, w, EPS)
    theta_p = np.arctan2(p[:, 1], p[:, 0])
    expected = np.arctan2(MU_Y**2 * np.sin(theta_s), MU_X**2 * np.cos(theta_s))
    # a few flops from exact: round-off
    np.testing.assert_allclose(theta_p, expected, rtol=0, atol=1e-13)
    np.testing.assert_allclose(np.tan(theta_p), (MU_Y / MU_X) ** 2 * np.tan(theta_s), rtol=1e-11)
    # on the slip surface, where its radius is μ(θ_p) p_n
    np.testing.assert_allclose((p[:, 0] / MU_X) ** 2 + (p[:, 1] / MU_Y) ** 2, p_n**2, rtol=1e-13)
    np.testing.assert_allclose(np.linalg.norm(p, axis=-1), _polar_radius(theta_p) * p_n,
                               rtol=1e-13)
    # normality: the slip is along ∇g(p) = (p_1/μ_x², p_2/μ_y²) / (...), outward
    gradient = np.stack([p[:, 0] / MU_X**2, p[:, 1] / MU_Y**2], axis=-1)
    cross = gradient[:, 0] * w[:, 1] - gradient[:, 1] * w[:, 0]
    np.testing.assert_allclose(cross / np.linalg.norm(gradient, axis=-1), 0.0, atol=1e-13)
    assert np.all(np.sum(gradient * w, axis=-1) > 0)
    # and not opposite the slip, except along the axes
    assert np.max(np.abs(np.sin(theta_p - theta_s))) > 0.3


def test_non_associated_traction_opposes_the_slip_with_the_radius_of_the_ellipse():
    theta_s = _angles(64)
    w = 0.7 * np.stack([np.cos(theta_s), np.sin(theta_s)], axis=-1)
    p_n = 2.0
    rule = laws.EllipticSlipRule(MU_X, MU_Y, associated=False)
    p = -rule.traction(rule.mu_ref * p_n, w, EPS)
    np.testing.assert_allclose(p / np.linalg.norm(p, axis=-1)[:, None],
                               w / np.linalg.norm(w, axis=-1)[:, None], rtol=0, atol=1e-14)
    # |w| - ε/2 has no part in the c1 direction outside the band: the magnitude is exact
    np.testing.assert_allclose(np.linalg.norm(p, axis=-1), _polar_radius(theta_s) * p_n,
                               rtol=1e-13)
    np.testing.assert_allclose(rule.slip_function(p, p_n), 0.0, atol=1e-13)


@pytest.mark.parametrize("regularisation", sorted(laws.REGULARISATIONS))
@pytest.mark.parametrize("associated", [True, False])
def test_slip_rules_dissipate(regularisation, associated):
    rng = np.random.default_rng(3)
    # slips across the band and far outside it, and exactly zero
    w = rng.standard_normal((400, 2)) * np.logspace(-5, 1, 400)[:, None]
    w[0] = 0.0
    rule = laws.EllipticSlipRule(MU_X, MU_Y, associated=associated)
    t = rule.traction(1.5, w, EPS, regularisation)
    power = -np.sum(t * w, axis=-1)
    assert np.all(np.isfinite(t))
    assert np.all(power >= 0) and np.all(power[1:] > 0)
    # never beyond the slip surface: g(p) <= 0 with p_n = bound / μ_ref (round-off allowed)
    assert np.all(rule.slip_function(-t, 1.5 / rule.mu_ref) <= 1e-14)


@pytest.mark.parametrize("regularisation", sorted(laws.REGULARISATIONS))
def test_associated_traction_is_minus_the_gradient_of_the_regularised_dissipation(
        regularisation):
    phi = laws.REGULARISATIONS[regularisation][0]
    rule = laws.EllipticSlipRule(MU_X, MU_Y)
    bound = 1.3

    def dissipation(w: np.ndarray) -> np.ndarray:
        # D_ε(w) = bound φ_ε(A w / μ_ref), φ_ε of the norm of the scaled slip
        z = np.stack([MU_X * w[:, 0], MU_Y * w[:, 1]], axis=-1) / rule.mu_ref
        return bound * phi(np.linalg.norm(z, axis=-1), EPS)

    rng = np.random.default_rng(5)
    # inside the band (|A w|/μ_ref < ε) and outside it, 10% away from its edge
    radius = np.concatenate([np.linspace(0.05, 0.9, 20), np.linspace(1.1, 50, 20)]) * EPS
    theta = rng.uniform(0, 2 * np.pi, radius.size)
    z = radius[:, None] * np.stack([np.cos(theta), np.sin(theta)], axis=-1)
    w = z * rule.mu_ref / np.array([MU_X, MU_Y])
    h = 1e-4 * EPS
    gradient = np.stack([(dissipation(w + h * e) - dissipation(w - h * e)) / (2 * h)
                         for e in np.eye(2)], axis=-1)
    # central differences: truncation h² |D'''| ~ (1e-4)² bound/ε^0 (D''' ~ 1/ε², times ε²),
    # round-off u_mach |D| / h ≤ 1e-16 * 0.05 / 1e-7: both below 1e-7 of |t| ~ bound
    np.testing.assert_allclose(-rule.traction(bound, w, EPS, regularisation), gradient,
                               rtol=0, atol=1e-7 * bound)


def test_rotated_frame_gives_the_traction_of_its_components():
    alpha = 0.6  # t1, t2 turned about the normal e_y
    t1, t2 = (np.cos(alpha), 0.0, np.sin(alpha)), (-np.sin(alpha), 0.0, np.cos(alpha))
    rng = np.random.default_rng(7)
    components = rng.standard_normal((50, 2))
    w = components @ np.array([t1, t2])
    for associated in (True, False):
        in_frame = laws.EllipticSlipRule(MU_X, MU_Y, associated=associated)
        global_ = laws.EllipticSlipRule(MU_X, MU_Y, associated=associated, frame=(t1, t2))
        expected = in_frame.traction(1.0, components, EPS) @ np.array([t1, t2])
        np.testing.assert_allclose(global_.traction(1.0, w, EPS), expected, atol=1e-15)


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"mu_x": -0.1, "mu_y": 0.3}, "mu_x"),
    ({"mu_x": 0.1, "mu_y": float("nan")}, "mu_y"),
    ({"mu_x": 0.1, "mu_y": 0.3, "associated": "yes"}, "associated"),
    ({"mu_x": 0.1, "mu_y": 0.3, "frame": ((1, 0, 0), (1, 0, 0))}, "frame"),
    ({"mu_x": 0.1, "mu_y": 0.3, "frame": ((1, 0, 0), (0, 1, 0), (0, 0, 1))}, "frame"),
])
def test_elliptic_rule_rejects_bad_parameter_by_name(kwargs, name):
    with pytest.raises(ValueError, match=f"^{name}="):
        laws.EllipticSlipRule(**kwargs)


def test_friction_traction_rejects_an_unknown_slip_rule():
    with pytest.raises(ValueError, match="^slip_rule="):
        laws.friction_traction(1.0, np.array([1.0]), 1.0, 1.0, EPS, slip_rule="elliptic")


# --- UFL: the assembled term ---------------------------------------------------------------------

def _interface(dim: int, velocity: typing.Callable[[np.ndarray], np.ndarray], n_cells: int = 4):
    """A unit square/cube, its face y = 0 as Γ_C (normal -e_y), u with d > 0 there and
    u̇ = ``velocity(x)`` (rows: nodes); the same fields on any partition."""
    comm = MPI.COMM_WORLD
    if dim == 2:
        msh = _compat.create_rectangle(comm, (0.0, 0.0), (1.0, 1.0), (n_cells, n_cells))
    else:
        msh = _compat.create_box(comm, (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (n_cells,) * 3)
    facets = mesh.locate_entities_boundary(msh, dim - 1, lambda x: np.isclose(x[1], 0.0))
    tags = mesh.meshtags(msh, dim - 1, facets, np.full(len(facets), 1, dtype=np.int32))
    # one rule for every form compared (UFL would estimate a degree per form, up to 1024
    # points per facet here); exact for d² times the bilinear traces
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags, subdomain_id=1,
                     metadata={"quadrature_degree": 4})
    V = _compat.vector_function_space(msh, 1)
    u, u_dot = fem.Function(V), fem.Function(V)
    x = V.tabulate_dof_coordinates()[:, :dim]
    k = np.random.default_rng(11).standard_normal((dim + 1, dim))
    u.x.array[:] = (0.002 * np.sin(x @ k[:dim].T + k[dim]) - 0.01 * np.eye(dim)[1]).ravel()
    u_dot.x.array[:] = velocity(x).ravel()
    for f in (u, u_dot):
        f.x.scatter_forward()
    frame = ((1.0, 0.0), ) if dim == 2 else ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    return u, u_dot, ufl.FacetNormal(msh), ds, frame


def _wave(x: np.ndarray, amplitude: float) -> np.ndarray:
    """A smooth field of the given amplitude in every component, a function of position."""
    dim = x.shape[1]
    k = np.random.default_rng(13).standard_normal((dim + 1, dim))
    return amplitude * np.cos(3 * x @ k[:dim].T + k[dim])


def _ramp(x: np.ndarray) -> np.ndarray:
    """Slips from -ε to 3ε along x, with a wave on top: across the c1 band and out of it."""
    return 4 * EPS * x[:, :1] - EPS + _wave(x, 0.5 * EPS)


def _assemble(form: ufl.Form, fields: tuple) -> tuple[PETSc.Vec, list[PETSc.Mat]]:
    b = dolfinx.fem.petsc.assemble_vector(_compat.form(form))
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    V = fields[0].function_space
    matrices = []
    for field in fields:
        A = dolfinx.fem.petsc.assemble_matrix(
            _compat.form(ufl.derivative(form, field, ufl.TrialFunction(V))))
        A.assemble()
        matrices.append(A)
    return b, matrices


def _friction_form(u, u_dot, n, ds, law, U_T=None):
    v = ufl.TestFunction(u.function_space)
    U_T = ufl.zero(len(u)) if U_T is None else U_T
    return forms.friction(u, u_dot, v, n, law, U_T, ds)


def _law(c_n, slip_rule, regularisation, mu=0.0):
    """m_n = 2, no gap; an elliptic rule's bound is μ_ref c_n."""
    return laws.InterfaceLaw(c_n=c_n, m_n=2.0, mu=mu, eps=EPS, regularisation=regularisation,
                             slip_rule=slip_rule)


@pytest.mark.parametrize(("dim", "associated", "regularisation"),
                         [(2, True, "c1"), (3, True, "smooth"), (2, False, "smooth"),
                          (3, False, "c1")])
def test_isotropic_rules_reproduce_the_coulomb_term(dim, associated, regularisation):
    u, u_dot, n, ds, frame = _interface(dim, _ramp)
    mu, c_n = 0.3, 50.0
    v = ufl.TestFunction(u.function_space)
    # the Coulomb term written out as before slip rules: c_T d^m φ'_ε(w)·v_T
    d = laws.penetration(forms.normal_part(u, n))
    w = forms.tangential_part(u_dot, n)
    direction = laws.REGULARISATIONS[regularisation][1](w, EPS)
    by_hand = mu * c_n * d**2.0 * ufl.inner(direction, forms.tangential_part(v, n)) * ds
    b_ref, A_ref = _assemble(by_hand, (u, u_dot))
    rule = laws.EllipticSlipRule(mu, mu, associated=associated, frame=frame)
    for slip_rule, tol in ((None, 0.0), (laws.CoulombSlipRule(), 0.0), (rule, 1e-12)):
        b, A = _assemble(_friction_form(u, u_dot, n, ds, _law(c_n, slip_rule, regularisation, mu)),
                         (u, u_dot))
        # the Coulomb rule is today's expression: the same code, the same bits (tol 0); the
        # isotropic ellipse reaches it through μ w / μ and sqrt(μ²/1): a few ulps per entry
        b.axpy(-1.0, b_ref)
        assert b.norm() <= tol * b_ref.norm(), (slip_rule, b.norm(), b_ref.norm())
        assert b_ref.norm() > 0
        for J, J_ref in zip(A, A_ref, strict=True):
            J.axpy(-1.0, J_ref, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            assert J.norm() <= tol * J_ref.norm(), (slip_rule, J.norm(), J_ref.norm())
            assert J_ref.norm() > 0
    # the band is crossed: some slips are inside it, some outside
    slips = np.abs(u_dot.x.array.reshape(-1, dim)[:, 0])
    comm = MPI.COMM_WORLD
    assert comm.allreduce(slips.min(), op=MPI.MIN) < EPS < comm.allreduce(slips.max(),
                                                                            op=MPI.MAX)


def _sliding(x: np.ndarray) -> np.ndarray:
    """An oblique slip of 5 ε with a wave of ε/2: outside the band everywhere."""
    return 5 * EPS * np.array([np.cos(0.5), 0.0, np.sin(0.5)]) + _wave(x, 0.5 * EPS)


def _near_rest(x: np.ndarray) -> np.ndarray:
    """Slips of at most ε/5 of either sign: inside the band everywhere, through w = 0."""
    return _wave(x, 0.2 * EPS)


@pytest.mark.parametrize(("associated", "velocity"),
                         [(True, _sliding), (True, _near_rest), (False, _sliding)],
                         ids=["associated-sliding", "associated-near-rest",
                              "non-associated-sliding"])
def test_elliptic_friction_term_passes_the_taylor_test_in_3d(associated, velocity):
    u, u_dot, n, ds, frame = _interface(3, velocity)
    rule = laws.EllipticSlipRule(MU_X, MU_Y, associated=associated, frame=frame)
    form = _friction_form(u, u_dot, n, ds, _law(50.0, rule, "c1"))
    L = _compat.form(form)
    b0, (J_u, J_v) = _assemble(form, (u, u_dot))
    x = u.function_space.tabulate_dof_coordinates()
    du = _wave(x, 1.0).ravel()
    du_vec = b0.duplicate()
    du_vec.array[:] = du[:len(du_vec.array)]
    # one step in u (through d) and in u_dot (through w): J du = (J_u + J_v) du
    Jdu, J_v_du = b0.duplicate(), b0.duplicate()
    J_u.mult(du_vec, Jdu)
    J_v.mult(du_vec, J_v_du)
    Jdu.axpy(1.0, J_v_du)
    u0, v0 = u.x.array.copy(), u_dot.x.array.copy()
    remainders = []
    # steps far below the distance of the slips to the band's edge |A w| = μ_ref ε (where the
    # c1 traction is only Lipschitz: a step across it leaves an O(h) remainder)
    for h in (4e-6, 2e-6, 1e-6):
        for f, f0 in ((u, u0), (u_dot, v0)):
            f.x.array[:] = f0 + h * EPS * du
            f.x.scatter_forward()
        b = dolfinx.fem.petsc.assemble_vector(L)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        b.axpy(-1.0, b0)
        assert b.norm() > 0
        b.axpy(-h * EPS, Jdu)
        remainders.append(b.norm())
    rates = np.log2(np.array(remainders[:-1]) / remainders[1:])
    # a consistent Jacobian leaves an O(h²) remainder; a wrong one O(h) (rate 1)
    assert rates.min() > 1.9, (rates, remainders)


@pytest.mark.parametrize("associated", [True, False])
def test_friction_jacobian_at_rest_is_finite_and_the_band_stiffness(associated):
    u, u_dot, n, ds, frame = _interface(3, lambda x: np.zeros_like(x))  # w = 0 exactly
    rule = laws.EllipticSlipRule(MU_X, MU_Y, associated=associated, frame=frame)
    c_T = rule.mu_ref * 50.0
    _, (J,) = _assemble(_friction_form(u, u_dot, n, ds, _law(50.0, rule, "c1")), (u_dot,))
    values = J.getValuesCSR()[2]  # this rank's rows: a rank may hold no contact facet
    comm = MPI.COMM_WORLD
    assert comm.allreduce(np.all(np.isfinite(values)), op=MPI.LAND)
    assert comm.allreduce(np.abs(values).max(initial=0.0), op=MPI.MAX) > 0
    # inside the band the associated traction is linear, -c_T d^m A² w / (μ_ref² ε): its
    # stiffness, written out; the non-associated one at w = 0 (where it has no derivative,
    # being homogeneous of degree 1 but not linear) is the Coulomb band's at μ_ref
    d = laws.penetration(forms.normal_part(u, n))
    v = ufl.TestFunction(u.function_space)
    t1, t2 = (ufl.as_vector(t) for t in frame)
    stretch = ((MU_X / rule.mu_ref) ** 2, (MU_Y / rule.mu_ref) ** 2) if associated else (1, 1)
    w = forms.tangential_part(u_dot, n)
    A2w = stretch[0] * ufl.dot(w, t1) * t1 + stretch[1] * ufl.dot(w, t2) * t2
    by_hand = c_T * d**2.0 / EPS * ufl.inner(A2w, forms.tangential_part(v, n)) * ds
    _, (J_ref,) = _assemble(by_hand, (u_dot,))
    J.axpy(-1.0, J_ref, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    # the same products in another order: round-off
    assert J.norm() <= 1e-12 * J_ref.norm()


# --- a 3D block sliding on an oblique belt --------------------------------------------------------

def _block_on_oblique_belt(rule: laws.EllipticSlipRule, belt_angle: float, pressure: float
                           ) -> tuple[np.ndarray, float]:
    """An elastic block 1 x 0.25 x 1 pressed by ``pressure`` on its top (y = 0.25) onto a rigid
    belt (y = 0) that moves at unit speed at ``belt_angle`` from e_x in the x-z plane; the top
    face is held in x and z (free in y, so the belt carries the whole load). Steady sliding
    (u̇ = 0) solved with Newton; returns the friction force on the block, minus the reaction
    of the holding face, and the normal force."""
    comm = MPI.COMM_WORLD
    L, H, B = 1.0, 0.25, 1.0
    msh = _compat.create_box(comm, (0.0, 0.0, 0.0), (L, H, B), (4, 2, 4))
    fdim = 2
    contact = mesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[1], 0.0))
    top = mesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[1], H))
    facets = np.concatenate([contact, top])
    order = np.argsort(facets)
    tags = mesh.meshtags(msh, fdim, facets[order], np.concatenate(
        [np.full(len(contact), 1, dtype=np.int32), np.full(len(top), 2, dtype=np.int32)])[order])
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags, metadata={"quadrature_degree": 2})
    V = _compat.vector_function_space(msh, 1)
    u, u_dot, u_ddot = (fem.Function(V, name=name) for name in ("u", "u_dot", "u_ddot"))
    v = ufl.TestFunction(V)
    c_n, m_n = 1e4, 1.0
    law = laws.InterfaceLaw(c_n=c_n, m_n=m_n, eps=EPS, slip_rule=rule)
    belt = fem.Constant(msh, np.array([np.cos(belt_angle), 0.0, np.sin(belt_angle)]))
    n = ufl.FacetNormal(msh)
    terms = forms.elasticity(u, v, 1e3, 0.3, ufl.dx(domain=msh)) \
        + forms.normal_compliance(u, v, n, law, ds(1)) \
        + forms.friction(u, u_dot, v, n, law, belt, ds(1)) \
        + forms.surface_traction(ufl.as_vector([0.0, -pressure, 0.0]), v, ds(2))
    held = [fem.locate_dofs_topological(V.sub(i), fdim, top) for i in (0, 2)]
    bcs = [fem.dirichletbc(PETSc.ScalarType(0), dofs, V.sub(i))
           for i, dofs in zip((0, 2), held, strict=True)]
    residual = forms.Residual(form=terms, u=u, u_dot=u_dot, u_ddot=u_ddot, v=v, bcs=bcs)
    # start at the uniform penetration the pressure makes: the compliance is stiff at once
    u.x.array.reshape(-1, 3)[:, 1] = -pressure / c_n
    u.x.scatter_forward()
    SteadySolver(residual, prefix="slip_rule_block_", linear_solver="lu").solve()
    # the residual without its Dirichlet rows: the holding face's reaction on its dofs
    R = dolfinx.fem.petsc.assemble_vector(_compat.form(residual.steady()))
    R.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    owned = V.dofmap.index_map.size_local * V.dofmap.index_map_bs
    reaction = np.zeros(3)
    for i, dofs in zip((0, 2), held, strict=True):
        reaction[i] = R.array[dofs[dofs < owned]].sum()
    return -comm.allreduce(reaction), pressure * L * B


@pytest.mark.parametrize("associated", [True, False])
def test_block_on_oblique_belt_feels_the_friction_force_of_the_slip_rule(associated):
    belt_angle, pressure = 0.5, 10.0
    rule = laws.EllipticSlipRule(MU_X, MU_Y, associated=associated,
                                 frame=((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    force, normal_force = _block_on_oblique_belt(rule, belt_angle, pressure)
    # the slip of the block on the belt is -U: the friction force on the block, opposite the
    # slip (non-associated) or at tan θ = (μ_y/μ_x)² tan(belt angle) (normality)
    expected_angle = np.arctan2(MU_Y**2 * np.sin(belt_angle), MU_X**2 * np.cos(belt_angle)) \
        if associated else belt_angle
    angle = np.arctan2(force[2], force[0])
    # every contact point slips at the belt's velocity, far outside the band (|A U|/μ_ref ≥
    # 0.4 ≫ ε): each traction is exactly μ(θ) p_n along the closed-form direction, and the
    # sum of the p_n balances the top load; what is left is Newton's residual (atol 1e-9)
    # against forces of order 1
    assert angle == pytest.approx(expected_angle, abs=1e-8)
    assert np.hypot(force[0], force[2]) == pytest.approx(
        _polar_radius(expected_angle) * normal_force, rel=1e-8)
    assert force[1] == 0.0  # nothing holds the block in y but the belt
    # normality turns the force away from the belt (here by 0.79 rad); the other rule does not
    assert (abs(angle - belt_angle) > 0.5) == associated
