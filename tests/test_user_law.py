"""A researcher's friction law, written once here (outside the package) and passed unchanged to
the finite element block, the rigid block and the law's own derivatives.

μ(s, p) = (μ_k + (μ_s - μ_k) e^{-s/v_s}) (1 + p/p_ref)^α falls with the slip speed s and rises
with the pressure p; it uses only operations valid on UFL, NumPy and the law's dual numbers.
"""

import dataclasses

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem.petsc
import numpy as np
import pytest
import scipy.integrate
import scipy.optimize
from dolfinx import fem

import fenicsfriction as ff
from fenicsfriction import _compat, laws
from fenicsfriction.contact import solve_with_search
from fenicsfriction.studies.block import RigidBlock, rigid_block_observables
from fenicsfriction.studies.block.data import CONTACT
from fenicsfriction.studies.oscillators import BeltOscillator

MU_S, MU_K, V_S, P_REF, ALPHA = 0.6, 0.4, 0.1, 0.2, 0.3


def user_mu(speed, pressure):
    """The user's law: Stribeck-like in the speed, a power of the pressure."""
    return (MU_K + (MU_S - MU_K) * laws.exp(-speed / V_S)) * (1 + pressure / P_REF) ** ALPHA


LAW = ff.InterfaceLaw(friction_coefficient=user_mu, eps=1e-3)
BELT_SPEED = ff.BlockOnBelt().belt_speed  # [cm/s], the scenes' default U


def user_mu_at_belt_speed(speed, pressure):
    """The user's μ with the speed frozen at the belt's: the same μ(U, p) in steady sliding
    (every point slips at U), but no slope in the speed."""
    return user_mu(BELT_SPEED, pressure)


@pytest.mark.parametrize("w", [-0.3, -2e-4, 5e-4, 0.05])
@pytest.mark.parametrize("regularisation", ["c1", "smooth"])
def test_numpy_derivatives_of_the_user_law_are_its_central_differences(w, regularisation):
    """∂t/∂d and ∂t/∂w from dual numbers against central differences, h = 1e-6 of the variable:
    truncation h² |t'''| and round-off u_mach |t|/h, both below 1e-7 relative."""
    law = LAW.replace(regularisation=regularisation)
    d = np.array([2e-5, 6e-5, 1e-4])
    dt_dd, dt_dw = law.friction_traction_derivatives(d, w)
    h_d, h_w = 1e-6 * d, 1e-6 * max(abs(w), law.eps)
    fd_d = (law.friction_traction(d + h_d, w) - law.friction_traction(d - h_d, w)) / (2 * h_d)
    fd_w = (law.friction_traction(d, w + h_w) - law.friction_traction(d, w - h_w)) / (2 * h_w)
    np.testing.assert_allclose(dt_dd, fd_d, rtol=1e-7)
    np.testing.assert_allclose(dt_dw, fd_w, rtol=1e-7, atol=1e-7 * np.abs(fd_w).max())


def test_rigid_block_with_the_user_law_slides_where_the_spring_balances_mu_p():
    """Steady sliding of the rigid block: the spring holds B0 ∫ μ(U, p(s)) p(s) ds, computed
    here by adaptive quadrature on the block's penetration profile (statics and the law, not the
    block's own integration rule); tolerance: the Newton tolerance 1e-12 of the weight plus the
    64-point Gauss rule on a smooth integrand."""
    block = RigidBlock(law=LAW)
    q = block.steady_state()
    observed = rigid_block_observables(block, q, np.zeros(3))
    U = block.belt_speed

    def traction(s):
        d = max(-q[1] - q[2] * s, 0.0)
        p = LAW.c_n * d**LAW.m_n
        return user_mu(U, p) * p

    expected = block.B0 * scipy.integrate.quad(traction, -block.L / 2, block.L / 2,
                                               epsabs=0, epsrel=1e-13)[0]
    assert observed["spring_force"] == pytest.approx(-expected, rel=1e-9)
    assert observed["friction_force"] == pytest.approx(expected, rel=1e-9)
    # the law acts: the pressure-dependent coefficient is not μ at p = 0
    assert expected / observed["normal_force"] > MU_K * 1.001


@pytest.fixture(scope="module")
def fe_block():
    scene = ff.BlockOnBelt(law=LAW)
    model = scene.build(MPI.COMM_WORLD)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix="user_law_", options=model.solver_options())
    report = solver.solve()
    return scene, model, report


