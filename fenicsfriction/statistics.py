r"""What an experimenter measures on a stick-slip run.

Two families, both read from what an integrator recorded and neither part of one:

* :func:`stick_slip_statistics` — mean forces, the apparent friction coefficient, stick and
  open fractions at a probe, the longest stick, from the flat per-step records of the finite
  element block (``BlockModel.dynamics_observer``) or the rigid block
  (``rigid_block_observables``);
* :func:`mode_intervals`, :func:`displacement_extrema`, :func:`limit_cycle` and
  :func:`belt_summary` — the phases, extremes and limit cycle of an event-located run
  (:class:`~fenicsfriction.events.HybridResult`,
  :class:`~fenicsfriction.studies.oscillators.belt.BeltResult`).

Imports NumPy and SciPy only (no dolfinx, no PETSc).
"""

from __future__ import annotations

import dataclasses
import math
import typing

import numpy as np
from scipy.integrate import trapezoid

from fenicsfriction.laws import check
from fenicsfriction.results import Record

if typing.TYPE_CHECKING:
    from fenicsfriction.events import HybridEvent, HybridResult

__all__ = ["BeltRun", "BeltSummary", "LimitCycle", "StickSlipStatistics", "belt_summary",
           "displacement_extrema", "limit_cycle", "mean_force_figures", "mode_intervals",
           "stick_slip_statistics"]


class BeltRun(typing.Protocol):
    """What the measures of an event-located run read: the protocol of
    :class:`~fenicsfriction.studies.oscillators.belt.BeltResult` (a family's type, which these
    generic measures do not import)."""

    t: np.ndarray  #: recorded times
    x: np.ndarray  #: displacements
    v: np.ndarray  #: velocities
    events: list[HybridEvent]  #: the located events
    stick_intervals: list[tuple[float, float]]  #: (start, end) of each stick phase
    hybrid: HybridResult  #: the integration's result (TS counters)
    method: str  #: ``"events"`` or ``"regularised"``

    def stick_onsets(self) -> np.ndarray:
        """Times of the located events that enter stick."""


@dataclasses.dataclass(frozen=True)
class StickSlipStatistics(Record):
    r"""What :func:`stick_slip_statistics` measures over the window [``t_from``, ``t_to``].

    Attributes:
        t_from, t_to: the window (times of its first and last record).
        mu, eps: the law's coefficient and regularisation speed, as given.
        mean_normal_force, mean_friction_force: time means :math:`\bar N`, :math:`\bar F_T`.
        normal_force_range: [min, max] of the normal force.
        apparent_coefficient: :math:`|\bar F_T| / \bar N`, the friction coefficient a
            measurement of mean forces would report.
        ratio_to_mu: ``apparent_coefficient / mu`` (NaN for μ = 0).
        probe_stick_fraction: share of the time the probe node sticks (in contact,
            :math:`|\dot u_T - U_T| < \varepsilon`).
        probe_open_fraction: share of the time the probe node is out of contact.
        probe_longest_stick: its longest uninterrupted stick [s] (a stick-slip relaxation
            cycle against brief adhesions).
        any_stick_fraction: share of the time some contact node sticks (from ``n_stick``;
            None without it).
        spring_elongation: ``{"start", "end", "mean"}`` of the spring elongation.
        max_energy_error: largest |energy error| over the whole run (None without one).
        duration: length of the whole run.
        steps, rejected_steps, newton_iterations: counters over the whole run.
    """

    t_from: float
    t_to: float
    mu: float
    eps: float
    mean_normal_force: float
    mean_friction_force: float
    normal_force_range: list[float]
    apparent_coefficient: float
    ratio_to_mu: float
    probe_stick_fraction: float
    probe_open_fraction: float
    probe_longest_stick: float
    any_stick_fraction: float | None
    spring_elongation: dict[str, float]
    max_energy_error: float | None
    duration: float
    steps: int
    rejected_steps: int
    newton_iterations: int


