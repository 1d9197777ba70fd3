r"""Flutter onset of the block on an elastic belt against the belt's stiffness and thickness.

The block of Martins & Oden (1986) (4r × 3r cells) slides on an elastic slab
(``fenicsfriction.studies.block``) whose Young's modulus is E_slab = ratio × E (E the block's,
1.4e6) and whose thickness is t, clamped on a rigid carrier at the belt speed. The two-body
contact is ``--formulation`` node-to-segment (Pop; Q1, nodal contact rule) or mortar
(``--degree`` 1 or 2). For each (ratio, t) it finds the
friction coefficient μ_crit at which steady sliding loses stability (a pair of eigenvalues of
the linearisation collides and one crosses into Re λ > 0): loci on a μ grid
(``--mu-step``) up to the first unstable point, then bisection to ``--onset-tol``
(:meth:`fenicsfriction.stability.Loci.onset`). It records μ_crit, the growing eigenvalue just
past the onset and the two modes that collide (their frequencies at the stable end), with the
one-body block on a rigid belt as the reference row: the same elements and rule for
node-to-segment (Q1, nodal rule), the block of the same degree with its Gauss rule for mortar
(``--reference`` chooses another rule).

Writes ``block_on_slab_study.json`` and ``block_on_slab_study.png`` to ``--out`` and prints a
markdown table. Serial; a few minutes at r = 1.
"""

from __future__ import annotations

import sys
import time

import numpy as np

try:
    from benchmarks._common import parser, save, write_summary
except ImportError:  # run as a script from benchmarks/
    from _common import parser, save, write_summary  # type: ignore[no-redef]

RATIOS = (1.0, 3.0, 10.0, 100.0, 1000.0)
THICKNESSES = (2.5, 10.0, 30.0)
MAX_MODULUS = 3e4  # [1/s]: the block's six modes (and the slab's, where they come down)


def onset(scene, mu_step: float, mu_max: float, tol: float, prefix: str) -> dict:
    """μ_crit of ``scene`` and the eigenvalues at its onset (None if stable up to mu_max)."""
    from mpi4py import MPI

    import fenicsfriction as ff
    from fenicsfriction.stability import Loci, StabilitySolver

    t0 = time.perf_counter()
    model = scene.build(MPI.COMM_SELF, with_friction=True)
    model.initial_guess()
    steady = ff.SteadySolver(model.residual, prefix=prefix, options=model.solver_options(),
                             search_rounds=model.search_rounds)
    pep = StabilitySolver(model.residual, prefix=prefix + "pep_")
    loci = Loci(steady, pep, model.mu, MAX_MODULUS)
    grid = np.arange(0.0, mu_max + 0.5 * mu_step, mu_step)
    previous, stable_modes = None, None
    row: dict = {"mu_crit": None}
    for mu in grid:
        ff.continuation(steady, model.mu, [float(mu)])
        modes = pep.solve(MAX_MODULUS)
        if loci.unstable(modes):
            if previous is None:
                raise RuntimeError(f"unstable at μ = {mu}, the first grid point")
            found = loci.onset(previous, float(mu), tol, reference=stable_modes)
            row = {"mu_crit": found.mu_crit, "interval": found.interval,
                   "growing": found.value, "colliding": found.colliding}
            break
        previous, stable_modes = float(mu), modes
    row["modes_below_max"] = len(stable_modes or [])
    row["dofs"] = model.V.dofmap.index_map.size_global * 2
    row["wall_time_s"] = time.perf_counter() - t0
    return row


