"""Where the camera poses of a bag import come from: a pose topic (``--pose``) or the tf
tree between a world frame and the camera frame (``--tf-frames``, by default the depth
image's frame in the root of its tree), checked against the bag with errors that list
its frames and links."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log.poses import PoseTrack
from sgtool.recorders.importers.bag_index import BagIndex
from sgtool.recorders.importers.bag_options import BagOptions
from sgtool.recorders.importers.pose_axes import to_optical
from sgtool.recorders.importers.tftree import TfTree, frame_name


@dataclass(frozen=True)
class PoseSource:
    """world_T_camera at a time, from the tf ``tree`` or a pose ``track`` (one of them), or
    a track of the frame ``mounted_on`` (a robot's odometry) carried to the camera by the
    tree."""

    world: str  # frame name
    camera: str  # frame name ("camera" for a pose topic of the camera itself)
    describe: str  # for notes, errors and the log metadata
    tree: TfTree | None = None
    track: PoseTrack | None = None
    mounted_on: str = ""  # the frame the track gives the pose of, when not the camera's
    axes: str = "optical"  # the camera frame's axes (:mod:`.pose_axes`): turned to optical

    def at(self, t_ns: int, camera: str | None = None) -> np.ndarray | None:
        """The pose of the optical frame at ``t_ns`` (of frame ``camera`` instead of the
        source's, in a tree); None where it cannot be resolved."""
        pose = self._frame_at(t_ns, camera)
        return pose if pose is None or self.axes == "optical" else to_optical(pose, self.axes)

    def _frame_at(self, t_ns: int, camera: str | None) -> np.ndarray | None:
        if self.track is not None:
            pose = self.track.at(t_ns)
            if pose is None or not self.mounted_on:
                return pose
            assert self.tree is not None
            mount = self.tree.lookup(self.mounted_on, camera or self.camera, t_ns)
            return None if mount is None else pose @ mount
        assert self.tree is not None
        return self.tree.lookup(self.world, camera or self.camera, t_ns)


def _links(tree: TfTree, most: int = 12) -> str:
    """The tree's links on one line (the first ``most``, then how many more)."""
    links = tree.describe()
    more = f"; and {len(links) - most} more" if len(links) > most else ""
    return "; ".join(links[:most]) + more


def pose_source_of(path: Path, idx: BagIndex, opts: BagOptions) -> PoseSource:
    """Where the camera's poses come from (``--pose``, ``--tf-frames`` or the depth
    images' frame in its tree), read with ``--camera-axes``; a one-line error naming the
    flags when the bag does not give them."""
    src = _source_of(path, idx, opts)
    if opts.camera_axes == "optical":
        return src
    return replace(src, axes=opts.camera_axes,
                   describe=f"{src.describe}, camera axes {opts.camera_axes}")


def _source_of(path: Path, idx: BagIndex, opts: BagOptions) -> PoseSource:
    if opts.pose is not None:
        if not idx.pose_samples:
            raise SgtoolError(f"{path}: --pose {opts.pose} has no messages")
        track = PoseTrack.from_samples(idx.pose_samples, max_gap_ns=opts.tf_max_gap_ns,
                                       tolerance_ns=opts.tf_tolerance_ns)
        what = f"topic {opts.pose} ({len(track)} poses)"
        child, cam = idx.pose_child, (idx.depth.frames[0] if idx.depth.frames else "")
        if not child or not cam or child == cam:
            return PoseSource(idx.pose_frame or "world", "camera", what, track=track)
        if child not in idx.tf.frames() or cam not in idx.tf.frames() or \
                idx.tf.path(child, cam) is None:
            raise SgtoolError(
                f"{path}: --pose {opts.pose} gives the pose of frame {child!r}, the depth "
                f"images are in frame {cam!r}, and /tf does not link the two; give "
                f"--tf-frames WORLD:{cam} to take the camera's pose from /tf, or a pose "
                "topic of the camera")
        return PoseSource(idx.pose_frame or "world", cam, f"{what}, of {child} -> {cam} "
                          "by /tf", tree=idx.tf, track=track, mounted_on=child)
    tree = idx.tf
    if not tree.links:
        raise SgtoolError(f"{path}: no transforms on /tf or /tf_static; give --pose TOPIC")
    frames_list = ", ".join(tree.frames())
    if opts.tf_frames is not None:
        world, camera = (frame_name(f) for f in opts.tf_frames)
    else:
        camera = idx.depth.frames[0] if idx.depth.frames else ""
        if camera not in tree.frames():
            raise SgtoolError(
                f"{path}: the depth images are in frame {camera!r}, which is not in the tf "
                f"tree (frames: {frames_list}); give --tf-frames WORLD:CAMERA"
            )
        world = tree.root_of(camera)
        if world == camera or outward_worlds(tree, camera):
            raise SgtoolError(f"{path}: {stored_outwards(tree, camera)}")
    if world == camera:
        raise SgtoolError(f"{path}: --tf-frames {world}:{camera}: the world and the camera "
                          "are one frame (every pose would be the identity)")
    for f in (world, camera):
        if f not in tree.frames():
            raise SgtoolError(
                f"{path}: --tf-frames: frame {f!r} is not in the tf tree; its links: "
                + _links(tree)
            )
    if tree.path(world, camera) is None:
        raise SgtoolError(
            f"{path}: frames {world!r} and {camera!r} are not connected in the tf tree "
            f"(roots: {', '.join(tree.roots())}); links: " + _links(tree)
        )
    return PoseSource(world, camera, f"tf {world} -> {camera}", tree=tree)


WORLD_NAMES = ("world", "map", "odom")  # frame names a world frame goes by, likeliest first


def is_world_name(frame: str) -> bool:
    return frame.lstrip("/") in WORLD_NAMES


def camera_like(tree: TfTree) -> list[str]:
    """The frames that look like cameras: those with "optical" in the name, else with
    "camera", else the leaves of the tree."""
    frames = tree.frames()
    parents = {link.parent for link in tree.links.values()}
    return [f for f in frames if "optical" in f] or [f for f in frames if "camera" in f] \
        or sorted(f for f in tree.links if f not in parents)


def world_candidates(tree: TfTree, camera: str) -> list[str]:
    """The frames linked with ``camera`` named like a world (:data:`WORLD_NAMES`, in that
    order), ``camera`` itself left out."""
    linked = [f for f in tree.frames() if f != camera and tree.path(f, camera) is not None]
    return [f for n in WORLD_NAMES for f in linked if f.lstrip("/") == n]


def outward_worlds(tree: TfTree, camera: str) -> list[str]:
    """The world-named frames linked with ``camera`` off its way to the root, when none is
    on it: a tree stored from the camera out (camera_link -> world); empty otherwise."""
    up = tree.ancestors(camera)
    if any(is_world_name(f) for f in up):
        return []
    return [f for f in world_candidates(tree, camera) if f not in up]


def stored_outwards(tree: TfTree, camera: str) -> str:
    """Why no default pose is read for ``camera`` (one line, no path): the tree stored
    from the camera out, with the pair to give; the images in a world frame, with the
    camera-like frames; or no world frame at all, with --estimate-poses."""
    root = tree.root_of(camera)
    where = "is the root of its tf tree" if root == camera else \
        f"hangs under {root!r}, the root of its tf tree"
    if is_world_name(camera):
        cams = [f for f in camera_like(tree) if f != camera]
        return (f"the depth images are in frame {camera!r}, the root of its tf tree: a world, "
                "not a camera; give --tf-frames WORLD:CAMERA with the camera's frame"
                + (f", e.g. --tf-frames {camera}:{cams[0]}" if cams else ""))
    named = outward_worlds(tree, camera) or world_candidates(tree, camera)
    if named:
        return (f"the depth images' frame {camera!r} {where}, and {named[0]!r} below it: the "
                "transforms are stored from the camera out, so no pose of the camera can be "
                f"read by default; give --tf-frames {named[0]}:{camera}")
    return (f"the depth images' frame {camera!r} {where} and no frame named like a world "
            f"({', '.join(WORLD_NAMES)}) is linked to it: the bag holds no camera "
            "trajectory; give --tf-frames WORLD:CAMERA, or --estimate-poses")
