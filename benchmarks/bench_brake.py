r"""The simplified brake at ≥ 1e5 unknowns: full quadratic eigensolve against modal projection.

Two pads pressed on a rotating disc (:mod:`fenicsfriction.studies.brake`), mesh size ``--h``
(2.8 mm: about 1.1e5 unknowns). Along a sweep of the friction coefficient (``--mu``, the first
value 0) it solves, at each μ, the steady sliding (Newton, a MUMPS LU per iteration), assembles
M, C, K̄ at that state, and computes every eigenvalue of the band 0-``--fmax`` Hz twice:

* **full**: SLEPc PEP (TOAR, shift-and-invert with a MUMPS LU) on the full matrices
  (:class:`fenicsfriction.cea.BandSolver`), asked for as many eigenvalues as the band needs
  (twice the number of real modes below 1.2 ``--fmax``, plus 8: no doubling of the request);
* **projected**: the quadratic eigenproblem projected on the m lowest real modes of
  (K_s, M), K_s the symmetric part of K̄ at μ = 0 (:class:`fenicsfriction.cea.ModalBasis`: one
  EPS shift-and-invert solve, computed once at μ = 0 and reused at every μ), solved densely,
  for m in ``--modes``; each pair's residual against the full matrices is computed (and
  timed with it), so the projected solve reports its own accuracy.

It records the wall time of each phase (the mesh, the steady solve, the assembly, the basis,
each μ's full and projected solves; the maximum over ranks), the peak resident memory of the
process (``getrusage``, the maximum over ranks) after each phase, the BLAS and the solver
path, the error of the projected eigenvalues against the full ones (for each full eigenvalue
in the band, the nearest projected one: |Δλ|/|λ|, the largest and the median, and the error of
the largest growth rate) as a function of m, and the speed-up of the projection measured in
the same run: full ÷ projected per μ, and for the whole sweep (basis included).

Writes ``bench_brake.json`` and ``bench_brake.png`` to ``--out`` and prints a markdown table.
"""

from __future__ import annotations

import logging
import resource
import time

from mpi4py import MPI

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction import cea
from fenicsfriction.results import environment, get_logger
from fenicsfriction.studies.brake import geometry, model

MODES = [20, 40, 80, 160]
MUS = [0.0, 0.3, 0.6, 0.9]


def timed(action, comm: MPI.Comm) -> tuple[float, object]:
    """Wall time of ``action()`` (the maximum over ranks) and its value."""
    comm.Barrier()
    t0 = time.perf_counter()
    value = action()
    return comm.allreduce(time.perf_counter() - t0, op=MPI.MAX), value


def peak_memory_mb(comm: MPI.Comm) -> float:
    """The largest peak resident set of the ranks so far [MB] (Linux reports kB)."""
    return comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, op=MPI.MAX)


def errors(full: list, projected: list) -> dict:
    """For each full eigenvalue, the nearest projected one: relative errors |Δλ|/|λ| (largest,
    median) and the error of the largest growth rate relative to its |λ|."""
    if not full:
        return {"max": float("nan"), "median": float("nan"), "growth": float("nan")}
    values = np.array([m.value for m in projected]) if projected else np.zeros(0, complex)
    rel = []
    for mode in full:
        nearest = values[np.argmin(np.abs(values - mode.value))] if len(values) else np.inf
        rel.append(abs(nearest - mode.value) / abs(mode.value))
    top = max(full, key=lambda m: m.value.real)
    top_p = max(projected, key=lambda m: m.value.real).value if projected else np.nan
    return {"max": float(np.max(rel)), "median": float(np.median(rel)),
            "growth": float(abs(top_p.real - top.value.real) / abs(top.value))}


def rows(modes: list) -> list[dict]:
    return [{"re": m.value.real, "frequency": m.value.imag / (2 * np.pi),
             "residual": m.residual} for m in modes]


