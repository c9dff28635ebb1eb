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
  tree; a tree of ``/tf_static`` links only is refused unless named, it would pose every
  image alike), every dynamic link interpolated at the image time (:mod:`.tftree`); or
  ``--pose TOPIC`` (``PoseStamped``, ``PoseWithCovarianceStamped``, ``TransformStamped``,
  ``Odometry``) giving the camera's optical frame in the world directly.

Without ``--depth``, ``--tf-frames`` or ``--pose`` alone import a *trajectory*: a log of
``/tf`` world -> camera transforms at the times the pose was measured, without frames.

A bag with images but no ``/tf`` and no ``--pose`` (a camera recorded alone), or any bag
with ``--estimate-poses``, gets its camera poses from RGB-D odometry (:mod:`.odometry`,
one more pass over the images); the drift against the bag's own poses is reported when it
has them. ``--estimate-poses`` needs ``--depth``: a bag of trajectories alone (no image
topic) is an error that suggests ``--tf-frames`` and ``--pose``.

When a flag is missing or names the wrong thing (a topic of another type, or whose first
image has an encoding that does not fit the flag: ``--rgb`` on 16UC1 depth), the error lists
the bag's topics with their types and suggests flags that fit their encodings. Without
``--info``, the bag's only CameraInfo topic is used. As for folders (:mod:`.rgbd`), the
depth images' header stamps (or record times, ``timestamps="bag"``), the depth scale and the
floor are checked before the frames are written, and the report says where the intrinsics,
depth scale, up and floor came from. The bag is read in two passes (time stamps, transforms and
calibration; then the images), so memory stays at a few frames.

This module drives the import; the steps are in :mod:`.bag_options` (flags),
:mod:`.bag_topics` (topic checks and suggestions), :mod:`.bag_messages` (message fields),
:mod:`.bag_index` (pass 1), :mod:`.bag_poses` (pose source), :mod:`.bag_sync` (pairing by
time) and :mod:`.bag_frames` (pass 2: decoding).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log import schemas as S
from sgtool.log.frame import CameraIntrinsics
from sgtool.log.records import Episode
from sgtool.log.writer import LogWriter
from sgtool.recorders.importers import bagfiles as B
from sgtool.recorders.importers.bag_frames import camera_of, decode_frames
from sgtool.recorders.importers.bag_index import BagIndex, index_bag
from sgtool.recorders.importers.bag_options import BagOptions, check_options
from sgtool.recorders.importers.bag_poses import PoseSource, pose_source_of
from sgtool.recorders.importers.bag_scale import bag_scale_pairs, bag_scale_problem
from sgtool.recorders.importers.bag_sync import PlannedFrame, plan_frames, planned_poses
from sgtool.recorders.importers.bag_topics import check_flags, describe_bag, with_only_info
from sgtool.recorders.importers.distortion import distortion_finding
from sgtool.recorders.importers.floor import floor_confidence_problem, frame_floor_problem
from sgtool.recorders.importers.focal_check import (
    along_axis_pairs,
    check_focal,
    ray_depth_problem,
    turn_pairs,
)
from sgtool.recorders.importers.images import ResizeLog, depth_to_metres
from sgtool.recorders.importers.odometry import (
    DriftReport,
    OdometryResult,
    drift_where_known,
    estimate_with_progress,
)
from sgtool.recorders.importers.pose_axes import ReadAs
from sgtool.recorders.importers.provenance import (
    ESTIMATED_FLOORS,
    FLOOR_ORIGINS,
    Findings,
    alignment_sources,
    source_metadata,
)
from sgtool.recorders.importers.sanity import (
    BAG_TIME_FIX,
    camera_heights,
    clock_offset_s,
    clock_problem,
    depth_scale_problem,
    floor_problem,
    no_depth_problem,
    timestamp_problem,
)
from sgtool.recorders.importers.scale_check import (
    convention_problems,
    fit_scale,
    pair_indices,
    pose_motion_problem,
)
from sgtool.recorders.importers.sink import (
    IMPORT_METADATA,
    ImportReport,
    drift_metadata,
    odometry_metadata,
    odometry_report_fields,
    write_log,
)
from sgtool.recorders.importers.upright import (
    DepthSample,
    WorldAlignment,
    estimate_alignment,
    given_up_problem,
)

__all__ = ["BagOptions", "check_flags", "check_options", "describe_bag", "import_bag",
           "read_trajectory"]


