r"""Meshes of the brake-squeal scenes: an annular disc and the bodies pressed on it.

The disc is shared by every scene (:func:`add_disc`): the pin on the disc (:func:`pin_on_disc`)
and the simplified brake's pads add their bodies above or below it. Coordinates: the disc's
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

For another scene on the same disc (the brake's pads), call :func:`add_disc` in the gmsh
model being built (the disc frame), tag its volume and faces with :func:`disc_groups`, and
size the mesh with :func:`refine_near`; or add the disc already meshed from identical sectors
with :func:`add_symmetric_disc` (exact doublets: a mode coupling's onset is then the other
bodies', not the mesh's); :class:`Disc` holds the disc's dimensions with the
defaults of a small steel brake disc.
"""

from __future__ import annotations

import dataclasses
import math
import typing

from mpi4py import MPI

import numpy as np

from fenicsfriction import laws
from fenicsfriction.meshing import gmsh_mesh

__all__ = [
    "DISC",
    "DISC_BOTTOM",
    "DISC_HUB",
    "DISC_RIM",
    "DISC_TOP",
    "NAMES",
    "PIN",
    "PIN_FACE",
    "PIN_HELD",
    "PIN_SIDE",
    "PIN_TOP",
    "Disc",
    "Pin",
    "PinOnDiscMesh",
    "add_disc",
    "add_symmetric_disc",
    "disc_groups",
    "pin_on_disc",
    "refine_near",
]

#: cell tag of the disc
DISC = 1
#: cell tag of the pin
PIN = 2
#: facet tag of the disc's inner rim (the hub, clamped)
DISC_HUB = 10
#: facet tag of the disc's top face (the master surface)
DISC_TOP = 11
#: facet tag of the disc's bottom face
DISC_BOTTOM = 12
#: facet tag of the disc's outer rim
DISC_RIM = 13
#: facet tag of the pin's end pressed on the disc (the slave surface)
PIN_FACE = 20
#: facet tag of the pin's top (loaded)
PIN_TOP = 21
#: facet tag of the pin's free side
PIN_SIDE = 22
#: facet tag of the pin's side in its holder
PIN_HELD = 23

#: the physical groups' names, by tag
NAMES = {DISC: "disc", PIN: "pin", DISC_HUB: "disc-hub", DISC_TOP: "disc-top",
         DISC_BOTTOM: "disc-bottom", DISC_RIM: "disc-rim", PIN_FACE: "pin-face",
         PIN_TOP: "pin-top", PIN_SIDE: "pin-side", PIN_HELD: "pin-held"}


@dataclasses.dataclass(frozen=True)
class Disc:
    """An annular disc, axis z, top face z = 0 (lengths in metres).

    Args:
        inner_radius: the hub's radius, where the disc is clamped [m].
        outer_radius: the rim's radius [m].
        thickness: [m]; the disc spans -thickness <= z <= 0.
    """

    inner_radius: float = 0.03
    outer_radius: float = 0.1
    thickness: float = 0.01

    def __post_init__(self) -> None:
        for name in ("inner_radius", "outer_radius", "thickness"):
            laws.check_positive(name, getattr(self, name))
        laws.check("outer_radius", self.outer_radius, self.outer_radius > self.inner_radius,
                   f"must be > inner_radius = {self.inner_radius}")


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


def add_disc(gmsh: typing.Any, disc: Disc) -> int:
    """Add the disc to the current gmsh model (OpenCASCADE kernel, not synchronised): the
    annulus inner_radius <= r <= outer_radius, -thickness <= z <= 0. Returns its volume tag."""
    occ = gmsh.model.occ
    outer = occ.addCylinder(0, 0, -disc.thickness, 0, 0, disc.thickness, disc.outer_radius)
    inner = occ.addCylinder(0, 0, -disc.thickness, 0, 0, disc.thickness, disc.inner_radius)
    (_, volume), = occ.cut([(3, outer)], [(3, inner)])[0]
    return volume


