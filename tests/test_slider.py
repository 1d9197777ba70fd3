"""The 2m+1 d.o.f. slider of the m.d.o.f. slider paper (2003): natural frequencies, averaging
against Floquet, the nonlinear motion."""

import dataclasses
import json
import math

import numpy as np
import pytest
import scipy.linalg

from fenicsfriction import laws
from fenicsfriction.events import HybridError, integrate_hybrid
from fenicsfriction.petsc_options import EVENTS_LOCATED_TO_RESOLUTION
from fenicsfriction.studies.oscillators.slider import (
    Contact,
    Slider,
    SliderMotion,
    stroboscopic_growth,
    table2_slider,
)

pytestmark = pytest.mark.sequential


def test_table2_natural_frequencies_are_the_roots_of_the_frequency_equation():
    # det(K - Ω² M) = 0 for M = diag(1, 0.01), K = [[11, -10], [-10, 10]]:
    # Ω⁴ - 1011 Ω² + 1000 = 0 (the paper's eq. 60: Ω1 = 0.9950, Ω2 = 31.7807)
    roots = np.sqrt(np.sort(np.roots([1.0, -1011.0, 1000.0])))
    omega, R = table2_slider(30.78).natural_frequencies()
    assert omega == pytest.approx(roots, rel=1e-13)
    assert np.round(omega, 4) == pytest.approx([0.9950, 31.7807], abs=1e-12)
    M, _, _ = table2_slider(30.78).tangential_matrices()
    assert pytest.approx(np.eye(2), abs=1e-13) == R.T @ M @ R


def test_two_identical_contacts_have_the_antisymmetric_mode_sqrt_kt_over_m():
    # contacts moving in opposition leave the slider at rest: Ω = sqrt(k_t/m) exactly
    contact = table2_slider(30.0).contacts[0]
    slider = Slider(1.0, 1.0, 0.015, [contact, contact])
    omega, R = slider.natural_frequencies()
    k = int(np.argmin(np.abs(omega - math.sqrt(contact.k_t / contact.mass))))
    assert omega[k] == pytest.approx(math.sqrt(contact.k_t / contact.mass), rel=1e-12)
    assert abs(R[0, k]) < 1e-12 and R[1, k] == pytest.approx(-R[2, k], rel=1e-12)
    assert slider.matrices()[0].shape == (5, 5)


def test_floquet_multipliers_of_a_smooth_surface_are_exp_of_the_eigenvalues_times_the_period():
    # roughness 0: constant coefficients, so the monodromy matrix is exp(A T); its eigenvalues
    # are exp(λ T) with λ from the quadratic eigenproblem (λ² M + λ C̄ + K) q = 0
    slider = table2_slider(30.78)
    smooth = Slider(1.0, 1.0, 0.015, [dataclasses.replace(slider.contacts[0], roughness=0.0)])
    floquet = smooth.floquet()
    M, C, K = smooth.tangential_matrices()
    C[1, 1] += smooth.contacts[0].slope() * smooth.contacts[0].normal_load
    n = M.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    expected = np.exp(np.linalg.eigvals(A) * floquet.period)
    assert np.sort_complex(floquet.multipliers) == pytest.approx(np.sort_complex(expected),
                                                                  rel=1e-8, abs=1e-10)


def test_averaging_and_floquet_agree_at_the_principal_resonance_and_its_band_edge():
    # ω_o ≈ 2Ω2: first-order averaging is O(ε) accurate (ε ~ ξ/Ω ~ 0.05), so growth rates
    # agree to a few per cent and the band edges to a small fraction of the band width (1.9)
    a, f = (table2_slider(63.5).averaged(), table2_slider(63.5).floquet())
    assert a.case.startswith("II: Ω2+Ω2")
    assert a.growth > 0 and f.growth == pytest.approx(a.growth, rel=0.02)

    def edge(rate, lo, hi):
        while hi - lo > 1e-3:
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if rate(mid) < 0 else (lo, mid)
        return (lo + hi) / 2

    upper_avg = edge(lambda w: -table2_slider(w).averaged().growth, 63.6, 66.0)
    upper_floquet = edge(lambda w: -table2_slider(w).floquet().growth, 63.6, 66.0)
    assert abs(upper_avg - upper_floquet) < 0.05
    assert upper_floquet == pytest.approx(64.45, abs=0.05)     # the paper: 62.70 < ω_o < 64.45


