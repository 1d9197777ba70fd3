"""The linear bulk condensed onto the contact interface (fenicsfriction.condensation): the same
Newton iterates as the sparse LU, with one factorisation for a whole continuation."""

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest
import ufl

import fenicsfriction as ff
from fenicsfriction._compat import petsc_vec
from fenicsfriction.condensation import interface_split

MU = np.linspace(0.0, 1.2, 9)


def _continuation(linear_solver: str, refine: int = 2):
    model = ff.BlockOnBelt(refine=refine).build(MPI.COMM_WORLD, with_friction=True)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix=f"cond{linear_solver.replace('-', '')}_",
                             options=model.solver_options(), linear_solver=linear_solver)
    records = ff.continuation(solver, model.mu, MU, observe=model.quantities)
    return model, solver, records


def test_jacobian_splits_into_constant_bulk_and_contact_facets():
    model = ff.BlockOnBelt(refine=1).build(MPI.COMM_WORLD, with_friction=True)
    constant, varying = interface_split(model.residual.steady_jacobian(), model.residual.u)
    assert {i.integral_type() for i in constant.integrals()} >= {"cell"}
    assert {i.integral_type() for i in varying} == {"exterior_facet"}
    # a bulk term that depends on u (a nonlinear elastic energy) makes the split unusable
    u, v = model.residual.u, model.residual.v
    nonlinear = model.residual.steady() + ufl.inner(u, u) * ufl.inner(u, v) * ufl.dx
    assert interface_split(ufl.derivative(nonlinear, u), u) is None


def test_condensed_newton_matches_sparse_lu_with_one_factorisation(lu_factorisations):
    model_lu, _, lu = _continuation("lu")
    before = lu_factorisations()
    model_c, solver, condensed = _continuation("condensed")
    assert solver.condensation is not None, "the block's Jacobian must split"
    assert solver.condensation.size == 2 * (2 * 4 * 2 + 1)  # both components of the base nodes
    # Newton sees the same linear systems (solved to 1e-8 relative): same iteration counts
    # and the same states to well below the discretisation error
    assert [r["newton_iterations"] for r in condensed] == [r["newton_iterations"] for r in lu]
    for a, b in zip(lu, condensed, strict=True):
        assert b["spring_force"] == pytest.approx(a["spring_force"], rel=1e-9, abs=1e-9)
        assert b["max_penetration"] == pytest.approx(a["max_penetration"], rel=1e-8)
    x_lu, x_c = petsc_vec(model_lu.residual.u), petsc_vec(model_c.residual.u)
    diff = x_c.copy()
    diff.axpy(-1.0, x_lu)
    assert diff.norm() <= 1e-8 * x_lu.norm()
    assert solver.condensation.factorisations == 1
    # serial: J with Γ last; in parallel K_II and the Schur complement's J, centralised
    assert lu_factorisations() - before == (1 if MPI.COMM_WORLD.size == 1 else 2)


def test_a_changed_bulk_parameter_is_seen_by_the_condensed_solver():
    """A bulk term with a parameter (an elastic foundation k u in the block) is constant in u,
    so it is condensed; changing k between solves must re-assemble and refactorise the bulk and
    give the LU's state, not a Newton that stalls on a stale bulk."""
    from dolfinx import fem

    states = {}
    for condense in (False, True):
        linear_solver = "condensed" if condense else "lu"
        model = ff.BlockOnBelt(refine=2).build(MPI.COMM_WORLD, with_friction=True)
        k = fem.Constant(model.msh, 0.01)
        R = model.residual
        R.form = R.form + model.thickness * k * ufl.inner(R.u, R.v) * ufl.dx
        model.initial_guess()
        solver = ff.SteadySolver(R, prefix=f"bulk{int(condense)}_",
                                 options=model.solver_options(), linear_solver=linear_solver)
        ff.continuation(solver, model.mu, [0.2, 0.4])
        k.value = 0.02  # the foundation twice as stiff: the spring force changes by ~1/3
        report = solver.solve()
        states[condense] = (petsc_vec(R.u).copy(), report.iterations, solver)
    (x_lu, its_lu, _), (x_c, its_c, condensed) = states[False], states[True]
    assert condensed.condensation.factorisations == 2
    assert its_c == its_lu
    diff = x_c.copy()
    diff.axpy(-1.0, x_lu)
    assert diff.norm() <= 1e-8 * x_lu.norm()


def test_without_mumps_the_schur_complement_is_formed_by_solves():
    """Another LU package (SuperLU_dist) has no Schur complement to give: C is then formed by one
    solve per interface dof, and Newton takes the same steps as with MUMPS's complement."""
    _, mumps, with_mumps = _continuation("condensed")
    model = ff.BlockOnBelt(refine=2).build(MPI.COMM_WORLD, with_friction=True)
    model.initial_guess()
    # the inner factorisation's options reach it through the solver's own (set up at the
    # first solve, after the solver's defaults have left the options database)
    solver = ff.SteadySolver(
        model.residual, prefix="condslu_",
        options={**model.solver_options(),
                 "condensed_pc_factor_mat_solver_type": "superlu_dist"},
        linear_solver="condensed")
    with_superlu = ff.continuation(solver, model.mu, MU, observe=model.quantities)
    assert not PETSc.Options().hasName("condslu_condensed_pc_factor_mat_solver_type")
    assert mumps.condensation._mumps_schur and not solver.condensation._mumps_schur
    assert not solver.condensation.whole
    assert ([r["newton_iterations"] for r in with_superlu]
            == [r["newton_iterations"] for r in with_mumps])
    for a, b in zip(with_mumps, with_superlu, strict=True):
        assert b["spring_force"] == pytest.approx(a["spring_force"], rel=1e-9, abs=1e-9)
        assert b["max_penetration"] == pytest.approx(a["max_penetration"], rel=1e-8)
