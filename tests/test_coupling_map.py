r"""The finite element mode-coupling map (fenicsfriction.cea.coupling_map) on the block of
Martins & Oden (1986) (4 × 3 nine-node quadrilaterals, 126 dofs, μ_crit = 0.370 by
tests/test_stability.py), full and by modal projection.
"""

import itertools

from mpi4py import MPI

import numpy as np
import pytest
from test_stability import dense_operators, sensitivity

import fenicsfriction as ff
from fenicsfriction.cea.coupling_map import ProjectedStability, coupling_map
from fenicsfriction.stability import Loci, StabilitySolver

COMM = MPI.COMM_WORLD
MAX_MODULUS = 3e4  # [1/s]: the block's six modes (tests/test_stability.py)
VALUES = np.linspace(0.0, 0.5, 6)
_COUNTER = itertools.count()


def prefix(name: str) -> str:
    """A PETSc options prefix no other solver of the run uses (ranks count alike)."""
    return f"map{next(_COUNTER)}{name}_"


def loci(modes: int | None = None) -> Loci:
    """The block at rest (μ = 0), its loci with the full eigensolver or one projected on
    ``modes`` modes."""
    model = ff.BlockOnBelt(refine=1).build(COMM, with_friction=True)
    model.initial_guess()
    steady = ff.SteadySolver(model.residual, prefix=prefix("steady"),
                             options=model.solver_options())
    solver = StabilitySolver(model.residual, prefix=prefix("pep"))
    if modes is not None:
        solver = ProjectedStability(solver, modes, prefix=prefix("basis"))
    return Loci(steady, solver, model.mu, MAX_MODULUS)


@pytest.fixture(scope="module")
def full_map():
    return coupling_map(loci(), VALUES, tol=1e-4)


def test_the_map_finds_the_known_onset_and_its_two_modes(full_map, shared_tmp_path):
    """The onset bisected between the grid's last stable (0.3) and first unstable (0.4) value
    is the known 0.370 (to the 1e-3 the mesh's value is known to; measured 0.3703), the
    colliding pair is the two tracked modes at 815 and 971 Hz at μ = 0 (the normal/rotation
    pair), each a curve over the values up to the coalescence, and the map is JSON and a PNG."""
    assert len(full_map.coalescences) == 1
    event = full_map.coalescences[0]
    assert event.p_crit == pytest.approx(0.370, abs=1e-3)
    assert 0.3 <= event.onset[0] < event.onset[1] <= 0.4
    assert event.onset[1] - event.onset[0] <= 1e-4
    assert len(set(event.modes)) == 2 and event.growing in event.modes
    first = {m["mode"]: m for m in full_map.records[0]["modes"]}
    for mode in event.modes:
        assert 800 < first[mode]["frequency"] < 1000  # Hz: 815 and 971 at μ = 0
        assert all(mode in {m["mode"] for m in r["modes"]} for r in full_map.records[:4])
    assert max(r["max_re"] for r in full_map.records) > 100  # a few hundred 1/s past it
    data = full_map.to_json()
    assert data["projection"] is None and data["coalescences"][0]["p_crit"] == event.p_crit
    path = shared_tmp_path / "map.png"
    full_map.plot(path, max_frequency=1500.0)
    COMM.Barrier()
    assert path.read_bytes()[:4] == b"\x89PNG"


def test_the_projected_onset_approaches_the_full_one_as_modes_are_added(full_map):
    """The basis is the frictionless problem's modes at μ = 0; along the sweep the contact's
    pressure moves to the front edge, so the stiffness the basis must represent changes, and
    the projected onset converges from above (Galerkin: a stiffer discrete system) as modes are
    added. Measured error (onset bisected to 1e-4 in [0.35, 0.4], the full one in [0.3, 0.4]:
    the midpoints may differ by 1e-4): 9.0e-3 with 3 modes, 5.2e-3 with 6, 2.3e-3 with 12,
    1.3e-3 with 40, 7.8e-4 with 63, 0 with all 126 (on the grid of the full map)."""
    errors = []
    for modes in (3, 12, 40):
        projected = coupling_map(loci(modes), [0.0, 0.35, 0.4], tol=1e-4)
        assert projected.projection == modes
        errors.append(projected.coalescences[0].p_crit - full_map.coalescences[0].p_crit)
    assert 0 < errors[2] < errors[1] < errors[0] < 0.012, errors
    assert errors[2] < 2e-3


def test_a_complete_basis_gives_the_full_eigenvalues():
    """With all 126 modes the projection is a change of basis, so at μ = 0.45 (past the onset)
    the six eigenvalues are the full PEP's up to rounding: each projected pair has a relative
    residual against the full matrices below 1e-8, and differs from the full eigenvalue by at
    most twice κ(λ) η(λ) |λ| (first-order perturbation theory, Tisseur 2000: condition number
    times backward error, both from the dense SVD of T(λ)). The projected pencil, K's modal
    entries up to 1.2e11 against M = I, is solved with a backward error of about 1e-9, and the
    growing pair, κ ≈ 2.3e3 so near its coalescence, moves by 2.4e-6 |λ| (measured; the other
    modes by less than 1e-9)."""
    full, projected = loci(), loci(126)
    a, b = full._solve_at(0.45), projected._solve_at(0.45)
    assert len(a) == len(b) == 6
    K, C, M = dense_operators(projected.stability.stability)
    for y in b:
        x = min(a, key=lambda m: abs(m.value - y.value))  # ±Re λ pairs share |λ|
        assert y.residual < 1e-8
        kappa, eta = sensitivity(K, C, M, y.value)
        assert abs(x.value - y.value) <= 2 * kappa * eta * abs(x.value) + 1e-12 * abs(x.value)


def test_the_projection_basis_is_the_frictionless_problems_at_its_first_state():
    """A sweep that starts at μ = 0.2 computes its basis there: the modes of the symmetric part
    of K̄ at that state with μ set to 0 (the friction stiffness dropped, the contact state
    kept) and M. The reference sets μ = 0 by hand, assembles the dense K̄ and M and solves the
    symmetric generalized problem with LAPACK (eigh). Both solves are accurate relative to the
    operator, whose ω² reach 1e11 (the contact's stiffness): 1e-8 of each ω² plus 1e-14 of the
    largest asked (measured: 1.5e-7 relative, 4e-6 absolute, on the driver spring's 24.7
    rad²/s²; 1e-10 relative on the others). The friction stiffness at μ = 0.2 would move the
    contact's modes by percents. (At μ = 0 it vanishes, so the maps above, which start there,
    cannot tell.)"""
    import scipy.linalg

    locus = loci(6)
    locus._solve_at(0.2)
    solver = locus.stability.stability
    assert solver.residual.friction is locus.parameter
    locus.parameter.value = 0.0
    try:
        K, _, M = dense_operators(solver)
    finally:
        locus.parameter.value = 0.2
    omega2 = scipy.linalg.eigh(0.5 * (K + K.T), M, eigvals_only=True)
    error = np.abs(locus.stability.basis.omega2 - omega2[:6])
    assert np.all(error <= 1e-8 * omega2[:6] + 1e-14 * omega2[-1]), (error, omega2[:6])
