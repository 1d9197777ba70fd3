r"""Elastic interaction of contacts on the surface of an elastic half-space.

Contacts :math:`i = 1..N` at surface points :math:`\mathbf r_i` act on the substrate with forces
:math:`\mathbf f_i`; the surface displaces by :math:`\mathbf u_i = \sum_j G_{ij}\mathbf f_j`.
:math:`G` is the Boussinesq-Cerruti Green tensor of a half-space (Landau & Lifshitz 1986,
*Theory of elasticity*, §8, eq. 8.19) on its surface :math:`z = 0`; with
:math:`g(r) = (1+\sigma)/(2\pi E r)`, :math:`\mathbf r = \mathbf r_i - \mathbf r_j`
(Braun (slides), "Interaction between contacts", eq. 1):

.. math::

    G_{ix,jx} = 2g\,[(1-\sigma) + \sigma x^2/r^2], \quad
    G_{iy,jy} = 2g\,[(1-\sigma) + \sigma y^2/r^2], \quad
    G_{ix,jy} = 2g\,\sigma x y/r^2,

    G_{iz,jz} = 2g\,(1-\sigma), \quad
    G_{iz,jx} = -g\,(1-2\sigma)\,x/r, \quad G_{ix,jz} = +g\,(1-2\sigma)\,x/r,

:math:`z` the *outward* normal of the substrate (the substrate fills :math:`z < 0`; Landau &
Lifshitz take :math:`z` into the medium, which flips the sign of the two normal-tangential
couplings). :math:`G` is symmetric, :math:`G_{i\alpha,j\beta} = G_{j\beta,i\alpha}`.

**Self term.** :math:`G(r)` diverges at :math:`r = 0`; a contact of radius :math:`a_c` is
modelled as a uniformly loaded disc and :math:`G_{ii}` is the displacement of its centre,
:math:`G_{ii} = \int_{\text{disc}} G(\mathbf r)\,dA/(\pi a_c^2)`:

.. math::

    G_{ix,ix} = G_{iy,iy} = \frac{(1+\sigma)(2-\sigma)}{\pi E a_c}, \qquad
    G_{iz,iz} = \frac{2(1-\sigma^2)}{\pi E a_c},

the second being Johnson's centre displacement under a uniform pressure (Johnson 1985,
*Contact mechanics*, §3.4); the off-diagonal self terms vanish by symmetry.

**Forces and the response to a break.** Contact :math:`i` is a spring :math:`k_i` stretched by
the prescribed :math:`U_0` less the substrate's displacement, :math:`F = K(U_0 - G F)`, so
(Braun (slides), "Interaction between contacts")

.. math::

    F = B K U_0, \quad B = (1 + K G)^{-1}, \qquad
    \delta F = B\,\delta K\,(1 - G B K)\,U_0 ,

:math:`\delta F` to first order in :math:`\delta K`; a break of contact :math:`i^*` is
:math:`\delta K = -k` on its three components. As :math:`(1 - GBK)U_0 = U_0 - GF` is the
stretching of the springs, :math:`\delta F = B\,\delta K\,(U_0 - G F)`: one solve with
:math:`1 + KG`. On a square lattice of spacing :math:`a` the response decays as :math:`r^{-1}`
(:math:`\delta F \approx \delta K\,G`) below the elastic correlation length
:math:`\lambda_c = a^2 E/k` and as :math:`r^{-3}` beyond it, where the other contacts screen
the break (Braun (slides), "Interaction between contacts: results"; Caroli & Nozières 1998).
"""

from __future__ import annotations

import dataclasses
import math
import typing

import numpy as np
import numpy.typing as npt
import scipy.linalg
import scipy.sparse.linalg

from fenicsfriction.laws import check, check_positive

__all__ = [
    "LatticeInteraction",
    "PowerLawFit",
    "break_response",
    "contact_forces",
    "correlation_length",
    "fit_power_laws",
    "green_tensor",
    "interaction_matrix",
    "radial_profile",
    "self_compliance",
]

Array: typing.TypeAlias = npt.NDArray[np.float64]


def _check_material(E: float, nu: float) -> None:
    check_positive("E", E)
    check("nu", nu, isinstance(nu, (int, float)) and -1.0 < nu < 0.5,
          "Poisson's ratio must lie in (-1, 0.5)")


