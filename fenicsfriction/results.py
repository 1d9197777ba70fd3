"""How results leave the program: typed records with ``to_json``, JSON files and CSV tables
written on rank 0 (tables row by row, as they are computed), and the package logger (INFO on
rank 0 only).

Imports NumPy and mpi4py only, so the reduced models use it as the finite element ones do.
"""

from __future__ import annotations

import collections
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

__all__ = ["CsvRows", "Record", "RunningStatistics", "SampledRecords", "StderrHandler",
           "StdoutHandler", "blas_library", "environment", "get_logger", "quiet_jit", "to_plain",
           "write_json", "write_summary"]


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


class StdoutHandler(logging.StreamHandler):
    """The package logger's progress handler: the records below WARNING (warnings and errors
    go to stderr), to the current ``sys.stdout`` or ``sys.stderr`` as :func:`get_logger` last
    chose (``progress``)."""

    #: "stdout" or "stderr"
    target = "stderr"

    def __init__(self) -> None:
        super().__init__()
        self.addFilter(lambda record: record.levelno < logging.WARNING)

    @property
    def stream(self) -> typing.Any:
        """The current ``sys.stdout`` or ``sys.stderr``."""
        return sys.stdout if StdoutHandler.target == "stdout" else sys.stderr

    @stream.setter
    def stream(self, value: typing.Any) -> None:
        pass


#: the root logger's handler that passes warnings and errors only (see :func:`quiet_jit`)
_ROOT_WARNINGS: list[logging.Handler] = []


def quiet_jit() -> None:
    """Keep the just-in-time compiler's build lines (``INFO:root:running build_ext``, one
    ``gcc`` line per form, on every rank) off the terminal, and its warnings on it.

    FFCx compiles each new form through cffi and setuptools, which lowers the root logger's
    level to INFO and logs its build steps there; importing FFCx (0.5) calls
    ``logging.basicConfig()``, which gives the root logger a handler passing every level, so
    each step is printed, on every rank. Here the FFCx and UFL loggers are set to WARNING; if
    the root logger has no handler (nobody configured logging) it gets one that passes
    warnings and errors to stderr, what Python prints anyway when no handler is configured;
    and a handler that ``basicConfig()`` made with its defaults (a stream, every level, the
    ``LEVEL:name:message`` format) is raised to WARNING. Other handlers (a configuration of
    the user's own) are left alone.
    """
    logging.getLogger("ffcx").setLevel(logging.WARNING)
    logging.getLogger("UFL").setLevel(logging.WARNING)
    root = logging.getLogger()
    if not _ROOT_WARNINGS:
        warnings_only = StderrHandler()
        warnings_only.setLevel(logging.WARNING)
        warnings_only.setFormatter(logging.Formatter(logging.BASIC_FORMAT))
        _ROOT_WARNINGS.append(warnings_only)
    if not root.handlers:
        root.addHandler(_ROOT_WARNINGS[0])
    for handler in root.handlers:
        formatter = handler.formatter
        if (type(handler) is logging.StreamHandler and handler.level == logging.NOTSET
                and formatter is not None and formatter._fmt == logging.BASIC_FORMAT):
            handler.setLevel(logging.WARNING)


def get_logger(comm: MPI.Comm = MPI.COMM_WORLD, progress: str | None = None) -> logging.Logger:
    """The package logger: INFO on rank 0, warnings only elsewhere. Also keeps the JIT
    compiler's build lines quiet (:func:`quiet_jit`).

    Args:
        comm: the ranks; rank 0 reports progress.
        progress: where the INFO records go, ``"stdout"`` (the command line: progress on
            stdout, the one closing line on stderr) or ``"stderr"`` (the default, for scripts
            that print their results to stdout); None keeps the last choice. Warnings and
            errors go to stderr.
    """
    if progress is not None:
        if progress not in ("stdout", "stderr"):
            raise ValueError(f"progress={progress!r} is invalid: use 'stdout' or 'stderr'")
        StdoutHandler.target = progress
    quiet_jit()
    logger = logging.getLogger("fenicsfriction")
    if not logger.handlers:
        to_stdout = StdoutHandler()
        to_stdout.setFormatter(logging.Formatter("%(message)s"))
        warnings = StderrHandler()
        warnings.setLevel(logging.WARNING)
        warnings.setFormatter(logging.Formatter("%(message)s"))
        logger.addHandler(to_stdout)
        logger.addHandler(warnings)
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


