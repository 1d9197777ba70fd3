"""Newton–Krylov with algebraic multigrid (fenicsfriction.amg): the direct path's answers to
Newton's tolerance (steady block in 2D and 3D, two-body contact, dynamics; 1 and 2 ranks),
Krylov counts that do not grow with the mesh, a near-nullspace that is the rigid motions of
each body, the automatic choice and the one-line error."""

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem.petsc
import numpy as np
import pytest
import ufl

import fenicsfriction as ff
from fenicsfriction import _compat, amg, forms
from fenicsfriction._compat import petsc_vec
from fenicsfriction.studies.contact import geometry

#: small meshes get several multigrid levels (GAMG's default stops at 1000 unknowns)
LEVELS = {"pc_gamg_coarse_eq_limit": 100}


def _relative_difference(a: PETSc.Vec, b: PETSc.Vec) -> float:
    diff = b.copy()
    diff.axpy(-1.0, a)
    return diff.norm() / a.norm()


def _block_continuation(linear_solver: str, dim: int, refine: int, tag: str, degree: int,
                        mu=(0.0, 0.25, 0.5)):
    model = ff.BlockOnBelt(refine=refine, dim=dim, degree=degree).build(MPI.COMM_WORLD,
                                                                        with_friction=True)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix=f"amg{tag}{linear_solver.replace('-', '')}_",
                             options={**model.solver_options(), **LEVELS},
                             linear_solver=linear_solver)
    records = ff.continuation(solver, model.mu, mu, observe=model.quantities)
    return model, solver, records


def _same_block_states(dim: int, refine: int, tag: str, degree: int) -> None:
    model_lu, _, lu = _block_continuation("lu", dim, refine, tag, degree)
    model_amg, solver, krylov = _block_continuation("amg", dim, refine, tag, degree)
    assert solver.linear_solver == "amg" and solver.near_nullspace is not None
    assert solver.snes.getKSP().getPC().getType() == "gamg"
    # each linear solve to 1e-8 relative: Newton takes the LU's steps to that accuracy, the
    # same number of them, and converges to the same state to Newton's tolerance (1e-10 of
    # the load on the residual: ~1e-10 relative on the state, the bulk well conditioned)
    assert [r["newton_iterations"] for r in krylov] == [r["newton_iterations"] for r in lu]
    for a, b in zip(lu, krylov, strict=True):
        assert b["spring_force"] == pytest.approx(a["spring_force"], rel=1e-8, abs=1e-9)
        assert b["max_penetration"] == pytest.approx(a["max_penetration"], rel=1e-8)
    assert _relative_difference(petsc_vec(model_lu.residual.u),
                                petsc_vec(model_amg.residual.u)) <= 1e-8


@pytest.mark.parametrize("dim", [2, 3])
def test_amg_continuation_reaches_the_lu_states(dim):
    """The 2D block (Q2, 1,683 unknowns) and the 3D block (Q1, 945), three levels each."""
    _same_block_states(dim, refine=2, tag=f"s{dim}", degree=2 if dim == 2 else 1)


@pytest.mark.mpi(min_size=2)
def test_amg_continuation_reaches_the_lu_states_on_two_ranks():
    _same_block_states(3, refine=2, tag="p3", degree=1)


def _patch(linear_solver: str, mesh: geometry.TwoBodyMesh):
    scene = ff.Patch(dim=2, passes=1)
    model = scene.model(mesh, clamp=False)  # Patch.build on a given mesh
    model.rollers(range(1))
    model.linear_solver = linear_solver
    guess = scene.law.uniform_penetration(scene.pressure) + scene.pressure / scene.E1
    model.solve_for_load(scene.pressure, guess=guess, rtol=1e-10)
    return model


def test_two_body_contact_by_amg_is_the_lu_solution():
    """The patch test: two bodies, each with its own rigid modes, coupled by the contact (its
    penalty 500x the bulk's stiffness E/h: GMRES needs many iterations, docs/solvers.md)."""
    mesh = geometry.patch_2d(MPI.COMM_WORLD)  # one partition for both
    opts = PETSc.Options()
    opts["contact_pc_gamg_coarse_eq_limit"] = 50  # two levels on the 2 x 100 nodes
    try:
        lu, krylov = _patch("lu", mesh), _patch("amg", mesh)
        levels = krylov.solver.snes.getKSP().getPC().getMGLevels()
    finally:
        opts.delValue("contact_pc_gamg_coarse_eq_limit")
    assert levels >= 2
    assert krylov.solver.linear_solver == "amg"
    assert len(krylov.solver.near_nullspace.getVecs()) == 2 * 3  # two bodies in 2D
    assert krylov.approach.value == pytest.approx(lu.approach.value, rel=1e-8)
    assert _relative_difference(petsc_vec(lu.u), petsc_vec(krylov.u)) <= 1e-8


