r"""Braun's earthquake-like (EQ) model of a nonhomogeneous frictional interface, without a mesh.

N contacts of stiffness k join a slider to a substrate. A contact's stretching x grows with the
slider's displacement X; the contact breaks when x exceeds its threshold x_s, drawn from the
threshold distribution P_c, and re-forms at once with a stretching drawn from the newborn
distribution R (default: relaxed, R = δ(x)) and a new threshold. The friction force is
F = k Σ_i x_i (Braun (slides), the earthquake-like model; Braun & Peyrard 2008, "Modeling
friction on a mesoscale: master equation for the earthquakelike model").

A re-formed contact draws its threshold from P_c conditioned on x_s > x (its newborn stretching):
a contact cannot be born broken. This is the rule under which the master equation
(:mod:`fenicsfriction.studies.multicontact.master_equation`) is the model's mean, whose break rate
P(x) = P_c(x)/∫_x^∞ P_c is the hazard of exactly this conditioned threshold.

Two drives:

* quasistatic (:meth:`EQModel.quasistatic`): the slider is moved by X and nothing else moves.
  The contacts do not interact, so each is a renewal process: it breaks after a further slip
  x_s − x_0 of the slider. The break positions are cumulative sums of these intervals, computed
  for all contacts at once, and F(X) follows exactly (no step) from the sorted breaks;
* spring-driven (:meth:`EQModel.spring_driven`): a slider of mass m pulled through a spring K
  whose end moves at speed v, m Ẍ + η Ẋ = K (v t − X) − F, integrated by the package's PETSc TS
  (:class:`~fenicsfriction.timestepping.ReducedDynamics`, generalized-α). The contacts
  break at step resolution: after each accepted step, every contact with x > x_s breaks and
  re-forms; the step bounds the overshoot x − x_s by |Ẋ| Δt.

Distributions are SciPy frozen continuous distributions (``scipy.stats.norm(loc, scale)``) or any
object with their ``pdf``, ``cdf``, ``sf``, ``ppf`` and ``isf`` methods. Random numbers come from a
:class:`numpy.random.Generator` seeded by ``seed``: a run is reproducible.
"""

from __future__ import annotations

import abc
import dataclasses
import typing

import numpy as np
from scipy import stats

from fenicsfriction.laws import check, check_positive
from fenicsfriction.results import Record

__all__ = ["Contacts", "Distribution", "EQModel", "IndependentContacts", "QuasistaticResult",
           "SlipEvents", "SpringDrivenResult", "SpringDrives", "SpringQuasistaticResult",
           "check_quasistatic",
           "describe_distribution", "drive", "drive_quasistatic", "slip_events"]


class Distribution(typing.Protocol):
    """A continuous distribution on the real line (what a SciPy frozen distribution offers)."""

    def pdf(self, x: typing.Any) -> typing.Any: ...

    def cdf(self, x: typing.Any) -> typing.Any: ...

    def sf(self, x: typing.Any) -> typing.Any: ...

    def ppf(self, q: typing.Any) -> typing.Any: ...

    def isf(self, q: typing.Any) -> typing.Any: ...


def describe_distribution(dist: Distribution | None) -> dict[str, typing.Any]:
    """A JSON-ready description: ``{"name": "delta", "at": 0}`` for None (relaxed contacts),
    the SciPy name, arguments and keywords of a frozen distribution, else its ``repr``."""
    if dist is None:
        return {"name": "delta", "at": 0.0}
    scipy_dist = getattr(dist, "dist", None)
    if scipy_dist is not None:
        return {"name": scipy_dist.name, "args": list(getattr(dist, "args", ())),
                "kwds": dict(getattr(dist, "kwds", {}))}
    return {"name": repr(dist)}


def check_quasistatic(X_max: float, n_points: int, realisations: int,
                      kinetic_from: float | None) -> float:
    """Check a quasistatic drive's arguments (:meth:`EQModel.quasistatic`); return the start
    of its kinetic window (None: X_max/2)."""
    check_positive("X_max", X_max)
    check("n_points", n_points, isinstance(n_points, int) and n_points >= 2,
          "must be an integer >= 2")
    check("realisations", realisations, isinstance(realisations, int) and realisations >= 1,
          "must be an integer >= 1")
    kinetic_from = 0.5 * X_max if kinetic_from is None else kinetic_from
    check("kinetic_from", kinetic_from, 0 <= kinetic_from < X_max, f"must lie in [0, {X_max})")
    return kinetic_from


