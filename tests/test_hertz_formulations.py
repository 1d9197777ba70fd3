"""Mortar contact converges to Hertz's cylinder (Hertz 1882; Johnson 1985, chapter 4) as the
mesh is refined.

The pressure compared is the one the mortar coupling transmits: each slave node's contact force
over its load weight (``SurfaceValues.force``), the lumped value of the traction field
sum_j p_j psi_j. Hertz's pressure p0 sqrt(1 - x²/a²) has a square-root edge, which caps the
pressure's convergence at first order in h: near the edge the profile's second derivative
grows like (a - x)^{-3/2}, so the element at distance k h from it contributes an error
~ p0 sqrt(h/a) k^{-3/2} over a length h, and the L2 norm sums to O(h/a) whatever the degree.
The fitted half-width and peak converge at least as fast until they reach the floor of
Hertz's own parabolic profile (about 0.2 % at a = R/10, docs/contact.md).
"""

import dataclasses

from mpi4py import MPI

import numpy as np

from fenicsfriction.studies.contact import closed_forms
from fenicsfriction.studies.contact.validation import Hertz


def transmitted_pressure_errors(a_over_h: int) -> dict[str, float]:
    """The relative errors of the fitted half-width and peak and the L2 error of the
    transmitted pressure, mortar (degree 1) on the 2D scene with h = a / ``a_over_h``."""
    scene = Hertz(dim=2, formulation="mortar", degree=1)
    a, p0 = scene.closed_form()
    scene = dataclasses.replace(scene, h_contact=a / a_over_h)
    _, model = scene.run(MPI.COMM_WORLD)
    values = model.surface_values()
    loaded = values.load_weight > 0
    x, weight = values.x[loaded, 0], values.load_weight[loaded]
    pressure = np.maximum(values.force[loaded, -1], 0.0)
    a_fit, p0_fit = closed_forms.fit_hertz_pressure(x, pressure)
    exact = closed_forms.hertz_pressure(x, a, p0)
    l2 = np.sqrt(np.sum(weight * (pressure - exact) ** 2) / np.sum(weight * exact**2))
    return {"half_width": abs(a_fit / a - 1), "peak": abs(p0_fit / p0 - 1),
            "pressure_l2": float(l2)}


def test_mortar_hertz_2d_converges_at_least_at_first_order():
    """From h = a/5 to a/10 every error falls at least by 2^1 (to 0.6 of it: first order with
    20 % to spare), and at a/10 the half-width and peak are within 1 %."""
    coarse, fine = transmitted_pressure_errors(5), transmitted_pressure_errors(10)
    for key in coarse:
        assert fine[key] < 0.6 * coarse[key], (key, coarse[key], fine[key])
    assert fine["half_width"] < 0.01 and fine["peak"] < 0.01
