"""Write the rolling scene's half-space (a block graded from the contact zone, quadrilaterals in
2D, hexahedra in 3D) as a gmsh mesh: ``python meshes/rolling.py --dim 3 --out rolling_3d.msh``."""

import pathlib
import time

from mpi4py import MPI

from _common import parser

from fenicsfriction.studies.rolling import geometry

#: per dimension: cells over a and the block's half-width and depth over a (the 2D half-plane's
#: displacement diverges logarithmically: its block is wider)
DEFAULTS = {2: (32, 1000.0), 3: (8, 20.0)}

if __name__ == "__main__":
    p = parser("rolling", __doc__)
    p.add_argument("--dim", type=int, choices=[2, 3], default=3, help="2 or 3 (3)")
    p.add_argument("--a", type=float, default=1.0, help="contact semi-axis along x")
    p.add_argument("--b", type=float, default=1.0, help="contact semi-axis along y (3D)")
    p.add_argument("--cells-per-a", type=int, help="cells over a (2D: 32, 3D: 8)")
    p.add_argument("--block-size", type=float, help="half-width and depth / a (2D: 1000, 3D: 20)")
    p.add_argument("--growth", type=float, default=1.3, help="cell growth outside the contact")
    args = p.parse_args()
    cells, block = DEFAULTS[args.dim]
    cells = args.cells_per_a or cells
    block = args.block_size or block
    zone = [args.a, args.b][:args.dim - 1]
    pathlib.Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    m = geometry.half_space(MPI.COMM_SELF, args.dim, zone, args.a / cells, block * args.a,
                            args.growth, msh_file=str(args.out))
    print(f"{args.out}: {m.parameters} ({time.perf_counter() - start:.1f} s)")
