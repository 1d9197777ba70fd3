"""The contact family's figures: the contact pressure and the tangential traction against the
closed forms (Hertz 1882; Cattaneo 1938 and Mindlin 1949), the patch test's transmitted
pressure (Taylor & Papadopoulos 1991) and the deformed bodies around the contact, built on
:mod:`fenicsfriction.plotting`."""

from __future__ import annotations

import typing

import numpy as np

from fenicsfriction import plotting
from fenicsfriction.studies.contact import closed_forms

if typing.TYPE_CHECKING:
    from fenicsfriction.plotting import PathLike
    from fenicsfriction.studies.contact.model import SurfaceValues, TwoBodyModel
    from fenicsfriction.studies.contact.validation import Hertz

__all__ = ["deformed_figure", "energy_balance_figure", "patch_pressure_figure",
           "pressure_figure", "traction_figure"]

#: half-widths of the window of the deformed figure around the contact, in contact half-widths
WINDOW = (2.5, 1.2)


def pressure_figure(scene: Hertz, summary: dict, values: SurfaceValues, r: np.ndarray,
                    path: PathLike) -> None:
    """The computed pressure at the slave nodes near the contact against Hertz's, dotted
    verticals at ±a (2D) or a (3D). Call on rank 0.

    Args:
        scene: the Hertz or Cattaneo scene solved.
        summary: its summary (``scene``, the contact half-width or radius, ``max_pressure``).
        values: the slave surface's values.
        r: the nodes' distance from the axis (:func:`~.validation.surface_comparison`).
        path: the PNG to write.
    """
    a, p0 = scene.closed_form()
    dim = values.x.shape[1]
    width = "half_width" if dim == 2 else "contact_radius"
    grid = np.linspace(-1.5 * a, 1.5 * a, 601) if dim == 2 else np.linspace(0, 1.5 * a, 301)
    near = np.abs(r) <= 1.5 * a
    plotting.plot_contact_pressure(
        [(r[near], values.pressure[near], "computed (slave nodes)")], path,
        "x" if dim == 2 else "r = √(x² + y²)",
        f"{summary['scene']} {dim}D: {width.replace('_', ' ')} {summary[width]:.4g} "
        f"(Hertz {a:.4g}), largest nodal pressure {summary['max_pressure']:.4g} "
        f"(Hertz's peak {p0:.4g})",
        reference=(grid, closed_forms.hertz_pressure(grid, a, p0), "Hertz"),
        marks=(-a, a) if dim == 2 else (a,))


def traction_figure(scene: typing.Any, summary: dict, values: SurfaceValues,
                    tractions: typing.Sequence[tuple[np.ndarray, str]], path: PathLike) -> None:
    """Cattaneo's tangential traction at the end of each loading (``tractions``: the traction
    on the block at the slave nodes and its label) against Cattaneo-Mindlin's, with the bound
    μ p and the stick zone. Call on rank 0."""
    a, p0 = scene.closed_form()
    grid = np.linspace(-1.5 * a, 1.5 * a, 601)
    c = closed_forms.cattaneo_stick_half_width(a, scene.q_ratio)
    plotting.plot_contact_traction(
        values.x[:, 0], tractions, scene.law.mu * values.pressure, grid,
        closed_forms.cattaneo_traction(grid, a, p0, scene.law.mu, scene.q_ratio),
        scene.law.mu * closed_forms.hertz_pressure(grid, a, p0), a, c, path,
        f"Q = {scene.q_ratio:g} μP, μ = {scene.law.mu:g}: stick half-width "
        f"{summary['stick_half_width']:.4g} (Cattaneo-Mindlin {c:.4g})")


def patch_pressure_figure(curves: typing.Sequence[tuple[np.ndarray, np.ndarray, str]],
                          deviations: dict[str, float], dim: int, pressure: float,
                          path: PathLike) -> None:
    """The patch test: the pressure transmitted across the non-matching interface by each
    pairing (``curves``: abscissa, pressure, label) against the one applied. Call on rank 0.

    Args:
        curves: one per pairing.
        deviations: the largest deviation of each pairing (``one_pass``, ``two_pass``).
        dim: 2 or 3.
        pressure: the pressure applied.
        path: the PNG to write.
    """
    x = np.array([c[0].min() for c in curves] + [c[0].max() for c in curves])
    text = ", ".join(f"{n.replace('_', ' ')} {d:.2e}" for n, d in deviations.items())
    plotting.plot_contact_pressure(
        curves, path, "x", f"patch test {dim}D: largest deviation {text}",
        reference=(np.array([x.min(), x.max()]), np.full(2, pressure), "applied"))


def deformed_figure(model: TwoBodyModel, path: PathLike, half_width: float | None,
                    title: str, marks: typing.Sequence[float] = ()) -> None:
    """The deformed bodies of a 2D model (none in 3D): around the contact zone at true scale
    (``half_width`` given: Hertz, Cattaneo) or the whole bodies magnified (the patch test).
    Collective: the cells are gathered on rank 0, which draws."""
    if model.dim != 2:
        return
    if half_width is not None:
        w, h = WINDOW
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


def energy_balance_figure(records: typing.Sequence[dict], summary: dict, path: PathLike) -> None:
    """The cylinder pressed and dragged (:class:`~.impact.PressAndDrag`): the energies, the
    work of the loads and the dissipated energy against time (left), and the drift of the
    balance over the largest work (right). Call on rank 0."""
    t = np.array([r["time"] for r in records])
    keys = ("kinetic", "elastic", "contact_energy", "work", "dissipated")
    work = max(max(abs(r["work"]) for r in records), np.finfo(float).tiny)
    balance = np.array([r["balance"] for r in records])
    with plotting.saved_figure(path, ncols=2, figsize=(11, 4.2)) as (left, right):
        for key in keys:
            left.plot(t, [r[key] for r in records], label=key.replace("_", " "))
        left.set_xlabel("t")
        left.set_ylabel("energy")
        left.legend(fontsize=8)
        right.plot(t, (balance - balance[0]) / work)
        right.set_xlabel("t")
        right.set_ylabel("(balance − initial) / largest work")
        error = summary.get("energy_balance_error")
        right.set_title(f"{summary.get('scheme')}, dt = {summary.get('dt'):.3g}: "
                        + ("no work yet" if error is None else f"error {error:.2e}"),
                        fontsize=9)
