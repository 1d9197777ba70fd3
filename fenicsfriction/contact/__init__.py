"""Two deformable bodies in frictional contact: the interface law of Martins & Oden (1986)
between a slave surface and a master one, in the same residual as the bulk terms
(:mod:`fenicsfriction.forms`), discretised by node-to-segment elements (Pop) or by a
segment-to-segment (mortar) integration. The scenes that use them are in
:mod:`fenicsfriction.studies.contact` and :mod:`fenicsfriction.studies.block`."""

from __future__ import annotations

import typing

from fenicsfriction import laws
from fenicsfriction.contact.kinematics import Projection, project
from fenicsfriction.contact.node_to_segment import ContactOperator, NodeToSegment, solve_with_search
from fenicsfriction.contact.pairing import Pairing, facet_nodes

__all__ = ["FORMULATIONS", "ContactOperator", "NodeToSegment", "Pairing", "Projection",
           "facet_nodes", "make_contact", "project", "solve_with_search"]

#: the discretisations of the contact between two surfaces: ``"node-to-segment"``
#: (:class:`NodeToSegment`: slave nodes against master facets, nodal rule) and ``"mortar"``
#: (:class:`fenicsfriction.contact.mortar.SegmentToSegment`: the law on mortar-weighted gaps,
#: segment-to-segment integration; passes the contact patch test, degree 1 or 2)
FORMULATIONS = ("node-to-segment", "mortar")


def make_contact(formulation: str, *args: typing.Any, **options: typing.Any) -> typing.Any:
    """The contact coupling of ``formulation`` (one of :data:`FORMULATIONS`) between a slave
    and a master surface: ``args`` and ``options`` as :class:`NodeToSegment`'s (u,
    facet_tags, slave, master, law, velocity=, fields=, transport=, weight=, ...)."""
    laws.check("formulation", formulation, formulation in FORMULATIONS,
               f"one of {', '.join(FORMULATIONS)}")
    if formulation == "mortar":
        from fenicsfriction.contact.mortar import SegmentToSegment
        return SegmentToSegment(*args, **options)
    return NodeToSegment(*args, **options)
