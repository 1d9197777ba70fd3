"""``block steady|dynamics``: every figure written checked for what its name says.

The time series' columns come from one observer (``BlockModel.dynamics_observer``). Each is
checked in two ways:

* on a state whose every column has a closed form: a rigid motion of the block, a
  translation plus a small rotation. The penetration is then linear along the base, and each
  integral is evaluated here by adaptive quadrature (``scipy.integrate.quad``);
* on the columns of a short ``block dynamics`` run (one run for the module), recomputed from
  the other columns of the same row and from the parameters echoed in ``summary.json``.

``block steady`` and ``block stability`` get the same treatment, one run each for the
module. The steady records and summary are checked against statics and the mesh's
closed-form counts. The stability loci at μ = 0 are checked against the rigid block's
closed-form frequencies. The ``statistics`` block of
``block dynamics`` is checked in tests/test_cli.py. The audit table is in
docs/verification.md, under "Reported figures".
"""

import csv
import dataclasses
import json
import pathlib
import re
import time
import typing

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import pytest
from capture import logged_lines, shared_folder, stdout_into
from scipy.integrate import quad, trapezoid

from fenicsfriction.cli import main

COMM = MPI.COMM_WORLD


# --- the observer on a rigid motion ------------------------------------------------------------

#: the rigid motion: translation (a, -b), rotation theta about the centroid; velocities
#: (vx, vy) and angular velocity omega. b > theta L/2 keeps every base node in contact.
A, B, THETA = 2e-3, 1e-4, 1.5e-6
VX, VY, OMEGA = 0.01, -0.02, 4e-4
MU, B_N = 0.4, 0.381e10


