"""Scenes of the nonhomogeneous interface: contacts on an elastic substrate (Braun (slides))."""

from fenicsfriction.scenes.interface.substrate import ElasticSubstrate, SubstrateBlock

__all__ = ["ElasticSubstrate", "SubstrateBlock"]
