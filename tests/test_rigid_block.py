r"""The rigid 3-d.o.f. block (Martins & Oden 1986, Fig. 9) against its own derivatives, statics,
its closed-form tangential mode, and the FE block in the stiff limit.

The rigid model is serial NumPy: under MPI every rank computes the same numbers, and only the
FE comparison is distributed.
"""

import itertools

from mpi4py import MPI

import numpy as np
import pytest
import scipy.integrate
import scipy.optimize

import fenicsfriction as ff
from fenicsfriction.stability import StabilitySolver
from fenicsfriction.studies.block import RigidBlock, rigid_block_observables
from fenicsfriction.studies.block.rigid import rigid_loci
from fenicsfriction.timestepping import ReducedDynamics

_COUNTER = itertools.count()


def prefix(name: str) -> str:
    """A PETSc options prefix used by no other solver of the run (options outlive solvers);
    the counter advances alike on every rank, as all ranks run the same tests in order."""
    return f"rigid{next(_COUNTER)}{name}_"


def central_difference(f, x: np.ndarray, steps: np.ndarray) -> np.ndarray:
    """Jacobian of f at x, column j from f(x ± steps[j] e_j)."""
    columns = []
    for j, h in enumerate(steps):
        e = np.zeros_like(x)
        e[j] = h
        columns.append((f(x + e) - f(x - e)) / (2 * h))
    return np.array(columns).T


# --- the linearisation and the steady state ---------------------------------------------------

DAMPED = {"law": ff.InterfaceLaw(mu=0.6, b_n=0.381e10, regularisation="smooth", eps=0.1),
          "viscous": (0.01, 0.2, 3.0)}


@pytest.mark.parametrize("state", ["at rest", "moving", "lifting off"])
def test_linearisation_is_the_derivative_of_the_residual(state):
    """(M, C, K̄) = (∂R/∂q̈, ∂R/∂q̇, ∂R/∂q) against central differences of R(q, q̇, q̈).

    The law is the damped one (b_n = 0.381e10) with the smooth regularisation (ε = 0.1 cm/s)
    and viscous damping, so every block of C is nonzero; states: the steady state (q̇ = 0),
    the same moving (then the damping pressure enters K̄), and rotated until 5 % of the base
    (at the +x end) lifts off (the graded quadrature of the partial-contact integrals).

    Steps: 1e-4 of the mean penetration d0 for u_yG (and u_xG; θ: that over L), 1e-5 cm/s
    for velocities (θ̇: over L). ∫ d_+^{2.5} ds is C³ in q, also across lift-off, so the
    truncation is ≈ (h/d)²/8 ≈ 5e-9 for q and ≲ (h/ε)² = 1e-8 for q̇; round-off,
    u_mach (W + K_x u_xG) / (h ‖K̄‖), is ≈ 3e-11. Tolerance 1e-7; measured ≤ 2e-10 (K̄) and
    ≤ 3e-10 (C). Rows (forces, forces, moment) and columns (cm, cm, rad) are brought to
    common units with L before taking norms.
    """
    rb = RigidBlock(**DAMPED)
    q = rb.steady_state()
    d0 = -q[1]
    q_dot = np.zeros(3) if state == "at rest" else np.array([0.05, 2e-3, 1e-5])
    if state == "lifting off":  # d(s) = -u_yG - θ s vanishes at s = 0.45 L
        q = np.array([q[0], q[1], -q[1] / (0.45 * rb.L)])
        assert -q[1] - q[2] * rb.L / 2 < 0 < -q[1] + q[2] * rb.L / 2
    M, C, K = rb.linearisation(q, q_dot)
    zero = np.zeros(3)
    per_unit = np.array([1.0, 1.0, 1.0 / rb.L])
    rows, cols = np.diag(per_unit), np.diag(1 / per_unit)

    def error(approx, exact):
        return np.linalg.norm(rows @ (approx - exact) @ cols) / np.linalg.norm(rows @ exact @ cols)

    K_fd = central_difference(lambda x: rb.residual(x, q_dot, zero), q, 1e-4 * d0 * per_unit)
    C_fd = central_difference(lambda x: rb.residual(q, x, zero), q_dot, 1e-5 * per_unit)
    M_fd = central_difference(lambda x: rb.residual(q, q_dot, x), zero, per_unit)
    assert error(K_fd, K) < 1e-7
    assert error(C_fd, C) < 1e-7
    assert error(M_fd, M) < 1e-12  # R is linear in q̈: round-off only
    interface = C - np.diag(rb.viscous)  # friction (u̇_xG column), damping (u̇_yG column)
    assert interface[0, 0] > 0 and interface[2, 0] > 0 and interface[1, 1] > 0


