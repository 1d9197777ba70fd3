"""Which theory reaches a given accuracy of the creep force first: FASTSIM or finite elements.

The same case for both — the wheel-rail ellipse of the issue (a = 6.304 mm along the rolling
direction, b = 12.61 mm, G = 82 GPa, ν = 0.28, Fn = 106.7 kN, μ = 0.3) — at the creepages
``CREEPAGES``: ξ = 1e-6 (the linear theory's full adhesion), 5e-4, 1e-3 and 2e-3 (partial slip,
adhesion 80 % to 20 % of the area).

* **FASTSIM** (Kalker's simplified theory) on n × n grids (``--grids``): wall time of one call
  (best of ``--repeats``).
* **Finite elements** (Kalker's complete theory, :class:`fenicsfriction.studies.rolling.
  RollingContact`: block of 10 a, cells growing by 1.5) at ``--cells`` cells per a, each with
  the ε sequence (10, 1, 0.1, 0.01) × the creepage: wall time of the whole sequence at each
  creepage (the mesh and the forms built once per mesh are counted apart, ``setup_s``).

**The reference** is the complete theory's exact creep force, which no closed form gives
between the linear theory and saturation. At ξ = 1e-6 it is Kalker's linear theory
(−G ab C11 ξ, Kalker 1990, Table E.3, three digits); at the other creepages the finest mesh,
whose own error is estimated by the relative change from the second finest (reported as
``reference_uncertainty``). Each method's error is |Fx/Fx_ref − 1| at each creepage, with
each force in partial slip normalised by its method's own discrete normal load (the nodal
rule integrates Hertz's pressure slightly low on coarse meshes, the midpoint rule slightly
high; in full adhesion the force does not depend on the load and is compared as it is), the
largest over the curve reported against the wall time for the whole curve.

Writes ``bench_rolling_methods.json`` and ``bench_rolling_methods.png`` (largest error
against time, log-log) to ``--out`` and prints markdown tables. Serial; about 2 minutes with
the defaults (the a/6 mesh dominates: 51 s of its creep curve).
"""

from __future__ import annotations

import sys
import time

from mpi4py import MPI

from _common import best_time, save, write_summary
from _common import parser as benchmark_parser

from fenicsfriction.studies.rolling import RollingContact
from fenicsfriction.studies.rolling.fastsim import fastsim, linear_theory

CASE = {"a": 6.304e-3, "b": 12.61e-3, "G": 82e9, "nu": 0.28, "mu": 0.3, "Fn": 106.7e3}
CREEPAGES = (1e-6, 5e-4, 1e-3, 2e-3)
EPS = (10.0, 1.0, 0.1, 0.01)


def _normalised(Fx: float, Fn: float) -> float:
    return -Fx / (CASE["mu"] * Fn)


def fastsim_rows(grids: list[int], repeats: int) -> list[dict]:
    rows = []
    for n in grids:
        curve, raw, seconds = [], [], 0.0
        for xi in CREEPAGES:
            # the FE model's normal pressure is Hertz's: FASTSIM with the same (ellipsoidal) bound
            best, result = best_time(lambda xi=xi, n=n: fastsim(**CASE, xi=xi, nx=n, ny=n,
                                                                pressure="ellipsoidal"), repeats)
            seconds += best
            curve.append(_normalised(result.Fx, result.Fn))
            raw.append(result.Fx)
        rows.append({"method": "fastsim", "n": n, "force": curve, "Fx": raw, "time_s": seconds})
        print(f"  FASTSIM {n} × {n}: {seconds * 1e3:.2f} ms", file=sys.stderr, flush=True)
    return rows


def fe_rows(cells: list[int], comm: MPI.Comm) -> list[dict]:
    rows = []
    for n in cells:
        t0 = time.perf_counter()
        scene = RollingContact(dim=3, block_size=10.0, growth=1.5, cells_per_a=n,
                               eps_sequence=EPS, **{k: v for k, v in CASE.items() if k != "mu"}
                               ).with_law(mu=CASE["mu"])
        model = scene.build(comm)
        setup = time.perf_counter() - t0
        results = model.creep_curve([(xi, 0.0, 0.0) for xi in CREEPAGES])
        rows.append({"method": "fe", "cells_per_a": n, "dofs": model.dofs, "setup_s": setup,
                     "force": [_normalised(r.Fx, r.Fn) for r in results],
                     "Fx": [r.Fx for r in results],
                     "newton_iterations": [r.newton_iterations for r in results],
                     "time_s": sum(r.wall_time_s for r in results)})
        print(f"  FE a/{n}: {model.dofs} dofs, {rows[-1]['time_s']:.1f} s "
              f"(+{setup:.1f} s set-up)", file=sys.stderr, flush=True)
    return rows


