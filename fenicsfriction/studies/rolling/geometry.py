r"""The half-space of the rolling scenes: a large block, graded geometrically towards the contact.

Kalker's symmetry (Kalker 1986, section 4: quasi-identical bodies) reduces the tangential
problem of two bodies to one elastic half-space loaded on its surface; the finite element model
approximates it by the block

* 2D: :math:`[-L_x, L_x] \times [-D, 0]` (plane strain), surface :math:`y = 0`;
* 3D: :math:`[-L_x, L_x] \times [-L_y, L_y] \times [-D, 0]`, surface :math:`z = 0`,

clamped on its far faces (sides and bottom). The mesh is a tensor product of 1D grids built
by gmsh's extrusion with layers (quadrilaterals / hexahedra): uniform, of size h, over the
*contact zone* :math:`|x| \le \ell_x` (and :math:`|y| \le \ell_y`) and in depth down to
:math:`\ell_x`, then growing geometrically by ``growth`` per cell up to the far faces. So a block
a thousand times the contact's size costs a few dozen cells per direction more than one twice
its size; the surface grid is aligned with the rolling direction x, which lets P1 (Q1)
displacements hold the exact stick field :math:`\Delta u_x = \xi x + g(y)`.

Facet tags: :data:`CONTACT` (the surface over the contact zone), :data:`SURFACE` (the rest of
the free surface), :data:`CLAMPED` (the far faces). gmsh runs on rank 0 and dolfinx distributes
the mesh (:func:`fenicsfriction.studies.contact.geometry._build`: the session's handling and the
error broadcast are the two-body scenes').
"""

from __future__ import annotations

import dataclasses
import typing

from mpi4py import MPI

import numpy as np
from dolfinx import mesh

from fenicsfriction import laws
from fenicsfriction.meshing import gmsh_mesh

__all__ = ["CLAMPED", "CONTACT", "SURFACE", "HalfSpaceMesh", "graded_coordinates",
           "half_space", "zone_half_widths"]

#: facet tag of the surface over the contact zone (where the contact tractions are integrated)
CONTACT = 1
#: facet tag of the rest of the free surface
SURFACE = 2
#: facet tag of the clamped far faces (sides and bottom)
CLAMPED = 3


@dataclasses.dataclass
class HalfSpaceMesh:
    """The block, its facet tags and the parameters it was made with.

    Attributes:
        mesh: the dolfinx mesh (quadrilaterals in 2D, hexahedra in 3D).
        facet_tags: :data:`CONTACT`, :data:`SURFACE` and :data:`CLAMPED`.
        parameters: contact zone, cell size, growth, block size and the cell count.
    """

    mesh: typing.Any
    facet_tags: typing.Any
    parameters: dict


def graded_coordinates(half_width: float, h: float, length: float, growth: float,
                       symmetric: bool = True) -> np.ndarray:
    """Nodes of a 1D grid: uniform (size ≈ ``h``, a whole number of cells) over
    [-half_width, half_width], then cells growing by the factor ``growth`` up to ``length``
    (the last cell stretched or merged so that the grid ends there exactly). With
    ``symmetric=False`` the grid is [0, length] with the uniform part [0, half_width].
    """
    laws.check_positive("h", h)
    laws.check_positive("half_width", half_width)
    laws.check("length", length, length >= half_width, f"must be >= {half_width}")
    laws.check("growth", growth, growth >= 1, "the cell growth factor must be >= 1")
    n = max(1, round((2 if symmetric else 1) * half_width / h))
    inner = np.linspace(-half_width if symmetric else 0.0, half_width, n + 1)
    step, outer = inner[1] - inner[0], [half_width]
    while outer[-1] < length - 1e-12 * length:
        step *= growth
        outer.append(outer[-1] + step)
    if len(outer) > 2 and length - outer[-2] < 0.5 * (outer[-2] - outer[-3]):
        outer.pop(-2)  # a last cell less than half its neighbour: merged into it
    outer[-1] = length
    right = np.asarray(outer[1:])
    if not symmetric:
        return np.concatenate([inner, right])
    return np.concatenate([-right[::-1], inner, right])


