"""Spin in the rolling finite element model (Kalker's complete theory): mesh study and spin curve.

* Small spin (linear theory): on the circle (ν = 0, p0 = 0.01 G, μ = 0.3) at φ a = 1e-6 (far
  below the saturation creepage μ p0/G = 3e-3), the spin coefficients
  :math:`C_{23} = -F_y/(G c^3 \\phi)` and :math:`C_{33} = -M_z/(G c^4 \\phi)` (c = √(ab); the
  linear theory's convention, Kalker 1967; Kalker 1990, Table E.3) for each mesh of
  ``--cells`` (cells over a, a geometric sequence), with Richardson's extrapolation and
  observed order from the last three (Richardson 1911; Roache 1998, section 5.4).
* Large spin: the FE curve F_y(φ), M_z(φ) on ``--curve-cells`` from φ a/(μ p0/G) = 0.05 to
  full slip, each point from the last, against FASTSIM (Kalker 1982) with both traction bounds.

Writes ``bench_rolling_spin.json`` and ``bench_rolling_spin.png`` to ``--out`` and prints
markdown tables (rank 0). Serial, with the defaults 5 minutes on a free core (the a/8 mesh,
105,903 unknowns, 1.5 GB), 15 on two cores shared by many runs.
"""

from __future__ import annotations

import math

from mpi4py import MPI

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction.studies.rolling import fastsim, kalker
from fenicsfriction.studies.rolling.model import RollingContact

MU = 0.3
P0 = 0.01  # Hertz's peak pressure over G
SMALL = 1e-6  # φ a of the linear theory
def scene(cells: int, block: float = 10.0) -> RollingContact:
    """The circle of the study on a mesh of ``cells`` over a on a block of ``block`` a. The
    cells outside the contact zone grow by 1 + 2/cells (1.5 at h = a/4): the local cell size
    h + (growth - 1) d at a distance d from the zone then scales with h everywhere, so that the
    meshes are one family (with a fixed growth the far mesh stays as coarse and the
    coefficients are not monotone in h: C23 = 1.379 at a/6, 1.342 at a/8, 1.368 at a/9)."""
    return RollingContact(dim=3, nu=0.0, p0=P0, cells_per_a=cells, block_size=block,
                          growth=1 + 2 / cells).with_law(mu=MU)


def small_spin_row(cells: int, block: float) -> dict:
    """The spin coefficients of the mesh of ``cells`` over a."""
    s = scene(cells, block)
    model = s.build()
    phi = SMALL / s.a
    result = model.solve((0.0, 0.0, phi))
    c = s.a  # the circle: c = √(ab) = a
    return {"cells_per_a": cells, "block_size": block, "dofs": model.dofs,
            "C23": -result.Fy / (s.G * c**3 * phi), "C33": -result.Mz / (s.G * c**4 * phi),
            "Fx_over_Fy": result.Fx / result.Fy, "newton_iterations": result.newton_iterations,
            "wall_time_s": result.wall_time_s}


def richardson(h: list[float], f: list[float]) -> dict:
    """Richardson's extrapolation of the last three values ``f`` on meshes ``h`` of a constant
    ratio: the observed order p and the limit f3 + (f3 - f2)/(r^p - 1)."""
    (h1, h2, h3), (f1, f2, f3) = h[-3:], f[-3:]
    r = h1 / h2
    check = abs(h2 / h3 - r) < 1e-9 * r
    if not check or (f2 - f1) * (f3 - f2) <= 0:
        return {"order": None, "limit": None, "monotone": False}
    p = math.log((f2 - f1) / (f3 - f2)) / math.log(r)
    return {"order": p, "limit": f3 + (f3 - f2) / (r**p - 1), "monotone": True}


def spin_curve(cells: int, block: float, ratios: list[float]) -> list[dict]:
    """F_y and M_z over φ a = ratio μ p0/G, FE and FASTSIM."""
    s = scene(cells, block)
    model = s.build()
    saturation = MU * P0  # μ p0 / G
    Fn = s.normal_load
    phis = [q * saturation / s.a for q in ratios]
    fast = {bound: fastsim.creep_curve(s.a, s.a, s.G, s.nu, MU, Fn, phi=np.asarray(phis),
                                       nx=80, ny=80, pressure=bound)
            for bound in fastsim.PRESSURES}
    rows = []
    for k, (q, phi) in enumerate(zip(ratios, phis, strict=True)):
        r = model.solve((0.0, 0.0, phi))
        row = {"phi_a_over_saturation": q, "phi": phi, "Fy": r.Fy / (MU * Fn),
               "Mz": r.Mz / (MU * Fn * s.a), "adhesion": r.adhesion_fraction,
               "newton_iterations": r.newton_iterations, "wall_time_s": r.wall_time_s}
        for bound, results in fast.items():
            row[f"fastsim_{bound}"] = {"Fy": results[k].Fy / (MU * Fn),
                                       "Mz": results[k].Mz / (MU * Fn * s.a),
                                       "adhesion": results[k].adhesion_fraction}
        rows.append(row)
    return rows


