"""Pointwise interface laws against closed forms, finite differences and the papers."""

import math

from mpi4py import MPI

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh

import fenicsfriction as ff
from fenicsfriction import _compat, laws

EPS = 0.3  # any ε > 0; the closed forms below are written for this value

# (w, φ_ε(w), φ_ε'(w), ψ_ε(w), ψ_ε'(w)) worked by hand from the definitions with ε = 0.3
HAND_VALUES = [
    (0.0, 0.0, 0.0, 0.3, 0.0),
    (0.15, 0.0375, 0.5, math.sqrt(0.1125), 0.15 / math.sqrt(0.1125)),  # |w| < ε: w²/(2ε), w/ε
    (-0.15, 0.0375, -0.5, math.sqrt(0.1125), -0.15 / math.sqrt(0.1125)),
    (0.4, 0.25, 1.0, 0.5, 0.8),  # |w| > ε: |w| - ε/2, sign(w); ψ = sqrt(0.16 + 0.09)
    (-0.4, 0.25, -1.0, 0.5, -0.8),
    (-2.0, 1.85, -1.0, math.sqrt(4.09), -2.0 / math.sqrt(4.09)),
]


@pytest.mark.parametrize(("w", "phi", "dphi", "psi", "dpsi"), HAND_VALUES)
def test_regularisations_match_their_closed_forms(w, phi, dphi, psi, dpsi):
    # every value is a handful of flops from exact: 1e-14 is round-off
    assert laws.abs_c1(w, EPS) == pytest.approx(phi, rel=1e-14, abs=1e-15)
    assert laws.abs_c1_derivative(w, EPS) == pytest.approx(dphi, rel=1e-14, abs=1e-15)
    assert laws.abs_smooth(w, EPS) == pytest.approx(psi, rel=1e-14)
    assert laws.abs_smooth_derivative(w, EPS) == pytest.approx(dpsi, rel=1e-14, abs=1e-15)


def test_regularisations_work_elementwise_on_arrays():
    w = np.array([row[0] for row in HAND_VALUES])
    expected = np.array([row[1:] for row in HAND_VALUES]).T
    got = [laws.abs_c1(w, EPS), laws.abs_c1_derivative(w, EPS), laws.abs_smooth(w, EPS),
           laws.abs_smooth_derivative(w, EPS)]
    np.testing.assert_allclose(got, expected, rtol=1e-14, atol=1e-15)


@pytest.mark.parametrize("name", sorted(laws.REGULARISATIONS))
def test_derivatives_are_central_differences_of_the_regularisations(name):
    f, df, ddf = laws.REGULARISATIONS[name]
    # points on both sides of the kinks |w| = ε, kept 1e-3 away from them
    w = np.concatenate([np.linspace(-3, -0.301, 40), np.linspace(-0.299, 0.299, 41),
                        np.linspace(0.301, 3, 40)])
    h = 1e-6
    fd = (f(w + h, EPS) - f(w - h, EPS)) / (2 * h)
    # truncation: 0 for the piecewise quadratic/linear φ_ε, h²|ψ'''|/6 ≤ h²/ε² ~ 1e-11 for ψ_ε;
    # round-off: u_mach |f| / h ≤ 1e-16 * 3 / 1e-6 = 3e-10
    np.testing.assert_allclose(fd, df(w, EPS), rtol=0, atol=1e-8)
    # the second derivative (scalar slip) likewise from φ'_ε: truncation 0 (c1) or
    # h² |ψ''''| / 6 ≲ h² / ε³ ~ 4e-11 (ψ_ε); round-off u_mach / h = 1e-10
    fd2 = (df(w + h, EPS) - df(w - h, EPS)) / (2 * h)
    np.testing.assert_allclose(fd2, ddf(w, EPS), rtol=0, atol=1e-8)
    assert ddf(0.0, EPS) == pytest.approx(1 / EPS, rel=1e-14)  # both: 1/ε at zero slip


