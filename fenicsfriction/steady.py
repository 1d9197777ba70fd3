r"""Problem 2, steady sliding: :math:`R(u_0, 0, 0; v) = 0` solved with PETSc SNES.

Defaults: Newton with backtracking line search (``newtonls``/``bt``). Where the Jacobian
splits into a constant (linear elastic) bulk and a nonlinear contact interface, its linear
systems are solved without a factorisation per iteration (``linear_solver``): small interfaces
by condensing the bulk onto them (:mod:`fenicsfriction.condensation`: one MUMPS factorisation
and one dense Schur complement for a whole continuation, a small dense system per iteration),
large ones (3D) by flexible GMRES preconditioned with a factorisation kept across iterations
and steps (:mod:`fenicsfriction.reused_lu`); elsewhere by a MUMPS LU per iteration. Large
problems (3D beyond 2.5e4-2.5e5 unknowns per rank) are solved by GMRES preconditioned with
algebraic multigrid and the bodies' rigid-body near-nullspace (:mod:`fenicsfriction.amg`),
which needs no factorisation at all. Every
option can be changed through the PETSc options database under the solver's prefix (default
``steady_``), e.g. ``-steady_snes_rtol 1e-12``, or ``-steady_ksp_type preonly -steady_pc_type
lu`` for the LU at every iteration.

Drivers on top of one solve (Martins & Oden 1986, "NINCT increments"):

* :func:`continuation` — a parameter (μ) stepped from its current value through a list of
  targets, each Newton solve started from the secant extrapolation of the last two; a failed
  step is halved until it converges or ``max_halvings`` is exhausted, which raises
  :class:`ContinuationError` with the last converged state kept in ``u``.
* :func:`epsilon_sequence` — Kalker's *sequential process* (Kalker 1986, section 6): ε_k → 0,
  each solve starting from the previous one, recording how much the solution still changes.
* :func:`solve_continued` — a solve at a parameter value that falls back, when the direct
  solve fails, on continuation from an easy value: natural steps halved on failure, then,
  where the branch folds back (a limit point: halving cannot pass it), pseudo-arclength
  steps round the fold (Keller 1977) until the branch reaches the value again.
"""

from __future__ import annotations

import dataclasses
import logging
import time
import typing

from petsc4py import PETSc

import dolfinx.fem.petsc
import numpy as np
import ufl
from dolfinx import fem

from fenicsfriction import _compat
from fenicsfriction.amg import (
    attach_near_nullspace,
    requested_amg,
    resolve_linear_solver,
    uses_amg,
)
from fenicsfriction.assembly import (
    BulkWatcher,
    CoupledMatrix,
    assemble_jacobian,
    assemble_residual,
)
from fenicsfriction.condensation import (
    InterfaceCondensation,
    condensation_for,
    interface_split,
)
from fenicsfriction.coupling import CouplingOperator
from fenicsfriction.forms import Residual
from fenicsfriction.laws import check
from fenicsfriction.petsc_options import RoundoffConvergence, options_with_defaults
from fenicsfriction.reused_lu import ReusedFactorisation

__all__ = ["ContinuationError", "SolveError", "SolveReport", "SteadySolver", "continuation",
           "epsilon_sequence", "solve_continued"]

log = logging.getLogger(__name__)

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

#: defaults when Newton's systems are preconditioned by a factorisation that outlives the
#: iteration (the condensed bulk or the reused LU): flexible GMRES (right preconditioning, so
#: the test is on the true residual, and no extra preconditioner application to form the
#: solution); with the condensation it stops after one iteration while the split holds
KRYLOV_OPTIONS = {
    "ksp_type": "fgmres",
    "ksp_rtol": 1e-8,
    "ksp_max_it": 200,
    "pc_type": "python",
}

#: the choices of ``SteadySolver(linear_solver=...)``
LINEAR_SOLVERS = ("auto", "condensed", "reused-lu", "lu", "amg")

