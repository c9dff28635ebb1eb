"""The focal length checked against metric poses: intrinsics a quarter off stretch the
map sideways, and the surfaces two turned views share then do not meet. A synthetic room
rendered with fx = fy = 60 and imported as 45 (or 80) names the focal length that fits;
the true one passes; the ICL sequence with a wrong intrinsics file is refused."""

from __future__ import annotations

import dataclasses
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from support.rgbd_scenes import K as TRUE_K
from support.rgbd_scenes import look_at, make_scene_folder, render, room

from sgtool.errors import SgtoolError
from sgtool.recorders.importers.focal_check import (
    FocalFit,
    fit_focal,
    focal_problem,
    turn_pairs,
)
from sgtool.recorders.importers.rgbd import RgbdOptions, import_rgbd
from sgtool.recorders.importers.textformats import PinholeParams

# 30 frames walking 1 cm and turning about 1.2 degrees a frame in a 5 x 4 m room
POSES = [look_at((-1.0 + 0.01 * i, -0.5, 1.4), (2.5, 1.5 - 0.075 * i, 0.6)) for i in range(30)]


def _pairs(k_seen=TRUE_K):  # type: ignore[no-untyped-def]
    depths = [render(room(), p, k_seen) for p in POSES]
    return [(depths[i], depths[j], POSES[i], POSES[j]) for i, j in turn_pairs(POSES)]


def test_turned_pairs_spread_over_the_sequence() -> None:
    got = turn_pairs(POSES)
    assert len(got) >= 3
    assert all(j - i in range(2, 6) for i, j in got)  # 3 degrees: two to five frames on
    assert got[0][0] == 0 and got[-1][0] > 10
    assert turn_pairs(POSES[:1]) == [] and turn_pairs([POSES[0]] * 10) == []


@pytest.mark.parametrize(("fx", "factor"), [(45.0, 60 / 45), (80.0, 60 / 80)])
def test_a_wrong_focal_length_names_the_one_that_fits(fx: float, factor: float) -> None:
    given = dataclasses.replace(TRUE_K, fx=fx, fy=fx)
    fit = fit_focal(_pairs(), given)
    assert fit is not None and fit.pairs >= 3 and fit.agree == fit.pairs
    assert abs(fit.factor / factor - 1.0) < 0.07
    assert fit.given_mm > 3 * fit.gap_mm
    text = focal_problem(fit, given, "flag --intrinsics")
    assert text is not None and text.startswith(
        f"intrinsics (flag --intrinsics): the focal length looks {fit.factor:.2f}x too "
        f"{'short' if factor > 1 else 'long'}")
    assert f"fx, fy {fx * fit.factor:.0f}" in text


def test_the_true_focal_length_passes() -> None:
    fit = fit_focal(_pairs(), TRUE_K)
    assert fit is not None and fit.factor == 1.0 and fit.agree == 0
    assert focal_problem(fit, TRUE_K, "x") is None


def test_only_a_clear_consistent_disagreement_counts() -> None:
    clear = FocalFit(1.3, 6, 1.0, 6.0, 6)
    assert focal_problem(clear, TRUE_K, "x") is not None
    for fit in (None, dataclasses.replace(clear, factor=1.08),  # within 10 %
                dataclasses.replace(clear, given_mm=2.0),  # not 2.5x the best gap
                dataclasses.replace(clear, agree=4),  # pairs disagree
                dataclasses.replace(clear, pairs=2, agree=2)):  # too few pairs
        assert focal_problem(fit, TRUE_K, "x") is None


def test_an_import_with_wrong_intrinsics_warns_and_the_right_ones_pass(tmp_path: Path) -> None:
    root = make_scene_folder(tmp_path / "f", room(), POSES)
    right = PinholeParams(TRUE_K.fx, TRUE_K.fy, TRUE_K.cx, TRUE_K.cy)
    rep = import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=right, progress=False))
    assert rep.warnings == ()
    assert dict(rep.checks)["focal length against the poses"].startswith(
        "surfaces of 6 turned frame pairs meet best at 1.00x the focal length")
    wrong = dataclasses.replace(right, fx=45.0, fy=45.0)
    rep = import_rgbd(root, tmp_path / "b.mcap", RgbdOptions(intrinsics=wrong, progress=False))
    assert [w for w in rep.warnings if "focal length looks 1.3" in w], rep.warnings


