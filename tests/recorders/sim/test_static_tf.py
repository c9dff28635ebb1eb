"""The recorder writes the fixed base -> camera link once on /tf_static (Foxglove and ROS
tools expect fixed transforms there) and world -> base on /tf each frame; readers compose
the same camera poses as rendered, from the start and from the middle of the log; instance
ids are 16UC1. A log of an older minor schema version is read as before."""

from __future__ import annotations

import numpy as np
from support.paths import GOLDEN
from support.small_house import small_house

from sgtool.log import LogReader
from sgtool.log import schemas as S
from sgtool.recorders.sim import CameraConfig, RecordOptions, record_house
from sgtool.recorders.sim.events import SimObserver
from sgtool.recorders.sim.recording import LogRecorder


class Poses(SimObserver):
    def __init__(self) -> None:
        self.poses: list[np.ndarray] = []

    def on_tick(self, sim) -> None:  # type: ignore[no-untyped-def]  # noqa: ANN001
        rec = next(o for o in sim.observers if isinstance(o, LogRecorder))
        if rec.last_frame is not None and (not self.poses or rec.frames > len(self.poses)):
            self.poses.append(rec.last_frame.pose)


def test_fixed_link_once_on_tf_static(tmp_path):
    seen = Poses()
    out = tmp_path / "rec.mcap"
    record_house(small_house(), out, RecordOptions(camera=CameraConfig(width=80, height=60),
                                                   frames=12), observers=[seen])
    with LogReader(out) as r:
        assert r.message_count(S.TF_STATIC) == 1 and r.message_count(S.TF) == 12
        (static,) = [d.message for d in r.messages([S.TF_STATIC])]
        assert (static.parent_frame_id, static.child_frame_id) == ("base", "camera")
        assert {d.message.child_frame_id for d in r.messages([S.TF])} == {"base"}
        frames = list(r.frames())
        late = list(r.frames(start_ns=frames[6].time_ns))
        assert {d.message.encoding for d in r.messages([S.IDS])} == {"16UC1"}
    assert len(frames) == len(seen.poses) == 12
    for fr, pose in zip(frames, seen.poses, strict=True):
        assert np.allclose(fr.pose, pose, atol=1e-9)
    assert np.allclose(late[0].pose, seen.poses[6], atol=1e-9)


def test_an_older_minor_version_is_read():
    with LogReader(GOLDEN / "house10-start.mcap") as r:
        version = r.metadata[S.METADATA_NAME]["log_schema_version"]
        assert S.parse_version(version) < S.LOG_SCHEMA_VERSION
        assert S.parse_version(version)[0] == S.LOG_SCHEMA_VERSION[0]
        assert r.frame_count() > 0 and next(iter(r.frames())).pose is not None
