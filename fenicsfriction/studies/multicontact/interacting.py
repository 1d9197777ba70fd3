r"""The earthquake-like model with contacts that interact through the elastic bodies (Braun
(slides), "Interaction between contacts: EQ simulation").

The contacts of :class:`~fenicsfriction.studies.multicontact.eq_model.EQModel` sit at points
:math:`\mathbf r_i` of the interface between two elastic bodies. The slider's rigid
displacement X stretches contact i by :math:`U_{0,i} = X - b_i` (:math:`b_i` set when it was
born) less the bodies' relative surface displacement :math:`(G f)_i`, so its force is

.. math::

    f = k\,(U_0 - G f) \quad\Longrightarrow\quad f = M U_0, \qquad
    M = (k^{-1} + G)^{-1} = B k,\quad B = (1 + kG)^{-1},

the slides' :math:`F = B K U_0` for the sliding component. :math:`G` is the tangential
compliance of the pair of bodies: for two identical bodies (the slider and the base of the same
material) it is twice the half-space's :math:`G_{ix,jx}`
(:func:`~fenicsfriction.studies.multicontact.interaction.interaction_matrix`), and the
normal-tangential couplings of the two bodies cancel (Johnson 1985, *Contact mechanics*, §5.1:
elastically similar bodies), so sliding along x loads the contacts along x only.

Between breaks the forces grow linearly with X, :math:`\partial f/\partial X = M\mathbf 1`, and
the friction force is :math:`F = \sum_i f_i` with the interface's stiffness
:math:`S = \mathbf 1^T M \mathbf 1 \le N k`. A contact breaks when its stretching
:math:`f_i/k` exceeds its threshold and re-forms at once with a newborn stretching
:math:`x_0` (relaxed: 0), i.e. its :math:`U_{0,i}` is reset so that :math:`f_i = k x_0`. For
the set :math:`S` of contacts breaking together this is one small solve,
:math:`\delta U_{0,S} = M_{SS}^{-1}(k x_0 - f_S)`, and the others' forces change by
:math:`M_{\cdot S}\,\delta U_{0,S}`: exactly the response to the break
(:func:`~fenicsfriction.studies.multicontact.interaction.break_response`, which removes the
contact: a relaxed contact carries no force, so the others see the same field). The response
loads the neighbours (to first order :math:`M \approx k - k^2 G`, :math:`M_{ij} < 0`), which
may break in turn, at the same X: an avalanche, resolved in rounds until no contact is over its
threshold.
With :math:`G = 0` (no interaction) :math:`M = k` and nothing cascades: the model is
:class:`EQModel` exactly, random draws included.

The interaction's strength is the dimensionless :math:`k/(E a)` of a lattice of spacing a
(the slides' :math:`v_1`; the elastic correlation length is :math:`\lambda_c = a/v_1`). The
stronger it is, the more of a break's force goes to the neighbours, and avalanches grow: the
slides' "the stronger is the interaction, the wider is the range of model parameters where
stick-slip occurs" (:func:`~fenicsfriction.studies.multicontact.instability.coupling_map`).

Cost: :class:`InteractingEQModel` holds :math:`M` dense, one :math:`O(N^3)` Cholesky
inversion (N ≲ 2000); a break costs :math:`O(N)` per broken contact.
:class:`LatticeEQModel` is matrix-free: on a square lattice :math:`G` depends on the offset
only, so :math:`(k^{-1} + G) f` is a convolution, done by FFT on a :math:`2n \times 2n`
circulant embedding (as
:class:`~fenicsfriction.studies.multicontact.interaction.LatticeInteraction`); the rate
:math:`M\mathbf 1` is one conjugate-gradient solve, and an avalanche's round one more, on the
contacts that keep their offsets: with :math:`\delta f_S = k x_0 - f_S` prescribed on
the broken set S, :math:`(k^{-1} + G)_{\bar S \bar S}\,\delta f_{\bar S} =
-G_{\bar S S}\,\delta f_S` (the same update as the dense one, which solves with
:math:`M_{SS}`), preconditioned by the circulant of the periodic lattice, each offset at its
nearest image (Strang 1986, "A proposal for Toeplitz matrix calculations"). Set-up
:math:`O(N \log N)`, memory :math:`O(N)`, a round :math:`O(N \log N)` per iteration.
"""