def test_fe_block_with_the_user_law_balances_spring_and_friction(fe_block):
    """Statics: the spring force equals the friction resultant, which is the law's μ(U, p) p
    integrated over Γ_C (the UFL integral of the law, written here, not the model's); rows
    of a converged residual: 1e-8 of the load."""
    scene, model, _ = fe_block
    q = model.quantities()
    spring = model.spring.force(model.residual.u)
    assert spring == pytest.approx(-q.friction_force, abs=1e-8 * scene.weight)
    p = model.pressure()
    expected = model.msh.comm.allreduce(fem.assemble_scalar(_compat.form(
        scene.B0 * user_mu(scene.belt_speed, p) * p * model.ds_contact)), op=MPI.SUM)
    assert q.friction_force == pytest.approx(expected, rel=1e-10)
    assert q.friction_force / q.normal_force > MU_K * 1.001


def test_jacobian_with_the_user_law_passes_the_taylor_test(fe_block):
    """‖R(u + h δ) - R(u) - h J δ‖ falls as h² (ufl.derivative of the residual holding the user's
    law, through Residual.steady_jacobian): the ratio of successive remainders at h, h/2 is 4."""
    _, model, _ = fe_block
    R = model.residual
    F, J = _compat.form(R.steady()), _compat.form(R.steady_jacobian())
    u0 = R.u.x.array.copy()
    rng = np.random.default_rng(0)
    delta = fem.Function(R.V)
    delta.x.array[:] = 1e-6 * rng.standard_normal(len(u0))
    delta.x.scatter_forward()

    def residual() -> np.ndarray:
        b = dolfinx.fem.petsc.assemble_vector(F)
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        return b

    b0 = residual()
    A = dolfinx.fem.petsc.assemble_matrix(J)
    A.assemble()
    Jd = A.createVecLeft()
    A.mult(_compat.petsc_vec(delta), Jd)
    remainders = []
    for h in (1.0, 0.5, 0.25):
        R.u.x.array[:] = u0 + h * delta.x.array
        R.u.x.scatter_forward()
        b = residual()
        b.axpy(-1.0, b0)
        b.axpy(-h, Jd)
        remainders.append(b.norm())
    R.u.x.array[:] = u0
    R.u.x.scatter_forward()
    rates = np.log2(np.array(remainders[:-1]) / np.array(remainders[1:]))
    assert rates == pytest.approx([2.0, 2.0], abs=0.1), remainders


def test_block_on_a_stiff_slab_with_the_user_law_carries_mu_p_at_every_node():
    """Two-body node-to-segment contact (the block on a slab 1e3 times stiffer) with the same
    law object: in steady sliding every slave node slips at U, so the friction resultant is
    B0 Σ_i A_i μ(U, p_i) p_i over the nodes' tributary lengths A_i and penetrations (read off the
    nodes, the law evaluated here), and the spring holds it. Tolerance 1e-6: the slab's top
    tilts by its compression (~1e-4 of the penetration over the block's length), which moves
    the x-component of the traction by its square."""
    scene = ff.BlockOnSlab(slab_E=1.4e9, slab_thickness=5.0, law=LAW)
    model = scene.build(MPI.COMM_WORLD)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix="user_law_slab_",
                             options=model.solver_options())
    solve_with_search(solver, [model.contact])  # the block slides ~23 cm along the slab
    q = model.quantities()
    d, slip, _ = model.nodal_contact()
    lengths = model.contact.nodal_weights[model.contact.pairing.slave_nodes]
    p = LAW.c_n * d**LAW.m_n
    local = scene.B0 * np.sum(lengths * user_mu(np.abs(slip), p) * p)
    expected = model.msh.comm.allreduce(local, op=MPI.SUM)
    assert np.allclose(np.abs(slip), scene.belt_speed, rtol=1e-9)
    assert q.friction_force == pytest.approx(expected, rel=1e-6)
    assert model.spring.force(model.residual.u) == pytest.approx(-expected, rel=1e-6)


