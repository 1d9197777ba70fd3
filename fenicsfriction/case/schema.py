r"""The case file: a TOML description of a researcher's own problem, read and checked here.

Every key, its unit and what it allows is in docs/case-files.md; this module is that reference
in code. :func:`read_case` parses the file with :mod:`tomllib`, fills in the defaults and checks
every value *before any mesh is built*: an unknown key (with the closest valid one suggested), a
missing required key, a value of the wrong type, out of its range or inconsistent with another
(ν ∉ (-1, 0.5), fmin >= fmax, ε larger than the sliding speed, a contact surface that is a
cell group, ...) and a physical group missing from the gmsh file (its ``$PhysicalNames``
section is read as text) raise :class:`CaseError`, a ``ValueError`` whose message is one line
naming the file, the key, its value and what is allowed. Nothing here imports dolfinx, PETSc
or gmsh, so a bad case file is answered at once.

The result, :class:`Case`, holds plain dictionaries with every default filled in: the model
builder (:mod:`fenicsfriction.case.model`) and the analyses (:mod:`fenicsfriction.case.analyses`)
read them and never check again.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import pathlib
import re
import subprocess
import sys
import tomllib
import typing

from fenicsfriction import laws

__all__ = ["ANALYSES", "CONTACT_FORMULATIONS", "CONTINUABLE", "Case", "CaseError",
           "interface_law", "read_case", "read_physical_names"]

#: the scalar parameters a continuation can step (each one ``fem.Constant`` of the model):
#: the law's values, the global load factor and the speed of the motion
CONTINUABLE = ("mu", "c_n", "b_n", "g", "eps", "load_scale", "speed", "omega")
#: the analyses a case can ask for, in the order they run
ANALYSES = ("steady", "cea", "transient")
#: the discretisations of a body-to-body contact (:data:`fenicsfriction.contact.FORMULATIONS`)
#: and the displacement degrees (``model.degree``) each one takes
CONTACT_FORMULATIONS = {"node-to-segment": (1,), "mortar": (1, 2)}
#: the sides of the generated shapes, "BODY.SIDE": name -> (axis, 0 the lower end, 1 the upper)
SIDES = {"xmin": (0, 0), "xmax": (0, 1), "ymin": (1, 0), "ymax": (1, 1),
         "zmin": (2, 0), "zmax": (2, 1)}
#: the components by name
COMPONENTS = {"x": 0, "y": 1, "z": 2}

Table: typing.TypeAlias = dict[str, typing.Any]


class CaseError(ValueError):
    """A case file that cannot be run: the message is one line naming the file, the key, its
    value and what is allowed."""


class _Checker:
    """Reads one case file's tables with its file name in every message."""

    def __init__(self, path: pathlib.Path):
        self.path = path

    def fail(self, key: str, value: typing.Any, allowed: str) -> typing.NoReturn:
        shown = value if isinstance(value, str) and value.startswith("<") else repr(value)
        raise CaseError(f"{self.path}: {key}={shown} is invalid: {allowed}")

    def keys(self, table: Table, where: str, allowed: typing.Iterable[str],
             required: typing.Iterable[str] = ()) -> None:
        """Unknown keys (the closest allowed one suggested) and missing required ones."""
        allowed = list(allowed)
        for key in table:
            if key not in allowed:
                close = difflib.get_close_matches(key, allowed, n=1)
                hint = f"did you mean '{close[0]}'? " if close else ""
                self.fail(_join(where, key), "<unknown key>",
                          f"{hint}allowed here: {', '.join(allowed)}")
        for key in required:
            if key not in table:
                self.fail(_join(where, key), "<missing>", "this key is required")

    def table(self, value: typing.Any, key: str) -> Table:
        if not isinstance(value, dict):
            self.fail(key, value, "must be a table")
        return value

    def number(self, table: Table, key: str, where: str, default: typing.Any = None,
               low: float | None = None, high: float | None = None, strict_low: bool = False,
               strict_high: bool = False, integer: bool = False) -> typing.Any:
        """``table[key]`` (or ``default``) as a finite number within the bounds."""
        value = table.get(key, default)
        name = _join(where, key)
        if value is None:
            return None
        kind = "an integer" if integer else "a number"
        ok_type = isinstance(value, int) if integer else isinstance(value, (int, float))
        if isinstance(value, bool) or not ok_type or not math.isfinite(value):
            self.fail(name, value, f"must be {kind} (finite)")
        if low is not None and (value <= low if strict_low else value < low):
            self.fail(name, value, f"must be {'>' if strict_low else '>='} {low:g}"
                      + (f" and {'<' if strict_high else '<='} {high:g}" if high is not None
                         else ""))
        if high is not None and (value >= high if strict_high else value > high):
            self.fail(name, value, f"must be {'<' if strict_high else '<='} {high:g}")
        return int(value) if integer else float(value)

    def choice(self, table: Table, key: str, where: str, choices: typing.Sequence[typing.Any],
               default: typing.Any = None) -> typing.Any:
        value = table.get(key, default)
        if value not in choices or isinstance(value, bool) != isinstance(choices[0], bool):
            self.fail(_join(where, key), value,
                      "must be one of " + ", ".join(repr(c) for c in choices))
        return value

    def vector(self, table: Table, key: str, where: str, dim: int | None,
               default: typing.Any = None, nonzero: bool = False, positive: bool = False,
               length: int | None = None) -> list[float] | None:
        """``table[key]``: a list of ``dim`` (or ``length``) finite numbers."""
        value = table.get(key, default)
        if value is None:
            return None
        name, n = _join(where, key), length or dim
        if not isinstance(value, list) or len(value) != n or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                for v in value):
            self.fail(name, value, f"must be a list of {n} finite numbers")
        if nonzero and not any(value):
            self.fail(name, value, "must not be the zero vector")
        if positive and min(value) <= 0:
            self.fail(name, value, "every component must be > 0")
        return [float(v) for v in value]

    def string(self, table: Table, key: str, where: str, default: typing.Any = None) -> typing.Any:
        value = table.get(key, default)
        if value is not None and not isinstance(value, str):
            self.fail(_join(where, key), value, "must be a string")
        return value


