r"""What is read off a built block: resultants, energies, powers, contact states, the motion of
the centre of mass and the values at a contact node, as typed records.

Every traction is the one of :mod:`fenicsfriction.laws`
(:func:`~fenicsfriction.laws.normal_traction`, :func:`~fenicsfriction.laws.friction_traction`)
that the residual integrates, evaluated in UFL for the integrals and in NumPy at a node for
:func:`probe`. Integrals over :math:`\Gamma_C` use the
contact measure of the residual (same quadrature), times the plane-strain breadth in 2D.
"""

from __future__ import annotations

import dataclasses
import typing

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem

from fenicsfriction import _compat, laws
from fenicsfriction.forms import elasticity, friction, normal_damping, normal_part
from fenicsfriction.results import Record
from fenicsfriction.scenes.block.data import TOP

if typing.TYPE_CHECKING:
    from fenicsfriction.scenes.block.model import BlockModel

__all__ = ["BlockQuantities", "CentreOfMass", "ContactStates", "Energies", "Powers",
           "ProbeValues", "centre_of_mass", "contact_states", "dynamics_observer", "energies",
           "powers", "probe", "quantities"]


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
        friction: x-traction of the belt on the body, -c_T(|slip|) d^{m_T} φ'_ε(slip).
    """

    x: float
    u_y: float
    v_x: float
    v_y: float
    slip: float
    pressure: float
    friction: float


def _integral(model: BlockModel, key: str, integrand: typing.Callable[[], typing.Any]) -> float:
    """∫_Γc integrand() ds (times the thickness), compiled at the first call only."""
    cache = model._functionals
    if key not in cache:
        cache[key] = _compat.form(model.thickness * integrand() * model.ds_contact)
    value = fem.assemble_scalar(cache[key])
    return model.msh.comm.allreduce(value, op=MPI.SUM)


def energies(model: BlockModel) -> Energies:
    """Kinetic, strain, interface, spring and load-potential energies of the current state.

    The load potential is -∫ b·u (weight) - ∫ t·u (top pressure).
    """
    s, R = model.scene, model.residual
    u, u_dot = R.u, R.u_dot
    if "energy" not in model._functionals:
        d = model.penetration()
        ds = ufl.Measure("ds", domain=model.msh, subdomain_data=model.facet_tags)
        forms = {"kinetic": 0.5 * model.rho * ufl.inner(u_dot, u_dot) * model.dx,
                 "strain": 0.5 * elasticity(u, u, s.E, s.nu, model.dx),
                 "interface": model.c_n * d ** (model.m_n + 1) / (model.m_n + 1)
                 * model.ds_contact,
                 "load": -ufl.inner(model.gravity, u) * model.dx
                 - ufl.inner(model.top_traction, u) * ds(TOP)}
        model._functionals["energy"] = {k: _compat.form(model.thickness * f)
                                        for k, f in forms.items()}
    comm = model.msh.comm
    values = {k: comm.allreduce(fem.assemble_scalar(f), op=MPI.SUM)
              for k, f in model._functionals["energy"].items()}
    force = model.spring.force(u)
    values["spring"] = 0.5 * force**2 / model.spring.stiffness
    values["total"] = sum(values.values())
    return Energies(**values)


def powers(model: BlockModel) -> Powers:
    """Power of the friction and normal-damping tractions on the body: the residual's own
    terms (:func:`~fenicsfriction.forms.friction`, :func:`~fenicsfriction.forms.normal_damping`)
    with the velocity u̇ as test function, sign reversed."""
    if "power" not in model._functionals:
        R, n, law = model.residual, model.normal, model.scene.law
        forms = {"friction": -friction(R.u, R.u_dot, R.u_dot, n, model.friction_c_T,
                                       model.m_T, model.gap, model.belt_velocity, model.eps,
                                       model.ds_contact, law.regularisation)
                 if model.with_friction else None,
                 "damping": -normal_damping(R.u, R.u_dot, R.u_dot, n, law.b_n, law.l_n,
                                            model.gap, model.ds_contact)
                 if law.b_n > 0 else None}
        model._functionals["power"] = {k: _compat.form(model.thickness * f)
                                       for k, f in forms.items() if f is not None}
    comm = model.msh.comm
    values = {"friction": 0.0, "damping": 0.0}
    values.update({k: comm.allreduce(fem.assemble_scalar(f), op=MPI.SUM)
                   for k, f in model._functionals["power"].items()})
    return Powers(**values)


def contact_states(model: BlockModel) -> ContactStates:
    """Counts of open, sticking and slipping contact nodes (see :class:`ContactStates`)."""
    y = model._contact_y
    d = np.maximum(-model.residual.u.x.array[y] - model.scene.g, 0.0)
    slip = np.abs(model.residual.u_dot.x.array[y - 1] - model.scene.belt_direction
                  * model.scene.belt_speed)
    closed = d > 0
    stick = closed & (slip < float(model.eps.value))
    counts = np.array([np.sum(~closed), np.sum(stick), np.sum(closed & ~stick)])
    n_open, n_stick, n_slip = model.msh.comm.allreduce(counts, op=MPI.SUM)
    return ContactStates(n_open=int(n_open), n_stick=int(n_stick), n_slip=int(n_slip))


def centre_of_mass(model: BlockModel) -> CentreOfMass:
    """Motion of the centre of mass and mean rotation (see :class:`CentreOfMass`)."""
    if "centre" not in model._functionals:
        R, dx = model.residual, model.dx
        forms = [f * dx for f in (*R.u, *R.u_dot)]
        curl = 0.5 * (R.u[1].dx(0) - R.u[0].dx(1))
        model._functionals["centre"] = [_compat.form(f) for f in (
            *forms, curl * dx, fem.Constant(model.msh, 1.0) * dx)]
    comm = model.msh.comm
    values = np.array([comm.allreduce(fem.assemble_scalar(f), op=MPI.SUM)
                       for f in model._functionals["centre"]])
    mean = values[:-1] / values[-1]
    dim = model.scene.dim
    return CentreOfMass(u_G=mean[:dim], v_G=mean[dim:2 * dim], theta=float(mean[-1]))


def _nodal_c_T(model: BlockModel) -> typing.Any:
    """c_T of the friction term as a NumPy value or a NumPy function of the slip speed."""
    law, s = model.scene.law, model.scene
    if not model.with_friction:
        return 0.0
    if s.friction_coefficient is not None:
        coefficient = s.friction_coefficient
        return lambda speed: law.c_n * coefficient(speed)
    return float(model.mu.value) * law.c_n


def probe(model: BlockModel, x: float) -> ProbeValues:
    """Nodal values at the contact node nearest to abscissa ``x`` (same on every rank).

    The tractions are those of :mod:`fenicsfriction.laws` at the node's penetration and slip,
    with the model's friction coefficient (velocity-dependent μ(|slip|) included).
    """
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
    _, owner, dof, node_x = cache["probe"]
    s, law, comm = model.scene, model.scene.law, model.msh.comm
    values = None
    if comm.rank == owner:
        u, v = model.residual.u.x.array, model.residual.u_dot.x.array
        d = max(-u[dof] - s.g, 0.0)
        slip = v[dof - 1] - s.belt_direction * s.belt_speed
        rate = -v[dof] if d > 0 else 0.0
        pressure = laws.normal_traction(d, law.c_n, law.m_n, rate, law.b_n, law.l_n)
        traction = laws.friction_traction(d, np.array([slip]), _nodal_c_T(model), law.m_T,
                                          float(model.eps.value), s.regularisation)[0]
        values = ProbeValues(x=node_x, u_y=float(u[dof]), v_x=float(v[dof - 1]),
                             v_y=float(v[dof]), slip=float(slip), pressure=float(pressure),
                             friction=float(traction))
    return comm.bcast(values, root=owner)


def quantities(model: BlockModel) -> BlockQuantities:
    """Resultants and penetration extremes of the current state (see :class:`BlockQuantities`)."""
    elastic = _integral(model, "normal", model.pressure)
    normal = elastic
    law = model.scene.law
    if law.b_n > 0:  # the damping part of the normal traction (zero at rest)
        normal += _integral(model, "damping", lambda: laws.normal_damping_pressure(
            model.penetration(), normal_part(model.residual.u_dot, model.normal), law.b_n,
            law.l_n))
    moment = _integral(model, "moment", lambda: (ufl.SpatialCoordinate(model.msh)[0]
                                                 - model.scene.L / 2) * model.pressure())
    friction_force = _integral(model, "friction", lambda: model.friction_traction()[0]) \
        if model.with_friction else 0.0
    uy = model.residual.u.x.array[model._contact_y]
    d = np.maximum(-uy - model.scene.g, 0.0)
    comm = model.msh.comm
    return BlockQuantities(
        mu=float(model.mu.value), normal_force=normal, normal_force_elastic=elastic,
        friction_force=friction_force, spring_force=model.spring.force(model.residual.u),
        centre_of_pressure=moment / elastic if elastic > 0 else float("nan"),
        min_penetration=comm.allreduce(d.min() if d.size else np.inf, op=MPI.MIN),
        max_penetration=comm.allreduce(d.max() if d.size else -np.inf, op=MPI.MAX))


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

    Args:
        model: the built block.
        probe_x: abscissa of the probe node [cm] (None: L/2).

    Returns:
        ``observe(t) -> dict``.
    """
    x = model.scene.L / 2 if probe_x is None else probe_x
    energy0 = energies(model).total
    last: dict[str, float] = {}

    def observe(t: float) -> dict[str, typing.Any]:
        q, power, energy = quantities(model), powers(model), energies(model)
        centre, node = centre_of_mass(model), probe(model, x)
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
                **dataclasses.asdict(contact_states(model)),
                **{f"probe_{k}": v for k, v in dataclasses.asdict(node).items()},
                "kinetic_energy": energy.kinetic, "friction_power": power.friction,
                "damping_power": power.damping,
                "energy_error": energy.total - energy0 - work}

    return observe