class RunningStatistics:
    r"""Minimum, maximum, largest magnitude and time mean of every number in a stream of
    records, in memory independent of their count: a long run's statistics without its rows.

    The time mean of a field :math:`x` sampled at :math:`t_0 < t_1 < \dots < t_n` is the
    trapezoidal rule :math:`\frac{1}{t_n - t_0}\sum_k \tfrac12 (x_{k-1} + x_k)(t_k - t_{k-1})`,
    the same as :func:`fenicsfriction.statistics.stick_slip_statistics` applies to the rows it
    is given, so the two agree on the same rows. Only records with ``time >= t_from`` count;
    integer counters (``newton_iterations``, ``rejected_steps``) are summed instead (``total``).

    Args:
        t_from: the start of the window.
    """

    #: fields that count events in a step: summed, not averaged
    COUNTERS = ("newton_iterations", "rejected_steps")

    def __init__(self, t_from: float = 0.0):
        self.t_from = t_from
        self.count = 0
        self.t_first: float | None = None
        self.t_last: float | None = None
        self._fields: dict[str, list[float]] = {}  # min, max, max |x|, ∫x dt, last x
        self.totals: dict[str, int] = dict.fromkeys(self.COUNTERS, 0)

    def add(self, record: dict[str, typing.Any]) -> None:
        """Account for one record (needs ``time``; non-numeric fields are skipped)."""
        t = float(record["time"])
        if t < self.t_from:
            return
        dt = 0.0 if self.t_last is None else t - self.t_last
        for key, value in record.items():
            if key in self.COUNTERS:
                self.totals[key] += int(value)
                continue
            if key == "time" or isinstance(value, bool) or not isinstance(value, (int, float)):
                continue
            x = float(value)
            field = self._fields.get(key)
            if field is None:
                self._fields[key] = [x, x, abs(x), 0.0, x]
                continue
            field[0], field[1], field[2] = min(field[0], x), max(field[1], x), max(field[2], abs(x))
            field[3] += 0.5 * (field[4] + x) * dt
            field[4] = x
        if self.t_first is None:
            self.t_first = t
        self.t_last = t
        self.count += 1

    def mean(self, key: str) -> float:
        """The time mean of ``key`` over the window (its value if only one record)."""
        field = self._fields[key]
        assert self.t_first is not None and self.t_last is not None
        span = self.t_last - self.t_first
        return field[3] / span if span > 0 else field[4]

    def __getitem__(self, key: str) -> dict[str, float]:
        """``min``, ``max``, ``max_abs`` and ``mean`` of ``key``."""
        low, high, largest = self._fields[key][:3]
        return {"min": low, "max": high, "max_abs": largest, "mean": self.mean(key)}

    def __contains__(self, key: str) -> bool:
        return key in self._fields

    def to_json(self) -> dict[str, typing.Any]:
        """The window, the number of records and the statistics of every field."""
        return to_plain({"t_from": self.t_first, "t_to": self.t_last, "records": self.count,
                         "totals": self.totals,
                         "fields": {key: self[key] for key in self._fields}})


class SampledRecords:
    """A bounded sample of a stream of records, for figures and statistics of a long run: every
    ``stride``-th record (the stride doubles, dropping every other record kept, whenever
    ``capacity`` is reached) and the last ``tail`` records in full.

    Args:
        capacity: the most records of the uniform sample (>= 2).
        tail: how many of the last records are kept in full.
    """

    def __init__(self, capacity: int = 4000, tail: int = 2000):
        for name, value, low in (("capacity", capacity, 2), ("tail", tail, 0)):
            if value < low:
                raise ValueError(f"{name}={value!r} is invalid: must be >= {low}")
        self.capacity, self.stride, self.seen = capacity, 1, 0
        self._sample: list[dict] = []
        self._tail: collections.deque = collections.deque(maxlen=tail)

    def add(self, record: dict) -> None:
        """Offer the next record of the stream."""
        if self.seen % self.stride == 0:
            self._sample.append(record)
            if len(self._sample) >= self.capacity:
                self._sample = self._sample[::2]
                self.stride *= 2
        if self._tail.maxlen:
            self._tail.append(record)
        self.seen += 1

    def records(self) -> list[dict]:
        """The sample and the tail, in stream order, each record once."""
        if not self._tail:
            return list(self._sample)
        start = self._tail[0]["time"]
        return [r for r in self._sample if r["time"] < start] + list(self._tail)
