"""The master equation of the earthquake-like model: conservation, its steady state and the
first break in closed form, second-order convergence, and agreement with the model's mean."""

import numpy as np
import pytest
from scipy import optimize, stats
from scipy.integrate import trapezoid

from fenicsfriction.studies.multicontact import EQModel, MasterEquation, critical_stiffness

pytestmark = pytest.mark.sequential


@pytest.mark.parametrize("newborn", [None, stats.norm(loc=0.0, scale=0.1)],
                         ids=["relaxed", "gaussian"])
def test_the_number_of_contacts_is_conserved_to_round_off(newborn):
    result = MasterEquation(EQModel(x_s_std=0.3, newborn=newborn), h=0.01).solve(X_max=5.0)
    # 500 steps, each a sum of ~200 masses: round-off ~ 500 × 200 × 1e-16
    assert result.mass_error < 1e-11


@pytest.mark.parametrize("P_c", [stats.uniform(loc=0.5, scale=1.0), stats.gamma(a=4.0, scale=0.25),
                                 stats.truncnorm(a=-2.0, b=np.inf, loc=1.0, scale=0.5)],
                         ids=["uniform", "gamma", "truncated normal"])
def test_steady_force_is_N_k_mean_square_threshold_over_twice_the_mean(P_c):
    model = EQModel(n_contacts=100, k=2.0, thresholds=P_c)
    closed_form = 100 * 2.0 * P_c.moment(2) / (2 * P_c.mean())
    equation = MasterEquation(model, h=0.005)
    # the quadrature of Q_s(x) ∝ ∫_x^∞ P_c, to QUADPACK's accuracy
    assert equation.steady_force() == pytest.approx(closed_form, rel=1e-8)
    # the steady state of the scheme: its O(h²) error, (h/σ)² ~ 1e-4 at most here
    assert equation.kinetic_force() == pytest.approx(closed_form, rel=1e-4)
    # the transient after 30 mean thresholds: O(h²) ~ 1e-5 and a decayed start
    assert equation.solve(X_max=30.0).force_at_X_max == pytest.approx(closed_form, rel=1e-4)


def test_kinetic_force_converges_to_the_closed_form_at_second_order():
    model = EQModel(n_contacts=1000, x_s_std=0.1)
    closed_form = 1000 * stats.truncnorm(a=-10.0, b=np.inf, loc=1.0, scale=0.1).moment(2) / 2
    errors = [abs(MasterEquation(model, h=h).kinetic_force() - closed_form)
              for h in (0.04, 0.02, 0.01)]
    np.testing.assert_allclose(np.log2(np.array(errors[:-1]) / errors[1:]), 2.0, atol=0.05)


@pytest.mark.parametrize("newborn", [None, stats.norm(loc=0.2, scale=0.1)],
                         ids=["relaxed", "gaussian"])
def test_steady_state_is_a_fixed_point_of_the_step(newborn):
    equation = MasterEquation(EQModel(x_s_std=0.2, newborn=newborn), h=0.01)
    q = equation.steady_state()
    assert np.sum(q) == pytest.approx(1.0, abs=1e-14) and np.all(q >= 0)
    np.testing.assert_allclose(equation.step(q), q, rtol=0, atol=1e-14)


def test_gaussian_newborn_kinetic_force_is_the_continuous_steady_state():
    """Q_s(x) ∝ s(x) ∫_{-∞}^x r(ξ)/s(ξ) dξ (the steady equation's solution along the
    characteristics, s the survival of P_c), by quadrature on a grid 100 times finer than
    the scheme's: the scheme's O(h) error (reborn contacts may break within a step) is
    (h/σ)·P(x)·h-sized, below 1e-3 here."""
    P_c = stats.truncnorm(a=-10.0, b=np.inf, loc=1.0, scale=0.1)
    newborn = stats.norm(loc=0.2, scale=0.1)
    model = EQModel(n_contacts=300, k=2.0, x_s_std=0.1, newborn=newborn)
    x = np.linspace(-0.5, 2.0, 250_001)
    s = P_c.sf(x)
    inner = np.concatenate([[0.0], np.cumsum(0.5 * (newborn.pdf(x[1:]) / s[1:]
                                                   + newborn.pdf(x[:-1]) / s[:-1])
                                             * np.diff(x))])
    Q = s * inner
    quadrature = 300 * 2.0 * trapezoid(x * Q, x) / trapezoid(Q, x)
    assert MasterEquation(model, h=0.005).kinetic_force() == pytest.approx(quadrature,
                                                                            rel=1e-3)


def test_kinetic_force_is_the_steady_one_and_the_transient_end_is_named_apart():
    """N = 1000, σ = 0.1 x_c: five lives leave the transient 2.5 % above the steady force;
    after 100 lives it has reached it (the decay is geometric, 2e-9 measured)."""
    equation = MasterEquation(EQModel(n_contacts=1000, x_s_std=0.1), h=0.01)
    closed_form = equation.steady_force()
    short, long = equation.solve(X_max=5.0), equation.solve(X_max=100.0)
    for result in (short, long):
        assert result.kinetic_force == pytest.approx(closed_form, rel=1e-4)  # O(h²) = 2e-5
        assert result.X_max == result.X[-1] and result.force_at_X_max == result.F[-1]
        # the force is N k ∫ x Q at the last X: recomputed from the stored Q
        assert result.force_at_X_max == pytest.approx(1000 * float(result.x @ result.Q),
                                                      rel=1e-14)
    assert short.X_max == 5.0 and short.force_at_X_max / short.kinetic_force - 1 > 0.02
    assert long.force_at_X_max == pytest.approx(long.kinetic_force, rel=1e-7)


