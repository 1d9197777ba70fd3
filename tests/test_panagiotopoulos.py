"""The Panagiotopoulos process against coupled Newton on the block on the belt (Kalker 1986, §3).

The process solves the residual with the friction bound frozen at the last iterate; at its fixed
point the frozen and the coupled residuals coincide, so it must reproduce Newton's solution.
Its convergence is a contraction of the map bound → state → bound, whose factor grows with μ
and with how strongly the tangential traction moves the normal one; for an elastic layer on
the rigid belt that coupling is the layer's second Dundurs constant β = (1 - 2ν)/(2(1 - ν)),
and the process stops converging near μβ = 1 while Newton goes on.
"""

import dataclasses
import pathlib

from mpi4py import MPI

import numpy as np
import pytest

import fenicsfriction as ff
from fenicsfriction.case import CaseModel, read_case
from fenicsfriction.contact import solve_with_search
from fenicsfriction.panagiotopoulos import PanagiotopoulosSolver, ProcessError
from fenicsfriction.studies.block import BlockOnSlab, LayeredBlockOnBelt

COMM = MPI.COMM_WORLD
ROOT = pathlib.Path(__file__).resolve().parents[1]


def _solvers(scene, *methods, **kwargs):
    model = scene.build(COMM, with_friction=True)
    solvers = [PanagiotopoulosSolver(model.residual, method=m, prefix=f"test_{m}_",
                                     options=model.solver_options(),
                                     parameters={"mu": model.mu}, **kwargs) for m in methods]
    return model, solvers


def _solve(model, solver, mu):
    model.mu.value = mu
    model.initial_guess()
    report = solver.solve()
    return report, model.residual.u.x.array.copy()


def _penetrations(model, u):
    model.residual.u.x.array[:] = u
    return np.concatenate(COMM.allgather(model.nodal_contact()[0]))


def test_process_at_zero_friction_is_newton_in_one_step():
    model, (newton, process) = _solvers(ff.BlockOnBelt(), "newton", "panagiotopoulos")
    _, u_newton = _solve(model, newton, 0.0)
    report, u_process = _solve(model, process, 0.0)
    assert report.converged and report.outer_iterations == 1
    # the same problem solved twice by Newton to snes_rtol 1e-10
    assert np.allclose(u_process, u_newton, rtol=0, atol=1e-9 * np.abs(u_newton).max())


@pytest.mark.parametrize("mu", [0.4, 1.2])
def test_process_converges_to_newton_at_moderate_mu(mu):
    model, (newton, process) = _solvers(ff.BlockOnBelt(), "newton", "panagiotopoulos",
                                        rtol=1e-8)
    _, u_newton = _solve(model, newton, mu)
    report, u_process = _solve(model, process, mu)
    assert report.converged and 2 < report.outer_iterations < 15
    assert report.changes[-1] <= 1e-8
    d_newton, d_process = _penetrations(model, u_newton), _penetrations(model, u_process)
    # the last change is the coupled residual relative to the friction forces (1e-8); the map
    # contracts by < 0.1 per iteration here, so the traction is within ~1e-8 of the fixed
    # point, and d ∝ bound^(1/m_n) with m_n = 2.5; 1e-6 leaves a factor 100 for the condition
    # of the elastic solve and Newton's own tolerance
    assert np.max(np.abs(d_process - d_newton)) < 1e-6 * d_newton.max()


def test_johnson_is_the_first_process_iterate():
    model, (johnson, process) = _solvers(ff.BlockOnBelt(), "johnson", "panagiotopoulos",
                                         max_iterations=2)
    report, u_johnson = _solve(model, johnson, 1.0)
    assert report.outer_iterations == 2 and not report.converged
    with pytest.raises(ProcessError, match="max_iterations") as caught:
        _solve(model, process, 1.0)
    u_process = model.residual.u.x.array
    assert caught.value.report.changes == pytest.approx(report.changes, rel=1e-8)
    assert np.allclose(u_process, u_johnson, rtol=0, atol=1e-12 * np.abs(u_johnson).max())
    # Johnson's step is an approximation: its friction traction is the frictionless
    # pressure's, which the tipping moment at μ = 1 changes by far more than the tolerance
    assert report.changes[-1] > 0.1


