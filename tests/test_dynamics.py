"""Dynamics (TSALPHA2 on the one residual) against the eigenproblem and energy conservation."""

import dataclasses

from mpi4py import MPI

import numpy as np
import pytest
import scipy.optimize

import fenicsfriction as ff
from fenicsfriction.dynamics import DynamicsSolver
from fenicsfriction.stability import StabilitySolver


def steady_block(mu: float, comm=MPI.COMM_WORLD, prefix="dyn", **fields):
    """A converged steady sliding state of the block at μ (``fields``: the scene's and its
    law's, e.g. ``belt_speed``, ``b_n``, ``eps``)."""
    law_fields = {f.name for f in dataclasses.fields(ff.InterfaceLaw)}
    law = ff.InterfaceLaw(mu=mu, **{k: v for k, v in fields.items() if k in law_fields})
    scene = ff.BlockOnBelt(**{k: v for k, v in fields.items() if k not in law_fields}, law=law)
    model = scene.build(comm, with_friction=mu > 0)
    model.initial_guess()
    solver = ff.SteadySolver(model.residual, prefix=f"{prefix}_steady_",
                             options=model.solver_options())
    ff.continuation(solver, model.mu, np.linspace(0.0, mu, 5))
    return model


def perturbed_run(model, dt: float, t_end: float, v_y: float, prefix: str):
    model.residual.u_dot.x.array[1::2] = v_y
    dynamics = DynamicsSolver(model.residual, prefix=prefix, atol=1e-12 * model.force_scale,
                              options={"snes_rtol": 1e-14})
    return dynamics.run(t_end, dt, observe=lambda t: {
        "normal_force": model.quantities().normal_force,
        **dataclasses.asdict(model.energies())})


def test_energy_without_friction_is_conserved_to_second_order_in_the_step():
    """Generalized-α with ρ∞ = 1 is second order: the energy error of the bouncing block
    (power-law contact, no friction or damping) must fall fourfold when dt halves."""
    errors = []
    for k, dt in enumerate((2e-5, 1e-5, 5e-6)):
        model = steady_block(0.0, prefix=f"energy{k}")
        records = perturbed_run(model, dt, 1e-3, -0.01, f"energy{k}_ts_")
        energy = np.array([r["total"] for r in records])
        errors.append(np.abs(energy - energy[0]).max() / max(r["kinetic"] for r in records))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert errors[-1] < 1e-5
    assert np.all(orders > 1.9), (errors, orders)


def test_growth_and_frequency_of_the_perturbation_match_the_unstable_eigenvalue():
    """At μ = 0.6 steady sliding is unstable (flutter pair λ = ±a + iω). A small normal
    velocity perturbation (linear regime: N varies < 1 %) excites the pair; fitting
    A e^{at} cos(ωt + φ) + B e^{-at} cos(ωt + ψ) + c to N(t) must give a and ω of the
    PEP within 1 % (time error of the scheme at dt = 1e-5 s: (ω dt)² ~ 3e-3 in phase)."""
    model = steady_block(0.6, prefix="growth")
    lam = max(StabilitySolver(model.residual, prefix="growth_pep_").solve(2e4),
              key=lambda m: m.value.real).value
    records = perturbed_run(model, 1e-5, 6e-3, -1e-4, "growth_ts_")
    t = np.array([r["time"] for r in records])
    n = np.array([r["normal_force"] for r in records])
    assert np.abs(n - n[0]).max() < 0.02 * n[0]  # linear regime

    def pair(t, a, w, c1, s1, c2, s2, c0):
        return (np.exp(a * t) * (c1 * np.cos(w * t) + s1 * np.sin(w * t))
                + np.exp(-a * t) * (c2 * np.cos(w * t) + s2 * np.sin(w * t)) + c0)

    guess = [0.9 * lam.real, 1.02 * lam.imag] + [np.std(n)] * 4 + [0.0]
    (a, w, *_), _ = scipy.optimize.curve_fit(pair, t, n - n.mean(), p0=guess, maxfev=20000)
    assert a == pytest.approx(lam.real, rel=1e-2)
    assert w == pytest.approx(lam.imag, rel=1e-2)


