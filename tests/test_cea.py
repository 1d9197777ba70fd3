r"""Complex eigenvalue analysis on matrices (:mod:`fenicsfriction.cea`): the dense QZ solve, the
SLEPc band solve, the modal projection, the sweep with coalescence detection, the readers, and
the flutter onsets of the two-degree-of-freedom model of Hoffmann et al. (2002).

Eigenvalues are compared between independent solvers (LAPACK's QZ on the companion form, SLEPc's
TOAR with shift-and-invert, ARPACK on the companion form with a complex shift): each computes
them with a backward error of a few machine epsilons times the conditioning, and the chains used
here have well separated, well conditioned eigenvalues, hence the relative tolerance 1e-8.
"""

import itertools
import math

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest
import scipy.io
import scipy.sparse
import scipy.sparse.linalg

from fenicsfriction.cea import (
    Band,
    BandSolver,
    HoffmannModel,
    ModalBasis,
    ParametricPencil,
    Sweep,
    dense_modes,
    from_array,
    read_matrix,
    symmetric_part,
    to_dense,
)
from fenicsfriction.cea.dense import quadratic_eig, relative_residuals

COMM = MPI.COMM_WORLD
_COUNTER = itertools.count()


def prefix(name: str) -> str:
    """A PETSc options prefix of its own for each solver (options outlive solvers)."""
    return f"tcea{next(_COUNTER)}{name}_"


def chain(n: int, seed: int = 0) -> dict[str, scipy.sparse.csr_matrix]:
    """A chain of n masses sliding on a belt, each with a tangential (x) and a normal (y)
    displacement: the x and y chains have different stiffnesses, every mass rests on a contact
    spring k_c and is held by an oblique spring coupling its x and y (k_xy), and friction adds
    -μ k_c to the x row from y (K1): a chain of Hoffmann's oscillators. The unknowns are
    interleaved (x0, y0, x1, y1, ...): 2n of them."""
    rng = np.random.default_rng(seed)

    def tridiagonal(k: float) -> scipy.sparse.csr_matrix:
        return scipy.sparse.diags([-k * np.ones(n - 1), 2 * k * np.ones(n), -k * np.ones(n - 1)],
                                  [-1, 0, 1])

    kc = 300.0
    Kx, Ky = tridiagonal(1e4), tridiagonal(1.3e4) + kc * scipy.sparse.eye(n)
    x, y = np.arange(0, 2 * n, 2), np.arange(1, 2 * n, 2)
    K0 = scipy.sparse.lil_matrix((2 * n, 2 * n))
    K0[np.ix_(x, x)] = Kx.toarray() if n <= 300 else Kx
    K0[np.ix_(y, y)] = Ky.toarray() if n <= 300 else Ky
    K0[x, y] = K0[y, x] = 100.0
    K1 = scipy.sparse.csr_matrix((-kc * np.ones(n), (x, y)), shape=(2 * n, 2 * n))
    masses = 1.0 + 0.5 * rng.random(2 * n)
    return {"M": scipy.sparse.diags(masses).tocsr(), "K0": K0.tocsr(), "K1": K1,
            "C0": scipy.sparse.diags(0.02 * masses).tocsr()}


def sparse_random(n: int, density: float, rng: np.random.Generator) -> scipy.sparse.csr_matrix:
    """An n × n matrix with about density·n² entries uniform in [0, 1) at random places
    (scipy.sparse.random's seeding keyword differs between SciPy versions)."""
    count = int(density * n * n)
    rows, cols = rng.integers(0, n, count), rng.integers(0, n, count)
    return scipy.sparse.csr_matrix((rng.random(count), (rows, cols)), shape=(n, n))


