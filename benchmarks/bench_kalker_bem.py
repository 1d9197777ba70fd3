r"""Kalker's creep coefficients C11, C22, C23, C33 by an independent boundary-element solution.

Kalker's linear theory of rolling contact (full adhesion: no slip anywhere in the ellipse) for
quasi-identical bodies on the elastic half-space, solved the way CONTACT solves "steady state
rolling, no slip" (Kalker 1990, ch. 5; Vollebregt's CONTACT user guide):

* the ellipse (semi-axes a along the rolling direction x, b lateral) on a uniform grid of
  rectangular elements, a/n by b/n (n elements per semi-axis), the elements whose centre lies
  inside it; piecewise-constant tangential tractions px, py;
* influence numbers: the relative tangential surface displacement of the two bodies at an
  element's centre under a unit uniform traction on a rectangle, the integral of the Cerruti
  point-load solution (Johnson 1985, eq. 3.86; Kalker 1990, ch. 5),

  .. math::

      u_i = \frac{1}{\pi G}\int\!\!\int \Big(\frac{1-\nu}{r}\,\delta_{ij}
            + \nu\,\frac{x_i x_j}{r^3}\Big)\, p_j \,\mathrm{d}A ,

  in closed form through the primitives  X ln(Y + R) + Y ln(X + R)  (of 1/r),  Y ln(X + R)
  (of x²/r³),  X ln(Y + R)  (of y²/r³) and  −R  (of xy/r³), checked here against a Gauss
  quadrature of the point-load kernel for a far element and the element's own centre;
* steady rolling without slip (Kalker's signs: the leading edge at x = +a, material flowing
  towards −x): the slip s = (ξ − φy, η + φx) − ∂u/∂x vanishes at every element's centre, with
  ∂u/∂x the first-order upwind difference (u(x + a/n) − u(x))/(a/n) along each row, the
  displacement at the upwind point given by the same influence numbers (outside the ellipse
  it is the displacement of the free surface under the tractions inside; see
  ``leading_edge`` of :func:`dense_matrix`);
* the system for (px, py) solved for unit ξ, η, φ; then with G = 1, c = √(ab) = 1
  C11 = −Fx/ξ, C22 = −Fy/η, C23 = −Fy/φ (and Mz/η: the same by reciprocity on the grid
  symmetric about the centre), C33 = −Mz/φ (the package's Fx = −G c² C11 ξ,
  Fy = −G c² (C22 η + c C23 φ), Mz = −G c³ (−C23 η + c C33 φ)).

Two solvers of the same discrete system. Dense (:func:`solve`, ``--method dense``): the half
y > 0, split by the symmetry y → −y (ξ: px even, py odd in y; η and φ: px odd, py even),
by LU; n <= 48 or so (3,616 unknown pairs, 2 GB). Matrix-free (:func:`solve_fft`, the
default): on the regular grid the influence numbers depend on the index offsets only, so the
upwind difference of the displacement is a 2D linear convolution of the tractions with the
differenced influence numbers, computed by real FFTs on a zero-padded box twice the
ellipse's bounding box (:class:`FFTOperator`); the whole ellipse, no symmetry split, so the
grid may be shifted by a fraction of a cell relative to the ellipse's centre (``--offsets``).
GMRES (restart 200) to the relative residual ``--rtol``, preconditioned by the operator's
row-by-row part (each grid row coupled to itself only: Toeplitz, one LU per row length),
which keeps the iterations at 50-183 from n = 64 to 192, growing with n, ν and a/b (without
it: 1,100-1,400 at n = 64, a = b, ν = 0.25).
Every run first checks the FFT operator's products against the dense matrices (n = 8, 12)
and the two solvers' coefficients against each other (n = 16, 24).

For each ellipse (a/b = 1, 0.5, 2) and ν = 0, 0.25, 0.5 on the grids ``--grids`` and each
grid offset, the coefficients are normalised by the discrete contact's own
c_d = √(area/π) (c_d², c_d³, c_d⁴ as for c) instead of c = √(ab): the elements whose centre
lies inside give a staircase contact whose area scatters from grid to grid, and the
coefficients with it. They are averaged over the offsets per grid and extrapolated by a
least-squares fit f∞ + k/n over the grids n >= ``--fit-from`` (the upwind difference is
first order): that limit is compared with Kalker 1990, Table E.3 (``kalker.TABLE``, imported
only for that comparison). Its uncertainty is the largest distance from it of the limits of
the fits f∞ + k/n + m/n², f∞ + k/n + m/n^1.5 and f∞ + k/n, over all the grids and without
the coarsest one or two, of the mean and of each offset's own sequence. The fit
f∞ + k/√n + m/n (the traction's square-root singularity at the leading edge could add such
a term) is recorded in the JSON, not counted.

Writes ``bench_kalker_bem.json`` (every grid's coefficients, time, GMRES iterations and the
process's peak RSS so far; every fit) and ``bench_kalker_bem.png`` (every coefficient / the
table's value against 1/n) to ``--out``, and prints a markdown table. Serial; the run times
are in benchmarks/README.md.
"""

