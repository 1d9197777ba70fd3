"""The 3D block at growing size and on 1 and 2 ranks: time and memory per rank of the steady
continuation to μ = 0.5 and of a dynamics run, direct (MUMPS) against Krylov + AMG.

One run is one mesh, one path and one rank count, in a process of its own (peak memory is the
process's): it writes ``bench_scale_3d_<path>_r<refine>_p<ranks>[_<tag>].json`` with

* the unknowns n (the 3D block of ``fenicsfriction block steady --dim 3``: 4r × 3r × 2r
  hexahedra of degree 2, n = 3 (8r+1)(6r+1)(4r+1));
* the steady continuation μ = 0 → 0.5 (``--mu-steps`` equal increments, secant predictor):
  wall time, Newton iterations per step, Krylov iterations;
* ``--steps`` fixed steps of generalized-α dynamics (dt = ``--dt``) from the steady state at
  μ = 0.5 with the belt's velocity perturbed: wall time per step, Newton iterations;
* each phase's time split by PETSc's event log, inside a log stage per phase (the maximum
  over the ranks): assembly (SNES function and Jacobian evaluations, inclusive), linear
  set-up (PCSetUp: MUMPS's factorisation or the AMG hierarchy), Krylov (KSPSolve without the
  set-up it contains), contact search (none in this scene: the belt is a compliance law on
  a plane, searched nowhere) and observers (their own log stage), and the rest;
* the peak resident memory of every rank after each phase, and :func:`_common.environment`.

``--collect`` reads every such JSON in ``--out`` and writes ``bench_scale_3d.json`` (the
least-squares exponents of time ~ n^a and memory ~ n^b on log-log axes, per path; the
strong-scaling speed-ups 1 → 2 ranks at equal n, the weak-scaling efficiencies 1 rank at n
against 2 ranks at about 2n, and the extrapolation to 8, 64 and 512 ranks described in
docs/scaling.md) and ``bench_scale_3d.png``, and prints the tables as markdown.
"""

from __future__ import annotations

import json
import logging
import math
import pathlib
import resource
import time
import typing

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
from _common import log_stage, note_solver, save, write_summary
from _common import parser as benchmark_parser

#: the dynamics scene of bench_dynamics.py (the law's ε and b_n; the belt speed)
MU, BELT_SPEED, B_N, EPS = 0.5, 0.08, 0.381e10, 1e-2
PERTURBATION = -0.01  # [cm/s], added to the normal velocity before the dynamics run

#: the linear set-up's PETSc events, none nested in another: MUMPS's factorisations and
#: GAMG's hierarchy (hypre's has no event of its own: its PCSetUp is counted when no other ran)
SETUP_EVENTS = ("MatLUFactorSym", "MatLUFactorNum", "MatCholFctrSym", "MatCholFctrNum",
                "PCSetUp_GAMG+")
PATHS = ("direct", "amg")


def dofs_of(refine: int) -> int:
    """Unknowns of the 3D block at ``refine`` (degree 2, nz = 2)."""
    return 3 * (8 * refine + 1) * (6 * refine + 1) * (4 * refine + 1)


def _peak_mib(comm: MPI.Comm) -> list[float]:
    return comm.allgather(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)


def _stage_times(stage: PETSc.Log.Stage, comm: MPI.Comm) -> dict[str, float]:
    """A phase's time by PETSc's events in its log stage, the maximum over the ranks:
    assembly (the SNES function and Jacobian evaluations), the linear set-up
    (:data:`SETUP_EVENTS`), the Krylov iterations with their preconditioner applications and
    the line search (the rest of the SNES solves), contact search (none in this scene)."""
    def event(name: str) -> float:
        return float(PETSc.Log.Event(name).getPerfInfo(stage)["time"])

    assembly = event("SNESFunctionEval") + event("SNESJacobianEval")
    setup = sum(map(event, SETUP_EVENTS)) or event("PCSetUp")
    times = {"assembly": assembly, "linear set-up": setup,
             "Krylov": event("SNESSolve") - assembly - setup, "contact search": 0.0}
    return {name: comm.allreduce(t, op=MPI.MAX) for name, t in times.items()}


