r"""Kalker's FASTSIM: steady rolling with the simplified theory, and the linear theory.

**Conventions** (shared with the finite element rolling contact): the bodies roll in
:math:`+x`; the contact's leading edge is :math:`x = +a(y)`, :math:`a(y) = a\sqrt{1-y^2/b^2}`,
and material points travel through it from :math:`+a(y)` to :math:`-a(y)`. Creepages:
:math:`\xi` longitudinal, :math:`\eta` lateral, :math:`\phi` spin (1/length); the rigid slip
is :math:`w = (\xi - \phi y,\ \eta + \phi x)`. Tractions and forces are those on body 1, so
that a positive creepage is opposed: :math:`F_x = -G ab\, C_{11} \xi` in the linear theory
(:func:`linear_theory`).

**Simplified theory** (Kalker 1986, "Mathematical models of friction for contact problems in
elasticity", Wear 113, eqs. 24-25): the surface displacement difference is :math:`u = L p`,
a brush of independent springs of flexibility :math:`L`. In steady rolling the slip is
:math:`s = w - \partial u/\partial x`, so where the surface adheres the traction grows from
zero at the leading edge as :math:`\partial p/\partial x = w/L`. Kalker (1982, "A fast
algorithm for the simplified theory of rolling contact", Vehicle System Dynamics 11, 1-13)
gives each creepage its own flexibility, chosen so that the simplified theory reproduces the
linear theory's coefficients exactly; here four, one per linear coefficient
(:class:`Flexibilities`):

.. math::

    L_1 = \frac{8a}{3 C_{11} G}, \qquad L_2 = \frac{8a}{3 C_{22} G}, \qquad
    L_3 = \frac{\pi a \sqrt{a/b}}{4 C_{23} G}, \qquad L_4 = \frac{8b}{15 C_{33} G}.

:math:`L_1, L_2, L_3` are Kalker's (1982; computed the same way in subroutine ``simpflex`` of
CONTACT, Vollebregt & Kalker, Vtech CMCC, Apache-2.0). Kalker uses :math:`L_3` for both
components of the spin slip, :math:`(-\phi y,\ \phi x)`; fitted to :math:`C_{23}` it makes the
lateral force of spin right and the spin moment of spin wrong by the factor
:math:`32 C_{23} (b/a)^{3/2} / (15 \pi C_{33})` (0.85 for a circle at :math:`\nu = 0.28`,
0.93 at :math:`a/b = 1/2`). In full adhesion the lateral component :math:`\phi x` gives only
:math:`F_y` (:math:`-\pi a^3 b \phi/(4 L_3)`) and the longitudinal one :math:`-\phi y` only
:math:`M_z` (:math:`-8 a^2 b^3 \phi/(15 L_4)`), so the default gives the latter its own
flexibility :math:`L_4`, fitted to :math:`C_{33}`: the simplified theory then reproduces all
four of Kalker's coefficients. The linear theory's fifth term, the moment of the lateral
creepage :math:`G c^3 C_{23} \eta`, is not fitted: the brush gives
:math:`\pi a^3 b \eta/(4 L_2) = (3\pi/32) C_{22} G a^2 b \eta`, i.e. :math:`C_{23}` replaced
by :math:`3\pi C_{22}\sqrt{a/b}/32` (0.67 of it on the wheel-rail case, 0.75 on the circle
at :math:`\nu = 0`).
Kalker's original is ``flexibility=Flexibilities(L1, L2, L3, L3)``
(:meth:`Flexibilities.kalker1982`).

**FASTSIM** (Kalker 1982; Kalker 1986, eqs. 28-30): the contact is cut into ``ny`` strips
along :math:`x`, each into ``nx`` equal elements; the traction is marched from the leading
edge, element centre to element centre (a half step from the edge to the first centre). The
elastic trial traction over a step :math:`\Delta x` is
:math:`p_H = p' - (\int w\,dx)/L` (the slip-free increment, with :math:`\int w\,dx` exact for
the linear :math:`w`), and the traction bound :math:`g = \mu p_n` clips it:
:math:`p = p_H` (adhesion) if :math:`|p_H| \le g`, else :math:`p = g\, p_H/|p_H|` (slip,
opposite to the slip). Forces are midpoint sums over the elements. In full adhesion the
traction is exact at the centres, so the force errors are the midpoint rule's,
:math:`O(n^{-2})`.

**Traction bound**: ``pressure="parabolic"`` (the default) is
:math:`(2F_n/(\pi ab))(1-x^2/a^2-y^2/b^2)`, the bound of Kalker's FASTSIM (1982; the normal
pressure of the simplified theory itself), and of the implementations users compare with.
``pressure="ellipsoidal"`` is the Hertz pressure :math:`p_0\sqrt{1-x^2/a^2-y^2/b^2}`,
:math:`p_0 = 3F_n/(2\pi ab)`, the pressure the normal problem actually has (and the one the
finite element model computes), which Vollebregt's CONTACT user guide advises: the parabola
raises the bound at the centre by a third and lowers it near the edges. On the wheel-rail case
of ``docs/rolling-fastsim.md`` (:math:`\mu = 0.33`) at :math:`\xi = 1.2\cdot 10^{-3}` the
parabolic bound gives :math:`|F_x| = 0.615\,\mu F_n`, the ellipsoidal :math:`0.660\,\mu F_n`.
Both carry
:math:`F_n`, so that full sliding gives :math:`|F| = \mu F_n` up to the quadrature of the
pressure.

With several flexibilities the directions of the trial increments are those of
:math:`(\xi/L_1, \eta/L_2)`, not :math:`(\xi, \eta)`: at full sliding under combined
creepage the force points along the former.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import time
import typing

import numpy as np
import numpy.typing as npt

from fenicsfriction.laws import check, check_positive
from fenicsfriction.studies.rolling.kalker import creep_coefficients

__all__ = ["Flexibilities", "FastsimResult", "LinearForces", "PRESSURES", "creep_curve",
           "fastsim", "flexibilities", "linear_theory"]

#: the traction bounds :func:`fastsim` offers, the default first
PRESSURES = ("parabolic", "ellipsoidal")


@dataclasses.dataclass(frozen=True)
class FastsimResult:
    """The tangential solution of one steady rolling contact by FASTSIM.

    Arrays have the shape (ny, nx): strip j (lateral position y[j, :]), element i counted from
    the leading edge.

    Attributes:
        xi: longitudinal creepage [-].
        eta: lateral creepage [-].
        phi: spin creepage [1/length].
        Fx: longitudinal force on body 1 [force].
        Fy: lateral force on body 1 [force].
        Mz: spin moment on body 1 about the contact's centre, sum of (x py - y px) dA
            [force·length].
        Fn: normal load [force].
        x: element centres' x [length].
        y: element centres' y [length].
        px: longitudinal traction at the element centres [force/length²].
        py: lateral traction [force/length²].
        pn: normal pressure of the traction bound [force/length²].
        adhesion: True where the element adheres (the trial traction was inside the bound).
        adhesion_fraction: share of the contact's (discretised) area in adhesion.
        wall_time_s: wall time of the march; for a batch (:func:`creep_curve`) the batch's
            time divided by its number of points.
    """

    xi: float
    eta: float
    phi: float
    Fx: float
    Fy: float
    Mz: float
    Fn: float
    x: np.ndarray
    y: np.ndarray
    px: np.ndarray
    py: np.ndarray
    pn: np.ndarray
    adhesion: np.ndarray
    adhesion_fraction: float
    wall_time_s: float


class LinearForces(typing.NamedTuple):
    """Kalker's linear theory: forces on body 1 [force] and spin moment [force·length]."""

    Fx: float
    Fy: float
    Mz: float


