"""The options of a bag import (the flags of ``sgtool import bag``) and the check of its
numeric ones and of flags that exclude each other, before the bag is opened."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log.records import Instances
from sgtool.recorders.importers.checks import (
    check_counts,
    check_depth_scale,
    check_height_band,
    check_intrinsics,
    check_non_negative,
    check_positive,
)
from sgtool.recorders.importers.instance_table import check_instances
from sgtool.recorders.importers.pose_axes import check_camera_axes
from sgtool.recorders.importers.sanity import DEFAULT_CAMERA_HEIGHT
from sgtool.recorders.importers.textformats import PinholeParams

MAX_TIME_OFFSET_S = 3600.0  # --time-offset


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
    camera_height: tuple[float, float] = DEFAULT_CAMERA_HEIGHT  # plausible band, m
    warn: Callable[[str], None] | None = None  # shows a warning at once
    timestamps: str = "header"  # image times: "header" stamps, or "bag" (record) times
    info_origin: str = ""  # how --info was chosen, when not given ("the only CameraInfo topic")
    allow_drop: bool = False  # depth images without a pose may be more than 10 %
    time_offset_ns: int = 0  # added to the images' times (header stamps or record times)
    instances: Instances | None = None  # what the ids stand for (:mod:`.instance_table`)
    camera_axes: str = "optical"  # the axes of the posed camera frame (:mod:`.pose_axes`)


def check_options(opts: BagOptions) -> None:
    """The numeric options and flags that exclude each other, before the bag is opened
    (user errors naming the flag)."""
    check_counts(opts.every, opts.limit)
    check_depth_scale(opts.depth_scale)
    check_height_band(opts.camera_height)
    check_intrinsics(opts.intrinsics)
    check_camera_axes(opts.camera_axes)
    if opts.camera_axes != "optical" and opts.depth is None:
        raise SgtoolError(f"--camera-axes {opts.camera_axes} reads the depth camera's poses "
                          "(give --depth); a trajectory import keeps its frame's poses as "
                          "they are")
    if opts.timestamps not in ("header", "bag"):
        raise SgtoolError(f"--timestamps {opts.timestamps!r}: give header or bag")
    check_positive(opts.depth_max, "--depth-max", "metres")
    check_non_negative(opts.max_dt_ns / 1e9, "--max-dt", "seconds")
    check_non_negative(opts.tf_tolerance_ns / 1e9, "--tf-tolerance", "seconds")
    if abs(opts.time_offset_ns) > MAX_TIME_OFFSET_S * 1e9:
        raise SgtoolError(f"--time-offset {opts.time_offset_ns / 1e9:g}: must be within "
                          f"+-{MAX_TIME_OFFSET_S:g} seconds")
    check_instances(opts.instances, opts.ids, "the id image topic too (--ids TOPIC, with "
                    "--depth)")
    if opts.instances is not None and opts.depth is None:
        raise SgtoolError(f"--ids {opts.ids} --instances: give the depth topic too "
                          "(--depth TOPIC)")
    if opts.pose is not None and opts.tf_frames is not None:
        raise SgtoolError(
            f"--tf-frames {':'.join(opts.tf_frames)} applies only to camera poses from the tf "
            f"tree (without --pose); --pose {opts.pose} gives the camera poses directly: "
            "give one of them")
