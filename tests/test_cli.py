"""The command line: results written as documented, user errors as one line and exit 2."""

import json
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import tempfile
import time

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest
from cli_errors import assert_one_error_line
from scipy.integrate import trapezoid

from fenicsfriction.cli import main

REQUIRED = {"mu", "normal_force", "friction_force", "spring_force", "centre_of_pressure",
            "min_penetration", "max_penetration", "newton_iterations", "residual_norm",
            "wall_time_s"}


@pytest.fixture
def out_dir() -> pathlib.Path:
    """One folder for all ranks, made by rank 0 (pytest's tmp_path rotation is per process)."""
    comm = MPI.COMM_WORLD
    path = pathlib.Path(comm.bcast(tempfile.mkdtemp(prefix="ff-cli-") if comm.rank == 0 else None))
    yield path / "out"
    comm.Barrier()
    if comm.rank == 0:
        shutil.rmtree(path, ignore_errors=True)


def test_steady_cli_writes_one_balanced_record_per_step(out_dir):
    code = main(["block", "steady", "--mu-max", "0.9", "--steps", "6", "--out", str(out_dir),
                 "--snapshots", "2"])
    assert code == 0
    records = json.loads((out_dir / "steady.json").read_text())
    assert isinstance(records, list) and len(records) == 7
    for r in records:
        assert set(r) >= REQUIRED
        # statics of the block against its data (Newton stops at ~1e-7 of the load, see
        # SteadySolver): the belt carries the weight W = 450, and the spring, read from its
        # node's displacement, holds μ W back; friction balances the spring
        assert r["normal_force"] == pytest.approx(450.0, rel=1e-6)
        assert r["spring_force"] == pytest.approx(-r["mu"] * 450.0, rel=1e-6, abs=1e-6)
        assert r["spring_force"] == pytest.approx(-r["friction_force"], rel=1e-6, abs=1e-6)
        assert r["centre_of_pressure"] == pytest.approx(-r["mu"] * 30.5 / 2, rel=1e-5, abs=1e-6)
    assert np.allclose([r["mu"] for r in records], np.linspace(0, 0.9, 7))
    summary = json.loads((out_dir / "summary.json").read_text())
    assert summary["failure"] is None and summary["tipping_limit"] == pytest.approx(1.6)
    # the BLAS the run used is recorded, read from the libraries the process mapped
    environment = summary["environment"]
    assert environment["ranks"] == MPI.COMM_WORLD.size
    assert environment["blas"]["paths"] and environment["blas"]["name"] != "unknown"
    assert environment["versions"]["petsc"].startswith(("3.", "4."))
    for name in ("steady.xdmf", "steady.h5", "deformed.png", "forces.png"):
        assert (out_dir / name).stat().st_size > 0, name


def test_stability_cli_writes_tracked_loci_and_both_onsets(out_dir):
    code = main(["block", "stability", "--mu-max", "0.6", "--steps", "6", "--out", str(out_dir),
                 "--onset-tol", "1e-3"])
    assert code == 0
    data = json.loads((out_dir / "stability.json").read_text())
    assert [s["mu"] for s in data["fe"]["steps"]] == pytest.approx(np.linspace(0, 0.6, 7))
    for step in data["fe"]["steps"]:
        assert step["modes"] and all({"mode", "re", "im", "residual", "accurate"} <= set(m)
                                     for m in step["modes"])
        assert all(m["accurate"] for m in step["modes"])
    # flutter of the normal/rotational pair: FE and rigid onsets lie between the grid
    # points that bracket them (0.3 stable, 0.4 unstable for FE; 0.4 and 0.5 for rigid)
    assert 0.3 < data["mu_crit"]["fe"] < 0.4 and 0.4 < data["mu_crit"]["rigid"] < 0.5
    # the block's elasticity softens the normal/rotation pair, so the FE block flutters before
    # the rigid one, by a few hundredths of μ (0.370 against 0.404, docs/block-stability.md)
    assert 0.02 < data["mu_crit"]["rigid"] - data["mu_crit"]["fe"] < 0.05
    onset = data["fe"]["onsets"][0]
    assert onset["interval"][1] - onset["interval"][0] <= 1e-3
    assert len({c["mode"] for c in onset["colliding"]}) == 2
    for name in ("loci.png", "growth.png", "unstable_modes.xdmf", "unstable_modes.h5"):
        assert (out_dir / name).stat().st_size > 0, name


