"""The summaries of runs that did not finish say what their keys say: a run stopped by a
signal (``oscillators belt``/``slider``: ``interrupted``, ``samples``, ``t_end``,
``wall_seconds``) and a run whose solver failed (``oscillators belt``/``slider``: ``failure``
and the same keys; ``rolling fe``: ``failure``), each key checked against what the test itself
knows: the signal it sent, the rows on disk, the limit it set through a PETSc option, PETSc's
own monitor lines, the time it measured.

In-process runs, a few seconds in all: the signal is sent by the process to itself from a
wrapper around the model's right-hand side (as a terminal's Ctrl-C would arrive mid-step); the
failures are forced by a PETSc limit (``ts_max_steps``, ``snes_max_it``) that the test removes
again. The audit table is in docs/verification.md, "Reported figures"."""

import os
import re
import signal

from petsc4py import PETSc

import pytest
import scipy.integrate
from capture import run_main

from fenicsfriction.cli import common
from fenicsfriction.results import CsvRows
from fenicsfriction.studies.oscillators import BeltOscillator
from fenicsfriction.studies.oscillators.slider import SliderMotion

pytestmark = pytest.mark.sequential  # in-process signals and PETSc options: the serial pass

#: the belt oscillator, every parameter away from 0 and 1
BELT = ["--m=2.0", "--k=3.0", "--N=1.5", "--v-belt=0.4", "--mu-s=0.6", "--mu-k=0.3"]
#: right-hand side calls before the signal (a few hundred samples into the run)
CALLS_BEFORE_SIGNAL = 600
#: the steps a failing segment may take (``-<prefix>ts_max_steps``)
MAX_STEPS = 40
#: rows of block dynamics' table before the signal (the initial state and 5 steps)
BLOCK_ROWS = 6


def _signalled_at_row(rows: int, signum: int, argv: list[str]) -> dict:
    """:func:`_run` with ``signum`` sent to this process as the ``rows``-th row is written."""
    write, written = CsvRows.write, [0]

    def write_then_signal(self, row):
        write(self, row)
        written[0] += 1
        if written[0] == rows:
            os.kill(os.getpid(), signum)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(CsvRows, "write", write_then_signal)
        return run_main(argv)


def _signalled_in_set_up(signum: int, argv: list[str]) -> dict:
    """:func:`_run` with ``signum`` sent to this process while the command creates its output
    folder (its set-up, before any step)."""
    folder, sent = common.output_folder, [False]

    def signal_then_folder(*args, **kwargs):
        if not sent[0]:
            sent[0] = True
            os.kill(os.getpid(), signum)
        return folder(*args, **kwargs)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(common, "output_folder", signal_then_folder)
        return run_main(argv)


def _signalled(system: type, signum: int, argv: list[str]) -> dict:
    """:func:`_run` with ``signum`` sent to this process at the right-hand side's
    CALLS_BEFORE_SIGNAL-th call."""
    rhs, calls = system.rhs, [0]

    def rhs_then_signal(self, t, y, mode):
        calls[0] += 1
        if calls[0] == CALLS_BEFORE_SIGNAL:
            os.kill(os.getpid(), signum)
        return rhs(self, t, y, mode)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(system, "rhs", rhs_then_signal)
        return run_main(argv)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("stops")
    belt = ["oscillators", "belt", *BELT, "--t-end", "1000"]
    slider = ["oscillators", "slider", "--t-end", "1000", "--sample-dt", "0.001"]
    rolling = ["rolling", "fe", "--dim", "2", "--a=1.0", "--G=1.0", "--nu=0.3", "--mu=0.3",
               "--Fn=0.01", "--xi=0.001", "--cells-per-a", "4", "--block-size", "10",
               "--eps-sequence", "1,0.1", "--out", str(root / "rolling"),
               "-rolling_snes_monitor"]
    return {
        "belt stopped": _signalled(BeltOscillator, signal.SIGTERM,
                                   [*belt, "--out", str(root / "belt-stopped")]),
        "slider stopped": _signalled(SliderMotion, signal.SIGINT,
                                     [*slider, "--out", str(root / "slider-stopped")]),
        "belt failed": run_main([*belt, "--out", str(root / "belt-failed")],
                            options={"belt_ts_max_steps": MAX_STEPS}),
        "slider failed": run_main([*slider, "--out", str(root / "slider-failed")],
                              options={"hybrid_ts_max_steps": MAX_STEPS}),
        "rolling failed": run_main(rolling, "rolling.json", options={"rolling_snes_max_it": 1}),
        "block stopped": _signalled_at_row(
            BLOCK_ROWS, signal.SIGINT, ["block", "dynamics", "--mu", "0.6", "--belt-speed",
                                        "0.08", "--t-end", "0.2", "--out", str(root / "block")]),
        "set-up stopped": _signalled_in_set_up(signal.SIGTERM, [*belt, "--out",
                                                                str(root / "set-up")]),
    }


