"""Which topics of a bag to import: the check of the topic flags against the bag's topics,
and, when a flag is missing or wrong, the listing of its topics and tf frames with
suggested flags (also ``sgtool import bag PATH --list``)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

from sgtool.errors import SgtoolError
from sgtool.recorders.importers import bagfiles as B
from sgtool.recorders.importers.bag_messages import add_tf_message
from sgtool.recorders.importers.bag_options import BagOptions
from sgtool.recorders.importers.images import (
    COLOUR_ENCODINGS,
    DEPTH_ENCODINGS,
    ID_ENCODINGS,
)
from sgtool.recorders.importers.tftree import TfTree

ROLE_FLAGS = {"depth": "--depth", "rgb": "--rgb", "ids": "--ids"}
ROLE_NEEDS = {
    "depth": "a depth encoding (16UC1/mono16 mm, 32FC1 m, compressedDepth)",
    "rgb": "a colour encoding (rgb8, bgr8, mono8, bayer_*, yuv422, JPEG/PNG)",
    "ids": "an integer encoding (8UC1, 16UC1, 32SC1)",
}


def roles_of(msgtype: str, encoding: str) -> set[str]:
    """What an image topic can be used for, from its first message's encoding (Image) or
    format (CompressedImage); every role when the encoding is not known."""
    if msgtype.endswith("CompressedImage"):
        fmt = encoding.lower().replace(" ", "")
        if "compresseddepth" in fmt:
            return {"depth"}
        head = encoding.split(";")[0].strip()
        if head in DEPTH_ENCODINGS:
            return {"depth"}
        return {"rgb", "depth"} if "png" in fmt and ";" not in fmt else {"rgb"}
    roles = set()
    if encoding in DEPTH_ENCODINGS:
        roles.add("depth")
    if encoding in COLOUR_ENCODINGS:
        roles.add("rgb")
    if encoding in ID_ENCODINGS:
        roles.add("ids")
    return roles or {"depth", "rgb", "ids"}


def peek_encodings(reader: Any, topics: list[B.TopicInfo]) -> dict[str, str]:
    """The encoding (Image) or format (CompressedImage) of each image topic's first
    message."""
    out = {}
    for t in topics:
        if t.msgtype not in B.IMAGE_TYPES or t.count == 0:
            continue
        for c, _, raw in reader.messages(B.connections_for(reader, t.topic)):
            msg = B.deserialize(reader, raw, c)
            out[t.topic] = str(getattr(msg, "encoding", None) or getattr(msg, "format", ""))
            break
    return out


def suggest_flags(topics: list[B.TopicInfo], tf_frames: list[str] | None = None,
                  encodings: dict[str, str] | None = None) -> list[str]:
    """Flags guessed from topic names and types (depth/colour/camera_info/ids), and from
    the first message's encoding when ``encodings`` has it (a 16UC1 topic is never
    suggested for --rgb). Without a depth topic, one item of alternatives for a trajectory:
    ``tf_frames`` (``--tf-frames WORLD:FRAME`` when not given and the bag has tf) and the
    pose topics."""
    enc = encodings or {}
    types = {t.topic: t.msgtype for t in topics}

    def fits(topic: str, role: str) -> bool:
        return topic not in enc or role in roles_of(types[topic], enc[topic])

    images = [t.topic for t in topics if t.msgtype in B.IMAGE_TYPES]
    infos = [t.topic for t in topics if t.msgtype in B.INFO_TYPES]
    poses = [t.topic for t in topics if t.msgtype in B.POSE_TYPES]
    tfs = [t.topic for t in topics if t.msgtype in B.TF_TYPES]
    out: list[str] = []
    named = [t for t in images if "depth" in t.lower() and fits(t, "depth")]
    if not named:  # a depth camera's topic need not say "depth": its encoding does
        named = [t for t in images if t in enc and (
            enc[t] in ("16UC1", "32FC1") or "compresseddepth" in enc[t].lower())]
    depth = min(named, key=lambda t: depth_rank(t, enc.get(t)), default=None)
    ids_words = ("instance", "segment", "label", "ids", "mask")
    ids = next((t for t in images if t != depth and fits(t, "ids")
                and any(w in t.lower() for w in ids_words)), None)
    colour = [t for t in images if t not in (depth, ids) and fits(t, "rgb")
              and "depth" not in t.lower()
              and any(w in t.lower() for w in ("rgb", "color", "colour", "image"))]
    rgb = min(colour, key=lambda t: colour_rank(t, enc.get(t), types[t], depth), default=None)
    out.extend(f"{flag} {topic}" for flag, topic in (("--depth", depth), ("--rgb", rgb),
                                                     ("--ids", ids)) if topic)
    if infos:
        out.append(f"--info {min(infos, key=lambda t: (-_shared_parts(t, depth or ''), t))}")
    if not depth:
        alternatives = (list(tf_frames) if tf_frames is not None else
                        ["--tf-frames WORLD:FRAME"] if tfs else [])
        alternatives += [f"--pose {p}" for p in poses[:4]]
        if len(poses) > 4:
            alternatives.append(f"... ({len(poses) - 4} more pose topics)")
        if alternatives:
            out.append(" | ".join(alternatives))
    return out


_ALIGNED_WORDS = ("aligned", "registered")


def _parts(topic: str) -> list[str]:
    return [p for p in topic.split("/") if p]


def _shared_parts(a: str, b: str) -> int:
    """How many leading path components two topic names share."""
    n = 0
    for x, y in zip(_parts(a), _parts(b), strict=False):
        if x != y:
            break
        n += 1
    return n


def depth_rank(topic: str, encoding: str | None) -> tuple[int, int, str]:
    """Sort key of a depth topic for the suggestions: depth aligned (registered) to the
    colour camera first, then the sensor's native encoding (16UC1/mono16, then
    compressedDepth/PNG, then 32FC1, then unknown), then the name."""
    aligned = 0 if any(w in topic.lower() for w in _ALIGNED_WORDS) else 1
    e = (encoding or "").lower()
    native = (0 if e in ("16uc1", "mono16") else 1 if "compresseddepth" in e or "png" in e
              else 2 if e == "32fc1" else 3)
    return aligned, native, topic


_COLOUR_RANK = {"rgb8": 0, "bgr8": 0, "rgba8": 0, "bgra8": 0, "8uc3": 0}


def colour_rank(topic: str, encoding: str | None, msgtype: str, depth: str | None
                ) -> tuple[int, int, str]:
    """Sort key of a colour topic for the suggestions: the depth topic's own camera first
    (the most leading path components shared, the colour stream a depth aligned "to_color"
    names), then native colour (rgb8/bgr8/...), compressed JPEG/PNG, YUV, Bayer, grey,
    unknown; then the name."""
    shared = _shared_parts(topic, depth) if depth else 0
    if depth and "to_color" in depth.lower() and "color" in topic.lower():
        shared += 1
    e = (encoding or "").lower()
    if msgtype.endswith("CompressedImage"):
        native = 1 if e else 5
    elif e in _COLOUR_RANK:
        native = 0
    else:
        native = (2 if e.startswith(("yuv", "uyvy", "yuyv")) else 3 if e.startswith("bayer")
                  else 4 if e in ("mono8", "mono16", "8uc1") else 5)
    return -shared, native, topic


def with_only_info(topics: list[B.TopicInfo], opts: BagOptions) -> BagOptions:
    """``opts`` with ``--info`` set to the bag's only CameraInfo topic when a depth topic is
    imported without --info or --intrinsics."""
    if opts.depth is None or opts.info is not None or opts.intrinsics is not None:
        return opts
    infos = [t.topic for t in topics if t.msgtype in B.INFO_TYPES]
    if len(infos) != 1:
        return opts
    return replace(opts, info=infos[0], info_origin="the only CameraInfo topic")


def peek_tf(reader: Any, topics: list[B.TopicInfo], max_messages: int = 500) -> TfTree:
    """The tf tree from ``/tf_static`` and the first ``max_messages`` ``/tf`` messages: the
    frames a bag has, cheaply, for listing and suggestions."""
    tree = TfTree()
    for t in topics:
        if t.msgtype not in B.TF_TYPES:
            continue
        for n, (c, _, raw) in enumerate(reader.messages(B.connections_for(reader, t.topic))):
            if n >= max_messages:
                break
            add_tf_message(tree, B.deserialize(reader, raw, c), t.topic, checked=False)
    return tree.freeze()


def tf_suggestions(tree: TfTree) -> list[str]:
    """``--tf-frames WORLD:CAMERA`` for the frames that look like cameras
    (:func:`~sgtool.recorders.importers.bag_poses.camera_like`), each with its root as
    the world, unless the tree is stored from the camera out
    (:func:`~sgtool.recorders.importers.bag_poses.outward_worlds`): then the world-named
    frame below it; a camera with no world at all gets none."""
    from sgtool.recorders.importers.bag_poses import (
        camera_like,
        is_world_name,
        outward_worlds,
        world_candidates,
    )

    picks = camera_like(tree)
    named = any("optical" in f or "camera" in f for f in picks)
    out = []
    for f in picks[:6]:
        root = tree.root_of(f)
        if is_world_name(f):  # a world leaf under the camera's root (stored outwards)
            if not named and not is_world_name(root):
                out.append(f"--tf-frames {f}:{root}")
            continue
        world = next(iter(outward_worlds(tree, f)), "") or (
            root if root != f else next(iter(world_candidates(tree, f)), ""))
        if world:
            out.append(f"--tf-frames {world}:{f}")
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
    sugg = suggest_flags(topics, tf_frames=[], encodings=peek_encodings(reader, topics))
    if sugg:
        lines.append("suggested flags: " + " ".join(sugg))
    tfs = tf_suggestions(tree)
    if tfs:
        lines.append("camera / trajectory frames: " + " | ".join(tfs))
    return "\n".join(lines)


def missing_error(
    path: Path, topics: list[B.TopicInfo], what: str, reader: Any = None
) -> SgtoolError:
    """The one line for a missing or wrong topic flag, with the flags to try; the bag's
    topic table rides as its ``details`` (printed before the line)."""
    tfs = None
    if reader is not None and any(t.msgtype in B.TF_TYPES for t in topics):
        tfs = tf_suggestions(peek_tf(reader, topics)) or None
    encodings = peek_encodings(reader, topics) if reader is not None else None
    sugg = suggest_flags(topics, tf_frames=tfs, encodings=encodings)
    return SgtoolError(
        f"{path}: {what}" + (f"; suggested flags: {' '.join(sugg)}" if sugg else ""),
        details=f"{path}: the bag's topics:\n{B.format_topics(topics)}")


def _check_topic(
    path: Path, topics: list[B.TopicInfo], topic: str | None, flag: str, allowed: tuple[str, ...]
) -> None:
    if topic is None:
        return
    found = {t.topic: t for t in topics}
    if topic not in found:
        raise missing_error(path, topics, f"{flag} {topic}: no such topic")
    t = found[topic]
    if t.msgtype not in allowed:
        raise SgtoolError(
            f"{path}: {flag} {topic} is a {t.msgtype} topic; {flag} needs "
            + " or ".join(allowed)
        )
    if t.count == 0:
        raise SgtoolError(f"{path}: {flag} {topic} has no messages")


def _check_encodings(path: Path, topics: list[B.TopicInfo], opts: BagOptions,
                     reader: Any) -> None:
    """Each image flag names a topic whose first message has an encoding for its role."""
    wanted = {role: getattr(opts, role) for role in ROLE_FLAGS if getattr(opts, role)}
    if not wanted:
        return
    encodings = peek_encodings(reader, [t for t in topics if t.topic in wanted.values()])
    types = {t.topic: t.msgtype for t in topics}
    for role, topic in wanted.items():
        enc = encodings.get(topic)
        if enc is None or role in roles_of(types[topic], enc):
            continue
        sugg = suggest_flags(topics, encodings=peek_encodings(reader, topics))
        raise SgtoolError(
            f"{path}: {ROLE_FLAGS[role]} {topic} carries {enc!r} images; {ROLE_FLAGS[role]} "
            f"needs {ROLE_NEEDS[role]}" + (f"; suggested flags: {' '.join(sugg)}" if sugg else ""))


def check_flags(
    path: Path, topics: list[B.TopicInfo], opts: BagOptions, reader: Any = None
) -> None:
    if opts.estimate_poses and opts.depth is None:
        has_images = any(t.msgtype in B.IMAGE_TYPES for t in topics)
        raise missing_error(
            path, topics,
            "--estimate-poses estimates camera poses from depth images, and "
            + ("it needs --depth (and --info, --rgb)" if has_images else
               "the bag has no image topic (sensor_msgs Image or CompressedImage): import "
               "its trajectory with --tf-frames or --pose, without --estimate-poses"),
            reader,
        )
    if opts.depth is None and opts.tf_frames is None and opts.pose is None:
        raise missing_error(
            path, topics,
            "say which topics to import: --depth (and --rgb, --info) for camera frames, or "
            "--tf-frames WORLD:FRAME / --pose TOPIC for a trajectory", reader,
        )
    if opts.depth is None and (opts.rgb or opts.ids or opts.info):
        raise missing_error(path, topics, "--rgb/--ids/--info need --depth (a frame is a "
                            "depth image)")
    _check_topic(path, topics, opts.depth, "--depth", B.IMAGE_TYPES)
    _check_topic(path, topics, opts.rgb, "--rgb", B.IMAGE_TYPES)
    _check_topic(path, topics, opts.ids, "--ids", B.IMAGE_TYPES)
    if reader is not None:
        _check_encodings(path, topics, opts, reader)
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
