"""Seeded sensor faults on synthetic frames: depth noise growing with z^2, holes, label
swaps and dropouts (structure exempt), odometry drift, profile parsing."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from sgtool.errors import SgtoolError
from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.recorders.sim.camera import base_T_camera, se2_matrix
from sgtool.recorders.sim.noise import (
    PROFILES,
    NoiseProfile,
    SensorFaults,
    names_file,
    parse_noise,
)

K = CameraIntrinsics.from_fov(200, 100, 60.0)
CAM = base_T_camera(1.2, 15.0)


def _frame(i: int = 0, z: float = 2.0, ids: np.ndarray | None = None,
           base: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> Frame:
    depth = np.full((100, 200), z, np.float32)
    depth[:, :10] = 0.0  # no return
    if ids is None:
        ids = np.zeros((100, 200), np.int32)
        ids[:, :50] = 1  # floor (structure)
        ids[:, 50:100] = 20
        ids[:, 100:150] = 21
        ids[:, 150:] = 22
    b = se2_matrix(*base)
    return Frame(i, i * 100_000_000, None, depth, ids, b @ CAM, K, b)


def test_clean_profile_is_the_identity() -> None:
    f = _frame()
    assert SensorFaults(PROFILES["none"], 0).apply(f) is f


def test_depth_noise_grows_with_z_squared_and_holes_have_their_rate() -> None:
    p = NoiseProfile("t", depth_sigma=0.004, holes=0.1)
    for z in (1.0, 3.0):
        f = _frame(z=z)
        g = SensorFaults(p, 7).apply(f)
        assert np.all(g.depth[:, :10] == 0.0)  # no return stays no return
        valid = g.depth[:, 10:]
        holes = valid == 0
        assert abs(holes.mean() - 0.1) < 0.01
        err = valid[~holes] - z
        assert abs(err.mean()) < 0.004 * z * z * 0.05
        assert math.isclose(err.std(), 0.004 * z * z, rel_tol=0.05)
        assert f.depth[0, 20] == z  # the input is not modified


def test_label_dropout_and_swaps_touch_objects_not_structure() -> None:
    f = _frame()
    drop = SensorFaults(NoiseProfile("d", label_dropout=1.0), 1, structure_ids=[1]).apply(f)
    assert set(np.unique(drop.ids).tolist()) == {0, 1}
    assert np.array_equal(drop.ids[:, :50], f.ids[:, :50])

    swap = SensorFaults(NoiseProfile("s", label_swap=1.0), 1, structure_ids=[1]).apply(f)
    assert np.array_equal(swap.ids[:, :50], f.ids[:, :50])
    ids = {int(swap.ids[0, c]) for c in (60, 110, 160)}
    assert ids == {20, 21, 22}  # still the same ids, regions permuted...
    moved = [int(swap.ids[0, c]) != int(f.ids[0, c]) for c in (60, 110, 160)]
    assert sum(moved) == 2  # ...one pair of three exchanged

    rates = NoiseProfile("r", label_dropout=0.3)
    faults = SensorFaults(rates, 3, structure_ids=[1])
    dropped = [len({20, 21, 22} & set(np.unique(faults.apply(_frame(i)).ids).tolist())) < 3
               for i in range(400)]
    # P(at least one of three objects dropped) = 1 - 0.7^3 = 0.657
    assert abs(np.mean(dropped) - 0.657) < 0.06


def test_drift_follows_odometry_and_is_seeded() -> None:
    """Driving 10 m straight in 0.05 m steps: no drift -> the true pose; with drift_xy the
    lateral error is a random walk of std drift_xy * sqrt(10 m), and the same in 0.5 m
    steps (errors of std drift_xy * |d| a frame made it sqrt(10) times smaller at 0.05
    m than at 0.5 m)."""
    def run(p: NoiseProfile, seed: int, step: float = 0.05) -> np.ndarray:
        faults = SensorFaults(p, seed, base_T_camera=CAM)
        out = []
        for i in range(round(10 / step) + 1):
            f = faults.apply(_frame(i, base=(step * i, 0.0, 0.0)))
            out.append(f.base_pose.copy())
            assert np.allclose(np.linalg.inv(f.base_pose) @ f.pose, CAM)
        return np.array(out)

    clean = run(NoiseProfile("z", holes=1e-9), 0)  # a non-clean profile without drift
    assert np.allclose(clean[-1][:2, 3], [10.0, 0.0])
    p = NoiseProfile("d", drift_xy=0.02)
    a, b, c = run(p, 1), run(p, 1), run(p, 2)
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    # lateral: 200 steps of std 0.02 * sqrt(0.05) -> std 0.02 * sqrt(10) = 0.063; as many
    # runs in 20 steps of 0.5 m: the same
    for step in (0.05, 0.5):
        ends = np.array([run(p, s, step)[-1][1, 3] for s in range(60)])
        assert 0.045 < ends.std() < 0.085, (step, ends.std())
    assert np.allclose(a[0], clean[0])  # the first frame is the true pose


def test_heading_drift_on_the_spot_does_not_depend_on_the_frame_rate() -> None:
    """Turning on the spot through 2 pi rad in steps of pi/8 or of pi/80: the heading's
    error is a random walk of std drift_yaw * sqrt(2 pi) either way (errors of std
    drift_yaw * |dyaw| a frame made it sqrt(10) times smaller in the smaller steps)."""
    p = NoiseProfile("d", drift_yaw=0.02)

    def end_yaw(seed: int, steps: int) -> float:
        faults = SensorFaults(p, seed, base_T_camera=CAM)
        for i in range(steps + 1):
            yaw = 2 * np.pi * i / steps
            b = faults.apply(_frame(i, base=(0.0, 0.0, yaw))).base_pose
        err = np.arctan2(b[1, 0], b[0, 0])  # the true end heading is 2 pi = 0
        return float(np.arctan2(np.sin(err), np.cos(err)))

    want = 0.02 * np.sqrt(2 * np.pi)  # 0.050 rad
    for steps in (16, 160):
        ends = np.array([end_yaw(s, steps) for s in range(60)])
        assert 0.7 * want < ends.std() < 1.3 * want, (steps, ends.std())


def test_drift_keeps_a_tilted_head_link() -> None:
    """The mounting given to the faults is the untilted one; a frame whose camera is on a
    tilted head keeps that frame's base -> camera link under drift."""
    faults = SensorFaults(NoiseProfile("d", drift_xy=0.02), 3, base_T_camera=CAM)
    tilted = base_T_camera(1.2, 50.0)
    for i in range(20):
        f = _frame(i, base=(0.05 * i, 0.0, 0.0))
        if i % 2:
            f = replace(f, pose=f.base_pose @ tilted)
        g = faults.apply(f)
        assert np.allclose(np.linalg.inv(g.base_pose) @ g.pose, tilted if i % 2 else CAM)


