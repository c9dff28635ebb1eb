"""Pass 1 of a bag import: the time stamps and frames of the images, the tf tree, the pose
samples and the calibration, and a few depth images for the world alignment -- everything
but the images, so memory stays small."""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sgtool.recorders.importers import bagfiles as B
from sgtool.recorders.importers.bag_messages import (
    add_tf_message,
    distortion_of_info,
    intrinsics_of_info,
    pose_of_message,
    stamp_ns,
)
from sgtool.recorders.importers.bag_options import BagOptions
from sgtool.recorders.importers.images import decode_depth_message
from sgtool.recorders.importers.tftree import TfTree, frame_name
from sgtool.recorders.importers.upright import sample_indices


@dataclass
class ImageIndex:
    stamps: list[int] = field(default_factory=list)
    frames: list[str] = field(default_factory=list)
    received: list[int] = field(default_factory=list)  # the bag's record times


@dataclass
class BagIndex:
    depth: ImageIndex = field(default_factory=ImageIndex)
    rgb: ImageIndex = field(default_factory=ImageIndex)
    ids: ImageIndex = field(default_factory=ImageIndex)
    tf: TfTree = field(default_factory=TfTree)
    pose_samples: list[tuple[int, np.ndarray]] = field(default_factory=list)
    pose_frame: str = ""
    pose_child: str = ""  # the frame a --pose topic's messages give the pose of ("": unsaid)
    info: tuple[int, int, float, float, float, float] | None = None
    distortion: tuple[str, tuple[float, ...]] | None = None  # of the first CameraInfo
    info_changes: int = 0  # how many times a CameraInfo's K differs from the one before
    # (time, K) of the first CameraInfo and of each one whose K differs from the one before
    info_samples: list[tuple[int, tuple[int, int, float, float, float, float]]] = field(
        default_factory=list)
    samples: dict[int, tuple[np.ndarray, float]] = field(default_factory=dict)  # depth k ->
    zero_stamps: int = 0
    tf_zero_stamps: int = 0  # dynamic /tf transforms with a zero stamp (_resolve_zero_tf_stamps)
    # record time minus header stamp of each dynamic /tf transform (ns)
    tf_latency_ns: list[int] = field(default_factory=list)


# a zero header stamp next to stamps within this of zero is a clock that starts at 0 (a
# simulator's), not an unset stamp
_SIM_CLOCK_NS = 60 * 10**9


def _info_time(depth: ImageIndex, stamp: int, received: int) -> int:
    """The time a CameraInfo change takes effect: its header stamp, or, when it has none
    (0), the stamp of the first depth image the bag recorded at or after it (on the
    images' clock, whatever it is; after the last image: past it)."""
    if stamp:
        return stamp
    later = [t for t, r in zip(depth.stamps, depth.received, strict=True) if r >= received]
    return min(later) if later else max(depth.stamps, default=0) + 1


def _resolve_zero_stamps(ii: ImageIndex, idx: BagIndex) -> None:
    """Replace the unset (zero) header stamps of one image topic by the bag's record times.
    A zero is unset unless the nearest non-zero stamp of the topic (in message order) is
    within ``_SIM_CLOCK_NS`` of it: a simulator's clock starts at 0, and its first image
    keeps its stamp."""
    stamps = np.asarray(ii.stamps, np.int64)
    nonzero = np.flatnonzero(stamps != 0)
    for i in np.flatnonzero(stamps == 0):
        if nonzero.size:
            near = nonzero[np.argmin(np.abs(nonzero - i))]
            if stamps[near] <= _SIM_CLOCK_NS:
                continue
        ii.stamps[i] = ii.received[i]
        idx.zero_stamps += 1


def _resolve_zero_tf_stamps(unset: list[tuple[Any, str, int]], idx: BagIndex,
                            first_stamp: int | None) -> None:
    """Add the /tf messages with a zero header stamp (message, topic, bag time) to the tree,
    at the bag's record time less the median delay of the stamped /tf transforms
    (``idx.tf_latency_ns``: about none on one clock, the offset of a simulator's clock from
    the recorder's), so on the clock of the other stamps. Counted in
    ``idx.tf_zero_stamps`` (a recorder that never set them) unless the first non-zero
    stamp of /tf lies within ``_SIM_CLOCK_NS``: a simulator's clock that starts at 0, whose
    zero is a time."""
    sim = first_stamp is not None and first_stamp <= _SIM_CLOCK_NS
    delay = int(np.median(idx.tf_latency_ns)) if idx.tf_latency_ns else 0
    for msg, topic, bag_t in unset:
        add_tf_message(idx.tf, msg, topic, unset_stamp_ns=max(bag_t - delay, 0) or None)
        if not sim:
            idx.tf_zero_stamps += sum(stamp_ns(tr.header) == 0 for tr in msg.transforms)