def green_tensor(separation: npt.ArrayLike, E: float, nu: float) -> Array:
    """The surface Green tensor :math:`G(\\mathbf r)`, 3×3, for separations ``r = r_i - r_j``.

    Args:
        separation: ``(..., 2)`` in-plane separations, all non-zero.
        E: Young's modulus of the substrate (Pa).
        nu: its Poisson's ratio σ, in (-1, 0.5).

    Returns:
        ``(..., 3, 3)``: ``G[..., α, β]`` is the displacement α at ``r_i`` per unit force β at
        ``r_j`` (m/N); the module docstring gives the formulas.
    """
    _check_material(E, nu)
    d = np.asarray(separation, dtype=float)
    check("separation", d.shape, d.ndim >= 1 and d.shape[-1] == 2, "the last axis must be (x, y)")
    r = np.hypot(d[..., 0], d[..., 1])
    check("separation", "a zero separation", bool(np.all(r > 0)),
          "every separation must be non-zero (the self term is self_compliance)")
    g = (1 + nu) / (2 * math.pi * E * r)
    cx, cy = d[..., 0] / r, d[..., 1] / r
    G = np.empty((*d.shape[:-1], 3, 3))
    G[..., 0, 0] = 2 * g * ((1 - nu) + nu * cx**2)
    G[..., 1, 1] = 2 * g * ((1 - nu) + nu * cy**2)
    G[..., 0, 1] = G[..., 1, 0] = 2 * g * nu * cx * cy
    G[..., 2, 2] = 2 * g * (1 - nu)
    G[..., 2, 0], G[..., 2, 1] = -g * (1 - 2 * nu) * cx, -g * (1 - 2 * nu) * cy
    G[..., 0, 2], G[..., 1, 2] = -G[..., 2, 0], -G[..., 2, 1]
    return G


def self_compliance(contact_radius: float, E: float, nu: float) -> Array:
    """The self term :math:`G_{ii}`: centre displacement of a uniformly loaded disc, 3×3."""
    _check_material(E, nu)
    check_positive("contact_radius", contact_radius)
    tangential = (1 + nu) * (2 - nu) / (math.pi * E * contact_radius)
    normal = 2 * (1 - nu**2) / (math.pi * E * contact_radius)
    return np.diag([tangential, tangential, normal])


def interaction_matrix(positions: npt.ArrayLike, E: float, nu: float,
                       contact_radius: float) -> Array:
    """The dense interaction matrix :math:`G` of contacts at ``positions``.

    Args:
        positions: ``(N, 2)`` distinct surface points (m).
        E: Young's modulus (Pa).
        nu: Poisson's ratio.
        contact_radius: radius of a contact, for the self term (m).

    Returns:
        ``(3N, 3N)``, row ``3 i + α``, column ``3 j + β`` (x, y, z components).
    """
    p = np.asarray(positions, dtype=float)
    check("positions", p.shape, p.ndim == 2 and p.shape[1] == 2 and len(p) > 0,
          "must be an (N, 2) array of surface points")
    n = len(p)
    d = p[:, None, :] - p[None, :, :]
    off = ~np.eye(n, dtype=bool)
    blocks = np.empty((n, n, 3, 3))
    blocks[off] = green_tensor(d[off], E, nu)
    blocks[~off] = self_compliance(contact_radius, E, nu)
    return blocks.transpose(0, 2, 1, 3).reshape(3 * n, 3 * n)


def _stiffness_vector(stiffness: float | npt.ArrayLike, n: int) -> Array:
    k = np.broadcast_to(np.asarray(stiffness, dtype=float), (n,))
    check("stiffness", stiffness, bool(np.all(np.isfinite(k)) and np.all(k > 0)),
          "contact stiffnesses must be finite and > 0")
    return np.repeat(k, 3)


def _displacements(U0: npt.ArrayLike, n: int) -> Array:
    u = np.broadcast_to(np.asarray(U0, dtype=float), (n, 3))
    return np.array(u).reshape(3 * n)


def contact_forces(G: Array, stiffness: float | npt.ArrayLike, U0: npt.ArrayLike) -> Array:
    """:math:`F = (1 + KG)^{-1} K U_0`, the contacts' forces on the substrate.

    Args:
        G: ``(3N, 3N)`` interaction matrix (:func:`interaction_matrix`).
        stiffness: the contacts' stiffness k (N/m), one value or ``(N,)``.
        U0: the prescribed stretching, ``(3,)`` for all contacts or ``(N, 3)`` (m).

    Returns:
        ``(N, 3)`` forces (N).
    """
    n = G.shape[0] // 3
    k = _stiffness_vector(stiffness, n)
    A = np.eye(3 * n) + k[:, None] * G
    forces = np.linalg.solve(A, k * _displacements(U0, n))
    return np.asarray(forces, dtype=np.float64).reshape(n, 3)


