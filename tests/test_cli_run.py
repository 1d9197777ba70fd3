"""``fenicsfriction run``: a bad case file is refused with one line naming the file, the key,
its value and what is allowed, exit status 2, before any mesh is built (timed, and the model
builder replaced by one that fails the test if reached); a good one runs and writes its files.
"""

import csv
import json
import math
import pathlib
import time

from mpi4py import MPI

import pytest

from fenicsfriction.case import model as case_model
from fenicsfriction.cli import main

COMM = MPI.COMM_WORLD

#: a small valid case: a square on a belt (2D, one Q1 cell row), steady sliding and CEA
GOOD = """
[model]
dim = 2
degree = 1
[bodies.block]
shape = "rectangle"
size = [2.0, 1.0]
divisions = [4, 2]
nodes_at = [[0.0, 0.5]]
E = 1e3
nu = 0.3
rho = 1.0
[[supports]]
type = "spring"
point = [0.0, 0.5]
component = "x"
stiffness = 10.0
[[loads]]
type = "pressure"
on = "block.ymax"
value = 1.0
[law]
c_n = 1e3
m_n = 1.0
mu = 0.1
eps = 1e-3
[[contacts]]
surface = "block.ymin"
foundation = { normal = [0.0, 1.0] }
[motion]
type = "translation"
velocity = [1.0, 0.0]
[steady]
start = 0.0
stop = 0.2
steps = 2
[cea]
band = [0.0, 100.0]
"""

#: a gmsh file's header as gmsh writes it: the names are all the check reads
MSH = """$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
3
2 1 "pad"
1 2 "friction"
1 3 "back"
$EndPhysicalNames
$Entities
"""

GMSH = GOOD.replace('shape = "rectangle"\nsize = [2.0, 1.0]\ndivisions = [4, 2]\n'
                    'nodes_at = [[0.0, 0.5]]', 'group = "pad"').replace(
    "[bodies.block]", '[mesh]\nfile = "pad.msh"\n[bodies.block]').replace(
    '"block.ymax"', '"back"').replace('"block.ymin"', '"friction"')

#: the square on an elastic base instead of the rigid belt: a body-to-body contact
TWO_BODIES = GOOD.replace('[[contacts]]\nsurface = "block.ymin"\n'
                          'foundation = { normal = [0.0, 1.0] }', """[bodies.base]
shape = "rectangle"
origin = [-1.0, -0.5]
size = [4.0, 0.5]
divisions = [8, 1]
E = 1e3
nu = 0.3
rho = 1.0
[[supports]]
type = "clamped"
on = "base.ymin"
[[contacts]]
slave = "block.ymin"
master = "base.ymax"
""")
MORTAR = TWO_BODIES.replace('master = "base.ymax"',
                            'master = "base.ymax"\nformulation = "mortar"')

#: (what is wrong, the case text, the key the line must name)
BAD = [
    ("unknown key", GOOD.replace("mu = 0.1", "mue = 0.1"), "law.mue"),
    ("missing material", GOOD.replace("rho = 1.0\n", ""), "bodies.block.rho"),
    ("negative modulus", GOOD.replace("E = 1e3", "E = -1e3"), "bodies.block.E"),
    ("non-finite value", GOOD.replace("E = 1e3", "E = inf"), "bodies.block.E"),
    ("Poisson's ratio", GOOD.replace("nu = 0.3", "nu = 0.5"), "bodies.block.nu"),
    ("empty band", GOOD.replace("[0.0, 100.0]", "[100.0, 100.0]"), "cea.band"),
    ("ε above the speed", GOOD.replace("eps = 1e-3", "eps = 2.0"), "law.eps"),
    ("wrong type", GOOD.replace("divisions = [4, 2]", 'divisions = "4x2"'),
     "bodies.block.divisions"),
    ("unknown side", GOOD.replace('"block.ymin"', '"block.bottom"'), "contacts[0].surface"),
    ("law's own range", GOOD.replace("m_n = 1.0", "m_n = 0.5"), "law.m_n"),
    ("parameter's range", GOOD.replace("start = 0.0", "start = -0.1"), "steady.values"),
    ("group not in the mesh", GMSH.replace('group = "pad"', 'group = "pads"'),
     "bodies.block.group"),
    ("cell group as a contact surface", GMSH.replace('"friction"', '"pad"'),
     "contacts[0].surface"),
    ("facet group as a body in 2D", GMSH.replace('group = "pad"', 'group = "back"'),
     "bodies.block.group"),
    ("unknown contact formulation", MORTAR.replace('"mortar"', '"nitsche"'),
     "contacts[0].formulation"),
    ("degree 2 with node-to-segment contact", TWO_BODIES.replace("degree = 1", "degree = 2"),
     "contacts[0].formulation"),
    ("degree 3 with mortar contact", MORTAR.replace("degree = 1", "degree = 3"),
     "model.degree"),
]


