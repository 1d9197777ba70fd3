"""Accuracy against wall time of the rolling finite element model (Kalker's complete theory).

* 2D, Carter's cylinders (Carter 1926; Johnson 1985, section 8.3): for each mesh (cells over
  a: ``--cells-2d``) and block size (``--blocks-2d``, in units of a) the small-creepage slope
  against :math:`(\\pi/2) a E^*`, and at ξ = 0.2 and 0.5 of saturation the force error over
  μP, the stick zone's trailing end against Carter's a - 2c and the traction's L2 error;
* 3D, the circle (ν = 0 and 0.25) and the ellipse a/b = 0.5: the small-creepage C11, C22
  against Kalker's table (Kalker 1990, Table E.3), for ``--cells-3d``;
* Kalker's ε sequence (Kalker 1986, section 6): per ε, the solution's change and Newton's
  iterations, on the finest 2D mesh.

Writes ``bench_rolling_fe.json`` and ``bench_rolling_fe.png`` to ``--out`` and prints
markdown tables (rank 0). Serial, about 3 minutes with the defaults.
"""

from __future__ import annotations

from mpi4py import MPI

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction.studies.rolling import closed_forms
from fenicsfriction.studies.rolling.kalker import creep_coefficients
from fenicsfriction.studies.rolling.model import RollingContact

CARTER = {"dim": 2, "nu": 0.0, "p0": 0.01}
MU = 0.3
SMALL = 1e-6  # creepage of the linear theory (far below μ p0/G = 3e-3)


def carter_row(cells: int, block: float) -> dict:
    scene = RollingContact(**CARTER, cells_per_a=cells, block_size=block).with_law(mu=MU)
    model = scene.build()
    row = {"cells_per_a": cells, "block_size": block, "dofs": model.dofs}
    result = model.solve((SMALL, 0.0, 0.0))
    slope = np.pi * scene.a * scene.E_star / 2
    row["slope_error"] = -result.Fx / SMALL / slope - 1
    saturation = scene.law.mu * scene.a / scene.radius
    for q in (0.2, 0.5):
        xi = q * saturation
        result = model.solve((xi, 0.0, 0.0))
        c = closed_forms.carter_stick_half_width(xi, scene.law.mu, scene.a, scene.radius)
        exact = closed_forms.carter_traction(result.x[:, 0], xi, scene.law.mu, scene.a,
                                             scene.peak_pressure, scene.radius)
        force = closed_forms.carter_force(xi, scene.law.mu, scene.a, scene.peak_pressure,
                                          scene.radius)
        row[f"q{q}"] = {
            "force_error_over_muP": (result.Fx - force) / (scene.law.mu * scene.normal_load),
            "stick_end": float(result.x[result.stick(), 0].min()), "carter_stick_end": 1 - 2 * c,
            "traction_error_l2": float(np.linalg.norm(result.traction[:, 0] - exact)
                                       / np.linalg.norm(exact)),
            "newton_iterations": result.newton_iterations, "wall_time_s": result.wall_time_s,
            "eps_records": result.eps_records}
    return row


def kalker_row(cells: int, nu: float, b: float) -> dict:
    scene = RollingContact(dim=3, nu=nu, b=b, p0=0.01, cells_per_a=cells, block_size=10.0,
                           growth=1.5, eps_sequence=(10.0, 1.0, 0.1))
    model = scene.build()
    area = scene.a * b
    fx = model.solve((SMALL, 0.0, 0.0))
    fy = model.solve((0.0, SMALL, 0.0))
    kalker = creep_coefficients(scene.a, b, nu)
    c11, c22 = kalker.C11, kalker.C22
    return {"cells_per_a": cells, "nu": nu, "a_over_b": scene.a / b, "dofs": model.dofs,
            "C11": -fx.Fx / (scene.G * area * SMALL), "kalker_C11": c11,
            "C22": -fy.Fy / (scene.G * area * SMALL), "kalker_C22": c22,
            "wall_time_s": fx.wall_time_s + fy.wall_time_s}


def main() -> None:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--cells-2d", default="8,16,32,64")
    flags.add_argument("--blocks-2d", default="10,100,1000")
    flags.add_argument("--cells-3d", default="4,6")
    args = flags.parse_args()
    comm = MPI.COMM_WORLD
    carter = [carter_row(n, L) for n in map(int, args.cells_2d.split(","))
              for L in map(float, args.blocks_2d.split(","))]
    kalker = [kalker_row(n, nu, b) for n in map(int, args.cells_3d.split(","))
              for nu, b in ((0.0, 1.0), (0.25, 1.0), (0.25, 2.0))]
    write_summary(args.out / "bench_rolling_fe.json", {"carter": carter, "kalker": kalker},
                  comm)
    if comm.rank != 0:
        return
    print("| cells/a | L/a | dofs | slope err | F err/μP (0.5) | stick end (Carter 0) | "
          "traction L2 | Newton | time [s] |\n|---|---|---|---|---|---|---|---|---|")
    for r in carter:
        h = r["q0.5"]
        print(f"| {r['cells_per_a']} | {r['block_size']:g} | {r['dofs']} | "
              f"{r['slope_error']:+.4f} | {h['force_error_over_muP']:+.4f} | "
              f"{h['stick_end']:+.4f} | {h['traction_error_l2']:.4f} | "
              f"{h['newton_iterations']} | {h['wall_time_s']:.2f} |")
    print("\n| cells/a | ν | a/b | dofs | C11 (Kalker) | C22 (Kalker) | time [s] |\n"
          "|---|---|---|---|---|---|---|")
    for r in kalker:
        print(f"| {r['cells_per_a']} | {r['nu']} | {r['a_over_b']} | {r['dofs']} | "
              f"{r['C11']:.3f} ({r['kalker_C11']}) | {r['C22']:.3f} ({r['kalker_C22']}) | "
              f"{r['wall_time_s']:.1f} |")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for block in sorted({r["block_size"] for r in carter}):
        rows = [r for r in carter if r["block_size"] == block]
        h = [1 / r["cells_per_a"] for r in rows]
        ax[0].loglog(h, [abs(r["slope_error"]) for r in rows], "o-", label=f"slope, L = {block:g}a")
        ax[0].loglog(h, [abs(r["q0.5"]["force_error_over_muP"]) for r in rows], "s--",
                     label=f"F at ξ/ξ_sat = 0.5, L = {block:g}a")
    ax[0].set_xlabel("h / a")
    ax[0].set_ylabel("relative error")
    ax[0].legend(fontsize=7)
    finest = carter[-1]["q0.5"]["eps_records"]
    ax[1].loglog([r["eps"] for r in finest[1:]], [r["change"] for r in finest[1:]], "o-")
    ax[1].set_xlabel("ε")
    ax[1].set_ylabel("max |u_k - u_{k-1}|")
    save(fig, args.out / "bench_rolling_fe.png", 120)


if __name__ == "__main__":
    main()
