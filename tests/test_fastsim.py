"""Kalker's FASTSIM against the linear theory, the strip solution in closed form, full sliding
and symmetry (Kalker 1982; Kalker 1986, eqs. 24-30)."""

import math
import re

import numpy as np
import pytest
import scipy.integrate

from fenicsfriction.studies.rolling.fastsim import (
    creep_curve,
    fastsim,
    flexibilities,
    linear_theory,
)
from fenicsfriction.studies.rolling.kalker import creep_coefficients

pytestmark = pytest.mark.sequential

# the wheel-rail example, SI units
A, B, G, NU, FN, MU = 6.304e-3, 12.61e-3, 82e9, 0.28, 106.7e3, 0.3
C = math.sqrt(A * B)
# creepages this small keep the trailing-edge slip zone of the ellipsoidal bound (where the
# bound vanishes) at relative size ~1e-12: the solution is the fully adhesive one
TINY = 1e-9


def _orders(errors):
    return [math.log2(e0 / e1) for e0, e1 in zip(errors[:-1], errors[1:], strict=True)]


def test_longitudinal_force_is_the_linear_theory_up_to_the_midpoint_rule_in_y():
    # in full adhesion px = -xi (a(y) - x)/L1 exactly at the centres and its x-midpoint sum is
    # exact, so the only error is the midpoint rule for int 2a(y)² dy over ny strips:
    # relative h²/8 = 1/(2 ny²) (f = 1 - t², h = 2/ny), whatever nx
    exact = linear_theory(A, B, G, NU, xi=TINY).Fx
    assert exact == pytest.approx(-G * A * B * creep_coefficients(A, B, NU).C11 * TINY)
    for ny, nx in ((10, 3), (20, 20), (40, 7), (80, 80)):
        result = fastsim(A, B, G, NU, MU, FN, xi=TINY, nx=nx, ny=ny)
        assert result.Fx / exact - 1 == pytest.approx(0.5 / ny**2, rel=1e-6)
        assert result.Fy == 0.0 and result.adhesion.all()


@pytest.mark.parametrize("creepage", ["eta", "phi"])
def test_lateral_force_converges_to_the_linear_theory_at_second_order(creepage):
    # L2 and L3 are Kalker's choice that makes the simplified theory's C22 and C23 the linear
    # theory's; the spin traction is quadratic in x, so the x-midpoint sum errs too: O(n^-2)
    kwargs = {"eta": TINY} if creepage == "eta" else {"phi": TINY / C}
    exact = linear_theory(A, B, G, NU, **kwargs).Fy
    errors = [abs(fastsim(A, B, G, NU, MU, FN, nx=n, ny=n, **kwargs).Fy / exact - 1)
              for n in (10, 20, 40, 80)]
    assert errors[-1] < 2e-4
    assert all(1.9 < order < 2.2 for order in _orders(errors)), _orders(errors)


def test_spin_moment_converges_to_the_simplified_theorys_closed_forms():
    # simplified theory in full adhesion: Mz = pi a³ b eta / (4 L2) for lateral creepage
    # (Kalker's sign: -G c³ (-C23 eta) > 0) and Mz = -8 a² b³ phi / (15 L4) for spin, which
    # L4 makes the linear theory's -G c⁴ C33 phi
    _, L2, _, L4 = flexibilities(A, B, G, NU)
    phi = TINY / C
    exact = {"eta": math.pi * A**3 * B * TINY / (4 * L2), "phi": -8 * A**2 * B**3 * phi / (15 * L4)}
    assert exact["eta"] * linear_theory(A, B, G, NU, eta=TINY).Mz > 0
    assert exact["phi"] == pytest.approx(linear_theory(A, B, G, NU, phi=phi).Mz, rel=1e-12)
    for name, kwargs in (("eta", {"eta": TINY}), ("phi", {"phi": phi})):
        errors = [abs(fastsim(A, B, G, NU, MU, FN, nx=n, ny=n, **kwargs).Mz / exact[name] - 1)
                  for n in (10, 20, 40, 80)]
        assert errors[-1] < 1e-3
        assert all(1.8 < order < 2.2 for order in _orders(errors)), (name, _orders(errors))


