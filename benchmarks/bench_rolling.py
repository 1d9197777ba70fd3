"""Accuracy against cost of Kalker's FASTSIM for a steady rolling wheel-rail contact.

The issue's example in SI units (a = 6.304 mm along the rolling direction, b = 12.61 mm,
G = 82 GPa, nu = 0.28, Fn = 106.7 kN, mu = 0.3; ellipsoidal traction bound) at the
longitudinal creepages xi = 1e-4 (nearly linear), 1e-3 and 3e-3 (partial slip), on
n × n grids (``--grids``, n strips of n elements). For each grid and creepage:

* the creep force Fx, its relative error against the finest grid (the reference) and the
  observed order log2(e_n / e_2n) between successive doublings;
* at xi = 1e-4, Fx over the linear theory's -G a b C11 xi (Kalker's slope, which FASTSIM
  approaches as xi -> 0; the rest is the slip already present at the trailing edge);
* the wall time of one FASTSIM call (best of ``--repeats``), and as a same-run baseline the
  time over that of the 40 × 40 grid, which travels between machines where seconds do not.

Then the batch: a 100-point creep curve (xi from 0 to 5e-3) on 40 × 40 in one vectorised
call, against 100 separate calls.

Writes ``bench_rolling.json`` and ``bench_rolling.png`` (error against time, log-log) to
``--out`` and prints markdown tables. Serial; about 10 s with the defaults.
"""

from __future__ import annotations

import math
import sys

import numpy as np
from _common import best_time, save, write_summary
from _common import parser as benchmark_parser

from fenicsfriction.studies.rolling.fastsim import creep_curve, fastsim, linear_theory

# the ellipsoidal (Hertz) bound, as in the table of docs/rolling-fastsim.md (the default is
# Kalker's parabolic one since issue 27)
CASE = {"a": 6.304e-3, "b": 12.61e-3, "G": 82e9, "nu": 0.28, "mu": 0.3, "Fn": 106.7e3,
        "pressure": "ellipsoidal"}
CREEPAGES = (1e-4, 1e-3, 3e-3)
BASELINE_GRID = 40


def grid_study(grids: list[int], repeats: int) -> list[dict]:
    rows = []
    for n in grids:
        for xi in CREEPAGES:
            seconds, result = best_time(lambda n=n, xi=xi: fastsim(**CASE, xi=xi, nx=n, ny=n),
                                        repeats)
            rows.append({"n": n, "xi": xi, "Fx": result.Fx, "time_s": seconds,
                         "adhesion_fraction": result.adhesion_fraction})
        print(f"  {n} × {n}: {rows[-1]['time_s'] * 1e3:.2f} ms", file=sys.stderr, flush=True)
    finest = max(grids)
    slope = {xi: linear_theory(CASE["a"], CASE["b"], CASE["G"], CASE["nu"], xi=xi).Fx
             for xi in CREEPAGES}
    for xi in CREEPAGES:
        series = [r for r in rows if r["xi"] == xi]
        reference = next(r["Fx"] for r in series if r["n"] == finest)
        base = next((r["time_s"] for r in series if r["n"] == BASELINE_GRID), None)
        for r in series:
            r["error"] = abs(r["Fx"] / reference - 1) if r["n"] != finest else None
            r["over_linear_theory"] = r["Fx"] / slope[xi]
            r["time_over_40x40"] = r["time_s"] / base if base else None
        errors = [r["error"] for r in series if r["error"]]
        for r, e0, e1 in zip(series, errors[:-1], errors[1:], strict=False):
            r["order"] = math.log2(e0 / e1)
    return rows


def batch_study(repeats: int) -> dict:
    xis = np.linspace(0.0, 5e-3, 100)
    batch, _ = best_time(lambda: creep_curve(**CASE, xi=xis, nx=40, ny=40), repeats)
    single, _ = best_time(lambda: [fastsim(**CASE, xi=float(xi), nx=40, ny=40) for xi in xis],
                          repeats)
    return {"points": len(xis), "grid": 40, "batch_s": batch, "one_by_one_s": single,
            "one_by_one_over_batch": single / batch}


def table(rows: list[dict]) -> str:
    lines = ["| grid | xi | Fx [N] | error vs finest | order n→2n | Fx / linear theory "
             "| adhesion | time [ms] | time / 40×40 |", "|---" * 9 + "|"]
    for r in rows:
        error = "reference" if r["error"] is None else f"{r['error']:.2e}"
        order = f"{r['order']:.2f}" if "order" in r else ""
        ratio = f"{r['time_over_40x40']:.2f}" if r["time_over_40x40"] else ""
        lines.append(f"| {r['n']}×{r['n']} | {r['xi']:g} | {r['Fx']:.1f} | {error} | {order} "
                     f"| {r['over_linear_theory']:.4f} | {r['adhesion_fraction']:.3f} "
                     f"| {r['time_s'] * 1e3:.3f} | {ratio} |")
    return "\n".join(lines)


def plot(rows: list[dict], path, dpi: int) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4.5))
    for xi, marker in zip(CREEPAGES, "osd", strict=True):
        series = [r for r in rows if r["xi"] == xi and r["error"]]
        ax.loglog([r["time_s"] for r in series], [r["error"] for r in series], marker + "-",
                  label=f"ξ = {xi:g}")
        for r in series:
            ax.annotate(f"{r['n']}", (r["time_s"], r["error"]), fontsize=6,
                        textcoords="offset points", xytext=(3, 3))
    ax.set(xlabel="wall time of one FASTSIM call [s]",
           ylabel="|Fx / Fx(finest grid) - 1|", title="FASTSIM: creep force error against cost")
    ax.legend()
    save(fig, path, dpi)


def main() -> int:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--grids", type=int, nargs="+", default=[5, 10, 20, 40, 80, 160, 320],
                       help="strips (= elements per strip) of each grid; the finest is the "
                       "reference (5 10 20 40 80 160 320)")
    flags.add_argument("--repeats", type=int, default=5, help="timing repeats (best of; 5)")
    flags.add_argument("--dpi", type=int, default=110)
    args = flags.parse_args()
    rows = grid_study(sorted(args.grids), args.repeats)
    batch = batch_study(args.repeats)
    args.out.mkdir(parents=True, exist_ok=True)
    print(f"FASTSIM, a = {CASE['a']} m, b = {CASE['b']} m, Fn = {CASE['Fn']} N, "
          f"mu = {CASE['mu']}:\n\n{table(rows)}\n\n"
          f"{batch['points']}-point creep curve on {batch['grid']}×{batch['grid']}: "
          f"{batch['batch_s'] * 1e3:.1f} ms in one call, {batch['one_by_one_s'] * 1e3:.1f} ms "
          f"one by one (×{batch['one_by_one_over_batch']:.1f})")
    plot(rows, args.out / "bench_rolling.png", args.dpi)
    write_summary(args.out / "bench_rolling.json",
                  {"case": CASE, "creepages": CREEPAGES, "grids": rows, "creep_curve": batch})
    print(f"wrote {args.out / 'bench_rolling.json'} and {args.out / 'bench_rolling.png'}",
          file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
