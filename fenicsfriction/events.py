r"""Event-located integration of piecewise-smooth ODEs (stick/slip) with PETSc TS.

A :class:`HybridSystem` is a first-order ODE :math:`\dot y = f_m(t, y)` whose right-hand side
depends on a discrete *mode* :math:`m` (any hashable value the system defines, e.g. a tuple of
``"slip+"``, ``"slip-"``, ``"stick"``, one per contact). Each mode comes with event functions
:math:`g_k(t, y; m)`; by convention **every** :math:`g_k \ge 0` while the mode holds, and a
:math:`g_k` crossing zero ends it. :func:`integrate_hybrid` then

1. integrates a smooth segment with PETSc TS (adaptive explicit Runge-Kutta, Dormand-Prince
   ``rk``/``5dp`` by default), whose event handler (``TSSetEventHandler``, terminating) locates
   the crossing to the event tolerance, so that the TS stops *at* the event time;
2. asks the system for the state and mode after the event, ``system.switch(t, y, m, fired)``;
3. restarts a new TS from there, until ``t_end``.

The switch is responsible for picking a consistent mode: one whose event functions are >= 0 at
the switch and stay so.

The event tolerance (``ts_event_tol``: |g| below it counts as zero) cannot be met once it is
below what the time resolution allows, |dg/dt| × ulp(t): late in a long run, or where g is
steep. PETSc 3.18 then retries the location without end (or accepts a time whose |g| exceeds
the tolerance). The driver watches for both: a location that makes no progress is resumed from
the last accepted step with the tolerance raised ×100 (up to ``_MAX_EVENT_TOL``; each such
relaxation is counted in ``HybridResult.relaxed_locations``), and the mode entered after an
event is checked against the tolerance its location actually achieved. An event function
that starts at zero and stays within the tolerance while moving away from it (a tangential
departure, as stick -> slip with μ(0) = μ_s) is not taken for an event.

Two failures are caught and reported (:class:`HybridError`, naming the time and the mode)
instead of looping: a mode that starts with some :math:`g_k < 0` or whose
:math:`g_k` starting at zero turns negative at once, and a mode entered twice at the same
instant (events re-firing without time advancing: an inconsistent switch or Zeno chattering).
``max_events`` bounds the number of events in all.

PETSc objects live on ``MPI.COMM_SELF``: every rank integrates the same small system. Options
are read under the prefix (default ``hybrid_``), e.g. ``-hybrid_ts_rk_type 3bs`` or
``-hybrid_ts_event_tol 1e-10``; a TS type without an interpolation formula cannot be used with
``sample_dt`` (samples are read from the Runge-Kutta dense output, ``TSInterpolate``).
"""

from __future__ import annotations

import dataclasses
import typing

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np

from fenicsfriction.laws import check
from fenicsfriction.petsc_options import callback_error, options_with_defaults
from fenicsfriction.results import Record
from fenicsfriction.timestepping import DynamicsError

__all__ = ["DEFAULT_OPTIONS", "HybridError", "HybridEvent", "HybridResult", "HybridSystem",
           "Observer", "integrate_hybrid"]

#: PETSc options of the hybrid integration (adaptive Dormand-Prince RK5(4), events located to
#: ``ts_event_tol``), under the prefix; options in the database win.
DEFAULT_OPTIONS = {
    "ts_type": "rk",
    "ts_rk_type": "5dp",
    "ts_adapt_type": "basic",
    "ts_exact_final_time": "matchstep",
    "ts_max_reject": 20,
    "ts_max_steps": 10**6,  # per segment: a run that would take longer stops with HybridError
    # |g| below this counts as zero; it is also the relative time tolerance of the location
    "ts_event_tol": 1e-12,
}

# Right-hand sides evaluated without an accepted step after which a location counts as stalled:
# PETSc 3.18 retries an event location until |g| <= tol, with no limit, so a tolerance below
# what the time resolution allows (|dg/dt| × ulp(t)) would loop forever
_MAX_LOCATION_TRIES = 1000