def _join(where: str, key: str) -> str:
    return f"{where}.{key}" if where else key


@dataclasses.dataclass
class Case:
    """A checked case file with its defaults filled in (see docs/case-files.md).

    Attributes:
        path: the case file.
        title: its title.
        model: ``dim``, ``degree``, ``plane``, ``thickness``, ``load_scale``.
        mesh: ``file`` (absolute path) and ``script``, or None when every body is generated.
        bodies: name -> body table (material, damping, ``group`` or a generated ``shape``).
        supports, loads, contacts: lists of tables.
        law: the interface law's keyword arguments (friction coefficient law and slip rule
            still as tables: :func:`fenicsfriction.case.model.interface_law` makes the objects).
        motion: ``type`` "translation" (``velocity``) or "rotation" (``omega``, ``axis``,
            ``point``), or None.
        steady, cea, transient: the analyses' tables, None when not asked for.
        physical_names: the gmsh file's physical groups, (dim, name) -> tag.
    """

    path: pathlib.Path
    title: str
    model: Table
    mesh: Table | None
    bodies: dict[str, Table]
    supports: list[Table]
    loads: list[Table]
    law: Table
    contacts: list[Table]
    motion: Table | None
    steady: Table | None
    cea: Table | None
    transient: Table | None
    physical_names: dict[tuple[int, str], int] = dataclasses.field(default_factory=dict)

    @property
    def parameter(self) -> str:
        """The continued parameter (``steady.parameter``, default ``"mu"``)."""
        return self.steady["parameter"] if self.steady else "mu"

    def parameter_value(self) -> float:
        """The continued parameter's value as the case file sets it."""
        return _parameter_value(self, self.parameter)


def _parameter_value(case: Case, name: str) -> float:
    if name == "load_scale":
        return case.model["load_scale"]
    if name == "speed":
        assert case.motion is not None
        return math.hypot(*case.motion["velocity"])
    if name == "omega":
        assert case.motion is not None
        return case.motion["omega"]
    return case.law[name]


TOP_KEYS = ("title", "model", "mesh", "bodies", "supports", "loads", "law", "contacts", "motion",
            *ANALYSES)
MATERIAL_KEYS = ("E", "nu", "rho", "rayleigh_alpha", "rayleigh_beta", "rotating")
SHAPE_KEYS = ("shape", "origin", "size", "divisions", "x", "y", "z", "nodes_at")
LAW_KEYS = ("c_n", "m_n", "mu", "m_T", "b_n", "l_n", "g", "eps", "regularisation",
            "friction_coefficient", "slip_rule")
FRICTION_LAWS = {"constant": (("mu",), ()),
                 "stribeck": (("mu_s", "mu_k", "v_s"), ("exponent",)),
                 "piecewise-linear": ((), ("mu_s", "slope", "v_c"))}


