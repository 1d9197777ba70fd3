"""Strong scaling of the steady continuation and of the PEP: where the time goes on each rank count.

Run it once serially and once under ``mpirun -n 2`` (``make benchmark`` does both) on the same
mesh; each run writes ``bench_scaling_<ranks>.json`` with the wall time of

* the steady continuation μ = 0 → 1.5 in 30 steps (the solver's defaults: the bulk condensed
  onto the contact interface, secant predictor), split by PETSc's event log into residual
  assembly, interface Jacobian assembly, the MUMPS factorisations (symbolic and numeric; the
  bulk's Schur complement comes out of them), the triangular solves of the Newton iterations,
  PETSc's dense LU of the interface block (serial), and the rest (SciPy's dense interface LU
  in parallel, the observers' quantities, SNES);
* the quadratic eigenproblem at μ = 0.5 (every |λ| ≤ 8000 rad/s), split into the MUMPS
  factorisation, the triangular solves and the rest (TOAR's orthogonalisation, projected
  problem).

When both files exist in ``--out``, the second run also prints the strong-scaling table: each
stage's time on 1 and 2 ranks and its speed-up. Timings are the maximum over the ranks.
"""

from __future__ import annotations

import json
import logging
import time

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
from _common import note_solver, write_summary
from _common import parser as benchmark_parser

import fenicsfriction as ff

MU_STEPS = np.linspace(0.0, 1.5, 31)
MU_PEP = 0.5

#: stage -> the PETSc events whose exclusive times it sums (PETSc's own event names)
STEADY_STAGES = {
    "residual assembly": ["SNESFunctionEval"],
    "Jacobian (interface) assembly": ["SNESJacobianEval"],
    "factorisation, with the bulk's Schur complement": ["MatLUFactorSym", "MatLUFactorNum"],
    "Newton triangular solves": ["MatSolve"],
    "dense interface LU": ["MatLUFactor"],
}
PEP_STAGES = {
    "factorisation": ["MatLUFactorSym", "MatLUFactorNum"],
    "triangular solves": ["MatSolve"],
}


def _event_times(names: list[str]) -> float:
    return sum(PETSc.Log.Event(name).getPerfInfo().get("time", 0.0) for name in names)


def _snapshot(stages: dict) -> dict:
    return {stage: _event_times(events) for stage, events in stages.items()}


def _stage_times(before: dict, after: dict, total: float, comm: MPI.Comm) -> dict:
    times = {k: comm.allreduce(after[k] - before[k], op=MPI.MAX) for k in before}
    times["rest"] = max(total - sum(times.values()), 0.0)
    return times


def run(refine: int, comm: MPI.Comm) -> dict:
    model = ff.BlockOnBelt(refine=refine).build(comm, with_friction=True)
    dofs = model.V.dofmap.index_map.size_global * model.V.dofmap.index_map_bs
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, options=model.solver_options())
    # the residual's own stages (those the SNES events do not cover: the PC's set-up and its
    # dense interface work are inside PCSetUp/PCApply, counted as the rest)
    before = _snapshot(STEADY_STAGES)
    comm.Barrier()
    t0 = time.perf_counter()
    ff.continuation(solver, model.mu, MU_STEPS, observe=model.quantities)
    steady_total = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    steady = _stage_times(before, _snapshot(STEADY_STAGES), steady_total, comm)
    note_solver(solver)
    pc_setup = PETSc.Log.Event("PCSetUp").getPerfInfo().get("time", 0.0)

    model.mu.value = MU_PEP
    model.slide_to(MU_PEP, solver)
    stability = ff.StabilitySolver(model.residual)
    before = _snapshot(PEP_STAGES)
    comm.Barrier()
    t0 = time.perf_counter()
    modes = stability.solve(max_modulus=8000)
    note_solver(stability)
    pep_total = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    pep = _stage_times(before, _snapshot(PEP_STAGES), pep_total, comm)
    return {"refine": refine, "dofs": dofs, "ranks": comm.size,
            "interface_dofs": None if solver.condensation is None else solver.condensation.size,
            "steady_total_s": steady_total, "steady_stages_s": steady,
            "pc_setup_s": comm.allreduce(pc_setup, op=MPI.MAX),
            "pep_total_s": pep_total, "pep_stages_s": pep,
            "flutter": [m.value for m in modes if m.value.imag > 0][:2]}


def table(one: dict, two: dict) -> str:
    lines = ["| stage | 1 rank [s] | 2 ranks [s] | speed-up | share on 2 ranks |",
             "|---|---|---|---|---|"]
    for kind in ("steady", "pep"):
        total1, total2 = one[f"{kind}_total_s"], two[f"{kind}_total_s"]
        lines.append(f"| **{'steady continuation' if kind == 'steady' else 'PEP'}** "
                     f"| **{total1:.2f}** | **{total2:.2f}** | **{total1 / total2:.2f}** | |")
        for stage, t1 in one[f"{kind}_stages_s"].items():
            t2 = two[f"{kind}_stages_s"][stage]
            speedup = f"{t1 / t2:.2f}" if t2 > 0 else "-"
            lines.append(f"| {stage} | {t1:.2f} | {t2:.2f} | {speedup} | {t2 / total2:.0%} |")
    return "\n".join(lines)


def main() -> None:
    parser = benchmark_parser(__doc__)
    parser.add_argument("--refine", type=int, default=46,
                        help="mesh refinement (default 46: 184 × 138, 204,426 dofs)")
    args = parser.parse_args()
    logging.getLogger("ffcx").setLevel(logging.WARNING)
    logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)
    PETSc.Log.begin()
    comm = MPI.COMM_WORLD
    say = ff.results.get_logger(comm).info
    result = run(args.refine, comm)
    say(f"{comm.size} rank(s), {result['dofs']} dofs: continuation "
        f"{result['steady_total_s']:.2f} s, PEP {result['pep_total_s']:.2f} s")
    out = args.out / f"bench_scaling_{comm.size}.json"
    write_summary(out, result, comm)
    other = args.out / f"bench_scaling_{1 if comm.size == 2 else 2}.json"
    if comm.rank == 0 and other.exists():
        runs = sorted([result, json.loads(other.read_text())], key=lambda r: r["ranks"])
        if runs[0]["dofs"] == runs[1]["dofs"] and [r["ranks"] for r in runs] == [1, 2]:
            print(f"Strong scaling at {result['dofs']} dofs:\n\n{table(*runs)}", flush=True)


if __name__ == "__main__":
    main()
