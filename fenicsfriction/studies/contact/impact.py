r"""Dynamics between two bodies: the cylinder pressed onto the block, then dragged.

The 2D Hertz geometry with inertia: a load P (per unit length) switched on at t = 0 on the
cylinder's flat top pushes it from rest into the block, about whose static Hertz state it then
oscillates (a suddenly applied load: the approach overshoots to about twice the static one).
From ``drag_start`` a tangential traction Q = ``q_ratio`` μP pulls the top: above μP the
cylinder slides, and when the traction is released (``drag_end``) the contact passes from
slide to stick, where the regularised friction's slope is steepest (Pop's remark: the
step is cut back until Newton converges, PETSc TS's rejection of a failed step).

The energy balance closes the run: kinetic + elastic + stored in the compliance − work of the
loads + dissipated by the interface = its initial value. The default scheme (``"energy"``)
makes it close to Newton's tolerance whatever ε and dt: the midpoint rule (generalized-α at
ρ∞ = 1, which conserves kinetic + elastic energy of linear elasticity), the contact's elastic
pressure the discrete gradient of its potential between the step's ends (Gonzalez 1996;
Laursen & Chawla 1997; Armero & Petőcz 1998) and the friction at the midpoint slip rate, whose
work over the step is exactly the dissipation recorded (Armero & Petőcz 1999). Generalized-α
(``"alpha2"``, ρ∞ = ``rho_infinity``) and central differences (``"central"``) balance it to
their accuracy only; with a narrow ε the stick dashpots make generalized-α drift by O(1)
(docs/contact.md).
"""

from __future__ import annotations

import dataclasses
import time
import typing
import warnings

from mpi4py import MPI
from petsc4py import PETSc

import numpy as np
import ufl

from fenicsfriction import _compat, laws
from fenicsfriction.dynamics import CentralDifference, DynamicsError, DynamicsSolver
from fenicsfriction.elasticity import lame
from fenicsfriction.laws import check
from fenicsfriction.studies.contact import closed_forms, geometry
from fenicsfriction.studies.contact.geometry import LOAD
from fenicsfriction.studies.contact.model import TwoBodyModel
from fenicsfriction.studies.contact.validation import _Bodies

__all__ = ["PressAndDrag", "summarise"]

#: ``"energy"``: the energy-consistent midpoint rule (:class:`DynamicsSolver` with
#: ``energy_consistent``); ``"alpha2"``: generalized-α at ``rho_infinity``; ``"central"``:
#: explicit central differences
SCHEMES = ("energy", "alpha2", "central")

#: steps a contact period (:meth:`PressAndDrag.contact_period`) for the default step
STEPS_PER_PERIOD = 8


