"""Reduced models: scenes that need a few degrees of freedom and no mesh (no dolfinx).

The statistics of their runs (stick phases, limit cycles, summaries) are in
:mod:`fenicsfriction.statistics`.
"""

from fenicsfriction.reduced.belt import BeltOscillator, BeltResult
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

__all__ = ["BeltOscillator", "BeltResult", "BouncingMass", "Contact", "HybridError",
           "HybridResult", "ReducedDynamics", "RigidBlock", "Slider", "SliderMotion",
           "integrate_hybrid", "rigid_block_observables", "stability_map", "table2_slider"]
