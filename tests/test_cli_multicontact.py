"""``fenicsfriction multicontact ...``: multicontact.json with the documented names, the numbers
against the closed forms of the EQ model and the travelling front, the figures, and a bad value
as one line and exit status 2. Serial and under ``mpirun -n 2``."""

import json

import numpy as np
import pytest
from cli_errors import assert_one_error_line

from fenicsfriction.cli import main


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
    assert summary["sustained_stick_slip"] == [[False, True]]
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
    assert summary["onset_stick_slip"] == [[True, False]]


def test_fk_front_runs_near_the_continuum_travelling_wave(shared_tmp_path):
    out = shared_tmp_path / "fk"
    assert main(["multicontact", "fk", "--n", "120", "--g", "100", "--force", "1.0",
                 "--t-end", "30", "--out", str(out)]) == 0
    summary = _json(out)
    # g = 100: the chain's front is within 1-2 % of the continuum's away from f_min, f_max
    # (docs/multicontact-fk.md); 5 % here
    assert summary["front_speed"] == pytest.approx(summary["continuum_front_speed"], rel=0.05)
    assert summary["energy_residual"] < 1e-5 * 120
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


def test_slider_writes_its_fronts_and_fields(shared_tmp_path):
    out = shared_tmp_path / "slider"
    assert main(["multicontact", "slider", "--nx", "10", "--ny", "2", "--t-end", "1.6e-3",
                 "--dt", "4e-6", "--spread", "0.05", "--push-speed", "1e-3", "--patches", "5",
                 "--viscosity", "2e-6", "--out", str(out)]) == 0
    summary = _json(out)
    assert summary["breaks"] >= 1 and np.isfinite(summary["peak_push_force"])
    assert (summary["parameters"]["patches"], summary["parameters"]["viscosity"]) == (5, 2e-6)
    speeds = [f["speed"] for f in summary["fronts"] if f["speed"] is not None]  # NaN: null
    assert max(speeds, default=0.0) <= summary["wave_speeds"]["c_p"]
    for name in ("slider.csv", "fronts.png", "slider.xdmf"):
        assert (out / name).stat().st_size > 0
