"""``fenicsfriction oscillators slider-map|slider|belt``: the reduced friction oscillators (the
m.d.o.f. slider with oscillatory normal forces, "Friction-induced sliding instability in a
multi-degree-of-freedom system with oscillatory normal forces" (2003), and the 1-d.o.f.
oscillator on a belt).

Both time series are written row by row as the integration samples them; a signal stops the run
at the next sample, a failure of the integration where it failed, with what was computed kept
(see :mod:`fenicsfriction.signals`). MPI and PETSc are imported inside the run functions.
"""

from __future__ import annotations

import argparse
import functools
import logging
import pathlib
import time
import typing

from fenicsfriction.cli.arguments import LazyChoices, Parser, omega_range

if typing.TYPE_CHECKING:
    import numpy as np

    from fenicsfriction.results import CsvRows

__all__ = ["add_parser", "run_oscillator", "run_stability_map"]


def add_parser(commands: typing.Any) -> None:
    """``oscillators slider-map|slider|belt``."""
    family = commands.add_parser(
        "oscillators", help="reduced friction oscillators: the m.d.o.f. slider, the belt",
        description="The m.d.o.f. slider under oscillatory normal forces (its stability map "
                    "and its stick-slip response) and the 1-d.o.f. oscillator on a belt.")
    studies = family.add_subparsers(dest="study", required=True, parser_class=Parser,
                                    metavar="STUDY")
    readings = {"choices": LazyChoices("fenicsfriction.studies.oscillators.slider.table2",
                                       "TABLE2_READINGS"),
                "default": "paper",
                "metavar": "READING",
                "help": "reading of the paper's dimensionless Table 2 model: %(choices)s "
                        "(default: %(default)s)"}
    smap = studies.add_parser(
        "slider-map", help="stability of steady sliding vs forcing frequency (m.d.o.f. slider)",
        description="Growth rate of perturbations of steady sliding of the Table 2 slider by "
                    "first-order averaging and by Floquet multipliers (PETSc TS), with the "
                    "unstable bands.")
    smap.add_argument("--omega-range", type=omega_range, required=True, metavar="LO:HI")
    smap.add_argument("--samples", type=int, default=101, help="forcing frequencies sampled")
    smap.add_argument("--methods", default="averaging,floquet",
                      help="comma-separated: averaging, floquet")
    smap.add_argument("--reading", **readings)
    smap.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    smap.set_defaults(run=run_stability_map)
    time_response = Parser(add_help=False)
    time_response.add_argument("--t-end", type=float, default=100.0,
                               help="final (dimensionless) time")
    time_response.add_argument("--eps", type=float,
                               help="regularised law of this width (no events)")
    time_response.add_argument("--rtol", type=float, default=1e-8,
                               help="relative tolerance of the steps")
    time_response.add_argument("--sample-dt", type=float, default=0.01,
                               help="output sampling step")
    time_response.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    mdof = studies.add_parser(
        "slider", parents=[time_response],
        help="stick-slip time response of the m.d.o.f. slider (Table 2)",
        description="Integrates the m.d.o.f. slider with stick and slip switched at events "
                    "located by PETSc TS (or a regularised law with --eps); TS options as "
                    "-hybrid_<option>.")
    mdof.add_argument("--omega", type=float, default=30.78, help="forcing frequency ω_o")
    mdof.add_argument("--reading", **readings)
    mdof.add_argument("--normal-force", choices=["signed", "absolute", "clipped"],
                      default="signed", help="how N enters friction (signed, as eq. 21)")
    mdof.add_argument("--coupled", action="store_true",
                      help="the roughness under a contact follows its tangential motion")
    mdof.add_argument("--perturbation", type=float, default=0.01,
                      help="initial slider velocity added to steady sliding")
    mdof.set_defaults(run=run_oscillator, scene="mdof")
    belt = studies.add_parser(
        "belt", parents=[time_response],
        help="stick-slip time response of the 1-d.o.f. oscillator on a belt",
        description="Integrates m ẍ + c ẋ + k x = μ(v_b − ẋ) N with stick and slip switched at "
                    "events located by PETSc TS (or a regularised law with --eps); TS options "
                    "as -belt_<option>.")
    for flag, default, text in (("--m", 1.0, "mass"), ("--k", 1.0, "stiffness"),
                                ("--c", 0.0, "damping"), ("--N", 1.0, "normal force"),
                                ("--v-belt", 0.5, "belt speed"),
                                ("--mu-s", 0.6, "static coefficient"),
                                ("--mu-k", 0.3, "kinetic coefficient (constant, stribeck)"),
                                ("--slope", 0.03, "dμ/d|v| (piecewise)"),
                                ("--v-c", 15.0, "end of the slope (piecewise)"),
                                ("--v-s", 0.5, "Stribeck speed (stribeck)")):
        belt.add_argument(flag, type=float, default=default, help=f"{text} ({default})")
    belt.add_argument("--law", choices=["constant", "piecewise", "stribeck"],
                      default="constant", help="μ(v) while slipping (constant: μ_k, with μ_s "
                                               "for stick)")
    belt.add_argument("--x0", type=float, default=0.0, help="initial displacement (0)")
    belt.add_argument("--v0", type=float,
                      help="initial velocity (the belt's: the mass starts stuck to the belt)")
    belt.set_defaults(run=run_oscillator, scene="belt")


