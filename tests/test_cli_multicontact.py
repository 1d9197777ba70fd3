"""``fenicsfriction multicontact ...``: multicontact.json with the documented names, each figure
recomputed from the stored records (CSV) or a closed form (the slider, FK), the numbers
against the closed forms of the EQ model and the travelling front, the figures, and a bad value
as one line and exit status 2. Serial and under ``mpirun -n 2``."""

import csv
import json

import numpy as np
import pytest
from cli_errors import assert_one_error_line

from fenicsfriction.cli import main
from fenicsfriction.studies.multicontact.frenkel_kontorova import FKChain, _Chain


def _json(path):
    return json.loads((path / "multicontact.json").read_text())


def test_eq_against_its_master_equation_and_the_kinetic_closed_form(shared_tmp_path):
    out = shared_tmp_path / "eq"
    assert main(["multicontact", "eq", "--N", "4000", "--x-s-std", "0.1", "--X-max", "6",
                 "--out", str(out)]) == 0
    summary = _json(out)
    assert {"parameters", "kinetic_force", "static_force", "K_star", "X", "F"} <= set(summary)
    assert {"N", "k", "x_s_mean", "x_s_std", "newborn"} <= set(summary["parameters"])
    # relaxed newborns: the kinetic force is N k <x_s²>/(2 <x_s>) = N k (x_c² + σ²)/(2 x_c);
    # one realisation of 4000 contacts fluctuates by ~N^(-1/2) = 1.6 %
    assert summary["kinetic_force"] == pytest.approx(4000 * (1 + 0.01) / 2, rel=0.03)
    me = summary["master_equation"]
    assert summary["static_force"] == pytest.approx(me["static_force"], rel=0.03)
    assert summary["K_star"] > 0 and len(summary["X"]) == len(summary["F"])
    assert (out / "eq.png").stat().st_size > 0


def test_eq_with_interacting_contacts_writes_its_avalanches(shared_tmp_path):
    out = shared_tmp_path / "eq-coupled"
    assert main(["multicontact", "eq", "--N", "144", "--coupling", "0.1", "--out", str(out)]) == 0
    summary = _json(out)
    assert summary["parameters"]["coupling"] == 0.1
    # the bodies in series soften the interface: S < N k (0.29 N k on this lattice)
    assert 0.1 * 144 < summary["interface_stiffness"] < 144
    # five contact lives: X_max = 5 x_c N k/S
    assert summary["X"][-1] == pytest.approx(5 * 144 / summary["interface_stiffness"])
    rows = (out / "avalanches.csv").read_text().splitlines()
    assert len(rows) > 144 and summary["largest_avalanche"] > 0.1  # avalanches, not single


def test_coupling_map_has_no_stick_slip_without_interaction_and_some_with(shared_tmp_path):
    out = shared_tmp_path / "coupling-map"
    assert main(["multicontact", "stability-map", "--N", "144", "--couplings", "0,0.1",
                 "--spreads", "0.3", "--lives", "6", "--out", str(out)]) == 0
    summary = _json(out)
    assert summary["stick_slip"] == [[False, True]]
    assert (out / "coupling_map.png").stat().st_size > 0


def test_master_equation_conserves_the_contacts(shared_tmp_path):
    out = shared_tmp_path / "me"
    assert main(["multicontact", "master-equation", "--x-s-std", "0.3", "--out", str(out)]) == 0
    summary = _json(out)
    assert summary["mass_error"] < 1e-12
    assert summary["kinetic_force"] == pytest.approx(1000 * (1 + 0.09) / 2, rel=1e-3)