def import_bag(path: str | Path, out: str | Path, opts: BagOptions) -> ImportReport:
    """Import a bag into the log ``out`` (see the module docstring)."""
    path, out = Path(path), Path(out)
    check_options(opts)
    with B.open_bag(path) as reader:
        topics = B.list_topics(reader)
        opts = with_only_info(topics, opts)
        check_flags(path, topics, opts, reader)
        idx = index_bag(reader, opts, topics)
        has_tf = bool(idx.tf.links)
        estimate = opts.depth is not None and (
            opts.estimate_poses or (opts.pose is None and opts.tf_frames is None and not has_tf)
        )
        src = None
        if not (estimate and not has_tf and opts.pose is None):
            try:
                src = pose_source_of(path, idx, opts)
            except SgtoolError:
                if not estimate:
                    raise
                # estimating anyway: the bag's poses were only wanted as the reference
        if (opts.depth is not None and src is not None and src.tree is not None
                and src.track is None
                and not src.tree.sample_times(src.world, src.camera)):
            # /tf_static links alone (a camera driver's mounts, a camera recorded alone)
            # would pose every image the same (as asked when --tf-frames names the pair)
            if not estimate and opts.tf_frames is None:
                raise SgtoolError(
                    f"{path}: {src.describe} has static links only (/tf_static): every "
                    "frame would get the same pose; give --tf-frames WORLD:CAMERA through a "
                    "moving /tf link, --pose TOPIC, or --estimate-poses")
            if estimate:
                src = None  # no reference to measure the drift against
        if src is None and opts.camera_axes != "optical":
            raise SgtoolError(f"--camera-axes {opts.camera_axes}: {path}'s poses are not read "
                              "(the camera's are estimated from the depth); leave it out")
        kind = f"bag/{B.bag_kind(path)}"
        meta = {
            "source": path.resolve().name,
            "source_kind": kind,
            "pose_source": src.describe if src else "none",
            "topics": " ".join(f"{f}={t}" for f, t in (
                ("depth", opts.depth), ("rgb", opts.rgb), ("ids", opts.ids),
                ("info", opts.info), ("pose", opts.pose)) if t),
            "instance_ids": "present" if opts.ids else "absent",
            **({"instance_table": f"{len(opts.instances.instances)} instances"}
               if opts.instances is not None else {}),
        }
        if opts.depth is None:
            assert src is not None
            return _import_trajectory(path, out, src, opts, meta, kind)
        findings = Findings(opts.warn)
        k = camera_of(path, idx, opts, findings)
        findings.problem(timestamp_problem(
            sorted(idx.depth.stamps), f"{path}: --depth {opts.depth} ({opts.timestamps} times)",
            BAG_TIME_FIX), given=opts.timestamps != "header")
        check_depth_samples(idx, opts, findings, f"{path}: --depth {opts.depth}")
        back = sum(b < a for a, b in itertools.pairwise(idx.depth.stamps))
        if back and opts.timestamps == "header":  # each image is posed at its own stamp
            findings.warning(f"{path}: --depth {opts.depth}: {back} image(s) stamped earlier "
                             "than the image recorded before; each is posed at its own stamp "
                             "(--timestamps bag takes the recording times)")
        checks: list[tuple[str, str]] = []
        if opts.timestamps == "header" and src is not None and src.tree is not None:
            offset = clock_offset_s([r - t for r, t in zip(idx.depth.received,
                                                           idx.depth.stamps, strict=True)],
                                    idx.tf_latency_ns)
            if offset is not None:
                checks.append(("clock", f"images recorded {offset:+.3f} s after their stamps "
                               "relative to /tf"))
            findings.problem(clock_problem(offset, f"{path}: --depth {opts.depth}"),
                             given=opts.time_offset_ns != 0)
        if src is not None:
            _check_poses(reader, idx, opts, src, k, findings, checks, estimate)
        plan, notes = plan_frames(idx, src, opts, keep_unposed=estimate)
        if not plan:
            raise SgtoolError(
                f"{path}: none of the {len(idx.depth.stamps)} depth images has a pose from "
                f"{src.describe if src else 'anywhere'}"
                + (f" (tf links: {'; '.join(idx.tf.describe())})" if src and src.tree else "")
            )
        _lens_distortion(idx, opts, k, findings, notes)
        drift = None
        odo: OdometryResult | None = None
        pose_source = src.describe if src else "none"
        reference = f"the bag's poses ({src.describe})" if src else "none"
        if estimate:
            if opts.floor is None and opts.floor_auto and opts.up is None:
                # before the odometry: the floor of each sampled frame on its own
                findings.problem(frame_floor_problem(
                    [depth_to_metres(raw, _scale(raw, scale, opts))
                     for raw, scale in idx.samples.values()], k, opts.camera_height),
                    given=False)
            plan, drift, odo, pose_source = _estimate(reader, plan, idx, opts, k, src)
            meta.update(drift_metadata(drift, reference))
            meta.update(odometry_metadata(odo))
            if odo.warning():
                notes.append(str(odo.warning()))
        meta["pose_source"] = pose_source
        poses = planned_poses(plan)
        by_k = {p.k_depth: pose for p, pose in zip(plan, poses, strict=True)}
        samples = [
            DepthSample(depth_to_metres(raw, _scale(raw, scale, opts)), k, by_k[kk])
            for kk, (raw, scale) in sorted(idx.samples.items()) if kk in by_k
        ]
        alignment = estimate_alignment(poses, samples, up=opts.up,
                                       floor=opts.floor, floor_auto=opts.floor_auto)
        findings.problem(given_up_problem(alignment), given=True)
        findings.problem(findings.floor_doubt(floor_confidence_problem(
            alignment.floor, alignment.floor_confidence, alignment.floor_method,
            alignment.floor_detail, float(np.median(camera_heights(poses, alignment.matrix))),
            opts.camera_height)), given=False)
        if alignment.floor_method != "none":
            findings.problem(
                floor_problem(poses, alignment.matrix, alignment.floor,
                              FLOOR_ORIGINS[alignment.floor_method], opts.camera_height),
                given=alignment.floor_method not in ESTIMATED_FLOORS)
        if alignment.floor_detail:
            checks.append(("floor", alignment.floor_detail))
        sources = [("intrinsics", f"{k.fx:g},{k.fy:g},{k.cx:g},{k.cy:g}",
                    _intrinsics_origin(opts)),
                   ("depth scale", *_scale_origin(idx, opts)), *alignment_sources(alignment)]
        meta["intrinsics"] = f"{k.fx:g},{k.fy:g},{k.cx:g},{k.cy:g}"
        meta.update(source_metadata(sources))
        if findings.warnings:
            meta["warnings"] = "\n".join(findings.warnings)
        resizes = ResizeLog()
        n, has_rgb, has_ids = write_log(
            out, decode_frames(reader, plan, idx, opts, k, resizes), alignment=alignment,
            metadata=meta, total=len(plan), progress=opts.progress, notes=notes,
            compression=opts.compression, resizes=resizes, instances=opts.instances,
        )
    return ImportReport(
        output=out, source=str(path), kind=kind, frames=n, poses=n, alignment=alignment,
        has_rgb=has_rgb, has_ids=has_ids, pose_source=pose_source, drift=drift,
        notes=tuple(notes), drift_reference=reference, sources=tuple(sources),
        warnings=tuple(findings.warnings), resizes=tuple(resizes.lines()),
        resize_counts=tuple(resizes.as_dicts()), checks=tuple(checks),
        **odometry_report_fields(odo),
    )


