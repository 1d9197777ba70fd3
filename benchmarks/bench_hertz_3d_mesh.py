"""The 3D Hertz scene's two headline figures against the mesh under the contact.

The quarter sphere on a block (:class:`~fenicsfriction.studies.contact.validation.Hertz`,
``dim=3``: R = 1, E = 1, ν = 0.3 for both bodies, node-to-segment contact, one pass,
c_n = 1e4, the load of a = R/10) on a ladder of meshes (``--levels``): the default (h = a/5 in
the cube |x|, |y|, |z| <= 0.25 R) and a thin refined slab along the contact plane
(``geometry.hertz_3d(refine_depth=...)``: |x|, |y| <= 0.14 R, |z| <= 0.03 R) at h = a/10,
a/15, a/20. For each: unknowns, wall time, Newton iterations and the errors against Hertz
(Hertz 1882; Johnson 1985, eqs. 4.22-4.23) of

* ``contact_radius``: the radius of the nodal rule's contact area (``TwoBodyModel.contact_area``,
  the tributary areas of the nodes in contact projected on the plane, four quarters making
  πa²), and ``peak_pressure``: the pressure on the axis recovered by the L2 projection of the
  nodal pressures onto c0 + c1 r² over r <= 0.6 a_h (``validation.pressure_on_axis``) — the
  scene's headline figures;
* the old figures: ``gap_crossing_radius``, the mean radius where the interpolated nodal gap
  changes sign, and ``max_pressure``, the largest nodal pressure;
* ``fitted_*``: Hertz's ellipse fitted through every contact node's pressure;
* the scatter of the nodal pressures about Hertz's over r < 0.8 a (rms and largest relative
  deviation): what ``max_pressure`` is the maximum of;
* observed orders log(e_i/e_{i+1}) / log(h_i/h_{i+1}) of |error| between successive rungs.

Writes ``bench_hertz_3d_mesh.json`` and ``.png`` (the errors against h/a) to ``--out``, prints a
markdown table. Serial; the ladder takes about 10 minutes on one core (a/20: 32,000 unknowns).
"""

from __future__ import annotations

import sys
import time

from mpi4py import MPI

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction.steady import SolveError
from fenicsfriction.studies.contact import geometry
from fenicsfriction.studies.contact.validation import Hertz

#: name: (h_contact, refine_half_width, refine_depth) per unit R; depth None: the default cube.
#: (a/15 is h = 0.0067 R: at 0.02/3 R the first solve's Newton line search diverges after 29
#: iterations, residual 7.4e-5)
LEVELS = {"a/5 (default)": (0.02, 0.25, None), "a/10 slab": (0.01, 0.14, 0.03),
          "a/15 slab": (0.0067, 0.14, 0.03), "a/20 slab": (0.005, 0.13, 0.025)}


def run(name: str) -> dict:
    """One rung: the scene solved on its mesh, the figures and the nodal scatter."""
    h, width, depth = LEVELS[name]
    scene = Hertz(dim=3)
    start = time.perf_counter()
    mesh = geometry.hertz_3d(MPI.COMM_WORLD, h_contact=h, refine_half_width=width,
                             refine_depth=depth)
    model = scene.model(mesh, fix_load_face=False)
    summary, _ = scene.run(model=model)
    values = model.surface_values()
    a, p0 = scene.closed_form()
    r = np.linalg.norm(values.x[:, :2], axis=1)
    inner = (r < 0.8 * a) & (values.load_weight > 0)
    deviation = values.pressure[inner] / (p0 * np.sqrt(1 - (r[inner] / a) ** 2)) - 1
    keys = ("dofs", "contact_radius_error", "peak_pressure_error", "gap_crossing_radius_error",
            "max_pressure_error", "fitted_contact_radius_error", "fitted_max_pressure_error",
            "newton_iterations")
    return {"level": name, "h_over_a": h / a, "refine_half_width": width,
            "refine_depth": depth, **{k: summary[k] for k in keys},
            "scatter_rms": float(np.sqrt(np.mean(deviation**2))),
            "scatter_max": float(np.abs(deviation).max()),
            "wall_time_s": time.perf_counter() - start}


def main() -> None:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--levels", default=",".join(LEVELS),
                       help="comma-separated rungs (default: all)")
    args = flags.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    for name in args.levels.split(","):
        print(f"{name} ...", file=sys.stderr, flush=True)
        try:
            rows.append(run(name))
        except SolveError as err:  # recorded, the ladder goes on
            print(f"{name}: {err}", file=sys.stderr, flush=True)
            rows.append({"level": name, "failure": str(err)})
        write_summary(args.out / "bench_hertz_3d_mesh.json", {"rows": rows})
    failed = [r for r in rows if "failure" in r]
    rows = [r for r in rows if "failure" not in r]
    headline = ("contact_radius_error", "peak_pressure_error")
    for coarse, fine in zip(rows[:-1], rows[1:], strict=True):
        ratio = np.log(coarse["h_over_a"] / fine["h_over_a"])
        fine["observed_orders"] = {k: float(np.log(abs(coarse[k]) / abs(fine[k])) / ratio)
                                   for k in headline}
    write_summary(args.out / "bench_hertz_3d_mesh.json", {"rows": rows + failed})
    print("| mesh | unknowns | wall time (s) | contact radius | peak pressure | orders (radius, "
          "peak) | gap-crossing radius | max nodal pressure | fitted a / p0 | nodal scatter "
          "rms / max (r < 0.8a) | Newton |\n|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        orders = r.get("observed_orders")
        order_text = "—" if orders is None else (f"{orders['contact_radius_error']:.1f}, "
                                                 f"{orders['peak_pressure_error']:.1f}")
        print(f"| {r['level']} | {r['dofs']} | {r['wall_time_s']:.0f} "
              f"| {r['contact_radius_error']:+.2%} | {r['peak_pressure_error']:+.2%} "
              f"| {order_text} | {r['gap_crossing_radius_error']:+.1%} "
              f"| {r['max_pressure_error']:+.1%} | {r['fitted_contact_radius_error']:+.2%} / "
              f"{r['fitted_max_pressure_error']:+.2%} | {r['scatter_rms']:.1%} / "
              f"{r['scatter_max']:.1%} | {r['newton_iterations']} |")
    for r in failed:
        print(f"| {r['level']} | failed: {r['failure']} |")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4))
    h = [r["h_over_a"] for r in rows]
    for key, label, style in (("contact_radius_error", "contact radius (nodal-rule area)", "o-"),
                              ("peak_pressure_error", "peak pressure (axis recovery)", "s-"),
                              ("gap_crossing_radius_error", "gap sign-change radius", "o--"),
                              ("max_pressure_error", "largest nodal pressure", "s--"),
                              ("fitted_contact_radius_error", "fitted a", "o:"),
                              ("fitted_max_pressure_error", "fitted p0", "s:")):
        ax.plot(h, [100 * abs(r[key]) for r in rows], style, label=label)
    ax.axhline(3.0, color="gray", ls="--", lw=0.8, label="3 %")
    ax.set(xlabel="h / a at the contact", ylabel="|error| against Hertz (%)",
           title="Hertz 3D, node-to-segment, c_n = 1e4")
    ax.legend(fontsize=8)
    save(fig, args.out / "bench_hertz_3d_mesh.png", dpi=120)


if __name__ == "__main__":
    main()
