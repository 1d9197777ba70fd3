"""``fenicsfriction steady|stability|dynamics block|block-on-slab``: the finite element block
on a rigid belt or on an elastic slab.

Each command writes what it computes as it goes (``steady.json``/``stability.json`` rewritten
after every μ step, ``timeseries.csv`` one row per time step) and, stopped by a signal or a
solver failure, keeps what it has, writes ``summary.json`` saying where it stopped and returns
non-zero (see :mod:`fenicsfriction.signals`).
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import pathlib
import time
import typing

from mpi4py import MPI

import numpy as np

from fenicsfriction import io, plotting, results
from fenicsfriction.cli.common import flag, output_folder, scene_from_flags, stop_line
from fenicsfriction.laws import check
from fenicsfriction.results import CsvRows
from fenicsfriction.signals import Interrupted, StopSignals
from fenicsfriction.studies.block.slab import SCENES

if typing.TYPE_CHECKING:
    from fenicsfriction.steady import SteadySolver
    from fenicsfriction.studies.block import BlockModel, BlockOnBelt

__all__ = ["run_dynamics", "run_stability", "run_steady"]


def _scene(args: argparse.Namespace, **fixed: typing.Any) -> BlockOnBelt:
    """The scene from the flags that name its fields (unset flags keep its defaults)."""
    from fenicsfriction.cli.arguments import SLAB_FLAGS

    scene_cls = SCENES[args.scene]
    names = {f.name for f in dataclasses.fields(scene_cls)}
    for name in SLAB_FLAGS:
        given = getattr(args, name, None)
        check(flag(name), given, given is None or name in names,
              f"the scene {args.scene} has no slab (use block-on-slab)")
    return scene_from_flags(scene_cls, args, **fixed)


def _build(args: argparse.Namespace) -> tuple[BlockOnBelt, BlockModel, SteadySolver, np.ndarray]:
    """Validate the shared flags and return (scene, model, steady solver, μ targets)."""
    from fenicsfriction.steady import SteadySolver

    check("--mu-max", args.mu_max, np.isfinite(args.mu_max) and args.mu_max >= 0, "must be >= 0")
    check("--steps", args.steps, args.steps >= 1, "must be >= 1")
    check("--max-halvings", args.max_halvings, args.max_halvings >= 0, "must be >= 0")
    scene = _scene(args)
    output_folder(args.out)
    model = scene.build(MPI.COMM_WORLD, with_friction=args.mu_max > 0)
    model.initial_guess()
    solver = SteadySolver(model.residual, prefix="steady_", options=model.solver_options())
    return scene, model, solver, np.linspace(0.0, args.mu_max, args.steps + 1)


def _stopped(failure: str | None, interrupted: Interrupted | None) -> int:
    """The one closing line of a run that did not finish, and its exit status."""
    if interrupted is not None:
        stop_line(f"{interrupted}; the results so far are written")
        return interrupted.exit_code
    if failure is not None:
        stop_line(failure)
        return 1
    return 0


def run_steady(args: argparse.Namespace, log: logging.Logger) -> int:
    """Continuation in μ, the optional ε sequence, fields, JSON and figures."""
    from fenicsfriction.steady import ContinuationError, continuation, epsilon_sequence

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
    eps_records = None
    if args.eps_sequence and failure is None and interrupted is None:
        eps_records = epsilon_sequence(solver, model.eps, args.eps_sequence,
                                       observe=model.quantities)
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
        "failure": failure, "interrupted": None if interrupted is None else str(interrupted)},
        comm)
    plotting.plot_deformed(snapshots, out / "deformed.png", scene.L, scene.H, comm)
    plotting.plot_steady_forces(records, out / "forces.png", scene.spring_height,
                                scene.belt_direction, scene.tipping_limit, comm)
    comm.Barrier()  # every file exists on return, whichever rank asks
    log.info(f"results in {out}/: steady.json, summary.json, steady.xdmf, deformed.png, forces.png"
             + (", epsilon.json" if eps_records else ""))
    return _stopped(failure, interrupted)


def run_stability(args: argparse.Namespace, log: logging.Logger) -> int:
    """Loci of the FE block along μ with the onsets, beside the rigid block's."""
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
    check("--onset-tol", args.onset_tol, args.onset_tol > 0, "must be > 0")
    check("--growth-tol", args.growth_tol, args.growth_tol > 0, "must be > 0")
    t_start = time.perf_counter()
    scene, model, solver, targets = _build(args)
    out: pathlib.Path = args.out
    loci = Loci(solver, StabilitySolver(model.residual, prefix="stability_"), model.mu,
                args.max_frequency, args.growth_tol)
    transitions: list[tuple[float, float, list[Mode]]] = []
    previous: dict[str, typing.Any] = {}
    records: list[dict] = []

    def write(fe: dict, rigid: typing.Any, failure: str | None, interrupted: str | None) -> None:
        results.write_summary(out / "stability.json", {
            "scene": args.scene, "parameters": dataclasses.asdict(scene), "ranks": comm.size,
            "mu_crit": {"fe": fe["mu_crit"], "rigid": rigid.mu_crit if rigid else None},
            "fe": fe, "rigid": rigid, "max_frequency": args.max_frequency,
            "growth_tol": args.growth_tol, "wall_time_s": time.perf_counter() - t_start,
            "failure": failure, "interrupted": interrupted}, comm)

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
    finished = failure is None and interrupted is None
    onsets = [loci.onset(a, b, args.onset_tol, reference=ref)
              for a, b, ref in transitions] if finished else []
    rigid = rigid_loci(scene, targets, args.max_frequency, args.growth_tol,
                       args.onset_tol) if interrupted is None else None
    fe = {"steps": records, "onsets": onsets,
          "mu_crit": onsets[0].mu_crit if onsets else None,
          "unstable_intervals": {str(k): v for k, v in
                                 unstable_intervals(records, args.growth_tol).items()}}
    write(fe, rigid, failure, None if interrupted is None else str(interrupted))
    plotting.plot_loci(records, rigid.steps if rigid else [], out / "loci.png", comm)
    plotting.plot_growth(records, rigid.steps if rigid else [], out / "growth.png", comm)
    comm.Barrier()
    log.info(f"μ_crit: FE {fe['mu_crit']}, rigid {rigid.mu_crit if rigid else None}; FE unstable "
             f"intervals by mode {fe['unstable_intervals']}; rigid "
             f"{rigid.unstable_intervals if rigid else None}")
    log.info(f"results in {out}/: stability.json, loci.png, growth.png, unstable_modes.xdmf")
    return _stopped(failure, interrupted)


