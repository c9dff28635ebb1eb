"""RGB-D folder layouts: detection and listing of frames, poses and camera parameters.

- ``tum`` (TUM RGB-D benchmark): ``rgb.txt`` and ``depth.txt`` list time-stamped images,
  ``groundtruth.txt`` holds the motion-capture trajectory (camera-to-world) at ~100 Hz.
  Colour is associated with each depth image by nearest time stamp within ``max_dt``
  (20 ms, as the benchmark's ``associate.py``); the pose at the depth time is interpolated
  from the ground truth. Depth is in 1/5000 m. Intrinsics: the benchmark's published
  calibration for freiburg1/2/3 when the folder name says which, else they must be given.
- ``7scenes`` (Microsoft 7-Scenes, Shotton et al. CVPR 2013): ``frame-XXXXXX.color.png``
  (or ``.jpg``), ``frame-XXXXXX.depth.png`` (mm, 65535 = no return), ``frame-XXXXXX.pose.txt``
  (camera-to-world 4x4). Kinect v1 at 30 Hz: frame n is at n/30 s. Intrinsics: a
  ``camera-intrinsics.txt`` 3x3 matrix when present, else the dataset's 585, 585, 320, 240.
  (7-Scenes depth is not registered to colour; the mapping uses depth only.)
- ``open3d`` (Open3D reconstruction system / Redwood): ``color/`` (or ``image/``, ``rgb/``)
  and ``depth/`` folders of images paired by name, a ``.log`` trajectory (camera-to-world)
  and an intrinsics JSON (``intrinsic_matrix``) or text file named for them
  (``intrinsics.txt``: a 3x3 camera matrix); depth in mm. Without one, the PrimeSense
  default 525, 525, 319.5, 239.5 that Open3D itself assumes. Frames are ``1/fps`` apart, in
  natural name order ("2.png" before "10.png", as Open3D's ``sorted_alphanum``); images
  named by plain numbers are at their number's time (a frame missing from the numbering
  leaves a gap). Without a ``.log``, a ``traj.txt`` of a 4x4 matrix a line (as SLAM
  systems write it), or a ``pose/`` folder of one 4x4 text file a frame and an
  ``intrinsic/intrinsic_depth.txt`` (a ScanNet export: :mod:`.pose_files`) are read.
- ``replica``: Replica scenes as NICE-SLAM renders them (:mod:`.replica_layout`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from sgtool.errors import SgtoolError, a_or_an
from sgtool.log.poses import PoseTrack
from sgtool.recorders.importers.image_files import (
    depth_images,
    frame_slots,
    images,
    natural_key,
    pair_name,
)
from sgtool.recorders.importers.pose_files import (
    folder_intrinsics,
    pose_folder,
    posed_pairs,
    poses_by_block_id,
    seven_scenes_intrinsics,
)
from sgtool.recorders.importers.replica_layout import is_replica, read_replica, replica_missing
from sgtool.recorders.importers.sanity import id_step_notes, time_range_problem, timestamp_problem
from sgtool.recorders.importers.stamps import NearestStamp
from sgtool.recorders.importers.textformats import (
    PinholeParams,
    is_matrix_trajectory,
    is_open3d_log,
    open3d_log_first_frame,
    read_pose_file,
    read_tum_list,
    read_tum_trajectory,
    trajectory_poses,
    untracked_pose,
)

LAYOUTS = ("tum", "7scenes", "open3d", "replica")

# TUM RGB-D calibrated colour intrinsics (vision.in.tum.de/data/datasets/rgbd-dataset/
# file_formats, "Intrinsic Camera Calibration of the Kinect")
TUM_INTRINSICS = {
    "freiburg1": PinholeParams(517.3, 516.5, 318.6, 255.3, source="TUM freiburg1 calibration"),
    "freiburg2": PinholeParams(520.9, 521.0, 325.1, 249.7, source="TUM freiburg2 calibration"),
    "freiburg3": PinholeParams(535.4, 539.2, 320.1, 247.6, source="TUM freiburg3 calibration"),
}
SEVEN_SCENES_INTRINSICS = PinholeParams(585.0, 585.0, 320.0, 240.0,
                                        source="dataset default: 7-Scenes")
PRIMESENSE_INTRINSICS = PinholeParams(525.0, 525.0, 319.5, 239.5,
                                      source="dataset default: PrimeSense, as Open3D assumes")

# (any case: "frame-000100.depth.PNG" as copied from a camera or another file system)
_SEVEN = re.compile(r"^frame-(\d+)\.(color|depth|pose)\.(png|jpg|jpeg|txt)$", re.IGNORECASE)


def _seven_depth(name: str) -> bool:
    """Whether ``name`` is a 7-Scenes depth image."""
    m = _SEVEN.match(name)
    return m is not None and m.group(2).lower() == "depth"


@dataclass(frozen=True)
class FolderFrame:
    time_ns: int
    depth_path: Path
    color_path: Path | None
    pose: np.ndarray | None  # camera-to-world in the source world, when the source has one


@dataclass(frozen=True)
class FolderSequence:
    layout: str
    root: Path
    frames: tuple[FolderFrame, ...]
    intrinsics: PinholeParams | None
    depth_scale: float  # raw depth units per metre
    pose_source: str  # "ground truth" | "trajectory" | "none"
    notes: tuple[str, ...] = ()
    dropped: int = 0  # depth images left out because the poses do not cover their time
    scale_source: str = ""  # where depth_scale came from, when not the layout's default


LAYOUT_NAMES = {"tum": "TUM RGB-D", "7scenes": "7-Scenes", "open3d": "Open3D/Redwood",
                "replica": "Replica (NICE-SLAM)"}
LAYOUT_FILES = {
    "tum": "rgb.txt + depth.txt",
    "7scenes": "frame-XXXXXX.depth.png",
    "open3d": "color/ or image/ and depth/ folders",
    "replica": "results/depthNNNNNN.png, traj.txt",
}


def looks_like(root: Path) -> str | None:
    """The layout a folder's names suggest (see :func:`detect_layout`), or None."""
    names = {p.name for p in root.iterdir()}
    if "depth.txt" in names or "rgb.txt" in names:
        return "tum"  # (one list missing: TUM's reader says which, not another layout)
    if any(_seven_depth(n) for n in names):
        return "7scenes"
    if "depth" in names and (root / "depth").is_dir() and _color_dir(root) is not None:
        return "open3d"
    return "replica" if "results" in names and is_replica(root) else None