def half_space(comm: MPI.Comm, dim: int, zone: typing.Sequence[float], h: float,
               length: float, growth: float = 1.3, msh_file: str | None = None
               ) -> HalfSpaceMesh:
    """The graded block of a half-space (see the module's docstring).

    Args:
        comm: the communicator the mesh is distributed over (gmsh runs on its rank 0).
        dim: 2 or 3.
        zone: the contact zone's half-widths (ℓ_x,) in 2D, (ℓ_x, ℓ_y) in 3D [length].
        h: the cell size over the contact zone [length].
        length: L, the block's half-width and depth [length], at least max(zone).
        growth: the size ratio of consecutive cells outside the zone (>= 1).
        msh_file: if given, rank 0 writes the gmsh mesh there (``.msh``).

    Returns:
        The mesh, its facet tags and its parameters.

    Raises:
        ValueError: a parameter is out of range (named in the message).
    """
    laws.check("dim", dim, dim in (2, 3), "2 or 3")
    laws.check("zone", list(zone), len(zone) == dim - 1
               and all(isinstance(z, (int, float)) and z > 0 for z in zone),
               f"{dim - 1} positive half-width(s)")
    laws.check_positive("h", h)
    laws.check("h", h, h <= min(zone), f"must be <= the contact zone's half-width {min(zone)}")
    laws.check("length", length, isinstance(length, (int, float)) and length >= max(zone),
               f"must be >= the contact zone's half-width {max(zone)}")
    laws.check("growth", growth, isinstance(growth, (int, float)) and growth >= 1, "must be >= 1")
    axes = [graded_coordinates(z, h, length, growth) for z in zone]
    depth = graded_coordinates(zone[0], h, length, growth, symmetric=False)
    axes.append(-depth[::-1])  # from -L up to the surface

    def construct(gmsh: typing.Any) -> None:
        geo = gmsh.model.geo
        start = [nodes[0] for nodes in axes] + [0.0] * (3 - dim)
        entity = [(0, geo.addPoint(*start))]
        # extrude along each axis with one layer per cell: the tensor-product grid
        for axis, nodes in enumerate(axes):
            span = nodes[-1] - nodes[0]
            shift = [0.0, 0.0, 0.0]
            shift[axis] = span
            heights = ((nodes[1:] - nodes[0]) / span).tolist()
            out = geo.extrude(entity, *shift, numElements=[1] * len(heights), heights=heights,
                              recombine=True)
            entity = [out[1]]  # the extruded entity (out[0] is the translated copy)
        geo.synchronize()
        body = entity[0][1]
        top: list[int] = []
        far: list[int] = []
        for _, face in gmsh.model.getBoundary([(dim, body)], oriented=False):
            box = gmsh.model.getBoundingBox(dim - 1, face)
            flat_top = abs(box[dim - 1]) < 1e-9 * length and abs(box[dim + 2]) < 1e-9 * length
            (top if flat_top else far).append(face)
        gmsh.model.addPhysicalGroup(dim, [body], 1)
        gmsh.model.addPhysicalGroup(dim - 1, top, SURFACE)
        gmsh.model.addPhysicalGroup(dim - 1, far, CLAMPED)

    msh, _, facet_tags = gmsh_mesh(comm, f"half_space_{dim}d", dim, construct, msh_file)
    facet_tags = _tag_contact(msh, facet_tags, zone, h)
    cells = msh.topology.index_map(dim).size_global
    parameters = {"dim": dim, "zone": list(zone), "h": float(h), "length": float(length),
                  "growth": float(growth), "cells": int(cells),
                  "surface_cells_per_axis": [len(a) - 1 for a in axes[:-1]],
                  "depth_cells": len(depth) - 1}
    return HalfSpaceMesh(msh, facet_tags, parameters)


def _tag_contact(msh: mesh.Mesh, facet_tags: typing.Any, zone: typing.Sequence[float],
                 h: float) -> typing.Any:
    """The gmsh tags with the free surface's facets over the contact zone retagged
    :data:`CONTACT` (their midpoints inside the zone's box)."""
    fdim = msh.topology.dim - 1
    inside = mesh.locate_entities_boundary(
        msh, fdim, lambda x: np.isclose(x[fdim], 0.0) & np.all(
            [np.abs(x[i]) <= z + 1e-9 * h for i, z in enumerate(zone)], axis=0))
    indices, values = facet_tags.indices.copy(), facet_tags.values.copy()
    values[np.isin(indices, inside)] = CONTACT
    order = np.argsort(indices)
    return mesh.meshtags(msh, fdim, indices[order].astype(np.int32),
                         values[order].astype(np.int32))


def zone_half_widths(a: float, b: float | None, dim: int, margin: float = 1.0) -> list[float]:
    """The contact zone of an ellipse (2D: a strip) of semi-axes a, b widened by ``margin``."""
    laws.check("margin", margin, margin >= 1, "the contact zone must hold the contact (>= 1)")
    return [margin * a] if dim == 2 else [margin * a, margin * (b if b is not None else a)]

