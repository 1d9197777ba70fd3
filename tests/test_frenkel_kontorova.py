"""Slip fronts of the FK-EQ chain (fenicsfriction.studies.multicontact.frenkel_kontorova): the
front speed against the continuum travelling wave and the sound speed, the energy balance across
located breaks, pinning by a threshold spread, and hysteresis under a force cycle."""

import numpy as np
import pytest

from fenicsfriction.studies.multicontact.frenkel_kontorova import (
    FKChain,
    TriangleRamp,
    _Chain,
    front_speeds,
)

pytestmark = pytest.mark.sequential

# κ = k + K = 1.25: f_min = 0.75, f_max = 1.25, kink width a sqrt(g/κ)
PARAMETERS = {"m": 1.0, "eta": 1.0, "k": 1.0, "K": 0.25, "u_s": 1.0}


def chain(n: int, g: float, **kwargs) -> FKChain:
    return FKChain(n=n, g=g, **{**PARAMETERS, **kwargs})


def test_front_speed_tends_to_the_continuum_travelling_wave_as_the_kink_widens():
    # the chain's discreteness corrects the continuum speed at order (a/w)² = κ/g, w the kink
    # width: 1.25 % at g = 100, 0.31 % at g = 400; the speed is fitted over 80 and 100 contacts
    # well behind the starting step (its transient) and ahead of the free end (its reflection)
    errors = []
    for g, n, relaxed, first, last in ((100.0, 200, 20, 60, 140), (400.0, 300, 40, 100, 200)):
        speeds = front_speeds(chain(n, g), [1.0], relaxed=relaxed, first=first, last=last)
        errors.append(abs(speeds.measured[0] / speeds.continuum[0] - 1))
    assert errors[0] < 0.02
    assert errors[1] < 0.005
    assert errors[1] < errors[0] / 3  # second order in a/w: 4 times smaller for w twice as wide


def test_front_is_subsonic_below_f_max_but_outruns_sound_as_a_domino_at_f_max():
    c = chain(120, 25.0)
    speeds = front_speeds(c, [1.1, 1.2, 1.24], relaxed=10, first=30, last=90)
    # the continuum front is bounded by c_0 = 5; so is the chain's at 1.1 and 1.2
    assert np.all(speeds.continuum < c.sound_speed)
    assert np.all(speeds.measured[:2] < c.sound_speed)
    assert speeds.measured[1] > speeds.measured[0]  # faster with a larger drive
    # at f = 1.24 the intact contacts sit within (f_max - f)/κ = 0.008 of their threshold:
    # each breaks in the short time its broken neighbour takes to pull it that far, and the
    # front runs as a domino faster than c_0 (steadily: 5.72 over contacts 30-90 and 500-600
    # of a 640-contact chain). The continuum has no such front: ahead of a front at v > c_0
    # its profile would need (m v² - a² g) λ² + m η v λ + κ = 0 with λ > 0; the chain's
    # 4 g sinh²(λa/2) in place of a² g λ² admits a steep precursor at any speed
    assert speeds.measured[2] > c.sound_speed


def test_continuum_speed_has_the_low_and_high_velocity_limits():
    c = chain(10, 100.0)
    # relative corrections: O(r²) at f_min (r = 2(f - f_min)/(k u_s)), O(1 - r) at f_max
    for offset in (1e-3, 1e-5):
        low = c.f_min + offset
        assert c.continuum_front_speed(low) == pytest.approx(c.low_velocity_speed(low),
                                                             rel=10 * offset)
        high = c.f_max - offset
        assert c.continuum_front_speed(high) == pytest.approx(c.high_velocity_speed(high),
                                                              rel=10 * offset)
    assert c.continuum_front_speed(c.f_min) == 0.0


def test_work_of_the_force_balances_dissipation_storage_and_broken_contacts():
    c = chain(60, 25.0)
    result = c.simulate(TriangleRamp(0.5, 1.0, 20.0), 50.0, relaxed=10, sample_dt=0.5)
    assert result.break_sites.size > 20  # the balance crosses many breaks
    # the integrals ride in the state: their error is the Runge-Kutta error (rtol 1e-8 per
    # step, a few thousand steps); each break is booked at its located stretching u_s ± 1e-12
    assert np.max(np.abs(result.energy_residual())) < 1e-6 * np.max(np.abs(result.work))
    assert np.all(np.diff(result.dissipated) >= 0)
    assert result.broken_loss[-1] == pytest.approx(
        0.5 * c.k * c.u_s**2 * result.break_sites.size, rel=1e-10)


