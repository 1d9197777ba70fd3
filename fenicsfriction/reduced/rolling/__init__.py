"""Steady rolling contact without a mesh: Kalker's linear theory and FASTSIM.

One module per question:

* :mod:`~fenicsfriction.reduced.rolling.hertz` — where do the bodies touch? The Hertz ellipse
  (:func:`hertz_from_curvatures`, :func:`hertz_from_radii`, :class:`HertzEllipse`);
* :mod:`~fenicsfriction.reduced.rolling.kalker` — how stiff is the contact against creep?
  Kalker's coefficients C11, C22, C23 (:func:`creep_coefficients`);
* :mod:`~fenicsfriction.reduced.rolling.fastsim` — what are the tractions and forces? Kalker's
  simplified theory by FASTSIM (:func:`~fenicsfriction.reduced.rolling.fastsim.fastsim`,
  :func:`creep_curve`) and the linear theory (:func:`linear_theory`).

The name ``fastsim`` of this package is the module; the function is
``fenicsfriction.reduced.rolling.fastsim.fastsim``.
"""

from __future__ import annotations

import typing

from fenicsfriction._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "HertzEllipse": "hertz", "combined_modulus": "hertz", "hertz_from_curvatures": "hertz",
    "hertz_from_radii": "hertz", "quasi_identical_modulus": "hertz",
    "KalkerCoefficients": "kalker", "creep_coefficients": "kalker",
    "FastsimResult": "fastsim", "LinearForces": "fastsim", "creep_curve": "fastsim",
    "flexibilities": "fastsim", "linear_theory": "fastsim"}, ("fastsim", "hertz", "kalker"))

if typing.TYPE_CHECKING:  # the same names, eagerly, for type checkers
    from fenicsfriction.reduced.rolling import fastsim, hertz, kalker
    from fenicsfriction.reduced.rolling.fastsim import (
        FastsimResult,
        LinearForces,
        creep_curve,
        flexibilities,
        linear_theory,
    )
    from fenicsfriction.reduced.rolling.hertz import (
        HertzEllipse,
        combined_modulus,
        hertz_from_curvatures,
        hertz_from_radii,
        quasi_identical_modulus,
    )
    from fenicsfriction.reduced.rolling.kalker import KalkerCoefficients, creep_coefficients