@pytest.mark.parametrize(("name", "signum"), [("belt stopped", signal.SIGTERM),
                                              ("slider stopped", signal.SIGINT)])
def test_stopped_oscillator_summary_says_the_signal_and_the_last_row(runs, name, signum):
    """Exit 128 + the signal's number; ``interrupted`` names the signal the test sent and the
    last sample (its time to 6 digits, the rows written); ``samples`` = the rows on disk;
    ``t_end`` = the last row's time (not the requested 1000); ``wall_seconds`` within the
    command's time; ``failure`` null; the one closing line on stderr says the same."""
    run = runs[name]
    summary, rows = run["json"], run["rows"]
    assert run["code"] == 128 + signum
    assert set(summary) - {"environment"} == {"interrupted", "failure", "samples", "t_end",
                                              "wall_seconds"}
    assert summary["failure"] is None and summary["samples"] == len(rows) > 10
    assert summary["t_end"] == rows[-1]["t"] < 1000
    where = f"t = {rows[-1]['t']:.6g} ({len(rows)} samples)"
    assert summary["interrupted"] == f"interrupted by {signal.Signals(signum).name} after {where}"
    assert 0 < summary["wall_seconds"] < run["seconds"]
    assert run["stderr"][-1] == (f"fenicsfriction: {summary['interrupted']}; the results so "
                                 "far are written")


@pytest.mark.parametrize("name", ["belt failed", "slider failed"])
def test_failed_oscillator_summary_says_where_the_integration_stopped(runs, name):
    """Exit 1; ``failure`` is the integrator's message: TS stopped (PETSc's reason
    TS_CONVERGED_ITS, 2: the step limit) after the MAX_STEPS steps the test allowed, at the
    time of the last row and in the mode of the last row; ``t_end`` = the last row's time,
    before the requested 1000; ``wall_seconds`` within the command's time; the belt's
    ``samples`` = the rows on disk; the slider's ``steps`` (its full summary, of the run up to
    the failure) = the limit, the run being one segment; the closing line on stderr says it."""
    run = runs[name]
    summary, rows = run["json"], run["rows"]
    assert run["code"] == 1
    match = re.search(r"TS stopped at t = (\S+) in mode (.+) with reason (-?\d+) after (\d+) "
                      r"steps", summary["failure"])
    assert match, summary["failure"]
    t, mode, reason, steps = match.groups()
    assert int(reason) == PETSc.TS.ConvergedReason.CONVERGED_ITS and int(steps) == MAX_STEPS
    assert float(t) == pytest.approx(rows[-1]["t"], rel=1e-11)
    assert summary["t_end"] == rows[-1]["t"] < 1000
    stuck = rows[-1]["stick"] == 1
    assert (mode in ("'stick'", "(0,)")) is stuck, (mode, rows[-1])
    if name == "belt failed":
        assert set(summary) - {"environment"} == {"interrupted", "failure", "samples", "t_end",
                                                  "wall_seconds"}
        assert summary["interrupted"] is None and summary["samples"] == len(rows)
        assert 0 < summary["wall_seconds"] < run["seconds"]
        assert run["stderr"][-1].startswith(f"fenicsfriction: integration stopped after "
                                            f"t = {rows[-1]['t']:.6g}: {summary['failure']}")
    else:  # the slider summarises the run up to there: one segment, so its steps are the limit
        assert summary["events"] == 0 and summary["steps"] == MAX_STEPS
        assert summary["interrupted"] is None and summary["samples"] == len(rows)
        assert 0 < summary["wall_seconds"] < run["seconds"]
        assert summary["failure"].startswith(f"integration stopped at t = {rows[-1]['t']:.6g}: ")
        assert run["stderr"][-1] == (f"fenicsfriction: {summary['failure']}; the results so "
                                     "far are written")


