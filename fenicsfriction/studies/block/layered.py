"""A layered block on the belt: a bottom layer of other elastic constants under the block.

The dissimilar case of the Panagiotopoulos process (Kalker 1986, section 3): the normal and
tangential problems of an elastic body on a rigid foundation are coupled through the body's
second Dundurs constant, β = (1 - 2ν) / (2 (1 - ν)) against a rigid half-space, and through
how compliant the body is against the interface. A soft layer at the contact makes that
coupling strong while the stiff block above keeps the tipping limit of the rigid body.
"""

from __future__ import annotations

import dataclasses
import typing

import numpy as np
from dolfinx import fem

from fenicsfriction import _compat
from fenicsfriction.laws import check
from fenicsfriction.studies.block.data import BlockOnBelt
from fenicsfriction.studies.block.model import BlockModel

if typing.TYPE_CHECKING:
    from mpi4py import MPI

__all__ = ["LayeredBlockModel", "LayeredBlockOnBelt"]


@dataclasses.dataclass
class LayeredBlockOnBelt(BlockOnBelt):
    """:class:`~fenicsfriction.studies.block.BlockOnBelt` with a bottom layer.

    Args:
        layer_E: Young's modulus of the layer [10^3 kg cm^-1 s^-2].
        layer_nu: Poisson's ratio of the layer [-].
        layer_thickness: its thickness [cm], in (0, H); the cells whose centre lies below it
            are the layer's (choose a multiple of the cell height H / (3 refine)).
        Other parameters: see :class:`~fenicsfriction.studies.block.BlockOnBelt`.
    """

    layer_E: float = 1.4e3
    layer_nu: float = 0.0
    layer_thickness: float = 30.5 / 3

    def validate(self) -> None:
        super().validate()
        check("layer_E", self.layer_E, np.isfinite(self.layer_E) and self.layer_E > 0,
              "must be a finite number > 0")
        check("layer_nu", self.layer_nu, -1 < self.layer_nu < 0.5,
              "Poisson's ratio must lie in (-1, 0.5)")
        check("layer_thickness", self.layer_thickness, 0 < self.layer_thickness < self.H,
              f"must lie in (0, H) = (0, {self.H})")

    def build(self, comm: MPI.Comm | None = None,
              with_friction: bool | None = None) -> LayeredBlockModel:
        """The finite element model (see :meth:`BlockOnBelt.build`)."""
        from mpi4py import MPI
        return LayeredBlockModel(self, MPI.COMM_WORLD if comm is None else comm, with_friction)


class LayeredBlockModel(BlockModel):
    """The block model with cell-wise (DG0) E and ν: the layer's below ``layer_thickness``."""

    scene: LayeredBlockOnBelt

    def _moduli(self) -> tuple[typing.Any, typing.Any]:
        s = self.scene
        Q = _compat.scalar_function_space(self.msh, "DG", 0)
        fields = []
        for layer, block in ((s.layer_E, s.E), (s.layer_nu, s.nu)):
            f = fem.Function(Q)
            f.interpolate(lambda x, a=layer, b=block: np.where(x[1] < s.layer_thickness, a, b))
            fields.append(f)
        return fields[0], fields[1]