def test_fault_streams_are_independent() -> None:
    """Adding depth holes does not change which labels get dropped."""
    p1 = NoiseProfile("a", label_dropout=0.5)
    p2 = replace(p1, holes=0.2)
    f1, f2 = SensorFaults(p1, 9, [1]), SensorFaults(p2, 9, [1])
    for i in range(20):
        assert np.array_equal(f1.apply(_frame(i)).ids, f2.apply(_frame(i)).ids)


def test_parse_noise(tmp_path: Path) -> None:
    assert parse_noise(None) == PROFILES["none"] == parse_noise("none")
    odd = tmp_path / "odd.json"  # a profile that is no name: one line, not a TypeError
    odd.write_text('{"profile": ["mild"]}')
    with pytest.raises(SgtoolError, match="unknown profile"):
        parse_noise(str(odd))
    assert parse_noise("mild") == PROFILES["mild"]
    p = parse_noise("strong,holes=0.2,drift_xy=0")
    assert (p.holes, p.drift_xy, p.label_swap) == (0.2, 0.0, PROFILES["strong"].label_swap)
    assert parse_noise("holes=0.05").depth_sigma == 0.0
    f = tmp_path / "faults.json"
    f.write_text(json.dumps({"profile": "mild", "label_swap": 0.5}))
    q = parse_noise(str(f))
    assert (q.name, q.label_swap, q.holes) == ("faults", 0.5, PROFILES["mild"].holes)
    with pytest.raises(SgtoolError, match="unknown profile 'loud'"):
        parse_noise("loud")
    with pytest.raises(SgtoolError, match="unknown field 'hole'"):
        parse_noise("hole=0.1")
    with pytest.raises(SgtoolError, match="at most 1"):
        parse_noise("holes=2")
    with pytest.raises(SgtoolError, match="not a number"):
        parse_noise("holes=lots")
    (tmp_path / "bad.json").write_text("[1, 2]")
    with pytest.raises(SgtoolError, match="JSON object"):
        parse_noise(str(tmp_path / "bad.json"))
    with pytest.raises(SgtoolError, match="holes is given twice"):
        parse_noise("mild,holes=0.1,holes=0.2")  # not the last one silently
    (tmp_path / "twice.json").write_text('{"holes": 0.1, "holes": 0.9}')
    with pytest.raises(SgtoolError, match=r"twice.json: holes is given twice"):
        parse_noise(str(tmp_path / "twice.json"))  # a file as the text: the same rule
    for empty in ("", "  "):  # an empty --noise is a mistake, not a perfect sensor
        with pytest.raises(SgtoolError, match="empty"):
            parse_noise(empty)
    assert names_file(str(f)) and names_file("nj/my.json") and not names_file("mild,holes=1")


