"""Figures people would rather look at than read (matplotlib, drawn on rank 0): the helpers
every family's figures are built on (:func:`saved_figure`, ...), and the block's and the
oscillators' figures. dolfinx is imported only by the helpers that read a mesh
(:func:`cell_outlines`, :func:`body_cells`), so the mesh-free families' figures do without."""

from __future__ import annotations

import contextlib
import os
import typing

from mpi4py import MPI

import numpy as np

if typing.TYPE_CHECKING:
    from dolfinx import fem

PathLike = str | os.PathLike

__all__ = ["body_cells", "cell_outlines", "plot_contact_deformed", "plot_contact_pressure",
           "plot_contact_traction", "plot_creep_curves", "plot_deformed", "plot_growth",
           "plot_loci", "plot_oscillator", "plot_rolling_traction_line",
           "plot_rolling_traction_map", "plot_stability_map", "plot_steady_forces",
           "plot_stick_slip", "plot_stroboscopic_growth", "saved_figure"]


def _pyplot() -> typing.Any:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


@contextlib.contextmanager
def saved_figure(path: PathLike, ncols: int = 1, figsize: tuple[float, float] = (6.5, 4.5),
                 dpi: int = 120) -> typing.Iterator[typing.Any]:
    """``ncols`` axes side by side (a NumPy array of them); on leaving the block the figure is
    laid out, written to ``path`` and closed. Call on rank 0."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, ncols, figsize=figsize, squeeze=False)
    try:
        yield axes[0]
    finally:
        fig.tight_layout()
        fig.savefig(path, dpi=dpi)
        plt.close(fig)


def cell_outlines(u: fem.Function) -> tuple[np.ndarray, np.ndarray] | None:
    """Reference coordinates and displacements of every quadrilateral's corners, on rank 0.

    Returns ``(X, U)`` of shape (num_cells, 4, 2) on rank 0 and ``None`` elsewhere.
    """
    from dolfinx import fem

    from fenicsfriction import _compat

    msh = u.function_space.mesh
    V1 = _compat.vector_function_space(msh, 1)
    u1 = fem.Function(V1)
    u1.interpolate(u)
    num_cells = msh.topology.index_map(msh.topology.dim).size_local
    cell_dofs = np.array([V1.dofmap.cell_dofs(c) for c in range(num_cells)])
    dofs = cell_dofs.reshape(num_cells, -1)[:, [0, 1, 3, 2]]  # tensor-product order -> polygon
    X = V1.tabulate_dof_coordinates()[:, :2][dofs]
    U = u1.x.array.reshape(-1, 2)[dofs]
    gathered = msh.comm.gather((X, U), root=0)
    if msh.comm.rank != 0:
        return None
    return (np.concatenate([g[0] for g in gathered]), np.concatenate([g[1] for g in gathered]))


def plot_deformed(snapshots: list[tuple[float, np.ndarray, np.ndarray]], path: PathLike,
                  length: float, height: float, comm: MPI.Comm = MPI.COMM_WORLD) -> None:
    """Deformed configurations at several μ (Martins & Oden 1986, Fig. 7), magnified.

    The mean displacement (the spring's rigid stretch, tens of cm) is removed and the rest,
    rotation and deformation of order 1e-4 cm, is magnified in each panel by its own factor
    (given in the panel's title), so that the largest deviation in every panel is 8 % of the
    height: the deformation grows with μ by orders of magnitude, and one shared factor would
    leave the low-μ panels looking undeformed.
    """
    if comm.rank != 0 or not snapshots:
        return
    plt = _pyplot()
    fig, axes = plt.subplots(1, len(snapshots), figsize=(3.2 * len(snapshots), 3.4),
                             squeeze=False)
    for ax, (mu, X, U) in zip(axes[0], snapshots, strict=True):
        W = U - U.reshape(-1, 2).mean(axis=0)
        amplitude = np.abs(W).max()
        scale = 0.08 * height / amplitude if amplitude > 0 else 1.0
        for x, w in zip(X, W, strict=True):
            ax.fill(*x.T, fc="none", ec="0.8", lw=0.6)
            ax.fill(*(x + scale * w).T, fc="tab:blue", alpha=0.15, ec="tab:blue", lw=0.8)
        ax.axhline(0.0, color="k", lw=1.5)
        ax.set_title(f"μ = {mu:.3g}  (×{scale:.3g})")
        ax.set_aspect("equal")
        ax.set_xlim(-0.1 * length, 1.1 * length)
        ax.set_ylim(-0.25 * height, 1.15 * height)
        ax.set_xlabel("x [cm]")
    axes[0][0].set_ylabel("y [cm]")
    fig.suptitle("Steady sliding: deformed block (rigid stretch removed, each panel magnified)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_steady_forces(records: list[dict], path: PathLike, spring_height: float,
                       belt_direction: int, tipping_limit: float,
                       comm: MPI.Comm = MPI.COMM_WORLD) -> None:
    """Resultant forces, centre of pressure and penetration against μ."""
    if comm.rank != 0 or not records:
        return
    plt = _pyplot()
    mu = np.array([r["mu"] for r in records])
    get = lambda key: np.array([r[key] for r in records])  # noqa: E731
    fig, axes = plt.subplots(1, 3, figsize=(14, 4))
    ax = axes[0]
    ax.plot(mu, get("normal_force"), "o-", ms=3, label="normal force N")
    ax.plot(mu, np.abs(get("friction_force")), "s-", ms=3, label="|friction force|")
    ax.plot(mu, np.abs(get("spring_force")), "x", label="|spring force|")
    ax.plot(mu, mu * get("normal_force"), "k:", label="μ N")
    ax.set_xlabel("μ")
    ax.set_ylabel("force [10³ kg cm s⁻²]")
    ax.legend()
    ax = axes[1]
    ax.plot(mu, get("centre_of_pressure"), "o-", ms=3, label="computed")
    ax.plot(mu, -belt_direction * mu * spring_height, "k:", label="statics: −μ h_s")
    ax.axvline(tipping_limit, color="r", lw=0.8, ls="--", label=f"tipping μ = {tipping_limit:.3g}")
    ax.set_xlabel("μ")
    ax.set_ylabel("centre of pressure − L/2 [cm]")
    ax.legend()
    ax = axes[2]
    ax.plot(mu, get("max_penetration"), "o-", ms=3, label="max")
    ax.plot(mu, get("min_penetration"), "s-", ms=3, label="min")
    ax.set_xlabel("μ")
    ax.set_ylabel("penetration [cm]")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _fe_points(records: list[dict]) -> tuple[np.ndarray, np.ndarray]:
    """(μ, λ) of every FE eigenvalue in the loci records."""
    mu = np.array([r["mu"] for r in records for _ in r["modes"]])
    lam = np.array([complex(m["re"], m["im"]) for r in records for m in r["modes"]])
    return mu, lam


def _rigid_points(steps: list[dict]) -> tuple[np.ndarray, np.ndarray]:
    mu = np.array([s["mu"] for s in steps for _ in s["eigenvalues"]])
    lam = np.array([complex(*v) for s in steps for v in s["eigenvalues"]])
    return mu, lam


def plot_loci(records: list[dict], rigid_steps: list[dict], path: PathLike,
              comm: MPI.Comm = MPI.COMM_WORLD) -> None:
    """Eigenvalues in the complex plane coloured by μ, FE and rigid (Martins & Oden 1986,
    Fig. 9)."""
    if comm.rank != 0:
        return
    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(12, 5), sharex=True, sharey=True)
    for ax, (mu, lam), title in ((axes[0], _fe_points(records), "finite elements"),
                                 (axes[1], _rigid_points(rigid_steps), "rigid block (3 dof)")):
        both = np.concatenate([lam, lam.conj()])
        sc = ax.scatter(both.real, both.imag, c=np.concatenate([mu, mu]), s=10, cmap="viridis")
        ax.axvline(0.0, color="k", lw=0.6)
        ax.set_title(title)
        ax.set_xlabel("Re λ [1/s]")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("Im λ [rad/s]")
    fig.colorbar(sc, ax=axes, label="μ")
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_growth(records: list[dict], rigid_steps: list[dict], path: PathLike,
                comm: MPI.Comm = MPI.COMM_WORLD) -> None:
    """Largest Re λ against μ, FE and rigid (Martins & Oden 1986, Fig. 8)."""
    if comm.rank != 0:
        return
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot([r["mu"] for r in records], [r["max_re"] for r in records], "o-", ms=3,
            label="finite elements")
    ax.plot([s["mu"] for s in rigid_steps], [s["max_re"] for s in rigid_steps], "s--", ms=3,
            label="rigid block")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("μ")
    ax.set_ylabel("max Re λ [1/s]")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _last_cycle(t: np.ndarray, signal: np.ndarray) -> slice:
    """Indices of the last full cycle of an oscillating signal (between its last two upward
    crossings of the mean); the last tenth of the record if there are fewer than two."""
    centred = signal - signal.mean()
    up = np.flatnonzero((centred[:-1] < 0) & (centred[1:] >= 0))
    if len(up) >= 2:
        return slice(up[-2], up[-1] + 1)
    return slice(int(0.9 * len(t)), len(t))


def plot_stick_slip(runs: dict, path: PathLike, mu: float, eps: float) -> None:
    """Martins & Oden (1986), Figs. 10-15, for one or more runs (``{label: records}``,
    records from ``BlockModel.dynamics_observer``): phase plane of the normal motion of the
    centre of mass, tangential velocity of the probe node against the belt speed (last ~5 ms),
    spring elongation against time, and the probe's normal and friction stress over the last
    cycle of the normal oscillation (sticking marked)."""
    plt = _pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(12, 8.5))
    (phase, velocity), (spring, traction) = axes
    for (label, records), colour in zip(runs.items(), plt.rcParams["axes.prop_cycle"]
                                        .by_key()["color"], strict=False):
        get = lambda key, rs=records: np.array([r[key] for r in rs])  # noqa: E731
        t = get("time")
        phase.plot(1e4 * get("u_yG"), get("v_yG"), lw=0.4, color=colour, label=label)
        late = t >= t[-1] - 5e-3
        velocity.plot(1e3 * t[late], get("probe_v_x")[late], lw=0.8, color=colour, label=label)
        belt = get("probe_v_x")[0] - get("probe_slip")[0]
        velocity.axhline(belt, color=colour, ls="--", lw=0.8)
        spring.plot(t, get("spring_elongation"), color=colour, label=label)
        cycle = _last_cycle(t, get("normal_force"))
        tc = 1e3 * (t[cycle] - t[cycle][0])
        traction.plot(tc, get("probe_pressure")[cycle], color=colour, label=f"{label}: normal")
        friction = get("probe_friction")[cycle]
        traction.plot(tc, friction, color=colour, ls="--", label=f"{label}: friction")
        stick = (get("probe_pressure")[cycle] > 0) & (np.abs(get("probe_slip")[cycle]) < eps)
        traction.plot(tc[stick], friction[stick], "o", ms=3, color=colour)
        traction.plot(tc, mu * get("probe_pressure")[cycle], ":", color=colour, lw=0.8)
    phase.set_xlabel("vertical displacement of the centre of mass u_yG [1e-4 cm]")
    phase.set_ylabel("vertical velocity v_yG [cm/s]")
    phase.set_title("Normal motion, phase plane (Fig. 10)")
    velocity.set_xlabel("time [ms]")
    velocity.set_ylabel("tangential velocity of the probe node [cm/s]")
    velocity.set_title("Contact point velocity; dashed: belt speed (Fig. 11)")
    spring.set_xlabel("time [s]")
    spring.set_ylabel("spring elongation [cm]")
    spring.set_title("Spring elongation (Figs. 12-13)")
    traction.set_xlabel("time in the last cycle [ms]")
    traction.set_ylabel("stress at the probe node")
    traction.set_title("Normal (solid), friction (dashed), μ × normal (dotted); "
                       "dots: stick (Figs. 14-15)", fontsize=9)
    for ax in axes.flat:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_oscillator(t: np.ndarray, displacement: np.ndarray, velocity: np.ndarray,
                    surface_speed: float, stick: list[tuple[float, float]], path: PathLike,
                    title: str, names: tuple[str, str] = ("x", "ẋ")) -> None:
    """Response of a friction oscillator: the whole run with its envelope, a close-up of the
    last cycles, and the velocity of the contact against the surface speed, stick shaded."""
    plt = _pyplot()
    fig, axes = plt.subplots(3, 1, figsize=(8, 8))
    axes[0].plot(t, displacement, lw=0.4)
    axes[0].set(xlabel="t", ylabel=names[0], title=title)
    close = t >= t[-1] - 0.1 * (t[-1] - t[0])
    axes[1].plot(t[close], displacement[close], lw=0.8)
    axes[1].set(xlabel="t", ylabel=f"{names[0]} (last 10 %)")
    axes[2].plot(t[close], velocity[close], lw=0.8, label=names[1])
    axes[2].axhline(surface_speed, color="k", ls="--", lw=0.8, label="surface speed")
    for a, b in stick:
        if b >= t[close][0]:
            axes[2].axvspan(max(a, t[close][0]), b, color="tab:red", alpha=0.2, lw=0)
    axes[2].set(xlabel="t", ylabel=f"{names[1]} (stick shaded)")
    axes[2].legend(loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_stability_map(omega: np.ndarray, growth: dict, bands: dict, path: PathLike,
                       reference_bands: typing.Sequence[tuple[float, float]] = ()) -> None:
    """Growth rate of perturbations of steady sliding against the forcing frequency, by each
    method, with the unstable bands shaded and reference bands (e.g. a paper's) marked."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4))
    for (method, g), colour in zip(growth.items(), ("tab:blue", "tab:orange"), strict=False):
        ax.plot(omega, g, color=colour, label=method)
        for a, b in bands.get(method, []):
            ax.axvspan(a, b, color=colour, alpha=0.15, lw=0)
    for i, (a, b) in enumerate(reference_bands):
        if a <= omega[-1] and b >= omega[0]:
            ax.axvspan(a, b, ymin=0.95, ymax=1.0, color="k",
                       label="paper" if i == 0 else None)
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set(xlabel="forcing frequency ω_o", ylabel="growth rate (max Re)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_stroboscopic_growth(runs: dict, path: PathLike) -> None:
    """Distance of time responses from their periodic solution, |y(kT) − y((k−1)T)| at the
    forcing periods (log scale), each with the line of its predicted rate.

    Args:
        runs: label -> (t_k, d_k, predicted rate).
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4))
    for (label, (t, d, rate)), colour in zip(runs.items(), plt.rcParams["axes.prop_cycle"],
                                             strict=False):
        ax.semilogy(t, d, color=colour["color"], lw=0.9, label=label)
        ax.semilogy(t, d[-1] * np.exp(rate * (t - t[-1])), color=colour["color"], lw=0.8,
                    ls="--")
    ax.set(xlabel="t", ylabel="|y(kT) − y((k−1)T)|",
           title="linearised motion (solid) against the Floquet rate (dashed)")
    ax.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# --- two elastic bodies in contact -----------------------------------------------------------

def body_cells(u: fem.Function, cell_tags: typing.Any,
               window: tuple[float, float, float, float] | None = None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Corners, corner displacements and body tag of the 2D cells (triangles) in ``window``
    (x_min, x_max, y_min, y_max; a cell with a corner inside is kept), gathered on rank 0.

    ``u`` is a vector Function (of any degree: its values at the corners are drawn). Returns
    ``(X, U, body)`` of shapes (n, 3, 2), (n, 3, 2) and (n,) on rank 0, ``None`` elsewhere.
    """
    from dolfinx import fem

    from fenicsfriction import _compat

    msh = u.function_space.mesh
    V = _compat.vector_function_space(msh, 1)
    corners = fem.Function(V)
    corners.interpolate(u)
    num_cells = msh.topology.index_map(msh.topology.dim).size_local
    dofs = np.array([V.dofmap.cell_dofs(c) for c in range(num_cells)]).reshape(num_cells, -1)
    X = V.tabulate_dof_coordinates()[:, :2][dofs]
    U = corners.x.array.reshape(-1, 2)[dofs]
    body = np.zeros(num_cells, dtype=np.int32)
    tagged = cell_tags.indices < num_cells
    body[cell_tags.indices[tagged]] = cell_tags.values[tagged]
    if window is not None:
        x0, x1, y0, y1 = window
        inside = ((X[..., 0] >= x0) & (X[..., 0] <= x1) & (X[..., 1] >= y0)
                  & (X[..., 1] <= y1)).any(axis=1)
        X, U, body = X[inside], U[inside], body[inside]
    gathered = msh.comm.gather((X, U, body), root=0)
    if msh.comm.rank != 0:
        return None
    X, U, body = (np.concatenate([g[k] for g in gathered]) for k in range(3))
    return X, U, body


def plot_contact_deformed(cells: tuple[np.ndarray, np.ndarray, np.ndarray], path: PathLike,
                          window: tuple[float, float, float, float], scale: float,
                          title: str, marks: typing.Sequence[float] = ()) -> None:
    """The undeformed (grey) and deformed (coloured by body) cells of :func:`body_cells`,
    displacements multiplied by ``scale``, within ``window``; vertical lines at ``marks``
    (e.g. Hertz's ±a). Call on rank 0."""
    from matplotlib.collections import PolyCollection

    plt = _pyplot()
    X, U, body = cells
    fig, ax = plt.subplots(figsize=(8, 4.8))
    ax.add_collection(PolyCollection(list(X), facecolors="0.6", alpha=0.3, edgecolors="none",
                                     label="undeformed"))
    for tag, colour, name in ((1, "tab:blue", "body 1"), (2, "tab:orange", "body 2")):
        mine = body == tag
        if mine.any():
            ax.add_collection(PolyCollection(list(X[mine] + scale * U[mine]), facecolors=colour,
                                             alpha=0.35, edgecolors=colour, lw=0.15,
                                             label=name))
    for x in marks:
        ax.axvline(x, color="k", ls=":", lw=0.8)
    ax.set_xlim(window[0], window[1])
    ax.set_ylim(window[2], window[3])
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.legend(loc="best", fontsize=8)
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_contact_pressure(curves: typing.Sequence[tuple[np.ndarray, np.ndarray, str]],
                          path: PathLike, xlabel: str, title: str,
                          reference: tuple[np.ndarray, np.ndarray, str] | None = None,
                          marks: typing.Sequence[float] = ()) -> None:
    """Contact pressures (abscissa, pressure, label) against a closed form ``reference``
    (drawn as a line), dotted verticals at ``marks``. Call on rank 0."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    if reference is not None:
        ax.plot(*reference[:2], "k-", lw=1.2, label=reference[2])
    for (x, p, label), marker in zip(curves, "os^vd", strict=False):
        ax.plot(x, p, marker, ms=3.5, mfc="none", label=label)
    for mark in marks:
        ax.axvline(mark, color="k", ls=":", lw=0.8)
    ax.set_xlabel(xlabel)
    ax.set_ylabel("contact pressure")
    ax.set_title(title)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def plot_contact_traction(x: np.ndarray, tractions: typing.Sequence[tuple[np.ndarray, str]],
                          mu_p: np.ndarray, grid: np.ndarray, exact: np.ndarray,
                          mu_p_exact: np.ndarray, a: float, c: float, path: PathLike,
                          title: str, window: float | None = None) -> None:
    """Cattaneo-Mindlin: the tangential tractions (one per ε, label) and μ p at the nodes
    ``x`` against the closed forms on ``grid``, ``exact`` and μ p_Hertz; the stick zone
    |x| < c and the slip zones c < |x| < a of the closed form shaded. Call on rank 0."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(10, 4.5))
    ax.axvspan(-c, c, color="tab:green", alpha=0.12, label=f"stick |x| < c = {c:.4g}")
    for lo, hi in ((-a, -c), (c, a)):
        ax.axvspan(lo, hi, color="tab:red", alpha=0.10,
                   label="slip c < |x| < a" if lo < 0 else None)
    ax.plot(grid, mu_p_exact, "k--", lw=1.0, label="μ p (Hertz)")
    ax.plot(grid, exact, "k-", lw=1.2, label="q (Cattaneo-Mindlin)")
    ax.plot(x, mu_p, "x", ms=4, color="tab:gray", label="μ p (computed)")
    for (q, label), marker in zip(tractions, "os^vd", strict=False):
        ax.plot(x, q, marker, ms=3.5, mfc="none", label=label)
    half = window if window is not None else 1.5 * a
    ax.set_xlim(-half, half)
    ax.set_xlabel("x")
    ax.set_ylabel("tangential traction")
    ax.set_title(title)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def plot_creep_curves(curves: typing.Sequence[tuple[np.ndarray, np.ndarray, str, str]],
                      path: PathLike, xlabel: str, ylabel: str, title: str) -> None:
    """Creep-force curves side by side: (creepage, force, label, matplotlib style) each, e.g.
    FASTSIM, the finite element complete theory, Kalker's linear theory and the saturation
    ±μ Fn. Call on rank 0."""
    with saved_figure(path, figsize=(7.5, 4.8), dpi=130) as (ax,):
        for x, f, label, style in curves:
            ax.plot(x, f, style, ms=4, mfc="none", label=label)
        ax.axhline(0.0, color="k", lw=0.5)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.set_title(title, fontsize=10)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)


def plot_rolling_traction_line(x: np.ndarray, traction: np.ndarray, bound: np.ndarray,
                               adhesion: np.ndarray, path: PathLike, title: str,
                               exact: tuple[np.ndarray, np.ndarray, str] | None = None) -> None:
    """A line contact in steady rolling (2D): the tangential traction and the traction bound
    μ p_n at the surface points ``x``, the adhesion points marked, a closed form ``exact``
    (abscissae, traction, label) as a line. Call on rank 0."""
    with saved_figure(path, figsize=(9, 4.5), dpi=130) as (ax,):
        order = np.argsort(x)
        ax.plot(x[order], bound[order], "k--", lw=1.0, label="bound μ p_n")
        ax.plot(x[order], -bound[order], "k--", lw=1.0)
        if exact is not None:
            ax.plot(exact[0], exact[1], "k-", lw=1.2, label=exact[2])
        ax.plot(x[order], traction[order], "o", ms=3, mfc="none", color="tab:blue",
                label="traction (slip)")
        stuck = adhesion.astype(bool)
        ax.plot(x[stuck], traction[stuck], "o", ms=3.5, color="tab:green", label="adhesion")
        ax.set_xlabel("x (rolling direction →, leading edge on the right)")
        ax.set_ylabel("tangential traction on body 1")
        ax.set_title(title, fontsize=10)
        ax.legend(fontsize=8)


def plot_rolling_traction_map(x: np.ndarray, y: np.ndarray, px: np.ndarray, py: np.ndarray,
                              bound: np.ndarray, adhesion: np.ndarray, a: float, b: float,
                              path: PathLike, title: str) -> None:
    """An elliptic contact in steady rolling (3D): the traction's share of its bound
    |p_τ|/(μ p_n) in colour at the points (x, y), the traction as arrows, the adhesion
    points ringed and the contact ellipse (a along x, b along y) drawn; points where the bound
    is zero (outside the contact) are left out. Call on rank 0."""
    height = float(np.clip(5.0 * b / a, 3.5, 7.5))
    with saved_figure(path, figsize=(7.0, height), dpi=130) as (ax,):
        inside = bound > 0  # the contact area: where the pressure is positive
        x, y, px, py, bound, adhesion = (v[inside] for v in (x, y, px, py, bound, adhesion))
        share = np.divide(np.hypot(px, py), bound, out=np.zeros_like(bound), where=bound > 0)
        dots = ax.scatter(x, y, c=share, s=12, cmap="viridis", vmin=0.0, vmax=1.0)
        stuck = adhesion.astype(bool)
        ax.scatter(x[stuck], y[stuck], s=30, facecolors="none", edgecolors="tab:red", lw=0.6,
                   label="adhesion")
        scale = np.abs(np.hypot(px, py)).max()
        if scale > 0:
            step = max(1, len(x) // 400)
            ax.quiver(x[::step], y[::step], px[::step], py[::step], color="w", alpha=0.8,
                      scale=scale * 25, width=0.003)
        t = np.linspace(0.0, 2 * np.pi, 200)
        ax.plot(a * np.cos(t), b * np.sin(t), "k-", lw=0.8)
        ax.set_aspect("equal")
        ax.set_xlabel("x (rolling direction →)")
        ax.set_ylabel("y")
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=8, loc="upper left")
        ax.figure.colorbar(dots, ax=ax, label="|p_τ| / (μ p_n)", shrink=0.8)
