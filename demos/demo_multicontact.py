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
# # A nonhomogeneous frictional interface: many contacts, their master equation, fronts
#
# This demo shows how to compute friction from many contacts that break and re-form, following
# Braun's lectures *Nonhomogeneous frictional interface* (Braun (slides); Braun & Röder 2002;
# Braun & Peyrard 2008): the earthquake-like (EQ) model against its master equation, the
# elastic instability that turns smooth sliding into stick-slip, the elastic interaction of
# contacts through the substrate, slip fronts in the Frenkel-Kontorova chain, and an elastic
# finite element slider whose onset of sliding is a sequence of detachment fronts.
#
# **The EQ model.** N contacts of stiffness k hold the slider; when the slider moves by X every
# attached contact stretches by X; a contact breaks when its stretching exceeds its threshold
# $x_s$ (drawn from $P_c$) and re-forms with a stretching drawn from R (here relaxed,
# $R = \delta(x)$). The friction force is $F = k\sum_i x_i$. For many contacts the distribution
# $Q(x; X)$ of the stretchings obeys the **master equation**
#
# $$ \frac{\partial Q}{\partial X} + \frac{\partial Q}{\partial x} + P(x)Q
#    = R(x)\int P(\xi)Q(\xi; X)\,d\xi, \qquad P(x) = \frac{P_c(x)}{\int_x^\infty P_c}, $$
#
# and $F(X) = N k \int x Q\,dx$. See `docs/multicontact.md`.
#
# Figures go to `FENICSFRICTION_DEMO_OUT` (default `results/interface`). Run it serially or in
# parallel: `mpirun -n 2 python3 demos/demo_multicontact.py` (the reduced models run on each rank
# alike; the finite element slider is distributed).

# %%
import logging
import os
import pathlib

from mpi4py import MPI

import numpy as np

import fenicsfriction as ff
from fenicsfriction.studies.multicontact import (
    ElasticSlider,
    ElasticSliderModel,
    EQModel,
    FKChain,
    InteractingEQModel,
    LatticeInteraction,
    MasterEquation,
    coupling_map,
    fit_power_laws,
    instability_map,
    radial_profile,
)

logging.getLogger("ffcx").setLevel(logging.WARNING)
comm = MPI.COMM_WORLD
say = ff.results.get_logger(comm=comm).info
out = pathlib.Path(os.environ.get("FENICSFRICTION_DEMO_OUT", "results/interface"))
if comm.rank == 0:
    out.mkdir(parents=True, exist_ok=True)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

# %% [markdown]
# ## 1. The EQ model and its master equation
#
# Gaussian thresholds (mean $x_c = 1$, spread σ = 0.3), relaxed newborn contacts, all contacts
# relaxed at X = 0. The model is moved exactly (each contact is a renewal process: its breaks
# lie at the cumulative sums of its slips), the master equation is solved by characteristics
# with ΔX = Δx (an exact shift, exact survival over a step: second order, conservative to
# round-off). In the sliding state the force is the closed form $N k\langle x_s^2\rangle /
# (2\langle x_s\rangle)$.

# %%
model = EQModel(n_contacts=4000, k=1.0, x_s_mean=1.0, x_s_std=0.3)
runs = {N: EQModel(n_contacts=N, k=1.0, x_s_mean=1.0, x_s_std=0.3).quasistatic(
    6.0, realisations=4, seed=1) for N in (250, 4000)}
me = MasterEquation(model, h=0.005).solve(6.0)
# the Gaussian thresholds are truncated at x_s > 0 for relaxed newborns; at σ = 0.3 the
# truncated mass is 4e-4, its effect on <x_s²>/<x_s> below 1e-3
kinetic = model.n_contacts * (1.0 + 0.3**2) / 2
say(f"master equation: static force {me.static_force:.1f}, kinetic {me.kinetic_force:.1f} "
    f"(closed form {kinetic:.1f}), K* = {me.K_star:.1f} = {me.K_star / 4000:.3f} N k, "
    f"mass error {me.mass_error:.1e}")
differences = {}
for N, run in runs.items():
    scaled = np.interp(me.X, run.X, run.F) / N
    differences[N] = float(np.sqrt(np.mean((scaled - me.F / 4000) ** 2)))
    say(f"EQ model, N = {N}: static force per contact {run.static_force / N:.4f}, kinetic "
        f"{run.kinetic_force / N:.4f}; rms difference from the master equation "
        f"{differences[N]:.2e}")

