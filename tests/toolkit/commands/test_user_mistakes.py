"""User inputs that once crashed a command or slipped through: a folder whose name is not
UTF-8, a bag that breaks while it is read, a ROS time past 2038, wrong types in a pin index,
an output that is a FIFO, a view written under a log's name, options that do nothing."""

from __future__ import annotations

import json
import os
import struct
from pathlib import Path

import cv2
import numpy as np
import pytest
from click.testing import CliRunner
from support.bag_export import BagWriter
from support.logfixtures import write_log
from support.paths import GOLDEN

from sgtool.analysis.noise_study import record_task_log
from sgtool.cli import cli
from sgtool.errors import SgtoolError
from sgtool.log import LogReader
from sgtool.log.writer import LogWriter
from sgtool.recorders.importers.bagfiles import damaged_bag, open_bag
from sgtool.recorders.importers.images import read_color_file_kind

GOLDEN_LOG = GOLDEN / "house6-tour.mcap"


def _refusal(args: list[str]) -> str:
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 2, r.output
    assert r.exception is None or isinstance(r.exception, SystemExit), r.exception
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("sgtool: error:"), r.output
    return lines[0]


def test_an_image_in_a_folder_whose_name_is_not_utf8_is_read(tmp_path):
    folder = tmp_path / os.fsdecode(b"k\xff")  # a name in another encoding
    folder.mkdir()
    ok, png = cv2.imencode(".png", np.full((4, 6, 3), (10, 20, 30), np.uint8))
    assert ok
    png.tofile(folder / "a.png")
    rgb, kind = read_color_file_kind(folder / "a.png")
    assert rgb.shape == (4, 6, 3) and tuple(rgb[0, 0]) == (30, 20, 10)  # BGR file -> RGB
    assert kind == "8-bit 3-channel"


def test_metadata_naming_such_a_folder_stays_valid_utf8(tmp_path):
    path = tmp_path / "m.mcap"
    with LogWriter(path, seed=1) as w:
        w.add_metadata("sgtool.import", {"source": os.fsdecode(b"k\xff"), "plain": "ok"})
    with LogReader(path) as r:
        assert r.metadata["sgtool.import"] == {"source": "k\\xff", "plain": "ok"}


def test_a_bag_that_breaks_while_read_is_one_line_and_our_own_errors_are_not(tmp_path):
    bag = tmp_path / "b.bag"
    with BagWriter(bag, "ros1") as w:
        t = 1_700_000_000_000_000_000
        w.write("/tf", "tf2_msgs/msg/TFMessage", t,
                w.tf(t, [w.transform_stamped(t, "world", "cam", np.eye(4))]))
    with pytest.raises(SgtoolError, match="damaged or truncated bag.*struct.error|"
                                          "damaged or truncated bag.*error"):
        with open_bag(bag):
            raise struct.error("unpack requires a buffer of 8 bytes")
    with pytest.raises(KeyError):  # a bug of ours is not passed off as a damaged file
        with open_bag(bag):
            raise KeyError("x")
    assert damaged_bag(EOFError()) and not damaged_bag(ValueError("x"))


def test_an_export_time_base_past_the_ros_time_range_is_refused(tmp_path):
    out = tmp_path / "e.bag"
    err = _refusal(["export", "bag", str(GOLDEN_LOG), "-o", str(out), "--time-base", "5e9"])
    assert "2147483647 s" in err and not out.exists()
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("case, why", [
    ([], "must be an object, not a list"),
    ({"options": {"every": "abc"}}, "replay option 'every' is a string 'abc'; expected int"),
    ({"options": {"every": True}}, "replay option 'every' is a boolean True"),
    ({"options": "fast"}, "replay options must be an object, not a string"),
    ({"quality": 5}, "'quality' is a number, expected an object"),
])
def test_a_pin_index_with_wrong_types_is_one_line(tmp_path, case, why):
    folder = tmp_path / "pins"
    folder.mkdir()
    entry = case if not isinstance(case, dict) else {
        "log": "x.mcap", "log_sha256": "0" * 64, "refreshes": 1, "final_sha256": "0" * 64,
        "sequence_sha256": "0" * 64, **case}
    (folder / "expected.json").write_text(json.dumps(
        {"format": 2, "sgtool_version": "0", "cases": {"small": entry}}))
    assert why in _refusal(["golden", "check", "--dir", str(folder)])


def test_a_fifo_is_never_replaced_even_with_force(tmp_path):
    fifo = tmp_path / "out.mcap"
    os.mkfifo(fifo)
    err = _refusal(["doctor", str(GOLDEN_LOG), "--recover", str(fifo), "--force"])
    assert "not a regular file" in err
    assert fifo.exists() and not fifo.is_file()
    # a command without --force is not told of one (golden check --junit /dev/stdout was)
    err = _refusal(["golden", "check", "--dir", str(tmp_path), "--junit", str(fifo)])
    assert "not a regular file (a device, pipe or socket)" in err and "--force" not in err


