r"""The disc of the brake scenes (fenicsfriction.discs): what the planted-bug runs found
checked only by the 4-minute pin-on-disc study (tests/planted_bugs.toml, room "brake").

:func:`~fenicsfriction.discs.disc_groups` sorts the OpenCASCADE disc's faces by their bounding
boxes; each group is checked here by its area, in closed form: the hub :math:`2\pi r_i t`, the
rim :math:`2\pi r_o t`, the top and bottom faces :math:`\pi(r_o^2 - r_i^2)` (OpenCASCADE's
surface integrals of the exact geometry: 1e-9 relative), the top at z = 0 and the bottom
at z = -t. No mesh is made.
"""

import math

import pytest

from fenicsfriction.discs import (
    DISC_BOTTOM,
    DISC_HUB,
    DISC_RIM,
    DISC_TOP,
    Disc,
    add_disc,
    disc_groups,
)

gmsh = pytest.importorskip("gmsh")

#: gmsh's geometry alone, no MPI: every rank of the MPI pass would repeat it
pytestmark = pytest.mark.sequential


def test_the_free_discs_faces_are_grouped_by_what_they_are():
    disc = Disc(inner_radius=0.03, outer_radius=0.11, thickness=0.013)
    owns = not getattr(gmsh, "isInitialized", lambda: False)()
    if owns:
        gmsh.initialize(readConfigFiles=False)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("disc_groups_check")
    try:
        volume = add_disc(gmsh, disc)
        gmsh.model.occ.synchronize()
        groups = disc_groups(gmsh, disc, volume)
        area = {tag: sum(gmsh.model.occ.getMass(2, face) for face in faces)
                for tag, faces in groups.items()}
        height = {tag: [gmsh.model.occ.getCenterOfMass(2, face)[2] for face in groups[tag]]
                  for tag in (DISC_TOP, DISC_BOTTOM)}
    finally:
        gmsh.model.remove()
        if owns:
            gmsh.finalize()
    r_i, r_o, t = disc.inner_radius, disc.outer_radius, disc.thickness
    assert area[DISC_HUB] == pytest.approx(2 * math.pi * r_i * t, rel=1e-9)
    assert area[DISC_RIM] == pytest.approx(2 * math.pi * r_o * t, rel=1e-9)
    for tag, z in ((DISC_TOP, 0.0), (DISC_BOTTOM, -t)):
        assert area[tag] == pytest.approx(math.pi * (r_o**2 - r_i**2), rel=1e-9)
        assert height[tag] == pytest.approx([z], abs=1e-12)
