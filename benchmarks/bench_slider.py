"""The elastic slider on EQ contacts: its peak (static) and slip forces converged in time step
and mesh, with the observed orders and Richardson's estimate, and its fronts' speeds.

The scene of :mod:`fenicsfriction.studies.multicontact.slider` (a 10 cm × 1 cm slider,
E = 1 GPa, plane strain; EQ contacts of threshold 1 μm, re-forming relaxed after 0.1 ms;
pushed at 1 mm/s at its trailing edge) run to 4.6 ms, through the precursors to the front that
spans the base. Two refinements of three levels each: the time step ``--steps`` on the mesh
``--dt-mesh``, and the mesh ``--meshes`` (nx × ny, each halving h) at the step ``--mesh-dt``.

What makes the quantities converge (``--viscosity``, ``--spread``, ``--patches``):

* every break radiates waves; undamped (generalized-α at spectral radius 1 keeps them all),
  they ring at ±30 N/m in the push force forever, the peak force is the largest of that noise
  and the contacts near their thresholds break on its crests: a Kelvin-Voigt relaxation time
  τ (``--viscosity``, default 2 µs: a 2 mm shear wave has ωτ/2 ≈ 2, overdamped; the
  slider's first modes ωτ/2 ≈ 0.01) makes them decay, a physical model whose limit exists;
* random thresholds drawn per node are a different realisation on every mesh: ``--spread 0``
  (default: all thresholds x̄_s) or thresholds shared by ``--patches`` patches of the base
  (the same realisation on every mesh), averaged over ``--seeds`` realisations.

For each run: the first break's time and force, the pusher force when the front (the
furthest broken contact) reaches L/4 and L/2, the peak force, the slip force (when the
far-edge contact first breaks), the fronts' largest speed under the causal grouping
(:func:`~fenicsfriction.studies.multicontact.slider.fronts`, bounded by c_p) and under the
time gap alone, wall time. For each quantity and each refinement: the observed order
p = log₂(|q₁ − q₂| / |q₂ − q₃|) and q₃ + (q₃ − q₂) / (2ᵖ − 1) (Richardson 1911; Roache 1998,
*Verification and Validation in Computational Science and Engineering*), ``nan`` where the
differences change sign.

``--ensemble`` (with ``--spread`` > 0, ``--patches`` and ``--seeds``): the random-threshold
study, whose converged quantity is the mean over realisations (one realisation's cascade
order flips with Δt and h). Seed by seed, every level of both refinements, each run appended
to ``bench_slider_ensemble.jsonl`` as it ends (a partial study is usable, a rerun resumes);
then ``bench_slider_ensemble.json``: per level the mean ± standard error s/√n, and the
observed order and Richardson's estimate of the means only where both differences between
levels, paired by seed, exceed twice their standard error (else "within noise"). One
process: about 3 minutes a seed.

Writes ``bench_slider.json`` and ``bench_slider.png`` (push force against time, per level) to
``--out``. Serial or under MPI (the history is the same on any number of ranks). About 4
minutes with the defaults on the shared 2-core machine (the 80 × 8 mesh 1.6 min, 0.5 µs on
40 × 4 1.3 min); ``--meshes 40x4,80x8,160x16 --steps ""`` (the mesh study one level finer)
takes 19 min (160 × 16: 15 min).
"""

from __future__ import annotations

import json
import math
import pathlib
import sys
import time

from mpi4py import MPI

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction.studies.multicontact import ElasticSlider, ElasticSliderModel, fronts

T_END = 4.6e-3
QUANTITIES = ("first_break_force", "force_at_quarter", "force_at_half", "peak_force",
              "slip_force", "slip_time")


def _force_when_front_reaches(history, x: float) -> float:
    position = np.nan_to_num(np.array(history.front_position), nan=-1.0)
    reached = np.flatnonzero(position >= x - 1e-12)
    return float(history.push_force[reached[0]]) if len(reached) else float("nan")