def _sequence_hint(root: Path) -> str:
    seqs = sorted(p.name for p in root.iterdir() if p.is_dir() and (  # 7-Scenes; Replica
        p.name.startswith("seq-") or (p / "results").is_dir()))
    return f"; it has sequence folders {', '.join(seqs[:5])}: import one of them" if seqs else ""


def detect_layout(root: Path) -> str:
    """The layout of a folder, or a user error that says what was looked for."""
    if not root.is_dir():
        raise SgtoolError(f"{root} is not a folder")
    layout = looks_like(root)
    if layout is not None:
        return layout
    known = "; ".join(f"{LAYOUT_NAMES[k]}: {v}" for k, v in LAYOUT_FILES.items())
    raise SgtoolError(f"{root}: no known RGB-D layout ({known}){_sequence_hint(root)}")


def missing_for_layout(root: Path, layout: str) -> str | None:
    """What a folder lacks to be read in ``layout``, or None when it has it all."""
    if layout == "tum":
        absent = [n for n in ("rgb.txt", "depth.txt") if not (root / n).is_file()]
        return f"no {' and no '.join(absent)}" if absent else None
    if layout == "7scenes":
        if not any(_seven_depth(p.name) for p in root.iterdir()):
            return "no frame-XXXXXX.depth.png files"
        return None
    if layout == "open3d":
        if not (root / "depth").is_dir():
            return "no depth/ folder"
        if _color_dir(root) is None:
            return "no color/, image/ or rgb/ folder"
        if not images(root / "depth"):
            held = sorted({p.suffix.lower() for p in (root / "depth").iterdir() if p.suffix})
            return "no images in depth/" + (f" (it holds {', '.join(held[:4])} files; depth "
                                            "is read from 16-bit PNG or TIFF images)"
                                            if held else "")
        return None
    if layout == "replica":
        return replica_missing(root)
    raise SgtoolError(f"unknown layout {layout!r} ({', '.join(LAYOUTS)})")