@pytest.mark.parametrize("mu", [0.0, 0.5, 1.2])
@pytest.mark.parametrize("spring_height", [None, 10.0])
def test_steady_state_balances_weight_friction_spring_and_moments(mu, spring_height):
    """Statics of the steady state, with the base integrals recomputed independently (adaptive
    quadrature, split at the lift-off point): normal force = W; friction = μ N along the belt
    (Coulomb, slip speed ≫ ε); the spring force cancels it; moments about G vanish:
    B0 ∫ p s ds + F_fric H/2 - F_s (h_s - H/2) = 0.

    Newton stops at 1e-12 of W (forces) and of W L (moment); quad is asked for 1e-12 of the
    integral or of W (W L); tolerance 1e-9 of W and W L.
    """
    rb = RigidBlock(spring_height=spring_height, law=ff.InterfaceLaw(mu=mu))
    u_x, u_y, theta = rb.steady_state()

    def penetration(s):
        return max(-u_y - theta * s, 0.0)

    lift_off = [-u_y / theta] if theta != 0 and abs(u_y / theta) < rb.L / 2 else None

    def integral(f, scale):
        return rb.B0 * scipy.integrate.quad(f, -rb.L / 2, rb.L / 2, points=lift_off,
                                            epsabs=1e-12 * scale / rb.B0, epsrel=1e-12,
                                            limit=200)[0]

    normal = integral(lambda s: rb.law.c_n * penetration(s) ** rb.law.m_n, rb.weight)
    moment = integral(lambda s: rb.law.c_n * penetration(s) ** rb.law.m_n * s, rb.weight * rb.L)
    friction = mu * normal  # c_T d^{m_T} = μ c_n d^{m_n}, dragging the block along the belt
    spring = -rb.K_x * (u_x - theta * (rb.spring_height - rb.H / 2))
    W = rb.weight
    assert normal == pytest.approx(W, rel=1e-9)
    assert friction == pytest.approx(mu * W, abs=1e-9 * W)
    assert friction + spring == pytest.approx(0.0, abs=1e-9 * W)
    assert moment + friction * rb.H / 2 - spring * (rb.spring_height - rb.H / 2) \
        == pytest.approx(0.0, abs=1e-9 * W * rb.L)
    if mu > 0:  # friction and spring tilt the block onto its -x end, where the belt comes in
        assert moment < 0


# --- eigenvalues ------------------------------------------------------------------------------

MU_GRID = np.linspace(0.0, 1.5, 7)  # up to just below the tipping limit L/H = 1.6


def tangential_eigenvalue(rb: RigidBlock) -> complex:
    lam = rb.eigenvalues(rb.steady_state())
    return lam[np.argmin(abs(lam - 1j * np.sqrt(rb.K_x / rb.mass)))]


def test_tangential_pair_does_not_move_with_mu_when_the_spring_acts_through_g():
    """With the spring through G, u_xG enters no other equation (K̄ and C are block triangular:
    friction depends on the slip speed and the penetration, not on u_xG), so ±i sqrt(K_x/M)
    is an eigenvalue exactly, at every μ: found to round-off (≤ 1e-14 relative; measured
    2e-16). With the spring 10 cm above the base, its moment couples u_xG to θ and the pair
    moves with μ (measured: 4e-8 from i sqrt(K_x/M) at μ = 0, 6e-7 at μ = 1.5), which this
    claim would not survive.
    """
    omega = np.sqrt(RigidBlock().K_x / RigidBlock().mass)
    for mu in MU_GRID:
        lam = tangential_eigenvalue(RigidBlock(law=ff.InterfaceLaw(mu=mu)))
        assert abs(lam - 1j * omega) <= 1e-14 * omega, (mu, lam)
    low, high = (tangential_eigenvalue(RigidBlock(spring_height=10.0, law=ff.InterfaceLaw(mu=mu)))
                 for mu in MU_GRID[[0, -1]])
    assert abs(high - low) > 1e-7 * omega


