"""No command ends in a traceback or eats the memory: solver failures in every stage exit 1
with one line saying where, signals from the first line of ``main`` exit 130/143 with a
summary, progress on stdout and the one closing line on stderr, ``--record-every`` with
statistics streamed over every step, and a quiet just-in-time compiler under ``mpirun``."""

import csv
import json
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import time

from mpi4py import MPI

import numpy as np
import pytest
from scipy.integrate import trapezoid

from fenicsfriction.cli import main
from fenicsfriction.results import RunningStatistics, SampledRecords

serial_only = pytest.mark.skipif(MPI.COMM_WORLD.size > 1,
                                 reason="starts its own interpreter; runs in the serial pass")


def _environment(**extra: str) -> dict:
    """A child interpreter's environment: without the MPI launcher's variables."""
    return {**{k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))},
            **extra}


def _run(args: list[str]) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "fenicsfriction", *args], capture_output=True,
                          text=True, timeout=300, env=_environment())


def _closing_line(result: subprocess.CompletedProcess) -> str:
    """The one line on stderr (progress went to stdout); no traceback."""
    assert "Traceback" not in result.stderr, result.stderr
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("fenicsfriction: "), lines[0]
    return lines[0]


# --- solver failures: exit 1, one line saying where, what converged written ----------------------

@serial_only
def test_failed_slide_to_mu_in_dynamics_is_one_line_and_exit_1(tmp_path):
    """Newton limited to one iteration cannot reach the first steady state: the run says the
    slide to μ failed, takes no time step and writes the state it has."""
    result = _run(["block", "dynamics", "--mu", "0.5", "--t-end", "1e-4", "--out",
                   str(tmp_path), "-steady_snes_max_it", "1"])
    assert result.returncode == 1, result.stderr
    line = _closing_line(result)
    assert "slide to μ = 0.5" in line and "no time step taken" in line and "DIVERGED" in line
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["stage"] == "slide to μ" and summary["steps"] == 0
    assert summary["failure"] == line.removeprefix("fenicsfriction: ")
    assert summary["mu_last_converged"] is None  # not even μ = 0 converged
    assert (tmp_path / "slide.xdmf").exists() and not (tmp_path / "timeseries.csv").exists()


@serial_only
def test_a_step_limit_reached_before_t_end_is_a_stop_that_keeps_its_steps(tmp_path):
    """The user's -dynamics_ts_max_steps is honoured (it was overridden by an internal limit
    of 1e9): 5 steps of 1e-5 s end at t = 5e-5 s, short of t_end, which is a stop — exit 1,
    the line and the summary say so, and the 5 steps and the initial row are written."""
    result = _run(["block", "dynamics", "--mu", "0.6", "--t-end", "3e-4", "--dt", "1e-5",
                   "--b-n", "0.381e10", "--stride", "1000", "--out", str(tmp_path),
                   "-dynamics_ts_max_steps", "5"])
    assert result.returncode == 1, result.stderr
    line = _closing_line(result)
    assert "the step limit ts_max_steps = 5 was reached" in line and "t = 5e-05" in line
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["stage"] == "time integration" and summary["steps"] == 5
    assert summary["failure"] == line.removeprefix("fenicsfriction: ")
    rows = _table(tmp_path / "timeseries.csv")
    assert [r["time"] for r in rows] == pytest.approx([1e-5 * k for k in range(6)], rel=1e-9)


@serial_only
def test_failed_eps_sequence_keeps_the_steps_done_and_exits_1(tmp_path):
    """The continuation converges in at most 3 Newton iterations per step, the jump from
    ε = 1e-3 to 1e3 cm/s (from Coulomb to a viscous law) needs 4: the ε sequence fails at its
    second value, keeping the first."""
    result = _run(["block", "steady", "--mu-max", "0.3", "--steps", "3", "--snapshots", "0",
                   "--eps-sequence", "1e-3,1e3", "--out", str(tmp_path),
                   "-steady_snes_max_it", "3"])
    assert result.returncode == 1, result.stderr
    line = _closing_line(result)
    assert "ε sequence at μ = 0.3 failed at ε = 1000 (step 2 of 2)" in line
    assert "ε = 0.001" in line  # the last converged ε, whose state is written
    assert "step   3/3" in result.stdout  # progress on stdout
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["stage"] == "ε sequence" and summary["eps_last_converged"] == 1e-3
    assert summary["mu_last_converged"] == pytest.approx(0.3)
    steps = json.loads((tmp_path / "epsilon.json").read_text())
    assert [s["eps"] for s in steps] == [1e-3]
    assert len(json.loads((tmp_path / "steady.json").read_text())) == 4
    assert (tmp_path / "epsilon_last.xdmf").exists()


