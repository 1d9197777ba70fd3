r"""Wall time and accuracy of the stability eigensolver (SLEPc PEP) against the number of dofs.

Problem 3 on the block on a moving belt (Martins & Oden 1986) at μ = 0.5, past the
collision of the normal/rotation pair (flutter, λ ≈ ±403 + 5365i): every eigenvalue with
|λ| ≤ 8000 rad/s, computed by :class:`fenicsfriction.stability.StabilitySolver` (TOAR,
shift-and-invert about σ = 8000/4 = 2000 with a MUMPS LU factorisation), on the 4r × 3r
nine-node mesh (2D, plane strain) and on the 4r × 3r × 2r 27-node hexahedral mesh (3D) for a
range of refinement factors r. For every mesh it records:

* the PEP wall time: ``StabilitySolver.solve`` (assembling K̄, C, M included; the assembly alone
  is timed apart), and its parts from PETSc's log: the LU factorisation (symbolic + numeric),
  the number and time of the triangular solves, the rest of ``PEPSolve`` (orthogonalisation,
  projected problem, extraction); converged / requested eigenpairs, TOAR restarts, and the
  largest relative residual of the returned pairs;
* the baseline: **one MUMPS LU factorisation** (symbolic + numeric: ``KSPSetUp`` of preonly +
  LU) of the matrix the shift-and-invert factorises, σ²M + σC + K̄, built by hand from the
  same assembled matrices, and of K̄ alone. *PEP ÷ one factorisation* is the eigensolve's cost
  in units of the one step it cannot avoid, a ratio of two times measured moments apart on
  the same machine, so it travels between machines where seconds do not: it is the figure to
  drive down, and a few PEP option variants (``VARIANTS``) are measured against it;
* accuracy: (a) the relative error of every eigenvalue against scipy's dense QZ on the
  companion linearisation (:func:`~fenicsfriction.numerics.dense_eigenvalues`) of the same
  K̄, C, M, where n is small enough for that (``--dense-max-dofs``; its wall time is recorded
  too); (b) the growing eigenvalue of the flutter pair and the spring mode against the finest
  mesh of the same dimension (discretisation convergence), and the flutter pair against the
  rigid 3-dof block (:class:`~fenicsfriction.studies.block.RigidBlock`) for reference.

Timings are the best of up to 3 calls (noise only adds time); a call that takes long is timed
fewer times (the calls stop once ``TIME_BUDGET`` seconds are spent).

The steady state the PEP starts from is timed too (the "steady" entry): Newton from the
initial guess at μ = 0.5 with the solver's default linear solver (the bulk condensed onto
small contact interfaces, GMRES with a reused LU on large ones, as in 3D), then one more
iteration forced (``snes_force_iteration``) with the same solver. Its accuracy limits the
eigenvalues': the SNES test accepts a state once the residual is below an estimate of its
round-off floor, and a state accepted there can move the flutter eigenvalue by ~1e-6
(relative); the forced iteration reaches the attainable residual, and the eigenvalues then
agree to ~1e-10 whatever the path to the state.

Writes ``bench_stability.json`` and ``bench_stability.png`` to ``--out`` and prints markdown
tables to stdout (progress goes to stderr). Rank 0 writes and prints; run serially or with
``mpirun -n 2``.
"""

from __future__ import annotations

import logging
import pathlib
import time

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
from _common import note_solver, save, write_summary
from _common import parser as benchmark_parser

import fenicsfriction as ff
from fenicsfriction.numerics import dense_eigenvalues
from fenicsfriction.results import to_plain
from fenicsfriction.stability import StabilitySolver
from fenicsfriction.studies.block import RigidBlock

MU = 0.5
MAX_MODULUS = 8000.0  # [rad/s]: the spring mode, the flutter pair; the next mode is at 1.8e4
SHIFT = MAX_MODULUS / 4  # StabilitySolver.solve's default shift, σ
FLUTTER_MIN_FREQUENCY = 1000.0  # [rad/s]: modes above it are the flutter pair
REPEATS = 3
TIME_BUDGET = 6.0  # [s]: no further repeat of a measurement once this much has been spent
REFINE_2D = [1, 2, 4, 8, 16, 32, 64]
REFINE_3D = [1, 2, 3, 4]
QUICK_2D, QUICK_3D = [1, 2, 4, 8], [1, 2]
DENSE_MAX_DOFS = 500
# PEP variants: options over DEFAULT_OPTIONS (under the solver's prefix) and solve() arguments
# ("nev 7": the least that can certify the disc, 6 eigenvalues in it and 1 beyond)
VARIANTS = {
    "default": ({}, {}),
    "nev 7": ({}, {"nev": 7}),
    "tol 1e-8": ({"pep_tol": 1e-8}, {}),
    "scale none": ({"pep_scale": "none"}, {}),
    "tol 1e-8, nev 7, ncv 28": ({"pep_tol": 1e-8, "pep_ncv": 28}, {"nev": 7}),
}
LOG_EVENTS = ("MatLUFactorSym", "MatLUFactorNum", "MatSolve", "PEPSolve")


