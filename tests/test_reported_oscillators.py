"""Every figure ``oscillators slider-map|slider|belt`` reports is what its name says: each key
of ``summary.json`` / ``stability_map.json``, each column of ``timeseries.csv`` and the printed
headline lines, checked against its definition — recomputed from the written rows, against a
closed form at the run's settings (the 1-d.o.f. stick-slip cycle, the frequency equation of
Table 2, the characteristic roots) or against an independent computation written here (the
Floquet exponent by SciPy's Runge-Kutta instead of PETSc TS).

One run per command, shared by the module's tests; the audit table is in
docs/verification.md, "Reported figures"."""

import dataclasses
import math
import re

import numpy as np
import pytest
import scipy.integrate
from capture import run_main

from fenicsfriction import laws
from fenicsfriction.events import integrate_hybrid
from fenicsfriction.petsc_options import EVENTS_LOCATED_TO_RESOLUTION
from fenicsfriction.studies.oscillators import BeltOscillator
from fenicsfriction.studies.oscillators.slider import Slider, table2_slider
from fenicsfriction.studies.oscillators.slider.model import ScaledFriction

pytestmark = pytest.mark.sequential  # mesh-free: no MPI to test, the MPI pass skips it

#: the belt oscillator, every parameter away from 0 and 1 (mass and stiffness told apart)
BELT = {"m": 2.0, "k": 3.0, "N": 1.5, "v-belt": 0.4, "mu-s": 0.6, "mu-k": 0.3}
#: a falling law with damping: c + N μ'(v_b) = 0.08 − 2 × 0.03 > 0, steady sliding stable
BELT_PIECEWISE = {"m": 2.0, "k": 3.0, "N": 2.0, "c": 0.08, "slope": 0.03, "mu-s": 0.6}
SLIDER_OMEGA = 30.78          # inside the Ω2 − Ω1 band: growing, stick-slip within a second
MAP_OMEGAS = (30.0, 31.56, 3)  # samples 30, 30.78, 31.56: the band closed on both sides


def _flags(values: dict) -> list[str]:
    return [f"--{k}={v!r}" for k, v in values.items()]


def _run(argv: list[str], name: str) -> dict:
    """:func:`capture.run_main`, its JSON ``name``; the printed lines as ``lines``."""
    run = run_main(argv, name)
    return {**run, "lines": run["stdout"]}


def _run_logging_calls(argv: list[str], name: str) -> dict:
    """:func:`_run` with every call of the belt oscillator's ``rhs`` and ``events`` logged in
    order, as ("f", t) and ("g", t): the integrator's counters are recounted from it."""
    calls: list[tuple[str, float]] = []
    rhs, events = BeltOscillator.rhs, BeltOscillator.events

    def logged_rhs(self, t, y, mode):
        calls.append(("f", float(t)))
        return rhs(self, t, y, mode)

    def logged_events(self, t, y, mode):
        calls.append(("g", float(t)))
        return events(self, t, y, mode)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(BeltOscillator, "rhs", logged_rhs)
        patch.setattr(BeltOscillator, "events", logged_events)
        run = _run(argv, name)
    return {**run, "calls": calls}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("oscillators")
    lo, hi, samples = MAP_OMEGAS
    return {
        "belt": _run_logging_calls(["oscillators", "belt", *_flags(BELT), "--t-end", "20",
                                    "--out", str(root / "belt")], "summary.json"),
        "piecewise": _run(["oscillators", "belt", *_flags(BELT_PIECEWISE), "--law", "piecewise",
                           "--t-end", "2", "--out", str(root / "piecewise")], "summary.json"),
        "slider": _run(["oscillators", "slider", "--omega", str(SLIDER_OMEGA), "--t-end", "1",
                        "--sample-dt", "0.001", "--out", str(root / "slider")], "summary.json"),
        "map": _run(["oscillators", "slider-map", "--omega-range", f"{lo}:{hi}", "--samples",
                     str(samples), "--out", str(root / "map")], "stability_map.json"),
    }


