"""fenicsfriction: dynamic friction with normal compliance in FEniCSx.

Interface laws with normal compliance and regularised Coulomb-type friction (Martins & Oden
1987), steady sliding on a moving foundation, its stability as a quadratic eigenproblem, and
the dynamics that follow, on one UFL residual; reduced (mesh-free) models beside the finite
element ones.

Every name in ``__all__`` is importable from the package itself. The names are loaded on first
use, so ``import fenicsfriction.reduced`` (the models without a mesh) does not import dolfinx.
"""

from __future__ import annotations

import importlib
import typing
from importlib import metadata as _metadata

try:
    __version__ = _metadata.version("fenicsfriction")
except _metadata.PackageNotFoundError:  # running from a source tree
    __version__ = "0.0.0+unknown"

#: public name -> the module that defines it
_EXPORTS: dict[str, str] = {
    # pointwise laws (NumPy and UFL)
    "InterfaceLaw": "laws", "ConstantFriction": "laws", "PiecewiseLinearFriction": "laws",
    "StribeckFriction": "laws",
    # the one residual
    "Residual": "forms", "NodalSpring": "forms",
    # solvers on the finite element residual
    "SteadySolver": "steady", "SolveError": "steady", "SolveReport": "steady",
    "ContinuationError": "steady", "continuation": "steady", "epsilon_sequence": "steady",
    "StabilitySolver": "stability", "Loci": "stability", "Mode": "stability",
    "EigenSolveError": "stability", "unstable_intervals": "stability",
    "DynamicsSolver": "dynamics", "CentralDifference": "dynamics",
    "DynamicsError": "timestepping",
    # post-processing and output
    "stick_slip_statistics": "statistics", "dense_eigenvalues": "numerics",
    "Record": "results", "write_json": "results", "get_logger": "results",
    # scenes
    "BlockData": "scenes", "BlockOnBelt": "scenes", "BlockModel": "scenes",
    # reduced models (no mesh)
    "RigidBlock": "reduced", "ReducedDynamics": "reduced", "BouncingMass": "reduced",
    "BeltOscillator": "reduced", "Slider": "reduced", "SliderMotion": "reduced",
    "Contact": "reduced", "table2_slider": "reduced", "stability_map": "reduced",
    "integrate_hybrid": "reduced", "HybridError": "reduced", "HybridResult": "reduced",
}

_SUBMODULES = ("dynamics", "forms", "io", "laws", "numerics", "plotting", "reduced", "results",
               "scenes", "stability", "statistics", "steady", "timestepping")

__all__ = sorted([*_EXPORTS, *_SUBMODULES, "__version__"])


def __getattr__(name: str) -> typing.Any:
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{module}"), name)
    globals()[name] = value  # later look-ups skip __getattr__
    return value


def __dir__() -> list[str]:
    return __all__


if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers and IDEs
    from fenicsfriction import (
        dynamics,
        forms,
        io,
        laws,
        numerics,
        plotting,
        reduced,
        results,
        scenes,
        stability,
        statistics,
        steady,
        timestepping,
    )
    from fenicsfriction.dynamics import CentralDifference, DynamicsSolver
    from fenicsfriction.forms import NodalSpring, Residual
    from fenicsfriction.laws import (
        ConstantFriction,
        InterfaceLaw,
        PiecewiseLinearFriction,
        StribeckFriction,
    )
    from fenicsfriction.numerics import dense_eigenvalues
    from fenicsfriction.reduced import (
        BeltOscillator,
        BouncingMass,
        Contact,
        HybridError,
        HybridResult,
        ReducedDynamics,
        RigidBlock,
        Slider,
        SliderMotion,
        integrate_hybrid,
        stability_map,
        table2_slider,
    )
    from fenicsfriction.results import Record, get_logger, write_json
    from fenicsfriction.scenes import BlockData, BlockModel, BlockOnBelt
    from fenicsfriction.stability import (
        EigenSolveError,
        Loci,
        Mode,
        StabilitySolver,
        unstable_intervals,
    )
    from fenicsfriction.statistics import stick_slip_statistics
    from fenicsfriction.steady import (
        ContinuationError,
        SolveError,
        SolveReport,
        SteadySolver,
        continuation,
        epsilon_sequence,
    )
    from fenicsfriction.timestepping import DynamicsError
