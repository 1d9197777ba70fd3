"""Scenes: geometry, tags and parameters of the papers' examples (data, not logic).

Importing this package does not import dolfinx; ``BlockModel`` loads it on first use.
"""

from __future__ import annotations

import typing

from fenicsfriction.scenes.block import BlockData, BlockOnBelt
from fenicsfriction.scenes.block_on_slab import BlockOnSlab

__all__ = ["SCENES", "BlockData", "BlockModel", "BlockOnBelt", "BlockOnSlab", "SlabModel"]

SCENES = {"block": BlockOnBelt, "block-on-slab": BlockOnSlab}


def __getattr__(name: str) -> typing.Any:
    if name == "BlockModel":
        from fenicsfriction.scenes.block.model import BlockModel
        return BlockModel
    if name == "SlabModel":
        from fenicsfriction.scenes.block_on_slab.model import SlabModel
        return SlabModel
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
