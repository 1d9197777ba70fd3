r"""A thin ring spinning about its axis, seen from the space-fixed frame (Eulerian description):
the travelling waves' splitting (Bryan 1890), against the inextensional ring's closed form and
against the same ring computed in the co-rotating frame.

The ring is a 2D annulus in plane stress (mean radius R, radial thickness h, unit depth), with
Q2 elements on an exact (r, θ) grid of degree-2 geometry, so the mesh is N-fold symmetric and
each doublet n is degenerate at rest. In the space-fixed frame the residual is

.. math:: \rho\langle\ddot u, v\rangle + a(u, v)
          + \rho\langle(\nabla\dot u)w, v\rangle - \rho\langle\dot u, (\nabla v)w\rangle
          - \rho\langle(\nabla u)w, (\nabla v)w\rangle, \qquad w = \Omega e_z\times x

(no prestress), plus a distributed spring on the boundary, weak enough (rigid modes at 1e-3
ω_2, a relative frequency change ~ 1e-6) to keep the rigid modes off λ = 0.

Closed forms (inextensional ring, u_r = -∂u_θ/∂θ, u_θ = a cos nθ + b sin nθ; the energies of the
co-rotating frame give m ä - 2γ ḃ + (k - mΩ²) a = 0 and its partner, with
m = πρAR(1 + n²), γ = 2nπρARΩ; Bryan 1890, Huang & Soedel 1987):

* at rest, ω_n² = EI/(ρAR⁴) n²(n² - 1)²/(n² + 1) (I = h³/12, A = h);
* in the co-rotating frame, ω = S ∓ 2nΩ/(n² + 1), S = sqrt(ω_n² - c²Ω²), c = (n² - 1)/(n² + 1):
  the pattern lags the ring by 2Ω/(n² + 1) (Bryan's factor);
* in space a wave e^{i(nθ - σt)} of the rotating frame has frequency σ + nΩ, so
  ω_± = S ± n c Ω: (ω_+ - ω_-)/(2Ω) = n(n² - 1)/(n² + 1) exactly in Ω, and the mean frequency
  falls by ω_n - S ≈ c²Ω²/(2ω_n) (the centrifugal softening without prestress).

With the centrifugal prestress (hoop tension ρAΩ²R², its geometric stiffness) the same algebra
gives ω_± = S' ± n c Ω with S' = sqrt(ω_n² + (n c Ω)²) (see the last test).

The thin-ring formulas neglect shear and rotary inertia: their relative error is O((h/R)²),
checked by halving h. The co-rotating frame's residual (Coriolis 2ρΩ e_z × u̇, centrifugal
ρΩ e_z × (Ω e_z × u)) is an independent formulation of the same continuum: u(x, t) =
Q(t) U(Q(t)ᵀx, t) maps one onto the other, so for a mode with n nodal diameters
λ_space = λ_rot ± i n Ω, up to the discretisation of ∂/∂θ on the mesh.

Measured (serial and on 2 ranks): h/R = 0.05: ω_2, ω_3 within -1.16e-3, -3.15e-3 of the thin
ring; h/R = 0.025: -2.91e-4, -7.91e-4 (ratio 4.0); split/(2Ω) 1.20051, 2.40119 (errors 4.3e-4,
5.0e-4) and 1.20013, 2.40030 (1.1e-4, 1.2e-4); λ_space - λ_rot = ±i n Ω to 3e-9 relative.
"""

import itertools

from mpi4py import MPI

import dolfinx.fem.petsc
import numpy as np
import pytest
import ufl
from dolfinx import fem

from fenicsfriction import _compat, forms
from fenicsfriction.elasticity import lame
from fenicsfriction.meshing import annulus
from fenicsfriction.rotation import RigidRotation
from fenicsfriction.stability import StabilitySolver
from fenicsfriction.steady import SteadySolver