if comm.rank == 0:
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    for N, run in runs.items():
        ax.plot(run.X, run.F / N, lw=0.8, label=f"EQ model, N = {N} (4 realisations)")
    ax.plot(me.X, me.F / 4000, "k-", label="master equation")
    ax.axhline(kinetic / 4000, color="gray", ls=":", label="N k⟨x_s²⟩/(2⟨x_s⟩)")
    ax.set(xlabel="X / x_c", ylabel="F / (N k x_c)", title="static peak, then kinetic friction")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "eq_master_equation.png", dpi=110)
    plt.close(fig)

# %% [markdown]
# **Checks.** The master equation conserves the contacts to round-off and gives the kinetic
# closed form to its second-order error (h = 0.005: 1e-4); the model's mean over realisations
# approaches it like $N^{-1/2}$ (the benchmark fits −0.497): 16 times more contacts, about 4
# times closer.

# %%
assert me.mass_error < 1e-12
assert abs(me.kinetic_force / kinetic - 1) < 2e-3
assert 2.0 < differences[250] / differences[4000] < 8.0, differences

# %% [markdown]
# ## 2. The elastic instability
#
# Drive the slider (mass m) through a spring K at speed v. It can follow $F(X)$ only where
# $K > -F'(X)$: below $K^* = -\max F'(X)$ the slider jumps after each static peak, stick-slip;
# above it slides smoothly. The spring-driven model is integrated by PETSc TS (generalized-α;
# breaks at step resolution), each run classified by whether the slider jumped (its speed
# exceeds 10 v).

# %%
smap = instability_map(K=[10.0, 40.0, 400.0, 1200.0], relative_spread=[0.1, 0.3],
                       n_contacts=300, seed=2)
for i, s in enumerate(smap.relative_spread):
    say(f"σ/x_c = {s}: K* = {smap.K_star[i]:.1f}; stick-slip at K = "
        f"{[float(K) for K, j in zip(smap.K, smap.onset_stick_slip[i], strict=True) if j]}")

# %% [markdown]
# **Check.** Far from the boundary (a factor 3 on either side of K*) the runs fall on the side
# the master equation predicts.

# %%
stiffness = smap.K
for i in range(len(smap.relative_spread)):
    critical = smap.K_star[i]
    far = (stiffness < critical / 3) | (stiffness > 3 * critical)
    predicted = stiffness < critical
    assert np.all(smap.onset_stick_slip[i][far] == predicted[far]), (i, smap.onset_stick_slip[i])

# %% [markdown]
# ## 3. The elastic interaction of contacts
#
# Contacts sit on an elastic half-space (spacing a, Young's modulus E), so the force of one
# moves the others: $U = -G F$ with the half-space Green tensor (Landau & Lifshitz, §8), and
# under a uniform shear $U_0$ the contacts carry $F = (1 + KG)^{-1} K U_0$. When one breaks, the
# others take up its load: $\delta F = B\,\delta K\,(1 - GBK)U_0$. Inside the elastic
# correlation length $\lambda_c = a^2E/k$ the response falls like $r^{-1}$ (the substrate is
# soft against the contacts), beyond it like $r^{-3}$ (the others screen the break). The
# lattice is solved matrix-free (FFT products, conjugate gradients).

# %%
n, lam = 192, 4.0
lattice = LatticeInteraction(n=n, spacing=1.0, E=1.0, nu=0.3, stiffness=1.0 / lam,
                             contact_radius=0.5)
centre = (n // 2) * n + n // 2
r, df = radial_profile(lattice.positions, lattice.break_response((1.0, 0.0, 0.0), centre),
                       centre, edges=np.geomspace(1.0, n / 4, 24))
laws = fit_power_laws(r, df, near_limit=2.0, far_limit=3 * lam)
say(f"interaction, λ_c = {lam:g} a: δf ∝ r^{laws.far_exponent:.2f} beyond 3 λ_c "
    f"(near zone: see docs/multicontact-interaction.md, −1.05 at λ_c = 256 a)")
if comm.rank == 0:
    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    ax.loglog(r, df, "o", ms=3, label="|δf(r)|")
    ax.axvline(lam, color="gray", lw=0.8, label="λ_c")
    ax.set(xlabel="r / a", ylabel="|δf|", title="response to a break")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "interaction.png", dpi=110)
    plt.close(fig)

