"""The earthquake-like model with contacts coupled through the elastic bodies: the avalanche
update against an independent solve of the broken interface, the no-interaction limit against
the plain model, the bookkeeping of forces, and stick-slip widening with the coupling."""


import numpy as np
import pytest
from scipy import stats

from fenicsfriction.studies.multicontact import (
    EQModel,
    InteractingEQModel,
    LatticeCompliance,
    LatticeEQModel,
    coupling_map,
    interaction_matrix,
    lattice_compliance,
)

pytestmark = pytest.mark.sequential


def _stiff_thresholds(interface, rng, hold):
    """A realisation in which only contact ``hold`` can break."""
    contacts = interface.contacts(rng)
    contacts.thresholds[:] = 1e6
    contacts.thresholds[hold] = 1.0
    return contacts


def test_a_break_leaves_the_others_with_the_forces_of_the_interface_without_it():
    model = EQModel(n_contacts=25, k=2.0)
    interface = InteractingEQModel.lattice(model, coupling=0.5, nu=0.25)
    contacts = _stiff_thresholds(interface, np.random.default_rng(0), hold=12)
    X, trigger = contacts.next_break()
    assert trigger == 12
    assert contacts.relax(X, trigger) == 1
    # independent: the other 24 contacts stretched by X against the bodies, f = (1/k + G)⁻¹ X
    G = interface.compliance
    others = np.arange(25) != 12
    expected = np.linalg.solve(np.eye(24) / 2.0 + G[np.ix_(others, others)], np.full(24, X))
    np.testing.assert_allclose(contacts.forces[others], expected, rtol=1e-12)
    assert contacts.forces[12] == 0.0  # re-formed relaxed
    # the neighbours take load: every other contact's force rose
    assert np.all(contacts.forces[others] > X * interface.stiffness_matrix.sum(axis=1)[others])


def test_the_compliance_is_twice_the_half_space_tangential_block():
    positions, G = lattice_compliance(3, 2.0, E=5.0, nu=0.3, contact_radius=0.5)
    full = interaction_matrix(positions, 5.0, 0.3, 0.5)
    np.testing.assert_array_equal(G, 2 * full[0::3, 0::3])
    assert np.all(G > 0) and np.all(np.linalg.eigvalsh(G) > 0)


@pytest.mark.parametrize("matrix_free", [False, True])
def test_forces_stay_those_of_the_tracked_stretchings_through_the_avalanches(matrix_free):
    model = EQModel(n_contacts=64, x_s_std=0.2)
    if matrix_free:
        interface = LatticeEQModel(model, coupling=0.3)
        # M from the dense inverse of 1/k + G, G assembled column by column: independent of
        # the conjugate gradients that update the forces
        M = np.linalg.inv(np.eye(64) / model.k + interface.compliance.dense())
    else:
        interface = InteractingEQModel.lattice(model, coupling=0.3)
        M = interface.stiffness_matrix
    contacts = interface.contacts(np.random.default_rng(3))
    X = 0.0
    for _ in range(150):
        X, trigger = contacts.next_break()
        contacts.relax(X, trigger)
    assert sum(a[1] for a in contacts.avalanches) > 150  # some avalanches broke several
    # f = M (X − b) for the offsets b of the re-formed contacts (the update's invariant)
    np.testing.assert_allclose(contacts.forces, M @ (X - contacts.offsets),
                               rtol=1e-9, atol=1e-9 * np.max(np.abs(contacts.forces)))
    assert np.all(contacts.forces <= model.k * contacts.thresholds)  # none left over
    assert contacts.friction(X) == pytest.approx(np.sum(contacts.forces), rel=1e-12)


def test_without_interaction_the_spring_driven_run_is_the_plain_models():
    model = EQModel(n_contacts=100, x_s_std=0.3)
    interface = InteractingEQModel.lattice(model, coupling=0.0)
    assert interface.interface_stiffness == pytest.approx(100.0, rel=1e-14)
    drive = {"K": 30.0, "v": 1.0, "mass": 1e-3, "damping": 0.05, "t_end": 4.0, "dt": 5e-4}
    plain, coupled = model.spring_driven(**drive, seed=5), interface.spring_driven(**drive, seed=5)
    assert plain.breaks.sum() > 100  # several lives
    np.testing.assert_array_equal(coupled.breaks, plain.breaks)  # the same draws, in order
    np.testing.assert_allclose(coupled.X, plain.X, rtol=1e-9, atol=1e-12)


