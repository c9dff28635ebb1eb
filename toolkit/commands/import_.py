"""``sgtool import bag|rgbd``: foreign recordings into sgtool logs.

The work is done in :mod:`sgtool.recorders.importers`; this module parses options and
prints the import report (or JSON with ``--json``).
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path
from typing import Any

import click

from sgtool.canonical import json_text
from sgtool.commands.options import PathParam, check_log_output, option_group
from sgtool.errors import SgtoolError
from sgtool.recorders.importers.checks import (
    MAX_DT_S,
    MAX_TF_TOLERANCE_S,
    check_floor,
    seconds_option_ns,
)


def _floor(text: str) -> tuple[float | None, bool]:
    s = text.strip().lower()
    if s == "auto":
        return None, True
    if s == "none":
        return None, False
    try:
        value = float(s)
    except ValueError as e:
        raise SgtoolError(f"--floor {text!r}: give auto, none or a height in metres") from e
    return check_floor(value), False


def _offset_ns(seconds: float) -> int:
    """``--time-offset`` in seconds (finite) -> integer nanoseconds."""
    import math

    from sgtool.recorders.importers.bag_options import MAX_TIME_OFFSET_S

    if not math.isfinite(seconds):
        raise SgtoolError(f"--time-offset {seconds!r}: give a number of seconds")
    if abs(seconds) > MAX_TIME_OFFSET_S:  # the value given, not one cut to fit nanoseconds
        raise SgtoolError(f"--time-offset {seconds:g}: must be within "
                          f"+-{MAX_TIME_OFFSET_S:g} seconds")
    return round(seconds * 1e9)


def _output(output: str | None, force: bool) -> Path:
    """``-o``: given, then the one output check of a log."""
    if not output:
        raise SgtoolError("give the output log with -o OUT.mcap")
    return check_log_output(output, force=force)


def _unused_odometry_note(report) -> None:  # type: ignore[no-untyped-def]
    """A note when --odometry or --depth-max was given but no pose was estimated."""
    ctx = click.get_current_context(silent=True)
    if ctx is None or report.odometry_failures is not None:
        return
    given = [f"--{n.replace('_', '-')}" for n in ("odometry", "depth_max")
             if ctx.get_parameter_source(n) == click.core.ParameterSource.COMMANDLINE]
    if given:
        click.echo(f"sgtool: note: {' and '.join(given)} did nothing: no pose was estimated "
                   f"(poses: {report.pose_source}); --estimate-poses estimates them",
                   err=True)


def _print_report(report, as_json: bool) -> None:  # type: ignore[no-untyped-def]
    _unused_odometry_note(report)
    if as_json:
        a = report.alignment
        d = {
            "output": str(report.output), "source": report.source, "kind": report.kind,
            "frames": report.frames, "poses": report.poses, "pose_source": report.pose_source,
            "colour": report.has_rgb, "instance_ids": report.has_ids,
            "alignment": {"matrix": a.matrix.round(9).tolist(), "source_up": list(a.up),
                          "up_method": a.up_method, "floor": a.floor,
                          "floor_method": a.floor_method},
            "drift": asdict(report.drift) if report.drift else None,
            "drift_reference": report.drift_reference if report.drift else None,
            "odometry_failures": report.odometry_failures,
            "odometry_failure_reasons": dict(report.odometry_reasons)
            if report.odometry_failures is not None else None,
            "notes": list(report.notes),
            "sources": {name: {"value": value, "origin": origin}
                        for name, value, origin in report.sources},
            "warnings": list(report.warnings),
            "resizes": [dict(r) for r in report.resize_counts],
            "checks": {name: verdict for name, verdict in report.checks},
        }
        click.echo(json_text(d, indent=2, sort_keys=True))
    else:  # on one terminal the warnings stand above already (:func:`_warn`)
        shown = sys.stdout.isatty() and sys.stderr.isatty()
        for line in report.lines(warnings_shown=shown):
            click.echo(line)


def _warn(text: str) -> None:
    """A warning of the import, shown on stderr as soon as it is found."""
    click.echo(f"sgtool: warning: {text}", err=True)


def _world_options(f):  # type: ignore[no-untyped-def]
    f = click.option(
        "--camera-height", default="0.45:2.2", show_default=True,
        help="MIN:MAX metres: the band of plausible camera heights above the floor. An "
        "estimated floor that puts the camera outside it is an error (the floor was not in "
        "view: give --floor); a given --floor outside it, a warning.",
    )(f)
    f = click.option(
        "--floor", default="auto", show_default=True,
        help="Floor height in the source world along the up direction: 'auto' (1st "
        "percentile of upward-facing surface heights in a few depth frames), 'none' (keep "
        "the height), or metres.",
    )(f)
    f = click.option(
        "--up", default="auto", show_default=True,
        help="Direction of the source world that points up: an axis (x, -x, y, -y, z, -z), "
        "a vector 'ux,uy,uz', or 'auto' (mean camera up, refined by the normals of "
        "horizontal surfaces). Bag trajectories without images keep their world unless "
        "given.",
    )(f)
    return f


_common_options = option_group([
    click.option("-o", "--output", type=PathParam(dir_okay=False),
                 help="The sgtool log to write (OUT.mcap)."),
    click.option("--intrinsics", default=None,
                 help="Camera intrinsics 'fx,fy,cx,cy' in pixels, or a file (Open3D JSON, "
                 "a 3x3 matrix as text, or the four numbers fx fy cx cy); overrides what the "
                 "source says."),
    click.option("--depth-scale", type=float, default=None,
                 help="Raw depth units per metre (default: 16-bit depth 1000 for bags "
                 "and 7-Scenes/Open3D, 5000 for TUM; a bag's 32FC1 float depth 1, metres; "
                 "depth image files are 16-bit)."),
    click.option("--max-dt", type=float, default=0.02, show_default=True,
                 help="Largest time difference (s, at most 60) when pairing colour (and ids) "
                 "with a depth image. Colour of another size than the depth is resized to it "
                 "when the aspect ratio is the same, and refused when it differs (it would "
                 "no longer be registered to the depth)."),
    click.option("--every", type=int, default=1, show_default=True,
                 help="Keep every N-th frame."),
    click.option("--limit", type=int, default=None, help="Keep at most N frames."),
    click.option("--compression", type=click.Choice(["zstd", "lz4", "none"]),
                 default="zstd", show_default=True,
                 help="MCAP chunk compression (lz4: ~1.4x faster import, ~30 % larger)."),
    click.option("--force", is_flag=True, help="Overwrite the output log."),
    click.option("--allow-drop", is_flag=True,
                 help="Import the frames that have a pose even when more than 10 % of the "
                 "depth images have none (without it, an error); for a folder, also leave "
                 "out the frames whose poses jump away and come back (placeholders where "
                 "tracking was lost)."),
    click.option("--json", "as_json", is_flag=True, help="Print the report as JSON."),
    click.option("--quiet", is_flag=True, help="No progress bars."),
])


_camera_axes_option = click.option(
    "--camera-axes", type=click.Choice(["optical", "opengl", "body"]), default="optical",
    show_default=True,
    help="Axes of the camera frame the poses are given in: optical (x right, y down, z "
    "forward: OpenCV's, ROS's *_optical_frame), opengl (x right, y up, z backward: OpenGL's, "
    "NeRF's, Blender's) or body (x forward, y left, z up: ROS's camera_link). The pose "
    "check names the one that fits when the poses as read do not move as the depth does.")


def _odometry_options(estimate_help: str, odometry_help: str,
                      depth_max_help: str) -> Callable[[Any], Any]:
    """``--estimate-poses``, ``--odometry`` and ``--depth-max``, with the command's help."""
    return option_group([
        click.option("--estimate-poses", is_flag=True, help=estimate_help),
        click.option("--odometry", type=click.Choice(["rgbd+icp", "rgbd", "icp"]),
                     default="rgbd+icp", show_default=True, help=odometry_help),
        click.option("--depth-max", type=float, default=4.0, show_default=True,
                     help=depth_max_help),
    ])


