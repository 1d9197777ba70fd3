r"""What is read off a built block: resultants, energies, powers, contact states, the motion of
the centre of mass and the values at a contact node, as typed records.

Every traction is the one of :mod:`fenicsfriction.laws`
(:func:`~fenicsfriction.laws.normal_traction`, :func:`~fenicsfriction.laws.friction_traction`)
that the residual integrates, evaluated in UFL for the integrals and in NumPy at a node for
:func:`probe`. Integrals over :math:`\Gamma_C` use the
contact measure of the residual (same quadrature), times the plane-strain breadth in 2D.

The integrals of a record are assembled together, in one pass over the mesh and one reduction
over the ranks (:class:`Functionals`): a time step's observation costs one vector assembly,
not eighteen scalar ones.
"""

from __future__ import annotations

import dataclasses
import typing

from mpi4py import MPI

import dolfinx.fem.petsc
import numpy as np
import ufl
from dolfinx import fem

from fenicsfriction import _compat, laws
from fenicsfriction.assembly import assemble_into
from fenicsfriction.results import Record
from fenicsfriction.studies.block.data import TOP

if typing.TYPE_CHECKING:
    from fenicsfriction.studies.block.model import BlockModel

__all__ = ["BlockQuantities", "CentreOfMass", "ContactStates", "Energies", "Functionals",
           "Powers", "ProbeValues", "centre_of_mass", "contact_states", "dynamics_observer",
           "energies", "powers", "probe", "quantities"]


@dataclasses.dataclass
class BlockQuantities(Record):
    """Resultants and penetration extremes of a state (same on every rank).

    Attributes:
        mu: the friction coefficient μ of the model's constant [-].
        normal_force: total normal contact force on the body (upwards > 0), normal damping
            included [force].
        normal_force_elastic: its elastic part ∫ c_n d^{m_n}, which bounds the friction force
            (|F| <= μ N_elastic) and locates ``centre_of_pressure`` [force].
        friction_force: x-component of the friction force on the body [force].
        spring_force: x-component of the driver spring's force on the body [force].
        centre_of_pressure: x of the elastic normal resultant minus L/2 [cm] (NaN out of contact).
        min_penetration, max_penetration: extremes of d over the contact nodes [cm].
    """

    mu: float
    normal_force: float
    normal_force_elastic: float
    friction_force: float
    spring_force: float
    centre_of_pressure: float
    min_penetration: float
    max_penetration: float


@dataclasses.dataclass
class Energies(Record):
    """Energies of a state [force × cm]: ``kinetic``, ``strain``, ``interface`` (∫ c_n
    d^{m_n+1}/(m_n+1)), ``load`` (potential of weight and top pressure), ``spring`` and their
    sum ``total`` (conserved by the dynamics without friction and damping)."""

    kinetic: float
    strain: float
    interface: float
    load: float
    spring: float
    total: float


@dataclasses.dataclass
class Powers(Record):
    """Power of the interface forces on the body [force × cm/s]: ``friction`` ∫ t_T · u̇ (the
    moving belt can put energy in) and ``damping`` -∫ b_n d^{l_n} u̇_n² (<= 0)."""

    friction: float
    damping: float


@dataclasses.dataclass
class ContactStates(Record):
    """Counts of contact nodes: open (d = 0), sticking (|u̇_T - U_T| < ε, the regularisation
    band) and slipping, over the whole mesh."""

    n_open: int
    n_stick: int
    n_slip: int


@dataclasses.dataclass
class CentreOfMass(Record):
    """Displacement ``u_G`` and velocity ``v_G`` of the centre of mass (means over the body,
    uniform density) and the mean rotation ``theta`` = ∫ ½ curl u / area [rad]."""

    u_G: np.ndarray
    v_G: np.ndarray
    theta: float


