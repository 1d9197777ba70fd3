r"""Time integration of the few-d.o.f. models: PETSc TS (TSALPHA2) without a mesh.

:class:`ReducedDynamics` integrates any model offering

* ``residual(q, q_dot, q_ddot) -> ndarray`` (size n), the equations of motion R = 0, and
* ``linearisation(q, q_dot) -> (M, C, K)`` = (∂R/∂q̈, ∂R/∂q̇, ∂R/∂q), dense n × n,

with the shared set-up, Newton stopping test, cut-back and run loop of
:class:`~fenicsfriction.timestepping.Alpha2Integrator` (sequential, on ``MPI.COMM_SELF``: every rank
integrates the same small system). The Jacobian TS asks for is :math:`K + s_v C + s_a M`.

:class:`BouncingMass` is the smallest such model with the interface's normal law: a mass under
gravity on a compliant foundation, whose periods are known in closed form (linear foundation,
also with flight) or by an energy quadrature (power law). :func:`rigid_block_observables` reads
the forces and the contact state of a :class:`~fenicsfriction.reduced.RigidBlock`.
"""

from __future__ import annotations

import dataclasses
import typing

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np

from fenicsfriction import laws
from fenicsfriction.laws import check
from fenicsfriction.timestepping import Alpha2Integrator

if typing.TYPE_CHECKING:
    from fenicsfriction.reduced.rigid_block import RigidBlock

ArrayLike: typing.TypeAlias = typing.Any  # an array of floats, or a float for one d.o.f.

__all__ = ["BouncingMass", "ReducedDynamics", "rigid_block_observables"]


class ReducedDynamics(Alpha2Integrator):
    """Generalized-α (TSALPHA2) integration of a few-d.o.f. model, dense and sequential.

    Args:
        model: offers ``residual(q, q_dot, q_ddot)`` and ``linearisation(q, q_dot)``.
        q0, q_dot0: initial displacement and velocity (n values each).
        prefix: PETSc options prefix of the TS (and its SNES/KSP/PC).
        options: defaults over :data:`~fenicsfriction.timestepping.DEFAULT_OPTIONS` (LU by PETSc's
            own dense factorisation instead of MUMPS); options in the database win.
        atol: absolute Newton tolerance on the residual (force units); None: 1e-10 times the
            model's ``weight`` if it has a positive one, else 1e-10.

    Attributes:
        q, q_dot: the current state (NumPy arrays): the initial one, the accepted step while
            ``observe`` runs, the final one after :meth:`run`. Assigning to them before a run
            sets its initial state; a second run continues from the final state (the time
            restarts at 0).

    With the default ρ∞ = 1 the scheme advances (q, q̇) by the implicit midpoint rule, and the
    starting acceleration does not enter. With ρ∞ < 1 it does, and PETSc 3.18's start
    (``TSAlpha_Restart``) estimates it twice too large: a free fall at ρ∞ = 0.5 keeps a
    velocity error g h/6 after the first step.
    """

    def __init__(self, model: typing.Any, q0: ArrayLike, q_dot0: ArrayLike,
                 prefix: str = "reduced_", options: dict | None = None,
                 atol: float | None = None):
        q0, q_dot0 = (np.array(x, dtype=float).ravel() for x in (q0, q_dot0))
        check("q0", q0, q0.size > 0 and bool(np.all(np.isfinite(q0))), "must be finite numbers")
        check("q_dot0", q_dot0, q_dot0.shape == q0.shape and bool(np.all(np.isfinite(q_dot0))),
              f"must be {q0.size} finite numbers, like q0")
        self.model = model
        self.q, self.q_dot = q0, q_dot0
        if atol is None:
            weight = float(getattr(model, "weight", 0.0) or 0.0)
            atol = 1e-10 * (weight if weight > 0 else 1.0)
        n = q0.size
        comm = MPI.COMM_SELF
        self._u, self._v, F = (PETSc.Vec().createSeq(n, comm=comm) for _ in range(3))
        J = PETSc.Mat().createDense((n, n), comm=comm)
        J.setUp()
        self._rows = np.arange(n, dtype=PETSc.IntType)
        super().__init__(comm, prefix, F, J,
                         {"pc_factor_mat_solver_type": "petsc", **(options or {})}, atol)

    def _state(self) -> tuple[PETSc.Vec, PETSc.Vec]:
        self._u.setArray(self.q)
        self._v.setArray(self.q_dot)
        return self._u, self._v

    def _load(self, x: typing.Any, xdot: typing.Any, xddot: typing.Any) -> None:
        """Copy an accepted state into ``q`` and ``q_dot`` (the acceleration is not kept)."""
        self.q = x.getArray(readonly=True).copy()
        self.q_dot = xdot.getArray(readonly=True).copy()

    def _F(self, ts, t, x, xdot, xddot, F):
        F.setArray(self.model.residual(*(v.getArray(readonly=True) for v in (x, xdot, xddot))))

    def _J(self, ts, t, x, xdot, xddot, shift_v, shift_a, J, P):
        M, C, K = self.model.linearisation(x.getArray(readonly=True),
                                           xdot.getArray(readonly=True))
        J.setValues(self._rows, self._rows, np.asarray(K + shift_v * C + shift_a * M).ravel())
        J.assemble()
        self.convergence.jacobian_assembled(J)


