"""Write the simplified brake (a disc and two pads) as a gmsh mesh:
``python meshes/brake.py --h 0.004 --out brake.msh``."""

import pathlib
import time

from mpi4py import MPI

import numpy as np
from _common import parser

from fenicsfriction.studies.brake import geometry

if __name__ == "__main__":
    p = parser("brake", __doc__)
    defaults = geometry.BrakeGeometry()
    p.add_argument("--h", type=float, default=0.006,
                   help="tetrahedra size [m] (6 mm: 1.6e4 unknowns, 2.8 mm: 1.2e5)")
    p.add_argument("--free-disc", action="store_true",
                   help="mesh the disc freely (gmsh) instead of from identical sectors")
    for name, value in vars(defaults).items():
        unit = "degrees" if name == "pad_angle" else "m"
        p.add_argument(f"--{name.replace('_', '-')}", type=float, default=value,
                       help=f"{name} [{unit}]")
    args = p.parse_args()
    dims = geometry.BrakeGeometry(**{k: getattr(args, k) for k in vars(defaults)})
    pathlib.Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    m = geometry.brake(MPI.COMM_SELF, h=args.h, geometry=dims, msh_file=str(args.out),
                       symmetric_disc=not args.free_disc)
    vertices = m.mesh.topology.index_map(0).size_global
    print(f"{args.out}: {m.mesh.topology.index_map(3).size_global} tetrahedra, {vertices} "
          f"vertices ({3 * vertices} unknowns), {time.perf_counter() - start:.1f} s")
    for tag, name in geometry.NAMES.items():
        data = m.cell_tags if tag < 10 else m.facet_tags
        print(f"  {name} = {tag}: {int(np.count_nonzero(data.values == tag))}")
