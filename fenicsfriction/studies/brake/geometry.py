r"""The simplified disc brake's mesh: an annular disc and two pads pressed on its faces.

The disc is the brake-squeal scenes' disc
(:class:`fenicsfriction.discs.Disc`), meshed by default from identical
sectors (:func:`~fenicsfriction.discs.add_symmetric_disc`: its doublets stay
exactly degenerate, only the pads split them), or freely like the pin on the disc's
(:func:`~fenicsfriction.discs.add_disc`): an annulus about the z
axis (inner radius ``r_hub``, outer ``r_disc``), its top face z = 0, its bottom z =
-``thickness``, clamped on its inner cylinder (the hub). It is described in Eulerian form: the
mesh does not turn, the rotation enters only through the disc's velocity at the contact (the
transport velocity of the friction law). The two pads are annular sectors (radii
``pad_r_in``, ``pad_r_out``, opening ``pad_angle`` about the +x axis, thickness
``pad_thickness``) lying on the disc's faces: the outboard pad on the top face, the inboard
pad under the bottom one. No backplate: the pressure acts on the pads' backs.

The three bodies are meshed apart (no common node: the meshes do not match on the contact
faces) with tetrahedra of size ``h`` (degree-1 geometry), on rank 0 of ``comm``, and read into
one distributed dolfinx mesh.

Tags (the disc's are those of :mod:`fenicsfriction.discs`; the gmsh physical
groups carry the names in brackets):

=========================  =====  ================================================================
name                       value  entities
=========================  =====  ================================================================
``DISC``                   1      the disc's cells (``disc``)
:data:`PAD_IN`             2      the inboard pad's cells (``pad-in``)
:data:`PAD_OUT`            3      the outboard pad's cells (``pad-out``)
``DISC_HUB``               10     the disc's inner cylinder, clamped (``disc-hub``)
``DISC_TOP``               11     the disc's face z = 0, master of the outboard pad (``disc-top``)
``DISC_BOTTOM``            12     the face z = -thickness, master of the inboard pad
                                  (``disc-bottom``)
``DISC_RIM``               13     the disc's outer cylinder, free (``disc-rim``)
:data:`PAD_IN_FACE`        20     the inboard pad's friction face, slave (``pad-in-face``)
:data:`PAD_OUT_FACE`       21     the outboard pad's friction face, slave (``pad-out-face``)
:data:`PAD_IN_BACK`        22     the inboard pad's back, under pressure (``pad-in-back``)
:data:`PAD_OUT_BACK`       23     the outboard pad's back, under pressure (``pad-out-back``)
:data:`PAD_IN_ABUTMENT`    24     the inboard pad's two radial end faces (``pad-in-abutment``)
:data:`PAD_OUT_ABUTMENT`   25     the outboard pad's two radial end faces (``pad-out-abutment``)
=========================  =====  ================================================================

The pads' cylindrical sides are free and untagged.
"""

from __future__ import annotations

import dataclasses
import math
import typing

from mpi4py import MPI

from fenicsfriction import laws
from fenicsfriction.discs import (
    DISC,
    DISC_BOTTOM,
    DISC_HUB,
    DISC_RIM,
    DISC_TOP,
    Disc,
    add_disc,
    add_symmetric_disc,
    disc_groups,
)
from fenicsfriction.meshing import gmsh_mesh

__all__ = ["NAMES", "PAD_IN", "PAD_IN_ABUTMENT", "PAD_IN_BACK", "PAD_IN_FACE", "PAD_OUT",
           "PAD_OUT_ABUTMENT", "PAD_OUT_BACK", "PAD_OUT_FACE", "BrakeGeometry", "BrakeMesh",
           "brake"]

#: cell tag of the inboard pad (z < 0)
PAD_IN = 2
#: cell tag of the outboard pad (z > 0)
PAD_OUT = 3
#: facet tag of the inboard pad's friction face (slave)
PAD_IN_FACE = 20
#: facet tag of the outboard pad's friction face (slave)
PAD_OUT_FACE = 21
#: facet tag of the inboard pad's back, under the pressure
PAD_IN_BACK = 22
#: facet tag of the outboard pad's back, under the pressure
PAD_OUT_BACK = 23
#: facet tag of the inboard pad's two radial end faces, held in their plane
PAD_IN_ABUTMENT = 24
#: facet tag of the outboard pad's two radial end faces, held in their plane
PAD_OUT_ABUTMENT = 25

