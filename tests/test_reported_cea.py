"""Every figure ``cea matrices`` reports is what its name says: each column of
``eigenvalues.csv``, each key of ``eigenvalues.json``, ``unstable.json`` and ``summary.json``,
the eigenvectors and the printed lines, checked against its definition on a pencil whose
eigenvalues are known independently — a two-degree-of-freedom M, C, K(p) = K + p K1 read from
MatrixMarket files, whose eigenvalues are the roots of the quartic det(λ²M + λC + K(p))
(NumPy's polynomial roots here, not the command's QZ or SLEPc) and whose flutter onset is
bisected on those roots.

One run, shared by the module's tests; the audit table is in docs/verification.md,
"Reported figures"."""

import contextlib
import csv
import io
import json
import math
import re
import time

import numpy as np
import pytest
import scipy.io
import scipy.linalg

from fenicsfriction.cli import main

pytestmark = pytest.mark.sequential  # a 2-unknown pencil: the MPI pass has test_cli_cea

#: the pencil: masses and stiffnesses away from 0 and 1 and unequal, a damper on each
#: co-ordinate, and the follower-force coupling K1 of a friction coefficient (Hoffmann et al.
#: 2002); the unequal damping destabilises it early, near p = 3.8, before the undamped
#: merging at p = 5.5
M = np.diag([1.0, 2.0])
C = np.diag([0.02, 0.01])
K = np.array([[5.0, 1.0], [1.0, 4.0]])
K1 = np.array([[0.0, -1.0], [0.0, 0.0]])
VALUES = [0.0, 2.0, 4.0, 6.0, 8.0]
STABLE, UNSTABLE = 2.0, 4.0   # the sampled values around the onset
NAME = "kappa"
BAND = (0.0, 1.0)
GROWTH_TOL = 1e-9
REFINE_TOL = 1e-6


def _quartic_roots(p: float) -> np.ndarray:
    """The eigenvalues of (λ²M + λC + K + pK1) with Im λ >= 0, ascending in Im λ: the roots
    of (m1λ² + c1λ + k11)(m2λ² + c2λ + k22) − (k12 + p K1[0,1]) k21."""
    a = np.array([M[0, 0], C[0, 0], K[0, 0]])
    b = np.array([M[1, 1], C[1, 1], K[1, 1]])
    quartic = np.polymul(a, b)
    quartic[-1] -= (K[0, 1] + p * K1[0, 1]) * K[1, 0]
    roots = np.roots(quartic)
    return np.array(sorted(roots[roots.imag >= 0], key=lambda z: z.imag))


def _grows(z: complex) -> bool:
    return z.real > GROWTH_TOL * abs(z)


def _onset() -> float:
    """The smallest p in [STABLE, UNSTABLE] at which a root grows, bisected on the quartic's
    roots."""
    low, high = STABLE, UNSTABLE
    assert not any(map(_grows, _quartic_roots(low))) and any(map(_grows, _quartic_roots(high)))
    while high - low > 1e-12:
        mid = 0.5 * (low + high)
        low, high = (low, mid) if any(map(_grows, _quartic_roots(mid))) else (mid, high)
    return 0.5 * (low + high)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cea")
    for name, matrix in (("M", M), ("C", C), ("K", K), ("K1", K1)):
        scipy.io.mmwrite(str(folder / f"{name}.mtx"), matrix)
    argv = ["cea", "matrices", *[x for n in ("M", "C", "K", "K1")
                                 for x in (f"--{n}", str(folder / f"{n}.mtx"))],
            "--param-values", f"{VALUES[0]}:{VALUES[-1]}:{len(VALUES)}", "--param-name", NAME,
            "--band", f"{BAND[0]}:{BAND[1]}", "--method", "both", "--modes", "2",
            "--growth-tol", str(GROWTH_TOL), "--refine-tol", str(REFINE_TOL), "--vectors",
            "--out", str(folder / "out")]
    out = io.StringIO()
    t0 = time.perf_counter()
    with contextlib.redirect_stdout(out):
        code = main(argv)
    seconds = time.perf_counter() - t0
    result = {"code": code, "seconds": seconds, "lines": out.getvalue().splitlines(),
              "out": folder / "out"}
    for name in ("summary", "eigenvalues", "unstable"):
        result[name] = json.loads((folder / "out" / f"{name}.json").read_text())
    with open(folder / "out" / "eigenvalues.csv") as f:
        result["csv"] = list(csv.DictReader(f))
    return result