def test_force_cycle_leaves_the_front_advanced_at_the_static_equilibrium():
    c = chain(60, 25.0)
    result = c.simulate(TriangleRamp(0.5, 0.9, 20.0), 70.0, relaxed=10, sample_dt=0.5)
    n = c.n
    anchors_start, anchors_end = result.hybrid.y[0, 2 * n:], result.hybrid.y[-1, 2 * n:3 * n]
    # below f_min the front does not retreat: no contact breaks backwards, the broken ones stay
    assert np.all(anchors_end >= anchors_start[:n])
    assert result.break_sites.size > 5
    # 30 time units after the ramp with damping η = 1 the chain is at rest, at the equilibrium
    # of its new anchors (a linear solve, independent of the integration): e^{-15} ~ 3e-7
    assert result.u[-1] == pytest.approx(c.equilibrium(0.5, anchors_end), abs=1e-5)
    assert result.u[0] == pytest.approx((0.5 + c.k * anchors_start[:n]) / (c.k + c.K))
    # hysteresis: at the same force the chain ends further forward than it started
    shift = np.mean(c.equilibrium(0.5, anchors_end) - c.equilibrium(0.5, anchors_start[:n]))
    assert result.mean_displacement[-1] - result.mean_displacement[0] == pytest.approx(
        shift, abs=1e-5)
    assert shift > 0
    assert result.front_position[-1] == c.a * result.break_sites.max()


def test_threshold_spread_pins_a_front_that_crosses_the_uniform_chain():
    # above f_min = 0.75 (and above the discrete chain's own pinning, near 0.78 here): on the
    # uniform chain the front runs through
    f, relaxed = 0.85, 10
    uniform = chain(60, 25.0).simulate(f, 40.0, relaxed=relaxed)
    assert np.all(np.isfinite(uniform.break_time[relaxed:]))
    spread = chain(60, 25.0).with_defects(0.2, seed=1)
    pinned = spread.simulate(f, 40.0, relaxed=relaxed)
    assert np.isnan(pinned.break_time[30:]).all()
    # pinned: no breaks in the last half of the run, the blocks at rest
    assert pinned.break_times.max() < 20.0
    assert np.abs(pinned.hybrid.y[-1, spread.n:2 * spread.n]).max() < 1e-3


def test_same_seed_gives_the_same_thresholds_and_front():
    base = chain(40, 25.0)
    first, again = (base.with_defects(0.1, seed=7).simulate(0.9, 10.0, relaxed=5)
                    for _ in range(2))
    np.testing.assert_array_equal(first.break_times, again.break_times)
    np.testing.assert_array_equal(base.with_defects(0.1, seed=7).thresholds,
                                  base.with_defects(0.1, seed=7).thresholds)
    assert not np.array_equal(base.with_defects(0.1, seed=7).thresholds,
                              base.with_defects(0.1, seed=8).thresholds)


@pytest.mark.parametrize(("kwargs", "name"), [({"n": 2}, "n"), ({"eta": 0.0}, "eta"),
                                              ({"K": -1.0}, "K"),
                                              ({"thresholds": np.ones(3)}, "thresholds")])
def test_bad_parameters_are_named(kwargs, name):
    with pytest.raises(ValueError, match=name):
        FKChain(**{"n": 10, "g": 1.0, **PARAMETERS, **kwargs})


def test_bad_runs_are_named():
    c = chain(10, 25.0)
    with pytest.raises(ValueError, match="force"):
        c.simulate(c.f_max, 1.0, relaxed=2)  # the intact contacts start at their threshold
    with pytest.raises(ValueError, match="relaxed"):
        c.simulate(1.0, 1.0, relaxed=11)
    with pytest.raises(ValueError, match="f=0.5"):
        c.continuum_front_speed(0.5)


def test_sound_speed_is_the_long_wave_limit_of_the_chains_dispersion():
    # the equations of motion (their Jacobian by differences: linear between breaks) have
    # omega_j^2 = (k + K)/m + 4 (g/m) sin^2(j pi / 2n) with free ends; the lowest mode's
    # wavenumber is q_1 = pi / (n a), so (omega_1^2 - omega_0^2) / q_1^2 = c_0^2 up to the
    # relative (pi / 2n)^2 / 3 = 4e-5 at n = 144. A spacing a != 1 so that c_0 carries it
    chain = FKChain(n=144, m=2.0, eta=1.0, g=50.0, k=1.0, K=0.25, u_s=1.0, a=0.5)
    system = _Chain(chain, lambda t: 0.0)
    n, y0 = chain.n, np.zeros(system.size)
    stiffness = np.empty((n, n))
    for j in range(n):
        y = y0.copy()
        y[j] = 1.0
        stiffness[:, j] = -(system.rhs(0.0, y, 0) - system.rhs(0.0, y0, 0))[n:2 * n]
    omega2 = np.sort(np.linalg.eigvalsh(0.5 * (stiffness + stiffness.T)))
    j = np.arange(n)
    assert omega2 == pytest.approx((chain.k + chain.K) / chain.m
                                   + 4 * chain.g / chain.m * np.sin(j * np.pi / (2 * n)) ** 2,
                                   rel=1e-10)
    q1 = np.pi / (n * chain.a)
    assert chain.sound_speed == pytest.approx(np.sqrt(omega2[1] - omega2[0]) / q1, rel=1e-4)