COMM = MPI.COMM_WORLD
E, NU, RHO = 210e9, 0.3, 7850.0  # steel [Pa, -, kg/m³]
R = 0.15  # mean radius [m]
#: radial thickness / R -> (elements through the thickness, around): elements about square
MESHES = {0.05: (2, 256), 0.025: (2, 512)}
SPIN = 0.1  # Ω / ω_2 of the thin ring
#: SLEPc's default scaling (pep_scale scalar) makes LAPACK's Schur reordering (trexc) fail on
#: the exactly degenerate doublets of this symmetric mesh at Ω = 0; unscaled TOAR is fine here
OPTIONS = {"pep_scale": "none"}
_COUNTER = itertools.count()


def thin_ring(n: int, h: float) -> float:
    """ω_n [rad/s] of the inextensional thin ring at rest (plane stress, unit depth)."""
    return float(np.sqrt(E * h**2 / 12 / (RHO * R**4) * n**2 * (n**2 - 1) ** 2 / (n**2 + 1)))


def bryan(n: int) -> float:
    """(ω_+ - ω_-)/(2Ω) in the space-fixed frame: n(n² - 1)/(n² + 1)."""
    return n * (n**2 - 1) / (n**2 + 1)


def ring(h_over_R: float, frame: str, prestress: bool = False):
    """The spinning ring's residual in the ``"space"`` (Eulerian) or ``"rotating"`` frame and
    its angular velocity (a Constant, 0 to start with). With ``prestress`` (space frame, Ω =
    SPIN ω_2) the stress of the steady state under the centripetal load, solved from the same
    residual, stiffens it (:func:`fenicsfriction.forms.geometric_stiffness`)."""
    h = h_over_R * R
    n_radial, n_around = MESHES[h_over_R]
    mesh = annulus(COMM, R - h / 2, R + h / 2, n_radial, n_around)
    V = _compat.vector_function_space(mesh, 2)
    u, u_dot, u_ddot = fem.Function(V), fem.Function(V), fem.Function(V)
    v = ufl.TestFunction(V)
    dx = ufl.dx(mesh)
    Omega = fem.Constant(mesh, 0.0)
    support = RHO * h * (1e-3 * thin_ring(2, h)) ** 2 / 2  # rigid modes at 1e-3 ω_2

    def residual(u, extra=0):
        form = (forms.inertia(RHO, u_ddot, v, dx)
                + forms.elasticity(u, v, E, NU, dx, plane_stress=True)
                + forms.elastic_support(u, v, support, ufl.as_vector((0.0, 0.0)), ufl.ds(mesh)))
        if frame == "space":
            w = RigidRotation(omega=Omega).velocity(ufl.SpatialCoordinate(mesh))
            form += (forms.gyroscopic(RHO, w, u_dot, v, dx)
                     + forms.centrifugal_softening(RHO, w, u, v, dx))
        else:  # written out apart from forms.py: an independent formulation

            def ez_cross(a):
                return ufl.as_vector((-a[1], a[0]))

            form += (2 * RHO * Omega * ufl.inner(ez_cross(u_dot), v) * dx
                     + RHO * Omega**2 * ufl.inner(ez_cross(ez_cross(u)), v) * dx)
        return forms.Residual(form=form + extra, u=u, u_dot=u_dot, u_ddot=u_ddot, v=v)

    if not prestress:
        return residual(u), Omega
    Omega.value = SPIN * thin_ring(2, h)
    w = RigidRotation(omega=Omega).velocity(ufl.SpatialCoordinate(mesh))
    u_c = fem.Function(V)
    steady = SteadySolver(residual(u_c, forms.centripetal_load(RHO, w, v, dx)),
                          prefix=f"ring{next(_COUNTER)}_")
    assert steady.solve().converged  # linear: one Newton step
    lmbda, mu = lame(E, NU, plane_stress=True)
    strain = ufl.sym(ufl.grad(u_c))
    sigma0 = 2 * mu * strain + lmbda * ufl.tr(strain) * ufl.Identity(2)
    return residual(u, forms.geometric_stiffness(sigma0, u, v, dx)), Omega


