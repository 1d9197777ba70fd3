r"""The block of Martins & Oden (1986) on an elastic belt: its data.

The block, its interface law, its weight and its driver spring are those of
:class:`~fenicsfriction.studies.block.BlockOnBelt` (every field kept and validated alike); the
rigid belt is replaced by a deformable slab, a second body in the same mesh, and the contact
between them is two-body contact carrying the same law of Martins & Oden (1986): the block's
bottom is the slave surface, the slab's top the master. ``formulation`` chooses its
discretisation (:func:`fenicsfriction.contact.make_contact`): node-to-segment (Pop; the
default) or mortar (the law on mortar-weighted gaps, segment-to-segment integration).

Modelling choices, changeable through the fields where they are numbers:

* **The slab rides on a rigid carrier.** Its bottom is clamped to a carrier moving at the belt
  speed; the slab moves with it rigidly, its elastic deformation superposed. The contact's
  relative velocity is :math:`w = \dot u_s - (U_T + \sum_a N_a \dot u_a)`, :math:`U_T` the
  belt velocity (``transport``), so in steady sliding (:math:`\dot u = 0`) the friction sees
  :math:`-U_T` exactly as in the one-body scene.
* **No convective terms.** In the carrier's frame the slab's material flows through the
  contact zone at the belt speed V, which adds :math:`\rho V \partial\dot u/\partial x` and
  :math:`\rho V^2 \partial^2 u/\partial x^2` terms to its equations; they are dropped, as
  V / c ≈ 0.287 / 2·10^5 ≈ 10^-6 for the slab's wave speeds c.
* **No slab weight.** The carrier carries it; in linear elasticity it only adds a static field
  that does not change the contact.
* **Defaults.** ``slab_E`` = E and ``slab_nu`` = ν (a belt of the block's material, where the
  belt's compliance matters most); ``slab_E`` = 1e3 E is the stiff limit, in which the scene
  reproduces the one-body block on a rigid belt (tested). ``slab_thickness`` = 10 cm (about
  H/3), ``slab_length`` = 3 L centred under the block (a slab edge one block length away from
  each block corner), ``slab_density`` = the block's (M / (L H B0)).
* **Degree and contact rule.** Node-to-segment contact needs degree-1 Lagrange elements
  (``degree`` = 1, the default); mortar contact takes degree 1 or 2 (nine-node Q2). Either
  applies the law at the slave nodes, each carrying its tributary length (the contact's
  nodal measure), so ``contact_quadrature`` is ``"nodal"`` whatever the degree. With
  node-to-segment the one-body reference is ``BlockOnBelt(degree=1,
  contact_quadrature="nodal")`` (not ``"gll"``, which FFCx evaluates with five points per
  facet on Q1); ``docs/block-on-slab.md`` compares mortar with the one-body Q2 block.
* **Mesh.** Both bodies are quadrilaterals of one mesh, disjoint (the block's bottom and the
  slab's top both at y = 0, with their own nodes). Under the block the slab's columns have the
  block's width L / (4 r); beyond it ``ceil(overhang / (2 h))`` columns of about twice that;
  ``max(1, round(t / h))`` rows through the thickness t (h = L / (4 r)).
"""

from __future__ import annotations

import dataclasses
import typing

import numpy as np

from fenicsfriction.laws import check
from fenicsfriction.studies.block.data import BlockOnBelt

if typing.TYPE_CHECKING:
    from mpi4py import MPI

    from fenicsfriction.studies.block.slab_model import SlabModel

#: the block-slab contact's discretisations (those of
#: :data:`fenicsfriction.contact.FORMULATIONS`, which needs dolfinx to import)
FORMULATIONS = ("node-to-segment", "mortar")

__all__ = ["BLOCK", "FORMULATIONS", "SCENES", "SLAB", "SLAB_BOTTOM", "SLAB_SIDES", "SLAB_TOP",
           "BlockOnSlab"]

