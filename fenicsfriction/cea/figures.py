"""The mode-coupling map of a sweep (matplotlib, Agg, drawn on rank 0): frequency and growth rate
of every tracked mode against the parameter, the coalescences marked."""

from __future__ import annotations

import typing

import numpy as np

from fenicsfriction.cea.sweep import Coalescence
from fenicsfriction.plotting import PathLike, saved_figure

__all__ = ["plot_coupling_map"]


def plot_coupling_map(records: list[dict], path: PathLike,
                      events: typing.Sequence[Coalescence] = (),
                      param_name: str = "p") -> None:
    """Frequency [Hz] (left) and Re λ [1/s] (right) of each tracked mode against the parameter.

    Args:
        records: :attr:`Sweep.records <fenicsfriction.cea.sweep.Sweep.records>`.
        path: the PNG written.
        events: coalescences, marked at their ``p_crit`` (dashed) and frequency.
        param_name: the parameter's name on the axes.
    """
    curves: dict[int, list[tuple[float, float, float]]] = {}
    for record in records:
        for m in record["modes"]:
            curves.setdefault(m["mode"], []).append((record["p"], m["frequency"], m["re"]))
    with saved_figure(path, ncols=2, figsize=(10.0, 4.2)) as (freq, growth):
        for ident, points in sorted(curves.items()):
            p, f, re = np.array(points).T
            line, = freq.plot(p, f, ".-", ms=3, lw=1)
            growth.plot(p, re, ".-", ms=3, lw=1, color=line.get_color(), label=f"mode {ident}")
        for event in events:
            for ax in (freq, growth):
                ax.axvline(event.p_crit, color="k", ls="--", lw=0.8)
            freq.plot([event.p_crit], [event.frequency], "ko", mfc="none")
        growth.axhline(0.0, color="0.5", lw=0.8)
        freq.set(xlabel=param_name, ylabel="frequency Im λ/2π [Hz]", title="mode coupling")
        growth.set(xlabel=param_name, ylabel="growth rate Re λ [1/s]",
                   title="unstable where Re λ > 0")
        if len(curves) <= 12:
            growth.legend(fontsize=7)
