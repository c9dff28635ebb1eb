"""Readers (and writers) of the small text formats RGB-D datasets come with.

- TUM RGB-D (Sturm et al., IROS 2012): ``rgb.txt`` / ``depth.txt`` ("timestamp filename"
  lines) and trajectories ``groundtruth.txt`` ("timestamp tx ty tz qx qy qz qw", the pose
  of the colour camera's optical centre in the motion-capture world, i.e. camera-to-world);
  ``#`` starts a comment.
- Open3D / Redwood ``.log`` trajectories: blocks of one metadata line ("i j n") and four
  rows of a camera-to-world 4x4 matrix.
- Intrinsics: Open3D's ``PinholeCameraIntrinsic`` JSON (``intrinsic_matrix`` stored column
  major), a 3x3 matrix as text (7-Scenes / tsdf-fusion ``camera-intrinsics.txt``), or
  ``fx,fy,cx,cy`` given on the command line.

Parsing errors are user errors naming the file and the line.
"""

from __future__ import annotations

import io
import json
import math
import re
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from pathlib import Path

import numpy as np

from sgtool.errors import SgtoolError
from sgtool.log.codec import rigid_problem
from sgtool.log.poses import pose_from_tq


def seconds_to_ns(text: str) -> int:
    """A decimal seconds stamp ("1305031102.160407") -> integer nanoseconds, exactly (no
    float rounding, so two files naming the same instant agree to the nanosecond)."""
    try:
        return int((Decimal(text) * 1_000_000_000).to_integral_value())
    except InvalidOperation as e:
        raise ValueError(f"not a time stamp: {text!r}") from e


MAX_TIME_NS = 2**63 - 1  # the largest time a log (int64 nanoseconds) holds: year 2262


def _data_lines(path: Path) -> list[tuple[int, list[str]]]:
    try:
        text = path.read_text(encoding="utf-8-sig")  # a byte-order mark (Notepad) dropped
    except UnicodeDecodeError as e:
        raise SgtoolError(f"{path} is not a text file") from e
    out = []
    for n, line in enumerate(text.splitlines(), 1):
        s = line.split("#", 1)[0].strip()
        if s:
            out.append((n, s.replace(",", " ").split()))
    return out


def read_tum_list(path: Path) -> list[tuple[int, str]]:
    """(time ns, relative file name) from a TUM ``rgb.txt`` / ``depth.txt``, in the file's
    order (the importer checks that the times increase before it relies on them)."""
    out = []
    for n, parts in _data_lines(path):
        if len(parts) < 2:
            raise SgtoolError(f"{path}:{n}: expected 'timestamp filename', got {' '.join(parts)!r}")
        try:
            out.append((seconds_to_ns(parts[0]), parts[1]))
        except ValueError as e:
            raise SgtoolError(f"{path}:{n}: {e}") from e
    return out


def read_tum_trajectory(path: Path) -> list[tuple[int, np.ndarray]]:
    """(time ns, camera-to-world 4x4) from a TUM trajectory file."""
    out = []
    for n, parts in _data_lines(path):
        if len(parts) != 8:
            raise SgtoolError(
                f"{path}:{n}: a TUM trajectory line has 8 numbers "
                f"(timestamp tx ty tz qx qy qz qw), this one has {len(parts)}"
            )
        try:
            t = seconds_to_ns(parts[0])
            v = [float(x) for x in parts[1:]]
        except ValueError as e:
            raise SgtoolError(f"{path}:{n}: {e}") from e
        if abs(t) > MAX_TIME_NS:
            raise SgtoolError(f"{path}:{n}: time stamp {parts[0]} is beyond year 2262 in "
                              "seconds: TUM files give seconds (not ms or us)")
        if not np.all(np.isfinite(v)):
            raise SgtoolError(f"{path}:{n}: not a valid pose (a number is NaN or infinite)")
        if np.linalg.norm(v[3:]) < 1e-6:
            raise SgtoolError(f"{path}:{n}: not a valid pose (the quaternion is zero)")
        out.append((t, pose_from_tq(v[:3], v[3:])))
    return sorted(out, key=lambda tp: tp[0])