def _solver_args(cls: type, path: str) -> dict[str, typing.Any]:
    """How ``cls`` (SteadySolver or DynamicsSolver) is asked for ``path``, explicitly (their
    ``"auto"`` may pick either). Direct: the steady solver's reused MUMPS LU under FGMRES (its
    3D path before AMG; the condensation, faster below ≈ 4e4 unknowns, fills a dense
    complement that grows like n^(4/3)), the dynamics' MUMPS LU at every Newton iteration.
    AMG: both solvers' ``linear_solver="amg"`` (GMRES + GAMG with the rigid-body
    near-nullspace, :mod:`fenicsfriction.amg`)."""
    if path == "amg":
        return {"linear_solver": "amg"}
    return {"linear_solver": "reused-lu" if cls.__name__ == "SteadySolver" else "lu"}


class _Observers:
    """The observers' time in a log stage of their own: the spring force at every step."""

    def __init__(self, model: typing.Any):
        self.model, self.stage = model, log_stage("observers")
        self.seconds = 0.0

    def __call__(self, *_: typing.Any) -> dict[str, float]:
        self.stage.push()
        t0 = time.perf_counter()
        q = self.model.quantities()
        self.seconds += time.perf_counter() - t0
        self.stage.pop()
        return {"spring_force": float(q.spring_force)}


def run(refine: int, path: str, mu_steps: int, steps: int, dt: float, comm: MPI.Comm,
        checkpoint: typing.Callable[[dict], None]) -> dict:
    """Steady continuation and ``steps`` dynamics steps of the 3D block at ``refine``;
    ``checkpoint`` receives the results between the two."""
    import fenicsfriction as ff
    from fenicsfriction.dynamics import DynamicsError, DynamicsSolver

    say = ff.results.get_logger(comm).info
    t0 = time.perf_counter()
    law = ff.InterfaceLaw(mu=0.0, b_n=B_N, eps=EPS)
    model = ff.BlockOnBelt(refine=refine, dim=3, belt_speed=BELT_SPEED, law=law).build(
        comm, with_friction=True)
    n = model.V.dofmap.index_map.size_global * model.V.dofmap.index_map_bs
    observe = _Observers(model)
    build_s = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    say(f"{n} unknowns, {comm.size} rank(s), {path}: model built in {build_s:.1f} s")
    out: dict[str, typing.Any] = {"refine": refine, "dofs": n, "ranks": comm.size,
                                  "path": path, "build_s": build_s,
                                  "peak_mib_build": _peak_mib(comm)}

    stage = log_stage("steady continuation")
    stage.push()
    comm.Barrier()
    t0, cpu0 = time.perf_counter(), time.process_time()
    solver = ff.SteadySolver(model.residual, prefix="scale_s_",
                             **_merge(_solver_args(ff.SteadySolver, path),
                                      model.solver_options()))
    model.initial_guess()
    records = ff.continuation(solver, model.mu, np.linspace(0.0, MU, mu_steps + 1),
                              observe=observe)
    steady_s = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    steady_cpu = comm.allgather(time.process_time() - cpu0)
    stage.pop()
    note_solver(solver)
    krylov = solver.snes.getLinearSolveIterations()
    out["steady"] = {"wall_time_s": steady_s, "cpu_time_s_per_rank": steady_cpu,
                     "linear_solver": solver.linear_solver,
                     "jit_s": comm.allreduce(solver.jit_time_s, op=MPI.MAX),
                     "newton_iterations": [r["newton_iterations"] for r in records],
                     "krylov_iterations_last_step": krylov,
                     "stages_s": {**_stage_times(stage, comm),
                                  "observers": comm.allreduce(observe.seconds, op=MPI.MAX)},
                     "spring_force": records[-1]["spring_force"]}
    out["peak_mib_steady"] = _peak_mib(comm)
    say(f"  steady continuation to μ = {MU}: {steady_s:.1f} s, Newton "
        f"{out['steady']['newton_iterations']}, {out['peak_mib_steady']} MiB")
    inner = getattr(solver.preconditioner, "ksp", None)  # the reused LU's factors
    for obj in (solver.snes, solver.A, solver.b, solver.x, inner):  # the SNES and its
        if obj is not None:                                          # callbacks form a
            obj.destroy()                                            # cycle gc leaves
    if steps == 0:
        return out
    checkpoint(out)  # what the steady phase measured survives a dynamics run killed

    r = model.residual
    r.u_dot.x.array[1::3] += PERTURBATION  # normal: as bench_dynamics.py, Newton works
    observe.seconds = 0.0
    stage = log_stage("dynamics")
    stage.push()
    comm.Barrier()
    t0, cpu0 = time.perf_counter(), time.process_time()
    dynamics = DynamicsSolver(r, prefix="scale_d_", atol=1e-10 * model.force_scale,
                              **_solver_args(DynamicsSolver, path))
    setup_s, setup_cpu = time.perf_counter() - t0, time.process_time() - cpu0
    failure = None
    try:
        records = dynamics.run(steps * dt, dt, observe=observe)
    except DynamicsError as err:
        records, failure = err.records, str(err)
    dynamics_s = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    step_cpu = comm.allgather((time.process_time() - cpu0 - setup_cpu) / max(len(records) - 1, 1))
    stage.pop()
    note_solver(dynamics)
    done = len(records) - 1
    out["dynamics"] = {"wall_time_s": dynamics_s, "setup_s": comm.allreduce(setup_s, op=MPI.MAX),
                       "dt": dt, "steps": done, "failure": failure,
                       "time_per_step_s": (dynamics_s - setup_s) / max(done, 1),
                       "cpu_time_per_step_s_per_rank": step_cpu,
                       "newton_iterations": int(sum(x["newton_iterations"] for x in records)),
                       "rejected_steps": int(sum(x["rejected_steps"] for x in records)),
                       "stages_s": {**_stage_times(stage, comm),
                                    "observers": comm.allreduce(observe.seconds, op=MPI.MAX)}}
    out["peak_mib_dynamics"] = _peak_mib(comm)
    say(f"  {done} dynamics steps: {dynamics_s:.1f} s "
        f"({out['dynamics']['time_per_step_s']:.2f} s/step), "
        f"{out['peak_mib_dynamics']} MiB")
    dynamics.ts.destroy()
    return out


