"""Case files build the models the Python scenes build: the block cases give BlockOnBelt's and
BlockOnSlab's steady states, eigenvalues and flutter onset; a pad on a rotating plane gives the
closed-form friction torque; a transient from the unstable mode grows at Re λ."""

import json
import math
import pathlib
import zlib

from mpi4py import MPI

import numpy as np
import pytest
import ufl
from dolfinx import fem
from scipy.integrate import dblquad

from fenicsfriction import _compat
from fenicsfriction.case import CaseModel, read_case, run_case
from fenicsfriction.case.analyses import SEARCH_ROUNDS
from fenicsfriction.case.schema import CONTACT_FORMULATIONS
from fenicsfriction.contact import FORMULATIONS
from fenicsfriction.stability import Loci, StabilitySolver
from fenicsfriction.steady import SteadySolver, continuation
from fenicsfriction.studies.block import BlockOnBelt, BlockOnSlab

ROOT = pathlib.Path(__file__).resolve().parents[1]
COMM = MPI.COMM_WORLD
MAX_MODULUS = 3e4  # [rad/s]: the block command's default disc, the cases' band

#: the pad of docs/case-files.md: a stiff pad pushed δ into a plane turning about the z axis
PAD = """
[model]
dim = 3
degree = 1
[bodies.pad]
shape = "box"
origin = [0.09, -0.01, 0.0]
size = [0.02, 0.02, 0.01]
divisions = [4, 4, 2]
E = 2e11
nu = 0.3
rho = 7800.0
[[supports]]
type = "displacement"
on = "pad.zmax"
x = 0.0
y = 0.0
z = -1e-5
[law]
c_n = 1e9
m_n = 1.0
mu = 0.5
eps = 1e-3
[[contacts]]
name = "disc"
surface = "pad.zmin"
foundation = { point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }
initial_penetration = 1e-5
[motion]
type = "rotation"
omega = 10.0
"""


def write_case(folder: pathlib.Path, name: str, text: str) -> pathlib.Path:
    path = folder / name
    if COMM.rank == 0:
        path.write_text(text)
    COMM.Barrier()
    return path


def slide(residual, mu, values, prefix: str) -> None:
    """Steady sliding continued in μ through ``values`` (atol 1e-10 of the weight 450)."""
    solver = SteadySolver(residual, prefix=prefix, options={"snes_atol": 4.5e-8})
    continuation(solver, mu, values)


def moments(u: fem.Function) -> np.ndarray:
    """∫ u_x, ∫ u_y, ∫ |u|² over the mesh: numbering-free fingerprints of the field."""
    dx = ufl.Measure("dx", domain=u.function_space.mesh)
    return np.array([u.function_space.mesh.comm.allreduce(fem.assemble_scalar(_compat.form(f)))
                     for f in (u[0] * dx, u[1] * dx, ufl.inner(u, u) * dx)])


def spectrum(residual, prefix: str) -> np.ndarray:
    values = [m.value for m in StabilitySolver(residual, prefix=prefix).solve(MAX_MODULUS)]
    return np.array(sorted(values, key=lambda z: (round(z.imag, 3), z.real)))


@pytest.mark.parametrize(("name", "scene"), [("block-on-belt", BlockOnBelt),
                                             ("block-on-slab", BlockOnSlab)])
def test_block_case_files_give_the_python_scenes_states_and_eigenvalues(name, scene):
    """Same mesh (numbered otherwise), same terms: the steady states at μ = 0.5 agree to the
    Newton tolerance (relative 1e-9: both converge quadratically far below it) and the
    eigenvalues to the PEP's tolerance, 1e-8 of the largest |λ| (the backward error is relative
    to the operators' norms: the spring's mode, |λ| = sqrt(K_x/M) = 5 against 2.5e4, carries
    an error of 2e-8 of itself, 1e-11 of the spectrum)."""
    case = read_case(ROOT / "cases" / f"{name}.toml")
    model = CaseModel(case, COMM)
    model.initial_guess()
    slide(model.residual, model.parameters["mu"], [0.0, 0.25, 0.5], f"case_{name}_")
    reference = scene().build(COMM, with_friction=True)
    reference.initial_guess()
    slide(reference.residual, reference.mu, [0.0, 0.25, 0.5], f"scene_{name}_")
    assert np.allclose(moments(model.residual.u), moments(reference.residual.u), rtol=1e-9,
                       atol=0)
    forces = next(iter(model.contact_forces().values()))
    q = reference.quantities()
    assert forces["normal_force"] == pytest.approx(q.normal_force, rel=1e-10)
    assert forces["friction_force"][0] == pytest.approx(q.friction_force, rel=1e-10)
    ours, theirs = spectrum(model.residual, f"case_{name}_pep_"), \
        spectrum(reference.residual, f"scene_{name}_pep_")
    assert len(ours) == len(theirs) == 6
    assert np.abs(ours - theirs).max() <= 1e-8 * np.abs(theirs).max(), (ours, theirs)


