"""Newton with GMRES preconditioned by a factorisation kept across iterations and continuation
steps (fenicsfriction.reused_lu): the LU's Newton iterates with far fewer factorisations, a
renewal when the Krylov count grows, and the choice ``linear_solver="auto"`` makes."""

from mpi4py import MPI

import numpy as np
import pytest

import fenicsfriction as ff
from fenicsfriction import steady
from fenicsfriction._compat import petsc_vec
from fenicsfriction.reused_lu import ReusedFactorisation

MU = np.linspace(0.0, 1.2, 9)


def _continuation(linear_solver: str, tag: str, refine: int = 2, dim: int = 2, **options):
    model = ff.BlockOnBelt(refine=refine, dim=dim).build(MPI.COMM_WORLD, with_friction=True)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix=f"reuse{tag}_",
                             options={**model.solver_options(), **options},
                             linear_solver=linear_solver)
    records = ff.continuation(solver, model.mu, MU, observe=model.quantities)
    return model, solver, records


def _relative_difference(a, b) -> float:
    diff = b.copy()
    diff.axpy(-1.0, a)
    return diff.norm() / a.norm()


@pytest.mark.parametrize("dim", [2, 3])
def test_reused_factorisation_gives_the_lu_iterates_with_one_factorisation(dim,
                                                                         lu_factorisations):
    model_lu, _, lu = _continuation("lu", f"lu{dim}", refine=1 if dim == 3 else 2, dim=dim)
    before = lu_factorisations()
    model_r, solver, reused = _continuation("reused-lu", f"r{dim}", refine=1 if dim == 3 else 2,
                                            dim=dim)
    assert solver.linear_solver == "reused-lu"
    assert isinstance(solver.preconditioner, ReusedFactorisation)
    # GMRES solves each Newton system to 1e-8 relative, so Newton takes the LU's steps up to
    # that: the same iteration counts and states well below the discretisation error
    assert [r["newton_iterations"] for r in reused] == [r["newton_iterations"] for r in lu]
    for a, b in zip(lu, reused, strict=True):
        assert b["spring_force"] == pytest.approx(a["spring_force"], rel=1e-9, abs=1e-9)
        assert b["max_penetration"] == pytest.approx(a["max_penetration"], rel=1e-8)
    assert _relative_difference(petsc_vec(model_lu.residual.u),
                                petsc_vec(model_r.residual.u)) <= 1e-8
    # the contact stiffness is small against the bulk's: the μ = 0 factorisation preconditions
    # the whole continuation to μ = 1.2 within the renewal threshold
    assert solver.preconditioner.factorisations == 1 == lu_factorisations() - before
    # and it is the μ = 0 factorisation that is applied (an LU of the current Jacobian would
    # take GMRES one iteration)
    assert solver.snes.getKSP().getIterationNumber() > 1


def test_a_growing_krylov_count_renews_the_factorisation(lu_factorisations):
    """With a renewal threshold of 2 Krylov iterations the factorisation is renewed along the
    path (the count reaches 3-11 with the μ = 0 factorisation) and the states do not change."""
    _, solver_once, once = _continuation("reused-lu", "once")
    model = ff.BlockOnBelt(refine=2).build(MPI.COMM_WORLD, with_friction=True)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix="reuserenew_",
                             options=model.solver_options(), linear_solver="reused-lu")
    solver.preconditioner.refactorise_after = 2
    before = lu_factorisations()
    renewed = ff.continuation(solver, model.mu, MU, observe=model.quantities)
    assert solver.preconditioner.factorisations > 2
    assert lu_factorisations() - before == solver.preconditioner.factorisations
    assert solver_once.preconditioner.factorisations == 1
    for a, b in zip(once, renewed, strict=True):
        assert b["spring_force"] == pytest.approx(a["spring_force"], rel=1e-9, abs=1e-9)
        assert b["max_penetration"] == pytest.approx(a["max_penetration"], rel=1e-8)


def test_auto_condenses_small_interfaces_and_reuses_the_lu_beyond(monkeypatch):
    model = ff.BlockOnBelt(refine=2).build(MPI.COMM_WORLD, with_friction=True)
    small = ff.SteadySolver(model.residual, prefix="autosmall_", options=model.solver_options())
    assert small.linear_solver == "condensed" and small.condensation is not None
    # 459 interface dofs, 945,945 nonzeros: |Γ|² = 0.22 nnz(J), reused beyond 0.2
    monkeypatch.setattr(steady, "AUTO_CONDENSE_MAX_FILL", 0.2)
    model3 = ff.BlockOnBelt(refine=2, dim=3).build(MPI.COMM_WORLD, with_friction=True)
    solver3 = ff.SteadySolver(model3.residual, prefix="auto3d_", options=model3.solver_options())
    assert solver3.linear_solver == "reused-lu"
    # 34 interface dofs, 12,740 nonzeros: |Γ|² = 0.09 nnz(J), reused below that
    monkeypatch.setattr(steady, "AUTO_CONDENSE_MAX_FILL", 0.05)
    large = ff.SteadySolver(model.residual, prefix="autolarge_", options=model.solver_options())
    assert large.linear_solver == "reused-lu" and large.condensation is None
    lu = ff.SteadySolver(model.residual, prefix="autolu_", options=model.solver_options(),
                         linear_solver="lu")
    assert lu.linear_solver == "lu" and lu.preconditioner is None


def test_an_unknown_linear_solver_is_refused_by_name():
    model = ff.BlockOnBelt(refine=1).build(MPI.COMM_WORLD, with_friction=True)
    with pytest.raises(ValueError, match="linear_solver='cholesky' is invalid: use one of auto"):
        ff.SteadySolver(model.residual, linear_solver="cholesky")