def test_c1_regularisation_is_c1_but_not_c2_at_eps():
    delta = 1e-9
    below, above = EPS * (1 - delta), EPS * (1 + delta)
    # value and slope agree from both sides (jumps would be O(1), continuity gives O(δ))
    assert abs(laws.abs_c1(above, EPS) - laws.abs_c1(below, EPS)) < 3 * delta * EPS
    assert abs(laws.abs_c1_derivative(above, EPS) - laws.abs_c1_derivative(below, EPS)) \
        < 3 * delta
    # the curvature jumps from 1/ε (quadratic part) to 0 (linear part)
    h = 1e-4
    curvature_below = (laws.abs_c1_derivative(EPS, EPS)
                       - laws.abs_c1_derivative(EPS - h, EPS)) / h
    curvature_above = (laws.abs_c1_derivative(EPS + h, EPS)
                       - laws.abs_c1_derivative(EPS, EPS)) / h
    assert curvature_below == pytest.approx(1 / EPS, rel=1e-10)
    assert curvature_above == pytest.approx(0.0, abs=1e-10)


def test_regularisations_tend_to_the_absolute_value():
    w = np.array([-1.0, -0.2, 0.5, 2.0])
    for eps in (1e-2, 1e-4):
        # φ_ε = |w| - ε/2 exactly once ε < |w|; ψ_ε - |w| = ε²/(ψ_ε + |w|) ≤ ε²/(2|w|)
        np.testing.assert_allclose(laws.abs_c1(w, eps), np.abs(w) - eps / 2, rtol=1e-14)
        assert np.all(laws.abs_smooth(w, eps) - np.abs(w) <= eps**2 / (2 * np.abs(w)))
        np.testing.assert_allclose(laws.abs_c1_derivative(w, eps), np.sign(w), rtol=1e-14)


def test_ufl_path_agrees_with_numpy_path():
    """The same builders in a compiled UFL expression give the NumPy values (vector w)."""
    msh = mesh.create_unit_square(MPI.COMM_WORLD, 2, 2)
    w = fem.Constant(msh, np.zeros(2))
    eps = fem.Constant(msh, EPS)
    values = ufl.as_vector([laws.abs_c1(w, eps), laws.abs_c1_derivative(w, eps)[0],
                            laws.abs_smooth(w, eps), laws.abs_smooth_derivative(w, eps)[0]])
    expression = fem.Expression(values, np.array([[0.5, 0.5]]))
    cells = np.arange(min(1, msh.topology.index_map(2).size_local), dtype=np.int32)
    for row in HAND_VALUES:
        w.value[:] = [row[0], 0.0]
        for got in _compat.evaluate_expression(expression, msh, cells):
            np.testing.assert_allclose(got, row[1:], rtol=1e-14, atol=1e-15)


def test_coulomb_law_bounds_friction_by_mu_times_normal_pressure():
    law = laws.InterfaceLaw(c_n=1e10, m_n=2.5, mu=0.6)
    assert law.coulomb and law.m_T == law.m_n and law.l_n == law.m_n
    assert law.c_T == pytest.approx(0.6e10, rel=1e-15)
    d = np.array([0.0, 1e-5, 6e-5, 2e-4])
    np.testing.assert_allclose(laws.friction_bound(d, law.c_T, law.m_T),
                               0.6 * laws.normal_pressure(d, law.c_n, law.m_n), rtol=1e-14)
    np.testing.assert_allclose(laws.normal_pressure(d, law.c_n, law.m_n), 1e10 * d**2.5,
                               rtol=1e-14)


@pytest.mark.parametrize("change", [{"m_T": 2.0}, {"b_n": 1e8},
                                    {"friction_coefficient": laws.PiecewiseLinearFriction()}])
def test_law_is_not_coulomb_when_exponents_damping_or_speed_dependence_differ(change):
    assert not laws.InterfaceLaw(c_n=1e10, m_n=2.5, mu=0.6, **change).coulomb


