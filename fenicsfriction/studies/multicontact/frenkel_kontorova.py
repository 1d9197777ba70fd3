r"""Slip fronts of a nonhomogeneous frictional interface: the driven Frenkel-Kontorova chain
with earthquake-like (breaking) contacts, the FK-EQ model of Braun (slides), "Crack as a
solitary wave".

A chain of n blocks of mass m, spacing a, neighbours coupled by springs g, each block held by
a substrate spring K and by one contact of stiffness k to the base, driven by a force f(t):

.. math::
    m\ddot u_i + m\eta\dot u_i - g(u_{i+1} + u_{i-1} - 2u_i) + F_s(u_i) + K u_i = f(t).

**The contact force** (what is implemented): :math:`F_s = k(u_i - b_i)` with an anchor
:math:`b_i`. The contact breaks when its stretching reaches its threshold,
:math:`|u_i - b_i| = u_{s,i}`, and re-forms at once relaxed: :math:`b_i \leftarrow u_i`; the
energy :math:`k u_{s,i}^2/2` of the broken contact is lost. A contact first stretched forward
from :math:`b_i = 0` thus gives the slides' piecewise-linear force, :math:`k u` for
:math:`u < u_s` and :math:`k(u - u_s)` after the break. Breaking backwards (stretching
:math:`-u_{s,i}`, when f is lowered) is allowed by the same rule.

**Breaks are located as events**: the state is (u, u̇, b) plus three running integrals (the
work of f, the viscous dissipation, the broken-contact losses);
:func:`fenicsfriction.events.integrate_hybrid` integrates each smooth stretch with
PETSc TS (explicit Dormand-Prince 5(4), adaptive) and locates every zero of
:math:`g_i = u_{s,i} - |u_i - b_i|` to the event tolerance, where the anchor is reset. An
explicit scheme suits: between breaks the system is linear and not stiff (its highest
frequency :math:`\sqrt{(4g + k + K)/m}` sets the step, as it would set the accuracy of an
implicit one), and the event location makes the break times exact to the tolerance instead of
to the step, which the front speed is measured from.

**Boundary conditions** (Braun (slides)): the right part of the chain is unrelaxed
(:math:`b_i = 0`, far-field :math:`u_R = f/(k + K)`), the left part relaxed (broken once,
:math:`b_i = u_{s,i}`, :math:`u_L = (f + k u_s)/(k + K)`). The ends are free (no neighbour
beyond them), so that each uniform far-field state is an equilibrium at its end whatever f(t)
does; the two states meet in a step at t = 0 (:meth:`FKChain.simulate`).

**The continuum limit** :math:`i \to x = ia`: :math:`m u_{tt} + m\eta u_t - a^2 g u_{xx} +
F(u) = 0`, :math:`F = F_s + K u - f`. A front moving right at speed v,
:math:`u = u(\xi)`, :math:`\xi = x - vt`, with the break at ξ = 0 where u = u_s, solves
:math:`(a^2 g - m v^2) u'' + m\eta v u' = F(u)` with F linear on each side
(:math:`F = \kappa(u - u_R)` ahead, :math:`\kappa(u - u_L)` behind, κ = k + K). Matching the
two exponentials and their slopes at ξ = 0 gives, with
:math:`r = 2(f - f_{min})/(k u_s) \in [0, 1)`,

.. math::
    v(f) = \frac{c_0}{\sqrt{1 + m\eta^2 (1 - r^2)/(4 r^2 \kappa)}}, \qquad
    c_0 = a\sqrt{g/m},\quad f_{min} = (k/2 + K) u_s,\quad f_{max} = (k + K) u_s,

exact for this piecewise-linear F. Its limits are the slides' two formulas: at low velocity
:math:`v \approx 2 r c_0 \sqrt{\kappa/m}/\eta = (f - f_{min})/(m_k\eta)` with the kink mass
:math:`m_k = m k u_s/(4 a \sqrt{g\kappa})`; near :math:`f_{max}`,
:math:`v \approx c_0/\sqrt{1 + m\eta^2 (f_{max} - f)/(k\kappa u_s)}`. Below
:math:`f_{min}` (the Maxwell point, where the potential of F has equal minima) a front
retreats or stops; above :math:`f_{max}` the unrelaxed part breaks everywhere at once.

The discrete chain departs from this in two places. Near :math:`f_{min}` its own lattice
pinning stops fronts the continuum would move slowly (when the kink is a few contacts wide).
Near :math:`f_{max}` the intact contacts sit within :math:`(f_{max} - f)/\kappa` of their
threshold and each breaks as soon as its broken neighbour has pulled it that far: the front
runs as a domino faster than :math:`c_0`. A front at :math:`v > c_0` has no continuum profile
(ahead of it :math:`(m v^2 - a^2 g)\lambda^2 + m\eta v\lambda + \kappa = 0` has no root
λ > 0), but the chain, with :math:`4 g \sinh^2(\lambda a/2)` in place of
:math:`a^2 g \lambda^2`, has a steep precursor at any speed.

The slides cite for slip fronts the experiments of S.M. Rubinstein, G. Cohen and J. Fineberg
(2004), "Detachment fronts and the onset of dynamic friction", Nature 430, 1005, and (2007),
"Dynamics of precursors to frictional sliding", Phys. Rev. Lett. 98, 226103, and the
simulations of O.M. Braun, I. Barel and M. Urbakh (2009), "Dynamics of transition from static
to kinetic friction", Phys. Rev. Lett. 103, 194301.
"""

