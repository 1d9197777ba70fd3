"""Contact at scale: the distributed contact search and the contact partition on Hertz 3D.

The quarter sphere on a block (:func:`~fenicsfriction.studies.contact.geometry.hertz_3d`, the
scene of ``fenicsfriction contact hertz --dim 3``; node-to-segment, c_n = 1e4, E = 1) is solved
at the approach of Hertz's a = R/10 (δ = a²/R, one solve with the search repeated until it
holds) on meshes whose element size at the contact is each of ``--h-contact``. Run it once
serially and once under ``mpirun -n 2`` with the same flags; each run writes
``bench_contact_scale_<ranks>.json``; the run that finds both files also compares them: the
nodal pressures (slave nodes matched by their coordinates) on 1 and 2 ranks, the largest
difference relative to the peak pressure, and writes ``bench_contact_scale.png``.

For each size and each partition of ``--partitions`` (``graph``: dolfinx's partitioner, one
body per rank; ``contact``: both bodies cut by the angle about the z axis) it records, per
rank: the slave nodes it pairs, the master facets it held at the last search (against the
whole master surface's), the search's time (exchange of the master facets near its slave
nodes, k-d tree, distances; and building the pairing operator), the exchange rounds, and the
peak resident memory (``resource.getrusage``); and the unknowns, the wall times of the mesh,
the model and the solve, Newton iterations, the linear solver (KSP, PC, factorisation
package), BLAS, and the load average at the start and end of the run (``os.getloadavg``: the
machine's two cores may be shared, so compare only ratios measured in one run).
"""

from __future__ import annotations

import json
import os
import pathlib
import resource
import sys
import time

from mpi4py import MPI

import numpy as np
from _common import environment as run_environment
from _common import parser as benchmark_parser

from fenicsfriction.studies.contact import geometry
from fenicsfriction.studies.contact.validation import Hertz

#: searches timed alone at the solution (their median is recorded)
SEARCH_REPEATS = 5


def _peak_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _per_rank(comm: MPI.Comm, value: float) -> list:
    return comm.allgather(value)


def run(h_contact: float, partition: str, comm: MPI.Comm) -> dict:
    """One size and partition: the solve and the search's numbers per rank."""
    scene = Hertz(dim=3)
    a = scene.radius / 10
    t0 = time.perf_counter()
    mesh = geometry.hertz_3d(comm, R=scene.radius, h_contact=h_contact, partition=partition)
    t1 = time.perf_counter()
    model = scene.model(mesh, fix_load_face=False)
    t2 = time.perf_counter()
    report = model.solve_at(a**2 / scene.radius)
    t3 = time.perf_counter()
    values = model.surface_values()
    pairing = model.contacts[0].pairing
    repeat = []
    for _ in range(SEARCH_REPEATS):  # the search alone at the solution, ranks started together
        comm.Barrier()
        ts = time.perf_counter()
        pairing.search(model.u)
        repeat.append(time.perf_counter() - ts)
    held_all = comm.allreduce(len({tuple(r) for r in pairing.facet_global_nodes.tolist()}))
    ksp = model.solver.snes.getKSP()
    pc = ksp.getPC()
    factor = pc.getFactorSolverType() if pc.getType() in ("lu", "cholesky") else None
    master_total = model.comm.allreduce(
        int(np.count_nonzero(mesh.facet_tags.values == geometry.MASTER)))
    return {
        "h_contact": h_contact, "partition": partition, "dofs": model.dofs,
        "mesh_s": t1 - t0, "model_s": t2 - t1, "solve_s": t3 - t2,
        "newton_iterations": report.iterations, "searches": pairing.searches,
        "solver": {"ksp": ksp.getType(), "pc": pc.getType(), "factor": factor},
        "slave_nodes": _per_rank(comm, len(pairing.slave_nodes)),
        "held_master_facets": _per_rank(comm, pairing.held),
        "paired_facets_distinct": held_all,
        "master_facets_tagged_sum": master_total,
        "search_s": _per_rank(comm, pairing.time_s["search"]),
        "exchange_s": _per_rank(comm, pairing.time_s["exchange"]),
        "build_s": _per_rank(comm, pairing.time_s["build"]),
        "rounds_last": pairing.rounds,
        "search_repeat_s": _per_rank(comm, float(np.median(repeat))),
        "peak_mib": _per_rank(comm, _peak_mib()),
        "x": values.x.tolist(), "pressure": values.pressure.tolist(),
        "force": values.force[:, -1].tolist(),
    }