@serial_only
def test_failed_onset_bisection_keeps_the_loci_and_exits_1(tmp_path):
    """The grid steps of 0.1 converge in 3 Newton iterations; the bisection's first jump, from
    μ = 0.6 back to 0.4 with no halving allowed, does not."""
    result = _run(["block", "stability", "--mu-max", "0.6", "--steps", "6", "--onset-tol",
                   "1e-3", "--max-halvings", "0", "--out", str(tmp_path),
                   "-steady_snes_max_it", "3"])
    assert result.returncode == 1, result.stderr
    line = _closing_line(result)
    assert "onset bisection in μ ∈ [0.3, 0.4] failed at μ = 0.6" in line
    data = json.loads((tmp_path / "stability.json").read_text())
    assert data["stage"] == "onset bisection" and data["failure"] in line
    assert [s["mu"] for s in data["fe"]["steps"]] == pytest.approx(np.linspace(0, 0.6, 7))
    assert data["fe"]["onsets"] == [] and data["fe"]["mu_crit"] is None
    assert data["rigid"]["mu_crit"] is not None  # the rigid model does not depend on it


def test_an_onset_tolerance_below_round_off_is_refused(shared_tmp_path, capsys):
    """A bisection to 1e-17 would never end (μ's spacing near 0.4 is 5.6e-17)."""
    code = main(["block", "stability", "--mu-max", "0.6", "--steps", "6", "--onset-tol",
                 "1e-17", "--out", str(shared_tmp_path)])
    assert code == 2
    if MPI.COMM_WORLD.rank == 0:
        assert "--onset-tol=1e-17 is invalid" in capsys.readouterr().err


# --- signals from the first line ------------------------------------------------------------------

#: a child that says when the interpreter is up and the package's (3 ms) top level loaded,
#: then runs ``python -m fenicsfriction ARGS``: the delays below count from there (before
#: it, Python's own start-up cannot be caught; on a loaded machine it can take 0.1 s)
_LAUNCH = ("import runpy, sys; import fenicsfriction.signals; print('up', flush=True); "
           "sys.argv[0] = 'fenicsfriction'; "
           "runpy.run_module('fenicsfriction', run_name='__main__', alter_sys=True)")


def _signal_after(args: list[str], delay: float, signum: int) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-c", _LAUNCH, *args]
    process = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env=_environment())
    assert process.stdout is not None and process.stdout.readline() == "up\n"
    time.sleep(delay)
    process.send_signal(signum)
    out, err = process.communicate(timeout=120)
    return subprocess.CompletedProcess(cmd, process.returncode, out, err)


@serial_only
@pytest.mark.parametrize(("delay", "signum"), [(0.1, signal.SIGINT), (0.6, signal.SIGTERM)])
def test_a_signal_in_the_set_up_writes_a_summary_and_exits_128_plus_its_number(
        tmp_path, delay, signum):
    """0.1 s after start: the flags are being read and MPI/PETSc/dolfinx imported; 0.6 s: the
    imports or the model's build. Either way: a summary saying so, one line, 130 or 143."""
    started = time.monotonic()
    result = _signal_after(["block", "dynamics", "--mu", "0.6", "--t-end", "0.05", "--out",
                            str(tmp_path)], delay, signum)
    assert result.returncode == 128 + signum, result.stderr
    line = _closing_line(result)
    name = signal.Signals(signum).name
    assert f"interrupted by {name} after the " in line
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["interrupted"].startswith(f"interrupted by {name}")
    # stopped at the set-up's next stage, long before the 5000 steps
    assert summary.get("steps", 0) <= 1 and time.monotonic() - started < 30


# --- long runs: --record-every K and statistics over every step -----------------------------------

def _table(path: pathlib.Path) -> list[dict]:
    return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(path.open())]


def test_record_every_k_writes_every_kth_step_and_keeps_statistics_of_all(shared_tmp_path):
    """The same run with K = 1 and K = 7: the table of K = 7 is rows 0, 7, ..., 28 and the last
    of K = 1's, and both summaries' running statistics equal NumPy's over K = 1's table."""
    args = ["block", "dynamics", "--mu", "0.6", "--t-end", "3e-4", "--dt", "1e-5",
            "--b-n", "0.381e10", "--stride", "1000"]
    assert main([*args, "--out", str(shared_tmp_path / "k1")]) == 0
    assert main([*args, "--record-every", "7", "--out", str(shared_tmp_path / "k7")]) == 0
    full = _table(shared_tmp_path / "k1" / "timeseries.csv")
    thinned = _table(shared_tmp_path / "k7" / "timeseries.csv")
    assert len(full) == 31
    assert [r["time"] for r in thinned] == [full[i]["time"] for i in [*range(0, 31, 7), 30]]
    # the same steps; under MPI two runs differ by the round-off of parallel assembly, which
    # Newton's tolerance (1e-10 of the load) lets through: 1e-7 relative between the runs
    between = 1e-7
    assert thinned[3]["normal_force"] == pytest.approx(full[21]["normal_force"], rel=between)
    t = np.array([r["time"] for r in full])
    # energy_error is a balance of energies near round-off (1e-8 J here), so its statistics are
    # compared on the scale of the work it balances (3e-4 J), not on its own: between two MPI
    # runs it moves by 1e-4 of itself, which is 1e-9 of the work
    power = np.array([abs(r["friction_power"]) + abs(r["damping_power"]) for r in full])
    work = trapezoid(power, t)
    for name, rel in (("k1", 1e-12), ("k7", between)):
        summary = json.loads((shared_tmp_path / name / "summary.json").read_text())
        stats = summary["running_statistics"]
        assert stats["records"] == 31 and summary["steps"] == 30
        for key in ("normal_force", "energy_error", "spring_elongation"):
            x = np.array([r[key] for r in full])
            got, scale = stats["fields"][key], np.abs(x).max()
            floor = max(scale, work) if key == "energy_error" else scale
            close = {"rel": rel, "abs": rel * floor}
            assert got["min"] == pytest.approx(x.min(), **close)
            assert got["max"] == pytest.approx(x.max(), **close)
            assert got["max_abs"] == pytest.approx(scale, **close)
            assert got["mean"] == pytest.approx(trapezoid(x, t) / (t[-1] - t[0]), **close)
        assert summary["statistics"]["max_energy_error"] == pytest.approx(
            np.abs([r["energy_error"] for r in full]).max(), rel=rel, abs=rel * work)
        if name == "k1":  # the same run's table
            assert summary["statistics"]["newton_iterations"] == sum(
                int(r["newton_iterations"]) for r in full)


