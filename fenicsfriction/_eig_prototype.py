"""TEMPORARY stand-in for fenicsfriction.amg.rigid_body_modes until that merges."""
from __future__ import annotations

from petsc4py import PETSc

import numpy as np


def rigid_body_modes(V) -> PETSc.NullSpace:
    bs = V.dofmap.index_map_bs
    nloc = V.dofmap.index_map.size_local
    x = V.tabulate_dof_coordinates()[:nloc]
    basis = []
    for k in range(bs):
        b = np.zeros((nloc, bs))
        b[:, k] = 1
        basis.append(b)
    pairs = [(0, 1)] if bs == 2 else [(0, 1), (1, 2), (2, 0)]
    for i, j in pairs:
        b = np.zeros((nloc, bs))
        b[:, i] = -x[:, j]
        b[:, j] = x[:, i]
        basis.append(b)
    comm = V.mesh.comm
    vecs = []
    for b in basis:
        v = PETSc.Vec().createMPI((nloc * bs, PETSc.DECIDE), comm=comm)
        v.setArray(b.ravel())
        vecs.append(v)
    # Gram-Schmidt
    for i, v in enumerate(vecs):
        for w in vecs[:i]:
            v.axpy(-v.dot(w), w)
        v.normalize()
    return PETSc.NullSpace().create(vectors=vecs, comm=comm)
