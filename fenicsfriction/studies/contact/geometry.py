r"""Meshes of the two-body contact scenes: two disjoint bodies in one dolfinx mesh.

Each builder makes a gmsh model of two bodies that share no node (each body is meshed on its
own, so the meshes do not match on the contact surfaces), on rank 0 of ``comm``, and reads it
into a distributed dolfinx mesh with the physical tags below. Body 1 is the slave body (its
nodes are the contact candidates), body 2 the master body (its facets are the segments).

Tags (cells: :data:`BODY1`, :data:`BODY2`; facets: the rest):

======================  =====  ==========================================================
name                    value  facets
======================  =====  ==========================================================
:data:`SLAVE`           10     body 1's candidate contact surface
:data:`LOAD`            11     body 1's loaded face
:data:`MASTER`          20     body 2's candidate contact surface
:data:`FIXED`           21     body 2's clamped bottom
:data:`SYMMETRY_X`      30     the plane x = 0, both bodies (3D quarter models only)
:data:`SYMMETRY_Y`      31     the plane y = 0, both bodies (3D quarter models only)
======================  =====  ==========================================================

Other boundary facets (the blocks' far sides, the patch bodies' lateral faces) are untagged.
The Hertz scenes put a node of each body at the origin, where they touch (zero initial gap
there); the patch scenes' bodies touch along the whole plane y = 0 (2D) or z = 0 (3D).

The builders own the gmsh session: they initialise gmsh without the user's configuration
files, set ``Mesh.*`` options, and finalise it; where gmsh has ``isInitialized`` (not 4.8) and
reports a session open already, they use it and remove only their own model. Geometry is P1:
the cylinder's arc and the sphere are approximated by the chords and flat triangles of their
boundary facets, whose vertices lie on the exact surface.

In parallel, ``partition="graph"`` (the default) leaves the mesh to dolfinx's graph
partitioner, which sees two disconnected bodies: on two ranks it puts (nearly) all of body 1 on
one rank and body 2 on the other, so that one rank has every slave node and the contact search
and the slave side's contact work are all its own. ``partition="contact"`` cuts both bodies
across the contact plane instead, by a coordinate in that plane (x for the cylinder and the
patches; the angle about the z axis for the quarter sphere, whose contact patch is a quarter
disc around the origin): the cells sorted by it are shared out in equal runs, so that each
rank holds a slice of each body, of the slave surface and of the master surface under it
(:func:`fenicsfriction._compat.key_partitioner`).
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import typing

from mpi4py import MPI

import numpy as np

from fenicsfriction import laws
from fenicsfriction.meshing import gmsh_mesh

__all__ = [
    "BODY1",
    "BODY2",
    "FIXED",
    "LOAD",
    "MASTER",
    "SLAVE",
    "SYMMETRY_X",
    "SYMMETRY_Y",
    "PARTITIONS",
    "TwoBodyMesh",
    "hertz_2d",
    "hertz_3d",
    "patch_2d",
    "patch_3d",
]

#: cell tag of body 1, the slave body (cylinder, sphere or upper block)
BODY1 = 1
#: cell tag of body 2, the master body (the lower block)
BODY2 = 2
#: facet tag of body 1's candidate contact surface
SLAVE = 10
#: facet tag of body 1's loaded face
LOAD = 11
#: facet tag of body 2's candidate contact surface
MASTER = 20
#: facet tag of body 2's clamped bottom
FIXED = 21
#: facet tag of the symmetry plane x = 0 (both bodies; 3D quarter models)
SYMMETRY_X = 30
#: facet tag of the symmetry plane y = 0 (both bodies; 3D quarter models)
SYMMETRY_Y = 31

#: how the mesh is partitioned: dolfinx's graph partitioner, or cut across the contact
PARTITIONS = ("graph", "contact")

_NAMES = {BODY1: "body1", BODY2: "body2", SLAVE: "slave", LOAD: "load", MASTER: "master",
          FIXED: "fixed", SYMMETRY_X: "symmetry_x", SYMMETRY_Y: "symmetry_y"}

#: numbers the gmsh models, so that each call's model has its own name


@dataclasses.dataclass
class TwoBodyMesh:
    """Two disjoint bodies in one distributed mesh, with their tags.

    Attributes:
        mesh: The dolfinx mesh (triangles in 2D, tetrahedra in 3D; P1 geometry).
        cell_tags: :data:`BODY1` / :data:`BODY2` on every cell.
        facet_tags: :data:`SLAVE`, :data:`LOAD`, :data:`MASTER`, :data:`FIXED` and, on the
            quarter models, :data:`SYMMETRY_X`, :data:`SYMMETRY_Y`.
        parameters: The geometry's name (``"geometry"``) and the parameters the mesh was made
            with, defaults filled in and mesh sizes after ``refine`` (the ones in use).
    """

    mesh: typing.Any
    cell_tags: typing.Any
    facet_tags: typing.Any
    parameters: dict


# --- input checks ------------------------------------------------------------------------------

def _check_int(name: str, value: typing.Any, lowest: int) -> None:
    ok = isinstance(value, numbers.Integral) and not isinstance(value, bool) \
        and int(value) >= lowest
    laws.check(name, value, ok, f"must be an integer >= {lowest}")


def _check_sizes(R: float, h_contact: float, h_far: float, refine_half_width: float,
                 refine: int, grading: float) -> None:
    laws.check_positive("h_contact", h_contact)
    laws.check_positive("h_far", h_far)
    laws.check("h_far", h_far, h_far >= h_contact, f"must be >= h_contact = {h_contact}")
    laws.check_positive("refine_half_width", refine_half_width)
    laws.check("refine_half_width", refine_half_width, h_contact <= refine_half_width <= R,
               f"must lie in [h_contact, R] = [{h_contact}, {R}]")
    _check_int("refine", refine, 0)
    laws.check_positive("grading", grading)


def _default(value: float | None, scale: float) -> float:
    return scale if value is None else value


# --- the gmsh session on rank 0 (fenicsfriction.meshing) ---------------------------------------

def _build(comm: MPI.Comm, name: str, gdim: int, construct: typing.Callable[[typing.Any], None],
           msh_file: str | None, parameters: dict, partition: str = "graph",
           key: typing.Callable[[typing.Any], typing.Any] | None = None) -> TwoBodyMesh:
    """:func:`~fenicsfriction.meshing.gmsh_mesh` with the parameters the mesh was made with;
    ``partition="contact"`` cuts the cells by ``key`` of their centroids."""
    laws.check("partition", partition, partition in PARTITIONS, f"one of {', '.join(PARTITIONS)}")
    msh, cell_tags, facet_tags = gmsh_mesh(comm, name, gdim, construct, msh_file,
                                           partition_key=key if partition == "contact" else None)
    return TwoBodyMesh(msh, cell_tags, facet_tags,
                       {"geometry": name, **parameters, "partition": partition})


def _along_x(centroids: typing.Any) -> typing.Any:
    return centroids[:, 0]


def _around_z(centroids: typing.Any) -> typing.Any:
    return np.arctan2(centroids[:, 1], centroids[:, 0])


def _add_groups(gmsh: typing.Any, dim: int, groups: dict[int, list[int]]) -> None:
    """One physical group per tag (``groups``: tag -> entities of dimension ``dim``)."""
    for tag, entities in groups.items():
        if not entities:
            raise RuntimeError(f"no entity found for the {_NAMES[tag]} tag {tag}")
        gmsh.model.addPhysicalGroup(dim, entities, tag)
        gmsh.model.setPhysicalName(dim, tag, _NAMES[tag])


def _boundary(gmsh: typing.Any, dim: int, tag: int) -> list[tuple[int, list[float]]]:
    """The boundary entities of entity ``(dim, tag)`` with their bounding boxes
    ``[xmin, ymin, zmin, xmax, ymax, zmax]``."""
    faces = gmsh.model.getBoundary([(dim, tag)], oriented=False)
    return [(t, list(gmsh.model.getBoundingBox(d, t))) for d, t in faces]


def _flat(box: list[float], axis: int, value: float, tol: float) -> bool:
    """Whether a bounding box is flat in ``axis`` at ``value``."""
    return abs(box[axis] - value) < tol and abs(box[axis + 3] - value) < tol


def _refine_near_origin(gmsh: typing.Any, h_contact: float, h_far: float, half_width: float,
                        grading: float, depth: float | None = None) -> None:
    """Mesh size ``h_contact`` in the box |x|, |y| <= ``half_width``, |z| <= ``depth``
    (default ``half_width``), growing linearly with the distance from it (by ``grading`` per
    unit length) up to ``h_far``."""
    depth = half_width if depth is None else depth
    field = gmsh.model.mesh.field
    box = field.add("Box")
    for key, value in (("VIn", h_contact), ("VOut", h_far), ("XMin", -half_width),
                       ("XMax", half_width), ("YMin", -half_width), ("YMax", half_width),
                       ("ZMin", -depth), ("ZMax", depth),
                       ("Thickness", (h_far - h_contact) / grading)):
        field.setNumber(box, key, value)
    field.setAsBackgroundMesh(box)
    # the field alone sets the size: not the points, not the curvature, not the boundary
    for option in ("MeshSizeFromPoints", "MeshSizeFromCurvature", "MeshSizeExtendFromBoundary"):
        gmsh.option.setNumber(f"Mesh.{option}", 0)


# --- Hertz: a cylinder / sphere on a block -----------------------------------------------------

def _hertz_sizes(R: float, block_half_width: float | None, block_height: float | None,
                 h_contact: float | None, h_far: float | None,
                 refine_half_width: float | None, refine: int, grading: float,
                 defaults: tuple[float, float]) -> tuple[float, float, float, float, float]:
    """The Hertz scenes' checked block size and mesh sizes (W, H, h_contact, h_far after
    ``refine``, and the refined zone's half-width); ``defaults``: h_contact and the zone's
    half-width per unit R."""
    laws.check_positive("R", R)
    W = _default(block_half_width, 4 * R)
    H = _default(block_height, 4 * R)
    laws.check("block_half_width", W, isinstance(W, numbers.Real) and W >= R,
               f"must be >= R = {R}")
    laws.check_positive("block_height", H)
    h_c, h_f = _default(h_contact, defaults[0] * R), _default(h_far, 0.5 * R)
    w = _default(refine_half_width, defaults[1] * R)
    _check_sizes(R, h_c, h_f, w, refine, grading)
    return W, H, h_c / 2**refine, h_f / 2**refine, w


def hertz_2d(comm: MPI.Comm, R: float = 1.0, block_half_width: float | None = None,
             block_height: float | None = None, h_contact: float | None = None,
             h_far: float | None = None, refine_half_width: float | None = None,
             refine: int = 0, grading: float = 0.3, msh_file: str | None = None,
             partition: str = "graph") -> TwoBodyMesh:
    """A half-cylinder on a block, plane strain (triangles).

    Body 1 is the lower half-disc of radius ``R`` centred at (0, R): its lowest point touches the
    block at the origin. Its flat top (y = R, |x| <= R) is :data:`LOAD`; its whole lower arc is
    :data:`SLAVE` (a slave node's gap decides whether it touches, and the whole arc has the
    closed-form length πR; the nodes far from the contact cost little). Body 2 is the block
    [-W, W] x [-H, 0]: its top y = 0 is :data:`MASTER`, its bottom y = -H :data:`FIXED`. Each
    body has a node at the origin.

    Args:
        comm: The communicator the mesh is distributed over (gmsh runs on its rank 0).
        R: The cylinder's radius.
        block_half_width: W (default 4R); at least R, so that the block lies under the cylinder.
        block_height: H (default 4R).
        h_contact: Mesh size near the contact (default 0.005R), before ``refine``.
        h_far: Largest mesh size, away from the contact (default 0.5R), before ``refine``.
        refine_half_width: Half-width of the square |x|, |y| <= it where the size is
            ``h_contact`` (default 0.3R); in [h_contact, R].
        refine: Halve ``h_contact`` and ``h_far`` this many times.
        grading: Growth of the mesh size per unit distance from that square, up to ``h_far``.
        msh_file: If given, rank 0 writes the gmsh mesh there (``.msh``).
        partition: ``"graph"`` (dolfinx's partitioner: one body per rank) or ``"contact"``
            (both bodies cut across the contact plane; see the module's notes).

    Returns:
        The mesh and its tags; ``parameters`` holds the values above, the sizes after ``refine``.

    Raises:
        ValueError: A parameter is out of range (the message names it, its value, what is
            allowed).
    """
    W, H, h_c, h_f, w = _hertz_sizes(R, block_half_width, block_height, h_contact, h_far,
                                     refine_half_width, refine, grading, (0.005, 0.3))

    def construct(gmsh: typing.Any) -> None:
        occ = gmsh.model.occ
        # body 1: two quarter arcs meeting at the origin, and the flat top
        origin1, centre = occ.addPoint(0, 0, 0), occ.addPoint(0, R, 0)
        right1, left1 = occ.addPoint(R, R, 0), occ.addPoint(-R, R, 0)
        arcs = [occ.addCircleArc(right1, centre, origin1), occ.addCircleArc(origin1, centre, left1)]
        top1 = occ.addLine(left1, right1)
        disc = occ.addPlaneSurface([occ.addCurveLoop([*arcs, top1])])
        occ.remove([(0, centre)])
        # body 2: its own point at the origin, splitting the top edge
        corners = [occ.addPoint(x, y, 0) for x, y in ((-W, -H), (W, -H), (W, 0), (0, 0), (-W, 0))]
        edges = [occ.addLine(corners[i], corners[(i + 1) % 5]) for i in range(5)]
        block = occ.addPlaneSurface([occ.addCurveLoop(edges)])
        occ.synchronize()
        _add_groups(gmsh, 2, {BODY1: [disc], BODY2: [block]})
        _add_groups(gmsh, 1, {SLAVE: arcs, LOAD: [top1], MASTER: edges[2:4], FIXED: [edges[0]]})
        _refine_near_origin(gmsh, h_c, h_f, w, grading)

    parameters = {"R": R, "block_half_width": W, "block_height": H, "h_contact": h_c,
                  "h_far": h_f, "refine_half_width": w, "refine": refine, "grading": grading}
    return _build(comm, "hertz_2d", 2, construct, msh_file, parameters, partition, _along_x)


def hertz_3d(comm: MPI.Comm, R: float = 1.0, block_half_width: float | None = None,
             block_height: float | None = None, h_contact: float | None = None,
             h_far: float | None = None, refine_half_width: float | None = None,
             refine: int = 0, grading: float = 0.3, msh_file: str | None = None,
             partition: str = "graph", refine_depth: float | None = None) -> TwoBodyMesh:
    """A quarter of a hemisphere on a quarter block (x >= 0, y >= 0; tetrahedra).

    Body 1 is the quarter (x, y >= 0) of the lower hemisphere of radius ``R`` centred at
    (0, 0, R): its lowest point (the sphere's pole) touches the block at the origin. Its flat
    top z = R is :data:`LOAD`, its spherical surface :data:`SLAVE`. Body 2 is the block
    [0, W] x [0, W] x [-H, 0]: its top z = 0 is :data:`MASTER`, its bottom :data:`FIXED`. Both
    bodies' faces on x = 0 are :data:`SYMMETRY_X`, on y = 0 :data:`SYMMETRY_Y`; the block's faces
    x = W, y = W are untagged. Each body has a node at the origin.

    Args:
        comm: The communicator the mesh is distributed over (gmsh runs on its rank 0).
        R: The sphere's radius.
        block_half_width: W (default 4R); at least R, so that the block lies under the sphere.
        block_height: H (default 4R).
        h_contact: Mesh size near the contact (default 0.02R), before ``refine``.
        h_far: Largest mesh size, away from the contact (default 0.5R), before ``refine``.
        refine_half_width: Half-width of the cube |x|, |y|, |z| <= it where the size is
            ``h_contact`` (default 0.25R); in [h_contact, R].
        refine_depth: If given, the refined zone is the slab |x|, |y| <= ``refine_half_width``,
            |z| <= ``refine_depth`` instead (in [h_contact, refine_half_width]): a thin layer
            along the contact plane, for a small ``h_contact`` at a sane cost.
        refine: Halve ``h_contact`` and ``h_far`` this many times (about 8 times the cells).
        grading: Growth of the mesh size per unit distance from that cube, up to ``h_far``.
        msh_file: If given, rank 0 writes the gmsh mesh there (``.msh``).
        partition: ``"graph"`` (dolfinx's partitioner: one body per rank) or ``"contact"``
            (both bodies cut across the contact plane; see the module's notes).

    Returns:
        The mesh and its tags; ``parameters`` holds the values above, the sizes after ``refine``.

    Raises:
        ValueError: A parameter is out of range (the message names it, its value, what is
            allowed).
    """
    W, H, h_c, h_f, w = _hertz_sizes(R, block_half_width, block_height, h_contact, h_far,
                                     refine_half_width, refine, grading, (0.02, 0.25))
    if refine_depth is not None:
        laws.check("refine_depth", refine_depth, h_c <= refine_depth <= w,
                   f"must lie in [h_contact, refine_half_width] = [{h_c}, {w}]")

    def construct(gmsh: typing.Any) -> None:
        occ = gmsh.model.occ
        # latitudes -π/2 (the pole, at the origin) to 0 (the flat top), longitudes 0 to π/2
        ball = occ.addSphere(0, 0, R, R, -1, -math.pi / 2, 0, math.pi / 2)
        block = occ.addBox(0, 0, -H, W, W, H)
        occ.synchronize()
        tol = 1e-6 * max(R, W, H)
        groups: dict[int, list[int]] = {tag: [] for tag in (SLAVE, LOAD, MASTER, FIXED,
                                                           SYMMETRY_X, SYMMETRY_Y)}
        for face, box in _boundary(gmsh, 3, ball):
            if _flat(box, 0, 0, tol):
                groups[SYMMETRY_X].append(face)
            elif _flat(box, 1, 0, tol):
                groups[SYMMETRY_Y].append(face)
            elif _flat(box, 2, R, tol):
                groups[LOAD].append(face)
            else:
                groups[SLAVE].append(face)
        for face, box in _boundary(gmsh, 3, block):
            for axis, value, tag in ((0, 0, SYMMETRY_X), (1, 0, SYMMETRY_Y), (2, 0, MASTER),
                                     (2, -H, FIXED)):
                if _flat(box, axis, value, tol):
                    groups[tag].append(face)
        _add_groups(gmsh, 3, {BODY1: [ball], BODY2: [block]})
        _add_groups(gmsh, 2, groups)
        _refine_near_origin(gmsh, h_c, h_f, w, grading, refine_depth)

    parameters = {"R": R, "block_half_width": W, "block_height": H, "h_contact": h_c,
                  "h_far": h_f, "refine_half_width": w, "refine": refine, "grading": grading,
                  "refine_depth": refine_depth}
    return _build(comm, "hertz_3d", 3, construct, msh_file, parameters, partition, _around_z)


# --- patch tests: two stacked blocks with non-matching interface meshes ------------------------

def _check_patch(n_upper: int, n_lower: int, width: float, height: float) -> None:
    _check_int("n_upper", n_upper, 1)
    _check_int("n_lower", n_lower, 1)
    laws.check_positive("width", width)
    laws.check_positive("height", height)


def _structured(gmsh: typing.Any, dim: int, body: int, n: int, width: float,
                height: float) -> None:
    """Transfinite boundary of a rectangle (``dim`` 2) or box (3): ``n`` elements across the
    width, as many as keep them square over the height. A box's volume is meshed freely."""
    tol = 1e-6 * max(width, height)
    n_height = max(1, round(n * height / width))
    surfaces = [body] if dim == 2 else [f for f, _ in _boundary(gmsh, dim, body)]
    for surface in surfaces:
        for curve, box in _boundary(gmsh, 2, surface):
            vertical = box[dim + 2] - box[dim - 1] > tol  # extends along y (2D) or z (3D)
            gmsh.model.mesh.setTransfiniteCurve(curve, (n_height if vertical else n) + 1)
        gmsh.model.mesh.setTransfiniteSurface(surface)
    if dim == 3:
        points = gmsh.model.getBoundary([(3, body)], recursive=True)
        gmsh.model.mesh.setSize(points, width / n)


def _patch(comm: MPI.Comm, dim: int, n_upper: int, n_lower: int, width: float, height: float,
           msh_file: str | None, partition: str) -> TwoBodyMesh:
    _check_patch(n_upper, n_lower, width, height)
    normal = dim - 1  # the axis across the interface: y in 2D, z in 3D

    def construct(gmsh: typing.Any) -> None:
        occ = gmsh.model.occ
        if dim == 2:
            upper = occ.addRectangle(0, 0, 0, width, height)
            lower = occ.addRectangle(0, -height, 0, width, height)
        else:
            upper = occ.addBox(0, 0, 0, width, width, height)
            lower = occ.addBox(0, 0, -height, width, width, height)
        occ.synchronize()
        tol = 1e-6 * max(width, height)
        groups: dict[int, list[int]] = {tag: [] for tag in (SLAVE, LOAD, MASTER, FIXED)}
        for body, planes in ((upper, ((0, SLAVE), (height, LOAD))),
                             (lower, ((0, MASTER), (-height, FIXED)))):
            for facet, box in _boundary(gmsh, dim, body):
                for value, tag in planes:
                    if _flat(box, normal, value, tol):
                        groups[tag].append(facet)
        _add_groups(gmsh, dim, {BODY1: [upper], BODY2: [lower]})
        _add_groups(gmsh, dim - 1, groups)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        _structured(gmsh, dim, upper, n_upper, width, height)
        _structured(gmsh, dim, lower, n_lower, width, height)

    parameters = {"n_upper": n_upper, "n_lower": n_lower, "width": width, "height": height}
    return _build(comm, f"patch_{dim}d", dim, construct, msh_file, parameters, partition,
                  _along_x)


def patch_2d(comm: MPI.Comm, n_upper: int = 5, n_lower: int = 7, width: float = 1.0,
             height: float = 1.0, msh_file: str | None = None,
             partition: str = "graph") -> TwoBodyMesh:
    """Two stacked rectangles touching along y = 0, meshed with structured triangles.

    Body 1 is [0, width] x [0, height] with ``n_upper`` elements across the width, body 2 is
    [0, width] x [-height, 0] with ``n_lower``; each has as many rows as keep its elements
    square. Body 1's bottom is :data:`SLAVE`, its top :data:`LOAD`; body 2's top is
    :data:`MASTER`, its bottom :data:`FIXED`. With coprime ``n_upper``, ``n_lower`` the interface
    nodes of the two bodies coincide only at x = 0 and x = width (with equal counts, the meshes
    match node for node, still as two bodies).

    Args:
        comm: The communicator the mesh is distributed over (gmsh runs on its rank 0).
        n_upper: Elements across body 1's width (>= 1).
        n_lower: Elements across body 2's width (>= 1).
        width: Both bodies' width.
        height: Each body's height.
        msh_file: If given, rank 0 writes the gmsh mesh there (``.msh``).
        partition: ``"graph"`` (one body per rank) or ``"contact"`` (both cut along x).

    Returns:
        The mesh and its tags; ``parameters`` holds the values above.

    Raises:
        ValueError: A parameter is out of range.
    """
    return _patch(comm, 2, n_upper, n_lower, width, height, msh_file, partition)


def patch_3d(comm: MPI.Comm, n_upper: int = 4, n_lower: int = 5, width: float = 1.0,
             height: float = 1.0, msh_file: str | None = None,
             partition: str = "graph") -> TwoBodyMesh:
    """Two stacked boxes touching along z = 0 (tetrahedra), the 3D :func:`patch_2d`.

    Body 1 is [0, width]^2 x [0, height], body 2 is [0, width]^2 x [-height, 0]. Every face is
    meshed with structured triangles, ``n_upper`` (body 1) or ``n_lower`` (body 2) across the
    width and as many over the height as keep them right isosceles; the volumes are meshed
    freely. Body 1's bottom is :data:`SLAVE`, its top :data:`LOAD`; body 2's top is
    :data:`MASTER`, its bottom :data:`FIXED`; the lateral faces are untagged.

    Args:
        comm: The communicator the mesh is distributed over (gmsh runs on its rank 0).
        n_upper: Elements across body 1's width (>= 1).
        n_lower: Elements across body 2's width (>= 1).
        width: Both bodies' width and depth.
        height: Each body's height.
        msh_file: If given, rank 0 writes the gmsh mesh there (``.msh``).
        partition: ``"graph"`` (one body per rank) or ``"contact"`` (both cut along x).

    Returns:
        The mesh and its tags; ``parameters`` holds the values above.

    Raises:
        ValueError: A parameter is out of range.
    """
    return _patch(comm, 3, n_upper, n_lower, width, height, msh_file, partition)