def test_kalkers_single_spin_flexibility_misses_the_spin_moment_by_his_own_factor():
    # Kalker 1982 fits L3 to C23 and uses it for both spin components: Fy of spin stays the
    # linear theory's, Mz of spin becomes -8 a² b³ phi/(15 L3), i.e. the linear theory's times
    # 32 C23 (b/a)^(3/2) / (15 pi C33)
    phi = TINY / C
    flex = flexibilities(A, B, G, NU)
    k = creep_coefficients(A, B, NU)
    linear = linear_theory(A, B, G, NU, phi=phi)
    kalker, ours = (fastsim(A, B, G, NU, MU, FN, phi=phi, nx=160, ny=160, flexibility=f)
                    for f in (flex.kalker1982(), flex))
    factor = 32 * k.C23 * (B / A) ** 1.5 / (15 * math.pi * k.C33)
    assert kalker.Mz / linear.Mz == pytest.approx(factor, rel=2e-4)
    assert ours.Mz / linear.Mz == pytest.approx(1, rel=2e-4)
    assert kalker.Fy == pytest.approx(ours.Fy, rel=1e-12)  # phi x alone makes Fy


def _strip_force(kappa: float) -> float:
    """F/(mu * strip load) of one strip under a parabolic bound and longitudinal creepage:
    adhesion from the leading edge to x* = a(2 kappa - 1), where xi (a - x)/L1 meets
    mu p (1 - x²/a²), slip behind it; kappa = xi a / (2 L1 mu p) (derived in
    docs/rolling-fastsim.md; cf. Johnson 1985, §8.4 for the 2D rolling strip)."""
    return 1.0 - (1.0 - min(kappa, 1.0)) ** 3


@pytest.mark.parametrize("kappa", [0.1, 0.35, 0.7, 0.95, 1.5])
def test_one_strip_is_the_closed_form_strip_solution(kappa):
    # ny = 1: one strip through the centre, of width 2b, under p_hat (1 - x²/a²); the
    # traction is exact at the centres (adhesion: the line; slip: the bound), so the error is
    # the midpoint rule's across the kink at x*: O(nx^-2)
    L1 = flexibilities(A, B, G, NU).L1
    p_hat = 2 * FN / (math.pi * A * B)
    xi = kappa * 2 * L1 * MU * p_hat / A
    exact = -2 * B * MU * p_hat * (4 * A / 3) * _strip_force(kappa)
    errors = [abs(fastsim(A, B, G, NU, MU, FN, xi=xi, nx=nx, ny=1, pressure="parabolic").Fx
                  / exact - 1) for nx in (100, 200, 400)]
    assert errors[-1] < 5e-6
    assert all(1.9 < order < 2.1 for order in _orders(errors)), _orders(errors)


def test_parabolic_fastsim_is_the_strip_solution_integrated_across_the_strips():
    # each strip y is a 2D strip of half-length a(y) under mu p_hat (1 - y²/b²)(1 - x²/a(y)²):
    # Fx = -int mu p_hat (1 - y²/b²) (4 a(y)/3) S(kappa(y)) dy, kappa(y) = kappa0 / sqrt(1 -
    # y²/b²), integrated by quad; FASTSIM's nx × ny midpoint sums approach it at O(n^-2)
    L1 = flexibilities(A, B, G, NU).L1
    p_hat = 2 * FN / (math.pi * A * B)
    kappa0 = 0.5
    xi = kappa0 * 2 * L1 * MU * p_hat / A

    def integrand(y):
        s = 1 - (y / B) ** 2
        return MU * p_hat * s * 4 * A * math.sqrt(s) / 3 * _strip_force(kappa0 / math.sqrt(s))

    edge = B * math.sqrt(1 - kappa0**2)  # beyond |y| = edge the strips slide entirely
    exact = -scipy.integrate.quad(integrand, -B, B, points=[-edge, edge], epsabs=0,
                                  epsrel=1e-13)[0]
    errors = [abs(fastsim(A, B, G, NU, MU, FN, xi=xi, nx=n, ny=n, pressure="parabolic").Fx
                  / exact - 1) for n in (20, 40, 80, 160)]
    assert errors[-1] < 2e-4
    assert all(1.5 < order < 2.5 for order in _orders(errors)), _orders(errors)


@pytest.mark.parametrize("pressure", ["ellipsoidal", "parabolic"])
def test_full_sliding_carries_mu_times_the_normal_load(pressure):
    n = 40
    sliding = fastsim(A, B, G, NU, MU, FN, xi=1.0, nx=n, ny=n, pressure=pressure)
    dx = sliding.x[:, :1] - sliding.x[:, 1:2]  # each strip's element length
    load = float(np.sum(sliding.pn * dx * 2 * B / n))
    # every element slides backwards: Fx is exactly -mu times the discretised load
    assert not sliding.adhesion.any()
    assert sliding.Fx == pytest.approx(-MU * load, rel=1e-12)
    # the discretised load is Fn up to the quadrature of the pressure: the ellipsoidal one's
    # square root at the edge costs more (O(n^-1.5)) than the parabola's (O(n^-2))
    errors = [abs(fastsim(A, B, G, NU, MU, FN, xi=1.0, nx=m, ny=m, pressure=pressure).Fx
                  / (MU * FN) + 1) for m in (20, 40, 80, 160)]
    assert errors[1] < (2e-3 if pressure == "ellipsoidal" else 5e-4)
    assert all(order > 1.4 for order in _orders(errors)), _orders(errors)