def layout_error(root: Path, layout: str, missing: str) -> SgtoolError:
    """A one-line error: the folder is not ``layout`` (what is missing), and which layout
    it looks like instead."""
    seen = looks_like(root) if root.is_dir() else None
    if seen is not None and seen != layout:
        hint = (f"; it looks like {a_or_an(LAYOUT_NAMES[seen])} folder "
                f"({LAYOUT_FILES[seen]}): use --layout {seen}, or --layout auto")
    elif seen is None:
        hint = f"; it matches no known layout{_sequence_hint(root)}"
    else:
        hint = ""
    return SgtoolError(
        f"{root}: not {a_or_an(LAYOUT_NAMES[layout])} folder "
        f"({LAYOUT_FILES[layout]}): {missing}{hint}"
    )


def _color_dir(root: Path) -> Path | None:
    for n in ("color", "image", "rgb"):
        if (root / n).is_dir():
            return root / n
    return None


def read_sequence(
    root: Path,
    layout: str | None = None,
    *,
    max_dt_ns: int = 20_000_000,
    fps: float = 30.0,
    trajectory: Path | None = None,
    keep_unposed: bool = False,
    timestamps: str = "file",
    skip_missing: bool = False,
    intrinsics_given: bool = False, depth_scale_given: bool = False,
) -> FolderSequence:
    """List a folder's frames (see the module docstring). ``trajectory`` overrides the
    dataset's pose file (TUM text or Open3D .log); ``keep_unposed`` keeps frames the
    ground truth does not cover (for pose estimation). ``timestamps`` "file" takes the
    listed times (checked: :func:`~.sanity.timestamp_problem`), "index" frame n at n / fps
    in the listed order; ``skip_missing`` leaves out listed files that do not exist
    (otherwise an error before anything is read); ``intrinsics_given``: the folder's
    intrinsics files are not read (``--intrinsics`` overrides them, broken or not; a
    Replica cam_params.json, which holds the depth scale too, not if ``depth_scale_given``)."""
    root = Path(root)
    if not root.is_dir():
        raise SgtoolError(f"{root}: no such folder" if not root.exists()
                          else f"{root} is not a folder")
    given = layout
    layout = layout or detect_layout(root)
    missing = missing_for_layout(root, layout)
    if missing is not None:
        raise layout_error(root, layout, missing)
    if layout == "tum":
        seq = _read_tum(root, max_dt_ns, trajectory, keep_unposed, timestamps, fps,
                        skip_missing)
    elif layout == "7scenes":
        seq = _read_7scenes(root, fps, trajectory, skip_missing, keep_unposed, intrinsics_given)
    elif layout == "open3d":
        seq = _read_open3d(root, fps, trajectory, skip_missing, keep_unposed, intrinsics_given)
    elif layout == "replica":
        seq = read_replica(root, fps, trajectory, (intrinsics_given, depth_scale_given))
    else:  # pragma: no cover - missing_for_layout refuses unknown layouts
        raise SgtoolError(f"unknown layout {layout!r} ({', '.join(LAYOUTS)})")
    if not seq.frames:
        raise SgtoolError(f"{root}: no frames found in the {LAYOUT_NAMES[layout]} layout")
    unused = [flag for flag, on, layouts in (
        ("--timestamps index", timestamps != "file", ("tum",)),
        ("--skip-missing", skip_missing, ("tum", "7scenes", "open3d")))
              if on and layout not in layouts]
    if unused:  # said, not silently ignored
        seq = replace(seq, notes=(*seq.notes, f"{' and '.join(unused)}: not used by the "
                                  f"{LAYOUT_NAMES[layout]} layout"))
    seen = looks_like(root)
    if given is not None and seen is not None and seen != given:
        seq = replace(seq, notes=(*seq.notes, f"read as {LAYOUT_NAMES[given]} as asked; the "
                                  f"folder also looks like {LAYOUT_NAMES[seen]} "
                                  f"({LAYOUT_FILES[seen]})"))
    return seq