def test_dynamics_cli_writes_a_time_series_whose_energy_balance_closes(out_dir):
    code = main(["block", "dynamics", "--mu", "0.6", "--t-end", "5e-4", "--dt", "1e-5",
                 "--b-n", "0.381e10", "--out", str(out_dir), "--stride", "25"])
    assert code == 0
    import csv
    rows = list(csv.DictReader((out_dir / "timeseries.csv").open()))
    assert len(rows) == 51
    assert {"time", "dt", "normal_force", "friction_force", "spring_force", "n_stick",
            "n_slip", "n_open", "energy_error"} <= set(rows[0])
    kinetic = max(float(r["kinetic_energy"]) for r in rows)
    # generalized-α is second order: (ω dt)² ~ 3e-3 of the oscillation's energy at most
    assert max(abs(float(r["energy_error"])) for r in rows) < 3e-3 * kinetic
    # momentum balance along the belt, M Δv_xG = ∫ (F_T + F_s) dt (trapezoidal rule, exact to
    # O(dt²) for the midpoint rule the scheme reduces to): independent of how F_T is integrated
    time = np.array([float(r["time"]) for r in rows])
    force = np.array([float(r["friction_force"]) + float(r["spring_force"]) for r in rows])
    impulse = trapezoid(force, time)
    change = 0.45 * (float(rows[-1]["v_xG"]) - float(rows[0]["v_xG"]))
    assert impulse == pytest.approx(change, abs=1e-2 * trapezoid(np.abs(force), time))
    damped = 0
    for r in rows:  # sliding everywhere: the perturbation is far from sticking
        assert int(r["n_slip"]) == 9 and int(r["n_stick"]) == int(r["n_open"]) == 0
        # the normal damping b_n d^{l_n} u̇_n adds to N while the block moves
        damped += abs(float(r["normal_force"]) - float(r["normal_force_elastic"])) > 1e-3
    assert damped > len(rows) // 2  # the damping part is present while the block moves
    _summary_is_what_its_names_say(out_dir, rows, mu=0.6)


def _summary_is_what_its_names_say(out_dir: pathlib.Path, rows: list[dict], mu: float) -> None:
    """Every figure of ``block dynamics``'s summary.json recomputed from timeseries.csv by its
    definition (statistics over the second half, time means by the trapezoidal rule), and
    the table's derived columns from their own definitions."""
    summary = json.loads((out_dir / "summary.json").read_text())
    table = {key: np.array([float(r[key]) for r in rows]) for key in rows[0]}
    t = table["time"]
    assert summary["failure"] is None and summary["interrupted"] is None
    assert summary["steps"] == len(rows) - 1 and summary["dt"] == 1e-5
    parameters = summary["parameters"]
    assert parameters["law"]["mu"] == mu
    # the table: the spring's elongation is −F_s/K_x; every base node open, stuck or slipping
    np.testing.assert_allclose(table["spring_elongation"],
                               -table["spring_force"] / parameters["K_x"], rtol=1e-12)
    counts = table["n_open"] + table["n_stick"] + table["n_slip"]
    assert np.all(counts == counts[0]) and counts[0] == 9  # 2 × 4 Q2 facets + 1
    # sliding at |slip| ≫ ε: the friction force is μ times the compliance's (elastic) normal
    # force, the damping adding to N only (regularisation |w|/√(w² + ε²): below 1e-6 here)
    np.testing.assert_allclose(np.abs(table["friction_force"]),
                               mu * table["normal_force_elastic"], rtol=1e-4)
    stats = summary["statistics"]
    window = t >= 0.5 * t[-1]
    tw = t[window]

    def mean(values):
        return trapezoid(values[window], tw) / (tw[-1] - tw[0])

    assert (stats["t_from"], stats["t_to"], stats["mu"]) == (tw[0], tw[-1], mu)
    N, F = mean(table["normal_force"]), mean(table["friction_force"])
    assert stats["mean_normal_force"] == pytest.approx(N, rel=1e-12)
    assert stats["mean_friction_force"] == pytest.approx(F, rel=1e-12)
    assert stats["normal_force_range"] == [table["normal_force"][window].min(),
                                           table["normal_force"][window].max()]
    assert stats["apparent_coefficient"] == pytest.approx(abs(F) / N, rel=1e-12)
    assert stats["ratio_to_mu"] == pytest.approx(abs(F) / N / mu, rel=1e-12)
    in_contact = table["probe_pressure"] > 0
    sticks = in_contact & (np.abs(table["probe_slip"]) < stats["eps"])
    assert stats["probe_stick_fraction"] == pytest.approx(mean(sticks.astype(float)), abs=1e-12)
    assert stats["probe_open_fraction"] == pytest.approx(mean((~in_contact).astype(float)),
                                                         abs=1e-12)
    assert stats["any_stick_fraction"] == pytest.approx(mean((table["n_stick"] > 0) * 1.0),
                                                        abs=1e-12)
    assert stats["probe_longest_stick"] == 0.0 and not sticks[window].any()  # all sliding
    elongation = table["spring_elongation"]
    assert stats["spring_elongation"] == pytest.approx(
        {"start": elongation[window][0], "end": elongation[-1], "mean": mean(elongation)},
        rel=1e-12)
    assert stats["max_energy_error"] == pytest.approx(np.abs(table["energy_error"]).max(),
                                                      rel=1e-12)
    assert stats["duration"] == pytest.approx(t[-1] - t[0], rel=1e-12)
    assert stats["steps"] == len(rows) - 1
    assert stats["newton_iterations"] == table["newton_iterations"].sum()
    assert stats["rejected_steps"] == table["rejected_steps"].sum()