def test_full_sliding_under_combined_creepage_points_along_the_flexibility_weighted_creepage():
    L1, L2, _, _ = flexibilities(A, B, G, NU)
    xi, eta = 0.3, -0.4
    sliding = fastsim(A, B, G, NU, MU, FN, xi=xi, eta=eta)
    direction = np.array([xi / L1, eta / L2]) / math.hypot(xi / L1, eta / L2)
    force = np.array([sliding.Fx, sliding.Fy])
    assert force / np.linalg.norm(force) == pytest.approx(-direction, abs=1e-12)
    assert np.linalg.norm(force) == pytest.approx(MU * FN, rel=2e-3)  # the load's quadrature


@pytest.mark.parametrize("phi", [TINY / C, 2e-3 / C, 1.0 / C])
def test_pure_spin_gives_no_longitudinal_force_and_a_lateral_force_against_the_spin(phi):
    # px(x, -y) = -px(x, y) and py(x, -y) = py(x, y): the strips at ±y clip alike
    result = fastsim(A, B, G, NU, MU, FN, phi=phi)
    assert abs(result.Fx) <= 1e-12 * abs(result.Fy)
    assert result.Fy < 0  # the sign of -G c³ C23 phi
    assert np.allclose(result.px, -result.px[::-1], rtol=0, atol=1e-9 * np.abs(result.px).max())


def test_adhesion_is_at_the_leading_edge_and_shrinks_as_the_creepage_grows():
    # up to just below full sliding, which the parabolic bound reaches at kappa = 1 of the
    # strip solution, xi = 2 L1 mu p_hat / a = 4.47e-3
    xis = np.linspace(1e-5, 4.4e-3, 30)
    results = creep_curve(A, B, G, NU, MU, FN, xi=xis)
    fractions = [r.adhesion_fraction for r in results]
    # on a 40 × 40 grid the fraction moves in steps of whole elements (1/40 of a strip)
    assert fractions[0] > 0.99 and fractions[-1] < 0.03
    assert all(f1 <= f0 for f0, f1 in zip(fractions[:-1], fractions[1:], strict=True))
    assert len(set(fractions)) > 15
    for r in results:
        # per strip: a run of adhering elements from the leading edge (element 0), then slip
        first_slip = np.argmin(r.adhesion, axis=1)
        first_slip[r.adhesion.all(axis=1)] = r.adhesion.shape[1]
        expected = np.arange(r.adhesion.shape[1])[None, :] < first_slip[:, None]
        assert np.array_equal(r.adhesion, expected)
    # the creep curve rises monotonically towards mu Fn
    forces = [-r.Fx for r in results]
    assert all(f1 > f0 for f0, f1 in zip(forces[:-1], forces[1:], strict=True))
    assert forces[-1] < MU * FN * 1.001  # the parabolic load's quadrature error at 40 × 40


def test_a_creep_curve_is_the_same_as_its_points_one_by_one():
    xis, etas = np.array([1e-4, 1e-3, 3e-3]), np.array([0.0, -5e-4, 2e-3])
    batch = creep_curve(A, B, G, NU, MU, FN, xi=xis, eta=etas, phi=1.0, nx=12, ny=9)
    for r, xi, eta in zip(batch, xis, etas, strict=True):
        single = fastsim(A, B, G, NU, MU, FN, xi=xi, eta=eta, phi=1.0, nx=12, ny=9)
        assert (r.Fx, r.Fy, r.Mz) == pytest.approx((single.Fx, single.Fy, single.Mz),
                                                   rel=1e-14, abs=1e-20)
        assert np.array_equal(r.adhesion, single.adhesion)


def test_a_hundred_point_creep_curve_on_a_40_by_40_grid_runs():
    # timing belongs to benchmarks/bench_rolling.py; here only that the batch completes
    results = creep_curve(A, B, G, NU, MU, FN, xi=np.linspace(0, 5e-3, 100), eta=1e-4)
    assert len(results) == 100 and all(np.isfinite([r.Fx, r.Fy, r.Mz]).all() for r in results)


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"a": 0.0}, "a"), ({"b": -1.0}, "b"), ({"G": math.inf}, "G"), ({"nu": 0.6}, "nu"),
    ({"mu": 0.0}, "mu"), ({"Fn": -1.0}, "Fn"), ({"nx": 0}, "nx"), ({"ny": 2.5}, "ny"),
    ({"nx": True}, "nx"), ({"pressure": "flat"}, "pressure"), ({"xi": math.nan}, "xi"),
    ({"eta": [1.0]}, "eta"), ({"a": 1.0, "b": 0.05}, "a/b")])
