r"""Newton's linear systems by a Krylov method preconditioned with algebraic multigrid (AMG): the
rigid-body near-nullspace, the PETSc options of the AMG path, and the automatic choice of a
solver's linear-solver path.

An elastic body's stiffness K annihilates its rigid motions (3 in 2D, 6 in 3D); aggregation
AMG (PETSc GAMG, Adams et al. 2004; Vaněk, Mandel & Brezina 1996) builds its coarse spaces from
these *near-nullspace* vectors, restricted to each aggregate, and with them converges in a
number of iterations independent of the mesh size. A mesh that holds several bodies (two-body
contact, a block on a slab) has the rigid motions of each body: :func:`rigid_body_modes` returns
one set per body (connected component of the mesh), each supported on its own body, which
spans the global set and more; the supports couple only through the contact terms.

The Jacobian is not symmetric wherever friction slips (the friction force follows the normal
pressure), so the Krylov method is GMRES with right preconditioning (its test is on the true
residual); CG is kept for a symmetric problem. The Krylov tolerance is tied to Newton's: a
relative 1e-8 per linear solve keeps Newton's quadratic phase down to its own tolerance, so
the converged state equals the direct path's to Newton's tolerance.

Everything here is a default under the solver's options prefix: ``-<prefix>pc_type lu`` gives
the direct path back, ``-<prefix>pc_type hypre`` BoomerAMG, any ``-<prefix>pc_gamg_*`` or
``-<prefix>mg_levels_*`` option tunes GAMG (docs/solvers.md has the measurements behind the
defaults and the crossovers of :func:`choose_linear_solver`).
"""

from __future__ import annotations

from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.la
import numpy as np
import scipy.sparse
import scipy.sparse.csgraph
from dolfinx import fem

from fenicsfriction.laws import check

__all__ = ["AMG_TYPES", "LINEAR_SOLVER_PATHS", "amg_options", "attach_near_nullspace",
           "bodies", "choose_linear_solver", "requested_amg", "resolve_linear_solver",
           "rigid_body_modes", "uses_amg"]

#: the AMG preconditioners :func:`amg_options` configures (PETSc ``pc_type``)
AMG_TYPES = ("gamg", "hypre")

#: the paths :func:`choose_linear_solver` chooses from
LINEAR_SOLVER_PATHS = ("lu", "condensed", "reused-lu", "amg")

#: ``"auto"`` solves by AMG from this many unknowns per rank on in 3D where the alternative
#: is a sparse LU at every Newton iteration (contact-free dynamics, a Jacobian that does not
#: split). Measured on the 3D block's steady continuation (Q2, μ = 0 → 0.5 in 5 steps, 13
#: Newton iterations, load average 6-15 on 2 cores): LU/AMG wall time 0.85 at 18,525
#: unknowns (38.0 s / 44.5 s, one run), 2.1 at 42,075 (536 s / 259 s, two runs): the
#: crossover near 2.5e4
AMG_MIN_UNKNOWNS_3D = 25_000

#: and from this many where the steady Jacobian splits and the LU of its bulk is reused
#: (:mod:`fenicsfriction.reused_lu`): the reused LU was 3.4x faster than AMG at 18,525
#: unknowns (12.9 s / 44.5 s), 3.5x and 2.3x at 42,075 (two runs) and 2.9x at 80,073 (273 s /
#: 784 s), its time growing like n^2.0 against AMG's n^1.7 there. This bound is not a
#: measured time crossover: it is where MUMPS's fill (n^(4/3)) rather than its time decides
AMG_MIN_UNKNOWNS_3D_REUSED_LU = 250_000

#: in 2D from this many: MUMPS's fill grows like n log n there and the condensation onto the
#: interface is 4.6x faster than the LU at 99,202 unknowns (docs/benchmarks.md); no 2D
#: crossover was measured, this bound keeps the direct paths on every 2D study mesh
AMG_MIN_UNKNOWNS_2D = 1_000_000


