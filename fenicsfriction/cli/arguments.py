"""What the families' parsers share: one-line errors, and flag types that parse without
importing anything heavy.

``fenicsfriction --help`` and a mistyped flag need nothing but argparse, so they answer at
once: each family's module (:mod:`~fenicsfriction.cli.block`, ...) defines its flags in
``add_parser`` beside its ``run_*`` functions and imports MPI, PETSc and dolfinx inside them,
once the flags are known.
"""

from __future__ import annotations

import argparse
import importlib
import typing

__all__ = ["LazyChoices", "Parser", "creep_range", "floats", "omega_range"]


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors (no usage block) and exit status 2."""

    def error(self, message: str) -> typing.NoReturn:
        self.exit(2, f"{self.prog}: error: {message}\n")


def floats(text: str) -> list[float]:
    """``"1e-2,1e-3"`` -> ``[0.01, 0.001]``."""
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated numbers, got {text!r}") from None


def omega_range(text: str) -> tuple[float, float]:
    """``"30:31"`` -> ``(30.0, 31.0)``."""
    try:
        lo, hi = (float(v) for v in text.split(":"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected LO:HI, got {text!r}") from None
    return lo, hi


class LazyChoices:
    """The ``choices`` of a flag, read from ``module.name`` (a dict or collection) when argparse
    first checks a value or prints the sub-command's help, so that listing them costs no import.
    """

    def __init__(self, module: str, name: str):
        self.module, self.name = module, name

    def _values(self) -> list[str]:
        return sorted(getattr(importlib.import_module(self.module), self.name))

    def __contains__(self, value: object) -> bool:
        return value in self._values()

    def __iter__(self) -> typing.Iterator[str]:
        return iter(self._values())


def creep_range(text: str) -> list[float]:
    """``"0:3e-3:31"`` -> 31 creepages from 0 to 3e-3 (both ends included)."""
    try:
        lo, hi, count = text.split(":")
        n = int(count)
        values = [float(lo) + (float(hi) - float(lo)) * i / max(n - 1, 1) for i in range(n)]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected LO:HI:N, got {text!r}") from None
    if n < 1:
        raise argparse.ArgumentTypeError(f"expected N >= 1 points in LO:HI:N, got {text!r}")
    return values