def main() -> None:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--cells", default="2,4,8", help="meshes of the small-spin study")
    flags.add_argument("--block", type=float, default=10.0, help="block size over a")
    flags.add_argument("--curve-cells", type=int, default=6, help="mesh of the spin curve")
    flags.add_argument("--curve", default="0.05,0.1,0.2,0.5,1,2,5,10,20",
                       help="φ a over μ p0/G of the spin curve ('' for none)")
    args = flags.parse_args()
    comm = MPI.COMM_WORLD
    cells = [int(n) for n in args.cells.split(",") if n]
    study = [small_spin_row(n, args.block) for n in cells]
    s = scene(cells[0] if cells else 1)
    coefficients = kalker.creep_coefficients(s.a, s.a, s.nu)
    linear = {"C23": coefficients.C23, "C33": coefficients.C33}
    extrapolated = {}
    if len(study) >= 3:
        h = [1 / r["cells_per_a"] for r in study]
        extrapolated = {k: richardson(h, [r[k] for r in study]) for k in ("C23", "C33")}
    ratios = [float(q) for q in args.curve.split(",") if q]
    curve = spin_curve(args.curve_cells, args.block, ratios) if ratios else []
    write_summary(args.out / "bench_rolling_spin.json",
                  {"small_spin": study, "linear_theory": linear, "richardson": extrapolated,
                   "curve_cells_per_a": args.curve_cells, "curve": curve}, comm)
    if comm.rank != 0:
        return
    print("| cells/a | dofs | C23 (Kalker) | C33 (Kalker) | Newton | time [s] |\n"
          "|---|---|---|---|---|---|")
    for r in study:
        print(f"| {r['cells_per_a']} | {r['dofs']} | {r['C23']:.4f} ({linear['C23']}) | "
              f"{r['C33']:.4f} ({linear['C33']}) | {r['newton_iterations']} | "
              f"{r['wall_time_s']:.1f} |")
    for k, e in extrapolated.items():
        if e["monotone"]:
            print(f"{k}: Richardson limit {e['limit']:.4f} (order {e['order']:.2f}), "
                  f"{e['limit'] / linear[k] - 1:+.2%} from Kalker's {linear[k]}")
        else:
            print(f"{k}: not monotone over the last three meshes, no extrapolation")
    if curve:
        print("\n| φa/(μp0/G) | Fy/μFn FE | ellipsoidal | parabolic | Mz/(μFn a) FE | "
              "ellipsoidal | parabolic | adhesion FE |\n|---|---|---|---|---|---|---|---|")
        for r in curve:
            e, p = r["fastsim_ellipsoidal"], r["fastsim_parabolic"]
            print(f"| {r['phi_a_over_saturation']:g} | {r['Fy']:+.4f} | {e['Fy']:+.4f} | "
                  f"{p['Fy']:+.4f} | {r['Mz']:+.4f} | {e['Mz']:+.4f} | {p['Mz']:+.4f} | "
                  f"{r['adhesion']:.2f} |")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    if study:
        h = [1 / r["cells_per_a"] for r in study]
        for k, marker in (("C23", "o-"), ("C33", "s-")):
            ax[0].loglog(h, [abs(r[k] / linear[k] - 1) for r in study], marker,
                         label=f"|{k} / Kalker's - 1|")
        ax[0].set_xlabel("h / a")
        ax[0].set_ylabel("relative difference")
        ax[0].legend(fontsize=8)
    if curve:
        q = [r["phi_a_over_saturation"] for r in curve]
        for key, label, color in (("Fy", "Fy / μFn", "C0"), ("Mz", "Mz / (μFn a)", "C1")):
            ax[1].semilogx(q, [-r[key] for r in curve], "o-", color=color, label=f"−{label} FE")
            for bound, style in (("ellipsoidal", "--"), ("parabolic", ":")):
                ax[1].semilogx(q, [-r[f"fastsim_{bound}"][key] for r in curve], style,
                               color=color, label=f"FASTSIM, {bound}")
        ax[1].set_xlabel("φ a / (μ p0 / G)")
        ax[1].legend(fontsize=7)
    save(fig, args.out / "bench_rolling_spin.png", 120)


if __name__ == "__main__":
    main()
