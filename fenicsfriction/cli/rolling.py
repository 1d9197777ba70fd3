"""``fenicsfriction rolling fastsim|fe|curve``: steady rolling of a Hertzian contact by Kalker's
simplified theory (FASTSIM, no mesh) or by the complete theory (finite elements).

Each command writes to ``--out``: ``rolling.json`` (one record, or one per point of a curve:
``Fx``, ``Fy``, ``Mz``, ``Fn``, ``mu``, ``creepage`` (ξ, η, φ), ``adhesion_fraction``,
``method``, ``parameters``, ``wall_time_s``), ``traction.png`` (the traction against its bound
with the adhesion area), ``creep_curve.png`` (curves: the methods side by side with Kalker's
linear theory) and, for the finite elements, ``rolling.xdmf`` (the displacement and the surface
traction). Every point of a curve prints one progress line.
"""

from __future__ import annotations

import argparse
import logging
import pathlib
import typing

from mpi4py import MPI

import numpy as np

from fenicsfriction import plotting, results
from fenicsfriction.cli.common import flag, named_by_flag, output_folder, stop_line
from fenicsfriction.laws import check

__all__ = ["run_rolling"]


#: the flags of each method's discretisation
_METHOD_FLAGS = {"fastsim": ("nx", "ny", "pressure"),
                 "fe": ("dim", "cells_per_a", "block_size", "normal", "eps_sequence")}


def _parameters(args: argparse.Namespace, method: str) -> dict[str, typing.Any]:
    """The contact's data and ``method``'s discretisation, as given (b: a when not given)."""
    names = ("a", "b", "G", "nu", "mu", "Fn") + _METHOD_FLAGS[method]
    values = {k: getattr(args, k, None) for k in names}
    if values["b"] is None:
        values["b"] = values["a"]
    if values.get("dim") == 2:  # a line contact: no lateral semi-axis
        del values["b"]
    return {k: v for k, v in values.items() if v is not None}


def _record(method: str, parameters: dict, Fx: float, Fy: float, Mz: float | None, Fn: float,
            creepage: tuple[float, float, float], adhesion_fraction: float,
            wall_time_s: float, **extra: typing.Any) -> dict[str, typing.Any]:
    xi, eta, phi = creepage
    return {"method": method, "Fx": Fx, "Fy": Fy, "Mz": Mz, "Fn": Fn, "mu": parameters["mu"],
            "creepage": {"xi": xi, "eta": eta, "phi": phi},
            "adhesion_fraction": adhesion_fraction, "wall_time_s": wall_time_s,
            "parameters": parameters, **extra}


# --- FASTSIM ------------------------------------------------------------------------------------

def _fastsim_records(p: dict, args: argparse.Namespace,
                     xi: typing.Sequence[float]) -> tuple[list, list]:
    """(records, FASTSIM results) of the parameters ``p`` at the creepages ``xi`` (with the
    flags' η and φ)."""
    from fenicsfriction.studies.rolling.fastsim import creep_curve

    grid = {k: p[k] for k in _METHOD_FLAGS["fastsim"] if k in p}
    points = creep_curve(p["a"], p["b"], p["G"], p["nu"], p["mu"], p["Fn"], xi=np.asarray(xi),
                         eta=np.full(len(xi), args.eta), phi=np.full(len(xi), args.phi), **grid)
    records = [_record("fastsim", p, r.Fx, r.Fy, r.Mz, r.Fn, (r.xi, r.eta, r.phi),
                       r.adhesion_fraction, r.wall_time_s) for r in points]
    return records, points


def _fastsim_traction(result: typing.Any, p: dict, path: pathlib.Path) -> None:
    plotting.plot_rolling_traction_map(
        result.x.ravel(), result.y.ravel(), result.px.ravel(), result.py.ravel(),
        p["mu"] * result.pn.ravel(), result.adhesion.ravel(), p["a"], p["b"], path,
        f"FASTSIM: ξ = {result.xi:.4g}, η = {result.eta:.4g}, φ = {result.phi:.4g};\n"
        f"Fx/(μFn) = {result.Fx / (p['mu'] * result.Fn):.4f}, adhesion "
        f"{result.adhesion_fraction:.1%} of the area")


# --- the finite element complete theory -------------------------------------------------------

