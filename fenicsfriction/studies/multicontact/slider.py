r"""An elastic slider on a base of breakable contacts: the onset of sliding as detachment fronts.

The "self-consistent problem" of Braun (slides), "Nonhomogeneous frictional interface": a 2D
elastic slider :math:`[0, L]\times[0, H]` (plane strain, or plane stress) whose base is held by
the earthquake-like (EQ) contacts of Braun, Barel & Urbakh (2009), "Dynamics of transition
from static to kinetic friction", and pushed at its trailing (left) edge; the onset of sliding
is a sequence of detachment fronts, as measured by Rubinstein, Cohen & Fineberg (2004),
"Detachment fronts and the onset of dynamic friction".

The finite element model (:class:`ElasticSliderModel`) is the package's one residual
(:mod:`fenicsfriction.forms`) integrated by :class:`~fenicsfriction.dynamics.DynamicsSolver`
(generalized-α, TSALPHA2):

.. math::
    \int_\Omega \rho\,\ddot u\cdot v + \int_\Omega \sigma(u):\varepsilon(v)
    + \int_{y=0} k\,a_j\,(u_x - U_j)\,v_x
    + \int_{x=0} k_p\,(u_x - V t)\,v_x = 0,

per unit breadth, with :math:`u_y = 0` on the base (a rigid flat base; the EQ contacts act
tangentially only). The base integral uses the nodal (trapezoidal) rule, so each base node j
carries a spring of stiffness :math:`k w_j` (:math:`w_j` its share of the base, h or h/2 at
the corners) to its anchor :math:`U_j`, switched on (:math:`a_j = 1`) or off (0). The pusher
is a stage moving at speed V coupled to the left face by springs of stiffness :math:`k_p` per
unit length.

Modelling choices the papers leave open (Braun, Barel & Urbakh 2009 describe a 1D chain):

* **Breaking is an event between time steps.** After each accepted step every attached
  contact whose stretch :math:`|u_x - U_j|` exceeds its threshold :math:`x_{s,j}` breaks; the
  step in between is a smooth linear problem. The overshoot of the stretch past the threshold
  is at most :math:`|\dot u_x|\,\Delta t`, so the step must be small against
  :math:`x_s/\dot u_x`.
* **Re-attachment.** A broken contact stays off for ``delay`` and then re-forms relaxed: its
  anchor is the node's position at that moment (with ``delay = 0``, at once, at the break):
  the distribution R(x) of new-born stretchings in the slides' master equation is δ(x).
  Each (re-)formed contact draws a new threshold, uniform in
  :math:`\bar x_s\,[1 - \delta, 1 + \delta]`.
* **Reproducible under MPI.** A threshold is a function of (seed, the node's number
  :math:`j = x/h` along the base, how many times it broke), drawn with NumPy's counter-based
  seeding, so it does not depend on how the mesh is partitioned.
* The energy a break dissipates is the spring energy it releases, :math:`\tfrac12 k w_j s^2`.
"""

from __future__ import annotations

import dataclasses
import math
import pathlib
import typing

from mpi4py import MPI

import numpy as np
import ufl
from dolfinx import fem, mesh

from fenicsfriction import _compat
from fenicsfriction.dynamics import DynamicsSolver
from fenicsfriction.forms import Residual, elasticity, inertia
from fenicsfriction.laws import check, check_positive
from fenicsfriction.results import CsvRows, Record, write_json

__all__ = ["BASE", "LEFT", "Break", "Front", "ElasticSlider", "ElasticSliderModel",
           "SliderHistory", "fronts"]

#: facet tags of the slider's mesh: the base on the contacts and the left side
BASE, LEFT = 1, 2


