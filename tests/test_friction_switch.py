r"""The friction switch of the stability solver (complex eigenvalue analysis): K̄ and C assembled
without their friction parts, on the block of Martins & Oden (1986) (4 × 3 nine-node
quadrilaterals, as tests/test_stability.py).

The parts dropped are checked against the friction term's own derivatives assembled apart,
and the physics: without the friction stiffness K̄ is symmetric and the flutter (mode
coupling, μ_crit ≈ 0.370) is gone; without the friction damping the onset is the coupling's.
"""

import itertools

from mpi4py import MPI

import dolfinx.fem.petsc
import numpy as np
import pytest

import fenicsfriction as ff
from fenicsfriction import _compat
from fenicsfriction.forms import friction
from fenicsfriction.stability import Loci, StabilitySolver

COMM = MPI.COMM_WORLD
MAX_MODULUS = 3e4  # [1/s]: the block's six modes (tests/test_stability.py)
EPS_MACH = np.finfo(float).eps
_COUNTER = itertools.count()
#: smooth regularisation with ε = 0.03 cm/s (U_T = 0.287 cm/s): the friction damping
#: c_T d^m ψ''_ε(U_T) is then a few per cent of the modes' critical damping
SMOOTH = ff.InterfaceLaw(regularisation="smooth", eps=0.03)


def prefix(name: str) -> str:
    """A PETSc options prefix no other solver of the run uses (ranks count alike)."""
    return f"switch{next(_COUNTER)}{name}_"


def sliding_block(mu: float, **changes):
    """The default block in steady sliding at ``mu`` (from μ = 0 in steps <= 0.1)."""
    model = ff.BlockOnBelt(refine=1, **changes).build(COMM, with_friction=True)
    model.initial_guess()
    steady = ff.SteadySolver(model.residual, prefix=prefix("steady"),
                             options=model.solver_options())
    steps = max(int(np.ceil(mu / 0.1)), 1)
    ff.continuation(steady, model.mu, np.linspace(0.0, mu, steps + 1)[1:])
    return model, steady


def dense(A) -> np.ndarray:
    """A distributed PETSc matrix as a NumPy array on every rank."""
    rows = np.arange(*A.getOwnershipRange(), dtype=np.int32)
    local = A.getValues(rows, np.arange(A.getSize()[1], dtype=np.int32))
    return np.vstack(COMM.allgather(local))


def friction_derivative(model, field) -> np.ndarray:
    """The derivative of the friction term alone with respect to ``field`` (u or u̇) at the
    steady state, assembled from forms.friction apart from the solver."""
    R = model.residual
    term = model.thickness * friction(R.u, R.u_dot, R.v, model.normal, model.law,
                                      model.belt_velocity, model.ds_contact)
    form = _compat.form(R.at_rest(R.derivative(term, field)))
    A = dolfinx.fem.petsc.assemble_matrix(form)
    A.assemble()
    return dense(A)


def test_the_switch_drops_exactly_the_friction_derivatives():
    """K̄ - K̄(friction_stiffness=False) = ∂(friction term)/∂u and C - C(friction_damping=False)
    = ∂(friction term)/∂u̇, each assembled apart, at μ = 0.5 with normal damping (so C keeps
    a part of its own). Both sides are sums of the same quadrature-point values in another
    order: equal to round-off, u_mach times the size of the operator (measured 3e-18 of
    K̄'s largest entry, 0 for C; tolerance 100 u_mach). The friction part's largest entry is
    0.8 % of K̄'s and 5 % of C's, so dropping anything else or nothing would show; μ is back
    at 0.5 afterwards."""
    model, _ = sliding_block(0.5, law=SMOOTH.replace(b_n=0.381e10))
    full = StabilitySolver(model.residual, prefix=prefix("full"))
    dropped = StabilitySolver(model.residual, prefix=prefix("dropped"),
                              friction_stiffness=False, friction_damping=False)
    full.assemble()
    dropped.assemble()
    assert float(model.mu.value) == 0.5
    for name, field in (("K", model.residual.u), ("C", model.residual.u_dot)):
        whole, rest = dense(getattr(full, name)), dense(getattr(dropped, name))
        part = friction_derivative(model, field)
        scale = abs(whole).max()
        assert abs(part).max() > 5e-3 * scale
        assert abs(rest).max() > 0.5 * scale
        assert abs(whole - rest - part).max() < 100 * EPS_MACH * scale, name


