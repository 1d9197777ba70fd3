r"""The block on a moving belt as a rigid body in plane motion (Martins & Oden 1986, Figs. 6, 9).

Three degrees of freedom :math:`q = (u_{xG}, u_{yG}, \theta)`: the displacement of the centre
of mass G and the (small) rotation, counter-clockwise. A rigid motion moves a point X by
:math:`u = (u_{xG} - \theta (Y - Y_G),\; u_{yG} + \theta (X - X_G))`, so on the base
(:math:`Y - Y_G = -H/2`, :math:`s = X - X_G \in [-L/2, L/2]`):

* penetration :math:`d(s) = (-u_{yG} - \theta s - g)_+`,
* slip velocity :math:`w = \dot u_{xG} + \dot\theta H/2 - U_T`.

The same interface law as the FE model (:mod:`fenicsfriction.laws`) is integrated over the base
(per unit breadth, times B0) with Gauss quadrature graded towards the lift-off point, exact for the
paper's exponents. Generalised forces by virtual power:

.. math::
    Q_x = B_0\!\int t_x\,ds + F_s,\quad Q_y = B_0\!\int p\,ds - W,\quad
    Q_\theta = B_0\!\int (p\,s + t_x H/2)\,ds - F_s (h_s - H/2),

with the tractions of :mod:`fenicsfriction.laws`, :math:`p = c_n d^{m_n} + b_n d^{l_n}\dot u_n`
(:func:`~fenicsfriction.laws.normal_traction`) and :math:`t_x = -c_T d^{m_T}\phi_\varepsilon'(w)`
(:func:`~fenicsfriction.laws.friction_traction`),
and the spring force :math:`F_s = -K_x (u_{xG} - \theta (h_s - H/2))` at height :math:`h_s`.
The equations of motion are :math:`M\ddot q + C_v \dot q - Q(q, \dot q) = 0` with
:math:`M = \mathrm{diag}(M, M, I)`; the linearisation (M, C, K̄) is derived analytically and
checked against finite differences in the tests.
"""

from __future__ import annotations

import dataclasses
import typing

import numpy as np

from fenicsfriction.laws import check
from fenicsfriction.numerics import bisect, dense_eigenvalues
from fenicsfriction.results import Record
from fenicsfriction.studies.block.data import BlockData

__all__ = ["RigidBlock", "RigidLoci", "rigid_block_observables", "rigid_loci"]

_GAUSS = tuple((np.polynomial.legendre.leggauss(64)[i] + (1, 0)[i]) / 2 for i in range(2))