from __future__ import annotations

import abc
import dataclasses
import math
import typing

import numpy as np
import numpy.typing as npt
import scipy.fft
import scipy.linalg

from fenicsfriction.laws import check, check_positive
from fenicsfriction.studies.multicontact.eq_model import (
    EQModel,
    QuasistaticResult,
    SpringDrives,
    check_quasistatic,
)
from fenicsfriction.studies.multicontact.interaction import (
    green_tensor,
    interaction_matrix,
    self_compliance,
)

__all__ = ["CoupledContacts", "DenseStiffness", "InteractingEQModel",
           "InteractingQuasistaticResult", "LatticeCompliance", "LatticeEQModel",
           "LatticeStiffness", "StiffnessOperator", "lattice_compliance"]

Array: typing.TypeAlias = npt.NDArray[np.float64]


def lattice_compliance(n: int, spacing: float, E: float, nu: float,
                       contact_radius: float | None = None) -> tuple[Array, Array]:
    """The tangential compliance of contacts on an ``n × n`` square lattice between two
    identical elastic bodies: ``2 G[x, x]`` of the half-space's interaction matrix.

    Args:
        n: contacts per side.
        spacing: the lattice spacing a (m).
        E: Young's modulus of both bodies (Pa); ``math.inf``: rigid bodies, G = 0.
        nu: their Poisson's ratio.
        contact_radius: radius of a contact for the self term; None: a/2.

    Returns:
        ``(positions (n², 2), G (n², n²))``, contact ``(i, j)`` at ``(i a, j a)``, flat index
        ``i n + j``.
    """
    check("n", n, isinstance(n, (int, np.integer)) and n >= 1, "must be an integer >= 1")
    check_positive("spacing", spacing)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    positions = spacing * np.stack([i.ravel(), j.ravel()], axis=1).astype(float)
    if math.isinf(E):
        return positions, np.zeros((n * n, n * n))
    radius = 0.5 * spacing if contact_radius is None else contact_radius
    G = interaction_matrix(positions, E, nu, radius)
    return positions, np.ascontiguousarray(2.0 * G[0::3, 0::3])


class LatticeCompliance:
    """:func:`lattice_compliance` applied matrix-free: ``G f`` by FFT on the ``2n × 2n``
    circulant embedding of the lattice's offsets, O(N log N), no N × N array.

    Args: as :func:`lattice_compliance` (``E`` finite).

    Attributes:
        n, size: contacts per side and N = n².
        diagonal: G_ii, the self term (all equal).
    """

    def __init__(self, n: int, spacing: float, E: float, nu: float,
                 contact_radius: float | None = None) -> None:
        check("n", n, isinstance(n, (int, np.integer)) and n >= 1, "must be an integer >= 1")
        check_positive("spacing", spacing)
        self.n, self.size = int(n), int(n) ** 2
        radius = 0.5 * spacing if contact_radius is None else contact_radius
        offsets = np.fft.fftfreq(2 * self.n, d=1.0 / (2 * self.n))  # 0, 1, .., n, -(n-1), .., -1
        dx, dy = np.meshgrid(offsets * spacing, offsets * spacing, indexing="ij")
        kernel = np.zeros((2 * self.n, 2 * self.n))
        nonzero = np.hypot(dx, dy) > 0
        kernel[nonzero] = 2.0 * green_tensor(np.stack([dx[nonzero], dy[nonzero]], axis=-1),
                                             E, nu)[:, 0, 0]
        self.diagonal = 2.0 * float(self_compliance(radius, E, nu)[0, 0])
        kernel[0, 0] = self.diagonal
        self._spectrum = scipy.fft.rfft2(kernel)
        # the periodic lattice's circulant (each offset taken at its nearest image, Strang
        # 1986): the preconditioner's spectrum, O(N log N)
        near = np.fft.fftfreq(self.n, d=1.0 / self.n)
        px, py = np.meshgrid(near * spacing, near * spacing, indexing="ij")
        periodic = np.zeros((self.n, self.n))
        inner = np.hypot(px, py) > 0
        periodic[inner] = 2.0 * green_tensor(np.stack([px[inner], py[inner]], axis=-1),
                                             E, nu)[:, 0, 0]
        periodic[0, 0] = self.diagonal
        self.periodic_spectrum = scipy.fft.rfft2(periodic)

    def apply(self, forces: Array) -> Array:
        """G f for ``(N,)`` forces: the relative displacements ``(N,)``."""
        n = self.n
        padded = np.zeros((2 * n, 2 * n))
        padded[:n, :n] = forces.reshape(n, n)
        full = scipy.fft.irfft2(self._spectrum * scipy.fft.rfft2(padded), s=(2 * n, 2 * n))
        return full[:n, :n].ravel()

    def dense(self) -> Array:
        """G as an ``(N, N)`` array, column by column (for checks at small N)."""
        return np.stack([self.apply(e) for e in np.eye(self.size)], axis=1)


