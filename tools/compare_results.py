#!/usr/bin/env python3
"""Compare two result trees number by number: the check that a restructuring changed no result.

    tools/compare_results.py BEFORE_DIR AFTER_DIR [--rename OLD=NEW ...] [--logs BEFORE AFTER ...]

Every JSON and CSV file under BEFORE_DIR is matched with the file of the same relative path
under AFTER_DIR (after the ``--rename`` substitutions of path parts, e.g. a renamed output
folder); every number must be identical (bit for bit, as parsed), except the values of timing
keys (wall times, JIT times, speed-ups, CPU counts), which are listed apart. ``--logs`` compares
two logs (a demo's stdout) line by line, times masked, as multisets (MPI ranks interleave),
and lists the lines only one holds. ``--nested law`` compares the
entries of a record that moved into a sub-record ``law`` with their old places. Exit status 1
if any non-timing number differs or a file is missing.
"""

from __future__ import annotations

import argparse
import collections
import csv
import json
import math
import pathlib
import re
import sys

# keys whose values are measured on the machine, not computed: wall and JIT times, their
# ratios, the processor count, peak memory, the BLAS in use
TIMING = re.compile(r"(time|iteration|step)_s$|_ms$|^seconds$|^cpus$|speedup|wall|^jit|"
                    r"peak_memory|rss|^blas", re.I)
TIME_IN_TEXT = re.compile(r"\b\d+(?:\.\d+)?(?:e[-+]?\d+)? ?(?:s|ms|min)\b")


def _same(a: object, b: object) -> bool:
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


def _gather(a: dict, b: dict, nested: tuple[str, ...]) -> tuple[dict, dict]:
    """``a`` and ``b`` with the entries of a ``nested`` sub-record that only ``b`` has (e.g. the
    parameters of an interface law now recorded as ``law: {...}``) lifted to ``b``'s level
    where ``a`` holds them there, so that they are compared rather than reported as moved."""
    b = dict(b)
    for name in nested:
        if name in b and name not in a and isinstance(b[name], dict):
            inner = dict(b.pop(name))
            for k in [k for k in inner if k in a and k not in b]:
                b[k] = inner.pop(k)
            if inner:
                b[name] = inner
    return a, b


def compare_json(a: object, b: object, where: str, out: dict) -> None:
    if isinstance(a, dict) and isinstance(b, dict):
        a, b = _gather(a, b, out["nested"])
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                out["keys"].append(f"{where}/{k}: only {'after' if k in b else 'before'}")
                continue
            if out["timing_key"].search(k):
                if not _same(a[k], b[k]):
                    out["timing"] += 1
                continue
            compare_json(a[k], b[k], f"{where}/{k}", out)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out["diff"].append(f"{where}: length {len(a)} != {len(b)}")
            return
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            compare_json(x, y, f"{where}[{i}]", out)
    else:
        out["numbers"] += isinstance(a, (int, float))
        if not _same(a, b):
            out["diff"].append(f"{where}: {a!r} != {b!r}")


def compare_csv(pa: pathlib.Path, pb: pathlib.Path, where: str, out: dict) -> None:
    ra, rb = (list(csv.reader(p.open())) for p in (pa, pb))
    if len(ra) != len(rb) or (ra and ra[0] != rb[0]):
        out["diff"].append(f"{where}: shape or header differs")
        return
    header = ra[0] if ra else []
    skip = {i for i, h in enumerate(header) if out["timing_key"].search(h)}
    for r, (x, y) in enumerate(zip(ra[1:], rb[1:], strict=True)):
        for c, (u, v) in enumerate(zip(x, y, strict=True)):
            if c in skip:
                continue
            out["numbers"] += 1
            if u != v:
                out["diff"].append(f"{where} row {r + 1} {header[c] if header else c}: {u} != {v}")


def _log_lines(path: pathlib.Path, roots: tuple[str, ...]) -> list[str]:
    """A log's lines without the JIT compiler's (a warm cache prints none) and with times
    masked (``0.50 s``, ``12 ms``) and the output roots replaced."""
    lines = []
    for line in path.read_text(errors="replace").splitlines():
        if "INFO:root" in line or "libffcx" in line:
            continue
        line = TIME_IN_TEXT.sub("<time>", line)
        for root in roots:
            line = line.replace(root, "<out>")
        lines.append(line.rstrip())
    return lines


def compare_logs(a: pathlib.Path, b: pathlib.Path, roots: tuple[str, ...],
                 renames: list[tuple[str, str]]) -> list[str]:
    """The lines of two logs that only one holds, as a multiset: ranks interleave their lines
    differently from run to run, so the order is not compared."""
    la, lb = _log_lines(a, roots), _log_lines(b, roots)
    for old, new in renames:
        la = [line.replace(old, new) for line in la]
    ca, cb = collections.Counter(la), collections.Counter(lb)
    return [f"- {x}" for x in (ca - cb).elements()] + [f"+ {y}" for y in (cb - ca).elements()]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", type=pathlib.Path)
    parser.add_argument("after", type=pathlib.Path)
    parser.add_argument("--rename", action="append", default=[], metavar="OLD=NEW")
    parser.add_argument("--logs", nargs=2, action="append", default=[], type=pathlib.Path)
    parser.add_argument("--timing", action="append", default=[], metavar="REGEX",
                        help="more keys whose values are measured times or their ratios (a "
                             "benchmark's own names, e.g. 'ratio$')")
    parser.add_argument("--nested", action="append", default=[], metavar="KEY",
                        help="a sub-record (e.g. law) whose entries were recorded one level up "
                             "before")
    args = parser.parse_args()
    renames = [tuple(r.split("=", 1)) for r in args.rename]
    out: dict = {"diff": [], "keys": [], "timing": 0, "numbers": 0, "files": 0, "missing": [],
                 "nested": tuple(args.nested),
                 "timing_key": re.compile("|".join([TIMING.pattern, *args.timing]), re.I)}
    for pa in sorted(args.before.rglob("*")):
        if pa.suffix not in (".json", ".csv"):
            continue
        rel = pa.relative_to(args.before).as_posix()
        for old, new in renames:
            rel = rel.replace(old, new)
        pb = args.after / rel
        if not pb.exists():
            out["missing"].append(rel)
            continue
        out["files"] += 1
        if pa.suffix == ".json":
            compare_json(json.loads(pa.read_text()), json.loads(pb.read_text()), rel, out)
        else:
            compare_csv(pa, pb, rel, out)
    print(f"{out['files']} files, {out['numbers']} numbers compared; "
          f"{len(out['diff'])} differ; {out['timing']} timing values differ (ignored); "
          f"{len(out['missing'])} files missing after; {len(out['keys'])} keys added/removed")
    for line in out["missing"] + out["keys"] + out["diff"][:200]:
        print("  " + line)
    log_diffs = []
    roots = (str(args.before), str(args.after))
    for a, b in args.logs:
        log_diffs += compare_logs(a, b, roots, renames)
    if args.logs:
        print(f"logs: {len(log_diffs)} lines differ (times masked, order ignored)")
        for d in log_diffs[:300]:
            print(d)
    return 1 if out["diff"] or out["missing"] else 0


if __name__ == "__main__":
    sys.exit(main())
