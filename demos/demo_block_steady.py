# # Steady sliding of a block on a moving belt (Martins & Oden 1986, Figs. 6-7)
#
# A linearly elastic block (plane strain, breadth $B_0$) rests with its weight on a rough belt
# moving at speed $U_T$ and is held back by a horizontal spring $K_x$ through its centre of
# mass. The interface has normal compliance and Coulomb friction (seed 000, eqs. 1-2):
#
# $$ -\sigma_n = c_n d^{m_n}, \qquad \sigma_T = c_T d^{m_T}\,\tau, \qquad
#    d = (u_n - g)_+, \quad c_T = \mu c_n. $$
#
# Steady sliding (Problem 2) is the regularised virtual-power residual at $\dot u = \ddot u = 0$:
#
# $$ a(u_0, v) + \langle P(u_0), v\rangle + \langle J_\varepsilon(u_0, 0), v\rangle
#    - \langle f, v\rangle = 0 \quad \forall v. $$
#
# This demo (1) builds the scene and looks at its residual, (2) follows the steady state in
# $\mu$ with Newton, (3) adds a term of its own to the residual — a pressure on the top face —
# and re-solves, checking the statics of each state.
#
# Run it serially or in parallel: `mpirun -n 2 python3 demos/demo_block_steady.py`.

# +
import logging

from mpi4py import MPI

import numpy as np

import fenicsfriction as ff
from fenicsfriction import forms

logging.getLogger("ffcx").setLevel(logging.WARNING)
comm = MPI.COMM_WORLD
say = ff.results.get_logger(comm).info
# -

# ## The scene and its residual
# The scene is data: the paper's block with its default 4 × 3 mesh of nine-node
# quadrilaterals. `build` makes the mesh, the space and the one residual
# $R(u, \dot u, \ddot u; v)$; the friction coefficient is a `fem.Constant` we will step.

scene = ff.BlockOnBelt(mu=0.0)
model = scene.build(comm, with_friction=True)
R = model.residual
say(f"R has {len(R.form.integrals())} integrals; steady form keeps "
    f"{len(R.steady().integrals())} (inertia drops out at rest)")
for integral in R.steady().integrals():
    say(f"  {integral.integral_type():15s} subdomain {integral.subdomain_id()}")

# ## Continuation in μ (seed 000: NINCT increments, Newton at each)
# Every PETSc option of the solver can be set under its prefix, e.g. `-demo_snes_monitor`.

model.initial_guess()
solver = ff.SteadySolver(R, prefix="demo_", options=model.solver_options())
records = ff.continuation(solver, model.mu, np.linspace(0.0, 1.2, 13), observe=model.quantities)
for r in records[::4]:
    say(f"μ = {r['mu']:.2f}: N = {r['normal_force']:.2f}, friction = {r['friction_force']:.2f}, "
        f"spring = {r['spring_force']:.2f}, centre of pressure = {r['centre_of_pressure']:.3f} cm")
last = records[-1]
assert np.isclose(last["friction_force"], last["mu"] * last["normal_force"], rtol=1e-8)
assert np.isclose(last["centre_of_pressure"], -last["mu"] * scene.spring_height, rtol=1e-5)

# ## Adding a term of our own
# The residual is an ordinary UFL form: we add the virtual work of a uniform pressure $p$ on
# the top face, $-\int_{\Gamma_{top}} t\cdot v\,ds$ with $t = -p\,e_y$, times the breadth,
# and build a new solver from the extended residual. Normal force and friction must grow by
# $p L B_0$ and $\mu p L B_0$.

# +
import dataclasses  # noqa: E402

import ufl  # noqa: E402
from dolfinx import fem  # noqa: E402

p_top = 0.2  # [10^3 kg cm^-1 s^-2]
ds = ufl.Measure("ds", domain=model.msh, subdomain_data=model.facet_tags)
top_load = fem.Constant(model.msh, np.array([0.0, -p_top]))
extended = dataclasses.replace(
    R, form=R.form + model.thickness * forms.surface_traction(top_load, R.v, ds(2)))
solver_top = ff.SteadySolver(extended, prefix="demo_top_", options=model.solver_options())
report = solver_top.solve()
q = model.quantities()
extra = p_top * scene.L * scene.B0
say(f"with p = {p_top} on top: N = {q['normal_force']:.2f} (expected {scene.weight + extra:.2f}),"
    f" friction = {q['friction_force']:.2f}, Newton {report.iterations} iterations")
assert np.isclose(q["normal_force"], scene.weight + extra, rtol=1e-8)
assert np.isclose(q["friction_force"], q["mu"] * q["normal_force"], rtol=1e-8)
# -
