"""`stick_slip_statistics` on synthetic records whose statistics are known in closed form."""

import numpy as np
import pytest

from fenicsfriction.statistics import stick_slip_statistics

pytestmark = pytest.mark.sequential


def records(n: int = 4001) -> list[dict]:
    """t ∈ [0, 1]: N = 2 + sin(10πt) (mean 2 over whole periods), F = 0.5 N - 0.1 while
    slipping, F = 0 while sticking (t ∈ [0.6, 0.7]: slip velocity 0 there, 1 elsewhere), the
    probe out of contact on t ∈ [0.8, 0.85], spring elongation 3 - t."""
    out = []
    for t in np.linspace(0.0, 1.0, n):
        stick = 0.6 <= t <= 0.7
        N = 2.0 + np.sin(10 * np.pi * t)
        out.append({"time": t, "normal_force": N, "friction_force": 0.0 if stick else 0.5 * N - 0.1,
                    "spring_elongation": 3.0 - t, "probe_slip": 0.0 if stick else 1.0,
                    "probe_pressure": 0.0 if 0.8 <= t <= 0.85 else N, "n_stick": int(stick),
                    "rejected_steps": 0, "newton_iterations": 2})
    return out


def test_statistics_of_a_synthetic_run_match_their_closed_forms():
    """Window [0.5, 1] (2.5 periods of N: ∫N = 1 + (cos 5π - cos 10π)/(10π) = 1 - 2/(10π);
    ∫F = 0.5 ∫N over the slip part − 0.1 × 0.4, ∫N over the stick part = 0.2 + (cos 6π −
    cos 7π)/(10π) = 0.2 + 2/(10π)). Trapezoidal sampling at 2.5e-4: the indicator jumps cost
    ≤ 1 sample (2.5e-4 / 0.5 = 5e-4 of a fraction); the smooth integrals are exact to 1e-7."""
    stats = stick_slip_statistics(records(), mu=0.5, eps=0.01, t_from=0.5)
    int_n = 1.0 + (np.cos(5 * np.pi) - np.cos(10 * np.pi)) / (10 * np.pi)
    int_n_stick = 0.2 + (np.cos(6 * np.pi) - np.cos(7 * np.pi)) / (10 * np.pi)
    int_f = 0.5 * (int_n - int_n_stick) - 0.1 * 0.4
    assert stats.mean_normal_force == pytest.approx(int_n / 0.5, rel=1e-3)
    assert stats.apparent_coefficient == pytest.approx(int_f / int_n, rel=2e-3)
    assert stats.ratio_to_mu == pytest.approx(int_f / int_n / 0.5, rel=2e-3)
    assert stats.probe_stick_fraction == pytest.approx(0.2, abs=1e-3)
    assert stats.any_stick_fraction == pytest.approx(0.2, abs=1e-3)
    assert stats.probe_open_fraction == pytest.approx(0.1, abs=1e-3)
    assert stats.probe_longest_stick == pytest.approx(0.1, abs=5e-4)
    assert stats.spring_elongation["start"] == pytest.approx(2.5, abs=1e-3)
    assert stats.spring_elongation["end"] == 2.0
    assert stats.spring_elongation["mean"] == pytest.approx(2.25, rel=1e-9)
    assert stats.normal_force_range == pytest.approx([1.0, 3.0], abs=1e-6)
    assert stats.max_energy_error is None  # no energy_error in the records
    assert stats.steps == 4000 and stats.newton_iterations == 8002


def test_statistics_refuse_a_window_past_the_end():
    with pytest.raises(ValueError, match="t_from"):
        stick_slip_statistics(records(11), mu=0.5, eps=0.01, t_from=1.0)
