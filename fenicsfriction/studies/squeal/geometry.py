r"""Meshes of the brake-squeal scenes: an annular disc and the bodies pressed on it.

The disc (:mod:`fenicsfriction.discs`, shared with the simplified brake) and the pin pressed
on it (:func:`pin_on_disc`). Coordinates: the disc's
axis is z, its top face z = 0, its bottom z = -thickness; it spans inner_radius <= r <=
outer_radius and is clamped on its inner rim (the hub). Sliding is a rotation ω e_z of the
disc, so at a point (x, y) of its surface the disc moves with ω e_z × x, along e_θ.

Each body is meshed on its own: bodies pressed on the disc share no node with it, their meshes
do not match on the contact surfaces, and the contact is node-to-segment
(:class:`~fenicsfriction.contact.NodeToSegment`, degree-1 tetrahedra). Physical groups carry
both a number and a name (the case files select them by name):

====================  =====  ================================================================
name                  value  entities
====================  =====  ================================================================
``disc``              1      the disc's cells
``pin``               2      the pin's cells
``disc-hub``          10     the disc's inner rim r = inner_radius (clamped)
``disc-top``          11     the disc's top face z = 0 (the master surface)
``disc-bottom``       12     the disc's bottom face z = -thickness
``disc-rim``          13     the disc's outer rim r = outer_radius
``pin-face``          20     the pin's end pressed on the disc (the slave surface)
``pin-top``           21     the pin's other end (loaded, held by its holder)
``pin-side``          22     the pin's free cylindrical side
``pin-held``          23     the pin's side in its holder (the sleeve at its top)
====================  =====  ================================================================

The pin-on-disc mesh is written in the pin's frame: built as above, it is then turned about the
x axis by the pin's inclination α (:class:`Pin`), so that the pin's axis is e_z and its
holder holds the x and y components (a case file can say so), while the disc's axis becomes
:attr:`Pin.disc_axis` = (0, -sin α, cos α) through the origin.

The disc's groups are those of :mod:`fenicsfriction.discs`.
"""

from __future__ import annotations

import dataclasses
import math
import typing

from mpi4py import MPI

import numpy as np

from fenicsfriction import laws
from fenicsfriction.discs import (
    DISC,
    DISC_NAMES,
    Disc,
    add_disc,
    disc_groups,
)
from fenicsfriction.meshing import gmsh_mesh

__all__ = [
    "NAMES",
    "PIN",
    "PIN_FACE",
    "PIN_HELD",
    "PIN_SIDE",
    "PIN_TOP",
    "Pin",
    "PinOnDiscMesh",
    "add_groups",
    "pin_on_disc",
]

#: cell tag of the pin
PIN = 2
#: facet tag of the pin's end pressed on the disc (the slave surface)
PIN_FACE = 20
#: facet tag of the pin's top (loaded)
PIN_TOP = 21
#: facet tag of the pin's free side
PIN_SIDE = 22
#: facet tag of the pin's side in its holder
PIN_HELD = 23

#: the physical groups' names, by tag
NAMES = {**DISC_NAMES, PIN: "pin", PIN_FACE: "pin-face", PIN_TOP: "pin-top",
         PIN_SIDE: "pin-side", PIN_HELD: "pin-held"}


@dataclasses.dataclass(frozen=True)
class Pin:
    """A cylindrical pin pressed on the disc's top face (lengths in metres, angle in degrees).

    The pin's axis passes through the contact point (radius, 0, 0) of the disc's top face, in
    the plane x = radius spanned by e_z and the sliding direction e_y = e_θ, at ``angle`` from
    e_z: its unit vector is a = (0, sin α, cos α), so a pin leaning with α > 0 has its top
    downstream of its face for a disc turning ω e_z with ω > 0 (its end is dragged, a pulled
    pin); α < 0 pushes it (a sprag). The end pressed on the disc is the cylinder cut by the
    plane z = 0 (an ellipse of semi-axes r and r / cos α), the top is perpendicular to a at
    distance ``length`` from the contact point along the axis. Its last ``held`` along the
    axis sits in a holder (a sleeve): that part of its side is tagged apart, so that a model
    can hold it across the axis there, which clamps the pin's bending and leaves its axial
    motion free. (All this in the disc's frame; the mesh of :func:`pin_on_disc` is turned
    into the pin's, where a = e_z and the disc's axis is :attr:`disc_axis`.)

    Args:
        radius: the contact point's distance from the disc's axis, R_p [m].
        pin_radius: the cylinder's radius [m].
        length: from the contact point to the top's centre, along the axis [m].
        angle: α, the axis's inclination from e_z towards e_θ [degrees], |α| < 60.
        held: the length of the pin in its holder [m], < length.
    """

    radius: float = 0.065
    pin_radius: float = 0.004
    length: float = 0.05
    angle: float = 20.0
    held: float = 0.01

    def __post_init__(self) -> None:
        for name in ("radius", "pin_radius", "length", "held"):
            laws.check_positive(name, getattr(self, name))
        laws.check("held", self.held, self.held < self.length, f"must be < length = {self.length}")
        laws.check("angle", self.angle, abs(self.angle) < 60, "must lie in (-60, 60) degrees")

    @property
    def disc_axis(self) -> tuple[float, float, float]:
        """The disc's axis in the pin's frame (the mesh's): (0, -sin α, cos α)."""
        alpha = math.radians(self.angle)
        return (0.0, -math.sin(alpha), math.cos(alpha))

    @property
    def axis(self) -> tuple[float, float, float]:
        """The unit vector a of the pin's axis, towards its top, in the disc's frame."""
        alpha = math.radians(self.angle)
        return (0.0, math.sin(alpha), math.cos(alpha))

    @property
    def face_area(self) -> float:
        """The area of the pressed end, π r² / cos α [m²]."""
        return math.pi * self.pin_radius**2 / math.cos(math.radians(self.angle))

    @property
    def top_area(self) -> float:
        """The area of the top, π r² [m²]."""
        return math.pi * self.pin_radius**2


