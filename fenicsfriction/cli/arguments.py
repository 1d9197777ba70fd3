"""The command line's flags: every sub-command's parser, built without importing the solvers.

``fenicsfriction --help`` and a mistyped flag need nothing but argparse, so they answer at
once; the module that runs a command (:mod:`~fenicsfriction.cli.block`,
:mod:`~fenicsfriction.cli.oscillators`), and with it MPI, PETSc and dolfinx, is imported only
once the flags are known.
"""

from __future__ import annotations

import argparse
import importlib
import pathlib
import typing

__all__ = ["SLAB_FLAGS", "LazyChoices", "Parser", "add_block_parsers", "add_contact_parsers",
           "add_interface_parsers", "add_oscillator_parsers", "add_rolling_parsers", "creep_range",
           "floats", "omega_range"]


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


def _scene_flags() -> argparse.ArgumentParser:
    """Flags shared by the commands that follow the steady state in μ (None: scene default)."""
    flags = Parser(add_help=False)
    flags.add_argument("scene", choices=LazyChoices("fenicsfriction.studies.block.slab", "SCENES"),
                       help="scene to run: block (rigid belt) or block-on-slab (elastic slab)")
    flags.add_argument("--mu-max", type=float, required=True, help="last friction coefficient")
    flags.add_argument("--steps", type=int, default=30, help="continuation increments (NINCT)")
    flags.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    flags.add_argument("--refine", type=int, default=1, help="mesh refinement (4r × 3r cells)")
    flags.add_argument("--degree", type=int,
                       help="Lagrange degree (block: 2, Q2; block-on-slab: 1, the only one)")
    flags.add_argument("--E", type=float, help="Young's modulus [10³ kg cm⁻¹ s⁻²] (1.4e6)")
    flags.add_argument("--B0", type=float, help="breadth out of the plane [cm] (30.5)")
    flags.add_argument("--K-x", type=float, dest="K_x", help="driver spring [10³ kg s⁻²] (11.1)")
    flags.add_argument("--spring-height", type=float, help="spring height [cm] (H/2)")
    flags.add_argument("--belt-speed", type=float, help="belt speed [cm/s] (0.287)")
    flags.add_argument("--belt-direction", type=int, help="+1 or -1 (+1)")
    flags.add_argument("--eps", type=float, help="regularisation ε [cm/s] (1e-3)")
    flags.add_argument("--regularisation", help="c1 or smooth (c1)")
    flags.add_argument("--contact-quadrature",
                       help="gauss, gll or nodal (block: gauss; block-on-slab: nodal, its only "
                            "rule)")
    _slab_flags(flags)
    flags.add_argument("--max-halvings", type=int, default=8,
                       help="step halvings allowed when a continuation step fails")
    return flags


def _slab_flags(parser: argparse.ArgumentParser) -> None:
    """The slab's fields of the scene block-on-slab (None: the scene's defaults)."""
    slab = parser.add_argument_group("block-on-slab (the elastic belt)")
    slab.add_argument("--slab-E", type=float, dest="slab_E",
                      help="the slab's Young's modulus [10³ kg cm⁻¹ s⁻²] (the block's E)")
    slab.add_argument("--slab-nu", type=float, help="the slab's Poisson's ratio (the block's ν)")
    slab.add_argument("--slab-thickness", type=float, help="the slab's thickness [cm] (10)")
    slab.add_argument("--slab-length", type=float, help="the slab's length [cm] (3 L)")
    slab.add_argument("--slab-density", type=float,
                      help="the slab's density [10³ kg cm⁻³] (the block's)")


#: the flags of :func:`_slab_flags`, which only the scene block-on-slab accepts
SLAB_FLAGS = ("slab_E", "slab_nu", "slab_thickness", "slab_length", "slab_density")


