"""/tf header stamps against log times: frames are paired with /tf by log time (say so),
a log whose stamps disagree beyond a tolerance is warned about (naming the offset and
``--tf-time``) or refused, and ``--tf-time stamp`` pairs by the stamps instead.

The logs here: a calibration, then per frame ``i`` (log time ``i * DT``) one transform
world -> camera with the camera ``i`` metres along x, then a depth image. The transforms'
header stamps are their log times plus an offset."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from sgtool.cli import cli
from sgtool.errors import LogFormatError
from sgtool.log import CameraIntrinsics, LogReader, LogWriter, codec
from sgtool.log import schemas as S
from sgtool.log.frame_assembly import (
    FRAME_TOPICS,
    TF_STAMP_REFUSE_S,
    TF_STAMP_WARN_S,
    FrameAssembler,
)

DT = 100_000_000  # 0.1 s between frames
N = 6


def camera_at(x: float) -> np.ndarray:
    T = np.array([[0, 0, 1, 0], [-1, 0, 0, 0], [0, -1, 0, 1.2], [0, 0, 0, 1]], float)  # noqa: N806
    T[0, 3] = x
    return T


def tf_log(path, offset_s: float):
    k = CameraIntrinsics.from_fov(16, 12, 60.0)
    depth = np.full((12, 16), 2.0, np.float32)
    with LogWriter(path, seed=1) as w:
        w.write_calibration(0, k)
        for i in range(N):
            t = i * DT
            stamp = t + round(offset_s * 1e9)
            w.write_proto(S.TF, t, codec.encode_transform(stamp, S.WORLD_FRAME, S.CAMERA_FRAME,
                                                          camera_at(float(i))))
            w.write_depth(t, depth)
    return path


def assembled(path, tf_time: str = "log"):
    """(camera x of every frame, the assembler's note)."""
    asm = FrameAssembler(where=str(path), tf_time=tf_time)
    xs = []
    with LogReader(path) as r:
        for d in r.messages(FRAME_TOPICS):
            xs += [fr.pose[0, 3] for fr in asm.push(d.topic, d.log_time_ns, d.message)]
    xs += [fr.pose[0, 3] for fr in asm.finish()]
    return xs, asm.tf_stamp_note()


def test_agreeing_stamps_pair_by_log_time_without_a_note(tmp_path):
    xs, note = assembled(tf_log(tmp_path / "ok.mcap", 0.0))
    assert xs == [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]
    assert note is None
    # the sgtool writer stamps every message with its log time
    xs, note = assembled(tf_log(tmp_path / "tiny.mcap", TF_STAMP_WARN_S / 2))
    assert note is None


def test_stamps_a_quarter_second_off_are_noted_with_the_offset_and_the_option(tmp_path):
    log = tf_log(tmp_path / "late.mcap", 0.25)
    xs, note = assembled(log)
    assert xs == [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]  # paired by log time, as before
    assert note == (f"{log}: 6 of 6 /tf message(s) have header stamps more than 0.05 s from "
                    "their log times (at most +0.250 s, at log time 0 ns); frames were paired "
                    "with /tf by log time (--tf-time stamp pairs them by stamps)")


def test_pairing_by_stamps_interpolates_between_the_transforms_around_the_frame(tmp_path):
    log = tf_log(tmp_path / "late.mcap", 0.25)
    xs, note = assembled(log, tf_time="stamp")
    # frame i (stamp 0.1 i s) lies between the transforms of frames j and j + 1 (stamped
    # 0.1 j + 0.25, camera at x = j): x = i - 2.5 for frames 3..5; frame 2 is 0.05 s
    # before the first transform, near enough to take it; frames 0 and 1 have no pose
    assert np.isnan(xs[:2]).all()
    assert xs[2:] == pytest.approx([0.0, 0.5, 1.5, 2.5])
    assert note is None


def test_stamps_beyond_the_larger_tolerance_are_refused_naming_the_option(tmp_path):
    log = tf_log(tmp_path / "far.mcap", -2.0)
    assert TF_STAMP_REFUSE_S < 2.0
    with pytest.raises(LogFormatError) as info:
        assembled(log)
    msg = str(info.value)
    assert msg == (f"{log}: /tf message at 0 ns: its header stamp is -2.000 s from its log "
                   "time (more than 1 s): frames are paired with /tf by log time, which "
                   "would build another map than its stamps say; --tf-time stamp pairs "
                   "them by stamps")
    xs, note = assembled(log, tf_time="stamp")  # the user's choice: no refusal
    # each frame's own transform (read just before it, stamped 2 s earlier) is the latest
    # read at or before the frame's stamp
    assert xs == [0.0, 1.0, 2.0, 3.0, 4.0, 5.0] and note is None


def test_replay_warns_refuses_and_takes_the_choice(tmp_path):
    late = tf_log(tmp_path / "late.mcap", 0.25)
    r = CliRunner().invoke(cli, ["replay", str(late)])
    assert r.exit_code == 0, r.output
    warning = [s for s in r.output.splitlines() if s.startswith("warning: ")]
    assert len(warning) == 1
    assert "at most +0.250 s" in warning[0] and "--tf-time stamp" in warning[0]

    far = tf_log(tmp_path / "far.mcap", 2.0)
    r = CliRunner().invoke(cli, ["replay", str(far)])
    assert r.exit_code == 2
    lines = r.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sgtool: error: ")
    assert "+2.000 s from its log time" in lines[0] and "--tf-time stamp" in lines[0]

    early = tf_log(tmp_path / "early.mcap", -2.0)  # stamps 2 s before the log times
    assert CliRunner().invoke(cli, ["replay", str(early)]).exit_code == 2
    out = tmp_path / "derived.mcap"
    r = CliRunner().invoke(cli, ["replay", str(early), "--tf-time", "stamp", "-o", str(out)])
    assert "header stamps" not in r.output  # the user's choice: no offset warning, but
    # each frame's pose would come from a transform stamped 2 s before its image: left out
    assert r.exit_code == 2, r.output
    assert "no frame has a camera pose: 6 frame(s) left out: their camera pose would come " \
        "from a /tf sample older than the image (up to 2.000 s" in r.output
    half = tf_log(tmp_path / "half.mcap", -0.25)  # by stamps, poses a quarter second old
    r = CliRunner().invoke(cli, ["replay", str(half), "--tf-time", "stamp", "-o", str(out)])
    assert r.exit_code == 0, r.output
    with LogReader(out) as d:
        assert d.metadata["sgtool.replay"]["tf_time"] == "stamp"


def test_replay_help_says_which_time_it_uses():
    text = " ".join(CliRunner().invoke(cli, ["replay", "-h"]).output.split())
    assert "The time that pairs /tf transforms with camera frames" in text
    assert "[default: log]" in text


def test_a_derived_log_of_the_other_tf_time_is_not_complete(tmp_path):
    from sgtool.analysis.batch_replay import ReplayJob, is_complete
    from sgtool.replayers.derived_log import ReplayOptions, replay

    log = tf_log(tmp_path / "ok.mcap", 0.0)
    out = tmp_path / "derived.mcap"
    replay(log, out)  # pairing by log time
    by_log = ReplayJob(str(log), str(out), ReplayOptions(), False)
    by_stamp = ReplayJob(str(log), str(out), ReplayOptions(tf_time="stamp"), False)
    assert is_complete(by_log) and not is_complete(by_stamp)
    out.unlink()
    replay(log, out, ReplayOptions(tf_time="stamp"))
    assert is_complete(by_stamp) and not is_complete(by_log)
