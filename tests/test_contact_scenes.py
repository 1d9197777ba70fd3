"""The two-body scenes with either contact formulation: node-to-segment (Pop) or mortar
(segment-to-segment integration of mortar-weighted gaps), degree 1 or 2.

Each claim is checked against something the code does not compute itself: the uniform
pressure of the contact patch test (Taylor & Papadopoulos 1991), Hertz's and
Cattaneo-Mindlin's closed forms (Johnson 1985, chapters 4 and 7), the one-body block on a
rigid belt, and the same scene solved on one rank.
"""

from mpi4py import MPI

import numpy as np
import pytest

import fenicsfriction as ff
from fenicsfriction.studies.block import slab
from fenicsfriction.studies.contact.validation import Cattaneo, Hertz, Patch


def test_the_slab_scene_offers_the_contact_formulations():
    """The block scenes' data spell the formulations without importing dolfinx: the same as
    the contact package's."""
    from fenicsfriction.contact import FORMULATIONS

    assert slab.FORMULATIONS == FORMULATIONS


@pytest.mark.parametrize("scene", [Hertz, Patch, Cattaneo])
def test_degree_two_needs_the_mortar_formulation(scene):
    with pytest.raises(ValueError, match=r"^degree=2 is invalid: 2 needs the mortar"):
        scene(degree=2)
    with pytest.raises(ValueError, match=r"^formulation='segment' is invalid"):
        scene(formulation="segment")
    with pytest.raises(ValueError, match=r"^degree=3 is invalid"):
        scene(formulation="mortar", degree=3)


def test_the_perturbed_lagrangian_is_node_to_segments():
    with pytest.raises(ValueError, match=r"^enforcement='perturbed-lagrangian' is invalid"):
        Cattaneo(formulation="mortar", enforcement="perturbed-lagrangian")


def test_slab_degree_two_needs_the_mortar_formulation():
    with pytest.raises(ValueError, match=r"^degree=2 is invalid"):
        ff.BlockOnSlab(degree=2)
    with pytest.raises(ValueError, match=r"^formulation='nodes' is invalid"):
        ff.BlockOnSlab(formulation="nodes")
    with pytest.raises(ValueError, match=r"^contact_quadrature='gauss' is invalid"):
        ff.BlockOnSlab(formulation="mortar", degree=2, contact_quadrature="gauss")
    scene = ff.BlockOnSlab(formulation="mortar", degree=2)  # the nodal rule is the contact's
    assert scene.contact_quadrature == "nodal"


def test_summaries_record_the_formulation_and_degree():
    summary, model = Patch(dim=2).run(MPI.COMM_WORLD)
    assert summary["parameters"]["formulation"] == "node-to-segment"
    assert summary["parameters"]["degree"] == 1
    assert model.formulation == "node-to-segment" and model.degree == 1


@pytest.mark.parametrize("passes", [1, 2])
@pytest.mark.parametrize("degree", [1, 2])
@pytest.mark.parametrize("dim", [2, 3])
def test_mortar_passes_the_patch_test(dim, degree, passes):
    """Taylor & Papadopoulos (1991): a uniform pressure must cross non-matching meshes
    uniformly. The mortar integrals are exact for the polynomials involved (segmentation,
    Gauss rules of degree 5 and 4), so it does, in one pass as in two and with quadratic
    elements, to the solver's tolerance: the force on every slave node is the applied
    pressure times the node's load weight (zero at the vertices of 6-node triangles) and the
    law's pressure at every node is the applied one. Node-to-segment deviates by 15-33 % in
    one pass (test_contact.py). Tolerance 1e-8: the load is reached to 1e-10 and Newton's
    residual is 1e-10 of the nodal forces (measured 2e-12 to 8e-12)."""
    scene = Patch(dim=dim, passes=passes, formulation="mortar", degree=degree)
    summary, model = scene.run(MPI.COMM_WORLD)
    assert summary["pressure_deviation"] < 1e-8
    values = model.surface_values()
    assert np.abs(values.pressure / scene.pressure - 1).max() < 1e-8
    assert summary["parameters"]["formulation"] == "mortar"
    assert summary["parameters"]["degree"] == degree


@pytest.mark.mpi(min_size=2)
@pytest.mark.parametrize(("dim", "degree"), [(2, 2), (3, 1)])
def test_mortar_patch_on_two_ranks_is_the_serial_one(dim, degree):
    """The mortar patch (the upper block on one rank, the lower on the other: the
    partitioner splits the two bodies) against the same scene solved by each rank alone:
    the slave nodes' forces agree to the solver's tolerance (Newton stops at |R| <= 1e-9
    against forces of 1e-2 per unit length or area), the deviations to round-off."""
    scene = Patch(dim=dim, passes=2, formulation="mortar", degree=degree)
    summary, model = scene.run(MPI.COMM_WORLD)
    alone, model_alone = scene.run(MPI.COMM_SELF)
    here, there = model.surface_values(), model_alone.surface_values()
    # on failure, what each solve reached (a force off by the Newton residual's order, or
    # not, tells a loose solve from a parallel fault)
    solves = {key: (summary[key], alone[key])
              for key in ("residual_norm", "atol", "newton_iterations")}
    assert np.allclose(here.x, there.x)
    assert np.allclose(here.force, there.force, atol=1e-7 * scene.pressure), \
        (np.abs(here.force - there.force).max() / scene.pressure, solves)
    assert np.allclose(here.pressure, there.pressure, atol=1e-7 * scene.pressure), \
        (np.abs(here.pressure - there.pressure).max() / scene.pressure, solves)
    assert summary["pressure_deviation"] == pytest.approx(alone["pressure_deviation"],
                                                          abs=1e-8)


