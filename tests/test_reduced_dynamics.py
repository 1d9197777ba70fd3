r"""PETSc TS on the few-d.o.f. models (:class:`fenicsfriction.timestepping.ReducedDynamics`)
against closed forms, an energy quadrature, energy conservation and the rigid block's eigenvalues.

With the default ρ∞ = 1, PETSc's generalized-α (α_m = α_f = γ = 1/2, β = 1/4) advances (x, v)
by the implicit midpoint rule, x_{n+1} = x_n + h (v_n + v_{n+1})/2,
m (v_{n+1} - v_n)/h = f((x_n + x_{n+1})/2, (v_n + v_{n+1})/2) (only A_n + A_{n+1} enters the
updates, so the starting acceleration does not matter). Its error on a harmonic oscillation is
known: the discrete frequency is ω_h = (2/h) arctan(ωh/2), a phase error (ωh)²/12, and a mode
λ = a + iω is integrated as λ + λ³h²/12, i.e. a relative error -(ωh)²/4 in a and -(ωh)²/12
in ω. The tolerances below rest on these.

The models are serial NumPy and the TS lives on ``MPI.COMM_SELF``: under MPI every rank runs
the same integration.
"""

import itertools

from petsc4py import PETSc

import numpy as np
import pytest
import scipy.optimize
from scipy.integrate import trapezoid

from fenicsfriction.laws import InterfaceLaw
from fenicsfriction.studies.block import RigidBlock, rigid_block_observables
from fenicsfriction.studies.oscillators import BouncingMass
from fenicsfriction.timestepping import DynamicsError, ReducedDynamics

_COUNTER = itertools.count()


def prefix(name: str) -> str:
    """A PETSc options prefix used by no other solver of the run."""
    return f"red{next(_COUNTER)}{name}_"


def trajectory(model, q0, q_dot0, t_end, dt, name, **observe):
    """Run TSALPHA2 (default options) and return the records with ``y``, ``v``, ``energy``."""
    dyn = ReducedDynamics(model, q0, q_dot0, prefix=prefix(name))
    return dyn.run(t_end, dt, observe=lambda t: {
        "y": dyn.q[0], "v": dyn.q_dot[0], "energy": float(model.energy(dyn.q, dyn.q_dot)[0])})


def apex_times(records) -> np.ndarray:
    """Times of the maxima of y, each from the parabola through the three samples around it
    (exact in flight: the midpoint rule reproduces constant-acceleration motion exactly)."""
    t = np.array([r["time"] for r in records])
    y = np.array([r["y"] for r in records])
    tops = []
    for j in np.where((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:]))[0] + 1:
        c2, c1, _ = np.polyfit(t[j - 1:j + 2] - t[j], y[j - 1:j + 2], 2)
        tops.append(t[j] - c1 / (2 * c2))
    return np.array(tops)


def mean_period(records) -> float:
    tops = apex_times(records)
    assert len(tops) >= 2, "no full period recorded"
    return (tops[-1] - tops[0]) / (len(tops) - 1)


# --- the bouncing mass: closed forms and quadrature -------------------------------------------

# ω = 1e3, g = 1e3
LINEAR = {"mass": 1.0, "weight": 1000.0, "law": InterfaceLaw(c_n=1e6, m_n=1.0), "area": 1.0}


def linear_period(omega: float, g: float, d0: float, v0: float) -> tuple[float, float]:
    """Period of the mass started at its equilibrium y = -d0 (d0 = g/ω²) with upward speed v0
    on a linear foundation, and the time spent in contact.

    In contact y + d0 = a sin(ωt), a = v0/ω. If a <= d0 the mass never leaves: T = 2π/ω.
    Otherwise it lifts off at y = 0, sin φ = d0/a, with speed v_s = ω sqrt(a² - d0²), flies
    for 2 v_s/g and lands with -v_s; contact is the arc sin φ < d0/a, φ from π - arcsin(d0/a)
    to 2π + arcsin(d0/a): T = (π + 2 arcsin(d0/a))/ω + 2 v_s/g.
    """
    a = v0 / omega
    if a <= d0:
        return 2 * np.pi / omega, 2 * np.pi / omega
    arc = (np.pi + 2 * np.arcsin(d0 / a)) / omega
    return arc + 2 * omega * np.sqrt(a * a - d0 * d0) / g, arc


