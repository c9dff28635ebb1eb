"""RoomSpace keeps its blocked cells incrementally: the same answers as the distance
transform of the whole room (the definition) on seeded random furnishings."""

from __future__ import annotations

import numpy as np
from scipy import ndimage
from support.room_space_reference import free_mask_edt

from sgtool.datasets.house_plan import Opening, PlanRoom, Rect
from sgtool.datasets.robot_clearance import REACH, ROBOT_RADIUS
from sgtool.datasets.room_space import CELL, RoomSpace


def _reference_free_ok(space: RoomSpace, boxes: list[Rect], extra: Rect | None) -> bool:
    """free_ok as it was written before: the EDT of the whole room, whole-grid reach masks."""
    occ = space.occ.copy()
    if extra is not None:
        occ[space._cell_slices(extra)] = True
    free = free_mask_edt(occ, CELL)
    labels, _ = ndimage.label(free, structure=np.ones((3, 3), bool))
    if not space.approach:
        return True
    lab = {int(labels[a]) for a in space.approach}
    if 0 in lab or len(lab) != 1:
        return False
    main = labels == lab.pop()
    ys = space.inner.y0 + (np.arange(space.rows) + 0.5) * CELL
    xs = space.inner.x0 + (np.arange(space.cols) + 0.5) * CELL
    for b in boxes:
        dx = np.maximum(np.maximum(b.x0 - xs, xs - b.x1), 0.0)
        dy = np.maximum(np.maximum(b.y0 - ys, ys - b.y1), 0.0)
        near = (dy[:, None] ** 2 + dx[None, :] ** 2) <= (REACH - ROBOT_RADIUS) ** 2
        if not (near & main).any():
            return False
    return True


def _room() -> tuple[PlanRoom, list[Opening]]:
    room = PlanRoom(0, "kitchen", Rect(0.0, 0.0, 4.3, 3.7), "n")
    doors = [Opening("door", (1.2, 0.0), 0.9, True, (0, 1)),
             Opening("door", (4.3, 2.0), 0.9, False, (0, 2))]
    return room, doors


def _box(rng: np.random.Generator) -> Rect:
    x, y = rng.uniform(-0.3, 4.3), rng.uniform(-0.3, 3.7)
    w, d = rng.uniform(0.05, 1.6), rng.uniform(0.05, 1.2)
    return Rect(float(x), float(y), float(x + w), float(y + d))


def test_blocked_cells_match_the_distance_transform() -> None:
    rng = np.random.default_rng(7)
    for _ in range(20):
        space = RoomSpace(*_room())
        assert np.array_equal(~space.blocked, free_mask_edt(space.occ, CELL))
        for _ in range(6):
            space.add(_box(rng))
            assert np.array_equal(~space.blocked, free_mask_edt(space.occ, CELL))


def test_free_ok_matches_the_whole_room_check() -> None:
    rng = np.random.default_rng(11)
    answers = []
    for _ in range(30):
        space = RoomSpace(*_room())
        placed: list[Rect] = []
        for _ in range(8):
            extra = _box(rng) if rng.random() < 0.8 else None
            reach = placed + ([extra] if extra is not None else [])
            got = space.free_ok(reach, extra)
            assert got == _reference_free_ok(space, reach, extra)
            answers.append(got)
            if got and extra is not None:
                space.add(extra)
                placed.append(extra)
    assert 0 < sum(answers) < len(answers)  # both outcomes were checked
