"""Names of a package loaded on first use (PEP 562), so that importing a package costs only
what is used: ``import fenicsfriction.studies.oscillators`` does not import SciPy's integrators
or MPI until a model needs them, and the command line's ``--help`` imports no solver at all.
"""

from __future__ import annotations

import importlib
import sys
import typing

__all__ = ["attach"]


def attach(package: str, exports: dict[str, str], submodules: typing.Sequence[str] = ()
           ) -> tuple[typing.Callable[[str], typing.Any], typing.Callable[[], list[str]],
                      list[str]]:
    """``(__getattr__, __dir__, __all__)`` for ``package``.

    Args:
        package: the package's ``__name__``.
        exports: public name -> the submodule (relative, dotted) that defines it.
        submodules: submodules reachable as attributes.
    """
    names = sorted([*exports, *submodules])

    def __getattr__(name: str) -> typing.Any:
        if name in submodules:
            return importlib.import_module(f"{package}.{name}")
        module = exports.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f"{package}.{module}"), name)
        vars(sys.modules[package])[name] = value  # later look-ups skip __getattr__
        return value

    def __dir__() -> list[str]:
        return names

    return __getattr__, __dir__, names
