# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.14.4
# ---

# %% [markdown]
# # Stick-slip of the block on a belt: the apparent friction coefficient
#
# This demo shows how to integrate the dynamics of the block on a belt of Martins & Oden
# (1986, Figs. 10-15) from a perturbed steady sliding state past the flutter onset, watch the
# oscillation grow until the contact sticks for part of each cycle, and measure what a
# friction experiment would: the *apparent* friction coefficient, mean force over mean force.
# The finite element block and the rigid 3-d.o.f. block are run side by side.
#
# Past the flutter onset ($\mu \approx 0.37$ for the finite element block, see
# `demo_block_stability.py`) steady sliding is unstable: a small normal velocity
# perturbation grows at the rate $\mathrm{Re}\,\lambda$ of the unstable eigenvalue. The normal
# force then oscillates, the friction force follows it, the contact points are driven back and
# forth along the belt and — if the belt is slow enough — catch up with it and stick for
# part of each cycle. Sticking lowers the mean friction force below $\mu$ times the mean
# normal force: a measurement of mean forces reports an apparent kinetic coefficient
# $\bar F_T / \bar N$ smaller than $\mu$, although the law has one coefficient only.
#
# The equation integrated is the regularised virtual-power equation (Problem 1ε of Martins &
# Oden 1986), the one residual of `fenicsfriction.forms`:
#
# $$ \langle \rho \ddot u, v\rangle + a(u, v) + \langle P(u), v\rangle
#    + \langle B(u, \dot u), v\rangle + \langle J_\varepsilon(u, \dot u), v\rangle
#    - \langle f, v\rangle = 0 \quad \forall v, $$
#
# with $B$ the normal damping $b_n d^{l_n} \dot d$, by PETSc TS (generalized-α, Newton at each
# step, the step cut back where Newton needs it at slide-to-stick transitions), with the
# data of their Figs. 13-15 ($\mu = 0.6$, $K_x = 11.1\cdot 10^3$ kg/s², $B_0 = 30.5$ cm,
# $b_n = 0.381\cdot 10^{10}$, $l_n = 2.5$) at the paper's two belt speeds, 0.08 and 0.287 cm/s.
#
# The rigid 3-d.o.f. block of the stability analysis (`fenicsfriction.studies.block.RigidBlock`,
# the same interface law integrated over its base, same data) is driven by the same time
# integrator (TSALPHA2 through `ReducedDynamics`) next to each finite element run: its
# flutter onset is later ($\mu \approx 0.40$) and its growth rate smaller, but the sequence is
# the same.
#
# Reference: J.A.C. Martins, J.T. Oden, "Interface models, variational principles and
# numerical solutions for dynamic friction problems", in *Mechanics of Material Interfaces*,
# Selvadurai & Voyiadjis (eds), Elsevier 1986.
#
# Each run is a separate, small (126-dof) problem: with `mpirun -n 2` the two belt speeds
# run side by side, one per rank. Set `FENICSFRICTION_DEMO_T_END` to change the simulated
# time (default 0.6 s, half a period of the spring; the test suite runs 0.01 s) and
# `FENICSFRICTION_DEMO_OUT` for the output folder.

# %%
import logging
import os
import pathlib
import sys

from mpi4py import MPI

import numpy as np
from scipy.integrate import trapezoid

import fenicsfriction as ff
from fenicsfriction.dynamics import DynamicsSolver
from fenicsfriction.plotting import plot_stick_slip
from fenicsfriction.results import CsvRows
from fenicsfriction.signals import Interrupted, StopSignals
from fenicsfriction.stability import StabilitySolver
from fenicsfriction.statistics import stick_slip_statistics
from fenicsfriction.studies.block import RigidBlock, rigid_block_observables
from fenicsfriction.timestepping import ReducedDynamics