def _merge(args: dict, options: dict) -> dict:
    """``args`` with the model's SNES tolerances added to its ``options``."""
    return {**args, "options": {**args.get("options", {}), **options}}


# --- collecting the runs -----------------------------------------------------------------------
def fit_exponent(n: list[float], y: list[float]) -> float | None:
    """The least-squares slope of log y against log n (None below two points)."""
    if len(n) < 2:
        return None
    return float(np.polyfit(np.log(n), np.log(y), 1)[0])


def collect(folder: pathlib.Path) -> dict:
    runs = [json.loads(p.read_text()) for p in sorted(folder.glob("bench_scale_3d_*_r*_p*.json"))]
    summary: dict[str, typing.Any] = {"runs": runs, "fits": {}, "strong": [], "weak": []}
    for path in PATHS:
        serial = sorted((r for r in runs if r["path"] == path and r["ranks"] == 1),
                        key=lambda r: r["dofs"])
        best = {}
        for r in serial:  # the fastest of repeated runs at one size
            if r["dofs"] not in best or (r["steady"]["wall_time_s"]
                                         < best[r["dofs"]]["steady"]["wall_time_s"]):
                best[r["dofs"]] = r
        serial = list(best.values())
        n = [r["dofs"] for r in serial]
        fits = {"dofs": n, "steady_s": [r["steady"]["wall_time_s"] for r in serial],
                "peak_mib": [max(r.get("peak_mib_dynamics", r["peak_mib_steady"]))
                             for r in serial],
                "step_s": [r["dynamics"]["time_per_step_s"] if "dynamics" in r else None
                           for r in serial],
                "steady_time_exponent": fit_exponent(
                    n, [r["steady"]["wall_time_s"] for r in serial]),
                "memory_exponent": fit_exponent(
                    n, [max(r["peak_mib_steady"]) for r in serial])}
        dyn = [r for r in serial if "dynamics" in r]
        fits["step_time_exponent"] = fit_exponent(
            [r["dofs"] for r in dyn], [r["dynamics"]["time_per_step_s"] for r in dyn])
        cpu = [r for r in serial if "cpu_time_s_per_rank" in r["steady"]]
        fits["steady_cpu_exponent"] = fit_exponent(
            [r["dofs"] for r in cpu], [r["steady"]["cpu_time_s_per_rank"][0] for r in cpu])
        cpu = [r for r in dyn if "cpu_time_per_step_s_per_rank" in r["dynamics"]]
        fits["step_cpu_exponent"] = fit_exponent(
            [r["dofs"] for r in cpu],
            [r["dynamics"]["cpu_time_per_step_s_per_rank"][0] for r in cpu])
        fits["memory_exponent_dynamics"] = fit_exponent(
            [r["dofs"] for r in dyn], [max(r["peak_mib_dynamics"]) for r in dyn])
        summary["fits"][path] = fits
        for two in (r for r in runs if r["path"] == path and r["ranks"] == 2):
            # the serial run of the same tag (measured moments before), else the fastest
            same = [r for r in runs if r["path"] == path and r["ranks"] == 1
                    and r["dofs"] == two["dofs"] and r.get("tag") == two.get("tag")]
            for one in same or [r for r in serial if r["dofs"] == two["dofs"]]:
                summary["strong"].append(_strong(one, two))
            half = [r for r in runs if r["path"] == path and r["ranks"] == 1
                    and 1.6 <= two["dofs"] / r["dofs"] <= 2.4]
            for one in [r for r in half if r.get("tag") == two.get("tag")] or [
                    r for r in serial if r in half]:
                summary["weak"].append(_weak(one, two))
    return summary


