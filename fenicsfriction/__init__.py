"""fenicsfriction: dynamic friction with normal compliance in FEniCSx.

Interface laws with normal compliance and regularised Coulomb-type friction (Martins & Oden
1986), steady sliding on a moving foundation, its stability as a quadratic eigenproblem, and
the dynamics that follow, on one UFL residual (:mod:`~fenicsfriction.laws` →
:mod:`~fenicsfriction.forms` → :mod:`~fenicsfriction.steady`, :mod:`~fenicsfriction.stability`,
:mod:`~fenicsfriction.dynamics`); the studies, grouped by physics family with their mesh-free
models beside the finite element ones, in :mod:`fenicsfriction.studies`.

Every name in ``__all__`` is importable from the package itself. The names are loaded on first
use, so importing a mesh-free model (``fenicsfriction.studies.rolling.fastsim``, say) does not
import dolfinx.
"""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

#: public name -> the module that defines it
_EXPORTS: dict[str, str] = {
    # the interface law (NumPy and UFL)
    "InterfaceLaw": "laws", "ConstantFriction": "laws", "PiecewiseLinearFriction": "laws",
    "StribeckFriction": "laws", "CoulombSlipRule": "laws", "EllipticSlipRule": "laws",
    # the one residual
    "Residual": "forms", "NodalSpring": "forms", "RigidRotation": "rotation",
    # solvers on the finite element residual
    "SteadySolver": "steady", "SolveError": "steady", "SolveReport": "steady",
    "ContinuationError": "steady", "continuation": "steady", "epsilon_sequence": "steady",
    "solve_continued": "steady",
    "StabilitySolver": "stability", "Loci": "stability", "Mode": "stability",
    "EigenSolveError": "stability", "unstable_intervals": "stability", "Onset": "stability",
    "DynamicsSolver": "dynamics", "CentralDifference": "dynamics",
    "DynamicsError": "timestepping", "ReducedDynamics": "timestepping",
    "PanagiotopoulosSolver": "panagiotopoulos", "ProcessError": "panagiotopoulos",
    "ProcessReport": "panagiotopoulos", "SurfaceMollifier": "mollification",
    "integrate_hybrid": "events", "HybridError": "events", "HybridResult": "events",
    "rigid_body_modes": "amg", "choose_linear_solver": "amg",
    # two-body contact elements
    "NodeToSegment": "contact", "solve_with_search": "contact",
    # post-processing and output
    "stick_slip_statistics": "statistics", "StickSlipStatistics": "statistics",
    "mode_intervals": "statistics", "limit_cycle": "statistics", "LimitCycle": "statistics",
    "belt_summary": "statistics", "BeltSummary": "statistics",
    "dense_eigenvalues": "numerics", "bisect": "numerics",
    "Record": "results", "write_json": "results", "get_logger": "results", "CsvRows": "results",
    "StopSignals": "signals", "Interrupted": "signals",
    # studies: the block on a belt
    "BlockData": "studies.block", "BlockOnBelt": "studies.block", "BlockModel": "studies.block",
    "BlockOnSlab": "studies.block", "SlabModel": "studies.block",
    "LayeredBlockOnBelt": "studies.block", "BlockQuantities": "studies.block",
    "Energies": "studies.block", "Powers": "studies.block", "ContactStates": "studies.block",
    "CentreOfMass": "studies.block", "ProbeValues": "studies.block",
    "RigidBlock": "studies.block", "RigidLoci": "studies.block", "rigid_loci": "studies.block",
    # studies: two-body contact
    "Hertz": "studies.contact", "Patch": "studies.contact", "Cattaneo": "studies.contact",
    "TwoBodyModel": "studies.contact", "PressAndDrag": "studies.contact",
    # studies: rolling contact
    "fastsim": "studies.rolling.fastsim", "creep_curve": "studies.rolling",
    "linear_theory": "studies.rolling", "creep_coefficients": "studies.rolling",
    "HertzEllipse": "studies.rolling", "FastsimResult": "studies.rolling",
    "RollingContact": "studies.rolling",
    # studies: oscillators
    "BouncingMass": "studies.oscillators", "BeltOscillator": "studies.oscillators",
    "BeltResult": "studies.oscillators", "Slider": "studies.oscillators",
    "SliderMotion": "studies.oscillators", "Contact": "studies.oscillators",
    "table2_slider": "studies.oscillators", "stability_map": "studies.oscillators",
    "AveragedStability": "studies.oscillators", "FloquetStability": "studies.oscillators",
    "StabilityMap": "studies.oscillators",
    # studies: multicontact (Braun's many breaking contacts)
    "EQModel": "studies.multicontact", "MasterEquation": "studies.multicontact",
    "InteractingEQModel": "studies.multicontact", "FKChain": "studies.multicontact",
}

_SUBMODULES = ("amg", "contact", "dynamics", "events", "forms", "io", "laws", "meshing",
               "mollification", "numerics", "panagiotopoulos", "plotting", "results", "rotation",
               "signals", "stability", "statistics", "steady", "studies", "timestepping")

_getattr, __dir__, __all__ = attach(__name__, _EXPORTS, _SUBMODULES)
__all__.append("__version__")  # the same list __dir__ returns


def __getattr__(name: str) -> typing.Any:
    if name != "__version__":
        return _getattr(name)
    # read on first use: importlib.metadata costs a third of the package's import, the time
    # in which a command line's Ctrl-C would otherwise still end in a traceback
    from importlib import metadata
    try:
        version = metadata.version("fenicsfriction")
    except metadata.PackageNotFoundError:  # running from a source tree
        version = "0.0.0+unknown"
    globals()["__version__"] = version
    return version


if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers and IDEs
    from fenicsfriction import (
        contact,
        dynamics,
        events,
        forms,
        io,
        laws,
        meshing,
        mollification,
        numerics,
        panagiotopoulos,
        plotting,
        results,
        rotation,
        signals,
        stability,
        statistics,
        steady,
        studies,
        timestepping,
    )
    from fenicsfriction.contact import NodeToSegment, solve_with_search
    from fenicsfriction.dynamics import CentralDifference, DynamicsSolver
    from fenicsfriction.events import HybridError, HybridResult, integrate_hybrid
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
    from fenicsfriction.results import CsvRows, Record, get_logger, write_json
    from fenicsfriction.rotation import RigidRotation
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
        solve_continued,
    )
    from fenicsfriction.studies.block import (
        BlockData,
        BlockModel,
        BlockOnBelt,
        BlockOnSlab,
        BlockQuantities,
        CentreOfMass,
        ContactStates,
        Energies,
        LayeredBlockOnBelt,
        Powers,
        ProbeValues,
        RigidBlock,
        RigidLoci,
        SlabModel,
        rigid_loci,
    )
    from fenicsfriction.studies.contact import Cattaneo, Hertz, Patch, PressAndDrag, TwoBodyModel
    from fenicsfriction.studies.multicontact import (
        EQModel,
        FKChain,
        InteractingEQModel,
        MasterEquation,
    )
    from fenicsfriction.studies.oscillators import (
        AveragedStability,
        BeltOscillator,
        BeltResult,
        BouncingMass,
        Contact,
        FloquetStability,
        Slider,
        SliderMotion,
        StabilityMap,
        stability_map,
        table2_slider,
    )
    from fenicsfriction.studies.rolling import (
        FastsimResult,
        HertzEllipse,
        RollingContact,
        creep_coefficients,
        creep_curve,
        linear_theory,
    )
    from fenicsfriction.studies.rolling.fastsim import fastsim
    from fenicsfriction.timestepping import DynamicsError, ReducedDynamics
