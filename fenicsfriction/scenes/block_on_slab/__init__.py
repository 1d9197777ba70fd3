"""The block of Martins & Oden (1986) on an elastic slab (a deformable belt), in two-body
node-to-segment contact (Pop): its data (dolfinx-free) and the finite element model,
which loads dolfinx on first use."""

from __future__ import annotations

import importlib
import typing

from fenicsfriction.scenes.block_on_slab.data import BlockOnSlab

__all__ = ["BlockOnSlab", "SlabModel"]


def __getattr__(name: str) -> typing.Any:
    if name == "SlabModel":
        return importlib.import_module("fenicsfriction.scenes.block_on_slab.model").SlabModel
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