def test_master_equation_reports_each_figure_as_its_name_says(shared_tmp_path):
    """The defaults (N = 1000, σ = 0.1 x_c, five lives): every key of multicontact.json
    against its definition, by a closed form or recomputed from the stored X, F, x, Q."""
    out = shared_tmp_path / "me-names"
    assert main(["multicontact", "master-equation", "--out", str(out)]) == 0
    s = _json(out)
    X, F, x, Q, h = (np.array(s[key]) for key in ("X", "F", "x", "Q", "h"))
    assert s["h"] == 0.01 and s["parameters"]["N"] == 1000 and s["parameters"]["x_s_std"] == 0.1
    # kinetic: the sliding state, N k ⟨x_s²⟩/(2⟨x_s⟩) = 1000 (1 + 0.01)/2 (the truncation at
    # x_s > 0 is 1e-23 at 10σ), to the scheme's O(h²) = 1.7e-5
    assert s["kinetic_force"] == pytest.approx(505.0, rel=1e-4)
    # the transient's end, named apart: F and N k Σ x Q at X_max = 5 x_c, still 2.5 % above
    assert s["X_max"] == X[-1] == 5.0
    assert s["force_at_X_max"] == F[-1] == pytest.approx(1000 * float(x @ Q), rel=1e-14)
    assert s["force_at_X_max"] / s["kinetic_force"] - 1 == pytest.approx(0.025, abs=0.002)
    assert s["static_force"] == F.max()
    assert s["K_star"] == pytest.approx(-np.min(np.gradient(F, h)), rel=1e-14)
    assert abs(Q.sum() - 1) <= s["mass_error"] < 1e-12
    rows = np.loadtxt(out / "force.csv", delimiter=",", skiprows=1)
    np.testing.assert_array_equal(rows, np.column_stack([X, F]))


def test_stability_map_is_smooth_well_above_K_star_and_stick_slip_well_below(shared_tmp_path):
    out = shared_tmp_path / "map"
    assert main(["multicontact", "stability-map", "--N", "300", "--K", "25,1000", "--spreads",
                 "0.3", "--out", str(out)]) == 0
    summary = _json(out)
    K_star = summary["K_star"][0]
    assert 25 < K_star < 1000  # 0.44 N k for σ = 0.3 x_c
    assert summary["stick_slip"] == [[True, False]]


def _csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {key: np.array([float(r[key]) if r[key] else np.nan for r in rows])
            for key in rows[0]}


