r"""Martins & Oden (1986) case (b): where does the block on the belt end in a stick?

Martins & Oden describe two outcomes of the flutter-driven oscillation of the block on a moving
belt: (a) above a critical belt speed the oscillation persists with brief adhesions; (b) below
it "the normal (and rotational) damping is able to damp out the normal (and rotational)
oscillation and the body sticks", until the spring tears it loose (their Figs. 12 and 13).
With the finite element data of their Fig. 13 read as the package reads them (K_x = 11.1
10³ kg s⁻², the caption's "K = 11100 Kg s⁻²") neither the FE nor the rigid block sticks in 20 s
(``long_run_block.py``). This study maps where the stick exists.

**Event criterion.** A run sticks (case (b)) when the whole base reaches the belt speed and
stays there: the rigid base within ε of the belt speed (|w| < ε, in contact), every FE base
node in contact and within ε (``n_stick`` = all), without interruption for longer than
``--stick-min`` (default 10 ms, eight periods of the normal oscillation, 1.2 ms), with the
normal oscillation decayed during it (|v_yG| at its end below 1 % of its largest value in
the run). Brief adhesions inside a cycle (case (a)) last a fraction of a period.

**Why the spring matters** (the 1-d.o.f. mechanism, tested in ``tests/test_rigid_block.py``
on the rigid block with a static and a kinetic coefficient): once the flutter oscillation
saturates, the mean friction force drops from μW to an apparent μ_a W; the spring, stretched to
μW/K_x, then drives a tangential oscillation about the new equilibrium, of velocity amplitude
up to (μ - μ_a) W / sqrt(K_x M) (less where μ_a grows with the slip speed and damps it). Where
the block reaches the belt speed it sticks with the static capacity μN, the normal damping
kills the normal oscillation, and the spring must load up again before it tears the block
loose: case (b). The soft spring's (K_x = 11.1) amplitude would be large, but its period is
1.26 s and the slow drift of the mean never reaches the belt; the stiffer readings of the
caption oscillate within tens of milliseconds. This is a mechanism, not a sharp criterion:
the map below is what decides.

Runs (``--no-map``, ``--rigid-points`` and ``--fe-points`` select them):

* the rigid block (:class:`~fenicsfriction.studies.block.RigidBlock`) on the (K_x, U) plane
  with the FE data of Fig. 13 (μ = 0.6, b_n = 0.381e10, l_n = 2.5, B0 = 30.5 cm), including
  the readings of the caption's spring: 11.1 (as written, kg), 338.6 (per cm of breadth, times
  B0) and 11100 (10³ kg, the unit of the rigid model's K_x = 2388 and 4441 in Figs. 10-11);
  then variations of ε and b_n at chosen points;
* the FE block (:class:`~fenicsfriction.BlockOnBelt`, the paper's 4 × 3 Q2 mesh) at the
  decisive points (``--fe-points``), short windows.

Writes ``case_b.json`` and ``case_b.png`` (the stick map and the elongation traces) to --out.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import multiprocessing
import pathlib
import time
import typing

from mpi4py import MPI

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

import fenicsfriction as ff
from fenicsfriction.studies.block import RigidBlock
from fenicsfriction.timestepping import ReducedDynamics

MU, B_N, PERTURBATION, DT = 0.6, 0.381e10, -0.01, 1e-5  # Fig. 13's data; [cm/s]; [s]
#: the readings of Fig. 13's "K = 11100 Kg s⁻²" in 10³ kg s⁻²: as written, per cm of breadth,
#: in the 10³ kg of the rigid model's figures; and the rigid model's own K_x of Figs. 10-11
K_READINGS = {"as written (kg)": 11.1, "per cm of breadth": 11.1 * 30.5,
              "10^3 kg": 11100.0}
K_GRID = (11.1, 338.55, 1110.0, 2388.0, 4441.0, 11100.0)
U_GRID = (0.02, 0.04, 0.08, 0.16, 0.287)


@dataclasses.dataclass
class Point:
    """One run: spring, belt speed, ε, normal damping, μ and the simulated time."""

    K_x: float
    belt_speed: float
    eps: float = 1e-2
    b_n: float = B_N
    mu: float = MU
    t_end: float = 0.3
    dt: float = DT
    #: the FE mesh's refinement (4·refine × 3·refine Q2 cells; the paper's is 1)
    refine: int = 1


def spring_period(K_x: float, mass: float = 0.45) -> float:
    return 2 * math.pi * math.sqrt(mass / K_x)


def episodes(flags: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of each run of consecutive flagged samples."""
    padded = np.concatenate([[False], flags, [False]]).astype(int)
    starts = np.nonzero(np.diff(padded) == 1)[0]
    ends = np.nonzero(np.diff(padded) == -1)[0] - 1
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