class StiffnessOperator(typing.Protocol):
    """What :class:`CoupledContacts` needs of M = (1/k + G)⁻¹."""

    #: M 1, the contacts' force per unit slider displacement.
    rate: Array

    def update(self, over: npt.NDArray[np.intp], change: Array) -> tuple[Array, Array]:
        """The forces' change when the contacts ``over`` change theirs by ``change`` and the
        others keep their offsets, and the offsets' change on ``over``."""


class DenseStiffness:
    """M = (1/k + G)⁻¹ held dense: the update of :class:`CoupledContacts` by :math:`M_{SS}`."""

    def __init__(self, M: Array) -> None:
        self.M = M
        self.rate: Array = M.sum(axis=1)

    def update(self, over: npt.NDArray[np.intp], change: Array) -> tuple[Array, Array]:
        """The forces' change when the contacts ``over`` change theirs by ``change`` and the
        others keep their offsets, and the offsets' change on ``over``."""
        jump = change / self.M[over[0], over[0]] if over.size == 1 else \
            scipy.linalg.solve(self.M[np.ix_(over, over)], change, assume_a="pos")
        return self.M[:, over] @ jump, -jump


class LatticeStiffness:
    """M = (1/k + G)⁻¹ applied by conjugate gradients on the FFT compliance, matrix-free.

    Args:
        k: the contacts' stiffness.
        compliance: G (:class:`LatticeCompliance`).
        rtol: the relative residual of each solve.
        max_iterations: per solve; beyond, the run stops with an error naming ``rtol``.

    Attributes:
        rate: M 1.
        iterations: conjugate-gradient iterations so far, all solves.
        solves: the solves so far.
    """

    def __init__(self, k: float, compliance: LatticeCompliance, rtol: float = 1e-10,
                 max_iterations: int = 2000) -> None:
        check_positive("rtol", rtol)
        self.k, self.G, self.rtol, self.max_iterations = k, compliance, rtol, max_iterations
        n = compliance.n
        self._preconditioner = 1.0 / (1.0 / k + compliance.periodic_spectrum.real)
        self._shape = (n, n)
        self.iterations = self.solves = 0
        everyone = np.ones(compliance.size, dtype=bool)
        self.rate = self.solve(np.ones(compliance.size), everyone)

    def operator(self, f: Array) -> Array:
        """(1/k + G) f."""
        return f / self.k + self.G.apply(f)

    def _precondition(self, r: Array) -> Array:
        return scipy.fft.irfft2(self._preconditioner * scipy.fft.rfft2(r.reshape(self._shape)),
                                s=self._shape).ravel()

    def solve(self, rhs: Array, free: npt.NDArray[np.bool_]) -> Array:
        """x with ``(1/k + G)_{FF} x_F = rhs_F`` on the contacts ``free`` (F) and x = 0 off
        them, by preconditioned conjugate gradients (the operator restricted to F is
        symmetric positive definite, and so is the preconditioner restricted likewise)."""
        x = np.zeros_like(rhs)
        r = np.where(free, rhs, 0.0)
        target = self.rtol * float(np.linalg.norm(r))
        z = np.where(free, self._precondition(r), 0.0)
        d, rz = z.copy(), float(r @ z)
        for _ in range(self.max_iterations):
            if float(np.linalg.norm(r)) <= target:
                break
            q = np.where(free, self.operator(d), 0.0)
            alpha = rz / float(d @ q)
            x += alpha * d
            r -= alpha * q
            z = np.where(free, self._precondition(r), 0.0)
            rz, previous = float(r @ z), rz
            d = z + (rz / previous) * d
            self.iterations += 1
        else:
            check("rtol", self.rtol, False, f"conjugate gradients did not reach it in "
                  f"{self.max_iterations} iterations")
        self.solves += 1
        return x

    def update(self, over: npt.NDArray[np.intp], change: Array) -> tuple[Array, Array]:
        """As :meth:`DenseStiffness.update`: one solve on the contacts that keep their
        offsets, loaded by the broken ones' change through G."""
        delta = np.zeros(self.G.size)
        delta[over] = change
        free = np.ones(self.G.size, dtype=bool)
        free[over] = False
        delta += self.solve(-self.G.apply(delta), free)
        return delta, -self.operator(delta)[over]


