r"""Steady sliding of the block on the belt (Problem 2, the block of Martins & Oden 1986):
statics and closed forms.

Tolerances come from one fact. At a converged state the assembled residual R (nodal forces)
satisfies ‖R‖₂ ≤ ``residual_norm`` and the exact residual of that state differs from the
assembled one by at most its round-off floor, which the solver includes in the ``atol`` it
reports. A resultant that is a linear functional c·R of the residual with |c_i| ≤ 1 — a sum of
rows — is then known to sqrt(n) (residual_norm + atol) by Cauchy-Schwarz (:func:`slack`).
The resultants of the block are such functionals, exactly, because the quantities are
integrated with the residual's own contact quadrature and the elastic term vanishes on rigid
motions (all linear, so nodally exact):

* rows along y, R(e_y) = W + p_top L B0 - N;
* rows along x, R(e_x) = -(friction + spring);
* the rigid rotation r = (-y, x - L/2) about the base midpoint, R(r) = spring·h_s - N·x_cp
  (weight and top pressure have no moment about it, friction acts on y = 0 with no lever).
"""

import dataclasses

from mpi4py import MPI

import dolfinx.fem.petsc
import numpy as np
import pytest
from dolfinx import fem

import fenicsfriction as ff
from fenicsfriction._compat import petsc_vec
from fenicsfriction.assembly import assemble_jacobian, assemble_residual

COMM = MPI.COMM_WORLD
MU_PATH = np.linspace(0.0, 1.5, 16)  # up to just below the tipping limit L/H = 1.6


def solve_block(scene: ff.BlockOnBelt, prefix: str, targets, comm=COMM):
    """Build the scene with friction, start from its initial guess and continue μ."""
    model = scene.build(comm, with_friction=True)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix=prefix, options=model.solver_options())
    records = ff.continuation(solver, model.mu, targets, observe=model.quantities)
    return model, solver, records


def slack(residual_norm: float, atol: float, n_dofs: int) -> float:
    """Bound on |c·R| for |c_i| ≤ 1 at a converged state (see the module docstring)."""
    return np.sqrt(n_dofs) * (residual_norm + atol)


# --- a closed-form solution -----------------------------------------------------------------

@pytest.mark.parametrize(("refine", "degree"), [(1, 2), (2, 2), (2, 1)])
def test_frictionless_block_under_top_pressure_penetrates_uniformly(refine, degree):
    """No weight, pressure p on top, no friction: σ_yy = -p everywhere (a linear displacement
    field, exact in Q1 and Q2), so every contact node penetrates d = (p / c_n)^(1/m_n)."""
    p = 0.3
    scene = ff.BlockOnBelt(weight=0.0, top_pressure=p, refine=refine, degree=degree)
    model = scene.build(COMM)  # μ = 0: no friction term
    d = (p / scene.law.c_n) ** (1 / scene.law.m_n)
    # start tilted and too deep, so that Newton has to find the answer
    model.residual.u.interpolate(
        lambda x: np.vstack([np.zeros(x.shape[1]), -d * (1.5 + 0.5 * x[0] / scene.L)]))
    solver = ff.SteadySolver(model.residual, prefix="uniform_",
                             options=model.solver_options())
    report = solver.solve()
    q = model.quantities()
    assert report.iterations >= 2
    load = p * scene.L * scene.B0
    force_error = slack(report.residual_norm, report.atol, petsc_vec(model.residual.u).getSize())
    assert q.normal_force == pytest.approx(load, abs=force_error)
    # d ∝ N^(1/m_n): a force error δN moves the penetration by δd/d = δN / (m_n N); the
    # factor 10 allows for the error not being spread uniformly over the contact nodes
    tolerance = 10 * force_error / (scene.law.m_n * load)
    assert q.min_penetration == pytest.approx(d, rel=tolerance)
    assert q.max_penetration == pytest.approx(d, rel=tolerance)


# --- global equilibrium along the continuation in μ -----------------------------------------

@pytest.fixture(scope="module", params=[(1, 0.5), (-1, 0.5), (1, 0.3), (-1, 0.3)],
                ids=["belt+x-spring_H/2", "belt-x-spring_H/2", "belt+x-spring_0.3H",
                     "belt-x-spring_0.3H"])
