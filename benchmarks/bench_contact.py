"""Accuracy against cost of two-body contact (Hertz 2D and 3D), and where the time goes.

For each mesh of the Hertz scenes (a cylinder on a block in plane strain, refinement levels
``--refine-2d``, default 0 1 2; a quarter sphere on a block, ``--refine-3d``, default 0; each
level halves the mesh size) it records:

* accuracy against Hertz (Hertz 1882; Johnson 1985, eqs. 4.22-4.23 and 4.43-4.45): the
  half-width / contact radius where the interpolated gap changes sign (the scene's own
  measure; it places the edge only to within an element), the half-width and peak pressure
  of the Hertz ellipse fitted through every contact node's pressure, the peak nodal
  pressure, and the L2 error of the nodal pressures against p0 sqrt(1 - r²/a²);
* cost: wall times of the mesh (gmsh), the model (forms, JIT from a warm cache) and the
  solve (the approach found by secant steps until the contact force is the load to 1e-5),
  the median of ``--repeats`` runs where the mesh is small; Newton iterations per solve;
* where the solve's time goes, from PETSc's log (``PETSc.Log``) and the contact's own
  timers: contact search and building Q (``Pairing.time_s``), the contact residual and
  chained Jacobian (``ContactOperator.time_s``), the bulk assembly (SNES's function and
  Jacobian evaluations less the contact's parts), the LU factorisations (MUMPS, symbolic and
  numeric) and the triangular solves, and the rest (SNES, line search, Python);
* a same-run baseline: the contact's share (search + residual + Jacobian) over the bulk LU
  factorisation's, a ratio that does not depend on the machine's speed; and the two-pass
  formulation's solve time over the one-pass one on the coarsest 2D mesh.

The search's growth with the surface size is measured apart, on synthetic surfaces: a strip
(2D) or plate (3D) of n (n²) master facets with its other face's nodes laid onto it, timing
``Pairing.search`` alone (first search with the build of Q, then repeated searches, which
keep the pairing), and fitting time ∝ facets^α.

Writes ``bench_contact.json`` and ``bench_contact.png`` to ``--out`` and prints markdown
tables to stdout (progress on stderr). Rank 0 writes and prints; run serially or with
``mpirun -n 2``. About 10 minutes serially with the defaults (the 2D level 2 mesh, 544 000
unknowns, takes 4 of them); ``--refine-3d 0,1`` adds the 3D level 1 mesh (see
docs/benchmarks.md for its cost).
"""

from __future__ import annotations

import logging
import statistics
import sys
import time

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction.contact import Pairing, facet_nodes
from fenicsfriction.studies.contact import closed_forms, geometry
from fenicsfriction.studies.contact.model import TwoBodyModel
from fenicsfriction.studies.contact.validation import Hertz

EVENTS = ("SNESFunctionEval", "SNESJacobianEval", "MatLUFactorSym", "MatLUFactorNum",
          "MatSolve", "SNESSolve")
SMALL = 60_000  # unknowns: meshes up to this size are run --repeats times
SEARCH_SIZES = {2: (250, 1000, 4000, 16000, 64000), 3: (16, 32, 64, 128)}
SEARCH_REPEATS = 5

log = logging.getLogger("bench_contact")


def event_times(comm: MPI.Comm) -> dict[str, float]:
    """Cumulative time of each PETSc event in :data:`EVENTS` (max over the ranks)."""
    return {name: comm.allreduce(PETSc.Log.Event(name).getPerfInfo()["time"], op=MPI.MAX)
            for name in EVENTS}