@pytest.mark.parametrize(("B0", "spring_height"), [(30.5, None), (30.5, 10.0), (14.0, None),
                                              (14.0, 10.0)])
def test_stiff_fe_block_has_the_eigenvalues_of_the_rigid_block(B0, spring_height):
    """E × 10³: the FE eigenvalues below 1.5 max|λ_rigid| are the three rigid-body modes
    (spring, normal, rotation; the elastic modes, sqrt(10³) times higher than at the paper's
    E, lie beyond 5e5 rad/s), and they match the rigid model's at μ = 0, 0.5 (flutter) and
    1.2, within 1 %.

    The difference has two sources: the block's elasticity, relative 1/E (5e-5 at E × 10³,
    5e-6 at E × 10⁴ for μ ≤ 0.5 with the spring at mid-height; stiffer still, the steady
    state's round-off floor u_mach ‖J‖ ‖u‖ grows with E and takes over), and the FE contact
    quadrature, inexact once part of the base lifts off — at μ = 1.2 with the spring at
    mid-height the centre of pressure is μ H/2 = 18 cm from G, past the 13.6 cm a fully
    pressed base can carry (p ∝ d^{2.5}, d linear) — where it is 1.9e-3 and does not shrink
    with E. Measured maximum: 1.9e-3 (serial and 2 ranks); the tolerance 1e-2 is
    five times that.
    """
    scene = ff.BlockOnBelt(refine=1, E=1.4e9, B0=B0, spring_height=spring_height)
    model = scene.build(MPI.COMM_WORLD, with_friction=True)
    model.initial_guess()
    steady = ff.SteadySolver(model.residual, prefix=prefix("steady"),
                             options=model.solver_options())
    stability = StabilitySolver(model.residual, prefix=prefix("pep"))
    for mu in (0.0, 0.5, 1.2):
        ff.continuation(steady, model.mu, [mu])
        rb = RigidBlock.from_scene(scene, law=scene.law.replace(mu=mu))
        rigid = rb.eigenvalues(rb.steady_state())
        rigid = rigid[rigid.imag >= 0]
        fe = np.array([m.value for m in stability.solve(max_modulus=1.5 * abs(rigid).max())])
        assert len(fe) == len(rigid) == 3, (mu, fe, rigid)
        rows, cols = scipy.optimize.linear_sum_assignment(abs(fe[:, None] - rigid[None, :]))
        error = abs(fe[rows] - rigid[cols]) / abs(rigid[cols])
        assert error.max() < 1e-2, (mu, fe[rows], rigid[cols], error)


# --- bad input --------------------------------------------------------------------------------

def test_bad_parameters_raise_value_errors_naming_them():
    with pytest.raises(ValueError, match=r"^mass=0 is invalid"):
        RigidBlock(mass=0)
    scene = ff.BlockOnBelt(refine=1)
    model = scene.build(MPI.COMM_WORLD)
    with pytest.raises(ValueError, match=r"^residual_tol=0 is invalid"):
        StabilitySolver(model.residual, prefix=prefix("bad"), residual_tol=0)
    solver = StabilitySolver(model.residual, prefix=prefix("bad"))
    with pytest.raises(ValueError, match=r"^max_modulus=-1 is invalid"):
        solver.solve(max_modulus=-1)


def test_rigid_counterpart_carries_the_top_pressure_and_the_scene_law():
    """A top pressure p is a resultant p L B0 through G: it joins the weight; the law is the
    scene's own object, friction coefficient law included (never replaced by a constant μ)."""
    scene = ff.BlockOnBelt(top_pressure=0.3, law=ff.InterfaceLaw(mu=0.5))
    block = RigidBlock.from_scene(scene)
    assert block.weight == pytest.approx(scene.weight + 0.3 * scene.L * scene.B0, rel=1e-15)
    stribeck = ff.InterfaceLaw(friction_coefficient=ff.laws.StribeckFriction(0.8, 0.5, 0.1))
    assert RigidBlock.from_scene(ff.BlockOnBelt(law=stribeck)).law is stribeck


