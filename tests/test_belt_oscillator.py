"""The one-d.o.f. oscillator on a belt (fenicsfriction.studies.oscillators.belt): linear
stability of steady sliding, the classic stick-slip cycle in closed form, momentum balance
across events."""

import json

import numpy as np
import pytest
from scipy.integrate import trapezoid

from fenicsfriction import laws
from fenicsfriction.statistics import BeltSummary, belt_summary, displacement_extrema, limit_cycle
from fenicsfriction.studies.oscillators.belt import BeltOscillator

pytestmark = pytest.mark.sequential


def classic(**kwargs) -> BeltOscillator:
    """c = 0, μ_k = 0.3 < μ_s = 0.5, ω = 1, v_b = 1: T = 6.288, 6 % of it stuck."""
    parameters = {"m": 1.0, "k": 1.0, "c": 0.0, "N": 1.0, "v_belt": 1.0,
                  "law": laws.InterfaceLaw(mu=0.3, regularisation="smooth"), "mu_static": 0.5}
    return BeltOscillator(**{**parameters, **kwargs})


# PiecewiseLinearFriction keeps slip exactly linear (μ' = -slope for |v| < v_c); Stribeck is
# linear only to first order, hence the small perturbation
LAWS = {"piecewise linear": (laws.PiecewiseLinearFriction(mu_s=0.75, slope=0.03, v_c=15.0), 5.0),
        "Stribeck": (laws.StribeckFriction(mu_s=0.5, mu_k=0.3, v_s=1.0), 1.0)}


@pytest.mark.parametrize("side", [-0.05, 0.05])
@pytest.mark.parametrize("law", sorted(LAWS))
def test_perturbations_of_steady_sliding_grow_or_decay_at_the_linear_rate(law, side):
    friction, v_belt = LAWS[law]
    N = 10.0
    c_boundary = -N * float(friction.derivative(v_belt))  # c + N μ'(v_b) = 0
    oscillator = BeltOscillator(m=1.0, k=1.0, c=(1 + side) * c_boundary, N=N, v_belt=v_belt,
                                law=friction)
    rate = oscillator.linear_eigenvalues().real
    expected = -side * c_boundary / 2  # Re s = -(c + N μ')/(2m)
    assert rate == pytest.approx([expected, expected], rel=1e-12)
    assert oscillator.is_steady_sliding_stable() == (side > 0)

    x0 = oscillator.steady_sliding()
    result = oscillator.simulate(100.0, x0=x0, v0=1e-3 * v_belt, rtol=1e-10, atol=1e-13)
    assert not result.events  # the slip never ends
    # successive maxima of x0 + A e^{σt} cos(ω_d t + φ) are a period 2π/ω_d apart and scale by
    # e^{σ 2π/ω_d}: log(max - x0) is linear in t with slope Re s
    times, values, kinds = displacement_extrema(result)
    slope = np.polyfit(times[kinds > 0], np.log(values[kinds > 0] - x0), 1)[0]
    assert np.sign(slope) == np.sign(expected)
    # the Stribeck law's curvature at an amplitude |ẋ| ~ 2e-3 v_b shifts the rate by O(1e-3)
    # (7e-4 measured); the piecewise linear law is matched to the integration error (1e-8)
    assert slope == pytest.approx(expected, rel=5e-3 if law == "Stribeck" else 1e-5)


def test_classic_stick_slip_cycle_matches_the_closed_form_and_converges_with_rtol():
    oscillator = classic()
    exact = oscillator.classic_limit_cycle()
    errors = []
    for rtol in (1e-6, 1e-8, 1e-10):
        # from stick at x = 0: the first slip starts at (x_s, v_b), on the cycle
        result = oscillator.simulate(15.0, x0=0.0, v0=1.0, rtol=rtol, atol=1e-2 * rtol)
        cycle = limit_cycle(result)
        errors.append(max(abs(cycle.period / exact.period - 1),
                          abs(cycle.amplitude / exact.amplitude - 1),
                          abs(cycle.stick_fraction - exact.stick_fraction)))
        assert [(e.mode_before, e.mode_after) for e in result.events[:3]] == \
            [("stick", "slip+"), ("slip+", "stick"), ("stick", "slip+")]
    assert errors[1] < 1e-6  # the default tolerances
    assert errors[0] > errors[1] > errors[2]


def test_regularised_law_approaches_the_stick_slip_cycle_as_eps_vanishes():
    oscillator = classic()
    exact = oscillator.classic_limit_cycle()
    period_errors, amplitude_errors = [], []
    for eps in (1e-3, 1e-4, 1e-5):
        result = oscillator.simulate(20.0, x0=0.0, v0=1.0, method="regularised", eps=eps)
        assert not result.stick_intervals
        cycle = limit_cycle(result)
        period_errors.append(abs(cycle.period / exact.period - 1))
        amplitude_errors.append(abs(cycle.amplitude / exact.amplitude - 1))
    # the breakaway force misses μ_s N by O((ε/v_b)^(1/3)) (regularised_force): at least a
    # factor 0.7 per decade, and within 1 % at ε = 1e-5 v_b
    for errors in (period_errors, amplitude_errors):
        assert errors[1] < 0.7 * errors[0] and errors[2] < 0.7 * errors[1]
        assert errors[2] < 1e-2


