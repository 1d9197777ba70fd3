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
  ``--leading-edge``);
* the dense system for (px, py), split by the symmetry y → −y (ξ: px even, py odd in y; η and
  φ: px odd, py even), solved for unit ξ, η, φ; then with G = 1, c = √(ab) = 1
  C11 = −Fx/ξ, C22 = −Fy/η, C23 = −Fy/φ (and Mz/η: the same by reciprocity),
  C33 = −Mz/φ (the package's Fx = −G c² C11 ξ, Fy = −G c² (C22 η + c C23 φ),
  Mz = −G c³ (−C23 η + c C33 φ)).

For each ellipse (a/b = 1, 0.5, 2) and ν = 0, 0.25, 0.5 on the grids ``--grids``, the
coefficients and their relative difference from Kalker 1990, Table E.3 (``kalker.TABLE``,
imported only for that comparison), three ways:

* Richardson: on the finest n/4, n/2, n among the grids, the observed order
  p = log2(d1/d2) of the two changes and the limit f3 + d2/(2^p − 1) (none where the changes
  differ in sign or do not shrink);
* a least-squares fit f = f_inf + k/n over the grids n >= ``--fit-from`` (the upwind
  difference is first order);
* the same fit of the coefficients normalised by the discrete contact's own
  c_d = √(area/π) (c_d², c_d³, c_d⁴ as for c) instead of c = √(ab).