def mu_path(request):
    """The continuation 0 ≤ μ ≤ 1.5 for a belt direction and a spring height h_s."""
    direction, height = request.param
    scene = ff.BlockOnBelt(belt_direction=direction, spring_height=height * ff.BlockOnBelt.H)
    model, _, records = solve_block(scene, "path_", MU_PATH)
    return scene, records, petsc_vec(model.residual.u).getSize()


def test_continuation_reaches_every_mu_to_a_small_fraction_of_the_load(mu_path):
    scene, records, n = mu_path
    np.testing.assert_allclose([r["mu"] for r in records], MU_PATH, rtol=1e-15)
    for r in records:  # so that the slacks below are small (sqrt(n) ≈ 11: ≤ 1e-5 of W)
        assert r["residual_norm"] + r["atol"] <= 1e-6 * scene.weight, r


def test_spring_holds_mu_times_the_weight_at_every_mu(mu_path):
    """C1 law with ε < |U_T|: φ'_ε(-U_T) = -τ exactly, so Coulomb's F = dir μ N holds with
    N = W; the spring, read off its node's displacement, balances it. Its error is the
    horizontal balance's slack plus μ times the vertical one's."""
    scene, records, n = mu_path
    assert scene.law.eps < scene.belt_speed
    for r in records:
        expected = scene.belt_direction * r["mu"] * scene.weight
        assert abs(-r["spring_force"] - expected) <= (1 + r["mu"]) * slack(
            r["residual_norm"], r["atol"], n), r


def test_friction_balances_spring_at_every_mu(mu_path):
    _, records, n = mu_path
    for r in records:
        assert abs(r["friction_force"] + r["spring_force"]) <= slack(
            r["residual_norm"], r["atol"], n), r


def test_normal_force_carries_the_weight_at_every_mu(mu_path):
    scene, records, n = mu_path
    for r in records:
        assert abs(r["normal_force"] - scene.weight) <= slack(r["residual_norm"], r["atol"], n)


def test_centre_of_pressure_balances_the_spring_moment_at_every_mu(mu_path):
    """x_cp = -dir μ h_s: the friction moment μ N h_s about the base is carried by the pressure.

    x_cp + dir μ h_s = [h_s (friction + spring) - R(r)] / N, with |r_i| ≤ sqrt((L/2)² + H²).
    """
    scene, records, n = mu_path
    lever = np.hypot(scene.L / 2, scene.H)
    for r in records:
        expected = -scene.belt_direction * r["mu"] * scene.spring_height
        tolerance = slack(r["residual_norm"], r["atol"], n) * (lever + scene.spring_height) \
            / r["normal_force"]
        assert r["centre_of_pressure"] == pytest.approx(expected, abs=tolerance)


# --- the Jacobian -----------------------------------------------------------------------------

def test_jacobian_is_the_derivative_of_the_residual():
    """Taylor test at a sliding state, nodal spring included:
    ‖R(u + h δu) - R(u) - h J(u) δu‖ = O(h²)."""
    model, solver, records = solve_block(ff.BlockOnBelt(), "taylor_", [0.3, 0.6])
    R = model.residual
    u = petsc_vec(R.u)
    residual_at_u = dolfinx.fem.petsc.create_vector(solver.L)
    residual, J_du = residual_at_u.duplicate(), residual_at_u.duplicate()
    J = dolfinx.fem.petsc.create_matrix(solver.a)
    assemble_residual(residual_at_u, solver.L, solver.a, R.bcs, u, R.springs)
    assemble_jacobian(J, solver.a, R.bcs, R.springs)

    # random |δu_i| ≤ d_min/4 (d_min ≈ 3e-5 cm): for h ≤ 1 the contact stays closed (Q2
    # interpolation overshoots nodal values by at most 25%), so R is smooth along the path.
    # Plus a rigid slide of 1 cm along x: it costs no elastic energy, so only the spring
    # (K_x = 11.1, tiny next to the contact stiffness) sees it and a J without the spring fails
    rng = np.random.default_rng(seed=COMM.rank)
    du = u.copy()
    scale = records[-1]["min_penetration"] / 4
    values = rng.uniform(-scale, scale, du.getLocalSize())
    values[0::model.V.dofmap.index_map_bs] += 1.0  # x components (dofs are interleaved)
    du.setArray(values)
    J.mult(du, J_du)
    u0 = u.copy()
    steps = 0.5 ** np.arange(7)
    increments, remainders = [], []
    for h in steps:
        u0.copy(u)
        u.axpy(h, du)
        R.u.x.scatter_forward()
        assemble_residual(residual, solver.L, solver.a, R.bcs, u, R.springs)
        residual.axpy(-1.0, residual_at_u)
        increments.append(residual.norm())
        residual.axpy(-h, J_du)
        remainders.append(residual.norm())
    u0.copy(u)
    R.u.x.scatter_forward()

    orders = np.log2(np.array(remainders[:-1]) / remainders[1:])
    # a wrong or incomplete Jacobian (checked: without the spring, or without the friction's
    # coupling K_Tn) leaves an O(h) remainder, order ≈ 1.0; third-order terms shift it by O(h)
    assert np.all(np.abs(orders - 2) < 0.1), orders
    # the remainder is not small because R itself barely changes: J δu is what cancels
    assert remainders[-1] < 1e-3 * increments[-1]


