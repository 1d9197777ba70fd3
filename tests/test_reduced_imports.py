"""The mesh-free models, the generic pieces they use and the families' data import without
dolfinx: a researcher without FEniCSx can still run them."""

import os
import subprocess
import sys

import pytest

MODULES = [
    # generic pieces
    "fenicsfriction.laws", "fenicsfriction.events", "fenicsfriction.timestepping",
    "fenicsfriction.statistics", "fenicsfriction.numerics", "fenicsfriction.studies",
    "fenicsfriction.discs",
    # the families' mesh-free models and data
    "fenicsfriction.studies.block.data", "fenicsfriction.studies.block.slab",
    "fenicsfriction.studies.block.rigid",
    "fenicsfriction.studies.contact.closed_forms",
    "fenicsfriction.studies.rolling.fastsim", "fenicsfriction.studies.rolling.hertz",
    "fenicsfriction.studies.rolling.kalker", "fenicsfriction.studies.rolling.closed_forms",
    "fenicsfriction.studies.multicontact.eq_model",
    "fenicsfriction.studies.multicontact.master_equation",
    "fenicsfriction.studies.multicontact.instability",
    "fenicsfriction.studies.multicontact.interaction",
    "fenicsfriction.studies.multicontact.interacting",
    "fenicsfriction.studies.multicontact.frenkel_kontorova",
    "fenicsfriction.studies.multicontact.figures", "fenicsfriction.studies.rolling.figures",
    "fenicsfriction.studies.oscillators.slider", "fenicsfriction.studies.oscillators.belt",
    "fenicsfriction.studies.oscillators.bouncing_mass",
]


@pytest.mark.parametrize("module", MODULES)
def test_module_imports_without_dolfinx(module):
    # a fresh interpreter (this one has dolfinx loaded by other tests), outside the MPI job
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_", "PMI_"))}
    code = (f"import sys, importlib; m = importlib.import_module({module!r}); "
            "[getattr(m, n) for n in getattr(m, '__all__', [])]; "
            "print(sorted(m for m in sys.modules if 'dolfinx' in m))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         check=True, timeout=120)
    assert out.stdout.strip() == "[]"
