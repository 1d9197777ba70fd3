"""Coupled Newton against the Panagiotopoulos process and Johnson's step; symmetry; mollification.

Four studies (Kalker 1986, sections 3-4 and eq. 27):

* **block** — steady sliding of the block on the belt (Martins & Oden 1986's data, Q2,
  ``--refine``; ``--scene block-on-slab``: Q1 on an elastic slab, the friction bound then in
  the two-body contact coupling's forms), μ from 0 to just below the discrete tipping limit:
  for each method (:class:`fenicsfriction.panagiotopoulos.PanagiotopoulosSolver`, every solve
  from the same initial guess) the outer and Newton iterations, the wall time (median of
  ``--repeats``), the contraction factor of the process (geometric mean of its change ratios)
  and the error of the contact penetrations against Newton's (max over the nodes, relative
  to the largest);
* **layered** — the same block on a soft layer (E/1000, ν = 0 or 0.25; spring at H/12, so
  the tipping limit is 9.6): the μ where the process stops converging (bisection to
  ``--mu-tol`` with at most 200 outer iterations), against 1/β, β = (1 - 2ν)/(2(1 - ν)) the
  layer's second Dundurs constant against the rigid belt; Newton at the same μ;
* **de_pater** — the Cattaneo scene (cylinder on block, Q = μP/2), coupled Newton: the shift
  of the pressure centroid under Q (in units of the half-width a) and the relative L2 change
  of the pressure, for identical bodies (one and two passes), a β = 0 pair of different
  materials and pairs with β ≠ 0;
* **mollified** — the block in Q1 with the nodal contact rule (``--refine-mollified``), μ =
  1.2: the mollified law (Oden & Pires 1983) against the local one, at the loaded corner
  (penetration, local and mollified bound) and over Γ_C, for radii r = 0 .. L/4.

Writes ``bench_panagiotopoulos.json`` and ``bench_panagiotopoulos.png`` to ``--out`` and
prints markdown tables (rank 0). About 2 minutes serially with the defaults.
"""

from __future__ import annotations

import logging
import statistics
import sys

from mpi4py import MPI

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

import fenicsfriction as ff
from fenicsfriction.panagiotopoulos import PanagiotopoulosSolver, ProcessError
from fenicsfriction.studies.block import LayeredBlockOnBelt
from fenicsfriction.studies.block.slab import SCENES
from fenicsfriction.studies.contact import closed_forms
from fenicsfriction.studies.contact.validation import Cattaneo

METHODS = ("newton", "panagiotopoulos", "johnson")
log = logging.getLogger("bench_panagiotopoulos")


def _penetrations(model, comm: MPI.Comm) -> np.ndarray:
    return np.concatenate(comm.allgather(model.nodal_contact()[0]))


def _run(model, solver, mu: float, comm: MPI.Comm) -> tuple[dict, np.ndarray]:
    model.mu.value = mu
    model.initial_guess()
    try:
        report = solver.solve()
    except ProcessError as err:
        report = err.report
    return ({"outer": report.outer_iterations, "newton": report.newton_iterations,
             "time_s": report.wall_time_s, "converged": report.converged,
             "changes": report.changes}, _penetrations(model, comm))


def _contraction(changes: list[float]) -> float | None:
    """Geometric mean of the ratios of successive changes after the first (frictionless)."""
    c = np.array(changes[1:])
    c = c[c > 0]
    return float(np.exp(np.mean(np.diff(np.log(c))))) if len(c) > 2 else None


