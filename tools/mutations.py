"""Mutation check of the mapping and scene-graph parameters: which tests notice a changed
default?

For each mutation (a file of the ``sgtool`` package, an exact text, its replacement: a
default moved by +20 % or -20 %, the door threshold also by +33 %, the room centre rule
swapped), the script copies the package into a temporary directory (``toolkit/`` as
``sgtool/``, ``recorders/`` etc. as its subpackages, as setup.py maps them), applies the
mutation there, runs the chosen test files against the copy (``PYTHONPATH`` puts it ahead
of the editable install; the script checks that it does) and prints a table
``parameter | mutation | caught by``. The working tree is never modified, so it is safe
while others edit and test it. Tests run one mutation at a time (the machine is shared).

Usage (from the repository root, by hand)::

    python tools/mutations.py                      # the default test files
    python tools/mutations.py --tests tests/toolkit/scenegraph/test_parts.py \
        tests/toolkit/mapping/test_voronoi.py       # e.g. the "before" column
    python tools/mutations.py --only door          # mutations whose parameter matches
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
ROOTS = {"toolkit": "sgtool", "recorders": "sgtool/recorders",
         "replayers": "sgtool/replayers", "datasets": "sgtool/datasets",
         "analysis": "sgtool/analysis"}
DEFAULT_TESTS = ("tests/toolkit/mapping/test_parameters.py",
                 "tests/toolkit/scenegraph/test_parameters.py",
                 "tests/toolkit/scenegraph/test_parts.py", "tests/toolkit/mapping/test_voronoi.py")
RS, VO = "scenegraph/room_segmentation.py", "mapping/voronoi.py"
AS, FR = "scenegraph/assign.py", "scenegraph/frontiers.py"


@dataclass(frozen=True)
class Mutation:
    parameter: str
    label: str
    file: str  # relative to the sgtool package (toolkit/)
    old: str
    new: str


def scaled(parameter: str, file: str, line: str, value: str, factors: tuple[float, ...]
           ) -> list[Mutation]:
    """Mutations of a default ``value`` written in ``line`` (exact text in ``file``)."""
    out = []
    for f in factors:
        new_value = repr(round(float(value) * f, 6))
        out.append(Mutation(parameter, f"{value} -> {new_value} ({(f - 1) * 100:+.0f} %)",
                            file, line, line.replace(value, new_value, 1)))
    return out


UP_DOWN = (1.2, 0.8)
MUTATIONS: list[Mutation] = [
    *scaled("door threshold", RS, "door_threshold: float = 0.03", "0.03", (1.2, 4 / 3, 0.8)),
    *scaled("door KDE bandwidth", RS, "door_bandwidth: float = 0.15", "0.15", UP_DOWN),
    *scaled("min room size", RS, "min_room_length: float = 1.0", "1.0", UP_DOWN),
    Mutation("room centre rule", "min eccentricity -> medoid (min summed distance)", RS,
             "np.where(reach, d, 0.0).max(axis=1)", "np.where(reach, d, 0.0).sum(axis=1)"),
    *scaled("Voronoi min clearance", VO, "min_clearance: float = 0.2", "0.2", UP_DOWN),
    *scaled("sparsification node spacing", VO, "node_spacing: float = 0.6", "0.6", UP_DOWN),
    *scaled("assignment exponent", AS, "exponent: float = 1.3", "1.3", UP_DOWN),
    *scaled("assignment unit (weight)", AS, "unit: float = 0.075", "0.075", UP_DOWN),
    *scaled("frontier min size", FR, "min_size: float = 0.3", "0.3", UP_DOWN),
    # further defaults of the same stages
    *scaled("Voronoi min spur", VO, "min_spur: float = 0.3", "0.3", UP_DOWN),
    *scaled("frontier max size", FR, "max_size: float = 2.5", "2.5", UP_DOWN),
    *scaled("frontier min pocket", FR, "min_pocket: float = 0.5", "0.5", UP_DOWN),
    *scaled("assignment candidate radius", AS, "candidate_radius: float = 2.5", "2.5",
            UP_DOWN),
]


def copy_tree(dest: Path) -> Path:
    """The package as the editable install maps it, under ``dest``; returns the sgtool dir."""
    for folder, target in ROOTS.items():
        shutil.copytree(REPO / folder, dest / target,
                        ignore=shutil.ignore_patterns("__pycache__", "*.pyc"),
                        dirs_exist_ok=True)
    return dest / "sgtool"


def env_for(root: Path) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(root) + (os.pathsep + env["PYTHONPATH"]
                                     if env.get("PYTHONPATH") else "")
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    return env


def check_import(root: Path) -> None:
    """The copy, not the working tree, must be what ``import sgtool`` finds."""
    code = ("import sgtool, sgtool.mapping.voronoi as v, sgtool.recorders as r; "
            "print(v.__file__); print(r.__file__)")
    got = subprocess.run([sys.executable, "-c", code], cwd=REPO, env=env_for(root),
                         capture_output=True, text=True, check=True).stdout.split()
    if not all(Path(p).resolve().is_relative_to(root.resolve()) for p in got):
        sys.exit(f"sgtool is not imported from the copy {root}: {got}")


def run_tests(root: Path, tests: list[str]) -> tuple[bool, list[str], str]:
    """(all passed, failing tests as ``file::test``, pytest's last line)."""
    cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rfE", *tests]
    p = subprocess.run(cmd, cwd=REPO, env=env_for(root), capture_output=True, text=True)
    failed = sorted({m.group(1) for m in re.finditer(r"^(?:FAILED|ERROR) (\S+)",
                                                     p.stdout, re.M)})
    last = p.stdout.strip().splitlines()[-1] if p.stdout.strip() else p.stderr.strip()[-200:]
    return p.returncode == 0, failed, last


def summary(failed: list[str]) -> str:
    """``file (n tests)`` per test file, from ``path::test`` ids."""
    per: dict[str, int] = {}
    for f in failed:
        name = f.split("::")[0].removeprefix("tests/")
        per[name] = per.get(name, 0) + 1
    return ", ".join(f"{k} ({v})" for k, v in sorted(per.items()))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tests", nargs="+", default=list(DEFAULT_TESTS),
                    help="test files (relative to the repository root)")
    ap.add_argument("--only", default="", help="run mutations whose parameter contains this")
    ap.add_argument("--list", action="store_true", help="list the mutations and exit")
    args = ap.parse_args()
    muts = [m for m in MUTATIONS if args.only.lower() in m.parameter.lower()]
    if args.list:
        for m in muts:
            print(f"{m.parameter} | {m.label} | {m.file}: {m.old!r} -> {m.new!r}")
        return
    with tempfile.TemporaryDirectory(prefix="sgtool-mut-") as tmp:
        root = Path(tmp)
        pkg = copy_tree(root)
        check_import(root)
        t0 = time.perf_counter()
        ok, failed, last = run_tests(root, args.tests)
        if not ok:
            sys.exit(f"the unmutated copy fails ({last}): {failed}; fix that first")
        print(f"baseline: {last} ({time.perf_counter() - t0:.1f} s)", file=sys.stderr)
        rows: list[tuple[str, str, str]] = []
        for m in muts:
            path = pkg / m.file
            original = path.read_text()
            if original.count(m.old) != 1:
                rows.append((m.parameter, m.label, f"NOT APPLIED ({m.old!r} found "
                                                   f"{original.count(m.old)} times)"))
                continue
            path.write_text(original.replace(m.old, m.new))
            try:
                ok, failed, last = run_tests(root, args.tests)
            finally:
                path.write_text(original)
            caught = "-- (survives)" if ok else (summary(failed) or f"error: {last}")
            rows.append((m.parameter, m.label, caught))
            print(f"{m.parameter} | {m.label} | {caught}", file=sys.stderr)
    w0 = max(len(r[0]) for r in rows + [("parameter", "", "")])
    w1 = max(len(r[1]) for r in rows + [("", "mutation", "")])
    print(f"tests: {' '.join(args.tests)}")
    print(f"{'parameter':<{w0}} | {'mutation':<{w1}} | caught by")
    print(f"{'-' * w0}-|-{'-' * w1}-|-{'-' * 9}")
    for p, lab, c in rows:
        print(f"{p:<{w0}} | {lab:<{w1}} | {c}")
    survived = sum(r[2].startswith("--") for r in rows)
    stale = sum(r[2].startswith("NOT APPLIED") for r in rows)
    print(f"{len(rows) - survived - stale} of {len(rows) - stale} mutations caught"
          + (f"; {stale} not applied (the code they change moved: update them)"
             if stale else ""))
    if stale:
        sys.exit(1)


if __name__ == "__main__":
    main()