from __future__ import annotations

import dataclasses
import math
import typing

import numpy as np

from fenicsfriction.events import HybridResult, integrate_hybrid
from fenicsfriction.laws import check, check_positive
from fenicsfriction.results import Record

__all__ = ["FKChain", "FKResult", "FrontSpeeds", "TriangleRamp", "front_speeds"]

#: a force given as a constant or as a function of time
Force = float | typing.Callable[[float], float]


@dataclasses.dataclass(frozen=True)
class TriangleRamp:
    """f(t) rising linearly from ``f_low`` to ``f_high`` over ``ramp_time`` and back over the
    same time, then constant at ``f_low``: the force cycle of a hysteresis loop."""

    f_low: float
    f_high: float
    ramp_time: float

    def __post_init__(self) -> None:
        check_positive("ramp_time", self.ramp_time)
        check("f_high", self.f_high, self.f_high >= self.f_low,
              f"must be >= f_low = {self.f_low}")

    def __call__(self, t: float) -> float:
        """f(t)."""
        s = min(t, 2 * self.ramp_time - t) / self.ramp_time
        return self.f_low + (self.f_high - self.f_low) * max(s, 0.0)


@dataclasses.dataclass
class FKResult(Record):
    """A run of :meth:`FKChain.simulate`.

    Attributes:
        t: recorded times (samples, and each break twice: before and after it).
        u: displacements, shape (len(t), n).
        force: f(t).
        front_position: a × the index of the rightmost contact broken so far (NaN before the
            first break of the run).
        mean_displacement: mean of u over the chain.
        work: work done by f since t = 0.
        dissipated: viscous dissipation ∫ m η Σ u̇² dt since t = 0.
        broken_loss: elastic energy of the contacts lost at their breaks since t = 0.
        stored: kinetic + chain + substrate + contact energy at t.
        break_time: the first break of each contact in the run (NaN if none).
        break_sites, break_times: every break in order (site index, time).
        hybrid: the event-located integration (counters, events).
    """

    t: np.ndarray
    u: np.ndarray = dataclasses.field(repr=False)
    force: np.ndarray
    front_position: np.ndarray
    mean_displacement: np.ndarray
    work: np.ndarray
    dissipated: np.ndarray
    broken_loss: np.ndarray
    stored: np.ndarray
    break_time: np.ndarray
    break_sites: np.ndarray
    break_times: np.ndarray
    hybrid: HybridResult = dataclasses.field(repr=False)
    a: float = 1.0

    def energy_residual(self) -> np.ndarray:
        """work − (stored − stored(0)) − dissipated − broken_loss at each recorded time: zero
        up to the integration error."""
        return self.work - (self.stored - self.stored[0]) - self.dissipated - self.broken_loss

    def front_speed(self, first: int, last: int) -> float:
        """The front speed from the first-break times of contacts ``first`` to ``last``
        (inclusive, all broken): a / the least-squares slope of break time against index."""
        sites = np.arange(first, last + 1)
        times = self.break_time[sites]
        check("last", last, bool(np.all(np.isfinite(times))),
              f"contacts {first}..{last} must all have broken")
        return self.a / float(np.polyfit(sites, times, 1)[0])

    def front_velocity(self) -> tuple[np.ndarray, np.ndarray]:
        """The local front speed against time: between the first breaks of neighbouring
        contacts (both broken), a / their time difference, at the later break's time."""
        t = self.break_time
        both = np.isfinite(t[1:]) & np.isfinite(t[:-1])
        return t[1:][both], self.a / (t[1:][both] - t[:-1][both])

    def rows(self) -> list[dict[str, float]]:
        """One CSV row per recorded time: t, f, front position, mean u, energies."""
        return [{"t": t, "force": f, "front_position": x, "mean_displacement": mu, "work": w,
                 "dissipated": d, "broken_loss": b, "stored": s}
                for t, f, x, mu, w, d, b, s in zip(
                    self.t, self.force, self.front_position, self.mean_displacement,
                    self.work, self.dissipated, self.broken_loss, self.stored, strict=True)]