def _lens_distortion(idx: BagIndex, opts: BagOptions, k: CameraIntrinsics,
                     findings: Findings, notes: list[str]) -> None:
    """A note, or a warning when it moves pixels noticeably, for a CameraInfo with
    distortion (sgtool does not undistort: :mod:`.distortion`)."""
    found = distortion_finding(idx.distortion, str(opts.info), k)
    if found is None:
        return
    text, serious = found
    if serious:
        findings.warning(text)
    else:
        notes.append(text)


def _scale(raw: np.ndarray, scale: float, opts: BagOptions) -> float:
    """Units per metre of a decoded depth image: --depth-scale when given (16-bit or float
    depth alike), else the encoding's."""
    return opts.depth_scale if opts.depth_scale else scale


def _check_poses(reader: Any, idx: BagIndex, opts: BagOptions, src: PoseSource,
                 k: CameraIntrinsics, findings: Findings, checks: list[tuple[str, str]],
                 estimate: bool) -> None:
    """The depth scale and the focal length against the poses of ``src`` (nearby and
    turned depth pairs: :mod:`.scale_check`, :mod:`.focal_check`): the fits into
    ``checks``, their problems into ``findings`` (the depth scale not blamed where the
    focal length explains the depth's motion)."""
    pairs, turned = bag_scale_pairs(reader, idx, opts, src, k, (pair_indices, turn_pairs))
    fit = fit_scale(pairs, k)
    if fit is not None:
        checks.append(("depth scale against the poses", fit.describe()))
    focal, problem, explains = check_focal(turned, pairs, k, fit, _intrinsics_origin(opts))
    if focal is not None:
        checks.append(("focal length against the poses", focal.describe()))
    ray = ray_depth_problem(turned, k, focal, f"--depth {opts.depth}")
    if ray is not None:  # it explains the turned pairs' gaps: no focal length's problem
        findings.warning(ray)
        problem, explains = None, False
        pairs = along_axis_pairs(pairs, k)  # the rest judged on the depth so read
        fit = fit_scale(pairs, k)
    findings.problem(problem, given=opts.intrinsics is not None)
    if explains:
        return
    for text in convention_problems(pairs, k, fit, src.describe,
                                    ReadAs(opts.camera_axes, bag=True)):
        findings.problem(text, given=estimate)
    motion = pose_motion_problem(fit, src.describe)
    if motion is not None:
        findings.problem(motion[0], given=estimate or not motion[1])
    findings.problem(bag_scale_problem(fit, idx, opts, src, _scale_origin(idx, opts)[1]),
                     given=opts.depth_scale is not None)


