r"""Mode contributions: which modes of each body, alone, make up a complex mode of the system.

Brake-squeal engineers explain an unstable mode of the assembled brake by the modes of its
parts: "pad mode 3 and disc mode 5 couple". Each body :math:`b` on its own — its stiffness
(elasticity, supports, springs) without the contact or interface stiffness, its mass — has
real **free-interface modes** :math:`K_b \phi_{b,j} = \omega_{b,j}^2 M_b \phi_{b,j}`,
normalised :math:`\Phi_b^T M_b \Phi_b = I` (:class:`~fenicsfriction.cea.projection.ModalBasis`
on the body's rows and columns, taken with PETSc's ``createSubMatrix``). A complex mode
:math:`w` of the coupled system restricted to the body, :math:`w_b`, has the modal
participations :math:`q_{b,j} = \phi_{b,j}^T M_b w_b`, and its **contribution** is

.. math:: c_{b,j} = \frac{|q_{b,j}|^2}{w^H M w}.

With every mode of every body the contributions sum to 1: :math:`\sum_j |q_{b,j}|^2 =
w_b^H M_b w_b` (the modes are complete and M-orthonormal), and the bodies' masses are the
blocks of M. A truncated basis leaves the remainder ``unexplained``: the part of the complex
mode's kinetic norm outside the modes computed. (The contributions are the squared modal
coordinates of the mode in the bodies' modal bases, the decomposition of component mode
synthesis; compare the "modal participation" of commercial CEA codes.)

The body's stiffness is the residual's :math:`\bar K` with the interface left out: the
couplings (node-to-segment contact between bodies) are never in it, and the integrals over the
facet tags given as ``interface`` (a contact integral against a rigid foundation, e.g. the
block on its belt) are removed from the form before it is compiled. What remains is assembled
at the current state with the nodal springs and the Dirichlet rows, whose dofs are left out of
the bodies. A body without enough supports (the block held only by its driver spring) keeps its
rigid-body modes, at zero frequency, as free-interface modes: they take part in the coupled
modes like any other (the shift-and-invert target is negative, so K_b - σ M_b stays regular).
Modes that share one frequency (the rigid ones) are an arbitrary basis of their eigenspace:
only the sum of their contributions means something.
"""

from __future__ import annotations

import dataclasses
import math
import typing

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem.petsc
import numpy as np
import ufl

from fenicsfriction import _compat
from fenicsfriction.assembly import assemble_jacobian
from fenicsfriction.cea.projection import ModalBasis
from fenicsfriction.forms import Residual
from fenicsfriction.laws import check
from fenicsfriction.results import Record
from fenicsfriction.stability import Mode

if typing.TYPE_CHECKING:
    from dolfinx import fem

__all__ = ["BodyModes", "Contribution", "FreeInterfaceModes", "ModeContributions", "body_dofs",
           "plot_contributions", "without_interface"]

#: contributions below this share are summed into ``others`` instead of listed
MIN_SHARE = 0.01


def body_dofs(V: fem.FunctionSpace, cells: np.ndarray, bcs: typing.Sequence = ()) -> PETSc.IS:
    """The global indices of the dofs of ``V`` on ``cells`` that this rank owns, the Dirichlet
    dofs of ``bcs`` left out (the layout of the PETSc matrices assembled on ``V``).

    Args:
        V: the (vector) function space.
        cells: this rank's local indices of the body's cells (ghosts may be included).
        bcs: Dirichlet conditions whose dofs do not belong to the body's modes.
    """
    bs, index_map = V.dofmap.index_map_bs, V.dofmap.index_map
    nodes = _compat.cell_dofs(V, np.asarray(cells, dtype=np.int32))
    dofs = (nodes[:, None] * bs + np.arange(bs)).ravel()
    dofs = dofs[dofs < index_map.size_local * bs]
    for bc in bcs:
        constrained = bc.dof_indices()[0]
        dofs = np.setdiff1d(dofs, constrained)
    dofs = np.unique(dofs)
    start = index_map.local_range[0] * bs
    return PETSc.IS().createGeneral((start + dofs).astype(PETSc.IntType), comm=V.mesh.comm)


def without_interface(form: ufl.Form, interface: typing.Iterable[int]) -> ufl.Form:
    """``form`` less its exterior-facet integrals over the facet tags ``interface``."""
    tags = set(interface)
    kept = [integral for integral in form.integrals()
            if not (integral.integral_type() == "exterior_facet"
                    and integral.subdomain_id() in tags)]
    return ufl.Form(kept)