def test_linear_period_closed_form_agrees_with_an_adaptive_ode_solution():
    """The closed form (derived above) against DOP853 at rtol 1e-12 with its own event location
    (apexes, ẏ = 0 going down), for a long flight (a = 2 d0, flight 45 % of the period) and
    no flight (a = d0/2). The kink of the force at y = 0 costs the adaptive solver accuracy
    locally; measured agreement 6e-13, tolerance 1e-10."""
    bm = BouncingMass(**LINEAR)
    omega, g, d0 = np.sqrt(bm.law.c_n * bm.area / bm.mass), bm.gravity, -bm.equilibrium()
    for ratio in (2.0, 0.5):
        v0 = ratio * d0 * omega
        T = linear_period(omega, g, d0, v0)[0]

        def rhs(t, z):
            return [z[1], -bm.residual(z[:1], z[1:], [0.0])[0] / bm.mass]

        def apex(t, z):
            return z[1]
        apex.direction = -1
        sol = scipy.integrate.solve_ivp(rhs, (0, 3.2 * T), [-d0, v0], method="DOP853",
                                        rtol=1e-12, atol=1e-15 * max(d0, v0), events=apex)
        tops = sol.t_events[0]
        assert len(tops) == 3
        assert np.diff(tops) == pytest.approx([T, T], rel=1e-10)
        assert (sol.y[0].max() > 0) == (ratio > 1)  # flight only when a > d0


@pytest.mark.parametrize("ratio", [1.05, 0.5])
def test_period_on_a_linear_foundation_converges_at_second_order(ratio):
    """Mass on a linear foundation (m_n = 1), started at equilibrium with upward speed
    v0 = ratio·d0·ω: with a flight (ratio 1.05) and without (0.5). Periods (apex to apex, two
    periods) with 100, 200 and 400 steps per period against :func:`linear_period`.

    The error is the midpoint rule's phase error on the contact arcs,
    e ≈ (t_contact/T)(ω/ω_h - 1) ≈ (t_contact/T)(ωh)²/12 (flight is integrated exactly),
    plus, with flight, what the step straddling each lift-off and landing adds: the force
    has a kink there, and the impulse of that step is wrong by up to J h²/8 (J = ω² v_s the
    jump of the force rate), with a coefficient set by where the kink falls in the step,
    erratic as h changes. Through the energy it moves the period by
    δT = 2 v_s² δv/(ω⁴ a² d0), δv ≤ v_s (ωh)²/8: at most 3 % of the smooth error per
    bounce for a = 1.05 d0, but as large as the smooth error for a = 2 d0 (flight 45 % of
    the period), where e/(ωh)² was measured anywhere between -0.03 and 0.08 for 100 to 800
    steps per period and the orders at 100-200-400 steps are 2.95 and 2.29: still O(h²),
    but with no clean ratio. Hence the short flight here (10 % of the period).

    Asserted: orders log2(e(h)/e(h/2)) within 2 ± 0.15 (a ±5 % wobble of e/(ωh)²; measured
    2.03, 2.01 with flight, 2.00, 2.00 without); the finest error (400 steps) within 10 % of
    the predicted phase error (measured: 1.79e-5, 3.6 % below the prediction 1.86e-5, with
    flight; 2.06e-5, equal to the prediction to 2e-5 relative, without).
    """
    bm = BouncingMass(**LINEAR)
    omega, g, d0 = np.sqrt(bm.law.c_n * bm.area / bm.mass), bm.gravity, -bm.equilibrium()
    v0 = ratio * d0 * omega
    T, contact = linear_period(omega, g, d0, v0)
    errors = []
    for n in (100, 200, 400):
        records = trajectory(bm, [-d0], [v0], 2.2 * T, T / n, f"lin{n}")
        assert (max(r["y"] for r in records) > 0) == (ratio > 1)  # flight only when a > d0
        errors.append(mean_period(records) / T - 1)
    errors = np.array(errors)
    orders = np.log2(errors[:-1] / errors[1:])
    h = T / 400
    predicted = contact / T * (omega * h / (2 * np.arctan(omega * h / 2)) - 1)
    assert np.all(np.abs(orders - 2) < 0.15), (errors, orders)
    assert errors[-1] == pytest.approx(predicted, rel=0.1), (errors, predicted)