def test_block_case_file_finds_the_onset_of_the_block_command(shared_tmp_path):
    """run_case bisects the flutter onset on the case's grid (μ = 0, 0.1, ..., 0.6) to
    onset_tol = 1e-4; Loci on BlockOnBelt, bisected on the same grid interval, agrees within
    that tolerance, and so does the onset eigenvalue (to 1e-3 of |λ|: Re λ grows like
    sqrt(μ - μ_crit), so it is the sensitive part, measured equal here)."""
    case = read_case(ROOT / "cases" / "block-on-belt.toml")
    outcome = run_case(case, shared_tmp_path / "out", COMM)
    assert outcome.exit_code == 0 and len(outcome.onsets) == 1
    summary = json.loads((shared_tmp_path / "out" / "summary.json").read_text())
    assert summary["mu_crit"] == pytest.approx(outcome.mu_crit)
    model = BlockOnBelt().build(COMM, with_friction=True)
    model.initial_guess()
    steady = SteadySolver(model.residual, prefix="onset_scene_", options={"snes_atol": 4.5e-8})
    loci = Loci(steady, StabilitySolver(model.residual, prefix="onset_scene_pep_"), model.mu,
                MAX_MODULUS)
    last: dict = {}
    loci.follow([0.3], on_step=lambda r, m: last.update(modes=m))
    onset = loci.onset(0.3, 0.4, 1e-4, reference=last["modes"])
    assert abs(outcome.mu_crit - onset.mu_crit) <= 1e-4
    assert outcome.mu_crit == pytest.approx(0.37026, abs=1e-4)  # docs/block-stability.md
    theirs, ours = complex(*onset.value), complex(*outcome.onsets[0].value)
    assert abs(ours - theirs) <= 1e-3 * abs(theirs)


def rectangle_integral_of_r() -> float:
    """∫ r dA over the pad's face [0.09, 0.11] × [-0.01, 0.01], r the distance to the axis."""
    return dblquad(lambda y, x: math.hypot(x, y), 0.09, 0.11, -0.01, 0.01,
                   epsabs=0, epsrel=1e-13)[0]


@pytest.mark.parametrize("comm", [COMM, MPI.COMM_SELF], ids=["world", "self"])
def test_friction_torque_of_a_pad_on_a_rotating_plane_is_mu_integral_of_p_r(
        shared_tmp_path, comm):
    """The pad (E = 2e11) is pushed δ = 1e-5 into a plane of linear compliance c_n = 1e9, so the
    pressure is c_n δ uniform to c_n h / E = 5e-5; the plane turns about the z axis at 10 rad/s
    (slip speeds ~1 m/s >> ε), so the friction traction is μ p along ω × r and its torque
    μ c_n δ ∫ r dA (tolerance 1e-4: twice the pad's compliance). Under 2 ranks the same
    numbers come from the mesh on both ranks and on each alone (round-off, 1e-10)."""
    case = read_case(write_case(shared_tmp_path, "pad.toml", PAD))
    model = CaseModel(case, comm)
    model.initial_guess()
    SteadySolver(model.residual, prefix=f"pad_{comm.size}_",
                 options={"snes_atol": 1e-10 * 4.0}).solve()
    forces = model.contact_forces()["disc"]
    p = 1e9 * 1e-5
    assert forces["normal_force"] == pytest.approx(p * 4e-4, rel=1e-4)
    assert forces["friction_torque"] == pytest.approx(0.5 * p * rectangle_integral_of_r(),
                                                      rel=1e-4)
    # the net friction force μ p ∫ ω×r/|ω×r| dA is along +y for a pad centred on the x axis
    # (its x part cancels between y and -y up to the pressure's departure from uniform)
    fx, fy, fz = forces["friction_force"]
    assert fy > 0 and abs(fx) < 1e-4 * fy and fz == 0.0
    values = COMM.allgather(forces["friction_torque"])
    assert max(values) - min(values) <= 1e-10 * abs(values[0])