# --- closed forms and independent computations --------------------------------------------

def _classic_cycle(m, k, N, v, mu_s, mu_k):
    """The 1-d.o.f. stick-slip cycle (c = 0, constant μ_k < μ_s; Popp & Stelter 1990): stuck
    from x_k − Δ up to x_s = μ_s N/k at the belt's speed (2Δ/v), then the harmonic arc
    x − x_k = R cos ψ about x_k = μ_k N/k, ω = √(k/m), from ψ = −φ to π + φ, R = √(Δ² + (v/ω)²),
    tan φ = v/(ωΔ). Returns period, amplitude (peak to peak), x_min, x_max, stick fraction."""
    omega = math.sqrt(k / m)
    x_k, delta = mu_k * N / k, (mu_s - mu_k) * N / k
    radius = math.hypot(delta, v / omega)
    phi = math.atan2(v / omega, delta)
    stick = 2 * delta / v
    period = (math.pi + 2 * phi) / omega + stick
    return {"period": period, "amplitude": 2 * radius, "x_min": x_k - radius,
            "x_max": x_k + radius, "stick_fraction": stick / period}


def _floquet_growth(omega: float, slider=None, rtol: float = 1e-11) -> float:
    """ln max|ρ|/T of the monodromy of M q̈ + C(t) q̇ + K q = 0 over T = 2π/ω (the slider's
    tangential linear periodic system, eq. 27), by SciPy's DOP853 — not the package's PETSc
    TS. ``slider``: Table 2's at ω by default."""
    slider = table2_slider(omega) if slider is None else slider
    M, _, K = slider.tangential_matrices()
    n = len(M)
    Minv = np.linalg.inv(M)

    def rhs(t, z):
        Z = z.reshape(2 * n, 2 * n)
        q, v = Z[:n], Z[n:]
        return np.vstack([v, -Minv @ (slider.periodic_damping(t) @ v + K @ q)]).ravel()

    period = 2 * math.pi / omega
    solution = scipy.integrate.solve_ivp(rhs, (0, period), np.eye(2 * n).ravel(),
                                         method="DOP853", rtol=rtol, atol=1e-2 * rtol)
    monodromy = solution.y[:, -1].reshape(2 * n, 2 * n)
    return float(np.log(np.abs(np.linalg.eigvals(monodromy)).max()) / period)


#: Dormand-Prince RK5(4) (Dormand & Prince 1980): the stage times t_n + c_i h of a step; the
#: seventh stage, at the step's end, is the first of the next step (FSAL), so a step after an
#: accepted or a rejected one may skip its first evaluation
DP5_NODES = (0.0, 0.2, 0.3, 0.8, 8 / 9, 1.0, 1.0)


