"""Rolling contact of two identical elastic bodies by finite elements (Kalker's complete
theory): Carter's cylinders (2D), the Hertzian ellipse (3D), the Cattaneo-Mindlin shift."""

from fenicsfriction.scenes.rolling.model import (
    RollingContact,
    RollingModel,
    RollingResult,
    write_xdmf,
)

__all__ = ["RollingContact", "RollingModel", "RollingResult", "write_xdmf"]
