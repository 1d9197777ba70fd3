"""``fenicsfriction cea matrices``: the eigenvalues of a band along a parameter from matrix files
or the built-in Hoffmann model, the onsets, the outputs, and user errors as one line naming the
flag (exit 2) before any matrix is read."""

import csv
import json
import math
import pathlib

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest
import scipy.io
import scipy.sparse
from cli_errors import assert_one_error_line

from fenicsfriction.cea import HoffmannModel, from_array
from fenicsfriction.cli import main

COMM = MPI.COMM_WORLD


@pytest.fixture
def out_dir(shared_tmp_path) -> pathlib.Path:
    return shared_tmp_path / "out"


def on_rank0(write) -> None:
    if COMM.rank == 0:
        write()
    COMM.Barrier()


def hoffmann_chain(n: int) -> dict[str, scipy.sparse.csr_matrix]:
    """n Hoffmann oscillators (default model) in a row, neighbours' x tied by springs of 0.3."""
    parts = HoffmannModel().matrices()
    blocks = {k: scipy.sparse.block_diag([v] * n).tolil() for k, v in parts.items()}
    for i in range(n - 1):
        a, b = 2 * i, 2 * i + 2
        blocks["K0"][a, a] += 0.3
        blocks["K0"][b, b] += 0.3
        blocks["K0"][a, b] -= 0.3
        blocks["K0"][b, a] -= 0.3
    return {k: v.tocsr() for k, v in blocks.items()}


def write_chain(folder: pathlib.Path, n: int) -> dict[str, str]:
    """The chain's M and K0 as MatrixMarket, K1 in a MATLAB file beside another matrix, a
    damping C = 0.01 M as PETSc binary: every format the command reads."""
    parts = hoffmann_chain(n)
    on_rank0(lambda: folder.mkdir(parents=True, exist_ok=True))
    on_rank0(lambda: scipy.io.mmwrite(str(folder / "M.mtx"), parts["M"]))
    on_rank0(lambda: scipy.io.mmwrite(str(folder / "K.mtx"), parts["K0"]))
    on_rank0(lambda: scipy.io.savemat(str(folder / "friction.mat"),
                                      {"K1": parts["K1"], "other": np.eye(2)}))
    viewer = PETSc.Viewer().createBinary(str(folder / "C.petsc"), "w", comm=COMM)
    from_array(0.01 * parts["M"], COMM).view(viewer)
    viewer.destroy()
    return {"--M": str(folder / "M.mtx"), "--K": str(folder / "K.mtx"),
            "--K1": f"{folder / 'friction.mat'}:K1", "--C": str(folder / "C.petsc")}


def test_hoffmann_example_finds_the_damped_onset_by_both_methods(out_dir):
    """--example hoffmann-damped is C = diag(0.02, 0): by hand (Routh-Hurwitz, see the library's
    tests) μ_c = k12/k3 = 1/2 at ω_c = sqrt(k22'/m) = sqrt(5/2); the bisection to 1e-7 with the
    growth threshold 1e-9 |λ| (Re λ grows with slope ~3e-3 past μ_c) lands within 1e-6."""
    assert main(["cea", "matrices", "--example", "hoffmann-damped", "--param-values", "0:1.5:7",
                 "--band", "0:1", "--method", "both", "--modes", "2", "--growth-tol", "1e-9",
                 "--refine-tol", "1e-7", "--param-name", "mu", "--vectors",
                 "--out", str(out_dir)]) == 0
    unstable = json.loads((out_dir / "unstable.json").read_text())
    for method in ("full", "projection"):
        (event,) = unstable[method]["coalescences"]
        assert event["p_crit"] == pytest.approx(0.5, abs=1e-6)
        assert event["frequency"] * 2 * math.pi == pytest.approx(math.sqrt(2.5), rel=1e-4)
        growing = [step for step in unstable[method]["unstable_modes"] if step["modes"]]
        assert [step["mu"] for step in growing] == pytest.approx([0.75, 1.0, 1.25, 1.5])
        assert (out_dir / f"coupling_map_{method}.png").stat().st_size > 0
    assert len(list((out_dir / "vectors").glob("full_p*_mode*.npy"))) == 4
    summary = json.loads((out_dir / "summary.json").read_text())
    assert summary["full_solver"] == "dense" and summary["basis_modes"] == 2
    if COMM.rank == 0:
        with open(out_dir / "eigenvalues.csv") as f:
            rows = list(csv.DictReader(f))
        assert len(rows) == 2 * 7 * 2  # methods × values × the model's two modes
        assert {"method", "mu", "mode", "re", "im", "frequency", "residual",
                "damping_ratio"} <= set(rows[0])


