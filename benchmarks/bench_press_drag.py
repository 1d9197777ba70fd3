r"""Energy balance of the cylinder pressed and dragged: the energy-consistent step against
generalized-α.

The scene of ``PressAndDrag`` (the 2D cylinder on the block, h = 0.05 R at the contact,
a load P switched on at t = 0, a drag 1.5 μP from t = 1.5 to 2.5, the end at t = 3) is run
for ε ∈ {1e-3, 1e-4, 1e-5} and dt ∈ {0.02, 0.05}, with friction (μ = 0.3) and without (one
run per dt: ε does not enter), by

* ``energy``: the energy-consistent midpoint step (generalized-α at ρ∞ = 1 with the
  contact's pressure the discrete gradient of its potential, Gonzalez 1996; Laursen &
  Chawla 1997; Armero & Petőcz 1998, 1999), the default;
* ``alpha2``: the baseline, generalized-α at ρ∞ = 0.8 with the midpoint contact force and the
  trapezoidal rule on the dissipated power,

on the meshes of ``--h`` (default 0.05, the Debian 12 gmsh mesh of 1,286 unknowns, and 0.051,
a perturbed one: a slightly different mesh of the same sizes, as another gmsh release makes).
Each run reports ``energy_balance_error`` (the largest drift of kinetic + elastic + stored −
work + dissipated, over the largest work of the loads), the dissipated energy, the
cut-backs, Newton iterations and wall time; the ratios energy/alpha2 of the error and of the
wall time are measured in the same run. One more run per mesh at the default step (8 steps a
contact period, ``PressAndDrag.default_dt``) with friction at ε = 1e-3 (``--no-default-dt``
skips it; ``--schemes`` chooses the schemes).

Writes ``bench_press_drag.json`` and ``bench_press_drag.png`` (the balance error of every run,
both schemes) to ``--out`` and prints a markdown table. Serial.
"""

from __future__ import annotations

import logging
import warnings

from mpi4py import MPI

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction.studies.contact.impact import PressAndDrag

EPS = [1e-3, 1e-4, 1e-5]
DT = [0.02, 0.05]
SCHEMES = ["energy", "alpha2"]


def scene(h: float, mu: float, eps: float, t_end: float) -> PressAndDrag:
    return PressAndDrag(q_ratio=1.5, drag_start=1.5, drag_end=2.5, t_end=t_end,
                        h_contact=h).with_law(mu=mu, eps=eps)


def run(h: float, mu: float, eps: float, dt: float | None, scheme: str, t_end: float) -> dict:
    with warnings.catch_warnings():  # dt = 0.02, 0.05 do not resolve the contact period
        warnings.simplefilter("ignore")
        _, summary = scene(h, mu, eps, t_end).run(scheme=scheme, dt=dt, comm=MPI.COMM_SELF)
    summary.update(h=h, mu=mu, eps=eps if mu > 0 else None)
    print(f"h {h:g} mu {mu:g} eps {eps:g} dt {summary['dt']:.4g} {scheme:>6s}: balance "
          f"{summary['energy_balance_error']:.2e}, {summary['rejected_steps']} cut-backs, "
          f"{summary['wall_time_s']:.1f} s{'' if summary['failure'] is None else ' FAILED'}",
          flush=True)
    return summary


def main(argv: list[str] | None = None) -> None:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--h", type=float, nargs="+", default=[0.05, 0.051],
                       help="mesh sizes at the contact (0.05 0.051: the Debian 12 mesh and a "
                            "perturbed one)")
    flags.add_argument("--schemes", nargs="+", choices=SCHEMES, default=SCHEMES,
                       help="the schemes run (energy alpha2)")
    flags.add_argument("--no-default-dt", action="store_true",
                       help="skip the run at the default step (long on fine meshes)")
    flags.add_argument("--t-end", type=float, default=3.0, help="final time (3)")
    args = flags.parse_args(argv)
    logging.getLogger("ffcx").setLevel(logging.WARNING)
    args.out.mkdir(parents=True, exist_ok=True)
    runs = []
    for h in args.h:
        for dt in DT:
            for mu, eps_list in ((0.3, EPS), (0.0, [EPS[0]])):
                for eps in eps_list:
                    for scheme in args.schemes:
                        runs.append(run(h, mu, eps, dt, scheme, args.t_end))
        if not args.no_default_dt and "energy" in args.schemes:
            runs.append(run(h, 0.3, 1e-3, None, "energy", args.t_end))
    table = ["| mesh h | μ | ε | dt | energy: balance error | cut-backs | time | "
             "generalized-α: balance error | cut-backs | time | error ratio | time ratio |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in runs:
        if r["scheme"] != "energy":
            continue
        base = next((b for b in runs if b["scheme"] == "alpha2" and b["h"] == r["h"]
                     and b["mu"] == r["mu"] and b["eps"] == r["eps"] and b["dt"] == r["dt"]),
                    None)
        r["ratio_to_alpha2"] = None if base is None or base["energy_balance_error"] in (None, 0) \
            else {"energy_balance_error": r["energy_balance_error"]
                  / base["energy_balance_error"],
                  "wall_time_s": r["wall_time_s"] / base["wall_time_s"]}
        cells = [f"{r['h']:g} ({r['dofs']} unknowns)", f"{r['mu']:g}",
                 "—" if r["eps"] is None else f"{r['eps']:g}", f"{r['dt']:.3g}",
                 f"{r['energy_balance_error']:.1e}", str(r["rejected_steps"]),
                 f"{r['wall_time_s']:.1f} s"]
        if base is None:
            cells += ["—"] * 5
        else:
            failed = "" if base["failure"] is None else f" (stopped at t = {base['t_reached']:.3g})"
            cells += [f"{base['energy_balance_error']:.1e}{failed}",
                      str(base["rejected_steps"]), f"{base['wall_time_s']:.1f} s",
                      f"{r['ratio_to_alpha2']['energy_balance_error']:.1e}",
                      f"{r['ratio_to_alpha2']['wall_time_s']:.2f}"]
        table.append("| " + " | ".join(cells) + " |")
    print("\n".join(table))
    write_summary(args.out / "bench_press_drag.json", {"runs": runs}, MPI.COMM_SELF)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 4))
    energy = [r for r in runs if r["scheme"] == "energy"]
    x = np.arange(len(energy))
    ax.semilogy(x, [max(r["energy_balance_error"], 1e-16) for r in energy], "o",
                label="energy-consistent")
    with_base = [(i, r["ratio_to_alpha2"]) for i, r in enumerate(energy)
                 if r["ratio_to_alpha2"] is not None]
    ax.semilogy([i for i, _ in with_base],
                [energy[i]["energy_balance_error"] / q["energy_balance_error"]
                 for i, q in with_base], "s", label="generalized-α ρ∞ = 0.8")
    labels = [f"h{r['h']:g} μ{r['mu']:g} ε{r['eps'] or 0:g} dt{r['dt']:.3g}" for r in energy]
    ax.set_xticks(x, labels, rotation=90, fontsize=6)
    ax.axhline(1e-3, color="gray", linestyle=":", label="1e-3 of the work")
    ax.set_ylabel("energy balance error / work")
    ax.legend()
    save(fig, args.out / "bench_press_drag.png", dpi=120)


if __name__ == "__main__":
    main()
