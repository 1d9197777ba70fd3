r"""The elastic instability of the earthquake-like model (Braun (slides), the elastic
instability; Braun & Peyrard 2008, "Modeling friction on a mesoscale: master equation for the
earthquakelike model").

A slider held by the contacts' force F(X) and pulled through a spring K stays in equilibrium,
F(X) = K (X_d − X), while dX/dX_d = K/(K + F'(X)) > 0; it jumps where F'(X) = −K. No jump
happens for any drive if K > K* = −max_X F'(X) (the steepest fall of F), so a stiff drive
slides smoothly and a soft one (K < K*) sticks and slips. F(X) here is the master equation's
transient from all contacts relaxed; for thresholds spread by σ around x_c the fall after the
static peak has slope ~ N k x_c/σ, and K* grows as the spread narrows.

:func:`instability_map` classifies each (K, σ/x_c) by the slip events of the slider pulled
infinitely slowly
(:meth:`~fenicsfriction.studies.multicontact.eq_model.EQModel.spring_quasistatic`): the slider
jumps at the static peak when one event there drops the spring force by more than
``drop_threshold`` of it. K* is the limit N → ∞ of a mean field; a finite interface's own F(X)
fluctuates by ~N^(-1/2), so runs with K near K* may fall on either side
(``benchmarks/bench_multicontact.py`` measures where). K* speaks of the first collective break
only (the map's ``onset_stick_slip``): later, the contacts' phases spread and F(X) flattens,
and the late window's jumps (``sustained_stick_slip``) fade as N grows for every K (the same
benchmark): repeated stick-slip needs contacts that re-form in phase, i.e. ageing, which the
plain model does not have. The spring-driven runs with inertia are kept
beside, with their former speed classification, max Ẋ > 10 v.
"""

from __future__ import annotations

import dataclasses
import typing

import numpy as np

from fenicsfriction.laws import check, check_positive
from fenicsfriction.results import Record
from fenicsfriction.studies.multicontact.eq_model import EQModel
from fenicsfriction.studies.multicontact.master_equation import (
    MasterEquation,
    MasterEquationResult,
)

__all__ = ["CouplingMap", "InstabilityMap", "coupling_map", "critical_stiffness", "instability_map"]


def critical_stiffness(model: EQModel, h: float | None = None) -> float:
    """K* = −max F'(X) of the master equation's transient from all contacts relaxed.

    Args:
        model: the interface (N, k, P_c, R).
        h: the master equation's step; None: σ/50 (F' changes on the scale σ, and the
            scheme's O(h²) error is then ~1e-4 relative).

    The transient is followed to X = 2 x_c + 10 σ, past the first collective break, where F
    falls fastest (later breaks are spread wider).
    """
    return _first_breaks(model, h).K_star


def _first_breaks(model: EQModel, h: float | None) -> MasterEquationResult:
    step = model.x_s_std / 50 if h is None else h
    return MasterEquation(model, step).solve(2 * model.x_s_mean + 10 * model.x_s_std)


@dataclasses.dataclass
class InstabilityMap(Record):
    """Spring-driven runs over K (columns) and the relative spread σ/x_c (rows).

    Attributes:
        K: the drive stiffnesses.
        relative_spread: σ/x_c of the Gaussian thresholds.
        K_star: the critical stiffness of each row (:func:`critical_stiffness`).
        onset_stick_slip: the map's classification, by the events of the infinitely slow
            drive: a jump at the static peak (``onset_drop > drop_threshold``), which K*
            predicts as N → ∞.
        sustained_stick_slip: jumps in the late window (``largest_late_drop >
            drop_threshold``), reported beside: without ageing it fades with N for every K.
        onset_drop: the largest event's drop over the peak force (infinitely slow drive).
        largest_late_drop: the largest late event's drop over the late mean force (the same
            runs).
        jump_fraction: the late advance made in jumps (the same runs).
        fast_slip, max_speed, stuck_fraction, velocity_spread, force_spread: the measures of
            the spring-driven runs with inertia (see
            :class:`~fenicsfriction.studies.multicontact.eq_model.SpringDrivenResult`).
        drop_threshold: the classification's threshold.
        drive: v, the mass, the damping ratio, t_end and the steps per period used.
        parameters: N, k, x_s_mean, seed (the rows vary x_s_std).
    """

    K: np.ndarray
    relative_spread: np.ndarray
    K_star: np.ndarray
    onset_stick_slip: np.ndarray
    sustained_stick_slip: np.ndarray
    onset_drop: np.ndarray
    largest_late_drop: np.ndarray
    jump_fraction: np.ndarray
    fast_slip: np.ndarray
    max_speed: np.ndarray
    stuck_fraction: np.ndarray
    velocity_spread: np.ndarray
    force_spread: np.ndarray
    drop_threshold: float
    drive: dict
    parameters: dict