from __future__ import annotations

import math
import sys
import time
import typing

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction.studies.rolling import kalker

#: (a/b, nu) of every row compared
ROWS = tuple((ratio, nu) for ratio in (1.0, 0.5, 2.0) for nu in (0.0, 0.25, 0.5))
NAMES = ("C11", "C22", "C23", "C33")
#: the default grids, offsets (cells, in x and y) and those of ``--fast``
DEFAULT_GRIDS = (64, 80, 96, 112, 128)
DEFAULT_OFFSETS = (0.0, 0.25)
FAST_GRIDS = (48, 56, 64, 72, 80)


def _log_sum(s: np.ndarray, t: np.ndarray, r: np.ndarray) -> np.ndarray:
    """ln(s + r) with r = √(s² + t²), without the cancellation of s + r for s < 0 (then
    s + r = t²/(r − s)); 0 where s + r = 0 (the primitive's factor vanishes there)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(s >= 0.0, np.log(s + r), np.log(t * t / (r - s)))
    return np.where(np.isfinite(out), out, 0.0)


def _primitives(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                         np.ndarray]:
    """The double primitives in (x, y) of 1/r, x²/r³, y²/r³ and xy/r³."""
    r = np.hypot(x, y)
    lx, ly = _log_sum(x, y, r), _log_sum(y, x, r)
    return x * ly + y * lx, y * lx, x * ly, -r


def rectangle_integrals(x: np.ndarray, y: np.ndarray, hx: float, hy: float
                        ) -> tuple[np.ndarray, ...]:
    """The integrals of 1/r, x²/r³, y²/r³, xy/r³ over the rectangle of sides hx, hy centred at
    (−x, −y): i.e. of the kernels at (x − x', y − y') over the element, for the point (x, y)
    relative to the element's centre."""
    total = [np.zeros(np.broadcast(x, y).shape) for _ in range(4)]
    for sx in (-1.0, 1.0):
        for sy in (-1.0, 1.0):
            for k, f in enumerate(_primitives(x + sx * hx / 2, y + sy * hy / 2)):
                total[k] += sx * sy * f
    return tuple(total)