def best_of(measure, comm: MPI.Comm) -> dict:
    """The fastest of up to REPEATS calls of ``measure`` (returns a dict with ``time_s``,
    already the maximum over ranks); no further call once TIME_BUDGET seconds are spent."""
    results: list[dict] = []
    while len(results) < REPEATS and sum(r["time_s"] for r in results) < TIME_BUDGET:
        results.append(measure())
        comm.Barrier()
    best = min(results, key=lambda r: r["time_s"])
    return {**best, "repeats": len(results)}


def timed(action, comm: MPI.Comm) -> tuple[float, object]:
    """Wall time of ``action()`` (maximum over ranks) and what it returned."""
    comm.Barrier()
    t0 = time.perf_counter()
    value = action()
    return comm.allreduce(time.perf_counter() - t0, op=MPI.MAX), value


def _log_events() -> dict:
    return {name: PETSc.Log.Event(name).getPerfInfo() for name in LOG_EVENTS}


def destroy(stab: StabilitySolver) -> None:
    """Free a StabilitySolver's PETSc objects (the PEP holds the LU factors) collectively."""
    for obj in (stab.pep, stab.K, stab.C, stab.M):
        obj.destroy()


def pep_solve(stab: StabilitySolver, comm: MPI.Comm, solve_args: dict) -> dict:
    """One ``stab.solve`` with its breakdown from PETSc's log (times: maximum over ranks)."""
    before = _log_events()
    wall, modes = timed(lambda: stab.solve(max_modulus=MAX_MODULUS, **solve_args), comm)
    after = _log_events()
    count = {k: int(after[k]["count"] - before[k]["count"]) for k in LOG_EVENTS}
    seconds = {k: comm.allreduce(after[k]["time"] - before[k]["time"], op=MPI.MAX)
               for k in LOG_EVENTS}
    pep = stab.pep
    return {"time_s": wall,
            "lu_s": seconds["MatLUFactorSym"] + seconds["MatLUFactorNum"],
            "lu_count": count["MatLUFactorNum"],
            "solves": count["MatSolve"], "solves_s": seconds["MatSolve"],
            "pepsolve_s": seconds["PEPSolve"],
            "iterations": pep.getIterationNumber(),
            "converged": pep.getConverged(), "requested": pep.getDimensions()[0],
            "max_residual": max(m.residual for m in modes),
            "values": [m.value for m in modes]}


def factorisation(A: PETSc.Mat, comm: MPI.Comm) -> dict:
    """Wall time of one MUMPS LU factorisation of A, symbolic and numeric (a fresh KSP)."""
    ksp = PETSc.KSP().create(comm)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("lu")
    pc.setFactorSolverType("mumps")
    ksp.setOperators(A)
    wall, _ = timed(ksp.setUp, comm)
    ksp.destroy()
    return {"time_s": wall}


def shifted_matrix(stab: StabilitySolver, shift: float) -> PETSc.Mat:
    """σ²M + σC + K̄: what shift-and-invert factorises (up to PEP's scaling of λ)."""
    A = stab.K.copy()
    pattern = PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN
    A.axpy(shift, stab.C, structure=pattern)
    A.axpy(shift**2, stab.M, structure=pattern)
    return A


def gather_dense(A: PETSc.Mat, comm: MPI.Comm) -> np.ndarray | None:
    """The whole of a distributed matrix as a NumPy array on rank 0 (``None`` elsewhere)."""
    rows = np.arange(*A.getOwnershipRange(), dtype=np.int32)
    local = A.getValues(rows, np.arange(A.getSize()[1], dtype=np.int32))
    blocks = comm.gather(local, root=0)
    return np.vstack(blocks) if comm.rank == 0 else None


