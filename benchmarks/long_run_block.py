r"""The long run of the block at the slow belt: does it end in a stick, and when?

Martins & Oden (1986) describe two outcomes of the flutter-driven oscillation of the block on a
belt: (a) above a critical belt speed the oscillation persists with brief adhesions; (b) below
it, "at a sufficiently small value of the spring elongation, the normal (and rotational)
damping is able to damp out the normal (and rotational) oscillation and the body sticks". With
the finite element data of their Figs. 13-15 (μ = 0.6, K_x = 11.1, b_n = 0.381e10, l_n = 2.5)
the soft spring's period is 1.26 s, so the outcome at 0.08 cm/s needs seconds of simulated time.

This script reads the time series of the finite element run (the CLI's ``timeseries.csv``)::

    fenicsfriction dynamics block --mu 0.6 --belt-speed 0.08 --b-n 0.381e10 --eps 1e-3 \
        --t-end 20 --dt 1e-5 --stride 20000 --out DIR

integrates the rigid block (:class:`~fenicsfriction.studies.block.RigidBlock`, same data, same ε,
same integrator and step; 32 min for 20 s on 2 shared cores) unless ``--rigid-csv`` gives
its time series from an earlier run, and prints, for both, per window of ``--window``
seconds: the apparent coefficient F̄/N̄, the range of N, the spring elongation, the share of
the time some base point sticks and the whole base sticks, and the longest whole-base stick;
then the verdict.

**The block sticks** when the whole base sticks — every base node of the finite element block
in contact and within ε of the belt speed (``n_stick`` = all contact nodes, ``n_open`` = 0),
the rigid block's base within ε — without interruption for longer than ``--stick-min``
(default 50 ms, about 40 periods of the normal oscillation, 1.2 ms): the normal oscillation has
died out and the spring has not yet torn the block loose (case (b)). Brief adhesions inside an
oscillation cycle (case (a)) last a fraction of a period.

Writes ``long_run_block.json`` to ``--out``.
"""

from __future__ import annotations

import csv
import pathlib
import time

from mpi4py import MPI

import numpy as np
from _common import parser as benchmark_parser
from _common import write_summary
from scipy.integrate import trapezoid

import fenicsfriction as ff
from fenicsfriction.results import CsvRows
from fenicsfriction.studies.block import RigidBlock, rigid_block_observables
from fenicsfriction.timestepping import ReducedDynamics

MU, BELT_SPEED, B_N = 0.6, 0.08, 0.381e10
PERTURBATION = -0.01  # [cm/s]
DT = 1e-5  # [s]
COLUMNS = ("time", "normal_force", "friction_force", "spring_elongation")


def read(path: pathlib.Path) -> dict[str, np.ndarray]:
    """The columns needed from a time series; ``whole`` flags a whole-base stick per row."""
    with open(path, newline="") as f:
        rows = csv.reader(f)
        header = next(rows)
        index = {name: header.index(name) for name in header}
        fe = "n_stick" in index
        wanted = COLUMNS + (("n_stick", "n_slip", "n_open") if fe else ("contact",))
        data: dict[str, list] = {name: [] for name in wanted}
        for row in rows:
            if len(row) < len(header):  # a row being written when the file was read
                break
            for name in wanted:
                data[name].append(row[index[name]])
    series = {name: np.array(data[name], dtype=float) for name in COLUMNS}
    if fe:
        stick, slip, closed = (np.array(data[n], dtype=int) for n in ("n_stick", "n_slip",
                                                                         "n_open"))
        series["some"] = stick > 0
        series["whole"] = (stick > 0) & (slip == 0) & (closed == 0)
    else:
        contact = np.array(data["contact"])
        series["some"] = series["whole"] = contact == "stick"
    return series


def episodes(t: np.ndarray, flags: np.ndarray) -> list[tuple[float, float]]:
    """(start, end) of each run of consecutive flagged samples."""
    padded = np.concatenate([[False], flags, [False]]).astype(int)
    starts = np.nonzero(np.diff(padded) == 1)[0]
    ends = np.nonzero(np.diff(padded) == -1)[0] - 1
    return [(float(t[a]), float(t[b])) for a, b in zip(starts, ends, strict=True)]


def share(t: np.ndarray, flags: np.ndarray) -> float:
    """Share of the time over which ``flags`` holds (trapezoidal in time)."""
    return float(trapezoid(flags.astype(float), t) / (t[-1] - t[0]))