def test_penetration_is_the_positive_part_of_the_approach():
    u_n = np.array([-1e-3, 0.0, 1e-4, 5e-4])
    np.testing.assert_allclose(laws.penetration(u_n, 2e-4), [0.0, 0.0, 0.0, 3e-4],
                               rtol=1e-12, atol=0)


def test_uniform_penetration_solves_the_compliance_law():
    law = laws.InterfaceLaw(c_n=1e10, m_n=2.5)
    d = law.uniform_penetration(0.3)
    assert laws.normal_pressure(d, law.c_n, law.m_n) == pytest.approx(0.3, rel=1e-14)


def test_normal_traction_is_compliance_plus_damping_with_their_own_exponents():
    """Martins & Oden's eq. 1 at exponents other than 1 (where d**l = d would hide a dropped
    exponent) and l_n defaulting to m_n: values written out by hand."""
    d, rate = 2e-4, 3e-3
    expected = 1e10 * d**2.5 + 4e7 * d**1.5 * rate
    assert laws.normal_traction(d, 1e10, 2.5, rate, 4e7, 1.5) == pytest.approx(expected,
                                                                               rel=1e-14)
    assert laws.normal_traction(d, 1e10, 2.5, rate, 4e7) == pytest.approx(
        1e10 * d**2.5 + 4e7 * d**2.5 * rate, rel=1e-14)
    assert laws.friction_bound(d, 3e9, 2.25) == pytest.approx(3e9 * d**2.25, rel=1e-14)


def test_piecewise_linear_friction_defaults_are_those_of_the_slider_paper_eq_59():
    """μ = 0.75 - 0.03|V_rel| for |V_rel| < 15, 0.3 above (the m.d.o.f. slider paper (2003),
    eq. 59)."""
    mu = laws.PiecewiseLinearFriction()
    speeds = np.array([0.0, 1.0, 5.0, 10.0, 14.999, 15.0, 15.001, 20.0, 1e3])
    expected = [0.75, 0.72, 0.60, 0.45, 0.75 - 0.03 * 14.999, 0.3, 0.3, 0.3, 0.3]
    np.testing.assert_allclose(mu(speeds), expected, rtol=1e-14)


def test_stribeck_friction_falls_from_static_to_kinetic():
    for exponent in (1.0, 2.0):
        mu = laws.StribeckFriction(mu_s=0.6, mu_k=0.4, v_s=0.1, exponent=exponent)
        assert mu(0.0) == pytest.approx(0.6, rel=1e-15)
        assert mu(1e3) == pytest.approx(0.4, rel=1e-15)  # e^{-(1e4)^δ} underflows to 0
        assert mu(0.1) == pytest.approx(0.4 + 0.2 / math.e, rel=1e-14)  # at v = v_s
        assert np.all(np.diff(mu(np.linspace(0, 0.5, 50))) < 0)  # strictly falling


@pytest.mark.parametrize("law", [laws.PiecewiseLinearFriction(),
                                 laws.StribeckFriction(mu_s=0.6, mu_k=0.4, v_s=0.1),
                                 laws.ConstantFriction(0.5)])
def test_friction_coefficient_depends_on_the_speed_only(law):
    """μ(v) = μ(|v|): a signed relative velocity (reduced models) gives the same μ."""
    v = np.linspace(0.0, 30.0, 61)
    np.testing.assert_array_equal(law(-v), law(v))


def test_constant_friction_is_constant():
    np.testing.assert_array_equal(laws.ConstantFriction(0.6)(np.array([0.0, 0.3, 50.0])), 0.6)


# (parameter, bad value): each must be rejected with both named in the message
BAD_LAW = [("c_n", 0.0), ("c_n", -1e10), ("m_n", 0.5), ("eps", 0.0), ("eps", -1e-3),
           ("g", -0.1), ("mu", -0.2), ("regularisation", "tanh"), ("m_T", 0.9), ("b_n", -1.0),
           ("eps", float("nan"))]
