"""``sgtool import bag``: a ROS 1 / ROS 2 recording into an sgtool log.

What is read (flags of the command):
- ``--depth`` ``sensor_msgs/Image`` (16UC1 mm, 32FC1 m) or ``CompressedImage`` (PNG or
  ``compressedDepth``): one sgtool frame per depth image, at its header time stamp;
- ``--rgb`` colour ``Image``/``CompressedImage``, ``--ids`` instance-id ``Image``: each
  associated with the depth image of nearest header stamp within ``--max-dt`` (20 ms) and
  written at the depth image's time (an sgtool frame is the messages of one log time);
- ``--info`` ``CameraInfo`` (K/k, ROS 1 and ROS 2 spellings): the intrinsics;
- the camera pose: the ``/tf`` + ``/tf_static`` tree from ``WORLD`` to ``CAMERA``
  (``--tf-frames WORLD:CAMERA``; by default the depth image's frame in the root of its
  tree), every dynamic link interpolated at the image time (:mod:`.tftree`); or
  ``--pose TOPIC`` (``PoseStamped``, ``PoseWithCovarianceStamped``, ``TransformStamped``,
  ``Odometry``) giving the camera's optical frame in the world directly.

Without ``--depth``, ``--tf-frames`` or ``--pose`` alone import a *trajectory*: a log of
``/tf`` world -> camera transforms at the times the pose was measured, without frames.

A bag with images but no ``/tf`` and no ``--pose`` (a camera recorded alone), or any bag
with ``--estimate-poses``, gets its camera poses from RGB-D odometry (:mod:`.odometry`,
one more pass over the images); the drift against the bag's own poses is reported when it
has them. ``--estimate-poses`` needs ``--depth``: a bag of trajectories alone (no image
topic) is an error that suggests ``--tf-frames`` and ``--pose``.

When a flag is missing or names the wrong thing, the error lists the bag's topics with
their types and suggests flags. The bag is read in two passes (time stamps, transforms and
calibration; then the images), so memory stays at a few frames.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log import schemas as S
from sgtool.log.frame import CameraIntrinsics
from sgtool.log.writer import LogWriter
from sgtool.recorders.importers import bagfiles as B
from sgtool.recorders.importers.checks import (
    check_counts,
    check_depth_scale,
    check_non_negative,
    check_positive,
)
from sgtool.recorders.importers.images import (
    decode_color_message,
    decode_depth_message,
    decode_ids_message,
    depth_for_log,
    depth_to_metres,
    resize_to,
)
from sgtool.recorders.importers.odometry import (
    DriftReport,
    OdometryResult,
    drift_against,
    estimate_trajectory,
)
from sgtool.recorders.importers.poses import PoseTrack, pose_from_tq
from sgtool.recorders.importers.sink import (
    IMPORT_METADATA,
    ImportFrame,
    ImportReport,
    drift_metadata,
    odometry_metadata,
    odometry_report_fields,
    write_log,
)
from sgtool.recorders.importers.textformats import PinholeParams
from sgtool.recorders.importers.tftree import TfTree, frame_name
from sgtool.recorders.importers.upright import DepthSample, WorldAlignment, estimate_alignment

ALIGNMENT_SAMPLES = 8


@dataclass(frozen=True)
class BagOptions:
    rgb: str | None = None
    depth: str | None = None
    ids: str | None = None
    info: str | None = None
    tf_frames: tuple[str, str] | None = None  # (world, camera)
    pose: str | None = None
    intrinsics: PinholeParams | None = None
    depth_scale: float | None = None  # units per metre of 16-bit depth; None = mm
    max_dt_ns: int = 20_000_000
    tf_tolerance_ns: int = 50_000_000
    tf_max_gap_ns: int = 500_000_000
    up: np.ndarray | None = None
    floor: float | None = None
    floor_auto: bool = True
    every: int = 1
    limit: int | None = None
    progress: bool = True
    compression: str = "zstd"
    estimate_poses: bool = False
    odometry: str = "rgbd+icp"
    depth_max: float = 4.0


# ----- message fields ------------------------------------------------------------------------
def stamp_ns(header: Any) -> int:
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def _tq(translation: Any, rotation: Any) -> np.ndarray:
    return pose_from_tq(
        (translation.x, translation.y, translation.z), (rotation.x, rotation.y, rotation.z,
                                                        rotation.w)
    )


def pose_of_message(msg: Any, msgtype: str) -> tuple[int, str, np.ndarray]:
    """(stamp, parent frame, parent_T_child) of a pose-like message."""
    if msgtype.endswith("TransformStamped"):
        T = _tq(msg.transform.translation, msg.transform.rotation)  # noqa: N806
    elif msgtype.endswith("PoseStamped"):
        T = _tq(msg.pose.position, msg.pose.orientation)  # noqa: N806
    else:  # PoseWithCovarianceStamped, Odometry
        T = _tq(msg.pose.pose.position, msg.pose.pose.orientation)  # noqa: N806
    return stamp_ns(msg.header), frame_name(msg.header.frame_id), T


def intrinsics_of_info(msg: Any) -> tuple[int, int, float, float, float, float]:
    k = getattr(msg, "k", None)
    if k is None:
        k = msg.K  # ROS 1 spelling
    k = np.asarray(k, dtype=np.float64).ravel()
    return int(msg.width), int(msg.height), float(k[0]), float(k[4]), float(k[2]), float(k[5])


# ----- flags, topics and suggestions ---------------------------------------------------------
def suggest_flags(topics: list[B.TopicInfo], tf_frames: list[str] | None = None) -> list[str]:
    """Flags guessed from topic names and types (depth/colour/camera_info/ids). Without a
    depth topic, one item of alternatives for a trajectory: ``tf_frames`` (``--tf-frames
    WORLD:FRAME`` when not given and the bag has tf) and the pose topics."""
    images = [t.topic for t in topics if t.msgtype in B.IMAGE_TYPES]
    infos = [t.topic for t in topics if t.msgtype in B.INFO_TYPES]
    poses = [t.topic for t in topics if t.msgtype in B.POSE_TYPES]
    tfs = [t.topic for t in topics if t.msgtype in B.TF_TYPES]
    out = []
    depth = next((t for t in images if "depth" in t.lower()), None)
    ids_words = ("instance", "segment", "label", "ids", "mask")
    ids = next((t for t in images if any(w in t.lower() for w in ids_words)), None)
    rgb = next(
        (t for t in images if t not in (depth, ids)
         and any(w in t.lower() for w in ("rgb", "color", "colour", "image"))),
        None,
    )
    if depth:
        out.append(f"--depth {depth}")
    if rgb:
        out.append(f"--rgb {rgb}")
    if ids:
        out.append(f"--ids {ids}")
    if infos:
        ns = depth.rsplit("/", 1)[0] if depth else ""
        out.append(f"--info {next((t for t in infos if ns and t.startswith(ns)), infos[0])}")
    if not depth:
        alternatives = (list(tf_frames) if tf_frames is not None else
                        ["--tf-frames WORLD:FRAME"] if tfs else [])
        alternatives += [f"--pose {p}" for p in poses[:4]]
        if len(poses) > 4:
            alternatives.append(f"... ({len(poses) - 4} more pose topics)")
        if alternatives:
            out.append(" | ".join(alternatives))
    return out


def peek_tf(reader: Any, topics: list[B.TopicInfo], max_messages: int = 500) -> TfTree:
    """The tf tree from ``/tf_static`` and the first ``max_messages`` ``/tf`` messages: the
    frames a bag has, cheaply, for listing and suggestions."""
    tree = TfTree()
    for t in topics:
        if t.msgtype not in B.TF_TYPES:
            continue
        static = t.topic.rstrip("/").endswith("tf_static")
        for n, (c, _, raw) in enumerate(reader.messages(B.connections_for(reader, t.topic))):
            if n >= max_messages:
                break
            msg = reader.deserialize(raw, c.msgtype)
            for tr in msg.transforms:
                tree.add(tr.header.frame_id, tr.child_frame_id, stamp_ns(tr.header),
                         _tq(tr.transform.translation, tr.transform.rotation), static=static)
    return tree.freeze()


def tf_suggestions(tree: TfTree) -> list[str]:
    """``--tf-frames ROOT:LEAF`` for every leaf frame of the tree."""
    parents = {link.parent for link in tree.links.values()}
    leaves = sorted(f for f in tree.links if f not in parents)
    cams = [f for f in leaves if "optical" in f] or [f for f in leaves if "camera" in f]
    picks = cams or leaves
    out = [f"--tf-frames {tree.root_of(f)}:{f}" for f in picks[:6]]
    if len(picks) > 6:
        out.append(f"... ({len(picks) - 6} more)")
    return out


def describe_bag(reader: Any, path: Path) -> str:
    """Topics, tf links and suggested flags (``sgtool import bag PATH --list``)."""
    topics = B.list_topics(reader)
    tree = peek_tf(reader, topics)
    lines = [f"{path} ({B.bag_kind(path)}): topics", B.format_topics(topics)]
    if tree.links:
        lines.append("tf links (from /tf_static and the first /tf messages):")
        lines.extend("  " + d for d in tree.describe())
    sugg = suggest_flags(topics, tf_frames=[])
    if sugg:
        lines.append("suggested flags: " + " ".join(sugg))
    tfs = tf_suggestions(tree)
    if tfs:
        lines.append("camera / trajectory frames: " + " | ".join(tfs))
    return "\n".join(lines)


def _missing_message(
    path: Path, topics: list[B.TopicInfo], what: str, reader: Any = None
) -> str:
    tfs = None
    if reader is not None and any(t.msgtype in B.TF_TYPES for t in topics):
        tfs = tf_suggestions(peek_tf(reader, topics)) or None
    sugg = suggest_flags(topics, tf_frames=tfs)
    return (
        f"{path}: {what}. The bag's topics:\n{B.format_topics(topics)}"
        + (f"\nsuggested flags: {' '.join(sugg)}" if sugg else "")
    )


def _check_topic(
    path: Path, topics: list[B.TopicInfo], topic: str | None, flag: str, allowed: tuple[str, ...]
) -> None:
    if topic is None:
        return
    found = {t.topic: t for t in topics}
    if topic not in found:
        raise SgtoolError(_missing_message(path, topics, f"{flag} {topic}: no such topic"))
    t = found[topic]
    if t.msgtype not in allowed:
        raise SgtoolError(
            f"{path}: {flag} {topic} is a {t.msgtype} topic; {flag} needs "
            + " or ".join(allowed)
        )
    if t.count == 0:
        raise SgtoolError(f"{path}: {flag} {topic} has no messages")


def check_flags(
    path: Path, topics: list[B.TopicInfo], opts: BagOptions, reader: Any = None
) -> None:
    if opts.estimate_poses and opts.depth is None:
        has_images = any(t.msgtype in B.IMAGE_TYPES for t in topics)
        raise SgtoolError(_missing_message(
            path, topics,
            "--estimate-poses estimates camera poses from depth images, and "
            + ("it needs --depth (and --info, --rgb)" if has_images else
               "the bag has no image topic (sensor_msgs Image or CompressedImage): import "
               "its trajectory with --tf-frames or --pose, without --estimate-poses"),
            reader,
        ))
    if opts.depth is None and opts.tf_frames is None and opts.pose is None:
        raise SgtoolError(_missing_message(
            path, topics,
            "say which topics to import: --depth (and --rgb, --info) for camera frames, or "
            "--tf-frames WORLD:FRAME / --pose TOPIC for a trajectory", reader,
        ))
    if opts.depth is None and (opts.rgb or opts.ids or opts.info):
        raise SgtoolError(
            _missing_message(path, topics, "--rgb/--ids/--info need --depth (a frame is a "
                             "depth image)")
        )
    _check_topic(path, topics, opts.depth, "--depth", B.IMAGE_TYPES)
    _check_topic(path, topics, opts.rgb, "--rgb", B.IMAGE_TYPES)
    _check_topic(path, topics, opts.ids, "--ids", B.IMAGE_TYPES)
    _check_topic(path, topics, opts.info, "--info", B.INFO_TYPES)
    _check_topic(path, topics, opts.pose, "--pose", B.POSE_TYPES)
    if opts.depth and opts.info is None and opts.intrinsics is None:
        infos = [t.topic for t in topics if t.msgtype in B.INFO_TYPES]
        raise SgtoolError(
            f"{path}: the camera intrinsics are needed: give --info TOPIC "
            + (f"(CameraInfo topics: {', '.join(infos)})" if infos else
               "(the bag has no CameraInfo topic)")
            + " or --intrinsics fx,fy,cx,cy"
        )


# ----- pass 1: index --------------------------------------------------------------------------
@dataclass
class _ImageIndex:
    stamps: list[int] = field(default_factory=list)
    frames: list[str] = field(default_factory=list)


@dataclass
class _BagIndex:
    depth: _ImageIndex = field(default_factory=_ImageIndex)
    rgb: _ImageIndex = field(default_factory=_ImageIndex)
    ids: _ImageIndex = field(default_factory=_ImageIndex)
    tf: TfTree = field(default_factory=TfTree)
    pose_samples: list[tuple[int, np.ndarray]] = field(default_factory=list)
    pose_frame: str = ""
    info: tuple[int, int, float, float, float, float] | None = None
    info_changes: int = 0
    samples: dict[int, tuple[np.ndarray, float]] = field(default_factory=dict)  # depth k ->
    zero_stamps: int = 0


def _stamp_or_bagtime(header: Any, bag_t: int, idx: _BagIndex) -> int:
    t = stamp_ns(header)
    if t == 0:
        idx.zero_stamps += 1
        return int(bag_t)
    return t


def _index(reader: Any, opts: BagOptions, topics: list[B.TopicInfo]) -> _BagIndex:
    from tqdm import tqdm

    idx = _BagIndex(tf=TfTree(max_gap_ns=opts.tf_max_gap_ns, tolerance_ns=opts.tf_tolerance_ns))
    tf_topics = [t.topic for t in topics if t.msgtype in B.TF_TYPES]
    wanted = {opts.depth, opts.rgb, opts.ids, opts.info, opts.pose, *tf_topics} - {None}
    conns = [c for c in reader.connections if c.topic in wanted]
    n_depth = sum(t.count for t in topics if t.topic == opts.depth)
    keep = set(np.linspace(0, max(n_depth - 1, 0), min(ALIGNMENT_SAMPLES, n_depth))
               .round().astype(int).tolist()) if n_depth else set()
    total = sum(int(c.msgcount) for c in conns)
    bar = tqdm(total=total, unit="msg", desc="index", file=sys.stderr,
               disable=None if opts.progress else True, leave=False)
    try:
        for c, bag_t, raw in reader.messages(connections=conns):
            bar.update(1)
            msg = reader.deserialize(raw, c.msgtype)
            mt = B.normalise_type(c.msgtype)
            if c.topic in tf_topics:
                static = c.topic.rstrip("/").endswith("tf_static")
                for tr in msg.transforms:
                    idx.tf.add(tr.header.frame_id, tr.child_frame_id, stamp_ns(tr.header),
                               _tq(tr.transform.translation, tr.transform.rotation),
                               static=static)
                continue
            if c.topic == opts.pose:
                t, parent, T = pose_of_message(msg, mt)  # noqa: N806
                idx.pose_samples.append((t, T))
                idx.pose_frame = idx.pose_frame or parent
                continue
            if c.topic == opts.info:
                k = intrinsics_of_info(msg)
                if idx.info is None:
                    idx.info = k
                elif k != idx.info:
                    idx.info_changes += 1
                continue
            for topic, ii in ((opts.depth, idx.depth), (opts.rgb, idx.rgb), (opts.ids, idx.ids)):
                if c.topic == topic:
                    t = _stamp_or_bagtime(msg.header, bag_t, idx)
                    if topic == opts.depth and len(ii.stamps) in keep:
                        idx.samples[len(ii.stamps)] = decode_depth_message(msg, mt, topic)
                    ii.stamps.append(t)
                    ii.frames.append(frame_name(msg.header.frame_id))
    finally:
        bar.close()
    idx.tf.freeze()
    return idx


# ----- poses -----------------------------------------------------------------------------------
@dataclass(frozen=True)
class _PoseSource:
    world: str
    camera: str
    describe: str
    tree: TfTree | None = None
    track: PoseTrack | None = None

    def at(self, t_ns: int, camera: str | None = None) -> np.ndarray | None:
        if self.track is not None:
            return self.track.at(t_ns)
        assert self.tree is not None
        return self.tree.lookup(self.world, camera or self.camera, t_ns)


def _pose_source(path: Path, idx: _BagIndex, opts: BagOptions) -> _PoseSource:
    if opts.pose is not None:
        if not idx.pose_samples:
            raise SgtoolError(f"{path}: --pose {opts.pose} has no messages")
        track = PoseTrack.from_samples(idx.pose_samples, max_gap_ns=opts.tf_max_gap_ns,
                                       tolerance_ns=opts.tf_tolerance_ns)
        return _PoseSource(idx.pose_frame or "world", "camera",
                           f"topic {opts.pose} ({len(track)} poses)", track=track)
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
    for f in (world, camera):
        if f not in tree.frames():
            raise SgtoolError(
                f"{path}: --tf-frames: frame {f!r} is not in the tf tree; its links are:\n  "
                + "\n  ".join(tree.describe())
            )
    if tree.path(world, camera) is None:
        raise SgtoolError(
            f"{path}: frames {world!r} and {camera!r} are not connected in the tf tree "
            f"(roots: {', '.join(tree.roots())}); links:\n  " + "\n  ".join(tree.describe())
        )
    return _PoseSource(world, camera, f"tf {world} -> {camera}", tree=tree)


# ----- pass 2: frames --------------------------------------------------------------------------
@dataclass(frozen=True)
class _Planned:
    k_depth: int
    t_ns: int
    pose: np.ndarray | None
    k_rgb: int | None
    k_ids: int | None


def _nearest_within(stamps: list[int], order: list[int], t: int, max_dt: int) -> int | None:
    """Index (into ``stamps``) of the stamp nearest ``t`` within ``max_dt``; ``order`` is
    the argsort of ``stamps``."""
    import bisect

    if not stamps:
        return None
    sorted_t = [stamps[i] for i in order]
    j = bisect.bisect_left(sorted_t, t)
    best = None
    for jj in (j - 1, j):
        if 0 <= jj < len(sorted_t):
            d = abs(sorted_t[jj] - t)
            if d <= max_dt and (best is None or d < best[0]):
                best = (d, order[jj])
    return None if best is None else best[1]


def _plan(
    idx: _BagIndex, src: _PoseSource | None, opts: BagOptions, keep_unposed: bool = False
) -> tuple[list[_Planned], list[str]]:
    """The frames to write: depth images in time order with their pose (None when
    ``src`` is None or, with ``keep_unposed``, when it does not cover the time) and the
    colour/id images paired with them."""
    notes = []
    seen: set[int] = set()
    rgb_order = sorted(range(len(idx.rgb.stamps)), key=lambda i: idx.rgb.stamps[i])
    ids_order = sorted(range(len(idx.ids.stamps)), key=lambda i: idx.ids.stamps[i])
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
        k_rgb = _nearest_within(idx.rgb.stamps, rgb_order, t, opts.max_dt_ns) if opts.rgb else None
        k_ids = _nearest_within(idx.ids.stamps, ids_order, t, opts.max_dt_ns) if opts.ids else None
        no_rgb += opts.rgb is not None and k_rgb is None
        no_ids += opts.ids is not None and k_ids is None
        plan.append(_Planned(k, t, pose, k_rgb, k_ids))
    if no_pose and src is not None:
        what = "kept, estimated" if keep_unposed else "dropped"
        notes.append(f"{no_pose} depth images without a pose from {src.describe} ({what})")
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
    if idx.info_changes:
        notes.append(f"the camera info changed {idx.info_changes} times; the first is used")
    plan = plan[:: opts.every]
    if opts.limit is not None:
        plan = plan[: opts.limit]
    return plan, notes


def _frames(
    reader: Any, plan: list[_Planned], idx: _BagIndex, opts: BagOptions, k: CameraIntrinsics
) -> Iterator[ImportFrame]:
    """The planned frames in time order, decoding only the images they use."""
    need: dict[str, dict[int, Any]] = {
        "depth": {p.k_depth: i for i, p in enumerate(plan)},
        "rgb": {},
        "ids": {},
    }
    for i, p in enumerate(plan):
        if p.k_rgb is not None:
            need["rgb"].setdefault(p.k_rgb, []).append(i)
        if p.k_ids is not None:
            need["ids"].setdefault(p.k_ids, []).append(i)
    topic_kind = {opts.depth: "depth", opts.rgb: "rgb", opts.ids: "ids"}
    topic_kind.pop(None, None)
    counters = dict.fromkeys(("depth", "rgb", "ids"), 0)
    decoded: dict[int, dict[str, Any]] = {}
    conns = [c for c in reader.connections if c.topic in topic_kind]
    next_i = 0

    def complete(i: int) -> bool:
        d = decoded.get(i, {})
        p = plan[i]
        return ("depth" in d and (p.k_rgb is None or "rgb" in d)
                and (p.k_ids is None or "ids" in d))

    def build(i: int) -> ImportFrame:
        d = decoded.pop(i)
        raw, scale = d["depth"]
        rgb = resize_to(d["rgb"], k.width, k.height) if "rgb" in d else None
        ids = resize_to(d["ids"], k.width, k.height) if "ids" in d else None
        pose = plan[i].pose if plan[i].pose is not None else np.eye(4)
        return ImportFrame(plan[i].t_ns, depth_for_log(raw, scale), pose, k, rgb=rgb, ids=ids)

    for c, _, raw in reader.messages(connections=conns):
        kind = topic_kind[c.topic]
        kk = counters[kind]
        counters[kind] += 1
        targets = need[kind].get(kk)
        if targets is None:
            continue
        mt = B.normalise_type(c.msgtype)
        msg = reader.deserialize(raw, c.msgtype)
        if kind == "depth":
            raw_d, scale = decode_depth_message(msg, mt, c.topic)
            if raw_d.shape != (k.height, k.width):
                raise SgtoolError(
                    f"topic {c.topic}: a depth image of {raw_d.shape[1]}x{raw_d.shape[0]} "
                    f"pixels; the camera info says {k.width}x{k.height}"
                )
            if opts.depth_scale is not None and raw_d.dtype == np.uint16:
                scale = opts.depth_scale
            decoded.setdefault(targets, {})["depth"] = (raw_d, scale)
        else:
            arr = (decode_color_message(msg, mt, c.topic) if kind == "rgb"
                   else decode_ids_message(msg, mt, c.topic))
            for i in targets:
                decoded.setdefault(i, {})[kind] = arr
        while next_i < len(plan) and complete(next_i):
            yield build(next_i)
            next_i += 1
    while next_i < len(plan):
        if not complete(next_i):  # the bag changed between the passes
            raise SgtoolError("the bag's images changed while it was being read")
        yield build(next_i)
        next_i += 1


def _camera(path: Path, idx: _BagIndex, opts: BagOptions) -> CameraIntrinsics:
    if not idx.samples:
        raise SgtoolError(f"{path}: --depth {opts.depth} has no messages")
    raw, _ = next(iter(idx.samples.values()))
    h, w = raw.shape[:2]
    if opts.intrinsics is not None:
        p = opts.intrinsics
        if (p.width and p.width != w) or (p.height and p.height != h):
            raise SgtoolError(f"--intrinsics are for {p.width}x{p.height}, depth is {w}x{h}")
        return CameraIntrinsics(w, h, p.fx, p.fy, p.cx, p.cy)
    if idx.info is None:
        raise SgtoolError(f"{path}: --info {opts.info} has no messages")
    iw, ih, fx, fy, cx, cy = idx.info
    if (iw, ih) != (w, h):
        raise SgtoolError(
            f"{path}: --info {opts.info} is for {iw}x{ih} images but the depth images on "
            f"{opts.depth} are {w}x{h}; give the depth camera's CameraInfo topic"
        )
    if fx <= 0 or fy <= 0:
        raise SgtoolError(f"{path}: --info {opts.info} has no focal length (K is zero)")
    return CameraIntrinsics(w, h, fx, fy, cx, cy)


# ----- entry points ---------------------------------------------------------------------------
def check_options(opts: BagOptions) -> None:
    """The numeric options, before the bag is opened (user errors naming the flag)."""
    check_counts(opts.every, opts.limit)
    check_depth_scale(opts.depth_scale)
    check_positive(opts.depth_max, "--depth-max", "metres")
    check_non_negative(opts.max_dt_ns / 1e9, "--max-dt", "seconds")
    check_non_negative(opts.tf_tolerance_ns / 1e9, "--tf-tolerance", "seconds")


def import_bag(path: str | Path, out: str | Path, opts: BagOptions) -> ImportReport:
    """Import a bag into the log ``out`` (see the module docstring)."""
    path, out = Path(path), Path(out)
    check_options(opts)
    with B.open_bag(path) as reader:
        topics = B.list_topics(reader)
        check_flags(path, topics, opts, reader)
        idx = _index(reader, opts, topics)
        has_tf = bool(idx.tf.links)
        estimate = opts.depth is not None and (
            opts.estimate_poses or (opts.pose is None and opts.tf_frames is None and not has_tf)
        )
        src = None
        if not (estimate and not has_tf and opts.pose is None):
            try:
                src = _pose_source(path, idx, opts)
            except SgtoolError:
                if not estimate:
                    raise
                # estimating anyway: the bag's poses were only wanted as the reference
        kind = f"bag/{B.bag_kind(path)}"
        meta = {
            "source": path.resolve().name,
            "source_kind": kind,
            "pose_source": src.describe if src else "none",
            "topics": " ".join(f"{f}={t}" for f, t in (
                ("depth", opts.depth), ("rgb", opts.rgb), ("ids", opts.ids),
                ("info", opts.info), ("pose", opts.pose)) if t),
            "instance_ids": "present" if opts.ids else "absent",
        }
        if opts.depth is None:
            assert src is not None
            return _import_trajectory(path, out, src, opts, meta, kind)
        k = _camera(path, idx, opts)
        plan, notes = _plan(idx, src, opts, keep_unposed=estimate)
        if not plan:
            raise SgtoolError(
                f"{path}: none of the {len(idx.depth.stamps)} depth images has a pose from "
                f"{src.describe if src else 'anywhere'}"
                + (f" (tf links: {'; '.join(idx.tf.describe())})" if src and src.tree else "")
            )
        drift = None
        odo: OdometryResult | None = None
        pose_source = src.describe if src else "none"
        reference = f"the bag's poses ({src.describe})" if src else "none"
        if estimate:
            plan, drift, odo, pose_source = _estimate(reader, plan, idx, opts, k, src)
            meta.update(drift_metadata(drift, reference))
            meta.update(odometry_metadata(odo))
            if odo.warning():
                notes.append(str(odo.warning()))
        meta["pose_source"] = pose_source
        by_k = {p.k_depth: p for p in plan}
        samples = [
            DepthSample(depth_to_metres(raw, opts.depth_scale if opts.depth_scale and
                                        raw.dtype == np.uint16 else scale), k, by_k[kk].pose)
            for kk, (raw, scale) in sorted(idx.samples.items()) if kk in by_k
        ]
        alignment = estimate_alignment([p.pose for p in plan], samples, up=opts.up,
                                       floor=opts.floor, floor_auto=opts.floor_auto)
        meta["intrinsics"] = f"{k.fx:g},{k.fy:g},{k.cx:g},{k.cy:g}"
        meta["intrinsics_source"] = f"topic {opts.info}" if opts.intrinsics is None else "given"
        n, has_rgb, has_ids = write_log(
            out, _frames(reader, plan, idx, opts, k), alignment=alignment, metadata=meta,
            total=len(plan), progress=opts.progress, notes=notes, compression=opts.compression,
        )
    return ImportReport(
        output=out, source=str(path), kind=kind, frames=n, poses=n, alignment=alignment,
        has_rgb=has_rgb, has_ids=has_ids, pose_source=pose_source, drift=drift,
        notes=tuple(notes), drift_reference=reference,
        **(odometry_report_fields(odo) if odo is not None else {}),  # type: ignore[arg-type]
    )


def _estimate(
    reader: Any, plan: list[_Planned], idx: _BagIndex, opts: BagOptions, k: CameraIntrinsics,
    src: _PoseSource | None,
) -> tuple[list[_Planned], DriftReport | None, OdometryResult, str]:
    """Poses of the planned frames by odometry (an extra pass over the images); the drift
    against the bag's own poses where it has them."""
    from dataclasses import replace

    from tqdm import tqdm

    if opts.odometry == "rgbd" and not opts.rgb:
        raise SgtoolError("--odometry rgbd needs --rgb; use icp")
    bar = tqdm(total=len(plan), unit="frame", desc="odometry", file=sys.stderr,
               disable=None if opts.progress else True, leave=False)

    def gen():  # type: ignore[no-untyped-def]
        for fr in _frames(reader, plan, idx, opts, k):
            d = fr.depth.astype(np.float32) / 1000.0 if fr.depth.dtype == np.uint16 else fr.depth
            yield fr.rgb, d

    try:
        res = estimate_trajectory(gen(), k, method=opts.odometry, start=plan[0].pose,
                                  depth_max=opts.depth_max, times_ns=[p.t_ns for p in plan],
                                  progress=lambda i: bar.update(1))
    finally:
        bar.close()
    ref = [(i, p.pose) for i, p in enumerate(plan) if p.pose is not None]
    drift = None
    if len(ref) >= 2:
        drift = drift_against([res.poses[i] for i, _ in ref], [T for _, T in ref])
    new_plan = [replace(p, pose=T) for p, T in zip(plan, res.poses, strict=True)]
    desc = f"estimated by {res.method} odometry"
    if src is not None:
        desc += f" ({src.describe} kept for the drift)"
    return new_plan, drift, res, desc