def test_csv_eigenvalues_are_the_quartics_roots(run):
    """re, im: the roots (backward-stable solvers on a well-conditioned 2 x 2 pencil: 1e-9
    relative; the pair at a coalescence is matched by distance); frequency = Im λ/2π;
    damping_ratio = −Re λ/|λ|; the parameter column the values given, under --param-name;
    method one of the two; residual a relative residual at round-off, flagged accurate."""
    assert run["code"] == 0
    rows = run["csv"]
    assert len(rows) == 2 * len(VALUES) * 2      # methods x values x the two modes
    for method in ("full", "projection"):
        for p in VALUES:
            got = [r for r in rows if r["method"] == method and float(r[NAME]) == p]
            z = np.array([complex(float(r["re"]), float(r["im"])) for r in got])
            exact = _quartic_roots(p)
            nearest = exact[np.abs(z[:, None] - exact[None, :]).argmin(axis=1)]
            assert sorted(np.abs(z[:, None] - exact[None, :]).argmin(axis=1)) == [0, 1]
            assert np.allclose(z, nearest, rtol=1e-9, atol=0)
            for r, lam in zip(got, z, strict=True):
                assert float(r["frequency"]) == pytest.approx(lam.imag / (2 * math.pi),
                                                              rel=1e-14)
                assert float(r["damping_ratio"]) == pytest.approx(-lam.real / abs(lam),
                                                                  rel=1e-12, abs=1e-15)
                assert float(r["residual"]) < 1e-13 and r["accurate"] == "True"


def test_json_records_are_the_csv_and_max_re_their_maximum(run):
    """eigenvalues.json holds the same rows per method and value, with max_re = max Re λ."""
    records = run["eigenvalues"]["records"]
    assert run["eigenvalues"]["param_name"] == NAME
    assert run["eigenvalues"]["band_hz"] == list(BAND)
    for method in ("full", "projection"):
        assert [r["p"] for r in records[method]] == VALUES
        for record in records[method]:
            rows = [r for r in run["csv"] if r["method"] == method
                    and float(r[NAME]) == record["p"]]
            assert [(m["mode"], m["re"], m["im"]) for m in record["modes"]] == [
                (int(r["mode"]), float(r["re"]), float(r["im"])) for r in rows]
            assert record["max_re"] == max(m["re"] for m in record["modes"])


def test_coalescence_is_the_quartics_onset(run):
    """Per method, one coalescence: interval the two sampled values around the onset; onset
    its bisected bracket, no wider than --refine-tol, around the onset bisected on the roots;
    p_crit its midpoint; value the growing root at the bracket's unstable end and frequency
    its Im/2π; frequencies the pair's frequencies at the stable end; gap the relative gaps
    |f_a − f_b|/mean(f) of the pair at the stable end and of the growing mode and its
    neighbour at the sampled unstable end."""
    onset = _onset()
    for method in ("full", "projection"):
        (event,) = run["unstable"][method]["coalescences"]
        assert event["interval"] == [STABLE, UNSTABLE]
        low, high = event["onset"]
        assert high - low <= REFINE_TOL and low <= onset + 1e-9 and onset - 1e-9 <= high
        assert event["p_crit"] == 0.5 * (low + high)
        growing = max(_quartic_roots(high), key=lambda z: z.real)
        assert event["value"] == pytest.approx([growing.real, growing.imag], rel=1e-7,
                                               abs=1e-12)
        assert event["frequency"] == pytest.approx(event["value"][1] / (2 * math.pi),
                                                   rel=1e-14)
        f_stable = _quartic_roots(STABLE).imag / (2 * math.pi)
        assert sorted(event["frequencies"]) == pytest.approx(sorted(f_stable), rel=1e-9)
        f_unstable = _quartic_roots(UNSTABLE).imag / (2 * math.pi)
        gaps = [abs(f[0] - f[1]) / (0.5 * (f[0] + f[1])) for f in (f_stable, f_unstable)]
        assert event["gap"] == pytest.approx(gaps, rel=1e-8)
        assert event["growing"] in event["modes"] and sorted(event["modes"]) == [0, 1]


def test_unstable_intervals_and_modes_are_the_growing_roots(run):
    """unstable_intervals: per mode id, the first and last sampled values at which it grows
    (Re λ > growth-tol |λ|) — here 4 to 8, one mode; unstable_modes: at each value, the rows
    that grow."""
    growing_at = [p for p in VALUES if any(map(_grows, _quartic_roots(p)))]
    assert growing_at == [4.0, 6.0, 8.0]
    for method in ("full", "projection"):
        unstable = run["unstable"][method]
        (event,) = unstable["coalescences"]
        assert unstable["unstable_intervals"] == {str(event["growing"]): [[4.0, 8.0]]}
        for step, p in zip(unstable["unstable_modes"], VALUES, strict=True):
            assert step[NAME] == p
            rows = step["modes"]
            assert len(rows) == sum(map(_grows, _quartic_roots(p)))
            assert all(r["mode"] == event["growing"] and r["re"] > 0 for r in rows)