def add_block_parsers(commands: typing.Any) -> None:
    """``steady``, ``stability`` and ``dynamics``, each for the scene ``block``."""
    scene = _scene_flags()
    steady = commands.add_parser(
        "steady", parents=[scene], help="steady sliding with continuation in μ (Problem 2)",
        description="Steady sliding solved by Newton (PETSc SNES) at each μ from 0 to --mu-max; "
                    "PETSc options can be given as -steady_<option> after the flags.")
    steady.add_argument("--eps-sequence", type=floats, metavar="E1,E2,...",
                        help="after the continuation, Kalker's sequential ε process at μ-max")
    steady.add_argument("--snapshots", type=int, default=4, help="deformed shapes to draw")
    stability = commands.add_parser(
        "stability", parents=[scene], help="eigenvalue loci and flutter onset (Problem 3)",
        description="Quadratic eigenvalues of the linearised steady sliding (SLEPc PEP) at each "
                    "μ from 0 to --mu-max, FE and rigid model side by side; PETSc/SLEPc options "
                    "as -stability_<option> after the flags.")
    stability.add_argument("--max-frequency", type=float, default=3e4,
                           help="every eigenvalue with |λ| below this [rad/s] is computed")
    stability.add_argument("--onset-tol", type=float, default=1e-4,
                           help="width of the μ interval the onset is bisected to")
    stability.add_argument("--growth-tol", type=float, default=1e-6,
                           help="a mode grows when Re λ > growth-tol |λ|")
    dynamics = commands.add_parser(
        "dynamics", help="dynamics from a perturbed steady state (Problem 1ε, PETSc TS)",
        description="Generalized-α (TSALPHA2) integration from the steady sliding state at --mu "
                    "plus a normal velocity perturbation; TS/SNES options as -dynamics_<option> "
                    "after the flags (e.g. -dynamics_ts_adapt_type basic).")
    dynamics.add_argument("scene",
                          choices=LazyChoices("fenicsfriction.studies.block.slab", "SCENES"),
                          help="scene to run: block (rigid belt) or block-on-slab")
    dynamics.add_argument("--mu", type=float, required=True, help="friction coefficient")
    dynamics.add_argument("--t-end", type=float, required=True, help="final time [s]")
    dynamics.add_argument("--dt", type=float, default=1e-5, help="(initial) time step [s]")
    dynamics.add_argument("--perturbation", type=float, default=-0.01,
                          help="initial normal velocity added to the steady state [cm/s]")
    dynamics.add_argument("--stride", type=int, default=20, help="steps between field outputs")
    dynamics.add_argument("--probe-x", type=float,
                          help="abscissa [cm] of the contact node whose tractions are recorded "
                               "(default: L/2, the paper's node 29)")
    dynamics.add_argument("--scheme", choices=["alpha2", "central"], default="alpha2",
                          help="implicit generalized-α, or explicit central differences with "
                               "a lumped mass (dt capped at 0.9 of the stable step)")
    dynamics.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    for flag, dest, kind, text in (
            ("--refine", "refine", int, "mesh refinement (1)"),
            ("--belt-speed", "belt_speed", float, "belt speed [cm/s] (0.287)"),
            ("--b-n", "b_n", float, "normal damping [10³ kg cm^(-2-l_n) s⁻¹] (0)"),
            ("--K-x", "K_x", float, "driver spring [10³ kg s⁻²] (11.1)"),
            ("--B0", "B0", float, "breadth [cm] (30.5)"),
            ("--eps", "eps", float, "regularisation ε [cm/s] (1e-3)"),
            ("--regularisation", "regularisation", str, "c1 or smooth (c1)")):
        dynamics.add_argument(flag, dest=dest, type=kind, help=text)
    _slab_flags(dynamics)


