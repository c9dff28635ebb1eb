"""Camera poses and intrinsics as one text file per frame, the way a ScanNet export (the
``SensReader`` of ScanNet) and many reconstruction tools write them beside ``color/`` and
``depth/``:

- ``pose/NAME.txt`` (or ``poses/``): the 4x4 camera-to-world matrix of the depth image
  ``depth/NAME.*``, four rows of four numbers (a 3x4 without the last row is taken too);
  a matrix of no finite number (ScanNet writes ``-inf`` where its reconstruction lost the
  camera) or a missing file is a frame without a pose, one partly finite is damaged;
- ``intrinsic/intrinsic_depth.txt``: the depth camera's matrix, 3x3 or ScanNet's 4x4 (the
  3x3 in its top-left corner, the rest the identity's); an intrinsics file beside the
  images (:func:`folder_intrinsics`) otherwise.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log.codec import rigid_problem
from sgtool.recorders.importers.textformats import (
    PinholeParams,
    is_intrinsics_json,
    is_open3d_log,
    open3d_log_blocks,
    read_intrinsics_file,
    untracked_pose,
)

POSE_FOLDERS = ("pose", "poses")
INTRINSICS_FILE = Path("intrinsic") / "intrinsic_depth.txt"


def pose_folder(root: Path) -> Path | None:
    """The folder of per-frame pose files in ``root`` (module doc), or None."""
    for name in POSE_FOLDERS:
        folder = root / name
        if folder.is_dir() and any(p.suffix.lower() == ".txt" for p in folder.iterdir()):
            return folder
    return None


def read_pose(path: Path) -> np.ndarray | None:
    """The 4x4 camera-to-world matrix of one pose file (four rows of four numbers, or the
    top three), None when no number is finite (:func:`untracked_pose`: a reconstruction
    that lost the camera); a file of another shape, or a matrix that is not rigid
    (:func:`~sgtool.log.codec.rigid_problem`), is a one-line error."""
    if untracked_pose(path):
        return None
    try:
        text = path.read_text(encoding="utf-8-sig", errors="replace")
    except OSError as e:
        raise SgtoolError(f"{path}: cannot read ({e.strerror})") from None
    rows = [r.replace(",", " ").split() for line in text.splitlines()
            if (r := line.split("#", 1)[0].strip())]
    try:
        m = np.array(rows, dtype=np.float64)
    except ValueError:  # not numbers, or rows of other lengths
        m = np.empty((0, 0))
    if m.shape == (3, 4):
        m = np.vstack([m, [0.0, 0.0, 0.0, 1.0]])
    if m.shape != (4, 4):
        raise SgtoolError(f"{path}: expected a 4x4 camera-to-world matrix (four rows of four "
                          f"numbers), got {m.shape[0]}x{m.shape[1] if m.ndim > 1 else 0}")
    problem = rigid_problem(m)
    if problem is not None:
        raise SgtoolError(f"{path}: not a rigid camera-to-world matrix ({problem[1]})")
    return m


def read_pose_folder(folder: Path, names: list[str]) -> list[np.ndarray | None]:
    """The pose of each frame named in ``names`` (the depth images' stems): that of
    ``folder/NAME.txt``, None where it is missing or not finite."""
    files = {p.stem: p for p in folder.iterdir() if p.suffix.lower() == ".txt"}
    by_number = {int(k): p for k, p in files.items() if k.isdigit()}  # 000012.txt for 12.png
    out: list[np.ndarray | None] = []
    for name in names:
        path = files.get(name) or (by_number.get(int(name)) if name.isdigit() else None)
        out.append(read_pose(path) if path is not None and path.is_file() else None)
    if names and files and all(p is None for p in out) and not any(
            n in files or (n.isdigit() and int(n) in by_number) for n in names):
        raise SgtoolError(f"{folder}: none of its {len(files)} pose files is named for a depth "
                          f"image (depth {names[0]}.* wants {folder.name}/{names[0]}.txt; "
                          f"it has {sorted(files)[0]}.txt)")
    return out


# text files beside the images an Open3D folder's intrinsics are read from (a 3x3 camera
# matrix; ScanNet's 4x4): named for them, the depth camera's before the colour camera's
INTRINSICS_TEXTS = frozenset({"intrinsic", "intrinsics", "camera_intrinsic", "camera_intrinsics",
                              "intrinsic_depth", "intrinsic_color", "depth_intrinsics"})


def seven_scenes_intrinsics(root: Path, default: PinholeParams, *,
                            given: bool = False) -> PinholeParams:
    """A 7-Scenes folder's ``camera-intrinsics.txt`` (a 3x3 camera matrix), else
    ``default``; not read when the intrinsics are ``given`` (``--intrinsics``)."""
    path = root / "camera-intrinsics.txt"
    if given or not path.is_file():
        return default
    return replace(read_intrinsics_file(path), source="file camera-intrinsics.txt")


def folder_intrinsics(root: Path, default: PinholeParams, notes: list[str], *,
                      given: bool = False) -> PinholeParams | None:
    """The depth camera's intrinsics of a folder (each file read as ``--intrinsics FILE``
    reads one): ``intrinsic/intrinsic_depth.txt`` (module doc), else an intrinsics JSON
    or a text file of :data:`INTRINSICS_TEXTS` beside the images (any case), else
    ``default``; None, with a note, for a ScanNet export with only the colour camera's
    ``intrinsic/intrinsic_color.txt`` (no default is that camera's). None of them is read
    when the intrinsics are ``given`` (``--intrinsics``): ``default``."""
    path = root / INTRINSICS_FILE
    if path.is_file() and not given:
        return replace(read_intrinsics_file(path), source=f"file {INTRINSICS_FILE}")
    texts = sorted((p for p in root.iterdir() if p.suffix.lower() == ".txt"  # .TXT too
                    and p.stem.lower().replace("-", "_") in INTRINSICS_TEXTS),
                   key=lambda p: ("depth" not in p.stem.lower(), p.name))  # depth's first
    for p in [] if given else [*sorted(root.glob("*.json")), *texts]:
        if p.suffix != ".json" or is_intrinsics_json(p):
            return replace(read_intrinsics_file(p), source=f"file {p.name}")
    if not path.is_file() and (root / "intrinsic" / "intrinsic_color.txt").is_file():
        notes.append("intrinsic/intrinsic_color.txt not read: the colour camera's, not the "
                     "depth images' (intrinsic/intrinsic_depth.txt)")
        return None
    return default


def posed_pairs(folder: Path, pairs: list[tuple[Path, Path | None]], keep_unposed: bool,
                notes: list[str]) -> tuple[list[tuple[Path, Path | None]],
                                           list[np.ndarray | None], int]:
    """The (depth, colour) ``pairs`` of a folder with their poses from the pose files in
    ``folder``: (pairs kept, their poses, how many were left out). A frame without a pose
    (no file, or not finite) is left out, unless ``keep_unposed`` (poses to be estimated);
    either way a note in ``notes`` says how many and the first."""
    poses = read_pose_folder(folder, [d.stem for d, _ in pairs])
    notes.append(f"poses from {folder.name}/ ({sum(p is not None for p in poses)} files)")
    lost = [d for (d, _), p in zip(pairs, poses, strict=True) if p is None]
    if not lost:
        return pairs, poses, 0
    notes.append(f"{len(lost)} of {len(pairs)} frames have no finite pose in {folder.name}/ "
                 f"(first: {lost[0].name})" + ("" if keep_unposed else ": left out"))
    if keep_unposed:
        return pairs, poses, 0
    if len(lost) == len(pairs):
        raise SgtoolError(f"{folder}: none of the {len(pairs)} frames has a finite pose "
                          "(give --estimate-poses to estimate them from the depth)")
    kept = [(pair, p) for pair, p in zip(pairs, poses, strict=True) if p is not None]
    return [k for k, _ in kept], [p for _, p in kept], len(lost)


def poses_by_block_id(trajectory: Path, numbers: list[float], notes: list[str]
                      ) -> list[np.ndarray] | None:
    """The poses of frames numbered ``numbers`` (their image names) from an Open3D
    ``.log`` whose block ids skip some numbers (a lab removed bad frames with their pose
    blocks), each frame's the block of its number, with a note; None when ``trajectory``
    is no such log, its ids run without a gap, or a frame's number has no block (those
    are read, or refused, frame by frame in order)."""
    if not is_open3d_log(trajectory):
        return None
    blocks = open3d_log_blocks(trajectory)
    ids = [k for k, _ in blocks]
    if len(set(ids)) < len(ids) or ids == [ids[0] + i for i in range(len(ids))]:
        return None
    by_id = dict(blocks)
    if not numbers or any(n not in by_id for n in numbers):
        return None
    notes.append(f"poses from {trajectory.name} paired with the images by its block ids "
                 f"(they skip numbers, as the images do)")
    return [by_id[n] for n in numbers]