logging.getLogger("ffcx").setLevel(logging.WARNING)
world = MPI.COMM_WORLD
say = ff.results.get_logger(comm=world).info
out = pathlib.Path(os.environ.get("FENICSFRICTION_DEMO_OUT", "results/stick_slip"))
T_END = float(os.environ.get("FENICSFRICTION_DEMO_T_END", "0.6"))  # [s]
DT = 1e-5  # [s]: Newmark step of the paper's rigid model; cut back where Newton needs it
MU, EPS = 0.6, 1e-2  # ε [cm/s]: the stick band, 1/8 of the slower belt speed
BELT_SPEEDS = [0.08, 0.287]  # [cm/s]
PERTURBATION = -0.01  # [cm/s], normal velocity added to the steady state


#: SIGINT/SIGTERM end a run at its next step (see "Stopping cleanly" below)
stop = StopSignals(comm=MPI.COMM_SELF)
interrupted: list[str] = []  # where this rank's runs stopped


def belt_scene(belt_speed):
    """The data of Figs. 13-15 at one belt speed."""
    return ff.BlockOnBelt(belt_speed=belt_speed, law=ff.InterfaceLaw(mu=MU, b_n=0.381e10,
                                                                      eps=EPS))


# %% [markdown]
# ## Stopping cleanly
# A run writes its time series row by row as it goes (`CsvRows`), and SIGINT/SIGTERM (Ctrl-C)
# end it at its next step (`StopSignals`): the rows done stay on disk, the rank skips its
# remaining runs, the summary says where each run stopped, and the demo exits with 130
# (143 for SIGTERM) without its checks, which need complete runs.


# %%
def integrate(solver, records: list, **callbacks) -> None:
    """``solver.run`` to T_END; a signal ends it at the next step with ``records`` kept."""
    if interrupted:  # an earlier run of this rank was stopped: skip the rest
        return
    try:
        solver.run(t_end=T_END, dt=DT, **callbacks)
    except Interrupted as err:
        interrupted.append(f"{err}")


def statistics_of(records: list, mu: float, eps: float) -> ff.results.Record | None:
    """The statistics over the second half of what was integrated (None: too little)."""
    if len(records) < 3:
        return None
    t_from = records[-1]["time"] / 2 if interrupted else T_END / 2
    return stick_slip_statistics(records, mu=mu, eps=eps, t_from=t_from)


# %% [markdown]
# ## One run: steady state, its eigenvalues, the perturbed dynamics
# The steady state at $\mu = 0.6$ is reached by continuation from $\mu = 0$; the eigenvalue
# with the largest real part is its growth rate, kept next to the run so the two can be
# compared (the test suite checks the agreement on a linear-regime run). The steady state's
# normal velocity $\dot u_n$ is then perturbed at every node and the dynamics integrated.


# %%
def run(belt_speed: float, comm: MPI.Comm) -> tuple[list, ff.results.Record | None, dict]:
    scene = belt_scene(belt_speed)
    model = scene.build(comm=comm)
    model.initial_guess()
    steady = ff.SteadySolver(model.residual, prefix=f"ss{belt_speed}_steady_",
                             options=model.solver_options())
    model.slide_to(mu=MU, solver=steady, step=0.05)
    modes = StabilitySolver(model.residual, prefix=f"ss{belt_speed}_pep_").solve(
        max_modulus=2e4)
    growth = max(modes, key=lambda m: m.value.real).value
    model.perturb_normal_velocity(PERTURBATION)
    solver = DynamicsSolver(model.residual, prefix=f"ss{belt_speed}_ts_",
                            atol=1e-10 * model.force_scale)
    log = ff.results.get_logger(comm=comm).info
    progress = max(1, int(T_END / DT / 20))

    def on_step(record: dict) -> None:
        k = len(records)
        records.append(record)
        table.write(record)
        if k % progress == 0:
            log(f"U = {belt_speed}: step {k:6d}  t = {record['time']:.4f} s  "
                f"dt = {record['dt']:.1e}  Newton {record['newton_iterations']}  "
                f"N = {record['normal_force']:.0f}  stick/slip/open {record['n_stick']}/"
                f"{record['n_slip']}/{record['n_open']}  energy error "
                f"{record['energy_error']:.2e}")
        stop.check(f"U = {belt_speed} cm/s (finite elements), t = {record['time']:.4g} s")

    records: list[dict] = []
    with CsvRows(path=out / f"timeseries_FE_U{belt_speed}.csv", comm=comm) as table:
        integrate(solver, records, observe=model.dynamics_observer(), on_step=on_step)
    statistics = statistics_of(records, mu=MU, eps=EPS)
    about = {"belt_speed": belt_speed, "weight": scene.weight,
             "unstable_eigenvalue": [growth.real, growth.imag],
             "wall_time_s": sum(r["wall_time_s"] for r in records)}
    return records, statistics, about


