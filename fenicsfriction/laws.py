r"""Pointwise interface laws of Martins & Oden (1986, eqs. 1-2) and their regularisations.

Every builder takes UFL expressions (to be used in forms) or NumPy arrays/floats (to be used in
reduced models and post-processing) and returns the same kind. Notation (see docs/theory.md):

* :math:`d = (u_n - g)_+` penetration (approach) of the interface, :math:`g \ge 0` initial gap;
* normal compliance :math:`c_n d^{m_n}`, normal damping :math:`b_n d^{l_n} \dot u_n`;
* friction bound :math:`c_T d^{m_T}`; Coulomb is :math:`m_T = m_n`, :math:`c_T = \mu c_n`;
* regularised friction direction :math:`\phi_\varepsilon'(w)` with :math:`w = \dot u_T - U_T`.
* slip rules (:class:`CoulombSlipRule`, :class:`EllipticSlipRule`): the slip surface
  :math:`g(p_\tau, p_n) \le 0` and the direction of the traction on it (Frederiksson 1976;
  Kalker 1986, §7).

The two tractions of the interface on the body are defined here once, :func:`normal_traction`
and :func:`friction_traction`; :class:`InterfaceLaw` holds the law's parameters, friction
coefficient law and slip rule, and exposes the tractions and their NumPy derivatives: the
residual's terms (:mod:`fenicsfriction.forms`), the scenes' observables and the reduced models
all take a law and call it.

Parameters are validated in one place, :class:`InterfaceLaw`; a bad value raises ``ValueError``
naming the parameter, its value and what is allowed.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import typing

import numpy as np
import ufl
from ufl.algorithms.map_integrands import map_integrand_dags
from ufl.corealg.multifunction import MultiFunction
from ufl.corealg.traversal import unique_pre_traversal
from ufl.variable import Label

__all__ = [
    "FRICTION_BOUND",
    "FrictionLaw",
    "ConstantFriction",
    "CoulombSlipRule",
    "EllipticSlipRule",
    "InterfaceLaw",
    "PiecewiseLinearFriction",
    "REGULARISATIONS",
    "SLIP_RULES",
    "SlipRule",
    "StribeckFriction",
    "abs_c1",
    "abs_c1_derivative",
    "abs_c1_second_derivative",
    "abs_smooth",
    "abs_smooth_derivative",
    "abs_smooth_second_derivative",
    "check",
    "exp",
    "friction_bound",
    "friction_bounds",
    "friction_traction",
    "is_speed_law",
    "maximum",
    "minimum",
    "normal_damping_pressure",
    "normal_pressure",
    "normal_traction",
    "penetration",
    "sqrt",
    "substitute_friction_bound",
]

Scalar: typing.TypeAlias = typing.Any  # a float, a NumPy array or a UFL expression


def check(name: str, value: typing.Any, ok: bool, allowed: str) -> None:
    """Raise ``ValueError("name=value is invalid: allowed")`` unless ``ok``."""
    if not ok:
        raise ValueError(f"{name}={value!r} is invalid: {allowed}")


def check_positive(name: str, value: typing.Any, strict: bool = True) -> None:
    """:func:`check` that ``value`` is a finite real number, > 0 (``strict``) or >= 0."""
    ok = isinstance(value, numbers.Real) and math.isfinite(value) \
        and (float(value) > 0 if strict else float(value) >= 0)
    check(name, value, ok, f"must be a finite number {'>' if strict else '>='} 0")


def _is_ufl(*xs: typing.Any) -> bool:
    return any(isinstance(x, ufl.core.expr.Expr) for x in xs)


def _max(a: Scalar, b: Scalar) -> Scalar:
    return ufl.max_value(a, b) if _is_ufl(a, b) else np.maximum(a, b)


def _min(a: Scalar, b: Scalar) -> Scalar:
    return ufl.min_value(a, b) if _is_ufl(a, b) else np.minimum(a, b)


def _norm(w: typing.Any) -> Scalar:
    """Euclidean norm of a UFL vector; element-wise |w| of NumPy input.

    NumPy input is read as scalar tangential velocities (reduced models, one tangent direction).
    """
    if _is_ufl(w):
        return ufl.sqrt(ufl.inner(w, w)) if w.ufl_shape else abs(w)
    return np.abs(np.asarray(w, dtype=float))


def _sqrt(x: Scalar) -> Scalar:
    return ufl.sqrt(x) if _is_ufl(x) else np.sqrt(x)


def _exp(x: Scalar) -> Scalar:
    return ufl.exp(x) if _is_ufl(x) else np.exp(x)


# --- normal response (Martins & Oden 1986, eq. 1) ----------------------------------------------

def penetration(u_n: Scalar, g: Scalar = 0.0) -> Scalar:
    """Approach of the interface :math:`d = (u_n - g)_+` (Martins & Oden 1986, Fig. 3)."""
    return _max(u_n - g, 0.0)


def normal_pressure(d: Scalar, c_n: Scalar, m_n: Scalar) -> Scalar:
    """Elastic normal compliance :math:`-\\sigma_n^e = c_n d^{m_n}` (Martins & Oden 1986, eq. 1)."""
    return c_n * d**m_n


def normal_damping_pressure(d: Scalar, u_n_dot: Scalar, b_n: Scalar, l_n: Scalar) -> Scalar:
    """Dissipative normal stress :math:`-\\sigma_n^d = b_n d^{l_n} \\dot u_n` (Martins & Oden
    1986, eq. 1)."""
    return b_n * d**l_n * u_n_dot


def friction_bound(d: Scalar, c_T: Scalar, m_T: Scalar) -> Scalar:
    """Maximum friction stress :math:`c_T d^{m_T}` (Martins & Oden 1986, eq. 2)."""
    return c_T * d**m_T


FRICTION_BOUND = Label()
"""The label of the friction bound inside :func:`friction_traction`'s UFL expressions.

