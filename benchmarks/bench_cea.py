r"""Modal CEA against the full quadratic eigenproblem on a finite element pencil: eigenvalue error
against the number of modes, and the speed-up of a parameter sweep.

The block on a moving belt (Martins & Oden 1986; 2D plane strain, 4r × 3r nine-node mesh, r = 16
by default: 25,026 dofs) gives K̄(μ), C(μ), M (:class:`~fenicsfriction.stability.StabilitySolver`
at the steady state of each μ). Every eigenvalue in the band 0-4 kHz (|Re λ| <= 2π·1 kHz, the
spring mode, the normal/rotation pair that flutters past μ ≈ 0.37 and the first elastic modes)
is computed at each μ of the sweep

* by the full PEP (:class:`~fenicsfriction.cea.full.BandSolver`: SLEPc TOAR, shift-and-invert
  about σ = 2π·1000 with MUMPS, the number requested doubled until the disc through the band's
  far corner is covered), the reference;
* by projection on the 10, 20, 40, 80 lowest modes of (sym K̄, M) at the frictionless steady
  state (μ = 0), computed once (:class:`~fenicsfriction.cea.projection.ModalBasis`: SLEPc
  Krylov-Schur, GHEP, shift-and-invert about 0), the projected 2m × 2m companion problem
  solved by LAPACK's QZ and the vectors lifted back.

It records, per μ: the full PEP's time, nev and residuals; per number of modes, the projected
solve's time (projection + QZ + lifting + residuals against the full matrices), the largest
relative distance of a full eigenvalue to the nearest projected one, and the largest residual;
the basis's time once; the same-run baseline — one MUMPS LU factorisation of σ²M + σC + K̄,
what any shift-and-invert step must pay — as the ratio *time ÷ one LU*, which travels between
machines where seconds do not; the speed-up of a sweep of N points, (N · full) ÷ (basis +
N · projected), and the BLAS, the ranks and the peak resident memory (max over ranks).

Writes ``bench_cea.json`` and ``bench_cea.png`` to ``--out``; prints a markdown table. Rank 0
writes; run serially or with ``mpirun -n 2``. About 1 min serially with the defaults.
"""

from __future__ import annotations

import logging
import math
import resource
import time

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

import fenicsfriction as ff
from fenicsfriction.cea import Band, BandSolver, ModalBasis, symmetric_part
from fenicsfriction.results import to_plain
from fenicsfriction.stability import StabilitySolver

MU_VALUES = [0.3, 0.5]  # below and past the flutter onset (≈ 0.37)
BAND = Band(0.0, 4000.0, max_rate=2 * math.pi * 1000.0)  # [Hz], [1/s]
MODES = [10, 20, 40, 80]
SWEEP_POINTS = [1, 10, 100]  # the sweep lengths the speed-up is given for


def timed(action, comm: MPI.Comm) -> tuple[float, object]:
    """Wall time of ``action()`` (maximum over ranks) and what it returned."""
    comm.Barrier()
    t0 = time.perf_counter()
    value = action()
    return comm.allreduce(time.perf_counter() - t0, op=MPI.MAX), value


def one_lu(K: PETSc.Mat, C: PETSc.Mat, M: PETSc.Mat, shift: float, comm: MPI.Comm) -> float:
    """Wall time of one MUMPS LU (symbolic + numeric) of σ²M + σC + K̄, best of 2."""
    A = K.copy()
    pattern = PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN
    A.axpy(shift, C, structure=pattern)
    A.axpy(shift**2, M, structure=pattern)
    times = []
    for _ in range(2):
        ksp = PETSc.KSP().create(comm)
        ksp.setType("preonly")
        ksp.getPC().setType("lu")
        ksp.getPC().setFactorSolverType("mumps")
        ksp.setOperators(A)
        times.append(timed(ksp.setUp, comm)[0])
        ksp.destroy()
    A.destroy()
    return min(times)