# %% [markdown]
# ## The rigid block, same data, same integrator
# Three d.o.f. $(u_{xG}, u_{yG}, \theta)$, its steady state by Newton, its eigenvalues from
# the dense quadratic eigenproblem; the same perturbation, step and statistics (its base
# slides or sticks as a whole).


# %%
def run_rigid(block: RigidBlock, name: str, stem: str
              ) -> tuple[list, ff.results.Record | None, dict]:
    q = block.steady_state()
    growth = max(block.eigenvalues(q), key=lambda lam: lam.real)
    solver = ReducedDynamics(model=block, q0=q, q_dot0=[0.0, PERTURBATION, 0.0],
                             prefix=f"rb_{name}_ts_")
    records: list[dict] = []

    def on_step(record: dict) -> None:
        records.append(record)
        table.write(record)
        stop.check(f"{name} (rigid), t = {record['time']:.4g} s")

    with CsvRows(path=out / f"timeseries_{stem}.csv", comm=MPI.COMM_SELF) as table:
        integrate(solver, records, observe=lambda t: rigid_block_observables(
            block, solver.q, solver.q_dot), on_step=on_step)
    statistics = statistics_of(records, mu=block.law.mu, eps=block.law.eps)
    about = {"belt_speed": block.belt_speed, "weight": block.weight,
             "unstable_eigenvalue": [growth.real, growth.imag],
             "wall_time_s": sum(r["wall_time_s"] for r in records)}
    return records, statistics, about


# %% [markdown]
# The rigid counterpart of the finite element block at each belt speed, and the rigid
# model's own data of Figs. 10-12: $B_0 = 14$ cm, $I = 70$, a stiffer spring $K_x = 2388$,
# $\mu = 1$, modal damping ratios 0.005 ($x$), 0.04 ($y$, $\theta$) at $\mu = 0$, at the belt
# speed of Fig. 10 (0.127 cm/s) and the two of the paper's outcomes (Fig. 12): 0.287 cm/s,
# where the oscillation persists with brief adhesions, and 0.08 cm/s, where the normal
# damping wins and the body sticks until the spring tears it loose (stick-slip relaxation).
# With the stiff spring (period 86 ms) both happen within the run.

# %%
FIG12_SPEEDS = [0.127, 0.08, 0.287]  # [cm/s]
RIGID = {f"U = {U} cm/s": RigidBlock.from_scene(belt_scene(U)) for U in BELT_SPEEDS}
RIGID.update({f"Figs. 10-12: μ = 1, U = {U} cm/s": RigidBlock.with_modal_damping(
    (0.005, 0.04, 0.04), belt_speed=U, B0=14.0, inertia=70.0, K_x=2388.0,
    law=ff.InterfaceLaw(mu=1.0, b_n=0.381e10, eps=EPS)) for U in FIG12_SPEEDS})


# %% [markdown]
# ## All runs, shared out over the ranks
# A rank runs its share of the belt speeds on its own communicator, then its share of the
# rigid runs; rank 0 gathers.

# %%
mine = BELT_SPEEDS[world.rank::world.size]
comm = MPI.COMM_SELF if world.size > 1 else world
if world.rank == 0:
    out.mkdir(parents=True, exist_ok=True)
world.Barrier()
with stop:
    results = {U: run(U, comm) for U in mine}
    names = list(RIGID)
    rigid = {name: run_rigid(RIGID[name], f"r{i}", f"rigid_{i}") for i, name in enumerate(names)
             if i % world.size == world.rank}
gathered = world.gather((results, rigid, interrupted), root=0)
stopped = world.bcast([where for _, _, part in gathered for where in part]
                      if world.rank == 0 else None, root=0)