def _dynamics(linear_solver: str, energy_consistent: bool):
    model = ff.BlockOnBelt(refine=2).build(MPI.COMM_WORLD, with_friction=True)
    model.initial_guess()
    ff.continuation(ff.SteadySolver(model.residual, prefix=f"amgdyn{linear_solver}_st_",
                                    options=model.solver_options()), model.mu, [0.0, 0.3])
    model.perturb_normal_velocity(-1e-3)
    solver = ff.DynamicsSolver(model.residual, prefix=f"amgdyn{linear_solver}_",
                               atol=1e-10 * model.force_scale, options=LEVELS,
                               linear_solver=linear_solver,
                               energy_consistent=energy_consistent)
    records = solver.run(5e-5, 1e-5, observe=lambda t: {
        "normal_force": model.quantities().normal_force})
    return model, solver, records


@pytest.mark.parametrize("energy_consistent", [False, True])
def test_dynamics_by_amg_steps_like_the_lu(energy_consistent):
    """Five steps of generalized-α (and of the energy-consistent midpoint rule) after a kick."""
    model_lu, _, lu = _dynamics("lu", energy_consistent)
    model_amg, solver, krylov = _dynamics("amg", energy_consistent)
    assert solver.linear_solver == "amg"
    assert solver.ts.getSNES().getKSP().getPC().getMGLevels() >= 2
    assert len(krylov) == len(lu) == 6
    for a, b in zip(lu, krylov, strict=True):
        assert b["normal_force"] == pytest.approx(a["normal_force"], rel=1e-8)
    assert _relative_difference(petsc_vec(model_lu.residual.u),
                                petsc_vec(model_amg.residual.u)) <= 1e-8


def test_krylov_counts_do_not_grow_with_the_mesh():
    """GMRES + GAMG with the rigid modes on the 3D block (Q1) at h, h/2, h/3 (945, 5,967 and
    18,525 unknowns; measured 12.3, 15.0 and 16.3 Krylov iterations per Newton iteration):
    the mean count grows by at most 1.5x, where a one-level preconditioner's grows like
    1/h (3x)."""
    counts = []
    for refine in (2, 4, 6):
        model = ff.BlockOnBelt(refine=refine, dim=3, degree=1).build(MPI.COMM_WORLD,
                                                                     with_friction=True)
        model.initial_guess()
        model.mu.value = 0.3
        solver = ff.SteadySolver(model.residual, prefix=f"amgcount{refine}_",
                                 options={**model.solver_options(), **LEVELS},
                                 linear_solver="amg")
        report = solver.solve()
        counts.append(report.krylov_iterations / report.iterations)
    assert max(counts) <= 1.5 * counts[0], counts


def _elastic_operator(msh, degree: int = 1) -> tuple[PETSc.Mat, object]:
    V = _compat.vector_function_space(msh, degree)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    w = dolfinx.fem.Function(V)
    a = _compat.form(ufl.derivative(forms.elasticity(w, v, 1.0, 0.3, ufl.dx(domain=msh)), w, u))
    A = dolfinx.fem.petsc.assemble_matrix(a)
    A.assemble()
    return A, V


