"""The block on a moving belt (Martins & Oden 1986): its data (dolfinx-free), the finite element
model and what is read off it, the block on a layered belt and on an elastic slab (two-body
contact, Pop), and the rigid block beside them (no mesh). The finite element models load
dolfinx on first use."""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "BlockData": "data", "BlockOnBelt": "data", "SCENES": "slab",
    "BlockModel": "model",
    "BlockQuantities": "observables", "CentreOfMass": "observables",
    "ContactStates": "observables", "Energies": "observables", "Powers": "observables",
    "ProbeValues": "observables",
    "LayeredBlockModel": "layered", "LayeredBlockOnBelt": "layered",
    "BlockOnSlab": "slab", "SlabModel": "slab_model",
    "RigidBlock": "rigid", "RigidLoci": "rigid", "rigid_loci": "rigid",
    "rigid_block_observables": "rigid"})

if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers
    from fenicsfriction.studies.block.data import BlockData, BlockOnBelt
    from fenicsfriction.studies.block.layered import LayeredBlockModel, LayeredBlockOnBelt
    from fenicsfriction.studies.block.model import BlockModel
    from fenicsfriction.studies.block.observables import (
        BlockQuantities,
        CentreOfMass,
        ContactStates,
        Energies,
        Powers,
        ProbeValues,
    )
    from fenicsfriction.studies.block.rigid import (
        RigidBlock,
        RigidLoci,
        rigid_block_observables,
        rigid_loci,
    )
    from fenicsfriction.studies.block.slab import SCENES, BlockOnSlab
    from fenicsfriction.studies.block.slab_model import SlabModel