def quadrature_period(bm: BouncingMass, v0: float) -> tuple[float, float, float]:
    """Period by energy quadrature T = 2 ∫ dy / sqrt(2 (E - V(y))/m) between the turning
    points y1 < y2 (V(y) = c_n A d^{m_n+1}/(m_n+1) + W y), and y1, y2; independent of the
    model's code. y = c + r sin φ removes the inverse square-root end singularities (checked
    once against DOP853 at rtol 1e-13: agreement 2e-13)."""
    d0 = -bm.equilibrium()

    def V(y):
        d = max(-y, 0.0)
        return bm.law.c_n * bm.area * d ** (bm.law.m_n + 1) / (bm.law.m_n + 1) + bm.weight * y

    E = V(-d0) + 0.5 * bm.mass * v0**2
    y1 = scipy.optimize.brentq(lambda y: V(y) - E, -10 * d0, -d0, xtol=1e-16 * d0, rtol=1e-15)
    top = E / bm.weight + d0  # above the flight apex E/W
    y2 = scipy.optimize.brentq(lambda y: V(y) - E, -d0, top, xtol=1e-16 * d0, rtol=1e-15)
    c, r = (y1 + y2) / 2, (y2 - y1) / 2

    def integrand(phi):
        return r * np.cos(phi) / np.sqrt(max(2 * (E - V(c + r * np.sin(phi))) / bm.mass, 1e-300))

    T = 2 * scipy.integrate.quad(integrand, -np.pi / 2, np.pi / 2, epsabs=0, epsrel=1e-12,
                                 limit=200)[0]
    return T, y1, y2


def test_error_control_follows_the_tolerance_and_resolves_lift_off_and_landing():
    """PETSc's error control (``ts_adapt_type basic``) on the mass with a short flight
    (a = 1.05 d0), over 2.2 periods, at ts_atol = 1e-3 d0 and 1e-4 d0 (ts_rtol 0).

    TSALPHA2 estimates the local error as the distance to a first-order prediction, O(h²), so
    the steps scale as tol^{1/2}: ten times tighter costs √10 ≈ 3.16 times the steps
    (measured 3.16; asserted within [2.5, 4]). The period (against the closed form) improves
    with the tolerance (measured 3.6e-7 → 4.7e-8; asserted: both below 1e-6 and a factor
    > 4 apart), and the steps vary along the orbit, small at lift-off and landing where the
    force has its kink, large in flight (measured max/min 65; asserted > 10)."""
    bm = BouncingMass(**LINEAR)
    omega, g, d0 = np.sqrt(bm.law.c_n * bm.area / bm.mass), bm.gravity, -bm.equilibrium()
    v0 = 1.05 * d0 * omega
    T = linear_period(omega, g, d0, v0)[0]
    steps, errors = [], []
    for tol in (1e-3, 1e-4):
        dyn = ReducedDynamics(bm, [-d0], [v0], prefix=prefix("adaptive"), options={
            "ts_adapt_type": "basic", "ts_atol": tol * d0, "ts_rtol": 0.0})
        records = dyn.run(2.2 * T, T / 100, observe=lambda t, dyn=dyn: {"y": dyn.q[0]})
        dts = np.array([r["dt"] for r in records[1:-1]])
        assert dts.max() > 10 * dts.min()
        steps.append(len(records) - 1)
        errors.append(abs(mean_period(records) / T - 1))
    assert 2.5 < steps[1] / steps[0] < 4, steps
    assert max(errors) < 1e-6 and errors[1] < errors[0] / 4, errors


