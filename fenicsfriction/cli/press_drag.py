"""``fenicsfriction contact press-drag``: the cylinder pressed onto the block and dragged, in
time (:class:`~fenicsfriction.studies.contact.impact.PressAndDrag`), with its energy balance.

Writes to ``--out``: ``contact.json`` (the summary: ``energy_balance_error``, the drift of
kinetic + elastic + stored − work + dissipated over the largest work of the loads; the largest
penetration, cut-backs, Newton iterations, wall time), ``energy.csv`` (the energies at every
step) and ``energy.png`` (the energies and the balance's drift against time). One progress line
every ``--stride`` steps; a step size that does not resolve the contact springs' period is
said in one line. Ctrl-C stops at the end of a step and writes what was computed (exit status
130); a diverged integration writes its summary and ends with one line (exit status 1).
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import pathlib
import typing

if typing.TYPE_CHECKING:
    from mpi4py import MPI

__all__ = ["add_parser", "run_press_drag"]


def add_parser(scenes: typing.Any,
               discretisation: typing.Callable[[argparse.ArgumentParser], None]) -> None:
    """The ``press-drag`` scene of ``fenicsfriction contact``; ``discretisation`` adds the
    contact scenes' ``--formulation`` and ``--degree``."""
    parser = scenes.add_parser(
        "press-drag", help="the cylinder pressed and dragged, in time: its energy balance",
        description="The 2D cylinder under a load switched on at t = 0 falls onto the block; "
                    "a tangential traction q μP drags it from --drag-start to --drag-end. "
                    "Integrated by the energy-consistent midpoint step (default) or "
                    "generalized-α; writes contact.json (energy_balance_error), energy.csv "
                    "and energy.png. PETSc options as -press_<option> after the flags.")
    parser.add_argument("--eps", type=float,
                        help="regularisation ε of the slip rate [length/time] (1e-3)")
    parser.add_argument("--dt", type=float,
                        help="time step; default: 8 steps a period of the contact springs")
    parser.add_argument("--frictionless", action="store_true", help="μ = 0 (no drag)")
    parser.add_argument("--mu", type=float, help="friction coefficient (0.3)")
    parser.add_argument("--c-n", dest="c_n", type=float,
                        help="normal compliance coefficient: p = c_n d (1e3)")
    parser.add_argument("--t-end", dest="t_end", type=float, help="final time (3)")
    parser.add_argument("--drag-start", dest="drag_start", type=float,
                        help="the drag's start (1.5)")
    parser.add_argument("--drag-end", dest="drag_end", type=float, help="the drag's end (2.5)")
    parser.add_argument("--q-ratio", dest="q_ratio", type=float,
                        help="the drag Q/(μP) (1.5: the cylinder slides)")
    parser.add_argument("--h-contact", dest="h_contact", type=float,
                        help="mesh size at the contact (0.05 R: 1,286 unknowns)")
    parser.add_argument("--scheme", choices=["energy", "alpha2"], default="energy",
                        help="energy: the energy-consistent midpoint step; alpha2: "
                             "generalized-α at ρ∞ = 0.8 (energy)")
    discretisation(parser)
    parser.add_argument("--stride", type=int, default=50,
                        help="a progress line every STRIDE steps (50)")
    parser.add_argument("--out", type=pathlib.Path, required=True, help="output folder")


def run_press_drag(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    """Integrate the scene, write its outputs; the exit status."""
    import warnings

    from fenicsfriction import results
    from fenicsfriction.cli.common import output_folder, scene_from_flags, stopped
    from fenicsfriction.laws import check
    from fenicsfriction.results import CsvRows
    from fenicsfriction.signals import Interrupted, StopSignals
    from fenicsfriction.studies.contact import figures
    from fenicsfriction.studies.contact.impact import PressAndDrag, summarise

    check("--stride", args.stride, args.stride >= 1, "must be >= 1")
    check("--mu", args.mu, args.mu is None or not args.frictionless,
          "give --mu or --frictionless, not both")
    scene = scene_from_flags(PressAndDrag, args, **({"mu": 0.0} if args.frictionless else {}))
    if args.dt is not None:
        check("dt", args.dt, 0 < args.dt <= scene.t_end, f"must lie in (0, t_end = {scene.t_end}]")
    out = output_folder(args.out)
    model = scene.build(comm, args.scheme)
    period = scene.contact_period(model)
    dt = scene.default_dt(model) if args.dt is None else args.dt
    log.info(f"press-drag: {model.dofs} dofs on {comm.size} rank(s), scheme {args.scheme}, "
             f"μ = {scene.law.mu:g}, ε = {scene.law.eps:g}, dt = {dt:.4g} (contact period "
             f"{period:.3g}), t_end = {scene.t_end:g}")
    unresolved = scene.unresolved(model, dt)
    if unresolved is not None:
        log.warning(f"warning: {unresolved}")
    records: list[dict] = []
    interrupted = None
    summary: dict = {}
    with StopSignals(comm) as stop, CsvRows(out / "energy.csv", comm) as table:
        def on_step(record: dict) -> None:
            k = len(records)
            records.append(record)
            table.write(record)
            if k % args.stride == 0:
                drift = record["balance"] - records[0]["balance"]
                log.info(f"step {k:6d}  t={record['time']:.4f}  dt={record['dt']:.3g}  "
                         f"Newton {record['newton_iterations']}  cut-backs "
                         f"{record['rejected_steps']}  work {record['work']:.4g}  "
                         f"dissipated {record['dissipated']:.4g}  balance drift {drift:.3g}")
            stop.check(f"t = {record['time']:.6g} (step {k})")

        try:
            with warnings.catch_warnings():  # said above in one line
                warnings.simplefilter("ignore")
                _, summary = scene.run(args.scheme, dt, comm, model, on_step=on_step)
        except Interrupted as err:
            interrupted = err
            summary = {"scheme": args.scheme, "dt": dt, "dofs": model.dofs,
                       **summarise(records), "failure": None}
    summary = {"scene": "press-drag", "parameters": dataclasses.asdict(scene),
               "contact_period": period, "ranks": comm.size, **summary,
               "interrupted": None if interrupted is None else str(interrupted)}
    results.write_summary(out / "contact.json", summary, comm)
    if comm.rank == 0 and len(records) > 1:
        figures.energy_balance_figure(records, summary, out / "energy.png")
    comm.Barrier()
    error = summary["energy_balance_error"]
    log.info(f"energy balance error {'—' if error is None else f'{error:.3e}'} of the work, "
             f"dissipated {summary['dissipated']:.4g}, largest penetration "
             f"{summary['max_penetration']:.3g}, {summary['steps']} steps, "
             f"{summary['rejected_steps']} cut-backs, {summary['newton_iterations']} Newton "
             f"iterations")
    log.info(f"results in {out}/: contact.json, energy.csv, energy.png")
    failure = summary.get("failure")
    return stopped(None if failure is None else f"press-drag: {failure}", interrupted)