@pytest.mark.mpi(min_size=2)
def test_mortar_slab_steady_state_on_two_ranks_is_the_serial_one():
    """The block on a slab with mortar contact at μ = 0.3, distributed against each rank
    alone: the resultants agree to the solves' residual bound, sqrt(n) (|R| + atol) each
    (a resultant is a row sum of R), and the contact nodes' penetrations to the relative
    amount δd/d = δN/(m_n N), times 10 for a non-uniform error (as the node-to-segment test
    in test_block_on_slab.py)."""
    scene = ff.BlockOnSlab(refine=2, slab_thickness=5.0, slab_E=1.4e7, formulation="mortar")
    results = []
    for comm, prefix in ((MPI.COMM_WORLD, "mortar_world_"), (MPI.COMM_SELF, "mortar_self_")):
        model = scene.build(comm, with_friction=True)
        model.initial_guess()
        steady = ff.SteadySolver(model.residual, prefix=prefix, options=model.solver_options(),
                                 search_rounds=model.search_rounds)
        records = model.slide_to(0.3, steady, step=0.1)
        d = model.nodal_contact()[0]
        x = model.V.tabulate_dof_coordinates()[model._contact_y // 2, 0]
        xs, ds = (np.concatenate(a) for a in zip(*comm.allgather((x, d)), strict=True))
        order = np.argsort(xs)
        results.append((model, records[-1], xs[order], ds[order]))
    (world, a, xa, da), (alone, b, xb, db) = results
    n = world.V.dofmap.index_map.size_global * 2
    bound = np.sqrt(n) * (a["residual_norm"] + a["atol"] + b["residual_norm"] + b["atol"])
    qa, qb = world.quantities(), alone.quantities()
    for key in ("normal_force", "friction_force", "spring_force"):
        assert getattr(qa, key) == pytest.approx(getattr(qb, key), abs=bound), key
    assert xa == pytest.approx(xb, abs=1e-12)
    relative = 10 * bound / (scene.law.m_n * scene.weight)
    assert np.abs(da - db).max() <= relative * db.max() + 1e-15


def test_mortar_hertz_line_contact_against_hertz():
    """The cylinder on the block with mortar contact (P1, h = a/10) against Hertz (Johnson
    1985, chapter 4). The peak transmitted pressure (nodal force over load weight) and the
    ellipse fitted through the nodes' transmitted pressures are within 1 % of p0 (measured
    +0.17 % both) and the fitted half-width within 1 % of a (-0.05 %; Hertz's parabolic
    profile itself is good to ~0.2 % here). Where the weighted gaps change sign
    is one element inside the edge (measured -10.05 % = -1.0 h): a weighted gap averages the
    gap over the node's two elements, and outside the contact the gap grows like
    (x - a)^{3/2} to far more than the penetration p/c_n, so a node whose support straddles
    the edge opens; checked within 1.5 h."""
    scene = Hertz(h_contact=0.01, formulation="mortar")
    summary, _ = scene.run(MPI.COMM_WORLD)
    a, _ = scene.closed_form()
    assert abs(summary["max_pressure_error"]) < 0.01
    assert abs(summary["fitted_max_pressure_error"]) < 0.01
    assert abs(summary["fitted_half_width_error"]) < 0.01
    assert -1.5 * 0.01 < summary["half_width"] - a < 0


def test_mortar_cattaneo_stick_zone_against_cattaneo_mindlin():
    """Cattaneo-Mindlin with mortar contact (P1, h = a/10, Q = μP/2 in two increments): the
    stick zone's half-width c = a sqrt(1 - Q/μP) (Johnson 1985, chapter 7) is located to
    within the nodes' reach, 1.5 h (measured 0.0598 against 0.0707, -1.09 h; node-to-segment
    -0.59 h on this mesh, both -0.68 h at h = a/20), and the tangential traction's relative
    L2 error, which comes from the stick-slip boundary and the contact edges where the closed
    form has infinite slopes, stays below 25 % (measured 18 %; 11 % at h = a/20;
    node-to-segment 8.9 %)."""
    scene = Cattaneo(h_contact=0.01, increments=2, formulation="mortar")
    summary, _ = scene.run(MPI.COMM_WORLD)
    c = summary["cattaneo_stick_half_width"]
    assert abs(summary["stick_half_width"] - c) < 1.5 * 0.01
    assert summary["traction_error_l2"] < 0.25
    assert summary["parameters"]["formulation"] == "mortar"