@dataclasses.dataclass
class ProbeValues(Record):
    """Values at one contact node.

    Attributes:
        x: abscissa of the node [cm].
        u_y, v_x, v_y: its displacement and velocity [cm, cm/s].
        slip: v_x - U_T [cm/s].
        pressure: normal traction c_n d^{m_n} + b_n d^{l_n} ḋ [force / cm²].
        friction: x-traction of the belt on the body, -c_T(|slip|, p) d^{m_T} φ'_ε(slip).
    """

    x: float
    u_y: float
    v_x: float
    v_y: float
    slip: float
    pressure: float
    friction: float


class Functionals:
    r"""Several scalar integrals :math:`\int f_i`, assembled in one pass.

    The integrals become one linear form :math:`\sum_i \int f_i\, q_i` with :math:`q` a test
    function of the cellwise constant vectors with one entry per integral: its vector holds
    each integral's share on each cell, and the sum over the (owned) cells of entry i is
    :math:`\int f_i`. Every integral keeps its own measure and quadrature, so the values are
    those of ``fem.assemble_scalar`` on each form up to the order of summation.

    Args:
        msh: the mesh of the integrands.
        forms: scalar forms by name (functionals: no arguments).
    """

    def __init__(self, msh: typing.Any, forms: dict[str, ufl.Form]):
        self.names = list(forms)
        q = ufl.TestFunction(_compat.dg0_vector_space(msh, len(forms)))
        integrals = [integral.reconstruct(integrand=integral.integrand() * q[i])
                     for i, form in enumerate(forms.values()) for integral in form.integrals()]
        self.form = _compat.form(ufl.Form(integrals))
        self.vector = dolfinx.fem.petsc.create_vector(self.form)
        self.comm = msh.comm

    def local(self) -> np.ndarray:
        """This rank's share of each integral, in the order of ``names`` (no communication)."""
        owned = assemble_into(self.vector, self.form).array_r
        return owned.reshape(-1, len(self.names)).sum(axis=0)

    def values(self) -> dict[str, float]:
        """The integrals by name (same on every rank)."""
        totals = self.local()
        self.comm.Allreduce(MPI.IN_PLACE, totals, op=MPI.SUM)
        return {name: float(v) for name, v in zip(self.names, totals, strict=True)}


def _contact(model: BlockModel, integrand: typing.Any) -> ufl.Form:
    """∫_Γc integrand ds (times the thickness), with the residual's contact quadrature."""
    return model.thickness * integrand * model.ds_contact


def _quantity_forms(model: BlockModel) -> dict[str, ufl.Form]:
    """The integrals of :func:`quantities`: normal force (elastic part and damping), its moment
    about mid-base, the friction force."""
    forms = {"normal_elastic": _contact(model, model.pressure())}
    law = model.scene.law
    if law.b_n > 0:  # the damping part of the normal traction (zero at rest)
        forms["normal_damping"] = _contact(model, model.damping_pressure())
    forms["moment"] = _contact(model, (ufl.SpatialCoordinate(model.msh)[0]
                                       - model.scene.L / 2) * model.pressure())
    if model.with_friction:
        forms["friction"] = _contact(model, model.friction_traction()[0])
    return forms


def _energy_forms(model: BlockModel) -> dict[str, ufl.Form]:
    """Kinetic, strain, interface and load-potential energies (:func:`energies`)."""
    u = model.residual.u
    d = model.penetration()
    ds = ufl.Measure("ds", domain=model.msh, subdomain_data=model.facet_tags)
    forms = {**model.energy_forms(),
             "interface": model.c_n * d ** (model.m_n + 1) / (model.m_n + 1) * model.ds_contact,
             "load": -ufl.inner(model.gravity, u) * model.dx
             - ufl.inner(model.top_traction, u) * ds(TOP)}
    return {k: model.thickness * f for k, f in forms.items()}


def _power_forms(model: BlockModel) -> dict[str, ufl.Form]:
    """Power of friction and normal damping (:func:`powers`): the residual's own terms with the
    velocity as test function, sign reversed."""
    return {k: model.thickness * f for k, f in model.interface_power_forms().items()}


