"""The elastic slider on breakable (EQ) contacts: the elastic limit against a closed form, the
energy balance of the breaks, fronts from the pushed edge, the same history on 1 and 2 ranks.

The slider is small (20 x 2 or 10 x 2 cells) and the runs short (a few hundred to a thousand
steps of the linear generalized-α scheme), so each test takes a few seconds.
"""

from __future__ import annotations

import csv
import json

from mpi4py import MPI

import dolfinx.fem.petsc
import numpy as np
import pytest
import ufl

from fenicsfriction.io import FieldWriter
from fenicsfriction.studies.multicontact import Break, ElasticSlider, ElasticSliderModel, fronts

#: a slider whose contacts break one after the other from the pushed edge: thresholds within
#: ±5 %, so the stretch (decaying from the edge over sqrt(E H / k) = 6 node spacings) decides
#: the order; a broken contact stays off for 0.1 ms, shedding its load to its neighbours
PUSHED = ElasticSlider(nx=20, ny=2, push_speed=2e-3, spread=0.05, delay=1e-4, seed=3)


def _settle_crossing(times: np.ndarray, values: np.ndarray) -> float:
    """Time of the first downward zero crossing of ``values``, linearly interpolated."""
    i = np.flatnonzero((values[:-1] > 0) & (values[1:] <= 0))[0]
    return float(times[i] + values[i] / (values[i] - values[i + 1]) * (times[i + 1] - times[i]))


def test_unbreakable_stiff_slider_oscillates_as_a_rigid_block_on_its_springs():
    # E H / k = 1e3 m², screening length 32 m >> L: the slider moves as a rigid block of mass
    # rho H per unit length on springs k per unit length, omega^2 = k / (rho H)
    scene = ElasticSlider(nx=10, ny=2, E=1e11, k=1e8, threshold=np.inf, k_push=0.0)
    model = ElasticSliderModel(scene, MPI.COMM_WORLD)
    period = 2 * np.pi / np.sqrt(scene.k / (scene.rho * scene.H))
    model.residual.u_dot.x.array[0::2] = 1e-3

    def mean_base_displacement(t: float) -> dict:
        u = model.base_displacement()
        return {"u": model.msh.comm.allreduce(float(u.sum()))}

    records = model.solver().run(0.6 * period, period / 200, observe=mean_base_displacement)
    half = _settle_crossing(np.array([r["time"] for r in records]),
                            np.array([r["u"] for r in records]))
    # Newmark's average acceleration lengthens the period by (omega dt)^2 / 12 = 8e-5 at
    # 200 steps a period; the body's compliance shifts omega^2 by ~ k L^2 / (E H) ~ 1e-5
    assert half == pytest.approx(period / 2, rel=3e-4)


@pytest.mark.parametrize("delay", [0.0, 2e-5])
def test_energy_lost_equals_the_spring_energy_the_breaks_released(delay):
    scene = ElasticSlider(nx=10, ny=2, k_push=0.0, threshold=1e-6, spread=0.5, delay=delay)
    model = ElasticSliderModel(scene, MPI.COMM_WORLD)
    model.residual.u_dot.x.array[0::2] = 0.1  # a slider thrown along its base
    initial = sum(model.energies().values())

    def balance(t: float) -> dict:
        if t > 0:
            model.update_contacts(t)
        return {"energy": sum(model.energies().values()),
                "released": sum(b.energy for b in model.breaks)}

    records = model.solver().run(4e-4, 2e-6, observe=balance)
    assert len(model.breaks) > 20
    released = records[-1]["released"]
    assert released > 0.5 * initial  # the breaks dissipate most of it: the check has teeth
    # the trapezoidal rule (generalized-α, spectral radius 1) conserves the energy of a linear
    # system step by step, and a break removes exactly its spring's energy: round-off only
    for r in records:
        assert r["energy"] + r["released"] == pytest.approx(initial, rel=1e-10)


def test_momentum_changes_by_the_impulse_of_the_contacts_and_the_pusher():
    model = ElasticSliderModel(PUSHED, MPI.COMM_WORLD)

    def forces(t: float) -> dict:
        model.time.value = t
        before = model.contact_force()  # the springs that acted over the step just done
        if t > 0:
            model.update_contacts(t)
        return {"momentum": model.momentum(), "before": before,
                "after": model.contact_force(), "push": model.push_force()}

    records = model.solver().run(1.5e-3, 2e-6, observe=forces)
    assert len(model.breaks) > 5
    # the trapezoidal rule: M (v_n+1 - v_n) = dt F(u_n+1/2) and the forces are linear in u
    # and t, so the momentum gained is dt times the mean of the forces at both ends of the
    # step (the springs as they were over it); elastic forces sum to zero: round-off only
    for old, new in zip(records[:-1], records[1:], strict=True):
        impulse = 0.5 * new["dt"] * (old["after"] + new["before"] + old["push"] + new["push"])
        assert new["momentum"] - old["momentum"] == pytest.approx(
            impulse, rel=1e-8, abs=1e-10 * PUSHED.rho * PUSHED.L * PUSHED.H * 1e-3)


