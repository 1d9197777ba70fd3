"""Node-to-segment contact between two bodies: derivatives, pairing, parallel agreement.

The contact's Jacobian is ufl.derivative of its residual chained through the pairing operator
Q; a Taylor test checks it: with a consistent Jacobian the remainder
|R(u + h du) - R(u) - h J du| falls like h² (a wrong block leaves an O(h) remainder).
"""

from __future__ import annotations

from mpi4py import MPI

import dolfinx.fem.petsc
import numpy as np
import pytest
from dolfinx import fem
from two_blocks import MASTER, SLAVE, UPPER, stacked_blocks

from fenicsfriction import _compat
from fenicsfriction.contact import NodeToSegment, solve_with_search
from fenicsfriction.contact.pairing import point_facet_distance, surface_coordinates
from fenicsfriction.laws import InterfaceLaw


def _contact(dim: int, friction: bool, overlap: float = 0.02, comm=MPI.COMM_WORLD,
             frozen: bool = True, seed: int = 1):
    msh, cell_tags, ft = stacked_blocks(comm, dim, 3, 4, overlap=overlap)
    V = _compat.vector_function_space(msh, 1)
    u, u_old = fem.Function(V, name="u"), fem.Function(V, name="u_old")
    x = V.tabulate_dof_coordinates()[:, :dim]
    # a smooth random-looking state, the same on any partition (a function of position)
    rng = np.random.default_rng(seed)
    k = rng.standard_normal((3, dim))
    for f, scale in ((u, 0.01), (u_old, 0.005)):
        f.x.array[:] = (scale * np.sin(x @ k[:dim].T + k[2])).ravel()
        f.x.scatter_forward()
    law = InterfaceLaw(c_n=100.0, m_n=2.0)
    options = {}
    if friction:
        law = law.replace(mu=0.5, eps=1e-2)
        options = {"velocity": (u - u_old) / 0.1, "fields": [u_old]}
    contact = NodeToSegment(u, ft, SLAVE, MASTER, law, frozen=frozen, **options)
    contact.cell_tags = cell_tags
    return contact, u


def _residual(operator, u, values):
    u.x.array[:] = values
    u.x.scatter_forward()
    b = dolfinx.fem.petsc.create_vector(operator.F)
    b.set(0.0)
    operator.add_to_residual(b)
    return b


@pytest.mark.parametrize(("dim", "friction"), [(2, False), (2, True), (3, False), (3, True)])
def test_contact_jacobian_passes_the_taylor_test(dim, friction):
    contact, u = _contact(dim, friction)
    operator = contact.operator({u: 1.0})
    x0 = u.x.array.copy()
    b0 = _residual(operator, u, x0)
    J = operator.matrix()
    du = fem.Function(u.function_space)
    x = u.function_space.tabulate_dof_coordinates()[:, :dim]
    # every dof moving, the same direction on any partition (a function of position)
    du.x.array[:] = np.cos(x @ np.arange(1.0, dim + 1) * np.arange(1, dim + 1)[:, None]).T.ravel()
    du.x.scatter_forward()
    Jdu = b0.duplicate()
    J.mult(_compat.petsc_vec(du), Jdu)
    remainders = []
    for h in (2e-4, 1e-4, 5e-5):
        b = _residual(operator, u, x0 + h * du.x.array)
        b.axpy(-1.0, b0)
        first = b.norm()
        b.axpy(-h, Jdu)
        remainders.append(b.norm())
        assert first > 0
    rates = np.log2(np.array(remainders[:-1]) / remainders[1:])
    # second order, the remainder's constant is the residual's curvature (m_n = 2, finite
    # sliding of the closest point); a missing chain term leaves rate 1
    assert rates.min() > 1.9, rates