def test_rigid_loci_bracket_each_onset_between_a_stable_and_a_growing_block():
    """The onsets are re-checked on blocks solved from scratch: no growing mode onset_tol below
    μ_crit, one onset_tol above; the unstable intervals cover the grid points that grow."""
    scene = ff.BlockOnBelt()
    targets, max_frequency, growth_tol, tol = np.linspace(0.0, 1.4, 8), 6000.0, 1e-6, 1e-3
    loci = rigid_loci(scene, targets, max_frequency, growth_tol, tol)

    def grows(mu):
        block = RigidBlock.from_scene(scene, law=scene.law.replace(mu=mu))
        lam = block.eigenvalues(block.steady_state())
        lam = lam[(lam.imag >= 0) & (np.abs(lam) <= max_frequency)]
        return bool(np.any(lam.real > growth_tol * np.abs(lam)))

    assert loci.onsets and loci.mu_crit == loci.onsets[0]
    for onset in loci.onsets:
        assert not grows(onset - tol) and grows(onset + tol)
    growing = [float(mu) for mu in targets if grows(mu)]
    first, last = loci.unstable_intervals[0]
    assert growing[0] == pytest.approx(first, rel=1e-14)
    assert first - (targets[1] - targets[0]) < loci.mu_crit < first <= last
    assert [s["mu"] for s in loci.steps] == pytest.approx(list(targets), rel=1e-15)
    assert loci.to_json()["mu_crit"] == loci.mu_crit


def test_rigid_generalised_forces_integrate_the_pointwise_tractions():
    """The rigid block's generalised forces integrate laws.normal_traction and
    laws.friction_traction: at full contact with θ = 0 and a uniform slip they are B0 L times
    the pointwise tractions (closed form, smooth regularisation, normal damping on)."""
    block = RigidBlock(law=ff.InterfaceLaw(mu=0.6, b_n=1e6, regularisation="smooth", eps=1e-2))
    d, rate, w = 2e-4, 0.03, 0.1
    q = np.array([0.0, -d, 0.0])
    q_dot = np.array([w + block.belt_speed, -rate, 0.0])
    forces = block.generalised_forces(q, q_dot)
    area = block.L * block.B0
    p = block.law.c_n * d**block.law.m_n + block.law.b_n * d**block.law.l_n * rate
    t = -0.6 * block.law.c_n * d**block.law.m_n * w / np.sqrt(w**2 + 1e-4)
    F_s = block._spring(q)
    arm = block.spring_height - block.H / 2
    assert forces == pytest.approx([area * t + F_s, area * p - block.weight,
                                    area * t * block.H / 2 - F_s * arm], rel=1e-10)


# --- stick or no stick: the tangential oscillator on the belt ---------------------------------

