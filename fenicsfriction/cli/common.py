"""What every command shares: one-line argument errors and the output folder.

Records are written as they are computed (:class:`fenicsfriction.results.CsvRows`) and a signal
stops a run at the next step (:mod:`fenicsfriction.signals`).
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import typing

from mpi4py import MPI

__all__ = ["Parser", "floats", "omega_range", "output_folder", "stop_line"]


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


def stop_line(message: str, comm: MPI.Comm = MPI.COMM_WORLD) -> None:
    """Print the one line that says where and why a run stopped, on rank 0's stderr.

    Every rank reaches it together (a signal is agreed on over the ranks, a solver failure is
    collective), and one rank says it, so the user sees one line whatever the rank count.

    Args:
        message: what to say, after ``fenicsfriction: ``.
        comm: the run's communicator.
    """
    if comm.rank == 0:
        print(f"fenicsfriction: {message}", file=sys.stderr, flush=True)
