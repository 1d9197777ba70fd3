r"""Problem 2, steady sliding: :math:`R(u_0, 0, 0; v) = 0` solved with PETSc SNES.

Defaults: Newton with backtracking line search (``newtonls``/``bt``), MUMPS LU. Every option
can be changed through the PETSc options database under the solver's prefix (default
``steady_``), e.g. ``-steady_snes_rtol 1e-12`` or ``-steady_pc_factor_mat_solver_type
superlu_dist``.

Drivers on top of one solve (Martins & Oden 1986, "NINCT increments"):

* :func:`continuation` — a parameter (μ) stepped from its current value through a list of
  targets, each Newton solve warm-started from the last; a failed step is halved until it
  converges or ``max_halvings`` is exhausted, which raises :class:`ContinuationError` with the
  last converged state kept in ``u``.
* :func:`epsilon_sequence` — Kalker's *sequential process* (Kalker 1986, section 6): ε_k → 0,
  each solve starting from the previous one, recording how much the solution still changes.
"""

from __future__ import annotations

import dataclasses
import time
import typing

from petsc4py import PETSc

import dolfinx.fem.petsc
import numpy as np
from dolfinx import fem

from fenicsfriction import _compat
from fenicsfriction.assembly import assemble_jacobian, assemble_residual
from fenicsfriction.forms import Residual
from fenicsfriction.laws import check
from fenicsfriction.petsc_options import RoundoffConvergence, options_with_defaults

__all__ = ["ContinuationError", "SolveError", "SolveReport", "SteadySolver", "continuation",
           "epsilon_sequence"]

DEFAULT_OPTIONS = {
    "snes_type": "newtonls",
    "snes_linesearch_type": "bt",
    "snes_rtol": 1e-10,
    "snes_atol": 1e-9,
    "snes_stol": 0.0,
    "snes_max_it": 50,
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
}


class SolveError(RuntimeError):
    """A Newton solve did not converge; ``report`` says how, the state was restored."""

    def __init__(self, message: str, report: SolveReport):
        super().__init__(message)
        self.report = report


class ContinuationError(RuntimeError):
    """A continuation step failed even after halving; ``records`` holds the converged steps."""

    def __init__(self, message: str, records: list):
        super().__init__(message)
        self.records = records


@dataclasses.dataclass
class SolveReport:
    """Outcome of one SNES solve (``atol``: the absolute tolerance actually used)."""

    converged: bool
    reason: str
    iterations: int
    residual_norm: float
    wall_time_s: float
    atol: float


_REASONS = {v: k for k, v in vars(PETSc.SNES.ConvergedReason).items() if not k.startswith("_")}


class SteadySolver:
    """Newton (PETSc SNES) on the steady residual of a :class:`Residual`.

    Args:
        residual: the problem's one residual; its ``u`` holds the initial guess and the result.
        prefix: PETSc options prefix of the SNES (and its KSP/PC).
        options: defaults for this solver, merged over :data:`DEFAULT_OPTIONS`; options already
            in the PETSc database (set by the user) take precedence.
        jit_cache_dir: FFCx cache directory (default: dolfinx's); ``jit_time_s`` records the
            time spent compiling (or loading) the two forms.
        roundoff_safety: the absolute tolerance is raised, at each iteration, to this multiple
            of the residual's round-off floor sqrt(n) ε_mach ‖J‖_∞ ‖u‖_∞ (cancellation in J u,
            large when a soft spring carries a large rigid displacement); 0 disables it. The
            bound over-estimates the floor Newton actually reaches by 10-100x on the block
            (e.g. 7e-4 against 5e-6 on the 32x24 mesh), so a factor 1 is safe.

    Attributes:
        snes: the PETSc SNES, exposed for monitoring or further configuration.
        L, a: the compiled residual and Jacobian forms.
    """

    def __init__(self, residual: Residual, prefix: str = "steady_",
                 options: dict | None = None, jit_cache_dir: str | None = None,
                 roundoff_safety: float = 1.0):
        self.residual = residual
        self.u = residual.u
        t0 = time.perf_counter()
        self.L = _compat.form(residual.steady(), jit_cache_dir)
        self.a = _compat.form(residual.steady_jacobian(), jit_cache_dir)
        self.jit_time_s = time.perf_counter() - t0
        self.b = dolfinx.fem.petsc.create_vector(self.L)
        self.A = dolfinx.fem.petsc.create_matrix(self.a)
        self.x = self.b.duplicate()
        comm = self.u.function_space.mesh.comm
        self.snes = PETSc.SNES().create(comm)
        self.snes.setOptionsPrefix(prefix)
        self.snes.setFunction(self._F, self.b)
        self.snes.setJacobian(self._J, self.A)
        with options_with_defaults(prefix, {**DEFAULT_OPTIONS, **(options or {})}):
            self.snes.setFromOptions()
            self.snes.getKSP().setFromOptions()
            self.snes.getKSP().getPC().setFromOptions()
        self.convergence = RoundoffConvergence(self.snes, roundoff_safety)
        self.snes.setConvergenceTest(self.convergence)

    def _update(self, x: PETSc.Vec) -> None:
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        x.copy(_compat.petsc_vec(self.u))
        self.u.x.scatter_forward()

    def _F(self, snes, x, b):
        self._update(x)
        assemble_residual(b, self.L, self.a, self.residual.bcs, x, self.residual.springs)

    def _J(self, snes, x, A, P):
        assemble_jacobian(A, self.a, self.residual.bcs, self.residual.springs)
        self.convergence.jacobian_assembled(A)

    def solve(self) -> SolveReport:
        """Solve from the current ``u``; on failure restore ``u`` and raise :class:`SolveError`."""
        u_vec = _compat.petsc_vec(self.u)
        u_vec.copy(self.x)
        saved = u_vec.copy()
        t0 = time.perf_counter()
        self.snes.solve(None, self.x)
        reason = self.snes.getConvergedReason()
        report = SolveReport(
            converged=reason > 0, reason=_REASONS.get(reason, str(reason)),
            iterations=self.snes.getIterationNumber(),
            residual_norm=float(self.snes.getFunctionNorm()),
            wall_time_s=time.perf_counter() - t0, atol=self.convergence.atol_used)
        finite = np.isfinite(report.residual_norm)
        if report.converged and finite:
            self._update(self.x)
        else:
            saved.copy(u_vec)
            self.u.x.scatter_forward()
            report.converged = False
        saved.destroy()
        if not report.converged:
            raise SolveError(
                f"Newton did not converge ({report.reason}) after {report.iterations} "
                f"iterations, residual norm {report.residual_norm:.3e}; state restored", report)
        return report


