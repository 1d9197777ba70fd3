"""Checks of the io-events room that its planted bugs asked for (tests/planted_bugs.toml):
the hybrid integrator's error control uses the tolerances it is given, and the mesh rows of
``vertex_rows`` put a node row where the spring is.

Both are checked against properties that hold by definition, not against numbers the code
printed: PETSc's step-error norm, max_i |e_i| / (atol + rtol max(|y_i|, |ŷ_i|)), is invariant
when the state and atol are scaled together; and a Lagrange row of nodes of degree p lies at
the vertex rows and at the fractions k/p between them.
"""

import numpy as np
import pytest

from fenicsfriction.events import integrate_hybrid
from fenicsfriction.meshing import vertex_rows

pytestmark = pytest.mark.sequential

OMEGA = 2.0


class ScaledSwings:
    """x'' = -ω² x from (A, 0), split at the turning points (tests/test_events.py's
    HalfSwings), its event function g = ±ẋ/A independent of the amplitude A."""

    size = 2

    def __init__(self, amplitude: float):
        self.amplitude = amplitude

    def rhs(self, t, y, mode):
        return np.array([y[1], -OMEGA**2 * y[0]])

    def events(self, t, y, mode):
        return np.array([-y[1] if mode == "down" else y[1]]) / self.amplitude

    def switch(self, t, y, mode, fired):
        return y, "up" if mode == "down" else "down"


def test_the_error_control_uses_rtol_and_atol_as_given():
    """The same oscillator at amplitudes 1 and 1024 (a power of 2: every product is scaled
    exactly), with atol scaled by the amplitude and rtol not: PETSc's weighted error norm is
    the same number in both runs, so they take the same steps and locate the same events.
    rtol and atol differ by 1e3 here, so a swap of the two breaks the invariance."""
    rtol, atol, scale = 1e-6, 1e-9, 1024.0
    runs = [integrate_hybrid(ScaledSwings(a), [a, 0.0], "down", 6.0, rtol=rtol, atol=a * atol)
            for a in (1.0, scale)]
    unit, scaled = runs
    assert len(unit.events) == len(scaled.events) == int(6.0 * OMEGA / np.pi)
    assert unit.rhs_evaluations == scaled.rhs_evaluations
    assert unit.steps == scaled.steps
    assert np.allclose([e.t for e in scaled.events], [e.t for e in unit.events],
                       rtol=1e-14, atol=0)
    assert np.allclose(scaled.y / scale, unit.y, rtol=0, atol=1e-14)
    # and the tolerance is the one asked for: the k-th turning point kπ/ω to about rtol
    # (velocity error ~ rtol per step, over |ẍ| = ω²), not to the much finer atol
    times = np.array([e.t for e in unit.events])
    error = np.abs(times - np.pi / OMEGA * np.arange(1, times.size + 1)).max()
    assert 1e-10 < error < 1e-5


@pytest.mark.parametrize(("n_rows", "degree", "H", "target"), [
    (6, 2, 1.0, 0.27),  # a midside row slides onto the target (cell row 1 of 6)
    (6, 2, 3.0, 1.35),  # the same with H != 1 (cell row 2)
    (5, 2, 2.0, 0.93),
    (4, 1, 1.0, 0.4),   # degree 1: a vertex row moves there
    (6, 3, 1.0, 0.45),  # degree 3: a row at a third of a cell
])
def test_vertex_rows_put_a_row_of_nodes_at_the_target(n_rows, degree, H, target):
    """The rows are increasing from 0 to H, n_rows + 1 of them, and one row of the
    degree-p nodes (vertex rows and the fractions k/p of each cell row between them) is at
    the target height."""
    rows = vertex_rows(n_rows, degree, H, target)
    assert len(rows) == n_rows + 1 and rows[0] == 0.0 and rows[-1] == pytest.approx(H)
    assert np.all(np.diff(rows) > 0)
    cell_nodes = rows[:-1, None] + np.diff(rows)[:, None] * np.arange(degree) / degree
    nodes = np.append(cell_nodes.ravel(), rows[-1])
    assert np.abs(nodes - target).min() < 1e-12 * H
