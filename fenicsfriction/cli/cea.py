"""``fenicsfriction cea matrices``: complex eigenvalue analysis (CEA) of matrices from files —
every eigenvalue in a frequency band along a parameter, by the full quadratic eigenproblem, by
projection on a modal basis, or both.

The matrices M, C(p) = C + p C1, K(p) = K + p K1 + p² K2 are read from MatrixMarket, MATLAB or
PETSc binary files (:mod:`fenicsfriction.cea.matrices`), or built in (``--example hoffmann``:
the two-degree-of-freedom model of Hoffmann et al. 2002). The flags and the files' presence are
checked before anything is read; the eigenvalues of each parameter value are written as they are
computed (``eigenvalues.csv``), and a signal or a solver failure stops the run with what was
computed written. MPI and PETSc are imported inside the run function.
"""

from __future__ import annotations

import argparse
import logging
import pathlib
import time
import typing

from fenicsfriction.cli.arguments import Parser

__all__ = ["add_parser", "parameter_values", "run_matrices"]

#: the matrix flags -> the part of the pencil each gives
MATRIX_FLAGS = {"M": "M", "C": "C0", "C1": "C1", "K": "K0", "K1": "K1", "K2": "K2"}

#: the built-in examples: the Hoffmann model's keyword arguments
EXAMPLES: dict[str, dict[str, float]] = {"hoffmann": {}, "hoffmann-damped": {"c1": 0.02}}


def parameter_values(text: str) -> list[float]:
    """``"0:1:11"`` -> 11 values from 0 to 1 (both ends included); ``"0,0.5,2"`` -> those."""
    try:
        if ":" in text:
            lo, hi, count = text.split(":")
            n = int(count)
            if n < 1:
                raise ValueError
            return [float(lo) + (float(hi) - float(lo)) * i / max(n - 1, 1) for i in range(n)]
        values = [float(v) for v in text.split(",") if v.strip()]
        if values:
            return values
    except ValueError:
        pass
    raise argparse.ArgumentTypeError(
        f"expected LO:HI:N (N >= 1 values) or V1,V2,..., got {text!r}")