def test_static_force_is_the_peak_of_the_first_break_in_closed_form():
    """Before any re-formed contact breaks, F/(N k) = X s(X) + ∫_0^X p(ξ)(X − ξ) dξ
    = X − ∫_0^X ξ p(ξ) dξ (s, p: P_c's survival and density given x_s > 0), whose maximum,
    where X p(X) = 1, is the static force (re-formed contacts break from X ≈ 1.4 on)."""
    P_c = stats.norm(loc=1.0, scale=0.1)
    X = np.linspace(0.0, 1.4, 140_001)
    xp = X * P_c.pdf(X) / P_c.sf(0.0)
    closed_form = 50 * 2.0 * float(np.max(
        X - np.concatenate([[0.0], np.cumsum(0.5 * (xp[1:] + xp[:-1]) * np.diff(X))])))
    result = MasterEquation(EQModel(n_contacts=50, k=2.0, x_s_std=0.1), h=0.005).solve(3.0)
    assert result.static_force == float(np.max(result.F))
    # the scheme's O(h²) with h/σ = 0.05
    assert result.static_force == pytest.approx(closed_form, rel=1e-4)  # 4e-6 measured


def test_the_default_gaussian_steady_force_uses_thresholds_above_zero():
    model = EQModel(n_contacts=10, x_s_mean=1.0, x_s_std=0.5)
    P_c = stats.truncnorm(a=-2.0, b=np.inf, loc=1.0, scale=0.5)  # P_c given x_s > 0
    assert MasterEquation(model, h=0.01).steady_force() == pytest.approx(
        10 * P_c.moment(2) / (2 * P_c.mean()), rel=1e-8)


def test_force_converges_at_second_order_in_the_step():
    model = EQModel(n_contacts=1, x_s_std=0.3)
    reference = MasterEquation(model, h=0.0005).solve(X_max=3.0).F[-1]
    errors = [abs(MasterEquation(model, h=h).solve(X_max=3.0).F[-1] - reference)
              for h in (0.04, 0.02, 0.01)]
    orders = np.log2(np.array(errors[:-1]) / errors[1:])
    np.testing.assert_allclose(orders, 2.0, atol=0.2)


def test_critical_stiffness_matches_the_first_break_in_closed_form():
    # before any re-formed contact breaks, F/(N k) = X s(X) + ∫_0^X p(ξ)(X − ξ) dξ with
    # s = P_c's survival and p its density (given x_s > 0), so F'/(N k) = 1 − X p(X)
    P_c = stats.norm(loc=1.0, scale=0.1)
    slope = optimize.minimize_scalar(lambda X: -X * P_c.pdf(X), bounds=(0.5, 1.5),
                                     method="bounded", options={"xatol": 1e-10})
    closed_form = 50 * 2.0 * (-slope.fun / P_c.sf(0.0) - 1.0)
    # centred differences of F on a grid of σ/50: O((h/σ)²) ~ 1e-3
    assert critical_stiffness(EQModel(n_contacts=50, k=2.0, x_s_std=0.1)) == pytest.approx(
        closed_form, rel=2e-3)


def test_transient_is_the_mean_of_the_model_and_its_noise_falls_like_one_over_root_N():
    X_max, h, every = 4.0, 0.002, 50
    master = MasterEquation(EQModel(n_contacts=1, x_s_std=0.3), h=h).solve(X_max=X_max)
    assert master.static_force > 1.15 * master.kinetic_force  # a static peak, then kinetic
    X, F_per_contact = master.X[::every], master.F[::every]
    sizes = np.array([100, 400, 1600, 6400])
    noise = []
    for n in sizes:
        runs = [EQModel(n_contacts=int(n), x_s_std=0.3).quasistatic(X_max, n_points=X.size,
                                                                    seed=seed)
                for seed in range(8)]
        np.testing.assert_allclose(runs[0].X, X, atol=1e-12)
        noise.append(np.sqrt(np.mean([(run.F / n - F_per_contact) ** 2 for run in runs])))
    exponent = np.polyfit(np.log(sizes), np.log(noise), 1)[0]
    # 8 realisations × 81 correlated points per size: the exponent is known to about ±0.05;
    # a bias of the master equation (h² ~ 4e-6 of x_c) would flatten it at large N
    assert exponent == pytest.approx(-0.5, abs=0.1)


def test_bad_step_is_named_in_the_error():
    with pytest.raises(ValueError, match="h"):
        MasterEquation(EQModel(), h=0.0)
    with pytest.raises(ValueError, match="newborn"):
        MasterEquation(EQModel(newborn=stats.norm(0.0, 0.1)), h=0.01).steady_force()
