"""Write the pin-on-disc scene (a steel pin pressed on an annular disc clamped at its hub,
tetrahedra) as a gmsh mesh with named physical groups:
``python meshes/pin_on_disc.py --out results/pin_on_disc.msh --refine 1``."""

import time

from mpi4py import MPI

import numpy as np
from _common import parser

from fenicsfriction import discs
from fenicsfriction.studies.squeal import geometry

if __name__ == "__main__":
    p = parser("pin_on_disc", __doc__)
    disc, pin = discs.Disc(), geometry.Pin()
    p.add_argument("--h-far", type=float, default=0.008, help="largest mesh size, in the disc [m]")
    p.add_argument("--refine", type=int, default=0, help="halve the mesh sizes this many times")
    p.add_argument("--angle", type=float, default=pin.angle,
                   help="the pin's inclination from e_z towards the sliding direction [deg]")
    p.add_argument("--length", type=float, default=pin.length, help="the pin's length [m]")
    p.add_argument("--radius", type=float, default=pin.radius,
                   help="the contact point's radius on the disc, R_p [m]")
    args = p.parse_args()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    pin = geometry.Pin(radius=args.radius, length=args.length, angle=args.angle)
    m = geometry.pin_on_disc(MPI.COMM_SELF, disc, pin, h_far=args.h_far, refine=args.refine,
                             msh_file=str(args.out))
    vertices = m.mesh.topology.index_map(0).size_global
    print(f"{args.out}: {m.mesh.topology.index_map(3).size_global} cells, {vertices} vertices, "
          f"{3 * vertices} P1 dofs ({time.perf_counter() - start:.1f} s)")
    for tag, name in geometry.NAMES.items():
        tags = m.cell_tags if tag in (discs.DISC, geometry.PIN) else m.facet_tags
        print(f"  {name} = {tag}: {int(np.count_nonzero(tags.values == tag))}")
    print("  sizes:", m.parameters)