def _import_trajectory(
    path: Path, out: Path, src: _PoseSource, opts: BagOptions, meta: dict[str, str], kind: str
) -> ImportReport:
    """A log of /tf world -> camera at the measured times (no frames). The camera-up
    estimate of the world alignment assumes an optical frame, which a trajectory of a
    robot base is not: the world is kept unless --up / --floor are given."""
    if src.track is not None:
        times = list(src.track.times)
    else:
        assert src.tree is not None
        times = src.tree.sample_times(src.world, src.camera)
        if not times:  # all static: one pose
            times = [0]
    samples = [(t, T) for t in times if (T := src.at(t)) is not None]  # noqa: N806
    unresolved = len(times) - len(samples)
    samples = samples[:: opts.every]
    if opts.limit is not None:
        samples = samples[: opts.limit]
    if not samples:
        raise SgtoolError(f"{path}: no pose could be resolved from {src.describe}")
    if opts.up is not None:
        alignment = estimate_alignment([T for _, T in samples], [], up=opts.up,
                                       floor=opts.floor, floor_auto=False)
    elif opts.floor is not None:
        alignment = WorldAlignment(np.eye(3), float(opts.floor), (0.0, 0.0, 1.0), "none", "given")
    else:
        alignment = WorldAlignment.identity()
    meta = {**meta, **alignment.metadata(), "content": "trajectory"}
    A = alignment.matrix  # noqa: N806
    with LogWriter(out, compression=opts.compression) as w:
        w.add_metadata(IMPORT_METADATA, meta)
        w.write_record("episode", samples[0][0], {"kind": "import", "status": "started",
                                                  "source": meta["source"], "frames": 0})
        for t, T in samples:  # noqa: N806
            w.write_transform(t, S.WORLD_FRAME, S.CAMERA_FRAME, A @ T)
        w.write_record("episode", samples[-1][0], {
            "kind": "import", "status": "ended", "source": meta["source"], "frames": 0,
            "extra": {"poses": len(samples), "content": "trajectory"},
        })
    return ImportReport(
        output=out, source=str(path), kind=kind, frames=0, poses=len(samples),
        alignment=alignment, has_rgb=False, has_ids=False,
        pose_source=src.describe,
        notes=(f"trajectory of {len(samples)} poses, no frames",)
        + ((f"{unresolved} sample times where the chain was incomplete (skipped)",)
           if unresolved else ()),
    )


def read_trajectory(log: str | Path) -> list[tuple[int, np.ndarray]]:
    """(time, world_T_camera) of every /tf world -> camera transform in an sgtool log."""
    from sgtool.log import codec
    from sgtool.log.reader import LogReader

    out = []
    with LogReader(log) as r:
        for d in r.messages([S.TF]):
            if d.message.parent_frame_id == S.WORLD_FRAME and \
                    d.message.child_frame_id == S.CAMERA_FRAME:
                out.append((d.log_time_ns, codec.decode_transform(d.message)))
    return out
