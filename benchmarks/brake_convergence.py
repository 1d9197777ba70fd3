r"""Mesh convergence of the simplified brake: frequencies at μ = 0 and the onset of mode coupling.

On each mesh size ``--h`` (default 6, 4 and 3 mm: 1.6e4 to 1e5 unknowns, 2, 3 and 4 elements
across the disc built of identical sectors; ``--free-disc``: its free gmsh mesh) the brake of
:mod:`fenicsfriction.studies.brake` is solved along μ: steady sliding, then every eigenvalue
of the band 0-``--fmax`` Hz by the full PEP (:class:`fenicsfriction.cea.BandSolver`); the
modes are tracked by MAC along the grid ``--mu`` (:class:`fenicsfriction.cea.Sweep`), the
first step where a mode starts to grow is bisected to ``--tol`` in μ (μ_crit), and the two
modes that coupled are named by their frequencies at the stable end and their kinetic energy
in the disc.

Recorded per mesh: the unknowns, the band's frequencies at μ = 0, μ_crit and the
coupled pair, the growth rate at the last μ, the wall time; and the frequencies of the disc
alone (clamped at its hub, no pad) on the same mesh, whose doublets are exact pairs on the
sector mesh (round-off) and are split by a free mesh's own asymmetry, to be compared with the
split of the brake's pair, which sets μ_crit. The table gives both splits
near the coupled pair (without an onset, near the brake's two closest frequencies).

Between the meshes: each frequency's observed order of convergence from three successive meshes,
the p of f = f₀ + c hᵖ through them (log(|f₁ − f₂| / |f₂ − f₃|) / log(h₁/h₂) for a constant
ratio; degree-1 tetrahedra: 2 for eigenvalues, in theory), and the change of μ_crit.

Writes ``brake_convergence.json`` and ``brake_convergence.png`` to ``--out`` and prints a
markdown table.
"""

from __future__ import annotations

import logging
import math
import time

from mpi4py import MPI

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction import cea
from fenicsfriction.results import get_logger, to_plain
from fenicsfriction.studies.brake import geometry, model

SIZES = [0.006, 0.004, 0.003]
MUS = [0.0, 0.1, 0.2, 0.3, 0.45, 0.6]


def split(frequencies: list[float], near: float) -> float:
    """The gap between the two frequencies of ``frequencies`` nearest ``near`` [Hz]."""
    a, b = sorted(sorted(frequencies, key=lambda f: abs(f - near))[:2])
    return b - a


def closest_pair(frequencies: list[float]) -> float:
    """The mean frequency of the two nearest neighbours (the doublet most nearly merged)."""
    f = np.sort(frequencies)
    i = int(np.argmin(np.diff(f)))
    return float(0.5 * (f[i] + f[i + 1]))


def run(h: float, args, comm: MPI.Comm, say) -> dict:
    t0 = time.perf_counter()
    brake = model.BrakeModel(geometry.brake(comm, h=h, symmetric_disc=not args.free_disc))
    band = cea.Band(0.0, args.fmax)
    solver = cea.BandSolver(comm, prefix="brake_conv_", dense_below=0)

    def solve_at(mu: float) -> list:
        brake.solve_steady(mu)
        return solver.solve(*brake.pencil(), band, nev=32)

    sweep = cea.Sweep(solve_at, comm, growth_tol=args.growth_tol)
    sweep.follow(args.mu)
    frequencies = [m.value.imag / (2 * math.pi) for m in sweep.modes[0]]
    events = sweep.coalescences()
    onset = None
    if events:
        first = min(events, key=lambda e: e.interval[0])
        step = [r["p"] for r in sweep.records].index(first.interval[0])
        pair = [next(m for m in sweep.modes[step] if m.ident == ident) for ident in first.modes]
        shares = [brake.kinetic_shares(m.vector)["disc"] for m in pair]
        onset = {**to_plain(sweep.refine(first, args.tol)), "disc_share": shares}
    alone = brake.disc_alone(args.fmax)
    last = sweep.modes[-1]
    growing = max(last, key=lambda m: m.value.real)
    record = {"h": h, "dofs": brake.dofs, "frequencies": frequencies, "onset": onset,
              "disc_alone": alone,
              "growth_at_last_mu": [growing.value.real, growing.value.imag / (2 * math.pi)],
              "records": sweep.records, "wall_time_s": time.perf_counter() - t0}
    say(f"h = {h * 1e3:.2f} mm: {brake.dofs} unknowns, μ_crit "
        f"{onset['p_crit'] if onset else float('nan'):.4f}, "
        f"{record['wall_time_s']:.0f} s")
    return record