@pytest.mark.parametrize("layer_nu", [0.0, 0.25])
def test_process_stops_converging_near_the_dundurs_limit_where_newton_does_not(layer_nu):
    """A soft layer (E/1000) under the block, the spring low (tipping limit 9.6): the process
    converges at μβ = 0.8, fails at μβ = 1.3 in bounded time with the last iterate kept, and
    Newton converges at both."""
    scene = LayeredBlockOnBelt(layer_nu=layer_nu, spring_height=30.5 / 12)
    beta = (1 - 2 * layer_nu) / (2 * (1 - layer_nu))
    model, (newton, process) = _solvers(scene, "newton", "panagiotopoulos", max_iterations=100,
                                        patience=4)
    report, _ = _solve(model, process, 0.8 / beta)
    assert report.converged
    mu = 1.3 / beta
    assert _solve(model, newton, mu)[0].converged
    model.initial_guess()
    with pytest.raises(ProcessError, match="mu=") as caught:
        process.solve()
    failed = caught.value.report
    assert not failed.converged and failed.outer_iterations <= 100
    assert failed.wall_time_s < 20  # bounded: at most 100 Newton solves of a 4 x 3 mesh
    u = model.residual.u.x.array
    assert np.all(np.isfinite(u))
    # the last iterate is a converged frozen solve: its normal force balances the weight
    assert model.quantities().normal_force == pytest.approx(scene.weight, rel=1e-8)


def test_bad_options_are_rejected():
    model = ff.BlockOnBelt().build(COMM, with_friction=True)
    with pytest.raises(ValueError, match="method='gauss-seidel'"):
        PanagiotopoulosSolver(model.residual, method="gauss-seidel")
    with pytest.raises(ValueError, match="mollification_radius=1.0"):
        PanagiotopoulosSolver(model.residual, method="newton", mollification_radius=1.0)
    with pytest.raises(ValueError, match="layer_thickness=40"):
        LayeredBlockOnBelt(layer_thickness=40.0)
    frictionless = ff.BlockOnBelt().build(COMM)
    with pytest.raises(ValueError, match="needs a friction term"):
        PanagiotopoulosSolver(frictionless.residual)


# --- two bodies: the block on an elastic slab (node-to-segment contact as a coupling) ------------

def _slab_profile(model, u):
    """(x, penetration) of the block's contact nodes, sorted by x, on every rank."""
    model.residual.u.x.array[:] = u
    d = model.nodal_contact()[0]
    x = model.V.tabulate_dof_coordinates()[model.contact.pairing.slave_nodes, 0]
    gathered = model.msh.comm.allgather((x, d))
    xs, ds = (np.concatenate(a) for a in zip(*gathered, strict=True))
    order = np.argsort(xs)
    return xs[order], ds[order]


def test_process_on_a_two_body_contact_reaches_newtons_state():
    """The block on a slab of its own stiffness, μ = 0.8 (half the tipping limit 1.6): the
    friction bound lives in the contact coupling's forms only, and the process fixes it there.

    The process stops at a change of 1e-8 (the coupled residual relative to the friction
    forces) with a contraction below 0.9 per iteration, so its traction is within ~1e-7 of the
    fixed point; d ∝ bound^(1/m_n): 1e-6 of the largest penetration leaves a factor ≥ 4 for
    the elastic solve's condition and Newton's own tolerance. Johnson's step (the frictionless
    pressure's bound) is off by more than 1e-3, so the comparison can tell a frozen bound
    from none."""
    model, (newton, process, johnson) = _solvers(BlockOnSlab(), "newton", "panagiotopoulos",
                                                 "johnson", rtol=1e-8)
    _, u_newton = _solve(model, newton, 0.8)
    report, u_process = _solve(model, process, 0.8)
    assert report.converged and 3 < report.outer_iterations < 15
    _, u_johnson = _solve(model, johnson, 0.8)
    x, d_newton = _slab_profile(model, u_newton)
    _, d_process = _slab_profile(model, u_process)
    _, d_johnson = _slab_profile(model, u_johnson)
    assert len(x) == 5 and d_newton.min() > 0
    assert np.max(np.abs(d_process - d_newton)) < 1e-6 * d_newton.max()
    assert np.max(np.abs(d_johnson - d_newton)) > 1e-3 * d_newton.max()


#: the contacts of the case-file tests: (formulation, model.degree)
CASE_CONTACTS = [("node-to-segment", 1), ("mortar", 1), ("mortar", 2)]


def _slab_case(folder, formulation: str, degree: int, comm=COMM):
    """cases/block-on-slab.toml with the contact's formulation and the degree given."""
    text = (ROOT / "cases" / "block-on-slab.toml").read_text().replace(
        'formulation = "node-to-segment"', f'formulation = "{formulation}"').replace(
        "degree = 1 ", f"degree = {degree} ")
    path = folder / f"slab-{formulation}-{degree}.toml"
    if COMM.rank == 0:
        path.write_text(text)
    COMM.Barrier()
    return CaseModel(read_case(path), comm)


