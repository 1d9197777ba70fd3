"""What the benchmark scripts share: the ``--out`` flag, saving a figure, the best of repeated
timings, and the record of what a run ran on and how it solved (:func:`environment`), which
every benchmark writes into its JSON (:func:`write_summary`)."""

from __future__ import annotations

import argparse
import gc
import os
import pathlib
import resource
import sys
import time
import typing

from mpi4py import MPI
from petsc4py import PETSc

from fenicsfriction import results

#: the load average (1, 5, 15 min) when the benchmark started: this module is imported first
LOAD_AT_START = os.getloadavg()

#: PETSc events counted in every record: which factorisations, preconditioners and Krylov
#: solves really ran (an event that never ran is left out)
PATH_EVENTS = ("SNESSolve", "TSStep", "KSPSolve", "KSPGMRESOrthog", "PCSetUp", "PCApply",
               "MatLUFactorSym", "MatLUFactorNum", "MatCholFctrSym", "MatCholFctrNum",
               "MatSolve", "PCSetUp_GAMG+", "  GAMG PtAP", "EPSSolve", "PEPSolve")

# PETSc's event log, started before the run creates any object (every benchmark imports this
# module first), so that the record can say which factorisations and preconditioners ran
PETSc.Log.begin()

_noted: list[dict[str, typing.Any]] = []
_stages: list[str] = ["Main Stage"]


def parser(doc: str | None) -> argparse.ArgumentParser:
    """An argument parser described by the first line of ``doc``, with ``--out``."""
    flags = argparse.ArgumentParser(description=(doc or "").splitlines()[0])
    flags.add_argument("--out", type=pathlib.Path, default=pathlib.Path("results/benchmarks"),
                       help="output folder (default: results/benchmarks)")
    return flags


def save(fig: typing.Any, path: pathlib.Path, dpi: int) -> None:
    """Lay out, write and close a matplotlib figure."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def best_time(call: typing.Callable[[], typing.Any], repeats: int) -> tuple[float, typing.Any]:
    """The shortest of ``repeats`` wall times of ``call()`` (noise only ever adds time), and
    the last call's value."""
    times, value = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        value = call()
        times.append(time.perf_counter() - t0)
    return min(times), value


def _ksp_path(ksp: typing.Any) -> dict[str, typing.Any]:
    """A KSP's type, its PC's type and, below it, the factor package, the AMG flavour or the
    ``PCPYTHON`` context (and the KSP that context solves with), as PETSc reports them."""
    pc = ksp.getPC()
    path: dict[str, typing.Any] = {"prefix": ksp.getOptionsPrefix(), "ksp": ksp.getType(),
                                   "pc": pc.getType()}
    if path["pc"] in ("lu", "cholesky", "ilu", "icc"):
        path["factor_package"] = pc.getFactorSolverType()
    elif path["pc"] == "hypre":
        path["hypre"] = pc.getHYPREType()
    elif path["pc"] == "python":
        context = pc.getPythonContext()
        path["python_context"] = type(context).__qualname__
        inner = getattr(context, "ksp", None)
        if inner is not None and hasattr(inner, "getPC"):
            path["inner"] = _ksp_path(inner)
    return path


def solver_path(solver: typing.Any) -> dict[str, typing.Any]:
    """How ``solver`` solves, read back from its PETSc objects: a TS, SNES, KSP, EPS or PEP, or
    a fenicsfriction solver holding one (as ``ts``, ``snes``, ``pep``, ``eps`` or ``ksp``)."""
    kind = type(solver).__name__
    if kind == "TS":
        return {"ts": solver.getType(), **solver_path(solver.getSNES())}
    if kind == "SNES":
        return {"snes": solver.getType(), **_ksp_path(solver.getKSP())}
    if kind in ("EPS", "PEP"):
        return {kind.lower(): solver.getType(), "st": solver.getST().getType(),
                **_ksp_path(solver.getST().getKSP())}
    if kind == "KSP":
        return _ksp_path(solver)
    for name in ("ts", "snes", "pep", "eps", "ksp"):
        inner = getattr(solver, name, None)
        if inner is not None and hasattr(inner, "getType"):
            return {"solver": type(solver).__qualname__, **solver_path(inner)}
    return {"solver": type(solver).__qualname__, "unknown": True}


