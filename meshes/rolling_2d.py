"""Write the 2D rolling scene's half-space (a graded block, quadrilaterals/hexahedra) as a gmsh
mesh."""

import pathlib
import time

from mpi4py import MPI

from _common import parser

from fenicsfriction.scenes.rolling import geometry

if __name__ == "__main__":
    p = parser("rolling_2d", __doc__)
    p.add_argument("--a", type=float, default=1.0, help="contact semi-axis along x")
    p.add_argument("--cells-per-a", type=int, default=32, help="cells over a")
    p.add_argument("--block-size", type=float, default=1000.0, help="half-width and depth / a")
    p.add_argument("--growth", type=float, default=1.3, help="cell growth outside the contact")
    args = p.parse_args()
    zone = [args.a]
    pathlib.Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    m = geometry.half_space(MPI.COMM_SELF, 2, zone, args.a / args.cells_per_a,
                            args.block_size * args.a, args.growth, msh_file=str(args.out))
    print(f"{args.out}: {m.parameters} ({time.perf_counter() - start:.1f} s)")
