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
# # Stability of steady sliding: flutter of the block on a belt
#
# This demo shows how to compute the eigenvalues of steady sliding of the finite element
# block of Martins & Oden (1986, Figs. 8-9) as a function of the friction coefficient $\mu$,
# find the $\mu$ at which steady sliding loses stability (flutter) and the two modes that
# collide there, and compare the result with the rigid 3-d.o.f. block of their Fig. 9.
#
# Linearising the regularised virtual-power equation about a steady sliding state $u_0$
# gives the quadratic eigenproblem of their Problem 3,
#
# $$ (\lambda^2 M + \lambda C + \bar K)\, w = 0, \qquad
#    M = \frac{\partial R}{\partial \ddot u},\; C = \frac{\partial R}{\partial \dot u},\;
#    \bar K = \frac{\partial R}{\partial u} \text{ at } (u_0, 0, 0). $$
#
# $\bar K$ is not symmetric: friction turns normal displacement into tangential force,
# $K_{Tn} = -m_T c_T d^{m_T-1}\,\tau\otimes n$. Without damping the eigenvalues are imaginary
# for small $\mu$; as $\mu$ grows, two of them meet and leave the imaginary axis (flutter),
# and steady sliding becomes dynamically unstable: a mode grows like $e^{\mathrm{Re}\,\lambda\,
# t}$.
#
# Reference: J.A.C. Martins, J.T. Oden, "Interface models, variational principles and
# numerical solutions for dynamic friction problems", in *Mechanics of Material Interfaces*,
# Selvadurai & Voyiadjis (eds), Elsevier 1986.
#
# Run it serially or in parallel: `mpirun -n 2 python3 demos/demo_block_stability.py`.

# %%
import logging

from mpi4py import MPI

import numpy as np

import fenicsfriction as ff
from fenicsfriction.stability import Loci, StabilitySolver, unstable_intervals
from fenicsfriction.studies.block import RigidBlock

logging.getLogger("ffcx").setLevel(logging.WARNING)
comm = MPI.COMM_WORLD
say = ff.results.get_logger(comm=comm).info

# %% [markdown]
# ## The operators come from the one residual
# `StabilitySolver` differentiates the residual $R(u, \dot u, \ddot u; v)$ with respect to
# $\ddot u$, $\dot u$ and $u$ to get $M$, $C$ and $\bar K$: nothing is linearised by hand. The
# steady state $u_0$ at each $\mu$ comes from a `SteadySolver` on the same residual.

# %%
scene = ff.BlockOnBelt()
model = scene.build(comm=comm, with_friction=True)
model.initial_guess()
steady = ff.SteadySolver(model.residual, prefix="demo_steady_", options=model.solver_options())
stability = StabilitySolver(model.residual, prefix="demo_pep_")

# %% [markdown]
# ## Eigenvalue loci in $\mu$
# Every eigenvalue with $|\lambda|$ below $3\cdot 10^4$ rad/s is computed at each $\mu$ (SLEPc
# TOAR, shift-and-invert) and the modes are followed from step to step by their modal
# assurance criterion (MAC).

# %%
mu_grid = np.linspace(0.0, 1.5, 31)
history = []
loci = Loci(steady, stability, model.mu, max_modulus=3e4)
records = loci.follow(mu_grid, on_step=lambda record, modes: history.append(modes))
intervals = unstable_intervals(records)
say(f"FE modes unstable on the μ grid: {intervals}")

# %% [markdown]
# ## The onset, and which modes collide
# Between the last stable and the first unstable $\mu$ of the grid, the onset is bisected;
# flutter is a collision: the growing eigenvalue is born from two modes that meet in
# frequency.

# %%
first = next(k for k, modes in enumerate(history) if loci.unstable(modes))
onset = loci.onset(mu_grid[first - 1], mu_grid[first], tol=1e-3, reference=history[first - 1])
say(f"flutter onset μ_crit = {onset.mu_crit:.4f}: modes "
    f"{[c['mode'] for c in onset.colliding]} collide at ω ≈ {onset.value[1]:.0f} rad/s")
assert len({c["mode"] for c in onset.colliding}) == 2

# %% [markdown]
# ## The rigid block (Fig. 9)
# The same interface law integrated over the base of a rigid body with three degrees of
# freedom $(u_{xG}, u_{yG}, \theta)$. The spring acts through the centre of mass $G$, so the
# tangential pair of eigenvalues stays at $\pm i\sqrt{K_x/M}$ whatever $\mu$: a closed form to
# check the rigid model's eigenvalues against at every step.

# %%
q = None
rigid_max_re = []
for mu in mu_grid:
    block = RigidBlock.from_scene(scene, law=scene.law.replace(mu=mu))
    q = block.steady_state(q)
    lam = block.eigenvalues(q)
    rigid_max_re.append(lam.real.max())
    assert np.isclose(lam[np.argmin(abs(lam))].imag ** 2, scene.K_x / scene.mass, rtol=1e-8)
rigid_unstable = mu_grid[np.array(rigid_max_re) > 1e-6 * 5e3]
say(f"rigid block unstable on the μ grid from {rigid_unstable.min():.2f} "
    f"to {rigid_unstable.max():.2f}")

# %% [markdown]
# Both models lose stability through the pair of normal and rotational modes, over
# overlapping ranges of $\mu$.

# %%
fe_unstable = [r["mu"] for r in records if r["max_re"] > 1e-6 * 5e3]
assert max(min(fe_unstable), rigid_unstable.min()) < min(max(fe_unstable), rigid_unstable.max())
