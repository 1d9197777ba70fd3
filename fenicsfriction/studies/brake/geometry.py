r"""The simplified disc brake's mesh: an annular disc and two pads pressed on its faces.

The disc is an annulus (inner radius ``r_hub``, outer ``r_disc``, thickness ``thickness``)
centred on the z axis, its mid-plane z = 0, clamped on its inner cylinder (the hub). It is
described in Eulerian form: the mesh does not turn, the rotation enters only through the
disc's velocity at the contact (the transport velocity of the friction law). The two pads are
annular sectors (radii ``pad_r_in``, ``pad_r_out``, opening ``pad_angle`` about the +x axis,
thickness ``pad_thickness``) lying on the disc's faces: the inboard pad under z = -h/2, the
outboard pad over z = +h/2. No backplate: the pressure acts on the pads' backs.

The three bodies are meshed apart (no common node: the meshes do not match on the contact
faces) with tetrahedra of size ``h`` (degree-1 geometry), on rank 0 of ``comm``, and read into
one distributed dolfinx mesh.

Tags (module constants; the gmsh physical groups carry the names in brackets):

==================  =====  =======================================================
name                value  entities
==================  =====  =======================================================
:data:`DISC`        1      the disc's cells (``disc``)
:data:`PAD_IN`      2      the inboard pad's cells (``pad-in``)
:data:`PAD_OUT`     3      the outboard pad's cells (``pad-out``)
:data:`DISC_HUB`    10     the disc's inner cylinder, clamped (``disc-hub``)
:data:`DISC_TOP`    11     the disc's face z = +h/2, master of the outboard pad (``disc-top``)
:data:`DISC_BOTTOM` 12     the disc's face z = -h/2, master of the inboard pad (``disc-bottom``)
:data:`PAD_IN_FACE` 20     the inboard pad's friction face, slave (``pad-in-face``)
:data:`PAD_OUT_FACE` 21    the outboard pad's friction face, slave (``pad-out-face``)
:data:`PAD_IN_BACK` 22     the inboard pad's back, under pressure (``pad-in-back``)
:data:`PAD_OUT_BACK` 23    the outboard pad's back, under pressure (``pad-out-back``)
:data:`PAD_IN_ABUTMENT` 24   the inboard pad's two radial end faces (``pad-in-abutment``)
:data:`PAD_OUT_ABUTMENT` 25  the outboard pad's two radial end faces (``pad-out-abutment``)
==================  =====  =======================================================

The disc's rim and the pads' cylindrical sides are free and untagged.
"""

from __future__ import annotations

import dataclasses
import math
import typing

from mpi4py import MPI

from fenicsfriction import laws
from fenicsfriction.meshing import gmsh_mesh

__all__ = ["DISC", "DISC_BOTTOM", "DISC_HUB", "DISC_TOP", "NAMES", "PAD_IN", "PAD_IN_ABUTMENT",
           "PAD_IN_BACK", "PAD_IN_FACE", "PAD_OUT", "PAD_OUT_ABUTMENT", "PAD_OUT_BACK",
           "PAD_OUT_FACE", "BrakeGeometry", "BrakeMesh", "brake"]

