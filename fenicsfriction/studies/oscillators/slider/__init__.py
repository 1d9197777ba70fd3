r"""The 2m+1 d.o.f. slider on a rough moving surface ("Friction-induced sliding instability in a
multi-degree-of-freedom system with oscillatory normal forces" (2003)).

One module per question:

* :mod:`~fenicsfriction.studies.oscillators.slider.model` — what is the slider? :class:`Contact`,
  :class:`Slider` (its matrices, natural frequencies, steady sliding, forced response),
  :class:`ScaledFriction`;
* :mod:`~fenicsfriction.studies.oscillators.slider.stability` — is steady sliding stable?
  First-order averaging (:meth:`Slider.averaged`) and Floquet multipliers (:meth:`Slider.floquet`),
  :func:`stability_map` over the forcing frequency, :func:`stroboscopic_growth` of a time
  response;
* :mod:`~fenicsfriction.studies.oscillators.slider.table2` — the paper's numerical example
  (:func:`table2_slider`, ``TABLE2_READINGS``, ``TABLE2_PAPER_BANDS``);
* :mod:`~fenicsfriction.studies.oscillators.slider.motion` — how does it move?
  :class:`SliderMotion`, the nonlinear equations with true stick (events) or a regularised law.
"""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "Contact": "model", "ScaledFriction": "model", "Slider": "model", "SliderMotion": "motion",
    "AveragedStability": "stability", "FloquetStability": "stability",
    "StabilityMap": "stability", "stability_map": "stability",
    "stroboscopic_growth": "stability", "TABLE2_PAPER_BANDS": "table2",
    "TABLE2_READINGS": "table2", "table2_slider": "table2"})

if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers
    from fenicsfriction.studies.oscillators.slider.model import Contact, ScaledFriction, Slider
    from fenicsfriction.studies.oscillators.slider.motion import SliderMotion
    from fenicsfriction.studies.oscillators.slider.stability import (
        AveragedStability,
        FloquetStability,
        StabilityMap,
        stability_map,
        stroboscopic_growth,
    )
    from fenicsfriction.studies.oscillators.slider.table2 import (
        TABLE2_PAPER_BANDS,
        TABLE2_READINGS,
        table2_slider,
    )