def test_each_column_of_a_rigid_motion_is_its_closed_form():
    """u = (a - θ(y - H/2), -b + θ(x - L/2)), u̇ = (vx - ω(y - H/2), vy + ω(x - L/2)): the base
    (y = 0) penetrates by d(x) = b - θ(x - L/2) at the rate ḋ = -(vy + ω(x - L/2)). It slips at
    w = vx + ωH/2 - U everywhere, and |w| ≫ ε, so the friction traction is μ c_n d^m against w.
    Every column follows from these by definition."""
    from fenicsfriction.studies.block.data import BlockOnBelt

    scene = BlockOnBelt()
    scene = dataclasses.replace(scene, law=scene.law.replace(mu=MU, b_n=B_N))
    model = scene.build(COMM)
    model.mu.value = MU
    L, H, B0, M = scene.L, scene.H, scene.B0, scene.mass
    law = scene.law
    c_n, m, l_n = law.c_n, law.m_n, law.l_n
    U = scene.belt_direction * scene.belt_speed
    u, u_dot = model.residual.u, model.residual.u_dot
    u.interpolate(lambda x: np.stack([A - THETA * (x[1] - H / 2), -B + THETA * (x[0] - L / 2)]))
    u_dot.interpolate(lambda x: np.stack([VX - OMEGA * (x[1] - H / 2),
                                          VY + OMEGA * (x[0] - L / 2)]))
    row = model.dynamics_observer()(0.0)

    def d(x):
        return B - THETA * (x - L / 2)

    def d_rate(x):
        return -(VY + OMEGA * (x - L / 2))

    def over_base(f):
        return B0 * quad(f, 0.0, L, epsabs=0, epsrel=1e-12)[0]

    w = VX + OMEGA * H / 2 - U
    elastic = over_base(lambda x: c_n * d(x) ** m)
    damping = over_base(lambda x: B_N * d(x) ** l_n * d_rate(x))
    friction = -np.sign(w) * MU * elastic
    # the contact integrals use the residual's 5-point Gauss rule per facet on a d^2.5 that
    # varies by ±40 % along the base: measured agreement 2e-15; the volume integrals of the
    # linear fields are exact. 1e-9 leaves room for round-off on other machines
    rel = 1e-9
    assert row["u_yG"] == pytest.approx(-B, rel=1e-12)
    assert row["v_yG"] == pytest.approx(VY, rel=1e-12)
    assert row["v_xG"] == pytest.approx(VX, rel=1e-12)
    assert row["theta"] == pytest.approx(THETA, rel=1e-10)
    # ½ ∫ρ|u̇|²: the centre of mass's ½ M |v|² and the rotation's ½ I ω², I = M (L² + H²)/12
    kinetic = 0.5 * M * (VX**2 + VY**2) + 0.5 * M * (L**2 + H**2) / 12 * OMEGA**2
    assert row["kinetic_energy"] == pytest.approx(kinetic, rel=1e-12)
    assert row["normal_force_elastic"] == pytest.approx(elastic, rel=rel)
    assert row["normal_force"] == pytest.approx(elastic + damping, rel=rel)
    # x of the elastic normal resultant, from mid-base
    centre = over_base(lambda x: (x - L / 2) * c_n * d(x) ** m) / elastic
    assert row["centre_of_pressure"] == pytest.approx(centre, rel=rel)
    # extremes over the base nodes: the corners (θ > 0: deepest at x = 0)
    assert row["max_penetration"] == pytest.approx(d(0.0), rel=1e-10)
    assert row["min_penetration"] == pytest.approx(d(L), rel=1e-10)
    assert row["friction_force"] == pytest.approx(friction, rel=rel)
    # powers of the interface tractions on the body: friction t_T u̇_x (u̇_x is uniform on the
    # base), damping -∫ b_n d^l ḋ² (≤ 0)
    assert row["friction_power"] == pytest.approx(friction * (VX + OMEGA * H / 2), rel=rel)
    assert row["damping_power"] == pytest.approx(
        -over_base(lambda x: B_N * d(x) ** l_n * d_rate(x) ** 2), rel=rel)
    # the driver spring at (0, h_s): F = -K_x u_x there
    u_spring = A - THETA * (scene.spring_height - H / 2)
    assert row["spring_force"] == pytest.approx(-scene.K_x * u_spring, rel=1e-10)
    assert row["spring_elongation"] == pytest.approx(u_spring, rel=1e-10)
    # the probe (default L/2, a node of the Q2 mesh): its own values, and the law there
    x = L / 2
    assert row["probe_x"] == pytest.approx(x, rel=1e-12)
    assert row["probe_u_y"] == pytest.approx(-d(x), rel=1e-10)
    assert row["probe_v_x"] == pytest.approx(VX + OMEGA * H / 2, rel=1e-10)
    assert row["probe_v_y"] == pytest.approx(VY, rel=1e-10)
    assert row["probe_slip"] == pytest.approx(w, rel=1e-10)
    assert row["probe_pressure"] == pytest.approx(
        c_n * d(x) ** m + B_N * d(x) ** l_n * d_rate(x), rel=1e-10)
    assert row["probe_friction"] == pytest.approx(-np.sign(w) * MU * c_n * d(x) ** m, rel=1e-10)
    # 9 base nodes (4 Q2 facets), all pressed and slipping; nothing has happened yet
    assert (row["n_open"], row["n_stick"], row["n_slip"]) == (0, 0, 9)
    assert row["energy_error"] == 0.0


# --- block dynamics: the columns of one run -------------------------------------------------

#: the perturbation of the steady state's normal velocity, and the run's time step
KICK, DT = -0.01, 1e-5


@pytest.fixture(scope="module")
def dynamics(tmp_path_factory):
    out = shared_folder(tmp_path_factory, "dynamics") / "out"
    lines = _run_logged(["block", "dynamics", "--mu", "0.6", "--t-end", "2e-4", "--dt", str(DT),
                         "--b-n", "0.381e10", "--perturbation", str(KICK), "--stride", "100",
                         "--out", str(out)])
    headline = [x for x in lines if x.startswith("apparent friction coefficient")]
    if COMM.rank == 0:
        _closing_line_lists_the_files_written(lines[-1])
        summary = json.loads((out / "summary.json").read_text())["statistics"]
        # "apparent friction coefficient <4 decimals> (μ = <mu>), probe node sticks <%>"
        assert headline == [f"apparent friction coefficient "
                            f"{summary['apparent_coefficient']:.4f} (μ = 0.6), probe node "
                            f"sticks {summary['probe_stick_fraction']:.1%} of the time (second "
                            "half of the run)"]
    with (out / "timeseries.csv").open() as table:
        rows = list(csv.DictReader(table))
    columns = {key: np.array([float(r[key]) for r in rows]) for key in rows[0]}
    return json.loads((out / "summary.json").read_text()), columns


