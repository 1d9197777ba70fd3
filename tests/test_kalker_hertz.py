"""Kalker's creepage coefficients (Kalker 1990, Table E.3) and the Hertz ellipse (Johnson 1985,
§4.2): the theory's own limits and identities, and Boussinesq's integral of the pressure."""

import math
import re

import numpy as np
import pytest
import scipy.special

from fenicsfriction.elasticity import effective_modulus
from fenicsfriction.studies.rolling.hertz import (
    HertzEllipse,
    hertz_from_curvatures,
    hertz_from_radii,
    quasi_identical_modulus,
)
from fenicsfriction.studies.rolling.kalker import NU, RATIO, TABLE, creep_coefficients

pytestmark = pytest.mark.sequential

# ---------------------------------------------------------------- Kalker's coefficients


def _coefficients(ratio, nu):
    c = creep_coefficients(ratio, 1.0, nu)
    return np.array([c.C11, c.C22, c.C23, c.C33])


#: Kalker 1990, Table E.3, typed here apart from the module: rows a/b (g = min(a/b, b/a)) of
#: (C11, C22, C23, C33) at nu = 0, 0.25, 0.5. C11-C23 as in CONTACT's linrol; the rows at
#: g = 0.1-0.3 are those the smoothness test below cannot judge, g = 0.5 the typo's row.
LITERAL = {
    0.1: ((2.51, 3.31, 4.85), (2.51, 2.52, 2.53), (0.334, 0.473, 0.731), (6.42, 8.28, 11.7)),
    0.2: ((2.59, 3.37, 4.81), (2.59, 2.63, 2.66), (0.483, 0.603, 0.809), (3.46, 4.27, 5.66)),
    0.3: ((2.68, 3.44, 4.80), (2.68, 2.75, 2.81), (0.607, 0.715, 0.889), (2.49, 2.96, 3.72)),
    0.5: ((2.88, 3.62, 4.83), (2.88, 3.01, 3.14), (0.827, 0.929, 1.07), (1.74, 1.93, 2.22)),
    2.0: ((4.37, 5.10, 6.11), (4.37, 4.90, 5.56), (2.35, 2.62, 2.96), (0.958, 0.819, 0.650)),
    1 / 0.3: ((5.57, 6.34, 7.34), (5.57, 6.40, 7.51), (3.79, 4.32, 5.01),
              (0.868, 0.674, 0.446)),
    5.0: ((6.96, 7.78, 8.82), (6.96, 8.14, 9.79), (5.72, 6.63, 7.89), (0.828, 0.601, 0.341)),
    10.0: ((10.7, 11.7, 12.9), (10.7, 12.8, 16.0), (12.2, 14.6, 18.0), (0.795, 0.526, 0.228)),
}


@pytest.mark.parametrize("ratio", sorted(LITERAL))
def test_every_coefficient_off_the_circular_row_is_kalkers(ratio):
    # the rolling tests take their reference from the same table, so only literal values
    # catch a mistyped entry (C11 = 3.26 instead of 3.62 at a/b = 0.5 moves the wheel-rail
    # C11 by 10 % and no other test notices)
    for n, nu in enumerate(NU):
        expected = [column[n] for column in LITERAL[ratio]]
        assert _coefficients(ratio, nu) == pytest.approx(expected, rel=1e-9), nu


def test_the_table_is_smooth_along_every_column_in_its_interior():
    # a mistyped entry is a kink: each interior entry (g = 0.4-0.9, both halves, every column)
    # is predicted from the cubic through its four nearest neighbours in log C. Three digits
    # round each entry by <= 0.5 %, which the cubic's weights (1/6, 2/3, 2/3, 1/6 at worst)
    # carry to <= 0.8 %, plus the entry's own 0.5 %: 1.5 %. Measured worst 0.9 %; the typo
    # 3.62 -> 3.26 leaves a residual of 11 %.
    for half, rows in TABLE.items():
        for k in range(4):
            for n in range(3):
                column = np.log(rows[:, k, n])
                for i in range(3, 9):
                    near = [j for j in np.argsort(abs(np.arange(10) - i), kind="stable")
                            if j != i][:4]
                    fit = np.polyval(np.polyfit(RATIO[near], column[near], 3), RATIO[i])
                    assert abs(fit - column[i]) < 0.015, (half, k, n, RATIO[i])


