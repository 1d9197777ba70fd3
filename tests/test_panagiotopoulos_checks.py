"""Checks of the panagiotopoulos room that its planted bugs asked for
(tests/planted_bugs.toml): the process starts from the frictionless normal problem
(Kalker 1986, §3: p_τ⁽⁰⁾ = 0) on every solve, whatever an earlier solve left frozen, and
for a friction integral as for a contact coupling's friction; and it gives up exactly
``patience`` iterations after the smallest change.
"""

from mpi4py import MPI

import numpy as np
import pytest

import fenicsfriction as ff
from fenicsfriction.panagiotopoulos import PanagiotopoulosSolver, ProcessError
from fenicsfriction.studies.block import BlockOnSlab, LayeredBlockOnBelt

#: serial only: the MPI pass of the suite is near its time budget (the process on two ranks
#: is compared with one in tests/test_panagiotopoulos.py)
pytestmark = pytest.mark.sequential


@pytest.mark.parametrize(("scene", "mu"), [(ff.BlockOnBelt(), 1.0), (BlockOnSlab(), 0.8)],
                         ids=["integral", "coupling"])
def test_every_solve_starts_from_the_frictionless_normal_problem(scene, mu):
    """Johnson's step twice from the same guess: the first outer solve has no friction, so
    the friction forces it was solved with are zero and the first relative change is 1
    exactly (‖f⁽¹⁾ − 0‖ / ‖f⁽¹⁾‖), for the block on the belt (a friction integral) and on a
    slab (node-to-segment contact: its friction forces are its residual less its
    frictionless residual); the second call repeats the first to round-off, although the
    first left its converged bound frozen in the solver."""
    model = scene.build(MPI.COMM_WORLD, with_friction=True)
    johnson = PanagiotopoulosSolver(model.residual, method="johnson",
                                    prefix=f"checks_johnson_{type(scene).__name__}_",
                                    options=model.solver_options(),
                                    parameters={"mu": model.mu})
    model.mu.value = mu
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


def test_the_process_gives_up_patience_iterations_after_its_smallest_change():
    """The soft layer past the Dundurs limit (μβ = 1.3, tests/test_panagiotopoulos.py): the
    changes stop falling, and the process stops when the smallest change is ``patience``
    iterations old, for patience 2 and 3."""
    scene = LayeredBlockOnBelt(layer_nu=0.0, spring_height=30.5 / 12)
    model = scene.build(MPI.COMM_WORLD, with_friction=True)
    model.mu.value = 1.3 / 0.5  # β = 1/2 for ν = 0
    for patience in (2, 3):
        process = PanagiotopoulosSolver(model.residual, prefix=f"checks_patience{patience}_",
                                        options=model.solver_options(), max_iterations=100,
                                        patience=patience, parameters={"mu": model.mu})
        model.initial_guess()
        with pytest.raises(ProcessError, match="diverges") as caught:
            process.solve()
        changes = caught.value.report.changes
        assert len(changes) - 1 - int(np.argmin(changes)) == patience, changes
