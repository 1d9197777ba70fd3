"""The package's rooms import downwards only (read from the source with ``ast``, every import
counted: inside functions and under ``TYPE_CHECKING`` too).

* Nothing outside ``fenicsfriction/studies/`` and ``fenicsfriction/cli/`` imports a study or
  the command line: the engine and the generic pieces serve the families, never the reverse.
* A family (``fenicsfriction/studies/<family>/``) imports no other family: what two families
  share moves down into a generic module.
* Only the command line itself and ``fenicsfriction/__main__.py`` import the command line.
"""

from __future__ import annotations

import ast
import pathlib

import pytest

PACKAGE = pathlib.Path(__file__).resolve().parent.parent / "fenicsfriction"

#: the package's and the studies' ``__init__`` re-export the families' names lazily (strings
#: resolved on first access) and import them under TYPE_CHECKING for type checkers only: the
#: flat public API (``ff.BlockOnBelt``), not a dependency of the engine
EXEMPT = {"fenicsfriction/__init__.py", "fenicsfriction/studies/__init__.py"}


def _module_name(path: pathlib.Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: pathlib.Path) -> list[tuple[int, str]]:
    """(line, absolute module name) of every import in the file, relative ones resolved."""
    package = _module_name(path)
    if path.name != "__init__.py":
        package = package.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                base = ".".join([*anchor, base] if base else anchor)
            # ``from fenicsfriction import cli`` imports the submodule: count the names too
            found += [(node.lineno, f"{base}.{alias.name}") for alias in node.names]
    return found


def _violations() -> list[str]:
    problems = []
    for path in sorted(PACKAGE.rglob("*.py")):
        where = path.relative_to(PACKAGE.parent).as_posix()
        if where in EXEMPT:
            continue
        parts = where.split("/")
        family = parts[2] if parts[1] == "studies" and len(parts) > 3 else None
        in_studies, in_cli = parts[1] == "studies", parts[1] == "cli"
        in_cli = in_cli or where == "fenicsfriction/__main__.py"
        for line, name in _imports(path):
            target = name.split(".")
            if target[0] != "fenicsfriction" or len(target) < 2:
                continue
            if target[1] in ("studies", "cli") and not (in_studies or in_cli):
                problems.append(f"{where}:{line} imports {name} (the engine imports no study "
                                "or command line)")
            elif (family is not None and target[1] == "studies" and len(target) > 2
                  and target[2] != family):
                problems.append(f"{where}:{line} imports {name} (another family)")
            elif target[1] == "cli" and not in_cli:
                problems.append(f"{where}:{line} imports {name} (only the command line may)")
    return problems


def test_rooms_import_downwards_only():
    problems = _violations()
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize(("source", "expected"), [
    ("import fenicsfriction.studies.rolling.hertz", "fenicsfriction.studies.rolling.hertz"),
    ("from fenicsfriction import cli", "fenicsfriction.cli"),
    ("def f():\n    from ..rolling import hertz", "fenicsfriction.studies.rolling.hertz"),
    ("import typing\nif typing.TYPE_CHECKING:\n    from fenicsfriction.cli import main",
     "fenicsfriction.cli.main"),
])
def test_every_kind_of_import_is_seen(tmp_path, monkeypatch, source, expected):
    """An import at the top, of a submodule by name, relative inside a function, under
    TYPE_CHECKING: each is read with its absolute module name."""
    module = tmp_path / "fenicsfriction" / "studies" / "contact" / "probe.py"
    module.parent.mkdir(parents=True)
    module.write_text(source)
    monkeypatch.setattr(f"{__name__}.PACKAGE", tmp_path / "fenicsfriction")
    assert expected in [name for _, name in _imports(module)]