def errors_against(full: list, projected: list) -> list[float]:
    """The relative distance of each full eigenvalue to the nearest projected one."""
    if not projected:
        return [math.inf] * len(full)
    values = np.array([m.value for m in projected])
    return [float(np.min(np.abs(values - m.value)) / abs(m.value)) for m in full]


def run(refine: int, dim: int, comm: MPI.Comm) -> dict:
    say = ff.results.get_logger(comm).info
    scene = ff.BlockOnBelt(refine=refine, dim=dim)
    model = scene.build(comm, with_friction=True)
    dofs = model.V.dofmap.index_map.size_global * model.V.dofmap.index_map_bs
    model.mu.value = 0.0
    model.initial_guess()
    steady = ff.SteadySolver(model.residual, prefix="benchcea_s_",
                             options=model.solver_options())
    steady.solve()
    stab = StabilitySolver(model.residual, prefix="benchcea_stab_")
    stab.assemble()
    stiffness, mass = symmetric_part(stab.K), stab.M.copy()
    basis_times = {}
    for m in MODES:  # each size timed on its own; the largest basis is kept and truncated
        basis_times[m], basis = timed(lambda m=m: ModalBasis(stiffness, mass, modes=m,
                                                             prefix=f"benchcea_basis{m}_"), comm)
    basis_s = basis_times[max(MODES)]
    say(f"{dofs} dofs; basis of {basis.size} modes ({basis.frequencies[0]:.4g}-"
        f"{basis.frequencies[-1]:.4g} Hz) in {basis_s:.2f} s")
    solver = BandSolver(comm, prefix="benchcea_full_", dense_below=0)
    points, done = [], 0.0
    for mu in MU_VALUES:
        steps = max(int(math.ceil((mu - done) / 0.1)), 1)
        ff.continuation(steady, model.mu, list(np.linspace(done, mu, steps + 1)[1:]))
        done = mu
        stab.assemble()
        K, C, M = stab.K, stab.C, stab.M
        full_s, full = timed(lambda K=K, C=C, M=M: solver.solve(M, C, K, BAND), comm)
        lu_s = one_lu(K, C, M, BAND.rate, comm)
        point = {"mu": mu, "full_s": full_s, "full_nev": solver.last_nev, "one_lu_s": lu_s,
                 "full_ratio": full_s / lu_s, "count": len(full),
                 "values": [m.value for m in full],
                 "full_max_residual": max(m.residual for m in full), "projection": {}}
        say(f"μ = {mu}: full PEP {full_s:.2f} s (nev {solver.last_nev}, {len(full)} in band, "
            f"{full_s / lu_s:.1f} LU), one LU {lu_s:.3f} s; λ = "
            + ", ".join(f"{m.value:.5g}" for m in full))
        for m in MODES:
            truncated = basis.truncated(m)
            proj_s, projected = timed(lambda b=truncated, K=K, C=C, M=M: b.solve(M, C, K, BAND),
                                      comm)
            errors = errors_against(full, projected)
            error = max(errors)
            nearest = [min(projected, key=lambda p, v=f.value: abs(p.value - v))
                       for f in full] if projected else []
            point["projection"][m] = {
                "time_s": proj_s, "ratio": proj_s / lu_s, "count": len(projected),
                "max_relative_error": error, "relative_errors": errors,
                "max_residual": max((p.residual for p in nearest), default=math.inf),
                "basis_s": basis_times[m],
                "speedup": {n: n * full_s / (basis_times[m] + n * proj_s)
                            for n in SWEEP_POINTS}}
            say(f"  {m:3d} modes: {proj_s:.3f} s, rel. errors "
                + " ".join(f"{e:.1e}" for e in errors)
                + f", max residual {point['projection'][m]['max_residual']:.1e}")
        points.append(point)
    peak = comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, op=MPI.MAX)
    return {"dim": dim, "refine": refine, "dofs": dofs, "basis_s": basis_s,
            "basis_times_s": basis_times,
            "basis_modes": basis.size, "basis_frequencies_hz": basis.frequencies,
            "basis_solver": basis.eps.getType(), "full_solver": solver.last_method,
            "points": points, "peak_rss_mb": peak / 1024}