def pose_matrix(path: Path, rows: list[tuple[int, list[str]]]) -> np.ndarray:
    """The rigid camera-to-world 4x4 written as four text ``rows`` (line number, numbers) of
    ``path``; a user error naming the line otherwise."""
    out = []
    for n, parts in rows:
        if len(parts) != 4:
            raise SgtoolError(f"{path}:{n}: expected a matrix row of four numbers, this one "
                              f"has {len(parts)}")
        try:
            vals = [float(x) for x in parts]
        except ValueError as e:
            raise SgtoolError(f"{path}:{n}: {e}") from e
        if not np.all(np.isfinite(vals)):
            raise SgtoolError(f"{path}:{n}: a pose matrix row that is not finite "
                              f"({' '.join(parts)})")
        out.append(vals)
    m = np.array(out, dtype=np.float64)
    problem = rigid_problem(m)
    if problem is not None:
        row, text = problem
        raise SgtoolError(f"{path}:{rows[row][0]}: {text}")
    return m


MATRIX_LINE = (12, 16)  # numbers a line of a trajectory of matrices: 3x4 or 4x4, row by row


def is_matrix_trajectory(path: Path) -> bool:
    """Whether ``path``'s first line of numbers is a pose matrix written on one line
    (:func:`read_matrix_trajectory`), not a TUM line of 8 numbers."""
    rows = _data_lines(path)
    return bool(rows) and len(rows[0][1]) in MATRIX_LINE


def read_matrix_trajectory(path: Path) -> list[np.ndarray]:
    """Camera-to-world poses written a frame a line as a matrix, row by row: 16 numbers (a
    4x4: the ``traj.txt`` of NICE-SLAM's Replica renders and of the SLAM systems that read
    it) or 12 (a 3x4: KITTI's ``poses.txt``), in frame order; each checked rigid."""
    out = []
    for n, parts in _data_lines(path):
        if len(parts) not in MATRIX_LINE:
            raise SgtoolError(f"{path}:{n}: a line of this trajectory is a pose matrix of 12 "
                              f"or 16 numbers (3x4 or 4x4, row by row); this one has "
                              f"{len(parts)}")
        rows = [(n, parts[i:i + 4]) for i in range(0, len(parts), 4)]
        out.append(pose_matrix(path, rows if len(parts) == 16 else
                               [*rows, (n, ["0", "0", "0", "1"])]))
    return out


def untracked_pose(path: Path) -> bool:
    """A 4x4 pose file (as :func:`read_pose_file` reads it) of which no number is finite:
    a frame its tracker lost (ScanNet writes ``-inf`` rows), no pose rather than a damaged
    file (a partly non-finite or malformed one is :func:`read_pose_file`'s error)."""
    try:
        rows = _data_lines(path)
        vals = [float(x) for _, parts in rows for x in parts]
    except (OSError, SgtoolError, ValueError):
        return False
    return len(rows) == 4 and len(vals) == 16 and not any(math.isfinite(v) for v in vals)


def read_pose_file(path: Path) -> np.ndarray:
    """A 4x4 camera-to-world pose as text (7-Scenes ``frame-XXXXXX.pose.txt``), checked
    rigid."""
    rows = _data_lines(path)
    if len(rows) != 4:
        raise SgtoolError(f"{path}: expected a 4x4 pose matrix (four rows of four numbers), "
                          f"found {len(rows)} rows")
    return pose_matrix(path, rows)


def read_open3d_log(path: Path) -> list[np.ndarray]:
    """Camera-to-world 4x4 poses of an Open3D / Redwood ``.log`` trajectory, each checked
    rigid, in the order of the frame ids of their block headers ``i j n`` (Open3D writes
    ``i i i+1`` for frame i): blocks out of order are put in order; a frame id given twice,
    or ids with a gap (a pose for a frame the folder may not have), are refused (unless
    every block has the same one: ids that say nothing, file order)."""
    return [m for _, m in open3d_log_blocks(path, gaps=False)]


