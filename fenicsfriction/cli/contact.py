"""``fenicsfriction contact hertz|patch|cattaneo``: two elastic bodies in contact
(node-to-segment or mortar, ``--formulation``), each scene against its closed form (Hertz
1882; Taylor & Papadopoulos 1991's patch test; Cattaneo 1938 and Mindlin 1949).

Each command writes to ``--out``: ``contact.json`` (the scene's summary), ``surface.csv`` (the
slave surface's nodal values beside the closed forms), ``pressure.png``, ``deformed.png`` (2D),
``traction.png`` (Cattaneo) and ``bodies.xdmf`` (the displacement on the mesh of both bodies,
with the cell and facet tags). Every Newton solve prints one progress line (approach, contact
force, Newton iterations), every increment of the tangential load another.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import logging
import pathlib
import typing

from fenicsfriction.cli import press_drag
from fenicsfriction.cli.arguments import Parser, floats

if typing.TYPE_CHECKING:
    from mpi4py import MPI

    import numpy as np

    from fenicsfriction.studies.contact.model import TwoBodyModel

__all__ = ["add_parser", "run_contact"]

#: the logger of the model, whose debug line reports each solve of the load's approach
_MODEL_LOGGER = "fenicsfriction.studies.contact.model"

#: the contact's discretisations (:data:`fenicsfriction.contact.FORMULATIONS`, spelled here so
#: that parsing the flags imports no dolfinx) and the enforcements of node-to-segment's law
_FORMULATIONS = ("node-to-segment", "mortar")
_ENFORCEMENTS = ("compliance", "perturbed-lagrangian")


def _formulation(text: str) -> str:
    """``--formulation``'s value; the law's enforcement, which this flag chose before, is
    pointed to ``--enforcement``."""
    if text in _ENFORCEMENTS:
        raise argparse.ArgumentTypeError(
            f"{text!r} is an enforcement of the law now: use --enforcement {text} "
            f"(--formulation is {' or '.join(_FORMULATIONS)})")
    if text not in _FORMULATIONS:
        raise argparse.ArgumentTypeError(
            f"invalid choice: {text!r} (choose from {', '.join(_FORMULATIONS)})")
    return text


def _bodies_flags() -> argparse.ArgumentParser:
    """The two bodies and their interface law, shared by the contact scenes (None: the scene's
    defaults, given in the help)."""
    flags = Parser(add_help=False)
    group = flags.add_argument_group("the two bodies and the interface law")
    for flag, text in (("--E1", "body 1's Young's modulus (1)"),
                       ("--nu1", "body 1's Poisson's ratio (0.3)"),
                       ("--E2", "body 2's Young's modulus (1)"),
                       ("--nu2", "body 2's Poisson's ratio (0.3)"),
                       ("--c-n", "normal compliance coefficient: p = c_n d^m_n (1e4)"),
                       ("--m-n", "normal compliance exponent, >= 1 (1: a linear penalty)")):
        group.add_argument(flag, type=float, dest=flag[2:].replace("-", "_"), help=text)
    _discretisation_flags(flags)
    flags.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    return flags


def _discretisation_flags(parser: argparse.ArgumentParser) -> None:
    """``--formulation`` and ``--degree``, the contact's discretisation (every scene's)."""
    discretisation = parser.add_argument_group("the contact's discretisation")
    discretisation.add_argument(
        "--formulation", type=_formulation, metavar="{" + ",".join(_FORMULATIONS) + "}",
        help="node-to-segment (slave nodes on master segments, nodal rule) or mortar (the law "
             "on mortar-weighted gaps, segment-to-segment integration) (node-to-segment)")
    discretisation.add_argument("--degree", type=int, choices=[1, 2],
                                help="Lagrange degree of the displacement; 2 needs "
                                     "--formulation mortar (1)")


def _hertz_flags(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--load", type=float,
                        help="P per unit length (2D) or the total force F (3D); default: the "
                             "load giving a = R/10")
    parser.add_argument("--radius", type=float, help="R of the cylinder or sphere (1)")
    parser.add_argument("--refine", type=int,
                        help="mesh refinement level: each halves the element size (0: 0.005 R "
                             "at the contact)")
    parser.add_argument("--h-contact", type=float,
                        help="the element size at the contact before --refine (0.005 R)")


def _partition_flag(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--partition", help="how the mesh is cut over the ranks: graph "
                        "(dolfinx's partitioner) or contact (both bodies across the contact "
                        "plane) (graph)")


def add_parser(commands: typing.Any) -> None:
    """``contact hertz|patch|cattaneo``: the two-body validation scenes."""
    contact = commands.add_parser(
        "contact", help="two elastic bodies in contact (node-to-segment or mortar), against "
                        "closed forms",
        description="Validation scenes of two-body contact: Hertz (2D cylinder, 3D sphere), "
                    "the contact patch test and Cattaneo-Mindlin's partial slip; each writes "
                    "contact.json, surface.csv, figures and bodies.xdmf to --out. PETSc "
                    "options as -contact_<option> after the flags.")
    contact.set_defaults(run=run_contact)
    scenes = contact.add_subparsers(dest="scene", required=True, parser_class=Parser,
                                    metavar="STUDY")
    bodies = _bodies_flags()
    hertz = scenes.add_parser(
        "hertz", parents=[bodies], help="cylinder (2D) or sphere (3D) on a block, vs Hertz",
        description="A cylinder (plane strain) or a quarter sphere pressed on an elastic "
                    "block to the load --load: contact half-width (radius) and peak pressure "
                    "against Hertz's.")
    hertz.add_argument("--dim", type=int, choices=[2, 3], default=2, help="2 or 3 (2)")
    _partition_flag(hertz)
    _hertz_flags(hertz)
    hertz.add_argument("--passes", type=int, choices=[1, 2], default=1,
                       help="1: the cylinder's surface is the slave; 2: each surface in turn")
    patch = scenes.add_parser(
        "patch", parents=[bodies], help="the contact patch test (non-matching meshes)",
        description="Two stacked blocks with non-matching meshes under a uniform pressure "
                    "must transmit it uniformly (Taylor & Papadopoulos 1991).")
    patch.add_argument("--dim", type=int, choices=[2, 3], default=2, help="2 or 3 (2)")
    _partition_flag(patch)
    patch.add_argument("--passes", choices=["1", "2", "both"], default="both",
                       help="one pass, two passes, or both side by side (both)")
    patch.add_argument("--pressure", type=float, help="the pressure applied (0.01)")
    patch.add_argument("--n-upper", type=int, help="elements across the upper block (5)")
    patch.add_argument("--n-lower", type=int, help="elements across the lower block (7)")
    cattaneo = scenes.add_parser(
        "cattaneo", parents=[bodies], help="partial slip under a tangential force (2D)",
        description="The 2D Hertz cylinder with friction, then a tangential force rising to "
                    "Q = q μP in increments (Pop's incremental formulation): stick zone "
                    "and tangential traction against Cattaneo (1938) and Mindlin (1949).")
    _hertz_flags(cattaneo)
    cattaneo.add_argument("--passes", type=int, choices=[1, 2], default=1,
                          help="1: the cylinder's surface is the slave; 2: each in turn")
    cattaneo.add_argument("--mu", type=float, help="friction coefficient (0.3)")
    cattaneo.add_argument("--q-ratio", type=float, help="Q/(μP) reached, in [0, 1) (0.5)")
    cattaneo.add_argument("--increments", type=int, help="increments of Q (10)")
    cattaneo.add_argument("--eps", type=float,
                          help="regularisation of the slip increment [length] (1e-6)")
    cattaneo.add_argument("--eps-sequence", type=floats, metavar="E1,E2,...",
                          help="Kalker's sequential process: the tangential loading again for "
                               "each ε (replaces --eps)")
    cattaneo.add_argument("--enforcement", choices=_ENFORCEMENTS,
                          help="how the law is enforced: normal compliance with regularised "
                               "friction, or Pop's perturbed Lagrangian (penalties c_n and "
                               "--penalty-T; node-to-segment only) (compliance)")
    cattaneo.add_argument("--penalty-T", dest="penalty_T", type=float,
                          help="tangential penalty of the perturbed Lagrangian "
                               "[force/length^3] (1e4)")
    press_drag.add_parser(scenes, _discretisation_flags)


def _named_by_flag(message: str, args: argparse.Namespace) -> str:
    """A scene's or mesh's ``name=value is invalid: ...`` with ``name`` replaced by its flag,
    when the user gave that flag."""
    from fenicsfriction.cli.common import flag

    given = [k for k, v in vars(args).items() if v is not None]
    for name in sorted(given, key=len, reverse=True):
        if message.startswith(f"{name}="):
            return flag(name) + message[len(name):]
    return message


@contextlib.contextmanager
def _solve_lines(comm: MPI.Comm) -> typing.Iterator[None]:
    """Let the model's line about each solve (approach, contact force, Newton iterations)
    through on rank 0 for the duration of the block."""
    logger = logging.getLogger(_MODEL_LOGGER)
    level = logger.level
    if comm.rank == 0:
        logger.setLevel(logging.DEBUG)
    try:
        yield
    finally:
        logger.setLevel(level)


def _discretisation(scene: typing.Any) -> str:
    return f"{scene.formulation} contact, degree {scene.degree}"


def _percent(value: float, reference: float) -> str:
    return f"{value:.5g} (closed form {reference:.5g}, {100 * (value / reference - 1):+.2f} %)"


def _write_fields(path: pathlib.Path, model: TwoBodyModel) -> None:
    """The displacement with the cell (body) and facet (surface) tags, for ParaView
    (collective)."""
    from dolfinx import fem, io

    from fenicsfriction import _compat

    geometry = model.geometry
    msh = geometry.mesh
    u = model.u
    if _compat.element_degree(u.function_space) != 1:
        # XDMF holds fields of the mesh's coordinate degree (1): the quadratic displacement
        # at the vertices
        u = fem.Function(_compat.vector_function_space(msh, 1), name=model.u.name)
        u.interpolate(model.u)
    msh.topology.create_connectivity(msh.topology.dim - 1, msh.topology.dim)
    geometry.cell_tags.name = "bodies"
    geometry.facet_tags.name = "surfaces"
    with io.XDMFFile(msh.comm, str(path), "w") as xdmf:
        xdmf.write_mesh(msh)
        _compat.write_meshtags(xdmf, geometry.cell_tags, msh)
        _compat.write_meshtags(xdmf, geometry.facet_tags, msh)
        xdmf.write_function(u, 0.0)


def _surface_rows(values: typing.Any, columns: dict[str, np.ndarray], dim: int,
                  extra: dict[str, typing.Any] | None = None) -> list[dict]:
    """One CSV row per slave node: the coordinates, then ``columns``."""
    names = "xy"[:dim - 1]
    rows = []
    for i in range(len(values.x)):
        row = dict(extra or {})
        row.update({n: float(values.x[i, k]) for k, n in enumerate(names)})
        row.update({k: float(v[i]) for k, v in columns.items()})
        rows.append(row)
    return rows


def _hertz_outputs(scene: typing.Any, summary: dict, model: TwoBodyModel, out: pathlib.Path,
                   comm: MPI.Comm, log: logging.Logger,
                   tractions: typing.Sequence[tuple[np.ndarray, str]] = ()) -> None:
    """surface.csv, pressure.png, deformed.png (2D), traction.png (Cattaneo), bodies.xdmf."""
    from fenicsfriction.cli.common import write_rows
    from fenicsfriction.studies.contact import figures
    from fenicsfriction.studies.contact.validation import surface_comparison

    a, _ = scene.closed_form()
    values = model.surface_values()
    dim = model.dim
    r, columns = surface_comparison(scene, values)
    cattaneo = summary["scene"] == "cattaneo"
    write_rows(out / "surface.csv", _surface_rows(values, columns, dim), comm)
    if comm.rank == 0:
        figures.pressure_figure(scene, summary, values, r, out / "pressure.png")
        if cattaneo:
            figures.traction_figure(scene, summary, values, tractions, out / "traction.png")
    figures.deformed_figure(model, out / "deformed.png", a if dim == 2 else None,
                            f"{summary['scene']}: the contact region, displacements at true "
                            "scale", marks=(-a, a))
    _write_fields(out / "bodies.xdmf", model)
    comm.Barrier()
    log.info(f"results in {out}/: contact.json, surface.csv, pressure.png"
             + (", traction.png" if cattaneo else "") + (", deformed.png" if dim == 2 else "")
             + ", bodies.xdmf")


def _run_hertz(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    from fenicsfriction import results
    from fenicsfriction.cli.common import output_folder, scene_from_flags
    from fenicsfriction.studies.contact.validation import Hertz

    scene = scene_from_flags(Hertz, args)
    out = output_folder(args.out)
    a, p0 = scene.closed_form()
    model = scene.build(comm)
    width = "half_width" if scene.dim == 2 else "contact_radius"
    log.info(f"hertz {scene.dim}D: {model.dofs} dofs on {comm.size} rank(s), load "
             f"{scene.load:.6g} ({'per unit length' if scene.dim == 2 else 'total'}), "
             f"{scene.passes} pass(es), {_discretisation(scene)}; Hertz: "
             f"{width.replace('_', ' ')} {a:.6g}, peak "
             f"pressure {p0:.6g}" + ("; a quarter model: each solve's force and load below "
                                     "are a quarter of the total" if scene.dim == 3 else ""))
    try:
        with _solve_lines(comm):
            summary, model = scene.run(comm, model)
    except RuntimeError as err:
        return _failed(out, "hertz", scene, err, comm)
    results.write_summary(out / "contact.json", summary, comm)
    fitted = summary[f"fitted_{width}"], summary["fitted_max_pressure"]
    peak = summary["peak_pressure"]
    log.info(f"{width.replace('_', ' ')} {_percent(summary[width], a)}; peak pressure "
             + ("none" if peak is None else _percent(peak, p0))
             + f" (on the axis), largest nodal {_percent(summary['max_pressure'], p0)}; "
             "Hertz's ellipse fitted to the nodal "
             "pressures: " + (f"{_percent(fitted[0], a)}, {_percent(fitted[1], p0)}"
                              if fitted[0] is not None else "none")
             + f"; {summary['newton_iterations']} Newton iterations in {summary['solves']} "
             f"solves, {summary['wall_time_s']:.1f} s")
    _hertz_outputs(scene, summary, model, out, comm, log)
    return 0


def _run_cattaneo(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    import numpy as np

    from fenicsfriction import results
    from fenicsfriction.cli.common import output_folder, scene_from_flags
    from fenicsfriction.laws import check
    from fenicsfriction.studies.contact.validation import Cattaneo

    sequence = args.eps_sequence
    if sequence is not None:
        check("--eps-sequence", args.eps_sequence, len(sequence) >= 1 and all(
            np.isfinite(e) and e > 0 for e in sequence), "every ε must be > 0")
        check("--eps", args.eps, args.eps is None, "give --eps or --eps-sequence, not both")
    scene = scene_from_flags(Cattaneo, args, **({"eps": sequence[-1]} if sequence else {}))
    out = output_folder(args.out)
    a, _ = scene.closed_form()
    model = scene.build(comm)
    log.info(f"cattaneo: {model.dofs} dofs on {comm.size} rank(s), load {scene.load:.6g} per "
             f"unit length, μ = {scene.law.mu:g}, Q to {scene.q_ratio:g} μP in "
             f"{scene.increments} increments, ε = {sequence if sequence else scene.law.eps}, "
             f"{_discretisation(scene)}; Hertz half-width {a:.6g}")
    tractions: list[tuple[np.ndarray, str]] = []
    counts: dict[float, int] = {}

    def on_increment(row: dict) -> None:
        eps = row.get("eps", scene.law.eps)
        k = counts[eps] = counts.get(eps, 0) + 1
        log.info(f"ε = {eps:.3g}  increment {k}/{scene.increments}  Q/(μP) = "
                 f"{row['q_ratio']:.4g}  stick half-width {row['stick_half_width']:.5g} "
                 f"(Cattaneo-Mindlin {row['cattaneo_stick_half_width']:.5g})  Newton "
                 f"{row['newton_iterations']}")
        if k == scene.increments:  # the traction at the end of this ε's loading
            tractions.append((-model.surface_values().traction[:, 0], f"computed, ε = {eps:g}"))

    try:
        with _solve_lines(comm):
            if sequence:
                summary, model = scene.run_sequence(sequence, comm, model,
                                                    on_increment=on_increment)
            else:
                summary, model = scene.run(comm, model, on_increment=on_increment)
    except RuntimeError as err:
        return _failed(out, "cattaneo", scene, err, comm)
    results.write_summary(out / "contact.json", summary, comm)
    log.info(f"half-width {_percent(summary['half_width'], a)}; stick half-width "
             f"{_percent(summary['stick_half_width'], summary['cattaneo_stick_half_width'])}; "
             f"traction error (L2) {summary['traction_error_l2']:.3%}; "
             f"{summary['newton_iterations']} Newton iterations, {summary['wall_time_s']:.1f} s")
    if sequence:
        log.info("Kalker's sequential process:\n%12s %14s %14s %8s", "eps", "stick half-w.",
                 "traction err.", "Newton")
        for record in summary["eps_sequence"]:
            log.info("%12.3e %14.6g %14.3e %8d", record["eps"], record["stick_half_width"],
                     record["traction_error_l2"], record["newton_iterations"])
    _hertz_outputs(scene, summary, model, out, comm, log, tractions)
    return 0


def _run_patch(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    import numpy as np

    from fenicsfriction import results
    from fenicsfriction.cli.common import output_folder, scene_from_flags, write_rows
    from fenicsfriction.studies.contact import figures
    from fenicsfriction.studies.contact.validation import Patch

    pairings = {"1": {"one_pass": 1}, "2": {"two_pass": 2},
                "both": {"one_pass": 1, "two_pass": 2}}[args.passes]
    scenes = {name: scene_from_flags(Patch, args, passes=passes)
              for name, passes in pairings.items()}
    out = output_folder(args.out)
    summaries, models = {}, {}
    for name, scene in scenes.items():
        log.info(f"patch {scene.dim}D, {name.replace('_', ' ')}: pressure {scene.pressure:g}, "
                 f"{scene.n_upper} and {scene.n_lower} elements across the blocks, "
                 f"{_discretisation(scene)}")
        try:
            with _solve_lines(comm):
                summaries[name], models[name] = scene.run(comm)
        except RuntimeError as err:
            return _failed(out, "patch", scene, err, comm)
        log.info(f"{name.replace('_', ' ')}: largest deviation of the transmitted pressure "
                 f"{summaries[name]['pressure_deviation']:.3e}, "
                 f"{summaries[name]['newton_iterations']} Newton iterations")
    first = next(iter(summaries.values()))
    summary = {**first, "parameters": {**first["parameters"], "passes": args.passes}}
    if args.passes == "both":
        for key in ("pressure_deviation", "newton_iterations", "wall_time_s"):
            summary[key] = {name: s[key] for name, s in summaries.items()}
    results.write_summary(out / "contact.json", summary, comm)
    rows, curves = [], []
    for name, model in models.items():
        scene = scenes[name]
        values = model.surface_values()
        transmitted = values.force[:, -1]
        rows += _surface_rows(values, {"pressure": values.pressure, "transmitted": transmitted,
                                       "applied": np.full(len(transmitted), scene.pressure),
                                       "gap": values.gap}, model.dim, {"passes": scene.passes})
        curves.append((values.x[:, 0], transmitted, f"transmitted, {name.replace('_', ' ')}"))
    write_rows(out / "surface.csv", rows, comm)
    # the two-pass solution (the one that passes the test) when both were run
    name, model = list(models.items())[-1]
    if comm.rank == 0:
        figures.patch_pressure_figure(
            curves, {n: s["pressure_deviation"] for n, s in summaries.items()}, first["dim"],
            scenes[name].pressure, out / "pressure.png")
    figures.deformed_figure(model, out / "deformed.png", None,
                            f"patch test, {name.replace('_', ' ')}")
    for other, m in models.items():
        _write_fields(out / ("bodies.xdmf" if other == name
                             else f"bodies-{other.replace('_', '-')}.xdmf"), m)
    comm.Barrier()
    log.info(f"results in {out}/: contact.json, surface.csv, pressure.png"
             + (", deformed.png" if first["dim"] == 2 else "") + ", bodies.xdmf"
             + (", bodies-one-pass.xdmf" if len(models) > 1 else ""))
    return 0


def _failed(out: pathlib.Path, name: str, scene: typing.Any, err: Exception,
            comm: MPI.Comm) -> int:
    """A solver failure: contact.json saying so, one line, exit status 1."""
    from fenicsfriction import results
    from fenicsfriction.cli.common import stop_line

    results.write_summary(out / "contact.json", {
        "scene": name, "parameters": dataclasses.asdict(scene), "failure": str(err)}, comm)
    stop_line(f"{name}: {err}", comm)
    return 1


def run_contact(args: argparse.Namespace, log: logging.Logger) -> int:
    """``contact hertz|patch|cattaneo``: the scene, its summary and its outputs."""
    from mpi4py import MPI

    run = {"hertz": _run_hertz, "patch": _run_patch, "cattaneo": _run_cattaneo,
           "press-drag": press_drag.run_press_drag}[args.scene]
    try:
        return run(args, log, MPI.COMM_WORLD)
    except ValueError as err:  # the scenes and meshes name their fields: name the flags
        raise ValueError(_named_by_flag(str(err), args)) from None
