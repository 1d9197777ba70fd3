r"""The pin on the disc (``fenicsfriction.studies.squeal``, the coarse mesh, 8k dofs): its
flutter onset against the two-mode model built from its own modes, the growth of the flutter
mode in time against its eigenvalue, and the same eigenvalues on one and two ranks.

The measured numbers and their mesh convergence are in docs/brake-squeal.md.
"""

import math
import pathlib

from mpi4py import MPI

import numpy as np
import pytest

from fenicsfriction.case import CaseModel, read_case
from fenicsfriction.stability import StabilitySolver
from fenicsfriction.steady import SteadySolver, continuation
from fenicsfriction.studies.squeal import geometry
from fenicsfriction.studies.squeal.model import PinOnDiscModel
from fenicsfriction.studies.squeal.study import stability_study, transient_growth
from fenicsfriction.studies.squeal.two_mode import TwoModeModel, coalescence

ROOT = pathlib.Path(__file__).resolve().parents[1]
MUS = [0.0, 0.3, 0.45]  # μ_crit = 0.371 on the coarse mesh
MAX_MODULUS = 2 * math.pi * 5000  # [1/s]: the band of the study (stability_study's default)


def build(comm=MPI.COMM_WORLD) -> PinOnDiscModel:
    return PinOnDiscModel(geometry.pin_on_disc(comm))


@pytest.fixture(scope="module")
def studied():
    """The coarse model and its study; the model is left in steady sliding at μ = 0.45, where
    a second pair (two modes of the pin) flutters too."""
    model = build()
    return model, stability_study(model, MUS, tol=2e-3, prefix="test_pod_")


def test_the_closed_form_coalescence_is_where_the_two_frequencies_merge():
    """coalescence() against the eigenvalues of the 2 × 2 problem: two real frequencies just
    below μ_c, a complex pair (one growing) just above, ω² at μ_c the mean of the diagonal."""
    K0 = np.diag([1.0, 4.0])
    B = np.array([[0.5, 1.0], [-2.0, -0.5]])
    mu_c, omega_c = coalescence(K0, B)
    for mu, merged in ((mu_c * (1 - 1e-6), False), (mu_c * (1 + 1e-6), True)):
        omega2 = np.linalg.eigvals(K0 + mu * B)
        assert (abs(omega2.imag).max() > 0) == merged
    K = K0 + mu_c * B
    assert omega_c**2 == pytest.approx((K[0, 0] + K[1, 1]) / 2)
    assert np.linalg.eigvals(K)[0] == pytest.approx(omega_c**2, rel=1e-6)


def test_the_two_mode_model_scales_stiffness_and_damping_from_its_mu1():
    """TwoModeModel.build from matrices projected at μ₁ = 0.3 (not 1, where μ/μ₁ = μ would hide
    a dropped μ₁): its eigenvalues at μ are those of λ² + λ (μ/μ₁) C₁ + K0 + μ (K₁ - K0)/μ₁,
    by the companion matrix; the frequencies are √diag(K0)/2π [Hz]."""
    K0 = np.diag([(2 * math.pi * 1000.0) ** 2, (2 * math.pi * 1100.0) ** 2])
    K1 = K0 + np.array([[2e6, 9e6], [-7e6, 1e6]])
    C1 = np.array([[30.0, 8.0], [-5.0, 12.0]])
    model = TwoModeModel.build(K0, K1, C1, mu1=0.3, indices=[0, 1])
    assert model.frequencies == pytest.approx([1000.0, 1100.0], rel=1e-12)
    mu = 0.45
    C, K = (mu / 0.3) * C1, K0 + (mu / 0.3) * (K1 - K0)
    companion = np.block([[np.zeros((2, 2)), np.eye(2)], [-K, -C]])
    expected = np.linalg.eigvals(companion)
    expected = np.sort_complex(expected[expected.imag >= 0])
    # two dense solvers (QZ on the pencil, eig on the unscaled companion with |K| ~ 5e7) agree
    # to ~4e-10 here; a dropped μ₁ moves the growth rates by a factor 0.3
    np.testing.assert_allclose(model.eigenvalues(mu), expected, rtol=1e-8)


def test_flutter_starts_where_a_pin_mode_meets_a_disc_mode(studied):
    """The onset lies inside the grid's bracket; the two modes that merge are a mode of the
    disc (under 10 % of its kinetic energy in the pin) and one of the pin (over half), and the
    two-mode model's real modes sit either side of the onset frequency; the projected K̄ is
    linear in μ (the steady state enters only through the small geometric terms of the
    contact)."""
    _, study = studied
    assert MUS[1] < study.mu_crit < MUS[2]
    disc, pin = sorted(study.coupling, key=lambda m: m["pin_share"])
    assert disc["pin_share"] < 0.1 < 0.5 < pin["pin_share"]
    low, high = study.two_mode["frequencies_hz"]
    assert low < study.onset_value[1] / (2 * math.pi) < high
    assert study.two_mode_linearity < 1e-4