# A stalled location is resumed with the event tolerance ×_RELAX, up to this; beyond, it fails
_RELAX = 100.0
_MAX_EVENT_TOL = 1e-6

# First-step refinements of one segment (each 16x smaller, when an event function starting at
# zero left it and came back within the first step) before the segment is reported as failed;
# without a bound a Zeno accumulation loops here for ever under PETSc 3.22's event location
_MAX_FIRST_STEP_RETRIES = 8

# Segments in a row that PETSc ends at an event still within the tolerance of its starting zero
_MAX_SPURIOUS = 100

# Events this close in time (relative to t_end) happen "at the same instant" for the guard
# against a mode re-entered without the time advancing.
_SAME_INSTANT = 1e-9


class HybridSystem(typing.Protocol):
    """A piecewise-smooth first-order system ``dy/dt = rhs(t, y, mode)``."""

    @property
    def size(self) -> int:
        """The size of the state y."""

    def rhs(self, t: float, y: np.ndarray, mode: typing.Any) -> np.ndarray:
        """dy/dt in ``mode``."""

    def events(self, t: float, y: np.ndarray, mode: typing.Any) -> np.ndarray:
        """Event functions g_k (floats; their number may depend on the mode): all >= 0 while
        ``mode`` holds; a sign change of any g_k ends the smooth segment."""

    def switch(self, t: float, y: np.ndarray, mode: typing.Any,
               fired: list[int]) -> tuple[np.ndarray, typing.Any]:
        """The state and the mode after the events ``fired`` (indices into ``events``) at t."""


#: ``observe(t, y, mode) -> dict``: what to record beside the state at each recorded time
Observer = typing.Callable[[float, np.ndarray, typing.Any], dict]


@dataclasses.dataclass(frozen=True)
class HybridEvent(Record):
    """One located event: at time ``t`` the events ``fired`` of ``mode_before`` crossed zero;
    the switch mapped the state ``y_before`` to ``y_after`` in ``mode_after``."""

    t: float
    fired: tuple[int, ...]
    mode_before: typing.Hashable
    mode_after: typing.Hashable
    y_before: np.ndarray
    y_after: np.ndarray


@dataclasses.dataclass
class HybridResult(Record):
    """History of a run of :func:`integrate_hybrid`.

    Attributes:
        t: recorded times (non-decreasing): t = 0, every accepted step (or, with ``sample_dt``,
            every multiple of it), each event twice (before and after the switch), t_end.
        y: the states at those times, shape (len(t), size).
        modes: the mode at each recorded time.
        events: the located events, in order.
        observations: ``observe(t, y, mode)`` at each recorded time (empty without observe).
        steps: accepted TS steps, all segments together (event-location steps included).
        rejected_steps: steps rejected by the error control.
        rhs_evaluations: calls of ``system.rhs``.
        segments: smooth segments integrated (one more than the events, unless stopped, plus
            one per relaxed location).
        relaxed_locations: event locations that stalled at the event tolerance (below the time
            resolution there) and were completed with a larger one.
    """

    t: np.ndarray
    y: np.ndarray
    modes: list
    events: list[HybridEvent]
    observations: list[dict]
    steps: int
    rejected_steps: int
    rhs_evaluations: int
    segments: int
    relaxed_locations: int = 0


class HybridError(DynamicsError):
    """The hybrid integration stopped before t_end.

    Attributes:
        t, y, mode: the last good time, state and mode.
        result: the history up to there (``records`` holds its events).
    """

    def __init__(self, message: str, t: float, y: np.ndarray, mode: typing.Any,
                 result: HybridResult) -> None:
        super().__init__(message, result.events)
        self.t, self.y, self.mode, self.result = t, y, mode, result


class _Stop(Exception):
    """Raised in a callback to end TSSolve (the segment's ``failure`` says why)."""