def test_without_the_friction_stiffness_the_stiffness_is_symmetric():
    """Friction couples normal displacement into tangential force: ‖K̄ - K̄ᵀ‖ is 0.8 % of ‖K̄‖
    with it; without it K̄ is symmetric to round-off (measured 1.4e-16 of ‖K̄‖_max; tolerance
    100 u_mach)."""
    model, _ = sliding_block(0.5)
    for kept, bound in ((True, None), (False, 100 * EPS_MACH)):
        solver = StabilitySolver(model.residual, prefix=prefix("sym"),
                                 friction_stiffness=kept)
        solver.assemble()
        K = dense(solver.K)
        asymmetry = abs(K - K.T).max() / abs(K).max()
        if bound is None:
            assert asymmetry > 1e-3
        else:
            assert asymmetry < bound


def test_without_the_friction_stiffness_no_mode_grows_up_to_mu_1_5():
    """The flutter is mode coupling: with K̄ symmetric and the friction damping (positive for a
    constant μ: C = c_T d^m ψ''_ε ≥ 0) kept, the steady sliding is stable at every μ up to 1.5
    (below the discrete tipping limit 1.56); measured max Re λ/|λ| = -7e-6 at μ = 0.1, more
    negative beyond. With everything on, μ = 0.45 has a growing mode (Re λ ≈ 310 s⁻¹)."""
    model, steady = sliding_block(0.0, law=SMOOTH)
    solver = StabilitySolver(model.residual, prefix=prefix("nok"), friction_stiffness=False)
    loci = Loci(steady, solver, model.mu, MAX_MODULUS)
    for record in loci.follow(np.linspace(0.1, 1.5, 15)):
        growth = [m["re"] / abs(complex(m["re"], m["im"])) for m in record["modes"]]
        assert max(growth) < 0, record["mu"]
    full = Loci(steady, StabilitySolver(model.residual, prefix=prefix("all")), model.mu,
                MAX_MODULUS)
    assert max(m["re"] for m in full.follow([0.45])[0]["modes"]) > 100


@pytest.mark.parametrize(("law", "dropped_damping", "expected"), [
    (ff.InterfaceLaw(), False, 0.370),   # the known onset (tests/test_stability.py)
    (ff.InterfaceLaw(), True, 0.370),    # no friction damping in 2D with φ_ε outside the band
    (SMOOTH, True, 0.372),               # the coupling of K̄ alone, the damping dropped
])
def test_without_the_friction_damping_the_onset_is_the_mode_couplings(law, dropped_damping,
                                                                       expected):
    """The onset bisected to 1e-4: with Pop's φ_ε (default law) the slip speed U_T = 0.287 is
    far outside the band (ε = 1e-3), φ''_ε = 0 in 2D, so the friction damping is exactly 0 and
    dropping it changes nothing: 0.3705 both ways. With ψ_ε (ε = 0.03) the regularisation
    also softens the friction stiffness: without the damping the onset is 0.3723 (measured);
    tolerance 1e-3 (the interval's width plus the mesh's onset known to 1e-3)."""
    model, steady = sliding_block(0.3, law=law)
    solver = StabilitySolver(model.residual, prefix=prefix("onset"),
                             friction_damping=not dropped_damping)
    onset = Loci(steady, solver, model.mu, MAX_MODULUS).onset(0.3, 0.45, tol=1e-4)
    assert onset.mu_crit == pytest.approx(expected, abs=1e-3)


def test_the_friction_damping_destabilises_before_the_coupling():
    """Hoffmann & Gaul (2003)'s destabilisation paradox: with ψ_ε (ε = 0.03) the friction
    damping, positive semi-definite but not proportional, makes the upper mode of the pair
    grow long before the coalescence: at μ = 0.2 Re λ ≈ +0.66 s⁻¹ at 5981 rad/s (measured),
    although each operator is stable alone (K̄ without friction damping: no growing mode
    below 0.372, previous test). The growth rate is 1e-4 |λ|, far above round-off
    (residuals 1e-12)."""
    model, steady = sliding_block(0.2, law=SMOOTH)
    for kept, grows in ((True, True), (False, False)):
        solver = StabilitySolver(model.residual, prefix=prefix("paradox"),
                                 friction_damping=kept)
        modes = solver.solve(MAX_MODULUS)
        growth = max(m.value.real / abs(m.value) for m in modes)
        assert (growth > 1e-5) == grows, (kept, growth)


