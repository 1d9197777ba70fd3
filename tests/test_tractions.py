"""One source for the interface tractions: the laws' functions against finite differences and
closed forms, and the block's observables (probe, stick-band damping) against the law written
out in the test; misuse of a frictionless model; the dolfinx-free packages."""

import os
import subprocess
import sys

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem.petsc
import numpy as np
import pytest
import ufl

import fenicsfriction as ff
from fenicsfriction import _compat, laws
from fenicsfriction.studies.block import BlockOnBelt

COMM = MPI.COMM_WORLD


def test_friction_traction_of_a_speed_law_scales_the_direction_by_mu_of_the_slip_speed():
    law = laws.StribeckFriction(mu_s=0.8, mu_k=0.5, v_s=0.1)
    c_n, m_T, eps, d = 2.0e4, 2.5, 1e-3, 3e-4
    w = np.array([-0.3, -5e-4, 0.0, 2e-4, 0.05])
    traction = laws.friction_traction(d, w, lambda s: c_n * law(s), m_T, eps)
    mu = law.mu_k + (law.mu_s - law.mu_k) * np.exp(-np.abs(w) / law.v_s)
    direction = np.where(np.abs(w) < eps, w / eps, np.sign(w))
    assert traction == pytest.approx(-c_n * mu * d**m_T * direction, rel=1e-13)


def test_normal_traction_is_elastic_plus_damping_part():
    d, rate = np.array([0.0, 1e-4, 2e-3]), np.array([0.5, -0.2, 0.1])
    p = laws.normal_traction(d, 1e10, 2.5, rate, 3e8, 2.0)
    assert p == pytest.approx(1e10 * d**2.5 + 3e8 * d**2 * rate, rel=1e-14)
    assert laws.normal_traction(d, 1e10, 2.5) == pytest.approx(1e10 * d**2.5, rel=1e-14)


@pytest.fixture(scope="module")
def stribeck_block():
    """A block with a Stribeck law pressed into the belt, its nodes moving at v_x = 0.05."""
    law = laws.StribeckFriction(mu_s=0.8, mu_k=0.5, v_s=0.1)
    scene = BlockOnBelt(law=ff.InterfaceLaw(friction_coefficient=law, eps=1e-2))
    model = scene.build(COMM)
    model.initial_guess()
    bs = model.V.dofmap.index_map_bs
    model.residual.u_dot.x.array[0::bs] = 0.05
    return scene, model


def test_probe_friction_follows_a_velocity_dependent_law(stribeck_block):
    """The probe's friction is -c_n μ(|slip|) d^{m_T} φ'_ε(slip) at its own d and slip (it used to
    be evaluated with the constant μ, zero for this scene)."""
    scene, model = stribeck_block
    values = model.probe(scene.L / 2)
    d = max(-values.u_y - scene.law.g, 0.0)
    assert d > 0 and abs(values.slip) > scene.law.eps
    assert values.slip == pytest.approx(0.05 - scene.belt_speed, rel=1e-14)
    mu = scene.law.friction_coefficient(abs(values.slip))
    expected = -scene.law.c_n * mu * d**scene.law.m_n * np.sign(values.slip)
    assert values.friction == pytest.approx(expected, rel=1e-12)
    assert values.pressure == pytest.approx(scene.law.c_n * d**scene.law.m_n, rel=1e-12)


def test_friction_force_of_a_velocity_dependent_law_is_mu_of_the_slip_times_normal_force(
        stribeck_block):
    """Every contact node slips at the same speed, so F = -μ(|slip|) N sgn(slip)."""
    scene, model = stribeck_block
    q = model.quantities()
    slip = 0.05 - scene.belt_speed
    assert q.friction_force == pytest.approx(
        -scene.law.friction_coefficient(abs(slip)) * q.normal_force_elastic * np.sign(slip),
        rel=1e-12)


def _assembled(form) -> np.ndarray:
    vector = dolfinx.fem.petsc.assemble_vector(_compat.form(form))
    vector.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    values = vector.array_r.copy()
    vector.destroy()
    return values


@pytest.mark.parametrize("regularisation", sorted(laws.REGULARISATIONS))
def test_band_damping_is_the_closed_form_row_sum(regularisation):
    """Row sums of the tangential damping in the band: ∫ B0 c_T d^{m_T}/ε v_x on Γ_C."""
    scene = BlockOnBelt(law=ff.InterfaceLaw(mu=0.4, eps=2e-3, regularisation=regularisation))
    model = scene.build(COMM)
    model.initial_guess()
    v = model.residual.v
    d = ufl.max_value(-model.residual.u[1], 0.0)
    closed = scene.B0 * 0.4 * scene.law.c_n * d**scene.law.m_n / 2e-3 * v[0] * model.ds_contact
    expected = _assembled(closed)
    assert np.max(np.abs(expected)) > 0
    assert _assembled(model.band_damping()) == pytest.approx(
        expected, rel=1e-13, abs=1e-13 * np.max(np.abs(expected)))


@pytest.mark.parametrize("build", [{}, {"with_friction": False}])
def test_stepping_mu_on_a_frictionless_model_is_refused(build):
    model = BlockOnBelt().build(COMM, **build)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix="frictionless_",
                             options=model.solver_options())
    with pytest.raises(ValueError, match="mu=0.3"):
        model.mu.value = 0.3
    with pytest.raises(ValueError, match="mu="):
        ff.continuation(solver, model.mu, [0.0, 0.2])
    assert float(model.mu.value) == 0.0


def test_stepping_mu_on_a_model_with_a_speed_law_is_refused(stribeck_block):
    _, model = stribeck_block
    with pytest.raises(ValueError, match="mu=0.3.*velocity-dependent"):
        model.mu.value = 0.3


def test_slide_to_ramps_mu_from_zero_and_holds_mu_w_in_the_spring():
    scene = BlockOnBelt(law=ff.InterfaceLaw(mu=0.3))
    model = scene.build(COMM)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix="slide_", options=model.solver_options())
    rows = model.slide_to(0.3, solver, step=0.12)
    assert [r["value"] for r in rows] == pytest.approx([0.0, 0.1, 0.2, 0.3], rel=1e-15)
    q = model.quantities()
    assert -q.spring_force == pytest.approx(0.3 * scene.weight, rel=1e-6)


def test_perturb_normal_velocity_moves_the_y_components_only():
    model = BlockOnBelt().build(COMM)
    before = model.residual.u_dot.x.array.copy()
    model.perturb_normal_velocity(-0.01)
    change = model.residual.u_dot.x.array - before
    assert np.all(change[1::2] == -0.01) and np.all(change[0::2] == 0.0)


@pytest.mark.skipif(COMM.size > 1, reason="starts its own interpreter; runs in the serial pass")
def test_reduced_models_and_scenes_import_without_dolfinx():
    code = ("import sys, fenicsfriction.studies, fenicsfriction.studies.block.data, "
            "fenicsfriction.studies.block.slab, fenicsfriction.studies.block.rigid; "
            "assert 'dolfinx' not in sys.modules, sorted(m for m in sys.modules if 'dolfinx' in m)")
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            timeout=120, env=env)
    assert result.returncode == 0, result.stderr