@dataclasses.dataclass
class QuasistaticResult(Record):
    """The friction force of a quasistatically moved slider (:meth:`EQModel.quasistatic`).

    Attributes:
        X: the slider positions where F is given (length units).
        F: the friction force at X, mean over the realisations (force units).
        F_std: its standard deviation over the realisations (0 for one realisation).
        histogram_edges, histogram: the density of the stretchings at the last X, all
            realisations pooled (integrates to 1).
        kinetic_force: the mean of F over X >= ``kinetic_from`` (the sliding state).
        static_force: the maximum of F on the grid X.
        kinetic_from: where the kinetic window starts.
        realisations: the number of independent interfaces averaged.
        breaks: the number of contact breaks, all realisations.
        parameters: the model's :meth:`EQModel.parameters`.
    """

    X: np.ndarray
    F: np.ndarray
    F_std: np.ndarray
    histogram_edges: np.ndarray
    histogram: np.ndarray
    kinetic_force: float
    static_force: float
    kinetic_from: float
    realisations: int
    breaks: int
    parameters: dict


@dataclasses.dataclass
class SlipEvents(Record):
    """The slip events of a spring-driven run (:func:`slip_events`), in order.

    Attributes:
        start, end: the times where each event's spring force starts and stops falling.
        drop: the fall of the spring force K (v t − X) over the event (force units).
        slip: the slider's advance over the event (length).
        breaks: the contacts broken in the event (those of its first step included), >= 1.
    """

    start: np.ndarray
    end: np.ndarray
    drop: np.ndarray
    slip: np.ndarray
    breaks: np.ndarray

    def after(self, t: float) -> SlipEvents:
        """The events that start at or after t."""
        keep = self.start >= t
        return SlipEvents(self.start[keep], self.end[keep], self.drop[keep], self.slip[keep],
                          self.breaks[keep])


def slip_events(t: np.ndarray, X: np.ndarray, spring_force: np.ndarray,
                breaks: np.ndarray) -> SlipEvents:
    r"""The slip events of a run: every maximal interval over which the spring force
    :math:`K (v t - X)` falls (the slider outruns the drive, :math:`\dot X > v`) and in which
    contacts break.

    A break's loss of force reaches the spring through the slider's motion, so an event is
    seen from its cause (the breaks at the step that starts it) to the spring force's first
    minimum: an underdamped slider's overshoot beyond its new equilibrium belongs to the
    event, and the later swings of its ring-down (falls without breaks, as is the start from
    rest) are not events.

    Args:
        t: the recorded times, increasing.
        X: the slider's position at t.
        spring_force: K (v t − X) at t.
        breaks: the contacts broken at the end of each step (after t).
    """
    falling = np.diff(spring_force) < 0
    edges = np.diff(falling.astype(np.int8), prepend=0, append=0)
    first, last = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)  # steps [first, last)
    counted = np.concatenate([[0], np.cumsum(breaks)])
    broken = (counted[last] - counted[first]).astype(int)
    first, last = first[broken > 0], last[broken > 0]
    return SlipEvents(start=t[first], end=t[last], drop=spring_force[first] - spring_force[last],
                      slip=X[last] - X[first], breaks=broken[broken > 0])