def block_study(comm: MPI.Comm, refine: int, repeats: int, scene_name: str = "block") -> dict:
    scene = SCENES[scene_name](refine=refine)
    model = scene.build(comm, with_friction=True)
    solvers = {m: PanagiotopoulosSolver(model.residual, method=m, prefix=f"bench_{m}_",
                                        options=model.solver_options(),
                                        parameters={"mu": model.mu}) for m in METHODS}
    limit = scene.discrete_tipping_limit
    mus = [*np.round(np.arange(0.0, limit, 0.1), 10), 0.99 * limit]
    rows = []
    for mu in mus:
        row: dict = {"mu": float(mu)}
        d_newton = None
        for method, solver in solvers.items():
            runs = [_run(model, solver, mu, comm) for _ in range(repeats)]
            result, d = runs[-1]
            result["time_s"] = statistics.median(r[0]["time_s"] for r in runs)
            if method == "newton":
                d_newton = d
            else:
                assert d_newton is not None
                result["error"] = float(np.abs(d - d_newton).max() / d_newton.max())
                result["contraction"] = _contraction(result["changes"])
            row[method] = result
        rows.append(row)
        log.info("block mu %.3f: %s", mu, {m: (row[m]["outer"], row[m]["newton"])
                                           for m in METHODS})
    return {"scene": scene_name, "refine": refine,
            "dofs": model.V.dofmap.index_map.size_global * 2,
            "tipping_limit": scene.tipping_limit, "discrete_tipping_limit": limit,
            "rows": rows}


def layered_study(comm: MPI.Comm, layer_nu: float, mu_tol: float) -> dict:
    scene = LayeredBlockOnBelt(layer_nu=layer_nu, spring_height=30.5 / 12)
    beta = (1 - 2 * layer_nu) / (2 * (1 - layer_nu))
    model = scene.build(comm, with_friction=True)
    newton, process = (PanagiotopoulosSolver(model.residual, method=m, prefix=f"layer_{m}_",
                                             options=model.solver_options(),
                                             max_iterations=200, patience=4,
                                             parameters={"mu": model.mu})
                       for m in ("newton", "panagiotopoulos"))
    sweep = []
    for ratio in (0.25, 0.5, 0.75, 0.9, 1.1, 1.5, 2.0):
        result, _ = _run(model, process, ratio / beta, comm)
        newton_result, _ = _run(model, newton, ratio / beta, comm)
        sweep.append({"mu": ratio / beta, "mu_beta": ratio, "process": result,
                      "newton": newton_result})
    converged = [r["mu"] for r in sweep if r["process"]["converged"]]
    failed = [r["mu"] for r in sweep if not r["process"]["converged"]]
    low, high = max(converged), min(m for m in failed if m > max(converged))
    while high - low > mu_tol:
        mid = (low + high) / 2
        result, _ = _run(model, process, mid, comm)
        low, high = (mid, high) if result["converged"] else (low, mid)
    return {"layer_nu": layer_nu, "layer_E": scene.layer_E, "beta": beta,
            "inverse_beta": 1 / beta, "process_limit": (low + high) / 2,
            "discrete_tipping_limit": scene.discrete_tipping_limit, "sweep": sweep}


def de_pater_study(comm: MPI.Comm, h_contact: float) -> list[dict]:
    beta_zero = 2 * (2 / 2.6) * 1.1  # E2 with ν2 = 0.1 whose (1 - 2ν)/G is body 1's
    cases = [("identical", {}), ("identical, 2 passes", {"passes": 2}),
             ("beta = 0, different", {"E2": beta_zero, "nu2": 0.1}),
             ("nu2 = 0.45", {"nu2": 0.45}), ("nu2 = 0", {"nu2": 0.0}),
             ("E2 = 3", {"E2": 3.0})]
    rows = []
    for name, materials in cases:
        scene = Cattaneo(increments=2, q_ratio=0.5, h_contact=h_contact, **materials)
        a, _ = scene.closed_form()
        row = {"case": name, "beta": closed_forms.dundurs_beta(scene.E1, scene.nu1, scene.E2,
                                                               scene.nu2), **materials}
        try:
            _, model = scene.load_normal(comm)
            before = model.surface_values()
            scene.load_tangential(model)
            after = model.surface_values()
        except (RuntimeError, ff.SolveError) as err:
            rows.append({**row, "failed": str(err)})
            continue
        w = before.weight

        def centroid(v, w=w):
            return float((w * v.pressure * v.x[:, 0]).sum() / (w * v.pressure).sum())

        rows.append({**row, "dofs": model.dofs, "centroid_shift_over_a":
                     (centroid(after) - centroid(before)) / a,
                     "pressure_change_l2": float(np.sqrt(
                         (w * (after.pressure - before.pressure) ** 2).sum()
                         / (w * before.pressure**2).sum()))})
        log.info("de Pater %s: %s", name, rows[-1])
    return rows