# %% [markdown]
# ## What a friction experiment would measure
# Over the second half of the run: mean forces and their ratio (the apparent coefficient),
# the share of time the mid-base node (the paper's node 29) sticks or is out of contact, and
# the spring elongation, which falls when the mean friction force falls. Rank 0 writes the
# time series (CSV), the statistics (JSON) and the figures.

# %%
if world.rank == 0:
    results = {U: r for part, _, _ in gathered for U, r in part.items()}
    rigid = {name: r for _, part, _ in gathered for name, r in part.items()}
    # (kind, label, file stem, records, statistics, about the run, model mass, x-dashpot)
    entries = [("FE", f"U = {U} cm/s", f"FE_U{U}", *results[U], belt_scene(U).mass, 0.0)
               for U in BELT_SPEEDS if U in results] + \
        [("rigid", name, f"rigid_{i}", *rigid[name], RIGID[name].mass, RIGID[name].viscous[0])
         for i, name in enumerate(names) if name in rigid]
    entries = [entry for entry in entries if entry[4] is not None]  # runs with statistics
    for kind, label, _, _, stats, about, _, _ in entries:
        energy = "" if stats.max_energy_error is None else \
            f", energy error ≤ {stats.max_energy_error:.2e}"
        anywhere = "" if stats.any_stick_fraction is None else \
            f", some node {stats.any_stick_fraction:.1%}"
        print(f"{kind:5s} {label}: apparent coefficient {stats.apparent_coefficient:.4f} "
              f"(μ = {stats.mu}, ratio {stats.ratio_to_mu:.4f}); mean N "
              f"{stats.mean_normal_force:.1f} (W = {about['weight']:.0f}), N in "
              f"[{stats.normal_force_range[0]:.0f}, "
              f"{stats.normal_force_range[1]:.0f}]; sticks: mid-base point "
              f"{stats.probe_stick_fraction:.1%}{anywhere} of the time (longest "
              f"{stats.probe_longest_stick * 1e3:.1f} ms), open "
              f"{stats.probe_open_fraction:.1%}; spring elongation "
              f"{stats.spring_elongation['start']:.5f} → "
              f"{stats.spring_elongation['end']:.5f} cm; {stats.steps} steps "
              f"({stats.rejected_steps} cut back){energy}, {about['wall_time_s']:.0f} s",
              flush=True)
    summary = [{"model": kind, "label": label, **stats.to_json(), **about}
               for kind, label, _, _, stats, about, _, _ in entries]
    ff.results.write_summary(out / "stick_slip.json", {"eps": EPS, "dt": DT, "t_end": T_END,
                                                    "perturbation": PERTURBATION,
                                                    "runs": summary,
                                                    **({"interrupted": stopped} if stopped
                                                       else {})}, comm=MPI.COMM_SELF)
if world.rank == 0 and not stopped:
    plot_stick_slip(runs={f"U = {U} cm/s": results[U][0] for U in BELT_SPEEDS},
                    path=out / "stick_slip.png", mu=MU, eps=EPS)
    plot_stick_slip(runs={f"rigid, {name}": rigid[name][0]
                          for name in names[:len(BELT_SPEEDS)]},
                    path=out / "stick_slip_rigid.png", mu=MU, eps=EPS)
    plot_stick_slip(runs={f"rigid, {name}": rigid[name][0]
                          for name in names[len(BELT_SPEEDS):]},
                    path=out / "stick_slip_rigid_figs10-12.png", mu=1.0, eps=EPS)
    say(f"wrote {out}/stick_slip.json, stick_slip*.png and the time series")
if stopped:  # one line, the status a shell reports for the signal, no checks
    say(f"{stopped[0]}; results so far in {out}/")
    sys.exit(128 + stop.received if stop.received else 130)

