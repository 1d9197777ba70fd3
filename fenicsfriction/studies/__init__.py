"""The studies, grouped by physics family; each family holds its finite element and its
mesh-free models side by side:

* :mod:`~fenicsfriction.studies.block` — the block on a moving belt (Martins & Oden 1986):
  steady sliding, stability, dynamics; the rigid block; the block on a layered belt and on an
  elastic slab;
* :mod:`~fenicsfriction.studies.contact` — two elastic bodies in contact (Pop): Hertz, the patch
  test, Cattaneo-Mindlin, a cylinder pressed and dragged;
* :mod:`~fenicsfriction.studies.rolling` — rolling contact (Kalker 1986): FASTSIM and the
  complete theory by finite elements;
* :mod:`~fenicsfriction.studies.multicontact` — Braun's nonhomogeneous interface of many
  breaking contacts;
* :mod:`~fenicsfriction.studies.oscillators` — oscillators without a mesh: the m.d.o.f. slider
  with oscillatory normal forces (2003), the oscillator on a belt, the bouncing mass.

A family imports the engine (laws, forms, solvers) and the generic pieces (time stepping,
events, statistics, meshing, io, plotting), never another family's module, and nothing below
``studies`` imports a family. The mesh-free modules never import dolfinx.
"""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

__getattr__, __dir__, __all__ = attach(
    __name__, {}, ("block", "contact", "multicontact", "oscillators", "rolling"))

if typing.TYPE_CHECKING:
    from fenicsfriction.studies import block, contact, multicontact, oscillators, rolling