def doublets(solver: StabilitySolver, h_over_R: float) -> dict:
    """The two frequencies [rad/s] of doublets n = 2 and 3, and under ``"growth"`` the largest
    Re λ [1/s] (of every eigenvalue below 1.5 ω_3)."""
    h = h_over_R * R
    modes = solver.solve(1.5 * thin_ring(3, h))
    result = {}
    for n in (2, 3):
        near = thin_ring(n, h)
        pair = [m for m in modes if abs(m.value.imag / near - 1) < 0.25]
        assert len(pair) == 2 and all(m.accurate for m in pair), pair
        # undamped: the eigenvalues are on the imaginary axis to the solver's accuracy
        assert all(abs(m.value.real) < 1e-8 * abs(m.value) for m in pair)
        result[n] = sorted(m.value.imag for m in pair)
    result["growth"] = max(m.value.real for m in modes)
    return result


def eigensolver(residual) -> StabilitySolver:
    return StabilitySolver(residual, prefix=f"ring{next(_COUNTER)}_", options=OPTIONS)


@pytest.fixture(scope="module")
def spectra():
    """(h/R, frame, Ω/ω_2) -> doublets: in space at rest and spinning (one solver each, Ω a
    Constant changed in place: no new form), spinning in the rotating frame, spinning in space
    with the centrifugal prestress."""
    out = {}
    for h_over_R in MESHES:
        residual, Omega = ring(h_over_R, "space")
        solver = eigensolver(residual)
        spins = (0.0, SPIN, 2 * SPIN) if h_over_R == 0.05 else (0.0, SPIN)
        for spin in spins:
            Omega.value = spin * thin_ring(2, h_over_R * R)
            out[h_over_R, "space", spin] = doublets(solver, h_over_R)
    residual, Omega = ring(0.05, "rotating")
    Omega.value = SPIN * thin_ring(2, 0.05 * R)
    out[0.05, "rotating", SPIN] = doublets(eigensolver(residual), 0.05)
    residual, _ = ring(0.05, "space", prestress=True)
    out[0.05, "prestressed", SPIN] = doublets(eigensolver(residual), 0.05)
    return out


def test_ring_at_rest_has_the_thin_ring_frequencies_to_order_h_over_R_squared(spectra):
    """ω_n/ω_n(thin) - 1 is below the straight Timoshenko beam's first correction at wave
    number n/R, -(n h/R)²(1 + E/(κG))/24 (κ = 5/6; a curved beam's is smaller), and falls by
    the factor 4 = 2² when h halves."""
    errors = {}
    for h_over_R in MESHES:
        for n in (2, 3):
            low, high = spectra[h_over_R, "space", 0.0][n]
            assert high - low < 1e-7 * high  # the symmetric mesh keeps the doublet degenerate
            errors[h_over_R, n] = high / thin_ring(n, h_over_R * R) - 1
            timoshenko = (n * h_over_R) ** 2 * (1 + 2 * (1 + NU) / (5 / 6)) / 24
            assert -timoshenko < errors[h_over_R, n] < 0, (h_over_R, n, errors)
    for n in (2, 3):
        # the next term is O((h/R)⁴) relative: the ratio is 4 to a few per cent
        assert errors[0.05, n] / errors[0.025, n] == pytest.approx(4.0, rel=0.05)