@dataclasses.dataclass
class FrontSpeeds(Record):
    """Measured front speeds against the driving force, beside the continuum closed form
    (:meth:`FKChain.continuum_front_speed`) and its low- and high-velocity limits."""

    force: np.ndarray
    measured: np.ndarray
    continuum: np.ndarray
    low_velocity: np.ndarray
    high_velocity: np.ndarray
    sound_speed: float

    def rows(self) -> list[dict[str, float]]:
        """One CSV row per force."""
        return [{"force": f, "measured": v, "continuum": c, "low_velocity": lo,
                 "high_velocity": hi, "sound_speed": self.sound_speed}
                for f, v, c, lo, hi in zip(self.force, self.measured, self.continuum,
                                           self.low_velocity, self.high_velocity, strict=True)]


@dataclasses.dataclass
class FKChain:
    """The FK-EQ chain (see the module docstring). Any consistent units.

    Args:
        n: number of blocks (contacts), >= 3.
        m: block mass, > 0.
        eta: viscous damping rate η (1/time), > 0.
        g: stiffness of the springs between neighbours, > 0.
        k: contact stiffness, > 0.
        K: substrate stiffness, >= 0.
        u_s: mean breaking threshold of the contacts' stretching, > 0.
        a: block spacing (lattice constant), > 0.
        thresholds: each contact's threshold :math:`u_{s,i}` (n values > 0); None: all u_s.
    """

    n: int
    m: float
    eta: float
    g: float
    k: float
    K: float
    u_s: float
    a: float = 1.0
    thresholds: np.ndarray | None = None

    def __post_init__(self) -> None:
        check("n", self.n, isinstance(self.n, int) and self.n >= 3, "must be an integer >= 3")
        for name in ("m", "eta", "g", "k", "u_s", "a"):
            check_positive(name, getattr(self, name))
        check_positive("K", self.K, strict=False)
        if self.thresholds is None:
            self.thresholds = np.full(self.n, float(self.u_s))
        self.thresholds = np.asarray(self.thresholds, dtype=float)
        check("thresholds", self.thresholds,
              self.thresholds.shape == (self.n,) and bool(np.all(self.thresholds > 0)),
              f"must be n = {self.n} numbers > 0")

    @property
    def u_thresholds(self) -> np.ndarray:
        """:math:`u_{s,i}` (never None after construction)."""
        return typing.cast(np.ndarray, self.thresholds)

    def with_defects(self, spread: float, seed: int) -> FKChain:
        """The same chain with thresholds :math:`u_s(1 + \\text{spread}\\,\\xi_i)`, ξ_i uniform
        in [-1, 1] from ``numpy.random.default_rng(seed)``; spread in [0, 1)."""
        check("spread", spread, 0 <= spread < 1, "must lie in [0, 1)")
        xi = np.random.default_rng(seed).uniform(-1.0, 1.0, self.n)
        return dataclasses.replace(self, thresholds=self.u_s * (1 + spread * xi))

    # --- closed forms -----------------------------------------------------------------------

    @property
    def sound_speed(self) -> float:
        """:math:`c_0 = a\\sqrt{g/m}`, the long-wave sound speed of the free chain."""
        return self.a * math.sqrt(self.g / self.m)

    @property
    def f_min(self) -> float:
        """:math:`(k/2 + K) u_s`: below it a front on the uniform chain does not advance."""
        return (self.k / 2 + self.K) * self.u_s

    @property
    def f_max(self) -> float:
        """:math:`(k + K) u_s`: above it the unrelaxed chain breaks everywhere."""
        return (self.k + self.K) * self.u_s

    @property
    def kink_mass(self) -> float:
        """:math:`m_k = m k u_s / (4 a \\sqrt{g (k + K)})`, of the low-velocity mobility."""
        return self.m * self.k * self.u_s / (4 * self.a * math.sqrt(self.g * (self.k + self.K)))

    def _reduced_force(self, f: typing.Any) -> np.ndarray:
        f = np.asarray(f, dtype=float)
        check("f", f.tolist(), bool(np.all((f >= self.f_min) & (f < self.f_max))),
              f"must lie in [f_min, f_max) = [{self.f_min:g}, {self.f_max:g})")
        return 2 * (f - self.f_min) / (self.k * self.u_s)

    def continuum_front_speed(self, f: typing.Any) -> np.ndarray:
        """The travelling-wave speed of the continuum limit (module docstring), f in
        [f_min, f_max)."""
        r = self._reduced_force(f)
        kappa = self.k + self.K
        with np.errstate(divide="ignore"):
            return self.sound_speed / np.sqrt(1 + self.m * self.eta**2 * (1 - r**2)
                                              / (4 * r**2 * kappa))

    def low_velocity_speed(self, f: typing.Any) -> np.ndarray:
        """:math:`(f - f_{min})/(m_k\\eta)`, the continuum speed's slope at f_min."""
        self._reduced_force(f)
        return (np.asarray(f, dtype=float) - self.f_min) / (self.kink_mass * self.eta)

    def high_velocity_speed(self, f: typing.Any) -> np.ndarray:
        """:math:`c_0/\\sqrt{1 + m\\eta^2 (f_{max} - f)/(k (k + K) u_s)}`, near f_max."""
        self._reduced_force(f)
        deficit = self.f_max - np.asarray(f, dtype=float)
        return self.sound_speed / np.sqrt(1 + self.m * self.eta**2 * deficit
                                          / (self.k * (self.k + self.K) * self.u_s))

    # --- the chain ------------------------------------------------------------------------

    def _laplacian(self, u: np.ndarray) -> np.ndarray:
        """u_{i+1} + u_{i-1} − 2u_i along the last axis, with free ends (no neighbour beyond
        them)."""
        d = np.diff(u, axis=-1)
        lap = np.zeros_like(u)
        lap[..., :-1] += d
        lap[..., 1:] -= d
        return lap

    def equilibrium(self, f: float, anchors: np.ndarray) -> np.ndarray:
        """The static displacements at force f with contact anchors b:
        (K + k) u − g Δu = f + k b."""
        identity = np.eye(self.n)
        matrix = (self.k + self.K) * identity - self.g * self._laplacian(identity)
        return np.linalg.solve(matrix, f + self.k * np.asarray(anchors, dtype=float))

    def energy(self, u: np.ndarray, v: np.ndarray, anchors: np.ndarray) -> np.ndarray:
        """Kinetic + chain + substrate + contact energy (last axis: the blocks)."""
        return 0.5 * (self.m * np.sum(v**2, axis=-1)
                      + self.g * np.sum(np.diff(u, axis=-1) ** 2, axis=-1)
                      + self.K * np.sum(u**2, axis=-1)
                      + self.k * np.sum((u - anchors) ** 2, axis=-1))

    def simulate(self, force: Force, t_end: float, relaxed: int, *,
                 sample_dt: float | None = None, rtol: float = 1e-8, atol: float = 1e-10,
                 prefix: str = "fk_") -> FKResult:
        """Integrate from rest with the ``relaxed`` leftmost contacts broken once (anchors
        :math:`b_i = u_{s,i}`), the others intact (:math:`b_i = 0`), each block where its own
        springs balance f(0), :math:`u_i = (f(0) + k b_i)/(k + K)`: the slides' relaxed and
        unrelaxed states meeting in a step (for f(0) > f_min no static front exists).

        Args:
            force: f, a constant or a function of time.
            t_end: final time, > 0.
            relaxed: number of broken contacts at the left end, in [0, n].
            sample_dt: record every multiple of it (breaks are always recorded); None: every
                accepted step.
            rtol, atol, prefix: of :func:`~fenicsfriction.events.integrate_hybrid`.

        Returns:
            The :class:`FKResult`.

        Raises:
            ValueError: bad arguments, or an initial contact stretched past its threshold.
        """
        drive = force if callable(force) else _Constant(float(force))
        check("relaxed", relaxed, isinstance(relaxed, int) and 0 <= relaxed <= self.n,
              f"must be an integer in [0, n = {self.n}]")
        n, thresholds = self.n, self.u_thresholds
        anchors = np.where(np.arange(n) < relaxed, thresholds, 0.0)
        u0 = (drive(0.0) + self.k * anchors) / (self.k + self.K)
        check("force", force, bool(np.all(np.abs(u0 - anchors) < thresholds)),
              "must leave every initial contact below its threshold at t = 0 (f(0) < f_max "
              "and the relaxed part not broken again)")
        system = _Chain(self, drive)
        y0 = np.concatenate([u0, np.zeros(n), anchors, np.zeros(3)])
        hybrid = integrate_hybrid(system, y0, 0, t_end, rtol=rtol, atol=atol,
                                  dt0=0.01 / math.sqrt((4 * self.g + self.k + self.K) / self.m),
                                  sample_dt=sample_dt, prefix=prefix)
        u, v, b = (hybrid.y[:, j * n:(j + 1) * n] for j in range(3))
        work, dissipated, loss = hybrid.y[:, 3 * n:].T
        sites = np.array([i for e in hybrid.events for i in e.fired], dtype=int)
        times = np.array([e.t for e in hybrid.events for _ in e.fired], dtype=float)
        first = np.full(n, np.nan)
        for i, t in zip(sites[::-1], times[::-1], strict=True):
            first[i] = t
        # breaks up to each recorded time (both records at a break's time count it)
        count = np.searchsorted(times, hybrid.t, side="right")
        rightmost = np.maximum.accumulate(sites) if sites.size else np.zeros(1, dtype=int)
        front = np.where(count > 0, self.a * rightmost[np.maximum(count - 1, 0)], np.nan)
        return FKResult(t=hybrid.t, u=u, force=np.array([drive(t) for t in hybrid.t]),
                        front_position=front, mean_displacement=u.mean(axis=1), work=work,
                        dissipated=dissipated, broken_loss=loss,
                        stored=self.energy(u, v, b), break_time=first, break_sites=sites,
                        break_times=times, hybrid=hybrid, a=self.a)


