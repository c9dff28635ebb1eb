"""Run one benchmark command from two source trees in alternating rounds, side by side.

On a shared, loaded machine wall-clock figures of two runs minutes apart mean little;
this runs the same command with this tree's ``sgtool`` and with a baseline tree's (a
``git worktree`` of an older commit) in alternating rounds, each in a fresh process, and
prints per tree the median wall seconds, median CPU seconds (user + system of the child)
and median peak RSS, and the ratio of the medians.

The baseline tree is imported through a shadow package folder (``--base-pkg``, built
here from ``--base``: ``sgtool`` -> ``BASE/toolkit`` plus the subpackage folders), put
first on ``PYTHONPATH``.

    git worktree add /tmp/replay-base HEAD
    .venv/bin/python benchmarks/side_by_side.py --base /tmp/replay-base --rounds 3 -- \\
        replay /tmp/sgtool-bench-replay/house3_10rooms_320x240_fps4.mcap -o {out} --force

``{out}`` in the command becomes a per-tree output file; ``--frames N`` prints frames/s
(N / median seconds) too. ``--md-figure ROW:COLUMN`` reads a figure the command writes
into a markdown table (``{out}`` then names an output folder: its ``run.md``, else its
``summary.md``) and prints its median per tree, e.g. the bench's own throughput column of
each tree's default houses::

    .venv/bin/python benchmarks/side_by_side.py --base /tmp/issue-time --rounds 5 \\
        --md-figure scout:Episodes/s -- bench --planners scout --houses 10 --episodes 20 \\
        --seeds 3 -w 2 -o {out}
"""

from __future__ import annotations

import argparse
import atexit
import compileall
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SUBPACKAGES = ("recorders", "replayers", "datasets", "analysis")


def temporary_folder(prefix: str) -> Path:
    """A fresh temporary folder, removed when the benchmark exits."""
    folder = Path(tempfile.mkdtemp(prefix=prefix))
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    return folder


def shadow_package(base: Path, folder: Path) -> Path:
    """A folder whose ``sgtool`` package is the tree ``base`` (symlinks). A folder made
    for another tree before is re-pointed: every link is made afresh."""
    pkg = folder / "sgtool"
    if pkg.exists():
        shutil.rmtree(pkg)
    pkg.mkdir(parents=True)
    for entry in (base / "toolkit").iterdir():
        (pkg / entry.name).symlink_to(entry)
    for sub in SUBPACKAGES:
        (pkg / sub).symlink_to(base / sub)
    return folder


def md_figure(folder: Path, row: str, column: str) -> float:
    """The number in ``column`` of the row whose first cell is ``row``, in the first
    markdown table of ``folder``'s run.md (else summary.md) whose header has ``column``."""
    md = next((f for f in (folder / "run.md", folder / "summary.md") if f.is_file()), None)
    if md is None:
        raise SystemExit(f"{folder}: no run.md or summary.md")
    col = None
    for line in md.read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if not line.startswith("|"):
            col = None
        elif col is None and column in cells:
            col = cells.index(column)
        elif col is not None and cells[0] == row:
            return float(cells[col].split()[0])
    raise SystemExit(f"{md}: no row {row!r} under a column {column!r}")


def run_once(args: list[str], pythonpath: str | None) -> tuple[float, float, float]:
    """(wall s, CPU s, peak RSS MiB) of ``sgtool ARGS`` in a fresh process."""
    env = dict(os.environ)
    if pythonpath:
        env["PYTHONPATH"] = pythonpath + os.pathsep + env.get("PYTHONPATH", "")
    with tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        proc = subprocess.Popen([sys.executable, "-c", _MAIN, *args], env=env,
                                stdout=subprocess.DEVNULL, stderr=err)
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        if proc.returncode != 0:
            err.seek(0)
            raise SystemExit(f"{' '.join(args)} failed: {err.read().decode()[-400:]}")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0