def add_oscillator_parsers(commands: typing.Any) -> None:
    """``stability-map mdof`` and ``oscillator mdof|belt``."""
    readings = {"choices": LazyChoices("fenicsfriction.studies.oscillators.slider.table2",
                                       "TABLE2_READINGS"),
                "default": "paper",
                "metavar": "READING",
                "help": "reading of the paper's dimensionless Table 2 model: %(choices)s "
                        "(default: %(default)s)"}
    smap = commands.add_parser(
        "stability-map", help="stability of steady sliding vs forcing frequency (m.d.o.f. slider)",
        description="Growth rate of perturbations of steady sliding of the Table 2 slider by "
                    "first-order averaging and by Floquet multipliers (PETSc TS), with the "
                    "unstable bands.")
    smap.add_argument("scene", choices=["mdof"], help="scene to run")
    smap.add_argument("--omega-range", type=omega_range, required=True, metavar="LO:HI")
    smap.add_argument("--samples", type=int, default=101, help="forcing frequencies sampled")
    smap.add_argument("--methods", default="averaging,floquet",
                      help="comma-separated: averaging, floquet")
    smap.add_argument("--reading", **readings)
    smap.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    osc = commands.add_parser(
        "oscillator", help="stick-slip time response of a friction oscillator",
        description="Integrates the m.d.o.f. slider (mdof) or the 1-d.o.f. oscillator on a "
                    "belt (belt) with stick and slip switched at events located by PETSc TS "
                    "(or a regularised law with --eps); TS options as -hybrid_<option> (mdof) or "
                    "-belt_<option> (belt).")
    osc.add_argument("scene", choices=["mdof", "belt"], help="scene to run")
    osc.add_argument("--t-end", type=float, default=100.0, help="final (dimensionless) time")
    osc.add_argument("--eps", type=float, help="regularised law of this width (no events)")
    osc.add_argument("--rtol", type=float, default=1e-8, help="relative tolerance of the steps")
    osc.add_argument("--sample-dt", type=float, default=0.01, help="output sampling step")
    osc.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    mdof = osc.add_argument_group("mdof (the m.d.o.f. slider, Table 2)")
    mdof.add_argument("--omega", type=float, default=30.78, help="forcing frequency ω_o")
    mdof.add_argument("--reading", **readings)
    mdof.add_argument("--normal-force", choices=["signed", "absolute", "clipped"],
                      default="signed", help="how N enters friction (signed, as eq. 21)")
    mdof.add_argument("--coupled", action="store_true",
                      help="the roughness under a contact follows its tangential motion")
    mdof.add_argument("--perturbation", type=float, default=0.01,
                      help="initial slider velocity added to steady sliding")
    belt = osc.add_argument_group("belt (m ẍ + c ẋ + k x = μ(v_b − ẋ) N)")
    for flag, default, text in (("--m", 1.0, "mass"), ("--k", 1.0, "stiffness"),
                                ("--c", 0.0, "damping"), ("--N", 1.0, "normal force"),
                                ("--v-belt", 0.5, "belt speed"),
                                ("--mu-s", 0.6, "static coefficient"),
                                ("--mu-k", 0.3, "kinetic coefficient (constant, stribeck)"),
                                ("--slope", 0.03, "dμ/d|v| (piecewise)"),
                                ("--v-c", 15.0, "end of the slope (piecewise)"),
                                ("--v-s", 0.5, "Stribeck speed (stribeck)")):
        belt.add_argument(flag, type=float, default=default, help=f"{text} ({default})")
    belt.add_argument("--law", choices=["constant", "piecewise", "stribeck"],
                      default="constant", help="μ(v) while slipping (constant: μ_k, with μ_s "
                                               "for stick)")
    belt.add_argument("--x0", type=float, default=0.0, help="initial displacement (0)")
    belt.add_argument("--v0", type=float,
                      help="initial velocity (the belt's: the mass starts stuck to the belt)")


def _bodies_flags() -> argparse.ArgumentParser:
    """The two bodies and their interface law, shared by the contact scenes (None: the scene's
    defaults, given in the help)."""
    flags = Parser(add_help=False)
    group = flags.add_argument_group("the two bodies and the interface law")
    for flag, text in (("--E1", "body 1's Young's modulus (1)"),
                       ("--nu1", "body 1's Poisson's ratio (0.3)"),
                       ("--E2", "body 2's Young's modulus (1)"),
                       ("--nu2", "body 2's Poisson's ratio (0.3)"),
                       ("--c-n", "normal compliance coefficient: p = c_n d^m_n (1e4)"),
                       ("--m-n", "normal compliance exponent, >= 1 (1: a linear penalty)")):
        group.add_argument(flag, type=float, dest=flag[2:].replace("-", "_"), help=text)
    flags.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    return flags


