"""Every demo runs, in-process, on however many ranks pytest runs on (1 and 2 in `make test`),
with its own physics checks on: a demo asserts what it shows, and an assertion that fails
fails the test.

The two long demos run shortened (``FENICSFRICTION_DEMO_T_END``), and check the short-run
form of their claims (see each demo's "Checks"):

- stick-slip, 0.01 s (1000 steps of 1e-5 s): the flutter oscillation has grown (N leaves
  ±20 % of the weight) and sticking has begun at the slow belt; impulse theorem, energy
  balance, apparent coefficient <= μ and stick at 0.08 cm/s only are checked on every run;
- slider, 20 time units: the full stability maps (bands against the paper's and averaging
  against Floquet), the linearised growth at ω_o = 63.5 against the Floquet rate (2.6
  e-foldings), no event at 62.0 and the growth of the nonlinear motion at 63.5.
"""

import json
import os
import pathlib
import runpy
import signal
import subprocess
import sys
import time

from mpi4py import MPI

import pytest

DEMOS = sorted((pathlib.Path(__file__).parents[1] / "demos").glob("demo_*.py"))
#: the simulated time of the demos that read FENICSFRICTION_DEMO_T_END (their own unit)
T_END = {"demo_block_stick_slip": "0.01", "demo_slider_table2": "20"}


@pytest.mark.parametrize("path", DEMOS, ids=[p.stem for p in DEMOS])
def test_demo_runs_with_its_checks(path, shared_tmp_path, monkeypatch):
    if path.stem in T_END:
        monkeypatch.setenv("FENICSFRICTION_DEMO_T_END", T_END[path.stem])
    monkeypatch.setenv("FENICSFRICTION_DEMO_OUT", str(shared_tmp_path))
    runpy.run_path(str(path), run_name="__main__")  # demos assert their own checks


JUPYTEXT_HEADER = """# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.14.4
# ---
"""


@pytest.mark.parametrize("path", DEMOS, ids=[p.stem for p in DEMOS])
def test_demo_is_a_literate_notebook(path):
    """Jupytext percent format: the header, a title cell saying what the demo shows, then
    code and markdown cells, and checks of its own."""
    text = path.read_text()
    assert text.startswith(JUPYTEXT_HEADER)
    title = text[len(JUPYTEXT_HEADER):].split("\n# %%\n")[0]
    assert "# %% [markdown]\n# # " in title and "This demo shows how to" in title
    assert "\n# %%\nimport " in text  # the imports open the first code cell
    assert text.count("\n# %% [markdown]\n") >= 3
    assert "assert " in text  # checks of its own


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1,
                    reason="starts its own interpreter; runs in the serial pass")
def test_interrupted_stick_slip_demo_keeps_its_rows_and_exits_130(tmp_path):
    """Ctrl-C during the long demo: the rows of the run in progress stay on disk, the summary
    says where it stopped, one closing line, status 130, no traceback."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
    env.update(FENICSFRICTION_DEMO_OUT=str(tmp_path), FENICSFRICTION_DEMO_T_END="0.6")
    table = tmp_path / "timeseries_FE_U0.08.csv"
    process = subprocess.Popen([sys.executable, str(DEMOS[0].parent / "demo_block_stick_slip.py")],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    start = time.monotonic()
    while (not table.exists() or len(table.read_text().splitlines()) < 20) \
            and process.poll() is None:
        assert time.monotonic() - start < 300, "no rows written"
        time.sleep(0.2)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert "Traceback" not in err and "interrupted by SIGINT" in err.strip().splitlines()[-1]
    rows = len(table.read_text().splitlines()) - 1
    summary = json.loads((tmp_path / "stick_slip.json").read_text())
    assert summary["interrupted"][0].startswith("interrupted by SIGINT")
    assert summary["runs"][0]["steps"] == rows - 1