def _steps_from_calls(calls: list[tuple[str, float]], t_end: float) -> dict:
    """The step attempts of a Dormand-Prince integration recovered from the log of its
    right-hand side ("f", t) and event function ("g", t) calls, apart from the integrator's
    own counters.

    Each attempt from t_n with step h evaluates the right-hand side at t_n + c_i h
    (:data:`DP5_NODES`, the first possibly reused): the calls are split into such runs of 7
    or 6 times, each fixing (t_n, h). An attempt is *kept* when the next one starts at its end
    (the next segment's first attempt, or t_end, for the last); it is *retried* when the next
    one starts at its own start again: rejected by the error control inside the step (no
    event function evaluated in between), or rolled back by the event location (the event
    functions were evaluated at its end and changed sign)."""
    f = [(k, t) for k, (kind, t) in enumerate(calls) if kind == "f"]
    attempts, p = [], 0
    while p < len(f):
        for nodes in (DP5_NODES, DP5_NODES[1:]):
            times = [t for _, t in f[p:p + len(nodes)]]
            if len(times) < len(nodes):
                continue
            h = (times[-1] - times[0]) / (nodes[-1] - nodes[0])
            t_n = times[0] - nodes[0] * h
            tol = 1e-7 * h + 1e-14 * max(abs(t_n), 1.0)
            if h > 0 and all(abs(t - t_n - c * h) <= tol
                             for t, c in zip(times, nodes, strict=True)):
                break
        else:
            raise AssertionError(f"the right-hand side call at t = {f[p][1]!r} starts no "
                                 "Dormand-Prince step")
        last = f[p + len(nodes) - 1][0]
        after = f[p + len(nodes)][0] if p + len(nodes) < len(f) else len(calls)
        attempts.append((t_n, h, any(kind == "g" for kind, _ in calls[last:after])))
        p += len(nodes)
    kept = rejected = rolled_back = 0
    for (t_n, h, evaluated), following in zip(attempts, [*attempts[1:], (t_end, 0.0, False)],
                                              strict=True):
        tol = 1e-7 * h + 1e-13 * abs(following[0])
        if abs(following[0] - (t_n + h)) <= tol:
            kept += 1
        else:
            assert abs(following[0] - t_n) <= tol, (t_n, h, following[0])
            rolled_back, rejected = rolled_back + evaluated, rejected + (not evaluated)
    return {"kept": kept, "rejected": rejected, "rolled_back": rolled_back,
            "rhs": len(f), "attempts": len(attempts)}


def _averaged_growth(slider, omega: float) -> float:
    """First-order averaging of the tangential linear periodic system z' = (A_0 + B(t)) z,
    written here from its definition (Nayfeh & Mook 1979, §5.3; the m.d.o.f. slider paper
    (2003), §4) and not by the package's modal formulas: A_0 the undamped system (eigenvalues
    ±iΩ_k, eigenvectors V), B(t) = −M⁻¹ C(t) in the velocity rows, all damping and its
    modulation (harmonics 0 and ±1 of ω, its Fourier coefficients exact from 8 samples). In
    the frame rotating at ν_k (ν = Ω shifted by ∓σ/2 on the pair Ω2 − Ω1 nearest ω, so that
    ν_2 − ν_1 = ω exactly), only the entries (k, l, p) of V⁻¹ B̂_p V with ν_l − ν_k + pω = 0
    survive the average; the growth is the largest real part of the eigenvalues of
    diag(i(Ω − ν)) + those entries."""
    M, _, K = slider.tangential_matrices()
    n = len(M)
    Minv = np.linalg.inv(M)
    zero = np.zeros((n, n))
    lam, V = np.linalg.eig(np.block([[zero, np.eye(n)], [-Minv @ K, zero]]))
    Vinv = np.linalg.inv(V)
    times = np.arange(8) * 2 * math.pi / omega / 8
    B = [Vinv @ np.block([[zero, zero], [zero, -Minv @ slider.periodic_damping(t)]]) @ V
         for t in times]
    harmonic = {p: sum(b * np.exp(-1j * p * omega * t) for b, t in zip(B, times, strict=True))
                / 8 for p in (-1, 0, 1)}
    frequency = lam.imag
    up = np.flatnonzero(frequency > 0)
    i, j = up[np.argsort(frequency[up])][:2]  # +iΩ1, +iΩ2: the difference resonance
    sigma = omega - (frequency[j] - frequency[i])
    nu = frequency.copy()
    nu[i], nu[j] = frequency[i] - sigma / 2, frequency[j] + sigma / 2
    for k in (i, j):
        nu[np.argmin(np.abs(lam - lam[k].conjugate()))] = -nu[k]
    averaged = np.diag(1j * (frequency - nu))
    for p, Bp in harmonic.items():
        resonant = np.abs(nu[None, :] - nu[:, None] + p * omega) < 1e-9 * omega
        averaged = averaged + np.where(resonant, Bp, 0.0)
    return float(np.linalg.eigvals(averaged).real.max())


