"""Stopping a long run cleanly on SIGINT/SIGTERM, under MPI too, from the first line of a
command to its last.

A signal handler only sets a flag; the run calls :meth:`StopSignals.check` at the end of every
step (a time step, a continuation step, an output sample), where the ranks of its communicator
agree on the flag with one ``allreduce`` and all raise :class:`Interrupted` at the same step. No
rank leaves a collective call (a PETSc solve, an assembly) half-way, so nothing hangs;
``mpirun`` forwards SIGINT/SIGTERM to every rank, and a rank that has not seen it yet learns of
it through the reduction. Runs that share nothing (e.g. one task per rank on ``COMM_SELF``)
each check their own communicator. The caller then closes its files, writes what it has and
exits with :attr:`Interrupted.exit_code` (130 for SIGINT, 143 for SIGTERM). A second signal
while the first is pending raises ``KeyboardInterrupt`` at once, for a run stuck in one step.

The flag belongs to the process, not to one :class:`StopSignals`: the command line installs
the handler first thing (:func:`catch`, before MPI, PETSc or dolfinx are imported). Until the
run's first :class:`StopSignals` opens (the set-up: imports, mesh, just-in-time compilation,
the first steady state; or the whole of a command that has no steps to stop at) the handler
raises at once (:func:`raise_at_once`, serial runs), naming the last stage the
set-up passed (:func:`checkpoint`); from then on it only sets the flag. A signal that comes
before ``main`` (``python -m fenicsfriction``'s own imports) is pending, and raised at the
first :func:`checkpoint`. This module imports mpi4py only when a check needs it.
"""

from __future__ import annotations

import signal
import types
import typing

if typing.TYPE_CHECKING:
    from mpi4py import MPI

__all__ = ["Interrupted", "SetUpInterrupt", "StopSignals", "catch", "checkpoint",
           "interruption", "pending", "pending_on", "raise_at_once", "release"]

#: SIGINT and SIGTERM, the signals turned into a flag
SIGNALS = (signal.SIGINT, signal.SIGTERM)

#: the first signal received and not yet handled (0: none); one per process
_received = [0]
#: raise at once (the set-up) rather than set the flag (a run with steps to stop at)
_immediate = [False]
#: the last stage of the set-up passed (:func:`checkpoint`), for the message
_stage = ["the start"]


class Interrupted(Exception):
    """A run stopped by a signal; ``signum`` is the signal, ``where`` the last step done."""

    def __init__(self, signum: int, where: str):
        self.signum, self.where = signum, where
        super().__init__(f"interrupted by {signal.Signals(signum).name} after {where}")

    @property
    def exit_code(self) -> int:
        """128 + the signal number, as a shell reports a process the signal ended."""
        return 128 + self.signum


class SetUpInterrupt(BaseException):
    """What the handler raises during the set-up (:func:`raise_at_once`): a ``BaseException``,
    like ``KeyboardInterrupt``, so that no ``except Exception`` on the way (a mesh generator's
    error report, a solver's) turns it into a failure; ``interrupted`` is the
    :class:`Interrupted` to report."""

    def __init__(self, interrupted: Interrupted):
        super().__init__(str(interrupted))
        self.interrupted = interrupted


def interruption(error: BaseException | None) -> Interrupted | None:
    """The :class:`Interrupted` that ``error`` is, wraps or was raised from (a PETSc error
    whose callback was interrupted, an import interrupted in its initialisation), or None."""
    seen: set[int] = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, Interrupted):
            return error
        if isinstance(error, SetUpInterrupt):
            return error.interrupted
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return None


def _handler(signum: int, frame: types.FrameType | None) -> None:
    if _received[0]:  # a second signal: do not wait for the step to end
        raise KeyboardInterrupt
    if _immediate[0]:
        raise SetUpInterrupt(Interrupted(signum, _stage[0]))
    _received[0] = signum


def catch() -> dict[int, typing.Any]:
    """Turn SIGINT and SIGTERM into the process's pending flag from now on.

    Returns:
        The handlers in place before, for :func:`release`.
    """
    return {sig: signal.signal(sig, _handler) for sig in SIGNALS}


def raise_at_once(comm: MPI.Comm | None = None) -> None:
    """From now until a :class:`StopSignals` opens, a signal raises :class:`SetUpInterrupt` in
    the handler (the set-up of a command, whose stages need not check).

    Serial runs only: under MPI a rank interrupted outside a collective call would leave the
    others waiting in it, so there the signal stays a flag, agreed on at the next
    :func:`checkpoint` or step.
    """
    if comm is None:
        from mpi4py import MPI
        comm = MPI.COMM_WORLD
    _immediate[0] = comm.size == 1


def release(previous: dict[int, typing.Any]) -> None:
    """Put back the handlers :func:`catch` replaced, and forget a pending signal."""
    for sig, handler in previous.items():
        signal.signal(sig, handler)
    _received[0] = 0
    _immediate[0] = False
    _stage[0] = "the start"


def pending() -> int:
    """The signal received and not handled yet on this process (0: none)."""
    return _received[0]


def pending_on(comm: MPI.Comm | None = None) -> int:
    """The largest signal pending over the ranks of ``comm`` (0: none), now handled on every
    rank (collective)."""
    signum = _agreed(comm)
    _received[0] = 0
    return signum


def _agreed(comm: MPI.Comm | None) -> int:
    """The largest pending signal over the ranks of ``comm`` (collective)."""
    if comm is None:
        from mpi4py import MPI
        comm = MPI.COMM_WORLD
    from mpi4py import MPI
    return int(comm.allreduce(_received[0], op=MPI.MAX))


def checkpoint(where: str, comm: MPI.Comm | None = None) -> None:
    """Raise :class:`Interrupted` on every rank of ``comm`` if any has a pending signal, which
    is then handled (no longer pending).

    Collective: every rank calls it at the same point of the set-up.

    Args:
        where: the stage just completed, e.g. ``"set-up (model built)"``.
        comm: the run's communicator (default ``COMM_WORLD``).
    """
    signum = _agreed(comm)
    if signum:
        _received[0] = 0  # handled: the caller reports it; a later signal starts afresh
        raise Interrupted(signum, where)
    _stage[0] = where


class StopSignals:
    """Turns SIGINT and SIGTERM into a flag that :meth:`check` raises on all ranks together.

    Use as a context manager around a run; the previous handlers are restored on exit. A
    signal already pending when it opens (received during the set-up) is raised at the first
    :meth:`check`.
    """

    SIGNALS = SIGNALS

    def __init__(self, comm: MPI.Comm | None = None):
        if comm is None:
            from mpi4py import MPI
            comm = MPI.COMM_WORLD
        self.comm = comm
        self._previous: dict[int, typing.Any] = {}

    @property
    def received(self) -> int:
        """The signal pending on this process (0: none)."""
        return _received[0]

    @received.setter
    def received(self, signum: int) -> None:
        _received[0] = signum

    def __enter__(self) -> StopSignals:
        self._previous = catch()
        _immediate[0] = False  # the run's steps have begun: a signal waits for a check
        return self

    def __exit__(self, *exc: object) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)

    def check(self, where: str) -> None:
        """Raise :class:`Interrupted` on every rank if any rank has received a signal.

        Args:
            where: the step just completed, for the message (e.g. ``"t = 0.01 s (step 1000)"``).
        """
        checkpoint(where, self.comm)
