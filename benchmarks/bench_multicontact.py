r"""Braun's earthquake-like model, its master equation and the elastic instability.

**Master equation, cost against accuracy**: the friction force at X = 3 x_c (Gaussian
thresholds, σ = 0.3 x_c, relaxed newborn contacts, from all contacts relaxed) for the steps
h = 0.04 … 0.0025 x_c, against h = 0.0005 x_c (the reference): error, observed order, wall
time.

**Model against equation**: the root-mean-square difference over X ∈ [0, 4 x_c] between the
friction force per contact of one realisation of N contacts (exact quasistatic drive) and the
master equation (h = 0.002 x_c), over 8 seeds, for N = 100 … 25600: the exponent of its fall
with N (the law of large numbers says −1/2) and the wall time of a realisation.

**Instability map**: the spring-driven model (N = 300, v = 1, ζ = 0.1) over K/(N k) and
σ/x_c, each run classified by the fraction of its late window spent stuck, with the master
equation's K* = −max F'(X) per σ: stick-slip should lie below K*, smooth sliding above.

**Interacting contacts, cost against N**: the EQ model on an n × n lattice between two identical
bodies (coupling k/(E a) = 0.1, σ = 0.3 x_c) moved quasistatically over four contact lives,
n = 8 … 24: the set-up (the dense stiffness matrix, O(N³)), the run, the time per break, and
the ratio of the run to the plain model's over the same lives (the baseline, same process).

Writes ``bench_multicontact.json`` and ``bench_multicontact.png`` to ``--out`` and prints markdown
tables. Serial (vectorised NumPy and a two-unknown TS).
"""

from __future__ import annotations

import time

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction.studies.multicontact import (
    EQModel,
    InstabilityMap,
    InteractingEQModel,
    MasterEquation,
    instability_map,
)

STEPS = [0.04, 0.02, 0.01, 0.005, 0.0025]
SIZES = [100, 400, 1600, 6400, 25600]
SPREADS = [0.05, 0.1, 0.2, 0.3, 0.5]
STIFFNESS = list(np.logspace(-1.5, 1.5, 7))  # × N k
SIDES = [8, 12, 16, 24]


def _convergence(out: dict) -> None:
    model = EQModel(n_contacts=1, x_s_std=0.3)
    reference = MasterEquation(model, h=0.0005).solve(X_max=3.0).F[-1]
    rows = []
    for h in STEPS:
        start = time.perf_counter()
        F = MasterEquation(model, h=h).solve(X_max=3.0).F[-1]
        rows.append({"h": h, "error": abs(F - reference), "wall_time_s":
                     time.perf_counter() - start})
    for coarse, fine in zip(rows[:-1], rows[1:], strict=True):
        fine["order"] = float(np.log2(coarse["error"] / fine["error"]))
    out["convergence"] = rows
    print("| h / x_c | |F − F_ref| / (N k x_c) | order | wall time (s) |\n|---|---|---|---|")
    for row in rows:
        print(f"| {row['h']} | {row['error']:.3e} | {row.get('order', float('nan')):.2f} "
              f"| {row['wall_time_s']:.3f} |")


def _noise(out: dict) -> None:
    master = MasterEquation(EQModel(n_contacts=1, x_s_std=0.3), h=0.002).solve(X_max=4.0)
    X, F = master.X[::50], master.F[::50]
    rows = []
    for n in SIZES:
        model = EQModel(n_contacts=n, x_s_std=0.3)
        start = time.perf_counter()
        runs = [model.quasistatic(4.0, n_points=X.size, seed=seed) for seed in range(8)]
        wall = (time.perf_counter() - start) / len(runs)
        rms = float(np.sqrt(np.mean([(run.F / n - F) ** 2 for run in runs])))
        rows.append({"N": n, "rms_difference": rms, "wall_time_s": wall})
    exponent = float(np.polyfit(np.log(SIZES), np.log([r["rms_difference"] for r in rows]),
                                1)[0])
    out["model_against_equation"] = {"rows": rows, "exponent": exponent,
                                     "static_force": master.static_force,
                                     "kinetic_force": master.kinetic_force,
                                     "K_star": master.K_star}
    print(f"\nexponent of the fall with N: {exponent:.3f}\n")
    print("| N | rms (F_EQ − F_ME)/N (k x_c) | wall time per realisation (s) |\n|---|---|---|")
    for row in rows:
        print(f"| {row['N']} | {row['rms_difference']:.3e} | {row['wall_time_s']:.3f} |")