def read_case(path: str | pathlib.Path, make_mesh: bool = True) -> Case:
    """Read and check a case file; nothing heavy is imported or built.

    Args:
        path: the TOML file.
        make_mesh: run ``mesh.script`` when ``mesh.file`` is missing (otherwise a missing
            file is an error).

    Returns:
        The :class:`Case`.

    Raises:
        CaseError: the first problem, one line naming the file, the key and what is allowed.
    """
    path = pathlib.Path(path)
    c = _Checker(path)
    try:
        data = tomllib.loads(path.read_text())
    except OSError as err:
        raise CaseError(f"{path}: cannot be read ({err.strerror or err})") from None
    except tomllib.TOMLDecodeError as err:
        raise CaseError(f"{path}: is not valid TOML ({err})") from None
    c.keys(data, "", TOP_KEYS, required=("model", "bodies"))
    title = c.string(data, "title", "", default=path.stem)
    model = _model(c, c.table(data["model"], "model"))
    dim = model["dim"]
    bodies_table = c.table(data["bodies"], "bodies")
    if not bodies_table:
        c.fail("bodies", {}, "at least one body is required")
    bodies = {name: _body(c, c.table(b, f"bodies.{name}"), f"bodies.{name}", model)
              for name, b in bodies_table.items()}
    generated = {n for n, b in bodies.items() if "shape" in b}
    if generated and len(generated) < len(bodies):
        c.fail("bodies", sorted(bodies), "either every body is generated (shape) or every body "
               "is a physical group of mesh.file (group)")
    boxes = [(n, b["axes"]) for n, b in bodies.items() if "shape" in b]
    for i, (first, a) in enumerate(boxes):
        for second, b in boxes[i + 1:]:
            if all(x[0] < y[-1] and y[0] < x[-1] for x, y in zip(a, b, strict=True)):
                c.fail(f"bodies.{second}", "<shape>", f"overlaps bodies.{first}: generated "
                       "bodies may touch but not overlap")
    mesh = None
    if not generated:
        c.keys(data, "", TOP_KEYS, required=("mesh",))
        mesh = _mesh(c, c.table(data["mesh"], "mesh"))
    elif "mesh" in data:
        c.fail("mesh", data["mesh"], "the bodies are generated (shape): no mesh file is read")
    surfaces = _Surfaces(c, bodies, dim)
    supports = [_support(c, c.table(s, f"supports[{i}]"), f"supports[{i}]", surfaces, bodies,
                         dim) for i, s in enumerate(_list(c, data, "supports"))]
    loads = [_load(c, c.table(s, f"loads[{i}]"), f"loads[{i}]", surfaces, bodies, dim)
             for i, s in enumerate(_list(c, data, "loads"))]
    law = _law(c, c.table(data.get("law", {}), "law"), dim)
    motion = _motion(c, c.table(data["motion"], "motion"), dim) if "motion" in data else None
    contacts = [_contact(c, c.table(s, f"contacts[{i}]"), f"contacts[{i}]", surfaces, model,
                         motion) for i, s in enumerate(_list(c, data, "contacts"))]
    if any(b["rotating"] for b in bodies.values()) and (motion is None
                                                       or motion["type"] != "rotation"):
        c.fail("motion", motion and motion["type"], "a rotating body needs motion.type = "
               "'rotation'")
    case = Case(path=path, title=title, model=model, mesh=mesh, bodies=bodies,
                supports=supports, loads=loads, law=law, contacts=contacts, motion=motion,
                steady=None, cea=None, transient=None)
    if "steady" in data or "cea" in data or "transient" in data:
        case.steady = _steady(c, c.table(data.get("steady", {}), "steady"), case)
    if "cea" in data:
        case.cea = _cea(c, c.table(data["cea"], "cea"), case)
    if "transient" in data:
        if case.cea is None:
            c.fail("transient", "<table>", "needs a [cea] table: it starts from the steady "
                   "state perturbed by the most unstable mode")
        case.transient = _transient(c, c.table(data["transient"], "transient"), case)
    if motion is not None and motion["type"] == "translation" and law["eps"] >= math.hypot(
            *motion["velocity"]) and contacts:
        c.fail("law.eps", law["eps"], f"must be smaller than the sliding speed "
               f"|motion.velocity| = {math.hypot(*motion['velocity']):g} (ε is the width of the "
               "stick band of the regularised friction)")
    if mesh is not None:
        case.physical_names = _check_groups(c, case, make_mesh)
    return case


def _list(c: _Checker, data: Table, key: str) -> list:
    value = data.get(key, [])
    if not isinstance(value, list):
        c.fail(key, "<table>", f"must be an array of tables: write [[{key}]]")
    return value


def _model(c: _Checker, t: Table) -> Table:
    c.keys(t, "model", ("dim", "degree", "plane", "thickness", "load_scale"), required=("dim",))
    dim = c.choice(t, "dim", "model", (2, 3))
    model = {"dim": dim, "degree": c.choice(t, "degree", "model", (1, 2, 3), default=1),
             "load_scale": c.number(t, "load_scale", "model", 1.0)}
    if dim == 2:
        model["plane"] = c.choice(t, "plane", "model", ("strain", "stress"), default="strain")
        model["thickness"] = c.number(t, "thickness", "model", 1.0, low=0, strict_low=True)
    else:
        for key in ("plane", "thickness"):
            if key in t:
                c.fail(f"model.{key}", t[key], "is for 2D models (model.dim = 2) only")
        model["plane"], model["thickness"] = None, 1.0
    return model


def _mesh(c: _Checker, t: Table) -> Table:
    c.keys(t, "mesh", ("file", "script"), required=("file",))
    base = c.path.parent
    file = c.string(t, "file", "mesh")
    script = c.string(t, "script", "mesh")
    if not file.endswith(".msh"):
        c.fail("mesh.file", file, "must be a gmsh .msh file (relative to the case file)")
    if script is not None and not (base / script).is_file():
        c.fail("mesh.script", script, f"no such file (relative to {base})")
    return {"file": (base / file).resolve(),
            "script": None if script is None else (base / script).resolve()}


