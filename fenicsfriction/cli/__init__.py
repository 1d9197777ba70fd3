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

import sys
import typing

from fenicsfriction import signals
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
    """Entry point of the ``fenicsfriction`` console script and ``python -m fenicsfriction``.

    SIGINT and SIGTERM are caught from the first line (:func:`fenicsfriction.signals.catch`):
    one during the start-up (flags, MPI, PETSc) waits for its end; one during the set-up
    (mesh, just-in-time compilation, the first steady state; a command with no steps to stop
    at) stops the command at once. Either way ``summary.json`` in ``--out`` says after which
    stage, one line and status 130/143. During the run's steps a signal stops it at the next
    step; after its last step the results are complete and the status is still 130/143.
    """
    previous = signals.catch()
    try:
        return _main(sys.argv[1:] if argv is None else list(argv))
    except KeyboardInterrupt:  # a second signal inside a step: no summary, but no traceback
        print("fenicsfriction: interrupted inside a step; the rows written so far are kept",
              file=sys.stderr, flush=True)
        return 130
    finally:
        signals.release(previous)


def _main(argv: list[str]) -> int:
    """:func:`main` once the signals are caught."""
    # everything after the first PETSc-style option (-prefix_name) goes to PETSc
    split = next((i for i, a in enumerate(argv) if a.startswith("-") and not a.startswith("--")
                  and len(a) > 2 and not a[1].isdigit()), len(argv))
    parser = _parser()
    hint = _old_spelling(argv)
    if hint is not None:
        parser.exit(2, f"fenicsfriction: {hint}\n")
    args = parser.parse_args(argv[:split])
    if split == len(argv):
        return _run(args, argv)
    from fenicsfriction.petsc_options import options_inserted
    with options_inserted(" ".join(argv[split:])):  # this run's only, not the process's
        return _run(args, argv)


def _run(args: typing.Any, argv: list[str]) -> int:
    """The command of the parsed ``args``, its set-up's signals and errors handled."""
    from mpi4py import MPI

    from fenicsfriction.cli.common import stop_line
    from fenicsfriction.results import blas_library, get_logger
    log = get_logger(MPI.COMM_WORLD, progress="stdout")  # and quiets the JIT's build lines
    comm = MPI.COMM_WORLD
    try:
        signals.checkpoint("the start-up (flags read, MPI and PETSc loaded)", comm)
        signals.raise_at_once(comm)  # the set-up's stages need not check
        blas = blas_library()
        if blas["optimized"] is False:
            log.warning("fenicsfriction: the reference BLAS is in use (%s): direct solvers and "
                        "eigensolvers run 2-3x slower; install an optimized one (Debian: "
                        "libopenblas0-serial)", ", ".join(blas["paths"]))
        code = args.run(args, log)
    except ValueError as err:
        if comm.rank == 0:
            print(f"fenicsfriction: error: {err}", file=sys.stderr, flush=True)
        return 2
    except BaseException as err:  # a signal in the set-up, before the run's own steps
        interrupted = signals.interruption(err)  # also inside an import or a PETSc callback
        if interrupted is None:
            raise
        _setup_summary(args, argv, interrupted, comm)
        stop_line(f"{interrupted}; the run had not begun its steps", comm)
        return interrupted.exit_code
    signum = signals.pending_on(comm)
    if signum:  # came after the run's last check: everything is written
        stop_line(f"{signals.Interrupted(signum, 'the run had finished')}; its results are "
                  "complete", comm)
        return 128 + signum
    return code


def _setup_summary(args: typing.Any, argv: list[str], err: Exception, comm: typing.Any) -> None:
    """``summary.json`` in the run's ``--out`` saying the set-up was interrupted (nothing if
    the command has no output folder or it cannot be written)."""
    out = getattr(args, "out", None)
    if out is None:
        return
    from fenicsfriction.cli.common import output_folder
    from fenicsfriction.results import write_summary
    try:
        output_folder(out, comm)
    except ValueError:
        return
    write_summary(out / "summary.json", {
        "command": ["fenicsfriction", *argv], "stage": "set-up", "interrupted": str(err),
        "failure": None}, comm)
