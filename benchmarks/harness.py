"""The shared harness of the benchmark scripts: timing, alternating rounds, side by side
against another source tree, JSON output, and the test support modules.

- :func:`timed` runs a callable once and returns its result with a :class:`Sample`: CPU
  seconds of this process (``time.process_time``: every thread, BLAS included) and wall
  seconds (``time.perf_counter``).
- :func:`alternate` runs several cases for a number of rounds, the order reversed every
  other round (so a change of machine load hits every case alike), and returns a
  :class:`Timing` per case; figures are medians over the rounds, rates are per CPU-second.
- :func:`shadow_tree` / :func:`run_tree` run a command with another checkout's ``sgtool``
  (a shadow package folder first on ``PYTHONPATH``, :mod:`side_by_side`);
  :func:`alternate_trees` runs a script's worker mode in both trees in alternating rounds.
- :func:`add_output_options` / :func:`emit` give every script ``--json PATH``: the figures
  as one JSON document (stable key order) besides the printed table.
- :func:`support` imports a module of ``tests/support`` (the synthetic worlds and writers
  the tests use), putting ``tests/`` on ``sys.path`` here and nowhere else.

Scripts run as ``python benchmarks/NAME.py`` (this folder is then first on ``sys.path``, so
``import harness`` works); ``tests/test_benchmarks.py`` runs each with tiny arguments.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any, TypeVar

from side_by_side import _MAIN, run_once, shadow_package, temporary_folder

REPO = Path(__file__).resolve().parents[1]
T = TypeVar("T")


@dataclass(frozen=True)
class Sample:
    """One measured run: CPU seconds of this process and wall seconds."""

    cpu_s: float
    wall_s: float


@dataclass
class Timing:
    """The samples of one case over the rounds; figures are medians."""

    label: str
    samples: list[Sample] = field(default_factory=list)

    @property
    def cpu_s(self) -> float:
        """Median CPU seconds per round."""
        return statistics.median(s.cpu_s for s in self.samples)

    @property
    def wall_s(self) -> float:
        """Median wall seconds per round."""
        return statistics.median(s.wall_s for s in self.samples)

    def per_cpu_s(self, work: float) -> float:
        """``work`` units (frames, episodes, ...) per CPU-second, median over the rounds."""
        return statistics.median(work / max(s.cpu_s, 1e-9) for s in self.samples)

    def per_wall_s(self, work: float) -> float:
        """``work`` units per wall second, median over the rounds."""
        return statistics.median(work / max(s.wall_s, 1e-9) for s in self.samples)

    def as_dict(self) -> dict[str, Any]:
        """The samples and their medians (JSON-ready)."""
        return {"label": self.label, "rounds": len(self.samples), "cpu_s": self.cpu_s,
                "wall_s": self.wall_s,
                "samples": [{"cpu_s": s.cpu_s, "wall_s": s.wall_s} for s in self.samples]}


def timed(fn: Callable[[], T]) -> tuple[T, Sample]:
    """``fn()`` with the CPU and wall seconds it took."""
    c0, w0 = time.process_time(), time.perf_counter()
    out = fn()
    return out, Sample(cpu_s=time.process_time() - c0, wall_s=time.perf_counter() - w0)


def round_order(names: Sequence[str], round_index: int) -> list[str]:
    """The order of the cases in round ``round_index``: as given, reversed every other
    round."""
    return list(names) if round_index % 2 == 0 else list(names)[::-1]


def alternate(cases: Mapping[str, Callable[[], object]], rounds: int,
              on_sample: Callable[[int, str, Sample], None] | None = None
              ) -> dict[str, Timing]:
    """Run every case once per round, the order alternating, for ``rounds`` rounds; a
    :class:`Timing` per case (in the order given). ``on_sample(round, name, sample)`` sees
    every run (e.g. to print it)."""
    out = {name: Timing(name) for name in cases}
    for r in range(rounds):
        for name in round_order(list(cases), r):
            _, sample = timed(cases[name])
            out[name].samples.append(sample)
            if on_sample is not None:
                on_sample(r, name, sample)
    return out


def best_of(fn: Callable[[], object], repeats: int) -> Sample:
    """The run with the least wall time of ``repeats`` runs of ``fn``."""
    return min((timed(fn)[1] for _ in range(max(1, repeats))), key=lambda s: s.wall_s)


def shadow_tree(tree: Path, folder: Path | None = None) -> str:
    """A ``PYTHONPATH`` entry whose ``sgtool`` is the checkout ``tree`` (a fresh temporary
    folder of links unless ``folder`` is given)."""
    folder = folder or temporary_folder("sgtool-tree-")
    return str(shadow_package(tree.resolve(), folder))


def run_tree(args: list[str], pythonpath: str | None) -> tuple[float, float, float]:
    """(wall s, CPU s, peak RSS MiB) of ``sgtool ARGS`` in a fresh process with
    ``pythonpath`` first (None: this tree)."""
    return run_once(args, pythonpath)


def sgtool_output(args: Sequence[str], pythonpath: str | None = None) -> str:
    """The stdout of ``sgtool ARGS`` in a fresh process with ``pythonpath`` first (None:
    this tree); a failure ends the caller with its last stderr."""
    env = dict(os.environ)
    if pythonpath:
        env["PYTHONPATH"] = pythonpath + os.pathsep + env.get("PYTHONPATH", "")
    proc = subprocess.run([sys.executable, "-c", _MAIN, *args], env=env, text=True,
                          capture_output=True, cwd=tempfile.gettempdir())
    if proc.returncode != 0:
        raise SystemExit(f"sgtool {' '.join(args)} failed:\n{proc.stderr.strip()[-2000:]}")
    return proc.stdout


def run_script(script: Path, args: Sequence[str], pythonpath: str | None = None,
               env: Mapping[str, str] | None = None, timeout: float | None = None) -> str:
    """Run ``python SCRIPT ARGS`` in a fresh process (in the temporary folder, so no
    checkout's files are found by accident) with ``pythonpath`` first on ``PYTHONPATH``
    (None: this tree) and ``env`` over the environment; its stdout. A failure ends the
    caller with the script's last stderr."""
    full = {**os.environ, **(env or {})}
    if pythonpath:
        full["PYTHONPATH"] = pythonpath + os.pathsep + full.get("PYTHONPATH", "")
    proc = subprocess.run([sys.executable, str(Path(script).resolve()), *args], env=full,
                          text=True, capture_output=True, timeout=timeout,
                          cwd=tempfile.gettempdir())
    if proc.returncode != 0:
        raise SystemExit(f"{Path(script).name} {' '.join(args)} failed:\n"
                         f"{proc.stderr.strip()[-2000:]}")
    return proc.stdout


def alternate_trees(script: Path, args: Sequence[str], against: Path | None, rounds: int,
                    labels: tuple[str, str] = ("baseline", "this tree"),
                    env: Mapping[str, str] | None = None) -> dict[str, list[Any]]:
    """Run ``SCRIPT ARGS`` (a worker mode printing one JSON document on its last stdout
    line) with the checkout ``against`` (None: not at all) and with this tree, the order
    alternating, for ``rounds`` rounds; per tree (``labels``: baseline, this tree) the
    documents in round order."""
    trees: dict[str, str | None] = {}
    if against is not None:
        trees[labels[0]] = shadow_tree(against)
    trees[labels[1]] = None
    out: dict[str, list[Any]] = {name: [] for name in trees}
    for r in range(rounds):
        for name in round_order(list(trees), r):
            text = run_script(script, args, trees[name], env=env)
            out[name].append(json.loads(text.strip().splitlines()[-1]))
    return out


def log_given(ap: argparse.ArgumentParser, log: Path) -> Path:
    """``log``, or the parser's one-line usage error when it is not a file (the default of
    a script reading a recording is the one ``benchmarks/replay.py`` caches)."""
    if not log.is_file():
        ap.error(f"{log}: no such log (give LOG, or run benchmarks/replay.py first: it "
                 "caches the default recording)")
    return log


def add_output_options(ap: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """``--json PATH``: also write the figures as JSON (``-``: stdout)."""
    ap.add_argument("--json", dest="json_out", default=None, metavar="PATH",
                    help="also write the figures as one JSON document to PATH (- : stdout)")
    return ap


def emit(doc: Mapping[str, Any], path: str | None) -> None:
    """Write ``doc`` as JSON (sorted keys) to ``path`` (``-``: stdout; None: nowhere),
    with the script's context: the command line and the load average."""
    if path is None:
        return
    from sgtool.canonical import strict_json

    full = {"argv": sys.argv[1:], "load_1min": round(os.getloadavg()[0], 2), **doc}
    # NaN (an SPL without a shortest path) as null
    text = json.dumps(strict_json(full), indent=1, sort_keys=True, default=_plain) + "\n"
    if path == "-":
        sys.stdout.write(text)
    else:
        Path(path).write_text(text)


def _plain(value: Any) -> Any:
    if isinstance(value, Timing):
        return value.as_dict()
    if isinstance(value, Sample):
        return {"cpu_s": value.cpu_s, "wall_s": value.wall_s}
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"not JSON: {type(value).__name__}")


def support(name: str) -> ModuleType:
    """The test support module ``tests/support/NAME.py`` (imported as ``support.NAME``, as
    the tests import it: its own imports of ``support.*`` then work too)."""
    tests = str(REPO / "tests")
    if tests not in sys.path:
        sys.path.append(tests)
    return importlib.import_module(f"support.{name}")