def _cylinders(p: dict) -> tuple[float, float]:
    """Hertz's peak pressure p0 and the relative radius R of Carter's cylinders (2D)."""
    from fenicsfriction.studies.rolling import RollingContact

    scene = RollingContact(dim=2, a=p["a"], G=p["G"], nu=p["nu"], Fn=p["Fn"])
    return scene.peak_pressure, scene.radius


def _fe_model(p: dict, comm: MPI.Comm) -> typing.Any:
    """The finite element model of the parameters ``p`` (built once, re-solved per creepage)."""
    from fenicsfriction.studies.rolling import RollingContact

    renamed = {"normal": "pressure"}
    fields: dict[str, typing.Any] = {renamed.get(k, k): (tuple(v) if k == "eps_sequence" else v)
                                     for k, v in p.items() if k != "mu"}
    scene = RollingContact(**fields).with_law(mu=p["mu"])
    return scene.build(comm)


def _fe_records(model: typing.Any, p: dict, args: argparse.Namespace,
                xi: typing.Sequence[float], log: logging.Logger) -> tuple[list, list]:
    """(records, results) of the creepages ``xi`` in turn, each from the last."""
    records, solutions = [], []
    for k, value in enumerate(xi):
        solution = model.solve((value, args.eta, args.phi))
        log.info(f"point {k + 1}/{len(xi)}: ξ = {value:.4g}  Fx/(μFn) = "
                 f"{solution.Fx / (p['mu'] * solution.Fn):+.5f}  adhesion "
                 f"{solution.adhesion_fraction:.3f}  Newton {solution.newton_iterations} over "
                 f"{len(solution.eps_records)} ε  {solution.wall_time_s:.1f} s")
        records.append(_record("fe", p, solution.Fx, solution.Fy, solution.Mz, solution.Fn,
                               (value, args.eta, args.phi), solution.adhesion_fraction,
                               solution.wall_time_s, newton_iterations=solution.newton_iterations,
                               eps=solution.eps, dofs=model.dofs))
        solutions.append(solution)
    return records, solutions


def _fe_traction(result: typing.Any, p: dict, dim: int, path: pathlib.Path) -> None:
    """traction.png of a finite element solution: the line contact against Carter (2D), the
    elliptic map (3D)."""
    xi = result.creepage[0]
    title = (f"complete theory (FE): ξ = {xi:.4g}; Fx/(μFn) = "
             f"{result.Fx / (p['mu'] * result.Fn):.4f}, adhesion {result.adhesion_fraction:.1%}")
    bound = p["mu"] * result.pressure
    if dim == 2:
        from fenicsfriction.studies.rolling import closed_forms
        p0, radius = _cylinders(p)
        grid = np.linspace(-p["a"], p["a"], 401)
        exact = (grid, closed_forms.carter_traction(grid, xi, p["mu"], p["a"], p0, radius),
                 "Carter (1926)")
        plotting.plot_rolling_traction_line(result.x[:, 0], result.traction[:, 0], bound,
                                            result.stick(), path, title, exact)
    else:
        plotting.plot_rolling_traction_map(
            result.x[:, 0], result.x[:, 1], result.traction[:, 0], result.traction[:, 1], bound,
            result.stick(), p["a"], p["b"], path, title.replace("; ", ";\n"))


# --- outputs ------------------------------------------------------------------------------------

def _creep_curve_png(records: list[dict], p: dict, args: argparse.Namespace,
                     path: pathlib.Path) -> None:
    """Fx/(μFn) against ξ: the records' method, FASTSIM beside it (cheap), Kalker's linear
    theory (3D) or Carter's closed form (2D)."""
    xi = np.array([r["creepage"]["xi"] for r in records])
    scale = p["mu"] * p["Fn"]
    fine = np.linspace(min(xi.min(), 0.0), xi.max(), 200)
    method = records[0]["method"]
    curves = [(xi, np.array([r["Fx"] for r in records]) / scale,
               "FASTSIM" if method == "fastsim" else "finite elements (complete theory)",
               "o-" if method == "fastsim" else "s")]
    if method == "fastsim" or p["dim"] == 3:
        from fenicsfriction.studies.rolling.fastsim import creep_curve, linear_theory
        if method != "fastsim":
            others = creep_curve(p["a"], p["b"], p["G"], p["nu"], p["mu"], p["Fn"], xi=fine,
                                 eta=np.full(len(fine), args.eta),
                                 phi=np.full(len(fine), args.phi))
            curves.append((fine, np.array([r.Fx for r in others]) / scale, "FASTSIM", "-"))
        slope = linear_theory(p["a"], p["b"], p["G"], p["nu"], xi=1.0).Fx
        if args.eta == 0 and args.phi == 0:
            linear = np.clip(slope * fine / scale, -1.0, 1.0)
            curves.append((fine, linear, "Kalker's linear theory (C11), clipped at μFn", "k:"))
    else:
        from fenicsfriction.studies.rolling.closed_forms import carter_force
        p0, radius = _cylinders(p)
        curves.append((fine, np.array([carter_force(x, p["mu"], p["a"], p0, radius)
                                       for x in fine]) / scale, "Carter (1926)", "k-"))
    plotting.plot_creep_curves(
        curves, path, "longitudinal creepage ξ", "Fx / (μ Fn)",
        f"creep-force curve: a = {p['a']:.4g}"
        + (f", b = {p['b']:.4g}" if "b" in p else " (line contact)") + f", ν = {p['nu']:g}, "
        f"μ = {p['mu']:g}, η = {args.eta:g}, φ = {args.phi:g}")