def _table2_scaled(scale: float, detuning: float) -> tuple[Slider, float]:
    """Table 2's slider with every small term scaled by ``scale``: the dashpots c_s, c_t and
    the friction slope S (so the mean friction damping S N_o and the parametric term
    S (N(t) − N_o) alike), at ω = Ω2 − Ω1 + scale × detuning; (slider, ω)."""
    base = table2_slider(SLIDER_OMEGA)
    Omega, _ = base.natural_frequencies()
    omega = Omega[1] - Omega[0] + scale * detuning
    contact = base.contacts[0]
    factor, unit, v_c = 100.0, 10.0, 20.0  # the "paper" reading
    law = ScaledFriction(laws.PiecewiseLinearFriction(mu_s=0.75, slope=0.03 * scale, v_c=v_c),
                         unit)
    contact = dataclasses.replace(
        contact, c_t=scale * contact.c_t, surface_speed=omega * contact.wavelength / (2 * math.pi),
        law=laws.InterfaceLaw(friction_coefficient=law, regularisation="smooth"),
        normal_force_factor=factor)
    return Slider(base.mass, base.stiffness, scale * base.damping, [contact]), omega


def _table2_frequencies() -> list[float]:
    """Ω of Table 2's tangential system: the roots of Ω⁴ − 1011 Ω² + 1000 = 0
    (docs/oscillators.md)."""
    return sorted(math.sqrt(r) for r in np.roots([1.0, -1011.0, 1000.0]).real)


def _mode_changes(values: list) -> int:
    return sum(a != b for a, b in zip(values, values[1:], strict=False))


# --- the belt --------------------------------------------------------------------------------

def test_belt_cycle_keys_are_the_closed_form_and_the_rows(runs):
    """period, amplitude, x_min, x_max and stick_fraction are the last cycle's: the closed
    form's (event location to 1e-12, integration at rtol 1e-8: 1e-6), and classic_cycle is
    the closed form itself; the extremes are those of the last period's rows (sampled every
    0.01 s: a sampled extreme misses the true one by at most |ẍ| dt²/8 = ω²R dt²/8 < 1e-5,
    and by the integration's 1e-8: 1e-4)."""
    summary, rows = runs["belt"]["json"], runs["belt"]["rows"]
    assert runs["belt"]["code"] == 0
    exact = _classic_cycle(BELT["m"], BELT["k"], BELT["N"], BELT["v-belt"], BELT["mu-s"],
                           BELT["mu-k"])
    for key, value in exact.items():
        assert summary[key] == pytest.approx(value, rel=1e-6)
        assert summary["classic_cycle"][key] == pytest.approx(value, rel=1e-12)
    last = [r["x"] for r in rows if r["t"] >= rows[-1]["t"] - summary["period"]]
    assert min(last) == pytest.approx(summary["x_min"], abs=1e-4)
    assert max(last) == pytest.approx(summary["x_max"], abs=1e-4)
    assert summary["period_change"] < 1e-6 and summary["classic_cycle"]["period_change"] == 0


def test_belt_run_keys_are_recounted_from_the_rows(runs):
    """events = the stick/slip switches of the table (no phase is shorter than a sample);
    stick_fraction_run = the share of stuck samples (within one sample per switch); t_end and
    method as written (the counters: the next test)."""
    summary, rows = runs["belt"]["json"], runs["belt"]["rows"]
    stick = [r["stick"] for r in rows]
    assert summary["events"] == _mode_changes(stick) > 4
    dt = rows[1]["t"] - rows[0]["t"]
    stuck = sum(stick[1:]) * dt / rows[-1]["t"]
    assert summary["stick_fraction_run"] == pytest.approx(stuck, abs=summary["events"] * dt / 20)
    # the run starts stuck for x_s/v_b: its share differs from the cycle's
    assert summary["stick_fraction_run"] != pytest.approx(summary["stick_fraction"], rel=1e-3)
    assert summary["t_end"] == rows[-1]["t"] == 20 and summary["method"] == "events"