@dataclasses.dataclass(frozen=True)
class _Constant:
    """A constant force as a function of time."""

    f: float

    def __call__(self, t: float) -> float:
        """f."""
        return self.f


class _Chain:
    """The chain as a :class:`~fenicsfriction.events.HybridSystem`: state
    (u, u̇, b, W, D, L), mode = the number of breaks so far (never re-entered)."""

    def __init__(self, chain: FKChain, drive: typing.Callable[[float], float]) -> None:
        self.chain, self.drive, self.n = chain, drive, chain.n
        self.size = 3 * chain.n + 3

    def rhs(self, t: float, y: np.ndarray, mode: int) -> np.ndarray:
        """(u̇, ü, ḃ = 0, f Σu̇, m η Σu̇², 0)."""
        c, n = self.chain, self.n
        u, v, b = y[:n], y[n:2 * n], y[2 * n:3 * n]
        f = self.drive(t)
        accel = (f - c.m * c.eta * v + c.g * c._laplacian(u) - c.k * (u - b) - c.K * u) / c.m
        return np.concatenate([v, accel, np.zeros(n),
                               [f * v.sum(), c.m * c.eta * float(v @ v), 0.0]])

    def events(self, t: float, y: np.ndarray, mode: int) -> np.ndarray:
        """:math:`u_{s,i} - |u_i - b_i|`."""
        n = self.n
        return self.chain.u_thresholds - np.abs(y[:n] - y[2 * n:3 * n])

    def switch(self, t: float, y: np.ndarray, mode: int,
               fired: list[int]) -> tuple[np.ndarray, int]:
        """Reset the anchors of the broken contacts to their blocks; book their energy."""
        n, y = self.n, y.copy()
        for i in fired:
            y[-1] += 0.5 * self.chain.k * (y[i] - y[2 * n + i]) ** 2
            y[2 * n + i] = y[i]
        return y, mode + len(fired)


