r"""Work-precision of the dynamics integrators on the stick-slip cycle of the block.

Problem 1ε on the block on a moving belt with the data of Martins & Oden (1986), Figs. 13-15
(μ = 0.6, belt speed 0.08 cm/s, normal damping b_n = 0.381e10, l_n = 2.5), ε = 1e-2 cm/s
(the demo's stick band; ``--eps`` changes it), on the paper's 4 × 3 mesh. From the steady
sliding state plus a normal velocity perturbation of -0.01 cm/s the flutter oscillation grows
(Re λ ≈ 400 s⁻¹), the contact nodes lift off and stick for parts of the cycle, and by
t ≈ 8 ms the normal force settles into a saturated stick-slip cycle, N ∈ [≈ 245, ≈ 830].
Over the window
[T/2, T] (T = ``--t-end``, default 16 ms) three properties of that cycle are measured:

* the period: mean spacing of the upward crossings of N − mean(N) (linear interpolation);
* the amplitude: the mean over the cycles of (max N − min N)/2;
* the apparent friction coefficient: mean F / mean N over the window.

Each integrator run reports its wall time (``run`` without the observation of N and F, ~0.4
ms a sample, timed apart), the relative errors of the period and amplitude and the absolute
error of the apparent coefficient against a **reference**: generalized-α (TSALPHA2, ρ∞ = 1)
with a step half the smallest of the runs. The runs:

* generalized-α with fixed steps ``--alpha2-dt`` (the cut-back quarters a step whose Newton
  solve fails and the step grows back);
* generalized-α with PETSc's error control (``ts_adapt_type basic``, the error of TSALPHA2's
  embedded estimate in the displacement, ``--adapt-atol`` [cm], ``ts_rtol`` 0);
* explicit central differences with a lumped mass at 0.9 × its stable step, which the stick
  band sets (2 m_i/(κ c_i), κ = 4) far below the elastic bound 2/ω_max, and at half that.
  Central differences integrate the *lumped-mass* system: against the consistent-mass
  reference their error stops at the lumping error, which is reported as such.

The errors are of the whole trajectory's statistics (growth, first sticking, saturation), not
of one period, so they also measure how well each scheme captures the transitions.

Writes ``bench_dynamics.json`` and ``bench_dynamics.png`` (errors against wall time; N(t) of
the reference and of the default over the last cycles) to ``--out`` and prints a markdown
table. Serial (the 126-dof problem gains nothing from more ranks).
"""

from __future__ import annotations

import logging
import pathlib
import time

from mpi4py import MPI

import numpy as np
from _common import note_solver, save, write_summary
from _common import parser as benchmark_parser
from scipy.integrate import trapezoid

import fenicsfriction as ff
from fenicsfriction.dynamics import CentralDifference, DynamicsError, DynamicsSolver

MU, BELT_SPEED, B_N, EPS = 0.6, 0.08, 0.381e10, 1e-2
PERTURBATION = -0.01  # [cm/s]
T_END = 16e-3  # [s]
ALPHA2_DT = [4e-5, 2e-5, 1e-5, 5e-6, 2.5e-6]  # [s]
ADAPT_ATOL = [1e-5, 1e-6]  # [cm]
CENTRAL_FACTORS = [1.0, 0.5]  # × 0.9 × the stable step
DEFAULT_DT = 1e-5  # the CLI's and the demo's generalized-α step


