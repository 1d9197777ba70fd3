"""``fenicsfriction contact hertz|patch|cattaneo``: two elastic bodies in node-to-segment
contact, each scene against its closed form (Hertz 1882; Taylor & Papadopoulos 1991's patch
test; Cattaneo 1938 and Mindlin 1949).

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

from mpi4py import MPI

import numpy as np

from fenicsfriction import _compat, plotting, results
from fenicsfriction.cli.common import (
    flag,
    output_folder,
    scene_from_flags,
    stop_line,
    write_rows,
)
from fenicsfriction.laws import check

if typing.TYPE_CHECKING:
    from fenicsfriction.studies.contact.model import TwoBodyModel

__all__ = ["run_contact"]

#: the logger of the model, whose debug line reports each solve of the load's approach
_MODEL_LOGGER = "fenicsfriction.studies.contact.model"

#: half-widths of the window of deformed.png around the contact, in contact half-widths
_WINDOW = (2.5, 1.2)


def _named_by_flag(message: str, args: argparse.Namespace) -> str:
    """A scene's or mesh's ``name=value is invalid: ...`` with ``name`` replaced by its flag,
    when the user gave that flag."""
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


def _percent(value: float, reference: float) -> str:
    return f"{value:.5g} (closed form {reference:.5g}, {100 * (value / reference - 1):+.2f} %)"


def _write_fields(path: pathlib.Path, model: TwoBodyModel) -> None:
    """The displacement with the cell (body) and facet (surface) tags, for ParaView
    (collective)."""
    from dolfinx import io

    geometry = model.geometry
    msh = geometry.mesh
    msh.topology.create_connectivity(msh.topology.dim - 1, msh.topology.dim)
    geometry.cell_tags.name = "bodies"
    geometry.facet_tags.name = "surfaces"
    with io.XDMFFile(msh.comm, str(path), "w") as xdmf:
        xdmf.write_mesh(msh)
        _compat.write_meshtags(xdmf, geometry.cell_tags, msh)
        _compat.write_meshtags(xdmf, geometry.facet_tags, msh)
        xdmf.write_function(model.u, 0.0)


def _deformed(model: TwoBodyModel, path: pathlib.Path, half_width: float | None,
              title: str, marks: typing.Sequence[float] = ()) -> None:
    """deformed.png of a 2D model: around the contact zone at true scale (``half_width``
    given: Hertz, Cattaneo) or the whole bodies magnified (the patch test)."""
    if model.dim != 2:
        return
    if half_width is not None:
        w, h = _WINDOW
        window = (-w * half_width, w * half_width, -h * half_width, h * half_width)
        cells = plotting.body_cells(model.u, model.geometry.cell_tags, window)
        scale = 1.0
    else:
        cells = plotting.body_cells(model.u, model.geometry.cell_tags)
        scale = 1.0
        if cells is not None:
            corners = cells[0].reshape(-1, 2)
            extent = np.ptp(corners, axis=0)
            window = (corners[:, 0].min() - 0.1 * extent[0], corners[:, 0].max() + 0.1 * extent[0],
                      corners[:, 1].min() - 0.1 * extent[1], corners[:, 1].max() + 0.1 * extent[1])
            amplitude = np.abs(cells[1]).max()
            scale = 0.1 * extent[1] / amplitude if amplitude > 0 else 1.0
            title += f" (displacements ×{scale:.3g})"
    if cells is not None:
        plotting.plot_contact_deformed(cells, path, window, scale, title, marks)


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
    from fenicsfriction.studies.contact import closed_forms

    a, p0 = scene.closed_form()
    values = model.surface_values()
    dim = model.dim
    r = values.x[:, 0] if dim == 2 else np.linalg.norm(values.x[:, :2], axis=1)
    # the tangential traction on the block (the slave's, body 1's, reversed): along Q
    on_block = -values.traction + 0.0
    columns = {"pressure": values.pressure, "hertz_pressure": closed_forms.hertz_pressure(r, a, p0),
               "gap": values.gap}
    if dim == 2:
        columns["traction"] = on_block[:, 0]
    else:
        columns = {"r": r, **columns, "traction_x": on_block[:, 0], "traction_y": on_block[:, 1]}
    cattaneo = summary["scene"] == "cattaneo"
    if cattaneo:
        columns["cattaneo_traction"] = closed_forms.cattaneo_traction(r, a, p0, scene.law.mu,
                                                                      scene.q_ratio)
    write_rows(out / "surface.csv", _surface_rows(values, columns, dim), comm)
    width = "half_width" if dim == 2 else "contact_radius"
    if comm.rank == 0:
        grid = np.linspace(-1.5 * a, 1.5 * a, 601) if dim == 2 else np.linspace(0, 1.5 * a, 301)
        near = np.abs(r) <= 1.5 * a
        plotting.plot_contact_pressure(
            [(r[near], values.pressure[near], "computed (slave nodes)")], out / "pressure.png",
            "x" if dim == 2 else "r = √(x² + y²)",
            f"{summary['scene']} {dim}D: {width.replace('_', ' ')} {summary[width]:.4g} "
            f"(Hertz {a:.4g}), peak {summary['max_pressure']:.4g} (Hertz {p0:.4g})",
            reference=(grid, closed_forms.hertz_pressure(grid, a, p0), "Hertz"),
            marks=(-a, a) if dim == 2 else (a,))
        if cattaneo:
            c = closed_forms.cattaneo_stick_half_width(a, scene.q_ratio)
            plotting.plot_contact_traction(
                values.x[:, 0], tractions, scene.law.mu * values.pressure, grid,
                closed_forms.cattaneo_traction(grid, a, p0, scene.law.mu, scene.q_ratio),
                scene.law.mu * closed_forms.hertz_pressure(grid, a, p0), a, c,
                out / "traction.png",
                f"Q = {scene.q_ratio:g} μP, μ = {scene.law.mu:g}: stick half-width "
                f"{summary['stick_half_width']:.4g} (Cattaneo-Mindlin {c:.4g})")
    _deformed(model, out / "deformed.png", a if dim == 2 else None,
              f"{summary['scene']}: the contact region, displacements at true scale",
              marks=(-a, a))
    _write_fields(out / "bodies.xdmf", model)
    comm.Barrier()
    log.info(f"results in {out}/: contact.json, surface.csv, pressure.png"
             + (", traction.png" if cattaneo else "") + (", deformed.png" if dim == 2 else "")
             + ", bodies.xdmf")


def _run_hertz(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
    from fenicsfriction.studies.contact.validation import Hertz

    scene = scene_from_flags(Hertz, args)
    out = output_folder(args.out)
    a, p0 = scene.closed_form()
    model = scene.build(comm)
    width = "half_width" if scene.dim == 2 else "contact_radius"
    log.info(f"hertz {scene.dim}D: {model.dofs} dofs on {comm.size} rank(s), load "
             f"{scene.load:.6g} ({'per unit length' if scene.dim == 2 else 'total'}), "
             f"{scene.passes} pass(es); Hertz: {width.replace('_', ' ')} {a:.6g}, peak "
             f"pressure {p0:.6g}" + ("; a quarter model: each solve's force and load below "
                                     "are a quarter of the total" if scene.dim == 3 else ""))
    try:
        with _solve_lines(comm):
            summary, model = scene.run(comm, model)
    except RuntimeError as err:
        return _failed(out, "hertz", scene, err, comm)
    results.write_summary(out / "contact.json", summary, comm)
    log.info(f"{width.replace('_', ' ')} {_percent(summary[width], a)}; peak pressure "
             f"{_percent(summary['max_pressure'], p0)}; {summary['newton_iterations']} Newton "
             f"iterations in {summary['solves']} solves, {summary['wall_time_s']:.1f} s")
    _hertz_outputs(scene, summary, model, out, comm, log)
    return 0


def _run_cattaneo(args: argparse.Namespace, log: logging.Logger, comm: MPI.Comm) -> int:
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
             f"{scene.increments} increments, ε = {sequence if sequence else scene.law.eps}; "
             f"Hertz half-width {a:.6g}")
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
    from fenicsfriction.studies.contact.validation import Patch

    pairings = {"1": {"one_pass": 1}, "2": {"two_pass": 2},
                "both": {"one_pass": 1, "two_pass": 2}}[args.passes]
    scenes = {name: scene_from_flags(Patch, args, passes=passes)
              for name, passes in pairings.items()}
    out = output_folder(args.out)
    summaries, models = {}, {}
    for name, scene in scenes.items():
        log.info(f"patch {scene.dim}D, {name.replace('_', ' ')}: pressure {scene.pressure:g}, "
                 f"{scene.n_upper} and {scene.n_lower} elements across the blocks")
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
        x = np.array([c[0].min() for c in curves] + [c[0].max() for c in curves])
        deviations = ", ".join(f"{n.replace('_', ' ')} {s['pressure_deviation']:.2e}"
                               for n, s in summaries.items())
        plotting.plot_contact_pressure(
            curves, out / "pressure.png", "x", f"patch test {first['dim']}D: largest deviation "
            f"{deviations}", reference=(np.array([x.min(), x.max()]),
                                       np.full(2, scenes[name].pressure), "applied"))
    _deformed(model, out / "deformed.png", None, f"patch test, {name.replace('_', ' ')}")
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
    results.write_summary(out / "contact.json", {
        "scene": name, "parameters": dataclasses.asdict(scene), "failure": str(err)}, comm)
    stop_line(f"{name}: {err}", comm)
    return 1


def run_contact(args: argparse.Namespace, log: logging.Logger) -> int:
    """``contact hertz|patch|cattaneo``: the scene, its summary and its outputs."""
    run = {"hertz": _run_hertz, "patch": _run_patch, "cattaneo": _run_cattaneo}[args.scene]
    try:
        return run(args, log, MPI.COMM_WORLD)
    except ValueError as err:  # the scenes and meshes name their fields: name the flags
        raise ValueError(_named_by_flag(str(err), args)) from None