def windows(s: dict[str, np.ndarray], width: float) -> list[dict]:
    """The statistics of each window [k width, (k+1) width)."""
    t = s["time"]
    rows = []
    for start in np.arange(0.0, t[-1], width):
        w = (t >= start) & (t <= start + width)
        if w.sum() < 3:
            continue
        tw = t[w]
        stuck = episodes(tw, s["whole"][w])
        rows.append({
            "t": [float(tw[0]), float(tw[-1])],
            "apparent_coefficient": float(trapezoid(s["friction_force"][w], tw)
                                          / trapezoid(s["normal_force"][w], tw)),
            "normal_force_range": [float(s["normal_force"][w].min()),
                                   float(s["normal_force"][w].max())],
            "elongation": [float(s["spring_elongation"][w][0]),
                           float(s["spring_elongation"][w][-1])],
            "some_stick": share(tw, s["some"][w]), "whole_stick": share(tw, s["whole"][w]),
            "longest_whole_stick": max((b - a for a, b in stuck), default=0.0)})
    return rows


def verdict(s: dict[str, np.ndarray], weight: float, stick_min: float) -> dict:
    """The first whole-base stick longer than ``stick_min``, if any, and the longest."""
    stuck = episodes(s["time"], s["whole"])
    longest = max(stuck, key=lambda e: e[1] - e[0], default=(0.0, 0.0))
    long = [e for e in stuck if e[1] - e[0] > stick_min]
    result = {"reached": float(s["time"][-1]), "sticks": bool(long),
              "longest_whole_stick": [longest[0], longest[1]],
              "long_sticks": len(long), "first_long_stick": list(long[0]) if long else None}
    if long:
        a, b = long[0]
        inside = (s["time"] >= a) & (s["time"] <= b)
        n = s["normal_force"][inside]
        result["first_long_stick_normal_force"] = [float(n.min()), float(n.max())]
        result["first_long_stick_weight"] = weight
        result["first_long_stick_elongation"] = float(s["spring_elongation"][inside][0])
    return result


def run_rigid(eps: float, t_end: float, out: pathlib.Path) -> pathlib.Path:
    """The rigid block of the same data to ``t_end``; its time series, written as it goes."""
    scene = ff.BlockOnBelt(belt_speed=BELT_SPEED, law=ff.InterfaceLaw(mu=MU, b_n=B_N, eps=eps))
    block = RigidBlock.from_scene(scene)
    solver = ReducedDynamics(model=block, q0=block.steady_state(),
                             q_dot0=[0.0, PERTURBATION, 0.0], prefix="long_rigid_ts_")
    path = out / "timeseries_rigid.csv"
    with CsvRows(path=path, comm=MPI.COMM_SELF) as table:
        solver.run(t_end=t_end, dt=DT, on_step=table.write, observe=lambda t:
                   rigid_block_observables(block, solver.q, solver.q_dot))
    return path


def main(argv=None) -> None:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--fe-csv", type=pathlib.Path, required=True,
                       help="timeseries.csv of the finite element run")
    flags.add_argument("--rigid-csv", type=pathlib.Path,
                       help="time series of an earlier rigid run (default: run it)")
    flags.add_argument("--eps", type=float, default=1e-3, help="ε of both runs [cm/s]")
    flags.add_argument("--window", type=float, default=1.0, help="window width [s]")
    flags.add_argument("--stick-min", type=float, default=0.05,
                       help="shortest whole-base stick that counts as the block sticking [s]")
    args = flags.parse_args(argv)
    for name in ("eps", "window", "stick_min"):
        if not getattr(args, name) > 0:
            flags.error(f"--{name.replace('_', '-')}={getattr(args, name)} must be > 0")
    args.out.mkdir(parents=True, exist_ok=True)
    fe = read(args.fe_csv)
    t0 = time.perf_counter()
    rigid_csv = args.rigid_csv or run_rigid(args.eps, float(fe["time"][-1]), args.out)
    rigid_wall = time.perf_counter() - t0
    rigid = read(rigid_csv)
    weight = ff.BlockOnBelt().weight
    summary = {"eps": args.eps, "stick_min": args.stick_min, "rigid_wall_time_s": rigid_wall}
    for name, s in (("fe", fe), ("rigid", rigid)):
        summary[name] = {"windows": windows(s, args.window),
                         "verdict": verdict(s, weight, args.stick_min)}
        print(f"\n{name}: reached t = {s['time'][-1]:.4f} s; {summary[name]['verdict']}")
        print("| window [s] | F/N | N range | elongation [cm] | some point sticks | "
              "whole base sticks | longest whole-base stick [ms] |\n|---|---|---|---|---|---|---|")
        for w in summary[name]["windows"]:
            print(f"| {w['t'][0]:.2f} – {w['t'][1]:.2f} | {w['apparent_coefficient']:.4f} | "
                  f"{w['normal_force_range'][0]:.0f} – {w['normal_force_range'][1]:.0f} | "
                  f"{w['elongation'][0]:.4f} → {w['elongation'][1]:.4f} | "
                  f"{w['some_stick']:.1%} | {w['whole_stick']:.1%} | "
                  f"{w['longest_whole_stick'] * 1e3:.1f} |")
    write_summary(args.out / "long_run_block.json", summary, MPI.COMM_SELF)


if __name__ == "__main__":
    main()
