"""Fixtures shared by the test suite; every test must pass serially and under `mpirun -n 2`."""

import gc
import pathlib

from mpi4py import MPI

import pytest
from capture import on_every_rank


@pytest.fixture(autouse=True)
def collective_cleanup():
    """Destroy the PETSc objects a test leaves behind on all ranks together.

    PETSc destructors are collective: if ranks garbage-collect at different times, the next
    collective call can deadlock (the dolfinx test suite does the same).
    """
    yield
    gc.collect()
    MPI.COMM_WORLD.Barrier()


@pytest.fixture
def shared_tmp_path(request) -> pathlib.Path:
    """One temporary folder seen by every rank: rank 0's ``tmp_path``, broadcast.

    pytest's ``tmp_path`` is made per process, so under MPI each rank would get its own.
    """
    return on_every_rank(request.getfixturevalue("tmp_path") if MPI.COMM_WORLD.rank == 0
                         else None)


@pytest.fixture
def lu_factorisations():
    """How many numerical LU factorisations PETSc has made so far (its event log, switched on
    here): the count a solver's own bookkeeping is checked against."""
    from petsc4py import PETSc

    PETSc.Log.begin()
    event = PETSc.Log.Event("MatLUFactorNum")
    return lambda: event.getPerfInfo()["count"]


def pytest_collection_modifyitems(config, items):
    """Under ``mpirun`` the modules marked ``sequential`` (dense models on ``COMM_SELF``, no
    mesh) are deselected: every rank would repeat the serial pass's computation, so they cost the
    MPI pass their whole serial time and test nothing parallel."""
    if MPI.COMM_WORLD.size == 1:
        return
    kept = [item for item in items if item.get_closest_marker("sequential") is None]
    if len(kept) < len(items):
        config.hook.pytest_deselected(items=[i for i in items if i not in kept])
        items[:] = kept
