r"""Problem 1ε, dynamics: :math:`R(u, \dot u, \ddot u; v) = 0` integrated by PETSc TS.

The default scheme is PETSc's generalized-α method for second-order systems (``TSALPHA2``;
Newmark's average acceleration is ``-dynamics_ts_alpha_radius 1``), with Newton (SNES, MUMPS)
at each step. TS asks for

* the residual :math:`F(t, u, \dot u, \ddot u) = R(u, \dot u, \ddot u)` — the one residual of
  :mod:`fenicsfriction.forms`, nothing rewritten;
* its Jacobian :math:`\partial R/\partial u + s_v\,\partial R/\partial \dot u
  + s_a\,\partial R/\partial \ddot u`, compiled once with the shifts :math:`s_v, s_a` as
  ``fem.Constant``.

Steps: fixed (``-dynamics_ts_adapt_type none``, the default) or adaptive
(``-dynamics_ts_adapt_type basic``, error-controlled). A step whose Newton solve fails is
retried with a quarter of the step (``ts_max_snes_failures = -1``): the cut-back of seed 001,
whose Newton iterations cycle across the steep part of φ_ε at slide-to-stick transitions when ε
is small and the step large. With fixed steps the step then grows back (doubling after each
accepted step) to the one asked for, so a transition costs a few small steps, not the rest of
the run. Newton stops on the residual (atol raised to its round-off floor, see
:class:`~fenicsfriction.assembly.RoundoffConvergence`), never on the step length.
Options live under the prefix (default ``dynamics_``).
"""

from __future__ import annotations

import time
import typing

import numpy as np
import ufl
from dolfinx import fem

import dolfinx.fem.petsc  # noqa: F401

from mpi4py import MPI
from petsc4py import PETSc

from fenicsfriction import _compat
from fenicsfriction.assembly import (RoundoffConvergence, assemble_jacobian, assemble_residual,
                                     options_with_defaults)
from fenicsfriction.forms import Residual
from fenicsfriction.laws import check

__all__ = ["DEFAULT_OPTIONS", "Alpha2Integrator", "CentralDifference", "DynamicsError",
           "DynamicsSolver", "stick_slip_statistics"]

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


class DynamicsError(RuntimeError):
    """The time integration stopped before the final time; ``records`` holds the steps done."""

    def __init__(self, message: str, records: list):
        super().__init__(message)
        self.records = records


