r"""Case files: what the planted-bug runs found untested (tests/planted_bugs.toml, room "case"),
each against a closed form, on models of a few dozen unknowns.

* **Rayleigh damping.** A body clamped on one side, no contact:
  with :math:`C = \alpha M + \beta K` every undamped mode :math:`\omega` keeps its shape and
  :math:`\lambda^2 + (\alpha + \beta\omega^2)\lambda + \omega^2 = 0`, so
  :math:`|\lambda| = \omega` and the damping ratio is
  :math:`\zeta = -\mathrm{Re}\,\lambda / |\lambda| = \alpha/(2\omega) + \beta\omega/2`
  (the roots of the quadratic). tests/test_cli_run.py checks that ``cea.csv`` reports
  :math:`-\mathrm{Re}\,\lambda / |\lambda|` under that name.
* **The band's lower edge** keeps the modes with :math:`\mathrm{Im}\,\lambda / 2\pi \ge f_{min}`.
* **A plane foundation below the body, and gravity.** The foundation's point lies a gap
  :math:`g_0` below the body's face; with linear compliance the contact carries the weight
  :math:`W = \rho g A` (times the thickness), so :math:`\int c_n d = W` and the mean
  penetration is :math:`W / (c_n L)`; the face's mean displacement is then
  :math:`-(g_0 + W/(c_n L))`, whatever the body's own deformation (equilibrium of the rigid
  translation, which no Dirichlet condition holds).
"""

import math
import pathlib

from mpi4py import MPI

import numpy as np
import pytest
from dolfinx import fem

from fenicsfriction import _compat
from fenicsfriction.case import CaseModel, read_case
from fenicsfriction.case.analyses import BandSolver
from fenicsfriction.stability import Mode, StabilitySolver
from fenicsfriction.steady import SteadySolver

COMM = MPI.COMM_WORLD
ALPHA, BETA = 0.7, 3e-4

#: a plate 2 x 1 clamped on its left side, Rayleigh damping, nothing else
DAMPED = f"""
[model]
dim = 2
thickness = 0.5
[bodies.plate]
shape = "rectangle"
size = [2.0, 1.0]
divisions = [4, 2]
E = 2e3
nu = 0.3
rho = 1.5
rayleigh_alpha = {ALPHA}
rayleigh_beta = {BETA}
[[supports]]
type = "clamped"
on = "plate.xmin"
"""

GAP, RHO, G, C_N, WIDTH = 0.1, 2.5, 4.0, 1e3, 2.0

#: a block over a plane 0.1 below its bottom face, pressed on it by its weight
ON_PLANE = f"""
[model]
dim = 2
[bodies.block]
shape = "rectangle"
size = [{WIDTH}, 1.0]
divisions = [4, 2]
E = 1e3
nu = 0.3
rho = {RHO}
[[supports]]
type = "displacement"
on = "block.xmin"
x = 0.0
[[loads]]
type = "gravity"
value = [0.0, -{G}]
[law]
c_n = {C_N}
m_n = 1.0
[[contacts]]
name = "plane"
surface = "block.ymin"
foundation = {{ point = [0.0, -{GAP}], normal = [0.0, 1.0] }}
initial_penetration = {GAP + RHO * G * WIDTH / (C_N * WIDTH)}
"""


def write_case(folder: pathlib.Path, name: str, text: str) -> pathlib.Path:
    path = folder / name
    if COMM.rank == 0:
        path.write_text(text)
    COMM.Barrier()
    return path


def test_rayleigh_damping_gives_each_mode_its_damping_ratio(shared_tmp_path):
    """Every eigenvalue of the plate: -Re λ/|λ| = α/(2|λ|) + β|λ|/2. Its 24 modes have |λ|
    from 9 to 335 rad/s, so both terms count (ζ = 0.040 at the lowest, sqrt(αβ) = 0.0145 at
    least, 0.051 at the highest). The PEP's eigenvalues of so small a problem carry relative
    errors ~1e-12: 1e-8 asked."""
    model = CaseModel(read_case(write_case(shared_tmp_path, "damped.toml", DAMPED)), COMM)
    modes = StabilitySolver(model.residual, prefix="case_rayleigh_").solve(2 * math.pi * 200.0)
    assert len(modes) == 24
    for mode in modes:
        modulus = abs(mode.value)
        expected = ALPHA / (2 * modulus) + BETA * modulus / 2
        assert -mode.value.real / modulus == pytest.approx(expected, rel=1e-8), mode.value


class _Fixed:
    """A stand-in eigensolver: the same modes whatever it is asked."""

    def __init__(self, frequencies):
        self.comm = COMM
        self.modes = [Mode(value=complex(-1.0, 2 * math.pi * f), residual=0.0, accurate=True,
                           vector=np.zeros(0)) for f in frequencies]

    def solve(self, max_modulus):
        return self.modes


def test_the_band_keeps_the_modes_from_fmin_in_hertz():
    """Modes at 1, 5, 12 and 40 Hz, band [10, 50] Hz: 12 and 40 Hz are kept (5 Hz is 31 rad/s,
    above 10)."""
    band = BandSolver(_Fixed([1.0, 5.0, 12.0, 40.0]), [10.0, 50.0])
    kept = [m.value.imag / (2 * math.pi) for m in band.solve(band.max_modulus)]
    assert kept == pytest.approx([12.0, 40.0], rel=1e-15)
    assert band.max_modulus == pytest.approx(2 * math.pi * 50.0, rel=1e-15)


def test_a_block_on_a_plane_below_it_sinks_by_the_gap_and_its_weights_penetration(
        shared_tmp_path):
    """Normal force W = ρ g A = 20 and mean face displacement -(g₀ + W/(c_n L)) = -0.11, both
    to Newton's tolerance (1e-10 of W asked; 1e-8 relative checked)."""
    case = read_case(write_case(shared_tmp_path, "plane.toml", ON_PLANE))
    model = CaseModel(case, COMM)
    model.initial_guess()
    weight = RHO * G * WIDTH * 1.0
    SteadySolver(model.residual, prefix="plane_gap_",
                 options={"snes_atol": 1e-10 * weight}).solve()
    assert model.contact_forces()["plane"]["normal_force"] == pytest.approx(weight, rel=1e-8)
    ds = model.ds(model.surface_tag("block.ymin"))
    u = model.residual.u

    def integral(form) -> float:
        return COMM.allreduce(fem.assemble_scalar(_compat.form(form)))

    one = fem.Constant(model.msh, np.float64(1.0))
    mean = integral(u[1] * ds) / integral(one * ds)
    assert mean == pytest.approx(-(GAP + weight / (C_N * WIDTH)), rel=1e-8)
