"""A parameter sweep of complex eigenvalue analyses: eigenvalues at each value, modes tracked
from value to value, the intervals where they grow and where two of them coalesce.

Mode-coupling (flutter) instability is two modes whose frequencies approach and merge as the
parameter (the friction coefficient) grows, one of the pair then growing (Re λ > 0) and the
other decaying (Hoffmann et al. 2002). :class:`Sweep` calls a solver (full, projected, or the
finite element model's) at each value, tracks the modes with
:func:`fenicsfriction.stability.track` (MAC of the eigenvectors), and finds in its records each
interval where a mode starts to grow, with its partner — the mode nearest to it in frequency
just before — and how far apart their frequencies were on both sides; :meth:`Sweep.refine`
bisects the interval to a tolerance.
"""

from __future__ import annotations

import dataclasses
import math
import typing

from mpi4py import MPI

from fenicsfriction.laws import check
from fenicsfriction.numerics import bisect
from fenicsfriction.results import Record
from fenicsfriction.stability import Mode, is_unstable, track

__all__ = ["Coalescence", "Sweep", "unstable_intervals"]


@dataclasses.dataclass
class Coalescence(Record):
    """Where a tracked mode starts to grow, and the mode it coupled with.

    Attributes:
        growing: the id of the mode that grows past the onset.
        modes: the ids of the two modes nearest its frequency at the stable end (the pair that
            coalesces).
        interval: the sweep's values [stable, unstable] around the onset.
        onset: the bisected bracket [stable, unstable] (:meth:`Sweep.refine`), else the interval.
        p_crit: the midpoint of ``onset``.
        value: the growing eigenvalue [re, im] at the unstable end [1/s].
        frequency: its frequency Im λ / 2π [Hz].
        frequencies: the pair's frequencies [Hz] at the stable end.
        gap: relative frequency gaps |f_a - f_b| / mean(f): of the pair at the stable end, and
            of the growing mode and the mode nearest it at the unstable end (0 past the merging
            of two undamped modes; damping keeps them apart).
    """

    growing: int
    modes: list[int]
    interval: list[float]
    onset: list[float]
    p_crit: float
    value: list[float]
    frequency: float
    frequencies: list[float]
    gap: list[float]


def _row(mode: Mode) -> dict[str, typing.Any]:
    return {"mode": mode.ident, "re": mode.value.real, "im": mode.value.imag,
            "frequency": mode.value.imag / (2 * math.pi), "residual": mode.residual,
            "accurate": mode.accurate}


def _gap(a: float, b: float) -> float:
    mean = 0.5 * (abs(a) + abs(b))
    return abs(a - b) / mean if mean > 0 else 0.0


class Sweep:
    """Eigenvalues along a parameter, modes tracked by MAC.

    Args:
        solve_at: the modes (Im λ >= 0, vectors distributed as :attr:`Mode.vector`) at a value.
        comm: the communicator of the eigenvectors.
        growth_tol: a mode grows when Re λ > growth_tol |λ|.

    Attributes:
        records: one dict per value: ``p``, ``modes`` (``mode`` id, ``re``, ``im``,
            ``frequency`` [Hz], ``residual``, ``accurate``), ``max_re``.
        modes: the tracked modes at each value, in the order of ``records``.
    """

    def __init__(self, solve_at: typing.Callable[[float], list[Mode]],
                 comm: MPI.Comm = MPI.COMM_WORLD, growth_tol: float = 1e-6):
        check("growth_tol", growth_tol, growth_tol > 0, "must be > 0")
        self.solve_at, self.comm, self.growth_tol = solve_at, comm, growth_tol
        self.records: list[dict[str, typing.Any]] = []
        self.modes: list[list[Mode]] = []
        self._next = 0

    def follow(self, values: typing.Iterable[float],
               on_step: typing.Callable[[dict, list[Mode]], None] | None = None
               ) -> list[dict[str, typing.Any]]:
        """Solve at each value (continuing any previous call) and return the new records;
        ``on_step(record, modes)`` sees each."""
        new = []
        for value in values:
            modes = self.solve_at(value)
            self._next = track(self.modes[-1] if self.modes else [], modes, self.comm,
                               self._next)
            record = {"p": float(value), "modes": [_row(m) for m in modes],
                      "max_re": max((m.value.real for m in modes), default=float("nan"))}
            self.records.append(record)
            self.modes.append(modes)
            new.append(record)
            if on_step is not None:
                on_step(record, modes)
        return new

    def unstable(self, modes: list[Mode]) -> list[Mode]:
        """The growing modes among ``modes``."""
        return [m for m in modes if is_unstable(m, self.growth_tol)]

    def coalescences(self) -> list[Coalescence]:
        """Each step of the records where a tracked mode starts to grow, with the pair of modes
        nearest its frequency just before (the tracking is not relied on there: at a
        coalescence the two eigenvectors merge and MAC cannot tell them apart)."""
        events = []
        for i in range(len(self.modes) - 1):
            before, after = self.modes[i], self.modes[i + 1]
            grown = {m.ident for m in self.unstable(before)}
            for mode in self.unstable(after):
                if mode.ident in grown or len(before) < 2:
                    continue
                f = mode.value.imag
                pair = sorted(before, key=lambda m: abs(m.value.imag - f))[:2]
                twins = [m.value.imag for m in after if m is not mode]
                twin = min(twins, key=lambda g: abs(g - f)) if twins else math.nan
                interval = [self.records[i]["p"], self.records[i + 1]["p"]]
                events.append(Coalescence(
                    growing=mode.ident, modes=[m.ident for m in pair], interval=interval,
                    onset=list(interval), p_crit=0.5 * sum(interval),
                    value=[mode.value.real, f], frequency=f / (2 * math.pi),
                    frequencies=[m.value.imag / (2 * math.pi) for m in pair],
                    gap=[_gap(pair[0].value.imag, pair[1].value.imag), _gap(f, twin)]))
        return events

    def refine(self, event: Coalescence, tol: float) -> Coalescence:
        """``event`` with its onset bisected to width ``tol``: the parameter where the number
        of growing modes first exceeds its count at the stable end (tracking is not needed
        inside the interval, so each step is one solve)."""
        stable, unstable = event.interval
        count = len(self.unstable(self.solve_at(stable)))
        low, high = bisect(lambda p: len(self.unstable(self.solve_at(p))) > count,
                           stable, unstable, tol)
        grow = max(self.unstable(self.solve_at(high)), key=lambda m: m.value.real)
        return dataclasses.replace(event, onset=[low, high], p_crit=0.5 * (low + high),
                                   value=[grow.value.real, grow.value.imag],
                                   frequency=grow.value.imag / (2 * math.pi))


def unstable_intervals(records: list[dict], growth_tol: float = 1e-6) -> dict[int, list]:
    """The sweep's intervals [first, last] of values in which each tracked mode grows."""
    from fenicsfriction.stability import unstable_intervals as intervals

    return intervals([{**r, "mu": r["p"]} for r in records], growth_tol)
