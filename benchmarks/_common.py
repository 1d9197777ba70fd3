"""What the benchmark scripts share: the ``--out`` flag, saving a figure, the best of repeated
timings."""

from __future__ import annotations

import argparse
import pathlib
import time
import typing


def parser(doc: str | None) -> argparse.ArgumentParser:
    """An argument parser described by the first line of ``doc``, with ``--out``."""
    flags = argparse.ArgumentParser(description=(doc or "").splitlines()[0])
    flags.add_argument("--out", type=pathlib.Path, default=pathlib.Path("results/benchmarks"),
                       help="output folder (default: results/benchmarks)")
    return flags


def save(fig: typing.Any, path: pathlib.Path, dpi: int) -> None:
    """Lay out, write and close a matplotlib figure."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def best_time(call: typing.Callable[[], typing.Any], repeats: int) -> tuple[float, typing.Any]:
    """The shortest of ``repeats`` wall times of ``call()`` (noise only ever adds time), and
    the last call's value."""
    times, value = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        value = call()
        times.append(time.perf_counter() - t0)
    return min(times), value