def test_projection_of_a_point_on_a_triangle_has_its_surface_coordinates():
    x = np.array([[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])
    p = np.array([[0.5, 0.25, 0.3]])
    N = surface_coordinates(p, x)
    # x1 + ξ1 (x2 - x1) + ξ2 (x3 - x1) = (0.5, 0.25): ξ1 = 0.25, ξ2 = 0.25
    assert np.allclose(N, [[0.5, 0.25, 0.25]])
    assert np.isclose(point_facet_distance(p, x)[0], 0.3)
    outside = np.array([[3.0, 0.0, 0.4]])  # nearest point: the vertex (2, 0, 0)
    assert np.isclose(point_facet_distance(outside, x)[0], np.hypot(1.0, 0.4))


def test_pairing_follows_finite_sliding():
    """The upper block slid by 1.3 of the lower mesh's cells: the search pairs every slave
    node over the master surface with the facet under its current position."""
    contact, u = _contact(2, friction=False, overlap=0.0)
    V = u.function_space
    cell_tags = contact.cell_tags
    upper = _compat.cell_dofs(V, cell_tags.indices[cell_tags.values == UPPER])
    u.x.array[:] = 0.0
    u.x.array.reshape(-1, 2)[upper, 0] = 1.3 / 4
    u.x.scatter_forward()
    contact.frozen = False
    contact.update()
    pairing = contact.pairing
    xs = pairing.x_nodes[pairing.slave_nodes] + u.x.array.reshape(-1, 2)[pairing.slave_nodes]
    N = surface_coordinates(xs, pairing.facet_coordinates(u))
    over = xs[:, 0] <= 1.0  # the slave nodes still above the lower block
    assert np.all(N[over] >= -1e-12) and np.all(N[over] <= 1 + 1e-12)
    assert pairing.changes >= 1


@pytest.mark.parametrize("dim", [2, 3])
def test_parallel_solve_matches_the_serial_one(dim):
    """The patch under pressure on this communicator (slave and master facets on different
    ranks under MPI) against the same problem solved on each rank alone: the contact forces
    agree to the solver tolerance."""
    from fenicsfriction.studies.contact.validation import Patch

    scene = Patch(dim=dim, n_upper=3 if dim == 3 else 5, n_lower=4 if dim == 3 else 7)
    summary, model = scene.run(MPI.COMM_WORLD)
    alone, model_alone = scene.run(MPI.COMM_SELF)
    here = model.surface_values()
    there = model_alone.surface_values()
    assert np.allclose(here.x, there.x)
    # Newton stops at |R| <= 1e-9 against forces of 1e-2 per unit length/area
    assert np.allclose(here.force, there.force, atol=1e-7 * scene.pressure / np.min(here.weight))
    assert summary["pressure_deviation"] == pytest.approx(alone["pressure_deviation"], abs=1e-6)


@pytest.mark.parametrize("dim", [2, 3])
def test_two_pass_contact_passes_the_patch_test_and_one_pass_does_not(dim):
    """Taylor & Papadopoulos (1991): node-to-segment contact transmits a uniform pressure
    across non-matching meshes only with both surfaces slave in turn. Two passes: the
    deviation left is the penalty's (c_n = 1e4 against E = 1: a few 1e-3)."""
    from fenicsfriction.studies.contact.validation import Patch

    one, _ = Patch(dim=dim, passes=1).run()
    two, _ = Patch(dim=dim, passes=2).run()
    assert two["pressure_deviation"] < 1e-2
    assert one["pressure_deviation"] > 10 * two["pressure_deviation"]


def test_search_between_solves_reaches_a_fixed_point():
    """solve_with_search returns a state whose own search keeps the pairing."""
    from fenicsfriction.studies.contact.validation import Patch

    _, model = Patch(dim=2).run()
    contact = model.contacts[0]
    changes = contact.pairing.changes
    assert not contact.pairing.search(model.u)
    assert contact.pairing.changes == changes
    report = solve_with_search(model.solver, model.contacts)
    assert report.rounds == 1


def test_perturbed_lagrangian_approaches_the_compliance_law_as_its_penalty_grows():
    """Cattaneo-Mindlin with Pop's perturbed Lagrangian (normal penalty c_n, tangential κ_T)
    and with the compliance law (the same linear normal penalty, friction regularised by a
    small ε): the normal pressures coincide, and the tangential tractions draw together as κ_T
    grows (the stick spring stiffens towards the regularised law's rigid stick)."""
    from fenicsfriction.studies.contact.validation import Cattaneo

    common = {"h_contact": 0.01, "increments": 2}
    _, model = Cattaneo(**common).with_law(eps=1e-6).run()
    reference = model.surface_values()
    scale = np.abs(reference.traction).max()
    distances = []
    for penalty_T in (1e2, 1e3):
        _, model = Cattaneo(enforcement="perturbed-lagrangian", penalty_T=penalty_T,
                            **common).run()
        values = model.surface_values()
        # the same normal penalty; the tangential law moves the approach by ~1e-3
        assert np.allclose(values.pressure, reference.pressure,
                           atol=3e-3 * reference.pressure.max())
        distances.append(np.abs(values.traction - reference.traction).max() / scale)
    # measured 0.20 and 0.083: the stick spring's own compliance, then what is left is the
    # discretisation of the stick-slip boundary (one node of h = 0.01 flips between the laws)
    assert distances[1] < 0.5 * distances[0], distances
    assert distances[1] < 0.1, distances


def test_hertz_converges_as_the_compliance_stiffens():
    """Hertz's line contact with linear compliance c_n: the compliance adds p/c_n to the
    approach, so the half-width and peak pressure converge to the Signorini limit like 1/c_n:
    each decade of c_n shrinks the change by about ten."""
    from fenicsfriction.studies.contact.validation import Hertz

    widths, peaks = [], []
    for c_n in (1e2, 1e3, 1e4):
        summary, _ = Hertz(h_contact=0.01).with_law(c_n=c_n).run()
        widths.append(summary["half_width"])
        peaks.append(summary["max_pressure"])
    for values in (widths, peaks):
        changes = np.abs(np.diff(values))
        assert changes[1] < 0.3 * changes[0], values
    # and the stiffest is within the mesh's accuracy of Hertz (h = a/10 here)
    assert summary["half_width_error"] == pytest.approx(0.0, abs=0.02)
    assert summary["max_pressure_error"] == pytest.approx(0.0, abs=0.02)


def test_hertz_sphere_matches_hertz_within_its_mesh_accuracy():
    """The quarter sphere on the block (19,131 unknowns, h = a/5 at the contact, the default
    mesh): the contact radius (of the nodal rule's contact area) and the peak pressure (the
    nodal pressures projected onto c0 + c1 r² near the axis) within 3 % of Hertz's (Johnson
    1985, eqs. 4.22-4.23; measured -0.07 % and -0.42 %: the area's rim runs midway between
    contact and open nodes, the projection averages the nodes' 10 % scatter); each figure is
    what its name says, recomputed from the model; the Hertz ellipse fitted through the
    contact nodes' pressures within 2 % (measured +0.19 % and +0.71 %); the gap's sign change
    along the facets' edges hugs the last contact node (measured -7.7 %, within h/a = 20 %)."""
    from fenicsfriction.studies.contact.closed_forms import fit_hertz_pressure
    from fenicsfriction.studies.contact.validation import AXIS_DISC, Hertz

    scene = Hertz(dim=3)
    summary, model = scene.run()
    a, p0 = scene.closed_form()
    assert summary["contact_radius_error"] == pytest.approx(0.0, abs=0.03)
    assert summary["peak_pressure_error"] == pytest.approx(0.0, abs=0.03)
    # what the names say: the radius of the circle whose quarter is the contact area, and the
    # weighted least-squares c0 of c0 + c1 r² through the nodes within AXIS_DISC of it
    radius = float(np.sqrt(4 * model.contact_area() / np.pi))
    assert summary["contact_radius"] == pytest.approx(radius, rel=1e-12)
    values = model.surface_values()
    r = np.linalg.norm(values.x[:, :2], axis=1)
    near = (r <= AXIS_DISC * radius) & (values.load_weight > 0)
    w, p = values.load_weight[near], values.force[near, -1]
    normal = np.array([[w.sum(), (w * r[near]**2).sum()],
                       [(w * r[near]**2).sum(), (w * r[near]**4).sum()]])
    c0, _ = np.linalg.solve(normal, [(w * p).sum(), (w * p * r[near]**2).sum()])
    assert summary["peak_pressure"] == pytest.approx(c0, rel=1e-10)
    assert summary["peak_pressure_error"] == pytest.approx(c0 / p0 - 1, rel=1e-10)
    fitted_a, fitted_p0 = fit_hertz_pressure(r, values.pressure)
    assert fitted_a == pytest.approx(a, rel=0.02)
    assert fitted_p0 == pytest.approx(p0, rel=0.02)
    assert abs(summary["gap_crossing_radius_error"]) < 0.2
    assert summary["load"] == pytest.approx(scene.load, rel=1e-4)  # 4 × the quarter's force


def test_contact_area_is_the_projected_area_of_the_nodes_in_contact():
    """The default quarter sphere moved rigidly by δ into the block (no solve): the slave
    nodes below z = δ penetrate. Their projected tributary areas, all nodes together, tile
    the polygon of the surface's rim on the plane (the faceted surface is a graph over it;
    the shoelace area of the rim nodes, to round-off), in the gathered surface values too
    (whose unprojected weights tile the faceted hemisphere, twice the disc); the contact area
    sums those of exactly the nodes below z = δ, and the nodes in contact make a quarter disc
    whose radius is that of the rigid indentation, √(2Rδ − δ²), to within half an element
    (the area's rim runs midway between the nodes in and out of contact); the gap changes
    sign on the plane z = δ (the rigid gap z − δ, linear along each edge)."""
    from fenicsfriction.studies.contact import geometry
    from fenicsfriction.studies.contact.validation import Hertz

    R, h = 1.0, 0.02  # the default h_contact
    model = Hertz(dim=3).build(MPI.COMM_SELF)
    contact = model.contacts[0]
    X = contact.nodal_space.tabulate_dof_coordinates()
    owned = len(model._projected_weight)
    weights = model._projected_weight
    rim = (weights > 0) & np.isclose(X[:owned, 2], R)
    angle = np.arctan2(X[:owned][rim, 1], X[:owned][rim, 0])
    xs, ys = X[:owned][rim][np.argsort(angle), :2].T
    xs, ys = np.concatenate([[0.0], xs]), np.concatenate([[0.0], ys])  # and the centre
    polygon = 0.5 * abs(np.dot(xs, np.roll(ys, -1)) - np.dot(ys, np.roll(xs, -1)))
    assert weights.sum() == pytest.approx(polygon, rel=1e-10)
    assert polygon == pytest.approx(np.pi * R**2 / 4, rel=0.02)  # the rim is inscribed
    body1 = model._body1_dofs
    values = model.surface_values()
    assert values.projected_weight.sum() == pytest.approx(polygon, rel=1e-10)
    # the faceted hemisphere 2πR²/4 over the quarter disc πR²/4, both inscribed (measured 2.017)
    assert values.weight.sum() == pytest.approx(2 * polygon, rel=0.03)
    for rho in (0.06, 0.1, 0.14):
        delta = R - np.sqrt(R**2 - rho**2)
        model.u.x.array[:] = 0.0
        model.u.x.array[body1] = -delta
        model.u.x.scatter_forward()
        values = model.surface_values()
        below = values.x[:, 2] < delta
        assert model.contact_area(values) == pytest.approx(
            values.projected_weight[below].sum(), rel=1e-12)
        assert model.contact_area() == model.contact_area(values)
        radius = np.sqrt(4 * model.contact_area(values) / np.pi)
        assert abs(radius - rho) < h / 2, (rho, radius)
        edge = model.contact_edge(values)
        assert len(edge) > 0 and np.allclose(edge[:, 2], delta, rtol=0, atol=1e-12 * R)
    assert geometry.SLAVE in model.geometry.facet_tags.values


def test_pressure_on_axis_reproduces_quadratics_and_projects_hertz_as_the_integral_does():
    """The axis recovery is a weighted least-squares projection onto c0 + c1 r²: on scattered
    nodes it returns c0 of any such quadratic to round-off; for Hertz's profile on many
    nodes of equal weight per area it tends to the continuous projection over the disc,
    whose normal equations are integrated here by quadrature (+0.35 % at 0.6 a), to the
    sampling error of the nodes."""
    from scipy import integrate

    from fenicsfriction.studies.contact.validation import AXIS_DISC, pressure_on_axis

    rng = np.random.default_rng(3)
    xy = rng.uniform(0, 1, (400, 2))
    r = np.linalg.norm(xy, axis=1)
    weight = rng.uniform(0.5, 1.5, len(r))
    assert pressure_on_axis(r, 2.0 - 0.7 * r**2, weight, 1.0) == pytest.approx(2.0, rel=1e-12)
    # scattered values: the intercept of numpy's weighted line through (r², p) over the disc
    # (polyfit weighs the residuals, hence √w)
    noisy = 2.0 - 0.7 * r**2 + 0.1 * rng.standard_normal(len(r))
    near = r <= AXIS_DISC * 1.2
    line = np.polyfit(r[near] ** 2, noisy[near], 1, w=np.sqrt(weight[near]))
    assert pressure_on_axis(r, noisy, weight, 1.2) == pytest.approx(line[1], rel=1e-12)
    # Hertz's profile on a fine grid of the quarter disc (equal areas)
    n = 400
    g = (np.arange(n) + 0.5) / n
    gx, gy = np.meshgrid(g, g)
    r = np.hypot(gx, gy).ravel()
    p = np.sqrt(np.clip(1 - r**2, 0, None))
    recovered = pressure_on_axis(r, p, np.full(r.size, 1.0 / n**2), 1.0)
    rho = AXIS_DISC
    moment = [integrate.quad(lambda s, k=k: s**k * s, 0, rho)[0] for k in (0, 2, 4)]
    load = [integrate.quad(lambda s, k=k: s**k * np.sqrt(1 - s**2) * s, 0, rho)[0]
            for k in (0, 2)]
    c0, _ = np.linalg.solve([[moment[0], moment[1]], [moment[1], moment[2]]], load)
    assert c0 == pytest.approx(1.0035, abs=2e-4)
    assert recovered == pytest.approx(c0, abs=5e-4)  # the grid's O(1/n) rim error


def test_pressure_on_axis_names_a_bad_disc():
    from fenicsfriction.studies.contact.validation import pressure_on_axis

    with pytest.raises(ValueError, match=r"disc=1.5 is invalid: a fraction"):
        pressure_on_axis(np.array([0.0, 0.1]), np.ones(2), np.ones(2), 1.0, disc=1.5)
    with pytest.raises(ValueError, match="pressure=.* is invalid: nodes at two distances"):
        pressure_on_axis(np.array([0.0, 0.9]), np.ones(2), np.ones(2), 1.0)


@pytest.mark.parametrize("dim", [2, 3])
def test_friction_is_tangential_and_opposes_the_slip_on_a_tilted_interface(dim):
    """Both blocks turned rigidly by 0.3 rad (the interface tilted), the upper one moving
    with a velocity that has a normal part: the friction traction at every slave node in
    contact has no normal component and points against the tangential slip, with the
    magnitude of the regularised law, μ c_n d^m_n |w_T| / √(|w_T|² + ε²) (Martins & Oden
    1986; slip 0.3 ≫ ε = 1e-2, so within 0.1 % of μ p)."""
    import ufl

    msh, cell_tags, ft = stacked_blocks(MPI.COMM_WORLD, dim, 3, 4, overlap=0.02)
    V = _compat.vector_function_space(msh, 1)
    u, u_old = fem.Function(V, name="u"), fem.Function(V, name="u_old")
    theta = 0.3
    c, s = np.cos(theta), np.sin(theta)
    turn = np.eye(dim)
    turn[:2, :2] = [[c, -s], [s, c]]
    up = turn[:, dim - 1]  # the interface's normal e_y (2D) / e_z (3D), turned
    if dim == 3:  # turn about x as well, so that no axis stays in the interface
        turn = turn @ np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
        up = turn[:, 2]
    x = V.tabulate_dof_coordinates()[:, :dim]
    u.x.array[:] = (x @ (turn - np.eye(dim)).T).ravel()
    slip = 0.3 * turn[:, 0] + (0.1 * turn[:, 1] if dim == 3 else 0.0)
    velocity = slip + 0.2 * turn[:, dim - 1]  # a normal part the friction must not see
    upper = _compat.cell_dofs(V, cell_tags.indices[cell_tags.values == UPPER])
    moving = u.x.array.copy().reshape(-1, dim)
    moving[upper] -= 0.1 * velocity
    u_old.x.array[:] = moving.ravel()
    for f in (u, u_old):
        f.x.scatter_forward()
    law = InterfaceLaw(c_n=100.0, m_n=2.0, mu=0.5, eps=1e-2)
    contact = NodeToSegment(u, ft, SLAVE, MASTER, law, velocity=(u - u_old) / 0.1,
                            fields=[u_old])
    contact.update()
    t, n = contact.traction, contact.normal
    direction = ufl.as_vector(list(-slip / np.linalg.norm(slip)))
    values = contact.nodal_values([ufl.dot(t, n), ufl.dot(t, direction),
                                   ufl.sqrt(ufl.dot(t, t)), contact.pressure,
                                   ufl.dot(n, ufl.as_vector(list(up)))])()
    touching = values[:, 3] > 0
    assert MPI.COMM_WORLD.allreduce(int(touching.sum())) >= 4 * (dim - 1)
    normal_part, along, size, pressure, aligned = values[touching].T
    largest = MPI.COMM_WORLD.allreduce(float(size.max(initial=0.0)), op=MPI.MAX)
    np.testing.assert_allclose(aligned, 1.0, atol=1e-10)  # the master's normal is turned
    np.testing.assert_allclose(normal_part, 0.0, atol=1e-12 * largest)
    np.testing.assert_allclose(along, size, rtol=1e-10)  # all of it against the slip
    np.testing.assert_allclose(size, 0.5 * pressure, rtol=1e-3)
