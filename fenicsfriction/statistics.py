r"""What an experimenter measures on a stick-slip run: mean forces, the apparent friction
coefficient, stick and open fractions at a probe, the longest stick.

Reads the flat per-step records of any integrator (the finite element block's
``dynamics_observer``, the rigid block's observables); imports NumPy only.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import trapezoid

from fenicsfriction.laws import check

__all__ = ["stick_slip_statistics"]


def _longest_run(t: np.ndarray, flags: np.ndarray) -> float:
    """Longest time span over which ``flags`` holds at consecutive samples (0 if never)."""
    longest, start = 0.0, None
    for time_k, flag in zip(t, flags, strict=True):
        if flag and start is None:
            start = time_k
        elif not flag and start is not None:
            start = None
        if start is not None:
            longest = max(longest, time_k - start)
    return float(longest)


def _time_mean(t: np.ndarray, values: np.ndarray) -> float:
    """Time average of a sampled signal (trapezoidal rule; steps may vary)."""
    return float(trapezoid(values, t) / (t[-1] - t[0]))


def stick_slip_statistics(records: list[dict], mu: float, eps: float,
                          t_from: float = 0.0) -> dict:
    r"""What an experimenter would measure on a run, over the records with time ≥ ``t_from``.

    Needs ``normal_force``, ``friction_force``, ``spring_elongation`` and the probe's
    ``probe_slip``/``probe_pressure`` (see ``BlockModel.dynamics_observer``;
    ``rigid_block_observables`` gives them for the rigid block), and ``energy_error`` if
    there is one (``max_energy_error`` is None otherwise).

    Returns:
        ``apparent_coefficient``: :math:`\bar F_T / \bar N` (time means), the friction
        coefficient a measurement of mean forces would report, against the law's ``mu``
        (``ratio_to_mu``); ``probe_stick_fraction`` / ``probe_open_fraction``: share of the
        time the probe node sticks (in contact, :math:`|\dot u_T - U_T| < \varepsilon`) or is
        out of contact; ``probe_longest_stick`` [s]: its longest uninterrupted stick (a
        stick-slip relaxation cycle against brief adhesions); ``any_stick_fraction``: share of
        the time some contact node sticks (from ``n_stick``; None without it);
        ``mean_normal_force``, ``mean_friction_force``, ``normal_force_range``;
        the spring elongation at the start and end of the window and its mean;
        ``max_energy_error`` over the whole run; ``steps``, ``rejected_steps``,
        ``newton_iterations`` over the whole run.
    """
    check("t_from", t_from, t_from < records[-1]["time"], "must be before the last record")
    t_all = np.array([r["time"] for r in records])
    window = [r for r in records if r["time"] >= t_from]
    t = np.array([r["time"] for r in window])
    series = {key: np.array([r[key] for r in window]) for key in
              ("normal_force", "friction_force", "spring_elongation", "probe_slip",
               "probe_pressure")}
    in_contact = series["probe_pressure"] > 0
    sticks = in_contact & (np.abs(series["probe_slip"]) < eps)
    mean_n = _time_mean(t, series["normal_force"])
    mean_f = _time_mean(t, series["friction_force"])
    return {"t_from": float(t[0]), "t_to": float(t[-1]), "mu": mu, "eps": eps,
            "mean_normal_force": mean_n, "mean_friction_force": mean_f,
            "normal_force_range": [float(series["normal_force"].min()),
                                   float(series["normal_force"].max())],
            "apparent_coefficient": abs(mean_f) / mean_n,
            "ratio_to_mu": abs(mean_f) / mean_n / mu if mu > 0 else float("nan"),
            "probe_stick_fraction": _time_mean(t, sticks.astype(float)),
            "probe_open_fraction": _time_mean(t, (~in_contact).astype(float)),
            "probe_longest_stick": _longest_run(t, sticks),
            "any_stick_fraction": (_time_mean(t, np.array([r["n_stick"] > 0 for r in window],
                                                          dtype=float))
                                   if "n_stick" in window[0] else None),
            "spring_elongation": {"start": float(series["spring_elongation"][0]),
                                  "end": float(series["spring_elongation"][-1]),
                                  "mean": _time_mean(t, series["spring_elongation"])},
            "max_energy_error": (float(max(abs(r["energy_error"]) for r in records))
                                 if "energy_error" in records[0] else None),
            "duration": float(t_all[-1] - t_all[0]), "steps": len(records) - 1,
            "rejected_steps": int(sum(r["rejected_steps"] for r in records)),
            "newton_iterations": int(sum(r["newton_iterations"] for r in records))}
