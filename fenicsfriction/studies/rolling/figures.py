"""The rolling family's figures: the traction against its bound with the adhesion area, and the
creep-force curve beside FASTSIM and the closed forms (Kalker's linear theory; Carter 1926),
built on :mod:`fenicsfriction.plotting`.

``p`` is the dictionary of the contact's data as the command line records it (``a``, ``b``
(3D), ``G``, ``nu``, ``mu``, ``Fn`` and the method's discretisation)."""

from __future__ import annotations

import typing

import numpy as np

from fenicsfriction import plotting

if typing.TYPE_CHECKING:
    from fenicsfriction.plotting import PathLike

__all__ = ["carter_cylinders", "creep_curve_figure", "fastsim_traction_figure",
           "fe_traction_figure", "reference_curves"]


def carter_cylinders(p: dict) -> tuple[float, float]:
    """Hertz's peak pressure p0 and the relative radius R of Carter's cylinders (2D) of the
    contact data ``p``."""
    from fenicsfriction.studies.rolling import RollingContact

    scene = RollingContact(dim=2, a=p["a"], G=p["G"], nu=p["nu"], Fn=p["Fn"])
    return scene.peak_pressure, scene.radius


def fastsim_traction_figure(result: typing.Any, p: dict, path: PathLike) -> None:
    """FASTSIM's traction map of one creepage (a :func:`~.fastsim.creep_curve` point). Call on
    rank 0."""
    plotting.plot_rolling_traction_map(
        result.x.ravel(), result.y.ravel(), result.px.ravel(), result.py.ravel(),
        p["mu"] * result.pn.ravel(), result.adhesion.ravel(), p["a"], p["b"], path,
        f"FASTSIM: ξ = {result.xi:.4g}, η = {result.eta:.4g}, φ = {result.phi:.4g};\n"
        f"Fx/(μFn) = {result.Fx / (p['mu'] * result.Fn):.4f}, adhesion "
        f"{result.adhesion_fraction:.1%} of the area")


def fe_traction_figure(result: typing.Any, p: dict, dim: int, path: PathLike) -> None:
    """The traction of a finite element solution: the line contact against Carter (2D), the
    elliptic map (3D). Call on rank 0."""
    xi = result.creepage[0]
    title = (f"complete theory (FE): ξ = {xi:.4g}; Fx/(μFn) = "
             f"{result.Fx / (p['mu'] * result.Fn):.4f}, adhesion {result.adhesion_fraction:.1%}")
    bound = p["mu"] * result.pressure
    if dim == 2:
        from fenicsfriction.studies.rolling import closed_forms
        p0, radius = carter_cylinders(p)
        grid = np.linspace(-p["a"], p["a"], 401)
        exact = (grid, closed_forms.carter_traction(grid, xi, p["mu"], p["a"], p0, radius),
                 "Carter (1926)")
        plotting.plot_rolling_traction_line(result.x[:, 0], result.traction[:, 0], bound,
                                            result.stick(), path, title, exact)
    else:
        plotting.plot_rolling_traction_map(
            result.x[:, 0], result.x[:, 1], result.traction[:, 0], result.traction[:, 1], bound,
            result.stick(), p["a"], p["b"], path, title.replace("; ", ";\n"))


def reference_curves(method: str, p: dict, eta: float, phi: float,
                     fine: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, str, str]]:
    """What a creep-force curve computed by ``method`` is compared with, as Fx/(μFn) on the
    creepages ``fine``: FASTSIM (beside the finite elements, 3D) and Kalker's linear theory
    clipped at μFn (no lateral creepage or spin), or Carter's closed form (2D).

    Returns:
        (ξ, Fx/(μFn), label, matplotlib style) of each reference.
    """
    scale = p["mu"] * p["Fn"]
    curves = []
    if method == "fastsim" or p["dim"] == 3:
        from fenicsfriction.studies.rolling.fastsim import creep_curve, linear_theory
        if method != "fastsim":
            others = creep_curve(p["a"], p["b"], p["G"], p["nu"], p["mu"], p["Fn"], xi=fine,
                                 eta=np.full(len(fine), eta), phi=np.full(len(fine), phi))
            curves.append((fine, np.array([r.Fx for r in others]) / scale, "FASTSIM", "-"))
        slope = linear_theory(p["a"], p["b"], p["G"], p["nu"], xi=1.0).Fx
        if eta == 0 and phi == 0:
            linear = np.clip(slope * fine / scale, -1.0, 1.0)
            curves.append((fine, linear, "Kalker's linear theory (C11), clipped at μFn", "k:"))
    else:
        from fenicsfriction.studies.rolling.closed_forms import carter_force
        p0, radius = carter_cylinders(p)
        curves.append((fine, np.array([carter_force(x, p["mu"], p["a"], p0, radius)
                                       for x in fine]) / scale, "Carter (1926)", "k-"))
    return curves


def creep_curve_figure(records: list[dict], p: dict, eta: float, phi: float,
                       path: PathLike) -> None:
    """Fx/(μFn) against ξ: the records' method (``rolling.json``'s records) beside
    :func:`reference_curves`. Call on rank 0."""
    xi = np.array([r["creepage"]["xi"] for r in records])
    scale = p["mu"] * p["Fn"]
    fine = np.linspace(min(xi.min(), 0.0), xi.max(), 200)
    method = records[0]["method"]
    curves = [(xi, np.array([r["Fx"] for r in records]) / scale,
               "FASTSIM" if method == "fastsim" else "finite elements (complete theory)",
               "o-" if method == "fastsim" else "s")]
    curves += reference_curves(method, p, eta, phi, fine)
    plotting.plot_creep_curves(
        curves, path, "longitudinal creepage ξ", "Fx / (μ Fn)",
        f"creep-force curve: a = {p['a']:.4g}"
        + (f", b = {p['b']:.4g}" if "b" in p else " (line contact)") + f", ν = {p['nu']:g}, "
        f"μ = {p['mu']:g}, η = {eta:g}, φ = {phi:g}")