def instability_map(K: typing.Sequence[float], relative_spread: typing.Sequence[float],
                    n_contacts: int = 300, k: float = 1.0, x_s_mean: float = 1.0,
                    v: float = 1.0, mass: float | None = None, damping_ratio: float = 0.1,
                    drive_distance: float = 6.0, steps_per_period: int = 20,
                    drop_threshold: float = 0.05, seed: int = 0) -> InstabilityMap:
    """Classify spring-driven runs over K × σ/x_c and give K* for each σ.

    Args:
        K: drive stiffnesses (force / length).
        relative_spread: σ/x_c values of the Gaussian thresholds.
        n_contacts, k, x_s_mean: the interface (see :class:`EQModel`).
        v: the drive's speed.
        mass: the slider's mass; None: 1e-5 N k x_c/v², so that the slider's period on its
            contacts, 2π √(m/(N k)) ≈ 0.02 x_c/v, is short against the loading.
        damping_ratio: ζ, the damping η = 2 ζ √(m (N k + K)).
        drive_distance: v t_end beyond the drive's stretch at the static peak,
            F_s/K (F_s of the master equation), in units of x_c; the late window is the
            second half of the run.
        steps_per_period: time steps per period 2π √(m/(N k + K)).
        drop_threshold: the spring-force drop of one late event, over the mean force, that
            makes a run stick-slip; it must exceed a single break's, ~2 (x_c + 3σ)/(N x_c).
        seed: seeds every run (the same thresholds for every K of a row).
    """
    K_values, spreads = np.asarray(K, dtype=float), np.asarray(relative_spread, dtype=float)
    check("K", K, K_values.size > 0 and bool(np.all(K_values > 0)), "must be numbers > 0")
    check("relative_spread", relative_spread,
          spreads.size > 0 and bool(np.all(spreads > 0)), "must be numbers > 0")
    check_positive("damping_ratio", damping_ratio, strict=False)
    check_positive("drive_distance", drive_distance)
    check("steps_per_period", steps_per_period,
          isinstance(steps_per_period, int) and steps_per_period >= 4, "must be an integer >= 4")
    stiffness = n_contacts * k
    m = 1e-5 * stiffness * x_s_mean / v**2 if mass is None else mass
    check_positive("mass", m)
    check("drop_threshold", drop_threshold, 0 < drop_threshold < 1, "must lie in (0, 1)")
    shape = (spreads.size, K_values.size)
    onset_jump, sustained, fast_slip = (np.zeros(shape, dtype=bool) for _ in range(3))
    onset, drop, jumps, speed, stuck, velocity, force = (np.zeros(shape) for _ in range(7))
    K_star = np.zeros(spreads.size)
    for i, spread in enumerate(spreads):
        model = EQModel(n_contacts=n_contacts, k=k, x_s_mean=x_s_mean,
                        x_s_std=float(spread * x_s_mean))
        master = _first_breaks(model, None)
        K_star[i] = master.K_star
        for j, K_j in enumerate(K_values):
            period = 2 * np.pi * np.sqrt(m / (stiffness + K_j))
            t_end = (drive_distance * x_s_mean + master.static_force / K_j) / v
            run = model.spring_driven(K=float(K_j), v=v, mass=m,
                                      damping=2 * damping_ratio * np.sqrt(m * (stiffness + K_j)),
                                      t_end=t_end,
                                      dt=period / steps_per_period, seed=seed)
            slow = model.spring_quasistatic(K=float(K_j), D_max=v * t_end, seed=seed,
                                            drop_threshold=drop_threshold)
            onset_jump[i, j], fast_slip[i, j] = slow.onset_stick_slip, run.fast_slip
            sustained[i, j] = slow.sustained_stick_slip
            onset[i, j], drop[i, j] = slow.onset_drop, slow.largest_late_drop
            jumps[i, j] = slow.jump_fraction
            speed[i, j], stuck[i, j] = run.max_speed, run.stuck_fraction
            velocity[i, j] = run.velocity_spread
            force[i, j] = run.force_spread
    return InstabilityMap(
        K=K_values, relative_spread=spreads, K_star=K_star, onset_stick_slip=onset_jump,
        sustained_stick_slip=sustained, onset_drop=onset, largest_late_drop=drop,
        jump_fraction=jumps, fast_slip=fast_slip,
        max_speed=speed, stuck_fraction=stuck, velocity_spread=velocity, force_spread=force,
        drop_threshold=float(drop_threshold),
        drive={"v": v, "mass": m, "damping_ratio": damping_ratio,
               "drive_distance": drive_distance, "steps_per_period": steps_per_period},
        parameters={"N": n_contacts, "k": k, "x_s_mean": x_s_mean, "seed": seed})


@dataclasses.dataclass
class CouplingMap(Record):
    """Interacting EQ interfaces over the coupling k/(E a) (columns) and the relative threshold
    spread σ/x_c (rows), moved quasistatically (:func:`coupling_map`).

    Attributes:
        coupling: k/(E a) of each column.
        relative_spread: σ/x_c of each row.
        sustained_stick_slip: ``largest_late_drop > drop_threshold``: jumps that go on in
            the late window (coupled contacts keep them, docs/multicontact.md).
        largest_late_drop: the largest fall of the friction force in one avalanche, late
            window, over the kinetic force.
        largest_avalanche: the most breaks in one avalanche, late window, over N.
        mean_avalanche: the mean breaks per avalanche, late window.
        interface_stiffness: S/(N k) of each column (the bodies' compliance in series).
        kinetic_force: the kinetic force over N k x_c.
        drop_threshold, lives: the classification's threshold and the distance moved, in
            contact lives x_c N k/S (the late window is its second half).
        parameters: N, k, x_s_mean, ν, the lattice, the realisations.
    """

    coupling: np.ndarray
    relative_spread: np.ndarray
    sustained_stick_slip: np.ndarray
    largest_late_drop: np.ndarray
    largest_avalanche: np.ndarray
    mean_avalanche: np.ndarray
    interface_stiffness: np.ndarray
    kinetic_force: np.ndarray
    drop_threshold: float
    lives: float
    parameters: dict


