"""Replica scenes as NICE-SLAM renders them (results/frameNNNNNN.jpg, depthNNNNNN.png at
1/6553.5 m, traj.txt of a matrix a line, cam_params.json beside the scene): detected and
imported as the same frames in the TUM layout are, and their faults refused in one line
(sgtool.recorders.importers.replica_layout)."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest
from support.rgbd_scenes import K, look_at, make_scene_folder, render, room

from sgtool.errors import SgtoolError
from sgtool.log.reader import LogReader
from sgtool.recorders.importers.layouts import read_sequence
from sgtool.recorders.importers.rgbd import RgbdOptions, import_rgbd

POSES = [look_at((-1.0 + 0.03 * i, -0.5 + 0.01 * i, 1.4), (2.5, 1.0 - 0.03 * i, 0.5))
         for i in range(20)]


def replica_scene(root: Path, poses=POSES, cam_params: bool = True) -> Path:
    """A NICE-SLAM Replica scene folder ``root`` (its cam_params.json beside it)."""
    (root / "results").mkdir(parents=True)
    for i, pose in enumerate(poses):
        raw = np.round(render(room(), pose, K) * 6553.5).clip(0, 65535).astype(np.uint16)
        cv2.imwrite(str(root / "results" / f"depth{i:06d}.png"), raw)
        cv2.imwrite(str(root / "results" / f"frame{i:06d}.jpg"),
                    np.full((K.height, K.width, 3), 90, np.uint8))
    (root / "traj.txt").write_text("".join(" ".join(f"{x:.9f}" for x in p.ravel()) + "\n"
                                           for p in poses))
    if cam_params:
        (root.parent / "cam_params.json").write_text(json.dumps({"camera": {
            "w": K.width, "h": K.height, "fx": K.fx, "fy": K.fy, "cx": K.cx, "cy": K.cy,
            "scale": 6553.5}}))
    return root


def test_a_replica_scene_imports_as_its_tum_twin(tmp_path) -> None:
    root = replica_scene(tmp_path / "Replica" / "room0")
    seq = read_sequence(root)
    assert seq.layout == "replica" and seq.depth_scale == 6553.5
    assert (seq.intrinsics.fx, seq.intrinsics.width) == (K.fx, K.width)
    assert "intrinsics and depth scale 6553.5 from file cam_params.json" in seq.notes
    rep = import_rgbd(root, tmp_path / "r.mcap", RgbdOptions(progress=False))
    assert rep.frames == 20 and any(line.startswith("depth scale: 6553.5 units/m [file "
                                                    "cam_params.json]") for line in rep.lines())
    assert dict(rep.checks)["depth scale against the poses"].startswith("depth moves 1.0")
    twin = make_scene_folder(tmp_path / "tum", room(), POSES)
    intr = f"{K.fx},{K.fy},{K.cx},{K.cy}"
    from sgtool.recorders.importers.textformats import parse_intrinsics

    import_rgbd(twin, tmp_path / "t.mcap", RgbdOptions(progress=False,
                                                       intrinsics=parse_intrinsics(intr)))
    with LogReader(tmp_path / "r.mcap") as a, LogReader(tmp_path / "t.mcap") as b:
        for fa, fb in zip(a.frames(), b.frames(), strict=True):
            assert np.allclose(fa.pose, fb.pose, atol=2e-3)


def test_a_replica_scene_without_cam_params_takes_the_renders_camera(tmp_path) -> None:
    """Without cam_params.json, the renders' own camera (1200x680): images of another size
    are refused by the import's intrinsics check, naming --intrinsics."""
    root = replica_scene(tmp_path / "room0", cam_params=False)
    seq = read_sequence(root)
    assert (seq.intrinsics.fx, seq.intrinsics.width, seq.intrinsics.height) == (600.0, 1200,
                                                                                 680)
    with pytest.raises(SgtoolError, match="--intrinsics"):
        import_rgbd(root, tmp_path / "r.mcap", RgbdOptions(progress=False))


def test_the_replica_folder_of_scenes_names_them(tmp_path) -> None:
    """The download's top folder (scenes beside cam_params.json): the refusal names the
    scene folders to import."""
    replica_scene(tmp_path / "Replica" / "room0", poses=POSES[:3])
    replica_scene(tmp_path / "Replica" / "office0", poses=POSES[:3])
    with pytest.raises(SgtoolError, match=r"it has sequence folders office0, room0: import one "
                       r"of them"):
        read_sequence(tmp_path / "Replica")


def test_a_replica_scene_s_faults_are_one_line(tmp_path) -> None:
    root = replica_scene(tmp_path / "Replica" / "room0", poses=POSES[:6])
    (root / "results" / "depth000003.png").unlink()
    with pytest.raises(SgtoolError, match=r"numbers have gaps \(first after depth000002\.png\)"):
        read_sequence(root)
    cv2.imwrite(str(root / "results" / "depth000003.png"), np.zeros((4, 4), np.uint16))
    lines = (root / "traj.txt").read_text().splitlines()
    (root / "traj.txt").write_text("\n".join(lines[:5]) + "\n")
    with pytest.raises(SgtoolError, match=r"traj\.txt has 5 poses for 6 depth images"):
        read_sequence(root)
    (root / "traj.txt").unlink()
    seq = read_sequence(root)
    assert seq.pose_source == "none" and "no traj.txt: the poses are estimated" in seq.notes
    (root / "results" / "frame000004.jpg").unlink()
    assert any(n.startswith("1 depth images without frameNNNNNN.jpg (first: depth000004")
               for n in read_sequence(root).notes)


def test_a_broken_cam_params_gives_way_to_both_flags(tmp_path) -> None:
    """A cam_params.json that does not read (no "scale"-bearing camera block) blocked the
    import even with --intrinsics (an outside lab's report): it holds the depth scale too,
    so --intrinsics alone is refused naming --depth-scale, and the two flags together
    import without reading it."""
    from sgtool.recorders.importers.textformats import parse_intrinsics

    root = replica_scene(tmp_path / "Replica" / "room0")
    (root.parent / "cam_params.json").write_text('{"camera": {"w": 80,')  # cut short
    with pytest.raises(SgtoolError, match=r"mend it, or give --intrinsics and --depth-scale "
                       r"to override it"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(progress=False))
    intr = parse_intrinsics(f"{K.fx},{K.fy},{K.cx},{K.cy}")
    with pytest.raises(SgtoolError, match=r"give --depth-scale as well to override it"):
        import_rgbd(root, tmp_path / "b.mcap", RgbdOptions(progress=False, intrinsics=intr))
    assert not (tmp_path / "b.mcap").exists()
    rep = import_rgbd(root, tmp_path / "c.mcap", RgbdOptions(
        progress=False, intrinsics=intr, depth_scale=6553.5))
    assert rep.frames == 20
    assert "intrinsics and depth scale from the flags (cam_params.json not read)" in \
        read_sequence(root, intrinsics_given=True, depth_scale_given=True).notes
