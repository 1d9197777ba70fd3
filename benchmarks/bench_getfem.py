"""Peer benchmark: the block's steady continuation in fenicsfriction and in GetFEM 5.4.

The same problem in both (Martins & Oden's 1986 block on a belt, plane strain, μ = 0 → 1.5 in
30 steps, each solve started from the last converged state):

* the same mesh: the regular 4r × 3r grid of nine-node (Q2) quadrilaterals on L × H;
* the same weak form: Hooke's law (Gauss 3 × 3, GetFEM's ``IM_GAUSS_PARALLELEPIPED(2,4)``),
  the weight as a body force, normal compliance c_n d^m_n and the C¹-regularised Coulomb
  friction on the base (Gauss rule of degree 8, as ``QUADRATURE["gauss"](2)``), the driving
  spring K_x on the x-displacement of the node (0, H/2), all times the breadth B0. GetFEM
  states it in its generic weak-form language (``add_linear_term``/``add_nonlinear_term``);
* the same stopping rule. GetFEM's ``model.solve`` tests an absolute residual tolerance that
  cannot be reached on fine meshes (the residual's round-off floor ‖J‖‖u‖ε grows with the
  mesh: at 6,370 dofs it stalls at 50 iterations for every μ), so GetFEM's Newton is driven
  here by the loop our SNES runs: ``build_all`` (its tangent matrix and residual), GetFEM's
  own MUMPS (``linsolve_mumps``), stop when ‖R‖₂ ≤ max(atol, √n ε‖J‖∞‖u‖∞) or ‖R‖₂ ≤ 1e-10 ‖R₀‖₂
  (:class:`fenicsfriction.petsc_options.RoundoffConvergence`), atol = 1e-10 × the weight.

fenicsfriction is timed with its defaults (the bulk condensed onto the contact interface,
the secant predictor) and with the LU-per-iteration path (``linear_solver="lu"``, no predictor:
the same algorithm as the GetFEM loop). GetFEM runs in a subprocess: both libraries link
MUMPS, and two copies of its symbols in one process are not safe. Timings exclude each side's
set-up (mesh, compiled forms; reported apart) and are the best of ``--repeats``; the
agreement is the spring force (μW by statics) and the maximum penetration at every μ.

Writes ``bench_getfem.json`` and ``bench_getfem.png``, prints a markdown table.
"""

from __future__ import annotations

import json
import logging
import subprocess
import sys
import time

import numpy as np
from _common import note_solver, save, write_summary
from _common import parser as benchmark_parser

MU_STEPS = np.linspace(0.0, 1.5, 31)
RTOL = 1e-10
WEIGHT = 450.0  # the block's, BlockOnBelt().weight


