"""The matrix-free boundary-element operator of benchmarks/bench_kalker_bem.py (Kalker's linear
theory of rolling contact by FFT convolution of the Cerruti influence numbers) against the
benchmark's dense matrices, at grids small enough for a unit test."""

import pathlib
import sys

import numpy as np
import pytest

pytestmark = pytest.mark.sequential

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "benchmarks"))
import bench_kalker_bem as bem  # noqa: E402


def test_fft_operator_equals_the_dense_matrices():
    """Products with random tractions of both parities in y (n = 8, 12; a/b = 0.5, 2) and the
    coefficients of the two solvers (n = 16, 24) agree to rounding and the GMRES tolerance."""
    check = bem.fft_check()
    assert check["product"] < 1e-13
    assert check["coefficients"] < 1e-9


def test_grid_offset_keeps_the_coefficients_of_a_fine_enough_grid():
    """A quarter-cell shift of the grid changes the area-normalised C11 by less than 0.5 % at
    n = 24 (the staircase only moves), and the GMRES residual is met."""
    values = [bem.solve_fft(1.0, 0.25, 24, (offset, offset)) for offset in (0.0, 0.25)]
    c11 = [v["C11"] / v["c_d2"] for v in values]
    assert abs(c11[1] / c11[0] - 1) < 5e-3
    assert max(v["residual"] for v in values) < 1e-9
    assert np.isfinite([v["C33"] for v in values]).all()
