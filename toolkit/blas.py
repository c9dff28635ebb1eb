"""One BLAS thread for the small matrix products of replay.

OpenBLAS splits even tiny products (the room classifier's 18 x 768 @ 768 x 512) over its
threads; on a busy machine waking them costs far more than the product itself (figures in
``docs/experiments/moved-from-docstrings.md``). Replay is one thread of small products, so it
runs with one BLAS thread, limited by ``threadpoolctl`` (a dependency).
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable

from sgtool.heap import ProcessWide


def _one_thread() -> Callable[[], object]:
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1, user_api="blas").restore_original_limits


_ONE_THREAD = ProcessWide(_one_thread)


def single_blas_thread() -> contextlib.AbstractContextManager[None]:
    """Limit BLAS libraries to one thread inside the block (module doc). The limit is one
    per process (:class:`~sgtool.heap.ProcessWide`): blocks in several threads may overlap
    in any order, and the last to leave restores the process's own setting."""
    return _ONE_THREAD()
