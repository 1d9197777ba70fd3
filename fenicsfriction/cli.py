"""Command line: ``fenicsfriction steady block --mu-max 1.5 --steps 30 --out DIR``.

User errors (a bad flag or parameter value) print one line and exit with status 2; a solver
failure writes what converged, prints one line and exits with status 1.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import pathlib
import sys
import time
import typing

import numpy as np

from mpi4py import MPI

__all__ = ["main"]


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> typing.NoReturn:  # one line, no usage block
        self.exit(2, f"{self.prog}: error: {message}\n")


def _floats(text: str) -> list[float]:
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated numbers, got {text!r}") from None


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="fenicsfriction", description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    steady = commands.add_parser(
        "steady", help="steady sliding with continuation in μ (Problem 2)",
        description="Steady sliding solved by Newton (PETSc SNES) at each μ from 0 to --mu-max; "
                    "PETSc options can be given as -steady_<option> after the flags.")
    steady.add_argument("scene", choices=["block"], help="scene to run")
    steady.add_argument("--mu-max", type=float, required=True, help="last friction coefficient")
    steady.add_argument("--steps", type=int, default=30, help="continuation increments (NINCT)")
    steady.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    steady.add_argument("--refine", type=int, default=1, help="mesh refinement (4r × 3r cells)")
    steady.add_argument("--degree", type=int, default=2, help="Lagrange degree (2: Q2)")
    steady.add_argument("--B0", type=float, help="breadth out of the plane [cm] (30.5)")
    steady.add_argument("--K-x", type=float, dest="K_x", help="driver spring [10³ kg s⁻²] (11.1)")
    steady.add_argument("--spring-height", type=float, help="spring height [cm] (H/2)")
    steady.add_argument("--belt-speed", type=float, help="belt speed [cm/s] (0.287)")
    steady.add_argument("--belt-direction", type=int, help="+1 or -1 (+1)")
    steady.add_argument("--eps", type=float, help="regularisation ε [cm/s] (1e-3)")
    steady.add_argument("--regularisation", help="c1 or smooth (c1)")
    steady.add_argument("--contact-quadrature", help="gauss or gll (gauss)")
    steady.add_argument("--eps-sequence", type=_floats, metavar="E1,E2,...",
                        help="after the continuation, Kalker's sequential ε process at μ-max")
    steady.add_argument("--max-halvings", type=int, default=8,
                        help="step halvings allowed when a continuation step fails")
    steady.add_argument("--snapshots", type=int, default=4, help="deformed shapes to draw")
    return parser


def _run_steady(args: argparse.Namespace, log: logging.Logger) -> int:
    from fenicsfriction import io, plotting
    from fenicsfriction.laws import check
    from fenicsfriction.scenes import SCENES
    from fenicsfriction.steady import ContinuationError, SteadySolver, continuation, \
        epsilon_sequence

    comm = MPI.COMM_WORLD
    check("--mu-max", args.mu_max, np.isfinite(args.mu_max) and args.mu_max >= 0, "must be >= 0")
    check("--steps", args.steps, args.steps >= 1, "must be >= 1")
    check("--max-halvings", args.max_halvings, args.max_halvings >= 0, "must be >= 0")
    check("--snapshots", args.snapshots, args.snapshots >= 0, "must be >= 0")
    scene_cls = SCENES[args.scene]
    names = {f.name for f in dataclasses.fields(scene_cls)}
    given = {k: v for k, v in vars(args).items() if k in names and v is not None}
    scene = scene_cls(**given)
    out: pathlib.Path = args.out
    t_start = time.perf_counter()
    model = scene.build(comm, with_friction=args.mu_max > 0)
    model.initial_guess()
    solver = SteadySolver(model.residual, prefix="steady_", options=model.solver_options())
    targets = np.linspace(0.0, args.mu_max, args.steps + 1)
    wanted = set(np.unique(np.linspace(0, args.steps, args.snapshots).round().astype(int))) \
        if args.snapshots else set()
    snapshots, count = [], [0]
    ndofs = model.V.dofmap.index_map.size_global * model.V.dofmap.index_map_bs
    log.info(f"{args.scene}: {ndofs} dofs on {comm.size} rank(s), JIT {solver.jit_time_s:.2f} s; "
             f"tipping limit μ = {scene.tipping_limit:.4g} (this mesh and contact quadrature: "
             f"{scene.discrete_tipping_limit:.6g})")

    with io.FieldWriter(out / "steady.xdmf", model) as fields:
        def on_step(record: dict) -> None:
            k = count[0]
            count[0] += 1
            fields.write(record["mu"])
            if k in wanted:
                outline = plotting.cell_outlines(model.residual.u)
                if outline is not None:
                    snapshots.append((record["mu"], *outline))
            log.info(f"step {k:3d}/{args.steps}  μ={record['mu']:.4f}  "
                     f"Newton {record['newton_iterations']:2d}  |R|={record['residual_norm']:.2e}"
                     f"  N={record['normal_force']:.4g}  F_T={record['friction_force']:.4g}  "
                     f"x_cp={record['centre_of_pressure']:.4g}  {record['wall_time_s']:.2f} s")

        failure = None
        try:
            records = continuation(solver, model.mu, targets, observe=model.quantities,
                                   max_halvings=args.max_halvings, on_step=on_step)
        except ContinuationError as err:
            records, failure = err.records, str(err)
    for r in records:
        r.pop("value")
    io.write_json(out / "steady.json", records, comm)
    eps_records = None
    if args.eps_sequence and failure is None:
        eps_records = epsilon_sequence(solver, model.eps, args.eps_sequence,
                                       observe=model.quantities)
        io.write_json(out / "epsilon.json", eps_records, comm)
        log.info("sequential ε process at μ = %.4g:\n%12s %12s %14s %8s", args.mu_max, "eps",
                 "change", "F_T/(μN) - 1", "Newton")
        for r in eps_records:
            ratio = r["friction_force"] / (r["mu"] * r["normal_force"]) - 1 if r["mu"] else 0.0
            change = "-" if r["change"] is None else f"{r['change']:.3e}"
            log.info("%12.3e %12s %14.3e %8d", r["eps"], change, ratio, r["newton_iterations"])
    reached = records[-1]["mu"] if records else None  # last target of the μ grid reached
    io.write_json(out / "summary.json", {
        "scene": args.scene, "parameters": dataclasses.asdict(scene), "ranks": comm.size,
        "dofs": ndofs, "jit_time_s": solver.jit_time_s,
        "wall_time_s": time.perf_counter() - t_start, "mu_reached": reached,
        "mu_last_converged": float(model.mu.value),
        "tipping_limit": scene.tipping_limit,
        "discrete_tipping_limit": scene.discrete_tipping_limit,
        "distance_to_tipping": scene.tipping_limit - float(model.mu.value),
        "failure": failure}, comm)
    plotting.plot_deformed(snapshots, out / "deformed.png", scene.L, scene.H, comm)
    plotting.plot_steady_forces(records, out / "forces.png", scene.spring_height,
                                scene.belt_direction, scene.tipping_limit, comm)
    comm.Barrier()  # every file exists on return, whichever rank asks
    log.info(f"results in {out}/: steady.json, summary.json, steady.xdmf, deformed.png, forces.png"
             + (", epsilon.json" if eps_records else ""))
    if failure is not None:
        log.error(f"fenicsfriction: {failure}")
        return 1
    return 0


def main(argv: typing.Optional[list[str]] = None) -> int:
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
    from fenicsfriction.io import get_logger
    log = get_logger(MPI.COMM_WORLD)
    try:
        return _run_steady(args, log)
    except ValueError as err:
        if MPI.COMM_WORLD.rank == 0:
            print(f"fenicsfriction: error: {err}", file=sys.stderr)
        return 2