def test_spinning_ring_splits_by_bryans_factor(spectra):
    """(ω_+ - ω_-)/(2Ω) = n(n² - 1)/(n² + 1) to O((h/R)²), the error falling as h/R does; the
    mean falls as sqrt(ω_n² - c²Ω²) (c = (n² - 1)/(n² + 1)) with the FE ω_n at rest."""
    errors = {}
    for h_over_R in MESHES:
        Omega = SPIN * thin_ring(2, h_over_R * R)
        for n in (2, 3):
            low, high = spectra[h_over_R, "space", SPIN][n]
            errors[h_over_R, n] = (high - low) / (2 * Omega) / bryan(n) - 1
            assert abs(errors[h_over_R, n]) < h_over_R**2, (h_over_R, n, errors)
            at_rest = spectra[h_over_R, "space", 0.0][n][0]
            c = (n**2 - 1) / (n**2 + 1)
            drop = at_rest - np.sqrt(at_rest**2 - (c * Omega) ** 2)
            # the inextensional model's O(Ω²) term, to O((h/R)²) as well (measured 1.4 and 2.8
            # (h/R)² for n = 2, 3 at both thicknesses)
            assert at_rest - (low + high) / 2 == pytest.approx(drop, rel=4 * h_over_R**2)
    for n in (2, 3):
        assert abs(errors[0.025, n]) < abs(errors[0.05, n]) / 3
        # linear in Ω: the same at 2Ω (measured 1.2e-5 apart, the coupling with the
        # extensional modes, O(Ω²/ω_ext²))
        low, high = spectra[0.05, "space", 2 * SPIN][n]
        twice = (high - low) / (4 * SPIN * thin_ring(2, 0.05 * R)) / bryan(n) - 1
        assert twice == pytest.approx(errors[0.05, n], abs=1e-4)


def test_space_and_rotating_frame_eigenvalues_differ_by_n_omega(spectra):
    """λ_space = λ_rot ± i n Ω: the forward wave (the higher frequency in space, the lower in
    the rotating frame) gains nΩ, the backward one loses it. Exact in the continuum; on this
    symmetric mesh the discretised ∂/∂θ of smooth modes is accurate to ~1e-9."""
    Omega = SPIN * thin_ring(2, 0.05 * R)
    space, rotating = spectra[0.05, "space", SPIN], spectra[0.05, "rotating", SPIN]
    for n in (2, 3):
        assert space[n][1] - rotating[n][0] == pytest.approx(n * Omega, rel=1e-6)
        assert rotating[n][1] - space[n][0] == pytest.approx(n * Omega, rel=1e-6)
        # Bryan's factor in the rotating frame: the pattern lags by 2Ω/(n² + 1)
        split = (rotating[n][1] - rotating[n][0]) / (2 * Omega)
        assert split == pytest.approx(2 * n / (n**2 + 1), rel=0.05**2)


#: the doublets [rad/s] of a serial run (h/R = 0.05, in space), at rest and at Ω = SPIN ω_2
SERIAL = {0.0: {2: [1333.90224076, 1333.90224098], 3: [3765.35055911, 3765.35055947]},
          SPIN: {2: [1171.16231038, 1491.80791567], 3: [3443.15607716, 4084.49188069]}}


def test_eigenvalues_do_not_depend_on_the_partition(spectra):
    """On any number of ranks the doublets are the serial run's, to the PEP's tolerance
    (pep_tol 1e-10; the degenerate pair at rest is resolved to ~1e-10 relative)."""
    for spin, reference in SERIAL.items():
        for n, values in reference.items():
            assert spectra[0.05, "space", spin][n] == pytest.approx(values, rel=1e-9)


