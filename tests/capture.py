"""What a command leaves besides its files: the folder every rank shares, the progress lines it
logs, what it prints (PETSc's monitors included) and the mesh size it writes. The tests that
check reported figures (``test_reported_*.py``) read a run through these, one way for all."""

from __future__ import annotations

import contextlib
import csv
import ctypes
import logging
import os
import pathlib
import re
import sys
import typing

from mpi4py import MPI

import pytest

from fenicsfriction.results import get_logger


def on_every_rank(path: pathlib.Path | None, comm: MPI.Comm = MPI.COMM_WORLD) -> pathlib.Path:
    """Rank 0's ``path``, broadcast: one folder seen by every rank (pytest makes its temporary
    folders per process)."""
    return pathlib.Path(comm.bcast(path, root=0))


def shared_folder(factory: pytest.TempPathFactory, name: str,
                  comm: MPI.Comm = MPI.COMM_WORLD) -> pathlib.Path:
    """A module-wide temporary folder seen by every rank."""
    return on_every_rank(factory.mktemp(name) if comm.rank == 0 else None, comm)


class LoggedLines(logging.Handler):
    """Collects the progress lines a command logs (rank 0's: the others log none)."""

    def __init__(self) -> None:
        super().__init__(logging.INFO)
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.lines.append(record.getMessage())


@contextlib.contextmanager
def logged_lines(comm: MPI.Comm = MPI.COMM_WORLD) -> typing.Iterator[list[str]]:
    """The list the package's logger fills while the block runs (the package's own handlers
    come first: :func:`get_logger` makes them on its first call)."""
    logger = get_logger(comm)
    handler = LoggedLines()
    logger.addHandler(handler)
    try:
        yield handler.lines
    finally:
        logger.removeHandler(handler)


@contextlib.contextmanager
def stdout_into(path: pathlib.Path) -> typing.Iterator[None]:
    """Everything printed, by Python (the progress lines) and by PETSc's C code (its SNES
    monitor), into ``path`` in the order printed: file descriptor 1 is pointed at the file
    and ``sys.stdout`` written through it line by line (PETSc flushes each print). petsc4py
    sends PETSc's printing through ``sys.stdout`` under pytest's capture and straight to the
    descriptor under ``pytest -s``: both land here."""
    sys.stdout.flush()
    saved = os.dup(1)
    target = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    os.dup2(target, 1)
    os.close(target)
    try:
        with open(1, "w", buffering=1, closefd=False) as stream, \
                contextlib.redirect_stdout(stream):
            yield
    finally:
        ctypes.CDLL(None).fflush(None)
        os.dup2(saved, 1)
        os.close(saved)


def xdmf_nodes(xdmf: pathlib.Path) -> int:
    """The number of mesh nodes, read from the Geometry item of an XDMF file."""
    geometry = re.search(r'<Geometry[^>]*>\s*<DataItem Dimensions="(\d+) \d+"',
                         xdmf.read_text())
    assert geometry is not None
    return int(geometry.group(1))


def run_main(argv: list[str], summary: str = "summary.json",
             options: dict | None = None) -> dict:
    """``main(argv)`` in this process, with the PETSc ``options`` set for it alone: its exit
    status (``code``), the JSON ``summary`` it wrote (``json``), the rows of its
    timeseries.csv as floats (``rows``; None without one), the lines it printed to stdout
    and stderr (``stdout``, ``stderr``) and its time (``seconds``)."""
    import io
    import json
    import time

    from fenicsfriction.cli import main
    from fenicsfriction.petsc_options import options_inserted

    out, err = io.StringIO(), io.StringIO()
    text = " ".join(f"-{name} {value}" for name, value in (options or {}).items())
    t0 = time.perf_counter()
    with options_inserted(text), contextlib.redirect_stdout(out), \
            contextlib.redirect_stderr(err):
        code = main(argv)
    seconds = time.perf_counter() - t0
    folder = pathlib.Path(argv[argv.index("--out") + 1])
    data = json.loads((folder / summary).read_text())
    rows = None
    if (folder / "timeseries.csv").exists():
        with open(folder / "timeseries.csv") as table:
            rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(table)]
    return {"code": code, "json": data, "rows": rows, "stdout": out.getvalue().splitlines(),
            "stderr": err.getvalue().splitlines(), "seconds": seconds}
