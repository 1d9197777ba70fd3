"""Speed against accuracy of the steady-sliding continuation on refined block meshes.

The block on a moving belt of Martins & Oden (1986) is followed in μ from 0 to 1.5 in 30
steps, Newton at each step (:func:`fenicsfriction.continuation`), on the 4r × 3r nine-node
mesh for each refinement factor r (default 1, 2, 4, 8). For every mesh it records:

* the cold JIT time of the residual and its Jacobian (a fresh FFCx cache directory per mesh),
  apart from the solve time (the sum of the continuation's per-step wall times, best of 3
  runs of the whole continuation);
* Newton iterations per μ step;
* the same continuation by the LU-per-iteration path (``linear_solver="lu"``, sparse LU at every
  Newton iteration, each step started from the last state: the package's solver before the
  bulk was condensed onto the interface and the secant predictor added), timed in the same
  run; *speed-up* is its time over the default solver's;
* a same-run baseline: one *bare Newton iteration* on that mesh — assemble R and dR/du, one
  MUMPS LU factorisation and solve, by hand, best of a few — so that
  ``solve / (iterations × bare)`` is the overhead of SNES, line search and continuation over
  the cost of a Newton iteration by sparse LU, a ratio that does not depend on the machine's
  speed (below 1 when the condensed solver makes an iteration cheaper than one LU);
* discretisation errors against the finest mesh at μ = 0.3, 0.9, 1.5: the penetration
  d = (-u_y)_+ along the base y = 0 at 513 common points (max norm and L2 norm, relative to
  the finest mesh's; the max norm also away from the corners, x in [L/8, 7L/8]), the maximum
  penetration, and the spring force. Statics makes the spring force (and so the spring's
  elongation) μW on every mesh, so its error only shows equilibrium; the penetration carries
  the discretisation error.

Writes ``bench_steady.json`` and ``bench_steady.png`` to ``--out`` and prints two markdown
tables to stdout (progress goes to stderr). Rank 0 writes and prints; run serially or with
``mpirun -n 2``.
"""

from __future__ import annotations

import itertools
import logging
import pathlib
import shutil
import tempfile
import time

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
from _common import note_solver, save, write_summary
from _common import parser as benchmark_parser

import fenicsfriction as ff
from fenicsfriction import _compat
from fenicsfriction.assembly import assemble_jacobian, assemble_residual

MU_STEPS = np.linspace(0.0, 1.5, 31)
MU_SAMPLES = (0.3, 0.9, 1.5)
NUM_BASE_POINTS = 513  # includes every base node of the 32 × 24 Q2 mesh (L/64 apart)
CORNER_MARGIN = 1 / 8  # "away from the corners": x in [L/8, 7L/8] (nodes of every mesh)
CONTINUATION_REPEATS = 3  # timings are the best of several runs: noise only adds time
BARE_REPEATS = 5


class BaseProbe:
    """u_y at fixed points of the base y = 0, gathered on rank 0 (``None`` elsewhere)."""

    def __init__(self, model: ff.studies.block.BlockModel, num_points: int):
        msh = model.msh
        self.comm = msh.comm
        self.num_points = num_points
        points = np.zeros((num_points, 3))
        points[:, 0] = np.linspace(0.0, model.scene.L, num_points)
        colliding = _compat.colliding_cells(msh, points)
        self.found = np.array([i for i in range(num_points) if len(colliding.links(i))],
                              dtype=np.int32)
        self.cells = np.array([colliding.links(i)[0] for i in self.found], dtype=np.int32)
        self.points = points[self.found]

    def __call__(self, u) -> np.ndarray | None:
        values = u.eval(self.points, self.cells)[:, 1] if len(self.found) else np.empty(0)
        gathered = self.comm.gather((self.found, values), root=0)
        if self.comm.rank != 0:
            return None
        uy = np.full(self.num_points, np.nan)
        for found, v in gathered:  # a point on a partition boundary is found twice: same value
            uy[found] = v
        if np.isnan(uy).any():
            raise RuntimeError("some base points lie in no cell of the mesh")
        return uy