def observed_order(f: np.ndarray, h: tuple[float, float, float]) -> float:
    """The order p of f = f₀ + c hᵖ through three meshes h₁ > h₂ > h₃: the root of
    (f₁ − f₂) / (f₂ − f₃) = (h₁ᵖ − h₂ᵖ) / (h₂ᵖ − h₃ᵖ) (log(|f₁ − f₂| / |f₂ − f₃|) / log r for a
    constant ratio r); NaN where the differences change sign or no p in (-20, 20) fits."""
    from scipy.optimize import brentq

    ratio = (f[0] - f[1]) / (f[1] - f[2])
    if not np.isfinite(ratio) or ratio <= 0:
        return float("nan")

    def gap(p: float) -> float:
        return (h[0]**p - h[1]**p) / (h[1]**p - h[2]**p) - ratio

    try:
        return float(brentq(gap, -19.9, 20.0))
    except ValueError:
        return float("nan")


def orders(runs: list[dict], count: int) -> list[list[float]]:
    """The observed order of each frequency from each three successive meshes."""
    result = []
    for a, b, c in zip(runs, runs[1:], runs[2:], strict=False):
        n = min(count, len(a["frequencies"]), len(b["frequencies"]), len(c["frequencies"]))
        f = np.array([r["frequencies"][:n] for r in (a, b, c)])
        result.append([observed_order(f[:, k], (a["h"], b["h"], c["h"])) for k in range(n)])
    return result


def plot(runs: list[dict], path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_f, ax_mu) = plt.subplots(1, 2, figsize=(11, 4.5))
    h = np.array([r["h"] for r in runs]) * 1e3
    n = min(len(r["frequencies"]) for r in runs)
    for k in range(min(n, 10)):
        ax_f.plot(h**2, [r["frequencies"][k] for r in runs], "o-", lw=0.8)
    ax_f.set_xlabel("h² [mm²]")
    ax_f.set_ylabel("frequency at μ = 0 [Hz]")
    ax_f.set_title("The lowest modes against h² (degree 1: f − f₀ ∝ h²)")
    ax_mu.plot(h, [r["onset"]["p_crit"] if r["onset"] else np.nan for r in runs], "o-")
    ax_mu.set_xlabel("h [mm]")
    ax_mu.set_ylabel("μ_crit")
    ax_mu.set_title("Onset of the first mode coupling")
    for ax in (ax_f, ax_mu):
        ax.grid(True, alpha=0.3)
    save(fig, path, dpi=120)


def main(argv=None) -> None:
    parser = benchmark_parser(__doc__)
    parser.add_argument("--h", type=float, nargs="+", default=SIZES,
                        help="mesh sizes [m], decreasing (default: %(default)s)")
    parser.add_argument("--mu", type=float, nargs="+", default=MUS,
                        help="the μ grid, from 0 (default: %(default)s)")
    parser.add_argument("--fmax", type=float, default=3000.0,
                        help="band's top [Hz] (default 3000: the n = 3 doublet and below)")
    parser.add_argument("--tol", type=float, default=0.0025, help="μ_crit's bracket width")
    parser.add_argument("--free-disc", action="store_true",
                        help="the disc's free gmsh mesh instead of identical sectors")
    parser.add_argument("--count", type=int, default=10,
                        help="the lowest frequencies whose orders are computed")
    parser.add_argument("--growth-tol", type=float, default=1e-6,
                        help="a mode grows when Re λ > growth_tol |λ| (default: %(default)s)")
    args = parser.parse_args(argv)
    logging.getLogger("ffcx").setLevel(logging.WARNING)
    logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)
    comm = MPI.COMM_WORLD
    say = get_logger(comm).info
    start = time.perf_counter()
    runs = [run(h, args, comm, say) for h in args.h]
    rates = orders(runs, args.count)
    if comm.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        plot(runs, args.out / "brake_convergence.png")
        print("\n| h [mm] | unknowns | f₁ … f₆ at μ = 0 [Hz] | μ_crit | coupled pair [Hz] "
              "(disc share) | pair's split at μ = 0 [Hz] | disc alone: split [Hz] | wall [s] |\n"
              "|---|---|---|---|---|---|---|---|")
        for r in runs:
            o = r["onset"]
            pair = "—" if o is None else ", ".join(
                f"{f:.0f} ({s:.2f})" for f, s in zip(o["frequencies"], o["disc_share"],
                                                     strict=True))
            crit = "—" if o is None else f"{o['p_crit']:.4f}"
            near = o["frequency"] if o else closest_pair(r["frequencies"])
            print(f"| {r['h'] * 1e3:.2f} | {r['dofs']:,} | "
                  + ", ".join(f"{f:.0f}" for f in r["frequencies"][:6])
                  + f" | {crit} | {pair} | {split(r['frequencies'], near):.1f} | "
                  f"{split(r['disc_alone'], near):.2g} | {r['wall_time_s']:.0f} |")
        for k, p in enumerate(rates):
            print(f"\norder from meshes {k + 1}-{k + 3}: "
                  + ", ".join(f"{x:.2f}" for x in p))
    write_summary(args.out / "brake_convergence.json",
                  {"fmax": args.fmax, "mu": args.mu, "tol": args.tol,
                   "growth_tol": args.growth_tol, "runs": runs,
                   "orders": rates, "total_s": time.perf_counter() - start}, comm)
    say(f"wrote {args.out / 'brake_convergence.json'} ({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
