"""Every public name is documented: each module of the package is in the API reference
(``docs/api/*.md``) with its members, each class and function its ``__all__`` names has a
docstring, each constant a ``#:`` comment, and every exported name resolves. The command line
is documented as a page (docs/cli.md), not in the API reference.
"""

import ast
import dataclasses
import importlib
import importlib.util
import inspect
import pathlib
import pkgutil
import re
import types
import typing

import pytest

import fenicsfriction

ROOT = pathlib.Path(__file__).resolve().parents[1]
API = ROOT / "docs" / "api"
INVENTORY = ROOT / "build" / "docs" / "html" / "objects.inv"
AUTOMODULE = re.compile(r"^\.\. automodule:: (\S+)\n((?:[ \t]+:.*\n)*)", re.MULTILINE)


def all_modules() -> list[str]:
    """Every module of the package but ``__main__`` (which runs the command line)."""
    return ["fenicsfriction"] + [
        info.name for info in pkgutil.walk_packages(fenicsfriction.__path__, "fenicsfriction.")
        if not info.name.endswith(".__main__")]


def public_modules() -> list[str]:
    """The modules the API reference covers: not private (``_compat``), not the command line."""
    return [name for name in all_modules()
            if not any(part.startswith("_") for part in name.split("."))
            and not name.startswith("fenicsfriction.cli")]


@dataclasses.dataclass
class Entry:
    """An ``automodule`` directive of the API reference."""

    page: str
    members: bool
    excluded: set[str]


def reference() -> dict[str, Entry]:
    """module -> its ``automodule`` directive in docs/api/*.md."""
    entries: dict[str, Entry] = {}
    for page in sorted(API.glob("*.md")):
        for match in AUTOMODULE.finditer(page.read_text(encoding="utf-8")):
            options = match.group(2)
            excluded = re.search(r":exclude-members:(.*)", options)
            assert match.group(1) not in entries, f"{match.group(1)} is documented twice"
            entries[match.group(1)] = Entry(
                page.name, re.search(r":members:", options) is not None,
                {n.strip() for n in excluded.group(1).split(",")} if excluded else set())
    return entries


def has_docstring(obj: typing.Any) -> bool:
    """Its own docstring: not inherited, not the signature a dataclass writes for itself."""
    doc = obj.__doc__ or ""
    if inspect.isclass(obj) and dataclasses.is_dataclass(obj):
        return bool(doc.strip()) and not doc.startswith(f"{obj.__name__}(")
    return bool(doc.strip())


def is_definition(obj: typing.Any) -> bool:
    """A class or function, documented where it is defined (not a constant or a type alias)."""
    return (inspect.isclass(obj) or inspect.isroutine(obj)) and not isinstance(
        obj, (types.GenericAlias, types.UnionType))


def attribute_docs(module: str) -> set[str]:
    """The module-level names with a ``#:`` comment or a docstring (what autodoc documents)."""
    from sphinx.pycode import ModuleAnalyzer

    return {name for scope, name in ModuleAnalyzer.for_module(module).find_attr_docs()
            if scope == ""}


def constant_home(module: str, name: str) -> str:
    """The module whose source assigns the constant ``name``, following ``from ... import``."""
    mod = importlib.import_module(module)
    package = module if hasattr(mod, "__path__") else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(inspect.getsource(mod))):
        if isinstance(node, ast.ImportFrom) and any(
                alias.name == name and alias.asname in (None, name) for alias in node.names):
            return constant_home(
                importlib.util.resolve_name("." * node.level + (node.module or ""), package), name)
    return module


def documented_where(module: str, name: str, entries: dict[str, Entry]) -> list[str]:
    """The problems with how ``module.name`` is documented (empty: documented once, in the
    module that defines it, with a docstring)."""
    obj = getattr(importlib.import_module(module), name)
    if inspect.ismodule(obj) or name.startswith("__"):  # __version__ is not API reference
        return []  # its own automodule is checked apart
    if is_definition(obj):
        problems = [] if has_docstring(obj) else ["no docstring"]
        home, own = obj.__module__, obj.__name__
        entry = entries.get(home)
        if entry is None or not entry.members:
            return [*problems, f"{home} (where it is defined) is not in docs/api with :members:"]
        if own in entry.excluded or own not in getattr(importlib.import_module(home), "__all__",
                                                       ()):
            return [*problems, f"{home}.{own} is left out of {home}'s documented members"]
        return problems
    # a constant: documented by a `#:` comment where it is assigned
    home = constant_home(module, name)
    entry = entries.get(home)
    if entry is None or not entry.members or name in entry.excluded:
        return [f"{home} (where it is assigned) is not in docs/api with :members:"]
    if name not in getattr(importlib.import_module(home), "__all__", ()):
        return [f"{home} assigns it but leaves it out of its __all__"]
    if name not in attribute_docs(home):
        return [f"a constant with no `#:` comment in {home}"]
    return []


def test_every_public_module_is_in_the_api_reference():
    entries = reference()
    missing = [name for name in public_modules() if name not in entries]
    assert not missing, f"add these modules to docs/api/*.md: {missing}"
    for name in public_modules():
        module = importlib.import_module(name)
        defines = [n for n in getattr(module, "__all__", ())
                   if is_definition(obj := getattr(module, n)) and obj.__module__ == name]
        if not hasattr(module, "__path__") or defines:  # a package only re-exporting needs none
            assert entries[name].members, f"{name} is in {entries[name].page} without :members:"
    stale = [name for name in entries if name not in all_modules()]
    assert not stale, f"docs/api/*.md documents modules that do not exist: {stale}"


def test_every_public_name_is_documented():
    entries = reference()
    problems = {f"{module}.{name}": found for module in public_modules()
                for name in getattr(importlib.import_module(module), "__all__", ())
                if (found := documented_where(module, name, entries))}
    assert not problems, "\n".join(f"{name}: {found}" for name, found in problems.items())


@pytest.mark.parametrize("module", all_modules())
def test_every_name_in_all_resolves(module):
    mod = importlib.import_module(module)
    unresolved = [name for name in getattr(mod, "__all__", ()) if not hasattr(mod, name)]
    assert not unresolved, f"{module}.__all__ names what it does not define: {unresolved}"


def test_the_built_reference_holds_every_public_class_and_function():
    """The HTML build's inventory (``make docs``, which ``make test`` runs first) has an entry
    for every class and function a public ``__all__`` names."""
    if not INVENTORY.exists():
        pytest.skip("no docs build: run `make docs`")
    from sphinx.util.inventory import InventoryFile

    with INVENTORY.open("rb") as stream:
        inventory = InventoryFile.load(stream, "", lambda base, uri: uri)
    documented = {name for kind, objects in inventory.items() if kind.startswith("py:")
                  for name in objects}
    missing = sorted({f"{obj.__module__}.{obj.__qualname__}"
                      for module in public_modules()
                      for name in getattr(importlib.import_module(module), "__all__", ())
                      if is_definition(obj := getattr(importlib.import_module(module), name))}
                     - documented)
    assert not missing, f"not in the built API reference (rebuild with `make docs`): {missing}"