def _centre_forms(model: BlockModel) -> dict[str, ufl.Form]:
    """∫ u_i, ∫ u̇_i, ∫ ½ curl u and the area (:func:`centre_of_mass`)."""
    R, dx, dim = model.residual, model.dx, model.scene.dim
    forms = {f"u{i}": R.u[i] * dx for i in range(dim)}
    forms.update({f"v{i}": R.u_dot[i] * dx for i in range(dim)})
    forms["curl"] = 0.5 * (R.u[1].dx(0) - R.u[0].dx(1)) * dx
    forms["area"] = fem.Constant(model.msh, 1.0) * dx
    return forms


def _evaluate(model: BlockModel, key: str,
              builder: typing.Callable[[BlockModel], dict[str, ufl.Form]]) -> dict[str, float]:
    """The integrals ``builder`` states, compiled at the first call only."""
    cache = model._functionals
    if key not in cache:
        cache[key] = Functionals(model.msh, builder(model))
    return cache[key].values()


def _spring_energy(model: BlockModel, force: float) -> float:
    return 0.5 * force**2 / model.spring.stiffness


def energies(model: BlockModel) -> Energies:
    """Kinetic, strain, interface, spring and load-potential energies of the current state.

    The load potential is -∫ b·u (weight) - ∫ t·u (top pressure).
    """
    values = _evaluate(model, "energy", _energy_forms)
    values["spring"] = _spring_energy(model, model.spring.force(model.residual.u))
    values["total"] = sum(values.values())
    return Energies(**values)


def powers(model: BlockModel) -> Powers:
    """Power of the friction and normal-damping tractions on the body: the residual's own
    terms (:func:`~fenicsfriction.forms.friction`, :func:`~fenicsfriction.forms.normal_damping`)
    with the velocity u̇ as test function, sign reversed."""
    values = {"friction": 0.0, "damping": 0.0}
    if model.with_friction or model.scene.law.b_n > 0:
        values.update(_evaluate(model, "power", _power_forms))
    return Powers(**values)


def _contact_counts(model: BlockModel, nodal: tuple | None = None) -> np.ndarray:
    """This rank's counts of open, sticking and slipping contact nodes."""
    d, slip, _ = model.nodal_contact() if nodal is None else nodal
    slip = np.abs(slip)
    closed = d > 0
    stick = closed & (slip < float(model.eps.value))
    return np.array([np.sum(~closed), np.sum(stick), np.sum(closed & ~stick)], dtype=float)


def contact_states(model: BlockModel) -> ContactStates:
    """Counts of open, sticking and slipping contact nodes (see :class:`ContactStates`)."""
    counts = _contact_counts(model)
    model.msh.comm.Allreduce(MPI.IN_PLACE, counts, op=MPI.SUM)
    n_open, n_stick, n_slip = counts
    return ContactStates(n_open=int(n_open), n_stick=int(n_stick), n_slip=int(n_slip))


def _centre(model: BlockModel, values: dict[str, float]) -> CentreOfMass:
    dim = model.scene.dim
    area = values["area"]
    return CentreOfMass(u_G=np.array([values[f"u{i}"] for i in range(dim)]) / area,
                        v_G=np.array([values[f"v{i}"] for i in range(dim)]) / area,
                        theta=values["curl"] / area)


def centre_of_mass(model: BlockModel) -> CentreOfMass:
    """Motion of the centre of mass and mean rotation (see :class:`CentreOfMass`)."""
    return _centre(model, _evaluate(model, "centre", _centre_forms))


def _nodal_law(model: BlockModel) -> laws.InterfaceLaw:
    """The scene's law with the model's current μ and ε, as NumPy numbers (μ = 0 without a
    friction term)."""
    law = model.scene.law.replace(mu=float(model.mu.value), eps=float(model.eps.value))
    if not model.with_friction:
        law = law.replace(mu=0.0, friction_coefficient=None, slip_rule=None)
    return law