@dataclasses.dataclass
class BodyModes:
    """One body's free-interface modes.

    Attributes:
        name: the body's name ("block", "pad", ...).
        dofs: its dofs (:func:`body_dofs`), the rows of ``mass`` and of ``basis.phi``.
        mass: its mass matrix M_b.
        basis: its M_b-orthonormal real modes (``omega2``, ``phi``, ``frequencies``).
    """

    name: str
    dofs: PETSc.IS
    mass: PETSc.Mat
    basis: ModalBasis

    def label(self, index: int) -> str:
        """``"block mode 3 (f = 880.1 Hz)"`` for the mode of index 2 (numbered from 1)."""
        return f"{self.name} mode {index + 1} (f = {self.basis.frequencies[index]:.4g} Hz)"


@dataclasses.dataclass
class Contribution(Record):
    """One body mode's share of a complex mode.

    Attributes:
        body: the body's name.
        mode: the body mode's number, from 1 by increasing frequency.
        frequency: its frequency [Hz].
        share: :math:`|q|^2 / w^H M w`.
    """

    body: str
    mode: int
    frequency: float
    share: float


@dataclasses.dataclass
class ModeContributions(Record):
    """The body modes making up one complex mode of the coupled system.

    Attributes:
        mode: the complex mode's ``ident`` (-1 when not tracked).
        value: its eigenvalue λ [1/s].
        frequency: Im λ / 2π [Hz].
        contributions: the body modes' shares >= ``min_share``, largest first.
        others: the sum of the shares below it.
        unexplained: 1 - the sum of all shares: the part outside the bodies' computed modes.
        bodies: each body's share of the kinetic norm, :math:`w_b^H M_b w_b / w^H M w`.
    """

    mode: int
    value: complex
    frequency: float
    contributions: list[Contribution]
    others: float
    unexplained: float
    bodies: dict[str, float]

    def table(self) -> str:
        """One line: ``"λ = ... (f = ... Hz): block mode 2 (f = ... Hz) 0.46, ..."``."""
        parts = [f"{c.body} mode {c.mode} (f = {c.frequency:.4g} Hz): {c.share:.2f}"
                 for c in self.contributions]
        return (f"λ = {self.value.real:.4g}{self.value.imag:+.4g}i (f = {self.frequency:.4g} Hz)"
                f": {', '.join(parts)}; others {self.others:.2f}, "
                f"unexplained {self.unexplained:.2f}")


