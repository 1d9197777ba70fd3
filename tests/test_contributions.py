r"""Mode contributions (fenicsfriction.cea.contributions): the free-interface modes of each body
and their shares of the coupled system's complex modes, on the block on an elastic slab (two
bodies, node-to-segment contact, 4 × 3 Q1 block on a 8 × 1 slab) and the block on its rigid
belt (one body, the interface an integral).
"""

import itertools

from mpi4py import MPI

import numpy as np
import pytest

import fenicsfriction as ff
from fenicsfriction.cea.contributions import FreeInterfaceModes, plot_contributions
from fenicsfriction.stability import Loci, StabilitySolver
from fenicsfriction.studies.block.data import CONTACT
from fenicsfriction.studies.block.slab import BLOCK, SLAB

COMM = MPI.COMM_WORLD
MAX_MODULUS = 3e4  # [1/s]: the block's six modes (docs/block-stability.md)
EPS_MACH = np.finfo(float).eps
_COUNTER = itertools.count()


def prefix(name: str) -> str:
    """A PETSc options prefix no other solver of the run uses (ranks count alike)."""
    return f"contrib{next(_COUNTER)}{name}_"


def sliding(scene, mu: float):
    """The scene built with friction, in steady sliding at ``mu`` (steps of at most 0.05)."""
    model = scene.build(COMM, with_friction=True)
    model.initial_guess()
    steady = ff.SteadySolver(model.residual, prefix=prefix("steady"),
                             options=model.solver_options())
    ff.continuation(steady, model.mu, np.linspace(0.0, mu, int(np.ceil(mu / 0.05)) + 1)[1:])
    return model, steady


def slab_bodies(model) -> dict:
    return {"block": model.cell_tags.find(BLOCK), "slab": model.cell_tags.find(SLAB)}


def all_cells(model) -> np.ndarray:
    cells = model.msh.topology.index_map(model.msh.topology.dim)
    return np.arange(cells.size_local + cells.num_ghosts, dtype=np.int32)


@pytest.fixture(scope="module")
def slab_at_0_2():
    """The block on the default slab (slab_E = E) sliding at μ = 0.2, below the flutter onset
    (0.2-0.25), its modes in the disc, and all the free-interface modes of both bodies."""
    model, steady = sliding(ff.BlockOnSlab(), 0.2)
    solver = StabilitySolver(model.residual, prefix=prefix("pep"))
    modes = solver.solve(MAX_MODULUS)
    fim = FreeInterfaceModes(model.residual, slab_bodies(model), modes=None,
                             prefix=prefix("fim"))
    return model, steady, solver, modes, fim


def test_contributions_of_every_body_mode_sum_to_one(slab_at_0_2):
    """With every mode of both bodies (40 block dofs, 18 free slab dofs) the shares of each
    body sum to its kinetic share w_bᴴ M_b w_b / wᴴ M w, computed directly (completeness of
    the M_b-orthonormal modes), and the bodies' shares sum to 1 (M is block diagonal between
    the bodies and zero on the clamped dofs): the unexplained part is round-off. The sums are
    of ≤ 40 terms of size ≤ 1 computed to the EPS's tolerance 1e-10 (the modes' M-orthogonality
    holds to it): tolerance 1e-8; measured ≤ 1e-13."""
    _, _, _, modes, fim = slab_at_0_2
    assert [b.basis.size for b in fim.bodies] == [40, 18]
    for mode in modes:
        record = fim.contributions(mode, min_share=0.0)
        assert record.others == 0.0
        for body in ("block", "slab"):
            total = sum(c.share for c in record.contributions if c.body == body)
            assert total == pytest.approx(record.bodies[body], abs=1e-8)
        assert sum(record.bodies.values()) == pytest.approx(1.0, abs=1e-8)
        assert abs(record.unexplained) < 1e-8


def test_the_shares_do_not_depend_on_the_modes_phase(slab_at_0_2):
    """An eigenvector is known up to a complex factor: w and e^{iθ} w (θ = 1 rad, which mixes
    its real and imaginary parts) have the same shares, each |q|² the same to round-off
    (1e-12 of the total asked)."""
    import dataclasses
    _, _, _, modes, fim = slab_at_0_2
    for mode in modes:
        turned = dataclasses.replace(mode, vector=np.exp(1j) * mode.vector)
        a, b = (fim.contributions(m, min_share=0.0) for m in (mode, turned))
        shares = {(c.body, c.mode): c.share for c in a.contributions}
        assert len(b.contributions) == len(shares)
        for c in b.contributions:
            assert c.share == pytest.approx(shares[(c.body, c.mode)], abs=1e-12)


