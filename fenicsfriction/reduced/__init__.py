"""Reduced models: scenes that need a few degrees of freedom and no mesh."""

from fenicsfriction.reduced.rigid_block import RigidBlock

__all__ = ["RigidBlock"]