def test_the_linearised_motion_integrated_in_time_grows_at_the_floquet_rate():
    # an independent route to the same number: the full motion (normal d.o.f. integrated, not
    # its closed-form response) with the friction of eq. 25, forcing included, integrated by
    # TS over 30 time units (e^4) against the largest multiplier of the one-period monodromy
    omega = 63.5
    slider = table2_slider(omega)
    motion = SliderMotion(slider, linearised=True)
    period = 2 * math.pi / omega
    result = integrate_hybrid(motion, motion.initial_state([0.01]), motion.slip_mode(), 30.0,
                              rtol=1e-8, atol=1e-10, sample_dt=period)
    assert result.events == []
    _, _, rate = stroboscopic_growth(result.t, result.y, period, t_from=15.0)
    # the other multipliers decay (Ω1's at -0.0074): from t = 15 on the growing one leads by
    # e^2 and more, and its stroboscopic differences dominate (measured agreement 3e-7)
    assert rate == pytest.approx(slider.floquet().growth, rel=1e-4)


def test_forced_response_is_the_periodic_motion_of_the_linear_system():
    # constant μ: no slope, no parametric term, the linearised motion is exactly linear and
    # its transient (heavily damped here) leaves the forced oscillation Im(Ŷ e^{iωt})
    contact = Contact(mass=0.1, k_t=10.0, c_t=1.0, k_n=1.0, c_n=0.2, normal_load=5.0,
                      roughness=0.1, wavelength=1.0, surface_speed=1.0,
                      law=laws.InterfaceLaw(mu=0.4, regularisation="smooth"))
    slider = Slider(1.0, 2.0, 2.0, [contact])
    motion = SliderMotion(slider, linearised=True)
    result = integrate_hybrid(motion, motion.initial_state(), motion.slip_mode(), 40.0,
                              rtol=1e-10, atol=1e-12, sample_dt=0.01)
    late = result.t > 30.0  # the slowest transient decays like e^{-0.91 t}
    Y = slider.forced_response()
    exact = np.imag(np.outer(np.exp(1j * contact.omega * result.t[late]), Y))
    deviation = result.y[late, :2] - slider.steady_sliding()
    assert np.abs(deviation - exact).max() < 1e-6 * np.abs(Y).max()


def test_steady_sliding_balances_the_mean_friction():
    # eq. 59 in the paper's reading: μ(V) = 0.75 − 0.03 V/10 on its slope, V = ω_o λ/2π
    slider = table2_slider(30.78)
    q = slider.steady_sliding()
    speed = 30.78 * 16.67 / (2 * math.pi)
    friction = (0.75 - 0.03 * speed / 10) * 0.05
    assert slider.stiffness * q[0] == pytest.approx(friction, rel=1e-12)   # slider spring
    assert 10.0 * (q[1] - q[0]) == pytest.approx(friction, rel=1e-12)  # k_t of Table 2


@pytest.mark.parametrize(("field", "value"), [("mass", 0.0), ("k_n", -1.0), ("wavelength", 0.0),
                                          ("wavelength", -2.0), ("k_t", -10.0)])
def test_bad_contact_parameters_are_named_in_the_error(field, value):
    contact = table2_slider(30.0).contacts[0]
    with pytest.raises(ValueError, match=f"{field}={value!r} is invalid"):
        dataclasses.replace(contact, **{field: value})


def test_bad_slider_parameters_are_named_in_the_error():
    contact = table2_slider(30.0).contacts[0]
    with pytest.raises(ValueError, match="stiffness=-1.0 is invalid"):
        Slider(1.0, -1.0, 0.0, [contact])
    with pytest.raises(ValueError, match="mass=0 is invalid"):
        Slider(0, 1.0, 0.0, [contact])
    with pytest.raises(ValueError, match="contacts=.* is invalid"):
        Slider(1.0, 1.0, 0.0, [])
    with pytest.raises(ValueError, match="reading='x' is invalid"):
        table2_slider(30.0, reading="x")
    with pytest.raises(ValueError, match="unit=0.0 is invalid"):
        dataclasses.replace(table2_slider(30.0).contacts[0].law.friction_coefficient, unit=0.0)
    assert laws.PiecewiseLinearFriction().derivative(3.0) == pytest.approx(-0.03)


