"""What the solvers ask of a term that no integral holds: a coupling between distant points of
the mesh (two-body contact, :class:`fenicsfriction.contact.NodeToSegment`).

A :class:`~fenicsfriction.forms.Residual` lists its couplings in ``couplings``. Each solver
compiles every coupling once, for the derivatives it needs (:meth:`Coupling.operator`), and
adds the compiled operators' residual and Jacobian to those of the integrals
(:func:`fenicsfriction.assembly.assemble_residual`,
:class:`fenicsfriction.assembly.CoupledMatrix`). Both interfaces are structural: a new
coupling needs only these members, no base class. A coupling with friction may also offer
:class:`FrictionBoundCoupling`, through which the Panagiotopoulos process
(:mod:`fenicsfriction.panagiotopoulos`) fixes its friction bound.
"""

from __future__ import annotations

import typing

if typing.TYPE_CHECKING:
    from petsc4py import PETSc

    from dolfinx import fem

__all__ = ["Coupling", "CouplingOperator", "FrictionBoundCoupling"]


@typing.runtime_checkable
class CouplingOperator(typing.Protocol):
    """A coupling compiled for one solver's derivatives (:meth:`Coupling.operator`)."""

    @property
    def contact(self) -> Coupling:
        """The coupling compiled: the solvers set its ``search_pending`` at the start of each
        Newton solve or time step (and, in explicit dynamics, before each residual)."""

    @property
    def pattern(self) -> typing.Hashable:
        """Identifies the nonzero pattern of the Jacobian (a contact's changes with the
        pairing only): read before each Jacobian assembly; while it is unchanged the
        Jacobian is added into the matrix's existing pattern, else the matrix is rebuilt and
        the factorisation set up anew."""

    def add_to_residual(self, b: PETSc.Vec) -> None:
        """Add the coupling's residual at the current state to ``b`` (called at every residual
        evaluation, the integrals already in ``b`` and the ghosts reduced, before the
        Dirichlet rows are set). A search due (``search_pending``) is done here first."""

    def add_to_matrix(self, A: PETSc.Mat, bcs: typing.Sequence[fem.DirichletBC] = (),
                      structure: typing.Any = None) -> None:
        """Add the Jacobian (the derivatives the operator was compiled for) to ``A``, the rows
        and columns of ``bcs`` zeroed (called at every Jacobian assembly, after the residual at
        the same state). ``structure`` is ``SUBSET_NONZERO_PATTERN`` while :attr:`pattern` is
        the one ``A`` was built for, else ``DIFFERENT_NONZERO_PATTERN``."""


@typing.runtime_checkable
class Coupling(typing.Protocol):
    """A term of the residual between distant points of the mesh, as the solvers use it.

    Attributes:
        search_pending: set by the solvers when the coupling should look again for which points
            it joins (a contact's pairing) at its next residual: at the start of each Newton
            solve (:class:`~fenicsfriction.steady.SteadySolver`) and each time step
            (:class:`~fenicsfriction.dynamics.DynamicsSolver`,
            :class:`~fenicsfriction.dynamics.CentralDifference`).
        step_from: optional; a Function of ``u``'s space that
            :class:`~fenicsfriction.dynamics.DynamicsSolver` with ``energy_consistent`` sets to
            u_n before each step, the coupling's force then being that of the midpoint step
            from it (:class:`~fenicsfriction.contact.NodeToSegment`).
        m_n: the exponent of its normal compliance;
            :class:`~fenicsfriction.dynamics.CentralDifference` bounds the stable step of
            springs that close later (:meth:`frequency_bound`) only when it is 1.
    """

    search_pending: bool
    m_n: typing.Any

    def search(self) -> bool:
        """Look again, at the current state, for which points the coupling joins (a contact's
        pairing, a mortar contact's geometry); True if that changed.
        :meth:`~fenicsfriction.steady.SteadySolver.solve_searched` repeats its solve until a
        search at the converged state returns False."""

    def operator(self, derivatives: dict[fem.Function, typing.Any],
                 rest: typing.Sequence[fem.Function] = (),
                 jit_cache_dir: str | None = None) -> CouplingOperator:
        """Compile the residual and its Jacobian Σ weight · ∂R/∂field over ``derivatives``
        (``{u: 1}`` for a stiffness, ``{u: 1, u_dot: shift}`` for a time step's Jacobian), with
        the fields of ``rest`` set to zero (u̇ in steady sliding). Called once per solver, when
        it is built."""

    def frequency_bound(self, lumped_mass: PETSc.Vec) -> float:
        """An upper bound of the coupling's contribution to ω² on the lumped mass, whatever
        the state (:class:`~fenicsfriction.dynamics.CentralDifference`, when it is built, for
        springs that close after the initial state)."""


@typing.runtime_checkable
class FrictionBoundCoupling(Coupling, typing.Protocol):
    """A coupling whose friction bound :math:`c_T d^{m_T}` a solver can replace: what the
    Panagiotopoulos process (:class:`fenicsfriction.panagiotopoulos.PanagiotopoulosSolver`)
    asks of ``Residual.couplings``.

    The process evaluates the bound at a frozen state by ``ufl.replace``-ing each Function of
    :attr:`configuration` in :meth:`friction_bound` by a copy of it taken after a solve, and
    solves the next time with the coupling :meth:`with_friction_bound` returns.
    :class:`~fenicsfriction.contact.NodeToSegment` is one; its ``friction_bound`` and
    ``with_friction_bound`` read and rebuild any coupling's forms ``F`` and ``G``.
    """

    @property
    def configuration(self) -> list[fem.Function]:
        """The Functions the coupling's geometry at its integration points is made of (the
        displacement and whatever the coupling derives from it and its pairing, e.g. the
        master's displacement and reference coordinates at the slave points). Copies of
        their values give the bound at the state of the copy, whatever the pairing later."""

    def friction_bound(self) -> typing.Any:
        """The friction bound of the coupling's law at its integration points (a UFL scalar,
        the expression labelled :data:`fenicsfriction.laws.FRICTION_BOUND` in its forms), or
        ``None`` if it has none."""

    def with_friction_bound(self, bound: typing.Any) -> FrictionBoundCoupling:
        """The same coupling with the UFL scalar ``bound`` in place of its friction bound,
        sharing this one's pairing (one search serves both)."""

    def search(self) -> bool:
        """Pair the surfaces at the current displacement; True if the pairing changed (the
        process goes on when a state it converged to no longer has the pairing it was
        solved with)."""
