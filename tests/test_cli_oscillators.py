"""The command line of the reduced friction oscillators (the m.d.o.f. slider, the belt
oscillator)."""

import csv
import json
import math
import pathlib

from mpi4py import MPI

import pytest

from fenicsfriction.cli import main


@pytest.fixture
def out_dir(shared_tmp_path) -> pathlib.Path:
    return shared_tmp_path / "out"


def test_stability_map_cli_finds_the_principal_band_by_both_methods(out_dir):
    assert main(["oscillators", "slider-map", "--omega-range", "62:65.5", "--samples", "8",
                 "--out", str(out_dir)]) == 0
    data = json.loads((out_dir / "stability_map.json").read_text())
    assert data["natural_frequencies"] == pytest.approx([0.9950, 31.7807], abs=5e-5)
    for method in ("averaging", "floquet"):
        (lo, hi), = data["bands"][method]          # one band, containing 2Ω2 = 63.56
        assert lo < 2 * 31.7807 < hi and len(data["growth"][method]) == 8
    assert (out_dir / "stability_map.png").stat().st_size > 0


def test_belt_cli_cycle_is_the_classic_closed_form(out_dir):
    # m = k = N = 1, c = 0, μ_s = 0.6, μ_k = 0.3, v_b = 0.5: stick until x_s = μ_s N/k, then a
    # harmonic arc x − x_k = R cos ψ about x_k = μ_k N/k from (x_s, v_b), ψ = −φ, to the next
    # ẋ = v_b at ψ = π + φ (x = x_k − Δ), then stuck back up to x_s: Δ = x_s − x_k,
    # R = √(Δ² + (v_b/ω)²), tan φ = v_b/(ωΔ); amplitude 2R, period (π + 2φ)/ω + 2Δ/v_b
    assert main(["oscillators", "belt", "--t-end", "40", "--out", str(out_dir)]) == 0
    summary = json.loads((out_dir / "summary.json").read_text())
    delta, v, omega = 0.3, 0.5, 1.0
    radius = math.hypot(delta, v / omega)
    phi = math.atan2(v / omega, delta)
    slip, stick = (math.pi + 2 * phi) / omega, 2 * delta / v
    assert summary["amplitude"] == pytest.approx(2 * radius, rel=1e-6)
    assert summary["period"] == pytest.approx(slip + stick, rel=1e-6)
    assert summary["events"] >= 10 and not summary["steady_sliding_stable"]
    if MPI.COMM_WORLD.rank == 0:  # the table, row by row: stuck, the spring k x = x is held by
        with open(out_dir / "timeseries.csv") as f:  # friction; slipping, F = μ_k N = 0.3
            rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
        assert rows[-1]["t"] == pytest.approx(40.0) and len(rows) > 4000
        stuck = [r for r in rows if r["stick"]]
        assert stuck and len(stuck) < len(rows)
        for r in stuck:
            assert r["v"] == pytest.approx(v) and r["friction_force"] == pytest.approx(r["x"])
            assert r["x"] <= 0.6 + 1e-9  # μ_s N / k: breakaway
        for r in rows:
            if not r["stick"]:
                assert r["friction_force"] == pytest.approx(0.3, rel=1e-12)


def test_mdof_oscillator_cli_writes_the_time_series(out_dir):
    assert main(["oscillators", "slider", "--omega", "30.16", "--t-end", "1", "--sample-dt",
                 "0.01", "--out", str(out_dir)]) == 0
    if MPI.COMM_WORLD.rank == 0:
        with open(out_dir / "timeseries.csv") as f:
            rows = list(csv.DictReader(f))
        assert {"t", "y_s", "v_1", "normal_force", "friction_force", "stick"} <= set(rows[0])
        assert float(rows[-1]["t"]) == pytest.approx(1.0)
    summary = json.loads((out_dir / "summary.json").read_text())
    assert summary["averaged_growth"] < 0 and summary["floquet_growth"] < 0   # 30.16: stable


@pytest.mark.parametrize(("args", "name"), [
    (["oscillators", "belt", "--m", "0"], "m=0.0"),
    (["oscillators", "belt", "--k", "-1"], "k=-1.0"),
    (["oscillators", "slider", "--omega", "0"], "--omega=0.0"),
    (["oscillators", "slider-map", "--omega-range", "5:1"], "--omega-range='5:1'")])
def test_bad_oscillator_input_is_named(out_dir, capsys, args, name):
    assert main([*args, "--out", str(out_dir)] if args[1] == "slider-map"
                else [*args, "--t-end", "1", "--out", str(out_dir)]) == 2
    if MPI.COMM_WORLD.rank == 0:
        assert name in capsys.readouterr().err