def log_stage(name: str) -> typing.Any:
    """The PETSc log stage ``name``; the events of every stage made here are counted in the
    record (:func:`environment`), not only those of the main stage."""
    if name not in _stages:
        _stages.append(name)
    return PETSc.Log.Stage(name)


def note_solver(solver: typing.Any) -> None:
    """Read ``solver``'s path now (it may be gone when the JSON is written); each distinct
    path is recorded once."""
    path = solver_path(solver)
    if path not in _noted:
        _noted.append(path)


def _covered(path: dict[str, typing.Any], paths: list[dict[str, typing.Any]]) -> bool:
    """Whether ``path`` (a live object's) is one of ``paths`` or the inner KSP of one."""
    def same(a: dict, b: dict) -> bool:
        return {k: v for k, v in a.items() if k != "solver"} == {
            k: v for k, v in b.items() if k != "solver"}
    return any(same(path, p) or same(path, p.get("inner", {})) for p in paths)


def _live_solver_paths(known: list[dict[str, typing.Any]]) -> list[dict[str, typing.Any]]:
    """The paths of the PETSc solvers still alive that ``known`` does not already hold."""
    kinds: tuple[type, ...] = (PETSc.TS, PETSc.SNES, PETSc.KSP)
    slepc = sys.modules.get("slepc4py.SLEPc")
    if slepc is not None:
        kinds += (slepc.EPS, slepc.PEP)
    paths = list(known)
    for obj in gc.get_objects():
        if isinstance(obj, kinds) and obj.handle:
            try:
                path = solver_path(obj)
            except Exception:  # an object half set up tells nothing
                continue
            if not _covered(path, paths):
                paths.append(path)
    return paths


def _event_counts() -> dict[str, dict[str, float]]:
    """Rank 0's count and time of each of :data:`PATH_EVENTS`, summed over the log stages."""
    log = PETSc.Log
    counts = {}
    for name in PATH_EVENTS:
        info = [log.Event(name).getPerfInfo(log.Stage(stage)) for stage in _stages]
        count = sum(int(i["count"]) for i in info)
        if count > 0:
            counts[name] = {"count": count, "time_s": sum(float(i["time"]) for i in info)}
    return counts


def environment(comm: MPI.Comm = MPI.COMM_WORLD, solvers: typing.Iterable = ()
                ) -> dict[str, typing.Any]:
    """The run's record: ranks, BLAS and versions (:func:`fenicsfriction.results.environment`),
    the peak resident memory of every rank (MiB, ``getrusage``'s ``ru_maxrss``), the load
    average at the start and now (other processes on the machine slow every timing), and
    the solver path: each of ``solvers``, those noted with :func:`note_solver` and the PETSc
    solvers still alive, as PETSc reports them, with the PETSc events that ran (rank 0's
    counts; the log starts when this module is imported)."""
    for solver in solvers:
        note_solver(solver)
    peak_mib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # KiB on Linux
    paths = _live_solver_paths(_noted)
    return {**results.environment(comm),
            "peak_memory_mib_per_rank": comm.allgather(peak_mib),
            "load_average": {"start": list(LOAD_AT_START), "end": list(os.getloadavg())},
            "solver_paths": paths, "petsc_events": _event_counts()}


def write_summary(path: pathlib.Path, data: dict[str, typing.Any],
                  comm: MPI.Comm = MPI.COMM_WORLD, solvers: typing.Iterable = ()) -> None:
    """Write ``data`` as JSON on rank 0 with the run's :func:`environment` under
    ``"environment"``."""
    results.write_json(path, {**data, "environment": environment(comm, solvers)}, comm)
