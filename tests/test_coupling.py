"""The coupling interface the solvers expect (fenicsfriction.coupling): the node-to-segment
contact satisfies it structurally, as does what its ``operator`` compiles; an object that
misses a member does not."""

from __future__ import annotations

from mpi4py import MPI

from dolfinx import fem
from two_blocks import MASTER, SLAVE, stacked_blocks

from fenicsfriction import _compat
from fenicsfriction.contact import NodeToSegment
from fenicsfriction.coupling import Coupling, CouplingOperator
from fenicsfriction.laws import InterfaceLaw


def test_node_to_segment_is_a_coupling_and_compiles_to_a_coupling_operator():
    msh, _, facet_tags = stacked_blocks(MPI.COMM_WORLD, 2, 3, 4, overlap=0.02)
    u = fem.Function(_compat.vector_function_space(msh, 1))
    contact = NodeToSegment(u, facet_tags, SLAVE, MASTER, InterfaceLaw(c_n=100.0, m_n=1.0))
    assert isinstance(contact, Coupling)
    operator = contact.operator({u: 1.0})
    assert isinstance(operator, CouplingOperator)
    assert isinstance(operator.contact, Coupling)


def test_an_object_without_the_members_is_not_a_coupling():
    class Incomplete:
        search_pending = True
        m_n = 1.0

        def operator(self, derivatives, rest=(), jit_cache_dir=None):
            return None

    assert not isinstance(Incomplete(), Coupling)  # no frequency_bound
    assert not isinstance(object(), CouplingOperator)
