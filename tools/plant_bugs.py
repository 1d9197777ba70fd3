"""Plant plausible bugs one at a time and show which test catches each.

A test suite is only as good as the bugs it notices. ``tests/planted_bugs.toml`` lists, room by
room, small plausible mistakes (a constant, a sign, a dropped factor, a swapped index): the
exact text to change, its replacement, and the test files that should notice. This script
copies the checkout (tracked and modified files, as they are now) into a temporary folder,
applies each bug there alone, runs its test files with ``pytest -x`` and reports whether they
failed (caught, and by which test first) or passed (the bug SURVIVED). The working tree itself
never holds a planted bug.

    python tools/plant_bugs.py                      # every bug in the catalogue
    python tools/plant_bugs.py --room rolling       # one room
    python tools/plant_bugs.py --out DIR            # also DIR/planted_bugs.json, bug by bug

Exit status 0 when every bug is caught, 1 when one survived, 2 for a catalogue entry that no
longer applies (its text is not found exactly once: the code moved on, mend the entry).
``tests/test_planted_bugs.py`` checks the catalogue applies on every run of the suite; running
the bugs themselves takes minutes, so it is this script's job, not the suite's.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib

ROOT = pathlib.Path(__file__).resolve().parents[1]
CATALOGUE = ROOT / "tests" / "planted_bugs.toml"


def read_catalogue(path: pathlib.Path = CATALOGUE) -> list[dict]:
    """The catalogue's bugs, each a table with ``room``, ``file``, ``old``, ``new``, ``why`` and
    ``tests`` (paths relative to the repository)."""
    bugs = tomllib.loads(path.read_text())["bug"]
    for i, bug in enumerate(bugs):
        missing = {"room", "file", "old", "new", "why", "tests"} - set(bug)
        if missing:
            raise ValueError(f"{path.name}: bug {i + 1} has no {', '.join(sorted(missing))}")
    return bugs


def applies(bug: dict, root: pathlib.Path = ROOT) -> str | None:
    """Why ``bug`` cannot be planted in the tree at ``root``, or None when it can."""
    source = root / bug["file"]
    if not source.is_file():
        return f"{bug['file']}: no such file"
    count = source.read_text().count(bug["old"])
    if count != 1:
        return f"{bug['file']}: the text to change occurs {count} times, not once: {bug['old']!r}"
    if bug["old"] == bug["new"]:
        return f"{bug['file']}: the replacement changes nothing"
    for test in bug["tests"]:
        if not (root / test.split("::")[0]).is_file():
            return f"{test}: no such test file"
    return None


def _copy_checkout(target: pathlib.Path) -> None:
    """The repository's tracked files as they are in the working tree, into ``target``."""
    files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, check=True,
                           capture_output=True).stdout.decode().split("\0")
    for name in filter(None, files):
        source = ROOT / name
        if source.is_file():
            (target / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, target / name)


def caught_by(stdout: str) -> str | None:
    """The test that failed first, from pytest's short summary (``-rfE``: "FAILED id - ..."
    or "ERROR id - ..."), or None (a collection error names no test)."""
    for line in stdout.splitlines():
        for mark in ("FAILED ", "ERROR "):
            if line.startswith(mark):
                return line[len(mark):].split(" - ")[0].strip()
    return None


def plant(bug: dict, tree: pathlib.Path, timeout: float) -> dict:
    """Run ``bug``'s tests in ``tree`` with the bug in place: ``verdict`` ("caught" or
    "survived"), ``caught_by`` (the first failing test's id), ``seconds``, ``last_line``."""
    source = tree / bug["file"]
    original = source.read_text()
    source.write_text(original.replace(bug["old"], bug["new"], 1))
    env = dict(os.environ, PYTHONPATH=str(tree), PYTHONDONTWRITEBYTECODE="1")
    start = time.perf_counter()
    by = None
    try:
        run = subprocess.run([sys.executable, "-m", "pytest", "-x", "-q", "-rfE", "-p",
                              "no:cacheprovider", *bug["tests"]], cwd=tree, env=env,
                             capture_output=True, text=True, timeout=timeout)
        verdict = "survived" if run.returncode == 0 else "caught"
        lines = [line for line in run.stdout.splitlines() if line.strip()]
        last = lines[-1] if lines else run.stderr.strip()[-200:]
        if verdict == "caught":
            by = caught_by(run.stdout)
    except subprocess.TimeoutExpired:
        verdict, last = "caught", f"the tests ran past {timeout:.0f} s (a hang counts as caught)"
    finally:
        source.write_text(original)
    return {"verdict": verdict, "caught_by": by, "seconds": round(time.perf_counter() - start, 1),
            "last_line": last}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--room", help="only the bugs of this room")
    parser.add_argument("--catalogue", type=pathlib.Path, default=CATALOGUE)
    parser.add_argument("--timeout", type=float, default=900.0,
                        help="seconds a bug's test run may take (default 900)")
    parser.add_argument("--out", type=pathlib.Path, help="folder for planted_bugs.json")
    args = parser.parse_args(argv)

    bugs = read_catalogue(args.catalogue)
    if args.room:
        bugs = [bug for bug in bugs if bug["room"] == args.room]
        if not bugs:
            print(f"error: --room {args.room}: no bug of that room in {args.catalogue.name}",
                  file=sys.stderr)
            return 2
    stale = [(bug, reason) for bug in bugs if (reason := applies(bug)) is not None]
    for bug, reason in stale:
        print(f"stale entry ({bug['room']}: {bug['why']}): {reason}", file=sys.stderr)
    if stale:
        return 2

    results: list[dict] = []
    if args.out:
        args.out.mkdir(parents=True, exist_ok=True)

    def write() -> None:  # after every bug: an interrupted run keeps what it found
        if args.out:
            (args.out / "planted_bugs.json").write_text(json.dumps(results, indent=1))

    with tempfile.TemporaryDirectory(prefix="planted-bugs-") as folder:
        tree = pathlib.Path(folder)
        _copy_checkout(tree)
        for i, bug in enumerate(bugs, 1):
            outcome = plant(bug, tree, args.timeout)
            results.append({**bug, **outcome})
            write()
            by = f" by {outcome['caught_by']}" if outcome["caught_by"] else ""
            print(f"[{i}/{len(bugs)}] {outcome['verdict'].upper():8s} {bug['room']:14s} "
                  f"{bug['why']}{by} ({outcome['seconds']:.0f} s)", flush=True)
    survived = [r for r in results if r["verdict"] == "survived"]
    print(f"{len(results) - len(survived)} of {len(results)} planted bugs caught"
          + (f"; SURVIVED: {'; '.join(r['why'] for r in survived)}" if survived else ""))
    return 1 if survived else 0


if __name__ == "__main__":
    sys.exit(main())