def _body(c: _Checker, t: Table, where: str, model: Table) -> Table:
    dim = model["dim"]
    c.keys(t, where, ("group", *SHAPE_KEYS, *MATERIAL_KEYS), required=("E", "nu", "rho"))
    body: Table = {
        "E": c.number(t, "E", where, low=0, strict_low=True),
        "nu": c.number(t, "nu", where, low=-1, high=0.5, strict_low=True, strict_high=True),
        "rho": c.number(t, "rho", where, low=0, strict_low=True),
        "rayleigh_alpha": c.number(t, "rayleigh_alpha", where, 0.0, low=0),
        "rayleigh_beta": c.number(t, "rayleigh_beta", where, 0.0, low=0),
        "rotating": c.choice(t, "rotating", where, (False, True), default=False)}
    if ("group" in t) == ("shape" in t):
        c.fail(where, "<table>", "give either group (a physical group of mesh.file) or shape "
               "(a generated rectangle or box)")
    if "group" in t:
        group = t["group"]
        if isinstance(group, bool) or not isinstance(group, (str, int)):
            c.fail(f"{where}.group", group, "must be a physical group's name or number")
        for key in SHAPE_KEYS:
            if key in t:
                c.fail(f"{where}.{key}", t[key], "is for generated bodies (shape) only")
        body["group"] = group
        return body
    shape = c.choice(t, "shape", where, ("rectangle", "box"))
    if (shape == "rectangle") != (dim == 2):
        c.fail(f"{where}.shape", shape, f"must be {'rectangle' if dim == 2 else 'box'} in a "
               f"{dim}D model")
    body["shape"] = shape
    body["origin"] = c.vector(t, "origin", where, dim, default=[0.0] * dim)
    size = c.vector(t, "size", where, dim, positive=True)
    divisions = t.get("divisions")
    axes = []
    for axis in range(dim):
        key = "xyz"[axis]
        if key in t:
            coordinates = c.vector(t, key, where, None, length=len(t[key]) if isinstance(
                t[key], list) else 0)
            if coordinates is None or len(coordinates) < 2 or any(
                    b <= a for a, b in zip(coordinates, coordinates[1:], strict=False)):
                c.fail(f"{where}.{key}", t[key], "must be an increasing list of at least 2 "
                       "vertex coordinates")
            axes.append(coordinates)
            continue
        if size is None or divisions is None:
            c.fail(f"{where}.size" if size is None else f"{where}.divisions", "<missing>",
                   f"give size and divisions (or the vertex coordinates {key} = [...])")
        if (not isinstance(divisions, list) or len(divisions) != dim
                or not all(isinstance(n, int) and not isinstance(n, bool) and n >= 1
                           for n in divisions)):
            c.fail(f"{where}.divisions", divisions, f"must be a list of {dim} integers >= 1")
        o, s, n = body["origin"][axis], size[axis], divisions[axis]
        axes.append([o + s * k / n for k in range(n + 1)])
    body["axes"] = axes
    points = t.get("nodes_at", [])
    if not isinstance(points, list):
        c.fail(f"{where}.nodes_at", points, f"must be a list of points of {dim} coordinates")
    body["nodes_at"] = [c.vector({"p": p}, "p", f"{where}.nodes_at", dim) for p in points]
    for p in body["nodes_at"]:
        if not all(a[0] <= x <= a[-1] for a, x in zip(axes, p, strict=True)):
            c.fail(f"{where}.nodes_at", p, "every point must lie in the body")
    return body


class _Surfaces:
    """Resolves the surface and body names of supports, loads and contacts.

    A generated body's sides are ``"BODY.SIDE"`` (SIDE one of :data:`SIDES`, zmin/zmax in
    3D only); a gmsh body's surfaces are physical groups of dimension dim - 1, by name or number,
    checked against the file later (:func:`_check_groups`).
    """

    def __init__(self, c: _Checker, bodies: dict[str, Table], dim: int):
        self.c, self.bodies, self.dim = c, bodies, dim
        self.generated = all("shape" in b for b in bodies.values())
        self.groups: list[tuple[str, typing.Any, int]] = []  # (key, group, dim) to check

    def surface(self, t: Table, key: str, where: str) -> typing.Any:
        value = t.get(key)
        name = _join(where, key)
        if value is None:
            self.c.fail(name, "<missing>", "this key is required (a surface)")
        if not self.generated:
            if isinstance(value, bool) or not isinstance(value, (str, int)):
                self.c.fail(name, value, "must be a physical group's name or number")
            self.groups.append((name, value, self.dim - 1))
            return value
        sides = [s for s, (axis, _) in SIDES.items() if axis < self.dim]
        body, _, side = str(value).partition(".")
        if body not in self.bodies:
            close = difflib.get_close_matches(body, list(self.bodies), n=1)
            self.c.fail(name, value, (f"did you mean '{close[0]}.{side}'? " if close else "")
                        + f"must be BODY.SIDE with BODY one of {', '.join(self.bodies)}")
        if side not in sides:
            self.c.fail(name, value, f"must be BODY.SIDE with SIDE one of {', '.join(sides)}")
        return value

    def body_names(self, t: Table, key: str, where: str) -> list[str]:
        value = t.get(key, list(self.bodies))
        if not isinstance(value, list) or not all(v in self.bodies for v in value):
            self.c.fail(_join(where, key), value,
                        f"must be a list of body names among {', '.join(self.bodies)}")
        return list(value)