def test_belt_counters_are_recounted_from_the_calls(runs):
    """rhs_evaluations = the calls of the oscillator's right-hand side, counted by a wrapper
    around it (exact); steps = the accepted steps and rejected_steps = the steps the error
    control rejected, both recovered from the times of those calls by the Dormand-Prince
    stage structure (:func:`_steps_from_calls`, exact). The steps the event location rolled
    back are neither: the run has each kind, so a counter that took one for another shows."""
    summary = runs["belt"]["json"]
    counted = _steps_from_calls(runs["belt"]["calls"], t_end=summary["t_end"])
    assert summary["rhs_evaluations"] == counted["rhs"]
    assert summary["steps"] == counted["kept"]
    assert summary["rejected_steps"] == counted["rejected"]
    assert counted["rejected"] > 0 and counted["rolled_back"] > 0
    assert counted["attempts"] == counted["kept"] + counted["rejected"] + counted["rolled_back"]


class _SteepHalfSwings:
    """x'' = −ω² x, ω = 1e3, split at the turning points (mode "down" while ẋ <= 0): |dg/dt| =
    ω² there, so an event tolerance of 1e-12 needs the time to 1e-18, below its resolution —
    PETSc 3.18's location stalls and the driver stops it and resumes with a larger one. Counts
    its own right-hand side calls."""

    size = 2

    def __init__(self):
        self.calls = 0

    def rhs(self, t, y, mode):
        self.calls += 1
        return np.array([y[1], -1e6 * y[0]])

    def events(self, t, y, mode):
        return np.array([-y[1] if mode == "down" else y[1]])

    def switch(self, t, y, mode, fired):
        return y, "up" if mode == "down" else "down"


def test_rhs_evaluations_are_the_calls_through_stalled_locations():
    """rhs_evaluations counts the calls of the system's right-hand side also where a stalled
    event location is stopped from inside the callback (it used to count that call, which
    evaluates nothing: one too many per relaxed location, 9 on the 0.5 s run). PETSc 3.22
    locates to the time resolution by itself: no stall there, the count is plain."""
    system = _SteepHalfSwings()
    result = integrate_hybrid(system, [1.0, 0.0], "down", 0.1)
    assert (result.relaxed_locations > 0) != EVENTS_LOCATED_TO_RESOLUTION
    assert result.rhs_evaluations == system.calls


def test_steps_from_calls_tells_the_attempts_apart():
    """The recount itself, on a log written here: a 7-call first step from 0 with h = 1,
    accepted; a 6-call step (first stage reused) from 1 with h = 2 rejected; again with
    h = 1, the event functions evaluated after it and rolled back; with h = 0.5 kept, ending
    the run at t_end = 1.5."""
    def step(t_n, h, first=True):
        return [("f", t_n + c * h) for c in (DP5_NODES if first else DP5_NODES[1:])]
    calls = [*step(0, 1), ("g", 1.0), *step(1, 2, False), *step(1, 1, False), ("g", 2.0),
             *step(1, 0.5)]
    assert _steps_from_calls(calls, t_end=1.5) == {
        "kept": 2, "rejected": 1, "rolled_back": 1, "rhs": 26, "attempts": 4}


def test_belt_rows_are_the_friction_law(runs):
    """friction_force: stuck, the force that holds the mass on the belt, k x (c = 0, ẍ = 0);
    slipping, μ_k N; v the belt's speed while stuck."""
    for r in runs["belt"]["rows"]:
        if r["stick"]:
            assert r["v"] == pytest.approx(BELT["v-belt"], rel=1e-12)
            assert r["friction_force"] == pytest.approx(BELT["k"] * r["x"], rel=1e-12,
                                                        abs=1e-15)
        else:
            assert r["friction_force"] == pytest.approx(BELT["mu-k"] * BELT["N"], rel=1e-12)


