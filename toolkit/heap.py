"""Keep the garbage collector's full scans off the replay loop.

Replay starts by loading its models (the room classifier's weights, the sentence encoder's
tables) and modules: hundreds of thousands of objects that live until the end. Python's
full (oldest-generation) collection walks every tracked object, so each of the two or
three that a 30-room replay triggers paused one refresh for 26-28 ms, the slowest
refreshes of the replay. :func:`frozen_heap` moves what exists at its start to the
collector's permanent generation (:func:`gc.freeze`) for the duration of the block, so a
full collection walks only the objects made since: 1.5-2.2 ms (measured on the 30-room
benchmark log). At the end they go back to the oldest generation (:func:`gc.unfreeze`),
so nothing stays exempt from collection after the block. Inside a block, or in a process
that froze its heap itself, it does nothing (unfreezing would release their objects too).
"""

from __future__ import annotations

import contextlib
import gc
from collections.abc import Iterator


@contextlib.contextmanager
def frozen_heap() -> Iterator[None]:
    """Exempt the objects alive now from full collections inside the block (module doc)."""
    if gc.get_freeze_count():  # frozen already (an enclosing block, or the host process)
        yield
        return
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()