def measure(scene: Hertz, model: TwoBodyModel, comm: MPI.Comm) -> dict:
    """Solve ``scene`` on ``model`` and take its accuracy, Newton counts and time shares."""
    solves: list[dict] = []
    solve_at = model.solve_at

    def recorded(approach: float):  # the same method, its report kept per solve
        t0 = time.perf_counter()
        report = solve_at(approach)
        solves.append({"approach": approach, "newton_iterations": report.iterations,
                       "rounds": report.rounds, "wall_time_s": time.perf_counter() - t0})
        return report

    model.solve_at = recorded  # type: ignore[method-assign]
    before = event_times(comm)
    comm.Barrier()
    t0 = time.perf_counter()
    summary, _ = scene.run(comm, model)
    solve_time = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    after = event_times(comm)
    ev = {k: after[k] - before[k] for k in EVENTS}
    mx = lambda value: comm.allreduce(value, op=MPI.MAX)  # noqa: E731
    search = mx(sum(c.pairing.time_s["search"] for c in model.contacts))
    build = mx(sum(c.pairing.time_s["build"] for c in model.contacts))
    residual = mx(sum(op.time_s["residual"] for op in model.solver.couplings))
    jacobian = mx(sum(op.time_s["jacobian"] for op in model.solver.couplings))
    lu = ev["MatLUFactorSym"] + ev["MatLUFactorNum"]
    # the searches inside the residual evaluations are in SNESFunctionEval; the ones between
    # solves are not, so the bulk part is bounded below by subtracting them all (they are
    # ~1 % of it)
    bulk = max(ev["SNESFunctionEval"] + ev["SNESJacobianEval"] - residual - jacobian
               - search - build, 0.0)
    shares = {"search": search, "build_Q": build, "contact_residual": residual,
              "contact_jacobian": jacobian, "bulk_assembly": bulk, "lu_factorisation": lu,
              "triangular_solves": ev["MatSolve"]}
    shares["other"] = max(solve_time - sum(shares.values()), 0.0)
    values = model.surface_values()
    dim = scene.dim
    r = np.linalg.norm(values.x[:, :dim - 1], axis=1)
    a, p0 = scene.closed_form()
    # one pass: the law's pressure at the slave nodes; two passes: each law carries half, and
    # the pressure is the nodal contact force of both passes per tributary length (area)
    pressure = values.pressure if scene.passes == 1 else np.maximum(values.force[:, -1], 0.0)
    a_fit, p0_fit = closed_forms.fit_hertz_pressure(r, pressure)
    exact = closed_forms.hertz_pressure(r, a, p0)
    l2 = float(np.sqrt(np.sum(values.weight * (pressure - exact) ** 2)
                       / np.sum(values.weight * exact**2)))
    width = "half_width" if dim == 2 else "contact_radius"
    master_facets = sum(comm.allreduce(len(c.pairing.master_facets)) for c in model.contacts)
    return {
        "dim": dim, "refine": scene.refine, "passes": scene.passes, "dofs": summary["dofs"],
        "h_contact": summary["parameters"]["h_contact"], "a": a,
        "slave_nodes": comm.allreduce(len(model.contacts[0].pairing.slave_nodes)),
        "master_facets": master_facets,
        "contact_nodes": int(np.count_nonzero(pressure > 0)),
        "edge_error": summary[f"{width}_error"], "fit_width_error": a_fit / a - 1,
        "fit_peak_error": p0_fit / p0 - 1, "max_pressure_error": float(pressure.max()) / p0 - 1,
        "pressure_l2_error": l2,
        "newton_iterations": summary["newton_iterations"], "solves": solves,
        "searches": sum(c.pairing.searches for c in model.contacts),
        "pairing_changes": sum(c.pairing.changes for c in model.contacts),
        "solve_time_s": solve_time, "time_s": shares,
        "contact_over_lu": (search + build + residual + jacobian) / lu if lu else None,
    }