def reference(fe: list[dict]) -> tuple[list[float], list[float]]:
    """(reference normalised forces, their relative uncertainty) over ``CREEPAGES``."""
    slope = linear_theory(CASE["a"], CASE["b"], CASE["G"], CASE["nu"], xi=1.0).Fx
    finest, second = fe[-1]["force"], fe[-2]["force"]
    values = [_normalised(slope * CREEPAGES[0], CASE["Fn"]), *finest[1:]]
    # relative: the table's three digits; the change from the second finest mesh
    spread = [5e-3, *(abs(f / s - 1) for f, s in zip(finest[1:], second[1:], strict=True))]
    return values, spread


def errors(rows: list[dict], ref: list[float]) -> None:
    """Relative errors; in full adhesion (the first creepage) of the force itself, which does
    not depend on the normal load."""
    linear = linear_theory(CASE["a"], CASE["b"], CASE["G"], CASE["nu"], xi=CREEPAGES[0]).Fx
    for row in rows:
        row["errors"] = e = [abs(row["Fx"][0] / linear - 1)] + [
            abs(f / r - 1) for f, r in zip(row["force"][1:], ref[1:], strict=True)]
        row["largest_error"] = max(e)


def table(rows: list[dict]) -> str:
    lines = ["| method | resolution | " + " | ".join(f"ξ = {x:g}" for x in CREEPAGES)
             + " | largest | time for the curve [s] |",
             "|---|---|" + "---|" * len(CREEPAGES) + "---|---|"]
    for r in rows:
        resolution = (f"{r['n']} × {r['n']}" if r["method"] == "fastsim"
                      else f"a/{r['cells_per_a']} ({r['dofs']} dofs)")
        lines.append(f"| {r['method']} | {resolution} | "
                     + " | ".join(f"{e:.2e}" for e in r["errors"])
                     + f" | {r['largest_error']:.2e} | {r['time_s']:.3g} |")
    return "\n".join(lines)


def plot(fastsim: list[dict], fe: list[dict], path, dpi: int) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    ax.loglog([r["time_s"] for r in fastsim], [r["largest_error"] for r in fastsim], "o-",
              label="FASTSIM (grid n × n)")
    ax.loglog([r["time_s"] for r in fe[:-1]], [r["largest_error"] for r in fe[:-1]], "s-",
              label="finite elements (cells per a)")
    for r in fastsim[::2]:
        ax.annotate(f"{r['n']}", (r["time_s"], r["largest_error"]), fontsize=7)
    for r in fe[:-1]:
        ax.annotate(f"a/{r['cells_per_a']}", (r["time_s"], r["largest_error"]), fontsize=7)
    ax.set(xlabel="wall time for the 4-point creep curve [s]",
           ylabel="largest relative error of Fx",
           title="creep force: simplified vs complete theory")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    save(fig, path, dpi)


def main() -> int:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--grids", default="5,10,20,40,80,160")
    flags.add_argument("--cells", default="3,4,6",
                       help="finite element meshes, cells per a (the last is the reference)")
    flags.add_argument("--repeats", type=int, default=5)
    flags.add_argument("--dpi", type=int, default=110)
    args = flags.parse_args()
    comm = MPI.COMM_WORLD
    grids = [int(n) for n in args.grids.split(",")]
    cells = [int(n) for n in args.cells.split(",")]
    if len(cells) < 2:
        flags.error("--cells needs at least two meshes (the finest is the reference)")
    fs = fastsim_rows(grids, args.repeats)
    fe = fe_rows(cells, comm)
    ref, spread = reference(fe)
    errors(fs, ref)
    errors(fe, ref)
    summary = {"case": CASE, "creepages": CREEPAGES, "eps_relative": EPS, "reference": ref,
               "reference_uncertainty": spread, "fastsim": fs, "fe": fe}
    if comm.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        plot(fs, fe, args.out / "bench_rolling_methods.png", args.dpi)
        print("reference Fx/(μFn):", ", ".join(f"{r:.4f} ± {s:.1e}"
                                               for r, s in zip(ref, spread, strict=True)))
        print(table(fs + fe[:-1]))
    write_summary(args.out / "bench_rolling_methods.json", summary, comm)
    return 0


if __name__ == "__main__":
    sys.exit(main())