def _support(c: _Checker, t: Table, where: str, surfaces: _Surfaces, bodies: dict[str, Table],
             dim: int) -> Table:
    kind = c.choice(t, "type", where, ("clamped", "displacement", "elastic", "spring"))
    axes = tuple("xyz"[:dim])
    if kind == "clamped":
        c.keys(t, where, ("type", "on"), required=("on",))
        return {"type": kind, "on": surfaces.surface(t, "on", where)}
    if kind == "displacement":
        c.keys(t, where, ("type", "on", *axes), required=("on",))
        values = {a: c.number(t, a, where) for a in axes if a in t}
        if not values:
            c.fail(where, "<table>", f"give the prescribed components among {', '.join(axes)}")
        return {"type": kind, "on": surfaces.surface(t, "on", where), "values": values}
    if kind == "elastic":
        c.keys(t, where, ("type", "on", "stiffness"), required=("on", "stiffness"))
        return {"type": kind, "on": surfaces.surface(t, "on", where),
                "stiffness": c.number(t, "stiffness", where, low=0, strict_low=True)}
    c.keys(t, where, ("type", "point", "component", "stiffness", "anchor"),
           required=("point", "component", "stiffness"))
    return {"type": kind, "point": c.vector(t, "point", where, dim),
            "component": COMPONENTS[c.choice(t, "component", where, axes)],
            "stiffness": c.number(t, "stiffness", where, low=0, strict_low=True),
            "anchor": c.number(t, "anchor", where, 0.0)}


def _load(c: _Checker, t: Table, where: str, surfaces: _Surfaces, bodies: dict[str, Table],
          dim: int) -> Table:
    kind = c.choice(t, "type", where, ("pressure", "traction", "gravity", "body_force"))
    if kind in ("pressure", "traction"):
        c.keys(t, where, ("type", "on", "value"), required=("on", "value"))
        value = (c.number(t, "value", where) if kind == "pressure"
                 else c.vector(t, "value", where, dim))
        return {"type": kind, "on": surfaces.surface(t, "on", where), "value": value}
    c.keys(t, where, ("type", "bodies", "value"), required=("value",))
    return {"type": kind, "bodies": surfaces.body_names(t, "bodies", where),
            "value": c.vector(t, "value", where, dim)}


def _law(c: _Checker, t: Table, dim: int) -> Table:
    c.keys(t, "law", LAW_KEYS)
    law: Table = {
        "c_n": c.number(t, "c_n", "law", 1e10, low=0, strict_low=True),
        "m_n": c.number(t, "m_n", "law", 2.5, low=1),
        "mu": c.number(t, "mu", "law", 0.0, low=0),
        "b_n": c.number(t, "b_n", "law", 0.0, low=0),
        "g": c.number(t, "g", "law", 0.0, low=0),
        "eps": c.number(t, "eps", "law", 1e-3, low=0, strict_low=True),
        "regularisation": c.choice(t, "regularisation", "law", ("c1", "smooth"), default="c1")}
    law["m_T"] = c.number(t, "m_T", "law", law["m_n"], low=1)
    law["l_n"] = c.number(t, "l_n", "law", law["m_n"], low=1)
    law["friction_coefficient"] = None
    if "friction_coefficient" in t:
        where = "law.friction_coefficient"
        f = c.table(t["friction_coefficient"], where)
        kind = c.choice(f, "type", where, tuple(FRICTION_LAWS))
        required, optional = FRICTION_LAWS[kind]
        c.keys(f, where, ("type", *required, *optional), required=required)
        law["friction_coefficient"] = {"type": kind, **{
            k: c.number(f, k, where, low=0) for k in (*required, *optional) if k in f}}
    law["slip_rule"] = None
    if "slip_rule" in t:
        where = "law.slip_rule"
        r = c.table(t["slip_rule"], where)
        kind = c.choice(r, "type", where, ("coulomb", "elliptic"))
        if kind == "coulomb":
            c.keys(r, where, ("type",))
            law["slip_rule"] = {"type": kind}
        else:
            c.keys(r, where, ("type", "mu_x", "mu_y", "associated", "frame"),
                   required=("mu_x", "mu_y"))
            frame = r.get("frame")
            if frame is not None and (not isinstance(frame, list) or len(frame) not in (1, 2)):
                c.fail(f"{where}.frame", frame, "must be a list of 1 or 2 tangent vectors")
            law["slip_rule"] = {
                "type": kind,
                "mu_x": c.number(r, "mu_x", where, low=0, strict_low=True),
                "mu_y": c.number(r, "mu_y", where, low=0, strict_low=True),
                "associated": c.choice(r, "associated", where, (True, False), default=True),
                "frame": None if frame is None else [
                    c.vector({"t": v}, "t", f"{where}.frame", dim, nonzero=True) for v in frame]}
    _checked_law(c, law, "law")
    return law


def interface_law(law: Table) -> laws.InterfaceLaw:
    """The :class:`~fenicsfriction.laws.InterfaceLaw` of a ``[law]`` table (its friction
    coefficient law and slip rule made objects); the law validates its own values."""
    values = {k: v for k, v in law.items() if k not in ("friction_coefficient", "slip_rule")}
    friction, rule = law.get("friction_coefficient"), law.get("slip_rule")
    if friction is not None:
        make = {"constant": laws.ConstantFriction, "stribeck": laws.StribeckFriction,
                "piecewise-linear": laws.PiecewiseLinearFriction}[friction["type"]]
        values["friction_coefficient"] = make(**{k: v for k, v in friction.items()
                                                 if k != "type"})
    if rule is not None and rule["type"] == "elliptic":
        values["slip_rule"] = laws.EllipticSlipRule(
            rule["mu_x"], rule["mu_y"], rule["associated"],
            None if rule["frame"] is None else tuple(tuple(t) for t in rule["frame"]))
    elif rule is not None:
        values["slip_rule"] = laws.CoulombSlipRule()
    return laws.InterfaceLaw(**values)