def run_mesh(dim: int, refine: int, repeats: int, comm: MPI.Comm, passes: int = 1) -> dict:
    """Mesh, model and solve ``repeats`` times (a fresh model each); the median timings."""
    attempts = []
    for _ in range(repeats):
        scene = Hertz(dim=dim, refine=refine, passes=passes)
        comm.Barrier()
        t0 = time.perf_counter()
        mesh = (geometry.hertz_2d if dim == 2 else geometry.hertz_3d)(comm, refine=refine)
        t1 = time.perf_counter()
        model = TwoBodyModel(mesh, scene.materials, scene.law, passes=passes,
                             fix_load_face=dim == 2)
        t2 = time.perf_counter()
        row = measure(scene, model, comm)
        row["mesh_time_s"] = comm.allreduce(t1 - t0, op=MPI.MAX)
        row["model_time_s"] = comm.allreduce(t2 - t1, op=MPI.MAX)
        attempts.append(row)
        print(f"  {dim}D refine {refine} ({passes} pass): {row['dofs']} dofs, solve "
              f"{row['solve_time_s']:.1f} s, {row['newton_iterations']} Newton iterations",
              file=sys.stderr, flush=True)
        del model, mesh
    row = min(attempts, key=lambda r: abs(r["solve_time_s"] - statistics.median(
        a["solve_time_s"] for a in attempts)))  # the median run, with its own shares
    row["repeats"] = repeats
    row["solve_times_s"] = [a["solve_time_s"] for a in attempts]
    return row


def strip_surfaces(comm: MPI.Comm, dim: int, n: int):
    """A strip (2D, n × 1 triangles' worth of facets along x) or plate (3D, n × n × 1 box of
    tetrahedra) whose top nodes are the slave nodes and bottom facets the master ones, and the
    displacement that lays the top onto the bottom, shifted by a third of an element."""
    from dolfinx import fem, mesh

    from fenicsfriction import _compat

    if dim == 2:
        msh = mesh.create_rectangle(comm, [np.array([0.0, 0.0]), np.array([1.0, 0.1])],
                                    [n, 1], mesh.CellType.triangle)
    else:
        msh = mesh.create_box(comm, [np.array([0.0, 0.0, 0.0]), np.array([1.0, 1.0, 0.1])],
                              [n, n, 1], mesh.CellType.tetrahedron)
    fdim = dim - 1
    bottom = mesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[dim - 1], 0.0))
    top = mesh.locate_entities_boundary(msh, fdim, lambda x: np.isclose(x[dim - 1], 0.1))
    facets = np.concatenate([bottom, top])
    order = np.argsort(facets)
    tags = mesh.meshtags(msh, fdim, facets[order].astype(np.int32),
                         np.concatenate([np.full(len(bottom), 2), np.full(len(top), 1)])
                         [order].astype(np.int32))
    V = _compat.vector_function_space(msh, 1)
    W = _compat.lagrange_vector_space(msh, 1, dim * dim)
    slave = np.unique(facet_nodes(V, tags, 1, outward=False))
    slave = slave[slave < V.dofmap.index_map.size_local]
    u = fem.Function(V)
    shift = np.zeros(dim)
    shift[:dim - 1] = 1.0 / (3 * n)
    shift[dim - 1] = -0.1 - 1e-4
    u.x.array.reshape(-1, dim)[slave] = shift
    return Pairing(V, W, slave, facet_nodes(V, tags, 2)), u


def search_scaling(comm: MPI.Comm, dim: int, sizes: tuple[int, ...]) -> dict:
    """Time of ``Pairing.search`` against the number of master facets, and the fitted
    exponent of time ∝ facets^α (first search with Q's build; repeated searches)."""
    rows = []
    for n in sizes:
        pairing, u = strip_surfaces(comm, dim, n)
        comm.Barrier()
        t0 = time.perf_counter()
        pairing.search(u)
        first = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
        times = []
        for _ in range(SEARCH_REPEATS):
            comm.Barrier()
            t0 = time.perf_counter()
            changed = pairing.search(u)
            times.append(comm.allreduce(time.perf_counter() - t0, op=MPI.MAX))
            assert not changed
        rows.append({"n": n, "master_facets": comm.allreduce(len(pairing.master_facets)),
                     "slave_nodes": comm.allreduce(len(pairing.slave_nodes)),
                     "first_search_s": first, "search_s": statistics.median(times)})
        print(f"  search {dim}D: {rows[-1]['master_facets']} facets, first "
              f"{first * 1e3:.1f} ms, again {rows[-1]['search_s'] * 1e3:.1f} ms",
              file=sys.stderr, flush=True)
    m = np.log([r["master_facets"] for r in rows])
    fit = lambda key: float(np.polyfit(m[1:], np.log([r[key] for r in rows[1:]]), 1)[0])  # noqa: E731
    return {"rows": rows, "exponent_first": fit("first_search_s"),
            "exponent_repeated": fit("search_s")}