BAD_SCENE = [("belt_direction", 0), ("belt_direction", 2), ("refine", 0), ("refine", 1.5),
             ("spring_height", 31.0), ("spring_height", -1.0), ("nu", 0.5), ("nu", -1.0),
             ("belt_speed", 0.0), ("degree", 4), ("contact_quadrature", "simpson")]


def assert_names(error: pytest.ExceptionInfo, name: str, value) -> None:
    assert str(value) in str(error.value), str(error.value)


@pytest.mark.parametrize(("name", "value"), BAD_LAW)
def test_interface_law_rejects_bad_parameter_by_name(name, value):
    with pytest.raises(ValueError, match=f"^{name}=") as error:
        laws.InterfaceLaw(**{"c_n": 1e10, "m_n": 2.5, name: value})
    assert_names(error, name, value)


@pytest.mark.parametrize(("name", "value"), [*BAD_SCENE, ("law", {"mu": 0.3})])
def test_block_scene_rejects_bad_parameter_by_name(name, value):
    with pytest.raises(ValueError, match=f"^{name}=") as error:
        ff.BlockOnBelt(**{name: value})
    assert_names(error, name, value)


@pytest.mark.parametrize(("name", "value"), BAD_LAW)
def test_block_scene_law_rejects_bad_parameter_by_name(name, value):
    """The scene holds the law, which validates its own fields (one place)."""
    with pytest.raises(ValueError, match=f"^{name}=") as error:
        ff.BlockOnBelt().with_law(**{name: value})
    assert_names(error, name, value)


@pytest.mark.parametrize(("law", "name", "value"), [
    (lambda v: laws.PiecewiseLinearFriction(slope=v), "slope", 0.06),  # μ(15) < 0
    (lambda v: laws.StribeckFriction(mu_s=0.6, mu_k=0.4, v_s=v), "v_s", 0.0),
    (lambda v: laws.StribeckFriction(mu_s=0.6, mu_k=v, v_s=0.1), "mu_k", -0.1),
    (lambda v: laws.ConstantFriction(v), "mu", -0.1),
])
def test_friction_coefficients_reject_bad_parameter_by_name(law, name, value):
    with pytest.raises(ValueError, match=f"^{name}=") as error:
        law(value)
    assert_names(error, name, value)


@pytest.mark.parametrize("law", [laws.ConstantFriction(0.4), laws.PiecewiseLinearFriction(),
                                 laws.StribeckFriction(0.6, 0.3, 2.0, 1.5)])
def test_friction_coefficient_derivative_is_its_central_difference(law):
    # away from the kinks (0 and v_c = 15): central differences are O(h²) accurate
    v = np.array([-20.0, -7.3, -0.9, 0.4, 3.1, 14.0, 30.0])
    h = 1e-6
    fd = (law(v + h) - law(v - h)) / (2 * h)
    assert np.allclose(law.derivative(v), fd, rtol=1e-7, atol=1e-9)


def test_power_law_secant_lands_on_the_load_of_an_exact_power_law():
    # F = C δ^k: one secant step through two exact points reaches the target to round-off
    from fenicsfriction.numerics import power_law_secant
    C, k = 3.0, 1.5
    x0, x1 = np.log(1e-3), np.log(2e-3)
    y0, y1 = np.log(C) + k * x0, np.log(C) + k * x1
    target = np.log(7.0)
    x = power_law_secant(x0, y0, x1, y1, target)
    assert C * np.exp(x) ** k == pytest.approx(7.0, rel=1e-12)
    # the safeguard bounds the exponent from below (a force that barely grows)
    flat = power_law_secant(x0, y0, x1, y0 + 1e-3 * (x1 - x0), target, min_slope=0.3)
    assert flat == pytest.approx(x1 + (target - (y0 + 1e-3 * (x1 - x0))) / 0.3)