def run(nx: int, ny: int, dt: float, seed: int, args, comm: MPI.Comm) -> dict:
    scene = ElasticSlider(nx=nx, ny=ny, spread=args.spread, delay=1e-4, push_speed=1e-3,
                          seed=seed, patches=args.patches, viscosity=args.viscosity)
    model = ElasticSliderModel(scene, comm)
    t0 = time.perf_counter()
    history = model.run(T_END, dt)
    seconds = time.perf_counter() - t0
    c_p, c_s = scene.wave_speeds
    position = np.nan_to_num(np.array(history.front_position), nan=-1.0)
    spanned = np.flatnonzero(position >= scene.L - 0.5 * scene.h)
    by_gap = fronts(history.breaks, lambda t: 0.0, 5 * dt, scene.L - 0.5 * scene.h)

    def fastest(found) -> float:
        return max((f.speed for f in found if np.isfinite(f.speed)), default=float("nan"))

    return {"nx": nx, "ny": ny, "dt": dt, "seed": seed, "ranks": comm.size,
            "wall_time_s": seconds, "steps": len(history.time) - 1,
            "breaks": len(history.breaks), "fronts": len(history.fronts),
            "arrested_fronts": sum(f.arrested for f in history.fronts),
            "first_break_time": history.breaks[0].time,
            "first_break_force": _force_when_front_reaches(history, 0.0),
            "force_at_quarter": _force_when_front_reaches(history, 0.25 * scene.L),
            "force_at_half": _force_when_front_reaches(history, 0.5 * scene.L),
            "peak_force": history.peak_force, "slip_force": history.slip_force,
            "slip_time": history.time[spanned[0]] if len(spanned) else float("nan"),
            "fastest_front_causal": fastest(history.fronts),
            "fastest_front_by_gap": fastest(by_gap), "c_p": c_p, "c_s": c_s,
            "time": history.time, "push_force": history.push_force}


def richardson(q: list[float]) -> dict:
    """Observed order p and extrapolated value q₃ − (q₂ − q₃) / (2ᵖ − 1) of three levels
    q = q* + C hᵖ refined by 2 each; ``nan`` unless the differences keep their sign and
    shrink (observed p > 0.5), else the levels are not in the asymptotic range."""
    if len(q) != 3:
        return {"values": q, "order": float("nan"), "extrapolated": float("nan"),
                "monotone": False, "spread": max(q, default=0.0) - min(q, default=0.0)}
    d1, d2 = q[0] - q[1], q[1] - q[2]
    p = math.log2(d1 / d2) if d1 * d2 > 0 else float("nan")
    converging = math.isfinite(p) and p > 0.5  # below: not yet in the asymptotic range
    return {"values": q, "order": p, "extrapolated": q[2] - d2 / (2**p - 1) if converging
            else float("nan"), "monotone": d1 * d2 > 0, "spread": max(q) - min(q)}


def _ensemble_levels(args) -> list[tuple[int, int, float]]:
    """The ensemble study's levels (nx, ny, dt), cheapest first: the time steps on
    ``--dt-mesh``, then the meshes at ``--mesh-dt`` (a level both studies share runs once)."""
    dt_mesh = tuple(int(v) for v in args.dt_mesh.split("x"))
    levels = [(dt_mesh[0], dt_mesh[1], float(dt)) for dt in args.steps.split(",") if dt]
    levels += [(int(m.split("x")[0]), int(m.split("x")[1]), args.mesh_dt)
               for m in args.meshes.split(",")]
    unique = list(dict.fromkeys(levels))
    return sorted(unique, key=lambda lv: lv[0] * lv[1] / lv[2])


def ensemble_statistics(rows: list[dict], levels: list[tuple[int, int, float]],
                        quantity: str) -> dict:
    r"""Mean and standard error :math:`s/\sqrt n` of ``quantity`` over the seeds run at each
    of three ``levels``, and the differences between neighbouring levels paired by seed (the
    same realisation on every level: the realisations' own scatter cancels), each with its
    standard error. The observed order and Richardson's estimate of the means only where both
    paired differences exceed twice their standard error; else ``nan`` and ``within_noise``:
    a difference smaller than its own noise says nothing about the order. The means and the
    differences are over the seeds run at every level."""
    def values(level: tuple[int, int, float]) -> dict[int, float]:
        return {r["seed"]: float(r[quantity]) for r in rows
                if (r["nx"], r["ny"], r["dt"]) == level and np.isfinite(r[quantity])}

    per_level = [values(lv) for lv in levels]
    seeds = sorted(set.intersection(*(set(v) for v in per_level))) if per_level else []
    table = np.array([[v[seed] for seed in seeds] for v in per_level])  # levels x seeds
    n = len(seeds)

    def error(x: np.ndarray) -> float:
        return float(np.std(x, ddof=1) / math.sqrt(n)) if n > 1 else float("nan")

    means = [float(np.mean(row)) if n else float("nan") for row in table]
    differences = [table[i] - table[i + 1] for i in range(len(levels) - 1)]
    noise = [error(d) for d in differences]
    resolved = len(levels) == 3 and n > 1 and all(
        abs(float(np.mean(d))) > 2 * e for d, e in zip(differences, noise, strict=True))
    fit = richardson(means) if resolved else {"order": float("nan"),
                                              "extrapolated": float("nan")}
    return {"levels": [list(lv) for lv in levels], "seeds": seeds, "mean": means,
            "standard_error": [error(row) for row in table],
            "difference": [float(np.mean(d)) if n else float("nan") for d in differences],
            "difference_error": noise, "within_noise": not resolved, "order": fit["order"],
            "extrapolated": fit["extrapolated"]}