def compare(out: pathlib.Path) -> list[dict]:
    """The 1- and 2-rank runs' pressures, size by size (contact partition on 2 ranks)."""
    one = json.loads((out / "bench_contact_scale_1.json").read_text())
    two = json.loads((out / "bench_contact_scale_2.json").read_text())
    rows = []
    for a in one["runs"]:
        for b in two["runs"]:
            if b["h_contact"] != a["h_contact"]:
                continue
            xa, xb = np.array(a["x"]), np.array(b["x"])
            pa, pb = np.array(a["pressure"]), np.array(b["pressure"])
            # matched by coordinates rounded off (a partition's may differ by 1e-17)
            ka, kb = (np.lexsort(np.round(x, 12).T[::-1]) for x in (xa, xb))
            xa, xb, pa, pb = xa[ka], xb[kb], pa[ka], pb[kb]
            same_nodes = xa.shape == xb.shape and bool(np.allclose(xa, xb, rtol=0, atol=1e-12))
            rows.append({
                "h_contact": a["h_contact"], "dofs": a["dofs"], "partition_2": b["partition"],
                "same_nodes": same_nodes,
                "pressure_difference": (float(np.abs(pa - pb).max() / np.abs(pa).max())
                                        if same_nodes else None),
                "solve_s_1": a["solve_s"], "solve_s_2": b["solve_s"],
                "search_s_1": max(a["search_s"]), "search_s_2": b["search_s"],
                "search_once_s_1": a.get("search_repeat_s"),
                "search_once_s_2": b.get("search_repeat_s"),
                "slave_nodes_2": b["slave_nodes"], "held_2": b["held_master_facets"],
                "held_1": a["held_master_facets"],
                "peak_mib_1": a["peak_mib"], "peak_mib_2": b["peak_mib"]})
    return rows


def plot(rows: list[dict], path: pathlib.Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from _common import save

    contact = [r for r in rows if r["partition_2"] == "contact"]
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    n = [r["dofs"] for r in contact]
    axes[0].loglog(n, [r["search_once_s_1"][0] for r in contact], "o-", label="1 rank")
    for k in range(2):
        axes[0].loglog(n, [r["search_once_s_2"][k] for r in contact], "s--",
                       label=f"2 ranks: rank {k}")
    axes[0].set(xlabel="unknowns", ylabel="one search [s]",
                title="search time per rank (contact partition)")
    axes[0].legend()
    axes[1].loglog(n, [r["peak_mib_1"][0] for r in contact], "o-", label="1 rank")
    for k in range(2):
        axes[1].loglog(n, [r["peak_mib_2"][k] for r in contact], "s--", label=f"2 ranks: rank {k}")
    axes[1].set(xlabel="unknowns", ylabel="peak resident memory [MiB]",
                title="memory per rank")
    axes[1].legend()
    save(fig, path, 120)


def main() -> None:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--h-contact", type=float, nargs="+", default=[0.04, 0.028, 0.02],
                       help="element sizes at the contact (R = 1; default 0.04 0.028 0.02)")
    flags.add_argument("--partitions", nargs="+", default=None,
                       help="graph and/or contact (default: contact; on 2+ ranks graph too)")
    args = flags.parse_args()
    comm = MPI.COMM_WORLD
    partitions = args.partitions or (["graph", "contact"] if comm.size > 1 else ["contact"])
    load_start = os.getloadavg()
    runs = []
    for h in args.h_contact:
        for partition in partitions:
            record = run(h, partition, comm)
            runs.append(record)
            if comm.rank == 0:
                print(f"h={h} {partition}: {record['dofs']:,} unknowns, solve "
                      f"{record['solve_s']:.1f} s, slave nodes {record['slave_nodes']}, held "
                      f"{record['held_master_facets']} of {record['master_facets_tagged_sum']}"
                      f" tagged, search {np.round(record['search_s'], 3).tolist()} s, peak "
                      f"{np.round(record['peak_mib']).tolist()} MiB", file=sys.stderr,
                      flush=True)
    summary = {"ranks": comm.size, "runs": runs, "loadavg_start": load_start,
               "loadavg_end": os.getloadavg(), "environment": run_environment(comm),
               "command": " ".join(sys.argv)}
    out = args.out
    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
        (out / f"bench_contact_scale_{comm.size}.json").write_text(json.dumps(summary))
        if all((out / f"bench_contact_scale_{k}.json").exists() for k in (1, 2)):
            rows = compare(out)
            (out / "bench_contact_scale_compare.json").write_text(json.dumps(rows, indent=1))
            plot(rows, out / "bench_contact_scale.png")
            for r in rows:
                print(json.dumps(r))


if __name__ == "__main__":
    main()
