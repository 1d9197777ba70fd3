"""What the mesh scripts share: the output flag, the build and a summary of the result."""

from __future__ import annotations

import argparse
import pathlib
import time
import typing

from mpi4py import MPI

import numpy as np

from fenicsfriction.studies.contact import geometry

TAGS = {"BODY1": geometry.BODY1, "BODY2": geometry.BODY2, "SLAVE": geometry.SLAVE,
        "LOAD": geometry.LOAD, "MASTER": geometry.MASTER, "FIXED": geometry.FIXED,
        "SYMMETRY_X": geometry.SYMMETRY_X, "SYMMETRY_Y": geometry.SYMMETRY_Y}


def parser(name: str, doc: str | None) -> argparse.ArgumentParser:
    """An argument parser with ``--out`` (the ``.msh`` file, default ``<name>.msh``)."""
    p = argparse.ArgumentParser(description=doc,
                                formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path(f"{name}.msh"),
                   help="the gmsh mesh to write (.msh)")
    return p


def build(builder: typing.Callable[..., geometry.TwoBodyMesh], out: pathlib.Path,
          **parameters: typing.Any) -> geometry.TwoBodyMesh:
    """Build the scene on this process alone, write ``out`` and print what was made."""
    out.parent.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    m = builder(MPI.COMM_SELF, msh_file=str(out), **parameters)
    seconds = time.perf_counter() - start
    tdim = m.mesh.topology.dim
    cells = m.mesh.topology.index_map(tdim).size_global
    vertices = m.mesh.topology.index_map(0).size_global
    print(f"{out}: {cells} cells, {vertices} vertices ({seconds:.1f} s, gmsh and dolfinx)")
    for name, tag in TAGS.items():
        data = m.cell_tags if tag in (geometry.BODY1, geometry.BODY2) else m.facet_tags
        count = int(np.count_nonzero(data.values == tag))
        if count:
            kind = "cells" if data is m.cell_tags else "facets"
            print(f"  {name} = {tag}: {count} {kind}")
    print("  parameters:", m.parameters)
    return m