def _strong(one: dict, two: dict) -> dict:
    row = {"path": one["path"], "dofs": one["dofs"], "tags": [one.get("tag"), two.get("tag")],
           "load": [one["environment"]["load_average"], two["environment"]["load_average"]]}
    for phase in ("steady", "dynamics"):
        if phase in one and phase in two:
            key = "wall_time_s" if phase == "steady" else "time_per_step_s"
            row[phase] = {"1": one[phase][key], "2": two[phase][key],
                          "speedup": one[phase][key] / two[phase][key],
                          "total_1": one[phase]["wall_time_s"],
                          "total_2": two[phase]["wall_time_s"],
                          "stages_1": one[phase]["stages_s"], "stages_2": two[phase]["stages_s"]}
            row[phase]["model"] = model(row, phase)
    return row


def predicted_time(t1: float, t2: float, p: int, log_growth: bool) -> float:
    """A stage's time on ``p`` ranks from its times on 1 and 2.

    Amdahl (``log_growth`` False): a part f that does not divide, t(p) = t1 ((1 - f)/p + f),
    f = 2 t2/t1 - 1 from the two measurements. AMG's set-up and Krylov iterations
    (``log_growth`` True): everything divides but the levels' communication and the coarse
    grids grow like log p, t(p) = t1 (1 + γ log2 p) / p with γ = 2 t2/t1 - 1. Both reproduce
    t2; they differ only in how they extrapolate, and both rest on two points."""
    if t1 <= 0.0:
        return 0.0
    excess = min(max(2.0 * t2 / t1 - 1.0, 0.0), 1.0 if not log_growth else math.inf)
    if log_growth:
        return t1 * (1.0 + excess * math.log2(p)) / p
    return t1 * ((1.0 - excess) / p + excess)


def model(row: dict, phase: str, ranks: tuple[int, ...] = (8, 64, 512)) -> dict[int, float]:
    """Predicted speed-ups on ``ranks`` at the same n (strong scaling) from a strong-scaling
    row's stage times: every stage, and the rest of the wall time, by
    :func:`predicted_time`; AMG's set-up and Krylov with log p growth, MUMPS's with Amdahl."""
    p1, p2 = row[phase]["stages_1"], row[phase]["stages_2"]
    total1, total2 = row[phase]["total_1"], row[phase]["total_2"]  # the phase's whole run
    rest1 = max(total1 - sum(p1.values()), 0.0)
    rest2 = max(total2 - sum(p2.values()), 0.0)
    amg = row["path"] == "amg"
    out = {}
    for p in ranks:
        t = predicted_time(rest1, rest2, p, False)
        for stage, t1 in p1.items():
            t += predicted_time(t1, p2[stage], p, amg and stage in ("linear set-up", "Krylov"))
        out[p] = total1 / t if t > 0 else math.nan
    return out


