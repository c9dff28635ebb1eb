"""Pass 2 of a bag import: the planned frames decoded from the image messages (depth,
colour, instance ids) in time order, only the images the plan uses; and the camera
intrinsics from ``--info`` or ``--intrinsics``, checked against the depth images."""

from __future__ import annotations

import bisect
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log.frame import CameraIntrinsics
from sgtool.recorders.importers import bagfiles as B
from sgtool.recorders.importers.bag_index import BagIndex
from sgtool.recorders.importers.bag_options import BagOptions
from sgtool.recorders.importers.bag_sync import PlannedFrame
from sgtool.recorders.importers.images import (
    ResizeLog,
    decode_color_message,
    decode_depth_message,
    decode_ids_message,
    depth_for_log,
    resize_to,
)
from sgtool.recorders.importers.provenance import Findings
from sgtool.recorders.importers.sanity import principal_point_problem
from sgtool.recorders.importers.sink import ImportFrame


def decode_frames(
    reader: Any, plan: list[PlannedFrame], idx: BagIndex, opts: BagOptions, k: CameraIntrinsics,
    resizes: ResizeLog | None = None,
) -> Iterator[ImportFrame]:
    """The planned frames in time order, decoding only the images they use; colour and id
    images resized to the depth images are counted in ``resizes``."""
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

    calibration = intrinsics_in_effect(idx, opts, k)

    def build(i: int) -> ImportFrame:
        d = decoded.pop(i)
        raw, scale = d["depth"]
        rgb = (resize_to(d["rgb"], k.width, k.height, f"topic {opts.rgb}", resizes, "colour")
               if "rgb" in d else None)
        ids = (resize_to(d["ids"], k.width, k.height, f"topic {opts.ids}", resizes, "ids")
               if "ids" in d else None)
        planned = plan[i]
        pose = planned.pose if planned.pose is not None else np.eye(4)
        return ImportFrame(planned.t_ns, depth_for_log(raw, scale), pose,
                           calibration(planned.t_ns), rgb=rgb, ids=ids)

    for c, _, raw in reader.messages(connections=conns):
        kind = topic_kind[c.topic]
        kk = counters[kind]
        counters[kind] += 1
        targets = need[kind].get(kk)
        if targets is None:
            continue
        mt = B.normalise_type(c.msgtype)
        msg = B.deserialize(reader, raw, c)
        if kind == "depth":
            raw_d, scale = decode_depth_message(msg, mt, c.topic)
            if raw_d.shape != (k.height, k.width):
                raise SgtoolError(
                    f"topic {c.topic}: a depth image of {raw_d.shape[1]}x{raw_d.shape[0]} "
                    f"pixels; the camera info says {k.width}x{k.height}"
                )
            if opts.depth_scale is not None:
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


def camera_of(path: Path, idx: BagIndex, opts: BagOptions,
              findings: Findings | None = None) -> CameraIntrinsics:
    """The depth camera from ``--intrinsics`` or ``--info``, checked against the sampled
    depth images: another size is an error; a principal point far from their centre
    (:func:`~.sanity.principal_point_problem`) an error for CameraInfo, a warning in
    ``findings`` for a flag."""
    k = _camera_of(path, idx, opts)
    if not (0 <= k.cx <= k.width and 0 <= k.cy <= k.height):
        raise SgtoolError(f"{path}: intrinsics ({_intrinsics_origin(opts)}): principal point "
                          f"({k.cx:g}, {k.cy:g}) is outside the {k.width}x{k.height} depth "
                          "images")
    if findings is not None:
        findings.problem(principal_point_problem(k.cx, k.cy, k.width, k.height,
                                                 _intrinsics_origin(opts)),
                         given=opts.intrinsics is not None)
    return k


def intrinsics_in_effect(idx: BagIndex, opts: BagOptions,
                         k: CameraIntrinsics) -> Callable[[int], CameraIntrinsics]:
    """The intrinsics of an image at time t: ``k`` (of :func:`camera_of`) until the
    CameraInfo changes, then the latest one at or before t (a zoom, a recalibration);
    ``k`` throughout with ``--intrinsics``. A change of image size is an error: the depth
    images keep theirs."""
    samples = [] if opts.intrinsics is not None else idx.info_samples[1:]
    for _, (iw, ih, fx, fy, *_rest) in samples:
        if (iw, ih) != (k.width, k.height) or fx <= 0 or fy <= 0:
            raise SgtoolError(f"--info {opts.info} changes to {iw}x{ih} images (focal length "
                              f"{fx:g}, {fy:g}) part-way through; the depth images are "
                              f"{k.width}x{k.height} (a log holds one image size)")
    times = [t for t, _ in samples]
    cams = [CameraIntrinsics(k.width, k.height, *info[2:]) for _, info in samples]

    def at(t: int) -> CameraIntrinsics:
        j = bisect.bisect_right(times, t)
        return k if j == 0 else cams[j - 1]

    return at


def _intrinsics_origin(opts: BagOptions) -> str:
    return "flag --intrinsics" if opts.intrinsics is not None else f"topic {opts.info}"


def _camera_of(path: Path, idx: BagIndex, opts: BagOptions) -> CameraIntrinsics:
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
    if not (fx > 0 and fy > 0):
        raise SgtoolError(f"{path}: --info {opts.info} has no usable focal length (K gives "
                          f"fx {fx:g}, fy {fy:g}; each must be > 0): a camera not calibrated "
                          "when recorded; give its intrinsics with --intrinsics fx,fy,cx,cy")
    return CameraIntrinsics(w, h, fx, fy, cx, cy)
