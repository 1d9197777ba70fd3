"""``fenicsfriction multicontact eq|master-equation|stability-map|interaction|fk|slider``:
Braun's nonhomogeneous frictional interface — the earthquake-like (EQ) model of many contacts,
its master equation, the elastic instability, the elastic interaction of contacts,
Frenkel-Kontorova slip fronts and an elastic slider on an EQ interface.

Each command writes ``multicontact.json`` (the parameters and the command's numbers), CSV
tables and PNG figures (:mod:`fenicsfriction.studies.multicontact.figures`) to ``--out``; the
slider also ``slider.xdmf``.
"""

from __future__ import annotations

import argparse
import logging
import pathlib
import typing

from fenicsfriction.cli.arguments import Parser, floats

if typing.TYPE_CHECKING:
    from mpi4py import MPI

__all__ = ["add_parser", "run_multicontact"]


def add_parser(commands: typing.Any) -> None:
    """``multicontact eq|master-equation|...``: Braun's nonhomogeneous frictional interface."""
    family = commands.add_parser(
        "multicontact", help="a nonhomogeneous frictional interface of many contacts (Braun)",
        description="Braun's earthquake-like interface: contacts that break at thresholds and "
                    "re-form; each command writes multicontact.json, CSV tables and figures "
                    "to --out.")
    family.set_defaults(run=run_multicontact)
    models = family.add_subparsers(dest="model", required=True, parser_class=Parser,
                                   metavar="STUDY")
    contacts = Parser(add_help=False)
    group = contacts.add_argument_group("the contacts (any consistent units)")
    for name, kind, default, text in (
            ("--N", int, 1000, "number of contacts"), ("--k", float, 1.0, "contact stiffness"),
            ("--x-s-mean", float, 1.0, "mean threshold stretching x_c"),
            ("--x-s-std", float, 0.1, "spread σ of the Gaussian thresholds"),
            ("--seed", int, 0, "seed of the random numbers")):
        group.add_argument(name, type=kind, default=default, help=f"{text} ({default})")
    group.add_argument("--newborn", choices=["relaxed", "gaussian"], default="relaxed",
                       help="stretching of re-formed contacts: δ(x), or Gaussian (relaxed)")
    group.add_argument("--newborn-mean", type=float, default=0.0,
                       help="mean of the Gaussian newborn stretching (0)")
    group.add_argument("--newborn-std", type=float, default=0.1,
                       help="spread of the Gaussian newborn stretching (0.1)")
    contacts.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    for name, text in (("eq", "the EQ model moved quasistatically, beside its master equation"),
                       ("master-equation", "the master equation of the stretching distribution")):
        command = models.add_parser(name, parents=[contacts], help=text, description=text + ".")
        command.add_argument("--X-max", type=float,
                             help="the slider's last position (5 contact lives: 5 x_c N k/S, "
                                  "5 x_c without interaction)")
        command.add_argument("--h", type=float, default=0.01,
                             help="the master equation's step ΔX = Δx (0.01)")
        if name == "eq":
            command.add_argument("--realisations", type=int, default=1,
                                 help="independent interfaces averaged (1)")
            command.add_argument("--coupling", type=float,
                                 help="interacting contacts: k/(E a) of a √N × √N lattice "
                                      "between two identical bodies (N a square, e.g. --N 256); "
                                      "none by default")
            command.add_argument("--nu", type=float, default=0.3,
                                 help="Poisson's ratio of the bodies, with --coupling (0.3)")
    smap = models.add_parser(
        "stability-map", parents=[contacts],
        help="smooth sliding or stick-slip of the EQ model over K (or the coupling) and σ/x_c",
        description="With --K: the spring-driven EQ model (PETSc TS) over drive stiffnesses and "
                    "threshold spreads, each run classified, with the master equation's K* "
                    "overlaid. With --couplings: interacting contacts on a √N × √N lattice "
                    "moved quasistatically over couplings k/(E a) and spreads, stick-slip where "
                    "one avalanche drops the force by more than --drop-threshold.")
    smap.add_argument("--K", type=floats, metavar="K1,K2,...", help="drive stiffnesses")
    smap.add_argument("--couplings", type=floats, metavar="C1,C2,...",
                      help="couplings k/(E a) of interacting contacts (instead of --K; "
                           "N a square, e.g. --N 256)")
    smap.add_argument("--drop-threshold", type=float, default=0.05,
                      help="the force drop in one event, over the force, that is stick-slip: "
                           "with --K one slip of the slow drive over the peak (onset) or the "
                           "late mean force; with --couplings one avalanche over the kinetic "
                           "force (0.05)")
    smap.add_argument("--lives", type=float, default=8.0,
                      help="with --couplings: the distance moved, in contact lives (8)")
    smap.add_argument("--spreads", type=floats, default=[0.1, 0.3], metavar="S1,S2,...",
                      help="relative threshold spreads σ/x_c (0.1,0.3)")
    interaction = models.add_parser(
        "interaction", help="the response of contacts to a break, through the half-space",
        description="Contacts on an n x n lattice of an elastic half-space (Landau-Lifshitz's "
                    "Green tensor): the force response δf(r) of the others when the centre one "
                    "breaks, its r^-1 and r^-3 laws and their crossover against λ_c = a²E/k.")
    interaction.add_argument("--n", type=int, default=256, help="lattice side (256)")
    interaction.add_argument("--lambda-c", type=float, default=16.0,
                             help="the elastic correlation length over the spacing (16)")
    interaction.add_argument("--nu", type=float, default=0.3, help="Poisson's ratio (0.3)")
    interaction.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    fk = models.add_parser(
        "fk", help="Frenkel-Kontorova slip fronts (PETSc TS, breaks as events)",
        description="m ü + m η u̇ − g(u_{i+1} + u_{i−1} − 2u_i) + F_s(u_i) + K u_i = f: a front "
                    "of breaking contacts from the relaxed left part, its speed against the "
                    "continuum travelling wave.")
    for name, kind, default, text in (
            ("--n", int, 200, "contacts"), ("--m", float, 1.0, "mass per contact"),
            ("--eta", float, 1.0, "damping rate η"), ("--g", float, 100.0, "chain stiffness"),
            ("--k", float, 1.0, "contact stiffness"), ("--K", float, 0.25, "substrate stiffness"),
            ("--u-s", float, 1.0, "contact threshold"), ("--force", float, 1.0, "driving force f"),
            ("--t-end", float, 100.0, "final time"),
            ("--spread", float, 0.0, "relative spread of the thresholds (defects)"),
            ("--seed", int, 1, "seed of the thresholds")):
        fk.add_argument(name, type=kind, default=default, help=f"{text} ({default})")
    fk.add_argument("--forces", type=floats, metavar="F1,F2,...",
                    help="also measure the front speed at each of these forces")
    fk.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    slider = models.add_parser(
        "slider", help="an elastic slider on EQ contacts, pushed at its trailing edge (dolfinx)",
        description="A 2D elastic slider whose base is held by breaking contacts, pushed at its "
                    "trailing edge: detachment fronts, precursors, the force of global slip.")
    for name, kind, text in (
            ("--L", float, "length [m] (0.1)"), ("--H", float, "height [m] (0.01)"),
            ("--nx", int, "cells along L (40)"), ("--ny", int, "cells along H (4)"),
            ("--E", float, "Young's modulus [Pa] (1e9)"), ("--nu", float, "Poisson's ratio (0.3)"),
            ("--rho", float, "density [kg/m³] (1000)"),
            ("--k", float, "contact stiffness per base length [N/m²] (1e10)"),
            ("--threshold", float, "mean threshold stretch [m] (1e-6)"),
            ("--spread", float, "relative spread of the thresholds (0.5)"),
            ("--delay", float, "time a broken contact stays off [s] (0)"),
            ("--push-speed", float, "speed of the pushing stage [m/s] (0.01)"),
            ("--seed", int, "seed of the thresholds (0)"),
            ("--patches", int, "patches of the base sharing a threshold, dividing nx (0: one "
                               "per node)"),
            ("--viscosity", float, "Kelvin-Voigt relaxation time of the slider [s] (0)")):
        slider.add_argument(name, type=kind, help=text)
    slider.add_argument("--t-end", type=float, default=5e-3, help="final time [s] (5e-3)")
    slider.add_argument("--dt", type=float, default=1e-6, help="time step [s] (1e-6)")
    slider.add_argument("--out", type=pathlib.Path, required=True, help="output folder")