@pytest.fixture
def rgbd_data(shared_data_dir: Path) -> Path:
    return shared_data_dir / "rgbd"


def test_a_wrong_intrinsics_file_is_refused_before_any_work(rgbd_data: Path,
                                                           tmp_path: Path) -> None:
    """The ICL folder's PrimeSense file edited to fx = fy = 400 (the camera's is 525)."""
    folder = tmp_path / "icl"
    shutil.copytree(rgbd_data / "icl-livingroom1-micro", folder)
    cam = folder / "camera_primesense.json"
    data = json.loads(cam.read_text())
    m = np.asarray(data["intrinsic_matrix"], float)
    m[0] = m[4] = 400.0  # column-major: fx, then fy
    data["intrinsic_matrix"] = m.tolist()
    cam.write_text(json.dumps(data))
    with pytest.raises(SgtoolError, match=r"intrinsics \(file camera_primesense.json\): the "
                       r"focal length looks 1\.3\dx too short: .* fx, fy 5[23]\d"):
        import_rgbd(folder, tmp_path / "i.mcap", RgbdOptions(progress=False, every=3))
    assert not (tmp_path / "i.mcap").exists()


def test_depth_stored_along_each_ray_is_named(tmp_path: Path) -> None:
    """Depth stored as each pixel's distance along its ray (as renderers and ICL-NUIM's raw
    files do): every check passed (the scale 1.0x, the focal length's best gap not 2.5x
    below) and the map bent. Read back along the optical axis the surfaces meet."""
    import cv2

    from sgtool.recorders.importers.focal_check import along_axis

    root = make_scene_folder(tmp_path / "f", room(), POSES)
    for png in sorted((root / "depth").glob("*.png")):
        z = cv2.imread(str(png), cv2.IMREAD_UNCHANGED).astype(float)
        ray = z / along_axis(np.ones_like(z), TRUE_K)  # z * sqrt(1 + x^2 + y^2)
        cv2.imwrite(str(png), np.round(ray).astype(np.uint16))
    right = PinholeParams(TRUE_K.fx, TRUE_K.fy, TRUE_K.cx, TRUE_K.cy)
    rep = import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=right, progress=False))
    (w,) = [w for w in rep.warnings if "distance along its ray" in w]
    assert w.startswith("depth (the depth images) looks like each pixel's distance along its "
                        "ray, not the depth along the optical axis")
    assert "intrinsics" not in " ".join(rep.warnings)  # not blamed on the focal length


def test_review_cases_of_the_checks_order(tmp_path: Path) -> None:
    """Found in review: depth along each ray and 0.7x its scale gave the ray warning alone
    (exit 0; the scale error was skipped); a camera that only pans (no nearby pair for the
    scale) dropped a clear focal problem."""
    import cv2

    from sgtool.recorders.importers.focal_check import along_axis

    right = PinholeParams(TRUE_K.fx, TRUE_K.fy, TRUE_K.cx, TRUE_K.cy)
    root = make_scene_folder(tmp_path / "ray", room(), POSES, units_per_m=3500.0)
    for png in sorted((root / "depth").glob("*.png")):
        z = cv2.imread(str(png), cv2.IMREAD_UNCHANGED).astype(float)
        cv2.imwrite(str(png), np.round(z / along_axis(np.ones_like(z), TRUE_K))
                    .astype(np.uint16))
    with pytest.raises(SgtoolError, match=r"depth scale 5000 units/m .* disagrees"):
        import_rgbd(root, tmp_path / "a.mcap", RgbdOptions(intrinsics=right, progress=False))
    pan = [look_at((0.0, 0.0, 1.4), (2.0 * np.cos(a), 2.0 * np.sin(a), 0.8))
           for a in np.radians(np.arange(-40.0, 40.0, 2.0))]
    root = make_scene_folder(tmp_path / "pan", room(), pan)
    wrong = dataclasses.replace(right, fx=45.0, fy=45.0)
    rep = import_rgbd(root, tmp_path / "b.mcap", RgbdOptions(intrinsics=wrong, progress=False,
                                                             floor=0.0))
    assert [w for w in rep.warnings if "the focal length looks 1.3" in w], rep.warnings