def ensemble(args, comm: MPI.Comm) -> int:
    """The random-threshold study: every level for one seed, then the next seed, each run
    appended to ``bench_slider_ensemble.jsonl`` as it ends (a partial study is usable; a
    rerun skips the runs the file already holds), then the statistics per level."""
    seeds = [int(v) for v in args.seeds.split(",")]
    levels = _ensemble_levels(args)
    path = pathlib.Path(args.out) / "bench_slider_ensemble.jsonl"
    done: list[dict] = []
    if path.exists():
        done = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    scene_keys = {"spread": args.spread, "patches": args.patches, "viscosity": args.viscosity}

    def have(nx: int, ny: int, dt: float, seed: int) -> bool:
        return any((r["nx"], r["ny"], r["dt"], r["seed"]) == (nx, ny, dt, seed)
                   and all(r.get(k) == v for k, v in scene_keys.items()) for r in done)

    if comm.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
    for seed in seeds:
        for nx, ny, dt in levels:
            if have(nx, ny, dt, seed):
                continue
            r = run(nx, ny, dt, seed, args, comm)
            row = {**{k: v for k, v in r.items() if k not in ("time", "push_force")},
                   **scene_keys}
            done.append(row)
            if comm.rank == 0:
                with path.open("a") as stream:
                    stream.write(json.dumps(row) + "\n")
                print(f"  seed {seed}, {nx} x {ny}, dt {dt:g}: {r['wall_time_s']:.1f} s, "
                      f"peak {r['peak_force']:.1f}, slip {r['slip_force']:.1f} N/m",
                      file=sys.stderr, flush=True)
    rows = [r for r in done if all(r.get(k) == v for k, v in scene_keys.items())
            and r["seed"] in seeds]
    dt_mesh = tuple(int(v) for v in args.dt_mesh.split("x"))
    studies = {
        "time_step": [(dt_mesh[0], dt_mesh[1], float(dt)) for dt in args.steps.split(",") if dt],
        "mesh": [(int(m.split("x")[0]), int(m.split("x")[1]), args.mesh_dt)
                 for m in args.meshes.split(",")]}
    summary = {name: {q: ensemble_statistics(rows, lv, q) for q in QUANTITIES}
               for name, lv in studies.items()}
    if comm.rank == 0:
        print("| study | quantity | levels | seeds | mean ± standard error | paired differences "
              "| order, Richardson |")
        print("|---|---|---|---|---|---|---|")
        for name, table in summary.items():
            for q, s in table.items():
                cells = ", ".join(f"{m:.4g} ± {e:.2g}" for m, e in
                                  zip(s["mean"], s["standard_error"], strict=True))
                steps = ", ".join(f"{d:.3g} ± {e:.2g}" for d, e in
                                  zip(s["difference"], s["difference_error"], strict=True))
                fit = "within noise" if s["within_noise"] else \
                    f"p = {s['order']:.2f}, {s['extrapolated']:.4g}"
                print(f"| {name} | {q} | {', '.join(str(lv) for lv in s['levels'])} | "
                      f"{len(s['seeds'])} | {cells} | {steps} | {fit} |")
    write_summary(args.out / "bench_slider_ensemble.json",
                  {"t_end": T_END, **scene_keys, "seeds": seeds, "studies": summary,
                   "rows": rows}, comm)
    return 0


