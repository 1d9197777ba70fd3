"""The mollified friction bound of Oden & Pires (1983) (Kalker 1986, eq. 27).

The operator is checked against its moment conditions (constants everywhere, linear fields in
the interior of a uniform mesh, the second moment of the continuous kernel on a quadratic),
and the mollified law against the local one: a radius below the node spacing is the local law.
"""

from mpi4py import MPI

import numpy as np
import pytest
import scipy.integrate

import fenicsfriction as ff
from fenicsfriction.mollification import SurfaceMollifier, mollifier_kernel
from fenicsfriction.panagiotopoulos import PanagiotopoulosSolver

COMM = MPI.COMM_WORLD


def _share(points, weights):
    """This rank's share of the surface nodes (contiguous blocks: any split must do)."""
    parts = np.array_split(np.arange(len(weights)), COMM.size)[COMM.rank]
    return points[parts], weights[parts], parts


def _line(n=161, length=1.0):
    x = np.linspace(0.0, length, n)[:, None]
    w = np.full(n, length / (n - 1))
    w[[0, -1]] /= 2  # trapezoidal tributary lengths
    return x, w


def test_mollifier_reproduces_constants_everywhere_and_linear_fields_inside():
    x, w = _line()
    r = 0.05
    points, weights, mine = _share(x, w)
    M = SurfaceMollifier(points, weights, r, COMM)
    assert np.allclose(M(np.full(len(mine), 3.0)), 3.0, rtol=0, atol=1e-14)
    linear = 2.0 - 5.0 * points[:, 0]
    interior = (points[:, 0] > r) & (points[:, 0] < 1 - r)
    # symmetric neighbours on a uniform line: the first moment vanishes to round-off
    assert np.allclose(M(linear)[interior], linear[interior], rtol=0, atol=1e-13)
    # at the ends the average is one-sided: a linear field is not reproduced there
    assert np.abs(M(linear) - linear).max() > 0.01


def test_mollifier_of_a_quadratic_adds_the_kernel_second_moment():
    """M[x²] = x² + m₂ inside, m₂ = ∫ω y² / ∫ω of the continuous kernel (a mollifier that
    did nothing, or a wrong kernel, would not give it)."""
    x, w = _line(n=801)
    r = 0.05
    points, weights, _ = _share(x, w)
    M = SurfaceMollifier(points, weights, r, COMM)
    kernel = lambda y: mollifier_kernel(np.array([abs(y)]), r)[0]  # noqa: E731
    m0 = scipy.integrate.quad(kernel, -r, r)[0]
    m2 = scipy.integrate.quad(lambda y: kernel(y) * y**2, -r, r)[0] / m0
    interior = (points[:, 0] > r) & (points[:, 0] < 1 - r)
    added = (M(points[:, 0] ** 2) - points[:, 0] ** 2)[interior]
    # 40 nodes across the kernel: the trapezoidal sums of a C∞ bump converge fast
    assert added == pytest.approx(np.full(added.shape, m2), rel=1e-4)


def test_mollifier_on_a_plane_reproduces_linear_fields_inside():
    g = np.linspace(0.0, 1.0, 41)
    X, Y = np.meshgrid(g, g)
    x = np.column_stack([X.ravel(), Y.ravel()])
    w = np.full(len(x), (g[1] - g[0]) ** 2)
    points, weights, _ = _share(x, w)
    M = SurfaceMollifier(points, weights, 0.1, COMM)
    linear = 1.0 + points @ np.array([2.0, -3.0])
    inside = np.all((points > 0.1) & (points < 0.9), axis=1)
    assert np.allclose(M(linear)[inside], linear[inside], rtol=0, atol=1e-12)


def test_mollifier_rejects_a_negative_radius():
    x, w = _line(n=5)
    with pytest.raises(ValueError, match="radius=-1"):
        SurfaceMollifier(x, w, -1.0, MPI.COMM_SELF)


def _block(refine):
    scene = ff.BlockOnBelt(degree=1, contact_quadrature="nodal", refine=refine,
                           law=ff.InterfaceLaw(mu=1.2))
    model = scene.build(COMM, with_friction=True)
    return scene, model, scene.L / (4 * refine)


def _contact_penetration(model):
    return np.concatenate(COMM.allgather(model.nodal_contact()[0]))


def test_mollified_law_tends_to_the_local_law_as_the_radius_shrinks():
    """Nodal contact rule (the bound is evaluated at the nodes, as the operator sees it): a
    radius below the node spacing h leaves every node alone, so the process reproduces
    Newton's local solution; larger radii average the peak at the loaded corner down."""
    scene, model, h = _block(refine=2)
    options = model.solver_options()
    model.initial_guess()
    PanagiotopoulosSolver(model.residual, method="newton", prefix="ml_newton_",
                          options=options).solve()
    local = _contact_penetration(model)
    errors = []
    for r in (0.5 * h, 2 * h, 4 * h):
        process = PanagiotopoulosSolver(model.residual, mollification_radius=r,
                                        prefix="ml_process_", options=options)
        model.initial_guess()
        assert process.solve().converged
        d = _contact_penetration(model)
        errors.append(np.abs(d - local).max() / local.max())
        corner = np.argmax(local)
        if r > h:  # the peak (the loaded corner) is lowered
            assert d[corner] < local[corner]
    # r < h: the local law, to the process's tolerance (1e-8 on the traction) over m_n = 2.5
    assert errors[0] < 1e-6
    # r = 2h, 4h: a change of per cent, growing with r (about linearly: docs)
    assert 0.01 < errors[1] < errors[2] < 0.2
