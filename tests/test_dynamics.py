"""Dynamics (TSALPHA2 on the one residual) against the eigenproblem and energy conservation."""

import numpy as np
import pytest
import scipy.optimize

from mpi4py import MPI

import fenicsfriction as ff
from fenicsfriction.dynamics import DynamicsSolver
from fenicsfriction.stability import StabilitySolver


def steady_block(mu: float, comm=MPI.COMM_WORLD, prefix="dyn", **scene):
    """A converged steady sliding state of the block at μ."""
    model = ff.BlockOnBelt(mu=mu, **scene).build(comm, with_friction=mu > 0)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix=f"{prefix}_steady_",
                             options=model.solver_options())
    ff.continuation(solver, model.mu, np.linspace(0.0, mu, 5))
    return model


def perturbed_run(model, dt: float, t_end: float, v_y: float, prefix: str):
    model.residual.u_dot.x.array[1::2] = v_y
    dynamics = DynamicsSolver(model.residual, prefix=prefix, atol=1e-12 * model.force_scale,
                              options={"snes_rtol": 1e-14})
    return dynamics.run(t_end, dt, observe=lambda t: {
        "normal_force": model.quantities()["normal_force"], **model.energies()})


def test_energy_without_friction_is_conserved_to_second_order_in_the_step():
    """Generalized-α with ρ∞ = 1 is second order: the energy error of the bouncing block
    (power-law contact, no friction or damping) must fall fourfold when dt halves."""
    errors = []
    for k, dt in enumerate((2e-5, 1e-5, 5e-6)):
        model = steady_block(0.0, prefix=f"energy{k}")
        records = perturbed_run(model, dt, 1e-3, -0.01, f"energy{k}_ts_")
        energy = np.array([r["total"] for r in records])
        errors.append(np.abs(energy - energy[0]).max() / max(r["kinetic"] for r in records))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert errors[-1] < 1e-5
    assert np.all(orders > 1.9), (errors, orders)


def test_growth_and_frequency_of_the_perturbation_match_the_unstable_eigenvalue():
    """At μ = 0.6 steady sliding is unstable (flutter pair λ = ±a + iω). A small normal
    velocity perturbation (linear regime: N varies < 1 %) excites the pair; fitting
    A e^{at} cos(ωt + φ) + B e^{-at} cos(ωt + ψ) + c to N(t) must give a and ω of the
    PEP within 1 % (time error of the scheme at dt = 1e-5 s: (ω dt)² ~ 3e-3 in phase)."""
    model = steady_block(0.6, prefix="growth")
    lam = max(StabilitySolver(model.residual, prefix="growth_pep_").solve(2e4),
              key=lambda m: m.value.real).value
    records = perturbed_run(model, 1e-5, 6e-3, -1e-4, "growth_ts_")
    t = np.array([r["time"] for r in records])
    n = np.array([r["normal_force"] for r in records])
    assert np.abs(n - n[0]).max() < 0.02 * n[0]  # linear regime

    def pair(t, a, w, c1, s1, c2, s2, c0):
        return (np.exp(a * t) * (c1 * np.cos(w * t) + s1 * np.sin(w * t))
                + np.exp(-a * t) * (c2 * np.cos(w * t) + s2 * np.sin(w * t)) + c0)

    guess = [0.9 * lam.real, 1.02 * lam.imag] + [np.std(n)] * 4 + [0.0]
    (a, w, *_), _ = scipy.optimize.curve_fit(pair, t, n - n.mean(), p0=guess, maxfev=20000)
    assert a == pytest.approx(lam.real, rel=1e-2)
    assert w == pytest.approx(lam.imag, rel=1e-2)


@pytest.mark.mpi(min_size=2)
def test_time_integration_is_the_same_on_one_and_two_ranks():
    series = []
    for comm, name in ((MPI.COMM_WORLD, "world"), (MPI.COMM_SELF, "self")):
        model = steady_block(0.6, comm=comm, prefix=f"ranks_{name}")
        records = perturbed_run(model, 1e-5, 1e-3, -1e-3, f"ranks_{name}_ts_")
        series.append(np.array([r["normal_force"] for r in records]))
    # Newton stops at 1e-12 of the load; the difference may only be round-off amplified by
    # the growing mode over 1 ms (e^{0.5} < 2)
    assert np.allclose(series[0], series[1], rtol=0, atol=1e-8 * series[0].max())


def test_central_differences_agree_with_generalized_alpha_and_respect_the_stable_step():
    """The explicit scheme (lumped mass) and the implicit one integrate the same residual:
    their normal forces agree to the schemes' O(dt²) error, and the explicit step is capped
    below the stable step 2/ω_max whatever step is asked for."""
    from fenicsfriction.dynamics import CentralDifference
    forces = []
    for scheme in ("central", "alpha2"):
        model = steady_block(0.6, prefix=f"cd_{scheme}")
        model.residual.u_dot.x.array[1::2] = -1e-4
        observe = lambda t, m=model: {"normal_force": m.quantities()["normal_force"]}  # noqa: E731
        if scheme == "central":
            explicit = CentralDifference(model.residual)
            records = explicit.run(2e-3, 2e-3, observe=observe)
            assert max(r["dt"] for r in records) <= 0.9 * explicit.stable_dt * (1 + 1e-12)
        else:
            records = DynamicsSolver(model.residual, prefix="cd_ts_",
                                     atol=1e-12 * model.force_scale).run(2e-3, 1e-6, observe)
        t = np.array([r["time"] for r in records])
        forces.append(np.interp(np.linspace(0, 2e-3, 41), t,
                                [r["normal_force"] for r in records]))
    signal = np.abs(forces[1] - forces[1][0]).max()
    assert np.abs(forces[0] - forces[1]).max() < 1e-2 * signal
