"""Braun's nonhomogeneous frictional interface, reduced (no mesh): the earthquake-like model of
many breaking contacts, its master equation, the elastic instability, the elastic interaction
of contacts through the half-space and Frenkel-Kontorova slip fronts (Braun (slides),
"Nonhomogeneous frictional interface")."""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "EQModel": "eq_model", "QuasistaticResult": "eq_model",
    "SpringDrivenResult": "eq_model", "describe_distribution": "eq_model",
    "MasterEquation": "master_equation", "MasterEquationResult": "master_equation",
    "InstabilityMap": "instability", "instability_map": "instability",
    "critical_stiffness": "instability", "CouplingMap": "instability",
    "coupling_map": "instability", "InteractingEQModel": "interacting",
    "InteractingQuasistaticResult": "interacting", "lattice_compliance": "interacting",
    "FKChain": "frenkel_kontorova",
    "FKResult": "frenkel_kontorova", "FrontSpeeds": "frenkel_kontorova",
    "TriangleRamp": "frenkel_kontorova", "front_speeds": "frenkel_kontorova",
    "LatticeInteraction": "interaction", "interaction_matrix": "interaction",
    "green_tensor": "interaction", "correlation_length": "interaction",
    "fit_power_laws": "interaction", "radial_profile": "interaction"})

if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers
    from fenicsfriction.reduced.interface.eq_model import (
        EQModel,
        QuasistaticResult,
        SpringDrivenResult,
        describe_distribution,
    )
    from fenicsfriction.reduced.interface.frenkel_kontorova import (
        FKChain,
        FKResult,
        FrontSpeeds,
        TriangleRamp,
        front_speeds,
    )
    from fenicsfriction.reduced.interface.instability import (
        CouplingMap,
        InstabilityMap,
        coupling_map,
        critical_stiffness,
        instability_map,
    )
    from fenicsfriction.reduced.interface.interacting import (
        InteractingEQModel,
        InteractingQuasistaticResult,
        lattice_compliance,
    )
    from fenicsfriction.reduced.interface.interaction import (
        LatticeInteraction,
        correlation_length,
        fit_power_laws,
        green_tensor,
        interaction_matrix,
        radial_profile,
    )
    from fenicsfriction.reduced.interface.master_equation import (
        MasterEquation,
        MasterEquationResult,
    )