@pytest.mark.mpi(min_size=2)
def test_time_integration_is_the_same_on_one_and_two_ranks():
    series = []
    for comm, name in ((MPI.COMM_WORLD, "world"), (MPI.COMM_SELF, "self")):
        model = steady_block(0.6, comm=comm, prefix=f"ranks_{name}")
        records = perturbed_run(model, 1e-5, 1e-3, -1e-3, f"ranks_{name}_ts_")
        series.append(np.array([r["normal_force"] for r in records]))
    # Newton stops at 1e-12 of the load; the difference may only be round-off amplified by
    # the growing mode over 1 ms (e^{0.5} < 2)
    assert np.allclose(series[0], series[1], rtol=0, atol=1e-8 * series[0].max())


def test_central_differences_agree_with_generalized_alpha_and_respect_the_stable_step():
    """The explicit scheme (lumped mass) and the implicit one integrate the same residual:
    their normal forces agree to the schemes' O(dt²) error, and the explicit step is capped
    below the stable step 2/ω_max whatever step is asked for."""
    from fenicsfriction.dynamics import CentralDifference
    forces = []
    for scheme in ("central", "alpha2"):
        model = steady_block(0.6, prefix=f"cd_{scheme}")
        model.residual.u_dot.x.array[1::2] = -1e-4
        observe = lambda t, m=model: {"normal_force": m.quantities().normal_force}  # noqa: E731
        if scheme == "central":
            explicit = CentralDifference(model.residual)
            records = explicit.run(2e-3, 2e-3, observe=observe)
            assert max(r["dt"] for r in records) <= 0.9 * explicit.stable_dt * (1 + 1e-12)
        else:
            records = DynamicsSolver(model.residual, prefix="cd_ts_",
                                     atol=1e-12 * model.force_scale).run(2e-3, 1e-6, observe)
        t = np.array([r["time"] for r in records])
        forces.append(np.interp(np.linspace(0, 2e-3, 41), t,
                                [r["normal_force"] for r in records]))
    signal = np.abs(forces[1] - forces[1][0]).max()
    assert np.abs(forces[0] - forces[1]).max() < 1e-2 * signal


def test_central_differences_need_the_stick_band_bound_inside_the_band():
    """With the belt slower than ε (0.005 < 0.01 cm/s) the steady state lies inside the
    regularisation band, where friction is the stiff dashpot c = c_T d^{m_T}/ε per unit area
    (F = μ N U/ε = 135 = 0.3 W here). The step bound from the elasticity alone, 2/ω_max
    (9.7e-6 s), is 36 times the band's (2.7e-7 s at κ = 4): at that step the explicit dashpot
    overshoots and the friction force chatters up to the saturated μN (measured 0.62 W); at
    the enforced band bound the steady state is kept (F within 1e-6 of 135 over 1 ms,
    measured 4e-10)."""
    from fenicsfriction.dynamics import CentralDifference
    peaks = {}
    for band in (False, True):
        model = steady_block(0.6, prefix=f"band{band}", eps=1e-2, belt_speed=0.005)
        weight = model.scene.weight
        explicit = CentralDifference(model.residual,
                                     band_damping=model.band_damping() if band else None)
        records = explicit.run(1e-3, 1e-3, observe=lambda t, m=model: {
            "friction": m.quantities().friction_force})
        friction = np.array([r["friction"] for r in records])
        assert friction[0] == pytest.approx(0.6 * weight * 0.005 / 1e-2, rel=1e-6)
        peaks[band] = np.abs(friction - friction[0]).max() / weight
    assert explicit.stable_dt_band < explicit.stable_dt_elastic / 10
    assert peaks[False] > 0.1 and peaks[True] < 1e-6 * 0.3, peaks