@dataclasses.dataclass
class SpringDrivenResult(Record):
    """A run of the slider pulled through a spring (:meth:`EQModel.spring_driven`).

    Attributes:
        t: the times of the accepted steps.
        X, X_dot: the slider's position and velocity.
        spring_force: K (v t − X), the force the drive applies.
        friction_force: k Σ x_i after the breaks of the step.
        breaks: the contacts broken at each step.
        K, v, mass, damping: the drive.
        late_from: where the late-time window starts.
        force_spread: std/mean of the spring force over the late window.
        velocity_spread: std(Ẋ)/v over the late window.
        stuck_fraction: the fraction of late steps with Ẋ < v/10.
        events: the slip events of the whole run (:func:`slip_events`).
        mean_force: the mean spring force over the late window.
        peak_force: the largest spring force of the run (the static peak).
        onset_drop: the largest event's drop over ``peak_force``.
        largest_late_drop: the largest spring-force drop of a late event over ``mean_force``.
        jump_fraction: the share of the slider's late displacement made in events whose
            drop, over ``mean_force``, exceeds ``drop_threshold`` (the drive carried by jumps).
        drop_threshold: the drop that makes an event a jump.
        onset_stick_slip: ``onset_drop > drop_threshold``.
        sustained_stick_slip: ``largest_late_drop > drop_threshold``.

        The classification is that of the infinitely slow drive
        (:class:`SpringQuasistaticResult`), by the same names, with the events of
        :func:`slip_events`. At a finite drive speed it is ambiguous near K*: a slider that
        follows a falling F(X) (K > K*) outruns the drive too, and the whole decline after the
        static peak is one falling interval, as large as a jump; the limit v → 0
        (:func:`drive_quasistatic`) is where the regimes separate.
        max_speed: max Ẋ/v over the run.
        fast_slip: ``max_speed > slip_speed``, the former speed classification, kept under its
            own name. It does not separate the regimes: a slider that follows its
            equilibrium moves at Ẋ = v K/(K + F'(X)), which exceeds any multiple of v as K
            approaches K* from above; single breaks make micro-slips of ~x_c/N at the
            oscillation's speed, above 10 v for small N; and a soft drive (K < N k/9) creeps
            at Ẋ < v/10 while loading, so the late-window spreads do not separate them either.
        parameters: the model's :meth:`EQModel.parameters`.
    """

    t: np.ndarray
    X: np.ndarray
    X_dot: np.ndarray
    spring_force: np.ndarray
    friction_force: np.ndarray
    breaks: np.ndarray
    K: float
    v: float
    mass: float
    damping: float
    late_from: float
    force_spread: float
    velocity_spread: float
    stuck_fraction: float
    events: SlipEvents
    mean_force: float
    peak_force: float
    onset_drop: float
    largest_late_drop: float
    jump_fraction: float
    drop_threshold: float
    onset_stick_slip: bool
    sustained_stick_slip: bool
    max_speed: float
    fast_slip: bool
    parameters: dict


class SpringDrives(abc.ABC):
    """The slider pulled through a spring, whatever holds its contacts: a model gives
    :meth:`contacts` (a fresh realisation) and :meth:`parameters`, and the drives are these
    (:class:`EQModel`'s independent contacts, the interacting models' coupled ones). An
    abstract base: a model that lacks either cannot be made."""

    @abc.abstractmethod
    def contacts(self, rng: np.random.Generator) -> Contacts:
        """A fresh realisation of the contacts, every contact relaxed at X = 0."""

    @abc.abstractmethod
    def parameters(self) -> dict[str, typing.Any]:
        """The model's parameters, which go into every result."""

    def spring_driven(self, K: float, v: float, mass: float, damping: float, t_end: float,
                      dt: float, seed: int | None = 0, late_from: float | None = None,
                      drop_threshold: float = 0.05, slip_speed: float = 10.0,
                      prefix: str = "eq_", options: dict | None = None) -> SpringDrivenResult:
        """Pull the slider, from rest with every contact relaxed, through a spring K whose end
        moves at speed v: m Ẍ + η Ẋ + F(X) = K (v t − X), by PETSc TS (generalized-α), the
        contacts breaking at step resolution (:func:`drive`); interacting contacts resolve an
        avalanche within the step whose end puts a contact over its threshold.

        The drive is a second degree of freedom D with D̈ = 0, D(0) = 0, Ḋ(0) = v, which the
        scheme integrates exactly (D = v t), so the residual needs no explicit time.

        Args:
            K: the drive's spring stiffness (force / length).
            v: the drive's speed (length / time).
            mass: m, the slider's mass.
            damping: η, the slider's viscous damping (force · time / length), >= 0.
            t_end: the duration.
            dt: the time step; a contact overshoots its threshold by at most |Ẋ| dt.
            seed: seeds the random generator.
            late_from: start of the late-time window classified; None: t_end/2. The run
                must reach the static peak: v t_end > F_s/K + x_c.
            drop_threshold: the spring-force drop of one event, over the late mean force
                (the onset's over the peak force), above which the event is a jump
                (:class:`SpringDrivenResult`).
            slip_speed: the speed, in units of v, of ``fast_slip`` (the former classification).
            prefix, options: the TS's options prefix and defaults
                (see :class:`~fenicsfriction.timestepping.ReducedDynamics`).
        """
        contacts = self.contacts(np.random.default_rng(seed))
        return drive(contacts, self.parameters(), K=K, v=v, mass=mass, damping=damping,
                     t_end=t_end, dt=dt, late_from=late_from, drop_threshold=drop_threshold,
                     slip_speed=slip_speed, prefix=prefix, options=options)

    def spring_quasistatic(self, K: float, D_max: float, seed: int | None = 0,
                           late_from: float | None = None,
                           drop_threshold: float = 0.05) -> SpringQuasistaticResult:
        """Pull the slider through a spring K infinitely slowly, event by event
        (:func:`drive_quasistatic`, whose arguments these are), every contact relaxed at
        D = 0; an event's breaks include any avalanche through the bodies."""
        contacts = self.contacts(np.random.default_rng(seed))
        return drive_quasistatic(contacts, self.parameters(), K=K, D_max=D_max,
                                 late_from=late_from, drop_threshold=drop_threshold)


