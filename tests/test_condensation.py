"""The linear bulk condensed onto the contact interface (fenicsfriction.condensation): the same
Newton iterates as the sparse LU, with one factorisation for a whole continuation."""

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem.petsc
import numpy as np
import pytest
import ufl

import fenicsfriction as ff
from fenicsfriction import _compat
from fenicsfriction._compat import petsc_vec
from fenicsfriction.assembly import BulkWatcher, split_constant
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


def _form_with_a_known_split():
    """A residual on the unit square whose Jacobian has, by construction, a constant cell
    integral (elasticity-like), a constant facet integral with a bulk constant and a bulk field
    (tag 1), a nonlinear facet integral (tag 2) and a facet integral linear between kinks
    (a Heaviside factor of u, tag 3)."""
    from dolfinx import fem, mesh

    msh = mesh.create_unit_square(MPI.COMM_WORLD, 4, 4)
    fdim = msh.topology.dim - 1
    sides = [mesh.locate_entities_boundary(msh, fdim, where) for where in (
        lambda x: np.isclose(x[0], 0.0), lambda x: np.isclose(x[0], 1.0),
        lambda x: np.isclose(x[1], 0.0))]
    indices = np.concatenate(sides)
    values = np.concatenate([np.full(len(f), t, dtype=np.int32)
                             for f, t in zip(sides, (1, 2, 3), strict=True)])
    order = np.argsort(indices)
    tags = mesh.meshtags(msh, fdim, indices[order], values[order])
    ds = ufl.Measure("ds", domain=msh, subdomain_data=tags)
    V = _compat.vector_function_space(msh, 1)
    u, v = fem.Function(V), ufl.TestFunction(V)
    field = fem.Function(_compat.scalar_function_space(msh, "Lagrange", 1))
    k = fem.Constant(msh, 2.0)
    R = (ufl.inner(ufl.grad(u), ufl.grad(v)) * ufl.dx
         + k * field * ufl.inner(u, v) * ds(1)
         + ufl.inner(u, u) * ufl.inner(u, v) * ds(2)
         + ufl.conditional(ufl.gt(u[1], 0.0), u[1], 0.0) * v[1] * ds(3))
    return ufl.derivative(R, u), u, k, field


def test_the_splitter_puts_exactly_the_integrals_constant_in_u_in_the_bulk():
    """K0 must hold the cell integral and the facet integrals of tags 1 and 3 (their derivative
    in u vanishes: tag 3's is a Heaviside factor), the rest only tag 2; K0 plus the rest,
    assembled apart, is the whole Jacobian (to round-off of its norm)."""
    from fenicsfriction.assembly import assemble_jacobian

    jacobian, u, _, field = _form_with_a_known_split()
    u.x.array[:] = 0.3
    field.x.array[:] = 1.5
    bulk, rest = split_constant(jacobian, [u])
    assert {(i.integral_type(), i.subdomain_id()) for i in bulk.integrals()} == {
        ("cell", "everywhere"), ("exterior_facet", 1), ("exterior_facet", 3)}
    for nonlinear in (rest, interface_split(jacobian, u)[1]):
        assert [(i.integral_type(), i.subdomain_id()) for i in nonlinear] == [
            ("exterior_facet", 2)]
    whole, parts = (_compat.form(f) for f in (jacobian, bulk))
    A = dolfinx.fem.petsc.create_matrix(whole)
    assemble_jacobian(A, whole, [])
    B = A.duplicate()
    assemble_jacobian(B, parts, [])
    assemble_jacobian(B, _compat.form(ufl.Form(rest)), [], base=B.copy())
    norm = A.norm()
    A.axpy(-1.0, B)
    assert A.norm() <= 1e-14 * norm


def test_the_bulk_is_assembled_again_when_an_input_changes_and_only_then():
    """The watcher assembles at the first refresh and again after a change of the bulk's
    constant, of its field, or of u where u enters between kinks (tag 3's Heaviside factor);
    a value set to what it was, or nothing changed, does not assemble."""
    jacobian, u, k, field = _form_with_a_known_split()
    bulk, _ = split_constant(jacobian, [u])
    count = []
    watcher = BulkWatcher([bulk], lambda: count.append(1))
    changes = [lambda: None, lambda: setattr(k, "value", 3.0), lambda: setattr(k, "value", 3.0),
               lambda: field.x.array.fill(1.0), lambda: u.x.array.fill(0.5), lambda: None]
    assembled = []
    for change in changes:
        change()
        assembled.append(watcher.refresh())
    assert assembled == [True, True, False, True, True, False]
    assert len(count) == watcher.assemblies == 4


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
    assert condensed._bulk_watcher.assemblies == 2  # at the start and after k changed
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
    # the condensation is the exact inverse: GMRES stops after one iteration at every Newton
    # step (the last solve's), and one factorisation serves the whole continuation
    assert solver.snes.getLinearSolveIterations() == solver.snes.getIterationNumber() > 0
    assert solver.condensation.factorisations == 1
    assert ([r["newton_iterations"] for r in with_superlu]
            == [r["newton_iterations"] for r in with_mumps])
    for a, b in zip(with_mumps, with_superlu, strict=True):
        assert b["spring_force"] == pytest.approx(a["spring_force"], rel=1e-9, abs=1e-9)
        assert b["max_penetration"] == pytest.approx(a["max_penetration"], rel=1e-8)
