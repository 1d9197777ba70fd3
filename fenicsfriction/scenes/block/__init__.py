"""The block on a moving belt (Martins & Oden 1986): its data (dolfinx-free), the finite element
model and what is read off it. ``BlockModel`` and the observables load dolfinx on first use."""

from __future__ import annotations

import importlib
import typing

from fenicsfriction.scenes.block.data import BlockData, BlockOnBelt

__all__ = ["BlockData", "BlockModel", "BlockOnBelt", "BlockQuantities", "CentreOfMass",
           "ContactStates", "Energies", "LayeredBlockModel", "LayeredBlockOnBelt", "Powers",
           "ProbeValues"]

_LAZY = {"BlockModel": "model", "BlockQuantities": "observables", "CentreOfMass": "observables",
         "ContactStates": "observables", "Energies": "observables",
         "LayeredBlockModel": "layered", "LayeredBlockOnBelt": "layered", "Powers": "observables",
         "ProbeValues": "observables"}


def __getattr__(name: str) -> typing.Any:
    if name in _LAZY:
        module = importlib.import_module(f"fenicsfriction.scenes.block.{_LAZY[name]}")
        return getattr(module, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