def test_the_projected_onset_converges_to_the_full_one_with_the_modes(studied):
    """The pencil projected on the two real modes (Hoffmann's model, closed form) flutters
    later than the full model: it drops the other modes, through which the pin's mode veers
    faster towards the disc's (32 % on the coarse mesh, docs/brake-squeal.md). Projected on
    the 12 lowest modes (up to 9.4 kHz, twice the band) its onset nears the full model's, to
    a Galerkin error of the modes left out that depends on the mesh: 0.6 %, 4.7 % and 0.8 % on
    three meshes of Debian 12's gmsh, 5.8 % on the coarse mesh of Debian 13's (8,043 unknowns
    against 8,004). So: within 8 %, and at most a quarter of the two-mode model's error
    (measured 2 % to 19 % of it)."""
    _, study = studied
    assert study.two_mode["mu_c"] > study.mu_crit
    assert study.two_mode["mu_c_damped"] == pytest.approx(study.two_mode["mu_c"], rel=2e-2)
    assert study.basis_onset == pytest.approx(study.mu_crit, rel=8e-2)
    assert (abs(study.basis_onset - study.mu_crit)
            < 0.25 * abs(study.two_mode["mu_c"] - study.mu_crit))


def test_the_flutter_mode_grows_at_the_rate_of_its_eigenvalue(studied):
    """From the steady state at μ = 0.45 plus its fastest growing mode (1 nm at most), the normal
    force oscillates as N₀ + A e^{at} cos(ωt + φ). Generalized-α with ρ∞ = 1 is the
    trapezoidal rule: a mode λ is multiplied by z = (1 + λΔt/2)/(1 - λΔt/2) per step, so the
    fit must give log|z|/Δt and arg z/Δt (0.3 %: the fit of two periods), and so a and ω of
    the PEP within (ωΔt)²/4 = 1.1 % and (ωΔt)²/12 (30 steps per period)."""
    model, _ = studied
    modes = StabilitySolver(model.residual, prefix="test_pod_growth_pep_").solve(MAX_MODULUS)
    growing = max(modes, key=lambda m: m.value.real)
    steps = 30
    run = transient_growth(model, growing, amplitude=1e-9, periods=2.0, steps_per_period=steps,
                           prefix="test_pod_ts_")
    lam = growing.value
    dt = 2 * math.pi / lam.imag / steps
    z = (1 + lam * dt / 2) / (1 - lam * dt / 2)
    a, omega = run.fitted
    assert run.max_relative_force < 0.05  # the linear regime
    assert a == pytest.approx(math.log(abs(z)) / dt, rel=3e-3)
    assert omega == pytest.approx(np.angle(z) / dt, rel=1e-3)
    assert a == pytest.approx(lam.real, rel=1.5e-2)
    assert omega == pytest.approx(lam.imag, rel=1e-2)


def test_the_case_file_is_the_same_model(studied, shared_tmp_path):
    """cases/pin-on-disc.toml run to μ = 0.45: the same growing eigenvalue as the Python
    scene's (Newton to 1e-10 of the load, the PEP to 1e-10). Its mesh is written here by the
    function its script calls (the case runner's ``python SCRIPT`` cannot start MPI inside an
    ``mpirun``)."""
    model, _ = studied
    path = shared_tmp_path / "pin-on-disc.toml"
    if MPI.COMM_WORLD.rank == 0:
        geometry.pin_on_disc(MPI.COMM_SELF, msh_file=str(shared_tmp_path / "pin-on-disc.msh"))
        path.write_text((ROOT / "cases" / "pin-on-disc.toml").read_text().replace(
            '"../meshes/pin_on_disc.py"', f'"{ROOT / "meshes" / "pin_on_disc.py"}"'))
    case = read_case(path) if MPI.COMM_WORLD.rank == 0 else None
    case = MPI.COMM_WORLD.bcast(case, root=0)
    from_file = CaseModel(case, MPI.COMM_WORLD)
    from_file.initial_guess()
    steady = SteadySolver(from_file.residual, prefix="test_pod_case_", linear_solver="lu")
    continuation(steady, from_file.parameters["mu"], MUS)
    growing = [max((m.value for m in StabilitySolver(residual, prefix=f"test_pod_{name}_pep_")
                    .solve(MAX_MODULUS)), key=lambda v: v.real)
               for name, residual in (("case", from_file.residual), ("scene", model.residual))]
    assert growing[0] == pytest.approx(growing[1], rel=1e-7)


@pytest.mark.mpi(min_size=2)
def test_the_eigenvalues_are_the_same_on_one_and_two_ranks(studied):
    """The growing eigenvalue at μ = 0.45 of the distributed model and of a serial one, each
    converged by Newton to 1e-10 of the load and the PEP to 1e-10."""
    model, _ = studied
    distributed = StabilitySolver(model.residual, prefix="test_pod_world_").solve(MAX_MODULUS)
    serial = build(MPI.COMM_SELF)
    serial.initial_guess()
    steady = SteadySolver(serial.residual, prefix="test_pod_self_", linear_solver="lu")
    continuation(steady, serial.mu, MUS)
    alone = StabilitySolver(serial.residual, prefix="test_pod_self_pep_").solve(MAX_MODULUS)
    growing = [max((m.value for m in modes), key=lambda v: v.real)
               for modes in (distributed, alone)]
    assert growing[0] == pytest.approx(growing[1], rel=1e-7)