def mollified_study(comm: MPI.Comm, refines: list[int]) -> list[dict]:
    rows = []
    for refine in refines:
        scene = ff.BlockOnBelt(degree=1, contact_quadrature="nodal", refine=refine)
        model = scene.build(comm, with_friction=True)
        options = model.solver_options()
        newton = PanagiotopoulosSolver(model.residual, method="newton", prefix="moll_newton_",
                                       options=options)
        _, local = _run(model, newton, 1.2, comm)
        corner = int(np.argmax(local))
        h = scene.L / (4 * refine)
        for fraction in (0.0, 1 / 32, 1 / 16, 1 / 8, 1 / 4):
            r = fraction * scene.L
            if 0 < r <= h:
                continue
            process = PanagiotopoulosSolver(model.residual, mollification_radius=r,
                                            prefix="moll_", options=options)
            result, d = _run(model, process, 1.2, comm)
            row = {"refine": refine, "h": h, "radius": r, "radius_over_L": fraction,
                   "outer": result["outer"], "converged": result["converged"],
                   "corner_penetration": float(d[corner]),
                   "local_corner_penetration": float(local[corner]),
                   "max_change": float(np.abs(d - local).max() / local.max())}
            if r > 0:
                x, bound, mollified = process.nodal_bound()
                i = np.argmin(np.abs(x[:, 0]))  # the loaded corner is at x = 0
                both = comm.allgather((abs(x[i, 0]), bound[i], mollified[i]) if len(x)
                                      else (np.inf, 0.0, 0.0))
                _, row["corner_bound"], row["corner_mollified_bound"] = min(both)
            rows.append(row)
            log.info("mollified %s", row)
    return rows


def plot(block: dict, layered: list[dict], path, dpi: int) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    mu = [r["mu"] for r in block["rows"]]
    for method, style in zip(METHODS, ("o-", "s--", "^:"), strict=True):
        axes[0, 0].plot(mu, [r[method]["newton"] for r in block["rows"]], style,
                        label=f"{method}: Newton iterations")
        axes[0, 1].semilogy(mu, [r[method]["time_s"] for r in block["rows"]], style,
                            label=method)
    axes[0, 0].plot(mu, [r["panagiotopoulos"]["outer"] for r in block["rows"]], "kx-",
                    label="process: outer iterations")
    axes[0, 0].set(xlabel="μ", ylabel="iterations",
                   title=f"{block['scene']} (tipping limit {block['discrete_tipping_limit']:.3f})")
    axes[0, 0].legend(fontsize=7)
    axes[0, 1].set(xlabel="μ", ylabel="wall time [s]", title="Wall time per solve")
    axes[0, 1].legend(fontsize=7)
    for method, style in (("panagiotopoulos", "s--"), ("johnson", "^:")):
        axes[1, 0].semilogy(mu[1:], [max(r[method]["error"], 1e-16) for r in block["rows"][1:]],
                            style, label=method)
    axes[1, 0].set(xlabel="μ", ylabel="max |d - d_Newton| / max d",
                   title="Error of the contact penetrations")
    axes[1, 0].legend(fontsize=7)
    for study, style in zip(layered, ("o-", "s-"), strict=True):
        rows = study["sweep"]
        axes[1, 1].plot([r["mu_beta"] for r in rows], [r["process"]["outer"] for r in rows],
                        style, label=f"layer ν = {study['layer_nu']} (limit μβ = "
                                     f"{study['process_limit'] * study['beta']:.2f})")
    axes[1, 1].axvline(1.0, color="k", lw=0.8)
    axes[1, 1].set(xlabel="μβ", ylabel="outer iterations (200: no convergence)",
                   title="Layered block: the process's limit")
    axes[1, 1].legend(fontsize=7)
    save(fig, path, dpi)