def test_without_interaction_the_kinetic_force_is_the_closed_form():
    P_c = stats.uniform(loc=0.5, scale=1.0)
    model = EQModel(n_contacts=400, k=2.0, thresholds=P_c)
    result = InteractingEQModel.lattice(model, coupling=0.0).quasistatic(
        X_max=12.0, realisations=5, kinetic_from=6.0)
    assert result.largest_avalanche == pytest.approx(1 / 400)  # single breaks only
    closed_form = 400 * 2.0 * P_c.moment(2) / (2 * P_c.mean())
    # 2000 contacts over six lives: the window mean is within ~1 % (as for the plain model)
    assert result.kinetic_force == pytest.approx(closed_form, rel=2e-2)


def test_interaction_softens_the_interface_and_its_breaks_cascade():
    model = EQModel(n_contacts=100, x_s_std=0.2)
    weak, strong = (InteractingEQModel.lattice(model, c) for c in (0.01, 1.0))
    assert 100.0 > weak.interface_stiffness > strong.interface_stiffness
    # strong coupling: the bodies' compliance in series dominates, S → 1ᵀ G⁻¹ 1
    rigid_contacts = np.sum(np.linalg.inv(strong.compliance))
    assert strong.interface_stiffness == pytest.approx(rigid_contacts, rel=0.5)
    assert strong.interface_stiffness < rigid_contacts
    runs = [m.quasistatic(6.0 * 100 / m.interface_stiffness) for m in (weak, strong)]
    assert runs[1].largest_avalanche > 10 * runs[0].largest_avalanche > 0


def test_stick_slip_widens_with_the_coupling():
    cmap = coupling_map([0.0, 0.1], [0.1, 0.5], n_side=12, lives=6.0)
    # no interaction, rigid drive: single breaks, each dropping F by k x_s ≈ 2 x_s/(N x_c) of it
    assert not np.any(cmap.sustained_stick_slip[:, 0])
    assert np.all(cmap.largest_avalanche[:, 0] == pytest.approx(1 / 144))
    # (a threshold beyond x_c + 4σ has odds 3e-5 in each of the ~500 late draws)
    single = (1 + 4 * cmap.relative_spread) / (144 * cmap.kinetic_force[:, 0])
    assert np.all(cmap.largest_late_drop[:, 0] < single)
    # interaction: avalanches of a tenth of the contacts or more, whatever the spread
    assert np.all(cmap.sustained_stick_slip[:, 1])
    assert np.all(cmap.largest_avalanche[:, 1] > 0.1)
    assert cmap.interface_stiffness[0] == pytest.approx(1.0)


@pytest.mark.parametrize(("call", "name"), [
    (lambda m: InteractingEQModel.lattice(EQModel(n_contacts=10), 0.1), "n_contacts"),
    (lambda m: InteractingEQModel.lattice(m, -0.1), "coupling"),
    (lambda m: InteractingEQModel(m, np.zeros((3, 3))), "compliance"),
    (lambda m: InteractingEQModel(m, -np.eye(16)), "compliance"),
    (lambda m: InteractingEQModel(m, np.triu(np.ones((16, 16)))), "compliance"),
    (lambda m: coupling_map([0.1], [0.2], n_side=4, drop_threshold=0.1), "drop_threshold"),
    (lambda m: coupling_map([-1.0], [0.2]), "couplings"),
])
def test_bad_input_is_named_in_the_error(call, name):
    with pytest.raises(ValueError, match=name):
        call(EQModel(n_contacts=16))


