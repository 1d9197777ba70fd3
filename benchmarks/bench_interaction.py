r"""Response of an interface of elastically interacting contacts to the break of one contact.

**Half-space** (Braun (slides), "Interaction between contacts"): contacts of stiffness k on an
``n × n`` square lattice of spacing a = 1 on an elastic half-space (E = 1, σ = 0.3, contact
radius a/2 for the self term), uniform shear U₀ = (1, 0, 0); the centre contact breaks
(δK = -k) and δF = B δK (1 - GBK) U₀ is solved matrix-free
(:class:`~fenicsfriction.studies.multicontact.interaction.LatticeInteraction`). For each
elastic correlation length λ_c = a²E/k: |δF|(r) (normalised by the broken contact's own δF),
the exponents fitted on r < λ_c/4 (near zone, when it holds ≥ 2 bins) and on
3λ_c < r < n/4 (far zone, away from the lattice's edge), and where the two fitted laws cross,
against λ_c.

**Finite block** (:class:`~fenicsfriction.studies.multicontact.ElasticSubstrate`): the same on a
lattice of contacts of spacing a = 2h covering the top face of a block of width W and depth
W/2 (uniform P1 hexahedra of side h = 1/8, clamped bottom), λ_c = a; the Green-tensor model of
the same contacts takes the contact radius for which its self term equals the FE node's
compliance (measured). Reported per W: the ratio of the broken contact's δF (block over
half-space: it carries the block's overall compliance), and, per unit δF at the break, the
median relative difference of δF between block and half-space in the near (r ≤ 2λ_c) and far
(r > 3λ_c) zones, and the ratio of the far zone's summed |δF|.

Writes ``bench_interaction.json`` and ``bench_interaction.png`` (|δF|(r) on log-log axes with
the r⁻¹ and r⁻³ laws; block against half-space) to ``--out``. The half-space part is serial
NumPy; the block part runs under MPI.
"""

from __future__ import annotations

import math
import time

from mpi4py import MPI

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction.results import get_logger
from fenicsfriction.studies.multicontact import ElasticSubstrate, SubstrateBlock
from fenicsfriction.studies.multicontact.interaction import (
    LatticeInteraction,
    break_response,
    fit_power_laws,
    interaction_matrix,
    radial_profile,
)

E, NU = 1.0, 0.3
SHEAR = [1.0, 0.0, 0.0]
log = get_logger()