def dense_check(stab: StabilitySolver, values: list[complex], comm: MPI.Comm) -> dict | None:
    """Relative error of each eigenvalue in the disc against dense QZ (result on rank 0)."""
    K, C, M = (gather_dense(A, comm) for A in (stab.K, stab.C, stab.M))
    if comm.rank != 0:
        return None
    t0 = time.perf_counter()
    lam = dense_eigenvalues(K, C, M)
    seconds = time.perf_counter() - t0
    inside = sorted(lam[(lam.imag >= 0) & (np.abs(lam) <= MAX_MODULUS)], key=abs)
    pep = np.array(values)
    modes = []
    for exact in inside:
        nearest = pep[np.argmin(np.abs(pep - exact))]
        modes.append({"dense": exact, "pep": nearest,
                      "relative_error": abs(nearest - exact) / abs(exact)})
    named = named_modes(values)
    return {"time_s": seconds, "count": len(inside), "modes": modes,
            "max_relative_error": max(m["relative_error"] for m in modes),
            **{name: min(abs(named[name] - exact) / abs(exact) for exact in inside)
               for name in named}}


def named_modes(values: list[complex]) -> dict:
    """The spring mode (smallest |λ|) and the growing eigenvalue of the flutter pair."""
    flutter = [v for v in values if v.imag > FLUTTER_MIN_FREQUENCY]
    return {"spring": min(values, key=abs), "flutter": max(flutter, key=lambda v: v.real)}


def steady_state(model, tag: str, comm: MPI.Comm) -> dict:
    """Steady sliding at μ = MU: Newton from the initial guess, then one iteration forced (see
    the module docstring), by one solver with its default linear solver."""
    model.mu.value = MU
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix=f"{tag}s_", options=model.solver_options())

    def solve_and_polish():
        first = solver.solve()
        solver.convergence.force_iteration = True
        return first, solver.solve()

    wall, reports = timed(solve_and_polish, comm)
    preconditioner = solver.preconditioner
    note_solver(solver)
    for obj in (solver.snes, solver.A, solver.b, solver.x):  # the SNES and its callbacks form
        obj.destroy()                                        # a cycle gc leaves
    return {"time_s": wall, "newton_iterations": [r.iterations for r in reports],
            "residual_norms": [r.residual_norm for r in reports],
            "linear_solver": solver.linear_solver,
            "factorisations": getattr(preconditioner, "factorisations", None)}


def run_mesh(dim: int, refine: int, comm: MPI.Comm, dense_max_dofs: int,
             variants_max_dofs: int) -> dict:
    """Steady state, the PEP and its variants, the baselines and the dense check on one mesh."""
    say = ff.results.get_logger(comm).info
    scene = ff.BlockOnBelt(refine=refine, dim=dim)
    model = scene.build(comm, with_friction=True)
    tag = f"b{dim}d{refine}"
    dofs = model.V.dofmap.index_map.size_global * model.V.dofmap.index_map_bs
    mesh = " × ".join(str(n * refine) for n in (4, 3, scene.nz)[:dim])
    steady = steady_state(model, tag, comm)
    say(f"{dim}D {mesh}: {dofs} dofs, steady state {steady['time_s']:.1f} s "
        f"({steady['linear_solver']}, Newton {steady['newton_iterations']})")

    variants, stab = {}, None
    names = list(VARIANTS) if dofs <= variants_max_dofs else ["default"]
    for i, name in enumerate(names):
        options, solve_args = VARIANTS[name]
        solver = StabilitySolver(model.residual, prefix=f"{tag}v{i}_", options=options)
        variants[name] = best_of(lambda s=solver, a=solve_args: pep_solve(s, comm, a), comm)
        note_solver(solver)
        if name == "default":
            stab = solver  # kept for the baselines and the dense check
        else:
            destroy(solver)
    default = variants["default"]
    assembly = best_of(lambda: {"time_s": timed(stab.assemble, comm)[0]}, comm)
    A = shifted_matrix(stab, SHIFT)
    lu_shifted = best_of(lambda: factorisation(A, comm), comm)
    A.destroy()
    lu_stiffness = best_of(lambda: factorisation(stab.K, comm), comm)
    dense = dense_check(stab, default["values"], comm) if dofs <= dense_max_dofs else None
    destroy(stab)
    for variant in variants.values():
        variant["ratio"] = variant["time_s"] / lu_shifted["time_s"]
        # the largest relative distance from a default eigenvalue to the variant's nearest
        variant["change"] = max(min(abs(v - d) for v in variant["values"]) / abs(d)
                                for d in default["values"])
    say(f"  PEP {default['time_s']:.2f} s, one LU {lu_shifted['time_s']:.2f} s, ratio "
        f"{default['ratio']:.2f}; variants " + ", ".join(
            f"{k} {v['ratio']:.2f}" for k, v in variants.items() if k != "default"))
    return {"dim": dim, "refine": refine, "mesh": mesh, "dofs": dofs, "steady": steady,
            "pep": default, "assembly_s": assembly["time_s"],
            "lu_shifted_s": lu_shifted["time_s"], "lu_stiffness_s": lu_stiffness["time_s"],
            "lu_repeats": lu_shifted["repeats"], "ratio": default["ratio"],
            "modes": named_modes(default["values"]), "dense": dense, "variants": variants}