class Scene:
    """The block at its steady sliding state, reset before every run."""

    def __init__(self, comm: MPI.Comm, eps: float = EPS):
        law = ff.InterfaceLaw(mu=MU, b_n=B_N, eps=eps)
        self.model = ff.BlockOnBelt(belt_speed=BELT_SPEED, law=law).build(comm)
        self.model.initial_guess()
        steady = ff.SteadySolver(self.model.residual, prefix="bench_steady_",
                                 options=self.model.solver_options())
        ff.continuation(steady, self.model.mu, np.linspace(0.0, MU, 13))
        note_solver(steady)
        r = self.model.residual
        self._u, self._v = r.u.x.array.copy(), r.u_dot.x.array.copy()

    def reset(self) -> None:
        r = self.model.residual
        r.u.x.array[:] = self._u
        r.u_dot.x.array[:] = self._v
        r.u_dot.x.array[1::r.V.dofmap.index_map_bs] += PERTURBATION
        r.u_ddot.x.array[:] = 0.0

    def observer(self, sample: float):
        """N and F every ``sample`` seconds at most (central differences take ~1e5 steps);
        ``observe.seconds`` accumulates the time spent observing."""
        last = [-np.inf]

        def observe(t: float) -> dict:
            if t - last[0] < sample and t > 0:
                return {}
            t0 = time.perf_counter()
            last[0] = t
            q = self.model.quantities()
            observe.seconds += time.perf_counter() - t0
            return {"N": q.normal_force, "F": q.friction_force}

        observe.seconds = 0.0
        return observe


def cycle(records: list[dict], t_from: float) -> dict:
    """Period, amplitude and apparent coefficient of the sampled N(t), F(t) on [t_from, end]."""
    rows = [(r["time"], r["N"], r["F"]) for r in records if "N" in r and r["time"] >= t_from]
    t, N, F = (np.array(c) for c in zip(*rows, strict=True))
    mean_n = trapezoid(N, t) / (t[-1] - t[0])
    s = N - mean_n
    up = np.nonzero((s[:-1] < 0) & (s[1:] >= 0))[0]
    crossings = t[up] - s[up] * (t[up + 1] - t[up]) / (s[up + 1] - s[up])
    amplitudes = [0.5 * (N[a:b + 1].max() - N[a:b + 1].min())
                  for a, b in zip(up[:-1], up[1:], strict=True)]
    return {"period": float(np.diff(crossings).mean()), "amplitude": float(np.mean(amplitudes)),
            "apparent_coefficient": float(trapezoid(F, t) / trapezoid(N, t)),
            "cycles": len(amplitudes), "mean_normal_force": float(mean_n)}


def run(scene: Scene, name: str, make, dt: float, t_end: float, sample: float) -> dict:
    """Integrate with the solver ``make()`` builds; wall time of ``run`` alone."""
    say = ff.results.get_logger(MPI.COMM_WORLD).info
    scene.reset()
    solver = make()
    observe = scene.observer(sample)
    t0 = time.perf_counter()
    failure = None
    try:
        records = solver.run(t_end, dt, observe=observe)
    except DynamicsError as err:
        records, failure = err.records, str(err)
    wall = time.perf_counter() - t0 - observe.seconds
    note_solver(solver)
    steps = len(records) - 1
    result = {"name": name, "dt": dt, "wall_time_s": wall, "observe_s": observe.seconds,
              "steps": steps,
              "rejected_steps": int(sum(r["rejected_steps"] for r in records)),
              "newton_iterations": int(sum(r["newton_iterations"] for r in records)),
              "min_dt": float(min(r["dt"] for r in records[1:])), "failure": failure,
              "stable_dt": getattr(solver, "stable_dt", None)}
    if failure is None:
        result.update(cycle(records, 0.5 * t_end))
        result["series"] = [(r["time"], r["N"]) for r in records
                            if "N" in r and r["time"] >= t_end - 3e-3]
    say(f"{name:>28s}: {steps:7d} steps ({result['rejected_steps']} rejected), "
        f"{wall:7.1f} s" + (f", period {result['period'] * 1e3:.5f} ms, amplitude "
                            f"{result['amplitude']:.3f}, F/N {result['apparent_coefficient']:.5f}"
                            if failure is None else f": {failure}"))
    if hasattr(solver, "ts"):
        solver.ts.destroy()
    return result


def errors(runs: list[dict], reference: dict) -> None:
    for r in runs:
        if r["failure"] is None:
            r["period_error"] = abs(r["period"] / reference["period"] - 1)
            r["amplitude_error"] = abs(r["amplitude"] / reference["amplitude"] - 1)
            r["coefficient_error"] = abs(r["apparent_coefficient"]
                                         - reference["apparent_coefficient"])


