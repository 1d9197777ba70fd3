r"""The validation scenes of two-body contact, each against its closed form.

* :class:`Hertz` — an elastic cylinder (2D, plane strain) or sphere (3D, quarter model) pressed
  on an elastic block: contact half-width/radius and peak pressure against Hertz's
  (:mod:`~fenicsfriction.studies.contact.closed_forms`), converging as the mesh is refined and
  as the compliance stiffens (c_n → ∞: the Signorini limit).
* :class:`Patch` — two blocks with non-matching meshes under a uniform pressure must transmit
  it uniformly (Taylor & Papadopoulos 1991's contact patch test), one pass or two.
* :class:`Cattaneo` — the 2D cylinder, then a tangential force rising to Q = q μP in
  increments (Pop's incremental formulation): the stick zone and the tangential traction
  against Cattaneo-Mindlin's, with Kalker's sequential ε → 0.

Units are the user's (consistent); the defaults are dimensionless: R = 1, E = 1, and the load
giving a contact half-width (radius) of R/10.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
import typing

from mpi4py import MPI

import numpy as np

from fenicsfriction import laws
from fenicsfriction.laws import check
from fenicsfriction.steady import SolveError
from fenicsfriction.studies.contact import closed_forms, geometry
from fenicsfriction.studies.contact.model import (
    Material,
    SurfaceValues,
    TwoBodyModel,
    check_discretisation,
)

__all__ = ["AXIS_DISC", "Cattaneo", "Hertz", "Patch", "pressure_on_axis", "surface_comparison"]

#: the regularisation during Cattaneo's normal loading, relative to the contact half-width
NORMAL_LOADING_EPS = 1e-2

#: the Newton iterations allowed when an increment of Cattaneo's perturbed Lagrangian is
#: repeated after failing within the solver's default 50
PENALTY_MAX_IT = 400

#: the disc r <= AXIS_DISC a_h over which :func:`pressure_on_axis` projects the nodal
#: pressures (a_h the measured half-width or radius): the projection of Hertz's profile onto
#: c0 + c1 r² over it overestimates p0 by 0.35 %, and it holds about 13 slave nodes of the
#: default 3D mesh, whose node-to-node scatter it averages out
AXIS_DISC = 0.6

log = logging.getLogger(__name__)


def pressure_on_axis(r: np.ndarray, pressure: np.ndarray, weight: np.ndarray,
                     radius: float, disc: float = AXIS_DISC) -> float:
    r"""The pressure on the axis r = 0 recovered from nodal pressures by a local L2 projection.

    The nodal pressures :math:`p_k` at distances :math:`r_k` from the axis are projected, in
    the nodal rule's inner product (weights :math:`w_k`), onto the even quadratics
    :math:`c_0 + c_1 r^2` over the disc :math:`r \le` ``disc`` × ``radius``: :math:`c_0` minimises
    :math:`\sum_{r_k \le \rho} w_k (c_0 + c_1 r_k^2 - p_k)^2`, a patch recovery in the manner
    of Zienkiewicz & Zhu (1992) on a patch fixed in physical size. It reproduces any such
    quadratic exactly; the node-to-node scatter of the pressures is averaged over the disc's
    nodes; Hertz's profile :math:`p_0\sqrt{1 - r^2/a^2}` is overestimated by its truncation,
    +0.15 %, +0.35 %, +0.72 % for discs of 0.5, 0.6, 0.7 a. Returns :math:`c_0`.

    Args:
        r: the nodes' distances from the axis (2D: |x|).
        pressure: their pressures.
        weight: their weights in the nodal rule (tributary lengths or areas), > 0.
        radius: the contact zone's measured half-width or radius.
        disc: the disc's radius relative to ``radius``, in (0, 1].
    """
    check("disc", disc, 0 < disc <= 1, "a fraction of the contact radius in (0, 1]")
    r, pressure, weight = (np.asarray(v, dtype=float) for v in (r, pressure, weight))
    inside = (r <= disc * radius) & (weight > 0)
    check("pressure", int(inside.sum()), bool(inside.any() and np.ptp(r[inside]) > 0),
          f"nodes at two distances at least, with weight > 0, within r <= {disc} x radius")
    basis = np.column_stack([np.ones(int(inside.sum())), r[inside] ** 2])
    root = np.sqrt(weight[inside])
    coefficients = np.linalg.lstsq(basis * root[:, None], pressure[inside] * root, rcond=None)[0]
    return float(coefficients[0])


@dataclasses.dataclass
class _Bodies:
    """Two elastic bodies and their interface law (shared by the scenes).

    Args:
        E1, nu1: body 1's (cylinder, sphere, upper block) Young's modulus [force/length²] and
            Poisson's ratio.
        E2, nu2: body 2's (the block below).
        law: the interface law (:class:`~fenicsfriction.laws.InterfaceLaw`): normal compliance
            c_n d^m_n [force/length^(2+m_n)], friction, regularisation; default frictionless,
            c_n = 1e4, m_n = 1 (a linear penalty). Change it with ``scene.with_law(c_n=...)``.
        passes: 1 (body 1's surface is the slave) or 2 (each surface slave in turn).
        formulation: the contact's discretisation: ``"node-to-segment"`` (slave nodes against
            master segments, nodal rule; Pop) or ``"mortar"`` (the law on mortar-weighted
            gaps, segment-to-segment integration); :func:`fenicsfriction.contact.make_contact`.
        degree: the Lagrange degree of the displacement, 1 or 2 (2: mortar only).
        partition: how :meth:`build` partitions the mesh over the ranks: ``"graph"``
            (dolfinx's graph partitioner) or ``"contact"`` (both bodies cut across the contact
            plane; :mod:`fenicsfriction.studies.contact.geometry`).
    """

    E1: float = 1.0
    nu1: float = 0.3
    E2: float = 1.0
    nu2: float = 0.3
    law: laws.InterfaceLaw = dataclasses.field(
        default_factory=lambda: laws.InterfaceLaw(c_n=1e4, m_n=1.0))
    passes: int = 1
    formulation: str = "node-to-segment"
    degree: int = 1
    partition: str = "graph"

    def __post_init__(self) -> None:
        check("partition", self.partition, self.partition in geometry.PARTITIONS,
              f"one of {', '.join(geometry.PARTITIONS)}")
        self.E_star  # noqa: B018  (validates E1, nu1, E2, nu2, naming each)
        check("law", self.law, isinstance(self.law, laws.InterfaceLaw),
              "must be a fenicsfriction.laws.InterfaceLaw (it validates its own parameters)")
        check("passes", self.passes, self.passes in (1, 2), "1 or 2")
        check_discretisation(self.formulation, self.degree)

    def model(self, mesh: geometry.TwoBodyMesh, **options: typing.Any) -> TwoBodyModel:
        """The :class:`TwoBodyModel` of these bodies, law, passes and discretisation on
        ``mesh`` (``options``: the model's other arguments)."""
        return TwoBodyModel(mesh, self.materials, self.law, passes=self.passes,
                            formulation=self.formulation, degree=self.degree, **options)

    @property
    def discretisation(self) -> dict[str, typing.Any]:
        """The contact formulation, the degree and the partition, as the summaries record
        them."""
        return {"formulation": self.formulation, "degree": self.degree,
                "partition": self.partition}

    def with_law(self, **changes: typing.Any) -> typing.Self:
        """The scene with its law changed, e.g. ``scene.with_law(c_n=1e5)``."""
        return dataclasses.replace(self, law=self.law.replace(**changes))

    @property
    def materials(self) -> tuple[Material, Material]:
        return Material(self.E1, self.nu1), Material(self.E2, self.nu2)

    @property
    def E_star(self) -> float:
        """The effective modulus :math:`E^*` (plane strain)."""
        return closed_forms.effective_modulus(self.E1, self.nu1, self.E2, self.nu2)


@dataclasses.dataclass
class Hertz(_Bodies):
    """A cylinder (``dim=2``) or sphere (``dim=3``) of radius ``radius`` on a block.

    Args:
        dim: 2 (plane strain, load per unit length) or 3 (a quarter model, total load).
        load: P [force/length] in 2D, F [force] in 3D; ``None``: the load giving a = R/10.
        radius: R [length].
        refine: the mesh's refinement level (each halves the element size).
        h_contact: the element size at the contact before refinement (``None``: the
            geometry's default, R/200 in 2D and R/50 in 3D).
    """

    dim: int = 2
    load: float | None = None
    radius: float = 1.0
    refine: int = 0
    h_contact: float | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        check("dim", self.dim, self.dim in (2, 3), "2 or 3")
        check("radius", self.radius, self.radius > 0, "the radius must be > 0")
        check("refine", self.refine, isinstance(self.refine, int) and self.refine >= 0,
              "an integer >= 0")
        if self.load is None:
            self.load = closed_forms.hertz_load(self.radius / 10, self.radius, self.E_star,
                                                self.dim)
        check("load", self.load, self.load > 0, "the load must be > 0")

    def closed_form(self) -> tuple[float, float]:
        """Hertz's half-width (2D) or contact radius (3D) and peak pressure."""
        assert self.load is not None
        solution = (closed_forms.hertz_line_contact if self.dim == 2
                    else closed_forms.hertz_point_contact)
        return solution(self.load, self.radius, self.E_star)

    def build(self, comm: MPI.Comm = MPI.COMM_WORLD) -> TwoBodyModel:
        mesh = (geometry.hertz_2d if self.dim == 2 else geometry.hertz_3d)(
            comm, R=self.radius, refine=self.refine, h_contact=self.h_contact,
            partition=self.partition)
        # the 2D cylinder's sliding is stopped at its loaded face; the quarter sphere's by the
        # symmetry planes
        return self.model(mesh, fix_load_face=self.dim == 2)

    def run(self, comm: MPI.Comm = MPI.COMM_WORLD, model: TwoBodyModel | None = None
            ) -> tuple[dict, TwoBodyModel]:
        """Solve and compare; returns the summary (see ``docs/cli.md``) and the model.

        The headline figures: ``half_width`` (2D) where the interpolated nodal gap changes
        sign; ``contact_radius`` (3D) the radius √(4A/π) of the quarter model's contact area
        A under the nodal rule (:meth:`TwoBodyModel.contact_area`), the sign change kept as
        ``gap_crossing_radius``; ``peak_pressure`` the pressure on the axis recovered by
        :func:`pressure_on_axis` from the nodes' transmitted pressures, the largest of them
        kept as ``max_pressure``; each beside Hertz's and with its relative ``*_error``."""
        t0 = time.perf_counter()
        model = model or self.build(comm)
        assert self.load is not None
        a, p0 = self.closed_form()
        # the quarter model carries a quarter of the load
        share = 1.0 if self.dim == 2 else 0.25
        solved = model.solve_for_load(share * self.load, guess=a**2 / self.radius, rtol=1e-5)
        values = model.surface_values()  # one contact search for every figure below
        edge = model.contact_edge(values)
        # where the interpolated nodal gap changes sign: next to the last contact node
        crossing = (np.ptp(edge[:, 0]) / 2 if self.dim == 2
                    else float(np.mean(np.linalg.norm(edge[:, :2], axis=1))))
        width = "half_width" if self.dim == 2 else "contact_radius"
        # 2D: the sign change; 3D: the radius of the nodal rule's contact area on the quarter
        # model (four quarters make the circle πa²)
        measured = (crossing if self.dim == 2
                    else math.sqrt(4 * model.contact_area(values) / math.pi))
        r = values.x[:, 0] if self.dim == 2 else np.linalg.norm(values.x[:, :2], axis=1)
        # the pressure each node transmits (its force over its load weight; nodes of zero
        # load weight, a 6-node triangle's vertices, carry none): node-to-segment's law
        # pressure, and what mortar's multipliers p_j amount to (they overshoot at the last
        # node in contact and scatter on the faceted sphere; docs/benchmarks.md)
        loaded = values.load_weight > 0
        transmitted = np.maximum(values.force[loaded, -1], 0.0)
        try:  # Hertz's ellipse through every loaded node's transmitted pressure
            fitted: tuple[float | None, float | None] = closed_forms.fit_hertz_pressure(
                np.abs(r[loaded]), transmitted)
        except ValueError:  # fewer than two contact nodes, or no falling profile
            fitted = (None, None)
        peak = float(transmitted.max(initial=0.0))
        try:
            on_axis: float | None = pressure_on_axis(np.abs(r[loaded]), transmitted,
                                                     values.load_weight[loaded], measured)
        except ValueError:  # fewer than two node distances within the disc
            on_axis = None
        summary = {
            "scene": "hertz", "dim": self.dim, "load": solved["load"] / share,
            "parameters": {"radius": self.radius, "E1": self.E1, "nu1": self.nu1,
                           "E2": self.E2, "nu2": self.nu2, "c_n": self.law.c_n,
                           "m_n": self.law.m_n, "refine": self.refine, "passes": self.passes,
                           "h_contact": model.geometry.parameters["h_contact"],
                           **self.discretisation},
            "dofs": model.dofs, "ranks": comm.size,
            width: measured, f"hertz_{width}": a,
            "max_pressure": peak, "hertz_max_pressure": p0,
            f"{width}_error": measured / a - 1, "max_pressure_error": peak / p0 - 1,
            "peak_pressure": on_axis,
            "peak_pressure_error": None if on_axis is None else on_axis / p0 - 1,
            "max_law_pressure": float(values.pressure.max()),
            **({} if self.dim == 2 else {"gap_crossing_radius": crossing,
                                         "gap_crossing_radius_error": crossing / a - 1}),
            f"fitted_{width}": fitted[0], "fitted_max_pressure": fitted[1],
            f"fitted_{width}_error": None if fitted[0] is None else fitted[0] / a - 1,
            "fitted_max_pressure_error": None if fitted[1] is None else fitted[1] / p0 - 1,
            "approach": solved["approach"], "newton_iterations": solved["newton_iterations"],
            "solves": solved["solves"], "cutbacks": solved["cutbacks"],
            "wall_time_s": time.perf_counter() - t0,
        }
        return summary, model


@dataclasses.dataclass
class Patch(_Bodies):
    """Two stacked blocks (non-matching meshes) under a uniform pressure.

    Args:
        dim: 2 or 3.
        pressure: the pressure applied (through the platen's approach) [force/length²].
        n_upper, n_lower: elements across the upper and the lower block (coprime: the
            interface nodes then coincide only at the ends).
    """

    dim: int = 2
    pressure: float = 0.01
    n_upper: int = 5
    n_lower: int = 7

    def __post_init__(self) -> None:
        super().__post_init__()
        check("dim", self.dim, self.dim in (2, 3), "2 or 3")
        check("pressure", self.pressure, self.pressure > 0, "the pressure must be > 0")
        for name in ("n_upper", "n_lower"):
            value = getattr(self, name)
            check(name, value, isinstance(value, int) and value >= 1, "an integer >= 1")

    def build(self, comm: MPI.Comm = MPI.COMM_WORLD) -> TwoBodyModel:
        mesh = (geometry.patch_2d if self.dim == 2 else geometry.patch_3d)(
            comm, n_upper=self.n_upper, n_lower=self.n_lower, partition=self.partition)
        model = self.model(mesh, clamp=False)
        model.rollers(range(self.dim - 1))
        return model

    def run(self, comm: MPI.Comm = MPI.COMM_WORLD) -> tuple[dict, TwoBodyModel]:
        """The pressure transmitted at the slave nodes (all passes' forces per load weight,
        :class:`~fenicsfriction.studies.contact.model.SurfaceValues`) and its largest
        deviation from the pressure applied, relative to it."""
        t0 = time.perf_counter()
        model = self.build(comm)
        guess = self.law.uniform_penetration(self.pressure) + self.pressure / self.E1
        solved = model.solve_for_load(self.pressure, guess=guess, rtol=1e-10)
        values = model.surface_values()
        # the force a uniform pressure puts on a node is the pressure times the node's load
        # weight (zero at the vertices of 6-node triangles, whose force must then vanish)
        transmitted = values.force[:, -1] / self.pressure
        expected = np.where(values.load_weight > 0, 1.0, 0.0)
        summary = {
            "scene": "patch", "dim": self.dim, "load": self.pressure,
            "parameters": {"E1": self.E1, "nu1": self.nu1, "E2": self.E2, "nu2": self.nu2,
                           "c_n": self.law.c_n, "m_n": self.law.m_n, "passes": self.passes,
                           "n_upper": self.n_upper, "n_lower": self.n_lower,
                           **self.discretisation},
            "dofs": model.dofs, "ranks": comm.size,
            "pressure_deviation": float(np.max(np.abs(transmitted - expected))),
            "newton_iterations": solved["newton_iterations"],
            "residual_norm": solved["residual_norm"], "atol": solved["atol"],
            "wall_time_s": time.perf_counter() - t0,
        }
        return summary, model


@dataclasses.dataclass
class Cattaneo(Hertz):
    """The 2D Hertz cylinder with friction, then a tangential force Q rising to ``q_ratio`` μP.

    Args:
        law: the interface law, Coulomb's with a constant μ > 0 (Cattaneo-Mindlin's closed
            form): compliance c_n, m_n, friction coefficient ``mu`` and the regularisation
            ``eps`` of the slip increment [length] (c1: Pop, eq. 15; a sequence ε_k → 0 is
            Kalker's sequential process, :meth:`run_sequence`); default c_n = 1e4, m_n = 1,
            μ = 0.3, ε = 1e-6.
        q_ratio: Q / (μ P), in [0, 1).
        increments: load increments of Q (the quasi-static path; the stick zone only shrinks).
        enforcement: ``"compliance"`` (the regularised law) or ``"perturbed-lagrangian"``
            (Pop, eq. 27: penalties κ_N = the law's ``c_n`` and κ_T = ``penalty_T``
            [force/length³]; node-to-segment only).
    """

    law: laws.InterfaceLaw = dataclasses.field(
        default_factory=lambda: laws.InterfaceLaw(c_n=1e4, m_n=1.0, mu=0.3, eps=1e-6))
    q_ratio: float = 0.5
    increments: int = 10
    enforcement: str = "compliance"
    penalty_T: float = 1e4

    def __post_init__(self) -> None:
        super().__post_init__()
        check("dim", self.dim, self.dim == 2, "Cattaneo-Mindlin is built in 2D")
        check("mu", self.law.mu, self.law.mu > 0 and self.law.friction_coefficient is None
              and self.law.slip_rule is None,
              "Cattaneo-Mindlin needs a constant friction coefficient > 0 (isotropic Coulomb)")
        check("q_ratio", self.q_ratio, 0 <= self.q_ratio < 1, "Q/(mu P) in [0, 1)")
        check("increments", self.increments,
              isinstance(self.increments, int) and self.increments >= 1, "an integer >= 1")
        check_discretisation(self.formulation, self.degree, self.enforcement)

    def build(self, comm: MPI.Comm = MPI.COMM_WORLD) -> TwoBodyModel:
        mesh = geometry.hertz_2d(comm, R=self.radius, refine=self.refine,
                                 h_contact=self.h_contact, partition=self.partition)
        return self.model(mesh, enforcement=self.enforcement, penalty_T=self.penalty_T)

    def stick_zone(self, values: SurfaceValues, tol: float = 1e-3) -> tuple[float, float]:
        """(stick half-width, slip half-width): the extent of the contact nodes whose traction
        is below the friction bound by more than ``tol`` (stick) and of all contact nodes."""
        contact = values.pressure > 0
        bound = self.law.coefficient(0.0, values.pressure) * values.pressure  # μ p_n
        utilisation = np.linalg.norm(values.traction, axis=1) / np.where(contact, bound, 1.0)
        stick = contact & (utilisation < 1 - tol)
        x = values.x[:, 0]
        return (float(np.ptp(x[stick]) / 2) if stick.any() else 0.0,
                float(np.ptp(x[contact]) / 2) if contact.any() else 0.0)

    def load_normal(self, comm: MPI.Comm = MPI.COMM_WORLD, model: TwoBodyModel | None = None
                    ) -> tuple[dict, TwoBodyModel]:
        """The normal load P alone (:meth:`Hertz.run`), under a wide regularisation: identical
        bodies (Dundurs' β = 0) do not slip under it (Johnson 1985, chapter 5), and the
        friction only holds the cylinder's sliding mode. Returns Hertz's summary and the
        model."""
        model = model or self.build(comm)
        a, _ = self.closed_form()
        model.eps.value = NORMAL_LOADING_EPS * a
        # the perturbed Lagrangian's: a soft spring
        model.penalty_T.value = self.E_star / self.radius
        return Hertz.run(self, comm, model)

    def load_tangential(self, model: TwoBodyModel, eps: float | None = None,
                        on_increment: typing.Callable[[dict], None] | None = None) -> dict:
        """Q from 0 to ``q_ratio`` μP in :attr:`increments` steps under the regularisation
        ``eps`` (default the law's ε), from the model's current (normally loaded) state.

        Returns ``eps``, ``stick_half_width`` (and Cattaneo's), ``traction_error_l2`` (the
        relative L2 error of the final tangential traction against Cattaneo-Mindlin's),
        ``newton_iterations`` (all increments) and ``increments`` (one row per increment).
        """
        eps = self.law.eps if eps is None else eps
        check("eps", eps, eps > 0, "the regularisation must be > 0")
        assert self.load is not None
        a, p0 = self.closed_form()
        model.eps.value = eps
        model.penalty_T.value = self.penalty_T
        rows = []
        for k in range(1, self.increments + 1):
            model.commit()
            q = self.q_ratio * k / self.increments
            model.shear.value = np.array([q * self.law.mu * self.load / (2 * self.radius), 0.0])
            iterations, repeated = self._solve_increment(model)
            values = model.surface_values()
            stick, _ = self.stick_zone(values)
            row = {"q_ratio": q, "stick_half_width": stick,
                   "cattaneo_stick_half_width": closed_forms.cattaneo_stick_half_width(a, q),
                   "newton_iterations": iterations}
            if repeated is not None:
                row["newton_limit_raised_to"] = repeated
            rows.append(row)
            if on_increment is not None:
                on_increment(row)
        values = model.surface_values()
        exact = closed_forms.cattaneo_traction(values.x[:, 0], a, p0, self.law.mu, self.q_ratio)
        # the traction on the cylinder opposes Q: its x component is -q(x). One pass: the
        # law's nodal traction; two: what both passes transmit, each node's force over its
        # load weight (the first pass's law, weighted 1/2, carries only its share)
        traction = values.traction if self.passes == 1 else values.force
        error = float(np.sqrt(np.sum(values.weight * (-traction[:, 0] - exact) ** 2)
                              / np.sum(values.weight * exact**2)))
        return {"eps": eps, "stick_half_width": rows[-1]["stick_half_width"],
                "cattaneo_stick_half_width": rows[-1]["cattaneo_stick_half_width"],
                "traction_error_l2": error,
                "newton_iterations": sum(r["newton_iterations"] for r in rows),
                "increments": rows}

    def _solve_increment(self, model: TwoBodyModel) -> tuple[int, int | None]:
        """One increment of Q; under the perturbed Lagrangian a failed solve is repeated from
        the increment's start with :data:`PENALTY_MAX_IT` Newton iterations allowed: a stiff
        stick spring κ_T makes Newton move the stick-slip boundary by about a node per
        iteration (the residual falls slowly but steadily: at κ_T = 1e5 E*/R, h = a/20 and
        Q = μP/10 the first increment needs 80, against the 50 allowed; continuation in κ_T,
        tenfold steps up from a softer spring's solution, needs as many at each step).
        Returns the Newton
        iterations (the failed solve's included) and the iteration limit of the repeated
        solve (``None``: solved directly)."""
        approach = float(model.approach.value)
        start = model.u.x.array.copy()
        try:
            return model.solve_at(approach).iterations, None
        except SolveError as err:
            if self.enforcement != "perturbed-lagrangian":
                raise
            iterations = err.report.iterations
        log.info("the increment did not converge at penalty_T=%.3g; repeated with %d Newton "
                 "iterations allowed", self.penalty_T, PENALTY_MAX_IT)
        model.u.x.array[:] = start
        model.u.x.scatter_forward()
        snes = model.solver.snes
        tolerances = snes.getTolerances()
        snes.setTolerances(max_it=PENALTY_MAX_IT)
        try:
            iterations += model.solve_at(approach).iterations
        except SolveError as err:
            raise SolveError(f"penalty_T={self.penalty_T:g}: the increment did not converge "
                             f"within {PENALTY_MAX_IT} Newton iterations either (a stiffer "
                             f"stick spring needs more; soften penalty_T): {err}",
                             err.report) from err
        finally:
            snes.setTolerances(max_it=tolerances[3])
        return iterations, PENALTY_MAX_IT

    def _summary(self, normal: dict, tangential: dict, t0: float) -> dict:
        summary = dict(normal)
        summary.update({
            "scene": "cattaneo", "q_ratio": self.q_ratio, "mu": self.law.mu,
            "enforcement": self.enforcement, "eps": tangential["eps"],
            "stick_half_width": tangential["stick_half_width"],
            "cattaneo_stick_half_width": tangential["cattaneo_stick_half_width"],
            "traction_error_l2": tangential["traction_error_l2"],
            "increments": tangential["increments"],
            "newton_iterations": normal["newton_iterations"] + tangential["newton_iterations"],
            "wall_time_s": time.perf_counter() - t0})
        summary["parameters"] = {**normal["parameters"], "mu": self.law.mu, "eps": self.law.eps,
                                 "increments": self.increments,
                                 "enforcement": self.enforcement, "penalty_T": self.penalty_T}
        return summary

    def run(self, comm: MPI.Comm = MPI.COMM_WORLD, model: TwoBodyModel | None = None,
            on_increment: typing.Callable[[dict], None] | None = None
            ) -> tuple[dict, TwoBodyModel]:
        """Normal load, then Q in increments; the summary adds ``q_ratio``,
        ``stick_half_width`` (and Cattaneo's), the traction error and one row per
        increment."""
        t0 = time.perf_counter()
        normal, model = self.load_normal(comm, model)
        tangential = self.load_tangential(model, on_increment=on_increment)
        return self._summary(normal, tangential, t0), model

    def run_sequence(self, eps_values: typing.Sequence[float], comm: MPI.Comm = MPI.COMM_WORLD,
                     model: TwoBodyModel | None = None,
                     on_increment: typing.Callable[[dict], None] | None = None
                     ) -> tuple[dict, TwoBodyModel]:
        """Kalker's sequential process: the tangential loading for each ε of ``eps_values``
        in turn, each from the same normally loaded state (the normal solve is done once; the
        friction law's history is the loading path, so each ε reruns the whole path, Newton
        starting every increment from the last increment of the same ε).

        The summary is :meth:`run`'s for the last ε, with ``eps_sequence``: one entry per ε
        (see :meth:`load_tangential`). ``on_increment`` receives each row with its ``eps``.
        """
        check("eps_sequence", list(eps_values), len(eps_values) >= 1, "at least one value")
        for eps in eps_values:
            check("eps_sequence", list(eps_values), eps > 0, "every ε must be > 0")
        t0 = time.perf_counter()
        normal, model = self.load_normal(comm, model)
        loaded = model.u.x.array.copy()
        # the perturbed Lagrangian's history: the tangential multipliers of the loaded state
        multipliers = [c.traction_old.x.array.copy() for c in model.contacts] \
            if self.enforcement == "perturbed-lagrangian" else None
        sequence = []
        for eps in eps_values:
            model.u.x.array[:] = loaded
            if multipliers is not None:
                for contact, values in zip(model.contacts, multipliers, strict=True):
                    contact.traction_old.x.array[:] = values
            model.shear.value = np.zeros(2)
            callback = None if on_increment is None else (
                lambda row, eps=eps: on_increment({"eps": eps, **row}))
            sequence.append(self.load_tangential(model, eps, on_increment=callback))
        summary = self._summary(normal, sequence[-1], t0)
        summary["newton_iterations"] = normal["newton_iterations"] + sum(
            s["newton_iterations"] for s in sequence)
        summary["eps_sequence"] = sequence
        return summary, model


def surface_comparison(scene: Hertz, values: SurfaceValues
                       ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The slave surface's nodal values beside the closed forms of a Hertz or Cattaneo scene.

    Args:
        scene: the scene solved (its :meth:`Hertz.closed_form` gives a and p0).
        values: the slave surface's values (:meth:`TwoBodyModel.surface_values`).

    Returns:
        (r, columns): the distance of each node from the axis (x in 2D, √(x² + y²) in 3D) and
        the columns of ``surface.csv``: the pressure beside Hertz's, the gap, the tangential
        traction on the block (along Q) and, for Cattaneo, Cattaneo-Mindlin's traction.
    """
    a, p0 = scene.closed_form()
    dim = values.x.shape[1]
    r = values.x[:, 0] if dim == 2 else np.linalg.norm(values.x[:, :2], axis=1)
    # the tangential traction on the block (the slave's, body 1's, reversed): along Q
    on_block = -values.traction + 0.0
    columns = {"pressure": values.pressure, "hertz_pressure": closed_forms.hertz_pressure(r, a, p0),
               "gap": values.gap}
    if dim == 2:
        columns["traction"] = on_block[:, 0]
    else:
        columns = {"r": r, **columns, "traction_x": on_block[:, 0], "traction_y": on_block[:, 1]}
    if isinstance(scene, Cattaneo):
        columns["cattaneo_traction"] = closed_forms.cattaneo_traction(r, a, p0, scene.law.mu,
                                                                      scene.q_ratio)
    return r, columns
