"""``sgtool run --again LOG`` (and ``sgtool.logged_run``): a run-bench episode, which
``run --episode K`` does not pick (run-bench draws its own episodes), runs again into the
same log; options given beside it change their own setting only."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

import sgtool
from sgtool.cli import cli
from sgtool.log.reader import LogReader
from sgtool.log.records import Episode

MEASURED = ("decision_time_s", "latency_s")  # wall-clock fields, the only ones that vary
GOLDEN = Path(__file__).resolve().parents[2] / "golden" / "house6-tour.mcap"


def masked(path: Path) -> list[tuple[str, int, object]]:
    """Every message of a log, the measured fields of its JSON records blanked."""
    out: list[tuple[str, int, object]] = []
    with LogReader(path) as r:
        for _, channel, m in r.raw_messages(None):
            data: object = bytes(m.data)
            if channel.topic.startswith("/sgtool/"):
                rec = json.loads(m.data)
                data = {k: 0 if k in MEASURED else v for k, v in rec.items()}
            out.append((channel.topic, int(m.log_time), data))
    return out


def opening(path: Path) -> Episode:
    with LogReader(path) as r:
        return next(e for _, e in r.records(Episode) if e.status == "started")


@pytest.fixture(scope="module")
def bench(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A run-bench folder: 2 episodes of one 4-room house, 64x48, 3 steps, two planners
    (random draws from a seed of its episode, so a rerun must get the episode's index)."""
    out = tmp_path_factory.mktemp("again") / "rb"
    r = CliRunner().invoke(cli, [
        "run-bench", "--planners", "random,greedy", "--houses", "1", "--house-seed", "3",
        "--rooms", "4-4", "--episodes", "2", "--max-steps", "3", "--resolution", "64x48",
        "-O", "greedy.max_failures=1", "-w", "1", "--no-progress", "-o", str(out)])
    assert r.exit_code == 0, r.output
    return out / "logs" / "none"


@pytest.mark.parametrize("planner", ["random", "greedy"])
def test_a_run_bench_episode_runs_again_into_the_same_log(bench: Path, tmp_path: Path,
                                                          planner: str) -> None:
    log = bench / planner / "house-3" / "ep-001.mcap"
    again = tmp_path / "again.mcap"
    r = CliRunner().invoke(cli, ["run", "--again", str(log), "-o", str(again), "--quiet"])
    assert r.exit_code == 0, r.output
    assert "note:" not in r.output  # nothing of the log runs otherwise today
    assert masked(again) == masked(log)


def test_options_beside_again_change_their_setting_only(bench: Path, tmp_path: Path) -> None:
    log = bench / "greedy" / "house-3" / "ep-001.mcap"
    out = tmp_path / "scout.mcap"
    r = CliRunner().invoke(cli, ["run", "--again", str(log), "--planner", "scout",
                                 "--max-steps", "2", "--resolution", "160x120", "-o", str(out),
                                 "--quiet"])
    assert r.exit_code == 0, r.output
    before, after = opening(log), opening(out)
    assert (after.planner, before.planner) == ("scout", "greedy")
    x, y = before.extras, after.extras
    assert y["max_steps"] == 2 and y["camera"]["width"] == 160 and x["camera"]["width"] == 64
    # the greedy's option stays with greedy; points per voxel follow the new image size
    assert "planner_options" in x and "planner_options" not in y
    assert y["mapping"]["min_points"] > x["mapping"]["min_points"]
    for same in ("episode", "episode_id", "targets", "target_rooms", "start_pose",
                 "start_room", "seed", "planner_seed", "fps", "noise", "navigation"):
        assert x[same] == y[same], same
    assert after.query == before.query and after.house_id == before.house_id


def test_logged_run_from_python(bench: Path) -> None:
    logged = sgtool.logged_run(bench / "greedy" / "house-3" / "ep-000.mcap")
    assert (logged.planner, logged.episode_index, logged.house_id) == ("greedy", 0, "house-3")
    assert logged.planner_options == {"max_failures": 1}
    assert logged.options.max_steps == 3 and logged.options.camera.width == 64
    assert logged.house.seed == 3 and logged.notes == ()


