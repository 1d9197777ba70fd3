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
