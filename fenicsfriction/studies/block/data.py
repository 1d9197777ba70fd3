r"""The block on a moving belt of Martins & Oden (1986, Figs. 6-15): its data.

Units are the paper's: mass 10^3 kg, length cm, time s (so force 10^3 kg cm s^-2 and stress
10^3 kg cm^-1 s^-2). The defaults are eq. (36)-(37) with the driver spring of the FE dynamics
(Figs. 13-15).

Choices the paper leaves open, made here and changeable through the fields:

* **Plane strain with breadth B0.** B0 is the block's breadth out of the plane (the
  plane-strain thickness): every 2D integral is multiplied by B0, so forces are totals, the
  contact pressure is force / (L B0), and ``mass``/``weight`` are totals over that breadth.
  With ``dim=3`` the block is a box L × H × B0 (breadth along z, hexahedra) with free faces
  at z = 0 and z = B0, and the spring node is at mid-breadth. Nothing restrains translation
  along z or rotation about y (only the transverse friction damping c_T d^m_T / |U_T| acts on
  them), so the symmetry plane z = B0/2 is held in z: exact for the symmetric steady state,
  and it removes those two rigid modes from the eigenproblem.
* **Weight as a body force** ρ g = W / (L H B0), mass density ρ = M / (L H B0).
* **Driver spring through the centre of mass.** A horizontal nodal spring of total stiffness
  K_x on the node of the left face at height ``spring_height`` (default H/2, the height of
  the centre of mass): its line of action is horizontal at that height, which gives the
  tipping limit μ < L/(2 h_s) = L/H = 1.6 and a tangential mode ±i sqrt(K_x/M) that does
  not move with μ. Mesh rows are shifted so that a node lies at that height (no shift for
  H/2). The spring is anchored at zero displacement: its elongation is -u_x at the node.
* **Belt** along ``belt_direction`` × e_x at ``belt_speed``; friction drags the block that
  way and the spring holds it back.
* **Contact** on the bottom face y = 0 (outward normal -e_y), initial gap g (default 0).
  The contact integrals use a fixed quadrature rule so that the reported resultants are
  computed exactly as the residual integrates them.
* **Discrete tipping limit.** The normal resultant cannot lie further out than the outermost
  contact quadrature point, so steady sliding exists only up to
  μ_h = (L/2 - s_1)/h_s (s_1: that point's distance from the corner). Gauss points
  (default, ``contact_quadrature="gauss"``) give μ_h → L/(2 h_s) as the mesh is refined;
  Gauss-Lobatto points (``"gll"``) include the corners, so μ_h = L/(2 h_s) on any mesh.
* **Nodal contact rule.** ``contact_quadrature="nodal"`` (degree 1, 2D) integrates Γ_C with
  the trapezoidal rule on the facets' vertices, each node carrying its tributary length: the
  rule of node-to-segment contact on its slave side, so the one-body counterpart of the block
  on a stiff slab. FFCx's ``"gll"`` rule is not that on Q1: its degree (2p + 5) gives five
  points per facet, and the nodal rule's rotational stiffness of the interface is higher
  (μ_crit 0.247 against 0.369 on the 4 × 3 Q1 mesh).
"""

from __future__ import annotations

import dataclasses
import typing

import numpy as np

from fenicsfriction import laws
from fenicsfriction.laws import check

if typing.TYPE_CHECKING:
    from mpi4py import MPI

    from fenicsfriction.studies.block.model import BlockModel

__all__ = ["CONTACT", "LEFT", "QUADRATURE", "RIGHT", "TOP", "BlockData", "BlockOnBelt"]

#: facet tags of the block's mesh: the base on the belt (Γ_C), the top and the two sides
CONTACT, TOP, LEFT, RIGHT = 1, 2, 3, 4