# %% [markdown]
# **Check.** Beyond λ_c the response falls like $r^{-3}$; the fit over $3\lambda_c < r < n/4$
# sees the local slope −2.7 … −3.0 (it reaches −3 only asymptotically), hence ±0.35.

# %%
assert abs(laws.far_exponent + 3.0) < 0.35, laws.far_exponent

# %% [markdown]
# **Interacting contacts in the EQ model.** Put the EQ contacts on a 16 × 16 lattice between
# two identical bodies: a contact's stretching is the slider's displacement less the bodies'
# relative surface displacement, $f = (k^{-1} + G)^{-1} U_0$, with G twice the half-space's
# tangential block. A break re-forms the contact relaxed and hands its load to the others at
# once; those that go over their thresholds break at the same X, an avalanche. The coupling
# $k/(Ea)$ measures the interaction (the correlation length is $\lambda_c = a/(k/(Ea))$).
# The slides' EQ simulation: "the stronger is the interaction, the wider is the range of model
# parameters where stick-slip occurs". Here with a rigid drive, where contacts without
# interaction always slide smoothly (each break drops F by ~2/N): a run is stick-slip when
# one avalanche drops F by more than 5 % of the kinetic force.

# %%
spreads_i, couplings = [0.1, 0.2, 0.3, 0.5], [0.0, 0.003, 0.01, 0.03, 0.1, 0.3]
cmap = coupling_map(couplings, spreads_i, n_side=16, lives=8.0)
say("interacting contacts (16 × 16, rigid drive), stick-slip runs per coupling: "
    + ", ".join(f"{c:g}: {n}/{len(spreads_i)}"
                for c, n in zip(couplings, cmap.sustained_stick_slip.sum(axis=0), strict=True))
    + "; largest avalanche " + ", ".join(f"{a:.0%}" for a in cmap.largest_avalanche.max(axis=0)))
coupled = {c: InteractingEQModel.lattice(EQModel(n_contacts=256, x_s_std=0.3), c)
           for c in (0.0, 0.01, 0.3)}
traces = {c: m.quasistatic(8 * 256 / m.interface_stiffness, n_points=16001)
          for c, m in coupled.items()}
if comm.rank == 0:
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4))
    for c, run in traces.items():
        lives = run.X * coupled[c].interface_stiffness / 256
        late = (lives >= 6.0) & (lives <= 7.0)
        a1.plot(lives[late], run.F[late] / 256, lw=0.8, label=f"k/(Ea) = {c:g}")
    a1.set(xlabel="contact lives X S/(N k x_c)", ylabel="F / (N k x_c)",
           title="σ/x_c = 0.3, one late life: single breaks, then avalanches")
    a1.legend(fontsize=8)
    shown = np.where(cmap.coupling > 0, cmap.coupling, 1e-3)
    for i, s in enumerate(cmap.relative_spread):
        a2.plot(shown, cmap.largest_late_drop[i], "o-", ms=4, label=f"σ/x_c = {s:g}")
    a2.axhline(cmap.drop_threshold, color="gray", ls=":", label="stick-slip above")
    a2.set(xscale="log", yscale="log", xlabel="k/(Ea) (no interaction at 1e-3)",
           ylabel="largest drop of F in one avalanche / F_k", title="stick-slip widens")
    a2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "interacting_contacts.png", dpi=110)
    plt.close(fig)

# %% [markdown]
# **Check.** Without interaction every break is single and no run is stick-slip; the number
# of stick-slip runs does not fall as the coupling grows, and at the strongest coupling every
# spread sticks and slips.

# %%
per_coupling = cmap.sustained_stick_slip.sum(axis=0)
assert per_coupling[0] == 0 and np.all(cmap.largest_avalanche[:, 0] == 1 / 256)
assert np.all(np.diff(per_coupling) >= 0) and per_coupling[-1] == len(spreads_i), per_coupling