def test_dynamics_beyond_the_tipping_limit_is_refused_in_one_line_before_any_work(tmp_path,
                                                                                   capsys):
    """μ = 2 > 1.5625: the block would tip, no steady sliding exists to start from. The limit
    is the moment balance about the outermost contact point, μ W h_s = W (L/2 − s_1), with
    s_1 the inset of the contact rule's first point: the 5-point Gauss-Legendre rule's
    tabulated node ±0.9061798459, so s_1 = (1 − 0.9061798459)/2 of the L/4 facet."""
    L, h_s = 48.8, 30.5 / 2
    limit = (L / 2 - (1 - 0.9061798459) / 2 * L / 4) / h_s
    for mu in ("2.0", "1.58"):  # 1.58: past the mesh's limit, short of L/(2 h_s) = 1.6
        out = tmp_path / f"tipped-{mu}"
        assert main(["block", "dynamics", "--mu", mu, "--t-end", "1e-3", "--out",
                     str(out)]) == 2
        err = capsys.readouterr().err
        assert_one_error_line(err, "--mu")
        if MPI.COMM_WORLD.rank == 0:
            assert f"--mu={mu}" in err and f"{limit:.6g}" in err
        assert not out.exists()  # refused before the output folder, the mesh and the solves


def test_steady_cli_stops_at_discrete_tipping_limit_and_reports_it(out_dir):
    """Beyond μ = L/H no steady state exists: exit 1, converged steps kept, no hang."""
    code = main(["block", "steady", "--mu-max", "1.7", "--steps", "2", "--out", str(out_dir),
                 "--max-halvings", "3", "--snapshots", "0"])
    assert code == 1
    summary = json.loads((out_dir / "summary.json").read_text())
    assert "continuation failed" in summary["failure"]
    assert 0.85 <= summary["mu_last_converged"] < 1.6
    assert len(json.loads((out_dir / "steady.json").read_text())) == 2  # μ = 0 and 0.85


@pytest.mark.parametrize(("flag", "value", "name"), [("--mu-max", "-1", "--mu-max"),
                                             ("--refine", "0", "refine"),
                                             ("--belt-direction", "2", "belt_direction"),
                                             ("--eps", "0", "eps")])
def test_bad_parameter_value_is_reported_by_name(out_dir, capsys, flag, value, name):
    args = ["block", "steady", "--mu-max", "0.5", "--steps", "2", "--out", str(out_dir)]
    args += [flag, value]
    assert main(args) == 2
    err = capsys.readouterr().err
    if MPI.COMM_WORLD.rank == 0:
        assert name in err and value in err


def test_a_runs_petsc_options_end_with_it(out_dir):
    """The PETSc options on a command line are that run's: called in-process (a notebook, a
    test), the database afterwards is the one before, an option the run overrode back at its
    old value and one it added gone, whether the run succeeds or stops on a user error."""
    opts = PETSc.Options()
    opts["steady_snes_rtol"] = "1e-11"  # the process's own, set before the run
    try:
        for extra, code in (([], 0), (["--steps", "0"], 2)):
            argv = ["block", "steady", "--mu-max", "0.3", "--steps", "2", "--out",
                    str(out_dir), *extra, "-steady_snes_rtol", "1e-12",
                    "-steady_snes_max_it", "40"]
            assert main(argv) == code
            assert opts.getString("steady_snes_rtol") == "1e-11"
            assert not opts.hasName("steady_snes_max_it")
    finally:
        opts.delValue("steady_snes_rtol")


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1,
                    reason="starts its own interpreter; runs in the serial pass")