def test_options_given_to_make_planner_are_logged(tmp_path: Path) -> None:
    """A planner built with options from Python runs with them: its log records them (it
    recorded none, and --again ran the defaults)."""
    house = sgtool.generate_house(3, rooms=(4, 4))
    _, episode = sgtool.pick_episode(house)
    opts = sgtool.ClosedLoopOptions(max_steps=1,
                                    camera=sgtool.CameraConfig(width=64, height=48))
    for timed in (True, False):
        out = tmp_path / f"scout-{timed}.mcap"
        planner = sgtool.make_planner("scout", delta=0.3, timed=timed)
        sgtool.run_closed_loop(house, episode, planner, out, opts)
        assert sgtool.logged_run(out).planner_options == {"delta": 0.3}, timed


@pytest.mark.parametrize(("args", "message"), [
    (["--seed", "3"], "--seed: --again runs the episode of its log"),
    (["--query", "bowl", "--episode", "1"], "--query, --episode: --again runs the episode"),
])
def test_options_that_pick_another_episode_are_refused(bench: Path, tmp_path: Path,
                                                       args: list[str], message: str) -> None:
    log = bench / "random" / "house-3" / "ep-000.mcap"
    out = tmp_path / "x.mcap"
    r = CliRunner().invoke(cli, ["run", "--again", str(log), *args, "-o", str(out)])
    assert r.exit_code == 2 and message in r.output, r.output
    assert not out.exists()


def test_a_log_without_a_closed_loop_episode_is_refused(tmp_path: Path) -> None:
    out = tmp_path / "x.mcap"
    r = CliRunner().invoke(cli, ["run", "--again", str(GOLDEN), "-o", str(out)])
    assert r.exit_code == 2, r.output
    assert "no closed-loop episodes in it" in r.output and not out.exists()
    r = CliRunner().invoke(cli, ["run", "-o", str(out)])
    assert r.exit_code == 2 and "Missing option '-p' / '--planner' (or --again LOG)" in r.output


def test_a_planner_s_own_given_options_attribute_is_not_taken_for_options() -> None:
    """A user's planner with an attribute named like make_planner's record of its options
    (not a mapping) runs with nothing recorded (it crashed the episode)."""
    from sgtool.recorders.sim.episode_extras import options_record

    class Mine:
        given_options = ("alpha", "beta")

    mine = {"planner_object": f"{__name__}:{Mine.__qualname__}"}
    assert options_record(Mine(), None) == mine
    assert options_record(Mine(), {"k": 1}) == {"planner_options": {"k": 1}, **mine}
    # one's own object in a TimedPlanner, a built-in made without make_planner (its options
    # unknown): marked too; make_planner's, timed or not: rebuilt by name
    from sgtool.planning.timing import TimedPlanner

    assert options_record(TimedPlanner(Mine()), None) == mine  # type: ignore[arg-type]
    greedy = type(sgtool.make_planner("greedy", timed=False))
    assert options_record(greedy(), None) == {
        "planner_object": f"{greedy.__module__}:{greedy.__qualname__}"}
    for timed in (True, False):
        assert options_record(sgtool.make_planner("greedy", timed=timed), None) == {}