def test_momentum_balance_holds_across_stick_slip_events():
    friction = laws.StribeckFriction(mu_s=0.5, mu_k=0.3, v_s=0.5)
    oscillator = BeltOscillator(m=2.0, k=1.0, c=0.05, N=1.0, v_belt=0.2, law=friction)
    h = 2e-3
    result = oscillator.simulate(40.0, x0=0.0, v0=0.0, sample_dt=h)
    sticks = result.stick_intervals
    assert len(sticks) >= 3
    # from the middle of a stick to the middle of the slip after the next one: the window holds
    # stick->slip, slip->stick and stick->slip
    t1 = sum(sticks[0]) / 2
    t2 = (sticks[1][1] + sticks[2][0]) / 2
    window = (result.t >= t1) & (result.t <= t2)
    kinds = [(e.mode_before, e.mode_after) for e in result.events if t1 < e.t < t2]
    assert ("stick", "slip+") in kinds and ("slip+", "stick") in kinds
    t, x, v, force = (a[window] for a in (result.t, result.x, result.v, result.friction_force))
    net = force - oscillator.c * v - oscillator.k * x
    impulse = trapezoid(net, t)  # events are recorded on both sides: no interval straddles one
    change = oscillator.m * (v[-1] - v[0])
    assert abs(change) > 1e-2
    # trapezoid error on each smooth piece: (h²/12)|f'(b) - f'(a)| (Euler-Maclaurin), f' read
    # from the samples; plus the RK error (rtol 1e-8) in the end velocities
    pieces = np.flatnonzero(np.diff(t) == 0).size + 1
    slope = np.abs(np.diff(net) / np.where(np.diff(t) > 0, np.diff(t), np.inf)).max()
    bound = h**2 / 12 * 2 * slope * pieces + 1e-7 * oscillator.m * oscillator.v_belt
    assert abs(impulse - change) < bound


def test_belt_summary_is_json_and_counts_the_events():
    result = classic().simulate(15.0, x0=0.0, v0=1.0)
    record = belt_summary(result)
    assert isinstance(record, BeltSummary)
    summary = json.loads(json.dumps(record.to_json()))
    exact = classic().classic_limit_cycle()
    assert summary["events"] == len(result.events) > 0
    assert summary["period"] == pytest.approx(exact.period, rel=1e-6)
    assert summary["stick_fraction"] == pytest.approx(exact.stick_fraction, rel=1e-5)
    assert summary["method"] == "events"


def test_steady_sliding_is_the_spring_balancing_kinetic_friction():
    oscillator = classic(c=0.2)
    x0 = oscillator.steady_sliding()
    assert oscillator.k * x0 == pytest.approx(0.3 * oscillator.N)
    result = oscillator.simulate(5.0)
    assert np.abs(result.x - x0).max() < 1e-12 and np.abs(result.v).max() < 1e-12


@pytest.mark.parametrize(("name", "value"), [("m", 0.0), ("k", -1.0), ("v_belt", 0.0),
                                         ("v_belt", -2.0), ("N", 0.0), ("c", -0.1)])
def test_bad_parameters_raise_naming_the_parameter(name, value):
    with pytest.raises(ValueError, match=f"^{name}={value!r} is invalid"):
        classic(**{name: value})


def test_static_coefficient_below_the_kinetic_one_is_rejected():
    with pytest.raises(ValueError, match="mu_static=0.2 is invalid"):
        classic(mu_static=0.2)


def test_steady_sliding_and_its_linearisation_at_parameters_other_than_one():
    """x₀ = μ(v_b) N / k and m s² + (c + N μ'(v_b)) s + k = 0, written out by hand for the
    Stribeck law at m, k, c, N, v_b all different (m = k = 1 would hide m and k swapped)."""
    m, k, c, N, v_b = 2.5, 40.0, 0.7, 8.0, 0.6
    oscillator = BeltOscillator(m=m, k=k, c=c, N=N, v_belt=v_b,
                                law=laws.StribeckFriction(mu_s=0.5, mu_k=0.3, v_s=1.0))
    mu, slope = 0.3 + 0.2 * np.exp(-v_b), -0.2 * np.exp(-v_b)
    assert oscillator.steady_sliding() == pytest.approx(mu * N / k, rel=1e-14)
    damping = c + N * slope
    root = np.sqrt(complex(damping**2 - 4 * m * k))
    expected = np.sort_complex(np.array([(-damping - root) / (2 * m),
                                         (-damping + root) / (2 * m)]))
    np.testing.assert_allclose(np.sort_complex(oscillator.linear_eigenvalues()), expected,
                               rtol=1e-12)
