"""``fenicsfriction block steady|stability|dynamics [--scene block|block-on-slab]``: the
finite element block on a rigid belt or on an elastic slab.

Each command writes what it computes as it goes (``steady.json``/``stability.json`` rewritten
after every μ step, ``timeseries.csv`` one row per time step) and, stopped by a signal or a
solver failure, keeps what it has, writes ``summary.json`` saying where it stopped and returns
non-zero (see :mod:`fenicsfriction.signals`). MPI, PETSc and dolfinx are imported inside the
run functions, after the flags parse.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import pathlib
import time
import typing

from fenicsfriction.cli.arguments import LazyChoices, Parser, floats

if typing.TYPE_CHECKING:
    import numpy as np

    from fenicsfriction.steady import SteadySolver
    from fenicsfriction.studies.block import BlockModel, BlockOnBelt

__all__ = ["add_parser", "run_dynamics", "run_stability", "run_steady"]

#: the scenes, read from the library when a value is checked or the help printed
_SCENES = LazyChoices("fenicsfriction.studies.block.slab", "SCENES")
#: the block-slab contact's discretisations, likewise
_FORMULATIONS = LazyChoices("fenicsfriction.studies.block.slab", "FORMULATIONS")


def _scene_flag(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--scene", choices=_SCENES, default="block",
                        help="block (on a rigid belt) or block-on-slab (on an elastic slab) "
                             "(block)")


def _continuation_flags() -> argparse.ArgumentParser:
    """Flags shared by the studies that follow the steady state in μ (None: scene default)."""
    flags = Parser(add_help=False)
    _scene_flag(flags)
    flags.add_argument("--mu-max", type=float, required=True, help="last friction coefficient")
    flags.add_argument("--steps", type=int, default=30, help="continuation increments (NINCT)")
    flags.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    flags.add_argument("--refine", type=int, default=1, help="mesh refinement (4r × 3r cells)")
    flags.add_argument("--degree", type=int,
                       help="Lagrange degree (block: 2, Q2; block-on-slab: 1, or 2 with "
                            "--formulation mortar)")
    flags.add_argument("--E", type=float, help="Young's modulus [10³ kg cm⁻¹ s⁻²] (1.4e6)")
    flags.add_argument("--B0", type=float, help="breadth out of the plane [cm] (30.5)")
    flags.add_argument("--K-x", type=float, dest="K_x", help="driver spring [10³ kg s⁻²] (11.1)")
    flags.add_argument("--spring-height", type=float, help="spring height [cm] (H/2)")
    flags.add_argument("--belt-speed", type=float, help="belt speed [cm/s] (0.287)")
    flags.add_argument("--belt-direction", type=int, help="+1 or -1 (+1)")
    flags.add_argument("--eps", type=float, help="regularisation ε [cm/s] (1e-3)")
    flags.add_argument("--regularisation", help="c1 or smooth (c1)")
    flags.add_argument("--contact-quadrature",
                       help="gauss, gll or nodal (block: gauss; block-on-slab: nodal, the "
                            "contact's own rule)")
    _slab_flags(flags)
    flags.add_argument("--max-halvings", type=int, default=8,
                       help="step halvings allowed when a continuation step fails")
    return flags


def _slab_flags(parser: argparse.ArgumentParser) -> None:
    """The slab's fields of the scene block-on-slab (None: the scene's defaults)."""
    slab = parser.add_argument_group("block-on-slab (the elastic belt)")
    slab.add_argument("--formulation", choices=_FORMULATIONS,
                      help="the block-slab contact: node-to-segment (nodal rule) or mortar "
                           "(segment-to-segment integration; degree 1 or 2) (node-to-segment)")
    slab.add_argument("--slab-E", type=float, dest="slab_E",
                      help="the slab's Young's modulus [10³ kg cm⁻¹ s⁻²] (the block's E)")
    slab.add_argument("--slab-nu", type=float, help="the slab's Poisson's ratio (the block's ν)")
    slab.add_argument("--slab-thickness", type=float, help="the slab's thickness [cm] (10)")
    slab.add_argument("--slab-length", type=float, help="the slab's length [cm] (3 L)")
    slab.add_argument("--slab-density", type=float,
                      help="the slab's density [10³ kg cm⁻³] (the block's)")


#: the flags of :func:`_slab_flags`, which only the scene block-on-slab accepts
SLAB_FLAGS = ("formulation", "slab_E", "slab_nu", "slab_thickness", "slab_length",
              "slab_density")


def add_parser(commands: typing.Any) -> None:
    """``block steady|stability|dynamics``, each for the scene ``--scene``."""
    family = commands.add_parser(
        "block", help="the finite element block on a belt: steady sliding, stability, dynamics",
        description="The elastic block of Martins, Oden & Simões pressed on a moving belt "
                    "(rigid, or an elastic slab with --scene block-on-slab).")
    studies = family.add_subparsers(dest="study", required=True, parser_class=Parser,
                                    metavar="STUDY")
    shared = _continuation_flags()
    steady = studies.add_parser(
        "steady", parents=[shared], help="steady sliding with continuation in μ (Problem 2)",
        description="Steady sliding solved by Newton (PETSc SNES) at each μ from 0 to --mu-max; "
                    "PETSc options can be given as -steady_<option> after the flags.")
    steady.add_argument("--eps-sequence", type=floats, metavar="E1,E2,...",
                        help="after the continuation, Kalker's sequential ε process at μ-max")
    steady.add_argument("--snapshots", type=int, default=4, help="deformed shapes to draw")
    steady.set_defaults(run=run_steady)
    stability = studies.add_parser(
        "stability", parents=[shared], help="eigenvalue loci and flutter onset (Problem 3)",
        description="Quadratic eigenvalues of the linearised steady sliding (SLEPc PEP) at each "
                    "μ from 0 to --mu-max, FE and rigid model side by side; PETSc/SLEPc options "
                    "as -stability_<option> after the flags.")
    stability.add_argument("--max-frequency", type=float, default=3e4,
                           help="every eigenvalue with |λ| below this [rad/s] is computed")
    stability.add_argument("--onset-tol", type=float, default=1e-4,
                           help="width of the μ interval the onset is bisected to")
    stability.add_argument("--growth-tol", type=float, default=1e-6,
                           help="a mode grows when Re λ > growth-tol |λ|")
    stability.set_defaults(run=run_stability)
    dynamics = studies.add_parser(
        "dynamics", help="dynamics from a perturbed steady state (Problem 1ε, PETSc TS)",
        description="Generalized-α (TSALPHA2) integration from the steady sliding state at --mu "
                    "plus a normal velocity perturbation; TS/SNES options as -dynamics_<option> "
                    "after the flags (e.g. -dynamics_ts_adapt_type basic).")
    _scene_flag(dynamics)
    dynamics.add_argument("--mu", type=float, required=True, help="friction coefficient")
    dynamics.add_argument("--t-end", type=float, required=True, help="final time [s]")
    dynamics.add_argument("--dt", type=float, default=1e-5, help="(initial) time step [s]")
    dynamics.add_argument("--perturbation", type=float, default=-0.01,
                          help="initial normal velocity added to the steady state [cm/s]")
    dynamics.add_argument("--stride", type=int, default=20, help="steps between field outputs")
    dynamics.add_argument("--record-every", type=int, default=1, metavar="K",
                          help="write every K-th time step (and the last) to timeseries.csv; "
                               "the summary's statistics still see every step (1)")
    dynamics.add_argument("--probe-x", type=float,
                          help="abscissa [cm] of the contact node whose tractions are recorded "
                               "(default: L/2, the paper's node 29)")
    dynamics.add_argument("--scheme", choices=["alpha2", "central"], default="alpha2",
                          help="implicit generalized-α, or explicit central differences with "
                               "a lumped mass (dt capped at 0.9 of the stable step)")
    dynamics.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    for flag, dest, kind, text in (
            ("--refine", "refine", int, "mesh refinement (1)"),
            ("--degree", "degree", int, "Lagrange degree (block: 2; block-on-slab: 1, or 2 "
                                        "with --formulation mortar)"),
            ("--belt-speed", "belt_speed", float, "belt speed [cm/s] (0.287)"),
            ("--b-n", "b_n", float, "normal damping [10³ kg cm^(-2-l_n) s⁻¹] (0)"),
            ("--K-x", "K_x", float, "driver spring [10³ kg s⁻²] (11.1)"),
            ("--B0", "B0", float, "breadth [cm] (30.5)"),
            ("--eps", "eps", float, "regularisation ε [cm/s] (1e-3)"),
            ("--regularisation", "regularisation", str, "c1 or smooth (c1)")):
        dynamics.add_argument(flag, dest=dest, type=kind, help=text)
    _slab_flags(dynamics)
    dynamics.set_defaults(run=run_dynamics)


def _scene(args: argparse.Namespace, **fixed: typing.Any) -> BlockOnBelt:
    """The scene from the flags that name its fields (unset flags keep its defaults)."""
    from fenicsfriction.cli.common import flag, scene_from_flags
    from fenicsfriction.laws import check
    from fenicsfriction.studies.block.slab import SCENES

    scene_cls = SCENES[args.scene]
    names = {f.name for f in dataclasses.fields(scene_cls)}
    for name in SLAB_FLAGS:
        given = getattr(args, name, None)
        check(flag(name), given, given is None or name in names,
              f"the scene {args.scene} has no slab and no two-body contact (use "
              "block-on-slab)")
    return scene_from_flags(scene_cls, args, **fixed)


def _build(args: argparse.Namespace) -> tuple[BlockOnBelt, BlockModel, SteadySolver, np.ndarray]:
    """Validate the shared flags and return (scene, model, steady solver, μ targets)."""
    from mpi4py import MPI

    import numpy as np

    from fenicsfriction.cli.common import output_folder
    from fenicsfriction.laws import check
    from fenicsfriction.steady import SteadySolver

    check("--mu-max", args.mu_max, np.isfinite(args.mu_max) and args.mu_max >= 0, "must be >= 0")
    check("--steps", args.steps, args.steps >= 1, "must be >= 1")
    check("--max-halvings", args.max_halvings, args.max_halvings >= 0, "must be >= 0")
    from fenicsfriction.signals import checkpoint

    scene = _scene(args)
    output_folder(args.out)
    model = scene.build(MPI.COMM_WORLD, with_friction=args.mu_max > 0)
    model.initial_guess()
    solver = SteadySolver(model.residual, prefix="steady_", options=model.solver_options(),
                          search_rounds=model.search_rounds)
    checkpoint("the set-up (model built and compiled)")
    return scene, model, solver, np.linspace(0.0, args.mu_max, args.steps + 1)


def run_steady(args: argparse.Namespace, log: logging.Logger) -> int:
    """Continuation in μ, the optional ε sequence, fields, JSON and figures."""
    from mpi4py import MPI

    import numpy as np

    from fenicsfriction import io, plotting, results
    from fenicsfriction.laws import check
    from fenicsfriction.signals import Interrupted, StopSignals
    from fenicsfriction.steady import (
        ContinuationError,
        SolveError,
        continuation,
        epsilon_sequence,
    )

    comm = MPI.COMM_WORLD
    check("--snapshots", args.snapshots, args.snapshots >= 0, "must be >= 0")
    t_start = time.perf_counter()
    scene, model, solver, targets = _build(args)
    out: pathlib.Path = args.out
    wanted = set(np.unique(np.linspace(0, args.steps, args.snapshots).round().astype(int))) \
        if args.snapshots else set()
    snapshots: list = []
    records: list[dict] = []
    ndofs = model.V.dofmap.index_map.size_global * model.V.dofmap.index_map_bs
    log.info(f"{args.scene}: {ndofs} dofs on {comm.size} rank(s), JIT {solver.jit_time_s:.2f} s; "
             f"tipping limit μ = {scene.tipping_limit:.4g} (this mesh and contact quadrature: "
             f"{scene.discrete_tipping_limit:.6g})")

    failure, interrupted = None, None
    with StopSignals(comm) as stop, io.FieldWriter(out / "steady.xdmf", model) as fields:
        def on_step(record: dict) -> None:
            k = len(records)
            records.append({key: v for key, v in record.items() if key != "value"})
            results.write_json(out / "steady.json", records, comm)
            fields.write(record["mu"])
            if k in wanted:
                outline = plotting.cell_outlines(model.residual.u)
                if outline is not None:
                    snapshots.append((record["mu"], *outline))
            log.info(f"step {k:3d}/{args.steps}  μ={record['mu']:.4f}  "
                     f"Newton {record['newton_iterations']:2d}  |R|={record['residual_norm']:.2e}"
                     f"  N={record['normal_force']:.4g}  F_T={record['friction_force']:.4g}  "
                     f"x_cp={record['centre_of_pressure']:.4g}  {record['wall_time_s']:.2f} s")
            stop.check(f"μ = {record['mu']:.6g} (step {k} of {args.steps})")

        try:
            continuation(solver, model.mu, targets, observe=model.quantities,
                         max_halvings=args.max_halvings, on_step=on_step)
        except ContinuationError as err:
            failure = str(err)
        except Interrupted as err:
            interrupted = err
    results.write_json(out / "steady.json", records, comm)
    eps_records: list[dict] | None = None
    eps_start = float(model.eps.value)
    if args.eps_sequence and failure is None and interrupted is None:
        eps_records = []
        try:
            with StopSignals(comm) as stop:
                def on_eps(record: dict) -> None:
                    assert eps_records is not None
                    eps_records.append(record)
                    results.write_json(out / "epsilon.json", eps_records, comm)
                    stop.check(f"ε = {record['eps']:.6g} (ε step {len(eps_records)} of "
                               f"{len(args.eps_sequence)}) at μ = {args.mu_max:.6g}")

                epsilon_sequence(solver, model.eps, args.eps_sequence,
                                 observe=model.quantities, on_step=on_eps)
        except SolveError as err:
            value = args.eps_sequence[len(eps_records)]
            last = (f"ε = {float(model.eps.value):.6g}" if eps_records else
                    f"the continuation's ε = {eps_start:.6g}")
            failure = (f"the ε sequence at μ = {args.mu_max:.6g} failed at ε = {value:.6g} "
                       f"(step {len(eps_records) + 1} of {len(args.eps_sequence)}): {err}; the "
                       f"last converged state ({last}) is written to epsilon_last.xdmf, the ε "
                       "steps done to epsilon.json")
            with io.FieldWriter(out / "epsilon_last.xdmf", model) as last_state:
                last_state.write(float(model.eps.value))
        except Interrupted as err:
            interrupted = err
        results.write_json(out / "epsilon.json", eps_records, comm)
        log.info("sequential ε process at μ = %.4g:\n%12s %12s %14s %8s", args.mu_max, "eps",
                 "change", "F_T/(μN) - 1", "Newton")
        for r in eps_records:
            ratio = r["friction_force"] / (r["mu"] * r["normal_force"]) - 1 if r["mu"] else 0.0
            change = "-" if r["change"] is None else f"{r['change']:.3e}"
            log.info("%12.3e %12s %14.3e %8d", r["eps"], change, ratio, r["newton_iterations"])
    reached = records[-1]["mu"] if records else None  # last target of the μ grid reached
    results.write_summary(out / "summary.json", {
        "scene": args.scene, "parameters": dataclasses.asdict(scene), "ranks": comm.size,
        "dofs": ndofs, "jit_time_s": solver.jit_time_s,
        "wall_time_s": time.perf_counter() - t_start, "mu_reached": reached,
        "mu_last_converged": float(model.mu.value),
        "tipping_limit": scene.tipping_limit,
        "discrete_tipping_limit": scene.discrete_tipping_limit,
        "distance_to_tipping": scene.tipping_limit - float(model.mu.value),
        "eps_last_converged": (float(model.eps.value) if eps_records is not None else None),
        "stage": (None if failure is None and interrupted is None else
                  "ε sequence" if eps_records is not None else "continuation in μ"),
        "failure": failure, "interrupted": None if interrupted is None else str(interrupted)},
        comm)
    plotting.plot_deformed(snapshots, out / "deformed.png", scene.L, scene.H, comm)
    plotting.plot_steady_forces(records, out / "forces.png", scene.spring_height,
                                scene.belt_direction, scene.tipping_limit, comm)
    comm.Barrier()  # every file exists on return, whichever rank asks
    # the figures drawn (rank 0's lists, where they are drawn and this line is logged)
    log.info(f"results in {out}/: steady.json, summary.json, steady.xdmf"
             + (", deformed.png" if snapshots else "") + (", forces.png" if records else "")
             + (", epsilon.json" if eps_records is not None else ""))
    from fenicsfriction.cli.common import stopped
    return stopped(failure, interrupted)


def run_stability(args: argparse.Namespace, log: logging.Logger) -> int:
    """Loci of the FE block along μ with the onsets, beside the rigid block's."""
    from mpi4py import MPI

    from fenicsfriction import io, plotting, results
    from fenicsfriction.laws import check
    from fenicsfriction.signals import Interrupted, StopSignals
    from fenicsfriction.stability import (
        EigenSolveError,
        Loci,
        Mode,
        StabilitySolver,
        unstable_intervals,
    )
    from fenicsfriction.steady import ContinuationError
    from fenicsfriction.studies.block.rigid import rigid_loci

    comm = MPI.COMM_WORLD
    check("--max-frequency", args.max_frequency, args.max_frequency > 0, "must be > 0")
    check("--onset-tol", args.onset_tol, args.onset_tol >= 1e-12 * max(args.mu_max, 1.0),
          "must be >= 1e-12 max(μ-max, 1) (a narrower interval is below round-off: the "
          "bisection would not end)")
    check("--growth-tol", args.growth_tol, args.growth_tol > 0, "must be > 0")
    t_start = time.perf_counter()
    scene, model, solver, targets = _build(args)
    out: pathlib.Path = args.out
    loci = Loci(solver, StabilitySolver(model.residual, prefix="stability_"), model.mu,
                args.max_frequency, args.growth_tol, max_halvings=args.max_halvings)
    transitions: list[tuple[float, float, list[Mode]]] = []
    previous: dict[str, typing.Any] = {}
    records: list[dict] = []

    def write(fe: dict, rigid: typing.Any, failure: str | None, interrupted: str | None,
              stage: str | None = None) -> None:
        results.write_summary(out / "stability.json", {
            "scene": args.scene, "parameters": dataclasses.asdict(scene), "ranks": comm.size,
            "mu_crit": {"fe": fe["mu_crit"], "rigid": rigid.mu_crit if rigid else None},
            "fe": fe, "rigid": rigid, "max_frequency": args.max_frequency,
            "growth_tol": args.growth_tol, "wall_time_s": time.perf_counter() - t_start,
            "stage": stage, "failure": failure, "interrupted": interrupted}, comm)

    failure, interrupted = None, None
    with StopSignals(comm) as stop, io.ModeWriter(out / "unstable_modes.xdmf", model) as shapes:
        def on_step(record: dict, modes: list[Mode]) -> None:
            records.append(record)
            growing = loci.unstable(modes)
            if previous and growing and not loci.unstable(previous["modes"]):
                transitions.append((previous["mu"], record["mu"], previous["modes"]))
            if growing:
                shapes.write(max(growing, key=lambda m: m.value.real), record["mu"])
            previous.update(mu=record["mu"], modes=modes)
            flagged = sum(not m["accurate"] for m in record["modes"])
            log.info(f"μ={record['mu']:.4f}  {len(modes)} modes  max Re λ={record['max_re']:.4g}"
                     f"  growing: {[m.ident for m in growing]}"
                     + (f"  ({flagged} inaccurate)" if flagged else ""))
            write({"steps": records, "onsets": [], "mu_crit": None, "unstable_intervals": {}},
                  None, None, "in progress")
            stop.check(f"μ = {record['mu']:.6g} (step {len(records) - 1} of {args.steps})")

        try:
            loci.follow(targets, on_step=on_step)
        except (ContinuationError, EigenSolveError) as err:
            failure = f"at μ = {float(model.mu.value):.6g}: {err}"
        except Interrupted as err:
            interrupted = err
    onsets = []
    stage = "continuation in μ" if failure is not None or interrupted is not None else None
    if failure is None and interrupted is None:
        with StopSignals(comm) as stop:
            for k, (a, b, ref) in enumerate(transitions):
                try:
                    onsets.append(loci.onset(a, b, args.onset_tol, reference=ref))
                    stop.check(f"the onset bisection in [{a:.6g}, {b:.6g}] ({k + 1} of "
                               f"{len(transitions)})")
                except (ContinuationError, EigenSolveError, ValueError) as err:
                    stage = "onset bisection"
                    failure = (f"the onset bisection in μ ∈ [{a:.6g}, {b:.6g}] failed at μ = "
                               f"{float(model.mu.value):.6g}: {err}; the loci of every grid "
                               f"step and the {len(onsets)} onset(s) found before are written "
                               "to stability.json")
                    break
                except Interrupted as err:
                    stage, interrupted = "onset bisection", err
                    break
    rigid = rigid_loci(scene, targets, args.max_frequency, args.growth_tol,
                       args.onset_tol) if interrupted is None else None
    fe = {"steps": records, "onsets": onsets,
          "mu_crit": onsets[0].mu_crit if onsets else None,
          "unstable_intervals": {str(k): v for k, v in
                                 unstable_intervals(records, args.growth_tol).items()}}
    write(fe, rigid, failure, None if interrupted is None else str(interrupted), stage)
    plotting.plot_loci(records, rigid.steps if rigid else [], out / "loci.png", comm)
    plotting.plot_growth(records, rigid.steps if rigid else [], out / "growth.png", comm)
    comm.Barrier()
    log.info(f"μ_crit: FE {fe['mu_crit']}, rigid {rigid.mu_crit if rigid else None}; FE unstable "
             f"intervals by mode {fe['unstable_intervals']}; rigid "
             f"{rigid.unstable_intervals if rigid else None}")
    log.info(f"results in {out}/: stability.json, loci.png, growth.png, unstable_modes.xdmf")
    from fenicsfriction.cli.common import stopped
    return stopped(failure, interrupted)