@pytest.fixture
def no_model(monkeypatch):
    """Building a model fails the test: a bad case must be refused before."""
    def refuse(*args, **kwargs):
        raise AssertionError("a model was built from a bad case file")
    monkeypatch.setattr(case_model.CaseModel, "__init__", refuse)


def write(folder: pathlib.Path, text: str) -> pathlib.Path:
    if COMM.rank == 0:
        (folder / "pad.msh").write_text(MSH)
        (folder / "case.toml").write_text(text)
    COMM.Barrier()
    return folder / "case.toml"


@pytest.mark.parametrize(("what", "text", "key"), BAD, ids=[b[0] for b in BAD])
def test_a_bad_case_file_gives_one_line_and_status_2_before_any_mesh(
        shared_tmp_path, capsys, no_model, what, text, key):
    path = write(shared_tmp_path, text)
    start = time.perf_counter()
    code = main(["run", str(path), "--out", str(shared_tmp_path / "out")])
    seconds = time.perf_counter() - start
    assert code == 2 and seconds < 2.0, (code, seconds)
    lines = [line for line in capsys.readouterr().err.splitlines() if "error" in line]
    if COMM.rank == 0:
        assert len(lines) == 1, lines
        assert lines[0].startswith(f"fenicsfriction: error: {path}: {key}="), lines[0]
        assert "invalid: " in lines[0]
    else:
        assert not lines


def test_an_unknown_key_is_answered_with_the_closest_valid_one(shared_tmp_path, capsys,
                                                               no_model):
    path = write(shared_tmp_path, GOOD.replace("mu = 0.1", "mue = 0.1"))
    assert main(["run", str(path), "--out", str(shared_tmp_path / "out")]) == 2
    if COMM.rank == 0:
        assert "did you mean 'mu'?" in capsys.readouterr().err


def test_a_good_case_runs_and_writes_its_files(shared_tmp_path):
    """The square presses with the pressure 1 on its top: the normal force is 2 (its width),
    the friction force μ N at each step (the slip speed 1 >> ε)."""
    out = shared_tmp_path / "out"
    assert main(["run", str(write(shared_tmp_path, GOOD)), "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "done" and summary["parameter"] == "mu"
    for mu, row in zip((0.0, 0.1, 0.2), summary["steady"], strict=True):
        assert row["contact0_normal_force"] == pytest.approx(2.0, rel=1e-8)
        assert row["contact0_friction_force_x"] == pytest.approx(mu * 2.0, rel=1e-8, abs=1e-12)
    for name in ("steady.csv", "cea.csv", "steady.xdmf", "loci.png", "coupling_map.png",
                 "continuation.png"):
        assert (out / name).stat().st_size > 0, name
    # cea.csv's columns are what their names say: f = Im λ / 2π, ζ = -Re λ / |λ| (the pair
    # that couples by μ = 0.2 has Re λ = ±0.2 1/s, so the sign of ζ is checked)
    with open(out / "cea.csv") as f:
        rows = list(csv.DictReader(f))
    damped = 0
    for row in rows:
        lam = complex(float(row["re"]), float(row["im"]))
        assert float(row["frequency_hz"]) == pytest.approx(lam.imag / (2 * math.pi), rel=1e-14)
        assert float(row["damping_ratio"]) == pytest.approx(-lam.real / abs(lam), rel=1e-14,
                                                            abs=1e-300)
        damped += abs(lam.real) > 1e-3 * abs(lam)
    assert damped >= 2