def _longest_run(t: np.ndarray, flags: np.ndarray) -> float:
    """Longest time span over which ``flags`` holds at consecutive samples (0 if never)."""
    longest, start = 0.0, None
    for time_k, flag in zip(t, flags, strict=True):
        if flag and start is None:
            start = time_k
        elif not flag and start is not None:
            start = None
        if start is not None:
            longest = max(longest, time_k - start)
    return float(longest)


def _time_mean(t: np.ndarray, values: np.ndarray) -> float:
    """Time average of a sampled signal (trapezoidal rule; steps may vary)."""
    return float(trapezoid(values, t) / (t[-1] - t[0]))


def mean_force_figures(mean_normal_force: float, mean_friction_force: float,
                       normal_force_range: typing.Sequence[float], mu: float
                       ) -> dict[str, typing.Any]:
    r"""The figures of a window's mean forces, however the means were taken.

    One definition for both readers: :func:`stick_slip_statistics` (means of a list of
    records) and ``block dynamics`` (means of every step, from its running statistics).

    Args:
        mean_normal_force, mean_friction_force: the window's time means :math:`\bar N`,
            :math:`\bar F_T`.
        normal_force_range: (min, max) of the normal force over the window.
        mu: the law's friction coefficient.

    Returns:
        ``mean_normal_force``, ``mean_friction_force``, ``normal_force_range`` (a list),
        ``apparent_coefficient`` :math:`|\bar F_T| / \bar N` and ``ratio_to_mu``, the apparent
        coefficient over μ (NaN for μ = 0): the :class:`StickSlipStatistics` fields of the
        same names.
    """
    apparent = abs(mean_friction_force) / mean_normal_force
    return {"mean_normal_force": float(mean_normal_force),
            "mean_friction_force": float(mean_friction_force),
            "normal_force_range": [float(v) for v in normal_force_range],
            "apparent_coefficient": float(apparent),
            "ratio_to_mu": float(apparent / mu) if mu > 0 else float("nan")}


def stick_slip_statistics(records: list[dict], mu: float, eps: float,
                          t_from: float = 0.0) -> StickSlipStatistics:
    r"""What an experimenter would measure on a run, over the records with time ≥ ``t_from``.

    Needs ``normal_force``, ``friction_force``, ``spring_elongation`` and the probe's
    ``probe_slip``/``probe_pressure`` (see ``BlockModel.dynamics_observer``;
    ``rigid_block_observables`` gives them for the rigid block), and ``energy_error`` if
    there is one (``max_energy_error`` is None otherwise).

    Args:
        records: the per-step records, in time order (each with a ``time``, and
            ``rejected_steps`` and ``newton_iterations`` counters).
        mu: the law's friction coefficient (the reference of ``ratio_to_mu``).
        eps: the regularisation speed: a probe slipping slower than it sticks.
        t_from: start of the window (the records before it count for the run totals only).

    Returns:
        The :class:`StickSlipStatistics` of the window.

    Raises:
        ValueError: ``t_from`` is not before the last record.
    """
    check("t_from", t_from, t_from < records[-1]["time"], "must be before the last record")
    t_all = np.array([r["time"] for r in records])
    window = [r for r in records if r["time"] >= t_from]
    t = np.array([r["time"] for r in window])
    series = {key: np.array([r[key] for r in window]) for key in
              ("normal_force", "friction_force", "spring_elongation", "probe_slip",
               "probe_pressure")}
    in_contact = series["probe_pressure"] > 0
    sticks = in_contact & (np.abs(series["probe_slip"]) < eps)
    forces = mean_force_figures(_time_mean(t, series["normal_force"]),
                                _time_mean(t, series["friction_force"]),
                                (series["normal_force"].min(), series["normal_force"].max()), mu)
    return StickSlipStatistics(
        t_from=float(t[0]), t_to=float(t[-1]), mu=mu, eps=eps, **forces,
        probe_stick_fraction=_time_mean(t, sticks.astype(float)),
        probe_open_fraction=_time_mean(t, (~in_contact).astype(float)),
        probe_longest_stick=_longest_run(t, sticks),
        any_stick_fraction=(_time_mean(t, np.array([r["n_stick"] > 0 for r in window],
                                                   dtype=float))
                            if "n_stick" in window[0] else None),
        spring_elongation={"start": float(series["spring_elongation"][0]),
                           "end": float(series["spring_elongation"][-1]),
                           "mean": _time_mean(t, series["spring_elongation"])},
        max_energy_error=(float(max(abs(r["energy_error"]) for r in records))
                          if "energy_error" in records[0] else None),
        duration=float(t_all[-1] - t_all[0]), steps=len(records) - 1,
        rejected_steps=int(sum(r["rejected_steps"] for r in records)),
        newton_iterations=int(sum(r["newton_iterations"] for r in records)))