# %% [markdown]
# ## Checks
# These hold for the short runs of the test suite (0.01 s) as for the full run.
#
# **The oscillation has grown.** The normal force leaves ±20 % of the weight.
#
# **Friction stays within its bound on average.** $|F_T| \le \mu N_{el}$ at every point, so
# the apparent coefficient cannot exceed $\mu$ — up to the normal damping in $N$, whose
# stress $b_n d^{l_n} \dot d$ is a time derivative: its mean over a window is a boundary term
# (< 1 % of $W$ over 5 ms, less over longer windows).
#
# **The spring balances friction on average, up to the momentum the block gains.** No other
# horizontal force acts on the block (the weight and the normal stresses are vertical), so
# over the window $[t_0, t_1]$ the impulse theorem holds,
#
# $$ \int_{t_0}^{t_1} (F_T + F_s - c_x v_{xG})\,dt = M\,[v_{xG}]_{t_0}^{t_1}, $$
#
# with $c_x$ the rigid block's dashpot (none on the finite element block). Friction and spring
# forces are computed apart (the interface integral, the spring's elongation) and $v_{xG}$ is
# the mean velocity of the body. The integral is taken by the trapezoidal rule over the
# recorded steps, not the integrator's own quadrature: they differ by a few $10^{-3}$ of
# $\int |F_T|\,dt$ where steps are cut back; the check allows 1 %.
#
# **Energy is accounted for.** The energy error $E(t) - E(0) - W(t)$ of the finite element
# runs (kinetic, strain, interface, spring and load energies against the work $W$ of the
# friction and damping stresses) stays below 1 % of the work $\int (|P_T| + |P_d|)\,dt$ those
# stresses exchange (generalized-α conserves energy up to the time error: 0.05-0.2 %).
#
# **The slow belt is caught up with, the fast one is not.** At $U_T = 0.08$ cm/s some
# contact node sticks (within $\varepsilon$ of the belt's speed) for part of the time, at
# 0.287 cm/s none does ($\mu = 0.6$, finite element and rigid block). On the finite element
# block the mid-base node sticks only while some node does: the nodal count of
# `contact_states` and the probe agree.

# %%
if world.rank == 0:
    for kind, label, _, records, stats, about, mass, dashpot in entries:
        low, high = stats.normal_force_range
        assert high - low > 0.4 * about["weight"], (label, stats.normal_force_range)
        assert stats.apparent_coefficient <= stats.mu * 1.02, (label, stats)

        window = [r for r in records if r["time"] >= T_END / 2]
        t = np.array([r["time"] for r in window])
        friction = np.array([r["friction_force"] for r in window])
        spring = np.array([r["spring_force"] for r in window])
        v_xG = np.array([r["v_xG"] for r in window])
        impulse = trapezoid(friction + spring - dashpot * v_xG, t)
        momentum = mass * (v_xG[-1] - v_xG[0])
        assert abs(impulse - momentum) < 1e-2 * trapezoid(abs(friction), t), \
            (label, impulse, momentum)

        if kind == "FE":
            t_all = np.array([r["time"] for r in records])
            power = np.array([abs(r["friction_power"]) + abs(r["damping_power"])
                              for r in records])
            assert stats.max_energy_error < 1e-2 * trapezoid(power, t_all), (label, stats)
            assert stats.any_stick_fraction >= stats.probe_stick_fraction, (label, stats)

        if stats.mu == MU:  # the data of Figs. 13-15
            sticks = stats.any_stick_fraction if kind == "FE" else stats.probe_stick_fraction
            caught_up = about["belt_speed"] == min(BELT_SPEEDS)
            assert (sticks > 0) == caught_up, (label, stats)

# %% [markdown]
# **The two outcomes of Fig. 12**, once the run is long enough (the default 0.6 s): at
# 0.287 cm/s adhesions stay brief (< 5 ms) while the apparent coefficient is below $\mu$; at
# 0.08 cm/s the body sticks for a long stretch (> 20 ms, the paper's case (b)).

# %%
if world.rank == 0 and T_END >= 0.5:
    fast = rigid["Figs. 10-12: μ = 1, U = 0.287 cm/s"][1]
    slow = rigid["Figs. 10-12: μ = 1, U = 0.08 cm/s"][1]
    assert fast.probe_longest_stick < 5e-3 and fast.apparent_coefficient < 1.0, fast
    assert slow.probe_longest_stick > 2e-2, slow