# --- the EQ model, its master equation, the elastic instability ---------------------------------

def _eq_model(args: argparse.Namespace) -> typing.Any:
    """The EQ model of the flags: Gaussian thresholds; newborn contacts relaxed or Gaussian."""
    from scipy import stats

    from fenicsfriction.laws import check_positive
    from fenicsfriction.studies.multicontact import EQModel

    newborn = None
    if args.newborn == "gaussian":
        check_positive("--newborn-std", args.newborn_std)
        newborn = stats.norm(args.newborn_mean, args.newborn_std)
    return EQModel(n_contacts=args.N, k=args.k, x_s_mean=args.x_s_mean, x_s_std=args.x_s_std,
                   newborn=newborn)


def _interacting(args: argparse.Namespace, model: typing.Any) -> typing.Any:
    """The model's contacts on a lattice, coupled by ``--coupling``; None without it."""
    if args.coupling is None:
        return None
    from fenicsfriction.studies.multicontact import InteractingEQModel

    return InteractingEQModel.lattice(model, args.coupling, nu=args.nu)


def _record(result: typing.Any) -> dict[str, typing.Any]:
    """A result's record with the issue's names: parameters, the forces, K*, X and F."""
    data = result.to_json()
    return {**data, "X": list(map(float, result.X)), "F": list(map(float, result.F))}


