"""An elastic slider on a base of breakable (earthquake-like) contacts, pushed at its trailing
edge: the onset of sliding as detachment fronts (Braun (slides), the self-consistent problem;
Braun, Barel & Urbakh 2009; Rubinstein, Cohen & Fineberg 2004). See
:mod:`fenicsfriction.scenes.interface_slider.model`."""

from fenicsfriction.scenes.interface_slider.model import (
    BASE,
    LEFT,
    Break,
    Front,
    InterfaceSlider,
    InterfaceSliderModel,
    SliderHistory,
    fronts,
)

__all__ = ["BASE", "LEFT", "Break", "Front", "InterfaceSlider", "InterfaceSliderModel",
           "SliderHistory", "fronts"]
