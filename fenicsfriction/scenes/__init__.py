"""Scenes: geometry, tags and parameters of the papers' examples (data, not logic)."""

from fenicsfriction.scenes.block import BlockModel, BlockOnBelt

__all__ = ["BlockModel", "BlockOnBelt", "SCENES"]

SCENES = {"block": BlockOnBelt}
