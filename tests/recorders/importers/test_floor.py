"""The floor from the whole scene: the lowest large horizontal plane with a confidence. A desk
seen from 0.5 m above it (the floor out of view: inside the camera-height band, so it used to
pass), and a scene without any horizontal surface (the "all-points" fallback, silently
accepted before), are one-line errors naming --floor, also before odometry runs; a real
floor in view is accepted, and a given --floor is the user's word."""

from __future__ import annotations

from pathlib import Path

import pytest
from support.rgbd_scenes import Rect, look_at, make_scene_folder, room

from sgtool.errors import SgtoolError
from sgtool.recorders.importers.rgbd import RgbdOptions, import_rgbd
from sgtool.recorders.importers.textformats import PinholeParams

K = PinholeParams(60.0, 60.0, 39.5, 29.5)
DESK = Rect(2, 0.75, (0.25, -1.6), (1.1, 1.6))  # a desk top 0.75 m up, wider than the view


def opts(**kw) -> RgbdOptions:  # type: ignore[no-untyped-def]
    return RgbdOptions(intrinsics=K, progress=False, **kw)


def desk_folder(root: Path, with_desk: bool = True) -> Path:
    """12 frames of a camera 1.25 m up (0.5 m above the desk) looking down at the desk,
    sliding 1 cm a frame; without the desk, the floor 1.25 m below is in view."""
    scene = room() + ([DESK] if with_desk else [])
    poses = [look_at((0.0, 0.01 * i, 1.25), (1.0, 0.01 * i, 0.8)) for i in range(12)]
    return make_scene_folder(root, scene, poses)


def test_a_desk_is_not_taken_for_the_floor(tmp_path):
    root = desk_folder(tmp_path / "desk")
    with pytest.raises(SgtoolError, match=r"the floor is not clear in the sampled depth frames "
                       r"\(estimate at 0.750 m .*camera 0.50 m above it\).*--floor"):
        import_rgbd(root, tmp_path / "a.mcap", opts())
    assert not (tmp_path / "a.mcap").exists()
    # the floor given: imported, the camera 1.25 m above it
    rep = import_rgbd(root, tmp_path / "b.mcap", opts(floor=0.0))
    assert rep.alignment.floor_method == "given" and rep.warnings == ()


def test_the_floor_in_view_is_found_with_confidence(tmp_path):
    rep = import_rgbd(desk_folder(tmp_path / "room", with_desk=False), tmp_path / "a.mcap",
                      opts())
    a = rep.alignment
    assert a.floor_method == "horizontal-plane"
    assert abs(a.floor) < 0.005 and a.floor_confidence >= 0.9
    # the report says what the floor and the scale checks found
    checks = dict(rep.checks)
    assert checks["floor"].startswith("confidence 1.00: ")
    assert "camera 1.25 m above it" in checks["floor"]
    # a camera sliding sideways past walls it faces: nothing to judge the scale by
    assert checks["depth scale against the poses"] == ("no verdict: no frame pair pins the "
                                                       "motion down")
    assert any(line.startswith("check: floor: confidence") for line in rep.lines())


def test_no_horizontal_surface_is_an_error_not_a_fallback(tmp_path):
    wall = [Rect(0, 1.0, (-9.0, -9.0), (9.0, 9.0))]
    poses = [look_at((0.0, 0.01 * i, 1.25), (1.0, 0.01 * i, 1.35)) for i in range(12)]
    root = make_scene_folder(tmp_path / "wall", wall, poses)
    with pytest.raises(SgtoolError, match=r"no horizontal surface in the sampled frames.*"
                       r"--floor"):
        import_rgbd(root, tmp_path / "a.mcap", opts())
    rep = import_rgbd(root, tmp_path / "b.mcap", opts(floor=0.0))
    assert rep.frames == 12


def test_the_desk_is_refused_before_odometry(tmp_path, monkeypatch):
    """With poses to estimate, the floor of each sampled frame is checked first: the error
    comes without a single odometry step."""
    import sgtool.recorders.importers.rgbd as rgbd

    def no_odometry(*a, **kw):  # type: ignore[no-untyped-def]
        raise AssertionError("odometry ran before the floor check")

    monkeypatch.setattr(rgbd, "estimate_with_progress", no_odometry)
    root = desk_folder(tmp_path / "desk")
    with pytest.raises(SgtoolError, match=r"the floor is not clear in any of the 8 sampled depth "
                       r"frames.*poses are to be estimated.*--floor"):
        import_rgbd(root, tmp_path / "a.mcap", opts(estimate_poses=True))