def add_symmetric_disc(gmsh: typing.Any, disc: Disc, h: float) -> dict[int, list[int]]:
    """Add the disc to the current gmsh model as a mesh with the disc's rotational symmetry:
    ``n`` identical sectors, each a rotated copy of the first (node for node), so that the
    mesh splits no doublet (an n-nodal-diameter pair stays degenerate to round-off for
    2 n_d < n). Call it after the other bodies are synchronised; they mesh as usual, the
    disc's mesh is already there (gmsh's discrete entities: a volume and its four faces).

    The cross-section (r, z) is a grid of ``round((outer - inner) / h)`` by ``max(2,
    round(thickness / h))`` squares, each cut into two triangles; it is revolved in ``n =
    ceil(2π r_mean / h)`` steps (r_mean the mean radius: edges of length h there), each
    prism cut into three tetrahedra by the rule of Dompierre, Labbé, Vallet & Camarero (1999,
    "How to subdivide pyramids, prisms and hexahedra into tetrahedra") on the cross-section's
    node numbers, the same in every sector, so that neighbouring prisms share their faces'
    diagonals. The spacing is uniform (a grading would have to depend on r and z only, to
    keep the sectors identical).

    Args:
        gmsh: the gmsh module, a model open (synchronised).
        disc: the disc's dimensions.
        h: the target edge length [m].

    Returns:
        The volume's entity under :data:`DISC` and the faces' under :data:`DISC_HUB`,
        :data:`DISC_TOP`, :data:`DISC_BOTTOM`, :data:`DISC_RIM`.
    """
    laws.check_positive("h", h)
    n_r = max(1, round((disc.outer_radius - disc.inner_radius) / h))
    n_z = max(2, round(disc.thickness / h))
    n = math.ceil(math.pi * (disc.inner_radius + disc.outer_radius) / h)
    r = np.linspace(disc.inner_radius, disc.outer_radius, n_r + 1)
    z = np.linspace(-disc.thickness, 0.0, n_z + 1)
    section = (n_r + 1) * (n_z + 1)  # cross-section nodes, index i * (n_z + 1) + k

    def index(i: int | np.ndarray, k: int | np.ndarray) -> np.ndarray:
        return np.asarray(i) * (n_z + 1) + k

    i, k = (a.ravel() for a in np.meshgrid(np.arange(n_r), np.arange(n_z), indexing="ij"))
    a, b, c, d = index(i, k), index(i + 1, k), index(i, k + 1), index(i + 1, k + 1)
    triangles = np.sort(np.concatenate([np.column_stack([a, b, d]),
                                        np.column_stack([a, d, c])]), axis=1)
    # the sectors' nodes: sector s holds the cross-section at angle 2π s / n
    theta = 2 * np.pi * np.arange(n) / n
    rr, zz = np.meshgrid(r, z, indexing="ij")
    rr, zz = rr.ravel(), zz.ravel()
    xyz = np.stack([np.outer(np.cos(theta), rr), np.outer(np.sin(theta), rr),
                    np.broadcast_to(zz, (n, section))], axis=-1).reshape(-1, 3)

    def node(s: np.ndarray, j: np.ndarray) -> np.ndarray:
        return (s % n)[:, None] * section + j[None, :] + 1  # gmsh's tags from 1

    s = np.arange(n)
    p, q, t = triangles.T  # p < q < t: the diagonals p-q', p-t', q-t' on the side faces
    tets = np.concatenate([
        np.stack([node(s, p), node(s, q), node(s, t), node(s + 1, t)], axis=-1),
        np.stack([node(s, p), node(s, q), node(s + 1, q), node(s + 1, t)], axis=-1),
        np.stack([node(s, p), node(s + 1, p), node(s + 1, q), node(s + 1, t)], axis=-1),
    ]).reshape(-1, 4)
    corners = xyz[tets - 1]
    volume = np.einsum("ij,ij->i", np.cross(corners[:, 1] - corners[:, 0],
                                            corners[:, 2] - corners[:, 0]),
                       corners[:, 3] - corners[:, 0])
    tets[volume < 0] = tets[volume < 0][:, [0, 2, 1, 3]]

    def band(edges: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
        """The triangles of the revolved cross-section's boundary edges (j0, j1)."""
        j0 = np.concatenate([e[0] for e in edges])
        j1 = np.concatenate([e[1] for e in edges])
        lo, hi = np.minimum(j0, j1), np.maximum(j0, j1)  # the diagonal lo-hi' as above
        return np.concatenate([
            np.stack([node(s, lo), node(s, hi), node(s + 1, hi)], axis=-1),
            np.stack([node(s, lo), node(s + 1, lo), node(s + 1, hi)], axis=-1)]).reshape(-1, 3)

    rows, cols = np.arange(n_r), np.arange(n_z)
    faces = {DISC_HUB: band([(index(0, cols), index(0, cols + 1))]),
             DISC_RIM: band([(index(n_r, cols), index(n_r, cols + 1))]),
             DISC_TOP: band([(index(rows, n_z), index(rows + 1, n_z))]),
             DISC_BOTTOM: band([(index(rows, 0), index(rows + 1, 0))])}
    model = gmsh.model
    existing = model.mesh.getNodes()[0]  # gmsh 4.8 has no getMaxNodeTag
    offset = int(existing.max()) if len(existing) else 0
    first = offset + 1
    volume_tag = model.addDiscreteEntity(3)
    model.mesh.addNodes(3, volume_tag, np.arange(first, first + len(xyz)), xyz.ravel())
    element = 1 + max((int(t.max()) for t in model.mesh.getElements()[1] if len(t)), default=0)
    model.mesh.addElementsByType(volume_tag, 4, np.arange(element, element + len(tets)),
                                 (tets + offset).ravel())
    element += len(tets)
    groups: dict[int, list[int]] = {DISC: [volume_tag]}
    for tag, triangles_of_face in faces.items():
        face = model.addDiscreteEntity(2)
        model.mesh.addElementsByType(face, 2, np.arange(element, element + len(triangles_of_face)),
                                     (triangles_of_face + offset).ravel())
        element += len(triangles_of_face)
        groups[tag] = [face]
    return groups


def _boundary(gmsh: typing.Any, volume: int) -> list[tuple[int, list[float]]]:
    faces = gmsh.model.getBoundary([(3, volume)], oriented=False)
    return [(t, list(gmsh.model.getBoundingBox(d, t))) for d, t in faces]


def disc_groups(gmsh: typing.Any, disc: Disc, volume: int) -> dict[int, list[int]]:
    """The disc's faces by tag (:data:`DISC_HUB`, :data:`DISC_TOP`, :data:`DISC_BOTTOM`,
    :data:`DISC_RIM`), found by their bounding boxes (after ``occ.synchronize()``)."""
    tol = 1e-3 * disc.thickness  # OpenCASCADE pads bounding boxes by ~1e-7
    groups: dict[int, list[int]] = {DISC_HUB: [], DISC_TOP: [], DISC_BOTTOM: [], DISC_RIM: []}
    for face, box in _boundary(gmsh, volume):
        if abs(box[2]) < tol and abs(box[5]) < tol:
            groups[DISC_TOP].append(face)
        elif abs(box[2] + disc.thickness) < tol and abs(box[5] + disc.thickness) < tol:
            groups[DISC_BOTTOM].append(face)
        elif abs(box[3] - disc.inner_radius) < tol:
            groups[DISC_HUB].append(face)
        else:
            groups[DISC_RIM].append(face)
    return groups


def add_groups(gmsh: typing.Any, dim: int, groups: dict[int, list[int]]) -> None:
    """One named physical group per tag (names from :data:`NAMES`)."""
    for tag, entities in groups.items():
        if not entities:
            raise RuntimeError(f"no entity found for the group {NAMES[tag]} ({tag})")
        gmsh.model.addPhysicalGroup(dim, entities, tag)
        gmsh.model.setPhysicalName(dim, tag, NAMES[tag])


def refine_near(gmsh: typing.Any, points: typing.Sequence[tuple[float, float, float]],
                radius: float, h_near: float, h_far: float, grading: float = 0.5) -> None:
    """Mesh size ``h_near`` within ``radius`` of each of ``points``, growing linearly with the
    distance beyond (by ``grading`` per unit length) up to ``h_far`` everywhere else."""
    field = gmsh.model.mesh.field
    balls = []
    for x, y, z in points:
        ball = field.add("Ball")
        for key, value in (("XCenter", x), ("YCenter", y), ("ZCenter", z), ("Radius", radius),
                           ("VIn", h_near), ("VOut", h_far),
                           ("Thickness", (h_far - h_near) / grading)):
            field.setNumber(ball, key, value)
        balls.append(ball)
    smallest = field.add("Min")
    field.setNumbers(smallest, "FieldsList", balls)
    field.setAsBackgroundMesh(smallest)
    for option in ("MeshSizeFromPoints", "MeshSizeFromCurvature", "MeshSizeExtendFromBoundary"):
        gmsh.option.setNumber(f"Mesh.{option}", 0)


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