class _BeltSpeed:
    """The belt speed U as the scalar parameter of :func:`fenicsfriction.continuation`: the
    model holds the belt's velocity as a vector ``fem.Constant`` U e_x."""

    def __init__(self, velocity: fem.Constant):
        self.velocity = velocity
        self.direction = velocity.value / np.linalg.norm(velocity.value)

    @property
    def value(self) -> float:
        return float(self.velocity.value @ self.direction)

    @value.setter
    def value(self, speed: float) -> None:
        self.velocity.value = speed * self.direction


def test_continuation_in_the_belt_speed_keeps_the_user_law_in_balance():
    """A steady continuation of the FE block with the user's law over the belt speed U, from
    2 v_s down to v_s/2, where μ(U, p) rises by 28 % with the Stribeck term: at every step the
    spring holds the friction resultant, which is the user's μ(U, p) p integrated over Γ_C
    at that U (the UFL integral written here). The balance is the sum of the residual's rows
    along the belt, so Cauchy-Schwarz bounds it by sqrt(n) times the residual norm each step's
    Newton stopped at; the friction against its integral as in the single solve above."""
    scene = ff.BlockOnBelt(law=LAW)
    model = scene.build(MPI.COMM_WORLD)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix="user_law_path_",
                             options=model.solver_options())
    solver.solve()
    speed = _BeltSpeed(model.belt_velocity)
    assert speed.value == pytest.approx(scene.belt_speed)
    comm = model.msh.comm

    def check() -> dict:
        q = model.quantities()
        spring = model.spring.force(model.residual.u)
        p = model.pressure()
        expected = comm.allreduce(fem.assemble_scalar(_compat.form(
            scene.B0 * user_mu(speed.value, p) * p * model.ds_contact)), op=MPI.SUM)
        return {"spring": spring, "friction": q.friction_force, "expected": expected,
                "normal": q.normal_force}

    targets = np.linspace(2 * V_S, V_S / 2, 7)
    records = ff.continuation(solver, speed, targets, observe=check)
    assert [r["value"] for r in records] == pytest.approx(targets)
    for r in records:
        dofmap = model.residual.V.dofmap
        bound = np.sqrt(dofmap.index_map.size_global * dofmap.index_map_bs) * r["residual_norm"]
        assert abs(r["spring"] + r["friction"]) <= bound, (r, bound)
        assert r["friction"] == pytest.approx(r["expected"], rel=1e-10)
    # the path moves: the slower belt pulls harder (the user's μ falls with the speed)
    ratio = records[-1]["friction"] / records[0]["friction"]
    assert ratio > 1.1, ratio


def test_point_contact_force_and_slope_of_the_user_law():
    """The mesh-free models' pieces of the law (belt oscillator, m.d.o.f. slider): the friction
    force of a point contact is -μ(|w|, N) N φ'_ε(w) (the smooth direction written here), and
    the speed slope of the user's μ (dual numbers) is its central difference (step 1e-6 v_s:
    truncation ~1e-12, round-off ~1e-10 relative)."""
    law = LAW.replace(regularisation="smooth")
    N, w = 2.0, np.array([-0.3, -1e-4, 0.0, 2e-4, 0.05])
    expected = -user_mu(np.abs(w), N) * N * w / np.sqrt(w**2 + law.eps**2)
    assert law.friction_force(N, w) == pytest.approx(expected, rel=1e-14, abs=0)
    s, h = np.array([1e-3, 0.05, 0.3]), 1e-6 * V_S
    central = (user_mu(s + h, N) - user_mu(s - h, N)) / (2 * h)
    assert law.coefficient_slope(s, N) == pytest.approx(central, rel=1e-7)
    belt = BeltOscillator(m=1.0, k=1.0, c=0.1, N=N, v_belt=0.05, law=law)
    assert belt.effective_damping() == pytest.approx(0.1 + N * central[1], rel=1e-7)


# --- stability of steady sliding --------------------------------------------------------------

def _sliding(scene: ff.BlockOnBelt, name: str) -> ff.BlockModel:
    """The FE block of ``scene`` in steady sliding, from the model's initial guess."""
    model = scene.build(MPI.COMM_WORLD, with_friction=True)
    model.initial_guess()
    ff.SteadySolver(model.residual, prefix=f"user_law_{name}_",
                    options=model.solver_options()).solve()
    return model


