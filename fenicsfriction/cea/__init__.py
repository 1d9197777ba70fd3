"""Complex eigenvalue analysis (CEA) as brake-squeal engineers run it, on matrices.

The stability of steady sliding is the quadratic eigenproblem
:math:`(\\lambda^2 M + \\lambda C(p) + K(p)) w = 0` along a parameter p (a friction
coefficient, a pressure); a mode with Re λ > 0 grows (squeal). Here the matrices come from
anywhere — the finite element model's :class:`~fenicsfriction.stability.StabilitySolver`, or
files exported by other codes (:mod:`~fenicsfriction.cea.matrices`) — and every eigenvalue in a
frequency band (:class:`~fenicsfriction.cea.band.Band`) is computed on the full matrices
(:mod:`~fenicsfriction.cea.full`: SLEPc PEP, or QZ when small, :mod:`~fenicsfriction.cea.dense`)
or on a modal basis (:mod:`~fenicsfriction.cea.projection`), read as each body's
free-interface modes' shares (:mod:`~fenicsfriction.cea.contributions`), swept in p with modes
tracked and their coalescence located (:mod:`~fenicsfriction.cea.sweep`), drawn as a
mode-coupling map (:mod:`~fenicsfriction.cea.figures`) and checked against the
two-degree-of-freedom model of Hoffmann et al. (2002) (:mod:`~fenicsfriction.cea.hoffmann`).

The names are loaded on first use (``import fenicsfriction.cea`` imports no PETSc).
"""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

#: public name -> the submodule that defines it
_EXPORTS: dict[str, str] = {
    "Band": "band",
    "BandSolver": "full",
    "ModalBasis": "projection", "symmetric_part": "projection",
    "ParametricPencil": "matrices", "read_matrix": "matrices", "from_array": "matrices",
    "to_dense": "matrices",
    "dense_modes": "dense", "quadratic_eig": "dense",
    "Sweep": "sweep", "Coalescence": "sweep",
    "HoffmannModel": "hoffmann",
    "plot_coupling_map": "figures",
    "FreeInterfaceModes": "contributions", "ModeContributions": "contributions",
    "plot_contributions": "contributions",
    "ProjectedStability": "coupling_map", "CouplingMap": "coupling_map",
}

_SUBMODULES = ("band", "contributions", "coupling_map", "dense", "figures", "full", "hoffmann",
               "matrices", "projection", "sweep")

__getattr__, __dir__, __all__ = attach(__name__, _EXPORTS, _SUBMODULES)

if typing.TYPE_CHECKING:
    from fenicsfriction.cea import (
        band,
        contributions,
        coupling_map,
        dense,
        figures,
        full,
        hoffmann,
        matrices,
        projection,
        sweep,
    )
    from fenicsfriction.cea.band import Band
    from fenicsfriction.cea.contributions import (
        FreeInterfaceModes,
        ModeContributions,
        plot_contributions,
    )
    from fenicsfriction.cea.coupling_map import CouplingMap, ProjectedStability
    from fenicsfriction.cea.dense import dense_modes, quadratic_eig
    from fenicsfriction.cea.figures import plot_coupling_map
    from fenicsfriction.cea.full import BandSolver
    from fenicsfriction.cea.hoffmann import HoffmannModel
    from fenicsfriction.cea.matrices import ParametricPencil, from_array, read_matrix, to_dense
    from fenicsfriction.cea.projection import ModalBasis, symmetric_part
    from fenicsfriction.cea.sweep import Coalescence, Sweep