def run_stability_map(args: argparse.Namespace, log: logging.Logger) -> int:
    """Averaging and Floquet growth rates over a range of forcing frequencies, with bands."""
    from mpi4py import MPI

    import numpy as np

    from fenicsfriction import plotting, results
    from fenicsfriction.cli.common import output_folder
    from fenicsfriction.laws import check
    from fenicsfriction.studies.oscillators.slider import (
        TABLE2_PAPER_BANDS,
        stability_map,
        table2_slider,
    )

    lo, hi = args.omega_range
    check("--omega-range", f"{lo:g}:{hi:g}", 0 < lo < hi, "needs 0 < LO < HI")
    check("--samples", args.samples, args.samples >= 2, "must be >= 2")
    out = output_folder(args.out)
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    result = stability_map(functools.partial(table2_slider, reading=args.reading),
                           np.linspace(lo, hi, args.samples), methods=methods)
    for method in methods:
        bands = [(round(a, 3), round(b, 3)) for a, b in result.bands[method]]
        per_omega = result.seconds[method] / args.samples * 1e3
        log.info(f"{method}: unstable bands {bands} ({per_omega:.2f} ms per ω_o)")
    paper = [list(band) for band in TABLE2_PAPER_BANDS]
    slider = table2_slider(lo, reading=args.reading)
    results.write_json(out / "stability_map.json", {
        "reading": args.reading, "natural_frequencies": slider.natural_frequencies()[0],
        "omega": result.omega, "growth": result.growth, "bands": result.bands,
        "seconds_per_omega": {k: v / args.samples for k, v in result.seconds.items()},
        "paper_bands": paper})
    if MPI.COMM_WORLD.rank == 0:
        plotting.plot_stability_map(result.omega, result.growth, result.bands,
                                    out / "stability_map.png", reference_bands=TABLE2_PAPER_BANDS)
    MPI.COMM_WORLD.Barrier()
    return 0