def accuracy_table(runs: list[dict]) -> str:
    lines = ["| mesh | unknowns | h/a | edge (nodes) | fitted a | fitted p0 | peak nodal p "
             "| p L2 | Newton (solves) | solve [s] |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in runs:
        lines.append(
            f"| {r['dim']}D r{r['refine']}{' 2-pass' if r['passes'] == 2 else ''} "
            f"| {r['dofs']} | {r['h_contact'] / r['a']:.3f} | {r['edge_error']:+.2%} "
            f"| {r['fit_width_error']:+.2%} | {r['fit_peak_error']:+.2%} "
            f"| {r['max_pressure_error']:+.2%} | {r['pressure_l2_error']:.2%} "
            f"| {r['newton_iterations']} ({len(r['solves'])}: "
            f"{', '.join(str(s['newton_iterations']) for s in r['solves'])}) "
            f"| {r['solve_time_s']:.1f} |")
    return "\n".join(lines)


def share_table(runs: list[dict]) -> str:
    keys = ("search", "build_Q", "contact_residual", "contact_jacobian", "bulk_assembly",
            "lu_factorisation", "triangular_solves", "other")
    lines = ["| mesh | " + " | ".join(k.replace("_", " ") for k in keys)
             + " | contact / LU |", "|---" * (len(keys) + 2) + "|"]
    for r in runs:
        total = r["solve_time_s"]
        cells = " | ".join(f"{r['time_s'][k] / total:.1%}" for k in keys)
        lines.append(f"| {r['dim']}D r{r['refine']}{' 2-pass' if r['passes'] == 2 else ''} "
                     f"| {cells} | {r['contact_over_lu']:.3f} |")
    return "\n".join(lines)


def search_table(scaling: dict) -> str:
    lines = ["| dim | master facets | slave nodes | first search + Q [ms] | search again [ms] |",
             "|---|---|---|---|---|"]
    for dim, data in scaling.items():
        for r in data["rows"]:
            lines.append(f"| {dim}D | {r['master_facets']} | {r['slave_nodes']} "
                         f"| {r['first_search_s'] * 1e3:.1f} | {r['search_s'] * 1e3:.1f} |")
        lines.append(f"| {dim}D | fitted α (time ∝ facets^α) | | "
                     f"{data['exponent_first']:.2f} | {data['exponent_repeated']:.2f} |")
    return "\n".join(lines)


def plot(runs: list[dict], scaling: dict, path, dpi: int) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    ax = axes[0, 0]
    for dim, marker in ((2, "o"), (3, "s")):
        rows = [r for r in runs if r["dim"] == dim and r["passes"] == 1]
        if not rows:
            continue
        t = [r["solve_time_s"] for r in rows]
        for key, style, label in (("fit_width_error", "-", "fitted a"),
                                  ("fit_peak_error", "--", "fitted p0"),
                                  ("edge_error", ":", "edge (nodes)"),
                                  ("pressure_l2_error", "-.", "p L2")):
            ax.loglog(t, [abs(r[key]) for r in rows], style + marker, label=f"{dim}D {label}")
    ax.set(xlabel="solve wall time [s]", ylabel="|relative error| against Hertz",
           title="Accuracy against cost (refine 0, 1, 2 →)")
    ax.legend(fontsize=7, ncol=2)
    ax = axes[0, 1]
    for r in runs:
        ax.plot(range(1, len(r["solves"]) + 1), [s["newton_iterations"] for s in r["solves"]],
                "o-", label=f"{r['dim']}D r{r['refine']} ({r['passes']} pass)")
    ax.set(xlabel="solve (approach step)", ylabel="Newton iterations", title="Newton per solve")
    ax.legend(fontsize=7)
    ax = axes[1, 0]
    keys = ("search", "build_Q", "contact_residual", "contact_jacobian", "bulk_assembly",
            "lu_factorisation", "triangular_solves", "other")
    labels = [f"{r['dim']}D r{r['refine']}{' 2p' if r['passes'] == 2 else ''}" for r in runs]
    bottom = np.zeros(len(runs))
    for key in keys:
        share = np.array([r["time_s"][key] / r["solve_time_s"] for r in runs])
        ax.bar(labels, share, bottom=bottom, label=key.replace("_", " "))
        bottom += share
    ax.set(ylabel="share of the solve's wall time", title="Where the time goes")
    ax.legend(fontsize=7, loc="lower right")
    ax = axes[1, 1]
    for dim, data in scaling.items():
        m = [r["master_facets"] for r in data["rows"]]
        ax.loglog(m, [r["first_search_s"] for r in data["rows"]], "o-",
                  label=f"{dim}D first (+Q), α = {data['exponent_first']:.2f}")
        ax.loglog(m, [r["search_s"] for r in data["rows"]], "s--",
                  label=f"{dim}D again, α = {data['exponent_repeated']:.2f}")
    for r in runs:
        if r["searches"]:
            ax.loglog(r["master_facets"], (r["time_s"]["search"]) / r["searches"], "k^")
    ax.set(xlabel="master facets", ylabel="time per search [s]",
           title="Contact search (▲: Hertz scenes, per search)")
    ax.legend(fontsize=7)
    save(fig, path, dpi)


def main() -> int:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--refine-2d", default="0,1,2", help="2D refinement levels (0,1,2)")
    flags.add_argument("--refine-3d", default="0", help="3D refinement levels (0)")
    flags.add_argument("--repeats", type=int, default=3,
                       help=f"runs of each mesh below {SMALL} unknowns (median; 3)")
    flags.add_argument("--dpi", type=int, default=110)
    args = flags.parse_args()
    comm = MPI.COMM_WORLD
    logging.getLogger("ffcx").setLevel(logging.WARNING)
    PETSc.Log.begin()
    levels = {2: [int(v) for v in args.refine_2d.split(",") if v],
              3: [int(v) for v in args.refine_3d.split(",") if v]}
    runs = []
    for dim, refines in levels.items():
        for refine in refines:
            # a probe of the size: the coarse meshes are repeated, the fine ones run once
            repeats = args.repeats if (dim == 2 and refine == 0) or (dim == 3 and refine == 0) \
                else 1
            runs.append(run_mesh(dim, refine, repeats, comm))
    if levels[2] and levels[2][0] == 0:
        runs.append(run_mesh(2, 0, args.repeats, comm, passes=2))
    scaling = {dim: search_scaling(comm, dim, SEARCH_SIZES[dim]) for dim in (2, 3)}
    one = next((r for r in runs if r["dim"] == 2 and r["refine"] == 0 and r["passes"] == 1),
               None)
    two = next((r for r in runs if r["passes"] == 2), None)
    baseline = None if one is None or two is None else two["solve_time_s"] / one["solve_time_s"]
    if comm.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        print(f"Accuracy and cost ({comm.size} rank{'s' if comm.size > 1 else ''}):\n\n"
              f"{accuracy_table(runs)}\n\nShares of the solve's wall time:\n\n"
              f"{share_table(runs)}\n\nContact search alone:\n\n{search_table(scaling)}\n")
        if baseline is not None:
            print(f"two-pass / one-pass solve time (2D r0): {baseline:.2f}")
        plot(runs, scaling, args.out / "bench_contact.png", args.dpi)
    write_summary(args.out / "bench_contact.json",
                             {"ranks": comm.size, "runs": runs, "search_scaling": scaling,
                              "two_pass_over_one_pass": baseline}, comm=comm)
    if comm.rank == 0:
        print(f"wrote {args.out / 'bench_contact.json'} and {args.out / 'bench_contact.png'}",
              file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
