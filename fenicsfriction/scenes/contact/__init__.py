"""Two elastic bodies in contact: the validation scenes (Hertz, the patch test,
Cattaneo-Mindlin), their finite element model and their closed forms."""

from fenicsfriction.scenes.contact.closed_forms import (
    cattaneo_stick_half_width,
    cattaneo_traction,
    effective_modulus,
    fit_hertz_pressure,
    hertz_line_contact,
    hertz_point_contact,
    hertz_pressure,
)

__all__ = ["cattaneo_stick_half_width", "cattaneo_traction", "effective_modulus",
           "fit_hertz_pressure", "hertz_line_contact", "hertz_point_contact", "hertz_pressure"]
