"""Keep the garbage collector's full scans and huge-page faults off the replay loop.

Replay starts by loading its modules and models (the room classifier's weights, the
sentence encoder's tables): objects that live until the end. Python's
full (oldest-generation) collection walks every tracked object, so each one a long replay
triggers pauses a refresh for as long as the walk over those start-up objects.
:func:`frozen_heap` moves what exists at its start to the collector's permanent generation
(:func:`gc.freeze`) for the duration of the block, so a full collection walks only the
objects made since. At the end they go back to the oldest generation (:func:`gc.unfreeze`),
so nothing stays exempt from collection after the block. Inside a block, or in a process
that froze its heap itself, it does nothing (unfreezing would release their objects too).

numpy asks the kernel for transparent huge pages for every large array (``madvise``); a
fault on such an array can make the kernel compact memory to find a free 2 MB page, in
kernel time charged to the thread. The voxel store's multi-megabyte arrays are allocated
afresh when a door opens or the store merges its tail, so those refreshes pay such faults.
:func:`small_pages` turns numpy's request off inside the block (4 kB pages, more but cheap
faults). What both blocks saved on the 30-room benchmark log is in
``docs/experiments/moved-from-docstrings.md``.
"""

from __future__ import annotations

import contextlib
import gc
import importlib
import threading
from collections.abc import Callable, Iterator


@contextlib.contextmanager
def frozen_heap() -> Iterator[None]:
    """Exempt the objects alive now from full collections inside the block (module doc).
    The heap is unfrozen however the block ends, a Ctrl-C during its start included."""
    if gc.get_freeze_count():  # frozen already (an enclosing block, or the host process)
        yield
        return
    # garbage left by earlier work goes now: frozen, it would outlive the block (a worker
    # running task after task would pile it up, frozen again before any full collection)
    gc.collect()
    try:
        gc.freeze()
        yield
    finally:
        gc.unfreeze()


class ProcessWide:
    """A setting that is one per process, shared by blocks that may overlap in several
    threads in any order: every block entering applies it (``apply`` returns what undoes
    it; applying again covers what was loaded since, a BLAS library imported inside the
    first block), and the last block to leave undoes them all, the latest first, so the
    process gets back the setting it had before the first. Use an instance as ``with
    setting():``."""

    def __init__(self, apply: Callable[[], Callable[[], object]]) -> None:
        self._apply = apply
        self._lock = threading.Lock()
        self._depth = 0
        self._undo: list[Callable[[], object]] = []

    @contextlib.contextmanager
    def __call__(self) -> Iterator[None]:
        entered = False
        try:
            with self._lock:
                self._undo.append(self._apply())
                self._depth += 1
                entered = True
            yield
        finally:
            if entered:
                with self._lock:
                    self._depth -= 1
                    if self._depth == 0:
                        undo, self._undo = self._undo, []
                        for step in reversed(undo):
                            step()


def hugepage_setter() -> Callable[[bool], bool] | None:
    """numpy's switch for ``madvise(MADV_HUGEPAGE)``: a function taking the new setting and
    returning the old (a private numpy function; None where it is missing)."""
    for name in ("numpy._core.multiarray", "numpy.core.multiarray"):
        try:
            setter = getattr(importlib.import_module(name), "_set_madvise_hugepage", None)
        except ImportError:
            continue
        if setter is not None:
            return setter
    return None


def _no_hugepages() -> Callable[[], object]:
    setter = hugepage_setter()
    if setter is None:
        return lambda: None
    old = setter(False)
    return lambda: setter(bool(old))


_SMALL_PAGES = ProcessWide(_no_hugepages)


def small_pages() -> contextlib.AbstractContextManager[None]:
    """numpy arrays allocated inside the block do not ask for huge pages (module doc).
    numpy's switch is one per process (:class:`ProcessWide`): blocks in several threads
    may overlap in any order."""
    return _SMALL_PAGES()
