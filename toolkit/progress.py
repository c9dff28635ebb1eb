"""Progress reporting: what long-running functions (replay, a closed-loop episode) advance
as they work."""

from __future__ import annotations

from typing import Protocol


class Progress(Protocol):
    """Anything that counts work done: ``update(n)`` advances it by ``n`` units (frames);
    its return value is ignored. A ``tqdm`` bar is one; so is any object with that method."""

    def update(self, n: int, /) -> object:
        """Advance by ``n`` units."""
        ...