def test_period_on_the_power_law_foundation_matches_the_energy_quadrature():
    """The paper's exponent m_n = 2.5 (the block's data: M = 0.45, W = 450, c_n = 1e10,
    A = L B0), started at equilibrium with 0.9 of the speed that would just lift it off, so
    the oscillation is strongly nonlinear (the period, 1.0996 ms, exceeds the linearised
    2π/ω₀, ω₀² = m_n W/(d0 M), by 11 %) and stays in contact (asserted: y < 0 throughout).

    The midpoint rule's error is O(h²) with the local (ω(y) h)²/12 of the stiffness
    K(y) = m_n c_n A d^{m_n-1}, largest at the bottom: the relative error must be below
    (ω_max h)²/12 and fall fourfold from 200 to 400 steps per period (order within 2 ± 0.2).
    Measured: errors 7.0e-5, 1.75e-5 against the bound 2.0e-4, 5.1e-5 at 200 and 400 steps,
    order 2.00.
    """
    bm = BouncingMass()
    d0 = -bm.equilibrium()
    v_lift = np.sqrt(2 * bm.law.m_n / (bm.law.m_n + 1) * bm.weight * d0 / bm.mass)  # V(0) - V(-d0)
    T, y1, y2 = quadrature_period(bm, 0.9 * v_lift)
    assert y2 < 0
    omega0 = np.sqrt(bm.law.m_n * bm.weight / (d0 * bm.mass))
    assert abs(T * omega0 / (2 * np.pi) - 1) > 0.05  # far from the linearised period
    omega_max = np.sqrt(bm.law.m_n * bm.law.c_n * bm.area * (-y1) ** (bm.law.m_n - 1) / bm.mass)
    errors, bounds = [], []
    for n in (200, 400):
        records = trajectory(bm, [-d0], [0.9 * v_lift], 2.2 * T, T / n, f"pow{n}")
        assert max(r["y"] for r in records) < 0
        errors.append(abs(mean_period(records) / T - 1))
        bounds.append((omega_max * T / n) ** 2 / 12)
    assert np.all(np.array(errors) < bounds), (errors, bounds)
    assert abs(np.log2(errors[0] / errors[1]) - 2) < 0.2, errors


def test_energy_is_conserved_to_second_order_and_exactly_for_a_linear_foundation():
    """Without damping the discrete energy (kinetic + foundation + gravity, relative to the
    largest kinetic energy) drifts by O(h²) on the power-law foundation with a flight
    (m_n = 2.5, 1.5 times the lift-off speed): orders within 2 ± 0.2 for 100, 200, 400 steps
    per linearised period over 3 periods (measured 3.7e-4, 9.2e-5, 2.3e-5: orders 2.00,
    2.00), the finest below 1e-4.

    On a linear foundation without flight the midpoint rule conserves the (quadratic) energy
    exactly: round-off only (200 steps, terms up to 8 times the kinetic energy: ~1e-13),
    tolerance 1e-11 against O((ωh)²) = 1e-2 for a scheme that does not (measured 1.2e-13).
    """
    bm = BouncingMass()
    d0 = -bm.equilibrium()
    v0 = 1.5 * np.sqrt(2 * bm.law.m_n / (bm.law.m_n + 1) * bm.weight * d0 / bm.mass)
    T0 = 2 * np.pi / np.sqrt(bm.law.m_n * bm.weight / (d0 * bm.mass))
    errors = []
    for n in (100, 200, 400):
        records = trajectory(bm, [-d0], [v0], 3 * T0, T0 / n, f"energy{n}")
        assert max(r["y"] for r in records) > 0  # it flies
        energy = np.array([r["energy"] for r in records])
        errors.append(np.abs(energy - energy[0]).max() / (0.5 * bm.mass * v0**2))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 2) < 0.2), (errors, orders)
    assert errors[-1] < 1e-4

    linear = BouncingMass(**LINEAR)
    d0 = -linear.equilibrium()
    v0 = 0.5 * d0 * np.sqrt(linear.law.c_n * linear.area / linear.mass)
    records = trajectory(linear, [-d0], [v0], 0.02, 1e-4, "energy_linear")
    energy = np.array([r["energy"] for r in records])
    assert np.abs(energy - energy[0]).max() < 1e-11 * 0.5 * linear.mass * v0**2


@pytest.mark.parametrize(("y", "y_dot", "m_n", "b_n"), [
    (-1e-4, 0.3, 2.5, 0.0), (-2e-4, -0.7, 2.5, 1e9), (-1e-3, 0.5, 1.0, 1e5), (2e-4, 0.3, 2.5, 1e9)])
