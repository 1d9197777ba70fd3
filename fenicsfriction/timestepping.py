r"""Second-order time stepping by PETSc TS without a mesh: the driver shared by the finite
element dynamics (:class:`fenicsfriction.dynamics.DynamicsSolver`) and the few-d.o.f. models
(:class:`ReducedDynamics`, dense and sequential).

The default scheme is PETSc's generalized-α method for second-order systems (``TSALPHA2``),
Newton (SNES) at each step from a constant-velocity predictor, with the step cut back to a
quarter when Newton fails and grown back afterwards (see :class:`Alpha2Integrator`). It imports
petsc4py only (no dolfinx).
"""

from __future__ import annotations

import time
import typing

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np

from fenicsfriction.laws import check
from fenicsfriction.petsc_options import (
    RoundoffConvergence,
    callback_error,
    options_with_defaults,
)

__all__ = ["DEFAULT_OPTIONS", "Alpha2Integrator", "DynamicsError", "ReducedDynamics"]

ArrayLike: typing.TypeAlias = typing.Any  # an array of floats, or a float for one d.o.f.


#: PETSc options of the TS (generalized-α, fixed steps, Newton with LU), under the solver's
#: prefix; options in the database win.
DEFAULT_OPTIONS = {
    "ts_type": "alpha2",
    "ts_alpha_radius": 1.0,
    "ts_adapt_type": "none",
    "ts_max_snes_failures": -1,
    "ts_max_reject": 20,
    "ts_exact_final_time": "matchstep",
    "snes_type": "newtonls",
    "snes_linesearch_type": "bt",
    "snes_rtol": 1e-10,
    "snes_max_it": 10,  # converged steps take 2-4; a cycling Newton is cut back sooner
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
}


#: serial systems up to this size are factorised by PETSc's own LU, which on a few hundred
#: dofs costs a fraction of MUMPS's per-call overhead (the block on the paper's 126-dof mesh:
#: a time step twice as fast); larger or distributed ones by MUMPS
SMALL_SYSTEM = 5000


def linear_solver_defaults(comm: typing.Any, size: int) -> dict[str, str]:
    """The LU package for a system of ``size`` unknowns on ``comm`` (see SMALL_SYSTEM)."""
    small = comm.size == 1 and size <= SMALL_SYSTEM
    return {"pc_factor_mat_solver_type": "petsc" if small else "mumps",
            **({"pc_factor_mat_ordering_type": "nd"} if small else {})}


class DynamicsError(RuntimeError):
    """The time integration stopped before the final time; ``records`` holds the steps done."""

    def __init__(self, message: str, records: list):
        super().__init__(message)
        self.records = records