def events(t: np.ndarray, stick: np.ndarray, v_y: np.ndarray, elongation: np.ndarray,
           friction: np.ndarray, normal: np.ndarray, stick_min: float) -> dict[str, typing.Any]:
    """The stick events of a run and its verdict (see the module's criterion)."""
    runs = episodes(stick)
    length = [float(t[b] - t[a]) for a, b in runs]
    peak_vy = float(np.max(np.abs(v_y))) or 1.0
    long = [(a, b) for (a, b), d in zip(runs, length, strict=True) if d > stick_min]
    decayed = [(a, b) for a, b in long if abs(v_y[b]) < 0.01 * peak_vy]
    half = t >= t[-1] / 2
    result: dict[str, typing.Any] = {
        "reached": float(t[-1]), "stick_events": len(runs),
        "stick_share": float(np.mean(stick)),
        "longest_stick": max(length, default=0.0),
        "long_sticks": len(long), "sticks": bool(decayed),
        "apparent_coefficient_second_half": float(np.sum(friction[half]) / np.sum(normal[half])),
        "normal_force_range_second_half": [float(normal[half].min()), float(normal[half].max())],
        "elongation": [float(elongation[0]), float(elongation.min()), float(elongation[-1])]}
    if decayed:
        a, b = decayed[0]
        result["first_stick"] = [float(t[a]), float(t[b])]
        result["first_stick_elongation"] = float(elongation[a])
    return result