# --- Kalker's sequential process in ε ---------------------------------------------------------

BELT_SPEED, MU = 0.08, 0.6


def epsilon_path(regularisation: str, eps_values, prefix: str):
    scene = ff.BlockOnBelt(belt_speed=BELT_SPEED,
                           law=ff.InterfaceLaw(regularisation=regularisation, eps=eps_values[0]))
    model, solver, _ = solve_block(scene, prefix, [MU / 2, MU])
    records = ff.epsilon_sequence(solver, model.eps, eps_values, observe=model.quantities)
    return scene, records


def test_smooth_regularisation_converges_quadratically_as_eps_decreases():
    eps_values = BELT_SPEED * np.array([1.0, 0.3, 0.1, 0.03, 0.01])
    scene, records = epsilon_path("smooth", eps_values, "smooth_")
    ratio = eps_values / BELT_SPEED
    coulomb = np.array([MU * r["normal_force"] for r in records])
    friction = np.array([r["friction_force"] for r in records])
    # ψ'_ε(-U_T) = -τ U / sqrt(U² + ε²) at every point: friction = μN / sqrt(1 + (ε/U)²) up to
    # summation round-off
    np.testing.assert_allclose(friction, coulomb / np.sqrt(1 + ratio**2), rtol=1e-12)
    # so |F - μN| = μN (ε/U)²/2 (1 + O((ε/U)²)): the observed order tends to 2
    errors = np.abs(friction - coulomb)
    orders = np.log(errors[:-1] / errors[1:]) / np.log(eps_values[:-1] / eps_values[1:])
    assert np.all(np.diff(orders) > 0), orders
    assert np.all(np.abs(orders[-2:] - 2) < 0.06), orders

    changes = np.array([r["change"] for r in records[1:]])
    assert records[0]["change"] is None
    assert np.all(np.diff(changes) < 0), changes
    # the change is the block's rigid slide |ΔF| / K_x (elastic shear adds ~1e-6 of it): the
    # max-norm includes the spring's node, whose displacement is exactly -spring / K_x
    spring = np.array([r["spring_force"] for r in records])
    assert np.all(changes >= np.abs(np.diff(spring)) / scene.K_x * (1 - 1e-12))
    slide = MU * scene.weight / scene.K_x * np.abs(np.diff(1 / np.sqrt(1 + ratio**2)))
    np.testing.assert_allclose(changes, slide, rtol=1e-4)


def test_c1_friction_is_exactly_coulomb_once_eps_is_below_belt_speed():
    eps_values = BELT_SPEED * np.array([2.0, 1.25, 0.99, 0.3, 0.1])
    scene, records = epsilon_path("c1", eps_values, "c1_")
    for r in records:
        # φ'_ε(-U_T) = -τ U / max(U, ε): a fraction of Coulomb above U, exactly Coulomb below
        expected = MU * r["normal_force"] * BELT_SPEED / max(BELT_SPEED, r["eps"])
        assert r["friction_force"] == pytest.approx(expected, rel=1e-12)
    # below U the residual no longer depends on ε: the state moves only within the solver's
    # tolerance (≲ 1e-7 W / K_x along the softest mode, the spring), against ~0.2 μW/K_x above
    stretch = MU * scene.weight / scene.K_x
    assert records[1]["change"] > 0.1 * stretch
    for r in records[3:]:
        assert r["change"] <= 1e-6 * stretch


