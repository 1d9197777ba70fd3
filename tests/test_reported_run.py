"""``fenicsfriction run CASE``: every figure of ``summary.json``, ``steady.csv``, ``cea.csv`` and
``transient.csv`` checked for what its name says. There is one run for the module: a square
block pressed on a belt, with a steady continuation in μ, the CEA and a short transient.
Figures are recomputed from the tables, or compared with closed forms: the pressure's
resultant, Coulomb's friction, the driver spring's rigid-body frequency and the growth
exp(Re λ t) of an unstable mode. The lines the run logs are parsed and compared with the
files, and its closing line with the folder. The audit table is in docs/verification.md,
under "Reported figures".
"""

import csv
import json
import pathlib
import re
import time

from mpi4py import MPI

import numpy as np
import pytest
from capture import logged_lines, shared_folder, xdmf_nodes

from fenicsfriction.cli import main

COMM = MPI.COMM_WORLD

#: a 2 × 1 block (ρ = 1: mass 2 per unit breadth) held by a spring k = 10 at its left edge,
#: pressed by p = 1 on a belt moving at 1; μ from 0 to 0.2 in 2 steps; the CEA; a transient
#: of 100 steps (ω dt = 0.08 for the unstable pair at 160 rad/s)
CASE = """
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
onset_tol = 1e-2
[transient]
amplitude = 1e-6
t_end = 0.05
dt = 5e-4
stride = 1000
"""


def _table(path: pathlib.Path) -> list[dict[str, str]]:
    with path.open() as table:
        return list(csv.DictReader(table))


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = shared_folder(tmp_path_factory, "run")
    case = folder / "square.toml"
    if COMM.rank == 0:
        case.write_text(CASE)
    COMM.Barrier()
    start = time.perf_counter()
    with logged_lines() as lines:
        assert main(["run", str(case), "--out", str(folder / "out")]) == 0
    elapsed = time.perf_counter() - start
    out = folder / "out"
    if COMM.rank == 0:
        (out / "lines.json").write_text(json.dumps(lines))
    COMM.Barrier()
    return json.loads((out / "summary.json").read_text()), out, elapsed


def test_summary_heading_and_steady_path(run):
    summary, out, elapsed = run
    assert (summary["status"], summary["exit_code"], summary["failure"],
            summary["interrupted"]) == ("done", 0, None, None)
    assert summary["title"] == "square" and summary["parameter"] == "mu"
    assert pathlib.Path(summary["case"]).name == "square.toml"
    assert 0 < summary["wall_time_s"] < elapsed
    rows = _table(out / "steady.csv")
    assert len(rows) == len(summary["steady"]) == 3
    for mu, row, record in zip((0.0, 0.1, 0.2), rows, summary["steady"], strict=True):
        assert float(row["mu"]) == record["mu"] == pytest.approx(mu, abs=1e-15)
        for key, value in record.items():  # the table is the summary's rows
            assert float(row[key]) == pytest.approx(value, rel=1e-15, abs=1e-300)
        # the pressure 1 on the top, 2 wide, is carried by the belt; the belt slides at 1 ≫ ε
        # under the whole base: Coulomb's μ N along the belt's motion
        assert record["contact0_normal_force"] == pytest.approx(2.0, rel=1e-8)
        assert record["contact0_friction_force_x"] == pytest.approx(2.0 * mu, rel=1e-8,
                                                                   abs=1e-12)
        assert record["contact0_friction_force_y"] == 0.0


