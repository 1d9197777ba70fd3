"""Oscillators without a mesh: the 2m+1 d.o.f. slider with oscillatory normal forces (2003),
the oscillator on a moving belt with true stick (events), and the bouncing mass on a compliant
foundation (the normal law's verification scene)."""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "BeltOscillator": "belt", "BeltResult": "belt", "BouncingMass": "bouncing_mass",
    "Contact": "slider", "Slider": "slider", "SliderMotion": "slider",
    "AveragedStability": "slider", "FloquetStability": "slider", "StabilityMap": "slider",
    "stability_map": "slider", "table2_slider": "slider"}, ("slider",))

if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers
    from fenicsfriction.studies.oscillators import slider
    from fenicsfriction.studies.oscillators.belt import BeltOscillator, BeltResult
    from fenicsfriction.studies.oscillators.bouncing_mass import BouncingMass
    from fenicsfriction.studies.oscillators.slider import (
        AveragedStability,
        Contact,
        FloquetStability,
        Slider,
        SliderMotion,
        StabilityMap,
        stability_map,
        table2_slider,
    )