def test_the_near_nullspace_is_the_rigid_motions_of_each_body():
    msh = geometry.patch_2d(MPI.COMM_WORLD).mesh  # two separate bodies
    A, V = _elastic_operator(msh)
    modes = amg.rigid_body_modes(V).getVecs()
    assert len(modes) == 6
    scale = A.norm(PETSc.NormType.INFINITY)
    body, count = amg.bodies(V)
    assert count == 2
    owned = V.dofmap.index_map.size_local
    Az = A.createVecLeft()
    for i, z in enumerate(modes):
        A.mult(z, Az)
        assert Az.norm() <= 1e-12 * scale * z.norm()  # a free elastic body does not resist
        # supported on one body only
        values = z.getArray(readonly=True).reshape(-1, 2)
        bodies_touched = np.unique(body[:owned][np.abs(values).max(axis=1) > 0])
        assert MPI.COMM_WORLD.allreduce(set(bodies_touched.tolist()), op=MPI.BOR) == {i // 3}
        for y in modes[:i]:
            assert abs(z.dot(y)) <= 1e-12
        assert z.norm() == pytest.approx(1.0, rel=1e-12)
    # and the check can fail: a stretch is no rigid motion
    stretch = modes[0].duplicate()
    x = V.tabulate_dof_coordinates()[:owned, :2]
    stretch.setArray(np.column_stack([x[:, 0], np.zeros(owned)]).ravel())
    A.mult(stretch, Az)
    assert Az.norm() > 1e-3 * scale * stretch.norm()


def test_auto_takes_amg_beyond_the_crossover(monkeypatch):
    assert amg.choose_linear_solver(3, 10**6, 1, splits=True) == "amg"
    assert amg.choose_linear_solver(3, 10**5, 1, splits=True) == "reused-lu"
    assert amg.choose_linear_solver(3, 10**5, 1, splits=False) == "amg"
    assert amg.choose_linear_solver(3, 10**5, 1, splits=False, contact=True) == "lu"
    assert amg.choose_linear_solver(2, 10**5, 1, splits=True, condensable=True) == "condensed"
    assert amg.choose_linear_solver(2, 10**5, 1, splits=False) == "lu"
    assert amg.choose_linear_solver(2, 2 * 10**6, 1, splits=False) == "amg"
    # per rank: the unknowns at the crossover on two ranks stay direct
    size = amg.AMG_MIN_UNKNOWNS_3D
    assert amg.choose_linear_solver(3, size, 1, splits=False) == "amg"
    assert amg.choose_linear_solver(3, size, 2, splits=False) == "lu"
    model = ff.BlockOnBelt(refine=1, dim=3).build(MPI.COMM_WORLD, with_friction=True)
    monkeypatch.setattr(amg, "AMG_MIN_UNKNOWNS_3D", 100)  # below 945 unknowns per rank
    monkeypatch.setattr(amg, "AMG_MIN_UNKNOWNS_3D_REUSED_LU", 100)
    solver = ff.SteadySolver(model.residual, prefix="amgauto_", options=model.solver_options())
    assert solver.linear_solver == "amg"
    dynamics = ff.DynamicsSolver(model.residual, prefix="amgautodyn_")
    assert dynamics.linear_solver == "amg" and dynamics.near_nullspace is not None
    # the options override the choice: the direct path back
    opts = PETSc.Options()
    opts["amgautolu_pc_type"] = "lu"
    try:
        direct = ff.SteadySolver(model.residual, prefix="amgautolu_",
                                 options=model.solver_options())
    finally:
        opts.delValue("amgautolu_pc_type")
    assert direct.linear_solver == "lu" and direct.near_nullspace is None
    # and an AMG preconditioner asked for on the command line takes the AMG path's defaults
    monkeypatch.setattr(amg, "AMG_MIN_UNKNOWNS_3D_REUSED_LU", 10**9)
    opts["amgautohypre_pc_type"] = "hypre"
    try:
        hypre = ff.SteadySolver(model.residual, prefix="amgautohypre_",
                                options=model.solver_options())
    finally:
        opts.delValue("amgautohypre_pc_type")
    assert hypre.linear_solver == "amg" and hypre.snes.getKSP().getType() == "gmres"
    assert hypre.snes.getKSP().getPC().getHYPREType() == "boomeramg"


def test_the_steady_and_dynamics_solvers_settle_the_path_by_one_rule():
    """resolve_linear_solver, which both solvers call: the AMG path, with its defaults for the
    preconditioner asked for, wherever the options ask for AMG, ``"amg"`` is chosen, or
    ``"auto"`` is past the crossover without contact; any other choice is left alone."""
    gamg3, hypre3 = amg.amg_options(3, "gamg"), amg.amg_options(3, "hypre")
    assert hypre3["pc_type"] == "hypre" and gamg3["pc_type"] == "gamg"
    big = 10 * amg.AMG_MIN_UNKNOWNS_3D
    assert amg.resolve_linear_solver("r_", "auto", 3, big, 1, False, False) == ("amg", gamg3)
    assert amg.resolve_linear_solver("r_", "auto", 3, big, 1, False, True) == ("auto", {})
    assert amg.resolve_linear_solver("r_", "auto", 3, 10, 1, True, False) == ("auto", {})
    assert amg.resolve_linear_solver("r_", "amg", 2, 10, 1, True, True) == (
        "amg", amg.amg_options(2, "gamg"))
    for choice in ("lu", "reused-lu", "condensed"):
        assert amg.resolve_linear_solver("r_", choice, 3, big, 1, True, False) == (choice, {})
    opts = PETSc.Options()
    opts["r_pc_type"] = "hypre"
    try:
        assert amg.resolve_linear_solver("r_", "lu", 3, 10, 1, False, True) == ("amg", hypre3)
    finally:
        opts.delValue("r_pc_type")


def test_an_unknown_linear_solver_is_refused_by_name():
    model = ff.BlockOnBelt(refine=1).build(MPI.COMM_WORLD, with_friction=True)
    with pytest.raises(ValueError, match="linear_solver='multigrid' is invalid: use one of"):
        ff.SteadySolver(model.residual, linear_solver="multigrid")
    with pytest.raises(ValueError, match="linear_solver='cg' is invalid: use one of auto, lu, "
                                         "amg"):
        ff.DynamicsSolver(model.residual, linear_solver="cg")
    with pytest.raises(ValueError, match="preconditioner='ml' is invalid"):
        amg.amg_options(3, "ml")
