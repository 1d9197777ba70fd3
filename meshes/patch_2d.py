"""Write the 2D patch scene (two stacked blocks, non-matching interface) as a gmsh mesh."""

from _common import build, parser

from fenicsfriction.studies.contact import geometry

if __name__ == "__main__":
    p = parser("patch_2d", __doc__)
    p.add_argument("--n-upper", type=int, default=5, help="elements across body 1")
    p.add_argument("--n-lower", type=int, default=7, help="elements across body 2")
    p.add_argument("--width", type=float, default=1.0)
    p.add_argument("--height", type=float, default=1.0)
    args = p.parse_args()
    build(geometry.patch_2d, args.out, n_upper=args.n_upper, n_lower=args.n_lower,
          width=args.width, height=args.height)
