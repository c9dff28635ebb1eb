"""Time sync of a bag import: the depth images in time order, each with its pose and the
colour and instance-id images nearest in time within ``--max-dt``, and notes on what was
dropped or could not be paired."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.recorders.importers.bag_index import BagIndex
from sgtool.recorders.importers.bag_options import BagOptions
from sgtool.recorders.importers.bag_poses import PoseSource
from sgtool.recorders.importers.sanity import dropped_problem
from sgtool.recorders.importers.stamps import NearestStamp
from sgtool.recorders.importers.tftree import frame_name


@dataclass(frozen=True)
class PlannedFrame:
    k_depth: int
    t_ns: int
    pose: np.ndarray | None
    k_rgb: int | None
    k_ids: int | None


def planned_poses(plan: list[PlannedFrame]) -> list[np.ndarray]:
    """The poses of ``plan`` in order, for a plan whose every frame is posed (by the pose
    source, or after odometry filled the unposed ones in)."""
    poses = []
    for p in plan:
        assert p.pose is not None, f"depth image {p.k_depth} was planned without a pose"
        poses.append(p.pose)
    return poses


def plan_frames(
    idx: BagIndex, src: PoseSource | None, opts: BagOptions, keep_unposed: bool = False
) -> tuple[list[PlannedFrame], list[str]]:
    """The frames to write: depth images in time order with their pose (None when
    ``src`` is None or, with ``keep_unposed``, when it does not cover the time) and the
    colour/id images paired with them. Dropping more than
    :data:`~.sanity.MAX_DROPPED` of the images for want of a pose is an error naming the
    flags, unless ``opts.allow_drop``."""
    notes = []
    seen: set[int] = set()
    rgb_near, ids_near = NearestStamp(idx.rgb.stamps), NearestStamp(idx.ids.stamps)
    plan = []
    no_pose = dup = no_rgb = no_ids = 0
    explicit_cam = opts.tf_frames is not None or opts.pose is not None
    for k in sorted(range(len(idx.depth.stamps)), key=lambda i: idx.depth.stamps[i]):
        t = idx.depth.stamps[k]
        if t in seen:
            dup += 1
            continue
        seen.add(t)
        pose = None if src is None else src.at(t, None if explicit_cam else idx.depth.frames[k])
        if pose is None and src is not None:
            no_pose += 1
            if not keep_unposed:
                continue
        k_rgb = rgb_near(t, opts.max_dt_ns) if opts.rgb else None
        k_ids = ids_near(t, opts.max_dt_ns) if opts.ids else None
        no_rgb += opts.rgb is not None and k_rgb is None
        no_ids += opts.ids is not None and k_ids is None
        plan.append(PlannedFrame(k, t, pose, k_rgb, k_ids))
    if no_pose and src is not None:
        what = "kept, estimated" if keep_unposed else "dropped"
        notes.append(f"{no_pose} depth images without a pose from {src.describe} ({what})")
        if not keep_unposed and not opts.allow_drop:
            problem = dropped_problem(
                no_pose, len(seen), f"no pose from {src.describe} within --tf-tolerance "
                f"{opts.tf_tolerance_ns / 1e9:g} s of their time",
                "give --tf-tolerance S to take poses further from the samples, "
                "--estimate-poses to estimate them by odometry, or --allow-drop to import "
                "only the posed frames")
            if problem:
                raise SgtoolError(problem)
    if dup:
        notes.append(f"{dup} depth images repeated a time stamp (dropped)")
    if no_rgb:
        notes.append(f"{no_rgb} depth images had no colour within {opts.max_dt_ns / 1e6:g} ms")
    if no_ids:
        notes.append(f"{no_ids} depth images had no instance ids within "
                     f"{opts.max_dt_ns / 1e6:g} ms")
    if opts.tf_frames is not None and idx.depth.frames:
        img_frames = sorted(set(idx.depth.frames))
        if img_frames != [frame_name(opts.tf_frames[1])]:
            notes.append(
                f"the depth images are in frame {', '.join(img_frames)}; the pose is that of "
                f"--tf-frames {frame_name(opts.tf_frames[1])} (it must be the optical frame: "
                "x right, y down, z forward)"
            )
    if idx.zero_stamps:
        notes.append(f"{idx.zero_stamps} images had a zero header stamp (bag time used)")
    if idx.tf_zero_stamps:
        notes.append(f"{idx.tf_zero_stamps} /tf transforms had a zero header stamp (bag time "
                     "used, less the other /tf stamps' delay)")
    if idx.info_changes:
        notes.append(f"the camera info changed {idx.info_changes} time(s); each image has the "
                     "one in effect at its time (the world alignment and checks use the first)")
    plan = plan[:: opts.every]
    if opts.limit is not None:
        plan = plan[: opts.limit]
    return plan, notes