@dataclasses.dataclass
class BouncingMass:
    r"""A mass under gravity on a compliant foundation, one d.o.f.: the vertical displacement
    y (upward; y = 0: the foundation's unloaded surface).

    The foundation presses with the normal law of :mod:`fenicsfriction.laws` over an area A:

    .. math::
        m\ddot y + W - A\left(c_n d^{m_n} + b_n d^{l_n}(-\dot y)\right) = 0,
        \qquad d = (-y)_+,

    so that the mass flies ballistically (ÿ = -W/m) once d = 0.

    Args:
        mass: m [10^3 kg], > 0.
        weight: W = m g [10^3 kg cm s^-2], > 0.
        c_n, m_n: foundation pressure c_n d^{m_n} [10^3 kg cm^(-1-m_n) s^-2], exponent >= 1.
        area: contact area A [cm^2], > 0.
        b_n, l_n: normal damping b_n d^{l_n} (-ẏ), >= 0, exponent >= 1 (None: m_n).

    Defaults: the block of Martins & Oden 1986 (M = 0.45, W = 450, c_n = 1e10, m_n = 2.5, A = L B0).
    """

    mass: float = 0.45
    weight: float = 450.0
    c_n: float = 1e10
    m_n: float = 2.5
    area: float = 48.8 * 30.5
    b_n: float = 0.0
    l_n: float = None  # type: ignore[assignment]  # None: set by __post_init__

    def __post_init__(self):
        if self.l_n is None:
            self.l_n = self.m_n
        for name in ("mass", "weight", "area"):
            value = getattr(self, name)
            check(name, value, isinstance(value, (int, float)) and np.isfinite(value)
                  and value > 0, "must be a finite number > 0")
        laws.InterfaceLaw(c_n=self.c_n, m_n=self.m_n, b_n=self.b_n, l_n=self.l_n)  # validates

    @property
    def gravity(self) -> float:
        """g = W / m [cm s^-2]."""
        return self.weight / self.mass

    def equilibrium(self) -> float:
        """Rest position y0 = -d0 with d0 = (W / (c_n A))^(1/m_n)."""
        return -(self.weight / (self.c_n * self.area)) ** (1.0 / self.m_n)

    def foundation_force(self, q: ArrayLike, q_dot: ArrayLike) -> np.ndarray:
        """Upward force of the foundation A (c_n d^{m_n} + b_n d^{l_n} (-ẏ))."""
        y, y_dot = np.asarray(q, float), np.asarray(q_dot, float)
        d = laws.penetration(-y)
        return self.area * (laws.normal_pressure(d, self.c_n, self.m_n)
                            + laws.normal_damping_pressure(d, -y_dot, self.b_n, self.l_n))

    def residual(self, q: ArrayLike, q_dot: ArrayLike, q_ddot: ArrayLike) -> np.ndarray:
        """R = m ÿ + W - foundation force."""
        return self.mass * np.asarray(q_ddot, float) + self.weight \
            - self.foundation_force(q, q_dot)

    def linearisation(self, q: ArrayLike, q_dot: ArrayLike | None = None
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(M, C, K) = (∂R/∂ÿ, ∂R/∂ẏ, ∂R/∂y) as 1 × 1 arrays; out of contact (y >= 0)
        C = K = 0 (d^0 would read 1 at d = 0 for a linear law)."""
        y = float(np.asarray(q, float).ravel()[0])
        y_dot = 0.0 if q_dot is None else float(np.asarray(q_dot, float).ravel()[0])
        if y >= 0:
            return np.array([[self.mass]]), np.zeros((1, 1)), np.zeros((1, 1))
        d = -y
        stiffness = self.m_n * self.c_n * d ** (self.m_n - 1) \
            + self.l_n * self.b_n * d ** (self.l_n - 1) * (-y_dot)
        return (np.array([[self.mass]]), np.array([[self.area * self.b_n * d**self.l_n]]),
                np.array([[self.area * stiffness]]))

    def energy(self, q: ArrayLike, q_dot: ArrayLike) -> np.ndarray:
        """Kinetic + foundation c_n A d^{m_n+1}/(m_n+1) + gravity W y (conserved if b_n = 0)."""
        y, y_dot = np.asarray(q, float), np.asarray(q_dot, float)
        d = laws.penetration(-y)
        return 0.5 * self.mass * y_dot**2 \
            + self.c_n * self.area * d ** (self.m_n + 1) / (self.m_n + 1) + self.weight * y


def rigid_block_observables(block: RigidBlock, q: ArrayLike, q_dot: ArrayLike,
                            probe_x: float | None = None) -> dict[str, typing.Any]:
    r"""Forces, motion and contact state of a :class:`~fenicsfriction.reduced.RigidBlock` at
    (q, q̇), under the names of :meth:`~fenicsfriction.scenes.block.BlockModel.dynamics_observer`
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
    Q = block.generalised_forces(q, q_dot)  # interface integrals + (F_s, -W, -F_s arm)
    spring = block._spring(q)
    w = q_dot[0] + q_dot[2] * block.H / 2 - block.belt_direction * block.belt_speed
    if block._contact_interval(q) is None:
        contact = "open"
    else:
        contact = "stick" if abs(w) < block.eps else "slip"
    elastic = block._integrate(q, lambda s, d: block.c_n * d**block.m_n, 1)[0]
    x = 0.5 * block.L if probe_x is None else float(probe_x)
    s = x - 0.5 * block.L  # from G's vertical
    d = max(-q[1] - block.g - q[2] * s, 0.0)
    friction = laws.friction_traction(d, w, block.mu * block.c_n, block.m_T, block.eps,
                                      block.regularisation)
    return {"normal_force": float(Q[1] + block.weight), "normal_force_elastic": float(elastic),
            "friction_force": float(Q[0] - spring), "spring_force": float(spring),
            "spring_elongation": float(-spring / block.K_x),
            "u_yG": float(q[1]), "v_xG": float(q_dot[0]), "v_yG": float(q_dot[1]),
            "theta": float(q[2]), "slip_velocity": float(w), "contact": contact,
            "probe_x": x, "probe_u_y": float(q[1] + q[2] * s),
            "probe_v_x": float(q_dot[0] + q_dot[2] * block.H / 2),
            "probe_v_y": float(q_dot[1] + q_dot[2] * s), "probe_slip": float(w),
            "probe_pressure": float(laws.normal_pressure(d, block.c_n, block.m_n)),
            "probe_friction": float(friction)}