def _weak(one: dict, two: dict) -> dict:
    """Weak scaling efficiency: (time per unknown on 1 rank) / (time per unknown per rank on
    2), i.e. t1 / t2 × (n2 / 2 n1) so that a slightly uneven size ratio is corrected to first
    order (the cost is not linear in n; the exponents fitted above say how far off that is)."""
    row = {"path": one["path"], "dofs": [one["dofs"], two["dofs"]],
           "tags": [one.get("tag"), two.get("tag")],
           "load": [one["environment"]["load_average"], two["environment"]["load_average"]]}
    for phase in ("steady", "dynamics"):
        if phase in one and phase in two:
            key = "wall_time_s" if phase == "steady" else "time_per_step_s"
            row[phase] = (one[phase][key] / two[phase][key]) * two["dofs"] / (2 * one["dofs"])
    return row


def plot(summary: dict, path: pathlib.Path) -> None:
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    for name, marker in zip(PATHS, "os", strict=True):
        f = summary["fits"].get(name)
        if not f or not f["dofs"]:
            continue
        axes[0].loglog(f["dofs"], f["steady_s"], marker, ls="-", label=name)
        steps = [(n, t) for n, t in zip(f["dofs"], f["step_s"], strict=True) if t is not None]
        axes[1].loglog(*zip(*steps, strict=True), marker, ls="-", label=name)
        axes[2].loglog(f["dofs"], f["peak_mib"], marker, ls="-", label=name)
    for ax, title in zip(axes, ("steady continuation to μ = 0.5 [s]",
                                "dynamics, time per step [s]", "peak memory per rank [MiB]"),
                         strict=True):
        ax.set_xlabel("unknowns n")
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    save(fig, path, 120)


