"""The import's sanity checks on synthetic TUM folders whose faults are known: interval time
stamps, duplicated and backward times, millimetre depth read at TUM's 5000, a table taken
for the floor, files listed but missing; and the report's statement of where each
parameter came from."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from click.testing import CliRunner
from support.bag_export import BagWriter
from support.logfixtures import synthetic_frame
from support.rgbd_folders import make_tum_folder

from sgtool.cli import cli
from sgtool.errors import SgtoolError
from sgtool.log import LogReader
from sgtool.log.frame import CameraIntrinsics
from sgtool.log.records import Instances
from sgtool.recorders.importers.bag import BagOptions, import_bag
from sgtool.recorders.importers.rgbd import RgbdOptions, import_rgbd
from sgtool.recorders.importers.sanity import (
    SWAP_SMOOTHER,
    depth_scale_problem,
    floor_problem,
    id_step_notes,
    roughness,
    timestamp_problem,
)
from sgtool.recorders.importers.sink import IMPORT_METADATA
from sgtool.recorders.importers.textformats import PinholeParams, read_intrinsics_file

K = PinholeParams(60.0, 60.0, 39.5, 29.5)
GOOD_TIMES = [100.0 + i / 30 for i in range(12)]


def opts(**kw) -> RgbdOptions:  # type: ignore[no-untyped-def]
    return RgbdOptions(intrinsics=kw.pop("intrinsics", K), progress=False, **kw)


# ----- pure checks ---------------------------------------------------------------------------
def test_timestamp_problems_are_named():
    ns = [round(t * 1e9) for t in GOOD_TIMES]
    assert timestamp_problem(ns, "depth.txt") is None
    # per-frame intervals where times belong: 193 values around 0.033 s
    rng = np.random.default_rng(0)
    intervals = [round(v * 1e9) for v in rng.uniform(0.0300, 0.0316, 193)]
    p = timestamp_problem(intervals, "depth.txt")
    assert p is not None and "per-frame intervals" in p and "--timestamps index --fps N" in p
    assert "go back in time" in p
    dup = ns[:5] + ns[4:]
    assert "1 repeat a time stamp" in timestamp_problem(dup, "d")  # type: ignore[operator]
    fast = [i * 1_000_000 for i in range(50)]  # 1000 fps
    assert "~1000 fps" in timestamp_problem(fast, "d")  # type: ignore[operator]


def test_depth_scale_problem_names_the_scale_that_fits():
    mm = np.full((10, 10), 2000, np.uint16)  # 2 m in millimetres
    mm[0] = 3500
    p = depth_scale_problem([mm], 5000.0, "dataset default: tum layout")
    assert p is not None
    assert "median depth 0.40 m" in p and "--depth-scale 1000 fits (median 2.00 m)" in p
    assert depth_scale_problem([mm], 1000.0, "x") is None
    assert depth_scale_problem([mm.astype(np.float32) / 1000], 1.0, "x") is None  # metres


def test_depth_scale_problem_names_every_scale_that_fits():
    """Replica's depth as NICE-SLAM renders it (1/6553.5 m) read as millimetres: several
    usual scales give indoor depth, which the depth alone cannot tell apart; the message
    names them all (6553.5 among them), not only the likeliest, whose map was 31 % too
    large with exit 0."""
    replica = np.full((10, 10), round(1.6 * 6553.5), np.uint16)  # 1.6 m
    replica[0] = round(3.0 * 6553.5)
    p = depth_scale_problem([replica], 1000.0, "dataset default: open3d layout")
    assert p is not None
    assert "--depth-scale 5000 fits (median 2.10 m), and so do " in p
    assert "6553.5 (median 1.60 m)" in p and "the depth alone cannot tell them apart" in p
    assert p.endswith("says which is its; give it, or --depth-scale 1000 to keep this one")
    # given by the user: a warning that keeps it (as for one scale that fits)
    from sgtool.recorders.importers.provenance import Findings

    kept = Findings()
    kept.problem(p, given=True)
    assert kept.warnings[0].endswith("says which is its; the value given is kept")
    assert depth_scale_problem([replica], 6553.5, "x") is None


def test_floor_problem_band():
    cam = np.eye(4)
    cam[2, 3] = 1.0  # camera 1 m up in the source; floor estimate at 0.58 -> 0.42 m above
    a = np.eye(4)
    a[2, 3] = -0.58
    p = floor_problem([cam], a, 0.58, "estimate", (0.45, 2.2))
    assert p is not None and "0.42 m above the floor" in p and "--floor" in p
    assert "(e.g. --floor -0.30 puts the camera at 1.3 m)" in p
    assert floor_problem([cam], a, 0.58, "estimate", (0.3, 2.2)) is None


# ----- the silent-wrong cases of issue 18 on folders ------------------------------------------
def test_interval_timestamps_fail_and_index_imports(tmp_path):
    rng = np.random.default_rng(1)
    times = list(rng.uniform(0.030, 0.034, 12))
    root = make_tum_folder(tmp_path / "f", times, ground_truth=False)
    with pytest.raises(SgtoolError, match=r"per-frame intervals.*--timestamps index --fps N"):
        import_rgbd(root, tmp_path / "a.mcap", opts())
    assert not (tmp_path / "a.mcap").exists()
    rep = import_rgbd(root, tmp_path / "b.mcap",
                      opts(timestamps="index", fps=15.0, odometry="icp"))
    assert rep.frames == 12
    with LogReader(tmp_path / "b.mcap") as r:
        times_ns = r.frame_times()
    assert times_ns == [round(i * 1e9 / 15) for i in range(12)]  # listed order, n / fps


def test_millimetre_depth_at_the_tum_default_fails_and_names_1000(tmp_path):
    root = make_tum_folder(tmp_path / "f", GOOD_TIMES, units_per_m=1000.0)
    with pytest.raises(SgtoolError, match=r"depth scale 5000 units/m \(dataset default: tum "
                       r"layout\) looks wrong.*--depth-scale 1000 fits"):
        import_rgbd(root, tmp_path / "a.mcap", opts())
    rep = import_rgbd(root, tmp_path / "b.mcap", opts(depth_scale=1000.0))
    assert ("depth scale", "1000 units/m", "flag --depth-scale") in rep.sources
    assert rep.warnings == ()
    # insisting on the wrong scale is a warning, shown at once
    seen: list[str] = []
    rep = import_rgbd(root, tmp_path / "c.mcap", opts(depth_scale=5000.0, warn=seen.append,
                                                      floor=None, floor_auto=False))
    assert len(seen) == 1 and "looks wrong" in seen[0] and rep.warnings == tuple(seen)
    # a scale so wrong that the depth leaves what the log holds: one line, nothing written
    seen.clear()
    with pytest.raises(SgtoolError, match=r"^frame 0 \(t = \d+ ns\): depth beyond 65.535 m "
                       r".*; nothing written$"):
        import_rgbd(root, tmp_path / "d.mcap", opts(depth_scale=1.0, warn=seen.append,
                                                     floor=None, floor_auto=False))
    assert len(seen) == 1 and not (tmp_path / "d.mcap").exists()


def test_table_taken_for_the_floor_fails_and_names_floor(tmp_path):
    root = make_tum_folder(tmp_path / "f", GOOD_TIMES, cam_height=0.42)
    with pytest.raises(SgtoolError, match=r"camera is 0.42 m above the floor.*--floor"):
        import_rgbd(root, tmp_path / "a.mcap", opts())
    rep = import_rgbd(root, tmp_path / "b.mcap", opts(camera_height=(0.3, 2.2)))
    assert rep.frames == 12
    # the real floor given: the camera is 0.42 + 1.0 = 1.42 m above it, inside the band
    given = import_rgbd(root, tmp_path / "c.mcap", opts(floor=-1.0))
    assert ("floor", "-1.000 m in the source", "flag --floor") in given.sources
    assert given.warnings == ()
    # a given floor outside the band is the user's word: a warning, not an error
    odd = import_rgbd(root, tmp_path / "d.mcap", opts(floor=0.2))
    assert len(odd.warnings) == 1 and "camera is 0.22 m above the floor" in odd.warnings[0]


def test_missing_files_are_checked_up_front(tmp_path):
    root = make_tum_folder(tmp_path / "f", GOOD_TIMES, missing=(3, 7))
    with pytest.raises(SgtoolError, match=r"4 of the 24 files listed are missing \(2 of "
                       r"rgb.txt, 2 of depth.txt; first: rgb/0003.png\).*--skip-missing"):
        import_rgbd(root, tmp_path / "a.mcap", opts())
    rep = import_rgbd(root, tmp_path / "b.mcap", opts(skip_missing=True))
    assert rep.frames == 10
    assert "skipped 4 missing files (2 of rgb.txt, 2 of depth.txt)" in rep.notes


def test_report_says_where_each_parameter_came_from(tmp_path):
    fr1 = CameraIntrinsics(640, 480, 517.3, 516.5, 318.6, 255.3)
    root = make_tum_folder(tmp_path / "rgbd_dataset_freiburg1_fake", GOOD_TIMES[:4], k=fr1)
    out = tmp_path / "o.mcap"
    r = CliRunner().invoke(cli, ["import", "rgbd", str(root), "-o", str(out), "--quiet"])
    assert r.exit_code == 0, r.output
    lines = r.output.splitlines()
    assert ("intrinsics: 517.3,516.5,318.6,255.3 [folder-name default: 'freiburg1' in "
            "'rgbd_dataset_freiburg1_fake' (TUM freiburg1 calibration)]") in lines
    assert "depth scale: 5000 units/m [dataset default: tum layout]" in lines
    assert any(x.startswith("up: (") and "[estimate: the normals of horizontal surfaces]" in x
               for x in lines)
    assert any(x.startswith("floor: ") and "[estimate: the lowest large horizontal plane" in x
               for x in lines)
    # the folder-name default is also a warning on stderr, before the work
    assert "sgtool: warning: intrinsics taken from the folder name" in r.output
    with LogReader(out) as rd:
        meta = rd.metadata[IMPORT_METADATA]
    assert meta["depth_scale_source"] == "dataset default: tum layout"
    assert meta["floor_source"].startswith("estimate")


def test_duplicated_and_backward_times_fail(tmp_path):
    times = GOOD_TIMES[:6] + [GOOD_TIMES[5]] + GOOD_TIMES[6:]
    root = make_tum_folder(tmp_path / "dup", times)
    with pytest.raises(SgtoolError, match=r"1 repeat a time stamp.*--timestamps index"):
        import_rgbd(root, tmp_path / "a.mcap", opts())
    # times of frames listed out of order: TUM associates by time, so they are read in
    # time order (the suggestion of --timestamps index would pair by list position)
    times = GOOD_TIMES[:4] + GOOD_TIMES[5:6] + GOOD_TIMES[4:5] + GOOD_TIMES[6:]
    root = make_tum_folder(tmp_path / "back", times)
    rep = import_rgbd(root, tmp_path / "b.mcap", opts())
    assert "depth.txt lists its images out of time order (1 step back): read in time " \
        "order" in rep.notes
    with LogReader(tmp_path / "b.mcap") as r:
        stamps = r.frame_times()
    assert stamps == sorted(stamps) and len(stamps) == len(times)
    # out of order and out of a log's range (negative): the range is the problem named
    root = make_tum_folder(tmp_path / "negative", [t - 1e6 for t in times])
    with pytest.raises(SgtoolError, match=r"negative"):
        import_rgbd(root, tmp_path / "n.mcap", opts())
    # stamps that are not times even in order stay refused
    times = [0.001 * (i % 3) for i in range(12)]
    root = make_tum_folder(tmp_path / "intervals", times)
    with pytest.raises(SgtoolError, match=r"steps go back in time"):
        import_rgbd(root, tmp_path / "c.mcap", opts())


def test_bag_with_one_header_stamp_fails_and_bag_times_import(tmp_path):
    """A driver that stamps every image with the same time: the header stamps repeat; the
    bag's record times are the way out."""
    bag = tmp_path / "b"
    with BagWriter(bag, "ros2-mcap") as w:
        for i in range(5):
            k, _, depth, _, pose, _ = synthetic_frame(i)
            t = 1_000_000_000 + i * 33_333_333
            w.write("/tf", "tf2_msgs/msg/TFMessage", t,
                    w.tf(t, [w.transform_stamped(t, "map", "cam", pose)]))
            w.write("/d/info", "sensor_msgs/msg/CameraInfo", t, w.camera_info(t, "cam", k))
            w.write("/d/image", "sensor_msgs/msg/Image", t,
                    w.image(1_000_000_000, "cam", np.round(depth * 1000).astype(np.uint16),
                            "16UC1"))
    base = BagOptions(depth="/d/image", progress=False, up=np.array([0, 0, 1.0]), floor=0.0,
                      tf_frames=("map", "cam"))
    with pytest.raises(SgtoolError, match=r"4 repeat a time stamp.*--timestamps bag"):
        import_bag(bag, tmp_path / "a.mcap", base)
    rep = import_bag(bag, tmp_path / "b.mcap", replace(base, timestamps="bag"))
    assert rep.frames == 5