def main() -> int:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--meshes", default="20x2,40x4,80x8", help="three meshes nx x ny")
    flags.add_argument("--mesh-dt", type=float, default=1e-6, help="step of the mesh study [s]")
    flags.add_argument("--steps", default="2e-6,1e-6,5e-7", help="three time steps [s]")
    flags.add_argument("--dt-mesh", default="40x4", help="mesh of the time-step study")
    flags.add_argument("--viscosity", type=float, default=2e-6,
                       help="Kelvin-Voigt relaxation time [s] (0: undamped)")
    flags.add_argument("--spread", type=float, default=0.0, help="threshold spread δ")
    flags.add_argument("--patches", type=int, default=0, help="threshold patches (0: per node)")
    flags.add_argument("--seeds", default="3", help="threshold seeds, comma-separated")
    flags.add_argument("--ensemble", action="store_true",
                       help="the random-threshold ensemble study: per seed every level, "
                            "appended to bench_slider_ensemble.jsonl as it goes")
    flags.add_argument("--dpi", type=int, default=110)
    args = flags.parse_args()
    comm = MPI.COMM_WORLD
    if args.ensemble:
        return ensemble(args, comm)
    seeds = [int(v) for v in args.seeds.split(",")]
    meshes = [tuple(int(v) for v in m.split("x")) for m in args.meshes.split(",")]
    steps = [float(v) for v in args.steps.split(",") if v]
    dt_mesh = tuple(int(v) for v in args.dt_mesh.split("x"))
    runs: dict[tuple, list[dict]] = {}

    def level(nx: int, ny: int, dt: float) -> list[dict]:
        if (nx, ny, dt) not in runs:
            runs[nx, ny, dt] = [run(nx, ny, dt, seed, args, comm) for seed in seeds]
            if comm.rank == 0:
                for r in runs[nx, ny, dt]:
                    print(f"  {nx} x {ny}, dt {dt:g}, seed {r['seed']}: {r['wall_time_s']:.1f} s,"
                          f" peak {r['peak_force']:.1f}, slip {r['slip_force']:.1f} N/m",
                          file=sys.stderr, flush=True)
        return runs[nx, ny, dt]

    studies = {"time_step": [level(*dt_mesh, dt) for dt in steps if dt > 0],
               "mesh": [level(nx, ny, args.mesh_dt) for nx, ny in meshes]}
    summary = {name: {q: richardson([float(np.mean([r[q] for r in lv])) for lv in levels])
                      for q in QUANTITIES} for name, levels in studies.items()}
    for name, levels in studies.items():
        for q in QUANTITIES:
            summary[name][q]["seed_std"] = [float(np.std([r[q] for r in lv])) for lv in levels]
    rows = [{k: v for k, v in r.items() if k not in ("time", "push_force")}
            for lv in runs.values() for r in lv]
    worst = max(r["fastest_front_causal"] / r["c_p"] for r in rows)
    if comm.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        print("| run | wall | breaks | fronts (arrested) | first break F | F at L/4 | F at L/2 "
              "| peak F | slip F | slip t | fastest front: causal, by gap (/ c_p) |")
        print("|---|---|---|---|---|---|---|---|---|---|---|")
        for r in rows:
            print(f"| {r['nx']} × {r['ny']}, {r['dt'] * 1e6:g} µs, seed {r['seed']} | "
                  f"{r['wall_time_s']:.1f} s | {r['breaks']} | {r['fronts']} "
                  f"({r['arrested_fronts']}) | {r['first_break_force']:.1f} | "
                  f"{r['force_at_quarter']:.1f} | {r['force_at_half']:.1f} | "
                  f"{r['peak_force']:.1f} | {r['slip_force']:.1f} | "
                  f"{r['slip_time'] * 1e3:.4f} ms | {r['fastest_front_causal'] / r['c_p']:.2f}, "
                  f"{r['fastest_front_by_gap'] / r['c_p']:.2f} |")
        print("\n| study | quantity | three levels | observed order | Richardson |")
        print("|---|---|---|---|---|")
        for name, table in summary.items():
            for q, s in table.items():
                print(f"| {name} | {q} | {', '.join(f'{v:.4g}' for v in s['values'])} | "
                      f"{s['order']:.2f} | {s['extrapolated']:.4g} |")
        print(f"\nfastest causal front / c_p over all runs: {worst:.3f}")
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
        for ax, (name, levels) in zip(axes, studies.items(), strict=True):
            for lv in levels:
                r = lv[0]
                ax.plot(np.array(r["time"]) * 1e3, r["push_force"], lw=0.7,
                        label=f"{r['nx']} × {r['ny']}, {r['dt'] * 1e6:g} µs")
            ax.set(xlabel="t [ms]", title=f"{name.replace('_', ' ')} study", xlim=(1.0, 4.6))
            ax.legend(fontsize=8)
        axes[0].set(ylabel="push force [N/m]")
        save(fig, args.out / "bench_slider.png", args.dpi)
    write_summary(args.out / "bench_slider.json",
                  {"t_end": T_END, "viscosity": args.viscosity, "spread": args.spread,
                   "patches": args.patches, "seeds": seeds, "studies": summary,
                   "fastest_causal_front_over_c_p": worst, "rows": rows}, comm)
    return 0


if __name__ == "__main__":
    sys.exit(main())