@pytest.mark.parametrize(("omega", "case"), [(1.0, "I: Ω1 ≈ ω1"), (31.78, "I: Ω2 ≈ ω1"),
                                         (15.9, "III: Ω2 ≈ ω1+ω1"), (10.0, "non-resonant")])
def test_cases_I_III_and_non_resonant_are_stable_at_the_modal_damping_rate(omega, case):
    # Table 1: away from Case II the averaged growth is -min ξ_ii/2, here < 0 (ξ_ii > 0);
    # Floquet's exact growth agrees to O(ε) of the damping rate. The weak fluctuation of the
    # slider-mass reading keeps the wide Case II bands of the paper's reading away from Ω2.
    slider = table2_slider(omega, reading="slider-mass")
    averaged = slider.averaged()
    assert averaged.case == case
    # ξ_ii = r_iᵀ C r_i on the mass-normalised modes of Table 2's matrices, C with the
    # friction damping S N_o = −0.003 × 0.05 of eq. 59 (slope 0.03 per 10 speed units)
    M, K = np.diag([1.0, 0.01]), np.array([[11.0, -10.0], [-10.0, 10.0]])
    C = np.array([[0.03, -0.015], [-0.015, 0.015 - 0.003 * 0.05]])
    _, R = scipy.linalg.eigh(K, M)
    xi = np.einsum("ik,ij,jk->k", R, C, R)
    assert averaged.modal_damping == pytest.approx(xi, rel=1e-12)
    assert averaged.growth == pytest.approx(-xi.min() / 2, rel=1e-12)
    assert averaged.growth < 0
    assert slider.floquet().growth == pytest.approx(averaged.growth, rel=1e-3)


def test_stability_results_are_json_records():
    averaged, floquet = table2_slider(63.5).averaged(), table2_slider(63.5).floquet()
    a, f = (json.loads(json.dumps(r.to_json())) for r in (averaged, floquet))
    assert a["growth"] == averaged.growth and a["case"] == averaged.case
    assert f["growth"] == floquet.growth and len(f["multipliers"]) == 4
    # the multipliers' product is det Φ(T) = exp(∫ tr A dt) (Liouville): tr A = −tr M̂⁻¹Ĉ(t),
    # whose mean over a period is that of the mean damping Ĉ + diag(0, S N_o)
    C = table2_slider(63.5).friction_damping([0.05])
    trace = -(C[0, 0] / 1.0 + C[1, 1] / 0.01)
    product = np.prod([complex(re, im) for re, im in f["multipliers"]])
    assert product.real == pytest.approx(math.exp(trace * floquet.period), rel=1e-8)


def _run(slider, t_end, eps=None, sample_dt=1e-3, **kwargs):
    motion = SliderMotion(slider, eps=eps, **kwargs)
    observe = lambda t, y, mode: {"F": motion.friction(t, y, mode)}  # noqa: E731
    result = integrate_hybrid(motion, motion.initial_state([0.01]), motion.slip_mode(), t_end,
                              rtol=1e-9, atol=1e-11, sample_dt=sample_dt, observe=observe)
    return motion, result


def test_stick_slip_switching_keeps_the_momentum_balance_across_the_events():
    # d/dt (m_s ẏ_s + Σ m_i ẏ_i) = −c_s ẏ_s − k_s y_s + Σ F_i (the contact springs are internal;
    # F_i is the stick reaction while sticking). The paper's reading at ω_o = 30.16 sticks and
    # slips at once (its forced response alone exceeds V_ref). Events are recorded before and
    # after each switch, so the trapezoid rule sees the jumps of F; its error h²ω²/12 with
    # F oscillating at ω ≈ 30 and h = 1e-4 is ~1e-6 of the impulse.
    slider = table2_slider(30.16)
    motion, result = _run(slider, 3.0, sample_dt=1e-4)
    assert len(result.events) >= 10 and any(e.mode_after == (0,) for e in result.events)
    t, y = result.t, result.y
    n = motion.size // 2
    momentum = slider.mass * y[:, n] + slider.contacts[0].mass * y[:, n + 1]
    force = -slider.damping * y[:, n] - slider.stiffness * y[:, 0] \
        + np.array([o["F"][0] for o in result.observations])
    impulse = np.sum((force[1:] + force[:-1]) / 2 * np.diff(t))
    scale = np.sum(np.abs(force[1:] + force[:-1]) / 2 * np.diff(t))
    assert abs(momentum[-1] - momentum[0] - impulse) < 2e-6 * scale


