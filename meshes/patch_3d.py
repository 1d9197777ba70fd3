"""Write the 3D patch scene (two stacked blocks, non-matching interface) as a gmsh mesh."""

from _common import build, parser

from fenicsfriction.studies.contact import geometry

if __name__ == "__main__":
    p = parser("patch_3d", __doc__)
    p.add_argument("--n-upper", type=int, default=4, help="elements across body 1")
    p.add_argument("--n-lower", type=int, default=5, help="elements across body 2")
    p.add_argument("--width", type=float, default=1.0)
    p.add_argument("--height", type=float, default=1.0)
    args = p.parse_args()
    build(geometry.patch_3d, args.out, n_upper=args.n_upper, n_lower=args.n_lower,
          width=args.width, height=args.height)
