"""The semantic voxel map of a log over time, for viewers (``sgtool view``).

:func:`voxel_snapshots` integrates the log's frames into a
:class:`~sgtool.mapping.voxels.VoxelMap` and, every ``every`` frames and after the last,
yields the map: voxel centres, colours and the voxel size. A voxel takes the colour of the
instance that won its label vote (the colour ``sgtool view`` gives that instance in the
segmentation image); voxels without an instance are shaded grey by height. At most
``max_voxels`` are drawn per snapshot (a deterministic stride over the sorted voxels), so
a whole house stays light in the viewer.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from sgtool.colors import color_for
from sgtool.log.reader import LogReader
from sgtool.mapping.voxels import VoxelConfig, VoxelMap

Snapshot = tuple[int, int, np.ndarray, np.ndarray, float]


def voxel_colours(ijk: np.ndarray, instance_ids: np.ndarray) -> np.ndarray:
    """(N, 3) uint8: the instance colour, grey by height where the id is 0."""
    cols = np.empty((len(ijk), 3), dtype=np.uint8)
    if not len(ijk):
        return cols
    ids = np.asarray(instance_ids)
    table = {int(i): color_for(int(i)) for i in np.unique(ids) if i > 0}
    for i, c in table.items():
        cols[ids == i] = c
    bare = ids <= 0
    if bare.any():
        z = ijk[bare, 2].astype(np.float64)
        span = max(float(z.max() - z.min()), 1.0)
        g = (90 + 130 * (z - z.min()) / span).astype(np.uint8)
        cols[bare] = np.stack([g, g, g], axis=1)
    return cols


def snapshot(vm: VoxelMap, max_voxels: int) -> tuple[np.ndarray, np.ndarray]:
    """Centres (N, 3) float32 and colours (N, 3) uint8 of (a stride over) the map."""
    ijk, label, _ = vm.voxels()
    if len(ijk) > max_voxels:
        keep = np.arange(0, len(ijk), int(np.ceil(len(ijk) / max_voxels)))
        ijk, label = ijk[keep], label[keep]
    ids = vm.label_ids()[label] if len(label) else np.zeros(0, np.int64)
    centres = ((ijk.astype(np.float64) + 0.5) * vm.resolution).astype(np.float32)
    return centres, voxel_colours(ijk, ids)


def voxel_snapshots(reader: LogReader, every: int = 10, max_frames: int | None = None,
                    config: VoxelConfig | None = None, max_voxels: int = 150_000
                    ) -> Iterator[Snapshot]:
    """(frame index, log time, centres, colours, voxel size) every ``every`` frames and
    after the last frame (module doc)."""
    vm = VoxelMap(config or VoxelConfig())
    last: tuple[int, int] | None = None
    n = 0
    for fr in reader.frames():
        if max_frames is not None and n >= max_frames:
            break
        if not np.all(np.isfinite(fr.pose)):
            continue
        src = fr.base_pose if fr.base_pose is not None else fr.pose
        vm.integrate(fr, (float(src[0, 3]), float(src[1, 3])))
        n += 1
        last = (fr.index, fr.time_ns)
        if n % every == 0:
            c, col = snapshot(vm, max_voxels)
            yield fr.index, fr.time_ns, c, col, vm.resolution
            last = None
    if last is not None:
        c, col = snapshot(vm, max_voxels)
        yield last[0], last[1], c, col, vm.resolution
