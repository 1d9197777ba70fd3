"""Reduced models: scenes that need a few degrees of freedom and no mesh."""

from fenicsfriction.reduced.belt import BeltOscillator, belt_summary, limit_cycle
from fenicsfriction.reduced.dynamics import BouncingMass, ReducedDynamics, rigid_block_observables
from fenicsfriction.reduced.events import HybridError, HybridResult, integrate_hybrid
from fenicsfriction.reduced.rigid_block import RigidBlock
from fenicsfriction.reduced.slider import (
                                           Contact,
                                           Slider,
                                           SliderMotion,
                                           stability_map,
                                           table2_slider,
)

__all__ = ["BeltOscillator", "BouncingMass", "Contact", "HybridError", "HybridResult",
           "ReducedDynamics", "RigidBlock", "Slider", "SliderMotion", "belt_summary",
           "integrate_hybrid", "limit_cycle", "rigid_block_observables", "stability_map",
           "table2_slider"]
