r"""Cost against accuracy of the reduced friction oscillators (the m.d.o.f. slider and the belt).

**Stability map** of the Table 2 slider of "Friction-induced sliding instability in a
multi-degree-of-freedom system with oscillatory normal forces" (2003) (paper reading) over
the forcing frequency: first-order averaging (closed-form averaged eigenvalues, Cases I-III)
against Floquet multipliers (monodromy matrix over one period by PETSc TS, Dormand–Prince,
rtol 1e-10). For each method: wall time per forcing frequency, and the unstable band edges
(bisected to 1e-4) against those of Floquet at rtol 1e-12 (the reference). The ratio
Floquet ÷ averaging per ω_o is the cost figure.

**Stick-slip integration** of the 1-d.o.f. oscillator on a belt whose limit cycle is known
in closed form (m = k = N = 1, c = 0, μ_s = 0.6, μ_k = 0.3, v_b = 0.5: period
(π + 2φ)/ω + 2Δ/v_b, amplitude 2R): the error of the cycle's amplitude and period after 4
cycles, against wall time, for event-located switching at rtol 1e-4 … 1e-10 and for the
regularised law at ε = 1e-2 … 1e-5 v_b (with rtol 1e-10: the error left is the law's). Which
gets a given amplitude accuracy faster?

Writes ``bench_oscillators.json`` and ``bench_oscillators.png`` to ``--out`` and prints
markdown tables. Serial (the systems have 2 to 6 unknowns).
"""

from __future__ import annotations

import pathlib
import time

import numpy as np
from _common import parser as benchmark_parser
from _common import save, write_summary

from fenicsfriction import laws
from fenicsfriction.statistics import limit_cycle
from fenicsfriction.studies.oscillators import BeltOscillator
from fenicsfriction.studies.oscillators.slider import stability_map, table2_slider

BANDS = [(29.0, 34.0), (60.0, 67.0)]
SAMPLES = 41
EVENT_RTOL = [1e-4, 1e-6, 1e-8, 1e-10]
REGULARISED_EPS = [1e-2, 1e-3, 1e-4, 1e-5]   # × v_b
T_END = 30.0                                   # ≈ 4.7 cycles of period 6.40


def _stability(out: dict) -> None:
    rows = []
    for lo, hi in BANDS:
        omegas = np.linspace(lo, hi, SAMPLES)
        tight = stability_map(lambda w: _TightFloquet(table2_slider(w)), omegas,
                              methods=("floquet",))
        fast = stability_map(table2_slider, omegas, methods=("averaging", "floquet"))
        for method in ("averaging", "floquet"):
            edges = np.ravel(fast.bands[method])
            exact = np.ravel(tight.bands["floquet"])
            rows.append({"range": [lo, hi], "method": method,
                         "ms_per_omega": 1e3 * fast.seconds[method] / SAMPLES,
                         "bands": fast.bands[method], "reference_bands": tight.bands["floquet"],
                         "max_edge_error": float(np.max(np.abs(edges - exact)))
                         if edges.shape == exact.shape else None})
    out["stability"] = rows


class _TightFloquet:
    """The same slider whose Floquet analysis runs at rtol 1e-12 (the reference)."""

    def __init__(self, slider):
        self.slider = slider

    def floquet(self):
        return self.slider.floquet(rtol=1e-12, atol=1e-14)


def _belt(out: dict) -> None:
    oscillator = BeltOscillator(m=1.0, k=1.0, c=0.0, N=1.0, v_belt=0.5,
                                law=laws.ConstantFriction(0.3), mu_static=0.6)
    exact = oscillator.classic_limit_cycle()
    runs = []
    cases = [("events", rtol, None) for rtol in EVENT_RTOL] + \
        [("regularised", 1e-10, eps * 0.5) for eps in REGULARISED_EPS]
    for method, rtol, eps in cases:
        best = np.inf
        for _ in range(3):      # best of 3: noise only ever adds time
            start = time.perf_counter()
            result = oscillator.simulate(T_END, x0=0.0, v0=0.5, method=method, eps=eps,
                                         rtol=rtol, atol=1e-2 * rtol)
            best = min(best, time.perf_counter() - start)
        cycle = limit_cycle(result)
        runs.append({"method": method, "rtol": rtol, "eps": eps, "seconds": best,
                     "steps": result.hybrid.steps, "events": len(result.events),
                     "amplitude_error": abs(cycle.amplitude / exact.amplitude - 1),
                     "period_error": abs(cycle.period / exact.period - 1)})
    out["belt"] = {"exact": {"period": exact.period, "amplitude": exact.amplitude},
                   "runs": runs}


def _plot(out: dict, path: pathlib.Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for method, marker in (("events", "o-"), ("regularised", "s--")):
        runs = [r for r in out["belt"]["runs"] if r["method"] == method]
        axes[0].loglog([r["seconds"] for r in runs], [r["amplitude_error"] for r in runs],
                       marker, label=method)
    axes[0].set(xlabel="wall time [s]", ylabel="relative error of the cycle amplitude",
                title="belt oscillator: stick-slip cycle")
    axes[0].legend()
    rows = out["stability"]
    labels = [f"{r['method']}\n{r['range'][0]:g}-{r['range'][1]:g}" for r in rows]
    axes[1].bar(labels, [r["ms_per_omega"] for r in rows], color=["tab:blue", "tab:orange"] * 2)
    axes[1].set(yscale="log", ylabel="ms per forcing frequency", title="stability map cost")
    save(fig, path, dpi=110)


def main() -> None:
    parser = benchmark_parser(__doc__)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    out: dict = {}
    _stability(out)
    _belt(out)
    write_summary(args.out / "bench_oscillators.json", out)
    _plot(out, args.out / "bench_oscillators.png")
    print("| range | method | ms per ω_o | unstable bands | max edge error |")
    print("|---|---|---|---|---|")
    for r in out["stability"]:
        bands = ", ".join(f"{a:.3f}-{b:.3f}" for a, b in r["bands"])
        err = ("n/a" if r["max_edge_error"] is None else "< 1e-4 (bisection)"
               if r["max_edge_error"] < 1e-4 else f"{r['max_edge_error']:.1e}")
        print(f"| {r['range'][0]:g}-{r['range'][1]:g} | {r['method']} | "
              f"{r['ms_per_omega']:.2f} | {bands} | {err} |")
    print()
    fastest = min(r["seconds"] for r in out["belt"]["runs"])
    print(f"fastest belt run: {fastest * 1e3:.1f} ms")
    print("| belt run | wall ÷ fastest | steps | amplitude error | period error |")
    print("|---|---|---|---|---|")
    for r in out["belt"]["runs"]:
        name = (f"events rtol {r['rtol']:.0e}" if r["method"] == "events"
                else f"regularised ε {r['eps'] / 0.5:.0e} v_b")
        print(f"| {name} | {r['seconds'] / fastest:.2f} | {r['steps']} | "
              f"{r['amplitude_error']:.1e} | {r['period_error']:.1e} |")


if __name__ == "__main__":
    main()