def test_a_planner_object_of_ones_own_is_not_rebuilt_by_its_name(tmp_path: Path) -> None:
    """A user's own planner object named like a built-in: its log records its class, golden
    pins no decisions of it (it pinned greedy's own, which the episode never made) and
    `run --again` asks for -p (it ran greedy); make_planner's planners are rebuilt."""
    greedy = type(sgtool.make_planner("greedy", timed=False))

    class Mine(greedy):  # type: ignore[misc,valid-type]
        pass

    house = sgtool.generate_house(3, rooms=(4, 4))
    _, episode = sgtool.pick_episode(house)
    opts = sgtool.ClosedLoopOptions(max_steps=2,
                                    camera=sgtool.CameraConfig(width=64, height=48))
    sgtool.run_closed_loop(house, episode, Mine(), tmp_path / "mine.mcap", opts)
    sgtool.run_closed_loop(house, episode, sgtool.make_planner("greedy"),
                           tmp_path / "made.mcap", opts)
    run = sgtool.logged_run(tmp_path / "mine.mcap")
    assert (run.planner, run.planner_object) == ("greedy", f"{__name__}:{Mine.__qualname__}")
    assert sgtool.logged_run(tmp_path / "made.mcap").planner_object is None
    pins = sgtool.pin_logs([tmp_path / "mine.mcap", tmp_path / "made.mcap"], tmp_path / "p")
    assert (pins.logs["mine"].planner, pins.logs["mine"].decisions) == (None, None)
    assert pins.logs["made"].planner == "greedy" and pins.logs["made"].decisions
    # and `golden pin` says so: a lab expecting its planner's decisions pinned is told
    r = CliRunner().invoke(cli, ["golden", "pin", str(tmp_path / "mine.mcap"),
                                 str(tmp_path / "made.mcap"), "--dir", str(tmp_path / "q")])
    assert r.exit_code == 0, r.output
    mine_line, made_line = r.stdout.splitlines()[:2]
    assert mine_line.startswith("pinned mine: ") and mine_line.endswith(
        f"; its decisions are not pinned (greedy: a planner object of one's own "
        f"({__name__}:{Mine.__qualname__}) cannot be built again from the log (its options "
        f"are unknown); record with sgtool.make_planner('module:Name', **options) to pin "
        f"its decisions) (../mine.mcap)"), mine_line  # the log as the pin stores it
    assert " greedy decisions (" in made_line and "not pinned" not in made_line
    out = tmp_path / "again.mcap"
    r = CliRunner().invoke(cli, ["run", "--again", str(tmp_path / "mine.mcap"), "-o", str(out)])
    assert r.exit_code == 2 and r.output.count("\n") == 1, r.output
    assert "its planner 'greedy' was a Python object (" in r.output and "give -p" in r.output
    assert "its class was defined in a function: put it in a module on PYTHONPATH and give " \
        "-p MODULE:Mine" in r.output, r.output
    assert not out.exists()


def _as_older_log(src: Path, dst: Path) -> None:
    """``src`` with its Episode records' extras as a log of before live navigation has
    them: no ``navigation`` (house navigation, the live settings absent)."""
    from mcap.reader import make_reader
    from mcap.writer import Writer

    with open(src, "rb") as f, open(dst, "wb") as g:
        r = make_reader(f)
        summary = r.get_summary()
        assert summary is not None
        w = Writer(g)
        w.start(profile=r.get_header().profile, library="test")
        schemas = {sid: w.register_schema(s.name, s.encoding, s.data)
                   for sid, s in sorted(summary.schemas.items())}
        channels = {cid: w.register_channel(c.topic, c.message_encoding,
                                            schemas.get(c.schema_id, 0), dict(c.metadata))
                    for cid, c in sorted(summary.channels.items())}
        for _, channel, m in r.iter_messages(log_time_order=False):
            data = m.data
            if channel.topic == "/sgtool/episode":
                rec = json.loads(data)
                rec.get("extra", {}).pop("navigation", None)
                data = json.dumps(rec).encode()
            w.add_message(channels[channel.id], m.log_time, data, m.publish_time, m.sequence)
        for a in r.iter_attachments():
            w.add_attachment(a.create_time, a.log_time, a.name, a.media_type, a.data)
        for md in r.iter_metadata():
            w.add_metadata(md.name, dict(md.metadata))
        w.finish()


def test_an_older_house_navigation_log_is_read(bench: Path, tmp_path: Path) -> None:
    """A log of before live navigation (no navigation settings: the house's) is read by
    logged_run as house navigation with the live settings at their defaults, which
    ClosedLoopOptions accepts (it refused the missing ones read as the settings of before,
    look_in 0 and no peek, for house navigation)."""
    old = tmp_path / "old.mcap"
    _as_older_log(bench / "greedy" / "house-3" / "ep-000.mcap", old)
    assert "navigation" not in opening(old).extras
    logged = sgtool.logged_run(old)
    assert logged.options.navigation == "house"
    assert logged.options.live == sgtool.ClosedLoopOptions().live
