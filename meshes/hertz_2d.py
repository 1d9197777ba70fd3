"""Write the 2D Hertz scene (half-cylinder on a block, plane strain) as a gmsh mesh."""

from _common import build, parser

from fenicsfriction.studies.contact import geometry

if __name__ == "__main__":
    p = parser("hertz_2d", __doc__)
    p.add_argument("--R", type=float, default=1.0, help="cylinder radius")
    p.add_argument("--refine", type=int, default=0, help="halve the mesh sizes this many times")
    p.add_argument("--h-contact", type=float, default=None, help="size at the contact (0.005R)")
    p.add_argument("--h-far", type=float, default=None, help="largest size (0.5R)")
    args = p.parse_args()
    build(geometry.hertz_2d, args.out, R=args.R, refine=args.refine, h_contact=args.h_contact,
          h_far=args.h_far)