def _quasi_static_first_break_force(scene: ElasticSlider) -> float:
    """Pusher force when the edge contact (x = 0) reaches its threshold under a quasi-static
    push: the static elastic problem (all contacts intact) solved once, scaled linearly."""
    model = ElasticSliderModel(scene, MPI.COMM_WORLD)
    model.time.value = 1.0
    R = model.residual
    steady = R.steady()
    problem = dolfinx.fem.petsc.LinearProblem(
        R.derivative(steady, R.u), -ufl.replace(steady, {R.u: ufl.zero(2)}), bcs=R.bcs,
        u=R.u, petsc_options={"ksp_type": "preonly", "pc_type": "lu"})
    problem.solve()
    at_edge = model.x == 0.0
    edge = model.msh.comm.allreduce(float(model.base_displacement()[at_edge].sum()))
    threshold = float(scene.draw_threshold(np.array([0]), np.array([0]))[0])
    return model.push_force() * threshold / edge


def test_fronts_start_at_the_pushed_edge_and_advance_contact_by_contact():
    model = ElasticSliderModel(PUSHED, MPI.COMM_WORLD)
    history = model.run(t_end=2.2e-3, dt=2e-6)
    first = history.breaks[0]
    assert first.x == 0.0
    # slow push: the first break comes at the static force, up to the inertia of the loading
    # (an oscillation of ~V/omega = 6e-8 m about the static state, 6 % of the threshold;
    # 1.7 % at this speed, 0.4 % at a quarter of it)
    assert history.push_force[history.time.index(first.time)] == pytest.approx(
        _quasi_static_first_break_force(PUSHED), rel=0.05)
    # the precursors: the furthest broken contact moves on one node spacing at a time over
    # the first half of the slider, each arrested front a step further than the one before
    reached = np.unique(np.array(history.front_position)[np.isfinite(history.front_position)])
    half = reached[reached <= PUSHED.L / 2]
    assert np.allclose(half, PUSHED.h * np.arange(len(half)))
    assert len(half) == PUSHED.nx // 2 + 1
    arrested = [f for f in history.fronts if f.arrested and f.start_time < history.time[-1]]
    assert len(arrested) > 5
    # then the whole interface slips, below the force all contacts could hold together
    assert np.isfinite(history.slip_force)
    assert history.slip_force < PUSHED.k * PUSHED.L * PUSHED.threshold * (1 + PUSHED.spread)
    # the slip force is the force at the step the far-edge contact first broke
    far = min(b.time for b in history.breaks if b.x == PUSHED.L)
    assert history.slip_force == history.push_force[history.time.index(far)]
    assert history.peak_force == max(history.push_force) >= history.slip_force
    # no front outruns the P waves; grouped by the time gap alone, some would (the old rule)
    c_p = PUSHED.wave_speeds[0]
    speeds = np.array([f.speed for f in history.fronts])
    assert np.sum(np.isfinite(speeds)) >= 5 and np.nanmax(speeds) <= c_p
    by_gap = fronts(history.breaks, lambda t: 0.0, 10e-6, PUSHED.L - PUSHED.h / 2)
    assert max(f.speed for f in by_gap if np.isfinite(f.speed)) > c_p
    assert sum(f.size for f in history.fronts) == len(history.breaks)


def test_wave_speeds_against_the_ratio_of_the_p_to_the_s_wave_speed():
    # (c_p / c_s)^2 = 2 (1 - nu) / (1 - 2 nu) in plane strain, 2 / (1 - nu) in plane stress;
    # c_s^2 = E / (2 (1 + nu) rho)
    scene = ElasticSlider(E=2e9, nu=0.25, rho=1200.0)
    c_p, c_s = scene.wave_speeds
    assert c_s == pytest.approx(np.sqrt(2e9 / (2 * 1.25 * 1200.0)), rel=1e-14)
    assert (c_p / c_s) ** 2 == pytest.approx(2 * 0.75 / 0.5, rel=1e-14)
    c_p, c_s = ElasticSlider(E=2e9, nu=0.25, rho=1200.0, plane_stress=True).wave_speeds
    assert (c_p / c_s) ** 2 == pytest.approx(2 / 0.75, rel=1e-14)


def _front(start_x: float, start_time: float, speed: float, count: int, h: float = 1e-3):
    return [Break(time=start_time + i * h / abs(speed), x=start_x + np.sign(speed) * i * h,
                  stretch=1e-6, energy=0.0) for i in range(count)]