class Flexibilities(typing.NamedTuple):
    r"""The simplified theory's flexibilities [length/(force/length²)], one per component of the
    rigid slip: in adhesion the traction grows from the leading edge as
    :math:`\partial p/\partial x = w/L`. ``L1`` for the longitudinal creepage ξ, ``L2`` for
    the lateral creepage η, ``L3`` for the spin's lateral slip φx (Kalker 1982: fitted to
    C23), ``L4`` for the spin's longitudinal slip -φy (fitted to C33; Kalker 1982 uses L3).
    """

    L1: float
    L2: float
    L3: float
    L4: float

    def kalker1982(self) -> Flexibilities:
        """Kalker's (1982) choice: L3 for both components of the spin slip."""
        return self._replace(L4=self.L3)


def _check_material(a: float, b: float, G: float, nu: float) -> None:
    check_positive("a", a)
    check_positive("b", b)
    check_positive("G", G)
    check("nu", nu, isinstance(nu, numbers.Real) and math.isfinite(nu) and 0.0 <= nu <= 0.5,
          "Poisson's ratio must be in [0, 0.5]")


def flexibilities(a: float, b: float, G: float, nu: float) -> Flexibilities:
    """The flexibilities (L1, L2, L3, L4) [length/(force/length²)] that make the simplified
    theory reproduce Kalker's C11, C22, C23, C33 (module docstring).

    Args:
        a: semi-axis along the rolling direction x [length], > 0.
        b: lateral semi-axis [length], > 0, with 0.1 <= a/b <= 10.
        G: combined shear modulus [force/length²], > 0.
        nu: Poisson's ratio, in [0, 0.5].
    """
    _check_material(a, b, G, nu)
    c = creep_coefficients(a, b, nu)
    return Flexibilities(L1=8.0 * a / (3.0 * c.C11 * G), L2=8.0 * a / (3.0 * c.C22 * G),
                         L3=math.pi * a * math.sqrt(a / b) / (4.0 * c.C23 * G),
                         L4=8.0 * b / (15.0 * c.C33 * G))