def rigid_reference(scene: ff.BlockOnBelt) -> dict:
    """Eigenvalues of the rigid 3-dof block of the same data at μ = MU."""
    rigid = RigidBlock.from_scene(scene, law=scene.law.replace(mu=MU))
    values = [v for v in rigid.eigenvalues(rigid.steady_state()) if v.imag >= 0]
    return named_modes(values)


def relative_errors(runs: list[dict], rigid: dict) -> None:
    """Add errors, in place: the flutter eigenvalue against the finest mesh of the same
    dimension and against the rigid block; the spring mode against the rigid block's
    sqrt(K_x/M) (the block's own compliance in series with the spring changes it by ~1e-7)."""
    for dim in {run["dim"] for run in runs}:
        same = [run for run in runs if run["dim"] == dim]
        finest = max(same, key=lambda run: run["dofs"])["modes"]
        for run in same:
            modes = run["modes"]
            run["errors"] = {
                "flutter": abs(modes["flutter"] - finest["flutter"]) / abs(finest["flutter"])
                if modes is not finest else None,
                **{f"{name}_vs_rigid": abs(modes[name] - rigid[name]) / abs(rigid[name])
                   for name in ("flutter", "spring")}}


def best_variant(runs: list[dict], min_dofs: int = 10_000) -> tuple[str, dict, int]:
    """The variant of lowest geometric mean ratio over the meshes with at least ``min_dofs``
    and every variant (over all such meshes if none has as many dofs), those means and the
    number of meshes."""
    measured = [run for run in runs if len(run["variants"]) == len(VARIANTS)]
    large = [run for run in measured if run["dofs"] >= min_dofs] or measured
    means = {name: float(np.exp(np.mean([np.log(run["variants"][name]["ratio"])
                                         for run in large]))) for name in VARIANTS}
    return min(means, key=means.get), means, len(large)


def _complex(value: complex, digits: int = 6) -> str:
    return f"{value.real:+.{digits}g} {'+' if value.imag >= 0 else '−'} " \
           f"{abs(value.imag):.{digits}g}i"