def bare_newton_iteration(solver: ff.SteadySolver, repeats: int) -> float:
    """Best wall time of: assemble R and dR/du at the current u, MUMPS LU factorise and solve.

    The first pass also does MUMPS's symbolic analysis, which SNES does once per continuation;
    it is left out, as it is from every SNES iteration but the first.
    """
    comm = solver.u.function_space.mesh.comm
    ksp = PETSc.KSP().create(comm)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("lu")
    pc.setFactorSolverType("mumps")
    ksp.setOperators(solver.A)
    b, dx = solver.b.duplicate(), solver.x.duplicate()  # ghosted, as assembly needs
    x = _compat.petsc_vec(solver.u)
    R = solver.residual
    times = []
    for _ in range(repeats + 1):
        comm.Barrier()
        t0 = time.perf_counter()
        assemble_residual(b, solver.L, solver.a, R.bcs, x, R.springs)
        assemble_jacobian(solver.A, solver.a, R.bcs, R.springs)
        ksp.solve(b, dx)
        times.append(comm.allreduce(time.perf_counter() - t0, op=MPI.MAX))
    for obj in (ksp, b, dx):
        obj.destroy()
    return min(times[1:])


def run_mesh(refine: int, comm: MPI.Comm) -> dict:
    """The continuation on the 4r × 3r mesh: timings, Newton counts, sampled base profiles."""
    model = ff.BlockOnBelt(refine=refine).build(comm, with_friction=True)
    model.initial_guess()
    probe = BaseProbe(model, NUM_BASE_POINTS)
    cache = comm.bcast(tempfile.mkdtemp(prefix="ffcx-bench-") if comm.rank == 0 else None)
    solver = ff.SteadySolver(model.residual, prefix=f"b{refine}_",
                             options=model.solver_options(), jit_cache_dir=cache)
    samples: dict[float, dict] = {}

    def observe() -> dict:
        q = model.quantities().to_json()
        uy = probe(model.residual.u)  # collective: every rank calls it at the same μ
        for mu in MU_SAMPLES:
            if np.isclose(q["mu"], mu):
                samples[mu] = {**q, "penetration": None if uy is None
                               else np.maximum(-uy - model.scene.law.g, 0.0)}
        return q

    # the baseline in the same run: a sparse LU at every Newton iteration, each step started
    # from the last state (the package's solver before the condensation and the predictor)
    direct = ff.SteadySolver(model.residual, prefix=f"d{refine}_",
                             options={**model.solver_options(), "ksp_type": "preonly",
                                      "pc_type": "lu"}, jit_cache_dir=cache, linear_solver="lu")

    def best_of(run_solver: ff.SteadySolver, predictor: str, repeats: int) -> tuple:
        attempts = []
        for _ in range(repeats):  # the same continuation from the same start
            model.mu.value = MU_STEPS[0]
            model.initial_guess()
            comm.Barrier()
            records = ff.continuation(run_solver, model.mu, MU_STEPS, observe=observe,
                                      predictor=predictor)
            total = comm.allreduce(sum(r["wall_time_s"] for r in records), op=MPI.MAX)
            attempts.append((total, records))
        return min(attempts, key=lambda attempt: attempt[0])

    repeats = CONTINUATION_REPEATS if refine <= 16 else 1
    direct_time, direct_records = best_of(direct, "none", repeats)
    solve_time, records = best_of(solver, "secant", repeats)  # the samples kept are these
    bare = bare_newton_iteration(solver, BARE_REPEATS)
    note_solver(solver)
    note_solver(direct)
    comm.Barrier()
    if comm.rank == 0:
        shutil.rmtree(cache, ignore_errors=True)
    iterations = np.array([r["newton_iterations"] for r in records])
    return {"refine": refine, "mesh": f"{4 * refine} × {3 * refine}",
            "dofs": model.V.dofmap.index_map.size_global * model.V.dofmap.index_map_bs,
            "jit_time_s": comm.allreduce(solver.jit_time_s, op=MPI.MAX),
            "solve_time_s": solve_time,
            "linear_solver": solver.linear_solver,
            "interface_dofs": None if solver.condensation is None else solver.condensation.size,
            "direct_solve_time_s": direct_time,
            "direct_newton_iterations_total": int(sum(r["newton_iterations"]
                                                      for r in direct_records)),
            "speedup_over_direct": direct_time / solve_time,
            "bare_newton_iteration_s": bare,
            "newton_iterations_total": int(iterations.sum()),
            "newton_iterations_mean": float(iterations.mean()),
            "newton_iterations_max": int(iterations.max()),
            "halvings_total": int(sum(r["halvings"] for r in records)),
            "steps": [{k: r[k] for k in ("value", "newton_iterations", "halvings",
                                         "wall_time_s", "max_penetration", "spring_force")}
                      for r in records],
            "samples": samples}


