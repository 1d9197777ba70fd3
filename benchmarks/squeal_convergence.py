r"""Mesh convergence of the pin on the disc: the coupling frequencies and the flutter onset.

The pin-on-disc scene (``fenicsfriction.studies.squeal``: a steel pin inclined 20° towards the
sliding direction, held in a rigid sleeve and pressed with 48 N on a steel disc clamped at its
hub, linear normal compliance 1e11 N/m³, ε = 1e-3 m/s ≪ ω R_p = 0.65 m/s) is meshed with
tetrahedra at decreasing sizes (every size times ``--scales``; 1 is h = 8 mm in the disc, 2 mm
at the contact and in the pin). On each mesh: steady sliding and the eigenvalue loci on a μ
grid, the onset μ_crit bisected to ``--tol``, the two real modes of the frictionless problem
that carry the flutter mode (their frequencies: the coupling frequencies) and the onset μ_c of
the two-mode model built from them (:mod:`fenicsfriction.studies.squeal.two_mode`), and the
onset of the pencil projected on the 12 lowest real modes.

Observed rates from three successive meshes (h_{k+1}/h_k = r): p = log(|q_k - q_{k+1}| /
|q_{k+1} - q_{k+2}|) / log(1/r), in the mesh size h.

Writes ``squeal_convergence.json`` and ``squeal_convergence.png`` to ``--out`` and prints a
markdown table. Serial; about 10 minutes with the default scales on an idle machine.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

try:
    from benchmarks._common import parser, save, write_summary
except ImportError:  # run as a script from benchmarks/
    from _common import parser, save, write_summary  # type: ignore[no-redef]


def one_mesh(scale: float, mus: list[float], tol: float) -> dict:
    """The study on the mesh of sizes times ``scale``."""
    from mpi4py import MPI

    from fenicsfriction.studies.squeal import geometry
    from fenicsfriction.studies.squeal.model import PinOnDiscModel
    from fenicsfriction.studies.squeal.study import stability_study

    t0 = time.perf_counter()
    mesh = geometry.pin_on_disc(MPI.COMM_WORLD, h_far=0.008 * scale, h_contact=0.002 * scale,
                                h_pin=0.002 * scale)
    model = PinOnDiscModel(mesh)
    study = stability_study(model, mus, tol=tol,
                            prefix=f"conv{str(scale).replace('.', '_')}_").to_json()
    two = study["two_mode"]
    row = {"scale": scale, "dofs": study["dofs"], "mu_crit": study["mu_crit"],
           "f_onset_hz": study["onset_value"][1] / (2 * math.pi),
           "f_coupling_hz": two["frequencies_hz"], "mu_c_two_mode": two["mu_c"],
           "mu_c_two_mode_damped": two["mu_c_damped"], "f_c_two_mode_hz": two["f_c_hz"],
           "mu_c_basis": study["basis_onset"],
           "wall_time_s": time.perf_counter() - t0, "study": study}
    print(f"scale {scale}: {row['dofs']} dofs, mu_crit {row['mu_crit']:.4f}, two-mode "
          f"{row['mu_c_two_mode']:.4f}, coupling {two['frequencies_hz']} Hz "
          f"({row['wall_time_s']:.0f} s)", file=sys.stderr)
    return row


def rates(values: list[float], ratio: float) -> list[float]:
    """Observed orders from successive triples of a sequence on meshes h, r h, r² h, ..."""
    out = []
    for a, b, c in zip(values, values[1:], values[2:], strict=False):
        if (b - c) == 0 or (a - b) == 0:
            out.append(math.nan)
        else:
            out.append(math.log(abs(a - b) / abs(b - c)) / math.log(1 / ratio))
    return out


def main() -> None:
    flags = parser(__doc__)
    flags.add_argument("--scales", type=float, nargs="+", default=[1.0, 0.75, 0.5625],
                       help="mesh sizes relative to the default mesh (a geometric sequence)")
    flags.add_argument("--mus", type=float, nargs="+",
                       default=[0.0, 0.2, 0.3, 0.45, 0.6], help="the μ grid")
    flags.add_argument("--tol", type=float, default=2e-3, help="the onset's bracket")
    args = flags.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    rows = [one_mesh(s, args.mus, args.tol) for s in args.scales]
    ratio = args.scales[1] / args.scales[0]
    quantities = {"mu_crit": [r["mu_crit"] for r in rows],
                  "mu_c_two_mode": [r["mu_c_two_mode"] for r in rows],
                  "mu_c_basis": [r["mu_c_basis"] for r in rows],
                  "f_onset_hz": [r["f_onset_hz"] for r in rows],
                  "f_coupling_low_hz": [r["f_coupling_hz"][0] for r in rows],
                  "f_coupling_high_hz": [r["f_coupling_hz"][1] for r in rows]}
    observed = {k: rates(v, ratio) for k, v in quantities.items()}
    summary = {"rows": rows, "observed_rates": observed, "ratio": ratio}
    write_summary(args.out / "squeal_convergence.json", summary)
    print("| h / h₀ | dofs | f₁ [Hz] | f₂ [Hz] | μ_crit (FE) | f at onset [Hz] | μ_c (two modes) "
          "| μ_c (12 modes) | time [s] |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['scale']:.4g} | {r['dofs']} | {r['f_coupling_hz'][0]:.1f} | "
              f"{r['f_coupling_hz'][1]:.1f} | {r['mu_crit']:.4f} | {r['f_onset_hz']:.1f} | "
              f"{r['mu_c_two_mode']:.4f} | {r['mu_c_basis']:.4f} | {r['wall_time_s']:.0f} |")
    print("\nobserved rates:", {k: [round(x, 2) for x in v] for k, v in observed.items()})

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(9, 3.6))
    h = np.array([r["scale"] for r in rows]) * 8.0
    left.plot(h, quantities["mu_crit"], "o-", label="μ_crit, finite elements")
    left.plot(h, quantities["mu_c_two_mode"], "s--", label="μ_c, two-mode model")
    left.plot(h, quantities["mu_c_basis"], "^:", label="μ_c, 12 modes")
    left.set_xlabel("disc mesh size h [mm]")
    left.set_ylabel("flutter onset μ")
    left.legend()
    for key, label in (("f_coupling_low_hz", "f₁ (μ = 0)"), ("f_coupling_high_hz", "f₂ (μ = 0)"),
                       ("f_onset_hz", "f at the onset")):
        right.plot(h, quantities[key], "o-", label=label)
    right.set_xlabel("disc mesh size h [mm]")
    right.set_ylabel("frequency [Hz]")
    right.legend()
    save(fig, args.out / "squeal_convergence.png", 120)


if __name__ == "__main__":
    main()
