"""Braun's nonhomogeneous frictional interface: friction from many breaking contacts (Braun
(slides), "Nonhomogeneous frictional interface").

Without a mesh: the earthquake-like model (:mod:`.eq_model`) and its master equation
(:mod:`.master_equation`), the elastic instability (:mod:`.instability`), the elastic
interaction of contacts through the half-space (:mod:`.interaction`), interacting EQ contacts
(:mod:`.interacting`) and Frenkel-Kontorova slip fronts (:mod:`.frenkel_kontorova`). By finite
elements (dolfinx, loaded on first use): contacts as springs on an elastic substrate
(:mod:`.substrate`) and an elastic slider on breakable contacts whose onset of sliding is a
sequence of detachment fronts (:mod:`.slider`; Braun, Barel & Urbakh 2009; Rubinstein, Cohen &
Fineberg 2004)."""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "EQModel": "eq_model", "QuasistaticResult": "eq_model",
    "SpringDrivenResult": "eq_model", "describe_distribution": "eq_model",
    "SpringQuasistaticResult": "eq_model", "SlipEvents": "eq_model", "slip_events": "eq_model",
    "MasterEquation": "master_equation", "MasterEquationResult": "master_equation",
    "InstabilityMap": "instability", "instability_map": "instability",
    "critical_stiffness": "instability", "CouplingMap": "instability",
    "coupling_map": "instability", "InteractingEQModel": "interacting",
    "InteractingQuasistaticResult": "interacting", "lattice_compliance": "interacting",
    "LatticeEQModel": "interacting", "LatticeCompliance": "interacting",
    "FKChain": "frenkel_kontorova",
    "FKResult": "frenkel_kontorova", "FrontSpeeds": "frenkel_kontorova",
    "TriangleRamp": "frenkel_kontorova", "front_speeds": "frenkel_kontorova",
    "LatticeInteraction": "interaction", "interaction_matrix": "interaction",
    "green_tensor": "interaction", "correlation_length": "interaction",
    "fit_power_laws": "interaction", "radial_profile": "interaction",
    "ElasticSubstrate": "substrate", "SubstrateBlock": "substrate",
    "ElasticSlider": "slider", "ElasticSliderModel": "slider", "SliderHistory": "slider",
    "Break": "slider", "Front": "slider", "fronts": "slider"})

if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers
    from fenicsfriction.studies.multicontact.eq_model import (
        EQModel,
        QuasistaticResult,
        SlipEvents,
        SpringDrivenResult,
        SpringQuasistaticResult,
        describe_distribution,
        slip_events,
    )
    from fenicsfriction.studies.multicontact.frenkel_kontorova import (
        FKChain,
        FKResult,
        FrontSpeeds,
        TriangleRamp,
        front_speeds,
    )
    from fenicsfriction.studies.multicontact.instability import (
        CouplingMap,
        InstabilityMap,
        coupling_map,
        critical_stiffness,
        instability_map,
    )
    from fenicsfriction.studies.multicontact.interacting import (
        InteractingEQModel,
        InteractingQuasistaticResult,
        LatticeCompliance,
        LatticeEQModel,
        lattice_compliance,
    )
    from fenicsfriction.studies.multicontact.interaction import (
        LatticeInteraction,
        correlation_length,
        fit_power_laws,
        green_tensor,
        interaction_matrix,
        radial_profile,
    )
    from fenicsfriction.studies.multicontact.master_equation import (
        MasterEquation,
        MasterEquationResult,
    )
    from fenicsfriction.studies.multicontact.slider import (
        Break,
        ElasticSlider,
        ElasticSliderModel,
        Front,
        SliderHistory,
        fronts,
    )
    from fenicsfriction.studies.multicontact.substrate import ElasticSubstrate, SubstrateBlock