def test_the_switch_drops_the_friction_of_node_to_segment_contact():
    """On the block on an elastic slab the friction is in the node-to-segment coupling, not in
    the integrals; at μ = 0.3, past its onset (0.2-0.25), K̄ is unsymmetric by 1.2 % of its
    largest entry and the pair grows at 259 s⁻¹. Without the friction stiffness K̄ is
    symmetric to round-off (measured 6e-17; tolerance 100 u_mach: frictionless contact derives
    from a potential) and, C being zero (no damping, no friction damping in 2D), every
    eigenvalue is on the imaginary axis to round-off (measured |Re λ| ≤ 1e-11 |λ|; tolerance
    1e-9)."""
    model = ff.BlockOnSlab().build(COMM, with_friction=True)
    model.initial_guess()
    steady = ff.SteadySolver(model.residual, prefix=prefix("slab"),
                             options=model.solver_options())
    ff.continuation(steady, model.mu, np.linspace(0.05, 0.3, 6))
    assert model.residual.friction is model.mu
    for kept in (True, False):
        solver = StabilitySolver(model.residual, prefix=prefix("slabpep"),
                                 friction_stiffness=kept)
        modes = solver.solve(MAX_MODULUS)
        K = dense(solver.K)
        asymmetry = abs(K - K.T).max() / abs(K).max()
        growth = max(abs(m.value.real) / abs(m.value) for m in modes)
        if kept:
            assert asymmetry > 1e-3 and growth > 1e-2
        else:
            assert asymmetry < 100 * EPS_MACH and growth < 1e-9


def test_dropping_friction_needs_a_friction_constant():
    """A residual without a friction constant (a frictionless model) refuses the switch."""
    model = ff.BlockOnBelt(refine=1).build(COMM, with_friction=False)
    assert model.residual.friction is None
    with pytest.raises(ValueError, match="friction_stiffness=False needs a friction constant"):
        StabilitySolver(model.residual, prefix=prefix("refused"), friction_stiffness=False)


STRIBECK = ff.InterfaceLaw(friction_coefficient=ff.laws.StribeckFriction(
    mu_s=0.4, mu_k=0.2, v_s=0.5))  # μ(0.287 cm/s) = 0.313, falling: dμ/dv = -0.225 s/cm


def steady_with_law(scene):
    model = scene.build(COMM)
    model.initial_guess()
    ff.SteadySolver(model.residual, prefix=prefix("law"), options=model.solver_options()).solve()
    return model


def test_a_falling_friction_law_is_negative_damping_not_coupling():
    """With μ(v) a law the block's friction term carries a factor of value 1 of its own
    (``friction_factor``), which the switch sets to 0. Stribeck's law falls through μ = 0.313
    at the belt speed, below the coupling onset 0.370: every mode grows with everything on
    (measured Re λ from 0.11 to 226 s⁻¹), none without the friction damping, and they still
    grow without the friction stiffness: negative damping. K̄ without its friction part is
    symmetric to round-off (tolerance 100 u_mach), and the factor is 1 again afterwards."""
    model = steady_with_law(ff.BlockOnBelt(refine=1, law=STRIBECK))
    assert model.residual.friction is model.friction_factor is not model.mu
    growing = {}
    for stiffness, damping in ((True, True), (True, False), (False, True)):
        solver = StabilitySolver(model.residual, prefix=prefix("lawpep"),
                                 friction_stiffness=stiffness, friction_damping=damping)
        modes = solver.solve(MAX_MODULUS)
        growing[stiffness, damping] = [m for m in modes if m.value.real > 1e-6 * abs(m.value)]
        if not stiffness:
            K = dense(solver.K)
            assert abs(K - K.T).max() < 100 * EPS_MACH * abs(K).max()
    assert len(growing[True, True]) == 6
    assert not growing[True, False]
    assert len(growing[False, True]) >= 6
    assert float(model.friction_factor.value) == 1.0


def test_the_slabs_contact_carries_the_factor_of_a_friction_law():
    """On the slab the friction coefficient law of the node-to-segment contact is multiplied by
    the factor: without the friction damping C is zero (no normal damping), with it C has the
    negative damping of the falling law (a negative eigenvalue of C + Cᵀ)."""
    model = steady_with_law(ff.BlockOnSlab(law=STRIBECK))
    assert model.residual.friction is model.friction_factor is not None
    for damping in (True, False):
        solver = StabilitySolver(model.residual, prefix=prefix("slablaw"),
                                 friction_damping=damping)
        solver.assemble()
        C = dense(solver.C)
        if damping:
            assert np.linalg.eigvalsh(C + C.T).min() < 0
        else:
            assert abs(C).max() == 0.0