def break_response(G: Array, stiffness: float | npt.ArrayLike, U0: npt.ArrayLike,
                   broken: int) -> Array:
    """:math:`\\delta F = B\\,\\delta K\\,(1 - GBK)\\,U_0` for the break of contact ``broken``.

    Args:
        G: ``(3N, 3N)`` interaction matrix.
        stiffness: k (N/m), one value or ``(N,)``.
        U0: prescribed stretching, ``(3,)`` or ``(N, 3)`` (m).
        broken: index of the breaking contact (``δK = -k`` on its three components).

    Returns:
        ``(N, 3)`` force changes, to first order in δK (N).
    """
    n = G.shape[0] // 3
    check("broken", broken, isinstance(broken, (int, np.integer)) and 0 <= broken < n,
          f"must be a contact index in [0, {n})")
    k = _stiffness_vector(stiffness, n)
    lu = scipy.linalg.lu_factor(np.eye(3 * n) + k[:, None] * G)
    BK = scipy.linalg.lu_solve(lu, np.diag(k))
    dK = np.zeros(3 * n)
    dK[3 * broken:3 * broken + 3] = -k[3 * broken:3 * broken + 3]
    stretching = _displacements(U0, n) - G @ (BK @ _displacements(U0, n))
    return scipy.linalg.lu_solve(lu, dK * stretching).reshape(n, 3)


def correlation_length(spacing: float, E: float, stiffness: float) -> float:
    """:math:`\\lambda_c = a^2 E/k`, the elastic correlation length (Braun (slides))."""
    check_positive("spacing", spacing)
    check_positive("E", E)
    check_positive("stiffness", stiffness)
    return spacing**2 * E / stiffness


@dataclasses.dataclass
class LatticeInteraction:
    """Contacts of equal stiffness on an ``n × n`` square lattice, solved matrix-free.

    :math:`G` between lattice sites depends on the offset only (block-Toeplitz with Toeplitz
    blocks), so :math:`G x` is a convolution, done by FFT on a ``2n × 2n`` circulant embedding
    in :math:`O(n^2 \\log n)`; :math:`1 + kG` (symmetric positive definite: :math:`G` is the
    compliance of the half-space) is solved by conjugate gradients. Contact ``(i, j)`` sits at
    ``(i a, j a)``; flat index ``i n + j``.

    Attributes:
        n: contacts per side.
        spacing: lattice spacing a (m).
        E: Young's modulus (Pa).
        nu: Poisson's ratio.
        stiffness: contact stiffness k (N/m).
        contact_radius: radius of a contact for the self term (m).
        rtol: relative tolerance of conjugate gradients.
    """

    n: int
    spacing: float
    E: float
    nu: float
    stiffness: float
    contact_radius: float
    rtol: float = 1e-10
    _kernel: npt.NDArray[np.complex128] = dataclasses.field(init=False, repr=False)

    def __post_init__(self) -> None:
        check("n", self.n, isinstance(self.n, int) and self.n >= 2, "must be an integer >= 2")
        check_positive("spacing", self.spacing)
        check_positive("stiffness", self.stiffness)
        check_positive("rtol", self.rtol)
        offsets = np.fft.fftfreq(2 * self.n, d=1.0 / (2 * self.n))  # 0, 1, .., n, -(n-1), .., -1
        dx, dy = np.meshgrid(offsets * self.spacing, offsets * self.spacing, indexing="ij")
        d = np.stack([dx, dy], axis=-1)
        nonzero = np.hypot(dx, dy) > 0
        blocks = np.zeros((2 * self.n, 2 * self.n, 3, 3))
        blocks[nonzero] = green_tensor(d[nonzero], self.E, self.nu)
        blocks[0, 0] = self_compliance(self.contact_radius, self.E, self.nu)
        self._kernel = np.fft.rfft2(blocks, axes=(0, 1))

    @property
    def positions(self) -> Array:
        """``(n², 2)`` contact positions (m)."""
        i, j = np.meshgrid(np.arange(self.n), np.arange(self.n), indexing="ij")
        return self.spacing * np.stack([i.ravel(), j.ravel()], axis=1).astype(float)

    @property
    def correlation_length(self) -> float:
        """:math:`\\lambda_c = a^2 E/k` (m)."""
        return correlation_length(self.spacing, self.E, self.stiffness)

    def apply_green(self, forces: Array) -> Array:
        """:math:`G F` for ``(n², 3)`` forces: the surface displacements ``(n², 3)``."""
        m = self.n
        padded = np.zeros((2 * m, 2 * m, 3))
        padded[:m, :m] = forces.reshape(m, m, 3)
        spectrum = np.einsum("pqab,pqb->pqa", self._kernel, np.fft.rfft2(padded, axes=(0, 1)))
        full = np.fft.irfft2(spectrum, s=(2 * m, 2 * m), axes=(0, 1))
        return full[:m, :m].reshape(m * m, 3)

    def solve(self, rhs: Array) -> Array:
        """:math:`(1 + kG)^{-1}` applied to ``(n², 3)`` ``rhs``."""
        size = 3 * self.n**2
        op = scipy.sparse.linalg.LinearOperator(
            (size, size), dtype=float,
            matvec=lambda x: x + self.stiffness * self.apply_green(x.reshape(-1, 3)).ravel())
        x, info = scipy.sparse.linalg.cg(op, rhs.ravel(), **_cg_tolerance(self.rtol))
        check("rtol", self.rtol, info == 0, f"conjugate gradients did not converge (info={info})")
        return x.reshape(-1, 3)

    def forces(self, U0: npt.ArrayLike) -> Array:
        """:math:`F = B k U_0` for a uniform ``U0`` ``(3,)`` or ``(n², 3)``: ``(n², 3)`` (N)."""
        return self.solve(self.stiffness * _displacements(U0, self.n**2).reshape(-1, 3))

    def break_response(self, U0: npt.ArrayLike, broken: int) -> Array:
        """:math:`\\delta F = B\\,\\delta K\\,(U_0 - GF)` after ``broken`` breaks: ``(n², 3)``."""
        check("broken", broken, isinstance(broken, (int, np.integer)) and 0 <= broken < self.n**2,
              f"must be a contact index in [0, {self.n**2})")
        U = _displacements(U0, self.n**2).reshape(-1, 3)
        stretching = U[broken] - self.apply_green(self.forces(U))[broken]
        source = np.zeros_like(U)
        source[broken] = -self.stiffness * stretching
        return self.solve(source)