class _History:
    """Recorded times, states, modes and observations, plus the run's counters."""

    def __init__(self, sample_dt: float | None, observe: Observer | None) -> None:
        self.sample_dt, self.observe = sample_dt, observe
        self.t: list[float] = []
        self.y: list[np.ndarray] = []
        self.modes: list = []
        self.observations: list[dict] = []
        self.events: list[HybridEvent] = []
        self.next_sample = 1  # index j of the next sample time j * sample_dt
        self.steps = self.rejected_steps = self.rhs_evaluations = self.segments = 0
        self.relaxed_locations = 0

    def record(self, t: float, y: np.ndarray, mode: typing.Any) -> None:
        self.t.append(float(t))
        self.y.append(np.array(y, dtype=float))
        self.modes.append(mode)
        if self.observe is not None:
            self.observations.append(self.observe(float(t), self.y[-1], mode))

    def result(self) -> HybridResult:
        return HybridResult(t=np.array(self.t), y=np.array(self.y), modes=list(self.modes),
                            events=list(self.events), observations=list(self.observations),
                            steps=self.steps, rejected_steps=self.rejected_steps,
                            rhs_evaluations=self.rhs_evaluations, segments=self.segments,
                            relaxed_locations=self.relaxed_locations)


class _Segment:
    """One smooth segment in a fixed mode: a fresh TS whose events terminate it.

    Attributes after :meth:`run`: ``t``, ``y`` (the last accepted state: at the event, at t_end
    or before a failure), ``fired`` (event indices; empty at t_end), ``dt_max`` (largest
    accepted step), ``failure`` (a message, or None), ``stalled`` (the failure is an event
    location that made no progress: resumable from ``t``, ``y`` with a larger tolerance),
    ``spurious`` (PETSc ended the segment at events that have not left their starting zero:
    the mode holds, resumable from ``t``, ``y``).
    """

    # set by run()
    t0: float
    t: float
    y: np.ndarray
    g: np.ndarray
    g_accepted: np.ndarray
    pending: np.ndarray
    event_tol: float
    base_event_tol: float
    _sample: PETSc.Vec

    def __init__(self, system: HybridSystem, mode: typing.Any, history: _History) -> None:
        self.system, self.mode, self.history = system, mode, history
        self.fired: list[int] = []
        self.failure: str | None = None
        self.left_after: float | None = None  # time to an event starting at zero
        # found negative: then the mode was left at once, or left and re-entered in that time
        self.dt_max = 0.0
        self.locating = 0  # right-hand sides evaluated since the last accepted step
        self.stalled = self.spurious = False

    def _rhs(self, ts: PETSc.TS, t: float, x: PETSc.Vec, f: PETSc.Vec) -> None:
        self.locating += 1  # reset by each accepted step
        if self.locating > _MAX_LOCATION_TRIES and self.failure is None:
            self.stalled = True
            self.failure = (f"no step accepted in {_MAX_LOCATION_TRIES} evaluations at "
                            f"t = {t:.15g} in mode {self.mode!r} (event values "
                            f"{np.asarray(self.g).tolist()}): the event location does not "
                            f"converge; raise the event tolerance (-<prefix>ts_event_tol, now "
                            f"{self.event_tol:g}) or scale the event functions")
        if self.failure is not None:
            raise _Stop  # ends TSSolve: converged reasons do not end the location loop
        self.history.rhs_evaluations += 1  # counted here: a stopped call evaluates nothing
        f.setArray(self.system.rhs(t, x.getArray(readonly=True), self.mode))

    def _events(self, ts: PETSc.TS, t: float, x: PETSc.Vec, fvalue: np.ndarray) -> None:
        fvalue[:] = self.g = self.system.events(t, x.getArray(readonly=True), self.mode)

    def _post_event(self, ts: PETSc.TS, fired: typing.Sequence[int], t: float, x: PETSc.Vec,
                    forward: bool) -> None:
        # PETSc counts |g| < tol as an event even for a g that started at zero and has not
        # left that band yet. If it is still moving away from zero (up since the last
        # accepted step) nothing crossed: the mode holds and the driver resumes it; if it is
        # coming back, it is an event (e.g. a bounce below the tolerance's height)
        g = np.asarray(self.g, dtype=float)
        self.fired = sorted(int(k) for k in fired
                            if not (self.pending[int(k)] and g[int(k)] > self.g_accepted[int(k)]))
        self.spurious = not self.fired

    def _post_step(self, ts: PETSc.TS) -> None:
        self.locating = 0
        if self.pending.any():  # PETSc skips events that start at zero: watch them here
            g = np.asarray(self.g, dtype=float)
            wrong = self.pending & (g < -self.event_tol)
            if wrong.any():  # stop; the last good state stays the previous one
                self.left_after = ts.getTime() - self.t0
                self.failure = (f"mode {self.mode!r} is inconsistent: its event functions "
                                f"{np.flatnonzero(wrong).tolist()} start at zero at "
                                f"t = {self.t0:.12g} and turn negative at once")
                ts.setConvergedReason(PETSc.TS.ConvergedReason.CONVERGED_USER)
                return
            self.pending &= ~(g > self.event_tol)
            self.g_accepted = g.copy()  # read for pending events only (_post_event)
        t, t_prev = ts.getTime(), ts.getPrevTime()
        self.t, self.y = t, ts.getSolution().getArray(readonly=True).copy()
        self.dt_max = max(self.dt_max, t - t_prev)
        history = self.history
        if history.sample_dt is None:
            history.record(t, self.y, self.mode)
        else:
            while history.next_sample * history.sample_dt <= t:
                ts.interpolate(history.next_sample * history.sample_dt, self._sample)
                history.record(history.next_sample * history.sample_dt,
                               self._sample.getArray(readonly=True), self.mode)
                history.next_sample += 1

    def run(self, t0: float, y0: np.ndarray, t_end: float, dt: float, options: dict,
            prefix: str, event_tol: float | None = None) -> None:
        """Integrate from (t0, y0) to the first event or t_end; ``event_tol`` overrides the
        ``ts_event_tol`` option (which sets the base tolerance)."""
        self.t0, self.t, self.y = t0, t0, y0
        comm = MPI.COMM_SELF
        x = PETSc.Vec().createSeq(y0.size, comm=comm)
        x.setArray(y0)
        f, self._sample = x.duplicate(), x.duplicate()
        ts = PETSc.TS().create(comm)
        ts.setOptionsPrefix(prefix)
        ts.setRHSFunction(self._rhs, f)
        g0 = np.asarray(self.system.events(t0, y0, self.mode), dtype=float).ravel()
        if g0.size:
            ts.setEventHandler([0] * g0.size, [True] * g0.size, self._events, self._post_event)
        with options_with_defaults(prefix, options) as opts:
            self.base_event_tol = opts.getReal("ts_event_tol")
            ts.setFromOptions()
        self.event_tol = self.base_event_tol if event_tol is None else event_tol
        if g0.size:
            ts.setEventTolerances(tol=self.event_tol)
        wrong = np.flatnonzero(g0 < -self.event_tol)
        if wrong.size:
            self.failure = (f"mode {self.mode!r} is inconsistent at t = {t0:.12g}: its event "
                            f"functions {wrong.tolist()} are negative, {g0[wrong].tolist()}")
        self.pending = np.abs(g0) <= self.event_tol
        self.g = self.g_accepted = g0
        ts.setTime(t0)
        ts.setTimeStep(min(dt, t_end - t0))
        ts.setMaxTime(t_end)
        ts.setPostStep(self._post_step)
        try:
            if self.failure is None:
                ts.solve(x)
                reason = ts.getConvergedReason()
                if reason < 0 or (reason != PETSc.TS.ConvergedReason.CONVERGED_EVENT
                                  and self.failure is None and ts.getTime() < t_end):
                    self.failure = (f"TS stopped at t = {ts.getTime():.12g} in mode "
                                    f"{self.mode!r} with reason {reason} after "
                                    f"{ts.getStepNumber()} steps")
        except _Stop:
            pass
        except PETSc.Error as raised:  # e.g. a NaN in the error estimate
            error = callback_error(raised)
            if not isinstance(error, PETSc.Error | _Stop):
                raise error from None
            if isinstance(error, PETSc.Error) and self.failure is None:
                self.failure = (f"TS failed in mode {self.mode!r} after t = {self.t:.12g} "
                                f"with PETSc error {error.ierr}")
        finally:
            self.history.steps += ts.getStepNumber()
            self.history.rejected_steps += ts.getStepRejections()
            self.history.segments += 1
            ts.setPostStep(None)
            for obj in (ts, x, f, self._sample):
                obj.destroy()