def markdown(summary: dict) -> str:
    lines = ["| path | n | ranks | run | load | steady [s] (CPU) | Newton | dyn. s/step (CPU) "
             "| steps | peak MiB/rank |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in sorted(summary["runs"], key=lambda r: (r["path"], r["dofs"], r["ranks"])):
        d, st = r.get("dynamics", {}), r["steady"]
        load = r["environment"]["load_average"]
        cpu = st.get("cpu_time_s_per_rank", [math.nan])[0]
        step_cpu = d.get("cpu_time_per_step_s_per_rank", [math.nan])[0]
        lines.append(f"| {r['path']} | {r['dofs']:,} | {r['ranks']} | {r.get('tag') or '-'} | "
                     f"{load['start'][0]:.1f}-{load['end'][0]:.1f} | "
                     f"{st['wall_time_s']:.1f} ({cpu:.1f}) | {sum(st['newton_iterations'])} | "
                     f"{d.get('time_per_step_s', math.nan):.2f} ({step_cpu:.2f}) | "
                     f"{d.get('steps', 0)} | "
                     f"{max(r.get('peak_mib_dynamics', r['peak_mib_steady'])):.0f} |")
    lines += ["", "| path | sizes | time exponent: steady (CPU) | dynamics step (CPU) "
              "| memory exponent: steady | with dynamics |", "|---|---|---|---|---|---|"]
    for name, f in summary["fits"].items():
        cells = [f"{v:.2f}" if v is not None else "-" for v in
                 (f["steady_time_exponent"], f["steady_cpu_exponent"], f["step_time_exponent"],
                  f["step_cpu_exponent"], f["memory_exponent"], f["memory_exponent_dynamics"])]
        cells = [f"{cells[0]} ({cells[1]})", f"{cells[2]} ({cells[3]})", *cells[4:]]
        cells.insert(0, ", ".join(f"{n:,}" for n in f["dofs"]))
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    for row in summary["strong"]:
        load = [f"{x['start'][0]:.1f}-{x['end'][0]:.1f}" for x in row["load"]]
        lines += ["", f"Strong scaling, {row['path']}, n = {row['dofs']:,}, runs {row['tags']} "
                  f"(load average 1 rank: {load[0]}, 2 ranks: {load[1]}):", "",
                  "| phase | stage | 1 rank [s] | 2 ranks [s] | speed-up | share on 2 ranks |",
                  "|---|---|---|---|---|---|"]
        for phase in ("steady", "dynamics"):
            if phase not in row:
                continue
            p = row[phase]
            unit = "" if phase == "steady" else " per step"
            lines.append(f"| **{phase}{unit}** | | **{p['1']:.2f}** | **{p['2']:.2f}** | "
                         f"**{p['speedup']:.2f}** | |")
            for stage, t1 in p["stages_1"].items():
                t2 = p["stages_2"][stage]
                lines.append(f"| | {stage} | {t1:.2f} | {t2:.2f} | "
                             f"{t1 / t2 if t2 > 0 else math.nan:.2f} | {t2 / p['total_2']:.0%} |")
            lines.append("| | model: speed-up on 8 / 64 / 512 ranks | | | " + " / ".join(
                f"{v:.1f}" for v in p["model"].values()) + " | |")
    for row in summary["weak"]:
        load = [f"{x['start'][0]:.1f}-{x['end'][0]:.1f}" for x in row["load"]]
        lines.append(f"- weak scaling, {row['path']}, 1 rank at {row['dofs'][0]:,}, 2 ranks at "
                     f"{row['dofs'][1]:,} (runs {row['tags']}, load {load}): " + ", ".join(
                         f"{k} {row[k]:.0%}" for k in ("steady", "dynamics") if k in row))
    return "\n".join(lines)


def main() -> None:
    parser = benchmark_parser(__doc__)
    parser.add_argument("--refine", type=int, default=3,
                        help="mesh refinement r (4r × 3r × 2r Q2 hexahedra; default 3: 18,525 "
                             "unknowns; 5, 7, 9, 12: 80,073, 213,237, 445,665, 1,040,907)")
    parser.add_argument("--path", choices=PATHS, default="direct",
                        help="direct: MUMPS (the solvers' default path); amg: Krylov + AMG")
    parser.add_argument("--mu-steps", type=int, default=10,
                        help="continuation increments to μ = 0.5 (default 10)")
    parser.add_argument("--steps", type=int, default=10,
                        help="dynamics steps (default 10; 0: none)")
    parser.add_argument("--dt", type=float, default=1e-5, help="time step [s] (default 1e-5)")
    parser.add_argument("--tag", default="", help="suffix of the JSON's name (repeated runs)")
    parser.add_argument("--collect", action="store_true",
                        help="no run: fit, plot and tabulate the JSONs in --out")
    args = parser.parse_args()
    if args.collect:
        summary = collect(args.out)
        write_summary(args.out / "bench_scale_3d.json", summary, MPI.COMM_SELF)
        plot(summary, args.out / "bench_scale_3d.png")
        print(markdown(summary))
        return
    for flag, value, ok in (("--refine", args.refine, args.refine >= 1),
                            ("--mu-steps", args.mu_steps, args.mu_steps >= 1),
                            ("--steps", args.steps, args.steps >= 0),
                            ("--dt", args.dt, args.dt > 0)):
        if not ok:
            parser.error(f"{flag}={value} is invalid: must be positive")
    logging.getLogger("ffcx").setLevel(logging.WARNING)
    logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)
    PETSc.Log.begin()
    comm = MPI.COMM_WORLD
    name = f"bench_scale_3d_{args.path}_r{args.refine}_p{comm.size}"
    path = args.out / f"{name}{'_' + args.tag if args.tag else ''}.json"

    def checkpoint(result: dict) -> None:
        write_summary(path, {**result, "tag": args.tag}, comm)

    checkpoint(run(args.refine, args.path, args.mu_steps, args.steps, args.dt, comm,
                   checkpoint))


if __name__ == "__main__":
    main()