@click.group("import")
def command() -> None:
    """Import ROS 1/2 bags and RGB-D folders into sgtool logs.

    Imported logs hold depth, colour (when the source has it), camera calibration and
    world -> camera poses; instance ids only when the source has them (replay then builds
    geometry only). The imported world is made z-up with the floor at z=0 (sgtool maps
    heights along z): see --up and --floor.
    """


@command.command("bag")
@click.argument("path", type=PathParam(exists=True))
@click.option("--depth", help="Depth image topic (sensor_msgs/Image 16UC1 or 32FC1, or "
              "CompressedImage PNG/compressedDepth): one frame per depth image.")
@click.option("--rgb", help="Colour image topic (Image or CompressedImage).")
@click.option("--ids", help="Instance-id image topic (integer Image), if the bag has one.")
@click.option("--instances", type=PathParam(dir_okay=False, exists=True),
              help="What the --ids stand for: a JSON file {\"instances\": [{\"id\": 1, "
              "\"category\": \"chair\", \"kind\": \"furniture\"}, ...]} (kind: object, "
              "furniture, door or structure; the sgtool.Instances record, see docs/api.md). "
              "Without it the ids are imported and a replay builds geometry only.")
@click.option("--info", help="CameraInfo topic of the depth camera (the intrinsics).")
@click.option("--tf-frames", help="WORLD:CAMERA frames of the tf tree for the camera pose "
              "(default: the depth image's frame in the root of its tree). Without --depth: "
              "import the trajectory of CAMERA in WORLD.")