@pytest.mark.parametrize("args", [["--mu-max", "-1"], ["--mu-max", "abc"], ["--steps", "0"],
                                  ["--regularisation", "tanh"]])
def test_user_error_prints_one_line_without_traceback(tmp_path, args):
    cmd = [sys.executable, "-m", "fenicsfriction", "block", "steady", "--mu-max", "0.5",
           "--out", str(tmp_path), *args]
    result = subprocess.run(cmd, capture_output=True, text=True, timeout=120, env=_environment())
    assert result.returncode == 2
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    assert "Traceback" not in result.stderr and args[1] in lines[0]


def _environment() -> dict:
    """The environment of a child interpreter: without the MPI launcher's variables."""
    return {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}


def _rows(path: pathlib.Path) -> int:
    return max(len(path.read_text().splitlines()) - 1, 0) if path.exists() else 0


def _interrupt(cmd: list[str], table: pathlib.Path, signum: int, rows: int = 5,
               timeout: float = 300.0) -> subprocess.CompletedProcess:
    """Start ``cmd``, wait for ``rows`` rows in ``table``, send ``signum``, wait for the end."""
    process = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env=_environment())
    start = time.monotonic()
    while _rows(table) < rows and process.poll() is None:
        assert time.monotonic() - start < timeout, "no rows written"
        time.sleep(0.2)
    assert process.poll() is None, process.communicate()
    process.send_signal(signum)
    out, err = process.communicate(timeout=120)
    return subprocess.CompletedProcess(cmd, process.returncode, out, err)


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1,
                    reason="starts its own interpreter; runs in the serial pass")
def test_interrupted_dynamics_keeps_every_step_and_exits_130(tmp_path):
    """Ctrl-C in a long run: the rows computed so far, a summary saying where it stopped, one
    line on stderr and status 130 (what a shell reports for SIGINT)."""
    cmd = [sys.executable, "-m", "fenicsfriction", "block", "dynamics", "--mu", "0.6",
           "--belt-speed", "0.08", "--t-end", "0.2", "--out", str(tmp_path)]
    result = _interrupt(cmd, tmp_path / "timeseries.csv", signal.SIGINT)
    assert result.returncode == 130, result.stderr
    assert "Traceback" not in result.stderr
    last = result.stderr.strip().splitlines()[-1]
    assert "interrupted by SIGINT" in last and "t = " in last
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["interrupted"].startswith("interrupted by SIGINT")
    rows = _rows(tmp_path / "timeseries.csv")
    assert rows >= 5 and summary["steps"] == rows - 1
    assert (tmp_path / "dynamics.xdmf").stat().st_size > 0


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1,
                    reason="starts its own interpreter; runs in the serial pass")
@pytest.mark.parametrize("scene", [["slider", "--t-end", "2000"], ["belt", "--t-end", "1e7"]])
def test_terminated_oscillator_keeps_its_samples_and_exits_143(tmp_path, scene):
    cmd = [sys.executable, "-m", "fenicsfriction", "oscillators", *scene, "--out", str(tmp_path)]
    result = _interrupt(cmd, tmp_path / "timeseries.csv", signal.SIGTERM, rows=50)
    assert result.returncode == 143, result.stderr
    assert "Traceback" not in result.stderr
    # progress lines, then one line saying where it stopped
    stops = [line for line in result.stderr.splitlines() if "interrupted" in line]
    assert len(stops) == 1 and stops[0] == result.stderr.strip().splitlines()[-1]
    assert "interrupted by SIGTERM" in stops[0] and "t = " in stops[0]
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["samples"] == _rows(tmp_path / "timeseries.csv") >= 50
    assert 0 < summary["t_end"] < float(scene[-1])


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1,
                    reason="starts its own interpreter; runs in the serial pass")
@pytest.mark.parametrize("command", [["block", "steady", "--mu-max", "0.5"],
                                     ["block", "dynamics", "--mu", "0.5", "--t-end", "1e-3"],
                                     ["oscillators", "belt"]])
@pytest.mark.parametrize("where", ["under a file", "/proc"])
def test_unwritable_output_folder_is_one_line_and_exit_2(tmp_path, command, where):
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    out = blocker / "out" if where == "under a file" else pathlib.Path("/proc/ff-cli-test")
    cmd = [sys.executable, "-m", "fenicsfriction", *command, "--out", str(out)]
    result = subprocess.run(cmd, capture_output=True, text=True, timeout=120, env=_environment())
    assert result.returncode == 2
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "--out=" in lines[0] and "Traceback" not in result.stderr