class CoupledContacts:
    """The contacts of an :class:`InteractingEQModel` in one realisation: their forces at a
    reference position, their thresholds, the breaks and avalanches (the module docstring).

    Attributes:
        forces: f at ``X_ref`` (force units).
        X_ref: the slider position where ``forces`` hold.
        offsets: :math:`b` with :math:`f = M (X_{ref} - b)` (kept for checks).
        thresholds: the current thresholds (length).
        rate: :math:`\\partial f/\\partial X = M \\mathbf 1`.
        stiffness: S, the friction force's slope between breaks.
        weight: a force scale, N k x_c.
        avalanches: ``(X, breaks, force drop)`` of every :meth:`relax` that broke contacts.
    """

    def __init__(self, model: EQModel, stiffness: Array | StiffnessOperator,
                 rng: np.random.Generator, max_rounds: int) -> None:
        self.stiffness_operator: StiffnessOperator = DenseStiffness(stiffness) if isinstance(
            stiffness, np.ndarray) else stiffness
        self.model, self.rng, self.max_rounds = model, rng, max_rounds
        n = model.n_contacts
        self.forces: Array = np.zeros(n)
        self.offsets: Array = np.zeros(n)
        self.X_ref = 0.0
        self.thresholds = model.draw_thresholds(rng, np.zeros(n))
        self.rate = self.stiffness_operator.rate
        self._loaded = np.flatnonzero(self.rate > 0)  # the contacts X loads (rate is fixed)
        self.stiffness = float(self.rate.sum())
        self.weight = n * model.k * model.x_s_mean
        self.avalanches: list[tuple[float, int, float]] = []

    def forces_at(self, X: float) -> Array:
        """The contacts' forces at X, before any break there."""
        return self.forces + (X - self.X_ref) * self.rate

    def friction(self, X: float) -> float:
        return float(np.sum(self.forces)) + (X - self.X_ref) * self.stiffness

    def next_break(self) -> tuple[float, int]:
        """The slider position of the next break under further loading, and the contact that
        breaks there (``(inf, -1)`` if none is loaded)."""
        loaded = self._loaded
        if loaded.size == 0:
            return math.inf, -1
        room = (self.model.k * self.thresholds[loaded] - self.forces[loaded]) / self.rate[loaded]
        first = int(np.argmin(room))
        return self.X_ref + max(0.0, float(room[first])), int(loaded[first])

    def relax(self, X: float, trigger: int | None = None) -> int:
        """Break and re-form, in rounds, every contact over its threshold at X (and
        ``trigger``, the one :meth:`next_break` found at its threshold, whatever the round-off);
        return the number of breaks (a contact may break more than once in an avalanche)."""
        f = self.forces_at(X)
        k, before, broken, rounds = self.model.k, float(np.sum(f)), 0, 0
        kept = None  # the state before the avalanche, copied at its first round
        while (over := np.flatnonzero(f > k * self.thresholds)).size or trigger is not None:
            if trigger is not None:
                over = over if trigger in over else np.union1d(over, [trigger])
                trigger = None
            if kept is None:
                kept = self.thresholds.copy(), self.offsets.copy()
            if rounds == self.max_rounds:
                self.thresholds, self.offsets = kept
                raise RuntimeError(f"the avalanche at X = {X:.6g} was still going after "
                                   f"max_rounds = {self.max_rounds} rounds ({broken} breaks); "
                                   "the contacts are left as they were before it")
            x0 = self.model.draw_newborn(self.rng, over.size)
            change, offset_change = self.stiffness_operator.update(over, k * x0 - f[over])
            f += change
            f[over] = k * x0
            self.offsets[over] += offset_change
            self.thresholds[over] = self.model.draw_thresholds(self.rng, x0)
            broken += over.size
            rounds += 1
        self.forces, self.X_ref = f, X
        if broken:
            self.avalanches.append((X, broken, before - float(np.sum(f))))
        return broken


