"""The closed forms of the contact scenes and the Hertz fit the demo and benchmark use."""

import numpy as np
import pytest

from fenicsfriction.studies.contact import closed_forms

pytestmark = pytest.mark.sequential


def test_hertz_fit_recovers_the_profile_from_nodes_that_miss_its_edge():
    """Nodes every 0.013 from 0 (none at the edge, a few outside at zero pressure):
    the fit returns a and p0 to round-off, where the last contact node is 9 % short."""
    a, p0 = 0.1, 0.0275
    r = np.arange(0.0, 0.2, 0.013)
    a_fit, p0_fit = closed_forms.fit_hertz_pressure(r, closed_forms.hertz_pressure(r, a, p0))
    assert a_fit == pytest.approx(a, rel=1e-12)
    assert p0_fit == pytest.approx(p0, rel=1e-12)
    assert np.abs(r[np.abs(r) < a]).max() < 0.92 * a


def test_hertz_fit_refuses_a_profile_without_contact():
    with pytest.raises(ValueError, match="pressure"):
        closed_forms.fit_hertz_pressure(np.linspace(0, 1, 5), np.zeros(5))


def test_line_and_point_contact_are_consistent_with_their_loads():
    """P = π a p0 / 2 (line), F = 2 π a² p0 / 3 (point): the pressure's integrals."""
    a, p0 = closed_forms.hertz_line_contact(0.004, 1.0, 1.1)
    assert np.pi * a * p0 / 2 == pytest.approx(0.004)
    a, p0 = closed_forms.hertz_point_contact(0.001, 1.0, 1.1)
    assert 2 * np.pi * a**2 * p0 / 3 == pytest.approx(0.001)


def test_hertz_contact_size_and_peak_match_worked_numbers():
    """Johnson 1985, eqs. 4.22-4.23 (sphere: a³ = 3FR/(4E*), p0 = 3F/(2πa²)) and 4.43-4.45
    (cylinder: a² = 4PR/(πE*), p0 = 2P/(πa)) worked by hand for E* = 100 GPa, R = 0.1 m and
    the loads that give a = 1 mm: F = 4 E* a³/(3R) = 4000/3 N, P = π E* a²/(4R) = 2.5e5 π N/m;
    then p0 = 2e9/π Pa (sphere) and 5e8 Pa (cylinder)."""
    a, p0 = closed_forms.hertz_point_contact(4000 / 3, 0.1, 1e11)
    assert a == pytest.approx(1e-3, rel=1e-12) and p0 == pytest.approx(2e9 / np.pi, rel=1e-12)
    a, p0 = closed_forms.hertz_line_contact(2.5e5 * np.pi, 0.1, 1e11)
    assert a == pytest.approx(1e-3, rel=1e-12) and p0 == pytest.approx(5e8, rel=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
def test_hertz_pressure_makes_the_surface_conform_to_the_profile(dim):
    """The independent integral: Hertz's pressure on a half-space lowers the surface by
    u(0) − u(a) = a²/(2R) between the centre and the edge, the profile's drop there
    (Johnson 1985, chapters 2-3). 2D, by line loads: u(0) − u(a) = (2/(π E*))
    ∫_{-a}^{a} p(s) ln|(a − s)/s| ds. 3D, by ring loads: u(0) = (2/E*) ∫_0^a p ds and
    u(a) = (4/(π E*)) ∫_0^a p(s) s/(a + s) K(2√(as)/(a + s)) ds, K the complete elliptic
    integral of the first kind of modulus k (SciPy's ellipk takes m = k²)."""
    from scipy import integrate, special

    R, E_star = 0.7, 2.3
    a, p0 = (closed_forms.hertz_line_contact if dim == 2 else closed_forms.hertz_point_contact)(
        0.01, R, E_star)

    def p(s):
        return p0 * np.sqrt(max(1 - (s / a) ** 2, 0.0))

    if dim == 2:
        drop = sum(integrate.quad(lambda s: p(s) * np.log(abs((a - s) / s)), lo, hi,
                                  points=[0.0], limit=200)[0]
                   for lo, hi in ((-a, 0.0), (0.0, a))) * 2 / (np.pi * E_star)
    else:
        centre = 2 / E_star * integrate.quad(p, 0.0, a)[0]
        edge = 4 / (np.pi * E_star) * integrate.quad(
            lambda s: p(s) * s / (a + s) * special.ellipk((2 * np.sqrt(a * s) / (a + s)) ** 2),
            0.0, a, limit=200)[0]
        drop = centre - edge
    assert drop == pytest.approx(a**2 / (2 * R), rel=1e-5)