# --- event-located runs: phases, extremes, limit cycle ------------------------------------------


@dataclasses.dataclass(frozen=True)
class LimitCycle(Record):
    """Period, amplitude and stick fraction of a (stick-slip) cycle.

    Attributes:
        period: T.
        amplitude: max - min of x over a cycle (peak to peak).
        x_min, x_max: the extremes of x.
        stick_fraction: time spent sticking over T.
        period_change: |T - T_previous| of the cycle before (0 for a closed form); a measure of
            how far the transient has died out.
    """

    period: float
    amplitude: float
    x_min: float
    x_max: float
    stick_fraction: float
    period_change: float = 0.0


@dataclasses.dataclass(frozen=True)
class BeltSummary(Record):
    """JSON-able numbers of a belt oscillator run (:func:`belt_summary`).

    Attributes:
        period, amplitude, x_min, x_max, stick_fraction, period_change: the last cycle's
            (:class:`LimitCycle`); None without two cycle markers (and ``period_change``
            None without three).
        events: the number of located events.
        stick_fraction_run: time spent sticking over the whole run.
        steps, rejected_steps, rhs_evaluations: the integrator's counters.
        t_end: the final time.
        method: ``"events"`` or ``"regularised"``.
    """

    period: float | None
    amplitude: float | None
    x_min: float | None
    x_max: float | None
    stick_fraction: float | None
    period_change: float | None
    events: int
    stick_fraction_run: float
    steps: int
    rejected_steps: int
    rhs_evaluations: int
    t_end: float
    method: str


def mode_intervals(result: HybridResult, holds: typing.Callable[[typing.Any], bool]
                   ) -> list[tuple[float, float]]:
    """The time intervals of a run during which ``holds(mode)`` is true.

    Read from the located events, so exact to the event tolerance (e.g. a contact's stick
    phases).

    Args:
        result: the run (:class:`~fenicsfriction.events.HybridResult`).
        holds: mode -> whether the phase of interest holds in it.

    Returns:
        The (start, end) of each interval, in order.
    """
    intervals: list[tuple[float, float]] = []
    start = float(result.t[0]) if holds(result.modes[0]) else math.nan
    for event in result.events:
        before, after = holds(event.mode_before), holds(event.mode_after)
        if before and not after:
            intervals.append((start, event.t))
        elif after and not before:
            start = event.t
    if holds(result.modes[-1]):
        intervals.append((start, float(result.t[-1])))
    return intervals


