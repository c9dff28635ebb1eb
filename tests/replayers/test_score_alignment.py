"""A drifted map is scored for its rooms, not for its shift: a simulated recording with pose
drift writes the true base pose beside the logged one (``world -> base_truth``), and
scoring carries the map onto the house by the rigid fit of the one onto the other."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from mcap.reader import make_reader
from mcap.writer import Writer
from support.paths import GOLDEN

from sgtool.house.io import load_house_text
from sgtool.log import LogReader
from sgtool.log import schemas as S
from sgtool.log.codec import decode_transform, encode_transform
from sgtool.log.poses import planar_fit
from sgtool.replayers.derived_log import replay
from sgtool.replayers.score import score, truth_alignment

TOUR = GOLDEN / "house6-tour.mcap"


def turn(angle: float, dx: float, dy: float) -> np.ndarray:
    T = np.eye(4)  # noqa: N806
    c, s = math.cos(angle), math.sin(angle)
    T[:2, :2] = [[c, -s], [s, c]]
    T[:2, 3] = dx, dy
    return T


def test_planar_fit_recovers_a_turn_and_a_shift() -> None:
    rng = np.random.default_rng(0)
    poses = [turn(rng.uniform(-3, 3), *rng.uniform(-5, 5, 2)) for _ in range(5)]
    for p in poses:
        p[2, 3] = 1.2  # a height the fit leaves alone
    moved = turn(0.7, 1.5, -2.0)
    fit = planar_fit(poses, [moved @ p for p in poses])
    assert np.allclose(fit, moved, atol=1e-12)
    # one pose is enough: its heading fixes the turn
    assert np.allclose(planar_fit(poses[:1], [moved @ poses[0]]), moved, atol=1e-12)
    assert np.array_equal(planar_fit([], []), np.eye(4))


def moved_log(src: Path, dst: Path, moved: np.ndarray) -> None:
    """``src`` with its logged base poses carried by ``moved`` (the map's frame turned
    and shifted against the house's) and the true ones written beside them."""
    with open(src, "rb") as f, open(dst, "wb") as out:
        reader = make_reader(f)
        w = Writer(out)
        w.start(profile=S.PROFILE, library="test")
        schemas: dict[int, int] = {}
        channels: dict[int, int] = {}
        for schema, channel, message in reader.iter_messages(log_time_order=True):
            if schema is not None and schema.id not in schemas:
                schemas[schema.id] = w.register_schema(schema.name, schema.encoding,
                                                       schema.data)
            if channel.id not in channels:
                channels[channel.id] = w.register_channel(
                    channel.topic, channel.message_encoding,
                    schemas.get(channel.schema_id, 0), dict(channel.metadata))
            data = message.data
            if channel.topic == S.TF:
                tf = FrameTransform()
                tf.ParseFromString(data)
                if tf.parent_frame_id == S.WORLD_FRAME and tf.child_frame_id == S.BASE_FRAME:
                    true = decode_transform(tf)
                    truth = encode_transform(message.log_time, S.WORLD_FRAME,
                                             S.TRUE_BASE_FRAME, true)
                    data = encode_transform(message.log_time, S.WORLD_FRAME, S.BASE_FRAME,
                                            moved @ true).SerializeToString()
                    w.add_message(channels[channel.id], message.log_time, data,
                                  message.publish_time, message.sequence)
                    data = truth.SerializeToString()
            w.add_message(channels[channel.id], message.log_time, data,
                          message.publish_time, message.sequence)
        for a in reader.iter_attachments():
            w.add_attachment(a.create_time, a.log_time, a.name, a.media_type, a.data)
        for m in reader.iter_metadata():
            w.add_metadata(m.name, m.metadata)
        w.finish()


def scored(log: Path, aligned: bool) -> dict[str, float]:
    last = {}

    def keep(ref, stream) -> None:  # noqa: ANN001
        last["ref"], last["stream"] = ref, stream

    replay(log, None, on_refresh=keep)
    with LogReader(log) as r:
        spec = load_house_text(r.house_json())
        align = truth_alignment(r) if aligned else None
    b = last["stream"].builder
    q = score(spec, b.instances, last["ref"].layers, last["ref"].graph, b.trajectory,
              align)["strict"]
    return {"purity": q.purity, "objects": q.object_accuracy, "ari": q.object_ari}


def test_a_turned_and_shifted_map_scores_as_the_original_once_aligned(tmp_path):
    """The tour's base poses turned 90 degrees and shifted 2 m: its map is the original's
    turned (a quarter turn and whole metres keep the voxel grid), so once aligned it
    scores as the original (within what the grid's rounding changes); not aligned, its
    nodes and objects fall outside their rooms. The objects' rooms ARI asks no position."""
    moved = turn(math.pi / 2, 2.0, -1.0)
    log = tmp_path / "moved.mcap"
    moved_log(TOUR, log, moved)
    with LogReader(log) as r:
        align = truth_alignment(r)
        frames = r.frame_count()
    assert align is not None and align.frames == frames
    assert np.allclose(align.transform, np.linalg.inv(moved), atol=1e-9)
    assert align.rms_m < 1e-9
    with LogReader(TOUR) as r:
        assert truth_alignment(r) is None  # a log without drift holds no true pose
    original = scored(TOUR, aligned=False)
    fixed, shifted = scored(log, aligned=True), scored(log, aligned=False)
    assert abs(fixed["purity"] - original["purity"]) <= 0.02
    assert abs(fixed["objects"] - original["objects"]) <= 0.02
    assert shifted["purity"] < original["purity"] - 0.05
    assert shifted["objects"] < original["objects"] - 0.2
    assert abs(shifted["ari"] - original["ari"]) <= 0.02


def test_a_drifted_recording_logs_its_true_poses(tmp_path):
    """``sgtool record`` under pose drift writes the true base pose at every frame; its
    fit leaves less position error than the drift itself, and no drift writes none."""
    from click.testing import CliRunner

    from sgtool.cli import cli

    for noise, name in (("drift_xy=0.02,drift_yaw=0.02", "d.mcap"),
                        ("mild,drift_xy=0,drift_yaw=0", "c.mcap")):
        r = CliRunner().invoke(cli, ["record", "--seed", "3", "--rooms", "4-4",
                                     "--resolution", "32x24", "--fps", "2", "--frames", "60",
                                     "--noise", noise, "--quiet", "-o", str(tmp_path / name)])
        assert r.exit_code == 0, r.output
    with LogReader(tmp_path / "c.mcap") as r:
        assert truth_alignment(r) is None
    with LogReader(tmp_path / "d.mcap") as r:
        align = truth_alignment(r)
        base, truth = {}, {}
        for m in r.messages([S.TF]):
            if m.message.child_frame_id == S.BASE_FRAME:
                base[m.log_time_ns] = decode_transform(m.message)
            elif m.message.child_frame_id == S.TRUE_BASE_FRAME:
                truth[m.log_time_ns] = decode_transform(m.message)
        assert align is not None and align.frames == r.frame_count() == 60
    assert sorted(base) == sorted(truth)
    raw = math.sqrt(np.mean([np.sum((base[t][:2, 3] - truth[t][:2, 3]) ** 2)
                             for t in base]))
    assert raw > 0.0
    assert align.rms_m <= raw


def test_a_replay_cut_short_is_aligned_by_the_poses_it_replayed(tmp_path):
    """--max-frames: the map holds the first frames only, so the fit takes their poses
    only (the later, more drifted ones carried the early map off the house)."""
    from click.testing import CliRunner

    from sgtool.cli import cli

    log = tmp_path / "d.mcap"
    r = CliRunner().invoke(cli, ["record", "--seed", "3", "--rooms", "4-4", "--resolution",
                                 "32x24", "--fps", "2", "--frames", "60", "--noise",
                                 "drift_xy=0.2,drift_yaw=0.2", "--quiet", "-o", str(log)])
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(cli, ["replay", str(log), "--score", "--max-frames", "20"])
    assert r.exit_code == 0, r.output
    assert "a rigid fit over 20 frames" in r.output
