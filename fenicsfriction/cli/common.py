"""What every command shares: one-line argument errors, the output folder, records written as
they are computed, and a clean stop on SIGINT/SIGTERM.

Stopping under MPI. A signal handler only sets a flag; each command calls
:meth:`StopSignals.check` at the end of every step (a time step, a continuation step, an output
sample), where the ranks agree on the flag with one ``allreduce`` and all raise
:class:`Interrupted` at the same step. No rank leaves a collective call (a PETSc solve, an
assembly) half-way, so nothing hangs; ``mpirun`` forwards SIGINT/SIGTERM to every rank, and a
rank that has not seen it yet learns of it through the reduction. The command then closes its
files, writes the summary of the steps done and exits with 128 + the signal number (130 for
SIGINT, 143 for SIGTERM). A second signal while the first is pending raises
``KeyboardInterrupt`` at once, for a run stuck inside one step.
"""

from __future__ import annotations

import argparse
import csv
import pathlib
import signal
import types
import typing

from mpi4py import MPI

__all__ = ["CsvRows", "Interrupted", "Parser", "StopSignals", "floats", "omega_range",
           "output_folder"]


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors (no usage block) and exit status 2."""

    def error(self, message: str) -> typing.NoReturn:
        self.exit(2, f"{self.prog}: error: {message}\n")


def floats(text: str) -> list[float]:
    """``"1e-2,1e-3"`` -> ``[0.01, 0.001]``."""
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated numbers, got {text!r}") from None


def omega_range(text: str) -> tuple[float, float]:
    """``"30:31"`` -> ``(30.0, 31.0)``."""
    try:
        lo, hi = (float(v) for v in text.split(":"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected LO:HI, got {text!r}") from None
    return lo, hi


def output_folder(path: pathlib.Path, comm: MPI.Comm = MPI.COMM_WORLD) -> pathlib.Path:
    """Make ``path`` on rank 0 and check that a file can be written in it, before any work.

    Raises:
        ValueError: ``--out=PATH is invalid: ...`` on every rank, naming the reason.
    """
    problem = None
    if comm.rank == 0:
        try:
            path.mkdir(parents=True, exist_ok=True)
            probe = path / ".write-test"
            probe.write_text("")
            probe.unlink()
        except OSError as err:
            problem = f"cannot write there ({err.strerror or err})"
    problem = comm.bcast(problem, root=0)
    if problem is not None:
        raise ValueError(f"--out={str(path)!r} is invalid: {problem}")
    return path


class Interrupted(Exception):
    """A run stopped by a signal; ``signum`` is the signal, ``where`` the last step done."""

    def __init__(self, signum: int, where: str):
        self.signum, self.where = signum, where
        super().__init__(f"interrupted by {signal.Signals(signum).name} after {where}")

    @property
    def exit_code(self) -> int:
        """128 + the signal number, as a shell reports a process the signal ended."""
        return 128 + self.signum


class StopSignals:
    """Turns SIGINT and SIGTERM into a flag that :meth:`check` raises on all ranks together.

    Use as a context manager around a run; the previous handlers are restored on exit.
    """

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self, comm: MPI.Comm = MPI.COMM_WORLD):
        self.comm = comm
        self.received = 0
        self._previous: dict[int, typing.Any] = {}

    def _handler(self, signum: int, frame: types.FrameType | None) -> None:
        if self.received:  # a second signal: do not wait for the step to end
            raise KeyboardInterrupt
        self.received = signum

    def __enter__(self) -> StopSignals:
        for sig in self.SIGNALS:
            self._previous[sig] = signal.signal(sig, self._handler)
        return self

    def __exit__(self, *exc: object) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)

    def check(self, where: str) -> None:
        """Raise :class:`Interrupted` on every rank if any rank has received a signal.

        Args:
            where: the step just completed, for the message (e.g. ``"t = 0.01 s (step 1000)"``).
        """
        signum = self.comm.allreduce(self.received, op=MPI.MAX)
        if signum:
            raise Interrupted(signum, where)


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