def test_a_truncated_basis_leaves_the_rest_unexplained(slab_at_0_2):
    """With a few modes of each body the unexplained part is what the basis misses, between 0
    and 1, and listed shares + ``others`` + ``unexplained`` = 1. The pair near 880 Hz lives in
    the block's three modes below 1 Hz (unexplained 1.8e-3 with those alone, measured); the
    block's three elastic complex modes (3-4.4 kHz) are outside them (unexplained ≈ 1), and
    come in as modes are added: measured max 2.2e-3 with 6 modes a body, 5.5e-4 with 10,
    4e-5 with 20, 8e-12 with all."""
    model, _, _, modes, _ = slab_at_0_2
    unexplained = {}
    for count in (3, 10):
        fim = FreeInterfaceModes(model.residual, slab_bodies(model), modes=count,
                                 prefix=prefix(f"trunc{count}"))
        records = [fim.contributions(mode) for mode in modes]
        for record in records:
            total = sum(c.share for c in record.contributions) + record.others \
                + record.unexplained
            assert total == pytest.approx(1.0, abs=1e-12)
            assert -1e-8 < record.unexplained < 1.0
        unexplained[count] = np.array([r.unexplained for r in records])
    by_frequency = FreeInterfaceModes(model.residual, slab_bodies(model), max_frequency=5000.0,
                                      prefix=prefix("fmax"))
    # the block's modes below 5 kHz: 0, 0, 0.79, 3140, 3990, 4360 Hz; the slab's first: 6451
    assert [b.basis.size for b in by_frequency.bodies] == [6, 0]
    assert by_frequency.contributions(modes[1]).unexplained < 3e-3
    assert np.all(unexplained[3][1:3] < 3e-3)
    assert np.all(unexplained[3][3:] > 0.99)
    assert np.all(unexplained[10] < 1e-3)


def test_the_coalescing_pair_is_made_of_the_blocks_rigid_modes(slab_at_0_2):
    """The two modes that coalesce at the flutter onset (bisected to 1e-3 in [0.2, 0.3]), taken
    at the stable end where they are apart, are each ≥ 90 % the block's modes below 1 Hz (its
    two rigid modes, vertical translation and rotation free but for the interface, and the
    driver spring's 0.79 Hz): the contact springs make them the 880 Hz pair. The slab, as
    stiff as the block, takes < 5 % of each (measured 96-97 % and 0.04 %)."""
    model, steady, solver, modes, fim = slab_at_0_2
    loci = Loci(steady, solver, model.mu, MAX_MODULUS)
    tracked = {}
    loci.follow([0.2], on_step=lambda record, found: tracked.update({m.ident: m for m in found}))
    onset = loci.onset(0.2, 0.3, tol=1e-3, reference=list(tracked.values()))
    for colliding in onset.colliding:
        record = fim.contributions(tracked[colliding["mode"]], min_share=0.0)
        rigid = sum(c.share for c in record.contributions if c.body == "block"
                    and c.frequency < 1.0)
        assert rigid > 0.9, record.table()
        assert record.bodies["slab"] < 0.05


def test_the_blocks_free_modes_are_the_same_on_the_belt_and_on_the_slab():
    """The block alone is the same body in both scenes: on the belt its stiffness is K̄ less
    the contact integral (facet tag CONTACT), on the slab the integrals over the block's cells
    (the contact is a coupling). Both give 40 modes: two rigid ones (|ω| below round-off of the
    elastic ones), the driver spring's sqrt(K_x/M) to 1e-6 (the elastic modes correct it by
    about K_x / (M ω_1²) ≈ 6e-8) and the elastic ones equal to the EPS tolerance (1e-10,
    relative; tolerance 1e-8)."""
    belt, _ = sliding(ff.BlockOnBelt(degree=1, contact_quadrature="nodal"), 0.1)
    on_belt = FreeInterfaceModes(belt.residual, {"block": all_cells(belt)}, interface=[CONTACT],
                                 modes=None, prefix=prefix("belt"))
    slab = ff.BlockOnSlab().build(COMM, with_friction=True)
    on_slab = FreeInterfaceModes(slab.residual, slab_bodies(slab), modes=None,
                                 prefix=prefix("slab"))
    a, b = on_belt.bodies[0].basis.omega2, on_slab.bodies[0].basis.omega2
    assert len(a) == len(b) == 40
    assert np.all(abs(a[:2]) < 1e-9 * a[-1]) and np.all(abs(b[:2]) < 1e-9 * b[-1])
    s = belt.scene
    spring = np.sqrt(s.K_x / s.mass)
    assert np.sqrt(a[2]) == pytest.approx(spring, rel=1e-6)
    assert np.sqrt(b[2]) == pytest.approx(spring, rel=1e-6)
    assert a[3:] == pytest.approx(b[3:], rel=1e-8)


def test_the_records_are_json_and_the_chart_is_drawn(slab_at_0_2, shared_tmp_path):
    """Each record's ``to_json`` is plain data naming the body modes; the bar chart is a PNG."""
    _, _, _, modes, fim = slab_at_0_2
    records = [fim.contributions(mode) for mode in modes]
    data = records[1].to_json()
    assert {"mode", "value", "frequency", "contributions", "others", "unexplained",
            "bodies"} <= set(data)
    assert data["contributions"][0]["body"] == "block"
    assert "block mode" in records[1].table()
    path = shared_tmp_path / "contributions.png"
    plot_contributions(records, path)
    COMM.Barrier()
    assert path.read_bytes()[:4] == b"\x89PNG"