#: ``"auto"`` condenses the bulk onto the interface Γ while its dense Schur complement holds
#: at most this fraction of the Jacobian's nonzeros, |Γ|² <= f nnz(J), and reuses an LU beyond.
#: MUMPS forms the complement within the factorisation, at a cost that grows with |Γ|² against
#: the factor; the reused LU costs a few solves per Newton iteration instead. On the block's 2D
#: meshes |Γ|² is 0.08-0.1 nnz(J) and condensing is 4.6x faster (99,202 dofs); on its 3D meshes
#: |Γ|² is 0.14 nnz(J) (945 dofs) to 0.55 (135,975): condensing is 1.2-1.3x faster up to 0.30
#: (18,525 dofs), even at 0.39 (42,075) and slower at 0.55 (docs/benchmarks.md)
AUTO_CONDENSE_MAX_FILL = 0.45


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
    """Outcome of one solve (``atol``: the absolute tolerance actually used; ``iterations``
    summed over the ``rounds`` of Newton solves the contact search needed; ``krylov_iterations``:
    the Krylov iterations of the last round's linear solves, 0 or 1 each for a direct solve)."""

    converged: bool
    reason: str
    iterations: int
    residual_norm: float
    wall_time_s: float
    atol: float
    rounds: int = 1
    krylov_iterations: int = 0
    #: :func:`solve_continued`: how the value was reached (``None``: a direct solve), with
    #: ``start``, ``steps``, ``cutbacks``, ``arclength_steps`` and ``turning_points``
    continuation: dict | None = None


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
            of the residual's round-off floor, sqrt(n) ‖J‖_∞ ‖u‖_∞ times the machine
            precision (cancellation in J u, large when a soft spring carries a large rigid
            displacement); 0 disables it. The bound over-estimates the floor Newton actually
            reaches by 10-100x on the block (e.g. 7e-4 against 5e-6 on the 32x24 mesh), so a
            factor 1 is safe.
        linear_solver: how Newton's linear systems are solved (one of
            :data:`LINEAR_SOLVERS`). ``"condensed"``: the linear bulk condensed onto the
            nonlinear interface (one factorisation of the bulk for the whole continuation,
            :mod:`fenicsfriction.condensation`), where the Jacobian splits so (else the sparse
            LU); ``"reused-lu"``: flexible GMRES preconditioned by the LU of an earlier
            iteration's Jacobian, renewed when the Krylov count grows
            (:mod:`fenicsfriction.reused_lu`); ``"lu"``: a sparse LU at every iteration;
            ``"amg"``: GMRES preconditioned by GAMG with the bodies' rigid-body
            near-nullspace (:mod:`fenicsfriction.amg`); ``"auto"`` (default): AMG beyond the
            measured crossover (:func:`fenicsfriction.amg.choose_linear_solver`: in 3D, from
            :data:`~fenicsfriction.amg.AMG_MIN_UNKNOWNS_3D_REUSED_LU` unknowns per rank where
            the Jacobian splits, :data:`~fenicsfriction.amg.AMG_MIN_UNKNOWNS_3D` where it does
            not; never with contact couplings), else
            condensed while the dense Schur complement is small against
            the Jacobian (:data:`AUTO_CONDENSE_MAX_FILL`: in 2D), the reused LU beyond (3D),
            the LU where the Jacobian does not split. A PC chosen
            in the PETSc options overrides it: ``-<prefix>pc_type lu`` the direct path,
            ``-<prefix>pc_type gamg`` or ``hypre`` the AMG path with that preconditioner.
            Where the Jacobian splits, the first two and AMG assemble the constant bulk once
            and only the interface at each iteration (docs/solvers.md has what each costs).
        search_rounds: how many Newton solves :meth:`solve_searched` (each step of
            :func:`continuation`) may run until a search of the contact couplings at the
            converged state keeps their pairing; 1 (default): one solve, no search after it.
            Mortar contact, whose geometry is held within a solve, needs more wherever the
            bodies slide between solves (10 for the block on a slab).

    Attributes:
        snes: the PETSc SNES, exposed for monitoring or further configuration.
        L, a: the compiled residual and Jacobian forms.
        linear_solver: the choice in effect (``"auto"`` resolved).
        preconditioner: the ``PCPYTHON`` context of the first two choices (``None`` for the
            LU and AMG); ``condensation`` is it when it condenses, else ``None``.
        near_nullspace: the rigid-body modes attached to the Jacobian on the AMG path (one set
            per body), else ``None``.
    """

    def __init__(self, residual: Residual, prefix: str = "steady_",
                 options: dict | None = None, jit_cache_dir: str | None = None,
                 roundoff_safety: float = 1.0, linear_solver: str = "auto",
                 search_rounds: int = 1):
        check("linear_solver", linear_solver, linear_solver in LINEAR_SOLVERS,
              f"use one of {', '.join(LINEAR_SOLVERS)}")
        check("search_rounds", search_rounds,
              isinstance(search_rounds, int) and search_rounds >= 1, "an integer >= 1")
        self.search_rounds = search_rounds
        self.residual = residual
        self.u = residual.u
        t0 = time.perf_counter()
        self.L = _compat.form(residual.steady(), jit_cache_dir)
        jacobian = residual.steady_jacobian()
        self.a = _compat.form(jacobian, jit_cache_dir)
        self.jit_time_s = time.perf_counter() - t0
        self.b = dolfinx.fem.petsc.create_vector(self.L)
        self.A = dolfinx.fem.petsc.create_matrix(self.a)
        self.x = self.b.duplicate()
        # the contact couplings' steady residual and its derivative in u; with them the
        # integrals are assembled apart (dolfinx assembles only into its own pattern)
        self.couplings: list[CouplingOperator] = [
            c.operator({self.u: 1.0}, rest=[residual.u_dot], jit_cache_dir=jit_cache_dir)
            for c in residual.couplings]
        self._coupled = CoupledMatrix(self.A) if self.couplings else None
        if self._coupled is not None:
            self.A = self._coupled.A
        comm = self.u.function_space.mesh.comm
        dim = self.u.function_space.mesh.geometry.dim
        # the constant bulk and the interface: not for the LU per iteration (unless the options
        # ask for AMG), nor with contact couplings
        split = (None if self.couplings or (linear_solver == "lu" and requested_amg(prefix) is None)
                 else interface_split(jacobian, self.u))
        linear_solver, amg_defaults = resolve_linear_solver(
            prefix, linear_solver, dim, self.A.getSize()[0], comm.size,
            splits=split is not None, contact=bool(self.couplings))
        self.preconditioner: InterfaceCondensation | ReusedFactorisation | None = None
        if split is not None and linear_solver in ("auto", "condensed"):
            nonzeros = self.A.getInfo(PETSc.Mat.InfoType.GLOBAL_SUM)["nz_allocated"]
            self.preconditioner = condensation_for(
                split, self.u.function_space, prefix,
                **({"max_interface": int(np.sqrt(AUTO_CONDENSE_MAX_FILL * nonzeros))}
                   if linear_solver == "auto" else {}))
        if linear_solver == "reused-lu" and self.couplings:
            raise ValueError("linear_solver='reused-lu' is not available with contact "
                             "couplings (their pattern changes with the pairing); use 'lu'")
        if linear_solver == "reused-lu" or (linear_solver == "auto" and split is not None
                                             and self.preconditioner is None):
            self.preconditioner = ReusedFactorisation(comm, prefix)
        self.snes = PETSc.SNES().create(comm)
        self.snes.setOptionsPrefix(prefix)
        self.snes.setFunction(self._F, self.b)
        self.snes.setJacobian(self._J, self.A)
        defaults = {**DEFAULT_OPTIONS, **(KRYLOV_OPTIONS if self.preconditioner else {}),
                    **amg_defaults,
                    **(options or {})}
        with options_with_defaults(prefix, defaults):
            self.snes.setFromOptions()
            self.snes.getKSP().setFromOptions()
            self.snes.getKSP().getPC().setFromOptions()
            self.convergence = RoundoffConvergence(self.snes, roundoff_safety)  # reads options
        pc = self.snes.getKSP().getPC()
        self._bulk: PETSc.Mat | None = None
        self._bulk_watcher: BulkWatcher | None = None
        if self.preconditioner is not None and pc.getType() == "python":
            # its factorisations are set up at the first solve, after the defaults are gone
            self.preconditioner.option_defaults = dict(options or {})
            pc.setPythonContext(self.preconditioner)
            self.linear_solver = ("condensed" if isinstance(self.preconditioner,
                                                           InterfaceCondensation)
                                  else "reused-lu")
        else:
            self.preconditioner = None
            self.linear_solver = "lu"
        self.near_nullspace: PETSc.NullSpace | None = None
        if uses_amg(self.snes.getKSP()):  # also when chosen by the options only
            self.near_nullspace = attach_near_nullspace(self.A, self.u.function_space)
            self.linear_solver = "amg"
        # defaults in place during each solve: AMG configures its levels at the first
        self._solve_defaults = defaults if self.linear_solver == "amg" else {}
        if (self.preconditioner is not None or self.linear_solver == "amg") and split is not None:
            # the bulk's Jacobian is constant: assembled once, the interface at each iteration
            bulk_form, interface = split
            self._a_interface = _compat.form(ufl.Form(interface), jit_cache_dir)
            self._a_bulk = _compat.form(bulk_form, jit_cache_dir)
            assemble_jacobian(self.A, self.a, residual.bcs, residual.springs)  # full pattern
            self._bulk = self.A.duplicate(copy=True)  # so the copy in _J keeps it
            # a change of what the bulk depends on besides u (a continued bulk parameter)
            # re-assembles the bulk and refactorises
            self._bulk_watcher = BulkWatcher([bulk_form], self._assemble_bulk)
            self._bulk_watcher.refresh()
        self.snes.setConvergenceTest(self.convergence)

    def _update(self, x: PETSc.Vec) -> None:
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        x.copy(_compat.petsc_vec(self.u))
        self.u.x.scatter_forward()

    def _F(self, snes, x, b):
        self._update(x)
        assemble_residual(b, self.L, self.a, self.residual.bcs, x, self.residual.springs,
                          self.couplings)

    def _assemble_bulk(self) -> None:
        assemble_jacobian(self._bulk, self._a_bulk, self.residual.bcs, self.residual.springs)

    @property
    def condensation(self) -> InterfaceCondensation | None:
        """The condensation in use, if the bulk is condensed onto the interface."""
        condensed = isinstance(self.preconditioner, InterfaceCondensation)
        return typing.cast(InterfaceCondensation, self.preconditioner) if condensed else None

    def _J(self, snes, x, A, P):
        if self.preconditioner is not None:
            self.preconditioner.krylov_count(snes.getKSP().getIterationNumber())
        if self._bulk_watcher is not None:
            if self._bulk_watcher.refresh() and self.preconditioner is not None:
                self.preconditioner.stale = True
            assemble_jacobian(A, self._a_interface, self.residual.bcs, base=self._bulk)
        elif self._coupled is not None:
            assemble_jacobian(self._coupled.base, self.a, self.residual.bcs,
                              self.residual.springs)
            if self._coupled.assemble(self.couplings, self.residual.bcs):
                snes.getKSP().getPC().reset()
                if self.near_nullspace is not None:  # on the matrix whose storage was replaced
                    A.setNearNullSpace(self.near_nullspace)
        else:
            assemble_jacobian(A, self.a, self.residual.bcs, self.residual.springs)
        self.convergence.jacobian_assembled(A)

    def solve(self) -> SolveReport:
        """Solve from the current ``u``, the contact couplings' pairing searched at the first
        residual; on failure restore ``u`` and raise :class:`SolveError`."""
        saved = _compat.petsc_vec(self.u).copy()
        report = self._newton()
        if not report.converged:
            saved.copy(_compat.petsc_vec(self.u))
            self.u.x.scatter_forward()
        saved.destroy()
        if not report.converged:
            raise SolveError(
                f"Newton did not converge ({report.reason}) after {report.iterations} "
                f"iterations, residual norm {report.residual_norm:.3e}; state restored", report)
        return report

    def solve_searched(self) -> SolveReport:
        """:meth:`solve`, repeated from its result while a search of the contact couplings at
        the converged state changes their pairing (up to ``search_rounds`` solves): the state
        returned is an equilibrium of its own pairing, a fixed point of the search
        (:func:`fenicsfriction.contact.solve_with_search` for any solver). Mortar contact,
        whose geometry is held within a solve, needs it wherever the bodies slide between
        solves (the block on a slab slides 2 cm between continuation steps); node-to-segment
        contact recomputes its projections within the solve. :func:`continuation` solves so.

        Raises:
            SolveError: a solve failed (``u`` is the last converged round's, or the start), or
                the pairing still changed after ``search_rounds`` solves.
        """
        if self.search_rounds == 1:
            return self.solve()
        t0 = time.perf_counter()
        iterations = 0
        for rounds in range(1, self.search_rounds + 1):
            try:
                report = self.solve()
            except SolveError as err:
                err.report.iterations += iterations
                raise
            iterations += report.iterations
            report.iterations, report.rounds = iterations, rounds
            report.wall_time_s = time.perf_counter() - t0
            # every coupling searches (collectively), whether or not another changed
            changed = [coupling.contact.search() for coupling in self.couplings]
            if not any(changed):
                return report
        raise SolveError(f"contact search: the pairing still changed after "
                         f"{self.search_rounds} Newton solves (search_rounds)", report)

    def _newton(self) -> SolveReport:
        """One SNES solve from the current ``u``; ``u`` takes the result if it converged."""
        for coupling in self.couplings:
            coupling.contact.search_pending = True
        _compat.petsc_vec(self.u).copy(self.x)
        t0 = time.perf_counter()
        # GAMG reads its levels' options when it builds them, at the first solve
        with options_with_defaults(self.snes.getOptionsPrefix(), self._solve_defaults):
            self.snes.solve(None, self.x)
        reason = self.snes.getConvergedReason()
        report = SolveReport(
            converged=reason > 0, reason=_REASONS.get(reason, str(reason)),
            iterations=self.snes.getIterationNumber(),
            residual_norm=float(self.snes.getFunctionNorm()),
            wall_time_s=time.perf_counter() - t0, atol=self.convergence.atol_used,
            krylov_iterations=self.snes.getLinearSolveIterations())
        report.converged = report.converged and bool(np.isfinite(report.residual_norm))
        if report.converged:
            self._update(self.x)
        return report


def continuation(solver: SteadySolver, parameter: fem.Constant, targets: typing.Iterable[float],
                 observe: typing.Callable[[], typing.Any] | None = None,
                 max_halvings: int = 8,
                 on_step: typing.Callable[[dict], None] | None = None,
                 predictor: str = "secant") -> list[dict]:
    """Step ``parameter`` through ``targets``, solving at each value.

    Args:
        solver: the steady solver (its ``u`` is the warm start and holds the result); a
            :class:`SteadySolver` solves each step with :meth:`SteadySolver.solve_searched`.
        parameter: the ``fem.Constant`` being continued (e.g. the friction coefficient).
        targets: the values to reach, in order; each one reached produces one record.
        observe: returns extra quantities recorded at each converged target, a dict or a
            record (e.g. ``model.quantities``) whose fields become columns of the row.
        max_halvings: how many times a failing increment may be halved.
        on_step: called with each record as soon as it exists (progress output).
        predictor: the initial guess of each solve. ``"secant"``: extrapolated linearly from
            the last two converged states (Keller 1977's secant predictor; the first step and
            the first after a failure start from the last state); ``"none"``: the last state.
            A smooth path then needs about one Newton iteration less per step.

    Returns:
        One record per target: ``value``, ``newton_iterations`` (summed over any halved
        sub-steps), ``residual_norm``, ``halvings``, ``wall_time_s`` and what ``observe`` adds.

    Raises:
        ContinuationError: a step failed after ``max_halvings`` halvings; ``u`` and
            ``parameter`` keep the last converged state, ``error.records`` the steps so far.
    """
    check("predictor", predictor, predictor in ("secant", "none"), "use 'secant' or 'none'")
    # a SteadySolver's solves are repeated until the contact search holds; another solver
    # (the Panagiotopoulos process) searches in its own iterations
    solve = getattr(solver, "solve_searched", solver.solve)
    records: list[dict] = []
    current = float(parameter.value)
    u_vec = _compat.petsc_vec(solver.u)
    converged = u_vec.copy()  # the last converged state
    previous: tuple[float, PETSc.Vec] | None = None  # the one before, for the secant
    try:
        for target in targets:
            t0 = time.perf_counter()
            iterations, halvings, step = 0, 0, target - current
            while True:
                trial = current + step if abs(target - current) > abs(step) else target
                parameter.value = trial
                if predictor == "secant" and previous is not None and previous[0] != current:
                    # u = u_c + (u_c - u_p) (trial - c) / (c - p)
                    u_vec.axpby(1.0, 0.0, converged)
                    u_vec.axpy(-1.0, previous[1])
                    u_vec.scale((trial - current) / (current - previous[0]))
                    u_vec.axpy(1.0, converged)
                    solver.u.x.scatter_forward()
                try:
                    report = solve()
                except SolveError as err:
                    iterations += err.report.iterations
                    parameter.value = current
                    converged.copy(u_vec)  # the solver restored its start: the prediction
                    solver.u.x.scatter_forward()
                    if halvings == max_halvings:
                        raise ContinuationError(
                            f"continuation failed at {trial:.6g} (from converged "
                            f"{current:.6g}, target {target:.6g}) after {halvings} step "
                            f"halvings: {err}", records) from err
                    halvings += 1
                    step /= 2
                    if previous is not None:  # the path bends here: restart from the last state
                        previous[1].destroy()
                        previous = None
                    continue
                iterations += report.iterations
                if previous is None:
                    previous = (current, converged.copy())
                else:
                    converged.copy(previous[1])
                    previous = (current, previous[1])
                u_vec.copy(converged)
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
    finally:
        converged.destroy()
        if previous is not None:
            previous[1].destroy()
    return records


def _row(values: typing.Any) -> dict[str, typing.Any]:
    """The fields of a record (a dataclass such as ``BlockModel.quantities()``), or a dict, as
    the flat columns of a table row (values as they are, so rows do not depend on which)."""
    if dataclasses.is_dataclass(values) and not isinstance(values, type):
        return {f.name: getattr(values, f.name) for f in dataclasses.fields(values)}
    return dict(values)


def epsilon_sequence(solver: SteadySolver, eps: fem.Constant, values: typing.Iterable[float],
                     observe: typing.Callable[[], typing.Any] | None = None,
                     on_step: typing.Callable[[dict], None] | None = None) -> list[dict]:
    """Kalker's sequential ε process: solve for each ε in ``values``, warm-starting each solve.

    Each record has ``eps``, ``newton_iterations``, ``change`` (the max-norm of the solution
    change from the previous ε; ``None`` for the first), ``residual_norm``, ``atol`` and what
    ``observe`` adds; ``on_step`` sees each record as soon as it exists (a caller keeps the
    ones done when a later solve fails). A failing solve raises :class:`SolveError` with ``u``
    and ``eps`` at the last converged ε.
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
        if on_step is not None:
            on_step(record)
    if previous is not None:
        previous.destroy()
    return records



def solve_continued(solver: SteadySolver, parameter: fem.Constant, target: float,
                    start: float = 0.0, max_cutbacks: int = 8, max_arclength_steps: int = 100
                    ) -> SolveReport:
    r"""Solve at ``parameter = target`` from the current ``u``; if Newton fails, reach
    ``target`` by continuation from ``start`` (a value where the same guess converges, e.g.
    μ = 0) instead of giving up.

    The continuation first takes natural steps in the parameter, each from the last
    converged state, halving a step that fails (steps are never lengthened again). When a
    step halved ``max_cutbacks`` times still fails, the branch is taken to fold back there
    (a limit point, where the Jacobian turns singular), and pseudo-arclength continuation
    (Keller 1977) follows it round the fold: the state and the parameter are solved
    together, each step of length ds along the tangent t of the branch,

    .. math::

        R(u, p) = 0, \qquad \langle t, (u - u_k, p - p_k) \rangle = \Delta s,

    with the inner product :math:`\langle a, b \rangle = \frac1n \sum_i a_i b_i / U_i^2
    + a_p b_p`, U_i the mean change of the i-th component of u per unit parameter over the
    natural steps (so that a rigid slide held by a soft spring, 1e6 times a penetration,
    does not hide the penetrations' turn at the fold); each Newton correction is
    found by bordering (two solves with the Jacobian; Keller 1977), t is the solution of
    :math:`J t_u = -\partial_p R\,t_p` (∂_p R by a forward difference), oriented along the
    previous one. Once the branch crosses ``target`` again, Newton solves at ``target`` from
    the state interpolated between the two steps that bracket it. The state reached is
    therefore on the branch connected to ``start``; where the problem has several solutions
    at ``target`` (beyond a fold) it is that branch's, not the one a direct solve might
    find.

    Args:
        solver: the steady solver (its ``u`` holds the guess and the result).
        parameter: the ``fem.Constant`` continued (e.g. the friction coefficient).
        target: the value to solve at.
        start: the easy value the continuation starts from (solved from the same guess).
        max_cutbacks: how many times the natural step may be halved before the steps turn
            to arclength, and how many halvings in a row an arclength step may take before
            giving up.
        max_arclength_steps: a bound on the arclength steps.

    Returns:
        The report of the last solve; its ``continuation`` is ``None`` for a direct solve,
        else a dict with ``start``, ``steps`` (natural steps converged), ``cutbacks`` (all
        halvings), ``arclength_steps`` and ``turning_points`` (the parameter values where the
        branch turned back), also logged.

    Raises:
        ContinuationError: the start did not converge, the arclength steps could not be
            halved further or exceeded ``max_arclength_steps`` (``u`` and ``parameter`` keep
            the last converged state; ``records`` is empty).
    """
    check("max_cutbacks", max_cutbacks, isinstance(max_cutbacks, int) and max_cutbacks >= 0,
          "an integer >= 0")
    solve = solver.solve_searched
    parameter.value = target
    try:
        return solve()
    except SolveError as err:
        log.info("direct solve at %.6g failed (%s); continuing from %.6g", target,
                 err.report.reason, start)
    info: dict[str, typing.Any] = {"start": float(start), "steps": 0, "cutbacks": 0,
                                   "arclength_steps": 0, "turning_points": []}
    parameter.value = start
    try:
        report = solve()
    except SolveError as err:
        parameter.value = start
        raise ContinuationError(f"continuation to {target:.6g}: the start {start:.6g} did not "
                                f"converge either: {err}", []) from err
    u_vec = _compat.petsc_vec(solver.u)
    states = [(float(start), u_vec.copy())]  # the converged natural steps, the last two kept
    origin = u_vec.copy()
    step = target - start
    try:
        while True:  # natural steps, each from the last converged state
            current, converged = states[-1]
            trial = target if abs(target - current) <= abs(step) else current + step
            parameter.value = trial
            try:
                report = solve()
            except SolveError:
                converged.copy(u_vec)
                solver.u.x.scatter_forward()
                parameter.value = current
                if abs(step) <= abs(target - start) / 2**max_cutbacks:
                    break
                info["cutbacks"] += 1
                step /= 2
                continue
            info["steps"] += 1
            if trial == target:
                report.continuation = info
                log.info("reached %.6g by continuation from %.6g: %d steps, %d cut-backs",
                         target, start, info["steps"], info["cutbacks"])
                return report
            if len(states) == 2:
                states.pop(0)[1].destroy()
            states.append((trial, u_vec.copy()))
        log.info("continuation to %.6g: natural steps cannot pass %.6g (a fold?); arclength",
                 target, states[-1][0])
        report = _arclength(solver, parameter, target, states, origin, info, max_cutbacks,
                            max_arclength_steps)
    finally:
        for _, vec in states:
            vec.destroy()
        origin.destroy()
    report.continuation = info
    log.info("reached %.6g by continuation from %.6g: %d steps, %d arclength steps, "
             "%d cut-backs, turning points %s", target, start, info["steps"],
             info["arclength_steps"], info["cutbacks"], info["turning_points"])
    return report


def _arclength(solver: SteadySolver, parameter: fem.Constant, target: float,
               states: list[tuple[float, PETSc.Vec]], origin: PETSc.Vec, info: dict,
               max_cutbacks: int, max_steps: int) -> SolveReport:
    """Pseudo-arclength steps from the last of ``states`` (the natural steps' last two)
    until the branch crosses ``target``, then Newton at ``target`` (see
    :func:`solve_continued`; ``origin``: the state at ``info["start"]``)."""
    u_vec = _compat.petsc_vec(solver.u)
    comm = solver.u.function_space.mesh.comm
    p_k, u_k = states[-1][0], states[-1][1].copy()
    # U_i: the mean change of each component of u per unit parameter from the start, so
    # that every component counts alike (a rigid slide held by a soft spring can be 1e6
    # times a penetration, whose change near a fold is what the steps must follow); nearly
    # still components are floored at 1e-6 of the largest
    weights = u_k.copy()
    weights.axpy(-1.0, origin)
    travelled = abs(p_k - info["start"]) or 1.0
    weights.abs()
    weights.scale(1.0 / travelled)
    floor = max(weights.max()[1], 1e-300) * 1e-6
    with weights.localForm() as local:
        local.array[:] = 1.0 / np.maximum(local.array, floor) ** 2 / weights.getSize()
    work = u_k.duplicate()
    diff = u_k.copy()
    # the first step: as long as the last natural step, in the arclength metric
    if len(states) > 1:
        u_k.copy(diff)
        diff.axpy(-1.0, states[0][1])
        work.pointwiseMult(weights, diff)
        ds = float(np.sqrt(work.dot(diff) + (p_k - states[0][0]) ** 2))
    else:
        ds = abs(target - p_k) / 8
    diff.destroy()
    ksp = PETSc.KSP().create(comm)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    F, F_p, z1, z2 = (u_vec.duplicate() for _ in range(4))
    t_u, t_p = u_vec.duplicate(), 0.0
    atol = max(solver.convergence.atol_used, solver.snes.getTolerances()[1])

    def residual(p: float, out: PETSc.Vec) -> None:
        parameter.value = p
        solver._F(solver.snes, u_vec, out)

    def jacobian_solves(p: float, tangent_only: bool = False) -> None:
        """z2 = -J⁻¹ ∂_p R at (u, p); z1 = -J⁻¹ R too unless ``tangent_only``."""
        h = 1e-7 * max(1.0, abs(p))
        residual(p + h, F_p)
        residual(p, F)
        F_p.axpy(-1.0, F)
        F_p.scale(-1.0 / h)
        solver._J(solver.snes, u_vec, solver.A, solver.A)
        ksp.setOperators(solver.A)
        ksp.setUp()
        ksp.solve(F_p, z2)
        if not tangent_only:
            F.scale(-1.0)
            ksp.solve(F, z1)
            F.scale(-1.0)

    def dot(a_u: PETSc.Vec, a_p: float, b_u: PETSc.Vec, b_p: float) -> float:
        work.pointwiseMult(weights, a_u)
        return work.dot(b_u) + a_p * b_p

    def tangent(previous: tuple[PETSc.Vec, float] | None) -> None:
        nonlocal t_p
        u_k.copy(u_vec)
        solver.u.x.scatter_forward()
        jacobian_solves(p_k, tangent_only=True)
        z2.copy(t_u)
        t_p = 1.0
        norm = np.sqrt(dot(t_u, t_p, t_u, t_p))
        sign = (np.sign(dot(t_u, t_p, *previous)) if previous is not None
                else np.sign(target - p_k))
        t_u.scale(sign / norm)
        t_p = sign / norm

    previous: tuple[PETSc.Vec, float] | None = None
    halvings = 0
    try:
        tangent(None)
        for _ in range(max_steps):
            # predictor along the tangent, corrector: Newton on (R, arclength) by bordering
            u_k.copy(u_vec)
            u_vec.axpy(ds, t_u)
            p = p_k + ds * t_p
            converged = False
            for _ in range(25):
                solver.u.x.scatter_forward()
                jacobian_solves(p)
                d_u = u_vec.copy()
                d_u.axpy(-1.0, u_k)
                N = dot(t_u, t_p, d_u, p - p_k) - ds
                d_u.destroy()
                log.debug("arclength p %.8g ds %.3g t_p %.3g |F| %.3e (atol %.3e) N %.3e",
                          p, ds, t_p, F.norm(), atol, N)
                if F.norm() <= 10 * atol and abs(N) <= 1e-8 * ds:
                    converged = True
                    break
                dp = (-N - dot(t_u, 0.0, z1, 0.0)) / (t_p + dot(t_u, 0.0, z2, 0.0))
                u_vec.axpy(1.0, z1)
                u_vec.axpy(dp, z2)
                p += dp
                if not np.isfinite(p) or not np.isfinite(u_vec.norm()):
                    break
            if not converged:
                if halvings == max_cutbacks:
                    raise ContinuationError(
                        f"arclength continuation to {target:.6g} stalled at {p_k:.6g} after "
                        f"{halvings} halvings of its step", [])
                halvings += 1
                info["cutbacks"] += 1
                ds /= 2
                continue
            halvings = 0
            info["arclength_steps"] += 1
            if (p - target) * (p_k - target) <= 0:  # crossed: Newton at target from between
                weight = (target - p_k) / (p - p_k)
                u_vec.scale(weight)
                u_vec.axpy(1.0 - weight, u_k)
                solver.u.x.scatter_forward()
                parameter.value = target
                try:
                    return solver.solve_searched()
                except SolveError as err:
                    raise ContinuationError(f"arclength continuation crossed {target:.6g} "
                                            f"but Newton there failed: {err}", []) from err
            u_vec.copy(u_k)
            p_k = p
            t_old = (t_u.copy(), t_p)
            if previous is not None:
                previous[0].destroy()
            previous = t_old
            tangent(previous)
            if np.sign(t_p) != np.sign(previous[1]):
                info["turning_points"].append(float(p_k))
            ds *= 1.5
        raise ContinuationError(f"arclength continuation did not reach {target:.6g} within "
                                f"{max_steps} steps (max_arclength_steps)", [])
    except ContinuationError:
        u_k.copy(u_vec)
        solver.u.x.scatter_forward()
        parameter.value = p_k
        raise
    finally:
        for vec in (F, F_p, z1, z2, t_u, u_k, weights, work):
            vec.destroy()
        if previous is not None:
            previous[0].destroy()
        ksp.destroy()