#: the physical groups' names
NAMES = {DISC: "disc", PAD_IN: "pad-in", PAD_OUT: "pad-out", DISC_HUB: "disc-hub",
         DISC_TOP: "disc-top", DISC_BOTTOM: "disc-bottom", DISC_RIM: "disc-rim",
         PAD_IN_FACE: "pad-in-face",
         PAD_OUT_FACE: "pad-out-face", PAD_IN_BACK: "pad-in-back", PAD_OUT_BACK: "pad-out-back",
         PAD_IN_ABUTMENT: "pad-in-abutment", PAD_OUT_ABUTMENT: "pad-out-abutment"}


@dataclasses.dataclass(frozen=True)
class BrakeGeometry:
    """The brake's dimensions [m] and opening [degrees]; the defaults are a small car's solid
    front disc (280 mm) with pads of about 50 cm².

    Attributes:
        r_hub: the disc's inner radius, where it is clamped [m].
        r_disc: the disc's outer radius [m].
        thickness: the disc's thickness h [m].
        pad_r_in, pad_r_out: the pads' inner and outer radii [m], within the disc's.
        pad_angle: the pads' opening about the +x axis [degrees], in (0, 180).
        pad_thickness: the pads' thickness [m].
    """

    r_hub: float = 0.06
    r_disc: float = 0.14
    thickness: float = 0.012
    pad_r_in: float = 0.09
    pad_r_out: float = 0.135
    pad_angle: float = 55.0
    pad_thickness: float = 0.01

    def __post_init__(self) -> None:
        for name in ("r_hub", "r_disc", "thickness", "pad_r_in", "pad_r_out", "pad_angle",
                     "pad_thickness"):
            laws.check_positive(name, getattr(self, name))
        laws.check("r_disc", self.r_disc, self.r_disc > self.r_hub, "must be > r_hub")
        laws.check("pad_r_in", self.pad_r_in, self.r_hub < self.pad_r_in < self.pad_r_out,
                   "must lie in (r_hub, pad_r_out)")
        laws.check("pad_r_out", self.pad_r_out, self.pad_r_out <= self.r_disc, "must be <= r_disc")
        laws.check("pad_angle", self.pad_angle, self.pad_angle < 180, "must be < 180 degrees")

    @property
    def pad_area(self) -> float:
        """One pad's friction face [m²]."""
        return math.radians(self.pad_angle) / 2 * (self.pad_r_out**2 - self.pad_r_in**2)

    @property
    def mean_radius(self) -> float:
        """The pads' mean radius (pad_r_in + pad_r_out) / 2 [m]."""
        return 0.5 * (self.pad_r_in + self.pad_r_out)


@dataclasses.dataclass
class BrakeMesh:
    """The brake's distributed mesh, its tags and what it was made with.

    Attributes:
        mesh: the dolfinx mesh (tetrahedra, degree-1 geometry).
        cell_tags: :data:`DISC`, :data:`PAD_IN`, :data:`PAD_OUT`.
        facet_tags: the facet tags of the module's table.
        geometry: the dimensions.
        h: the mesh size [m].
        symmetric_disc: whether the disc's mesh is made of identical sectors.
    """

    mesh: typing.Any
    cell_tags: typing.Any
    facet_tags: typing.Any
    geometry: BrakeGeometry
    h: float
    symmetric_disc: bool = True

    @property
    def parameters(self) -> dict:
        return {"geometry": "brake", **dataclasses.asdict(self.geometry), "h": self.h,
                "symmetric_disc": self.symmetric_disc}


def _sector(occ: typing.Any, r_in: float, r_out: float, angle: float, z0: float,
            height: float) -> int:
    """An annular sector r_in <= r <= r_out, |θ| <= angle/2, z0 <= z <= z0 + height."""
    outer = occ.addCylinder(0, 0, z0, 0, 0, height, r_out, angle=math.radians(angle))
    inner = occ.addCylinder(0, 0, z0, 0, 0, height, r_in, angle=math.radians(angle))
    (kind, volume), = occ.cut([(3, outer)], [(3, inner)])[0]
    occ.rotate([(3, volume)], 0, 0, 0, 0, 0, 1, -math.radians(angle) / 2)
    return volume


def _classify(gmsh: typing.Any, volume: int, rules: dict[int, typing.Callable]) -> dict:
    """The boundary faces of a pad ``volume`` sorted by the first rule (tag -> test of the
    face's centre of mass) they pass; faces passing none are left out."""
    found: dict[int, list[int]] = {tag: [] for tag in rules}
    for _, face in gmsh.model.getBoundary([(3, volume)], oriented=False):
        x, y, z = gmsh.model.occ.getCenterOfMass(2, face)
        for tag, rule in rules.items():
            if rule(x, y, z):
                found[tag].append(face)
                break
    return found