def _belt(args: argparse.Namespace, table: CsvRows,
          progress: typing.Callable[[float, typing.Any], None]) -> tuple[dict, tuple]:
    """The belt oscillator's run, its table written one sample at a time.

    Args:
        args: the parsed flags.
        table: receives the row (t, x, v, friction_force, stick) of every sample.
        progress: called with (t, mode) after each sample (reports, stops on a signal).

    Returns:
        (summary, what to plot).
    """
    import numpy as np

    from fenicsfriction import laws
    from fenicsfriction.statistics import belt_summary
    from fenicsfriction.studies.oscillators import BeltOscillator
    from fenicsfriction.studies.oscillators.belt import STICK

    law: dict[str, typing.Callable[[], laws.FrictionCoefficient]] = {
           "constant": lambda: laws.ConstantFriction(args.mu_k),
           "piecewise": lambda: laws.PiecewiseLinearFriction(args.mu_s, args.slope, args.v_c),
           "stribeck": lambda: laws.StribeckFriction(args.mu_s, args.mu_k, args.v_s)}
    oscillator = BeltOscillator(args.m, args.k, args.c, args.N, args.v_belt,
                                law[args.law](), mu_static=args.mu_s)
    method = "events" if args.eps is None else "regularised"

    def friction(y: np.ndarray, mode: typing.Any) -> float:
        """The friction force of the sample, as :meth:`BeltOscillator.simulate` reports it."""
        if method == "regularised":
            return float(oscillator.regularised_force(np.array([args.v_belt - y[1]]),
                                                      args.eps)[0])
        return oscillator.friction_force(y, mode)

    def observe(t: float, y: np.ndarray, mode: typing.Any) -> dict:
        table.write({"t": t, "x": y[0], "v": y[1], "friction_force": friction(y, mode),
                     "stick": int(mode == STICK)})
        progress(t, mode)
        return {}

    run = oscillator.simulate(args.t_end, x0=args.x0,
                              v0=args.v_belt if args.v0 is None else args.v0, method=method,
                              eps=args.eps, rtol=args.rtol, atol=1e-2 * args.rtol,
                              sample_dt=args.sample_dt, observe=observe)
    summary = belt_summary(run).to_json()
    # stick_fraction stays the last cycle's, beside its period and amplitude (and the classic
    # cycle's); the whole run's, start-up included, is stick_fraction_run
    summary = {**summary, "effective_damping": oscillator.effective_damping(),
               "steady_sliding_stable": oscillator.is_steady_sliding_stable(),
               "linear_eigenvalues": [[s.real, s.imag]
                                      for s in oscillator.linear_eigenvalues()]}
    if args.law == "constant" and args.c == 0 and args.mu_s > args.mu_k:
        summary["classic_cycle"] = oscillator.classic_limit_cycle().to_json()
    plot = (run.t, run.x, run.v, args.v_belt, run.stick_intervals, ("x", "ẋ"))
    return summary, plot


def _slider(args: argparse.Namespace, table: CsvRows,
            progress: typing.Callable[[float, typing.Any], None]) -> tuple[dict, tuple,
                                                                            str | None]:
    """The m.d.o.f. slider's run, its table written one sample at a time.

    Args:
        args: the parsed flags.
        table: receives the row (t, y_s, y_1, x_1, v_s, v_1, normal_force, friction_force,
            stick) of every sample.
        progress: called with (t, mode) after each sample (reports, stops on a signal).

    Returns:
        (summary, what to plot, the failure of the integration or None). A run the
        integration could not finish is summarised up to where it stopped.
    """
    import numpy as np

    from fenicsfriction.events import HybridError, integrate_hybrid
    from fenicsfriction.statistics import mode_intervals
    from fenicsfriction.studies.oscillators.slider import SliderMotion, table2_slider

    slider = table2_slider(args.omega, reading=args.reading)
    motion = SliderMotion(slider, normal_force=args.normal_force, coupled=args.coupled,
                          eps=args.eps)
    n = motion.size // 2

    def observe(t: float, y: np.ndarray, mode: typing.Any) -> dict:
        normal, force = motion.contact_forces(t, y, mode)
        table.write({"t": t, "y_s": y[0], "y_1": y[1], "x_1": y[2], "v_s": y[n],
                     "v_1": y[n + 1], "normal_force": normal[0], "friction_force": force[0],
                     "stick": int(mode[0] == 0)})
        progress(t, mode)
        return {}

    failure = None
    try:
        run = integrate_hybrid(motion, motion.initial_state([args.perturbation]),
                               motion.slip_mode(), args.t_end, rtol=args.rtol,
                               atol=1e-2 * args.rtol, sample_dt=args.sample_dt,
                               observe=observe)
    except HybridError as error:
        failure = f"integration stopped at t = {error.t:.6g}: {error}"
        run = error.result
    t, y = run.t, run.y
    stick = mode_intervals(run, lambda mode: mode[0] == 0)
    omega, _ = slider.natural_frequencies()
    late = t >= t[-1] / 2
    summary = {"omega": args.omega, "reading": args.reading, "natural_frequencies": omega,
               "surface_speed": slider.contacts[0].surface_speed,
               "averaged_growth": slider.averaged().growth,
               "floquet_growth": slider.floquet().growth, "events": len(run.events),
               "stick_fraction": sum(b - a for a, b in stick) / t[-1],
               "slider_amplitude_first_half": float(np.ptp(y[~late, 0])) / 2,
               "slider_amplitude_second_half": float(np.ptp(y[late, 0])) / 2,
               "steps": run.steps, "t_end": float(t[-1])}
    if failure is not None:
        summary["failure"] = failure
    plot = (t, y[:, 0], y[:, n + 1], slider.contacts[0].surface_speed, stick,
            ("slider y_s", "velocity of mass 1, ẏ_1"))
    return summary, plot, failure