def test_regularised_law_agrees_with_true_stick_where_no_contact_sticks():
    # the slider-mass reading slides without sticking: the two laws differ by
    # μN(1 − V/√(V²+ε²)) ≈ μN ε²/2V², V ≈ 80, so the trajectories agree to ~1e-8 at ε = 1e-2
    slider = table2_slider(30.16, reading="slider-mass")
    _, events = _run(slider, 5.0, sample_dt=0.5)
    _, smooth = _run(slider, 5.0, eps=1e-2, sample_dt=0.5)
    assert not events.events
    assert smooth.y[-1] == pytest.approx(events.y[-1], rel=1e-6, abs=1e-8)


def test_bad_motion_options_are_named_in_the_error():
    with pytest.raises(ValueError, match="normal_force='x' is invalid"):
        SliderMotion(table2_slider(30.0), normal_force="x")
    with pytest.raises(ValueError, match="eps=0.0 is invalid"):
        SliderMotion(table2_slider(30.0), eps=0.0)
    with pytest.raises(ValueError, match="linearised=True is invalid"):
        SliderMotion(table2_slider(30.0), eps=1e-2, linearised=True)


class _UnscaledEvents(SliderMotion):
    """Events ×factor: an event tolerance of 1e-12 is then below their time resolution."""

    def __init__(self, slider, factor):
        super().__init__(slider)
        self.factor = factor

    def events(self, t, y, mode):
        return super().events(t, y, mode) * self.factor


def _events_to(motion, t_end):
    return integrate_hybrid(motion, motion.initial_state([0.01]), motion.slip_mode(), t_end,
                            rtol=1e-8, atol=1e-10)


def test_events_below_their_time_resolution_are_located_with_a_relaxed_tolerance():
    # PETSc 3.18 retries an event location until |g| <= tol without limit; the driver resumes
    # a stalled location with a larger tolerance and must find the same events (PETSc 3.22
    # locates to the time resolution by itself and must find them too)
    scaled = _events_to(SliderMotion(table2_slider(30.16)), 10.0)
    steep = _events_to(_UnscaledEvents(table2_slider(30.16), 1e4), 10.0)
    assert scaled.relaxed_locations == 0
    assert (steep.relaxed_locations > 0) != EVENTS_LOCATED_TO_RESOLUTION
    assert [e.mode_after for e in steep.events] == [e.mode_after for e in scaled.events]
    # |g| <= 1e-8 after relaxation, |dg/dt| ~ 1e4 × O(ω V_ref / V_ref): time error << 1e-9
    times = np.array([[a.t, b.t] for a, b in zip(scaled.events, steep.events, strict=True)])
    assert np.abs(times[:, 0] - times[:, 1]).max() < 1e-9


def test_an_event_beyond_the_relaxed_tolerance_never_hangs():
    # ×1e12: even the largest tolerance (1e-6) is below the resolution of PETSc 3.18's
    # location, which then raises; PETSc 3.22's locates to the time resolution and must find
    # the events of the scaled problem
    if EVENTS_LOCATED_TO_RESOLUTION:
        scaled = _events_to(SliderMotion(table2_slider(30.16)), 10.0)
        steep = _events_to(_UnscaledEvents(table2_slider(30.16), 1e12), 10.0)
        assert [e.mode_after for e in steep.events] == [e.mode_after for e in scaled.events]
        times = np.array([[a.t, b.t] for a, b in zip(scaled.events, steep.events, strict=True)])
        assert np.abs(times[:, 0] - times[:, 1]).max() < 1e-9
        return
    with pytest.raises(HybridError, match="event location does not converge") as error:
        _events_to(_UnscaledEvents(table2_slider(30.16), 1e12), 10.0)
    assert 0 < error.value.t < 10 and error.value.result.t[-1] == error.value.t
    assert "now 1e-06" in str(error.value)  # raised once the tolerance reached its cap