# --- mesh convergence -------------------------------------------------------------------------

def base_penetration(model, points: np.ndarray) -> np.ndarray:
    """Penetration (-u_y)_+ at the base nodes with x in ``points``, on every rank."""
    V = model.V
    bs = V.dofmap.index_map_bs
    facets = model.facet_tags.find(model.CONTACT)
    dofs = fem.locate_dofs_topological(V.sub(1), model.msh.topology.dim - 1, facets)
    dofs = dofs[dofs < V.dofmap.index_map.size_local * bs]  # owned ones, each counted once
    x = np.concatenate(COMM.allgather(V.tabulate_dof_coordinates()[dofs // bs, 0]))
    d = np.concatenate(COMM.allgather(np.maximum(-model.residual.u.x.array[dofs], 0.0)))
    nearest = np.array([np.argmin(np.abs(x - p)) for p in points])
    np.testing.assert_allclose(x[nearest], points, atol=1e-10)
    return d[nearest]


def test_base_penetration_converges_under_mesh_refinement():
    """μ = 0.9, meshes 4r × 3r (r = 1, 2, 4, 8) against r = 16, at the 9 base nodes of the
    coarsest Q2 mesh (nodes of every refinement: the meshes are nested).

    Measured (serial and 2 ranks): at the corner x = 0, where the friction moment
    concentrates the pressure (x_cp = -μ h_s), the error falls at order ≈ 1.0, 1.2, 1.6 (the
    last inflated by the reference) — the corner limits it; elsewhere at order ≈ 3.3, 3.9
    from r = 2 on (Q2 nodal values: h³ or better). From r = 1 to 2 the node next to the
    corner is still inside the corner's pollution zone (order 0.2), so that step is left out.
    """
    points = np.linspace(0.0, ff.BlockOnBelt.L, 9)
    penetration = {}
    for refine in (1, 2, 4, 8, 16):
        model, _, _ = solve_block(ff.BlockOnBelt(refine=refine), f"mesh{refine}_",
                                  [0.3, 0.6, 0.9])
        penetration[refine] = base_penetration(model, points)
    reference = penetration.pop(16)
    errors = np.array([np.abs(penetration[r] - reference) for r in (1, 2, 4, 8)])
    corner_orders = np.log2(errors[:-1, 0] / errors[1:, 0])
    smooth_orders = np.log2(errors[1:-1, 1:].max(axis=1) / errors[2:, 1:].max(axis=1))
    # bounds: convergence at the corner at all (> 0.75), and clearly better than the O(h²)
    # of a Q1 method away from it (> 2.5); the r = 8 errors (5e-10 cm) are ~50x the
    # solver's floor (sqrt(n) atol / contact stiffness ≈ 1e-11 cm), so they are resolved
    assert np.all(corner_orders > 0.75), corner_orders
    assert np.all(smooth_orders > 2.5), smooth_orders


# --- failure ----------------------------------------------------------------------------------

@pytest.mark.timeout(120)
def test_failed_continuation_raises_and_keeps_the_last_converged_step():
    """Beyond tipping (μ = 1.7 > L/H) no steady state exists: the continuation gives up after
    Newton fails, reports the converged targets and leaves the last of them in place."""
    scene = ff.BlockOnBelt()
    assert scene.tipping_limit < 1.7
    model = scene.build(COMM, with_friction=True)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix="fail_",
                             options=model.solver_options())
    states = []

    def observe():
        states.append(model.residual.u.x.array.copy())
        return model.quantities()

    with pytest.raises(ff.ContinuationError) as failure:
        ff.continuation(solver, model.mu, [0.4, 0.8, 1.7], observe=observe, max_halvings=0)
    q = model.quantities()  # collective: before any assertion that one rank alone could fail
    unchanged = COMM.allreduce(np.array_equal(model.residual.u.x.array, states[-1]),
                               op=MPI.LAND)
    records = failure.value.records
    assert [r["value"] for r in records] == [0.4, 0.8]
    assert float(model.mu.value) == 0.8
    assert unchanged
    fields = dataclasses.asdict(q)
    assert fields == {key: records[-1][key] for key in fields}


@pytest.mark.timeout(120)
def test_halved_continuation_stops_at_an_equilibrium_after_failure():
    """From μ = 0.8 towards 1.7 with two halvings: 1.7 fails, 1.25 converges, 1.7 fails,
    1.475 converges, 1.7 fails again and it gives up — at 1.475, which is no target (so not in
    the records) but must be a converged state, not Newton's last diverged iterate."""
    scene = ff.BlockOnBelt()
    model = scene.build(COMM, with_friction=True)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix="halve_",
                             options=model.solver_options())
    with pytest.raises(ff.ContinuationError) as failure:
        ff.continuation(solver, model.mu, [0.8, 1.7], max_halvings=2)
    R = model.residual
    residual = dolfinx.fem.petsc.create_vector(solver.L)
    assemble_residual(residual, solver.L, solver.a, R.bcs, petsc_vec(R.u), R.springs)
    q = model.quantities()
    assert [r["value"] for r in failure.value.records] == [0.8]
    assert float(model.mu.value) == pytest.approx(0.8 + 0.9 / 2 + 0.9 / 4, rel=1e-15)
    # a diverged iterate leaves nodal forces of order the load (~60 here); a converged state
    # is held to ≤ 1e-6 W (see test_continuation_reaches_every_mu...)
    assert residual.norm() <= 1e-6 * scene.weight
    # equilibrium along x with the spring force read off the nodal displacement, and
    # Coulomb's law in closed form: the spring holds μ W
    assert q.friction_force == pytest.approx(-q.spring_force, rel=1e-6)
    assert -q.spring_force == pytest.approx(float(model.mu.value) * scene.weight, rel=1e-6)
    assert q.normal_force == pytest.approx(scene.weight, rel=1e-6)


def test_solvers_sharing_a_prefix_each_get_their_own_defaults():
    """Defaults never outlive the solver that set them (options the user sets still win)."""
    tolerances = []
    for weight in (450.0, 4.5):
        model = ff.BlockOnBelt(weight=weight).build(MPI.COMM_WORLD)
        solver = ff.SteadySolver(model.residual, prefix="shared_",
                                 options=model.solver_options())
        tolerances.append((model.solver_options()["snes_atol"], solver.snes.getTolerances()[1]))
    assert all(wanted == used for wanted, used in tolerances)


def test_failed_epsilon_step_restores_eps_with_the_state():
    law = ff.InterfaceLaw(mu=0.6, regularisation="smooth", eps=0.08)
    model = ff.BlockOnBelt(belt_speed=0.08, law=law).build(MPI.COMM_WORLD)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix="eps_restore_",
                             options=model.solver_options())
    ff.epsilon_sequence(solver, model.eps, [0.08])
    u_converged = model.residual.u.x.array.copy()
    solver.snes.setTolerances(max_it=1)
    with pytest.raises(ff.SolveError):
        ff.epsilon_sequence(solver, model.eps, [0.0008])
    assert float(model.eps.value) == 0.08
    assert np.array_equal(model.residual.u.x.array, u_converged)


def test_a_forced_iteration_polishes_a_converged_state():
    """PETSc leaves -snes_force_iteration to the convergence test: ours must honour it, given as
    an option of the solver or set on its test, or a state accepted at its round-off floor
    cannot be polished (the stability benchmark relies on it)."""
    model = ff.BlockOnBelt(refine=1).build(MPI.COMM_WORLD, with_friction=True)
    model.mu.value = 0.5
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix="force0_", options=model.solver_options())
    solver.solve()
    assert solver.solve().iterations == 0  # converged already
    solver.convergence.force_iteration = True
    assert solver.solve().iterations == 1
    forced = ff.SteadySolver(model.residual, prefix="force1_",
                             options={**model.solver_options(), "snes_force_iteration": True})
    assert forced.convergence.force_iteration
    assert forced.solve().iterations == 1
