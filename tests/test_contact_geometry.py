"""The two-body contact meshes (fenicsfriction.studies.contact.geometry) against closed forms.

Every test runs on any number of ranks (the meshes are built on rank 0 and distributed); sums
over facets use each rank's owned facets and an allreduce.

Curved surfaces are approximated by their boundary facets, whose vertices lie on the exact
circle or sphere, so the bodies are inscribed and the bounds below are rigorous:

* a chord of length h on a circle of radius R subtends θ = 2 arcsin(h / 2R) and cuts off a
  segment of area R²(θ - sin θ)/2 ≤ R²θ³/12; its length falls short of the arc Rθ by
  Rθ - 2R sin(θ/2) ≤ Rθ³/24. Summed over an arc of angle Θ (Σθ = Θ), the area misses at most
  ΘR²θ_max²/12 and the length at most ΘRθ_max²/24.
* a triangle inscribed in a sphere, with circumradius ρ, lies in a plane at distance
  d = sqrt(R² - ρ²) from the centre. The cone from the centre over it misses, of the sphere's
  sector over it (solid angle Ω), at most Ω(R³ - d³)/3 ≤ ΩR²(R - d) ≤ ΩRρ², so the quarter
  hemisphere (Σ Ω = π/2) misses at most (π/2)Rρ_max² of its volume. Projected radially onto
  the sphere, its area is scaled by R²d/r³ with r in [d, R], hence by a factor in
  [d/R, R²/d²] ⊂ [1 - ρ²/R², 1 + ρ²/(R² - ρ²)].
"""

from __future__ import annotations

import math

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest
import ufl
from dolfinx import fem

from fenicsfriction.studies.contact import geometry
from fenicsfriction.studies.contact.geometry import (
    BODY1,
    BODY2,
    FIXED,
    LOAD,
    MASTER,
    SLAVE,
    SYMMETRY_X,
    SYMMETRY_Y,
)

R = 2.0  # not 1: the defaults scale with R


@pytest.fixture(scope="module")
def hertz2():
    return geometry.hertz_2d(MPI.COMM_WORLD, R=R)


@pytest.fixture(scope="module")
def hertz3():
    return geometry.hertz_3d(MPI.COMM_WORLD, R=R)


@pytest.fixture(scope="module")
def patch2():
    return geometry.patch_2d(MPI.COMM_WORLD, n_upper=5, n_lower=7, width=2.0, height=0.5)


@pytest.fixture(scope="module")
def patch3():
    return geometry.patch_3d(MPI.COMM_WORLD, n_upper=4, n_lower=5, width=2.0, height=0.5)


def measure(m: geometry.TwoBodyMesh, tag: int) -> float:
    """Area/volume of the cells (tags < 10) or length/area of the facets with ``tag``."""
    msh = m.mesh
    kind, data = ("dx", m.cell_tags) if tag in (BODY1, BODY2) else ("ds", m.facet_tags)
    d = ufl.Measure(kind, domain=msh, subdomain_data=data)
    one = fem.Constant(msh, PETSc.ScalarType(1.0))
    return msh.comm.allreduce(fem.assemble_scalar(fem.form(one * d(tag))), op=MPI.SUM)


def vertex_coordinates(msh) -> np.ndarray:
    """Coordinates of the local vertices, by vertex index (P1 geometry: vertex i of a cell is
    its geometry node i)."""
    tdim, gdim = msh.topology.dim, msh.geometry.dim
    msh.topology.create_connectivity(tdim, 0)
    cell_vertices = msh.topology.connectivity(tdim, 0).array.reshape(-1, tdim + 1)
    dofmap = msh.geometry.dofmap
    nodes = np.asarray(getattr(dofmap, "array", dofmap)).reshape(-1, tdim + 1)
    index_map = msh.topology.index_map(0)
    x = np.full((index_map.size_local + index_map.num_ghosts, gdim), np.nan)
    x[cell_vertices] = msh.geometry.x[nodes, :gdim]
    return x


