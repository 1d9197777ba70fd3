"""Stopping a long run cleanly on SIGINT/SIGTERM, under MPI too.

A signal handler only sets a flag; the run calls :meth:`StopSignals.check` at the end of every
step (a time step, a continuation step, an output sample), where the ranks of its communicator
agree on the flag with one ``allreduce`` and all raise :class:`Interrupted` at the same step. No
rank leaves a collective call (a PETSc solve, an assembly) half-way, so nothing hangs;
``mpirun`` forwards SIGINT/SIGTERM to every rank, and a rank that has not seen it yet learns of
it through the reduction. Runs that share nothing (e.g. one task per rank on ``COMM_SELF``)
each check their own communicator. The caller then closes its files, writes what it has and
exits with :attr:`Interrupted.exit_code` (130 for SIGINT, 143 for SIGTERM). A second signal
while the first is pending raises ``KeyboardInterrupt`` at once, for a run stuck in one step.
"""

from __future__ import annotations

import signal
import types
import typing

from mpi4py import MPI

__all__ = ["Interrupted", "StopSignals"]


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
