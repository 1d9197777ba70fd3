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

from mpi4py import MPI

import numpy as np

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


def _scene_flags() -> argparse.ArgumentParser:
    """Flags shared by the commands that build a scene (None: the scene's default)."""
    flags = _Parser(add_help=False)
    flags.add_argument("scene", choices=["block"], help="scene to run")
    flags.add_argument("--mu-max", type=float, required=True, help="last friction coefficient")
    flags.add_argument("--steps", type=int, default=30, help="continuation increments (NINCT)")
    flags.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    flags.add_argument("--refine", type=int, default=1, help="mesh refinement (4r × 3r cells)")
    flags.add_argument("--degree", type=int, default=2, help="Lagrange degree (2: Q2)")
    flags.add_argument("--E", type=float, help="Young's modulus [10³ kg cm⁻¹ s⁻²] (1.4e6)")
    flags.add_argument("--B0", type=float, help="breadth out of the plane [cm] (30.5)")
    flags.add_argument("--K-x", type=float, dest="K_x", help="driver spring [10³ kg s⁻²] (11.1)")
    flags.add_argument("--spring-height", type=float, help="spring height [cm] (H/2)")
    flags.add_argument("--belt-speed", type=float, help="belt speed [cm/s] (0.287)")
    flags.add_argument("--belt-direction", type=int, help="+1 or -1 (+1)")
    flags.add_argument("--eps", type=float, help="regularisation ε [cm/s] (1e-3)")
    flags.add_argument("--regularisation", help="c1 or smooth (c1)")
    flags.add_argument("--contact-quadrature", help="gauss or gll (gauss)")
    flags.add_argument("--max-halvings", type=int, default=8,
                       help="step halvings allowed when a continuation step fails")
    return flags


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="fenicsfriction", description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    scene = _scene_flags()
    steady = commands.add_parser(
        "steady", parents=[scene], help="steady sliding with continuation in μ (Problem 2)",
        description="Steady sliding solved by Newton (PETSc SNES) at each μ from 0 to --mu-max; "
                    "PETSc options can be given as -steady_<option> after the flags.")
    steady.add_argument("--eps-sequence", type=_floats, metavar="E1,E2,...",
                        help="after the continuation, Kalker's sequential ε process at μ-max")
    steady.add_argument("--snapshots", type=int, default=4, help="deformed shapes to draw")
    stability = commands.add_parser(
        "stability", parents=[scene], help="eigenvalue loci and flutter onset (Problem 3)",
        description="Quadratic eigenvalues of the linearised steady sliding (SLEPc PEP) at each "
                    "μ from 0 to --mu-max, FE and rigid model side by side; PETSc/SLEPc options "
                    "as -stability_<option> after the flags.")
    stability.add_argument("--max-frequency", type=float, default=3e4,
                           help="every eigenvalue with |λ| below this [rad/s] is computed")
    stability.add_argument("--onset-tol", type=float, default=1e-4,
                           help="width of the μ interval the onset is bisected to")
    stability.add_argument("--growth-tol", type=float, default=1e-6,
                           help="a mode grows when Re λ > growth-tol |λ|")
    dynamics = commands.add_parser(
        "dynamics", help="dynamics from a perturbed steady state (Problem 1ε, PETSc TS)",
        description="Generalized-α (TSALPHA2) integration from the steady sliding state at --mu "
                    "plus a normal velocity perturbation; TS/SNES options as -dynamics_<option> "
                    "after the flags (e.g. -dynamics_ts_adapt_type basic).")
    dynamics.add_argument("scene", choices=["block"], help="scene to run")
    dynamics.add_argument("--mu", type=float, required=True, help="friction coefficient")
    dynamics.add_argument("--t-end", type=float, required=True, help="final time [s]")
    dynamics.add_argument("--dt", type=float, default=1e-5, help="(initial) time step [s]")
    dynamics.add_argument("--perturbation", type=float, default=-0.01,
                          help="initial normal velocity added to the steady state [cm/s]")
    dynamics.add_argument("--stride", type=int, default=20, help="steps between field outputs")
    dynamics.add_argument("--probe-x", type=float,
                          help="abscissa [cm] of the contact node whose tractions are recorded "
                               "(default: L/2, the paper's node 29)")
    dynamics.add_argument("--scheme", choices=["alpha2", "central"], default="alpha2",
                          help="implicit generalized-α, or explicit central differences with "
                               "a lumped mass (dt capped at 0.9 of the stable step)")
    dynamics.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    for flag, dest, kind, text in (
            ("--refine", "refine", int, "mesh refinement (1)"),
            ("--belt-speed", "belt_speed", float, "belt speed [cm/s] (0.287)"),
            ("--b-n", "b_n", float, "normal damping [10³ kg cm^(-2-l_n) s⁻¹] (0)"),
            ("--K-x", "K_x", float, "driver spring [10³ kg s⁻²] (11.1)"),
            ("--B0", "B0", float, "breadth [cm] (30.5)"),
            ("--eps", "eps", float, "regularisation ε [cm/s] (1e-3)"),
            ("--regularisation", "regularisation", str, "c1 or smooth (c1)")):
        dynamics.add_argument(flag, dest=dest, type=kind, help=text)
    _oscillator_parsers(commands)
    return parser