def displacement_extrema(result: BeltRun) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times, values and kinds (+1 maximum, -1 minimum) of the extremes of x.

    Where ẋ changes sign between two records, the cubic Hermite interpolant of (x, ẋ) is
    extremal (error O(h⁴) in the value).

    Args:
        result: the run (:class:`~fenicsfriction.studies.oscillators.belt.BeltResult`: ``t``, ``x``,
            ``v``).

    Returns:
        (times, values, kinds), one entry per extremum, in time order.
    """
    t, x, v = result.t, result.x, result.v
    times, values, kinds = [], [], []
    for i in np.flatnonzero((np.sign(v[:-1]) != np.sign(v[1:])) & (t[1:] > t[:-1])):
        h = t[i + 1] - t[i]
        # p(s) = x0 + h v0 s + a s² + b s³ on s in [0, 1]
        a = 3 * (x[i + 1] - x[i]) - h * (2 * v[i] + v[i + 1])
        b = -2 * (x[i + 1] - x[i]) + h * (v[i] + v[i + 1])
        roots = np.roots([3 * b, 2 * a, h * v[i]])
        real = [r.real for r in roots if abs(r.imag) < 1e-12 and 0 <= r.real <= 1]
        s = real[0] if real else 0.5
        times.append(t[i] + h * s)
        values.append(x[i] + h * v[i] * s + a * s**2 + b * s**3)
        kinds.append(1 if v[i] > 0 else -1)
    return np.array(times), np.array(values), np.array(kinds)


def limit_cycle(result: BeltRun) -> LimitCycle:
    """Measure the last full cycle of a run (make the run long enough for transients to die).

    The cycle is delimited by the last two stick onsets (located events) if the run has them,
    else by the last two maxima of x (interpolated, :func:`displacement_extrema`); the
    amplitude is max - min of x over it, the extremes interpolated alike.

    Args:
        result: the run (:class:`~fenicsfriction.studies.oscillators.belt.BeltResult`).

    Returns:
        The :class:`LimitCycle`; ``period_change`` is NaN without a third cycle marker.

    Raises:
        ValueError: fewer than two cycle markers.
    """
    onsets = result.stick_onsets()
    times, values, kinds = displacement_extrema(result)
    markers = onsets if onsets.size >= 2 else times[kinds > 0]
    check("result", f"<{markers.size} cycle markers>", markers.size >= 2,
          "needs at least two stick onsets or maxima of x: run longer")
    start, end = markers[-2], markers[-1]
    inside = (times >= start) & (times <= end)
    in_cycle = (result.t >= start) & (result.t <= end)
    x_max = max(values[inside & (kinds > 0)], default=result.x[in_cycle].max())
    x_min = min(values[inside & (kinds < 0)], default=result.x[in_cycle].min())
    stick = sum(max(0.0, min(b, end) - max(a, start)) for a, b in result.stick_intervals)
    period = end - start
    change = abs(period - (markers[-2] - markers[-3])) if markers.size >= 3 else math.nan
    return LimitCycle(period=float(period), amplitude=float(x_max - x_min), x_min=float(x_min),
                      x_max=float(x_max), stick_fraction=float(stick / period),
                      period_change=float(change))


def belt_summary(result: BeltRun) -> BeltSummary:
    """The JSON-able numbers of a belt oscillator run.

    Args:
        result: the run (:class:`~fenicsfriction.studies.oscillators.belt.BeltResult`).

    Returns:
        The :class:`BeltSummary`: the last cycle's :class:`LimitCycle` (None where it cannot
        be measured), the events, the stick fraction over the whole run, the counters.
    """
    try:
        cycle: dict[str, float | None] = dataclasses.asdict(limit_cycle(result))
    except ValueError:
        cycle = dict.fromkeys(("period", "amplitude", "x_min", "x_max", "stick_fraction",
                               "period_change"))
    duration = float(result.t[-1] - result.t[0])
    stuck = sum(b - a for a, b in result.stick_intervals)
    return BeltSummary(
        **{key: (None if value is None or math.isnan(value) else value)
           for key, value in cycle.items()},
        events=len(result.events), stick_fraction_run=stuck / duration,
        steps=result.hybrid.steps, rejected_steps=result.hybrid.rejected_steps,
        rhs_evaluations=result.hybrid.rhs_evaluations, t_end=float(result.t[-1]),
        method=result.method)