def test_bouncing_mass_linearisation_is_the_derivative_of_its_residual(y, y_dot, m_n, b_n):
    """(M, C, K) against central differences of R, in contact with and without damping and
    in flight (all zero but M). Steps 1e-6 of |y| and of |ẏ|: truncation ≈ (1e-6)²,
    round-off u_mach W/(h K) ≲ 1e-9; tolerance 1e-7 (measured ≤ 8e-11 for K, 1e-9 for C)."""
    bm = BouncingMass(law=InterfaceLaw(m_n=m_n, b_n=b_n, c_n=1e10 if m_n > 1 else 1e6))
    hy, hv = 1e-6 * abs(y), 1e-6 * abs(y_dot)
    M, C, K = bm.linearisation([y], [y_dot])
    R = lambda y, y_dot: bm.residual([y], [y_dot], [0.0])[0]  # noqa: E731
    K_fd = (R(y + hy, y_dot) - R(y - hy, y_dot)) / (2 * hy)
    C_fd = (R(y, y_dot + hv) - R(y, y_dot - hv)) / (2 * hv)
    scale = max(abs(K[0, 0]), 1.0)
    assert abs(K_fd - K[0, 0]) <= 1e-7 * scale
    assert abs(C_fd - C[0, 0]) <= 1e-7 * max(abs(C[0, 0]), 1.0)
    assert M[0, 0] == bm.mass
    if y > 0:
        assert K[0, 0] == C[0, 0] == 0.0
    else:
        assert K[0, 0] > 0 and (C[0, 0] > 0) == (b_n > 0)


# --- the rigid block: growth and decay of a small perturbation against its eigenvalues --------

def rigid_block(mu: float) -> RigidBlock:
    """The rigid-model data of Martins & Oden 1986, Figs. 10-12 (B0 = 14, I = 70, K_x = 2388,
    belt 0.127 cm/s)
    with viscous damping c_i = 2 ζ_i sqrt(k_i m_i), ζ = (0.005, 0.04, 0.04): k_i the diagonal
    of K̄ at the frictionless steady state, where K̄ and the mass matrix are diagonal, so the
    ζ_i are exactly the modal damping ratios at μ = 0; the c_i are then kept for every μ."""
    data = {"B0": 14.0, "inertia": 70.0, "K_x": 2388.0, "belt_speed": 0.127}
    frictionless = RigidBlock(**data)
    M, _, K = frictionless.linearisation(frictionless.steady_state())
    viscous = tuple(2 * zeta * np.sqrt(k * m)
                    for zeta, k, m in zip((0.005, 0.04, 0.04), np.diag(K), np.diag(M),
                                              strict=True))
    return RigidBlock(viscous=viscous, **data, law=InterfaceLaw(mu=mu))


def test_modal_damping_gives_the_asked_damping_ratios_at_mu_0():
    """``RigidBlock.with_modal_damping``: at μ = 0 the eigenvalues λ = -ζω ± iω√(1-ζ²) of the
    damped block give back ζ = -Re λ/|λ| for each of the three modes (the tangential pair with
    the spring, the normal and the rotation pairs; sorted by frequency); the coefficients are
    those of the helper above at any μ. Exact up to the eigensolver: tolerance 1e-9."""
    data = {"B0": 14.0, "inertia": 70.0, "K_x": 2388.0, "belt_speed": 0.127}
    ratios = (0.005, 0.04, 0.04)
    block = RigidBlock.with_modal_damping(ratios, **data)
    lam = block.eigenvalues(block.steady_state())
    lam = lam[lam.imag > 0]
    assert len(lam) == 3
    measured = -lam.real / abs(lam)
    # frequencies: tangential (spring) < normal/rotation; the x ratio is the smallest one
    assert measured[np.argmin(abs(lam))] == pytest.approx(ratios[0], rel=1e-9)
    assert sorted(measured) == pytest.approx(sorted(ratios), rel=1e-9)
    damped = RigidBlock.with_modal_damping(ratios, law=InterfaceLaw(mu=1.0), **data)
    assert damped.viscous == pytest.approx(
        rigid_block(1.0).viscous, rel=1e-12)
    with pytest.raises(ValueError, match="viscous"):
        RigidBlock(viscous=(1.0, float("nan"), 1.0))


def two_modes(t, a1, w1, c1, s1, a2, w2, c2, s2, c0):
    return (np.exp(a1 * t) * (c1 * np.cos(w1 * t) + s1 * np.sin(w1 * t))
            + np.exp(a2 * t) * (c2 * np.cos(w2 * t) + s2 * np.sin(w2 * t)) + c0)