@dataclasses.dataclass
class InteractingQuasistaticResult(QuasistaticResult):
    """:class:`QuasistaticResult` of interacting contacts, with their avalanches.

    Attributes:
        avalanche_X: where each avalanche happened (all realisations, in order).
        avalanche_size: the breaks of each avalanche.
        force_drop: the fall of the friction force in each avalanche.
        largest_avalanche: the largest avalanche's breaks over N.
        interface_stiffness: S = 1ᵀ M 1, dF/dX between breaks.

    The coupling k/(E a) is in ``parameters``.
    """

    avalanche_X: np.ndarray
    avalanche_size: np.ndarray
    force_drop: np.ndarray
    largest_avalanche: float
    interface_stiffness: float


class _Interface(SpringDrives):
    """The drives of interacting contacts, whatever holds their stiffness (the spring drives
    are :class:`~fenicsfriction.studies.multicontact.eq_model.SpringDrives`'; abstract: a
    model gives ``interface_stiffness``, ``parameters`` and ``contacts``)."""

    model: EQModel

    @property
    @abc.abstractmethod
    def interface_stiffness(self) -> float:
        """S, the friction force's slope dF/dX between breaks."""

    @abc.abstractmethod
    def contacts(self, rng: np.random.Generator) -> CoupledContacts:
        """A fresh realisation of the coupled contacts, every contact relaxed at X = 0."""

    def quasistatic(self, X_max: float, n_points: int = 401, realisations: int = 1,
                    seed: int | None = 0, kinetic_from: float | None = None,
                    bins: int = 50) -> InteractingQuasistaticResult:
        """Move the slider from X = 0, every contact relaxed, to ``X_max``, break by break.

        Event-driven and exact: F is linear in X between breaks, the next break is found in
        closed form, and each avalanche is resolved at its X (arguments as
        :meth:`EQModel.quasistatic`).
        """
        kinetic_from = check_quasistatic(X_max, n_points, realisations, kinetic_from)
        rng = np.random.default_rng(seed)
        X = np.linspace(0.0, X_max, n_points)
        F = np.empty((realisations, n_points))
        stretch, avalanches = [], []
        for r in range(realisations):
            contacts = self.contacts(rng)
            at, after = [0.0], [0.0]  # F just after each avalanche, and where
            while (event := contacts.next_break())[0] <= X_max:
                X_next = event[0]
                contacts.relax(*event)
                at.append(X_next)
                after.append(contacts.friction(X_next))
            last = np.searchsorted(at, X, side="right") - 1
            F[r] = np.asarray(after)[last] + (X - np.asarray(at)[last]) * contacts.stiffness
            stretch.append(contacts.forces_at(X_max) / self.model.k)
            avalanches.extend(contacts.avalanches)
        density, edges = np.histogram(np.concatenate(stretch), bins=bins, density=True)
        where, size, drop = (np.array([a[i] for a in avalanches]) for i in range(3))
        mean_F = F.mean(axis=0)
        return InteractingQuasistaticResult(
            X=X, F=mean_F, F_std=F.std(axis=0), histogram_edges=edges, histogram=density,
            kinetic_force=float(np.mean(mean_F[kinetic_from <= X])),
            static_force=float(np.max(mean_F)), kinetic_from=float(kinetic_from),
            realisations=realisations, breaks=int(np.sum(size)), parameters=self.parameters(),
            avalanche_X=where, avalanche_size=size.astype(int), force_drop=drop,
            largest_avalanche=float(np.max(size, initial=0) / self.model.n_contacts),
            interface_stiffness=self.interface_stiffness)