def test_centrifugal_prestress_raises_the_doublets_and_removes_the_divergence(spectra):
    """Without prestress the linearised rigid rotation diverges, λ ≈ Ω (the softening pushes
    δφ e_z × x outwards). With the hoop stress T = ρAΩ²R² of the steady state its geometric
    stiffness ½T∫ψ² (ψ = (n² - 1)(a cos nθ + b sin nθ)/R on the inextensional mode) adds
    mΩ²(n² - 1)²/(n² + 1) to k - mΩ², and the same algebra gives in space
    ω_± = S' ± n c Ω, S' = sqrt(ω_n² + (n c Ω)²): the split is unchanged, the mean rises by
    S' - ω_n, and the rigid motions are neutral (by the virial identity
    ∫tr σ_0 = ∫ρΩ²|x|², exact for the discrete steady state as x is in the Q2 space).
    Measured: rise 9.5973 vs 9.5920 s⁻¹ (n = 2), 13.6228 vs 13.6164 (n = 3), errors
    0.2 (h/R)² (and 0.2 (h/R)² again at h/R = 0.025); growth 3e-10 s⁻¹."""
    Omega = SPIN * thin_ring(2, 0.05 * R)
    assert spectra[0.05, "space", SPIN]["growth"] == pytest.approx(Omega, rel=0.01)
    prestressed = spectra[0.05, "prestressed", SPIN]
    assert prestressed["growth"] < 1e-6 * Omega
    for n in (2, 3):
        low, high = prestressed[n]
        assert (high - low) / (2 * Omega) == pytest.approx(bryan(n), rel=0.05**2)
        at_rest = spectra[0.05, "space", 0.0][n][0]
        c = (n**2 - 1) / (n**2 + 1)
        rise = np.sqrt(at_rest**2 + (n * c * Omega) ** 2) - at_rest
        assert (low + high) / 2 - at_rest == pytest.approx(rise, rel=0.05**2)


def dense(A) -> np.ndarray:
    """The whole of a (distributed) PETSc matrix as a NumPy array on every rank."""
    rows = np.arange(*A.getOwnershipRange(), dtype=np.int32)
    local = A.getValues(rows, np.arange(A.getSize()[1], dtype=np.int32))
    return np.vstack(A.getComm().tompi4py().allgather(local))


def assembled(form) -> np.ndarray:
    A = dolfinx.fem.petsc.assemble_matrix(_compat.form(form))
    A.assemble()
    values = dense(A)
    A.destroy()
    return values


def test_gyroscopic_matrix_is_skew_and_the_softening_symmetric_negative_semidefinite():
    """G = -Gᵀ and -K_c = -K_cᵀ ≤ 0 to round-off, by construction. On the ring (w·n = 0) G
    equals the form before integration by parts, 2ρ⟨(w·∇)u̇, v⟩, up to the boundary term
    ∫ρ(w·n) u̇·v left by the degree-2 circles, whose w·n is O((2π/n_around)⁴) (measured
    4.1e-5 with 24 elements around, 2.6e-6 with 48). (The softening has no such check: before
    integration by parts it takes second derivatives, whose jumps between C⁰ elements it
    misses.)"""
    h = 0.05 * R
    mesh = annulus(COMM, R - h / 2, R + h / 2, 1, 48)
    area = COMM.allreduce(dolfinx.fem.assemble_scalar(_compat.form(1.0 * ufl.dx(mesh))))
    assert area == pytest.approx(2 * np.pi * R * h, rel=1e-6)  # measured -6.1e-7
    V = _compat.vector_function_space(mesh, 2)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    w = RigidRotation(omega=300.0).velocity(ufl.SpatialCoordinate(mesh))
    dx = ufl.dx(mesh)
    G = assembled(forms.gyroscopic(RHO, w, u, v, dx))
    softening = assembled(forms.centrifugal_softening(RHO, w, u, v, dx))
    scale_G, scale_K = np.abs(G).max(), np.abs(softening).max()
    assert np.abs(G + G.T).max() < 1e-14 * scale_G  # measured 2.4e-16
    assert np.abs(softening - softening.T).max() < 1e-14 * scale_K
    eigenvalues = np.linalg.eigvalsh(softening)
    assert eigenvalues.max() < 1e-14 * scale_K < -eigenvalues.min()
    G_direct = assembled(2 * RHO * ufl.inner(forms.convective_derivative(w, u), v) * dx)
    assert np.abs(G - G_direct).max() < 1e-5 * scale_G
