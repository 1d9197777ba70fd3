"""Speed against error of two-body contact: node-to-segment against mortar on Hertz, 2D and 3D.

The Hertz scenes (:class:`~fenicsfriction.studies.contact.validation.Hertz`: a cylinder on a
block in plane strain, a quarter sphere on a block; a = R/10) are solved with node-to-segment
contact (degree 1) and with mortar contact (degree 1 and 2) on a ladder of meshes, the element
size at the contact h = a/5, a/10, a/20, a/40 in 2D (``--ladder-2d``) and a/5, a/10 in 3D
(``--ladder-3d``), set by the scene's ``h_contact`` (the far field, graded from it, is the
same on every rung). Degree 2 in 3D runs at h = a/5 only by default (``--degree2-3d``): its
surface node spacing is then that of degree 1 at a/10, and at a/10 it would have eight times
the 100 000 unknowns of degree 1 there; even at a/5 (about 140 000 unknowns) it is the longest
run (``--degree2-3d ""`` leaves it out; ``--configs mortar:2`` runs it alone).

For each run it records:

* the error against Hertz (Hertz 1882; Johnson 1985, eqs. 4.22-4.23 and 4.43-4.45) of the
  half-width (2D) or contact radius (3D) where the interpolated nodal gap changes sign (2D: the
  scene's ``half_width``; 3D: its ``gap_crossing_radius``; node-to-segment: the gap of each
  slave node; mortar: the mortar-weighted gap, an average over the node's support), and the
  half-width of the Hertz ellipse fitted through the nodal pressures; the peak pressure, fitted
  and the largest nodal one; the relative L2 error of the nodal pressures against p0
  sqrt(1 - r²/a²), with the nodal rule's weights;
* the nodal pressure is the *transmitted* one: each slave node's contact force over its load
  weight (the integral of its shape function over the slave surface,
  :class:`~fenicsfriction.studies.contact.model.SurfaceValues`), for both formulations. For
  node-to-segment it is the law's pressure at the node. For mortar it is the lumped value of
  the traction field sum_j p_j psi_j, while the law's nodal value p_j (the pressure of the
  node's mortar-weighted penetration) overshoots at the last node in contact, whose support
  the edge crosses; the errors of p_j are recorded too (``law_*``). Degree 2 in 3D: the
  6-node triangles' vertices have load weight 0 (their force vanishes under any smooth
  pressure) and are left out; the midside nodes carry the pressure;
* unknowns, wall times of the mesh (gmsh), the model (forms and their JIT from a warm cache)
  and the solve (the approach found by secant steps until the contact force is the load to
  1e-5, with the contact search repeated until it holds), Newton iterations and searches;
  within the solve the contact search (and building its pairing operator), the contact
  residual and Jacobian, and the LU factorisations and triangular solves (PETSc's log);
* the solve's CPU time (the process's), steadier than its wall time where the cores are shared;
* the linear solver (the KSP, PC and factorisation package) and the peak resident memory of
  the process so far (the rungs run from small to large within each dimension);
* same-run ratios: mortar's solve time over node-to-segment's on the same mesh (degree 1;
  degree 2, whose mesh is the same and whose unknowns are about four (2D) or seven (3D) times
  as many).

Writes ``bench_hertz_formulations.json`` and ``.png`` (error against solve time, log-log, both
formulations, 2D and 3D panels; error against unknowns) to ``--out``, prints markdown tables to
stdout, progress to stderr. ``--dims 2 --levels 2`` takes about a minute; the 2D ladder about
15 minutes and the 3D rungs of degree 1 about half an hour on one core, most of it at a/10
(about 100 000 unknowns each). ``--merge`` tabulates and plots the JSON of separate runs
together.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import pathlib
import resource
import statistics
import sys
import time

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction.steady import DEFAULT_OPTIONS, SolveError
from fenicsfriction.studies.contact import closed_forms, geometry
from fenicsfriction.studies.contact.model import SurfaceValues, TwoBodyModel
from fenicsfriction.studies.contact.validation import Hertz

#: (formulation, degree) compared
CONFIGS = (("node-to-segment", 1), ("mortar", 1), ("mortar", 2))
EVENTS = ("MatLUFactorSym", "MatLUFactorNum", "MatSolve")
LINE_SEARCH = "contact_snes_linesearch_type"  # TwoBodyModel's solver prefix is contact_
SMALL = 15_000  # unknowns: meshes up to this size are run --repeats times

log = logging.getLogger("bench_hertz_formulations")


def event_times(comm: MPI.Comm) -> dict[str, float]:
    """Cumulative time of each PETSc event in :data:`EVENTS` (max over the ranks)."""
    return {name: comm.allreduce(PETSc.Log.Event(name).getPerfInfo()["time"], op=MPI.MAX)
            for name in EVENTS}


def peak_memory_mb(comm: MPI.Comm) -> float:
    """The peak resident memory of the process so far (max over ranks) [MiB]."""
    return comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, op=MPI.MAX)


def pressure_errors(r: np.ndarray, pressure: np.ndarray, weight: np.ndarray, a: float,
                    p0: float) -> dict[str, float]:
    """Errors of nodal pressures at distances ``r`` against Hertz's profile: the fitted
    ellipse's half-width and peak, the largest nodal pressure, and the L2 norm of the
    difference with the nodal ``weight`` (relative to Hertz's)."""
    a_fit, p0_fit = closed_forms.fit_hertz_pressure(r, pressure)
    exact = closed_forms.hertz_pressure(r, a, p0)
    l2 = float(np.sqrt(np.sum(weight * (pressure - exact) ** 2) / np.sum(weight * exact**2)))
    return {"fit_width_error": a_fit / a - 1, "fit_peak_error": p0_fit / p0 - 1,
            "max_pressure_error": float(pressure.max()) / p0 - 1, "pressure_l2_error": l2}


def accuracy(scene: Hertz, values: SurfaceValues) -> dict[str, float]:
    """The transmitted pressure's errors (force over load weight at the nodes that carry
    load) and the law's nodal pressure's (``law_`` keys)."""
    dim = scene.dim
    r = np.linalg.norm(values.x[:, :dim - 1], axis=1)
    a, p0 = scene.closed_form()
    loaded = values.load_weight > 0
    transmitted = np.maximum(values.force[loaded, -1], 0.0)
    errors = pressure_errors(r[loaded], transmitted, values.load_weight[loaded], a, p0)
    law = pressure_errors(r, values.pressure, values.weight, a, p0)
    errors.update({f"law_{key}": value for key, value in law.items()})
    errors["contact_nodes"] = int(np.count_nonzero(transmitted > 0))
    return errors


def run_once(dim: int, a_over_h: int, formulation: str, degree: int, comm: MPI.Comm,
             c_n: float | None) -> dict:
    """Mesh, build and solve one scene; its accuracy and where its time went."""
    scene = Hertz(dim=dim, formulation=formulation, degree=degree)
    a, p0 = scene.closed_form()
    scene = dataclasses.replace(scene, h_contact=a / a_over_h)
    if c_n is not None:
        scene = scene.with_law(c_n=c_n)
    comm.Barrier()
    t0 = time.perf_counter()
    mesh = (geometry.hertz_2d if dim == 2 else geometry.hertz_3d)(
        comm, R=scene.radius, h_contact=scene.h_contact)
    t1 = time.perf_counter()
    model: TwoBodyModel = scene.model(mesh, fix_load_face=dim == 2)
    solver = model.solver  # compiles the forms
    t2 = time.perf_counter()
    before = event_times(comm)
    comm.Barrier()
    t3, cpu = time.perf_counter(), time.process_time()
    summary, _ = scene.run(comm, model)
    solve_time = comm.allreduce(time.perf_counter() - t3, op=MPI.MAX)
    # the process's own CPU time: on shared cores a steadier measure of cost than wall time
    solve_cpu = comm.allreduce(time.process_time() - cpu, op=MPI.MAX)
    after = event_times(comm)
    mx = lambda value: comm.allreduce(value, op=MPI.MAX)  # noqa: E731
    pairings = [c.pairing for c in model.contacts]
    values = model.surface_values()
    # the edge where the nodal gaps change sign (3D: not the scene's contact_radius, the
    # radius of the nodal rule's contact area)
    edge = "half_width_error" if dim == 2 else "gap_crossing_radius_error"
    ksp = solver.snes.getKSP()
    pc = ksp.getPC()
    row = {
        "dim": dim, "formulation": formulation, "degree": degree, "a_over_h": a_over_h,
        "h_contact": scene.h_contact, "a": a, "p0": p0, "c_n": float(scene.law.c_n),
        "dofs": summary["dofs"], "edge_error": summary[edge],
        **accuracy(scene, values),
        "newton_iterations": summary["newton_iterations"], "solves": summary["solves"],
        "mesh_time_s": mx(t1 - t0), "model_time_s": mx(t2 - t1), "solve_time_s": solve_time,
        "solve_cpu_s": solve_cpu,
        "time_s": {
            "search": mx(sum(p.time_s["search"] + p.time_s["build"] for p in pairings)),
            "contact_residual": mx(sum(op.time_s["residual"] for op in solver.couplings)),
            "contact_jacobian": mx(sum(op.time_s["jacobian"] for op in solver.couplings)),
            "lu_factorisation": (after["MatLUFactorSym"] - before["MatLUFactorSym"]
                                 + after["MatLUFactorNum"] - before["MatLUFactorNum"]),
            "triangular_solves": after["MatSolve"] - before["MatSolve"]},
        "searches": sum(p.searches for p in pairings),
        "linear_solver": {"path": solver.linear_solver, "ksp": ksp.getType(),
                          "pc": pc.getType(), "factor": pc.getFactorSolverType(),
                          "line_search": PETSc.Options().getString(
                              LINE_SEARCH, DEFAULT_OPTIONS["snes_linesearch_type"])},
    }
    del model, mesh
    row["peak_memory_mb"] = peak_memory_mb(comm)
    return row


def run_mesh(dim: int, a_over_h: int, formulation: str, degree: int, repeats: int,
             comm: MPI.Comm, c_n: float | None) -> dict:
    """``run_once`` once, and again up to ``repeats`` times where the mesh is small; the
    median run by solve time, with the times of all."""
    failed = None
    try:
        attempts = [run_once(dim, a_over_h, formulation, degree, comm, c_n)]
    except (SolveError, RuntimeError) as error:
        # the backtracking line search can stall at a kink of the piecewise-linear contact
        # residual (frozen geometry, (d)+): full Newton steps, an active-set iteration
        failed = str(error)
        print(f"  {dim}D h = a/{a_over_h} {formulation} P{degree}: {failed}; again with "
              "full Newton steps", file=sys.stderr, flush=True)
        options = PETSc.Options()
        options[LINE_SEARCH] = "basic"
        try:
            attempts = [run_once(dim, a_over_h, formulation, degree, comm, c_n)]
        except (SolveError, RuntimeError) as error:  # recorded, and the ladder goes on
            return {"dim": dim, "formulation": formulation, "degree": degree,
                    "a_over_h": a_over_h, "failed": f"{failed}; basic: {error}"}
        finally:
            options.delValue(LINE_SEARCH)
    if attempts[0]["dofs"] <= SMALL and failed is None:
        attempts += [run_once(dim, a_over_h, formulation, degree, comm, c_n)
                     for _ in range(repeats - 1)]
    median = statistics.median(r["solve_time_s"] for r in attempts)
    row = min(attempts, key=lambda r: abs(r["solve_time_s"] - median))
    row["solve_times_s"] = [r["solve_time_s"] for r in attempts]
    row["default_line_search_failed"] = failed
    print(f"  {dim}D h = a/{a_over_h} {label(row)}: {row['dofs']} unknowns, solve "
          f"{row['solve_time_s']:.1f} s, {row['newton_iterations']} Newton iterations, "
          f"p0 {row['fit_peak_error']:+.2%}, a {row['fit_width_error']:+.2%}",
          file=sys.stderr, flush=True)
    return row


def label(row: dict) -> str:
    return ("NTS" if row["formulation"] == "node-to-segment" else "mortar") + f" P{row['degree']}"


def ratios(runs: list[dict]) -> list[dict]:
    """Mortar's solve time over node-to-segment's on the same mesh (same dim and h)."""
    out = []
    for r in runs:
        if r["formulation"] != "mortar":
            continue
        base = next((b for b in runs if b["formulation"] == "node-to-segment"
                     and b["dim"] == r["dim"] and b["a_over_h"] == r["a_over_h"]), None)
        if base is not None:
            out.append({"dim": r["dim"], "a_over_h": r["a_over_h"], "degree": r["degree"],
                        "solve_ratio": r["solve_time_s"] / base["solve_time_s"],
                        "dofs_ratio": r["dofs"] / base["dofs"],
                        "newton_ratio": r["newton_iterations"] / base["newton_iterations"]})
    return out


def accuracy_table(runs: list[dict]) -> str:
    lines = ["| scene | contact | h | unknowns | edge (gap) | fitted a | fitted p0 | peak p "
             "| p L2 | Newton (searches) | mesh [s] | model [s] | solve [s] | search [s] "
             "| residual [s] | Jacobian [s] | LU [s] | memory [MiB] |",
             "|---" * 18 + "|"]
    for r in runs:
        t = r["time_s"]
        lines.append(
            f"| {r['dim']}D | {label(r)} | a/{r['a_over_h']} | {r['dofs']} "
            f"| {r['edge_error']:+.1%} | {r['fit_width_error']:+.1%} "
            f"| {r['fit_peak_error']:+.1%} | {r['max_pressure_error']:+.1%} "
            f"| {r['pressure_l2_error']:.1%} | {r['newton_iterations']}"
            f"{'*' if r['default_line_search_failed'] else ''} "
            f"({r['searches']}) | {r['mesh_time_s']:.1f} | {r['model_time_s']:.1f} "
            f"| {r['solve_time_s']:.1f} | {t['search']:.1f} | {t['contact_residual']:.1f} "
            f"| {t['contact_jacobian']:.1f} | {t['lu_factorisation']:.1f} "
            f"| {r['peak_memory_mb']:.0f} |")
    if any(r["default_line_search_failed"] for r in runs):
        lines.append("\n\\* the backtracking line search stalled; solved with full Newton steps")
    return "\n".join(lines)


def law_table(runs: list[dict]) -> str:
    lines = ["| scene | contact | h | fitted a | fitted p0 | peak p | p L2 |", "|---" * 7 + "|"]
    for r in runs:
        if r["formulation"] == "mortar":
            lines.append(f"| {r['dim']}D | {label(r)} | a/{r['a_over_h']} "
                         f"| {r['law_fit_width_error']:+.1%} | {r['law_fit_peak_error']:+.1%} "
                         f"| {r['law_max_pressure_error']:+.1%} "
                         f"| {r['law_pressure_l2_error']:.1%} |")
    return "\n".join(lines)


def ratio_table(rows: list[dict]) -> str:
    lines = ["| scene | h | mortar degree | solve time ÷ NTS | unknowns ÷ NTS | Newton ÷ NTS |",
             "|---" * 6 + "|"]
    for r in rows:
        lines.append(f"| {r['dim']}D | a/{r['a_over_h']} | {r['degree']} "
                     f"| {r['solve_ratio']:.2f} | {r['dofs_ratio']:.2f} "
                     f"| {r['newton_ratio']:.2f} |")
    return "\n".join(lines)


def plot(runs: list[dict], path, dpi: int) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    dims = sorted({r["dim"] for r in runs})
    fig, axes = plt.subplots(2, len(dims), figsize=(5.5 * len(dims), 8), squeeze=False)
    colours = {("node-to-segment", 1): "C0", ("mortar", 1): "C1", ("mortar", 2): "C2"}
    for column, dim in enumerate(dims):
        for row, (x_key, x_label) in enumerate((("solve_time_s", "solve wall time [s]"),
                                                ("dofs", "unknowns"))):
            ax = axes[row, column]
            for config in CONFIGS:
                rows = sorted((r for r in runs if r["dim"] == dim
                               and (r["formulation"], r["degree"]) == config),
                              key=lambda r: r["dofs"])
                if not rows:
                    continue
                x = [r[x_key] for r in rows]
                name = label(rows[0])
                for key, style in (("fit_peak_error", "o-"), ("fit_width_error", "s--"),
                                   ("pressure_l2_error", "^:")):
                    short = {"fit_peak_error": "p0", "fit_width_error": "a",
                             "pressure_l2_error": "p L2"}[key]
                    ax.loglog(x, [max(abs(r[key]), 1e-4) for r in rows], style,
                              color=colours[config], label=f"{name} {short}")
            ax.axhline(0.03, color="0.6", lw=0.8, label="3 %")
            ax.set(xlabel=x_label, ylabel="|relative error| against Hertz",
                   title=f"Hertz {dim}D: error against {x_label.split(' [')[0]}")
            ax.legend(fontsize=6, ncol=3)
    save(fig, path, dpi)


def main() -> int:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--dims", default="2,3", help="scenes to run: 2, 3 or 2,3 (2,3)")
    flags.add_argument("--ladder-2d", default="5,10,20,40",
                       help="2D rungs, a/h (5,10,20,40)")
    flags.add_argument("--ladder-3d", default="5,10", help="3D rungs, a/h (5,10)")
    flags.add_argument("--levels", type=int, default=None,
                       help="only the first LEVELS rungs of each ladder (all)")
    flags.add_argument("--degree2-2d", default="5,10,20",
                       help="2D rungs (a/h) where mortar degree 2 runs (5,10,20)")
    flags.add_argument("--degree2-3d", default="5",
                       help="3D rungs (a/h) where mortar degree 2 runs (5)")
    flags.add_argument("--configs", default="node-to-segment:1,mortar:1,mortar:2",
                       help="formulation:degree pairs to run (all three)")
    flags.add_argument("--c-n", type=float, default=None,
                       help="the compliance c_n of every run (the scene's default, 1e4)")
    flags.add_argument("--repeats", type=int, default=3,
                       help=f"runs of each mesh up to {SMALL} unknowns (median; 3)")
    flags.add_argument("--merge", type=pathlib.Path, nargs="*", default=[],
                       help="JSON files of earlier runs to tabulate and plot with this one's "
                            "(e.g. --dims '' --merge 2d/*.json 3d/*.json: no new run)")
    flags.add_argument("--dpi", type=int, default=110)
    args = flags.parse_args()
    comm = MPI.COMM_WORLD
    logging.getLogger("ffcx").setLevel(logging.WARNING)
    PETSc.Log.begin()
    numbers = lambda text: [int(v) for v in text.split(",") if v]  # noqa: E731
    ladders = {2: numbers(args.ladder_2d), 3: numbers(args.ladder_3d)}
    degree2 = {2: numbers(args.degree2_2d), 3: numbers(args.degree2_3d)}
    configs = [(name, int(degree)) for name, degree in
               (pair.split(":") for pair in args.configs.split(",") if pair)]
    runs: list[dict] = []
    failures: list[dict] = []
    for path in args.merge:  # earlier runs' results, tabulated with this run's
        earlier = json.loads(path.read_text())
        runs += earlier["runs"]
        failures += earlier["failures"]
    json_path = args.out / "bench_hertz_formulations.json"
    for dim in numbers(args.dims):
        for a_over_h in ladders[dim][:args.levels]:
            for formulation, degree in configs:
                if degree == 2 and a_over_h not in degree2[dim]:
                    continue
                row = run_mesh(dim, a_over_h, formulation, degree, args.repeats, comm,
                               args.c_n)
                (failures if "failed" in row else runs).append(row)
                # written after every run: a long ladder stopped keeps what it measured
                write_summary(json_path, {"ranks": comm.size, "runs": runs,
                                                     "failures": failures}, comm=comm)
    same_mesh = ratios(runs)
    if comm.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        print(f"Accuracy (transmitted nodal pressure) and cost ({comm.size} "
              f"rank{'s' if comm.size > 1 else ''}):\n\n{accuracy_table(runs)}\n\n"
              f"Mortar, the law's nodal pressure p_j instead:\n\n{law_table(runs)}\n\n"
              f"Same-mesh ratios:\n\n{ratio_table(same_mesh)}\n")
        for row in failures:
            print(f"failed: {row['dim']}D h = a/{row['a_over_h']} {row['formulation']} "
                  f"P{row['degree']}: {row['failed']}")
        plot(runs, args.out / "bench_hertz_formulations.png", args.dpi)
    write_summary(json_path,
                             {"ranks": comm.size, "runs": runs, "failures": failures,
                              "same_mesh_ratios": same_mesh},
                             comm=comm)
    if comm.rank == 0:
        print(f"wrote {json_path} and "
              f"{args.out / 'bench_hertz_formulations.png'}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