def brake(comm: MPI.Comm, h: float = 0.006, geometry: BrakeGeometry | None = None,
          msh_file: str | None = None, symmetric_disc: bool = True) -> BrakeMesh:
    """Mesh the disc and its two pads with tetrahedra of size ``h``.

    The disc's mesh is by default rotationally symmetric
    (:func:`~fenicsfriction.discs.add_symmetric_disc`: identical sectors,
    so that the disc alone has exactly degenerate doublets and only the pads split them, as
    in brake CEA practice); ``symmetric_disc=False`` gives the squeal scenes' free
    tetrahedral mesh (:func:`~fenicsfriction.discs.add_disc`), whose own
    asymmetry splits the doublets by a few Hz (docs/brake.md).

    Args:
        comm: the communicator the mesh is distributed over (gmsh runs on its rank 0).
        h: the tetrahedra's size [m] (6 mm: about 2e4 unknowns; 3 mm: 1e5).
        geometry: the dimensions (default :class:`BrakeGeometry`).
        msh_file: if given, rank 0 writes the gmsh mesh there (``.msh``).
        symmetric_disc: the disc made of identical sectors (default) or meshed freely.

    Returns:
        The mesh, its tags (the module's table) and the parameters.
    """
    laws.check_positive("h", h)
    g = geometry or BrakeGeometry()
    disc_shape = Disc(inner_radius=g.r_hub, outer_radius=g.r_disc, thickness=g.thickness)
    top, bottom, tp = 0.0, -g.thickness, g.pad_thickness
    tol = 1e-6 * g.r_disc

    def construct(gmsh: typing.Any) -> None:
        occ = gmsh.model.occ
        disc = None if symmetric_disc else add_disc(gmsh, disc_shape)
        pad_in = _sector(occ, g.pad_r_in, g.pad_r_out, g.pad_angle, bottom - tp, tp)
        pad_out = _sector(occ, g.pad_r_in, g.pad_r_out, g.pad_angle, top, tp)
        occ.synchronize()  # no fragment: the bodies keep their own faces and nodes
        if disc is None:
            faces = add_symmetric_disc(gmsh, disc_shape, h)
            disc_cells = faces.pop(DISC)
        else:
            faces, disc_cells = disc_groups(gmsh, disc_shape, disc), [disc]
        for volume, face, back, abutment, z_face, z_back in (
                (pad_in, PAD_IN_FACE, PAD_IN_BACK, PAD_IN_ABUTMENT, bottom, bottom - tp),
                (pad_out, PAD_OUT_FACE, PAD_OUT_BACK, PAD_OUT_ABUTMENT, top, top + tp)):
            faces.update(_classify(gmsh, volume, {
                face: lambda x, y, z, zf=z_face: abs(z - zf) < tol,
                back: lambda x, y, z, zb=z_back: abs(z - zb) < tol,
                # the end faces are planes through the axis: their centres at angle ±α/2
                abutment: lambda x, y, z: abs(abs(math.degrees(math.atan2(y, x)))
                                              - g.pad_angle / 2) < 1e-3}))
        for tag, entities in ((DISC, disc_cells), (PAD_IN, [pad_in]), (PAD_OUT, [pad_out])):
            gmsh.model.addPhysicalGroup(3, entities, tag)
            gmsh.model.setPhysicalName(3, tag, NAMES[tag])
        for tag, entities in faces.items():
            if not entities:
                raise RuntimeError(f"no face found for the {NAMES[tag]} tag {tag}")
            gmsh.model.addPhysicalGroup(2, entities, tag)
            gmsh.model.setPhysicalName(2, tag, NAMES[tag])
        for option in ("MeshSizeFromPoints", "MeshSizeFromCurvature",
                       "MeshSizeExtendFromBoundary"):
            gmsh.option.setNumber(f"Mesh.{option}", 0)
        gmsh.option.setNumber("Mesh.MeshSizeMin", h)
        gmsh.option.setNumber("Mesh.MeshSizeMax", h)

    msh, cell_tags, facet_tags = gmsh_mesh(comm, "brake", 3, construct, msh_file)
    return BrakeMesh(msh, cell_tags, facet_tags, g, h, symmetric_disc)