@dataclasses.dataclass
class PinOnDiscMesh:
    """The pin and the disc in one distributed mesh (tetrahedra, P1 geometry).

    Attributes:
        mesh: the dolfinx mesh.
        cell_tags: :data:`DISC`, :data:`PIN`.
        facet_tags: the faces of the table in the module docstring.
        disc, pin: the geometry.
        parameters: the mesh sizes in use.
    """

    mesh: typing.Any
    cell_tags: typing.Any
    facet_tags: typing.Any
    disc: Disc
    pin: Pin
    parameters: dict


def add_groups(gmsh: typing.Any, dim: int, groups: dict[int, list[int]]) -> None:
    """One named physical group per tag (names from :data:`NAMES`)."""
    for tag, entities in groups.items():
        if not entities:
            raise RuntimeError(f"no entity found for the group {NAMES[tag]} ({tag})")
        gmsh.model.addPhysicalGroup(dim, entities, tag)
        gmsh.model.setPhysicalName(dim, tag, NAMES[tag])


def _add_pin(gmsh: typing.Any, pin: Pin) -> list[int]:
    """The pin's two volumes: its free part, from the face (the cylinder cut by z = 0), and
    the part in its holder, sharing their interface."""
    occ = gmsh.model.occ
    a = pin.axis
    # start far enough below z = 0 that the cut leaves the whole ellipse of the face
    below = 2 * pin.pin_radius * abs(a[1]) / a[2] + pin.pin_radius
    start = [pin.radius - 0.0, -below * a[1], -below * a[2]]
    free = pin.length - pin.held + below
    cylinder = occ.addCylinder(*start, *(free * c for c in a), pin.pin_radius)
    size = 4 * (pin.length + pin.pin_radius)
    half_space = occ.addBox(pin.radius - size, -size, -size, 2 * size, 2 * size, size)
    (_, lower), = occ.cut([(3, cylinder)], [(3, half_space)])[0]
    base = [s + free * c for s, c in zip(start, a, strict=True)]
    upper = occ.addCylinder(*base, *(pin.held * c for c in a), pin.pin_radius)
    pieces, _ = occ.fragment([(3, lower)], [(3, upper)])
    return [tag for _, tag in pieces]


