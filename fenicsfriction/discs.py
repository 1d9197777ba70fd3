r"""An annular disc for the scenes of a body pressed on a turning disc (a pin on a disc, a
disc brake), built in gmsh: its dimensions, its volume and faces, its physical groups.

Coordinates: the disc's axis is z, its top face z = 0, its bottom z = -thickness; it spans
inner_radius <= r <= outer_radius and is clamped on its inner rim (the hub). Sliding is a
rotation ω e_z of the disc, described in Eulerian fashion (its mesh does not turn), so at a
point (x, y) of its surface the disc moves with ω e_z × x, along e_θ.

Two ways to put it in the gmsh model being built: :func:`add_disc` (an OpenCASCADE volume, meshed
with the rest; tag its faces with :func:`disc_groups`, size the mesh near the contacts with
:func:`refine_near`), or :func:`add_symmetric_disc` (already meshed from identical sectors: its
doublets stay exactly degenerate, so a mode coupling's onset is the other bodies', not the
mesh's). :class:`Disc` holds the dimensions, with the defaults of a small steel brake disc.

====================  =====  ================================================================
name                  value  entities
====================  =====  ================================================================
``disc``              1      the disc's cells
``disc-hub``          10     the inner rim r = inner_radius (clamped)
``disc-top``          11     the top face z = 0 (a master surface)
``disc-bottom``       12     the bottom face z = -thickness
``disc-rim``          13     the outer rim r = outer_radius
====================  =====  ================================================================
"""

from __future__ import annotations

import dataclasses
import math
import typing

import numpy as np

from fenicsfriction import laws

__all__ = ["DISC", "DISC_BOTTOM", "DISC_HUB", "DISC_NAMES", "DISC_RIM", "DISC_TOP", "Disc",
           "add_disc", "add_symmetric_disc", "disc_groups", "refine_near"]

#: cell tag of the disc
DISC = 1
#: facet tag of the disc's inner rim (the hub, clamped)
DISC_HUB = 10
#: facet tag of the disc's top face (the master surface)
DISC_TOP = 11
#: facet tag of the disc's bottom face
DISC_BOTTOM = 12
#: facet tag of the disc's outer rim
DISC_RIM = 13
#: the disc's physical groups' names, by tag
DISC_NAMES = {DISC: "disc", DISC_HUB: "disc-hub", DISC_TOP: "disc-top",
              DISC_BOTTOM: "disc-bottom", DISC_RIM: "disc-rim"}


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