def open3d_log_blocks(path: Path, gaps: bool = True) -> list[tuple[float, np.ndarray]]:
    """(frame id, pose) of each block of an Open3D ``.log`` (:func:`read_open3d_log`), in
    id order; ids with a gap are refused only when not ``gaps``."""
    rows = _data_lines(path)
    if len(rows) % 5:
        raise SgtoolError(
            f"{path}: an Open3D .log trajectory has 5 lines per pose (\"i j n\" and 4 matrix "
            f"rows); {len(rows)} lines is not a multiple of 5"
        )
    poses: list[tuple[float, np.ndarray]] = []
    seen: dict[float, int] = {}
    for b in range(0, len(rows), 5):
        n0, head = rows[b]
        try:
            frame = float(head[0]) if len(head) == 3 else math.nan
        except ValueError:
            frame = math.nan
        if not math.isfinite(frame):
            raise SgtoolError(f"{path}:{n0}: expected the block header 'i j n' (numbers)")
        poses.append((frame, pose_matrix(path, rows[b + 1:b + 5])))
        seen.setdefault(frame, n0)
    if 1 < len(seen) < len(poses):
        twice = next(i for i, (k, _) in enumerate(poses) if seen[k] != rows[5 * i][0])
        raise SgtoolError(f"{path}:{rows[5 * twice][0]}: frame id {poses[twice][0]:g} is "
                          f"given twice (first on line {seen[poses[twice][0]]}); each pose "
                          "block's header 'i j n' names its frame i")
    if len(seen) == len(poses):
        poses.sort(key=lambda p: p[0])
        ids = [k for k, _ in poses]
        if not gaps and ids != [ids[0] + i for i in range(len(ids))]:
            gap = next(i for i in range(1, len(ids)) if ids[i] != ids[i - 1] + 1)
            raise SgtoolError(f"{path}: the frame ids of its pose blocks jump from "
                              f"{ids[gap - 1]:g} to {ids[gap]:g}; each block's header 'i j n' "
                              "names its frame, one pose per frame in order")
    return poses


@dataclass(frozen=True)
class PinholeParams:
    """fx, fy, cx, cy in pixels and, when the source says, the image size."""

    fx: float
    fy: float
    cx: float
    cy: float
    width: int | None = None
    height: int | None = None
    source: str = ""


def checked_pinhole(fx: float, fy: float, cx: float, cy: float, what: str, *,
                    width: int | None = None, height: int | None = None, source: str = ""
                    ) -> PinholeParams:
    """``PinholeParams`` whose numbers are finite, with fx, fy > 0 and cx, cy >= 0 (inside
    the image: checked against its size by the importer); a user error naming ``what``."""
    vals = (fx, fy, cx, cy)
    if not all(np.isfinite(vals)):
        raise SgtoolError(f"{what}: intrinsics fx,fy,cx,cy = {','.join(f'{v:g}' for v in vals)} "
                          "are not finite")
    if fx <= 0 or fy <= 0 or cx < 0 or cy < 0:
        raise SgtoolError(f"{what}: intrinsics fx,fy,cx,cy = {','.join(f'{v:g}' for v in vals)}: "
                          "focal lengths must be positive and the principal point inside the "
                          "image")
    return PinholeParams(float(fx), float(fy), float(cx), float(cy), width=width,
                         height=height, source=source)