The bound is wrapped in a :class:`ufl.variable.Variable` with this label, which changes
nothing in the forms or their derivatives but lets a solver find it in a residual and
evaluate it elsewhere: :mod:`fenicsfriction.panagiotopoulos` freezes it at the last iterate
(Kalker 1986, section 3) or replaces it by its mollification (Kalker 1986, eq. 27).
"""


def _is_bound(o: typing.Any) -> bool:
    return isinstance(o, ufl.classes.Variable) and o.ufl_operands[1] == FRICTION_BOUND


class _BoundSubstitution(MultiFunction):
    """Maps each labelled friction bound to ``replacement(bound expression)``."""

    def __init__(self, replacement: typing.Callable[[typing.Any], typing.Any]):
        super().__init__()
        self.replacement = replacement

    expr = MultiFunction.reuse_if_untouched

    def variable(self, o: typing.Any, expression: typing.Any, label: typing.Any) -> typing.Any:
        if _is_bound(o):
            return self.replacement(o.ufl_operands[0])
        return self.reuse_if_untouched(o, expression, label)


def substitute_friction_bound(form: ufl.Form,
                              replacement: typing.Callable[[typing.Any], typing.Any]
                              ) -> ufl.Form:
    """``form`` with every friction bound :math:`c_T d^{m_T}` (labelled
    :data:`FRICTION_BOUND`) replaced by ``replacement(bound)``, e.g. the bound at a frozen
    state, ``lambda g: ufl.replace(g, {u: u_N})``."""
    return map_integrand_dags(_BoundSubstitution(replacement), form)


def friction_bounds(form: ufl.Form) -> list[typing.Any]:
    """The distinct friction bound expressions of ``form`` (labelled by
    :func:`friction_traction`), in order of appearance."""
    found: list = []
    for integral in form.integrals():
        for o in unique_pre_traversal(integral.integrand()):
            if _is_bound(o) and o.ufl_operands[0] not in found:
                found.append(o.ufl_operands[0])
    return found


# --- regularisations of |w| (Pop, eq. 15; Kalker 1986, eq. 40) -----------------------------------

def abs_c1(w: typing.Any, eps: Scalar) -> Scalar:
    """C1 regularisation :math:`\\phi_\\varepsilon(w) = |w|^2/(2\\varepsilon)` for
    :math:`|w|<\\varepsilon`, :math:`|w| - \\varepsilon/2` otherwise."""
    r = _norm(w)
    if _is_ufl(r, eps):
        return ufl.conditional(ufl.lt(r, eps), r**2 / (2 * eps), r - eps / 2)
    return np.where(r < eps, r**2 / (2 * eps), r - eps / 2)


def abs_c1_derivative(w: typing.Any, eps: Scalar) -> typing.Any:
    """:math:`\\phi_\\varepsilon'(w) = w / \\max(|w|, \\varepsilon)` (a vector like ``w``)."""
    r = _norm(w)
    if _is_ufl(r, eps):
        # a conditional, not max_value: UFL differentiates max(a, b) as c a' + (1 - c) b', and
        # at w = 0 (stick, a body at rest) the unused a' = w/|w| is 0/0, which the product
        # turns into a NaN Jacobian; a conditional's unused branch is not multiplied
        return ufl.conditional(ufl.lt(r, eps), w / eps, w / r)
    return w / _max(r, eps)


def abs_c1_second_derivative(w: Scalar, eps: Scalar) -> Scalar:
    """:math:`\\phi_\\varepsilon''(w)` of a scalar slip (one tangent direction): 1/ε inside
    the band |w| < ε, 0 outside. At w = 0 it is also the coefficient of the isotropic
    tangential stiffness :math:`\\partial\\phi_\\varepsilon'/\\partial w = I/\\varepsilon` of a
    vector slip."""
    r = _norm(w)
    if _is_ufl(r, eps):
        return ufl.conditional(ufl.lt(r, eps), 1 / eps, 0.0)
    return np.where(r < eps, 1.0 / eps, 0.0)


def abs_smooth(w: typing.Any, eps: Scalar) -> Scalar:
    """Smooth regularisation :math:`\\psi_\\varepsilon(w) = \\sqrt{|w|^2 + \\varepsilon^2}`."""
    # |w|² as w·w, not sqrt(w·w)²: UFL differentiates the latter as 2|w| (w/|w|), which is
    # 0·∞ = NaN where the slip vanishes (a node at rest, the spin's centre at the first Newton
    # step), and Newton's linear solve fails on the NaN rows
    if _is_ufl(w):
        square = ufl.inner(w, w) if w.ufl_shape else w**2
    else:
        square = np.asarray(w, dtype=float) ** 2
    return _sqrt(square + eps**2)


def abs_smooth_derivative(w: typing.Any, eps: Scalar) -> typing.Any:
    """:math:`\\psi_\\varepsilon'(w) = w / \\sqrt{|w|^2 + \\varepsilon^2}`."""
    return w / abs_smooth(w, eps)


def abs_smooth_second_derivative(w: Scalar, eps: Scalar) -> Scalar:
    """:math:`\\psi_\\varepsilon''(w) = \\varepsilon^2 / (w^2 + \\varepsilon^2)^{3/2}` of a scalar
    slip; at w = 0, 1/ε, the coefficient of the isotropic tangential stiffness."""
    return eps**2 / abs_smooth(w, eps) ** 3


REGULARISATIONS: dict[str, tuple[typing.Callable[..., typing.Any], ...]] = {
    "c1": (abs_c1, abs_c1_derivative, abs_c1_second_derivative),
    "smooth": (abs_smooth, abs_smooth_derivative, abs_smooth_second_derivative),
}
"""φ_ε, φ'_ε and φ''_ε (scalar slip) of each regularisation, by name."""


# --- slip rules (Frederiksson 1976; Michałowski & Mróz 1978; Kalker 1986, §7) ------------------

def _components(w: typing.Any, frame: tuple[typing.Any, ...] | None) -> list[Scalar]:
    """The slip's components (w·t1, w·t2) in ``frame``; with no frame, ``w``'s own components
    (the last axis of a NumPy array)."""
    if frame is None:
        if _is_ufl(w):
            return [w[i] for i in range(w.ufl_shape[0])]
        w = np.asarray(w, dtype=float)
        return [w[..., i] for i in range(w.shape[-1])]
    if _is_ufl(w, *frame):
        return [ufl.dot(w, t if _is_ufl(t) else ufl.as_vector(t)) for t in frame]
    return [np.asarray(w, dtype=float) @ np.asarray(t) for t in frame]


