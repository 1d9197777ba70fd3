"""fenicsfriction: dynamic friction with normal compliance in FEniCSx.

Interface laws with normal compliance and regularised Coulomb-type friction (Martins & Oden
1987), steady sliding on a moving foundation, its stability as a quadratic eigenproblem, and
the dynamics that follow, on one UFL residual; reduced (mesh-free) models beside the finite
element ones.

Every name in ``__all__`` is importable from the package itself. The names are loaded on first
use, so ``import fenicsfriction.reduced`` (the models without a mesh) does not import dolfinx.
"""

from __future__ import annotations

import typing
from importlib import metadata as _metadata

from fenicsfriction._lazy import attach

try:
    __version__ = _metadata.version("fenicsfriction")
except _metadata.PackageNotFoundError:  # running from a source tree
    __version__ = "0.0.0+unknown"

#: public name -> the module that defines it
_EXPORTS: dict[str, str] = {
    # pointwise laws (NumPy and UFL)
    "InterfaceLaw": "laws", "ConstantFriction": "laws", "PiecewiseLinearFriction": "laws",
    "StribeckFriction": "laws", "CoulombSlipRule": "laws", "EllipticSlipRule": "laws",
    # the one residual
    "Residual": "forms", "NodalSpring": "forms",
    # solvers on the finite element residual
    "SteadySolver": "steady", "SolveError": "steady", "SolveReport": "steady",
    "ContinuationError": "steady", "continuation": "steady", "epsilon_sequence": "steady",
    "StabilitySolver": "stability", "Loci": "stability", "Mode": "stability",
    "EigenSolveError": "stability", "unstable_intervals": "stability", "Onset": "stability",
    "DynamicsSolver": "dynamics", "CentralDifference": "dynamics",
    "DynamicsError": "timestepping",
    "PanagiotopoulosSolver": "panagiotopoulos", "ProcessError": "panagiotopoulos",
    "ProcessReport": "panagiotopoulos", "SurfaceMollifier": "mollification",
    # post-processing and output
    "stick_slip_statistics": "statistics", "StickSlipStatistics": "statistics",
    "mode_intervals": "statistics", "limit_cycle": "statistics", "LimitCycle": "statistics",
    "belt_summary": "statistics", "BeltSummary": "statistics",
    "dense_eigenvalues": "numerics", "bisect": "numerics",
    "Record": "results", "write_json": "results", "get_logger": "results", "CsvRows": "results",
    "StopSignals": "signals", "Interrupted": "signals",
    # scenes
    "BlockData": "scenes", "BlockOnBelt": "scenes", "BlockModel": "scenes",
    "BlockOnSlab": "scenes", "SlabModel": "scenes", "LayeredBlockOnBelt": "scenes.block",
    "Hertz": "scenes.contact.validation", "Patch": "scenes.contact.validation",
    "Cattaneo": "scenes.contact.validation", "TwoBodyModel": "scenes.contact.model",
    "PressAndDrag": "scenes.contact.impact",
    # two-body contact
    "NodeToSegment": "contact", "solve_with_search": "contact",
    "BlockQuantities": "scenes.block", "Energies": "scenes.block", "Powers": "scenes.block",
    "ContactStates": "scenes.block", "CentreOfMass": "scenes.block",
    "ProbeValues": "scenes.block",
    # reduced models (no mesh)
    "RigidBlock": "reduced", "RigidLoci": "reduced.rigid_block", "rigid_loci":
    "reduced.rigid_block", "ReducedDynamics": "reduced", "BouncingMass": "reduced",
    "BeltOscillator": "reduced", "Slider": "reduced", "SliderMotion": "reduced",
    "Contact": "reduced", "table2_slider": "reduced", "stability_map": "reduced",
    "integrate_hybrid": "reduced", "HybridError": "reduced", "HybridResult": "reduced",
    "BeltResult": "reduced", "AveragedStability": "reduced.slider",
    "FloquetStability": "reduced.slider", "StabilityMap": "reduced.slider",
    "fastsim": "reduced.rolling.fastsim", "creep_curve": "reduced.rolling",
    "linear_theory": "reduced.rolling", "creep_coefficients": "reduced.rolling",
    "HertzEllipse": "reduced.rolling", "FastsimResult": "reduced.rolling",
}

_SUBMODULES = ("contact", "dynamics", "forms", "io", "laws", "mollification", "numerics",
               "panagiotopoulos", "plotting", "reduced", "results", "scenes", "signals",
               "stability", "statistics", "steady", "timestepping")

__getattr__, __dir__, __all__ = attach(__name__, _EXPORTS, _SUBMODULES)
__all__.append("__version__")  # the same list __dir__ returns


if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers and IDEs
    from fenicsfriction import (
        dynamics,
        forms,
        io,
        laws,
        mollification,
        numerics,
        panagiotopoulos,
        plotting,
        reduced,
        results,
        scenes,
        signals,
        stability,
        statistics,
        steady,
        timestepping,
    )
    from fenicsfriction.contact import NodeToSegment, solve_with_search
    from fenicsfriction.dynamics import CentralDifference, DynamicsSolver
    from fenicsfriction.forms import NodalSpring, Residual
    from fenicsfriction.laws import (
        ConstantFriction,
        CoulombSlipRule,
        EllipticSlipRule,
        InterfaceLaw,
        PiecewiseLinearFriction,
        StribeckFriction,
    )
    from fenicsfriction.mollification import SurfaceMollifier
    from fenicsfriction.numerics import bisect, dense_eigenvalues
    from fenicsfriction.panagiotopoulos import PanagiotopoulosSolver, ProcessError, ProcessReport
    from fenicsfriction.reduced import (
        BeltOscillator,
        BeltResult,
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
    from fenicsfriction.reduced.rigid_block import RigidLoci, rigid_loci
    from fenicsfriction.reduced.rolling import (
        FastsimResult,
        HertzEllipse,
        creep_coefficients,
        creep_curve,
        linear_theory,
    )
    from fenicsfriction.reduced.rolling.fastsim import fastsim
    from fenicsfriction.reduced.slider import AveragedStability, FloquetStability, StabilityMap
    from fenicsfriction.results import CsvRows, Record, get_logger, write_json
    from fenicsfriction.scenes import BlockData, BlockModel, BlockOnBelt, BlockOnSlab, SlabModel
    from fenicsfriction.scenes.block import (
        BlockQuantities,
        CentreOfMass,
        ContactStates,
        Energies,
        LayeredBlockOnBelt,
        Powers,
        ProbeValues,
    )
    from fenicsfriction.scenes.contact.impact import PressAndDrag
    from fenicsfriction.scenes.contact.model import TwoBodyModel
    from fenicsfriction.scenes.contact.validation import Cattaneo, Hertz, Patch
    from fenicsfriction.signals import Interrupted, StopSignals
    from fenicsfriction.stability import (
        EigenSolveError,
        Loci,
        Mode,
        Onset,
        StabilitySolver,
        unstable_intervals,
    )
    from fenicsfriction.statistics import (
        BeltSummary,
        LimitCycle,
        StickSlipStatistics,
        belt_summary,
        limit_cycle,
        mode_intervals,
        stick_slip_statistics,
    )
    from fenicsfriction.steady import (
        ContinuationError,
        SolveError,
        SolveReport,
        SteadySolver,
        continuation,
        epsilon_sequence,
    )
    from fenicsfriction.timestepping import DynamicsError