def test_cea_table_and_onset_are_what_they_say(run):
    summary, out, _ = run
    rows = _table(out / "cea.csv")
    steps = summary["cea"]
    assert len(rows) == sum(len(s["modes"]) for s in steps)
    by_step = iter(rows)
    for step in steps:
        res = []
        for mode in step["modes"]:
            row = next(by_step)
            assert float(row["mu"]) == step["mu"] and int(row["mode"]) == mode["mode"]
            re, im = float(row["re"]), float(row["im"])
            assert (re, im) == (mode["re"], mode["im"])
            # the frequency is Im λ / 2π, the damping ratio -Re λ / |λ|
            assert float(row["frequency_hz"]) == pytest.approx(im / (2 * np.pi), rel=1e-12)
            assert float(row["damping_ratio"]) == pytest.approx(-re / abs(complex(re, im)),
                                                                rel=1e-12, abs=1e-300)
            assert float(row["residual"]) == mode["residual"] and row["accurate"] == "True"
            res.append(re)
        assert step["max_re"] == max(res)
        # the band: every kept eigenvalue below 2π · 100 Hz
        assert all(0 <= m["im"] <= 2 * np.pi * 100 for m in step["modes"])
    # μ = 0: the lowest mode is the block on its spring, nearly rigid: ω² = k/m = 10/2 (the
    # block's own compliance, E = 1e3 in series with k = 10, softens it by about 1 %)
    lowest = min(m["im"] for m in steps[0]["modes"])
    assert lowest == pytest.approx(np.sqrt(10.0 / 2.0), rel=0.02)
    # the onset: bisected to onset_tol (1e-2) between the grid steps that bracket it; the
    # eigenvalue there grows (Re λ > growth_tol |λ|, 1e-6) and its frequency lies between
    # the two colliding modes' on the stable side
    onset = summary["onsets"][0]
    low, high = onset["interval"]
    assert high - low <= 1e-2 and low <= onset["mu_crit"] <= high
    assert summary["mu_crit"] == onset["mu_crit"]
    grid = [s["mu"] for s in steps]
    assert any(a <= low and high <= b for a, b in zip(grid[:-1], grid[1:], strict=True))
    re, im = onset["value"]
    assert re > 1e-6 * abs(complex(re, im))
    frequencies = sorted(c["im"] for c in onset["colliding"])
    assert frequencies[0] <= im <= frequencies[1]


def test_transient_grows_at_re_lambda_and_its_rate_is_the_tables(run):
    summary, out, _ = run
    transient = summary["transient"]
    rows = _table(out / "transient.csv")
    t = np.array([float(r["time"]) for r in rows])
    amplitude = np.array([float(r["amplitude"]) for r in rows])
    assert transient["steps"] == len(rows) - 1 == 100
    np.testing.assert_allclose(transient["time"], t, rtol=1e-15)
    np.testing.assert_allclose(transient["amplitude"], amplitude, rtol=1e-15)
    # started at the last steady value, from its most unstable mode, at the amplitude asked
    last = summary["cea"][-1]
    assert transient["at"] == last["mu"] == 0.2
    top = max(last["modes"], key=lambda m: m["re"])
    # (solved again at that value: the same to round-off)
    assert transient["eigenvalue"] == pytest.approx([top["re"], top["im"]], rel=1e-9)
    assert transient["growth_rate_re_lambda"] == transient["eigenvalue"][0]
    assert amplitude[0] == pytest.approx(1e-6, rel=1e-9)
    # the measured rate: the least-squares slope of log(amplitude) over the second half
    late = t >= 0.5 * t[-1]
    slope = np.polyfit(t[late], np.log(amplitude[late]), 1)[0]
    assert transient["growth_rate_measured"] == pytest.approx(slope, rel=1e-9)
    # and the mode grows like exp(Re λ t): generalized-α at ω dt = 0.08 errs by O((ω dt)²)
    # (measured: the rate 1.6e-3 low, the amplitude within 1.6e-5 of the exponential)
    assert transient["growth_rate_measured"] == pytest.approx(top["re"], rel=1e-2)
    np.testing.assert_allclose(amplitude, 1e-6 * np.exp(top["re"] * t), rtol=1e-4)


#: a number as the progress lines print it
VALUE = r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?"
#: one standing alone (not inside a word, such as the 0 of contact0)
NUMBER = r"(?<![\w.])" + VALUE