def _vector(components: list[Scalar], frame: tuple[typing.Any, ...] | None) -> typing.Any:
    """The vector Σ c_i t_i of components in ``frame`` (the inverse of :func:`_components`)."""
    if frame is None:
        if _is_ufl(*components):
            return ufl.as_vector(components)
        return np.stack(np.broadcast_arrays(*components), axis=-1)
    if _is_ufl(*components, *frame):
        return sum(c * (t if _is_ufl(t) else ufl.as_vector(t))
                   for c, t in zip(components, frame, strict=True))
    return sum(np.asarray(c)[..., None] * np.asarray(t)
               for c, t in zip(components, frame, strict=True))


def _direction(components: list[Scalar], eps: Scalar, regularisation: str) -> list[Scalar]:
    """The components of the regularised direction :math:`\\phi_\\varepsilon'(z)` of the vector
    z with these components (:data:`REGULARISATIONS`)."""
    _, derivative, second_derivative = REGULARISATIONS[regularisation]
    if _is_ufl(*components, eps):
        direction = derivative(ufl.as_vector(components), eps)
        return [direction[i] for i in range(len(components))]
    r = np.sqrt(sum(np.asarray(c, dtype=float) ** 2 for c in components))
    # φ'_ε(z) = z φ'_ε(|z|)/|z|, whose limit at z = 0 is z φ''_ε(0)
    scale = np.where(r > 0, derivative(r, eps) / np.where(r > 0, r, 1.0),
                     second_derivative(0.0, eps))
    return [c * scale for c in components]


@dataclasses.dataclass(frozen=True)
class CoulombSlipRule:
    """Isotropic Coulomb friction, the associated rule of the circular slip surface
    :math:`g = |p_\\tau| - \\mu p_n` (Kalker 1986, eqs. 50-52): the traction of
    :func:`friction_traction` as it was before slip rules, the default."""

    def traction(self, bound: Scalar, w: typing.Any, eps: Scalar,
                 regularisation: str = "c1") -> typing.Any:
        """:math:`-c_T d^{m_T} \\phi_\\varepsilon'(w)` with ``bound`` :math:`= c_T d^{m_T}`.

        Args:
            bound: the friction bound (:func:`friction_bound`).
            w: the slip velocity (UFL vector, or NumPy scalars: one tangent direction).
            eps: regularisation parameter ε.
            regularisation: ``"c1"`` or ``"smooth"`` (:data:`REGULARISATIONS`).

        Returns:
            The traction on the body, a vector like ``w``.
        """
        return -bound * REGULARISATIONS[regularisation][1](w, eps)