@pytest.mark.parametrize(("mu", "v_y", "t_end"), [(1.0, -1e-5, 5e-3), (0.15, -1e-4, 2e-2)])
def test_small_perturbation_grows_or_decays_with_the_rigid_eigenvalues(mu, v_y, t_end):
    """From the steady state with a u̇_yG perturbation (Newmark step 1e-5 s as in the paper),
    the normal force N(t) carries the normal and rotation pairs only (with the spring through
    G, neither the u_xG equation nor the slip direction, |w| ≈ U ≫ ε, feeds back), so fitting
    two modes e^{a t}(c cos ωt + s sin ωt) plus a constant to N must give the two pairs
    λ = a + iω of the linearisation.

    μ = 1 (the figures' value): one pair is unstable (a > 0, asserted); a perturbation of
    1e-5 cm/s, 1000 times below the paper's, keeps N within 7e-4 W over 5 ms (linear regime;
    asserted < 1e-2 W). μ = 0.15: all pairs decay (asserted); 1e-4 cm/s over 20 ms, N within
    5e-4 W (the pairs are 8.5 % apart in frequency: the window spans 1.5 beats). The time
    error of the scheme is -(ωh)²/4 ≈ 8e-4 in a and -(ωh)²/12 ≈ 3e-4 in ω (ωh ≤ 0.06).
    Measured relative errors: μ = 1, a 1.1e-4, ω 1.4e-4 (unstable pair); μ = 0.15,
    a 7.8e-4 and 1.0e-3, ω 2.5e-4 and 2.9e-4 (predicted 7.6e-4, 9.0e-4, 2.5e-4, 3.0e-4).
    Tolerances (as asked): 5 % in a, 1 % in ω.
    """
    rb = rigid_block(mu)
    q = rb.steady_state()
    lam = rb.eigenvalues(q)
    lam = lam[(lam.imag > 0) & (abs(lam) > 1e3)]  # the normal and rotation pairs
    lam = lam[np.argsort(-lam.real)]
    assert len(lam) == 2
    assert (lam[0].real > 0) == (mu == 1.0) and lam[1].real < 0

    dyn = ReducedDynamics(rb, q, [0.0, v_y, 0.0], prefix=prefix(f"rigid{mu}"))
    records = dyn.run(t_end, 1e-5, observe=lambda t: rigid_block_observables(rb, dyn.q,
                                                                             dyn.q_dot))
    assert {r["contact"] for r in records} == {"slip"}
    t = np.array([r["time"] for r in records])
    n = np.array([r["normal_force"] for r in records])
    assert n[0] == pytest.approx(rb.weight, rel=1e-10)  # steady state: N = W
    assert np.abs(n - n[0]).max() < 1e-2 * rb.weight  # linear regime
    scale = np.abs(n - n[0]).max()
    guess = [0.9 * lam[0].real, 1.01 * lam[0].imag, scale, scale,
             1.1 * lam[1].real, 0.99 * lam[1].imag, scale, scale, 0.0]
    fit, _ = scipy.optimize.curve_fit(two_modes, t, n - n[0], p0=guess, maxfev=20000)
    a, w = fit[[0, 4]], fit[[1, 5]]
    assert a == pytest.approx(lam.real, rel=0.05), (a, lam)
    assert w == pytest.approx(lam.imag, rel=0.01), (w, lam)


def test_rigid_block_observables_balance_at_the_steady_state():
    """At the steady state: N = W, friction μ N along the belt's motion (+x), balanced by the
    spring, slip velocity -U, 'slip'; lifted clear of the belt: no force, 'open'; moving
    with the belt: 'stick'. Newton stops at 1e-12 W: tolerance 1e-10."""
    rb = rigid_block(0.5)
    q = rb.steady_state()
    obs = rigid_block_observables(rb, q, np.zeros(3))
    assert obs["normal_force"] == pytest.approx(rb.weight, rel=1e-10)
    assert obs["friction_force"] == pytest.approx(0.5 * rb.weight, rel=1e-10)
    assert obs["spring_force"] == pytest.approx(-obs["friction_force"], rel=1e-10)
    assert obs["slip_velocity"] == -rb.belt_speed and obs["contact"] == "slip"
    lifted = rigid_block_observables(rb, np.array([0.0, 1.0, 0.0]), np.zeros(3))
    assert lifted["contact"] == "open" and lifted["normal_force"] == 0.0
    riding = rigid_block_observables(rb, q, np.array([rb.belt_speed, 0.0, 0.0]))
    assert riding["contact"] == "stick" and riding["slip_velocity"] == 0.0


