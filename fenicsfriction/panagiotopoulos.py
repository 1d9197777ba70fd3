r"""The Panagiotopoulos process: the friction bound frozen between Newton solves (Kalker 1986, §3).

Kalker (1986, section 3) solves frictional contact with an unknown normal pressure by
alternating two problems until the tangential traction :math:`p_\tau` stops changing:

1. :math:`p_\tau^{(0)} = 0`;
2. the normal problem with :math:`p_\tau^{(I)}` as tangential traction gives :math:`p_n^{(I)}`;
   the tangential problem with :math:`p_n^{(I)}` as normal traction gives
   :math:`p_\tau^{(I+1)}`; stop when it is close to :math:`p_\tau^{(I)}`.

It may diverge for large μ, where the solution is no longer unique; stopped after one step it is
Johnson's approximation (frictionless normal problem, then the tangential one). Oden & Pires
(1983) proved existence through the same iteration with the bound frozen between iterations.

**How it is derived from the one residual.** The only way the normal state enters the friction
term is its bound :math:`c_T d^{m_T}` (:func:`fenicsfriction.laws.friction_traction` labels it
with :data:`fenicsfriction.laws.FRICTION_BOUND`). The process replaces that labelled
expression, wherever it occurs in :attr:`Residual.form`, by the same expression evaluated at a
frozen copy :math:`u_N` of the state (``bound_state``), or by its mollification
(:mod:`fenicsfriction.mollification`); everything else — elasticity, normal compliance, the
loads — stays at the current u. A two-body contact coupling
(:class:`~fenicsfriction.coupling.FrictionBoundCoupling`) has its forms compiled apart: it
hands over its bound and the Functions its geometry is made of (``configuration``: u, the
master's mirror, the pairing's reference coordinates), and is rebuilt with the bound evaluated
at their frozen copies, so that a later search of the pairing leaves the frozen bound where
it was. Each outer iteration is one Newton solve
(:class:`~fenicsfriction.steady.SteadySolver`) of that frozen residual, which is Kalker's two
half-steps fused: the tangential traction follows the law with the bound of the last iterate
(the tangential problem with :math:`p_n^{(I)}` fixed) while the normal state responds to it
(the normal problem with :math:`p_\tau^{(I+1)}`). The first solve has the bound switched off
(:math:`p_\tau^{(0)} = 0`: the frictionless normal problem); ``method="johnson"`` stops after
the second.

**Stopping.** After each solve the friction term is assembled twice, with the bound it was
solved with and with the bound of the new state: the relative change of these nodal friction
forces, :math:`\|f^{(I+1)} - f^{(I)}\| / \|f^{(I+1)}\|`, is the change of the tangential
traction, and also exactly the coupled residual of the new state relative to its friction
forces (the two residuals differ only by that term). A coupling's friction is not an
integral of its own: its nodal forces are its residual less its residual with the friction
switched off. The process stops when it is below
``rtol``; it gives up (:class:`ProcessError`, the last iterate kept in ``u``) when an inner
solve fails, when the change has not reached a new minimum for ``patience`` iterations
(divergence or a cycle), or after ``max_iterations``.
"""

from __future__ import annotations

import dataclasses
import time
import typing

from petsc4py import PETSc

import numpy as np
import ufl
from dolfinx import fem

from fenicsfriction import _compat
from fenicsfriction.assembly import assemble_into, assemble_owned
from fenicsfriction.coupling import FrictionBoundCoupling
from fenicsfriction.forms import Residual
from fenicsfriction.laws import check, check_positive, friction_bounds, substitute_friction_bound
from fenicsfriction.mollification import SurfaceMollifier
from fenicsfriction.steady import SolveError, SteadySolver

__all__ = ["METHODS", "PanagiotopoulosSolver", "ProcessError", "ProcessReport",
           "friction_bounds", "substitute_friction_bound"]