@dataclasses.dataclass(frozen=True)
class EllipticSlipRule:
    """Orthotropic friction: the elliptic slip surface
    :math:`g(p_\\tau, p_n) = \\sqrt{(p_1/\\mu_x)^2 + (p_2/\\mu_y)^2} - p_n \\le 0`, with
    :math:`p_1, p_2` the friction resistance :math:`p = -t` in the tangent frame (t1, t2).

    * ``associated=True`` (Frederiksson 1976; Kalker 1986, eqs. 45-47): the slip is normal to
      the slip surface, :math:`w = \\lambda\\, \\partial g/\\partial p`, :math:`\\lambda \\ge 0`.
      The traction is :math:`t = -\\partial D_\\varepsilon/\\partial w` with the regularised
      dissipation :math:`D_\\varepsilon(w) = p_n \\mu_{ref}\\, \\phi_\\varepsilon(A w /
      \\mu_{ref})`, :math:`A = \\mathrm{diag}(\\mu_x, \\mu_y)`; outside the band
      :math:`|A w| < \\mu_{ref}\\varepsilon` it is :math:`t = -p_n A^2 w / |A w|`, on the
      ellipse, at the angle :math:`\\tan\\theta_p = (\\mu_y/\\mu_x)^2 \\tan\\theta_s` from t1
      when the slip is at :math:`\\theta_s`: not opposite the slip unless it is along an axis.
    * ``associated=False`` (a non-associated rule in the sense of Michałowski & Mróz 1978,
      "Associated and non-associated sliding rules in contact friction problems"): the
      traction opposes the slip with the magnitude on the slip surface,
      :math:`t = -\\mu(\\theta_s) p_n \\phi_\\varepsilon'(w)`,
      :math:`1/\\mu(\\theta)^2 = \\cos^2\\theta/\\mu_x^2 + \\sin^2\\theta/\\mu_y^2`.

    The bound handed to :meth:`traction` is :math:`c_T d^{m_T} = \\mu_{ref} p_n` with
    :math:`\\mu_{ref} = \\max(\\mu_x, \\mu_y)` (:attr:`mu_ref`): it stays the largest
    traction, as the bound of Martins & Oden (1986, eq. 2); pass ``c_T = mu_ref * c_n``. With
    :math:`\\mu_x = \\mu_y = \\mu` both rules are Coulomb's, :class:`CoulombSlipRule`.

    Args:
        mu_x: friction coefficient along t1 [-], > 0.
        mu_y: friction coefficient along t2 [-], > 0 (not used on a 2D contact line).
        associated: normality (True) or traction opposite the slip (False).
        frame: the tangent unit vectors (t1, t2) of Γ_C in the global frame (``(t1,)`` on the
            contact line of a 2D body), constant sequences of floats or UFL vectors (a curved
            Γ_C); ``None``: the slip's own components are (w·t1, w·t2) (NumPy: the last axis).
    """

    mu_x: float
    mu_y: float
    associated: bool = True
    frame: tuple[typing.Any, ...] | None = None

    def __post_init__(self) -> None:
        check_positive("mu_x", self.mu_x)
        check_positive("mu_y", self.mu_y)
        check("associated", self.associated, isinstance(self.associated, bool),
              "must be True (normality) or False (traction opposite the slip)")
        if self.frame is None:
            return
        frame = tuple(self.frame)
        check("frame", self.frame, len(frame) in (1, 2),
              "must hold the tangent vectors (t1, t2), or (t1,) in 2D")
        if _is_ufl(*frame):
            object.__setattr__(self, "frame", frame)
            return
        vectors = [np.asarray(t, dtype=float) for t in frame]
        gram = np.array([[a @ b for b in vectors] for a in vectors]) \
            if all(v.shape == vectors[0].shape and v.ndim == 1 for v in vectors) else None
        check("frame", self.frame,
              gram is not None and len(vectors[0]) in (2, 3)
              and np.allclose(gram, np.eye(len(vectors)), rtol=0, atol=1e-12),
              "the tangent vectors must be orthonormal, 2 or 3 components each")
        object.__setattr__(self, "frame", tuple(tuple(float(x) for x in v) for v in vectors))

    @property
    def mu_ref(self) -> float:
        """:math:`\\mu_{ref} = \\max(\\mu_x, \\mu_y)`: the bound :math:`c_T d^{m_T}` is
        :math:`\\mu_{ref} p_n`."""
        return max(self.mu_x, self.mu_y)

    def _coefficients(self, count: int) -> tuple[float, ...]:
        check("w", f"{count} tangent components", count in (1, 2),
              "the slip needs 1 or 2 components in the frame (give a frame for 3D vectors)")
        return (self.mu_x, self.mu_y)[:count]

    def coefficient(self, w: typing.Any) -> Scalar:
        """:math:`\\mu(\\theta)` along the tangent direction of ``w``: the radius of the slip
        surface there per unit p_n, :math:`|w| / |A^{-1} w|` (μ_ref at w = 0)."""
        components = _components(w, self.frame)
        mu = self._coefficients(len(components))
        r2 = sum(c**2 for c in components)
        s2 = sum((c / m) ** 2 for c, m in zip(components, mu, strict=True))
        if _is_ufl(s2):
            # a conditional, not a guarded ratio: at w = 0 the ratio's derivative is 0/0 (see
            # abs_c1_derivative), a conditional's unused branch is never evaluated
            return ufl.conditional(ufl.gt(s2, 0), ufl.sqrt(r2 / s2), self.mu_ref)
        return np.where(s2 > 0, np.sqrt(r2 / np.where(s2 > 0, s2, 1.0)), self.mu_ref)

    def slip_function(self, p: typing.Any, p_n: Scalar) -> Scalar:
        """Kalker's (1986, eq. 46) slip function
        :math:`g = \\sqrt{(p_1/\\mu_x)^2 + (p_2/\\mu_y)^2} - p_n` of the friction resistance
        :math:`p = -t` (≤ 0; = 0 on the slip surface)."""
        components = _components(p, self.frame)
        mu = self._coefficients(len(components))
        return _sqrt(sum((c / m) ** 2 for c, m in zip(components, mu, strict=True))) - p_n

    def traction(self, bound: Scalar, w: typing.Any, eps: Scalar,
                 regularisation: str = "c1") -> typing.Any:
        """The regularised traction on the body at slip velocity ``w``.

        Args:
            bound: the friction bound :math:`c_T d^{m_T} = \\mu_{ref} p_n`.
            w: the slip velocity: a UFL vector or a NumPy array (last axis: components), in
                the global frame when :attr:`frame` is given, else in (t1, t2).
            eps: regularisation parameter ε.
            regularisation: ``"c1"`` or ``"smooth"`` (:data:`REGULARISATIONS`).

        Returns:
            The traction, a vector like ``w`` (tangent to Γ_C).
        """
        components = _components(w, self.frame)
        scale = [m / self.mu_ref for m in self._coefficients(len(components))]
        if self.associated:
            # -∂D_ε/∂w with D_ε = bound φ_ε(A w / μ_ref): the chain rule's A / μ_ref
            z = [k * c for k, c in zip(scale, components, strict=True)]
            direction = [k * c for k, c in zip(scale, _direction(z, eps, regularisation),
                                                strict=True)]
        else:
            ratio = self.coefficient(w) / self.mu_ref
            direction = [ratio * c for c in _direction(components, eps, regularisation)]
        return -bound * _vector(direction, self.frame)


#: Either slip rule (the type of ``slip_rule`` arguments; ``None`` is Coulomb's isotropic law).
SlipRule = CoulombSlipRule | EllipticSlipRule
SLIP_RULES = (CoulombSlipRule, EllipticSlipRule)
"""The slip rules :func:`friction_traction` takes."""


# --- the interface tractions (Martins & Oden 1986, eqs. 1-2) --------------------------------------

def normal_traction(d: Scalar, c_n: Scalar, m_n: Scalar, approach_rate: Scalar = 0.0,
                    b_n: Scalar = 0.0, l_n: Scalar | None = None) -> Scalar:
    """Normal contact pressure on the body :math:`c_n d^{m_n} + b_n d^{l_n} \\dot d`.

    Args:
        d: penetration :math:`d \\ge 0` (see :func:`penetration`).
        c_n, m_n: normal compliance coefficient and exponent.
        approach_rate: :math:`\\dot u_n`, the normal velocity into the foundation.
        b_n, l_n: normal damping coefficient and exponent (``None``: ``m_n``).

    Returns:
        The elastic part (:func:`normal_pressure`) plus the damping part
        (:func:`normal_damping_pressure`), pushing the body out of the foundation when > 0.
    """
    return normal_pressure(d, c_n, m_n) \
        + normal_damping_pressure(d, approach_rate, b_n, m_n if l_n is None else l_n)


def is_speed_law(c_T: typing.Any) -> bool:
    """True when ``c_T`` is a function of the slip speed (UFL expressions are callable too)."""
    return callable(c_T) and not isinstance(c_T, ufl.core.expr.Expr)