def run_dynamics(args: argparse.Namespace, log: logging.Logger) -> int:
    """Steady sliding at μ, a normal velocity kick, then the time integration."""
    from fenicsfriction.dynamics import CentralDifference, DynamicsSolver
    from fenicsfriction.statistics import stick_slip_statistics
    from fenicsfriction.steady import SteadySolver
    from fenicsfriction.timestepping import DynamicsError

    comm = MPI.COMM_WORLD
    check("--mu", args.mu, np.isfinite(args.mu) and args.mu >= 0, "must be >= 0")
    check("--t-end", args.t_end, args.t_end > 0, "must be > 0")
    check("--dt", args.dt, 0 < args.dt <= args.t_end, "must lie in (0, t-end]")
    check("--stride", args.stride, args.stride >= 1, "must be >= 1")
    scene = _scene(args, mu=args.mu)
    check("--scheme", args.scheme, args.scheme == "alpha2" or args.scene == "block",
          f"the scene {args.scene} needs alpha2 (central differences have no contact "
          "couplings)")
    out = output_folder(args.out)
    model = scene.build(comm)
    model.initial_guess()
    steady = SteadySolver(model.residual, prefix="steady_", options=model.solver_options())
    model.slide_to(args.mu, steady)
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

    records: list[dict] = []
    failure, interrupted = None, None
    with StopSignals(comm) as stop, CsvRows(out / "timeseries.csv", comm) as table, \
            io.FieldWriter(out / "dynamics.xdmf", model) as fields:
        def on_step(record: dict) -> None:
            k = len(records)
            records.append(record)
            table.write(record)
            if k % args.stride == 0:
                fields.write(record["time"])
                log.info(f"step {k:6d}  t={record['time']:.4e} s  dt={record['dt']:.2e}  "
                         f"Newton {record['newton_iterations']}  N={record['normal_force']:.4g}"
                         f"  F_T={record['friction_force']:.4g}  stick/slip/open "
                         f"{record['n_stick']}/{record['n_slip']}/{record['n_open']}")
            stop.check(f"t = {record['time']:.6g} s (step {k})")

        try:
            dynamics.run(args.t_end, args.dt, observe=observe, on_step=on_step)
        except DynamicsError as err:
            failure = str(err)
        except Interrupted as err:
            interrupted = err
    statistics = None
    if len(records) > 2:  # over the second half of what was integrated
        statistics = stick_slip_statistics(records, args.mu, float(model.eps.value),
                                           t_from=0.5 * records[-1]["time"])
        if comm.rank == 0:
            plotting.plot_stick_slip({f"U = {scene.belt_speed} cm/s": records},
                                     out / "stick_slip.png", args.mu, float(model.eps.value))
        log.info(f"apparent friction coefficient {statistics.apparent_coefficient:.4f} "
                 f"(μ = {args.mu}), probe node sticks {statistics.probe_stick_fraction:.1%} "
                 f"of the time (second half of the run)")
    results.write_summary(out / "summary.json", {
        "scene": args.scene, "parameters": dataclasses.asdict(scene), "scheme": args.scheme,
        "dt": args.dt, "steps": len(records) - 1, "failure": failure,
        "interrupted": None if interrupted is None else str(interrupted),
        "statistics": statistics}, comm)
    log.info(f"results in {out}/: timeseries.csv, summary.json, dynamics.xdmf, stick_slip.png")
    return _stopped(failure, interrupted)
