"""The distributed solve gives the serial answer (run with `mpirun -n 2 ... pytest --with-mpi`).

Without ``--with-mpi`` pytest-mpi skips these tests; they run in the MPI pass.
"""

from mpi4py import MPI

import numpy as np
import pytest

import fenicsfriction as ff
from fenicsfriction._compat import petsc_vec

FORCES = ("normal_force", "friction_force", "spring_force")
PENETRATIONS = ("min_penetration", "max_penetration")


def continuation(comm: MPI.Comm, prefix: str) -> tuple[ff.BlockOnBelt, list, int]:
    scene = ff.BlockOnBelt(refine=2)  # 8 × 6 cells: every rank owns part of the contact face
    model = scene.build(comm, with_friction=True)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix=prefix, options=model.solver_options())
    records = ff.continuation(solver, model.mu, np.linspace(0.0, 1.5, 16),
                              observe=model.quantities)
    return scene, records, petsc_vec(model.residual.u).getSize()


@pytest.mark.mpi(min_size=2)
def test_distributed_continuation_matches_serial_solve_on_every_rank():
    """COMM_WORLD (mesh split over the ranks) against COMM_SELF (each rank alone, whole mesh).

    Each solve is an equilibrium to its residual: a row sum of R — a force resultant — is
    known to sqrt(n) (residual_norm + atol) (Cauchy-Schwarz; atol includes R's round-off
    floor), so two solves agree to the sum of their bounds; the centre of pressure carries
    the lever arm (≤ sqrt((L/2)² + H²) + h_s) and 1/N. The penetration follows a force error
    δN as δd/d = δN / (m_n N); a factor 10 allows for a non-uniform error.
    """
    scene, distributed, n = continuation(MPI.COMM_WORLD, "world_")
    _, serial, n_serial = continuation(MPI.COMM_SELF, "self_")
    assert n == n_serial
    lever = np.hypot(scene.L / 2, scene.H) + scene.spring_height
    for a, b in zip(distributed, serial, strict=True):
        assert a["mu"] == b["mu"]
        force_error = np.sqrt(n) * (a["residual_norm"] + a["atol"] + b["residual_norm"]
                                    + b["atol"])
        for key in FORCES:
            assert a[key] == pytest.approx(b[key], abs=force_error), (key, a, b)
        assert a["centre_of_pressure"] == pytest.approx(
            b["centre_of_pressure"], abs=force_error * lever / b["normal_force"]), (a, b)
        for key in PENETRATIONS:
            tolerance = 10 * force_error / (scene.law.m_n * b["normal_force"]) \
                * b["max_penetration"]
            assert a[key] == pytest.approx(b[key], abs=tolerance), (key, a, b)