def _probe_node(model: BlockModel, x: float) -> tuple[int, int, float]:
    """(owning rank, local y-dof, abscissa) of the contact node nearest to ``x`` (cached)."""
    cache = model._functionals
    if "probe" not in cache or cache["probe"][0] != x:
        coords = model.V.tabulate_dof_coordinates()
        y = model._contact_y
        nodes = y // model.scene.dim
        distance = np.abs(coords[nodes, 0] - x) if y.size else np.array([np.inf])
        best = int(np.argmin(distance))
        comm = model.msh.comm
        _, owner = comm.allreduce((float(distance[best]), comm.rank), op=MPI.MINLOC)
        cache["probe"] = (x, owner, int(y[best]) if y.size else -1,
                          float(coords[nodes[best], 0]) if y.size else 0.0)
    return cache["probe"][1:]


def _probe_values(model: BlockModel, dof: int, node_x: float, law: laws.InterfaceLaw,
                  nodal: tuple) -> ProbeValues:
    """The probe's values, on the rank that owns its node (``nodal``: this rank's
    :meth:`~fenicsfriction.studies.block.model.BlockModel.nodal_contact`)."""
    u, v = model.residual.u.x.array, model.residual.u_dot.x.array
    k = int(np.flatnonzero(model._contact_y == dof)[0])
    d, slip, rate = (float(a[k]) for a in nodal)
    pressure = law.normal_traction(d, rate)
    traction = law.friction_traction(d, np.array([slip]))[0]
    return ProbeValues(x=node_x, u_y=float(u[dof]), v_x=float(v[dof - 1]), v_y=float(v[dof]),
                       slip=float(slip), pressure=float(pressure), friction=float(traction))


def probe(model: BlockModel, x: float) -> ProbeValues:
    """Nodal values at the contact node nearest to abscissa ``x`` (same on every rank).

    The tractions are those of :mod:`fenicsfriction.laws` at the node's penetration and slip,
    with the model's μ and ε (a friction coefficient law μ(|slip|, p) included).
    """
    owner, dof, node_x = _probe_node(model, x)
    comm = model.msh.comm
    nodal = model.nodal_contact()  # collective
    values = (_probe_values(model, dof, node_x, _nodal_law(model), nodal)
              if comm.rank == owner else None)
    return comm.bcast(values, root=owner)


def _penetration_extremes(model: BlockModel, nodal: tuple | None = None) -> np.ndarray:
    """This rank's (max d, -min d) over its contact nodes (-inf, -inf without any)."""
    d = (model.nodal_contact() if nodal is None else nodal)[0]
    return np.array([d.max(), -d.min()]) if d.size else np.full(2, -np.inf)


def _quantities(model: BlockModel, values: dict[str, float], spring_force: float,
                extremes: np.ndarray) -> BlockQuantities:
    elastic = values["normal_elastic"]
    return BlockQuantities(
        mu=float(model.mu.value), normal_force=elastic + values.get("normal_damping", 0.0),
        normal_force_elastic=elastic, friction_force=values.get("friction", 0.0),
        spring_force=spring_force,
        centre_of_pressure=values["moment"] / elastic if elastic > 0 else float("nan"),
        min_penetration=float(-extremes[1]), max_penetration=float(extremes[0]))


def quantities(model: BlockModel) -> BlockQuantities:
    """Resultants and penetration extremes of the current state (see :class:`BlockQuantities`)."""
    extremes = _penetration_extremes(model)
    model.msh.comm.Allreduce(MPI.IN_PLACE, extremes, op=MPI.MAX)
    return _quantities(model, _evaluate(model, "quantities", _quantity_forms),
                       model.spring.force(model.residual.u), extremes)


def _local_spring_force(model: BlockModel) -> float:
    spring = model.spring
    if spring.local_dof < 0:
        return 0.0
    return -spring.stiffness * (model.residual.u.x.array[spring.local_dof] - spring.anchor)


