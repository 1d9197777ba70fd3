r"""The slider's nonlinear motion: true stick located by events, or a regularised law.

The equations of motion of the m.d.o.f. slider paper (2003) ("Friction-induced sliding
instability in a multi-degree-of-freedom system with oscillatory normal forces", eqs. 1-12)
with the full friction law, as a :class:`~fenicsfriction.events.HybridSystem` for
:func:`~fenicsfriction.events.integrate_hybrid`.
"""

from __future__ import annotations

import math
import typing

import numpy as np

from fenicsfriction.laws import check
from fenicsfriction.studies.oscillators.slider.model import Slider

__all__ = ["Mode", "SliderMotion"]

#: One entry per contact: +1 / −1 slipping with V_rel ≷ 0, 0 sticking
Mode = tuple[int, ...]

_NORMAL_FORCE_MODELS = ("signed", "absolute", "clipped")

#: q, q̇, N, V_rel, F_req and the normal spring force at one time and state
_ContactState = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


class SliderMotion:
    r"""The slider's nonlinear equations of motion as a
    :class:`~fenicsfriction.events.HybridSystem`.

    State :math:`y = (q, \dot q)` with :math:`q = (y_s, y_1..y_m, x_1..x_m)` (eq. 8). The mode is
    a tuple with one entry per contact: +1 / −1 slipping with :math:`V_{rel} \gtrless 0`, 0
    sticking (:math:`\dot y_i = V_{ref,i}`, eq. 5). Events (each >= 0 while the mode holds,
    scaled by :math:`V_{ref,i}` and :math:`\mu_s \max|N_i|`): slipping, :math:`\pm V_{rel,i}`;
    sticking, :math:`\mu_s |N_i| - |F_{req,i}|` with the
    force that keeps the contact on the surface,
    :math:`F_{req,i} = c_{t,i}(V_{ref,i} - \dot y_s) + k_{t,i}(y_i - y_s)`. At an event a
    contact whose required force is within the static bound sticks, else it slips in the
    direction of that force.

    Args:
        slider: the :class:`Slider`.
        normal_force: how N enters friction — ``"signed"`` (eq. 21, the paper's linear
            model: N may change sign), ``"absolute"`` (eq. 3: |N|), ``"clipped"`` (max(N, 0):
            the contact opens when N would pull).
        coupled: the surface input reads :math:`X_i = V_{ref,i} t - y_i` (the contact's own
            motion shifts the roughness under it, §2 of the paper) instead of eq. 14's
            :math:`X_i = V_{ref,i} t`.
        eps: None: true stick by events; > 0: no stick, each contact's law regularised with
            ε = ``eps`` (:meth:`fenicsfriction.laws.InterfaceLaw.friction_force`; the smooth
            regularisation: :math:`F = \mu(V) N\,V/\sqrt{V^2+\varepsilon^2}`), one mode, no
            events.
        linearised: friction linearised about steady sliding (eq. 25),
            :math:`F_i = (\mu^*_i - S_i \dot y_i) N_i(t)` with the signed N, no stick, no
            events: the linear periodic system of :meth:`Slider.averaged` and
            :meth:`Slider.floquet`, forcing included, integrated in time.
    """

    def __init__(self, slider: Slider, normal_force: str = "signed", coupled: bool = False,
                 eps: float | None = None, linearised: bool = False) -> None:
        check("normal_force", normal_force, normal_force in _NORMAL_FORCE_MODELS,
              f"must be one of {_NORMAL_FORCE_MODELS}")
        check("eps", eps, eps is None or (math.isfinite(eps) and eps > 0),
              "must be None (events) or a number > 0 (regularised law)")
        check("linearised", linearised, not linearised or (
            eps is None and normal_force == "signed" and not coupled),
            "the linearised friction of eq. 25 takes the signed N, no eps and no coupling")
        self.slider, self.normal_force, self.coupled, self.eps = slider, normal_force, coupled, eps
        self.linearised = linearised
        m = slider.m
        self.size = 2 * (2 * m + 1)
        self._M, self._C, self._K = slider.matrices()
        self._Minv = 1.0 / np.diag(self._M)

        def get(name: str) -> np.ndarray:
            return np.array([getattr(c, name) for c in slider.contacts])

        self._mass, self._k_t, self._c_t = get("mass"), get("k_t"), get("c_t")
        self._k_n, self._c_n, self._N0 = get("k_n"), get("c_n"), get("normal_load")
        self._h, self._lam, self._V = get("roughness"), get("wavelength"), get("surface_speed")
        self._f = get("normal_force_factor")
        self._laws = [c.law if eps is None else c.law.replace(eps=eps) for c in slider.contacts]
        self._mu_s = np.array([c.static_coefficient for c in slider.contacts])
        self._mu_star = np.array([c.mu_star() for c in slider.contacts])
        self._force_scale = np.maximum(self._mu_s, 1e-3) * np.array(
            [c.normal_load + c.fluctuation_amplitude() for c in slider.contacts])
        self._tangential = slice(1, m + 1)
        self._normal = slice(m + 1, 2 * m + 1)

    def _contact_state(self, t: float, y: np.ndarray) -> _ContactState:
        """The pieces every mode needs: q, q̇, N, V_rel, F_req and the normal spring force."""
        n = self.size // 2
        q, v = y[:n], y[n:]
        ys, yi, xi = q[0], q[self._tangential], q[self._normal]
        vs, vi, vxi = v[0], v[self._tangential], v[self._normal]
        X = self._V * t - (yi if self.coupled else 0.0)
        X_dot = self._V - (vi if self.coupled else 0.0)
        phase = 2 * np.pi * X / self._lam
        x_in = self._h * np.sin(phase)
        x_in_dot = self._h * 2 * np.pi / self._lam * np.cos(phase) * X_dot
        normal_spring = self._c_n * (vxi - x_in_dot) + self._k_n * (xi - x_in)
        N = self._N0 - self._f * normal_spring        # N_o + f_N m ẍ, m ẍ = −(spring + dashpot)
        if self.normal_force == "absolute":
            N = np.abs(N)
        elif self.normal_force == "clipped":
            N = np.maximum(N, 0.0)
        V_rel = self._V - vi
        F_req = self._c_t * (self._V - vs) + self._k_t * (yi - ys)
        return q, v, N, V_rel, F_req, normal_spring

    def friction(self, t: float, y: np.ndarray, mode: Mode) -> np.ndarray:
        """Friction force on each contact (+ along the surface's motion); the reaction F_req
        for a sticking contact.

        Args:
            t: time.
            y: the state (q, q̇).
            mode: the :data:`Mode`.

        Returns:
            F_i of each contact.
        """
        return self._friction(self._contact_state(t, y), mode)

    def _friction(self, state: _ContactState, mode: Mode) -> np.ndarray:
        _, _, N, V_rel, F_req, _ = state
        if self.linearised:  # μ(V_rel) ≈ μ* + S (V_rel − V_ref) = μ* − S ẏ_i
            return (self._mu_star - self.slider.slopes * (self._V - V_rel)) * N
        if self.eps is not None:  # the contact slips at -V_rel on the surface
            return np.array([law.friction_force(n, -V)
                             for law, n, V in zip(self._laws, N, V_rel, strict=True)])
        mu = np.array([law.coefficient(abs(V), n)
                       for law, n, V in zip(self._laws, N, V_rel, strict=True)])
        sign = np.array(mode, dtype=float)
        return np.where(sign == 0, F_req, mu * N * sign)

    def contact_forces(self, t: float, y: np.ndarray, mode: Mode
                       ) -> tuple[np.ndarray, np.ndarray]:
        """(N, F): normal and friction force of each contact, from one contact-state
        evaluation.

        Args:
            t: time.
            y: the state (q, q̇).
            mode: the :data:`Mode`.

        Returns:
            (N_i, F_i) of each contact.
        """
        state = self._contact_state(t, y)
        return state[2], self._friction(state, mode)

    def rhs(self, t: float, y: np.ndarray, mode: Mode) -> np.ndarray:
        """dy/dt = (q̇, M⁻¹(forces)) in ``mode``; a sticking contact moves with its surface."""
        n = self.size // 2
        state = self._contact_state(t, y)
        q, v, normal_spring = state[0], state[1], state[5]
        force = -self._C @ v - self._K @ q
        force[self._normal] = -normal_spring            # the normal d.o.f. see the surface
        force[self._tangential] += self._friction(state, mode)
        a = force * self._Minv
        if self.eps is None:
            stick = np.flatnonzero(np.array(mode) == 0)
            a[1 + stick] = 0.0                           # eq. 5: ÿ_i = 0 while sticking
        out = np.empty_like(y)
        out[:n], out[n:] = v, a
        if self.eps is None:
            out[1 + stick] = self._V[stick]
        return out

    def events(self, t: float, y: np.ndarray, mode: Mode) -> np.ndarray:
        """Per contact, >= 0 while ``mode`` holds: ±V_rel/V_ref slipping, (μ_s|N| − |F_req|)
        scaled sticking; none for the regularised or linearised law."""
        if self.eps is not None or self.linearised:
            return np.zeros(0)
        _, _, N, V_rel, F_req, _ = self._contact_state(t, y)
        sign = np.array(mode, dtype=float)
        # scaled to O(1) (by V_ref and μ_s max|N|) so that one absolute event tolerance fits all
        return np.where(sign == 0, (self._mu_s * np.abs(N) - np.abs(F_req)) / self._force_scale,
                        sign * V_rel / self._V)

    def switch(self, t: float, y: np.ndarray, mode: Mode,
               fired: list[int]) -> tuple[np.ndarray, Mode]:
        """At V_rel = 0: stick if the required force is within the static bound and the
        contact was slipping, else slip in the direction of the required force."""
        _, _, N, _, F_req, _ = self._contact_state(t, y)
        y, new_mode = y.copy(), list(mode)
        n = self.size // 2
        for i in fired:
            y[n + 1 + i] = self._V[i]                    # V_rel = 0 at either kind of event
            holds = abs(F_req[i]) < self._mu_s[i] * abs(N[i]) and new_mode[i] != 0
            new_mode[i] = 0 if holds else (1 if F_req[i] > 0 else -1)
        return y, tuple(new_mode)

    def initial_state(self, perturbation: typing.Sequence[float] = ()) -> np.ndarray:
        """Steady sliding: the mean tangential position (eq. 13) at rest, the normal d.o.f. on
        their steady response (eq. 17); ``perturbation`` is added to (ẏ_s, ẏ_1, …)."""
        m = self.slider.m
        y = np.zeros(self.size)
        y[:m + 1] = self.slider.steady_sliding()
        for i, c in enumerate(self.slider.contacts):
            X = c.normal_amplitude()
            y[m + 1 + i] = X.imag
            y[self.size // 2 + m + 1 + i] = (1j * c.omega * X).imag
        p = np.asarray(perturbation, dtype=float)
        y[self.size // 2: self.size // 2 + p.size] += p
        return y

    def slip_mode(self) -> Mode:
        """Every contact slipping forward (V_rel > 0): the mode of steady sliding."""
        return (1,) * self.slider.m