def _smooth_segment(system: HybridSystem, mode: typing.Any, history: _History, t: float,
                    y: np.ndarray,
                    t_end: float, dt: float, options: dict, prefix: str,
                    event_tol: float | None) -> _Segment:
    """Integrate in ``mode`` from (t, y) to its first event or t_end, retrying what can be
    retried: a first step that jumped over a short excursion of an event starting at zero
    (smaller step), and a location stalled below the time resolution (larger tolerance)."""
    segment = _Segment(system, mode, history)
    segment.run(t, y, t_end, dt, options, prefix, event_tol)
    retries = 0
    while segment.left_after is not None and segment.left_after > _SAME_INSTANT * t_end:
        if retries == _MAX_FIRST_STEP_RETRIES:  # e.g. a Zeno accumulation of events: stop
            segment.failure = (
                f"mode {mode!r} from t = {t:.12g}: an event function starting at zero left "
                f"it and came back within the first step {_MAX_FIRST_STEP_RETRIES} times "
                f"with steps down to {dt:.3e}; the events accumulate (Zeno behaviour?)")
            break
        retries += 1
        dt = segment.left_after / 16  # look closer: the first step may have jumped over
        segment = _Segment(system, mode, history)  # a short excursion
        segment.run(t, y, t_end, dt, options, prefix, event_tol)
    while segment.stalled and segment.event_tol < _MAX_EVENT_TOL:
        # the location cannot reach |g| <= tol at this time resolution: resume from the last
        # accepted step (same mode, nothing recorded twice) with a larger tolerance
        history.relaxed_locations += 1
        tol = min(segment.event_tol * _RELAX, _MAX_EVENT_TOL)
        g = np.abs(np.asarray(system.events(segment.t, segment.y, mode), dtype=float))
        close = np.flatnonzero((g <= tol) & ~segment.pending)
        if close.size:  # that step is on the event already, to the larger tolerance
            segment.fired, segment.failure, segment.stalled = [int(k) for k in close], None, False
            segment.event_tol = tol
            break
        resume_t, resume_y = segment.t, segment.y
        segment = _Segment(system, mode, history)
        segment.run(resume_t, resume_y, t_end, dt, options, prefix, tol)
    return segment