def linear_theory(a: float, b: float, G: float, nu: float, xi: float = 0.0, eta: float = 0.0,
                  phi: float = 0.0) -> LinearForces:
    r"""Kalker's linear theory (see :mod:`~fenicsfriction.studies.rolling.kalker`):
    :math:`F_x = -G c^2 C_{11}\xi`, :math:`F_y = -G c^2 (C_{22}\eta + c\, C_{23}\phi)`,
    :math:`M_z = -G c^3 (-C_{23}\eta + c\, C_{33}\phi)`, :math:`c = \sqrt{ab}`.

    Args:
        a: semi-axis along the rolling direction x [length], > 0.
        b: lateral semi-axis [length], > 0, with 0.1 <= a/b <= 10.
        G: combined shear modulus [force/length²], > 0.
        nu: Poisson's ratio, in [0, 0.5].
        xi: longitudinal creepage [-].
        eta: lateral creepage [-].
        phi: spin creepage [1/length].
    """
    _check_material(a, b, G, nu)
    for name, value in (("xi", xi), ("eta", eta), ("phi", phi)):
        check(name, value, isinstance(value, numbers.Real) and math.isfinite(value),
              "a creepage must be a finite number")
    k = creep_coefficients(a, b, nu)
    c2 = a * b
    c = math.sqrt(c2)
    return LinearForces(Fx=-G * c2 * k.C11 * xi, Fy=-G * c2 * (k.C22 * eta + c * k.C23 * phi),
                        Mz=-G * c2 * c * (-k.C23 * eta + c * k.C33 * phi))


def _creepages(**values: npt.ArrayLike) -> list[np.ndarray]:
    """The creepages as float arrays of one common 1-D shape."""
    arrays = []
    for name, value in values.items():
        array = np.asarray(value, dtype=float)
        check(name, value, array.ndim <= 1 and bool(np.all(np.isfinite(array))),
              "creepages must be finite numbers or 1-D arrays of them")
        arrays.append(array)
    shapes = {name: array.shape for name, array in zip(values, arrays, strict=True)}
    try:
        common, ok = np.broadcast_shapes(*shapes.values()), True
    except ValueError:
        common, ok = (), False
    check("creepage shapes", shapes, ok, "xi, eta and phi must broadcast together")
    return [np.atleast_1d(np.broadcast_to(array, common)) for array in arrays]


