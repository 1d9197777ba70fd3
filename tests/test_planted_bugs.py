"""The catalogue of planted bugs (tests/planted_bugs.toml, run by tools/plant_bugs.py) still
applies to today's code: every entry's text occurs exactly once in its file and its test files
exist, so that the catalogue cannot silently go stale as the code moves on."""

import importlib.util
import pathlib
import subprocess
import sys

import pytest

pytestmark = pytest.mark.sequential

ROOT = pathlib.Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("plant_bugs", ROOT / "tools" / "plant_bugs.py")
assert _spec is not None and _spec.loader is not None
plant_bugs = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(plant_bugs)

BUGS = plant_bugs.read_catalogue()


@pytest.mark.parametrize("bug", BUGS, ids=[f"{b['room']}: {b['why'][:60]}" for b in BUGS])
def test_the_planted_bug_applies_to_todays_code(bug):
    assert plant_bugs.applies(bug) is None, plant_bugs.applies(bug)


def test_the_check_notices_a_stale_entry():
    stale = dict(BUGS[0], old=BUGS[0]["old"] + " and text that is nowhere")
    assert "occurs 0 times" in plant_bugs.applies(stale)


def test_every_room_listed_has_a_handful():
    rooms: dict[str, int] = {}
    for bug in BUGS:
        rooms[bug["room"]] = rooms.get(bug["room"], 0) + 1
    assert all(count >= 3 for count in rooms.values()), rooms


def test_the_catching_test_is_named_from_pytests_own_summary(tmp_path):
    """``caught_by`` reads the id of the first failing test out of a real pytest run's
    output, run as the script runs it (-x -q -rfE)."""
    (tmp_path / "test_probe.py").write_text(
        "def test_passes():\n    pass\n\n\ndef test_fails():\n    assert 1 == 2\n\n\n"
        "def test_never_reached():\n    assert False\n")
    run = subprocess.run([sys.executable, "-m", "pytest", "-x", "-q", "-rfE", "-p",
                          "no:cacheprovider", "test_probe.py"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 1
    assert plant_bugs.caught_by(run.stdout) == "test_probe.py::test_fails"
    assert plant_bugs.caught_by("1 passed in 0.01s") is None
