"""Newton's linear-solver paths on the 3D block's steady continuation: LU per iteration, the
reused LU, Krylov + GAMG and Krylov + BoomerAMG, wall time and Krylov counts, same run.

The continuation μ = 0 → 0.5 in 5 steps on the Q2 brick mesh ``--refine`` (945 unknowns at
1, 5,967 at 2, 18,525 at 3, 42,075 at 4, 80,073 at 5); each path from the same initial guess,
its final state compared with the first path's. The JSON records the load average at the start
and the end (the ratios of one run are what travels between machines), the peak resident memory
of the process after each path (it only grows: the first path's is its own), the BLAS and the
paths' PETSc types. Used for the crossovers of ``fenicsfriction.amg`` (docs/solvers.md).

    python benchmarks/bench_amg.py --refine 2 3 --paths lu reused-lu amg hypre --out DIR
"""

from __future__ import annotations

import os
import resource
import time

from mpi4py import MPI

import numpy as np
from _common import parser, write_summary

import fenicsfriction as ff
from fenicsfriction import amg
from fenicsfriction._compat import petsc_vec

PATHS = ("lu", "reused-lu", "condensed", "amg", "hypre")


def continuation(refine: int, path: str, mu: np.ndarray) -> dict:
    """One continuation by ``path``: its record and the final displacement."""
    model = ff.BlockOnBelt(refine=refine, dim=3).build(MPI.COMM_WORLD, with_friction=True)
    model.initial_guess()
    options = dict(model.solver_options())
    linear_solver = path
    if path == "hypre":
        linear_solver = "amg"
        options.update(amg.amg_options(3, "hypre"))
    t0 = time.perf_counter()
    solver = ff.SteadySolver(model.residual, prefix=f"bench{path.replace('-', '')}{refine}_",
                             options=options, linear_solver=linear_solver)
    setup = time.perf_counter() - t0  # with the forms' JIT (the first path of a run compiles)
    t0 = time.perf_counter()
    krylov: list[int] = []

    def observe() -> dict:  # the Krylov iterations of each step's Newton solve
        krylov.append(solver.snes.getLinearSolveIterations())
        return {}

    records = ff.continuation(solver, model.mu, mu, observe=observe)
    ksp = solver.snes.getKSP()
    return {"path": path, "linear_solver": solver.linear_solver, "ksp": ksp.getType(),
            "pc": ksp.getPC().getType(), "unknowns": petsc_vec(model.residual.u).getSize(),
            "setup_s": setup, "wall_time_s": time.perf_counter() - t0,
            "newton_iterations": sum(r["newton_iterations"] for r in records),
            "krylov_per_step": krylov,
            "peak_rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
            "u": petsc_vec(model.residual.u).copy()}


def main() -> None:
    flags = parser(__doc__)
    flags.add_argument("--refine", type=int, nargs="+", default=[1, 2])
    flags.add_argument("--paths", nargs="+", choices=PATHS, default=["lu", "reused-lu", "amg"])
    args = flags.parse_args()
    comm = MPI.COMM_WORLD
    mu = np.linspace(0.0, 0.5, 6)
    config = getattr(np.__config__, "CONFIG", {})  # NumPy >= 1.26
    result: dict = {"ranks": comm.size, "load_average_start": os.getloadavg(),
                    "blas": config.get("Build Dependencies", {}).get("blas", {}).get(
                        "name", "unknown"), "meshes": []}
    for refine in args.refine:
        rows = [continuation(refine, path, mu) for path in args.paths]
        reference = rows[0]["u"]
        for row in rows:
            diff = row["u"].copy()
            diff.axpy(-1.0, reference)
            row["relative_difference"] = diff.norm() / reference.norm()
            row.pop("u")
            if comm.rank == 0:
                print(f"refine {refine}: {row['path']:10s} {row['unknowns']:8d} unknowns "
                      f"{row['wall_time_s']:8.2f} s, Newton {row['newton_iterations']}, "
                      f"Krylov per step {row['krylov_per_step']}", flush=True)
        result["meshes"].append({"refine": refine, "rows": rows})
    result["load_average_end"] = os.getloadavg()
    write_summary(args.out / "bench_amg.json", result, comm)


if __name__ == "__main__":
    main()