def creep_curve(a: float, b: float, G: float, nu: float, mu: float, Fn: float,
                xi: npt.ArrayLike = 0.0, eta: npt.ArrayLike = 0.0, phi: npt.ArrayLike = 0.0,
                nx: int = 40, ny: int = 40, pressure: str = "parabolic",
                flexibility: Flexibilities | None = None) -> list[FastsimResult]:
    """FASTSIM at many creepages at once (one march, vectorised over the points and strips).

    ``xi``, ``eta`` and ``phi`` are numbers or 1-D arrays broadcast together; one result per
    point. See :func:`fastsim` for the arguments.
    """
    _check_material(a, b, G, nu)
    for name, value in (("mu", mu), ("Fn", Fn)):
        check_positive(name, value)
    for name, value in (("nx", nx), ("ny", ny)):
        check(name, value, isinstance(value, numbers.Integral) and not isinstance(value, bool)
              and value >= 1, "must be an integer >= 1")
    check("pressure", pressure, pressure in PRESSURES, f"one of {PRESSURES}")
    xis, etas, phis = _creepages(xi=xi, eta=eta, phi=phi)
    if flexibility is None:
        flexibility = flexibilities(a, b, G, nu)
    check("flexibility", flexibility, isinstance(flexibility, Flexibilities)
          and all(math.isfinite(v) and v > 0 for v in flexibility),
          "a Flexibilities of four positive numbers")
    L1, L2, L3, L4 = flexibility

    t0 = time.perf_counter()
    dy = 2.0 * b / ny
    y_strip = -b + (np.arange(ny) + 0.5) * dy
    half = a * np.sqrt(1.0 - (y_strip / b) ** 2)          # a(y) of each strip
    dx = 2.0 * half / nx
    x = half[:, None] - (np.arange(nx)[None, :] + 0.5) * dx[:, None]
    y = np.broadcast_to(y_strip[:, None], x.shape)
    rho2 = np.clip(1.0 - (x / a) ** 2 - (y / b) ** 2, 0.0, None)
    pn = 1.5 * Fn / (math.pi * a * b) * np.sqrt(rho2) if pressure == "ellipsoidal" \
        else 2.0 * Fn / (math.pi * a * b) * rho2
    bound = mu * pn
    # slip-free increments per unit length: constant along a strip in x; linear in x in y
    rate_x = xis[:, None] / L1 - phis[:, None] * y_strip[None, :] / L4
    rate_y = etas[:, None] / L2
    spin_y = phis[:, None] / L3
    px = np.zeros((len(xis), ny, nx))
    py = np.zeros_like(px)
    slip = np.zeros(px.shape, dtype=bool)
    tx: npt.NDArray[np.float64] = np.zeros((len(xis), ny))
    ty: npt.NDArray[np.float64] = np.zeros_like(tx)
    for i in range(nx):
        step = 0.5 * dx if i == 0 else dx                  # from the edge, then centre to centre
        mid = x[:, i] + 0.5 * step                         # w_y is linear: its midpoint is exact
        tx = tx - rate_x * step
        ty = ty - (rate_y + spin_y * mid) * step
        size = np.hypot(tx, ty)
        over = size > bound[:, i]
        scale = np.where(over, bound[:, i] / np.where(over, size, 1.0), 1.0)
        tx, ty = tx * scale, ty * scale
        px[:, :, i], py[:, :, i], slip[:, :, i] = tx, ty, over
    area = np.broadcast_to((dx * dy)[:, None], x.shape)
    Fx = np.einsum("kji,ji->k", px, area)
    Fy = np.einsum("kji,ji->k", py, area)
    Mz = np.einsum("kji,ji->k", x * py - y * px, area)
    adhered = np.einsum("kji,ji->k", ~slip, area) / area.sum()
    wall = (time.perf_counter() - t0) / len(xis)
    return [FastsimResult(xi=float(xis[k]), eta=float(etas[k]), phi=float(phis[k]),
                          Fx=float(Fx[k]), Fy=float(Fy[k]), Mz=float(Mz[k]), Fn=float(Fn),
                          x=x, y=y, px=px[k], py=py[k], pn=pn, adhesion=~slip[k],
                          adhesion_fraction=float(adhered[k]), wall_time_s=wall)
            for k in range(len(xis))]


def fastsim(a: float, b: float, G: float, nu: float, mu: float, Fn: float, xi: float = 0.0,
            eta: float = 0.0, phi: float = 0.0, nx: int = 40, ny: int = 40,
            pressure: str = "parabolic", flexibility: Flexibilities | None = None
            ) -> FastsimResult:
    """Kalker's FASTSIM for steady rolling of a Hertzian contact (module docstring).

    Args:
        a: semi-axis along the rolling direction x [length], > 0.
        b: lateral semi-axis [length], > 0, with 0.1 <= a/b <= 10 (Kalker's table).
        G: combined shear modulus [force/length²], > 0.
        nu: Poisson's ratio, in [0, 0.5].
        mu: coefficient of friction, > 0.
        Fn: normal load [force], > 0.
        xi: longitudinal creepage [-].
        eta: lateral creepage [-].
        phi: spin creepage [1/length].
        nx: elements per strip, >= 1.
        ny: strips, >= 1.
        pressure: the traction bound's pressure, "parabolic" (Kalker's FASTSIM, default) or
            "ellipsoidal" (Hertz's).
        flexibility: the simplified theory's flexibilities; default :func:`flexibilities`
            (Kalker's 1982 choice: ``flexibilities(...).kalker1982()``).
    """
    for name, value in (("xi", xi), ("eta", eta), ("phi", phi)):
        check(name, value, isinstance(value, numbers.Real), "a creepage must be a number "
              "(creep_curve takes arrays)")
    return creep_curve(a, b, G, nu, mu, Fn, xi=xi, eta=eta, phi=phi, nx=nx, ny=ny,
                       pressure=pressure, flexibility=flexibility)[0]
