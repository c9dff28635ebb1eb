"""Image stamps against /tf: images stamped 0.25 s later than the instant their /tf describes
(the bag recorded both at the true times) took the poses of 0.25 s later without a word;
now the bag's record times show it, and the error names --time-offset with the shift that
fits and --timestamps bag. A camera's ordinary latency (images recorded after their stamps)
is not a clock error."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from support.bag_export import BagWriter
from support.logfixtures import synthetic_frame

from sgtool.cli import cli
from sgtool.errors import SgtoolError
from sgtool.recorders.importers.bag import BagOptions, import_bag
from sgtool.recorders.importers.sanity import clock_offset_s, clock_problem

T0 = 1_700_000_000_000_000_000
DT = 100_000_000
DEPTH, INFO = "/camera/depth/image_raw", "/camera/depth/camera_info"
KEEP_WORLD = dict(up=np.array([0.0, 0.0, 1.0]), floor_auto=False, progress=False)


def write_bag(path: Path, n: int = 10, *, stamp_shift_ns: int = 0,
              latency_ns: int = 0) -> Path:
    """``n`` synthetic frames: /tf stamped and recorded at the true times; depth recorded
    ``latency_ns`` after the true time and stamped ``stamp_shift_ns`` after it."""
    with BagWriter(path, "ros1") as w:
        for i in range(n):
            k, _, depth, _, pose, _ = synthetic_frame(i)
            t = T0 + i * DT
            w.write("/tf", "tf2_msgs/msg/TFMessage", t,
                    w.tf(t, [w.transform_stamped(t, "world", "cam", pose)]))
            w.write(INFO, "sensor_msgs/msg/CameraInfo", t, w.camera_info(t, "cam", k))
            w.write(DEPTH, "sensor_msgs/msg/Image", t + latency_ns,
                    w.image(t + stamp_shift_ns, "cam",
                            (depth * 1000).round().astype(np.uint16), "16UC1"))
    return path


def test_images_stamped_after_their_tf_are_refused_naming_the_fixes(tmp_path):
    bag = write_bag(tmp_path / "b.bag", stamp_shift_ns=250_000_000)
    with pytest.raises(SgtoolError, match=r"the image stamps are 0.250 s later than the times "
                       r"the bag recorded them.*--time-offset -0.250.*--timestamps bag"):
        import_bag(bag, tmp_path / "a.mcap", BagOptions(depth=DEPTH, info=INFO, **KEEP_WORLD))
    assert not (tmp_path / "a.mcap").exists()
    # either fix imports every frame with the true poses
    for extra in (dict(timestamps="bag"), dict(time_offset_ns=-250_000_000)):
        rep = import_bag(bag, tmp_path / "b.mcap", BagOptions(depth=DEPTH, info=INFO,
                                                              **extra, **KEEP_WORLD))
        assert rep.frames == 10 and rep.warnings == ()
        (tmp_path / "b.mcap").unlink()
    r = CliRunner().invoke(cli, ["import", "bag", str(bag), "--depth", DEPTH, "--info", INFO,
                                 "-o", str(tmp_path / "c.mcap"), "--quiet", "--up", "z",
                                 "--floor", "none", "--time-offset", "-0.25"])
    assert r.exit_code == 0, r.output
    for given in ("1e7", "-1e9", "5000"):  # named as given
        r = CliRunner().invoke(cli, ["import", "bag", str(bag), "--depth", DEPTH,
                                     "--time-offset", given, "-o", str(tmp_path / "d.mcap")])
        assert r.exit_code == 2 and r.output.strip() == (
            f"sgtool: error: --time-offset {float(given):g}: must be within +-3600 seconds")


def test_camera_latency_is_not_a_clock_error(tmp_path):
    bag = write_bag(tmp_path / "b.bag", latency_ns=80_000_000)  # recorded 80 ms late
    rep = import_bag(bag, tmp_path / "a.mcap", BagOptions(depth=DEPTH, info=INFO, **KEEP_WORLD))
    assert rep.frames == 10 and rep.warnings == ()


def test_clock_offset_from_record_times():
    assert clock_offset_s([80, 90, 85], [0, 1, 2]) == pytest.approx(84e-9)
    assert clock_offset_s([], [1]) is None
    assert clock_problem(-0.04, "x") is None and clock_problem(0.5, "x") is None
    assert "--time-offset -0.060" in str(clock_problem(-0.06, "x"))