@pytest.mark.parametrize("name", ["belt", "piecewise"])
def test_belt_linearisation_keys_are_the_characteristic_roots(runs, name):
    """effective_damping = c + N μ'(v_b) (μ' = −slope on the falling branch, 0 for the
    constant law), linear_eigenvalues the roots of m s² + c_eff s + k = 0, and
    steady_sliding_stable iff c_eff > 0; classic_cycle only for the constant law with c = 0."""
    p = BELT if name == "belt" else BELT_PIECEWISE
    summary = runs[name]["json"]
    c_eff = p.get("c", 0.0) - (p["N"] * p["slope"] if "slope" in p else 0.0)
    assert summary["effective_damping"] == pytest.approx(c_eff, abs=1e-12)
    roots = sorted(np.roots([p["m"], c_eff, p["k"]]).astype(complex), key=lambda s: s.imag)
    got = sorted((complex(re, im) for re, im in summary["linear_eigenvalues"]),
                 key=lambda s: s.imag)
    assert np.allclose(got, roots, rtol=1e-12, atol=1e-14)
    assert summary["steady_sliding_stable"] is (c_eff > 0)
    assert ("classic_cycle" in summary) is (name == "belt")


# --- the m.d.o.f. slider ---------------------------------------------------------------------

def test_slider_amplitudes_and_stick_fraction_are_recomputed_from_the_rows(runs):
    """slider_amplitude_first_half/second_half: half the peak-to-peak of y_s over the samples
    before/after t_end/2 (the same samples: exact); stick_fraction: stuck time over the run,
    against the share of stuck samples (within one sample per switch); events at least the
    mode switches seen in the rows (stick, slip forward, slip backward; a phase shorter than
    a sample can hide between two). The rows include the event instants themselves."""
    summary, rows = runs["slider"]["json"], runs["slider"]["rows"]
    assert runs["slider"]["code"] == 0
    t = np.array([r["t"] for r in rows])
    y = np.array([r["y_s"] for r in rows])
    late = t >= t[-1] / 2
    assert summary["slider_amplitude_first_half"] == np.ptp(y[~late]) / 2
    assert summary["slider_amplitude_second_half"] == np.ptp(y[late]) / 2
    V = summary["surface_speed"]
    # the rows at events (V_rel = 0 to round-off, slip about to start) show no direction
    modes = [0 if r["stick"] else int(np.sign(V - r["v_1"])) for r in rows
             if r["stick"] or abs(V - r["v_1"]) > 1e-9 * V]
    switches = _mode_changes(modes)
    assert summary["events"] >= switches > 0
    dt = t[1] - t[0]
    stuck = sum(r["stick"] * (b - a) for r, a, b in zip(rows, t, t[1:], strict=False)) / t[-1]
    assert summary["stick_fraction"] == pytest.approx(stuck, abs=summary["events"] * dt)
    assert summary["stick_fraction"] > 0
    assert summary["t_end"] == t[-1] == 1 and summary["steps"] > 0


def test_slider_rows_are_the_contact_forces_by_their_definitions(runs):
    """normal_force: N_o + f_N m ẍ on the steady normal response (eq. 21), on which the normal
    d.o.f. start and stay (uncoupled roughness: rtol 1e-8 of the fluctuation); friction_force
    stuck: the reaction k_t (y_1 − y_s) + c_t (V − ẏ_s), with ẏ_1 = V; slipping:
    μ(|V − ẏ_1|) N along V − ẏ_1 (eq. 21, the signed N)."""
    contact = table2_slider(SLIDER_OMEGA).contacts[0]
    V = contact.surface_speed
    scale = abs(contact.normal_fluctuation())
    for r in runs["slider"]["rows"]:
        assert r["normal_force"] == pytest.approx(float(contact.normal_force(r["t"])),
                                                  abs=1e-6 * scale)
        if r["stick"]:
            assert r["v_1"] == pytest.approx(V, rel=1e-12)
            assert r["friction_force"] == pytest.approx(
                contact.k_t * (r["y_1"] - r["y_s"]) + contact.c_t * (V - r["v_s"]), rel=1e-9)
        elif abs(V - r["v_1"]) > 1e-9 * V:
            relative = V - r["v_1"]
            assert r["friction_force"] == pytest.approx(
                np.sign(relative) * contact.mu(abs(relative)) * r["normal_force"], rel=1e-9)
        else:  # a row at an event: V_rel = 0 to round-off, the direction is the mode's
            assert abs(r["friction_force"]) == pytest.approx(
                contact.mu(0.0) * abs(r["normal_force"]), rel=1e-9)


