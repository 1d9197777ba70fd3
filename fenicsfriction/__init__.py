"""fenicsfriction: dynamic friction with normal compliance in FEniCSx (Martins & Oden 1986)."""

from importlib import metadata as _metadata

from fenicsfriction import forms, io, laws
from fenicsfriction.forms import Residual
from fenicsfriction.laws import InterfaceLaw
from fenicsfriction.scenes import BlockOnBelt
from fenicsfriction.steady import (ContinuationError, SolveError, SteadySolver, continuation,
                                   epsilon_sequence)

try:
    __version__ = _metadata.version("fenicsfriction")
except _metadata.PackageNotFoundError:  # running from a source tree
    __version__ = "0.0.0+unknown"

__all__ = ["BlockOnBelt", "ContinuationError", "InterfaceLaw", "Residual", "SolveError",
           "SteadySolver", "__version__", "continuation", "epsilon_sequence", "forms", "io", "laws"]