def _checked_law(c: _Checker, law: Table, where: str) -> None:
    """The law's own validation (:class:`fenicsfriction.laws.InterfaceLaw`), named by key."""
    try:
        interface_law(law)
    except ValueError as err:
        name, _, rest = str(err).partition("=")
        value, _, allowed = rest.partition(" is invalid: ")
        c.fail(_join(where, name), f"<{value}>" if value else "<value>", allowed or str(err))


def _motion(c: _Checker, t: Table, dim: int) -> Table:
    kind = c.choice(t, "type", "motion", ("translation", "rotation"))
    if kind == "translation":
        c.keys(t, "motion", ("type", "velocity"), required=("velocity",))
        return {"type": kind, "velocity": c.vector(t, "velocity", "motion", dim, nonzero=True)}
    c.keys(t, "motion", ("type", "omega", "axis", "point"), required=("omega",))
    omega = c.number(t, "omega", "motion")
    if omega == 0:
        c.fail("motion.omega", omega, "must be nonzero (rad/s; its sign is the sense)")
    axis = c.vector(t, "axis", "motion", None, default=[0.0, 0.0, 1.0], nonzero=True, length=3)
    assert axis is not None
    if dim == 2 and (axis[0] or axis[1]):
        c.fail("motion.axis", axis, "in 2D the axis is normal to the plane: [0, 0, ±1]")
    return {"type": kind, "omega": omega, "axis": axis,
            "point": c.vector(t, "point", "motion", dim, default=[0.0] * dim)}


def _contact(c: _Checker, t: Table, where: str, surfaces: _Surfaces, model: Table,
             motion: Table | None) -> Table:
    dim = model["dim"]
    if "foundation" in t:
        c.keys(t, where, ("name", "surface", "foundation", "moving", "quadrature_degree",
                          "quadrature_rule", "initial_penetration"), required=("surface",))
        f = c.table(t["foundation"], f"{where}.foundation")
        c.keys(f, f"{where}.foundation", ("point", "normal"), required=("normal",))
        contact: Table = {
            "kind": "foundation", "surface": surfaces.surface(t, "surface", where),
            "point": c.vector(f, "point", f"{where}.foundation", dim, default=[0.0] * dim),
            "normal": c.vector(f, "normal", f"{where}.foundation", dim, nonzero=True),
            "quadrature_degree": c.number(t, "quadrature_degree", where, low=1, integer=True),
            "quadrature_rule": c.choice(t, "quadrature_rule", where,
                                        ("default", "GLL", "nodal"), default="default")}
        if contact["quadrature_rule"] == "nodal" and model["degree"] != 1:
            c.fail(f"{where}.quadrature_rule", "nodal", "the nodal rule needs model.degree = 1")
        if motion is not None and motion["type"] == "rotation" and dim == 3:
            n, a = contact["normal"], motion["axis"]
            cross = [n[1] * a[2] - n[2] * a[1], n[2] * a[0] - n[0] * a[2],
                     n[0] * a[1] - n[1] * a[0]]
            if math.hypot(*cross) > 1e-12 * math.hypot(*n) * math.hypot(*a):
                c.fail(f"{where}.foundation.normal", contact["normal"],
                       f"a rotating plane foundation turns about its normal: must be parallel "
                       f"to motion.axis = {a}")
        if motion is not None and motion["type"] == "translation" and t.get("moving", True):
            n, v = contact["normal"], motion["velocity"]
            if abs(sum(a * b for a, b in zip(n, v, strict=True))) > 1e-12 * math.hypot(
                    *n) * math.hypot(*v):
                c.fail("motion.velocity", v, f"a plane foundation slides in its plane: must be "
                       f"orthogonal to {where}.foundation.normal = {n}")
        if motion is not None and motion["type"] == "rotation" and dim == 2:
            c.fail("motion.type", "rotation", "a rigid plane foundation cannot rotate in 2D: "
                   "mesh the rotating body and use a body-to-body contact (slave, master)")
    else:
        c.keys(t, where, ("name", "slave", "master", "passes", "moving", "formulation",
                          "initial_penetration"), required=("slave", "master"))
        formulation = c.choice(t, "formulation", where, tuple(CONTACT_FORMULATIONS),
                               default="node-to-segment")
        degree = model["degree"]
        if degree not in CONTACT_FORMULATIONS[formulation]:
            if any(degree in degrees for degrees in CONTACT_FORMULATIONS.values()):
                c.fail(f"{where}.formulation", formulation, f"must be 'mortar' with "
                       f"model.degree = {degree} (node-to-segment contact needs degree 1)")
            c.fail("model.degree", degree, "must be 1 or 2 with a body-to-body contact "
                   "(2 with formulation = 'mortar')")
        contact = {"kind": "bodies", "slave": surfaces.surface(t, "slave", where),
                   "master": surfaces.surface(t, "master", where),
                   "passes": c.choice(t, "passes", where, (1, 2), default=1),
                   "formulation": formulation}
    contact["name"] = c.string(t, "name", where, default=f"contact{where[9:-1]}")
    contact["moving"] = c.choice(t, "moving", where, (True, False), default=motion is not None)
    if contact["moving"] and motion is None:
        c.fail(f"{where}.moving", True, "needs a [motion] table (the foundation's or the master "
               "body's motion)")
    contact["initial_penetration"] = c.number(t, "initial_penetration", where, low=0)
    return contact