def test_a_rerun_recording_must_be_named_rrd(tmp_path):
    out = tmp_path / "view.mcap"
    assert "must end in .rrd" in _refusal(["view", str(GOLDEN_LOG), "-o", str(out)])
    err = _refusal(["replay", str(GOLDEN_LOG), "-o", str(out), "--rrd", str(out)])
    assert "--rrd" in err and "must end in .rrd" in err
    assert not list(tmp_path.iterdir())


def test_rooms_without_seed_and_a_negative_depth_range_are_refused(tmp_path):
    out = tmp_path / "r.mcap"
    assert "give --seed N as well" in _refusal(["record", "--rooms", "6-8", "-o", str(out)])
    assert "need 4 <= MIN <= MAX" in _refusal(["record", "--rooms", "5-2", "-o", str(out)])
    assert "need 0 < MIN < MAX" in _refusal(["record", "--depth-range", "-1,0", "-o",
                                             str(out)])
    # each message names the option given, and only that one
    assert _refusal(["record", "--start", "-1", "-o", str(out)]).endswith(
        "--start -1: must be >= 0")
    assert _refusal(["record", "--speed", "0", "-o", str(out)]).endswith(
        "--speed 0: must be > 0")
    assert not list(tmp_path.iterdir())


def test_a_path_through_a_file_names_the_file(tmp_path):
    from sgtool.llm.recorded import TranscriptWriter

    (tmp_path / "log.mcap").write_bytes(b"x")
    with pytest.raises(SgtoolError, match="log.mcap is a file, not a folder"):
        TranscriptWriter(tmp_path / "log.mcap" / "t.jsonl")


def test_a_cut_off_cached_study_log_is_recorded_again(tmp_path, monkeypatch):
    log = tmp_path / "house" / "k.mcap"
    log.parent.mkdir()
    write_log(tmp_path / "whole.mcap", n=2)
    log.write_bytes((tmp_path / "whole.mcap").read_bytes()[:-40])  # cut off its end

    recorded: list[Path] = []

    def fake_record(spec, out, opts, house_id):  # type: ignore[no-untyped-def]
        recorded.append(Path(out))
        Path(out).write_bytes((tmp_path / "whole.mcap").read_bytes())

    import sgtool.recorders.sim as sim

    monkeypatch.setattr(sim, "record_house", fake_record)
    from sgtool.analysis.noise_study import RecordingSettings, StudyTask
    from sgtool.datasets.generator import generate_house

    task = StudyTask(house="house", noise="none", log=str(log),
                     spec_text=generate_house(0, rooms=(4, 4)).to_json(),
                     settings=RecordingSettings(), key_json="")
    assert record_task_log(task) and recorded == [log]
    assert not record_task_log(task)  # whole now: kept


def test_a_run_that_leaves_its_recorded_transcript_is_an_error(tmp_path):
    empty = tmp_path / "t.jsonl"
    empty.write_text("")
    out = tmp_path / "run.mcap"
    err = _refusal(["run", "-p", "moma-llm", "--llm-replay", str(empty), "--frames", "200",
                    "--resolution", "32x24", "--quiet", "-o", str(out)])
    assert "holds no (more) responses" in err and "holds the episode up to there" in err
    with LogReader(out) as r:  # the episode so far is a whole log
        assert r.frame_count() > 0


@pytest.mark.parametrize("args, line", [
    (["--closed-loop", "bogus"], "sgtool: error: --closed-loop: unknown planner 'bogus'"),
    (["--closed-loop", "scout", "--closed-loop-noise", "bogus"],
     "sgtool: error: --closed-loop-noise bogus: unknown profile 'bogus'"),
    (["--closed-loop", "scout", "--closed-loop-noise", "none,none"],
     "sgtool: error: --closed-loop/--closed-loop-noise: a name is given twice"),
    (["--closed-loop", "moma-llm"], "sgtool: error: --closed-loop moma-llm: no LLM endpoint "
     "configured: set SGTOOL_LLM_BASE_URL (and SGTOOL_LLM_API_KEY if it needs one); study "
     "noise has no option for it"),
    (["--resolution", "4097x120"], "sgtool: error: --resolution 4097x120: each side "
     "8..4096 pixels"),
    (["--resolution", "7x120"], "sgtool: error: --resolution 7x120: each side "
     "8..4096 pixels"),
    (["--cache", "{tmp}/f/x"], "sgtool: error: --cache {tmp}/f/x: lies under {tmp}/f, which "
     "is no folder"),
    (["--closed-loop-noise", "mild", "--closed-loop-houses", "2"], "sgtool: error: "
     "--closed-loop-noise, --closed-loop-houses: for the closed-loop part; give "
     "--closed-loop PLANNERS too"),
    (["--profile", "mild", "--profile", "mild"], "sgtool: error: --profile mild: given twice"),
])
def test_study_names_its_own_closed_loop_options(tmp_path, monkeypatch, args, line):
    """study noise checks its closed-loop planners and profiles with run-bench's and
    record's rules, its LLM planners' endpoint, resolution and cache before any recording,
    and the message names the option the user gave."""
    for key in ("SGTOOL_LLM_BASE_URL", "OPENAI_BASE_URL", "SGTOOL_LLM_API_KEY",
                "OPENAI_API_KEY"):
        monkeypatch.delenv(key, raising=False)
    (tmp_path / "f").write_text("a file")
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    r = CliRunner().invoke(cli, ["study", "noise", *args, "-o", str(tmp_path / "s")])
    assert r.exit_code == 2 and r.output.startswith(line.replace("{tmp}", str(tmp_path))), \
        r.output
    assert not (tmp_path / "s").exists()


