"""FASTSIM under spin: grid convergence of Fx, Fy, Mz and the two spin flexibilities.

The issue's wheel-rail case (a = 6.304 mm, b = 12.61 mm, G = 82 GPa, nu = 0.28,
Fn = 106.7 kN, mu = 0.33; Kalker's parabolic bound, the default) on n × n grids (``--grids``)
at the creepages of ``CASES``: a small spin (the linear theory's regime), large pure spins
and spin with longitudinal creepage. For each case, grid and choice of the spin
flexibilities (the package's, L4 fitted to C33 for the slip -phi y, and Kalker's 1982 single
L3):

* Fx, Fy (per mu Fn) and Mz (per mu Fn c, c = sqrt(ab));
* the change from the previous grid and the observed order log2(d_n / d_2n) of those changes;
* against the finest grid, the error, and the first-order Richardson limit 2 F_N - F_(N/2)
  (FASTSIM's force converges at first order once the traction turns inside the slip zone).

At the small spin the linear theory's Fy and Mz (Kalker's C23, C33) are printed beside.
Writes ``bench_fastsim_spin.json`` and ``bench_fastsim_spin.png`` (error of Fy and Mz
against n) to ``--out`` and prints markdown tables. Serial; a few seconds.
"""

from __future__ import annotations

import math
import sys

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction.studies.rolling.fastsim import fastsim, flexibilities, linear_theory

CASE = {"a": 6.304e-3, "b": 12.61e-3, "G": 82e9, "nu": 0.28, "mu": 0.33, "Fn": 106.7e3}
C = math.sqrt(CASE["a"] * CASE["b"])
#: (name, xi, eta, phi [1/m]); phi c = 0.009 per 1/m here
CASES = (("small spin", 0.0, 0.0, 1e-4), ("pure spin 1/m", 0.0, 0.0, 1.0),
         ("pure spin 4/m", 0.0, 0.0, 4.0), ("xi 2e-3, spin 4/m", 2e-3, 0.0, 4.0))


def grid_study(grids: list[int]) -> list[dict]:
    """One row per case, flexibility choice and grid."""
    ours = flexibilities(CASE["a"], CASE["b"], CASE["G"], CASE["nu"])
    rows = []
    for name, xi, eta, phi in CASES:
        for label, flex in (("C33 (default)", ours), ("Kalker 1982", ours.kalker1982())):
            values = []
            for n in grids:
                r = fastsim(**CASE, xi=xi, eta=eta, phi=phi, nx=n, ny=n, flexibility=flex)
                values.append(np.array([r.Fx, r.Fy, r.Mz / C]) / (CASE["mu"] * CASE["Fn"]))
            finest, richardson = values[-1], 2 * values[-1] - values[-2]
            for k, n in enumerate(grids):
                change = np.abs(values[k] - values[k - 1]) if k else None
                before = np.abs(values[k - 1] - values[k - 2]) if k > 1 else None
                order = (np.log2(before / change).tolist()
                         if change is not None and before is not None and np.all(change > 0)
                         else None)
                rows.append({"case": name, "creepage": [xi, eta, phi], "flexibility": label,
                             "n": n, "Fx": float(values[k][0]), "Fy": float(values[k][1]),
                             "Mz": float(values[k][2]),
                             "error_vs_finest": np.abs(values[k] - finest).tolist(),
                             "error_vs_richardson": np.abs(values[k] - richardson).tolist(),
                             "observed_order": order})
    return rows


def linear_reference() -> dict[str, float]:
    """The linear theory at the small spin, per mu Fn (Mz per mu Fn c)."""
    _, xi, eta, phi = CASES[0]
    forces = linear_theory(CASE["a"], CASE["b"], CASE["G"], CASE["nu"], xi=xi, eta=eta, phi=phi)
    scale = CASE["mu"] * CASE["Fn"]
    return {"Fy": forces.Fy / scale, "Mz": forces.Mz / (scale * C)}


def table(rows: list[dict]) -> str:
    lines = ["| case | flexibility | n | Fy/(μFn) | Mz/(μFn c) | err Fy (Richardson) | "
             "err Mz (Richardson) | order Fy, Mz |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        order = ("" if r["observed_order"] is None
                 else f"{r['observed_order'][1]:.2f}, {r['observed_order'][2]:.2f}")
        lines.append(f"| {r['case']} | {r['flexibility']} | {r['n']} | {r['Fy']:+.5g} | "
                     f"{r['Mz']:+.5g} | {r['error_vs_richardson'][1]:.1e} | "
                     f"{r['error_vs_richardson'][2]:.1e} | {order} |")
    return "\n".join(lines)


def plot(rows: list[dict], path, dpi: int) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), sharey=True)
    for ax, k, quantity in zip(axes, (1, 2), ("Fy/(μFn)", "Mz/(μFn c)"), strict=True):
        for name, *_ in CASES:
            series = [r for r in rows if r["case"] == name and r["flexibility"] ==
                      "C33 (default)" and r["error_vs_richardson"][k] > 0]
            ax.loglog([r["n"] for r in series], [r["error_vs_richardson"][k] for r in series],
                      "o-", label=name)
        ax.set(xlabel="n (strips = elements per strip)",
               title=f"{quantity}: |value - Richardson limit|")
    axes[0].set_ylabel("error")
    axes[0].legend(fontsize=8)
    save(fig, path, dpi)


def main() -> int:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--grids", type=int, nargs="+", default=[10, 20, 40, 80, 160, 320, 640],
                       help="strips (= elements per strip) of each grid, at least three "
                       "(10 20 40 80 160 320 640)")
    flags.add_argument("--dpi", type=int, default=110)
    args = flags.parse_args()
    grids = sorted(args.grids)
    if len(grids) < 3 or grids[0] < 1:
        print(f"--grids={args.grids}: give at least three grids of n >= 1", file=sys.stderr)
        return 2
    rows = grid_study(grids)
    linear = linear_reference()
    args.out.mkdir(parents=True, exist_ok=True)
    print(f"FASTSIM under spin, {CASE}, parabolic bound:\n\n{table(rows)}\n\n"
          f"linear theory at phi = {CASES[0][3]}: Fy/(μFn) = {linear['Fy']:+.5g}, "
          f"Mz/(μFn c) = {linear['Mz']:+.5g}")
    plot(rows, args.out / "bench_fastsim_spin.png", args.dpi)
    write_summary(args.out / "bench_fastsim_spin.json",
                  {"case": CASE, "cases": CASES, "grids": grids, "rows": rows,
                   "linear_theory_small_spin": linear})
    print(f"wrote {args.out / 'bench_fastsim_spin.json'} and "
          f"{args.out / 'bench_fastsim_spin.png'}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
