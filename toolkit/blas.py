"""One BLAS thread for the small matrix products of replay.

OpenBLAS splits even tiny products (the room classifier's 18 x 768 @ 768 x 512) over its
threads; on a busy machine waking them costs far more than the product itself (figures in
``docs/experiments/moved-from-docstrings.md``). Replay is one thread of small products, so it
runs with one BLAS thread, limited by ``threadpoolctl`` (a dependency).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator


@contextlib.contextmanager
def single_blas_thread() -> Iterator[None]:
    """Limit BLAS libraries to one thread inside the block (module doc)."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        yield