def bodies(V: fem.FunctionSpace) -> tuple[np.ndarray, int]:
    """The body (connected component of the mesh) of each node of ``V`` on this rank, owned and
    ghost, numbered 0, 1, ... the same on every rank; and the number of bodies.

    Each rank labels the components of its own part of the mesh; a ghost node joins its
    component to the owner's component of that node, and the (few) joins are gathered on every
    rank and merged there, so no rank holds more than the list of components.
    """
    comm = V.mesh.comm
    index_map = V.dofmap.index_map
    n_local = index_map.size_local + index_map.num_ghosts
    cells = V.dofmap.list  # an adjacency list up to 0.7, an array of rows from 0.8
    cells = np.asarray(getattr(cells, "array", cells)).reshape(-1, V.dofmap.dof_layout.num_dofs)
    # a chain through each cell's nodes connects them
    rows, cols = cells[:, :-1].ravel(), cells[:, 1:].ravel()
    graph = scipy.sparse.coo_matrix((np.ones(rows.size), (rows, cols)), shape=(n_local, n_local))
    count, local = scipy.sparse.csgraph.connected_components(graph, directed=False)
    offset = comm.scan(count) - count
    label = local + offset  # a global number for each rank's component
    # the owner's label of each ghost node
    owner = dolfinx.la.vector(index_map)
    owner.array[:] = label
    owner.scatter_forward()
    ghost_labels = owner.array[index_map.size_local:].astype(np.int64)
    joins = np.unique(np.column_stack([label[index_map.size_local:], ghost_labels]), axis=0)
    joins = np.concatenate(comm.allgather(joins.reshape(-1, 2)))
    total = comm.allreduce(count, op=MPI.SUM)
    merged = scipy.sparse.coo_matrix((np.ones(len(joins)), (joins[:, 0], joins[:, 1])),
                                     shape=(total, total))
    n_bodies, body_of_component = scipy.sparse.csgraph.connected_components(merged,
                                                                            directed=False)
    return body_of_component[label], int(n_bodies)


def _modes(x: np.ndarray, gdim: int) -> list[np.ndarray]:
    """The rigid motions at the points ``x`` (rows, centred): translations, then rotations."""
    n = x.shape[0]
    modes = []
    for i in range(gdim):
        mode = np.zeros((n, gdim))
        mode[:, i] = 1.0
        modes.append(mode)
    # rotation about axis k: (-x_j, x_i) in the (i, j) plane
    planes = [(0, 1)] if gdim == 2 else [(0, 1), (1, 2), (2, 0)]
    for i, j in planes:
        mode = np.zeros((n, gdim))
        mode[:, i], mode[:, j] = -x[:, j], x[:, i]
        modes.append(mode)
    return modes


def rigid_body_modes(V: fem.FunctionSpace, per_body: bool = True) -> PETSc.NullSpace:
    r"""The rigid motions of the bodies of a vector space ``V`` as an orthonormal PETSc
    near-nullspace: 3 vectors per body in 2D (two translations, one rotation), 6 in 3D.

    Args:
        V: a vector Lagrange space (the displacement's).
        per_body: one set per body (connected component of the mesh, :func:`bodies`), each
            vector zero outside its body; else one set for the whole mesh. The bodies move
            independently wherever they do not touch, so the global set leaves each body's
            relative rigid motion out of the coarse spaces: with the contact's penalty the
            two-body operator is nearly singular in exactly those directions.

    The vectors are orthonormalised (modified Gram–Schmidt, twice: the rotations of a body far
    from the origin are nearly translations) after centring each body's coordinates on its
    centroid.
    """
    gdim = V.mesh.geometry.dim
    bs = V.dofmap.index_map_bs
    check("V", bs, bs == gdim, f"must be a vector space of {gdim} components (block size {bs})")
    comm = V.mesh.comm
    n_owned = V.dofmap.index_map.size_local
    x = V.tabulate_dof_coordinates()[:n_owned, :gdim]
    if per_body:
        body, n_bodies = bodies(V)
        body = body[:n_owned]
    else:
        body, n_bodies = np.zeros(n_owned, dtype=np.int64), 1
    sums = comm.allreduce(np.column_stack([
        np.bincount(body, weights=x[:, k], minlength=n_bodies) for k in range(gdim)]
        + [np.bincount(body, minlength=n_bodies)]), op=MPI.SUM)
    centroids = sums[:, :gdim] / np.maximum(sums[:, gdim:], 1)
    vectors = []
    for b in range(n_bodies):
        inside = body == b
        for mode in _modes(x - centroids[b], gdim):
            mode[~inside] = 0.0
            vec = PETSc.Vec().createMPI((n_owned * bs, PETSc.DETERMINE), bsize=bs, comm=comm)
            vec.setArray(mode.ravel())
            vectors.append(vec)
    for _ in range(2):
        for i, vec in enumerate(vectors):
            for previous in vectors[:i]:
                vec.axpy(-vec.dot(previous), previous)
            vec.scale(1.0 / vec.norm())
    return PETSc.NullSpace().create(vectors=vectors, comm=comm)