def run_rigid(point: Point, stick_min: float) -> dict[str, typing.Any]:
    """The rigid block of Fig. 13's data at ``point``: its events (and a thinned trace)."""
    scene = ff.BlockOnBelt(belt_speed=point.belt_speed, K_x=point.K_x, refine=point.refine,
                           law=ff.InterfaceLaw(mu=point.mu, b_n=point.b_n, eps=point.eps))
    block = RigidBlock.from_scene(scene)
    solver = ReducedDynamics(model=block, q0=block.steady_state(),
                             q_dot0=[0.0, PERTURBATION, 0.0], prefix="caseb_rigid_")
    columns: dict[str, list[float]] = {k: [] for k in ("t", "w", "stick", "v_y", "e", "F", "N")}
    arm, h2 = block.spring_height - block.H / 2, block.H / 2

    def observe(t: float) -> dict:
        q, q_dot = solver.q, solver.q_dot
        w = q_dot[0] + q_dot[2] * h2 - point.belt_speed
        touching = block._contact_interval(q) is not None
        Q = block.generalised_forces(q, q_dot)
        spring = block._spring(q)
        for key, value in (("t", t), ("w", w), ("stick", touching and abs(w) < point.eps),
                           ("v_y", q_dot[1]), ("e", q[0] - q[2] * arm),
                           ("F", Q[0] - spring), ("N", Q[1] + block.weight)):
            columns[key].append(float(value))
        return {}

    t0 = time.perf_counter()
    observe(0.0)
    solver.run(t_end=point.t_end, dt=point.dt, observe=observe)
    c = {k: np.array(v) for k, v in columns.items()}
    result = {**dataclasses.asdict(point), "model": "rigid", "wall_time_s":
              time.perf_counter() - t0, "steps": len(c["t"]) - 1,
              "steady_elongation": float(point.mu * block.weight / point.K_x),
              **events(c["t"], c["stick"].astype(bool), c["v_y"], c["e"], c["F"], c["N"],
                       stick_min)}
    every = max(1, len(c["t"]) // 2000)
    result["trace"] = {"t": c["t"][::every].tolist(), "elongation": c["e"][::every].tolist()}
    return result


def run_fe(point: Point, stick_min: float, comm: MPI.Comm) -> dict[str, typing.Any]:
    """The FE block (4·refine × 3·refine Q2, Fig. 13's data) at ``point``: its events and a
    thinned trace."""
    from fenicsfriction.dynamics import DynamicsSolver

    scene = ff.BlockOnBelt(belt_speed=point.belt_speed, K_x=point.K_x, refine=point.refine,
                           law=ff.InterfaceLaw(mu=point.mu, b_n=point.b_n, eps=point.eps))
    tag = f"caseb_fe_{point.K_x:g}_{point.belt_speed:g}_{point.refine}".replace(".", "p")
    model = scene.build(comm=comm)
    model.initial_guess()
    steady = ff.SteadySolver(model.residual, prefix=f"{tag}_steady_",
                             options=model.solver_options())
    model.slide_to(mu=point.mu, solver=steady, step=0.05)
    model.perturb_normal_velocity(PERTURBATION)
    solver = DynamicsSolver(model.residual, prefix=f"{tag}_ts_", atol=1e-10 * model.force_scale)
    columns: dict[str, list[float]] = {k: [] for k in ("t", "stick", "v_y", "e", "F", "N")}

    def on_step(r: dict) -> None:  # keep only what the events need
        for key, name in (("t", "time"), ("v_y", "v_yG"), ("e", "spring_elongation"),
                          ("F", "friction_force"), ("N", "normal_force")):
            columns[key].append(float(r[name]))
        columns["stick"].append(float(r["n_slip"] == 0 and r["n_open"] == 0
                                      and r["n_stick"] > 0))

    t0 = time.perf_counter()
    solver.run(t_end=point.t_end, dt=point.dt, observe=model.dynamics_observer(),
               on_step=on_step)
    c = {k: np.array(v) for k, v in columns.items()}
    result = {**dataclasses.asdict(point), "model": "fe", "wall_time_s":
              time.perf_counter() - t0, "steps": len(c["t"]) - 1,
              "steady_elongation": float(point.mu * scene.weight / point.K_x),
              **events(c["t"], c["stick"].astype(bool), c["v_y"], c["e"], c["F"], c["N"],
                       stick_min)}
    every = max(1, len(c["t"]) // 2000)
    result["trace"] = {"t": c["t"][::every].tolist(), "elongation": c["e"][::every].tolist()}
    return result


def _rigid_job(args: tuple[Point, float]) -> dict[str, typing.Any]:
    return run_rigid(*args)


def plot(rigid: list[dict], fe: list[dict], path: pathlib.Path) -> None:
    """Stick map of the rigid block on the (K_x, U) plane, and elongation traces."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.5))
    plane = [r for r in rigid if r["eps"] == 1e-2 and r["b_n"] == B_N and r["mu"] == MU]
    for r in plane:
        ax.scatter(r["K_x"], r["belt_speed"], marker="o" if r["sticks"] else "x",
                   color="C3" if r["sticks"] else "C0", s=60)
    for name, K in K_READINGS.items():
        ax.axvline(K, color="0.7", lw=0.8)
        ax.text(K, 0.98, name, rotation=90, fontsize=7, va="top",
                transform=ax.get_xaxis_transform())
    ax.set(xscale="log", xlabel="K_x [10³ kg s⁻²]", ylabel="belt speed U [cm/s]",
           title="rigid block, Fig. 13 data: o stick (case b), x no stick")
    for r in [*plane, *fe]:
        if r["belt_speed"] in (0.08, 0.287) and r["K_x"] in (2388.0, 4441.0, 11100.0):
            bx.plot(r["trace"]["t"], np.array(r["trace"]["elongation"])
                    / r["steady_elongation"], lw=0.8, ls="-" if r["model"] == "rigid" else "--",
                    label=f"{r['model']} K={r['K_x']:g} U={r['belt_speed']:g}")
    bx.set(xlabel="t [s]", ylabel="elongation / (μW/K_x)", title="spring elongation")
    bx.legend(fontsize=6)
    save(fig, path, dpi=120)


HEADER = ("| model | K_x | U | ε | b_n | μ | dt | t_end | sticks | first stick [s] | "
          "longest stick [ms] | stick share | F/N (2nd half) | N range (2nd half) | "
          "elongation / (μW/K_x): start, min, end | wall [s] |\n" + "|---" * 16 + "|")


def row(r: dict[str, typing.Any]) -> str:
    """One line of the table of runs."""
    first = r.get("first_stick", [None])[0]
    e = np.array(r["elongation"]) / r["steady_elongation"]
    model = r["model"] if r.get("refine", 1) == 1 else f"{r['model']} (mesh ×{r['refine']})"
    return (f"| {model} | {r['K_x']:g} | {r['belt_speed']:g} | {r['eps']:g} | "
            f"{r['b_n']:g} | {r['mu']:g} | {r['dt']:g} | {r['reached']:.3g} | "
            f"{'yes' if r['sticks'] else 'no'} | {'-' if first is None else f'{first:.4f}'} | "
            f"{r['longest_stick'] * 1e3:.1f} | {r['stick_share']:.1%} | "
            f"{r['apparent_coefficient_second_half']:.4f} | "
            f"{r['normal_force_range_second_half'][0]:.0f} – "
            f"{r['normal_force_range_second_half'][1]:.0f} | "
            f"{e[0]:.4f}, {e[1]:.4f}, {e[2]:.4f} | {r['wall_time_s']:.0f} |")


def keep(r: dict[str, typing.Any], out: pathlib.Path) -> None:
    """Append a finished run to ``case_b_runs.jsonl`` (what a stopped study has done)."""
    if MPI.COMM_WORLD.rank == 0:
        with open(out / "case_b_runs.jsonl", "a") as f:
            f.write(json.dumps(r) + "\n")


def parse_points(text: str, dt: float, t_end: float) -> list[Point]:
    """'K:U[:ε[:b_n[:μ[:t_end]]]]' separated by commas (ValueError if malformed)."""
    points = []
    for item in filter(None, text.split(",")):
        values = [float(x) for x in item.split(":")]
        if not 2 <= len(values) <= 6 or not all(np.isfinite(values)):
            raise ValueError(item)
        defaults = [None, None, 1e-2, B_N, MU, t_end]
        K, U, eps, b_n, mu, t = values + defaults[len(values):]
        points.append(Point(K, U, eps=eps, b_n=b_n, mu=mu, t_end=t, dt=dt))
    return points


def main(argv: list[str] | None = None) -> None:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--map", action=argparse.BooleanOptionalAction, default=True,
                       help="run the rigid map on (K_x, U) and its variations (default yes)")
    flags.add_argument("--rigid-points", default="",
                       help="more rigid runs, 'K:U[:eps[:b_n[:mu[:t_end]]]]' separated by commas")
    flags.add_argument("--fe-points", default="",
                       help="FE runs, 'K:U[:eps[:b_n[:mu[:t_end]]]]' separated by commas")
    flags.add_argument("--t-end", type=float, default=0.3,
                       help="run length [s] (0.3; the map runs 3 spring periods, up to 1 s)")
    flags.add_argument("--dt", type=float, default=DT, help="time step [s] (1e-5)")
    flags.add_argument("--stick-min", type=float, default=0.01,
                       help="shortest whole-base stick that counts as case (b) [s] (0.01)")
    flags.add_argument("--jobs", type=int, default=2, help="rigid runs in parallel (2)")
    flags.add_argument("--fe-refine", type=int, default=1,
                       help="the FE points' mesh refinement: 4·r × 3·r Q2 cells (1, the paper's)")
    args = flags.parse_args(argv)
    for name in ("t_end", "stick_min", "dt"):
        if not getattr(args, name) > 0:
            flags.error(f"--{name.replace('_', '-')}={getattr(args, name)} must be > 0")
    if args.jobs < 1:
        flags.error(f"--jobs={args.jobs} must be >= 1")
    if args.fe_refine < 1:
        flags.error(f"--fe-refine={args.fe_refine} must be >= 1")
    lists = {}
    for name in ("rigid_points", "fe_points"):
        try:
            lists[name] = parse_points(getattr(args, name), args.dt, args.t_end)
        except ValueError as err:
            flags.error(f"--{name.replace('_', '-')}: {err} is not 'K:U[:eps[:b_n[:mu[:t_end]]]]'"
                        " with 2 to 6 finite numbers")
    args.out.mkdir(parents=True, exist_ok=True)
    points: list[Point] = []
    if args.map:
        points = [Point(K, U, dt=args.dt,
                        t_end=max(args.t_end, min(3 * spring_period(K), 1.0)))
                  for K in sorted(K_GRID, reverse=True) for U in U_GRID]
        points += [Point(K, 0.08, eps=1e-3, dt=args.dt) for K in (4441.0, 11100.0)]
        points += [Point(K, 0.08, b_n=b, dt=args.dt) for K in (4441.0, 11100.0)
                   for b in (0.0, 4 * B_N)]
    points += lists["rigid_points"]
    print(HEADER, flush=True)
    t0 = time.perf_counter()
    rigid = []
    with multiprocessing.get_context("fork").Pool(args.jobs) as pool:
        for r in pool.imap_unordered(_rigid_job, [(p, args.stick_min) for p in points]):
            rigid.append(r)
            print(row(r), flush=True)
            keep(r, args.out)
    rigid_wall = time.perf_counter() - t0
    fe = []
    for p in lists["fe_points"]:
        fe.append(run_fe(dataclasses.replace(p, refine=args.fe_refine), args.stick_min,
                         MPI.COMM_WORLD))
        print(row(fe[-1]), flush=True)
        keep(fe[-1], args.out)
    summary = {"stick_min": args.stick_min, "K_readings": K_READINGS,
               "rigid_wall_time_s": rigid_wall, "rigid": rigid, "fe": fe}
    if MPI.COMM_WORLD.rank == 0:
        plot(rigid, fe, args.out / "case_b.png")
    write_summary(args.out / "case_b.json", json.loads(json.dumps(summary)), MPI.COMM_WORLD)


if __name__ == "__main__":
    main()
