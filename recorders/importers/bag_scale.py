"""The depth scale of a bag checked against its metric poses (``/tf`` or ``--pose``) before
the frames are written: a few pairs of nearby depth images are decoded (one pass over the
depth topic, deserialising only those) and their ICP motion compared with the poses'
(:mod:`.scale_check`). The fit says whether the poses move as the depth does, whatever the
depth's encoding; only 16-bit depth has a scale to name."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from sgtool.log.frame import CameraIntrinsics
from sgtool.recorders.importers import bagfiles as B
from sgtool.recorders.importers.bag_index import BagIndex
from sgtool.recorders.importers.bag_options import BagOptions
from sgtool.recorders.importers.bag_poses import PoseSource
from sgtool.recorders.importers.images import decode_depth_message, depth_to_metres
from sgtool.recorders.importers.scale_check import (
    ScaleFit,
    geometric_scale_problem,
    pair_indices,
)

_Pair = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def bag_scale_pairs(reader: Any, idx: BagIndex, opts: BagOptions, src: PoseSource,
                    k: CameraIntrinsics,
                    selects: Sequence[Callable[[list[np.ndarray]], list[tuple[int, int]]]]
                    = (pair_indices,)) -> list[list[_Pair]]:
    """Per selector of ``selects``, pairs of depth images in metres with their poses from
    ``src``, as :func:`~.scale_check.fit_scale` and
    :func:`~.scale_check.convention_problems` take them (one pass over the depth topic for
    all): the pairs it picks from the images' poses in time order (:func:`pair_indices`:
    nearby frames; :func:`~.focal_check.turn_pairs`: turned ones); empty without a usable
    pair."""
    empty: list[list[_Pair]] = [[] for _ in selects]
    if not idx.samples:
        return empty
    explicit = opts.tf_frames is not None or opts.pose is not None
    posed: list[tuple[int, np.ndarray]] = []
    for kk in sorted(range(len(idx.depth.stamps)), key=lambda i: idx.depth.stamps[i]):
        T = src.at(idx.depth.stamps[kk], None if explicit else idx.depth.frames[kk])  # noqa: N806
        if T is not None:
            posed.append((kk, T))
    chosen = [select([T for _, T in posed]) for select in selects]
    need = {posed[i][0] for pairs in chosen for p in pairs for i in p}
    if not need:
        return empty
    got: dict[int, np.ndarray] = {}
    count = 0
    for c, _, raw in reader.messages(connections=B.connections_for(reader, str(opts.depth))):
        if count in need:
            a, scale = decode_depth_message(B.deserialize(reader, raw, c),
                                            B.normalise_type(c.msgtype), c.topic)
            s = opts.depth_scale if opts.depth_scale else scale
            got[count] = depth_to_metres(a, s)
            if len(got) == len(need):
                break
        count += 1
    return [[(got[posed[i][0]], got[posed[j][0]], posed[i][1], posed[j][1])
             for i, j in pairs if posed[i][0] in got and posed[j][0] in got
             and got[posed[i][0]].shape == (k.height, k.width)]
            for pairs in chosen]


def bag_scale_problem(fit: ScaleFit | None, idx: BagIndex, opts: BagOptions,
                      src: PoseSource, origin: str) -> str | None:
    """The problem of the fit (naming the ``--depth-scale`` that fits), or None; None for
    depth that is not 16-bit (metres have no scale to name: :func:`bag_scale_pairs`' other
    use, the poses' motion, is :func:`~.scale_check.pose_motion_problem`'s)."""
    if not idx.samples or next(iter(idx.samples.values()))[0].dtype != np.uint16:
        return None
    return geometric_scale_problem(fit, opts.depth_scale or 1000.0, origin, src.describe)