def _omega_range(text: str) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in text.split(":"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected LO:HI, got {text!r}") from None
    return lo, hi


def _oscillator_parsers(commands) -> None:
    """``oscillator mdof|belt`` and ``stability-map mdof``: the reduced models of seed 004."""
    from fenicsfriction.reduced.slider import TABLE2_READINGS

    readings = {"choices": sorted(TABLE2_READINGS), "default": "paper",
                    "help": "reading of seed 004's dimensionless Table 2 model (paper)"}
    smap = commands.add_parser(
        "stability-map", help="stability of steady sliding vs forcing frequency (seed 004)",
        description="Growth rate of perturbations of steady sliding of the Table 2 slider by "
                    "first-order averaging and by Floquet multipliers (PETSc TS), with the "
                    "unstable bands.")
    smap.add_argument("scene", choices=["mdof"], help="scene to run")
    smap.add_argument("--omega-range", type=_omega_range, required=True, metavar="LO:HI")
    smap.add_argument("--samples", type=int, default=101, help="forcing frequencies sampled")
    smap.add_argument("--methods", default="averaging,floquet",
                      help="comma-separated: averaging, floquet")
    smap.add_argument("--reading", **readings)
    smap.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    osc = commands.add_parser(
        "oscillator", help="stick-slip time response of a friction oscillator (seed 004)",
        description="Integrates the slider of seed 004 (mdof) or the 1-d.o.f. oscillator on a "
                    "belt (belt) with stick and slip switched at events located by PETSc TS "
                    "(or a regularised law with --eps); TS options as -hybrid_<option>.")
    osc.add_argument("scene", choices=["mdof", "belt"], help="scene to run")
    osc.add_argument("--t-end", type=float, default=100.0, help="final (dimensionless) time")
    osc.add_argument("--eps", type=float, help="regularised law of this width (no events)")
    osc.add_argument("--rtol", type=float, default=1e-8, help="relative tolerance of the steps")
    osc.add_argument("--sample-dt", type=float, default=0.01, help="output sampling step")
    osc.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    mdof = osc.add_argument_group("mdof (seed 004, Table 2)")
    mdof.add_argument("--omega", type=float, default=30.78, help="forcing frequency ω_o")
    mdof.add_argument("--reading", **readings)
    mdof.add_argument("--normal-force", choices=["signed", "absolute", "clipped"],
                      default="signed", help="how N enters friction (signed, as eq. 21)")
    mdof.add_argument("--coupled", action="store_true",
                      help="the roughness under a contact follows its tangential motion")
    mdof.add_argument("--perturbation", type=float, default=0.01,
                      help="initial slider velocity added to steady sliding")
    belt = osc.add_argument_group("belt (m ẍ + c ẋ + k x = μ(v_b − ẋ) N)")
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


def _run_dynamics(args: argparse.Namespace, log: logging.Logger) -> int:
    import csv

    from fenicsfriction import io, results
    from fenicsfriction.dynamics import CentralDifference, DynamicsError, DynamicsSolver
    from fenicsfriction.laws import check
    from fenicsfriction.plotting import plot_stick_slip
    from fenicsfriction.scenes import SCENES
    from fenicsfriction.statistics import stick_slip_statistics
    from fenicsfriction.steady import SteadySolver, continuation

    comm = MPI.COMM_WORLD
    check("--mu", args.mu, np.isfinite(args.mu) and args.mu >= 0, "must be >= 0")
    check("--t-end", args.t_end, args.t_end > 0, "must be > 0")
    check("--dt", args.dt, 0 < args.dt <= args.t_end, "must lie in (0, t-end]")
    check("--stride", args.stride, args.stride >= 1, "must be >= 1")
    scene_cls = SCENES[args.scene]
    names = {f.name for f in dataclasses.fields(scene_cls)}
    scene = scene_cls(mu=args.mu, **{k: v for k, v in vars(args).items()
                                     if k in names and k != "mu" and v is not None})
    model = scene.build(comm)
    model.initial_guess()
    steady = SteadySolver(model.residual, prefix="steady_", options=model.solver_options())
    continuation(steady, model.mu, np.linspace(0.0, args.mu, 1 + int(np.ceil(args.mu / 0.05))))
    model.residual.u_dot.x.array[1::model.V.dofmap.index_map_bs] += args.perturbation
    if args.scheme == "central":
        dynamics = CentralDifference(model.residual, band_damping=model.band_damping())
        log.info(f"central differences: stable step {dynamics.stable_dt_elastic:.3e} s "
                 f"(elastic), {dynamics.stable_dt_band:.3e} s (stick band), using "
                 f"{min(args.dt, dynamics.safety * dynamics.stable_dt):.3e} s")
    else:
        dynamics = DynamicsSolver(model.residual, prefix="dynamics_",
                                  atol=1e-10 * model.force_scale)
    out: pathlib.Path = args.out
    observe = model.dynamics_observer(args.probe_x)

    records = []
    with io.FieldWriter(out / "dynamics.xdmf", model) as fields:
        def on_step(record: dict) -> None:
            k = len(records)
            records.append(record)
            if k % args.stride == 0:
                fields.write(record["time"])
                log.info(f"step {k:6d}  t={record['time']:.4e} s  dt={record['dt']:.2e}  "
                         f"Newton {record['newton_iterations']}  N={record['normal_force']:.4g}"
                         f"  F_T={record['friction_force']:.4g}  stick/slip/open "
                         f"{record['n_stick']}/{record['n_slip']}/{record['n_open']}")

        failure = None
        try:
            dynamics.run(args.t_end, args.dt, observe=observe, on_step=on_step)
        except DynamicsError as err:
            failure = str(err)
    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
        with open(out / "timeseries.csv", "w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=list(records[0]))
            writer.writeheader()
            writer.writerows(records)
    statistics = None
    if len(records) > 2:  # over the second half of what was integrated
        statistics = stick_slip_statistics(records, args.mu, float(model.eps.value),
                                           t_from=0.5 * records[-1]["time"])
        if comm.rank == 0:
            plot_stick_slip({f"U = {scene.belt_speed} cm/s": records}, out / "stick_slip.png",
                            args.mu, float(model.eps.value))
        log.info(f"apparent friction coefficient {statistics['apparent_coefficient']:.4f} "
                 f"(μ = {args.mu}), probe node sticks {statistics['probe_stick_fraction']:.1%} "
                 f"of the time (second half of the run)")
    results.write_json(out / "summary.json", {"scene": args.scene,
                                         "parameters": dataclasses.asdict(scene),
                                         "scheme": args.scheme, "dt": args.dt,
                                         "steps": len(records) - 1, "failure": failure,
                                         "statistics": statistics}, comm)
    log.info(f"results in {out}/: timeseries.csv, summary.json, dynamics.xdmf, stick_slip.png")
    if failure is not None:
        log.error(f"fenicsfriction: {failure}")
        return 1
    return 0


def _build(args: argparse.Namespace):
    """Validate the shared flags and return (scene, model, steady solver, μ targets)."""
    from fenicsfriction.laws import check
    from fenicsfriction.scenes import SCENES
    from fenicsfriction.steady import SteadySolver

    check("--mu-max", args.mu_max, np.isfinite(args.mu_max) and args.mu_max >= 0, "must be >= 0")
    check("--steps", args.steps, args.steps >= 1, "must be >= 1")
    check("--max-halvings", args.max_halvings, args.max_halvings >= 0, "must be >= 0")
    scene_cls = SCENES[args.scene]
    names = {f.name for f in dataclasses.fields(scene_cls)}
    scene = scene_cls(**{k: v for k, v in vars(args).items() if k in names and v is not None})
    model = scene.build(MPI.COMM_WORLD, with_friction=args.mu_max > 0)
    model.initial_guess()
    solver = SteadySolver(model.residual, prefix="steady_", options=model.solver_options())
    return scene, model, solver, np.linspace(0.0, args.mu_max, args.steps + 1)


def _run_steady(args: argparse.Namespace, log: logging.Logger) -> int:
    from fenicsfriction import io, plotting, results
    from fenicsfriction.laws import check
    from fenicsfriction.steady import ContinuationError, continuation, epsilon_sequence

    comm = MPI.COMM_WORLD
    check("--snapshots", args.snapshots, args.snapshots >= 0, "must be >= 0")
    t_start = time.perf_counter()
    scene, model, solver, targets = _build(args)
    out: pathlib.Path = args.out
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
    results.write_json(out / "steady.json", records, comm)
    eps_records = None
    if args.eps_sequence and failure is None:
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
    results.write_json(out / "summary.json", {
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


def _rigid_loci(scene, targets: np.ndarray, max_frequency: float, growth_tol: float,
                onset_tol: float) -> dict:
    """Eigenvalues of the rigid block along the same μ grid, and its onsets by bisection."""
    from fenicsfriction.reduced import RigidBlock

    q, steps = None, []

    def values(mu: float) -> np.ndarray:
        nonlocal q
        block = RigidBlock.from_scene(scene, mu=mu)
        q = block.steady_state(q)
        lam = block.eigenvalues(q)
        return lam[(lam.imag >= 0) & (np.abs(lam) <= max_frequency)]

    def grows(lam: np.ndarray) -> bool:
        return bool(np.any(lam.real > growth_tol * np.abs(lam)))

    for mu in targets:
        lam = values(mu)
        steps.append({"mu": float(mu), "eigenvalues": [[v.real, v.imag] for v in lam],
                      "max_re": float(lam.real.max())})
    flags = [grows(np.array([complex(*v) for v in st["eigenvalues"]])) for st in steps]
    onsets, intervals = [], []
    for k in range(1, len(steps)):
        if flags[k] and not flags[k - 1]:
            lo, hi = targets[k - 1], targets[k]
            values(lo)
            while hi - lo > onset_tol:
                mid = 0.5 * (lo + hi)
                lo, hi = (lo, mid) if grows(values(mid)) else (mid, hi)
            onsets.append(0.5 * (lo + hi))
            intervals.append([float(targets[k]), float(targets[k])])
        if flags[k] and intervals:
            intervals[-1][1] = float(targets[k])
    return {"steps": steps, "onsets": onsets, "mu_crit": onsets[0] if onsets else None,
            "unstable_intervals": intervals}


def _run_stability(args: argparse.Namespace, log: logging.Logger) -> int:
    from fenicsfriction import io, plotting, results
    from fenicsfriction.laws import check
    from fenicsfriction.stability import EigenSolveError, Loci, StabilitySolver, unstable_intervals
    from fenicsfriction.steady import ContinuationError

    comm = MPI.COMM_WORLD
    check("--max-frequency", args.max_frequency, args.max_frequency > 0, "must be > 0")
    check("--onset-tol", args.onset_tol, args.onset_tol > 0, "must be > 0")
    check("--growth-tol", args.growth_tol, args.growth_tol > 0, "must be > 0")
    t_start = time.perf_counter()
    scene, model, solver, targets = _build(args)
    out: pathlib.Path = args.out
    loci = Loci(solver, StabilitySolver(model.residual, prefix="stability_"), model.mu,
                args.max_frequency, args.growth_tol)
    transitions, previous = [], {}
    with io.ModeWriter(out / "unstable_modes.xdmf", model) as shapes:
        def on_step(record: dict, modes: list) -> None:
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

        failure, records = None, []
        try:
            loci.follow(targets, on_step=lambda r, m: (records.append(r), on_step(r, m)))
        except (ContinuationError, EigenSolveError) as err:
            failure = f"at μ = {float(model.mu.value):.6g}: {err}"
    onsets = [] if failure else [loci.onset(a, b, args.onset_tol, reference=ref)
                                 for a, b, ref in transitions]
    rigid = _rigid_loci(scene, targets, args.max_frequency, args.growth_tol, args.onset_tol)
    fe = {"steps": records, "onsets": onsets,
          "mu_crit": onsets[0]["mu_crit"] if onsets else None,
          "unstable_intervals": {str(k): v for k, v in
                                 unstable_intervals(records, args.growth_tol).items()}}
    results.write_json(out / "stability.json", {
        "scene": args.scene, "parameters": dataclasses.asdict(scene), "ranks": comm.size,
        "mu_crit": {"fe": fe["mu_crit"], "rigid": rigid["mu_crit"]},
        "fe": fe, "rigid": rigid, "max_frequency": args.max_frequency,
        "growth_tol": args.growth_tol, "wall_time_s": time.perf_counter() - t_start,
        "failure": failure}, comm)
    plotting.plot_loci(records, rigid["steps"], out / "loci.png", comm)
    plotting.plot_growth(records, rigid["steps"], out / "growth.png", comm)
    comm.Barrier()
    log.info(f"μ_crit: FE {fe['mu_crit']}, rigid {rigid['mu_crit']}; FE unstable intervals by "
             f"mode {fe['unstable_intervals']}; rigid {rigid['unstable_intervals']}")
    log.info(f"results in {out}/: stability.json, loci.png, growth.png, unstable_modes.xdmf")
    if failure is not None:
        log.error(f"fenicsfriction: {failure}")
        return 1
    return 0


def _run_stability_map(args: argparse.Namespace, log: logging.Logger) -> int:
    import functools

    from fenicsfriction import results
    from fenicsfriction.laws import check
    from fenicsfriction.plotting import plot_stability_map
    from fenicsfriction.reduced.slider import TABLE2_PAPER_BANDS, stability_map, table2_slider

    lo, hi = args.omega_range
    check("--omega-range", f"{lo:g}:{hi:g}", 0 < lo < hi, "needs 0 < LO < HI")
    check("--samples", args.samples, args.samples >= 2, "must be >= 2")
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    result = stability_map(functools.partial(table2_slider, reading=args.reading),
                           np.linspace(lo, hi, args.samples), methods=methods)
    for method in methods:
        bands = [(round(a, 3), round(b, 3)) for a, b in result.bands[method]]
        per_omega = result.seconds[method] / args.samples * 1e3
        log.info(f"{method}: unstable bands {bands} ({per_omega:.2f} ms per ω_o)")
    out: pathlib.Path = args.out
    paper = [list(band) for band in TABLE2_PAPER_BANDS]
    slider = table2_slider(lo, reading=args.reading)
    results.write_json(out / "stability_map.json", {
        "reading": args.reading, "natural_frequencies": slider.natural_frequencies()[0],
        "omega": result.omega, "growth": result.growth, "bands": result.bands,
        "seconds_per_omega": {k: v / args.samples for k, v in result.seconds.items()},
        "paper_bands": paper})
    if MPI.COMM_WORLD.rank == 0:
        plot_stability_map(result.omega, result.growth, result.bands, out / "stability_map.png",
                           reference_bands=paper)
    MPI.COMM_WORLD.Barrier()
    return 0


def _run_oscillator(args: argparse.Namespace, log: logging.Logger) -> int:
    import csv

    from fenicsfriction import laws, results
    from fenicsfriction.laws import check
    from fenicsfriction.plotting import plot_oscillator
    from fenicsfriction.reduced import BeltOscillator, belt_summary
    from fenicsfriction.reduced.events import HybridError, integrate_hybrid, mode_intervals
    from fenicsfriction.reduced.slider import SliderMotion, table2_slider

    check("--t-end", args.t_end, args.t_end > 0, "must be > 0")
    check("--sample-dt", args.sample_dt, 0 < args.sample_dt <= args.t_end,
          "must lie in (0, t-end]")
    out: pathlib.Path = args.out
    rank0 = MPI.COMM_WORLD.rank == 0
    next_report = [0.0]

    def progress(t, y, mode) -> dict:
        if t >= next_report[0]:
            log.info(f"t = {t:10.4f} / {args.t_end:g}  mode {mode}")
            next_report[0] += args.t_end / 10
        return {}

    start = time.perf_counter()
    if args.scene == "belt":
        law = {"constant": lambda: laws.ConstantFriction(args.mu_k),
               "piecewise": lambda: laws.PiecewiseLinearFriction(args.mu_s, args.slope, args.v_c),
               "stribeck": lambda: laws.StribeckFriction(args.mu_s, args.mu_k, args.v_s)}
        oscillator = BeltOscillator(args.m, args.k, args.c, args.N, args.v_belt,
                                    law[args.law](), mu_static=args.mu_s)
        method = "events" if args.eps is None else "regularised"
        run = oscillator.simulate(args.t_end, x0=args.x0,
                                  v0=args.v_belt if args.v0 is None else args.v0, method=method,
                                  eps=args.eps, rtol=args.rtol, atol=1e-2 * args.rtol,
                                  sample_dt=args.sample_dt)
        t, x, v, force = run.t, run.x, run.v, run.friction_force
        stick, surface = run.stick_intervals, args.v_belt
        summary = belt_summary(run)
        summary = {**summary, "stick_fraction": summary["stick_fraction_run"],
                   "effective_damping": oscillator.effective_damping(),
                   "steady_sliding_stable": oscillator.is_steady_sliding_stable(),
                   "linear_eigenvalues": [[s.real, s.imag]
                                          for s in oscillator.linear_eigenvalues()]}
        if args.law == "constant" and args.c == 0 and args.mu_s > args.mu_k:
            summary["classic_cycle"] = dataclasses.asdict(oscillator.classic_limit_cycle())
        columns = {"t": t, "x": x, "v": v, "friction_force": force,
                   "stick": [int(m == "stick") for m in run.modes]}
        names = ("x", "ẋ")
    else:
        check("--omega", args.omega, args.omega > 0, "must be > 0")
        slider = table2_slider(args.omega, reading=args.reading)
        motion = SliderMotion(slider, normal_force=args.normal_force, coupled=args.coupled,
                              eps=args.eps)
        try:
            run = integrate_hybrid(motion, motion.initial_state([args.perturbation]),
                                   motion.slip_mode(), args.t_end, rtol=args.rtol,
                                   atol=1e-2 * args.rtol, sample_dt=args.sample_dt,
                                   observe=progress)
        except HybridError as error:
            log.info(f"stopped: {error}")
            run = error.result
        n = motion.size // 2
        t, y = run.t, run.y
        forces = np.array([motion.contact_forces(ti, yi, mode)
                           for ti, yi, mode in zip(t, y, run.modes, strict=True)])
        normal, force = forces[:, 0, 0], forces[:, 1, 0]
        stuck = np.array([mode[0] == 0 for mode in run.modes])
        stick = mode_intervals(run, lambda mode: mode[0] == 0)
        surface = slider.contacts[0].surface_speed
        omega, _ = slider.natural_frequencies()
        late = t >= t[-1] / 2
        summary = {"omega": args.omega, "reading": args.reading,
                   "natural_frequencies": omega, "surface_speed": surface,
                   "averaged_growth": slider.averaged().growth,
                   "floquet_growth": slider.floquet().growth, "events": len(run.events),
                   "stick_fraction": sum(b - a for a, b in stick) / t[-1],
                   "slider_amplitude_first_half": float(np.ptp(y[~late, 0])) / 2,
                   "slider_amplitude_second_half": float(np.ptp(y[late, 0])) / 2,
                   "steps": run.steps, "t_end": float(t[-1])}
        columns = {"t": t, "y_s": y[:, 0], "y_1": y[:, 1], "x_1": y[:, 2], "v_s": y[:, n],
                   "v_1": y[:, n + 1], "normal_force": normal, "friction_force": force,
                   "stick": stuck.astype(int)}
        x, v, names = y[:, 0], y[:, n + 1], ("slider y_s", "velocity of mass 1, ẏ_1")
    summary["wall_seconds"] = time.perf_counter() - start
    log.info(f"{summary['events']} events, stick fraction {summary['stick_fraction']:.3f}, "
             f"{summary['wall_seconds']:.1f} s")
    results.write_json(out / "summary.json", summary)
    if rank0:
        with open(out / "timeseries.csv", "w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(columns)
            writer.writerows(zip(*columns.values(), strict=True))
        plot_oscillator(t, x, v, surface, stick, out / "oscillator.png",
                        title=f"{args.scene}: {summary['events']} stick/slip events",
                        names=names)
    MPI.COMM_WORLD.Barrier()
    return 0


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
    from fenicsfriction.results import get_logger
    log = get_logger(MPI.COMM_WORLD)
    try:
        commands = {"steady": _run_steady, "stability": _run_stability, "dynamics": _run_dynamics,
                    "stability-map": _run_stability_map, "oscillator": _run_oscillator}
        return commands[args.command](args, log)
    except ValueError as err:
        if MPI.COMM_WORLD.rank == 0:
            print(f"fenicsfriction: error: {err}", file=sys.stderr)
        return 2