# %% [markdown]
# ## 4. Slip fronts in the Frenkel-Kontorova chain
#
# $m\ddot u_i + m\eta\dot u_i - g(u_{i+1} + u_{i-1} - 2u_i) + F_s(u_i) + K u_i = f$: contacts
# of stiffness k that break at $u_s$ and re-form relaxed; the left part of the chain relaxed,
# the right part not. Between $f_{min} = (k/2 + K)u_s$ and $f_{max} = (k + K)u_s$ a front of
# breaks runs into the unrelaxed part; its continuum travelling wave has the speed
# $v = c_0/\sqrt{1 + m\eta^2(1 - r^2)/(4 r^2 (k + K))}$, $r = 2(f - f_{min})/(k u_s)$, which
# has the slides' low- and high-velocity limits. Breaks are located as TS events.

# %%
chain = FKChain(n=150, m=1.0, eta=1.0, g=100.0, k=1.0, K=0.25, u_s=1.0)
fk = chain.simulate(1.0, t_end=25.0, relaxed=15)
speed = fk.front_speed(20, 60)
say(f"FK chain: front speed {speed:.4f}, continuum {chain.continuum_front_speed(1.0):.4f}, "
    f"sound speed {chain.sound_speed:.1f}; energy balance residual "
    f"{np.abs(fk.energy_residual()).max():.1e} of the work {fk.work[-1]:.1f}")
pinned = chain.with_defects(0.2, seed=1).simulate(0.85, t_end=40.0, relaxed=15)
say(f"with ±20 % threshold spread at f = 0.85 the front breaks "
    f"{int(np.isfinite(pinned.break_time).sum()) - 15} contacts and stops "
    f"(the uniform chain: all)")

# %% [markdown]
# **Checks.** At g = 100 the discrete front is within 1-2 % of the continuum wave away from
# $f_{min}$, $f_{max}$ (`docs/multicontact-fk.md`; 3 % asserted); the work of f is the stored,
# dissipated and broken-contact energy to the integrator's tolerance; the defects pin the
# front.

# %%
assert abs(speed / chain.continuum_front_speed(1.0) - 1) < 0.03
assert np.abs(fk.energy_residual()).max() < 1e-6 * fk.work[-1]
assert np.isfinite(pinned.break_time).sum() < chain.n

# %% [markdown]
# ## 5. An elastic slider on EQ contacts: detachment fronts
#
# A 2D elastic slider (10 cm × 1 cm, E = 1 GPa, plane strain) whose base is held by EQ
# contacts (thresholds 1 μm ± 5 %, re-forming relaxed after 0.1 ms) is pushed at its trailing
# edge by a stage moving at 1 mm/s (Rubinstein, Cohen & Fineberg 2004; Braun, Barel & Urbakh
# 2009). The furthest contact broken so far is the front.

# %%
slider = ElasticSlider(nx=20, ny=2, spread=0.05, delay=1e-4, push_speed=1e-3, seed=3)
history = ElasticSliderModel(slider, comm).run(t_end=4e-3, dt=2e-6)
arrested = [f for f in history.fronts if f.arrested]
say(f"slider: first break at {history.breaks[0].time * 1e3:.3f} ms, x = "
    f"{history.breaks[0].x:.3g} m; {len(arrested)} arrested fronts (precursors); the front "
    f"spans the base at a push force of {history.slip_force:.0f} N/m (peak "
    f"{max(history.push_force):.0f} N/m)")
if comm.rank == 0:
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    ax.plot(np.array(history.time) * 1e3, np.array(history.front_position) / slider.L, "-")
    ax.plot([b.time * 1e3 for b in history.breaks], [b.x / slider.L for b in history.breaks],
            ".", ms=3, color="tab:red", label="breaks")
    ax.set(xlabel="t [ms]", ylabel="front position x / L",
           title="onset of sliding: precursors, then a front across the base")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "slider_fronts.png", dpi=110)
    plt.close(fig)

# %% [markdown]
# **Checks.** The first contact breaks at the pushed edge; arrested precursors come before the
# front that crosses the whole base, which does so below the force all contacts could hold,
# $k L \bar x_s (1 + \delta)$.

# %%
assert history.breaks[0].x == 0.0
assert len(arrested) >= 3
assert np.isfinite(history.slip_force)
assert history.slip_force < slider.k * slider.L * slider.threshold * (1 + slider.spread)
say(f"figures in {out}/")
