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
from fenicsfriction.studies.multicontact import ElasticSlider, ElasticSliderModel

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
                                             ("delay", -1.0)])
def test_bad_scene_parameter_is_named(name, value):
    with pytest.raises(ValueError, match=name):
        ElasticSlider(**{name: value})