def influence(x: np.ndarray, y: np.ndarray, hx: float, hy: float, nu: float
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Axx, Axy (= Ayx), Ayy at the point (x, y) from the element centred at the origin, for
    quasi-identical bodies with G = 1 (relative displacement of the two bodies)."""
    one, xx, yy, xy = rectangle_integrals(x, y, hx, hy)
    return (((1 - nu) * one + nu * xx) / math.pi, nu * xy / math.pi,
            ((1 - nu) * one + nu * yy) / math.pi)


def self_check() -> dict[str, float]:
    """Relative errors of the closed-form influence numbers against quadratures of the Cerruti
    kernel: for a far element (offset 3.7, -2.2 element sizes), a tensor Gauss-Legendre rule
    of 24 x 24 points; at the element's own centre (1/r singular), polar coordinates about the
    centre over the four triangles centre-side, where the radial integral is exact and 48
    Gauss points in the angle remain."""
    hx, hy, nu = 0.7, 1.3, 0.3
    nodes, weights = np.polynomial.legendre.leggauss(24)
    far = (3.7 * hx, -2.2 * hy)
    xs, ys = hx / 2 * nodes, hy / 2 * nodes
    w = np.outer(weights, weights) * hx * hy / 4
    dx, dy = far[0] - xs[:, None], far[1] - ys[None, :]
    r = np.hypot(dx, dy)
    quad = np.array([np.sum(w * ((1 - nu) / r + nu * dx**2 / r**3)),
                     np.sum(w * nu * dx * dy / r**3),
                     np.sum(w * ((1 - nu) / r + nu * dy**2 / r**3))]) / math.pi
    closed = np.array(influence(np.array(far[0]), np.array(far[1]), hx, hy, nu))
    # self: the kernel is g(theta)/rho, so its integral over a triangle is that of
    # g(theta) rho_max(theta) in theta
    nodes, weights = np.polynomial.legendre.leggauss(48)
    alpha = math.atan2(hy, hx)
    quad_self = np.zeros(3)
    for lo, hi, reach in ((-alpha, alpha, lambda t: hx / 2 / np.abs(np.cos(t))),
                          (alpha, math.pi - alpha, lambda t: hy / 2 / np.abs(np.sin(t))),
                          (math.pi - alpha, math.pi + alpha,
                           lambda t: hx / 2 / np.abs(np.cos(t))),
                          (math.pi + alpha, 2 * math.pi - alpha,
                           lambda t: hy / 2 / np.abs(np.sin(t)))):
        t = (lo + hi) / 2 + (hi - lo) / 2 * nodes
        wt = weights * (hi - lo) / 2 * reach(t)
        quad_self += np.array([np.sum(wt * ((1 - nu) + nu * np.cos(t) ** 2)),
                               np.sum(wt * nu * np.cos(t) * np.sin(t)),
                               np.sum(wt * ((1 - nu) + nu * np.sin(t) ** 2))]) / math.pi
    closed_self = np.array(influence(np.array(0.0), np.array(0.0), hx, hy, nu))
    return {"far_Axx": float(abs(closed[0] / quad[0] - 1)),
            "far_Axy": float(abs(closed[1] / quad[1] - 1)),
            "far_Ayy": float(abs(closed[2] / quad[2] - 1)),
            "self_Axx": float(abs(closed_self[0] / quad_self[0] - 1)),
            "self_Ayy": float(abs(closed_self[2] / quad_self[2] - 1)),
            "self_Axy_abs": float(abs(closed_self[1] - quad_self[1]))}


def grid(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The elements of the half y > 0 of the ellipse with n elements per semi-axis: the
    integer indices (i, j) of their centres ((i + 1/2) a/n, (j + 1/2) b/n)."""
    i, j = np.meshgrid(np.arange(-n, n), np.arange(n), indexing="ij")
    inside = ((i + 0.5) / n) ** 2 + ((j + 0.5) / n) ** 2 < 1.0
    return i[inside], j[inside]


def dense_matrix(ratio: float, nu: float, n: int, parity: tuple[float, float],
                 leading_edge: str = "elastic") -> np.ndarray:
    """The dense system of the half y > 0 (:func:`grid`) for tractions (px, py) of parity
    ``parity`` in y (+1 even, −1 odd): the upwind difference (u(x + a/n) − u(x))/(a/n) of the
    displacement (ux, uy) at every centre. ``leading_edge``: "elastic" takes the displacement
    at an upwind point outside the ellipse from the influence numbers (the free surface moves
    under the tractions inside); "zero" sets it to 0."""
    a, b = math.sqrt(ratio), 1.0 / math.sqrt(ratio)
    hx, hy = a / n, b / n
    i, j = grid(n)
    # influence numbers on the lattice of index offsets (di, dj), di in [-2n, 2n + 1]
    di = np.arange(-2 * n, 2 * n + 2)[:, None]
    dj = np.arange(-2 * n, 2 * n + 1)[None, :]
    table = influence(di * hx, dj * hy, hx, hy, nu)
    off_i, off_j = 2 * n, 2 * n
    ti, si = i[:, None], i[None, :]
    direct = (ti - si + off_i, j[:, None] - j[None, :] + off_j)
    mirror = (ti - si + off_i, j[:, None] + j[None, :] + 1 + off_j)
    upwind_direct = (direct[0] + 1, direct[1])
    upwind_mirror = (mirror[0] + 1, mirror[1])
    if leading_edge == "zero":
        # the upwind point of an element on the leading edge lies outside: u = 0 there
        ahead = ((i + 1.5) / n) ** 2 + ((j + 0.5) / n) ** 2 >= 1.0
    else:
        ahead = np.zeros(i.size, dtype=bool)
    keep = (~ahead)[:, None]

    def block(k: int, sign: float) -> np.ndarray:
        """(u_up − u)/hx at every centre from the sources' component with parity ``sign``."""
        t = table[k]
        up = t[upwind_direct] + sign * t[upwind_mirror]
        return (np.where(keep, up, 0.0) - (t[direct] + sign * t[mirror])) / hx

    sx, sy = parity
    return np.block([[block(0, sx), block(1, sy)], [block(1, sx), block(2, sy)]])


def solve(ratio: float, nu: float, n: int, leading_edge: str = "elastic"
          ) -> dict[str, float]:
    """The four coefficients (and C23 from Mz/η) of the ellipse a/b = ``ratio`` (c = 1, G = 1)
    on the grid of n elements per semi-axis, by dense solves of the half y > 0
    (:func:`dense_matrix`)."""
    a, b = math.sqrt(ratio), 1.0 / math.sqrt(ratio)
    hx, hy = a / n, b / n
    i, j = grid(n)
    x = (i + 0.5) * hx
    y = (j + 0.5) * hy
    area = hx * hy
    out: dict[str, float] = {}
    for sx, sy in ((1.0, -1.0), (-1.0, 1.0)):  # (px, py) parity in y: xi's, then eta's and phi's
        matrix = dense_matrix(ratio, nu, n, (sx, sy), leading_edge)
        if sx > 0:
            rhs = np.concatenate([np.ones_like(x), np.zeros_like(x)])[:, None]  # xi = 1
        else:
            rhs = np.stack([np.concatenate([np.zeros_like(x), np.ones_like(x)]),  # eta = 1
                            np.concatenate([-y, x])], axis=1)  # phi = 1
        p = np.linalg.solve(matrix, rhs)
        px, py = p[: x.size], p[x.size:]
        fx, fy = 2 * area * px.sum(axis=0), 2 * area * py.sum(axis=0)
        mz = 2 * area * (x[:, None] * py - y[:, None] * px).sum(axis=0)
        if sx > 0:
            out["C11"] = float(-fx[0])
        else:
            out.update(C22=float(-fy[0]), C23=float(-fy[1]), C23_from_Mz=float(mz[0]),
                       C33=float(-mz[1]))
    return out


class FFTOperator:
    """The same discrete operator on the whole ellipse, matrix-free: on the regular grid the
    influence numbers depend on the index offsets only, so the displacement of every element
    is a 2D linear convolution of the tractions with them, and so is its upwind difference
    (the convolution with the differenced influence numbers (A(di + 1, dj) − A(di, dj))/hx).
    Both are computed by real FFTs on a zero-padded box at least twice the ellipse's bounding
    box, which makes the circular convolution exact on the box.

    The box holds the cells i, j = −n − 1 … n, centred at ((i + 1/2 + ox) a/n,
    (j + 1/2 + oy) b/n): ``offset`` = (ox, oy) shifts the grid by a fraction of a cell
    relative to the ellipse's centre (0, 0 is the grid of :func:`grid`, mirrored); the unknowns
    are (px, py) on the cells whose centre lies inside the ellipse."""

    def __init__(self, ratio: float, nu: float, n: int,
                 offset: tuple[float, float] = (0.0, 0.0)) -> None:
        import scipy.fft

        self._fft = scipy.fft
        a, b = math.sqrt(ratio), 1.0 / math.sqrt(ratio)
        self.hx, self.hy = a / n, b / n
        cells = np.arange(-n - 1, n + 1)
        self.x = np.broadcast_to(((cells + 0.5 + offset[0]) * self.hx)[:, None],
                                 (cells.size, cells.size))
        self.y = np.broadcast_to(((cells + 0.5 + offset[1]) * self.hy)[None, :],
                                 (cells.size, cells.size))
        self.mask = (self.x / a) ** 2 + (self.y / b) ** 2 < 1.0
        self.size = int(self.mask.sum())
        nx, ny = self.mask.shape
        self.shape = (scipy.fft.next_fast_len(2 * nx), scipy.fft.next_fast_len(2 * ny))
        di = np.arange(-(nx - 1), nx + 1)[:, None]  # one more than the box: the upwind point
        dj = np.arange(-(ny - 1), ny)[None, :]
        table = influence(di * self.hx, dj * self.hy, self.hx, self.hy, nu)
        rows, cols = np.arange(-(nx - 1), nx) % self.shape[0], dj[0] % self.shape[1]
        self.kernels = []
        #: the differenced influence numbers along the element's own row (dj = 0), xx and yy
        self.row_kernels = []
        for k, t in enumerate(table):
            differenced = (t[1:] - t[:-1]) / self.hx  # di in [-(nx - 1), nx - 1]
            padded = np.zeros(self.shape)
            padded[np.ix_(rows, cols)] = differenced
            self.kernels.append(scipy.fft.rfft2(padded))
            if k != 1:
                self.row_kernels.append(differenced[:, ny - 1].copy())

    def matvec(self, v: np.ndarray) -> np.ndarray:
        """The upwind difference of (ux, uy) at every element for the tractions
        v = (px, py) of the elements (in the order of the mask)."""
        fft, m = self._fft, self.size
        fields = []
        for part in (v[:m], v[m:]):
            field = np.zeros(self.mask.shape)
            field[self.mask] = part
            fields.append(fft.rfft2(field, s=self.shape))
        kxx, kxy, kyy = self.kernels
        nx, ny = self.mask.shape
        ux = fft.irfft2(kxx * fields[0] + kxy * fields[1], s=self.shape)[:nx, :ny]
        uy = fft.irfft2(kxy * fields[0] + kyy * fields[1], s=self.shape)[:nx, :ny]
        return np.concatenate([ux[self.mask], uy[self.mask]])

    def strip_preconditioner(self) -> typing.Callable[[np.ndarray], np.ndarray]:
        """The inverse of the operator's row-by-row part: each row of the grid coupled only to
        itself (dj = 0; there Axy = 0, so px and py decouple). A row of the ellipse is a run
        of consecutive cells and the row's matrix is Toeplitz, so rows of equal length share
        one LU factorisation."""
        import scipy.linalg

        index = np.full(self.mask.shape, -1)
        index[self.mask] = np.arange(self.size)
        groups: dict[int, list[np.ndarray]] = {}
        nx = self.mask.shape[0]
        for column in range(self.mask.shape[1]):
            cells = np.nonzero(self.mask[:, column])[0]
            if cells.size:
                groups.setdefault(cells.size, []).append(index[cells, column])
        factors = []
        for length, members in groups.items():
            k = np.arange(length)
            offsets = k[:, None] - k[None, :] + nx - 1
            factors.append((np.array(members).T,
                            [scipy.linalg.lu_factor(kernel[offsets])
                             for kernel in self.row_kernels]))
        m = self.size

        def apply(v: np.ndarray) -> np.ndarray:
            out = np.empty_like(v)
            for members, (fxx, fyy) in factors:
                out[:m][members] = scipy.linalg.lu_solve(fxx, v[:m][members])
                out[m:][members] = scipy.linalg.lu_solve(fyy, v[m:][members])
            return out

        return apply


def _gmres(operator: typing.Any, rhs: np.ndarray, rtol: float,
           preconditioner: typing.Any) -> tuple[np.ndarray, int]:
    """scipy's GMRES (restart 200) to the relative residual ``rtol``, with the number of
    inner iterations; raises if it does not converge."""
    import inspect

    from scipy.sparse.linalg import gmres

    count = [0]

    def tick(_: typing.Any) -> None:
        count[0] += 1

    tolerance = ("rtol" if "rtol" in inspect.signature(gmres).parameters else "tol")
    solution, info = gmres(operator, rhs, atol=0.0, restart=200, maxiter=50,
                           M=preconditioner, callback=tick, callback_type="pr_norm",
                           **{tolerance: rtol})
    if info != 0:
        raise RuntimeError(f"GMRES did not converge (info = {info}, {count[0]} iterations)")
    return solution, count[0]


def solve_fft(ratio: float, nu: float, n: int, offset: tuple[float, float] = (0.0, 0.0),
              rtol: float = 1e-10) -> dict[str, typing.Any]:
    """As :func:`solve` on the whole ellipse, grid shifted by ``offset`` cells
    (:class:`FFTOperator`), by GMRES to the relative residual ``rtol``, preconditioned by the
    row-by-row operator (:meth:`FFTOperator.strip_preconditioner`); one solve each for ξ, η,
    φ = 1. Also the element count, the squared discrete c (c_d² = area/π, c = 1), the
    iterations and the largest true relative residual."""
    from scipy.sparse.linalg import LinearOperator

    op = FFTOperator(ratio, nu, n, offset)
    m = op.size
    operator = LinearOperator((2 * m, 2 * m), matvec=op.matvec, dtype=float)
    preconditioner = LinearOperator((2 * m, 2 * m), matvec=op.strip_preconditioner(),
                                    dtype=float)
    x, y = op.x[op.mask], op.y[op.mask]
    area = op.hx * op.hy
    zero, one = np.zeros(m), np.ones(m)
    out: dict[str, typing.Any] = {"elements": m, "c_d2": m * area / math.pi,
                                  "iterations": [], "residual": 0.0}
    for creepage, rhs in (("xi", np.concatenate([one, zero])),
                          ("eta", np.concatenate([zero, one])),
                          ("phi", np.concatenate([-y, x]))):
        p, iterations = _gmres(operator, rhs, rtol, preconditioner)
        out["iterations"].append(iterations)
        out["residual"] = max(out["residual"], float(np.linalg.norm(op.matvec(p) - rhs)
                                                     / np.linalg.norm(rhs)))
        px, py = p[:m], p[m:]
        fx, fy = area * px.sum(), area * py.sum()
        mz = area * (x * py - y * px).sum()
        if creepage == "xi":
            out["C11"] = float(-fx)
        elif creepage == "eta":
            out.update(C22=float(-fy), C23_from_Mz=float(mz))
        else:
            out.update(C23=float(-fy), C33=float(-mz))
    return out


def fft_check() -> dict[str, float]:
    """The FFT operator against the dense matrices of :func:`dense_matrix`: the products with
    random tractions of either parity on the half y > 0 (mirrored onto the whole ellipse) at
    n = 8, 12 (a/b = 0.5, 2; ν = 0.3), and the coefficients of :func:`solve_fft` against
    :func:`solve` at n = 16 (a/b = 2, ν = 0.25) and n = 24 (a/b = 0.5, ν = 0.5); the largest
    relative differences."""
    rng = np.random.default_rng(1)
    worst_product = 0.0
    for n in (8, 12):
        i, j = grid(n)
        for ratio in (0.5, 2.0):
            op = FFTOperator(ratio, 0.3, n)
            index = np.full(op.mask.shape, -1)
            index[op.mask] = np.arange(op.size)
            upper = index[i + n + 1, j + n + 1]
            lower = index[i + n + 1, -j - 1 + n + 1]
            for parity in ((1.0, -1.0), (-1.0, 1.0)):
                half = rng.standard_normal(2 * i.size)
                full = np.zeros(2 * op.size)
                for k, sign in enumerate(parity):
                    part = half[k * i.size:(k + 1) * i.size]
                    full[k * op.size + upper] = part
                    full[k * op.size + lower] = sign * part
                dense = dense_matrix(ratio, 0.3, n, parity) @ half
                product = op.matvec(full)
                fft = np.concatenate([product[upper], product[op.size + upper]])
                worst_product = max(worst_product, float(np.max(np.abs(fft - dense))
                                                         / np.max(np.abs(dense))))
    worst_coefficient = 0.0
    for ratio, nu, n in ((2.0, 0.25, 16), (0.5, 0.5, 24)):
        dense_values, fft_values = solve(ratio, nu, n), solve_fft(ratio, nu, n)
        worst_coefficient = max(worst_coefficient,
                                max(abs(fft_values[k] / v - 1) for k, v in dense_values.items()))
    return {"product": worst_product, "coefficients": worst_coefficient}


def table_row(ratio: float, nu: float) -> dict[str, float]:
    """Kalker 1990, Table E.3 at a tabulated a/b and nu (for the comparison only)."""
    half, g = ("a<=b", ratio) if ratio <= 1.0 else ("a>b", 1.0 / ratio)
    row = int(np.argmin(np.abs(kalker.RATIO - g)))
    column = int(np.argmin(np.abs(kalker.NU - nu)))
    return {name: float(kalker.TABLE[half][row, k, column]) for k, name in enumerate(NAMES)}


def fit(ns: list[int], values: list[float], powers: tuple[float, ...]
        ) -> dict[str, float]:
    """Least-squares f = f_inf + sum_k c_k / n^p_k over the grids given, with the rms
    residual."""
    h = 1.0 / np.asarray(ns, dtype=float)
    design = np.stack([np.ones_like(h)] + [h**p for p in powers], axis=1)
    coef, *_ = np.linalg.lstsq(design, np.asarray(values), rcond=None)
    residual = np.asarray(values) - design @ coef
    return {"limit": float(coef[0]), "rms_residual": float(np.sqrt(np.mean(residual**2)))}


#: how each coefficient scales with c under a uniform scaling of the contact
SCALING = {"C11": 2, "C22": 2, "C23": 3, "C23_from_Mz": 3, "C33": 4}
COEFFICIENTS = ("C11", "C22", "C23", "C23_from_Mz", "C33")
#: the fit forms f_inf + ...: the headline is the first; the others give the uncertainty
FORMS = {"k/n": (1.0,), "k/n+m/n^2": (1.0, 2.0), "k/n+m/n^1.5": (1.0, 1.5)}
#: reported, not used for the uncertainty: a square-root term, which the traction's
#: singularity at the leading edge could contribute
EXTRA_FORMS = {"k/n^0.5+m/n": (0.5, 1.0)}


def half_unit(value: float) -> float:
    """Half a unit in the last of three significant digits (the table's rounding)."""
    return 0.5 * 10.0 ** (math.floor(math.log10(abs(value))) - 2)


def limits(ns: list[int], series: dict[str, list[float]]) -> dict[str, typing.Any]:
    """The limits of one coefficient's grid sequences (``series``: "mean" over the grid
    offsets, and each offset's own): the headline fit k/n of the mean over all grids, every
    form of :data:`FORMS` over all grids and without the coarsest one or two (while at least
    two more points than parameters remain), of the mean and of each offset; the uncertainty
    is the largest distance of those limits from the headline (None when the grids allow no
    other fit)."""
    variants: dict[str, dict[str, float]] = {}
    for label, values in series.items():
        for form, powers in {**FORMS, **EXTRA_FORMS}.items():
            for drop in (0, 1, 2):
                if len(ns) - drop < len(powers) + 3:
                    continue
                variants[f"{label} {form} n>={ns[drop]}"] = fit(ns[drop:], values[drop:],
                                                                powers)
    head = variants[f"mean k/n n>={ns[0]}"]
    others = [abs(v["limit"] - head["limit"]) for k, v in variants.items()
              if v is not head and not any(extra in k for extra in EXTRA_FORMS)]
    # too few grids for any other fit: no spread to state
    spread = max(others) if others else None
    return {"limit": head["limit"], "rms_residual": head["rms_residual"],
            "uncertainty": spread, "variants": variants}


def study(grids: list[int], offsets: list[tuple[float, float]], fit_from: int,
          rtol: float, method: str) -> list[dict]:
    """One record per (a/b, nu): every grid's and offset's coefficients (raw, and normalised
    by the discrete contact's own c_d = sqrt(area/pi) instead of c), elements, time, GMRES
    iterations, the process's peak RSS so far, the limits (:func:`limits`) and the table's
    values."""
    import resource

    records = []
    for ratio, nu in ROWS:
        runs = []
        for n in grids:
            for offset in offsets if method == "fft" else [(0.0, 0.0)]:
                t0 = time.perf_counter()
                if method == "fft":
                    result = solve_fft(ratio, nu, n, offset, rtol)
                else:
                    result = {**solve(ratio, nu, n), "elements": 2 * grid(n)[0].size,
                              "c_d2": 2.0 * grid(n)[0].size / n**2 / math.pi}
                seconds = time.perf_counter() - t0
                values = {k: result[k] for k in COEFFICIENTS}
                peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
                runs.append({"n": n, "offset": list(offset), "elements": result["elements"],
                             "seconds": seconds, "peak_rss_MB": peak,
                             "iterations": result.get("iterations"),
                             "residual": result.get("residual"), "raw": values,
                             "area_normalised": {k: v / result["c_d2"] ** (SCALING[k] / 2)
                                                 for k, v in values.items()}})
                print(f"a/b = {ratio}, nu = {nu}, n = {n}, offset = {offset}: "
                      f"{seconds:.1f} s, {peak:.0f} MB, iterations "
                      f"{result.get('iterations')}", file=sys.stderr, flush=True)
        reference = table_row(ratio, nu)
        fitted = [n for n in grids if n >= fit_from]
        record: dict = {"a/b": ratio, "nu": nu, "table": reference, "runs": runs,
                        "fit_grids": fitted, "limits": {}}
        for kind in ("raw", "area_normalised"):
            record["limits"][kind] = {}
            if len(fitted) < 4:
                continue
            for name in COEFFICIENTS:
                per_offset = {str(tuple(o)): [next(r[kind][name] for r in runs
                                                   if r["n"] == n and r["offset"] == list(o))
                                              for n in fitted]
                              for o in (offsets if method == "fft" else [(0.0, 0.0)])}
                mean = list(np.mean(np.array(list(per_offset.values())), axis=0))
                series = {"mean": mean, **(per_offset if len(per_offset) > 1 else {})}
                lim = limits(fitted, series)
                ref = reference["C23" if name == "C23_from_Mz" else name]
                lim["difference"] = lim["limit"] / ref - 1
                lim["consistent"] = (None if lim["uncertainty"] is None else
                                     bool(abs(lim["limit"] - ref)
                                          <= half_unit(ref) + lim["uncertainty"]))
                record["limits"][kind][name] = lim
        records.append(record)
    return records


def _percent(value: float | None) -> str:
    return "—" if value is None else f"{100 * value:+.2f} %"


def _spread(value: float | None) -> str:
    return "—" if value is None else f"{value:.4f}"


def table(records: list[dict]) -> str:
    """Markdown: per row and coefficient, the table's value, the finest grid's (mean over the
    offsets, area-normalised), the limit (fit k/n of the area-normalised coefficients) ±
    the spread of the fit forms and ranges, its rms residual, its difference from the table
    and whether it is within the table's rounding plus that spread."""
    lines = ["| a/b | ν | coef. | table | finest n | limit ± spread | rms resid. | "
             "limit/table − 1 | within ½ digit + spread |", "|---|---|---|---|---|---|---|---|---|"]
    for rec in records:
        finest = max(r["n"] for r in rec["runs"])
        for name in COEFFICIENTS:
            ref = rec["table"]["C23" if name == "C23_from_Mz" else name]
            last = np.mean([r["area_normalised"][name] for r in rec["runs"]
                            if r["n"] == finest])
            lim = rec["limits"]["area_normalised"].get(name)
            if lim is None:
                lines.append(f"| {rec['a/b']} | {rec['nu']} | {name} | {ref} | {last:.4f} |"
                             " — | — | — | — |")
                continue
            lines.append(f"| {rec['a/b']} | {rec['nu']} | {name} | {ref} | {last:.4f} | "
                         f"{lim['limit']:.4f} ± {_spread(lim['uncertainty'])} | "
                         f"{lim['rms_residual']:.1e} | {_percent(lim['difference'])} | "
                         f"{ {True: 'yes', False: 'NO', None: '—'}[lim['consistent']]} |")
    return "\n".join(lines)


def plot(records: list[dict], path, dpi: int) -> None:
    """Each coefficient / table value against 1/n, area-normalised, one line per row and
    grid offset, with the k/n fit's limit at 1/n = 0."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 4, figsize=(16, 4), sharey=True)
    for ax, name in zip(axes, NAMES, strict=True):
        for rec in records:
            ref = rec["table"][name]
            offsets = sorted({tuple(r["offset"]) for r in rec["runs"]})
            color = None
            for k, offset in enumerate(offsets):
                runs = [r for r in rec["runs"] if tuple(r["offset"]) == offset]
                line, = ax.plot([1.0 / r["n"] for r in runs],
                                [r["area_normalised"][name] / ref for r in runs],
                                "o-" if k == 0 else "s--", ms=3, color=color,
                                label=f"a/b={rec['a/b']}, ν={rec['nu']}" if k == 0 else None)
                color = line.get_color()
            lim = rec["limits"]["area_normalised"].get(name)
            if lim is not None and lim["uncertainty"] is not None:
                ax.errorbar([0.0], [lim["limit"] / ref], yerr=[lim["uncertainty"] / ref],
                            fmt="*", color=color, ms=6)
        ax.axhline(1.0, color="k", lw=0.8)
        for bound in (-1, 1):
            ax.axhline(1.0 + bound * 0.002, color="k", lw=0.5, ls=":")
        ax.set(xlabel="1/n (n elements per semi-axis)",
               title=f"{name} (BEM, area-normalised) / table")
        ax.set_xlim(left=-0.001)
    axes[0].legend(fontsize=6)
    save(fig, path, dpi)


def main() -> int:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--grids", type=int, nargs="+", default=list(DEFAULT_GRIDS),
                       help="elements per semi-axis of each grid, at least four of n >= "
                       f"--fit-from ({' '.join(map(str, DEFAULT_GRIDS))})")
    flags.add_argument("--offsets", type=float, nargs="+", default=list(DEFAULT_OFFSETS),
                       help="grid offsets in cells relative to the ellipse's centre, the same "
                       "in x and y, averaged per grid "
                       f"({' '.join(map(str, DEFAULT_OFFSETS))})")
    flags.add_argument("--fast", action="store_true",
                       help=f"a smoke test: the grids {' '.join(map(str, FAST_GRIDS))}, all "
                       "fitted, offset 0 only (about 1 min; limits to about 0.6 %)")
    flags.add_argument("--fit-from", type=int, default=64,
                       help="the fits use the grids n >= this (64)")
    flags.add_argument("--rtol", type=float, default=1e-10,
                       help="GMRES relative residual (1e-10)")
    flags.add_argument("--method", choices=("fft", "dense"), default="fft",
                       help="fft: matrix-free GMRES on the whole ellipse (default); dense: the "
                       "dense solve of the half y > 0 (n <= 48 or so: memory)")
    flags.add_argument("--dpi", type=int, default=110)
    args = flags.parse_args()
    grids = sorted(set(FAST_GRIDS if args.fast else args.grids))
    offsets = [(0.0, 0.0)] if args.fast else [(o, o) for o in dict.fromkeys(args.offsets)]
    if args.fast:
        args.fit_from = FAST_GRIDS[0]
    if len([n for n in grids if n >= args.fit_from]) < 4 or grids[0] < 2:
        print(f"--grids={grids}: give at least four grids of n >= --fit-from = "
              f"{args.fit_from}", file=sys.stderr)
        return 2
    if not all(0.0 <= o[0] <= 0.5 for o in offsets):
        print(f"--offsets={args.offsets}: each in [0, 0.5]", file=sys.stderr)
        return 2
    checks = self_check()
    worst = max(checks.values())
    print(f"influence numbers vs quadrature of the Cerruti kernel: worst {worst:.1e}",
          file=sys.stderr)
    if worst > 1e-10:
        print(f"self-check failed: {checks}", file=sys.stderr)
        return 1
    against_dense = fft_check()
    print(f"FFT operator vs dense matrices: products {against_dense['product']:.1e}, "
          f"coefficients {against_dense['coefficients']:.1e}", file=sys.stderr)
    if against_dense["product"] > 1e-12 or against_dense["coefficients"] > 1e-8:
        print(f"FFT check failed: {against_dense}", file=sys.stderr)
        return 1
    # the literal recipe "u = 0 ahead of the leading edge", at a/b = 1, nu = 0, for the record
    zero_edge = {n: solve(1.0, 0.0, n, leading_edge="zero") for n in (10, 12, 16, 20)}
    t0 = time.perf_counter()
    records = study(grids, offsets, args.fit_from, args.rtol, args.method)
    seconds = time.perf_counter() - t0
    args.out.mkdir(parents=True, exist_ok=True)
    print(table(records))
    plot(records, args.out / "bench_kalker_bem.png", args.dpi)
    write_summary(args.out / "bench_kalker_bem.json",
                  {"grids": grids, "offsets": offsets, "fit_from": args.fit_from,
                   "rtol": args.rtol, "method": args.method, "study_seconds": seconds,
                   "influence_self_check": checks, "fft_vs_dense": against_dense,
                   "leading_edge_zero_a_b_1_nu_0": zero_edge, "rows": records})
    print(f"wrote {args.out / 'bench_kalker_bem.json'} and "
          f"{args.out / 'bench_kalker_bem.png'} ({seconds:.0f} s)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