def front_speeds(chain: FKChain, forces: typing.Sequence[float], *, relaxed: int,
                 first: int, last: int, rtol: float = 1e-8) -> FrontSpeeds:
    """Measure the front speed at each constant force (:meth:`FKResult.front_speed` over
    contacts ``first``..``last``) beside the continuum closed forms. Each run lasts until the
    continuum front would pass ``last`` 1.5 times over (and at least the time sound takes)."""
    f_values = np.asarray(forces, dtype=float)
    continuum = chain.continuum_front_speed(f_values)
    measured = []
    for f, v in zip(f_values, continuum, strict=True):
        distance = chain.a * (last + 1 - relaxed)
        t_end = 1.5 * distance / min(v, chain.sound_speed) if v > 0 else np.inf
        check("forces", f, np.isfinite(t_end), f"must exceed f_min = {chain.f_min:g}")
        result = chain.simulate(float(f), t_end, relaxed, sample_dt=t_end / 10, rtol=rtol)
        measured.append(result.front_speed(first, last))
    return FrontSpeeds(force=f_values, measured=np.array(measured), continuum=continuum,
                       low_velocity=chain.low_velocity_speed(f_values),
                       high_velocity=chain.high_velocity_speed(f_values),
                       sound_speed=chain.sound_speed)
