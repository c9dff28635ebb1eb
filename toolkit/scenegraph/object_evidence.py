"""Whether a seen instance is an object of the scene graph, and where: its labels are
votes over frames, not a verdict of one frame.

- **Existence.** An instance is an object once at least ``min_frames`` frames gave it
  points, and only while it *wins* at least ``min_voxels`` voxels (the most votes in the
  voxel, ties to the lower label index, as
  :meth:`~sgtool.mapping.voxels.VoxelMap.winning_labels`). A label that one frame put on
  something (a swapped or spurious id) makes no object. An object seen in many frames
  keeps its voxels through a few contradicting frames (they add minority votes), but it
  is dropped when its voxels are seen empty (the map removes voxels that views saw
  through, :meth:`~sgtool.mapping.voxels.VoxelMap.clear_seen_through`) or are all out-voted
  by other labels.
- **Position.** The centroid of the voxels it wins, not of every voxel it got a vote in:
  a frame that gave its id to another object, or depth noise that smeared its label over
  the wall behind it, leaves minority votes there that no longer pull it away.

Pure functions over voxel keys and their winning labels; the map is read by
:func:`sgtool.scenegraph.object_placement.seen_instances`, which looks up the winners
only in the voxels an object or a piece of furniture got a vote in.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sgtool.mapping.voxel_keys import VOXEL_SHIFT, unpack


@dataclass(frozen=True)
class EvidenceRule:
    """How much evidence makes an object (module doc)."""

    min_frames: int = 2  # frames that gave the instance points
    min_voxels: int = 1  # voxels it wins


@dataclass(frozen=True)
class WonVoxels:
    """Per label index: the voxels it wins (``count``) and the sum of their integer
    (i, j, k) indices (``sums``, shape (L, 3)), from which their centroid follows."""

    count: np.ndarray
    sums: np.ndarray

    def centroid(self, label: int, resolution: float) -> tuple[float, float, float] | None:
        """Mean of the centres (m) of the voxels ``label`` wins; None when it wins none."""
        if not 0 <= label < len(self.count) or self.count[label] == 0:
            return None
        c = (self.sums[label].astype(np.float64) / float(self.count[label]) + 0.5) * resolution
        return (float(c[0]), float(c[1]), float(c[2]))


def won_voxels(voxel_keys: np.ndarray, winners: np.ndarray, n_labels: int) -> WonVoxels:
    """:class:`WonVoxels` of distinct voxels (``key >> VOXEL_SHIFT``) and the winning label
    index of each (:meth:`~sgtool.mapping.voxels.VoxelMap.winning_labels`), for label
    indices below ``n_labels`` (winners with a higher index are not counted)."""
    ix, iy, iz, _ = unpack(voxel_keys << VOXEL_SHIFT)
    ok = winners < n_labels
    lab = winners[ok]
    count = np.bincount(lab, minlength=n_labels)[:n_labels].astype(np.int64)
    sums = np.zeros((n_labels, 3), dtype=np.int64)
    for axis, idx in enumerate((ix[ok], iy[ok], iz[ok])):  # integer sums, exact in float64
        s = np.bincount(lab, weights=idx.astype(np.float64), minlength=n_labels)
        sums[:, axis] = np.rint(s[:n_labels]).astype(np.int64)
    return WonVoxels(count, sums)


def is_object(frames: int, won: int, rule: EvidenceRule) -> bool:
    """True when an instance given points by ``frames`` frames and winning ``won`` voxels
    has the evidence ``rule`` asks for (module doc)."""
    return frames >= rule.min_frames and won >= rule.min_voxels