def test_slider_linear_keys_are_the_frequency_equation_and_floquet(runs):
    """natural_frequencies: the roots of Ω⁴ − 1011 Ω² + 1000 = 0 (5e-5, the table's digits);
    surface_speed: the V with 2πV/λ = ω_o; floquet_growth: the Floquet exponent computed here
    by SciPy (both integrators at 1e-10: 1e-6 relative); averaged_growth: the slider-map's
    averaging at the same ω_o (same function: exact); both differ, so a swap shows."""
    summary = runs["slider"]["json"]
    assert summary["omega"] == SLIDER_OMEGA and summary["reading"] == "paper"
    assert summary["natural_frequencies"] == pytest.approx(_table2_frequencies(), abs=5e-5)
    contact = table2_slider(SLIDER_OMEGA).contacts[0]
    assert 2 * math.pi * summary["surface_speed"] / contact.wavelength == pytest.approx(
        SLIDER_OMEGA, rel=1e-12)
    assert summary["floquet_growth"] == pytest.approx(_floquet_growth(SLIDER_OMEGA), rel=1e-6)
    omega = runs["map"]["json"]["omega"]
    i = int(np.argmin(np.abs(np.array(omega) - SLIDER_OMEGA)))
    assert omega[i] == pytest.approx(SLIDER_OMEGA, rel=1e-12)
    assert summary["averaged_growth"] == pytest.approx(
        runs["map"]["json"]["growth"]["averaging"][i], rel=1e-12)
    assert summary["floquet_growth"] != pytest.approx(summary["averaged_growth"], rel=0.1)


def test_averaged_growth_is_first_order_averaging(runs):
    """averaged_growth (and the map's averaging) is the growth of the first-order averaged
    equations, written out here in the rotating frame of the Ω2 − Ω1 resonance from the
    undamped system's eigenvectors (:func:`_averaged_growth`), not by the package's modal
    formulas (ξ_ii, Γ²/16 of eq. 47): the same first-order truncation, so equal to round-off
    (1e-9)."""
    summary = runs["slider"]["json"]
    reference = _averaged_growth(table2_slider(SLIDER_OMEGA), SLIDER_OMEGA)
    assert summary["averaged_growth"] == pytest.approx(reference, rel=1e-9)
    assert summary["averaged_growth"] > 0  # inside the band: a sign error shows


def test_averaging_converges_to_floquet_as_the_small_terms_vanish():
    """First-order averaging is the leading term of the Floquet exponent: with the damping,
    the friction slope (so the modulation) and the detuning all scaled by ε (Table 2 at
    ε = 1), the exponent is ε g_1 + O(ε²) with g_1 the averaged growth at ε = 1 (Nayfeh &
    Mook 1979, ch. 5). The package's averaging (the function behind averaged_growth) is
    checked against the Floquet exponent by SciPy at ε = 1/2 and 1/4: it scales as ε, and
    its error falls at least as ε² (ratio >= 3.5 on halving ε; measured 7.8, i.e. ε³ here:
    the O(ε²) correction vanishes at this resonance). A dropped ½ or a wrong Γ²/16 leaves an
    O(ε) error (ratio 2)."""
    detuning = SLIDER_OMEGA - (_table2_frequencies()[1] - _table2_frequencies()[0])
    growth, error = {}, {}
    for scale in (0.5, 0.25):
        slider, omega = _table2_scaled(scale, detuning)
        growth[scale] = slider.averaged().growth
        error[scale] = abs(_floquet_growth(omega, slider, rtol=1e-12) - growth[scale])
    assert growth[0.5] == pytest.approx(2 * growth[0.25], rel=1e-3) and growth[0.25] > 0
    assert error[0.25] < 0.1 * growth[0.25]
    assert error[0.5] / error[0.25] >= 3.5