The elements whose centre lies inside give a staircase contact whose area jumps by up to
±1 % between neighbouring grids (n >= 10); the coefficients follow, so the three-grid
Richardson order mostly measures that scatter, not an asymptotic order, and the fits over many
grids are the estimates to read. Writes ``bench_kalker_bem.json`` and ``bench_kalker_bem.png``
(every coefficient / the table's value against 1/n) to ``--out``, and prints a markdown table.
Serial; about 6 minutes and 2 GB with the default grids (n = 48: 7,232 elements, 3,616 on the
half y > 0 solved, about 15 s per ellipse and ν).
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction.studies.rolling import kalker

#: (a/b, nu) of every row compared
ROWS = tuple((ratio, nu) for ratio in (1.0, 0.5, 2.0) for nu in (0.0, 0.25, 0.5))
NAMES = ("C11", "C22", "C23", "C33")


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


def solve(ratio: float, nu: float, n: int, leading_edge: str = "elastic"
          ) -> dict[str, float]:
    """The four coefficients (and C23 from Mz/η) of the ellipse a/b = ``ratio`` (c = 1, G = 1)
    on the grid of n elements per semi-axis. ``leading_edge``: "elastic" takes the displacement
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

    x = (i + 0.5) * hx
    y = (j + 0.5) * hy
    area = hx * hy
    out: dict[str, float] = {}
    for sx, sy in ((1.0, -1.0), (-1.0, 1.0)):  # (px, py) parity in y: xi's, then eta's and phi's
        matrix = np.block([[block(0, sx), block(1, sy)], [block(1, sx), block(2, sy)]])
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


def table_row(ratio: float, nu: float) -> dict[str, float]:
    """Kalker 1990, Table E.3 at a tabulated a/b and nu (for the comparison only)."""
    half, g = ("a<=b", ratio) if ratio <= 1.0 else ("a>b", 1.0 / ratio)
    row = int(np.argmin(np.abs(kalker.RATIO - g)))
    column = int(np.argmin(np.abs(kalker.NU - nu)))
    return {name: float(kalker.TABLE[half][row, k, column]) for k, name in enumerate(NAMES)}


def richardson(values: list[float]) -> dict[str, float | None]:
    """Observed order and limit from three values on grids each twice as fine as the last
    (None where the two changes differ in sign: no asymptotic order to see)."""
    d1, d2 = values[1] - values[0], values[2] - values[1]
    if d1 * d2 <= 0.0 or abs(d2) >= abs(d1):
        return {"order": None, "limit": None}
    order = math.log2(d1 / d2)
    return {"order": order, "limit": values[2] + d2 / (2.0**order - 1.0)}


def first_order_fit(ns: list[int], values: list[float]) -> dict[str, float]:
    """Least-squares f = f_inf + k/n over the grids given (the upwind difference is first
    order; the fit averages the staircase boundary's scatter), with the rms residual."""
    h = 1.0 / np.asarray(ns, dtype=float)
    design = np.stack([np.ones_like(h), h], axis=1)
    coef, *_ = np.linalg.lstsq(design, np.asarray(values), rcond=None)
    residual = np.asarray(values) - design @ coef
    return {"limit": float(coef[0]), "slope": float(coef[1]),
            "rms_residual": float(np.sqrt(np.mean(residual**2)))}


#: how each coefficient scales with c under a uniform scaling of the contact
SCALING = {"C11": 2, "C22": 2, "C23": 3, "C23_from_Mz": 3, "C33": 4}


def study(grids: list[int], fit_from: int) -> list[dict]:
    """One record per (a/b, nu): every grid's coefficients (raw, and normalised by the
    discrete contact's own c_d = sqrt(area/pi) instead of c), time, the Richardson triple and
    the first-order fits, and the table's values."""
    doubled = [n for n in grids if n % 4 == 0 and n // 2 in grids and n // 4 in grids]
    triple = [doubled[-1] // 4, doubled[-1] // 2, doubled[-1]] if doubled else []
    records = []
    for ratio, nu in ROWS:
        runs = []
        for n in grids:
            t0 = time.perf_counter()
            values = solve(ratio, nu, n)
            seconds = time.perf_counter() - t0
            c2 = 2.0 * grid(n)[0].size / n**2 / math.pi  # discrete area / (pi a b), c = 1
            runs.append({"n": n, "elements": 2 * grid(n)[0].size, "seconds": seconds,
                         "raw": values,
                         "area_normalised": {k: v / c2 ** (SCALING[k] / 2)
                                             for k, v in values.items()}})
        reference = table_row(ratio, nu)
        record: dict = {"a/b": ratio, "nu": nu, "table": reference, "runs": runs,
                        "richardson_grids": triple, "richardson": {}, "fit_grids": [],
                        "fit": {}}
        fitted = [r for r in runs if r["n"] >= fit_from]
        record["fit_grids"] = [r["n"] for r in fitted]
        for kind in ("raw", "area_normalised"):
            record["richardson"][kind], record["fit"][kind] = {}, {}
            for name in ("C11", "C22", "C23", "C23_from_Mz", "C33"):
                table_value = reference["C23" if name == "C23_from_Mz" else name]
                if triple:
                    rich = richardson([next(r[kind][name] for r in runs if r["n"] == n)
                                       for n in triple])
                    limit = rich["limit"]
                    rich["difference"] = None if limit is None else limit / table_value - 1
                    record["richardson"][kind][name] = rich
                if len(fitted) >= 3:
                    fit = first_order_fit([r["n"] for r in fitted],
                                          [r[kind][name] for r in fitted])
                    fit["difference"] = fit["limit"] / table_value - 1
                    record["fit"][kind][name] = fit
        records.append(record)
        print(f"a/b = {ratio}, nu = {nu}: {sum(r['seconds'] for r in runs):.1f} s",
              file=sys.stderr, flush=True)
    return records


def _percent(value: float | None) -> str:
    return "—" if value is None else f"{100 * value:+.2f} %"


def table(records: list[dict]) -> str:
    """Markdown: per row and coefficient, the table's value, the finest grid's, the
    Richardson limit (order) and the first-order fits (raw, area-normalised), with their
    relative differences from the table."""
    lines = ["| a/b | ν | coef. | table | finest n | Richardson (order) | fit raw | "
             "fit area-norm. |", "|---|---|---|---|---|---|---|---|"]
    for rec in records:
        finest = rec["runs"][-1]
        for name in ("C11", "C22", "C23", "C23_from_Mz", "C33"):
            ref = rec["table"]["C23" if name == "C23_from_Mz" else name]
            rich = rec["richardson"].get("raw", {}).get(name, {})
            order = rich.get("order")
            rich_text = ("—" if rich.get("limit") is None else
                         f"{rich['limit']:.4f} ({order:.2f}) {_percent(rich['difference'])}")
            fits = [rec["fit"][kind].get(name) for kind in ("raw", "area_normalised")]
            fit_text = ["—" if f is None else f"{f['limit']:.4f} {_percent(f['difference'])}"
                        for f in fits]
            lines.append(f"| {rec['a/b']} | {rec['nu']} | {name} | {ref} | "
                         f"{finest['raw'][name]:.4f} | {rich_text} | {fit_text[0]} | "
                         f"{fit_text[1]} |")
    return "\n".join(lines)


def plot(records: list[dict], path, dpi: int) -> None:
    """Each coefficient / table value against 1/n, raw (solid) and area-normalised (dashed),
    one line per row."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 4, figsize=(16, 4), sharey=True)
    for ax, name in zip(axes, NAMES, strict=True):
        for rec in records:
            h = [1.0 / r["n"] for r in rec["runs"]]
            ref = rec["table"][name]
            line, = ax.plot(h, [r["raw"][name] / ref for r in rec["runs"]], "o-", ms=3,
                            label=f"a/b={rec['a/b']}, ν={rec['nu']}")
            ax.plot(h, [r["area_normalised"][name] / ref for r in rec["runs"]], "--",
                    color=line.get_color())
        ax.axhline(1.0, color="k", lw=0.8)
        ax.set(xlabel="1/n (n elements per semi-axis)", title=f"{name} (BEM) / Kalker's table")
        ax.set_xlim(left=0.0)
    axes[0].legend(fontsize=6)
    save(fig, path, dpi)


def main() -> int:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--grids", type=int, nargs="+",
                       default=[10, 12, 16, 20, 24, 28, 32, 36, 40, 44, 48],
                       help="elements per semi-axis of each grid, at least three; the finest "
                       "n, n/2, n/4 among them give the Richardson limit "
                       "(10 12 16 20 24 28 32 36 40 44 48)")
    flags.add_argument("--fit-from", type=int, default=16,
                       help="the least-squares fits use the grids n >= this (16)")
    flags.add_argument("--dpi", type=int, default=110)
    args = flags.parse_args()
    grids = sorted(set(args.grids))
    if len(grids) < 3 or grids[0] < 2:
        print(f"--grids={args.grids}: give at least three grids of n >= 2", file=sys.stderr)
        return 2
    if args.fit_from < 2:
        print(f"--fit-from={args.fit_from}: must be >= 2", file=sys.stderr)
        return 2
    checks = self_check()
    worst = max(checks.values())
    print(f"influence numbers vs quadrature of the Cerruti kernel: worst {worst:.1e}",
          file=sys.stderr)
    if worst > 1e-10:
        print(f"self-check failed: {checks}", file=sys.stderr)
        return 1
    # the literal recipe "u = 0 ahead of the leading edge", at a/b = 1, nu = 0, for the record
    zero_edge = {n: solve(1.0, 0.0, n, leading_edge="zero") for n in grids if n <= 20}
    records = study(grids, args.fit_from)
    args.out.mkdir(parents=True, exist_ok=True)
    print(table(records))
    plot(records, args.out / "bench_kalker_bem.png", args.dpi)
    write_summary(args.out / "bench_kalker_bem.json",
                  {"grids": grids, "fit_from": args.fit_from, "influence_self_check": checks,
                   "leading_edge_zero_a_b_1_nu_0": zero_edge, "rows": records})
    print(f"wrote {args.out / 'bench_kalker_bem.json'} and "
          f"{args.out / 'bench_kalker_bem.png'}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