def test_matrix_files_in_every_format_full_equals_projection_on_all_modes(shared_tmp_path,
                                                                         out_dir):
    """A 60-unknown chain read from .mtx, .mat and PETSc binary: the full solve (SLEPc's PEP,
    forced by --dense-below 0) and the projection on all 60 modes give the same eigenvalues
    (both backward stable, well separated eigenvalues: 1e-9 relative)."""
    files = write_chain(shared_tmp_path / "chain", 30)
    args = [a for flag, path in files.items() for a in (flag, path)]
    assert main(["cea", "matrices", *args, "--param-values", "0,0.8", "--band", "0:0.5",
                 "--method", "both", "--modes", "60", "--dense-below", "0",
                 "--out", str(out_dir)]) == 0
    assert json.loads((out_dir / "summary.json").read_text())["full_solver"] == "pep"
    records = json.loads((out_dir / "eigenvalues.json").read_text())["records"]
    for full, projected in zip(records["full"], records["projection"], strict=True):
        a = np.array([complex(m["re"], m["im"]) for m in full["modes"]])
        b = np.array([complex(m["re"], m["im"]) for m in projected["modes"]])
        # pairs that have coalesced share Im λ: matched by distance, not by the written order
        nearest = b[np.abs(a[:, None] - b[None, :]).argmin(axis=1)]
        assert len(a) == len(b) == 60 and np.allclose(nearest, a, rtol=1e-9, atol=0)
        assert max(m["residual"] for m in full["modes"] + projected["modes"]) < 1e-10


@pytest.mark.parametrize(("args", "name"), [
    (["--K", "K.mtx"], "--M"),
    (["--M", "M.mtx", "--K", "missing.mtx"], "--K"),
    (["--example", "hoffmann", "--M", "M.mtx"], "--example"),
    (["--example", "hoffmann", "--band", "3:1"], "--band"),
    (["--example", "hoffmann", "--modes", "4"], "--modes"),
    (["--example", "hoffmann", "--method", "projection", "--modes", "0"], "--modes"),
    (["--M", "M.mtx", "--K", "K.mtx", "--K1", "small.mtx"], "--K1"),
    (["--M", "M.mtx", "--K", "rect.mtx"], "--K"),
    (["--M", "M.mtx", "--K", "K.mtx", "--K1", "friction.mat"], "--K1"),
])
def test_bad_input_is_one_line_naming_the_flag(shared_tmp_path, capsys, args, name):
    folder = shared_tmp_path / "chain"
    write_chain(folder, 2)
    on_rank0(lambda: scipy.io.mmwrite(str(folder / "small.mtx"), np.eye(3)))
    on_rank0(lambda: scipy.io.mmwrite(str(folder / "rect.mtx"), np.ones((4, 3))))
    args = [str(folder / a) if a.endswith((".mtx", ".mat")) else a for a in args]
    extra = [] if "--band" in args else ["--band", "0:1"]
    assert main(["cea", "matrices", *args, *extra, "--param-values", "0:1:3",
                 "--out", str(shared_tmp_path / "out")]) == 2
    assert_one_error_line(capsys.readouterr().err, name)


@pytest.mark.parametrize("values", ["0:1:0", "a:b:3", "1:2"])
def test_bad_parameter_values_stop_the_parser(shared_tmp_path, capsys, values):
    with pytest.raises(SystemExit) as stop:
        main(["cea", "matrices", "--example", "hoffmann", "--param-values", values,
              "--band", "0:1", "--out", str(shared_tmp_path)])
    assert stop.value.code == 2
    assert "argument --param-values: expected LO:HI:N" in capsys.readouterr().err