def test_a_transient_from_the_unstable_mode_grows_at_re_lambda(shared_tmp_path):
    """From the steady state at μ = 0.5 plus 1e-7 cm of the growing mode (linear regime: the
    steady penetration is ~5e-5 cm), the motion's amplitude on the mode grows at Re λ = 404
    1/s: measured within 1 % (generalized-α's algorithmic damping and period error at
    ω dt = 0.055 are ~1e-3 of the rate; the other, stable, modes are not excited)."""
    text = (ROOT / "cases" / "block-on-belt.toml").read_text()
    text = text.replace("stop = 0.6", "stop = 0.5").replace("steps = 6", "steps = 1")
    text = text.replace("onset_tol = 1e-4", "onset_tol = 1e-2")
    text += "\n[transient]\namplitude = 1e-7\nt_end = 3e-3\ndt = 1e-5\nstride = 100\n"
    case = read_case(write_case(shared_tmp_path, "transient.toml", text))
    outcome = run_case(case, shared_tmp_path / "out", COMM)
    assert outcome.exit_code == 0
    measured, expected = (outcome.transient[k] for k in ("growth_rate_measured",
                                                          "growth_rate_re_lambda"))
    assert expected > 300 and measured == pytest.approx(expected, rel=1e-2)
    assert (shared_tmp_path / "out" / "transient.csv").stat().st_size > 0


def block_at(folder: pathlib.Path, mu: float, cea: str, comm: MPI.Comm = COMM) -> tuple:
    """The block case at ``mu`` with the [cea] table's extra lines ``cea``, solved steady on
    ``comm``."""
    text = (ROOT / "cases" / "block-on-belt.toml").read_text().replace(
        "onset_tol = 1e-4", "onset_tol = 1e-4\n" + cea)
    key = zlib.crc32(cea.encode())  # not hash(): it differs between the ranks' interpreters
    case = read_case(write_case(folder, f"case-{key}.toml", text))
    model = CaseModel(case, comm)
    model.initial_guess()
    slide(model.residual, model.parameters["mu"], [0.0, mu][:1 + (mu > 0)],
          f"switch_{key}_")
    return case, model


def test_the_friction_stiffness_alone_makes_the_block_flutter(shared_tmp_path):
    """At μ = 0.5 the block's pair grows (Re λ = 404 1/s); without the friction part of K̄ no
    mode grows (mode coupling), without the friction part of C it still does."""
    from fenicsfriction.case.analyses import eigensolver
    for extra, grows in (("", True), ("friction_stiffness = false", False),
                         ("friction_damping = false", True)):
        case, model = block_at(shared_tmp_path, 0.5, extra)
        solver = eigensolver(case, model, prefix=f"switch_pep_{zlib.crc32(extra.encode())}_")
        largest = max(m.value.real for m in solver.solve(solver.max_modulus))
        assert (largest > 100) == grows, (extra, largest)


def test_a_complete_modal_basis_gives_the_full_eigenvalues_and_modal_damping_its_ratio(
        shared_tmp_path):
    """Projected on all 126 real modes the quadratic eigenproblem is the full one (Galerkin
    with a complete basis): the same eigenvalues at μ = 0.5, to the solvers' accuracy. At μ = 0
    K̄ is symmetric and C = 0, so the basis modes are the modes: with modal damping ζ each
    eigenvalue is ω(-ζ + i sqrt(1 - ζ²)), Re λ = -ζ |λ|: to 1e-4, as Φᵀ K̄ Φ is diagonal to
    the basis's EPS tolerance only (1e-10 of ‖K̄‖, the complete basis reaching far above the
    band; measured 1e-7, and 3e-6 to 2e-5 for the driver spring's 5 rad/s mode, depending on
    the EPS's subspace size). Each rank solves
    alone: a shift-and-invert EPS asked for all 126 modes at once does not always return a
    complete basis on 2 ranks (measured: the unstable pair off by 2e-5 in one run of three)."""
    from fenicsfriction.case.analyses import eigensolver
    case, model = block_at(shared_tmp_path, 0.5, "", MPI.COMM_SELF)
    full = spectrum(model.residual, "complete_full_")
    case, model = block_at(shared_tmp_path, 0.5, 'method = "projection"\nmodes = 126',
                           MPI.COMM_SELF)
    solver = eigensolver(case, model, prefix="complete_projected_")
    projected = sorted((m.value for m in solver.solve(solver.max_modulus)),
                       key=lambda z: (round(z.imag, 3), z.real))
    # to the PEP's tolerance times the growing pair's condition (it is past a coalescence:
    # measured 6e-8 of its |λ| on Debian 13, 2e-9 on Debian 12; a basis of 20 modes is off by
    # 1e-3: μ_crit 0.3723 against 0.3703)
    assert np.abs(np.array(projected) - full).max() <= 1e-7 * np.abs(full).max()
    case, model = block_at(shared_tmp_path, 0.0,
                           'method = "projection"\nmodes = 126\nmodal_damping = 0.02',
                           MPI.COMM_SELF)
    solver = eigensolver(case, model, prefix="complete_damped_")
    for mode in solver.solve(solver.max_modulus):
        deviation = abs(mode.value.real / (-0.02 * abs(mode.value)) - 1)
        assert deviation < 1e-4