def _gauss(degree: int) -> tuple[np.ndarray, dict]:
    """Gauss points on [0, 1] of the contact rule and its UFL metadata."""
    q = 2 * degree + 4
    x = (np.polynomial.legendre.leggauss(q // 2 + 1)[0] + 1) / 2
    return x, {"quadrature_degree": q}


def _gll(degree: int) -> tuple[np.ndarray, dict]:
    """Gauss-Lobatto points (corners included) and metadata; FFCx uses (q+3)/2 points."""
    q = 2 * degree + 5
    return np.array([0.0, 1.0]), {"quadrature_degree": q, "quadrature_rule": "GLL"}


def _nodal(degree: int) -> tuple[np.ndarray, dict]:
    """The nodal (trapezoidal) rule of degree-1 facets: their two vertices, equal weights; the
    model takes its metadata from :func:`fenicsfriction._compat.nodal_quadrature`."""
    return np.array([0.0, 1.0]), {}


#: the contact rules of ``BlockData.contact_quadrature``: name -> (points on [0, 1], UFL metadata)
QUADRATURE = {"gauss": _gauss, "gll": _gll, "nodal": _nodal}


@dataclasses.dataclass
class BlockData:
    """The block, its interface and its driver: what the FE and the rigid models share.

    Args:
        L: length of the block along the belt [cm].
        H: height of the block [cm].
        B0: breadth out of the plane, the plane-strain thickness [cm].
        mass: total mass M [10^3 kg].
        weight: total weight W, applied as a body force [10^3 kg cm s^-2].
        law: the interface law (:class:`~fenicsfriction.laws.InterfaceLaw`, in the units
            above: c_n [10^3 kg cm^(-1-m_n) s^-2], b_n [10^3 kg cm^(-2-l_n) s^-1], g [cm],
            ε [cm/s]); default the paper's, eq. (36), with μ = 0. Change it with
            ``dataclasses.replace(scene, law=scene.law.replace(mu=0.3))``.
        belt_speed: |U_T| [cm/s], > 0.
        belt_direction: +1 (belt moves along +x) or -1.
        K_x: total stiffness of the driver spring [10^3 kg s^-2].
        spring_height: height of the spring's line of action [cm] (None: H/2).
    """

    L: float = 48.8
    H: float = 30.5
    B0: float = 30.5
    mass: float = 0.45
    weight: float = 450.0
    law: laws.InterfaceLaw = dataclasses.field(default_factory=laws.InterfaceLaw)
    belt_speed: float = 0.287
    belt_direction: int = 1
    K_x: float = 11.1
    spring_height: float = None  # type: ignore[assignment]  # None: set by __post_init__

    def __post_init__(self):
        if self.spring_height is None:
            self.spring_height = self.H / 2
        self.validate()

    def validate(self) -> None:
        """Raise ``ValueError`` naming the first parameter out of its range."""
        for name in ("L", "H", "B0", "mass", "K_x", "belt_speed"):
            value = getattr(self, name)
            check(name, value, np.isfinite(value) and value > 0, "must be a finite number > 0")
        check("weight", self.weight, self.weight >= 0, "must be >= 0")
        check("belt_direction", self.belt_direction, self.belt_direction in (1, -1),
              "must be +1 or -1")
        check("spring_height", self.spring_height, 0 <= self.spring_height <= self.H,
              f"must lie in [0, H] = [0, {self.H}]")
        check("law", self.law, isinstance(self.law, laws.InterfaceLaw),
              "must be a fenicsfriction.laws.InterfaceLaw (it validates its own parameters)")

    def with_law(self, **changes: typing.Any) -> typing.Self:
        """The scene with its law changed, e.g. ``scene.with_law(mu=0.3)``."""
        return dataclasses.replace(self, law=self.law.replace(**changes))

    @property
    def tipping_limit(self) -> float:
        """μ at which the normal resultant reaches the front corner: L / (2 h_s)."""
        return self.L / (2 * self.spring_height) if self.spring_height > 0 else np.inf


@dataclasses.dataclass
class BlockOnBelt(BlockData):
    """The block-on-belt scene: :class:`BlockData` and the finite element model's own data.

    Args:
        E: Young's modulus [10^3 kg cm^-1 s^-2].
        nu: Poisson's ratio [-].
        top_pressure: uniform pressure on the top face [10^3 kg cm^-1 s^-2] (0 in the paper).
        refine: mesh refinement factor; the mesh has 4·refine × 3·refine cells.
        degree: polynomial degree of the Lagrange quadrilaterals (2: nine-node Q2).
        contact_quadrature: "gauss", "gll" (Gauss-Lobatto, includes the corners) or "nodal"
            (trapezoidal on the vertices; degree 1, 2D) on Γ_C.
        dim: 2 (plane strain, the paper's model) or 3 (a box, 4r × 3r × nz·r hexahedra).
        nz: cells across the breadth per refinement in 3D (even, so a node row is at B0/2).
        Other parameters: see :class:`BlockData`.
    """

    E: float = 1.4e6
    nu: float = 0.25
    top_pressure: float = 0.0
    refine: int = 1
    degree: int = 2
    contact_quadrature: str = "gauss"
    dim: int = 2
    nz: int = 2

    def validate(self) -> None:
        super().validate()
        check("E", self.E, np.isfinite(self.E) and self.E > 0, "must be a finite number > 0")
        check("nu", self.nu, -1 < self.nu < 0.5, "Poisson's ratio must lie in (-1, 0.5)")
        check("top_pressure", self.top_pressure, self.top_pressure >= 0, "must be >= 0")
        check("weight", self.weight, self.weight + self.top_pressure > 0,
              "weight and top_pressure cannot both be 0: nothing presses the block on the belt")
        check("refine", self.refine, isinstance(self.refine, int) and self.refine >= 1,
              "must be an integer >= 1")
        check("degree", self.degree, self.degree in (1, 2, 3), "must be 1, 2 or 3")
        check("dim", self.dim, self.dim in (2, 3), "must be 2 or 3")
        check("nz", self.nz, isinstance(self.nz, int) and self.nz >= 2 and self.nz % 2 == 0,
              "must be an even integer >= 2")
        check("contact_quadrature", self.contact_quadrature,
              self.contact_quadrature in QUADRATURE, f"must be one of {sorted(QUADRATURE)}")
        self.check_contact_rule()

    def check_contact_rule(self) -> None:
        """Raise ``ValueError`` if ``contact_quadrature`` does not fit the elements: the
        nodal rule is the trapezoidal rule on degree-1 facets in 2D."""
        check("contact_quadrature", self.contact_quadrature,
              self.contact_quadrature != "nodal" or (self.degree == 1 and self.dim == 2),
              "the nodal rule is for degree 1 in 2D (trapezoidal on the facets' vertices)")

    @property
    def contact_pressure(self) -> float:
        """Mean contact pressure (W + p_top L B0) / (L B0) at equilibrium."""
        return self.weight / (self.L * self.B0) + self.top_pressure

    @property
    def discrete_tipping_limit(self) -> float:
        """μ at which the resultant reaches the outermost contact quadrature point."""
        if self.spring_height == 0:
            return np.inf
        points = QUADRATURE[self.contact_quadrature](self.degree)[0]
        s_1 = points.min() * self.L / (4 * self.refine)
        return (self.L / 2 - s_1) / self.spring_height

    def build(self, comm: MPI.Comm | None = None,
              with_friction: bool | None = None) -> BlockModel:
        """Mesh, spaces, the residual and its parameters as ``fem.Constant``.

        Args:
            comm: communicator the mesh is distributed over (default ``MPI.COMM_WORLD``).
            with_friction: include the friction term; default only when the law has friction
                (μ > 0, a friction coefficient law or a slip rule): a frictionless scene
                assembles no friction, and its μ cannot be stepped away from 0 afterwards.

        Returns:
            The built :class:`~fenicsfriction.studies.block.model.BlockModel`.
        """
        from mpi4py import MPI

        from fenicsfriction.studies.block.model import BlockModel
        return BlockModel(self, MPI.COMM_WORLD if comm is None else comm, with_friction)