def _map(out: dict) -> InstabilityMap:
    n = 300
    start = time.perf_counter()
    result = instability_map([s * n for s in STIFFNESS], SPREADS, n_contacts=n)
    out["instability_map"] = {**result.to_json(), "wall_time_s": time.perf_counter() - start}
    below = result.K[None, :] < result.K_star[:, None]
    agree = float(np.mean(below == result.stick_slip))
    out["instability_map"]["agreement_with_K_star"] = agree
    print(f"\ninstability map: classification agrees with K > K* in {100 * agree:.0f} % of runs")
    print("| σ/x_c | K*/(N k) | " + " | ".join(f"{s:.3g}" for s in STIFFNESS) + " |")
    print("|---|---|" + "---|" * len(STIFFNESS))
    for i, spread in enumerate(SPREADS):
        cells = ["S" if ss else "." for ss in result.stick_slip[i]]
        print(f"| {spread} | {result.K_star[i] / n:.3g} | " + " | ".join(cells) + " |")
    return result


def _interacting(out: dict) -> None:
    rows = []
    print("\ninteracting contacts (k/(E a) = 0.1, σ = 0.3 x_c, four lives):")
    print("| N | set-up (s) | run (s) | breaks | µs per break | run / plain model's |")
    print("|---|---|---|---|---|---|")
    for n in SIDES:
        model = EQModel(n_contacts=n * n, x_s_std=0.3)
        start = time.perf_counter()
        coupled = InteractingEQModel.lattice(model, 0.1)
        setup = time.perf_counter() - start
        lives = 4.0 * n * n / coupled.interface_stiffness
        start = time.perf_counter()
        run = coupled.quasistatic(lives)
        wall = time.perf_counter() - start
        start = time.perf_counter()
        model.quasistatic(4.0)  # the same four lives without interaction
        plain = time.perf_counter() - start
        rows.append({"N": n * n, "setup_s": setup, "run_s": wall, "breaks": run.breaks,
                     "largest_avalanche": run.largest_avalanche, "plain_run_s": plain,
                     "ratio_to_plain": wall / plain})
        print(f"| {n * n} | {setup:.3f} | {wall:.2f} | {run.breaks} | "
              f"{1e6 * wall / run.breaks:.0f} | {wall / plain:.0f} |")
    out["interacting_cost"] = {"coupling": 0.1, "relative_spread": 0.3, "lives": 4,
                               "rows": rows}


def main() -> None:
    flags = benchmark_parser(__doc__)
    args = flags.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    out: dict = {}
    _convergence(out)
    _noise(out)
    result = _map(out)
    _interacting(out)
    write_summary(args.out / "bench_multicontact.json", out)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    rows = out["model_against_equation"]["rows"]
    ax1.loglog([r["N"] for r in rows], [r["rms_difference"] for r in rows], "o-",
               label="EQ model − master equation")
    ax1.loglog(SIZES, rows[0]["rms_difference"] * np.sqrt(SIZES[0] / np.array(SIZES)), "k--",
               label="N^(−1/2)")
    ax1.set_xlabel("N")
    ax1.set_ylabel("rms difference of F/N (k x_c)")
    ax1.legend()
    n = result.parameters["N"]
    K_grid, spread_grid = np.meshgrid(result.K / n, result.relative_spread)
    ax2.scatter(K_grid[result.stick_slip], spread_grid[result.stick_slip], marker="x",
                color="C3", label="stick-slip")
    ax2.scatter(K_grid[~result.stick_slip], spread_grid[~result.stick_slip], marker="o",
                facecolors="none", edgecolors="C0", label="smooth")
    ax2.plot(result.K_star / n, result.relative_spread, "k-", label="K* (master equation)")
    ax2.set_xscale("log")
    ax2.set_xlabel("K / (N k)")
    ax2.set_ylabel("σ / x_c")
    ax2.legend()
    save(fig, args.out / "bench_multicontact.png", dpi=120)


if __name__ == "__main__":
    main()