def attach_near_nullspace(A: PETSc.Mat, V: fem.FunctionSpace,
                          per_body: bool = True) -> PETSc.NullSpace:
    """Give ``A`` (a Jacobian on ``V``) its rigid-body near-nullspace, which GAMG builds its
    coarse spaces from and BoomerAMG interpolates (``vec_interp_variant``); the block size is
    dolfinx's (one block per node). Returned: the near-nullspace (set it again on a matrix
    whose storage was replaced)."""
    nullspace = rigid_body_modes(V, per_body)
    A.setNearNullSpace(nullspace)
    return nullspace


def amg_options(dim: int, preconditioner: str = "gamg", symmetric: bool = False) -> dict:
    """PETSc options of the Krylov + AMG path (to put under the solver's prefix).

    Args:
        dim: the geometric dimension (BoomerAMG's strong threshold: 0.25 in 2D, 0.5 in 3D).
        preconditioner: ``"gamg"`` (smoothed aggregation with the near-nullspace, the default:
            faster on the block, docs/solvers.md) or ``"hypre"`` (BoomerAMG, systems options:
            nodal coarsening and interpolation of the rigid modes).
        symmetric: the Jacobian is symmetric (no slipping friction): CG, else GMRES.

    GAMG: one smoothing of the tentative prolongator (``agg_nsmooths 1``), a drop threshold
    0.01, Chebyshev smoothing with Jacobi on the levels, the interpolation kept across Newton
    iterations (``reuse_interpolation``: the Galerkin products are redone on the new Jacobian,
    the aggregates and prolongators kept; the interface is a small part of the operator).
    """
    check("preconditioner", preconditioner, preconditioner in AMG_TYPES,
          f"use one of {', '.join(AMG_TYPES)}")
    krylov = {"ksp_type": "cg" if symmetric else "gmres", "ksp_rtol": 1e-8,
              "ksp_atol": 1e-50, "ksp_max_it": 500, "ksp_norm_type": "unpreconditioned"}
    if not symmetric:
        krylov.update({"ksp_pc_side": "right", "ksp_gmres_restart": 100,
                       "ksp_gmres_modifiedgramschmidt": True})
    if preconditioner == "gamg":
        return {**krylov, "pc_type": "gamg", "pc_gamg_type": "agg",
                "pc_gamg_agg_nsmooths": 1, "pc_gamg_threshold": 0.01,
                "pc_gamg_reuse_interpolation": True, "pc_gamg_coarse_eq_limit": 1000,
                "mg_levels_ksp_type": "chebyshev", "mg_levels_pc_type": "jacobi",
                "mg_levels_ksp_max_it": 2}
    return {**krylov, "pc_type": "hypre", "pc_hypre_type": "boomeramg",
            "pc_hypre_boomeramg_strong_threshold": 0.5 if dim == 3 else 0.25,
            "pc_hypre_boomeramg_nodal_coarsen": 6,
            "pc_hypre_boomeramg_vec_interp_variant": 3,
            "pc_hypre_boomeramg_coarsen_type": "HMIS",
            "pc_hypre_boomeramg_interp_type": "ext+i",
            "pc_hypre_boomeramg_agg_nl": 1}