#: commands of the old grammar (COMMAND SCENE) and the new spelling the hint must name
OLD_SPELLINGS = [
    (["steady", "block", "--mu-max", "1"], "'steady block' is now 'block steady'"),
    (["stability", "block-on-slab", "--mu-max", "1"],
     "'stability block-on-slab' is now 'block stability --scene block-on-slab'"),
    (["dynamics", "block", "--mu", "0.6"], "'dynamics block' is now 'block dynamics'"),
    (["stability-map", "mdof", "--omega-range", "30:34"],
     "'stability-map mdof' is now 'oscillators slider-map'"),
    (["oscillator", "mdof"], "'oscillator mdof' is now 'oscillators slider'"),
    (["oscillator", "belt"], "'oscillator belt' is now 'oscillators belt'"),
    (["interface", "eq", "--N", "400"], "'interface eq' is now 'multicontact eq'"),
    (["steady"], "'steady ...' is now 'block steady' or 'block steady --scene block-on-slab'")]


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1,
                    reason="starts its own interpreter; runs in the serial pass")
@pytest.mark.parametrize(("argv", "hint"), OLD_SPELLINGS)
def test_old_spelling_prints_the_new_one_in_one_line_and_exits_2(tmp_path, argv, hint):
    result = subprocess.run([sys.executable, "-m", "fenicsfriction", *argv, "--out",
                             str(tmp_path)], capture_output=True, text=True, timeout=60,
                            env=_environment())
    assert result.returncode == 2
    assert result.stderr.splitlines() == [f"fenicsfriction: {hint}"], result.stderr
    assert not (tmp_path / "summary.json").exists()  # nothing ran


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1,
                    reason="starts its own interpreter; runs in the serial pass")
@pytest.mark.parametrize(("argv", "flag", "value"), [
    (["block", "steady", "--mu-max", "1", "--scene", "slab"], "--scene", "slab"),
    (["block", "dynamics", "--mu", "0.6", "--t-end", "1e-3", "--scheme", "rk4"], "--scheme",
     "rk4"),
    (["oscillators", "belt", "--law", "coulomb"], "--law", "coulomb"),
    (["oscillators", "slider-map", "--omega-range", "30"], "--omega-range", "30"),
    (["contact", "cattaneo", "--penalty-T", "soft"], "--penalty-T", "soft"),
    (["rolling", "curve", "--xi-range", "0:1", "--a", "1", "--G", "1", "--nu", "0.3", "--mu",
      "0.3", "--Fn", "1"], "--xi-range", "0:1"),
    (["multicontact", "eq", "--N", "many"], "--N", "many")])
def test_bad_flag_value_names_the_flag_in_one_line_and_exits_2(tmp_path, argv, flag, value):
    result = subprocess.run([sys.executable, "-m", "fenicsfriction", *argv, "--out",
                             str(tmp_path)], capture_output=True, text=True, timeout=60,
                            env=_environment())
    assert result.returncode == 2
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in result.stderr, result.stderr
    assert flag in lines[0] and value in lines[0], lines[0]


def test_pop_penalty_is_the_flag_penalty_T_not_eps_T(out_dir):
    """ε names the regularisation only: the old flag of Pop's tangential penalty is refused."""
    with pytest.raises(SystemExit) as stop:
        main(["contact", "cattaneo", "--eps-T", "1e4", "--out", str(out_dir)])
    assert stop.value.code == 2


SOLVERS = ("dolfinx", "mpi4py.MPI", "petsc4py.PETSc")


@pytest.mark.parametrize(("argv", "not_imported"), [
    (["--help"], (*SOLVERS, "scipy")),
    (["block", "steady", "--mu-max", "x", "--out", "o"], (*SOLVERS, "scipy")),
    (["block", "stability", "--help"], (*SOLVERS, "scipy")),
    (["oscillators", "belt"], (*SOLVERS, "scipy")),
    # checking a reading loads the slider's model (NumPy, SciPy) but no solver
    (["oscillators", "slider", "--reading", "nope", "--out", "o"], SOLVERS)])
def test_help_and_flag_errors_import_no_solver(argv, not_imported):
    """``--help`` and a flag error are answered by argparse alone: neither MPI, PETSc nor
    dolfinx is imported (each costs tenths of a second), so they return at once."""
    script = ("import sys\nfrom fenicsfriction.cli import main\ntry:\n"
              f"    main({argv!r})\nexcept SystemExit as stop:\n    code = stop.code\n"
              f"print([m for m in {not_imported!r} if m in sys.modules], code)")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=60)
    assert done.stdout.splitlines()[-1] == f"[] {0 if '--help' in argv else 2}", done.stderr