def table(runs: list[dict], reference: dict) -> str:
    lines = ["| scheme | step [s] | steps (rejected) | wall [s] | wall ÷ default | period error "
             "| amplitude error | F/N error |", "|---|---|---|---|---|---|---|---|"]
    default = next(r for r in runs if r["name"] == f"alpha2 dt={DEFAULT_DT:g}")
    for r in runs:
        if r["failure"] is not None:
            lines.append(f"| {r['name']} | {r['dt']:.3g} | {r['steps']} ({r['rejected_steps']}) "
                         f"| {r['wall_time_s']:.1f} | | failed: {r['failure']} | | |")
            continue
        step = f"{r['dt']:.3g}" if "adapt" not in r["name"] else f"≥ {r['min_dt']:.2g}"
        lines.append(f"| {r['name']} | {step} | {r['steps']} ({r['rejected_steps']}) | "
                     f"{r['wall_time_s']:.1f} | {r['wall_time_s'] / default['wall_time_s']:.2f}"
                     f" | {r['period_error']:.1e} | {r['amplitude_error']:.1e} | "
                     f"{r['coefficient_error']:.1e} |")
    lines.append(f"| reference: alpha2 dt={reference['dt']:.3g} | | {reference['steps']} | "
                 f"{reference['wall_time_s']:.1f} | | period {reference['period'] * 1e3:.5f} ms | "
                 f"amplitude {reference['amplitude']:.3f} | F/N "
                 f"{reference['apparent_coefficient']:.5f} |")
    return "\n".join(lines)