def test_running_statistics_window_and_counters_match_numpy():
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.5, 1.5, 200))
    x = rng.normal(2.0, 3.0, 200)
    stats = RunningStatistics(t_from=t[50])
    for k in range(200):
        stats.add({"time": t[k], "x": x[k], "flag": True, "name": "a", "newton_iterations": k})
    window = slice(50, None)
    assert stats.count == 150 and stats.totals["newton_iterations"] == sum(range(50, 200))
    assert stats["x"]["mean"] == pytest.approx(trapezoid(x[window], t[window])
                                               / (t[-1] - t[50]), rel=1e-13)
    assert stats["x"]["min"] == x[window].min() and stats["x"]["max"] == x[window].max()
    assert stats["x"]["max_abs"] == np.abs(x[window]).max()
    assert "flag" not in stats and "name" not in stats


def test_sampled_records_are_bounded_uniform_and_end_with_the_tail():
    sample = SampledRecords(capacity=8, tail=5)
    for k in range(1000):
        sample.add({"time": float(k)})
    kept = [int(r["time"]) for r in sample.records()]
    assert kept[-5:] == list(range(995, 1000))  # the tail in full
    head = kept[:-5]
    assert len(head) < 8 and head[0] == 0
    assert set(np.diff(head)) == {sample.stride}  # uniform: every stride-th record
    assert sample.stride == 256 and head == list(range(0, 995, 256))


# --- the just-in-time compiler under mpirun -------------------------------------------------------

#: a form no other test compiles (a fresh cache anyway), through the package's logger
_JIT_SCRIPT = """
from mpi4py import MPI
import ufl
from dolfinx import fem, mesh
import fenicsfriction as ff
from fenicsfriction import _compat
log = ff.results.get_logger(MPI.COMM_WORLD, progress="stdout")
msh = mesh.create_unit_square(MPI.COMM_WORLD, 2, 2)
V = _compat.vector_function_space(msh, 1)
u = fem.Function(V)
value = fem.assemble_scalar(_compat.form(ufl.inner(u, u) * ufl.dx + 3.25 * ufl.dx(domain=msh)))
log.info("assembled %.6g", MPI.COMM_WORLD.allreduce(value))
"""


@serial_only
@pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun")
def test_jit_compilation_prints_nothing_under_mpirun(tmp_path):
    """A fresh cache makes every form compile on 2 ranks; the compiler's build lines
    (``INFO:root:running build_ext``, one per form and rank before) do not appear."""
    script = tmp_path / "jit.py"
    script.write_text(_JIT_SCRIPT)
    result = subprocess.run(
        ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", "2", sys.executable,
         str(script)], capture_output=True, text=True, timeout=300,
        env=_environment(XDG_CACHE_HOME=str(tmp_path / "cache")))
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "cache" / "fenics").is_dir()  # it did compile, into the fresh cache
    assert "INFO" not in result.stdout + result.stderr, result.stderr[-2000:]
    assert result.stdout.splitlines() == ["assembled 3.25"], result.stdout


def test_a_signal_seen_by_one_rank_stops_every_rank_at_the_same_check():
    """mpirun forwards a signal to every rank, but not at the same instant: the ranks agree on
    the largest pending one, so rank 0 alone having it stops them all (serially: trivially)."""
    from fenicsfriction import signals
    comm = MPI.COMM_WORLD
    previous = signals.catch()
    try:
        if comm.rank == 0:
            signals._received[0] = signal.SIGTERM
        with pytest.raises(signals.Interrupted) as stopped:
            signals.checkpoint("a test's set-up", comm)
        assert stopped.value.exit_code == 143 and "after a test's set-up" in str(stopped.value)
        assert signals.pending() == 0  # handled: the next check goes on
        signals.checkpoint("the next stage", comm)
    finally:
        signals.release(previous)