def test_failed_rolling_fe_summary_names_the_point_and_newtons_reason(runs):
    """Exit 1; ``failure`` names the point of the curve and its creepages (the flags), and is
    Newton's report: DIVERGED_MAX_IT after the 1 iteration the test allowed, with the residual
    norm of PETSc's own monitor's last line (4 digits); the parameters echo the flags; the
    closing line on stderr is the failure."""
    run = runs["rolling failed"]
    summary = run["json"]
    assert run["code"] == 1 and summary["method"] == "fe"
    assert summary["parameters"]["cells_per_a"] == 4 and summary["parameters"]["mu"] == 0.3
    prefix = "point 1/1 (ξ = 0.001, η = 0, φ = 0): Newton did not converge (DIVERGED_MAX_IT) " \
             "after 1 iterations, residual norm "
    assert summary["failure"].startswith(prefix), summary["failure"]
    norm = float(summary["failure"][len(prefix):].split(";")[0])
    monitor = [line for line in run["stdout"] if re.match(r"\s*\d+ SNES Function norm", line)]
    assert re.match(r"\s*1 SNES Function norm", monitor[-1])
    assert norm == pytest.approx(float(monitor[-1].split()[-1]), rel=5e-4)
    assert run["stderr"][-1] == f"fenicsfriction: rolling fe: {summary['failure']}"


def test_stopped_block_dynamics_summary_says_the_signal_and_what_was_integrated(runs):
    """Exit 130; ``interrupted`` names SIGINT, the last row's time (6 digits) and its step
    (the rows less the initial state); ``stage`` "time integration", ``failure`` null;
    ``steps`` = the rows' steps; ``wall_time_s`` within the command's time; ``statistics``
    over what was integrated: its totals (steps, Newton iterations, rejected steps) summed
    from the rows, ``duration`` and ``t_to`` the last row's time, the window from half of it
    (``t_from``, the first row at or after t/2), the mean forces the trapezoidal time means of
    the window's rows (1e-12) and ``apparent_coefficient`` their ratio; ``max_energy_error``
    the rows' largest |energy_error|."""
    run = runs["block stopped"]
    summary, rows = run["json"], run["rows"]
    assert run["code"] == 130 and len(rows) == BLOCK_ROWS
    t_last, steps = rows[-1]["time"], len(rows) - 1
    assert summary["interrupted"] == (f"interrupted by SIGINT after t = {t_last:.6g} s "
                                      f"(step {steps})")
    assert run["stderr"][-1] == (f"fenicsfriction: {summary['interrupted']}; the results so "
                                 "far are written")
    assert summary["stage"] == "time integration" and summary["failure"] is None
    assert summary["steps"] == steps and summary["sampled_every"] == 1
    assert 0 < summary["wall_time_s"] < run["seconds"]
    stats = summary["statistics"]
    assert stats["steps"] == steps
    for key in ("newton_iterations", "rejected_steps"):
        assert stats[key] == sum(r[key] for r in rows)
    assert stats["duration"] == stats["t_to"] == t_last
    window = [r for r in rows if r["time"] >= t_last / 2]
    assert stats["t_from"] == window[0]["time"]
    t = [r["time"] for r in window]
    for key in ("normal_force", "friction_force"):
        mean = float(scipy.integrate.trapezoid([r[key] for r in window], t)) / (t[-1] - t[0])
        assert stats[f"mean_{key}"] == pytest.approx(mean, rel=1e-12)
    assert stats["apparent_coefficient"] == pytest.approx(
        stats["mean_friction_force"] / stats["mean_normal_force"], rel=1e-12)
    assert stats["max_energy_error"] == max(abs(r["energy_error"]) for r in rows)


def test_set_up_stopped_summary_says_the_stage_and_the_command(runs):
    """A signal during the set-up (here while the output folder is made): exit 143, nothing
    integrated; summary.json holds the command as typed, ``stage`` "set-up", ``interrupted``
    naming SIGTERM and the last stage passed (the start-up), ``failure`` null; the closing
    line says the run had not begun its steps."""
    run = runs["set-up stopped"]
    summary = run["json"]
    assert run["code"] == 143 and run["rows"] is None
    assert set(summary) - {"environment"} == {"command", "stage", "interrupted", "failure"}
    assert summary["command"] == ["fenicsfriction", "oscillators", "belt", *BELT, "--t-end",
                                  "1000", "--out", summary["command"][-1]]
    assert summary["command"][-1].endswith("set-up")
    assert summary["stage"] == "set-up" and summary["failure"] is None
    assert summary["interrupted"] == ("interrupted by SIGTERM after the start-up (flags read, "
                                      "MPI and PETSc loaded)")
    assert run["stderr"][-1] == (f"fenicsfriction: {summary['interrupted']}; the run had not "
                                 "begun its steps")