def at(parts: dict, mu: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return (parts["M"].toarray(), parts["C0"].toarray(),
            (parts["K0"] + mu * parts["K1"]).toarray())


def petsc(parts: dict, mu: float) -> tuple[PETSc.Mat, PETSc.Mat, PETSc.Mat]:
    return tuple(from_array(A, COMM) for A in at(parts, mu))


def values(modes) -> np.ndarray:
    return np.array([m.value for m in modes])


def test_companion_qz_gives_the_undamped_frequencies_in_closed_form():
    """Undamped Hoffmann model below its onset: λ = iω, ω² the eigenvalues of K/m, which for a
    2 × 2 matrix are (tr ± sqrt(tr² - 4 det)) / 2."""
    model = HoffmannModel()
    parts = model.matrices()
    K = parts["K0"] + 0.5 * parts["K1"]
    tr, det = np.trace(K), np.linalg.det(K)
    omega2 = np.array([tr - math.sqrt(tr**2 - 4 * det), tr + math.sqrt(tr**2 - 4 * det)]) / 2
    modes = dense_modes(parts["M"], np.zeros((2, 2)), K)
    assert np.allclose(values(modes), 1j * np.sqrt(omega2), rtol=1e-13, atol=1e-13)
    assert max(m.residual for m in modes) < 1e-14


def test_band_solve_by_pep_agrees_with_dense_qz():
    """SLEPc's TOAR (forced even on a small system) and LAPACK's QZ find the same eigenvalues in
    the band, each with a small residual, and nothing outside it."""
    parts = chain(100)
    band = Band(2.0, 12.0)
    solver = BandSolver(COMM, prefix=prefix("pep"), dense_below=0)
    pep = solver.solve(*petsc(parts, 0.4), band)
    assert solver.last_method == "pep"
    qz = dense_modes(*at(parts, 0.4), band)
    assert len(pep) == len(qz) > 5
    assert np.allclose(values(pep), values(qz), rtol=1e-8, atol=0)
    assert max(m.residual for m in pep + qz) < 1e-10
    assert all(band.contains(m.value) for m in pep)


def test_band_solve_by_pep_agrees_with_dense_qz_on_a_random_sparse_pencil():
    """n = 160, K an unsymmetric sparse random matrix made positive by its diagonal, C random
    sparse, M a random positive diagonal: no structure for either solver to rely on."""
    rng = np.random.default_rng(11)
    n = 160
    noise = sparse_random(n, 0.02, rng)
    K = (noise + scipy.sparse.diags(4.0 + rng.random(n))).tocsr() * 1e3
    C = sparse_random(n, 0.01, rng)
    M = scipy.sparse.diags(0.5 + rng.random(n)).tocsr()
    band = Band(8.0, 9.0)  # the lowest 33 eigenvalues
    solver = BandSolver(COMM, prefix=prefix("random"), dense_below=0)
    pep = solver.solve(*(from_array(A, COMM) for A in (M, C, K)), band)
    qz = dense_modes(M.toarray(), C.toarray(), K.toarray(), band)
    assert len(pep) == len(qz) > 5
    qz_values = values(qz)
    nearest = qz_values[np.abs(values(pep)[:, None] - qz_values[None, :]).argmin(axis=1)]
    assert np.allclose(values(pep), nearest, rtol=1e-8, atol=0)
    assert max(m.residual for m in pep) < 1e-10


def test_band_solve_on_a_mid_size_pencil_agrees_with_arpack():
    """n = 2000: SLEPc's PEP against ARPACK (scipy) on the companion pencil with a complex shift
    at the band's centre, an independent method and arithmetic."""
    parts = chain(1000, seed=3)
    band = Band(0.4, 0.9)  # about 11 modes in the band, 20 below its top
    pep = BandSolver(COMM, prefix=prefix("mid")).solve(*petsc(parts, 0.3), band)
    M, C, K = (parts["M"], parts["C0"], parts["K0"] + 0.3 * parts["K1"])
    n = M.shape[0]
    eye, zero = scipy.sparse.eye(n), scipy.sparse.csr_matrix((n, n))
    # complex matrices: ARPACK then works in complex arithmetic about the complex shift
    A = scipy.sparse.bmat([[zero, eye], [-K, -C]]).tocsc().astype(complex)
    B = scipy.sparse.bmat([[eye, zero], [zero, M]]).tocsc().astype(complex)
    centre = 1j * sum(band.omega) / 2
    arpack = scipy.sparse.linalg.eigs(A, k=3 * len(pep) + 10, M=B, sigma=centre,
                                      return_eigenvectors=False)
    assert max(abs(arpack - centre)) > abs(band.omega[1] - band.omega[0]) / 2 + band.rate
    inside = arpack[[band.contains(v) for v in arpack]]
    inside = inside[np.argsort(inside.imag)]
    assert len(pep) == len(inside) > 5
    assert np.allclose(values(pep), inside, rtol=1e-8, atol=0)
    assert max(m.residual for m in pep) < 1e-10


def test_modal_projection_on_every_mode_equals_the_full_solve():
    parts = chain(15)
    M, C, K = petsc(parts, 0.6)
    band = Band(0.0, 40.0)
    full = BandSolver(COMM, prefix=prefix("all")).solve(M, C, K, band)
    basis = ModalBasis(symmetric_part(K), M, modes=30, prefix=prefix("basis"))
    projected = basis.solve(M, C, K, band)
    assert len(projected) == len(full) == 30
    assert np.allclose(values(projected), values(full), rtol=1e-10, atol=0)
    assert max(m.residual for m in projected) < 1e-10


def test_modal_basis_is_mass_orthonormal_and_matches_the_dense_modes():
    """Φᵀ M Φ = I and the frequencies are the symmetric problem's (dense eigh)."""
    parts = chain(40)
    M, _, K = petsc(parts, 0.0)
    basis = ModalBasis(K, M, max_frequency=10.0, prefix=prefix("freq"))
    omega2 = scipy.linalg.eigh(parts["K0"].toarray(), parts["M"].toarray(), eigvals_only=True)
    expected = omega2[omega2 <= (2 * math.pi * 10.0) ** 2]
    assert np.allclose(basis.omega2, expected, rtol=1e-10)
    assert np.allclose(basis.project(M), np.eye(basis.size), atol=1e-10)


def test_projection_error_decreases_as_modes_are_added():
    """The lowest coupled modes of a 400-unknown chain on 10, 20, 40, 80 modes of the frictionless
    problem: a Galerkin projection, so the error and the residual against the full matrices of
    the projected eigenvalue nearest each exact one fall as the basis grows."""
    parts = chain(200, seed=1)
    M, C, K = petsc(parts, 0.5)
    band = Band(0.0, 2.0)
    full = values(BandSolver(COMM, prefix=prefix("ref"), dense_below=0).solve(M, C, K, band))
    basis = ModalBasis(from_array(parts["K0"], COMM), M, modes=80, prefix=prefix("grow"))
    errors, residuals = [], []
    for m in (10, 20, 40, 80):
        projected = basis.truncated(m).solve(M, C, K, Band(0.0, 4.0))
        nearest = [min(projected, key=lambda p, v=v: abs(p.value - v)) for v in full]
        errors.append(max(abs(p.value - v) / abs(v) for p, v in zip(nearest, full, strict=True)))
        residuals.append(max(p.residual for p in nearest))
    assert all(b < a for a, b in itertools.pairwise(errors)), errors
    assert all(b < a for a, b in itertools.pairwise(residuals)), residuals
    assert errors[0] > 1e-6 and errors[-1] < errors[0] / 100


def test_residuals_of_the_companion_solve_are_backward_errors():
    """A perturbed eigenvalue has a residual of the order of its perturbation."""
    M, C, K = at(chain(5), 0.2)
    lam, w = quadratic_eig(M, C, K)
    assert relative_residuals(M, C, K, lam, w).max() < 1e-13
    assert relative_residuals(M, C, K, lam * (1 + 1e-6), w).min() > 1e-8


def test_pencil_at_a_parameter_is_the_polynomial_in_it():
    rng = np.random.default_rng(5)
    arrays = {name: rng.standard_normal((7, 7)) for name in ("M", "C0", "C1", "K0", "K1", "K2")}
    pencil = ParametricPencil(**{k: from_array(v, COMM) for k, v in arrays.items()})
    M, C, K = (to_dense(A) for A in pencil.at(0.7))
    assert np.allclose(M, arrays["M"])
    assert np.allclose(C, arrays["C0"] + 0.7 * arrays["C1"])
    assert np.allclose(K, arrays["K0"] + 0.7 * arrays["K1"] + 0.49 * arrays["K2"])
    bare = ParametricPencil(M=pencil.M, K0=pencil.K0)
    assert not to_dense(bare.at(1.0)[1]).any()
    with pytest.raises(ValueError, match=r"^K1='3x3' is invalid: must have the size of M"):
        ParametricPencil(M=pencil.M, K0=pencil.K0, K1=from_array(np.eye(3), COMM))


def _write_on_rank0(write) -> None:
    if COMM.rank == 0:
        write()
    COMM.Barrier()


def test_readers_round_trip_matrix_market_matlab_and_petsc_binary(shared_tmp_path):
    A = (sparse_random(9, 0.3, np.random.default_rng(2)) + scipy.sparse.eye(9)).tocsr()
    B = np.arange(81.0).reshape(9, 9)
    _write_on_rank0(lambda: scipy.io.mmwrite(str(shared_tmp_path / "A.mtx"), A))
    _write_on_rank0(lambda: scipy.io.savemat(str(shared_tmp_path / "one.mat"), {"K": A}))
    _write_on_rank0(lambda: scipy.io.savemat(str(shared_tmp_path / "two.mat"), {"K": A, "M": B}))
    viewer = PETSc.Viewer().createBinary(str(shared_tmp_path / "A.petsc"), "w", comm=COMM)
    from_array(A, COMM).view(viewer)
    viewer.destroy()
    for path in ("A.mtx", "one.mat", "two.mat:K", "A.petsc"):
        read = read_matrix(f"{shared_tmp_path}/{path}", COMM)
        assert read.getOwnershipRange() == from_array(A, COMM).getOwnershipRange()
        # MatrixMarket's text keeps 16 significant digits
        assert np.allclose(to_dense(read), A.toarray(), rtol=1e-15, atol=0), path
    assert np.array_equal(to_dense(read_matrix(f"{shared_tmp_path}/two.mat:M", COMM)), B)


@pytest.mark.parametrize(("content", "message"), [
    (np.ones((2, 3)), r"^--K='2x3' is invalid: must be a square matrix"),
    (np.array([[1.0, np.nan], [0.0, 1.0]]), r"is invalid: all entries must be finite"),
    (np.array([[1j, 0], [0, 1]]), r"is invalid: must be real"),
])
def test_readers_reject_what_is_not_a_real_square_finite_matrix(shared_tmp_path, content,
                                                                 message):
    path = shared_tmp_path / "bad.mtx"
    _write_on_rank0(lambda: scipy.io.mmwrite(str(path), content))
    with pytest.raises(ValueError, match=message):
        read_matrix(path, COMM, name="--K")


def test_readers_name_the_flag_of_a_missing_file_or_an_ambiguous_matlab_file(shared_tmp_path):
    with pytest.raises(ValueError, match=r"^--M='nowhere.mtx' is invalid: no such file$"):
        read_matrix("nowhere.mtx", COMM, name="--M")
    path = shared_tmp_path / "two.mat"
    _write_on_rank0(lambda: scipy.io.savemat(str(path), {"K": np.eye(2), "M": np.eye(2)}))
    with pytest.raises(ValueError, match=r"holds 2 matrices \(K, M\): name one as FILE:VARIABLE"):
        read_matrix(path, COMM, name="--M")
    with pytest.raises(ValueError, match=r"the file's matrices are K, M"):
        read_matrix(f"{path}:C", COMM, name="--M")
    garbage = shared_tmp_path / "garbage.bin"
    _write_on_rank0(lambda: garbage.write_bytes(b"not a matrix"))
    with pytest.raises(ValueError, match=r"not a PETSc binary matrix"):
        read_matrix(garbage, COMM, name="--K")


def test_band_rejects_an_empty_or_negative_range():
    with pytest.raises(ValueError, match=r"^fmax=1.0 is invalid: must be a finite number > fmin"):
        Band(2.0, 1.0)
    with pytest.raises(ValueError, match=r"^fmin=-1.0 is invalid"):
        Band(-1.0, 1.0)


# --- Hoffmann et al. (2002) -----------------------------------------------------------------

def hoffmann_sweep(model: HoffmannModel, growth_tol: float = 1e-9) -> Sweep:
    parts = model.matrices()
    band = Band(0.0, 1.0)
    return Sweep(lambda mu: dense_modes(parts["M"], parts["C0"], parts["K0"] + mu * parts["K1"],
                                        band, comm=COMM), COMM, growth_tol)


def test_hoffmann_undamped_onset_by_hand():
    """k11 = 2 cos²45° + cos²135° = 3/2, k12 = 2·1/2 - 1/2 = 1/2, k22' = 3/2 + 1 = 5/2:
    μ_c = ((3/2 - 5/2)² + 4/4) / (4 · 1/2 · 1) = 1, ω_c² = (3/2 + 5/2)/2 = 2."""
    mu, omega = HoffmannModel().undamped_onset()
    assert mu == pytest.approx(1.0, rel=1e-14)
    assert omega == pytest.approx(math.sqrt(2.0), rel=1e-14)


def test_sweep_finds_hoffmann_coalescence_without_damping():
    """The two modes merge at μ_c with frequency ω_c; bisection brackets μ_c to its tolerance
    and the relative frequency gap closes past it."""
    model = HoffmannModel(k1=1.7, k3=1.3)
    mu_c, omega_c = model.undamped_onset()
    sweep = hoffmann_sweep(model)
    sweep.follow(np.linspace(0.0, 2 * mu_c, 24))  # no grid value at μ_c itself
    (event,) = sweep.coalescences()
    assert event.interval[0] < mu_c < event.interval[1] and sorted(event.modes) == [0, 1]
    assert event.gap[1] < 1e-12 < event.gap[0]
    refined = sweep.refine(event, tol=1e-7)
    # past μ_c, Re λ grows like sqrt(μ - μ_c): it exceeds growth_tol |λ| within (1e-9)² of μ_c
    assert refined.onset[0] - 1e-12 <= mu_c <= refined.onset[1] + 1e-12
    assert refined.frequency * 2 * math.pi == pytest.approx(omega_c, rel=1e-3)


def test_damping_on_one_coordinate_halves_hoffmann_onset():
    """C = diag(c, 0): by hand, Δ3 = m²c²(k12² - μ k12 k3) vanishes at μ_c = k12/k3 whatever c,
    with ω_c² = a1/a3 = k22'/m (the destabilisation paradox: μ_c drops from 1 to 1/2 for any
    c > 0). The sweep's bisection finds it (Re λ grows linearly past μ_c, slope ~ c: the growth
    threshold 1e-9|λ| shifts it by < 1e-6)."""
    model = HoffmannModel(c1=0.02)
    mu_c, omega_c = model.damped_onset()
    assert mu_c == pytest.approx(model.k12 / model.k3, rel=1e-12)
    assert omega_c == pytest.approx(math.sqrt(model.k22 / model.m), rel=1e-12)
    sweep = hoffmann_sweep(model)
    sweep.follow(np.linspace(0.0, 1.5, 16))
    refined = sweep.refine(sweep.coalescences()[0], tol=1e-8)
    assert refined.p_crit == pytest.approx(mu_c, abs=1e-6)
    assert refined.frequency * 2 * math.pi == pytest.approx(omega_c, rel=1e-4)


def test_equal_damping_raises_hoffmann_onset_as_proportional_damping_predicts():
    """C = c M: λ² + cλ + s = 0 for each eigenvalue s = α + iβ of K/m; Re λ = 0 where β² = c²α,
    β² = k12 k3 (μ - μ_c0), α = ω_c²: μ_c = μ_c0 + c² ω_c² / (k12 k3)."""
    c = 0.05
    model = HoffmannModel(c1=c, c2=c)
    mu_c0, omega_c0 = HoffmannModel().undamped_onset()
    expected = mu_c0 + c**2 * omega_c0**2 / (model.k12 * model.k3)
    mu_c, omega_c = model.damped_onset()
    assert mu_c == pytest.approx(expected, rel=1e-12)
    assert omega_c == pytest.approx(omega_c0, rel=1e-12)
    sweep = hoffmann_sweep(model)
    sweep.follow(np.linspace(0.0, 2.0, 21))
    refined = sweep.refine(sweep.coalescences()[0], tol=1e-8)
    assert refined.p_crit == pytest.approx(mu_c, abs=1e-6)
    assert mu_c > mu_c0 > HoffmannModel(c1=c).damped_onset()[0]


def test_damped_onset_matches_the_eigenvalues_on_both_sides():
    """Unequal damping on both coordinates (no hand formula): the Routh-Hurwitz root separates
    μ where every eigenvalue decays from μ where one grows (dense QZ)."""
    model = HoffmannModel(c1=0.003, c2=0.03)
    mu_c, omega_c = model.damped_onset()
    parts = model.matrices()
    growth = [quadratic_eig(parts["M"], parts["C0"], parts["K0"] + mu * parts["K1"])[0]
              for mu in (mu_c * (1 - 1e-6), mu_c * (1 + 1e-6))]
    assert growth[0].real.max() < 0 < growth[1].real.max()
    assert abs(growth[1][growth[1].real.argmax()]) == pytest.approx(omega_c, rel=1e-5)


def test_coalescence_of_a_chain_by_the_full_solver():
    """The chain's x and y modes couple through friction: the sweep on SLEPc's band solve finds a
    coalescence whose refined onset the dense QZ confirms (stable just before, growing just
    after)."""
    parts = chain(20, seed=4)
    band = Band(0.0, 6.0)
    solver = BandSolver(COMM, prefix=prefix("sweep"), dense_below=0)
    sweep = Sweep(lambda mu: solver.solve(*petsc(parts, mu), band), COMM, growth_tol=1e-7)
    sweep.follow(np.linspace(0.0, 3.0, 7))
    assert solver.last_method == "pep"
    events = sweep.coalescences()
    assert events, sweep.records[-1]["max_re"]
    refined = sweep.refine(events[0], tol=1e-3)
    low, high = (dense_modes(*at(parts, mu), band) for mu in refined.onset)
    assert max(m.value.real for m in low) < 1e-7 * max(abs(m.value) for m in low)
    assert max(m.value.real for m in high) > 0