def test_fk_reports_each_figure_as_its_name_says(shared_tmp_path):
    out = shared_tmp_path / "fk"
    assert main(["multicontact", "fk", "--n", "120", "--g", "100", "--force", "1.0",
                 "--t-end", "30", "--forces", "1.0", "--out", str(out)]) == 0
    summary, rows = _json(out), _csv(out / "fk.csv")
    p = summary["parameters"]
    n, m, eta, g, k, K, u_s, f = (p[name] for name in ("n", "m", "eta", "g", "k", "K", "u_s",
                                                        "force"))
    kappa, a = k + K, 1.0
    # g = 100: the chain's front is within 1-2 % of the continuum's away from f_min, f_max
    # (docs/multicontact-fk.md); 5 % here
    assert summary["front_speed"] == pytest.approx(summary["continuum_front_speed"], rel=0.05)
    assert summary["relaxed"] == max(1, n // 10)
    assert (summary["f_min"], summary["f_max"]) == pytest.approx(((k / 2 + K) * u_s, kappa * u_s),
                                                                  rel=1e-15)
    # sound_speed: the long-wave limit of the chain's own dispersion. The equations of motion
    # (their Jacobian, by differences: they are linear) have omega_j^2 = (k + K)/m
    # + 4 (g/m) sin^2(j pi / 2n) (free ends), so (omega_1^2 - omega_0^2) / q_1^2 -> c_0^2,
    # q_1 = pi / (n a), to the relative (pi / 2n)^2 / 3 = 5.7e-5
    chain = FKChain(n=n, m=m, eta=eta, g=g, k=k, K=K, u_s=u_s)
    system = _Chain(chain, lambda t: 0.0)
    y0 = np.zeros(system.size)
    stiffness = np.empty((n, n))
    for j in range(n):
        y = y0.copy()
        y[j] = 1.0
        stiffness[:, j] = -(system.rhs(0.0, y, 0) - system.rhs(0.0, y0, 0))[n:2 * n]
    omega2 = np.sort(np.linalg.eigvalsh(0.5 * (stiffness + stiffness.T)))
    j = np.arange(n)
    assert omega2 == pytest.approx(kappa / m + 4 * g / m * np.sin(j * np.pi / (2 * n)) ** 2,
                                   rel=1e-10)
    long_wave = np.sqrt(omega2[1] - omega2[0]) / (np.pi / (n * a))
    assert summary["sound_speed"] == pytest.approx(long_wave, rel=1e-4)
    # continuum_front_speed: the travelling wave u(x - v t) of the continuum limit, decaying
    # as exp(-lambda xi) ahead and exp(mu xi) behind, must match value (u_s) and slope at the
    # break: -lambda (u_s - u_R) = mu (u_s - u_L)
    v = summary["continuum_front_speed"]
    stiff = a**2 * g - m * v**2
    lam = (m * eta * v + np.sqrt((m * eta * v) ** 2 + 4 * stiff * kappa)) / (2 * stiff)
    mu = (-m * eta * v + np.sqrt((m * eta * v) ** 2 + 4 * stiff * kappa)) / (2 * stiff)
    u_R, u_L = f / kappa, (f + k * u_s) / kappa
    assert -lam * (u_s - u_R) == pytest.approx(mu * (u_s - u_L), rel=1e-10)
    # energy_residual: work - (stored - stored(0)) - dissipated - broken_loss, from fk.csv
    residual = rows["work"] - (rows["stored"] - rows["stored"][0]) - rows["dissipated"] \
        - rows["broken_loss"]
    assert summary["energy_residual"] == pytest.approx(np.abs(residual).max(), rel=1e-9)
    assert summary["energy_residual"] < 1e-5 * n
    # contacts_broken: each break loses k u_s^2 / 2 (uniform thresholds), none breaks twice
    assert summary["contacts_broken"] == round(rows["broken_loss"][-1] / (0.5 * k * u_s**2))
    assert np.all(rows["force"] == f)
    # front_speed: a / the slope of the first-break times of contacts first..last, read off
    # fk.csv's front position (each break recorded, its time exact to the event tolerance)
    first, last = max(1, n // 10) + 5, max(1, n // 10) + 5 + max(5, (n - max(1, n // 10)) // 3)
    sites = np.arange(first, last + 1)
    times = [rows["t"][np.flatnonzero(rows["front_position"] >= a * i)[0]] for i in sites]
    assert summary["front_speed"] == pytest.approx(a / np.polyfit(sites, times, 1)[0],
                                                   rel=1e-9)
    # front_speeds: the sweep's own run at the same force breaks at the same times; its closed
    # forms as the module's docstring derives them; front_speeds.csv holds the same numbers
    sweep = summary["front_speeds"]
    assert sweep["measured"][0] == pytest.approx(summary["front_speed"], rel=1e-5)
    assert sweep["continuum"][0] == pytest.approx(v, rel=1e-15)
    assert sweep["sound_speed"] == summary["sound_speed"]
    kink_mass = m * k * u_s / (4 * a * np.sqrt(g * kappa))
    assert sweep["low_velocity"][0] == pytest.approx((f - (k / 2 + K) * u_s)
                                                     / (kink_mass * eta), rel=1e-12)
    assert sweep["high_velocity"][0] == pytest.approx(
        a * np.sqrt(g / m) / np.sqrt(1 + m * eta**2 * (kappa * u_s - f) / (k * kappa * u_s)),
        rel=1e-12)
    table = _csv(out / "front_speeds.csv")
    for key in ("force", "measured", "continuum", "low_velocity", "high_velocity"):
        assert table[key] == pytest.approx(sweep[key], rel=1e-15)
    for name in ("fk.csv", "fk.png"):
        assert (out / name).stat().st_size > 0


def test_interaction_response_falls_like_r_minus_3_beyond_the_correlation_length(
        shared_tmp_path):
    out = shared_tmp_path / "interaction"
    assert main(["multicontact", "interaction", "--n", "192", "--lambda-c", "4",
                 "--out", str(out)]) == 0
    summary = _json(out)
    # beyond λ_c the broken contact's dipole is unscreened: δf ∝ r^-3 (Braun (slides));
    # the fit over r in (3 λ_c, n/4) measures -2.9 on 512² lattices
    # (docs/multicontact-interaction.md)
    assert summary["far_exponent"] == pytest.approx(-3.0, abs=0.35)
    assert (out / "interaction.png").stat().st_size > 0


@pytest.mark.parametrize(("argv", "name"), [
    (["eq", "--N", "0"], "--N"),
    (["master-equation", "--h", "-1"], "--h"),
    (["eq", "--newborn", "gaussian", "--newborn-std", "0"], "--newborn-std"),
    (["fk", "--g", "-1"], "--g"),
    (["slider", "--nx", "10", "--patches", "3"], "--patches"),
    (["eq", "--coupling", "0.1"], "--N"),
    (["stability-map", "--N", "100", "--couplings", "0.1", "--K", "3"], "--K"),
    (["stability-map"], "--K"),
    (["stability-map", "--N", "144", "--couplings", "-0.1"], "--couplings"),
    # a lattice too small to reach the far law's range r > 3 λ_c
    (["interaction", "--n", "32"], "--n")])
def test_bad_value_is_one_line_naming_the_parameter_and_exit_2(shared_tmp_path, capsys, argv,
                                                                name):
    code = main(["multicontact", *argv, "--out", str(shared_tmp_path / "bad")])
    assert code == 2
    assert_one_error_line(capsys.readouterr().err, name)


def test_slider_reports_each_figure_as_its_name_says(shared_tmp_path):
    # contacts that stay off past the run (--delay): each breaks once, so the attached count
    # and the breaks can be told from the fronts
    out = shared_tmp_path / "slider"
    assert main(["multicontact", "slider", "--nx", "10", "--ny", "2", "--t-end", "1e-3",
                 "--dt", "4e-6", "--spread", "0.05", "--push-speed", "4e-3", "--patches", "5",
                 "--viscosity", "2e-6", "--delay", "1", "--out", str(out)]) == 0
    summary, rows = _json(out), _csv(out / "slider.csv")
    p = summary["parameters"]
    assert (p["patches"], p["viscosity"], p["nx"], p["dt"]) == (5, 2e-6, 10, 4e-6)
    L, h, E, nu, rho = p["L"], p["L"] / p["nx"], p["E"], p["nu"], p["rho"]
    c_s = np.sqrt(E / (2 * (1 + nu) * rho))
    assert summary["wave_speeds"]["c_s"] == pytest.approx(c_s, rel=1e-14)
    assert summary["wave_speeds"]["c_p"] == pytest.approx(
        c_s * np.sqrt(2 * (1 - nu) / (1 - 2 * nu)), rel=1e-14)
    force, position = rows["push_force"], rows["front_position"]
    assert summary["peak_push_force"] == np.max(force)
    spanned = np.flatnonzero(np.nan_to_num(position, nan=-1.0) >= L - 0.5 * h)
    assert len(spanned) > 0  # the check has teeth: the far edge broke
    assert summary["slip_force"] == force[spanned[0]]
    found = summary["fronts"]
    assert summary["breaks"] == sum(f["size"] for f in found) > 1
    assert rows["attached"][0] == p["nx"] + 1
    assert rows["attached"][-1] == p["nx"] + 1 - summary["breaks"]
    assert np.all(np.diff(rows["attached"]) <= 0)
    started = np.flatnonzero(np.isfinite(position))[0]
    assert rows["time"][started] == pytest.approx(min(f["start_time"] for f in found), rel=1e-12)
    assert np.nanmax(position) == max(f["tip_x"] for f in found)
    assert any(f["tip_time"] > f["start_time"] for f in found)  # a front with a speed
    for f in found:
        assert f["start_time"] <= f["tip_time"] <= f["end_time"] and f["size"] >= 1
        for x in (f["start_x"], f["tip_x"]):
            assert 0 <= x <= L and x / h == pytest.approx(round(x / h), abs=1e-9)
        assert f["push_force"] == pytest.approx(np.interp(f["start_time"], rows["time"], force),
                                                rel=1e-12)
        assert f["arrested"] == (f["tip_x"] < L - 0.5 * h)
        if f["tip_time"] > f["start_time"]:
            assert f["speed"] == pytest.approx((f["tip_x"] - f["start_x"])
                                               / (f["tip_time"] - f["start_time"]), rel=1e-12)
            assert abs(f["speed"]) <= summary["wave_speeds"]["c_p"]
        else:
            assert f["speed"] is None  # NaN: a front whose tip broke in its first step
    for name in ("slider.csv", "fronts.png", "slider.xdmf"):
        assert (out / name).stat().st_size > 0