def _missing_files(root: Path, lists: dict[str, list[tuple[int, str]]],
                   skip_missing: bool) -> tuple[dict[str, list[tuple[int, str]]], list[str]]:
    """Every file the lists name, checked up front: an error naming the count and the first
    missing one, or with ``skip_missing`` the lists without them and a note."""
    missing = {name: [(t, f) for t, f in rows if not (root / f).is_file()]
               for name, rows in lists.items()}
    n = sum(len(v) for v in missing.values())
    if n == 0:
        return lists, []
    total = sum(len(v) for v in lists.values())
    first = next(f for v in missing.values() for _, f in v)
    per = ", ".join(f"{len(v)} of {name}" for name, v in missing.items() if v)
    if not skip_missing:
        raise SgtoolError(
            f"{root}: {n} of the {total} files listed are missing ({per}; first: {first}); "
            "give --skip-missing to import the frames that are there")
    kept = {name: [r for r in rows if r not in set(missing[name])]
            for name, rows in lists.items()}
    return kept, [f"skipped {n} missing files ({per})"]


def _read_tum(
    root: Path, max_dt_ns: int, trajectory: Path | None, keep_unposed: bool,
    timestamps: str = "file", fps: float = 30.0, skip_missing: bool = False,
) -> FolderSequence:
    lists, notes = _missing_files(
        root, {"rgb.txt": read_tum_list(root / "rgb.txt"),
               "depth.txt": read_tum_list(root / "depth.txt")}, skip_missing)
    rgb, depth = lists["rgb.txt"], lists["depth.txt"]
    if not depth:
        raise SgtoolError(f"{root / 'depth.txt'} lists no depth images")
    if timestamps == "index":
        return _read_tum_by_index(root, rgb, depth, fps, notes)
    for name, rows in (("depth.txt", depth), ("rgb.txt", rgb)):
        what = str(root / name)
        in_range = time_range_problem([t for t, _ in rows], what)
        problem = in_range or timestamp_problem([t for t, _ in rows], what)
        in_order = sorted(rows)
        if problem and not in_range and in_order != rows and \
                not timestamp_problem([t for t, _ in in_order], what):
            # times of frames listed out of order: TUM associates by time, so sort them
            back = sum(b[0] < a[0] for a, b in zip(rows, rows[1:], strict=False))
            notes.append(f"{name} lists its images out of time order ({back} step"
                         f"{'s' if back > 1 else ''} back): read in time order")
            rows[:] = in_order
        elif problem:
            raise SgtoolError(problem)
    gt_path = trajectory or (root / "groundtruth.txt")
    if trajectory is not None and (is_open3d_log(trajectory) or
                                   is_matrix_trajectory(trajectory)):
        return _read_tum_log_poses(root, rgb, depth, max_dt_ns, trajectory, notes)
    track = None
    if gt_path.is_file():
        # ground truth at ~100 Hz: interpolate over gaps up to 0.1 s, no extrapolation
        # beyond 10 ms (the motion-capture system loses markers now and then); a sparser
        # trajectory (a SLAM system's) over gaps of 2.5 of its steps, to 0.5 s
        samples = read_tum_trajectory(gt_path)
        if not samples and not keep_unposed:
            raise SgtoolError(f"{gt_path}: holds no poses (TUM lines: time tx ty tz qx qy qz "
                              "qw); give a trajectory, or --estimate-poses")
        step = float(np.median(np.diff(sorted(t for t, _ in samples)))) if len(samples) > 1 else 0.0
        track = PoseTrack.from_samples(
            samples, max_gap_ns=int(min(max(100_000_000, 2.5 * step), 500_000_000)),
            tolerance_ns=10_000_000) if samples else None
    frames = []
    no_rgb = no_pose = 0
    near = NearestStamp([r for r, _ in rgb])
    for t, name in depth:
        color = _colour_near(root, rgb, near(t, max_dt_ns))
        no_rgb += color is None
        pose = track.at(t) if track is not None else None
        if track is not None and pose is None:
            no_pose += 1
            if not keep_unposed:
                continue
        frames.append(FolderFrame(t, root / name, color, pose))
    if not frames:
        span = "" if track is None else (  # two clocks (Unix time and from 0) show here
            f" (depth {depth[0][0] / 1e9:.3f}-{depth[-1][0] / 1e9:.3f} s, poses "
            f"{track.times[0] / 1e9:.3f}-{track.times[-1] / 1e9:.3f} s)")
        raise SgtoolError(
            f"{root}: none of the {len(depth)} depth images is within the time span of "
            f"{gt_path.name}{span}; give --estimate-poses to estimate their poses")
    if no_rgb:
        notes.append(f"{no_rgb} depth images had no colour image within {max_dt_ns / 1e6:g} ms")
    if no_pose:
        what = "kept without pose" if keep_unposed else "dropped"
        notes.append(f"{no_pose} depth images outside the ground truth ({what})")
    return FolderSequence(
        "tum", root, tuple(frames), _tum_intrinsics(root), 5000.0,
        "none" if track is None else ("trajectory" if trajectory else "ground truth"),
        tuple(notes), dropped=0 if keep_unposed else no_pose,
    )


