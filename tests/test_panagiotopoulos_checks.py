"""Checks of the panagiotopoulos room that its planted bugs asked for
(tests/planted_bugs.toml): the process starts from the frictionless normal problem
(Kalker 1986, §3: p_τ⁽⁰⁾ = 0) on every solve, whatever an earlier solve left frozen.
"""

from mpi4py import MPI

import numpy as np
import pytest

import fenicsfriction as ff
from fenicsfriction.panagiotopoulos import PanagiotopoulosSolver

pytestmark = pytest.mark.sequential


def test_every_solve_starts_from_the_frictionless_normal_problem():
    """Johnson's step twice from the same guess, μ = 1: the first outer solve has no friction,
    so the friction forces it was solved with are zero and the first relative change is 1
    exactly (‖f⁽¹⁾ − 0‖ / ‖f⁽¹⁾‖); the second call repeats the first to round-off, although
    the first left its converged bound frozen in the solver."""
    model = ff.BlockOnBelt().build(MPI.COMM_WORLD, with_friction=True)
    johnson = PanagiotopoulosSolver(model.residual, method="johnson", prefix="checks_johnson_",
                                    options=model.solver_options(),
                                    parameters={"mu": model.mu})
    model.mu.value = 1.0
    states, reports = [], []
    for _ in range(2):
        model.initial_guess()
        reports.append(johnson.solve())
        states.append(model.residual.u.x.array.copy())
    for report in reports:
        assert report.outer_iterations == 2
        assert report.changes[0] == 1.0
    assert reports[1].changes == pytest.approx(reports[0].changes, rel=1e-10)
    scale = np.abs(states[0]).max()
    assert np.allclose(states[1], states[0], rtol=0, atol=1e-12 * scale)