def _hertz_flags(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--load", type=float,
                        help="P per unit length (2D) or the total force F (3D); default: the "
                             "load giving a = R/10")
    parser.add_argument("--radius", type=float, help="R of the cylinder or sphere (1)")
    parser.add_argument("--refine", type=int,
                        help="mesh refinement level: each halves the element size (0: 0.005 R "
                             "at the contact)")


def add_contact_parsers(commands: typing.Any) -> None:
    """``contact hertz|patch|cattaneo``: the two-body validation scenes."""
    contact = commands.add_parser(
        "contact", help="two elastic bodies in node-to-segment contact, against closed forms",
        description="Validation scenes of two-body contact: Hertz (2D cylinder, 3D sphere), "
                    "the contact patch test and Cattaneo-Mindlin's partial slip; each writes "
                    "contact.json, surface.csv, figures and bodies.xdmf to --out. PETSc "
                    "options as -contact_<option> after the flags.")
    scenes = contact.add_subparsers(dest="scene", required=True, parser_class=Parser)
    bodies = _bodies_flags()
    hertz = scenes.add_parser(
        "hertz", parents=[bodies], help="cylinder (2D) or sphere (3D) on a block, vs Hertz",
        description="A cylinder (plane strain) or a quarter sphere pressed on an elastic "
                    "block to the load --load: contact half-width (radius) and peak pressure "
                    "against Hertz's.")
    hertz.add_argument("--dim", type=int, choices=[2, 3], default=2, help="2 or 3 (2)")
    _hertz_flags(hertz)
    hertz.add_argument("--passes", type=int, choices=[1, 2], default=1,
                       help="1: the cylinder's surface is the slave; 2: each surface in turn")
    patch = scenes.add_parser(
        "patch", parents=[bodies], help="the contact patch test (non-matching meshes)",
        description="Two stacked blocks with non-matching meshes under a uniform pressure "
                    "must transmit it uniformly (Taylor & Papadopoulos 1991).")
    patch.add_argument("--dim", type=int, choices=[2, 3], default=2, help="2 or 3 (2)")
    patch.add_argument("--passes", choices=["1", "2", "both"], default="both",
                       help="one pass, two passes, or both side by side (both)")
    patch.add_argument("--pressure", type=float, help="the pressure applied (0.01)")
    patch.add_argument("--n-upper", type=int, help="elements across the upper block (5)")
    patch.add_argument("--n-lower", type=int, help="elements across the lower block (7)")
    cattaneo = scenes.add_parser(
        "cattaneo", parents=[bodies], help="partial slip under a tangential force (2D)",
        description="The 2D Hertz cylinder with friction, then a tangential force rising to "
                    "Q = q μP in increments (Pop's incremental formulation): stick zone "
                    "and tangential traction against Cattaneo (1938) and Mindlin (1949).")
    _hertz_flags(cattaneo)
    cattaneo.add_argument("--passes", type=int, choices=[1, 2], default=1,
                          help="1: the cylinder's surface is the slave; 2: each in turn")
    cattaneo.add_argument("--mu", type=float, help="friction coefficient (0.3)")
    cattaneo.add_argument("--q-ratio", type=float, help="Q/(μP) reached, in [0, 1) (0.5)")
    cattaneo.add_argument("--increments", type=int, help="increments of Q (10)")
    cattaneo.add_argument("--eps", type=float,
                          help="regularisation of the slip increment [length] (1e-6)")
    cattaneo.add_argument("--eps-sequence", type=floats, metavar="E1,E2,...",
                          help="Kalker's sequential process: the tangential loading again for "
                               "each ε (replaces --eps)")
    cattaneo.add_argument("--formulation", choices=["compliance", "perturbed-lagrangian"],
                          help="the contact law: normal compliance with regularised friction, "
                               "or Pop's perturbed Lagrangian (penalties c_n and --eps-T) "
                               "(compliance)")
    cattaneo.add_argument("--eps-T", dest="penalty_T", type=float,
                          help="tangential penalty of the perturbed Lagrangian "
                               "[force/length^3] (1e4)")


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