def read_intrinsics_file(path: Path) -> PinholeParams:
    """Open3D intrinsic JSON, a 3x3 matrix text file (or a 4x4 with it in the top-left
    corner and the identity's other entries, as ScanNet writes it), or a text file of the
    four numbers ``fx fy cx cy`` as ``--intrinsics`` takes them (one line, spaces or
    commas)."""
    if path.suffix.lower() == ".json":
        try:
            d = json.loads(path.read_text(encoding="utf-8-sig"))
            m = np.asarray(d["intrinsic_matrix"], dtype=np.float64).reshape(3, 3).T
            w, h = d.get("width"), d.get("height")
            size = (int(w) if w else None, int(h) if h else None)
        except (json.JSONDecodeError, KeyError, ValueError, TypeError, AttributeError,
                OverflowError) as e:  # (OverflowError: "width": 1e999)
            raise SgtoolError(
                f"{path}: expected Open3D intrinsics JSON with 'width', 'height' and a "
                f"9-number 'intrinsic_matrix' ({type(e).__name__}: {e})"
            ) from e
        if any(v is not None and v <= 0 for v in size):
            raise SgtoolError(f"{path}: image size {w}x{h} is not positive")
        if _transposed(m):
            raise SgtoolError(
                f"{path}: 'intrinsic_matrix' reads as [[fx 0 cx] [0 fy cy] [0 0 1]] only "
                "transposed: Open3D lists it column by column (fx, 0, 0, 0, fy, 0, cx, cy, "
                "1); this one is row by row: reorder it")
        return checked_pinhole(m[0, 0], m[1, 1], m[0, 2], m[1, 2], str(path), width=size[0],
                               height=size[1], source=str(path.name))
    try:
        text = path.read_text(encoding="utf-8-sig", errors="replace")
        data = "\n".join(line.split("#", 1)[0] for line in text.splitlines())
        m = np.loadtxt(io.StringIO(data), dtype=np.float64,
                       delimiter="," if "," in data else None)
    except ValueError:
        raise SgtoolError(f"{path}: expected a 3x3 camera matrix [[fx 0 cx] [0 fy cy] [0 0 1]] "
                          "(three rows of three numbers), the four numbers fx fy cx cy, or "
                          "Open3D intrinsics JSON") from None
    if m.size == 4 and m.ndim == 1:  # fx fy cx cy, as --intrinsics takes them
        fx, fy, cx, cy = (float(v) for v in m)
        return checked_pinhole(fx, fy, cx, cy, str(path), source=str(path.name))
    if m.shape == (4, 4) and np.allclose(m[3], [0, 0, 0, 1]) and np.allclose(m[:3, 3], 0):
        m = m[:3, :3]  # ScanNet's intrinsic_*.txt: the camera matrix in a 4x4's corner
    if m.shape == (3, 3) and _transposed(m):
        raise SgtoolError(f"{path}: a 3x3 camera matrix [[fx 0 cx] [0 fy cy] [0 0 1]] "
                          "written transposed (cx, cy in its last row): transpose it")
    if m.shape != (3, 3) or abs(m[2, 2] - 1.0) > 1e-6 or m[0, 0] <= 0 or m[1, 1] <= 0:
        raise SgtoolError(f"{path}: expected a 3x3 camera matrix [[fx 0 cx] [0 fy cy] [0 0 1]], "
                          "the four numbers fx fy cx cy, or Open3D intrinsics JSON")
    return checked_pinhole(m[0, 0], m[1, 1], m[0, 2], m[1, 2], str(path),
                           source=str(path.name))


def _transposed(m: np.ndarray) -> bool:
    """Whether the camera matrix ``m`` as read has its principal point in the last row
    and nothing in the last column: the matrix written transposed."""
    return bool((m[2, 0] != 0 or m[2, 1] != 0) and m[0, 2] == 0 and m[1, 2] == 0)