def _intrinsics_origin(opts: BagOptions) -> str:
    return ("flag --intrinsics" if opts.intrinsics is not None else
            f"topic {opts.info}" + (f" ({opts.info_origin})" if opts.info_origin else ""))


def _scale_origin(idx: BagIndex, opts: BagOptions) -> tuple[str, str]:
    """(value, origin) of the depth scale of a bag import."""
    raws = list(idx.samples.values())
    if not raws:
        return "-", "no depth"
    raw, scale = raws[0]
    if opts.depth_scale is not None:
        return f"{opts.depth_scale:g} units/m", "flag --depth-scale"
    if raw.dtype == np.uint16:
        return f"{scale:g} units/m", "the image encoding: 16-bit depth is millimetres in ROS"
    return "metres", "the image encoding: 32FC1 depth is metres"


def check_depth_samples(idx: BagIndex, opts: BagOptions, findings: Findings,
                        what: str) -> None:
    """The sampled depth images (``what`` names their topic): some valid pixel, and the
    depth scale against them, before the frames are decoded."""
    if not idx.samples:
        return
    raws = [raw for raw, _ in idx.samples.values()]
    findings.problem(no_depth_problem(raws, what), given=False)
    raw0, scale0 = next(iter(idx.samples.values()))
    _, origin = _scale_origin(idx, opts)
    findings.problem(depth_scale_problem(raws, _scale(raw0, scale0, opts), origin),
                     given=opts.depth_scale is not None)


def _estimate(
    reader: Any, plan: list[PlannedFrame], idx: BagIndex, opts: BagOptions, k: CameraIntrinsics,
    src: PoseSource | None,
) -> tuple[list[PlannedFrame], DriftReport | None, OdometryResult, str]:
    """Poses of the planned frames by odometry (an extra pass over the images); the drift
    against the bag's own poses where it has them."""
    from dataclasses import replace

    if opts.odometry == "rgbd" and not opts.rgb:
        raise SgtoolError("--odometry rgbd needs --rgb; use icp")

    def gen() -> Iterator[tuple[np.ndarray | None, np.ndarray]]:
        for fr in decode_frames(reader, plan, idx, opts, k):
            d = fr.depth.astype(np.float32) / 1000.0 if fr.depth.dtype == np.uint16 else fr.depth
            yield fr.rgb, d

    res = estimate_with_progress(gen(), k, len(plan), method=opts.odometry,
                                 start=plan[0].pose, depth_max=opts.depth_max,
                                 times_ns=[p.t_ns for p in plan], progress=opts.progress)
    drift = drift_where_known(res.poses, [p.pose for p in plan])
    new_plan = [replace(p, pose=T) for p, T in zip(plan, res.poses, strict=True)]
    desc = f"estimated by {res.method} odometry"
    if src is not None:
        desc += f" ({src.describe} kept for the drift)"
    return new_plan, drift, res, desc


def _import_trajectory(
    path: Path, out: Path, src: PoseSource, opts: BagOptions, meta: dict[str, str], kind: str
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
    if src.tree is not None and src.track is None:  # /tf: the pose of a named frame
        # the frames export names it by (the world's only when the import kept it)
        meta["pose_frame"] = src.camera
        if np.array_equal(alignment.matrix, np.eye(4)):
            meta["world_frame"] = src.world
    A = alignment.matrix  # noqa: N806
    with LogWriter(out, compression=opts.compression) as w:
        w.add_metadata(IMPORT_METADATA, meta)
        w.write_record(Episode(kind="import", status="started", source=meta["source"],
                               frames=0), samples[0][0])
        for t, T in samples:  # noqa: N806
            w.write_transform(t, S.WORLD_FRAME, S.CAMERA_FRAME, A @ T)
        w.write_record(Episode(kind="import", status="ended", source=meta["source"], frames=0,
                               extra={"poses": len(samples), "content": "trajectory"}),
                       samples[-1][0])
    return ImportReport(
        output=out, source=str(path), kind=kind, frames=0, poses=len(samples),
        alignment=alignment, has_rgb=False, has_ids=False,
        pose_source=src.describe, sources=tuple(alignment_sources(alignment)),
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