def test_a_runaway_avalanche_stops_with_an_error_and_keeps_the_state_before_it():
    model = EQModel(n_contacts=16)
    interface = InteractingEQModel.lattice(model, coupling=1.0)
    interface.max_rounds = 1
    contacts = interface.contacts(np.random.default_rng(0))
    # contact 5 breaks at X = 1 and its load tips the others, set just above their forces
    contacts.thresholds[:] = 1.001 * contacts.forces_at(1.0) / model.k
    contacts.thresholds[5] = 1e-3
    thresholds = contacts.thresholds.copy()
    with pytest.raises(RuntimeError, match="max_rounds = 1"):
        contacts.relax(1.0)
    np.testing.assert_array_equal(contacts.thresholds, thresholds)
    assert contacts.X_ref == 0.0 and np.all(contacts.offsets == 0.0)
    contacts.max_rounds = 10
    assert contacts.relax(1.0) > 1  # an avalanche


def test_the_fft_compliance_is_the_dense_lattice_compliance():
    # an independent construction: the dense matrix of the half-space's Green tensor
    positions, G = lattice_compliance(5, 1.3, E=2.0, nu=0.27, contact_radius=0.4)
    fft = LatticeCompliance(5, 1.3, E=2.0, nu=0.27, contact_radius=0.4)
    np.testing.assert_allclose(fft.dense(), G, rtol=1e-12, atol=1e-14 * np.max(G))


def test_the_matrix_free_model_has_the_dense_models_events():
    # k, x_c, σ, ν and the coupling away from 0 and 1: the two solve the same interface, the
    # one by Cholesky, the other by conjugate gradients to 1e-10: the same draws, in order
    model = EQModel(n_contacts=100, k=1.7, x_s_mean=0.9, x_s_std=0.25)
    dense = InteractingEQModel.lattice(model, 0.2, nu=0.27)
    free = LatticeEQModel(model, 0.2, nu=0.27)
    assert free.interface_stiffness == pytest.approx(dense.interface_stiffness, rel=1e-9)
    np.testing.assert_allclose(free.stiffness.rate, dense.stiffness_matrix.sum(axis=1),
                               rtol=1e-9)
    X_max = 2.0 * 0.9 * 100 * 1.7 / dense.interface_stiffness
    a, b = dense.quasistatic(X_max, seed=4), free.quasistatic(X_max, seed=4)
    assert a.breaks > 150 and a.largest_avalanche > 5 / 100  # avalanches, not single breaks
    np.testing.assert_array_equal(b.avalanche_size, a.avalanche_size)
    # an event's position is a threshold over a rate, each to the solves' 1e-10
    np.testing.assert_allclose(b.avalanche_X, a.avalanche_X, rtol=1e-8)
    np.testing.assert_allclose(b.force_drop, a.force_drop, rtol=1e-6,
                               atol=1e-8 * a.kinetic_force)
    np.testing.assert_allclose(b.F, a.F, rtol=1e-8)


def test_slow_spring_drive_events_of_interacting_contacts():
    model = EQModel(n_contacts=64, k=1.3, x_s_mean=1.1, x_s_std=0.2)
    K, D_max = 20.0, 64 * 1.3 * 1.1 / 20.0 + 3.0
    plain = model.spring_quasistatic(K=K, D_max=D_max, seed=2)
    # without interaction, the lattice's contacts (dense or matrix-free) are the plain ones
    for uncoupled in (InteractingEQModel.lattice(model, 0.0), LatticeEQModel(model, 0.0)):
        run = uncoupled.spring_quasistatic(K=K, D_max=D_max, seed=2)
        np.testing.assert_array_equal(run.events.breaks, plain.events.breaks)
        np.testing.assert_allclose(run.events.drop, plain.events.drop, rtol=1e-9,
                                   atol=1e-12 * plain.peak_force)
    # coupled, the dense and the matrix-free interfaces have the same events
    dense = InteractingEQModel.lattice(model, 0.3).spring_quasistatic(K=K, D_max=D_max, seed=2)
    free = LatticeEQModel(model, 0.3).spring_quasistatic(K=K, D_max=D_max, seed=2)
    np.testing.assert_array_equal(free.events.breaks, dense.events.breaks)
    np.testing.assert_allclose(free.D, dense.D, rtol=1e-8)
    # every event's drop is K times the slider's slip at fixed drive
    np.testing.assert_allclose(dense.events.drop, K * dense.events.slip, rtol=1e-9)
    assert dense.events.breaks.size > 5 and dense.events.breaks.max() > 1  # avalanches