def relative_errors(runs: list[dict]) -> None:
    """Add errors against the last (finest) run and observed rates to each run, in place.

    Rates are log(e_coarse / e_fine) / log(h_coarse / h_fine) between successive meshes; the
    last one is biased upwards because the reference is only one refinement finer.
    """
    reference = runs[-1]["samples"]
    s_base = np.linspace(0.0, 1.0, NUM_BASE_POINTS)
    inner = (s_base >= CORNER_MARGIN) & (s_base <= 1 - CORNER_MARGIN)
    for run in runs:
        run["errors"] = {}
        for mu in MU_SAMPLES:
            s, ref = run["samples"][mu], reference[mu]
            diff, d_ref = s["penetration"] - ref["penetration"], ref["penetration"]
            scale = np.abs(d_ref).max()
            run["errors"][mu] = {
                "penetration_max": np.abs(diff).max() / scale,
                "penetration_max_inner": np.abs(diff[inner]).max() / scale,
                "penetration_l2": np.linalg.norm(diff) / np.linalg.norm(d_ref),
                "max_penetration": abs(s["max_penetration"] / ref["max_penetration"] - 1),
                "spring_force": abs(s["spring_force"] / ref["spring_force"] - 1)}
    for coarse, fine in itertools.pairwise(runs[:-1]):  # the finest has no error
        ratio = fine["refine"] / coarse["refine"]
        fine["rates"] = {mu: {key: float(np.log(coarse["errors"][mu][key] / value)
                                         / np.log(ratio))
                              for key, value in fine["errors"][mu].items()
                              if key != "spring_force"} for mu in MU_SAMPLES}


def speed_table(runs: list[dict]) -> str:
    """Markdown table of cost per mesh."""
    lines = [(f"| mesh | dofs | JIT, cold [s] | solve [s] | solve ÷ solve on {runs[0]['mesh']} "
              "| Newton it./step, mean (max) | bare Newton it. [ms] | solve ÷ (it. × bare) "
              "| LU-per-iteration path [s] (Newton it.) | speed-up |"),
             "|---|---|---|---|---|---|---|---|---|---|"]
    for run in runs:
        overhead = run["solve_time_s"] / (run["newton_iterations_total"]
                                          * run["bare_newton_iteration_s"])
        lines.append(
            f"| {run['mesh']} | {run['dofs']} | {run['jit_time_s']:.2f} "
            f"| {run['solve_time_s']:.2f} | {run['solve_time_s'] / runs[0]['solve_time_s']:.1f} "
            f"| {run['newton_iterations_mean']:.2f} ({run['newton_iterations_max']}) "
            f"| {1e3 * run['bare_newton_iteration_s']:.2f} | {overhead:.2f} "
            f"| {run['direct_solve_time_s']:.2f} ({run['direct_newton_iterations_total']}) "
            f"| {run['speedup_over_direct']:.1f} |")
    return "\n".join(lines)


