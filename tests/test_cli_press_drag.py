"""``fenicsfriction contact press-drag``: the summary with its ``energy_balance_error``, the
energy table and the figure written as documented (docs/cli.md), the balance closed, a bad
value as one line naming its flag (exit status 2) and a diverged integration as a summary and
one line (exit status 1). Serial and under ``mpirun -n 2``."""

import csv
import json
import os
import signal
import subprocess
import sys
import time

from mpi4py import MPI

import pytest
from cli_errors import assert_one_error_line

from fenicsfriction.cli import main

#: a short drag through slide and back to stick, dt = 0.05 (20 steps)
SHORT = ["--t-end", "1.0", "--drag-start", "0.5", "--drag-end", "0.8"]


def test_press_drag_writes_its_balance_and_closes_it(shared_tmp_path):
    out = shared_tmp_path / "press-drag"
    assert main(["contact", "press-drag", "--eps", "1e-4", "--dt", "0.05", *SHORT,
                 "--out", str(out)]) == 0
    summary = json.loads((out / "contact.json").read_text())
    assert {"energy_balance_error", "work", "dissipated", "max_penetration", "rejected_steps",
            "newton_iterations", "contact_period", "parameters", "ranks",
            "environment"} <= set(summary)
    assert summary["parameters"]["law"]["eps"] == 1e-4 and summary["dt"] == 0.05
    assert summary["steps"] == 20 and summary["failure"] is None
    # the energy-consistent step: Newton's tolerance (1e-10 P a step), not the scheme's error
    assert summary["energy_balance_error"] < 1e-3
    assert summary["dissipated"] > 0
    with (out / "energy.csv").open() as table:
        rows = list(csv.DictReader(table))
    assert len(rows) == 21
    assert {"time", "kinetic", "elastic", "contact_energy", "work", "dissipated",
            "balance"} <= set(rows[0])
    assert (out / "energy.png").stat().st_size > 0


def test_frictionless_press_drag_has_no_dissipation(shared_tmp_path):
    out = shared_tmp_path / "frictionless"
    assert main(["contact", "press-drag", "--frictionless", "--dt", "0.05", *SHORT,
                 "--out", str(out)]) == 0
    summary = json.loads((out / "contact.json").read_text())
    assert summary["parameters"]["law"]["mu"] == 0.0
    assert summary["dissipated"] == 0.0 and summary["energy_balance_error"] < 1e-3


@pytest.mark.parametrize(("argv", "name"), [(["--eps", "0"], "--eps"),
                                            (["--dt", "0"], "--dt"),
                                            (["--t-end", "0"], "--t-end"),
                                            (["--mu", "0.3", "--frictionless"], "--mu")])
def test_bad_value_is_one_line_naming_the_flag_and_exit_2(shared_tmp_path, capsys, argv, name):
    code = main(["contact", "press-drag", *argv, "--out", str(shared_tmp_path / "bad")])
    assert code == 2
    assert_one_error_line(capsys.readouterr().err, name)


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1,
                    reason="starts its own interpreter; runs in the serial pass")
def test_a_diverged_integration_writes_its_summary_and_exits_1(tmp_path):
    """Newton allowed one iteration and no cut-back: the first step that needs two (the
    cylinder lands) stops the run; its summary says where, and one line says why."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
    result = subprocess.run([sys.executable, "-m", "fenicsfriction", "contact", "press-drag",
                             "--dt", "0.05", *SHORT, "--out", str(tmp_path),
                             "-press_snes_max_it", "1", "-press_ts_max_reject", "0"],
                            capture_output=True, text=True, timeout=300, env=env)
    assert result.returncode == 1, result.stderr
    summary = json.loads((tmp_path / "contact.json").read_text())
    assert summary["failure"] is not None and 0 < summary["t_reached"] < 1.0
    last = [line for line in result.stderr.splitlines() if line.strip()][-1]
    assert last.startswith("fenicsfriction: press-drag: TS ")


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1,
                    reason="starts its own interpreter; runs in the serial pass")
def test_ctrl_c_keeps_every_step_and_exits_130(tmp_path):
    """Ctrl-C in a long run (the default step, 8 a contact period: thousands of steps): the
    rows so far, a summary saying where it stopped, one line, status 130."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
    table = tmp_path / "energy.csv"
    process = subprocess.Popen([sys.executable, "-m", "fenicsfriction", "contact", "press-drag",
                                "--out", str(tmp_path)], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, env=env)
    start = time.monotonic()
    rows = lambda: len(table.read_text().splitlines()) - 1 if table.exists() else 0  # noqa: E731
    while rows() < 5 and process.poll() is None:
        assert time.monotonic() - start < 300, "no rows written"
        time.sleep(0.2)
    assert process.poll() is None, process.communicate()
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert "Traceback" not in err
    assert "interrupted by SIGINT" in err.strip().splitlines()[-1]
    summary = json.loads((tmp_path / "contact.json").read_text())
    assert summary["interrupted"].startswith("interrupted by SIGINT")
    assert summary["steps"] == rows() - 1 >= 4