@click.option("--pose", help="Pose topic (PoseStamped, PoseWithCovarianceStamped, "
              "TransformStamped, Odometry) giving the camera's optical frame in the world, "
              "instead of tf; a topic whose messages name another child frame (an "
              "odometry's base_link) is carried to the depth images' frame by /tf.")
@click.option("--timestamps", type=click.Choice(["header", "bag"]), default="header",
              show_default=True,
              help="Image times: the header stamps (checked: distinct, a camera's rate), or the "
              "times the bag recorded the messages.")
@click.option("--tf-tolerance", type=float, default=0.05, show_default=True,
              help="How far (s) before/after a transform's samples a pose may be taken.")
@click.option("--time-offset", type=float, default=0.0, show_default=True,
              help="Seconds added to the image times before they are paired with poses "
              "(a camera clock off from /tf's: image stamps later than the bag recorded them "
              "are an error that names the offset that fits).")
@_odometry_options(
    estimate_help="Estimate the camera poses by RGB-D odometry even when the bag has tf (the "
    "drift against the bag's poses is reported). Needs --depth. A bag without tf and without "
    "--pose is always estimated.",
    odometry_help="Odometry for estimated poses (see `sgtool import rgbd --help`).",
    depth_max_help="Depth beyond this (m) is ignored by the odometry.")
@click.option("--list", "list_only", is_flag=True,
              help="List the bag's topics, tf links and suggested flags, and stop.")
@_camera_axes_option
@_world_options
@_common_options
def bag(path: str, list_only: bool, output: str | None, force: bool, as_json: bool,
        **given: Any) -> None:
    """Import a ROS 1 .bag, a ROS 2 bag folder (sqlite3 or MCAP) or a bare ROS 2 .mcap/.db3
    file at PATH.

    Each depth image becomes a frame at its header time, with the colour (and id) image of
    nearest time within --max-dt and the camera pose from tf interpolated at that time.
    Without flags, it stops (exit 2) naming the bag's topics and the flags to give for
    them; --list only lists the topics.

    \b
    Example:
      sgtool import bag run.bag -o run.mcap --depth /camera/depth/image_raw \\
        --rgb /camera/rgb/image_color --info /camera/depth/camera_info
      sgtool import bag tf_example.bag -o traj.mcap --tf-frames odom:base_link
    """
    from sgtool.recorders.importers.bag import check_options, describe_bag, import_bag
    from sgtool.recorders.importers.bagfiles import open_bag

    if list_only:
        with open_bag(path) as reader:
            if as_json:
                from sgtool.recorders.importers.bagfiles import list_topics

                click.echo(json_text({"path": path, "topics": [
                    {"topic": t.topic, "type": t.msgtype, "count": t.count}
                    for t in list_topics(reader)]}, indent=2))
            else:
                click.echo(describe_bag(reader, Path(path)))
        return
    opts = _bag_options(**given)
    check_options(opts)
    if not (opts.depth or opts.tf_frames or opts.pose):
        # nothing to import yet: the error lists the topics and suggests flags
        from sgtool.recorders.importers.bag import check_flags
        from sgtool.recorders.importers.bagfiles import list_topics

        with open_bag(path) as reader:
            check_flags(Path(path), list_topics(reader), opts, reader)
    _print_report(import_bag(path, _output(output, force), opts), as_json)