def parse_intrinsics(text: str) -> PinholeParams:
    """``fx,fy,cx,cy`` or a path to an intrinsics file."""
    parts = [p for p in re.split(r"[,\s]+", text.strip()) if p]
    if len(parts) == 4:
        try:
            fx, fy, cx, cy = (float(p) for p in parts)
        except ValueError:
            pass
        else:
            return checked_pinhole(fx, fy, cx, cy, f"--intrinsics {text!r}", source="given")
    path = Path(text)
    if not path.is_file():
        looks_like_file = len(parts) == 1 and (path.suffix or "/" in text)
        raise SgtoolError(
            f"--intrinsics {text!r}: " + ("no such file; give " if looks_like_file else
                                          "give ")
            + "'fx,fy,cx,cy' in pixels or an intrinsics file (Open3D JSON, or a 3x3 matrix "
            "as text)"
        )
    return read_intrinsics_file(path)


def is_open3d_log(path: Path) -> bool:
    """Whether a ``--trajectory`` file is an Open3D ``.log`` (any case of the suffix, and
    a first line of three numbers: the frame ids of a 4x4 block) rather than a TUM
    trajectory (eight numbers a line), whatever its name."""
    if path.suffix.lower() != ".log" or not path.is_file():
        return False
    with path.open("rb") as f:
        for raw in f:
            line = raw.decode("utf-8", "replace").strip()
            if line and not line.startswith("#"):
                return len(line.split()) == 3
    return False


def open3d_log_first_frame(path: Path) -> int:
    """The smallest frame id ``i`` of an Open3D ``.log``'s block headers ``i j n`` (0 when
    every block names the same one, or one is negative: ids that say nothing)."""
    rows = _data_lines(path)
    ids = {float(rows[b][1][0]) for b in range(0, len(rows) - len(rows) % 5, 5)
           if len(rows[b][1]) == 3}
    return int(min(ids)) if len(ids) > 1 and min(ids) >= 0 else 0


def trajectory_poses(trajectory: Path | None, count: int, hint: str = "",
                     shorter: bool = False, also: int | None = None
                     ) -> list[np.ndarray] | None:
    """Poses from a --trajectory file for frames in order (Open3D .log, a matrix a line
    (:func:`read_matrix_trajectory`), or a TUM file whose lines are taken in order);
    ``hint`` says why the counts may differ; ``shorter``: an Open3D .log that ends before
    the frames is taken (the first frames' poses); ``also``: another count taken."""
    if trajectory is None:
        return None
    if not trajectory.is_file():
        raise SgtoolError(f"--trajectory {trajectory}: no such file")
    log = is_open3d_log(trajectory)
    matrices = not log and is_matrix_trajectory(trajectory)
    timed = not log and not matrices
    poses = ([T for _, T in read_tum_trajectory(trajectory)] if timed
             else read_open3d_log(trajectory) if log
             else read_matrix_trajectory(trajectory))
    # a TUM file's lines, their times unused, or a matrix a line (no frame ids either) pose
    # the frames in order only when there is one a frame: one short may lack any frame
    # (tracking lost, a placeholder line removed), not only the last ones; a .log's block
    # headers name their frames
    if len(poses) not in (count, also) and not (shorter and log
                                                and 0 < len(poses) < count):
        raise SgtoolError(f"{trajectory} has {len(poses)} poses for {count} frames{hint}"
                          + ("; this layout takes a TUM trajectory's lines one per frame, in "
                             "order, its times unused (a TUM folder, with rgb.txt and "
                             "depth.txt, pairs them by time)" if timed else
                             "; a matrix a line names no frame: one line per frame, in order"
                             if matrices else ""))
    return poses


def is_intrinsics_json(path: Path) -> bool:
    """Whether a JSON file means to be intrinsics (names 'intrinsic_matrix', or is named
    for a camera or its intrinsics and is no JSON at all: one cut short): other JSON
    files of a folder are not read as intrinsics; a malformed intrinsics file is an
    error."""
    try:
        text = path.read_text(errors="replace")
    except OSError as e:
        raise SgtoolError(f"{path}: cannot read ({e.strerror})") from e
    if "intrinsic_matrix" in text:
        return True
    if any(w in path.name.lower() for w in ("intrinsic", "camera")):
        try:
            json.loads(text)
        except ValueError:
            return True
    return False