@dataclasses.dataclass
class RigidBlock(BlockData):
    """Rigid block on a belt: :class:`~fenicsfriction.studies.block.BlockData` plus inertia.

    Args:
        inertia: moment of inertia about G [10^3 kg cm^2]; None: M (L² + H²)/12 (uniform).
        viscous: linear viscous damping (c_x, c_y, c_θ) on q [10^3 kg s^-1, ..., 10^3 kg cm² s^-1].
        Other parameters: see :class:`~fenicsfriction.studies.block.BlockData`.
    """

    inertia: float = None  # type: ignore[assignment]  # None: set by __post_init__
    viscous: tuple = (0.0, 0.0, 0.0)

    def __post_init__(self):
        if self.inertia is None:
            self.inertia = self.mass * (self.L**2 + self.H**2) / 12
        super().__post_init__()

    def validate(self) -> None:
        super().validate()
        check("inertia", self.inertia, np.isfinite(self.inertia) and self.inertia > 0,
              "must be a finite number > 0")
        check("weight", self.weight, self.weight > 0, "must be > 0")
        check("viscous", self.viscous, len(self.viscous) == 3
              and all(np.isfinite(c) and c >= 0 for c in self.viscous),
              "must be three finite coefficients >= 0")

    @classmethod
    def from_scene(cls, scene: BlockData, **changes: typing.Any) -> RigidBlock:
        """The rigid counterpart of a scene (its :class:`BlockData` fields), with ``changes``.

        A uniform top pressure p of the FE scene is a vertical resultant p L B0 through G, so
        it joins the weight; the law is the scene's, friction coefficient law included.
        """
        shared = {f.name: getattr(scene, f.name) for f in dataclasses.fields(BlockData)}
        shared["weight"] += getattr(scene, "top_pressure", 0.0) * scene.L * scene.B0
        return cls(**{**shared, **changes})

    @classmethod
    def with_modal_damping(cls, ratios: tuple[float, float, float], **data: typing.Any
                           ) -> RigidBlock:
        """A block with viscous damping c_i = 2 ζ_i sqrt(k_i m_i), ζ = ``ratios`` for
        (u_xG, u_yG, θ), k_i the diagonal of K̄ at the frictionless steady state of the block
        ``data`` describes (where K̄ and the mass matrix are diagonal, so the ζ_i are exactly its
        modal damping ratios at μ = 0); the c_i are then kept at every μ (Martins & Oden 1986,
        Figs. 10-12: ζ = 0.005, 0.04, 0.04)."""
        check("ratios", ratios, len(ratios) == 3 and all(np.isfinite(z) and z >= 0
                                                         for z in ratios),
              "must be three finite ratios >= 0")
        law = data.get("law", BlockData().law)
        frictionless = cls(**{**data, "law": law.replace(mu=0.0, friction_coefficient=None)})
        M, _, K = frictionless.linearisation(frictionless.steady_state())
        viscous = tuple(float(2 * z * np.sqrt(k * m))
                        for z, k, m in zip(ratios, np.diag(K), np.diag(M), strict=True))
        return cls(**{**data, "viscous": viscous})

    @property
    def mass_matrix(self) -> np.ndarray:
        return np.diag([self.mass, self.mass, self.inertia])

    # --- base integrals --------------------------------------------------------------------------
    def _contact_interval(self, q: np.ndarray) -> tuple[float, float, bool] | None:
        """Contact part [lo, hi] of the base and whether d vanishes at ``lo`` (else at ``hi``
        or nowhere: full contact)."""
        a, theta = -q[1] - self.law.g, q[2]
        lo, hi = -self.L / 2, self.L / 2
        if theta == 0.0:
            return (lo, hi, False) if a > 0 else None
        s0 = a / theta
        if theta > 0:
            lo_, hi_, at_lo = lo, min(hi, s0), False
        else:
            lo_, hi_, at_lo = max(lo, s0), hi, s0 > lo
        return (lo_, hi_, at_lo) if hi_ > lo_ else None

    def _integrate(self, q: np.ndarray, integrand: typing.Callable[[np.ndarray, np.ndarray],
                   np.ndarray], size: int) -> np.ndarray:
        """B0 ∫ integrand(s, d(s)) ds over the contact part of the base (vector valued).

        64-point Gauss-Legendre on the graded map s = e + (o - e) t^4 from the lift-off point e:
        d^m becomes t^(4m) times a polynomial, so the rule is exact for m in steps of 1/4
        (m_n = 2.5 in the paper) and accurate to round-off otherwise.
        """
        interval = self._contact_interval(q)
        if interval is None:
            return np.zeros(size)
        lo, hi, at_lo = interval
        a, theta = -q[1] - self.law.g, q[2]
        t, weights = _GAUSS
        lift_off = theta != 0.0 and (at_lo or hi < self.L / 2)
        if lift_off:
            e, o = (lo, hi) if at_lo else (hi, lo)
            s_pts = e + (o - e) * t**4
            ds = np.abs(o - e) * 4 * t**3
        else:
            s_pts = lo + (hi - lo) * t
            ds = np.full_like(t, hi - lo)
        d = np.maximum(a - theta * s_pts, 0.0)
        values = np.asarray(integrand(s_pts, d)).reshape(size, -1)
        return self.B0 * values @ (weights * ds)

    # --- residual and its linearisation ----------------------------------------------------------
    def _spring(self, q: np.ndarray) -> float:
        return -self.K_x * (q[0] - q[2] * (self.spring_height - self.H / 2))

    def generalised_forces(self, q: np.ndarray, q_dot: np.ndarray) -> np.ndarray:
        """Q(q, q̇): interface, spring and weight forces on (u_xG, u_yG, θ)."""
        U = self.belt_direction * self.belt_speed
        w = q_dot[0] + q_dot[2] * self.H / 2 - U
        law = self.law

        def integrand(s: np.ndarray, d: np.ndarray) -> np.ndarray:
            p = law.normal_traction(d, -(q_dot[1] + q_dot[2] * s))
            t = law.friction_traction(d, w)
            return np.array([t, p, p * s + t * self.H / 2])  # arrays over s

        Q = self._integrate(q, integrand, 3)
        F_s = self._spring(q)
        return Q + np.array([F_s, -self.weight, -F_s * (self.spring_height - self.H / 2)])

    def residual(self, q: np.ndarray, q_dot: np.ndarray, q_ddot: np.ndarray) -> np.ndarray:
        """R(q, q̇, q̈) = M q̈ + C_v q̇ - Q(q, q̇)."""
        return self.mass_matrix @ q_ddot + np.asarray(self.viscous) * q_dot \
            - self.generalised_forces(np.asarray(q, float), np.asarray(q_dot, float))

    def linearisation(self, q: np.ndarray, q_dot: np.ndarray | None = None
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(M, C, K̄) = (∂R/∂q̈, ∂R/∂q̇, ∂R/∂q) at (q, q̇): the kinematics differentiated by
        hand, the tractions by the law's NumPy derivatives
        (:meth:`~fenicsfriction.laws.InterfaceLaw.friction_traction_derivatives`)."""
        q = np.asarray(q, float)
        q_dot = np.zeros(3) if q_dot is None else np.asarray(q_dot, float)
        U = self.belt_direction * self.belt_speed
        w = q_dot[0] + q_dot[2] * self.H / 2 - U
        law, h2 = self.law, self.H / 2

        def integrand(s, d):
            vn = -(q_dot[1] + q_dot[2] * s)  # normal velocity into the belt
            dp_dd, dp_dvn = law.normal_traction_derivatives(d, vn)
            dt_dd, dt_dw = law.friction_traction_derivatives(d, w)
            zero, one = np.zeros_like(s), np.ones_like(s)
            dd = np.array([zero, -one, -s])  # ∂d/∂q, one column per point
            dp_dq, dt_dq = dp_dd * dd, dt_dd * dd
            dp_dqdot = dp_dvn * np.array([zero, -one, -s])
            dt_dqdot = dt_dw * np.array([one, zero, h2 * one])
            rows = lambda dp, dt: np.array([dt, dp, dp * s + dt * h2])  # noqa: E731
            return np.concatenate([rows(dp_dq, dt_dq), rows(dp_dqdot, dt_dqdot)])

        J = self._integrate(q, integrand, 18)
        dQ_dq, dQ_dqdot = J[:9].reshape(3, 3), J[9:].reshape(3, 3)
        arm = self.spring_height - h2
        spring = -self.K_x * np.array([1.0, 0.0, -arm])  # ∂F_s/∂q
        dQ_dq += np.outer([1.0, 0.0, -arm], spring)
        return self.mass_matrix, np.diag(self.viscous) - dQ_dqdot, -dQ_dq

    # --- solutions -------------------------------------------------------------------------------
    def initial_guess(self) -> np.ndarray:
        law = self.law
        d0 = (self.weight / (self.L * self.B0 * law.c_n)) ** (1 / law.m_n)
        return np.array([self.belt_direction * law.mu * self.weight / self.K_x, -d0 - law.g,
                         0.0])

    def steady_state(self, q0: np.ndarray | None = None, tol: float = 1e-12,
                     max_it: int = 100) -> np.ndarray:
        """Steady sliding Q(q, 0) = 0 by Newton with backtracking, from ``q0``.

        Raises ``RuntimeError`` (naming μ and the residual) if Newton does not converge.
        """
        q = self.initial_guess() if q0 is None else np.array(q0, float)
        zero = np.zeros(3)
        scale = self.weight * np.array([1.0, 1.0, self.L])
        r = self.residual(q, zero, zero)
        for _ in range(max_it):
            if np.max(np.abs(r) / scale) < tol:
                return q
            K = self.linearisation(q)[2]
            step = np.linalg.solve(K, -r)
            alpha = 1.0
            while alpha > 1e-8:
                trial = q + alpha * step
                r_trial = self.residual(trial, zero, zero)
                if np.max(np.abs(r_trial) / scale) < np.max(np.abs(r) / scale):
                    break
                alpha /= 2
            q, r = trial, r_trial
        raise RuntimeError(f"rigid block: Newton did not converge at mu={self.law.mu} "
                           f"(scaled residual {np.max(np.abs(r) / scale):.3e})")

    def eigenvalues(self, q: np.ndarray) -> np.ndarray:
        """Eigenvalues of (λ² M + λ C + K̄) at q (companion form), sorted by |λ|."""
        M, C, K = self.linearisation(q)
        return dense_eigenvalues(K, C, M)


@dataclasses.dataclass
class RigidLoci(Record):
    """Eigenvalues of the rigid block along a μ grid and the flutter onsets between grid points.

    Attributes:
        steps: one row per μ: ``mu``, ``eigenvalues`` ([re, im] with Im λ >= 0 and
            |λ| <= max_frequency) and ``max_re``.
        onsets: μ of each onset (midpoint of the bisection's final interval).
        mu_crit: the first onset, or None.
        unstable_intervals: grid intervals [first, last] of μ where a mode grows.
    """

    steps: list[dict[str, typing.Any]]
    onsets: list[float]
    mu_crit: float | None
    unstable_intervals: list[list[float]]


def rigid_loci(scene: BlockData, targets: typing.Sequence[float] | np.ndarray,
               max_frequency: float, growth_tol: float, onset_tol: float) -> RigidLoci:
    """Eigenvalues of the rigid counterpart of ``scene`` along the μ grid ``targets``, and the
    onsets of growth between grid points located by bisection.

    Args:
        scene: the block (its :class:`BlockData` fields, see :meth:`RigidBlock.from_scene`).
        targets: the μ grid, increasing.
        max_frequency: eigenvalues with |λ| above it are left out [1/s].
        growth_tol: a mode grows when Re λ > growth_tol |λ|.
        onset_tol: width of the bisection's final interval in μ.

    Returns:
        The :class:`RigidLoci`. Each steady state starts Newton from the previous one.
    """
    q: np.ndarray | None = None
    steps: list[dict[str, typing.Any]] = []

    def values(mu: float) -> np.ndarray:
        nonlocal q
        block = RigidBlock.from_scene(scene, law=scene.law.replace(mu=mu))
        q = block.steady_state(q)
        lam = block.eigenvalues(q)
        return lam[(lam.imag >= 0) & (np.abs(lam) <= max_frequency)]

    def grows(lam: np.ndarray) -> bool:
        return bool(np.any(lam.real > growth_tol * np.abs(lam)))

    for mu in targets:
        lam = values(mu)
        steps.append({"mu": float(mu), "eigenvalues": [[v.real, v.imag] for v in lam],
                      "max_re": float(lam.real.max())})
    flags = [grows(np.array([complex(*v) for v in st["eigenvalues"]])) for st in steps]
    onsets: list[float] = []
    intervals: list[list[float]] = []
    for k in range(1, len(steps)):
        if flags[k] and not flags[k - 1]:
            values(targets[k - 1])  # Newton's warm start for the bisection
            lo, hi = bisect(lambda mu: grows(values(mu)), targets[k - 1], targets[k], onset_tol)
            onsets.append(0.5 * (lo + hi))
            intervals.append([float(targets[k]), float(targets[k])])
        if flags[k] and intervals:
            intervals[-1][1] = float(targets[k])
    return RigidLoci(steps=steps, onsets=onsets, mu_crit=onsets[0] if onsets else None,
                     unstable_intervals=intervals)


def rigid_block_observables(block: RigidBlock, q: typing.Any, q_dot: typing.Any,
                            probe_x: float | None = None) -> dict[str, typing.Any]:
    r"""Forces, motion and contact state of a :class:`~fenicsfriction.studies.block.RigidBlock` at
    (q, q̇), under the names of :meth:`~fenicsfriction.studies.block.BlockModel.dynamics_observer`
    so that :func:`~fenicsfriction.statistics.stick_slip_statistics` and
    :func:`~fenicsfriction.plotting.plot_stick_slip` read FE and rigid runs alike.

    Returns:
        ``normal_force`` B0 ∫ p ds (normal damping included), ``normal_force_elastic``
        B0 ∫ c_n d^{m_n} ds, ``friction_force`` B0 ∫ t_x ds (along x), ``spring_force`` F_s and
        ``spring_elongation`` -F_s/K_x, ``u_yG``, ``v_xG``, ``v_yG``, ``theta``;
        ``slip_velocity`` w = u̇_xG + θ̇ H/2 - U (the same at every base point) and ``contact``:
        ``"open"`` (no penetration anywhere on the base), ``"stick"`` (|w| < ε) or ``"slip"``;
        and at the base point ``probe_x`` (from the rear end, default L/2): ``probe_x``,
        ``probe_u_y``, ``probe_v_x``, ``probe_v_y``, ``probe_slip`` (= w), ``probe_pressure``
        c_n d^{m_n} and ``probe_friction`` (the tangential traction).
    """
    q, q_dot = np.asarray(q, float), np.asarray(q_dot, float)
    check("probe_x", probe_x, probe_x is None or 0 <= probe_x <= block.L,
          f"must lie on the base, in [0, L = {block.L}]")
    law = block.law
    Q = block.generalised_forces(q, q_dot)  # interface integrals + (F_s, -W, -F_s arm)
    spring = block._spring(q)
    w = q_dot[0] + q_dot[2] * block.H / 2 - block.belt_direction * block.belt_speed
    if block._contact_interval(q) is None:
        contact = "open"
    else:
        contact = "stick" if abs(w) < law.eps else "slip"
    elastic = block._integrate(q, lambda s, d: law.pressure(d), 1)[0]
    x = 0.5 * block.L if probe_x is None else float(probe_x)
    s = x - 0.5 * block.L  # from G's vertical
    d = max(-q[1] - law.g - q[2] * s, 0.0)
    friction = law.friction_traction(d, w)
    return {"normal_force": float(Q[1] + block.weight), "normal_force_elastic": float(elastic),
            "friction_force": float(Q[0] - spring), "spring_force": float(spring),
            "spring_elongation": float(-spring / block.K_x),
            "u_yG": float(q[1]), "v_xG": float(q_dot[0]), "v_yG": float(q_dot[1]),
            "theta": float(q[2]), "slip_velocity": float(w), "contact": contact,
            "probe_x": x, "probe_u_y": float(q[1] + q[2] * s),
            "probe_v_x": float(q_dot[0] + q_dot[2] * block.H / 2),
            "probe_v_y": float(q_dot[1] + q_dot[2] * s), "probe_slip": float(w),
            "probe_pressure": float(law.pressure(d)),
            "probe_friction": float(friction)}