def requested_amg(prefix: str) -> str | None:
    """The AMG preconditioner the options database asks for under ``prefix``
    (``-<prefix>pc_type gamg`` or ``hypre``, e.g. from the command line), else ``None``: a
    solver then takes the AMG path with that preconditioner's defaults."""
    pc_type = PETSc.Options(prefix).getString("pc_type", "")
    return pc_type if pc_type in AMG_TYPES else None


def resolve_linear_solver(prefix: str, linear_solver: str, dim: int, size: int, ranks: int,
                          splits: bool, contact: bool) -> tuple[str, dict]:
    """A solver's ``linear_solver`` choice as the options and the problem's size settle it,
    with the option defaults of the path (:class:`~fenicsfriction.steady.SteadySolver`'s and
    :class:`~fenicsfriction.dynamics.DynamicsSolver`'s).

    The AMG path, ``("amg", amg_options(dim, type))``, where ``-<prefix>pc_type gamg|hypre``
    asks for it (that type; :func:`requested_amg`), where ``linear_solver`` is ``"amg"`` (GAMG),
    or where it is ``"auto"`` and :func:`choose_linear_solver` (``dim``, ``size``, ``ranks``,
    ``splits``, ``contact`` as there) picks AMG; else ``(linear_solver, {})``, ``"auto"``
    left for the solver to settle among its factorisations.
    """
    amg_type = requested_amg(prefix)
    if (amg_type is not None or linear_solver == "amg"
            or (linear_solver == "auto" and choose_linear_solver(
                dim, size, ranks, splits, contact=contact) == "amg")):
        return "amg", amg_options(dim, amg_type or "gamg")
    return linear_solver, {}


def uses_amg(ksp: PETSc.KSP) -> bool:
    """Whether the options put an AMG preconditioner on ``ksp`` (else a factorisation)."""
    return ksp.getPC().getType() in AMG_TYPES


def choose_linear_solver(dim: int, size: int, ranks: int, splits: bool,
                         condensable: bool = False, contact: bool = False) -> str:
    """The linear-solver path ``"auto"`` takes (one of :data:`LINEAR_SOLVER_PATHS`).

    Args:
        dim: the geometric dimension.
        size: the global number of unknowns.
        ranks: the number of MPI ranks.
        splits: the Jacobian splits into a constant bulk and an interface (steady problems
            without contact couplings), which the condensation and the reused LU need.
        condensable: the interface is small enough to condense onto
            (``steady.AUTO_CONDENSE_MAX_FILL``).
        contact: the residual has two-body contact couplings. Their penalty stiffness far
            above the bulk's (the patch test: c_n = 1e4 against E/h ≈ 20) takes GMRES + GAMG
            230 iterations per Newton step at 2,682 unknowns and past 500 at 10,090, whichever
            near-nullspace (per body or global): the LU stays the automatic choice there, AMG
            is available by ``linear_solver="amg"`` or the PETSc options.

    In 3D: AMG from :data:`AMG_MIN_UNKNOWNS_3D` unknowns per rank where the alternative is an
    LU per iteration, from :data:`AMG_MIN_UNKNOWNS_3D_REUSED_LU` where the Jacobian splits; in
    2D from :data:`AMG_MIN_UNKNOWNS_2D`. Below, the factorisations as before: condensed,
    reused LU where the Jacobian splits, else an LU per iteration.
    """
    check("dim", dim, dim in (2, 3), "use 2 or 3")
    if dim == 2:
        threshold = AMG_MIN_UNKNOWNS_2D
    else:
        threshold = AMG_MIN_UNKNOWNS_3D_REUSED_LU if splits else AMG_MIN_UNKNOWNS_3D
    if not contact and size >= threshold * ranks:
        return "amg"
    if splits:
        return "condensed" if condensable else "reused-lu"
    return "lu"