def test_flying_pixels_mix_the_two_sides_of_depth_edges() -> None:
    f = _frame(z=4.0)
    depth = f.depth.copy()
    depth[20:80, 60:120] = 2.0  # a box 2 m away before a wall at 4 m
    f = replace(f, depth=depth)
    p = NoiseProfile("t", flying=0.5)
    g = SensorFaults(p, 5).apply(f)
    changed = g.depth != depth
    edge = np.zeros_like(changed)
    edge[19:81, 59:121] = True
    edge[21:79, 61:119] = False  # the pixels either side of the box's outline
    edge[:, :11] = False  # the no-return band's edge is no depth edge
    assert not (changed & ~edge).any()  # only edge pixels, and about half of them
    assert abs(changed[edge].mean() - 0.5) < 0.08
    assert np.all((g.depth[changed] > 2.0) & (g.depth[changed] < 4.0))  # between the two
    assert np.array_equal(SensorFaults(p, 5).apply(f).depth, g.depth)  # seeded
    assert parse_noise("flying=0.5") == replace(p, name="flying=0.5")
    with pytest.raises(SgtoolError, match="flying=1.5: a probability"):
        parse_noise("flying=1.5")


def test_flying_pixels_leave_the_other_faults_as_they_were() -> None:
    """Adding mixed pixels moves only edge pixels: the depth noise elsewhere and the
    holes are the same draws."""
    p1 = NoiseProfile("a", depth_sigma=0.004, holes=0.1)
    p2 = replace(p1, flying=1.0)
    f = _frame(z=3.0)
    depth = f.depth.copy()
    depth[40:60, 100:140] = 1.5
    f = replace(f, depth=depth)
    a, b = SensorFaults(p1, 2).apply(f).depth, SensorFaults(p2, 2).apply(f).depth
    inner = np.zeros(a.shape, dtype=bool)
    inner[:, 12:] = True
    inner[38:62, 98:142] = False
    assert np.array_equal(a[inner], b[inner]) and not np.array_equal(a, b)


def test_a_file_named_like_a_profile_does_not_take_its_place(tmp_path: Path,
                                                               monkeypatch) -> None:
    """A file called none, mild or strong in the current folder (notes, a transcript
    written as `transcript=none`) leaves the profile of that name as it is; ./NAME reads
    the file."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "none").write_text("some notes\n")
    (tmp_path / "mild").write_text("{}")
    assert parse_noise("none") == PROFILES["none"] and parse_noise(None) == PROFILES["none"]
    assert parse_noise("mild") == PROFILES["mild"]
    assert not names_file("mild") and names_file("./mild")
    assert parse_noise("./mild").holes == 0.0  # the file: no fault given
    with pytest.raises(SgtoolError, match="not valid JSON"):
        parse_noise("./none")


def test_a_profile_of_ones_own_cannot_take_a_built_in_name(tmp_path: Path) -> None:
    """A JSON profile named (or whose file is named) mild with other faults would be
    labelled and pooled as mild: one line; the same faults under the name pass."""
    for text, name in (('{"name": "mild", "holes": 0.3}', "x.json"),
                       ('{"holes": 0.3}', "strong.json")):
        f = tmp_path / name
        f.write_text(text)
        how = "its \"name\"" if "name" in text else "the file's name"
        with pytest.raises(SgtoolError, match=f"\\({how}\\), a built-in profile, with other"):
            parse_noise(str(f))
    same = tmp_path / "same.json"
    same.write_text(json.dumps({"profile": "mild", "name": "mild",
                                "holes": PROFILES["mild"].holes}))
    assert parse_noise(str(same)) == PROFILES["mild"]


def test_a_profile_made_in_python_cannot_take_a_built_in_name() -> None:
    """`NoiseProfile("mild", holes=0.3)` would be labelled and pooled as mild: one line;
    the built-in faults under the name, or another name, pass."""
    with pytest.raises(SgtoolError, match=r"NoiseProfile\('mild', ...\): a built-in"):
        NoiseProfile("mild", holes=0.3)
    with pytest.raises(SgtoolError, match="a built-in profile's name"):
        NoiseProfile(" none ", holes=0.01)
    with pytest.raises(SgtoolError, match="NoiseProfile name"):
        NoiseProfile(3)  # type: ignore[arg-type]
    assert NoiseProfile("mild", **{k: v for k, v in PROFILES["mild"].to_dict().items()
                                   if k != "name"}) == PROFILES["mild"]
    assert NoiseProfile("mine", holes=0.3).holes == 0.3


def test_a_profiles_name_must_name_a_folder_and_the_text_form_takes_it(tmp_path: Path) -> None:
    """A profile's name is its run-bench log folder (logs/NAME/): an empty one or one with
    a / was taken (an outside lab's JSON), and `--noise mild,name=x` said "name='x' is not
    a number" while the JSON form takes a name."""
    for name in ("", "  ", "a/b", "..", "x\\y"):
        f = tmp_path / "p.json"
        f.write_text(json.dumps({"name": name, "holes": 0.1}))
        with pytest.raises(SgtoolError, match=r"name .*: a profile's name names its log "
                           r"folder \(run-bench's logs/NAME/\)"):
            parse_noise(str(f))
    with pytest.raises(SgtoolError, match=r"name 'a/b': a profile's name names its log"):
        parse_noise("mild,holes=0.1,name=a/b")
    p = parse_noise("mild,holes=0.1,name=mine")
    assert p.name == "mine" and p.holes == 0.1
    assert parse_noise("holes=0.1,name=mine") == replace(PROFILES["none"], holes=0.1,
                                                         name="mine")
