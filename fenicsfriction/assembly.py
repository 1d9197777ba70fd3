"""Assembly of a :class:`~fenicsfriction.forms.Residual` into PETSc objects.

The SNES, TS and PEP drivers all go through these functions, so UFL integrals and nodal
springs are always assembled together and Dirichlet rows are treated one way
(dolfinx 0.5 pattern of ``python/test/unit/nls/test_newton.py``).

Every scene's body is linear: the integrals of a Jacobian that the state does not enter (the
elastic stiffness, the mass) are the same at every iteration. :func:`split_constant` tells them
apart from the others, and :class:`BulkWatcher` assembles them again only when one of their
inputs (a constant such as the density, a field other than the state) has changed; the
steady, dynamic and stability solvers all split and watch through these two.
"""

from __future__ import annotations

import typing

from petsc4py import PETSc

import dolfinx.fem.petsc
import numpy as np
import ufl
from dolfinx import fem

from fenicsfriction import _compat
from fenicsfriction.coupling import CouplingOperator

__all__ = ["BulkWatcher", "CoupledMatrix", "assemble_into", "assemble_jacobian",
           "assemble_owned", "assemble_residual", "split_constant"]


def assemble_into(vector: PETSc.Vec, form: typing.Any) -> PETSc.Vec:
    """``vector`` = the linear form assembled anew (zeroed first), the ghosts' contributions
    added to their owners; returned for chaining."""
    with vector.localForm() as local:
        local.set(0.0)
    dolfinx.fem.petsc.assemble_vector(vector, form)
    vector.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    return vector


def assemble_owned(form: typing.Any) -> np.ndarray:
    """A linear form's assembled vector: its owned entries, the ghosts' contributions added
    (a copy; e.g. nodal forces or the tributary areas of the nodes)."""
    vector = assemble_into(dolfinx.fem.petsc.create_vector(form), form)
    values = vector.array_r.copy()
    vector.destroy()
    return values


def assemble_residual(b: PETSc.Vec, L: fem.FormMetaClass, a: fem.FormMetaClass, bcs: list,
                      x: PETSc.Vec, springs: typing.Sequence = (),
                      couplings: typing.Sequence[CouplingOperator] = ()) -> None:
    """b = R(x) with Dirichlet rows set to (x - g) scaled by -1, springs included.

    ``x`` must already hold the state the coefficients of ``L`` see (ghosts updated).
    ``couplings`` are compiled terms that are not integrals of ``L`` (two-body contact,
    :class:`~fenicsfriction.coupling.CouplingOperator`): each adds its part with
    ``add_to_residual(b)``.
    """
    with b.localForm() as b_local:
        b_local.set(0.0)
    dolfinx.fem.petsc.assemble_vector(b, L)
    if bcs:
        dolfinx.fem.petsc.apply_lifting(b, [a], [bcs], [x], -1.0)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    if springs:
        b_array, x_array = b.getArray(), x.getArray(readonly=True)
        for spring in springs:
            spring.add_to_residual(b_array, x_array)
    for coupling in couplings:
        coupling.add_to_residual(b)
    if bcs:
        dolfinx.fem.petsc.set_bc(b, bcs, x, -1.0)


