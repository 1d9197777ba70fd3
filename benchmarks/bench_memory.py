"""Memory of a long command-line run: the resident set size of ``fenicsfriction ARGS`` sampled
in time, against the steps it has done.

Runs the command as a child process (the package from ``--tree``, so that two versions can be
compared on the same command), reads its ``VmRSS`` and ``VmHWM`` (peak) from
``/proc/PID/status`` every ``--every`` seconds together with the number of steps done (the
``step`` column of the progress lines is not needed: the rows of ``timeseries.csv``, or with
``--record-every K`` K times them), and fits the growth of the RSS per step over the second
half of the samples. Writes ``bench_memory.json`` (samples, fit, peak) and
``bench_memory.png`` to ``--out``. The measured command (default: the finite element block of
Martins & Oden at the slow belt, the docs' 20 s run shortened by ``--t-end``)::

    python benchmarks/bench_memory.py --out DIR --t-end 1 [--tree /path/to/other/checkout]
        [-- extra CLI flags, e.g. --record-every 100]
"""

from __future__ import annotations

import json
import os
import pathlib
import subprocess
import sys
import time

import numpy as np
from _common import parser as benchmark_parser
from _common import save

#: the long run of benchmarks/long_run_block.py (Martins & Oden 1986, Figs. 13-15 data)
COMMAND = ["block", "dynamics", "--mu", "0.6", "--belt-speed", "0.08", "--b-n", "0.381e10",
           "--eps", "1e-3", "--dt", "1e-5", "--stride", "20000"]


def _status(pid: int) -> dict[str, float]:
    """VmRSS and VmHWM of ``pid`` in MB (empty once it has ended)."""
    values = {}
    try:
        for line in pathlib.Path(f"/proc/{pid}/status").read_text().splitlines():
            key, _, rest = line.partition(":")
            if key in ("VmRSS", "VmHWM"):
                values[key] = float(rest.split()[0]) / 1024.0
    except OSError:
        pass
    return values


def _rows(path: pathlib.Path) -> int:
    try:
        with open(path, "rb") as table:
            return max(sum(1 for _ in table) - 1, 0)
    except OSError:
        return 0


def main() -> None:
    flags = benchmark_parser(__doc__)
    flags.add_argument("--t-end", type=float, default=1.0, help="simulated time [s] (1)")
    flags.add_argument("--tree", type=pathlib.Path, default=pathlib.Path(__file__).parents[1],
                       help="the checkout whose package runs (default: this one)")
    flags.add_argument("--every", type=float, default=5.0, help="seconds between samples")
    flags.add_argument("--record-every", type=int, default=1,
                       help="passed to the command if > 1 (a tree without the flag: leave 1)")
    flags.add_argument("extra", nargs="*", help="more flags for the command (after --)")
    args = flags.parse_args()
    out: pathlib.Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    run_dir = out / "run"
    command = [*COMMAND, "--t-end", str(args.t_end), "--out", str(run_dir), *args.extra]
    if args.record_every > 1:
        command += ["--record-every", str(args.record_every)]
    env = {**{k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))},
           "PYTHONPATH": str(args.tree)}
    started = time.monotonic()
    child = subprocess.Popen([sys.executable, "-m", "fenicsfriction", *command], env=env,
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    samples = []
    while child.poll() is None:
        status = _status(child.pid)
        if status:
            samples.append({"wall_s": time.monotonic() - started,
                            "steps": _rows(run_dir / "timeseries.csv") * args.record_every,
                            "rss_mb": status.get("VmRSS"), "peak_mb": status.get("VmHWM")})
        time.sleep(args.every)
    stderr = child.stderr.read() if child.stderr else ""
    # the stepping's second half (the figures and statistics at the end are not growth)
    done = samples[-1]["steps"] if samples else 0
    late = [s for s in samples[len(samples) // 2:] if 0 < s["steps"] < done]
    slope = None
    if len(late) >= 2 and late[-1]["steps"] > late[0]["steps"]:
        fit = np.polyfit([s["steps"] for s in late], [s["rss_mb"] for s in late], 1)
        slope = float(fit[0]) * 1024.0  # KB per step
    steps_20s = 20.0 / 1e-5
    summary = {"command": ["fenicsfriction", *command], "tree": str(args.tree),
               "exit_code": child.returncode, "stderr_tail": stderr[-2000:],
               "wall_time_s": time.monotonic() - started, "samples": samples,
               "peak_rss_mb": max((s["peak_mb"] or 0.0 for s in samples), default=None),
               "growth_kb_per_step": slope,
               "rss_at_20s_extrapolated_mb": (None if slope is None else
                                              late[-1]["rss_mb"] + slope / 1024.0
                                              * (steps_20s - late[-1]["steps"])),
               "csv_mb": ((run_dir / "timeseries.csv").stat().st_size / 2**20
                          if (run_dir / "timeseries.csv").exists() else None)}
    (out / "bench_memory.json").write_text(json.dumps(summary, indent=1) + "\n")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot([s["steps"] for s in samples], [s["rss_mb"] for s in samples], "o-", ms=3)
    ax.set_xlabel("time steps done")
    ax.set_ylabel("resident set size [MB]")
    ax.set_title(f"{' '.join(command[:2])}, t_end = {args.t_end} s", fontsize=9)
    save(fig, out / "bench_memory.png", 120)
    print(json.dumps({k: summary[k] for k in ("exit_code", "wall_time_s", "peak_rss_mb",
                                               "growth_kb_per_step",
                                               "rss_at_20s_extrapolated_mb", "csv_mb")}))


if __name__ == "__main__":
    main()
