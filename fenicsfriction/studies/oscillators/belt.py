r"""The one-d.o.f. mass-spring-damper on a moving belt: stick-slip with located events.

A mass m on a belt moving at :math:`v_b > 0`, held by a spring k and a dashpot c, pressed with
a normal force N:

.. math::
    m\ddot x + c\dot x + k x = F, \qquad v_r = v_b - \dot x \ \text{(relative velocity)},

with the friction force F of the interface law's coefficient μ(v) (:class:`InterfaceLaw
<fenicsfriction.laws.InterfaceLaw>`, read at the normal force N) and a static coefficient
:math:`\mu_s` (default μ(0)):

* **slip** (:math:`v_r \ne 0`): :math:`F = \mu(v_r) N \operatorname{sgn}(v_r)`; modes
  ``"slip+"`` (:math:`v_r > 0`, the belt drags the mass forward) and ``"slip-"``;
* **stick** (:math:`\dot x = v_b`, :math:`\ddot x = 0`): F is the required force
  :math:`F_{req} = k x + c v_b`, admissible while :math:`|F_{req}| \le \mu_s N`.

Events (:mod:`fenicsfriction.events`, all >= 0 while the mode holds): in stick
:math:`\mu_s N \mp F_{req}`, whose zero starts a slip in the direction of the required force;
in slip :math:`\pm v_r`, whose zero ends it. At :math:`v_r = 0` the mass sticks if
:math:`-\mu_s N \le F_{req} < \mu_s N` (in stick :math:`F_{req}` grows at the rate
:math:`k v_b`, so the upper bound is left at once), else it slips in the direction of
:math:`F_{req}`.

Linearising the slip about steady sliding (:math:`\dot x = 0`, :math:`x_0 = \mu(v_b) N / k`)
with :math:`F \approx \mu(v_b) N - N \mu'(v_b)\dot x` gives
:math:`m\ddot\xi + (c + N\mu'(v_b))\dot\xi + k\xi = 0`: steady sliding is stable iff the
effective damping :math:`c + N \mu'(v_b)` is positive.
"""

from __future__ import annotations

import dataclasses
import math
import typing

import numpy as np

from fenicsfriction import laws
from fenicsfriction.events import HybridEvent, HybridResult, Observer, integrate_hybrid
from fenicsfriction.laws import check, check_positive
from fenicsfriction.results import Record
from fenicsfriction.statistics import LimitCycle, mode_intervals

# LimitCycle (the closed-form cycle's type) lives with the statistics that measure one
__all__ = ["BeltOscillator", "BeltResult", "LimitCycle"]

STICK, SLIP_FORWARD, SLIP_BACKWARD = "stick", "slip+", "slip-"
_SLIP_SIGN = {SLIP_FORWARD: 1.0, SLIP_BACKWARD: -1.0}