def _steady(c: _Checker, t: Table, case: Case) -> Table:
    c.keys(t, "steady", ("parameter", "values", "start", "stop", "steps", "max_halvings"))
    parameter = c.choice(t, "parameter", "steady", CONTINUABLE, default="mu")
    if parameter in ("speed", "omega"):
        wanted = "translation" if parameter == "speed" else "rotation"
        if case.motion is None or case.motion["type"] != wanted:
            c.fail("steady.parameter", parameter, f"needs motion.type = '{wanted}'")
    if "values" in t:
        for key in ("start", "stop", "steps"):
            if key in t:
                c.fail(f"steady.{key}", t[key], "give either values or start, stop, steps")
        values = t["values"]
        if not isinstance(values, list) or not values:
            c.fail("steady.values", values, "must be a non-empty list of numbers")
        values = c.vector(t, "values", "steady", None, length=len(values))
    else:
        start = c.number(t, "start", "steady", _parameter_value(case, parameter))
        stop = c.number(t, "stop", "steady", start)
        steps = c.number(t, "steps", "steady", 1 if stop != start else 0, low=0, integer=True)
        values = [start + (stop - start) * k / max(steps, 1) for k in range(steps + 1)]
    assert values is not None
    for value in values:
        _check_parameter(c, case, parameter, value)
    return {"parameter": parameter, "values": values,
            "max_halvings": c.number(t, "max_halvings", "steady", 8, low=0, integer=True)}


def _check_parameter(c: _Checker, case: Case, name: str, value: float,
                     where: str = "steady.values") -> None:
    """A value of the continued parameter, checked as the law (or the motion) checks it."""
    if name in case.law:
        try:
            interface_law({**case.law, name: value})
        except ValueError as err:
            c.fail(where, value, f"{name}: {str(err).partition(' is invalid: ')[2] or err}")
    elif name == "omega" and value == 0:
        c.fail(where, value, "must be nonzero")
    elif name == "speed" and value <= case.law["eps"]:
        c.fail(where, value, f"must be larger than law.eps = {case.law['eps']:g}")
    elif name == "load_scale" and value < 0:
        c.fail(where, value, "must be >= 0")


def _cea(c: _Checker, t: Table, case: Case) -> Table:
    c.keys(t, "cea", ("method", "band", "modes", "modal_damping", "friction_stiffness",
                      "friction_damping", "contributions", "growth_tol", "onset_tol"),
           required=("band",))
    band = c.vector(t, "band", "cea", None, length=2)
    assert band is not None
    if not 0 <= band[0] < band[1]:
        c.fail("cea.band", band, "must be [fmin, fmax] in Hz with 0 <= fmin < fmax")
    method = c.choice(t, "method", "cea", ("full", "projection"), default="full")
    values = case.steady["values"] if case.steady else []
    onset_tol = c.number(t, "onset_tol", "cea", 1e-4, low=0, strict_low=True)
    if len(values) > 1 and onset_tol >= abs(values[-1] - values[0]):
        c.fail("cea.onset_tol", onset_tol, "must be smaller than the continuation's range")
    for key in ("modes", "modal_damping"):
        if key in t and method != "projection":
            c.fail(f"cea.{key}", t[key], "is for cea.method = 'projection' only (the modal "
                   "basis); use the bodies' rayleigh_alpha/rayleigh_beta with the full method")
    zeta = t.get("modal_damping", 0.0)
    ratios = zeta if isinstance(zeta, list) else [zeta]
    if not ratios or not all(isinstance(z, (int, float)) and not isinstance(z, bool)
                             and math.isfinite(z) and 0 <= z < 1 for z in ratios):
        c.fail("cea.modal_damping", zeta,
               "must be a damping ratio ζ in [0, 1), or a list of them (one per basis mode)")
    modes = c.number(t, "modes", "cea", 40 if method == "projection" else None, low=1,
                     integer=True)
    if isinstance(zeta, list) and len(ratios) != modes:
        c.fail("cea.modal_damping", zeta, f"must have one ratio per basis mode (cea.modes = "
               f"{modes})")
    switches = {key: c.choice(t, key, "cea", (True, False), default=True)
                for key in ("friction_stiffness", "friction_damping")}
    law = case.law
    linear_in_mu = law["friction_coefficient"] is None and (
        law["slip_rule"] is None or law["slip_rule"]["type"] == "coulomb")
    for key, kept in switches.items():
        if not kept and not linear_in_mu:
            c.fail(f"cea.{key}", False, "dropping the friction part needs friction linear in "
                   "law.mu (no friction_coefficient law, Coulomb's slip rule)")
    return {"method": method, "band": band, "modes": modes,
            "modal_damping": [float(z) for z in ratios] if method == "projection" else None,
            **switches,
            "contributions": c.number(t, "contributions", "cea", None, low=1, integer=True),
            "growth_tol": c.number(t, "growth_tol", "cea", 1e-6, low=0, strict_low=True),
            "onset_tol": onset_tol}