def run_dynamics(args: argparse.Namespace, log: logging.Logger) -> int:
    """Steady sliding at μ, a normal velocity kick, then the time integration."""
    from mpi4py import MPI

    import numpy as np

    from fenicsfriction import io, plotting, results
    from fenicsfriction.cli.common import output_folder, stopped
    from fenicsfriction.dynamics import CentralDifference, DynamicsSolver
    from fenicsfriction.laws import check
    from fenicsfriction.results import CsvRows, RunningStatistics, SampledRecords
    from fenicsfriction.signals import Interrupted, StopSignals, checkpoint
    from fenicsfriction.statistics import mean_force_figures, stick_slip_statistics
    from fenicsfriction.steady import ContinuationError, SteadySolver
    from fenicsfriction.timestepping import DynamicsError

    comm = MPI.COMM_WORLD
    check("--mu", args.mu, np.isfinite(args.mu) and args.mu >= 0, "must be >= 0")
    check("--t-end", args.t_end, args.t_end > 0, "must be > 0")
    check("--dt", args.dt, 0 < args.dt <= args.t_end, "must lie in (0, t-end]")
    check("--stride", args.stride, args.stride >= 1, "must be >= 1")
    check("--record-every", args.record_every, args.record_every >= 1, "must be >= 1")
    scene = _scene(args, mu=args.mu)
    # beyond the tipping limit no steady sliding exists to start from: refuse before meshing
    check("--mu", args.mu, args.mu < scene.discrete_tipping_limit,
          f"must be < {scene.discrete_tipping_limit:.6g}, the tipping limit of this block "
          f"(L/(2 h_s) = {scene.tipping_limit:.6g}, less the outermost contact point's inset): "
          "beyond it no steady sliding exists to start the dynamics from")
    check("--scheme", args.scheme, args.scheme == "alpha2" or args.scene == "block",
          f"the scene {args.scene} needs alpha2 (central differences have no contact "
          "couplings)")
    out = output_folder(args.out)
    t_start = time.perf_counter()
    model = scene.build(comm)
    model.initial_guess()
    steady = SteadySolver(model.residual, prefix="steady_", options=model.solver_options(),
                          search_rounds=model.search_rounds)
    checkpoint("the set-up (model built and compiled)")

    def summary(**fields: typing.Any) -> None:
        results.write_summary(out / "summary.json", {
            "scene": args.scene, "parameters": dataclasses.asdict(scene), "scheme": args.scheme,
            "dt": args.dt, "record_every": args.record_every,
            "wall_time_s": time.perf_counter() - t_start, **fields}, comm)

    try:
        model.slide_to(args.mu, steady)
    except ContinuationError as err:
        reached = float(err.records[-1]["value"]) if err.records else None
        with io.FieldWriter(out / "slide.xdmf", model) as last_state:
            last_state.write(float(model.mu.value))
        kept = ("no steady state converged (the initial guess is written to slide.xdmf)"
                if reached is None else
                f"the last converged steady state (μ = {reached:.6g}) is written to slide.xdmf")
        halt = (f"the slide to μ = {args.mu:.6g} (the steady state the run starts from) "
                f"failed: {err}; no time step taken, {kept}")
        summary(stage="slide to μ", mu_last_converged=reached, steps=0, failure=halt,
                interrupted=None, statistics=None, running_statistics=None)
        return stopped(halt, None)
    checkpoint(f"the set-up (steady sliding at μ = {args.mu:.6g})")
    model.perturb_normal_velocity(args.perturbation)
    dynamics: CentralDifference | DynamicsSolver
    if args.scheme == "central":
        dynamics = CentralDifference(model.residual, band_damping=model.band_damping())
        log.info(f"central differences: stable step {dynamics.stable_dt_elastic:.3e} s "
                 f"(elastic), {dynamics.stable_dt_band:.3e} s (stick band), using "
                 f"{min(args.dt, dynamics.safety * dynamics.stable_dt):.3e} s")
    else:
        dynamics = DynamicsSolver(model.residual, prefix="dynamics_",
                                  atol=1e-10 * model.force_scale)
    observe = model.dynamics_observer(args.probe_x)

    # every step feeds the running statistics; a bounded sample is kept for the figures and
    # the stick-slip statistics; every K-th step goes to the table: memory stays flat
    whole, window = RunningStatistics(), RunningStatistics(t_from=0.5 * args.t_end)
    sampled = SampledRecords()
    steps = [0]
    last: dict[str, typing.Any] = {}
    failure, interrupted = None, None
    with StopSignals(comm) as stop, CsvRows(out / "timeseries.csv", comm) as table, \
            io.FieldWriter(out / "dynamics.xdmf", model) as fields:
        def on_step(record: dict) -> None:
            k = steps[0]
            steps[0] += 1
            for accumulator in (whole, window, sampled):
                accumulator.add(record)
            last.update(record=record, written=k % args.record_every == 0)
            if last["written"]:
                table.write(record)
            if k % args.stride == 0:
                fields.write(record["time"])
                log.info(f"step {k:6d}  t={record['time']:.4e} s  dt={record['dt']:.2e}  "
                         f"Newton {record['newton_iterations']}  N={record['normal_force']:.4g}"
                         f"  F_T={record['friction_force']:.4g}  stick/slip/open "
                         f"{record['n_stick']}/{record['n_slip']}/{record['n_open']}")
            stop.check(f"t = {record['time']:.6g} s (step {k})")

        try:
            dynamics.run(args.t_end, args.dt, observe=observe, on_step=on_step,
                         keep_records=False)
        except DynamicsError as err:
            failure = str(err)
        except Interrupted as err:
            interrupted = err
        if last and not last["written"]:  # the last step is always in the table
            table.write(last["record"])
    statistics = None
    records = sampled.records()
    if len(records) > 2:  # over the second half of what was integrated
        statistics = stick_slip_statistics(records, args.mu, float(model.eps.value),
                                           t_from=0.5 * records[-1]["time"])
        # the run's totals from every step, not the sample
        exact: dict[str, typing.Any] = {
            "steps": whole.count - 1, "newton_iterations": whole.totals["newton_iterations"],
            "rejected_steps": whole.totals["rejected_steps"]}
        if "energy_error" in whole:
            exact["max_energy_error"] = whole["energy_error"]["max_abs"]
        if failure is None and interrupted is None and window.count > 2:
            # the second half of the run as asked: its means from every step
            exact.update(t_from=window.t_first, **mean_force_figures(
                window.mean("normal_force"), window.mean("friction_force"),
                (window["normal_force"]["min"], window["normal_force"]["max"]), args.mu))
        statistics = dataclasses.replace(statistics, **exact)
        if comm.rank == 0:
            plotting.plot_stick_slip({f"U = {scene.belt_speed} cm/s": records},
                                     out / "stick_slip.png", args.mu, float(model.eps.value))
        log.info(f"apparent friction coefficient {statistics.apparent_coefficient:.4f} "
                 f"(μ = {args.mu}), probe node sticks {statistics.probe_stick_fraction:.1%} "
                 f"of the time (second half of the run)")
    summary(steps=whole.count - 1, failure=failure,
            interrupted=None if interrupted is None else str(interrupted),
            stage=None if failure is None and interrupted is None else "time integration",
            statistics=statistics, sampled_every=sampled.stride,
            running_statistics=whole.to_json())
    log.info(f"results in {out}/: timeseries.csv, summary.json, dynamics.xdmf, stick_slip.png")
    return stopped(failure, interrupted)
