r"""Problem 1ε, dynamics: :math:`R(u, \dot u, \ddot u; v) = 0` integrated by PETSc TS.

The default scheme is PETSc's generalized-α method for second-order systems (``TSALPHA2``;
Newmark's average acceleration is ``-dynamics_ts_alpha_radius 1``), with Newton (SNES, MUMPS)
at each step, or beyond the crossover of :func:`fenicsfriction.amg.choose_linear_solver`
Newton–Krylov with GMRES and algebraic multigrid (``linear_solver``). TS asks for

* the residual :math:`F(t, u, \dot u, \ddot u) = R(u, \dot u, \ddot u)` — the one residual of
  :mod:`fenicsfriction.forms`, nothing rewritten;
* its Jacobian :math:`\partial R/\partial u + s_v\,\partial R/\partial \dot u
  + s_a\,\partial R/\partial \ddot u`, compiled once with the shifts :math:`s_v, s_a` as
  ``fem.Constant``.

Steps: fixed (``-dynamics_ts_adapt_type none``, the default) or adaptive
(``-dynamics_ts_adapt_type basic``, error-controlled). A step whose Newton solve fails is
retried with a quarter of the step (``ts_max_snes_failures = -1``): the cut-back of Pop's
"A finite element method for frictional contact problems",
whose Newton iterations cycle across the steep part of φ_ε at slide-to-stick transitions when ε
is small and the step large. With fixed steps the step then grows back (doubling after each
accepted step) to the one asked for, so a transition costs a few small steps, not the rest of
the run. Newton stops on the residual (atol raised to its round-off floor, see
:class:`~fenicsfriction.petsc_options.RoundoffConvergence`), never on the step length.
Options live under the prefix (default ``dynamics_``).
"""

from __future__ import annotations

import time
import typing

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem.petsc
import numpy as np
import ufl
from dolfinx import fem

from fenicsfriction import _compat
from fenicsfriction.amg import attach_near_nullspace, resolve_linear_solver, uses_amg
from fenicsfriction.assembly import (
    BulkWatcher,
    CoupledMatrix,
    assemble_jacobian,
    assemble_residual,
    split_constant,
)
from fenicsfriction.coupling import CouplingOperator
from fenicsfriction.forms import Residual
from fenicsfriction.laws import check
from fenicsfriction.timestepping import DEFAULT_OPTIONS, Alpha2Integrator, DynamicsError

__all__ = ["DEFAULT_OPTIONS", "DYNAMICS_LINEAR_SOLVERS", "CentralDifference", "DynamicsError",
           "DynamicsSolver"]

#: the choices of ``DynamicsSolver(linear_solver=...)``
DYNAMICS_LINEAR_SOLVERS = ("auto", "lu", "amg")