@dataclasses.dataclass
class EQModel(SpringDrives):
    """The earthquake-like model's interface (Braun (slides), the earthquake-like model).

    Args:
        n_contacts: N, the number of contacts.
        k: the stiffness of one contact (force / length).
        x_s_mean, x_s_std: mean x_c and spread σ of the default Gaussian threshold
            distribution P_c (length); ignored when ``thresholds`` is given.
        thresholds: P_c, any :class:`Distribution`; None: Gaussian(x_s_mean, x_s_std).
        newborn: R, the stretching of a re-formed contact; None: relaxed, R = δ(x).
    """

    n_contacts: int = 1000
    k: float = 1.0
    x_s_mean: float = 1.0
    x_s_std: float = 0.1
    thresholds: Distribution | None = None
    newborn: Distribution | None = None
    _gaussian: tuple[tuple[float, float], Distribution] | None = dataclasses.field(
        default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        check("n_contacts", self.n_contacts,
              isinstance(self.n_contacts, (int, np.integer)) and self.n_contacts >= 1,
              "must be an integer >= 1")
        check_positive("k", self.k)
        check_positive("x_s_mean", self.x_s_mean)
        check_positive("x_s_std", self.x_s_std)
        for name in ("thresholds", "newborn"):
            dist = getattr(self, name)
            check(name, dist, dist is None or all(
                callable(getattr(dist, m, None)) for m in ("pdf", "cdf", "sf", "ppf", "isf")),
                "must be None or a distribution with pdf, cdf, sf, ppf and isf "
                "(e.g. scipy.stats.norm(loc, scale))")

    @property
    def P_c(self) -> Distribution:
        """The threshold distribution P_c (the Gaussian is kept while its parameters stay: a
        SciPy frozen distribution costs ~0.3 ms to make, more than a step's draws)."""
        if self.thresholds is not None:
            return self.thresholds
        key = (self.x_s_mean, self.x_s_std)
        if self._gaussian is None or self._gaussian[0] != key:
            self._gaussian = (key, stats.norm(loc=self.x_s_mean, scale=self.x_s_std))
        return self._gaussian[1]

    def parameters(self) -> dict[str, typing.Any]:
        """N, k, the threshold distribution's mean and spread and the newborn distribution."""
        P_c = typing.cast(typing.Any, self.P_c)  # SciPy's have mean and std, the protocol not
        mean, std = (float(P_c.mean()), float(P_c.std())) if hasattr(P_c, "std") else \
            (self.x_s_mean, self.x_s_std)
        return {"N": int(self.n_contacts), "k": float(self.k), "x_s_mean": mean,
                "x_s_std": std, "thresholds": describe_distribution(self.thresholds) if
                self.thresholds is not None else {"name": "norm", "args": [mean, std],
                                                  "kwds": {}},
                "newborn": describe_distribution(self.newborn)}

    def draw_newborn(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """Stretchings of ``size`` re-formed contacts, drawn from R."""
        if self.newborn is None:
            return np.zeros(size)
        return np.asarray(self.newborn.ppf(rng.random(size)), dtype=float)

    def draw_thresholds(self, rng: np.random.Generator, x0: np.ndarray) -> np.ndarray:
        """Thresholds drawn from P_c conditioned on x_s > x0, by inversion of its survival
        function: x_s = isf(u sf(x0)), u uniform on (0, 1]."""
        P_c = self.P_c
        u = 1.0 - rng.random(np.shape(x0))  # (0, 1]: isf(0) would be +inf
        return np.asarray(P_c.isf(u * P_c.sf(x0)), dtype=float)

    def quasistatic(self, X_max: float, n_points: int = 401, realisations: int = 1,
                    seed: int | None = 0, kinetic_from: float | None = None,
                    bins: int = 50) -> QuasistaticResult:
        """Move the slider from X = 0, every contact relaxed, to ``X_max``, exactly.

        Each contact is a renewal process (no interaction): its breaks lie at the cumulative
        sums of the slips x_s − x_0 of its successive lives, drawn at once for all contacts;
        F(X) = k (N X − Σ a_i(X)) with anchors a = (birth position) − x_0 changed at the sorted
        breaks. No step: the grid only samples the exact piecewise-linear F.

        Args:
            X_max: the last slider position (length).
            n_points: points of the grid X on [0, X_max].
            realisations: independent interfaces of N contacts, averaged.
            seed: seeds the random generator.
            kinetic_from: start of the window averaged into the kinetic force; None: X_max/2.
            bins: bins of the stretching histogram.
        """
        kinetic_from = check_quasistatic(X_max, n_points, realisations, kinetic_from)
        rng = np.random.default_rng(seed)
        n = self.n_contacts * realisations
        # lives[:, l]: the newborn stretching x_0 and the slip to the break of each life
        x0 = [np.zeros((n, 1))]
        slip = [self.draw_thresholds(rng, x0[0])]
        while np.min(np.sum(np.concatenate(slip, axis=1), axis=1)) <= X_max:
            more = max(2, int(np.ceil(X_max / max(float(np.mean(slip[0])), 1e-300))))
            new_x0 = self.draw_newborn(rng, n * more).reshape(n, more)
            x0.append(new_x0)
            slip.append(self.draw_thresholds(rng, new_x0) - new_x0)
        x0_all, slips = np.concatenate(x0, axis=1), np.concatenate(slip, axis=1)
        breaks = np.cumsum(slips, axis=1)
        # a break at B ends life l (anchor B_{l-1} - x0_l) and starts life l+1 (B_l - x0_{l+1})
        anchors = np.concatenate([np.zeros((n, 1)), breaks[:, :-1]], axis=1) - x0_all
        jumps = np.diff(anchors, axis=1)
        last = np.sum(breaks <= X_max, axis=1)  # lives ended before X_max, per contact
        X = np.linspace(0.0, X_max, n_points)
        F = np.empty((realisations, n_points))
        alive = np.sum(last)
        for r in range(realisations):
            rows = slice(r * self.n_contacts, (r + 1) * self.n_contacts)
            at, jump = breaks[rows, :-1].ravel(), jumps[rows].ravel()
            order = np.argsort(at)
            sum_anchor = np.concatenate([[0.0], np.cumsum(jump[order])])
            F[r] = self.k * (self.n_contacts * X
                             - sum_anchor[np.searchsorted(at[order], X, side="right")])
        stretch = X_max - anchors[np.arange(n), last]
        density, edges = np.histogram(stretch, bins=bins, density=True)
        mean_F = F.mean(axis=0)
        return QuasistaticResult(
            X=X, F=mean_F, F_std=F.std(axis=0), histogram_edges=edges, histogram=density,
            kinetic_force=float(np.mean(mean_F[kinetic_from <= X])),
            static_force=float(np.max(mean_F)), kinetic_from=float(kinetic_from),
            realisations=realisations, breaks=int(alive), parameters=self.parameters())

    def contacts(self, rng: np.random.Generator) -> IndependentContacts:
        """A fresh realisation, every contact relaxed at X = 0."""
        return IndependentContacts(self, rng)


class Contacts(typing.Protocol):
    """The contacts as the spring-driven slider sees them (:func:`drive`): a friction force
    linear in the slider's position X between breaks, and the breaks."""

    #: dF/dX between breaks (force / length).
    stiffness: float
    #: a force scale of the interface, for the tolerance of the time integration.
    weight: float

    def friction(self, X: float) -> float:
        """The contacts' force on the slider at X, before the breaks at X."""

    def relax(self, X: float, trigger: int | None = None) -> int:
        """Break every contact over its threshold at X and re-form it (and any it overloads),
        ``trigger`` whatever the round-off; return the number of breaks."""

    def next_break(self) -> tuple[float, int]:
        """The slider position of the next break under further loading and its contact."""


class IndependentContacts:
    """The EQ model's contacts without interaction: x_i = X − a_i, F = k (N X − Σ a_i)."""

    def __init__(self, model: EQModel, rng: np.random.Generator) -> None:
        self.model, self.rng = model, rng
        self.anchors = np.zeros(model.n_contacts)
        self.thresholds = model.draw_thresholds(rng, self.anchors)
        self.sum_anchors = 0.0
        self.stiffness = model.n_contacts * model.k
        self.weight = model.n_contacts * model.k * model.x_s_mean

    def friction(self, X: float) -> float:
        return self.model.k * (self.model.n_contacts * X - self.sum_anchors)

    def next_break(self) -> tuple[float, int]:
        reach = self.anchors + self.thresholds
        first = int(np.argmin(reach))
        return float(reach[first]), first

    def relax(self, X: float, trigger: int | None = None) -> int:
        over = X - self.anchors > self.thresholds
        if trigger is not None:
            over[trigger] = True
        broken = np.flatnonzero(over)
        if broken.size:
            x0 = self.model.draw_newborn(self.rng, broken.size)
            self.anchors[broken] = X - x0
            self.thresholds[broken] = self.model.draw_thresholds(self.rng, x0)
            self.sum_anchors = float(np.sum(self.anchors))
        return int(broken.size)


def drive(contacts: Contacts, parameters: dict, K: float, v: float, mass: float,
          damping: float, t_end: float, dt: float, late_from: float | None = None,
          drop_threshold: float = 0.05, slip_speed: float = 10.0, prefix: str = "eq_",
          options: dict | None = None) -> SpringDrivenResult:
    """Pull a slider held by ``contacts`` through a spring K (see :meth:`EQModel.spring_driven`,
    whose arguments these are; ``parameters`` go into the result)."""
    from fenicsfriction.timestepping import ReducedDynamics

    for name, value in (("K", K), ("v", v), ("mass", mass), ("t_end", t_end), ("dt", dt),
                        ("slip_speed", slip_speed)):
        check_positive(name, value)
    check_positive("damping", damping, strict=False)
    check("drop_threshold", drop_threshold, 0 < drop_threshold < 1, "must lie in (0, 1)")
    late_from = 0.5 * t_end if late_from is None else late_from
    check("late_from", late_from, 0 <= late_from < t_end, f"must lie in [0, {t_end})")
    slider = _SpringDrivenSlider(contacts, K, mass, damping)
    integrator = ReducedDynamics(slider, [0.0, 0.0], [0.0, v], prefix=prefix, options=options,
                                 atol=1e-12 * contacts.weight)
    records = integrator.run(
        t_end, dt, observe=lambda t: slider.observe(integrator.q, integrator.q_dot))
    t, X, X_dot, D, friction, broken = (np.array([r[key] for r in records]) for key in
                                        ("time", "X", "X_dot", "D", "friction", "breaks"))
    spring = K * (D - X)
    late = t >= late_from
    events = slip_events(t, X, spring, broken)
    late_events = events.after(late_from)
    mean_force = float(np.mean(spring[late]))
    drops = late_events.drop / abs(mean_force)
    advance = float(X[-1] - X[late][0])
    jumps = float(np.sum(late_events.slip[drops > drop_threshold]))
    largest = float(np.max(drops, initial=0.0))
    peak = float(np.max(spring))
    onset = float(np.max(events.drop, initial=0.0)) / peak
    max_speed = float(np.max(X_dot) / v)
    return SpringDrivenResult(
        t=t, X=X, X_dot=X_dot, spring_force=spring, friction_force=friction,
        breaks=broken.astype(int), K=float(K), v=float(v), mass=float(mass),
        damping=float(damping), late_from=float(late_from),
        force_spread=float(np.std(spring[late]) / abs(mean_force)),
        velocity_spread=float(np.std(X_dot[late]) / v),
        stuck_fraction=float(np.mean(X_dot[late] < 0.1 * v)), events=events,
        mean_force=mean_force, peak_force=peak, onset_drop=onset, largest_late_drop=largest,
        jump_fraction=jumps / advance if advance > 0 else 0.0,
        drop_threshold=float(drop_threshold), onset_stick_slip=onset > drop_threshold,
        sustained_stick_slip=largest > drop_threshold, max_speed=max_speed,
        fast_slip=max_speed > slip_speed, parameters=parameters)


@dataclasses.dataclass
class SpringQuasistaticResult(Record):
    """The slider pulled through a spring K infinitely slowly (:func:`drive_quasistatic`).

    Attributes:
        D: the drive's positions at the events.
        events: the events (``start`` = ``end`` = the drive's position D there): a break and
            the slip and further breaks it causes at fixed D, until the slider rests.
        K: the drive's stiffness.
        late_from: where the late window starts (a drive position).
        mean_force: the mean spring force over the late window (exact: it is linear in D
            between events).
        largest_late_drop: the largest drop of a late event over ``mean_force``.
        jump_fraction: the share of the slider's late advance made in events whose drop
            exceeds ``drop_threshold``.
        mean_breaks: the mean breaks per late event.
        peak_force: the largest spring force of the run (the static peak).
        onset_drop: the largest drop of any event over ``peak_force``: the first collective
            break, from all contacts relaxed, where F(X) falls fastest.
        drop_threshold: the drop that makes an event a jump.
        onset_stick_slip: ``onset_drop > drop_threshold``: the slider jumps at the static
            peak, which the elastic instability predicts for K < K* as N → ∞
            (:func:`~fenicsfriction.studies.multicontact.instability.critical_stiffness`):
            the plain model's stick-slip, the static-to-kinetic transition.
        sustained_stick_slip: ``largest_late_drop > drop_threshold``: the jumps go on in the
            late window. Without ageing the contacts' phases spread after the first collective
            break and this fades with N for every K (docs/multicontact.md).
        parameters: the model's parameters.
    """

    D: np.ndarray
    events: SlipEvents
    K: float
    late_from: float
    mean_force: float
    largest_late_drop: float
    jump_fraction: float
    mean_breaks: float
    peak_force: float
    onset_drop: float
    drop_threshold: float
    onset_stick_slip: bool
    sustained_stick_slip: bool
    parameters: dict


def drive_quasistatic(contacts: Contacts, parameters: dict, K: float, D_max: float,
                      late_from: float | None = None,
                      drop_threshold: float = 0.05) -> SpringQuasistaticResult:
    r"""Pull a slider held by ``contacts`` through a spring K whose end D moves infinitely
    slowly, from D = 0, event by event and exactly.

    Between events the slider rests on its equilibrium :math:`K (D - X) = F(X)`, F linear in X
    (slope S), so X reaches the next break at :math:`D = X + F(X)/K`. There the contact breaks
    at fixed D; F falls, and the slider slips to its new equilibrium,
    :math:`X' = X + (K (D - X) - F(X))/(K + S)`, breaking in their order every contact it
    takes past its threshold on the way (each re-formed where it broke), until it rests: one
    event, whose spring-force drop is :math:`K (X_{end} - X_{start})`. This is the limit
    v → 0 of :func:`drive` for an overdamped slider (no overshoot), where time scales
    separate and the events are unambiguous: a stiff drive (K > K*) loses single breaks,
    each :math:`k x_s K/(K + S)`, and a soft one (K < K*) loses a finite fraction of its force
    in one event of O(N) breaks.

    Args:
        contacts: the contacts (:class:`Contacts`), from X = 0.
        parameters: go into the result.
        K: the drive's stiffness (force / length).
        D_max: the drive's last position (length).
        late_from: where the late window starts; None: D_max/2.
        drop_threshold: the drop, over the late mean force, that makes an event a jump.
    """
    check_positive("K", K)
    check_positive("D_max", D_max)
    check("drop_threshold", drop_threshold, 0 < drop_threshold < 1, "must lie in (0, 1)")
    late_from = 0.5 * D_max if late_from is None else late_from
    check("late_from", late_from, 0 <= late_from < D_max, f"must lie in [0, {D_max})")
    S = contacts.stiffness
    X = 0.0
    at, before, after, start, slips, counts = [], [], [], [], [], []
    while True:
        X_break, trigger = contacts.next_break()
        if X_break < X:  # round-off: a contact left at its threshold by the last slip
            X_break = X
        D = X_break + contacts.friction(X_break) / K
        if D_max < D:
            break
        X, X_start, force_before = X_break, X_break, K * (D - X_break)
        broken = contacts.relax(X, trigger)
        while True:  # the slip at fixed D, break by break
            target = X + (K * (D - X) - contacts.friction(X)) / (K + S)
            X_next, trigger = contacts.next_break()
            if X_next > target:
                X = target
                break
            X = max(X, X_next)
            broken += contacts.relax(X, trigger)
        at.append(D)
        before.append(force_before)
        after.append(K * (D - X))
        start.append(X_start)
        slips.append(X - X_start)
        counts.append(broken)
    D_events = np.asarray(at)
    events = SlipEvents(start=D_events, end=D_events.copy(),
                        drop=np.asarray(before) - np.asarray(after), slip=np.asarray(slips),
                        breaks=np.asarray(counts, dtype=int))
    # between events X and the spring force are linear in D, of slopes K/(K + S), K S/(K + S)
    knots = np.concatenate([[0.0], D_events])
    force_after = np.concatenate([[0.0], after])  # just after each event (and at D = 0)
    slider_after = np.concatenate([[0.0], np.asarray(start) + np.asarray(slips)])

    def slider(d: float) -> float:
        i = int(np.searchsorted(knots, d, side="right")) - 1
        return float(slider_after[i] + (d - knots[i]) * K / (K + S))

    ends = np.concatenate([knots[1:], [D_max]])
    left, right = np.clip(knots, late_from, D_max), np.clip(ends, late_from, D_max)
    slope = K * S / (K + S)
    midpoint_force = force_after + slope * (0.5 * (left + right) - knots)
    mean_force = float(np.sum(midpoint_force * (right - left)) / (D_max - late_from))
    late = events.after(late_from)
    drops = late.drop / abs(mean_force)
    advance = slider(D_max) - slider(late_from)
    jumps = float(np.sum(late.slip[drops > drop_threshold]))
    largest = float(np.max(drops, initial=0.0))
    peak = float(np.max(before, initial=float(force_after[-1] + slope * (D_max - knots[-1]))))
    onset = float(np.max(events.drop, initial=0.0)) / peak
    return SpringQuasistaticResult(
        D=D_events, events=events, K=float(K), late_from=float(late_from),
        mean_force=mean_force, largest_late_drop=largest,
        jump_fraction=jumps / advance if advance > 0 else 0.0,
        mean_breaks=float(np.mean(late.breaks)) if late.breaks.size else 0.0,
        peak_force=peak, onset_drop=onset, drop_threshold=float(drop_threshold),
        onset_stick_slip=onset > drop_threshold, sustained_stick_slip=largest > drop_threshold,
        parameters=parameters)


class _SpringDrivenSlider:
    """The slider and the drive q = (X, D) for :class:`ReducedDynamics`; the contacts break
    after each accepted step (:meth:`observe`)."""

    def __init__(self, contacts: Contacts, K: float, mass: float, damping: float) -> None:
        self.contacts, self.K, self.mass, self.damping = contacts, K, mass, damping

    def residual(self, q: np.ndarray, q_dot: np.ndarray, q_ddot: np.ndarray) -> np.ndarray:
        return np.array([self.mass * q_ddot[0] + self.damping * q_dot[0]
                         + self.contacts.friction(q[0]) - self.K * (q[1] - q[0]),
                         self.mass * q_ddot[1]])

    def linearisation(self, q: np.ndarray, q_dot: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return (self.mass * np.eye(2), np.diag([self.damping, 0.0]),
                np.array([[self.contacts.stiffness + self.K, -self.K], [0.0, 0.0]]))

    def observe(self, q: np.ndarray, q_dot: np.ndarray) -> dict[str, float]:
        broken = self.contacts.relax(float(q[0]))
        return {"X": float(q[0]), "X_dot": float(q_dot[0]), "D": float(q[1]),
                "friction": self.contacts.friction(float(q[0])), "breaks": float(broken)}
