"""Shared test set-up: where the third-party data lives, one BLAS thread, the frozen session
heap, signal handlers restored after each test, ``ci_only`` tests, and how pytest-xdist
workers share the suite (``-n``)."""

from __future__ import annotations

import gc
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

REPO = Path(__file__).resolve().parents[1]

# One BLAS thread in the test processes and every process they start (CLI subprocesses,
# benchmark scripts, Ray nodes, pytest-xdist workers). The suite is many small matrix
# products (the sentence encoder runs one text at a time); OpenBLAS splits even those over
# its threads, and on busy or shared cores waking them costs many times the product itself
# (docs/experiments/suite-time.md). Results do not depend on it: OpenBLAS partitions the
# output, not the sums. A value set by the caller is kept.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
# One embedding cache per test session, made here so that pytest-xdist workers (which
# inherit this process's environment) share it: a text is encoded once per session, not
# once per worker (support.semantics_fixtures points SGTOOL_CACHE at it).
# The process that made it removes it when the session ends.
_MADE_CACHE: str | None = None
if "SGTOOL_TEST_CACHE" not in os.environ:
    _MADE_CACHE = os.environ["SGTOOL_TEST_CACHE"] = tempfile.mkdtemp(prefix="sgtool-test-cache-")

# Tests that start a Ray instance run one after another in one pytest-xdist worker, so the
# suite never runs two Ray instances at once (each sizes itself to the machine's CPUs).
RAY_STARTERS = ("tests/analysis/test_ray_executor.py::", "tests/analysis/test_ray_cluster.py::",
                "[benchmarks/ray_scale.py]")
MAX_AUTO_WORKERS = 4  # each worker holds its own torch, encoder and test data in memory


def shared_data() -> Path:
    """``../shared/data`` beside the repository (override with SGTOOL_SHARED_DATA)."""
    env = os.environ.get("SGTOOL_SHARED_DATA")
    return Path(env) if env else REPO.parent / "shared" / "data"


@pytest.fixture
def shared_data_dir() -> Path:
    d = shared_data()
    if not d.is_dir():
        pytest.skip(f"third-party data folder {d} is absent (a fresh clone has no ../shared)")
    return d


def pytest_collection_finish(session: pytest.Session) -> None:
    """Freeze the session's heap once the test modules are imported (:func:`gc.freeze`).

    ``sgtool.heap.frozen_heap`` (every replay and bench run) starts with a full
    :func:`gc.collect` unless the process froze its heap itself; in a test session that
    collection walks every object the suite has imported and cached (torch, the test
    modules, their data), hundreds of thousands, at each replay. Frozen here, the blocks do
    nothing, as they do in a host process that froze its heap, and their outputs are the
    same. ``tests/toolkit/test_heap.py`` tests the blocks themselves in an unfrozen heap
    (fixture :func:`unfrozen_heap`)."""
    gc.collect()
    gc.freeze()


@pytest.fixture
def unfrozen_heap() -> Iterator[None]:
    """The collector as in a process that froze nothing (for tests of ``sgtool.heap``);
    the session's heap is frozen again afterwards."""
    gc.unfreeze()
    try:
        yield
    finally:
        gc.collect()
        gc.freeze()


@pytest.fixture(autouse=True)
def signal_handlers() -> Iterator[None]:
    """Each test starts with the session's SIGINT/SIGTERM handlers: ``sgtool.cli.main``
    called in process ignores Ctrl-C once its command is done (``_finished``), and an
    ignored signal is inherited across exec by every subprocess a later test starts (a
    served replay would then never stop on Ctrl-C)."""
    import signal

    saved = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    yield
    for s, handler in saved.items():
        signal.signal(s, handler)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """``ci_only`` tests (minutes of retraining) run where ``CI`` is set, as ``.ci/run`` is;
    set ``CI=1`` to run them by hand."""
    if os.environ.get("CI"):
        return
    skip = pytest.mark.skip(reason="ci_only: runs in CI (set CI=1 to run here)")
    for item in items:
        if "ci_only" in item.keywords:
            item.add_marker(skip)


def pytest_unconfigure(config: pytest.Config) -> None:
    """Remove the session's embedding cache (when this process made it)."""
    if _MADE_CACHE is not None:
        shutil.rmtree(_MADE_CACHE, ignore_errors=True)


def xdist_scope(nodeid: str) -> str:
    """The unit of work of a pytest-xdist worker: the test's file (module fixtures are built
    once), or ``ray`` for every test that starts a Ray instance."""
    if any(mark in nodeid for mark in RAY_STARTERS):
        return "ray"
    return nodeid.split("::", 1)[0]


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: Any) -> Any:
    """``--dist loadfile`` (as ``bash setup.sh test`` runs) hands out :func:`xdist_scope`
    units; any other ``--dist`` is xdist's own."""
    if config.getoption("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class FileOrRayScheduling(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return xdist_scope(nodeid)

    return FileOrRayScheduling(config, log)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """``-n auto``: one worker per CPU this process may use, at most MAX_AUTO_WORKERS."""
    if hasattr(os, "sched_getaffinity"):  # Linux: the CPUs this process may run on
        cpus = len(os.sched_getaffinity(0))
    else:
        cpus = os.cpu_count() or 1
    return max(1, min(cpus, MAX_AUTO_WORKERS))