def table(result: dict) -> str:
    rows = ["| μ | method | time [s] | ÷ one LU | in band | max rel. error | max residual |",
            "|---|---|---|---|---|---|---|"]
    for p in result["points"]:
        rows.append(f"| {p['mu']} | full PEP (nev {p['full_nev']}) | {p['full_s']:.3f} | "
                    f"{p['full_ratio']:.2f} | {p['count']} | (reference) | "
                    f"{p['full_max_residual']:.1e} |")
        for m, q in p["projection"].items():
            rows.append(f"| {p['mu']} | {m} modes | {q['time_s']:.3f} | {q['ratio']:.2f} | "
                        f"{q['count']} | {q['max_relative_error']:.1e} | "
                        f"{q['max_residual']:.1e} |")
    return "\n".join(rows)


def plot(result: dict, path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (err, cost) = plt.subplots(1, 2, figsize=(10, 4))
    for p in result["points"]:
        modes = list(p["projection"])
        err.semilogy(modes, [p["projection"][m]["max_relative_error"] for m in modes], "o-",
                     label=f"μ = {p['mu']}")
        cost.plot(modes, [p["projection"][m]["time_s"] for m in modes], "o-",
                  label=f"projected, μ = {p['mu']}")
        cost.axhline(p["full_s"], ls="--", color=cost.lines[-1].get_color(),
                     label=f"full PEP, μ = {p['mu']}")
    cost.axhline(result["basis_s"], color="k", ls=":", label=f"basis ({max(MODES)} modes), once")
    err.set(xlabel="modes in the basis", ylabel="max relative eigenvalue error",
            title=f"{result['dofs']} dofs, band 0-{BAND.fmax:g} Hz")
    cost.set(xlabel="modes in the basis", ylabel="wall time per sweep point [s]",
             title="cost per point")
    err.legend()
    cost.legend(fontsize=7)
    save(fig, path, 120)


def main(argv=None) -> None:
    parser = benchmark_parser(__doc__)
    parser.add_argument("--refine", type=int, default=16,
                        help="refinement factor r of the block's 4r × 3r mesh (16: 25,026 dofs)")
    parser.add_argument("--dim", type=int, choices=[2, 3], default=2, help="2 or 3 (2)")
    args = parser.parse_args(argv)
    logging.getLogger("ffcx").setLevel(logging.WARNING)
    logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)
    comm = MPI.COMM_WORLD
    t0 = time.perf_counter()
    result = run(args.refine, args.dim, comm)
    total = time.perf_counter() - t0
    if comm.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        plot(result, args.out / "bench_cea.png")
        speedups = {m: q["speedup"] for m, q in result["points"][-1]["projection"].items()}
        print(f"Modal CEA vs the full PEP ({comm.size} rank{'s' if comm.size > 1 else ''}, "
              f"{result['dofs']} dofs, basis {result['basis_s']:.2f} s once, total "
              f"{total:.0f} s, peak {result['peak_rss_mb']:.0f} MB):\n\n{table(result)}\n\n"
              "Basis time per size: " + ", ".join(f"{m} modes {t:.2f} s" for m, t in
                                                  result["basis_times_s"].items())
              + ".\n\nSpeed-up of a sweep of N points (last μ), (N · full) ÷ (basis + N · "
              "projected): "
              + "; ".join(f"{m} modes: " + ", ".join(f"N={n} {s:.1f}" for n, s in v.items())
                          for m, v in speedups.items()), flush=True)
    write_summary(args.out / "bench_cea.json",
                             {"band_hz": [BAND.fmin, BAND.fmax], "max_rate": BAND.rate,
                              "mu_values": MU_VALUES, "modes": MODES, "total_time_s": total,
                              **to_plain(result)}, comm)


if __name__ == "__main__":
    main()
