"""`sgtool export foxglove-layout` writes the shipped layout; every topic its panels name
is a topic of a derived log (so no panel is empty by a typo)."""

from __future__ import annotations

import json

from click.testing import CliRunner
from support.paths import GOLDEN

from sgtool.cli import cli
from sgtool.log import LogReader
from sgtool.replayers.derived_log import ReplayOptions, replay


def panel_topics(layout: dict) -> set[str]:
    out: set[str] = set()
    for cfg in layout["configById"].values():
        out |= set(cfg.get("topics", {}))
        if "imageTopic" in cfg.get("imageMode", {}):
            out.add(cfg["imageMode"]["imageTopic"])
        if "topicPath" in cfg:
            out.add(cfg["topicPath"])
    return out


def test_layout_names_topics_of_a_derived_log(tmp_path):
    out = tmp_path / "layout.json"
    r = CliRunner().invoke(cli, ["export", "foxglove-layout", "-o", str(out)])
    assert r.exit_code == 0, r.output
    layout = json.loads(out.read_text())
    derived = tmp_path / "derived.mcap"
    replay(GOLDEN / "house10-start.mcap", derived, ReplayOptions(max_frames=30))
    with LogReader(derived) as rd:
        topics = rd.topics()
    assert panel_topics(layout) <= set(topics)
    assert "/map/graph" in panel_topics(layout)
    r = CliRunner().invoke(cli, ["export", "foxglove-layout", "-o", str(out)])
    assert r.exit_code == 2 and "--force" in r.output


def test_the_3d_panel_follows_a_frame_the_log_has(tmp_path):
    """base by default (simulated and closed-loop logs); camera for an imported recording,
    whose /tf has world -> camera only."""
    out = tmp_path / "layout.json"
    for args, frame in (([], "base"), (["--follow", "camera"], "camera")):
        r = CliRunner().invoke(cli, ["export", "foxglove-layout", "-o", str(out), "--force",
                                     *args])
        assert r.exit_code == 0, r.output
        assert json.loads(out.read_text())["configById"]["3D!sgtool"]["followTf"] == frame
    r = CliRunner().invoke(cli, ["export", "foxglove-layout", "-o", str(out), "--force",
                                 "--follow", "base_link"])
    assert r.exit_code == 2 and "'base_link' is not one of 'base', 'camera', 'world'" in r.output


def test_the_id_and_depth_images_are_drawn_in_colour_over_their_range(tmp_path):
    """Foxglove draws a 16UC1 image as grey over 0..10000 unless told otherwise: instance
    ids (tens to hundreds) were black, depth in millimetres (up to the 6 m range) dim. The
    layout maps each through a colour map over its own range."""
    out = tmp_path / "layout.json"
    assert CliRunner().invoke(cli, ["export", "foxglove-layout", "-o", str(out)]).exit_code == 0
    modes = {cfg["imageMode"]["imageTopic"]: cfg["imageMode"]
             for cfg in json.loads(out.read_text())["configById"].values()
             if "imageTopic" in cfg.get("imageMode", {})}
    ids, depth = modes["/camera/instances"], modes["/camera/depth"]
    with LogReader(GOLDEN / "house10-start.mcap") as r:
        frames = list(r.frames())
    most_id = max(int(f.ids.max()) for f in frames)
    most_mm = max(float(f.depth.max()) for f in frames) * 1000.0
    for mode, most in ((ids, most_id), (depth, most_mm)):
        assert mode["colorMode"] == "colormap" and mode["minValue"] == 0
        assert most <= mode["maxValue"] <= 10 * most