def test_stable_mu_decays_at_the_rate_of_its_eigenvalue():
    """Below the flutter onset, with normal damping, every eigenvalue has Re λ < 0: a small
    normal velocity perturbation must decay. N(t) is dominated (10:1) by the normal mode; a
    two-mode fit A e^{at} cos(ωt + φ) must give that mode's a within 5 % and ω within 1 % of
    the PEP eigenvalue (time error at dt = 1e-5 s: (ω dt)²/12 ~ 2e-4 in frequency, none in
    the decay rate with ρ∞ = 1)."""
    model = steady_block(0.2, prefix="decay", b_n=0.381e10)
    values = [m.value for m in StabilitySolver(model.residual, prefix="decay_pep_").solve(2e4)
              if m.value.imag > 1000]
    assert max(v.real for v in values) < 0
    records = perturbed_run(model, 1e-5, 4e-3, -1e-4, "decay_ts_")
    t = np.array([r["time"] for r in records])
    n = np.array([r["normal_force"] for r in records])

    def modes(t, a1, w1, c1, s1, a2, w2, c2, s2, c0):
        return (np.exp(a1 * t) * (c1 * np.cos(w1 * t) + s1 * np.sin(w1 * t))
                + np.exp(a2 * t) * (c2 * np.cos(w2 * t) + s2 * np.sin(w2 * t)) + c0)

    low, high = sorted(values, key=lambda v: v.imag)[:2]
    guess = [0.8 * low.real, low.imag, 0.1, 0.1, 0.8 * high.real, high.imag, 0.1, 0.1, 0.0]
    p, _ = scipy.optimize.curve_fit(modes, t, n - n[0], p0=guess, maxfev=50000)
    fitted = [(np.hypot(p[2], p[3]), complex(p[0], p[1])),
              (np.hypot(p[6], p[7]), complex(p[4], p[5]))]
    dominant = max(fitted, key=lambda f: f[0])[1]
    exact = min(values, key=lambda v: abs(v - dominant))
    assert dominant.real == pytest.approx(exact.real, rel=5e-2)
    assert dominant.imag == pytest.approx(exact.imag, rel=1e-2)


def test_small_eps_and_a_large_step_are_recovered_by_the_cut_back():
    """The hard case of Pop, "A finite element method for frictional contact problems":
    ε = 1e-3 cm/s and dt = 1e-5 s, past the onset at the slow
    belt speed. Contact points reach the belt speed within 5 ms; Newton then cycles across the
    regularisation band and fails. The run must finish without user action (failed steps
    retried at a quarter of the step, which then grows back), and agree with a run at a
    quarter of the step: the normal force within 2 % of its oscillation range (both are
    second-order accurate; (ω dt)² ~ 3e-3 at dt = 1e-5 s)."""
    series = []
    for dt in (1e-5, 2.5e-6):
        model = steady_block(0.6, prefix=f"hard{dt}", belt_speed=0.08, b_n=0.381e10, eps=1e-3)
        model.residual.u_dot.x.array[1::2] += -0.01
        solver = DynamicsSolver(model.residual, prefix=f"hard{dt}_ts_",
                                atol=1e-10 * model.force_scale)
        records = solver.run(7e-3, dt, observe=lambda t, m=model: {
            "normal_force": m.quantities().normal_force,
            **dataclasses.asdict(m.contact_states())})
        assert records[-1]["time"] == pytest.approx(7e-3, rel=1e-12)
        if dt == 1e-5:
            assert sum(r["rejected_steps"] for r in records) > 0  # the cut-back did act
            assert any(r["n_stick"] > 0 for r in records)
            assert max(r["dt"] for r in records[-20:]) == pytest.approx(dt)  # grown back
        t = np.array([r["time"] for r in records])
        series.append((t, np.array([r["normal_force"] for r in records])))
    (t, coarse), (t_fine, fine) = series
    reference = np.interp(t, t_fine, fine)
    assert np.abs(coarse - reference).max() < 2e-2 * np.ptp(reference)


def dynamic_state(prefix: str, eps: float = 1e-2, t_end: float = 4e-3):
    """The block of Figs. 13-15 at 0.08 cm/s, 4 ms past the kick: oscillating, some nodes
    lifted off or sticking, every term of the residual active."""
    model = steady_block(0.6, prefix=prefix, belt_speed=0.08, b_n=0.381e10, eps=eps)
    model.perturb_normal_velocity(-0.01)
    DynamicsSolver(model.residual, prefix=f"{prefix}_ts_",
                   atol=1e-10 * model.force_scale).run(t_end, 1e-5)
    return model