def _colour_near(root: Path, rgb: list[tuple[int, str]], j: int | None) -> Path | None:
    """The colour image ``j`` of ``rgb`` (a :class:`NearestStamp` answer), None for None."""
    return None if j is None else root / rgb[j][1]


def _read_tum_log_poses(root: Path, rgb: list[tuple[int, str]], depth: list[tuple[int, str]],
                        max_dt_ns: int, trajectory: Path, notes: list[str]) -> FolderSequence:
    """``--trajectory X.log`` for a TUM folder: an Open3D .log has no times, so its poses go
    to the depth images in the listed order."""
    poses = trajectory_poses(trajectory, len(depth))
    assert poses is not None
    near = NearestStamp([r for r, _ in rgb])
    frames = [FolderFrame(t, root / name, _colour_near(root, rgb, near(t, max_dt_ns)), poses[i])
              for i, (t, name) in enumerate(depth)]
    no_rgb = sum(f.color_path is None for f in frames)
    if no_rgb:
        notes.append(f"{no_rgb} depth images had no colour image within {max_dt_ns / 1e6:g} ms")
    notes.append(f"poses from {trajectory.name} in depth.txt's order (it has no times)")
    return FolderSequence("tum", root, tuple(frames), _tum_intrinsics(root), 5000.0,
                          "trajectory", tuple(notes))


def _tum_intrinsics(root: Path) -> PinholeParams | None:
    """The TUM calibration the folder's name says (freiburg1/2/3), or None."""
    name = root.resolve().name
    for key, params in TUM_INTRINSICS.items():
        if key in name:
            return replace(params, source=f"folder-name default: {key!r} in {name!r} "
                           f"({params.source})")
    return None


