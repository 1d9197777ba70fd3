r"""The master equation of the earthquake-like model: the distribution Q(x; X) of the contacts'
stretchings x when the slider is at X (Braun (slides), the master equation; Braun & Peyrard
2008, "Modeling friction on a mesoscale: master equation for the earthquakelike model"):

.. math::
    \frac{\partial Q}{\partial X} + \frac{\partial Q}{\partial x} + P(x)\,Q
    = R(x) \int P(\xi)\,Q(\xi; X)\,d\xi, \qquad
    P(x) = \frac{P_c(x)}{\int_x^\infty P_c(\xi)\,d\xi},

with the friction force F(X) = N k ∫ x Q(x; X) dx.

Scheme (characteristics, "shift"): Q is carried as masses q_j at the nodes x_j = x_min + j h,
and the slider advances by ΔX = h, so that the transport is an exact shift by one node. Along
the characteristic from x_j to x_j + h a contact survives with the exact probability
S_j = exp(−∫ P) = s(x_j + h)/s(x_j), s = ∫_x^∞ P_c (the survival function of P_c). The broken
mass b = Σ q_j (1 − S_j) is reborn with the distribution R: a contact broken during the step
is re-formed at a uniformly distributed moment and carried on by the rest of the step, so R's
masses on the cells [x_j − h/2, x_j + h/2] are spread half to x_j, half to x_{j+1} (linear
interpolation of the mean half-step transport). Σ r_j = 1, so Σ q_j is conserved to round-off.
The error of F is O(h²) when the reborn contacts do not break again within a step (P = 0 on R's
support, e.g. R = δ(x) with thresholds > 0), otherwise O(h) (measured by the tests).

The kinetic force is that of the sliding state, the steady solution Q_s of the scheme
(:meth:`MasterEquation.steady_state`): Q_s = shift(S Q_s) + b R with b the broken mass is a
lower bidiagonal system, q_j = S_{j−1} q_{j−1} + b r_j, solved at once and normalised to
Σ q = 1. It carries the scheme's O(h²) error (relaxed newborns: N k ⟨x_s²⟩/(2⟨x_s⟩),
:meth:`MasterEquation.steady_force`, to 1.7e-5 at h = σ/10). The transient from Q = δ(x)
approaches it only over many contact lives when the thresholds' spread σ is narrow (the
broken contacts re-form in step and break again together): at σ = 0.1 x_c the force after
five lives is still 2.5 % above the kinetic one, after 100 lives 2e-9. The force where the
transient was stopped is reported apart, as ``force_at_X_max``.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from fenicsfriction.laws import check, check_positive
from fenicsfriction.results import Record
from fenicsfriction.studies.multicontact.eq_model import EQModel

__all__ = ["MasterEquation", "MasterEquationResult"]

#: where the grid ends: beyond this survival probability of P_c (or below this cumulative
#: probability of R) the neglected mass is below round-off in F
TAIL = 1e-15


@dataclasses.dataclass
class MasterEquationResult(Record):
    """A solution of the master equation from all contacts relaxed, Q(x; 0) = δ(x).

    Attributes:
        X: the slider positions, multiples of h (length).
        F: the friction force N k ∫ x Q dx at X.
        x: the nodes of Q.
        Q: the masses at the nodes at the last X (Σ Q = 1; divide by h for a density).
        kinetic_force: the force of the sliding state, N k Σ x_j q_j over the steady
            solution (:meth:`MasterEquation.steady_state`), whatever X_max is.
        X_max: the last X of the transient (``X[-1]``).
        force_at_X_max: F at X_max, the transient's end (tends to ``kinetic_force`` as
            X_max grows; 2.5 % above it after five lives at σ = 0.1 x_c).
        static_force: max F.
        K_star: −max F'(X), F' by centred differences (the critical stiffness of the
            elastic instability).
        mass_error: max over X of |Σ Q − 1|.
        h: the step ΔX = Δx.
        parameters: the model's :meth:`~EQModel.parameters`.
    """

    X: np.ndarray
    F: np.ndarray
    x: np.ndarray
    Q: np.ndarray
    kinetic_force: float
    X_max: float
    force_at_X_max: float
    static_force: float
    K_star: float
    mass_error: float
    h: float
    parameters: dict


class MasterEquation:
    """The master equation of an :class:`~EQModel` (its N, k, P_c and R) on a grid of step h.

    Args:
        model: the earthquake-like model's interface.
        h: ΔX = Δx (length).
    """

    def __init__(self, model: EQModel, h: float) -> None:
        check_positive("h", h)
        self.model, self.h = model, h
        P_c = model.P_c
        low = 0.0 if model.newborn is None else min(0.0, float(model.newborn.ppf(TAIL)))
        high = max(float(P_c.isf(TAIL)), 2 * h)
        if model.newborn is not None:
            high = max(high, float(model.newborn.isf(TAIL)))
        n_low = int(np.ceil(-low / h))
        self.x = h * np.arange(-n_low, int(np.ceil(high / h)) + 2)
        check("h", h, self.x.size <= 10**7, f"gives {self.x.size} nodes; allowed: <= 1e7")
        self.zero = n_low  # the node x = 0
        sf_here, sf_next = P_c.sf(self.x), P_c.sf(self.x + h)
        self.survival = np.divide(sf_next, sf_here, out=np.zeros_like(self.x),
                                  where=sf_here > 0)
        self.survival[-1] = 0.0  # nothing leaves the grid: its last node breaks for sure
        self.reborn = self._newborn_masses()

    def _newborn_masses(self) -> np.ndarray:
        """R's masses at the nodes, carried on by half a step on average (see the module)."""
        h, newborn = self.h, self.model.newborn
        if newborn is None:
            cells = np.zeros_like(self.x)
            cells[self.zero] = 1.0
        else:
            cells = np.diff(newborn.cdf(np.append(self.x - h / 2, self.x[-1] + h / 2)))
        masses = 0.5 * cells
        masses[1:] += 0.5 * cells[:-1]
        return masses / np.sum(masses)

    def initial(self) -> np.ndarray:
        """All contacts relaxed: Q = δ(x)."""
        q = np.zeros_like(self.x)
        q[self.zero] = 1.0
        return q

    def step(self, q: np.ndarray) -> np.ndarray:
        """Q at X + h from Q at X (masses at the nodes)."""
        kept = q * self.survival
        shifted = np.empty_like(q)
        shifted[0] = 0.0
        shifted[1:] = kept[:-1]
        return shifted + (np.sum(q) - np.sum(kept)) * self.reborn

    def steady_state(self) -> np.ndarray:
        """The masses of the sliding state, the fixed point ``step(q) = q`` with Σ q = 1
        (the lower bidiagonal system of the module's notes, solved by a banded solve)."""
        from scipy import linalg

        bands = np.zeros((2, self.x.size))
        bands[0] = 1.0
        bands[1, :-1] = -self.survival[:-1]
        q = linalg.solve_banded((1, 0), bands, self.reborn)
        return q / np.sum(q)

    def kinetic_force(self) -> float:
        """The force of the sliding state, N k Σ x_j q_j over :meth:`steady_state`."""
        return self.model.n_contacts * self.model.k * float(self.x @ self.steady_state())

    def solve(self, X_max: float) -> MasterEquationResult:
        """Q and F from X = 0 (all contacts relaxed) to ``X_max`` (rounded to a multiple of h)."""
        check_positive("X_max", X_max)
        n = max(2, int(round(X_max / self.h)))
        N_k = self.model.n_contacts * self.model.k
        q = self.initial()
        F = np.empty(n + 1)
        mass_error = 0.0
        F[0] = N_k * float(self.x @ q)
        for i in range(1, n + 1):
            q = self.step(q)
            F[i] = N_k * float(self.x @ q)
            mass_error = max(mass_error, abs(float(np.sum(q)) - 1.0))
        X = self.h * np.arange(n + 1)
        return MasterEquationResult(
            X=X, F=F, x=self.x.copy(), Q=q, kinetic_force=self.kinetic_force(),
            X_max=float(X[-1]), force_at_X_max=float(F[-1]),
            static_force=float(np.max(F)), K_star=float(-np.min(np.gradient(F, self.h))),
            mass_error=mass_error, h=self.h, parameters=self.model.parameters())

    def steady_force(self) -> float:
        """The kinetic force for relaxed newborn contacts (R = δ(x)), by quadrature of the
        steady state Q_s(x) ∝ ∫_x^∞ P_c (x >= 0): N k ∫ x Q_s / ∫ Q_s = N k ⟨x_s²⟩/(2⟨x_s⟩)
        with ⟨·⟩ over P_c restricted to x_s > 0."""
        check("model.newborn", self.model.newborn, self.model.newborn is None,
              "must be None (relaxed newborn contacts) for this closed form")
        from scipy import integrate

        sf = self.model.P_c.sf
        norm = integrate.quad(sf, 0.0, np.inf)[0]
        first = integrate.quad(lambda x: x * sf(x), 0.0, np.inf)[0]
        return self.model.n_contacts * self.model.k * first / norm