#: a gmsh script of the convention of meshes/*.py (``--out FILE``): the block's 4 × 3 grid of
#: quadrilaterals with named physical groups
GMSH_SCRIPT = '''
import argparse
import gmsh
out = argparse.ArgumentParser()
out.add_argument("--out")
path = out.parse_args().out
gmsh.initialize(readConfigFiles=False)
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("block")
L, H = 48.8, 30.5
gmsh.model.occ.addRectangle(0, 0, 0, L, H)
gmsh.model.occ.synchronize()
names = {}
for _, curve in gmsh.model.getEntities(1):
    x, y, _ = gmsh.model.occ.getCenterOfMass(1, curve)
    horizontal = abs(y) < 1e-9 or abs(y - H) < 1e-9
    gmsh.model.mesh.setTransfiniteCurve(curve, 5 if horizontal else 4)
    name = ("bottom" if y < 1e-9 else "top") if horizontal else ("left" if x < 1e-9 else "right")
    names.setdefault(name, []).append(curve)
gmsh.model.mesh.setTransfiniteSurface(1)
gmsh.model.mesh.setRecombine(2, 1)
gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, [1]), "block")
for name, curves in names.items():  # (gmsh 4.8 has no name= argument)
    gmsh.model.setPhysicalName(1, gmsh.model.addPhysicalGroup(1, curves), name)
gmsh.model.mesh.generate(2)
gmsh.write(path)
gmsh.finalize()
'''


def test_a_gmsh_mesh_made_by_its_script_gives_the_generated_block(shared_tmp_path):
    """The block case on a .msh written by its mesh.script (the file missing at first), bodies
    and surfaces named by physical group: the same mesh as the generated one, so the same
    eigenvalues at μ = 0.5 (to the PEP's tolerance, as above)."""
    pytest.importorskip("gmsh")
    text = (ROOT / "cases" / "block-on-belt.toml").read_text()
    text = text.replace("[bodies.block]", '[mesh]\nfile = "block.msh"\nscript = "block.py"\n\n'
                        "[bodies.block]")
    text = "\n".join(line for line in text.splitlines()
                     if not line.startswith(("shape =", "origin =", "size =", "divisions =")))
    text = text.replace("nodes_at = [[0.0, 15.25]]", 'group = "block"')
    text = text.replace('"block.ymin"', '"bottom"')
    write_case(shared_tmp_path, "block.py", GMSH_SCRIPT)
    path = write_case(shared_tmp_path, "gmsh.toml", text)
    case = read_case(path) if COMM.rank == 0 else None  # rank 0 runs the script
    case = COMM.bcast(case, root=0)
    assert (shared_tmp_path / "block.msh").is_file()
    model = CaseModel(case, COMM)
    model.initial_guess()
    slide(model.residual, model.parameters["mu"], [0.0, 0.25, 0.5], "gmsh_")
    generated = CaseModel(read_case(ROOT / "cases" / "block-on-belt.toml"), COMM)
    generated.initial_guess()
    slide(generated.residual, generated.parameters["mu"], [0.0, 0.25, 0.5], "generated_")
    ours, theirs = spectrum(model.residual, "gmsh_pep_"), spectrum(generated.residual,
                                                                   "generated_pep_")
    assert len(ours) == 6
    assert np.abs(ours - theirs).max() <= 1e-8 * np.abs(theirs).max(), (ours, theirs)