def test_the_observer_records_the_integrals_assembled_one_by_one():
    """The observer assembles its 16 integrals in one pass (one DG0 vector with an entry per
    integral) and reduces them with the nodal values in two collective calls. Its values must be
    those of ``fem.assemble_scalar`` on each form (what the observer did before) up to the
    order of summation: 1e-12 relative (measured ≤ 7e-16 on the resultants), and its row those
    of the model's one-at-a-time accessors."""
    from dolfinx import fem

    from fenicsfriction import _compat
    from fenicsfriction.studies.block import observables

    model = dynamic_state("observer")
    comm = model.msh.comm
    forms = {**observables._quantity_forms(model), **observables._energy_forms(model)}
    batch = observables.Functionals(model.msh, forms).values()
    for name, form in forms.items():
        single = comm.allreduce(fem.assemble_scalar(_compat.form(form)), op=MPI.SUM)
        assert batch[name] == pytest.approx(single, rel=1e-12)
    assert abs(batch["normal_damping"]) > 1e-3 * batch["normal_elastic"]  # a moving state

    row = model.dynamics_observer()(0.0)
    q, e, p = model.quantities(), model.energies(), model.powers()
    centre, states = model.centre_of_mass(), model.contact_states()
    node = model.probe(model.scene.L / 2)
    expected = {"normal_force": q.normal_force, "friction_force": q.friction_force,
                "centre_of_pressure": q.centre_of_pressure,
                "min_penetration": q.min_penetration, "max_penetration": q.max_penetration,
                "spring_force": q.spring_force, "kinetic_energy": e.kinetic,
                "friction_power": p.friction, "damping_power": p.damping,
                "u_yG": centre.u_G[1], "v_xG": centre.v_G[0], "theta": centre.theta,
                "n_open": states.n_open, "n_stick": states.n_stick, "n_slip": states.n_slip,
                "probe_slip": node.slip, "probe_pressure": node.pressure,
                "probe_friction": node.friction}
    for key, value in expected.items():
        assert row[key] == pytest.approx(value, rel=1e-12, abs=1e-15), key
    assert row["energy_error"] == 0.0  # the first row is the reference


def test_the_jacobian_with_its_constant_part_assembled_once_is_the_full_jacobian():
    """The solver assembles K0 + s_v C0 + s_a M0 (elasticity, mass: no field in them) once
    per step size and the contact integrals at each Newton iteration. At a moving state, for
    two step sizes, the sum must equal the full form ∂R/∂u + s_v ∂R/∂u̇ + s_a ∂R/∂ü assembled
    in one piece (to round-off: 1e-12 of its norm, measured 2.7e-16); a changed density must
    be seen."""
    from fenicsfriction import _compat
    from fenicsfriction.assembly import assemble_jacobian

    model = dynamic_state("split")
    solver = DynamicsSolver(model.residual, prefix="split_ts_")
    R = model.residual
    full = solver.A.duplicate()
    split = solver.A.duplicate()
    state = [_compat.petsc_vec(f).copy() for f in (R.u, R.u_dot, R.u_ddot)]
    for shift_v, shift_a in ((2e5, 4e10), (8e5, 6.4e11)):
        solver._J(solver.ts, 0.0, *state, shift_v, shift_a, split, split)
        assemble_jacobian(full, solver.a, R.bcs, R.springs)
        norm = full.norm()
        full.axpy(-1.0, split)
        assert full.norm() < 1e-12 * norm, (shift_v, shift_a)
    solver._J(solver.ts, 0.0, *state, 2e5, 4e10, split, split)
    assert solver._bulk.watcher.assemblies == 1  # new shifts re-form the sum, not the parts
    model.rho.value = 2 * model.rho.value
    solver._J(solver.ts, 0.0, *state, 2e5, 4e10, full, full)
    assert solver._bulk.watcher.assemblies == 2
    full.axpy(-1.0, split)
    assert full.norm() > 1e-3 * split.norm()  # the mass doubled: s_a M0 changed