def main() -> int:
    flags = parser(__doc__)
    flags.add_argument("--refine", type=int, default=1, help="block mesh 4r × 3r (1)")
    flags.add_argument("--formulation", choices=["node-to-segment", "mortar"],
                       default="node-to-segment", help="the block-slab contact")
    flags.add_argument("--degree", type=int, choices=[1, 2], default=1,
                       help="Lagrange degree (2: mortar only) (1)")
    flags.add_argument("--reference", choices=["nodal", "gauss", "gll"],
                       help="the one-body block's contact rule (node-to-segment: nodal; "
                            "mortar: gauss)")
    flags.add_argument("--ratios", default=",".join(map(str, RATIOS)),
                       help="E_slab / E values")
    flags.add_argument("--thicknesses", default=",".join(map(str, THICKNESSES)),
                       help="slab thicknesses [cm]")
    flags.add_argument("--mu-step", type=float, default=0.05, help="μ grid step (0.05)")
    flags.add_argument("--mu-max", type=float, default=0.6, help="last μ of the grid (0.6)")
    flags.add_argument("--onset-tol", type=float, default=1e-4, help="bisection width (1e-4)")
    flags.add_argument("--dpi", type=int, default=110)
    args = flags.parse_args()
    import fenicsfriction as ff

    ratios = [float(v) for v in args.ratios.split(",")]
    thicknesses = [float(v) for v in args.thicknesses.split(",")]
    args.out.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    E = ff.BlockOnBelt().E
    settings = {"mu_step": args.mu_step, "mu_max": args.mu_max, "tol": args.onset_tol}
    rule = args.reference or ("nodal" if args.formulation == "node-to-segment" else "gauss")
    reference = onset(ff.BlockOnBelt(degree=args.degree, contact_quadrature=rule,
                                     refine=args.refine), prefix="rigid_", **settings)
    print(f"rigid belt (degree {args.degree}, {rule} rule): μ_crit = {reference['mu_crit']}",
          file=sys.stderr)
    rows = []
    for k, (t, ratio) in enumerate((t, r) for t in thicknesses for r in ratios):
        scene = ff.BlockOnSlab(refine=args.refine, slab_E=ratio * E, slab_thickness=t,
                               formulation=args.formulation, degree=args.degree)
        row = {"ratio": ratio, "slab_E": ratio * E, "thickness": t,
               **onset(scene, prefix=f"slab{k}_", **settings)}
        rows.append(row)
        print(f"t = {t:5.1f} cm  E_slab/E = {ratio:7.1f}: μ_crit = {row['mu_crit']}  "
              f"({row['wall_time_s']:.1f} s)", file=sys.stderr)
    result = {"refine": args.refine, "formulation": args.formulation, "degree": args.degree,
              "reference_rule": rule, "max_modulus": MAX_MODULUS, **settings,
              "rigid": reference, "slab": rows, "wall_time_s": time.perf_counter() - t_start}
    write_summary(args.out / "block_on_slab_study.json", result)
    print(table(reference, rows))
    plot(reference, rows, thicknesses, args.out / "block_on_slab_study.png", args.dpi)
    return 0


def _fmt(row: dict) -> tuple[str, str, str, str]:
    if row["mu_crit"] is None:
        return "stable", "-", "-", "-"
    freqs = sorted(c["im"] for c in row["colliding"])
    return (f"{row['mu_crit']:.4f}", f"{row['growing'][0]:.1f}", f"{row['growing'][1]:.0f}",
            " / ".join(f"{f:.0f}" for f in freqs))


def table(reference: dict, rows: list[dict]) -> str:
    """Markdown: one row per slab, the rigid belt first."""
    lines = ["| t [cm] | E_slab / E | μ_crit | Δμ_crit vs rigid | Re λ past onset [1/s] | "
             "Im λ at onset [rad/s] | colliding modes' Im λ [rad/s] | modes below 3e4 | "
             "time [s] |", "|---|---|---|---|---|---|---|---|---|"]
    mu_ref = reference["mu_crit"]
    lines.append("| rigid | ∞ | " + " | ".join(_fmt(reference)[:1]) + " | 0 | "
                 + " | ".join(_fmt(reference)[1:]) + f" | {reference['modes_below_max']} | "
                 f"{reference['wall_time_s']:.1f} |")
    for r in rows:
        mu, re, im, coll = _fmt(r)
        delta = "-" if r["mu_crit"] is None else f"{r['mu_crit'] - mu_ref:+.4f}"
        lines.append(f"| {r['thickness']:g} | {r['ratio']:g} | {mu} | {delta} | {re} | {im} | "
                     f"{coll} | {r['modes_below_max']} | {r['wall_time_s']:.1f} |")
    return "\n".join(lines)


def plot(reference: dict, rows: list[dict], thicknesses: list[float], path, dpi: int) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4))
    for t in thicknesses:
        mine = [r for r in rows if r["thickness"] == t and r["mu_crit"] is not None]
        x = [r["ratio"] for r in mine]
        ax.semilogx(x, [r["mu_crit"] for r in mine], "o-", label=f"t = {t:g} cm")
        bx.semilogx(x, [r["growing"][1] for r in mine], "o-", label=f"t = {t:g} cm")
    if reference["mu_crit"] is not None:
        ax.axhline(reference["mu_crit"], color="k", ls="--", label="rigid belt")
        bx.axhline(reference["growing"][1], color="k", ls="--", label="rigid belt")
    ax.set(xlabel="E_slab / E_block", ylabel="μ_crit", title="flutter onset")
    bx.set(xlabel="E_slab / E_block", ylabel="Im λ at onset [rad/s]",
           title="frequency of the growing mode")
    ax.legend()
    bx.legend()
    save(fig, path, dpi)


if __name__ == "__main__":
    sys.exit(main())
