"""Brake squeal: bodies pressed on a turning disc, the stability of their steady sliding.

``geometry`` holds the pin on the disc (:func:`~.geometry.pin_on_disc`; the disc is
:mod:`fenicsfriction.discs`, shared with the brake); ``model`` the pin-on-disc finite element model;
``study`` its stability study and the transient growth of its flutter mode; ``two_mode`` its
reduction to the two coupling modes. Loads dolfinx on first use."""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "Disc": "geometry", "Pin": "geometry", "PinOnDiscMesh": "geometry",
    "PinOnDisc": "model", "PinOnDiscModel": "model", "Steel": "model",
    "StabilityStudy": "study", "TransientGrowth": "study", "TwoModeModel": "two_mode"},
    ("geometry", "model", "study", "two_mode"))

if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers
    from fenicsfriction.studies.squeal import geometry, model, study, two_mode
    from fenicsfriction.studies.squeal.geometry import Disc, Pin, PinOnDiscMesh
    from fenicsfriction.studies.squeal.model import PinOnDisc, PinOnDiscModel, Steel
    from fenicsfriction.studies.squeal.study import StabilityStudy, TransientGrowth
    from fenicsfriction.studies.squeal.two_mode import TwoModeModel
