"""Scenes: geometry, tags and parameters of the papers' examples (data, not logic)."""

from fenicsfriction.scenes.block import BlockData, BlockModel, BlockOnBelt

__all__ = ["SCENES", "BlockData", "BlockModel", "BlockOnBelt"]

SCENES = {"block": BlockOnBelt}