def _stiff_block_gap(scene: ff.BlockOnBelt, name: str) -> tuple[np.ndarray, np.ndarray]:
    """The rigid block's eigenvalues (Im λ >= 0; dense, from its own (M, C, K̄), the law's dual
    numbers) and the FE block's in |λ| <= 1.5 max |λ_rigid| (SLEPc), paired nearest first, and
    the gaps |λ_FE - λ_rigid| / |λ_rigid|."""
    rigid_block = RigidBlock.from_scene(scene)
    assert rigid_block.law is scene.law  # the user's object itself, never a copy or a constant
    rigid = rigid_block.eigenvalues(rigid_block.steady_state())
    rigid = rigid[rigid.imag >= 0]
    model = _sliding(scene, name)
    stability = ff.StabilitySolver(model.residual, prefix=f"user_law_{name}_pep_")
    modes = stability.solve(max_modulus=1.5 * abs(rigid).max())
    assert all(m.accurate for m in modes), [m.residual for m in modes]
    fe = np.array([m.value for m in modes])
    assert len(fe) == len(rigid), (fe, rigid)
    rows, cols = scipy.optimize.linear_sum_assignment(abs(fe[:, None] - rigid[None, :]))
    return rigid[cols], abs(fe[rows] - rigid[cols]) / abs(rigid[cols])


def test_stiff_fe_block_with_the_user_law_has_the_rigid_blocks_eigenvalues():
    """The user's law, unchanged, in the stability analysis of the FE block (StabilitySolver,
    the PEP of ufl.derivatives of the residual) and of the rigid block (RigidBlock, its
    (M, C, K̄) from the law's dual-number derivatives, dense eigenvalues): two computations
    that share the law object and nothing else.

    In steady sliding μ(U, p) ≈ 0.55 > μ_crit ≈ 0.37 and μ falls with the slip speed, so
    below 1.5 max|λ_rigid| there are four eigenvalues (Im λ >= 0): the spring mode split into
    two real growing ones λ₁λ₂ ≈ K_x/M by the negative damping B0 ∫ c_n d^{m_T} ∂μ/∂s ds
    (λ₁ + λ₂ ≈ 177 1/s), and the normal/rotation flutter pair, its growth rates ≈ +529 and
    -472 1/s no longer opposite because of that damping. The FE block tends to the rigid one
    as E grows: the elastic compliance adds a relative 1/E to each eigenvalue. Measured gap
    max |λ_FE - λ_rigid| / |λ_rigid| (the flutter pair) at E × 1, 10, 100: 3.8e-2, 4.1e-3,
    4.1e-4 (the same serially and on 2 ranks), so each step of ×10 in E divides it by 9.3,
    9.9; the band 7 to 13 asserts the 1/E rate (a higher order term 1/E² shows at E × 1).
    Every mode's gap falls too. At E × 100, 1e-3 is 2.5 times the measured gap, and far
    above the PEP's own error (relative residuals ≤ 1e-10, the spring's slow real mode,
    |λ| ≈ 0.14, the worst conditioned, off by 1e-5). Stiffer still the steady state's
    round-off (u_mach ‖J‖ ‖u‖, growing with E) takes over: 4-6e-5 at E × 10³ and 10⁴.

    Without the slope ∂μ/∂s the eigenvalues are others: with the user's μ frozen at the belt
    speed (the same μ(U, p), the same steady state, the same K̄) the spring mode is the
    undamped ±i sqrt(K_x/M) ≈ 4.97i and the flutter pair ±490 + 5309i, which the rigid block
    confirms (gap 3.7e-4); the user's eigenvalues lie 2.2e-2 (the flutter pair) to 36 (the
    spring's slow mode) of their modulus away from these, beyond ten times the 1e-3: an FE
    damping matrix without the slope would fail the comparison with the rigid block.
    """
    base = ff.BlockOnBelt(law=LAW)
    gaps = []
    for factor in (1, 10, 100):
        rigid, gap = _stiff_block_gap(dataclasses.replace(base, E=factor * base.E),
                                      f"stiff{factor}")
        gaps.append(gap)
    assert len(rigid) == 4 and np.sum(rigid.imag == 0) == 2, rigid
    assert np.all(rigid[rigid.imag == 0].real > 0)  # the negative slope: two growing modes
    assert np.all(gaps[1] < gaps[0]) and np.all(gaps[2] < gaps[1]), gaps
    worst = np.array([g.max() for g in gaps])
    assert np.all((worst[:-1] / worst[1:] > 7) & (worst[:-1] / worst[1:] < 13)), worst
    assert worst[-1] < 1e-3, worst

    frozen, frozen_gap = _stiff_block_gap(
        dataclasses.replace(base, E=100 * base.E,
                            law=LAW.replace(friction_coefficient=user_mu_at_belt_speed)),
        "frozen")
    assert frozen_gap.max() < 1e-3, frozen_gap
    assert len(frozen) == 3 and abs(frozen[0].real) < 1e-6 * abs(frozen[0]), frozen
    distance = abs(rigid[:, None] - frozen[None, :]).min(axis=1) / abs(rigid)
    assert distance.min() > 10 * 1e-3, (rigid, frozen)


