"""Two deformable bodies in frictional contact (Pop): node-to-segment contact elements
carrying the interface law of Martins & Oden (1986) between a slave surface and a master one,
in the same residual as the bulk terms (:mod:`fenicsfriction.forms`). The scenes that use them
are in :mod:`fenicsfriction.studies.contact` and :mod:`fenicsfriction.studies.block`."""

from fenicsfriction.contact.kinematics import Projection, project
from fenicsfriction.contact.node_to_segment import ContactOperator, NodeToSegment, solve_with_search
from fenicsfriction.contact.pairing import Pairing, facet_nodes

__all__ = ["ContactOperator", "NodeToSegment", "Pairing", "Projection", "facet_nodes", "project",
           "solve_with_search"]