def test_bad_input_is_refused_naming_the_parameter(kwargs, name):
    args = {"a": A, "b": B, "G": G, "nu": NU, "mu": MU, "Fn": FN, **kwargs}
    with pytest.raises(ValueError, match=f"^{re.escape(name)}="):
        fastsim(**args)


def test_creep_curve_refuses_creepages_that_do_not_broadcast():
    with pytest.raises(ValueError, match="^creepage shapes="):
        creep_curve(A, B, G, NU, MU, FN, xi=[1e-3, 2e-3], eta=[0.0, 1e-3, 2e-3])
    with pytest.raises(ValueError, match="^phi="):
        creep_curve(A, B, G, NU, MU, FN, phi=[[1.0]])


def test_linear_theory_gives_kalkers_spin_moment_with_spin():
    # Kalker 1990, Appendix E: Mz = -G c³ (-C23 eta + c C33 phi): the lateral coupling's sign
    # is opposite to the spin's own, and the theory is linear (superposition)
    k = creep_coefficients(A, B, NU)
    eta, phi = 1e-3, 0.4
    Fx, Fy, Mz = linear_theory(A, B, G, NU, xi=1e-3, eta=eta, phi=phi)
    assert (Fx, Fy, Mz) == pytest.approx((-G * C**2 * k.C11 * 1e-3,
                                          -G * C**2 * (k.C22 * eta + C * k.C23 * phi),
                                          G * C**3 * k.C23 * eta - G * C**4 * k.C33 * phi),
                                         rel=1e-14)
    spin, lateral = (linear_theory(A, B, G, NU, phi=phi).Mz, linear_theory(A, B, G, NU, eta=eta).Mz)
    assert spin < 0 < lateral and Mz == pytest.approx(spin + lateral, rel=1e-14)


# ------------------------------------------------ against Kalker's algorithm, strip by strip

def _kalker_fastsim(xi, eta, phi, flex, n, mu, pressure):
    """Kalker's FASTSIM (1982) as published, written out strip by strip: n strips of equal
    width, n equal steps along each from the leading edge, the traction carried by the steps'
    end points (zero at the leading edge), the slip-free increment of each step taken at its
    midpoint, clipped to the bound mu p_n at the new point; forces by the sum over the points
    (the trapezoidal rule, the traction vanishing at both edges). Another discretisation than
    the package's element centres: the two agree to O(h)."""
    L1, L2, L3, L4 = flex
    p_hat = (2 if pressure == "parabolic" else 1.5) * FN / (math.pi * A * B)
    dy = 2 * B / n
    Fx = Fy = Mz = 0.0
    for j in range(n):
        y = -B + (j + 0.5) * dy
        half = A * math.sqrt(1 - (y / B) ** 2)
        dx = 2 * half / n
        px = py = 0.0
        for i in range(1, n + 1):
            x = half - i * dx
            rho2 = max(1 - (x / A) ** 2 - (y / B) ** 2, 0.0)
            bound = mu * p_hat * (rho2 if pressure == "parabolic" else math.sqrt(rho2))
            px -= dx * (xi / L1 - phi * y / L4)
            py -= dx * (eta / L2 + phi * (x + 0.5 * dx) / L3)
            size = math.hypot(px, py)
            if size > bound:
                px, py = px * bound / size, py * bound / size
            Fx += px * dx * dy
            Fy += py * dx * dy
            Mz += (x * py - y * px) * dx * dy
    return Fx, Fy, Mz


# the wheel-rail creep curves (mu = 0.33), from small creepage to full sliding,
# without and with spin (phi c up to 0.07)
WHEEL_RAIL_MU = 0.33
CURVES = {"xi": {"xi": np.linspace(1e-3, 1e-2, 10)},
          "xi with spin": {"xi": np.linspace(1e-3, 1e-2, 10), "phi": 2.0},
          "pure spin": {"phi": np.linspace(0.8, 8.0, 10)},
          "eta against spin": {"eta": np.linspace(1e-3, 1e-2, 10), "phi": -2.0}}


