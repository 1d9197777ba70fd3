r"""The stability eigenproblem at scale: shift-and-invert with Krylov + AMG inner solves against
the MUMPS LU, on the 3D block up to more than 5e5 unknowns.

The block on a moving belt (Martins & Oden 1986) as a 4r × 3r × 2r box of 27-node hexahedra
at μ = 0.5, past the flutter onset: every eigenvalue with |λ| <= 8000 rad/s (the spring mode
and the flutter pair ≈ ±399 + 5352i) by :class:`fenicsfriction.stability.StabilitySolver`,
SLEPc TOAR about σ = 2000, once with ``inner="amg"`` (GMRES + GAMG on σ²M + σC + K̄ with the
rigid-body near-nullspace, SOR smoothing, inner rtol 1e-12) and once with ``inner="direct"``
(MUMPS LU) where ``--direct-max-dofs`` allows, in the same process on the same steady state.

The steady state comes first, by Newton with GMRES + GAMG (the rigid-body near-nullspace on
the Jacobian): the steady solver's own 3D default, an LU reused as preconditioner, would hold
MUMPS' factors and hide the eigen solve's memory. Per path it records the wall time, the CPU
time of this process, the peak resident memory of the stage per rank (Linux ``VmHWM``, reset
before each stage through ``/proc/self/clear_refs``) and ``getrusage``'s peak of the whole
process per rank, the number of inner solves and Krylov iterations, every eigenvalue and its
residual against the full K̄, C, M; and the relative difference of each AMG eigenvalue to the
direct one, the BLAS, the ranks and the load average at the start and end of each size (the
machine may be shared: compare the two paths' times within one size, measured moments apart).

Writes ``bench_eig_scale.json`` (after every size) and ``bench_eig_scale.png`` to ``--out``;
prints a markdown table. Rank 0 writes; run serially or with ``mpirun -n 2``.
"""

from __future__ import annotations

import logging
import os
import resource
import time

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
from _common import parser as benchmark_parser
from _common import save

import fenicsfriction as ff
from fenicsfriction.amg import amg_options, attach_near_nullspace
from fenicsfriction.results import to_plain
from fenicsfriction.stability import StabilitySolver

MU = 0.5
MAX_MODULUS = 8000.0  # [rad/s]
REFINE = [2, 4, 6, 8]
DIRECT_MAX_DOFS = 400_000
#: the steady state's Newton-Krylov solver (over the block's SNES tolerances)
STEADY_OPTIONS = amg_options(3)


def stage_peak_mb() -> float:
    """This process's peak resident memory since the last :func:`reset_peak` [MiB]."""
    with open("/proc/self/status") as status:
        line = next(line for line in status if line.startswith("VmHWM"))
    return int(line.split()[1]) / 1024


def reset_peak() -> None:
    """Reset the kernel's peak resident memory of this process to its current one."""
    with open("/proc/self/clear_refs", "w") as refs:
        refs.write("5")


def process_peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def measured(action, comm: MPI.Comm) -> tuple[dict, object]:
    """Wall time (max over ranks), CPU time of the process (max over ranks) and the stage's
    peak memory per rank of ``action()``, and what it returned."""
    comm.Barrier()
    reset_peak()
    cpu0, t0 = time.process_time(), time.perf_counter()
    value = action()
    wall, cpu = time.perf_counter() - t0, time.process_time() - cpu0
    return {"time_s": comm.allreduce(wall, op=MPI.MAX), "cpu_s": comm.allreduce(cpu, op=MPI.MAX),
            "peak_mb_per_rank": comm.allgather(stage_peak_mb())}, value


def steady_state(model, comm: MPI.Comm, tag: str) -> dict:
    model.mu.value = MU
    model.initial_guess()
    opts = PETSc.Options()
    for key, value in STEADY_OPTIONS.items():  # kept: GAMG reads its levels' at the solve
        opts[f"{tag}s_{key}"] = value
    solver = ff.SteadySolver(model.residual, prefix=f"{tag}s_", options=model.solver_options(),
                             linear_solver="lu")
    attach_near_nullspace(solver.A, model.V)
    stats, report = measured(solver.solve, comm)
    for obj in (solver.snes, solver.A, solver.b, solver.x):
        obj.destroy()
    return {**stats, "newton_iterations": report.iterations,
            "residual_norm": report.residual_norm}


def eigen_solve(model, comm: MPI.Comm, tag: str, inner: str) -> tuple[dict, list]:
    PETSc.Log.begin()
    solves = PETSc.Log.Event("KSPSolve")
    before = solves.getPerfInfo()["count"]

    def solve():
        solver = StabilitySolver(model.residual, prefix=f"{tag}{inner}_", inner=inner)
        modes = solver.solve(MAX_MODULUS)
        ksp = solver.pep.getST().getKSP()
        info = {"path": solver.shift_invert.path, "pc": ksp.getPC().getType(),
                "ksp": ksp.getType(), "inner_rtol": ksp.getTolerances()[0],
                "pep_iterations": solver.pep.getIterationNumber()}
        for obj in (solver.pep, solver.K, solver.C, solver.M):
            obj.destroy()
        solver.shift_invert.destroy()
        return info, modes

    stats, (info, modes) = measured(solve, comm)
    info["inner_solves"] = int(solves.getPerfInfo()["count"] - before)
    return {**stats, **info, "values": [m.value for m in modes],
            "residuals": [m.residual for m in modes],
            "max_residual": max(m.residual for m in modes),
            "all_accurate": all(m.accurate for m in modes)}, modes


