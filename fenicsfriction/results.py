"""How results leave the program: typed records with ``to_json``, JSON files and CSV tables
written on rank 0 (tables row by row, as they are computed), and the package logger (INFO on
rank 0 only).

Imports NumPy and mpi4py only, so the reduced models use it as the finite element ones do.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import logging
import os
import pathlib
import platform
import re
import sys
import typing

from mpi4py import MPI

import numpy as np

__all__ = ["CsvRows", "Record", "StderrHandler", "blas_library", "environment", "get_logger",
           "to_plain", "write_json", "write_summary"]


def to_plain(value: typing.Any) -> typing.Any:
    """``value`` as JSON-ready Python: records and dicts to dicts, arrays and tuples to lists,
    NumPy scalars to Python numbers, complex numbers to ``[re, im]``, non-finite floats to None."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: to_plain(getattr(value, f.name)) for f in dataclasses.fields(value)
                if f.repr}
    if isinstance(value, dict):
        return {str(k): to_plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return to_plain(value.tolist())
    if isinstance(value, np.generic):
        return to_plain(value.item())
    if isinstance(value, complex):
        return [to_plain(value.real), to_plain(value.imag)]
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value


class Record:
    """Mixin for the package's result dataclasses: ``to_json()`` gives plain JSON-ready data.

    Fields declared with ``repr=False`` (large arrays such as eigenvectors) are left out.
    """

    def to_json(self) -> dict[str, typing.Any]:
        """The record as a dict of JSON-ready values (see :func:`to_plain`)."""
        return to_plain(self)


class StderrHandler(logging.StreamHandler):
    """A handler writing to ``sys.stderr`` as it is when a record comes, not as it was when
    the handler was made (a test's captured stream is closed once the test ends)."""

    @property
    def stream(self) -> typing.Any:
        """The current ``sys.stderr``."""
        return sys.stderr

    @stream.setter
    def stream(self, value: typing.Any) -> None:
        pass


def get_logger(comm: MPI.Comm = MPI.COMM_WORLD) -> logging.Logger:
    """The package logger: INFO on rank 0, warnings only elsewhere."""
    logger = logging.getLogger("fenicsfriction")
    if not logger.handlers:
        handler = StderrHandler()
        handler.setFormatter(logging.Formatter("%(message)s"))
        logger.addHandler(handler)
        logger.propagate = False
    logger.setLevel(logging.INFO if comm.rank == 0 else logging.WARNING)
    return logger


def write_json(path: str | pathlib.Path, data: typing.Any,
               comm: MPI.Comm = MPI.COMM_WORLD) -> None:
    """Write ``data`` as JSON on rank 0 (NumPy scalars converted, non-finite floats -> null)."""
    if comm.rank == 0:
        path = pathlib.Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(to_plain(data), indent=1) + "\n")
    comm.Barrier()


_BLAS_PATTERN = re.compile(r"lib(openblas|blas|mkl_rt|mkl_core|blis|flexiblas|atlas)[^/]*\.so")


def blas_library() -> dict[str, typing.Any]:
    """The BLAS this process runs on, read from the shared objects it has mapped (Linux).

    ``name`` is ``"OpenBLAS"``, ``"reference"`` (Netlib's unoptimised BLAS, which makes
    MUMPS and dense eigensolvers 2-3x slower), ``"MKL"``, ``"BLIS"``, ... or ``"unknown"``;
    ``paths`` are the mapped libraries (symbolic links resolved by the kernel), so a slow
    machine can be diagnosed from any run's summary. On Debian, ``libopenblas0-serial``
    switches the ``libblas.so.3`` alternative to OpenBLAS by itself.
    """
    try:
        with open("/proc/self/maps") as maps:
            paths = sorted({line.split()[-1] for line in maps
                            if _BLAS_PATTERN.search(line.rsplit("/", 1)[-1])})
    except OSError:
        return {"name": "unknown", "optimized": None, "paths": []}
    joined = " ".join(paths).lower()
    for key, name in (("openblas", "OpenBLAS"), ("mkl", "MKL"), ("blis", "BLIS"),
                      ("flexiblas", "FlexiBLAS"), ("atlas", "ATLAS")):
        if key in joined:
            return {"name": name, "optimized": True, "paths": paths}
    if paths:
        return {"name": "reference", "optimized": False, "paths": paths}
    return {"name": "unknown", "optimized": None, "paths": paths}


def environment(comm: MPI.Comm = MPI.COMM_WORLD) -> dict[str, typing.Any]:
    """What a run ran on: ranks, BLAS, and the versions of Python, NumPy, PETSc, SLEPc and
    dolfinx (those already imported; nothing is imported here to find out)."""
    import sys

    versions: dict[str, str] = {"python": platform.python_version(), "numpy": np.__version__}
    if "petsc4py" in sys.modules:
        from petsc4py import PETSc
        versions["petsc"] = ".".join(map(str, PETSc.Sys.getVersion()))
    if "slepc4py" in sys.modules:
        from slepc4py import SLEPc
        versions["slepc"] = ".".join(map(str, SLEPc.Sys.getVersion()))
    if "dolfinx" in sys.modules:
        versions["dolfinx"] = sys.modules["dolfinx"].__version__
    return {"ranks": comm.size, "blas": blas_library(), "versions": versions,
            "machine": platform.machine(), "cpus": os.cpu_count()}


def write_summary(path: str | pathlib.Path, data: dict[str, typing.Any],
                  comm: MPI.Comm = MPI.COMM_WORLD) -> None:
    """:func:`write_json` of a run's summary, with the :func:`environment` it ran in added."""
    write_json(path, {**data, "environment": environment(comm)}, comm)


class CsvRows:
    """A CSV table written row by row on rank 0 and flushed after each row, so that whatever
    stops the run leaves every computed row on disk. The header is the first row's keys."""

    def __init__(self, path: pathlib.Path, comm: MPI.Comm = MPI.COMM_WORLD):
        self.path, self.comm = path, comm
        self._file: typing.TextIO | None = None
        self._writer: csv.DictWriter | None = None

    def write(self, row: dict[str, typing.Any]) -> None:
        """Append ``row`` (same keys as the first row)."""
        if self.comm.rank != 0:
            return
        if self._writer is None:
            self._file = open(self.path, "w", newline="")  # noqa: SIM115 (closed in close())
            self._writer = csv.DictWriter(self._file, fieldnames=list(row))
            self._writer.writeheader()
        self._writer.writerow(row)
        assert self._file is not None
        self._file.flush()

    def close(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None

    def __enter__(self) -> CsvRows:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
