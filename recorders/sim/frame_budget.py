"""The frame budget of a closed-loop episode: a fixed count, or so many frames per room.

The papers scale an episode's budget with the size of the house; ``--frames-per-room N``
(``sgtool run``, ``sgtool run-bench``) gives an episode ``N x`` the house's room count
frames. It excludes ``--frames``.
"""

from __future__ import annotations

from sgtool.errors import SgtoolError


class FrameBudgetError(SgtoolError):
    """Both budgets given, or one below 1."""


def frame_budget(frames: int | None, per_room: int | None, rooms: int) -> int | None:
    """The episode's frame budget (None: none): ``frames``, or ``per_room x rooms``."""
    if frames is not None and per_room is not None:
        raise FrameBudgetError("give either --frames or --frames-per-room, not both")
    if frames is not None and frames < 1:
        raise FrameBudgetError(f"--frames {frames}: must be >= 1")
    if per_room is None:
        return frames
    if per_room < 1:
        raise FrameBudgetError(f"--frames-per-room {per_room}: must be >= 1")
    return int(per_room) * max(int(rooms), 1)