def plot(summary: dict, path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_err, ax_time, ax_loci) = plt.subplots(1, 3, figsize=(15, 4.5))
    for step in summary["steps"]:
        ms = [p["modes"] for p in step["projected"]]
        ax_err.semilogy(ms, [p["error"]["max"] for p in step["projected"]], "o-",
                        label=f"μ = {step['mu']:g}, largest")
        ax_err.semilogy(ms, [p["error"]["median"] for p in step["projected"]], "x:",
                        label=f"μ = {step['mu']:g}, median")
    ax_err.set_xscale("log", base=2)
    ax_err.set_xlabel("modes in the basis m")
    ax_err.set_ylabel("|λ_m − λ_full| / |λ_full| in the band")
    ax_err.set_title(f"Projection error ({summary['dofs']:,} unknowns)")
    ax_err.legend(fontsize=6)
    phases = summary["phases"]
    sizes = [p["modes"] for p in summary["steps"][0]["projected"]]
    names = ["steady (per μ)", "assembly (per μ)", "basis (once)", "full PEP (per μ)"] + [
        f"projected m={m} (per μ)" for m in sizes]
    values = [phases["steady_s"], phases["assembly_s"], phases["basis_s"], phases["full_s"]] + [
        float(np.mean([s["projected"][k]["time_s"] for s in summary["steps"]]))
        for k in range(len(sizes))]
    ax_time.barh(names, values)
    ax_time.set_xscale("log")
    ax_time.set_xlabel("wall time [s] (mean over μ)")
    ax_time.set_title(f"Speed-up of the sweep, basis included: {summary['speedup_sweep']:.1f}×")
    for step in summary["steps"]:
        f = [r["frequency"] for r in step["full"]]
        ax_loci.scatter(f, [r["re"] for r in step["full"]], s=12, label=f"μ = {step['mu']:g}")
    ax_loci.axhline(0, color="k", lw=0.5)
    ax_loci.set_xlabel("frequency [Hz]")
    ax_loci.set_ylabel("Re λ [1/s]")
    ax_loci.set_title("Full PEP eigenvalues in the band")
    ax_loci.legend(fontsize=7)
    for ax in (ax_err, ax_loci):
        ax.grid(True, which="both", alpha=0.3)
    save(fig, path, dpi=120)


