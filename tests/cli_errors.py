"""What a user error looks like on the command line, checked the same way by every CLI test."""

from mpi4py import MPI


def assert_one_error_line(err: str, name: str) -> None:
    """Rank 0 printed exactly one ``fenicsfriction: error: NAME=...`` line; the others none."""
    lines = [line for line in err.splitlines() if "error" in line]
    if MPI.COMM_WORLD.rank == 0:
        assert len(lines) == 1 and lines[0].startswith("fenicsfriction: error: "), lines
        assert f"{name}=" in lines[0], lines[0]
    else:
        assert not lines