@dataclasses.dataclass
class InteractingEQModel(_Interface):
    """EQ contacts coupled through the elastic bodies by the compliance G (module docstring).

    Args:
        model: the contacts: N, k, the threshold and newborn distributions.
        compliance: G, ``(N, N)`` symmetric positive semi-definite, the relative tangential
            surface displacement at contact i per unit force at contact j (length/force).
        coupling: k/(E a) when G comes from :meth:`lattice` (reported only).
        max_rounds: the rounds an avalanche may take before the run stops with an error.
    """

    model: EQModel
    compliance: Array
    coupling: float | None = None
    max_rounds: int = 10_000
    stiffness_matrix: Array = dataclasses.field(init=False, repr=False)

    def __post_init__(self) -> None:
        n = self.model.n_contacts
        G = np.asarray(self.compliance, dtype=float)
        check("compliance", G.shape, G.shape == (n, n), f"must be ({n}, {n}), N = n_contacts")
        check("compliance", "an asymmetric matrix", bool(np.allclose(G, G.T, rtol=1e-12,
                                                                     atol=0.0)),
              "must be symmetric")
        check("max_rounds", self.max_rounds,
              isinstance(self.max_rounds, int) and self.max_rounds >= 1, "must be an integer >= 1")
        try:
            factor = scipy.linalg.cho_factor(np.eye(n) / self.model.k + G)
        except np.linalg.LinAlgError:
            raise ValueError("compliance=<an indefinite matrix> is invalid: 1/k + G must be "
                             "positive definite (G is a compliance)") from None
        M = scipy.linalg.cho_solve(factor, np.eye(n))
        self.compliance, self.stiffness_matrix = G, 0.5 * (M + M.T)

    @classmethod
    def lattice(cls, model: EQModel, coupling: float, nu: float = 0.3, spacing: float = 1.0,
                contact_radius: float | None = None) -> InteractingEQModel:
        """The model's N contacts on a square lattice between two identical bodies.

        Args:
            model: the contacts; N must be a square n².
            coupling: k/(E a), the interaction's strength (0: none, E = ∞).
            nu: Poisson's ratio of the bodies.
            spacing: the lattice spacing a (length).
            contact_radius: the contacts' radius for the self term; None: a/2.
        """
        n = math.isqrt(model.n_contacts)
        check("n_contacts", model.n_contacts, n * n == model.n_contacts,
              "must be a square n² for a lattice")
        check_positive("coupling", coupling, strict=False)
        E = model.k / (coupling * spacing) if coupling > 0 else math.inf
        _, G = lattice_compliance(n, spacing, E, nu, contact_radius)
        return cls(model, G, coupling=float(coupling))

    @property
    def interface_stiffness(self) -> float:
        """S = 1ᵀ M 1: the friction force's slope dF/dX between breaks (≤ N k)."""
        return float(self.stiffness_matrix.sum())

    def parameters(self) -> dict[str, typing.Any]:
        """The contacts' parameters, the coupling and the interface stiffness."""
        return {**self.model.parameters(), "coupling": self.coupling,
                "interface_stiffness": self.interface_stiffness}

    def contacts(self, rng: np.random.Generator) -> CoupledContacts:
        """A fresh realisation, every contact relaxed at X = 0."""
        return CoupledContacts(self.model, self.stiffness_matrix, rng, self.max_rounds)