def _read_tum_by_index(root: Path, rgb: list[tuple[int, str]], depth: list[tuple[int, str]],
                       fps: float, notes: list[str]) -> FolderSequence:
    """``--timestamps index``: the depth images in the listed order, frame n at n / fps,
    colour n with depth n; a ground truth (by time) cannot be matched and is not used."""
    if rgb and len(rgb) != len(depth):
        raise SgtoolError(
            f"{root}: --timestamps index pairs colour n with depth n, but rgb.txt lists "
            f"{len(rgb)} images and depth.txt {len(depth)}")
    frames = tuple(
        FolderFrame(round(i * 1e9 / fps), root / name, root / rgb[i][1] if rgb else None, None)
        for i, (_, name) in enumerate(depth))
    notes.append(f"--timestamps index: frame n at n/{fps:g} s in the listed order")
    if (root / "groundtruth.txt").is_file():
        notes.append("groundtruth.txt not used: its times cannot be matched to frame numbers")
    return FolderSequence("tum", root, frames, _tum_intrinsics(root), 5000.0, "none",
                          tuple(notes))


def _seven_missing(root: Path, by_id: dict[int, dict[str, Path]],
                   skip_missing: bool) -> tuple[list[int], list[str]]:
    """The frame numbers to import. A frame with some files but no depth image, or without
    colour when other frames have it, is an error naming it (as a missing file TUM lists),
    or with ``skip_missing`` is left out with a note."""
    colour = next((v["color"].suffix for v in by_id.values() if "color" in v), None)
    need = {"depth": ".png", **({"color": colour} if colour else {})}
    lacking = {i: [k for k in need if k not in v] for i, v in sorted(by_id.items())}
    lacking = {i: lack for i, lack in lacking.items() if lack}
    keep = sorted(i for i in by_id if i not in lacking)
    if not lacking:
        return keep, []
    i, lack = next(iter(lacking.items()))
    first = f"frame-{i:06d}.{lack[0]}{need[lack[0]]}"
    if not skip_missing:
        raise SgtoolError(f"{root}: {len(lacking)} of {len(by_id)} frames lack a depth or "
                          f"colour image (first: {first} is missing); give --skip-missing to "
                          "import the complete frames")
    return keep, [f"skipped {len(lacking)} frames without depth or colour (first: {first})"]


def _read_7scenes(root: Path, fps: float, trajectory: Path | None, skip_missing: bool = False,
                  keep_unposed: bool = False, intrinsics_given: bool = False) -> FolderSequence:
    """Frames ``frame-XXXXXX.*`` in id order; frames without a pose.txt (when others have
    one) are kept to be estimated (``keep_unposed``) or left out and counted as dropped,
    as a TUM ground truth that does not cover them."""
    by_id: dict[int, dict[str, Path]] = {}
    for p in root.iterdir():
        m = _SEVEN.match(p.name)
        if m:
            by_id.setdefault(int(m.group(1)), {})[m.group(2).lower()] = p
    ids, notes = _seven_missing(root, by_id, skip_missing)
    notes += id_step_notes(ids, fps)
    ext_poses = trajectory_poses(trajectory, len(ids))
    frames = []
    for n, i in enumerate(ids):
        files = by_id[i]
        pose = None
        if ext_poses is not None:
            pose = ext_poses[n]
        elif "pose" in files and not untracked_pose(files["pose"]):
            pose = read_pose_file(files["pose"])
        frames.append(FolderFrame(round(i * 1e9 / fps), files["depth"], files.get("color"), pose))
    intr = seven_scenes_intrinsics(root, SEVEN_SCENES_INTRINSICS, given=intrinsics_given)
    posed = sum(f.pose is not None for f in frames)
    dropped = 0
    if 0 < posed < len(frames):
        first = next(f.depth_path.name for f in frames if f.pose is None)
        notes.append(f"{len(frames) - posed} of {len(frames)} frames have no pose.txt, or "
                     f"one of non-finite numbers (untracked) (first: {first})"
                     + ("" if keep_unposed else ": left out"))
        if not keep_unposed:
            dropped = len(frames) - posed
            frames = [f for f in frames if f.pose is not None]
    kind = "trajectory" if trajectory else ("ground truth" if posed else "none")
    return FolderSequence("7scenes", root, tuple(frames), intr, 1000.0, kind, tuple(notes),
                          dropped=dropped)


