"""Command line: ``fenicsfriction FAMILY STUDY [flags]``, e.g.
``fenicsfriction block steady --mu-max 1.5 --steps 30 --out DIR``.

One module per physics family, each defining its flags (``add_parser``) beside the functions
that run them: :mod:`~fenicsfriction.cli.block` (the finite element block: ``block
steady|stability|dynamics``), :mod:`~fenicsfriction.cli.oscillators` (the reduced oscillators:
``oscillators slider-map|slider|belt``), :mod:`~fenicsfriction.cli.contact` (two elastic bodies
in contact: ``contact hertz|patch|cattaneo``), :mod:`~fenicsfriction.cli.rolling` (steady
rolling: ``rolling fastsim|fe|curve``) and :mod:`~fenicsfriction.cli.multicontact` (Braun's
interface of many contacts: ``multicontact eq|master-equation|stability-map|interaction|fk|
slider``), and :mod:`~fenicsfriction.cli.run` runs a case file (``run CASE.toml``: one's
own problem, docs/case-files.md); :mod:`~fenicsfriction.cli.common` holds what they share
once they run. The family
modules import MPI, PETSc and dolfinx inside their run functions, after the flags parse, so
``--help`` and a flag error answer at once.

User errors (a bad flag or parameter value, an unwritable ``--out``, a command spelled the old
way) print one line and exit with status 2; a solver failure writes what converged, prints one
line and exits with status 1; SIGINT/SIGTERM stop the run at the next step with everything
computed so far written, one line, and status 130/143.
"""

from __future__ import annotations

import logging
import sys

from fenicsfriction.cli import block, cea, contact, multicontact, oscillators, rolling, run
from fenicsfriction.cli.arguments import Parser

__all__ = ["main"]

#: the families, in the order ``--help`` lists them
FAMILIES = (block, oscillators, contact, rolling, multicontact, cea, run)

#: the first words of the old grammar (``COMMAND SCENE``) -> the new spelling of each scene
#: (None: any scene, kept as the study)
RENAMED = {"steady": {"block": "block steady",
                      "block-on-slab": "block steady --scene block-on-slab"},
           "stability": {"block": "block stability",
                         "block-on-slab": "block stability --scene block-on-slab"},
           "dynamics": {"block": "block dynamics",
                        "block-on-slab": "block dynamics --scene block-on-slab"},
           "stability-map": {"mdof": "oscillators slider-map"},
           "oscillator": {"mdof": "oscillators slider", "belt": "oscillators belt"},
           "interface": {}}


def _old_spelling(argv: list[str]) -> str | None:
    """The one line saying how a command of the old grammar is spelled now; None if ``argv``
    does not start with one."""
    if not argv or argv[0] not in RENAMED:
        return None
    old = argv[0]
    second = argv[1] if len(argv) > 1 and not argv[1].startswith("-") else None
    if old == "interface":
        study = second or "STUDY"
        return f"'interface {study}' is now 'multicontact {study}'"
    new = RENAMED[old].get(second or "")
    if new is None:  # no or an unknown scene: every spelling
        return (f"'{old} ...' is now " + " or ".join(
            f"'{n}'" for n in dict.fromkeys(RENAMED[old].values())))
    return f"'{old} {second}' is now '{new}'"


#: the root logger's handler while a command runs, warnings and errors only (made at the
#: first run: its class comes with the MPI-importing results module)
_WARNINGS_ONLY: list[logging.Handler] = []


def _parser() -> Parser:
    parser = Parser(prog="fenicsfriction",
                    description="Friction by finite elements and reduced models: "
                                "fenicsfriction FAMILY STUDY [flags] [PETSc options].")
    commands = parser.add_subparsers(dest="family", required=True, parser_class=Parser,
                                     metavar="FAMILY")
    for family in FAMILIES:
        family.add_parser(commands)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``fenicsfriction`` console script and ``python -m fenicsfriction``."""
    argv = sys.argv[1:] if argv is None else list(argv)
    # everything after the first PETSc-style option (-prefix_name) goes to PETSc
    split = next((i for i, a in enumerate(argv) if a.startswith("-") and not a.startswith("--")
                  and len(a) > 2 and not a[1].isdigit()), len(argv))
    parser = _parser()
    hint = _old_spelling(argv)
    if hint is not None:
        parser.exit(2, f"fenicsfriction: {hint}\n")
    args = parser.parse_args(argv[:split])
    if split < len(argv):
        from petsc4py import PETSc
        PETSc.Options().insertString(" ".join(argv[split:]))
    logging.getLogger("ffcx").setLevel(logging.WARNING)
    logging.getLogger("UFL").setLevel(logging.WARNING)
    logging.getLogger().setLevel(logging.WARNING)
    # the just-in-time compiler's build (setuptools) configures the root logger at INFO the
    # first time a form is compiled, unless it has a handler already: one that passes only
    # warnings keeps its build lines off the terminal
    from mpi4py import MPI

    from fenicsfriction.results import StderrHandler, blas_library, get_logger
    if not _WARNINGS_ONLY:
        handler = StderrHandler()
        handler.setLevel(logging.WARNING)
        handler.setFormatter(logging.Formatter("%(levelname)s:%(name)s:%(message)s"))
        _WARNINGS_ONLY.append(handler)
    if _WARNINGS_ONLY[0] not in logging.getLogger().handlers:  # once: main() runs many times
        logging.getLogger().addHandler(_WARNINGS_ONLY[0])
    log = get_logger(MPI.COMM_WORLD)
    blas = blas_library()
    if blas["optimized"] is False:
        log.warning("fenicsfriction: the reference BLAS is in use (%s): direct solvers and "
                    "eigensolvers run 2-3x slower; install an optimized one (Debian: "
                    "libopenblas0-serial)", ", ".join(blas["paths"]))
    try:
        return args.run(args, log)
    except ValueError as err:
        if MPI.COMM_WORLD.rank == 0:
            print(f"fenicsfriction: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # a second signal inside a step: no summary, but no traceback
        print("fenicsfriction: interrupted inside a step; the rows written so far are kept",
              file=sys.stderr)
        return 130