@dataclasses.dataclass
class BeltResult(Record):
    """A run of :meth:`BeltOscillator.simulate`.

    Attributes:
        t, x, v: recorded times, displacements and velocities (each event appears twice: before
            and after the switch).
        modes: ``"stick"``, ``"slip+"``, ``"slip-"`` (``method="events"``) or ``"smooth"``.
        friction_force: F at each recorded time (the required force while sticking).
        events: the located events (empty for the regularised law).
        stick_intervals: (start, end) of each stick phase (none for the regularised law: the
            smooth law creeps, it never sticks).
        hybrid: the :class:`~fenicsfriction.events.HybridResult` (TS counters).
        method: ``"events"`` or ``"regularised"``.
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    modes: np.ndarray
    friction_force: np.ndarray
    events: list[HybridEvent]
    stick_intervals: list[tuple[float, float]]
    hybrid: HybridResult
    method: str

    def stick_onsets(self) -> np.ndarray:
        """Times of the located events that enter stick (empty for the regularised law)."""
        return np.array([e.t for e in self.events if e.mode_after == STICK])


@dataclasses.dataclass
class BeltOscillator:
    """Mass-spring-damper on a belt with a friction coefficient law (a
    :class:`~fenicsfriction.events.HybridSystem`, state y = (x, ẋ)).

    Args:
        m: mass, > 0.
        k: spring stiffness, > 0.
        c: viscous damping, >= 0.
        N: normal force, > 0.
        v_belt: belt speed v_b, > 0.
        law: the interface law (:class:`~fenicsfriction.laws.InterfaceLaw`), of which a point
            model uses the friction part: the coefficient μ(speed, N) (``mu`` or a law such as
            :class:`~fenicsfriction.laws.StribeckFriction` or a user's function; the normal
            force N is its pressure) and, for ``method="regularised"``, the regularisation.
            The normal compliance (c_n, m_n, b_n, g) is not used: N is given. A bare
            coefficient law μ(speed, pressure) is taken as
            ``InterfaceLaw(friction_coefficient=μ, regularisation="smooth")``.
        mu_static: static coefficient μ_s >= μ(0); None: μ(0).

    Any consistent units; the tests use dimensionless ones.
    """

    m: float
    k: float
    c: float
    N: float
    v_belt: float
    law: laws.InterfaceLaw | laws.FrictionLaw
    mu_static: float | None = None

    size: typing.ClassVar[int] = 2

    def __post_init__(self) -> None:
        check_positive("m", self.m)
        check_positive("k", self.k)
        check_positive("c", self.c, strict=False)
        check_positive("N", self.N)
        check_positive("v_belt", self.v_belt)
        if not isinstance(self.law, laws.InterfaceLaw):
            check("law", self.law, callable(self.law),
                  "must be an InterfaceLaw or a friction coefficient law mu(speed, pressure)")
            self.law = laws.InterfaceLaw(friction_coefficient=self.law, regularisation="smooth")
        mu_0 = self.mu(0.0)
        if self.mu_static is None:
            self.mu_static = mu_0
        check_positive("mu_static", self.mu_static, strict=False)
        check("mu_static", self.mu_static, self.mu_static >= mu_0,
              f"must be >= mu(0) = {mu_0:g}: sticking may not hold less than sliding starts with")

    @property
    def static_coefficient(self) -> float:
        """μ_s: ``mu_static`` (μ(0) when not given)."""
        return self.mu(0.0) if self.mu_static is None else self.mu_static

    @property
    def _law(self) -> laws.InterfaceLaw:
        assert isinstance(self.law, laws.InterfaceLaw)  # made one by __post_init__
        return self.law

    def mu(self, v_r: float) -> float:
        """The law's coefficient μ(|v_r|, N) at the relative velocity v_r."""
        return float(self._law.coefficient(abs(v_r), self.N))

    # --- the hybrid system ----------------------------------------------------------------------

    def required_force(self, x: typing.Any) -> typing.Any:
        """Friction force that keeps the mass stuck to the belt: F_req = k x + c v_b."""
        return self.k * np.asarray(x, dtype=float) + self.c * self.v_belt

    def friction_force(self, y: np.ndarray, mode: str) -> float:
        """F in ``mode`` at the state y = (x, ẋ)."""
        if mode == STICK:
            return float(self.required_force(y[0]))
        return _SLIP_SIGN[mode] * self.mu(self.v_belt - y[1]) * self.N

    def rhs(self, t: float, y: np.ndarray, mode: str) -> np.ndarray:
        """(ẋ, ẍ): (v_b, 0) in stick, (ẋ, (F - c ẋ - k x)/m) in slip."""
        if mode == STICK:
            return np.array([self.v_belt, 0.0])
        force = self.friction_force(y, mode) - self.c * y[1] - self.k * y[0]
        return np.array([y[1], force / self.m])

    def events(self, t: float, y: np.ndarray, mode: str) -> np.ndarray:
        """Stick: (μ_s N - F_req, μ_s N + F_req); slip±: ±v_r."""
        if mode == STICK:
            bound, force = self.static_coefficient * self.N, float(self.required_force(y[0]))
            return np.array([bound - force, bound + force])
        return np.array([_SLIP_SIGN[mode] * (self.v_belt - y[1])])

    def mode_at_belt_speed(self, x: float) -> str:
        """The consistent mode at ẋ = v_b: stick if -μ_s N <= F_req < μ_s N, else slip in the
        direction of F_req."""
        bound, force = self.static_coefficient * self.N, float(self.required_force(x))
        if force >= bound:
            return SLIP_FORWARD
        return STICK if force >= -bound else SLIP_BACKWARD

    def switch(self, t: float, y: np.ndarray, mode: str,
               fired: list[int]) -> tuple[np.ndarray, str]:
        """Every event of this model happens at ẋ = v_b: the velocity is set to v_b exactly
        (the located state is off by the event tolerance); a stick ends in the slip the bound
        reached points to, a slip at the mode :meth:`mode_at_belt_speed` picks."""
        y_new = np.array([y[0], self.v_belt])
        if mode == STICK:
            return y_new, SLIP_FORWARD if fired[0] == 0 else SLIP_BACKWARD
        return y_new, self.mode_at_belt_speed(y[0])

    # --- steady sliding and its linearisation -----------------------------------------------

    def steady_sliding(self) -> float:
        """Position of steady sliding (ẋ = 0, slip velocity v_b): x0 = μ(v_b) N / k."""
        return self.mu(self.v_belt) * self.N / self.k

    def effective_damping(self) -> float:
        """c + N dμ/dv(v_b): the damping of small oscillations about steady sliding."""
        return self.c + self.N * float(self._law.coefficient_slope(self.v_belt, self.N))

    def linear_eigenvalues(self) -> np.ndarray:
        """Roots s of m s² + (c + N μ'(v_b)) s + k = 0 (complex, conjugate pair first by
        imaginary part when oscillatory)."""
        return np.sort_complex(np.roots([self.m, self.effective_damping(), self.k])
                               .astype(complex))

    def is_steady_sliding_stable(self) -> bool:
        """Steady sliding is asymptotically stable iff c + N μ'(v_b) > 0."""
        return self.effective_damping() > 0

    # --- the classic stick-slip cycle in closed form ----------------------------------------

    def classic_limit_cycle(self) -> LimitCycle:
        r"""The stick-slip cycle for c = 0 and a constant kinetic coefficient μ_k < μ_s.

        Derivation. Let :math:`\omega = \sqrt{k/m}`, :math:`x_k = \mu_k N/k`,
        :math:`x_s = \mu_s N/k` and :math:`\Delta = x_s - x_k = (\mu_s - \mu_k) N/k > 0`.

        * Stick: ẋ = v_b until the spring force reaches the static bound, k x = μ_s N, i.e.
          x = x_s.
        * Slip (v_r > 0, F = μ_k N): :math:`m\ddot x = \mu_k N - k x`, a harmonic arc about
          x_k. From :math:`(x, \dot x) = (x_s, v_b)`,
          :math:`x - x_k = R\cos(\omega t - \varphi)` with
          :math:`R = \sqrt{\Delta^2 + (v_b/\omega)^2}`, :math:`\tan\varphi = v_b/(\omega\Delta)`,
          :math:`\varphi \in (0, \pi/2)`; :math:`\dot x = -R\omega\sin(\omega t - \varphi)`.
          The slip ends when ẋ = v_b again: :math:`\sin(\omega t - \varphi) = -\sin\varphi`,
          first at :math:`\omega t - \varphi = \pi + \varphi`, so the slip lasts
          :math:`(\pi + 2\varphi)/\omega` (ẋ < v_b in between) and ends at
          :math:`x = x_k - \Delta`.
        * There :math:`F_{req} = k(x_k - \Delta) = (2\mu_k - \mu_s) N \ge -\mu_s N`: the
          mass sticks (for any μ_k >= 0) and rides back to x_s in :math:`2\Delta/v_b`.

        Hence :math:`T = 2\Delta/v_b + (\pi + 2\varphi)/\omega`. The extremes of x are those of
        the arc, reached inside the slip (:math:`\omega t - \varphi = 0` and π):
        :math:`x_k \pm R`, so the amplitude (peak to peak) is 2R. Every slip that starts from
        stick starts at (x_s, v_b): the cycle is reached after one slip from any stick.

        Raises:
            ValueError: c > 0, a coefficient law other than a constant, or μ_s <= μ_k.
        """
        check("c", self.c, self.c == 0, "the closed form needs c = 0")
        coefficient = self._law.friction_coefficient
        check("law", self.law,
              coefficient is None or isinstance(coefficient, laws.ConstantFriction),
              "the closed form needs a constant kinetic coefficient")
        mu_k = self.mu(0.0)
        check("mu_static", self.mu_static, self.static_coefficient > mu_k,
              f"the closed form needs mu_static > mu_k = {mu_k:g} (else no stick-slip)")
        omega = math.sqrt(self.k / self.m)
        x_k = mu_k * self.N / self.k
        delta = (self.static_coefficient - mu_k) * self.N / self.k
        radius = math.hypot(delta, self.v_belt / omega)
        phi = math.atan2(self.v_belt / omega, delta)
        stick = 2 * delta / self.v_belt
        period = stick + (math.pi + 2 * phi) / omega
        return LimitCycle(period=period, amplitude=2 * radius, x_min=x_k - radius,
                          x_max=x_k + radius, stick_fraction=stick / period)

    # --- time integration ---------------------------------------------------------------------

    def regularised_law(self, eps: float) -> laws.InterfaceLaw:
        r"""The law of ``method="regularised"``: the interface law with ε = ``eps`` and the
        coefficient :math:`\mu_\varepsilon` below (its friction force, on the mass,
        :math:`F_\varepsilon = \mu_\varepsilon(v_r) N \phi_\varepsilon'(v_r)`: with the smooth
        regularisation :math:`\mu_\varepsilon(v_r) N v_r/\sqrt{v_r^2 + \varepsilon^2}`).

        :math:`\mu_\varepsilon = \mu` when μ_s = μ(0). A static coefficient above μ(0) (the
        classic jump μ_s > μ_k) cannot be carried by the direction regularisation alone
        (:math:`|F_\varepsilon| < \mu(v) N`); it is spread over a Stribeck-type layer,
        :math:`\mu_\varepsilon(v) = \mu(v) + (\mu_s - \mu(0)) e^{-|v|/v_\varepsilon}` with
        :math:`v_\varepsilon = \sqrt{\varepsilon v_b}`, the geometric mean of the two speeds, so
        that both :math:`\varepsilon/v_\varepsilon` and :math:`v_\varepsilon/v_b` vanish as
        ε → 0 and the breakaway force :math:`\max F_\varepsilon` tends to μ_s N.
        """
        jump = self.static_coefficient - self.mu(0.0)
        if jump <= 0:
            return self._law.replace(eps=eps)
        kinetic, v_layer = self._law.coefficient, math.sqrt(eps * self.v_belt)

        def layered(speed: typing.Any, pressure: typing.Any) -> typing.Any:
            return kinetic(speed, pressure) + jump * np.exp(-speed / v_layer)
        return self._law.replace(eps=eps, friction_coefficient=layered)

    def regularised_force(self, v_r: typing.Any, eps: float) -> typing.Any:
        """The friction force on the mass of :meth:`regularised_law` at the relative
        velocity v_r (the mass slips at -v_r on the belt)."""
        return self.regularised_law(eps).friction_force(self.N, -np.asarray(v_r, dtype=float))

    def simulate(self, t_end: float, x0: float | None = None,
                 v0: float | None = None, method: str = "events",
                 eps: float | None = None, rtol: float = 1e-8, atol: float = 1e-10,
                 sample_dt: float | None = None, max_step: float | None = None,
                 observe: Observer | None = None, prefix: str = "belt_") -> BeltResult:
        """Integrate from (x0, v0) over [0, t_end].

        Args:
            t_end: final time.
            x0, v0: initial displacement and velocity; None: steady sliding
                (:meth:`steady_sliding`, 0).
            method: ``"events"`` (stick and slip, events located by
                :func:`~fenicsfriction.events.integrate_hybrid`) or ``"regularised"``
                (the regularised law :meth:`regularised_law` by the same TS, no events).
            eps: the law's regularisation speed ε for ``"regularised"``; None: 1e-3 v_b.
            rtol, atol, sample_dt, max_step, observe, prefix: see
                :func:`~fenicsfriction.events.integrate_hybrid`.

        Returns:
            The :class:`BeltResult`.
        """
        check("method", method, method in ("events", "regularised"),
              "must be 'events' or 'regularised'")
        x0 = self.steady_sliding() if x0 is None else float(x0)
        v0 = 0.0 if v0 is None else float(v0)
        kwargs: dict[str, typing.Any] = {"rtol": rtol, "atol": atol, "sample_dt": sample_dt,
                                         "max_step": max_step, "observe": observe,
                                         "prefix": prefix}
        if method == "regularised":
            eps = 1e-3 * self.v_belt if eps is None else eps
            check_positive("eps", eps)
            law = self.regularised_law(eps)
            hybrid = integrate_hybrid(_Regularised(self, law), [x0, v0], "smooth", t_end,
                                      **kwargs)
            force = law.friction_force(self.N, -(self.v_belt - hybrid.y[:, 1]))
            stick = []
        else:
            if v0 == self.v_belt:
                mode0 = self.mode_at_belt_speed(x0)
            else:
                mode0 = SLIP_FORWARD if v0 < self.v_belt else SLIP_BACKWARD
            hybrid = integrate_hybrid(self, [x0, v0], mode0, t_end, **kwargs)
            force = np.array([self.friction_force(y, mode)
                              for y, mode in zip(hybrid.y, hybrid.modes, strict=True)])
            stick = mode_intervals(hybrid, lambda mode: mode == STICK)
        return BeltResult(t=hybrid.t, x=hybrid.y[:, 0], v=hybrid.y[:, 1],
                          modes=np.array(hybrid.modes), friction_force=force,
                          events=hybrid.events, stick_intervals=stick, hybrid=hybrid,
                          method=method)


class _Regularised:
    """The belt oscillator with a regularised law (:meth:`BeltOscillator.regularised_law`):
    one mode, no events."""

    size = 2

    def __init__(self, oscillator: BeltOscillator, law: laws.InterfaceLaw) -> None:
        self.oscillator, self.law = oscillator, law

    def rhs(self, t: float, y: np.ndarray, mode: str) -> np.ndarray:
        """(ẋ, ẍ) with the regularised friction force."""
        o = self.oscillator
        friction = self.law.friction_force(o.N, -(o.v_belt - y[1]))
        force = friction - o.c * y[1] - o.k * y[0]
        return np.array([y[1], force / o.m])

    def events(self, t: float, y: np.ndarray, mode: str) -> np.ndarray:
        """None: the smooth law has one mode."""
        return np.empty(0)

    def switch(self, t: float, y: np.ndarray, mode: str,
               fired: list[int]) -> tuple[np.ndarray, str]:
        """Never called (no events)."""
        raise AssertionError("the regularised law has no events")