@dataclasses.dataclass(frozen=True)
class ElasticSlider:
    """The slider, its EQ contacts and the pusher (SI units; forces per unit breadth in 2D).

    Attributes:
        L, H: length and height of the slider [m].
        nx, ny: cells along and across.
        E, nu, rho: Young's modulus [Pa], Poisson's ratio, density [kg/m³].
        plane_stress: plane stress instead of plane strain.
        k: stiffness of the base contacts per unit base length [Pa/m]; node j: k w_j.
        threshold: mean breaking stretch x̄_s [m] (``inf``: unbreakable contacts).
        spread: relative half-width δ of the uniform threshold distribution, in [0, 1).
        delay: time a broken contact stays off before re-forming relaxed [s].
        k_push: stiffness of the pusher springs per unit length of the left face [Pa/m].
        push_speed: speed V of the pusher stage [m/s].
        seed: seed of the thresholds.
        patches: number of equal patches of the base that share a threshold (0: one per node);
            with ``nx`` a multiple of ``patches`` the realisation of the thresholds is a
            function of x alone, the same on every mesh.
        viscosity: Kelvin-Voigt relaxation time τ of the slider [s]: σ = C : (ε(u) + τ ε(u̇))
            damps the waves the breaks radiate (a mode of frequency ω by ωτ/2 of critical).
    """

    L: float = 0.1
    H: float = 0.01
    nx: int = 40
    ny: int = 4
    E: float = 1e9
    nu: float = 0.3
    rho: float = 1000.0
    plane_stress: bool = False
    k: float = 1e10
    threshold: float = 1e-6
    spread: float = 0.5
    delay: float = 0.0
    k_push: float = 1e11
    push_speed: float = 0.01
    seed: int = 0
    patches: int = 0
    viscosity: float = 0.0

    def __post_init__(self) -> None:
        for name in ("L", "H", "E", "rho", "k"):
            check_positive(name, getattr(self, name))
        check("threshold", self.threshold, self.threshold > 0, "must be > 0 (inf: unbreakable)")
        for name in ("nx", "ny"):
            check(name, getattr(self, name), int(getattr(self, name)) >= 1, "must be >= 1")
        check("nu", self.nu, -1 < self.nu < 0.5, "must lie in (-1, 0.5)")
        check("spread", self.spread, 0 <= self.spread < 1, "must lie in [0, 1)")
        for name in ("delay", "k_push", "push_speed", "viscosity"):
            check_positive(name, getattr(self, name), strict=False)
        check("patches", self.patches, self.patches >= 0 and (
            self.patches == 0 or self.nx % self.patches == 0),
            f"must be 0 or divide nx = {self.nx}")

    @property
    def h(self) -> float:
        """Spacing of the base nodes [m]."""
        return self.L / self.nx

    @property
    def wave_speeds(self) -> tuple[float, float]:
        r"""The slider's P- and S-wave speeds :math:`(c_p, c_s)` [m/s]: :math:`c_s^2 = \mu/\rho`;
        :math:`c_p^2 = (\lambda + 2\mu)/\rho` in plane strain, :math:`E/(\rho(1 - \nu^2))`
        (the plate's) in plane stress."""
        mu = self.E / (2 * (1 + self.nu))
        if self.plane_stress:
            return math.sqrt(self.E / (self.rho * (1 - self.nu**2))), math.sqrt(mu / self.rho)
        lam = self.E * self.nu / ((1 + self.nu) * (1 - 2 * self.nu))
        return math.sqrt((lam + 2 * mu) / self.rho), math.sqrt(mu / self.rho)

    def draw_threshold(self, node: np.ndarray, count: np.ndarray) -> np.ndarray:
        """Thresholds x_s [m] of base nodes ``node`` (numbers j = x/h) formed ``count`` times
        before: the same numbers on any partition of the mesh."""
        if not np.isfinite(self.threshold):
            return np.full(len(node), np.inf)
        where = node if self.patches == 0 else np.minimum(
            np.asarray(node) * self.patches // self.nx, self.patches - 1)
        uniform = np.array([np.random.default_rng((self.seed, int(j), int(c))).random()
                            for j, c in zip(where, count, strict=True)])
        return self.threshold * (1.0 + self.spread * (2.0 * uniform - 1.0))


@dataclasses.dataclass
class Break(Record):
    """One contact breaking: time [s], position x [m], stretch [m], released energy [J/m]."""

    time: float
    x: float
    stretch: float
    energy: float


@dataclasses.dataclass
class Front(Record):
    """A detachment front: a burst of breaks spreading from ``start_x``.

    Attributes:
        start_time, end_time: first and last break of the burst [s].
        start_x, tip_x: where it started and the furthest break it reached [m].
        tip_time: when it reached ``tip_x`` (the first break there) [s].
        speed: mean speed of its tip, (tip_x - start_x) / (tip_time - start_time) [m/s]
            (``nan`` when the tip broke in the first break's step).
        arrested: it stopped before the far (leading) edge: a precursor.
        push_force: pusher force per unit breadth when it started [N/m].
        size: how many breaks it grouped.
    """

    start_time: float
    end_time: float
    start_x: float
    tip_x: float
    tip_time: float
    speed: float
    arrested: bool
    push_force: float
    size: int = 1


def fronts(breaks: typing.Sequence[Break], push_force: typing.Callable[[float], float],
           gap: float, far_edge: float, wave_speed: float = math.inf) -> list[Front]:
    r"""Group breaks into fronts by causality: a break joins a front only if a signal at the
    wave speed c could have carried it from one of the front's breaks at most ``gap`` [s]
    before it,

    .. math::
        |x_e - x_f| \le c\,(t_e - t_f), \qquad 0 \le t_e - t_f \le \text{gap};

    otherwise it starts a front of its own. Where several fronts could have caused it, it
    joins the one whose reachable break is the latest (then the nearest). A front's breaks
    lie in the light cone of its first break (the bound holds link by link along the
    causal chain and adds up), so its speed never exceeds c: the rule of causality that
    bounds rupture fronts by the material's limiting wave speed (Freund 1990, *Dynamic
    Fracture Mechanics*; Rosakis 2002, "Intersonic shear cracks and fault ruptures"), and the
    largest c (the P-wave speed) lets supershear fronts through, as Rubinstein, Cohen &
    Fineberg (2004) saw them. Breaks at different places in the same step are never one
    front's: nothing travels in no time. ``wave_speed = inf`` is the grouping by the time
    gap alone. A front is arrested when its tip stays short of ``far_edge`` [m]."""
    check("wave_speed", wave_speed, wave_speed > 0, "must be > 0 (inf: the time gap alone)")
    check_positive("gap", gap, strict=False)
    groups: list[list[Break]] = []
    for b in sorted(breaks, key=lambda b: (b.time, b.x)):
        best: tuple[float, float] | None = None  # (time, -distance) of the best cause so far
        joins = -1
        for g, group in enumerate(groups):
            for f in reversed(group):  # the front's breaks, latest first
                lag = b.time - f.time
                if lag > gap:
                    break
                # the times are sums of steps: a relative 1e-9 absorbs their round-off
                reachable = lag >= 0 if math.isinf(wave_speed) else \
                    abs(b.x - f.x) <= wave_speed * lag * (1.0 + 1e-9)
                if reachable and (best is None or (f.time, -abs(b.x - f.x)) > best):
                    best, joins = (f.time, -abs(b.x - f.x)), g
        if joins < 0:
            groups.append([b])
        else:
            groups[joins].append(b)
    result = []
    for group in sorted(groups, key=lambda group: (group[0].time, group[0].x)):
        first, tip = group[0], max(group, key=lambda b: (b.x, -b.time))
        duration = tip.time - first.time
        speed = (tip.x - first.x) / duration if duration > 0 else float("nan")
        result.append(Front(start_time=first.time, end_time=group[-1].time, start_x=first.x,
                            tip_x=tip.x, tip_time=tip.time, speed=speed, arrested=tip.x < far_edge,
                            push_force=push_force(first.time), size=len(group)))
    return result


@dataclasses.dataclass
class SliderHistory(Record):
    """What a run gives: the front history and the fronts.

    Attributes:
        time: the accepted step times [s].
        front_position: x of the furthest contact broken since the start [m] (``nan`` before
            the first break), per step.
        push_force: pusher force per unit breadth [N/m], per step.
        attached: number of attached contacts, per step.
        breaks: every break since the model was built, in order.
        fronts: the breaks grouped into fronts (:func:`fronts`).
        slip_force: the pusher force at the step the far-edge contact first broke (the
            detachment had spanned the interface) [N/m]; ``nan`` if it never did.
        peak_force: the largest pusher force [N/m] (the static friction force).
    """

    time: list[float]
    front_position: list[float]
    push_force: list[float]
    attached: list[int]
    breaks: list[Break]
    fronts: list[Front]
    slip_force: float
    peak_force: float

    def write_csv(self, path: str | pathlib.Path, comm: MPI.Comm = MPI.COMM_WORLD) -> None:
        """The front history as a CSV table (on rank 0)."""
        with CsvRows(pathlib.Path(path), comm) as rows:
            for row in zip(self.time, self.front_position, self.push_force, self.attached,
                           strict=True):
                rows.write(dict(zip(("time", "front_position", "push_force", "attached"), row,
                                    strict=True)))

    def write_json(self, path: str | pathlib.Path, comm: MPI.Comm = MPI.COMM_WORLD) -> None:
        """Everything as JSON (on rank 0)."""
        write_json(path, self.to_json(), comm)


class _TimedSolver(DynamicsSolver):
    """The dynamics solver with the model's clock set at each residual (the pusher's stage
    moves within a step)."""

    def __init__(self, model: ElasticSliderModel, **kwargs: typing.Any):
        self.model = model
        super().__init__(model.residual, **kwargs)

    def _F(self, ts, t, x, xdot, xddot, F):
        self.model.time.value = t
        super()._F(ts, t, x, xdot, xddot, F)


class ElasticSliderModel:
    """The slider as a finite element model, its EQ contacts and their breaking.

    Attributes:
        scene: the parameters.
        msh, V, facet_tags: mesh (quadrilaterals, degree 1), vector space, facets BASE / LEFT.
        residual: the one residual.
        anchor, attached: scalar degree-1 fields of the anchors U_j [m] and the switches a_j
            (base nodes only).
        time: ``fem.Constant`` clock of the pusher.
        viscosity: ``fem.Constant`` Kelvin-Voigt time τ [s] (from the scene; set its
            ``value`` to run another τ with the same compiled forms).
        node, x, weight, threshold, breaks_so_far, off_since, ever_broken: per owned base
            node: its number j, abscissa, share w_j of the base, current threshold, breaks,
            time it broke (``nan`` while attached), broken since the start.
    """

    CONTACT = BASE

    def __init__(self, scene: ElasticSlider, comm: MPI.Comm = MPI.COMM_WORLD):
        self.scene = s = scene
        msh = _compat.create_rectangle(comm, (0.0, 0.0), (s.L, s.H), (s.nx, s.ny))
        self.msh = msh
        fdim = msh.topology.dim - 1
        tol = 1e-10 * s.L
        facets = [mesh.locate_entities_boundary(msh, fdim, where) for where in (
            lambda x: np.isclose(x[1], 0.0, atol=tol), lambda x: np.isclose(x[0], 0.0, atol=tol))]
        indices = np.concatenate(facets)
        tags = np.concatenate([np.full(len(f), t, dtype=np.int32)
                               for f, t in zip(facets, (BASE, LEFT), strict=True)])
        order = np.argsort(indices)
        self.facet_tags = mesh.meshtags(msh, fdim, indices[order], tags[order])
        self.V = V = _compat.vector_function_space(msh, 1)
        Q = _compat.scalar_function_space(msh, "Lagrange", 1)
        self.anchor, self.attached = fem.Function(Q), fem.Function(Q)
        self.time = fem.Constant(msh, 0.0)
        # a Constant, not a number in the form: one compiled form serves every τ (τ = 0 too)
        self.viscosity = fem.Constant(msh, np.float64(s.viscosity))
        ds = ufl.Measure("ds", domain=msh, subdomain_data=self.facet_tags,
                         metadata=_compat.nodal_quadrature(fdim))
        self.ds_base, self.ds_left = ds(BASE), ds(LEFT)
        u, u_dot, u_ddot = fem.Function(V, name="displacement"), fem.Function(V), fem.Function(V)
        v = ufl.TestFunction(V)
        form = inertia(s.rho, u_ddot, v, ufl.dx(domain=msh)) \
            + elasticity(u + self.viscosity * u_dot, v, s.E, s.nu, ufl.dx(domain=msh),
                         s.plane_stress) \
            + s.k * self.attached * (u[0] - self.anchor) * v[0] * self.ds_base
        if s.k_push > 0:
            form += s.k_push * (u[0] - s.push_speed * self.time) * v[0] * self.ds_left
        base_y = fem.locate_dofs_topological(V.sub(1), fdim, self.facet_tags.find(BASE))
        bcs = [fem.dirichletbc(np.float64(0.0), base_y, V.sub(1))]
        self.residual = Residual(form=form, u=u, u_dot=u_dot, u_ddot=u_ddot, v=v, bcs=bcs)
        self._base_nodes(Q, fdim)
        self._push_force = _compat.form(
            s.k_push * (s.push_speed * self.time - u[0]) * self.ds_left)
        energy = {"kinetic": 0.5 * s.rho * ufl.inner(u_dot, u_dot) * ufl.dx(domain=msh),
                        "strain": 0.5 * elasticity(u, u, s.E, s.nu, ufl.dx(domain=msh),
                                                   s.plane_stress),
                        "contacts": 0.5 * s.k * self.attached * (u[0] - self.anchor) ** 2
                        * self.ds_base}
        self._energy = {name: _compat.form(f) for name, f in energy.items()}
        self._contact_force = _compat.form(
            s.k * self.attached * (self.anchor - u[0]) * self.ds_base)
        self._momentum = _compat.form(s.rho * u_dot[0] * ufl.dx(domain=msh))
        self.breaks: list[Break] = []

    def _base_nodes(self, Q: fem.FunctionSpace, fdim: int) -> None:
        """Owned base nodes: numbers, abscissae, weights; all contacts attached and relaxed."""
        s = self.scene
        dofs = fem.locate_dofs_topological(Q, fdim, self.facet_tags.find(BASE))
        self.dofs = dofs[dofs < Q.dofmap.index_map.size_local]
        x = Q.tabulate_dof_coordinates()
        # the vector space numbers its nodes as the scalar one (same element, same mesh)
        assert np.allclose(self.V.tabulate_dof_coordinates()[self.dofs], x[self.dofs])
        self.node = np.rint(x[self.dofs, 0] / s.h).astype(np.int64)
        self.x = self.node * s.h  # exact abscissae: the same on any partition
        self.weight = np.where((self.node == 0) | (self.node == s.nx), 0.5 * s.h, s.h)
        self.breaks_so_far = np.zeros(len(self.dofs), dtype=np.int64)
        self.threshold = s.draw_threshold(self.node, self.breaks_so_far)
        self.off_since = np.full(len(self.dofs), np.nan)
        self.ever_broken = np.zeros(len(self.dofs), dtype=bool)
        self.attached.x.array[self.dofs] = 1.0
        self.attached.x.scatter_forward()

    def base_displacement(self) -> np.ndarray:
        """u_x at the owned base nodes [m]."""
        return self.residual.u.x.array[2 * self.dofs]

    def update_contacts(self, t: float) -> list[Break]:
        """Break the overstretched contacts and re-form those whose delay is over (the event
        between two time steps); returns the breaks, the same on every rank."""
        s = self.scene
        ux = self.base_displacement()
        on = self.attached.x.array[self.dofs] > 0.5
        stretch = np.abs(ux - self.anchor.x.array[self.dofs])
        broken = on & (stretch > self.threshold)
        local = [Break(time=t, x=float(xj), stretch=float(sj), energy=0.5 * s.k * w * sj**2)
                 for xj, sj, w in zip(self.x[broken], stretch[broken], self.weight[broken],
                                      strict=True)]
        self.breaks_so_far[broken] += 1
        self.ever_broken |= broken
        self.off_since[broken] = t
        due = ~on & (t - self.off_since >= s.delay) | broken & (s.delay == 0)
        self.attached.x.array[self.dofs[broken]] = 0.0
        self.attached.x.array[self.dofs[due]] = 1.0
        self.anchor.x.array[self.dofs[due]] = ux[due]
        self.off_since[due] = np.nan
        self.threshold[due] = s.draw_threshold(self.node[due], self.breaks_so_far[due])
        for field in (self.attached, self.anchor):
            field.x.scatter_forward()
        gathered = [b for part in self.msh.comm.allgather(local) for b in part]
        self.breaks += sorted(gathered, key=lambda b: b.x)
        return gathered

    def push_force(self) -> float:
        """Force per unit breadth the pusher exerts on the slider [N/m]."""
        return self.msh.comm.allreduce(fem.assemble_scalar(self._push_force))

    def contact_force(self) -> float:
        """Tangential force per unit breadth the attached contacts exert on the slider [N/m]."""
        return self.msh.comm.allreduce(fem.assemble_scalar(self._contact_force))

    def momentum(self) -> float:
        """Tangential momentum of the slider per unit breadth [kg/s]."""
        return self.msh.comm.allreduce(fem.assemble_scalar(self._momentum))

    def energies(self) -> dict[str, float]:
        """Kinetic, strain and contact-spring energies per unit breadth [J/m]."""
        return {name: self.msh.comm.allreduce(fem.assemble_scalar(f))
                for name, f in self._energy.items()}

    def front_position(self) -> float:
        """x of the furthest contact broken since the start [m] (``nan`` before any)."""
        local = self.x[self.ever_broken].max(initial=-np.inf)
        value = self.msh.comm.allreduce(local, op=MPI.MAX)
        return value if np.isfinite(value) else float("nan")

    def contact_traction(self) -> typing.Any:
        """UFL traction of the contacts on the slider, for output fields (meaningful on the
        base only)."""
        return ufl.as_vector([self.scene.k * self.attached
                              * (self.anchor - self.residual.u[0]), 0.0])

    def solver(self, prefix: str = "slider_", options: dict | None = None) -> DynamicsSolver:
        """The generalized-α solver of this model, the pusher's clock kept in step."""
        return _TimedSolver(self, prefix=prefix, options=options,
                            atol=1e-10 * self.scene.k * self.scene.L * self.scene.threshold
                            if np.isfinite(self.scene.threshold) else 1e-10)

    def run(self, t_end: float, dt: float, solver: DynamicsSolver | None = None,
            on_step: typing.Callable[[dict], None] | None = None,
            front_gap: float | None = None, wave_speed: float | None = None) -> SliderHistory:
        """Push for ``t_end`` with steps ``dt``, breaking contacts between steps.

        Args:
            t_end, dt: duration and (fixed) step [s].
            solver: default :meth:`solver`.
            on_step: called with each step's record (e.g. field output).
            front_gap: breaks closer in time than this can belong to one front [s]; default
                5 dt.
            wave_speed: the speed that bounds the fronts (:func:`fronts`) [m/s]; default the
                P-wave speed.

        Returns:
            The history of the run.
        """
        solver = solver or self.solver()

        def observe(t: float) -> dict[str, typing.Any]:
            self.time.value = t
            if t > 0:
                self.update_contacts(t)
            attached = self.msh.comm.allreduce(int(np.sum(self.attached.x.array[self.dofs])))
            return {"front_position": self.front_position(), "push_force": self.push_force(),
                    "attached": attached}

        records = solver.run(t_end, dt, observe=observe, on_step=on_step)
        times = [r["time"] for r in records]
        force = [r["push_force"] for r in records]

        def force_at(t: float) -> float:
            return float(np.interp(t, times, force))

        far_edge = self.scene.L - 0.5 * self.scene.h
        found = fronts(self.breaks, force_at, front_gap or 5 * dt, far_edge,
                       wave_speed or self.scene.wave_speeds[0])
        position = np.array([r["front_position"] for r in records])
        spanned = np.flatnonzero(position >= far_edge)
        return SliderHistory(time=times, front_position=[float(p) for p in position],
                             push_force=force, attached=[r["attached"] for r in records],
                             breaks=list(self.breaks), fronts=found,
                             slip_force=float(force[spanned[0]]) if len(spanned) else float("nan"),
                             peak_force=float(np.max(force)))
