"""Every command line the documentation shows runs: each ``fenicsfriction ...`` line of a fenced
code block in README.md and docs/*.md is run with its ``--out DIR`` in a temporary folder and
must exit with status 0.

What is not a command to run: a synopsis (a line with ``[--flag]`` options or ``a|b``
alternatives, which docs/cli.md spells out as runnable examples) and a line prefixed by
``nice``, the marker of the hours-long reproductions of the papers' runs. A leading
``mpirun -n N`` is dropped: the command runs serially (the MPI pass of the suite runs the CLI's
own tests on 2 ranks); PETSc options after the flags pass through as documented.
"""

import os
import pathlib
import re
import shlex
import subprocess
import sys

from mpi4py import MPI

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```[^\n]*\n(.*?)^```", re.S | re.M)
LAUNCHER = re.compile(r"^(mpirun|mpiexec)\s+-n\s+\d+\s+")


def _lines(text: str) -> list[str]:
    """The logical lines of a code block: backslash continuations joined, comments removed."""
    joined = re.sub(r"\\\n\s*", " ", text)
    return [re.split(r"\s+#", line, maxsplit=1)[0].strip() for line in joined.splitlines()]


def documented_commands() -> list[tuple[str, str]]:
    """(page, command line) of every runnable ``fenicsfriction`` line, in page order."""
    found = []
    for page in PAGES:
        for block in FENCE.findall(page.read_text()):
            for line in _lines(block):
                command = LAUNCHER.sub("", line)
                command = re.sub(r"^python3? -m fenicsfriction\b", "fenicsfriction", command)
                if not command.startswith("fenicsfriction "):
                    continue
                if re.search(r"\[-|\|", command):  # a synopsis
                    continue
                found.append((page.name, line))
    first: dict[str, str] = {}  # a line shown on several pages runs once
    for page, line in found:
        first.setdefault(line, page)
    return [(page, line) for line, page in first.items()]


COMMANDS = documented_commands()


def _argv(line: str, out: pathlib.Path) -> list[str]:
    """The interpreter's command for a documented line, ``--out DIR`` replaced by ``out``."""
    words = shlex.split(LAUNCHER.sub("", line))
    words = words[3:] if words[:3] in (["python", "-m", "fenicsfriction"],
                                        ["python3", "-m", "fenicsfriction"]) else words[1:]
    assert "--out" in words, f"a documented command without --out: {line}"
    words[words.index("--out") + 1] = str(out)
    # a case file is named relative to the repository (the command runs in a temporary folder)
    words = [str(ROOT / w) if w.endswith(".toml") and not pathlib.Path(w).is_absolute() else w
             for w in words]
    return [sys.executable, "-m", "fenicsfriction", *words]


def test_the_documentation_shows_commands_of_every_family():
    families = {shlex.split(LAUNCHER.sub("", line))[1] for _, line in COMMANDS}
    assert {"block", "oscillators", "contact", "rolling", "multicontact"} <= families, families


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1,
                    reason="starts its own interpreter; runs in the serial pass")
@pytest.mark.parametrize(("page", "line"), COMMANDS,
                         ids=[f"{page}: {line[:90]}" for page, line in COMMANDS])
def test_documented_command_runs(tmp_path, page, line):
    """One documented line as a user types it, in a temporary folder. The suite's serial pass
    runs test files on every core (pytest-xdist), so the commands run one after another here."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
    out = tmp_path / "out"
    result = subprocess.run(_argv(line, out), capture_output=True, text=True, timeout=600,
                            env=env, cwd=tmp_path)
    assert result.returncode == 0, f"{page}: {line}\n{result.stderr[-2000:]}"
    assert any(out.iterdir()), f"{page}: {line} wrote nothing"
