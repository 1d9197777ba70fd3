"""What the mortar contact's geometry costs: search and build of B on a large 3D surface.

Two thin plates of tetrahedra, one on the other, non-matching: the upper one's lower face (the
slave surface) has 2 n² triangles (``--n``, default 50: 5000 slave facets), the lower one's
upper face 2 m² (``--m``, default 43). For each displacement degree (1 and 2) it times
:class:`fenicsfriction.contact.mortar.SegmentToSegment`'s first search (the nodal normals, the
candidate pairs from a k-d tree, the segmentation and integration of D and M: ``"search"``;
B as a PETSc matrix and the reference gaps: ``"build"``), then ``--repeats`` further searches
after a small displacement (the median), beside node-to-segment's search on the same degree-1
surfaces (:class:`fenicsfriction.contact.Pairing`) as a same-run baseline. Writes
``bench_mortar.json`` to ``--out`` and prints a markdown table (rank 0); run serially or under
``mpirun -n 2``. About 20 s serially.
"""

from __future__ import annotations

import itertools
import statistics
import sys
import time

from mpi4py import MPI

import numpy as np
from _common import parser as benchmark_parser
from _common import write_summary
from dolfinx import fem, mesh

from fenicsfriction import _compat
from fenicsfriction.contact import NodeToSegment
from fenicsfriction.contact.mortar import SegmentToSegment
from fenicsfriction.laws import InterfaceLaw

SLAVE, MASTER = 10, 20


def _plate(n: int, z0: float, thickness: float) -> tuple[np.ndarray, np.ndarray]:
    """The unit square times [z0, z0 + thickness] in n x n x 1 cubes of six tetrahedra."""
    axes = [np.linspace(0.0, 1.0, n + 1)] * 2 + [np.array([z0, z0 + thickness])]
    x = np.array(list(itertools.product(*axes)))
    index = np.arange(len(x)).reshape(n + 1, n + 1, 2)
    cells = []
    for i, j in itertools.product(range(n), repeat=2):
        box = [index[i + a, j + b, c] for a, b, c in itertools.product((0, 1), repeat=3)]
        for path in itertools.permutations(range(3)):
            vertex, nodes = 0, [box[0]]
            for axis in path:
                vertex += 1 << (2 - axis)
                nodes.append(box[vertex])
            cells.append(nodes)
    return x, np.array(cells)


def plates(comm: MPI.Comm, n: int, m: int) -> tuple[mesh.Mesh, mesh.MeshTags]:
    """The two plates in one mesh, the upper one's lower face (z = 0) tagged SLAVE, the lower
    one's upper face MASTER."""
    if comm.rank == 0:
        x1, c1 = _plate(n, 0.0, 0.05)
        x2, c2 = _plate(m, -0.05, 0.05)
        x, cells = np.vstack([x1, x2]), np.vstack([c1, c2 + len(x1)])
    else:
        x, cells = np.zeros((0, 3)), np.zeros((0, 4), dtype=np.int64)
    msh = _compat.create_simplex_mesh(comm, cells, x)
    tdim = 3
    msh.topology.create_connectivity(tdim - 1, tdim)
    facets = mesh.exterior_facet_indices(msh.topology)
    f_to_c = msh.topology.connectivity(tdim - 1, tdim)
    cells_all = np.arange(msh.topology.index_map(tdim).size_local
                          + msh.topology.index_map(tdim).num_ghosts, dtype=np.int32)
    upper = mesh.compute_midpoints(msh, tdim, cells_all)[:, 2] > 0
    z = mesh.compute_midpoints(msh, tdim - 1, facets)[:, 2]
    in_upper = np.array([upper[f_to_c.links(f)[0]] for f in facets], dtype=bool)
    values = np.zeros(len(facets), dtype=np.int32)
    values[in_upper & np.isclose(z, 0.0)] = SLAVE
    values[~in_upper & np.isclose(z, 0.0)] = MASTER
    keep = values > 0
    return msh, mesh.meshtags(msh, tdim - 1, facets[keep].astype(np.int32), values[keep])


def _timed_searches(contact, u: fem.Function, repeats: int) -> tuple[float, float]:
    """The first search's time and the median of ``repeats`` more (u moved a little)."""
    comm = u.function_space.mesh.comm
    comm.Barrier()
    t0 = time.perf_counter()
    contact.search()
    first = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    times = []
    x = u.function_space.tabulate_dof_coordinates()
    for k in range(repeats):
        u.x.array[:] = (1e-3 * np.sin(x[:, :3] @ [3.0, 2.0, 1.0] + k)[:, None]
                        * np.array([0.3, 0.2, -1.0])).ravel()
        u.x.scatter_forward()
        comm.Barrier()
        t0 = time.perf_counter()
        contact.search()
        times.append(comm.allreduce(time.perf_counter() - t0, op=MPI.MAX))
    return first, statistics.median(times)


def main(argv: list[str]) -> None:
    parser = benchmark_parser(__doc__)
    parser.add_argument("--n", type=int, default=50, help="slave plate: 2 n² facets (50)")
    parser.add_argument("--m", type=int, default=43, help="master plate: 2 m² facets (43)")
    parser.add_argument("--repeats", type=int, default=3, help="further searches (3)")
    args = parser.parse_args(argv)
    comm = MPI.COMM_WORLD
    msh, facet_tags = plates(comm, args.n, args.m)
    law = InterfaceLaw(c_n=1.0, m_n=1.0)
    rows = []
    for name, degree in (("node-to-segment", 1), ("mortar", 1), ("mortar", 2)):
        V = _compat.vector_function_space(msh, degree)
        u = fem.Function(V)
        t0 = time.perf_counter()
        kind = SegmentToSegment if name == "mortar" else NodeToSegment
        contact = kind(u, facet_tags, SLAVE, MASTER, law)
        setup = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
        first, again = _timed_searches(contact, u, args.repeats)
        parts = contact.pairing.time_s
        rows.append((name, degree, setup, first, again, parts["search"], parts["build"]))
    keys = ("contact", "degree", "setup_s", "first_search_s", "later_search_median_s",
            "search_s", "build_s")
    write_summary(args.out / "bench_mortar.json",
                  {"slave_facets": 2 * args.n**2, "master_facets": 2 * args.m**2,
                   "ranks": comm.size, "repeats": args.repeats,
                   "runs": [dict(zip(keys, row, strict=True)) for row in rows]},
                  comm=comm)
    if comm.rank == 0:
        facets = 2 * args.n**2
        print(f"{facets} slave facets against {2 * args.m**2}, {comm.size} rank(s)\n")
        print("| contact | degree | set-up [s] | first search [s] | later search, median [s] "
              "| all searches: search / build [s] |")
        print("|---|---|---|---|---|---|")
        for name, degree, setup, first, again, search, build in rows:
            print(f"| {name} | {degree} | {setup:.2f} | {first:.2f} | {again:.2f} "
                  f"| {search:.2f} / {build:.2f} |")


if __name__ == "__main__":
    main(sys.argv[1:])