def _half_space(n: int, correlation_lengths: list[float]) -> list[dict]:
    rows = []
    for lam in correlation_lengths:
        t0 = time.perf_counter()
        lattice = LatticeInteraction(n=n, spacing=1.0, E=E, nu=NU, stiffness=E / lam,
                                     contact_radius=0.5, rtol=1e-9)
        broken = (n // 2) * n + n // 2
        response = lattice.break_response(SHEAR, broken)
        r, f = radial_profile(lattice.positions, response, broken,
                              edges=np.geomspace(1.0, n / 4, 40))
        f = f / np.linalg.norm(response[broken])
        row = {"n": n, "lambda_c": lam, "seconds": time.perf_counter() - t0,
               "r": r, "dF": f}
        near, far = r < lam / 4, r > 3 * lam
        if near.sum() >= 2:
            row["near_exponent"] = float(np.polyfit(np.log(r[near]), np.log(f[near]), 1)[0])
        if far.sum() >= 2:
            row["far_exponent"] = float(np.polyfit(np.log(r[far]), np.log(f[far]), 1)[0])
        if near.sum() >= 2 and far.sum() >= 2:
            fit = fit_power_laws(r, f, lam / 4, 3 * lam)
            row["crossover"], row["crossover_over_lambda_c"] = fit.crossover, fit.crossover / lam
        log.info("half-space n=%d λ_c=%g: %s", n, lam,
                 {k: v for k, v in row.items() if k not in ("r", "dF")})
        rows.append(row)
    return rows


def _node_compliance(block: SubstrateBlock) -> float:
    """u_x at a top-face node under a unit x-force there (tiny spring: no anchor)."""
    substrate = ElasticSubstrate(MPI.COMM_WORLD, block, [[0.0, 0.0]], stiffness=1e-12)
    return float(substrate.displacements(0.0, [1.0, 0.0, 0.0])[0, 0])


def _block(widths: list[float], h: float) -> list[dict]:
    rows = []
    a = 2 * h
    lam = a
    for width in widths:
        t0 = time.perf_counter()
        cells = round(width / h)
        block = SubstrateBlock(width=width, depth=width / 2, E=E, nu=NU, cells_per_side=cells,
                               cells_deep=cells // 2)
        side = np.arange(-width / 2 + a, width / 2 - a / 2, a)
        positions = np.array([[x, y] for x in side for y in side])
        broken = int(np.argmin(np.linalg.norm(positions, axis=1)))
        k = a**2 * E / lam
        fe = ElasticSubstrate(MPI.COMM_WORLD, block, positions, k).break_response(SHEAR, broken)
        compliance = _node_compliance(block)
        radius = (1 + NU) * (2 - NU) / (math.pi * E * compliance)
        G = interaction_matrix(positions, E, NU, contact_radius=radius)
        green = break_response(G, k, SHEAR, broken)
        r = np.linalg.norm(positions - positions[broken], axis=1)
        # each response per unit source: the uniform-shear forces, hence the broken contact's
        # load, depend on the block's overall compliance; what propagates is compared here
        fe_unit = fe / np.linalg.norm(fe[broken])
        green_unit = green / np.linalg.norm(green[broken])
        difference = (np.linalg.norm(fe_unit - green_unit, axis=1)
                      / np.maximum(np.linalg.norm(green_unit, axis=1), 1e-300))
        near, far = (r > 0) & (r <= 2 * lam), r > 3 * lam
        edges = np.geomspace(a, width / 2, 12)
        r_fe, f_fe = radial_profile(positions, fe, broken, edges)
        r_g, f_g = radial_profile(positions, green, broken, edges)
        row = {"width": width, "depth": width / 2, "h": h, "contacts": len(positions),
               "lambda_c": lam, "node_compliance": compliance, "contact_radius": radius,
               "near_median_relative_difference": float(np.median(difference[near])),
               "far_median_relative_difference": float(np.median(difference[far])),
               "broken_fe_over_green": float(np.linalg.norm(fe[broken])
                                             / np.linalg.norm(green[broken])),
               "far_fe_over_green_sum": float(np.sum(np.linalg.norm(fe_unit[far], axis=1))
                                              / np.sum(np.linalg.norm(green_unit[far], axis=1))),
               "seconds": time.perf_counter() - t0,
               "r_fe": r_fe, "dF_fe": f_fe / np.linalg.norm(fe[broken]),
               "r_green": r_g, "dF_green": f_g / np.linalg.norm(green[broken])}
        log.info("block W=%g: %s", width, {k: v for k, v in row.items()
                                           if not k.startswith(("r_", "dF_"))})
        rows.append(row)
    return rows


def _plot(out: dict, path: object) -> None:
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    # near zone δF/δF* ≈ k G(r) ∝ a²/(λ_c r): λ_c² δF/δF* against r/λ_c is one curve
    curves = [(np.asarray(row["r"]) / row["lambda_c"],
               row["lambda_c"]**2 * np.asarray(row["dF"]), row["lambda_c"])
              for row in out["half_space"]]
    for x, y, lam in curves:
        left.loglog(x, y, ".-", label=f"λ_c = {lam:g} a")
    x_near, y_near, _ = curves[-1]
    x_far, y_far, _ = curves[0]
    left.loglog(x_near, y_near[0] * x_near[0] / x_near, "k--", lw=0.8, label="∝ r⁻¹")
    left.loglog(x_far, y_far[-1] * (x_far[-1] / x_far) ** 3, "k:", lw=0.8, label="∝ r⁻³")
    left.set(xlabel="r / λ_c", ylabel="(λ_c/a)² |δF| / |δF at the break|",
             title=f"half-space, {out['half_space'][0]['n']}² contacts")
    left.legend(fontsize=8)
    for row in out["block"]:
        lines = right.loglog(row["r_fe"], row["dF_fe"], "o-", ms=3,
                             label=f"block W = {row['width']:g}")
        right.loglog(row["r_green"], row["dF_green"], "--", color=lines[0].get_color(),
                     label=f"half-space, same contacts (W = {row['width']:g})")
    right.set(xlabel="r", ylabel="|δF| / |δF at the break|",
              title=f"FE block against half-space, λ_c = {out['block'][0]['lambda_c']:g}")
    right.legend(fontsize=7)
    save(fig, path, dpi=130)


def main() -> None:
    parser = benchmark_parser(__doc__)
    parser.add_argument("--n", type=int, default=512, help="lattice side (default 512)")
    parser.add_argument("--lambda-c", type=float, nargs="+", default=[4.0, 16.0, 64.0],
                        help="correlation lengths a²E/k in lattice spacings")
    parser.add_argument("--widths", type=float, nargs="+", default=[2.0, 3.0, 4.0],
                        help="block widths (h = 1/8)")
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    out: dict = {}
    if comm.rank == 0:
        out["half_space"] = _half_space(args.n, args.lambda_c)
    out["half_space"] = comm.bcast(out.get("half_space"), root=0)
    out["block"] = _block(args.widths, h=1 / 8)
    if comm.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        _plot(out, args.out / "bench_interaction.png")
    write_summary(args.out / "bench_interaction.json", out)


if __name__ == "__main__":
    main()