def main() -> int:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--refine", type=int, default=2, help="block mesh refinement (2)")
    flags.add_argument("--scene", choices=tuple(SCENES), default="block",
                       help="the block study's scene (block: on the rigid belt)")
    flags.add_argument("--repeats", type=int, default=3, help="timed runs per solve (3)")
    flags.add_argument("--mu-tol", type=float, default=0.02,
                       help="bisection tolerance of the process's limit (0.02)")
    flags.add_argument("--h-contact", type=float, default=0.01,
                       help="Cattaneo mesh size at the contact (0.01)")
    flags.add_argument("--refine-mollified", default="4,8", help="Q1 block meshes (4,8)")
    flags.add_argument("--dpi", type=int, default=110)
    args = flags.parse_args()
    comm = MPI.COMM_WORLD
    logging.getLogger("ffcx").setLevel(logging.WARNING)
    logging.basicConfig(level=logging.INFO, stream=sys.stderr,
                        format="%(name)s: %(message)s")
    block = block_study(comm, args.refine, args.repeats, args.scene)
    layered = [layered_study(comm, nu, args.mu_tol) for nu in (0.0, 0.25)]
    de_pater = de_pater_study(comm, args.h_contact)
    mollified = mollified_study(comm, [int(v) for v in args.refine_mollified.split(",") if v])
    if comm.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        print("| μ | Newton its | process outer/inner | Johnson inner | time N/P/J [ms] "
              "| contraction | error process | error Johnson |\n|---|---|---|---|---|---|---|---|")
        for r in block["rows"]:
            n, p, j = r["newton"], r["panagiotopoulos"], r["johnson"]
            c = "-" if p["contraction"] is None else f"{p['contraction']:.3f}"
            print(f"| {r['mu']:.3f} | {n['newton']} | {p['outer']}/{p['newton']}"
                  f"{'' if p['converged'] else ' (failed)'} | {j['newton']} | "
                  f"{1e3 * n['time_s']:.1f}/{1e3 * p['time_s']:.1f}/{1e3 * j['time_s']:.1f} | "
                  f"{c} | {p['error']:.1e} | {j['error']:.1e} |")
        print("\n| layer ν | β | 1/β | process limit μ | Newton (from the guess) converged at "
              "μβ |\n|---|---|---|---|---|")
        for s in layered:
            newton = ", ".join(f"{r['mu_beta']:g}" for r in s["sweep"]
                               if r["newton"]["converged"])
            print(f"| {s['layer_nu']} | {s['beta']:.3f} | {s['inverse_beta']:.3f} | "
                  f"{s['process_limit']:.3f} | {newton} |")
        print("\n| case | β | centroid shift / a | pressure change (L2) |\n|---|---|---|---|")
        for r in de_pater:
            if "failed" in r:
                print(f"| {r['case']} | {r['beta']:.4f} | failed | {r['failed'][:60]} |")
            else:
                print(f"| {r['case']} | {r['beta']:.4f} | {r['centroid_shift_over_a']:.3e} | "
                      f"{r['pressure_change_l2']:.3e} |")
        print("\n| refine | r/L | r/h | outer | corner d / local | corner bound local → "
              "mollified | max change of d |\n|---|---|---|---|---|---|---|")
        for r in mollified:
            bound = (f"{r['corner_bound']:.3f} → {r['corner_mollified_bound']:.3f}"
                     if "corner_bound" in r else "-")
            print(f"| {r['refine']} | {r['radius_over_L']:.4f} | {r['radius'] / r['h']:.2f} | "
                  f"{r['outer']} | {r['corner_penetration'] / r['local_corner_penetration']:.4f}"
                  f" | {bound} | {r['max_change']:.2e} |")
        plot(block, layered, args.out / "bench_panagiotopoulos.png", args.dpi)
    write_summary(args.out / "bench_panagiotopoulos.json",
                             {"ranks": comm.size, "block": block, "layered": layered,
                              "de_pater": de_pater, "mollified": mollified}, comm=comm)
    return 0


if __name__ == "__main__":
    sys.exit(main())