def _write(out: pathlib.Path, records: list[dict], curve: bool, comm: MPI.Comm) -> None:
    data: typing.Any = {"records": records} if curve else records[0]
    results.write_summary(out / "rolling.json", data, comm)


def _validate(args: argparse.Namespace) -> None:
    for name in ("a", "G", "Fn"):
        check(flag(name), getattr(args, name), np.isfinite(getattr(args, name))
              and getattr(args, name) > 0, "must be a finite number > 0")
    if args.b is not None:
        check("--b", args.b, np.isfinite(args.b) and args.b > 0, "must be a finite number > 0")
    check("--nu", args.nu, 0 <= args.nu <= 0.5, "must be in [0, 0.5]")
    check("--mu", args.mu, np.isfinite(args.mu) and args.mu > 0, "must be a finite number > 0")


#: the scenes' and models' parameter names whose flag is not ``--name``
_FLAGS = {"eps": "--eps-sequence", "pressure": "--normal", "xi": "--xi", "eta": "--eta",
          "phi": "--phi"}


def run_rolling(args: argparse.Namespace, log: logging.Logger) -> int:
    """``rolling fastsim|fe|curve``: the creep forces, the traction, the outputs."""
    try:
        return _run(args, log)
    except ValueError as err:  # the models name their parameters: name the flags
        raise ValueError(named_by_flag(str(err), _FLAGS)) from None


def _run(args: argparse.Namespace, log: logging.Logger) -> int:
    comm = MPI.COMM_WORLD
    _validate(args)
    curve = args.method == "curve"
    method = args.curve_method if curve else args.method
    p = _parameters(args, method)
    xi = args.xi_range if curve else [args.xi]
    out = output_folder(args.out)
    if method == "fastsim":
        records, points = _fastsim_records(p, args, xi)
        if comm.rank == 0:
            _fastsim_traction(points[-1], p, out / "traction.png")
        for r in records:
            log.info(f"ξ = {r['creepage']['xi']:.4g}  Fx = {r['Fx']:.6g}  Fy = {r['Fy']:.6g}  "
                     f"Fx/(μFn) = {r['Fx'] / (r['mu'] * r['Fn']):+.5f}  adhesion "
                     f"{r['adhesion_fraction']:.3f}")
        written = ["rolling.json", "traction.png"]
    else:
        model = _fe_model(p, comm)
        log.info(f"rolling fe {model.dim}D: {model.dofs} dofs on {comm.size} rank(s)")
        try:
            records, solutions = _fe_records(model, p, args, xi, log)
        except RuntimeError as err:
            results.write_summary(out / "rolling.json", {
                "method": "fe", "parameters": p, "failure": str(err)}, comm)
            stop_line(f"rolling fe: {err}", comm)
            return 1
        from fenicsfriction.studies.rolling import write_xdmf
        write_xdmf(out / "rolling.xdmf", model)
        if comm.rank == 0:
            _fe_traction(solutions[-1], p, model.dim, out / "traction.png")
        written = ["rolling.json", "traction.png", "rolling.xdmf"]
    _write(out, records, curve, comm)
    if curve:
        if comm.rank == 0:
            _creep_curve_png(records, p, args, out / "creep_curve.png")
        written.append("creep_curve.png")
    comm.Barrier()
    log.info(f"results in {out}/: {', '.join(written)}")
    return 0