def test_headline_lines_say_what_the_files_hold(run):
    """What ``run`` logs: the first line the unknowns (two per node of the mesh in
    steady.xdmf, counted there) and the ranks; one line per μ with the steady row's forces, the
    CEA's mode count, max Re λ and the growing modes (Re λ > growth_tol |λ|, recounted from
    the modes); the onset line the first onset's μ, λ, its frequency Im λ/2π and the colliding
    modes; the transient's first sample and its two rates; the closing line the files, each
    of which exists. Each figure is compared at the digits printed."""
    summary, out, elapsed = run
    if COMM.rank != 0:  # rank 0 logs, the others do not
        return
    lines = json.loads((out / "lines.json").read_text())
    first = lines[0]
    assert first.startswith(f"square: {2 * xdmf_nodes(out / 'steady.xdmf')} dofs on {COMM.size} "
                            "rank(s), JIT ")
    assert 0 < float(re.findall(NUMBER, first)[-1]) < summary["wall_time_s"] < elapsed
    steps = [x for x in lines if x.startswith("step ")]
    assert len(steps) == len(summary["cea"]) == len(summary["steady"]) == 3
    for k, (line, row, step) in enumerate(zip(steps, summary["steady"], summary["cea"],
                                              strict=True)):
        assert line.startswith(f"step {k:3d}/2  mu=")
        numbers = dict(re.findall(rf"(\w+)=({VALUE})", line))
        assert float(numbers["mu"]) == pytest.approx(row["mu"], abs=1e-6)
        for key in ("contact0_normal_force", "contact0_friction_force_x"):
            assert float(numbers[key]) == pytest.approx(row[key], rel=5e-4, abs=1e-12)
        assert f"  {len(step['modes'])} modes  " in line
        assert float(line.split("max Re λ=")[1].split()[0]) == pytest.approx(step["max_re"],
                                                                              rel=5e-4)
        growing = [m["mode"] for m in step["modes"]
                   if m["re"] > 1e-6 * abs(complex(m["re"], m["im"]))]
        assert line.endswith(f"growing: {growing}")
    assert growing  # the last step grows: the onset lies before it
    onset = summary["onsets"][0]
    re_, im = onset["value"]
    (line,) = [x for x in lines if x.startswith("onset at ")]
    mu, lam_re, lam_im, hz, *modes = (float(v) for v in re.findall(NUMBER, line))
    assert (mu, lam_re, lam_im) == pytest.approx((onset["mu_crit"], re_, im), rel=5e-4)
    assert hz == pytest.approx(im / (2 * np.pi), rel=1e-5)
    assert modes == [c["mode"] for c in onset["colliding"]]
    transient = summary["transient"]
    samples = [x for x in lines if x.startswith("t=")]  # every stride (1000) steps: the first
    assert len(samples) == 1
    t0, amplitude = (float(v) for v in re.findall(NUMBER, samples[0]))
    assert (t0, amplitude) == pytest.approx((transient["time"][0], transient["amplitude"][0]),
                                            rel=5e-4, abs=1e-12)
    (line,) = [x for x in lines if x.startswith("transient: measured growth rate")]
    measured, re_lambda = (float(v) for v in re.findall(NUMBER + r"(?= 1/s)", line))
    assert (measured, re_lambda) == pytest.approx(
        (transient["growth_rate_measured"], transient["growth_rate_re_lambda"]), rel=5e-5)
    closing = lines[-1]
    assert closing.startswith(f"results in {out}/: ")
    listed = set(closing.split(": ", 1)[1].split(", "))
    # every file written is listed (an XDMF file's heavy data beside it), and none else
    heavy = {name.replace(".xdmf", ".h5") for name in listed if name.endswith(".xdmf")}
    assert {p.name for p in out.iterdir()} - {"lines.json"} == listed | heavy