def run_oscillator(args: argparse.Namespace, log: logging.Logger) -> int:
    """Stick-slip time response of the slider or the belt oscillator: CSV, JSON and a figure.

    ``timeseries.csv`` gets one row per sample as the integration produces it (rank 0 writes;
    every rank integrates the same small system). A signal stops the run at the next sample
    (status 130/143) and a failure of the integration where it failed (status 1); either way
    ``summary.json`` says where and why, the rows stay on disk and one line is printed.
    """
    from mpi4py import MPI

    from fenicsfriction import plotting, results
    from fenicsfriction.cli.common import output_folder, stop_line
    from fenicsfriction.laws import check
    from fenicsfriction.results import CsvRows
    from fenicsfriction.signals import Interrupted, StopSignals
    from fenicsfriction.timestepping import DynamicsError

    check("--t-end", args.t_end, args.t_end > 0, "must be > 0")
    check("--sample-dt", args.sample_dt, 0 < args.sample_dt <= args.t_end,
          "must lie in (0, t-end]")
    if args.scene == "mdof":
        check("--omega", args.omega, args.omega > 0, "must be > 0")
    out = output_folder(args.out)
    comm = MPI.COMM_WORLD
    next_report = [0.0]
    samples = [0.0, 0]  # last sampled time, count
    start = time.perf_counter()

    def stopped(key: str, why: Exception) -> dict:
        """The summary of a run that ended early: what was sampled, and why it ended (both
        keys, the other one null, as every command writes them)."""
        return {"interrupted": None, "failure": None, key: str(why), "t_end": samples[0],
                "samples": samples[1], "wall_seconds": time.perf_counter() - start}

    failure = None
    with StopSignals(comm) as stop, CsvRows(out / "timeseries.csv", comm) as table:
        def progress(t: float, mode: typing.Any) -> None:
            samples[:] = t, samples[1] + 1
            if t >= next_report[0]:
                log.info(f"t = {t:10.4f} / {args.t_end:g}  mode {mode}")
                next_report[0] += args.t_end / 10
            stop.check(f"t = {t:.6g} ({samples[1]} samples)")

        try:
            if args.scene == "belt":
                summary, plot = _belt(args, table, progress)
            else:
                summary, plot, failure = _slider(args, table, progress)
        except Interrupted as err:
            results.write_summary(out / "summary.json", stopped("interrupted", err))
            stop_line(f"{err}; the results so far are written")
            return err.exit_code
        except DynamicsError as err:  # the belt's integration failed: no cycle to summarise
            results.write_summary(out / "summary.json", stopped("failure", err))
            stop_line(f"integration stopped after t = {samples[0]:.6g}: {err}; the results "
                      "so far are written")
            return 1
    summary["wall_seconds"] = time.perf_counter() - start
    if failure is not None:  # the slider's integration failed: its summary says where, too
        summary.update(interrupted=None, samples=samples[1])
    run_stick = summary.get("stick_fraction_run", summary["stick_fraction"])  # belt, slider
    log.info(f"{summary['events']} events, stick fraction {run_stick:.3f} over the run, "
             f"{summary['wall_seconds']:.1f} s")
    results.write_summary(out / "summary.json", summary)
    if comm.rank == 0:
        t, x, v, surface, stick, names = plot
        plotting.plot_oscillator(t, x, v, surface, stick, out / "oscillator.png",
                                 title=f"{args.scene}: {summary['events']} stick/slip events",
                                 names=names)
    comm.Barrier()
    if failure is not None:
        stop_line(f"{failure}; the results so far are written")
        return 1
    return 0
