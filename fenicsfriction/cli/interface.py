"""``fenicsfriction interface eq|master-equation|stability-map|interaction|fk|slider``: Braun's
nonhomogeneous frictional interface — the earthquake-like (EQ) model of many contacts, its master
equation, the elastic instability, the elastic interaction of contacts, Frenkel-Kontorova slip
fronts and an elastic slider on an EQ interface.

Each command writes ``interface.json`` (the parameters and the command's numbers), CSV tables
and PNG figures to ``--out``; the slider also ``slider.xdmf``.
"""

from __future__ import annotations

import argparse
import logging
import typing

from mpi4py import MPI

import numpy as np

from fenicsfriction import plotting, results
from fenicsfriction.cli.common import named_by_flag, output_folder, write_rows

__all__ = ["run_interface"]


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


def _interface_json(result: typing.Any) -> dict[str, typing.Any]:
    """A result's record with the issue's names: parameters, the forces, K*, X and F."""
    data = result.to_json()
    return {**data, "X": list(map(float, result.X)), "F": list(map(float, result.F))}


def _run_eq(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    from fenicsfriction.studies.multicontact import MasterEquation

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
    summary = {"command": "eq", **_interface_json(run), "K_star": me.K_star,
               "master_equation": {"kinetic_force": me.kinetic_force,
                                   "static_force": me.static_force, "h": me.h}}
    results.write_summary(out / "interface.json", summary, comm)
    write_rows(out / "force.csv", ({"X": x, "F": f, "F_std": e}
                             for x, f, e in zip(run.X, run.F, run.F_std, strict=True)), comm)
    files = "interface.json, force.csv, eq.png"
    if interacting is not None:
        write_rows(out / "avalanches.csv", ({"X": x, "breaks": b, "force_drop": d} for x, b, d
                                            in zip(run.avalanche_X, run.avalanche_size,
                                                   run.force_drop, strict=True)), comm)
        files += ", avalanches.csv"
    if comm.rank == 0:
        with plotting.saved_figure(out / "eq.png", ncols=2, figsize=(11, 4)) as (a1, a2):
            a1.plot(run.X, run.F, "-", lw=1, label=f"EQ model ({args.realisations} realisation(s))")
            a1.plot(me.X, me.F, "k-", lw=1.2, label="master equation"
                    + ("" if interacting is None else " (no interaction)"))
            a1.set(xlabel="X", ylabel="F", title="friction force against the slider's position")
            a1.legend(fontsize=8)
            centres = 0.5 * (run.histogram_edges[1:] + run.histogram_edges[:-1])
            a2.bar(centres, run.histogram, width=np.diff(run.histogram_edges), alpha=0.5,
                   label="EQ model")
            a2.plot(me.x, me.Q / me.h, "k-", label="master equation")
            a2.set(xlabel="stretching x", ylabel="density Q(x; X)",
                   title=f"stretchings at X = {X_max:g}")
            a2.legend(fontsize=8)
    log.info(f"static force {run.static_force:.6g} (master equation {me.static_force:.6g}), "
             f"kinetic {run.kinetic_force:.6g} ({me.kinetic_force:.6g}), K* = {me.K_star:.6g}"
             + ("" if interacting is None else
                f", largest avalanche {run.largest_avalanche:.1%} of the contacts")
             + f"; results in {out}/: {files}")
    return 0


def _run_master_equation(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    from fenicsfriction.studies.multicontact import MasterEquation

    model = _eq_model(args)
    out = output_folder(args.out, comm)
    X_max = 5.0 * args.x_s_mean if args.X_max is None else args.X_max
    me = MasterEquation(model, args.h).solve(X_max)
    results.write_summary(out / "interface.json",
                          {"command": "master-equation", **_interface_json(me)}, comm)
    write_rows(out / "force.csv", ({"X": x, "F": f} for x, f in zip(me.X, me.F, strict=True)), comm)
    if comm.rank == 0:
        with plotting.saved_figure(out / "master_equation.png", ncols=2,
                                   figsize=(11, 4)) as (a1, a2):
            a1.plot(me.X, me.F, "k-")
            a1.axhline(me.kinetic_force, color="gray", ls=":", label="kinetic")
            a1.set(xlabel="X", ylabel="F", title=f"F(X): static {me.static_force:.4g}, K* = "
                                                 f"{me.K_star:.4g}")
            a1.legend(fontsize=8)
            a2.plot(me.x, me.Q / me.h, "k-")
            a2.set(xlabel="stretching x", ylabel="Q(x; X)", title=f"Q at X = {me.X[-1]:.4g}")
    log.info(f"static force {me.static_force:.6g}, kinetic {me.kinetic_force:.6g}, "
             f"K* = {me.K_star:.6g}, mass error {me.mass_error:.1e}; results in {out}/: "
             "interface.json, force.csv, master_equation.png")
    return 0


def _run_stability_map(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    from fenicsfriction.laws import check
    from fenicsfriction.studies.multicontact import instability_map

    check("--K", args.K, (args.K is None) != (args.couplings is None),
          "give --K (drive stiffnesses) or --couplings (interacting contacts), one of the two")
    if args.couplings is not None:
        return _run_coupling_map(args, log, comm)
    out = output_folder(args.out, comm)
    log.info(f"stability-map: {len(args.K)} stiffnesses × {len(args.spreads)} spreads, "
             f"{args.N} contacts")
    smap = instability_map(args.K, args.spreads, n_contacts=args.N, k=args.k,
                           x_s_mean=args.x_s_mean, seed=args.seed)
    results.write_summary(out / "interface.json", {"command": "stability-map",
                                                   **smap.to_json()}, comm)
    write_rows(out / "map.csv", ({"relative_spread": s, "K": K, "K_star": smap.K_star[i],
                            "stick_slip": bool(smap.stick_slip[i, j]),
                            "max_speed": smap.max_speed[i, j]}
                           for i, s in enumerate(smap.relative_spread)
                           for j, K in enumerate(smap.K)), comm)
    if comm.rank == 0:
        with plotting.saved_figure(out / "stability_map.png", figsize=(6.5, 4.5)) as (ax,):
            _classified(ax, smap.K, smap.relative_spread, smap.stick_slip)
            ax.plot(smap.K_star, smap.relative_spread, "k-", label="K* = −max F′(X)")
            ax.set(xscale="log", xlabel="drive stiffness K", ylabel="threshold spread σ/x_c",
                   title="elastic instability of the EQ interface")
            ax.legend(fontsize=8)
    agree = np.mean(smap.stick_slip == (smap.K[None, :] < smap.K_star[:, None]))
    log.info(f"{agree:.0%} of the runs on the side of K* the master equation predicts; "
             f"results in {out}/: interface.json, map.csv, stability_map.png")
    return 0


def _classified(ax: typing.Any, x: np.ndarray, spreads: np.ndarray,
                stick_slip: np.ndarray) -> None:
    """The runs of a map as crosses (stick-slip) and circles (smooth sliding)."""
    xx, ss = np.meshgrid(x, spreads)
    stuck = stick_slip.astype(bool)
    ax.scatter(xx[stuck], ss[stuck], marker="x", color="tab:red", label="stick-slip")
    ax.scatter(xx[~stuck], ss[~stuck], marker="o", facecolors="none", edgecolors="tab:blue",
               label="smooth sliding")


def _run_coupling_map(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    import math

    from fenicsfriction.laws import check
    from fenicsfriction.studies.multicontact import coupling_map

    n_side = math.isqrt(args.N)
    check("--N", args.N, n_side**2 == args.N, "must be a square n² with --couplings (e.g. 256)")
    out = output_folder(args.out, comm)
    log.info(f"stability-map: {len(args.couplings)} couplings × {len(args.spreads)} spreads, "
             f"{n_side} × {n_side} interacting contacts, {args.lives:g} lives each")
    cmap = coupling_map(args.couplings, args.spreads, n_side=n_side, k=args.k,
                        x_s_mean=args.x_s_mean, lives=args.lives,
                        drop_threshold=args.drop_threshold, seed=args.seed)
    results.write_summary(out / "interface.json", {"command": "stability-map",
                                                   **cmap.to_json()}, comm)
    write_rows(out / "map.csv", ({"relative_spread": s, "coupling": c,
                                  "stick_slip": bool(cmap.stick_slip[i, j]),
                                  "largest_drop": cmap.largest_drop[i, j],
                                  "largest_avalanche": cmap.largest_avalanche[i, j]}
                                 for i, s in enumerate(cmap.relative_spread)
                                 for j, c in enumerate(cmap.coupling)), comm)
    if comm.rank == 0:
        with plotting.saved_figure(out / "coupling_map.png", ncols=2,
                                   figsize=(11, 4.5)) as (a1, a2):
            shown = np.where(cmap.coupling > 0, cmap.coupling,
                             np.min(cmap.coupling[cmap.coupling > 0], initial=1.0) / 3)
            _classified(a1, shown, cmap.relative_spread, cmap.stick_slip)
            a1.set(xscale="log", xlabel="coupling k/(E a) (no interaction at the left edge)",
                   ylabel="threshold spread σ/x_c", title="stick-slip of interacting contacts")
            a1.legend(fontsize=8)
            for i, s in enumerate(cmap.relative_spread):
                a2.plot(shown, cmap.largest_drop[i], "o-", label=f"σ/x_c = {s:g}")
            a2.axhline(cmap.drop_threshold, color="gray", ls=":", label="threshold")
            a2.set(xscale="log", yscale="log", xlabel="coupling k/(E a)",
                   ylabel="largest drop of F in one avalanche / F_k",
                   title="avalanches grow with the interaction")
            a2.legend(fontsize=8)
    log.info(f"stick-slip in {int(np.sum(cmap.stick_slip))} of {cmap.stick_slip.size} runs; "
             "per coupling: " + ", ".join(f"{c:g}: {int(n)}" for c, n in
                                           zip(cmap.coupling, cmap.stick_slip.sum(axis=0),
                                               strict=True))
             + f"; results in {out}/: interface.json, map.csv, coupling_map.png")
    return 0


# --- the elastic interaction of contacts --------------------------------------------------------

def _run_interaction(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    from fenicsfriction.studies.multicontact import (
        LatticeInteraction,
        fit_power_laws,
        radial_profile,
    )

    out = output_folder(args.out, comm)
    lam = args.lambda_c
    lattice = LatticeInteraction(n=args.n, spacing=1.0, E=1.0, nu=args.nu, stiffness=1.0 / lam,
                                 contact_radius=0.5)
    log.info(f"interaction: {args.n} x {args.n} contacts (spacing a = 1, E = 1, ν = "
             f"{args.nu:g}), k = 1/λ_c: λ_c = a²E/k = {lam:g} a; the centre contact breaks "
             "under a uniform shear")
    broken = (args.n // 2) * args.n + args.n // 2
    response = lattice.break_response((1.0, 0.0, 0.0), broken)
    r, f = radial_profile(lattice.positions, response, broken,
                          edges=np.geomspace(1.0, args.n / 4, 40))
    f = f / np.linalg.norm(response[broken])
    near = max(lam / 4, 2.0)  # at least two distance bins for the near law
    fit = fit_power_laws(r, f, near, 3 * lam)
    summary = {"command": "interaction", "parameters": {"n": args.n, "nu": args.nu,
                                                        "lambda_c": lam, "spacing": 1.0,
                                                        "E": 1.0, "contact_radius": 0.5},
               "near_exponent": fit.near_exponent, "far_exponent": fit.far_exponent,
               "crossover": fit.crossover, "crossover_over_lambda_c": fit.crossover / lam,
               "r": list(map(float, r)), "dF": list(map(float, f))}
    results.write_summary(out / "interface.json", summary, comm)
    write_rows(out / "response.csv", ({"r": x, "dF": y} for x, y in zip(r, f, strict=True)), comm)
    if comm.rank == 0:
        with plotting.saved_figure(out / "interaction.png", figsize=(6, 4.2)) as (ax,):
            ax.loglog(r, f, "o", ms=3, label="|δf(r)| / |δf(0)|")
            for slope, pre, where, style in (
                    (fit.near_exponent, fit.near_prefactor, r < near, "k--"),
                    (fit.far_exponent, fit.far_prefactor, r > 3 * lam, "k:")):
                if np.any(where):
                    ax.loglog(r[where], pre * r[where] ** slope, style, label=f"slope {slope:.2f}")
            ax.axvline(lam, color="gray", lw=0.8, label="λ_c")
            ax.set(xlabel="r / a", ylabel="response of the other contacts",
                   title="a contact breaks: the response against distance")
            ax.legend(fontsize=8)
    log.info(f"near exponent {fit.near_exponent:.3f} (r < {near:g}), far {fit.far_exponent:.3f} "
             f"(r > 3 λ_c), crossover at {fit.crossover / lam:.2f} λ_c; results in {out}/: "
             "interface.json, response.csv, interaction.png")
    return 0


# --- Frenkel-Kontorova slip fronts --------------------------------------------------------------

def _run_fk(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
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
    results.write_summary(out / "interface.json", summary, comm)
    if comm.rank == 0:
        panels = 2 if args.forces else 1
        with plotting.saved_figure(out / "fk.png", ncols=panels,
                                   figsize=(5.5 * panels, 4)) as axes:
            ax = axes[0]
            sites = np.flatnonzero(broken)
            ax.plot(run.break_time[sites], sites * chain.a, ".", ms=3)
            ax.set(xlabel="t", ylabel="x of the contact (first break)",
                   title=f"front in the x–t plane, f = {args.force:g}")
            if args.forces:
                ax = axes[1]
                s = summary["front_speeds"]
                fine = np.linspace(chain.f_min, chain.f_max, 201)[1:-1]
                ax.plot(s["force"], s["measured"], "o", label="chain")
                ax.plot(fine, chain.continuum_front_speed(fine), "k-",
                        label="continuum travelling wave")
                ax.plot(fine, chain.low_velocity_speed(fine), "k--", lw=0.8,
                        label="low-velocity limit")
                ax.plot(fine, chain.high_velocity_speed(fine), "k:", lw=0.8,
                        label="high-velocity limit")
                ax.set_ylim(0, 1.2 * chain.sound_speed)
                ax.axhline(chain.sound_speed, color="gray", ls=":", label="sound speed")
                ax.set(xlabel="f", ylabel="front speed", title="front speed against the force")
                ax.legend(fontsize=8)
    log.info(f"{summary['contacts_broken']} contacts broken; front speed "
             f"{summary.get('front_speed', float('nan')):.6g} (continuum "
             f"{summary['continuum_front_speed'] or float('nan'):.6g}); results in {out}/: "
             "interface.json, fk.csv, fk.png" + (", front_speeds.csv" if args.forces else ""))
    return 0


# --- the elastic slider on an EQ interface ------------------------------------------------------

def _run_slider(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    from fenicsfriction.io import FieldWriter
    from fenicsfriction.studies.multicontact import ElasticSlider, ElasticSliderModel

    names = ("L", "H", "nx", "ny", "E", "nu", "rho", "k", "threshold", "spread", "delay",
             "push_speed", "seed")
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
               "slip_force": history.slip_force,
               "peak_push_force": float(np.max(history.push_force))}
    results.write_summary(out / "interface.json", summary, comm)
    with FieldWriter(out / "slider.xdmf", model) as writer:
        writer.write(float(model.time.value))
    if comm.rank == 0:
        with plotting.saved_figure(out / "fronts.png", ncols=2, figsize=(11, 4)) as (a1, a2):
            a1.plot(np.array(history.time) * 1e3, np.array(history.front_position) / scene.L, "-")
            for b in history.breaks:
                a1.plot(b.time * 1e3, b.x / scene.L, ".", color="tab:red", ms=2)
            a1.set(xlabel="t [ms]", ylabel="x / L", title="detachment fronts (breaks in red)")
            a2.plot(np.array(history.time) * 1e3, history.push_force, "-")
            a2.set(xlabel="t [ms]", ylabel="push force [N/m]",
                   title="the force on the trailing edge")
    log.info(f"{len(history.breaks)} breaks, {len(history.fronts)} fronts, slip force "
             f"{history.slip_force}; results in {out}/: interface.json, slider.csv, fronts.png, "
             "slider.xdmf")
    return 0


#: the models' parameter names whose flag is not ``--name``
_FLAGS = {"n_contacts": "--N", "relative_spread": "--spreads", "X_max": "--X-max"}


def run_interface(args: argparse.Namespace, log: logging.Logger) -> int:
    """``interface COMMAND``: the model, its numbers and figures."""
    run = {"eq": _run_eq, "master-equation": _run_master_equation,
           "stability-map": _run_stability_map, "interaction": _run_interaction,
           "fk": _run_fk, "slider": _run_slider}[args.model]
    try:
        code = run(args, log, MPI.COMM_WORLD)
        MPI.COMM_WORLD.Barrier()  # rank 0's figures are written before any rank returns
        return code
    except ValueError as err:  # the models name their parameters: name the flags
        raise ValueError(named_by_flag(str(err), _FLAGS)) from None
