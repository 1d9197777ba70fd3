r"""Kalker's creepage and spin coefficients of the linear theory of rolling contact.

For an elliptic contact with semi-axes :math:`a` (along the rolling direction :math:`x`) and
:math:`b` (lateral, :math:`y`), quasi-identical bodies of shear modulus :math:`G` and Poisson's
ratio :math:`\nu`, and small creepages :math:`\xi` (longitudinal), :math:`\eta` (lateral),
:math:`\phi` (spin, 1/length), Kalker's linear theory gives the tangential force on body 1
(Kalker 1967; Kalker 1990, Appendix E; :math:`c = \sqrt{ab}`):

.. math::

    F_x = -G c^2 C_{11} \xi, \qquad
    F_y = -G c^2 (C_{22} \eta + c\, C_{23} \phi), \qquad
    M_z = -G c^3 (-C_{23} \eta + c\, C_{33} \phi).

The sign of the coupling in :math:`M_z` is Kalker's: a lateral creepage :math:`\eta > 0` gives
:math:`M_z > 0`; the simplified theory gives the same sign (its traction
:math:`p_y = -\eta (a(y) - x)/L_2` grows towards the trailing edge :math:`x < 0`).

Source of the table: J. J. Kalker (1990), *Three-dimensional elastic bodies in rolling
contact*, Kluwer, Table E.3 (the coefficients of his 1967 thesis, *On the rolling contact of
two elastic bodies in the presence of dry friction*, TH Delft). :math:`C_{11}, C_{22}, C_{23}`
are transcribed digit for digit from the copy in subroutine ``linrol`` of ``src/m_hertz.f90``
of CONTACT (E. A. H. Vollebregt and J. J. Kalker, Vtech CMCC, open-source version, Apache
License 2.0, https://github.com/eve70a/CONTACT), which holds those three columns only.
:math:`C_{33}` is the same table's fourth column; no machine-readable public copy of it was
found, so it was keyed in and is checked by the tests against the narrow-ellipse limit
:math:`C_{33} \to \pi^2/(16(1-\nu)g)` (:math:`g = a/b \to 0`: every strip :math:`y` a
two-dimensional rolling contact of creepage :math:`-\phi y`), against its smoothness along
the rows and, in ``docs/rolling-fastsim.md``, against an independent
polynomial fit of Kalker's table (within 1.2 % on every row but :math:`a/b = 10`).

Interpolation (:func:`creep_coefficients`), as in CONTACT's ``linrol``: with
:math:`g = \min(a/b, b/a) \in [0.1, 1]` the row of the half-table for :math:`a \le b` or
:math:`a > b`, linear in :math:`g` between the tabulated rows (spacing 0.1), then in
:math:`\nu` the quadratic through the three tabulated :math:`\nu = 0, 0.25, 0.5` of
:math:`1/C` (exact at the nodes). Ratios outside :math:`[0.1, 10]` are refused rather than
extrapolated (Kalker's slender-ellipse asymptotes, which CONTACT uses there, are not
continuous with the table's last row).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from fenicsfriction.laws import check, check_positive

__all__ = ["KalkerCoefficients", "NU", "RATIO", "TABLE", "creep_coefficients"]

#: tabulated g = min(a/b, b/a)
RATIO = np.round(np.arange(1, 11) * 0.1, 12)
#: tabulated Poisson's ratios
NU = np.array([0.0, 0.25, 0.5])

#: Kalker 1990, Table E.3: ``TABLE[half][row, coefficient, nu]``; half "a<=b" is indexed by
#: g = a/b, half "a>b" by g = b/a; coefficient 0, 1, 2, 3 = C11, C22, C23, C33; nu = 0, 0.25, 0.5.
TABLE: dict[str, np.ndarray] = {
    "a<=b": np.array([
        [[2.51, 3.31, 4.85], [2.51, 2.52, 2.53], [0.334, 0.473, 0.731], [6.42, 8.28, 11.7]],
        [[2.59, 3.37, 4.81], [2.59, 2.63, 2.66], [0.483, 0.603, 0.809], [3.46, 4.27, 5.66]],
        [[2.68, 3.44, 4.80], [2.68, 2.75, 2.81], [0.607, 0.715, 0.889], [2.49, 2.96, 3.72]],
        [[2.78, 3.53, 4.82], [2.78, 2.88, 2.98], [0.720, 0.823, 0.977], [2.02, 2.32, 2.77]],
        [[2.88, 3.62, 4.83], [2.88, 3.01, 3.14], [0.827, 0.929, 1.07], [1.74, 1.93, 2.22]],
        [[2.98, 3.72, 4.91], [2.98, 3.14, 3.31], [0.930, 1.03, 1.18], [1.56, 1.68, 1.86]],
        [[3.09, 3.81, 4.97], [3.09, 3.28, 3.48], [1.03, 1.14, 1.29], [1.43, 1.50, 1.60]],
        [[3.19, 3.91, 5.05], [3.19, 3.41, 3.65], [1.13, 1.25, 1.40], [1.34, 1.37, 1.42]],
        [[3.29, 4.01, 5.12], [3.29, 3.54, 3.82], [1.23, 1.36, 1.51], [1.27, 1.27, 1.27]],
        [[3.40, 4.12, 5.20], [3.40, 3.67, 3.98], [1.33, 1.47, 1.63], [1.21, 1.19, 1.16]]]),
    "a>b": np.array([
        [[10.7, 11.7, 12.9], [10.7, 12.8, 16.0], [12.2, 14.6, 18.0], [0.795, 0.526, 0.228]],
        [[6.96, 7.78, 8.82], [6.96, 8.14, 9.79], [5.72, 6.63, 7.89], [0.828, 0.601, 0.341]],
        [[5.57, 6.34, 7.34], [5.57, 6.40, 7.51], [3.79, 4.32, 5.01], [0.868, 0.674, 0.446]],
        [[4.84, 5.57, 6.57], [4.84, 5.48, 6.31], [2.88, 3.24, 3.70], [0.912, 0.747, 0.549]],
        [[4.37, 5.10, 6.11], [4.37, 4.90, 5.56], [2.35, 2.62, 2.96], [0.958, 0.819, 0.650]],
        [[4.06, 4.78, 5.80], [4.06, 4.50, 5.04], [2.01, 2.23, 2.50], [1.01, 0.892, 0.751]],
        [[3.82, 4.54, 5.58], [3.82, 4.21, 4.67], [1.76, 1.95, 2.18], [1.05, 0.965, 0.852]],
        [[3.65, 4.36, 5.42], [3.65, 3.99, 4.39], [1.58, 1.75, 1.94], [1.10, 1.04, 0.954]],
        [[3.51, 4.22, 5.30], [3.51, 3.81, 4.16], [1.44, 1.59, 1.77], [1.16, 1.11, 1.06]],
        [[3.40, 4.12, 5.20], [3.40, 3.67, 3.98], [1.33, 1.47, 1.63], [1.21, 1.19, 1.16]]]),
}


@dataclasses.dataclass(frozen=True)
class KalkerCoefficients:
    """Kalker's linear-theory coefficients for one ellipse and Poisson's ratio (dimensionless).

    Attributes:
        C11: longitudinal creepage coefficient.
        C22: lateral creepage coefficient.
        C23: lateral-spin coupling coefficient.
        C33: spin moment coefficient.
    """

    C11: float
    C22: float
    C23: float
    C33: float


def creep_coefficients(a: float, b: float, nu: float) -> KalkerCoefficients:
    """Kalker's :math:`C_{11}, C_{22}, C_{23}, C_{33}` for semi-axes ``a`` (rolling direction) and
    ``b`` (lateral), interpolated in Kalker 1990, Table E.3 (see the module docstring).

    Args:
        a: semi-axis along the rolling direction x [length], > 0.
        b: lateral semi-axis [length], > 0, with 0.1 <= a/b <= 10.
        nu: Poisson's ratio, 0 <= nu <= 0.5.
    """
    check_positive("a", a)
    check_positive("b", b)
    ratio = a / b
    check("a/b", ratio, 0.1 - 1e-12 <= ratio <= 10.0 + 1e-12,
          "the table covers 0.1 <= a/b <= 10 (b/a from 1 to 0.1)")
    check("nu", nu, isinstance(nu, (int, float)) and math.isfinite(nu) and 0.0 <= nu <= 0.5,
          "Poisson's ratio must be in [0, 0.5]")
    half, g = ("a<=b", ratio) if ratio <= 1.0 else ("a>b", 1.0 / ratio)
    g = min(max(g, RATIO[0]), RATIO[-1])
    rows = TABLE[half]
    at_g = np.array([[np.interp(g, RATIO, rows[:, k, n]) for n in range(3)] for k in range(4)])
    # Lagrange basis on nu = 0, 0.25, 0.5, applied to 1/C (CONTACT's linrol does the same)
    basis = np.array([8.0 * (nu - 0.25) * (nu - 0.5), -16.0 * nu * (nu - 0.5),
                      8.0 * nu * (nu - 0.25)])
    c11, c22, c23, c33 = 1.0 / ((1.0 / at_g) @ basis)
    return KalkerCoefficients(C11=float(c11), C22=float(c22), C23=float(c23), C33=float(c33))
