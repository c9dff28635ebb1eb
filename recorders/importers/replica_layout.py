"""The ``replica`` RGB-D folder layout: Replica scenes as NICE-SLAM renders them, the form
most SLAM and scene-graph work reads them in (a scene folder such as ``room0/``):

- ``results/frameNNNNNN.jpg`` (colour) and ``results/depthNNNNNN.png`` (16-bit depth in
  1/6553.5 m), paired by number;
- ``traj.txt``: a camera-to-world 4x4 matrix a line, one a frame in order (the optical
  frame's: x right, y down, z forward);
- ``cam_params.json`` beside the scene folders (or in the scene folder): ``{"camera":
  {"w", "h", "fx", "fy", "cx", "cy", "scale"}}``; without it the renders' camera
  (1200x680, fx = fy = 600, cx 599.5, cy 339.5) and depth scale 6553.5.

Frame n is at n / fps (the renders are 30 Hz sequences).
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import TYPE_CHECKING

from sgtool.errors import SgtoolError
from sgtool.recorders.importers.textformats import (
    PinholeParams,
    checked_pinhole,
    read_matrix_trajectory,
    trajectory_poses,
)

if TYPE_CHECKING:
    from sgtool.recorders.importers.layouts import FolderSequence

REPLICA_INTRINSICS = PinholeParams(600.0, 600.0, 599.5, 339.5, 1200, 680,
                                   source="dataset default: Replica as NICE-SLAM renders it")
REPLICA_DEPTH_SCALE = 6553.5  # raw units per metre
_DEPTH = re.compile(r"depth(\d+)\.png$", re.IGNORECASE)
_FRAME = re.compile(r"frame(\d+)\.(jpg|jpeg|png)$", re.IGNORECASE)


def is_replica(root: Path) -> bool:
    """Whether ``root`` holds ``results/`` with depthNNNNNN.png images (module doc)."""
    results = root / "results"
    return results.is_dir() and any(_DEPTH.match(p.name) for p in results.iterdir())


def replica_missing(root: Path) -> str | None:
    """What a folder lacks to be read as ``replica``, or None."""
    if not is_replica(root):
        return "no results/depthNNNNNN.png images"
    return None


def _camera(root: Path, intrinsics_given: bool = False, scale_given: bool = False
            ) -> tuple[PinholeParams, float, str]:
    """The intrinsics, the depth scale and where they came from: cam_params.json in the
    scene folder or beside it, else the renders' defaults. The file is not read when
    both are given (``--intrinsics``, ``--depth-scale``: they override it, broken or not);
    when one is, a file that does not read is refused naming the other flag (it holds
    both)."""
    path = next((p for p in (root / "cam_params.json", root.parent / "cam_params.json")
                 if p.is_file()), None)
    if path is None:
        return REPLICA_INTRINSICS, REPLICA_DEPTH_SCALE, "dataset default: replica layout"
    if intrinsics_given and scale_given:
        return REPLICA_INTRINSICS, REPLICA_DEPTH_SCALE, \
            f"the flags ({path.name} not read)"
    try:
        cam = json.loads(path.read_text(encoding="utf-8-sig"))["camera"]
        k = checked_pinhole(float(cam["fx"]), float(cam["fy"]), float(cam["cx"]),
                            float(cam["cy"]), str(path), width=int(cam["w"]),
                            height=int(cam["h"]), source=f"file {path.name}")
        scale = float(cam.get("scale", REPLICA_DEPTH_SCALE))
    except (json.JSONDecodeError, KeyError, TypeError, ValueError) as e:
        flag = ("--depth-scale as well" if intrinsics_given else "--intrinsics as well"
                if scale_given else "--intrinsics and --depth-scale")
        raise SgtoolError(f"{path}: expected {{\"camera\": {{\"w\", \"h\", \"fx\", \"fy\", "
                          f"\"cx\", \"cy\", \"scale\"}}}} ({type(e).__name__}: {e}); it holds "
                          f"the intrinsics and the depth scale: mend it, or give {flag} "
                          "to override it") from e
    if not scale > 0:
        raise SgtoolError(f"{path}: depth scale {scale:g}: must be positive")
    return k, scale, f"file {path.name}"


def read_replica(root: Path, fps: float, trajectory: Path | None,
                 given: tuple[bool, bool] = (False, False)) -> FolderSequence:
    """The frames of a ``replica`` folder (module doc); ``trajectory`` overrides
    ``traj.txt`` (read as ``--trajectory`` files are); ``given``: whether the intrinsics
    and the depth scale are given (:func:`_camera`)."""
    from sgtool.recorders.importers.layouts import FolderFrame, FolderSequence

    results = root / "results"
    depths = {int(m.group(1)): p for p in results.iterdir() if (m := _DEPTH.match(p.name))}
    colours = {int(m.group(1)): p for p in results.iterdir() if (m := _FRAME.match(p.name))}
    numbers = sorted(depths)
    notes = []
    gaps = [a for a, b in zip(numbers, numbers[1:], strict=False) if b != a + 1]
    if gaps:
        raise SgtoolError(f"{results}: the depth images' numbers have gaps (first after "
                          f"depth{gaps[0]:06d}.png): traj.txt poses frames by line, so a gap "
                          "would shift every later pose; give the missing images")
    no_colour = [n for n in numbers if n not in colours]
    if no_colour:
        notes.append(f"{len(no_colour)} depth images without frameNNNNNN.jpg (first: "
                     f"depth{no_colour[0]:06d}.png): imported without colour")
    traj = trajectory or (root / "traj.txt")
    if trajectory is None and not traj.is_file():
        poses = None
        notes.append("no traj.txt: the poses are estimated")
    else:
        poses = (read_matrix_trajectory(traj) if trajectory is None
                 else trajectory_poses(trajectory, len(numbers)) or [])
        if len(poses) != len(numbers):
            raise SgtoolError(f"{traj} has {len(poses)} poses for {len(numbers)} depth "
                              "images; a matrix a line names no frame: one line per frame, "
                              "in order")
        notes.append(f"poses from {traj.name}")
    k, scale, origin = _camera(root, *given)
    notes.append(f"intrinsics and depth scale {scale:g} from {origin}" if not all(given)
                 else f"intrinsics and depth scale from {origin}")
    frames = tuple(FolderFrame(round((n - numbers[0]) * 1e9 / fps), depths[n],
                               colours.get(n), None if poses is None else poses[i])
                   for i, n in enumerate(numbers))
    return FolderSequence("replica", root, frames, k, scale,
                          "none" if poses is None else
                          ("trajectory" if trajectory is not None else "ground truth"),
                          tuple(notes), scale_source=origin)