@pytest.mark.parametrize("pressure", ["parabolic", "ellipsoidal"])
@pytest.mark.parametrize("curve", sorted(CURVES))
def test_the_creep_curve_is_kalkers_fastsim_within_one_percent(curve, pressure):
    # same grid (the default 40 × 40), two discretisations of one algorithm: they differ by
    # O(h); measured on every curve <= 0.094 % of mu Fn (and of mu Fn c for Mz) with the
    # parabolic bound, <= 0.47 % with the ellipsoidal one (whose square root at the edges the
    # two quadratures sample differently)
    flex = flexibilities(A, B, G, NU)
    scale = WHEEL_RAIL_MU * FN * np.array([1.0, 1.0, C])
    for r in creep_curve(A, B, G, NU, WHEEL_RAIL_MU, FN, pressure=pressure, **CURVES[curve]):
        ours = np.array([r.Fx, r.Fy, r.Mz])
        reference = _kalker_fastsim(r.xi, r.eta, r.phi, flex, 40, WHEEL_RAIL_MU, pressure)
        assert np.abs(ours - reference) / scale == pytest.approx(0, abs=0.01), (r.xi, r.eta,
                                                                               r.phi)


def test_both_discretisations_converge_to_one_creep_force_under_spin():
    # under large spin the traction turns within the slip zone and both converge at first
    # order only (Fy: -0.191, -0.171, -0.163, -0.158 mu Fn on 20² ... 160²); on 160² they
    # agree within 1e-4 mu Fn, and Kalker's own single spin flexibility agrees alike
    flex = flexibilities(A, B, G, NU)
    for f in (flex, flex.kalker1982()):
        ours = fastsim(A, B, G, NU, WHEEL_RAIL_MU, FN, xi=2e-3, phi=4.0, nx=160, ny=160,
                       flexibility=f)
        reference = _kalker_fastsim(2e-3, 0.0, 4.0, f, 160, WHEEL_RAIL_MU, "parabolic")
        scale = WHEEL_RAIL_MU * FN * np.array([1.0, 1.0, C])
        assert np.abs(np.array([ours.Fx, ours.Fy, ours.Mz]) - reference) / scale \
            == pytest.approx(0, abs=1e-3)


def test_the_default_bound_is_kalkers_parabola():
    # on the wheel-rail case at xi = 1.2e-3 the default is the strip-by-strip
    # algorithm's with the parabolic bound (measured 0.6156 against 0.6150 mu Fn), and not the
    # ellipsoidal one's (0.6568: 7 % more)
    flex = flexibilities(A, B, G, NU)
    default = fastsim(A, B, G, NU, WHEEL_RAIL_MU, FN, xi=1.2e-3)
    kalker, hertz = (_kalker_fastsim(1.2e-3, 0.0, 0.0, flex, 40, WHEEL_RAIL_MU, pressure)[0]
                     for pressure in ("parabolic", "ellipsoidal"))
    assert default.Fx == pytest.approx(kalker, rel=2e-3)
    assert abs(default.Fx / hertz - 1) > 0.05
    parabolic = fastsim(A, B, G, NU, WHEEL_RAIL_MU, FN, xi=1.2e-3, pressure="parabolic")
    assert default.Fx == parabolic.Fx and np.array_equal(default.pn, parabolic.pn)


@pytest.mark.parametrize("flexibility", [(1.0, 2.0, 3.0), "L", (1.0, 2.0, 3.0, -4.0)])
def test_a_flexibility_that_is_not_four_positive_numbers_is_refused(flexibility):
    if isinstance(flexibility, tuple) and len(flexibility) == 4:
        from fenicsfriction.studies.rolling.fastsim import Flexibilities

        flexibility = Flexibilities(*flexibility)
    with pytest.raises(ValueError, match="^flexibility="):
        fastsim(A, B, G, NU, MU, FN, xi=1e-3, flexibility=flexibility)


@pytest.mark.parametrize("on", [(x, e, p) for x in (0, 1) for e in (0, 1) for p in (0, 1)])
def test_every_combination_of_creepages_gives_finite_forces_and_a_spin_moment(on):
    # any of xi, eta, phi zero: both theories answer (no None), and no creepage gives nothing
    xi, eta, phi = (v * s for v, s in zip(on, (1e-3, -5e-4, 2.0), strict=True))
    linear = linear_theory(A, B, G, NU, xi=xi, eta=eta, phi=phi)
    simplified = fastsim(A, B, G, NU, MU, FN, xi=xi, eta=eta, phi=phi)
    for forces in (linear, (simplified.Fx, simplified.Fy, simplified.Mz)):
        assert all(isinstance(v, float) and math.isfinite(v) for v in forces)
    assert (np.any(np.array(linear) != 0) and simplified.adhesion_fraction < 1) == any(on)