def assemble_jacobian(A: PETSc.Mat, a: fem.FormMetaClass, bcs: list,
                      springs: typing.Sequence = (), diagonal: float = 1.0,
                      base: PETSc.Mat | None = None) -> None:
    """A = dR/du (bilinear form ``a``) plus nodal spring stiffnesses.

    Dirichlet rows and columns are zeroed with ``diagonal`` on the diagonal (1 for a
    stiffness, 0 for damping and mass so that constrained dofs give infinite eigenvalues).

    With ``base`` (a matrix of A's sparsity, e.g. the constant bulk part of the Jacobian with
    its springs and Dirichlet rows, assembled once), A = base + the integrals of ``a``: only the
    changing part is assembled, and ``springs`` are already in ``base``.
    """
    if base is not None:
        base.copy(A, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        _compat.assemble_matrix_into(A, a, bcs, diagonal, zero=False)
        A.assemble()
        return
    _compat.assemble_matrix_into(A, a, bcs, diagonal)
    if springs:  # the Dirichlet diagonal was INSERTed; PETSc needs a flush before ADD
        A.assemblyBegin(PETSc.Mat.AssemblyType.FLUSH)
        A.assemblyEnd(PETSc.Mat.AssemblyType.FLUSH)
    for spring in springs:
        spring.add_to_matrix(A)
    A.assemble()


class CoupledMatrix:
    """A = base + each coupling's Jacobian (``add_to_matrix``, Dirichlet rows and columns
    zeroed), for terms that couple distant dofs (two-body contact).

    ``base`` is the matrix dolfinx assembles the integrals (and springs) into; A is a matrix of
    its own because the couplings' nonzero pattern follows the contact pairing and dolfinx
    assembles only into the pattern it created. While the couplings' pattern holds, the sums go
    into A's existing pattern; when it changed, A's pattern is rebuilt (PETSc replaces its
    storage) and the caller must reset the preconditioner that factorised A: PETSc 3.22 does
    not see the new pattern by itself and would reuse the old symbolic factorisation.

    Attributes:
        base: the matrix of the integrals.
        A: the coupled matrix (the same object for the solver's whole life).
    """

    def __init__(self, base: PETSc.Mat):
        self.base = base
        self.A = base.duplicate()
        self.A.assemble()
        self._pattern: tuple | None = None  # the couplings' pattern A was last built for

    def assemble(self, couplings: typing.Sequence[CouplingOperator], bcs: list) -> bool:
        """A = base + the couplings' Jacobians; True when A's pattern was rebuilt."""
        pattern = tuple(coupling.pattern for coupling in couplings)
        structure = PETSc.Mat.Structure
        if pattern == self._pattern:
            self.A.zeroEntries()
            self.A.axpy(1.0, self.base, structure=structure.SUBSET_NONZERO_PATTERN)
            for coupling in couplings:
                coupling.add_to_matrix(self.A, bcs, structure.SUBSET_NONZERO_PATTERN)
            return False
        self.base.copy(self.A, structure=structure.DIFFERENT_NONZERO_PATTERN)
        for coupling in couplings:
            coupling.add_to_matrix(self.A, bcs, structure.DIFFERENT_NONZERO_PATTERN)
        self._pattern = pattern
        return True


def split_constant(jacobian: ufl.Form, fields: typing.Iterable[fem.Function]
                   ) -> tuple[ufl.Form | None, list[ufl.classes.Integral]]:
    """``(K0, the other integrals)`` of a Jacobian, derivatives expanded: K0 (``None`` if
    empty) holds the integrals whose derivative with respect to each of ``fields`` vanishes
    identically (the elastic stiffness, the mass).

    What else enters K0 is watched by :class:`BulkWatcher`: its constants, the fields not in
    ``fields``, and a field of ``fields`` that appears where its derivative vanishes (a
    Heaviside factor of the gap under linear compliance, constant only piecewise), so K0 is
    assembled again whenever one of them moves. The steady solver passes ``u`` (a bulk
    parameter field is watched), the time stepper every field of the Jacobian (only
    constants are watched: the fields a scene changes between steps, e.g. which contacts
    hold, go with the integrals assembled at each iteration).
    """
    if jacobian.empty():
        return None, []
    fields = list(fields)
    constant: list = []
    varying: list = []
    for integral in ufl.algorithms.expand_derivatives(jacobian).integrals():
        form = ufl.Form([integral])
        fixed = all(ufl.algorithms.expand_derivatives(ufl.derivative(form, field)).empty()
                    for field in fields)
        (constant if fixed else varying).append(integral)
    return (ufl.Form(constant) if constant else None), varying


class BulkWatcher:
    """Assembles the constant part of an operator (K0 of :func:`split_constant`) again only
    when one of its inputs has changed since the last assembly.

    The inputs are the forms' constants (``fem.Constant``: E, ρ, a continued bulk parameter)
    and fields (``fem.Function``), compared by value.

    Args:
        forms: the UFL forms of the constant part.
        assemble: assembles it (the caller's matrices, springs and Dirichlet rows).

    Attributes:
        inputs: the constants and fields the forms depend on.
        assemblies: how many times ``assemble`` was called.
    """

    def __init__(self, forms: typing.Iterable[ufl.Form], assemble: typing.Callable[[], None]):
        self.inputs: list = []
        for form in forms:
            for item in (*ufl.algorithms.analysis.extract_constants(form),
                         *ufl.algorithms.analysis.extract_coefficients(form)):
                if item not in self.inputs:
                    self.inputs.append(item)
        self._assemble = assemble
        self._values: list[np.ndarray] | None = None
        self.assemblies = 0

    def _current(self) -> list[np.ndarray]:
        return [np.array(c.value if hasattr(c, "value") else c.x.array) for c in self.inputs]

    def refresh(self) -> bool:
        """Assemble if never assembled or an input changed; True when it assembled."""
        values = self._current()
        if self._values is not None and all(
                np.array_equal(now, then) for now, then in zip(values, self._values, strict=True)):
            return False
        self._assemble()
        self._values = values
        self.assemblies += 1
        return True