@dataclasses.dataclass
class PressAndDrag(_Bodies):
    """The cylinder of radius ``radius`` pressed on the block and dragged.

    Args:
        load: P [force/length]; ``None``: the load of a Hertz half-width R/10.
        radius: R [length].
        density: both bodies' mass density [mass/length³].
        law: the interface law: compliance c_n d^m_n, normal damping b_n, friction
            coefficient ``mu`` (0: frictionless, no drag) and the regularisation ``eps`` of the
            slip rate [length/time]; default c_n = 1e3, m_n = 1, μ = 0.3, ε = 1e-3, b_n = 0.
            Against the contact's speeds (~1e-3 at the drag) a narrow ε makes the stick
            dashpots (c_T d/ε per node) far stiffer than 1/dt²: Newton fails at some stick
            transitions and the step is cut back. The drag is ``q_ratio`` times the law's
            constant ``mu``.
        q_ratio: the drag Q/(μP) between ``drag_start`` and ``drag_end``.
        drag_start, drag_end, t_end: times [time].
        h_contact: the mesh size at the contact [length].
        rho_infinity: generalized-α's spectral radius at infinite frequency (scheme
            ``"alpha2"``; below 1 it damps the ringing of the stiff stick dashpots, which the
            midpoint rule carries undamped: a sticking node's end-of-step velocity flips sign
            from step to step, at no cost in energy).
    """

    load: float | None = None
    radius: float = 1.0
    density: float = 1.0
    law: laws.InterfaceLaw = dataclasses.field(
        default_factory=lambda: laws.InterfaceLaw(c_n=1e3, m_n=1.0, mu=0.3, eps=1e-3))
    q_ratio: float = 1.5
    drag_start: float = 1.5
    drag_end: float = 2.5
    t_end: float = 3.0
    h_contact: float = 0.05
    rho_infinity: float = 0.8

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.load is None:
            self.load = closed_forms.hertz_load(self.radius / 10, self.radius, self.E_star)
        check("load", self.load, self.load > 0, "the load must be > 0")
        check("density", self.density, self.density > 0, "must be > 0")
        check("drag_start", self.drag_start, 0 <= self.drag_start <= self.drag_end,
              "0 <= drag_start <= drag_end")
        check("t_end", self.t_end, self.t_end > 0, "must be > 0")

    def build(self, comm: MPI.Comm = MPI.COMM_WORLD, scheme: str = "energy") -> TwoBodyModel:
        """The model the scheme integrates (``"energy"``: with the contacts' start of step)."""
        mesh = geometry.hertz_2d(comm, R=self.radius, h_contact=self.h_contact)
        return self.model(mesh, density=self.density, energy_consistent=scheme == "energy")

    def contact_period(self, model: TwoBodyModel) -> float:
        """2π/ω of the contact springs, ω² the bound of
        :meth:`~fenicsfriction.contact.NodeToSegment.frequency_bound` on the row-sum lumped
        mass (every slave node's spring c_n A_i between the lightest surface nodes; linear
        compliance): the shortest period the contact can ring with."""
        import dolfinx.fem.petsc
        v = ufl.TestFunction(model.V)
        ones = ufl.as_vector([1.0] * model.dim)
        lumped = dolfinx.fem.petsc.assemble_vector(
            _compat.form(self.density * ufl.inner(ones, v) * model.dx))
        lumped.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        omega2 = sum(c.frequency_bound(lumped) for c in model.contacts)
        lumped.destroy()
        return float(2 * np.pi / np.sqrt(omega2))

    def default_dt(self, model: TwoBodyModel) -> float:
        """The step that resolves the contact period: :data:`STEPS_PER_PERIOD` steps a
        :meth:`contact_period`, rounded down to a divisor of t_end."""
        dt = self.contact_period(model) / STEPS_PER_PERIOD
        return float(self.t_end / np.ceil(self.t_end / dt))

    def unresolved(self, model: TwoBodyModel, dt: float) -> str | None:
        """The one-line warning that ``dt`` does not resolve the contact period (more than
        1/:data:`STEPS_PER_PERIOD` of it), or None. With the energy-consistent scheme the
        balance still closes; what an unresolved step loses is the phase of the ringing of the
        contact nodes (the midpoint rule lengthens a period T by (ωΔt/2)/atan(ωΔt/2))."""
        period = self.contact_period(model)
        if dt <= period / STEPS_PER_PERIOD * (1 + 1e-9):
            return None
        return (f"dt = {dt:g} does not resolve the contact springs' period {period:.3g} "
                f"(at most {period / STEPS_PER_PERIOD:.3g}: {STEPS_PER_PERIOD} steps a period)")

    def traction(self, t: float) -> np.ndarray:
        """The traction on the cylinder's top at time t: −P/(2R) normal, the drag between
        ``drag_start`` and ``drag_end``."""
        assert self.load is not None
        p = self.load / (2 * self.radius)
        drag = self.q_ratio * self.law.mu * p if self.drag_start <= t < self.drag_end else 0.0
        return np.array([drag, -p])

    def run(self, scheme: str = "energy", dt: float | None = None,
            comm: MPI.Comm = MPI.COMM_WORLD, model: TwoBodyModel | None = None,
            on_step: typing.Callable[[dict], None] | None = None) -> tuple[list[dict], dict]:
        """Integrate; returns one record per step (time, energies, penetration) and a summary
        (``energy_balance_error``: the largest drift of the balance over the largest work of
        the loads; the largest penetration, cut-backs, Newton iterations, wall time;
        ``failure``: None, or why the integration stopped at ``t_reached``, the records then
        those of the steps done).

        ``dt=None``: :meth:`default_dt` (implicit schemes); a step that does not resolve the
        contact springs' period is warned about in one line (:meth:`contact_period`)."""
        check("scheme", scheme, scheme in SCHEMES, f"one of {', '.join(SCHEMES)}")
        model = model or self.build(comm, scheme)
        check("model", "TwoBodyModel", (scheme == "energy") == hasattr(model, "u_start"),
              "built for the scheme (PressAndDrag.build(comm, scheme))")
        assert self.load is not None
        energy = _EnergyBalance(model)
        if scheme != "central":
            if dt is None:
                dt = self.default_dt(model)
            elif (unresolved := self.unresolved(model, dt)) is not None:
                warnings.warn(unresolved, stacklevel=2)
        if scheme in ("energy", "alpha2"):
            # the midpoint step's Newton crosses the steep stick band in up to ~20 iterations
            # rather than cycling: with 25 allowed instead of 10, ε = 1e-5 and dt = 0.05 take
            # 0 cut-backs and 237 iterations instead of 43 and 935 (h = 0.05)
            solver: typing.Any = DynamicsSolver(
                model.residual, prefix="press_", atol=1e-10 * self.load,
                options={"ts_alpha_radius": self.rho_infinity,
                         **({"snes_max_it": 25} if scheme == "energy" else {})},
                energy_consistent=scheme == "energy")
        else:
            solver = CentralDifference(model.residual)
            dt = self.t_end if dt is None else dt  # capped at the stable step

        def observe(t: float) -> dict:
            record = energy.record(t)  # with the load of the step that ends at t
            model.shear.value = self.traction(t)  # the load of the next step
            return record

        # the drag switches within a step: set the load of the first step before it starts
        model.shear.value = self.traction(0.0)
        failure = None
        clock = time.perf_counter()
        try:
            records = solver.run(self.t_end, dt, observe=observe, on_step=on_step)
        except DynamicsError as err:  # the fields hold the last accepted state
            records, failure = err.records, str(err)
        summary = {"scheme": scheme, "dt": dt, "dofs": model.dofs, **summarise(records),
                   "wall_time_s": time.perf_counter() - clock,
                   "stable_dt": getattr(solver, "stable_dt", None), "failure": failure}
        return records, summary