def continuation(solver: SteadySolver, parameter: fem.Constant, targets: typing.Iterable[float],
                 observe: typing.Callable[[], typing.Any] | None = None,
                 max_halvings: int = 8,
                 on_step: typing.Callable[[dict], None] | None = None) -> list[dict]:
    """Step ``parameter`` through ``targets``, solving at each value.

    Args:
        solver: the steady solver (its ``u`` is the warm start and holds the result).
        parameter: the ``fem.Constant`` being continued (e.g. the friction coefficient).
        targets: the values to reach, in order; each one reached produces one record.
        observe: returns extra quantities recorded at each converged target, a dict or a
            record (e.g. ``model.quantities``) whose fields become columns of the row.
        max_halvings: how many times a failing increment may be halved.
        on_step: called with each record as soon as it exists (progress output).

    Returns:
        One record per target: ``value``, ``newton_iterations`` (summed over any halved
        sub-steps), ``residual_norm``, ``halvings``, ``wall_time_s`` and what ``observe`` adds.

    Raises:
        ContinuationError: a step failed after ``max_halvings`` halvings; ``u`` and
            ``parameter`` keep the last converged state, ``error.records`` the steps so far.
    """
    records: list[dict] = []
    current = float(parameter.value)
    for target in targets:
        t0 = time.perf_counter()
        iterations, halvings, step = 0, 0, target - current
        while True:
            trial = current + step if abs(target - current) > abs(step) else target
            parameter.value = trial
            try:
                report = solver.solve()
            except SolveError as err:
                iterations += err.report.iterations
                parameter.value = current
                if halvings == max_halvings:
                    raise ContinuationError(
                        f"continuation failed at {trial:.6g} (from converged {current:.6g}, "
                        f"target {target:.6g}) after {halvings} step halvings: {err}",
                        records) from err
                halvings += 1
                step /= 2
                continue
            iterations += report.iterations
            current = trial
            if current == target:
                break
        record = {"value": float(target), "newton_iterations": iterations,
                  "residual_norm": report.residual_norm, "atol": report.atol,
                  "halvings": halvings,
                  "wall_time_s": time.perf_counter() - t0}
        if observe is not None:
            record.update(_row(observe()))
        records.append(record)
        if on_step is not None:
            on_step(record)
    return records


def _row(values: typing.Any) -> dict[str, typing.Any]:
    """The fields of a record (a dataclass such as ``BlockModel.quantities()``), or a dict, as
    the flat columns of a table row (values as they are, so rows do not depend on which)."""
    if dataclasses.is_dataclass(values) and not isinstance(values, type):
        return {f.name: getattr(values, f.name) for f in dataclasses.fields(values)}
    return dict(values)


def epsilon_sequence(solver: SteadySolver, eps: fem.Constant, values: typing.Iterable[float],
                     observe: typing.Callable[[], typing.Any] | None = None) -> list[dict]:
    """Kalker's sequential ε process: solve for each ε in ``values``, warm-starting each solve.

    Each record has ``eps``, ``newton_iterations``, ``change`` (the max-norm of the solution
    change from the previous ε; ``None`` for the first), ``residual_norm``, ``atol`` and what
    ``observe`` adds. A failing solve raises :class:`SolveError` with ``u`` and ``eps`` at the
    last converged ε.
    """
    records: list[dict] = []
    u_vec = _compat.petsc_vec(solver.u)
    previous = None
    for value in values:
        check("eps", value, value > 0, "the regularisation parameter must be > 0")
        last = float(eps.value)
        eps.value = value
        try:
            report = solver.solve()
        except SolveError:
            eps.value = last  # u was restored to the state converged at ``last``
            raise
        change = None
        if previous is not None:
            previous.axpy(-1.0, u_vec)
            change = previous.norm(PETSc.NormType.INFINITY)
            previous.destroy()
        previous = u_vec.copy()
        record = {"eps": float(value), "newton_iterations": report.iterations, "change": change,
                  "residual_norm": report.residual_norm, "atol": report.atol}
        if observe is not None:
            record.update(_row(observe()))
        records.append(record)
    if previous is not None:
        previous.destroy()
    return records