class Alpha2Integrator:
    """PETSc TS (TSALPHA2 by default) on a second-order system R(t, x, ẋ, ẍ) = 0: the set-up,
    the Newton stopping test, the cut-back and regrowth of the step, and the run loop with its
    records, shared by the FE solver and the few-d.o.f. models of the studies
    (:class:`ReducedDynamics`).

    A subclass provides the residual ``_F(ts, t, x, xdot, xddot, F)``, the Jacobian
    ``_J(ts, t, x, xdot, xddot, shift_v, shift_a, J, P)`` (which must call
    ``self.convergence.jacobian_assembled(J)``), ``_load(x, xdot, xddot)`` (put an accepted state
    where ``observe`` reads it) and ``_state()`` (the initial displacement and velocity vectors,
    which receive the final state).

    Newton starts each step from the constant-velocity predictor
    :math:`x_{n+1} = x_n + \\Delta t\\,\\dot x_n` (``predictor=True``, the default), not from
    PETSc's :math:`x_{n+1} = x_n`, which with Newmark's β = 1/4 means
    :math:`\\dot x_{n+1} = -\\dot x_n`: Newton would start every contact point of a body that
    slides with the belt at rest relative to the ground, slipping at −U_T, across the
    regularisation band |u̇_T − U_T| < ε of a sticking point, where the friction force turns
    by 2 c_T d^{m_T} within 2ε and Newton cycles when ε is small. From the predictor a sticking
    point starts at its last slip speed. Only the starting point changes: the step still solves
    R = 0 to the same tolerance. (Block on a belt, ε = 1e-3 cm/s, dt = 1e-5 s, the
    first 10 ms: 2451 Newton iterations and 70 cut-backs instead of 24150 and 1546.)

    Attributes:
        ts: the PETSc TS, exposed for monitoring or further configuration.
        fixed_steps: no error control (``ts_adapt_type none``): a cut step grows back.
        convergence: the Newton stopping test (its ``atol_used``: the last tolerance).
    """

    def __init__(self, comm: typing.Any, prefix: str, F: PETSc.Vec, J: PETSc.Mat,
                 options: dict | None, atol: float, predictor: bool = True):
        check("atol", atol, np.isfinite(atol) and atol > 0, "must be a finite number > 0")
        self.ts = PETSc.TS().create(comm)
        self.ts.setOptionsPrefix(prefix)
        self.ts.setI2Function(self._F, F)
        self.ts.setI2Jacobian(self._J, J)
        defaults = {**DEFAULT_OPTIONS, **linear_solver_defaults(comm, F.getSize()),
                    "snes_atol": atol, **(options or {})}
        #: the defaults a subclass keeps in place during the run (AMG builds its levels, and
        #: reads their options, at the first step)
        self.run_defaults: dict = {}
        self._defaults = defaults
        with options_with_defaults(prefix, defaults) as opts:
            self.ts.setFromOptions()
            # petsc4py 3.18 does not wrap TSAdapt: read the choice from the options
            self.fixed_steps = opts.getString("ts_adapt_type") == "none"
        self.convergence = RoundoffConvergence(self.ts.getSNES())
        self.ts.getSNES().setConvergenceTest(self.convergence)
        if predictor:
            self.ts.getSNES().setInitialGuess(self._predict)

    def _predict(self, snes: PETSc.SNES, x: PETSc.Vec) -> None:
        """Newton's starting point x_n + Δt ẋ_n (TS holds x_n, ẋ_n until the step is accepted;
        Δt is the step being tried, cut back or not)."""
        x_n, v_n = self.ts.getSolution2()
        x_n.copy(x)
        x.axpy(self.ts.getTimeStep(), v_n)

    def _F(self, ts, t, x, xdot, xddot, F):
        raise NotImplementedError

    def _J(self, ts, t, x, xdot, xddot, shift_v, shift_a, J, P):
        raise NotImplementedError

    def _load(self, x: PETSc.Vec, xdot: PETSc.Vec, xddot: PETSc.Vec | None) -> None:
        raise NotImplementedError

    def _state(self) -> tuple[PETSc.Vec, PETSc.Vec]:
        raise NotImplementedError

    def run(self, t_end: float, dt: float,
            observe: typing.Callable[[float], dict] | None = None,
            on_step: typing.Callable[[dict], None] | None = None,
            keep_records: bool = True) -> list[dict]:
        """Integrate from t = 0 to ``t_end`` with (initial) step ``dt``.

        Args:
            observe: called after every accepted step (fields hold the state), its dict is
                merged into the step's record.
            on_step: called with each record (progress output, field output).
            keep_records: return (and attach to a :class:`DynamicsError`) every record; False
                for a long run whose ``on_step`` streams them: the memory then stays flat.

        Returns:
            One record per accepted step (and one for t = 0; none if not ``keep_records``):
            ``time``, ``dt``,
            ``newton_iterations`` (rejected attempts included), ``rejected_steps`` (cut-backs
            and error-control rejections before this step), ``wall_time_s`` and what
            ``observe`` adds.

        Raises:
            DynamicsError: TS stopped early (e.g. too many step rejections); the fields hold
                the last accepted state and ``error.records`` the steps done.
        """
        check("t_end", t_end, t_end > 0, "must be > 0")
        check("dt", dt, 0 < dt <= t_end, f"must lie in (0, t_end = {t_end}]")
        u, v = (vec.copy() for vec in self._state())
        self.ts.setSolution2(u, v)
        self.ts.setTime(0.0)
        self.ts.setStepNumber(0)
        self.ts.setTimeStep(dt)
        self.ts.setMaxTime(t_end)
        # no step limit unless the user set one (-PREFIX_ts_max_steps): then reaching it
        # before t_end is a stop, reported as such
        max_steps = PETSc.Options(self.ts.getOptionsPrefix()).getInt("ts_max_steps", 10**9)
        self.ts.setMaxSteps(max_steps)
        records: list[dict] = []
        clock = [time.perf_counter(), 0, 0]
        last_time = [0.0]  # of the last accepted step

        def regrow(ts):  # after a cut-back, back to the step asked for (not past t_end)
            remaining = t_end - ts.getTime()
            if self.fixed_steps and ts.getTimeStep() < min(dt, remaining):
                ts.setTimeStep(min(2.0 * ts.getTimeStep(), dt, remaining))

        def monitor(ts, step, t, x):
            snes_its, rejected = ts.getSNESIterations(), ts.getStepRejections()
            record = {"time": float(t), "dt": 0.0,
                      "newton_iterations": snes_its - clock[1],
                      "rejected_steps": rejected - clock[2],
                      "wall_time_s": time.perf_counter() - clock[0]}
            clock[:] = time.perf_counter(), snes_its, rejected
            if step:  # the fields hold the last residual evaluation: load the accepted state
                self._load(x, ts.getSolution2()[1], None)
                record["dt"] = float(t - last_time[0])
            last_time[0] = float(t)
            if observe is not None:
                record.update(observe(float(t)))
            if keep_records:
                records.append(record)
            if on_step is not None:
                on_step(record)

        self.ts.setMonitor(monitor)
        self.ts.setPostStep(regrow)
        error = None
        try:
            with options_with_defaults(self.ts.getOptionsPrefix(), self.run_defaults):
                self.ts.solve(u)
        except PETSc.Error as err:  # e.g. a NaN in the error estimate: report, keep the state
            cause = callback_error(err)
            if not isinstance(cause, PETSc.Error):  # from a monitor (an interrupt): not a failure
                self.ts.cancelMonitor()
                self.ts.setPostStep(None)
                raise cause from None
            error = cause
        self.ts.cancelMonitor()
        self.ts.setPostStep(None)
        reason = self.ts.getConvergedReason()
        x, x_dot = self.ts.getSolution2()
        self._load(x, x_dot, None)  # also after a failure: the last accepted state
        for target, vec in zip(self._state(), (x, x_dot), strict=True):
            vec.copy(target)
        u.destroy()
        v.destroy()
        if error is not None:
            raise DynamicsError(f"TS failed at t = {self.ts.getTime():.6g} after "
                                f"{self.ts.getStepNumber()} steps with PETSc error {error.ierr} "
                                f"(see the PETSc trace above); the fields hold the last "
                                f"accepted state", records) from error
        if reason < 0:
            raise DynamicsError(f"TS stopped at t = {self.ts.getTime():.6g} with reason "
                                f"{reason} after {self.ts.getStepNumber()} steps", records)
        if reason == PETSc.TS.ConvergedReason.CONVERGED_ITS:
            raise DynamicsError(f"TS stopped at t = {self.ts.getTime():.6g}, before t_end = "
                                f"{t_end:.6g}: the step limit ts_max_steps = {max_steps} was "
                                "reached", records)
        return records


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