def test_causal_grouping_finds_a_known_front_and_two_simultaneous_ones():
    c = 1000.0
    # and a break behind the tip after it (the front filling in): the speed is the tip's
    run = _front(0.0, 1e-3, 300.0, 20)
    backfill = Break(time=run[-1].time + 2e-6, x=0.01, stretch=1e-6, energy=0.0)
    one = fronts([*run, backfill], lambda t: 2 * t, 1e-4, 0.05, c)
    assert len(one) == 1 and one[0].size == 21 and one[0].arrested
    assert one[0].speed == pytest.approx(300.0, rel=1e-12)
    assert (one[0].tip_time, one[0].end_time) == (run[-1].time, backfill.time)
    assert (one[0].start_x, one[0].tip_x, one[0].push_force) == (0.0, pytest.approx(0.019),
                                                                 2e-3)
    # two fronts starting together 5 cm apart, one running right at 300 m/s, one left at
    # 200 m/s, their breaks interleaved in time: each break is reachable only from its own
    # front within c, so the two come apart
    both = _front(0.0, 1e-3, 300.0, 12) + _front(0.05, 1e-3, -200.0, 12)
    found = fronts(both, lambda t: 0.0, 1e-4, 0.1, c)
    assert sorted((f.start_x, f.size) for f in found) == [(0.0, 12), (0.05, 12)]
    assert found[0].speed == pytest.approx(300.0, rel=1e-12)
    # by the time gap alone they were one "front" that reached 5 cm in no time
    merged = fronts(both, lambda t: 0.0, 1e-4, 0.1)
    assert len(merged) == 1 and merged[0].tip_x == 0.05 and np.isnan(merged[0].speed)


def test_a_run_of_breaks_faster_than_the_wave_speed_is_not_a_front():
    c = 1000.0
    found = fronts(_front(0.0, 0.0, 2 * c, 10), lambda t: 0.0, 1e-4, 0.05, c)
    assert len(found) == 10 and all(np.isnan(f.speed) for f in found)
    # breaks in the same step at different places are never one front's
    same_step = [Break(time=1e-3, x=x, stretch=0.0, energy=0.0) for x in (0.0, 1e-3, 2e-3)]
    assert len(fronts(same_step, lambda t: 0.0, 1e-4, 0.05, c)) == 3
    # random breaks: every break in one front, no front faster than c
    rng = np.random.default_rng(1)
    breaks = [Break(time=float(t), x=float(x), stretch=0.0, energy=0.0)
              for t, x in zip(np.round(rng.uniform(0, 1e-3, 300), 6),
                              rng.integers(0, 40, 300) * 2.5e-3, strict=True)]
    found = fronts(breaks, lambda t: 0.0, 2e-5, 0.1, c)
    assert sum(f.size for f in found) == 300
    assert np.nanmax([f.speed for f in found]) <= c and len(found) < 300
    with pytest.raises(ValueError, match="wave_speed"):
        fronts(breaks, lambda t: 0.0, 2e-5, 0.1, 0.0)


def test_patched_thresholds_are_the_same_realisation_on_every_mesh():
    coarse, fine = (ElasticSlider(nx=nx, patches=5, spread=0.5) for nx in (10, 40))
    j = np.arange(11)
    assert np.array_equal(coarse.draw_threshold(j, np.zeros(11)),
                          fine.draw_threshold(4 * j, np.zeros(11)))
    # within a patch one value, patch to patch another, each re-formation a new draw
    values = fine.draw_threshold(np.arange(41), np.zeros(41))
    # patch m is [m L/5, (m + 1) L/5): nodes 8m to 8m + 7, the far-edge node in the last
    assert len(np.unique(values)) == 5 and values[40] == values[32]
    assert all(len(np.unique(values[8 * m:8 * m + 8])) == 1 for m in range(5))
    assert np.all(values[8:40:8] != values[7:39:8])
    assert fine.draw_threshold(np.array([3]), np.array([1]))[0] != values[3]
    with pytest.raises(ValueError, match="patches"):
        ElasticSlider(nx=10, patches=3)


