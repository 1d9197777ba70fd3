"""The reduced models and the statistics import without dolfinx (they need no mesh)."""

import os
import subprocess
import sys

import pytest

MODULES = ["fenicsfriction.reduced.slider", "fenicsfriction.reduced.belt",
           "fenicsfriction.reduced.events", "fenicsfriction.statistics",
           "fenicsfriction.reduced.rolling.fastsim", "fenicsfriction.reduced.rolling.hertz",
           "fenicsfriction.reduced.interface.eq_model",
           "fenicsfriction.reduced.interface.master_equation",
           "fenicsfriction.reduced.interface.instability"]


@pytest.mark.parametrize("module", MODULES)
def test_module_imports_without_dolfinx(module):
    # a fresh interpreter (this one has dolfinx loaded by other tests), outside the MPI job
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_", "PMI_"))}
    code = f"import sys, {module}; print(sorted(m for m in sys.modules if 'dolfinx' in m))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         check=True, timeout=120)
    assert out.stdout.strip() == "[]"