def coupling_map(couplings: typing.Sequence[float], relative_spread: typing.Sequence[float],
                 n_side: int = 16, k: float = 1.0, x_s_mean: float = 1.0, nu: float = 0.3,
                 lives: float = 8.0, realisations: int = 1, drop_threshold: float = 0.05,
                 seed: int = 0) -> CouplingMap:
    """Stick-slip of interacting contacts (Braun (slides), "Interaction between contacts: EQ
    simulation") over the coupling and the threshold spread.

    Each interface (:class:`~fenicsfriction.studies.multicontact.interacting.InteractingEQModel`
    on an ``n_side × n_side`` lattice between two identical bodies) is moved quasistatically
    over ``lives`` contact lives; in the second half a run is classified stick-slip when one
    avalanche drops the friction force by more than ``drop_threshold`` of the kinetic force.
    That is what a rigid drive sees: without interaction every break is single and drops F by
    k x_s, 2 x_s/(N x_c) of the kinetic force ~N k x_c/2, so the threshold must stand above
    the largest single break (checked: > 6/N, a threshold of 3 x_c). The spring-driven runs
    (:meth:`InteractingEQModel.spring_driven`) are the dynamic counterpart; their late-time
    measures do not separate the regimes on such small lattices (see
    :class:`~fenicsfriction.studies.multicontact.eq_model.SpringDrivenResult`).

    Args:
        couplings: k/(E a) values, >= 0 (0: no interaction).
        relative_spread: σ/x_c values of the Gaussian thresholds, > 0.
        n_side: the lattice's side (N = n_side² contacts).
        k, x_s_mean: the contacts' stiffness and mean threshold.
        nu: Poisson's ratio of the bodies.
        lives: the distance moved, in contact lives x_c N k/S.
        realisations: independent interfaces per cell (their largest drop counts).
        drop_threshold: the force drop, over the kinetic force, that makes a run stick-slip.
        seed: seeds every cell (the same thresholds for every coupling of a row).
    """
    from fenicsfriction.studies.multicontact.interacting import InteractingEQModel

    values, spreads = np.asarray(couplings, dtype=float), np.asarray(relative_spread, dtype=float)
    check("couplings", couplings, values.size > 0 and bool(np.all(values >= 0)),
          "must be numbers >= 0")
    check("relative_spread", relative_spread,
          spreads.size > 0 and bool(np.all(spreads > 0)), "must be numbers > 0")
    check("n_side", n_side, isinstance(n_side, int) and n_side >= 2, "must be an integer >= 2")
    check_positive("lives", lives)
    n = n_side**2
    check("drop_threshold", drop_threshold,
          isinstance(drop_threshold, (int, float)) and 6.0 / n < drop_threshold < 1.0,
          f"must lie in (6/N, 1) = ({6.0 / n:.3g}, 1): one break drops F by 2 x_s/(N x_c)")
    shape = (spreads.size, values.size)
    drop, largest, mean, kinetic = (np.zeros(shape) for _ in range(4))
    stiffness = np.zeros(values.size)
    for i, spread in enumerate(spreads):
        model = EQModel(n_contacts=n, k=k, x_s_mean=x_s_mean, x_s_std=float(spread * x_s_mean))
        for j, coupling in enumerate(values):
            interface = InteractingEQModel.lattice(model, float(coupling), nu=nu)
            stiffness[j] = interface.interface_stiffness / (n * k)
            X_max = lives * x_s_mean / stiffness[j]
            run = interface.quasistatic(X_max, realisations=realisations, seed=seed)
            late = run.avalanche_X >= run.kinetic_from
            drop[i, j] = np.max(run.force_drop[late], initial=0.0) / run.kinetic_force
            largest[i, j] = np.max(run.avalanche_size[late], initial=0) / n
            mean[i, j] = np.mean(run.avalanche_size[late]) if np.any(late) else 0.0
            kinetic[i, j] = run.kinetic_force / (n * k * x_s_mean)
    return CouplingMap(
        coupling=values, relative_spread=spreads, sustained_stick_slip=drop > drop_threshold,
        largest_late_drop=drop, largest_avalanche=largest, mean_avalanche=mean,
        interface_stiffness=stiffness, kinetic_force=kinetic,
        drop_threshold=float(drop_threshold), lives=float(lives),
        parameters={"N": n, "k": k, "x_s_mean": x_s_mean, "nu": nu, "n_side": n_side,
                    "realisations": realisations, "seed": seed})
