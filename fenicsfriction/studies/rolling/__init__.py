"""Steady rolling contact (Kalker 1986): Kalker's linear theory and FASTSIM without a mesh,
and the complete theory by finite elements.

One module per question:

* :mod:`~fenicsfriction.studies.rolling.hertz` — where do the bodies touch? The Hertz ellipse
  (:func:`hertz_from_curvatures`, :func:`hertz_from_radii`, :class:`HertzEllipse`);
* :mod:`~fenicsfriction.studies.rolling.kalker` — how stiff is the contact against creep?
  Kalker's coefficients C11, C22, C23, C33 (:func:`creep_coefficients`);
* :mod:`~fenicsfriction.studies.rolling.fastsim` — what are the tractions and forces? Kalker's
  simplified theory by FASTSIM (:func:`~fenicsfriction.studies.rolling.fastsim.fastsim`,
  :func:`creep_curve`) and the linear theory (:func:`linear_theory`).
* :mod:`~fenicsfriction.studies.rolling.model` — the complete theory by finite elements on
  a graded half-space (:mod:`~fenicsfriction.studies.rolling.geometry`): Carter's cylinders
  (2D), the Hertzian ellipse (3D), the Cattaneo-Mindlin shift
  (:class:`RollingContact`, closed forms in :mod:`~fenicsfriction.studies.rolling.closed_forms`);
  loads dolfinx on first use.

The name ``fastsim`` of this package is the module; the function is
``fenicsfriction.studies.rolling.fastsim.fastsim``.
"""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "HertzEllipse": "hertz", "hertz_from_curvatures": "hertz",
    "hertz_from_radii": "hertz", "quasi_identical_modulus": "hertz",
    "KalkerCoefficients": "kalker", "creep_coefficients": "kalker",
    "FastsimResult": "fastsim", "Flexibilities": "fastsim", "LinearForces": "fastsim",
    "creep_curve": "fastsim",
    "flexibilities": "fastsim", "linear_theory": "fastsim",
    "RollingContact": "model", "RollingModel": "model", "RollingResult": "model",
    "write_xdmf": "model"}, ("closed_forms", "fastsim", "geometry", "hertz", "kalker"))

if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers
    from fenicsfriction.studies.rolling import closed_forms, fastsim, geometry, hertz, kalker
    from fenicsfriction.studies.rolling.fastsim import (
        FastsimResult,
        Flexibilities,
        LinearForces,
        creep_curve,
        flexibilities,
        linear_theory,
    )
    from fenicsfriction.studies.rolling.hertz import (
        HertzEllipse,
        hertz_from_curvatures,
        hertz_from_radii,
        quasi_identical_modulus,
    )
    from fenicsfriction.studies.rolling.kalker import KalkerCoefficients, creep_coefficients
    from fenicsfriction.studies.rolling.model import (
        RollingContact,
        RollingModel,
        RollingResult,
        write_xdmf,
    )