def summarise(records: typing.Sequence[dict]) -> dict:
    """What :meth:`PressAndDrag.run` reports of its records (also of an interrupted run's):
    ``energy_balance_error``, the largest drift of the balance over the largest work of the
    loads (None before any work), the work, the dissipated energy, the largest penetration,
    the steps, cut-backs and Newton iterations, the time reached."""
    balance = np.array([r["balance"] for r in records])
    work = max((abs(r["work"]) for r in records[1:]), default=0.0)
    last = records[-1] if records else {}
    return {
        "steps": max(len(records) - 1, 0), "t_reached": float(last.get("time", 0.0)),
        "energy_balance_error": (float(np.max(np.abs(balance - balance[0])) / work)
                                 if work > 0 else None),
        "work": float(last.get("work", 0.0)), "dissipated": float(last.get("dissipated", 0.0)),
        "max_penetration": float(max((r["max_penetration"] for r in records), default=0.0)),
        "rejected_steps": int(sum(r["rejected_steps"] for r in records)),
        "newton_iterations": int(sum(r["newton_iterations"] for r in records)),
    }


class _EnergyBalance:
    r"""Energies of the two bodies and the work and dissipation summed over the steps.

    The work of the (stepwise constant) load over a step is exact, :math:`t\cdot(u_{n+1} -
    u_n)`. The dissipation of a step: with the energy-consistent scheme its own,
    :math:`\Delta t\, D(u_{n+1/2}, (u_{n+1} - u_n)/\Delta t)` at the state the step's
    contact force was evaluated at (so the discrete balance closes to Newton's tolerance);
    otherwise the trapezoidal rule on the end-of-step powers.
    """

    def __init__(self, model: TwoBodyModel):
        from dolfinx import fem
        self.model = model
        u, u_dot = model.u, model.residual.u_dot
        dx = model.dx
        assert model.density is not None, "a dynamic model"
        eps = ufl.sym(ufl.grad(u))
        forms = {"kinetic": 0.5 * model.density * ufl.inner(u_dot, u_dot) * dx}
        elastic = 0.0
        for tag, material in zip((1, 2), model.materials, strict=True):
            lmbda, mu = lame(material.E, material.nu)
            elastic = elastic + (mu * ufl.inner(eps, eps) + 0.5 * lmbda * ufl.tr(eps) ** 2) \
                * dx(tag)
        forms["elastic"] = elastic
        self.u_previous = fem.Function(u.function_space)
        forms["work"] = ufl.inner(model.shear, u - self.u_previous) * model.ds(LOAD)
        self.forms = {k: _compat.form(f) for k, f in forms.items()}
        self.contact = [(_compat.form(c.potential),
                         _compat.form(c.dissipation) if c.relative_velocity is not None
                         else None) for c in model.contacts]
        self.start: fem.Function | None = getattr(model, "u_start", None)
        self.last: tuple[float, float] | None = None  # t, dissipated power
        self.work = 0.0
        self.dissipated = 0.0

    def _scalar(self, form: typing.Any) -> float:
        from dolfinx import fem
        return self.model.comm.allreduce(fem.assemble_scalar(form))

    def _dissipation(self) -> float:
        return sum(self._scalar(d) for _, d in self.contact if d is not None)

    def _step_dissipation(self, dt: float) -> float:
        """Δt D at the step's midpoint state (the fields put back afterwards)."""
        assert self.start is not None
        model = self.model
        u, u_dot = model.u, model.residual.u_dot
        end, velocity = u.x.array.copy(), u_dot.x.array.copy()
        u.x.array[:] = 0.5 * (end + self.u_previous.x.array)
        u_dot.x.array[:] = (end - self.u_previous.x.array) / dt
        self.start.x.array[:] = self.u_previous.x.array
        for contact in model.contacts:
            contact.update(search=False)
        dissipated = dt * self._dissipation()
        u.x.array[:], u_dot.x.array[:] = end, velocity
        self.start.x.array[:] = end  # the contact's pressure at u_{n+1} until the next step
        for contact in model.contacts:
            contact.update(search=False)
        return dissipated

    def record(self, t: float) -> dict:
        for contact in self.model.contacts:  # the pairing the step was solved with
            contact.update(search=not contact.searched)
        values = {k: self._scalar(f) for k, f in self.forms.items()}
        stored = sum(self._scalar(p) for p, _ in self.contact)
        power = 0.0 if self.start is not None else self._dissipation()
        if self.last is not None:
            t0, power0 = self.last
            self.work += values["work"]
            self.dissipated += (self._step_dissipation(t - t0) if self.start is not None
                                else 0.5 * (t - t0) * (power0 + power))
        self.last = (t, power)
        self.u_previous.x.array[:] = self.model.u.x.array
        penetration = self.model.comm.allreduce(
            -min(0.0, float(self.model.nodal_gap().min(initial=0.0))), op=MPI.MAX)
        total = values["kinetic"] + values["elastic"] + stored
        return {"kinetic": values["kinetic"], "elastic": values["elastic"],
                "contact_energy": stored, "work": self.work, "dissipated": self.dissipated,
                "balance": total - self.work + self.dissipated,
                "max_penetration": penetration}