def test_rigid_block_probe_tractions_integrate_to_the_resultants():
    """The base-point tractions (``probe_*``) integrated over the base by the trapezoidal rule
    on 4001 points (error ~ (L/4000)² of the pressure's curvature, < 1e-6 here) give the
    resultants computed by the block's own quadrature, at the steady state and at a tilted,
    partly lifted state; friction is μ × pressure while slipping (|w| = U ≫ ε)."""
    rb = rigid_block(0.5)
    q_steady = rb.steady_state()
    q_tilted = q_steady + np.array([0.0, 0.4 * (q_steady[1] + rb.law.g), 8e-6])  # lifts the rear
    for q in (q_steady, q_tilted):
        x = np.linspace(0.0, rb.L, 4001)
        probes = [rigid_block_observables(rb, q, np.zeros(3), probe_x=xi) for xi in x]
        pressure = np.array([o["probe_pressure"] for o in probes])
        friction = np.array([o["probe_friction"] for o in probes])
        whole = probes[0]
        assert rb.B0 * trapezoid(pressure, x) == pytest.approx(whole["normal_force_elastic"],
                                                              rel=1e-6)
        assert rb.B0 * trapezoid(friction, x) == pytest.approx(whole["friction_force"], rel=1e-6)
        assert friction == pytest.approx(0.5 * pressure, rel=1e-12, abs=0)
        assert whole["probe_v_x"] - whole["probe_slip"] == rb.belt_speed
    assert (pressure == 0).any() and (pressure > 0).any()  # the tilted state is partly open
    # at rest there is no damping part; normal_force is Q_y + W with Q_y = ∫p - W, so the two
    # differ by the round-off of adding and removing W (the BLAS's summation order shows there)
    assert whole["normal_force"] == pytest.approx(whole["normal_force_elastic"], rel=1e-14)


def test_a_petsc_error_inside_the_time_step_is_reported_with_the_last_state_kept():
    """An error raised by PETSc inside TSSolve (as TSALPHA2's error norm does when it meets a
    NaN) stops the run with a DynamicsError naming the time and the error code; the records
    of the accepted steps and their last state are kept."""

    class Failing(BouncingMass):
        calls = 0

        def residual(self, q, q_dot, q_ddot):
            Failing.calls += 1
            if Failing.calls == 40:
                raise PETSc.Error(72)  # PETSC_ERR_FP
            return super().residual(q, q_dot, q_ddot)

    mass = Failing()
    dyn = ReducedDynamics(mass, [mass.equilibrium()], [0.1], prefix=prefix("failing"))
    with pytest.raises(DynamicsError, match=r"TS failed at t = .* PETSc error 72") as err:
        dyn.run(1e-2, 1e-4, observe=lambda t: {"y": float(dyn.q[0]), "v": float(dyn.q_dot[0])})
    records = err.value.records
    assert 1 < len(records) < 100 and records[-1]["time"] < 1e-2
    assert (dyn.q[0], dyn.q_dot[0]) == (records[-1]["y"], records[-1]["v"])


# --- bad input --------------------------------------------------------------------------------

def test_bad_input_raises_value_errors_naming_the_parameter():
    for bad, name in (({"mass": 0.0}, "mass"), ({"mass": -1.0}, "mass"),
                      ({"weight": 0.0}, "weight"), ({"area": -1.0}, "area"),
                      ({"law": {"c_n": 1e6}}, "law")):
        with pytest.raises(ValueError, match=rf"^{name}=.* is invalid"):
            BouncingMass(**bad)
    for bad, name in (({"c_n": 0.0}, "c_n"), ({"c_n": -1e10}, "c_n"), ({"m_n": 0.5}, "m_n"),
                      ({"b_n": -1.0}, "b_n")):  # the law validates its own fields
        with pytest.raises(ValueError, match=rf"^{name}=.* is invalid"):
            BouncingMass(law=InterfaceLaw(**bad))
    bm = BouncingMass()
    with pytest.raises(ValueError, match=r"^q_dot0=.* is invalid"):
        ReducedDynamics(bm, [0.0], [0.0, 1.0], prefix=prefix("bad"))
    with pytest.raises(ValueError, match=r"^atol=-1 is invalid"):
        ReducedDynamics(bm, [0.0], [0.0], prefix=prefix("bad"), atol=-1)
    dyn = ReducedDynamics(bm, [bm.equilibrium()], [0.0], prefix=prefix("bad"))
    with pytest.raises(ValueError, match=r"^dt=-1e-05 is invalid"):
        dyn.run(1e-3, -1e-5)
