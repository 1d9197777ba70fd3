"""``fenicsfriction run CASE.toml --out DIR``: a researcher's own problem from a case file.

The case file (docs/case-files.md) is read and checked on rank 0 before anything is built: a
bad key or value prints one line naming the file, the key, its value and what is allowed, and
exits with status 2. Then the model is built and the analyses the file asks for run in order
(:mod:`fenicsfriction.case.analyses`), serially or under ``mpirun``, writing as they go.
"""

from __future__ import annotations

import argparse
import logging
import pathlib
import typing

__all__ = ["add_parser", "run"]


def add_parser(commands: typing.Any) -> None:
    """``run CASE --out DIR``."""
    parser = commands.add_parser(
        "run", help="run a case file: your mesh, bodies, contacts and analyses",
        description="Build the model a case file describes (TOML: bodies from a gmsh .msh or "
                    "generated, supports, loads, contacts, motion) and run its analyses "
                    "(steady continuation, complex eigenvalue analysis, transient); PETSc "
                    "options as -steady_/-stability_/-dynamics_<option> after the flags.")
    parser.add_argument("case", type=pathlib.Path, help="the case file (.toml)")
    parser.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace, log: logging.Logger) -> int:
    """Read and check the case on rank 0, then build and run it on every rank."""
    from mpi4py import MPI

    from fenicsfriction.case.schema import CaseError, read_case
    from fenicsfriction.cli.common import output_folder, stop_line

    comm = MPI.COMM_WORLD
    case, error = None, None
    if comm.rank == 0:
        try:
            case = read_case(args.case)
        except CaseError as err:
            error = str(err)
    case, error = comm.bcast((case, error), root=0)
    if error is not None:
        raise ValueError(error)
    out = output_folder(args.out, comm)
    from fenicsfriction.case.analyses import run_case

    outcome = run_case(case, out, comm, log)
    if outcome.interrupted is not None:
        stop_line(f"{outcome.interrupted}; the results so far are written", comm)
    elif outcome.failure is not None:
        stop_line(outcome.failure, comm)
    log.info(f"results in {out}/: summary.json, steady.csv, steady.xdmf"
             + (", continuation.png" if outcome.steady else "")
             + (", cea.csv, unstable_modes.xdmf, loci.png, growth.png, coupling_map.png"
                if case.cea else "")
             + (", transient.csv, transient.png" if case.transient else ""))
    return outcome.exit_code
