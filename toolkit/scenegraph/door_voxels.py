"""The voxels of the door instances, kept up to date from the keys entering the voxel map.

The door evidence of every refresh (:func:`sgtool.scenegraph.door_evidence.doorways`)
needs each door's voxels; asking the map (:meth:`~sgtool.mapping.voxels.VoxelMap.voxels_of`)
scans every (voxel, label) key of the house at every refresh. :class:`DoorVoxels` keeps
the door keys instead: the builder hands it the keys new since the last refresh (the ones
the BEV columns are updated from) and, when it rebuilds those columns from every key (the
floor level moved, voxels were removed), all keys. A door's voxels are then the same set
``voxels_of`` gives (keys only enter the map between removals; any removal makes the
builder rebuild), in another order, which no consumer depends on. A change of the set of
door instances (a new instance table) also asks for a rebuild (:meth:`DoorVoxels.stale`).

Door *evidence* is the voxels a door wins (:meth:`DoorVoxels.won`): labels are votes over
frames, so a frame that gave another object's pixels a door's id (a swapped label) adds
a minority door vote there and no doorway. Only the kept door keys' voxels can be won by
a door, so their winners are looked up in those voxels alone
(:meth:`~sgtool.mapping.voxels.VoxelMap.winning_labels`), never by a scan of the map. A
swapped frame can still give a door the part of an object that frame alone saw (no other
vote there): those columns hold door voxels that one frame each gave, so a door's column
is evidence only when it holds a voxel that several frames gave the door's label (the
builder asks for two; a door seen in fewer frames so far asks for fewer). A blob a door
wins farther away is dropped: the door's evidence is the won voxels near their median
(:func:`near_median`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np

from sgtool.mapping.vote_store import sorted_unique
from sgtool.mapping.voxels import COLUMN_SHIFT, LABEL_MASK, VOXEL_SHIFT, unpack


def near_median(ijk: np.ndarray, reach: float) -> np.ndarray:
    """The voxels (ijk rows) within ``reach`` voxels (xy distance) of their median x and
    median y: a door's voxels are one panel and its opening, so votes that a swapped
    label left elsewhere in the house (a few frames against hundreds) are dropped; the
    median stays with the majority. Order kept."""
    if len(ijk) == 0:
        return ijk
    mx = float(np.median(ijk[:, 0]))
    my = float(np.median(ijk[:, 1]))
    d2 = (ijk[:, 0] - mx) ** 2 + (ijk[:, 1] - my) ** 2
    keep = d2 <= reach * reach
    return ijk if keep.all() else ijk[keep]


def _same_column(keys: np.ndarray, door: np.ndarray, strong: np.ndarray) -> np.ndarray:
    """Which of the (voxel, label) ``keys`` (of the doors ``door``) share their (x, y)
    column with a ``strong`` key of the same door."""
    col = (door.astype(np.int64) << 40) | (keys >> COLUMN_SHIFT)
    anchor = np.sort(col[strong])
    if not len(anchor):
        return strong.copy()
    at = np.minimum(np.searchsorted(anchor, col), len(anchor) - 1)
    return anchor[at] == col


class DoorVoxels:
    """Door instance id -> its (voxel, label) keys (module doc)."""

    def __init__(self) -> None:
        self._doors: frozenset[int] = frozenset()
        self._keys: dict[int, list[np.ndarray]] = {}
        self._ijk: dict[int, np.ndarray] = {}  # unpacked keys of a door, until it gets more

    def stale(self, doors: Iterable[int]) -> bool:
        """True when the door instances differ from those the keys were kept for."""
        return frozenset(int(d) for d in doors) != self._doors

    def reset(self, keys: np.ndarray, label_ids: np.ndarray, doors: Iterable[int]) -> None:
        """Keep the door keys among ``keys`` (every key of the map) only."""
        self._doors = frozenset(int(d) for d in doors)
        self._keys = {}
        self._ijk = {}
        self.add(keys, label_ids)

    def add(self, keys: np.ndarray, label_ids: np.ndarray) -> None:
        """Keys new in the map; ``label_ids`` the instance id of every label index."""
        if not self._doors or len(keys) == 0:
            return
        n = len(label_ids)
        if n < 2:
            return
        door_label = np.isin(label_ids, np.asarray(sorted(self._doors), dtype=np.int64))
        door_label[0] = False  # label 0: no instance
        lab = keys & LABEL_MASK
        hit = door_label[np.minimum(lab, n - 1)] & (lab < n)  # overflow labels: no door
        if not hit.any():
            return
        keys = keys[hit]
        inst = label_ids[keys & LABEL_MASK]
        for iid in np.unique(inst).tolist():
            self._keys.setdefault(int(iid), []).append(keys[inst == iid])
            self._ijk.pop(int(iid), None)

    def won(self, instance_ids: Iterable[int],
            winning_labels: Callable[[np.ndarray], np.ndarray],
            frame_counts: Callable[[np.ndarray], np.ndarray] | None = None,
            min_frames: int = 1) -> dict[int, np.ndarray]:
        """Instance id -> ijk (M, 3) of the voxels each door wins (module doc);
        ``winning_labels`` gives the winning label of sorted distinct voxel keys (the map's
        :meth:`~sgtool.mapping.voxels.VoxelMap.winning_labels`). With ``frame_counts`` (the
        map's :meth:`~sgtool.mapping.voxels.VoxelMap.frame_counts`) a won voxel counts
        only in a column where the door holds a voxel that at least ``need`` frames gave
        its label, ``need`` = ``min_frames``, or the median of the door's won voxels' frame
        counts when that is lower (a door seen in one frame so far keeps its voxels)."""
        ids = sorted(int(i) for i in instance_ids)
        parts = []
        for iid in ids:
            got = self._keys.get(iid)
            if got and len(got) > 1:
                got[:] = [np.concatenate(got)]
            parts.append(got[0] if got else np.zeros(0, np.int64))
        sizes = np.array([len(p) for p in parts], dtype=np.int64)
        if not sizes.sum():
            return {iid: np.zeros((0, 3), np.int64) for iid in ids}
        keys = np.concatenate(parts)  # door by door, in id order
        door = np.repeat(np.arange(len(ids)), sizes)
        vk_all = keys >> VOXEL_SHIFT
        vk = sorted_unique(vk_all)
        at = np.searchsorted(vk, vk_all)
        mine = winning_labels(vk)[at] == (keys & LABEL_MASK)
        if frame_counts is not None and min_frames > 1 and mine.any():
            won_at = np.flatnonzero(mine)
            frames = frame_counts(keys[won_at])
            need = np.full(len(ids), min_frames, dtype=np.int64)
            for j in np.unique(door[won_at]).tolist():
                need[j] = min(min_frames, int(np.median(frames[door[won_at] == j])))
            strong = frames >= need[door[won_at]]
            mine[won_at] = _same_column(keys[won_at], door[won_at], strong)
        ix, iy, iz, _ = unpack(keys[mine])
        ijk = np.stack([ix, iy, iz], axis=1)
        split = np.cumsum(np.bincount(door[mine], minlength=len(ids)))[:-1]
        return dict(zip(ids, np.split(ijk, split), strict=True))

    def of(self, instance_ids: Iterable[int]) -> dict[int, np.ndarray]:
        """Instance id -> ijk (M, 3) of its voxels (each once), for door instances."""
        out: dict[int, np.ndarray] = {}
        for iid in sorted(int(i) for i in instance_ids):
            parts = self._keys.get(iid)
            if not parts:
                out[iid] = np.zeros((0, 3), np.int64)
                continue
            got = self._ijk.get(iid)
            if got is None:
                if len(parts) > 1:
                    parts[:] = [np.concatenate(parts)]
                ix, iy, iz, _ = unpack(parts[0])
                got = self._ijk[iid] = np.stack([ix, iy, iz], axis=1)
                got.setflags(write=False)
            out[iid] = got
        return out