def test_interpolation_returns_the_tabulated_values_at_the_nodes():
    for half, rows in TABLE.items():
        for g, row in zip(RATIO, rows, strict=True):
            ratio = g if half == "a<=b" else 1.0 / g
            for n, nu in enumerate(NU):
                assert _coefficients(ratio, nu) == pytest.approx(row[:, n], rel=1e-12)


def test_circular_contact_matches_kalkers_values():
    # a = b (Kalker 1967): C11 = 3.40, 4.12, 5.20; C22 = 3.40, 3.67, 3.98;
    # C23 = 1.33, 1.47, 1.63; C33 = 1.21, 1.19, 1.16 for nu = 0, 0.25, 0.5; both half-tables
    # end on this row
    expected = {0.0: (3.40, 3.40, 1.33, 1.21), 0.25: (4.12, 3.67, 1.47, 1.19),
                0.5: (5.20, 3.98, 1.63, 1.16)}
    for nu, values in expected.items():
        assert _coefficients(1.0, nu) == pytest.approx(values, abs=1e-12)
        below, above = _coefficients(1.0 - 1e-9, nu), _coefficients(1.0 + 1e-9, nu)
        assert below == pytest.approx(above, rel=1e-7)  # continuous across a = b


def test_longitudinal_and_lateral_coefficients_agree_without_poisson_effect():
    # nu = 0 decouples the normal and tangential problems and makes x and y alike up to the
    # ellipse, which Kalker's table shows as C11 = C22 for every ratio
    for ratio in np.geomspace(0.1, 10.0, 37):
        longitudinal, lateral, _, _ = _coefficients(ratio, 0.0)
        assert longitudinal == pytest.approx(lateral, rel=1e-12)


def test_creepage_coefficients_grow_with_poissons_ratio():
    # C11, C22, C23 only: C33 falls with nu from a/b = 1 on (Kalker's table, e.g. the circle's
    # 1.21, 1.19, 1.16) and rises below a/b = 0.9
    nus = np.linspace(0.0, 0.5, 26)
    for ratio in np.geomspace(0.1, 10.0, 25):
        values = np.array([_coefficients(ratio, nu)[:3] for nu in nus])
        assert np.all(np.diff(values, axis=0) > 0), ratio


@pytest.mark.parametrize("nu", [0.0, 0.25, 0.5])
def test_narrow_ellipses_approach_kalkers_closed_forms(nu):
    # a/b -> 0 (Kalker 1990, Appendix E): C11 -> pi²/(4(1 - nu)), C22 -> pi²/4. Extrapolated
    # linearly from the rows a/b = 0.2 and 0.1, the table lands within 3 % of them (the rows
    # bend slightly towards the limit: the extrapolation's own error)
    small, smaller = _coefficients(0.2, nu), _coefficients(0.1, nu)
    at_zero = 2 * smaller - small
    assert at_zero[0] == pytest.approx(math.pi**2 / (4 * (1 - nu)), rel=0.03)
    assert at_zero[1] == pytest.approx(math.pi**2 / 4, rel=0.03)


@pytest.mark.parametrize("nu", [0.0, 0.25, 0.5])
def test_narrow_ellipses_spin_moment_coefficient_approaches_the_strip_limit(nu):
    # a/b = g -> 0: every strip y is Carter's 2D rolling contact of half-length a(y) under the
    # creepage -phi y, whose force per length is (pi/2) a(y) E* (-phi y) with E* = G/(1 - nu)
    # (closed_forms, small creepage); its moment -int y f dy = -pi² E* a b³ phi/16 is
    # -G (ab)² C33 phi with C33 = pi²/(16 (1 - nu) g). g C33, extrapolated linearly from the
    # rows g = 0.2 and 0.1, lands within 5 % of pi²/(16 (1 - nu)) (measured 4.0, 2.5, 2.1 %)
    g_c33 = [g * _coefficients(g, nu)[3] for g in (0.2, 0.1)]
    assert 2 * g_c33[1] - g_c33[0] == pytest.approx(math.pi**2 / (16 * (1 - nu)), rel=0.05)