#: the choices of ``PanagiotopoulosSolver(method=...)``: coupled Newton on the residual itself,
#: the process to convergence, the process stopped after one step (Johnson)
METHODS = ("newton", "panagiotopoulos", "johnson")


@dataclasses.dataclass
class ProcessReport:
    """Outcome of one :meth:`PanagiotopoulosSolver.solve`.

    Attributes:
        method: one of :data:`METHODS`.
        converged: the relative change fell below ``rtol`` (Newton: SNES converged; Johnson:
            whether its one step happened to be within ``rtol``, for information).
        outer_iterations: Newton solves of the frozen residual (the first one frictionless);
            1 for Newton.
        newton_iterations: Newton iterations summed over them.
        wall_time_s: time of the whole solve.
        changes: the relative change of the tangential traction after each outer iteration.
        reason: why it stopped.
        parameters: the values of the watched parameters (e.g. μ) during the solve.
    """

    method: str
    converged: bool
    outer_iterations: int
    newton_iterations: int
    wall_time_s: float
    changes: list[float]
    reason: str
    parameters: dict[str, float]


class ProcessError(RuntimeError):
    """The process did not converge; ``report`` says how, ``u`` holds the last iterate."""

    def __init__(self, message: str, report: ProcessReport):
        super().__init__(message)
        self.report = report