def _run_eq(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:

    from fenicsfriction import results
    from fenicsfriction.cli.common import output_folder, write_rows
    from fenicsfriction.studies.multicontact import MasterEquation, figures

    model = _eq_model(args)
    interacting = _interacting(args, model)
    moved = model if interacting is None else interacting
    lives = 1.0 if interacting is None else args.N * args.k / interacting.interface_stiffness
    X_max = 5.0 * args.x_s_mean * lives if args.X_max is None else args.X_max
    out = output_folder(args.out, comm)
    log.info(f"eq: {args.N} contacts, k = {args.k:g}, thresholds N({args.x_s_mean:g}, "
             f"{args.x_s_std:g}), newborn {args.newborn}"
             + ("" if interacting is None else f", coupling k/(E a) = {args.coupling:g} "
                f"(S = {interacting.interface_stiffness / (args.N * args.k):.3g} N k)")
             + f"; X to {X_max:g}, {args.realisations} realisation(s), seed {args.seed}")
    run = moved.quasistatic(X_max, realisations=args.realisations, seed=args.seed)
    me = MasterEquation(model, args.h).solve(X_max)
    summary = {"command": "eq", **_record(run), "K_star": me.K_star,
               "master_equation": {"kinetic_force": me.kinetic_force,
                                   "static_force": me.static_force, "X_max": me.X_max,
                                   "force_at_X_max": me.force_at_X_max, "h": me.h}}
    results.write_summary(out / "multicontact.json", summary, comm)
    write_rows(out / "force.csv", ({"X": x, "F": f, "F_std": e}
                             for x, f, e in zip(run.X, run.F, run.F_std, strict=True)), comm)
    files = "multicontact.json, force.csv, eq.png"
    if interacting is not None:
        write_rows(out / "avalanches.csv", ({"X": x, "breaks": b, "force_drop": d} for x, b, d
                                            in zip(run.avalanche_X, run.avalanche_size,
                                                   run.force_drop, strict=True)), comm)
        files += ", avalanches.csv"
    if comm.rank == 0:
        figures.eq_figure(run, me, args.realisations, interacting is not None, X_max,
                          out / "eq.png")
    log.info(f"static force {run.static_force:.6g} (master equation {me.static_force:.6g}), "
             f"kinetic {run.kinetic_force:.6g} ({me.kinetic_force:.6g}), K* = {me.K_star:.6g}"
             + ("" if interacting is None else
                f", largest avalanche {run.largest_avalanche:.1%} of the contacts")
             + f"; results in {out}/: {files}")
    return 0


def _run_master_equation(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:

    from fenicsfriction import results
    from fenicsfriction.cli.common import output_folder, write_rows
    from fenicsfriction.studies.multicontact import MasterEquation, figures

    model = _eq_model(args)
    out = output_folder(args.out, comm)
    X_max = 5.0 * args.x_s_mean if args.X_max is None else args.X_max
    me = MasterEquation(model, args.h).solve(X_max)
    results.write_summary(out / "multicontact.json",
                          {"command": "master-equation", **_record(me)}, comm)
    write_rows(out / "force.csv", ({"X": x, "F": f} for x, f in zip(me.X, me.F, strict=True)), comm)
    if comm.rank == 0:
        figures.master_equation_figure(me, out / "master_equation.png")
    log.info(f"static force {me.static_force:.6g}, kinetic (steady state) "
             f"{me.kinetic_force:.6g}, force at X_max = {me.X_max:g} {me.force_at_X_max:.6g} "
             f"({me.force_at_X_max / me.kinetic_force - 1:+.2%} from kinetic), "
             f"K* = {me.K_star:.6g}, mass error {me.mass_error:.1e}; results in {out}/: "
             "multicontact.json, force.csv, master_equation.png")
    return 0


def _run_stability_map(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    import numpy as np

    from fenicsfriction import results
    from fenicsfriction.cli.common import output_folder, write_rows
    from fenicsfriction.laws import check
    from fenicsfriction.studies.multicontact import figures, instability_map

    check("--K", args.K, (args.K is None) != (args.couplings is None),
          "give --K (drive stiffnesses) or --couplings (interacting contacts), one of the two")
    if args.couplings is not None:
        return _run_coupling_map(args, log, comm)
    out = output_folder(args.out, comm)
    log.info(f"stability-map: {len(args.K)} stiffnesses × {len(args.spreads)} spreads, "
             f"{args.N} contacts")
    smap = instability_map(args.K, args.spreads, n_contacts=args.N, k=args.k,
                           x_s_mean=args.x_s_mean, drop_threshold=args.drop_threshold,
                           seed=args.seed)
    record = smap.to_json()
    results.write_summary(out / "multicontact.json", {"command": "stability-map", **record},
                          comm)
    columns = ("onset_stick_slip", "sustained_stick_slip", "onset_drop", "largest_late_drop",
               "jump_fraction", "fast_slip", "max_speed")
    write_rows(out / "map.csv", ({"relative_spread": s, "K": K, "K_star": smap.K_star[i],
                                  **{c: _cell(getattr(smap, c)[i, j]) for c in columns}}
                                 for i, s in enumerate(smap.relative_spread)
                                 for j, K in enumerate(smap.K)), comm)
    if comm.rank == 0:
        figures.stability_map_figure(smap, out / "stability_map.png")
    agree = np.mean(smap.onset_stick_slip == (smap.K[None, :] < smap.K_star[:, None]))
    log.info(f"{agree:.0%} of the runs jump at the static peak on the side of K* the master "
             f"equation predicts; sustained stick-slip in {int(smap.sustained_stick_slip.sum())}"
             f" of {smap.sustained_stick_slip.size}; results in {out}/: multicontact.json, "
             "map.csv, stability_map.png")
    return 0


def _cell(value: typing.Any) -> bool | float:
    """A map cell for the CSV: a classification as a bool, a measure as a float."""
    import numpy as np

    return bool(value) if np.asarray(value).dtype == np.bool_ else float(value)


def _run_coupling_map(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    import math

    import numpy as np

    from fenicsfriction import results
    from fenicsfriction.cli.common import output_folder, write_rows
    from fenicsfriction.laws import check
    from fenicsfriction.studies.multicontact import coupling_map, figures

    n_side = math.isqrt(args.N)
    check("--N", args.N, n_side**2 == args.N, "must be a square n² with --couplings (e.g. 256)")
    out = output_folder(args.out, comm)
    log.info(f"stability-map: {len(args.couplings)} couplings × {len(args.spreads)} spreads, "
             f"{n_side} × {n_side} interacting contacts, {args.lives:g} lives each")
    cmap = coupling_map(args.couplings, args.spreads, n_side=n_side, k=args.k,
                        x_s_mean=args.x_s_mean, lives=args.lives,
                        drop_threshold=args.drop_threshold, seed=args.seed)
    results.write_summary(out / "multicontact.json", {"command": "stability-map",
                                                   **cmap.to_json()}, comm)
    write_rows(out / "map.csv", ({"relative_spread": s, "coupling": c,
                                  "sustained_stick_slip":
                                      bool(cmap.sustained_stick_slip[i, j]),
                                  "largest_late_drop": cmap.largest_late_drop[i, j],
                                  "largest_avalanche": cmap.largest_avalanche[i, j]}
                                 for i, s in enumerate(cmap.relative_spread)
                                 for j, c in enumerate(cmap.coupling)), comm)
    if comm.rank == 0:
        figures.coupling_map_figure(cmap, out / "coupling_map.png")
    log.info(f"sustained stick-slip in {int(np.sum(cmap.sustained_stick_slip))} of "
             f"{cmap.sustained_stick_slip.size} runs; per coupling: "
             + ", ".join(f"{c:g}: {int(n)}" for c, n in
                         zip(cmap.coupling, cmap.sustained_stick_slip.sum(axis=0),
                                               strict=True))
             + f"; results in {out}/: multicontact.json, map.csv, coupling_map.png")
    return 0


# --- the elastic interaction of contacts --------------------------------------------------------

def _profile_edges(n: int) -> typing.Any:
    """The distance bins of the break response's radial profile on an n × n lattice."""
    import numpy as np

    return np.geomspace(1.0, n / 4, 40)


def _centre(n: int) -> int:
    """The index of the contact that breaks: the lattice's centre."""
    return (n // 2) * n + n // 2


def _far_bins(n: int, lambda_c: float) -> int:
    """How many points of the response's profile lie beyond 3 λ_c (the far law's range): the
    lattice's distances from the centre contact, binned as the profile bins them (empty bins
    dropped, each bin at the geometric mean of its distances), not the bins' own centres —
    on a small lattice many bins are empty and a bin's sites sit off its centre."""
    import numpy as np

    from fenicsfriction.studies.multicontact import radial_profile

    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    positions = np.stack([i.ravel(), j.ravel()], axis=1).astype(float)
    r, _ = radial_profile(positions, np.ones((n * n, 1)), _centre(n), edges=_profile_edges(n))
    return int(np.count_nonzero(r > 3 * lambda_c))


def _smallest_n(lambda_c: float) -> int:
    """The smallest lattice side whose far range holds two bins."""
    n = 8
    while _far_bins(n, lambda_c) < 2:
        n += 1
    return n


def _run_interaction(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    import numpy as np

    from fenicsfriction import results
    from fenicsfriction.cli.common import output_folder, write_rows
    from fenicsfriction.laws import check
    from fenicsfriction.studies.multicontact import (
        LatticeInteraction,
        figures,
        fit_power_laws,
        radial_profile,
    )

    lam = args.lambda_c
    check("--n", args.n, _far_bins(args.n, lam) >= 2,
          f"a lattice reaching past 3 λ_c = {3 * lam:g} spacings, where the far law is "
          f"fitted (with --lambda-c {lam:g}: --n >= {_smallest_n(lam)})")
    out = output_folder(args.out, comm)
    lattice = LatticeInteraction(n=args.n, spacing=1.0, E=1.0, nu=args.nu, stiffness=1.0 / lam,
                                 contact_radius=0.5)
    log.info(f"interaction: {args.n} x {args.n} contacts (spacing a = 1, E = 1, ν = "
             f"{args.nu:g}), k = 1/λ_c: λ_c = a²E/k = {lam:g} a; the centre contact breaks "
             "under a uniform shear")
    broken = _centre(args.n)
    response = lattice.break_response((1.0, 0.0, 0.0), broken)
    r, f = radial_profile(lattice.positions, response, broken, edges=_profile_edges(args.n))
    f = f / np.linalg.norm(response[broken])
    near = max(lam / 4, 2.0)  # at least two distance bins for the near law
    fit = fit_power_laws(r, f, near, 3 * lam)
    summary = {"command": "interaction", "parameters": {"n": args.n, "nu": args.nu,
                                                        "lambda_c": lam, "spacing": 1.0,
                                                        "E": 1.0, "contact_radius": 0.5},
               "near_exponent": fit.near_exponent, "far_exponent": fit.far_exponent,
               "crossover": fit.crossover, "crossover_over_lambda_c": fit.crossover / lam,
               "r": list(map(float, r)), "dF": list(map(float, f))}
    results.write_summary(out / "multicontact.json", summary, comm)
    write_rows(out / "response.csv", ({"r": x, "dF": y} for x, y in zip(r, f, strict=True)), comm)
    if comm.rank == 0:
        figures.interaction_figure(r, f, fit, near, lam, out / "interaction.png")
    log.info(f"near exponent {fit.near_exponent:.3f} (r < {near:g}), far {fit.far_exponent:.3f} "
             f"(r > 3 λ_c), crossover at {fit.crossover / lam:.2f} λ_c; results in {out}/: "
             "multicontact.json, response.csv, interaction.png")
    return 0


# --- Frenkel-Kontorova slip fronts --------------------------------------------------------------

def _run_fk(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    import numpy as np

    from fenicsfriction import results
    from fenicsfriction.cli.common import output_folder, write_rows
    from fenicsfriction.studies.multicontact import figures
    from fenicsfriction.studies.multicontact.frenkel_kontorova import FKChain, front_speeds

    chain = FKChain(n=args.n, m=args.m, eta=args.eta, g=args.g, k=args.k, K=args.K,
                    u_s=args.u_s)
    if args.spread > 0:
        chain = chain.with_defects(args.spread, args.seed)
    out = output_folder(args.out, comm)
    relaxed = max(1, args.n // 10)
    log.info(f"fk: {args.n} contacts, f_min = {chain.f_min:.6g}, f_max = {chain.f_max:.6g}, "
             f"sound speed {chain.sound_speed:.6g}; f = {args.force:g}, t_end = {args.t_end:g}")
    run = chain.simulate(args.force, args.t_end, relaxed, sample_dt=args.t_end / 400)
    broken = np.isfinite(run.break_time)
    summary: dict[str, typing.Any] = {
        "command": "fk", "parameters": {k: getattr(args, k) for k in (
            "n", "m", "eta", "g", "k", "K", "u_s", "force", "t_end", "spread", "seed")},
        "relaxed": relaxed, "f_min": chain.f_min, "f_max": chain.f_max,
        "sound_speed": chain.sound_speed,
        "continuum_front_speed": float(chain.continuum_front_speed(args.force))
        if args.force > chain.f_min else None,
        "contacts_broken": int(broken.sum()),
        "energy_residual": float(np.abs(run.energy_residual()).max())}
    first, last = relaxed + 5, relaxed + 5 + max(5, (args.n - relaxed) // 3)
    if last < args.n and np.all(broken[first:last + 1]):
        summary["front_speed"] = run.front_speed(first, last)
    if args.forces:
        sweep = front_speeds(chain, args.forces, relaxed=relaxed, first=first,
                             last=min(last, args.n - 1))
        summary["front_speeds"] = sweep.to_json()
        write_rows(out / "front_speeds.csv", sweep.rows(), comm)
    write_rows(out / "fk.csv", run.rows(), comm)
    results.write_summary(out / "multicontact.json", summary, comm)
    if comm.rank == 0:
        figures.fk_figure(chain, run, args.force,
                          summary["front_speeds"] if args.forces else None, out / "fk.png")
    log.info(f"{summary['contacts_broken']} contacts broken; front speed "
             f"{summary.get('front_speed', float('nan')):.6g} (continuum "
             f"{summary['continuum_front_speed'] or float('nan'):.6g}); results in {out}/: "
             "multicontact.json, fk.csv, fk.png" + (", front_speeds.csv" if args.forces else ""))
    return 0


# --- the elastic slider on an EQ interface ------------------------------------------------------

def _run_slider(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    from fenicsfriction import results
    from fenicsfriction.cli.common import output_folder
    from fenicsfriction.io import FieldWriter
    from fenicsfriction.studies.multicontact import ElasticSlider, ElasticSliderModel, figures

    names = ("L", "H", "nx", "ny", "E", "nu", "rho", "k", "threshold", "spread", "delay",
             "push_speed", "seed", "patches", "viscosity")
    scene = ElasticSlider(**{n: getattr(args, n) for n in names if getattr(args, n) is not None})
    out = output_folder(args.out, comm)
    model = ElasticSliderModel(scene, comm)
    log.info(f"slider: {scene.nx} x {scene.ny} cells, {scene.nx + 1} EQ contacts on the base, "
             f"pushed at {scene.push_speed:g}; t_end = {args.t_end:g}, dt = {args.dt:g}")
    steps = {"n": 0}

    def progress(*_: typing.Any) -> None:
        steps["n"] += 1
        if steps["n"] % max(1, int(args.t_end / args.dt) // 20) == 0:
            log.info(f"step {steps['n']}  t = {float(model.time.value):.4g}  front at "
                     f"{model.front_position():.4g}  push force {model.push_force():.4g}")

    history = model.run(args.t_end, args.dt, on_step=progress)
    history.write_csv(out / "slider.csv")
    summary = {"command": "slider", "parameters": {**scene.__dict__, "t_end": args.t_end,
                                                   "dt": args.dt},
               "breaks": len(history.breaks), "fronts": [f.to_json() for f in history.fronts],
               "slip_force": history.slip_force, "peak_push_force": history.peak_force,
               "wave_speeds": {"c_p": scene.wave_speeds[0], "c_s": scene.wave_speeds[1]}}
    results.write_summary(out / "multicontact.json", summary, comm)
    with FieldWriter(out / "slider.xdmf", model) as writer:
        writer.write(float(model.time.value))
    if comm.rank == 0:
        figures.slider_figure(history, scene.L, out / "fronts.png")
    log.info(f"{len(history.breaks)} breaks, {len(history.fronts)} fronts, slip force "
             f"{history.slip_force}; results in {out}/: multicontact.json, slider.csv, fronts.png, "
             "slider.xdmf")
    return 0


#: the models' parameter names whose flag is not ``--name``
_FLAGS = {"n_contacts": "--N", "relative_spread": "--spreads", "X_max": "--X-max"}


def run_multicontact(args: argparse.Namespace, log: logging.Logger) -> int:
    """``multicontact STUDY``: the model, its numbers and figures."""
    from mpi4py import MPI

    from fenicsfriction.cli.common import named_by_flag

    run = {"eq": _run_eq, "master-equation": _run_master_equation,
           "stability-map": _run_stability_map, "interaction": _run_interaction,
           "fk": _run_fk, "slider": _run_slider}[args.model]
    try:
        code = run(args, log, MPI.COMM_WORLD)
        MPI.COMM_WORLD.Barrier()  # rank 0's figures are written before any rank returns
        return code
    except ValueError as err:  # the models name their parameters: name the flags
        raise ValueError(named_by_flag(str(err), _FLAGS)) from None