_MAIN = "import sys; from sgtool.cli import main; sys.argv[0] = \"sgtool\"; sys.exit(main())"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--base", type=Path, required=True, help="baseline source tree")
    ap.add_argument("--base-pkg", type=Path, default=None,
                    help="folder for the shadow packages (default: a fresh temporary one, "
                    "so runs of several people at once never re-point each other's links)")
    ap.add_argument("--tree", type=Path, default=None,
                    help="the tree to measure against the baseline (default: this one); "
                    "e.g. a copy of the baseline with one engineer's files laid over it")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--frames", type=int, default=0, help="frames per run, for frames/s")
    ap.add_argument("--md-figure", default=None, metavar="ROW:COLUMN",
                    help="also read this figure from the markdown table the command writes "
                    "into the {out} folder (module doc)")
    ap.add_argument("--no-compile", action="store_true",
                    help="do not byte-compile the trees first (with PYTHONDONTWRITEBYTECODE a "
                    "tree without __pycache__, e.g. a fresh `git archive`, compiles every "
                    "module from source in every run, which the other tree may not)")
    ap.add_argument("command", nargs=argparse.REMAINDER, help="-- sgtool arguments")
    a = ap.parse_args(argv)
    cmd = [c for c in a.command if c != "--"]
    if a.base_pkg is None:
        a.base_pkg = temporary_folder("sgtool-base-pkg-")
    if not a.no_compile:
        here = Path(__file__).resolve().parents[1]
        for tree in (a.base, a.tree or here):
            for sub in ("toolkit", *SUBPACKAGES):
                compileall.compile_dir(str(tree.resolve() / sub), quiet=1)
    load0 = os.getloadavg()[0]
    pkg = str(shadow_package(a.base.resolve(), a.base_pkg))
    this = (str(shadow_package(a.tree.resolve(), temporary_folder("sgtool-tree-")))
            if a.tree is not None else None)
    trees = {"this tree": this, "baseline": pkg}
    got: dict[str, list[tuple[float, float, float]]] = {k: [] for k in trees}
    figures: dict[str, list[float]] = {k: [] for k in trees}
    out_dir = temporary_folder("sgtool-side-")
    for r in range(a.rounds):
        order = list(trees) if r % 2 == 0 else list(trees)[::-1]
        for name in order:
            args = [c.replace("{out}", str(out_dir / f"{name.replace(' ', '_')}.mcap"))
                    for c in cmd]
            out = out_dir / f"{name.replace(' ', '_')}.mcap"
            if out.is_dir():  # the last round's output folder
                shutil.rmtree(out)
            got[name].append(run_once(args, trees[name]))
            w, c, m = got[name][-1]
            fig = ""
            if a.md_figure:
                figures[name].append(md_figure(out, *a.md_figure.rsplit(":", 1)))
                fig = f"  {a.md_figure} {figures[name][-1]:g}"
            print(f"round {r + 1} {name:<10} wall {w:6.2f} s  cpu {c:6.2f} s  "
                  f"rss {m:.0f} MiB{fig}", file=sys.stderr)
    print(f"{'tree':<10}{'wall s':>9}{'cpu s':>9}{'peak RSS MiB':>14}"
          + (f"{'frames/s':>10}{'frames/cpu-s':>14}" if a.frames else ""))
    med = {}
    for name, runs in got.items():
        w = statistics.median(x[0] for x in runs)
        c = statistics.median(x[1] for x in runs)
        m = statistics.median(x[2] for x in runs)
        med[name] = (w, c)
        extra = f"{a.frames / w:>10.1f}{a.frames / c:>14.1f}" if a.frames else ""
        print(f"{name:<10}{w:>9.2f}{c:>9.2f}{m:>14.1f}{extra}")
    if a.md_figure:
        fb, ft = (statistics.median(figures[k]) for k in ("baseline", "this tree"))
        print(f"{a.md_figure}: this tree {ft:g}, baseline {fb:g} (medians), "
              f"this / baseline {ft / fb:.2f}x")
    bw, bc = med["baseline"]
    tw, tc = med["this tree"]
    print(f"speed-up (baseline / this tree): wall {bw / tw:.2f}x, cpu {bc / tc:.2f}x "
          f"({a.rounds} alternating rounds; 1-minute load average {load0:.1f} at the start, "
          f"{os.getloadavg()[0]:.1f} at the end)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
