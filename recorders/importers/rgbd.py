"""``sgtool import rgbd``: an RGB-D folder (TUM, 7-Scenes, Open3D/Redwood) into a log.

Steps: list the frames (:mod:`.layouts`); take the dataset's poses, or estimate them by
odometry (:mod:`.odometry`) when it has none or when asked, measuring the drift against
the dataset's poses where they exist (ground truth for TUM and 7-Scenes, the reconstructed
trajectory an Open3D/Redwood folder comes with); estimate the z-up world alignment from
the poses and a few depth frames (:mod:`.upright`); write the frames (:mod:`.sink`). Log
times are the dataset's time stamps (TUM) or frame number / fps. The images are read
twice (odometry, then writing) rather than held in memory.

Before the heavy work (:mod:`.sanity`, :mod:`.provenance`): every listed file exists (else
an error, or ``skip_missing``), the listed time stamps increase at a camera's rate (else an
error naming ``--timestamps index --fps N``), the depth of a few frames at the depth scale
looks indoor (else an error naming the scale that fits), and after the world alignment the
camera is within ``camera_height`` of the floor (else an error naming ``--floor``). A check
of a value the user gave with a flag warns instead. The report says where the intrinsics,
depth scale, up direction and floor came from.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.extras import require
from sgtool.log.frame import CameraIntrinsics
from sgtool.log.records import Instances
from sgtool.recorders.importers.checks import (
    FPS_RANGE,
    MAX_DT_S,
    check_counts,
    check_depth_scale,
    check_floor,
    check_height_band,
    check_intrinsics,
    check_positive,
    check_range,
)
from sgtool.recorders.importers.floor import floor_confidence_problem, frame_floor_problem
from sgtool.recorders.importers.focal_check import (
    FocalFit,
    along_axis_pairs,
    check_focal,
    ray_depth_problem,
    turn_pairs,
)
from sgtool.recorders.importers.folder_ids import id_files, read_ids, unread_ids_note
from sgtool.recorders.importers.images import (
    ResizeLog,
    colour_kind_problem,
    depth_for_log,
    depth_to_metres,
    header_kind,
    read_color_file_kind,
    read_depth_file,
    resize_to,
)
from sgtool.recorders.importers.instance_table import check_instances
from sgtool.recorders.importers.layouts import FolderFrame, FolderSequence, read_sequence
from sgtool.recorders.importers.odometry import (
    DriftReport,
    OdometryResult,
    drift_where_known,
    estimate_with_progress,
)
from sgtool.recorders.importers.pose_axes import (
    OPTICAL_C2W,
    ReadAs,
    check_camera_axes,
    convention_text,
    to_optical,
)
from sgtool.recorders.importers.pose_jumps import placeholder_poses_problem, placeholder_runs
from sgtool.recorders.importers.provenance import (
    ESTIMATED_FLOORS,
    FLOOR_ORIGINS,
    Findings,
    alignment_sources,
    source_metadata,
)
from sgtool.recorders.importers.sanity import (
    DEFAULT_CAMERA_HEIGHT,
    camera_heights,
    depth_scale_problem,
    dropped_problem,
    floor_problem,
    no_depth_problem,
    principal_point_problem,
)
from sgtool.recorders.importers.scale_check import (
    ScaleFit,
    convention_problems,
    fit_scale,
    frozen_poses_problem,
    geometric_scale_problem,
    pair_indices,
    pose_motion_problem,
)
from sgtool.recorders.importers.sink import (
    ImportFrame,
    ImportReport,
    drift_metadata,
    odometry_metadata,
    odometry_report_fields,
    write_log,
)
from sgtool.recorders.importers.textformats import PinholeParams
from sgtool.recorders.importers.upright import (
    DepthSample,
    estimate_alignment,
    given_up_problem,
    sample_indices,
)


@dataclass(frozen=True)
class RgbdOptions:
    """How :func:`import_rgbd` reads a folder (the flags of ``sgtool import rgbd``):
    ``layout`` (None: detected), ``depth_scale`` and ``intrinsics`` (None: the layout's),
    ``fps``, a ``trajectory`` file or ``estimate_poses`` by ``odometry``, ``up`` and
    ``floor`` (None: estimated), ``every``/``limit`` on the frames, ``timestamps``
    (``file``: the listed times; ``index``: n / fps), the poses' ``camera_axes`` and
    ``world_to_camera`` (:mod:`.pose_axes`), a folder of instance-id images ``ids`` and
    their table ``instances`` (:mod:`.folder_ids`). :func:`check_options` checks them
    before anything is read."""

    layout: str | None = None
    depth_scale: float | None = None  # raw units per metre; None = the layout's
    intrinsics: PinholeParams | None = None  # None = the layout's
    fps: float = 30.0
    trajectory: Path | None = None
    estimate_poses: bool = False
    odometry: str = "rgbd+icp"
    depth_max: float = 4.0  # odometry only
    up: np.ndarray | None = None  # None = estimate
    floor: float | None = None  # None = estimate (unless floor_auto is False)
    floor_auto: bool = True
    every: int = 1
    limit: int | None = None
    max_dt_ns: int = 20_000_000
    progress: bool = True
    compression: str = "zstd"
    timestamps: str = "file"  # "file": the listed times (checked); "index": n / fps
    skip_missing: bool = False
    camera_height: tuple[float, float] = DEFAULT_CAMERA_HEIGHT  # plausible band, m
    warn: Callable[[str], None] | None = None  # shows a warning at once
    allow_drop: bool = False  # frames the poses do not cover may be more than 10 %
    # the convention of the folder's (or ``trajectory``'s) poses (:mod:`.pose_axes`)
    camera_axes: str = "optical"
    world_to_camera: bool = False
    ids: Path | None = None  # a folder of instance-id images (:mod:`.folder_ids`)
    instances: Instances | None = None  # what the ids stand for (:mod:`.instance_table`)


def python_options(opts: object) -> RgbdOptions:
    """``opts`` as a Python caller may give them, in the types :func:`import_rgbd` works
    with: None is the defaults; ``trajectory`` a path as text too (one that is no file is
    one line, as the flag's is); ``up`` an axis or ``auto`` as ``--up`` takes it, or three
    numbers; ``floor`` ``"auto"`` or ``"none"`` as ``--floor`` takes them. A value of
    another type is one :class:`SgtoolError` line naming the field (not an error deep
    inside the import)."""
    from sgtool.arg_checks import of_type, whole
    from sgtool.recorders.importers.upright import parse_up

    if opts is None:
        return RgbdOptions()
    of_type("opts", opts, RgbdOptions, "an sgtool.RgbdOptions (RgbdOptions(every=2, ...))")
    assert isinstance(opts, RgbdOptions)
    whole("every", opts.every)  # the range: check_options, naming the flag
    whole("limit", opts.limit, optional=True)
    changes: dict[str, object] = {}
    dt: object = opts.max_dt_ns
    if isinstance(dt, float) and dt.is_integer():
        changes["max_dt_ns"] = int(dt)  # 2e7 nanoseconds, as before
    elif isinstance(opts.max_dt_ns, bool) or not isinstance(opts.max_dt_ns, int | np.integer):
        raise SgtoolError(f"max_dt_ns={opts.max_dt_ns!r}: whole nanoseconds (--max-dt 0.02 "
                          "is max_dt_ns=20_000_000)")
    traj = opts.trajectory
    if traj is not None and not isinstance(traj, Path):
        if not isinstance(traj, str | os.PathLike):
            raise SgtoolError(f"trajectory: a file's path, got {type(traj).__name__}")
        changes["trajectory"] = traj = Path(traj)
    if traj is not None and not Path(traj).is_file():
        raise SgtoolError(f"--trajectory {traj}: no such file")
    up = opts.up
    if isinstance(up, str):
        changes["up"] = parse_up(up)
    elif up is not None:
        try:
            v = np.asarray(up, dtype=np.float64)
        except (TypeError, ValueError):
            v = np.zeros(0)
        if v.shape != (3,) or not np.all(np.isfinite(v)) or np.linalg.norm(v) < 1e-9:
            raise SgtoolError(f"up={up!r}: three finite numbers, not all 0 (or an axis as "
                              "--up takes it: 'z', '-y', 'auto')")
        changes["up"] = v / np.linalg.norm(v)
    if opts.ids is not None and not isinstance(opts.ids, Path):
        if not isinstance(opts.ids, str | os.PathLike):
            raise SgtoolError(f"ids: a folder's path, got {type(opts.ids).__name__}")
        changes["ids"] = Path(opts.ids)
    check_instances(opts.instances, opts.ids, "the folder of the id images too (--ids DIR)")
    if isinstance(opts.floor, str) and opts.floor.strip().lower() in ("auto", "none"):
        changes["floor"] = None
        changes["floor_auto"] = opts.floor.strip().lower() == "auto"
    return replace(opts, **changes) if changes else opts  # type: ignore[arg-type]


def check_options(opts: RgbdOptions) -> None:
    """The numeric options, before anything is read (user errors naming the flag)."""
    check_counts(opts.every, opts.limit)
    check_height_band(opts.camera_height)
    if opts.timestamps not in ("file", "index"):
        raise SgtoolError(f"--timestamps {opts.timestamps!r}: give file or index")
    check_depth_scale(opts.depth_scale)
    check_range(opts.fps, "--fps", *FPS_RANGE, "frames per second")
    check_positive(opts.depth_max, "--depth-max", "metres")
    check_range(opts.max_dt_ns / 1e9, "--max-dt", 0.0, MAX_DT_S, "seconds")
    check_floor(opts.floor)
    check_intrinsics(opts.intrinsics)
    check_camera_axes(opts.camera_axes)


def in_sgtool_convention(seq: FolderSequence, axes: str,
                         world_to_camera: bool) -> FolderSequence:
    """``seq`` with its poses, given with camera ``axes`` (and inverted), turned into
    camera-to-world poses of the optical frame (:func:`~.pose_axes.to_optical`), and a
    note saying so; ``seq`` itself in sgtool's own convention; one line when the flags
    were given for a folder without poses (estimated: they would be ignored)."""
    said = convention_text(axes, world_to_camera)
    if not said:
        return seq
    if seq.pose_source == "none":
        flags = [f for f, on in (("--camera-axes", axes != "optical"),
                                 ("--world-to-camera", world_to_camera)) if on]
        raise SgtoolError(f"{' and '.join(flags)}: {seq.root} has no poses to read (they "
                          "are estimated from the depth); leave "
                          f"{'them' if len(flags) > 1 else 'it'} out")
    frames = tuple(replace(f, pose=None if f.pose is None else
                           to_optical(f.pose, axes, world_to_camera)) for f in seq.frames)
    return replace(seq, frames=frames, notes=(*seq.notes, f"poses read as given: {said}"))


def drift_reference(seq: FolderSequence, trajectory: Path | None) -> str:
    """What the drift of estimated poses is measured against: the dataset's ground truth
    (TUM, 7-Scenes), a trajectory given with --trajectory, or the trajectory an Open3D /
    Redwood folder comes with (a reconstruction, e.g. ICL-NUIM's in the Open3D data)."""
    if seq.pose_source == "ground truth":
        return "ground truth"
    if trajectory is not None:
        return f"the given trajectory {trajectory.name} (not ground truth)"
    return "the reference trajectory (reconstructed, not ground truth)"


def camera_for(seq: FolderSequence, opts: RgbdOptions, width: int, height: int,
               findings: Findings | None = None) -> CameraIntrinsics:
    """The camera of ``width`` x ``height`` depth images: the intrinsics given or the
    layout's, for that size (a principal point outside the images is an error; one far from
    their centre a :func:`~.sanity.principal_point_problem`, whatever size the intrinsics
    say).
    """
    p = opts.intrinsics or seq.intrinsics
    if p is None:
        raise SgtoolError(
            f"{seq.root}: the {seq.layout} layout does not say the camera intrinsics"
            + (" (intrinsic/ has only intrinsic_color.txt, the colour camera's)"
               if any("intrinsic_color.txt not read" in n for n in seq.notes) else "")
            + "; give them with --intrinsics fx,fy,cx,cy (or an intrinsics file)"
        )
    if (p.width and p.width != width) or (p.height and p.height != height):
        raise SgtoolError(
            f"intrinsics {p.source or ''} are for {p.width}x{p.height} images, the depth "
            f"images are {width}x{height}; give theirs with --intrinsics fx,fy,cx,cy (or a "
            "file)"
        )
    origin = "flag --intrinsics" if opts.intrinsics is not None else p.source
    if not (0 <= p.cx <= width and 0 <= p.cy <= height):
        raise SgtoolError(f"intrinsics ({origin}): principal point ({p.cx:g}, {p.cy:g}) is "
                          f"outside the {width}x{height} depth images")
    if findings is not None:
        findings.problem(principal_point_problem(p.cx, p.cy, width, height, origin),
                         given=opts.intrinsics is not None)
    return CameraIntrinsics(width, height, float(p.fx), float(p.fy), float(p.cx), float(p.cy))


@dataclass(frozen=True)
class ColourStream:
    """The pixel kind (:func:`~.images.pixel_kind`) of a folder's first colour image, which
    every other colour image must have."""

    kind: str
    path: Path

    @classmethod
    def of(cls, frames: list[FolderFrame]) -> ColourStream | None:
        """The first colour image's kind, and every PNG colour header checked against it
        (cheap: 26 bytes a file), before any heavy work; None without colour."""
        paths = [f.color_path for f in frames if f.color_path is not None]
        if not paths:
            return None
        _, kind = read_color_file_kind(paths[0])
        stream = cls(kind, paths[0])
        for path in paths[1:]:
            head = header_kind(path)
            if head is not None:
                stream.check(head, path)
        return stream

    def check(self, kind: str, path: Path) -> None:
        problem = colour_kind_problem(kind, path, self.kind, self.path)
        if problem is not None:
            raise SgtoolError(problem)


def _load(fr: FolderFrame, scale: float, size: tuple[int, int] | None = None,
          colour: ColourStream | None = None, resizes: ResizeLog | None = None,
          ) -> tuple[np.ndarray, np.ndarray | None]:
    """A folder frame's raw depth and its colour image (None without one) resized to the
    depth image (counted in ``resizes``); a depth image whose size differs from ``size``, or
    a colour image of another kind than ``colour``'s, is refused."""
    raw = read_depth_file(fr.depth_path)
    if size is not None and (raw.shape[1], raw.shape[0]) != size:
        raise SgtoolError(
            f"{fr.depth_path}: {raw.shape[1]}x{raw.shape[0]} pixels, the first depth image has "
            f"{size[0]}x{size[1]}"
        )
    rgb: np.ndarray | None = None
    if fr.color_path is not None:
        rgb, kind = read_color_file_kind(fr.color_path)
        if colour is not None:
            colour.check(kind, fr.color_path)
        rgb = resize_to(rgb, raw.shape[1], raw.shape[0], str(fr.color_path), resizes)
    return raw, rgb


def run_odometry(
    frames: list[FolderFrame], k: CameraIntrinsics, scale: float, opts: RgbdOptions,
    start: np.ndarray | None, colour: ColourStream | None = None,
) -> OdometryResult:
    size = (k.width, k.height)

    def gen() -> Iterator[tuple[np.ndarray | None, np.ndarray]]:
        for fr in frames:
            raw, rgb = _load(fr, scale, size, colour)
            yield rgb, depth_to_metres(raw, scale)

    if opts.odometry == "rgbd" and any(f.color_path is None for f in frames):
        raise SgtoolError("--odometry rgbd needs a colour image for every frame; use icp")
    return estimate_with_progress(gen(), k, len(frames), method=opts.odometry, start=start,
                                  depth_max=opts.depth_max,
                                  times_ns=[f.time_ns for f in frames], progress=opts.progress)


def check_scale_by_geometry(frames: list[FolderFrame], k: CameraIntrinsics, scale: float,
                            origin: str, pose_source: str, findings: Findings,
                            given: bool, estimate: bool = False,
                            intrinsics: tuple[str, bool] = ("given", True),
                            read_as: ReadAs = OPTICAL_C2W
                            ) -> tuple[ScaleFit | None, FocalFit | None]:
    r"""The depth scale and the focal length against the metric poses
    (:mod:`.scale_check`, :mod:`.focal_check`), on a few pairs of nearby and of turned
    frames, before any heavy work; the fits (None without a usable pair). Poses the depth
    does not follow are an error when clear, else a warning (a warning only when the
    poses are to be ``estimate``\ d anyway); a focal length that does not fit is an error
    unless the ``intrinsics`` (origin, whether given by the user) were given; when it
    explains the depth not moving as the poses do, the depth scale is not blamed."""
    poses = [np.asarray(f.pose) for f in frames]

    def depth_pairs(ij: list[tuple[int, int]]
                    ) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
        return [(depth_to_metres(read_depth_file(frames[i].depth_path), scale),
                 depth_to_metres(read_depth_file(frames[j].depth_path), scale),
                 poses[i], poses[j]) for i, j in ij]

    pairs = depth_pairs(pair_indices(poses))
    fit = fit_scale(pairs, k)
    turned = [p for p in depth_pairs(turn_pairs(poses))
              if p[0].shape == p[1].shape == (k.height, k.width)]
    focal, problem, explains = check_focal(turned, pairs, k, fit, intrinsics[0])
    ray = ray_depth_problem(turned, k, focal, "the depth images")
    if ray is not None:  # it explains the turned pairs' gaps: no focal length's problem
        findings.warning(ray)
        problem, explains = None, False
        pairs = along_axis_pairs(pairs, k)  # the rest judged on the depth so read
        fit = fit_scale(pairs, k)
    findings.problem(problem, given=intrinsics[1])
    if explains:
        return fit, focal
    for problem in convention_problems(pairs, k, fit, pose_source, read_as):
        findings.problem(problem, given=estimate)
    motion = pose_motion_problem(fit, pose_source)
    if motion is not None:
        findings.problem(motion[0], given=estimate or not motion[1])
    findings.problem(geometric_scale_problem(fit, scale, origin, pose_source), given=given)
    return fit, focal


def _without_placeholders(frames: list[FolderFrame], opts: RgbdOptions
                          ) -> tuple[list[FolderFrame], int]:
    """``frames`` without the runs of placeholder poses
    (:func:`~sgtool.recorders.importers.pose_jumps.placeholder_runs`) when ``--allow-drop``
    asks for the posed frames only (the poses are not estimated), and how many were left
    out; else ``frames`` as they are (a run stops the import later, naming its frames)."""
    if not opts.allow_drop or opts.estimate_poses or any(f.pose is None for f in frames):
        return frames, 0
    runs = placeholder_runs(np.array([np.asarray(f.pose, float)[:3, 3] for f in frames]))
    out = {i for a, b in runs for i in range(a, b + 1)}
    return [f for i, f in enumerate(frames) if i not in out], len(out)


def import_rgbd(root: str | Path, out: str | Path, opts: RgbdOptions | None = None) -> ImportReport:
    """Import the RGB-D folder ``root`` into the log ``out`` (module doc) and return what
    was written; options and the folder's files are checked before any work, each problem
    a one-line :class:`~sgtool.errors.SgtoolError`."""
    require("cv2", api="sgtool.import_rgbd")  # before any work
    opts = python_options(opts)
    root, out = Path(root), Path(out)
    check_options(opts)
    seq = read_sequence(root, opts.layout, max_dt_ns=opts.max_dt_ns, fps=opts.fps,
                        trajectory=opts.trajectory, keep_unposed=opts.estimate_poses,
                        timestamps=opts.timestamps, skip_missing=opts.skip_missing,
                        intrinsics_given=opts.intrinsics is not None,
                        depth_scale_given=opts.depth_scale is not None)
    seq = in_sgtool_convention(seq, opts.camera_axes, opts.world_to_camera)
    frames = list(seq.frames[:: opts.every])
    if opts.limit is not None:
        frames = frames[: opts.limit]
    if not frames:
        raise SgtoolError(f"{root}: no frames left after --every/--limit")
    if not opts.allow_drop:
        problem = dropped_problem(
            seq.dropped, len(seq.frames) + seq.dropped,
            ("they have no pose.txt, or one of non-finite numbers (untracked)"
             if seq.layout == "7scenes" else
             "they have no pose file, or one of non-finite numbers (untracked)"
             if any(n.startswith("poses from pose") for n in seq.notes) else
             f"the {seq.pose_source} of {root.name} does not cover their time"),
            "give --estimate-poses to estimate the poses of all frames, or --allow-drop to "
            "import only the covered ones")
        if problem:
            raise SgtoolError(f"{root}: {problem}")
    frames, jumped = _without_placeholders(frames, opts)
    id_paths = None if opts.ids is None else id_files(opts.ids, [f.depth_path
                                                                 for f in frames])
    colour = ColourStream.of(frames)
    findings = Findings(opts.warn)
    scale = float(opts.depth_scale if opts.depth_scale is not None else seq.depth_scale)
    scale_origin = ("flag --depth-scale" if opts.depth_scale is not None
                    else seq.scale_source or f"dataset default: {seq.layout} layout")
    picks = sample_indices(len(frames))
    raws = [read_depth_file(frames[i].depth_path) for i in picks]
    findings.problem(no_depth_problem(raws, str(root)), given=False)
    k = camera_for(seq, opts, raws[0].shape[1], raws[0].shape[0], findings)
    checks: list[tuple[str, str]] = []
    intr_origin = "flag --intrinsics" if opts.intrinsics is not None else \
        (seq.intrinsics.source if seq.intrinsics is not None else "given")
    if seq.pose_source != "none" and all(f.pose is not None for f in frames):
        # first: metric poses name the scale that fits better than a usual median does
        fit, focal = check_scale_by_geometry(
            frames, k, scale, scale_origin, seq.pose_source, findings,
            given=opts.depth_scale is not None, estimate=opts.estimate_poses,
            intrinsics=(intr_origin, opts.intrinsics is not None),
            read_as=ReadAs(opts.camera_axes, opts.world_to_camera))
        checks.append(("depth scale against the poses",
                       fit.describe() if fit else "no verdict: no frame pair pins the motion down"))
        if focal is not None:
            checks.append(("focal length against the poses", focal.describe()))
        frozen = frozen_poses_problem([np.asarray(f.pose) for f in frames],
                                      [depth_to_metres(r, scale) for r in raws],
                                      seq.pose_source)
        if frozen is not None and not opts.estimate_poses:
            findings.problem(frozen[0], given=not frozen[1])
        if not opts.estimate_poses:
            findings.problem(placeholder_poses_problem(
                [np.asarray(f.pose) for f in frames], [f.depth_path.name for f in frames],
                seq.pose_source), given=False)
    findings.problem(depth_scale_problem(raws, scale, scale_origin),
                     given=opts.depth_scale is not None)
    if opts.intrinsics is None and intr_origin.startswith("folder-name default"):
        findings.warning(f"intrinsics taken from the folder name ({intr_origin}); give "
                         "--intrinsics fx,fy,cx,cy if the images come from another camera")

    notes = list(seq.notes) + ([f"{jumped} frame(s) whose poses jump away and come back "
                                 "(placeholders) left out (--allow-drop)"] if jumped else [])
    unread = unread_ids_note(root) if opts.ids is None else None
    notes += [unread] if unread else []
    drift: DriftReport | None = None
    odo: OdometryResult | None = None
    reference = drift_reference(seq, opts.trajectory)
    source_poses = [f.pose for f in frames]
    if opts.estimate_poses or seq.pose_source == "none":
        if opts.floor is None and opts.floor_auto and opts.up is None:
            # before the odometry: the floor of each sampled frame on its own
            findings.problem(frame_floor_problem([depth_to_metres(r, scale) for r in raws],
                                                 k, opts.camera_height), given=False)
        # start at the first reference pose, so the estimate lives in the dataset's world
        odo = run_odometry(frames, k, scale, opts, source_poses[0], colour)
        poses = list(odo.poses)
        if odo.warning():
            notes.append(str(odo.warning()))
        drift = drift_where_known(poses, source_poses)
        pose_source = f"estimated by {odo.method} odometry"
        if seq.pose_source != "none":
            pose_source += f" (the dataset's {seq.pose_source} kept for the drift)"
        # the dataset's pose file measures the drift only: not where the poses come from
        notes = [f"{n[len('poses from '):]} kept to measure the odometry's drift"
                 if n.startswith("poses from ") else n for n in notes]
    else:
        poses = [np.asarray(p) for p in source_poses]
        pose_source = (f"trajectory {opts.trajectory} (--trajectory)" if opts.trajectory
                       else f"{seq.pose_source} of the dataset")

    samples = [DepthSample(depth_to_metres(raw, scale), k, poses[i])
               for raw, i in zip(raws, picks, strict=True)]
    alignment = estimate_alignment(poses, samples, up=opts.up, floor=opts.floor,
                                   floor_auto=opts.floor_auto)
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
    sources = [("intrinsics", f"{k.fx:g},{k.fy:g},{k.cx:g},{k.cy:g}", intr_origin),
               ("depth scale", f"{scale:g} units/m", scale_origin),
               *alignment_sources(alignment)]

    meta = {
        "source": str(root.resolve().name),
        "source_kind": f"rgbd/{seq.layout}",
        "layout": seq.layout,
        "pose_source": pose_source,
        "depth_scale": f"{scale:g}",
        "intrinsics": f"{k.fx:g},{k.fy:g},{k.cx:g},{k.cy:g}",
        **source_metadata(sources),
        "instance_ids": "absent" if opts.ids is None else "present",
        "frames_in_source": str(len(seq.frames)),
        "every": str(opts.every),
        "timestamps": opts.timestamps,
        **({"warnings": "\n".join(findings.warnings)} if findings.warnings else {}),
        **drift_metadata(drift, reference),
        **(odometry_metadata(odo) if odo is not None else {}),
    }

    resizes = ResizeLog()

    def gen() -> Iterator[ImportFrame]:
        size = (k.width, k.height)
        for i, (fr, pose) in enumerate(zip(frames, poses, strict=True)):
            raw, rgb = _load(fr, scale, size, colour, resizes)
            ids = None if id_paths is None else read_ids(id_paths[i], raw.shape)
            yield ImportFrame(fr.time_ns, depth_for_log(raw, scale), pose, k, rgb=rgb, ids=ids)

    n, has_rgb, has_ids = write_log(out, gen(), alignment=alignment, metadata=meta,
                                    total=len(frames), progress=opts.progress, notes=notes,
                                    compression=opts.compression, resizes=resizes,
                                    instances=opts.instances)
    return ImportReport(
        output=out, source=str(root), kind=f"rgbd/{seq.layout}", frames=n, poses=len(poses),
        alignment=alignment, has_rgb=has_rgb, has_ids=has_ids, pose_source=pose_source,
        drift=drift, notes=tuple(notes), drift_reference=reference,
        sources=tuple(sources), warnings=tuple(findings.warnings),
        resizes=tuple(resizes.lines()), resize_counts=tuple(resizes.as_dicts()),
        checks=tuple(checks), **odometry_report_fields(odo),
    )