@dataclasses.dataclass
class LatticeEQModel(_Interface):
    """:class:`InteractingEQModel` on an ``n × n`` lattice between two identical bodies,
    matrix-free (module docstring): the same contacts, draws and events, for N = n² far
    beyond a dense M (16,384 contacts and more).

    Args:
        model, coupling, nu, spacing, contact_radius: as :meth:`InteractingEQModel.lattice`.
        rtol: the relative residual of each conjugate-gradient solve.
        max_rounds: the rounds an avalanche may take before the run stops with an error.
    """

    model: EQModel
    coupling: float
    nu: float = 0.3
    spacing: float = 1.0
    contact_radius: float | None = None
    rtol: float = 1e-10
    max_rounds: int = 10_000
    compliance: LatticeCompliance | None = dataclasses.field(init=False, repr=False)
    stiffness: LatticeStiffness | None = dataclasses.field(init=False, repr=False)

    def __post_init__(self) -> None:
        n = math.isqrt(self.model.n_contacts)
        check("n_contacts", self.model.n_contacts, n * n == self.model.n_contacts,
              "must be a square n² for a lattice")
        check_positive("coupling", self.coupling, strict=False)
        check("max_rounds", self.max_rounds,
              isinstance(self.max_rounds, int) and self.max_rounds >= 1, "must be an integer >= 1")
        if self.coupling > 0:
            E = self.model.k / (self.coupling * self.spacing)
            self.compliance = LatticeCompliance(n, self.spacing, E, self.nu, self.contact_radius)
            self.stiffness = LatticeStiffness(self.model.k, self.compliance, self.rtol)
        else:
            self.compliance = self.stiffness = None

    @property
    def interface_stiffness(self) -> float:
        """S = 1ᵀ M 1: the friction force's slope dF/dX between breaks (≤ N k)."""
        if self.stiffness is None:
            return float(self.model.n_contacts * self.model.k)
        return float(self.stiffness.rate.sum())

    def parameters(self) -> dict[str, typing.Any]:
        """The contacts' parameters, the coupling and the interface stiffness."""
        return {**self.model.parameters(), "coupling": float(self.coupling),
                "interface_stiffness": self.interface_stiffness, "matrix_free": True}

    def contacts(self, rng: np.random.Generator) -> CoupledContacts:
        """A fresh realisation, every contact relaxed at X = 0."""
        stiffness: StiffnessOperator = self.stiffness if self.stiffness is not None else \
            _Diagonal(self.model.k, self.model.n_contacts)  # no interaction: M = k
        return CoupledContacts(self.model, stiffness, rng, self.max_rounds)


class _Diagonal:
    """M = k (no interaction), as a stiffness operator."""

    def __init__(self, k: float, n: int) -> None:
        self.k = k
        self.rate: Array = np.full(n, k)

    def update(self, over: npt.NDArray[np.intp], change: Array) -> tuple[Array, Array]:
        delta: Array = np.zeros(self.rate.size)
        delta[over] = change
        relaxed: Array = np.asarray(-change / self.k, dtype=float)
        return delta, relaxed
