"""Command line: ``fenicsfriction steady block --mu-max 1.5 --steps 30 --out DIR``.

One module per family of commands: :mod:`~fenicsfriction.cli.block` (the finite element block:
``steady``, ``stability``, ``dynamics``), :mod:`~fenicsfriction.cli.oscillators` (the reduced
oscillators: ``stability-map``, ``oscillator``) and :mod:`~fenicsfriction.cli.contact` (two
elastic bodies in contact: ``contact hertz|patch|cattaneo``), :mod:`~fenicsfriction.cli.rolling`
(steady rolling: ``rolling fastsim|fe|curve``); :mod:`~fenicsfriction.cli.common`
holds what they share. The flags are in :mod:`~fenicsfriction.cli.arguments`, which imports
nothing heavy: the command's module (MPI, PETSc, dolfinx) is imported after the flags parse,
so ``--help`` and a flag error answer at once.

User errors (a bad flag or parameter value, an unwritable ``--out``) print one line and exit
with status 2; a solver failure writes what converged, prints one line and exits with
status 1; SIGINT/SIGTERM stop the run at the next step with everything computed so far written,
one line, and status 130/143.
"""

from __future__ import annotations

import importlib
import logging
import sys

from fenicsfriction.cli.arguments import (
    Parser,
    add_block_parsers,
    add_contact_parsers,
    add_interface_parsers,
    add_oscillator_parsers,
    add_rolling_parsers,
)

__all__ = ["main"]

# command -> (module of fenicsfriction.cli, function), imported once the flags have parsed
COMMANDS = {"steady": ("block", "run_steady"), "stability": ("block", "run_stability"),
            "dynamics": ("block", "run_dynamics"),
            "stability-map": ("oscillators", "run_stability_map"),
            "oscillator": ("oscillators", "run_oscillator"),
            "contact": ("contact", "run_contact"), "rolling": ("rolling", "run_rolling"),
            "interface": ("interface", "run_interface")}


#: the root logger's handler while a command runs: warnings and errors only
_WARNINGS_ONLY = logging.StreamHandler()
_WARNINGS_ONLY.setLevel(logging.WARNING)
_WARNINGS_ONLY.setFormatter(logging.Formatter("%(levelname)s:%(name)s:%(message)s"))


def _parser() -> Parser:
    parser = Parser(prog="fenicsfriction", description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    add_block_parsers(commands)
    add_oscillator_parsers(commands)
    add_contact_parsers(commands)
    add_rolling_parsers(commands)
    add_interface_parsers(commands)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``fenicsfriction`` console script and ``python -m fenicsfriction``."""
    argv = sys.argv[1:] if argv is None else list(argv)
    # everything after the first PETSc-style option (-prefix_name) goes to PETSc
    split = next((i for i, a in enumerate(argv) if a.startswith("-") and not a.startswith("--")
                  and len(a) > 2 and not a[1].isdigit()), len(argv))
    args = _parser().parse_args(argv[:split])
    if split < len(argv):
        from petsc4py import PETSc
        PETSc.Options().insertString(" ".join(argv[split:]))
    logging.getLogger("ffcx").setLevel(logging.WARNING)
    logging.getLogger("UFL").setLevel(logging.WARNING)
    logging.getLogger().setLevel(logging.WARNING)
    # the just-in-time compiler's build (setuptools) configures the root logger at INFO the
    # first time a form is compiled, unless it has a handler already: one that passes only
    # warnings keeps its build lines off the terminal
    if _WARNINGS_ONLY not in logging.getLogger().handlers:  # once: main() may run many times
        logging.getLogger().addHandler(_WARNINGS_ONLY)
    from mpi4py import MPI

    from fenicsfriction.results import blas_library, get_logger
    log = get_logger(MPI.COMM_WORLD)
    blas = blas_library()
    if blas["optimized"] is False:
        log.warning("fenicsfriction: the reference BLAS is in use (%s): direct solvers and "
                    "eigensolvers run 2-3x slower; install an optimized one (Debian: "
                    "libopenblas0-serial)", ", ".join(blas["paths"]))
    module, function = COMMANDS[args.command]
    run = getattr(importlib.import_module(f"fenicsfriction.cli.{module}"), function)
    try:
        return run(args, log)
    except ValueError as err:
        if MPI.COMM_WORLD.rank == 0:
            print(f"fenicsfriction: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # a second signal inside a step: no summary, but no traceback
        print("fenicsfriction: interrupted inside a step; the rows written so far are kept",
              file=sys.stderr)
        return 130