def run_size(refine: int, comm: MPI.Comm, direct_max_dofs: int, paths: list[str]) -> dict:
    say = ff.results.get_logger(comm).info
    load_start = os.getloadavg()
    model = ff.BlockOnBelt(refine=refine, dim=3).build(comm, with_friction=True)
    dofs = model.V.dofmap.index_map.size_global * model.V.dofmap.index_map_bs
    tag = f"es{refine}"
    steady = steady_state(model, comm, tag)
    say(f"r={refine}: {dofs} dofs, steady state {steady['time_s']:.1f} s "
        f"(Newton {steady['newton_iterations']})")
    results: dict = {}
    for inner in paths:
        if inner == "direct" and dofs > direct_max_dofs:
            continue
        results[inner], _ = eigen_solve(model, comm, tag, inner)
        r = results[inner]
        say(f"  {inner}: {r['time_s']:.1f} s (cpu {r['cpu_s']:.1f} s), peak "
            f"{max(r['peak_mb_per_rank']):.0f} MiB/rank, {r['inner_solves']} inner solves, "
            f"max residual {r['max_residual']:.1e}")
    record = {"refine": refine, "dofs": dofs, "steady": steady, "paths": results,
              "process_peak_mb_per_rank": comm.allgather(process_peak_mb()),
              "loadavg_start": list(load_start), "loadavg_end": list(os.getloadavg())}
    if "amg" in results and "direct" in results:
        amg, direct = (np.array(results[k]["values"]) for k in ("amg", "direct"))
        if len(amg) == len(direct):
            # to the nearest AMG eigenvalue: the flutter pair's ±Re λ have equal moduli
            nearest = np.abs(amg[None, :] - direct[:, None]).min(axis=1)
            record["relative_difference"] = (nearest / np.abs(direct)).tolist()
            record["max_relative_difference"] = float(max(record["relative_difference"]))
            record["time_ratio_amg_over_direct"] = \
                results["amg"]["time_s"] / results["direct"]["time_s"]
            record["cpu_ratio_amg_over_direct"] = \
                results["amg"]["cpu_s"] / results["direct"]["cpu_s"]
            record["memory_ratio_amg_over_direct"] = \
                max(results["amg"]["peak_mb_per_rank"]) / max(results["direct"]["peak_mb_per_rank"])
    return record


def table(records: list[dict]) -> str:
    """Markdown: per size, each path's wall and CPU time and stage peak, their ratio, the
    eigenvalues' agreement and the load average."""
    lines = ["| unknowns | AMG wall / CPU [s] | AMG peak [MiB] | direct wall / CPU [s] "
             "| direct peak [MiB] | AMG ÷ direct (CPU) | max rel. diff. | AMG max residual "
             "| load (start/end) |",
             "|---:|---:|---:|---:|---:|---:|---:|---:|---|"]

    def times(p: dict | None) -> str:
        return f"{p['time_s']:.1f} / {p['cpu_s']:.1f}" if p else "—"

    def peak(p: dict | None) -> str:
        return f"{max(p['peak_mb_per_rank']):.0f}" if p else "—"

    for r in records:
        amg, direct = r["paths"].get("amg"), r["paths"].get("direct")
        ratio = r.get("cpu_ratio_amg_over_direct")
        diff = r.get("max_relative_difference")
        lines.append(
            f"| {r['dofs']:,} | {times(amg)} | {peak(amg)} | {times(direct)} | {peak(direct)} "
            f"| {'—' if ratio is None else f'{ratio:.1f}'} "
            f"| {'—' if diff is None else f'{diff:.1e}'} "
            f"| {'—' if amg is None else format(amg['max_residual'], '.1e')} "
            f"| {r['loadavg_start'][0]:.1f}/{r['loadavg_end'][0]:.1f} |")
    return "\n".join(lines)


def plot(records: list[dict], path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_t, ax_m) = plt.subplots(1, 2, figsize=(9, 3.6))
    for inner, marker in (("amg", "o-"), ("direct", "s--")):
        rows = [r for r in records if inner in r["paths"]]
        n = [r["dofs"] for r in rows]
        ax_t.loglog(n, [r["paths"][inner]["cpu_s"] for r in rows], marker, label=inner)
        ax_m.loglog(n, [max(r["paths"][inner]["peak_mb_per_rank"]) / 1024 for r in rows],
                    marker, label=inner)
    ax_t.set(xlabel="unknowns", ylabel="eigen solve CPU time [s]")  # wall: load-dependent
    ax_m.set(xlabel="unknowns", ylabel="peak memory of the stage [GiB/rank]")
    for ax in (ax_t, ax_m):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    save(fig, path, dpi=120)


def main(argv=None) -> None:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--refine", type=int, nargs="+", default=REFINE,
                       help=f"refinement factors r (default {REFINE}; r=10: 607,743 unknowns)")
    flags.add_argument("--direct-max-dofs", type=int, default=DIRECT_MAX_DOFS,
                       help=f"no direct solve above this many unknowns ({DIRECT_MAX_DOFS})")
    flags.add_argument("--paths", nargs="+", default=["amg", "direct"],
                       choices=["amg", "direct"], help="inner solves to measure, in order")
    args = flags.parse_args(argv)
    logging.getLogger("ffcx").setLevel(logging.WARNING)
    comm = MPI.COMM_WORLD
    args.out.mkdir(parents=True, exist_ok=True)
    records = []
    for refine in args.refine:
        records.append(run_size(refine, comm, args.direct_max_dofs, args.paths))
        ff.results.write_summary(args.out / "bench_eig_scale.json",
                                 to_plain({"mu": MU, "max_modulus": MAX_MODULUS,
                                           "sizes": records}), comm)
    if comm.rank == 0:
        plot(records, args.out / "bench_eig_scale.png")
        print(table(records))


if __name__ == "__main__":
    main()