def _cg_tolerance(rtol: float) -> dict[str, float]:
    """``rtol=`` for SciPy >= 1.12, ``tol=`` before (Debian 12 ships 1.10)."""
    import inspect
    name = "rtol" if "rtol" in inspect.signature(scipy.sparse.linalg.cg).parameters else "tol"
    return {name: rtol, "atol": 0.0}


def radial_profile(positions: npt.ArrayLike, response: npt.ArrayLike, broken: int,
                   edges: npt.ArrayLike) -> tuple[Array, Array]:
    """|δF| against the distance from the broken contact, averaged in distance bins.

    Geometric means (of r and of |δF|) per bin, the natural average for a power law; empty
    bins are dropped.

    Args:
        positions: ``(N, 2)`` contact positions (m).
        response: ``(N, 3)`` force changes (N).
        broken: index of the broken contact (excluded).
        edges: increasing bin edges (m); contacts outside ``[edges[0], edges[-1])`` are dropped.

    Returns:
        ``(r, |δF|)`` per non-empty bin.
    """
    p, edges = np.asarray(positions, dtype=float), np.asarray(edges, dtype=float)
    r = np.linalg.norm(p - p[broken], axis=1)
    magnitude = np.linalg.norm(np.asarray(response, dtype=float), axis=1)
    keep = (r >= edges[0]) & (r < edges[-1]) & (magnitude > 0)
    which = np.digitize(r[keep], edges)
    bins = [which == b for b in np.unique(which)]
    return (np.array([np.exp(np.log(r[keep][s]).mean()) for s in bins]),
            np.array([np.exp(np.log(magnitude[keep][s]).mean()) for s in bins]))


@dataclasses.dataclass(frozen=True)
class PowerLawFit:
    """Two power laws :math:`c r^{p}` fitted below and above the correlation length.

    Attributes:
        near_exponent: exponent fitted on ``r < near_limit``.
        far_exponent: exponent fitted on ``r > far_limit``.
        near_prefactor: prefactor of the near law.
        far_prefactor: prefactor of the far law.
        crossover: where the two fitted laws meet (m).
    """

    near_exponent: float
    far_exponent: float
    near_prefactor: float
    far_prefactor: float
    crossover: float


def fit_power_laws(r: npt.ArrayLike, f: npt.ArrayLike, near_limit: float,
                   far_limit: float) -> PowerLawFit:
    """Least-squares lines in log-log on ``r < near_limit`` and ``r > far_limit``.

    Args:
        r: distances (m), > 0.
        f: magnitudes at those distances, > 0.
        near_limit: upper end of the near range.
        far_limit: lower end of the far range.

    Returns:
        The two fitted laws and the distance at which they cross.
    """
    r, f = np.asarray(r, dtype=float), np.asarray(f, dtype=float)
    check("f", "non-positive values", bool(np.all(f > 0) and np.all(r > 0)),
          "distances and magnitudes must be > 0 for a log-log fit")
    near, far = r < near_limit, r > far_limit
    check("near_limit", near_limit, near.sum() >= 2, "must leave at least two near points")
    check("far_limit", far_limit, far.sum() >= 2, "must leave at least two far points")
    p_near, c_near = np.polyfit(np.log(r[near]), np.log(f[near]), 1)
    p_far, c_far = np.polyfit(np.log(r[far]), np.log(f[far]), 1)
    crossover = math.exp((c_far - c_near) / (p_near - p_far))
    return PowerLawFit(float(p_near), float(p_far), math.exp(c_near), math.exp(c_far), crossover)