def _tf_frames(text: str | None) -> tuple[str, str] | None:
    """``--tf-frames WORLD:CAMERA``."""
    if text is None:
        return None
    parts = text.split(":")
    if len(parts) != 2 or not all(parts):
        raise SgtoolError(f"--tf-frames {text!r}: give WORLD:CAMERA, e.g. map:camera")
    if parts[0] == parts[1]:
        raise SgtoolError(f"--tf-frames {text!r}: the world and the camera are one frame "
                          "(every pose would be the identity); give two frames")
    return parts[0], parts[1]


def _bag_options(*, depth: str | None, rgb: str | None, ids: str | None,
                 instances: str | None, info: str | None,
                 tf_frames: str | None, pose: str | None, timestamps: str,
                 tf_tolerance: float, time_offset: float, estimate_poses: bool,
                 odometry: str, depth_max: float, up: str, floor: str, camera_height: str,
                 intrinsics: str | None, depth_scale: float | None, max_dt: float,
                 every: int, limit: int | None, compression: str, allow_drop: bool,
                 quiet: bool, camera_axes: str) -> Any:
    """The options of `sgtool import bag` (other than the output), each checked, as
    :class:`sgtool.recorders.importers.bag.BagOptions`."""
    from sgtool.recorders.importers.bag import BagOptions
    from sgtool.recorders.importers.checks import parse_height_band
    from sgtool.recorders.importers.instance_table import read_instance_table
    from sgtool.recorders.importers.textformats import parse_intrinsics
    from sgtool.recorders.importers.upright import parse_up

    frames = _tf_frames(tf_frames)
    fl, floor_auto = _floor(floor)
    return BagOptions(
        rgb=rgb, depth=depth, ids=ids, info=info, tf_frames=frames, pose=pose,
        instances=None if instances is None else read_instance_table(instances),
        intrinsics=parse_intrinsics(intrinsics) if intrinsics else None,
        depth_scale=depth_scale, max_dt_ns=seconds_option_ns(max_dt, "--max-dt", MAX_DT_S),
        tf_tolerance_ns=seconds_option_ns(tf_tolerance, "--tf-tolerance", MAX_TF_TOLERANCE_S),
        up=parse_up(up), floor=fl,
        floor_auto=floor_auto, every=every, limit=limit, progress=not quiet,
        compression=compression, estimate_poses=estimate_poses, odometry=odometry,
        depth_max=depth_max, camera_height=parse_height_band(camera_height), warn=_warn,
        timestamps=timestamps, allow_drop=allow_drop,
        time_offset_ns=_offset_ns(time_offset), camera_axes=camera_axes,
    )


@command.command("rgbd")
@click.argument("folder", type=PathParam(exists=True, file_okay=False))
@click.option("--layout", type=click.Choice(["auto", "tum", "7scenes", "open3d", "replica"]),
              default="auto", show_default=True,
              help="Folder layout: TUM RGB-D (rgb.txt, depth.txt, groundtruth.txt), 7-Scenes "
              "(frame-XXXXXX.color/depth/pose), Open3D/Redwood (color|image/, depth/, "
              "*.log or traj.txt, intrinsics JSON; or, without them, a ScanNet export's "
              "pose/NAME.txt and intrinsic/intrinsic_depth.txt), Replica as NICE-SLAM renders "
              "it (results/frameNNNNNN.jpg and depthNNNNNN.png, traj.txt, cam_params.json).")
@click.option("--fps", type=float, default=30.0, show_default=True,
              help="Frame rate (0.1-1000) for layouts without time stamps (7-Scenes frame n "
              "is at n/fps; an Open3D image numbered n at (n - first) / step / fps, step the "
              "usual gap of the numbers, so a missing image leaves a gap; names that are "
              "no frame numbers at their position / fps) and for --timestamps index; give "
              "the real spacing of the images when frames were skipped (odometry checks the "
              "motion per step against it).")
@click.option("--timestamps", type=click.Choice(["file", "index"]), default="file",
              show_default=True,
              help="TUM time stamps: 'file' takes rgb.txt/depth.txt's (checked: increasing, "
              "distinct, a camera's rate), 'index' puts frame n at n/--fps in the listed "
              "order and pairs colour n with depth n (the ground truth is then not used).")