def friction_traction(d: Scalar, w: typing.Any, c_T: typing.Any, m_T: Scalar, eps: Scalar,
                      regularisation: str = "c1", slip_rule: SlipRule | None = None
                      ) -> typing.Any:
    """Regularised friction traction on the body :math:`-c_T d^{m_T} \\phi_\\varepsilon'(w)`.

    Args:
        d: penetration.
        w: slip velocity :math:`\\dot u_T - U_T` (UFL vector, or NumPy scalars/arrays: one tangent
            direction).
        c_T: the friction coefficient of the bound, a number/UFL value (Coulomb: :math:`\\mu c_n`)
            or a callable of the slip speed :math:`|w|` (velocity-dependent μ, e.g.
            ``lambda s: c_n * StribeckFriction(...)(s)``).
        m_T: friction exponent.
        eps: regularisation parameter ε.
        regularisation: ``"c1"`` or ``"smooth"`` (:data:`REGULARISATIONS`).
        slip_rule: the slip surface and rule (:data:`SLIP_RULES`); ``None``: isotropic
            Coulomb, :class:`CoulombSlipRule`. An :class:`EllipticSlipRule` reads the bound
            :math:`c_T d^{m_T}` as :math:`\\mu_{ref} p_n`.

    Returns:
        The traction, a vector like ``w`` opposing the slip (Martins & Oden 1986, eq. 2), or
        the one of ``slip_rule``.
    """
    check("slip_rule", slip_rule, slip_rule is None or isinstance(slip_rule, SLIP_RULES),
          f"must be None or one of {', '.join(r.__name__ for r in SLIP_RULES)}")
    if is_speed_law(c_T):
        c_T = c_T(_norm(w))
    bound = friction_bound(d, c_T, m_T)
    if _is_ufl(bound):  # labelled, so that a solver can freeze or mollify it
        bound = ufl.classes.Variable(bound, FRICTION_BOUND)
    rule = CoulombSlipRule() if slip_rule is None else slip_rule
    return rule.traction(bound, w, eps, regularisation)


# --- velocity-dependent friction coefficients ---------------------------------------------------

@dataclasses.dataclass(frozen=True)
class ConstantFriction:
    """Coulomb's constant coefficient :math:`\\mu(v) = \\mu`."""

    mu: float

    def __post_init__(self) -> None:
        check("mu", self.mu, self.mu >= 0, "the friction coefficient must be >= 0")

    def __call__(self, speed: Scalar, pressure: Scalar = None) -> Scalar:
        """μ at relative velocity ``speed`` (any ``pressure``): the constant."""
        return self.mu + 0 * abs(speed)

    def derivative(self, speed: Scalar) -> np.ndarray:
        """dμ/dv at the signed relative velocity ``speed`` (NumPy): zero."""
        return 0.0 * np.asarray(speed, dtype=float)


@dataclasses.dataclass(frozen=True)
class PiecewiseLinearFriction:
    """:math:`\\mu = \\mu_s - s |v|` for :math:`|v| < v_c`, then constant: eq. 59 of
    "Friction-induced sliding instability in a multi-degree-of-freedom system with oscillatory
    normal forces" (2003).

    Defaults are the paper's: ``mu_s=0.75, slope=0.03, v_c=15`` (so :math:`\\mu_k = 0.3`).
    """

    mu_s: float = 0.75
    slope: float = 0.03
    v_c: float = 15.0

    def __post_init__(self) -> None:
        check("mu_s", self.mu_s, self.mu_s >= 0, "the static coefficient must be >= 0")
        check("v_c", self.v_c, self.v_c > 0, "the transition speed must be > 0")
        mu_k = self.mu_s - self.slope * self.v_c
        check("slope", self.slope, mu_k >= 0,
              f"mu_s - slope*v_c must be >= 0 (got {mu_k:g}): mu may not turn negative")

    def __call__(self, speed: Scalar, pressure: Scalar = None) -> Scalar:
        """μ at relative velocity ``speed`` (its magnitude is used: signed input is fine; any
        ``pressure``)."""
        return self.mu_s - self.slope * minimum(abs(speed), self.v_c)

    def derivative(self, speed: Scalar) -> np.ndarray:
        """dμ/dv at the signed relative velocity ``speed`` (NumPy).

        μ is even in v, so the derivative is odd: -slope sgn(v) below v_c, 0 above. At v = 0 and
        at |v| = v_c the one-sided values differ; the value returned there is 0.
        """
        v = np.asarray(speed, dtype=float)
        return np.where(np.abs(v) < self.v_c, -self.slope * np.sign(v), 0.0)


@dataclasses.dataclass(frozen=True)
class StribeckFriction:
    """Exponential Stribeck-type law.

    :math:`\\mu = \\mu_k + (\\mu_s-\\mu_k) e^{-(|v|/v_s)^\\delta}`.
    """

    mu_s: float
    mu_k: float
    v_s: float
    exponent: float = 1.0

    def __post_init__(self) -> None:
        check("mu_k", self.mu_k, self.mu_k >= 0, "the kinetic coefficient must be >= 0")
        check("mu_s", self.mu_s, self.mu_s >= 0, "the static coefficient must be >= 0")
        check("v_s", self.v_s, self.v_s > 0, "the Stribeck speed must be > 0")
        check("exponent", self.exponent, self.exponent > 0, "the exponent must be > 0")

    def __call__(self, speed: Scalar, pressure: Scalar = None) -> Scalar:
        """μ at relative velocity ``speed`` (its magnitude is used: signed input is fine; any
        ``pressure``)."""
        ratio = abs(speed) / self.v_s
        return self.mu_k + (self.mu_s - self.mu_k) * exp(-(ratio**self.exponent))

    def derivative(self, speed: Scalar) -> np.ndarray:
        """dμ/dv at the signed relative velocity ``speed`` (NumPy); 0 at v = 0."""
        v = np.asarray(speed, dtype=float)
        ratio = np.abs(v) / self.v_s
        with np.errstate(divide="ignore", invalid="ignore"):
            d = -(self.mu_s - self.mu_k) * self.exponent * ratio ** (self.exponent - 1) \
                * np.exp(-(ratio**self.exponent)) / self.v_s
        return np.where(v == 0, 0.0, d * np.sign(v))


FrictionCoefficient = ConstantFriction | PiecewiseLinearFriction | StribeckFriction


# --- operations valid on UFL, NumPy and the dual numbers of the derivatives --------------------