class PanagiotopoulosSolver:
    """Steady frictional problems by coupled Newton, the Panagiotopoulos process or Johnson's step.

    Args:
        residual: the problem's one residual (its ``u``: the initial guess and the result). The
            process needs a friction term (:func:`fenicsfriction.forms.friction`) or a contact
            coupling with friction; every coupling must be a
            :class:`~fenicsfriction.coupling.FrictionBoundCoupling` (node-to-segment and
            mortar contact), its bound fixed the same way as the integrals'.
        method: one of :data:`METHODS`.
        rtol: the relative change of the tangential traction at which the process stops.
        max_iterations: the most outer iterations (Newton solves of the frozen residual).
        patience: outer iterations allowed without a new smallest change before the process
            is declared divergent.
        mollification_radius: r >= 0 of the mollified friction bound (Oden & Pires 1983;
            :mod:`fenicsfriction.mollification`); 0 is the local law. The mollified law is
            solved by the process only: its bound depends on the pressure of every node within
            r, whose derivative Newton's Jacobian does not have.
        parameters: named constants reported with each solve and named in errors
            (e.g. ``{"mu": model.mu}``).
        prefix, options, linear_solver, jit_cache_dir: of the inner
            :class:`~fenicsfriction.steady.SteadySolver` (the frozen residual's; Newton's with
            ``method="newton"``).

    Attributes:
        solver: the inner SteadySolver.
        bound_state: the frozen copy :math:`u_N` the local bound is evaluated at (with
            couplings, also the frozen copies of their ``configuration``).
        mollified_bound: the nodal field of the mollified bound (``None`` for r = 0).
        frozen: the frozen :class:`~fenicsfriction.forms.Residual` (``None`` for Newton).
    """

    def __init__(self, residual: Residual, method: str = "panagiotopoulos", rtol: float = 1e-8,
                 max_iterations: int = 50, patience: int = 3,
                 mollification_radius: float = 0.0,
                 parameters: dict[str, fem.Constant] | None = None,
                 prefix: str = "panagiotopoulos_", options: dict | None = None,
                 linear_solver: str = "auto", jit_cache_dir: str | None = None):
        check("method", method, method in METHODS, f"use one of {', '.join(METHODS)}")
        check_positive("rtol", rtol)
        check("max_iterations", max_iterations,
              isinstance(max_iterations, int) and max_iterations >= 2, "an integer >= 2")
        check("patience", patience, isinstance(patience, int) and patience >= 1,
              "an integer >= 1")
        check_positive("mollification_radius", mollification_radius, strict=False)
        check("mollification_radius", mollification_radius,
              mollification_radius == 0 or method != "newton",
              "the mollified law is solved by the Panagiotopoulos process only (method "
              "'panagiotopoulos' or 'johnson')")
        self.method, self.rtol = method, rtol
        self.max_iterations, self.patience = max_iterations, patience
        self.parameters = dict(parameters or {})
        self.u = residual.u
        self.frozen: Residual | None = None
        self.mollified_bound: fem.Function | None = None
        V = residual.V
        self.bound_state = fem.Function(V, name="bound_state")
        solver_args: dict[str, typing.Any] = {"prefix": prefix, "options": options,
                                              "linear_solver": linear_solver,
                                              "jit_cache_dir": jit_cache_dir}
        if method == "newton":
            self.solver = SteadySolver(residual, **solver_args)
            return
        couplings = list(residual.couplings)
        for coupling in couplings:
            check("residual", "couplings", isinstance(coupling, FrictionBoundCoupling),
                  "contact couplings that expose their friction bound (configuration, "
                  "friction_bound, with_friction_bound, search: "
                  "fenicsfriction.coupling.FrictionBoundCoupling)")
        coupling_bounds = [c.friction_bound() for c in couplings]
        steady = residual.steady()
        bounds = friction_bounds(steady)
        check("residual", "form", bool(bounds) or any(b is not None for b in coupling_bounds),
              "the process needs a friction term (fenicsfriction.forms.friction, or a contact "
              "coupling with friction)")
        msh = V.mesh
        self.friction_on = fem.Constant(msh, 1.0)
        if mollification_radius > 0:
            check("mollification_radius", mollification_radius, not couplings,
                  "the mollified bound is built on the residual's own friction integrals; "
                  "with contact couplings use 0")
            check("residual", "form", len(bounds) == 1,
                  f"one friction bound to mollify (found {len(bounds)})")
            self._bound = bounds[0]
            self._build_mollifier(steady, mollification_radius)
        # the fields a bound is evaluated at, each with its frozen copy: u, and the Functions
        # each coupling's geometry is made of (the master's mirror, the pairing's reference
        # coordinates), so that a later search does not move a frozen bound
        self._frozen_fields: dict[fem.Function, fem.Function] = {self.u: self.bound_state}
        for coupling, bound in zip(couplings, coupling_bounds, strict=True):
            if bound is not None:
                for f in coupling.configuration:
                    self._frozen_fields.setdefault(
                        f, fem.Function(f.function_space, name=f"frozen_{f.name}"))

        def replacement(bound: typing.Any) -> typing.Any:
            # switched off (friction_on = 0) for the first, frictionless, solve
            if self.mollified_bound is not None:
                return self.friction_on * self.mollified_bound
            return self.friction_on * ufl.replace(bound, self._frozen_fields)

        frozen_couplings = [c if b is None else c.with_friction_bound(replacement(b))
                            for c, b in zip(couplings, coupling_bounds, strict=True)]
        self.frozen = dataclasses.replace(
            residual, form=substitute_friction_bound(residual.form, replacement),
            couplings=frozen_couplings)
        self.solver = SteadySolver(self.frozen, **solver_args)
        # the friction integrals of the frozen steady residual: their assembled vector is the
        # tangential traction (as nodal forces) the bound of the moment produces; a coupling's
        # friction is not an integral of its own, so its part is its compiled residual less
        # the same without friction (friction_on = 0)
        friction = ufl.Form([i for i in steady.integrals() if friction_bounds(ufl.Form([i]))])
        self._friction = (_compat.form(substitute_friction_bound(friction, replacement),
                                       jit_cache_dir) if friction.integrals() else None)
        self._couplings = [op for op, b in zip(self.solver.couplings, coupling_bounds, strict=True)
                           if b is not None]
        self._used = self.solver.b.duplicate()
        self._new = self._used.duplicate()
        self._frictionless, self._scratch = self._used.duplicate(), self._used.duplicate()

    # --- the frozen bound ----------------------------------------------------------------------
    def _build_mollifier(self, steady: ufl.Form, radius: float) -> None:
        """The nodal space of the bound on Γ_C, the lumped projection onto its surface nodes
        and the mollifier of those nodes."""
        integrals = [i for i in steady.integrals() if friction_bounds(ufl.Form([i]))]
        measures = {(i.integral_type(), i.subdomain_id(), repr(i.metadata())) for i in integrals}
        check("residual", "form", len(measures) == 1 and integrals[0].integral_type()
              == "exterior_facet", "a mollified bound on one exterior-facet measure")
        first = integrals[0]
        ds = ufl.Measure(first.integral_type(), domain=first.ufl_domain(),
                         subdomain_id=first.subdomain_id(),
                         subdomain_data=first.subdomain_data(), metadata=first.metadata())
        V = self.u.function_space
        msh = V.mesh
        S = _compat.scalar_function_space(msh, "Lagrange", _compat.element_degree(V))
        fdim = msh.topology.dim - 1
        tags, tag = first.subdomain_data(), first.subdomain_id()
        facets = tags.indices[tags.values == tag]
        dofs = fem.locate_dofs_topological(S, fdim, facets)
        self._surface = dofs[dofs < S.dofmap.index_map.size_local]
        q = ufl.TestFunction(S)
        self._bound_form = _compat.form(self._bound * q * ds)
        self._weights = assemble_owned(_compat.form(q * ds))[self._surface]
        points = S.tabulate_dof_coordinates()[self._surface, :msh.geometry.dim]
        self.mollifier = SurfaceMollifier(points, self._weights, radius, msh.comm)
        self.mollified_bound = fem.Function(S, name="mollified_bound")

    def nodal_bound(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(coordinates, local bound c_T d^{m_T} at the current ``u``, the mollified bound
        frozen for the next solve) at the surface nodes this rank owns, for a mollified solver.
        The local bound is the lumped projection on the nodes: their exact values under the
        nodal contact rule."""
        check("mollification_radius", 0.0, self.mollified_bound is not None,
              "nodal values are kept by a mollified solver (radius > 0)")
        assert self.mollified_bound is not None
        local = assemble_owned(self._bound_form)[self._surface] / self._weights
        S = self.mollified_bound.function_space
        return (S.tabulate_dof_coordinates()[self._surface], local,
                self.mollified_bound.x.array[self._surface].copy())

    def _freeze(self) -> None:
        """Evaluate the bound at the current state and keep it for the next solve."""
        if self.mollified_bound is None:
            for field, frozen in self._frozen_fields.items():
                frozen.x.array[:] = field.x.array  # same layout, ghosts included
            return
        _, local, _ = self.nodal_bound()
        self.mollified_bound.x.array[self._surface] = self.mollifier(local)
        self.mollified_bound.x.scatter_forward()

    def _coupling_residual(self, vector: PETSc.Vec) -> PETSc.Vec:
        """The couplings' residual at the current state, their mirrors refreshed."""
        with vector.localForm() as local:
            local.set(0.0)
        for operator in self._couplings:
            operator.add_to_residual(vector)
        return vector

    def _without_friction(self) -> None:
        """Keep the couplings' residual with the friction switched off (``_frictionless``)."""
        if self._couplings:
            on = float(self.friction_on.value)
            self.friction_on.value = 0.0
            self._coupling_residual(self._frictionless)
            self.friction_on.value = on

    def _traction(self, vector: PETSc.Vec) -> PETSc.Vec:
        """The nodal friction forces of the bound of the moment: the friction integrals', and
        the couplings' residual less :meth:`_without_friction`'s."""
        with vector.localForm() as local:
            local.set(0.0)
        if self._friction is not None:
            assemble_into(vector, self._friction)
        if self._couplings:
            vector.axpy(1.0, self._coupling_residual(self._scratch))
            vector.axpy(-1.0, self._frictionless)
        return vector

    def _searched_again(self) -> bool:
        """Search every coupling's pairing at the current state; True if one changed (the
        state was solved with a pairing it no longer has)."""
        assert self.frozen is not None
        changed = [coupling.search() for coupling in self.frozen.couplings]  # every one
        return any(changed)

    # --- the solve ----------------------------------------------------------------------------
    def _report(self, converged: bool, outer: int, newton: int, t0: float, changes: list,
                reason: str) -> ProcessReport:
        return ProcessReport(
            method=self.method, converged=converged, outer_iterations=outer,
            newton_iterations=newton, wall_time_s=time.perf_counter() - t0,
            changes=list(changes), reason=reason,
            parameters={name: float(c.value) for name, c in self.parameters.items()})

    def _where(self) -> str:
        values = ", ".join(f"{n}={float(c.value):.6g}" for n, c in self.parameters.items())
        return f" at {values}" if values else ""

    def solve(self) -> ProcessReport:
        """Solve from the current ``u``; the result is left in ``u``.

        Raises:
            ProcessError: the process (or Newton) did not converge; ``u`` holds the last
                iterate that an inner solve converged to, ``error.report`` the history.
        """
        t0 = time.perf_counter()
        if self.method == "newton":
            try:
                inner = self.solver.solve()
            except SolveError as err:
                report = self._report(False, 1, err.report.iterations, t0, [], str(err))
                raise ProcessError(f"Newton failed{self._where()}: {err}", report) from err
            return self._report(True, 1, inner.iterations, t0, [], inner.reason)
        changes: list[float] = []
        newton = 0
        since = 0  # the patience counts the changes since the last change of the pairing
        outer_limit = 2 if self.method == "johnson" else self.max_iterations
        self.friction_on.value = 0.0  # p_τ(0) = 0: the frictionless normal problem first
        for outer in range(1, outer_limit + 1):
            try:
                newton += self.solver.solve().iterations
            except SolveError as err:
                newton += err.report.iterations
                report = self._report(False, outer - 1, newton, t0, changes,
                                      f"inner Newton failed: {err.report.reason}")
                last = f"{changes[-1]:.3e}" if changes else "none"
                raise ProcessError(
                    f"Panagiotopoulos process{self._where()}: the Newton solve of outer "
                    f"iteration {outer} failed ({err.report.reason}); last change {last}; "
                    "u holds the last iterate", report) from err
            self._without_friction()
            used = self._traction(self._used)
            self.friction_on.value = 1.0
            self._freeze()
            new = self._traction(self._new)
            size = new.norm()
            new.axpy(-1.0, used)
            change = new.norm() / size if size > 0 else (0.0 if new.norm() == 0 else np.inf)
            changes.append(float(change))
            if change <= self.rtol:
                if self.method == "johnson" or not self._searched_again():
                    return self._report(True, outer, newton, t0, changes,
                                        f"change {change:.3e} <= rtol {self.rtol:.1e}")
                since = len(changes)  # solved with a pairing it no longer has: go on
                continue
            if self.method == "johnson" and outer == 2:
                return self._report(False, outer, newton, t0, changes,
                                    "one step (Johnson's approximation)")
            best = since + int(np.argmin(changes[since:]))
            if not np.isfinite(change) or len(changes) - 1 - best >= self.patience:
                report = self._report(False, outer, newton, t0, changes,
                                      "the change stopped falling")
                raise ProcessError(
                    f"Panagiotopoulos process{self._where()} diverges: the change of the "
                    f"tangential traction has not fallen below its minimum "
                    f"{changes[best]:.3e} (iteration {best + 1}) for {self.patience} "
                    f"iterations; at iteration {outer} it is {change:.3e}; u holds the "
                    "last iterate", report)
        report = self._report(False, outer_limit, newton, t0, changes,
                              "max_iterations reached")
        raise ProcessError(
            f"Panagiotopoulos process{self._where()}: no convergence after {outer_limit} "
            f"iterations (max_iterations); last change {changes[-1]:.3e}; u holds the last "
            "iterate", report)