def integrate_hybrid(system: HybridSystem, y0: typing.Sequence[float] | np.ndarray,
                     mode0: typing.Any, t_end: float, *, rtol: float = 1e-8,
                     atol: float = 1e-10, dt0: float | None = None,
                     max_step: float | None = None, max_events: int = 100000,
                     sample_dt: float | None = None,
                     observe: Observer | None = None,
                     prefix: str = "hybrid_") -> HybridResult:
    """Integrate a piecewise-smooth system from t = 0 to ``t_end``, locating each event.

    Args:
        system: the :class:`HybridSystem`.
        y0, mode0: initial state (``system.size`` values) and mode; the mode's event functions
            must be >= 0 at y0.
        t_end: final time, > 0.
        rtol, atol: error-control tolerances of the adaptive Runge-Kutta steps (PETSc options
            ``-<prefix>ts_rtol``/``ts_atol`` win).
        dt0: first step; None: 1e-3 t_end. Later segments start with the largest accepted step
            of the previous one.
        max_step: upper bound of the step (``ts_adapt_dt_max``); None: no bound.
        max_events: the run stops with :class:`HybridError` at the event after this many.
        sample_dt: record the dense output at the multiples of ``sample_dt`` instead of the
            accepted steps (events and t_end are recorded either way).
        observe: ``observe(t, y, mode) -> dict``, called at each recorded time.
        prefix: PETSc options prefix of the TS.

    Returns:
        The :class:`HybridResult` (history, events and counters).

    Raises:
        HybridError: TS failed or stopped early, a mode was inconsistent at its start, a mode
            was re-entered at the same instant, or more than ``max_events`` events; it carries
            the last good time, state and mode and the history so far.
    """
    y = np.array(y0, dtype=float).ravel()
    check("y0", y0, y.size == system.size and bool(np.all(np.isfinite(y))),
          f"must be {system.size} finite numbers (system.size)")
    check("t_end", t_end, np.isfinite(t_end) and t_end > 0, "must be a finite number > 0")
    check("rtol", rtol, rtol > 0, "must be > 0")
    check("atol", atol, atol > 0, "must be > 0")
    check("dt0", dt0, dt0 is None or dt0 > 0, "must be None or > 0")
    check("max_step", max_step, max_step is None or max_step > 0, "must be None or > 0")
    check("max_events", max_events, max_events >= 0, "must be >= 0")
    check("sample_dt", sample_dt, sample_dt is None or sample_dt > 0, "must be None or > 0")
    options = {**DEFAULT_OPTIONS, "ts_rtol": rtol, "ts_atol": atol}
    if max_step is not None:
        options["ts_adapt_dt_max"] = max_step
    dt = min(dt0 if dt0 is not None else 1e-3 * t_end, max_step or np.inf)
    history = _History(sample_dt, observe)
    history.record(0.0, y, mode0)
    t, mode = 0.0, mode0
    # modes entered since the time last advanced
    instant_start, instant_modes = t, set[typing.Any]()

    def fail(message: str) -> typing.NoReturn:
        raise HybridError(message, t, y, mode, history.result())

    event_tol = None  # None: the option's tolerance; else what the last location achieved
    spurious = 0  # segments in a row ended by a spurious event (see _Segment._post_event)
    while True:
        segment = _smooth_segment(system, mode, history, t, y, t_end, dt, options, prefix,
                                  event_tol)
        if segment.t != history.t[-1] or history.modes[-1] != mode:
            history.record(segment.t, segment.y, mode)
        t, y, dt = segment.t, segment.y, segment.dt_max or dt
        if segment.failure is not None:
            fail(segment.failure)
        if segment.spurious:  # only events still at their starting zero: same mode, go on
            spurious += 1
            if spurious > _MAX_SPURIOUS:
                fail(f"events of mode {mode!r} stay within the event tolerance of zero for "
                     f"{_MAX_SPURIOUS} steps after t = {t:.12g}: the motion does not leave "
                     f"the switching surface")
            continue
        spurious = 0
        if not segment.fired:
            return history.result()
        # PETSc may accept a location whose |g| exceeds the tolerance (the time step reached
        # its resolution): the next mode's events may start that far from zero
        g = np.abs(np.asarray(system.events(t, y, mode), dtype=float))[segment.fired]
        event_tol = min(max(segment.base_event_tol, 2.0 * float(g.max(initial=0.0))),
                        _MAX_EVENT_TOL)
        if len(history.events) >= max_events:
            fail(f"more than max_events = {max_events} events by t = {t:.12g} (mode "
                 f"{mode!r}): chattering or Zeno behaviour?")
        y_new, mode_new = system.switch(t, y, mode, segment.fired)
        y_new = np.array(y_new, dtype=float).ravel()
        history.events.append(HybridEvent(t=t, fired=tuple(segment.fired), mode_before=mode,
                                          mode_after=mode_new, y_before=y, y_after=y_new))
        history.record(t, y_new, mode_new)
        if t - instant_start > _SAME_INSTANT * t_end:
            instant_start, instant_modes = t, set()
        if mode_new in instant_modes:
            fail(f"events re-fire at t = {t:.12g}: mode {mode_new!r} was entered at this "
                 f"instant already (modes {sorted(map(repr, instant_modes))}): the switch picks "
                 f"an inconsistent mode or the motion chatters")
        instant_modes.add(mode_new)
        y, mode = y_new, mode_new
        if t >= t_end:
            return history.result()