#: cell tags of the two bodies
BLOCK, SLAB = 1, 2
#: facet tags of the slab (the block's are those of the one-body scene: CONTACT is the slave)
SLAB_TOP, SLAB_BOTTOM, SLAB_SIDES = 5, 6, 7


@dataclasses.dataclass
class BlockOnSlab(BlockOnBelt):
    """The block-on-slab scene: :class:`BlockOnBelt` on an elastic slab.

    Args:
        slab_E: the slab's Young's modulus [10^3 kg cm^-1 s^-2] (None: E).
        slab_nu: the slab's Poisson's ratio [-] (None: nu).
        slab_thickness: the slab's thickness t [cm].
        slab_length: the slab's length [cm], > L, centred under the block (None: 3 L).
        slab_density: the slab's mass density [10^3 kg cm^-3] (None: the block's).
        formulation: the block-slab contact's discretisation, ``"node-to-segment"`` or
            ``"mortar"``.
        Other parameters: see :class:`BlockOnBelt`; ``degree`` 1 (or 2 with mortar),
        ``dim`` 2.
    """

    degree: int = 1
    contact_quadrature: str = "nodal"
    formulation: str = "node-to-segment"
    slab_E: float = None  # type: ignore[assignment]  # None: set by __post_init__
    slab_nu: float = None  # type: ignore[assignment]
    slab_thickness: float = 10.0
    slab_length: float = None  # type: ignore[assignment]
    slab_density: float = None  # type: ignore[assignment]

    def __post_init__(self):
        if self.slab_E is None:
            self.slab_E = self.E
        if self.slab_nu is None:
            self.slab_nu = self.nu
        if self.slab_length is None:
            self.slab_length = 3 * self.L
        if self.slab_density is None:
            self.slab_density = self.mass / (self.L * self.H * self.B0)
        super().__post_init__()

    def validate(self) -> None:
        super().validate()
        check("formulation", self.formulation, self.formulation in FORMULATIONS,
              f"one of {', '.join(FORMULATIONS)}")
        check("degree", self.degree, self.degree in (1, 2) and (
            self.degree == 1 or self.formulation == "mortar"),
              "must be 1, or 2 with the mortar formulation (node-to-segment contact needs "
              "degree-1 elements)")
        check("dim", self.dim, self.dim == 2, "must be 2 (the slab scene is plane strain)")
        for name in ("slab_E", "slab_thickness", "slab_density"):
            value = getattr(self, name)
            check(name, value, bool(np.isfinite(value)) and value > 0,
                  "must be a finite number > 0")
        check("slab_nu", self.slab_nu, -1 < self.slab_nu < 0.5,
              "Poisson's ratio must lie in (-1, 0.5)")
        check("slab_length", self.slab_length,
              bool(np.isfinite(self.slab_length)) and self.slab_length > self.L,
              f"must be a finite number > L = {self.L}")

    def check_contact_rule(self) -> None:
        check("contact_quadrature", self.contact_quadrature,
              self.contact_quadrature == "nodal",
              "must be nodal: the two-body contact integrates the slave surface so")

    @property
    def discrete_tipping_limit(self) -> float:
        """μ at which the resultant reaches the block's corner node: L / (2 h_s), the nodal
        rule holding the corners."""
        return self.tipping_limit

    def build(self, comm: MPI.Comm | None = None,
              with_friction: bool | None = None) -> SlabModel:
        """Mesh both bodies, pair their surfaces and assemble the residual.

        Args:
            comm: communicator the mesh is distributed over (default ``MPI.COMM_WORLD``).
            with_friction: include the friction term (default: μ > 0 or a velocity law).

        Returns:
            The built :class:`~fenicsfriction.studies.block.slab_model.SlabModel`.
        """
        from mpi4py import MPI

        from fenicsfriction.studies.block.slab_model import SlabModel
        return SlabModel(self, MPI.COMM_WORLD if comm is None else comm, with_friction)


SCENES = {"block": BlockOnBelt, "block-on-slab": BlockOnSlab}
"""The block scenes by the name the command line gives them."""
