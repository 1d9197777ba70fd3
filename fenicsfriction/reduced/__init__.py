"""Reduced models: scenes that need a few degrees of freedom and no mesh (no dolfinx).

The statistics of their runs (stick phases, limit cycles, summaries) are in
:mod:`fenicsfriction.statistics`.
"""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "BeltOscillator": "belt", "BeltResult": "belt", "BouncingMass": "dynamics",
    "ReducedDynamics": "dynamics", "rigid_block_observables": "dynamics",
    "HybridError": "events", "HybridResult": "events", "integrate_hybrid": "events",
    "RigidBlock": "rigid_block", "Contact": "slider", "Slider": "slider",
    "SliderMotion": "slider", "stability_map": "slider", "table2_slider": "slider"})

if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers
    from fenicsfriction.reduced.belt import BeltOscillator, BeltResult
    from fenicsfriction.reduced.dynamics import (
        BouncingMass,
        ReducedDynamics,
        rigid_block_observables,
    )
    from fenicsfriction.reduced.events import HybridError, HybridResult, integrate_hybrid
    from fenicsfriction.reduced.rigid_block import RigidBlock
    from fenicsfriction.reduced.slider import (
        Contact,
        Slider,
        SliderMotion,
        stability_map,
        table2_slider,
    )