def test_the_predictor_changes_where_newton_starts_not_the_steps():
    """Newton starts from x_n + Δt ẋ_n instead of PETSc's x_n. Where no step is cut back
    (ε = 1e-2, the first 3 ms: growth, no sticking) both solve the same equations to the same
    tolerance, so the normal force must agree to where Newton stops, its round-off floor
    (~1e-4 in force; measured 1.8e-7 of the range of N, allowed 1e-5), while Newton needs
    fewer iterations (measured 303 against 604). In the stick band (ε = 1e-3, 8 ms, the
    first sticking) PETSc's start cycles: the predictor must cut the iterations at least
    threefold (measured 24150 → 2451 over 10 ms)."""
    iterations = {}
    for eps, t_end in ((1e-2, 3e-3), (1e-3, 8e-3)):
        series = {}
        for predictor in (True, False):
            model = steady_block(0.6, prefix=f"pred{eps}{predictor}", belt_speed=0.08,
                                 b_n=0.381e10, eps=eps)
            model.perturb_normal_velocity(-0.01)
            solver = DynamicsSolver(model.residual, prefix=f"pred{eps}{predictor}_ts_",
                                    atol=1e-10 * model.force_scale, predictor=predictor)
            records = solver.run(t_end, 1e-5, observe=lambda t, m=model: {
                "normal_force": m.quantities().normal_force})
            iterations[eps, predictor] = sum(r["newton_iterations"] for r in records)
            series[predictor] = (records, np.array([r["normal_force"] for r in records]))
        if eps == 1e-2:
            (new, n_new), (old, n_old) = series[True], series[False]
            assert sum(r["rejected_steps"] for r in new + old) == 0
            assert np.abs(n_new - n_old).max() < 1e-5 * np.ptp(n_old)
            assert iterations[eps, True] < iterations[eps, False]
    assert iterations[1e-3, True] * 3 < iterations[1e-3, False], iterations


def test_error_control_through_the_stick_band_agrees_with_fixed_steps():
    """PETSc's error control (``ts_adapt_type basic``) with the predictor and the cut-back, at
    ε = 1e-3 through the first sticking (8 ms): the run must finish, with steps rejected and
    steps grown past the fixed one, and give the normal force of the fixed 1e-5 s steps within
    2 % of its range. Against generalized-α at 1.25e-6 s, atol = 1e-4 cm is off by 0.86 % of
    the range (1252 steps, 1780 Newton iterations), the fixed 1e-5 s steps by 0.45 % (890,
    1874): the estimate does not buy accuracy here (atol = 1e-5: 0.047 %, 4299 steps)."""
    series = []
    for options in ({}, {"ts_adapt_type": "basic", "ts_atol": 1e-4, "ts_rtol": 0.0}):
        model = steady_block(0.6, prefix=f"adapt{len(options)}", belt_speed=0.08,
                             b_n=0.381e10, eps=1e-3)
        model.perturb_normal_velocity(-0.01)
        solver = DynamicsSolver(model.residual, prefix=f"adapt{len(options)}_ts_",
                                atol=1e-10 * model.force_scale, options=options)
        records = solver.run(8e-3, 1e-5, observe=lambda t, m=model: {
            "normal_force": m.quantities().normal_force})
        assert records[-1]["time"] == pytest.approx(8e-3, rel=1e-12)
        if options:
            steps = np.array([r["dt"] for r in records[1:]])
            assert sum(r["rejected_steps"] for r in records) > 0
            assert steps.max() > 1e-5 and steps.min() < 1e-6, (steps.min(), steps.max())
        series.append((np.array([r["time"] for r in records]),
                       np.array([r["normal_force"] for r in records])))
    (t, fixed), (t_adapt, adaptive) = series
    assert np.abs(np.interp(t, t_adapt, adaptive) - fixed).max() < 2e-2 * np.ptp(fixed)