def accuracy_table(runs: list[dict]) -> str:
    """Markdown table of relative errors against the finest mesh (observed rates in brackets)."""
    keys = ("penetration_max", "penetration_max_inner", "penetration_l2")
    lines = [("| μ | mesh | d on the base, max norm | d on [L/8, 7L/8], max norm "
              "| d on the base, L2 | spring force |"),
             "|---|---|---|---|---|---|"]
    for mu in MU_SAMPLES:
        for run in runs[:-1]:
            cells = [f"{run['errors'][mu][key]:.1e}"
                     + (f" ({run['rates'][mu][key]:.1f})" if "rates" in run else "")
                     for key in keys]
            cells.append(f"{run['errors'][mu]['spring_force']:.0e}")
            lines.append(f"| {mu} | {run['mesh']} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def plot(runs: list[dict], path: pathlib.Path) -> None:
    """Error against wall time per mesh (left) and Newton iterations per μ step (right)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    fig, (ax_err, ax_newton) = plt.subplots(1, 2, figsize=(13, 5.2))
    coarse = runs[:-1]
    colours = dict(zip(MU_SAMPLES, ("tab:blue", "tab:orange", "tab:green"), strict=True))
    norms = (("penetration_max", "o-", "max norm, whole base"),
             ("penetration_max_inner", "s:", "max norm, x in [L/8, 7L/8]"),
             ("penetration_l2", "^--", "L2, whole base"))
    for mu, colour in colours.items():
        # wall time to reach μ: the continuation's steps up to and including it
        times = [sum(s["wall_time_s"] for s in run["steps"] if s["value"] <= mu + 1e-12)
                 for run in coarse]
        for key, style, _ in norms:
            ax_err.loglog(times, [run["errors"][mu][key] for run in coarse], style,
                          color=colour)
        for t, run in zip(times, coarse, strict=True):
            ax_err.annotate(run["mesh"], (t, run["errors"][mu]["penetration_max"]),
                            textcoords="offset points", xytext=(4, 4), fontsize=8, color=colour)
    ax_err.add_artist(ax_err.legend(
        handles=[Line2D([], [], color=c, lw=3, label=f"μ = {mu}") for mu, c in colours.items()],
        loc="upper left", fontsize=8))
    ax_err.legend(handles=[Line2D([], [], color="0.3", marker=st[0], ls=st[1:], label=name)
                           for _, st, name in norms], loc="upper right", fontsize=8)
    bottom, top = ax_err.get_ylim()
    ax_err.set_ylim(bottom, top * 20)  # room for the legends above the data
    ax_err.set_xlabel("wall time of the continuation from μ = 0 to μ [s] (JIT excluded)")
    ax_err.set_ylabel(f"relative error of the penetration d(x) on y = 0\n"
                      f"against the {runs[-1]['mesh']} mesh")
    ax_err.set_title("Accuracy against solve time, one point per mesh")
    ax_err.grid(True, which="both", alpha=0.3)

    for run, marker in zip(runs, "osD^v<>", strict=False):
        steps = run["steps"]
        ax_newton.plot([s["value"] for s in steps], [s["newton_iterations"] for s in steps],
                       marker=marker, ms=4, alpha=0.8, label=f"{run['mesh']} ({run['dofs']} dofs)")
    ax_newton.set_xlabel("friction coefficient μ at the end of the step")
    ax_newton.set_ylabel("Newton iterations in the step")
    ax_newton.set_title(f"Newton iterations per continuation step (Δμ = {MU_STEPS[1]:.3g})")
    ax_newton.yaxis.get_major_locator().set_params(integer=True)
    ax_newton.grid(True, alpha=0.3)
    ax_newton.legend(fontsize=8)
    save(fig, path, dpi=120)


def main(argv=None) -> None:
    parser = benchmark_parser(__doc__)
    parser.add_argument("--refine", type=int, nargs="+", default=[1, 2, 4, 8],
                        help="refinement factors, increasing; the last is the reference "
                             "(default: 1 2 4 8)")
    args = parser.parse_args(argv)
    if len(args.refine) < 2 or sorted(set(args.refine)) != args.refine or args.refine[0] < 1:
        parser.error("--refine needs at least two increasing factors >= 1")

    logging.getLogger("ffcx").setLevel(logging.WARNING)
    # the JIT's C compiler lines come through the root logger, whose level setuptools resets
    logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)
    comm = MPI.COMM_WORLD
    say = ff.results.get_logger(comm).info
    runs = []
    for refine in args.refine:
        run = run_mesh(refine, comm)
        say(f"{run['mesh']}: {run['dofs']} dofs, JIT {run['jit_time_s']:.2f} s, solve "
            f"{run['solve_time_s']:.2f} s, {run['newton_iterations_total']} Newton iterations")
        runs.append(run)
    if comm.rank == 0:
        relative_errors(runs)
        args.out.mkdir(parents=True, exist_ok=True)
        plot(runs, args.out / "bench_steady.png")
        # the tables go to stdout (progress to stderr), to be pasted into README.md
        print(f"Cost ({comm.size} rank{'s' if comm.size > 1 else ''}):\n\n{speed_table(runs)}\n\n"
              f"Relative errors against the {runs[-1]['mesh']} mesh (observed rate):\n\n"
              f"{accuracy_table(runs)}", flush=True)
    for run in runs:  # the sampled profiles are long and exist on rank 0 only
        for sample in run["samples"].values():
            sample.pop("penetration")
    write_summary(args.out / "bench_steady.json",
                     {"ranks": comm.size, "mu_steps": MU_STEPS.tolist(), "mu_samples": MU_SAMPLES,
                      "base_points": NUM_BASE_POINTS, "corner_margin": CORNER_MARGIN,
                      "continuation_repeats": CONTINUATION_REPEATS, "bare_repeats": BARE_REPEATS,
                      "runs": runs}, comm)
    say(f"wrote {args.out / 'bench_steady.json'} and {args.out / 'bench_steady.png'}")


if __name__ == "__main__":
    main()