def _band(text: str) -> tuple[float, float]:
    try:
        low, high = (float(v) for v in text.split(":"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected FMIN:FMAX in Hz, got {text!r}") from None
    return low, high


def add_parser(commands: typing.Any) -> None:
    """``cea matrices``."""
    family = commands.add_parser(
        "cea", help="complex eigenvalue analysis of matrices (brake squeal): bands, sweeps, "
                    "modal projection",
        description="Complex eigenvalue analysis of the quadratic eigenproblem "
                    "(λ²M + λC(p) + K(p)) w = 0 along a parameter p.")
    studies = family.add_subparsers(dest="study", required=True, parser_class=Parser,
                                    metavar="STUDY")
    matrices = studies.add_parser(
        "matrices", help="eigenvalues in a band along a parameter, from matrix files",
        description="Every eigenvalue with frequency in --band at each --param-values, on "
                    "M, C(p) = C + p C1, K(p) = K + p K1 + p² K2 read from .mtx (MatrixMarket), "
                    ".mat (MATLAB; FILE.mat:VARIABLE when it holds several) or PETSc binary "
                    "files; PETSc/SLEPc options as -cea_<option> (full PEP) and "
                    "-cea_basis_<option> (modal basis) after the flags.")
    files = matrices.add_argument_group("the matrices (files), or --example")
    for flag, part in MATRIX_FLAGS.items():
        files.add_argument(f"--{flag}", dest=f"matrix_{flag}", metavar="FILE",
                           help=f"the pencil's {part}" + (" (required)" if flag in "MK" else ""))
    files.add_argument("--example", choices=sorted(EXAMPLES),
                       help="a built-in pencil instead of files: Hoffmann et al.'s two-degree-"
                            "of-freedom model, p = μ (undamped; -damped: c1 = 0.02)")
    matrices.add_argument("--param-values", type=parameter_values, required=True,
                          metavar="LO:HI:N", help="the parameter's values (or V1,V2,...)")
    matrices.add_argument("--param-name", default="p", help="the parameter's name (p)")
    matrices.add_argument("--band", type=_band, required=True, metavar="FMIN:FMAX",
                          help="the frequencies Im λ/2π wanted [Hz]")
    matrices.add_argument("--max-rate", type=float,
                          help="the largest |Re λ| reported [1/s] (default 2π FMAX/4)")
    matrices.add_argument("--method", choices=["full", "projection", "both"], default="full",
                          help="the full PEP (SLEPc; dense QZ when small), the projection on "
                               "the modes of (sym K, M), or both (full)")
    matrices.add_argument("--dense-below", type=int, default=400,
                          help="the full solve is dense QZ up to this many unknowns, SLEPc's "
                               "PEP above (400)")
    matrices.add_argument("--modes", type=int,
                          help="modes of the basis (projection; default 40 unless "
                               "--basis-frequency)")
    matrices.add_argument("--basis-frequency", type=float,
                          help="or every mode below this frequency [Hz] in the basis")
    matrices.add_argument("--growth-tol", type=float, default=1e-6,
                          help="a mode grows when Re λ > growth-tol |λ| (1e-6)")
    matrices.add_argument("--refine-tol", type=float,
                          help="bisect each onset to this width in the parameter")
    matrices.add_argument("--vectors", action="store_true",
                          help="write the growing modes' eigenvectors as .npy")
    matrices.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    matrices.set_defaults(run=run_matrices)


def _check_flags(args: argparse.Namespace) -> dict[str, str]:
    """Every flag's value, and that the matrix files exist, before anything is read; the
    files by part name."""
    import math

    from fenicsfriction.laws import check

    given = {flag: getattr(args, f"matrix_{flag}") for flag in MATRIX_FLAGS
             if getattr(args, f"matrix_{flag}") is not None}
    if args.example is not None:
        check("--example", args.example, not given,
              f"replaces the matrix files; drop {', '.join('--' + f for f in given)}")
    else:
        for flag in ("M", "K"):
            check(f"--{flag}", None, flag in given, "a matrix file is required (or --example)")
    for flag, path in given.items():
        file = pathlib.Path(path.rsplit(":", 1)[0] if ".mat:" in path else path)
        check(f"--{flag}", path, file.is_file(), "no such file")
    fmin, fmax = args.band
    check("--band", f"{fmin:g}:{fmax:g}", 0 <= fmin < fmax and math.isfinite(fmax),
          "needs 0 <= FMIN < FMAX (finite, in Hz)")
    if args.max_rate is not None:
        check("--max-rate", args.max_rate, args.max_rate > 0, "must be > 0")
    check("--growth-tol", args.growth_tol, args.growth_tol > 0, "must be > 0")
    check("--dense-below", args.dense_below, args.dense_below >= 0, "must be >= 0")
    if args.refine_tol is not None:
        check("--refine-tol", args.refine_tol, args.refine_tol > 0, "must be > 0")
    if args.modes is not None:
        check("--modes", args.modes, args.modes >= 1, "must be >= 1")
    if args.basis_frequency is not None:
        check("--basis-frequency", args.basis_frequency, args.basis_frequency > 0,
              "must be > 0")
        check("--basis-frequency", args.basis_frequency, args.modes is None,
              "give --modes or --basis-frequency, not both")
    if args.method == "full":
        for flag in ("modes", "basis_frequency"):
            check(f"--{flag.replace('_', '-')}", getattr(args, flag), getattr(args, flag) is None,
                  "only with --method projection or both")
    return {MATRIX_FLAGS[flag]: path for flag, path in given.items()}


def run_matrices(args: argparse.Namespace, log: logging.Logger) -> int:
    """Read the pencil, sweep the parameter with each method, write the eigenvalues, the
    growing modes, the coalescences and the coupling maps."""
    from mpi4py import MPI

    import numpy as np

    from fenicsfriction import results
    from fenicsfriction.cea import (
        Band,
        BandSolver,
        HoffmannModel,
        ModalBasis,
        ParametricPencil,
        Sweep,
        from_array,
        plot_coupling_map,
        symmetric_part,
    )
    from fenicsfriction.cea.sweep import unstable_intervals
    from fenicsfriction.cli.common import named_by_flag, output_folder, stop_line, stopped
    from fenicsfriction.signals import Interrupted, StopSignals
    from fenicsfriction.stability import EigenSolveError, Mode

    comm = MPI.COMM_WORLD
    paths = _check_flags(args)
    fmin, fmax = args.band
    band = Band(fmin, fmax, max_rate=args.max_rate)
    out = output_folder(args.out, comm)
    t_start = time.perf_counter()
    if args.example is not None:
        parts = HoffmannModel(**EXAMPLES[args.example]).matrices()
        pencil = ParametricPencil(**{k: from_array(v, comm) for k, v in parts.items()})
    else:
        flags = {part: f"--{flag}" for flag, part in MATRIX_FLAGS.items()}
        try:
            pencil = ParametricPencil.read(paths, comm, flags)
        except ValueError as err:
            raise ValueError(named_by_flag(str(err), flags)) from None
    log.info(f"cea: {pencil.size} unknowns, parts {', '.join(pencil.parts())}; "
             f"{len(args.param_values)} values of {args.param_name}; band "
             f"{band.fmin:g}-{band.fmax:g} Hz, |Re λ| <= {band.rate:.4g} 1/s")
    methods = ["full", "projection"] if args.method == "both" else [args.method]
    basis_time = None
    solvers: dict[str, typing.Callable[[float], list[Mode]]] = {}
    if "full" in methods:
        full = BandSolver(comm, prefix="cea_", dense_below=args.dense_below)
        solvers["full"] = lambda p: full.solve(*pencil.at(p), band)
    if "projection" in methods:
        t0 = time.perf_counter()
        try:
            basis = ModalBasis(symmetric_part(pencil.K0), pencil.M,
                               modes=None if args.basis_frequency
                               else min(args.modes or 40, pencil.size),
                               max_frequency=args.basis_frequency, prefix="cea_basis_")
        except EigenSolveError as err:
            results.write_summary(out / "summary.json", {"failure": f"modal basis: {err}"},
                                  comm)
            stop_line(f"modal basis: {err}")
            return 1
        basis_time = time.perf_counter() - t0
        log.info(f"modal basis: {basis.size} modes of (sym K, M), {basis.frequencies[0]:.4g}-"
                 f"{basis.frequencies[-1]:.4g} Hz, in {basis_time:.3g} s")
        solvers["projection"] = lambda p: basis.solve(*pencil.at(p), band)

    sweeps = {method: Sweep(solve, comm, args.growth_tol) for method, solve in solvers.items()}
    timings: dict[str, float] = {}
    vectors_dir = out / "vectors"

    def write(failure: str | None, interrupted: str | None) -> dict:
        summary: dict[str, typing.Any] = {
            "param_name": args.param_name, "band_hz": [band.fmin, band.fmax],
            "max_rate": band.rate, "unknowns": pencil.size, "methods": methods,
            "basis_modes": basis.size if "projection" in methods else None,
            "full_solver": full.last_method if "full" in methods else None,
            "basis_time_s": basis_time, "sweep_time_s": timings,
            "wall_time_s": time.perf_counter() - t_start, "failure": failure,
            "interrupted": interrupted}
        results.write_json(out / "eigenvalues.json", {
            "param_name": args.param_name, "band_hz": [band.fmin, band.fmax],
            "records": {m: s.records for m, s in sweeps.items()}}, comm)
        unstable = {m: {"coalescences": events.get(m, []),
                        "unstable_intervals": unstable_intervals(s.records, args.growth_tol),
                        "unstable_modes": [
                            {args.param_name: r["p"],
                             "modes": [row for row in r["modes"]
                                       if row["re"] > args.growth_tol * abs(complex(row["re"],
                                                                                    row["im"]))]}
                            for r in s.records]}
                    for m, s in sweeps.items()}
        results.write_json(out / "unstable.json", unstable, comm)
        results.write_summary(out / "summary.json", summary, comm)
        return unstable

    events: dict[str, list] = {}
    failure, interrupted = None, None
    with StopSignals(comm) as stop, results.CsvRows(out / "eigenvalues.csv", comm) as table:
        for method, sweep in sweeps.items():
            def on_step(record: dict, modes: list[Mode], method: str = method,
                        sweep: Sweep = sweep) -> None:
                step = len(sweep.records) - 1
                for row in record["modes"]:
                    modulus = abs(complex(row["re"], row["im"]))
                    table.write({"method": method, args.param_name: record["p"], **row,
                                 "damping_ratio": -row["re"] / modulus if modulus else 0.0})
                growing = sweep.unstable(modes)
                if args.vectors:
                    for mode in growing:
                        whole = comm.gather(mode.vector, root=0)
                        if whole is not None:  # rank 0
                            vectors_dir.mkdir(exist_ok=True)
                            np.save(vectors_dir / f"{method}_p{step:03d}_mode{mode.ident}.npy",
                                    np.concatenate(whole))
                flagged = sum(not m.accurate for m in modes)
                log.info(f"{method:10s} {args.param_name}={record['p']:.6g}  {len(modes)} in band"
                         f"  max Re λ={record['max_re']:.4g}  growing: "
                         f"{[m.ident for m in growing]}"
                         + (f"  ({flagged} inaccurate)" if flagged else ""))
                stop.check(f"{method} {args.param_name} = {record['p']:.6g} (value {step + 1} "
                           f"of {len(args.param_values)})")

            t0 = time.perf_counter()
            try:
                sweep.follow(args.param_values, on_step=on_step)
                events[method] = sweep.coalescences()
                if args.refine_tol is not None:
                    events[method] = [sweep.refine(e, args.refine_tol) for e in events[method]]
            except EigenSolveError as err:
                failure = f"{method} at {args.param_name} after {len(sweep.records)} values: {err}"
            except Interrupted as err:
                interrupted = err
            timings[method] = time.perf_counter() - t0
            if failure is not None or interrupted is not None:
                break
    write(failure, None if interrupted is None else str(interrupted))
    for method, sweep in sweeps.items():
        if comm.rank == 0 and sweep.records:
            plot_coupling_map(sweep.records, out / f"coupling_map_{method}.png",
                              events.get(method, []), args.param_name)
        for e in events.get(method, []):
            log.info(f"{method}: mode {e.growing} grows past {args.param_name} = {e.p_crit:.8g} "
                     f"(bracket {e.onset[0]:.8g} to {e.onset[1]:.8g}) at {e.frequency:.6g} Hz, "
                     f"modes {e.modes} at relative frequency gap {e.gap[0]:.3g} -> "
                     f"{e.gap[1]:.3g}")
    comm.Barrier()
    log.info(f"results in {out}/: eigenvalues.csv, eigenvalues.json, unstable.json, "
             f"summary.json, coupling_map_*.png" + (", vectors/" if args.vectors else ""))
    return stopped(failure, interrupted)