def test_json_report_carries_sources_and_warnings(tmp_path):
    root = make_tum_folder(tmp_path / "f", GOOD_TIMES)
    out = tmp_path / "o.mcap"
    r = CliRunner().invoke(cli, ["import", "rgbd", str(root), "-o", str(out), "--quiet",
                                 "--json", "--intrinsics", "60,60,39.5,29.5", "--floor", "1.2"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.output[r.output.index("{"):])
    assert d["sources"]["intrinsics"] == {"value": "60,60,39.5,29.5",
                                          "origin": "flag --intrinsics"}
    assert d["sources"]["floor"]["origin"] == "flag --floor"
    # the camera is 1.4 - 1.2 = 0.2 m above the given floor: a warning, in the JSON too
    assert len(d["warnings"]) == 1 and "camera is 0.20 m above the floor" in d["warnings"][0]
    assert r.output.startswith("sgtool: warning: the camera is 0.20 m above the floor")


def test_an_intrinsics_file_of_another_shape_says_what_it_should_hold(tmp_path):
    """A pose trajectory given as --intrinsics: the message shows the matrix to give, not
    numpy's advice about its own arguments."""
    bad = tmp_path / "k.txt"
    bad.write_text("0 0 1\n1 0 0 0\n0 1 0 0\n")
    with pytest.raises(SgtoolError) as err:
        read_intrinsics_file(bad)
    assert str(err.value) == (f"{bad}: expected a 3x3 camera matrix [[fx 0 cx] [0 fy cy] "
                              "[0 0 1]] (three rows of three numbers), the four numbers fx fy "
                              "cx cy, or Open3D intrinsics JSON")


def test_time_stamps_in_milliseconds_are_named_so():
    """TUM lists written in ms (10 frames over 300 "s"): the refusal says they read as
    30 fps in milliseconds, and how to keep the ground truth's poses."""
    from sgtool.recorders.importers.sanity import timestamp_problem

    ms = [int(t * 1e9) for t in (100.0 * 1000 + 33.3 * i for i in range(10))]
    text = timestamp_problem(ms, "depth.txt")
    assert text is not None and "read as milliseconds, 30 fps" in text
    assert "to keep its poses" in text
    assert timestamp_problem([int(i * 1e9 / 30) for i in range(10)], "depth.txt") is None
    slow = timestamp_problem([int(i * 300e9) for i in range(10)], "depth.txt")  # 1 per 5 min
    assert slow is not None and "milliseconds" not in slow


@pytest.mark.parametrize(("binning", "offset"), [(2, (0, 0)), (1, (100, 60)), (2, (100, 60))])
def test_a_binned_or_cropped_camera_gets_the_intrinsics_of_its_images(
        tmp_path, binning: int, offset: tuple[int, int]) -> None:
    """A driver publishing 2x2-binned images, a region of interest or both: its CameraInfo
    holds the full sensor's K and size (REP 104). The import failed ("for 128x96 images
    but the depth images are 64x48"); it gives the images' own intrinsics now."""
    bag = tmp_path / "b"
    with BagWriter(bag, "ros2-mcap") as w:
        for i in range(5):
            k, _, depth, _, pose, _ = synthetic_frame(i)
            # the full sensor: the images' pixels are binning x binning of its pixels,
            # starting at pixel offset of it
            full = CameraIntrinsics(k.width * binning + 2 * offset[0],
                                    k.height * binning + 2 * offset[1],
                                    k.fx * binning, k.fy * binning,
                                    k.cx * binning + offset[0], k.cy * binning + offset[1])
            info = w.camera_info(0, "cam", full)
            roi = replace(info.roi, x_offset=offset[0], y_offset=offset[1],
                          width=k.width * binning, height=k.height * binning) \
                if offset != (0, 0) else info.roi
            info = replace(info, binning_x=binning, binning_y=binning, roi=roi)
            t = 1_000_000_000 + i * 33_333_333
            w.write("/tf", "tf2_msgs/msg/TFMessage", t,
                    w.tf(t, [w.transform_stamped(t, "map", "cam", pose)]))
            w.write("/d/info", "sensor_msgs/msg/CameraInfo", t, info)
            w.write("/d/image", "sensor_msgs/msg/Image", t,
                    w.image(t, "cam", np.round(depth * 1000).astype(np.uint16), "16UC1"))
    opts = BagOptions(depth="/d/image", progress=False, up=np.array([0, 0, 1.0]), floor=0.0,
                      tf_frames=("map", "cam"))
    assert import_bag(bag, tmp_path / "a.mcap", opts).frames == 5
    with LogReader(tmp_path / "a.mcap") as r:
        got = next(r.frames()).intrinsics
    assert (got.width, got.height) == (k.width, k.height)
    assert (got.fx, got.fy, got.cx, got.cy) == pytest.approx((k.fx, k.fy, k.cx, k.cy))


def _floor_and_wall(h: int = 60, w: int = 80) -> np.ndarray:
    """Smooth depth in millimetres: a wall 3 m away above a floor that comes nearer row by
    row (1-3 m), with a little sensor noise."""
    rows = np.linspace(3000.0, 1000.0, h)[:, None] * np.ones((1, w))
    rows[: h // 3] = 3000.0
    noise = np.random.default_rng(0).normal(0.0, 3.0, (h, w))
    return np.round(rows + noise).astype(np.uint16)


def test_depth_in_the_other_byte_order_is_named_as_such_not_as_a_scale():
    """16-bit depth whose is_bigendian flag is wrong read as millimetres: its values spread
    over the whole 16-bit range, which one of the usual scales "fits"; the message said
    to give that scale (an outside lab's bag). Swapped back it is smooth indoor depth."""
    mm = _floor_and_wall()
    wrong = mm.byteswap()  # the bytes as a wrong flag reads them
    assert roughness([wrong]) > SWAP_SMOOTHER * roughness([mm])
    p = depth_scale_problem([wrong], 1000.0, "the encoding 16UC1")
    assert p is not None and "--depth-scale 10000 fits" not in p, p
    assert "with each value's bytes swapped it is smooth indoor depth (median 2.00 m)" in p, p
    assert "(a ROS Image's is_bigendian flag, or files written with their bytes swapped)" in p
    # depth in the right order is no problem, and a wrong scale is still named as one
    assert depth_scale_problem([mm], 1000.0, "x") is None
    p = depth_scale_problem([mm], 5000.0, "x")
    assert p is not None and "--depth-scale 1000 fits" in p and "swapped" not in p
    # a float image in the other byte order too (32FC1 metres)
    metres = (mm.astype(np.float32) / 1000).byteswap()
    p = depth_scale_problem([metres], 1.0, "x")
    assert p is not None and "bytes swapped" in p, p


def test_python_options_of_another_type_are_one_line_or_taken_as_the_flags_take_them(tmp_path):
    """import_rgbd from Python: a dict, a number as text, seconds for nanoseconds are one
    SgtoolError line naming the field (not a TypeError/AttributeError from inside); a
    trajectory as text, up as an axis or a list, floor 'auto' work as the flags do."""
    root = make_tum_folder(tmp_path / "f", GOOD_TIMES[:6])
    for bad, match in ((lambda: import_rgbd(root, tmp_path / "a.mcap", {"every": 2}),
                        r"^opts: an sgtool.RgbdOptions .*got dict$"),
                       (lambda: import_rgbd(root, tmp_path / "a.mcap", opts(every="2")),
                        r"^every='2': a whole number$"),
                       (lambda: import_rgbd(root, tmp_path / "a.mcap", opts(max_dt_ns=0.02)),
                        r"^max_dt_ns=0.02: whole nanoseconds"),
                       (lambda: import_rgbd(root, tmp_path / "a.mcap", opts(up=[0, 0, 0])),
                        r"^up=\[0, 0, 0\]: three finite numbers"),
                       (lambda: import_rgbd(root, tmp_path / "a.mcap", opts(trajectory=3)),
                        r"^trajectory: a file's path, got int$"),
                       (lambda: import_rgbd(root, tmp_path / "a.mcap",
                                            opts(trajectory="nope.txt")),
                        r"^--trajectory nope.txt: no such file$")):
        with pytest.raises(SgtoolError, match=match):
            bad()
    assert not list(tmp_path.glob("a.mcap*"))
    with pytest.raises(SgtoolError, match=r"^--every 0: must be >= 1$"):  # the flag's range
        import_rgbd(root, tmp_path / "a.mcap", opts(every=0))
    given = import_rgbd(root, tmp_path / "b.mcap", opts(
        trajectory=str(root / "groundtruth.txt"), floor="auto"))
    assert given.frames == 6
    as_axis = import_rgbd(root, tmp_path / "c.mcap", opts(up="z"))
    as_list = import_rgbd(root, tmp_path / "d.mcap", opts(up=[0, 0, 2]))
    assert as_axis.frames == as_list.frames == 6
    assert (tmp_path / "c.mcap").read_bytes() == (tmp_path / "d.mcap").read_bytes()


def test_bag_instances_given_as_a_path_or_without_depth_say_what_to_give(tmp_path):
    table = Instances.from_json({"instances": [{"id": 1, "category": "chair",
                                                "kind": "furniture"}]})
    with pytest.raises(SgtoolError, match=r"^instances: an sgtool.Instances "
                       r"\(read_instance_table\(path\).*got str$"):
        import_bag(tmp_path, tmp_path / "a.mcap", BagOptions(
            depth="/d", ids="/i", instances="table.json", progress=False))  # type: ignore[arg-type]
    with pytest.raises(SgtoolError, match=r"^--ids /i --instances: give the depth topic too"):
        import_bag(tmp_path, tmp_path / "a.mcap", BagOptions(ids="/i", instances=table,
                                                             progress=False))


@pytest.mark.parametrize("folder", ["7scenes-redkitchen-every10", "open3d-testdata",
                                    "icl-livingroom1-micro"])
def test_real_depth_in_the_other_byte_order_is_named_so(shared_data_dir, folder):
    """Real Kinect depth is quantised: most neighbouring pixels are equal in either byte
    order, so a median over all pairs is 0 both ways and the byte order went unnamed
    (the message named a depth scale that "fits" again); read right, it is never called
    swapped."""
    from sgtool.recorders.importers.images import read_depth_file
    from sgtool.recorders.importers.sanity import swapped_fit

    files = sorted(p for p in (shared_data_dir / "rgbd" / folder).rglob("*.png")
                   if "depth" in str(p.relative_to(shared_data_dir)).lower())
    raws = [read_depth_file(p) for p in files][:8]
    scale = 5000.0 if folder == "open3d-testdata" else 1000.0
    swapped = [r.byteswap() for r in raws]
    p = depth_scale_problem(swapped, scale, "the layout")
    assert p is not None and "with each value's bytes swapped" in p, p
    for k in (scale, 1000.0, 5000.0, 10000.0, 100.0):
        assert swapped_fit(raws, k) is None


def test_frame_numbers_that_step_say_what_fps_means() -> None:
    """A folder of every 10th frame of a 30 Hz recording (frame-000000, -000010, ...):
    frame n is at n / fps, so `--fps 3` (the rate of the kept frames) spread the 100
    frames over 330 s without a word; the note says the step and the span. Consecutive
    numbers say nothing; a common step of 5 among steps of 10 and 5 is named."""
    (note,) = id_step_notes(range(0, 1000, 10), 3.0)
    assert note.startswith("the frame numbers advance by 10 (every 10th frame of a "
                           "recording): frame n is at n/3 s, so --fps is the rate of the "
                           "numbering, not of these 100 frames; they span 330 s"), note
    assert id_step_notes([0, 1, 2, 3], 30.0) == [] and id_step_notes([7], 30.0) == []
    assert "advance by 5" in id_step_notes([0, 10, 15, 25], 30.0)[0]