def test_vectors_are_the_growing_modes_eigenvectors(run):
    """--vectors: one file per method, value and growing mode, each an eigenvector of its
    eigenvalue: ‖(λ²M + λC + K(p))w‖ / ((|λ|²‖M‖∞ + |λ|‖C‖∞ + ‖K(p)‖∞)‖w‖) at round-off."""
    files = sorted((run["out"] / "vectors").glob("*.npy"))
    assert [f.name for f in files] == sorted(
        f"{m}_p{i:03d}_mode{e}.npy" for m in ("full", "projection")
        for e in [run["unstable"][m]["coalescences"][0]["growing"]] for i in (2, 3, 4))
    for f in files:
        method, step = f.name.split("_p")[0], int(f.name.split("_p")[1][:3])
        p = VALUES[step]
        (row,) = run["unstable"][method]["unstable_modes"][step]["modes"]
        lam = complex(row["re"], row["im"])
        w = np.load(f)
        Kp = K + p * K1
        residual = np.linalg.norm((lam**2 * M + lam * C + Kp) @ w) / (
            (abs(lam) ** 2 * np.abs(M).sum(1).max() + abs(lam) * np.abs(C).sum(1).max()
             + np.abs(Kp).sum(1).max()) * np.linalg.norm(w))
        assert residual < 1e-13


def test_summary_echoes_and_times(run):
    """param_name, band_hz echoed; max_rate the default 2π FMAX/4; unknowns the matrices'
    size; methods; basis_modes = --modes; full_solver dense below --dense-below (400);
    basis and sweep times positive and, with the rest, within wall_time_s, itself within the
    command's time; no failure, no interruption."""
    s = run["summary"]
    assert s["param_name"] == NAME and s["band_hz"] == list(BAND)
    assert s["max_rate"] == pytest.approx(2 * math.pi * BAND[1] / 4, rel=1e-15)
    assert s["unknowns"] == 2 and s["methods"] == ["full", "projection"]
    assert s["basis_modes"] == 2 and s["full_solver"] == "dense"
    parts = [s["basis_time_s"], *s["sweep_time_s"].values()]
    assert min(parts) > 0 and sum(parts) < s["wall_time_s"] < run["seconds"]
    assert s["failure"] is None and s["interrupted"] is None


def test_printed_lines_say_what_the_files_hold(run):
    """The header (unknowns, parts, values, band, rate), the modal basis (its frequencies
    are those of (sym K, M), by SciPy's eigh), one line per method and value (modes in band,
    max Re λ, growing ids) and the onset line (p_crit, bracket, frequency, modes, gaps)."""
    lines = run["lines"]
    s = run["summary"]
    assert (f"cea: 2 unknowns, parts M, C0, K0, K1; {len(VALUES)} values of {NAME}; band "
            f"0-1 Hz, |Re λ| <= {s['max_rate']:.4g} 1/s") in lines
    f = np.sqrt(scipy.linalg.eigh(0.5 * (K + K.T), M, eigvals_only=True)) / (2 * math.pi)
    (basis,) = [x for x in lines if x.startswith("modal basis:")]
    assert f"2 modes of (sym K, M), {f[0]:.4g}-{f[-1]:.4g} Hz" in basis
    for method in ("full", "projection"):
        for record, unstable in zip(run["eigenvalues"]["records"][method],
                                    run["unstable"][method]["unstable_modes"], strict=True):
            (line,) = [x for x in lines if re.match(
                rf"{method}\s+{NAME}={record['p']:.6g}\s", x)]
            assert f"{len(record['modes'])} in band" in line
            assert f"max Re λ={record['max_re']:.4g}" in line
            assert f"growing: {[r['mode'] for r in unstable['modes']]}" in line
        (e,) = run["unstable"][method]["coalescences"]
        assert (f"{method}: mode {e['growing']} grows past {NAME} = {e['p_crit']:.8g} (bracket "
                f"{e['onset'][0]:.8g} to {e['onset'][1]:.8g}) at {e['frequency']:.6g} Hz, "
                f"modes {e['modes']} at relative frequency gap {e['gap'][0]:.3g} -> "
                f"{e['gap'][1]:.3g}") in lines