def dynamics_observer(model: BlockModel, probe_x: float | None = None
                      ) -> typing.Callable[[float], dict[str, typing.Any]]:
    """An ``observe(t)`` for the time integrators: one flat table row of the state per step.

    Resultants (:func:`quantities`), centre-of-mass motion (``u_yG``, ``v_yG``, ``v_xG``,
    ``theta``), the spring elongation, contact-state counts, the probe node (:func:`probe`,
    prefix ``probe_``; default: mid-base, node 29 of Martins & Oden 1986) and the energy
    balance: ``energy_error`` = E(t) − E(0) − W(t), with E the kinetic + strain + interface +
    spring + load-potential energies and W the work of the friction and damping stresses
    (trapezoidal rule over the observed steps): zero for the exact solution, its drift measures
    the time error.

    All the integrals of a row are assembled in one pass (:class:`Functionals`) and, with the
    nodal values, reduced over the ranks in two collective calls.

    Args:
        model: the built block.
        probe_x: abscissa of the probe node [cm] (None: L/2).

    Returns:
        ``observe(t) -> dict``.
    """
    x = model.scene.L / 2 if probe_x is None else probe_x
    groups = {"q": _quantity_forms(model), "e": _energy_forms(model),
              "p": _power_forms(model), "c": _centre_forms(model)}
    functionals = Functionals(model.msh, {f"{g}.{k}": f for g, forms in groups.items()
                                          for k, f in forms.items()})
    owner, dof, node_x = _probe_node(model, x)
    comm = model.msh.comm
    probe_fields = [f.name for f in dataclasses.fields(ProbeValues)]
    n_integrals = len(functionals.names)
    last: dict[str, float] = {}

    def state() -> tuple[dict[str, dict[str, float]], float, np.ndarray, ProbeValues,
                         np.ndarray]:
        """Integrals by group, spring force, contact counts, probe, penetration extremes."""
        nodal = model.nodal_contact()  # collective: before the integrals, which use its search
        node = np.zeros(len(probe_fields))
        if comm.rank == owner:
            node[:] = dataclasses.astuple(_probe_values(model, dof, node_x, _nodal_law(model),
                                                        nodal))
        total = np.concatenate([functionals.local(), [_local_spring_force(model)],
                                _contact_counts(model, nodal), node])
        extremes = _penetration_extremes(model, nodal)
        comm.Allreduce(MPI.IN_PLACE, total, op=MPI.SUM)
        comm.Allreduce(MPI.IN_PLACE, extremes, op=MPI.MAX)
        values: dict[str, dict[str, float]] = {g: {} for g in groups}
        for name, v in zip(functionals.names, total[:n_integrals], strict=True):
            group, key = name.split(".", 1)
            values[group][key] = float(v)
        rest = total[n_integrals:]
        return (values, float(rest[0]), rest[1:4],
                ProbeValues(**dict(zip(probe_fields, map(float, rest[4:]), strict=True))),
                extremes)

    def total_energy(values: dict[str, float], spring_force: float) -> float:
        return sum(values.values()) + _spring_energy(model, spring_force)

    values, spring_force, _, _, _ = state()
    energy0 = total_energy(values["e"], spring_force)

    def observe(t: float) -> dict[str, typing.Any]:
        values, spring_force, counts, node, extremes = state()
        q = _quantities(model, values["q"], spring_force, extremes)
        centre = _centre(model, values["c"])
        power = Powers(**{"friction": 0.0, "damping": 0.0, **values["p"]})
        total_power = power.friction + power.damping
        work = last.get("work", 0.0)
        if last:
            work += 0.5 * (total_power + last["power"]) * (t - last["time"])
        last.update(time=t, power=total_power, work=work)
        return {"normal_force": q.normal_force, "normal_force_elastic": q.normal_force_elastic,
                "friction_force": q.friction_force, "spring_force": q.spring_force,
                "centre_of_pressure": q.centre_of_pressure,
                "min_penetration": q.min_penetration, "max_penetration": q.max_penetration,
                "spring_elongation": -q.spring_force / model.scene.K_x,
                "u_yG": float(centre.u_G[1]), "v_yG": float(centre.v_G[1]),
                "v_xG": float(centre.v_G[0]), "theta": centre.theta,
                "n_open": int(counts[0]), "n_stick": int(counts[1]), "n_slip": int(counts[2]),
                **{f"probe_{k}": v for k, v in dataclasses.asdict(node).items()},
                "kinetic_energy": values["e"]["kinetic"], "friction_power": power.friction,
                "damping_power": power.damping,
                "energy_error": total_energy(values["e"], spring_force) - energy0 - work}

    return observe