def _case_pressures(model):
    """The contact's nodal pressures, sorted by the nodes' x, on every rank."""
    pair = model.body_contacts[0]
    pair.update(search=False)
    values = pair.nodal_values([pair.pressure])()[:, 0]
    slave = pair.nodal_weights > 0
    x = pair.nodal_space.tabulate_dof_coordinates()[:len(slave), 0]
    gathered = model.msh.comm.allgather((x[slave], values[slave]))
    xs, ps = (np.concatenate(a) for a in zip(*gathered, strict=True))
    return ps[np.argsort(xs)]


def _case_solve(model, method, mu, search=False):
    solver = PanagiotopoulosSolver(model.residual, method=method, prefix=f"case_{method}_",
                                   options={"snes_atol": 4.5e-8},
                                   parameters={"mu": model.parameters["mu"]})
    model.parameters["mu"].value = mu
    model.initial_guess()
    report = solver.solve()
    if search:
        solve_with_search(solver.solver, model.body_contacts)
    return report, _case_pressures(model)


@pytest.mark.parametrize(("formulation", "degree"), CASE_CONTACTS)
def test_process_on_a_case_files_contact_reaches_newtons_state(shared_tmp_path,
                                                               formulation, degree):
    """The block-on-slab case with either contact formulation, μ = 0.8: the process against
    Newton, whose state is made consistent with its pairing by solve_with_search (the case's
    guess leaves the block where the spring is relaxed: one Newton solve slides it 32 cm with
    the pairing of the guess, 8 % off in the pressures; each outer iteration of the process
    searches anew).

    Nodal pressures p = c_n d^{m_n} within 1e-6 of the largest: the process's 1e-8 on the
    friction forces with a contraction below 0.9, times m_n = 2.5 and a margin for the
    solves' tolerance. Johnson's step is more than 1e-3 off."""
    model = _slab_case(shared_tmp_path, formulation, degree)
    _, newton = _case_solve(model, "newton", 0.8, search=True)
    report, process = _case_solve(model, "panagiotopoulos", 0.8)
    _, johnson = _case_solve(model, "johnson", 0.8)
    assert report.converged and 3 < report.outer_iterations < 15
    assert len(newton) == 5 * degree - (degree - 1) and newton.min() > 0
    assert np.max(np.abs(process - newton)) < 1e-6 * newton.max()
    assert np.max(np.abs(johnson - newton)) > 1e-3 * newton.max()


@pytest.mark.mpi(min_size=2)
@pytest.mark.parametrize(("formulation", "degree"), [("node-to-segment", 1), ("mortar", 2)])
def test_distributed_process_on_two_bodies_matches_serial(shared_tmp_path,
                                                          formulation, degree):
    """The process on the block-on-slab case over COMM_WORLD (the mesh, the contact's slave
    nodes and the pairing split over the ranks) and on COMM_SELF: the same nodal pressures,
    to the same 1e-6 of the largest as against Newton, and the same number of outer
    iterations (the changes are norms of assembled vectors, equal up to round-off)."""
    pressures, outer = [], []
    for comm in (COMM, MPI.COMM_SELF):
        model = _slab_case(shared_tmp_path, formulation, degree, comm)
        report, p = _case_solve(model, "panagiotopoulos", 0.8)
        pressures.append(p)
        outer.append(report.outer_iterations)
    world, alone = pressures
    assert len(world) == len(alone) == 5 * degree - (degree - 1) and outer[0] == outer[1]
    assert np.max(np.abs(world - alone)) < 1e-6 * alone.max()


def test_couplings_without_the_friction_bound_hook_are_refused():
    """A coupling that cannot hand over its friction bound (only the solvers' members) would
    keep a live bound the process cannot see: refused, as is mollifying a coupling's bound."""
    model = BlockOnSlab().build(COMM, with_friction=True)

    class Opaque:  # a Coupling (the solvers' members), without FrictionBoundCoupling's
        search_pending, m_n = True, 1.0

        def operator(self, derivatives, rest=(), jit_cache_dir=None):
            return model.contact.operator(derivatives, rest, jit_cache_dir)

        def frequency_bound(self, lumped_mass):
            return 0.0

    opaque = dataclasses.replace(model.residual, couplings=[Opaque()])
    with pytest.raises(ValueError, match="residual='couplings'.*FrictionBoundCoupling"):
        PanagiotopoulosSolver(opaque)
    with pytest.raises(ValueError, match="mollification_radius=1.0"):
        PanagiotopoulosSolver(model.residual, mollification_radius=1.0)