def test_fe_damping_is_the_users_speed_slope_at_every_contact_node():
    """C = ∂R/∂u̇ of the FE block in steady sliding against the law's NumPy derivative ∂t/∂w
    (dual numbers) summed by hand over the contact nodes. With the nodal rule on Q1 facets
    (the trapezoidal rule: each node carries its tributary length A_i) the friction term of C
    is the diagonal -B0 A_i ∂t/∂w(d_i, -U) on the nodes' x-dofs and nothing else (no normal
    damping; the C¹ direction φ'_ε is constant where |w| = U > ε, so all of it is
    -c_n d^{m_T} ∂μ/∂s, the user's slope in the speed). Both sides evaluate the same
    expression at the same nodal d_i, so they agree to round-off: 1e-12. With the speed frozen
    (user_mu_at_belt_speed) the steady state carries the same friction (to the Newton
    tolerance, 1e-8 of the load), and C vanishes: the damping is the slope alone. Measured:
    the five nodes' C_ii sum to -70.6 (10³ kg/s; the rigid block's ∂μ/∂s damping is of that
    size), diagonal and Frobenius norm equal to round-off, serially and on 2 ranks."""
    scene = ff.BlockOnBelt(law=LAW, degree=1, contact_quadrature="nodal")
    model = _sliding(scene, "nodal")
    stability = ff.StabilitySolver(model.residual, prefix="user_law_nodal_pep_")
    stability.assemble()
    comm, V = model.msh.comm, model.V
    bs = V.dofmap.index_map_bs
    x_dofs = fem.locate_dofs_topological(V.sub(0), model.msh.topology.dim - 1,
                                         model.facet_tags.find(CONTACT))
    x_dofs = x_dofs[x_dofs < V.dofmap.index_map.size_local * bs]  # owned
    x = V.tabulate_dof_coordinates()[x_dofs // bs, 0]
    nodes = np.unique(np.concatenate(comm.allgather(x)))
    tributary = np.diff(nodes, prepend=nodes[0]) / 2 + np.diff(nodes, append=nodes[-1]) / 2
    lengths = tributary[np.searchsorted(nodes, x)]
    u, u_dot = model.residual.u.x.array, model.residual.u_dot.x.array
    d, w = -u[x_dofs + 1], u_dot[x_dofs] - scene.belt_speed
    assert np.all(d > 0) and np.allclose(w, -scene.belt_speed, rtol=0, atol=0)
    _, dt_dw = LAW.friction_traction_derivatives(d, w)
    expected = -scene.B0 * lengths * dt_dw
    diagonal = stability.C.getDiagonal().getArray()
    assert diagonal[x_dofs] == pytest.approx(expected, rel=1e-12)
    assert np.all(expected < 0)  # μ falls with the speed: negative damping
    total = np.sqrt(comm.allreduce(np.sum(expected**2), op=MPI.SUM))
    assert len(nodes) == 5 and stability.C.norm(PETSc.NormType.FROBENIUS) == pytest.approx(
        total, rel=1e-12)  # nothing off the diagonal, nothing on other dofs

    frozen = _sliding(dataclasses.replace(
        scene, law=LAW.replace(friction_coefficient=user_mu_at_belt_speed)), "nodal_frozen")
    assert frozen.quantities().friction_force == pytest.approx(
        model.quantities().friction_force, abs=1e-8 * scene.weight)
    frozen_stability = ff.StabilitySolver(frozen.residual, prefix="user_law_nodal_frozen_pep_")
    frozen_stability.assemble()
    assert frozen_stability.C.norm(PETSc.NormType.FROBENIUS) == 0.0