def test_dynamics_columns_are_recomputed_from_the_others(dynamics):
    summary, c = dynamics
    p = summary["parameters"]
    law = p["law"]
    assert (summary["scene"], summary["scheme"], summary["dt"], summary["record_every"]) == \
        ("block", "alpha2", DT, 1)
    assert law["mu"] == 0.6 and law["b_n"] == 0.381e10
    # the run starts from steady sliding (the block at rest) kicked by a uniform normal
    # velocity: ½ M KICK² exactly, all of it in v_yG
    assert c["kinetic_energy"][0] == pytest.approx(0.5 * p["mass"] * KICK**2, rel=1e-10)
    assert c["v_yG"][0] == pytest.approx(KICK, rel=1e-10)
    assert c["v_xG"][0] == pytest.approx(0.0, abs=1e-12)
    # ½ M |v_G|² is the part of ½ ∫ρ|u̇|² carried by the centre of mass (Jensen)
    assert np.all(c["kinetic_energy"] >= 0.5 * p["mass"] * (c["v_xG"]**2 + c["v_yG"]**2)
                  * (1 - 1e-12))
    # u_yG is the time integral of v_yG: generalized-α's displacement update is the
    # trapezoidal rule in v up to O(dt²) of the acceleration's change (measured 1.3e-14 of
    # the displacement's change on this run, the Newmark parameters β = 1/4, γ = 1/2)
    t = c["time"]
    change = c["u_yG"] - c["u_yG"][0]
    integral = np.concatenate([[0.0], np.cumsum(0.5 * np.diff(t) * (c["v_yG"][1:]
                                                                    + c["v_yG"][:-1]))])
    assert np.max(np.abs(change - integral)) < 1e-6 * np.max(np.abs(change))
    # the probe's tractions are the law's at its own penetration d = -u_y, approach rate
    # ḋ = -v_y and slip v_x - U
    d = -c["probe_u_y"]
    U = p["belt_direction"] * p["belt_speed"]
    np.testing.assert_allclose(c["probe_slip"], c["probe_v_x"] - U, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(
        c["probe_pressure"], law["c_n"] * d ** law["m_n"]
        + law["b_n"] * d ** law["l_n"] * -c["probe_v_y"], rtol=1e-9)
    assert np.all(np.abs(c["probe_slip"]) > 100 * law["eps"])  # sliding: the bound μ c_n d^m
    np.testing.assert_allclose(c["probe_friction"], -np.sign(c["probe_slip"]) * law["mu"]
                               * law["c_n"] * d ** law["m_T"], rtol=1e-9)
    # the extremes bracket the probe's penetration and the mean one the normal force implies
    assert np.all(c["min_penetration"] <= d * (1 + 1e-12))
    assert np.all(d <= c["max_penetration"] * (1 + 1e-12))
    mean = (c["normal_force_elastic"] / (law["c_n"] * p["B0"] * p["L"])) ** (1 / law["m_n"])
    assert np.all((c["min_penetration"] < mean) & (mean < c["max_penetration"]))
    # the centre of pressure is the moment of the elastic pressure over the normal force:
    # inside the base, behind mid-base (friction tips the block forward: x_cp < 0 for U > 0)
    assert np.all(np.abs(c["centre_of_pressure"]) < p["L"] / 2)
    assert np.all(c["centre_of_pressure"] < 0)
    # power: the work of friction and damping closes the energy balance (energy_error, its
    # residual, is a few 1e-3 of the kinetic energy, test_cli); here the work itself is the
    # time integral of the two power columns, the trapezoidal rule the observer states
    power = c["friction_power"] + c["damping_power"]
    assert np.all(c["damping_power"] <= 0)
    work = trapezoid(power, t)
    assert abs(work) > 1e3 * np.max(np.abs(c["energy_error"]))
    # the rows: the time step, the counters
    np.testing.assert_allclose(np.diff(t), DT, rtol=1e-9)
    assert summary["steps"] == len(t) - 1
    assert summary["sampled_every"] == 1 and summary["stage"] is None  # 21 rows: all kept
    # running_statistics: every column's extremes and trapezoidal time mean over the run,
    # the counters summed (every step is written here: --record-every 1)
    running = summary["running_statistics"]
    assert (running["records"], running["t_from"], running["t_to"]) == (len(t), t[0], t[-1])
    assert running["totals"] == {key: c[key].sum() for key in ("newton_iterations",
                                                               "rejected_steps")}
    assert set(running["fields"]) == set(c) - {"time", "newton_iterations", "rejected_steps"}
    for key, field in running["fields"].items():
        assert (field["min"], field["max"], field["max_abs"]) == \
            (c[key].min(), c[key].max(), np.abs(c[key]).max()), key
        assert field["mean"] == pytest.approx(trapezoid(c[key], t) / (t[-1] - t[0]),
                                              rel=1e-9, abs=1e-12 * field["max_abs"]), key


# --- block steady ---------------------------------------------------------------------------

def _run_logged(argv: list[str]) -> list[str]:
    """Run a command, returning the progress lines it logged (rank 0's; none elsewhere)."""
    with logged_lines() as lines:
        assert main(argv) == 0
    return lines


def _residual_norm(solver: typing.Any) -> float:
    """‖F(u)‖₂ of the steady residual vector at the solver's state, assembled afresh: the
    integrals, the driver spring, the Dirichlet rows (u − g) — the discrete equations whose
    norm Newton drives below its tolerance."""
    from fenicsfriction import _compat
    from fenicsfriction.assembly import assemble_residual

    b = solver.b.duplicate()
    x = _compat.petsc_vec(solver.u)
    assemble_residual(b, solver.L, solver.a, solver.residual.bcs, x, solver.residual.springs,
                      solver.couplings)
    norm = b.norm(PETSc.NormType.NORM_2)
    b.destroy()
    return float(norm)


@pytest.fixture(scope="module")
def steady(tmp_path_factory):
    """The run, with the continuation it makes watched: at each converged target (where it
    calls ``observe``) the residual norm is assembled afresh at the state, and the clock
    read; the clock is read again as each record's ``on_step`` returns."""
    import fenicsfriction.steady

    folder = shared_folder(tmp_path_factory, "steady")
    out = folder / "out"
    real = fenicsfriction.steady.continuation
    watched: dict[str, typing.Any] = {"norms": [], "converged_at": [], "step_ends": []}

    def continuation(solver, parameter, targets, observe=None, on_step=None, **options):
        def observed():
            watched["converged_at"].append(time.perf_counter())
            watched["norms"].append(_residual_norm(solver))
            return observe()

        def stepped(record):
            on_step(record)
            watched["step_ends"].append(time.perf_counter())

        watched["step_ends"].append(time.perf_counter())  # the first step starts here
        return real(solver, parameter, targets, observe=observed, on_step=stepped, **options)

    printed = folder / f"stdout{COMM.rank}.txt"  # with PETSc's monitor of each iteration
    with pytest.MonkeyPatch.context() as patch, stdout_into(printed):
        patch.setattr(fenicsfriction.steady, "continuation", continuation)
        start = time.perf_counter()
        try:
            lines = _run_logged(["block", "steady", "--mu-max", "0.9", "--steps", "3",
                                 "--snapshots", "0", "--out", str(out), "-steady_snes_monitor"])
        finally:  # the option stays in PETSc's database: the later solvers need not print
            PETSc.Options().delValue("steady_snes_monitor")
        watched["elapsed"] = [time.perf_counter() - start]
    watched["printed"] = printed.read_text().splitlines()
    return (json.loads((out / "steady.json").read_text()),
            json.loads((out / "summary.json").read_text()), lines, watched)


def test_steady_records_and_summary_are_what_they_say(steady):
    records, summary, _, _ = steady
    p = summary["parameters"]
    law = p["law"]
    L, B0, W = p["L"], p["B0"], p["weight"]
    assert [r["mu"] for r in records] == pytest.approx([0.0, 0.3, 0.6, 0.9], abs=1e-15)
    for r in records:
        mu = r["mu"]
        # statics: the belt carries W, friction balances the spring at μ W
        assert r["normal_force"] == pytest.approx(W, rel=1e-6)
        assert r["normal_force_elastic"] == r["normal_force"]  # at rest: no damping
        assert r["friction_force"] == pytest.approx(mu * W, rel=1e-6, abs=1e-6)
        # the moment of the friction force about mid-base, at the spring's height h_s,
        # moves the resultant of the pressure back by μ h_s
        assert r["centre_of_pressure"] == pytest.approx(-mu * p["spring_height"], rel=1e-5,
                                                        abs=1e-6)
        # the pressure c_n d^m integrated over the base is N: its mean penetration lies
        # between the extremes (equal at μ = 0 only if the base stayed flat: it does not,
        # the elastic block sags)
        mean = (r["normal_force_elastic"] / (law["c_n"] * B0 * L)) ** (1 / law["m_n"])
        assert r["min_penetration"] < mean < r["max_penetration"]
        assert r["residual_norm"] <= r["atol"] and r["newton_iterations"] >= 1
        assert r["wall_time_s"] > 0 and r["halvings"] == 0
    # μ = 0: symmetric about mid-base
    assert records[0]["centre_of_pressure"] == pytest.approx(0.0, abs=1e-9 * L)
    assert summary["mu_reached"] == summary["mu_last_converged"] == records[-1]["mu"]
    assert summary["tipping_limit"] == pytest.approx(L / (2 * p["spring_height"]), rel=1e-12)
    assert summary["distance_to_tipping"] == pytest.approx(summary["tipping_limit"] - 0.9,
                                                           rel=1e-12)
    # the outermost contact point: the 5-point Gauss-Legendre rule's on the last of the 4
    # facets (the residual's rule for Q2)
    inset = L / 4 * (1 + np.polynomial.legendre.leggauss(5)[0][0]) / 2
    assert summary["discrete_tipping_limit"] == pytest.approx(
        (L / 2 - inset) / p["spring_height"], rel=1e-12)
    # Q2 on 4 × 3 cells: 9 × 7 nodes, two components
    assert summary["dofs"] == 2 * 9 * 7
    assert summary["ranks"] == COMM.size and summary["failure"] is None
    assert summary["eps_last_converged"] is None and summary["stage"] is None
    assert 0 < summary["jit_time_s"] < summary["wall_time_s"]


# --- block stability --------------------------------------------------------------------------

def test_steady_progress_lines_repeat_the_records(steady):
    """Each step's line prints its record's μ, Newton count, |R|, N, F_T and x_cp (to the
    digits shown), and the first line the dofs and both tipping limits of the summary."""
    records, summary, lines, _ = steady
    if COMM.rank != 0:
        assert lines == []
        return
    first = next(x for x in lines if " dofs on " in x)
    assert first.startswith(f"block: {summary['dofs']} dofs on {COMM.size} rank(s)")
    assert f"tipping limit μ = {summary['tipping_limit']:.4g}" in first
    assert first.endswith(f": {summary['discrete_tipping_limit']:.6g})")
    steps = [x for x in lines if x.startswith("step ")]
    assert len(steps) == len(records)
    for k, (line, r) in enumerate(zip(steps, records, strict=True)):
        assert line.startswith(f"step {k:3d}/{len(records) - 1}  ")
        assert f"μ={r['mu']:.4f}" in line
        assert f"Newton {r['newton_iterations']:2d}" in line
        assert f"|R|={r['residual_norm']:.2e}" in line
        assert f"N={r['normal_force']:.4g}" in line and f"F_T={r['friction_force']:.4g}" in line
        assert f"x_cp={r['centre_of_pressure']:.4g}" in line
        assert line.endswith(f"  {r['wall_time_s']:.2f} s")
    _closing_line_lists_the_files_written(lines[-1])


def _closing_line_lists_the_files_written(closing: str) -> None:
    """"results in OUT/: a, b, ...": every file in OUT is listed (an XDMF file's heavy data
    beside it), and every file listed is there."""
    assert closing.startswith("results in ")
    folder, files = closing[len("results in "):].split("/: ", 1)
    listed = set(files.split(", "))
    heavy = {name.replace(".xdmf", ".h5") for name in listed if name.endswith(".xdmf")}
    assert {p.name for p in pathlib.Path(folder).iterdir()} == listed | heavy


def test_steady_residual_norm_and_wall_time_are_what_they_say(steady):
    """``residual_norm``: ‖F(u)‖₂ of the discrete steady equations (SNES's function norm,
    Dirichlet rows included) at the state the step reports, assembled again at that state
    during the run, and PETSc's own monitor's last line of the step's solve; at most the
    step's ``atol`` (1e-10 of the load, raised to the Jacobian's round-off floor where that
    is higher: 4.5e-8 at μ = 0, 1.1e-5 to 3.3e-5 beyond, measured). ``newton_iterations``:
    the monitor's iterations of that solve. ``wall_time_s``: the time of that step alone (not
    cumulative), from the previous step's end to its convergence."""
    records, summary, _, watched = steady
    norms = watched["norms"]
    assert len(norms) == len(records)
    for r, norm in zip(records, norms, strict=True):
        # the same vector assembled again: equal to round-off in the last bits
        assert r["residual_norm"] == pytest.approx(norm, rel=1e-9, abs=1e-300)
        assert 0 < r["residual_norm"] <= r["atol"]
    if COMM.rank != 0:  # the records hold rank 0's clock; PETSc's monitor prints there
        return
    # PETSc's monitor: "k SNES Function norm <norm>" per iteration, k = 0 at each solve's
    # start; a step's Newton iterations are its lines with k >= 1, its residual norm the last
    # line's (printed to 13 digits)
    monitor = [(int(k), float(norm)) for k, norm in re.findall(
        r"^\s*(\d+) SNES Function norm (\S+)", "\n".join(watched["printed"]), re.MULTILINE)]
    solves = [k for k, (it, _) in enumerate(monitor) if it == 0] + [len(monitor)]
    assert len(solves) - 1 == len(records)  # one solve a step: no halving, no search round
    for r, first, end in zip(records, solves[:-1], solves[1:], strict=True):
        assert r["newton_iterations"] == end - first - 1 >= 1
        assert r["residual_norm"] == pytest.approx(monitor[end - 1][1], rel=1e-12)
    starts, ends = watched["step_ends"][:-1], watched["converged_at"]
    for r, start, end in zip(records, starts, ends, strict=True):
        # the step's own window: from the previous record's end to this one's convergence.
        # It holds the step's time and the loop's bookkeeping (microseconds; 0.1 s allowed
        # for a loaded machine's scheduling); a time counted from an earlier start exceeds it
        assert end - start - 0.1 <= r["wall_time_s"] <= end - start
    # the steps, the compilation and the set-up lie within the run's wall time, itself
    # within the command's
    assert sum(r["wall_time_s"] for r in records) + summary["jit_time_s"] < \
        summary["wall_time_s"] < watched["elapsed"][0]


@pytest.fixture(scope="module")
def stability(tmp_path_factory):
    out = shared_folder(tmp_path_factory, "stability") / "out"
    start = time.perf_counter()
    lines = _run_logged(["block", "stability", "--mu-max", "0.2", "--steps", "1", "--out",
                         str(out)])
    data = json.loads((out / "stability.json").read_text())
    if COMM.rank == 0:  # rank 0's clock, within the command's time
        assert 0 < data["wall_time_s"] < time.perf_counter() - start
    return data, lines


def test_stability_loci_at_mu_0_are_the_rigid_blocks_frequencies(stability):
    """At μ = 0 the rigid block on its linearised compliance has three uncoupled modes (the
    spring acts at mid-height, through the centre of mass): sliding on the driver spring,
    ω² = K_x/M; bouncing, ω² = k_n/M, with k_n = m_n W/d₀ the slope of N = c_n d^{m_n} B0 L at
    the penetration d₀ that carries W; rocking, ω² = k_n (L²/12) / (M (L² + H²)/12)."""
    data, _ = stability
    p = data["parameters"]
    law = p["law"]
    M, W, L, H = p["mass"], p["weight"], p["L"], p["H"]
    d0 = (W / (law["c_n"] * p["B0"] * L)) ** (1 / law["m_n"])
    k_n = law["m_n"] * W / d0
    expected = sorted([np.sqrt(p["K_x"] / M), np.sqrt(k_n / M),
                       np.sqrt(k_n * L**2 / (M * (L**2 + H**2)))])
    rigid = data["rigid"]["steps"][0]
    assert rigid["mu"] == 0.0
    assert sorted(im for _, im in rigid["eigenvalues"]) == pytest.approx(expected, rel=1e-9)
    assert all(re == 0.0 for re, _ in rigid["eigenvalues"])
    # the FE block's lowest mode is the same sliding on the spring: the block is stiff
    # against K_x = 11.1 (E B0 ~ 4e7), 2e-7 softer (measured)
    fe = data["fe"]["steps"]
    assert min(m["im"] for m in fe[0]["modes"]) == pytest.approx(expected[0], rel=1e-5)
    for step in fe + data["rigid"]["steps"]:
        res = [m["re"] for m in step["modes"]] if "modes" in step else \
            [re for re, _ in step["eigenvalues"]]
        assert step["max_re"] == max(res)
    for step in fe:
        for m in step["modes"]:
            assert abs(complex(m["re"], m["im"])) <= data["max_frequency"]
            # stable below the flutter onset (0.37): nothing grows by the growth test
            assert m["re"] <= data["growth_tol"] * abs(complex(m["re"], m["im"]))
    assert data["mu_crit"] == {"fe": None, "rigid": None}
    assert data["fe"]["unstable_intervals"] == {} and data["fe"]["onsets"] == []
    assert (data["max_frequency"], data["growth_tol"], data["ranks"]) == (3e4, 1e-6, COMM.size)
    assert [s["mu"] for s in fe] == [0.0, 0.2] and data["failure"] is None


def test_stability_progress_lines_repeat_the_loci(stability):
    """Each μ's line prints its step's μ, mode count and max Re λ; the closing line the
    critical μ of both models and the FE unstable intervals of stability.json."""
    data, lines = stability
    if COMM.rank != 0:
        assert lines == []
        return
    steps = [x for x in lines if x.startswith("μ=")]
    fe = data["fe"]["steps"]
    assert len(steps) == len(fe)
    for line, step in zip(steps, fe, strict=True):
        assert line.startswith(f"μ={step['mu']:.4f}  {len(step['modes'])} modes  "
                               f"max Re λ={step['max_re']:.4g}")
    closing = [x for x in lines if x.startswith("μ_crit:")]
    assert closing == [f"μ_crit: FE {data['fe']['mu_crit']}, rigid {data['rigid']['mu_crit']}; "
                       f"FE unstable intervals by mode {data['fe']['unstable_intervals']}; "
                       f"rigid {data['rigid']['unstable_intervals']}"]
    _closing_line_lists_the_files_written(lines[-1])