def index_bag(reader: Any, opts: BagOptions, topics: list[B.TopicInfo]) -> BagIndex:
    """Pass 1 over the wanted topics (module doc); the tf tree comes back frozen."""
    from tqdm import tqdm

    idx = BagIndex(tf=TfTree(max_gap_ns=opts.tf_max_gap_ns, tolerance_ns=opts.tf_tolerance_ns))
    tf_topics = [t.topic for t in topics if t.msgtype in B.TF_TYPES]
    wanted = {opts.depth, opts.rgb, opts.ids, opts.info, opts.pose, *tf_topics} - {None}
    conns = [c for c in reader.connections if c.topic in wanted]
    n_depth = sum(t.count for t in topics if t.topic == opts.depth)
    keep = set(sample_indices(n_depth))  # depth images kept for the world alignment
    info_received: list[int] = []  # the bag's record times of idx.info_samples
    unset: list[tuple[Any, str, int]] = []  # /tf messages with a zero stamp, bag time
    first_stamp: int | None = None  # the earliest non-zero stamp of /tf
    total = sum(int(c.msgcount) for c in conns)
    bar = tqdm(total=total, unit="msg", desc="index", file=sys.stderr,
               disable=None if opts.progress else True, leave=False)
    try:
        for c, bag_t, raw in reader.messages(connections=conns):
            bar.update(1)
            msg = B.deserialize(reader, raw, c)
            mt = B.normalise_type(c.msgtype)
            if c.topic in tf_topics:
                static = c.topic.rstrip("/").endswith("tf_static")
                stamps = [stamp_ns(tr.header) for tr in msg.transforms]
                if not static:  # the stamped ones of a message with a zero stamp count too
                    stamped = [t for t in stamps if t]
                    if stamped:
                        first_stamp = min(stamped if first_stamp is None
                                          else [first_stamp, *stamped])
                    idx.tf_latency_ns.extend(int(bag_t) - t for t in stamped)
                    if len(stamped) < len(stamps):  # unset, or a simulator's clock at 0
                        unset.append((msg, c.topic, int(bag_t)))
                        continue
                add_tf_message(idx.tf, msg, c.topic)
                continue
            if c.topic == opts.pose:
                t, parent, T = pose_of_message(msg, mt, c.topic)  # noqa: N806
                idx.pose_samples.append((t, T))
                idx.pose_frame = idx.pose_frame or parent
                idx.pose_child = idx.pose_child or frame_name(
                    str(getattr(msg, "child_frame_id", "") or ""))
                continue
            if c.topic == opts.info:
                k = intrinsics_of_info(msg)
                if idx.info is None:
                    idx.info = k
                    idx.distortion = distortion_of_info(msg)
                if not idx.info_samples or k != idx.info_samples[-1][1]:
                    t = int(bag_t) if opts.timestamps == "bag" else stamp_ns(msg.header)
                    idx.info_samples.append((t, k))
                    info_received.append(int(bag_t))
                    idx.info_changes = len(idx.info_samples) - 1
                continue
            for topic, ii in ((opts.depth, idx.depth), (opts.rgb, idx.rgb), (opts.ids, idx.ids)):
                if topic is not None and c.topic == topic:
                    t = int(bag_t) if opts.timestamps == "bag" else stamp_ns(msg.header)
                    if topic == opts.depth and len(ii.stamps) in keep:
                        idx.samples[len(ii.stamps)] = decode_depth_message(msg, mt, topic)
                    ii.stamps.append(t)
                    ii.received.append(int(bag_t))
                    ii.frames.append(frame_name(msg.header.frame_id))
    finally:
        bar.close()
    for ii in (idx.depth, idx.rgb, idx.ids):
        _resolve_zero_stamps(ii, idx)
    _resolve_zero_tf_stamps(unset, idx, first_stamp)
    # the first CameraInfo is the camera's until a change; the changes in time order
    timed = [(t, k) for t, k in idx.info_samples[:1]] + sorted(
        (_info_time(idx.depth, t, r), k)
        for (t, k), r in zip(idx.info_samples[1:], info_received[1:], strict=True))
    for ii in (idx.depth, idx.rgb, idx.ids):
        ii.stamps = [t + opts.time_offset_ns for t in ii.stamps]
    idx.info_samples = [(t + opts.time_offset_ns, k) for t, k in timed]
    idx.tf.freeze()
    return idx
