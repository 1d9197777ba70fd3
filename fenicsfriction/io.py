"""Fields on disk: XDMF time series of displacements, tractions and mode shapes (ParaView).

Numbers (JSON, CSV) are written by :mod:`fenicsfriction.results`."""

from __future__ import annotations

import pathlib
import typing

import numpy as np
from dolfinx import fem, io

from fenicsfriction import _compat

__all__ = ["FieldWriter", "ModeWriter"]


class _XDMFSeries:
    """An XDMF file holding a mesh and a time series of fields (a context manager)."""

    def __init__(self, path: str | pathlib.Path, msh: typing.Any):
        pathlib.Path(path).parent.mkdir(parents=True, exist_ok=True)
        self.file = io.XDMFFile(msh.comm, str(path), "w")
        self.file.write_mesh(msh)

    def close(self) -> None:
        self.file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class FieldWriter(_XDMFSeries):
    """XDMF time series of the displacement and the contact traction.

    dolfinx 0.5 writes fields of the mesh's coordinate degree only, so both are interpolated
    into a degree-1 vector space. The traction field is kept on the contact nodes only (zero
    elsewhere). The "time" of each record is the continuation parameter (μ) or the time.
    """

    def __init__(self, path: str | pathlib.Path, model: typing.Any):
        self.model = model
        msh = model.msh
        self.V1 = _compat.vector_function_space(msh, 1)
        self.displacement = fem.Function(self.V1, name="displacement")
        self.traction = fem.Function(self.V1, name="contact_traction")
        self._traction_expr = fem.Expression(model.contact_traction(),
                                             _compat.interpolation_points(self.V1))
        fdim = msh.topology.dim - 1
        facets = model.facet_tags.find(model.CONTACT)
        self._off_contact = np.setdiff1d(
            np.arange(self.V1.dofmap.index_map.size_local + self.V1.dofmap.index_map.num_ghosts),
            fem.locate_dofs_topological(self.V1, fdim, facets))
        super().__init__(path, msh)

    def write(self, t: float) -> None:
        self.displacement.interpolate(self.model.residual.u)
        self.traction.interpolate(self._traction_expr)
        values = self.traction.x.array.reshape(-1, self.model.msh.geometry.dim)
        values[self._off_contact] = 0.0
        self.file.write_function(self.displacement, t)
        self.file.write_function(self.traction, t)


class ModeWriter(_XDMFSeries):
    """XDMF series of complex mode shapes: real and imaginary parts as two degree-1 fields."""

    def __init__(self, path: str | pathlib.Path, model: typing.Any):
        msh = model.msh
        self.mode = fem.Function(model.V)
        self.V1 = _compat.vector_function_space(msh, 1)
        self.parts = (fem.Function(self.V1, name="mode_real"),
                      fem.Function(self.V1, name="mode_imag"))
        super().__init__(path, msh)

    def write(self, mode: typing.Any, t: float) -> None:
        """Write ``mode`` (a :class:`~fenicsfriction.stability.Mode`) at "time" ``t``."""
        owned = len(mode.vector)
        for part, values in zip(self.parts, (mode.vector.real, mode.vector.imag), strict=True):
            self.mode.x.array[:owned] = values
            self.mode.x.scatter_forward()
            part.interpolate(self.mode)
            self.file.write_function(part, t)