def plot(runs: list[dict], reference: dict, path: pathlib.Path, eps: float) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 4, figsize=(18, 4.2))
    families = {"alpha2 dt": ("o-", "generalized-α, fixed step"),
                "alpha2 adaptive": ("s-", "generalized-α, error control"),
                "central": ("^-", "central differences (lumped)")}
    for ax, key, label in zip(axes[:3], ("period_error", "amplitude_error", "coefficient_error"),
                              ("period, relative error", "amplitude, relative error",
                               "apparent coefficient, abs. error"), strict=True):
        for prefix, (style, name) in families.items():
            rows = [r for r in runs if r["name"].startswith(prefix) and r["failure"] is None]
            if rows:
                ax.loglog([r["wall_time_s"] for r in rows], [max(r[key], 1e-12) for r in rows],
                          style, label=name)
        for r in runs:
            if r["failure"] is None and r["name"].startswith("alpha2 dt"):
                ax.annotate(f"{r['dt']:.3g}", (r["wall_time_s"], max(r[key], 1e-12)),
                            fontsize=7, textcoords="offset points", xytext=(3, 3))
        ax.set_xlabel("wall time [s]")
        ax.set_title(label, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    ax = axes[3]
    t, N = np.array(reference["series"]).T
    ax.plot(t * 1e3, N, "k-", lw=1.5, label=f"reference, dt = {reference['dt']:.3g} s")
    for r in runs:
        if r["failure"] is None and r["name"] in (f"alpha2 dt={DEFAULT_DT:g}", "central ×1"):
            t, N = np.array(r["series"]).T
            ax.plot(t * 1e3, N, "--", lw=1, label=r["name"])
    ax.set_xlabel("t [ms]")
    ax.set_ylabel("normal force N")
    ax.set_title("the last cycles", fontsize=10)
    ax.legend(fontsize=8)
    fig.suptitle(f"Stick-slip cycle of the block (μ = {MU}, U = {BELT_SPEED} cm/s, ε = {eps}): "
                 "error against wall time", fontsize=11)
    save(fig, path, dpi=110)


def main(argv=None) -> None:
    parser = benchmark_parser(__doc__)
    parser.add_argument("--t-end", type=float, default=T_END,
                        help=f"simulated time [s]; the cycle is measured on its second half "
                             f"(default {T_END:g})")
    parser.add_argument("--alpha2-dt", type=float, nargs="+", default=ALPHA2_DT,
                        help="generalized-α fixed steps [s] (must include the default "
                             f"{DEFAULT_DT:g})")
    parser.add_argument("--adapt-atol", type=float, nargs="*", default=ADAPT_ATOL,
                        help="error-control tolerances [cm] (default: "
                             f"{' '.join(map(str, ADAPT_ATOL))})")
    parser.add_argument("--central", type=float, nargs="*", default=CENTRAL_FACTORS,
                        help="central-difference steps as fractions of 0.9 × the stable step")
    parser.add_argument("--eps", type=float, default=EPS,
                        help=f"regularisation ε [cm/s] (default {EPS:g}, the demo's)")
    args = parser.parse_args(argv)
    if not args.eps > 0:
        parser.error(f"--eps={args.eps} must be > 0")
    if DEFAULT_DT not in args.alpha2_dt:
        parser.error(f"--alpha2-dt must include the default step {DEFAULT_DT:g}")
    if args.t_end <= 4 * max(args.alpha2_dt):
        parser.error(f"--t-end={args.t_end} must exceed 4 × the largest step")

    logging.getLogger("ffcx").setLevel(logging.WARNING)
    logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)
    comm = MPI.COMM_WORLD
    say = ff.results.get_logger(comm).info
    t0 = time.perf_counter()
    scene = Scene(comm, args.eps)
    model = scene.model
    atol = 1e-10 * model.force_scale
    sample = 1e-6  # [s]: N's sampling error (ω·1e-6)²/8 ≈ 4e-6 of the amplitude
    dt_ref = 0.5 * min(args.alpha2_dt)
    say(f"reference: generalized-α, dt = {dt_ref:.3g} s, t_end = {args.t_end:g} s")
    reference = run(scene, f"alpha2 dt={dt_ref:g}", lambda: DynamicsSolver(
        model.residual, prefix="bench_ref_", atol=atol), dt_ref, args.t_end, sample)
    if reference["failure"] is not None:
        raise SystemExit(f"the reference run failed: {reference['failure']}")
    runs = [run(scene, f"alpha2 dt={dt:g}", lambda: DynamicsSolver(
        model.residual, prefix="bench_a2_", atol=atol), dt, args.t_end, sample)
        for dt in sorted(args.alpha2_dt, reverse=True)]
    for tol in args.adapt_atol:
        runs.append(run(scene, f"alpha2 adaptive atol={tol:g}", lambda tol=tol: DynamicsSolver(
            model.residual, prefix="bench_adapt_", atol=atol,
            options={"ts_adapt_type": "basic", "ts_atol": tol, "ts_rtol": 0.0}),
            DEFAULT_DT, args.t_end, sample))
    central = CentralDifference(model.residual, band_damping=model.band_damping())
    for factor in args.central:
        runs.append(run(scene, f"central ×{factor:g}", lambda: central,
                        factor * central.safety * central.stable_dt, args.t_end, sample))
    errors(runs, reference)
    total = time.perf_counter() - t0
    if comm.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        plot(runs, reference, args.out / "bench_dynamics.png", args.eps)
        print(f"Stick-slip cycle over [{args.t_end / 2:g}, {args.t_end:g}] s, μ = {MU}, "
              f"U = {BELT_SPEED} cm/s, ε = {args.eps}; central differences: stable step "
              f"{central.stable_dt:.3g} s (elastic {central.stable_dt_elastic:.3g} s); "
              f"total {total:.0f} s\n\n{table(runs, reference)}", flush=True)
    write_summary(args.out / "bench_dynamics.json",
                     {"mu": MU, "belt_speed": BELT_SPEED, "b_n": B_N, "eps": args.eps,
                      "perturbation": PERTURBATION, "t_end": args.t_end, "sample_s": sample,
                      "default_dt": DEFAULT_DT, "total_time_s": total,
                      "central_stable_dt": {"elastic": central.stable_dt_elastic,
                                            "band": central.stable_dt_band},
                      "reference": reference, "runs": runs}, comm)


if __name__ == "__main__":
    main()
