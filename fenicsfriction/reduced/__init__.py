"""Reduced models: scenes that need a few degrees of freedom and no mesh."""

from fenicsfriction.reduced.dynamics import BouncingMass, ReducedDynamics, rigid_block_observables
from fenicsfriction.reduced.rigid_block import RigidBlock

__all__ = ["BouncingMass", "ReducedDynamics", "RigidBlock", "rigid_block_observables"]