class Alpha2Integrator:
    """PETSc TS (TSALPHA2 by default) on a second-order system R(t, x, ẋ, ẍ) = 0: the set-up,
    the Newton stopping test, the cut-back and regrowth of the step, and the run loop with its
    records, shared by the FE solver and the few-d.o.f. models of :mod:`fenicsfriction.reduced`.

    A subclass provides the residual ``_F(ts, t, x, xdot, xddot, F)``, the Jacobian
    ``_J(ts, t, x, xdot, xddot, shift_v, shift_a, J, P)`` (which must call
    ``self.convergence.jacobian_assembled(J)``), ``_load(x, xdot, xddot)`` (put an accepted state
    where ``observe`` reads it) and ``_state()`` (the initial displacement and velocity vectors,
    which receive the final state).

    Attributes:
        ts: the PETSc TS, exposed for monitoring or further configuration.
        fixed_steps: no error control (``ts_adapt_type none``): a cut step grows back.
        convergence: the Newton stopping test (its ``atol_used``: the last tolerance).
    """

    def __init__(self, comm, prefix: str, F: PETSc.Vec, J: PETSc.Mat,
                 options: typing.Optional[dict], atol: float):
        check("atol", atol, np.isfinite(atol) and atol > 0, "must be a finite number > 0")
        self.ts = PETSc.TS().create(comm)
        self.ts.setOptionsPrefix(prefix)
        self.ts.setI2Function(self._F, F)
        self.ts.setI2Jacobian(self._J, J)
        with options_with_defaults(prefix, {**DEFAULT_OPTIONS, "snes_atol": atol,
                                            **(options or {})}) as opts:
            self.ts.setFromOptions()
            # petsc4py 3.18 does not wrap TSAdapt: read the choice from the options
            self.fixed_steps = opts.getString("ts_adapt_type") == "none"
        self.convergence = RoundoffConvergence(self.ts.getSNES())
        self.ts.getSNES().setConvergenceTest(self.convergence)

    def _F(self, ts, t, x, xdot, xddot, F):
        raise NotImplementedError

    def _J(self, ts, t, x, xdot, xddot, shift_v, shift_a, J, P):
        raise NotImplementedError

    def _load(self, x, xdot, xddot) -> None:
        raise NotImplementedError

    def _state(self) -> tuple[PETSc.Vec, PETSc.Vec]:
        raise NotImplementedError

    def run(self, t_end: float, dt: float,
            observe: typing.Optional[typing.Callable[[float], dict]] = None,
            on_step: typing.Optional[typing.Callable[[dict], None]] = None) -> list[dict]:
        """Integrate from t = 0 to ``t_end`` with (initial) step ``dt``.

        Args:
            observe: called after every accepted step (fields hold the state), its dict is
                merged into the step's record.
            on_step: called with each record (progress output, field output).

        Returns:
            One record per accepted step (and one for t = 0): ``time``, ``dt``,
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
        self.ts.setMaxSteps(10**9)
        records: list[dict] = []
        clock = [time.perf_counter(), 0, 0]

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
                record["dt"] = float(t - records[-1]["time"])
            if observe is not None:
                record.update(observe(float(t)))
            records.append(record)
            if on_step is not None:
                on_step(record)

        self.ts.setMonitor(monitor)
        self.ts.setPostStep(regrow)
        error = None
        try:
            self.ts.solve(u)
        except PETSc.Error as err:  # e.g. a NaN in the error estimate: report, keep the state
            error = err
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
        return records


class DynamicsSolver(Alpha2Integrator):
    """Generalized-α (TSALPHA2) integration of the one residual of a FE model.

    Args:
        residual: the residual; ``u`` and ``u_dot`` hold the initial state (e.g. a steady
            sliding state plus a velocity perturbation) and receive the final one.
        prefix: PETSc options prefix of the TS (and its SNES/KSP/PC).
        options: defaults over :data:`DEFAULT_OPTIONS`; options in the database win.
        atol: absolute Newton tolerance on the residual (force units).
    """

    def __init__(self, residual: Residual, prefix: str = "dynamics_",
                 options: typing.Optional[dict] = None, atol: float = 1e-8):
        self.residual = residual
        msh = residual.V.mesh
        self.shift_v = fem.Constant(msh, 0.0)
        self.shift_a = fem.Constant(msh, 0.0)
        R = residual.form
        jacobian = residual.derivative(R, residual.u)
        for field, shift in ((residual.u_dot, self.shift_v), (residual.u_ddot, self.shift_a)):
            part = residual.derivative(R, field)
            if not part.empty():
                jacobian = jacobian + shift * part
        self.L = _compat.form(R)
        self.a = _compat.form(jacobian)
        self.b = dolfinx.fem.petsc.create_vector(self.L)
        self.A = dolfinx.fem.petsc.create_matrix(self.a)
        super().__init__(msh.comm, prefix, self.b, self.A, options, atol)

    def _state(self) -> tuple[PETSc.Vec, PETSc.Vec]:
        return _compat.petsc_vec(self.residual.u), _compat.petsc_vec(self.residual.u_dot)

    def _load(self, x, xdot, xddot) -> None:
        """Copy a state into the fields (``xddot=None`` leaves the acceleration alone)."""
        for vec, field in ((x, self.residual.u), (xdot, self.residual.u_dot),
                           (xddot, self.residual.u_ddot)):
            if vec is not None:
                vec.copy(_compat.petsc_vec(field))
                field.x.scatter_forward()

    def _F(self, ts, t, x, xdot, xddot, F):
        self._load(x, xdot, xddot)
        assemble_residual(F, self.L, self.a, self.residual.bcs, x, self.residual.springs)

    def _J(self, ts, t, x, xdot, xddot, shift_v, shift_a, J, P):
        self.shift_v.value = shift_v
        self.shift_a.value = shift_a
        assemble_jacobian(J, self.a, self.residual.bcs, self.residual.springs)
        self.convergence.jacobian_assembled(J)


class CentralDifference:
    """Explicit central differences with a row-sum lumped mass (seed 000's FE dynamics).

    .. math::
        a_n = M_L^{-1}\\,(-R(u_n, \\tilde v_n, 0)),\\quad
        v_{n+1/2} = v_{n-1/2} + \\Delta t\\, a_n,\\quad u_{n+1} = u_n + \\Delta t\\, v_{n+1/2},

    with the velocity-dependent forces (friction, damping) evaluated at the predicted
    :math:`\\tilde v_n = v_{n-1/2} + \\tfrac{\\Delta t}{2} a_{n-1}`. The scheme is stable for
    :math:`\\Delta t < 2/\\omega_{max}`, :math:`\\omega_{max}^2` the largest eigenvalue of
    :math:`\\bar K w = \\omega^2 M_L w` (SLEPc EPS, at the initial state); steps are capped at
    ``safety`` times that bound. Tensor-product Lagrange elements have positive row sums.

    Friction is explicit too: inside the regularisation band a sticking node feels a dashpot
    :math:`c_i = c_T d_i^{m_T} A_i/\varepsilon`, stable only for
    :math:`\\Delta t < 2 m_i / c_i` — with a small ε far below :math:`2/\\omega_{max}`. Given
    ``band_damping`` (a linear form whose assembled vector holds the :math:`c_i`, e.g.
    ``BlockModel.band_damping()``) the cap also includes :math:`\\min_i 2 m_i/(\\kappa c_i)`,
    evaluated at the initial state with the margin κ = ``band_margin`` for the growth of the
    contact pressure during the run (the block's nodal pressure reaches ~3× its steady value
    past the flutter onset). ``stable_dt`` is the smaller bound, ``stable_dt_elastic`` and
    ``stable_dt_band`` the two.
    """

    def __init__(self, residual: Residual, safety: float = 0.9,
                 band_damping: typing.Optional[ufl.Form] = None, band_margin: float = 4.0):
        check("safety", safety, 0 < safety < 1, "must lie in (0, 1)")
        check("band_margin", band_margin, band_margin >= 1, "must be >= 1")
        self.residual, self.safety = residual, safety
        zero = ufl.zero(*residual.u.ufl_shape)
        self.L = _compat.form(ufl.replace(residual.form, {residual.u_ddot: zero}))
        mass = residual.derivative(residual.form, residual.u_ddot)
        self.b = dolfinx.fem.petsc.create_vector(self.L)
        M = dolfinx.fem.petsc.assemble_matrix(_compat.form(mass))
        M.assemble()
        self.lumped = self.b.duplicate()
        M.getRowSum(self.lumped)
        bc_dofs = [i for bc in residual.bcs for i in bc.dof_indices()[0]]
        with self.lumped.localForm() as m:
            m.array[bc_dofs] = np.inf  # constrained dofs never accelerate
        self.stable_dt_elastic = self._stable_step(residual)
        self.stable_dt_band = np.inf
        if band_damping is not None:
            c = dolfinx.fem.petsc.assemble_vector(_compat.form(band_damping))
            c.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            owned_c, owned_m = c.array_r, self.lumped.array_r  # owned entries (no ghosts)
            active = owned_c > 0
            local = (2.0 * owned_m[active] / (band_margin * owned_c[active])).min(initial=np.inf)
            self.stable_dt_band = float(c.getComm().tompi4py().allreduce(local, op=MPI.MIN))
            c.destroy()
        self.stable_dt = min(self.stable_dt_elastic, self.stable_dt_band)
        M.destroy()

    def _stable_step(self, residual: Residual) -> float:
        """2 / ω_max with ω_max² the largest eigenvalue of K̄ w = ω² M_L w."""
        from slepc4py import SLEPc
        a = _compat.form(residual.derivative(residual.at_rest(residual.form), residual.u))
        K = dolfinx.fem.petsc.create_matrix(a)
        assemble_jacobian(K, a, residual.bcs, residual.springs)
        inverse_mass = self.lumped.copy()
        inverse_mass.reciprocal()
        K.diagonalScale(inverse_mass, None)  # M_L^{-1} K̄: same eigenvalues ω²
        eps = SLEPc.EPS().create(K.getComm())
        eps.setOperators(K)
        eps.setProblemType(SLEPc.EPS.ProblemType.NHEP)
        eps.setWhichEigenpairs(SLEPc.EPS.Which.LARGEST_MAGNITUDE)
        eps.setTolerances(1e-6, 500)
        eps.solve()
        omega2 = max(abs(eps.getEigenvalue(i)) for i in range(eps.getConverged()))
        for obj in (eps, K, inverse_mass):
            obj.destroy()
        return 2.0 / np.sqrt(omega2)

    def run(self, t_end: float, dt: float,
            observe: typing.Optional[typing.Callable[[float], dict]] = None,
            on_step: typing.Optional[typing.Callable[[dict], None]] = None) -> list[dict]:
        """Integrate to ``t_end``; ``dt`` above ``safety × stable_dt`` is reduced to it.

        Records as :meth:`DynamicsSolver.run` (``newton_iterations`` is 0: nothing to solve).
        """
        check("t_end", t_end, t_end > 0, "must be > 0")
        check("dt", dt, 0 < dt <= t_end, f"must lie in (0, t_end = {t_end}]")
        dt = min(dt, self.safety * self.stable_dt)
        R = self.residual
        u, v = _compat.petsc_vec(R.u), _compat.petsc_vec(R.u_dot)
        a = v.duplicate()

        def acceleration() -> None:
            R.u.x.scatter_forward()
            R.u_dot.x.scatter_forward()
            assemble_residual(self.b, self.L, self.L, [], u, R.springs)
            a.pointwiseDivide(self.b, self.lumped)
            a.scale(-1.0)

        records, t, clock = [], 0.0, time.perf_counter()

        def record(step_dt: float) -> None:
            nonlocal clock
            entry = {"time": t, "dt": step_dt, "newton_iterations": 0, "rejected_steps": 0,
                     "wall_time_s": time.perf_counter() - clock}
            clock = time.perf_counter()
            if observe is not None:
                entry.update(observe(t))
            records.append(entry)
            if on_step is not None:
                on_step(entry)

        record(0.0)
        acceleration()
        v_half = v.copy()
        v_half.axpy(0.5 * dt, a)
        n_steps = int(np.ceil(t_end / dt - 1e-9))
        for k in range(n_steps):
            h = min(dt, t_end - t)
            u.axpy(h, v_half)  # u_{n+1} = u_n + h v_{n+1/2}
            t = t_end if k == n_steps - 1 else t + h
            v_half.copy(v)
            v.axpy(0.5 * h, a)  # predicted v_{n+1} for friction and damping
            acceleration()  # a_{n+1}
            v_half.copy(v)
            v.axpy(0.5 * h, a)  # v_{n+1} = v_{n+1/2} + h/2 a_{n+1}, recorded
            R.u_dot.x.scatter_forward()
            record(h)
            v_half.axpy(h, a)  # v_{n+3/2}
        for obj in (a, v_half):
            obj.destroy()
        return records


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
    return float(np.trapz(values, t) / (t[-1] - t[0]))


def stick_slip_statistics(records: list[dict], mu: float, eps: float,
                          t_from: float = 0.0) -> dict:
    r"""What an experimenter would measure on a run, over the records with time ≥ ``t_from``.

    Needs ``normal_force``, ``friction_force``, ``spring_elongation`` and the probe's
    ``probe_slip``/``probe_pressure`` (see ``BlockModel.dynamics_observer``;
    ``rigid_block_observables`` gives them for the rigid block), and ``energy_error`` if
    there is one (``max_energy_error`` is None otherwise).

    Returns:
        ``apparent_coefficient``: :math:`\bar F_T / \bar N` (time means), the friction
        coefficient a measurement of mean forces would report, against the law's ``mu``
        (``ratio_to_mu``); ``probe_stick_fraction`` / ``probe_open_fraction``: share of the
        time the probe node sticks (in contact, :math:`|\dot u_T - U_T| < \varepsilon`) or is
        out of contact; ``probe_longest_stick`` [s]: its longest uninterrupted stick (a
        stick-slip relaxation cycle against brief adhesions); ``any_stick_fraction``: share of
        the time some contact node sticks (from ``n_stick``; None without it);
        ``mean_normal_force``, ``mean_friction_force``, ``normal_force_range``;
        the spring elongation at the start and end of the window and its mean;
        ``max_energy_error`` over the whole run; ``steps``, ``rejected_steps``,
        ``newton_iterations`` over the whole run.
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
    mean_n = _time_mean(t, series["normal_force"])
    mean_f = _time_mean(t, series["friction_force"])
    return {"t_from": float(t[0]), "t_to": float(t[-1]), "mu": mu, "eps": eps,
            "mean_normal_force": mean_n, "mean_friction_force": mean_f,
            "normal_force_range": [float(series["normal_force"].min()),
                                   float(series["normal_force"].max())],
            "apparent_coefficient": abs(mean_f) / mean_n,
            "ratio_to_mu": abs(mean_f) / mean_n / mu if mu > 0 else float("nan"),
            "probe_stick_fraction": _time_mean(t, sticks.astype(float)),
            "probe_open_fraction": _time_mean(t, (~in_contact).astype(float)),
            "probe_longest_stick": _longest_run(t, sticks),
            "any_stick_fraction": (_time_mean(t, np.array([r["n_stick"] > 0 for r in window],
                                                          dtype=float))
                                   if "n_stick" in window[0] else None),
            "spring_elongation": {"start": float(series["spring_elongation"][0]),
                                  "end": float(series["spring_elongation"][-1]),
                                  "mean": _time_mean(t, series["spring_elongation"])},
            "max_energy_error": (float(max(abs(r["energy_error"]) for r in records))
                                 if "energy_error" in records[0] else None),
            "duration": float(t_all[-1] - t_all[0]), "steps": len(records) - 1,
            "rejected_steps": int(sum(r["rejected_steps"] for r in records)),
            "newton_iterations": int(sum(r["newton_iterations"] for r in records))}
