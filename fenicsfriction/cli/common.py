"""What every command shares once it runs: the output folder and the one line that ends a run.

Records are written as they are computed (:class:`fenicsfriction.results.CsvRows`) and a signal
stops a run at the next step (:mod:`fenicsfriction.signals`).
"""

from __future__ import annotations

import argparse
import dataclasses
import pathlib
import sys
import typing

from mpi4py import MPI

__all__ = ["flag", "named_by_flag", "output_folder", "scene_from_flags", "stop_line",
           "stopped", "write_rows"]


def flag(name: str) -> str:
    """The command-line flag of a field: ``slab_E`` -> ``--slab-E``."""
    return "--" + name.replace("_", "-")


def named_by_flag(message: str, renamed: dict[str, str] | None = None) -> str:
    """A model's ``name=value is invalid: ...`` with ``name`` replaced by its flag
    (``renamed[name]`` when the flag is not ``--name``)."""
    name = message.split("=", 1)[0]
    if not name.isidentifier():
        return message
    return (renamed or {}).get(name, flag(name)) + message[len(name):]


def scene_from_flags(cls: type, args: argparse.Namespace, **fixed: typing.Any) -> typing.Any:
    """The scene dataclass ``cls`` from the flags that name its fields (unset flags keep its
    defaults), with ``fixed`` fields set by the command."""
    fields = {f.name for f in dataclasses.fields(cls)}
    given = {k: v for k, v in vars(args).items() if v is not None}
    law_changes: dict[str, typing.Any] = {}
    if "law" in fields:  # the interface law's flags (--mu, --eps, ...) change the scene's law
        from fenicsfriction.laws import InterfaceLaw
        law_names = {f.name for f in dataclasses.fields(InterfaceLaw)}
        law_changes = {k: v for k, v in {**given, **fixed}.items() if k in law_names}
        fixed = {k: v for k, v in fixed.items() if k not in law_names}
    names = fields - set(fixed)
    scene = cls(**fixed, **{k: v for k, v in given.items() if k in names})
    return scene.with_law(**law_changes) if law_changes else scene


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


def write_rows(path: pathlib.Path, rows: typing.Iterable[dict],
               comm: MPI.Comm = MPI.COMM_WORLD) -> None:
    """A CSV table of ``rows`` (dicts with the same keys), written on rank 0; collective, every
    rank returns once it is written."""
    from fenicsfriction.results import CsvRows

    with CsvRows(path, comm) as table:
        for row in rows:
            table.write(row)
    comm.Barrier()


def stopped(failure: str | None, interrupted: typing.Any = None) -> int:
    """The exit status of a run, after its one closing line if it did not finish.

    Args:
        failure: what failed (a solver's summary), or None.
        interrupted: the :class:`~fenicsfriction.signals.Interrupted` that stopped the run, or
            None.

    Returns:
        The signal's status (130/143) after an interruption, 1 after a failure, else 0.
    """
    if interrupted is not None:
        stop_line(f"{interrupted}; the results so far are written")
        return int(interrupted.exit_code)
    if failure is not None:
        stop_line(failure)
        return 1
    return 0
