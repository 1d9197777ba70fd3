"""``fenicsfriction rolling fastsim|fe|curve``: steady rolling of a Hertzian contact by Kalker's
simplified theory (FASTSIM, no mesh) or by the complete theory (finite elements).

Each command writes to ``--out``: ``rolling.json`` (one record, or one per point of a curve:
``Fx``, ``Fy``, ``Mz``, ``Fn``, ``mu``, ``creepage`` (ξ, η, φ), ``adhesion_fraction``,
``method``, ``parameters``, ``wall_time_s``), ``traction.png`` (the traction against its bound
with the adhesion area), ``creep_curve.png`` (curves: the methods side by side with Kalker's
linear theory) and, for the finite elements, ``rolling.xdmf`` (the displacement and the surface
traction). Every point of a curve prints one progress line. The figures are
:mod:`fenicsfriction.studies.rolling.figures`.
"""

from __future__ import annotations

import argparse
import logging
import pathlib
import typing

from fenicsfriction.cli.arguments import Parser, creep_range, floats

if typing.TYPE_CHECKING:
    from mpi4py import MPI

__all__ = ["add_parser", "run_rolling"]


def _rolling_flags() -> argparse.ArgumentParser:
    """The Hertzian contact, the creepages and the methods' discretisations, shared by the
    rolling commands (None: the defaults given in the help)."""
    flags = Parser(add_help=False)
    contact = flags.add_argument_group("the contact (any consistent units)")
    for flag, text in (("--a", "semi-axis along the rolling direction x [length]"),
                       ("--b", "lateral semi-axis [length] (3D; default: a, a circle)"),
                       ("--G", "shear modulus of the (quasi-identical) bodies [force/length²]"),
                       ("--nu", "Poisson's ratio, in [0, 0.5]"),
                       ("--mu", "friction coefficient"),
                       ("--Fn", "normal force [force] (2D: per unit length)")):
        contact.add_argument(flag, type=float, dest=flag[2:], required=flag not in ("--b",),
                             help=text)
    creep = flags.add_argument_group("creepages (rigid slip over rolling distance)")
    creep.add_argument("--eta", type=float, default=0.0, help="lateral creepage η (0)")
    creep.add_argument("--phi", type=float, default=0.0, help="spin φ [1/length] (0)")
    fastsim = flags.add_argument_group("fastsim (Kalker's simplified theory)")
    fastsim.add_argument("--nx", type=int, help="elements per strip along x")
    fastsim.add_argument("--ny", type=int, help="strips across the contact")
    fastsim.add_argument("--pressure", choices=["parabolic", "ellipsoidal"],
                         help="the traction bound's pressure profile (parabolic: Kalker's)")
    fe = flags.add_argument_group("fe (Kalker's complete theory by finite elements)")
    fe.add_argument("--dim", type=int, choices=[2, 3], default=3,
                    help="2: Carter's cylinders (plane strain); 3: the Hertzian ellipse (3)")
    fe.add_argument("--cells-per-a", type=int,
                    help="cells over the semi-axis a in the contact zone (8)")
    fe.add_argument("--block-size", type=float,
                    help="the half-space block's half-width and depth over a (20)")
    fe.add_argument("--normal", choices=["hertz", "contact"], dest="normal",
                    help="2D: Hertz's pressure, or a frictionless contact against a rigid "
                         "parabola (hertz)")
    fe.add_argument("--eps-sequence", type=floats, metavar="E1,E2,...",
                    help="Kalker's sequential process: the regularisation ε of the slip, "
                         "relative to the creepage, decreasing, each solve from the previous "
                         "one (10 down to 0.01 in steps of √10)")
    flags.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    return flags


def add_parser(commands: typing.Any) -> None:
    """``rolling fastsim|fe|curve``: Kalker's steady rolling of a Hertzian contact."""
    rolling = commands.add_parser(
        "rolling", help="steady rolling contact: creep forces by Kalker's theories",
        description="Steady rolling of two quasi-identical elastic bodies with a Hertzian "
                    "contact: the creep forces, the traction and the adhesion area by the "
                    "simplified theory (FASTSIM) or by the complete theory (finite elements, "
                    "the sequential ε process). Each writes rolling.json, figures and (fe) "
                    "rolling.xdmf to --out; PETSc options as -rolling_<option> after the flags.")
    rolling.set_defaults(run=run_rolling)
    methods = rolling.add_subparsers(dest="method", required=True, parser_class=Parser,
                                     metavar="STUDY")
    flags = _rolling_flags()
    for name, text in (("fastsim", "Kalker's FASTSIM (no mesh): one creepage"),
                       ("fe", "the complete theory by finite elements: one creepage")):
        one = methods.add_parser(name, parents=[flags], help=text, description=text + ".")
        one.add_argument("--xi", type=float, default=0.0, help="longitudinal creepage ξ (0)")
    curve = methods.add_parser(
        "curve", parents=[flags], help="the creep-force curve over a range of ξ",
        description="The creep-force curve Fx(ξ) by one method, beside FASTSIM and Kalker's "
                    "linear theory; one rolling.json record per point.")
    curve.add_argument("--method", choices=["fastsim", "fe"], dest="curve_method",
                       default="fastsim", help="the theory computing the curve (fastsim)")
    curve.add_argument("--xi-range", type=creep_range, required=True, metavar="LO:HI:N",
                       help="N longitudinal creepages from LO to HI")


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
    import numpy as np

    from fenicsfriction.studies.rolling.fastsim import creep_curve

    grid = {k: p[k] for k in _METHOD_FLAGS["fastsim"] if k in p}
    points = creep_curve(p["a"], p["b"], p["G"], p["nu"], p["mu"], p["Fn"], xi=np.asarray(xi),
                         eta=np.full(len(xi), args.eta), phi=np.full(len(xi), args.phi), **grid)
    records = [_record("fastsim", p, r.Fx, r.Fy, r.Mz, r.Fn, (r.xi, r.eta, r.phi),
                       r.adhesion_fraction, r.wall_time_s) for r in points]
    return records, points