def facet_points(m: geometry.TwoBodyMesh, tag: int) -> np.ndarray:
    """Vertex coordinates (facet, vertex, axis) of all facets with ``tag``, each once, on every
    rank."""
    msh = m.mesh
    fdim = msh.topology.dim - 1
    msh.topology.create_connectivity(fdim, 0)
    owned = msh.topology.index_map(fdim).size_local
    facets = m.facet_tags.indices[(m.facet_tags.values == tag) & (m.facet_tags.indices < owned)]
    f2v = msh.topology.connectivity(fdim, 0)
    vertices = np.array([f2v.links(f) for f in facets], dtype=np.int32).reshape(-1, fdim + 1)
    local = vertex_coordinates(msh)[vertices]
    return np.concatenate(msh.comm.allgather(local))


def triangles(p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Areas, circumradii and longest edges of triangles ``p`` (triangle, vertex, axis)."""
    edges = np.linalg.norm(p[:, [1, 2, 0]] - p[:, [2, 0, 1]], axis=2)
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    return area, np.prod(edges, axis=1) / (4 * area), edges.max(axis=1)


def arc_bounds(radius: float, angle: float, h_max: float) -> tuple[float, float]:
    """Upper bounds on the area and length an inscribed polygon with chords <= ``h_max``
    misses of a circular arc of ``angle`` (see the module docstring)."""
    theta = 2 * math.asin(min(1.0, h_max / (2 * radius)))
    return angle * radius**2 * theta**2 / 12, angle * radius * theta**2 / 24


# --- Hertz 2D ----------------------------------------------------------------------------------

def test_hertz_2d_areas_and_lengths_are_the_inscribed_polygons(hertz2):
    """Half-disc: πR²/2 less the circular segments cut off by the SLAVE chords (to round-off),
    and less than the a priori bound; the arc πR likewise; the straight edges exactly."""
    W = H = 4 * R
    p = facet_points(hertz2, SLAVE)
    h = np.linalg.norm(p[:, 1] - p[:, 0], axis=1)
    assert np.allclose(np.linalg.norm(p - [0.0, R], axis=2), R, rtol=1e-12)  # on the circle
    theta = 2 * np.arcsin(h / (2 * R))
    assert theta.sum() == pytest.approx(math.pi, rel=1e-12)  # the chords span the half circle
    segments = R**2 / 2 * np.sum(theta - np.sin(theta))
    area_bound, length_bound = arc_bounds(R, math.pi, h.max())

    area1 = measure(hertz2, BODY1)
    assert area1 == pytest.approx(math.pi * R**2 / 2 - segments, abs=1e-12 * R**2)
    assert 0 < math.pi * R**2 / 2 - area1 <= area_bound
    slave = measure(hertz2, SLAVE)
    assert 0 < math.pi * R - slave <= length_bound
    assert measure(hertz2, BODY2) == pytest.approx(2 * W * H, rel=1e-12)
    assert measure(hertz2, LOAD) == pytest.approx(2 * R, rel=1e-12)
    assert measure(hertz2, MASTER) == pytest.approx(2 * W, rel=1e-12)
    assert measure(hertz2, FIXED) == pytest.approx(2 * W, rel=1e-12)
    assert measure(hertz2, SYMMETRY_X) == measure(hertz2, SYMMETRY_Y) == 0.0


def test_hertz_2d_is_refined_near_the_contact(hertz2):
    """SLAVE and MASTER facets within half the refined width of the origin are no longer than
    h_contact (1% for gmsh's rounding); far from it the arc is much coarser. Both bodies have a
    vertex at the origin (zero initial gap)."""
    h_contact = hertz2.parameters["h_contact"]
    assert h_contact == pytest.approx(0.005 * R)
    near = hertz2.parameters["refine_half_width"] / 2
    for tag in (SLAVE, MASTER):
        p = facet_points(hertz2, tag)
        h = np.linalg.norm(p[:, 1] - p[:, 0], axis=1)
        close = np.abs(p[:, :, 0]).max(axis=1) < near
        assert close.sum() >= 2 * near / h_contact  # the near part is covered
        assert h[close].max() <= 1.01 * h_contact
        assert h[~close].max() > 10 * h_contact
        assert np.count_nonzero(np.all(np.isclose(p, 0.0, atol=1e-14), axis=2)) == 2


def test_refine_halves_the_mesh_sizes():
    """``refine=1`` halves h_contact and h_far, and the SLAVE facets near the origin follow."""
    m = geometry.hertz_2d(MPI.COMM_WORLD, h_contact=0.04, h_far=0.5, refine=1)
    assert m.parameters["h_contact"] == 0.02 and m.parameters["h_far"] == 0.25
    p = facet_points(m, SLAVE)
    h = np.linalg.norm(p[:, 1] - p[:, 0], axis=1)
    close = np.abs(p[:, :, 0]).max(axis=1) < m.parameters["refine_half_width"] / 2
    assert 0.9 * 0.02 <= h[close].max() <= 1.01 * 0.02


# --- Hertz 3D ----------------------------------------------------------------------------------

def test_hertz_3d_volumes_and_areas_are_the_inscribed_polyhedra(hertz3):
    """Quarter hemisphere: its volume is the sum of the cones from the centre over the SLAVE
    triangles (the flat faces pass through the centre), πR³/6 less at most (π/2)Rρ_max²; the
    spherical area πR²/2 within the radial-projection bound; the flat faces and the block
    exactly, or (faces bounded by a quarter circle) within the polygon bounds."""
    W = H = 4 * R
    centre = np.array([0.0, 0.0, R])
    p = facet_points(hertz3, SLAVE)
    assert np.allclose(np.linalg.norm(p - centre, axis=2), R, rtol=1e-12)  # on the sphere
    area, rho, _ = triangles(p)
    distance = np.sqrt(R**2 - rho**2)  # of each triangle's plane from the centre

    volume1 = measure(hertz3, BODY1)
    assert volume1 == pytest.approx(np.sum(area * distance) / 3, rel=1e-11)
    assert 0 < math.pi * R**3 / 6 - volume1 <= math.pi / 2 * R * rho.max()**2
    slave = measure(hertz3, SLAVE)
    assert slave == pytest.approx(area.sum(), rel=1e-12)
    rho2 = rho.max()**2
    assert -slave * rho2 / R**2 <= math.pi * R**2 / 2 - slave <= slave * rho2 / (R**2 - rho2)

    assert measure(hertz3, BODY2) == pytest.approx(W * W * H, rel=1e-12)
    assert measure(hertz3, MASTER) == pytest.approx(W * W, rel=1e-12)
    assert measure(hertz3, FIXED) == pytest.approx(W * W, rel=1e-12)
    # quarter discs: the top of body 1 (LOAD), its sections by x = 0 and y = 0 (with the block's
    # W × H faces); the longest facet edge bounds the chords on the quarter circle
    for tag, block_face in ((LOAD, 0.0), (SYMMETRY_X, W * H), (SYMMETRY_Y, W * H)):
        body1 = facet_points(hertz3, tag)
        body1 = body1[body1[..., 2].min(axis=1) >= 0]
        area_bound, _ = arc_bounds(R, math.pi / 2, triangles(body1)[2].max())
        missing = math.pi * R**2 / 4 + block_face - measure(hertz3, tag)
        assert 0 < missing <= area_bound, tag


def test_hertz_3d_is_refined_near_the_contact(hertz3):
    """SLAVE and MASTER triangles near the origin have edges close to h_contact (a 2D
    unstructured mesher makes them within about √2 of the target size, 1.3 measured); far from
    it they are much larger. Both bodies have a vertex at the origin."""
    h_contact = hertz3.parameters["h_contact"]
    assert h_contact == pytest.approx(0.02 * R)
    near = hertz3.parameters["refine_half_width"] / 2
    for tag in (SLAVE, MASTER):
        p = facet_points(hertz3, tag)
        longest = triangles(p)[2]
        close = np.linalg.norm(p, axis=2).max(axis=1) < near
        assert close.sum() >= (near / h_contact)**2  # the near part is covered
        assert longest[close].max() <= 1.5 * h_contact
        assert longest[~close].max() > 10 * h_contact
        assert np.any(np.all(np.isclose(p, 0.0, atol=1e-14), axis=2))


def test_hertz_3d_refine_depth_refines_a_slab_along_the_contact_plane_only():
    """With ``refine_depth`` the fine size holds in |z| <= depth and the cells below it grow
    (the cube would refine them down to |z| = refine_half_width): on the block's symmetry face
    x = 0, triangles within the slab have edges near h_contact, those centred 3-4 depths below
    it (within the half-width) are more than twice as long."""
    h, width, depth = 0.02, 0.3, 0.05
    m = geometry.hertz_3d(MPI.COMM_WORLD, R=R, h_contact=h, refine_half_width=width,
                          refine_depth=depth)
    assert m.parameters["refine_depth"] == depth
    p = facet_points(m, SYMMETRY_X)
    longest = triangles(p)[2]
    y, z = p[..., 1].max(axis=1), p[..., 2]
    inside = (y < width / 2) & (z.min(axis=1) > -depth) & (z.max(axis=1) <= 0)
    centre = z.mean(axis=1)
    below = (y < width) & (centre < -3 * depth) & (centre > -4 * depth)
    assert inside.any() and below.any()
    assert longest[inside].max() <= 1.5 * h
    assert np.median(longest[below]) > 2 * h


# --- patches -----------------------------------------------------------------------------------

def test_patch_2d_interface_meshes_do_not_match(patch2):
    """5 against 7 uniform elements across the interface: the SLAVE nodes are k/5 and the
    MASTER nodes j/7 of the width, which coincide at the two ends only."""
    width, height = 2.0, 0.5
    for tag, n in ((SLAVE, 5), (MASTER, 7), (LOAD, 5), (FIXED, 7)):
        p = facet_points(patch2, tag)
        assert len(p) == n, tag
        assert np.allclose(np.linalg.norm(p[:, 1] - p[:, 0], axis=1), width / n)
        assert measure(patch2, tag) == pytest.approx(width, rel=1e-12)
    slave = np.unique(np.round(facet_points(patch2, SLAVE)[..., 0], 12))
    master = np.unique(np.round(facet_points(patch2, MASTER)[..., 0], 12))
    np.testing.assert_allclose(slave, np.linspace(0, width, 6), atol=1e-12)
    np.testing.assert_allclose(master, np.linspace(0, width, 8), atol=1e-12)
    assert set(slave) & set(master) == {0.0, width}
    for body in (BODY1, BODY2):
        assert measure(patch2, body) == pytest.approx(width * height, rel=1e-12)


def test_patch_3d_interface_meshes_do_not_match(patch3):
    """The same in 3D: the structured interfaces (4 and 5 divisions) share the four corners
    only; volumes and the tagged areas exactly."""
    width, height = 2.0, 0.5
    for tag, n in ((SLAVE, 4), (MASTER, 5), (LOAD, 4), (FIXED, 5)):
        assert len(facet_points(patch3, tag)) == 2 * n * n, tag
        assert measure(patch3, tag) == pytest.approx(width**2, rel=1e-12)
    slave = {tuple(x) for x in np.round(facet_points(patch3, SLAVE)[..., :2], 12).reshape(-1, 2)}
    master = {tuple(x) for x in np.round(facet_points(patch3, MASTER)[..., :2], 12).reshape(-1, 2)}
    assert len(slave) == 25 and len(master) == 36
    assert slave & master == {(0.0, 0.0), (width, 0.0), (0.0, width), (width, width)}
    for body in (BODY1, BODY2):
        assert measure(patch3, body) == pytest.approx(width**2 * height, rel=1e-12)


# --- all scenes --------------------------------------------------------------------------------

@pytest.mark.parametrize("scene", ["hertz2", "hertz3", "patch2", "patch3"])
def test_bodies_share_no_vertex_and_every_cell_is_tagged(scene, request):
    """The two bodies' cells have disjoint vertex sets (global indices, over all ranks), every
    cell carries BODY1 or BODY2, and the tagged facets are boundary facets of the right body."""
    m = request.getfixturevalue(scene)
    msh = m.mesh
    comm, tdim = msh.comm, msh.topology.dim
    cells = msh.topology.index_map(tdim)
    assert comm.allreduce(np.count_nonzero(m.cell_tags.indices < cells.size_local)) \
        == cells.size_global
    c2v = msh.topology.connectivity(tdim, 0).array.reshape(-1, tdim + 1)
    to_global = msh.topology.index_map(0).local_to_global
    vertices = {}
    for body in (BODY1, BODY2):  # a rank may hold no cell of a body
        local = np.unique(c2v[m.cell_tags.indices[m.cell_tags.values == body]])
        vertices[body] = set().union(*comm.allgather(set(to_global(local).tolist())))
    # local claims only after the collective calls: a rank that fails one must not leave the
    # other waiting
    assert set(np.unique(m.cell_tags.values)) <= {BODY1, BODY2}
    assert vertices[BODY1].isdisjoint(vertices[BODY2])
    assert len(vertices[BODY1]) + len(vertices[BODY2]) == msh.topology.index_map(0).size_global
    # each tagged facet is on the boundary (one cell) and in the body its tag belongs to
    msh.topology.create_connectivity(tdim - 1, tdim)
    f2c = msh.topology.connectivity(tdim - 1, tdim)
    body_of = dict(zip(m.cell_tags.indices, m.cell_tags.values, strict=True))
    owned = msh.topology.index_map(tdim - 1).size_local
    for tag, body in ((SLAVE, BODY1), (LOAD, BODY1), (MASTER, BODY2), (FIXED, BODY2)):
        facets = m.facet_tags.indices[(m.facet_tags.values == tag)
                                      & (m.facet_tags.indices < owned)]
        links = [f2c.links(f) for f in facets]
        assert all(len(c) == 1 and body_of[c[0]] == body for c in links), tag


@pytest.mark.mpi(min_size=2)
def test_meshes_are_distributed_over_the_ranks(hertz2, hertz3):
    """Built on rank 0, read onto every rank: each owns cells, none owns a cell twice. (The
    graph partitioner sees two disconnected bodies: on two ranks it gave each rank one body.)"""
    for m in (hertz2, hertz3):
        cells = m.mesh.topology.index_map(m.mesh.topology.dim)
        owned = np.count_nonzero(m.cell_tags.indices < cells.size_local)
        counts = m.mesh.comm.allgather(owned)
        assert sum(counts) == cells.size_global and min(counts) > 0


# --- errors ------------------------------------------------------------------------------------

@pytest.mark.parametrize(("builder", "kwargs", "message"), [
    (geometry.hertz_2d, {"R": -1.0}, "R=-1.0 is invalid"),
    (geometry.hertz_2d, {"block_half_width": 0.5}, "block_half_width=0.5 is invalid: must be >="),
    (geometry.hertz_2d, {"h_contact": 0.1, "h_far": 0.05}, "h_far=0.05 is invalid"),
    (geometry.hertz_2d, {"refine_half_width": 2.0}, "refine_half_width=2.0 is invalid"),
    (geometry.hertz_3d, {"refine": -1}, "refine=-1 is invalid: must be an integer >= 0"),
    (geometry.hertz_3d, {"refine": 1.5}, "refine=1.5 is invalid"),
    (geometry.hertz_3d, {"grading": 0.0}, "grading=0.0 is invalid"),
    (geometry.hertz_3d, {"refine_depth": 1.0}, "refine_depth=1.0 is invalid"),
    (geometry.patch_2d, {"n_upper": 0}, "n_upper=0 is invalid: must be an integer >= 1"),
    (geometry.patch_3d, {"width": float("nan")}, "width=nan is invalid"),
])
def test_bad_parameters_raise_value_error_naming_them(builder, kwargs, message):
    with pytest.raises(ValueError, match=message):
        builder(MPI.COMM_WORLD, **kwargs)


def test_a_gmsh_failure_raises_on_every_rank():
    """An error while rank 0 builds the model reaches every rank (none waits for the mesh), and
    the gmsh session is closed: the next mesh builds."""
    def construct(gmsh):
        raise KeyError("broken geometry")

    with pytest.raises(RuntimeError, match="building the broken mesh with gmsh failed: KeyError"):
        geometry._build(MPI.COMM_WORLD, "broken", 2, construct, None, {})
    assert geometry.patch_2d(MPI.COMM_WORLD, 1, 1).parameters["geometry"] == "patch_2d"
