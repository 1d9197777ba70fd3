"""Every demo runs, in-process, on however many ranks pytest runs on (1 and 2 in `make test`)."""

import pathlib
import runpy

import pytest

DEMOS = sorted((pathlib.Path(__file__).parents[1] / "demos").glob("demo_*.py"))


@pytest.mark.parametrize("path", DEMOS, ids=[p.stem for p in DEMOS])
def test_demo_runs(path, shared_tmp_path, monkeypatch):
    # the stick-slip demo: 10 ms (the oscillation has grown and sticking begun) into tmp
    monkeypatch.setenv("FENICSFRICTION_DEMO_T_END", "0.01")
    monkeypatch.setenv("FENICSFRICTION_DEMO_OUT", str(shared_tmp_path))
    runpy.run_path(str(path), run_name="__main__")  # demos assert their own checks