def main(argv=None) -> None:
    parser = benchmark_parser(__doc__)
    parser.add_argument("--h", type=float, default=0.0028,
                        help="mesh size [m] (default 0.0028: about 1.1e5 unknowns)")
    parser.add_argument("--mu", type=float, nargs="+", default=MUS,
                        help="friction coefficients, the first 0 (default: %(default)s)")
    parser.add_argument("--fmax", type=float, default=15000.0, help="band's top [Hz]")
    parser.add_argument("--modes", type=int, nargs="+", default=MODES,
                        help="basis sizes, increasing (default: %(default)s)")
    args = parser.parse_args(argv)
    if args.mu[0] != 0:
        parser.error("the first --mu must be 0 (the basis is the frictionless problem's)")
    logging.getLogger("ffcx").setLevel(logging.WARNING)
    logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)
    comm = MPI.COMM_WORLD
    say = get_logger(comm).info
    start = time.perf_counter()
    band = cea.Band(0.0, args.fmax)
    t_mesh, mesh = timed(lambda: geometry.brake(comm, h=args.h), comm)
    brake = model.BrakeModel(mesh)
    say(f"{brake.dofs} unknowns, mesh {t_mesh:.1f} s")
    memory = {"mesh": peak_memory_mb(comm)}
    full_solver = cea.BandSolver(comm, prefix="brake_full_", dense_below=0)
    basis = None
    steps, phase = [], {"steady": [], "assembly": [], "full": []}
    t_basis = 0.0
    for mu in args.mu:
        t_steady, report = timed(lambda mu=mu: brake.solve_steady(mu), comm)
        t_assembly, pencil = timed(brake.pencil, comm)
        M, C, K = pencil
        if basis is None:
            t_basis, basis = timed(lambda K=K, M=M: cea.ModalBasis(
                cea.symmetric_part(K), M, modes=max(args.modes), prefix="brake_basis_"), comm)
            memory["basis"] = peak_memory_mb(comm)
            in_band = int(np.count_nonzero(basis.frequencies < 1.2 * args.fmax))
            say(f"basis of {basis.size} modes: {t_basis:.1f} s, up to "
                f"{basis.frequencies[-1]:.0f} Hz, {in_band} below 1.2 fmax")
        nev = 2 * in_band + 8
        t_full, full = timed(lambda p=pencil, nev=nev: full_solver.solve(*p, band, nev=nev),
                             comm)
        memory[f"full mu={mu:g}"] = peak_memory_mb(comm)
        projected = []
        for m in args.modes:
            reduced = basis.truncated(m)
            t_proj, modes = timed(lambda r=reduced, p=pencil: r.solve(*p, band), comm)
            projected.append({"modes": m, "time_s": t_proj, "count": len(modes),
                              "error": errors(full, modes), "eigenvalues": rows(modes),
                              "max_residual": max((md.residual for md in modes),
                                                  default=float("nan"))})
        unstable = [md for md in full if md.value.real > 1e-6 * abs(md.value)]
        steps.append({"mu": mu, "newton_iterations": report.iterations,
                      "steady_s": t_steady, "assembly_s": t_assembly, "full_s": t_full,
                      "full_nev": full_solver.last_nev, "full_count": len(full),
                      "full": rows(full), "unstable": rows(unstable), "projected": projected,
                      "pad_forces": brake.pad_forces().tolist()})
        phase["steady"].append(t_steady)
        phase["assembly"].append(t_assembly)
        phase["full"].append(t_full)
        say(f"μ = {mu:g}: steady {t_steady:.1f} s ({report.iterations} it.), assembly "
            f"{t_assembly:.1f} s, full {t_full:.1f} s ({len(full)} in band, "
            f"{len(unstable)} unstable), projected "
            + ", ".join(f"m={p['modes']} {p['time_s']:.2f} s err {p['error']['max']:.1e}"
                        for p in projected))
    mean = {f"{k}_s": float(np.mean(v)) for k, v in phase.items()}
    largest = [s["projected"][-1]["time_s"] for s in steps]
    n_mu = len(args.mu)
    summary = {
        "dofs": brake.dofs, "h": args.h, "ranks": comm.size, "fmax": args.fmax,
        "band_max_rate": band.rate, "geometry": mesh.parameters,
        "pressure": float(brake.pressure.value), "omega": float(brake.omega.value),
        "mesh_s": t_mesh, "phases": {**mean, "basis_s": t_basis}, "basis_modes": basis.size,
        "basis_frequencies": basis.frequencies.tolist(),
        "speedup_per_mu": float(np.mean(phase["full"]) / np.mean(largest)),
        "speedup_sweep": float(sum(phase["full"]) / (t_basis + sum(largest))),
        "peak_memory_mb": memory, "steps": steps,
        "solver_path": {"steady": brake.steady_solver.linear_solver + " (MUMPS)",
                        "full": "SLEPc PEP TOAR, shift-and-invert σ = band rate, MUMPS LU",
                        "basis": "SLEPc EPS Krylov-Schur GHEP, shift-and-invert σ = 0, "
                                 "MUMPS LU",
                        "projected": "dense QZ of the 2m companion (scipy)"},
        "total_s": time.perf_counter() - start}
    if comm.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        plot(summary, args.out / "bench_brake.png")
        blas = environment(comm)["blas"]["name"]
        print(f"\n{brake.dofs:,} unknowns, {comm.size} rank(s), BLAS {blas}, band 0-"
              f"{args.fmax:g} Hz; mean over μ = {', '.join(f'{m:g}' for m in args.mu)}\n")
        print("| phase | wall time [s] |\n|---|---|")
        for key, value in summary["phases"].items():
            print(f"| {key[:-2]} | {value:.2f} |")
        for p in steps[-1]["projected"]:
            print(f"| projected, m = {p['modes']} (μ = {steps[-1]['mu']:g}) | {p['time_s']:.2f} |")
        print("\n| m | " + " | ".join(f"μ = {s['mu']:g}: largest / median error" for s in steps)
              + " |\n|---|" + "---|" * len(steps))
        for k, m in enumerate(args.modes):
            cells = [s["projected"][k]["error"] for s in steps]
            print(f"| {m} | " + " | ".join(f"{e['max']:.1e} / {e['median']:.1e}" for e in cells)
                  + " |")
        print(f"\nspeed-up per μ (full ÷ projected m = {args.modes[-1]}): "
              f"{summary['speedup_per_mu']:.1f}; sweep of {n_mu} μ with the basis: "
              f"{summary['speedup_sweep']:.1f}; peak memory {max(memory.values()):.0f} MB")
    write_summary(args.out / "bench_brake.json", summary, comm)
    say(f"wrote {args.out / 'bench_brake.json'} ({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
