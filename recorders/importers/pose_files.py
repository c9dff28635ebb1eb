"""Camera poses and intrinsics as one text file per frame, the way a ScanNet export (the
``SensReader`` of ScanNet) and many reconstruction tools write them beside ``color/`` and
``depth/``:

- ``pose/NAME.txt`` (or ``poses/``): the 4x4 camera-to-world matrix of the depth image
  ``depth/NAME.*``, four rows of four numbers (a 3x4 without the last row is taken too);
  a matrix that is not finite (ScanNet writes ``-inf`` where its reconstruction lost the
  camera) or a missing file is a frame without a pose;
- ``intrinsic/intrinsic_depth.txt``: the depth camera's matrix, 3x3 or ScanNet's 4x4 (the
  3x3 in its top-left corner, the rest the identity's).
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.recorders.importers.textformats import PinholeParams, checked_pinhole

POSE_FOLDERS = ("pose", "poses")
INTRINSICS_FILE = Path("intrinsic") / "intrinsic_depth.txt"


def pose_folder(root: Path) -> Path | None:
    """The folder of per-frame pose files in ``root`` (module doc), or None."""
    for name in POSE_FOLDERS:
        folder = root / name
        if folder.is_dir() and any(p.suffix.lower() == ".txt" for p in folder.iterdir()):
            return folder
    return None


def _matrix(path: Path) -> np.ndarray:
    """The numbers of a text file (whitespace or commas; ``#`` comments) as rows."""
    try:
        text = path.read_text(encoding="utf-8-sig", errors="replace")
    except OSError as e:
        raise SgtoolError(f"{path}: cannot read ({e.strerror})") from None
    data = "\n".join(line.split("#", 1)[0] for line in text.splitlines())
    if not data.strip():  # an empty file (an export cut short): no numbers, no numpy warning
        return np.empty((0, 0))
    try:
        m = np.loadtxt(io.StringIO(data), dtype=np.float64, ndmin=2,
                       delimiter="," if "," in data else None)
    except ValueError:
        m = np.empty((0, 0))
    return m


def read_pose(path: Path) -> np.ndarray | None:
    """The 4x4 camera-to-world matrix of one pose file, None when it is not finite (a
    reconstruction that lost the camera); a file of another shape, or a matrix whose
    rotation is not one, is a one-line error."""
    m = _matrix(path)
    if m.shape == (3, 4):
        m = np.vstack([m, [0.0, 0.0, 0.0, 1.0]])
    if m.shape != (4, 4):
        raise SgtoolError(f"{path}: expected a 4x4 camera-to-world matrix (four rows of four "
                          f"numbers), got {m.shape[0]}x{m.shape[1] if m.ndim > 1 else 0}")
    if not np.isfinite(m).all():
        return None
    r = m[:3, :3]
    if not np.allclose(m[3], [0.0, 0.0, 0.0, 1.0], atol=1e-6) or \
            not np.allclose(r @ r.T, np.eye(3), atol=1e-3) or np.linalg.det(r) <= 0:
        raise SgtoolError(f"{path}: not a rigid camera-to-world matrix (its top-left 3x3 is "
                          "no rotation, or its last row is not 0 0 0 1)")
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


def folder_intrinsics(root: Path) -> PinholeParams | None:
    """The depth camera's intrinsics of ``intrinsic/intrinsic_depth.txt`` (module doc), or
    None when the folder has no such file."""
    path = root / INTRINSICS_FILE
    if not path.is_file():
        return None
    m = _matrix(path)
    if m.shape == (4, 4) and np.allclose(m[3], [0, 0, 0, 1]) and np.allclose(m[:3, 3], 0):
        m = m[:3, :3]
    if m.shape != (3, 3) or abs(m[2, 2] - 1.0) > 1e-6 or m[0, 0] <= 0 or m[1, 1] <= 0:
        raise SgtoolError(f"{path}: expected a camera matrix [[fx 0 cx] [0 fy cy] [0 0 1]] "
                          "(3x3, or 4x4 with it in the top-left corner)")
    return checked_pinhole(m[0, 0], m[1, 1], m[0, 2], m[1, 2], str(path),
                           source=f"file {INTRINSICS_FILE}")


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