def test_block_reaches_the_belt_and_sticks_exactly_when_the_closed_form_says():
    """The mechanism of Martins & Oden's case (b), on the rigid block with a static and a
    kinetic friction coefficient and no flutter (μ ≤ 0.3, below the onset; normal damping on).

    Released at rest from u_xG = x* + ξ0, x* = μ_k W/K_x the kinetic equilibrium, the block
    slides (slip ≈ -U, friction μ_k W) and oscillates about x* at ω = sqrt(K_x/M): its velocity
    u̇_xG = -ξ0 ω sin ωt. It reaches the belt speed U only if ξ0 ω ≥ U: at ξ0 ω = 0.9 U it
    never sticks and its largest velocity is ξ0 ω; at ξ0 ω = 1.2 U it enters the stick band
    (u̇_xG = U - ε) at ωt_1 = π + arcsin((U - ε)/(ξ0 ω)), then moves with the belt until the
    spring force reaches the static capacity μ(ε) W (the law's μ at the band's edge), after
    T = [(μ(ε) - μ_k) W/K_x + sqrt(ξ0² - (U/ω)²)] / U.

    μ(|w|) falls linearly from μ_s = 0.3 to μ_k = 0.2 over |w| < v_c = 0.01U (PiecewiseLinear):
    the sliding phase (|w| ≥ 0.1U) sees μ_k exactly. The closed form leaves out the ramp (the
    block crosses v_c in v_c / (ω sqrt(ξ0²ω² - U²)) ≈ 0.1 ms, moving t_1 and T by ≲ 0.2 %),
    the creep inside the band (|w| < ε = 0.002 U: ≤ 0.2 % of T) and the flags' resolution of
    one step (0.1 %); implicit midpoint's phase error (ω dt)²/12 is 2e-6. Tolerances: 1e-3 on
    the largest velocity (measured 1.3e-6), 1 % on t_1 and T (measured 1.3e-4 and 5.7e-3).
    K_x, M, W and U are away from 1 and from the defaults.
    """
    mu_s, mu_k, U, eps = 0.3, 0.2, 0.5, 1e-3
    v_c = 0.01 * U
    law = ff.InterfaceLaw(b_n=0.381e10, eps=eps, friction_coefficient=ff.laws
                          .PiecewiseLinearFriction(mu_s, (mu_s - mu_k) / v_c, v_c))
    block = RigidBlock(K_x=2388.0, mass=0.3, weight=450.0, belt_speed=U, law=law)
    omega, W, dt = np.sqrt(block.K_x / block.mass), block.weight, 5e-5
    q_star = block.steady_state()
    assert q_star[0] == pytest.approx(mu_k * W / block.K_x, rel=1e-9)

    def release(ratio: float, t_end: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        q0 = q_star + np.array([ratio * U / omega, 0.0, 0.0])
        solver = ReducedDynamics(model=block, q0=q0, q_dot0=np.zeros(3),
                                 prefix=prefix("release"))
        rows: list[tuple[float, float, float]] = []
        solver.run(t_end=t_end, dt=dt, observe=lambda t: rows.append(
            (t, solver.q_dot[0], solver.q_dot[0] + solver.q_dot[2] * block.H / 2 - U)) or {})
        t, v, w = np.array(rows).T
        return t, v, w

    t, v, w = release(0.9, 0.06)  # past the velocity's peak at ωt = 3π/2
    assert not np.any(np.abs(w) < eps)
    assert v.max() == pytest.approx(0.9 * U, rel=1e-3)

    xi0 = 1.2 * U / omega
    t, v, w = release(1.2, 0.11)
    stuck = np.abs(w) < eps
    onset = t[np.argmax(stuck)]
    assert onset == pytest.approx((np.pi + np.arcsin((U - eps) / (xi0 * omega))) / omega,
                                  rel=1e-2)
    assert not stuck[-1] and np.all(stuck[t > onset + 0.01][:100])  # it stuck, then slid again
    capacity = law.friction_coefficient(eps)
    duration = ((capacity - mu_k) * W / block.K_x + np.sqrt(xi0**2 - (U / omega) ** 2)) / U
    assert np.sum(np.diff(t)[stuck[1:]]) == pytest.approx(duration, rel=1e-2)


def test_rigid_observables_tell_stick_from_slip_by_the_slip_against_eps():
    """``rigid_block_observables``: the base sticks when |w| < ε, w = u̇_xG + θ̇ H/2 - U (the
    rotation's share included), slips otherwise, is open when lifted; the friction force is
    the C1 law's -μ N w/ε inside the band and -μ N sgn(w) outside (N the elastic normal force;
    no normal damping here). ε, U and μ are away from 1 and from each other."""
    eps, U, mu = 2e-3, 0.3, 0.4
    block = RigidBlock(belt_speed=U, law=ff.InterfaceLaw(mu=mu, eps=eps))
    q = block.steady_state()
    h2 = block.H / 2
    for q_dot, ratio in (([U + 0.9 * eps, 0, 0], 0.9), ([U - 0.9 * eps, 0, 0], -0.9),
                         ([U + 1.1 * eps, 0, 0], 1.1), ([U - 1.1 * eps, 0, 0], -1.1),
                         ([U, 0, 0.95 * eps / h2], 0.95), ([U, 0, -1.05 * eps / h2], -1.05)):
        seen = rigid_block_observables(block, q, np.array(q_dot, float))
        assert seen["slip_velocity"] == pytest.approx(ratio * eps, rel=1e-9)
        assert seen["contact"] == ("stick" if abs(ratio) < 1 else "slip")
        coulomb = -mu * seen["normal_force_elastic"]
        assert seen["friction_force"] == pytest.approx(
            coulomb * (ratio if abs(ratio) < 1 else np.sign(ratio)), rel=1e-9)
    lifted = rigid_block_observables(block, np.array([q[0], 1e-3, 0.0]), np.zeros(3))
    assert lifted["contact"] == "open" and lifted["normal_force"] == 0.0
