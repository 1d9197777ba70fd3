r"""Braun's earthquake-like model, its master equation and the elastic instability.

**Master equation, cost against accuracy**: the friction force at X = 3 x_c (Gaussian
thresholds, σ = 0.3 x_c, relaxed newborn contacts, from all contacts relaxed) for the steps
h = 0.04 … 0.0025 x_c, against h = 0.0005 x_c (the reference): error, observed order, wall
time.

**Model against equation**: the root-mean-square difference over X ∈ [0, 4 x_c] between the
friction force per contact of one realisation of N contacts (exact quasistatic drive) and the
master equation (h = 0.002 x_c), over 8 seeds, for N = 100 … 25600: the exponent of its fall
with N (the law of large numbers says −1/2) and the wall time of a realisation.

**Instability map**: the model (N = 300) over K/(N k) and σ/x_c, each run classified by the
slip events of the slider pulled infinitely slowly (a jump at the static peak: one event drops
the spring force by more than 5 % of it), beside the former speed classification of the
spring-driven runs with inertia (v = 1, ζ = 0.1; max Ẋ > 10 v), with the master equation's
K* = −max F'(X) per σ: stick-slip should lie below K*, smooth sliding above.

**Events against N and run length**: the slow spring drive at K/K* = 0.5 … 2, σ/x_c = 0.1,
0.3, N = 100 … 3000, run 3 or 12 x_c past the static peak: the onset's drop (the largest
event over the peak force), the late window's largest drop over its mean force, the late
advance carried by jumps, the mean breaks per late event; and the spring-driven runs' speed
classification for the same N (3 x_c): which classification converges with N to K < K*.

**The map's disagreeing cells against N**: the cells of the instability map (N = 300) whose
onset classification disagreed with K* (σ = 0.3 x_c at K = N k, 2.3 K*; σ = 0.5 x_c at
K = 0.32 and 1.0 N k, 2.4 and 7.5 K*), at N = 100 … 3000 (K/(N k) fixed, so K/K* is too),
six seeds each, the map's slow drive (F_s/K + 6 x_c): the onset drop's mean, spread and
largest over the seeds, the seeds classified stick-slip, where the largest event falls (its
drive position against the static peak's), the exponent of the mean's fall with N.

**Interacting contacts, cost against N**: the EQ model on an n × n lattice between two identical
bodies (coupling k/(E a) = 0.1, σ = 0.3 x_c) moved quasistatically over four contact lives,
n = 8 … 32, dense (the stiffness matrix, O(N³)) and matrix-free (FFT and conjugate gradients):
the set-up, the run, the time per break, the events compared (sizes equal, positions to
tolerance) and the time ratio; then the matrix-free model alone at n = 64 and 128 (16,384
contacts) over its first breaks: the time per break and the iterations per solve.

**Interacting contacts, events**: the slow spring drive of matrix-free lattices (n = 8 … 32)
at couplings 0, 0.1, 0.3, σ = 0.3 x_c, K = S/2 (S the interface's stiffness): onset and late
drops against N.

``--sections`` picks some of: convergence, noise, map, map-cells, events, interacting,
interacting-events;
``--sizes`` the N of the events study, ``--sides`` the lattices compared dense against
matrix-free (a busy machine may want fewer).

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
    LatticeEQModel,
    MasterEquation,
    critical_stiffness,
    instability_map,
)

STEPS = [0.04, 0.02, 0.01, 0.005, 0.0025]
SIZES = [100, 400, 1600, 6400, 25600]
SPREADS = [0.05, 0.1, 0.2, 0.3, 0.5]
STIFFNESS = list(np.logspace(-1.5, 1.5, 7))  # × N k
SIDES = [8, 12, 16, 24, 32]
LARGE_SIDES = {64: 500, 128: 200}  # side: breaks timed
EVENT_SIZES = [100, 300, 1000, 3000]
EVENT_FACTORS = [0.5, 0.8, 0.9, 1.1, 1.25, 2.0]  # K/K*
EVENT_SPREADS = [0.1, 0.3]
RUN_LENGTHS = [3.0, 12.0]  # x_c past the static peak
COUPLINGS = [0.0, 0.1, 0.3]
MAP_CELLS = [(0.3, 1.0), (0.5, 10**-0.5), (0.5, 1.0)]  # (σ/x_c, K/(N k)) that disagreed at 300
CELL_SIZES = [100, 300, 1000, 3000]
CELL_SEEDS = range(6)


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
    agreement = {"agreement_with_K_star": result.onset_stick_slip,
                 "sustained_agreement_with_K_star": result.sustained_stick_slip,
                 "speed_agreement_with_K_star": result.fast_slip}
    for key, flags in agreement.items():
        out["instability_map"][key] = float(np.mean(below == flags))
    print(_map_table(out["instability_map"]))
    return result


def _map_table(record: dict) -> str:
    """The map as docs/multicontact.md shows it, from its JSON record: each cell
    ``onset_drop / largest_late_drop``, bold where above the threshold (``onset_stick_slip``,
    ``sustained_stick_slip``), ``v`` where ``fast_slip``; K/K* beside the cells whose onset
    classification disagrees with K*'s side."""
    K, K_star = np.array(record["K"]), np.array(record["K_star"])
    n, threshold = record["parameters"]["N"], record["drop_threshold"]
    below = K[None, :] < K_star[:, None]
    counts = {key: int(round(record[key + "_agreement_with_K_star"] * below.size))
              if key else int(round(record["agreement_with_K_star"] * below.size))
              for key in ("", "sustained", "speed")}
    lines = [f"\ninstability map (N = {n}, {below.size} cells, {record['wall_time_s']:.0f} s): "
             f"onset_stick_slip on K*'s side in {counts['']} of {below.size}, "
             f"sustained_stick_slip in {counts['sustained']}, fast_slip in {counts['speed']}",
             "| σ/x_c | K*/(N k) | " + " | ".join(f"K/(N k) = {k / n:.3g}" if j == 0 else
                                                  f"{k / n:.3g}" for j, k in enumerate(K))
             + " |", "|---|---|" + "---|" * K.size]

    def bold(value: float) -> str:
        return f"**{value:#.3g}**" if value > threshold else f"{value:#.3g}"

    for i, spread in enumerate(record["relative_spread"]):
        cells = []
        for j in range(K.size):
            onset, late = record["onset_drop"][i][j], record["largest_late_drop"][i][j]
            cell = f"{bold(onset)} / {bold(late)}" + (" v" if record["fast_slip"][i][j] else "")
            if record["onset_stick_slip"][i][j] != below[i, j]:
                cell += f" ({K[j] / K_star[i]:.2f} K*)"
            cells.append(cell)
        lines.append(f"| {spread} | {K_star[i] / n:.3g} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _events(out: dict) -> None:
    rows = []
    print("\nevents against N and run length (slow spring drive; onset drop / peak force, "
          "late largest drop / mean force):")
    print("| σ/x_c | N | run (x_c) | " + " | ".join(f"K/K* = {f}" for f in EVENT_FACTORS)
          + " |")
    print("|---|---|---|" + "---|" * len(EVENT_FACTORS))
    for spread in EVENT_SPREADS:
        for n in EVENT_SIZES:
            model = EQModel(n_contacts=n, x_s_std=spread)
            K_star = critical_stiffness(model)
            master = MasterEquation(model, h=spread / 50).solve(2.0 + 10 * spread)
            for length in RUN_LENGTHS:
                cells = []
                for factor in EVENT_FACTORS:
                    K = factor * K_star
                    start = time.perf_counter()
                    run = model.spring_quasistatic(K=K, D_max=master.static_force / K + length)
                    rows.append({"relative_spread": spread, "N": n, "run_length": length,
                                 "K_over_K_star": factor, "K_star": K_star,
                                 "onset_drop": run.onset_drop,
                                 "onset_stick_slip": run.onset_stick_slip,
                                 "largest_late_drop": run.largest_late_drop,
                                 "sustained_stick_slip": run.sustained_stick_slip,
                                 "jump_fraction": run.jump_fraction,
                                 "mean_breaks": run.mean_breaks, "events": int(run.D.size),
                                 "wall_time_s": time.perf_counter() - start})
                    cells.append(f"{run.onset_drop:.3f} / {run.largest_late_drop:.3f}")
                print(f"| {spread} | {n} | {length:g} | " + " | ".join(cells) + " |")
    speed = []
    for spread in EVENT_SPREADS:
        for n in EVENT_SIZES:
            model = EQModel(n_contacts=n, x_s_std=spread)
            K_star = critical_stiffness(model)
            master = MasterEquation(model, h=spread / 50).solve(2.0 + 10 * spread)
            mass = 1e-5 * n
            for factor in EVENT_FACTORS:
                K = factor * K_star
                period = 2 * np.pi * np.sqrt(mass / (n + K))
                run = model.spring_driven(K=K, v=1.0, mass=mass,
                                          damping=0.2 * np.sqrt(mass * (n + K)),
                                          t_end=master.static_force / K + RUN_LENGTHS[0],
                                          dt=period / 20)
                speed.append({"relative_spread": spread, "N": n, "K_over_K_star": factor,
                              "max_speed": run.max_speed, "fast_slip": run.fast_slip,
                              "onset_stick_slip": run.onset_stick_slip,
                              "dynamic_onset_drop": run.onset_drop,
                              "dynamic_largest_late_drop": run.largest_late_drop})
    out["events_study"] = {"rows": rows, "speed": speed, "drop_threshold": 0.05}
    print("\nspring-driven runs with inertia (v = 1, ζ = 0.1, 3 x_c): max Ẋ/v")
    print("| σ/x_c | N | " + " | ".join(f"K/K* = {f}" for f in EVENT_FACTORS) + " |")
    print("|---|---|" + "---|" * len(EVENT_FACTORS))
    for spread in EVENT_SPREADS:
        for n in EVENT_SIZES:
            cells = [f"{r['max_speed']:.1f}" for r in speed
                     if r["relative_spread"] == spread and r["N"] == n]
            print(f"| {spread} | {n} | " + " | ".join(cells) + " |")


def _map_cells(out: dict) -> None:
    rows, summary = [], []
    print("\nthe map's disagreeing cells against N (slow drive, F_s/K + 6 x_c, six seeds): "
          "onset drop over the peak force, mean ± std [largest], seeds above 5 %")
    print("| σ/x_c | K/(N k) | K/K* | " + " | ".join(f"N = {n}" for n in CELL_SIZES)
          + " | exponent |")
    print("|---|---|---|" + "---|" * (len(CELL_SIZES) + 1))
    for spread, stiffness in MAP_CELLS:
        cells, means = [], []
        for n in CELL_SIZES:
            model = EQModel(n_contacts=n, x_s_std=spread)
            master = MasterEquation(model, h=spread / 50).solve(2.0 + 10 * spread)
            K = stiffness * n
            K_star = critical_stiffness(model)
            peak_at = float(master.X[np.argmax(master.F)]) + master.static_force / K
            drops = []
            for seed in CELL_SEEDS:
                start = time.perf_counter()
                run = model.spring_quasistatic(K=K, D_max=master.static_force / K + 6.0,
                                               seed=seed)
                i = int(np.argmax(run.events.drop))
                drops.append(run.onset_drop)
                rows.append({"relative_spread": spread, "K_over_N_k": stiffness, "N": n,
                             "seed": seed, "K_over_K_star": K / K_star,
                             "onset_drop": run.onset_drop,
                             "onset_stick_slip": run.onset_stick_slip,
                             "largest_late_drop": run.largest_late_drop,
                             "largest_event_breaks": int(run.events.breaks[i]),
                             "largest_event_at": float(run.events.start[i]),
                             "static_peak_at": peak_at, "events": int(run.D.size),
                             "wall_time_s": time.perf_counter() - start})
            mean = float(np.mean(drops))
            means.append(mean)
            above = int(np.sum(np.asarray(drops) > 0.05))
            summary.append({"relative_spread": spread, "K_over_N_k": stiffness, "N": n,
                            "K_over_K_star": K / K_star, "mean_onset_drop": mean,
                            "std_onset_drop": float(np.std(drops)),
                            "largest_onset_drop": float(np.max(drops)),
                            "seeds_above_threshold": above, "seeds": len(drops)})
            cells.append(f"{mean:.3f} ± {np.std(drops):.3f} [{np.max(drops):.3f}], "
                         f"{above}/{len(drops)}")
        exponent = float(np.polyfit(np.log(CELL_SIZES), np.log(means), 1)[0])
        for row in summary[-len(CELL_SIZES):]:
            row["exponent"] = exponent
        print(f"| {spread} | {stiffness:.3g} | {summary[-1]['K_over_K_star']:.2f} | "
              + " | ".join(cells) + f" | {exponent:.2f} |")
    out["map_cells"] = {"rows": rows, "summary": summary, "drop_threshold": 0.05,
                        "drive_distance": 6.0}


def _interacting(out: dict) -> None:
    rows = []
    print("\ninteracting contacts (k/(E a) = 0.1, σ = 0.3 x_c, four lives), dense against "
          "matrix-free:")
    print("| N | set-up dense (s) | set-up free (s) | run dense (s) | run free (s) | breaks | "
          "µs per break dense | µs per break free | free / dense | same events |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for n in SIDES:
        model = EQModel(n_contacts=n * n, x_s_std=0.3)
        start = time.perf_counter()
        coupled = InteractingEQModel.lattice(model, 0.1)
        setup = time.perf_counter() - start
        start = time.perf_counter()
        free = LatticeEQModel(model, 0.1)
        setup_free = time.perf_counter() - start
        lives = 4.0 * n * n / coupled.interface_stiffness
        start = time.perf_counter()
        run = coupled.quasistatic(lives)
        wall = time.perf_counter() - start
        start = time.perf_counter()
        run_free = free.quasistatic(lives)
        wall_free = time.perf_counter() - start
        same = bool(np.array_equal(run.avalanche_size, run_free.avalanche_size))
        position = float(np.max(np.abs(run.avalanche_X - run_free.avalanche_X)) / lives) \
            if same else float("nan")
        rows.append({"N": n * n, "setup_s": setup, "setup_free_s": setup_free, "run_s": wall,
                     "run_free_s": wall_free, "breaks": run.breaks,
                     "largest_avalanche": run.largest_avalanche, "same_events": same,
                     "largest_position_difference_over_X_max": position,
                     "force_difference": float(np.max(np.abs(run.F - run_free.F))
                                               / np.max(np.abs(run.F))),
                     "ratio_free_to_dense": wall_free / wall,
                     "iterations_per_solve": free.stiffness.iterations / free.stiffness.solves
                     if free.stiffness is not None else 0.0})
        print(f"| {n * n} | {setup:.3f} | {setup_free:.3f} | {wall:.2f} | {wall_free:.2f} | "
              f"{run.breaks} | {1e6 * wall / run.breaks:.0f} | "
              f"{1e6 * wall_free / run.breaks:.0f} | {wall_free / wall:.1f} | {same} "
              f"({position:.1e}) |")
    large = []
    print("\nmatrix-free alone, its first breaks from all contacts relaxed:")
    print("| N | set-up (s) | breaks | ms per break | iterations per solve |")
    print("|---|---|---|---|---|")
    for n, count in LARGE_SIDES.items():
        model = EQModel(n_contacts=n * n, x_s_std=0.3)
        start = time.perf_counter()
        free = LatticeEQModel(model, 0.1)
        setup = time.perf_counter() - start
        assert free.stiffness is not None
        contacts = free.contacts(np.random.default_rng(0))
        solves, iterations = free.stiffness.solves, free.stiffness.iterations
        broken, start = 0, time.perf_counter()
        while broken < count:
            broken += contacts.relax(*contacts.next_break())
        wall = time.perf_counter() - start
        per_solve = (free.stiffness.iterations - iterations) / (free.stiffness.solves - solves)
        large.append({"N": n * n, "setup_s": setup, "breaks": broken, "run_s": wall,
                      "ms_per_break": 1e3 * wall / broken, "iterations_per_solve": per_solve,
                      "interface_stiffness_over_N_k": free.interface_stiffness / (n * n)})
        print(f"| {n * n} | {setup:.2f} | {broken} | {1e3 * wall / broken:.1f} | "
              f"{per_solve:.1f} |")
    out["interacting_cost"] = {"coupling": 0.1, "relative_spread": 0.3, "lives": 4,
                               "rows": rows, "matrix_free_large": large}


def _interacting_events(out: dict) -> None:
    rows = []
    print("\ninteracting contacts, slow spring drive K = S/2 (σ = 0.3 x_c, 6 lives): "
          "onset drop / late drop")
    print("| N | " + " | ".join(f"k/(E a) = {c}" for c in COUPLINGS) + " |")
    print("|---|" + "---|" * len(COUPLINGS))
    for n in SIDES:
        model = EQModel(n_contacts=n * n, x_s_std=0.3)
        cells = []
        for coupling in COUPLINGS:
            interface = LatticeEQModel(model, coupling)
            S = interface.interface_stiffness
            K = 0.5 * S
            start = time.perf_counter()
            run = interface.spring_quasistatic(K=K, D_max=n * n / K + 6.0 * n * n / S)
            rows.append({"N": n * n, "coupling": coupling, "K": K, "interface_stiffness": S,
                         "onset_drop": run.onset_drop,
                         "largest_late_drop": run.largest_late_drop,
                         "jump_fraction": run.jump_fraction, "mean_breaks": run.mean_breaks,
                         "largest_event_breaks": int(np.max(run.events.breaks, initial=0)),
                         "wall_time_s": time.perf_counter() - start})
            cells.append(f"{run.onset_drop:.3f} / {run.largest_late_drop:.3f}")
        print(f"| {n * n} | " + " | ".join(cells) + " |")
    out["interacting_events"] = rows


SECTIONS = ("convergence", "noise", "map", "map-cells", "events", "interacting",
            "interacting-events")


def main() -> None:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--sections", default=",".join(SECTIONS),
                       help=f"comma-separated, of {', '.join(SECTIONS)} (all)")
    flags.add_argument("--sizes", default=",".join(map(str, EVENT_SIZES)),
                       help="N of the events study (100,300,1000,3000)")
    flags.add_argument("--sides", default=",".join(map(str, SIDES)),
                       help="lattice sides, dense against matrix-free (8,12,16,24,32)")
    flags.add_argument("--large-sides", default="64:500,128:200",
                       help="matrix-free alone, side:breaks (64:500,128:200)")
    args = flags.parse_args()
    EVENT_SIZES[:] = [int(v) for v in args.sizes.split(",")]
    SIDES[:] = [int(v) for v in args.sides.split(",")]
    LARGE_SIDES.clear()
    LARGE_SIDES.update({int(a): int(b) for a, b in
                        (item.split(":") for item in args.large_sides.split(","))})
    chosen = [name.strip() for name in args.sections.split(",") if name.strip()]
    unknown = sorted(set(chosen) - set(SECTIONS))
    if unknown:
        flags.error(f"--sections {','.join(unknown)} is invalid: choose among "
                    f"{', '.join(SECTIONS)}")
    args.out.mkdir(parents=True, exist_ok=True)
    out: dict = {"sections": chosen}
    result = None
    steps = {"convergence": _convergence, "noise": _noise, "map-cells": _map_cells,
             "events": _events,
             "interacting": _interacting, "interacting-events": _interacting_events}
    for name in SECTIONS:
        if name not in chosen:
            continue
        if name == "map":
            result = _map(out)
        else:
            steps[name](out)
        # written after each section: a long run keeps what it measured
        write_summary(args.out / "bench_multicontact.json", out)
    _figure(out, result, args.out / "bench_multicontact.png")


def _figure(out: dict, result: InstabilityMap | None, path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    ax1, ax2, ax3, ax4 = axes.ravel()
    if "model_against_equation" in out:
        rows = out["model_against_equation"]["rows"]
        ax1.loglog([r["N"] for r in rows], [r["rms_difference"] for r in rows], "o-",
                   label="EQ model − master equation")
        ax1.loglog(SIZES, rows[0]["rms_difference"] * np.sqrt(SIZES[0] / np.array(SIZES)),
                   "k--", label="N^(−1/2)")
        ax1.set_xlabel("N")
        ax1.set_ylabel("rms difference of F/N (k x_c)")
        ax1.legend()
    else:
        ax1.set_visible(False)
    if result is None:
        ax2.set_visible(False)
    else:
        n = result.parameters["N"]
        K_grid, spread_grid = np.meshgrid(result.K / n, result.relative_spread)
        jumps = result.onset_stick_slip
        ax2.scatter(K_grid[jumps], spread_grid[jumps], marker="x",
                    color="C3", label="jump at the peak (events)")
        ax2.scatter(K_grid[~jumps], spread_grid[~jumps], marker="o",
                    facecolors="none", edgecolors="C0", label="smooth (events)")
        ax2.scatter(K_grid[result.fast_slip], spread_grid[result.fast_slip], marker="+",
                    s=120, color="k", label="max Ẋ > 10 v")
        ax2.plot(result.K_star / n, result.relative_spread, "k-", label="K* (master equation)")
        ax2.set_xscale("log")
        ax2.set_xlabel("K / (N k)")
        ax2.set_ylabel("σ / x_c")
        ax2.legend(fontsize=7)
    if "events_study" in out:
        rows = out["events_study"]["rows"]
        for i, factor in enumerate(EVENT_FACTORS):
            for key, ax, style in (("onset_drop", ax3, "-"), ("largest_late_drop", ax4, "-")):
                picked = [r for r in rows if r["K_over_K_star"] == factor
                          and r["relative_spread"] == EVENT_SPREADS[0]
                          and r["run_length"] == RUN_LENGTHS[-1]]
                ax.loglog([r["N"] for r in picked], [r[key] for r in picked], "o" + style,
                          color=f"C{i}", label=f"K/K* = {factor}")
        for ax, name in ((ax3, "onset: largest drop / peak force"),
                         (ax4, "late window: largest drop / mean force")):
            ax.axhline(0.05, color="k", ls=":", label="threshold")
            ax.set_xlabel("N")
            ax.set_ylabel(name)
            ax.set_title(f"slow spring drive, σ = {EVENT_SPREADS[0]} x_c", fontsize=9)
        ax3.legend(fontsize=7)
    else:
        ax3.set_visible(False)
        ax4.set_visible(False)
    save(fig, path, dpi=120)


if __name__ == "__main__":
    main()