def getfem_worker(refine: int, repeats: int) -> dict:
    """The continuation in GetFEM (run in its own process)."""
    import getfem as gf

    from fenicsfriction.elasticity import lame
    from fenicsfriction.studies.block import BlockOnBelt

    gf.util_trace_level(0)
    gf.util_warning_level(0)
    s = BlockOnBelt(refine=refine)
    t0 = time.perf_counter()
    m = gf.Mesh("cartesian", np.linspace(0, s.L, 4 * refine + 1),
                np.linspace(0, s.H, 3 * refine + 1))
    CONTACT = 1
    m.set_region(CONTACT, m.outer_faces_with_direction([0.0, -1.0], 0.01))
    mf = gf.MeshFem(m, 2)
    mf.set_fem(gf.Fem("FEM_QK(2,2)"))
    mim = gf.MeshIm(m, gf.Integ("IM_GAUSS_PARALLELEPIPED(2,4)"))
    mim_contact = gf.MeshIm(m, gf.Integ("IM_GAUSS_PARALLELEPIPED(2,8)"))
    md = gf.Model("real")
    md.add_fem_variable("u", mf)
    lmbda, shear = lame(s.E, s.nu)
    data = {"B0": s.B0, "lam": lmbda, "G": shear, "c_n": s.law.c_n, "m_n": s.law.m_n, "g": s.law.g,
            "eps": s.law.eps, "mu": 0.0}
    for name, value in data.items():
        md.add_initialized_data(name, [value])
    md.add_initialized_data("b", [0.0, -s.weight / (s.L * s.H * s.B0)])
    md.add_initialized_data("U", [s.belt_direction * s.belt_speed, 0.0])
    md.add_linear_term(mim, "B0*(lam*Div_u*Div_Test_u + 2*G*Sym(Grad_u):Grad_Test_u)"
                            " - B0*b.Test_u")
    # w = u̇_T - U_T = -U at steady sliding; C¹ regularisation: φ'(w) = w / max(|w|, ε)
    md.add_nonlinear_term(
        mim_contact, "B0*c_n*pow(pos_part(u.Normal-g), m_n)*(Test_u.Normal)"
                     " + B0*mu*c_n*pow(pos_part(u.Normal-g), m_n)"
                     "*((-U)/max(Norm(-U), eps)).(Test_u-(Test_u.Normal)*Normal)", CONTACT)
    nodes = mf.basic_dof_nodes()
    n = mf.nbdof()
    at_spring = (np.abs(nodes[0]) < 1e-9) & (np.abs(nodes[1] - s.spring_height) < 1e-9)
    spring_dof = int(np.flatnonzero(at_spring)[0])  # the x component comes first
    K = gf.Spmat("empty", n, n)
    K[spring_dof, spring_dof] = s.K_x
    md.add_explicit_matrix("u", "u", K)
    base_y = (np.abs(nodes[1]) < 1e-9) & (np.arange(n) % 2 == 1)
    setup = time.perf_counter() - t0
    atol = 1e-10 * s.contact_pressure * s.L * s.B0
    eps_mach = np.finfo(float).eps

    def newton() -> int:
        r0 = None
        for it in range(51):
            md.assembly("build_all")
            R = md.rhs()  # -residual
            J = md.tangent_matrix()
            norm = np.linalg.norm(R)
            u = md.variable("u")
            J.to_csc()
            row_of_value = J.csc_ind()[1]
            J_inf = np.bincount(row_of_value, np.abs(J.csc_val()), n).max()  # max row sum
            floor = np.sqrt(n) * eps_mach * J_inf * np.abs(u).max()
            r0 = norm if r0 is None else r0
            if norm <= max(atol, floor) or (it > 0 and norm <= RTOL * r0):
                return it
            md.set_variable("u", u + gf.linsolve_mumps(J, R).ravel())
        raise RuntimeError(f"GetFEM Newton did not converge at mu = {md.variable('mu')}")

    best = None
    for _ in range(repeats):
        d0 = (s.contact_pressure / s.law.c_n) ** (1 / s.law.m_n)
        md.set_variable("u", np.tile([0.0, -(d0 + s.law.g)], n // 2))
        steps = []
        for mu in MU_STEPS:
            md.set_variable("mu", [mu])
            t0 = time.perf_counter()
            iterations = newton()
            u = md.variable("u")
            steps.append({"mu": float(mu), "newton_iterations": iterations,
                          "wall_time_s": time.perf_counter() - t0,
                          "spring_force": float(-s.K_x * u[spring_dof]),
                          "max_penetration": float(np.maximum(-u[base_y] - s.law.g, 0).max())})
        total = sum(step["wall_time_s"] for step in steps)
        if best is None or total < best["solve_time_s"]:
            best = {"solve_time_s": total, "steps": steps}
    return {"dofs": n, "setup_s": setup, **best}


def fenicsfriction_run(refine: int, repeats: int) -> dict:
    from mpi4py import MPI

    import fenicsfriction as ff

    t0 = time.perf_counter()
    model = ff.BlockOnBelt(refine=refine).build(MPI.COMM_SELF, with_friction=True)
    default = ff.SteadySolver(model.residual, prefix=f"gf{refine}_",
                              options=model.solver_options())
    lu = ff.SteadySolver(model.residual, prefix=f"gflu{refine}_", linear_solver="lu",
                         options={**model.solver_options(), "ksp_type": "preonly",
                                  "pc_type": "lu"})
    setup = time.perf_counter() - t0
    out = {"dofs": model.V.dofmap.index_map.size_global * 2, "setup_s": setup}
    for name, solver, predictor in (("default", default, "secant"), ("lu", lu, "none")):
        best = None
        for _ in range(repeats):
            model.mu.value = 0.0
            model.initial_guess()
            records = ff.continuation(solver, model.mu, MU_STEPS, observe=model.quantities,
                                      predictor=predictor)
            total = sum(r["wall_time_s"] for r in records)
            note_solver(solver)
            if best is None or total < best[0]:
                best = (total, records)
        out[name] = {"solve_time_s": best[0], "steps": [
            {"mu": r["mu"], "newton_iterations": r["newton_iterations"],
             "wall_time_s": r["wall_time_s"], "spring_force": r["spring_force"],
             "max_penetration": r["max_penetration"]} for r in best[1]]}
    return out


def agreement(a: list[dict], b: list[dict], key: str, scale: float | None = None) -> float:
    """max over the steps of |a - b| / scale (default: relative to b)."""
    return max(abs(x[key] - y[key]) / (scale or abs(y[key])) for x, y in zip(a, b, strict=True))


def plot(rows: list[dict], path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    dofs = [r["dofs"] for r in rows]
    fig, (ax_t, ax_r) = plt.subplots(1, 2, figsize=(11, 4.5))
    for key, label, marker in (("ff_default_s", "fenicsfriction (default)", "o-"),
                               ("ff_lu_s", "fenicsfriction (LU per iteration)", "s--"),
                               ("getfem_s", "GetFEM 5.4 (LU per iteration)", "^-")):
        ax_t.loglog(dofs, [r[key] for r in rows], marker, label=label)
    ax_t.set(xlabel="dofs", ylabel="continuation wall time [s]",
             title="Block steady continuation, 31 μ steps")
    ax_t.legend()
    ax_t.grid(True, which="both", alpha=0.3)
    ax_r.semilogx(dofs, [r["getfem_s"] / r["ff_default_s"] for r in rows], "o-",
                  label="GetFEM ÷ fenicsfriction (default)")
    ax_r.semilogx(dofs, [r["getfem_s"] / r["ff_lu_s"] for r in rows], "s--",
                  label="GetFEM ÷ fenicsfriction (LU per iteration)")
    ax_r.axhline(1.0, color="k", lw=0.8)
    ax_r.set(xlabel="dofs", ylabel="ratio of wall times", title="> 1: fenicsfriction faster")
    ax_r.legend()
    ax_r.grid(True, which="both", alpha=0.3)
    save(fig, path, dpi=110)


def main() -> None:
    if len(sys.argv) == 4 and sys.argv[1] == "--getfem-worker":
        print(json.dumps(getfem_worker(int(sys.argv[2]), int(sys.argv[3]))))
        return
    parser = benchmark_parser(__doc__)
    parser.add_argument("--refine", type=int, nargs="+", default=[1, 4, 16, 32],
                        help="refinement factors (default 1 4 16 32: 126, 1,650, 25,026 and "
                             "99,202 dofs)")
    parser.add_argument("--repeats", type=int, default=3, help="best of (default 3; 1 above "
                                                              "25,026 dofs)")
    args = parser.parse_args()
    logging.getLogger("ffcx").setLevel(logging.WARNING)
    logging.getLogger().addFilter(lambda record: record.levelno >= logging.WARNING)
    from fenicsfriction.results import get_logger

    say = get_logger().info
    rows = []
    for refine in args.refine:
        repeats = args.repeats if refine <= 16 else 1
        ff_run = fenicsfriction_run(refine, repeats)
        done = subprocess.run([sys.executable, __file__, "--getfem-worker", str(refine),
                               str(repeats)], capture_output=True, text=True, check=True)
        gf_run = json.loads(done.stdout.strip().splitlines()[-1])
        row = {"refine": refine, "dofs": ff_run["dofs"], "getfem_dofs": gf_run["dofs"],
               "ff_default_s": ff_run["default"]["solve_time_s"],
               "ff_lu_s": ff_run["lu"]["solve_time_s"], "getfem_s": gf_run["solve_time_s"],
               "ff_setup_s": ff_run["setup_s"], "getfem_setup_s": gf_run["setup_s"],
               "newton": {k: sum(st["newton_iterations"] for st in v["steps"])
                          for k, v in (("ff_default", ff_run["default"]),
                                       ("ff_lu", ff_run["lu"]), ("getfem", gf_run))},
               # relative to the weight (the spring force is 0 at μ = 0)
               "spring_force_agreement": agreement(gf_run["steps"], ff_run["lu"]["steps"],
                                                   "spring_force", WEIGHT),
               "max_penetration_agreement": agreement(gf_run["steps"], ff_run["lu"]["steps"],
                                                      "max_penetration"),
               "fenicsfriction": ff_run, "getfem": gf_run}
        say(f"{row['dofs']} dofs: fenicsfriction {row['ff_default_s']:.2f} s (LU path "
            f"{row['ff_lu_s']:.2f} s), GetFEM {row['getfem_s']:.2f} s")
        rows.append(row)
    args.out.mkdir(parents=True, exist_ok=True)
    write_summary(args.out / "bench_getfem.json", {"mu_steps": MU_STEPS.tolist(), "rows": rows})
    plot(rows, args.out / "bench_getfem.png")
    print("| dofs | fenicsfriction [s] | its | LU path [s] | its | GetFEM 5.4 [s] | its "
          "| GetFEM ÷ fenicsfriction | GetFEM ÷ LU path | agreement: spring force ÷ W, "
          "max penetration |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        n = r["newton"]
        print(f"| {r['dofs']} | {r['ff_default_s']:.3f} | {n['ff_default']} | {r['ff_lu_s']:.3f} "
              f"| {n['ff_lu']} | {r['getfem_s']:.3f} | {n['getfem']} "
              f"| **{r['getfem_s'] / r['ff_default_s']:.1f}** | {r['getfem_s'] / r['ff_lu_s']:.1f} "
              f"| {r['spring_force_agreement']:.0e}, {r['max_penetration_agreement']:.0e} |")


if __name__ == "__main__":
    main()