class FreeInterfaceModes:
    """The free-interface modes of the bodies of a residual's model, and each complex mode's
    contributions from them (see the module docstring).

    Args:
        residual: the residual (its ``u`` at the state the stiffness is taken at; bodies are
            linear in this package, so any state gives the same K_b).
        bodies: each body's name and its cells (this rank's local cell indices).
        interface: facet tags whose integrals are the interface, left out of K_b.
        modes: how many modes of each body (the lowest); None: all of them (small bodies).
        max_frequency: or every mode of each body below this frequency [Hz] (``modes`` is
            then the first request; CEA practice keeps the body modes up to 1.5-2 times the
            band's top).
        prefix: PETSc options prefix; body ``b``'s EPS has ``prefix + b + "_"``.
        options: EPS options over :data:`fenicsfriction.cea.projection.DEFAULT_OPTIONS`.

    Attributes:
        bodies: the :class:`BodyModes`, in the order given.
        K, M: the assembled stiffness without the interface and the mass (whole space).
    """

    def __init__(self, residual: Residual, bodies: dict[str, np.ndarray],
                 interface: typing.Iterable[int] = (), modes: int | None = 20,
                 max_frequency: float | None = None, prefix: str = "cea_fim_",
                 options: dict | None = None):
        check("bodies", list(bodies), len(bodies) > 0, "give at least one body")
        self.comm: MPI.Comm = residual.V.mesh.comm
        M_form, _, K_form = residual.linearisation()
        K_form = without_interface(K_form, interface)
        self.K = self._assemble(K_form, residual, stiffness=True)
        self.M = self._assemble(M_form, residual, stiffness=False)
        self.bodies: list[BodyModes] = []
        for name, cells in bodies.items():
            dofs = body_dofs(residual.V, cells, residual.bcs)
            K_b = self.K.createSubMatrix(dofs, dofs)
            M_b = self.M.createSubMatrix(dofs, dofs)
            n = dofs.getSize()
            check("bodies", name, n > 0, "a body with free dofs")
            # a negative target below every mode: K_b - σ M_b is regular with rigid modes
            shift = -1e-6 * K_b.norm(PETSc.NormType.INFINITY) / M_b.norm(PETSc.NormType.INFINITY)
            basis = ModalBasis(K_b, M_b, modes=n if modes is None else min(modes, n),
                               max_frequency=max_frequency, shift=shift,
                               prefix=f"{prefix}{name}_", options=options)
            K_b.destroy()
            self.bodies.append(BodyModes(name=name, dofs=dofs, mass=M_b, basis=basis))

    @staticmethod
    def _assemble(form: ufl.Form, residual: Residual, stiffness: bool) -> PETSc.Mat:
        compiled = _compat.form(form)
        A = dolfinx.fem.petsc.create_matrix(compiled)
        assemble_jacobian(A, compiled, residual.bcs, residual.springs if stiffness else (),
                          1.0 if stiffness else 0.0)
        return A

    def contributions(self, mode: Mode, min_share: float = MIN_SHARE) -> ModeContributions:
        """The body modes' shares of the complex ``mode`` (its ``vector``: this rank's owned
        entries, the layout of ``K``)."""
        w = [self.M.createVecRight() for _ in range(2)]
        w[0].setArray(mode.vector.real)
        w[1].setArray(mode.vector.imag)
        mw = self.M.createVecLeft()
        total = 0.0
        for part in w:
            self.M.mult(part, mw)
            total += part.dot(mw)
        shares, kinetic = [], {}
        for body in self.bodies:
            q = np.zeros(body.basis.size, dtype=complex)
            norm = 0.0
            for part, unit in zip(w, (1.0, 1j), strict=True):
                sub = part.getSubVector(body.dofs)
                m_sub = body.mass.createVecLeft()
                body.mass.mult(sub, m_sub)
                norm += sub.dot(m_sub)
                q += unit * (body.basis.phi.T @ m_sub.getArray())
                part.restoreSubVector(body.dofs, sub)
                m_sub.destroy()
            q = self.comm.allreduce(q)
            kinetic[body.name] = norm / total
            shares += [Contribution(body=body.name, mode=j + 1,
                                    frequency=float(body.basis.frequencies[j]),
                                    share=float(abs(q[j]) ** 2 / total))
                       for j in range(body.basis.size)]
        for vec in (*w, mw):
            vec.destroy()
        shares.sort(key=lambda c: -c.share)
        listed = [c for c in shares if c.share >= min_share]
        explained = sum(c.share for c in shares)
        return ModeContributions(
            mode=mode.ident, value=mode.value, frequency=mode.value.imag / (2 * math.pi),
            contributions=listed, others=explained - sum(c.share for c in listed),
            unexplained=1.0 - explained, bodies=kinetic)


def plot_contributions(records: typing.Sequence[ModeContributions], path: typing.Any,
                       comm: MPI.Comm = MPI.COMM_WORLD) -> None:
    """Stacked bars: one per complex mode, one segment per listed body mode (labelled when
    it is large enough to read), then ``others`` and ``unexplained`` in grey (rank 0 draws)."""
    if comm.rank != 0:
        return
    from fenicsfriction.plotting import saved_figure
    with saved_figure(path, figsize=(7.0, 0.6 + 0.55 * max(len(records), 1))) as axes:
        ax = axes[0]
        colours: dict[tuple[str, int], str] = {}
        cycle = [f"C{i}" for i in range(10)]
        for row, record in enumerate(records):
            left = 0.0
            for c in record.contributions:
                key = (c.body, c.mode)
                colour = colours.setdefault(key, cycle[len(colours) % len(cycle)])
                ax.barh(row, c.share, left=left, color=colour, edgecolor="white")
                if c.share > 0.08:
                    ax.text(left + c.share / 2, row, f"{c.body} {c.mode}", ha="center",
                            va="center", fontsize=7, color="white")
                left += c.share
            for value, shade in ((record.others, "0.6"), (max(record.unexplained, 0.0), "0.85")):
                ax.barh(row, value, left=left, color=shade, edgecolor="white")
                left += value
        ax.set_yticks(range(len(records)))
        ax.set_yticklabels([f"{r.frequency:.4g} Hz, Re λ = {r.value.real:.3g}" for r in records],
                           fontsize=8)
        ax.set_xlim(0.0, 1.0)
        ax.set_xlabel("share of the kinetic norm (grey: other body modes, unexplained)")
        ax.invert_yaxis()
