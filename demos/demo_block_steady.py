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
# # Steady sliding of a block on a moving belt
#
# This demo shows how to build the block-on-belt scene of Martins & Oden (1986, Figs. 6-7),
# look at its one residual, follow the steady sliding state in the friction coefficient
# $\mu$ with Newton's method, and extend the residual with a term of your own — a pressure on
# the top face — written in UFL.
#
# A linearly elastic block (plane strain, breadth $B_0$) rests with its weight on a rough belt
# moving at speed $U_T$ and is held back by a horizontal spring $K_x$ through its centre of
# mass. The interface has normal compliance and Coulomb friction (Martins & Oden 1986,
# eqs. 1-2):
#
# $$ -\sigma_n = c_n d^{m_n}, \qquad \sigma_T = c_T d^{m_T}\,\tau, \qquad
#    d = (u_n - g)_+, \quad c_T = \mu c_n, $$
#
# where $\tau$ is the unit vector along the sliding velocity of the belt relative to the body.
# Steady sliding (their Problem 2) is the regularised virtual-power residual at
# $\dot u = \ddot u = 0$:
#
# $$ R(u_0; v) = a(u_0, v) + \langle P(u_0), v\rangle + \langle J_\varepsilon(u_0, 0), v\rangle
#    - \langle f, v\rangle = 0 \quad \forall v. $$
#
# Reference: J.A.C. Martins, J.T. Oden, "Interface models, variational principles and
# numerical solutions for dynamic friction problems", in *Mechanics of Material Interfaces*,
# Selvadurai & Voyiadjis (eds), Elsevier 1986.
#
# Run it serially or in parallel: `mpirun -n 2 python3 demos/demo_block_steady.py`.

# %%
import dataclasses
import logging

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem

import fenicsfriction as ff
from fenicsfriction.studies.block.data import TOP

logging.getLogger("ffcx").setLevel(logging.WARNING)
comm = MPI.COMM_WORLD
say = ff.results.get_logger(comm=comm).info

# %% [markdown]
# ## The scene and its residual
# The scene is data: the paper's block with its default 4 × 3 mesh of nine-node
# quadrilaterals. `build` makes the mesh, the function space and the one residual
# $R(u, \dot u, \ddot u; v)$; the friction coefficient is a `fem.Constant` we will step.
# At rest the inertia term $\langle \rho \ddot u, v\rangle$ drops out of the steady form.

# %%
scene = ff.BlockOnBelt()  # the paper's law, eq. (36), with μ = 0
model = scene.build(comm=comm, with_friction=True)
R = model.residual
say(f"R has {len(R.form.integrals())} integrals; steady form keeps "
    f"{len(R.steady().integrals())} (inertia drops out at rest)")
for integral in R.steady().integrals():
    say(f"  {integral.integral_type():15s} subdomain {integral.subdomain_id()}")

# %% [markdown]
# ## Continuation in $\mu$
# As in Martins & Oden (1986), $\mu$ is raised in increments with Newton's method at each
# one, from the frictionless state. Every PETSc option of the solver can be set under its
# prefix, e.g. `-demo_snes_monitor`.

# %%
model.initial_guess()
solver = ff.SteadySolver(model.residual, prefix="demo_", options=model.solver_options())
records = ff.continuation(solver, model.mu, targets=np.linspace(0.0, 1.2, 13),
                          observe=model.quantities)
for r in records[::4]:
    say(f"μ = {r['mu']:.2f}: N = {r['normal_force']:.2f}, friction = {r['friction_force']:.2f}, "
        f"spring = {r['spring_force']:.2f}, centre of pressure = {r['centre_of_pressure']:.3f} cm")

# %% [markdown]
# ### Statics of the sliding block
# The block slides steadily, so the forces on it balance. Vertically the normal force
# carries the weight, $N = W$; horizontally the spring holds the friction force, which the
# law makes $\mu N$ on a sliding interface: $F_s = -\mu W$ (the belt drags towards $+x$).
# Taking moments about the centre of mass, the spring acts at the height $h$ of the centre
# of mass above the belt, so the normal resultant moves back by $x_{cp} = -\mu h$. The
# spring force is read off the spring's elongation and $x_{cp}$ off the pressure
# distribution, not off the friction term. Newton stops at a residual $\|R\|$; the sum of
# the $n$ nodal residuals in one direction, which is what a resultant misses, is at most
# $\sqrt{n}\,\|R\|$.

# %%
n_dofs = model.V.dofmap.index_map.size_global * model.V.dofmap.index_map_bs


def resultant_tolerance(residual_norm):
    """Bound on the error of a force resultant at a state solved to ``residual_norm``."""
    return np.sqrt(n_dofs) * residual_norm