def test_narrow_ellipses_spin_coefficient_approaches_its_asymptote():
    # a/b = g -> 0, nu = 0: C23 -> pi sqrt(g)/3 (Kalker 1990, Appendix E, as used by CONTACT
    # below g = 0.1); at g = 0.1 the table is within 1 % of it
    spin = _coefficients(0.1, 0.0)[2]
    assert spin == pytest.approx(math.pi * math.sqrt(0.1) / 3, rel=0.01)


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"a": 0.0}, "a"), ({"b": -1.0}, "b"), ({"a": 0.05}, "a/b"), ({"a": 10.5}, "a/b"),
    ({"nu": -0.1}, "nu"), ({"nu": 0.51}, "nu"), ({"nu": math.nan}, "nu")])
def test_coefficients_refuse_bad_input(kwargs, name):
    args = {"a": 1.0, "b": 1.0, "nu": 0.3, **kwargs}
    with pytest.raises(ValueError, match=f"^{re.escape(name)}="):
        creep_coefficients(**args)


# ---------------------------------------------------------------- the Hertz ellipse

E_STAR = quasi_identical_modulus(82e9, 0.28)


def test_circular_contact_is_hertz_closed_form():
    # sphere of radius R on a plane: a = (3 F R / (4 E*))^(1/3), approach a²/R,
    # p0 = 3F/(2 pi a²) (Johnson 1985, §4.2)
    R, F = 0.02, 150.0
    contact = hertz_from_radii(R, R, math.inf, math.inf, F, E_STAR)
    a = (3 * F * R / (4 * E_STAR)) ** (1 / 3)
    assert (contact.a, contact.b) == pytest.approx((a, a), rel=1e-13)
    assert contact.approach == pytest.approx(a**2 / R, rel=1e-13)
    assert contact.p0 == pytest.approx(3 * F / (2 * math.pi * a**2), rel=1e-13)


@pytest.mark.parametrize(("A", "B"), [(1.0, 1.0 + 1e-9), (1.0, 1.3), (1.0, 4.0), (7.0, 1.0),
                                      (1.0, 500.0)])
def test_ellipse_reproduces_the_curvatures_through_legendres_integrals(A, B):
    # Johnson's relations re-evaluated with scipy's K(m), E(m) from the solved a, b, p0
    F = 2.0e4
    c = hertz_from_curvatures(A, B, F, E_STAR)
    long_axis, short_axis = max(c.a, c.b), min(c.a, c.b)
    m = 1 - (short_axis / long_axis) ** 2
    K, E = scipy.special.ellipk(m), scipy.special.ellipe(m)
    scale = c.p0 * short_axis / (E_STAR * m * long_axis**2)
    along_long, along_short = scale * (K - E), scale * (E / (1 - m) - K)
    # K - E loses digits to cancellation as m -> 0, hence the looser tolerance near a circle
    rel = 1e-4 if m < 1e-6 else 1e-10
    assert (along_long, along_short) == pytest.approx((min(A, B), max(A, B)), rel=rel)
    assert c.approach == pytest.approx(c.p0 * short_axis * K / E_STAR, rel=1e-12)
    assert (c.a > c.b) == (A < B)  # the long axis lies along the smaller curvature
    assert 2 * math.pi * c.a * c.b * c.p0 / 3 == pytest.approx(F, rel=1e-14)