def _read_open3d(root: Path, fps: float, trajectory: Path | None, skip_missing: bool = False,
                 keep_unposed: bool = False, intrinsics_given: bool = False) -> FolderSequence:
    """Depth images of ``depth/`` and colour images of the colour folder, paired by name
    (else in order when every name differs); a depth image without a colour image of its
    name (a lab that dropped bad colour frames) is a frame without colour, with a note:
    nothing lists the files, so none is missing. A colour image without a depth image
    makes the trajectory one pose longer than the frames: ``skip_missing`` takes the
    poses as those of every image name, depth or colour (in natural order), and leaves
    the frames without depth out with their poses."""
    notes: list[str] = []
    cdir = _color_dir(root)
    depths = depth_images(root / "depth", notes)
    colors = images(cdir) if cdir is not None else []
    by_stem = {pair_name(p): p for p in colors}
    pairs: list[tuple[Path, Path | None]]
    matched = sum(pair_name(d) in by_stem for d in depths)
    if matched or not colors:  # one naming scheme: by name, a depth image may lack colour
        pairs = [(d, by_stem.get(pair_name(d))) for d in depths]
        if matched < len(depths):
            first = next(d for d in depths if pair_name(d) not in by_stem)
            notes.append(f"{len(depths) - matched} depth images have no colour image of "
                         f"their name (first: {first.relative_to(root)})")
    elif len(colors) == len(depths):
        pairs = list(zip(depths, colors, strict=True))
        notes.append("depth and colour images paired in order (their names differ)")
    else:
        raise SgtoolError(f"{root}: {len(depths)} depth and {len(colors)} colour images with "
                          "different names; cannot pair them")
    traj = trajectory
    if traj is None:
        logs = sorted(root.glob("*.log"))
        named = [p for p in logs if p.name == "trajectory.log"]
        if named:
            traj = named[0]
        elif len(logs) == 1:
            traj = logs[0]
        elif len(logs) > 1:
            raise SgtoolError(f"{root}: several trajectories ({', '.join(p.name for p in logs)})"
                              "; choose one with --trajectory")
        elif (root / "traj.txt").is_file() and is_matrix_trajectory(root / "traj.txt"):
            traj = root / "traj.txt"  # a 4x4 matrix a line, as SLAM systems write it
    per_frame = pose_folder(root) if traj is None else None
    slot: dict[Path, float] = {}  # frame i stays at i/fps when frames before it are left out
    numbered = frame_slots([d for d, _ in pairs], depths + (colors if matched else []))
    holes: list[Path] = []
    if numbered is not None:  # times by number: a frame left out keeps later ones in place
        slot = numbered
        holes = [d for d, e in zip(depths, depths[1:], strict=False)
                 if numbered[e] - numbered[d] > 1]
        if holes:
            notes.append(f"{len(holes)} gap(s) in the numbers of the depth images (first: "
                         f"after {holes[0].relative_to(root)}); each frame is at its "
                         "number's time")
    dropped = 0
    if traj is None and per_frame is None and (root / "groundtruth.txt").is_file():
        notes.append("groundtruth.txt not read: a folder of depth/ and colour folders is read "
                     "as the open3d layout (poses from a *.log trajectory, image times from "
                     "their order); a TUM folder lists its images in rgb.txt and depth.txt")
    unpaired = sorted({pair_name(c) for c in colors} - {pair_name(d) for d in depths},
                      key=natural_key)
    hint = (f" ({len(unpaired)} colour images have no depth image; first: "
            f"depth/{by_stem[unpaired[0]].stem}.*"
            f" for {by_stem[unpaired[0]].relative_to(root)}"
            + ("" if skip_missing else "; --skip-missing leaves them out with their poses")
            + ")" if unpaired and len(pairs) < len(colors) else "")
    if traj is not None and skip_missing and unpaired and matched:
        stems = sorted({pair_name(d) for d in depths} | set(by_stem), key=natural_key)
        every = trajectory_poses(traj, len(stems), hint, also=len(pairs))
        assert every is not None
        poses: list[np.ndarray | None] | None = list(every)  # one pose per RGB-D pair
        if len(every) == len(stems) != len(pairs):  # one per image name: those of the pairs
            pose_of = dict(zip(stems, every, strict=True))
            poses = [pose_of[pair_name(d)] for d, _ in pairs]
            notes.append(f"--skip-missing: {len(unpaired)} colour image(s) without a depth "
                         "image left out with their poses (first: "
                         f"{by_stem[unpaired[0]].relative_to(root)})")
    elif per_frame is not None:
        slot = slot or {d: i for i, (d, _) in enumerate(pairs)}
        pairs, poses, dropped = posed_pairs(per_frame, pairs, keep_unposed, notes)
    else:
        by_id = poses_by_block_id(traj, [float(d.stem) for d, _ in pairs], notes) \
            if traj is not None and numbered is not None else None
        read = by_id if by_id is not None else trajectory_poses(
            traj, len(pairs), hint, shorter=True) if traj is not None else None
        poses = None if read is None else list(read)
        if read is not None and len(read) < len(pairs) and (holes or (unpaired and matched)):
            # a short trajectory's blocks go to the frames in order: with frames missing
            # from the numbering, which frames they pose is unclear (those of the image
            # names, or of the images there are)
            assert traj is not None
            which = (f"no depth image for {by_stem[unpaired[0]].relative_to(root)}"
                     if unpaired and matched else f"a gap after {holes[0].relative_to(root)}")
            raise SgtoolError(f"{traj}: {len(read)} poses for {len(pairs)} frames with frames "
                              f"missing from the numbering ({which}): which frames its poses "
                              "belong to is unclear; give one pose per frame")
        start = open3d_log_first_frame(traj) if traj is not None and poses is not None \
            and len(poses) < len(pairs) and is_open3d_log(traj) else 0
        head = pair_name(pairs[0][0]) if start else ""  # "2": numbered as recorded
        if start and poses is not None and (start + len(poses) > len(pairs) or (
                head.isascii() and head.isdigit() and head != "0")):
            assert traj is not None
            raise SgtoolError(f"{traj}: its pose blocks name frames {start}-"
                              f"{start + len(poses) - 1}, and the {len(pairs)} frames of "
                              f"{root.name} start at {pairs[0][0].name}: which frames they "
                              "pose is unclear; give one block per frame from the first")
        if start and poses is not None:
            # a reconstruction that started late: its first pose block is frame ``start``
            assert traj is not None
            notes.append(f"{start} of {len(pairs)} frames come before the first pose of "
                         f"{traj.name}, frame {start} (first: "
                         f"{pairs[0][0].relative_to(root)})"
                         + ("" if keep_unposed else ": left out"))
            if keep_unposed:
                poses = [*([None] * start), *poses]
            else:
                slot = slot or {d: i for i, (d, _) in enumerate(pairs)}
                dropped, pairs = start, pairs[start:]
    if poses is not None and len(poses) < len(pairs):  # a reconstruction that stopped early
        assert traj is not None
        late = len(pairs) - len(poses)
        notes.append(f"{late} of {len(pairs) + dropped} frames come after the last pose of "
                     f"{traj.name} "
                     f"(first: {pairs[len(poses)][0].relative_to(root)})"
                     + ("" if keep_unposed else ": left out"))
        if keep_unposed:
            poses = [*poses, *([None] * late)]
        else:
            dropped, pairs = dropped + late, pairs[:len(poses)]
    intr = folder_intrinsics(root, PRIMESENSE_INTRINSICS, notes, given=intrinsics_given)
    frames = tuple(
        FolderFrame(round((slot[d] if slot else i) * 1e9 / fps), d, c,
                    poses[i] if poses is not None else None)
        for i, (d, c) in enumerate(pairs)
    )
    return FolderSequence(
        "open3d", root, frames, intr, 1000.0,
        "trajectory" if poses is not None else "none",
        ((f"poses from {traj.name}",) if traj is not None else ()) + tuple(notes),
        dropped=dropped,
    )