def _rolling_flags() -> argparse.ArgumentParser:
    """The Hertzian contact, the creepages and the methods' discretisations, shared by the
    rolling commands (None: the defaults given in the help)."""
    flags = Parser(add_help=False)
    contact = flags.add_argument_group("the contact (any consistent units)")
    for flag, text in (("--a", "semi-axis along the rolling direction x [length]"),
                       ("--b", "lateral semi-axis [length] (3D; default: a, a circle)"),
                       ("--G", "shear modulus of the (quasi-identical) bodies [force/length²]"),
                       ("--nu", "Poisson's ratio, in [0, 0.5]"),
                       ("--mu", "friction coefficient"),
                       ("--Fn", "normal force [force] (2D: per unit length)")):
        contact.add_argument(flag, type=float, dest=flag[2:], required=flag not in ("--b",),
                             help=text)
    creep = flags.add_argument_group("creepages (rigid slip over rolling distance)")
    creep.add_argument("--eta", type=float, default=0.0, help="lateral creepage η (0)")
    creep.add_argument("--phi", type=float, default=0.0, help="spin φ [1/length] (0)")
    fastsim = flags.add_argument_group("fastsim (Kalker's simplified theory)")
    fastsim.add_argument("--nx", type=int, help="elements per strip along x")
    fastsim.add_argument("--ny", type=int, help="strips across the contact")
    fastsim.add_argument("--pressure", choices=["ellipsoidal", "parabolic"],
                         help="the traction bound's pressure profile")
    fe = flags.add_argument_group("fe (Kalker's complete theory by finite elements)")
    fe.add_argument("--dim", type=int, choices=[2, 3], default=3,
                    help="2: Carter's cylinders (plane strain); 3: the Hertzian ellipse (3)")
    fe.add_argument("--cells-per-a", type=int,
                    help="cells over the semi-axis a in the contact zone (8)")
    fe.add_argument("--block-size", type=float,
                    help="the half-space block's half-width and depth over a (20)")
    fe.add_argument("--normal", choices=["hertz", "contact"], dest="normal",
                    help="2D: Hertz's pressure, or a frictionless contact against a rigid "
                         "parabola (hertz)")
    fe.add_argument("--eps-sequence", type=floats, metavar="E1,E2,...",
                    help="Kalker's sequential process: the regularisation ε of the slip, "
                         "relative to the creepage, decreasing, each solve from the previous "
                         "one (10 down to 0.01 in steps of √10)")
    flags.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    return flags


def add_rolling_parsers(commands: typing.Any) -> None:
    """``rolling fastsim|fe|curve``: Kalker's steady rolling of a Hertzian contact."""
    rolling = commands.add_parser(
        "rolling", help="steady rolling contact: creep forces by Kalker's theories",
        description="Steady rolling of two quasi-identical elastic bodies with a Hertzian "
                    "contact: the creep forces, the traction and the adhesion area by the "
                    "simplified theory (FASTSIM) or by the complete theory (finite elements, "
                    "the sequential ε process). Each writes rolling.json, figures and (fe) "
                    "rolling.xdmf to --out; PETSc options as -rolling_<option> after the flags.")
    methods = rolling.add_subparsers(dest="method", required=True, parser_class=Parser)
    flags = _rolling_flags()
    for name, text in (("fastsim", "Kalker's FASTSIM (no mesh): one creepage"),
                       ("fe", "the complete theory by finite elements: one creepage")):
        one = methods.add_parser(name, parents=[flags], help=text, description=text + ".")
        one.add_argument("--xi", type=float, default=0.0, help="longitudinal creepage ξ (0)")
    curve = methods.add_parser(
        "curve", parents=[flags], help="the creep-force curve over a range of ξ",
        description="The creep-force curve Fx(ξ) by one method, beside FASTSIM and Kalker's "
                    "linear theory; one rolling.json record per point.")
    curve.add_argument("--method", choices=["fastsim", "fe"], dest="curve_method",
                       default="fastsim", help="the theory computing the curve (fastsim)")
    curve.add_argument("--xi-range", type=creep_range, required=True, metavar="LO:HI:N",
                       help="N longitudinal creepages from LO to HI")