# --- the finite element complete theory -------------------------------------------------------

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
        try:
            solution = model.solve((value, args.eta, args.phi))
        except RuntimeError as err:  # say where: which point of the curve, which creepages
            raise RuntimeError(f"point {k + 1}/{len(xi)} (ξ = {value:.6g}, η = {args.eta:.6g}, "
                               f"φ = {args.phi:.6g}): {err}") from err
        bound = p["mu"] * solution.Fn
        lateral = "" if model.dim == 2 else (
            f"  Fy/(μFn) = {solution.Fy / bound:+.5f}  Mz = {solution.Mz:.6g}")
        log.info(f"point {k + 1}/{len(xi)}: ξ = {value:.4g}  Fx/(μFn) = "
                 f"{solution.Fx / bound:+.5f}{lateral}  adhesion "
                 f"{solution.adhesion_fraction:.3f}  Newton {solution.newton_iterations} over "
                 f"{len(solution.eps_records)} ε  {solution.wall_time_s:.1f} s")
        records.append(_record("fe", p, solution.Fx, solution.Fy, solution.Mz, solution.Fn,
                               (value, args.eta, args.phi), solution.adhesion_fraction,
                               solution.wall_time_s, newton_iterations=solution.newton_iterations,
                               eps=solution.eps, dofs=model.dofs))
        solutions.append(solution)
    return records, solutions


# --- outputs ------------------------------------------------------------------------------------

def _write(out: pathlib.Path, records: list[dict], curve: bool, comm: MPI.Comm) -> None:
    from fenicsfriction import results

    data: typing.Any = {"records": records} if curve else records[0]
    results.write_summary(out / "rolling.json", data, comm)


def _validate(args: argparse.Namespace) -> None:
    import numpy as np

    from fenicsfriction.cli.common import flag
    from fenicsfriction.laws import check

    for name in ("a", "G", "Fn"):
        check(flag(name), getattr(args, name), np.isfinite(getattr(args, name))
              and getattr(args, name) > 0, "must be a finite number > 0")
    if args.b is not None:
        check("--b", args.b, np.isfinite(args.b) and args.b > 0, "must be a finite number > 0")
    check("--nu", args.nu, 0 <= args.nu <= 0.5, "must be in [0, 0.5]")
    check("--mu", args.mu, np.isfinite(args.mu) and args.mu > 0, "must be a finite number > 0")


#: the scenes' and models' parameter names whose flag is not ``--name``
_FLAGS = {"pressure": "--normal", "xi": "--xi", "eta": "--eta",
          "phi": "--phi"}


def run_rolling(args: argparse.Namespace, log: logging.Logger) -> int:
    """``rolling fastsim|fe|curve``: the creep forces, the traction, the outputs."""
    from fenicsfriction.cli.common import named_by_flag

    try:
        return _run(args, log)
    except ValueError as err:  # the models name their parameters: name the flags
        raise ValueError(named_by_flag(str(err), _FLAGS)) from None


def _run(args: argparse.Namespace, log: logging.Logger) -> int:
    from mpi4py import MPI

    from fenicsfriction import results
    from fenicsfriction.cli.common import output_folder, stop_line
    from fenicsfriction.studies.rolling import figures

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
            figures.fastsim_traction_figure(points[-1], p, out / "traction.png")
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
            figures.fe_traction_figure(solutions[-1], p, model.dim, out / "traction.png")
        written = ["rolling.json", "traction.png", "rolling.xdmf"]
    _write(out, records, curve, comm)
    if curve:
        if comm.rank == 0:
            figures.creep_curve_figure(records, p, args.eta, args.phi, out / "creep_curve.png")
        written.append("creep_curve.png")
    comm.Barrier()
    log.info(f"results in {out}/: {', '.join(written)}")
    return 0