def _boussinesq_gap(c: HertzEllipse, x0: float, y0: float) -> float:
    """Normal displacement difference (1/(pi E*)) ∫∫ p / r dA at (x0, y0) by quadrature in
    polar coordinates about the point: rho = R(theta) (1 - t²) makes the integrand smooth
    (p has a square-root zero at the ellipse's edge); Gauss-Legendre in t, the trapezoidal
    rule (spectrally accurate for periodic integrands) in theta."""
    t, wt = np.polynomial.legendre.leggauss(64)
    t, wt = 0.5 * (t + 1), 0.5 * wt
    theta = np.linspace(0, 2 * np.pi, 512, endpoint=False)
    cos, sin = np.cos(theta), np.sin(theta)
    # distance R(theta) to the edge: (x0 + R cos)²/a² + (y0 + R sin)²/b² = 1
    qa = cos**2 / c.a**2 + sin**2 / c.b**2
    qb = x0 * cos / c.a**2 + y0 * sin / c.b**2
    qc = x0**2 / c.a**2 + y0**2 / c.b**2 - 1
    R = (-qb + np.sqrt(qb**2 - qa * qc)) / qa
    rho = R[:, None] * (1 - t[None, :] ** 2)
    p = c.pressure(x0 + rho * cos[:, None], y0 + rho * sin[:, None])
    inner = (p * 2 * R[:, None] * t[None, :]) @ wt      # ∫ p drho, drho = 2 R t dt
    return float(inner.mean() * 2 * np.pi / (np.pi * E_STAR))


@pytest.mark.parametrize(("A", "B"), [(1.0, 2.5), (6.0, 1.0)])
def test_hertz_pressure_closes_the_gap_by_boussinesqs_integral(A, B):
    # inside the contact the elastic approach fills the gap: u(x, y) = delta - A x² - B y²,
    # with u from the half-space's point-load solution (Boussinesq) integrated over the
    # pressure: an independent check of a, b, p0 and the approach
    c = hertz_from_curvatures(A, B, 1.0e4, E_STAR)
    for x0, y0 in ((0.0, 0.0), (0.3 * c.a, -0.2 * c.b), (-0.1 * c.a, 0.7 * c.b)):
        gap = c.approach - A * x0**2 - B * y0**2
        # the quadrature is exact to round-off for the ellipsoidal pressure (measured 2e-16)
        assert _boussinesq_gap(c, x0, y0) == pytest.approx(gap, rel=1e-11)


def test_direct_ellipse_carries_the_load():
    c = HertzEllipse.from_axes(6.304e-3, 12.61e-3, 106.7e3)
    assert c.p0 == pytest.approx(3 * 106.7e3 / (2 * math.pi * 6.304e-3 * 12.61e-3), rel=1e-15)
    assert c.approach is None and c.pressure(0.0, 0.0) == pytest.approx(c.p0)
    assert c.pressure(7e-3, 0.0) == 0.0


def test_moduli():
    assert effective_modulus(210e9, 0.3, 210e9, 0.3) == pytest.approx(210e9 / (2 * 0.91))
    assert quasi_identical_modulus(80e9, 0.25) == pytest.approx(
        effective_modulus(200e9, 0.25, 200e9, 0.25), rel=1e-15)  # E = 2G(1 + nu)


@pytest.mark.parametrize(("call", "name"), [
    (lambda: hertz_from_curvatures(0.0, 1.0, 1.0, 1.0), "A"),
    (lambda: hertz_from_curvatures(1.0, 1.0, -1.0, 1.0), "Fn"),
    (lambda: hertz_from_curvatures(1.0, 1.0, 1.0, math.inf), "E_star"),
    (lambda: hertz_from_radii(0.0, 1.0, 1.0, 1.0, 1.0, 1.0), "R1x"),
    (lambda: hertz_from_radii(1.0, 1.0, -0.5, 1.0, 1.0, 1.0), "(1/R1x + 1/R2x)/2"),
    (lambda: HertzEllipse.from_axes(1.0, 0.0, 1.0), "b"),
    (lambda: effective_modulus(1.0, 0.7, 1.0, 0.3), "nu1"),
    (lambda: quasi_identical_modulus(-1.0, 0.3), "G")])
def test_hertz_refuses_bad_input(call, name):
    with pytest.raises(ValueError, match=f"^{re.escape(name)}="):
        call()
