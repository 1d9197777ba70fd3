"""The multicontact family's figures (Braun's interface of many contacts): the EQ model beside
its master equation, the stability maps, the elastic interaction of contacts, Frenkel-Kontorova
fronts and the elastic slider's detachment fronts, built on :func:`fenicsfriction.plotting.
saved_figure`. Without a mesh: no dolfinx is imported. Call each on rank 0."""

from __future__ import annotations

import typing

import numpy as np

from fenicsfriction import plotting

if typing.TYPE_CHECKING:
    from fenicsfriction.plotting import PathLike

__all__ = ["coupling_map_figure", "eq_figure", "fk_figure", "interaction_figure",
           "master_equation_figure", "slider_figure", "stability_map_figure"]


def eq_figure(run: typing.Any, me: typing.Any, realisations: int, interacting: bool,
              X_max: float, path: PathLike) -> None:
    """F(X) of the EQ model (``run``, quasistatic) beside its master equation's (``me``), and
    the distribution of stretchings at X_max against the master equation's Q."""
    with plotting.saved_figure(path, ncols=2, figsize=(11, 4)) as (a1, a2):
        a1.plot(run.X, run.F, "-", lw=1, label=f"EQ model ({realisations} realisation(s))")
        a1.plot(me.X, me.F, "k-", lw=1.2, label="master equation"
                + ("" if not interacting else " (no interaction)"))
        a1.set(xlabel="X", ylabel="F", title="friction force against the slider's position")
        a1.legend(fontsize=8)
        centres = 0.5 * (run.histogram_edges[1:] + run.histogram_edges[:-1])
        a2.bar(centres, run.histogram, width=np.diff(run.histogram_edges), alpha=0.5,
               label="EQ model")
        a2.plot(me.x, me.Q / me.h, "k-", label="master equation")
        a2.set(xlabel="stretching x", ylabel="density Q(x; X)",
               title=f"stretchings at X = {X_max:g}")
        a2.legend(fontsize=8)


def master_equation_figure(me: typing.Any, path: PathLike) -> None:
    """F(X) of the master equation with its kinetic force, and Q at the last X."""
    with plotting.saved_figure(path, ncols=2, figsize=(11, 4)) as (a1, a2):
        a1.plot(me.X, me.F, "k-")
        a1.axhline(me.kinetic_force, color="gray", ls=":", label="kinetic")
        a1.set(xlabel="X", ylabel="F", title=f"F(X): static {me.static_force:.4g}, K* = "
                                             f"{me.K_star:.4g}")
        a1.legend(fontsize=8)
        a2.plot(me.x, me.Q / me.h, "k-")
        a2.set(xlabel="stretching x", ylabel="Q(x; X)", title=f"Q at X = {me.X[-1]:.4g}")


def _classified(ax: typing.Any, x: np.ndarray, spreads: np.ndarray,
                stick_slip: np.ndarray) -> None:
    """The runs of a map as crosses (stick-slip) and circles (smooth sliding)."""
    xx, ss = np.meshgrid(x, spreads)
    stuck = stick_slip.astype(bool)
    ax.scatter(xx[stuck], ss[stuck], marker="x", color="tab:red", label="stick-slip")
    ax.scatter(xx[~stuck], ss[~stuck], marker="o", facecolors="none", edgecolors="tab:blue",
               label="smooth sliding")


def stability_map_figure(smap: typing.Any, path: PathLike) -> None:
    """The spring-driven runs (an :class:`~.instability.InstabilityMap`) over K and σ/x_c,
    with the master equation's K*."""
    with plotting.saved_figure(path, figsize=(6.5, 4.5)) as (ax,):
        _classified(ax, smap.K, smap.relative_spread, smap.onset_stick_slip)
        ax.plot(smap.K_star, smap.relative_spread, "k-", label="K* = −max F′(X)")
        ax.set(xscale="log", xlabel="drive stiffness K", ylabel="threshold spread σ/x_c",
               title="elastic instability of the EQ interface")
        ax.legend(fontsize=8)


