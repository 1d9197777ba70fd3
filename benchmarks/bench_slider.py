"""The elastic slider on EQ contacts: its cost per simulated front, against mesh and time step.

The scene of :mod:`fenicsfriction.studies.multicontact` (a 10 cm × 1 cm slider, E = 1 GPa,
plane strain; EQ contacts of threshold 1 μm ± 5 %, re-forming relaxed after 0.1 ms; pushed at
1 mm/s at its trailing edge) run to 4 ms, through the precursors to the front that spans the base,
on the meshes ``--meshes`` (nx × ny) and steps ``--steps``. For each run: the wall time, the time
steps, the breaks and fronts, the wall time per front and per step, and the observables whose
convergence the time per front buys: the first break's time and push force, the peak push force
and the slip force (the push force when the first front spans the base). Same-run baseline: each
run's time per step over the coarsest run's.

Writes ``bench_slider.json`` and ``bench_slider.png`` (time per front against the front count;
the slip force against the time step) to ``--out``. Serial or under MPI (the history is the same
on any number of ranks). About a minute with the defaults.
"""

from __future__ import annotations

import sys
import time

from mpi4py import MPI

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction.studies.multicontact import ElasticSlider, ElasticSliderModel

T_END = 4e-3


def run(nx: int, ny: int, dt: float, comm: MPI.Comm) -> dict:
    scene = ElasticSlider(nx=nx, ny=ny, spread=0.05, delay=1e-4, push_speed=1e-3, seed=3)
    model = ElasticSliderModel(scene, comm)
    t0 = time.perf_counter()
    history = model.run(T_END, dt)
    seconds = time.perf_counter() - t0
    steps = len(history.time) - 1
    fronts = len(history.fronts)
    return {"nx": nx, "ny": ny, "dt": dt, "ranks": comm.size, "wall_time_s": seconds,
            "steps": steps, "breaks": len(history.breaks), "fronts": fronts,
            "arrested_fronts": sum(f.arrested for f in history.fronts),
            "time_per_front_s": seconds / max(fronts, 1), "time_per_step_s": seconds / steps,
            "first_break_time": history.breaks[0].time if history.breaks else None,
            "first_break_force": (history.fronts[0].push_force if history.fronts else None),
            "peak_force": float(np.max(history.push_force)),
            "slip_force": history.slip_force}


def main() -> int:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--meshes", default="20x2,40x4", help="nx x ny, comma-separated")
    flags.add_argument("--steps", default="2e-6,1e-6", help="time steps [s], comma-separated")
    flags.add_argument("--dpi", type=int, default=110)
    args = flags.parse_args()
    comm = MPI.COMM_WORLD
    rows = []
    for mesh in args.meshes.split(","):
        nx, ny = (int(v) for v in mesh.split("x"))
        for dt in (float(v) for v in args.steps.split(",")):
            rows.append(run(nx, ny, dt, comm))
            if comm.rank == 0:
                r = rows[-1]
                print(f"  {nx} x {ny}, dt {dt:g}: {r['wall_time_s']:.1f} s, {r['fronts']} fronts, "
                      f"{r['time_per_front_s']:.3f} s per front", file=sys.stderr, flush=True)
    base = rows[0]["time_per_step_s"]
    for r in rows:
        r["time_per_step_over_coarsest"] = r["time_per_step_s"] / base
    if comm.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        print("| mesh | dt | steps | fronts (arrested) | wall time | per front | per step "
              "(/ coarsest) | first break: t, force | peak force | slip force |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for r in rows:
            print(f"| {r['nx']} × {r['ny']} | {r['dt']:g} | {r['steps']} | {r['fronts']} "
                  f"({r['arrested_fronts']}) | {r['wall_time_s']:.1f} s | "
                  f"{r['time_per_front_s']:.3f} s | {1e3 * r['time_per_step_s']:.2f} ms "
                  f"({r['time_per_step_over_coarsest']:.2f}) | "
                  f"{1e3 * r['first_break_time']:.3f} ms, {r['first_break_force']:.0f} N/m | "
                  f"{r['peak_force']:.0f} N/m | {r['slip_force']:.0f} N/m |")
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 3.8))
        for mesh in sorted({(r["nx"], r["ny"]) for r in rows}):
            sel = [r for r in rows if (r["nx"], r["ny"]) == mesh]
            a1.plot([r["fronts"] for r in sel], [r["time_per_front_s"] for r in sel], "o-",
                    label=f"{mesh[0]} × {mesh[1]}")
            a2.plot([r["dt"] for r in sel], [r["slip_force"] for r in sel], "o-",
                    label=f"{mesh[0]} × {mesh[1]}")
        a1.set(xlabel="fronts simulated", ylabel="wall time per front [s]")
        a2.set(xscale="log", xlabel="time step [s]", ylabel="slip force [N/m]")
        a1.legend(fontsize=8)
        save(fig, args.out / "bench_slider.png", args.dpi)
    write_summary(args.out / "bench_slider.json", {"t_end": T_END, "rows": rows}, comm)
    return 0


if __name__ == "__main__":
    sys.exit(main())