def cost_table(runs: list[dict]) -> str:
    """Markdown table of the PEP's cost against one factorisation, per mesh."""
    lines = [("| dim | mesh | dofs | PEP [s] | assembly [s] | one LU of σ²M+σC+K̄ [s] "
              "| one LU of K̄ [s] | **PEP ÷ one LU** | LU events in the PEP [s] "
              "| solves (count, s) | rest of PEPSolve [s] | converged / requested (restarts) "
              "| max residual |"),
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for run in runs:
        p = run["pep"]
        rest = p["pepsolve_s"] - p["lu_s"] - p["solves_s"]
        lines.append(
            f"| {run['dim']}D | {run['mesh']} | {run['dofs']} | {p['time_s']:.3g} "
            f"| {run['assembly_s']:.2g} | {run['lu_shifted_s']:.3g} | {run['lu_stiffness_s']:.3g} "
            f"| **{run['ratio']:.2f}** | {p['lu_s']:.3g} | {p['solves']}, {p['solves_s']:.2g} "
            f"| {rest:.2g} | {p['converged']} / {p['requested']} ({p['iterations']}) "
            f"| {p['max_residual']:.0e} |")
    return "\n".join(lines)


def accuracy_table(runs: list[dict], rigid: dict) -> str:
    """Markdown table of the eigenvalues and their errors, per mesh."""
    lines = [("| dim | mesh | dofs | flutter λ₊ | vs finest | vs rigid | spring mode λ "
              "| vs √(K_x/M) | vs dense QZ: flutter, spring (QZ time) |"),
             "|---|---|---|---|---|---|---|---|---|"]
    for run in runs:
        err, dense = run["errors"], run["dense"]
        finest = "—" if err["flutter"] is None else f"{err['flutter']:.1e}"
        lines.append(
            f"| {run['dim']}D | {run['mesh']} | {run['dofs']} | {_complex(run['modes']['flutter'])}"
            f" | {finest} | {err['flutter_vs_rigid']:.1e} "
            f"| {_complex(run['modes']['spring'], 7)} | {err['spring_vs_rigid']:.1e} | "
            + (f"{dense['flutter']:.0e}, {dense['spring']:.0e} ({dense['time_s']:.2g} s)"
               if dense else "—")
            + " |")
    lines.append(f"| rigid | 3 dof | 3 | {_complex(rigid['flutter'])} | | | "
                 f"{_complex(rigid['spring'], 7)} | | |")
    return "\n".join(lines)


def variant_table(runs: list[dict]) -> str:
    """Markdown table of PEP ÷ one LU per option variant (solves in brackets), per mesh."""
    lines = ["| dim | mesh | dofs | " + " | ".join(VARIANTS) + " |",
             "|---|---|---|" + "---|" * len(VARIANTS)]
    for run in runs:
        cells = [f"{run['variants'][name]['ratio']:.2f} ({run['variants'][name]['solves']})"
                 if name in run["variants"] else "—" for name in VARIANTS]
        lines.append(f"| {run['dim']}D | {run['mesh']} | {run['dofs']} | " + " | ".join(cells)
                     + " |")
    return "\n".join(lines)


def plot(runs: list[dict], rigid: dict, path: pathlib.Path) -> None:
    """Times and PEP ÷ one LU against dofs (left, middle), accuracy against dofs (right)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_time, ax_ratio, ax_acc) = plt.subplots(1, 3, figsize=(19, 5.6))
    dims = sorted({run["dim"] for run in runs})
    colour = {2: "tab:blue", 3: "tab:red"}
    for dim in dims:
        same = [run for run in runs if run["dim"] == dim]
        dofs = [run["dofs"] for run in same]
        c = colour[dim]
        ax_time.loglog(dofs, [run["pep"]["time_s"] for run in same], "o-", color=c,
                       label=f"{dim}D: PEP (StabilitySolver.solve)")
        ax_time.loglog(dofs, [run["lu_shifted_s"] for run in same], "s--", color=c,
                       label=f"{dim}D: one LU of σ²M + σC + K̄")
        ax_time.loglog(dofs, [run["lu_stiffness_s"] for run in same], "^:", color=c,
                       label=f"{dim}D: one LU of K̄")
        ax_time.loglog(dofs, [run["assembly_s"] for run in same], "x-.", color=c, alpha=0.6,
                       label=f"{dim}D: assembly of K̄, C, M")
        for k, name in enumerate(VARIANTS):
            measured = [run for run in same if name in run["variants"]]
            ax_ratio.semilogx([run["dofs"] for run in measured],
                              [run["variants"][name]["ratio"] for run in measured],
                              "o-" if dim == 2 else "s--", color=f"C{k}",
                              lw=2.5 if name == "default" else 1, ms=4,
                              label=f"{dim}D: {name}")
        acc = [(run["dofs"], run["errors"]["flutter"]) for run in same if run["errors"]["flutter"]]
        ax_acc.loglog(*zip(*acc, strict=True), "o-", color=c,
                      label=f"{dim}D: flutter λ₊ vs finest mesh")
        ax_acc.loglog(dofs, [run["errors"]["spring_vs_rigid"] for run in same], "v:", color=c,
                      label=f"{dim}D: spring mode vs √(K_x/M)")
        dense = [(run["dofs"], run["dense"]["max_relative_error"]) for run in same
                 if run["dense"]]
        if dense:
            ax_acc.loglog(*zip(*dense, strict=True), "D", color=c, ms=8, mfc="none",
                          label=f"{dim}D: PEP vs dense QZ, max over modes")
        ax_acc.loglog(dofs, [run["pep"]["max_residual"] for run in same], "x--", color=c,
                      alpha=0.6, label=f"{dim}D: max relative residual")
        ax_acc.loglog(dofs, [run["errors"]["flutter_vs_rigid"] for run in same], "-",
                      color=c, alpha=0.3, lw=4, label=f"{dim}D: flutter λ₊ vs rigid block")
    ax_time.set_xlabel("dofs")
    ax_time.set_ylabel("wall time [s]")
    ax_time.set_title("Eigensolve and one factorisation")
    ax_ratio.set_xlabel("dofs")
    ax_ratio.set_ylabel("PEP time ÷ one LU of σ²M + σC + K̄")
    ax_ratio.set_title("PEP ÷ one factorisation, per option variant")
    ax_acc.set_xlabel("dofs")
    ax_acc.set_ylabel("relative error of the eigenvalue")
    ax_acc.set_title(f"Accuracy at μ = {MU} (rigid block: λ₊ = {_complex(rigid['flutter'], 5)})")
    for ax in (ax_time, ax_ratio, ax_acc):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    save(fig, path, dpi=120)


def main(argv=None) -> None:
    parser = benchmark_parser(__doc__)
    parser.add_argument("--refine-2d", type=int, nargs="*", default=None,
                        help=f"2D refinement factors, increasing; the last is the reference "
                             f"(default: {' '.join(map(str, REFINE_2D))})")
    parser.add_argument("--refine-3d", type=int, nargs="*", default=None,
                        help=f"3D refinement factors, increasing (default: "
                             f"{' '.join(map(str, REFINE_3D))}; 6 gives 1.4e5 dofs)")
    parser.add_argument("--quick", action="store_true",
                        help=f"small meshes only: 2D {' '.join(map(str, QUICK_2D))}, "
                             f"3D {' '.join(map(str, QUICK_3D))}")
    parser.add_argument("--variants-max-dofs", type=int, default=10**6,
                        help="option variants on meshes with at most this many dofs (default: "
                             "10^6; each costs about one more PEP solve)")
    parser.add_argument("--dense-max-dofs", type=int, default=DENSE_MAX_DOFS,
                        help="dense QZ check on meshes with at most this many dofs (default: "
                             f"{DENSE_MAX_DOFS}; its time grows as n³)")
    args = parser.parse_args(argv)
    refine = {2: args.refine_2d if args.refine_2d is not None
              else QUICK_2D if args.quick else REFINE_2D,
              3: args.refine_3d if args.refine_3d is not None
              else QUICK_3D if args.quick else REFINE_3D}
    for dim, factors in refine.items():
        if sorted(set(factors)) != factors or (factors and factors[0] < 1):
            parser.error(f"--refine-{dim}d needs increasing factors >= 1")
    if not refine[2] and not refine[3]:
        parser.error("no mesh to run")

    logging.getLogger("ffcx").setLevel(logging.WARNING)
    # the JIT's C compiler lines come through the root logger, whose level setuptools resets
    logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)
    PETSc.Log.begin()  # the breakdown of each PEP solve comes from PETSc's event log
    comm = MPI.COMM_WORLD
    say = ff.results.get_logger(comm).info
    t0 = time.perf_counter()
    rigid = rigid_reference(ff.BlockOnBelt())
    runs = [run_mesh(dim, r, comm, args.dense_max_dofs, args.variants_max_dofs)
            for dim, factors in refine.items() for r in factors]
    total = time.perf_counter() - t0
    relative_errors(runs, rigid)
    best, means, count = best_variant(runs)
    if comm.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        plot(runs, rigid, args.out / "bench_stability.png")
        # the tables go to stdout (progress to stderr), to be pasted into README.md
        print(f"Cost ({comm.size} rank{'s' if comm.size > 1 else ''}, total run "
              f"{total:.0f} s):\n\n{cost_table(runs)}\n\n"
              f"Eigenvalues at μ = {MU} and relative errors:\n\n{accuracy_table(runs, rigid)}"
              f"\n\nPEP ÷ one LU per option variant (triangular solves):\n\n"
              f"{variant_table(runs)}\n\nGeometric mean over the {count} meshes with every "
              f"variant and ≥ 1e4 dofs (or all with every variant): "
              + ", ".join(f"{k} {v:.2f}" for k, v in means.items()) + f"; best: {best}",
              flush=True)
    write_summary(args.out / "bench_stability.json",
                     {"ranks": comm.size, "mu": MU, "max_modulus": MAX_MODULUS, "shift": SHIFT,
                      "repeats": REPEATS, "time_budget_s": TIME_BUDGET,
                      "variants": {k: {"options": o, "solve": s}
                                   for k, (o, s) in VARIANTS.items()},
                      "best_variant": best, "variant_geometric_means": means,
                      "rigid": to_plain(rigid), "total_time_s": total, "runs": to_plain(runs)},
                     comm)
    say(f"wrote {args.out / 'bench_stability.json'} and {args.out / 'bench_stability.png'} "
        f"({total:.0f} s)")


if __name__ == "__main__":
    main()