@click.option("--skip-missing", is_flag=True,
              help="Import the frames whose files exist when some are missing: files "
              "rgb.txt/depth.txt list (TUM), a 7-Scenes frame's depth, an Open3D colour image "
              "without its depth image (its pose left out with it); without it, missing "
              "files are an error before anything is read.")
@click.option("--trajectory", type=PathParam(dir_okay=False, exists=True),
              help="Poses to use instead of the dataset's: an Open3D .log, a TUM file, or a "
              "camera-to-world matrix a line (16 numbers, as NICE-SLAM's traj.txt; 12, as "
              "KITTI's poses.txt), one a frame in order.")
@_odometry_options(
    estimate_help="Estimate the poses by RGB-D odometry even when the dataset has them (their "
    "drift against the dataset's poses is reported). Sources without poses are always "
    "estimated.",
    odometry_help="Odometry: Open3D RGB-D odometry refined by point-to-plane ICP, RGB-D "
    "odometry alone, or ICP alone.",
    depth_max_help="Depth beyond this (m) is ignored by the odometry (not by the import).")
@_camera_axes_option
@click.option("--world-to-camera", is_flag=True,
              help="The poses map the world into the camera (extrinsics, as COLMAP and some "
              "SLAM systems write them), not the camera into the world: each is inverted.")
@click.option("--ids", type=PathParam(file_okay=False, exists=True), default=None,
              help="A folder of instance-id images (single-channel integer PNG/TIFF or .npy, "
              "0: no instance), each named as its depth image and of its size.")
@click.option("--instances", type=PathParam(dir_okay=False, exists=True), default=None,
              help="What the --ids stand for: a JSON file, as `import bag --instances` "
              "takes. Without it the ids are imported and a replay builds geometry only.")
@_world_options
@_common_options
def rgbd(folder: str, layout: str, fps: float, timestamps: str, skip_missing: bool,
         trajectory: str | None, estimate_poses: bool, odometry: str, depth_max: float,
         up: str, floor: str, camera_height: str, output: str | None, intrinsics: str | None,
         depth_scale: float | None, max_dt: float, every: int, limit: int | None,
         compression: str, force: bool, allow_drop: bool, as_json: bool, quiet: bool,
         camera_axes: str, world_to_camera: bool, ids: str | None, instances: str | None
         ) -> None:
    """Import an RGB-D image folder (TUM RGB-D, 7-Scenes, Open3D/Redwood, ScanNet export,
    Replica as NICE-SLAM renders it) at FOLDER.

    Log times are the dataset's time stamps (TUM) or frame number / --fps. Poses are the
    dataset's (ground truth or trajectory) or estimated by odometry; instance ids come
    from a folder of id images (--ids) with the table of what they stand for.

    \b
    Example:
      sgtool import rgbd rgbd_dataset_freiburg1_xyz -o fr1_xyz.mcap
      sgtool import rgbd 7scenes/redkitchen/seq-01 -o kitchen.mcap --estimate-poses
    """
    from sgtool.recorders.importers.checks import parse_height_band
    from sgtool.recorders.importers.instance_table import read_instance_table
    from sgtool.recorders.importers.rgbd import RgbdOptions, import_rgbd
    from sgtool.recorders.importers.textformats import parse_intrinsics
    from sgtool.recorders.importers.upright import parse_up

    out, (fl, floor_auto) = _output(output, force), _floor(floor)
    opts = RgbdOptions(
        layout=None if layout == "auto" else layout, depth_scale=depth_scale,
        intrinsics=parse_intrinsics(intrinsics) if intrinsics else None, fps=fps,
        trajectory=Path(trajectory) if trajectory else None, estimate_poses=estimate_poses,
        odometry=odometry, depth_max=depth_max, up=parse_up(up), floor=fl,
        floor_auto=floor_auto, every=every, limit=limit,
        max_dt_ns=seconds_option_ns(max_dt, "--max-dt", MAX_DT_S),
        progress=not quiet, compression=compression, timestamps=timestamps,
        skip_missing=skip_missing, camera_height=parse_height_band(camera_height), warn=_warn,
        allow_drop=allow_drop, camera_axes=camera_axes, world_to_camera=world_to_camera,
        ids=Path(ids) if ids else None, instances=read_instance_table(instances)
        if instances is not None else None,
    )
    _print_report(import_rgbd(folder, out, opts), as_json)