@pytest.mark.parametrize("name", ["belt", "piecewise", "slider"])
def test_oscillator_wall_time_and_printed_line(runs, name):
    """wall_seconds is positive and less than the command took; the closing line says the
    events and the stick fraction over the run that the summary holds."""
    summary = runs[name]["json"]
    assert 0 < summary["wall_seconds"] < runs[name]["seconds"]
    run_stick = summary.get("stick_fraction_run", summary["stick_fraction"])
    line = [x for x in runs[name]["lines"] if " events, stick fraction " in x][-1]
    events, fraction = re.match(r"(\d+) events, stick fraction (\S+) over the run", line).groups()
    assert int(events) == summary["events"]
    assert float(fraction) == pytest.approx(run_stick, abs=5e-4)


# --- the stability map -----------------------------------------------------------------------

def test_map_growth_is_floquets_and_its_bands_are_sign_changes(runs):
    """growth["floquet"] at each ω against the exponent computed here; each band of each
    method is where that method's growth changes sign (bisected to 1e-4: the growth at
    2e-3 outside an edge is negative, inside positive), and every sample inside a band
    grows, outside decays."""
    data = runs["map"]["json"]
    lo, hi, samples = MAP_OMEGAS
    assert data["omega"] == pytest.approx(np.linspace(lo, hi, samples), rel=1e-15)
    for w, g in zip(data["omega"], data["growth"]["floquet"], strict=True):
        assert g == pytest.approx(_floquet_growth(w), rel=1e-6)
    rate = {"averaging": lambda w: table2_slider(w).averaged().growth,
            "floquet": _floquet_growth}
    for method in ("averaging", "floquet"):
        (band,) = data["bands"][method]
        a, b = band
        assert rate[method](a - 2e-3) < 0 < rate[method](a + 2e-3)
        assert rate[method](b - 2e-3) > 0 > rate[method](b + 2e-3)
        for w, g in zip(data["omega"], data["growth"][method], strict=True):
            assert (g > 0) is (a < w < b)


def test_map_echoes_and_literal_keys(runs):
    """reading echoed; natural_frequencies from the frequency equation; paper_bands the
    paper's §5 bands, literally; seconds_per_omega positive and, times the samples, within
    the run; the printed band lines are the JSON's bands (3 decimals) and times (ms)."""
    data = runs["map"]["json"]
    assert data["reading"] == "paper"
    assert data["natural_frequencies"] == pytest.approx(_table2_frequencies(), abs=5e-5)
    assert data["paper_bands"] == [[30.74, 30.83], [32.72, 32.83], [62.70, 64.45]]
    samples = MAP_OMEGAS[2]
    assert sum(data["seconds_per_omega"].values()) * samples < runs["map"]["seconds"]
    for method in ("averaging", "floquet"):
        assert data["seconds_per_omega"][method] > 0
        (line,) = [x for x in runs["map"]["lines"] if x.startswith(f"{method}: ")]
        bands = [(round(a, 3), round(b, 3)) for a, b in data["bands"][method]]
        assert f"unstable bands {bands}" in line
        ms = float(re.search(r"\((\S+) ms per ω_o\)", line).group(1))
        assert ms == pytest.approx(data["seconds_per_omega"][method] * 1e3, abs=0.006)