def add_interface_parsers(commands: typing.Any) -> None:
    """``interface fk|slider|...``: Braun's nonhomogeneous frictional interface."""
    interface = commands.add_parser(
        "interface", help="a nonhomogeneous frictional interface of many contacts (Braun)",
        description="Braun's earthquake-like interface: contacts that break at thresholds and "
                    "re-form; each command writes interface.json, CSV tables and figures to "
                    "--out.")
    models = interface.add_subparsers(dest="model", required=True, parser_class=Parser)
    contacts = Parser(add_help=False)
    group = contacts.add_argument_group("the contacts (any consistent units)")
    for name, kind, default, text in (
            ("--N", int, 1000, "number of contacts"), ("--k", float, 1.0, "contact stiffness"),
            ("--x-s-mean", float, 1.0, "mean threshold stretching x_c"),
            ("--x-s-std", float, 0.1, "spread σ of the Gaussian thresholds"),
            ("--seed", int, 0, "seed of the random numbers")):
        group.add_argument(name, type=kind, default=default, help=f"{text} ({default})")
    group.add_argument("--newborn", choices=["relaxed", "gaussian"], default="relaxed",
                       help="stretching of re-formed contacts: δ(x), or Gaussian (relaxed)")
    group.add_argument("--newborn-mean", type=float, default=0.0,
                       help="mean of the Gaussian newborn stretching (0)")
    group.add_argument("--newborn-std", type=float, default=0.1,
                       help="spread of the Gaussian newborn stretching (0.1)")
    contacts.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    for name, text in (("eq", "the EQ model moved quasistatically, beside its master equation"),
                       ("master-equation", "the master equation of the stretching distribution")):
        command = models.add_parser(name, parents=[contacts], help=text, description=text + ".")
        command.add_argument("--X-max", type=float,
                             help="the slider's last position (5 contact lives: 5 x_c N k/S, "
                                  "5 x_c without interaction)")
        command.add_argument("--h", type=float, default=0.01,
                             help="the master equation's step ΔX = Δx (0.01)")
        if name == "eq":
            command.add_argument("--realisations", type=int, default=1,
                                 help="independent interfaces averaged (1)")
            command.add_argument("--coupling", type=float,
                                 help="interacting contacts: k/(E a) of a √N × √N lattice "
                                      "between two identical bodies (N a square, e.g. --N 256); "
                                      "none by default")
            command.add_argument("--nu", type=float, default=0.3,
                                 help="Poisson's ratio of the bodies, with --coupling (0.3)")
    smap = models.add_parser(
        "stability-map", parents=[contacts],
        help="smooth sliding or stick-slip of the EQ model over K (or the coupling) and σ/x_c",
        description="With --K: the spring-driven EQ model (PETSc TS) over drive stiffnesses and "
                    "threshold spreads, each run classified, with the master equation's K* "
                    "overlaid. With --couplings: interacting contacts on a √N × √N lattice "
                    "moved quasistatically over couplings k/(E a) and spreads, stick-slip where "
                    "one avalanche drops the force by more than --drop-threshold.")
    smap.add_argument("--K", type=floats, metavar="K1,K2,...", help="drive stiffnesses")
    smap.add_argument("--couplings", type=floats, metavar="C1,C2,...",
                      help="couplings k/(E a) of interacting contacts (instead of --K; "
                           "N a square, e.g. --N 256)")
    smap.add_argument("--drop-threshold", type=float, default=0.05,
                      help="with --couplings: the force drop in one avalanche, over the "
                           "kinetic force, that is stick-slip (0.05)")
    smap.add_argument("--lives", type=float, default=8.0,
                      help="with --couplings: the distance moved, in contact lives (8)")
    smap.add_argument("--spreads", type=floats, default=[0.1, 0.3], metavar="S1,S2,...",
                      help="relative threshold spreads σ/x_c (0.1,0.3)")
    interaction = models.add_parser(
        "interaction", help="the response of contacts to a break, through the half-space",
        description="Contacts on an n x n lattice of an elastic half-space (Landau-Lifshitz's "
                    "Green tensor): the force response δf(r) of the others when the centre one "
                    "breaks, its r^-1 and r^-3 laws and their crossover against λ_c = a²E/k.")
    interaction.add_argument("--n", type=int, default=256, help="lattice side (256)")
    interaction.add_argument("--lambda-c", type=float, default=16.0,
                             help="the elastic correlation length over the spacing (16)")
    interaction.add_argument("--nu", type=float, default=0.3, help="Poisson's ratio (0.3)")
    interaction.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    fk = models.add_parser(
        "fk", help="Frenkel-Kontorova slip fronts (PETSc TS, breaks as events)",
        description="m ü + m η u̇ − g(u_{i+1} + u_{i−1} − 2u_i) + F_s(u_i) + K u_i = f: a front "
                    "of breaking contacts from the relaxed left part, its speed against the "
                    "continuum travelling wave.")
    for name, kind, default, text in (
            ("--n", int, 200, "contacts"), ("--m", float, 1.0, "mass per contact"),
            ("--eta", float, 1.0, "damping rate η"), ("--g", float, 100.0, "chain stiffness"),
            ("--k", float, 1.0, "contact stiffness"), ("--K", float, 0.25, "substrate stiffness"),
            ("--u-s", float, 1.0, "contact threshold"), ("--force", float, 1.0, "driving force f"),
            ("--t-end", float, 100.0, "final time"),
            ("--spread", float, 0.0, "relative spread of the thresholds (defects)"),
            ("--seed", int, 1, "seed of the thresholds")):
        fk.add_argument(name, type=kind, default=default, help=f"{text} ({default})")
    fk.add_argument("--forces", type=floats, metavar="F1,F2,...",
                    help="also measure the front speed at each of these forces")
    fk.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
    slider = models.add_parser(
        "slider", help="an elastic slider on EQ contacts, pushed at its trailing edge (dolfinx)",
        description="A 2D elastic slider whose base is held by breaking contacts, pushed at its "
                    "trailing edge: detachment fronts, precursors, the force of global slip.")
    for name, kind, text in (
            ("--L", float, "length [m] (0.1)"), ("--H", float, "height [m] (0.01)"),
            ("--nx", int, "cells along L (40)"), ("--ny", int, "cells along H (4)"),
            ("--E", float, "Young's modulus [Pa] (1e9)"), ("--nu", float, "Poisson's ratio (0.3)"),
            ("--rho", float, "density [kg/m³] (1000)"),
            ("--k", float, "contact stiffness per base length [N/m²] (1e10)"),
            ("--threshold", float, "mean threshold stretch [m] (1e-6)"),
            ("--spread", float, "relative spread of the thresholds (0.5)"),
            ("--delay", float, "time a broken contact stays off [s] (0)"),
            ("--push-speed", float, "speed of the pushing stage [m/s] (0.01)"),
            ("--seed", int, "seed of the thresholds (0)")):
        slider.add_argument(name, type=kind, help=text)
    slider.add_argument("--t-end", type=float, default=5e-3, help="final time [s] (5e-3)")
    slider.add_argument("--dt", type=float, default=1e-6, help="time step [s] (1e-6)")
    slider.add_argument("--out", type=pathlib.Path, required=True, help="output folder")