def pin_on_disc(comm: MPI.Comm, disc: Disc = Disc(), pin: Pin = Pin(), h_far: float = 0.008,
                h_contact: float | None = None, h_pin: float | None = None,
                refine: int = 0, msh_file: str | None = None) -> PinOnDiscMesh:
    """A pin pressed on the disc's top face (tetrahedra; tags in the module docstring), in
    the pin's frame: the pin's axis is e_z, its face's centre (the contact point) at
    (radius, 0, 0), the disc's axis :attr:`Pin.disc_axis` through the origin.

    Mesh sizes: ``h_contact`` (default pin_radius / 2) within 3 pin radii of the contact
    point, growing by 0.5 per unit distance up to ``h_far`` in the disc; the pin has the size
    ``h_pin`` (default pin_radius / 2, at most ``h_far``) along its length. ``refine`` halves
    all three that many times (about 8 times the cells each): the mesh-convergence parameter.

    Args:
        comm: the communicator the mesh is distributed over (gmsh runs on its rank 0).
        disc, pin: the geometry.
        h_far: the largest mesh size, in the disc away from the pin [m].
        h_contact: the size near the contact [m].
        h_pin: the size in the pin [m].
        refine: halvings of the three sizes.
        msh_file: if given, rank 0 writes the gmsh mesh there (``.msh``).

    Returns:
        The mesh, its tags and the sizes in use (``parameters``).
    """
    laws.check_positive("h_far", h_far)
    laws.check("refine", refine, isinstance(refine, int) and refine >= 0,
               "must be an integer >= 0")
    h_c = pin.pin_radius / 2 if h_contact is None else h_contact
    h_p = min(pin.pin_radius / 2, h_far) if h_pin is None else h_pin
    laws.check_positive("h_contact", h_c)
    laws.check_positive("h_pin", h_p)
    scale = 0.5**refine
    h_f, h_c, h_p = h_far * scale, min(h_c, h_far) * scale, h_p * scale

    def construct(gmsh: typing.Any) -> None:
        disc_volume = add_disc(gmsh, disc)
        pin_volumes = _add_pin(gmsh, pin)
        gmsh.model.occ.synchronize()
        tol = 1e-3 * disc.thickness  # OpenCASCADE pads bounding boxes by ~1e-7
        groups = disc_groups(gmsh, disc, disc_volume)
        groups.update({PIN_FACE: [], PIN_TOP: [], PIN_SIDE: [], PIN_HELD: []})
        a = pin.axis
        boundary = gmsh.model.getBoundary([(3, v) for v in pin_volumes], oriented=False)
        for _, face in boundary:
            box = gmsh.model.getBoundingBox(2, face)
            height = (np.array(gmsh.model.occ.getCenterOfMass(2, face))
                      - [pin.radius, 0.0, 0.0]) @ np.array(a)
            plane = gmsh.model.getType(2, face) == "Plane"
            if abs(box[2]) < tol and abs(box[5]) < tol:
                groups[PIN_FACE].append(face)
            elif plane:
                groups[PIN_TOP].append(face)
            elif height > pin.length - pin.held:
                groups[PIN_HELD].append(face)
            else:
                groups[PIN_SIDE].append(face)
        # into the pin's frame: a turn by α about the x axis (through the contact point).
        # OpenCASCADE renumbers the faces it turns: they are found again by their centres
        # and areas (the hub's and the rim's centres coincide)
        angle = math.radians(pin.angle)
        turn = np.array([[1, 0, 0], [0, math.cos(angle), -math.sin(angle)],
                         [0, math.sin(angle), math.cos(angle)]])

        def signature(face: int, rotation: np.ndarray) -> np.ndarray:
            centre = rotation @ gmsh.model.occ.getCenterOfMass(2, face)
            return np.append(centre, math.sqrt(gmsh.model.occ.getMass(2, face)))

        keys = {face: signature(face, turn) for faces in groups.values() for face in faces}
        gmsh.model.occ.rotate([(3, v) for v in (disc_volume, *pin_volumes)],
                              0, 0, 0, 1, 0, 0, angle)
        gmsh.model.occ.synchronize()
        now = [(face, signature(face, np.eye(3))) for _, face in gmsh.model.getEntities(2)]
        renamed = {old: min(now, key=lambda f: float(np.linalg.norm(f[1] - k)))[0]
                   for old, k in keys.items()}
        add_groups(gmsh, 3, {DISC: [disc_volume], PIN: pin_volumes})
        add_groups(gmsh, 2, {tag: [renamed[f] for f in faces] for tag, faces in groups.items()})
        # the pin at its own size along its length, the disc refined under it
        field = gmsh.model.mesh.field
        pin_zone = field.add("Ball")
        middle = [pin.radius, 0.0, pin.length / 2]
        for key, value in (("XCenter", middle[0]), ("YCenter", middle[1]),
                           ("ZCenter", middle[2]), ("Radius", pin.length / 2 + 2 * h_p),
                           ("VIn", h_p), ("VOut", h_f)):
            field.setNumber(pin_zone, key, value)
        contact = field.add("Ball")
        for key, value in (("XCenter", pin.radius), ("YCenter", 0.0), ("ZCenter", 0.0),
                           ("Radius", 3 * pin.pin_radius), ("VIn", h_c), ("VOut", h_f),
                           ("Thickness", (h_f - h_c) / 0.5)):
            field.setNumber(contact, key, value)
        smallest = field.add("Min")
        field.setNumbers(smallest, "FieldsList", [pin_zone, contact])
        field.setAsBackgroundMesh(smallest)
        for option in ("MeshSizeFromPoints", "MeshSizeFromCurvature",
                       "MeshSizeExtendFromBoundary"):
            gmsh.option.setNumber(f"Mesh.{option}", 0)

    msh, cell_tags, facet_tags = gmsh_mesh(comm, "pin_on_disc", 3, construct, msh_file)
    return PinOnDiscMesh(msh, cell_tags, facet_tags, disc, pin,
                         {"h_far": h_f, "h_contact": h_c, "h_pin": h_p, "refine": refine})
