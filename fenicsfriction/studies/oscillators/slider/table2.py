r"""The numerical example of the m.d.o.f. slider paper (2003): Table 2 and its readings.

"Friction-induced sliding instability in a multi-degree-of-freedom system with oscillatory
normal forces" (2003), §5: a 3-d.o.f. slider (one contact) in dimensionless form (Table 2,
eqs. 53-59), the unstable bands it reports, and the readings of what the paper leaves open.
"""

from __future__ import annotations

import math

from fenicsfriction import laws
from fenicsfriction.laws import check
from fenicsfriction.studies.oscillators.slider.model import Contact, ScaledFriction, Slider

__all__ = ["TABLE2_PAPER_BANDS", "TABLE2_READINGS", "table2_slider"]

#: The unstable bands the paper reports (§5) near Ω2 − Ω1, Ω2 + Ω1 and 2 Ω2.
TABLE2_PAPER_BANDS = ((30.74, 30.83), (32.72, 32.83), (62.70, 64.45))

#: Readings of the paper's dimensionless model that it leaves open, by name:
#: (normal_force_factor f_N, velocity unit U of eq. 59, end of eq. 59's sloping branch in its
#: own units). See :func:`table2_slider`.
TABLE2_READINGS: dict[str, tuple[float, float, float]] = {
    "paper": (100.0, 10.0, 20.0),
    "eq59-unmodified": (100.0, 12.0, 15.0),
    "slider-mass": (1.0, 10.0, 20.0),
    "dimensional": (1.0, 1.0, 15.0),
}


def table2_slider(omega: float, reading: str = "paper") -> Slider:
    r"""The paper's 3-d.o.f. example (Table 2, eqs. 53-59), dimensionless, at forcing ω_o.

    Units: slider mass, slider stiffness and asperity height are 1 (time in 1/ω_1 with
    ω_1² = k_s/m_s). Table 2: m̄_1 = 0.01, k̄_1 = 10, c̄_1 = 1, ζ_1 = 0.015, k̄_n = 0.1,
    ζ_n = 0.1, ω_n = √10, N̂_o = 0.05, λ̂ = 16.67. So m_s = k_s = 1, c_s = ζ_1, the contact has
    m = 0.01, k_t = 10, c_t = c̄_1 ζ_1, k_n = k̄_n = m ω_n² (consistent), c_n = m ζ_n, h = 1,
    λ = λ̂, and the surface speed V̂_ref = ω_o λ̂ / 2π (eq. 53). This gives Ω1 = 0.9950,
    Ω2 = 31.7807 (eq. 60) in every reading.

    What the paper leaves open, and the readings offered (``TABLE2_READINGS``):

    * the factor of the normal-force fluctuation: eq. 55 writes N̂ = N̂_o − M̄ ω_o² cos(…),
      i.e. the fluctuation of the *contact*-mass normalisation (f_N = 1/m̄_1 = 100), while the
      slider-mass normalisation of eq. 57 gives m̄_1 x'' (f_N = 1);
    * the velocity unit U of eq. 59 (the slope 0.03 per U): with U = 1 the operating speeds
      V̂_ref = 2.65 ω_o ≈ 82 … 171 lie on the flat branch (S = 0, no instability at all);
    * whether N may reach zero: in all readings the fluctuation exceeds N̂_o = 0.05; the
      linear analysis (eq. 21), like the paper, keeps the signed N.

    ``"paper"`` (f_N = 100, U = 10, S = −0.003) is the reading that puts the three unstable
    bands where the paper does; it needs eq. 59's sloping branch continued to 20 law units
    (μ_k = 0.15 instead of 0.3) so that the 2Ω2 band's speeds (up to 17.1 law units) are on
    it, as the paper's analysis and its Figs. 10-13 require. ``"eq59-unmodified"`` keeps eq.
    59 as printed with the smallest unit (U = 12) that keeps every studied speed on its slope;
    ``"slider-mass"`` takes f_N = 1 with the paper's slope; ``"dimensional"`` is the consistent
    dimensional reading (f_N = 1, U = 1: every speed on the flat branch).

    Args:
        omega: the forcing frequency ω_o > 0.
        reading: a key of ``TABLE2_READINGS``.

    Returns:
        The :class:`~fenicsfriction.studies.oscillators.slider.model.Slider`.

    Raises:
        ValueError: an unknown reading or a non-positive frequency.
    """
    check("reading", reading, reading in TABLE2_READINGS,
          f"must be one of {sorted(TABLE2_READINGS)}")
    check("omega", omega, math.isfinite(omega) and omega > 0, "must be a positive frequency")
    factor, unit, v_c = TABLE2_READINGS[reading]
    law = ScaledFriction(laws.PiecewiseLinearFriction(mu_s=0.75, slope=0.03, v_c=v_c), unit)
    m, zeta_1, zeta_n, lam = 0.01, 0.015, 0.1, 16.67
    contact = Contact(mass=m, k_t=10.0, c_t=1.0 * zeta_1, k_n=m * 10.0, c_n=m * zeta_n,
                      normal_load=0.05, roughness=1.0, wavelength=lam,
                      surface_speed=omega * lam / (2 * math.pi),
                      law=laws.InterfaceLaw(friction_coefficient=law, regularisation="smooth"),
                      normal_force_factor=factor)
    return Slider(mass=1.0, stiffness=1.0, damping=zeta_1, contacts=[contact])
