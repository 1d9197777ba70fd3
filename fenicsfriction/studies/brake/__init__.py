"""The simplified disc brake: two pads pressed on a rotating disc, its steady sliding and the
mode-coupling instability of its complex eigenvalues (brake squeal). dolfinx is loaded on first
use."""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "BrakeGeometry": "geometry", "BrakeMesh": "geometry", "BrakeModel": "model",
    "Solid": "model"}, ("geometry", "model"))

if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers
    from fenicsfriction.studies.brake import geometry, model
    from fenicsfriction.studies.brake.geometry import BrakeGeometry, BrakeMesh
    from fenicsfriction.studies.brake.model import BrakeModel, Solid
