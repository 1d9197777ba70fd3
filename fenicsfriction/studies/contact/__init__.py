"""Two elastic bodies in contact through node-to-segment elements (Pop): the validation scenes
(Hertz, the patch test, Cattaneo-Mindlin), a cylinder pressed and dragged, their finite element
model, their gmsh meshes and their closed forms. The closed forms need no mesh; the rest loads
dolfinx on first use."""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "Cattaneo": "validation", "Hertz": "validation", "Patch": "validation",
    "Material": "model", "SurfaceValues": "model", "TwoBodyModel": "model",
    "PressAndDrag": "impact", "TwoBodyMesh": "geometry"},
    ("closed_forms", "geometry", "impact", "model", "validation"))

if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers
    from fenicsfriction.studies.contact import closed_forms, geometry, impact, model, validation
    from fenicsfriction.studies.contact.geometry import TwoBodyMesh
    from fenicsfriction.studies.contact.impact import PressAndDrag
    from fenicsfriction.studies.contact.model import Material, SurfaceValues, TwoBodyModel
    from fenicsfriction.studies.contact.validation import Cattaneo, Hertz, Patch
