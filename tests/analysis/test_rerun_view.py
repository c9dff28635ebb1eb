"""`sgtool view` writes a Rerun recording that `rerun rrd verify` accepts."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
import rerun as rr
from click.testing import CliRunner
from support.logfixtures import write_log
from support.paths import GOLDEN

from sgtool.cli import cli
from sgtool.colors import color_for


@pytest.fixture(autouse=True)
def strict_rerun():
    rr.set_strict_mode(True)  # bad input raises instead of being dropped with a warning
    yield
    rr.set_strict_mode(False)


def rrd_verify(path: Path) -> subprocess.CompletedProcess[str]:
    """`rerun rrd verify PATH` (the venv's rerun, else the one on PATH); must succeed."""
    exe = str(Path(sys.executable).parent / "rerun")
    if not Path(exe).exists():
        exe = shutil.which("rerun") or "rerun"
    res = subprocess.run([exe, "rrd", "verify", str(path)], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0, res.stderr
    return res


def test_view_writes_a_verified_rrd(tmp_path):
    log = write_log(tmp_path / "run.mcap")
    out = tmp_path / "view.rrd"
    r = CliRunner().invoke(cli, ["view", str(log), "-o", str(out), "--no-voxels"])
    assert r.exit_code == 0, r.output
    assert out.stat().st_size > 10_000 and not (tmp_path / "view.rrd.partial").exists()
    res = rrd_verify(out)
    assert "verified without error" in res.stderr + res.stdout


def test_view_refuses_to_overwrite_its_input(tmp_path):
    log = write_log(tmp_path / "run.mcap")
    r = CliRunner().invoke(cli, ["view", str(log), "-o", str(log)])
    assert r.exit_code == 2 and "must not be the input" in r.output


def test_colours_are_stable_and_distinct():
    assert color_for(3) == color_for(3)
    assert len({color_for(i) for i in range(50)}) == 50
    assert color_for("room:1") == color_for("room:1")


def test_view_of_a_replayed_log_with_voxels_and_derived_layers(tmp_path):
    """A golden log replayed (occupancy, Voronoi graph, rooms, scene graphs) and viewed with
    the voxel map, in strict mode: every logged archetype is valid, and the file verifies."""
    from sgtool.replayers.derived_log import ReplayOptions, replay

    golden = GOLDEN / "house10-start.mcap"
    derived = tmp_path / "derived.mcap"
    replay(golden, derived, ReplayOptions(max_frames=40))
    out = tmp_path / "view.rrd"
    r = CliRunner().invoke(cli, ["view", str(derived), "-o", str(out)])
    assert r.exit_code == 0, r.output
    rrd_verify(out)
    printed = rrd_print(out)
    assert "Blueprint" in printed and "ViewBlueprint" in printed  # the default layout
    assert re.search(r" /graph - data columns: \[GraphEdges:edges .*GraphNodes:node_ids", printed)


def rrd_print(path: Path) -> str:
    """`rerun rrd print PATH` (the venv's rerun, else the one on PATH)."""
    exe = str(Path(sys.executable).parent / "rerun")
    if not Path(exe).exists():
        exe = shutil.which("rerun") or "rerun"
    res = subprocess.run([exe, "rrd", "print", str(path)], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0, res.stderr
    return res.stdout + res.stderr


def test_graph_nodes_and_edges():
    from sgtool.analysis.rerun_view import graph_nodes_edges

    g = {"rooms": [{"id": "room:1", "category": "kitchen", "position": [0, 0],
                    "neighbours": ["room:2"]},
                   {"id": "room:2", "category": "hall", "position": [4, 0],
                    "neighbours": ["room:1"]}],
         "regions": [{"id": "region:1.1", "kind": "region", "room": "room:1",
                      "position": [1, 2]}],
         "objects": [{"id": "obj:3", "category": "cabinet", "parent": "region:1.1",
                      "room": "room:1", "position": [1, 2, 0.5], "state": "closed"},
                     {"id": "obj:4", "category": "apple", "parent": "obj:9",
                      "room": "room:1", "position": [1, 2, 0.9]}],
         "doors": [{"id": "door:5", "position": [2, 0], "rooms": ["room:1", "room:2"],
                    "state": "open"}]}
    ids, labels, pos, _, edges = graph_nodes_edges(g)
    assert ids == ["room:1", "room:2", "region:1.1", "obj:3", "obj:4", "door:5"]
    assert labels[3] == "cabinet (closed)" and pos[2] == (1.0, -2.0)
    # obj:4's parent obj:9 is not in the graph: no edge; room neighbours once
    assert edges == [("obj:3", "region:1.1"), ("region:1.1", "room:1"), ("door:5", "room:1"),
                     ("door:5", "room:2"), ("room:1", "room:2")]


@pytest.mark.parametrize("links", [
    [],  # no /tf at all: no camera link, no base link
    [("base", "camera"), ("camera", "base")],  # a cycle: neither reaches the world
])
def test_view_of_a_log_without_a_camera_pose(tmp_path, links):
    """Frames whose camera and base poses cannot be composed from /tf (a missing link or a
    cycle) are shown without a pose and without a robot marker, not an IndexError."""
    from support.logfixtures import DT, synthetic_frame

    from sgtool.log import LogWriter

    log = tmp_path / "run.mcap"
    with LogWriter(log, seed=7) as w:
        for i in range(3):
            k, rgb, depth, ids, _, _ = synthetic_frame(i)
            if i == 0:
                w.write_calibration(0, k)
            for parent, child in links:
                w.write_transform(i * DT, parent, child, np.eye(4))
            w.write_rgb(i * DT, rgb)
            w.write_depth(i * DT, depth)
            w.write_ids(i * DT, ids)
    out = tmp_path / "view.rrd"
    r = CliRunner().invoke(cli, ["view", str(log), "-o", str(out), "--no-voxels"])
    assert r.exit_code == 0, r.output
    rrd_verify(out)
    assert "note: 3 of 3 frames have no camera pose: /tf has no chain world -> camera" in (
        r.output)


def test_recording_id_follows_the_content_not_the_name(tmp_path):
    """Two different run.mcap from two folders are two recordings; one log is one."""
    from sgtool.analysis.rerun_view import recording_id

    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    a = write_log(tmp_path / "a" / "run.mcap", n=3)
    b = write_log(tmp_path / "b" / "run.mcap", n=4)
    assert recording_id(a) != recording_id(b)
    assert recording_id(a) == recording_id(a) and len(recording_id(a)) == 32


def test_path_pieces_with_every(tmp_path, monkeypatch):
    """The path in pieces of PATH_CHUNK points, frames skipped by --every included."""
    import sgtool.analysis.rerun_view as rv

    monkeypatch.setattr(rv, "PATH_CHUNK", 3)
    logged: dict[str, list] = {}

    class Rec(rr.RecordingStream):
        def log(self, entity, archetype, static=False):  # type: ignore[override]
            if entity.startswith("world/robot/path/"):
                logged[entity] = archetype

    from sgtool.log import LogReader

    log = write_log(tmp_path / "run.mcap", n=12)
    with LogReader(log) as r:
        rec = Rec("test")
        rec.memory_recording()
        rv._export(rec, r, every=5, max_frames=None, progress=None, voxels=None)
    # 12 points: pieces 0..3 of points [0..3], [3..6], [6..9], [9..10] (frame 10 last logged)
    xs = {k: [round(float(p[0]), 2) for p in np.array(
        v.strips.as_arrow_array().to_pylist()[0], float).reshape(-1, 3)]
        for k, v in logged.items()}
    assert sorted(xs) == [f"world/robot/path/{k}" for k in range(4)]
    assert xs["world/robot/path/0"] == [0.0, 0.05, 0.1, 0.15]
    assert xs["world/robot/path/2"] == [0.3, 0.35, 0.4, 0.45]


def test_view_of_a_trajectory_without_frames_draws_its_path(tmp_path):
    """`sgtool import bag` without --depth writes /tf world -> camera only: the view draws
    the path (no voxel map to build, no camera images)."""
    from sgtool.log import LogWriter, codec
    from sgtool.log import schemas as S

    log = tmp_path / "trajectory.mcap"
    with LogWriter(log, seed=1) as w:
        for i in range(5):
            pose = np.eye(4)
            pose[0, 3] = 0.5 * i
            t = i * 100_000_000
            w.write_proto(S.TF, t, codec.encode_transform(t, S.WORLD_FRAME, S.CAMERA_FRAME,
                                                          pose))
    out = tmp_path / "t.rrd"
    r = CliRunner().invoke(cli, ["view", str(log), "-o", str(out)])
    assert r.exit_code == 0, r.output
    rrd_verify(out)
    printed = rrd_print(out)
    assert "world/robot/path/0" in printed and "world/robot " in printed.replace("\n", " ")


def test_class_ids_past_16_bits_keep_their_labels():
    """Instance ids past 65535 (32SC1 images) become their ranks, never another id's
    class by wrapping; ids that fit are their own class ids."""
    from sgtool.analysis.rerun_view import class_ids, segmentation

    assert class_ids([5, 7, 65535]) is None
    ids = np.array([[5, 65541], [0, 99]], dtype=np.int32)
    assert segmentation(ids, None).tolist() == [[5, 0], [0, 99]]  # no wrap onto id 5
    dense = class_ids([65541, 5])
    assert dense is not None and dense.tolist() == [5, 65541]
    assert segmentation(ids, dense).tolist() == [[1, 2], [0, 0]]  # 99: no class


def test_episode_doors_and_empty_graphs_are_drawn(tmp_path):
    """The episode record (query and outcome) is a document; doors are points coloured by
    state; a graph without rooms or objects clears the last ones; no wall-clock timeline."""
    from sgtool.analysis.rerun_view import episode_text
    from sgtool.log import LogWriter

    text = episode_text({"kind": "search", "status": "success", "query": "bowl",
                         "steps": 4, "extra": {"end": "found"}})
    assert "- **query**: bowl" in text and "- **end**: found" in text
    from sgtool.scenegraph.graph import DoorNode, ObjectNode, RobotState, RoomNode, SceneGraph

    full = SceneGraph(
        robot=RobotState((0.0, 0.0)), rooms=(RoomNode("room:0", "kitchen", (1.0, 1.0)),),
        objects=(ObjectNode("obj:1", "bowl", "room:0", "room:0", (1.0, 1.0, 0.8)),),
        doors=(DoorNode("door:2", (2.0, 1.0), "open", ("room:0",)),)).to_dict()
    empty = SceneGraph(robot=RobotState((0.0, 0.0))).to_dict()
    derived = tmp_path / "graphs.mcap"
    with LogWriter(derived, seed=1) as w:
        w.write_record("scene_graph", 1, full)
        w.write_record("scene_graph", 2, empty)
        w.write_record("episode", 3, {"kind": "search", "status": "success",
                                      "query": "bowl"})
    out = tmp_path / "g.rrd"
    r = CliRunner().invoke(cli, ["view", str(derived), "-o", str(out), "--no-voxels"])
    assert r.exit_code == 0, r.output
    printed = rrd_print(out)
    for entity in ("/world/graph/doors", "/world/graph/objects", "/episode"):
        assert entity in printed, entity
    for entity in ("/world/graph/objects", "/world/graph/rooms", "/world/graph/doors"):
        assert f"{entity} - data columns: [Clear:is_recursive]" in printed, entity
    assert "log_time" not in printed


def test_max_frames_leaves_out_what_was_logged_after_the_last_frame(tmp_path):
    """`view --max-frames 10` of a 40-frame replay: the camera stops at frame 9, and so do
    the maps and graphs (they were logged until frame 39), on the frame timeline."""
    import collections

    import rerun.chunk as rc

    from sgtool.replayers.derived_log import ReplayOptions, replay

    derived = tmp_path / "derived.mcap"
    replay(GOLDEN / "house10-start.mcap", derived, ReplayOptions(max_frames=40))
    last: dict[str, int] = collections.defaultdict(int)
    for n in (10, None):
        out = tmp_path / f"v{n}.rrd"
        args = ["view", str(derived), "-o", str(out), "--no-voxels"]
        r = CliRunner().invoke(cli, args + (["--max-frames", str(n)] if n else []))
        assert r.exit_code == 0, r.output
        last.clear()
        for chunk in rc.RrdReader(str(out)).store().stream().to_chunks():
            batch = chunk.to_record_batch()
            if "frame" in batch.schema.names:
                frames = [f for f in batch.column("frame").to_pylist() if f is not None]
                if frames:
                    last[str(chunk.entity_path)] = max(last[str(chunk.entity_path)],
                                                       max(frames))
        if n:
            assert last["/world/camera/image/depth"] == 9
            assert last["/world/map/occupancy"] <= 9 and last["/graph"] <= 9
    assert last["/graph"] > 9 and last["/world/camera/image/depth"] == 39


def test_two_exports_of_one_log_hold_the_same(tmp_path, monkeypatch):
    """Two exports of one log differ in bytes (Rerun's ids; module doc) but not in what they
    hold: the same content digest, with the blueprint's entity paths fixed, however Rerun
    cut the rows into chunks; another log's export has another digest."""
    import time

    import rerun.chunk as rc

    import sgtool.analysis.rerun_view as rv
    from sgtool.analysis.rrd_contents import content_digest

    log = write_log(tmp_path / "run.mcap", n=6)
    first, second = tmp_path / "a.rrd", tmp_path / "b.rrd"
    rv.export(log, first)
    rv.export(log, second)
    assert content_digest(first) == content_digest(second)

    def blueprint_paths(path: Path) -> set[str]:
        reader = rc.RrdReader(str(path))
        return {str(c.entity_path) for c in reader.stream(store=reader.blueprints()[0])}

    assert blueprint_paths(first) == blueprint_paths(second)
    assert any(p.startswith("/container/") for p in blueprint_paths(first))

    # rows cut into chunks by the clock (what Rerun's default batcher does) hold the same
    monkeypatch.setattr(rv, "FILE_FLUSH_TICK_S", 0.001)
    chopped = tmp_path / "chopped.rrd"
    rv.export(log, chopped, progress=lambda n: time.sleep(0.02))

    def chunks(path: Path) -> int:
        return len(rc.RrdReader(str(path)).stream().to_chunks())

    assert chunks(chopped) > chunks(first)
    assert content_digest(chopped) == content_digest(first)

    shorter = tmp_path / "shorter.rrd"
    rv.export(log, shorter, max_frames=5)
    assert content_digest(shorter) != content_digest(first)


def test_info_of_a_rerun_recording_names_its_stores_and_digest(tmp_path):
    """`sgtool info FILE.rrd` prints the recording's stores and content digest (the same
    for two exports of one log); a file that only looks like one is one error line."""
    import sgtool.analysis.rerun_view as rv

    log = write_log(tmp_path / "run.mcap", n=4)
    a, b = tmp_path / "a.rrd", tmp_path / "b.rrd"
    rv.export(log, a)
    rv.export(log, b)
    runner = CliRunner()
    got = [json.loads(runner.invoke(cli, ["info", str(p), "--json"]).output) for p in (a, b)]
    assert got[0]["content_digest"] == got[1]["content_digest"]
    assert [s["kind"] for s in got[0]["stores"]] == ["recording", "blueprint"]
    rec = got[0]["stores"][0]
    assert rec["recording_id"] == rv.recording_id(log) and rec["rows"] > 4
    text = runner.invoke(cli, ["info", str(a)]).output
    assert "a Rerun recording" in text and got[0]["content_digest"] in text
    fake = tmp_path / "fake.rrd"
    fake.write_bytes(b"RRF2" + bytes(4))
    r = runner.invoke(cli, ["info", str(fake)])
    assert r.exit_code == 2 and "Rerun cannot read it" in r.output
    assert len(r.output.strip().splitlines()) == 1
    cut = tmp_path / "cut.rrd"  # a recording cut short: one line, no warning of Rerun's
    cut.write_bytes(a.read_bytes()[: a.stat().st_size // 2])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = runner.invoke(cli, ["info", str(cut)])
    assert r.exit_code == 2 and r.output.count("\n") == 1, r.output
    assert not caught, [str(w.message) for w in caught]