class _Dual:
    """A forward-mode dual number :math:`a + b\\,\\delta` (:math:`\\delta^2 = 0`) over NumPy
    arrays: a friction coefficient law evaluated on one carries its derivative along, so that
    :meth:`InterfaceLaw.friction_traction_derivatives` differentiates a user's μ(speed,
    pressure) without a derivative written by hand or a finite-difference step."""

    __array_ufunc__ = None  # NumPy defers to the operators below

    def __init__(self, value: typing.Any, slope: typing.Any):
        self.value, self.slope = np.asarray(value, dtype=float), np.asarray(slope, dtype=float)

    @staticmethod
    def lift(x: typing.Any) -> _Dual:
        return x if isinstance(x, _Dual) else _Dual(x, 0.0)

    def __add__(self, other: typing.Any) -> _Dual:
        o = _Dual.lift(other)
        return _Dual(self.value + o.value, self.slope + o.slope)

    __radd__ = __add__

    def __neg__(self) -> _Dual:
        return _Dual(-self.value, -self.slope)

    def __sub__(self, other: typing.Any) -> _Dual:
        return self + (-_Dual.lift(other))

    def __rsub__(self, other: typing.Any) -> _Dual:
        return _Dual.lift(other) - self

    def __mul__(self, other: typing.Any) -> _Dual:
        o = _Dual.lift(other)
        return _Dual(self.value * o.value, self.slope * o.value + self.value * o.slope)

    __rmul__ = __mul__

    def __truediv__(self, other: typing.Any) -> _Dual:
        o = _Dual.lift(other)
        return _Dual(self.value / o.value,
                     (self.slope * o.value - self.value * o.slope) / o.value**2)

    def __rtruediv__(self, other: typing.Any) -> _Dual:
        return _Dual.lift(other) / self

    def __pow__(self, exponent: typing.Any) -> _Dual:
        check("exponent", exponent, not isinstance(exponent, _Dual),
              "a dual number's exponent must be a number (write exp(b log a))")
        value = self.value**exponent
        with np.errstate(divide="ignore", invalid="ignore"):
            slope = np.where(self.slope == 0, 0.0,
                             exponent * self.value ** (exponent - 1) * self.slope)
        return _Dual(value, slope)

    def __rpow__(self, base: typing.Any) -> _Dual:
        return exp(self * np.log(base))

    def __abs__(self) -> _Dual:
        return _Dual(np.abs(self.value), np.sign(self.value) * self.slope)

    def exp(self) -> _Dual:
        e = np.exp(self.value)
        return _Dual(e, e * self.slope)

    def sqrt(self) -> _Dual:
        r = np.sqrt(self.value)
        with np.errstate(divide="ignore", invalid="ignore"):
            return _Dual(r, np.where(self.slope == 0, 0.0, self.slope / (2 * r)))

    def select(self, mask: typing.Any, other: typing.Any) -> _Dual:
        """``self`` where ``mask``, else ``other``."""
        o = _Dual.lift(other)
        return _Dual(np.where(mask, self.value, o.value), np.where(mask, self.slope, o.slope))


def _value(x: typing.Any) -> typing.Any:
    return x.value if isinstance(x, _Dual) else x


def exp(x: Scalar) -> Scalar:
    """:math:`e^x` of a UFL expression, a NumPy value or a dual number (write a user's
    friction coefficient law with it: :class:`InterfaceLaw`)."""
    if isinstance(x, _Dual):
        return x.exp()
    return _exp(x)


def sqrt(x: Scalar) -> Scalar:
    """:math:`\\sqrt{x}` of a UFL expression, a NumPy value or a dual number."""
    return x.sqrt() if isinstance(x, _Dual) else _sqrt(x)


def maximum(a: Scalar, b: Scalar) -> Scalar:
    """max(a, b) of UFL expressions, NumPy values or dual numbers."""
    if isinstance(a, _Dual) or isinstance(b, _Dual):
        a, b = _Dual.lift(a), _Dual.lift(b)
        return a.select(a.value >= b.value, b)
    return _max(a, b)


def minimum(a: Scalar, b: Scalar) -> Scalar:
    """min(a, b) of UFL expressions, NumPy values or dual numbers."""
    if isinstance(a, _Dual) or isinstance(b, _Dual):
        a, b = _Dual.lift(a), _Dual.lift(b)
        return a.select(a.value <= b.value, b)
    return _min(a, b)


# --- the interface law: one object, its tractions and their derivatives --------------------------

FrictionLaw: typing.TypeAlias = typing.Callable[[typing.Any, typing.Any], typing.Any]
"""A friction coefficient μ(speed, pressure): the built-in laws, or a user's function."""