def coupling_map_figure(cmap: typing.Any, path: PathLike) -> None:
    """Interacting contacts (a :class:`~.instability.CouplingMap`) over couplings and spreads,
    and the largest force drop of one avalanche against the coupling."""
    with plotting.saved_figure(path, ncols=2, figsize=(11, 4.5)) as (a1, a2):
        shown = np.where(cmap.coupling > 0, cmap.coupling,
                         np.min(cmap.coupling[cmap.coupling > 0], initial=1.0) / 3)
        _classified(a1, shown, cmap.relative_spread, cmap.sustained_stick_slip)
        a1.set(xscale="log", xlabel="coupling k/(E a) (no interaction at the left edge)",
               ylabel="threshold spread σ/x_c", title="stick-slip of interacting contacts")
        a1.legend(fontsize=8)
        for i, s in enumerate(cmap.relative_spread):
            a2.plot(shown, cmap.largest_late_drop[i], "o-", label=f"σ/x_c = {s:g}")
        a2.axhline(cmap.drop_threshold, color="gray", ls=":", label="threshold")
        a2.set(xscale="log", yscale="log", xlabel="coupling k/(E a)",
               ylabel="largest drop of F in one avalanche / F_k",
               title="avalanches grow with the interaction")
        a2.legend(fontsize=8)


def interaction_figure(r: np.ndarray, f: np.ndarray, fit: typing.Any, near: float,
                       lambda_c: float, path: PathLike) -> None:
    """The response of the other contacts against distance when one breaks, with the power
    laws ``fit`` below ``near`` and beyond 3 λ_c."""
    with plotting.saved_figure(path, figsize=(6, 4.2)) as (ax,):
        ax.loglog(r, f, "o", ms=3, label="|δf(r)| / |δf(0)|")
        for slope, pre, where, style in (
                (fit.near_exponent, fit.near_prefactor, r < near, "k--"),
                (fit.far_exponent, fit.far_prefactor, r > 3 * lambda_c, "k:")):
            if np.any(where):
                ax.loglog(r[where], pre * r[where] ** slope, style, label=f"slope {slope:.2f}")
        ax.axvline(lambda_c, color="gray", lw=0.8, label="λ_c")
        ax.set(xlabel="r / a", ylabel="response of the other contacts",
               title="a contact breaks: the response against distance")
        ax.legend(fontsize=8)


def fk_figure(chain: typing.Any, run: typing.Any, force: float, speeds: dict | None,
              path: PathLike) -> None:
    """The front in the x-t plane and, with ``speeds`` (:meth:`~.FrontSpeeds.to_json`), the
    measured front speed against the force beside the continuum travelling wave and its
    limits."""
    panels = 2 if speeds else 1
    with plotting.saved_figure(path, ncols=panels, figsize=(5.5 * panels, 4)) as axes:
        ax = axes[0]
        broken = np.isfinite(run.break_time)
        sites = np.flatnonzero(broken)
        ax.plot(run.break_time[sites], sites * chain.a, ".", ms=3)
        ax.set(xlabel="t", ylabel="x of the contact (first break)",
               title=f"front in the x–t plane, f = {force:g}")
        if speeds:
            ax = axes[1]
            fine = np.linspace(chain.f_min, chain.f_max, 201)[1:-1]
            ax.plot(speeds["force"], speeds["measured"], "o", label="chain")
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


def slider_figure(history: typing.Any, length: float, path: PathLike) -> None:
    """The elastic slider's detachment fronts (breaks in red) and the push force against
    time."""
    with plotting.saved_figure(path, ncols=2, figsize=(11, 4)) as (a1, a2):
        a1.plot(np.array(history.time) * 1e3, np.array(history.front_position) / length, "-")
        for b in history.breaks:
            a1.plot(b.time * 1e3, b.x / length, ".", color="tab:red", ms=2)
        a1.set(xlabel="t [ms]", ylabel="x / L", title="detachment fronts (breaks in red)")
        a2.plot(np.array(history.time) * 1e3, history.push_force, "-")
        a2.set(xlabel="t [ms]", ylabel="push force [N/m]",
               title="the force on the trailing edge")