#: cell tag of the disc
DISC = 1
#: cell tag of the inboard pad (z < 0)
PAD_IN = 2
#: cell tag of the outboard pad (z > 0)
PAD_OUT = 3
#: facet tag of the disc's inner cylinder, clamped
DISC_HUB = 10
#: facet tag of the disc's face z = +h/2, the outboard pad's master surface
DISC_TOP = 11
#: facet tag of the disc's face z = -h/2, the inboard pad's master surface
DISC_BOTTOM = 12
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
         DISC_TOP: "disc-top", DISC_BOTTOM: "disc-bottom", PAD_IN_FACE: "pad-in-face",
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
    """

    mesh: typing.Any
    cell_tags: typing.Any
    facet_tags: typing.Any
    geometry: BrakeGeometry
    h: float

    @property
    def parameters(self) -> dict:
        return {"geometry": "brake", **dataclasses.asdict(self.geometry), "h": self.h}


def _sector(occ: typing.Any, r_in: float, r_out: float, angle: float, z0: float,
            height: float) -> int:
    """An annular sector r_in <= r <= r_out, |θ| <= angle/2, z0 <= z <= z0 + height."""
    outer = occ.addCylinder(0, 0, z0, 0, 0, height, r_out, angle=math.radians(angle))
    inner = occ.addCylinder(0, 0, z0, 0, 0, height, r_in, angle=math.radians(angle))
    (kind, volume), = occ.cut([(3, outer)], [(3, inner)])[0]
    occ.rotate([(3, volume)], 0, 0, 0, 0, 0, 1, -math.radians(angle) / 2)
    return volume


def _classify(gmsh: typing.Any, volume: int, rules: dict[int, typing.Callable]) -> dict:
    """The boundary faces of ``volume`` sorted by the first rule they pass (tag -> test of the
    face's centre of mass and of its largest distance to the axis, from its bounding box: a
    whole cylinder has its centre on the axis); faces passing none are left out."""
    found: dict[int, list[int]] = {tag: [] for tag in rules}
    for _, face in gmsh.model.getBoundary([(3, volume)], oriented=False):
        x, y, z = gmsh.model.occ.getCenterOfMass(2, face)
        box = gmsh.model.getBoundingBox(2, face)
        reach = max(abs(box[0]), abs(box[1]), abs(box[3]), abs(box[4]))
        for tag, rule in rules.items():
            if rule(x, y, z, reach):
                found[tag].append(face)
                break
    return found


def brake(comm: MPI.Comm, h: float = 0.006, geometry: BrakeGeometry | None = None,
          msh_file: str | None = None) -> BrakeMesh:
    """Mesh the disc and its two pads with tetrahedra of size ``h``.

    Args:
        comm: the communicator the mesh is distributed over (gmsh runs on its rank 0).
        h: the tetrahedra's size [m] (6 mm: about 2e4 unknowns; 3 mm: 1e5).
        geometry: the dimensions (default :class:`BrakeGeometry`).
        msh_file: if given, rank 0 writes the gmsh mesh there (``.msh``).

    Returns:
        The mesh, its tags (the module's table) and the parameters.
    """
    laws.check_positive("h", h)
    g = geometry or BrakeGeometry()
    half, tp = g.thickness / 2, g.pad_thickness
    tol = 1e-6 * g.r_disc

    def construct(gmsh: typing.Any) -> None:
        occ = gmsh.model.occ
        disc_outer = occ.addCylinder(0, 0, -half, 0, 0, g.thickness, g.r_disc)
        hub = occ.addCylinder(0, 0, -half, 0, 0, g.thickness, g.r_hub)
        (_, disc), = occ.cut([(3, disc_outer)], [(3, hub)])[0]
        pad_in = _sector(occ, g.pad_r_in, g.pad_r_out, g.pad_angle, -half - tp, tp)
        pad_out = _sector(occ, g.pad_r_in, g.pad_r_out, g.pad_angle, half, tp)
        occ.synchronize()  # no fragment: the bodies keep their own faces and nodes

        faces = _classify(gmsh, disc, {
            DISC_TOP: lambda x, y, z, reach: abs(z - half) < tol,
            DISC_BOTTOM: lambda x, y, z, reach: abs(z + half) < tol,
            # the bounding box of a cylinder is its radius, up to gmsh's tolerance
            DISC_HUB: lambda x, y, z, reach: reach < 0.5 * (g.r_hub + g.r_disc)})
        for volume, face, back, abutment, sign in (
                (pad_in, PAD_IN_FACE, PAD_IN_BACK, PAD_IN_ABUTMENT, -1),
                (pad_out, PAD_OUT_FACE, PAD_OUT_BACK, PAD_OUT_ABUTMENT, 1)):
            faces.update(_classify(gmsh, volume, {
                face: lambda x, y, z, reach, s=sign: abs(z - s * half) < tol,
                back: lambda x, y, z, reach, s=sign: abs(z - s * (half + tp)) < tol,
                # the end faces are planes through the axis: their centres at angle ±α/2
                abutment: lambda x, y, z, reach: abs(abs(math.degrees(math.atan2(y, x)))
                                              - g.pad_angle / 2) < 1e-3}))
        for tag, entities in ((DISC, [disc]), (PAD_IN, [pad_in]), (PAD_OUT, [pad_out])):
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
    return BrakeMesh(msh, cell_tags, facet_tags, g, h)