@dataclasses.dataclass(frozen=True)
class InterfaceLaw:
    """The interface law of Martins & Oden (1986, eqs. 1-2): normal compliance, normal damping
    and regularised friction on :math:`\\Gamma_C`, the one object every model with an interface
    takes.

    Tractions on the body at penetration :math:`d` and slip velocity :math:`w`:

    * normal: :math:`p = c_n d^{m_n} + b_n d^{l_n} \\dot d` (:meth:`normal_traction`);
    * friction: :math:`t = -c_n \\mu(|w|, p_e)\\, d^{m_T} \\phi_\\varepsilon'(w)`, the bound
      :math:`c_T d^{m_T}` with :math:`c_T = \\mu c_n` (:meth:`friction_traction`), where
      :math:`p_e = c_n d^{m_n}` is the elastic pressure and μ the constant ``mu`` or the law
      ``friction_coefficient``; with an :class:`EllipticSlipRule` the bound is
      :math:`\\mu_{ref} c_n d^{m_T}` and the rule shapes the traction.

    Each method takes UFL (forms) or NumPy (reduced models, post-processing) input and returns
    the same kind; the NumPy derivatives (:meth:`normal_traction_derivatives`,
    :meth:`friction_traction_derivatives`) differentiate a friction coefficient law with dual
    numbers, so a user's law needs no derivative (see docs/user-law.md).

    A finite element model hands the law its ``fem.Constant`` values with :meth:`replace`
    (``law.replace(mu=mu_constant, c_n=...)``): UFL values are not validated, the others are.

    Args:
        c_n: normal compliance coefficient [force / length^(2+m_n)] (pressure per d^m_n), > 0
            (default: the block of Martins & Oden 1986, eq. 36, in 10^3 kg cm^(-1-m_n) s^-2).
        m_n: normal compliance exponent [-], >= 1 (experiments: 2 to 3.33).
        mu: friction coefficient c_T / c_n [-], >= 0 (Coulomb when m_T = m_n and b_n = 0).
        m_T: friction exponent [-], >= 1; ``None`` means m_T = m_n (Coulomb).
        b_n: normal damping coefficient [force time / length^(3+l_n)], >= 0.
        l_n: normal damping exponent [-], >= 1; ``None`` means l_n = m_n.
        g: initial gap [length], >= 0.
        eps: regularisation parameter ε of |u̇_T - U_T| [length / time], > 0.
        regularisation: ``"c1"`` (φ_ε, Pop, eq. 15) or ``"smooth"`` (ψ_ε, Kalker 1986, eq. 40).
        friction_coefficient: μ(speed, pressure) replacing ``mu``: a law of this module
            (:class:`ConstantFriction`, :class:`StribeckFriction`,
            :class:`PiecewiseLinearFriction`) or a user's function of the slip speed |w| and
            the elastic pressure :math:`c_n d^{m_n}` written with operations valid on UFL and
            NumPy (``+ - * / **``, :func:`exp`, :func:`sqrt`, :func:`maximum`,
            :func:`minimum`, ``abs``).
        slip_rule: the slip surface and rule (:data:`SLIP_RULES`); ``None``: isotropic Coulomb.
    """

    c_n: Scalar = 1e10
    m_n: float = 2.5
    mu: Scalar = 0.0
    m_T: float = None  # type: ignore[assignment]  # None: set by __post_init__
    b_n: Scalar = 0.0
    l_n: float = None  # type: ignore[assignment]  # None: set by __post_init__
    g: Scalar = 0.0
    eps: Scalar = 1e-3
    regularisation: str = "c1"
    friction_coefficient: FrictionLaw | None = None
    slip_rule: SlipRule | None = None

    def __post_init__(self) -> None:
        if self.m_T is None:
            object.__setattr__(self, "m_T", self.m_n)
        if self.l_n is None:
            object.__setattr__(self, "l_n", self.m_n)
        self.validate()

    def validate(self) -> None:
        """Check every parameter; raise ``ValueError`` naming the first bad one. UFL values
        (a model's ``fem.Constant``) are left to the model."""
        for name in ("c_n", "m_n", "mu", "m_T", "b_n", "l_n", "g", "eps"):
            value = getattr(self, name)
            if _is_ufl(value):
                continue
            check(name, value, isinstance(value, numbers.Real) and math.isfinite(value),
                  "must be a finite real number")
        numeric = {name: getattr(self, name) for name in ("c_n", "mu", "b_n", "g", "eps")
                   if not _is_ufl(getattr(self, name))}
        check("c_n", self.c_n, numeric.get("c_n", 1.0) > 0,
              "the normal compliance coefficient must be > 0")
        check("m_n", self.m_n, self.m_n >= 1, "the normal exponent must be >= 1")
        check("m_T", self.m_T, self.m_T >= 1, "the friction exponent must be >= 1")
        check("mu", self.mu, numeric.get("mu", 0.0) >= 0, "the friction coefficient must be >= 0")
        check("b_n", self.b_n, numeric.get("b_n", 0.0) >= 0,
              "the normal damping coefficient must be >= 0")
        check("l_n", self.l_n, self.l_n >= 1, "the damping exponent must be >= 1")
        check("g", self.g, numeric.get("g", 0.0) >= 0, "the initial gap must be >= 0")
        check("eps", self.eps, numeric.get("eps", 1.0) > 0,
              "the regularisation parameter must be > 0")
        check("regularisation", self.regularisation, self.regularisation in REGULARISATIONS,
              f"must be one of {sorted(REGULARISATIONS)}")
        check("friction_coefficient", self.friction_coefficient,
              self.friction_coefficient is None or callable(self.friction_coefficient),
              "must be None or a function mu(speed, pressure)")
        check("slip_rule", self.slip_rule,
              self.slip_rule is None or isinstance(self.slip_rule, SLIP_RULES),
              f"must be None or one of {', '.join(r.__name__ for r in SLIP_RULES)}")

    def replace(self, **changes: typing.Any) -> InterfaceLaw:
        """A copy with ``changes`` (validated; UFL values, e.g. a model's ``fem.Constant``,
        are taken as they are)."""
        return dataclasses.replace(self, **changes)

    @property
    def coulomb(self) -> bool:
        """True when the law is Coulomb's: m_T = m_n, no normal damping, constant μ."""
        return self.m_T == self.m_n and self.b_n == 0 and self.friction_coefficient is None

    @property
    def has_friction(self) -> bool:
        """True unless μ = 0 with no friction coefficient law or slip rule."""
        return not (isinstance(self.mu, numbers.Real) and self.mu == 0) \
            or self.friction_coefficient is not None or self.slip_rule is not None

    @property
    def c_T(self) -> Scalar:
        """The constant friction coefficient of the bound :math:`c_T = \\mu c_n`
        (:math:`\\mu_{ref} c_n` with an :class:`EllipticSlipRule`)."""
        if isinstance(self.slip_rule, EllipticSlipRule):
            return self.slip_rule.mu_ref * self.c_n
        return self.mu * self.c_n

    def uniform_penetration(self, pressure: float) -> float:
        """Penetration under a uniform pressure p: d = (p / c_n)^(1/m_n) (no damping)."""
        check("pressure", pressure, pressure >= 0, "must be >= 0")
        return (pressure / self.c_n) ** (1.0 / self.m_n)

    # --- tractions (UFL or NumPy) ----------------------------------------------------------------
    def pressure(self, d: Scalar) -> Scalar:
        """Elastic normal pressure :math:`c_n d^{m_n}` (:func:`normal_pressure`)."""
        return normal_pressure(d, self.c_n, self.m_n)

    def damping_pressure(self, d: Scalar, approach_rate: Scalar) -> Scalar:
        """Normal damping :math:`b_n d^{l_n} \\dot d` (:func:`normal_damping_pressure`)."""
        return normal_damping_pressure(d, approach_rate, self.b_n, self.l_n)

    def normal_traction(self, d: Scalar, approach_rate: Scalar = 0.0) -> Scalar:
        """Normal pressure on the body :math:`c_n d^{m_n} + b_n d^{l_n} \\dot d`
        (:func:`fenicsfriction.laws.normal_traction`)."""
        return normal_traction(d, self.c_n, self.m_n, approach_rate, self.b_n, self.l_n)

    def coefficient(self, speed: Scalar, pressure: Scalar) -> Scalar:
        """μ at slip speed ``speed`` and elastic pressure ``pressure``."""
        if self.friction_coefficient is None:
            return self.mu + 0 * speed
        return self.friction_coefficient(speed, pressure)

    def coefficient_slope(self, speed: typing.Any, pressure: typing.Any) -> np.ndarray:
        """∂μ/∂speed at ``speed`` >= 0 and ``pressure`` (NumPy): a law's own ``derivative``
        where it has one (the laws of this module), else the law evaluated on dual numbers
        (a user's function needs no derivative)."""
        law = self.friction_coefficient
        if law is None:
            return 0.0 * np.asarray(speed, dtype=float)
        derivative = getattr(law, "derivative", None)
        if derivative is not None:
            return derivative(speed)
        return _Dual.lift(law(_Dual(speed, 1.0), pressure)).slope

    def direction(self, w: typing.Any) -> typing.Any:
        """The regularised direction :math:`\\phi_\\varepsilon'(w)` of the slip ``w`` (UFL
        vector or NumPy), of the law's regularisation and ε (:data:`REGULARISATIONS`)."""
        return REGULARISATIONS[self.regularisation][1](w, self.eps)

    def friction_force(self, normal_force: typing.Any, w: typing.Any) -> typing.Any:
        """The regularised friction force of a point contact pressed with the normal force
        ``normal_force`` N at slip velocity ``w`` (NumPy, one tangent direction):
        :math:`-\\mu(|w|, N)\\, N\\, \\phi_\\varepsilon'(w)`, the traction of
        :meth:`friction_traction` with the bound μN of a mesh-free model (the compliance
        c_n, m_n is not used: N is the model's own; μ reads N as its pressure)."""
        return -self.coefficient(abs(w), normal_force) * normal_force * self.direction(w)

    def _c_T(self, d: Scalar) -> typing.Any:
        """c_T of :func:`fenicsfriction.laws.friction_traction`: μ c_n, or c_n μ(|w|, p_e) as a
        function of the slip speed."""
        if self.friction_coefficient is None:
            return self.c_T
        law, pressure = self.friction_coefficient, self.pressure(d)
        return lambda speed: self.c_n * law(speed, pressure)

    def friction_bound(self, d: Scalar, speed: Scalar = 0.0) -> Scalar:
        """The friction bound :math:`c_T d^{m_T}` at slip speed ``speed``
        (:func:`fenicsfriction.laws.friction_bound`)."""
        c_T = self._c_T(d)
        return friction_bound(d, c_T(speed) if is_speed_law(c_T) else c_T, self.m_T)

    def friction_traction(self, d: Scalar, w: typing.Any) -> typing.Any:
        """Regularised friction traction on the body at penetration ``d`` and slip velocity
        ``w`` (UFL vector, or NumPy: one tangent direction), the bound labelled
        :data:`FRICTION_BOUND` (:func:`fenicsfriction.laws.friction_traction`)."""
        return friction_traction(d, w, self._c_T(d), self.m_T, self.eps, self.regularisation,
                                 self.slip_rule)

    def stick_curvature(self) -> Scalar:
        """:math:`\\phi_\\varepsilon''(0)` of the regularisation (1/ε for both): inside the band
        the friction traction is the tangential damping
        :math:`c_T(0) d^{m_T} \\phi_\\varepsilon''(0)` (:meth:`friction_bound` at zero speed)."""
        return REGULARISATIONS[self.regularisation][2](0.0, self.eps)

    # --- NumPy derivatives (reduced models' linearisations) -------------------------------------
    def normal_traction_derivatives(self, d: typing.Any, approach_rate: typing.Any = 0.0
                                    ) -> tuple[np.ndarray, np.ndarray]:
        """(∂p/∂d, ∂p/∂ḋ) of :meth:`normal_traction` (NumPy, d > 0)."""
        mn, ln = self.m_n, self.l_n
        dp_dd = mn * self.c_n * d ** (mn - 1) + ln * self.b_n * d ** (ln - 1) * approach_rate
        return dp_dd, self.b_n * d**ln

    def friction_traction_derivatives(self, d: typing.Any, w: typing.Any
                                      ) -> tuple[np.ndarray, np.ndarray]:
        """(∂t/∂d, ∂t/∂w) of :meth:`friction_traction` for a scalar slip ``w`` (one tangent
        direction, NumPy, d > 0). A friction coefficient law is differentiated exactly by
        evaluating it on dual numbers; the slip rule must be Coulomb's."""
        check("slip_rule", self.slip_rule,
              self.slip_rule is None or isinstance(self.slip_rule, CoulombSlipRule),
              "the NumPy derivatives are those of the isotropic (Coulomb) rule")
        _, first, second = REGULARISATIONS[self.regularisation]
        dphi, ddphi = first(w, self.eps), second(w, self.eps)
        mT = self.m_T
        if self.friction_coefficient is None:
            c_T = self.c_T
            return -mT * c_T * d ** (mT - 1) * dphi, -c_T * d**mT * ddphi
        law, speed, pressure = self.friction_coefficient, np.abs(w), self.pressure(d)
        mu = _value(law(speed, pressure))
        dmu_ds = _Dual.lift(law(_Dual(speed, 1.0), pressure)).slope
        dmu_dp = _Dual.lift(law(speed, _Dual(pressure, 1.0))).slope
        dp_dd = self.m_n * self.c_n * d ** (self.m_n - 1)
        dt_dd = -self.c_n * (dmu_dp * dp_dd * d**mT + mu * mT * d ** (mT - 1)) * dphi
        dt_dw = -self.c_n * d**mT * (dmu_ds * np.sign(w) * dphi + mu * ddphi)
        return dt_dd, dt_dw