for r in records:
    tol = resultant_tolerance(r["residual_norm"])
    assert abs(r["normal_force"] - scene.weight) <= tol, r
    assert abs(r["spring_force"] + r["mu"] * scene.weight) <= (1 + r["mu"]) * tol, r
last = records[-1]
assert np.isclose(last["centre_of_pressure"], -last["mu"] * scene.spring_height, rtol=1e-5)

# %% [markdown]
# ## Adding a term of our own
# The residual is an ordinary UFL form. A uniform pressure $p$ on the top face
# $\Gamma_{top}$ is the traction $t = -p\, e_y$; its virtual work enters the load term
# $\langle f, v\rangle$, so the residual gains
#
# $$ R_{top}(v) = -B_0 \int_{\Gamma_{top}} t \cdot v \, ds, \qquad t = -p\, e_y, $$
#
# and a new solver is built from the extended residual.

# %%
p_top = 0.2  # [10^3 kg cm^-1 s^-2]
p = fem.Constant(model.msh, p_top)
e_y = ufl.as_vector((0.0, 1.0))
t = -p * e_y
B0 = model.thickness
v = R.v
ds = ufl.Measure("ds", domain=model.msh, subdomain_data=model.facet_tags)
R_top = -B0 * ufl.inner(t, v) * ds(TOP)
extended = dataclasses.replace(R, form=R.form + R_top)
solver_top = ff.SteadySolver(extended, prefix="demo_top_", options=model.solver_options())
report = solver_top.solve()
q = model.quantities()
extra = p_top * scene.L * scene.B0
say(f"with p = {p_top} on top: N = {q.normal_force:.2f} (expected {scene.weight + extra:.2f}),"
    f" friction = {q.friction_force:.2f}, Newton {report.iterations} iterations")

# %% [markdown]
# The top load adds $p L B_0$ to what the belt carries and, by the same statics, $\mu p L
# B_0$ to what the spring holds: $N = W + p L B_0$ and $F_s = -\mu (W + p L B_0)$.

# %%
tol = resultant_tolerance(report.residual_norm)
assert abs(q.normal_force - (scene.weight + extra)) <= tol
assert abs(q.spring_force + q.mu * (scene.weight + extra)) <= (1 + q.mu) * tol

# %% [markdown]
# ## A friction law of our own
# The interface law is one object, `ff.InterfaceLaw`, that every model takes. A friction
# coefficient of our own — falling exponentially with the slip speed $s$ and rising with the
# normal pressure $p$,
#
# $$ \mu(s, p) = \left(\mu_k + (\mu_s - \mu_k) e^{-s/v_s}\right)
#    \left(1 + \frac{p}{p_{ref}}\right)^{\alpha}, $$
#
# — is written once with operations valid on UFL and NumPy (`ff.laws.exp`), wrapped in the law
# and handed to the scene unchanged; the residual, its Jacobian and the observables follow
# (see docs/user-law.md). In steady sliding every point of the base slips at the belt speed
# $U_T$, so the friction resultant is $B_0 \int_{\Gamma_C} \mu(U_T, p)\, p \, ds$, and the
# spring holds it.

# %%
MU_S, MU_K, V_S, P_REF, ALPHA = 0.6, 0.4, 0.1, 0.2, 0.3


def user_mu(speed, pressure):
    """μ(s, p): Stribeck-like in the slip speed, a power law in the pressure."""
    return (MU_K + (MU_S - MU_K) * ff.laws.exp(-speed / V_S)) * (1 + pressure / P_REF) ** ALPHA


user_scene = scene.with_law(friction_coefficient=user_mu)
user_model = user_scene.build(comm=comm)
user_model.initial_guess()
user_report = ff.SteadySolver(user_model.residual, prefix="demo_user_",
                              options=user_model.solver_options()).solve()
qu = user_model.quantities()
pressure = user_model.pressure()
expected = comm.allreduce(fem.assemble_scalar(fem.form(
    user_scene.B0 * user_mu(user_scene.belt_speed, pressure) * pressure
    * user_model.ds_contact)), op=MPI.SUM)
mean_pressure = user_scene.weight / (user_scene.L * user_scene.B0)
say(f"user law: friction = {qu.friction_force:.3f} (∫ μ(U, p) p: {expected:.3f}), "
    f"spring = {qu.spring_force:.3f}, apparent μ = {qu.friction_force / qu.normal_force:.4f} "
    f"(μ at the mean pressure: {user_mu(user_scene.belt_speed, mean_pressure):.4f})")

# %%
tol = resultant_tolerance(user_report.residual_norm)
assert abs(qu.normal_force - user_scene.weight) <= tol
assert abs(qu.spring_force + qu.friction_force) <= 2 * tol
assert np.isclose(qu.friction_force, expected, rtol=1e-10)
