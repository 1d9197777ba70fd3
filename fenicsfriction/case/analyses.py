r"""The analyses of a case file, run in order on one built model and written as they go.

* **steady** — Newton continuation of steady sliding in one parameter
  (:func:`fenicsfriction.steady.continuation`): ``steady.csv`` one row per value (the
  contacts' normal and friction forces, the friction torque about a rotating foundation's
  axis), ``steady.xdmf`` the displacement at each value.
* **cea** — complex eigenvalue analysis along the same path: the quadratic eigenproblem
  :math:`(\lambda^2 M + \lambda C + \bar K)\phi = 0` of the one residual linearised at each
  steady state (:class:`~fenicsfriction.stability.StabilitySolver`, every eigenvalue with
  :math:`|\lambda| \le 2\pi f_{max}`, those with :math:`f = \mathrm{Im}\,\lambda / 2\pi` in
  the band [fmin, fmax] kept), modes tracked by MAC (:class:`~fenicsfriction.stability.Loci`)
  and each onset of instability bisected: ``cea.csv`` one row per mode and step,
  ``unstable_modes.xdmf`` the most unstable mode shape at each unstable step, ``loci.png``,
  ``growth.png`` and ``coupling_map.png`` (frequency and growth rate of each tracked mode
  against the parameter).
* **transient** — generalized-α integration (:class:`~fenicsfriction.dynamics.DynamicsSolver`)
  from the steady state at ``transient.at`` perturbed by the most unstable mode,
  :math:`u = u_0 + A\,\mathrm{Re}\,\phi`, :math:`\dot u = A\,\mathrm{Re}(\lambda\phi)`
  (φ scaled to a largest nodal displacement of 1): ``transient.csv`` and ``transient.png``;
  the growth rate is measured from the amplitude of the motion on the mode's two real
  vectors, :math:`|c(t)|` with :math:`u - u_0 \approx c_1 \mathrm{Re}\,\phi + c_2
  \mathrm{Im}\,\phi`, by a least-squares line through :math:`\log|c|` over the second half of
  the run, and compared with Re λ.

``summary.json`` holds the case, every step's eigenvalues, the onsets (``mu_crit`` is the first
onset's parameter value, whatever the parameter), the measured growth rate and where the run
stopped. A signal stops the run at the next step with everything computed so far written.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import pathlib
import time
import typing

from mpi4py import MPI

import numpy as np

from fenicsfriction import io, results
from fenicsfriction.case.model import CaseModel
from fenicsfriction.case.schema import Case
from fenicsfriction.steady import SteadySolver

if typing.TYPE_CHECKING:
    from fenicsfriction.stability import Mode, StabilitySolver

__all__ = ["BandSolver", "ModallyDamped", "Outcome", "eigensolver",
           "growth_rate", "run_case"]

#: the most Newton solves of one steady state until a search keeps its contacts' pairing
SEARCH_ROUNDS = 10


@dataclasses.dataclass
class Outcome(results.Record):
    """What a run of a case computed and where it stopped.

    Attributes:
        parameter: the continued parameter's name.
        steady: one row per value reached (the parameter's value under its own name).
        cea: one record per value (``mu``: the parameter's value, ``modes``, ``max_re``), as
            :meth:`fenicsfriction.stability.Loci.follow` gives them.
        onsets: each onset of instability (:class:`~fenicsfriction.stability.Onset`).
        mu_crit: the first onset's parameter value (None: no onset on the path).
        transient: the measured growth rate against Re λ, or None.
        failure: the solver failure that stopped the run, or None.
        interrupted: the signal that stopped the run, or None.
        exit_code: 0, 1 (a failure) or 128 + the signal.
    """

    parameter: str
    steady: list[dict] = dataclasses.field(default_factory=list)
    cea: list[dict] = dataclasses.field(default_factory=list)
    onsets: list[typing.Any] = dataclasses.field(default_factory=list)
    mu_crit: float | None = None
    transient: dict | None = None
    failure: str | None = None
    interrupted: str | None = None
    exit_code: int = 0


class BandSolver:
    """A :class:`~fenicsfriction.stability.StabilitySolver` that keeps the modes of a
    frequency band: what :class:`~fenicsfriction.stability.Loci` tracks, tests for growth and
    bisects is the band's modes only.

    Args:
        solver: the quadratic eigensolver (full, or projected: :class:`ModallyDamped`).
        band: [fmin, fmax] [Hz]; the disc |λ| <= 2π fmax is solved.
    """

    def __init__(self, solver: StabilitySolver | ModallyDamped, band: typing.Sequence[float]):
        self.solver, self.comm = solver, solver.comm
        self.fmin, self.fmax = band
        self.max_modulus = 2 * math.pi * self.fmax

    def solve(self, max_modulus: float) -> list[Mode]:
        """The modes of the band (``max_modulus`` is the band's, 2π fmax)."""
        return [m for m in self.solver.solve(max_modulus)
                if m.value.imag / (2 * math.pi) >= self.fmin]


class ModallyDamped:
    r"""Modal CEA with modal damping: the quadratic eigenproblem projected on the m lowest real
    modes of the frictionless problem
    (:class:`~fenicsfriction.cea.coupling_map.ProjectedStability`), with
    :math:`\mathrm{diag}(2\zeta_i\omega_i)` added to the projected damping matrix
    :math:`\Phi^T C \Phi` — the damping of each basis mode i, defined on the basis only (so
    these pairs carry no residual against the full matrices: ``residual`` is NaN).

    Args:
        stability: the full solver (its matrices are assembled and projected).
        modes: the number m of basis modes.
        zeta: one ratio for every mode, or one per mode.
        prefix: PETSc options prefix of the basis's EPS.
    """

    def __init__(self, stability: StabilitySolver, modes: int, zeta: typing.Sequence[float],
                 prefix: str = "stability_basis_"):
        from fenicsfriction.cea.coupling_map import ProjectedStability

        self.projected = ProjectedStability(stability, modes, prefix=prefix)
        self.comm = stability.comm
        self.zeta = np.broadcast_to(np.asarray(zeta, dtype=float), (modes,))

    def solve(self, max_modulus: float) -> list[Mode]:
        """The projected eigenvalues with |λ| <= ``max_modulus`` (Im λ >= 0), by |λ|."""
        from fenicsfriction.cea.dense import quadratic_eig
        from fenicsfriction.stability import Mode

        projected = self.projected
        if projected.basis is None or not np.any(self.zeta):
            modes = projected.solve(max_modulus)  # the first call computes the basis
            if not np.any(self.zeta):
                return modes
        basis, solver = projected.basis, projected.stability
        assert basis is not None
        solver.assemble()
        damping = np.diag(2 * self.zeta[:basis.size] * np.sqrt(np.maximum(basis.omega2, 0)))
        values, q = quadratic_eig(basis.project(solver.M), basis.project(solver.C) + damping,
                                  basis.project(solver.K))
        modes = [Mode(value=complex(v), residual=float("nan"), accurate=True,
                      vector=basis.phi @ q[:, i])
                 for i, v in enumerate(values) if v.imag >= 0 and abs(v) <= max_modulus]
        return sorted(modes, key=lambda m: abs(m.value))


def growth_rate(time: np.ndarray, amplitude: np.ndarray) -> float:
    """The slope of the least-squares line through log(amplitude) against time [1/s]."""
    keep = amplitude > 0
    return float(np.polyfit(time[keep], np.log(amplitude[keep]), 1)[0])


def _row(model: CaseModel, parameter: str, value: float) -> dict[str, typing.Any]:
    """A flat row: the parameter's value and each contact's resultants."""
    row: dict[str, typing.Any] = {parameter: value}
    for name, forces in model.contact_forces().items():
        row[f"{name}_normal_force"] = forces["normal_force"]
        for axis, f in zip("xyz", forces["friction_force"], strict=False):
            row[f"{name}_friction_force_{axis}"] = f
        if "friction_torque" in forces:
            row[f"{name}_friction_torque"] = forces["friction_torque"]
    return row


def run_case(case: Case, out: pathlib.Path, comm: MPI.Comm = MPI.COMM_WORLD,
             log: logging.Logger | None = None) -> Outcome:
    """Build the case's model and run its analyses, writing into ``out`` as they go.

    Args:
        case: the checked case (:func:`fenicsfriction.case.read_case`).
        out: the output folder (it must exist and be writable).
        comm: the communicator of the mesh.
        log: progress lines (default: the package logger).

    Returns:
        The :class:`Outcome`; ``summary.json`` holds it.
    """
    from fenicsfriction.signals import Interrupted, StopSignals
    from fenicsfriction.stability import EigenSolveError
    from fenicsfriction.steady import ContinuationError
    from fenicsfriction.timestepping import DynamicsError

    log = log or results.get_logger(comm)
    t_start = time.perf_counter()
    model = CaseModel(case, comm)
    model.initial_guess()
    outcome = Outcome(parameter=case.parameter)
    force = max(model.load_magnitude(), 1e-300)
    # a continuation step slides the bodies past master nodes: every steady state is solved
    # again until a search keeps its pairing (body-to-body contact; mortar holds its geometry
    # within a solve)
    solver = SteadySolver(model.residual, prefix="steady_",
                          options={"snes_atol": 1e-10 * force},
                          search_rounds=SEARCH_ROUNDS if model.body_contacts else 1)
    ndofs = model.V.dofmap.index_map.size_global * model.V.dofmap.index_map_bs
    log.info(f"{case.title}: {ndofs} dofs on {comm.size} rank(s), JIT {solver.jit_time_s:.2f} s")

    def summary(where: str = "done") -> None:
        results.write_summary(out / "summary.json", {
            "case": str(case.path), "title": case.title, "status": where,
            **outcome.to_json(), "wall_time_s": time.perf_counter() - t_start}, comm)

    with StopSignals(comm) as stop:  # held to the last file: a late signal waits for it
        try:
            if case.cea is None:
                _steady(case, model, solver, outcome, out, stop, log)
            else:
                _cea(case, model, solver, outcome, out, stop, log, summary)
                if case.transient is not None and outcome.cea:
                    _transient(case, model, solver, outcome, out, stop, log)
        except (ContinuationError, EigenSolveError, DynamicsError) as err:
            value = float(model.parameters[case.parameter].value)
            outcome.failure = f"at {case.parameter} = {value:.6g}: {err}"
            outcome.exit_code = 1
        except Interrupted as err:
            outcome.interrupted, outcome.exit_code = str(err), err.exit_code
        _figures(case, outcome, out, comm)
        signum = comm.allreduce(stop.received, op=MPI.MAX)
        stop.received = 0  # handled here, not again by the command line
        if signum and outcome.interrupted is None:  # after the last step: all is written
            outcome.interrupted = str(Interrupted(signum, "the last step"))
            outcome.exit_code = 128 + signum
        summary("done" if outcome.exit_code == 0 else "stopped")
    comm.Barrier()
    return outcome


def _steady(case: Case, model: CaseModel, solver: typing.Any, outcome: Outcome,
            out: pathlib.Path, stop: typing.Any, log: logging.Logger) -> None:
    from fenicsfriction.steady import continuation

    name = case.parameter
    values = case.steady["values"] if case.steady else [case.parameter_value()]
    max_halvings = case.steady["max_halvings"] if case.steady else 8
    with results.CsvRows(out / "steady.csv", comm=model.msh.comm) as table, \
            DisplacementWriter(out / "steady.xdmf", model) as fields:
        def on_step(record: dict) -> None:
            row = {**_row(model, name, record["value"]),
                   "newton_iterations": record["newton_iterations"],
                   "residual_norm": record["residual_norm"]}
            outcome.steady.append(row)
            table.write(row)
            fields.write(record["value"])
            log.info(_progress(len(outcome.steady) - 1, len(values), name, row))
            stop.check(f"{name} = {record['value']:.6g}")

        continuation(solver, model.parameters[name], values, max_halvings=max_halvings,
                     on_step=on_step)


def _progress(k: int, count: int, name: str, row: dict) -> str:
    forces = "  ".join(f"{key}={value:.4g}" for key, value in row.items()
                       if key.endswith(("normal_force", "friction_force_x", "friction_torque")))
    return f"step {k:3d}/{count - 1}  {name}={row[name]:.6g}  {forces}"


def eigensolver(case: Case, model: CaseModel, prefix: str = "stability_") -> BandSolver:
    """The eigensolver of ``[cea]``: the full quadratic eigenproblem
    (:class:`~fenicsfriction.stability.StabilitySolver`, with its friction switches) or its
    projection on the real modes of the frictionless problem
    (:class:`~fenicsfriction.cea.coupling_map.ProjectedStability`, with the modal damping), in
    the band."""
    from fenicsfriction.stability import StabilitySolver

    cea = case.cea
    assert cea is not None
    full = StabilitySolver(model.residual, prefix=prefix,
                           friction_stiffness=cea["friction_stiffness"],
                           friction_damping=cea["friction_damping"])
    if cea["method"] == "full":
        return BandSolver(full, cea["band"])
    return BandSolver(ModallyDamped(full, cea["modes"], cea["modal_damping"],
                                    prefix=f"{prefix}basis_"), cea["band"])


def _cea(case: Case, model: CaseModel, solver: typing.Any, outcome: Outcome, out: pathlib.Path,
         stop: typing.Any, log: logging.Logger, summary: typing.Callable[[str], None]) -> None:
    from fenicsfriction.stability import Loci

    cea = case.cea
    assert cea is not None and case.steady is not None
    name, values = case.parameter, case.steady["values"]
    band = eigensolver(case, model)
    loci = Loci(solver, band, model.parameters[name], band.max_modulus, cea["growth_tol"])
    transitions: list[tuple[float, float, list]] = []
    previous: dict[str, typing.Any] = {}
    bodies = None
    if cea["contributions"] is not None:
        from fenicsfriction.cea.contributions import FreeInterfaceModes
        bodies = FreeInterfaceModes(model.residual, model.body_cells(), model.interface_tags,
                                    modes=cea["contributions"])
    contributions: list = []
    with results.CsvRows(out / "cea.csv", comm=model.msh.comm) as table, \
            results.CsvRows(out / "steady.csv", comm=model.msh.comm) as steady_table, \
            DisplacementWriter(out / "steady.xdmf", model) as fields, \
            io.ModeWriter(out / "unstable_modes.xdmf", model) as shapes:
        def on_step(record: dict, modes: list) -> None:
            k = len(outcome.cea)
            value = record["mu"]
            outcome.cea.append(record)
            row = _row(model, name, value)
            outcome.steady.append(row)
            steady_table.write(row)
            fields.write(value)
            for m in record["modes"]:
                lam = complex(m["re"], m["im"])
                table.write({name: value, "mode": m["mode"], "re": m["re"], "im": m["im"],
                             "frequency_hz": m["im"] / (2 * math.pi),
                             "damping_ratio": -m["re"] / abs(lam) if lam else 0.0,
                             "residual": m["residual"], "accurate": m["accurate"]})
            growing = loci.unstable(modes)
            if previous and growing and not loci.unstable(previous["modes"]):
                transitions.append((previous["value"], value, previous["modes"]))
            if growing:
                worst = max(growing, key=lambda m: m.value.real)
                shapes.write(worst, value)
                if bodies is not None:
                    contributions.append((value, bodies.contributions(worst)))
            previous.update(value=value, modes=modes)
            log.info(f"{_progress(k, len(values), name, row)}  {len(modes)} modes  max Re λ="
                     f"{record['max_re']:.4g}  growing: {[m.ident for m in growing]}")
            summary("in progress")
            stop.check(f"{name} = {value:.6g} (step {k} of {len(values) - 1})")

        try:
            loci.follow(values, on_step=on_step)
        finally:
            if contributions:
                from fenicsfriction.cea.contributions import plot_contributions
                results.write_json(out / "contributions.json",
                                   [{name: v, **c.to_json()} for v, c in contributions],
                                   model.msh.comm)
                plot_contributions([c for _, c in contributions], out / "contributions.png",
                                   model.msh.comm)
    for stable, unstable, reference in transitions:
        onset = loci.onset(stable, unstable, cea["onset_tol"], reference=reference)
        outcome.onsets.append(onset)
        log.info(f"onset at {name} = {onset.mu_crit:.6g}: λ = {onset.value[0]:.4g} + "
                 f"{onset.value[1]:.6g} i ({onset.value[1] / (2 * math.pi):.6g} Hz), modes "
                 f"{[c['mode'] for c in onset.colliding]}")
        stop.check(f"the onset at {name} = {onset.mu_crit:.6g}")
    outcome.mu_crit = outcome.onsets[0].mu_crit if outcome.onsets else None


def _transient(case: Case, model: CaseModel, solver: typing.Any, outcome: Outcome,
               out: pathlib.Path, stop: typing.Any, log: logging.Logger) -> None:
    from fenicsfriction.dynamics import DynamicsSolver
    from fenicsfriction.stability import is_unstable
    from fenicsfriction.steady import continuation

    tr, cea = case.transient, case.cea
    assert tr is not None and cea is not None
    comm = model.msh.comm
    name = case.parameter
    continuation(solver, model.parameters[name], [tr["at"]])
    band = eigensolver(case, model, prefix="transient_pep_")
    modes = band.solve(band.max_modulus)
    growing = [m for m in modes if is_unstable(m, cea["growth_tol"])]
    if not growing:
        log.info(f"transient: no growing mode at {name} = {tr['at']:.6g}; skipped")
        return
    mode = max(growing, key=lambda m: m.value.real)
    R = model.residual
    owned = len(mode.vector)
    scale = comm.allreduce(float(np.abs(mode.vector).max(initial=0.0)), op=MPI.MAX)
    phi = mode.vector / scale
    u0 = R.u.x.array[:owned].copy()
    R.u.x.array[:owned] += tr["amplitude"] * phi.real
    R.u_dot.x.array[:owned] = tr["amplitude"] * (mode.value * phi).real
    for f in (R.u, R.u_dot):
        f.x.scatter_forward()
    basis = np.column_stack([phi.real, phi.imag])
    gram = comm.allreduce(basis.T @ basis)

    def observe(t: float) -> dict[str, float]:
        c = np.linalg.solve(gram, comm.allreduce(basis.T @ (R.u.x.array[:owned] - u0)))
        return {"amplitude": float(np.hypot(*c))}

    force = max(model.load_magnitude(), 1e-300)
    dynamics = DynamicsSolver(R, prefix="dynamics_", atol=1e-10 * force)
    rows: list[dict] = []
    with results.CsvRows(out / "transient.csv", comm) as table:
        def on_step(record: dict) -> None:
            rows.append(record)
            table.write(record)
            if len(rows) % tr["stride"] == 1:
                log.info(f"t={record['time']:.4e} s  amplitude={record['amplitude']:.4e}")
            stop.check(f"t = {record['time']:.6g} s")

        try:
            dynamics.run(tr["t_end"], tr["dt"], observe=observe, on_step=on_step)
        finally:
            t = np.array([r["time"] for r in rows])
            a = np.array([r["amplitude"] for r in rows])
            late = t >= 0.5 * t[-1] if len(t) else t
            measured = growth_rate(t[late], a[late]) if late.sum() > 2 else None
            outcome.transient = {"at": tr["at"], "eigenvalue": [mode.value.real, mode.value.imag],
                                 "growth_rate_measured": measured, "growth_rate_re_lambda":
                                 mode.value.real, "steps": len(rows) - 1,
                                 "time": t.tolist(), "amplitude": a.tolist()}
            if measured is not None:
                log.info(f"transient: measured growth rate {measured:.5g} 1/s against Re λ = "
                         f"{mode.value.real:.5g} 1/s")


def _figures(case: Case, outcome: Outcome, out: pathlib.Path, comm: MPI.Comm) -> None:
    from fenicsfriction import plotting

    if outcome.cea:
        plotting.plot_loci(outcome.cea, [], out / "loci.png", comm)
        plotting.plot_growth(outcome.cea, [], out / "growth.png", comm)
    if comm.rank != 0:
        return
    if outcome.cea:  # the map brake-squeal engineers read (the onsets are in summary.json)
        from fenicsfriction.cea.figures import plot_coupling_map
        plot_coupling_map([{"p": r["mu"], "modes": [
            {**m, "frequency": m["im"] / (2 * math.pi)} for m in r["modes"]]}
            for r in outcome.cea], out / "coupling_map.png", param_name=outcome.parameter)
    if outcome.steady:
        name = outcome.parameter
        keys = [k for k in outcome.steady[0] if k != name and k.endswith(
            ("normal_force", "friction_force_x", "friction_force_y", "friction_force_z",
             "friction_torque"))]
        with plotting.saved_figure(out / "continuation.png") as axes:
            for key in keys:
                axes[0].plot([r[name] for r in outcome.steady], [r[key] for r in outcome.steady],
                             "o-", ms=3, label=key)
            axes[0].set_xlabel(name)
            axes[0].legend()
            axes[0].grid(alpha=0.3)
    if outcome.transient and outcome.transient["time"]:
        tr = outcome.transient
        with plotting.saved_figure(out / "transient.png") as axes:
            axes[0].semilogy(tr["time"], tr["amplitude"], label="FE amplitude |c(t)|")
            a0 = tr["amplitude"][0]
            axes[0].semilogy(tr["time"], a0 * np.exp(tr["growth_rate_re_lambda"]
                                                     * np.asarray(tr["time"])),
                             "--", label="exp(Re λ t)")
            axes[0].set_xlabel("t [s]")
            axes[0].legend()
            axes[0].grid(alpha=0.3)


class DisplacementWriter(io.ModeWriter):
    """XDMF time series of the displacement (degree 1), the "time" the parameter's value."""

    def __init__(self, path: pathlib.Path, model: CaseModel):
        super().__init__(path, model)
        self.model = model
        self.parts[0].name = "displacement"

    def write(self, t: float) -> None:  # type: ignore[override]
        self.parts[0].interpolate(self.model.residual.u)
        self.file.write_function(self.parts[0], t)