def test_kelvin_voigt_viscosity_dissipates_tau_times_the_strain_rate_power():
    # unbreakable contacts, no pusher: the energy changes only by the viscous dissipation
    # tau int C eps(v):eps(v) over each step, v the step's mean velocity (the trapezoidal
    # rule evaluates the linear residual at the mid-step state): round-off only
    scene = ElasticSlider(nx=10, ny=2, threshold=np.inf, k_push=0.0, viscosity=3e-6)
    model = ElasticSliderModel(scene, MPI.COMM_WORLD)
    x = model.V.tabulate_dof_coordinates()
    model.residual.u_dot.x.array[0::2] = 0.1 * np.sin(np.pi * x[:, 0] / scene.L)
    mean = dolfinx.fem.Function(model.V)
    from fenicsfriction.forms import elasticity
    power = dolfinx.fem.form(scene.viscosity * elasticity(mean, mean, scene.E, scene.nu,
                                                           ufl.dx(domain=model.msh)))
    previous = {"v": model.residual.u_dot.x.array.copy()}

    def balance(t: float) -> dict:
        v = model.residual.u_dot.x.array
        mean.x.array[:] = 0.5 * (v + previous["v"])
        previous["v"] = v.copy()
        rate = model.msh.comm.allreduce(dolfinx.fem.assemble_scalar(power))
        return {"energy": sum(model.energies().values()), "rate": rate}

    records = model.solver().run(2e-4, 2e-6, observe=balance)
    lost = records[0]["energy"] - records[-1]["energy"]
    assert lost > 0.05 * records[0]["energy"]  # the damping is felt: the check has teeth
    for old, new in zip(records[:-1], records[1:], strict=True):
        assert old["energy"] - new["energy"] == pytest.approx(
            new["dt"] * new["rate"], rel=1e-8, abs=1e-12 * records[0]["energy"])


def test_one_compiled_form_runs_two_kelvin_voigt_times_and_tau_zero_conserves_energy():
    # tau is a fem.Constant of the form: one model, one solver (its forms compiled once) runs
    # tau = 3 and 6 us and tau = 0 from the same initial state. Unbreakable contacts, no
    # pusher, a linear system: undamped, the trapezoidal rule (generalized-alpha at spectral
    # radius 1) conserves the energy to round-off; damped, it loses more the larger tau
    scene = ElasticSlider(nx=10, ny=2, threshold=np.inf, k_push=0.0, viscosity=3e-6)
    model = ElasticSliderModel(scene, MPI.COMM_WORLD)
    assert model.viscosity in model.residual.form.constants()
    solver = model.solver()
    x = model.V.tabulate_dof_coordinates()
    start = np.zeros_like(model.residual.u_dot.x.array)
    start[0::2] = 0.1 * np.sin(np.pi * x[:, 0] / scene.L)
    compiled = (solver.L, solver.a)

    def lost(tau: float) -> float:
        model.viscosity.value = tau
        for field, value in ((model.residual.u, 0.0), (model.residual.u_dot, start),
                             (model.residual.u_ddot, 0.0)):
            field.x.array[:] = value
            field.x.scatter_forward()
        records = solver.run(1e-4, 2e-6, observe=lambda t: {
            "energy": sum(model.energies().values())})
        return (records[0]["energy"] - records[-1]["energy"]) / records[0]["energy"]

    damped, twice, undamped = lost(3e-6), lost(6e-6), lost(0.0)
    assert (solver.L, solver.a) == compiled
    assert damped > 0.05 and twice > 1.2 * damped  # more damping, more energy lost
    assert abs(undamped) < 1e-10


@pytest.mark.mpi(min_size=2)
def test_front_history_is_the_same_on_one_and_on_all_ranks(shared_tmp_path):
    models = [ElasticSliderModel(PUSHED, comm) for comm in (MPI.COMM_WORLD, MPI.COMM_SELF)]
    with FieldWriter(shared_tmp_path / "fields.xdmf", models[0]) as fields:
        world = models[0].run(t_end=1.5e-3, dt=2e-6,
                              on_step=lambda r: fields.write(r["time"]) if r["time"] > 1.4e-3
                              else None)
    alone = models[1].run(t_end=1.5e-3, dt=2e-6)
    assert [(b.time, b.x) for b in world.breaks] == [(b.time, b.x) for b in alone.breaks]
    assert np.allclose(world.push_force, alone.push_force, rtol=1e-8, atol=1e-8)
    world.write_csv(shared_tmp_path / "fronts.csv")
    world.write_json(shared_tmp_path / "history.json")
    MPI.COMM_WORLD.Barrier()
    with open(shared_tmp_path / "fronts.csv") as f:
        assert len(list(csv.DictReader(f))) == len(world.time)
    with open(shared_tmp_path / "history.json") as f:
        assert len(json.load(f)["fronts"]) == len(world.fronts)
    assert (shared_tmp_path / "fields.h5").exists()


@pytest.mark.parametrize(("name", "value"), [("spread", 1.0), ("threshold", 0.0), ("nx", 0),
                                             ("delay", -1.0), ("viscosity", -1e-6),
                                             ("patches", -1)])
def test_bad_scene_parameter_is_named(name, value):
    with pytest.raises(ValueError, match=name):
        ElasticSlider(**{name: value})