@pytest.mark.parametrize("fault, code, line", [
    ("interrupt", 130, "sgtool: interrupted; {out} was written; {rrd} was not (make it with: "
                       "sgtool view {out} -o {rrd})"),
    ("full disk", 2, "sgtool: error: cannot write {rrd}: No space left on device; {out} was "
                     "written, {rrd} was not (make it with: sgtool view {out} -o {rrd})"),
])
def test_a_failed_rrd_step_says_the_log_is_complete(tmp_path, monkeypatch, fault, code,
                                                    line):
    """replay -o D.mcap --rrd V.rrd: an interrupt or an error (a full disk: it said
    "nothing was written") in the .rrd step leaves the complete derived log, and the one
    line says so, with the command that makes the .rrd."""
    import sgtool.analysis.replay_run as replay_run
    from sgtool.errors import SgtoolError

    def failing(derived, rrd, show):
        if fault == "interrupt":
            raise KeyboardInterrupt
        raise SgtoolError(f"cannot write {rrd}: No space left on device (nothing was written)")

    monkeypatch.setattr(replay_run, "write_view", failing)
    out, rrd = tmp_path / "d.mcap", tmp_path / "v.rrd"
    r = CliRunner().invoke(cli, ["replay", str(GOLDEN_LOG), "-o", str(out), "--rrd", str(rrd),
                                 "--no-progress"])
    assert r.exit_code == code, r.output
    assert r.output.strip().splitlines()[-1] == line.format(out=out, rrd=rrd)
    assert out.exists() and not rrd.exists()


@pytest.mark.parametrize("args, line", [
    (["bench", "--planners", ""], "sgtool: error: --planners: name at least one planner"),
    (["run-bench", "--planners", ""], "sgtool: error: --planners: name at least one planner"),
    (["run-bench", "--budgets", ""], "sgtool: error: --budgets '': comma-separated frames per "
     "room, e.g. 90,100"),
])
def test_an_empty_list_is_not_the_defaults(tmp_path, args, line):
    r = CliRunner().invoke(cli, [*args, "-o", str(tmp_path / "out")])
    assert r.exit_code == 2 and r.output.strip() == line, r.output
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", [["bench", "--seeds", "1"], ["run-bench"],
                                     ["study", "noise"]])
def test_an_output_folder_that_is_the_house_folder_is_refused(tmp_path, command):
    """With --force the run would write its tables among the house specs, and the next run
    would read summary.json as a house; a single house file in the output folder is fine
    (--force keeps a user's files)."""
    from sgtool.datasets.generator import generate_house
    from sgtool.house.io import save_house

    houses = tmp_path / "houses"
    houses.mkdir()
    save_house(generate_house(3, rooms=(4, 4)), houses / "h.json")
    r = CliRunner().invoke(cli, [*command, "--house", str(houses), "-o", str(houses),
                                 "--force"])
    assert r.exit_code == 2 and r.output.strip() == (
        f"sgtool: error: -o {houses} is the --house folder {houses}, whose files are read "
        "as inputs; write the outputs to another folder"), r.output
    assert sorted(p.name for p in houses.iterdir()) == ["h.json"]


@pytest.mark.parametrize("args, says", [
    (["info", ""], "Invalid value for 'LOG': an empty path."),
    (["record", "--house", "", "-o", "x.mcap"], "Invalid value for '--house': an empty path."),
    (["bench", "-o", ""], "Invalid value for '-o' / '--out': an empty path."),
    (["scenes", "generate", "-o", ""], "Invalid value for '-o' / '--output': an empty path."),
    (["record", "--speed", "1e9", "-o", "x.mcap"], "--speed 1e+09: at most 5 m/s"),
    (["record", "--noise", "mild,holes=2", "-o", "x.mcap"],
     "--noise holes=2: a probability, at most 1"),
    (["record", "--seed", "-1", "-o", "x.mcap"], "Invalid value for '--seed': -1 is not in"),
])
def test_an_empty_path_and_out_of_range_values_are_one_line(tmp_path, monkeypatch, args,
                                                            says):
    """An empty path is not the working folder (Path('') is '.'); the message names the
    option the user gave."""
    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 2 and r.output.count("\n") == 1 and says in r.output, r.output
    assert list(tmp_path.iterdir()) == []


def test_ray_address_from_the_environment_is_named_so(monkeypatch, tmp_path):
    pytest.importorskip("ray")
    monkeypatch.setenv("RAY_ADDRESS", "junk")
    r = CliRunner().invoke(cli, ["bench", "--executor", "ray", "--houses", "1", "-o",
                                 str(tmp_path / "b")])
    assert r.exit_code == 2 and r.output.startswith("sgtool: error: RAY_ADDRESS 'junk': give "
                                                    "HOST:PORT"), r.output
