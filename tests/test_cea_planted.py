r"""Complex eigenvalue analysis: the pieces the planted-bug runs found untested
(tests/planted_bugs.toml, room "cea"), each against a closed form.

* :func:`~fenicsfriction.cea.symmetric_part` of an unsymmetric matrix is :math:`(A + A^T)/2`
  entry by entry: a factor lost there leaves the modal basis's vectors as they are (the
  eigenvectors of :math:`(2K_s, M)` are those of :math:`(K_s, M)`), so the projected
  eigenvalues do not notice; the basis's :math:`\omega^2`, which modal damping uses, does.
* A :class:`~fenicsfriction.cea.ParametricPencil` without :math:`C_0` is
  :math:`C(p) = p\,C_1`: every other test gives C_0, so the sum starts with the coefficient 1.
* The coalescence's reported pair (frequencies and relative gap) on the undamped model of
  Hoffmann et al. (2002), whose two frequencies at any μ are the roots of
  :math:`m^2\omega^4 - m\omega^2\operatorname{tr}K + \det K = 0`.
"""

import math

from mpi4py import MPI

import numpy as np
import pytest

from fenicsfriction.cea import (
    Band,
    HoffmannModel,
    ParametricPencil,
    Sweep,
    dense_modes,
    from_array,
    symmetric_part,
    to_dense,
)

COMM = MPI.COMM_WORLD


def test_the_symmetric_part_is_half_the_sum_with_the_transpose():
    """Entries of order 1, so round-off is 1e-16: tolerance 1e-14."""
    A = np.random.default_rng(7).standard_normal((9, 9))
    Ks = to_dense(symmetric_part(from_array(A, COMM)))
    assert np.allclose(Ks, 0.5 * (A + A.T), rtol=0, atol=1e-14)


def test_a_pencil_without_c0_has_c_proportional_to_the_parameter():
    """C(p) = p C1 and K(p) = K0 + p² K2 when C0 and K1 are absent (exact: one scaling)."""
    rng = np.random.default_rng(3)
    M, K0, C1, K2 = (rng.standard_normal((6, 6)) for _ in range(4))
    pencil = ParametricPencil(M=from_array(M, COMM), K0=from_array(K0, COMM),
                              C1=from_array(C1, COMM), K2=from_array(K2, COMM))
    _, C, K = (to_dense(A) for A in pencil.at(0.3))
    assert np.allclose(C, 0.3 * C1, rtol=0, atol=1e-15)
    assert np.allclose(K, K0 + 0.09 * K2, rtol=0, atol=1e-14)


def undamped_frequencies(model: HoffmannModel, mu: float) -> np.ndarray:
    """The two angular frequencies below the onset: ω² = (tr K ± sqrt(tr² K - 4 det K)) / 2m."""
    parts = model.matrices()
    K = parts["K0"] + mu * parts["K1"]
    tr, det = np.trace(K), np.linalg.det(K)
    root = math.sqrt(tr**2 - 4 * det)
    return np.sqrt(np.array([tr - root, tr + root]) / (2 * model.m))


def test_the_coalescence_reports_the_pairs_frequencies_and_gap_in_closed_form():
    """The sweep's event at the stable end of its interval: the pair's frequencies [Hz] are
    ω/2π of the closed form and the gap |f_a - f_b| / mean(f) is (ω₊ - ω₋) / ((ω₊ + ω₋)/2).
    The 2 × 2 QZ solve is backward stable and these eigenvalues are well separated (gap
    ~0.07 of ω at the last stable value): 1e-10 relative."""
    model = HoffmannModel(k1=1.7, k3=1.3, m=2.0)
    parts = model.matrices()
    band = Band(0.0, 1.0)
    sweep = Sweep(lambda mu: dense_modes(parts["M"], parts["C0"], parts["K0"] + mu * parts["K1"],
                                         band, comm=COMM), COMM, growth_tol=1e-9)
    mu_c, _ = model.undamped_onset()
    sweep.follow(np.linspace(0.0, 2 * mu_c, 24))
    (event,) = sweep.coalescences()
    low, high = undamped_frequencies(model, event.interval[0])
    assert sorted(event.frequencies) == pytest.approx([low / (2 * math.pi),
                                                      high / (2 * math.pi)], rel=1e-10)
    assert event.gap[0] == pytest.approx((high - low) / (0.5 * (high + low)), rel=1e-10)