def _transient(c: _Checker, t: Table, case: Case) -> Table:
    c.keys(t, "transient", ("at", "amplitude", "t_end", "dt", "stride"),
           required=("t_end", "amplitude"))
    t_end = c.number(t, "t_end", "transient", low=0, strict_low=True)
    dt = c.number(t, "dt", "transient", t_end / 1000, low=0, strict_low=True)
    if dt > t_end:
        c.fail("transient.dt", dt, f"must be <= t_end = {t_end:g}")
    assert case.steady is not None
    at = c.number(t, "at", "transient", case.steady["values"][-1])
    _check_parameter(c, case, case.parameter, at, "transient.at")
    return {"at": at, "amplitude": c.number(t, "amplitude", "transient", low=0, strict_low=True),
            "t_end": t_end, "dt": dt,
            "stride": c.number(t, "stride", "transient", 10, low=1, integer=True)}


# --- the gmsh file's physical groups ------------------------------------------------------------

_NAME_LINE = re.compile(r'^\s*(\d+)\s+(\d+)\s+"(.*)"\s*$')


def read_physical_names(path: pathlib.Path) -> dict[tuple[int, str], int]:
    """The ``$PhysicalNames`` section of a gmsh ``.msh`` file (ASCII header, any version):
    (dimension, name) -> tag, read as text without gmsh."""
    names: dict[tuple[int, str], int] = {}
    with open(path, "rb") as f:
        inside = False
        for raw in f:
            line = raw.decode("utf-8", "replace").strip()
            if line == "$PhysicalNames":
                inside = True
                next(f)  # the count
                continue
            if line == "$EndPhysicalNames":
                break
            if not inside and line in ("$Entities", "$Nodes", "$Elements"):
                break  # no names: gmsh writes them before the entities
            match = _NAME_LINE.match(line) if inside else None
            if match:
                names[(int(match[1]), match[3])] = int(match[2])
    return names


def _check_groups(c: _Checker, case: Case, make_mesh: bool) -> dict[tuple[int, str], int]:
    assert case.mesh is not None
    file, script = case.mesh["file"], case.mesh["script"]
    # made when missing, and made again when older than its script (as make does)
    stale = (file.is_file() and script is not None and script.is_file()
             and script.stat().st_mtime > file.stat().st_mtime)
    if not file.is_file() or (stale and make_mesh):
        if script is None or not make_mesh:
            c.fail("mesh.file", str(file), "no such file" + (" (and no mesh.script to make it)"
                                                            if script is None else ""))
        _run_script(c, script, file)
    names = read_physical_names(file)
    dim = case.model["dim"]
    wanted = [(f"bodies.{n}.group", b["group"], dim) for n, b in case.bodies.items()]
    surfaces = _Surfaces(c, case.bodies, dim)
    for i, t in enumerate(case.supports + case.loads):
        if "on" in t:
            kind = "supports" if i < len(case.supports) else "loads"
            index = i if i < len(case.supports) else i - len(case.supports)
            wanted.append((f"{kind}[{index}].on", t["on"], dim - 1))
    for i, t in enumerate(case.contacts):
        for key in ("surface", "slave", "master"):
            if key in t:
                wanted.append((f"contacts[{i}].{key}", t[key], dim - 1))
    del surfaces
    for key, group, gdim in wanted:
        if isinstance(group, int):
            found = [d for (d, _), tag in names.items() if tag == group]
            if found and gdim not in found:
                c.fail(key, group, f"is a group of dimension {found[0]} in {file.name}; "
                       f"{'cells' if gdim == dim else 'facets'} of dimension {gdim} needed")
            continue
        if (gdim, group) in names:
            continue
        other = [d for (d, n) in names if n == group]
        if other:
            c.fail(key, group, f"is a physical group of dimension {other[0]} in {file.name}; "
                   f"{'cells' if gdim == dim else 'facets'} of dimension {gdim} are needed here")
        known = sorted(n for (d, n) in names if d == gdim)
        close = difflib.get_close_matches(group, known, n=1)
        c.fail(key, group, (f"did you mean '{close[0]}'? " if close else "")
               + f"the physical groups of dimension {gdim} in {file.name} are: "
               + (", ".join(known) or "none"))
    return names


def _run_script(c: _Checker, script: pathlib.Path, file: pathlib.Path) -> None:
    """``python SCRIPT --out FILE`` (the convention of meshes/*.py), the package on the path.

    The script runs as a process of its own, outside the MPI job that may be reading the case:
    the launcher's variables (Open MPI's, PMIx's) are left out of its environment, else its
    ``import mpi4py`` would try to join the job and fail.
    """
    import os
    root = pathlib.Path(__file__).resolve().parents[2]
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_", "PMI_"))}
    env["PYTHONPATH"] = os.pathsep.join(
        [str(root), str(script.parent), os.environ.get("PYTHONPATH", "")])
    run = subprocess.run([sys.executable, str(script), "--out", str(file)], env=env,
                         capture_output=True, text=True, cwd=script.parent)
    if run.returncode != 0 or not file.is_file():
        last = (run.stderr.strip().splitlines() or ["no output"])[-1]
        c.fail("mesh.script", str(script), f"did not write {file.name} ({last})")