def stiff_slab_case(formulation: str, degree: int, refine: int) -> str:
    """cases/block-on-slab.toml with the contact's formulation and degree, the slab 1000 times
    the block's E and 2.5 cm thin (a rigid belt for the onset to 1e-5: docs/block-on-slab.md),
    every cell of both bodies split ``refine`` times along each axis."""
    text = (ROOT / "cases" / "block-on-slab.toml").read_text()
    text = text.replace('formulation = "node-to-segment"', f'formulation = "{formulation}"')
    text = text.replace("degree = 1 ", f"degree = {degree} ")
    text = text.replace("divisions = [4, 3]", f"divisions = [{4 * refine}, {3 * refine}]")
    x = next(line for line in text.splitlines() if line.startswith("x = "))
    coarse = np.array(json.loads(x[4:]))
    fine = np.interp(np.arange(refine * (len(coarse) - 1) + 1) / refine,
                     np.arange(len(coarse)), coarse)
    text = text.replace(x, f"x = {json.dumps(fine.tolist())}")
    slab = text.index("[bodies.slab]")
    return text[:slab] + text[slab:].replace("y = [-10.0, 0.0]", "y = [-2.5, 0.0]").replace(
        "E = 1.4e6", "E = 1.4e9", 1)


def test_mortar_case_onset_converges_to_the_one_body_blocks_at_second_order(shared_tmp_path):
    """The block-on-slab case with mortar contact of degree 2 on a stiff slab, on the 4 × 3
    and 8 × 6 block: run_case's onsets approach the mesh-converged onset of the one-body Q2
    block on a rigid belt, 0.37046 (docs/block-stability.md: Gauss contact rule, the same on
    8 × 6, 16 × 12 and 32 × 24; another discretisation of the interface, no mortar), from
    above at second order: the error falls by a factor 3-5 from one mesh to the next, and the
    Richardson extrapolation μ₂ + (μ₂ − μ₁)/3 lies within 1e-3 of it (measured 2.6e-4; each
    onset is bisected to 1e-4, and on 8 × 6 and 16 × 12 the extrapolation is within 7e-5, so
    what is left is the next order)."""
    onsets = []
    for refine in (1, 2):
        path = write_case(shared_tmp_path, f"mortar-{refine}.toml",
                          stiff_slab_case("mortar", 2, refine))
        outcome = run_case(read_case(path), shared_tmp_path / f"out-{refine}", COMM)
        assert outcome.exit_code == 0 and len(outcome.onsets) == 1
        onsets.append(outcome.mu_crit)
    converged = 0.37046
    coarse, fine = (mu - converged for mu in onsets)
    assert 0 < fine < coarse and 3 < coarse / fine < 5, onsets
    assert abs(onsets[1] + (onsets[1] - onsets[0]) / 3 - converged) < 1e-3, onsets


def test_the_case_files_contact_formulations_are_the_contacts():
    assert tuple(CONTACT_FORMULATIONS) == FORMULATIONS


def test_steady_states_with_body_contact_keep_the_pairing_they_were_solved_with():
    """Continuation of the block-on-slab case through μ = 0, 0.1, ..., 0.4: each step slides
    the block 4 cm along the slab (μW/K_x per 0.1), past master nodes 12.2 cm apart. A plain
    SteadySolver searches once per solve and converges, at μ = 0.1, to a state whose pairing
    changes when searched again (the pressures 2 % off the consistent state's); the case's
    solver, which solves again until a search keeps the pairing, never does."""
    case = read_case(ROOT / "cases" / "block-on-slab.toml")
    stale = {}
    for name in ("plain", "paired"):
        model = CaseModel(case, COMM)
        model.initial_guess()
        options = {"prefix": f"pairing_{name}_", "options": {"snes_atol": 4.5e-8}}
        solver = (SteadySolver(model.residual, **options) if name == "plain"
                  else SteadySolver(model.residual, search_rounds=SEARCH_ROUNDS, **options))
        (contact,) = model.body_contacts
        records = continuation(solver, model.parameters["mu"], [0.0, 0.1, 0.2, 0.3, 0.4],
                               observe=lambda contact=contact: {"changed": contact.search()})
        stale[name] = [r["value"] for r in records if r["changed"]]
    assert stale["plain"] and not stale["paired"], stale