class DynamicsSolver(Alpha2Integrator):
    r"""Generalized-α (TSALPHA2) integration of the one residual of a FE model.

    Args:
        residual: the residual; ``u`` and ``u_dot`` hold the initial state (e.g. a steady
            sliding state plus a velocity perturbation) and receive the final one.
        prefix: PETSc options prefix of the TS (and its SNES/KSP/PC).
        options: defaults over :data:`DEFAULT_OPTIONS`; options in the database win.
        atol: absolute Newton tolerance on the residual (force units).
        predictor: start Newton from x_n + Δt ẋ_n (see
            :class:`~fenicsfriction.timestepping.Alpha2Integrator`), else from x_n.
        energy_consistent: the energy-consistent midpoint rule: generalized-α at ρ∞ = 1
            (``ts_alpha_radius`` 1; the residual is then evaluated at
            :math:`u_{n+1/2} = (u_n + u_{n+1})/2`, :math:`\dot u = (u_{n+1} - u_n)/\Delta t`,
            :math:`\ddot u = (\dot u_{n+1} - \dot u_n)/\Delta t`: Newmark's average
            acceleration, which conserves kinetic + elastic energy of linear elasticity
            exactly), and every coupling with a ``step_from`` Function (a contact's start of
            step, :class:`~fenicsfriction.contact.NodeToSegment`) receives :math:`u_n` before
            each step, so that its force is the step's discrete gradient. A friction traction
            evaluated at the midpoint slip rate then dissipates exactly
            :math:`-\Delta t\, t_T\cdot w_{n+1/2} \ge 0` per step (Armero & Petőcz 1999),
            and the discrete energy balance closes to Newton's tolerance whatever ε.
        linear_solver: ``"lu"`` (a sparse LU at every Newton iteration), ``"amg"`` (GMRES
            preconditioned by GAMG with the bodies' rigid-body near-nullspace,
            :mod:`fenicsfriction.amg`) or ``"auto"`` (default: AMG beyond the measured
            crossover of :func:`~fenicsfriction.amg.choose_linear_solver`, else the LU). A PC
            chosen in the PETSc options overrides it (``-<prefix>pc_type lu``: the LU;
            ``gamg`` or ``hypre``: the AMG path with that preconditioner).

    Attributes:
        linear_solver: the path in effect (``"lu"`` or ``"amg"``).
        near_nullspace: the rigid-body modes on the Jacobian (AMG path), else ``None``.
    """

    def __init__(self, residual: Residual, prefix: str = "dynamics_",
                 options: dict | None = None, atol: float = 1e-8, predictor: bool = True,
                 energy_consistent: bool = False, linear_solver: str = "auto"):
        check("linear_solver", linear_solver, linear_solver in DYNAMICS_LINEAR_SOLVERS,
              f"use one of {', '.join(DYNAMICS_LINEAR_SOLVERS)}")
        self.residual = residual
        if energy_consistent:
            options = {**(options or {}), "ts_alpha_radius": 1.0}
        self.energy_consistent = energy_consistent
        self._step_start: tuple[PETSc.Vec, float] | None = None  # x_{n-1}, t_{n-1}
        self._mean_velocity: PETSc.Vec | None = None  # (x_n - x_{n-1}) / Δt_{n-1}
        #: the couplings' start-of-step fields, set to u_n before each step
        self.step_starts = [c.step_from for c in residual.couplings
                            if energy_consistent and getattr(c, "step_from", None) is not None]
        msh = residual.V.mesh
        self.shift_v = fem.Constant(msh, 0.0)
        self.shift_a = fem.Constant(msh, 0.0)
        R = residual.form
        jacobian = residual.derivative(R, residual.u)
        fixed: list[ufl.Form | None] = []  # the state-independent parts of K, C, M
        varying: list = []  # the other integrals of the Jacobian, shifts included
        for field, shift in ((residual.u, None), (residual.u_dot, self.shift_v),
                             (residual.u_ddot, self.shift_a)):
            part = residual.derivative(R, field)
            if field is not residual.u and not part.empty():
                jacobian = jacobian + shift * part
            constant, other = split_constant(part, part.coefficients())
            fixed.append(constant)
            varying += [i if shift is None else i.reconstruct(integrand=shift * i.integrand())
                        for i in other]
        self.L = _compat.form(R)
        self.a = _compat.form(jacobian)
        self.b = dolfinx.fem.petsc.create_vector(self.L)
        self.A = dolfinx.fem.petsc.create_matrix(self.a)
        # once in full, which fixes the matrix's nonzero structure for the sums below
        assemble_jacobian(self.A, self.a, residual.bcs, residual.springs)
        self._bulk = _ConstantJacobian(fixed, self.A, residual) if fixed[0] else None
        # None: every integral is constant (the state enters through couplings only)
        self.a_varying = (self.a if self._bulk is None
                          else _compat.form(ufl.Form(varying)) if varying else None)
        # contact couplings: residual and shifted Jacobian of their own, added to a matrix
        # apart from the one dolfinx assembles into (their pattern follows the pairing)
        self.couplings: list[CouplingOperator] = [
            c.operator({residual.u: 1.0, residual.u_dot: self.shift_v})
            for c in residual.couplings]
        self._coupled = CoupledMatrix(self.A) if self.couplings else None
        if self._coupled is not None:
            self.A = self._coupled.A
        dim = msh.geometry.dim
        _, amg_defaults = resolve_linear_solver(prefix, linear_solver, dim, self.b.getSize(),
                                                msh.comm.size, splits=False,
                                                contact=bool(self.couplings))
        options = {**amg_defaults, **(options or {})}
        super().__init__(msh.comm, prefix, self.b, self.A, options, atol, predictor)
        self.linear_solver, self.near_nullspace = "lu", None
        if uses_amg(self.ts.getSNES().getKSP()):
            self.near_nullspace = attach_near_nullspace(self.A, residual.V)
            self.linear_solver = "amg"
            self.run_defaults = self._defaults
        if self.couplings or energy_consistent:  # pairing searched at a step's first residual
            self.ts.setPreStep(self._pre_step)

    def _pre_step(self, ts: PETSc.TS) -> None:
        _search_due(self.couplings)
        x_n, t = ts.getSolution2()[0], ts.getTime()
        for start in self.step_starts:
            x_n.copy(_compat.petsc_vec(start))
            start.x.scatter_forward()
        if not self.energy_consistent:
            return
        if self._step_start is None or t <= self._step_start[1]:  # a (new) run's first step
            self._mean_velocity = None
            self._step_start = (x_n.copy(), t)
            return
        x_previous, t_previous = self._step_start
        if self._mean_velocity is None:
            self._mean_velocity = x_n.duplicate()
        x_n.copy(self._mean_velocity)
        self._mean_velocity.axpy(-1.0, x_previous)
        self._mean_velocity.scale(1.0 / (t - t_previous))
        x_n.copy(x_previous)
        self._step_start = (x_previous, t)

    def _predict(self, snes: PETSc.SNES, x: PETSc.Vec) -> None:
        """Newton's starting point: with the midpoint rule x_n + Δt (x_n − x_{n−1})/Δt_{n−1},
        the last step's mean velocity (the end-of-step velocity 2(x_n − x_{n−1})/Δt − ẋ_{n−1}
        of a sticking node flips sign from step to step: the stick dashpots ring); else
        :meth:`Alpha2Integrator._predict`."""
        if self._mean_velocity is None:
            super()._predict(snes, x)
            return
        self.ts.getSolution2()[0].copy(x)
        x.axpy(self.ts.getTimeStep(), self._mean_velocity)

    def _state(self) -> tuple[PETSc.Vec, PETSc.Vec]:
        return _compat.petsc_vec(self.residual.u), _compat.petsc_vec(self.residual.u_dot)

    def _load(self, x: typing.Any, xdot: typing.Any, xddot: typing.Any) -> None:
        """Copy a state into the fields (``xddot=None`` leaves the acceleration alone)."""
        for vec, field in ((x, self.residual.u), (xdot, self.residual.u_dot),
                           (xddot, self.residual.u_ddot)):
            if vec is not None:
                vec.copy(_compat.petsc_vec(field))
                field.x.scatter_forward()

    def _F(self, ts, t, x, xdot, xddot, F):
        self._load(x, xdot, xddot)
        assemble_residual(F, self.L, self.a, self.residual.bcs, x, self.residual.springs,
                          self.couplings)

    def _J(self, ts, t, x, xdot, xddot, shift_v, shift_a, J, P):
        self.shift_v.value = shift_v
        self.shift_a.value = shift_a
        bcs = self.residual.bcs
        target = J if self._coupled is None else self._coupled.base
        if self._bulk is None:
            assemble_jacobian(target, self.a, bcs, self.residual.springs)
        elif self.a_varying is None:
            self._bulk.matrix(shift_v, shift_a).copy(
                target, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        else:
            assemble_jacobian(target, self.a_varying, bcs,
                              base=self._bulk.matrix(shift_v, shift_a))
        if self._coupled is not None and self._coupled.assemble(self.couplings, bcs):
            ts.getSNES().getKSP().getPC().reset()
            if self.near_nullspace is not None:  # on the matrix whose storage was replaced
                J.setNearNullSpace(self.near_nullspace)
        self.convergence.jacobian_assembled(J)


def _search_due(couplings: typing.Sequence[CouplingOperator]) -> None:
    """Mark each contact's pairing to be searched at the next residual evaluation."""
    for coupling in couplings:
        coupling.contact.search_pending = True


class _ConstantJacobian:
    """K0 + s_v C0 + s_a M0: the state-independent part of the Jacobian (springs and Dirichlet
    rows included), assembled once; the sum is formed again when the shifts change (a new
    step size) or an input of K0, C0, M0 does (e.g. the density: ``watcher``)."""

    def __init__(self, forms: list[ufl.Form | None], A: PETSc.Mat, residual: Residual):
        self.residual = residual
        self.forms = [None if f is None else _compat.form(f) for f in forms]
        self.watcher = BulkWatcher([f for f in forms if f is not None], self._assemble_parts)
        self.parts: list[PETSc.Mat | None] = [None, None, None]
        self.pattern = A
        self.sum: PETSc.Mat | None = None
        self._key: tuple | None = None

    def _assemble_parts(self) -> None:
        for k, form in enumerate(self.forms):
            if form is None:
                continue
            if self.parts[k] is None:
                self.parts[k] = self.pattern.duplicate()
            # the stiffness carries the springs and the unit Dirichlet diagonal
            stiffness = k == 0
            assemble_jacobian(self.parts[k], form, self.residual.bcs,
                              self.residual.springs if stiffness else (),
                              diagonal=1.0 if stiffness else 0.0)

    def matrix(self, shift_v: float, shift_a: float) -> PETSc.Mat:
        """K0 + s_v C0 + s_a M0 for the given shifts."""
        if self.watcher.refresh():
            self._key = None
        if self._key != (shift_v, shift_a):
            same = PETSc.Mat.Structure.SAME_NONZERO_PATTERN
            stiffness, damping, mass = self.parts
            assert stiffness is not None, "the solver splits the Jacobian only when K0 exists"
            if self.sum is None:
                self.sum = stiffness.copy()
            else:
                stiffness.copy(self.sum, structure=same)
            for scale, part in ((shift_v, damping), (shift_a, mass)):
                if part is not None:
                    self.sum.axpy(scale, part, structure=same)
            self._key = (shift_v, shift_a)
        return self.sum


class CentralDifference:
    """Explicit central differences with a row-sum lumped mass (the FE dynamics of Martins & Oden
    1986).

    .. math::
        a_n = M_L^{-1}\\,(-R(u_n, \\tilde v_n, 0)),\\quad
        v_{n+1/2} = v_{n-1/2} + \\Delta t\\, a_n,\\quad u_{n+1} = u_n + \\Delta t\\, v_{n+1/2},

    with the velocity-dependent forces (friction, damping) evaluated at the predicted
    :math:`\\tilde v_n = v_{n-1/2} + \\tfrac{\\Delta t}{2} a_{n-1}`. The scheme is stable for
    :math:`\\Delta t < 2/\\omega_{max}`, :math:`\\omega_{max}^2` the largest eigenvalue of
    :math:`\\bar K w = \\omega^2 M_L w` (a SLEPc eigensolver, at the initial state); steps are
    capped at ``safety`` times that bound. Tensor-product Lagrange elements have positive row sums.

    Friction is explicit too: inside the regularisation band a sticking node feels a dashpot
    :math:`c_i = c_T d_i^{m_T} A_i/\\varepsilon`, stable only for
    :math:`\\Delta t < 2 m_i / c_i` — with a small ε far below :math:`2/\\omega_{max}`. Given
    ``band_damping`` (a linear form whose assembled vector holds the :math:`c_i`, e.g.
    ``BlockModel.band_damping()``) the cap also includes :math:`\\min_i 2 m_i/(\\kappa c_i)`,
    evaluated at the initial state with the margin κ = ``band_margin`` for the growth of the
    contact pressure during the run (the block's nodal pressure reaches ~3× its steady value
    past the flutter onset). ``stable_dt`` is the smaller bound, ``stable_dt_elastic`` and
    ``stable_dt_band`` the two.

    With contact couplings (two bodies) the elastic bound is taken at the initial state with
    the contact's Jacobian; springs that close later (an impact) are bounded by
    ``stable_dt_contact`` (linear compliance: :meth:`NodeToSegment.frequency_bound`).
    """

    def __init__(self, residual: Residual, safety: float = 0.9,
                 band_damping: ufl.Form | None = None, band_margin: float = 4.0):
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
        self.couplings: list[CouplingOperator] = [c.operator({}) for c in residual.couplings]
        bc_dofs = [i for bc in residual.bcs for i in bc.dof_indices()[0]]
        with self.lumped.localForm() as m:
            m.array[bc_dofs] = np.inf  # constrained dofs never accelerate
        self.stable_dt_elastic = self._stable_step(residual)
        # contact springs that close later than the initial state (an impact): their bound
        self.stable_dt_contact = np.inf
        if residual.couplings and all(c.m_n == 1 for c in residual.couplings):
            omega2 = (2.0 / self.stable_dt_elastic) ** 2 + sum(
                c.frequency_bound(self.lumped) for c in residual.couplings)
            self.stable_dt_contact = 2.0 / np.sqrt(omega2)
        self.stable_dt_band = np.inf
        if band_damping is not None:
            c = dolfinx.fem.petsc.assemble_vector(_compat.form(band_damping))
            c.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
            owned_c, owned_m = c.array_r, self.lumped.array_r  # owned entries (no ghosts)
            active = owned_c > 0
            local = (2.0 * owned_m[active] / (band_margin * owned_c[active])).min(initial=np.inf)
            self.stable_dt_band = float(c.getComm().tompi4py().allreduce(local, op=MPI.MIN))
            c.destroy()
        self.stable_dt = min(self.stable_dt_elastic, self.stable_dt_band,
                             self.stable_dt_contact)
        M.destroy()

    def _stable_step(self, residual: Residual) -> float:
        """2 / ω_max with ω_max² the largest eigenvalue of K̄ w = ω² M_L w (contact couplings
        included at the initial state; those that close later: ``stable_dt_contact``)."""
        from slepc4py import SLEPc
        a = _compat.form(residual.derivative(residual.at_rest(residual.form), residual.u))
        K = dolfinx.fem.petsc.create_matrix(a)
        assemble_jacobian(K, a, residual.bcs, residual.springs)
        if residual.couplings:
            coupled = CoupledMatrix(K)
            coupled.assemble([c.operator({residual.u: 1.0}, rest=[residual.u_dot])
                              for c in residual.couplings], residual.bcs)
            K.destroy()
            K = coupled.A
        inverse_mass = self.lumped.copy()
        inverse_mass.reciprocal()
        K.diagonalScale(inverse_mass, None)  # M_L^{-1} K̄: same eigenvalues ω²
        eigensolver = SLEPc.EPS().create(K.getComm())
        eigensolver.setOperators(K)
        eigensolver.setProblemType(SLEPc.EPS.ProblemType.NHEP)
        eigensolver.setWhichEigenpairs(SLEPc.EPS.Which.LARGEST_MAGNITUDE)
        eigensolver.setTolerances(1e-6, 500)
        eigensolver.solve()
        omega2 = max(abs(eigensolver.getEigenvalue(i))
                     for i in range(eigensolver.getConverged()))
        for obj in (eigensolver, K, inverse_mass):
            obj.destroy()
        return 2.0 / np.sqrt(omega2)

    def run(self, t_end: float, dt: float,
            observe: typing.Callable[[float], dict] | None = None,
            on_step: typing.Callable[[dict], None] | None = None,
            keep_records: bool = True) -> list[dict]:
        """Integrate to ``t_end``; ``dt`` above ``safety × stable_dt`` is reduced to it.

        Records as :meth:`DynamicsSolver.run` (``newton_iterations`` is 0: nothing to solve;
        none kept if not ``keep_records``).
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
            _search_due(self.couplings)
            assemble_residual(self.b, self.L, self.L, [], u, R.springs, self.couplings)
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
            if keep_records:
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
